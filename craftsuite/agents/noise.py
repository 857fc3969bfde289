"""Exploration noise for the TD3 students, chosen by data (a JSON-able spec) so that run
configs, suites and ``--hyper`` can name it:

    {"type": "normal", "sigma": 0.3}                        N(0, sigma) per step (the default)
    {"type": "ou", "sigma": 0.3}                            SB3's Ornstein-Uhlenbeck process
    {"type": "persistent", "sigma": 0.6, "resample": 0.1}   one draw held for ~1/resample steps
"""

from __future__ import annotations

import numpy as np
from stable_baselines3.common.noise import (ActionNoise, NormalActionNoise, OrnsteinUhlenbeckActionNoise,
                                            VectorizedActionNoise)


class PersistentActionNoise(ActionNoise):
    """One N(0, sigma) draw held across steps, redrawn with probability ``resample`` per
    step and at every reset: straight runs of about 1 / resample steps, where white noise
    jitters the point mass in place (its 0.2 s time constant averages it out; measured in
    ``experiments/td3-horizon-exploration-reach``, "Exploration")."""

    def __init__(self, sigma: float, resample: float, dim: int = 2, seed: int = 0):
        if not sigma >= 0:
            raise ValueError(f"sigma must be >= 0, got {sigma!r}")
        if not 0 < resample <= 1:
            raise ValueError(f"resample is a probability per step in (0, 1], got {resample!r}")
        self.sigma, self.resample, self.dim = sigma, resample, dim
        self.rng = np.random.default_rng(seed)
        self.reset()

    def reset(self) -> None:
        self.eps = self.rng.normal(0.0, self.sigma, self.dim)

    def __call__(self) -> np.ndarray:
        if self.rng.random() < self.resample:
            self.eps = self.rng.normal(0.0, self.sigma, self.dim)
        return self.eps.copy()

    def __repr__(self) -> str:
        return f"PersistentActionNoise(sigma={self.sigma}, resample={self.resample})"


NOISES = {"normal": ("sigma",), "ou": ("sigma",), "persistent": ("sigma", "resample")}


def make_action_noise(spec: dict, dim: int, seed: int = 0, n_envs: int = 1) -> ActionNoise:
    """The ``ActionNoise`` a spec (see the module docstring) names, for ``dim`` actions
    in each of ``n_envs`` envs: one independent process per env. (SB3 vectorises a single
    noise by deep copies, which would give every env the same persistent draws.)"""
    if not isinstance(spec, dict) or spec.get("type") not in NOISES:
        raise ValueError(f"action_noise must be an ActionNoise or a spec {{'type': one of {', '.join(sorted(NOISES))}, "
                         f"'sigma': ...}}, got {spec!r}")
    kind, params = spec["type"], {k: v for k, v in spec.items() if k != "type"}
    missing = [k for k in NOISES[kind] if k not in params]
    unknown = [k for k in params if k not in NOISES[kind]]
    if missing or unknown:
        wrong = [f"missing {', '.join(missing)}"] if missing else []
        wrong += [f"unknown {', '.join(map(str, unknown))}"] if unknown else []
        raise ValueError(f"action_noise {kind!r} takes {', '.join(NOISES[kind])}; {', '.join(wrong)}: {spec!r}")
    try:
        params = {k: float(v) for k, v in params.items()}
    except (TypeError, ValueError):
        raise ValueError(f"action_noise {kind!r} takes numbers: {spec!r}") from None
    if not params["sigma"] >= 0:
        raise ValueError(f"sigma must be >= 0, got {params['sigma']!r}")

    def one(i: int) -> ActionNoise:
        if kind == "persistent":
            return PersistentActionNoise(params["sigma"], params["resample"], dim, seed + 7919 * i)
        noise = NormalActionNoise if kind == "normal" else OrnsteinUhlenbeckActionNoise
        return noise(np.zeros(dim), params["sigma"] * np.ones(dim))

    if n_envs == 1:
        return one(0)
    vectorized = VectorizedActionNoise(one(0), n_envs)
    vectorized.noises = [one(i) for i in range(n_envs)]
    return vectorized
