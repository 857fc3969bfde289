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
    if is_checkpoint(name):
        return checkpoint_policy(load_checkpoint(name), env, name)
    if name == "random":
        space = env.action_space
        space.seed(seed)
        return lambda obs: space.sample()
    return scripted_policy(env)


def is_checkpoint(name: str) -> bool:
    """Whether a policy's name is a checkpoint's path (not ``"random"`` or ``"scripted"``)."""
    return name not in ("random", "scripted")


def load_checkpoint(path):
    """The stable-baselines3 model saved at ``path``, with a clear error for a missing,
    corrupt or misnamed file."""
    from .agents.factory import load_agent
    from .files import file_to_read

    path = Path(path)
    file_to_read(path, "checkpoint", ("model.zip", "teacher.zip"))  # a student's run directory, or a teacher's
    if not path.is_file():
        raise FileNotFoundError(
            f"no such checkpoint {str(path)!r}; a policy is 'random', 'scripted' or a checkpoint file")
    return load_agent(path)


def checkpoint_policy(model, env, path):
    """A callable ``obs -> action`` of a loaded ``model`` (saved at ``path``) for ``env``,
    whose observations it must have been trained on."""
    _check_observations(Path(path), model.observation_space.shape, env)
    return lambda obs: model.predict(np.asarray(obs), deterministic=True)[0]


def _check_observations(path: Path, shape: tuple, env) -> None:
    """Raise a ValueError when a checkpoint's observation ``shape`` is not ``env``'s, saying
    whether the checkpoint was trained with the automaton state (product=True) or without it."""
    from .wrappers import observation_shapes

    if shape == env.observation_space.shape:
        return
    plain, product = observation_shapes(env)  # the world's own, under AutomatonObservation, and with it
    if shape == plain:
        raise ValueError(f"{path}: the policy's observation size {shape[0]} matches the plain observation "
                         "(trained without the automaton state); drop --product (product=False)")
    if shape == product:
        raise ValueError(f"{path}: the policy's observation size {shape[0]} matches the observation with the "
                         "automaton state (trained with it); make the env with product=True")
    name = env.spec.id if env.spec is not None else "the env"
    sizes = f"{plain}" + (f" ({product} with the automaton state)" if product else "")
    raise ValueError(f"{path}: the policy's observation shape {shape} is not {name}'s, {sizes}; "
                     "use a policy trained on this task and world (with the --env of its training)")
