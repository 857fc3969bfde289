"""Learning curves and performance profiles, drawn from a leaderboard's entries."""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import stats
from ..files import atomic_path
from .board import THRESHOLD, Aggregate, Board, aggregates


def file_part(label: str) -> str:
    """``label`` as part of a file name: ``Cont: frame_skip=2`` -> ``Cont-frame_skip-2``."""
    return re.sub(r"[^\w.]+", "-", label).strip("-")


def _steps_and_values(values_at) -> tuple[np.ndarray, np.ndarray]:
    """(step, value) pairs, a list or a (k, 2) array, as their steps and their values."""
    pairs = np.asarray(values_at, dtype=float).reshape(-1, 2)
    return pairs[:, 0], pairs[:, 1]


def _curve(values_at, grid):
    """Step function of (step, value) pairs sampled on ``grid`` (NaN before the first)."""
    if len(values_at) == 0:  # a run never evaluated: no value anywhere (as ``smoothed`` without episodes)
        return np.full(len(grid), np.nan)
    steps, vals = _steps_and_values(values_at)
    idx = np.searchsorted(steps, grid, side="right") - 1
    return np.where(idx >= 0, vals[np.maximum(idx, 0)], np.nan)


@dataclass
class Drawn:
    """A figure drawn but not written yet: its file's stem and, for a profile, its world."""

    stem: str
    figure: object  # a matplotlib Figure
    world_label: str = ""  # a profile's aggregate: its world and regime (Aggregate.label)


def save_figures(drawn: list[Drawn], out) -> list[Path]:
    """Write each figure to ``out/<stem>.png`` (made if missing); returns the paths."""
    paths = []
    for d in drawn:
        path = Path(out) / f"{d.stem}.png"
        with atomic_path(path) as tmp:
            d.figure.savefig(tmp, dpi=110)
        paths.append(path)
    return paths


def plot_curves(board: Board, out) -> list[Path]:
    """``draw_curves``, written to ``out``."""
    return save_figures(draw_curves(board), out)


def draw_curves(board: Board) -> list[Drawn]:
    """Figure-5-style learning curves per task and world, one line per row of the board:
    training return, greedy and training success (mean over seeds, with the t-interval band
    from 3 seeds), and the share of seeds that have reached 80% greedy success."""
    from matplotlib.figure import Figure  # not pyplot: no global backend switch in the caller's session
    from matplotlib.ticker import EngFormatter

    runs: dict[tuple, list[tuple[str, np.ndarray, np.ndarray, int]]] = {}
    for e in board:
        for curves in e.curves:
            runs.setdefault((e.task, e.world_label, e.regime), []).append(
                (e.label, curves.episodes, curves.evals, e.budget))
    several = len(board.regimes) > 1  # then each regime's curves are a figure of their own
    drawn = []
    for (task, world, regime), group in sorted(runs.items()):
        budget = max(g[3] for g in group)
        grid = np.linspace(budget / 50, budget, 50)
        fig = Figure(figsize=(14, 3.6))
        axes = fig.subplots(1, 3)
        for method in sorted({g[0] for g in group}):
            mine = [g for g in group if g[0] == method]
            color = None
            for ax, style, series in (
                (axes[0], "-", [smoothed(g[1][:, [0, 1]], grid) for g in mine]),
                (axes[1], "-", [_curve(g[2], grid) for g in mine]),
                (axes[1], "--", [smoothed(g[1][:, [0, 2]], grid) for g in mine]),
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
                    band = [stats.mean_interval(col[~np.isnan(col)], bounds=bounds) for col in data.T]
                    lo, hi = np.array([(b.low, b.high) for b in band]).T  # NaN below 3 seeds: no band
                    ax.fill_between(grid, lo, hi, color=color, alpha=0.2)
            # the share of seeds that have reached 80% greedy success by each point: censored runs
            # (never reached) stay in the denominator, as in a survival curve
            firsts = [next((step for step, success in g[2] if success >= THRESHOLD), None) for g in mine]
            share = [np.mean([f is not None and f <= x for f in firsts]) for x in grid]
            axes[2].step(grid, share, where="post", color=color, label=f"{method} ({len(mine)} seeds)")
        fig.suptitle(f"{task} ({world}, {regime} regime)")  # a world with settings is too long for a panel's title
        axes[0].set(title="training episode return", xlabel="transitions", ylabel="return")
        axes[1].set(xlabel="transitions", ylabel="success rate", ylim=(-0.02, 1.02))
        axes[1].set_title("success: greedy evaluation (solid), training episodes (dashed)", fontsize=9)
        axes[1].legend(loc="upper left", fontsize=8)
        axes[2].set(title=f"seeds that reached {THRESHOLD:.0%} greedy success", xlabel="transitions",
                    ylabel="share of seeds", ylim=(-0.02, 1.02))
        for ax in axes:  # 800k, not 800000 run into its neighbours
            ax.xaxis.set_major_formatter(EngFormatter(sep=""))
        fig.tight_layout()
        name = f"curves-{task}-{file_part(world)}" + (f"-{file_part(regime)}" if several else "")
        if any(d.stem == name for d in drawn):  # two settings that read alike once in a file name
            name += "-" + hashlib.sha256(world.encode()).hexdigest()[:6]
        drawn.append(Drawn(name, fig))
    return drawn


def smoothed(values_at, grid, window: float = 0.1):
    """Mean return of the episodes that ended in the last ``window`` of the budget before each grid point."""
    grid = np.asarray(grid, dtype=float)
    if len(values_at) == 0:
        return np.full(len(grid), np.nan)
    steps, vals = _steps_and_values(values_at)
    order = np.argsort(steps, kind="stable")
    steps, total = steps[order], np.concatenate(([0.0], np.cumsum(vals[order])))
    # the episodes in (g - width, g]: those up to g less those up to g - width
    upto, before = np.searchsorted(steps, grid, side="right"), np.searchsorted(steps, grid - window * grid[-1], "right")
    count = upto - before
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, (total[upto] - total[before]) / count, np.nan)


@dataclass
class Profile:
    world_label: str  # the aggregate's world and regime, as its page names it (Aggregate.label)
    path: Path


def plot_profiles(board: Board, out, aggs: list[Aggregate] | None = None) -> list[Profile]:
    """``draw_profiles``, written to ``out``."""
    drawn = draw_profiles(board, aggs)
    return [Profile(d.world_label, path) for d, path in zip(drawn, save_figures(drawn, out), strict=True)]


def draw_profiles(board: Board, aggs: list[Aggregate] | None = None) -> list[Drawn]:
    """Per world with an aggregate (``aggs``: the board's, if already computed), the
    performance profile of final greedy success: the share of runs (averaged over tasks)
    above each threshold, with its stratified-bootstrap band (Agarwal et al. 2021, Figure
    5), as ``profile-<world>``."""
    from matplotlib.figure import Figure

    taus = np.linspace(0, 1, 51)
    drawn = []
    for agg in aggregates(list(board)) if aggs is None else aggs:
        if not agg.scores:
            continue
        fig = Figure(figsize=(6, 3.8))
        ax = fig.subplots()
        for method in sorted(agg.scores, key=lambda m: -agg.iqm[m]["auc"].value):
            # >= tau: a rate of tau counts
            value, low, high = stats.performance_profile(agg.scores[method], taus - 1e-9)
            line, = ax.plot(taus, value, label=f"{method} ({agg.runs[method]} runs)")
            ax.fill_between(taus, low, high, color=line.get_color(), alpha=0.2)
        ax.set(title=f"{agg.label}: {len(agg.tasks)} task{'s' if len(agg.tasks) > 1 else ''}",
               xlabel="final greedy success \u03c4",
               ylabel="share of runs with success \u2265 \u03c4", ylim=(-0.02, 1.02))
        ax.legend(fontsize=8)
        fig.tight_layout()
        drawn.append(Drawn(f"profile-{file_part(f'{agg.world_label} {agg.regime}')}", fig, agg.label))
    return drawn
