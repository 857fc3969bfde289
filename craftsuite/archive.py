"""The results archive: finished runs' records, kept where they outlive the machine that
trained them (in this repository, ``results/``), so that a campaign accumulates across
machines and every results page regenerates from data.

One directory per suite, shaped as a transfer output, so that every reader of runs reads
it as one::

    results/<suite>/suite.json, provenance.json      the suite as last run; every session
                                                      (of those that trained or kept runs here)
    results/<suite>/teachers/<run name>/              config.json, result.json, evals.csv,
                                                      episodes.csv.gz, table.npz
    results/<suite>/students/<run name>/              config.json, result.json, evals.csv,
                                                      episodes.csv.gz
    results/<suite>/looks.json                        readings of comparisons the runs' records
                                                      cannot show (written by hand: reporting.looks)

Only records: never checkpoints, replay buffers, models or TensorBoard logs (a run
restored from here says it has no model). ``episodes.csv``, one row per training episode
and the largest record, is kept compressed (``runs.read_csv`` reads either form).

A record is checked before it is used: its ``config.json`` and ``result.json`` must read
as a finished run's, its ``evals.csv`` must hold its evaluations and the directory's name
must be the run key of the settings it records. One that does not (damaged, or copied in
from elsewhere under another name) is named and skipped, never pooled. ``craftsuite
archive`` also skips, by name, a run of a task, world or method its suite does not run.
"""

from __future__ import annotations

import gzip
import json
import secrets
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .completion import needs_reread, reread_in_place, reread_logs
from .files import atomic_path, atomic_write
from .runs import RunError, in_use, read_columns, read_config, read_csv, read_result, record_key

RECORDS = ("config.json", "result.json", "evals.csv", "table.npz")  # kept as they are (table.npz: teachers)
COMPRESSED = ("episodes.csv",)  # kept as <name>.gz
KINDS = ("teachers", "students")


def check_record(run: Path, kind: str | None = None) -> str | None:
    """Why the run at ``run`` cannot be archived or used from the archive (None: it can): a
    missing or damaged record (its evaluations too), an unfinished run, a result of another
    kind than ``kind`` (``teachers``, ``students``; by default the name of the run's parent
    directory), or a directory name that is not its settings' run key."""
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
    return _check_evals(run / "evals.csv") or _check_format(run, record, outcome) or _check_success(run, record)


def _check_format(run: Path, record: dict, outcome: dict) -> str | None:
    """Why a student's record breaks the record format (``craftsuite.record_format``; None:
    it keeps it). A teacher's result follows its own rules: it stops at its target."""
    from .record_format import (RecordError, breaks_format, check_config, check_episodes, check_evals, check_result,
                                required)

    if outcome.get("kind") != "student":
        return None
    log = None  # the log being read
    try:
        check_config(record, run / "config.json")
        check_result(outcome, record, run / "result.json")
        for name, check in (("evals.csv", check_evals), ("episodes.csv", check_episodes)):
            log = run / name
            check(read_columns(log, required(name)), outcome["steps"], log)
    except RecordError as err:
        return breaks_format(err)
    except (ValueError, OSError, EOFError) as err:
        return f"{log or run} does not read as a run's log ({err}): the record is damaged"
    return None


def _check_success(run: Path, record: dict) -> str | None:
    """Why a record whose success counted acceptance cannot be re-read as completion
    (``completion``; None: it can, or it needs no re-reading)."""
    try:
        if needs_reread(record):
            reread_logs(run, record)
    except RunError as err:
        return f"{run}: {err}"
    return None


def _check_evals(evals: Path) -> str | None:
    """Why a finished run's ``evals.csv`` is not a record of its evaluations (None: it is).
    Every run, teacher or student, evaluates at its end: a record without one is damaged,
    and the leaderboard could not read it."""
    if not evals.is_file():  # (never kept compressed: the archive keeps this one as it is)
        return f"{evals} is missing: a finished run's record has its evaluations (the last at its end)"
    from .record_format import RecordError, check_evaluated

    try:
        check_evaluated(len(read_csv(evals, ("step", "success"))), evals)
    except RecordError as err:
        return str(err)
    except (ValueError, OSError) as err:
        return f"{evals} does not read as a run's log ({err}): the record is damaged"
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
        RunError: the run is not finished (it has no result.json), or its success counted
            the automaton's acceptance and its record cannot say what completed (``completion``).
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
    try:
        reread_in_place(dest)  # a record whose success counted acceptance is kept as completion
    except BaseException:
        shutil.rmtree(dest, ignore_errors=True)
        raise
    old = final.with_name(f".{run.name}.{secrets.token_hex(4)}.old")
    if final.exists():
        final.rename(old)
    dest.rename(final)
    shutil.rmtree(old, ignore_errors=True)
    return final


def reuse(archive: Path | None, out: Path, kind: str, name: str) -> tuple[str, str | None]:
    """How a transfer into ``out`` reuses the run ``name`` of ``kind`` (``teachers``,
    ``students``) it asks for, with the archive at ``archive`` (None: none), and why where a
    record is refused: ``("finished", None)``, ``out`` holds it finished; ``("busy", None)``, a
    live process trains it in ``out`` (nothing is restored into it, and a transfer started
    now stops at its lock); ``("archived", None)``, the archive's record is usable (``restore``
    copies it); ``("skipped", why)``, the archive's record is not; ``("absent", None)``, the
    archive has none. (Skipped or absent, the run trains, resuming from its checkpoint in
    ``out`` where it has one.) ``restore`` and the dry run both decide by it. Telling a
    busy run takes its lock for an instant (``runs.in_use``): a run starting in that
    instant is refused as in use, as it would be beside any live run."""
    run = Path(out) / kind / name
    if (run / "result.json").is_file():
        return "finished", None
    if in_use(run):
        return "busy", None
    record = None if archive is None else Path(archive) / kind / name
    if record is None or not record.is_dir():
        return "absent", None
    why = check_record(record)
    return ("archived", None) if why is None else ("skipped", why)


def restore(archive: Path, out: Path, names: dict[str, set[str]], log=print) -> dict[str, int]:
    """Copy into ``out/<kind>/`` the archived runs named in ``names`` (kind -> run names)
    that ``out`` does not hold finished: a run there is finished, so it is reused and not
    trained again (``reuse`` decides each). An unusable archived record of a run it would
    copy is named through ``log`` and skipped (that run trains), as is a run a live process
    trains in ``out``; the archive's other records are not read (a suite's archive
    holds thousands, and a transfer of one cell asks for a few). Returns how many of each
    kind were restored."""
    restored = {}
    for kind in KINDS:
        count = 0
        for name in sorted(names.get(kind, set())):
            found, why = reuse(archive, out, kind, name)
            dest = Path(out) / kind / name
            if found == "archived" and in_use(dest):  # a run took it while its record was read
                found = "busy"
            if found == "busy":
                log(f"results archive: {dest} is in use by a live run: nothing is restored into it")
            elif found == "skipped":
                log(f"results archive: skipped {why}")
            elif found == "archived":
                if dest.exists():  # unfinished: the archive's finished run of the same settings wins
                    shutil.rmtree(dest)
                shutil.copytree(Path(archive) / kind / name, dest)
                count += 1
        restored[kind] = count
    return restored


def keep_all(out: Path, archive: Path, names: dict[str, set[str]], suite: dict | None = None,
             log=print, record_always: bool = False) -> dict[str, int]:
    """Archive the finished runs of ``out`` named in ``names`` (kind -> run names), then,
    where this call kept a run (or ``record_always``), the suite as run (``suite.json``) and
    every session that ran into ``out`` (merged into the archive's ``provenance.json`` by
    session id): a call that keeps nothing new leaves the archive as it was unless told to
    record. A run that cannot be kept (a record whose success cannot be re-read) is named
    through ``log``; the others are kept all the same. Returns how many of each kind were kept."""
    from .provenance import merge, read

    out, archive = Path(out), Path(archive)
    kept = {}
    for kind in KINDS:
        count = 0
        for name in sorted(names.get(kind, set())):
            run = out / kind / name
            if (run / "result.json").exists() and not _same(run, archive / kind / name):
                try:
                    keep(run, archive, kind)
                except RunError as err:
                    log(f"results archive {archive}: not kept: {err}")
                    continue
                count += 1
        kept[kind] = count
    if not (record_always or any(kept.values())):
        return kept
    if suite is not None:
        atomic_write(archive / "suite.json", json.dumps(suite, indent=2) + "\n")
    # (a session that reused every run stays off the archive's record, though a later one into out is on it)
    sessions = [s for s in read(out) if not s.get("reused_only")]
    if sessions:
        merge(archive, sessions)
    return kept


def _same(run: Path, archived_run: Path) -> bool:
    """Whether the archive already holds this run's result as this version reads it (a run
    restored from it, or kept before, its success re-read or not: ``completion``). An
    archived record whose success still counts acceptance is not (keeping it re-reads it)."""
    theirs = archived_run / "result.json"
    if not theirs.exists():
        return False
    try:
        mine, held = read_result(run), read_result(archived_run)
        return (_unmarked(mine) == _unmarked(held)
                and not needs_reread(read_config(archived_run)))
    except RunError:  # unreadable there: keeping it again is what mends it
        return False


def _unmarked(result: dict) -> dict:
    """A result without the mark of a re-reading: the same run's either way."""
    return {k: v for k, v in result.items() if k != "success_reread"}


def size(archive: Path) -> int:
    """The archive's size in bytes."""
    return sum(p.stat().st_size for p in Path(archive).rglob("*") if p.is_file())


def outside(record: dict, kind: str, suite, rungs: list[str]) -> str | None:
    """Why a run (``record``: its config.json) is not one of ``suite``'s (a ``suites.Suite``
    whose rungs are ``rungs``): a task it does not run or, for a student, a world or method,
    and where it can go instead. None: it is one. Its budget and other settings are not asked
    (see ``add``)."""
    missed = _missed(record, kind, suite, rungs)
    if missed is None:
        return None
    field, known = missed
    return (f"{field} {record.get(field)} is not one of suite {suite.name}'s {field}s ({', '.join(known)}): "
            f"{_elsewhere(record, kind, suite.name)}")


def _missed(record: dict, kind: str, suite, rungs: list[str]) -> tuple[str, tuple] | None:
    """The first field of ``record`` that ``suite`` does not run, with the values it does."""
    asked = [("task", rungs)] + ([("world", suite.worlds), ("method", suite.methods)] if kind == "students" else [])
    return next(((field, tuple(known)) for field, known in asked if record.get(field) not in known), None)


def _elsewhere(record: dict, kind: str, suite: str) -> str:
    """Where a run that is not one of ``suite``'s can go instead: the archived suites whose
    task, world and method it is, else an archive of its own (a transfer runs rungs, worlds
    and methods beyond its suite's, and keeps them only where --archive DIR says)."""
    from .suites import SUITES

    fits = [name for name, s in SUITES.items() if name != suite and s.archived
            and _missed(record, kind, s, [spec.name for spec in s.rungs()]) is None]
    if fits:
        return f"archive it with --suite set to a suite that runs it ({', '.join(fits)})"
    read = (f", or read it where it is beside this archive (craftsuite leaderboard RUNS ARCHIVE/{suite} --out DIR)"
            if kind == "students" else "")
    return ("no suite runs it: run its transfer again with the same --out and --archive DIR (an archive of its own, "
            f"not results) to keep it{read}")


@dataclass
class Source:
    """A directory of runs read and checked for the archive (``scan``); nothing is kept yet."""

    path: Path
    runs: dict[str, list[Path]]  # kind -> the run directories to keep
    skipped: list[str]  # why each other run is left out, naming it
    suite: dict | None  # the suite to record: the source's suite.json, else the suite's definition


def scan(source, suite=None) -> Source:
    """The finished runs under ``source`` (a transfer output, with ``students/`` and
    ``teachers/``, or a directory of student runs) that can be archived as runs of
    ``suite`` (a ``suites.Suite``; None: of any), and why each other run cannot. Reads what
    ``add`` uses (``suite.json``, ``provenance.json``) and writes nothing.

    Raises:
        FileNotFoundError: ``source`` is not a directory.
        ValueError: no run under it (no directory holding a config.json or result.json),
            or a damaged ``provenance.json``.
    """
    from .provenance import read

    source = Path(source)
    found = _runs_under(source)
    read(source)  # a damaged provenance.json, named before anything is kept (add merges it)
    rungs = [spec.name for spec in suite.rungs()] if suite is not None else []
    runs, skipped = {kind: [] for kind in KINDS}, []
    for kind, candidates in found.items():
        for run in candidates:
            if not (run / "result.json").exists():
                skipped.append(f"{run}: not finished (no result.json)")
                continue
            reason = check_record(run, kind)
            if reason is None and suite is not None:
                reason = outside(read_config(run), kind, suite, rungs)
                reason = reason and f"{run}: {reason}"
            if reason is None:
                runs[kind].append(run)
            else:
                skipped.append(reason)
    return Source(source, runs, skipped, _suite_to_record(source, suite, skipped))


def _runs_under(source: Path) -> dict[str, list[Path]]:
    """The run directories under ``source`` by kind: those holding a run's record.

    Raises:
        FileNotFoundError: ``source`` is not a directory.
        ValueError: it holds no run (or is one).
    """
    if not source.is_dir():
        raise FileNotFoundError(f"no run directory at {source}")
    roots = {kind: source / kind for kind in KINDS if (source / kind).is_dir()} or {"students": source}
    found = {kind: sorted(p for p in root.iterdir() if p.is_dir() and not p.name.startswith(".")
                          and ((p / "config.json").exists() or (p / "result.json").exists()))
             for kind, root in roots.items()}
    if any(found.values()):
        return found
    if (source / "config.json").exists():
        raise ValueError(f"{source} is a run, not a directory of runs: give the directory that holds it "
                         f"({source.parent})")
    folders = sorted(p.name for root in roots.values() for p in root.iterdir() if p.is_dir())
    raise ValueError(f"no runs found under {source}" + (f" (its folders {', '.join(folders[:3])}"
                     f"{', ...' if len(folders) > 3 else ''} hold no run's record)" if folders else "")
                     + ": give a transfer output or a directory of student runs")


def _suite_to_record(source: Path, suite, skipped: list[str]) -> dict | None:
    """The suite ``add`` records with the runs of ``source``: its ``suite.json`` (the suite as
    it ran), else ``suite``'s definition; where its suite.json cannot be used, why, added
    to ``skipped``."""
    from dataclasses import asdict

    registered = None if suite is None else asdict(suite)
    path = source / "suite.json"
    if not path.exists():
        return registered
    try:
        ran = json.loads(path.read_text())
    except ValueError as err:
        skipped.append(f"{path} is not valid JSON ({err}): the registered suite is recorded")
        return registered
    if not isinstance(ran, dict):
        skipped.append(f"{path} holds no suite (a JSON {type(ran).__name__}): the registered suite is recorded")
        return registered
    if suite is not None and ran.get("name") != suite.name:  # never another suite's over this one's
        skipped.append(f"{path} is suite {ran.get('name')}'s, not {suite.name}'s: the registered suite is recorded")
        return registered
    return ran


def add(source: Source, archive: Path) -> dict[str, int]:
    """Archive the runs of ``source`` (``scan``), with the sessions of its
    ``provenance.json`` and the suite it records: runs made without the archive, or on
    another machine. Returns how many of each kind were kept: a run the archive holds
    already is not kept again, and where none is kept, the archive's ``suite.json`` and
    ``provenance.json`` are left as they are. (Runs of other budgets or settings than the
    suite's own are kept too, as ``--steps`` makes them: the leaderboard never pools them
    with the suite's.)"""
    kept = {kind: 0 for kind in KINDS}
    for kind, runs in source.runs.items():
        for run in runs:
            if not _same(run, Path(archive) / kind / run.name):
                keep(run, archive, kind)
                kept[kind] += 1
    if any(kept.values()):
        keep_all(source.path, archive, {}, suite=source.suite, record_always=True)  # their sessions and suite
    return kept
