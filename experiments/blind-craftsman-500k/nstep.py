"""The tool rung with SB3's own TD3 and n-step returns.

Usage: python experiments/blind-craftsman-500k/nstep.py N SEED [SEED ...]

td3_reach.py's *tool* rung (a wood, then the factory, +100 on the tool), its world (frame
skip 10, 200-step episodes) and its persistent noise (N(0, 0.6) redrawn w.p. 0.1), but
SB3's own TD3 (uniform replay, policy delay 2, the package's TD3 settings otherwise:
[256, 256], lr 1e-4, batch 64) with ``n_steps=N``; 40k steps per seed, two processes.
Prints greedy success every 5,000 steps (10 fresh episodes) and the training wins.
"""

from __future__ import annotations

import argparse
from concurrent.futures import ProcessPoolExecutor

import _tools  # noqa: F401  (td3_reach and _students live with the calibration experiment)


def run(n: int, seed: int):
    import craftsuite.agents.factory as factory
    from _students import train_with_reports
    from stable_baselines3 import TD3
    from td3_reach import HORIZONS, register_reach

    real = factory.make_agent

    def make_agent(method, env_id, **kw):
        a = real(method, env_id, **kw)  # builds the env and the persistent noise as the package does
        return TD3("MlpPolicy", a.env, learning_rate=1e-4, buffer_size=1_000_000, batch_size=64, learning_starts=1_000,
                   gamma=0.99, tau=0.005, target_policy_noise=0.2, target_noise_clip=0.5, action_noise=a.action_noise,
                   policy_kwargs={"net_arch": [256, 256]}, n_steps=n, seed=seed)

    factory.make_agent = make_agent  # _students builds its agent through this name
    task = register_reach("tool")
    rows = train_with_reports("td3", None, task=task, seed=seed, steps=40_000, every=5_000, env_kwargs=HORIZONS[10][1],
                              action_noise={"type": "persistent", "sigma": 0.6, "resample": 0.1})
    return n, seed, rows


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", type=int, help="steps per return")
    parser.add_argument("seeds", type=int, nargs="+")
    args = parser.parse_args(argv)
    with ProcessPoolExecutor(2) as pool:
        for n, seed, rows in pool.map(run, [args.n] * len(args.seeds), args.seeds):
            print(f"n={n} seed={seed} greedy", " ".join(f"{r['eval_success']:.1f}" for r in rows),
                  f"| wins {rows[-1]['train_wins']}/{rows[-1]['train_episodes']}")


if __name__ == "__main__":
    main()
