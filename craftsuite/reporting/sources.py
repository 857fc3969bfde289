"""A directory of runs as the reports read it: its student runs as a board, the suite that
made it and the sessions that ran (``provenance.json``)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from ..suites import SUITES
from . import looks
from .board import Board, build


@dataclass
class RunsDirectory:
    path: Path  # as given: a transfer output, or a directory of student runs
    students: Path  # where its student runs lie: ``students/`` of a transfer output, or the path itself
    board: Board
    suite: dict  # the suite as last run into it (``suite.json``; empty: none)
    sessions: list[dict]  # the sessions that made it (``provenance.json``; empty: none)

    @property
    def name(self) -> str:
        """The suite it holds runs of: its suite.json's, else the directory's name
        (``results/<suite>``)."""
        return _name(self.suite, self.path)


def _name(suite: dict, path: Path) -> str:
    return suite.get("name", path.name)


def superseded(suite, students: Path):
    """A test of a run's ``config.json``: a run of ``suite``'s rungs, worlds and learner
    regime at a budget other than the one the suite asks for now (its budget re-calibrated
    since the run trained, or a candidate its calibration tried), on a rung and world whose
    cell at today's budget has runs under ``students``. Such runs stay in the archive but
    are not the suite's cell; where the cell has no run (a directory trained with
    ``--steps``, say), the runs there are the rung's only ones and are not set apart."""
    from ..runs import RunError, read_config
    from .board import regime_of

    rungs = {spec.name: spec for spec in suite.rungs()}

    def mine(config: dict) -> bool | None:
        """Whether the run is at the suite's budget; None: not a run of the suite's cells."""
        spec = rungs.get(config.get("task"))
        if spec is None or config.get("world") not in suite.worlds or regime_of(config) != suite.regime:
            return None
        return config["steps"] == suite.budget(spec, config["world"])

    held = set()  # (task, world) whose cell at today's budget has runs here
    for run in sorted(students.iterdir()) if students.is_dir() else []:
        try:
            config = read_config(run)
            if mine(config):
                held.add((config["task"], config["world"]))
        except (RunError, OSError, ValueError, KeyError, TypeError):
            continue  # build names the damaged records

    def test(config: dict) -> bool:
        return mine(config) is False and (config["task"], config["world"]) in held

    return test


def read_runs(path, *, transfer: bool = False, suite_cells: bool = False, keep=None, only: str = "",
              required: bool = True) -> RunsDirectory:
    """The runs under ``path``; ``transfer``: ``path`` must be a transfer output (with ``students/``);
    ``suite_cells``: in the directory of a suite of this version (``RunsDirectory.name``), its
    runs at budgets the suite no longer asks for, beside runs at the budget it does, are set
    apart (``superseded``, ``Board.apart``). ``keep``: a test of a run's ``config.json``, as
    ``board.build``'s (the runs it holds false for are not read further); ``only``: those runs
    in words, for the message where none is left (e.g. `` of --tasks Reach``); ``required``:
    whether a directory with no finished (kept) run is refused (one of several need not be).

    Raises:
        FileNotFoundError: no such directory.
        ValueError: no finished student run in it (where ``required``), with the unfinished
            counted and each damaged record named; or a damaged ``suite.json``,
            ``provenance.json`` or ``looks.json`` (``looks.check``: not checked with ``keep``).
    """
    from ..provenance import read

    path = Path(path)
    students = path / "students" if (path / "students").is_dir() else path
    if transfer and students == path:
        raise FileNotFoundError(f"{path} is not a transfer output directory (no students/)")
    if not students.is_dir():
        raise FileNotFoundError(f"no run directory at {path}")
    suite = suite_json(path)
    asked = SUITES.get(_name(suite, path)) if suite_cells else None
    board = build(students, apart=None if asked is None else superseded(asked, students), keep=keep)
    unfinished = len(board.unfinished) + (len(board.apart.unfinished) if board.apart else 0)
    if required and not board.entries and not (board.apart and board.apart.entries):
        raise ValueError(f"no finished student runs{only} under {students}"
                         + (f" ({unfinished} unfinished)" if unfinished else "")
                         + "".join(f"; not read: {reason}" for reason in board.unreadable)
                         + _runs_elsewhere(path))
    if keep is None:  # a narrowed board holds some of the cells looks.json names: the whole directory checks it
        looks.check([*board.entries, *(board.apart.entries if board.apart else [])])
    return RunsDirectory(path, students, board, suite, read(path))


def _runs_elsewhere(path: Path) -> str:
    """Where the runs are, for a path given a level too low (one run's own directory) or too
    high (a results archive, whose suites each hold a runs directory): the path to give
    instead, or nothing."""
    if (path / "config.json").is_file():
        holder = path.parent.parent if path.parent.name in ("students", "teachers") else path.parent
        return f"; it is one run's directory: give the directory of runs that holds it ({holder})"
    inner = sorted(p for p in path.iterdir() if (p / "students").is_dir())
    if inner:
        return (f"; its folders hold runs: give one or more of them ({' '.join(map(str, inner[:4]))}"
                + (", ..." if len(inner) > 4 else "") + ")")
    return ""


_SUITE_FIX = "move it aside (the suite's next transfer into the directory writes it again), or give another directory"


def suite_json(path: Path) -> dict:
    """The suite as last run into ``path`` (``suite.json``; empty: none)."""
    if not (path / "suite.json").exists():
        return {}
    try:
        suite = json.loads((path / "suite.json").read_text())
    except ValueError as err:
        raise ValueError(f"{path / 'suite.json'} is not valid JSON ({err}): {_SUITE_FIX}") from None
    if not isinstance(suite, dict):
        raise ValueError(f"{path / 'suite.json'} is not a suite's record (a JSON object): {_SUITE_FIX}")
    return suite


def session_line(session: dict, *, to_the_minute: bool) -> str:
    """A session of ``provenance.json`` as a list item: its command, when it started (the
    day, or ``to_the_minute``), the commit, how long it took and on what machine."""
    s = session
    started = s["started"][:16].replace("T", " ") + " UTC" if to_the_minute else s["started"][:10]
    took = "did not finish" if s.get("seconds") is None else f"{s['seconds'] / 60:.{1 if to_the_minute else 0}f} min"
    return f"- `{s['command']}`: {started}, commit {s.get('commit') or 'unknown'}, {took} on {s['machine']}"
