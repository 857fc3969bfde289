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
