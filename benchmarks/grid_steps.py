"""Grid env throughput, single process: the bare world beside the product env from make().

Usage: python benchmarks/grid_steps.py [--steps N]

"world" is ``GridWorldEnv`` stepped directly; "product (make)" is
``gymnasium.make(id, product=True)``: the automaton one-hot wrapper plus gymnasium's
default wrappers (TimeLimit, OrderEnforcing, PassiveEnvChecker), as users get it. Actions
are drawn in advance so that sampling is not timed; episodes reset when they end.
"""

from __future__ import annotations

import argparse
import gymnasium as gym
import numpy as np

import craftsuite
from _timing import reset_ms, steps_per_second


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=200_000)
    args = parser.parse_args()
    actions = np.random.default_rng(0).integers(0, 4, args.steps).tolist()
    print("| id | world steps/s | product (make) steps/s | reset ms |")
    print("|---|---|---|---|")
    for env_id in [i for i in craftsuite.registered_ids() if "-Grid" in i]:
        world = gym.make(env_id, max_episode_steps=None).unwrapped
        product = gym.make(env_id, product=True)
        w = max(steps_per_second(world, actions) for _ in range(2))
        p = max(steps_per_second(product, actions) for _ in range(2))
        print(f"| {env_id} | {w:,.0f} | {p:,.0f} | {reset_ms(product):.3f} |", flush=True)


if __name__ == "__main__":
    main()
