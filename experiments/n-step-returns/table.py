"""The experiment's table: each cell's one-step runs (the standard suite's, in the results
archive) beside its n-step runs, in final greedy success, AUC and steps to 80%.

    python experiments/n-step-returns/table.py
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from run import CELLS  # noqa: E402

from craftsuite.reporting.board import build  # noqa: E402

SOURCES = ("results/standard/students", "results/n-step-returns/students")


def n_steps(entry) -> int:
    config = json.loads((entry.runs[0] / "config.json").read_text())
    return config["effective"]["hyperparameters"].get("n_steps", 1)


def main() -> None:
    entries = [e for root in SOURCES for e in build(root)]
    print("| rung | world | method | n | final success [95% t] | AUC | reached 80% | median over all seeds |")
    print("|---|---|---|---|---|---|---|---|")
    for task, world, methods, _ in CELLS:
        for method in methods:
            here = sorted((e for e in entries if (e.task, e.world, e.method) == (task, world, method)), key=n_steps)
            for e in here:
                s, auc, overall = e.stats["success"], e.stats["auc"], e.reached.overall
                print(f"| {task} | {world} | `{method}` | {n_steps(e)} | {s.value:.2f} [{s.low:.2f}, {s.high:.2f}] "
                      f"| {auc.value:.2f} | {e.reached} | {'never' if math.isinf(overall) else f'{overall:,.0f}'} |")


if __name__ == "__main__":
    main()
