"""A first learning comparison: TD3 with dynamic distillation vs TD3 from scratch.

Usage: python benchmarks/transfer_td3.py --table out/teachers/BlindCraftsman-dynamic.npz
                                         [--task BlindCraftsman] [--steps N] [--seeds 0 1 2]

The table comes from ``benchmarks/teachers.py`` (a 7x7 grid teacher distilled into the
task's automaton); the students learn in the MuJoCo world of the same task. Runs go two
at a time (this machine's two cores). Per run: episodes finished, success rate and mean
return over the last 25% of episodes, and the step of the first success.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import time

import numpy as np
from stable_baselines3.common.callbacks import BaseCallback


class EpisodeLog(BaseCallback):
    def __init__(self):
        super().__init__()
        self.episodes = []  # (step, return, success)

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            if "episode" in info:
                self.episodes.append((self.num_timesteps, float(info["episode"]["r"]), bool(info["is_success"])))
        return True


def run(job):
    method, task, table_path, steps, seed = job
    import torch
    torch.set_num_threads(1)
    import craftsuite  # noqa: F401
    from craftsuite.agents import AutomatonQTable
    from craftsuite.agents.methods import make_agent

    table = AutomatonQTable.load(table_path) if method == "td3-dynamic" else None
    agent = make_agent(method, f"CraftSuite/{task}-Cont-v0", table=table, seed=seed)
    log = EpisodeLog()
    t = time.perf_counter()
    agent.learn(steps, callback=log)
    return method, seed, log.episodes, time.perf_counter() - t


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--table", required=True)
    parser.add_argument("--task", default="BlindCraftsman")
    parser.add_argument("--steps", type=int, default=20_000)
    parser.add_argument("--seeds", type=int, nargs="*", default=[0, 1, 2])
    parser.add_argument("--json", help="also write per-episode logs here")
    args = parser.parse_args()
    jobs = [(m, args.task, args.table, args.steps, s) for s in args.seeds for m in ("td3-dynamic", "td3")]
    with mp.get_context("spawn").Pool(2) as pool:
        results = pool.map(run, jobs)
    print(f"| method | seed | episodes | success, last 25% | return, last 25% | first success at step | minutes |")
    print("|---|---|---|---|---|---|---|")
    summary = {}
    for method, seed, episodes, seconds in results:
        tail = episodes[int(len(episodes) * 0.75):] or episodes
        success = np.mean([e[2] for e in tail]) if tail else float("nan")
        ret = np.mean([e[1] for e in tail]) if tail else float("nan")
        first = next((e[0] for e in episodes if e[2]), None)
        summary.setdefault(method, []).append((success, ret))
        print(f"| {method} | {seed} | {len(episodes)} | {success:.2f} | {ret:.1f} | {first} | {seconds / 60:.1f} |")
    print()
    for method, rows in summary.items():
        s, r = np.array(rows).T
        print(f"{method}: success {s.mean():.2f} +- {s.std():.2f}, return {r.mean():.1f} +- {r.std():.1f} "
              f"over {len(rows)} seeds")
    if args.json:
        with open(args.json, "w") as f:
            json.dump([{"method": m, "seed": s, "episodes": e} for m, s, e, _ in results], f)


if __name__ == "__main__":
    main()
