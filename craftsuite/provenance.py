"""Where a result came from: the command, the code (version and git commit), the machine.

``transfer`` appends one session per invocation to ``<out>/provenance.json``; the results
page (``leaderboard.write_page``) prints them beside the leaderboard it generates.
"""

from __future__ import annotations

import json
import os
import platform
import shlex
import subprocess
import sys
from datetime import datetime, timezone
from pathlib import Path

from .runs import atomic_write

FILE = "provenance.json"


def git_commit() -> str | None:
    """The checkout's commit (``-dirty`` with uncommitted changes), None outside a checkout."""
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(["git", "rev-parse", "--short=10", "HEAD"], cwd=here, capture_output=True,
                                text=True, timeout=10)
        if commit.returncode != 0:
            return None
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=here,
                               capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return commit.stdout.strip() + ("-dirty" if dirty else "")


def machine() -> str:
    """e.g. ``Linux x86_64, 2 cores, 23.4 GiB, Python 3.11.7``."""
    memory = ""
    try:
        memory = f", {os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES') / 2**30:.1f} GiB"
    except (ValueError, OSError, AttributeError):
        pass
    return f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores{memory}, Python {platform.python_version()}"


def versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {}
    for name in ("craftsuite", "torch", "stable-baselines3", "gymnasium", "mujoco"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            pass
    return out


def record_session(out, started: datetime, seconds: float, command: list[str] | None = None) -> Path:
    """Append this invocation to ``out/provenance.json``."""
    path = Path(out) / FILE
    sessions = read(out)
    if command is None:  # `python -m craftsuite` runs __main__.py: name it as users type it
        program = Path(sys.argv[0]).name
        command = ["craftsuite" if program in ("__main__.py", "craftsuite") else program, *sys.argv[1:]]
    sessions.append({"command": shlex.join(command), "started": started.astimezone(timezone.utc).isoformat(timespec="seconds"),
                     "seconds": round(seconds, 1), "commit": git_commit(), "machine": machine(),
                     "versions": versions()})
    atomic_write(path, json.dumps(sessions, indent=2) + "\n")
    return path


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
