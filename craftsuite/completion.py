"""Success as completion, in run records of every format.

A run's ``success`` (its training episodes' and its evaluations') says that the episode
completed the task. In the grid and MuJoCo worlds, and on the kinematic board for tasks
without a tile that ends the episode, acceptance ends the episode: completing and
accepting are one event. On the kinematic board, a tile ends the episode (Blind
Craftsman's home, acting within 0.4 of (0, 0) with three tools), while the automaton may
accept earlier (its ``home`` holds in home's whole cell): success is the tile acting with
the objective met (``KinematicWorldEnv``).

Records of format 2 and before counted the automaton's acceptance on the kinematic board.
``reread`` gives such a record's logs with success as completion, where its data decide
it: a training episode completed if it was accepted and ended before its time limit (an
episode completed on its very last step reads as not completed: the logs cannot tell it
from one cut there); an evaluation's success holds where it was 0, or where every episode
ran to the limit (then it is 0). Tasks whose automaton accepts only as a tile ends the
episode (``BoardRules.acceptance_completes``: Dungeon Quest) need no re-reading.
"""

from __future__ import annotations

import gzip
import json
from pathlib import Path

from .files import atomic_write
from .record_format import required
from .runs import (EPISODE_CORE, EVAL_FIELDS, FORMAT, RunError, counts_acceptance, csv_text, read_config, read_log,
                   read_result)

REREAD = ("success re-read as completion from a record that counted the automaton's acceptance: "
          "a training episode completed if accepted and ended before its time limit")


def needs_reread(record: dict) -> bool:
    """Whether a ``config.json`` record's success counts acceptance, not completion.

    Raises:
        RunError: the record's task is unknown here, so its board cannot be read.
    """
    if not counts_acceptance(record):
        return False
    env_id = record["effective"]["world"]["id"]
    from .envs.tiles import BoardRules
    from .labelling import Labeller
    from .task_registry import resolve_task

    try:
        spec = resolve_task(record["task"])
    except (KeyError, ValueError) as err:
        raise RunError(f"{env_id}: a kinematic record of task {record['task']!r}, unknown here ({err}): "
                       "register the task to read what its success means") from None
    automaton = spec.automaton
    return not BoardRules(spec).acceptance_completes(automaton, Labeller(spec, automaton.propositions))


def time_limit(record: dict) -> int:
    """The episode limit a ``config.json`` record's world ran under."""
    import gymnasium as gym

    world = record["effective"]["world"]
    limit = world.get("kwargs", {}).get("max_episode_steps") or gym.spec(world["id"]).max_episode_steps
    return int(limit)


def reread(record: dict, episodes: list[dict], evals: list[dict]) -> tuple[list[dict], list[dict]]:
    """A record's training episodes and evaluations (``runs.read_csv`` rows) with success as
    completion; the rows as they are when the record needs no re-reading.

    Raises:
        RunError: an evaluation whose success the record cannot decide (some episodes were
            accepted and some ended early: which ones completed is not in the record).
    """
    if not needs_reread(record):
        return episodes, evals
    limit = time_limit(record)
    episodes = [{**r, "success": int(bool(int(float(r["success"]))) and int(float(r["length"])) < limit)}
                for r in episodes]
    out = []
    for r in evals:
        if float(r["success"]) > 0 and float(r["length"]) < limit:
            raise RunError(f"{record['effective']['world']['id']}: the evaluation at step {r['step']} counted "
                           f"acceptance ({r['success']}) and some episodes ended early: its completions cannot be "
                           "read from the record; train the run again")
        out.append({**r, "success": 0.0 if float(r["length"]) >= limit else r["success"]})
    return episodes, out


def reread_in_place(run: Path) -> bool:
    """Re-read a finished run's record (a run directory, or an archived record) whose success
    counted acceptance: its logs rewritten with success as completion, in the form each has
    (``episodes.csv``, or the archive's ``.gz``), its ``config.json`` of this version's
    format (not in the run key) and its ``result.json`` saying so. Returns whether it did.

    Raises:
        RunError: a record whose success its data cannot decide, or whose logs do not read
            (the file named).
    """
    run = Path(run)
    config = read_config(run)
    if not needs_reread(config):
        return False
    episodes, evals = reread_logs(run, config)
    fields = tuple(episodes[0]) if episodes else EPISODE_CORE  # the log's own columns, in its order
    if (run / "episodes.csv").exists():
        atomic_write(run / "episodes.csv", csv_text(fields, episodes))
    elif (run / "episodes.csv.gz").exists():  # mtime 0: the same log compresses to the same bytes (the archive's)
        atomic_write(run / "episodes.csv.gz", gzip.compress(csv_text(fields, episodes).encode(),
                                                           compresslevel=9, mtime=0))
    atomic_write(run / "evals.csv", csv_text(EVAL_FIELDS, evals))
    atomic_write(run / "config.json", json.dumps({**config, "format": FORMAT}, indent=2, sort_keys=True) + "\n")
    result = read_result(run)
    atomic_write(run / "result.json", json.dumps({**result, "success_reread": REREAD}, indent=2) + "\n")
    return True


def reread_logs(run: Path, config: dict) -> tuple[list[dict], list[dict]]:
    """A run's training episodes and evaluations with success as completion (``reread``).

    Raises:
        RunError: as ``reread``, or a log that does not read, naming the file.
    """
    # the columns of every record's log: one made before ``seen`` and ``states`` has only these
    return reread(config, read_log(run / "episodes.csv", required("episodes.csv")),
                  read_log(run / "evals.csv", EVAL_FIELDS, required=True))
