"""The envs a population collects from and is evaluated in: one vector env of K x n envs
(member k owns envs k*n .. k*n + n - 1), the world's native vector env where it has one
(``gymnasium.make_vec(..., vectorization_mode="vector_entry_point")``), else gymnasium's
``SyncVectorEnv``; gymnasium's same-step autoreset either way, so that a step that ends an
episode still hands back its last observation (``final_obs``) for the replay."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode


def make_envs(env_id: str, num_envs: int, env_kwargs: dict, product: bool) -> gym.vector.VectorEnv:
    import craftsuite  # noqa: F401  (registers the ids)

    kwargs = {**env_kwargs, "product": product}
    vector_kwargs = {"autoreset_mode": AutoresetMode.SAME_STEP}
    if gym.spec(env_id).vector_entry_point is not None:  # a native vector env takes them as keywords
        return gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                            **vector_kwargs, **kwargs)
    return gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="sync", vector_kwargs=vector_kwargs, **kwargs)


def step_records(info: dict, ended: np.ndarray, next_obs: np.ndarray):
    """From a same-step-autoreset step's ``info``: the real next observations (the final one
    where an episode ended), the automaton transitions ``(N, 3)`` and success flags of the
    steps that ended an episode."""
    real_next = next_obs.copy()
    n = len(next_obs)
    final = info.get("final_info", {})
    if ended.any():
        final_obs = info["final_obs"]
        for i in np.flatnonzero(ended):
            real_next[i] = final_obs[i]
    transitions = _transitions(info, n)
    if ended.any():
        ended_transitions = _transitions(final, n)
        transitions[ended] = ended_transitions[ended]
    success = np.zeros(n, dtype=bool)
    if ended.any():
        success[ended] = np.asarray(final["is_success"], dtype=bool)[ended]
    return real_next, transitions, success


def _transitions(info: dict, n: int) -> np.ndarray:
    """``(N, 3)`` int64 ``(w, sigma, w')``: the native vector envs' ``transition`` array,
    or the single worlds' tuples as SyncVectorEnv gathers them."""
    if "transition" in info:
        return np.asarray(info["transition"], dtype=np.int64).reshape(n, 3).copy()
    out = np.zeros((n, 3), dtype=np.int64)
    for i, t in enumerate(info.get("automaton_transition", [None] * n)):
        if t is not None:
            out[i] = t
    return out
