"""Which collection regime learns most per wall-clock second on two cores?

Usage: python experiments/collection-regime/run.py [--tasks Reach FirstWood] [--seeds 0 1 2 3]
       [--regimes A B ...] [--seconds 180] [--transitions N] [--every 15] [--workers 2] [--out results.jsonl]

Each run trains TD3 from scratch on ``CraftSuite/<task>-Cont-v0`` (the registered world;
regimes A-J) or DQN on ``CraftSuite/<task>-Grid10-v0`` (one fixed instance, layout 1, as
the suites' grid students; regimes a-d) for ``--seconds`` of training time (evaluations
excluded) or ``--transitions``, whichever comes first, in one of the regimes below, and
every ``--every`` seconds plays 20 greedy episodes on fresh seeds. A row per evaluation
goes to ``--out`` (JSON lines): seconds, transitions, gradient updates, greedy success.
``summary.py`` turns the file into the README's tables. (DQN anneals its epsilon over the
first 10% of ``--transitions``, so DQN runs need it.)
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor
from itertools import product

# Every regime shares the exploration (the persistent noise under which TD3 learned here)
# and uniform replay; they differ in envs per update, updates per step, batch, lr, network.
NOISE = {"type": "persistent", "sigma": 0.6, "resample": 0.1}
REGIMES = {
    "A": dict(n_envs=1, batch_size=64, learning_rate=1e-4, net=[64, 64]),     # the package's TD3, small net
    "B": dict(n_envs=1, batch_size=256, learning_rate=1e-3, net=[64, 64]),    # SB3 zoo's batch and lr
    "C": dict(n_envs=10, batch_size=64, learning_rate=1e-4, net=[64, 64]),    # the authors' collection
    "D": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[64, 64]),
    "E": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[64, 64]),
    "F": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[64, 64], gradient_steps=4),
    "G": dict(n_envs=10, batch_size=256, learning_rate=1e-3, net=[256, 256]),
    "H": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[64, 64], prioritized=True),
    "I": dict(n_envs=4, batch_size=256, learning_rate=3e-4, net=[64, 64]),
    "J": dict(n_envs=4, batch_size=256, learning_rate=1e-3, net=[256, 256]),
    "K": dict(n_envs=10, batch_size=256, learning_rate=3e-4, net=[64, 64]),  # D, a third of the step size
    # DQN on the grids (the package's DQN otherwise: dueling, double, PER, lr 5e-4, batch 64);
    # the target network is updated every 100 gradient updates in each
    "a": dict(n_envs=1, target_update_interval=100, net=[64, 64]),  # the package's
    "b": dict(n_envs=4, target_update_interval=400, net=[64, 64]),
    "c": dict(n_envs=10, target_update_interval=1_000, net=[64, 64]),  # the authors' collection
    "d": dict(n_envs=4, target_update_interval=200, gradient_steps=2, net=[64, 64]),
}
EVAL_EPISODES = 20


def describe(regime: dict) -> str:
    updates = regime.get("gradient_steps", 1) / regime["n_envs"]
    if "batch_size" not in regime:  # DQN
        return f"DQN, {regime['n_envs']} env(s), {updates:g} updates/transition, {regime['net']}"
    return (f"{regime['n_envs']} env(s), {updates:g} updates/transition, batch {regime['batch_size']}, "
            f"lr {regime['learning_rate']:g}, {regime['net']}" + (", PER" if regime.get("prioritized") else ""))


def run(task: str, name: str, seed: int, seconds: float, every: float, transitions: int | None = None) -> list[dict]:
    import torch

    torch.set_num_threads(1)
    import craftsuite  # noqa: F401
    from stable_baselines3.common.callbacks import BaseCallback

    from craftsuite.agents.factory import make_agent
    from craftsuite.training import evaluate

    regime = dict(REGIMES[name])
    net = regime.pop("net")
    n_envs = regime.pop("n_envs")
    dqn = "batch_size" not in regime
    env_id = f"CraftSuite/{task}-{'Grid10' if dqn else 'Cont'}-v0"
    env_kwargs = {"layout_seed": 1} if dqn else {}
    if dqn:
        agent = make_agent("dqn", env_id, seed=seed, n_envs=n_envs, env_kwargs=env_kwargs,
                           policy_kwargs={"net_arch": net}, **regime)
    else:
        agent = make_agent("td3", env_id, seed=seed, n_envs=n_envs, action_noise=NOISE,
                           policy_kwargs={"net_arch": net}, prioritized=regime.pop("prioritized", False),
                           buffer_size=1_000_000, **regime)
    rows = []

    class Clock(BaseCallback):
        """Counts training time only; evaluates every ``every`` seconds of it; stops at ``seconds``."""

        def _on_training_start(self):
            self.trained, self.mark, self.next = 0.0, time.perf_counter(), every

        def _on_step(self) -> bool:
            now = time.perf_counter()
            self.trained += now - self.mark
            if self.trained >= self.next:
                success, ret, _ = evaluate(agent, env_id, EVAL_EPISODES, seed=10**7 + len(rows), product=False,
                                        env_kwargs=env_kwargs)
                rows.append({"task": task, "regime": name, "seed": seed, "seconds": round(self.trained, 1),
                             "transitions": int(self.num_timesteps), "updates": int(agent.n_updates),
                             "success": success, "return": round(ret, 2)})
                self.next += every
            self.mark = time.perf_counter()
            return self.trained < seconds

    agent.learn(transitions or 10**9, callback=Clock())
    agent.get_env().close()
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", nargs="+", default=["Reach"])
    parser.add_argument("--regimes", nargs="+", choices=list(REGIMES), default=list("ABCDEFG"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3])
    parser.add_argument("--seconds", type=float, default=180)
    parser.add_argument("--transitions", type=int, help="also stop here (DQN's epsilon schedule needs it)")
    parser.add_argument("--every", type=float, default=15)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default="results.jsonl")
    args = parser.parse_args()
    jobs = list(product(args.tasks, args.regimes, args.seeds))
    with ProcessPoolExecutor(args.workers) as pool, open(args.out, "a") as out:
        futures = [pool.submit(run, t, r, s, args.seconds, args.every, args.transitions) for t, r, s in jobs]
        for (task, regime, seed), future in zip(jobs, futures):
            rows = future.result()
            for row in rows:
                out.write(json.dumps(row) + "\n")
            out.flush()
            best = max((r["success"] for r in rows), default=0.0)
            print(f"{task} {regime} ({describe(REGIMES[regime])}) seed {seed}: best greedy success {best:.2f}, "
                  f"{rows[-1]['transitions']:,} transitions, {rows[-1]['updates']:,} updates", flush=True)


if __name__ == "__main__":
    main()
