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
    from .files import file_to_read

    file_to_read(path, "checkpoint", ("model.zip", "teacher.zip"))  # a student's run directory, or a teacher's
    if not path.is_file():
        raise FileNotFoundError(
            f"no such checkpoint {str(path)!r}; a policy is 'random', 'scripted' or a checkpoint file")
    model = load_agent(path)
    _check_observations(path, model.observation_space.shape, env)
    return lambda obs: model.predict(np.asarray(obs), deterministic=True)[0]


def _check_observations(path: Path, shape: tuple, env) -> None:
    """Raise a ValueError when a checkpoint's observation ``shape`` is not ``env``'s, saying
    whether the checkpoint was trained with the automaton state (product=True) or without it."""
    if shape == env.observation_space.shape:
        return
    plain = env.unwrapped.observation_space.shape  # the world's own, under AutomatonObservation
    automaton = getattr(env.unwrapped, "automaton", None)
    product = (plain[0] + automaton.n_states,) if automaton is not None and len(plain) == 1 else None
    if shape == plain:
        raise ValueError(f"{path}: the policy's observation size {shape[0]} matches the plain observation "
                         "(trained without the automaton state); drop --product")
    if shape == product:
        raise ValueError(f"{path}: the policy's observation size {shape[0]} matches the observation with the "
                         "automaton state (trained with it); add --product")
    name = env.spec.id if env.spec is not None else "the env"
    sizes = f"{plain}" + (f" ({product} with the automaton state)" if product else "")
    raise ValueError(f"{path}: the policy's observation shape {shape} is not {name}'s, {sizes}; "
                     "use a policy trained on this task and world (with the --env of its training)")
