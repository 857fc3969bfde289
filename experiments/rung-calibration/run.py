"""TD3 from scratch in MuJoCo on the middle rungs between FirstTool and the paper's tasks,
in the standard suite's TD3 regime, 5 seeds as one population per rung: where does greedy
success land at a medium-rung budget?

    python experiments/rung-calibration/run.py --steps 800000 --out experiments/rung-calibration/results
    python experiments/rung-calibration/run.py --check   # the scripted policy and random play per rung
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.configs import StudentConfig
from craftsuite.ids import cont_id
from craftsuite.episodes import rollout
from craftsuite.scripted import scripted_policy
from craftsuite.suites import SUITES
from craftsuite.task_registry import ladder

RUNGS = tuple(spec.name for spec in ladder("middle"))  # KeySwordDragon, ToolHome, TwoToolsHome


def check(episodes: int = 50) -> None:
    """Each rung's completion by its scripted policy and by uniformly random actions."""
    for task in RUNGS:
        env_id = cont_id(task)
        env = gym.make(env_id)
        policy = scripted_policy(env.unwrapped)
        scripted = rollout(env, lambda obs: policy(), episodes, seed=0)
        rng = np.random.default_rng(0)
        random = rollout(env, lambda obs: rng.uniform(-1, 1, 2).astype(np.float32), episodes, seed=0)
        print(f"{env_id}: scripted {np.mean([e.success for e in scripted]):.2f} "
              f"({np.mean([e.length for e in scripted]):.0f} decisions), "
              f"random {np.mean([e.success for e in random]):.2f}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=800_000, help="transitions per run")
    parser.add_argument("--seeds", type=int, default=5)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results")
    parser.add_argument("--check", action="store_true", help="only the scripted and random completion")
    parser.add_argument("--rungs", nargs="+", choices=RUNGS, help="only these rungs (default: every one)")
    args = parser.parse_args(argv)
    if args.check:
        return check()
    from craftsuite.suite_runner import run_students

    standard = SUITES["standard"]
    configs = []
    for task in args.rungs or RUNGS:
        for seed in range(args.seeds):
            configs.append(StudentConfig(task=task, method="td3", world="Cont", seed=seed, steps=args.steps,
                                         eval_every=args.steps // 20, eval_episodes=standard.eval_episodes,
                                         hyperparameters=dict(standard.td3_hyperparameters),
                                         n_envs=standard.td3_n_envs, engine="population"))
    run_students(configs, args.out / "students", workers=args.workers)
    print(" ".join(sys.argv))


if __name__ == "__main__":
    main()
