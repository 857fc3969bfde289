"""How long a directory's runs took to train, as measured: by the sessions that trained them
(``provenance.json``: a session stopped part way has no duration) and by the runs
themselves (``result.json``: a population's training seconds since step 0, across every
stop and resume, and the machine it finished on)."""

from __future__ import annotations

import re

from ..runs import RunError, read_result
from .board import Board


def wall_time_lines(sessions: list[dict]) -> list[str]:
    """The directory's training time as its sessions measured it, summed per kind of machine
    (its cores): what running the suite's cells here took. Sessions that did not finish are
    counted apart (their time is not known)."""
    took: dict[str, float] = {}
    unfinished = 0
    for s in sessions:
        if not s["command"].startswith("craftsuite transfer"):
            continue  # archiving and the like train nothing
        if s.get("seconds") is None:
            unfinished += 1
            continue
        cores = re.search(r"(\d+) cores?", s.get("machine", ""))
        kind = f"{cores.group(1)} cores" if cores else "machine unknown"
        took[kind] = took.get(kind, 0.0) + s["seconds"]
    if not took:
        return []
    parts = [f"{seconds / 3600:.1f} h on {kind}" for kind, seconds in sorted(took.items())]
    return [f"- Wall time of the sessions that trained these runs: {', '.join(parts)}"
            + (f" ({unfinished} session{'s' if unfinished > 1 else ''} not finished, not counted)" if unfinished
               else "")]


def training_time_lines(board: Board) -> list[str]:
    """The training time the board's runs record, per learner regime and per machine (its
    cores) and device: each population's once (its members share its wall time, so each
    member counts its share). On a machine that runs one population per core, the wall
    time is about this divided by the cores. Runs whose records keep only their last
    session's time are counted apart."""
    took: dict[str, dict[str, float]] = {}  # regime -> machine and device -> seconds
    runs = partial = 0
    for entry in board:
        for run in entry.runs:
            try:
                result = read_result(run)
            except RunError:
                continue
            seconds = result.get("seconds", result.get("seconds_this_session"))
            if not isinstance(seconds, (int, float)):
                continue
            cores = re.search(r"(\d+) cores?", result.get("machine", ""))
            kind = (f"{cores.group(1)} cores, " if cores else "") + result.get("device", "cpu")
            mine = took.setdefault(entry.regime, {})
            mine[kind] = mine.get(kind, 0.0) + seconds / max(1, int(result.get("members", 1)))
            runs += 1
            partial += "seconds" not in result
    if not took:
        return []
    parts = ["`" + regime + "` " + ", ".join(f"{seconds / 3600:.1f} h ({kind})"
                                             for kind, seconds in sorted(kinds.items(), key=lambda kv: -kv[1]))
             for regime, kinds in took.items()]
    return [f"- Training time recorded by the {runs} runs, per learner regime (a population's wall time counted "
            "once, its members sharing it; with a population per core, the wall time on N cores is about this / N): "
            + "; ".join(parts)
            + (f" ({partial} of the runs come from before their records kept the time across a stop and resume: "
               "their last session's time only)" if partial else "")]
