"""Teachers: env steps and minutes to 90% greedy success per task (7x7 grids, product DQN).

Usage: python benchmarks/teachers.py [--quick | --tasks ...] [--max-steps N] [--seed S] [--out DIR]
       [--page PATH | --no-page]

Target: every teacher reaches 90% greedy success within its step limit. Trains
CraftSuite's teacher (dueling double DQN with prioritized replay over the product MDP, on
one fixed 7x7 instance as in the paper: ``layout_seed=0``) with ``train_teacher``,
the same code as ``craftsuite teacher``. Every 5,000 steps its greedy policy plays 50
episodes from fresh start positions (seeds never used in training); it stops at the first
evaluation with >= 90% success. One task at a time, one torch thread. By default the
paper's three tasks (about 8 minutes on an idle core); ``--quick`` trains the quick suite's
teachers (Reach, FirstTool) instead, as ``make bench`` does. Without ``--out`` every
teacher trains afresh in a temporary directory; teachers that already finished under a
given ``--out`` are reused, not retrained (their minutes are those of the run that trained
them). Greedy success jumps rather than climbs: a greedy policy on one instance either has
a path from every start cell or loops somewhere.
"""

from __future__ import annotations

import argparse
import json
import tempfile

import craftsuite  # noqa: F401
from craftsuite.configs import TeacherConfig
from craftsuite.runs import read_csv
from craftsuite.training import train_teacher
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

PAPER_TASKS = ["BlindCraftsman", "DungeonQuest", "DiamondMine"]
QUICK_TASKS = ["Reach", "FirstTool"]  # the quick suite's teachers


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    tasks = parser.add_mutually_exclusive_group()
    tasks.add_argument("--tasks", nargs="+", default=PAPER_TASKS)
    tasks.add_argument("--quick", action="store_true", help=f"the quick suite's teachers: {', '.join(QUICK_TASKS)}")
    parser.add_argument("--max-steps", type=int, default=300_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", help="keep (and reuse) the teachers here; default: a fresh temporary directory")
    add_page_argument(parser)
    args = parser.parse_args()
    import torch
    torch.set_num_threads(1)

    with tempfile.TemporaryDirectory(prefix="craftsuite-teachers-") as scratch:
        train(QUICK_TASKS if args.quick else args.tasks, args, args.out or scratch)


def train(tasks: list[str], args, out: str) -> None:
    rows = []
    for task in tasks:
        path = train_teacher(TeacherConfig(task=task, seed=args.seed, max_steps=args.max_steps), out)
        result = json.loads((path / "result.json").read_text())
        curve = " ".join(f"{int(r['step']) // 1000}k:{float(r['success']):.2f}" for r in read_csv(path / "evals.csv"))
        rows.append((task, result, curve, path))
    report = Report()
    report()
    report(f"| task (7x7, seed {args.seed}) | env steps to >= 90% greedy success (target: within {args.max_steps:,}) "
           "| minutes | success at stop | evaluations (step:success) |")
    report("|---|---|---|---|---|")
    for task, r, curve, _path in rows:
        reached = f"{r['steps']:,}" if r["reached_target"] else f"**not within {r['steps']:,}**"
        report(f"| {task} | {reached} | {r['seconds_this_session'] / 60:.1f} | {r['success']:.2f} | {curve} |")
    if args.out:
        print("\nteachers and tables: " + ", ".join(str(p) for *_, p in rows))
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
