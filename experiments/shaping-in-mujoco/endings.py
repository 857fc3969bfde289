"""How the training episodes of archived cells ended, per method and window of transitions:
completed, broken (the automaton's rejecting sink), or timed out (the world's step limit),
and of the timed-out ones, how many never left the automaton's initial state ("idle").
Reads records only (``config.json``, ``episodes.csv.gz``, ``evals.csv``); trains nothing.

With ``--pairs A:B ...``, also each method A against method B by the results page's rules
(``craftsuite.reporting.board.compare``), in final greedy success and in AUC; each method's
cell is read from the first of ``--students`` that holds it (never pooled across them).

Usage: python experiments/shaping-in-mujoco/endings.py [--students results/standard/students ...]
       [--task KeySwordDragon] [--world Cont] [--steps 100000]
       [--methods td3 product-td3 td3-rs td3-dynamic-rs] [--window 20000] [--pairs A:B ...]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import gymnasium as gym

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.ids import env_id
from craftsuite.reached import bits
from craftsuite.reporting.board import COMPARED, build, compare, run_metrics
from craftsuite.runs import EPISODE_FIELDS, read_config, read_csv
from craftsuite.task_registry import resolve_task

ENDINGS = ("completed", "broken", "timed out", "idle")


def ending(row: dict, sink: set[int], start: int, limit: int) -> list[str]:
    """The endings one training episode counts under: completed, broken or timed out, and
    idle as well where it timed out without leaving the initial automaton state."""
    states = set(bits(int(row["states"])))
    if int(float(row["success"])):
        return ["completed"]
    if states & sink:
        return ["broken"]
    if int(row["length"]) < limit:
        return []  # a truncation before the limit: none of these
    return ["timed out", "idle"] if states == {start} else ["timed out"]


def read_cell(runs: list[Path], window: int, steps: int) -> dict:
    automaton = resolve_task(read_config(runs[0])["task"]).automaton
    sink = {q for q, r in enumerate(automaton.rejecting.tolist()) if r}
    config = read_config(runs[0])
    limit = gym.spec(env_id(config["task"], config["world"])).max_episode_steps
    counts = {lo: dict.fromkeys(("episodes", *ENDINGS), 0) for lo in range(0, steps, window)}
    for run in runs:
        for row in read_csv(run / "episodes.csv", EPISODE_FIELDS, True):
            lo = min((int(row["step"]) - 1) // window * window, steps - window)
            counts[lo]["episodes"] += 1
            for name in ending(row, sink, int(automaton.initial), limit):
                counts[lo][name] += 1
    return {"windows": counts, "final": [run_metrics(r)["success"] for r in runs]}


def cell_runs(students: Path, task: str, world: str, method: str, steps: int) -> list[Path]:
    """The archived runs of one cell at one budget whose episodes record what they reached."""
    found = []
    for run in sorted(students.glob(f"student-{task}-{world}-{method}-s*")):
        config = read_config(run)
        if config["method"] == method and config["steps"] == steps:
            found.append(run)
    return sorted(found, key=lambda r: read_config(r)["seed"])


def cells(roots: list[Path], task: str, world: str, steps: int) -> dict:
    """Each method's leaderboard entry of the cell (``n-step-wide``, one setting), from the
    first root that holds it: a rerun at another commit keeps the run key of the run it
    repeats, so two roots are never pooled."""
    out = {}
    for root in roots:
        for e in build(root).entries:
            if (e.task, e.world, e.budget, e.regime, e.variant) == (task, world, steps, "n-step-wide", ""):
                out.setdefault(e.method, e)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--students", nargs="+", default=["results/standard/students"])
    ap.add_argument("--task", default="KeySwordDragon")
    ap.add_argument("--world", default="Cont")
    ap.add_argument("--steps", type=int, default=100_000)
    ap.add_argument("--methods", nargs="+", default=["td3", "product-td3", "td3-rs", "td3-dynamic-rs"])
    ap.add_argument("--window", type=int, default=20_000)
    ap.add_argument("--pairs", nargs="*", default=[], help="A:B, method A against method B")
    args = ap.parse_args(argv)
    roots = [Path(s) for s in args.students]
    for method in args.methods:
        found_in = (cell_runs(root, args.task, args.world, method, args.steps) for root in roots)
        runs = next((r for r in found_in if r), [])
        if not runs:
            raise SystemExit(f"no {method} runs of {args.task} in {args.world} at {args.steps:,} transitions under "
                             f"{args.students}: name a directory of student runs with --students")
        try:
            cell = read_cell(runs, args.window, args.steps)
        except ValueError as err:  # a record made before episodes.csv kept the states its episodes visited
            raise SystemExit(f"{method}: {err}: this reads runs whose episodes record 'seen' and 'states'") from None
        finals = " ".join(f"{s:.2f}" for s in cell["final"])
        print(f"== {method} ({len(runs)} seeds; final greedy success {finals})")
        for lo, c in cell["windows"].items():
            print(f"  {lo:>7,}-{lo + args.window:>7,}: {c['episodes']:5d} episodes: {c['completed']:4d} completed, "
                  f"{c['broken']:4d} broken, {c['timed out']:4d} timed out ({c['idle']:4d} idle in the initial state)")
    found = cells(roots, args.task, args.world, args.steps) if args.pairs else {}
    for pair in args.pairs:
        a, _, b = pair.partition(":")
        if a not in found or b not in found:
            raise SystemExit(f"--pairs {pair}: no {a if a not in found else b} cell of {args.task} in {args.world} at "
                             f"{args.steps:,} transitions under {' '.join(args.students)}")
        for metric, words in COMPARED.items():
            c = compare(found[a], found[b], metric)
            d = c.difference
            print(f"{a} against {b}, {words}: {d.value:+.2f} [{d.low:+.2f}, {d.high:+.2f}], "
                  f"P(> {b}) {c.improvement.value:.2f}: {c.verdict}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
