"""Replays each student run's last greedy evaluation and asks of every failed episode whether
its state (agent cell, cells' contents, inventory, automaton state) came back: a loop, which
a deterministic greedy policy in the deterministic grid can only leave at the time limit.
Then the same episodes with epsilon-greedy actions (a sensitivity reading only).

Usage: python experiments/greedy-loops/loops.py STUDENTS_DIR [--suite hard] [--epsilon 0.05]
       [--noise-seeds 5] [--own-success] [--out loops.json]

STUDENTS_DIR holds Grid10 student runs with their ``model.zip`` (a transfer's output
``students/``; the results archive keeps no models). A run whose replay does not give its
recorded final success stops the script: the replay would not be the policy its record read.
The saved model is not quite that policy: the last evaluation runs before the last step's
gradient updates (as SB3's callbacks run before its ``train()``) and the model is saved after
them. ``--own-success`` reads each saved model on the same seeds as it plays them, recording
the run's recorded success beside it.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import gymnasium as gym
import numpy as np

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.factory import load_agent
from craftsuite.episodes import rollout
from craftsuite.evaluation import protocol, sees_automaton
from craftsuite.ids import env_id as id_of
from craftsuite.runs import eval_seed, read_config, read_csv


def state_of(env) -> tuple:
    """The grid's whole state: what the next step depends on besides the action."""
    u = env.unwrapped
    return (u._agent, tuple(u._cells), repr(u.inventory_counts), u.tracker.state)


def replay(model, env_id: str, kwargs: dict, product: bool, n: int, seed: int, epsilon: float = 0.0,
           noise_seed: int = 0) -> list[dict]:
    """``n`` episodes of the model on reset seeds ``seed``, ``seed + 1``, ... side by side (as
    the suites' evaluation plays them), each with whether its state repeated and where it ended."""
    envs = [gym.make(env_id, product=product, **kwargs) for _ in range(n)]
    rng = np.random.default_rng(noise_seed)
    seen: list[set] = [set() for _ in range(n)]
    looped = [None] * n

    def policy(batch):
        actions = model.predict(batch, deterministic=True)[0]
        if epsilon:
            noisy = rng.random(len(actions)) < epsilon
            actions = np.where(noisy, rng.integers(envs[0].action_space.n, size=len(actions)), actions)
        return actions

    def on_reset(episode):
        seen[episode].add(state_of(envs[episode]))

    def on_step(episode, reward, info):
        s = state_of(envs[episode])
        if s in seen[episode] and looped[episode] is None:
            looped[episode] = len(seen[episode])  # the distinct states before the first repeat
        seen[episode].add(s)

    try:
        played = rollout(envs, policy, n, seed, on_reset=on_reset, on_step=on_step)
        return [{"seed": e.seed, "success": e.success, "length": e.length, "looped": looped[i] is not None,
                 "distinct_states": len(seen[i]), "end_automaton_state": envs[i].unwrapped.tracker.state}
                for i, e in enumerate(played)]
    finally:
        for env in envs:
            env.close()


def last_evaluation(run: Path) -> tuple[int, float]:
    last = read_csv(run / "evals.csv", ("step", "success"), required=True)[-1]
    return int(last["step"]), float(last["success"])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("students", type=Path)
    parser.add_argument("--suite", default="hard")
    parser.add_argument("--epsilon", type=float, default=0.05)
    parser.add_argument("--noise-seeds", type=int, default=5)
    parser.add_argument("--own-success", action="store_true",
                        help="read each saved model's own greedy success; do not stop where it differs from the record")
    parser.add_argument("--out", type=Path, default=Path("loops.json"))
    args = parser.parse_args()
    runs = sorted(p.parent for p in args.students.glob("*/model.zip"))
    if not runs:
        raise SystemExit(f"no student run with a model.zip under {args.students}: give a transfer's students/")
    out = []
    for run in runs:
        config = read_config(run)
        env_id = id_of(config["task"], config["world"])
        suite_config, _ = protocol(env_id, args.suite)
        kwargs, n = suite_config.env_kwargs, suite_config.eval_episodes
        step, recorded = last_evaluation(run)
        model = load_agent(run / "model.zip")
        product = sees_automaton(model, env_id, kwargs)
        greedy = replay(model, env_id, kwargs, product, n, eval_seed(step))
        success = float(np.mean([e["success"] for e in greedy]))
        if abs(success - recorded) > 1e-9 and not args.own_success:
            raise SystemExit(f"{run.name}: the replay's greedy success {success:.2f} is not the recorded "
                             f"{recorded:.2f}: not the policy the record read; stopping")
        noisy = [replay(model, env_id, kwargs, product, n, eval_seed(step), args.epsilon, k)
                 for k in range(args.noise_seeds)]
        failed = [e for e in greedy if not e["success"]]
        row = {"run": run.name, "method": config["method"], "seed": config["seed"], "step": step,
               "recorded_success": recorded, "greedy_success": success, "failed": len(failed),
               "failed_looped": sum(e["looped"] for e in failed),
               "failed_end_states": sorted({e["end_automaton_state"] for e in failed}),
               "epsilon_success": float(np.mean([e["success"] for ep in noisy for e in ep])), "episodes": greedy}
        out.append(row)
        print(f"{row['method']:>8} seed {row['seed']:>2}: recorded {recorded:.2f}, greedy {success:.2f}, "
              f"failed {len(failed):>2}, "
              f"of them loops {row['failed_looped']:>2}, end states {row['failed_end_states']}, "
              f"epsilon {args.epsilon}: {row['epsilon_success']:.2f}", flush=True)
    args.out.write_text(json.dumps({"epsilon": args.epsilon, "noise_seeds": args.noise_seeds, "runs": out}, indent=1))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
