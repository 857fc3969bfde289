"""A teacher's distilled table with every value scaled, toward the student's return scale.

Usage: python experiments/self-loops/scale_table.py TABLE OUT [--factor 0.1]

Loads TABLE (a teacher's ``table.npz``), multiplies its values by ``--factor`` and saves the
result to OUT, which ``craftsuite student ... --table OUT`` then distils from. OUT must not
exist yet: a table written before is never overwritten.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--factor", type=float, default=0.1)
    args = parser.parse_args(argv)
    if args.out.exists():
        parser.error(f"{args.out} exists; choose another path")
    from craftsuite.agents import AutomatonQTable

    table = AutomatonQTable.load(args.table)
    table.q *= args.factor
    table.save(args.out)
    print(f"{args.out}: values {table.q.min():.1f} to {table.q.max():.1f}")


if __name__ == "__main__":
    main()
