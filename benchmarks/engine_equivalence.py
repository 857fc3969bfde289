"""The two engines learn alike: TD3 students trained by SB3 (one agent per run) and by the
population engine (the seeds in one process), compared on steps to 80% and AUC.

Usage: python benchmarks/engine_equivalence.py [RUNS] [--page PATH | --no-page]

RUNS (default: the records kept in experiments/engine-equivalence/records) holds
``<engine>-<Task>/`` transfer outputs made by (Reach: 150k transitions per run, FirstTool:
400k; the suites' TD3 regime in the MuJoCo world; 10 seeds)::

    craftsuite transfer --suite quick --tasks Reach --methods td3 --seeds 10 --steps 150000 \\
        --engine population|sb3 --workers 1 --no-video --out RUNS/<engine>-Reach

``--engine sb3`` trains no more (removed with the SB3 trainer): its runs train at the commit
experiments/engine-equivalence/README.md names; this script only reads their records.

Per task and metric: each engine's median over seeds, the two-sided Mann-Whitney U test's
p-value (scipy), and the probability that a population run beats an SB3 run (ties half)
with its 95% bootstrap interval (``stats.probability_of_improvement``). Steps to 80% greedy
success count a seed that never got there as later than any that did. "Not
distinguishable" means p >= 0.05 and an interval that holds 0.5.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
from scipy.stats import mannwhitneyu

from craftsuite import stats
from craftsuite.reporting.board import run_metrics
from _page import Report, add_page_argument

ENGINES = ("population", "sb3")
RECORDS = Path(__file__).resolve().parents[1] / "experiments" / "engine-equivalence" / "records"
TASKS = ("Reach", "FirstTool")


def runs_of(root: Path, engine: str, task: str) -> list[dict]:
    students = root / f"{engine}-{task}" / "students"
    metrics = [run_metrics(run) for run in sorted(students.glob("student-*"))] if students.is_dir() else []
    return [m for m in metrics if m is not None]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", type=Path, nargs="?", default=RECORDS)
    add_page_argument(parser)
    args = parser.parse_args()
    if not any(runs_of(args.runs, engine, task) for engine in ENGINES for task in TASKS):
        print(f"engine_equivalence: no finished runs under {args.runs}; the page keeps its section "
              "(make them with the commands in this script's docstring)")
        return
    report = Report()
    report("| task | metric | population: median (seeds) | SB3: median (seeds) | Mann-Whitney p | "
           "P(population > SB3) [95%] | verdict |")
    report("|---|---|---|---|---|---|---|")
    for task in TASKS:
        runs = {engine: runs_of(args.runs, engine, task) for engine in ENGINES}
        if any(len(r) < 2 for r in runs.values()):  # a test needs two runs a side
            report(f"| {task} | | {len(runs['population'])} runs | {len(runs['sb3'])} runs | | | not compared |")
            continue
        budget = runs["sb3"][0]["budget"]
        for metric in ("steps_to_80", "auc"):
            values = {}
            for engine in ENGINES:
                raw = [r[metric] for r in runs[engine]]
                values[engine] = np.array([math.inf if v is None else float(v) for v in raw])
            # fewer steps is better: compare their negatives, so P > 0.5 always means "population better"
            sign = -1.0 if metric == "steps_to_80" else 1.0
            pop, sb3 = sign * values["population"], sign * values["sb3"]
            p = mannwhitneyu(pop, sb3, alternative="two-sided").pvalue
            better = stats.probability_of_improvement([pop], [sb3])
            same = p >= 0.05 and better.low <= 0.5 <= better.high

            def median(v):
                m = float(np.median(v))
                return "never" if math.isinf(m) else (f"{m:,.0f}" if metric == "steps_to_80" else f"{m:.2f}")

            name = "steps to 80%" if metric == "steps_to_80" else "AUC"
            report(f"| {task} ({budget:,}) | {name} | {median(values['population'])} ({len(pop)}) | "
                   f"{median(values['sb3'])} ({len(sb3)}) | {p:.2f} | {better.value:.2f} [{better.low:.2f}, "
                   f"{better.high:.2f}] | {'not distinguishable' if same else 'DIFFERENT'} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
