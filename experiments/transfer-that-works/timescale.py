"""How many steps one automaton edge takes in each world, at the optimum: the scripted
policy's steps per change of automaton state, on the teacher's 7x7 grid, the students'
10x10 grid and the MuJoCo world. Their ratio is the time-scale conversion that re-discounting
the teacher's values would use.

    python experiments/transfer-that-works/timescale.py --episodes 20
"""

from __future__ import annotations

import argparse

import gymnasium as gym

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.scripted import scripted_policy

TASKS = ("BlindCraftsman", "DungeonQuest", "DiamondMine")
WORLDS = ("Grid7", "Grid10", "Cont")


def steps_per_edge(env_id: str, episodes: int) -> tuple[float, float, int]:
    """(steps per automaton edge, steps per episode, episodes won) of the scripted policy."""
    env = gym.make(env_id)
    policy = scripted_policy(env)
    steps = edges = wins = 0
    for seed in range(episodes):
        obs, info = env.reset(seed=seed)
        while True:
            obs, _, terminated, truncated, info = env.step(policy(obs))
            w, _, w_next = info["automaton_transition"]
            steps, edges = steps + 1, edges + (w != w_next)
            if terminated or truncated:
                wins += bool(info.get("is_success", False))
                break
    return steps / max(edges, 1), steps / episodes, wins


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--episodes", type=int, default=20)
    args = parser.parse_args()
    print("| task | " + " | ".join(f"{w} steps/edge" for w in WORLDS) + " | Grid10 / Grid7 | Cont / Grid7 |")
    print("|---" * (len(WORLDS) + 3) + "|")
    for task in TASKS:
        per = {w: steps_per_edge(f"CraftSuite/{task}-{w}-v0", args.episodes) for w in WORLDS}
        cells = [f"{s:.2f} ({won}/{args.episodes} won, {n:.0f} steps)" for s, n, won in per.values()]
        print(f"| {task} | " + " | ".join(cells) + f" | {per['Grid10'][0] / per['Grid7'][0]:.2f} | "
              f"{per['Cont'][0] / per['Grid7'][0]:.2f} |")


if __name__ == "__main__":
    main()
