"""Which of a suite's rungs some method has learned, per world: the question a results page is
read for first ("does anything solve the paper's tasks in MuJoCo?"), answered from the
archived runs rather than left to be counted from the tables."""

from __future__ import annotations

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


def learned_markdown(board: Board, suite_name: str) -> list[str]:
    """Lines of Markdown: per world of the suite ``suite_name`` (as defined now), the rungs
    some method learned (mean final greedy success at least ``THRESHOLD``), those whose
    finished runs none learned (with the best method's mean) and those with no finished run.
    No lines for a name that is not a suite of this version."""
    suite = SUITES.get(suite_name)
    if suite is None:
        return []
    rows = []
    for world in suite.worlds:
        learned, short, absent = [], [], []
        for spec in suite.rungs():
            here = [e for e in board if e.task == spec.name and e.world == world and _mean(e) > -1]
            if not here:
                absent.append(spec.name)
                continue
            config = suite.student_config(spec, world, scratch(world))
            own = (suite.regime, config.steps, world_label(world, config.env_kwargs))
            # at the suite's own setting first: a run of an older regime or budget is named after it
            best = sorted(here, key=lambda e: ((e.regime, e.budget, e.world_label) != own, -_mean(e), e.label))
            winners = [e for e in best if _mean(e) >= THRESHOLD]
            if winners:
                others = len({e.method for e in winners} - {winners[0].method})
                more = f" and {others} other method{'s' if others > 1 else ''}" if others else ""
                learned.append(f"{spec.name} ({_named(winners[0], own)}{more})")
            else:
                short.append(f"{spec.name} (best {_named(best[0], own)})")
        rows.append(f"| {world} | {len(learned)} of {len(suite.rungs())}"
                    + (": " + "; ".join(learned) if learned else "") + " | " + ("; ".join(short) or "none")
                    + " | " + (", ".join(absent) or "none") + " |")
    return [f"Rungs learned: some method's mean final greedy success at least {THRESHOLD:.0%}. Each rung names "
            "one method, the best at the suite's own regime, budget and world where one ran there (else the best "
            "of the others, its setting named), and how many other methods reached it in any setting:", "",
            "| world | learned | finished runs, learned by none | no finished run |", "|---|---|---|---|",
            *rows, ""]
