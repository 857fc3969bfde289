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
from craftsuite.reporting.board import COMPARED, build, compare
from craftsuite.runs import EPISODE_FIELDS, read_csv
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


def read_cell(entry, window: int) -> dict:
    """One leaderboard entry's training episodes, counted per window of transitions."""
    automaton = resolve_task(entry.task).automaton
    sink = {q for q, r in enumerate(automaton.rejecting.tolist()) if r}
    # the world's episode limit, or the one the runs set
    limit = entry.world_kwargs.get("max_episode_steps") or gym.spec(env_id(entry.task, entry.world)).max_episode_steps
    counts = {lo: dict.fromkeys(("episodes", *ENDINGS), 0) for lo in range(0, entry.budget, window)}
    for run in entry.runs:
        for row in read_csv(run / "episodes.csv", EPISODE_FIELDS, True):
            lo = min((int(row["step"]) - 1) // window * window, max(counts))  # the last window takes the rest
            counts[lo]["episodes"] += 1
            for name in ending(row, sink, int(automaton.initial), limit):
                counts[lo][name] += 1
    return {"windows": counts, "final": entry.values["success"]}


def cells(roots: list[Path], task: str, world: str, steps: int) -> dict:
    """Each method's leaderboard entry of the cell (finished runs, ``n-step-wide``, one
    setting), from the first root that holds it: a rerun at another commit keeps the run key
    of the run it repeats, so two roots are never pooled."""
    out = {}
    for root in roots:
        here = [e for e in build(root).entries
                if (e.task, e.world, e.budget, e.regime) == (task, world, steps, "n-step-wide")]
        for method in {e.method for e in here} - set(out):
            mine = [e for e in here if e.method == method]
            if len(mine) > 1:
                raise SystemExit(f"{root}: {method}'s runs of {task} in {world} at {steps:,} transitions differ in "
                                 f"more than the seed ({', '.join(e.label for e in mine)}): give a root of one setting")
            out[method] = mine[0]
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
    found = cells([Path(s) for s in args.students], args.task, args.world, args.steps)
    for method in args.methods:
        if method not in found:
            raise SystemExit(f"no finished {method} runs of {args.task} in {args.world} at {args.steps:,} transitions "
                             f"under {' '.join(args.students)}: name directories of student runs with --students")
        try:
            cell = read_cell(found[method], args.window)
        except ValueError as err:  # a record made before episodes.csv kept the states its episodes visited
            raise SystemExit(f"{method}: {err}: this reads runs whose episodes record 'seen' and 'states'") from None
        finals = " ".join(f"{s:.2f}" for s in cell["final"])
        print(f"== {method} ({len(found[method].runs)} seeds; final greedy success {finals})")
        for lo, c in cell["windows"].items():
            end = min(lo + args.window, args.steps)
            print(f"  {lo:>7,}-{end:>7,}: {c['episodes']:5d} episodes: {c['completed']:4d} completed, "
                  f"{c['broken']:4d} broken, {c['timed out']:4d} timed out ({c['idle']:4d} idle in the initial state; "
                  f"{c['timed out'] / max(c['episodes'], 1):.0%} of the episodes timed out)")
    for pair in args.pairs:
        a, _, b = pair.partition(":")
        if a not in found or b not in found:  # (read above only where named in --methods)
            raise SystemExit(f"--pairs {pair}: no {a if a not in found else b} cell of {args.task} in {args.world} at "
                             f"{args.steps:,} transitions under {' '.join(args.students)}")
        for metric, words in COMPARED.items():
            c = compare(found[a], found[b], metric)
            d = c.difference
            print(f"{a} against {b}, {words}: {d.value:+.2f} [{d.low:+.2f}, {d.high:+.2f}], "
                  f"P(> {b}) {c.improvement.value:.2f}: {c.said}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
