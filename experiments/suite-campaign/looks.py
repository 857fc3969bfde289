"""The cells this campaign read more than once before deciding how many seeds to give them,
re-read with the error shared out over their looks.

    python experiments/suite-campaign/looks.py

A cell that gets more seeds because a first reading was undecided has had more than one
chance to decide, so an interval at 95% on its final sample claims more than it has. A
conservative check: read the final sample at 1 - 0.05/k for the k looks taken (Bonferroni;
a guarantee only where k is fixed in advance and every look is read at that level, which these
were not). Prints, per distilled-against-scratch comparison of those cells, Welch's interval of
the difference in final greedy success at 95% and at that level, and what that interval alone
says (the page's *ahead*/*behind* also has other routes: this checks the difference only).
"""

from __future__ import annotations

from craftsuite import stats
from craftsuite.reporting.board import SMALLEST_DIFFERENCE, build

REGIME = "n-step-wide"
# (suite, task, world, scratch, distilled methods): the seed counts read, in order (this
# folder's README, the parts that gave each cell more seeds, and experiments/twenty-seeds and
# experiments/fresh-seeds for the Grid10 middle rungs)
LOOKS = {
    ("hard", "BlindCraftsman", "Grid10", "dqn", ("dynamic", "static")): (10, 20),
    ("hard", "GoldMine", "Grid10", "dqn", ("dynamic", "static")): (10, 20),
    ("standard", "KeySwordDragon", "Grid10", "dqn", ("dynamic", "static")): (10, 20, 100),
    ("standard", "ToolHome", "Grid10", "dqn", ("dynamic", "static")): (10, 20, 100),
    ("standard", "TwoToolsHome", "Grid10", "dqn", ("dynamic", "static")): (10, 20, 100, 150),
    ("standard", "ToolHome", "Cont", "td3", ("td3-dynamic",)): (3, 10, 20),
    ("standard", "ToolHome", "Cont", "td3", ("td3-dynamic-edges",)): (5, 10, 20),
    ("standard", "ToolHome", "Cont", "td3", ("td3-static",)): (5, 20),
}


def reading(d: stats.Estimate) -> str:
    """What the difference's interval alone says."""
    if d.low > 0:
        return "ahead"
    if d.high < 0:
        return "behind"
    if -SMALLEST_DIFFERENCE < d.low and d.high < SMALLEST_DIFFERENCE:
        return f"no difference of {SMALLEST_DIFFERENCE:g} or more"
    return "undecided"


def main() -> None:
    boards = {}
    for (suite, task, world, scratch, methods), seeds in LOOKS.items():
        board = boards.setdefault(suite, build(f"results/{suite}/students"))
        # of a method's settings on the task (budgets included), the one with the most seeds
        cell = {}
        for e in sorted(board.entries, key=lambda e: len(e.seeds)):
            if e.task == task and e.world == world and e.regime == REGIME:
                cell[e.method] = e
        level = 1 - (1 - stats.LEVEL) / len(seeds)
        for method in methods:
            missing = [m for m in (method, scratch) if m not in cell]
            if missing:
                raise SystemExit(f"{task} ({world}): no {REGIME} runs of {', '.join(missing)} under "
                                 f"results/{suite}/students; run this from the project's root")
            x, y = cell[method].values["success"], cell[scratch].values["success"]
            if not (len(x) == len(y) == seeds[-1] and cell[method].budget == cell[scratch].budget):
                raise SystemExit(f"{task} ({world}): {method} has {len(x)} seeds at {cell[method].budget:,}, "
                                 f"{scratch} {len(y)} at {cell[scratch].budget:,}; LOOKS says {seeds[-1]} each")
            plain, shared = stats.difference(x, y), stats.difference(x, y, level=level)
            print(f"{task} ({world}) {method} - {scratch}, {len(x)}/{len(y)} seeds, looks at "
                  f"{', '.join(map(str, seeds))}: {plain.value:+.2f} [{plain.low:+.2f}, {plain.high:+.2f}] "
                  f"({reading(plain)}); at {level:.1%}: [{shared.low:+.2f}, {shared.high:+.2f}] "
                  f"({reading(shared)})")


if __name__ == "__main__":
    main()
