"""Part 5's budgets: the hard suite's Grid10 budget for each paper task, by the rule in this
folder's README (fixed before any candidate ran).

    python experiments/suite-campaign/grid_budgets.py [--tasks T ...] [--out DIR]

For each task, DQN from scratch (the hard suite's own `dqn` config on Grid10, with its budget
and evaluation interval replaced: DQN anneals its exploration over a tenth of its budget, so
each candidate is its own run) at 50k, 100k, 200k and 500k transitions, 5 seeds, smallest
first. A task stops at the first candidate whose mean final greedy success is at least 0.8;
where none is, its budget stays 1M. Finished candidates are reused, so a second call resumes
where the first stopped. Prints one row per task.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from craftsuite.runs import last_success
from craftsuite.suite_runner import run_students
from craftsuite.suites import SUITES

CANDIDATES = (50_000, 100_000, 200_000, 500_000)
LEARNED = 0.8  # mean final greedy success at which a candidate counts as learning the task
FALLBACK = 1_000_000  # a task's budget where no candidate learns it
SEEDS = 5
WORLD = "Grid10"


def candidate(spec, budget: int) -> list:
    """The hard suite's scratch DQN runs of a task at ``budget``, one per seed."""
    suite = SUITES["hard"]
    return [dataclasses.replace(suite.student_config(spec, WORLD, "dqn", seed), steps=budget,
                                eval_every=suite.eval_interval(budget, WORLD)) for seed in range(SEEDS)]


def choose(finals: dict[int, float]) -> int:
    """The rule: the first candidate (smallest budget) whose mean final greedy success is at
    least ``LEARNED``; ``FALLBACK`` where none is (``finals``: mean by candidate run so far)."""
    return next((b for b in sorted(finals) if finals[b] >= LEARNED), FALLBACK)


def main(argv=None) -> None:
    suite = SUITES["hard"]
    names = [s.name for s in suite.rungs()]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", nargs="+", default=names, choices=names)
    parser.add_argument("--out", type=Path, default=Path("runs/grid-budgets"))
    # one candidate at a time (each is one population of 5): a second worker would wait
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args(argv)
    rows = []
    for spec in [s for s in suite.rungs() if s.name in args.tasks]:
        finals = {}
        for steps in CANDIDATES:
            runs = run_students(candidate(spec, steps), args.out / "students", workers=args.workers)
            finals[steps] = float(np.mean([last_success(r) for r in runs]))
            print(f"{spec.name} at {steps:,}: mean final greedy success {finals[steps]:.2f}", flush=True)
            if choose(finals) == steps:  # the rule has its budget: the larger candidates do not run
                break
        rows.append((spec.name, finals, choose(finals)))
    print("\n| task | candidate: mean final greedy success (5 seeds) | budget by the rule |")
    print("|---|---|---|")
    for name, finals, budget in rows:
        print(f"| {name} | {'; '.join(f'{s // 1000}k: {m:.2f}' for s, m in finals.items())} | {budget:,} |")


if __name__ == "__main__":
    main()
