"""The learner-regime experiment's tables and decisions, from the records (the plan: this
folder's README): per setting, the IQM of AUC over the rungs' runs with its
stratified-bootstrap interval; per factor, each costlier setting's probability of
improvement over the incumbent, and the setting the rule keeps.

    python experiments/learner-regime/table.py [--wave 2 --n TD3_N DQN_N] [--winners TD3 DQN] [--runs DIR]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
from pathlib import Path

from craftsuite.reporting.board import run_metrics
from craftsuite.stats import aggregate_iqm, probability_of_improvement


def _driver():
    """The experiment's run.py (by path: every experiment has one), which owns the settings."""
    spec = importlib.util.spec_from_file_location("learner_regime_run", Path(__file__).with_name("run.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def auc_by_setting(driver, wave: int, ns: dict, roots: list[Path], winners: dict | None = None) -> dict:
    """{(world, setting): [AUCs of rung 1's seeds, rung 2's, ...]} for the runs found under
    ``roots`` (each a directory of a suite's runs)."""
    found = driver.finished_runs(roots)
    out = {}
    for suite in driver.RUNGS:
        for name, c in driver.configs(suite, wave, ns, winners):
            run = found.get(c.run_name())
            if run is not None:
                out.setdefault((c.world, name), {}).setdefault(c.task, []).append(run_metrics(run)["auc"])
    return {key: [aucs for _, aucs in sorted(rungs.items())] for key, rungs in out.items()}


def decide(order: list[str], aucs: dict[str, list], rungs: int, seeds: int) -> tuple[str | None, list[str]]:
    """The README's rule over the settings in ``order`` (cheapest first): the setting kept
    (None until every setting has all ``seeds`` runs on all ``rungs``), and a line per
    comparison made."""
    incumbent, lines = order[0], []
    for candidate in order[1:]:
        complete = [len(aucs.get(s, [])) == rungs and all(len(r) == seeds for r in aucs[s])
                    for s in (candidate, incumbent)]
        if not all(complete):
            lines.append(f"{candidate} against {incumbent}: not every rung has all its seeds yet")
            return None, lines
        p = probability_of_improvement(aucs[candidate], aucs[incumbent])
        wins = p.low > 0.5
        lines.append(f"P({candidate} > {incumbent}) = {p.value:.2f} [{p.low:.2f}, {p.high:.2f}]: "
                     f"{'adopted' if wins else 'not above 0.5: the cheaper stays'}")
        if wins:
            incumbent = candidate
    return incumbent, lines


def main(argv=None) -> None:
    driver = _driver()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    driver.reader_arguments(parser)
    args = parser.parse_args(argv)
    ns, winners = driver.read_settings(args)
    aucs = auc_by_setting(driver, args.wave, ns, args.runs, winners)
    for world, algorithm in driver.SCRATCH.items():
        settings = driver.settings_for(args.wave, world, ns[world], winners[world])
        print(f"\n### {algorithm.upper()} ({world})\n")
        print("| setting | overrides | runs | IQM of AUC [95% stratified bootstrap] |")
        print("|---|---|---|---|")
        mine = {name: aucs[(world, name)] for name in settings if (world, name) in aucs}
        for name, overrides in settings.items():
            if name not in mine:
                print(f"| {name} | `{json.dumps(overrides)}` | 0 | not run yet |")
                continue
            runs = sum(len(r) for r in mine[name])
            est = aggregate_iqm(mine[name]) if all(len(r) >= 2 for r in mine[name]) else None
            shown = "n/a" if est is None else f"{est.value:.2f} [{est.low:.2f}, {est.high:.2f}]"
            print(f"| {name} | `{json.dumps(overrides)}` | {runs} ({len(mine[name])} rungs) | {shown} |")
        rungs = sum(len(driver.RUNGS[suite]) for suite in driver.WAVES[args.wave])
        seeds = min(driver.SUITES[suite].seeds for suite in driver.WAVES[args.wave])
        for order in driver.factors(args.wave, world, ns[world], winners[world]):
            kept, lines = decide(order, mine, rungs, seeds)
            print("")
            for line in lines:
                print(f"- {line}")
            print(f"- kept: **{kept}**" if kept else "- undecided yet")


if __name__ == "__main__":
    main()
