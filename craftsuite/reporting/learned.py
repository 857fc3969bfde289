"""Which of a suite's rungs some method has learned, per world: the question a results page is
read for first ("does anything solve the paper's tasks in MuJoCo?"), answered from the
archived runs rather than left to be counted from the tables."""

from __future__ import annotations

from ..suites import SUITES
from .board import THRESHOLD, Board, Entry


def _mean(entry: Entry) -> float:
    values = [v for v in entry.values["success"] if v == v]  # NaN: a run without an evaluation
    return sum(values) / len(values) if values else float("nan")


def _named(entry: Entry, regime: str, budget: int) -> str:
    """``td3-dynamic` 0.99``, with the learner regime and budget where they are not the suite's."""
    extra = ([] if entry.regime == regime else [entry.regime]) + ([] if entry.budget == budget
                                                                    else [f"{entry.budget:,} transitions"])
    return f"`{entry.label}` {_mean(entry):.2f}" + (f" ({', '.join(extra)})" if extra else "")


def learned_markdown(board: Board, suite_name: str) -> list[str]:
    """Lines of Markdown: per world of the suite ``suite_name`` (as defined now), the rungs
    some method learned (mean final greedy success at least ``THRESHOLD``), those run but
    learned by none (with the best method's mean) and those not run. None for a name that is
    not a suite of this version."""
    suite = SUITES.get(suite_name)
    if suite is None:
        return []
    rows = []
    for world in suite.worlds:
        learned, short, absent = [], [], []
        for spec in suite.rungs():
            here = [e for e in board if e.task == spec.name and e.world == world and _mean(e) == _mean(e)]
            if not here:
                absent.append(spec.name)
                continue
            budget = suite.budget(spec, world)
            # the suite's own setting first: a run of an older regime or budget is named after it
            best = sorted(here, key=lambda e: ((e.regime, e.budget) != (suite.regime, budget), -_mean(e), e.label))
            winners = [e for e in best if _mean(e) >= THRESHOLD]
            if winners:
                more = f" and {len(winners) - 1} more" if len(winners) > 1 else ""
                learned.append(f"{spec.name} ({_named(winners[0], suite.regime, budget)}{more})")
            else:
                short.append(f"{spec.name} (best {_named(best[0], suite.regime, budget)})")
        rows.append(f"| {world} | {len(learned)} of {len(suite.rungs())}"
                    + (": " + "; ".join(learned) if learned else "") + " | " + ("; ".join(short) or "none")
                    + " | " + (", ".join(absent) or "none") + " |")
    return [f"Rungs learned: some method's mean final greedy success at least {THRESHOLD:.0%} (the best "
            "method that reached it, with its mean, and how many others did; a learner regime or budget other "
            f"than the suite's `{suite.regime}` and its budget is named):", "",
            "| world | learned | run, learned by none | not run |", "|---|---|---|---|", *rows, ""]
