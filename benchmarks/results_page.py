"""The results page: the time to build docs/results.md from the archive, now and at a reference commit.

Usage: python benchmarks/results_page.py [ARCHIVE ...] [--reference COMMIT] [--repeat N] [--page PATH | --no-page]

Each campaign part ends by rebuilding the results page from every archived record
(``craftsuite leaderboard results/standard results/hard --page docs/results.md``: the
records read, every comparison's intervals and bootstraps, the plots). Each build runs in
a fresh process, as a user runs it; the row gives its wall time, its CPU time (user and
system) and its peak resident memory, the fastest of ``--repeat`` builds. The reference is
the same command with the package as it was at ``--reference`` (its ``craftsuite/``,
``tasks/`` and ``assets/`` read from git) over the same archive, so both read the same
records; the default reference is the last commit before the page read each run's logs
once and counted the probability of improvement from midranks. "Same page" says whether
the two builds wrote the same text (the reference's wording may differ where the page's
has changed since).

Target: at most 2 minutes of CPU for the whole archive, so that rebuilding the page after
a campaign part costs minutes of a 2-core machine, not a part's share of it.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _page import ROOT, Report, add_page_argument  # benchmarks/ is on sys.path as a script

REFERENCE = "81fd8777"
ARCHIVES = ("results/standard", "results/hard")
TARGET_CPU_S = 120.0
_PACKAGE_PATHS = ("craftsuite", "tasks", "assets")  # what the package reads (craftsuite.paths)
PAGE_NAME = "results.md"


def build(tree: Path, archives: list[Path], where: Path) -> dict:
    """One page build by the package in ``tree`` into ``where``/results.md, in a fresh process: wall and
    CPU seconds, peak GB. The page is named relatively, as the page names the command that wrote it."""
    env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
    command = [sys.executable, "-m", "craftsuite", "leaderboard", *map(str, archives), "--page", PAGE_NAME]
    start = time.perf_counter()
    with tempfile.TemporaryFile() as log:
        child = subprocess.Popen(command, cwd=where, env=env, stdout=log, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode:
            log.seek(0)
            tail = log.read().decode(errors="replace").strip().splitlines()[-1:] or ["no output"]
            raise RuntimeError(f"the page build by {tree} failed (exit {child.returncode}): {tail[0]}")
    return {"wall": time.perf_counter() - start, "user": usage.ru_utime, "sys": usage.ru_stime,
            "rss_gb": usage.ru_maxrss / 2**20}


def fastest(tree: Path, archives: list[Path], where: Path, repeat: int) -> dict:
    runs = [build(tree, archives, where) for _ in range(repeat)]
    return min(runs, key=lambda r: r["user"] + r["sys"])


def package_at(commit: str, into: Path) -> Path:
    """The package's files at ``commit`` (from git), unpacked into ``into``."""
    packed = subprocess.run(["git", "archive", commit, *_PACKAGE_PATHS], cwd=ROOT, capture_output=True)
    if packed.returncode:
        last = packed.stderr.decode(errors="replace").strip().splitlines()[-1:] or ["git failed"]
        raise ValueError(f"--reference {commit}: not a commit of this checkout's git history ({last[0]}); "
                         "give one that `git log` lists")
    into.mkdir(parents=True, exist_ok=True)
    subprocess.run(["tar", "-x", "-C", str(into)], input=packed.stdout, check=True)
    return into


def runs_in(archives: list[Path]) -> int:
    return sum(1 for a in archives for d in (a / "students").glob("*") if d.is_dir())


def row(name: str, got: dict, same: str) -> str:
    cpu = got["user"] + got["sys"]
    return (f"| {name} | {got['wall']:.1f} | {cpu:.1f} ({got['user']:.1f} + {got['sys']:.1f}) | "
            f"{'met' if cpu <= TARGET_CPU_S else 'NOT met'} | {got['rss_gb']:.2f} | {same} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("archives", nargs="*", default=list(ARCHIVES), metavar="ARCHIVE",
                        help="the archives the page is built from (default: %(default)s)")
    parser.add_argument("--reference", default=REFERENCE, help="the commit to compare with (default: %(default)s)")
    parser.add_argument("--repeat", type=int, default=1, help="builds of each, the fastest shown (default: 1)")
    add_page_argument(parser)
    args = parser.parse_args()
    archives = [(ROOT / a).resolve() for a in args.archives]
    missing = [name for name, a in zip(args.archives, archives) if not (a / "students").is_dir()]
    if missing:
        parser.error(f"{', '.join(missing)}: not an archive (no students/ in it); give archives such as "
                     f"{' '.join(ARCHIVES)}")
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat}: give at least 1")
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        try:
            reference = package_at(args.reference, scratch / "reference")
        except ValueError as err:
            parser.error(str(err))
        pages = {"now": scratch / "page-now", "reference": scratch / "page-reference"}
        for where in pages.values():
            where.mkdir()
        try:
            now = fastest(ROOT, archives, pages["now"], args.repeat)
            then = fastest(reference, archives, pages["reference"], args.repeat)
        except RuntimeError as err:
            sys.exit(f"results_page.py: {err}")
        a, b = ((where / PAGE_NAME).read_text().splitlines() for where in pages.values())
        differ = sum(x != y for x, y in zip(a, b)) + abs(len(a) - len(b))
    same = "yes" if not differ else f"no ({differ} of {len(a):,} lines differ)"
    report = Report()
    report(f"{runs_in(archives):,} archived runs in {', '.join(args.archives)}; fastest of {args.repeat} "
           f"build{'s' if args.repeat > 1 else ''} each.")
    report("")
    report(f"| package | wall s | CPU s (user + system) | target <= {TARGET_CPU_S:.0f} s CPU | peak GB | "
           "same page as now |")
    report("|---|---|---|---|---|---|")
    report(row("now", now, "-"))
    report(row(f"at `{args.reference}`", then, same))
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
