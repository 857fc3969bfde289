"""Code size: lines of the package per area, and of its tests, beside a reference commit.

Usage: python benchmarks/code_size.py [--reference COMMIT] [--page PATH | --no-page]

Lines of Python (blank and comment lines included) in each top-level area of ``craftsuite/``
(a subpackage, or the modules directly under it), in the whole package and in ``tests/``,
now and at ``--reference`` (read from git, so the reference is the same on every machine).
The default reference is the last commit at which the SB3 agents held their own copy of the
learning rules beside the population engine's: every rule is now written once, and the two
learners' code (``agents/`` and ``population/``) should be smaller for it.
"""

from __future__ import annotations

import argparse
from collections import Counter
from pathlib import Path

from _page import ROOT, Report, add_page_argument, at_reference  # benchmarks/ is on sys.path as a script

REFERENCE = "85ab46c"


def _area(path: str) -> str:
    parts = Path(path).parts
    return f"{parts[1]}/" if len(parts) > 2 else "modules directly under craftsuite/"


def lines_now() -> tuple[Counter, int]:
    areas = Counter()
    for p in (ROOT / "craftsuite").rglob("*.py"):
        areas[_area(p.relative_to(ROOT).as_posix())] += len(p.read_text().splitlines())
    tests = sum(len(p.read_text().splitlines()) for p in (ROOT / "tests").rglob("*.py"))
    return areas, tests


def lines_at(commit: str) -> tuple[Counter, int]:
    areas, tests = Counter(), 0
    for path in at_reference(commit, "ls-tree", "-r", "--name-only", commit, "craftsuite", "tests").splitlines():
        if path.endswith(".py"):
            n = len(at_reference(commit, "show", f"{commit}:{path}").splitlines())
            if path.startswith("tests/"):
                tests += n
            else:
                areas[_area(path)] += n
    return areas, tests


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--reference", default=REFERENCE, help="the commit to compare with (default: %(default)s)")
    add_page_argument(parser)
    args = parser.parse_args()
    try:
        then, tests_then = lines_at(args.reference)
    except ValueError as err:
        parser.error(str(err))
    now, tests_now = lines_now()
    report = Report()
    report(f"| area | lines now | lines at `{args.reference}` | change |")
    report("|---|---|---|---|")
    for area in sorted(set(now) | set(then)):
        report(f"| `{area}` | {now[area]:,} | {then[area]:,} | {now[area] - then[area]:+,} |")
    learners = ("agents/", "population/")
    for name, a, b in (("`agents/` + `population/`", sum(now[k] for k in learners), sum(then[k] for k in learners)),
                       ("**the package**", sum(now.values()), sum(then.values())),
                       ("`tests/`", tests_now, tests_then)):
        report(f"| {name} | {a:,} | {b:,} | {a - b:+,} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
