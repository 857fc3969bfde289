"""TD3 students on a shorter horizon: does a coarser control period let them learn?

Usage: python experiments/td3-horizon-exploration-reach/td3_horizon.py TABLE [--task T] [--frame-skip K] [--limit N]
       [--steps N] [--seed S] [--methods td3 td3-dynamic]

Trains each method (one process per method, one torch thread each) on
``CraftSuite/<task>-Cont-v0`` made with ``frame_skip=K`` (physics steps of 0.025 s per
action; the world's default is 2) and a time limit of N steps, with a [256, 256]
network (the quick suite's before 2026-11-22) and otherwise the package defaults. Every 5,000 steps it prints the
greedy success and return over 10 fresh episodes and the training episodes completed so
far. TABLE is a teacher's ``table.npz`` (``craftsuite teacher``) for the dynamic method.
First it prints how many steps the scripted policy needs at this frame skip and at the
default (mean over 10 episodes), i.e. how much the horizon shrinks, and how many rewarded
events a persistent random walk (a new uniform action with probability 0.1 per step) meets
per 1,000-step episode at the default (30 episodes): what exploration alone finds.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

from _students import train_with_reports  # this folder is on sys.path when run as a script
from random_walk import random_walk


def run(method: str, args) -> list[dict]:
    return train_with_reports(method, args.table, task=args.task, seed=args.seed, steps=args.steps, every=5_000,
                              env_kwargs={"frame_skip": args.frame_skip, "max_episode_steps": args.limit},
                              policy_kwargs={"net_arch": [256, 256]})


def scripted_steps(task: str, frame_skip: int, episodes: int = 10) -> float:
    import gymnasium as gym

    import craftsuite  # noqa: F401
    from craftsuite.episodes import rollout
    from craftsuite.scripted import scripted_policy

    env = gym.make(f"CraftSuite/{task}-Cont-v0", frame_skip=frame_skip, max_episode_steps=5_000)
    policy = scripted_policy(env)
    return sum(rollout(env, policy, 1, s)[0].length for s in range(episodes)) / episodes


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", help="a teacher's table.npz")
    parser.add_argument("--task", default="BlindCraftsman")
    parser.add_argument("--frame-skip", type=int, default=5)
    parser.add_argument("--limit", type=int, default=400, help="time limit in steps")
    parser.add_argument("--steps", type=int, default=100_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--methods", nargs="+", default=["td3", "td3-dynamic"])
    args = parser.parse_args()
    for skip in sorted({2, args.frame_skip}):
        print(f"scripted policy, frame_skip {skip}: {scripted_steps(args.task, skip):.1f} steps per episode")
    walk = random_walk(args.task, episodes=30)
    print(f"persistent random walk: {walk['rewarded_events']:.2f} rewarded events per 1,000-step episode")
    with ProcessPoolExecutor(len(args.methods)) as pool:
        results = list(pool.map(run, args.methods, [args] * len(args.methods)))
    print(f"\n{args.task}, frame_skip {args.frame_skip}, limit {args.limit}, seed {args.seed}")
    print("| method | steps | greedy success | greedy return | training episodes | training wins |")
    print("|---|---|---|---|---|---|")
    for rows in results:
        last = rows[-1]
        print(f"| {last['method']} | {last['step']:,} | {last['eval_success']:.2f} | {last['eval_return']} "
              f"| {last['train_episodes']} | {last['train_wins']} |")


if __name__ == "__main__":
    main()
