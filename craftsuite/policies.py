"""Policies by name, for videos and evaluation: ``random``, ``scripted`` or a checkpoint path."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .scripted import scripted_policy


def load_policy(name: str, env, seed: int = 0):
    """A callable ``obs -> action`` for ``env``.

    Args:
        name: ``"random"``, ``"scripted"``, or the path of a stable-baselines3 checkpoint
            (``.zip``) trained on this env's observation and action spaces.
    """
    if name == "random":
        space = env.action_space
        space.seed(seed)
        return lambda obs: space.sample()
    if name == "scripted":
        return scripted_policy(env)
    return _load_checkpoint(Path(name), env)


def _load_checkpoint(path: Path, env):
    from .agents.factory import load_agent

    if not path.is_file():
        raise FileNotFoundError(
            f"no such checkpoint {str(path)!r}; a policy is 'random', 'scripted' or a checkpoint file")
    model = load_agent(path)
    if model.observation_space.shape != env.observation_space.shape:
        raise ValueError(
            f"{path}: the policy expects observations of shape {model.observation_space.shape}, "
            f"the env gives {env.observation_space.shape} (another task, or product=True missing?)")
    return lambda obs: model.predict(np.asarray(obs), deterministic=True)[0]
