"""How long a directory's runs took to train, as measured: by the sessions that trained them
(``provenance.json``: a session stopped part way has no duration) and by the runs
themselves (``result.json``: each run's share of its populations' wall time since step 0,
across every stop and resume, and the machine it finished on)."""

from __future__ import annotations

import re

from ..regimes import order
from ..runs import RunError, read_config, read_result
from .board import Board


def _machine_kind(machine: str | None, unknown: str) -> str:
    """What a machine as provenance describes it is counted under: its cores (``2 cores``),
    and its CPU where it names one (``2 cores of AMD EPYC (family 23 model 1, AVX2)``,
    ``provenance.cpu``), since machines of one core count train at rates several times apart."""
    parts = [part.strip() for part in (machine or "").split(",")]
    for i, part in enumerate(parts):
        found = re.fullmatch(r"(\d+) cores?", part)
        if found:  # what lies between the system (the first part) and the cores names the CPU
            return f"{found.group(1)} cores" + (f" of {', '.join(parts[1:i])}" if i > 1 else "")
    return unknown


def wall_time_lines(sessions: list[dict]) -> list[str]:
    """The directory's training time as its sessions measured it, summed per kind of machine
    (its cores, and its CPU where recorded: ``_machine_kind``): what running the suite's cells
    here took. Sessions that did not finish are counted apart (their time is not known)."""
    took: dict[str, float] = {}
    unfinished = 0
    for s in sessions:
        if not s["command"].startswith("craftsuite transfer"):
            continue  # archiving and the like train nothing
        if s.get("seconds") is None:
            unfinished += 1
            continue
        kind = _machine_kind(s.get("machine"), "machine unknown")
        took[kind] = took.get(kind, 0.0) + s["seconds"]
    if not took:
        return []
    parts = [f"{seconds / 3600:.1f} h on {kind}" for kind, seconds in sorted(took.items())]
    return [f"- Wall time of the sessions that trained these runs: {', '.join(parts)}"
            + (f"; {unfinished} session{'s' if unfinished > 1 else ''} not finished, not counted" if unfinished
               else "")]


def _timed(board: Board):
    """Each run of the board with its share of the wall time (``seconds_share``), as
    ``(entry, result, share, whole)``: ``whole`` where the share covers its whole training,
    i.e. its record holds one, or it trained in one session (then that session's wall time
    divided among its population's members is its share). A run resumed before records kept
    the share has only its last session's: not whole. Runs with no time are left out."""
    for entry in board:
        for run in entry.runs:
            try:
                result, config = read_result(run), read_config(run)
            except RunError:
                continue
            if isinstance(result.get("seconds_share"), (int, float)):
                yield entry, result, float(result["seconds_share"]), True
            elif isinstance(result.get("seconds_this_session"), (int, float)):
                share = result["seconds_this_session"] / max(1, int(result.get("members", 1)))
                yield entry, result, share, len(config.get("provenance") or []) == 1


def training_time_lines(board: Board) -> list[str]:
    """The training time the board's runs record, per learner regime and per the machine
    (``_machine_kind``) and device each finished on: each run's share of its populations' wall time
    (``_timed``), so that a population counts once. On a machine that runs one population
    per core, the wall time is about this divided by the cores. Runs whose share covers
    only their last session are counted apart."""
    took: dict[str, dict[str, float]] = {}  # regime -> machine and device -> seconds
    runs = partial = 0
    for entry, result, share, whole in _timed(board):
        kind = (f"{_machine_kind(result.get('machine'), 'machine not recorded')}, "
                f"{result.get('device', 'device not recorded')}")
        mine = took.setdefault(entry.regime, {})
        mine[kind] = mine.get(kind, 0.0) + share
        runs += 1
        partial += not whole
    if not took:
        return []
    parts = ["`" + regime + "` " + ", ".join(f"{seconds / 3600:.1f} h ({kind})"
                                             for kind, seconds in sorted(took[regime].items(), key=lambda kv: -kv[1]))
             for regime in sorted(took, key=order)]
    return [f"- Training time recorded by the {runs} runs, per learner regime and the machine each finished on (a "
            "population's wall time counted once, its members sharing it; with a population per core, the wall time "
            "on N cores is about this / N): " + "; ".join(parts)
            + (f" ({partial} of the runs were stopped and resumed before records kept the time across a stop: "
               "their last session's time only)" if partial else "")]


def rates(board: Board) -> dict[str, dict[str, float]]:
    """Per learner regime and world, the transitions per second one population process
    trained at on a CPU, as the board's runs recorded it: their transitions over their shares
    of the wall time, from the runs whose share covers their whole training (``_timed``). An
    average over the tasks, methods and population sizes that ran (a population of 10 runs
    more transitions per process than one of 5); a page reads one rate per regime and world
    wherever it projects a time, so its figures agree."""
    steps: dict[tuple[str, str], float] = {}
    seconds: dict[tuple[str, str], float] = {}
    for entry, result, share, whole in _timed(board):
        if result.get("device") != "cpu" or not whole or share <= 0:
            continue
        key = entry.regime, entry.world
        steps[key] = steps.get(key, 0.0) + result["steps"]
        seconds[key] = seconds.get(key, 0.0) + share
    out: dict[str, dict[str, float]] = {}
    for (regime, world), n in steps.items():
        out.setdefault(regime, {})[world] = n / seconds[regime, world]
    return out
