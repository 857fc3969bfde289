"""Re-read the results page's distilled-against-scratch comparisons in final greedy success
with each run's value the mean of its last k evaluations instead of its last one.

The archives are read as ``craftsuite leaderboard ... --page`` reads them (the same boards,
pairs, readings and rules); only the per-run value of final greedy success changes. Prints,
per world and learner regime, the runs whose last evaluation lies 0.3 or more from the mean
of their last three, then every comparison's verdict on the page and at each k, then how many
verdicts change. ``--json`` keeps all of it.

    python experiments/final-evaluation-noise/last_evaluations.py results/standard results/hard \
        --k 3 5 --json experiments/final-evaluation-noise/last_evaluations.json
"""

from __future__ import annotations

import argparse
import dataclasses
import json
from collections import Counter
from pathlib import Path

import numpy as np

from craftsuite.reporting.board import Entry, compare
from craftsuite.reporting.looks import looks
from craftsuite.reporting.pages import comparisons
from craftsuite.reporting.sources import read_runs

APART = 0.3  # a last evaluation this far from the mean of the last three "stands apart"
WORDS = ("ahead", "behind", "no difference", "undecided")


def last_mean(entry: Entry, k: int) -> list[float]:
    """Per seed, the mean greedy success of the run's last ``k`` evaluations (those it has)."""
    return [float(np.mean(c.evals[-k:, 1])) if len(c.evals) else float("nan") for c in entry.curves]


def at_last(entry: Entry, k: int) -> Entry:
    """``entry`` with its final greedy success read as the mean of each run's last ``k`` evaluations."""
    return dataclasses.replace(entry, values={**entry.values, "success": last_mean(entry, k)})


def word(verdict: str) -> str:
    """A verdict's word, its ", by less than 0.2" set aside."""
    return next((w for w in WORDS if verdict.startswith(w)), verdict)


def change(before: str, after: str) -> str | None:
    """How a verdict's word changed (None: it did not)."""
    if before == after:
        return None
    if after == "undecided":
        return "decided to undecided"
    if before == "undecided":
        return "undecided to decided"
    return "one decided verdict to another"


def interval(c) -> list[float]:
    return [round(c.difference.value, 4), round(c.difference.low, 4), round(c.difference.high, 4)]


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("archives", nargs="+", type=Path, help="suite archives, as the results page reads them")
    parser.add_argument("--k", nargs="+", type=int, default=[3, 5], help="how many last evaluations to average")
    parser.add_argument("--json", type=Path, help="write everything read here to this file")
    args = parser.parse_args(argv)
    if any(k < 1 for k in args.k):
        parser.error("--k: each k must be 1 or more (1 is the page's own read)")

    try:
        boards = [read_runs(path, suite_cells=True).board for path in args.archives]
    except (FileNotFoundError, ValueError) as err:  # a missing archive, or one with no finished run
        parser.error(f"{err}: give suite archives such as results/standard")

    # 1. runs whose last evaluation stands apart from the mean of their last three
    apart: dict[str, list[int]] = {}
    for board in boards:
        for e in board:
            row = apart.setdefault(f"{e.world_label} | {e.regime}", [0, 0])
            for c in e.curves:
                row[1] += 1
                row[0] += int(len(c.evals) > 0 and abs(c.evals[-1, 1] - np.mean(c.evals[-3:, 1])) >= APART - 1e-9)
    print(f"runs whose last evaluation lies {APART} or more from the mean of their last three:")
    for key, (n, of) in sorted(apart.items()):
        print(f"  {key}: {n} of {of} ({n / of:.1%})")

    # 2. every comparison, on the page and at each k
    rows = []
    for entry, base, c in comparisons(boards):
        if c is None:
            continue  # other budgets: not compared on the page either
        k_looks = looks(entry, base)
        row = {"task": entry.task, "world": entry.world_label, "regime": entry.regime,
               "pair": f"{entry.label} - {base.label}", "seeds": [len(entry.seeds), len(base.seeds)],
               "looks": k_looks, "page": {"verdict": c.verdict, "difference": interval(c)}}
        for k in args.k:
            again = compare(at_last(entry, k), at_last(base, k), "success", k_looks)
            row[f"k={k}"] = {"verdict": again.verdict, "difference": interval(again),
                             "shift": [round(float(np.mean(last_mean(e, k)) - np.mean(e.values["success"])), 4)
                                       for e in (entry, base)]}
        rows.append(row)

    print(f"\n{len(rows)} comparisons; verdict on the page, then at k = {', '.join(map(str, args.k))} "
          "(difference [interval] where the verdict's word changed):")
    for row in rows:
        said = [row["page"]["verdict"]] + [row[f"k={k}"]["verdict"] for k in args.k]
        moved = any(word(s) != word(said[0]) for s in said[1:])
        text = " | ".join(said) if moved else said[0]
        extra = "  ".join(f"{name}: {r['difference'][0]:+.2f} [{r['difference'][1]:+.2f}, {r['difference'][2]:+.2f}]"
                          for name, r in [("page", row["page"])] + [(f"k={k}", row[f"k={k}"]) for k in args.k]) \
            if moved else ""
        print(f"  {'*' if moved else ' '} {row['task']} {row['world']} {row['regime']} {row['pair']} "
              f"(read {row['looks']}x): {text}" + (f"\n      {extra}" if extra else ""))

    # 3. how many changed
    summary = {}
    for k in args.k:
        kinds = Counter(change(word(r["page"]["verdict"]), word(r[f"k={k}"]["verdict"])) for r in rows)
        changed = {kind: n for kind, n in kinds.items() if kind is not None}
        summary[f"k={k}"] = {"changed": sum(changed.values()), **changed}
        print(f"\nk = {k}: {sum(changed.values())} of {len(rows)} verdicts change"
              + "".join(f"; {kind}: {n}" for kind, n in sorted(changed.items())))
        for regime in sorted({r["regime"] for r in rows}):
            mine = [r for r in rows if r["regime"] == regime]
            decided = [sum(word(r[key]["verdict"]) != "undecided" for r in mine) for key in ("page", f"k={k}")]
            print(f"  {regime}: decided on the page {decided[0]} of {len(mine)}, at k = {k} {decided[1]}")
    if args.json:
        args.json.write_text(json.dumps({"archives": [str(p) for p in args.archives], "k": args.k,
                                         "apart": apart, "comparisons": rows, "summary": summary}, indent=1) + "\n")


if __name__ == "__main__":
    main()
