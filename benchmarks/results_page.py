"""The results page: the time to build docs/results.md from the archive, now and at a reference commit.

Usage: python benchmarks/results_page.py [ARCHIVE ...] [--reference COMMIT] [--repeat N] [--page PATH | --no-page]

Each campaign part ends by rebuilding the results page from the standard and hard suites'
archives (``craftsuite leaderboard results/standard results/hard --page docs/results.md``:
every record read, every comparison's intervals and bootstraps, the plots). Each build
runs in a fresh process, as a user runs it; its row gives the wall time, the CPU time
(user and system) and the peak resident memory of that process, the build of least CPU
of ``--repeat``. The reference is the same command with the package as it was at
``--reference`` (its ``craftsuite/``, ``tasks/`` and ``assets/`` read from git) over the
same archives, so both read the same records; the default reference is the last commit
before the obstacle tables took what each run's episodes reached from the board's own
reading of its log and the probability of improvement counted its resamples' pairs from
histograms of places. "Same page" says whether the two builds wrote the same text, and if not
how many lines of today's page differ (the reference's wording may differ where the
page's has changed since). ARCHIVE paths are relative to the current directory.

Target: at most 2 minutes of CPU for the two suites' archives, so that rebuilding the page
after a campaign part costs minutes of a 2-core machine, not a part's share of it (judged
only on those archives).
"""

from __future__ import annotations

import argparse
import difflib
import io
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

from _page import ROOT, Report, add_page_argument, at_reference  # benchmarks/ is on sys.path as a script
from craftsuite.archive import archived
from craftsuite.paths import DATA_DIRS

REFERENCE = "6d42ccb1"
ARCHIVES = ("results/standard", "results/hard")
TARGET_CPU_S = 120.0
PAGE_NAME = "results.md"


def build(tree: Path, archives: list[Path], where: Path) -> dict:
    """One page build by the package in ``tree`` into ``where``/results.md, in a fresh process: wall
    and CPU seconds, peak GB.

    It runs in ``where``, not in the checkout: ``python -m`` puts the working directory ahead of
    PYTHONPATH, so a build run from the checkout would import today's package whatever ``tree``
    is. ``os.wait4`` gives that one process's usage (the children's rusage of this process would
    hold git's, and the largest peak of any child so far)."""
    env = {**os.environ, "PYTHONPATH": str(tree), "MPLBACKEND": "Agg"}
    command = [sys.executable, "-m", "craftsuite", "leaderboard", *map(str, archives), "--page", PAGE_NAME]
    start = time.perf_counter()
    with tempfile.TemporaryFile() as log:
        child = subprocess.Popen(command, cwd=where, env=env, stdout=log, stderr=subprocess.STDOUT)
        try:
            _, status, usage = os.wait4(child.pid, 0)
        except BaseException:  # interrupted: leave no build running
            child.kill()
            child.wait()
            raise
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode:
            log.seek(0)
            said = log.read().decode(errors="replace").strip().splitlines()
            raise RuntimeError(f"exit {child.returncode}: {said[-1] if said else 'no output'}")
    return {"wall": time.perf_counter() - start, "user": usage.ru_utime, "sys": usage.ru_stime,
            "rss_gb": usage.ru_maxrss / 2**20}


def least_cpu(tree: Path, archives: list[Path], where: Path, repeat: int) -> dict:
    return min((build(tree, archives, where) for _ in range(repeat)), key=lambda r: r["user"] + r["sys"])


def package_at(commit: str, into: Path) -> Path:
    """The package's files at ``commit`` (from git), unpacked into ``into``."""
    packed = at_reference(commit, "archive", commit, "craftsuite", *DATA_DIRS, text=False)
    with tarfile.open(fileobj=io.BytesIO(packed)) as tar:
        # extraction filters came with Python 3.11.4; the package allows any 3.11 (and git's own archive is trusted)
        tar.extractall(into, **({"filter": "data"} if hasattr(tarfile, "data_filter") else {}))
    return into


def lines_differing(now: list[str], then: list[str]) -> int:
    """Lines of either page outside the runs the two share (an inserted line counts once)."""
    blocks = difflib.SequenceMatcher(None, now, then, autojunk=False).get_opcodes()
    return sum(max(i2 - i1, j2 - j1) for tag, i1, i2, j1, j2 in blocks if tag != "equal")


def row(name: str, got: dict | str, same: str, judged: bool) -> str:
    if isinstance(got, str):  # the build failed: why
        return f"| {name} | failed: {got} | | | | |"
    cpu = got["user"] + got["sys"]
    verdict = ("met" if cpu <= TARGET_CPU_S else "NOT met") if judged else "- (not the two suites' archives)"
    return (f"| {name} | {got['wall']:.1f} | {cpu:.1f} ({got['user']:.1f} + {got['sys']:.1f}) | {verdict} | "
            f"{got['rss_gb']:.2f} | {same} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("archives", nargs="*", metavar="ARCHIVE",
                        help=f"the archives the page is built from (default: {' '.join(ARCHIVES)})")
    parser.add_argument("--reference", default=REFERENCE, help="the commit to compare with (default: %(default)s)")
    parser.add_argument("--repeat", type=int, default=1, help="builds of each; the one of least CPU is shown "
                        "(default: 1)")
    add_page_argument(parser)
    args = parser.parse_args()
    names = args.archives or list(ARCHIVES)
    archives = [Path(a).resolve() for a in args.archives] or [ROOT / a for a in ARCHIVES]
    missing = [name for name, a in zip(names, archives) if not (a / "students").is_dir()]
    if missing:
        parser.error(f"{', '.join(missing)}: not an archive (no students/ in it); give archives such as "
                     f"{' '.join(ARCHIVES)}")
    if args.repeat < 1:
        parser.error(f"--repeat {args.repeat}: give at least 1")
    try:
        reference_name = at_reference(args.reference, "rev-parse", "--short", f"{args.reference}^{{commit}}").strip()
    except ValueError as err:
        parser.error(str(err))
    runs = sum(len(archived(a, "students")[0]) for a in archives)
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        try:  # a commit from before one of the package's directories existed, say
            reference = package_at(args.reference, scratch / "reference")
        except ValueError as err:
            parser.error(str(err))
        pages = {"now": scratch / "page-now", "reference": scratch / "page-reference"}
        for where in pages.values():
            where.mkdir()
        try:
            now = least_cpu(ROOT, archives, pages["now"], args.repeat)
        except RuntimeError as err:
            sys.exit(f"results_page.py: the page build of this checkout failed ({err}); run "
                     f"`craftsuite leaderboard {' '.join(names)} --page /tmp/results.md` to see why")
        try:
            then = least_cpu(reference, archives, pages["reference"], args.repeat)
            a, b = ((where / PAGE_NAME).read_text().splitlines() for where in pages.values())
            differ = lines_differing(a, b)
            same = "yes" if not differ else f"no ({differ} of {len(a):,} lines differ)"
        except RuntimeError as err:  # a package too old to read today's records: today's figures stand
            then, same = f"{err}; give a newer --reference", ""
    report = Report()
    report(f"{runs:,} student runs in {', '.join(names)}; the build of least CPU of {args.repeat} each.")
    report("")
    report(f"| package | wall s | CPU s (user + system) | target <= {TARGET_CPU_S:.0f} s CPU | peak GB | "
           "same page as now |")
    report("|---|---|---|---|---|---|")
    judged = sorted(archives) == sorted(ROOT / a for a in ARCHIVES)
    report(row("now", now, "-", judged))
    report(row(f"at `{reference_name}`", then, same, judged))
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
