"""MuJoCo env throughput, single process, side by side with its references.

Usage: python benchmarks/cont_steps.py [--steps N] [--no-render] [--page PATH | --no-page]

Targets: at least 25,000 steps/s with the product wrapper in the fine-control world
(``frame_skip=2``, 0.05 s an action: 1,250 simulated seconds per second), reset within
1 ms, at least 60 frames/s at 240x240. Per task, in one run: raw ``mujoco.mj_step`` on the
same compiled model (as many calls as one step of the registered world makes: its frame
skip), the bare ``ContinuousWorldEnv``, and ``gymnasium.make(id, product=True)`` as users
get it (best of 2), in the registered world and at ``frame_skip=2``; then dm_control's
``point_mass`` through ``dm_env`` as the outside reference. Also ``reset()`` time over 500
seeds and render frames/s at 240x240 (OSMesa, software, unless MUJOCO_GL says otherwise).

An env step spends about as long in Python (distances to every object in one numpy call,
labels only on steps that touch something) as in MuJoCo; tasks with many objects (Diamond
Mine's 43 bodies) make ``mj_step`` itself slower.
"""

from __future__ import annotations

import argparse
import time

import gymnasium as gym
import numpy as np

import craftsuite  # chooses MUJOCO_GL before mujoco is imported
import mujoco
from _page import Report, add_page_argument
from _timing import reset_ms, steps_per_second

FINE_SKIP = 2  # the fine-control world the step-rate target is stated for
TARGET_STEPS, TARGET_RESET_MS, TARGET_FPS = 25_000, 1.0, 60


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
    add_page_argument(parser)
    args = parser.parse_args()
    actions = list(np.random.default_rng(0).uniform(-1, 1, (args.steps, 2)).astype(np.float32))
    report = Report()
    report(f"| id | raw mj_step x frame skip /s | world steps/s | product (make) steps/s | product steps/s at "
           f"frame_skip {FINE_SKIP} (target >= {TARGET_STEPS:,}) | reset ms (target <= {TARGET_RESET_MS:g}) "
           f"| render fps 240x240 (target >= {TARGET_FPS}) | targets met |")
    report("|---|---|---|---|---|---|---|---|")
    for env_id in [i for i in craftsuite.registered_ids() if "-Cont-" in i]:
        product = gym.make(env_id, product=True, render_mode="rgb_array")
        world = product.unwrapped
        raw = raw_steps(world.model, world.frame_skip, args.steps)
        w = steps_per_second(world, actions)
        p = max(steps_per_second(product, actions) for _ in range(2))
        reset = reset_ms(product)
        fps = None
        if not args.no_render:
            product.render()
            t = time.perf_counter()
            for _ in range(100):
                product.render()
            fps = 100 / (time.perf_counter() - t)
        product.close()
        fine_env = gym.make(env_id, product=True, frame_skip=FINE_SKIP, max_episode_steps=1000)
        fine = max(steps_per_second(fine_env, actions) for _ in range(2))
        fine_env.close()
        met = fine >= TARGET_STEPS and reset <= TARGET_RESET_MS and (fps is None or fps >= TARGET_FPS)
        report(f"| {env_id} | {raw:,.0f} | {w:,.0f} | {p:,.0f} | {fine:,.0f} | {reset:.3f} "
               f"| {'-' if fps is None else f'{fps:.0f}'} | {'yes' if met else '**no**'} |")
    report(f"\ndm_control point_mass (easy) via dm_env, the outside reference: "
           f"{dm_control_point_mass(args.steps):,.0f} steps/s")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
