"""The envs a population collects from and is evaluated in: one native vector env of K x n
envs (member k owns envs k*n .. k*n + n - 1; ``gymnasium.make_vec(...,
vectorization_mode="vector_entry_point")``, which every CraftSuite id has), with gymnasium's
same-step autoreset, so that a step that ends an episode still hands back its last
observation (``final_obs``) for the replay."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode


def make_envs(env_id: str, num_envs: int, env_kwargs: dict, product: bool) -> gym.vector.VectorEnv:
    import craftsuite  # noqa: F401  (registers the ids)

    return gym.make_vec(env_id, num_envs=num_envs, vectorization_mode="vector_entry_point",
                        autoreset_mode=AutoresetMode.SAME_STEP, product=product, **env_kwargs)


def step_records(info: dict, ended: np.ndarray, next_obs: np.ndarray):
    """From a same-step-autoreset step's ``info``: the real next observations (the final one
    where an episode ended), the automaton transitions ``(N, 3)`` (the native vector envs'
    ``info["transition"]``, the final step's where an episode ended) and whether each env's
    episode ended in success."""
    real_next = next_obs
    success = np.zeros(len(next_obs), dtype=bool)
    if ended.any():
        real_next = next_obs.copy()
        final_obs = info["final_obs"]
        for i in np.flatnonzero(ended):
            real_next[i] = final_obs[i]
        success[ended] = np.asarray(info["final_info"]["is_success"], dtype=bool)[ended]
    return real_next, info["transition"], success


def observation_planes(env_id: str, env_kwargs: dict, product: bool, settings: dict) -> tuple[int, int, int] | None:
    """The grid planes ``(C, H, W)`` a residual CNN reads in ``env_id``'s observations
    (``observation_layout``), where ``settings`` ask for one; None otherwise.

    Raises:
        ValueError: a residual CNN asked for in a world without planes (not a grid).
    """
    if settings.get("features_extractor", "flatten") != "residual-cnn":
        return None
    env = gym.make(env_id, product=product, **env_kwargs)
    try:
        layout = getattr(env.unwrapped, "observation_layout", None)
    finally:
        env.close()
    if not isinstance(layout, dict) or "planes" not in layout:
        raise ValueError(f"features_extractor 'residual-cnn' reads grid planes; {env_id} has none "
                         "(it is for the grid worlds)")
    return tuple(layout["planes"])
