"""The record format of a student run, as data: the fields of ``config.json`` and
``result.json`` and the columns of ``evals.csv`` and ``episodes.csv``, what each means and
takes, at the record format ``runs.FORMAT``. CraftSuite's trainers write it, and so does
``craftsuite.Recorder`` for a run trained elsewhere; ``docs/records.md`` is generated from
it (``craftsuite records --markdown``), and every reader of a record checks it here
(``check_config``, ``check_result``, ``check_evals``, ``check_episodes``): a record that
breaks it is refused in one line naming the file, the field and the problem.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class Field:
    name: str
    kind: str  # as the docs say it: "string", "integer >= 0", "number in [0, 1]", ...
    required: bool
    meaning: str


CONFIG = (
    Field("task", "string", True, "the task's name: a rung of the ladder, or a task registered with "
          "`craftsuite.register_task`"),
    Field("world", "string", True, "`Cont` (MuJoCo), `Kinematic` or `Grid<size>`, e.g. `Grid10`"),
    Field("method", "string", True, "a row of `craftsuite.methods.METHODS`, or a self-reported run's own name"),
    Field("seed", "integer >= 0", True, "the run's seed"),
    Field("steps", "integer > 0", True, "the budget in transitions (env steps over all its envs)"),
    Field("eval_every", "integer > 0", False, "transitions between greedy evaluations"),
    Field("eval_episodes", "integer > 0", False, "episodes per greedy evaluation"),
    Field("layout_seed", "integer >= 0 or null", False, "a grid world's fixed instance (null: a new one per episode)"),
    Field("world_kwargs", "object", False, "`gymnasium.make` keywords of the world beyond its id"),
    Field("hyperparameters", "object", False, "CraftSuite's learner: settings beyond its algorithm's defaults"),
    Field("effective", "object", False, "CraftSuite's learner: every setting it ran with (method row, algorithm, "
          "world and the digest of its task's rules)"),
    Field("n_envs", "integer > 0", False, "envs stepped side by side"),
    Field("engine", "string", False, "what trained it: `population` or `sb3`"),
    Field("self_reported", "boolean", False, "true: trained outside CraftSuite (`craftsuite.Recorder`)"),
    Field("suite", "string", False, "self-reported: the suite whose protocol it followed"),
    Field("library", "string", False, "self-reported: what trained it"),
    Field("settings", "object", False, "self-reported: the learner's settings, as given"),
    Field("commit", "string or null", False, "self-reported: the commit of the code that trained it"),
    Field("product", "boolean", False, "self-reported: true where the agent observed the automaton state (absent: "
          "it did not)"),
    Field("rules", "string", False, "self-reported: the digest of its task's rules (CraftSuite's runs record it in "
          "`effective`); runs of a task whose rules differ are never pooled, nor are runs recorded before it was "
          "(they stand as a variant of their own)"),
    Field("format", "integer", False, "the record format (absent: 1)"),
    Field("provenance", "list", False, "per session that wrote it: time, versions, commit, machine"),
)
RESULT = (
    Field("kind", "`student`", True, "what ran (a teacher's record says `teacher`)"),
    Field("steps", "integer >= the budget", True, "the transitions collected"),
    Field("updates", "integer >= 0", False, "the gradient updates made"),
    Field("task", "string", False, "the task, as config.json says it"),
    Field("seed", "integer", False, "the seed, as config.json says it"),
    Field("method", "string", False, "the method, as config.json says it"),
    Field("self_reported", "boolean", False, "as config.json says it"),
    Field("seconds_share", "number >= 0", False, "the run's share of its training's wall time since step 0, in "
          "seconds: each session's, to its last checkpoint or the finish, divided among its population's members"),
    Field("members", "integer > 0", False, "the runs trained together as one population"),
    Field("machine", "string", False,
          "the machine it finished on (system, CPU and its widest vector instructions, cores, memory, Python)"),
)
EVALS = (
    Field("step", "integer in [0, steps]", True, "the transitions at the evaluation"),
    Field("success", "number in [0, 1]", True, "the share of its greedy episodes that completed the task"),
    Field("return", "finite number", False, "their mean return"),
    Field("episodes", "integer > 0", False, "how many episodes"),
    Field("length", "finite number", False, "their mean length in decisions"),
)
EPISODES = (
    Field("step", "integer in [0, steps]", True, "the transitions when the training episode ended"),
    Field("return", "finite number", True, "its return"),
    Field("length", "integer > 0", True, "its decisions"),
    Field("success", "0 or 1", True, "whether it completed the task"),
    Field("seen", "integer >= 0 or empty", False, "the propositions that held at some step, as bits (bit i: the "
          "automaton's i-th proposition); empty in rows written before the column"),
    Field("states", "integer >= 0 or empty", False, "the automaton states it visited, as bits (bit q: state q)"),
)
# rules of a file beyond its columns
_LINES = ("Every line ends with a line end: a last line without one is read as torn by a kill, and left out "
          "(a value cut short can keep every comma).")
NOTES = {"evals.csv": f"One row at least: every run evaluates at its end. {_LINES}", "episodes.csv": _LINES}
FILES = {"config.json": CONFIG, "result.json": RESULT, "evals.csv": EVALS, "episodes.csv": EPISODES}


def required(name: str) -> tuple[str, ...]:
    """The fields or columns every record's ``name`` (a key of ``FILES``) holds."""
    return tuple(f.name for f in FILES[name] if f.required)


class RecordError(ValueError):
    """A record that breaks the format: its message names the file, the field and the problem."""


def breaks_format(err: RecordError) -> str:
    """What a reader of records says of one that ``err`` refused."""
    return f"{err}: the record breaks the record format (docs/records.md)"


def _int(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _finite(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def check_config(config: dict, path) -> None:
    """``config.json``'s required fields, and the types of those a reader uses (a teacher's
    config, which caps its run at ``max_steps`` and has no budget, named as one)."""
    if "steps" not in config and "max_steps" in config:
        raise RecordError(f"{path} is a teacher's (max_steps, not steps), not a student's record")
    missing = [f.name for f in CONFIG if f.required and f.name not in config]
    if missing:
        raise RecordError(f"{path}: lacks {', '.join(missing)}")
    for name in ("task", "world", "method"):
        if not isinstance(config[name], str) or not config[name]:
            raise RecordError(f"{path}: {name} must be a non-empty string, got {config[name]!r}")
    if not _int(config["seed"]) or config["seed"] < 0:
        raise RecordError(f"{path}: seed must be an integer >= 0, got {config['seed']!r}")
    if not _int(config["steps"]) or config["steps"] <= 0:
        raise RecordError(f"{path}: steps (the budget in transitions) must be an integer > 0, got {config['steps']!r}")
    for name in ("eval_every", "eval_episodes"):
        if name in config and (not _int(config[name]) or config[name] <= 0):
            raise RecordError(f"{path}: {name} must be an integer > 0, got {config[name]!r}")


def check_result(result: dict, config: dict, path) -> None:
    """``result.json`` of a finished student: its transitions at least the budget, and its
    run the run ``config.json`` names."""
    if not _int(result.get("steps")):
        raise RecordError(f"{path}: steps (the transitions collected) must be an integer, got {result.get('steps')!r}")
    if result["steps"] < config["steps"]:
        raise RecordError(f"{path}: steps {result['steps']:,} is short of the budget in config.json "
                          f"({config['steps']:,}): a finished run collects its budget")
    if "updates" in result and result["updates"] is not None and (not _int(result["updates"]) or result["updates"] < 0):
        raise RecordError(f"{path}: updates must be an integer >= 0, got {result['updates']!r}")
    for name, valid, wanted in (("seconds_share", lambda v: _finite(v) and v >= 0, "a number >= 0"),
                                ("members", lambda v: _int(v) and v > 0, "an integer > 0"),
                                ("machine", lambda v: isinstance(v, str), "a string")):
        if name in result and not valid(result[name]):
            raise RecordError(f"{path}: {name} must be {wanted}, got {result[name]!r}")
    for name in ("task", "seed", "method"):
        if name in result and result[name] != config[name]:
            raise RecordError(f"{path}: {name} {result[name]!r} is not config.json's ({config[name]!r}): the result "
                              "of another run")


def check_evals(columns: dict, steps: int, path) -> dict[str, np.ndarray]:
    """``evals.csv``'s columns (as read: strings, ``runs.read_columns``): one row at least,
    steps within the run, success a rate, the means finite where given. Returns the ``step`` and ``success``
    columns as the floats it read (a reader then converts nothing twice)."""
    check_evaluated(len(columns["step"]), path)
    step = _numbers(columns["step"], "step", path)
    _refuse_first(columns, "step", path, (step != np.floor(step)) | (step < 0) | (step > steps),
                  f"is not a step of the run (0 to {steps:,} transitions)")
    success = _numbers(columns["success"], "success", path)
    _refuse_first(columns, "success", path, (success < 0) | (success > 1), "is not a rate in [0, 1]")
    for name in ("return", "length"):
        cells = columns.get(name, ())
        given = [i for i, value in enumerate(cells) if value != ""]
        _numbers([cells[i] for i in given], name, path, given)
    return {"step": step, "success": success}


def check_evaluated(rows: int, path) -> None:
    """A RecordError where ``evals.csv`` (at ``path``) holds ``rows`` = 0: a finished run,
    teacher or student, evaluates at its end."""
    if not rows:
        raise RecordError(f"{path} holds no evaluation: a finished run's record has one at least (at its end)")


def check_episodes(columns: dict, steps: int, path) -> dict[str, np.ndarray]:
    """``episodes.csv``'s columns (as read: strings): steps within the run, returns finite,
    success 0 or 1. Returns the ``step``, ``return`` and ``success`` columns as the floats it
    read."""
    step = _numbers(columns["step"], "step", path)
    _refuse_first(columns, "step", path, (step != np.floor(step)) | (step < 0) | (step > steps),
                  f"is not a step of the run (0 to {steps:,} transitions)")
    return {"step": step, "return": _numbers(columns["return"], "return", path),
            "success": completions(columns, path)}


def completions(columns: dict, path) -> np.ndarray:
    """``episodes.csv``'s ``success`` column (as read: strings) as 0/1 floats, one per
    training episode, or a RecordError naming the first line that is neither."""
    won = _numbers(columns["success"], "success", path)
    _refuse_first(columns, "success", path, (won != 0) & (won != 1), "is not 0 or 1")
    return won


def _numbers(cells, name: str, path, positions: list[int] | None = None) -> np.ndarray:
    """A column's cells as finite floats, or a RecordError naming the first line that is
    none (``positions``: each cell's row index, where the cells are some of the column's; a
    log's first row, index 0, is its line 2)."""
    def line(i: int) -> int:
        return (i if positions is None else positions[i]) + 2

    try:
        array = np.asarray(cells, dtype=float).reshape(-1)
    except (TypeError, ValueError):  # a cell that is no number: found one by one, to name it
        for i, value in enumerate(cells):
            try:
                float(value)
            except (TypeError, ValueError):
                raise RecordError(f"{path}: line {line(i)}: {name} {value!r} is not a number") from None
        raise  # (numpy refused what float() takes: not a cell's fault)
    first = np.flatnonzero(~np.isfinite(array))
    if first.size:
        raise RecordError(f"{path}: line {line(first[0])}: {name} is {cells[first[0]]}: a record holds finite numbers")
    return array


def _refuse_first(columns: dict, name: str, path, bad: np.ndarray, problem: str) -> None:
    """A RecordError naming the first line where ``bad`` holds, with its cell and ``problem``."""
    first = np.flatnonzero(bad)
    if first.size:
        raise RecordError(f"{path}: line {first[0] + 2}: {name} {columns[name][first[0]]} {problem}")


def markdown() -> str:
    """The format as a docs page (``docs/records.md``)."""
    from .runs import FORMAT

    lines = ["# Run records", "",
             "<!-- generated by `craftsuite records --markdown docs/records.md`; do not edit -->", "",
             f"A run is a directory of four files, at record format {FORMAT}. CraftSuite's trainers write them, and "
             "`craftsuite.Recorder` writes them for a run trained elsewhere (marked `self_reported`); "
             "`craftsuite leaderboard` reads any directory of them and refuses a record that breaks this format, "
             "naming the file, the field and the problem. The archive keeps `episodes.csv` gzipped "
             "(`episodes.csv.gz`). A run directory's name is `student-<task>-<world>-<method>-s<seed>-<key>`, the key "
             "a hash of its settings: two runs of equal settings are one run. A trainer's run directory holds "
             "more beside them, never read as the record: `.lock` (the advisory lock that keeps two live writers "
             "out, kept once the run is finished: a lock file deleted while another process opens it would let "
             "two in), `progress.json` (how far a run got), the model (`model.zip`, a teacher's `teacher.zip`) and, "
             "where its trainer writes them, checkpoints and TensorBoard logs; the archive keeps the four files "
             "alone (and a teacher's distilled `table.npz`).", ""]
    for name, fields in FILES.items():
        kind = "columns" if name.endswith(".csv") else "fields"
        lines += [f"## `{name}`", "", f"| {kind[:-1]} | takes | required | meaning |", "|---|---|---|---|"]
        lines += [f"| `{f.name}` | {f.kind} | {'yes' if f.required else ''} | {f.meaning} |" for f in fields]
        lines += ["", *([NOTES[name], ""] if name in NOTES else [])]
    lines += ["Format 3 made kinematic success mean completion (format 2 counted the automaton's acceptance: "
              "`craftsuite archive` re-reads such records). `seen` and `states` came within format 3; rows "
              "written before them leave them empty.", ""]
    return "\n".join(lines)


def write_markdown(path) -> Path:
    from .files import atomic_write

    path = Path(path)
    atomic_write(path, markdown())
    return path
