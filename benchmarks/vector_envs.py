"""Natively vectorized worlds beside gymnasium's SyncVectorEnv, 32 envs, single process.

Usage: python benchmarks/vector_envs.py [--envs N] [--steps N] [--page PATH | --no-page]

Targets: the native vector env (``gymnasium.make_vec(id, vectorization_mode="vector_entry_point",
product=True)``) at least 3x the steps/s of ``SyncVectorEnv`` over ``gymnasium.make(id,
product=True)`` (``vectorization_mode="sync"``) on the grid and the kinematic board, 1.5x on
the MuJoCo world (whose physics, ``frame_skip`` calls of ``mj_step`` per env and action, is
the same work in both and about half of a single env's step). Steps/s counts env steps (one
vector step of 32 envs is 32). Both run gymnasium's default NEXT_STEP
autoreset at the ids' registered episode lengths; actions are drawn in advance so that
sampling is not timed; best of 2 runs.

Why the native one is faster: moves, board and distance checks, observations and the
automaton step are numpy over all envs (the MuJoCo world: one ``MjModel``, each env's
``MjData`` stepped in a loop, the rest as arrays); only envs that touch an object run the
task's rules in Python; infos are built as arrays, not merged env by env.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym

import craftsuite  # noqa: F401  (registers the ids)
from _page import Report, add_page_argument

TARGETS = {"CraftSuite/BlindCraftsman-Grid10-v0": 3.0, "CraftSuite/BlindCraftsman-Kinematic-v0": 3.0,
           "CraftSuite/BlindCraftsman-Cont-v0": 1.5}


def vector_steps_per_second(envs, actions) -> float:
    """Env steps/s of a vector env over pre-drawn batches of actions (it autoresets)."""
    envs.reset(seed=0)
    t = time.perf_counter()
    for a in actions:
        envs.step(a)
    return len(actions) * envs.num_envs / (time.perf_counter() - t)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--envs", type=int, default=32)
    parser.add_argument("--steps", type=int, default=2_000, help="vector steps per run")
    add_page_argument(parser)
    args = parser.parse_args()
    report = Report()
    report("| id | envs | SyncVectorEnv steps/s | native steps/s | speed-up | target | target met |")
    report("|---|---|---|---|---|---|---|")
    for env_id, target in TARGETS.items():
        speeds = {}
        for mode in ("sync", "vector_entry_point"):
            envs = gym.make_vec(env_id, num_envs=args.envs, vectorization_mode=mode, product=True)
            envs.action_space.seed(0)
            actions = [envs.action_space.sample() for _ in range(args.steps)]
            speeds[mode] = max(vector_steps_per_second(envs, actions) for _ in range(2))
            envs.close()
        ratio = speeds["vector_entry_point"] / speeds["sync"]
        report(f"| {env_id} | {args.envs} | {speeds['sync']:,.0f} | {speeds['vector_entry_point']:,.0f} | "
               f"{ratio:.1f}x | >= {target:g}x | {'yes' if ratio >= target else '**no**'} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
