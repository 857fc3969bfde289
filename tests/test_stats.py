"""The statistics of record on data with known answers, and against rliable, their reference."""

from __future__ import annotations

import math

import numpy as np
import pytest

from craftsuite import stats


def test_iqm_by_hand():
    # one task of 8 runs: the middle half is the 3rd to the 6th in order
    assert stats.iqm([[10, 0, 1, 2, 3, 4, 5, -10]]) == pytest.approx((1 + 2 + 3 + 4) / 4)
    # across tasks (a 2-D array's rows) the runs are pooled before trimming
    assert stats.iqm(np.array([[0.0, 0.5, 1.0, 0.25], [1.0, 0.5, 0.0, 0.75]])) == pytest.approx(0.5)
    # each task weighs the same whatever its runs: pooled as they stand, 45 runs at 1 would make it 1.0
    assert stats.iqm([[1.0] * 45, [0.0] * 5]) == pytest.approx(0.5)
    assert stats.aggregate_iqm([np.array([1.0] * 45), np.array([0.0] * 5)]).value == pytest.approx(0.5)
    # a run on the edge of the middle half counts for its share: of 3 runs, a twelfth of each end's
    assert stats.iqm([[0.0, 1.0, 5.0]]) == pytest.approx((1.0 / 3 + 5.0 / 12) / 0.5)
    for flat in ([0.1, 0.9], [[0.1, 0.9], []]):  # runs not given per task, or a task without runs
        with pytest.raises(ValueError, match="iqm: give one non-empty list of runs per task"):
            stats.iqm(flat)


def test_t_interval_by_hand_and_the_pages_interval_at_its_edges():
    e = stats.t_interval([1.0, 2.0, 3.0])
    half = 4.302652729749464 * 1.0 / np.sqrt(3)  # t(0.975, df 2), sample sd 1
    assert (e.value, e.low, e.high) == pytest.approx((2.0, 2.0 - half, 2.0 + half))
    assert stats.mean_interval([0.9, 1.0, 1.0], bounds=(0.0, 1.0)).high == 1.0
    # every seed at a bound of [0, 1]: no spread, so the exact interval, Clopper and Pearson's for n of n
    assert stats.mean_interval([1.0] * 10, bounds=(0.0, 1.0)) == stats.Estimate(1.0, 0.025 ** 0.1, 1.0)
    assert stats.mean_interval([0.0] * 5, 0.9, bounds=(0.0, 1.0)) == stats.Estimate(0.0, 0.0, 1 - 0.05 ** 0.2)
    assert stats.mean_interval([2.0] * 5, bounds=(0.0, 2.0)).low == pytest.approx(2 * 0.025 ** 0.2)
    assert stats.mean_interval([1.0] * 10) == stats.Estimate(1.0, 1.0, 1.0)  # unbounded: nothing says it could be less
    assert stats.mean_interval([0.0] * 10, bounds=(0.0, math.inf)) == stats.Estimate(0.0, 0.0, 0.0)  # open above too
    two = stats.t_interval([0.2, 0.4])
    assert two.value == pytest.approx(0.3) and not two.has_interval  # below 3 seeds: no interval
    assert np.isnan(stats.t_interval([]).value)


def test_t_interval_covers_the_true_mean_at_its_level_with_five_seeds():
    """Simulated normal data: the 95% interval over 5 seeds covers the mean in 92-98% of
    4,000 trials (the binomial standard error at 95% over 4,000 trials is 0.35 points)."""
    rng = np.random.default_rng(7)
    covered = 0
    trials = 4_000
    for sample in rng.normal(loc=0.3, scale=0.2, size=(trials, 5)):
        e = stats.t_interval(sample)
        covered += e.low <= 0.3 <= e.high
    assert abs(covered / trials - 0.95) <= 0.03


def test_the_interval_of_seeds_all_at_one_still_covers_the_true_mean():
    # a seed learns (success 1.0) with probability 0.87, else not (0.0): 5 such seeds all read 1.0 about half
    # the time, where a t-interval reads no spread and says [1, 1]
    rng = np.random.default_rng(0)
    draws = [(rng.random(5) < 0.87).astype(float) for _ in range(2_000)]
    covered = np.mean([stats.mean_interval(d, bounds=(0.0, 1.0)).low <= 0.87 for d in draws])
    unbounded = np.mean([stats.t_interval(d).low <= 0.87 for d in draws])
    assert covered >= 0.95 and unbounded < 0.6


def test_near_a_bound_the_interval_is_widened_by_the_score_interval_and_never_narrowed():
    from scipy import optimize, stats as sp

    seeds = [1.0] * 19 + [0.0]
    t, e = stats.t_interval(seeds), stats.mean_interval(seeds, bounds=(0.0, 1.0))
    assert t.low > 0.8 > e.low and e.high == 1.0  # the t-interval misses a true 0.8; the widened one does not

    def score_ends(values):  # the means p whose score statistic sits on the t quantile, found by a root search
        x = np.asarray(values)
        m, n = x.mean(), len(x)
        phi, q = x.var(ddof=1) / (m * (1 - m)), sp.t.ppf(0.975, n - 1)
        gap = lambda p: (m - p) ** 2 - q**2 * phi * p * (1 - p) / n  # noqa: E731
        return optimize.brentq(gap, 1e-12, m), optimize.brentq(gap, m, 1 - 1e-12)

    assert e.low == pytest.approx(score_ends(seeds)[0], abs=1e-9)  # 0.74: Wilson's, up to the quantile
    near = [0.93, 0.95, 0.91, 0.92, 0.96, 0.94, 0.9, 0.93, 0.95, 0.94]  # small spread away from the bounds
    e, t = stats.mean_interval(near, bounds=(0.0, 1.0)), stats.t_interval(near)
    low, high = score_ends(near)
    assert (e.low, e.high) == pytest.approx((min(t.low, low), max(t.high, high)), abs=1e-9)
    assert e.low == pytest.approx(t.low, abs=0.003) and e.low <= t.low and e.high >= t.high  # nearly the t-interval
    # wide spread at a mean of one half: the score interval is the narrower, so the t-interval stands
    wide = [0.2, 0.8, 0.5, 0.1, 0.9]
    assert stats.mean_interval(wide, bounds=(0.0, 1.0)) == stats.t_interval(wide)
    # on another bounded scale the same interval, rescaled
    scaled = stats.mean_interval([2.0 * v for v in seeds], bounds=(0.0, 2.0))
    assert (scaled.low, scaled.high) == pytest.approx((2 * score_ends(seeds)[0], 2.0))
    # every value at a bound takes that bound's exact interval, even where the float mean rounds off it
    assert stats.mean_interval([0.3] * 10, bounds=(0.1, 0.3)).low == pytest.approx(0.1 + 0.2 * 0.025 ** 0.1)
    # a mean that rounds onto a bound leaves the t-interval (no score to read), not a division by zero
    one_off = [0.3] * 9 + [np.nextafter(0.3, 0.0)]
    assert stats.mean_interval(one_off, bounds=(0.1, 0.3)).high == 0.3


def test_the_widened_interval_covers_a_mean_near_one_where_the_t_interval_does_not():
    # seeds that learn (1.0) with probability 0.8, else not (0.0), 20 a side: a t-interval near the bound
    # reads 19 of 20 at 1 as [0.85, 1.00], missing 0.8 above its 5%
    rng = np.random.default_rng(3)
    draws = [(rng.random(20) < 0.8).astype(float) for _ in range(4_000)]
    draws = [d for d in draws if 0 < d.mean() < 1]  # all at 1 take the exact interval under both readings
    missed = np.mean([not stats.mean_interval(d, bounds=(0.0, 1.0)).low <= 0.8 <= stats.mean_interval(
        d, bounds=(0.0, 1.0)).high for d in draws])
    missed_t = np.mean([not stats.t_interval(d).low <= 0.8 <= stats.t_interval(d).high for d in draws])
    assert missed < 0.05 and missed_t > 0.06


def test_beside_a_widened_side_the_difference_squares_and_adds_and_elsewhere_is_welchs():
    near, far = [1.0] * 19 + [0.0], [1.0] * 15 + [0.0] * 5
    d = stats.difference(near, far, bounds=(0.0, 1.0))
    mine, theirs = (stats.mean_interval(v, bounds=(0.0, 1.0)) for v in (near, far))
    assert (d.low, d.high) == pytest.approx((0.2 - math.hypot(0.95 - mine.low, theirs.high - 0.75),
                                            0.2 + math.hypot(mine.high - 0.95, 0.75 - theirs.low)))
    # neither side widened (at a mean of one half the score interval is the narrower): Welch's, as unbounded
    wide, middle = [0.2, 0.8, 0.5, 0.1, 0.9], [0.3, 0.7, 0.4, 0.6, 0.5]
    assert stats.difference(wide, middle, bounds=(0.0, 1.0)) == stats.difference(wide, middle)


def test_a_difference_with_a_side_all_at_a_bound_squares_and_adds_the_two_intervals():
    ones, mixed = [1.0] * 5, [0.5, 0.7, 0.9, 0.6, 0.8]
    d = stats.difference(ones, mixed, bounds=(0.0, 1.0))
    mine, theirs = (stats.mean_interval(v, bounds=(0.0, 1.0)) for v in (ones, mixed))
    assert (d.value, d.low, d.high) == pytest.approx((0.3, 0.3 - math.hypot(1 - mine.low, theirs.high - 0.7),
                                                      0.3 + math.hypot(0.0, 0.7 - theirs.low)))
    welch = stats.difference(ones, mixed)  # unbounded: Welch's, which carries the mixed side's spread alone
    assert welch.low > 0 > d.low
    # a complete separation of 5 seeds against 5 is decided (an exact permutation test: p = 0.008)
    assert stats.difference([1.0] * 5, [0.0] * 5, bounds=(0.0, 1.0)).low > 0
    # nobody learned on either side: a gap of 0.2 is ruled out only from 17 seeds a side
    assert stats.difference([0.0] * 16, [0.0] * 16, bounds=(0.0, 1.0)).high > 0.2
    assert stats.difference([0.0] * 17, [0.0] * 17, bounds=(0.0, 1.0)).high < 0.2
    assert stats.difference([0.0] * 3, [0.0] * 3) == stats.Estimate(0.0, 0.0, 0.0)  # unbounded and constant


def test_steps_to_a_threshold_never_average_the_runs_that_did_not_get_there():
    assert str(stats.reached([300, None, 100, 200])) == "3 of 4; median 200"
    assert str(stats.reached([None, None])) == "0 of 2"
    assert stats.reached([10, 30]).median == 20.0
    # over every seed, a seed that never reached counting as later than all that did
    assert stats.reached([300, None, 100, 200]).overall == 250.0  # 200 and 300 in the middle
    assert stats.reached([300, None, 100]).overall == 300.0
    assert stats.reached([300, None, None, 100]).overall == math.inf  # the middle holds a never
    assert stats.reached([None, None, None]).overall == stats.reached([]).overall == math.inf


def test_aggregate_estimates_need_two_runs_per_task():
    with pytest.raises(ValueError, match="at least 2 runs per task"):
        stats.aggregate_iqm([np.array([1.0, 0.5]), np.array([1.0])])
    with pytest.raises(ValueError, match="same, non-empty list of tasks"):
        stats.probability_of_improvement([np.array([1.0, 0.5])], [])


@pytest.mark.slow  # bootstraps of both libraries
def test_the_estimates_agree_with_rliable():
    """rliable's IQM, probability of improvement and performance profile on the same
    runs x tasks matrices: point estimates equal, bootstrap intervals within resampling
    noise (both are 95% percentile intervals of 2,000 stratified resamples)."""
    from rliable import library as rly
    from rliable import metrics

    rng = np.random.default_rng(3)
    x = np.clip(rng.normal(0.6, 0.25, size=(5, 4)), 0, 1)  # 5 runs x 4 tasks
    y = np.clip(rng.normal(0.4, 0.25, size=(5, 4)), 0, 1)
    x_tasks, y_tasks = list(x.T), list(y.T)

    mine = stats.aggregate_iqm(x_tasks)
    point, ci = rly.get_interval_estimates({"x": x}, lambda s: np.array([metrics.aggregate_iqm(s)]), reps=2000)
    assert mine.value == pytest.approx(point["x"][0])
    assert (mine.low, mine.high) == pytest.approx(tuple(ci["x"][:, 0]), abs=0.03)

    mine = stats.probability_of_improvement(x_tasks, y_tasks)
    point, ci = rly.get_interval_estimates({"x,y": (x, y)}, metrics.probability_of_improvement, reps=2000)
    assert mine.value == pytest.approx(point["x,y"])
    assert (mine.low, mine.high) == pytest.approx(tuple(ci["x,y"].ravel()), abs=0.04)

    taus = np.linspace(0, 1, 11)
    value, low, high = stats.performance_profile(x_tasks, taus)
    theirs, bands = rly.create_performance_profile({"x": x}, taus, reps=2000)
    assert value == pytest.approx(theirs["x"])
    assert np.abs(low - bands["x"][0]).max() <= 0.1 and np.abs(high - bands["x"][1]).max() <= 0.1


def test_seeds_to_resolve_is_where_the_pages_interval_rules_start_to_decide():
    def like(values, n):  # n seeds with exactly the mean and sample spread of ``values``
        v = np.asarray(values, dtype=float)
        pattern = np.linspace(-1.0, 1.0, n)
        return v.mean() + v.std(ddof=1) * (pattern - pattern.mean()) / pattern.std(ddof=1)

    def decides(x, y) -> bool:  # the page's interval rules: t-intervals apart, or the difference within +-0.2
        a, b, d = stats.t_interval(x), stats.t_interval(y), stats.difference(x, y)
        return a.low > b.high or b.low > a.high or (-0.2 < d.low and d.high < 0.2)

    cases = [([0.23, 0.87, 1, 0.85, 0.57, 0.5, 0.78, 1, 0.92, 0.56], [1, 0, 0, 0, 0, 0, 1, 0, 0, 1]),  # a gap of 0.43
             ([0.0, 1.0, 1.0, 1.0, 0.5], [0.0, 0.0, 1.0, 0.0, 0.5]),  # 0.4, bimodal, unequal spreads
             ([0.0, 1.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.1, 0.2]),  # 0.14: only "no difference" can decide
             ([0.9, 1.0, 0.8, 1.0, 0.95], [0.9, 0.85, 1.0, 1.0, 0.7])]  # close and tight
    for x, y in cases:
        n = stats.seeds_to_resolve(x, y, 0.2)
        assert n is not None and decides(like(x, n), like(y, n)) and not decides(like(x, n - 1), like(y, n - 1))
    # the first case is decided by Welch's interval at 10 seeds, but not by the page's rules: more seeds it says
    assert stats.difference(*cases[0]).low > 0 and stats.seeds_to_resolve(*cases[0], 0.2) > 10
    # a side all at 1 of [0, 1] stays there, its exact interval narrowing with its seeds
    bounded = ([1.0] * 5, [1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0])
    n = stats.seeds_to_resolve(*bounded, 0.2, bounds=(0.0, 1.0))

    def decides_within(x, y) -> bool:
        a, b = stats.mean_interval(x, bounds=(0.0, 1.0)), stats.mean_interval(y, bounds=(0.0, 1.0))
        d = stats.difference(x, y, bounds=(0.0, 1.0))
        return a.low > b.high or b.low > a.high or (-0.2 < d.low and d.high < 0.2)

    assert n is not None and decides_within([1.0] * n, like(bounded[1], n))
    assert not decides_within([1.0] * (n - 1), like(bounded[1], n - 1))
    assert stats.seeds_to_resolve([1.0] * 5, [1.0] * 5, 0.2) is None  # no spread: nothing to extrapolate
    assert stats.seeds_to_resolve([0.0, 1.0], [1.0, 0.0], 0.2) is None  # too few seeds to read a spread
    assert stats.seeds_to_resolve([0.0, 1.0, 1.0], [0.0, 1.0, 1.0], 0.0) is None  # no gap, no margin: never


def test_an_interval_read_at_a_higher_level_keeps_as_many_resamples_beyond_each_end(monkeypatch):
    """At 95% the page's 2,000 resamples stand; a comparison read four times is read at 98.75%,
    where 2,000 would leave 12 resamples a tail and its ends would move with the seed."""
    assert stats.resamples(stats.LEVEL) == stats.RESAMPLES
    for k in (2, 3, 4, 6):
        level = stats.shared_level(k)
        assert stats.resamples(level) == stats.RESAMPLES * k  # 50 beyond each end, and not one more
    # the ends' spread over bootstrap seeds: about 0.011 with 2,000 resamples here, 0.006 now
    rng = np.random.default_rng(3)
    x, y = rng.uniform(size=10), rng.uniform(size=10) - 0.2
    ends = []
    for seed in range(20):
        monkeypatch.setattr(stats, "SEED", seed)
        e = stats.probability_of_improvement([x], [y], stats.shared_level(4))
        ends.append((e.low, e.high))
    assert np.std(ends, axis=0).max() < 0.009
    with pytest.raises(ValueError, match="between 0 and 1"):
        stats.resamples(1.0)


def test_the_probability_of_improvement_from_places_is_the_count_over_every_pair():
    """P(X > Y) + P(X = Y) / 2 from each value's place among the distinct values gives the
    count over every n x m pair to the bit, with ties (success comes in twentieths), distinct
    floats, unequal sides and a batch of resamples; and the probability of improvement's point
    is that count over its tasks' places."""
    rng = np.random.default_rng(5)
    for n, m in ((5, 5), (10, 20), (150, 150), (3, 1), (40, 41)):
        for x, y in ((rng.integers(0, 21, (40, n)) / 20, rng.integers(0, 21, (40, m)) / 20),
                     (rng.uniform(size=(40, n)), rng.uniform(size=(40, m)))):
            pairs = ((x[:, :, None] > y[:, None, :]) + 0.5 * (x[:, :, None] == y[:, None, :])).mean(axis=(1, 2))
            assert np.array_equal(stats.p_greater(x, y), pairs)
            assert np.array_equal(stats.p_greater(x.T, y.T, axis=0), pairs)
            if min(n, m) >= 2:  # (a bootstrap resamples 2 runs a side at least)
                improvement = stats.probability_of_improvement([x[0], x[1]], [y[0], y[1]])
                assert improvement.value == np.mean(pairs[:2])
    # a batch against one sample broadcasts, as counting the pairs would
    x, y = rng.integers(0, 21, (7, 6)) / 20, rng.integers(0, 21, 9) / 20
    pairs = ((x[:, :, None] > y[None, None, :]) + 0.5 * (x[:, :, None] == y[None, None, :])).mean(axis=(1, 2))
    assert np.array_equal(stats.p_greater(x, y), pairs)
    assert stats.p_greater([1.0, 1.0], [0.0, 1.0]) == 0.75
    # a run with no value in the metric has no place in the order: no probability, as no difference
    e = stats.probability_of_improvement([np.array([1.0, math.nan, 0.5])], [np.array([0.0, 1.0, 0.5])])
    assert math.isnan(e.value) and not e.has_interval
