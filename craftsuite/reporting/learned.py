"""Which of a suite's rungs some method has learned, per world: the question a results page is
read for first ("does anything solve the paper's tasks in MuJoCo?"), answered from the
archived runs rather than left to be counted from the tables."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..methods import scratch
from ..suites import SUITES
from .board import THRESHOLD, Board, Entry, finite_mean, world_label


def _mean(entry: Entry) -> float:
    return finite_mean(entry.values["success"])


def _named(entry: Entry, own: tuple[str, int, str]) -> str:
    """``` `td3-dynamic` 0.99 ```, with its learner regime, budget and world settings where
    they are not the suite's own (``own``)."""
    regime, budget, world = own
    extra = ([] if entry.regime == regime else [entry.regime]) + \
        ([] if entry.budget == budget else [f"{entry.budget:,} transitions"]) + \
        ([] if entry.world_label == world else [entry.world_label])
    return f"`{entry.label}` {_mean(entry):.2f}" + (f" ({', '.join(extra)})" if extra else "")


@dataclass
class Learned:
    """One world of a suite: its rungs some method learned, those whose finished runs none
    learned and those with no finished run, each as the page names it."""

    world: str
    rungs: int
    learned: dict[str, str]  # rung -> the method named, as the page says it
    short: dict[str, str]  # rung -> its best method, as the page says it
    absent: list[str]


def learned(board: Board, suite_name: str) -> list[Learned]:
    """Per world of the suite ``suite_name`` (as defined now), the rungs some method learned
    (mean final greedy success at least ``THRESHOLD``), those whose finished runs none
    learned (with the best method's mean) and those with no finished run; an empty list for
    a name that is not a suite of this version."""
    suite = SUITES.get(suite_name)
    if suite is None:
        return []
    out = []
    for world in suite.worlds:
        row = Learned(world, len(suite.rungs()), {}, {}, [])
        for spec in suite.rungs():
            # an entry with no finite final success (every run unfinished or unread) names nothing
            here = [e for e in board if e.task == spec.name and e.world == world and math.isfinite(_mean(e))]
            if not here:
                row.absent.append(spec.name)
                continue
            config = suite.student_config(spec, world, scratch(world))
            own = (suite.regime, config.steps, world_label(world, config.env_kwargs))
            # at the suite's own setting first: a run of an older regime or budget is named after it
            best = sorted(here, key=lambda e: ((e.regime, e.budget, e.world_label) != own, -_mean(e), e.label))
            winners = [e for e in best if _mean(e) >= THRESHOLD]
            if winners:
                others = len({e.method for e in winners} - {winners[0].method})
                more = f" and {others} other method{'s' if others > 1 else ''}" if others else ""
                row.learned[spec.name] = f"{_named(winners[0], own)}{more}"
            else:
                row.short[spec.name] = f"best {_named(best[0], own)}"
        out.append(row)
    return out


def learned_markdown(found: list[Learned]) -> list[str]:
    """Lines of Markdown: ``learned``'s table (``found``); none where it has no row."""
    def named(rungs: dict[str, str]) -> str:
        return "; ".join(f"{rung} ({text})" for rung, text in rungs.items())

    rows = [f"| {r.world} | {len(r.learned)} of {r.rungs}" + (": " + named(r.learned) if r.learned else "")
            + " | " + (named(r.short) or "none") + " | " + (", ".join(r.absent) or "none") + " |"
            for r in found]
    if not rows:
        return []
    return [f"Rungs learned: some method's mean final greedy success at least {THRESHOLD:.0%}. Each rung names "
            "one method, the best at the suite's own regime, budget and world where one ran there (else the best "
            "of the others, its setting named), and how many other methods reached it in any setting:", "",
            "| world | learned | finished runs, learned by none | no finished run |", "|---|---|---|---|",
            *rows, ""]
