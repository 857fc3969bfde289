"""docs/performance.md, written by the benchmarks: each script owns one section of it.

A benchmark prints its table (figures beside their targets or references) and hands the
same lines to :func:`write_section`, which replaces that script's section between its
markers and leaves the other sections as they were, so any one benchmark can be re-run
alone. Sections follow ``SECTIONS`` whatever order the scripts ran in, and every section
says how it was made: the command, the date, the commit and the machine.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import subprocess
import sys
from pathlib import Path

from craftsuite.files import atomic_write
from craftsuite.provenance import cpu

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "performance.md"

# The page's order: the package's own speed first (automata, worlds, training), then its statistics
# and the cost of reporting them.
SECTIONS = ("automata", "grid_steps", "cont_steps", "vector_envs", "student_throughput", "crm_memory",
            "checkpoint_memory", "engine_equivalence", "teachers", "interval_coverage", "verdict_error", "results_page",
            "code_size")

HEADER = """\
# Performance

How fast CraftSuite's parts are, and how well its statistics keep their level, each beside
its target or an outside reference. **This page is written by the benchmark scripts**: each
script in `benchmarks/` replaces its own section (`make bench` runs them all, about 30
minutes on 2 cores); edit the scripts, not this page. Each section names the command, date,
commit and machine that made it. Timings depend on what else the machine was doing: the
load average at the start of each run is given with its machine, and figures taken beside
other work understate an idle machine.
"""

_BEGIN = "<!-- begin section: {} -->"
_END = "<!-- end section: {} -->"


def add_page_argument(parser: argparse.ArgumentParser) -> None:
    """``--page PATH`` (default docs/performance.md) and ``--no-page`` for every benchmark."""
    parser.add_argument("--page", type=Path, default=PAGE, help="the page whose section this run replaces")
    parser.add_argument("--no-page", action="store_true", help="print the figures only; write no page")


def machine() -> str:
    """Cores, CPU (model and vector instructions: ``provenance.cpu``), memory, Python and the
    load average now, in one line."""
    model = cpu() or platform.processor() or platform.machine()
    memory = ""
    try:
        kib = int(Path("/proc/meminfo").read_text().split()[1])  # MemTotal comes first
        memory = f", {kib / 2**20:.0f} GiB"
    except (OSError, ValueError, IndexError):
        pass
    load = f", load average {os.getloadavg()[0]:.2f}" if hasattr(os, "getloadavg") else ""
    return (f"{os.cpu_count()} cores of {model}{memory}, {platform.system()} {platform.release()}, "
            f"Python {platform.python_version()}{load}")


def git(*args: str, text: bool = True) -> str | bytes:
    """``git ARGS`` in the checkout: what it printed, or a ValueError holding git's last line."""
    done = subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=text)
    if done.returncode:
        said = done.stderr if text else done.stderr.decode(errors="replace")
        raise ValueError((said.strip().splitlines() or ["git failed"])[-1])
    return done.stdout


def at_reference(reference: str, *args: str, text: bool = True) -> str | bytes:
    """``git ARGS`` about a benchmark's ``--reference``; a failure is one line naming the
    reference and the fix."""
    try:
        return git(*args, text=text)
    except ValueError as err:
        raise ValueError(f"--reference {reference}: not readable from this checkout's git history ({err}); "
                         "give a commit that `git log` lists") from None


def commit() -> str:
    """The short commit of the working tree, marked when files differ from it."""
    try:
        head = git("rev-parse", "--short", "HEAD").strip()
        status = git("status", "--porcelain")
    except (ValueError, OSError):
        return "unknown (not a git checkout)"
    changed = [line for line in status.splitlines() if not line.endswith(PAGE.relative_to(ROOT).as_posix())]
    return f"`{head}`" + (" with uncommitted changes" if changed else "")


def command(script: str, argv: list[str] | None = None) -> str:
    args = sys.argv[1:] if argv is None else argv
    return " ".join(["python", f"benchmarks/{Path(script).name}", *args])


def describe(doc: str) -> tuple[str, str]:
    """A script's title (its docstring's first line) and what it measures (the paragraphs
    after the Usage line): the docstring stays the one place that explains the benchmark."""
    paragraphs = [p.strip() for p in doc.strip().split("\n\n")]
    title = paragraphs[0].splitlines()[0].rstrip(".")
    about = [_unwrap(p) for p in paragraphs[1:] if not p.startswith("Usage:")]
    return title, "\n\n".join(about)


def _unwrap(paragraph: str) -> str:
    """One line per sentence run or list item ("* " or "- "), the docstring's wrapping undone."""
    items: list[str] = []
    for line in paragraph.splitlines():
        line = line.strip()
        if not items or line.startswith(("* ", "- ")):
            items.append(line)
        else:
            items[-1] += " " + line
    return "\n".join(items)


def render_section(name: str, doc: str, body: str, cmd: str, when: datetime.date | None = None) -> str:
    title, about = describe(doc)
    when = when or datetime.date.today()
    return "\n".join([
        _BEGIN.format(name), f"## {title}", "", about, "", "```bash", cmd, "```", "",
        f"Measured {when.isoformat()} at commit {commit()}, on {machine()}.", "",
        body.strip(), _END.format(name)])


def read_sections(text: str, page: Path) -> dict[str, str]:
    """The sections of an existing page, by name; a section whose markers do not pair is an error."""
    sections = {}
    for name in re.findall(r"<!-- begin section: (\S+) -->", text):
        begin, end = _BEGIN.format(name), _END.format(name)
        start, stop = text.find(begin), text.find(end)
        if stop < start:
            raise ValueError(f"{page}: section {name!r} has a begin marker but no end marker after it; "
                             "mend or delete the page and run the benchmarks again")
        sections[name] = text[start:stop + len(end)]
    return sections


def write_section(script: str, doc: str, body: str, page: Path = PAGE, argv: list[str] | None = None,
                  when: datetime.date | None = None) -> Path:
    """Replace ``script``'s section of ``page`` (creating the page if needed) with ``body``."""
    name = Path(script).stem
    if name not in SECTIONS:
        raise ValueError(f"{name!r} has no section on the performance page; known: {', '.join(SECTIONS)}")
    page = Path(page)
    sections = read_sections(page.read_text(), page) if page.exists() else {}
    sections[name] = render_section(name, doc, body, command(script, argv), when)
    text = HEADER + "".join(f"\n{sections[n]}\n" for n in SECTIONS if n in sections)
    atomic_write(page, text)  # a reader never sees half a page
    return page


class Report:
    """Lines printed as they come and kept for the page: ``report(line)``, then ``report.save(...)``."""

    def __init__(self):
        self.lines: list[str] = []

    def __call__(self, line: str = "") -> None:
        print(line, flush=True)
        self.lines.append(line)

    def save(self, script: str, doc: str, args: argparse.Namespace) -> None:
        if not args.no_page:
            print(f"\nwrote {write_section(script, doc, chr(10).join(self.lines), args.page)}")
