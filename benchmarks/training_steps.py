"""Training throughput: distilled students beside plain SB3, same network and settings.

Usage: python benchmarks/training_steps.py [--dqn-steps N] [--td3-steps N] [--repeats N] [--page PATH | --no-page]

Target: distillation costs at most 5% of the training speed (ratio >= 0.95). One run, one
process, one torch thread, side by side, on the same product env:
* plain SB3 DQN / TD3;
* the distilled student with plain SB3's network and settings (uniform replay; for DQN no
  dueling head, no double target): the headline ratio, distillation's own cost;
* CraftSuite's full agent without distillation (prioritized replay, and for DQN the
  dueling head and double target) and with it (``dynamic`` / ``td3-dynamic``).

A static table stands in for a teacher's: the cost per step is the same (one table
lookup per sampled transition). Each configuration is built afresh and timed
``--repeats`` times, interleaved with the others; the best rate counts (single runs on
this machine vary by about 10% with order and warm-up). The networks are the package's
defaults (DQN [64, 64] on BlindCraftsman-Grid10, TD3 [400, 300] on BlindCraftsman-Cont).
DQN takes one update per transition (``train_freq=1``) since 2026-11-23; figures from
before, at ``train_freq=4``, were about four times higher and their ratio nearer 1, since
the update, where distillation's lookup lives, was a smaller share of each step.
"""

from __future__ import annotations

import argparse
import time

from stable_baselines3 import DQN, TD3
from stable_baselines3.common.env_util import make_vec_env

import craftsuite  # noqa: F401
from craftsuite.agents import static_distillation
from craftsuite.agents.factory import make_agent
from craftsuite.agents.noise import make_action_noise
from craftsuite.hyperparameters import DQN_DEFAULTS, TD3_DEFAULTS
from _page import Report, add_page_argument  # benchmarks/ is on sys.path as a script

GRID, CONT = "CraftSuite/BlindCraftsman-Grid10-v0", "CraftSuite/BlindCraftsman-Cont-v0"
TARGET_RATIO = 0.95  # distilled over undistilled steps/s


def rate(agent, steps) -> float:
    t = time.perf_counter()
    agent.learn(steps)
    return steps / (time.perf_counter() - t)


def plain(defaults: dict) -> dict:
    """The package's defaults as plain SB3 takes them (TD3's noise is a spec there), with
    the fused Adam that make_agent gives its agents, so the ratio is distillation's alone."""
    policy_kwargs = {**defaults.get("policy_kwargs", {}), "optimizer_kwargs": {"fused": True}}
    if isinstance(defaults.get("action_noise"), dict):
        return {**defaults, "action_noise": make_action_noise(defaults["action_noise"], 2),
                "policy_kwargs": policy_kwargs}
    return {**defaults, "policy_kwargs": policy_kwargs}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dqn-steps", type=int, default=10_000)
    parser.add_argument("--td3-steps", type=int, default=3_000)
    parser.add_argument("--repeats", type=int, default=3)
    add_page_argument(parser)
    args = parser.parse_args()
    import torch
    torch.set_num_threads(1)

    table = static_distillation(craftsuite.tasks()["BlindCraftsman"].automaton)
    rows = []
    for name, world, steps, plain_cls, defaults, product, distilled in (
        ("DQN", GRID, args.dqn_steps, DQN, DQN_DEFAULTS, "product-dqn", "dynamic"),
        ("TD3", CONT, args.td3_steps, TD3, TD3_DEFAULTS, "product-td3", "td3-dynamic"),
    ):
        if steps == 0:
            continue
        same = dict(prioritized=False) | (dict(dueling=False, double=False) if name == "DQN" else {})
        builders = [
            lambda: plain_cls("MlpPolicy", make_vec_env(world, n_envs=1, seed=0, env_kwargs={"product": True}),
                              seed=0, **plain(defaults)),
            lambda: make_agent(distilled, world, seed=0, table=table, **same),
            lambda: make_agent(product, world, seed=0),
            lambda: make_agent(distilled, world, seed=0, table=table),
        ]
        best = [0.0] * len(builders)
        for _ in range(args.repeats):
            for i, build in enumerate(builders):
                best[i] = max(best[i], rate(build(), steps))
        rows.append((name, world, steps, *best))
    report = Report()
    report("| algorithm | env | steps | plain SB3 steps/s | distilled, SB3 settings | "
           f"ratio (target >= {TARGET_RATIO}) | "
           "full agent | full agent, distilled | ratio | targets met |")
    report("|---|---|---|---|---|---|---|---|---|---|")
    for name, world, steps, sb3, student, full, full_dist in rows:  # (``plain`` names the helper above)
        met = min(student / sb3, full_dist / full) >= TARGET_RATIO
        report(f"| {name} | {world} | {steps:,} | {sb3:,.0f} | {student:,.0f} | {student / sb3:.2f} | "
               f"{full:,.0f} | {full_dist:,.0f} | {full_dist / full:.2f} | {'yes' if met else '**no**'} |")
    report.save(__file__, __doc__, args)


if __name__ == "__main__":
    main()
