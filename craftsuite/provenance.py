"""Where a result came from: the command, the code (version and git commit), the machine.

``transfer`` takes a session when it starts (``start_session``), records it in
``<out>/provenance.json`` at once without a duration, and records its duration when it
ends: a session that is killed still leaves its command and commit, marked unfinished.
One that trained and kept nothing (every run it asked for reused) is marked ``reused_only``:
on record where it ran, never merged into a results archive (``archive.keep_all``).
The results page (``reporting.pages.write_results_page``) prints the sessions beside the leaderboard.
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import platform
import shlex
import subprocess
import sys
import uuid
from datetime import datetime, UTC
from pathlib import Path

from .files import atomic_write

FILE = "provenance.json"


COMMIT_VARIABLE = "CRAFTSUITE_COMMIT"


def git_commit() -> str | None:
    """The commit ``CRAFTSUITE_COMMIT`` names, if set: a copy of the tree on another machine
    says so, since a ``.git`` copied with it may be another commit's. Else the checkout's
    commit (``-dirty`` with uncommitted changes), or None outside a checkout."""
    if os.environ.get(COMMIT_VARIABLE):
        return os.environ[COMMIT_VARIABLE]
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], cwd=here, capture_output=True,
                                text=True, timeout=10)
        if commit.returncode != 0:
            return None
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):  # no git on this machine
        return None
    return commit.stdout.strip() + ("-dirty" if dirty else "")


def machine() -> str:
    """e.g. ``Linux x86_64, AMD EPYC (family 23 model 1, AVX2), 2 cores, 23.4 GiB, Python 3.11.7``."""
    memory = ""
    try:
        memory = f", {os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES') / 2**30:.1f} GiB"
    except (ValueError, OSError, AttributeError):
        pass
    processor = cpu()
    return (f"{platform.system()} {platform.machine()}{', ' + processor if processor else ''}, "
            f"{os.cpu_count()} cores{memory}, Python {platform.python_version()}")


# the widest first: torch's matrix products use the widest the CPU offers
VECTOR_FLAGS = (("avx512f", "AVX-512"), ("avx2", "AVX2"), ("avx", "AVX"))


def cpu(cpuinfo: str | None = None) -> str:
    """The CPU as ``/proc/cpuinfo`` (``cpuinfo``: its text) describes its first processor:
    its model, family and model numbers, and the widest vector instructions it offers, e.g.
    ``AMD EPYC (family 23 model 1, AVX2)``; "" where there is no such file. Machines of one
    core count train students at rates several times apart, and a virtual machine's model
    name may be generic (``AMD EPYC``): the numbers tell its generation, and the vector
    instructions what the matrix products, most of a student's time, run on."""
    if cpuinfo is None:
        try:
            cpuinfo = Path("/proc/cpuinfo").read_text(errors="replace")
        except OSError:
            return ""
    fields = {}
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        fields.setdefault(key.strip(), value.strip())  # the first processor's
    flags = set(fields.get("flags", "").split())
    numbers = (f"family {fields['cpu family']} model {fields['model']}"
               if fields.get("cpu family") and fields.get("model") else "")
    details = ", ".join(filter(None, [numbers, next((name for flag, name in VECTOR_FLAGS if flag in flags), "")]))
    model = fields.get("model name", "")
    return f"{model} ({details})" if model and details else model or details


def versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in ("craftsuite", "torch", "stable-baselines3", "gymnasium", "mujoco"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            pass
    return out


def stamp() -> dict:
    """The code that runs now, as a run's ``config.json`` records each session that trains
    it: the time, the git commit and the package versions (CraftSuite's among them)."""
    return {"at": datetime.now(UTC).isoformat(timespec="seconds"), "commit": git_commit(),
            "versions": versions()}


def command_line() -> list[str]:
    """This process's command line as users type it (``python -m craftsuite`` runs
    ``__main__.py``: ``craftsuite``)."""
    program = Path(sys.argv[0]).name
    return ["craftsuite" if program in ("__main__.py", "craftsuite") else program, *sys.argv[1:]]


def start_session(command: list[str] | str | None = None) -> dict:
    """This invocation as ``record_session`` writes it, taken when it starts: the code that
    runs is the code at its start, whatever is committed while it runs. ``command``: an
    argument list, a description (e.g. of a Python call) or None, this process's command line.
    Each session gets an id of its own, so two that start in the same second stay two."""
    if command is None:
        command = command_line()
    return {"id": uuid.uuid4().hex[:12], "command": command if isinstance(command, str) else shlex.join(command),
            "started": datetime.now(UTC).isoformat(timespec="seconds"),
            "commit": git_commit(), "machine": machine(), "versions": versions()}


def record_session(out, session: dict, seconds: float | None) -> Path:
    """Record a session (``start_session``) in ``out/provenance.json``: appended, or, if it
    is there already (its id), updated. ``seconds`` None: not finished."""
    return merge(out, [{**session, "seconds": None if seconds is None else round(seconds, 1)}])


def merge(out, sessions: list[dict]) -> Path:
    """Sessions into ``out/provenance.json``, each by its id: one already there is replaced
    (the last of that id), a new one appended. The record is read and rewritten under a
    lock (``_locked``), so that processes writing into one directory at once (a campaign's
    processes archiving into one archive) never write back a record without another's session."""
    path = Path(out) / FILE
    with _locked(out):
        found = read(out)
        for session in sessions:
            same = [i for i, s in enumerate(found) if s.get("id") == session.get("id")]
            if same:
                found[same[-1]] = session
            else:
                found.append(session)
        atomic_write(path, json.dumps(found, indent=2) + "\n")
    return path


LOCK = ".provenance.lock"  # beside the record; ignored by git


@contextlib.contextmanager
def _locked(directory):
    """An exclusive advisory lock (``flock``) held for the block, on a lock file of its own
    in ``directory`` (made if missing): a file opened for writing, which ``flock`` on a
    network file system also takes (there it is a POSIX lock, which needs one)."""
    Path(directory).mkdir(parents=True, exist_ok=True)
    fd = os.open(Path(directory) / LOCK, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # (closing drops the lock)


def read(out) -> list[dict]:
    path = Path(out) / FILE
    if not path.exists():
        return []
    try:
        sessions = json.loads(path.read_text())
    except ValueError:
        raise ValueError(f"{path} is not valid JSON: delete it to start its record afresh") from None
    if not isinstance(sessions, list):
        raise ValueError(f"{path} holds no list of sessions: delete it to start its record afresh")
    return sessions
