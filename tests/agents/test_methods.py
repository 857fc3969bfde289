"""Smoke training of every method, teacher distillation, save/load."""

from __future__ import annotations

import numpy as np
import pytest

from craftsuite.agents import AutomatonQTable
from craftsuite.agents.methods import METHODS, distill_from_replay, load_agent, make_agent

GRID, CONT = "CraftSuite/DungeonQuest-Grid7-v0", "CraftSuite/DungeonQuest-Cont-v0"
SMALL_DQN = dict(learning_starts=50, buffer_size=2_000, target_update_interval=100)
SMALL_TD3 = dict(learning_starts=50, buffer_size=2_000, policy_kwargs=dict(net_arch=[32, 32]))


@pytest.fixture(scope="module")
def teacher():
    agent = make_agent("product-dqn", GRID, seed=0, n_envs=2, **SMALL_DQN)
    agent.learn(400)
    return agent


@pytest.fixture(scope="module")
def table(teacher):
    return distill_from_replay(teacher)


def test_teacher_distills_a_table(teacher, table):
    assert table.kind == "dynamic" and table.counts.sum() == 400
    a = teacher.get_env().envs[0].unwrapped.automaton
    table.check(a)
    start = a.initial
    assert table.seen[start, 0]  # 'nothing happened' from the start was certainly seen


@pytest.mark.parametrize("method", [m for m in METHODS if METHODS[m].algorithm.__name__ == "AutomatonDQN"])
def test_grid_methods_train(method, table):
    agent = make_agent(method, "CraftSuite/DungeonQuest-Grid10-v0", table=table, seed=1, **SMALL_DQN)
    agent.learn(300)
    assert agent.num_timesteps == 300 and agent._n_updates > 0
    if METHODS[method].distill:
        assert agent.distill.student_counts.sum() > 0
    if METHODS[method].crm:
        assert agent.replay_buffer.pos == 300  # rows of real steps, each with its counterfactuals
        assert agent.replay_buffer.n_envs == agent.replay_buffer.n_live


@pytest.mark.parametrize("method", [m for m in METHODS if METHODS[m].algorithm.__name__ == "AutomatonTD3"])
def test_cont_methods_train(method, table):
    agent = make_agent(method, CONT, table=table, seed=1, **SMALL_TD3)
    agent.learn(200)
    assert agent.num_timesteps == 200 and agent._n_updates > 0
    assert agent.policy_delay_at(100) == 4 and agent.policy_delay_at(25_000) == 2


def test_method_and_world_must_match(table):
    with pytest.raises(ValueError, match="for MuJoCo"):
        make_agent("td3", GRID)
    with pytest.raises(ValueError, match="needs a teacher's table"):
        make_agent("dynamic", GRID)
    with pytest.raises(KeyError, match="unknown method"):
        make_agent("ppo", GRID)


def test_save_load_identical_q_values(teacher, tmp_path):
    path = tmp_path / "teacher.zip"
    teacher.save(path)
    back = load_agent(path)
    obs = teacher.replay_buffer.observations[:50].reshape(100, -1)
    assert np.array_equal(back.q_values(obs), teacher.q_values(obs))


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_agent(tmp_path / "nope.zip")
    bad = tmp_path / "bad.zip"
    bad.write_bytes(b"garbage")
    with pytest.raises(ValueError, match="not a saved agent"):
        load_agent(bad)


def test_table_round_trip(table, tmp_path, teacher):
    a = teacher.get_env().envs[0].unwrapped.automaton
    back = AutomatonQTable.load(table.save(tmp_path / "t.npz"), a)
    assert np.array_equal(back.q, table.q) and np.array_equal(back.counts, table.counts)
