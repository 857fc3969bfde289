"""Statistics of record, honest at the handful of seeds a benchmark can afford.

Following Agarwal et al. (2021), "Deep reinforcement learning at the edge of the
statistical precipice" (the ``rliable`` library):

* per task and method, the seeds' values and a Student t-interval of their mean
  (``mean_interval``). Below ``MIN_SEEDS_FOR_INTERVAL`` there is no interval, only the
  seeds. A percentile bootstrap over 5 seeds covers the true mean in about 85% of normal
  cases, not the 95% it is labelled with; the t-interval keeps its level
  (``benchmarks/interval_coverage.py``), except at and near a bound of a rate: where
  every seed sits at 1 there is no spread, no width, so there the exact interval for
  bounded values, and near it the t-interval widened by a score interval;
* across tasks, each method's interquartile mean (``aggregate_iqm``, each task weighing
  the same), the probability that it improves on a baseline (``probability_of_improvement``)
  and its performance profile (``performance_profile``), with stratified-bootstrap intervals.

The stratified bootstrap is ``scipy.stats.bootstrap`` with one sample per task (and per
method, for a comparison): each is resampled on its own, which is what stratifying by task
means, and tasks may have different numbers of seeds. ``rliable`` computes the same
estimates on its runs x tasks matrices, where every task has as many runs (the test suite
checks them against it), but it needs ``arch``, ``statsmodels``,
``pandas`` and ``seaborn`` (about 170 MB; its import took 1.8 s against scipy.stats' 0.8 s
here) and an equal number of runs on every task. Intervals are percentile intervals, as
rliable's are, from ``resamples(level)`` resamples with a fixed seed, so a page regenerates
identically: 2,000 at 95%, and more at the higher levels of a comparison read more than once,
so that each end of an interval still rests on ``TAIL_RESAMPLES`` resamples beyond it. At 4
tasks x 5 seeds they run narrow: the IQM's covered the truth in 89% of simulated cases, not 95%
(``benchmarks/interval_coverage.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import median

import numpy as np

LEVEL = 0.95
MIN_SEEDS_FOR_INTERVAL = 3  # fewer seeds: the values, and no interval
RESAMPLES = 2_000
TAIL_RESAMPLES = 50  # resamples beyond each end of a percentile interval: RESAMPLES at 95%
SEED = 0


@dataclass(frozen=True)
class Estimate:
    """A point estimate and its interval (``low``/``high`` NaN: no interval)."""

    value: float
    low: float = math.nan
    high: float = math.nan

    @property
    def has_interval(self) -> bool:
        return not (math.isnan(self.low) or math.isnan(self.high))


def shared_level(looks: int) -> float:
    """The level of each of ``looks`` readings of one comparison that together err at most
    as one reading at ``LEVEL`` does (Bonferroni: 1 - 0.05/k; conservative, and a guarantee
    only where k was fixed before the first reading and every reading taken at that level)."""
    if looks < 1:
        raise ValueError(f"looks: a comparison is read at least once, got {looks}")
    return 1 - (1 - LEVEL) / looks


UNBOUNDED = (-math.inf, math.inf)


def t_interval(values, level: float = LEVEL) -> Estimate:
    """The mean of ``values`` (one per seed) and its Student t-interval. Fewer than
    ``MIN_SEEDS_FOR_INTERVAL`` values: the mean alone. On a bounded scale the page reads
    ``mean_interval``, which starts from this one."""
    from scipy import stats

    x = np.asarray(values, dtype=float)
    if len(x) == 0 or not np.isfinite(x).all():  # a seed without a value: no estimate to make
        return Estimate(math.nan)
    mean = float(x.mean())
    if len(x) < MIN_SEEDS_FOR_INTERVAL:
        return Estimate(mean)
    half = float(stats.t.ppf(0.5 + level / 2, len(x) - 1) * x.std(ddof=1) / math.sqrt(len(x)))
    return Estimate(mean, mean - half, mean + half)


def mean_interval(values, level: float = LEVEL, bounds: tuple[float, float] = UNBOUNDED) -> Estimate:
    """The interval of the mean of ``values`` (one per seed) the results page reads: on an
    open scale the t-interval (``t_interval``). On a bounded one (a rate's [0, 1]), where a
    t-interval reads its width from the seeds' spread alone and so misses near a bound (19
    seeds at 1 and one at 0 give a t-interval of [0.85, 1.00], excluding a true 0.8):
    - every value at one bound (every seed at 1.0): no spread at all, so the exact interval
      for values within the bounds (``_at_bound_interval``);
    - otherwise the union of the t-interval and the quasi-binomial score interval
      (``_score_interval``), clipped to the bounds: never narrower than the t-interval, and
      wider where the seeds' spread understates the spread a mean farther from the bound
      would have (experiments/near-bound-intervals)."""
    return _side_interval(np.asarray(values, dtype=float), level, bounds)[0]


def _side_interval(x: np.ndarray, level: float, bounds: tuple[float, float]) -> tuple[Estimate, bool]:
    """``mean_interval`` of ``x``, and whether it reaches beyond the t-interval clipped to the
    bounds (where ``difference`` squares and adds instead of reading Welch's)."""
    t = t_interval(x, level)
    if not t.has_interval:
        return t, False
    if _at_bound(x, bounds):
        return _at_bound_interval(float(x[0]), len(x), level, bounds), True  # x[0]: the bound, not a rounded mean
    low, high = max(bounds[0], t.low), min(bounds[1], t.high)
    score = _score_interval(x, level, bounds)
    if not score.has_interval:
        return Estimate(t.value, low, high), False
    wide = Estimate(t.value, max(bounds[0], min(low, score.low)), min(bounds[1], max(high, score.high)))
    return wide, (wide.low, wide.high) != (low, high)


def _score_interval(x: np.ndarray, level: float, bounds: tuple[float, float]) -> Estimate:
    """The quasi-binomial score interval of the mean of values within ``bounds``, not all at
    one bound: on the [0, 1] scale, the means p with (mean - p)^2 <= t^2 phi p (1 - p) / n,
    t Student's quantile at n - 1 degrees of freedom and phi = s^2 / (mean (1 - mean)) the
    dispersion the seeds show. It models a value's variance as phi p (1 - p), a proportion's
    variance function (as fractional-response GLMs do): at p = mean it is the seeds' own
    spread, and it grows as p moves from a bound toward the middle, where a t-interval holds
    it fixed. For values all at 0 or 1 it is Wilson's score interval with t^2 n / (n - 1) in
    place of z^2. No interval on a scale open on either side, or where the mean is not
    strictly inside the bounds (values outside them, or a mean that rounds onto one)."""
    from scipy import stats

    low, high = bounds
    if not (math.isfinite(low) and math.isfinite(high)):
        return Estimate(float(x.mean()))
    u = (x - low) / (high - low)
    n, mean = len(u), float(u.mean())
    if not 0 < mean < 1:
        return Estimate(float(x.mean()))
    k = float(stats.t.ppf(0.5 + level / 2, n - 1)) ** 2 * float(u.var(ddof=1)) / (mean * (1 - mean)) / n
    # (mean - p)^2 = k p (1 - p), a quadratic in p: (1 + k) p^2 - (2 mean + k) p + mean^2 = 0
    centre, half = (2 * mean + k) / (2 * (1 + k)), math.sqrt(k * k + 4 * k * mean * (1 - mean)) / (2 * (1 + k))
    return Estimate(float(x.mean()), low + (high - low) * (centre - half), low + (high - low) * (centre + half))


def _at_bound(x: np.ndarray, bounds: tuple[float, float]) -> bool:
    """Whether every value sits at one bound of a bounded scale (all seeds at 1.0 of a rate,
    or all at 0.0); a scale open on either side has no exact interval to give."""
    return all(map(math.isfinite, bounds)) and any(bool((x == b).all()) for b in bounds)


def _at_bound_interval(bound: float, n: int, level: float, bounds: tuple[float, float]) -> Estimate:
    """The interval of the mean of ``n`` independent values within ``bounds`` that all sat at
    ``bound``, one of them: on a [0, 1] scale, n values all at 1 leave [(alpha/2)^(1/n), 1]
    (Clopper and Pearson's interval for n successes of n). It holds for any values within
    the bounds, not only 0 and 1: a value reaches the top no more often than its mean says
    (Markov's inequality), so n of them all there have probability at most mean^n. A
    t-interval would read no width from no spread: 5 seeds all at 1 are as likely as not
    from a mean of 0.87, and their t-interval says [1, 1]."""
    low, high = bounds
    reach = (high - low) * ((1 - level) / 2) ** (1 / n)
    return Estimate(bound, low + reach, high) if bound == high else Estimate(bound, low, high - reach)


def difference(x, y, level: float = LEVEL, bounds: tuple[float, float] = UNBOUNDED) -> Estimate:
    """mean(x) - mean(y) of two independent samples (one value per seed each) with Welch's
    t-interval (no equal variances assumed). Fewer than ``MIN_SEEDS_FOR_INTERVAL`` values
    on a side: the difference alone. Where a side's interval on a bounded scale
    (``mean_interval``) reaches beyond its t-interval (every seed at a bound; near one, where
    the seeds' spread understates a mean's farther in; and, by a little, most sides whose mean
    is not one half, as the score interval leans toward the middle), the interval is built
    from the two sides' own intervals, clipped to the scale, by square-and-add (MOVER,
    Zou and Donner 2008; Newcombe's method 10 does the same with two Wilson intervals, for a
    difference of proportions): from d, down by hypot(mean_x - low_x, high_y - mean_y) and
    up by hypot(high_x - mean_x, mean_y - low_y). A clipped end can be shorter than Welch's
    half-width, so on a side toward a bound this interval may be the narrower of the two.
    Both samples constant elsewhere: the interval is the difference itself, all the seeds say."""
    from scipy import stats

    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if len(x) == 0 or len(y) == 0 or not (np.isfinite(x).all() and np.isfinite(y).all()):
        return Estimate(math.nan)
    d = float(x.mean() - y.mean())
    if min(len(x), len(y)) < MIN_SEEDS_FOR_INTERVAL:
        return Estimate(d)
    (ix, x_widened), (iy, y_widened) = _side_interval(x, level, bounds), _side_interval(y, level, bounds)
    if x_widened or y_widened:
        return Estimate(d, d - math.hypot(ix.value - ix.low, iy.high - iy.value),
                        d + math.hypot(ix.high - ix.value, iy.value - iy.low))
    vx, vy = x.var(ddof=1) / len(x), y.var(ddof=1) / len(y)
    if vx + vy == 0:
        return Estimate(d, d, d)
    dof = (vx + vy) ** 2 / (vx**2 / (len(x) - 1) + vy**2 / (len(y) - 1))  # Welch-Satterthwaite
    half = float(stats.t.ppf(0.5 + level / 2, dof) * math.sqrt(vx + vy))
    return Estimate(d, d - half, d + half)


def seeds_to_resolve(x, y, smallest: float, level: float = LEVEL,
                     bounds: tuple[float, float] = UNBOUNDED) -> int | None:
    """The seeds a side at which a comparison of x against y would be decided by the results
    page's interval rules (``reporting.board.compare``), if the difference and the spreads
    measured held: the two means' intervals apart (ahead or behind), or the interval of the
    difference within +-``smallest`` (no difference), read by the very functions the page
    reads (``mean_interval``, ``difference``, within ``bounds``) on n seeds a side with the
    measured means and spreads (a side whose seeds all sat at a bound staying there). A
    planning figure for an undecided comparison, not a promise: a spread read from a handful
    of seeds is itself uncertain, the figure is where the expected interval just decides (so
    about half the time more seeds are needed), and the page's other route to *ahead* or
    *behind* (the probability of improvement's interval excluding one half while the
    difference's excludes 0 on the same side) is not modelled (it can decide sooner). None
    where it cannot be said: fewer than ``MIN_SEEDS_FOR_INTERVAL`` values on a side, no
    spread on either (unless at a bound, where the exact interval narrows with the seeds), or
    no number of seeds up to 100,000 that would decide it."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if min(len(x), len(y)) < MIN_SEEDS_FOR_INTERVAL or not (np.isfinite(x).all() and np.isfinite(y).all()):
        return None
    if x.var() + y.var() == 0 and not (_at_bound(x, bounds) or _at_bound(y, bounds)):
        return None

    def like(values: np.ndarray, n: int) -> np.ndarray:  # n seeds with exactly these seeds' mean and spread
        if values.var() == 0:
            return np.full(n, values[0])
        pattern = np.linspace(-1.0, 1.0, n)
        return values.mean() + values.std(ddof=1) * (pattern - pattern.mean()) / pattern.std(ddof=1)

    def decides(n: int) -> bool:  # each rule's intervals narrow as n grows: the first n at which either decides
        a, b = like(x, n), like(y, n)
        ia, ib = mean_interval(a, level, bounds), mean_interval(b, level, bounds)
        if ia.low > ib.high or ib.low > ia.high:
            return True
        d = difference(a, b, level, bounds)
        return -smallest < d.low and d.high < smallest

    low, high = MIN_SEEDS_FOR_INTERVAL - 1, MIN_SEEDS_FOR_INTERVAL  # double, then halve
    while not decides(high):
        if high > 100_000:
            return None
        low, high = high, high * 2
    while high - low > 1:
        mid = (low + high) // 2
        low, high = (low, mid) if decides(mid) else (mid, high)
    return high


def iqm(per_task) -> float:
    """The interquartile mean of runs over tasks (one array of runs per task; a 2-D array's
    rows are its tasks), each task weighing the same whatever its count of runs: each of a
    task's n runs weighs 1 / (tasks x n), and the IQM is the weighted mean of the middle
    half of that weight, a run on its edge counted for its share. rliable's runs x tasks
    matrices give every task as many runs, and there this is its IQM (``scipy.stats.trim_mean``
    cutting 25% from each end), up to floating-point rounding, wherever a quarter of the runs
    is a whole number; pooling unequal counts as they stand would let a task with many seeds
    outweigh the others.

    Raises:
        ValueError: not one non-empty array of runs per task."""
    samples = [np.asarray(s, dtype=float) for s in per_task]
    if not samples or any(s.ndim != 1 or len(s) == 0 for s in samples):
        raise ValueError("iqm: give one non-empty list of runs per task, e.g. [[0.2, 0.9, 1.0], [0.0, 0.5]]")
    return float(_task_weighted_iqm(*samples))


def _task_weighted_iqm(*xs, axis=-1):
    """``iqm`` of per-task samples along ``axis``, per batch row (a bootstrap's resamples)."""
    values = np.concatenate([np.moveaxis(x, axis, -1) for x in xs], axis=-1)
    weights = np.concatenate([np.full(x.shape[axis], 1.0 / (len(xs) * x.shape[axis])) for x in xs])
    order = np.argsort(values, axis=-1, kind="stable")
    ordered, w = np.take_along_axis(values, order, axis=-1), weights[order]
    above = np.cumsum(w, axis=-1)
    inside = np.clip(above, 0.25, 0.75) - np.clip(above - w, 0.25, 0.75)  # each run's weight in the middle half
    return (ordered * inside).sum(axis=-1) / inside.sum(axis=-1)


def resamples(level: float = LEVEL) -> int:
    """How many bootstrap resamples an interval at ``level`` draws: RESAMPLES, or enough that
    ``TAIL_RESAMPLES`` of them fall beyond each end (at 98.75%, four readings' level, 2,000
    would leave 12 a tail, and the interval's ends would move with the seed)."""
    if not 0 < level < 1:
        raise ValueError(f"level: a confidence level between 0 and 1, got {level}")
    tail = (1 - level) / 2
    return max(RESAMPLES, math.ceil(round(TAIL_RESAMPLES / tail, 6)))


def _bootstrap(samples: list[np.ndarray], statistic, level: float = LEVEL):
    """Percentile interval of ``statistic(*samples, axis=-1)`` over independent resamples
    of each sample (the stratified bootstrap)."""
    from scipy import stats

    short = [len(s) for s in samples if len(s) < 2]
    if short:
        raise ValueError("a stratified bootstrap needs at least 2 runs per task and method")
    result = stats.bootstrap(samples, statistic, n_resamples=resamples(level), confidence_level=level,
                             method="percentile", vectorized=True, paired=False, rng=SEED,
                             batch=RESAMPLES)  # (a higher level's resamples in batches: memory stays 95%'s)
    return result.confidence_interval.low, result.confidence_interval.high


def aggregate_iqm(per_task: list) -> Estimate:
    """``iqm`` over every run of every task (one array of runs per task, each task weighing
    the same), with a stratified-bootstrap interval."""
    samples = [np.asarray(s, dtype=float) for s in per_task]
    low, high = _bootstrap(samples, _task_weighted_iqm)
    return Estimate(iqm(samples), float(low), float(high))


def probability_of_improvement(x_per_task: list, y_per_task: list, level: float = LEVEL) -> Estimate:
    """P(X > Y): the probability that a run of method X scores higher than a run of Y on
    the same task (ties count half: the Mann-Whitney U over the pairs), averaged over the
    tasks, with a stratified-bootstrap interval at ``level`` (X's and Y's runs resampled per
    task); not a number where a run's value is not (not measured in the metric)."""
    if len(x_per_task) != len(y_per_task) or not x_per_task:
        raise ValueError("probability of improvement: give both methods' runs on the same, non-empty list of tasks")
    samples = [np.asarray(s, dtype=float) for pair in zip(x_per_task, y_per_task) for s in pair]
    if not all(np.isfinite(s).all() for s in samples):  # a run not measured in the metric: as difference()
        return Estimate(math.nan)
    # each value as its place among its task's distinct values (the order is all U reads), once: a
    # resample of places then counts its pairs in a histogram of at most n + m bins, not in a sort
    places, sizes = [], []
    for x, y in zip(samples[::2], samples[1::2]):
        both = _places(np.concatenate((x, y)))
        places += [both[:len(x)], both[len(x):]]
        sizes.append(len(both))

    def statistic(*xs, axis=-1):
        return np.mean([_u_of_places(np.moveaxis(x, axis, -1), np.moveaxis(y, axis, -1), k)
                        for x, y, k in zip(xs[::2], xs[1::2], sizes)], axis=0)

    low, high = _bootstrap(places, statistic, level)
    return Estimate(float(statistic(*places)), float(low), float(high))


def p_greater(x, y, axis: int = -1) -> np.ndarray:
    """P(X > Y) + P(X = Y) / 2 over every pair of a run of ``x`` and a run of ``y`` along
    ``axis`` (the Mann-Whitney U over n x m), exact, per batch row: each value's place among
    the row's distinct values (``_places``, a sort), then ``_u_of_places``. Finite values only
    (a NaN would take a place above every value): ``probability_of_improvement`` answers NaN
    before it asks."""
    x, y = np.moveaxis(np.asarray(x, dtype=float), axis, -1), np.moveaxis(np.asarray(y, dtype=float), axis, -1)
    batch = np.broadcast_shapes(x.shape[:-1], y.shape[:-1])  # (e.g. a batch of resamples against one sample)
    x, y = np.broadcast_to(x, batch + x.shape[-1:]), np.broadcast_to(y, batch + y.shape[-1:])
    both = _places(np.concatenate((x, y), axis=-1))
    n = x.shape[-1]
    return _u_of_places(both[..., :n], both[..., n:], both.shape[-1])


def _places(values: np.ndarray) -> np.ndarray:
    """Each value's place along the last axis: how many distinct values of its row lie below it
    (ties share a place; a row of k values has places under k)."""
    order = np.argsort(values, axis=-1)
    ordered = np.take_along_axis(values, order, axis=-1)
    # in sorted order, a value's place is the count of distinct values before it
    steps = np.concatenate((np.zeros(values.shape[:-1] + (1,), dtype=np.intp),
                            (ordered[..., 1:] != ordered[..., :-1]).astype(np.intp)), axis=-1)
    places = np.empty_like(order)
    np.put_along_axis(places, order, np.cumsum(steps, axis=-1), axis=-1)
    return places


def _u_of_places(x: np.ndarray, y: np.ndarray, k: int) -> np.ndarray:
    """``p_greater`` along the last axis of places (``_places``, each under ``k``): per
    row, a histogram of each side's places, in which x's places each count the y places below
    them and half of those level with them, in n + m + k a row (2,000 resamples of 150 runs a
    side in milliseconds, where counting the pairs takes n x m a row and ranking a sort). The
    counts are whole (twice U), so the float is the same as any exact count's."""
    n, m = x.shape[-1], y.shape[-1]
    batch = x.shape[:-1]
    rows = int(np.prod(batch))
    offsets = (np.arange(rows) * k).reshape(batch + (1,))  # each row's histogram its own k bins

    def histogram(places):
        return np.bincount((places.astype(np.intp) + offsets).ravel(), minlength=rows * k).reshape(batch + (k,))

    hx, hy = histogram(x), histogram(y)
    twice_u = (hx * (2 * (np.cumsum(hy, axis=-1) - hy) + hy)).sum(axis=-1)
    return twice_u / (2 * n * m)


def performance_profile(per_task: list, taus) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The fraction of runs scoring above each threshold in ``taus`` (averaged over tasks,
    so that each task weighs the same), with its stratified-bootstrap band: (values, low, high)."""
    samples = [np.asarray(s, dtype=float) for s in per_task]
    taus = np.asarray(taus, dtype=float)

    def statistic(*xs, axis=-1):
        return np.stack([np.mean([np.mean(x > tau, axis=axis) for x in xs], axis=0) for tau in taus])

    low, high = _bootstrap(samples, statistic)
    return statistic(*samples), np.asarray(low), np.asarray(high)


@dataclass(frozen=True)
class Reached:
    """Steps to a threshold over seeds: ``k`` of ``n`` reached it, the ``median`` of those
    that did (None: none did). Never a mean over the others, whose time is unknown."""

    k: int
    n: int
    median: float | None
    # the median over every seed, one that never reached counting as later than any that did
    # (inf: half or more never did): what a comparison of methods' time to a threshold reads
    overall: float = math.inf

    def __str__(self) -> str:
        if self.k == 0:
            return f"0 of {self.n}"
        return f"{self.k} of {self.n}; median {self.median:,.0f}"


def reached(steps) -> Reached:
    """``steps``: per seed, the transitions at which it reached the threshold, or None."""
    done = [s for s in steps if s is not None]
    every = sorted(math.inf if s is None else float(s) for s in steps)
    middle = every[(len(every) - 1) // 2: len(every) // 2 + 1]  # one value, or the two of an even count
    overall = math.inf if not every or math.inf in middle else float(np.mean(middle))
    return Reached(len(done), len(steps), float(median(done)) if done else None, overall)
