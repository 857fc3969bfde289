"""Leaderboards and learning curves from student run directories.

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

Per task, world and method (``build``): the mean over seeds with a 95% bootstrap
confidence interval (percentile, 2,000 resamples of the seeds). The world is its kind and
its settings (``world_label``): runs in a fixed grid instance or at another frame skip
are another benchmark, so they get a row and a plot of their own. A run that never reached
80% counts as its budget, and the entry reads ">= ...": a lower bound.
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .runs import atomic_write, read_csv

METRICS = ("success", "return", "train_success", "auc", "steps_to_80")

# REFERENCE.md section 5: the authors' shipped continuous results, one run each, mean
# episode reward over the last 5% of 2e6 steps (not the same metric window as ours).
PAPER_REFERENCE = {
    "BlindCraftsman": {"td3-dynamic": 19.95, "td3": 17.06},
    "DungeonQuest": {"td3-dynamic": 90.45, "td3": 87.97},
    "DiamondMine": {"td3-dynamic": 29.59, "td3": 8.58},
}


def world_label(config: dict) -> str:
    """A student's world as a leaderboard shows it: ``Cont``, ``Grid10``, or with the
    settings that change it, e.g. ``Cont: frame_skip=2, max_episode_steps=1000``."""
    import dataclasses

    from .training import StudentConfig  # the owner of a student's world settings

    fields = {f.name for f in dataclasses.fields(StudentConfig)}
    # world_kwargs is absent from configs older than the field
    settings = StudentConfig(**{k: v for k, v in config.items() if k in fields}).env_kwargs
    if not settings:
        return config["world"]
    return f"{config['world']}: " + ", ".join(f"{k}={json.dumps(v)}" for k, v in sorted(settings.items()))


def _file_part(label: str) -> str:
    """``label`` as part of a file name: ``Cont: frame_skip=2`` -> ``Cont-frame_skip-2``."""
    return re.sub(r"[^\w.]+", "-", label).strip("-")


def run_metrics(run: Path) -> dict | None:
    """The metrics of one finished run directory (None if it has not finished)."""
    run = Path(run)
    if not (run / "result.json").exists():
        return None
    result = json.loads((run / "result.json").read_text())
    config = json.loads((run / "config.json").read_text())
    if result.get("kind") != "student":
        return None  # a teacher run
    budget = int(config["steps"])
    episodes = read_csv(run / "episodes.csv")
    evals = read_csv(run / "evals.csv")
    tail = [e for e in episodes if int(e["step"]) > 0.9 * budget]
    if not tail and episodes:  # fewer episodes than the window: the last one
        tail = episodes[-1:]
    success = [float(e["success"]) for e in evals]
    reached = next((int(e["step"]) for e in evals if float(e["success"]) >= 0.8), None)
    return {
        "task": config["task"], "world": world_label(config), "method": config["method"], "seed": config["seed"],
        "budget": budget, "steps": result["steps"], "updates": result.get("updates"),
        "success": success[-1] if success else float("nan"),
        "return": float(np.mean([float(e["return"]) for e in tail])) if tail else float("nan"),
        "train_success": float(np.mean([int(e["success"]) for e in tail])) if tail else float("nan"),
        "auc": float(np.mean(success)) if success else float("nan"),
        "steps_to_80": reached,
    }


def bootstrap_ci(values, resamples: int = 2000, level: float = 0.95, seed: int = 0) -> tuple[float, float, float]:
    """Mean and percentile-bootstrap interval of the mean over ``values`` (seeds)."""
    x = np.asarray(values, dtype=float)
    if len(x) == 0:
        return float("nan"), float("nan"), float("nan")
    if len(x) == 1:
        return float(x[0]), float(x[0]), float(x[0])
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, len(x), size=(resamples, len(x)))].mean(axis=1)
    lo, hi = np.quantile(means, [(1 - level) / 2, 1 - (1 - level) / 2])
    return float(x.mean()), float(lo), float(hi)


@dataclass
class Entry:
    task: str
    world: str
    method: str
    seeds: int
    stats: dict  # metric -> (mean, lo, hi)
    censored: int  # runs that never reached 80% (counted at their budget)
    differs: tuple[str, ...] = ()  # config fields, other than the seed, in which the pooled runs differ
    budget: int = 0  # transitions per run (the largest, if the pooled runs differ)
    updates: int | None = None  # mean gradient updates per run (None: runs from before they were recorded)

    @property
    def budget_text(self) -> str:
        """The budget in transitions and gradient updates, e.g. ``60,000 / 15,000``."""
        return f"{self.budget:,} / " + (f"{self.updates:,}" if self.updates is not None else "?")


def build(students_root) -> list[Entry]:
    """One entry per (task, world, method) over the finished runs under ``students_root``."""
    groups: dict[tuple, list[dict]] = {}
    configs: dict[tuple, list[dict]] = {}
    for run in sorted(Path(students_root).iterdir()) if Path(students_root).is_dir() else []:
        m = run_metrics(run)
        if m is not None:
            key = (m["task"], m["world"], m["method"])
            groups.setdefault(key, []).append(m)
            configs.setdefault(key, []).append(json.loads((run / "config.json").read_text()))
    entries = []
    for (task, world, method), runs in sorted(groups.items()):
        stats = {k: bootstrap_ci([r[k] for r in runs]) for k in ("success", "return", "train_success", "auc")}
        steps = [r["steps_to_80"] if r["steps_to_80"] is not None else r["budget"] for r in runs]
        stats["steps_to_80"] = bootstrap_ci(steps)
        mine = configs[(task, world, method)]
        differs = tuple(sorted(k for k in {k for c in mine for k in c} - {"seed"}
                               if len({json.dumps(c.get(k), sort_keys=True) for c in mine}) > 1))
        updates = [r["updates"] for r in runs]
        entries.append(Entry(task, world, method, len(runs), stats,
                             sum(r["steps_to_80"] is None for r in runs), differs,
                             budget=max(r["budget"] for r in runs),
                             updates=None if None in updates else round(float(np.mean(updates)))))
    return entries


def _fmt(stat, digits=2, integer=False, prefix="") -> str:
    mean, lo, hi = stat
    if np.isnan(mean):
        return "n/a"
    if integer:
        return f"{prefix}{mean:,.0f} [{lo:,.0f}, {hi:,.0f}]"
    return f"{prefix}{mean:.{digits}f} [{lo:.{digits}f}, {hi:.{digits}f}]"


def _rung_order(task: str) -> tuple:
    """Sections follow the task ladder, easiest rung first (unknown tasks last, by name)."""
    from .registration import tasks

    spec = tasks().get(task)
    return spec.rung if spec is not None else (99, True, task)


def to_markdown(entries: list[Entry], title: str | None = "# Leaderboard") -> str:
    from .methods import METHODS

    lines = [title, ""] if title else []
    lines += ["Mean over seeds [95% bootstrap interval]. success: greedy, last evaluation; return and "
              "training success: training episodes (exploration noise on), last 10% of the budget; AUC: mean "
              "evaluation success over training; steps to 80% (greedy) success, in transitions: '>=' when "
              "some seeds never got there (counted at their budget); budget: transitions / gradient updates "
              "per run. A world with settings beyond the registered one names them.", ""]
    for key in sorted({(e.task, e.world) for e in entries}, key=lambda k: (_rung_order(k[0]), k[1])):
        lines += [f"## {key[0]} ({key[1]})", "",
                  "| method | seeds | success | return (last 10%) | training success (last 10%) | AUC "
                  "| steps to 80% success | budget |",
                  "|---|---|---|---|---|---|---|---|"]
        rows = sorted((e for e in entries if (e.task, e.world) == key),
                      key=lambda e: (-e.stats["auc"][0], -e.stats["return"][0]))
        for e in rows:
            steps = _fmt(e.stats["steps_to_80"], integer=True, prefix=">= " if e.censored else "")
            if e.censored:
                steps += f" ({e.seeds - e.censored}/{e.seeds} reached)"
            lines.append(f"| {e.method} | {e.seeds} | {_fmt(e.stats['success'])} | {_fmt(e.stats['return'], 1)} "
                         f"| {_fmt(e.stats['train_success'])} | {_fmt(e.stats['auc'])} | {steps} | {e.budget_text} |")
        notes = [f"*{e.method}: its {e.seeds} runs differ in {', '.join(e.differs)}, not only in the seed; "
                 "they are pooled here (put runs of another setting in another directory)*"
                 for e in rows if e.differs]
        # in any MuJoCo setting: the authors' continuous world was a kinematic 2-D toy, none of ours
        ref = PAPER_REFERENCE.get(key[0]) if key[1].split(":")[0] == "Cont" else None
        if ref:
            for method, value in ref.items():
                lines.append(f"| *reference: authors' {method}, 1 run, 2M steps (return over the last 5%)* "
                             f"| 1 | | {value:.2f} | | | | |")
        lines += ["", *notes] if notes else []
        lines.append("")
    shown = [m for m in METHODS if m in {e.method for e in entries}]
    shown += sorted({e.method for e in entries} - set(shown))  # runs of a method no longer in the table
    lines += ["Methods:", ""]
    lines += [f"- `{m}`: {METHODS[m].description if m in METHODS else 'not a method of this version'}"
              for m in shown]
    lines.append("")
    return "\n".join(lines)


def to_csv(entries: list[Entry]) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf)
    writer.writerow(["task", "world", "method", "seeds", *(f"{m}{s}" for m in METRICS for s in ("", "_lo", "_hi")),
                     "steps_to_80_censored", "pooled_runs_differ_in", "budget_transitions", "updates"])
    for e in entries:
        writer.writerow([e.task, e.world, e.method, e.seeds, *(v for m in METRICS for v in e.stats[m]), e.censored,
                         " ".join(e.differs), e.budget, "" if e.updates is None else e.updates])
    return buf.getvalue()


def write(entries: list[Entry], out) -> Path:
    """``leaderboard.md`` and ``leaderboard.csv`` in ``out``; returns the Markdown path."""
    out = Path(out)
    atomic_write(out / "leaderboard.csv", to_csv(entries))
    atomic_write(out / "leaderboard.md", to_markdown(entries))
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
        entries = build(students)
        if not entries:
            raise ValueError(f"no finished student runs under {students}")
        parts.append((run_dir, students, entries))
    for run_dir, students, entries in parts:
        suite = json.loads((run_dir / "suite.json").read_text()) if (run_dir / "suite.json").exists() else {}
        name = suite.get("name", run_dir.name)
        lines += [f"## {name}" + (f": {suite['description']}" if suite.get("description") else ""), "",
                  f"Runs in `{run_dir.as_posix()}`.", ""]
        sessions = read(run_dir)
        for s in sessions:
            took = "did not finish" if s.get("seconds") is None else f"{s['seconds'] / 60:.1f} min"
            lines.append(f"- `{s['command']}`: {s['started'][:16].replace('T', ' ')} UTC, commit "
                         f"{s.get('commit') or 'unknown'}, {took} on {s['machine']}")
        if not sessions:
            lines.append(f"- runs in `{run_dir}` (no provenance.json: not made by `craftsuite transfer`)")
        board = to_markdown(entries, title=None).replace("\n## ", "\n### ")
        lines += ["", board.strip(), ""]
        # named after the directory, not the suite: two directories of one suite keep their own plots
        images = path.parent / "images" / _file_part(f"results-{run_dir.name}")
        images.mkdir(parents=True, exist_ok=True)
        for plot in plot_curves(students, images):
            lines += [f"![{plot.stem}]({plot.relative_to(path.parent).as_posix()})", ""]
        for video in sorted(run_dir.glob("best-*.mp4")):
            shutil.copy(video, images / video.name)
            lines += [f"Video of the best student: [{video.name}]({(images / video.name).relative_to(path.parent).as_posix()})", ""]
    atomic_write(path, "\n".join(lines))
    return path


def _curve(values_at, grid):
    """Step function of (step, value) pairs sampled on ``grid`` (NaN before the first)."""
    steps = np.array([s for s, _ in values_at], dtype=float)
    vals = np.array([v for _, v in values_at], dtype=float)
    idx = np.searchsorted(steps, grid, side="right") - 1
    return np.where(idx >= 0, vals[np.maximum(idx, 0)], np.nan)


def plot_curves(students_root, out) -> list[Path]:
    """Figure-5-style learning curves per task and world: mean and 95% band over seeds."""
    from matplotlib.figure import Figure  # not pyplot: no global backend switch in the caller's session
    from matplotlib.ticker import EngFormatter

    runs: dict[tuple, list[tuple[dict, list, list, int]]] = {}
    for run in sorted(Path(students_root).iterdir()) if Path(students_root).is_dir() else []:
        if run_metrics(run) is None:
            continue
        config = json.loads((run / "config.json").read_text())
        episodes = read_csv(run / "episodes.csv")
        evals = read_csv(run / "evals.csv")
        key = (config["task"], world_label(config))
        runs.setdefault(key, []).append((config, episodes, evals, int(config["steps"])))
    paths = []
    for (task, world), group in sorted(runs.items()):
        budget = max(g[3] for g in group)
        grid = np.linspace(budget / 50, budget, 50)
        fig = Figure(figsize=(10, 3.6))
        axes = fig.subplots(1, 2)
        for method in sorted({g[0]["method"] for g in group}):
            mine = [g for g in group if g[0]["method"] == method]
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
                    lo, hi = np.array([bootstrap_ci(col[~np.isnan(col)])[1:] for col in data.T]).T
                    ax.fill_between(grid, lo, hi, color=color, alpha=0.2)
        fig.suptitle(f"{task} ({world})")  # a world with settings is too long for a panel's title
        axes[0].set(title="training episode return", xlabel="transitions", ylabel="return")
        axes[1].set(xlabel="transitions", ylabel="success rate", ylim=(-0.02, 1.02))
        axes[1].set_title("success: greedy evaluation (solid), training episodes (dashed)", fontsize=9)
        axes[1].legend(loc="upper left", fontsize=8)
        for ax in axes:  # 800k, not 800000 run into its neighbours
            ax.xaxis.set_major_formatter(EngFormatter(sep=""))
        fig.tight_layout()
        name = f"curves-{task}-{_file_part(world)}"
        if any(p.stem == name for p in paths):  # two settings that read alike once in a file name
            name += "-" + hashlib.sha256(world.encode()).hexdigest()[:6]
        path = Path(out) / f"{name}.png"
        tmp = path.with_name(f".{path.name}.tmp.png")
        fig.savefig(tmp, dpi=110)
        tmp.replace(path)
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
