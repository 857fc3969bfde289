"""A directory's student runs as a leaderboard: entries, their metrics, aggregates, verdicts.

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
"k of n reached; the median of those that did". The world is its name and the settings
that change it (``Entry.world``, ``Entry.world_kwargs``): runs in a fixed grid instance or
at another frame skip are another benchmark, so they get a row of their own. Runs of one
method whose settings differ in more than the seed are not pooled: each setting is a row
of its own, flagged.

Across tasks, per world and learner regime (``aggregates``): each method's IQM of final success and of AUC
with stratified-bootstrap intervals, and the probability that it improves on the same
algorithm from scratch.

Two entries are compared by ``verdict``.
"""

from __future__ import annotations

import json
import math
import string
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import stats
from ..completion import needs_reread
from ..progress import progress_bar
from ..record_format import RecordError, breaks_format, check_config, check_episodes, check_evals, check_result
from ..record_format import required as required_columns
from ..runs import RunError, evaluation_steps, flatten, read_config, read_log_columns, read_result, run_settings
from .obstacles import tally

# metrics with a mean and an interval per task and method; a rate lies in [0, 1]
METRICS = {"success": (0.0, 1.0), "return": (-math.inf, math.inf), "train_success": (0.0, 1.0),
           "auc": (0.0, 1.0)}
THRESHOLD = 0.8  # greedy success at which a run counts as having learned the task
# boards of this many runs or more say how far their reading is (an archive of thousands of
# runs reads for a minute or more; a transfer's own few runs in a second)
PROGRESS_FROM = 200
AGGREGATED = ("success", "auc")  # the metrics aggregated across tasks (rates: comparable across tasks)


def finite_mean(values) -> float:
    """The mean of the values that are numbers (-inf if none is: a run with no evaluation
    yet ranks last and has learned nothing)."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    return float(x.mean()) if len(x) else -math.inf


def unread_reason(err: Exception) -> str:
    """Why a record was not read, from the error that stopped it: its sentence
    (``automaton_state must be true, false or null, got 'yes'``), after the class's name
    only where the sentence alone would not say what went wrong: Python's own ``KeyError``
    (its message is the missing key) and ``TypeError``."""
    return f"{type(err).__name__}: {err}" if type(err) in (KeyError, TypeError) else str(err)


def world_of(config: dict) -> tuple[str, dict]:
    """A student's world as its ``config.json`` records it: the world's name and the
    keywords that change it (a fixed grid instance, a frame skip, a board size)."""
    from ..configs import StudentConfig  # the owner of a student's world settings
    from ..runs import config_from

    return config["world"], config_from(StudentConfig, config).env_kwargs


SELF_REPORTED = "self-reported"  # the regime of a run trained outside CraftSuite (craftsuite.recorder)


def regime_of(config: dict) -> str:
    """The learner regime a student's ``config.json`` ran under (``craftsuite.regimes``),
    read from the settings it recorded."""
    from ..methods import METHODS
    from ..regimes import regime_of as named

    algorithm = (config.get("effective") or {}).get("method", {}).get("algorithm")
    # a learner of its own (a recorded run, or a record of the format without CraftSuite's
    # settings): they are not CraftSuite's to read
    if config.get("self_reported") or (algorithm is None and config["method"] not in METHODS):
        return SELF_REPORTED
    if algorithm is None:
        algorithm = METHODS[config["method"]].algorithm
    return named(algorithm, config.get("hyperparameters") or {})


def world_label(world: str, kwargs: dict) -> str:
    """A world as a leaderboard shows it: ``Cont``, ``Grid10``, or with the settings that
    change it, e.g. ``Cont: frame_skip=2, max_episode_steps=1000``."""
    if not kwargs:
        return world
    return f"{world}: " + ", ".join(f"{k}={json.dumps(v)}" for k, v in sorted(kwargs.items()))


def finishing_session(config: dict) -> dict:
    """The last session of a run's ``config.json`` provenance, the one that finished it
    (empty: it names none)."""
    sessions = config.get("provenance") or []
    last = sessions[-1] if isinstance(sessions, list) and sessions else {}
    return last if isinstance(last, dict) else {}


@dataclass(frozen=True)
class Curves:
    """A run's learning curves as its logs give them, kept by ``run_metrics`` (which reads
    the logs anyway) for whoever draws them, and what its episodes reached for the obstacle
    tables: a page of thousands of runs then reads each log once."""

    episodes: np.ndarray  # (k, 3) per training episode: the step it ended at, its return, completed (0/1)
    evals: np.ndarray  # (j, 2) per evaluation: its step, greedy success
    reached: dict = field(default_factory=dict)  # its episodes' seen and states cells (obstacles.tally)


def run_metrics(run: Path) -> dict | None:
    """The metrics of one finished student run directory (None: a teacher's, or not
    finished), and its learning curves (``curves``, a ``Curves``).

    Raises:
        RunError: a damaged or unreadable record, named.
    """
    run = Path(run)
    if not (run / "result.json").exists():
        return None
    config = read_config(run)
    result = read_result(run)
    if result["kind"] != "student":
        return None  # a teacher run
    if needs_reread(config):  # its logs say another thing than success: the archive reads them again
        raise RunError(f"{run}: its success counted the automaton's acceptance on the kinematic board (record "
                       f"format {config.get('format', 1)}); keep it in a results archive (craftsuite archive "
                       "RUNS --suite S), which re-reads it as completion")
    # the record as the format has it (craftsuite.record_format): one line naming what breaks it
    raw_episodes = read_log_columns(run / "episodes.csv", required_columns("episodes.csv"))
    # no episodes.csv is no episode yet (a budget shorter than an episode); no evals.csv, damage
    raw_evals = read_log_columns(run / "evals.csv", required_columns("evals.csv"), required=True)
    try:
        check_config(config, run / "config.json")
        check_result(result, config, run / "result.json")
        eval_columns = check_evals(raw_evals, result["steps"], run / "evals.csv")
        episode_columns = check_episodes(raw_episodes, result["steps"], run / "episodes.csv")
    except RecordError as err:
        raise RunError(breaks_format(err)) from None
    budget = int(config["steps"])
    # the curves' arrays (Curves), as the checks above read them
    episodes = np.column_stack([episode_columns[name] for name in ("step", "return", "success")])
    evals = np.column_stack([eval_columns[name] for name in ("step", "success")])
    success = evals[:, 1]  # (one evaluation at least: check_evals)
    auc = float(success.mean())
    every, regime = config.get("eval_every"), regime_of(config)
    if regime == SELF_REPORTED and isinstance(every, int) and every > 0:
        # its loop chose when to evaluate: a curve short of the suite's schedule has no comparable area
        if not set(evaluation_steps(budget, every)) <= set(evals[:, 0].astype(int).tolist()):
            auc = float("nan")
    tail = episodes[episodes[:, 0] > 0.9 * budget]
    if not len(tail) and len(episodes):  # fewer episodes than the window: the last one
        tail = episodes[-1:]
    lengths = raw_evals.get("length") or ()
    reached = next((int(step) for step, s in evals if s >= THRESHOLD), None)
    world, world_kwargs = world_of(config)
    return {
        "task": config["task"], "world": world, "world_kwargs": world_kwargs, "method": config["method"],
        "regime": regime, "seed": config["seed"], "budget": budget, "steps": result["steps"],
        "updates": result.get("updates"),
        "success": float(success[-1]),
        "return": float(tail[:, 1].mean()) if len(tail) else float("nan"),
        "train_success": float(tail[:, 2].mean()) if len(tail) else float("nan"),
        "auc": auc,
        "steps_to_80": reached,
        # mean decisions of the last evaluation's episodes
        "length": float(lengths[-1] or "nan") if lengths else float("nan"),
        "finished_by": finishing_session(config),
        "curves": Curves(episodes, evals, tally(raw_episodes)),
    }


@dataclass
class Entry:
    """One row: a method's runs of one setting on one task in one world."""

    task: str
    world: str  # the world's name: Cont, Kinematic, Grid10
    method: str
    seeds: list[int]
    values: dict[str, list[float]]  # metric -> one value per seed, in seed order
    reached: stats.Reached  # seeds that reached 80% greedy success, and their median transitions
    budget: int = 0  # transitions per run
    updates: int | None = None  # mean gradient updates per run (None: runs from before they were recorded)
    variant: str = ""  # "a", "b", ...: the method's runs here differ in more than the seed, and this is one setting
    differs: dict = field(default_factory=dict)  # with a variant: the settings that tell it apart, and its values
    runs: list[Path] = field(default_factory=list)  # the run directories, in seed order
    curves: list[Curves] = field(default_factory=list)  # their learning curves, in seed order
    finished_by: list[dict] = field(default_factory=list)  # the session that finished each, in seed order
    world_kwargs: dict = field(default_factory=dict)  # the settings that change the world, beyond its name
    lengths: list[float] = field(default_factory=list)  # per seed: the last evaluation's mean episode length
    regime: str = "one-step"  # the learner regime its runs trained under (craftsuite.regimes)

    @property
    def self_reported(self) -> bool:
        """Trained outside CraftSuite, its records written by ``craftsuite.Recorder``."""
        return self.regime == SELF_REPORTED

    @property
    def label(self) -> str:
        return f"{self.method} ({self.variant})" if self.variant else self.method

    @property
    def world_label(self) -> str:
        return world_label(self.world, self.world_kwargs)

    @property
    def stats(self) -> dict[str, stats.Estimate]:
        return {m: stats.mean_interval(self.values[m], bounds=METRICS[m]) for m in METRICS}

    @property
    def budget_text(self) -> str:
        """The budget in transitions and gradient updates, e.g. ``60,000 / 15,000``."""
        return f"{self.budget:,} / " + (f"{self.updates:,}" if self.updates is not None else "?")


@dataclass
class Unfinished:
    """A student run that has no result yet: not on the board, but named beside it."""

    task: str
    world: str
    world_kwargs: dict
    method: str
    seed: int
    run: str  # the run directory's name
    regime: str = "one-step"

    @property
    def world_label(self) -> str:
        return world_label(self.world, self.world_kwargs)


@dataclass
class Board:
    """A directory's leaderboard: its entries, and the runs that are not on it."""

    entries: list[Entry]
    unfinished: list[Unfinished] = field(default_factory=list)
    unreadable: list[str] = field(default_factory=list)  # runs whose record is damaged: the file and the reason
    apart: Board | None = None  # the runs ``build`` was asked to set apart, as a board of their own

    def __iter__(self):
        return iter(self.entries)

    def __len__(self) -> int:
        return len(self.entries)

    @property
    def regimes(self) -> list[str]:
        """The learner regimes of CraftSuite's runs here, the regimes' table's order first
        (self-reported runs have a learner of their own: they stand beside every regime's
        runs, and make a regime of their own only where CraftSuite's runs are absent)."""
        from ..regimes import order

        mine = {e.regime for e in self.entries} | {u.regime for u in self.unfinished}
        if mine - {SELF_REPORTED}:
            mine.discard(SELF_REPORTED)
        return sorted(mine, key=order)

    def of_regime(self, regime: str) -> Board:
        """The runs of one learner regime, and the self-reported runs beside them (an
        unreadable record has none to tell: not among them; the runs set apart stay with
        the whole board)."""
        mine = (regime, SELF_REPORTED)
        return Board([e for e in self.entries if e.regime in mine], [u for u in self.unfinished if u.regime in mine])


def build(students_root, *more, apart=None, keep=None) -> Board:
    """The leaderboard of the runs under ``students_root`` (and the ``more`` directories of
    runs beside it: one board of them all): one entry per task, world, method and setting
    (runs that differ in more than the seed are never pooled). A run whose record is
    damaged is left out and named in ``Board.unreadable``, as is a run found twice.
    ``apart``: a test of a run's ``config.json``; the runs it holds true for make a board of
    their own, ``Board.apart`` (e.g. a suite's runs at a budget it no longer asks for).
    ``keep``: a test of a run's ``config.json``; the runs it holds false for are not read
    further, nor listed as unfinished or with damaged logs (a page about one method reads its
    runs alone: a run's logs take far longer to read than its config); a config that does not
    read, or a run found twice, is still named. Unlike ``apart``, whose failure names the run
    damaged, a ``keep`` that raises raises: it is the caller's test that is at fault."""
    groups: dict[tuple, list[tuple[dict, dict]]] = {}
    set_apart: dict[tuple, list[tuple[dict, dict]]] = {}
    board = Board([])
    elsewhere = Board([])
    found: dict[str, Path] = {}
    for root in map(Path, (students_root, *more)):
        for run in sorted(root.iterdir()) if root.is_dir() else []:
            held = found.get(run.name)
            if held is None:
                found[run.name] = run
                continue
            # one run key, one run: never counted twice; a finished copy before an unfinished one
            if (run / "result.json").exists() and not (held / "result.json").exists():
                found[run.name], run, held = run, held, run
            board.unreadable.append(f"{run}: the same run as {held}, counted once")
    bar = progress_bar(len(found), f"reading {students_root}", unit="run",
                       enabled=len(found) >= PROGRESS_FROM)
    for run in found.values():
        bar.update()
        if not (run / "config.json").exists():
            if (run / "result.json").exists():  # a result of no known run
                board.unreadable.append(f"{run / 'config.json'} is missing beside its result.json: "
                                        "the run's record is damaged")
            continue
        try:
            config = read_config(run)
        except RunError as err:
            board.unreadable.append(str(err))
            continue
        if keep is not None and not keep(config):  # outside the try: a test that fails is no damaged record
            continue
        try:
            m = run_metrics(run)
            away = apart is not None and apart(config)
            if m is None:
                if not (run / "result.json").exists() and run.name.startswith("student-"):
                    (elsewhere if away else board).unfinished.append(Unfinished(
                        config["task"], *world_of(config), config["method"], config["seed"], run.name,
                        regime_of(config)))
                continue
        except RunError as err:
            board.unreadable.append(str(err))
            continue
        except (ValueError, KeyError, TypeError) as err:  # a record that does not read as a run's
            board.unreadable.append(f"{run / 'config.json'}: {unread_reason(err)}")
            continue
        setting = {k: v for k, v in run_settings(config).items() if k != "seed"}
        # a regime's runs are never variants of another's: each regime is a board of its own (of_regime)
        key = (m["task"], world_label(m["world"], m["world_kwargs"]), m["method"], m["regime"],
               json.dumps(setting, sort_keys=True))
        (set_apart if away else groups).setdefault(key, []).append(({**m, "run": run}, setting))
    bar.close()
    board.entries = _entries(groups)
    if apart is not None:
        elsewhere.entries = _entries(set_apart)
        board.apart = elsewhere
    return board


def _entries(groups: dict[tuple, list[tuple[dict, dict]]]) -> list[Entry]:
    """One entry per group of runs (task, world, method, regime, setting); a method's
    settings on a task, where it has several, told apart as variants."""
    entries = []
    by_method: dict[tuple, list[tuple]] = {}
    for key in groups:
        by_method.setdefault(key[:4], []).append(key)
    for (task, _, method, regime), keys in sorted(by_method.items()):
        settings = [flatten(groups[k][0][1]) for k in keys]
        differing = sorted({name for s in settings for name in s
                            if len({json.dumps(t.get(name), sort_keys=True) for t in settings}) > 1})
        for i, key in enumerate(sorted(keys, key=lambda k: (-len(groups[k]), k[4]))):  # most runs first
            runs = sorted((m for m, _ in groups[key]), key=lambda m: m["seed"])
            setting = flatten(groups[key][0][1])
            updates = [r["updates"] for r in runs]
            entries.append(Entry(
                task, runs[0]["world"], method, [r["seed"] for r in runs], {m: [r[m] for r in runs] for m in METRICS},
                stats.reached([r["steps_to_80"] for r in runs]), budget=max(r["budget"] for r in runs),
                updates=None if None in updates else round(float(np.mean(updates))),
                variant=(string.ascii_lowercase[i] if i < 26 else str(i + 1)) if len(keys) > 1 else "",
                differs={name: setting.get(name, "(not recorded)") for name in differing},
                runs=[r["run"] for r in runs], curves=[r["curves"] for r in runs],
                finished_by=[r["finished_by"] for r in runs],
                world_kwargs=runs[0]["world_kwargs"],
                lengths=[r["length"] for r in runs], regime=regime))
    return entries


def best_run(board: Board, among=None) -> tuple[Path, Entry, int] | None:
    """The best student run on the board (``among``: only these run directories): the highest
    final greedy success, then the hardest rung, then the highest return; with its entry and
    its index in the entry's seeds. None: no run."""
    among = None if among is None else {Path(p).resolve() for p in among}
    best = None
    for e in board:
        for i, run in enumerate(e.runs):
            if among is not None and Path(run).resolve() not in among:
                continue
            ret, won = e.values["return"][i], e.values["success"][i]
            key = (won if math.isfinite(won) else -math.inf, rung_order(e.task)[0],
                   ret if math.isfinite(ret) else -math.inf)
            if best is None or key > best[0]:
                best = (key, Path(run), e, i)
    return None if best is None else best[1:]


def rung_order(task: str) -> tuple:
    """Tasks follow the task ladder, easiest rung first (unknown tasks last, by name)."""
    from ..task_registry import tasks

    spec = tasks().get(task)
    return spec.rung if spec is not None else (99, True, task)


def verdict(entry: Entry, baseline: Entry, metric: str) -> str:
    """How ``entry`` compares with ``baseline`` (same task and world) on ``metric``.

    ``steps_to_80``, the transfer target: whether ``entry`` reaches 80% greedy success in
    at most half the transitions of ``baseline``, read on the medians over all seeds
    (``stats.Reached.overall``), with the figures that say so: ``met (...)``, ``not met
    (...)`` or ``not known (...)``. Where the baseline's median is never within its budget,
    all that is known of its time is that it exceeds that budget, so half of it exceeds half
    the budget: reaching 80% within half the baseline's budget meets the target (the text
    says the baseline never got there), reaching it later, or never, says nothing either way.

    A metric with an interval (``METRICS``: ``auc``, ``return``, ...): ``ahead``,
    ``behind``, ``no difference measured`` (the intervals overlap), ``neither learned``
    (success 0 at every evaluation of both, for the success metrics), ``too few seeds``
    (no interval) or ``not measured``.
    """
    if metric == "steps_to_80":
        return _transfer_target(entry, baseline)
    a, b = entry.stats[metric], baseline.stats[metric]
    if math.isnan(a.value) or math.isnan(b.value):
        return "not measured"
    if metric in ("auc", "success") and a.value == 0 and b.value == 0:
        return "neither learned"
    if not (a.has_interval and b.has_interval):
        return "too few seeds"
    return _apart(a, b) or "no difference measured"


def _apart(a: stats.Estimate, b: stats.Estimate) -> str | None:
    """"ahead" or "behind" where the intervals ``a`` and ``b`` are apart; None where they
    overlap or either has none (NaN compares false)."""
    return "ahead" if a.low > b.high else "behind" if a.high < b.low else None


def _transfer_target(entry: Entry, baseline: Entry) -> str:
    mine, theirs = entry.reached.overall, baseline.reached.overall

    def text(steps: float, e: Entry) -> str:
        return f"{steps:,.0f}" if math.isfinite(steps) else f"never in {e.budget:,}"

    half = f"half of it {theirs / 2:,.0f}" if math.isfinite(theirs) else f"half of it above {baseline.budget / 2:,.0f}"
    figures = f"{text(mine, entry)} against {text(theirs, baseline)}; {half}"
    if not math.isfinite(mine):
        # never within its budget: short of the target only where scratch's half lay within it
        if math.isfinite(theirs) and entry.budget >= theirs / 2:
            return f"not met ({figures})"
        return f"not known: neither got there within its budget ({figures})"
    if math.isfinite(theirs):
        return f"{'met' if mine <= theirs / 2 else 'not met'} ({figures})"
    if mine <= baseline.budget / 2:
        return f"met: scratch never got there ({figures})"
    return f"not known: scratch never got there in its budget, and this took more than half of it ({figures})"


# the smallest difference a comparison must be able to see, in final greedy success and in
# AUC alike: where the interval of the difference lies within +-this, the two are said not to
# differ by it
SMALLEST_DIFFERENCE = 0.2


# the metrics a method is compared with its baseline in, each with the words a page reads it
# by: final greedy success (where a run ends) and AUC (how soon and how steadily it got there)
COMPARED = {"success": "final greedy success", "auc": "AUC"}
# where every value of both sides is 0 (or 1), what that says of the runs beyond "every
# seed of both at 0", by metric: an AUC of 0 (or 1) is success 0 (or 1) at every evaluation
ALL_SAME = {"success": "", "auc": " at every evaluation"}


@dataclass(frozen=True)
class Comparison:
    """A method against a baseline on one task and world, in one of ``COMPARED``."""

    difference: stats.Estimate  # its mean minus the baseline's, with its interval (``stats.difference``)
    improvement: stats.Estimate  # P(a run of it beats a run of the baseline), stratified bootstrap
    # "ahead" or "behind" (", by less than 0.2" where that too), "no difference of 0.2 or more",
    # "undecided", "too few seeds"
    verdict: str
    trivial: bool = False  # decided only because every seed of both sat at 0 (or at 1)
    # what the verdict rests on where the row's cells do not show it, said beside it: "every
    # seed of both at 1" (trivial), "the two means' intervals apart"
    note: str = ""
    # undecided: the seeds a side that would decide it at its next look (one more reading) if
    # the difference and spreads held (``stats.seeds_to_resolve``); None where decided or not to be said
    seeds_to_decide: int | None = None
    looks: int = 1  # the readings taken of it (``reporting.looks``): every interval of it is at ``level``

    @property
    def level(self) -> float:
        return stats.shared_level(self.looks)

    @property
    def said(self) -> str:
        """The verdict with its note, as a line says it."""
        return self.verdict + (f" ({self.note})" if self.note else "")

    @property
    def decided(self) -> bool:
        return self.verdict not in ("undecided", "too few seeds", "not measured")

    @property
    def side(self) -> str | None:
        """"ahead" or "behind" (whatever the verdict adds), else None."""
        word = self.verdict.split(",")[0]
        return word if word in ("ahead", "behind") else None

    @property
    def small(self) -> bool:
        """An *ahead* or *behind* whose gap is real but smaller than ``SMALLEST_DIFFERENCE``
        (the verdict says *, by less than 0.2*): a tally that counts it says so."""
        return self.side is not None and self.verdict.endswith(f"by less than {SMALLEST_DIFFERENCE:g}")


def probability_side(improvement: stats.Estimate, n: int, m: int) -> str | None:
    """"ahead" or "behind" where the probability of improvement's interval excludes one half,
    from ``n`` and ``m`` runs; else None. The bootstrap interval reads [1, 1] for any complete
    separation, 3 seeds a side too: it counts only from 5 seeds a side (there, an exact
    Mann-Whitney p = 0.008, within the error of a comparison read up to 6 times)."""
    if min(n, m) < 5 or not improvement.has_interval:
        return None
    return "ahead" if improvement.low > 0.5 else "behind" if improvement.high < 0.5 else None


def compare(entry: Entry, baseline: Entry, metric: str = "success", looks: int = 1) -> Comparison:
    """``entry`` against ``baseline`` (same task and world) in ``metric`` (one of
    ``COMPARED``; both lie in [0, 1]): *ahead* or *behind* where the two means' intervals
    (``stats.mean_interval``: a t-interval, the exact one where every seed sat at 0 or at 1,
    elsewhere widened by a score interval where it reaches further, which matters near those
    bounds) are apart, or where the probability of improvement's interval excludes one half
    and the difference's interval (``stats.difference``: square-and-add of the two sides'
    intervals wherever a side's was widened, which is most comparisons; else Welch's)
    excludes 0 on the same side (*, by less than 0.2* added where the
    difference's interval also lies within +-``SMALLEST_DIFFERENCE``: a real but small gap);
    else *no difference of 0.2 or more* where the interval of the difference lies within
    +-``SMALLEST_DIFFERENCE``; else *undecided*. One rule and one smallest difference for
    every metric, so that no threshold is chosen after the figures are seen. Every interval
    is at 95%, or for a comparison read ``looks`` times at ``stats.shared_level(looks)``
    (``reporting.looks``); an undecided one's seeds to decide are figured at the level of its
    next reading, ``looks + 1``."""
    if metric not in COMPARED:
        raise ValueError(f"no comparison in {metric!r}: compare in one of {', '.join(sorted(COMPARED))}")
    mine, theirs = entry.values[metric], baseline.values[metric]
    level = stats.shared_level(looks)
    bounds = METRICS[metric]
    diff = stats.difference(mine, theirs, level, bounds)
    note = ""
    try:
        better = stats.probability_of_improvement([mine], [theirs], level)
    except ValueError:  # fewer than 2 runs on a side
        better = stats.Estimate(math.nan)
    apart = _apart(*(stats.mean_interval(values, level, bounds) for values in (mine, theirs)))
    # the probability's route alone errs up to twice its nominal 5% at 5-10 seeds a side
    # (benchmarks/verdict_error.py): it decides only where the difference's interval agrees
    side = probability_side(better, len(mine), len(theirs))
    by_probability = side if (side == "ahead" and diff.low > 0) or (side == "behind" and diff.high < 0) else None
    if math.isnan(diff.value):
        said = "not measured"
    elif not (diff.has_interval and better.has_interval):
        said = "too few seeds"
    elif apart in ("ahead", "behind"):
        said = apart
        # the row's cells show the difference and the probability, not the two t-intervals:
        # where those two would not have decided it, the row says what did
        note = "" if by_probability == apart else "the two means' intervals apart"
    elif by_probability:
        said = by_probability
    elif -SMALLEST_DIFFERENCE < diff.low and diff.high < SMALLEST_DIFFERENCE:
        said = f"no difference of {SMALLEST_DIFFERENCE:g} or more"
        if {*mine, *theirs} in ({0.0}, {1.0}):  # said plainly: no comparison tells methods apart there
            return Comparison(diff, better, said, trivial=True, looks=looks,
                              note=f"every seed of both at {mine[0]:g}{ALL_SAME[metric]}")
    else:
        return Comparison(diff, better, "undecided", looks=looks, seeds_to_decide=stats.seeds_to_resolve(
            mine, theirs, SMALLEST_DIFFERENCE, stats.shared_level(looks + 1), bounds))
    if said in ("ahead", "behind") and -SMALLEST_DIFFERENCE < diff.low and diff.high < SMALLEST_DIFFERENCE:
        said += f", by less than {SMALLEST_DIFFERENCE:g}"
    return Comparison(diff, better, said, looks=looks, note=note)


def distilled_against_scratch(rows: list[Entry], self_reported: bool = False) -> list[tuple[Entry, Entry]]:
    """For one task, world and regime: each distilled student (a method with a distilled
    target), and with ``self_reported`` each self-reported method, beside its world's
    algorithm from scratch; none where scratch did not run or ran in variants."""
    from ..methods import is_distilled, scratch

    base = [e for e in rows if e.method == scratch(e.world) and not e.self_reported]
    if len(base) != 1:
        return []
    return [(e, base[0]) for e in rows if (is_distilled(e.method) and not e.self_reported)
            or (self_reported and e.self_reported)]


@dataclass
class Pairwise:
    """A method against the world's baseline on every task both ran with 2 runs or more of
    each metric: more tasks than the aggregate's common ones where other methods ran fewer. A
    method short of runs on some common task (left out of the aggregate) is still here, on
    the tasks where it has them."""

    tasks: list[str]
    baseline: str  # the world's algorithm from scratch (the aggregate's own may be None: not on every task)
    runs: tuple[int, int]  # the method's runs and the baseline's on those tasks
    improvement: dict[str, stats.Estimate]  # metric -> P(method > baseline)


@dataclass
class Aggregate:
    """One world's methods across its tasks."""

    world: str  # the world's name
    world_kwargs: dict  # and its settings: runs in another setting are another aggregate
    regime: str  # the learner regime: another regime's runs are another aggregate
    tasks: list[str]  # the tasks every aggregated method ran
    baseline: str | None  # the world's algorithm from scratch, if it ran
    iqm: dict[str, dict[str, stats.Estimate]]  # method -> metric -> IQM
    improvement: dict[str, dict[str, stats.Estimate]]  # method -> metric -> P(method > baseline)
    scores: dict[str, list[np.ndarray]]  # method -> final success per task (for profiles)
    runs: dict[str, int]  # method -> runs aggregated
    left_out: list[str]  # what was not aggregated, and why
    # method -> its comparison with the baseline on every task both ran, beyond ``tasks``
    against_baseline: dict[str, Pairwise] = field(default_factory=dict)

    @property
    def world_label(self) -> str:
        return world_label(self.world, self.world_kwargs)

    @property
    def label(self) -> str:
        """The world and the regime, e.g. ``Cont, n-step regime``: what its heading and profile name."""
        return f"{self.world_label}, {self.regime} regime"


def aggregates(entries) -> list[Aggregate]:
    """Per world, the methods compared across the tasks all of them ran, each with 2 runs
    or more per task that have a final success, and one setting (variants are not
    aggregated). A world with nothing to aggregate still says why (an empty aggregate)."""
    from ..methods import scratch

    def finite(entry, metric):
        x = np.asarray(entry.values[metric], dtype=float)
        return x[np.isfinite(x)]

    out = []
    for label, regime in sorted({(e.world_label, e.regime) for e in entries}):
        mine = [e for e in entries if (e.world_label, e.regime) == (label, regime)]
        world, world_kwargs = mine[0].world, mine[0].world_kwargs
        left_out = []
        if regime != SELF_REPORTED and any(e.self_reported for e in entries if e.world_label == label):
            left_out.append("self-reported runs: compared with these per rung, not aggregated with them")
        # A cell that does not read as one (runs of more than one setting; one cell in two
        # directories; another budget than the task's scratch runs: another benchmark) leaves the
        # aggregate. Where it is the baseline's, the task goes (the probability of improvement
        # needs the baseline on every task), unless that would take every task the baseline ran;
        # elsewhere the method goes and the others keep the task.
        scratch_method = scratch(world)
        unreadable = _unreadable_cells(mine, scratch_method)
        bad_base = {t for (t, m) in unreadable if m == scratch_method}
        if bad_base and bad_base != {e.task for e in mine if e.method == scratch_method}:
            left_out += [f"task {t}: the baseline {scratch_method} there has {unreadable[t, scratch_method]}"
                         for t in sorted(bad_base, key=rung_order)]
            mine = [e for e in mine if e.task not in bad_base]
        dropped: dict[str, list[str]] = {}
        for (task, method), why in sorted(unreadable.items(), key=lambda kv: (rung_order(kv[0][0]), kv[0][1])):
            if any((e.task, e.method) == (task, method) for e in mine):
                dropped.setdefault(method, []).append(f"{why} on {task}")
        left_out += [f"{m}: {'; '.join(dropped[m])}" for m in sorted(dropped)]
        methods = sorted({e.method for e in mine} - set(dropped))
        cells = {(e.task, e.method): e for e in mine if e.method in methods}
        tasks = sorted({e.task for e in mine}, key=rung_order)
        pairwise = _against_baseline(cells, tasks, methods, scratch_method, finite)
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
        baseline = scratch_method if scratch_method in methods else None
        if scratch_method and not baseline and any(e.method == scratch_method for e in mine):
            left_out.append(f"the baseline {scratch_method} is not aggregated: no probability of improvement here"
                            + ("; each method against it on the tasks both ran below" if pairwise else ""))
        per_task = {m: {metric: [finite(cells[(t, m)], metric) for t in common] for metric in AGGREGATED}
                    for m in methods}
        out.append(Aggregate(
            world=world, world_kwargs=world_kwargs, regime=regime, tasks=common, baseline=baseline,
            iqm={m: {metric: stats.aggregate_iqm(per_task[m][metric]) for metric in AGGREGATED} for m in methods},
            improvement={m: _improvement(cells, common, m, baseline, finite) for m in methods
                         if baseline and m != baseline},
            scores={m: per_task[m]["success"] for m in methods},
            runs={m: sum(len(x) for x in per_task[m]["success"]) for m in methods}, left_out=left_out,
            against_baseline=pairwise))
    return out


def _unreadable_cells(entries, baseline: str | None) -> dict[tuple[str, str], str]:
    """The (task, method) cells of ``entries`` that do not read as one cell, each with why."""
    one = [e for e in entries if not e.variant]
    count: dict[tuple[str, str], int] = {}
    for e in one:
        count[e.task, e.method] = count.get((e.task, e.method), 0) + 1
    budgets = {e.task: e.budget for e in one if e.method == baseline and count[e.task, e.method] == 1}
    out = {}
    for e in entries:
        if e.variant:
            out.setdefault((e.task, e.method), "runs of more than one setting")
        elif count[e.task, e.method] > 1:
            out.setdefault((e.task, e.method), "runs in more than one directory")
        elif budgets.get(e.task, e.budget) != e.budget:
            out.setdefault((e.task, e.method), "another budget than the scratch runs'")
    return out


def _improvement(cells: dict, tasks: list[str], method: str, baseline: str, finite) -> dict[str, stats.Estimate]:
    """P(a run of ``method`` beats a run of ``baseline`` on the same task), per aggregated
    metric, averaged over ``tasks``."""
    return {metric: stats.probability_of_improvement([finite(cells[(t, method)], metric) for t in tasks],
                                                     [finite(cells[(t, baseline)], metric) for t in tasks])
            for metric in AGGREGATED}


def _against_baseline(cells: dict, tasks: list[str], methods: list[str], baseline: str | None,
                      finite) -> dict[str, Pairwise]:
    """Each method against ``baseline`` on every task both ran with 2 finite runs or more
    of each metric: the probability of improvement on those tasks alone."""
    if baseline not in methods:
        return {}
    out = {}
    for m in methods:
        if m == baseline:
            continue
        shared = [t for t in tasks if all((t, x) in cells and len(finite(cells[(t, x)], metric)) >= 2
                                          for x in (m, baseline) for metric in AGGREGATED)]
        if shared:
            runs = tuple(sum(len(finite(cells[(t, x)], "success")) for t in shared) for x in (m, baseline))
            out[m] = Pairwise(shared, baseline, runs, _improvement(cells, shared, m, baseline, finite))
    return out
