"""Where on the ladder do the methods separate? The standard suite's runs, per rung and world.

Usage: python experiments/ladder-standard/analyze.py runs/standard

Per rung, world and method: each seed's final greedy success, the seeds that reached 80%
and the median transitions they took, the AUC (mean greedy success over training), and
two 95% intervals of the mean over seeds: the leaderboard's percentile bootstrap and a
Student t-interval (honest at 5 seeds, where the bootstrap's is too narrow). Then, per rung
and world, the pairs of methods whose intervals do not overlap, by either interval.
"""

from __future__ import annotations

import sys
from collections import defaultdict
from itertools import combinations
from pathlib import Path

import numpy as np
from scipy import stats

from craftsuite.reporting.board import rung_order, run_metrics, world_label
from craftsuite.methods import METHODS


def bootstrap_ci(values) -> tuple[float, float, float]:
    """The interval the leaderboard printed when this experiment ran: a percentile
    bootstrap of the mean over seeds (2,000 resamples)."""
    x = np.asarray(values, dtype=float)
    if len(x) < 2 or x.std() == 0:
        return float(x.mean()), float(x.mean()), float(x.mean())
    ci = stats.bootstrap((x,), np.mean, n_resamples=2_000, method="percentile", rng=0).confidence_interval
    return float(x.mean()), float(ci.low), float(ci.high)


def t_interval(values, level: float = 0.95) -> tuple[float, float, float]:
    x = np.asarray(values, dtype=float)
    mean = float(x.mean())
    if len(x) < 2:  # one seed says nothing about the spread: never "apart"
        return mean, -np.inf, np.inf
    if x.std(ddof=1) == 0:
        return mean, mean, mean
    half = stats.t.ppf((1 + level) / 2, len(x) - 1) * x.std(ddof=1) / np.sqrt(len(x))
    return mean, mean - half, mean + half


def main(root):
    students = Path(root) / "students"
    groups = defaultdict(list)
    for run in sorted(students.iterdir()):
        m = run_metrics(run)
        if m is not None:
            groups[m["task"], world_label(m["world"], m["world_kwargs"]), m["method"]].append(m)
    cells = sorted({(t, w) for t, w, _ in groups}, key=lambda k: (rung_order(k[0]), k[1]))
    print(f"{sum(map(len, groups.values()))} finished runs in {root}")
    separated = {}  # (task, world) -> pairs apart by the t-interval of final success or of AUC
    for task, world in cells:
        print(f"\n### {task} ({world})\n")
        print("| method | final success per seed | reached 80% (median transitions) | success: bootstrap | "
              "success: t | AUC: t |")
        print("|---|---|---|---|---|---|")
        rows = {}
        order = list(METHODS)
        for (t, w, method), runs in sorted(groups.items(),
                                           key=lambda g: order.index(g[0][2]) if g[0][2] in order else 99):
            if (t, w) != (task, world):
                continue
            runs.sort(key=lambda r: r["seed"])
            success = [r["success"] for r in runs]
            auc = [r["auc"] for r in runs]
            reached = [r["steps_to_80"] for r in runs if r["steps_to_80"] is not None]
            rows[method] = {"success": (bootstrap_ci(success), t_interval(success)), "auc": t_interval(auc)}
            hit = f"{len(reached)}/{len(runs)}" + (f" ({np.median(reached):,.0f})" if reached else "")
            b, t_, a = rows[method]["success"][0], rows[method]["success"][1], rows[method]["auc"]
            print(f"| {method} | {' '.join(f'{s:.2f}' for s in success)} | {hit} | {b[0]:.2f} [{b[1]:.2f}, {b[2]:.2f}] "
                  f"| [{t_[1]:.2f}, {t_[2]:.2f}] | {a[0]:.2f} [{a[1]:.2f}, {a[2]:.2f}] |")
        apart = []
        for m1, m2 in combinations(sorted(rows), 2):
            for name, pick in (("success, bootstrap", lambda r: r["success"][0]),
                               ("success, t", lambda r: r["success"][1]),
                               ("AUC, t", lambda r: r["auc"])):
                (_, lo1, hi1), (_, lo2, hi2) = pick(rows[m1]), pick(rows[m2])
                if hi1 < lo2 or hi2 < lo1:
                    apart.append(f"{m1} vs {m2} ({name})")
        print("\nIntervals that do not overlap: " + ("; ".join(apart) if apart else "none"))
        honest = [a for a in apart if "bootstrap" not in a]
        if honest:
            separated[task, world] = honest
    print("\n### Summary\n")
    for task in [t for t, w in cells if w == "Cont" and (t, w, "td3") in groups]:
        finals = [r["success"] for r in groups[task, "Cont", "td3"]]
        print(f"- td3 from scratch, {task} (Cont): final greedy success {np.mean(finals):.2f} "
              f"({sum(f >= 0.8 for f in finals)}/{len(finals)} seeds at >= 0.8)")
    print(f"- (rung, world) cells where two methods' t-intervals do not overlap: {len(separated)} of {len(cells)}")
    for (task, world), pairs in separated.items():
        print(f"  - {task} ({world}): {'; '.join(pairs)}")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "runs/standard")
