"""The replay of a saved CraftSuite agent: an SB3 ``ReplayBuffer`` that also keeps, per
transition, the automaton transition ``(w, sigma, w')``, and the keywords of prioritized
replay and n-step returns (``prioritized, alpha, beta, epsilon, n_steps, gamma``).

A saved ``AutomatonDQN``/``AutomatonTD3`` names this class and its keywords, so loading one
builds it; a replay pickled by the SB3 trainer (``replay.pkl`` of an old teacher run) is
read back here, for ``craftsuite distill``. Sampling by priority, n-step windows and CRM's
counterfactuals are the population engine's (``craftsuite.population.replay``); loaded with
SB3's own ``DQN``/``TD3``, a model adds and samples as SB3's buffer does, and
``save_replay_buffer`` pickles it whole as it does SB3's (nothing in CraftSuite saves one:
the engine checkpoints its own replay).
"""

from __future__ import annotations

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer


class SumTree:
    """The priorities in a replay the SB3 trainer pickled (a teacher's ``replay.pkl``), as a
    binary sum tree (leaves from ``leaves`` on). Such a pickle names this class, so it stays
    importable here; a buffer built now holds none."""

    def __init__(self, capacity: int):
        self.leaves = 1 << max(0, int(np.ceil(np.log2(max(capacity, 1)))))
        self.tree = np.zeros(2 * self.leaves)


class AutomatonReplayBuffer(ReplayBuffer):
    """SB3 replay buffer + ``(w, sigma, w')`` per transition (``w``, ``sigma``, ``w_next``).

    Args (beyond SB3's), as the model was trained with:
        prioritized: sampled by priority (else uniformly).
        alpha: priority exponent (0.7 in the paper's code).
        beta: importance-weight exponent.
        epsilon: added to |TD error| when priorities are updated (0.1 in the paper's code).
        n_steps: return length (1: one-step).
        gamma: the discount of n-step returns (the algorithm's).
    """

    def __init__(self, buffer_size: int, observation_space: spaces.Space, action_space: spaces.Space,
                 device: th.device | str = "auto", n_envs: int = 1, optimize_memory_usage: bool = False,
                 handle_timeout_termination: bool = True, prioritized: bool = True,
                 alpha: float = 0.7, beta: float = 0.4, epsilon: float = 0.1, n_steps: int = 1, gamma: float = 0.99):
        if not isinstance(n_steps, int) or isinstance(n_steps, bool) or n_steps < 1:
            raise ValueError(f"n_steps must be a positive integer, got {n_steps!r}")
        if n_steps > 1 and optimize_memory_usage:
            raise ValueError("n-step returns need next_observations: n_steps > 1 with optimize_memory_usage=True")
        super().__init__(buffer_size, observation_space, action_space, device, n_envs,
                         optimize_memory_usage=optimize_memory_usage,
                         handle_timeout_termination=handle_timeout_termination)
        self.n_steps, self.gamma = n_steps, gamma
        self.w = np.zeros((self.buffer_size, self.n_envs), dtype=np.int32)
        self.sigma = np.zeros((self.buffer_size, self.n_envs), dtype=np.int32)
        self.w_next = np.zeros((self.buffer_size, self.n_envs), dtype=np.int32)
        # what the model was trained with, kept as settings only: nothing here samples by priority
        self.prioritized = prioritized
        self.alpha, self.beta, self.epsilon = alpha, beta, epsilon

    _ROWS = ("observations", "next_observations", "actions", "rewards", "dones", "timeouts", "w", "sigma", "w_next")

    def __setstate__(self, state: dict) -> None:
        """An SB3 run's ``replay.pkl`` holds only its filled rows: the rest are made again."""
        state = {"n_steps": 1, "gamma": 0.99, **state}  # checkpoints from before n-step returns
        self.__dict__.update(state)
        for name in self._ROWS:
            rows = getattr(self, name, None)
            if isinstance(rows, np.ndarray) and len(rows) < self.buffer_size:
                full = np.zeros((self.buffer_size, *rows.shape[1:]), dtype=rows.dtype)
                full[:len(rows)] = rows
                setattr(self, name, full)


def automaton_buffer_kwargs(prioritized: bool, n_steps: int, gamma: float, given: dict | None) -> dict:
    """The keywords of an ``AutomatonReplayBuffer`` built by ``AutomatonDQN`` or
    ``AutomatonTD3``: ``n_steps`` is the algorithm's own setting (SB3's ``model.n_steps``),
    so that what the model says is what its buffer does; ``given`` may not say otherwise."""
    given = dict(given or {})
    if given.get("n_steps", n_steps) != n_steps:
        raise ValueError(f"n_steps is the algorithm's setting: pass n_steps={given['n_steps']}, "
                         f"not replay_buffer_kwargs={{'n_steps': ...}} (the algorithm's is {n_steps})")
    return {"prioritized": prioritized, "n_steps": n_steps, "gamma": gamma, **given}
