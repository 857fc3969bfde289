"""The cells this campaign read more than once before deciding how many seeds to give them,
re-read with the error shared out over their looks.

    python experiments/suite-campaign/looks.py

A cell read at fewer seeds before its seeds grew has had more than one chance to decide, so
an interval at 95% on its final sample claims more than it has. A conservative check: read
the final sample at 1 - 0.05/k for the k looks taken (Bonferroni; a guarantee only where k
is fixed in advance and every look is read at that level, which these
were not). The looks are the archive's data (results/<suite>/looks.json), which the results
page reads too, every interval of such a comparison at that level. Prints, per
distilled-against-scratch comparison of those cells, Welch's interval of the difference in
final greedy success at 95% and at that level, and what that interval alone says (the
page's *ahead*/*behind* also has other routes: this checks the difference only).
"""

from __future__ import annotations

from pathlib import Path

from craftsuite import stats
from craftsuite.methods import scratch
from craftsuite.reporting.board import SMALLEST_DIFFERENCE, build
from craftsuite.reporting.looks import FILE, read, readings

SUITES = ("standard", "hard")  # each suite's looks: results/<suite>/looks.json (craftsuite.reporting.looks)


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
    for suite in SUITES:
        path = Path("results", suite, FILE)
        if not path.is_file():
            continue
        board = build(path.parent / "students")
        for item in read(path):
            setting = (item["task"], item["world"], item["regime"], item["budget"])
            cell = {e.method: e for e in board.entries if (e.task, e.world, e.regime, e.budget) == setting}
            base = scratch(item["world"])
            for method in item["methods"]:
                missing = [m for m in (method, base) if m not in cell]
                if missing:
                    raise SystemExit(f"{item['task']} ({item['world']}, {item['budget']:,}): no {item['regime']} "
                                     f"runs of {', '.join(missing)} under {path.parent / 'students'}; run this from "
                                     "the project's root")
                x, y = cell[method].values["success"], cell[base].values["success"]
                counted = readings(cell[method])
                level = stats.shared_level(len(counted))
                plain, shared = stats.difference(x, y), stats.difference(x, y, level=level)
                print(f"{item['task']} ({item['world']}) {method} - {base}, {len(x)}/{len(y)} seeds, "
                      f"looks at {', '.join(map(str, counted))}: {plain.value:+.2f} "
                      f"[{plain.low:+.2f}, {plain.high:+.2f}] ({reading(plain)}); at {level:.1%}: "
                      f"[{shared.low:+.2f}, {shared.high:+.2f}] ({reading(shared)})")


if __name__ == "__main__":
    main()
