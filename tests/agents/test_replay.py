"""AutomatonReplayBuffer: automaton fields with several envs and episode ends; prioritized sampling."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_util import make_vec_env

import craftsuite  # noqa: F401
from craftsuite.agents.replay import AutomatonReplayBuffer, SumTree

ENV = "CraftSuite/DungeonQuest-Grid7-v0"


def fill(buffer, vec, steps, seed=0):
    """Step a VecEnv with random actions into the buffer; return the infos seen per step."""
    rng = np.random.default_rng(seed)
    obs = vec.reset()
    seen = []
    for _ in range(steps):
        actions = rng.integers(0, 4, vec.num_envs)
        next_obs, rewards, dones, infos = vec.step(actions)
        stored_next = next_obs.copy()
        for i, d in enumerate(dones):
            if d:
                stored_next[i] = infos[i]["terminal_observation"]
        buffer.add(obs, stored_next, actions, rewards, dones, infos)
        seen.append([info["automaton_transition"] for info in infos])
        obs = next_obs
    return seen


def test_automaton_fields_with_two_envs_across_episode_ends():
    vec = make_vec_env(ENV, n_envs=2, seed=3, env_kwargs={"product": True})
    buf = AutomatonReplayBuffer(600, vec.observation_space, vec.action_space, n_envs=2, prioritized=False)
    seen = fill(buf, vec, 300)
    ends = 0
    for t, per_env in enumerate(seen):
        for e, (w, sigma, w2) in enumerate(per_env):
            assert (buf.w[t, e], buf.sigma[t, e], buf.w_next[t, e]) == (w, sigma, w2)
            # the stored next observation carries w' in its one-hot (terminal ones included)
            assert buf.next_observations[t, e, -8:].argmax() == w2
            ends += bool(buf.dones[t, e])
    assert ends > 0  # the random walk ended some episodes (violations, successes)


def test_missing_automaton_info_is_a_clear_error():
    env = gym.make(ENV)
    buf = AutomatonReplayBuffer(10, env.observation_space, env.action_space)
    obs = np.zeros((1,) + env.observation_space.shape, np.float32)
    with pytest.raises(ValueError, match="automaton_transition"):
        buf.add(obs, obs, np.zeros(1), np.zeros(1), np.zeros(1), [{}])


def test_sum_tree_matches_brute_force():
    rng = np.random.default_rng(0)
    tree = SumTree(37)
    values = np.zeros(tree.leaves)
    for _ in range(20):
        idx = rng.integers(0, 37, 5)
        val = rng.uniform(0, 3, 5)
        tree.update(idx, val)
        for i, v in zip(idx, val):
            values[i] = v
    assert tree.total() == pytest.approx(values.sum())
    targets = rng.uniform(0, values.sum(), 200)
    expected = np.searchsorted(np.cumsum(values), targets, side="right")
    assert np.array_equal(tree.find(targets), expected)


def test_prioritized_sampling_and_importance_weights():
    vec = make_vec_env(ENV, n_envs=1, seed=0, env_kwargs={"product": True})
    buf = AutomatonReplayBuffer(64, vec.observation_space, vec.action_space, alpha=1.0, beta=1.0, epsilon=0.0)
    fill(buf, vec, 4)
    assert np.allclose(buf.tree.tree[buf.tree.leaves:buf.tree.leaves + 4], 1.0)  # new: max priority
    buf.update_priorities(np.arange(4), np.array([1.0, 1.0, 1.0, 5.0]))
    fill(buf, vec, 1, seed=1)  # the new transition enters at the new max priority (5)
    samples = [buf.sample(64) for _ in range(200)]
    idx = np.concatenate([s.indices for s in samples])
    freq = np.bincount(idx, minlength=5) / len(idx)
    assert freq == pytest.approx(np.array([1, 1, 1, 5, 5]) / 13, abs=0.01)
    s = samples[0]
    probs = np.array([1, 1, 1, 5, 5])[s.indices] / 13
    expected = (5 * probs) ** -1.0
    assert s.weights.numpy().reshape(-1) == pytest.approx(expected / expected.max(), rel=1e-5)
    assert s.w.shape == s.sigma.shape == s.w_next.shape == (64,)


def test_uniform_sampling_has_unit_weights():
    vec = make_vec_env(ENV, n_envs=2, seed=0, env_kwargs={"product": True})
    buf = AutomatonReplayBuffer(64, vec.observation_space, vec.action_space, n_envs=2, prioritized=False)
    fill(buf, vec, 10)
    s = buf.sample(32)
    assert (s.weights.numpy() == 1).all() and s.indices.max() < 20
    buf.update_priorities(s.indices, np.ones(32))  # a no-op, not an error


def _chain(buffer_size, rewards, ends=(), truncated=(), n_steps=3, gamma=0.5):
    """A one-env buffer holding transitions t = 0, 1, ... with observation t, next observation
    t + 0.5 and the given rewards; episodes end (terminated) after the steps in ``ends``,
    by the time limit after those in ``truncated``."""
    space = gym.spaces.Box(-100, 100, (1,), np.float32)
    buf = AutomatonReplayBuffer(buffer_size, space, space, prioritized=False, n_steps=n_steps, gamma=gamma)
    for t, r in enumerate(rewards):
        info = {"automaton_transition": (0, 0, 0), "TimeLimit.truncated": t in truncated}
        buf.add(np.array([[t]]), np.array([[t + 0.5]]), np.zeros((1, 1)), np.array([r]),
                np.array([t in ends or t in truncated]), [info])
    return buf


def _sampled(buf, expected):
    """Every row of ``expected`` ({row: (return, discount, done, next obs)}) as sampled."""
    s = buf.sample(256)
    got = {int(i): (float(r), float(d), float(done), float(nxt))
           for i, r, d, done, nxt in zip(s.indices, s.rewards[:, 0], s.discounts[:, 0], s.dones[:, 0],
                                         s.next_observations[:, 0])}
    assert got == expected


def test_n_step_returns_stop_at_episode_ends_and_bootstrap_after_truncation():
    # t:       0  1  2 (terminated)  3  4 (time limit)  5 (the newest)
    buf = _chain(10, [1, 2, 4, 8, 16, 32], ends={2}, truncated={4})
    _sampled(buf, {
        0: (1 + 0.5 * 2 + 0.25 * 4, 0.125, 1.0, 2.5),  # three rewards, the last one terminal: no bootstrap
        1: (2 + 0.5 * 4, 0.25, 1.0, 2.5),
        2: (4, 0.5, 1.0, 2.5),
        3: (8 + 0.5 * 16, 0.25, 0.0, 4.5),  # cut by the time limit: bootstrapped from its last observation
        4: (16, 0.5, 0.0, 4.5),
        5: (32, 0.5, 0.0, 5.5),  # its successor is not stored yet
    })


def test_n_step_windows_never_run_from_the_newest_row_into_the_oldest():
    # four rows, six transitions: rows hold t = 4, 5, 2, 3; row 1 (t = 5) is the newest
    buf = _chain(4, [1, 2, 4, 8, 16, 32])
    _sampled(buf, {
        2: (4 + 0.5 * 8 + 0.25 * 16, 0.125, 0.0, 4.5),  # t = 2, 3, 4 across the wrap
        3: (8 + 0.5 * 16 + 0.25 * 32, 0.125, 0.0, 5.5),
        0: (16 + 0.5 * 32, 0.25, 0.0, 5.5),  # stops at the newest row, not on into t = 2
        1: (32, 0.5, 0.0, 5.5),
    })


def test_one_step_samples_are_unchanged_and_bad_n_steps_are_refused():
    buf = _chain(10, [1, 2, 4], ends={2}, n_steps=1)
    s = buf.sample(64)
    assert s.discounts is None
    assert np.allclose(s.rewards[:, 0].numpy(), np.array([1, 2, 4])[s.indices])
    space = gym.spaces.Box(-1, 1, (1,), np.float32)
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="n_steps must be a positive integer"):
            AutomatonReplayBuffer(10, space, space, n_steps=bad)
    with pytest.raises(ValueError, match="optimize_memory_usage"):
        AutomatonReplayBuffer(10, space, space, n_steps=3, optimize_memory_usage=True)


def test_checkpoints_keep_n_steps_and_old_ones_load_as_one_step():
    import pickle

    buf = pickle.loads(pickle.dumps(_chain(10, [1, 2, 4], n_steps=3)))
    assert (buf.n_steps, buf.gamma) == (3, 0.5) and buf.sample(8).discounts is not None
    state = _chain(10, [1, 2, 4], n_steps=1).__getstate__()
    del state["n_steps"], state["gamma"]  # as pickled before n-step returns existed
    old = AutomatonReplayBuffer.__new__(AutomatonReplayBuffer)
    old.__setstate__(state)
    assert old.sample(8).discounts is None
