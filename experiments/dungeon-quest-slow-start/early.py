"""What the training episodes of one archived cell did early on, per method: how often they
ended in the automaton's rejecting sink (the objective broken), ran to the time limit, reached
the state one edge from acceptance, or completed; and, per seed, when its greedy success first
reached 80%. Reads records only (``episodes.csv.gz``, ``evals.csv``); trains nothing.

Usage: python experiments/dungeon-quest-slow-start/early.py [--students results/hard/students]
       [--task DungeonQuest] [--world Grid10] [--methods dqn static dynamic] [--window 5000]
       [--until 25000] [--out early.json]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import gymnasium as gym

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.ids import env_id
from craftsuite import stats
from craftsuite.reached import bits
from craftsuite.reporting.board import run_metrics
from craftsuite.reporting.obstacles import distances
from craftsuite.runs import EPISODE_FIELDS, read_config, read_csv
from craftsuite.task_registry import resolve_task


def classify(row: dict, sink: set[int], limit: int) -> str:
    """One training episode's ending: completed, broken (it entered the rejecting sink),
    timed out (the step limit), or other (a truncation before the limit)."""
    if int(float(row["success"])):
        return "completed"
    if set(bits(int(row["states"]))) & sink:
        return "broken"
    return "timed out" if int(row["length"]) >= limit else "other"


def read_run(run: Path, window: int, until: int) -> dict:
    config = read_config(run)
    automaton = resolve_task(config["task"]).automaton
    sink = {q for q, r in enumerate(automaton.rejecting.tolist()) if r}
    near = {q for q, d in enumerate(distances(automaton)) if d == 1}
    limit = gym.spec(env_id(config["task"], config["world"])).max_episode_steps  # the world's episode limit
    try:
        episodes = read_csv(run / "episodes.csv", EPISODE_FIELDS, True)  # (or the archive's .gz)
    except ValueError as err:  # a record made before episodes.csv kept what the episodes reached
        raise SystemExit(f"{run / 'episodes.csv'}: {err}: this reads runs whose episodes record 'seen' and "
                         "'states'; give --students and --methods of such runs (one budget and regime)") from None
    windows = []
    for lo in range(0, until, window):
        rows = [r for r in episodes if lo < int(r["step"]) <= lo + window]
        ends = [classify(r, sink, limit) for r in rows]
        windows.append({"from": lo, "to": lo + window, "episodes": len(rows),
                        **{k: ends.count(k) for k in ("completed", "broken", "timed out", "other")},
                        "reached one edge from acceptance": sum(bool(set(bits(int(r["states"]))) & near)
                                                                for r in rows)})
    metrics = run_metrics(run)  # the board's reading: first evaluation at 80%, final success
    return {"seed": config["seed"], "first at 80%": metrics["steps_to_80"], "final": metrics["success"],
            "limit": limit, "windows": windows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--students", default="results/hard/students")
    ap.add_argument("--task", default="DungeonQuest")
    ap.add_argument("--world", default="Grid10")
    ap.add_argument("--methods", nargs="+", default=["dqn", "static", "dynamic"])
    ap.add_argument("--window", type=int, default=5000)
    ap.add_argument("--until", type=int, default=25000)
    ap.add_argument("--out", default=None)
    args = ap.parse_args(argv)
    out = {}
    for method in args.methods:
        runs = sorted(Path(args.students).glob(f"student-{args.task}-{args.world}-{method}-s*"),
                      key=lambda p: int(p.name.split("-s")[-1].split("-")[0]))
        if not runs:
            raise SystemExit(f"no {method} runs of {args.task} on {args.world} under {args.students}: "
                             "name a directory of archived student runs with --students")
        out[method] = [read_run(r, args.window, args.until) for r in runs]
        print(f"== {method} ({len(runs)} seeds): per window, pooled over seeds, the training episodes that "
              "ended: completed / broken (rejecting sink) / timed out; reached one edge from acceptance")
        for i in range(len(out[method][0]["windows"])):
            w = [s["windows"][i] for s in out[method]]
            tot = {k: sum(x[k] for x in w) for k in w[0] if k not in ("from", "to")}
            print(f"  {w[0]['from']:>6,}-{w[0]['to']:>6,}: {tot['episodes']:4d} episodes: "
                  f"{tot['completed']:4d} completed, "
                  f"{tot['broken']:4d} broken, {tot['timed out']:3d} timed out; "
                  f"{tot['reached one edge from acceptance']:4d} reached one edge from acceptance")
        for s in out[method]:
            w0 = s["windows"][0]
            print(f"  seed {s['seed']:2d}: first at 80% {s['first at 80%']!s:>6}, first window {w0['episodes']:3d} "
                  f"episodes, {w0['broken']:3d} broken, {w0['timed out']:2d} timed out")
        # a seed that never reached 80% counts as later than any that did
        firsts = [s["first at 80%"] for s in out[method]]
        late = sum(f is None or f >= 20_000 for f in firsts)
        print(f"  median first at 80%: {stats.reached(firsts).overall:,.0f}; first at 20,000 or later (or never): "
              f"{late} of {len(firsts)} seeds")
    if args.out:
        Path(args.out).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
