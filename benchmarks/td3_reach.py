"""Can a TD3 student learn to reach one object in the MuJoCo world at all? A calibration task.

Usage: python benchmarks/td3_reach.py [--steps 30000] [--seeds 0 1] [--workers 2]

``Reach``: one wood in the 7 x 7 arena, objective ``F wood`` (+100 on touching it, which
ends the episode; -0.1 per step), so the only skill to learn is driving to a point given
its offset in the observation. TD3 from scratch (the quick suite's [256, 256] network,
package defaults otherwise) is trained under four settings, one process each:

* control period: the registered default (frame skip 2, 0.05 s, 1,000-step episodes)
  or coarser (frame skip 5, 0.125 s, 400-step episodes);
* exploration: the package's N(0, 0.3) drawn anew each step, or the persistent noise of
  ``_students.py`` (one N(0, 0.6) draw held, redrawn with probability 0.05).

Prints, per setting and seed, greedy success over 10 fresh episodes every 5,000 steps and
the training episodes won, then a summary of greedy success at the last step.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
from itertools import product

import numpy as np
from _students import PersistentActionNoise, train_with_reports  # benchmarks/ is on sys.path as a script

# The task as data, as tasks/*.toml would hold it.
REACH = {"name": "Reach", "formula": "F wood", "propositions": {"wood": {"obtained": "wood"}},
         "items": {"wood": {"count": 1}}, "rewards": {"step": -0.1, "completion": 100.0}}
HORIZONS = {"frame skip 2, 1,000 steps": {},
            "frame skip 5, 400 steps": {"frame_skip": 5, "max_episode_steps": 400}}
NOISES = ("N(0, 0.3) per step", "persistent N(0, 0.6), p 0.05")


def register_reach() -> None:
    import craftsuite
    from craftsuite.spec import load_spec

    craftsuite.register_task(load_spec(REACH, name_hint="td3_reach.py"))


def run(setting: tuple[str, str, int], steps: int) -> list[dict]:
    horizon, noise, seed = setting
    register_reach()  # here, in the worker that makes the envs (whatever the start method)
    kwargs = {"policy_kwargs": {"net_arch": [256, 256]}}
    if noise != NOISES[0]:
        kwargs["action_noise"] = PersistentActionNoise(0.6, 0.05, seed=seed)
    return train_with_reports("td3", None, task="Reach", seed=seed, steps=steps, every=5_000,
                              env_kwargs=HORIZONS[horizon] or None, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30_000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    settings = list(product(HORIZONS, NOISES, args.seeds))
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run, settings, [args.steps] * len(settings)))
    print("\n| control period, episode | exploration noise | seed | greedy success every 5,000 steps | training wins / episodes |")
    print("|---|---|---|---|---|")
    for (horizon, noise, seed), rows in zip(settings, results):
        curve = " ".join(f"{r['eval_success']:.1f}" for r in rows)
        print(f"| {horizon} | {noise} | {seed} | {curve} | {rows[-1]['train_wins']} / {rows[-1]['train_episodes']} |")
    print(f"\n| control period, episode | exploration noise | greedy success at {args.steps:,} (mean over seeds {args.seeds}) |")
    print("|---|---|---|")
    for horizon, noise in product(HORIZONS, NOISES):
        last = [rows[-1]["eval_success"] for (h, n, _), rows in zip(settings, results) if (h, n) == (horizon, noise)]
        print(f"| {horizon} | {noise} | {np.mean(last):.2f} ({', '.join(f'{x:.1f}' for x in last)}) |")


if __name__ == "__main__":
    main()
