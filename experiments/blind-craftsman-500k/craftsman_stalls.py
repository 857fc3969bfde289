"""How do the greedy failures on the craftsman rung end: a stall short of an object, or a cycle?

Usage: python experiments/blind-craftsman-500k/craftsman_stalls.py SEED [--steps 40000] [--episodes 40]

Trains TD3 from scratch on td3_reach.py's *craftsman* rung (Blind Craftsman's objects,
objective ``F wood``; frame skip 10, 200-step episodes, persistent noise N(0, 0.6) redrawn
w.p. 0.1, [256, 256]) with ``make_agent`` and ``learn`` alone (no evaluations in between),
then replays it on ``--episodes`` fresh episodes (seeds from 5000) twice: with the actor
(greedy) and with the critic's best of a 21 x 21 grid of thrusts. A failure is "stuck" if
its last 30 positions fit in a 0.3 m box. Prints success and stuck failures for each.
"""

from __future__ import annotations

import argparse

import _tools  # noqa: F401  (td3_reach lives with the calibration experiment)


def replay(agent, task: str, world: dict, act, episodes: int) -> tuple[float, int]:
    import gymnasium as gym
    import numpy as np

    wins = stuck = 0
    for e in range(episodes):
        env = gym.make(f"CraftSuite/{task}-Cont-v0", **world)
        obs, _ = env.reset(seed=5000 + e)
        path = []
        while True:
            obs, _, terminated, truncated, info = env.step(act(obs))
            path.append(env.unwrapped.data.qpos[:2].copy())
            if terminated or truncated:
                break
        env.close()
        wins += bool(info["is_success"])
        stuck += not info["is_success"] and np.ptp(np.array(path[-30:]), axis=0).max() <= 0.3
    return wins / episodes, stuck


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("seed", type=int)
    parser.add_argument("--steps", type=int, default=40_000)
    parser.add_argument("--episodes", type=int, default=40)
    args = parser.parse_args(argv)

    import torch

    torch.set_num_threads(1)
    from craftsuite.agents.factory import make_agent
    from greedy_stalls import critic_greedy
    from td3_reach import HORIZONS, register_reach

    task, world = register_reach("craftsman"), HORIZONS[10][1]
    agent = make_agent("td3", f"CraftSuite/{task}-Cont-v0", seed=args.seed, env_kwargs=world,
                       policy_kwargs={"net_arch": [256, 256]},
                       action_noise={"type": "persistent", "sigma": 0.6, "resample": 0.1})
    agent.learn(args.steps)
    for name, act in (("actor, greedy", lambda o: agent.predict(o, deterministic=True)[0]),
                      ("critic's best of 21 x 21 thrusts", lambda o: critic_greedy(agent, o))):
        success, stuck = replay(agent, task, world, act, args.episodes)
        print(f"{name}: success {success:.2f}, stuck failures {stuck}", flush=True)


if __name__ == "__main__":
    main()
