"""TD3 from scratch in MuJoCo on candidate rungs between FirstTool and the paper's tasks,
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

import craftsuite
from craftsuite.configs import StudentConfig
from craftsuite.ids import cont_id, parse_id
from craftsuite.rollouts import rollout
from craftsuite.scripted import scripted_policy
from craftsuite.suites import SUITES

SPECS = sorted((Path(__file__).parent / "specs").glob("*.toml"))


def check(episodes: int = 50) -> None:
    """Each rung's completion by its scripted policy and by uniformly random actions."""
    for path in SPECS:
        env_id = cont_id(parse_id(craftsuite.register_task(path)[0])[0])
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
    parser.add_argument("--rungs", nargs="+", help="only these spec files' stems (default: every spec)")
    args = parser.parse_args(argv)
    if args.check:
        return check()
    from craftsuite.suite_runner import run_students

    standard = SUITES["standard"]
    configs = []
    for path in [p for p in SPECS if not args.rungs or p.stem in args.rungs]:
        task = parse_id(craftsuite.register_task(path)[0])[0]
        for seed in range(args.seeds):
            configs.append(StudentConfig(task=task, method="td3", world="Cont", seed=seed, steps=args.steps,
                                         eval_every=args.steps // 20, eval_episodes=standard.eval_episodes,
                                         hyperparameters=dict(standard.td3_hyperparameters),
                                         n_envs=standard.td3_n_envs, engine="population"))
    run_students(configs, args.out / "students", workers=args.workers)
    print(" ".join(sys.argv))


if __name__ == "__main__":
    main()
