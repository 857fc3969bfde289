"""Tables from the JSON lines run.py wrote: learning per wall-clock second, per task and regime.

Usage: python experiments/collection-regime/summary.py results.jsonl [more.jsonl ...]
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict

import numpy as np

# the regimes run.py trained (SB3 agents' settings; run.py was removed with the SB3 trainer)
REGIMES = {
    "A": dict(n_envs=1, batch_size=64, learning_rate=1e-4, net=[64, 64]),     # the package's TD3, small net
    "B": dict(n_envs=1, batch_size=256, learning_rate=1e-3, net=[64, 64]),    # SB3 zoo's batch and lr
    "C": dict(n_envs=10, batch_size=64, learning_rate=1e-4, net=[64, 64]),    # the authors' collection
    "D": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[64, 64]),
    "E": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[64, 64]),
    "F": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[64, 64], gradient_steps=4),
    "G": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[256, 256]),
    "H": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[64, 64], prioritized=True),
    "I": dict(n_envs=4, batch_size=256, learning_rate=3e-4, net=[64, 64]),
    "J": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[256, 256]),
    "K": dict(n_envs=10, batch_size=256, learning_rate=3e-4, net=[64, 64]),  # D, a third of the step size
    # DQN on the grids (the package's DQN otherwise: dueling, double, PER, lr 5e-4, batch 64);
    # the target network is updated every 100 gradient updates in each
    "a": dict(n_envs=1, target_update_interval=100, net=[64, 64]),  # the package's
    "b": dict(n_envs=4, target_update_interval=400, net=[64, 64]),
    "c": dict(n_envs=10, target_update_interval=1_000, net=[64, 64]),  # the authors' collection
    "d": dict(n_envs=4, target_update_interval=200, gradient_steps=2, net=[64, 64]),
}


def describe(regime: dict) -> str:
    updates = regime.get("gradient_steps", 1) / regime["n_envs"]
    if "batch_size" not in regime:  # DQN
        return f"DQN, {regime['n_envs']} env(s), {updates:g} updates/transition, {regime['net']}"
    return (f"{regime['n_envs']} env(s), {updates:g} updates/transition, batch {regime['batch_size']}, "
            f"lr {regime['learning_rate']:g}, {regime['net']}" + (", PER" if regime.get("prioritized") else ""))


def main(paths):
    rows = [json.loads(line) for p in paths for line in open(p)]
    runs = defaultdict(list)
    for r in rows:
        runs[r["task"], r["regime"], r["seed"]].append(r)
    cells = defaultdict(list)
    for (task, regime, _seed), evals in runs.items():
        cells[task, regime].append(sorted(evals, key=lambda e: e["seconds"]))
    checkpoints = sorted({int(round(e["seconds"] / 10) * 10) for r in rows for e in [r]})
    marks = [m for m in (30, 60, 120, 180, 300) if m <= max(checkpoints)]
    from craftsuite.task_registry import ladder

    order = [s.name for s in ladder()]
    for task in sorted(dict.fromkeys(t for t, _ in cells), key=lambda t: order.index(t) if t in order else 99):
        print(f"\n{task}: greedy success (20 episodes) after N seconds of training, mean over seeds ('-': the "
              "runs had ended); seconds to the first evaluation at >= 0.8 (reached / seeds: median of those)")
        print("| regime | seeds | " + " | ".join(f"{m} s" for m in marks)
              + " | seconds to 0.8 | transitions/s | updates/s |")
        print("|---|---|" + "---|" * len(marks) + "---|---|---|")
        for regime in REGIMES:
            if (task, regime) not in cells:
                continue
            seeds = cells[task, regime]
            at = []
            for m in marks:
                if any(s[-1]["seconds"] < m - 1 for s in seeds):
                    at.append("-")  # a run had ended by then (its time or transition budget)
                    continue
                vals = [next((e["success"] for e in reversed(s) if e["seconds"] <= m + 1), 0.0) for s in seeds]
                at.append(f"{np.mean(vals):.2f}")
            reached = [next((e["seconds"] for e in s if e["success"] >= 0.8), None) for s in seeds]
            hit = [x for x in reached if x is not None]
            to80 = f"{len(hit)}/{len(seeds)}: {np.median(hit):.0f}" if hit else f"0/{len(seeds)}"
            tps = np.mean([s[-1]["transitions"] / s[-1]["seconds"] for s in seeds])
            ups = np.mean([s[-1]["updates"] / s[-1]["seconds"] for s in seeds])
            print(f"| {regime}: {describe(REGIMES[regime])} | {len(seeds)} | " + " | ".join(at)
                  + f" | {to80} | {tps:,.0f} | {ups:,.0f} |")


if __name__ == "__main__":
    main(sys.argv[1:])
