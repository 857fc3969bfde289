"""How often do the leaderboard's 95% intervals cover the truth, and what does rliable cost?

Usage: python benchmarks/interval_coverage.py [--trials N] [--page PATH | --no-page]

Coverage, on simulated normal seeds (mean 0.3, sd 0.2), of a 95% interval of the mean:
the Student t-interval the leaderboard starts from (``craftsuite.stats.t_interval``; on a
rate's [0, 1] it widens it near the bounds: ``mean_interval``) beside the
percentile bootstrap of the mean it used before (``scipy.stats.bootstrap``, 2,000
resamples). Then the stratified-bootstrap interval of the IQM across 4 tasks x 5 seeds
(``craftsuite.stats.aggregate_iqm``), on symmetric data, whose population IQM is its mean.
The reference is the nominal 95%; the binomial standard error over N trials is
sqrt(0.95 * 0.05 / N) (0.5 points at N = 2,000).

Last, the import cost of the statistics: ``scipy.stats`` (what CraftSuite imports) against
``rliable`` (with arch, statsmodels and pandas), each in a fresh process.
"""

from __future__ import annotations

import argparse
import subprocess
import sys

import numpy as np
from scipy import stats as scipy_stats

from craftsuite import stats
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

MEAN, SD = 0.3, 0.2


def coverage_of_the_mean(n: int, trials: int, rng) -> tuple[float, float]:
    t_hits = boot_hits = 0
    for sample in rng.normal(MEAN, SD, size=(trials, n)):
        e = stats.t_interval(sample)
        t_hits += e.has_interval and e.low <= MEAN <= e.high
        if n >= 2:
            ci = scipy_stats.bootstrap((sample,), np.mean, n_resamples=2_000, method="percentile",
                                       rng=rng).confidence_interval
            boot_hits += ci.low <= MEAN <= ci.high
    return t_hits / trials, boot_hits / trials


def coverage_of_the_iqm(trials: int, rng, tasks: int = 4, seeds: int = 5) -> float:
    hits = 0
    for _ in range(trials):
        e = stats.aggregate_iqm(list(rng.normal(MEAN, SD, size=(tasks, seeds))))
        hits += e.low <= MEAN <= e.high
    return hits / trials


def import_seconds(statement: str, repeats: int = 3) -> float | None:
    code = f"import time; t = time.perf_counter(); {statement}; print(time.perf_counter() - t)"
    times = []
    for _ in range(repeats):
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
        if done.returncode != 0:
            return None
        times.append(float(done.stdout))
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=2_000)
    add_page_argument(parser)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    report = Report()
    report(f"Coverage of a 95% interval of the mean over {args.trials:,} simulated cases (reference: 0.95; "
           f"standard error {np.sqrt(0.95 * 0.05 / args.trials):.3f}):")
    report()
    report("| seeds | t-interval (the leaderboard's) | percentile bootstrap (before) |")
    report("|---|---|---|")
    for n in (2, 3, 5, 10):
        t_cov, boot_cov = coverage_of_the_mean(n, args.trials, rng)
        t_text = f"{t_cov:.3f}" if n >= stats.MIN_SEEDS_FOR_INTERVAL else "none (below its minimum of seeds)"
        report(f"| {n} | {t_text} | {boot_cov:.3f} |")
    report()
    report(f"Stratified-bootstrap IQM interval, 4 tasks x 5 seeds: coverage "
           f"{coverage_of_the_iqm(args.trials, rng):.3f} over {args.trials:,} cases (reference: 0.95).")
    report()
    report("| import (fastest of 3 fresh processes) | seconds |")
    report("|---|---|")
    for name, statement in (("scipy.stats (what CraftSuite imports)", "import scipy.stats"),
                            ("rliable", "from rliable import library, metrics")):
        seconds = import_seconds(statement)
        report(f"| {name} | " + (f"{seconds:.2f}" if seconds is not None else "not installed") + " |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
