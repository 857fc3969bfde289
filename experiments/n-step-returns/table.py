"""The experiment's table: each cell's one-step runs (the standard suite's, in the results
archive) beside its n-step runs, in final greedy success, AUC and steps to 80%.

    python experiments/n-step-returns/table.py
"""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

from craftsuite.reporting.board import build


def _cells():
    """The driver's cells (its own run.py, by path: every experiment has a run.py)."""
    spec = importlib.util.spec_from_file_location("n_step_returns_run", Path(__file__).with_name("run.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.CELLS


SOURCES = ("results/standard/students", "results/n-step-returns/standard/students")


def n_steps(entry) -> int:
    config = json.loads((entry.runs[0] / "config.json").read_text())
    return config["effective"]["hyperparameters"].get("n_steps", 1)


def main() -> None:
    entries = [e for root in SOURCES for e in build(root)]
    print("| rung | world | method | n | final success [95% t] | AUC | reached 80% | median over all seeds |")
    print("|---|---|---|---|---|---|---|---|")
    for task, world, methods, _ in _cells():
        for method in methods:
            here = sorted((e for e in entries if (e.task, e.world, e.method) == (task, world, method)), key=n_steps)
            for e in here:
                s, auc, overall = e.stats["success"], e.stats["auc"], e.reached.overall
                print(f"| {task} | {world} | `{method}` | {n_steps(e)} | {s.value:.2f} [{s.low:.2f}, {s.high:.2f}] "
                      f"| {auc.value:.2f} | {e.reached} | {'never' if math.isinf(overall) else f'{overall:,.0f}'} |")


if __name__ == "__main__":
    main()
