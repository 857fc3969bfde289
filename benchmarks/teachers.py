"""Teachers: env steps and minutes to 90% greedy success per task (7x7 grids, product DQN).

Usage: python benchmarks/teachers.py [--tasks ...] [--max-steps N] [--seed S] [--out DIR]

Trains CraftSuite's teacher (dueling double DQN with prioritized replay over the product
MDP, on one fixed 7x7 instance as in the paper: ``layout_seed=0``) with ``train_teacher``,
the same code as ``craftsuite teacher``. Every 5,000 steps its greedy policy plays 50
episodes from fresh start positions (seeds never used in training); it stops at the first
evaluation with >= 90% success. One task at a time, so the minutes are those of one
process on an otherwise idle machine. Teachers that already finished under ``--out`` are
reused, not retrained (their minutes are those of the run that trained them).
"""

from __future__ import annotations

import argparse
import json

import craftsuite  # noqa: F401
from craftsuite.runs import read_csv
from craftsuite.training import TeacherConfig, train_teacher


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", nargs="*", default=["BlindCraftsman", "DungeonQuest", "DiamondMine"])
    parser.add_argument("--max-steps", type=int, default=300_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/teachers")
    args = parser.parse_args()
    import torch
    torch.set_num_threads(1)

    rows = []
    for task in args.tasks:
        path = train_teacher(TeacherConfig(task=task, seed=args.seed, max_steps=args.max_steps), args.out)
        result = json.loads((path / "result.json").read_text())
        curve = " ".join(f"{int(r['step']) // 1000}k:{float(r['success']):.2f}" for r in read_csv(path / "evals.csv"))
        rows.append((task, result, curve, path))
    print("\n| task | env steps to >= 90% greedy success | minutes | success at stop | evaluations (step:success) |")
    print("|---|---|---|---|---|")
    for task, r, curve, path in rows:
        reached = f"{r['steps']:,}" if r["reached_target"] else f"not within {r['steps']:,}"
        print(f"| {task} | {reached} | {r['seconds_this_session'] / 60:.1f} | {r['success']:.2f} | {curve} |")
    print("\nteachers and tables: " + ", ".join(str(p) for *_, p in rows))


if __name__ == "__main__":
    main()
