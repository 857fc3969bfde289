"""Fold a py-spy sample of a population's training process into the parts of its work.

Usage: python experiments/population-slowdown/fold.py SAMPLE.txt [SAMPLE.txt ...] [--transitions N ...]

SAMPLE.txt is ``py-spy record --format raw`` output: one line a distinct stack, its frames
from the outermost, ``;``-separated, then its count. A stack belongs to the first part, from
the outermost frame in, whose frame it passes through; ``--transitions`` (one a sample, in
order) turns each part's share into milliseconds a thousand transitions over the sample's
``--seconds``.
"""

from __future__ import annotations

import argparse
import re
from collections import Counter

# (part, pattern on a frame "[Class.]function (file:line)"): the first that a stack's frames match,
# from the outermost in, names its part
PARTS = (
    ("checkpoint", r"^_checkpoint \(.*population/train\.py"),
    ("evaluation", r"^(_evaluate|evaluate_members) \("),
    ("sampling", r"^(\w+\.)?sample \(.*population/replay\.py"),
    ("priorities", r"^(\w+\.)?update_priorities \(.*population/replay\.py"),
    ("update", r"^(\w+\.)?update \(.*population/(dqn|td3)\.py"),
    ("acting", r"^(\w+\.)?actions \(.*population/engine\.py"),
    ("storing", r"^(\w+\.)?add \(.*population/replay\.py"),
    ("world", r"(gymnasium/|craftsuite/envs/|craftsuite/worlds/|mujoco|dm_control)"),
)
ORDER = [name for name, _ in PARTS] + ["rest"]


def part_of(frames: list[str]) -> str:
    for frame in frames:
        for name, pattern in PARTS:
            if re.search(pattern, frame):
                return name
    return "rest"


def fold(path: str) -> Counter:
    counts: Counter = Counter()
    for line in open(path):
        line = line.rstrip("\n")
        if not line:
            continue
        stack, _, count = line.rpartition(" ")
        counts[part_of(stack.split(";"))] += int(count)
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("samples", nargs="+")
    parser.add_argument("--transitions", type=int, nargs="*", default=[],
                        help="transitions the population did during each sample, in order")
    parser.add_argument("--seconds", type=float, default=30.0, help="each sample's length")
    args = parser.parse_args()
    if args.transitions and len(args.transitions) != len(args.samples):
        parser.error(f"--transitions: give one count a sample ({len(args.samples)}), got {len(args.transitions)}")
    print("| sample | " + " | ".join(ORDER) + " | samples |")
    print("|---|" + "---|" * (len(ORDER) + 1))
    for i, path in enumerate(args.samples):
        counts = fold(path)
        total = sum(counts.values())
        cells = []
        for name in ORDER:
            share = counts[name] / total if total else 0.0
            text = f"{share:.0%}"
            if args.transitions:
                text += f" ({share * args.seconds / args.transitions[i] * 1e6:.0f})"
            cells.append(text)
        print(f"| {path} | " + " | ".join(cells) + f" | {total} |")
    if args.transitions:
        print("\nshare of the samples (ms a thousand transitions)")


if __name__ == "__main__":
    main()
