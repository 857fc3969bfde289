"""Can a TD3 student learn to reach one object in the MuJoCo world at all? A calibration task.

Usage: python experiments/td3-horizon-exploration-reach/td3_reach.py [--steps 30000] [--seeds 0 1] [--scenes one]
       [--frame-skips 2 5] [--noises white persistent] [--resample 0.05] [--hyper JSON] [--workers 2]

``Reach``: one wood in the 7 x 7 arena, objective ``F wood`` (+100 on touching it, which
ends the episode; -0.1 per step), so the only skill to learn is driving to a point given
its offset in the observation. ``--scenes three`` puts three woods in the arena (any one
will do), ``--scenes craftsman`` Blind Craftsman's objects (three woods, the factory, home
in a corner) with the same objective: is choosing among object slots, or ignoring some,
what a Blind Craftsman student cannot learn? ``--scenes tool`` is the next rung: the same
objects, +100 for the first tool (a wood, then the factory). TD3 from scratch (the quick
suite's [256, 256] network, package defaults otherwise) is trained under each chosen
setting (four by default), one process each:

* control period: the registered default (frame skip 2, 0.05 s, 1,000-step episodes),
  coarser (frame skip 5, 0.125 s, 400-step episodes) or about the grid teacher's step
  (frame skip 10, 0.25 s, 200-step episodes; ``--frame-skips 10``);
* exploration: the package's N(0, 0.3) drawn anew each step (``white``), or the
  persistent noise of ``_students.py`` (one N(0, 0.6) draw held, redrawn with probability
  ``--resample``).
``--hyper`` adds ``make_agent`` keywords, e.g. ``{"prioritized": false}``. (An ``--env``
option once passed ``offsets="sqrt"`` to the world, a square-root scale of the object
offsets; it did not raise greedy success, and the world no longer has that keyword.)

Prints, per setting and seed, greedy success and rewarded events (a wood, a completion) per
episode over 10 fresh episodes every 5,000 steps (so ``--steps`` of at least 5,000) and
the training episodes won, then a summary of greedy success at the last step.
"""

from __future__ import annotations

import argparse
import json
from concurrent.futures import ProcessPoolExecutor
from itertools import product

import numpy as np
from _students import train_with_reports  # this folder is on sys.path when run as a script

# The task as data, as tasks/*.toml would hold it, in four scenes: "three" and "craftsman"
# keep the objective ``F wood`` and add what a Blind Craftsman student sees besides (more woods
# to choose from, the factory and home as object slots to ignore); "tool" adds a stage.
REACH = {"name": "Reach", "formula": "F wood", "propositions": {"wood": {"obtained": "wood"}},
         "items": {"wood": {"count": 1}}, "rewards": {"step": -0.1, "completion": 100.0}}
SCENES = {
    "one": REACH,
    "three": {**REACH, "name": "Reach3", "items": {"wood": {"count": 3}}},
    "craftsman": {**REACH, "name": "ReachCraftsman", "items": {"wood": {"count": 3, "capacity": 2}},
                  "places": {"factory": {}, "home": {"placement": "corner"}}},
    # two stages: a wood, then the factory (Blind Craftsman's first tool), +100 on the tool
    "tool": {**REACH, "name": "ReachTool", "formula": "F tools1",
             "propositions": {"tools1": {"at_least": {"tools": 1}}},
             "items": {"wood": {"count": 3, "capacity": 2}},
             "places": {"factory": {}, "home": {"placement": "corner"}},
             "recipes": [{"at": "factory", "consume": {"wood": 1}, "produce": {"tools": 1}, "repeat": True}]},
}
# frame skip -> (label, gymnasium.make keywords); every limit is 50 s of simulated time
HORIZONS = {2: ("frame skip 2, 1,000 steps", {"frame_skip": 2, "max_episode_steps": 1000}),
            5: ("frame skip 5, 400 steps", {"frame_skip": 5, "max_episode_steps": 400}),
            10: ("frame skip 10, 200 steps", {"frame_skip": 10, "max_episode_steps": 200})}
NOISES = ("white", "persistent")


def register_reach(scene: str, entry_point: str | None = None) -> str:
    """Register the scene's task (in this process) and return its name. ``entry_point``
    ("module:function", taking the MuJoCo ids' keywords) makes its MuJoCo id's envs in
    place of craftsuite's, e.g. to wrap the world."""
    import craftsuite
    from craftsuite.spec import load_spec

    spec = SCENES[scene]
    craftsuite.register_task(load_spec(spec, name_hint="td3_reach.py"))
    if entry_point is not None:
        import gymnasium as gym

        env_id = f"CraftSuite/{spec['name']}-Cont-v0"
        registered = gym.spec(env_id)
        del gym.registry[env_id]
        # no vector entry point: every env of the id goes through entry_point
        gym.register(id=env_id, entry_point=entry_point, kwargs=registered.kwargs,
                     max_episode_steps=registered.max_episode_steps)
    return spec["name"]


def noise_label(noise: str, resample: float) -> str:
    return "N(0, 0.3) per step" if noise == "white" else f"persistent N(0, 0.6), p {resample:g}"


def run(setting: tuple[str, int, str, int], steps: int, resample: float, hyper: dict,
        entry_point: str | None = None) -> list[dict]:
    scene, skip, noise, seed = setting
    task = register_reach(scene, entry_point)  # here, in the worker that makes the envs (whatever the start method)
    kwargs = {"policy_kwargs": {"net_arch": [256, 256]}, **hyper}
    if noise == "persistent":
        kwargs["action_noise"] = {"type": "persistent", "sigma": 0.6, "resample": resample}
    return train_with_reports("td3", None, task=task, seed=seed, steps=steps, every=5_000,
                              env_kwargs=HORIZONS[skip][1], **kwargs)


def main(argv=None, entry_point: str | None = None):
    """``entry_point``: what makes the MuJoCo envs instead of craftsuite (``register_reach``)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=30_000)
    parser.add_argument("--scenes", nargs="+", choices=list(SCENES), default=["one"],
                        help="one wood; three woods; Blind Craftsman's objects (three woods, factory, home); "
                             "those objects with +100 for the first tool instead of a wood")
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1])
    parser.add_argument("--frame-skips", type=int, nargs="+", choices=sorted(HORIZONS), default=[2, 5])
    parser.add_argument("--noises", nargs="+", choices=NOISES, default=list(NOISES))
    parser.add_argument("--resample", type=float, default=0.05, help="the persistent noise's redraw probability")
    parser.add_argument("--hyper", type=json.loads, default={}, help="make_agent keywords as JSON")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if args.steps < 5_000:
        parser.error("--steps must be at least 5000 (one report every 5,000 steps)")
    settings = list(product(args.scenes, args.frame_skips, args.noises, args.seeds))
    n = len(settings)
    with ProcessPoolExecutor(args.workers) as pool:
        results = list(pool.map(run, settings, [args.steps] * n, [args.resample] * n, [args.hyper] * n,
                                    [entry_point] * n))
    if args.hyper:
        print(f"\nmake_agent keywords: {json.dumps(args.hyper)}")
    print("\n| scene | control period, episode | exploration noise | seed | greedy success every 5,000 steps "
          "| events / greedy episode | training wins / episodes |")
    print("|---|---|---|---|---|---|---|")
    for (scene, skip, noise, seed), rows in zip(settings, results):
        curve = " ".join(f"{r['eval_success']:.1f}" for r in rows)
        events = " ".join(f"{r['eval_events']:.1f}" for r in rows)
        print(f"| {scene} | {HORIZONS[skip][0]} | {noise_label(noise, args.resample)} | {seed} | {curve} | {events} "
              f"| {rows[-1]['train_wins']} / {rows[-1]['train_episodes']} |")
    print("\n| scene | control period, episode | exploration noise "
          f"| greedy success at {args.steps:,} (mean over seeds {args.seeds}) |")
    print("|---|---|---|---|")
    for setting in product(args.scenes, args.frame_skips, args.noises):
        last = [rows[-1]["eval_success"] for s, rows in zip(settings, results) if s[:3] == setting]
        scene, skip, noise = setting
        print(f"| {scene} | {HORIZONS[skip][0]} | {noise_label(noise, args.resample)} "
              f"| {np.mean(last):.2f} ({', '.join(f'{x:.1f}' for x in last)}) |")


if __name__ == "__main__":
    main()
