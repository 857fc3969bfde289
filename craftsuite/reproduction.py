"""The paper's Figure 5 as a report: each panel's task, world and methods beside the paper's
claim, read from a transfer directory's runs (``craftsuite leaderboard RUNS --reproduction PAGE``).

A panel says what ran (methods, seeds, budget in transitions and gradient updates), what
did not, its leaderboard rows and learning curves, and a verdict measured from the runs:
the distilled student's AUC (mean greedy success over the run) against each baseline's,
by their t-intervals. Every figure on the page comes from the runs; the paper's claims
are quoted, the authors' published returns are reference rows.
"""

from __future__ import annotations

import json
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .files import atomic_path, atomic_write
from .ids import CONT, KINEMATIC
from .reporting.board import world_label
from .runs import RunError, read_result

MIN_SEEDS_FOR_CLAIM = 5  # what a panel needs before its verdict is a claim


@dataclass(frozen=True)
class Panel:
    letter: str
    task: str
    worlds: tuple[str, ...]  # student worlds (``world_label``); a continuous panel is read in both continuous worlds
    distilled: str  # the paper's method
    baselines: tuple[str, ...]
    claim: str  # the paper's words

    def methods(self) -> tuple[str, ...]:
        return (self.distilled, *self.baselines)


_GRID_BASELINES = ("static", "crm", "product-dqn", "dqn")
_GRID_CLAIM = "automaton distillation in a 10x10 grid-world student outperforms the baselines (20 trials)"
_CONT_CLAIM = "a substantially faster convergence than learning from scratch using TD3 (20 trials)"
FIGURE_5 = (
    Panel("a", "DungeonQuest", ("Grid10",), "dynamic", _GRID_BASELINES, _GRID_CLAIM),
    Panel("b", "DiamondMine", ("Grid10",), "dynamic", _GRID_BASELINES, _GRID_CLAIM),
    Panel("c", "BlindCraftsman", ("Grid10",), "dynamic", _GRID_BASELINES, _GRID_CLAIM),
    Panel("d", "BlindCraftsmanObstacles", ("Grid10",), "dynamic", _GRID_BASELINES,
          "a faster convergence in the student grid world with obstacles the teacher never saw"),
    # the authors' distilled Blind Craftsman student ran on a 10x10 board (their scratch TD3 on 7x7)
    Panel("e", "BlindCraftsman", (KINEMATIC, world_label(KINEMATIC, {"size": 10}), CONT), "td3-dynamic", ("td3",),
          _CONT_CLAIM),
    # the paper's caption says Diamond Mine; the authors' TD3 runs behind it are their Gold Mine
    Panel("f", "GoldMine", (KINEMATIC, CONT), "td3-dynamic", ("td3",), _CONT_CLAIM),
    Panel("g", "DungeonQuest", (KINEMATIC, CONT), "td3-dynamic", ("td3",), _CONT_CLAIM),
)


def authors_curves() -> dict[tuple[str, str], list[tuple[int, float]]]:
    """The authors' published TD3 training curves (one seed per method, their logs binned
    into 100 spans: ``assets/authors_td3_returns.csv``), by (task, method): (transitions,
    mean episode return) pairs."""
    import csv

    from .paths import assets_dir

    curves: dict[tuple[str, str], list[tuple[int, float]]] = {}
    with (assets_dir() / "authors_td3_returns.csv").open(newline="") as f:
        for row in csv.DictReader(f):
            curves.setdefault((row["task"], row["method"]), []).append((int(row["transitions"]), float(row["return"])))
    return curves


def plot_against_authors(out, entries, task: str, world: str) -> Path | None:
    """Return per training episode against transitions, ours (mean over seeds, the last 10%
    of the budget before each point, as the leaderboard's curves) beside the authors'
    published curves, on their axis (20M transitions) and on ours; None when they published
    none for the task."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import EngFormatter

    from .reporting.plots import file_part, smoothed
    from .runs import read_csv

    theirs = {m: c for (t, m), c in authors_curves().items() if t == task}
    if not theirs or not entries:
        return None
    budget = max(e.budget for e in entries)
    grid = np.linspace(budget / 50, budget, 50)
    fig = Figure(figsize=(11, 3.6))
    axes = fig.subplots(1, 2)
    colors = {}
    for e in entries:
        series = np.array([smoothed([(int(r["step"]), float(r["return"])) for r in read_csv(run / "episodes.csv")],
                                    grid)
                           for run in e.runs])
        mean = np.full(len(grid), np.nan)
        valid = ~np.isnan(series).all(axis=0)  # before a run's first episode: no value yet
        mean[valid] = np.nanmean(series[:, valid], axis=0)
        for ax in axes:
            line, = ax.plot(grid, mean, "-", color=colors.get(e.method),
                            label=f"{e.method}, CraftSuite ({len(e.runs)} seeds)")
            colors[e.method] = line.get_color()
    for method, curve in sorted(theirs.items()):
        x, y = np.array(curve, dtype=float).T
        for ax, keep in ((axes[0], x > 0), (axes[1], x <= budget * 1.05)):
            ax.plot(x[keep], y[keep], ":", marker=".", color=colors.get(method), label=f"{method}, authors (1 seed)")
    axes[0].set(title="on the authors' axis", xlabel="transitions", ylabel="return per episode")
    axes[1].set(title="on this run's budget", xlabel="transitions")
    axes[0].legend(fontsize=7)
    for ax in axes:
        ax.xaxis.set_major_formatter(EngFormatter(sep=""))
    fig.suptitle(f"{task} ({world}): return per training episode")
    fig.tight_layout()
    path = Path(out) / f"returns-{task}-{file_part(world)}.png"
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    return path


def write_report(run_dir, path) -> Path:
    """``docs/reproduction.md``-style page for the runs under ``run_dir`` (a ``craftsuite
    transfer`` output), its images under ``images/reproduction`` beside ``path``.

    Raises:
        FileNotFoundError, ValueError: no such directory, no finished student run in it,
            or none of a task and world of Figure 5's panels.
    """
    from .reporting.board import Board, verdict
    from .reporting.pages import task_table
    from .reporting.plots import file_part, plot_curves
    from .reporting.sources import read_runs

    runs, path = read_runs(run_dir, transfer=True), Path(path)
    run_dir, board = runs.path, runs.board
    panels = {(p.task, w) for p in FIGURE_5 for w in p.worlds}  # not a task or world of no panel
    if not any((e.task, e.world_label) in panels for e in board):  # a page of empty panels says nothing
        raise ValueError(f"{run_dir} holds no run of a task and world of Figure 5's panels ("
                         + ", ".join(sorted({f"{t} in {w}" for t, w in panels})) + "): --reproduction reads a "
                         "transfer of the paper suite (craftsuite transfer --suite paper)")
    images = path.parent / "images" / "reproduction"
    shutil.rmtree(images, ignore_errors=True)
    images.mkdir(parents=True)
    curves = {p.stem: p for p in plot_curves(Board([e for e in board if (e.task, e.world_label) in panels]), images)}
    lines = ["# Reproducing the paper's Figure 5", "",
             f"<!-- generated by `craftsuite leaderboard {run_dir.as_posix()} --reproduction {path.as_posix()}`;"
             " do not edit -->", ""]
    lines += _what_ran(runs)
    summary = ["| panel | task | world | seeds per method | budget per run (transitions / updates) | "
               "the distilled student against each baseline |", "|---|---|---|---|---|---|"]
    body = []
    for panel in FIGURE_5:
        for world in panel.worlds:
            # a method's runs of several settings: the one with the most runs (variant "a")
            entries = {e.method: e for e in board if e.task == panel.task and e.world_label == world
                       and e.method in panel.methods() and e.variant in ("", "a")}
            ran = [m for m in panel.methods() if m in entries]
            missing = [m for m in panel.methods() if m not in entries]
            title = f"({panel.letter}) {panel.task}, {world}"
            if not ran:
                summary.append(f"| {panel.letter} | {panel.task} | {world} | did not run | | |")
                body += [f"## {title}", "", "Did not run.", ""]
                continue
            seeds = min(len(entries[m].seeds) for m in ran)
            budget = entries[ran[0]].budget_text
            if panel.distilled in entries:
                d = entries[panel.distilled]
                verdicts = "; ".join(f"{m}: AUC {verdict(d, entries[m], 'auc')}, "
                                     f"return {verdict(d, entries[m], 'return')}"
                                     for m in panel.baselines if m in entries) or "no baseline ran"
            else:
                verdicts = f"{panel.distilled} did not run"
            if seeds < MIN_SEEDS_FOR_CLAIM:
                verdicts += f" (fewer than {MIN_SEEDS_FOR_CLAIM} seeds: not a claim)"
            summary.append(f"| {panel.letter} | {panel.task} | {world} | {seeds} | {budget} | {verdicts} |")
            body += [f"## {title}", "", f"The paper: *{panel.claim}*.", "",
                     f"Measured: {verdicts}." + (f" Did not run: {', '.join(missing)}."
                                                 if [m for m in missing if m != panel.distilled] else ""), ""]
            body += [*task_table([entries[m] for m in ran]), ""]
            plot = curves.get(f"curves-{panel.task}-{file_part(world)}")
            if plot is not None:
                body += [f"![{panel.letter}: {panel.task}, {world}]({plot.relative_to(path.parent).as_posix()})", ""]
            if entries[ran[0]].world == KINEMATIC:  # the world the authors' continuous curves come from
                returns = plot_against_authors(images, [entries[m] for m in ran], panel.task, world)
                if returns is not None:
                    body += [f"![{panel.letter}: returns beside the authors']"
                             f"({returns.relative_to(path.parent).as_posix()})", ""]
    lines += ["## Panels", "", *summary, "",
              "AUC: the mean greedy success over a run's evaluations; return: the mean training-episode return "
              "over the last 10% of a run (the paper's figure plots reward per episode). *Ahead* / *behind*: the "
              "distilled student's 95% t-interval lies wholly above / below the baseline's; *no difference "
              "measured*: they overlap; *neither learned*: both succeed at no evaluation.", "", *body]
    atomic_write(path, "\n".join(lines))
    return path


def _what_ran(runs) -> list[str]:
    """The protocol, the sessions and the budgets as run (``runs``: a ``RunsDirectory``),
    and what the paper ran instead."""
    from .reporting.sources import session_line

    run_dir, board, suite = runs.path, runs.board, runs.suite
    lines = ["## What ran", "", *(session_line(s, to_the_minute=False) for s in runs.sessions)]
    if suite:
        def settings(algorithm):  # the suite's, then the command line's over them
            return {**suite.get(f"{algorithm}_hyperparameters", {}), **suite.get(f"{algorithm}_overrides", {})}

        def layout(key, fixed):  # a suite.json from before a field existed holds the default's meaning
            return "new every episode" if suite.get(key, fixed) is None else "fixed"

        lines += [f"- Suite `{suite.get('name')}`: teachers' layout {layout('teacher_layout_seed', 0)}, "
                  f"grid students' layout {layout('grid_layout_seed', 1)}; envs per gradient step: teachers "
                  f"{suite.get('teacher_n_envs', 1)}, DQN {suite.get('dqn_n_envs', 1)}, TD3 "
                  f"{suite.get('td3_n_envs', 1)}; distilled students see the automaton state: "
                  f"{'yes' if suite.get('students_see_automaton', True) else 'no'}.",
                  f"- DQN settings (teachers): `{json.dumps(suite.get('teacher_hyperparameters', {}))}`",
                  f"- DQN settings (students): `{json.dumps(settings('dqn'))}`",
                  f"- TD3 settings: `{json.dumps(settings('td3'))}`"]
    budgets = sorted({(e.budget, e.updates) for e in board})
    lines.append("- Budget per run: " + ", ".join(f"{b:,} transitions / " + ("unrecorded" if u is None else f"{u:,}")
                                                  + " gradient updates" for b, u in budgets)
                 + "; the paper's: 2M steps of 10 envs, i.e. 20M transitions and 2M updates, 20 seeds.")
    for teacher in sorted((run_dir / "teachers").glob("teacher-*/result.json")):
        r = read_result(teacher.parent)
        lines.append(f"- Teacher `{teacher.parent.name}`: {r['steps']:,} transitions, {r.get('updates', 0):,} "
                     f"updates, greedy success {r['success']:.2f} "
                     f"({'reached' if r['reached_target'] else 'did not reach'} its target)")
    if board.unfinished:
        lines.append(f"- Unfinished, not counted: {len(board.unfinished)} runs")
    lines += reread_note(runs.students)
    return [*lines, ""]


def reread_note(students: Path) -> list[str]:
    """A line for the records whose success was re-read as completion (``completion``), if any."""
    reread = 0
    for path in sorted(students.glob("*/result.json")):
        try:
            reread += "success_reread" in read_result(path.parent)
        except RunError:  # a damaged result: the board names it among the runs not read
            continue
    if not reread:
        return []
    return [f"- Success re-read: {reread} runs' records counted the automaton's acceptance as success on the "
            "kinematic board; read again as completion, a training episode completed if accepted and ended before "
            "its time limit, an evaluation where its record decides it (0, or every episode cut at the limit: 0)."]

