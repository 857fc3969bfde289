"""Leaderboards and results pages (Markdown, CSV), rendered from a board's entries."""

from __future__ import annotations

import csv
import io
import json
import math
import shutil
from pathlib import Path

import numpy as np

from .. import stats
from ..files import atomic_write
from ..ids import CONT, world_kind
from ..regimes import describe
from ..regimes import order as regime_order
from ..runs import RunError, read_config, read_result
from ..suites import SUITES, seeds_text
from ..archive import size as archive_size
from .board import (
    METRICS,
    THRESHOLD,
    SELF_REPORTED,
    SMALLEST_DIFFERENCE,
    ALL_SAME,
    COMPARED,
    Aggregate,
    Board,
    Comparison,
    Entry,
    aggregates,
    best_run,
    compare,
    distilled_against_scratch,
    finite_mean,
    rung_order,
    unread_reason,
    verdict,
)
from .coverage import Coverage, coverage, coverage_markdown
from .learned import Learned, learned, learned_markdown
from .looks import looks
from .plots import draw_curves, draw_profiles, file_part, save_figures
from .sources import read_runs, session_line
from .timing import rates, training_time_lines, wall_time_lines
from .to_decide import asks, needed, seeds_now, to_decide_markdown

# The authors' shipped continuous results, one run each, mean episode reward over the last
# 5% of 2e6 steps (not the same metric window as ours, nor our MuJoCo world).
PAPER_REFERENCE = {
    "BlindCraftsman": {"td3-dynamic": 19.95, "td3": 17.06},
    "DungeonQuest": {"td3-dynamic": 90.45, "td3": 87.97},
    "GoldMine": {"td3-dynamic": 29.59, "td3": 8.58},  # their third continuous task (the paper says Diamond Mine)
}

SEEDS_LISTED = 20  # beyond this, a row's seeds are counted at 0, at 1 and between instead of listed
LEGEND = (
    "Per task: the mean over seeds with its 95% Student t-interval (none below 3 seeds; where every seed sat at 0, "
    "or every seed at 1, the exact interval for values in [0, 1], as no spread gives a t-interval no width; "
    "elsewhere widened by the quasi-binomial score interval where that reaches further, which matters near 0 "
    "and 1), and "
    "every seed's "
    f"final greedy success (beyond {SEEDS_LISTED} seeds, how many sat at 0, at 1 and between). success: "
    "greedy, at the last evaluation; AUC: mean greedy success over the evaluations during training; return "
    "and training success: training episodes (exploration noise on) in the last 10% of the budget; reached "
    "80%: how many seeds reached 80% greedy success, and the median transitions of those that did; budget: "
    "transitions / gradient updates per run. A world with settings beyond the registered one names them.")

SELF_REPORTED_LEGEND = (
    "*Self-reported*: trained outside CraftSuite and recorded by `craftsuite.Recorder` on the suite's budget and "
    "evaluation schedule (its evaluations are `craftsuite.evaluate`'s, on the same seeds and world); CraftSuite did "
    "not train it. Its learner is its own, so it stands beside every learner regime's runs.")

AGGREGATE_LEGEND = (
    "Across the tasks every method of a world ran: the interquartile mean (IQM) over all runs of all tasks, each "
    "task weighing the same whatever its seeds (a rung run at 200 seeds counts as one at 10), with "
    "95% stratified-bootstrap intervals (each task's runs resampled on their own, 2,000 resamples), and the "
    "probability that a run of the method beats a run of {baseline} on the same task (ties count half; 0.5: no "
    "difference), averaged over tasks. With few seeds these intervals run narrow (an IQM interval over 4 tasks x "
    "5 seeds covered 89% of simulated cases, not 95%; docs/decisions.md), so two intervals apart are weaker "
    "evidence than they look; and two that overlap show the methods not told apart, not that they are alike "
    "(that takes the interval of their difference).")


def _fmt(estimate: stats.Estimate, digits: int = 2, signed: bool = False) -> str:
    if math.isnan(estimate.value):
        return "n/a"
    sign = "+" if signed else ""
    if not estimate.has_interval:
        return f"{estimate.value:{sign}.{digits}f}"
    return f"{estimate.value:{sign}.{digits}f} [{estimate.low:{sign}.{digits}f}, {estimate.high:{sign}.{digits}f}]"


def _difference_text(estimate: stats.Estimate) -> str:
    """A difference with its interval, to as many decimals (up to 4) as keep a bound from
    printing as a line it does not sit on: the verdicts read the bounds unrounded, so "+0.20"
    could stand for an interval inside the band or one reaching past it, and "-0.00" for an
    interval that excludes zero (a real gap) or one that touches it. A real gap's bound too
    near zero for 4 decimals prints in powers of ten (+3.0e-05)."""
    digits = 2
    bounds = (estimate.low, estimate.high) if estimate.has_interval else ()
    one_side = estimate.has_interval and (estimate.low > 0 or estimate.high < 0)

    def blurred(b: float) -> bool:
        at_band = abs(b) != SMALLEST_DIFFERENCE and round(abs(b), digits) == SMALLEST_DIFFERENCE
        at_zero = one_side and round(b, digits) == 0
        return at_band or at_zero

    while digits < 4 and any(blurred(b) for b in bounds):
        digits += 1
    if math.isnan(estimate.value) or not one_side:
        return _fmt(estimate, digits, signed=True)

    def text(x: float) -> str:  # as _fmt, but a figure still rounding to zero in powers of ten
        return f"{x:+.1e}" if round(x, digits) == 0 else f"{x:+.{digits}f}"

    return f"{text(estimate.value)} [{text(estimate.low)}, {text(estimate.high)}]"


def ranked(rows: list[Entry]) -> list[Entry]:
    """One task's rows as its table orders them: by AUC, then return, best first."""
    return sorted(rows, key=lambda e: (-finite_mean(e.values["auc"]), -finite_mean(e.values["return"]), e.label))


def per_seed_text(values: list[float]) -> str:
    """A row's final greedy success per seed: each listed, up to ``SEEDS_LISTED``; beyond,
    how many sat at 0, at 1 and between (outcomes per seed here are mostly 0 or 1, so the
    counts say what a list of 100 would, in a cell a reader can take in)."""
    if len(values) <= SEEDS_LISTED:
        return " ".join(f"{v:.2f}" for v in values)
    low, high, unmeasured = (sum(v == 0 for v in values), sum(v == 1 for v in values),
                             sum(math.isnan(v) for v in values))
    return (f"{low} at 0.00, {high} at 1.00, {len(values) - low - high - unmeasured} between"
            + (f", {unmeasured} not measured" if unmeasured else ""))


def task_table(rows: list[Entry]) -> list[str]:
    """The table of one task in one world: a row per entry (``ranked``) and, in the
    continuous worlds, the authors' published returns as reference rows."""
    lines = ["| method | seeds | success | success per seed | AUC | return (last 10%) "
             "| training success (last 10%) | reached 80% | budget |",
             "|---|---|---|---|---|---|---|---|---|"]
    for e in ranked(rows):
        st = e.stats
        seeds = per_seed_text(e.values["success"])
        label = f"{e.label} *(self-reported)*" if e.self_reported else e.label
        lines.append(f"| {label} | {len(e.seeds)} | {_fmt(st['success'])} | {seeds} | {_fmt(st['auc'])} "
                     f"| {_fmt(st['return'], 1)} | {_fmt(st['train_success'])} | {e.reached} | {e.budget_text} |")
    # in both continuous worlds: the authors' figures come from their kinematic toy (our
    # Kinematic world follows its step), beside which the MuJoCo world is the harder test
    ref = PAPER_REFERENCE.get(rows[0].task) if world_kind(rows[0].world) == CONT else None
    for method, value in (ref or {}).items():
        lines.append(f"| *reference: authors' {method}, 1 run, 2M steps (return over the last 5%)* "
                     f"| 1 | | | | {value:.2f} | | | |")
    return lines


def leaderboard_markdown(board: Board, title: str | None = "# Leaderboard", profiles: dict[str, Path] | None = None,
                         aggs: list[Aggregate] | None = None, level: int = 2) -> str:
    """The board as Markdown, its sections under headings of ``level``; ``profiles``: per
    world label, a performance-profile image to link; ``aggs``: the board's
    ``aggregates``, if already computed."""
    from ..methods import METHODS

    h = "#" * level
    lines = [title, ""] if title else []
    regimes = board.regimes
    if len(regimes) > 1:  # each regime a leaderboard of its own: its runs are never pooled with another's
        aggs = aggregates(list(board)) if aggs is None else aggs
        lines += [f"Runs of {len(regimes)} learner regimes: each regime's runs have tables of their own below, "
                  "never pooled with another's.", ""]
        for regime in regimes:
            part = leaderboard_markdown(board.of_regime(regime), title=f"{h} Learner regime `{regime}`",
                                        profiles=profiles, aggs=[a for a in aggs if a.regime == regime],
                                        level=level + 1)
            lines += [part.strip(), ""]
        lines += [f"Not read: {reason}\n" for reason in board.unreadable]
        return "\n".join(lines)
    entries = list(board)
    lines += [LEGEND, ""]
    if regimes and regimes[0] != SELF_REPORTED:
        lines += [f"Learner regime: `{regimes[0]}`, {describe(regimes[0])}.", ""]
    if any(e.self_reported for e in entries):
        lines += [SELF_REPORTED_LEGEND, ""]
    for task, world in sorted({(e.task, e.world_label) for e in entries}, key=lambda k: (rung_order(k[0]), k[1])):
        rows = ranked([e for e in entries if (e.task, e.world_label) == (task, world)])
        lines += [f"{h} {task} ({world})", "", *task_table(rows)]
        pairs = distilled_against_scratch(rows, self_reported=True)
        # the target reads transitions: a self-reported run at another budget is not set against it
        same = [(e, base) for e, base in pairs if not e.self_reported or e.budget == base.budget]
        if same:
            lines += ["", f"Transfer target (80% greedy success in at most half the transitions "
                      f"`{same[0][1].method}` needs; median over seeds, a seed that never reached 80% counting "
                      "as never): " + "; ".join(f"`{e.label}` {verdict(e, base, 'steps_to_80')}"
                                                 for e, base in same) + "."]
        if pairs:
            lines += ["", f"Against scratch, {COMPARED['success']} (the difference of the means with the two "
                      "sides' intervals squared and added where a side's interval reaches beyond its t-interval "
                      "(most comparisons), else Welch's t-interval; 95% unless said; the probability that a run "
                      "beats a scratch run, with its bootstrap interval): "
                      + "; ".join(_comparison_text(*pair) for pair in in_metric(pairs, "success")) + ".", "",
                      f"Against scratch, {COMPARED['auc']} (how soon a run learned; the same rules): "
                      + "; ".join(_comparison_text(*pair) for pair in in_metric(pairs, "auc")) + "."]
        lines += obstacles_markdown(rows)
        notes = _variant_notes(rows)
        if notes:
            lines += ["", "Runs of one method that differ in more than the seed are not pooled; "
                      "each setting is a row of its own (put runs of another setting in another directory):", ""]
            lines += [f"- {n}" for n in notes]
        waiting = [u for u in board.unfinished if (u.task, u.world_label) == (task, world)]
        if waiting:
            lines += ["", "Unfinished, not counted: " + ", ".join(
                f"{u.method} seed {u.seed}" for u in sorted(waiting, key=lambda u: (u.method, u.seed)))]
        lines.append("")
    others = sorted({(u.task, u.world_label) for u in board.unfinished} - {(e.task, e.world_label) for e in entries})
    for task, world in others:
        lines += [f"{h} {task} ({world})", "", "No run finished yet; unfinished: " + ", ".join(
            f"{u.method} seed {u.seed}" for u in board.unfinished if (u.task, u.world_label) == (task, world)), ""]
    for reason in board.unreadable:
        lines += [f"Not read: {reason}", ""]
    aggregate_lines = aggregates_markdown(aggregates(entries) if aggs is None else aggs, profiles, level + 1)
    if aggregate_lines:
        lines += [f"{h} Across tasks", "", *aggregate_lines]
    shown = [m for m in METHODS if m in {e.method for e in entries}]
    shown += sorted({e.method for e in entries} - set(shown))  # runs of a method no longer in the table
    lines += ["Methods:", ""]
    lines += [f"- `{m}`: {_method_note(m, [e for e in entries if e.method == m])}" for m in shown]
    lines.append("")
    return "\n".join(lines)


def _variant_notes(rows) -> list[str]:
    """What tells a method's variants apart, one note each, in the order of their letters (the
    table ranks them by success, so (b) may stand above (a))."""
    return [f"*{e.label}: " + "; ".join(f"{k} = {json.dumps(v)}" for k, v in e.differs.items()) + "*"
            for e in sorted((e for e in rows if e.variant), key=lambda e: (e.method, len(e.variant), e.variant))]


def _method_note(method: str, rows: list[Entry]) -> str:
    """What a method of a board's legend is: its row's description; a learner trained
    outside CraftSuite, with the libraries its records name; else a row this process has
    not registered."""
    from ..methods import METHODS  # (the rows registered by then: a user's too)

    if method in METHODS:
        return METHODS[method].description
    if rows and all(e.self_reported for e in rows):
        from ..runs import read_config

        configs = [read_config(run) for e in rows for run in e.runs]
        if not all(c.get("self_reported") for c in configs):  # records of the format written by other code
            return "trained outside CraftSuite's trainers (its records hold no CraftSuite learner's settings)"
        libraries = sorted({c.get("library") or "" for c in configs} - {""})
        return ("self-reported: trained outside CraftSuite" + (f" ({'; '.join(libraries)})" if libraries else "")
                + ", its records written by craftsuite.Recorder")
    return ("not a method of this version (a row of your own: `craftsuite leaderboard --methods module:name` "
            "reads its runs as the method they are)")


def _share(x: float) -> str:
    """A share of episodes, where a handful among thousands must not read as none."""
    return "0%" if x == 0 else "<1%" if x < 0.005 else f"{x:.0%}"


def obstacles_markdown(rows: list[Entry]) -> list[str]:
    """Where no method of one task's table learned it (mean final greedy success below
    ``THRESHOLD`` for every row), what each method's training episodes reached
    (``craftsuite.reporting.obstacles``): completions per 100k transitions, the visited
    automaton state closest to acceptance, and the share of episodes each proposition held in."""
    from ..task_registry import resolve_task
    from .obstacles import completed_per_100k, method_progress, route

    if not rows or any(finite_mean(e.values["success"]) >= THRESHOLD for e in rows):
        return []
    found, unread = [], []
    for e in ranked(rows):
        try:
            progress = method_progress(e.runs, [(c.episodes[:, 2], c.reached) for c in e.curves])
            per_100k = (progress.completed_per_100k if progress is not None
                        else float(np.mean([completed_per_100k(run) for run in e.runs])))
        except (RunError, OSError, ValueError) as err:
            unread.append(f"- not read: {e.label}: {err}")
            continue
        found.append((e, progress, per_100k))
    intro = (f"No method learned it (mean final greedy success below {THRESHOLD:.0%}). Where the training episodes "
             "stopped: completed training episodes per 100k transitions (mean over seeds)")
    if not any(p is not None and p.furthest is not None for _, p, _ in found):
        return ["", intro + " (what the episodes reached on the way is not in these records: they were made before "
                "episodes.csv recorded it):", "", "| method | seeds | completed per 100k |", "|---|---|---|",
                *[f"| {e.label} | {len(e.seeds)} | {per_100k:.1f} |" for e, _, per_100k in found], *unread]
    lines = []
    for e, progress, per_100k in found:
        if progress is None or progress.furthest is None:
            furthest = reached = "not recorded"
        else:
            f = progress.furthest
            after = route(resolve_task(e.task).automaton, f.state)
            where = {None: "", (): " (the initial)"}.get(None if after is None else tuple(after),
                                                          f" (after {', '.join(after or [])})")
            furthest = (f"state {f.state}{where}"
                        + f", {f.distance} edge{'s' if f.distance != 1 else ''} from acceptance "
                        f"({_share(f.share)} of episodes)")
            reached = ", ".join(f"{p} {_share(share)}" for p, share in progress.seen_share.items())
        # the counts too: 2 completions in 47,000 episodes round to 0.0 per 100k, as none would
        counts = f" ({progress.completed:,} of {progress.episodes:,} episodes)" if progress is not None else ""
        lines.append(f"| {e.label} | {len(e.seeds)} | {per_100k:.1f}{counts} | {furthest} | {reached} |")
    return ["", intro + "; of the automaton states the episodes visited, the one fewest edges from acceptance (of "
            "those as close, the one furthest from the start) and the share of episodes that visited it; the share "
            "of episodes in which each proposition held at "
            "some step (seeds pooled):", "",
            "| method | seeds | completed per 100k | furthest automaton state | propositions reached |",
            "|---|---|---|---|---|", *lines, *unread]


def _comparison_text(entry: Entry, baseline: Entry, c: Comparison | None) -> str:
    """One pair of ``in_metric`` in words (None: the two ran at other budgets)."""
    if c is None:
        return f"`{entry.label}` not compared: {entry.budget:,} transitions against {baseline.budget:,}"
    return (f"`{entry.label}` {_difference_text(c.difference)}, P(> `{baseline.label}`) {_fmt(c.improvement)}: "
            f"**{c.verdict}**" + _notes([c.note, _looks_text(c)]))


def _looks_text(c: Comparison) -> str:
    """Where a comparison was read more than once: how often, and at what level (else "")."""
    return "" if c.looks == 1 else f"read {c.looks} times: every interval at {c.level:.1%}"


def _notes(notes: list[str]) -> str:
    """A verdict's notes, those that say something, as one parenthesis."""
    said = [n for n in notes if n]
    return f" ({'; '.join(said)})" if said else ""


def comparisons(boards: list[Board]) -> list[tuple[Entry, Entry, Comparison | None]]:
    """Every distilled method against its algorithm from scratch, rung by rung, across
    ``boards`` (easiest rung first): each pair with its verdict in final greedy success
    (``board.compare``), None where the two ran at other budgets (never set side by side as
    one comparison). ``in_metric`` reads the same pairs in AUC."""
    return in_metric([pair for board in boards for pair in _pairs(board)], "success")


def in_metric(pairs, metric: str) -> list[tuple[Entry, Entry, Comparison | None]]:
    """``pairs`` (each starting with a method's entry and its baseline's, as ``comparisons``
    gives them) with their verdicts in ``metric``, one of ``board.COMPARED``: None where the
    two ran at other budgets."""
    return [(entry, base, compare(entry, base, metric, looks(entry, base)) if entry.budget == base.budget else None)
            for entry, base, *_ in pairs]


def _pairs(board: Board) -> list[tuple[Entry, Entry]]:
    """A board's distilled methods, each with its algorithm from scratch, easiest rung first."""
    out, entries = [], list(board)
    for task, world, regime in sorted({(e.task, e.world_label, e.regime) for e in entries},
                                      key=lambda k: (rung_order(k[0]), k[1], k[2])):
        here = [e for e in entries if (e.task, e.world_label, e.regime) == (task, world, regime)]
        out += distilled_against_scratch(here)
    return out


def decided_by_regime(pairs) -> dict[str, dict[str, int]]:
    """Per learner regime (a regime's runs are never pooled with another's), in the regimes'
    order: the comparisons, how many say *ahead*, *behind* and *no difference*, how many of
    the *ahead* and *behind* by less than the smallest difference ("ahead by less", "behind
    by less"), and how many were decided only because every seed of both sat at 0 or at 1."""
    tally: dict[str, dict[str, int]] = {}
    for entry, base, c in pairs:
        mine = tally.setdefault(entry.regime, {**dict.fromkeys(("comparisons", "ahead", "behind", "no difference",
                                                                "ahead by less", "behind by less", "trivial"), 0),
                                               "seeds to decide": []})
        mine["comparisons"] += 1
        need = None if c is None else needed(c, entry, base)
        if need is not None:
            mine["seeds to decide"].append(need)
        if c is not None and c.decided:
            mine[c.side or "no difference"] += 1
            if c.small:
                mine[f"{c.side} by less"] += 1
            mine["trivial"] += c.trivial
    return {regime: tally[regime] for regime in sorted(tally, key=regime_order)}


def _decided(t: dict[str, int]) -> int:
    return t["ahead"] + t["behind"] + t["no difference"]


def _sided(t: dict[str, int], side: str) -> str:
    """How many of a tally say ``side`` ("ahead" or "behind"), and how many of those by less
    than the smallest difference, in words a reader does not take for *no difference*: "8 (5
    of them a real gap under 0.2)"."""
    small, n = t[f"{side} by less"], t[side]
    if not small:
        return f"{n}"
    which = "a" if n == 1 else "all of them a" if small == n else f"{small} of them a"
    return f"{n} ({which} real gap under {SMALLEST_DIFFERENCE:g})"


def _seeds_to_decide(c: Comparison, entry: Entry, base: Entry) -> str:
    need = needed(c, entry, base)
    return "" if need is None else (f"at these means and spreads: about {need} seeds a side, where the smaller side "
                                    f"has {seeds_now(entry, base)}")


def comparisons_markdown(pairs, auc=None) -> list[str]:
    """The table of ``comparisons`` (``pairs``) and of the same pairs in AUC (``auc``:
    ``in_metric(pairs, "auc")``, read here if not given): the difference, probability and
    verdict of each in final greedy success and in AUC, and how many each decides."""
    if not pairs:
        return []
    auc = in_metric(pairs, "auc") if auc is None else auc
    rows = []
    for (entry, base, c), (_, _, in_auc) in zip(pairs, auc):
        head = f"| {entry.task} | {entry.world_label} | {entry.regime} | `{entry.label}` − `{base.label}` "
        rows.append(head + (f"| | | {entry.budget:,} against {base.budget:,} | not compared: other budgets | | | |"
                            if c is None else f"| {entry.budget:,} | {_cells(c, entry, base)} | "
                            f"{_cells(in_auc, entry, base)} |"))
    return ["| rung | world | learner regime | distilled − scratch | transitions per run "
            "| difference in success [interval] | P(distilled > scratch) [bootstrap] "
            "| verdict | difference in AUC [interval] | P(distilled > scratch) in AUC [bootstrap] | verdict in AUC |",
            "|---|---|---|---|---|---|---|---|---|---|---|", *rows, "",
            f"Decided in final greedy success (ahead, behind, or no difference of {SMALLEST_DIFFERENCE:g} or more) "
            f"{_tally_text(pairs)}: *ahead*/*behind* where the two means' intervals are apart (a row its own "
            "cells would not decide says so), or where the "
            "probability's interval (counted from 5 seeds a side) excludes one half and the difference's excludes 0 "
            "on the same side (the "
            "probability's interval alone errs up to twice its 5% at 5-10 seeds a side: docs/performance.md; "
            f"*by less than {SMALLEST_DIFFERENCE:g}* added where the difference's interval lies within "
            f"±{SMALLEST_DIFFERENCE:g} as well); "
            f"*no difference* where the difference's interval lies within ±{SMALLEST_DIFFERENCE:g} (a probability "
            "away from one half beside it says only that one side's runs won more of the pairings, a lead the "
            "rules did not confirm: the difference of the means may even lean the other way). A side whose "
            "seeds all sat at 0 (or all at 1) has no spread to read a t-interval from: its interval is the exact "
            "one for values in [0, 1] (Clopper and Pearson's for n of n: 10 seeds all at 1 leave any mean above "
            "0.69 at 95%). A side nearly there (19 seeds at 1 and one at 0) has a t-interval too narrow on its "
            "inner side ([0.85, 1.00], missing a true 0.8 more often than 5%): its interval is the t-interval "
            "widened by the quasi-binomial score interval, which lets the spread grow as a mean moves from the "
            "bound as a proportion's does ([0.74, 1.00]). Beside a side whose interval reaches beyond its "
            "t-interval (the score interval leans toward the middle, so by a little most sides' do), the "
            "difference's interval squares and adds the two sides' (MOVER, as Newcombe's method 10 does with "
            "Wilson intervals) in place of Welch's, so a row near a bound is decided only where its seeds can "
            "say so (experiments/bounded-intervals, experiments/near-bound-intervals). A comparison "
            "read at fewer seeds (of either side) before they grew had more than one chance to be decided. Its "
            "readings k are counted from the records: one after the runs of each commit that added seeds to "
            "either side (as the runs' config.json records; two such commits count as two readings even where "
            "nobody read between them), and one for each reading results/<suite>/looks.json names. Every "
            f"interval of a comparison read k times is at 1 − {1 - stats.LEVEL:g}/k (Bonferroni), and its row "
            "says so (\"read 3 times: every interval at 98.3%\"). An undecided row says how many "
            "seeds a side the interval rules would need to decide it at its next reading if its means and "
            "spreads held (a planning figure: a spread read from a handful of seeds is itself uncertain, and at "
            "that count the expected interval only just decides, so about half the time more seeds are needed)."
            + _by_regime_text(pairs), "",
            "Decided in AUC (the mean greedy success over the evaluations during training: how soon and how steadily "
            "a run learned, where final success says only where it ended), by the same rules and the same smallest "
            f"difference, {_tally_text(auc, 'auc')}. A gap of {SMALLEST_DIFFERENCE:g} in AUC is a large one (a run "
            f"at 1 for a further {SMALLEST_DIFFERENCE:.0%} of its evaluations, or a level {SMALLEST_DIFFERENCE:g} "
            "higher throughout), so an AUC *no difference* rules out only a gap that large." + _by_regime_text(auc), ""]


def _cells(c: Comparison, entry: Entry, base: Entry) -> str:
    """A comparison's difference, probability and verdict, as three cells of a table row."""
    return (f"{_difference_text(c.difference)} | {_fmt(c.improvement)} | "
            f"{c.verdict}" + _notes([c.note, _looks_text(c), _seeds_to_decide(c, entry, base)]))


def _tally_text(pairs, metric: str = "success") -> str:
    """How many of ``pairs`` (read in ``metric``) are decided, and how many of those only
    because every value of both sides was 0 (or 1)."""
    tally = decided_by_regime(pairs).values()
    return (f"on {sum(_decided(t) for t in tally)} of {len(pairs)} comparisons, {sum(t['trivial'] for t in tally)} "
            f"of them only {_all_same(metric)}")


def _all_same(metric: str) -> str:
    """Why a comparison in ``metric`` was decided trivially, as the counts say it."""
    return f"because every seed of both sat at 0 or at 1{ALL_SAME[metric]}"


def _by_regime_text(pairs) -> str:
    """Where ``pairs`` span several learner regimes, each regime's share decided other than
    by all-0/all-1 seeds, as a sentence (else nothing: the count before it says it all)."""
    tally = decided_by_regime(pairs)
    return (" By learner regime, decided and not only by all-0/all-1 seeds: " + "; ".join(
        f"`{regime}` {_decided(t) - t['trivial']} of {t['comparisons']}" for regime, t in tally.items()) + "."
        if len(tally) > 1 else "")


def aggregates_markdown(aggs: list[Aggregate], images: dict[str, Path] | None = None, level: int = 3) -> list[str]:
    h = "#" * level
    lines = []
    for agg in aggs:
        base = agg.baseline
        if not agg.iqm:
            lines += [f"{h} {agg.label}", "",
                      "Nothing to aggregate: " + "; ".join(agg.left_out or ["no method"]) + ".", "",
                      *_against_baseline_markdown(agg)]
            continue
        lines += [f"{h} {agg.label}: {len(agg.tasks)} task{'s' if len(agg.tasks) > 1 else ''} "
                  f"({', '.join(agg.tasks)})", "",
                  AGGREGATE_LEGEND.format(baseline=f"`{base}`" if base else "the algorithm from scratch (not run)"),
                  "",
                  "| method | runs | IQM success | IQM AUC | P(improves on " + (base or "scratch") + "): success "
                  "| P(improves): AUC |",
                  "|---|---|---|---|---|---|"]
        order = sorted(agg.iqm, key=lambda m: (-agg.iqm[m]["auc"].value, m))
        for m in order:
            imp = agg.improvement.get(m)
            lines.append(f"| {m} | {agg.runs[m]} | {_fmt(agg.iqm[m]['success'])} | {_fmt(agg.iqm[m]['auc'])} | "
                         + (f"{_fmt(imp['success'])} | {_fmt(imp['auc'])} |" if imp else
                            ("(the baseline) | |" if m == base else "| |")))
        if agg.left_out:
            lines += ["", "Not in this aggregate: " + "; ".join(agg.left_out) + "."]
        beyond = _against_baseline_markdown(agg)
        if beyond:
            lines += ["", *beyond[:-1]]
        if images and agg.label in images:
            lines += ["", f"![performance profile, {agg.label}]({images[agg.label].as_posix()})"]
        lines.append("")
    return lines


def _against_baseline_markdown(agg: Aggregate) -> list[str]:
    """Each method against the baseline on every task both ran, where that is more tasks
    than the aggregate's table (every method, where there is no table)."""
    rows = {m: pair for m, pair in agg.against_baseline.items() if not agg.iqm or len(pair.tasks) > len(agg.tasks)}
    if not rows:
        return []
    base = next(iter(rows.values())).baseline
    which = ("Each method that ran tasks beyond those every method ran (the table above reads only the tasks "
             "every method ran)"
             if agg.iqm else "Each method")
    lines = [f"{which} against `{base}` on every task both ran: the probability that a run of the method beats a "
             f"run of `{base}` on the same task (ties count half), averaged over those tasks, with its 95% "
             "stratified-bootstrap interval (each row its own tasks: rows are not compared with each other):", "",
             f"| method | tasks | runs (method / {base}) | P(improves on {base}): success | P(improves): AUC |",
             "|---|---|---|---|---|"]
    for m in sorted(rows, key=lambda m: (-len(rows[m].tasks), m)):
        pair = rows[m]
        lines.append(f"| {m} | {len(pair.tasks)} ({', '.join(pair.tasks)}) | {pair.runs[0]} / {pair.runs[1]} | "
                     f"{_fmt(pair.improvement['success'])} | {_fmt(pair.improvement['auc'])} |")
    return lines + [""]


def leaderboard_csv(board: Board) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(["task", "world", "regime", "method", "variant", "seeds",
                     *(f"{m}{s}" for m in METRICS for s in ("", "_lo", "_hi")),
                     "success_per_seed", "reached_80", "reached_80_median", "differs_in", "budget_transitions",
                     "updates", "set_apart"])
    for e, apart in _rows(board):
        st = e.stats
        writer.writerow([e.task, e.world_label, e.regime, e.method, e.variant, len(e.seeds),
                         *(("" if math.isnan(v) else v) for m in METRICS
                           for v in (st[m].value, st[m].low, st[m].high)),
                         " ".join(str(v) for v in e.values["success"]), e.reached.k,
                         "" if e.reached.median is None else e.reached.median, " ".join(e.differs), e.budget,
                         "" if e.updates is None else e.updates, int(apart)])
    return buf.getvalue()


def _rows(board: Board):
    """The board's entries and then those it set apart (``Board.apart``), each with whether it was."""
    yield from ((e, False) for e in board)
    yield from ((e, True) for e in (board.apart or []))


# the per-seed export's columns: DeepLTL's published per-seed results' (method, task, seed,
# success rate, mean steps), then what places a run: its world, budget and learner regime
SEED_FIELDS = ("method", "task", "seed", "success_rate", "mean_steps", "world", "budget_transitions", "regime",
               "self_reported", "set_apart")


def seeds_csv(board: Board) -> str:
    """Every run of the board, one row each (``SEED_FIELDS``): its final greedy success and
    the mean length of that evaluation's episodes."""
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(SEED_FIELDS)
    for e, apart in _rows(board):
        for seed, success, length in zip(e.seeds, e.values["success"], e.lengths or [math.nan] * len(e.seeds)):
            writer.writerow([e.label, e.task, seed, "" if math.isnan(success) else success,
                             "" if math.isnan(length) else length, e.world_label, e.budget, e.regime,
                             int(e.self_reported), int(apart)])
    return buf.getvalue()


def write_leaderboard(board: Board, out) -> Path:
    """``leaderboard.md``, ``leaderboard.csv``, ``seeds.csv`` (a row per run) and the
    performance profiles in ``out``; returns the Markdown path. Runs the board set apart
    (``Board.apart``) follow the leaderboard under their own heading and are rows of the
    CSVs (``set_apart`` 1). All is drawn and rendered before the first file is written."""
    out = Path(out)
    aggs = aggregates(list(board))
    drawn = draw_profiles(board, aggs)
    profiles = {d.world_label: Path(f"{d.stem}.png") for d in drawn}
    text = (leaderboard_markdown(board, profiles=profiles, aggs=aggs) if board.entries or board.unfinished
            else "# Leaderboard\n\nNo run of the suite's cells has finished.")
    text = "\n".join([text.rstrip(), "", *superseded_markdown(board.apart, level=2)]).rstrip() + "\n"
    table, per_seed = leaderboard_csv(board), seeds_csv(board)
    save_figures(drawn, out)
    atomic_write(out / "seeds.csv", per_seed)
    atomic_write(out / "leaderboard.csv", table)
    atomic_write(out / "leaderboard.md", text)
    return out / "leaderboard.md"


def write_results_page(run_dirs, path, title: str = "Results") -> Path:
    """A results page (Markdown) from transfer output directories: per directory, its
    suite, the sessions that made it (command, date, commit, machine: ``provenance.json``),
    its leaderboard and learning curves (copied beside the page, under ``images/``).

    Raises:
        FileNotFoundError, ValueError: a directory that is missing or holds no finished run,
            named; then nothing is written (the page and its images are written once all is drawn).
    """
    path = Path(path)
    lines = [f"# {title}", "",
             f"<!-- generated by `craftsuite leaderboard {' '.join(str(d) for d in run_dirs)} --page {path}`;"
             " do not edit -->", ""]
    # every directory read before anything is written
    directories = [read_runs(d, suite_cells=True) for d in run_dirs]
    pairs = comparisons([runs.board for runs in directories])
    auc = in_metric(pairs, "auc")
    # one rate per learner regime and world, from every directory's runs: the coverage and the
    # undecided comparisons' hours then project at the same figures
    measured = rates(Board([e for runs in directories for e in _every(runs.board)]))
    facts = {runs.path: _suite_facts(runs, measured) for runs in directories}
    ladder = aggregates([e for runs in directories for e in runs.board])
    lines += summary_markdown(pairs, directories, facts, ladder, auc)
    compared = comparisons_markdown(pairs, auc)
    if compared:
        lines += ["## Distilled against scratch", "",
                  "Each distilled method against its algorithm from scratch on each rung, in final greedy success "
                  "and in AUC (the rows come from the leaderboards below; the rules a verdict follows, and what "
                  "\"read k times\" means, come after the table).", "", *compared]
        current = frozenset(SUITES[runs.name].regime for runs in directories if runs.name in SUITES)
        suites = [SUITES[runs.name] for runs in directories if runs.name in SUITES]
        # the teachers today's suites train (none said: no suite's directory, nothing starred)
        teachers = frozenset(t.run_name() for suite in suites for t in suite.teachers().values()) if suites else None
        cheapest = to_decide_markdown(asks(pairs, auc, measured, current, teachers), current)
        if cheapest:
            lines += ["### What the undecided would ask", "", *cheapest]
    if len(directories) > 1:
        if any(agg.iqm for agg in ladder):
            lines += ["## Across the ladder", "", "The runs of all the directories below pooled, per world and "
                      "learner regime (each directory's own section aggregates its runs alone):", "",
                      *aggregates_markdown(ladder)]
    figures, videos = [], []  # (images directory, its figures), (video, its copy): written once all is drawn
    for runs in directories:
        suite, board, name = runs.suite, runs.board, runs.name
        lines += [f"## {name}" + (f": {suite['description']}" if suite.get("description") else ""), "",
                  f"Runs in `{runs.path.as_posix()}`." + _suite_scope(suite, runs.sessions), ""]
        lines += [session_line(s, to_the_minute=True) for s in runs.sessions]
        lines += wall_time_lines(runs.sessions) + training_time_lines(_every(board))
        found = facts[runs.path]
        if found is not None:
            lines += ["", *coverage_markdown(found[1]), *learned_markdown(found[0])]
        if not runs.sessions:
            lines.append(f"- runs in `{runs.path}` (no provenance.json: not made by `craftsuite transfer`)")
        # named after the directory, not the suite: two directories of one suite keep their own plots
        images = path.parent / "images" / file_part(f"results-{runs.path.name}")
        aggs = aggregates(list(board))
        profiles, curves = draw_profiles(board, aggs), draw_curves(board)
        figures.append((images, profiles + curves))
        text = leaderboard_markdown(board, title=None, profiles={
            d.world_label: (images / f"{d.stem}.png").relative_to(path.parent) for d in profiles},
            aggs=aggs, level=3) if board.entries or board.unfinished else "No run of the suite's cells has finished."
        lines += ["", text.strip(), ""]
        lines += superseded_markdown(board.apart)
        for plot in curves:
            lines += [f"![{plot.stem}]({(images / f'{plot.stem}.png').relative_to(path.parent).as_posix()})", ""]
        lines += teachers_markdown(runs.path / "teachers")
        shown = sorted(runs.path.glob("best-*.mp4"))
        for video in shown:
            videos.append((video, images / video.name))
            lines += [f"Video of the best student: [{video.name}]"
                      f"({(images / video.name).relative_to(path.parent).as_posix()})", ""]
        best = best_run(board)
        if not shown and best is not None and not (best[0] / "model.zip").exists():
            run, entry, i = best
            lines += [f"No video: the best student here, `{run.name}` (greedy success "
                      f"{entry.values['success'][i]:.2f}), kept its records but not its model (the results archive "
                      "keeps no models). `craftsuite video` needs one: train its cell again into a new directory "
                      "(`craftsuite transfer --no-archive --out DIR`).", ""]
        if (runs.path / "students").is_dir() and any((runs.path / "students").glob("*/episodes.csv.gz")):
            lines += [f"The records in `{runs.path.as_posix()}`: {archive_size(runs.path) / 1e6:.1f} MB.", ""]
    for images, drawn in figures:
        images.mkdir(parents=True, exist_ok=True)
        save_figures(drawn, images)
    for video, copy in videos:
        shutil.copy(video, copy)
    atomic_write(path, "\n".join(lines))
    return path


def _every(board: Board) -> Board:
    """A directory's runs, the suite's cells and those set apart, as one board."""
    return Board(board.entries + (board.apart.entries if board.apart else []))


def _suite_facts(runs, measured: dict[str, dict[str, float]]) -> tuple[list[Learned], Coverage] | None:
    """For a directory of a suite of this version: the rungs learned, read from every run
    (the suite's cells and those set apart), and its coverage, projected at the ``measured``
    rates of the suite's learner regime (``timing.rates``); None for any other."""
    if runs.name not in SUITES:
        return None
    regime = SUITES[runs.name].regime
    return learned(_every(runs.board), runs.name), coverage(runs.path, runs.name, measured.get(regime, {}))


def _needed_range(needs: list[int]) -> str:
    if not needs:
        return ""
    low, high = min(needs), max(needs)
    return (f" (the interval rules would need about {low if low == high else f'{low}-{high}'} seeds a side "
            "at the means and spreads measured)")


def summary_markdown(pairs, directories, facts, ladder: list[Aggregate] = (), auc=None) -> list[str]:
    """The page's answer in a few lines, from the sections below: the comparisons per
    learner regime and their verdicts in final greedy success and in AUC (``auc``: the same
    pairs, ``in_metric(pairs, "auc")``, read here if not given), each distilled method's probability of beating
    scratch across the tasks both ran (``ladder``: the aggregates of every directory
    together), the rungs some method learned per suite and world, and how much of each suite
    is archived and still to train (``facts``: ``_suite_facts`` per directory)."""
    lines = []
    if pairs:
        auc = in_metric(pairs, "auc") if auc is None else auc
        lines.append(f"- Distilled against scratch, {COMPARED['success']}: {_verdicts_text(pairs)}.")
        lines += _by_method_lines(pairs)
        lines.append(f"- Distilled against scratch, {COMPARED['auc']} (how soon a run learned; the same rules): "
                     f"{_verdicts_text(auc, 'auc')}.")
    lines += _distilled_across_the_ladder(ladder)
    names = [runs.name for runs in directories]
    learned_parts, coverage_parts = [], []
    for runs in directories:
        if facts[runs.path] is None:
            continue
        rows, found = facts[runs.path]
        # two directories of one suite: each named by its path
        name = runs.name if names.count(runs.name) == 1 else f"{runs.name} (`{runs.path.as_posix()}`)"
        learned_parts.append(f"{name}: " + ", ".join(f"{r.world} {len(r.learned)} of {r.rungs}" + _rungs_named(r)
                                                    for r in rows))
        left = (f" ({found.left / 1e6:,.1f}M transitions to train"
                + (f", about {found.hours / 2:,.1f} h on 2 cores at the rates recorded" if found.hours else "")
                + (f"; {', '.join(found.unknown)} not counted: no rate recorded" if found.hours and found.unknown
                   else "") + ")") if found.left else ""
        coverage_parts.append(f"{name} {found.archived:,} of {found.asked:,} runs{left}")
    if learned_parts:
        lines.append("- Rungs some method learned (mean final greedy success at least "
                     f"{THRESHOLD:.0%}, in any learner regime or budget: each suite's table names them): "
                     + "; ".join(learned_parts) + ".")
        lines.append("- Archived of each suite as defined now: " + "; ".join(coverage_parts) + ".")
    regimes = sorted({entry.regime for entry, _, _ in pairs}, key=regime_order)
    if lines and regimes:  # first: the terms the lines after it use
        lines.insert(0, "- Read as: a *learner regime* is the rule every student of a table learns by (runs of two "
                     "regimes are never pooled): " + "; ".join(f"`{r}`, {describe(r)}" for r in regimes)
                     + ". A world named with settings (`Grid10: layout_seed=1`) is the registered world with those "
                     "settings; a method marked with a letter is one method at other settings, named under its table.")
    return ["## In short", "", *lines, ""] if lines else []


def _rungs_named(row: Learned) -> str:
    """The rungs a world learned and those not yet run, in one parenthesis ("" where neither)."""
    named = [", ".join(row.learned)] * bool(row.learned) + [f"not yet run: {', '.join(row.absent)}"] * bool(row.absent)
    return f" ({'; '.join(named)})" if named else ""


def _verdicts_text(pairs, metric: str = "success") -> str:
    """Per learner regime, how many of ``pairs`` (read in ``metric``) say each verdict, and
    what the undecided ones would need."""
    return "; ".join(
        f"`{regime}` {t['comparisons']} comparison{'s' if t['comparisons'] > 1 else ''}: ahead on "
        f"{_sided(t, 'ahead')}, behind on {_sided(t, 'behind')}, no difference of {SMALLEST_DIFFERENCE:g} or more "
        f"on {t['no difference']} "
        f"({t['trivial']} of them only {_all_same(metric)}), undecided on "
        f"{t['comparisons'] - _decided(t)}" + _needed_range(t["seeds to decide"])
        for regime, t in decided_by_regime(pairs).items())


def _by_method_lines(pairs) -> list[str]:
    """The final-success tally again, per learner regime and distilled method: the paper's
    method, the static values and the teacher's values on edges are different answers."""
    methods = sorted({entry.method for entry, _, _ in pairs})
    if len(methods) < 2:
        return []
    rows: dict[str, list[str]] = {}
    for method in methods:
        for regime, t in decided_by_regime([p for p in pairs if p[0].method == method]).items():
            rows.setdefault(regime, []).append(
                f"`{method}` ({t['comparisons']} comparison{'s' if t['comparisons'] > 1 else ''}): ahead "
                f"{_sided(t, 'ahead')}, behind {_sided(t, 'behind')}, no difference "
                f"{t['no difference']} ({t['trivial']} only at all-0/all-1), "
                f"undecided {t['comparisons'] - _decided(t)}")
    return [f"  - per distilled method, `{regime}`: " + "; ".join(parts)
            for regime, parts in sorted(rows.items(), key=lambda kv: regime_order(kv[0]))]


def _distilled_across_the_ladder(ladder: list[Aggregate]) -> list[str]:
    """Per world and learner regime, each distilled method's probability of beating scratch
    in final greedy success and in AUC, over every task both ran (``Aggregate.against_baseline``)."""
    from ..methods import is_distilled

    rows = []
    for agg in ladder:
        mine = {m: p for m, p in agg.against_baseline.items() if is_distilled(m)}
        if mine:
            rows.append(f"  - {agg.label}: " + ", ".join(
                f"`{m}` {_fmt(p.improvement['success'])}, in AUC {_fmt(p.improvement['auc'])} "
                f"({len(p.tasks)} task{'s' if len(p.tasks) > 1 else ''})"
                for m, p in sorted(mine.items(), key=lambda kv: (-len(kv[1].tasks), kv[0]))))
    if not rows:
        return []
    return ["- Distilled against scratch across the ladder: the probability that a distilled run's final greedy "
            "success beats a scratch run's on the same task (ties count half, so a task where both sit at 0 or at 1 "
            "pulls it toward 0.5), averaged over every task both ran, with its 95% stratified-bootstrap interval; "
            "then the same in AUC (how soon a run learned; ties are rarer there). Each method is read over the "
            "tasks it ran, so two methods over different tasks are not compared with each other:",
            *rows]


def superseded_markdown(board: Board | None, level: int = 3) -> list[str]:
    """The suite's runs at budgets it does not ask for now: a table per task, kept beside the
    suite's cells rather than pooled with them or dropped; their heading at ``level``."""
    if not board or not (board.entries or board.unfinished):
        return []
    h = "#" * level
    lines = [f"{h} At budgets the suite no longer asks for", "",
             "Runs of the suite's learner regime at a budget other than the one it asks for now (their rung "
             "re-calibrated since, or a candidate budget its calibration tried), on rungs whose cell at today's "
             "budget has runs: kept apart from the suite's tables and comparisons above, and from its coverage; the "
             "rungs-learned count reads them as well, naming the budget where one of them is the best.", ""]
    cells = {(e.task, e.world_label) for e in board} | {(u.task, u.world_label) for u in board.unfinished}
    for task, world in sorted(cells, key=lambda k: (rung_order(k[0]), k[1])):
        rows = ranked([e for e in board if (e.task, e.world_label) == (task, world)])
        waiting = sorted((u.method, u.seed) for u in board.unfinished if (u.task, u.world_label) == (task, world))
        lines += [f"{h}# {task} ({world})", "", *(task_table(rows) if rows else [])]
        lines += [f"- {note}" for note in _variant_notes(rows)]
        if waiting:
            lines += ["", "Unfinished, not counted: " + ", ".join(f"{m} seed {seed}" for m, seed in waiting)]
        lines.append("")
    return lines


def teachers_markdown(root: Path) -> list[str]:
    """The finished teachers under ``root`` (product DQN on a grid, trained until their
    target greedy success, then distilled): one row each. A damaged record is named."""
    rows, problems = [], []
    for run in sorted(root.glob("teacher-*")) if root.is_dir() else []:
        try:
            config = read_config(run)
            result = read_result(run)
            seed = config.get("layout_seed")
            layout = "new every episode" if seed is None else f"fixed ({seed})"
            rows.append((rung_order(config["task"]), f"| {config['task']} | `{result['env_id']}` | {layout} "
                         f"| {result['steps']:,} / {result['updates']:,} | {result['success']:.2f} "
                         f"| {'yes' if result['reached_target'] else 'no'} ({config['target_success']:.0%}) |"))
        except (RunError, OSError, ValueError, KeyError, TypeError) as err:
            problems.append(f"- not read: {run} ({unread_reason(err)})")
    if not rows and not problems:
        return []
    return ["Teachers (product DQN on the 7x7 grid, trained until their target greedy success over 50 episodes or "
            "their budget, then distilled into their automaton's table):", "",
            "| task | world | layout | transitions / updates | greedy success | reached target |",
            "|---|---|---|---|---|---|", *[row for _, row in sorted(rows)], *problems, ""]


def _suite_scope(suite: dict, sessions: list[dict]) -> str:
    """What the last transfer into a directory asked for (``suite.json``: the suite as run,
    with any command-line overrides), e.g. `` As last run: rungs tagged easy, medium; worlds Cont;
    ...``. A directory that transfers of different commands ran into (an archive gathering a
    campaign's parts) says so instead: the last one's scope is not the directory's, and the
    sessions listed after this line name each one's. Sessions that only archived runs
    (``craftsuite archive``, which records what it kept) are not transfers."""
    transfers = {s.get("command") for s in sessions if "archived" not in s}
    if len(transfers) > 1:
        return f" Gathered from {len(transfers)} different transfers, each listed below with its command."
    parts = []
    if suite.get("tags") or suite.get("tasks"):
        parts.append("rungs " + "; ".join(filter(None, [
            f"tagged {', '.join(suite['tags'])}" if suite.get("tags") else "",
            ", ".join(suite.get("tasks") or ())])))
    for key, word in (("worlds", "worlds"), ("methods", "methods")):
        if suite.get(key):
            parts.append(f"{word} {', '.join(suite[key])}")
    if suite.get("seeds"):
        parts.append(seeds_text(suite["seeds"], suite.get("rung_seeds") or {}, suite.get("worlds"),
                                suite.get("tasks") if not suite.get("tags") else None))
    return f" As last run: {'; '.join(parts)}." if parts else ""
