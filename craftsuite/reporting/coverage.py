"""How much of a suite, as it is defined now, an archive directory holds: per world and
rung, the runs archived under the suite's current run keys against the runs it asks for,
and the transitions still to train. A suite runs in parts across machines and sessions; the
results page says which parts are in and which are not, so that a table that is missing a
cell reads as not run, not as cut."""

from __future__ import annotations

from pathlib import Path

from ..suites import SUITES
from .board import rung_order


def coverage_markdown(root: Path, suite_name: str, rates: dict[str, float] | None = None) -> list[str]:
    """Lines of Markdown for the archive directory ``root`` of the suite ``suite_name``; none
    for a name that is not a suite of this version (an archive of a removed or renamed one).
    ``rates``: per world, the transitions per second of one population process
    (``timing.rates``), from which the time still to train is projected."""
    suite = SUITES.get(suite_name)
    if suite is None:
        return []
    cells: dict[tuple[str, str], list] = {}  # (world, task) -> [archived, asked, transitions left, methods left]
    for config in suite.student_configs(Path(root) / "teachers"):
        cell = cells.setdefault((config.world, config.task), [0, 0, 0, set()])
        cell[1] += 1
        if (Path(root) / "students" / config.run_name() / "result.json").is_file():
            cell[0] += 1
        else:
            cell[2] += config.steps
            cell[3].add(config.method)
    archived = sum(c[0] for c in cells.values())
    asked = sum(c[1] for c in cells.values())
    left = sum(c[2] for c in cells.values())
    projected = _projection(cells, rates or {})
    lines = [f"The suite as defined now ({suite.regime} learner regime, {suite.seeds} seeds a cell) asks for "
             f"{asked:,} student runs; {archived:,} of them are archived here"
             + (f", and {left / 1e6:,.1f}M transitions are still to train." if left else ", all of them.")
             + (f" {projected}" if projected else ""), ""]
    if not left:
        return lines
    lines += ["| world | rung | runs archived / asked | transitions to train | methods not yet archived |",
              "|---|---|---|---|---|"]
    for (world, task), (done, total, todo, methods) in sorted(cells.items(),
                                                              key=lambda kv: (kv[0][0], rung_order(kv[0][1]))):
        missing = ", ".join(f"`{m}`" for m in suite.methods if m in methods) or "none"
        lines.append(f"| {world} | {task} | {done} / {total} | {todo / 1e6:,.1f}M | {missing} |")
    return [*lines, ""]


def _projection(cells: dict, rates: dict[str, float]) -> str:
    """The time still to train at the rates the archived runs recorded, per world and in all."""
    left: dict[str, float] = {}
    for (world, _), (_, _, todo, _) in cells.items():
        left[world] = left.get(world, 0.0) + todo
    known = {w: t / rates[w] for w, t in left.items() if t and rates.get(w)}
    unknown = sorted(w for w, t in left.items() if t and not rates.get(w))
    if not known:
        return ""
    hours = sum(known.values()) / 3600
    return ("At the rates its runs recorded on CPUs (one population process each, averaged over the methods and "
            "population sizes that ran: "
            + ", ".join(f"{w} {rates[w]:,.0f} transitions/s" for w in sorted(known)) + f"), that is about "
            f"{hours:,.1f} h of one process, {hours / 2:,.1f} h on 2 cores with a population on each"
            + (f" ({', '.join(unknown)} not counted: no run of it recorded its whole time)" if unknown else "") + ".")
