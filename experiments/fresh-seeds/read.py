"""The fresh-seeds replication's answer: the page's distilled-against-scratch verdicts on
Grid10's middle rungs, on the fresh seeds alone and on the archive's pool of all seeds, side
by side, from the records in results/standard.

Usage: python experiments/fresh-seeds/read.py [--archive results/standard] [--seeds 20 99] [--partial]

The fresh sample is one reading, planned before it ran; the pool is read as the page reads it,
at the level of its looks (``craftsuite.reporting.looks``). The plan reads the fresh sample
only when it is whole: while any of the nine cells lacks a fresh seed, this names what is
missing and reads nothing (exit 1). ``--partial`` reads the seeds that every cell has, as the
plan says for a sample cut short.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from craftsuite.reporting.board import build, compare, finite_mean
from craftsuite.reporting.looks import looks
from craftsuite.suites import SUITES

RUNGS = ("KeySwordDragon", "ToolHome", "TwoToolsHome")
METHODS = ("dqn", "static", "dynamic")
REGIME = "n-step-wide"


def reading(entry, baseline, looks: int = 1) -> str:
    """The page's verdict on ``entry`` against ``baseline`` read ``looks`` times."""
    c = compare(entry, baseline, looks=looks)
    return (f"{c.difference.value:+.2f} [{c.difference.low:+.2f}, {c.difference.high:+.2f}], "
            f"P {c.improvement.value:.2f} [{c.improvement.low:.2f}, {c.improvement.high:.2f}]: {c.said}")


def cells(board, budget: dict) -> dict:
    """The board's entries of the nine cells, by (rung, method), at the suite's budgets."""
    return {(e.task, e.method): e for e in board if e.world == "Grid10" and e.task in RUNGS
            and e.method in METHODS and e.budget == budget[e.task]}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--archive", type=Path, default=Path("results/standard"))
    parser.add_argument("--seeds", type=int, nargs=2, default=(20, 99), metavar=("FIRST", "LAST"),
                        help="the fresh sample's seeds (default: 20 99)")
    parser.add_argument("--partial", action="store_true", help="read the fresh seeds every cell has")
    args = parser.parse_args()
    first, last = args.seeds
    # the suite's budget per rung: runs at a budget it no longer asks for are another setting
    budget = {c.task: c.steps for c in SUITES["standard"].student_configs("teachers")
              if c.world == "Grid10" and c.task in RUNGS}
    if set(budget) != set(RUNGS):
        sys.exit(f"the standard suite has no Grid10 budget for {sorted(set(RUNGS) - set(budget))}: "
                 "this reading is of its middle rungs")
    if not (args.archive / "students").is_dir():
        sys.exit(f"{args.archive / 'students'}: no such directory; give --archive the suite's archive, "
                 "e.g. results/standard")
    pooled = build(args.archive / "students").of_regime(REGIME)
    fresh = build(args.archive / "students", apart=lambda c: not first <= c["seed"] <= last).of_regime(REGIME)
    fresh_cells, wanted = cells(fresh, budget), set(range(first, last + 1))
    have = {cell: set(fresh_cells[cell].seeds) if cell in fresh_cells else set()
            for cell in ((r, m) for r in RUNGS for m in METHODS)}
    missing = {cell: len(wanted - seeds) for cell, seeds in have.items() if wanted - seeds}
    if missing:
        print("fresh seeds missing: " + "; ".join(f"{r} {m}: {n}" for (r, m), n in missing.items()))
        if not args.partial:
            sys.exit(1)
        common = set.intersection(*have.values())
        print(f"reading the {len(common)} fresh seeds every cell has")
        fresh = build(args.archive / "students", apart=lambda c: c["seed"] not in common).of_regime(REGIME)
        fresh_cells = cells(fresh, budget)
    pooled_cells = cells(pooled, budget)
    print("| rung | method | seeds a side (fresh / all) | scratch mean (fresh / all) | fresh seeds alone | all seeds |")
    print("|---|---|---|---|---|---|")
    for rung in RUNGS:
        for method in METHODS[1:]:
            # (the distilled method against scratch, as the page's distilled_against_scratch pairs them)
            row = [(found.get((rung, method)), found.get((rung, "dqn"))) for found in (fresh_cells, pooled_cells)]
            if None in (side for pair in row for side in pair):
                print(f"| {rung} | `{method}` | no comparison: a side has no runs at the suite's budget | | | |")
                continue
            (f, fb), (p, pb) = row
            mean = [finite_mean(b.values["success"]) for b in (fb, pb)]
            print(f"| {rung} | `{f.label}` | {len(f.seeds)}+{len(fb.seeds)} / {len(p.seeds)}+{len(pb.seeds)} "
                  f"| {mean[0]:.2f} / {mean[1]:.2f} | {reading(f, fb)} | {reading(p, pb, looks(p, pb))} |")


if __name__ == "__main__":
    main()
