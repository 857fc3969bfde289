"""A directory of runs as the reports read it: its student runs as a board, the suite that
made it and the sessions that ran (``provenance.json``)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from .board import Board, build


@dataclass
class RunsDirectory:
    path: Path  # as given: a transfer output, or a directory of student runs
    students: Path  # where its student runs lie: ``students/`` of a transfer output, or the path itself
    board: Board
    suite: dict  # the suite as last run into it (``suite.json``; empty: none)
    sessions: list[dict]  # the sessions that made it (``provenance.json``; empty: none)


def read_runs(path, *, transfer: bool = False) -> RunsDirectory:
    """The runs under ``path``; ``transfer``: ``path`` must be a transfer output (with ``students/``).

    Raises:
        FileNotFoundError: no such directory.
        ValueError: no finished student run in it, with the unfinished counted and each
            damaged record named; or a damaged ``suite.json`` or ``provenance.json``.
    """
    from ..provenance import read

    path = Path(path)
    students = path / "students" if (path / "students").is_dir() else path
    if transfer and students == path:
        raise FileNotFoundError(f"{path} is not a transfer output directory (no students/)")
    if not students.is_dir():
        raise FileNotFoundError(f"no run directory at {path}")
    board = build(students)
    if not board.entries:
        raise ValueError(f"no finished student runs under {students}"
                         + (f" ({len(board.unfinished)} unfinished)" if board.unfinished else "")
                         + "".join(f"; not read: {reason}" for reason in board.unreadable))
    suite = {}
    if (path / "suite.json").exists():
        try:
            suite = json.loads((path / "suite.json").read_text())
        except ValueError as err:
            raise ValueError(f"{path / 'suite.json'} is not valid JSON ({err})") from None
    return RunsDirectory(path, students, board, suite, read(path))


def session_line(session: dict, *, to_the_minute: bool) -> str:
    """A session of ``provenance.json`` as a list item: its command, when it started (the
    day, or ``to_the_minute``), the commit, how long it took and on what machine."""
    s = session
    started = s["started"][:16].replace("T", " ") + " UTC" if to_the_minute else s["started"][:10]
    took = "did not finish" if s.get("seconds") is None else f"{s['seconds'] / 60:.{1 if to_the_minute else 0}f} min"
    return f"- `{s['command']}`: {started}, commit {s.get('commit') or 'unknown'}, {took} on {s['machine']}"
