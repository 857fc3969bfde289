"""100k steps more from each 500k checkpoint of runs/bc-fs10-500k, with another noise.

Usage: python experiments/blind-craftsman-500k/continue_training.py METHOD SIGMA [SIGMA ...]
       [--runs runs/bc-fs10-500k]

Each of the runs directory's METHOD students (``td3-dynamic`` or ``td3``) is loaded from
its checkpoint (model and replay buffer) and trained 100k steps further with the
persistent noise at SIGMA (resample 0.1); 20 greedy episodes (the same start seeds each
time) every 20k, with the training episodes won in each 20k. Run from the repository root;
two processes. Writes nothing into the runs.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

EXTRA, EVERY, EPISODES = 100_000, 20_000, 20


def job(run: Path, sigma: float) -> str:
    import torch

    torch.set_num_threads(1)
    import craftsuite  # noqa: F401  (registers the ids in this worker)
    from stable_baselines3.common.callbacks import BaseCallback

    from craftsuite.agents import AutomatonQTable
    from craftsuite.agents.factory import make_agent
    from craftsuite.agents.noise import make_action_noise
    from craftsuite.configs import StudentConfig
    from craftsuite.runs import load_config
    from craftsuite.training import evaluate

    cfg = load_config(StudentConfig, run)
    env_id, world = cfg.env_id, cfg.env_kwargs
    fresh = make_agent(cfg.method, env_id, table=cfg.table and AutomatonQTable.load(cfg.table),
                       seed=cfg.seed, env_kwargs=world, **cfg.hyperparameters, buffer_size=cfg.steps)
    agent = type(fresh).load(run / "checkpoint/model.zip", env=fresh.get_env(), device="cpu")
    agent.load_replay_buffer(run / "checkpoint/replay.pkl")
    agent.action_noise = make_action_noise({"type": "persistent", "sigma": sigma, "resample": 0.1}, 2, 1000 + cfg.seed)
    start, rows = agent.num_timesteps, []

    def greedy() -> float:
        return evaluate(agent, env_id, EPISODES, seed=10**8, product=cfg.product, env_kwargs=world)[0]

    class Report(BaseCallback):
        wins = episodes = 0

        def _on_step(self) -> bool:
            for info, done in zip(self.locals["infos"], self.locals["dones"]):
                self.episodes += bool(done)
                self.wins += bool(done and info.get("is_success"))
            if (self.num_timesteps - start) % EVERY == 0:
                rows.append(f"{self.num_timesteps // 1000}k {greedy():.2f} ({self.wins}/{self.episodes})")
                self.wins = self.episodes = 0
            return True

    rows.append(f"{start // 1000}k {greedy():.2f}")
    agent.learn(EXTRA, callback=Report(), reset_num_timesteps=False)
    return f"{cfg.method} sigma {sigma} seed {cfg.seed}: " + "  ".join(rows)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("method", choices=["td3-dynamic", "td3"])
    parser.add_argument("sigmas", type=float, nargs="+")
    parser.add_argument("--runs", type=Path, default=Path("runs/bc-fs10-500k"))
    args = parser.parse_args(argv)
    runs = sorted((args.runs / "students").glob(f"student-BlindCraftsman-Cont-{args.method}-s*"))
    if not runs:
        parser.error(f"no {args.method} student runs under {args.runs / 'students'}")
    jobs = [(run, s) for s in args.sigmas for run in runs]
    with ProcessPoolExecutor(2) as pool:
        for line in pool.map(job, *zip(*jobs)):
            print(line, flush=True)


if __name__ == "__main__":
    main()
