"""MuJoCo env throughput, single process, side by side with its references.

Usage: python benchmarks/cont_steps.py [--steps N]

Per task, in one run: raw ``mujoco.mj_step`` on the same compiled model (as many calls as
one env step makes: the registered world's frame skip), the bare ``ContinuousWorldEnv``, and
``gymnasium.make(id, product=True)`` as users get it; then dm_control's ``point_mass``
through ``dm_env`` as the outside reference. Also ``reset()`` time and render frames/s at
240x240 (OSMesa unless MUJOCO_GL says otherwise).
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import craftsuite  # chooses MUJOCO_GL before mujoco is imported
import mujoco
from _timing import reset_ms, steps_per_second


def raw_steps(model, frame_skip, n) -> float:
    data = mujoco.MjData(model)
    t = time.perf_counter()
    for _ in range(n):
        for _ in range(frame_skip):
            mujoco.mj_step(model, data)
    return n / (time.perf_counter() - t)


def dm_control_point_mass(n) -> float:
    from dm_control import suite

    env = suite.load("point_mass", "easy", task_kwargs={"random": 0})
    spec = env.action_spec()
    actions = np.random.default_rng(0).uniform(spec.minimum, spec.maximum, (n, spec.shape[0]))
    env.reset()
    t = time.perf_counter()
    for a in actions:
        if env.step(a).last():
            env.reset()
    return n / (time.perf_counter() - t)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=50_000)
    parser.add_argument("--no-render", action="store_true")
    args = parser.parse_args()
    actions = list(np.random.default_rng(0).uniform(-1, 1, (args.steps, 2)).astype(np.float32))
    print("| id | raw mj_step x frame skip /s | world steps/s | product (make) steps/s | reset ms | render fps 240x240 |")
    print("|---|---|---|---|---|---|")
    for env_id in [i for i in craftsuite.registered_ids() if "-Cont-" in i]:
        product = gym.make(env_id, product=True, render_mode="rgb_array")
        world = product.unwrapped
        raw = raw_steps(world.model, world.frame_skip, args.steps)
        w = steps_per_second(world, actions)
        p = max(steps_per_second(product, actions) for _ in range(2))
        reset = reset_ms(product)
        fps = "-"
        if not args.no_render:
            product.render()
            t = time.perf_counter()
            for _ in range(100):
                product.render()
            fps = f"{100 / (time.perf_counter() - t):.0f}"
        product.close()
        print(f"| {env_id} | {raw:,.0f} | {w:,.0f} | {p:,.0f} | {reset:.3f} | {fps} |", flush=True)
    print(f"\ndm_control point_mass (easy) via dm_env: {dm_control_point_mass(args.steps):,.0f} steps/s")


if __name__ == "__main__":
    main()
