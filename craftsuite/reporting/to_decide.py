"""What an undecided comparison asks before it is decided: the seeds a side at which the
page's interval rules would decide it if its means and spreads held (``stats.seeds_to_resolve``,
a planning figure), the runs that adds to each side, and what those runs cost in transitions
and in hours of one process at the rate the archive measured. Listed quickest first, so a
campaign's next part can be chosen by its cost (and fixed before any of its runs is read)."""

from __future__ import annotations

from dataclasses import dataclass

from .board import COMPARED, Comparison, Entry, rung_order


def seeds_now(entry: Entry, base: Entry) -> int:
    """The seeds a side a comparison is read at: the smaller side's."""
    return min(len(entry.seeds), len(base.seeds))


def needed(c: Comparison, entry: Entry, base: Entry) -> int | None:
    """An undecided comparison's seeds a side to decide it, where more than it has (the page's
    clipped intervals and the bootstrap differ from the model: a figure at or below today's
    seeds is not said)."""
    need = c.seeds_to_decide
    return need if need is not None and need > seeds_now(entry, base) else None


@dataclass(frozen=True)
class Ask:
    """One undecided comparison, in one metric, and what deciding it would cost."""

    entry: Entry
    base: Entry
    metric: str  # one of ``board.COMPARED``
    seeds: int  # a side
    runs: tuple[int, int]  # to add: (distilled, scratch)
    rate: float | None  # transitions/s of one process its world measured (None: no rate for its world)
    gone: str | None = None  # the teacher the distilled runs read, where today's suites train it no more

    @property
    def made(self) -> int:
        """The runs to add that today's suites can make: the scratch side's alone where the
        distilled side's teacher is gone."""
        return self.runs[1] + (0 if self.gone else self.runs[0])

    @property
    def transitions(self) -> int:
        """Of the runs to add that can be made (both sides run at one budget: only such pairs
        are compared)."""
        return self.made * self.entry.budget

    @property
    def hours(self) -> float | None:
        """Of one process, for the runs that can be made, at the measured rate."""
        return self.transitions / self.rate / 3600 if self.rate else None


def teacher_of(entry: Entry) -> str | None:
    """The teacher run a distilled entry's runs read (its name: its settings' hash), from its
    first run's record; None where they read none."""
    from ..runs import read_config

    teacher = read_config(entry.runs[0]).get("effective", {}).get("teacher") if entry.runs else None
    return teacher.split("/")[0] if teacher else None


def asks(pairs, auc, measured: dict[str, dict[str, float]], current: frozenset[str] = frozenset(),
         teachers: frozenset[str] | None = None) -> list[Ask]:
    """Every comparison of ``pairs`` (read in final greedy success) and ``auc`` (the same
    pairs in AUC) that is undecided with a figure to say: those of the ``current`` learner
    regimes (the ones the page's suites run now, which a campaign adds seeds to) first, then
    quickest first: by the hours at the ``measured`` rates (``timing.rates``: per learner
    regime, per world's name, a world's variants such as another layout sharing its rate),
    then (and where no rate is known, after the rest) by transitions. ``teachers``: the
    teacher runs today's suites train (their names); a distilled side whose runs read another
    is marked (``Ask.gone``): a run of its settings can no longer be made."""
    found = []
    for metric, read in (("success", pairs), ("auc", auc)):
        for entry, base, c in read:
            need = None if c is None else needed(c, entry, base)
            if need is None:
                continue
            runs = (max(0, need - len(entry.seeds)), max(0, need - len(base.seeds)))
            teacher = teacher_of(entry) if teachers is not None and runs[0] else None
            found.append(Ask(entry, base, metric, need, runs, measured.get(entry.regime, {}).get(entry.world),
                             teacher if teacher not in (teachers or ()) else None))
    # the hours first: the learner regimes' and worlds' rates differ several times over; a row
    # whose distilled side cannot grow after the rest of its group (it asks runs that cannot be made)
    return sorted(found, key=lambda a: (a.entry.regime not in current, a.gone is not None, a.hours is None,
                                        a.hours or 0.0,
                                        a.transitions, rung_order(a.entry.task), a.entry.world_label, a.metric))


def to_decide_markdown(found: list[Ask], current: frozenset[str] = frozenset()) -> list[str]:
    """``asks`` as a table with a line on how to read it (nothing where none is undecided);
    ``current``: the learner regimes ``asks`` listed first."""
    if not found:
        return []
    order = "quickest first"
    if current:
        names = ", ".join(f"`{r}`" for r in sorted(current))
        order = f"those of the learner regime the suites run now ({names}) first, each group quickest first"
    rows = [f"| {a.entry.task} | {a.entry.world_label} | {a.entry.regime} | `{a.entry.label}` − `{a.base.label}` "
            f"| {COMPARED[a.metric]} | {a.entry.budget:,} | {len(a.entry.seeds)} / {len(a.base.seeds)} | {a.seeds} "
            f"| {a.runs[0]}{'*' if a.gone else ''} + {a.runs[1]} | {a.transitions:,} "
            f"| {'?' if a.hours is None else f'{a.hours:.1f}'} |" for a in found]
    return ["| rung | world | learner regime | distilled − scratch | metric | transitions per run "
            "| seeds now (distilled / scratch) | seeds a side asked | runs to add (distilled + scratch) "
            "| transitions to add | hours of one process |",
            "|---|---|---|---|---|---|---|---|---|---|---|", *rows, "",
            "Each undecided comparison with the seeds a side its next reading would need if its means and spreads "
            "held (the planning figure of the table above), " + order + ": the runs that adds to each side, their "
            "transitions, and their hours in one population process at the rate this page's runs of that world "
            "and learner regime recorded on a CPU (two processes on two cores each run somewhat below that rate: "
            "docs/performance.md). A spread read from a handful of seeds is itself uncertain, so a figure can move "
            "a long way as seeds are added; fix the seeds of a part before reading any of them. A comparison "
            "undecided in both metrics has a row for each, of the same runs: the larger figure covers both."
            + gone_note(found), ""]


def gone_note(found: list[Ask]) -> str:
    """The sentence on the rows whose distilled side can no longer grow (none: empty)."""
    gone = sorted({a.gone for a in found if a.gone})
    if not gone:
        return ""
    return (" \\* The distilled runs read a teacher trained under settings today's suites no longer use "
            f"({', '.join(gone)}): `craftsuite transfer` adds to the scratch side only (the row's transitions and "
            "hours are that side's), and the distilled side's seeds stay as they are.")
