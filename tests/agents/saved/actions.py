"""Write ``actions.json``: what each saved model (``make.CASES``) answers to a few fixed
observations of its world (greedy actions; a DQN's Q-values, a TD3's first critic at its
actions), with the observations themselves. ``tests/agents/test_factory.py`` asserts that a
loaded model still answers the same.

The models cannot be made again (``make.py`` runs only at the commit it names), so these
answers were recorded from the saved files by the loading code that has read them since they
were saved; run from the repository root, ``python -m tests.agents.saved.actions``, only to
add a saved model, never to make a failing comparison pass."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import torch as th

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.methods import METHODS

from . import make

FILE = make.HERE / "actions.json"


def observations(name: str) -> np.ndarray:
    """Five observations of model ``name``'s world: a start, three states on a seeded random
    walk from it, and all zeros."""
    method, env_id, env_kwargs, _, _ = make.CASES[name]
    env = gym.make(env_id, **env_kwargs, product=METHODS[method].observes(None))
    obs, _ = env.reset(seed=3)
    env.action_space.seed(3)
    seen = [obs]
    for step in range(1, 13):
        obs, _, terminated, truncated, _ = env.step(env.action_space.sample())
        if step % 4 == 0:
            seen.append(obs)
        if terminated or truncated:
            obs, _ = env.reset(seed=3 + step)
    env.close()
    return np.stack([*seen, np.zeros_like(seen[0])]).astype(np.float32)


def answers(agent, obs: np.ndarray) -> dict:
    """The loaded ``agent``'s greedy actions for ``obs`` and the values behind them."""
    actions = agent.predict(obs, deterministic=True)[0]
    with th.no_grad():
        tensor = th.as_tensor(obs, device=agent.device)
        if agent.algorithm == "dqn":
            values = agent.q_net(tensor)
        else:
            values = agent.critic.q1_forward(tensor, agent.actor(tensor))
    return {"actions": np.asarray(actions).tolist(), "values": values.cpu().numpy().astype(float).tolist()}


def main() -> None:
    from craftsuite.agents.factory import load_agent

    recorded = {}
    for name in make.CASES:
        obs = observations(name)
        recorded[name] = {"observations": obs.tolist(), **answers(load_agent(make.HERE / f"{name}.zip"), obs)}
    FILE.write_text(json.dumps(recorded) + "\n")
    print(f"wrote {FILE} ({FILE.stat().st_size:,} bytes)")


if __name__ == "__main__":
    main()
