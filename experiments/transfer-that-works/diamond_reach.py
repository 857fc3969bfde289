"""How far exploration gets on Diamond Mine in MuJoCo: golds held, and how the episode
ended, under uniform random thrust and under the suites' persistent exploration noise
(N(0, 0.6) held, redrawn with probability 0.1 per step) with no policy under it.

    python experiments/transfer-that-works/diamond_reach.py --episodes 200
"""

from __future__ import annotations

import argparse
from collections import Counter

import gymnasium as gym
import numpy as np

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.noise import make_action_noise
from craftsuite.suites import TD3_REGIME

SUITE_NOISE = TD3_REGIME["td3_hyperparameters"]["action_noise"]


def explore(episodes: int, persistent: bool, seed: int = 0) -> tuple[Counter, Counter]:
    """(golds held at the end, how episodes ended) over ``episodes`` episodes."""
    env = gym.make("CraftSuite/DiamondMine-Cont-v0")
    rng = np.random.default_rng(seed)
    noise = make_action_noise(SUITE_NOISE, dim=2, seed=seed)  # the students' own noise process
    golds, endings = Counter(), Counter()
    gold = env.unwrapped.task.inventory.index("gold")
    for episode in range(episodes):
        env.reset(seed=seed + episode)
        noise.reset()
        while True:
            action = noise() if persistent else rng.uniform(-1, 1, 2)
            _, _, terminated, truncated, info = env.step(np.clip(action, -1, 1).astype(np.float32))
            if terminated or truncated:
                break
        golds[int(env.unwrapped.inventory_counts[gold])] += 1
        endings["won" if info.get("is_success") else "objective broken" if terminated else "time limit"] += 1
    return golds, endings


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=200)
    args = parser.parse_args()
    for name, persistent in (("uniform random thrust", False), (f"the suites' noise {SUITE_NOISE}", True)):
        golds, endings = explore(args.episodes, persistent)
        print(f"{name}: golds held at the end {dict(sorted(golds.items()))}; endings {dict(endings)}")


if __name__ == "__main__":
    main()
