"""Part 2 of the plan (this folder's README): each middle rung's MuJoCo budget under the
adopted regime, read from TD3-from-scratch learning curves by the rule fixed before.

    python experiments/learner-regime/budgets.py --setting n3 [--wave 1] [--n 3 3] [--winners ...]
    python experiments/learner-regime/budgets.py --setting n3 --grid-runs    # trains Grid10's candidates first

A TD3 run's curve at t transitions stands for a run of budget t (no schedule of TD3's
depends on the budget; its replay holds every transition either way), so the curves of
the regime's scratch runs give each rung's budget without new runs. DQN anneals its
exploration over a tenth of its budget: its curves do not, and its budgets need runs
(``--grid-runs``: the adopted setting's scratch DQN at each of ``GRID_BUDGETS``, 5 seeds, as
the standard suite would run it at that budget); Grid10's rule is the largest of them whose
mean final greedy success lies in [0.2, 0.8] (else today's budget).
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

import numpy as np

from craftsuite.runs import read_csv

LOW, HIGH = 0.3, 0.6  # the rule's band for scratch's mean greedy success: inside the 20-80% zone, below its middle
GRID = 50_000  # budgets are multiples of this
GRID_BUDGETS, GRID_LOW, GRID_HIGH = (30_000, 50_000, 75_000, 100_000), 0.2, 0.8  # Grid10's candidates and zone


def _driver():
    """The experiment's run.py (by path: every experiment has one), which owns the settings."""
    spec = importlib.util.spec_from_file_location("learner_regime_run", Path(__file__).with_name("run.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def mean_curve(runs: list[Path]) -> list[tuple[int, float]]:
    """The seeds' mean greedy success at each evaluation step they all have."""
    curves = [{int(float(r["step"])): float(r["success"]) for r in read_csv(run / "evals.csv")} for run in runs]
    steps = sorted(set.intersection(*(set(c) for c in curves))) if curves else []
    return [(s, float(np.mean([c[s] for c in curves]))) for s in steps]


def choose(curve: list[tuple[int, float]], budget: int) -> tuple[int, str]:
    """The rule: the largest evaluation step within ``budget`` at which the mean lies in
    [LOW, HIGH], rounded down to ``GRID`` (at least one GRID); where the mean never does,
    the current budget when scratch stays below LOW, and where it jumps past HIGH between
    two evaluations, the last step below LOW. Returns the budget and why."""
    inside = [s for s, m in curve if s <= budget and LOW <= m <= HIGH]
    if inside:
        return max(GRID, inside[-1] // GRID * GRID), f"mean {dict(curve)[inside[-1]]:.2f} at {inside[-1]:,}"
    if all(m < LOW for _, m in curve):
        return budget, "scratch stays below the band: the budget stays"
    below = [s for s, m in curve if m < LOW]
    step = below[-1] if below else curve[0][0]
    return max(GRID, step // GRID * GRID), f"the mean jumps past the band after {step:,}"


def grid_candidates(driver, setting: str, wave: int, ns: dict, winners: dict, budgets=GRID_BUDGETS) -> list:
    """The adopted setting's Grid10 scratch runs at each candidate budget: its standard-suite
    config with the budget (and the suite's evaluation interval for it) replaced."""
    import dataclasses

    from craftsuite.suites import SUITES

    suite = SUITES["standard"]
    return [dataclasses.replace(c, steps=b, eval_every=suite.eval_interval(b, c.world))
            for name, c in driver.configs("standard", wave, ns, winners) if name == setting and c.world == "Grid10"
            for b in budgets]


def grid_choice(finals: dict[int, float]) -> tuple[int, str]:
    """Grid10's rule: the largest candidate whose mean final success lies in the zone; where
    none does (the amendment of 2026-11-27, made before the second candidates were read),
    the candidate nearest the zone, the smaller budget on a tie."""
    inside = [b for b in sorted(finals) if GRID_LOW <= finals[b] <= GRID_HIGH]
    if inside:
        return inside[-1], f"mean final {finals[inside[-1]]:.2f} at {inside[-1]:,}"
    near = min(sorted(finals), key=lambda b: max(GRID_LOW - finals[b], finals[b] - GRID_HIGH))
    return near, f"no candidate in the zone; nearest: mean final {finals[near]:.2f} at {near:,}"


def main(argv=None) -> None:
    driver = _driver()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--setting", required=True, help="the adopted setting's name in run.py, e.g. n3")
    parser.add_argument("--grid-runs", action="store_true", help="train the Grid10 candidates first (into --out)")
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--grid-budgets", type=int, nargs="+", default=list(GRID_BUDGETS),
                        help="Grid10's candidate budgets (default: the plan's first ones, %(default)s); the plan's "
                             "confirmation clause runs further ones where none lands in the zone")
    driver.reader_arguments(parser)
    args = parser.parse_args(argv)
    ns, winners = driver.read_settings(args)
    candidates = grid_candidates(driver, args.setting, args.wave, ns, winners, args.grid_budgets)
    if args.grid_runs:
        from craftsuite.suite_runner import run_students

        held = driver.finished_runs(args.runs)
        todo = [c for c in candidates if c.run_name() not in held]
        print(f"Grid10 candidates: {len(candidates)} runs, {len(todo)} to train "
              f"({sum(c.steps for c in todo):,} transitions)")
        if todo:
            run_students(todo, args.out / "standard" / "students", workers=args.workers)
    found = driver.finished_runs(args.runs)
    print("| rung | budget now | candidate: seeds, mean final greedy success | budget by the rule | why |")
    print("|---|---|---|---|---|")
    for c in [c for name, c in driver.configs("standard", args.wave, ns, winners)
              if name == args.setting and c.world == "Grid10" and c.seed == 0]:
        finals, shown = {}, []
        for b in sorted(args.grid_budgets):
            runs = [found[r.run_name()] for r in candidates if r.task == c.task and r.steps == b
                    and r.run_name() in found]
            if runs:
                finals[b] = float(np.mean([float(read_csv(r / "evals.csv")[-1]["success"]) for r in runs]))
                shown.append(f"{b // 1000}k: {len(runs)}, {finals[b]:.2f}")
        budget, why = grid_choice(finals) if finals else (c.steps, "no runs found")
        print(f"| {c.task} | {c.steps:,} | {'; '.join(shown)} | {budget:,} | {why} |")
    print()
    found = driver.finished_runs(args.runs)
    print("| rung | budget now | seeds | mean greedy success at the evaluations | budget by the rule | why |")
    print("|---|---|---|---|---|---|")
    for name, c in driver.configs("standard", args.wave, ns, winners):
        if name != args.setting or c.world != "Cont" or c.seed != 0:
            continue
        seeds = [found[s.run_name()] for _, s in driver.configs("standard", args.wave, ns, winners)
                 if _ == name and s.world == "Cont" and s.task == c.task and s.run_name() in found]
        curve = mean_curve(seeds)
        shown = " ".join(f"{m:.2f}" for _, m in curve)
        budget, why = choose(curve, c.steps) if curve else (c.steps, "no runs found")
        print(f"| {c.task} | {c.steps:,} | {len(seeds)} | {shown} | {budget:,} | {why} |")


if __name__ == "__main__":
    main()
