"""Run directories: one per run, safe to kill, resume and read while it runs.

A run directory holds

* ``config.json``: the run's configuration (a dataclass, see ``craftsuite.configs``),
  its effective settings (``effective``: the algorithm's defaults merged with the
  overrides, the method's row, the world and its task's rules digest), the record format
  and its provenance (``provenance``: per session that trained it, the time, the
  CraftSuite version, the git commit and the versions of torch, SB3, gymnasium and
  mujoco). The run key, the last part of the directory's name, hashes the configuration
  and the effective settings, so a change of a default makes a new run;
* ``episodes.csv``: one row per finished training episode (step, return, length, success,
  and how far along the task it got: the propositions it saw and the automaton states it
  visited, as bitmasks: ``craftsuite.reached``);
* ``evals.csv``: one row per evaluation (step, success rate, mean return, episodes, mean
  episode length);
* ``checkpoint/``: the last state (networks, optimizer moments, replay: the population
  engine's ``population.pt``; ``model.zip`` and ``replay.pkl`` in an SB3-trained run's),
  written at each evaluation, and ``checkpoint-old/``, the one before, kept until the next
  is complete so that a damaged newest checkpoint can be resumed from the one before (the
  resume keeps the damaged one aside as ``checkpoint-unloadable/``); ``RunDir`` rotates
  them. A student's are removed when it finishes (its final model is ``model.zip``: the
  agent after its last step's gradient updates, which run after the last evaluation as
  SB3's callbacks run before its ``train()``, so its greedy success on that evaluation's
  seeds may differ from the one ``evals.csv`` records), a teacher's older one;
* ``tb/``: TensorBoard logs (on resume, what the killed run logged after its checkpoint is
  purged, as from the CSV logs);
* ``result.json``: written last; its presence means the run is finished and reusable. It
  names the agent's ``algorithm``, as the saved model does.

Every whole-file write goes through ``craftsuite.files`` (a temporary file, then
``os.replace``), so a killed run never leaves a half-written file.
An advisory lock (``flock`` on ``.lock``, which names its
holder) keeps two live runs out of one directory; the kernel drops it when its holder
dies, so a killed run can be started again at once (it resumes).
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import fcntl
import hashlib
import itertools
import json
import os
import shutil
import socket
import stat
from pathlib import Path

from .files import atomic_write, missing_folders, remove_empty

EPISODE_FIELDS = ("step", "return", "length", "success", "seen", "states")
# the columns every episodes.csv has: records made before ``seen`` and ``states`` have only
# these (a run resumed since has them empty in the rows of its first session)
EPISODE_CORE = EPISODE_FIELDS[:4]
EVAL_FIELDS = ("step", "success", "return", "episodes", "length")


class RunError(RuntimeError):
    """A run directory that cannot be used (locked by a live run, or holding another config)."""


class CheckpointError(RunError):
    """A checkpoint whose model or replay buffer cannot be read (truncated or damaged)."""


def machine_errors() -> tuple[type[BaseException], ...]:
    """Errors of the machine, not of a checkpoint's files, which loading one may raise:
    every trainer raises them as they are, never reads them as damage."""
    import torch  # (only where checkpoints load: torch is there already)

    return (MemoryError, torch.cuda.OutOfMemoryError)


# config.json's layout: 3, the dataclass fields with ``effective`` and ``provenance``. A
# record without ``format`` is read as layout 1, the fields alone: it loads, but it says
# nothing of the effective settings, so a run directory holding one is never resumed.
# Layout 2 is layout 3 whose kinematic success counted acceptance (``completion``).
FORMAT = 3
COMPLETION_FORMAT = 3  # the first layout whose kinematic success is completion
RECORD_KEYS = ("format", "provenance")  # in config.json, beside the settings: not hashed, not compared
# fields that say where a file lives, not what the run computes from: recorded, but neither
# hashed nor compared, so a moved or remounted runs directory keeps its keys (a student's
# teacher is in its effective settings by the teacher's run name, which hashes the teacher's)
LOCATIONS = ("table",)


def counts_acceptance(record: dict) -> bool:
    """Whether a ``config.json`` record is of a kinematic run made when its success counted
    the automaton's acceptance (record format 2 and before; ``craftsuite.completion`` says
    whether its task's acceptance and completion differ, and re-reads it)."""
    from .ids import KINEMATIC, parse_id

    env_id = record.get("effective", {}).get("world", {}).get("id")
    return record.get("format", 1) < COMPLETION_FORMAT and bool(env_id) and parse_id(env_id)[1] == KINEMATIC


def config_dict(config) -> dict:
    """A config dataclass as saved and hashed. A field added after runs existed carries
    ``metadata={"omit_if_default": True}``: at its default it is left out, so the runs of
    the same record format made before it keep their directories."""
    out = dataclasses.asdict(config)
    for f in dataclasses.fields(config):
        if f.metadata.get("omit_if_default"):
            default = f.default_factory() if f.default_factory is not dataclasses.MISSING else f.default
            if out[f.name] == default:
                del out[f.name]
        elif "omit_if" in f.metadata and out[f.name] == f.metadata["omit_if"]:  # what records without it meant
            del out[f.name]
    return out


def settings(config) -> dict:
    """What a run computes from: the config's fields and, if the config has an
    ``effective()`` method, its effective settings under ``"effective"``."""
    out = config_dict(config)
    if hasattr(config, "effective"):
        out["effective"] = config.effective()
    return out


# the metrics a run's TensorBoard HParams entry names (SB3's evaluation tags)
EVAL_METRICS = {"eval/mean_reward": 0.0, "eval/success_rate": 0.0}


def hparams(config) -> dict:
    """A run's settings as TensorBoard's HParams take them: one flat level of numbers,
    strings and booleans (``hyperparameters.learning_rate``; lists and None as JSON text).
    The effective settings come last: where they repeat a field (the overrides), theirs stand."""
    data = settings(config)
    flat = {**flatten({k: v for k, v in data.items() if k != "effective"}), **flatten(data.get("effective", {}))}
    return {k: v if isinstance(v, (bool, int, float, str)) else json.dumps(v) for k, v in flat.items()}


def config_key(config) -> str:
    """A short stable hash of a config's settings (not of its file locations): equal
    settings share a run directory."""
    return record_key(settings(config))


def record_key(record: dict) -> str:
    """The run key of a ``config.json`` record (or of a config's ``settings``): the hash of
    what it records beyond its format, provenance and file locations. Read back from a
    record, it is the key the run was made with, whatever this version's defaults."""
    return hashlib.sha256(json.dumps(run_settings(record), sort_keys=True).encode()).hexdigest()[:10]


def recorded_rules(record: dict) -> str | None:
    """The digest of the task's rules a ``config.json`` record says its run ran under
    (CraftSuite's runs in their effective settings, a self-reported run beside its task), or
    None where the record predates it."""
    return record.get("rules") or (record.get("effective") or {}).get("world", {}).get("rules")


def read_config(run) -> dict:
    """A run directory's ``config.json``, of any layout this version reads.

    Raises:
        RunError: no config.json, not JSON, not a run's record, or a layout newer than
            this version of CraftSuite reads; the message names the file and the reason.
    """
    path = Path(run) / "config.json"
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise RunError(f"{path} is missing: {Path(run)} is not a run directory") from None
    except ValueError as err:
        raise RunError(f"{path} is not valid JSON ({err}): the run's record is damaged") from None
    if not isinstance(data, dict) or "task" not in data:
        raise RunError(f"{path} holds no run configuration (no task): not a CraftSuite run record")
    layout = data.get("format", 1)
    if not isinstance(layout, int) or layout > FORMAT:
        raise RunError(f"{path} has record format {layout!r}, newer than this CraftSuite reads (up to {FORMAT}): "
                       "upgrade CraftSuite to read it")
    return data


def read_result(run) -> dict:
    """A finished run's ``result.json`` (a student's or a teacher's), the one reader of it.

    Raises:
        RunError: missing, not JSON, or not a run's result, naming the file.
    """
    path = Path(run) / "result.json"
    try:
        result = json.loads(path.read_text())
    except FileNotFoundError:
        raise RunError(f"{path} is missing: the run is not finished") from None
    except (ValueError, OSError) as err:
        raise RunError(f"{path} is not valid JSON ({err}): the run's result is damaged") from None
    if not isinstance(result, dict) or result.get("kind") not in ("student", "teacher"):
        raise RunError(f"{path} holds no student's or teacher's result (no kind): the run's result is damaged")
    if result["kind"] == "student" and not isinstance(result.get("steps"), int):
        raise RunError(f"{path} holds no transitions (steps): the run's result is damaged")
    return result


def config_from(cls, record: dict):
    """The config dataclass (``cls``) of a ``config.json`` record of any layout: its fields
    (the effective settings and the provenance are left out; a field a record predates
    takes its default, or the value its ``omit_if`` metadata says such records meant)."""
    fields = dataclasses.fields(cls)
    absent = {f.name: f.metadata["omit_if"] for f in fields if "omit_if" in f.metadata and f.name not in record}
    return cls(**absent, **{k: v for k, v in record.items() if k in {f.name for f in fields}})


def load_config(cls, run):
    """The config dataclass (``cls``) a run directory was made with."""
    return config_from(cls, read_config(run))


def flatten(data: dict, prefix: str = "") -> dict:
    """Nested settings as one level of dotted keys: ``{"a": {"b": 1}}`` -> ``{"a.b": 1}``."""
    out = {}
    for key, value in data.items():
        name = f"{prefix}.{key}" if prefix else key
        if isinstance(value, dict) and value:
            out.update(flatten(value, name))
        else:
            out[name] = value
    return out


def run_settings(record: dict) -> dict:
    """The settings part of a ``config.json`` record (what the run key hashes): without
    the record's format and provenance, nor file locations."""
    return {k: v for k, v in record.items() if k not in RECORD_KEYS + LOCATIONS}


EVAL_SEED = 10**7  # far from training's seeds (the run's seed and its envs' next ones)


def evaluation_steps(steps: int, every: int) -> list[int]:
    """The steps of a run's scheduled evaluations: every ``every`` transitions, and at its
    budget ``steps`` (a multiple of ``every`` or not), once."""
    return [*range(every, steps, every), steps]


def eval_seed(step: int) -> int:
    """The first episode seed of a run's evaluation at ``step`` (its episodes play the next
    ones), the same rule for every kind of run and engine; evaluations fewer than
    ``eval_episodes`` steps apart share some of their seeds."""
    return EVAL_SEED + step


def in_use(run) -> bool:
    """Whether a live process holds the run directory's lock (``RunDir``)."""
    # read-only (another user's lock may allow no more), so a shared lock: it conflicts with the
    # owner's exclusive one all the same, and NFS, which takes flock as fcntl, needs a descriptor
    # open for writing for an exclusive lock alone
    try:  # (opened at once: a directory this user may not search is named, as a lock it may not read)
        fd = _open_lock(Path(run) / ".lock", os.O_RDONLY)
    except (FileNotFoundError, NotADirectoryError):  # no lock, or no run directory: nothing holds it
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except BlockingIOError:
        return True
    finally:
        os.close(fd)  # (closing drops a lock taken here)
    return False


def _open_lock(lock: Path, flags: int) -> int:
    """A run's ``.lock`` opened; one this user may not open (another user's run) a RunError
    naming it, for the CLI and for code that calls the archive or a trainer alike; so is a
    directory in its place (read-only, Linux opens one: the same answer whatever the flags)."""
    try:
        fd = os.open(lock, flags)
    except PermissionError as err:
        raise RunError(f"{lock} cannot be opened here ({err.strerror}): the run belongs to another user; "
                       "run this as the user who trained it, or copy the run to a directory of your own") from None
    except IsADirectoryError:
        fd = None
    if fd is None or stat.S_ISDIR(os.fstat(fd).st_mode):
        if fd is not None:
            os.close(fd)
        raise RunError(f"{lock} is a directory where a run keeps its lock file; "
                       "remove it (rmdir, which refuses one that holds files) and run again")
    return fd


class RunDir:
    """One run's directory. Use as a context manager: it holds the lock while open."""

    def __init__(self, path, config):
        self.path = Path(path)
        self.config = config
        self._lock = self.path / ".lock"

    # -- ownership -------------------------------------------------------------------------------
    def __enter__(self) -> RunDir:
        self._created = not self.path.exists()
        self._made = missing_folders(self.path)  # its own and any missing above it (a new --out)
        self.path.mkdir(parents=True, exist_ok=True)
        self._acquire()
        try:
            self._record()
        except BaseException:
            self._release()
            raise
        return self

    def _record(self) -> None:
        """Write config.json: the settings, and this session in its provenance. A finished
        run's record is left as it is (reusing it trains nothing)."""
        from .provenance import stamp

        mine = json.loads(json.dumps(settings(self.config)))  # as it reads back: tuples are lists
        path = self.path / "config.json"
        sessions = []
        if path.exists():
            saved = read_config(self.path)
            if "effective" not in saved and "effective" in mine:
                raise RunError(f"{self.path} holds a run recorded without its effective settings (record format 1), "
                               "so it cannot be told to match this configuration; it is not resumed: "
                               "choose another output directory")
            if run_settings(saved) != run_settings(mine):
                raise RunError(f"{self.path} holds a run with another configuration ({path}); "
                               "choose another output directory")
            if self.finished():
                return
            if counts_acceptance(saved):  # its logs so far may count another success than it would go on to
                raise RunError(f"{self.path} holds a kinematic run recorded when success counted the automaton's "
                               f"acceptance (record format {saved.get('format', 1)}); it is not resumed: choose "
                               "another output directory")
            sessions = saved.get("provenance", [])
        record = {**mine, "format": FORMAT, "provenance": [*sessions, stamp()]}
        atomic_write(path, json.dumps(record, indent=2, sort_keys=True) + "\n")

    def __exit__(self, exc_type, *exc) -> None:
        try:
            if exc_type is not None and self._created:
                self._remove_if_unused()
        finally:
            self._release()

    def _remove_if_unused(self) -> None:
        """A run that failed before it wrote anything but its config (an agent that could not
        be built: a bad ``--hyper``) leaves no directory behind to be mistaken for a run, nor
        the empty folders it made above it."""
        if {p.name for p in self.path.iterdir()} <= {"config.json", ".lock"}:
            for name in ("config.json", ".lock"):
                (self.path / name).unlink(missing_ok=True)
            remove_empty(self._made)

    def _acquire(self) -> None:
        # An advisory lock held on an open file: the kernel drops it when its owner dies, so a
        # killed run's directory is free again at once, and two live runs can never both hold it.
        try:
            self._fd = _open_lock(self._lock, os.O_CREAT | os.O_RDWR)
        except FileNotFoundError:  # a run that failed at once removed the directory meanwhile
            self.path.mkdir(parents=True, exist_ok=True)
            self._fd = _open_lock(self._lock, os.O_CREAT | os.O_RDWR)
        try:
            fcntl.flock(self._fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            owner = os.pread(self._fd, 200, 0).decode(errors="replace").strip() or "unknown"
            os.close(self._fd)
            raise RunError(f"{self.path} is in use by another run (process {owner})") from None
        os.ftruncate(self._fd, 0)
        os.pwrite(self._fd, f"{socket.gethostname()} {os.getpid()}".encode(), 0)

    def _release(self) -> None:
        os.close(self._fd)  # releases the lock; the file stays (unlinking it would race a new owner)

    # -- files -----------------------------------------------------------------------------------
    # -- checkpoints: the newest being written, the last, the one before -----------------------
    CHECKPOINTS = ("checkpoint-new", "checkpoint", "checkpoint-old")  # newest first
    UNLOADABLE = "checkpoint-unloadable"  # where a checkpoint that failed to load is kept aside

    def set_aside(self, folder: Path) -> Path:
        """Keep a checkpoint ``folder`` that failed to load as ``checkpoint-unloadable`` (one
        kept: a newer failure replaces an older), out of the rotation of checkpoints."""
        aside = self.path / self.UNLOADABLE
        shutil.rmtree(aside, ignore_errors=True)
        folder.rename(aside)
        return aside

    def new_checkpoint(self) -> Path:
        """An empty ``checkpoint-new`` to write the next checkpoint into (what a kill left
        there is cleared); ``commit_checkpoint`` makes it the last."""
        new = self.path / "checkpoint-new"
        shutil.rmtree(new, ignore_errors=True)
        new.mkdir()
        return new

    def commit_checkpoint(self) -> None:
        """``checkpoint-new`` becomes ``checkpoint``, and ``checkpoint`` ``checkpoint-old``
        (the one before that is deleted): the one before the last is kept until the next is
        complete, so a resume has a complete one to fall back on if the newest is damaged."""
        new, last, old = (self.path / name for name in self.CHECKPOINTS)
        if last.exists():
            shutil.rmtree(old, ignore_errors=True)
            last.rename(old)
        new.rename(last)

    def checkpoint_dirs(self, files=("model.zip", "replay.pkl")) -> list[Path]:
        """The run's complete checkpoints (each holding all ``files``), newest first:
        ``checkpoint-new`` (complete only when a kill came between its writing and the
        commit: each file is written whole), ``checkpoint`` and ``checkpoint-old``."""
        return self.checkpoints_in(self.path, files)

    @classmethod
    def checkpoints_in(cls, path: Path, files) -> list[Path]:
        """``checkpoint_dirs`` of the run directory at ``path``, read without its config
        (a suite's driver looking at a member it does not own)."""
        return [d for d in (Path(path) / name for name in cls.CHECKPOINTS) if all((d / f).exists() for f in files)]

    def last_checkpoint(self, files=("model.zip", "replay.pkl")) -> Path | None:
        """The directory of the run's last complete checkpoint, if any."""
        dirs = self.checkpoint_dirs(files)
        return dirs[0] if dirs else None

    def remove_checkpoints(self, keep_last: bool = False) -> None:
        """A finished run's checkpoints (nothing resumes it), but ``checkpoint`` if ``keep_last``."""
        for name in self.CHECKPOINTS:
            if not (keep_last and name == "checkpoint"):
                shutil.rmtree(self.path / name, ignore_errors=True)

    @property
    def result_path(self) -> Path:
        return self.path / "result.json"

    def finished(self) -> bool:
        return self.result_path.exists()

    def write_result(self, result: dict) -> None:
        atomic_write(self.result_path, json.dumps(result, indent=2) + "\n")

    def write_progress(self, step: int, total: int) -> None:
        atomic_write(self.path / "progress.json", json.dumps({"step": step, "total": total}))

    def trim_logs(self, step: int) -> None:
        """Drop log rows after ``step`` (the checkpoint a resumed run starts from): those
        episodes are played again, and would otherwise be counted twice."""
        for name, fields in (("episodes.csv", EPISODE_FIELDS), ("evals.csv", EVAL_FIELDS)):
            rows = [r for r in read_csv(self.path / name) if int(float(r["step"])) <= step]
            write_csv(self.path / name, fields, rows)

    def append(self, name: str, fields: tuple[str, ...], rows: list[dict]) -> None:
        """Append rows to a CSV log (header on first write), flushed to disk."""
        path = self.path / name
        new = not path.exists() or path.stat().st_size == 0
        with open(path, "a", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=fields)
            if new:
                writer.writeheader()
            writer.writerows(rows)
            f.flush()
            os.fsync(f.fileno())


def last_success(run) -> float:
    """The greedy success of the last evaluation of the run at ``run`` (0 before any)."""
    evals = read_csv(Path(run) / "evals.csv")
    return float(evals[-1]["success"]) if evals else 0.0


def reached_target(run, target: float) -> bool:
    """Whether the run at ``run`` has an evaluation and its last reached ``target`` greedy
    success (a teacher's stopping rule)."""
    evals = read_csv(Path(run) / "evals.csv")
    return bool(evals) and float(evals[-1]["success"]) >= target


def teacher_outcome(result: dict, target: float) -> str:
    """A finished teacher's ``result.json`` in words, its target said whichever way it went:
    ``"2,000 steps, greedy success 0.68 (did NOT reach 90%)"``."""
    reached = "reached" if result["reached_target"] else "did NOT reach"
    return f"{result['steps']:,} steps, greedy success {result['success']:.2f} ({reached} {target:.0%})"


def read_csv(path, fields: tuple[str, ...] = (), required: bool = False) -> list[dict]:
    """A run's CSV log as rows (none if it is missing); ``<name>.gz`` beside a missing
    ``<name>`` is read instead (the results archive keeps ``episodes.csv`` compressed). Rows
    are read as ``csv.DictReader`` reads them (blank lines skipped, a long row's extra fields
    a list under None), less any row short of the header and a last line without its line end:
    torn lines.

    Args:
        fields: the columns the caller reads; given, a log that cannot hold them is refused
            (by default a log is read as it is, as a run being resumed reads its own).
        required: a missing log is refused instead of read as no rows.

    Raises:
        FileNotFoundError: ``required``, and neither form of the log exists.
        ValueError: with ``fields``, an empty log, a header without one of them, or a short
            row before the last (a kill tears the last line only).
    """
    header, rows = _log_rows(path, fields, required)
    if header is None:
        return []
    n, out = len(header), []
    for row in rows:
        if len(row) == n:
            out.append(dict(zip(header, row)))
        elif len(row) > n:
            out.append({**dict(zip(header, row)), None: row[n:]})
    return out


def read_columns(path, fields: tuple[str, ...], required: bool = False) -> dict[str, tuple[str, ...]]:
    """A run's CSV log as columns, each header name to its rows' strings, by the rules of
    ``read_csv`` (the same rows; ``fields`` must be in the header). A reader of many logs
    (a results page reads millions of rows) keeps columns, not a dict a row.

    Raises:
        FileNotFoundError, ValueError: as ``read_csv`` with ``fields``.
    """
    header, rows = _log_rows(path, fields, required)
    if header is None:
        return {name: () for name in fields}
    n = len(header)
    if rows and min(map(len, rows)) < n:  # (a scan at C speed: rows are copied only when one is short)
        rows = [row for row in rows if len(row) >= n]  # less a torn line, as read_csv
    return dict(zip(header, zip(*rows))) if rows else {name: () for name in header}


def _log_rows(path, fields: tuple[str, ...], required: bool) -> tuple[list[str] | None, list[list[str]]]:
    """A CSV log's header and non-blank rows, as lists of strings (no header: a missing log
    not ``required``, or an empty one when no ``fields`` are asked for)."""
    import gzip
    import io
    import zlib

    path = Path(path)
    packed = path.with_name(path.name + ".gz")
    # the whole file at once: a log of 50,000 lines parses in about 0.6-0.8 of the time it takes
    # through gzip's and the text layer's small reads
    try:
        if path.exists():
            data = path.read_bytes()
        elif packed.exists():
            data = gzip.decompress(packed.read_bytes())
        elif required:
            raise FileNotFoundError(f"{path} is missing")
        else:
            return None, []
        reader = csv.reader(io.TextIOWrapper(io.BytesIO(data), newline=""))  # (open()'s own decoding)
        header = next(reader, None)
        rows = [row for row in reader if row]
        if rows and not data.endswith((b"\n", b"\r")):
            # every writer ends its lines: a last line without its end was torn by a kill, however
            # many fields it kept (a value cut from "0.85" to "0.8" would read as the partial one)
            rows.pop()
    # neither is an OSError or a ValueError, the damage a log's readers name (reading_log)
    except zlib.error as err:
        raise ValueError(f"its compressed bytes are damaged ({err})") from None
    except csv.Error as err:
        raise ValueError(f"it does not parse as CSV ({err})") from None
    if fields:
        _check_log(header, rows, fields)
    return header, rows


def _check_log(header: list[str] | None, rows: list[list[str]], fields: tuple[str, ...]) -> None:
    """Raise ValueError where a log's header and rows cannot be the log of ``fields``."""
    if not header:
        raise ValueError("the file is empty, without even its header")
    lacking = [f for f in fields if f not in header]
    if lacking:
        raise ValueError(f"its header lacks {', '.join(lacking)}: it reads {','.join(header)[:60]!r}")
    n = len(header)
    if len(rows) > 1 and min(map(len, itertools.islice(rows, len(rows) - 1))) >= n:
        return  # (a scan at C speed first: the lines are counted in Python only when one is short)
    short = next((i for i, row in enumerate(rows[:-1]) if len(row) < n), None)
    if short is not None:
        raise ValueError(f"its line {short + 2} has fewer fields than its header; only a last line, torn by a "
                         "kill, may")


def read_log(path, fields: tuple[str, ...], row=dict, required: bool = False) -> list:
    """A run's CSV log for a reader of records, each row as ``row`` reads it (``fields``: the
    columns it reads); ``required``: a log every finished run has.

    Raises:
        RunError: a log that is missing (``required``) or does not read as the log's, naming the file.
    """
    with reading_log(path):
        return [row(r) for r in read_csv(path, fields, required)]


def read_log_columns(path, fields: tuple[str, ...], required: bool = False) -> dict[str, tuple[str, ...]]:
    """``read_log`` as columns (``read_columns``): for readers of many logs.

    Raises:
        RunError: as ``read_log``.
    """
    with reading_log(path):
        return read_columns(path, fields, required)


@contextlib.contextmanager
def reading_log(path):
    """Within it, a log at ``path`` that does not read (or whose cells do not convert) is
    raised as a RunError naming the file: a damaged record."""
    try:
        yield
    except FileNotFoundError:  # before OSError: not damaged bytes, but no file
        raise RunError(f"{path} is missing: the run's record is damaged (a finished run has evaluated at least "
                       "once, at its end)") from None
    except (KeyError, ValueError, OSError, EOFError) as err:  # OSError, EOFError: a damaged .gz
        raise RunError(f"{path} does not read as a run's log ({type(err).__name__}: {err}): "
                       "the run's record is damaged") from None


def csv_text(fields, rows) -> str:
    """Rows as a CSV log's text, its header first."""
    import io

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=fields)
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()


def write_csv(path, fields, rows) -> None:
    atomic_write(Path(path), csv_text(fields, rows))
