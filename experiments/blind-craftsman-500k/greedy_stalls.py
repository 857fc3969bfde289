"""Why a TD3 student that wins its noisy training episodes fails greedy ones.

Usage: python experiments/blind-craftsman-500k/greedy_stalls.py RUN_DIR [RUN_DIR ...] [--episodes N]

For each finished (or checkpointed) MuJoCo student run, its last checkpoint plays the same
fresh episodes five ways: greedy (the leaderboard's success); with N(0, 0.1) or N(0, 0.3)
added per step, or with the run's own training noise (its ``action_noise`` spec); and on
the critic instead of the actor, each step the thrust of a 21 x 21 grid with the highest
Q1 (is it the actor, or the critic, that fails?). Then, for the greedy episodes that
failed, it says how they ended: *stuck* (the agent stood or chattered within a 0.3 m box
for its last 30 steps), with the distance from there to the nearest object of each kind,
the actor's action there, and the critic's best thrust on that grid with the spread of
its values.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np


def _load(run: Path):
    """A run's config, its last checkpoint's model, and whether it sees the automaton state."""
    from craftsuite.agents.factory import load_agent
    from craftsuite.configs import StudentConfig
    from craftsuite.runs import RunDir, load_config

    config = load_config(StudentConfig, run)
    saved = RunDir(run, config).last_checkpoint()
    model = saved / "model.zip" if saved is not None else run / "model.zip"  # a finished run keeps its model only
    if not model.is_file():
        raise FileNotFoundError(f"{run} has no checkpoint nor final model yet")
    return config, load_agent(model), config.product


def _thrust_grid():
    import torch as th

    grid = np.linspace(-1, 1, 21)
    return th.as_tensor(np.array([(x, y) for x in grid for y in grid], dtype=np.float32))


def critic_values(model, obs: np.ndarray):
    """Q1 of ``obs`` for every thrust of the grid: (thrusts, values)."""
    import torch as th

    actions = _thrust_grid()
    obs = th.as_tensor(np.asarray(obs, dtype=np.float32)[None])
    with th.no_grad():
        q = model.critic.q1_forward(obs.repeat(len(actions), 1), actions)[:, 0].numpy()
    return actions.numpy(), q


def critic_greedy(model, obs: np.ndarray) -> np.ndarray:
    actions, q = critic_values(model, obs)
    return actions[int(q.argmax())]


def play(model, config, product: bool, episodes: int, noise=None, seed: int = 7000, act=None) -> list[dict]:
    """Episodes on seeds ``seed``, ``seed + 1``, ...; ``noise()`` (if given) is added to each
    action; ``act(model, obs)`` (if given) replaces the actor."""
    import gymnasium as gym

    out = []
    for e in range(episodes):
        env = gym.make(config.env_id, product=product, **config.env_kwargs)
        obs, _ = env.reset(seed=seed + e)
        if noise is not None:
            noise.reset()
        path = []
        while True:
            action = model.predict(obs, deterministic=True)[0] if act is None else act(model, obs)
            if noise is not None:
                action = np.clip(action + noise(), -1, 1)
            obs, _, terminated, truncated, info = env.step(action)
            path.append(env.unwrapped.data.qpos[:2].copy())
            if terminated or truncated:
                break
        out.append({"success": bool(info["is_success"]), "obs": obs, "path": np.array(path), "env": env})
    return out


def stall_report(model, episode: dict) -> dict | None:
    """How a failed greedy episode ended, if it got stuck (None if the agent was still moving)."""
    import torch as th

    last = episode["path"][-30:]
    if np.ptp(last, axis=0).max() > 0.3:
        return None
    env, here = episode["env"].unwrapped, episode["path"][-1]
    nearest = {kind: min(float(np.hypot(*(np.array(p) - here))) for p in points)
               for kind, points in env.object_positions().items() if points}
    actions, q = critic_values(model, episode["obs"])
    with th.no_grad():
        actor = model.actor(th.as_tensor(episode["obs"][None]))[0].numpy()
    return {"nearest": nearest, "actor": actor, "critic_best": actions[int(q.argmax())],
            "q_spread": float(q.max() - q.min()), "inventory": tuple(int(c) for c in env.inventory_counts),
            "at_wall": bool(np.abs(here).max() >= env.wall_limit - 0.01)}


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("runs", nargs="+", type=Path, help="student run directories (MuJoCo, TD3)")
    parser.add_argument("--episodes", type=int, default=40)
    args = parser.parse_args(argv)

    import torch as th
    from stable_baselines3.common.noise import NormalActionNoise

    from craftsuite.agents.noise import make_action_noise

    th.set_num_threads(1)
    for run in args.runs:
        config, model, product = _load(run)
        spec = config.hyperparameters.get("action_noise", {"type": "normal", "sigma": 0.3})
        ways = {"greedy": {},  # play() keywords
                "+ N(0, 0.1) per step": {"noise": NormalActionNoise(np.zeros(2), np.full(2, 0.1))},
                "+ N(0, 0.3) per step": {"noise": NormalActionNoise(np.zeros(2), np.full(2, 0.3))},
                f"+ its training noise {json.dumps(spec)}": {"noise": make_action_noise(spec, 2, seed=0)},
                "the critic's best of 21 x 21 thrusts": {"act": critic_greedy}}
        print(f"\n## {run.name}\n\n| actions | success ({args.episodes} episodes) |\n|---|---|")
        greedy = []
        for name, how in ways.items():
            np.random.seed(0)  # NormalActionNoise draws from numpy's global generator
            episodes = play(model, config, product, args.episodes, **how)
            if not greedy:
                greedy = episodes  # the first way; its envs stay open for the stall reports
            else:
                for e in episodes:
                    e["env"].close()
            print(f"| {name} | {np.mean([e['success'] for e in episodes]):.2f} |")
        failed = [e for e in greedy if not e["success"]]
        stalls = [r for r in (stall_report(model, e) for e in failed) if r is not None]
        for e in greedy:
            e["env"].close()
        print(f"\nGreedy failures: {len(failed)}, of which stuck (within 0.3 m for the last 30 steps): {len(stalls)}\n")
        if stalls:
            print("| inventory | nearest objects (m) | at the wall | actor's action | critic's best action "
                  "| critic's value spread |")
            print("|---|---|---|---|---|---|")
            for r in stalls:
                near = ", ".join(f"{k} {d:.2f}" for k, d in sorted(r["nearest"].items(), key=lambda kv: kv[1]))
                print(f"| {r['inventory']} | {near} | {'yes' if r['at_wall'] else ''} "
                      f"| ({r['actor'][0]:+.2f}, {r['actor'][1]:+.2f}) "
                      f"| ({r['critic_best'][0]:+.1f}, {r['critic_best'][1]:+.1f}) | {r['q_spread']:.1f} |")
            close = np.mean([min(r["nearest"].values()) < 1.0 for r in stalls])
            print(f"\nStuck within 1 m of an object (the pickup radius is 0.4 m): {close:.0%}")


if __name__ == "__main__":
    main()
