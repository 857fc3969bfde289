"""Teachers: env steps and minutes to 90% success per task (7x7 grids, product DQN).

Usage: python benchmarks/teachers.py [--tasks ...] [--max-steps N] [--seed S] [--out DIR]

Trains CraftSuite's teacher (dueling double DQN with prioritized replay over the product
MDP) and every ``--eval-every`` env steps evaluates the greedy policy on ``--episodes``
episodes with fresh seeds (never used in training). Stops at the first evaluation with
>= 90% success, saves the teacher and its distilled table in ``--out``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import craftsuite  # noqa: F401
from craftsuite.agents.methods import distill_from_replay, make_agent


def success_rate(agent, env_id: str, episodes: int, seed: int) -> float:
    env = gym.make(env_id, product=True)
    wins = 0
    for i in range(episodes):
        obs, _ = env.reset(seed=seed + i)
        done = False
        while not done:
            action, _ = agent.predict(obs, deterministic=True)
            obs, _, term, trunc, info = env.step(int(action))
            done = term or trunc
        wins += bool(info["is_success"])
    return wins / episodes


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", nargs="*", default=["BlindCraftsman", "DungeonQuest", "DiamondMine"])
    parser.add_argument("--max-steps", type=int, default=300_000)
    parser.add_argument("--eval-every", type=int, default=10_000)
    parser.add_argument("--episodes", type=int, default=50)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="out/teachers")
    args = parser.parse_args()
    import torch
    torch.set_num_threads(1)

    print("| task | env steps to >= 90% success | minutes | success (fresh seeds) |")
    print("|---|---|---|---|")
    for task in args.tasks:
        env_id = f"CraftSuite/{task}-Grid7-v0"
        agent = make_agent("product-dqn", env_id, seed=args.seed, n_envs=4)
        start, rate, steps = time.perf_counter(), 0.0, 0
        while steps < args.max_steps:
            agent.learn(args.eval_every, reset_num_timesteps=False)
            steps = agent.num_timesteps
            rate = success_rate(agent, env_id, args.episodes, seed=10_000_000 + steps)
            print(f"  {task}: {steps} steps, success {rate:.2f}", flush=True)
            if rate >= 0.9:
                break
        minutes = (time.perf_counter() - start) / 60
        out = Path(args.out)
        agent.save(out / f"{task}-teacher.zip")
        distill_from_replay(agent).save(out / f"{task}-dynamic.npz")
        reached = steps if rate >= 0.9 else f"not within {args.max_steps:,}"
        print(f"| {task} | {reached} | {minutes:.1f} | {rate:.2f} |", flush=True)


if __name__ == "__main__":
    main()
