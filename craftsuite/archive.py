"""The results archive: finished runs' records, kept where they outlive the machine that
trained them (in this repository, ``results/``), so that a campaign accumulates across
machines and every results page regenerates from data.

One directory per suite, shaped as a transfer output, so that every reader of runs reads
it as one::

    results/<suite>/suite.json, provenance.json      the suite as last run; every session
    results/<suite>/teachers/<run name>/              config.json, result.json, evals.csv,
                                                      episodes.csv.gz, table.npz
    results/<suite>/students/<run name>/              config.json, result.json, evals.csv,
                                                      episodes.csv.gz

Only records: never checkpoints, replay buffers, models or TensorBoard logs (a run
restored from here says it has no model). ``episodes.csv``, one row per training episode
and the largest record, is kept compressed (``runs.read_csv`` reads either form).

A record is checked before it is used: its ``config.json`` and ``result.json`` must read
as a finished run's and the directory's name must be the run key of the settings it
records. One that does not (damaged, or copied in from elsewhere under another name) is
named and skipped, never pooled.
"""

from __future__ import annotations

import gzip
import json
import secrets
import shutil
from pathlib import Path

import numpy as np

from .files import atomic_path, atomic_write
from .runs import RunError, in_use, read_config, record_key

RECORDS = ("config.json", "result.json", "evals.csv", "table.npz")  # kept as they are (table.npz: teachers)
COMPRESSED = ("episodes.csv",)  # kept as <name>.gz
KINDS = ("teachers", "students")


def check_record(run: Path, kind: str | None = None) -> str | None:
    """Why the run at ``run`` cannot be archived or used from the archive (None: it can): a
    missing or damaged record, an unfinished run, a result of another kind than ``kind``
    (``teachers``, ``students``; by default the name of the run's parent directory), or a
    directory name that is not its settings' run key."""
    try:
        record = read_config(run)
    except RunError as err:
        return str(err)
    result = run / "result.json"
    if not result.exists():
        return f"{run} has no result.json: not a finished run's record"
    try:
        outcome = json.loads(result.read_text())
        kind_of = outcome.get("kind")
    except (ValueError, AttributeError) as err:
        return f"{result} is not a run's result ({err}): the record is damaged"
    expected = kind or run.parent.name
    if f"{kind_of}s" != expected:
        return f"{result} is a {kind_of}'s result, not one of the {expected}: a record from elsewhere"
    key = record_key(record)
    if not run.name.endswith(f"-{key}"):
        return (f"{run.name} is not the name of the run its config.json records (its key is {key}): "
                "a record copied in from elsewhere, or edited")
    # a student's result names its run too: one from another run, beside this config, is foreign
    other = [f for f in ("task", "method", "seed") if f in outcome and f in record and outcome[f] != record[f]]
    if other:
        return (f"{result} is another run's result ({', '.join(f'{f} {outcome[f]!r}' for f in other)}, where "
                f"config.json records {', '.join(repr(record[f]) for f in other)}): a record from elsewhere")
    return None


def archived(archive: Path, kind: str) -> tuple[dict[str, Path], list[str]]:
    """The usable runs of one kind (``teachers``, ``students``) under ``archive``, by run
    name, and the reason each unusable one was skipped."""
    runs, skipped = {}, []
    root = Path(archive) / kind
    for run in sorted(root.iterdir()) if root.is_dir() else []:
        if not run.is_dir() or run.name.startswith("."):  # (a record being swapped in)
            continue
        reason = check_record(run)
        if reason is None:
            runs[run.name] = run
        else:
            skipped.append(reason)
    return runs, skipped


def keep(run: Path, archive: Path, kind: str) -> Path:
    """Copy a finished run's records into ``archive/kind/<run name>`` (replacing what was
    there); returns that directory.

    Raises:
        RunError: the run is not finished (it has no result.json).
    """
    run = Path(run)
    if not (run / "result.json").exists():
        raise RunError(f"{run} is not finished (no result.json): only finished runs are archived")
    final = Path(archive) / kind / run.name
    # the whole record is built beside its place, then swapped in: a reader (or a kill)
    # never meets one run's logs beside another's result, nor an older record's leftovers
    dest = final.with_name(f".{run.name}.{secrets.token_hex(4)}.tmp")
    dest.mkdir(parents=True)
    for name in RECORDS:
        if (run / name).exists() and name != "result.json":
            with atomic_path(dest / name) as tmp:
                if name.endswith(".npz"):  # a teacher's table: mostly zeros, written uncompressed
                    with np.load(run / name) as table:
                        np.savez_compressed(tmp, **table)
                else:
                    shutil.copyfile(run / name, tmp)
    for name in COMPRESSED:
        if (run / name).exists():
            # mtime 0: the same log compresses to the same bytes, so a re-archived run is no change
            atomic_write(dest / f"{name}.gz", gzip.compress((run / name).read_bytes(), compresslevel=9, mtime=0))
        elif (run / f"{name}.gz").exists():  # a run from another archive
            with atomic_path(dest / f"{name}.gz") as tmp:
                shutil.copyfile(run / f"{name}.gz", tmp)
    shutil.copyfile(run / "result.json", dest / "result.json")
    old = final.with_name(f".{run.name}.{secrets.token_hex(4)}.old")
    if final.exists():
        final.rename(old)
    dest.rename(final)
    shutil.rmtree(old, ignore_errors=True)
    return final


def restore(archive: Path, out: Path, names: dict[str, set[str]], log=print) -> dict[str, int]:
    """Copy into ``out/<kind>/`` the archived runs named in ``names`` (kind -> run names)
    that ``out`` does not hold finished: a run there is finished, so it is reused and not
    trained again. Unusable archived runs are named through ``log`` and skipped. Returns how
    many of each kind were restored."""
    restored = {}
    for kind in KINDS:
        runs, skipped = archived(archive, kind)
        for reason in skipped:
            log(f"results archive: skipped {reason}")
        count = 0
        for name in sorted(names.get(kind, set()) & set(runs)):
            dest = Path(out) / kind / name
            if (dest / "result.json").exists():
                continue
            if dest.exists():  # an unfinished run of the same settings: the archive's finished one wins,
                if in_use(dest):  # unless it is training now
                    log(f"results archive: {dest} is in use by a live run; its archived record is not restored")
                    continue
                shutil.rmtree(dest)
            shutil.copytree(runs[name], dest)
            count += 1
        restored[kind] = count
    return restored


def keep_all(out: Path, archive: Path, names: dict[str, set[str]], suite: dict | None = None) -> dict[str, int]:
    """Archive the finished runs of ``out`` named in ``names`` (kind -> run names), the
    suite as run (``suite.json``) and every session that ran into ``out`` (merged into the
    archive's ``provenance.json`` by session id). Returns how many of each kind were kept."""
    from .provenance import FILE, read

    out, archive = Path(out), Path(archive)
    kept = {}
    for kind in KINDS:
        count = 0
        for name in sorted(names.get(kind, set())):
            run = out / kind / name
            if (run / "result.json").exists() and not _same(run, archive / kind / name):
                keep(run, archive, kind)
                count += 1
        kept[kind] = count
    if suite is not None:
        atomic_write(archive / "suite.json", json.dumps(suite, indent=2) + "\n")
    sessions = read(archive)
    known = {s.get("id") for s in sessions}
    for session in read(out):
        if session.get("id") in known:
            sessions = [session if s.get("id") == session["id"] else s for s in sessions]
        else:
            sessions.append(session)
    if sessions:
        atomic_write(archive / FILE, json.dumps(sessions, indent=2) + "\n")
    return kept


def _same(run: Path, archived_run: Path) -> bool:
    """Whether the archive already holds this run's result (a run restored from it, or kept before)."""
    theirs = archived_run / "result.json"
    return theirs.exists() and theirs.read_bytes() == (run / "result.json").read_bytes()


def size(archive: Path) -> int:
    """The archive's size in bytes."""
    return sum(p.stat().st_size for p in Path(archive).rglob("*") if p.is_file())


def add(source, archive: Path, suite: dict | None = None) -> tuple[dict[str, int], list[str]]:
    """Archive the finished runs under ``source`` (a transfer output, with ``students/`` and
    ``teachers/``, or a directory of student runs), with the sessions of its
    ``provenance.json`` and its ``suite.json`` (the suite as it ran; else ``suite``, the
    suite's definition): runs made without the archive, or on another machine. Returns how
    many of each kind were kept and why each other run was skipped. (Runs of other budgets
    or settings than the suite's own are kept too, as ``--steps`` makes them: the
    leaderboard never pools them with the suite's.)

    Raises:
        FileNotFoundError: ``source`` is not a directory.
    """
    source = Path(source)
    if not source.is_dir():
        raise FileNotFoundError(f"no run directory at {source}")
    roots = {kind: source / kind for kind in KINDS if (source / kind).is_dir()} or {"students": source}
    skipped, found = [], {kind: set() for kind in KINDS}
    for kind, root in roots.items():
        for run in sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")):
            if not (run / "result.json").exists():
                skipped.append(f"{run}: not finished (no result.json)")
                continue
            reason = check_record(run, kind)
            if reason is None:
                found[kind].add(run.name)
            else:
                skipped.append(reason)
    kept = {kind: 0 for kind in KINDS}
    for kind, root in roots.items():
        for name in sorted(found[kind]):
            if not _same(root / name, Path(archive) / kind / name):
                keep(root / name, archive, kind)
                kept[kind] += 1
    if (source / "suite.json").exists():
        try:
            suite = json.loads((source / "suite.json").read_text())
        except ValueError as err:
            skipped.append(f"{source / 'suite.json'} is not valid JSON ({err}): the registered suite is recorded")
    keep_all(source, archive, {}, suite=suite)  # the sessions that made them, and the suite
    return kept, skipped

