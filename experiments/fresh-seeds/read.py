"""The fresh-seeds replication's answer: the page's distilled-against-scratch verdicts on
Grid10's middle rungs, on the fresh seeds (20-99) alone and on the archive's pool of all
seeds, side by side, from the records in results/standard.

Usage: python experiments/fresh-seeds/read.py [--archive results/standard] [--first-fresh 20]
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

from craftsuite.reporting.board import build, compare, distilled_against_scratch
from craftsuite.suites import SUITES

RUNGS = ("KeySwordDragon", "ToolHome", "TwoToolsHome")
REGIME = "n-step-wide"


def seeds_from(entry, first: int):
    """``entry`` with its seeds from ``first`` on, and only theirs."""
    keep = [i for i, seed in enumerate(entry.seeds) if seed >= first]
    return dataclasses.replace(entry, seeds=[entry.seeds[i] for i in keep],
                               values={k: [v[i] for i in keep] for k, v in entry.values.items()})


def reading(entry, baseline) -> str:
    c = compare(entry, baseline)
    return (f"{c.difference.value:+.2f} [{c.difference.low:+.2f}, {c.difference.high:+.2f}], "
            f"P {c.improvement.value:.2f} [{c.improvement.low:.2f}, {c.improvement.high:.2f}]: {c.verdict}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--archive", type=Path, default=Path("results/standard"))
    parser.add_argument("--first-fresh", type=int, default=20, help="the first seed of the fresh sample")
    args = parser.parse_args()
    board = build(args.archive / "students").of_regime(REGIME)
    # the suite's budget per rung: runs at a budget it no longer asks for are another setting
    budget = {c.task: c.steps for c in SUITES["standard"].student_configs("teachers") if c.env_id.endswith("Grid10-v0")}
    print("| rung | method | seeds (fresh / all) | scratch mean (fresh / all) | fresh seeds alone | all seeds |")
    print("|---|---|---|---|---|---|")
    for rung in RUNGS:
        rows = [e for e in board if e.task == rung and e.world == "Grid10" and e.budget == budget[rung]]
        for entry, baseline in distilled_against_scratch(rows):
            fresh, fresh_base = seeds_from(entry, args.first_fresh), seeds_from(baseline, args.first_fresh)
            scratch = [sum(b.values["success"]) / max(len(b.values["success"]), 1) for b in (fresh_base, baseline)]
            print(f"| {rung} | `{entry.method}` | {len(fresh.seeds)}+{len(fresh_base.seeds)} / "
                  f"{len(entry.seeds)}+{len(baseline.seeds)} | {scratch[0]:.2f} / {scratch[1]:.2f} | "
                  f"{reading(fresh, fresh_base)} | {reading(entry, baseline)} |")


if __name__ == "__main__":
    main()
