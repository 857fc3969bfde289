"""Wrappers over CraftSuite worlds."""

from __future__ import annotations

import gymnasium as gym
import numpy as np


def observation_shapes(env) -> tuple[tuple, tuple | None]:
    """A world's own observation shape, and its shape with the automaton state's one-hot
    (``AutomatonObservation``'s: None where the world's is not flat or tracks no automaton),
    whatever wraps it: how a policy's observation space tells which it was trained on."""
    base = env.unwrapped
    plain = tuple(base.observation_space.shape)
    automaton = getattr(base, "automaton", None)
    return plain, ((plain[0] + automaton.n_states,) if automaton is not None and len(plain) == 1 else None)


class AutomatonObservation(gym.ObservationWrapper, gym.utils.RecordConstructorArgs):
    """The product MDP's observation: the world's vector with the automaton state's one-hot.

    Works on any env whose ``unwrapped`` has an ``automaton`` (``craftsuite.automata.
    Automaton``) and tracks ``automaton_state``, as every CraftSuite world does. The
    transition ``(w, sigma, w')`` of each step is already in ``info["automaton_transition"]``.
    """

    def __init__(self, env: gym.Env):
        gym.utils.RecordConstructorArgs.__init__(self)
        gym.ObservationWrapper.__init__(self, env)
        base = env.unwrapped
        if not hasattr(base, "automaton") or not hasattr(base, "automaton_state"):
            raise TypeError(f"{base!r} tracks no automaton: AutomatonObservation needs a CraftSuite world")
        inner = env
        while isinstance(inner, gym.Wrapper):  # a second one-hot would lengthen the observation unnoticed
            if isinstance(inner, AutomatonObservation):
                raise ValueError("the env observes the automaton state already (made with product=True, or wrapped "
                                 "in AutomatonObservation): wrap it once")
            inner = inner.env
        space = env.observation_space
        if not isinstance(space, gym.spaces.Box) or len(space.shape) != 1:
            raise TypeError(f"AutomatonObservation needs a flat Box observation, got {space}")
        n = base.automaton.n_states
        self._one_hot = np.eye(n, dtype=space.dtype)
        self.observation_space = gym.spaces.Box(
            np.concatenate([space.low, np.zeros(n, space.dtype)]),
            np.concatenate([space.high, np.ones(n, space.dtype)]),
            dtype=space.dtype,
        )

    def observation(self, observation):
        return np.concatenate((observation, self._one_hot[self.env.unwrapped.automaton_state]))
