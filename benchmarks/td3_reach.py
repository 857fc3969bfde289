"""Can a TD3 student learn to reach one object in the MuJoCo world at all? A calibration task.

Usage: python benchmarks/td3_reach.py [--steps 30000] [--seeds 0 1] [--frame-skips 2 5]
       [--noises white persistent] [--resample 0.05] [--hyper JSON] [--workers 2]

``Reach``: one wood in the 7 x 7 arena, objective ``F wood`` (+100 on touching it, which
ends the episode; -0.1 per step), so the only skill to learn is driving to a point given
its offset in the observation. TD3 from scratch (the quick suite's [256, 256] network,
package defaults otherwise) is trained under each chosen setting (four by default), one
process each:

* control period: the registered default (frame skip 2, 0.05 s, 1,000-step episodes),
  coarser (frame skip 5, 0.125 s, 400-step episodes) or about the grid teacher's step
  (frame skip 10, 0.25 s, 200-step episodes; ``--frame-skips 10``);
* exploration: the package's N(0, 0.3) drawn anew each step (``white``), or the
  persistent noise of ``_students.py`` (one N(0, 0.6) draw held, redrawn with probability
  ``--resample``).
``--hyper`` adds ``make_agent`` keywords, e.g. ``{"prioritized": false}``.

Prints, per setting and seed, greedy success over 10 fresh episodes every 5,000 steps and
the training episodes won, then a summary of greedy success at the last step.
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from itertools import product

import numpy as np
from _students import PersistentActionNoise, train_with_reports  # benchmarks/ is on sys.path as a script

# The task as data, as tasks/*.toml would hold it.
REACH = {"name": "Reach", "formula": "F wood", "propositions": {"wood": {"obtained": "wood"}},
         "items": {"wood": {"count": 1}}, "rewards": {"step": -0.1, "completion": 100.0}}
# frame skip -> (label, gymnasium.make keywords); every limit is 50 s of simulated time
HORIZONS = {2: ("frame skip 2, 1,000 steps", {}),
            5: ("frame skip 5, 400 steps", {"frame_skip": 5, "max_episode_steps": 400}),
            10: ("frame skip 10, 200 steps", {"frame_skip": 10, "max_episode_steps": 200})}
NOISES = ("white", "persistent")


def register_reach() -> None:
    import craftsuite
    from craftsuite.spec import load_spec

    craftsuite.register_task(load_spec(REACH, name_hint="td3_reach.py"))


def noise_label(noise: str, resample: float) -> str:
    return "N(0, 0.3) per step" if noise == "white" else f"persistent N(0, 0.6), p {resample:g}"


def run(setting: tuple[int, str, int], steps: int, resample: float, hyper: dict) -> list[dict]:
    skip, noise, seed = setting
    register_reach()  # here, in the worker that makes the envs (whatever the start method)
    kwargs = {"policy_kwargs": {"net_arch": [256, 256]}, **hyper}
    if noise == "persistent":
        kwargs["action_noise"] = PersistentActionNoise(0.6, resample, seed=seed)
    return train_with_reports("td3", None, task="Reach", seed=seed, steps=steps, every=5_000,
                              env_kwargs=HORIZONS[skip][1] or None, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30_000)
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--frame-skips", type=int, nargs="+", choices=sorted(HORIZONS), default=[2, 5])
    parser.add_argument("--noises", nargs="+", choices=NOISES, default=list(NOISES))
    parser.add_argument("--resample", type=float, default=0.05, help="the persistent noise's redraw probability")
    parser.add_argument("--hyper", type=json.loads, default={}, help="make_agent keywords as JSON")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    settings = list(product(args.frame_skips, args.noises, args.seeds))
    n = len(settings)
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run, settings, [args.steps] * n, [args.resample] * n, [args.hyper] * n))
    if args.hyper:
        print(f"\nmake_agent keywords: {json.dumps(args.hyper)}")
    print("\n| control period, episode | exploration noise | seed | greedy success every 5,000 steps | training wins / episodes |")
    print("|---|---|---|---|---|")
    for (skip, noise, seed), rows in zip(settings, results):
        curve = " ".join(f"{r['eval_success']:.1f}" for r in rows)
        print(f"| {HORIZONS[skip][0]} | {noise_label(noise, args.resample)} | {seed} | {curve} | {rows[-1]['train_wins']} / {rows[-1]['train_episodes']} |")
    print(f"\n| control period, episode | exploration noise | greedy success at {args.steps:,} (mean over seeds {args.seeds}) |")
    print("|---|---|---|")
    for skip, noise in product(args.frame_skips, args.noises):
        last = [rows[-1]["eval_success"] for (k, n, _), rows in zip(settings, results) if (k, n) == (skip, noise)]
        print(f"| {HORIZONS[skip][0]} | {noise_label(noise, args.resample)} | {np.mean(last):.2f} ({', '.join(f'{x:.1f}' for x in last)}) |")


if __name__ == "__main__":
    main()
