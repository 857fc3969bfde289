"""Replay for K members at once: preallocated arrays with a leading member axis, a sum tree
per member in one array, and CRM's counterfactuals made when a batch is sampled.

Each member's transitions sit at the same positions of its own slice, written in step
(members collect in lockstep), in the order SB3's buffer uses: a step of ``n_envs`` envs
fills ``n_envs`` consecutive positions. Sampling is uniform, or
stratified by priority p ** alpha with importance weights (N P(i)) ** -beta over their
maximum, new transitions at the maximum priority seen.

With ``n_steps`` > 1 a sample is an n-step return, as SB3's ``NStepReplayBuffer`` makes one: the
discounted rewards of up to n steps of the same env (the next step of env j sits
``n_envs`` positions on), stopping at the episode's end (terminated or truncated) and at
the newest step written (what lies after it is unwritten, or the oldest steps once the
replay has wrapped), the next observation and terminal of the window's last step, and
``gamma ** k`` after its k rewards in ``discounts``. The automaton pair (w, sigma), the
priority and the importance weight stay the first step's.

CRM (``crm=CounterfactualView(...)``) stores each real step once, with its automaton
transition ``(w, sigma, w')``. A leaf of the sum tree is a (step, live automaton state u)
pair; sampling leaf (i, u) rewrites step i as read from u: the observation's one-hot, u' =
delta(u, sigma), the reward with u's completion bonus for the real one, an end where u'
accepts or is rejecting (Toro Icarte et al., JAIR 2022). Memory
grows with the steps, not with the steps times the automaton's states. With ``n_steps`` > 1
(n-step CRM), u is carried through the window's stored labels: each step pays the world's
reward and u's completion bonus, and the window stops where the automaton from u accepts or
is rejecting (then terminal), as one-step CRM ends a step, or where the real stream stops
(an episode's end or the newest step: then u's own end decides, as for one step).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import torch as th

from ..automata import Automaton


class Batch(NamedTuple):
    """One minibatch per member, each array ``(K, B, ...)``."""

    observations: np.ndarray  # or SparseRows
    actions: np.ndarray
    next_observations: np.ndarray  # or SparseRows
    rewards: np.ndarray  # (K, B) float32
    terminals: np.ndarray  # (K, B) float32: 1 where the step ended the episode (not a time limit)
    weights: np.ndarray  # (K, B) float32: importance weights (ones when uniform)
    leaves: np.ndarray  # (K, B) int64: what update_priorities takes back
    w: np.ndarray  # (K, B) automaton state the target reads (u for a counterfactual)
    sigma: np.ndarray  # (K, B) label of the step
    # (K, B) float32: gamma ** k, the bootstrap's discount after an n-step sample's k
    # rewards; None for one-step samples (the learner's gamma), as the SB3 buffer's
    discounts: np.ndarray | None = None


class SparseRows(NamedTuple):
    """Observations as their nonzero entries: ``index`` and ``value`` ``(..., width)``,
    ascending, padded with index 0 and value 0. A grid's observation (one-hot planes, a
    few inventory counts, the automaton one-hot) has a few dozen nonzeros in hundreds of
    entries: stored so, it takes a tenth of the memory, and a network's first layer reads
    it as a sum of a few weight rows (``nets.StackedMLP``) instead of a dense product."""

    index: np.ndarray  # int64
    value: np.ndarray  # float32


def sparse_rows(dense: np.ndarray, width: int) -> SparseRows:
    """The nonzero entries of each row of ``dense`` ``(..., d)``, padded to ``width``.

    Raises:
        ValueError: a row with more than ``width`` nonzeros.
    """
    nonzero = dense != 0
    most = int(nonzero.sum(axis=-1).max(initial=0))
    if most > width:
        raise ValueError(f"an observation has {most} nonzero entries, more than the {width} the replay stores")
    order = np.argsort(~nonzero, axis=-1, kind="stable")[..., :width]  # nonzero columns first, ascending
    value = np.take_along_axis(dense, order, axis=-1).astype(np.float32)
    index = np.where(value != 0, order, 0)
    return SparseRows(index.astype(np.int64), value)


def one_hot_at(rows: SparseRows, column: np.ndarray) -> SparseRows:
    """``rows`` whose last nonzero entry (the automaton state's one-hot, the observation's
    last columns) moves to ``column``."""
    last = (rows.value != 0).sum(axis=-1) - 1
    index = rows.index.copy()
    np.put_along_axis(index, last[..., None], np.asarray(column)[..., None], axis=-1)
    return SparseRows(index, rows.value)


class SumTrees:
    """One binary sum tree per member, all in one flat array (member k's tree at
    ``k * 2 * leaves``): updates and proportional sampling for every member in the same
    one-dimensional numpy operations (two-dimensional fancy indexing costs several times more)."""

    def __init__(self, members: int, capacity: int):
        self.members = members
        self.leaves = 1 << max(0, int(np.ceil(np.log2(max(capacity, 1)))))
        self.flat = np.zeros(members * 2 * self.leaves)
        self._base = (np.arange(members) * 2 * self.leaves)[:, None]

    @property
    def tree(self) -> np.ndarray:
        """The trees as ``(K, 2 * leaves)`` (a view): node 1 is each member's root."""
        return self.flat.reshape(self.members, 2 * self.leaves)

    def total(self) -> np.ndarray:
        return self.flat[self._base[:, 0] + 1]

    def update(self, leaves: np.ndarray, values: np.ndarray) -> None:
        """Set ``values`` at ``leaves``, both ``(K, M)`` (or broadcastable)."""
        leaves = np.asarray(leaves, dtype=np.int64)
        base = np.broadcast_to(self._base, leaves.shape).ravel()
        nodes = leaves.ravel() + self.leaves
        flat = self.flat
        flat[base + nodes] = np.broadcast_to(values, leaves.shape).ravel()
        while nodes[0] > 1:  # every leaf sits at one depth: climb level by level
            nodes = nodes >> 1
            left = base + 2 * nodes
            flat[base + nodes] = flat[left] + flat[left + 1]  # repeats write equal sums

    def find(self, targets: np.ndarray) -> np.ndarray:
        """For ``(K, B)`` targets, the leaf whose cumulative interval holds each."""
        shape = targets.shape
        base = np.broadcast_to(self._base, shape).ravel()
        targets = targets.ravel().copy()
        nodes = np.ones(len(targets), dtype=np.int64)
        flat = self.flat
        while nodes[0] < self.leaves:
            left = 2 * nodes
            mass = flat[base + left]
            right = targets >= mass
            targets -= mass * right
            nodes = left + right
        return (nodes - self.leaves).reshape(shape)

    def values(self, leaves: np.ndarray) -> np.ndarray:
        return self.flat[np.broadcast_to(self._base, leaves.shape) + leaves + self.leaves]


class CounterfactualView:
    """CRM's reading of one real step from every live automaton state (see the module
    docstring). ``n_states`` one-hot entries end each observation."""

    def __init__(self, automaton: Automaton, completion_reward: float, obs_dim: int):
        self.obs_dim = obs_dim
        self.delta = automaton.delta.astype(np.int64)
        self.accepting = automaton.accepting.astype(np.float32)
        self.ends = (automaton.accepting | automaton.rejecting).astype(np.float32)
        self.live = np.flatnonzero(~(automaton.accepting | automaton.rejecting))
        self.n_states, self.completion = automaton.n_states, float(completion_reward)
        self._eye = np.eye(self.n_states, dtype=np.float32)

    @property
    def n_live(self) -> int:
        return len(self.live)

    def world_reward(self, rewards, w, sigma):
        """The world's part of real rewards (steps, items): without the completion bonus.
        Stored instead of the reward, so that a float32 replay does not hold 99.9 for -0.1."""
        return rewards - self.completion * self.accepting[self.delta[w, sigma]]

    def relabel(self, obs, next_obs, world_rewards, sigma, j):
        """A stored step (obs, next_obs, world reward, sigma) as read from live state
        ``live[j]``: (obs, next_obs, rewards, terminals, u)."""
        u = self.live[j]
        u_next = self.delta[u, sigma]
        obs, next_obs = self.with_states(obs, next_obs, u, u_next)
        rewards = world_rewards.astype(np.float64) + self.completion * self.accepting[u_next]
        return obs, next_obs, rewards.astype(np.float32), self.ends[u_next], u

    def window(self, world_rewards, sigma, real_ends, j, gamma: float):
        """An n-step window of stored steps ``(K, B, n)`` (world rewards, labels, and where
        the real stream stops: an episode's end or the newest step) as read from live state
        ``live[j]``: the automaton carried from u through the window's labels pays each
        step's completion bonus and ends the window where it accepts or is rejecting, as
        one-step CRM ends a step. Returns (k: the steps taken, the discounted return,
        terminals, u, the automaton state after the k-th step)."""
        u = u_after = self.live[j]
        n = sigma.shape[-1]
        k = np.full(u.shape, n)
        returns = np.zeros(u.shape)
        terminals = np.zeros(u.shape, dtype=np.float32)
        going = np.ones(u.shape, dtype=bool)
        state = u
        for t in range(n):
            state = self.delta[state, sigma[..., t]]
            returns += going * gamma ** t * (world_rewards[..., t] + self.completion * self.accepting[state])
            u_after = np.where(going, state, u_after)
            ends_here = self.ends[state] > 0
            stop = going & (ends_here | real_ends[..., t])
            k = np.where(stop, t + 1, k)
            terminals = np.where(stop, ends_here, terminals).astype(np.float32)
            going &= ~stop
        return k, returns.astype(np.float32), terminals, u, u_after

    def with_states(self, obs, next_obs, u, u_next):
        """Observations whose automaton one-hot reads ``u`` (and ``u_next`` after the step)."""
        if isinstance(obs, SparseRows):
            first = self.obs_dim - self.n_states
            return one_hot_at(obs, first + u), one_hot_at(next_obs, first + u_next)
        obs[..., -self.n_states:] = self._eye[u]
        next_obs[..., -self.n_states:] = self._eye[u_next]
        return obs, next_obs


def _check_n_steps(n_steps) -> None:
    """Raise ValueError naming a return length the replay cannot sample."""
    if not isinstance(n_steps, int) or isinstance(n_steps, bool) or n_steps < 1:
        raise ValueError(f"n_steps must be a positive integer, got {n_steps!r}")


class PopulationReplay:
    """Every member's replay, ``capacity`` transitions each (SB3's rounding: whole steps of
    ``n_envs``). ``actions`` are ``action_shape`` of ``action_dtype`` per transition. With
    ``sparse_width``, observations are stored and sampled as ``SparseRows`` of that width
    (at least the most nonzero entries an observation of the world can have). ``n_steps``
    and ``gamma``: n-step returns (1: one-step samples, as before n-step returns existed).
    ``shaping`` (a ``shaping.Shaping``): every sampled reward shaped by the automaton's
    potential, from the sample's first automaton state to the state after its last step."""

    def __init__(self, members: int, capacity: int, n_envs: int, obs_dim: int, action_shape: tuple,
                 action_dtype=np.float32, *, prioritized: bool = True, alpha: float = 0.7, beta: float = 0.4,
                 epsilon: float = 0.1, crm: CounterfactualView | None = None, seed: int = 0,
                 sparse_width: int | None = None, n_steps: int = 1, gamma: float = 0.99, shaping=None):
        _check_n_steps(n_steps)
        if shaping is not None and crm is not None:
            raise ValueError("reward shaping and CRM: no method combines them, and their rewards are not composed")
        self.shaping = shaping  # a shaping.Shaping: sampled rewards shaped by the automaton's potential
        self.members, self.n_envs = members, n_envs
        self.capacity = max(capacity // n_envs, 1) * n_envs
        K, C = members, self.capacity
        self.sparse_width = sparse_width
        if sparse_width is None:
            self._observation_arrays = ("observations", "next_observations")
            self.observations = np.zeros((K, C, obs_dim), dtype=np.float32)
            self.next_observations = np.zeros((K, C, obs_dim), dtype=np.float32)
        else:
            self._observation_arrays = ("obs_index", "obs_value", "next_index", "next_value")
            for name in ("obs", "next"):
                setattr(self, f"{name}_index", np.zeros((K, C, sparse_width), dtype=np.int64))
                setattr(self, f"{name}_value", np.zeros((K, C, sparse_width), dtype=np.float32))
        self.actions = np.zeros((K, C, *action_shape), dtype=action_dtype)
        self.rewards = np.zeros((K, C), dtype=np.float32)
        self.terminals = np.zeros((K, C), dtype=np.float32)
        self.w = np.zeros((K, C), dtype=np.int64)
        self.sigma = np.zeros((K, C), dtype=np.int64)
        self.n_steps, self.gamma = n_steps, float(gamma)
        # where episodes ended, by the time limit too (terminals holds only the terminated):
        # n-step windows stop there. Kept only for them, so that a one-step replay, its
        # memory and its checkpoints stay as they were
        self.ended = np.zeros((K, C), dtype=bool) if n_steps > 1 else None
        self.pos, self.full = 0, False
        self.crm = crm
        self.per_step = crm.n_live if crm is not None else 1  # leaves per stored transition
        self.prioritized, self.alpha, self.beta, self.epsilon = prioritized, alpha, beta, epsilon
        self.trees = SumTrees(K, C * self.per_step) if prioritized else None
        self.max_priority = np.ones(K)
        self.rng = np.random.default_rng(seed)
        self._rows = np.arange(K)[:, None]

    @property
    def nbytes(self) -> int:
        """The bytes every member's replay holds once full: its arrays get their memory as
        transitions are written, so a run's memory grows to this over its budget."""
        held = sum(getattr(self, name).nbytes for name in self._arrays)
        return held + (self.trees.flat.nbytes if self.trees is not None else 0)

    @property
    def size(self) -> int:
        """Transitions stored per member."""
        return self.capacity if self.full else self.pos

    def add(self, obs, next_obs, actions, rewards, terminals, w, sigma, ended=None) -> None:
        """One step of every member's ``n_envs`` envs: arrays ``(K, n_envs, ...)``. ``ended``:
        where the step ended an episode, terminated or truncated (an n-step replay needs it;
        a one-step replay ignores it)."""
        at = slice(self.pos, self.pos + self.n_envs)
        if self.ended is not None:
            if ended is None:
                raise ValueError("an n-step replay needs to know where episodes ended: pass ended "
                                 "(terminated or truncated) to add")
            self.ended[:, at] = ended
        if self.sparse_width is None:
            self.observations[:, at] = obs
            self.next_observations[:, at] = next_obs
        else:
            self.obs_index[:, at], self.obs_value[:, at] = sparse_rows(np.asarray(obs), self.sparse_width)
            self.next_index[:, at], self.next_value[:, at] = sparse_rows(np.asarray(next_obs), self.sparse_width)
        self.actions[:, at] = np.asarray(actions).reshape(self.members, self.n_envs, *self.actions.shape[2:])
        self.rewards[:, at] = rewards if self.crm is None else self.crm.world_reward(
            np.asarray(rewards, dtype=np.float64), np.asarray(w), np.asarray(sigma))
        self.terminals[:, at] = terminals
        self.w[:, at] = w
        self.sigma[:, at] = sigma
        if self.trees is not None:
            first = self.pos * self.per_step
            leaves = np.broadcast_to(np.arange(first, first + self.n_envs * self.per_step), (self.members,
                                                                                           self.n_envs * self.per_step))
            self.trees.update(leaves, np.broadcast_to((self.max_priority ** self.alpha)[:, None], leaves.shape))
        self.pos += self.n_envs
        if self.pos == self.capacity:
            self.full, self.pos = True, 0

    def sample(self, batch_size: int) -> Batch:
        size = self.size
        if size == 0:
            raise RuntimeError("cannot sample from an empty replay")
        K, leaves_in_use = self.members, size * self.per_step
        if self.trees is None:
            leaves = self.rng.integers(0, leaves_in_use, size=(K, batch_size))
            weights = np.ones((K, batch_size), dtype=np.float32)
        else:
            total = self.trees.total()[:, None]
            targets = (np.arange(batch_size) + self.rng.random((K, batch_size))) * (total / batch_size)
            leaves = np.minimum(self.trees.find(np.minimum(targets, total * (1 - 1e-12))), leaves_in_use - 1)
            probs = self.trees.values(leaves) / total
            weights = (leaves_in_use * probs) ** (-self.beta)
            weights = (weights / weights.max(axis=1, keepdims=True)).astype(np.float32)
        index, j = np.divmod(leaves, self.per_step)
        first = self._flat(index)
        last, returns, discounts, window = first, None, None, None
        if self.n_steps > 1 and self.crm is not None:
            window_last, window = self._n_step_counterfactual(index, j)
            returns, discounts = window[1], (self.gamma ** window[0]).astype(np.float32)
            last = self._flat(window_last)
        elif self.n_steps > 1:
            window_last, returns, discounts = self._n_step(index)
            last = self._flat(window_last)

        def take(array, at=first):
            return array.reshape(K * self.capacity, *array.shape[2:]).take(at, axis=0).reshape(
                K, batch_size, *array.shape[2:])

        if self.sparse_width is None:
            obs, next_obs = take(self.observations), take(self.next_observations, last)
        else:
            obs = SparseRows(take(self.obs_index), take(self.obs_value))
            next_obs = SparseRows(take(self.next_index, last), take(self.next_value, last))
        rewards = take(self.rewards) if returns is None else returns
        terminals, w, sigma = take(self.terminals, last), take(self.w), take(self.sigma)
        if window is not None:
            _, _, terminals, w, u_after = window
            obs, next_obs = self.crm.with_states(obs, next_obs, w, u_after)
        elif self.crm is not None:
            obs, next_obs, rewards, terminals, w = self.crm.relabel(obs, next_obs, rewards, sigma, j)
        if self.shaping is not None:
            rewards = self.shaping(rewards, w, take(self.w, last), take(self.sigma, last), terminals, discounts)
        return Batch(obs, take(self.actions), next_obs, rewards, terminals, weights, leaves, w, sigma, discounts)

    def _flat(self, index: np.ndarray) -> np.ndarray:
        """Members' positions ``(K, ...)`` as one index into ``(K * C, ...)``: numpy's fast take."""
        rows = self._rows.reshape(-1, *([1] * (index.ndim - 1)))
        return (index + rows * self.capacity).ravel()

    def _window(self, index: np.ndarray):
        """For positions ``(K, B)``: each one's n-step window ``(K, B, n)`` of positions, as
        flat indices, and where the real stream stops in it (see ``_n_step``)."""
        n, n_envs = self.n_steps, self.n_envs
        steps = self.capacity // n_envs
        step, env = np.divmod(index, n_envs)
        window = (step[..., None] + np.arange(n)) % steps  # (K, B, n) vector steps
        positions = window * n_envs + env[..., None]
        flat = self._flat(positions).reshape(positions.shape)
        ends = self.ended.reshape(-1)[flat] | (window == (self.pos // n_envs - 1) % steps)
        return positions, flat, ends

    def _n_step_counterfactual(self, index: np.ndarray, j: np.ndarray):
        """For positions ``(K, B)`` read from live states ``j``: the position that ends each
        one's window as its automaton reads it, and ``CounterfactualView.window``'s
        (k, returns, terminals, u, u after)."""
        positions, flat, ends = self._window(index)
        window = self.crm.window(self.rewards.reshape(-1)[flat].astype(np.float64), self.sigma.reshape(-1)[flat],
                                 ends, j, self.gamma)
        last = np.take_along_axis(positions, window[0][..., None] - 1, axis=-1)[..., 0]
        return last, window

    def _n_step(self, index: np.ndarray):
        """For positions ``(K, B)``: the position that ends each one's n-step window, the
        discounted rewards up to it and ``gamma ** k`` after its k rewards.

        A position is (vector step, env): env j's next transition is ``n_envs`` positions on,
        modulo the capacity. A window stops at its episode's end (terminated or truncated),
        and at the newest vector step written: after it come unwritten positions, or, once
        the replay has wrapped, the oldest steps, which are no one's future."""
        n = self.n_steps
        positions, flat, ends = self._window(index)
        k = np.where(ends.any(axis=-1), ends.argmax(axis=-1), n - 1) + 1
        inside = np.arange(n) < k[..., None]
        # as the SB3 buffer sums them (float32 rewards times float64 discounts), then float32
        returns = (self.rewards.reshape(-1)[flat] * inside * self.gamma ** np.arange(n)).sum(axis=-1)
        last = np.take_along_axis(positions, k[..., None] - 1, axis=-1)[..., 0]
        return last, returns.astype(np.float32), (self.gamma ** k).astype(np.float32)

    def update_priorities(self, leaves: np.ndarray, td_errors: np.ndarray) -> None:
        """New priorities |TD error| + epsilon for the sampled leaves, ``(K, B)`` each."""
        if self.trees is None:
            return
        priorities = np.abs(np.asarray(td_errors, dtype=np.float64)) + self.epsilon
        self.max_priority = np.maximum(self.max_priority, priorities.max(axis=1))
        self.trees.update(leaves, priorities ** self.alpha)

    # -- checkpoints: one member's slice ----------------------------------------------------------
    _ARRAYS = ("actions", "rewards", "terminals", "w", "sigma")

    @property
    def _arrays(self) -> tuple[str, ...]:
        return self._observation_arrays + self._ARRAYS + (("ended",) if self.ended is not None else ())

    def member_state(self, k: int) -> dict:
        """Member ``k``'s filled rows, priorities and sampling position (for its checkpoint).

        The rows are tensors sharing the arrays' memory: ``torch.save`` writes a tensor's
        storage straight to the file, whereas it pickles a NumPy array whole in memory first
        (its bytes, then the pickle's string of them), so a large replay would be held several
        times over while it is saved."""
        n = self.size
        state = {name: th.from_numpy(getattr(self, name)[k, :n]) for name in self._arrays}
        state.update(pos=self.pos, full=self.full, max_priority=float(self.max_priority[k]))
        if self.trees is not None:
            priorities = self.trees.tree[k, self.trees.leaves:self.trees.leaves + n * self.per_step]
            state["priorities"] = th.from_numpy(priorities)
        return state

    def load_member(self, k: int, state: dict) -> None:
        """Member ``k`` from its ``member_state``, to resume from: its envs start fresh
        episodes, so an n-step replay ends each env's stored stream at its newest step.
        Its rows may be tensors or (an older checkpoint's) NumPy arrays."""
        state = {name: value.cpu().numpy() if th.is_tensor(value) else np.asarray(value)
                 for name, value in state.items()}
        n = len(state["rewards"])
        for name in self._arrays:
            getattr(self, name)[k, :n] = state[name]
        self.pos, self.full = int(state["pos"]), bool(state["full"])
        if self.ended is not None and n:  # else a window would run on into the next, unrelated episode
            newest = (self.pos - self.n_envs) % self.capacity
            self.ended[k, newest:newest + self.n_envs] = True
        self.max_priority[k] = state["max_priority"]
        if self.trees is not None and "priorities" in state:
            priorities = state["priorities"]
            single = SumTrees(1, self.trees.leaves)  # the member's tree rebuilt from its leaves
            if len(priorities):
                single.update(np.arange(len(priorities))[None], priorities[None])
            self.trees.tree[k] = single.tree[0]
