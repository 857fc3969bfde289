"""Replay with automaton fields and prioritized sampling, for SB3's off-policy algorithms.

``AutomatonReplayBuffer`` is an SB3 ``ReplayBuffer`` that also keeps, per transition, the
automaton transition ``(w, sigma, w')`` that the world put in ``info["automaton_transition"]``
(SB3 hands ``add`` the infos of the step, including the terminal step of an episode under
autoreset), and samples by priority: P(i) ~ p_i ** alpha, importance weights
(N P(i)) ** -beta normalised by their maximum, new transitions at the maximum priority.
With ``n_steps`` > 1 it samples n-step returns as SB3's ``NStepReplayBuffer`` does: the
discounted rewards up to n steps or the episode's end, the observation there, and the
discount ``gamma ** k`` for its bootstrap, in ``discounts``; the automaton fields and
priorities stay those of the first transition.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import torch as th
from gymnasium import spaces
from stable_baselines3.common.buffers import ReplayBuffer


class AutomatonSamples(NamedTuple):
    observations: th.Tensor
    actions: th.Tensor
    next_observations: th.Tensor
    dones: th.Tensor
    rewards: th.Tensor
    discounts: th.Tensor | None
    weights: th.Tensor  # importance weights (ones when sampling uniformly), shape (B, 1)
    indices: np.ndarray  # flat buffer indices, for update_priorities
    w: np.ndarray  # automaton state before the step
    sigma: np.ndarray  # label mask of the step
    w_next: np.ndarray  # automaton state after the step


class SumTree:
    """Priorities in a binary sum tree: O(log n) updates and proportional sampling, batched."""

    def __init__(self, capacity: int):
        self.leaves = 1 << max(0, int(np.ceil(np.log2(max(capacity, 1)))))
        self.tree = np.zeros(2 * self.leaves)

    def total(self) -> float:
        return float(self.tree[1])

    def update(self, indices: np.ndarray, values: np.ndarray) -> None:
        nodes = np.asarray(indices, dtype=np.int64).reshape(-1) + self.leaves
        tree = self.tree
        if len(nodes) == 1:  # one new transition per env step: plain Python is fastest
            node = int(nodes[0])
            tree[node] = float(np.asarray(values).reshape(-1)[0])
            node //= 2
            while node:
                tree[node] = tree[2 * node] + tree[2 * node + 1]
                node //= 2
            return
        tree[nodes] = values
        while nodes[0] > 1:  # all leaves sit at one depth: climb level by level
            nodes //= 2
            tree[nodes] = tree[2 * nodes] + tree[2 * nodes + 1]  # repeats write equal sums

    def find(self, targets: np.ndarray) -> np.ndarray:
        """Leaf index whose cumulative-sum interval contains each target."""
        nodes = np.ones(len(targets), dtype=np.int64)
        targets = targets.copy()
        while nodes[0] < self.leaves:
            left = 2 * nodes
            go_right = targets >= self.tree[left]
            targets = np.where(go_right, targets - self.tree[left], targets)
            nodes = np.where(go_right, left + 1, left)
        return nodes - self.leaves


class AutomatonReplayBuffer(ReplayBuffer):
    """SB3 replay buffer + ``(w, sigma, w')`` per transition + optional prioritized sampling.

    Args (beyond SB3's):
        prioritized: sample by priority (else uniformly, with unit weights).
        alpha: priority exponent (0.7 in the paper's code).
        beta: importance-weight exponent.
        epsilon: added to |TD error| when priorities are updated (0.1 in the paper's code).
        n_steps: return length (1: one-step samples, ``discounts`` None).
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
        self.prioritized = prioritized
        self.alpha, self.beta, self.epsilon = alpha, beta, epsilon
        self.tree = SumTree(self.buffer_size * self.n_envs) if prioritized else None
        self.max_priority = 1.0

    _ROWS = ("observations", "next_observations", "actions", "rewards", "dones", "timeouts", "w", "sigma", "w_next")

    def __getstate__(self) -> dict:
        """Pickle only the filled rows: a checkpoint of a 20k-step run holds 20k rows, not
        the 1M that SB3 allocates up front."""
        state = self.__dict__.copy()
        if not self.full:
            rows = self.pos + 1 if self.optimize_memory_usage else self.pos  # next obs live at row pos
            for name in self._ROWS:
                if isinstance(state.get(name), np.ndarray):
                    state[name] = state[name][:rows].copy()
        return state

    def __setstate__(self, state: dict) -> None:
        state = {"n_steps": 1, "gamma": 0.99, **state}  # checkpoints from before n-step returns
        self.__dict__.update(state)
        for name in self._ROWS:
            rows = getattr(self, name, None)
            if isinstance(rows, np.ndarray) and len(rows) < self.buffer_size:
                full = np.zeros((self.buffer_size, *rows.shape[1:]), dtype=rows.dtype)
                full[:len(rows)] = rows
                setattr(self, name, full)

    def add(self, obs, next_obs, action, reward, done, infos: list[dict[str, Any]]) -> None:
        pos = self.pos
        for env, info in enumerate(infos):
            try:
                self.w[pos, env], self.sigma[pos, env], self.w_next[pos, env] = info["automaton_transition"]
            except (KeyError, TypeError, ValueError):
                raise ValueError(
                    "AutomatonReplayBuffer needs info['automaton_transition'] = (w, sigma, w') from every "
                    "step: use a CraftSuite world (any id, product=True for an automaton-aware policy)"
                ) from None
        if self.tree is not None:
            priority = self.max_priority ** self.alpha
            for env in range(self.n_envs):
                self.tree.update(np.array([pos * self.n_envs + env]), np.array([priority]))
        super().add(obs, next_obs, action, reward, done, infos)

    def sample(self, batch_size: int, env=None) -> AutomatonSamples:
        size = self.buffer_size if self.full else self.pos
        if size == 0:
            raise RuntimeError("cannot sample from an empty replay buffer")
        if self.tree is None:
            flat = np.random.randint(0, size * self.n_envs, size=batch_size)
            weights = np.ones(batch_size, dtype=np.float32)
        else:
            total = self.tree.total()
            targets = (np.arange(batch_size) + np.random.random(batch_size)) * (total / batch_size)
            flat = np.minimum(self.tree.find(np.minimum(targets, total * (1 - 1e-12))), size * self.n_envs - 1)
            probs = self.tree.tree[flat + self.tree.leaves] / total
            weights = (size * self.n_envs * probs) ** (-self.beta)
            weights = (weights / weights.max()).astype(np.float32)
        return self._samples(flat, weights, env)

    def _samples(self, flat: np.ndarray, weights: np.ndarray, env=None) -> AutomatonSamples:
        batch, envs = np.divmod(flat, self.n_envs)
        if self.n_steps > 1:
            last, rewards, discounts = self._n_step(batch, envs, env)
        else:
            last, discounts = batch, None
            rewards = self._normalize_reward(self.rewards[batch, envs], env)
        if self.optimize_memory_usage:
            next_obs = self.observations[(batch + 1) % self.buffer_size, envs, :]
        else:
            next_obs = self.next_observations[last, envs, :]
        dones = self.dones[last, envs] * (1 - self.timeouts[last, envs])
        tensors = tuple(map(self.to_torch, (
            self._normalize_obs(self.observations[batch, envs, :], env),
            self.actions[batch, envs, :],
            self._normalize_obs(next_obs, env),
            dones.reshape(-1, 1),
            rewards.reshape(-1, 1),
        )))
        return AutomatonSamples(*tensors, None if discounts is None else self.to_torch(discounts.reshape(-1, 1)),
                                self.to_torch(weights.reshape(-1, 1)), flat,
                                self.w[batch, envs], self.sigma[batch, envs], self.w_next[batch, envs])

    def _n_step(self, batch: np.ndarray, envs: np.ndarray, env=None):
        """For each sampled row: the row that ends its n-step window (at an episode's end, or
        at the newest row, whose successor is not written yet), the discounted rewards up
        to it, and ``gamma ** k`` for the bootstrap after its k rows."""
        rows = (batch[:, None] + np.arange(self.n_steps)) % self.buffer_size
        ends = (self.dones[rows, envs[:, None]] > 0) | (self.timeouts[rows, envs[:, None]] > 0)
        ends |= rows == (self.pos - 1) % self.buffer_size
        k = np.where(ends.any(axis=1), ends.argmax(axis=1), self.n_steps - 1) + 1
        inside = np.arange(self.n_steps) < k[:, None]
        rewards = self._normalize_reward(self.rewards[rows, envs[:, None]], env)
        returns = (rewards * inside * self.gamma ** np.arange(self.n_steps)).sum(axis=1)
        return rows[np.arange(len(batch)), k - 1], returns.astype(np.float32), (self.gamma ** k).astype(np.float32)

    def update_priorities(self, indices: np.ndarray, td_errors: np.ndarray) -> None:
        """New priorities |TD error| + epsilon for the sampled transitions."""
        if self.tree is None:
            return
        priorities = np.abs(np.asarray(td_errors, dtype=np.float64).reshape(-1)) + self.epsilon
        self.max_priority = max(self.max_priority, float(priorities.max()))
        self.tree.update(indices, priorities ** self.alpha)


def automaton_buffer_kwargs(prioritized: bool, n_steps: int, gamma: float, given: dict | None) -> dict:
    """The keywords of an ``AutomatonReplayBuffer`` built by ``AutomatonDQN`` or
    ``AutomatonTD3``: ``n_steps`` is the algorithm's own setting (SB3's ``model.n_steps``),
    so that what the model says is what its buffer does; ``given`` may not say otherwise."""
    given = dict(given or {})
    if given.get("n_steps", n_steps) != n_steps:
        raise ValueError(f"n_steps is the algorithm's setting: pass n_steps={given['n_steps']}, "
                         f"not replay_buffer_kwargs={{'n_steps': ...}} (the algorithm's is {n_steps})")
    return {"prioritized": prioritized, "n_steps": n_steps, "gamma": gamma, **given}
