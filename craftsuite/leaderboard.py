"""Leaderboards, learning curves and results pages from student run directories.

Per run (``run_metrics``):

* ``success``: greedy success rate at the last evaluation;
* ``return``: mean training-episode return over the last 10% of the run's steps;
* ``train_success``: the share of training episodes won over the same window, with the
  exploration noise on (what SB3 logs as ``rollout/success_rate``); a policy can win
  there and still stall when evaluated greedily, so both are shown;
* ``auc``: area under the evaluation success curve, as a fraction of the budget (the mean
  of the evaluations, every ``eval_every`` steps and at the end): 1.0 means solved from the
  first one;
* ``steps_to_80``: transitions at the first evaluation with success >= 0.8 (None: never);
* ``budget`` and ``updates``: the run's transitions and gradient updates.

Per task, world and method (``build``): every seed's value, the mean and its Student
t-interval (``craftsuite.stats``; below 3 seeds, the seeds alone), and steps to 80% as
"k of n reached; the median of those that did". The world is its kind and its settings
(``world_label``): runs in a fixed grid instance or at another frame skip are another
benchmark, so they get a row and a plot of their own. Runs of one method whose settings
differ in more than the seed are not pooled: each setting is a row of its own, flagged.

Across tasks, per world (``aggregates``): each method's IQM of final success and of AUC
with stratified-bootstrap intervals, the probability that it improves on the same
algorithm from scratch, and performance profiles (``plot_profiles``).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import math
import re
import string
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import stats
from .files import atomic_path, atomic_write
from .ids import CONT, world_kind
from .runs import RunError, flatten, read_config, read_csv, run_settings

# metrics with a mean and an interval per task and method; a rate lies in [0, 1]
METRICS = {"success": (0.0, 1.0), "return": (-math.inf, math.inf), "train_success": (0.0, 1.0),
           "auc": (0.0, 1.0)}
THRESHOLD = 0.8  # greedy success at which a run counts as having learned the task
AGGREGATED = ("success", "auc")  # the metrics aggregated across tasks (rates: comparable across tasks)

# The authors' shipped continuous results, one run each, mean episode reward over the last
# 5% of 2e6 steps (not the same metric window as ours, nor our MuJoCo world).
PAPER_REFERENCE = {
    "BlindCraftsman": {"td3-dynamic": 19.95, "td3": 17.06},
    "DungeonQuest": {"td3-dynamic": 90.45, "td3": 87.97},
    "GoldMine": {"td3-dynamic": 29.59, "td3": 8.58},  # their third continuous task (the paper says Diamond Mine)
}


def world_label(config: dict) -> str:
    """A student's world as a leaderboard shows it: ``Cont``, ``Grid10``, or with the
    settings that change it, e.g. ``Cont: frame_skip=2, max_episode_steps=1000``."""
    from .runs import config_from
    from .configs import StudentConfig  # the owner of a student's world settings

    settings = config_from(StudentConfig, config).env_kwargs
    if not settings:
        return config["world"]
    return f"{config['world']}: " + ", ".join(f"{k}={json.dumps(v)}" for k, v in sorted(settings.items()))


def _file_part(label: str) -> str:
    """``label`` as part of a file name: ``Cont: frame_skip=2`` -> ``Cont-frame_skip-2``."""
    return re.sub(r"[^\w.]+", "-", label).strip("-")


def run_metrics(run: Path) -> dict | None:
    """The metrics of one finished student run directory (None: a teacher's, or not finished).

    Raises:
        RunError: a damaged or unreadable record, named.
    """
    run = Path(run)
    if not (run / "result.json").exists():
        return None
    config = read_config(run)
    try:
        result = json.loads((run / "result.json").read_text())
    except ValueError as err:
        raise RunError(f"{run / 'result.json'} is not valid JSON ({err}): the run's result is damaged") from None
    if result.get("kind") != "student":
        return None  # a teacher run
    budget = int(config["steps"])
    episodes = read_csv(run / "episodes.csv")
    evals = read_csv(run / "evals.csv")
    tail = [e for e in episodes if int(e["step"]) > 0.9 * budget]
    if not tail and episodes:  # fewer episodes than the window: the last one
        tail = episodes[-1:]
    success = [float(e["success"]) for e in evals]
    reached = next((int(e["step"]) for e in evals if float(e["success"]) >= THRESHOLD), None)
    return {
        "task": config["task"], "world": world_label(config), "method": config["method"], "seed": config["seed"],
        "budget": budget, "steps": result["steps"], "updates": result.get("updates"),
        "success": success[-1] if success else float("nan"),
        "return": float(np.mean([float(e["return"]) for e in tail])) if tail else float("nan"),
        "train_success": float(np.mean([int(e["success"]) for e in tail])) if tail else float("nan"),
        "auc": float(np.mean(success)) if success else float("nan"),
        "steps_to_80": reached,
    }


@dataclass
class Entry:
    """One row: a method's runs of one setting on one task in one world."""

    task: str
    world: str
    method: str
    seeds: list[int]
    values: dict[str, list[float]]  # metric -> one value per seed, in seed order
    reached: stats.Reached  # seeds that reached 80% greedy success, and their median transitions
    budget: int = 0  # transitions per run
    updates: int | None = None  # mean gradient updates per run (None: runs from before they were recorded)
    variant: str = ""  # "a", "b", ...: the method's runs here differ in more than the seed, and this is one setting
    differs: dict = field(default_factory=dict)  # with a variant: the settings that tell it apart, and its values
    runs: list[str] = field(default_factory=list)  # the run directories' names, in seed order

    @property
    def label(self) -> str:
        return f"{self.method} ({self.variant})" if self.variant else self.method

    @property
    def stats(self) -> dict[str, stats.Estimate]:
        return {m: stats.t_interval(self.values[m], bounds=METRICS[m]) for m in METRICS}

    @property
    def budget_text(self) -> str:
        """The budget in transitions and gradient updates, e.g. ``60,000 / 15,000``."""
        return f"{self.budget:,} / " + (f"{self.updates:,}" if self.updates is not None else "?")


@dataclass
class Board:
    """A directory's leaderboard: its entries, and the runs that are not on it."""

    entries: list[Entry]
    unfinished: list[dict] = field(default_factory=list)  # task, world, method, seed, run: no result.json yet
    unreadable: list[str] = field(default_factory=list)  # runs whose record is damaged: the reason

    def __iter__(self):
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)


def build(students_root) -> Board:
    """The leaderboard of the runs under ``students_root``: one entry per task, world,
    method and setting (runs that differ in more than the seed are never pooled)."""
    root = Path(students_root)
    groups: dict[tuple, list[tuple[dict, dict]]] = {}
    board = Board([])
    for run in sorted(root.iterdir()) if root.is_dir() else []:
        if not (run / "config.json").exists():
            continue
        try:
            m = run_metrics(run)
            config = read_config(run)
            if m is None:
                if not (run / "result.json").exists() and run.name.startswith("student-"):
                    board.unfinished.append({"task": config["task"], "world": world_label(config),
                                             "method": config["method"], "seed": config["seed"], "run": run.name})
                continue
        except RunError as err:
            board.unreadable.append(str(err))
            continue
        except (ValueError, KeyError, TypeError) as err:  # a record or log that does not read as a run's
            board.unreadable.append(f"{run}: {type(err).__name__}: {err}")
            continue
        setting = {k: v for k, v in run_settings(config).items() if k != "seed"}
        key = (m["task"], m["world"], m["method"], json.dumps(setting, sort_keys=True))
        groups.setdefault(key, []).append(({**m, "run": run.name}, setting))
    by_method: dict[tuple, list[tuple]] = {}
    for key in groups:
        by_method.setdefault(key[:3], []).append(key)
    for (task, world, method), keys in sorted(by_method.items()):
        settings = [flatten(groups[k][0][1]) for k in keys]
        differing = sorted({name for s in settings for name in s
                            if len({json.dumps(t.get(name), sort_keys=True) for t in settings}) > 1})
        for i, key in enumerate(sorted(keys, key=lambda k: (-len(groups[k]), k[3]))):  # most runs first
            runs = sorted((m for m, _ in groups[key]), key=lambda m: m["seed"])
            setting = flatten(groups[key][0][1])
            updates = [r["updates"] for r in runs]
            board.entries.append(Entry(
                task, world, method, [r["seed"] for r in runs], {m: [r[m] for r in runs] for m in METRICS},
                stats.reached([r["steps_to_80"] for r in runs]), budget=max(r["budget"] for r in runs),
                updates=None if None in updates else round(float(np.mean(updates))),
                variant=(string.ascii_lowercase[i] if i < 26 else str(i + 1)) if len(keys) > 1 else "",
                differs={name: setting.get(name, "(not recorded)") for name in differing},
                runs=[r["run"] for r in runs]))
    return board


def _fmt(estimate: stats.Estimate, digits: int = 2) -> str:
    if math.isnan(estimate.value):
        return "n/a"
    if not estimate.has_interval:
        return f"{estimate.value:.{digits}f}"
    return f"{estimate.value:.{digits}f} [{estimate.low:.{digits}f}, {estimate.high:.{digits}f}]"


def _finite_mean(values) -> float:
    """The mean of the values that are numbers (-inf if none is: a run with no episode yet ranks last)."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    return float(x.mean()) if len(x) else -math.inf


def _rung_order(task: str) -> tuple:
    """Sections follow the task ladder, easiest rung first (unknown tasks last, by name)."""
    from .task_registry import tasks

    spec = tasks().get(task)
    return spec.rung if spec is not None else (99, True, task)


LEGEND = (
    "Per task: the mean over seeds with its 95% Student t-interval (none below 3 seeds), and every seed's final "
    "greedy success. success: greedy, at the last evaluation; AUC: mean greedy success over the evaluations "
    "during training; return and training success: training episodes (exploration noise on) in the last 10% of "
    "the budget; reached 80%: how many seeds reached 80% greedy success, and the median transitions of those "
    "that did; budget: transitions / gradient updates per run. A world with settings beyond the registered one "
    "names them.")

AGGREGATE_LEGEND = (
    "Across the tasks every method of a world ran: the interquartile mean (IQM) over all runs of all tasks, with "
    "95% stratified-bootstrap intervals (each task's runs resampled on their own, 2,000 resamples), and the "
    "probability that a run of the method beats a run of {baseline} on the same task (ties count half; 0.5: no "
    "difference), averaged over tasks. With few seeds these intervals run narrow (an IQM interval over 4 tasks x "
    "5 seeds covered 89% of simulated cases, not 95%): read an overlap as no difference.")


def transfer_verdict(entry: Entry, baseline: Entry) -> str:
    """Whether ``entry`` reaches 80% greedy success in at most half the transitions of
    ``baseline`` (its algorithm from scratch, same task and world), read on the medians over
    all seeds (``stats.Reached.overall``), and the figures that say so. Where scratch's
    median is never within a budget at least ``entry``'s, reaching 80% at all meets the
    target, and the text says that scratch never got there (all that is known of scratch's
    time is that it exceeds its budget)."""
    mine, theirs = entry.reached.overall, baseline.reached.overall

    def text(steps: float, e: Entry) -> str:
        return f"{steps:,.0f}" if math.isfinite(steps) else f"never in {e.budget:,}"

    figures = f"{text(mine, entry)} against {text(theirs, baseline)}"
    if not math.isfinite(mine):
        return f"not met ({figures})"
    if math.isfinite(theirs) and mine <= theirs / 2:
        return f"met ({figures})"
    if not math.isfinite(theirs) and baseline.budget >= entry.budget:
        return f"met: scratch never got there ({figures})"
    return f"not met ({figures})"


def transfer_verdicts(rows: list[Entry]) -> list[tuple[Entry, Entry, str]]:
    """For one task and world: each distilled student (a method with a distilled target)
    beside its algorithm from scratch, (entry, scratch's entry, verdict text); none where
    scratch did not run or ran in variants."""
    from .methods import METHODS, scratch

    base = [e for e in rows if e.method == scratch(e.world.split(":")[0])]
    if len(base) != 1:
        return []
    return [(e, base[0], transfer_verdict(e, base[0])) for e in rows
            if e.method in METHODS and METHODS[e.method].distill]


def to_markdown(board, title: str | None = "# Leaderboard", profiles: dict[str, Path] | None = None,
                aggs: list[Aggregate] | None = None) -> str:
    """The board as Markdown; ``profiles``: per world, a performance-profile image to link;
    ``aggs``: the board's ``aggregates``, if already computed."""
    from .methods import METHODS

    entries = list(board)
    lines = [title, ""] if title else []
    lines += [LEGEND, ""]
    for key in sorted({(e.task, e.world) for e in entries}, key=lambda k: (_rung_order(k[0]), k[1])):
        lines += [f"## {key[0]} ({key[1]})", "",
                  "| method | seeds | success | success per seed | AUC | return (last 10%) "
                  "| training success (last 10%) | reached 80% | budget |",
                  "|---|---|---|---|---|---|---|---|---|"]
        rows = sorted((e for e in entries if (e.task, e.world) == key),
                      key=lambda e: (-_finite_mean(e.values["auc"]), -_finite_mean(e.values["return"]), e.label))
        for e in rows:
            st = e.stats
            seeds = " ".join(f"{v:.2f}" for v in e.values["success"])
            lines.append(f"| {e.label} | {len(e.seeds)} | {_fmt(st['success'])} | {seeds} | {_fmt(st['auc'])} "
                         f"| {_fmt(st['return'], 1)} | {_fmt(st['train_success'])} | {e.reached} | {e.budget_text} |")
        # in both continuous worlds: the authors' figures come from their kinematic toy (our
        # Kinematic world follows its step), beside which the MuJoCo world is the harder test
        ref = PAPER_REFERENCE.get(key[0]) if world_kind(key[1].split(":")[0]) == CONT else None
        if ref:
            for method, value in ref.items():
                lines.append(f"| *reference: authors' {method}, 1 run, 2M steps (return over the last 5%)* "
                             f"| 1 | | | | {value:.2f} | | | |")
        verdicts = transfer_verdicts(rows)
        if verdicts:
            lines += ["", f"Transfer target (80% greedy success in at most half the transitions "
                      f"`{verdicts[0][1].method}` needs; median over seeds, a seed that never reached 80% counting "
                      "as never): " + "; ".join(f"`{e.label}` {text}" for e, _, text in verdicts) + "."]
        notes = [f"*{e.label}: " + "; ".join(f"{k} = {json.dumps(v)}" for k, v in e.differs.items()) + "*"
                 for e in rows if e.variant]
        if notes:
            lines += ["", f"Runs of one method that differ in more than the seed are not pooled; "
                      "each setting is a row of its own (put runs of another setting in another directory):", ""]
            lines += [f"- {n}" for n in notes]
        waiting = [u for u in getattr(board, "unfinished", []) if (u["task"], u["world"]) == key]
        if waiting:
            lines += ["", "Unfinished, not counted: " + ", ".join(
                f"{u['method']} seed {u['seed']}" for u in sorted(waiting, key=lambda u: (u["method"], u["seed"])))]
        lines.append("")
    others = sorted({(u["task"], u["world"]) for u in getattr(board, "unfinished", [])}
                    - {(e.task, e.world) for e in entries})
    for task, world in others:
        lines += [f"## {task} ({world})", "", "No run finished yet; unfinished: " + ", ".join(
            f"{u['method']} seed {u['seed']}" for u in getattr(board, "unfinished", [])
            if (u["task"], u["world"]) == (task, world)), ""]
    for reason in getattr(board, "unreadable", []):
        lines += [f"Not read: {reason}", ""]
    aggregate_lines = aggregates_markdown(aggregates(entries) if aggs is None else aggs, profiles)
    if aggregate_lines:
        lines += ["## Across tasks", "", *aggregate_lines]
    shown = [m for m in METHODS if m in {e.method for e in entries}]
    shown += sorted({e.method for e in entries} - set(shown))  # runs of a method no longer in the table
    lines += ["Methods:", ""]
    lines += [f"- `{m}`: {METHODS[m].description if m in METHODS else 'not a method of this version'}"
              for m in shown]
    lines.append("")
    return "\n".join(lines)


@dataclass
class Aggregate:
    """One world's methods across its tasks."""

    world: str
    tasks: list[str]  # the tasks every aggregated method ran
    baseline: str | None  # the world's algorithm from scratch, if it ran
    iqm: dict[str, dict[str, stats.Estimate]]  # method -> metric -> IQM
    improvement: dict[str, dict[str, stats.Estimate]]  # method -> metric -> P(method > baseline)
    scores: dict[str, list[np.ndarray]]  # method -> final success per task (for profiles)
    runs: dict[str, int]  # method -> runs aggregated
    left_out: list[str]  # what was not aggregated, and why


def aggregates(entries) -> list[Aggregate]:
    """Per world, the methods compared across the tasks all of them ran, each with 2 runs
    or more per task that have a final success, and one setting (variants are not
    aggregated). A world with nothing to aggregate still says why (an empty aggregate)."""
    from .methods import scratch

    def finite(entry, metric):
        x = np.asarray(entry.values[metric], dtype=float)
        return x[np.isfinite(x)]

    out = []
    for world in sorted({e.world for e in entries}):
        mine = [e for e in entries if e.world == world]
        left_out = []
        variants = sorted({e.method for e in mine if e.variant})
        if variants:
            left_out.append(f"{', '.join(variants)}: runs of more than one setting")
        methods = sorted({e.method for e in mine} - set(variants))
        cells = {(e.task, e.method): e for e in mine if e.method in methods}
        tasks = sorted({e.task for e in mine}, key=_rung_order)
        blank = sum(len(e.seeds) - len(finite(e, m)) for e in cells.values() for m in AGGREGATED[:1])
        if blank:
            left_out.append(f"{blank} run{'s' if blank > 1 else ''} without an evaluation")
        # a method short of runs on a task every method ran is left out; the others keep the task
        common = [t for t in tasks if all((t, m) in cells for m in methods)]
        few = sorted(m for m in methods if any(min(len(finite(cells[(t, m)], metric)) for metric in AGGREGATED) < 2
                                               for t in common))
        if few:
            left_out.append(f"{', '.join(few)}: fewer than 2 runs on some task")
        methods = [m for m in methods if m not in few]
        common = [t for t in tasks if methods and all((t, m) in cells for m in methods)]
        for t in tasks:
            if t not in common:
                ran = sorted(m for m in methods if (t, m) in cells)
                left_out.append(f"task {t}: run by {', '.join(ran) or 'no aggregated method'} only")
        if not common:
            methods = []
        scratch_method = scratch(world.split(":")[0])
        baseline = scratch_method if scratch_method in methods else None
        if scratch_method and not baseline and any(e.method == scratch_method for e in mine):
            left_out.append(f"the baseline {scratch_method} is not aggregated: no probability of improvement")
        per_task = {m: {metric: [finite(cells[(t, m)], metric) for t in common] for metric in AGGREGATED}
                    for m in methods}
        out.append(Aggregate(
            world, common, baseline,
            {m: {metric: stats.aggregate_iqm(per_task[m][metric]) for metric in AGGREGATED} for m in methods},
            {m: {metric: stats.probability_of_improvement(per_task[m][metric], per_task[baseline][metric])
                 for metric in AGGREGATED} for m in methods if baseline and m != baseline},
            {m: per_task[m]["success"] for m in methods},
            {m: sum(len(x) for x in per_task[m]["success"]) for m in methods}, left_out))
    return out


def aggregates_markdown(aggs: list[Aggregate], images: dict[str, Path] | None = None) -> list[str]:
    lines = []
    for agg in aggs:
        base = agg.baseline
        if not agg.iqm:
            lines += [f"### {agg.world}", "", "Nothing to aggregate: " + "; ".join(agg.left_out or ["no method"]) + ".",
                      ""]
            continue
        lines += [f"### {agg.world}: {len(agg.tasks)} task{'s' if len(agg.tasks) > 1 else ''} ({', '.join(agg.tasks)})", "",
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
        if images and agg.world in images:
            lines += ["", f"![performance profile, {agg.world}]({images[agg.world].as_posix()})"]
        lines.append("")
    return lines


def to_csv(board) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(["task", "world", "method", "variant", "seeds", *(f"{m}{s}" for m in METRICS for s in ("", "_lo", "_hi")),
                     "success_per_seed", "reached_80", "reached_80_median", "differs_in", "budget_transitions",
                     "updates"])
    for e in board:
        st = e.stats
        writer.writerow([e.task, e.world, e.method, e.variant, len(e.seeds),
                         *(("" if math.isnan(v) else v) for m in METRICS
                           for v in (st[m].value, st[m].low, st[m].high)),
                         " ".join(str(v) for v in e.values["success"]), e.reached.k,
                         "" if e.reached.median is None else e.reached.median, " ".join(e.differs), e.budget,
                         "" if e.updates is None else e.updates])
    return buf.getvalue()


def write(board, out) -> Path:
    """``leaderboard.md``, ``leaderboard.csv`` and the performance profiles in ``out``;
    returns the Markdown path."""
    out = Path(out)
    aggs = aggregates(list(board))
    profiles = {p.world: p.path.relative_to(out) for p in plot_profiles(board, out, aggs)}
    atomic_write(out / "leaderboard.csv", to_csv(board))
    atomic_write(out / "leaderboard.md", to_markdown(board, profiles=profiles, aggs=aggs))
    return out / "leaderboard.md"


def write_page(run_dirs, path, title: str = "Results") -> Path:
    """A results page (Markdown) from transfer output directories: per directory, its
    suite, the sessions that made it (command, date, commit, machine: ``provenance.json``),
    its leaderboard and learning curves (copied beside the page, under ``images/``).

    Raises:
        FileNotFoundError, ValueError: a directory that is missing or holds no finished run,
            named; the page is then not written.
    """
    import shutil

    from .provenance import read

    path = Path(path)
    lines = [f"# {title}", "",
             f"<!-- generated by `craftsuite leaderboard {' '.join(str(d) for d in run_dirs)} --page {path}`;"
             " do not edit -->", ""]
    parts = []
    for run_dir in map(Path, run_dirs):
        students = run_dir / "students" if (run_dir / "students").is_dir() else run_dir
        if not students.is_dir():
            raise FileNotFoundError(f"no run directory at {run_dir}")
        board = build(students)
        if not board.entries:
            raise ValueError(f"no finished student runs under {students}"
                             + (f" ({len(board.unfinished)} unfinished)" if board.unfinished else ""))
        parts.append((run_dir, students, board))
    for run_dir, students, board in parts:
        suite = json.loads((run_dir / "suite.json").read_text()) if (run_dir / "suite.json").exists() else {}
        name = suite.get("name", run_dir.name)
        lines += [f"## {name}" + (f": {suite['description']}" if suite.get("description") else ""), "",
                  f"Runs in `{run_dir.as_posix()}`." + _suite_scope(suite), ""]
        sessions = read(run_dir)
        for s in sessions:
            took = "did not finish" if s.get("seconds") is None else f"{s['seconds'] / 60:.1f} min"
            lines.append(f"- `{s['command']}`: {s['started'][:16].replace('T', ' ')} UTC, commit "
                         f"{s.get('commit') or 'unknown'}, {took} on {s['machine']}")
        if not sessions:
            lines.append(f"- runs in `{run_dir}` (no provenance.json: not made by `craftsuite transfer`)")
        # named after the directory, not the suite: two directories of one suite keep their own plots
        images = path.parent / "images" / _file_part(f"results-{run_dir.name}")
        images.mkdir(parents=True, exist_ok=True)
        aggs = aggregates(list(board))
        profiles = {p.world: p.path.relative_to(path.parent) for p in plot_profiles(board, images, aggs)}
        text = to_markdown(board, title=None, profiles=profiles, aggs=aggs).replace("\n### ", "\n#### ").replace("\n## ", "\n### ")
        lines += ["", text.strip(), ""]
        for plot in plot_curves(students, images, board):
            lines += [f"![{plot.stem}]({plot.relative_to(path.parent).as_posix()})", ""]
        for video in sorted(run_dir.glob("best-*.mp4")):
            shutil.copy(video, images / video.name)
            lines += [f"Video of the best student: [{video.name}]({(images / video.name).relative_to(path.parent).as_posix()})", ""]
    atomic_write(path, "\n".join(lines))
    return path


def _suite_scope(suite: dict) -> str:
    """What the last transfer into a directory asked for (``suite.json``: the suite as run,
    with any command-line overrides), e.g. `` As run: rungs tagged easy, medium; worlds Cont; ...``."""
    parts = []
    if suite.get("tags") or suite.get("tasks"):
        parts.append("rungs " + "; ".join(filter(None, [
            f"tagged {', '.join(suite['tags'])}" if suite.get("tags") else "",
            ", ".join(suite.get("tasks") or ())])))
    for key, word in (("worlds", "worlds"), ("methods", "methods")):
        if suite.get(key):
            parts.append(f"{word} {', '.join(suite[key])}")
    if suite.get("seeds"):
        parts.append(f"{suite['seeds']} seed{'s' if suite['seeds'] > 1 else ''}")
    return f" As last run: {'; '.join(parts)}." if parts else ""


def _curve(values_at, grid):
    """Step function of (step, value) pairs sampled on ``grid`` (NaN before the first)."""
    steps = np.array([s for s, _ in values_at], dtype=float)
    vals = np.array([v for _, v in values_at], dtype=float)
    idx = np.searchsorted(steps, grid, side="right") - 1
    return np.where(idx >= 0, vals[np.maximum(idx, 0)], np.nan)


def plot_curves(students_root, out, board: Board | None = None) -> list[Path]:
    """Figure-5-style learning curves per task and world, one line per row of the board
    (``build(students_root)`` if not given): training return, greedy and training success
    (mean over seeds, with the t-interval band from 3 seeds), and the share of seeds that
    have reached 80% greedy success."""
    from matplotlib.figure import Figure  # not pyplot: no global backend switch in the caller's session
    from matplotlib.ticker import EngFormatter

    board = build(students_root) if board is None else board
    runs: dict[tuple, list[tuple[str, list, list, int]]] = {}
    for e in board:
        for name in e.runs:
            run = Path(students_root) / name
            runs.setdefault((e.task, e.world), []).append(
                (e.label, read_csv(run / "episodes.csv"), read_csv(run / "evals.csv"), e.budget))
    paths = []
    for (task, world), group in sorted(runs.items()):
        budget = max(g[3] for g in group)
        grid = np.linspace(budget / 50, budget, 50)
        fig = Figure(figsize=(14, 3.6))
        axes = fig.subplots(1, 3)
        for method in sorted({g[0] for g in group}):
            mine = [g for g in group if g[0] == method]
            color = None
            for ax, style, series in (
                (axes[0], "-", [_smoothed([(int(e["step"]), float(e["return"])) for e in g[1]], grid) for g in mine]),
                (axes[1], "-", [_curve([(int(e["step"]), float(e["success"])) for e in g[2]], grid) for g in mine]),
                (axes[1], "--", [_smoothed([(int(e["step"]), int(e["success"])) for e in g[1]], grid) for g in mine]),
            ):
                data = np.array(series)
                if data.size == 0:
                    continue
                valid = ~np.isnan(data).all(axis=0)  # before a run's first episode: no value yet
                mean = np.full(len(grid), np.nan)
                mean[valid] = np.nanmean(data[:, valid], axis=0)
                line, = ax.plot(grid, mean, style, color=color,
                                label=f"{method} ({len(mine)} seeds)" if style == "-" else None)
                color = line.get_color()  # one colour per method across panels and styles
                if style == "-":  # the dashed training success goes without a band, for legibility
                    bounds = (0.0, 1.0) if ax is axes[1] else (-math.inf, math.inf)
                    band = [stats.t_interval(col[~np.isnan(col)], bounds=bounds) for col in data.T]
                    lo, hi = np.array([(b.low, b.high) for b in band]).T  # NaN below 3 seeds: no band
                    ax.fill_between(grid, lo, hi, color=color, alpha=0.2)
            # the share of seeds that have reached 80% greedy success by each point: censored runs
            # (never reached) stay in the denominator, as in a survival curve
            firsts = [next((int(e["step"]) for e in g[2] if float(e["success"]) >= THRESHOLD), None) for g in mine]
            share = [np.mean([f is not None and f <= x for f in firsts]) for x in grid]
            axes[2].step(grid, share, where="post", color=color, label=f"{method} ({len(mine)} seeds)")
        fig.suptitle(f"{task} ({world})")  # a world with settings is too long for a panel's title
        axes[0].set(title="training episode return", xlabel="transitions", ylabel="return")
        axes[1].set(xlabel="transitions", ylabel="success rate", ylim=(-0.02, 1.02))
        axes[1].set_title("success: greedy evaluation (solid), training episodes (dashed)", fontsize=9)
        axes[1].legend(loc="upper left", fontsize=8)
        axes[2].set(title=f"seeds that reached {THRESHOLD:.0%} greedy success", xlabel="transitions",
                    ylabel="share of seeds", ylim=(-0.02, 1.02))
        for ax in axes:  # 800k, not 800000 run into its neighbours
            ax.xaxis.set_major_formatter(EngFormatter(sep=""))
        fig.tight_layout()
        name = f"curves-{task}-{_file_part(world)}"
        if any(p.stem == name for p in paths):  # two settings that read alike once in a file name
            name += "-" + hashlib.sha256(world.encode()).hexdigest()[:6]
        path = Path(out) / f"{name}.png"
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110)
        paths.append(path)
    return paths


def _smoothed(values_at, grid, window: float = 0.1):
    """Mean return of the episodes that ended in the last ``window`` of the budget before each grid point."""
    if not values_at:
        return np.full(len(grid), np.nan)
    steps = np.array([s for s, _ in values_at], dtype=float)
    vals = np.array([v for _, v in values_at], dtype=float)
    width = window * grid[-1]
    out = np.full(len(grid), np.nan)
    for i, g in enumerate(grid):
        sel = (steps <= g) & (steps > g - width)
        if sel.any():
            out[i] = vals[sel].mean()
    return out


@dataclass
class Profile:
    world: str
    path: Path


def plot_profiles(board, out, aggs: list[Aggregate] | None = None) -> list[Profile]:
    """Per world with an aggregate, the performance profile of final greedy success: the
    share of runs (averaged over tasks) above each threshold, with its stratified-bootstrap
    band (Agarwal et al. 2021, Figure 5); ``profile-<world>.png`` in ``out``."""
    from matplotlib.figure import Figure

    taus = np.linspace(0, 1, 51)
    out_paths = []
    for agg in aggregates(list(board)) if aggs is None else aggs:
        if not agg.scores:
            continue
        fig = Figure(figsize=(6, 3.8))
        ax = fig.subplots()
        for method in sorted(agg.scores, key=lambda m: -agg.iqm[m]["auc"].value):
            value, low, high = stats.performance_profile(agg.scores[method], taus - 1e-9)  # >= tau: a rate of tau counts
            line, = ax.plot(taus, value, label=f"{method} ({agg.runs[method]} runs)")
            ax.fill_between(taus, low, high, color=line.get_color(), alpha=0.2)
        ax.set(title=f"{agg.world}: {len(agg.tasks)} task{'s' if len(agg.tasks) > 1 else ''}", xlabel="final greedy success \u03c4",
               ylabel="share of runs with success \u2265 \u03c4", ylim=(-0.02, 1.02))
        ax.legend(fontsize=8)
        fig.tight_layout()
        path = Path(out) / f"profile-{_file_part(agg.world)}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=110)
        out_paths.append(Profile(agg.world, path))
    return out_paths
