"""TD3 exploration in the MuJoCo worlds: what the action noise reaches, and students with
a persistent noise.

Usage: python experiments/td3-horizon-exploration-reach/td3_exploration.py TABLE [--task T] [--steps N] [--seed S]
       [--methods td3 td3-dynamic] [--hyper JSON] [--env JSON] [--sigma 0.6] [--resample 0.05]

First, with the actor's output held at zero (what a fresh TD3 actor roughly gives), it
rolls out each noise process for 20 episodes of 1,000 steps and prints, per episode, the
rewarded events (an item or the completion), the steps spent pushing the arena wall and
the span of the agent's path (mean of its x and y extents): the package's default
N(0, 0.3) per step, SB3's Ornstein-Uhlenbeck noise (its defaults, sigma 0.3) and a
persistent noise that holds one N(0, sigma) draw and redraws it with probability
``resample`` per step.

Then it trains each method (one process each, one torch thread) with the persistent noise,
a [256, 256] network (the quick suite's before 2026-11-22) and ``--hyper`` (``make_agent`` keywords, e.g.
``{"learning_rate": 1e-3}``), and prints every 10,000 steps, over 10 fresh greedy episodes,
the success, return, rewarded events and automaton steps (transitions that change its
state: the task's progress) per episode and the violations (the objective broken, which
ends the episode); then the training episodes won and violated so far and the rewarded
events per training episode since the last line. ``--env`` (``gymnasium.make`` keywords,
e.g. ``{"frame_skip": 5, "max_episode_steps": 400}``) changes the students' world, not the
noise rollouts. TABLE is a teacher's ``table.npz``.
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor

import numpy as np
from _students import EVAL_EPISODES, train_with_reports  # this folder is on sys.path as a script

from craftsuite.agents.noise import PersistentActionNoise


def noise_processes(sigma: float, resample: float) -> dict:
    from stable_baselines3.common.noise import NormalActionNoise, OrnsteinUhlenbeckActionNoise

    z = np.zeros(2)
    return {"N(0, 0.3) per step (package default)": lambda s: NormalActionNoise(z, 0.3 * np.ones(2)),
            "Ornstein-Uhlenbeck (SB3 defaults, sigma 0.3)": lambda s: OrnsteinUhlenbeckActionNoise(z, 0.3 * np.ones(2)),
            f"persistent N(0, {sigma}), redrawn w.p. {resample}":
                lambda s: PersistentActionNoise(sigma, resample, seed=s)}


def coverage(task: str, make_noise, episodes: int = 20) -> dict:
    import gymnasium as gym

    import craftsuite  # noqa: F401

    env = gym.make(f"CraftSuite/{task}-Cont-v0", frame_skip=2, max_episode_steps=1000)  # the world it was written for
    events = wall = 0
    spans = []
    for episode in range(episodes):
        np.random.seed(episode)  # SB3's Normal and OU noises draw from numpy's global RNG
        noise = make_noise(episode)
        noise.reset()
        env.reset(seed=episode)
        path, done = [env.unwrapped.agent_position.copy()], False
        while not done:
            _, reward, terminated, truncated, _ = env.step(np.clip(noise(), -1, 1))
            events += reward > -0.05  # more than the step and wall costs
            wall += reward < -0.15  # the step cost and the wall cost together
            path.append(env.unwrapped.agent_position.copy())
            done = terminated or truncated
        spans.append(np.ptp(np.array(path), axis=0).mean())
    env.close()
    return {"events": events / episodes, "wall_steps": wall / episodes, "span": float(np.mean(spans))}


def train(method: str, args) -> list[dict]:
    return train_with_reports(method, args.table, task=args.task, seed=args.seed, steps=args.steps, every=10_000,
                              env_kwargs=args.env or None,
                              action_noise={"type": "persistent", "sigma": args.sigma, "resample": args.resample},
                              **{"policy_kwargs": {"net_arch": [256, 256]}, **args.hyper})


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("table", help="a teacher's table.npz")
    parser.add_argument("--task", default="BlindCraftsman")
    parser.add_argument("--steps", type=int, default=60_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--methods", nargs="+", default=["td3", "td3-dynamic"])
    parser.add_argument("--hyper", type=json.loads, default={}, help="make_agent keywords as JSON")
    parser.add_argument("--env", type=json.loads, default={},
                        help="gymnasium.make keywords for the students' world, as JSON")
    parser.add_argument("--sigma", type=float, default=0.6)
    parser.add_argument("--resample", type=float, default=0.05)
    args = parser.parse_args()
    print(f"{args.task}, actor output held at 0, 20 episodes of 1,000 steps per noise")
    print("| noise | rewarded events / episode | steps at the wall / episode | path span (m) |")
    print("|---|---|---|---|")
    for name, make in noise_processes(args.sigma, args.resample).items():
        c = coverage(args.task, make)
        print(f"| {name} | {c['events']:.2f} | {c['wall_steps']:.0f} | {c['span']:.2f} |", flush=True)
    with ProcessPoolExecutor(len(args.methods)) as pool:
        results = list(pool.map(train, args.methods, [args] * len(args.methods)))
    print(f"\n{args.task}, seed {args.seed}, persistent noise N(0, {args.sigma}) redrawn w.p. "
          f"{args.resample}, hyper {json.dumps(args.hyper)}, env {json.dumps(args.env)}")
    print("| method | step | greedy success | greedy return | events / greedy episode "
          "| automaton steps / greedy episode "
          f"| violations / {EVAL_EPISODES} greedy episodes | training wins | training violations "
          "| events / training episode |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rows in results:
        for r in rows:
            print(f"| {r['method']} | {r['step']:,} | {r['eval_success']:.2f} | {r['eval_return']} "
                  f"| {r['eval_events']:.1f} | {r['eval_edges']:.1f} | {r['eval_violations'] * EVAL_EPISODES:.0f} "
                  f"| {r['train_wins']} "
                  f"| {r['train_violations']} | {r['events_per_episode']} |")


if __name__ == "__main__":
    main()
