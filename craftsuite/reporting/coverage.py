"""How much of a suite, as it is defined now, an archive directory holds: per world and
rung, the runs archived under the suite's current run keys against the runs it asks for,
and the transitions still to train. A suite runs in parts across machines and sessions; the
results page says which parts are in and which are not, so that a table that is missing a
cell reads as not run, not as cut."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..suites import SUITES, Suite
from .board import rung_order


@dataclass
class Coverage:
    """How much of a suite, as defined now, an archive holds."""

    suite: Suite
    cells: dict  # (world, task) -> [transitions to train, {method: [runs archived, runs asked]}]
    hours: float | None  # the time still to train at the recorded rates, one population process (None: no rate)
    unknown: list[str]  # the worlds left to train that no rate covers (not in ``hours``)
    projection: str  # that time in words ("" without it)
    held: int = 0  # finished student runs in the directory, of the suite's cells or not

    @property
    def archived(self) -> int:
        return sum(done for _, methods in self.cells.values() for done, _ in methods.values())

    @property
    def asked(self) -> int:
        return sum(total for _, methods in self.cells.values() for _, total in methods.values())

    @property
    def left(self) -> int:
        return sum(todo for todo, _ in self.cells.values())


def coverage(root: Path, suite_name: str, rates: dict[str, float] | None = None) -> Coverage | None:
    """The archive directory ``root`` of the suite ``suite_name`` against the suite's runs;
    None for a name that is not a suite of this version (an archive of a removed or renamed
    one). ``rates``: per world, the transitions per second of one population process (the
    suite's learner regime's entry of ``timing.rates``), from which the time still to train
    is projected."""
    suite = SUITES.get(suite_name)
    if suite is None:
        return None
    cells: dict[tuple[str, str], list] = {}
    for config in suite.student_configs(Path(root) / "teachers"):
        cell = cells.setdefault((config.world, config.task), [0, {}])
        seeds = cell[1].setdefault(config.method, [0, 0])
        seeds[1] += 1
        if (Path(root) / "students" / config.run_name() / "result.json").is_file():
            seeds[0] += 1
        else:
            cell[0] += config.steps
    hours, unknown, projection = _projection(cells, rates or {})
    students = Path(root) / "students"
    held = sum((run / "result.json").is_file() for run in students.iterdir()) if students.is_dir() else 0
    return Coverage(suite, cells, hours, unknown, projection, held)


def coverage_markdown(found: Coverage | None) -> list[str]:
    """Lines of Markdown: ``coverage``'s sentence and, while runs are missing, its table per
    world and rung; none without a coverage (a directory of no suite of this version)."""
    if found is None:
        return []
    suite, left = found.suite, found.left
    lines = [f"The suite as defined now ({suite.regime} learner regime; {suite.seeds_text()}) asks for "
             f"{found.asked:,} student runs; {found.archived:,} of them are archived here"
             + (f", and {left / 1e6:,.1f}M transitions are still to train." if left else ", all of them.")
             + (f" The directory holds {found.held:,} finished student runs in all: the others are runs the suite "
                "does not ask for now (other seeds, learner regimes, budgets or settings)."
                if found.held > found.archived else "")
             + (f" {found.projection}" if found.projection else ""), ""]
    if not left:
        return lines
    lines += ["| world | rung | runs archived / asked | transitions to train | methods short of seeds (archived of "
              "asked, where any are) |",
              "|---|---|---|---|---|"]
    for (world, task), (todo, methods) in sorted(found.cells.items(), key=lambda kv: (kv[0][0], rung_order(kv[0][1]))):
        done, total = (sum(seeds) for seeds in zip(*methods.values()))
        missing = ", ".join(f"`{m}`" + (f" ({methods[m][0]} of {methods[m][1]})" if methods[m][0] else "")
                            for m in suite.methods if m in methods and methods[m][0] < methods[m][1]) or "none"
        lines.append(f"| {world} | {task} | {done} / {total} | {todo / 1e6:,.1f}M | {missing} |")
    return [*lines, ""]


def _projection(cells: dict, rates: dict[str, float]) -> tuple[float | None, list[str], str]:
    """The time still to train at the rates the page's runs of the suite's regime recorded: in hours of one
    population process, the worlds left to train that no rate covers, and in words (None
    and "" where no world left to train has a rate)."""
    left: dict[str, float] = {}
    for (world, _), (todo, _) in cells.items():
        left[world] = left.get(world, 0.0) + todo
    known = {w: t / rates[w] for w, t in left.items() if t and rates.get(w)}
    unknown = sorted(w for w, t in left.items() if t and not rates.get(w))
    if not known:
        return None, unknown, ""
    hours = sum(known.values()) / 3600
    words = ("At the rates this page's runs of its learner regime recorded on CPUs (one population process each, "
             "averaged over the tasks, methods and population sizes that ran: "
             + ", ".join(f"{w} {rates[w]:,.0f} transitions/s" for w in sorted(known)) + f"), that is about "
             f"{hours:,.1f} h of one process, {hours / 2:,.1f} h on 2 cores with a population on each"
             + (f" ({', '.join(unknown)} not counted: no run of it recorded its whole time)" if unknown else "") + ".")
    return hours, unknown, words
