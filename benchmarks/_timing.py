"""Timing helpers shared by the benchmark scripts."""

from __future__ import annotations

import time


def steps_per_second(env, actions) -> float:
    """Env steps/s over pre-drawn actions, resetting when an episode ends."""
    env.reset(seed=0)
    t = time.perf_counter()
    for a in actions:
        _, _, term, trunc, _ = env.step(a)
        if term or trunc:
            env.reset()
    return len(actions) / (time.perf_counter() - t)


def reset_ms(env, n: int = 500) -> float:
    t = time.perf_counter()
    for seed in range(n):
        env.reset(seed=seed)
    return (time.perf_counter() - t) / n * 1000
