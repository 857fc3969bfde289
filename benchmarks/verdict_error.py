"""How often does the results page call a gap that is not there, and find one that is?

Usage: python benchmarks/verdict_error.py [--trials N] [--page PATH | --no-page]

Each trial draws both sides' per-seed final greedy success from one distribution and reads
them with the page's own comparison (``craftsuite.reporting.board.compare``). A seed's
success is the share of 20 greedy episodes that succeed (the suites evaluate 20): in the
bimodal cases a seed learns with probability q and then succeeds in each episode with
probability 0.95, else 0.02; in the unimodal case each episode succeeds with probability
0.5. Where both sides share a distribution, any *ahead* or *behind* is false: its rate is
the rule's error, against a reference of 5% for a 95% rule (standard error
sqrt(0.05 * 0.95 / N)). The page's rule: the two means' intervals apart, or the probability
of improvement's bootstrap interval excluding one half **and** the difference's interval
excluding 0 (a side whose seeds all sat at 0 or at 1 takes its exact interval, any other its
t-interval widened by a score interval where that reaches further, which matters near 0 and 1;
the difference squares and adds the two sides' intervals wherever a side was widened, which is
most comparisons, else Welch's). Beside it: each route alone, and the rule the page had before
(either route alone decides). Then power: how often each rule says *ahead* when the
distilled side learns with q 0.2 higher. Then *all-or-nothing* outcomes (a seed that learned
succeeds in every episode, else in none, as the archive's learned seeds mostly do), where a
side's seeds often all read 1.00 or 0.00, on equal and unequal sides (experiments/
bounded-intervals): false *ahead*/*behind* where both sides share q, and false *no difference
of 0.2 or more* where their q differ by exactly 0.2 (reference 2.5%: a 95% interval within
+-0.2 is two one-sided tests at 2.5%).
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from craftsuite import stats
from craftsuite.reporting import board
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

EPISODES = 20  # greedy evaluation episodes per seed, as the suites run them
LEARNED, UNLEARNED = 0.95, 0.02  # an episode's success probability on a seed that learned / did not
SEEDS = (5, 10, 20, 100)
NULLS = (("bimodal, q = 0.2", 0.2), ("bimodal, q = 0.5", 0.5), ("bimodal, q = 0.8", 0.8), ("unimodal, p = 0.5", None))
GAPS = ((0.3, 0.5), (0.5, 0.7))  # (scratch's q, the distilled side's q)
EXACT_NULLS = (0.1, 0.9, 0.97)  # all-or-nothing outcomes, both sides at this q (0.97: nearly every seed at 1)
SIDES = ((5, 5), (10, 10), (20, 20), (100, 100), (5, 50), (10, 30))  # (distilled seeds, scratch seeds)
EXACT_GAPS = ((1.0, 0.8), (0.2, 0.0), (0.6, 0.4), (0.95, 0.75), (0.05, 0.25))  # (the distilled side's q, scratch's q):
# a gap of 0.2, one side at a bound, neither, or both near one (experiments/near-bound-intervals)


def draw(rng, n: int, q: float | None, exact: bool = False) -> list[float]:
    """n seeds' final greedy success: bimodal with learning probability q, or unimodal (q
    None); ``exact``: a seed that learned succeeds in every episode, else in none."""
    p = np.full(n, 0.5) if q is None else np.where(rng.random(n) < q, *((1.0, 0.0) if exact else (LEARNED, UNLEARNED)))
    return list(rng.binomial(EPISODES, p) / EPISODES)


def entry(values: list[float]) -> board.Entry:
    return board.Entry(task="T", world="Grid10", method="m", seeds=list(range(len(values))),
                       values={m: values for m in board.METRICS}, reached=stats.reached([]))


def routes(mine: list[float], theirs: list[float]) -> dict[str, str | None]:
    """The side ("ahead", "behind" or None) each rule gives: the page's, each of its two
    routes alone, and either route alone (the page's rule before)."""
    a, b = entry(mine), entry(theirs)
    comparison = board.compare(a, b)
    apart = board.verdict(a, b, "success")
    apart = apart if apart in ("ahead", "behind") else None
    probability = board.probability_side(comparison.improvement, len(mine), len(theirs))
    return {"page": comparison.side, "apart": apart, "probability": probability, "either": apart or probability}


RULES = ("page", "apart", "probability", "either")


def rates(rng, n: int, q_mine, q_theirs, trials: int, side: str | None) -> dict[str, float]:
    """Per rule, the share of trials giving ``side`` (None: either side)."""
    hits = dict.fromkeys(RULES, 0)
    for _ in range(trials):
        said = routes(draw(rng, n, q_mine), draw(rng, n, q_theirs))
        for rule in RULES:
            hits[rule] += said[rule] is not None and (side is None or said[rule] == side)
    return {rule: hits[rule] / trials for rule in RULES}


def exact_rates(rng, sides: tuple[int, int], q_mine: float, q_theirs: float, trials: int) -> tuple[float, float]:
    """All-or-nothing outcomes: the shares of trials in which the page's rule says *ahead* or
    *behind*, and *no difference of 0.2 or more*."""
    sided = same = 0
    for _ in range(trials):
        comparison = board.compare(entry(draw(rng, sides[0], q_mine, exact=True)),
                                   entry(draw(rng, sides[1], q_theirs, exact=True)))
        sided += comparison.side is not None
        same += comparison.verdict.startswith("no difference")
    return sided / trials, same / trials


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=1_000, help="trials per setting (a quarter at 100 seeds)")
    add_page_argument(parser)
    args = parser.parse_args()
    if args.trials < 1:
        parser.error(f"--trials must be at least 1, got {args.trials}")
    rng = np.random.default_rng(0)
    report = Report()

    def trials(n: int) -> int:
        return max(1, args.trials // 4) if n >= 100 else args.trials

    report(f"False *ahead*/*behind* under no difference, share of trials (reference: 0.05; standard error "
           f"{math.sqrt(0.05 * 0.95 / args.trials):.3f} at {args.trials:,} trials, "
           f"{math.sqrt(0.05 * 0.95 / trials(100)):.3f} at 100 seeds):")
    report()
    report("| outcomes per seed | seeds a side | the page's rule | t-intervals apart | probability's interval | "
           "either alone (before) |")
    report("|---|---|---|---|---|---|")
    worst = before = 0.0
    for name, q in NULLS:
        for n in SEEDS:
            r = rates(rng, n, q, q, trials(n), None)
            worst, before = max(worst, r["page"]), max(before, r["either"])
            report(f"| {name} | {n} | {r['page']:.3f} | {r['apart']:.3f} | {r['probability']:.3f} | "
                   f"{r['either']:.3f} |")
    report()
    report(f"The page's rule errs at most {worst:.3f} of the time here, the rule before at most {before:.3f} "
           "(reference 0.05).")
    report()
    report("Power: *ahead* where the distilled side's seeds learn with q 0.2 higher, share of trials:")
    report()
    report("| scratch's q → distilled's q | seeds a side | the page's rule | either alone (before) |")
    report("|---|---|---|---|")
    for q_theirs, q_mine in GAPS:
        for n in SEEDS:
            r = rates(rng, n, q_mine, q_theirs, trials(n), "ahead")
            report(f"| {q_theirs} → {q_mine} | {n} | {r['page']:.3f} | {r['either']:.3f} |")
    report()
    report("All-or-nothing outcomes (a learned seed succeeds in all 20 episodes, else in none): false *ahead*/"
           "*behind* where both sides learn with q (reference 0.05), false *no difference of 0.2 or more* where "
           "the distilled side's q is 0.2 away from scratch's (reference 0.025), share of trials under the page's "
           "rule:")
    report()
    report("| q | seeds (distilled, scratch) | false *ahead*/*behind* |")
    report("|---|---|---|")
    worst_sided = worst_same = 0.0
    for q in EXACT_NULLS:
        for sides in SIDES:
            sided, _ = exact_rates(rng, sides, q, q, trials(min(sides)))
            worst_sided = max(worst_sided, sided)
            report(f"| {q} | {sides[0]}, {sides[1]} | {sided:.3f} |")
    report()
    report("| distilled's q, scratch's q | seeds (distilled, scratch) | false *no difference* |")
    report("|---|---|---|")
    for q_mine, q_theirs in EXACT_GAPS:
        for sides in SIDES:
            _, same = exact_rates(rng, sides, q_mine, q_theirs, trials(min(sides)))
            worst_same = max(worst_same, same)
            report(f"| {q_mine}, {q_theirs} | {sides[0]}, {sides[1]} | {same:.3f} |")
    report()
    report(f"All-or-nothing: false *ahead*/*behind* at most {worst_sided:.3f} (reference 0.05), false *no "
           f"difference* at most {worst_same:.3f} (reference 0.025).")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
