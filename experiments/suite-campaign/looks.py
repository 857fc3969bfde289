"""The cells this campaign read more than once before deciding how many seeds to give them,
re-read with the error shared out over their looks.

    python experiments/suite-campaign/looks.py

A cell read at fewer seeds before its seeds grew has had more than one chance to decide, so
an interval at 95% on its final sample claims more than it has. A conservative check: read
the final sample at 1 - 0.05/k for the k looks taken (Bonferroni; a guarantee only where k
is fixed in advance and every look is read at that level, which these were not). The looks
are the archive's data (the sessions that finished its runs, and results/<suite>/looks.json:
craftsuite.reporting.looks), which the results page reads too, every interval of such a
comparison at that level. Prints, per distilled-against-scratch comparison read more than
once, the seeds a side (distilled/scratch) at each reading, Welch's interval of the
difference in final greedy success at 95% and at that level, and what that interval alone
says (the page's *ahead*/*behind* also has other routes: this checks the difference only).
"""

from __future__ import annotations

from pathlib import Path

from craftsuite import stats
from craftsuite.reporting.board import SMALLEST_DIFFERENCE
from craftsuite.reporting.looks import readings
from craftsuite.reporting.pages import comparisons
from craftsuite.reporting.sources import read_runs

SUITES = ("standard", "hard")  # each suite's archive: results/<suite>


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
        try:
            board = read_runs(Path("results", suite), suite_cells=True).board  # as the page reads it
        except FileNotFoundError:
            raise SystemExit(f"no archive at {Path('results', suite)}: run this from the project's root") from None
        for entry, base, c in comparisons([board]):
            if c is None or c.looks == 1:
                continue
            x, y = entry.values["success"], base.values["success"]
            counted = readings(entry, base)
            level = stats.shared_level(len(counted))
            plain, shared = stats.difference(x, y), stats.difference(x, y, level=level)
            seen = ", ".join(f"{a}/{'?' if b is None else b}" for a, b in counted)
            print(f"{entry.task} ({entry.world_label}, {entry.regime}, {entry.budget:,}) {entry.method} - "
                  f"{base.method}, read at {seen} seeds: {plain.value:+.2f} [{plain.low:+.2f}, {plain.high:+.2f}] "
                  f"({reading(plain)}); at {level:.1%}: [{shared.low:+.2f}, {shared.high:+.2f}] ({reading(shared)})")


if __name__ == "__main__":
    main()
