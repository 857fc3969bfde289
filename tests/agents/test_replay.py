"""The replay a saved agent is built with: it takes the keywords saved models hold, refuses
settings that cannot be, and reads a replay pickled before n-step returns existed."""

from __future__ import annotations

import pickle

import gymnasium as gym
import numpy as np
import pytest

from craftsuite.agents.replay import AutomatonReplayBuffer, SumTree

SPACE = gym.spaces.Box(-1, 1, (1,), np.float32)


def test_it_takes_the_saved_keywords_and_refuses_bad_n_steps():
    buf = AutomatonReplayBuffer(10, SPACE, SPACE, n_envs=2, prioritized=True, alpha=0.6, beta=0.5, epsilon=0.2,
                                n_steps=3, gamma=0.5)
    assert (buf.n_steps, buf.gamma, buf.alpha, buf.beta, buf.epsilon) == (3, 0.5, 0.6, 0.5, 0.2)
    assert buf.w.shape == buf.sigma.shape == buf.w_next.shape == (5, 2)  # SB3 counts transitions over all envs
    assert not hasattr(buf, "tree") and not hasattr(buf, "max_priority")  # settings only: it samples by no priority
    for bad in (0, 2.5, True):
        with pytest.raises(ValueError, match="n_steps must be a positive integer"):
            AutomatonReplayBuffer(10, SPACE, SPACE, n_steps=bad)
    with pytest.raises(ValueError, match="optimize_memory_usage"):
        AutomatonReplayBuffer(10, SPACE, SPACE, n_steps=3, optimize_memory_usage=True)


def test_a_replay_pickled_with_its_filled_rows_only_and_before_n_step_returns_loads_whole():
    state = dict(AutomatonReplayBuffer(10, SPACE, SPACE).__dict__)
    for name in ("observations", "w"):
        state[name] = state[name][:4] + 1  # as the SB3 trainer pickled it: its filled rows
    del state["n_steps"], state["gamma"]  # as pickled before n-step returns existed
    old = AutomatonReplayBuffer.__new__(AutomatonReplayBuffer)
    old.__setstate__(state)
    assert (old.n_steps, old.gamma) == (1, 0.99)
    assert old.observations.shape == (10, 1, 1) and old.observations[:4].min() == 1 and old.observations[4:].max() == 0
    assert old.w.shape == (10, 1) and old.w[:4].tolist() == [[1]] * 4


def test_a_replay_pickled_with_its_priorities_still_unpickles():
    old = AutomatonReplayBuffer(10, SPACE, SPACE)
    old.tree, old.max_priority = SumTree(10), 3.0  # what the SB3 trainer's prioritized replay pickled
    old.tree.tree[16 + 2] = 0.5
    back = pickle.loads(pickle.dumps(old))
    assert isinstance(back.tree, SumTree) and back.tree.leaves == 16 and back.tree.tree[18] == 0.5
    assert back.max_priority == 3.0 and back.observations.shape == (10, 1, 1)
