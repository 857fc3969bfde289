"""n-step returns on two middle rungs: the standard suite's runs of the paper's method and
its algorithm from scratch, again with ``n_steps`` > 1, against the suite's own one-step
runs in the results archive.

    python experiments/n-step-returns/run.py --out experiments/n-step-returns/results
    craftsuite archive experiments/n-step-returns/results --suite standard --archive results/n-step-returns
    python experiments/n-step-returns/table.py

Each run is the standard suite's config with ``n_steps`` added to its algorithm's settings
(the students' only: the teachers, and so the distilled tables, are the suite's own, read
from the results archive).
"""

from __future__ import annotations

import argparse
import dataclasses
import shutil
import sys
from pathlib import Path

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.suites import SUITES

# (rung, world, methods, n values): grids for steps-to-80% (their students reach it within
# the budget), MuJoCo where scratch lands mid-zone
CELLS = (
    ("ToolHome", "Grid10", ("dqn", "dynamic"), (3, 8)),
    ("KeySwordDragon", "Grid10", ("dqn", "dynamic"), (3, 8)),
    ("KeySwordDragon", "Cont", ("td3", "td3-dynamic"), (5,)),
    ("ToolHome", "Cont", ("td3", "td3-dynamic"), (5,)),
)


def configs(teacher_root: Path) -> list:
    # 10 seeds a cell, as this experiment ran (not the Grid10 middle rungs' 20 of twenty-seeds)
    standard = dataclasses.replace(SUITES["standard"], rung_seeds={}).student_configs(teacher_root)
    out = []
    for task, world, methods, ns in CELLS:
        for c in standard:
            if (c.task, c.world) == (task, world) and c.method in methods:
                out += [dataclasses.replace(c, hyperparameters={**c.hyperparameters, "n_steps": n}) for n in ns]
    return out


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    from craftsuite.suite_runner import run_students

    teachers = args.out / "teachers"  # the standard suite's own, from the archive
    for run in (Path("results") / "standard" / "teachers").iterdir():
        if not (teachers / run.name).exists():
            shutil.copytree(run, teachers / run.name)
    run_students(configs(teachers), args.out / "students", workers=args.workers)
    print(" ".join(sys.argv))


if __name__ == "__main__":
    main()
