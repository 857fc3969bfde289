"""One owner per setting: make_agent on an env made already, n_steps and the actor's delay
as SB3's own attributes and the model's settings, the algorithm saved with the model,
tables checked by file."""

from __future__ import annotations

import json
import zipfile

import gymnasium as gym
import numpy as np
import pytest
from stable_baselines3.common.env_util import make_vec_env
from stable_baselines3.common.monitor import Monitor

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents import AutomatonQTable, DistillationError
from craftsuite.agents.distillation import static_distillation
from craftsuite.agents.dqn import AutomatonDQN
from craftsuite.agents.factory import load_agent, make_agent, recorded_algorithm
from craftsuite.agents.td3 import AutomatonTD3
from craftsuite.hyperparameters import HyperparameterError
from craftsuite.task_registry import resolve_task

GRID, CONT = "CraftSuite/DungeonQuest-Grid7-v0", "CraftSuite/DungeonQuest-Cont-v0"
SMALL_DQN = dict(learning_starts=20, buffer_size=500, policy_kwargs={"net_arch": [16]})
SMALL_TD3 = dict(learning_starts=20, buffer_size=500, policy_kwargs={"net_arch": [16]})


# -- make_agent on an env ----------------------------------------------------------------------
def test_make_agent_takes_a_vec_env_or_a_gym_env():
    vec = make_vec_env(GRID, n_envs=2, seed=0, env_kwargs={"product": True})
    agent = make_agent("product-dqn", vec, **SMALL_DQN)
    assert agent.get_env() is vec and agent.n_envs == 2
    single = make_agent("dqn", gym.make(GRID), **SMALL_DQN)
    assert single.n_envs == 1 and isinstance(single.get_env().envs[0], Monitor)  # SB3's wrapping, as it acts


def test_make_agent_checks_the_world_of_an_env():
    with pytest.raises(ValueError, match="'td3' is for Cont worlds, not CraftSuite/DungeonQuest-Grid7-v0"):
        make_agent("td3", gym.make(GRID))
    with pytest.raises(ValueError, match="'dqn' is for Grid worlds, not CraftSuite/DungeonQuest-Cont-v0"):
        make_agent("dqn", make_vec_env(CONT, n_envs=1))
    # the automaton state in the observation exactly when the method is a product method
    with pytest.raises(ValueError, match="needs the automaton state.*product=True"):
        make_agent("product-dqn", gym.make(GRID))
    with pytest.raises(ValueError, match="must not see the automaton state.*product=False"):
        make_agent("dqn", gym.make(GRID, product=True))
    with pytest.raises(ValueError, match="needs a CraftSuite world, not CartPoleEnv"):
        make_agent("dqn", gym.make("CartPole-v1"))
    with pytest.raises(TypeError, match="a CraftSuite id, a gymnasium env or a VecEnv"):
        make_agent("dqn", 42)
    with pytest.raises(ValueError, match="env_kwargs"):
        make_agent("dqn", gym.make(GRID), env_kwargs={"layout_seed": 0})


# -- n_steps and policy_delay: SB3's attributes say what ran -----------------------------------
@pytest.mark.parametrize("method,world,small", [("product-dqn", GRID, SMALL_DQN), ("product-td3", CONT, SMALL_TD3)])
def test_n_steps_is_sb3s_attribute_and_the_buffers(method, world, small, tmp_path):
    agent = make_agent(method, world, n_steps=3, **small)
    assert agent.n_steps == agent.replay_buffer.n_steps == 3
    agent.save(tmp_path / "a.zip")
    back = load_agent(tmp_path / "a.zip")
    assert back.n_steps == back.replay_buffer.n_steps == 3
    with pytest.raises(ValueError, match="n_steps is the algorithm's setting"):
        make_agent(method, world, replay_buffer_kwargs={"n_steps": 2}, **small)


def test_the_actors_delay_is_a_schedule_or_a_constant_not_both():
    agent = make_agent("td3", CONT, **SMALL_TD3)
    assert (agent.policy_delay_at(0), agent.policy_delay_at(25_000)) == (4, 2)  # the default schedule
    constant = make_agent("td3", CONT, policy_delay=3, **SMALL_TD3)
    assert constant.policy_delay_at(0) == constant.policy_delay_at(10**6) == 3
    with pytest.raises(ValueError, match="not both"):
        make_agent("td3", CONT, policy_delay=3, delay_schedule=[[None, 2]], **SMALL_TD3)
    with pytest.raises(ValueError, match="delay_schedule must be"):
        make_agent("td3", CONT, delay_schedule=[[100, 0], [None, 2]], **SMALL_TD3)


# -- the algorithm saved with the model -------------------------------------------------------
def test_load_agent_takes_the_class_the_model_records(tmp_path, monkeypatch):
    for method, world, small, cls in (("dqn", GRID, SMALL_DQN, AutomatonDQN), ("td3", CONT, SMALL_TD3, AutomatonTD3)):
        agent = make_agent(method, world, **small)
        agent.save(tmp_path / f"{method}.zip")
        with zipfile.ZipFile(tmp_path / f"{method}.zip") as z:
            assert json.loads(z.read("data"))["algorithm"] == method
        assert recorded_algorithm(tmp_path / f"{method}.zip") == method
        tried = []
        for other in (AutomatonDQN, AutomatonTD3):  # only the recorded class is asked to load
            real = other.load.__func__
            monkeypatch.setattr(other, "load",
                                classmethod(lambda c, *a, real=real, **k: (tried.append(c), real(c, *a, **k))[1]))
        back = load_agent(tmp_path / f"{method}.zip")
        monkeypatch.undo()
        assert type(back) is cls and tried == [cls]


def test_an_unknown_recorded_algorithm_is_named(tmp_path):
    agent = make_agent("dqn", GRID, **SMALL_DQN)
    agent.algorithm = "ppo"
    agent.save(tmp_path / "a.zip")
    with pytest.raises(ValueError, match="a 'ppo' agent, which this CraftSuite does not know"):
        load_agent(tmp_path / "a.zip")


def test_models_that_record_no_algorithm_are_tried_class_by_class(tmp_path):
    agent = make_agent("td3", CONT, **SMALL_TD3)
    del agent.algorithm  # as a plain SB3 checkpoint records none
    agent.save(tmp_path / "model.zip")
    assert recorded_algorithm(tmp_path / "model.zip") is None
    assert type(load_agent(tmp_path / "model.zip")) is AutomatonTD3


# -- hyperparameters are checked by make_agent too ------------------------------------------------
def test_make_agent_names_a_bad_setting_before_it_makes_an_env(monkeypatch):
    import craftsuite.agents.factory as factory

    monkeypatch.setattr(factory, "make_vec_env", lambda *a, **k: pytest.fail("an env was made"))
    with pytest.raises(HyperparameterError, match="batch_size must be an integer"):
        make_agent("dqn", GRID, batch_size="big")
    with pytest.raises(HyperparameterError, match="DQN has no setting 'policy_delay'"):
        make_agent("dqn", GRID, policy_delay=2)


# -- a teacher's table, checked by file -------------------------------------------------------
@pytest.fixture
def automaton():
    return resolve_task("DungeonQuest").automaton


def test_table_errors_name_the_file_and_the_problem(tmp_path, automaton):
    text = tmp_path / "notes.npz"
    text.write_text("not a table")
    with pytest.raises(DistillationError, match=r"notes.npz is not a CraftSuite distilled table: not an .npz") as err:
        AutomatonQTable.load(text)
    assert "allow_pickle" not in str(err.value)
    other = tmp_path / "other.npz"
    np.savez(other, q=np.zeros((2, 2)))
    with pytest.raises(DistillationError, match=r"other.npz .* lacks the arrays counts, meta \(it has q\)"):
        AutomatonQTable.load(other)
    good = static_distillation(automaton).save(tmp_path / "t.npz")
    cut = tmp_path / "cut.npz"
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    with pytest.raises(DistillationError, match="cut.npz"):
        AutomatonQTable.load(cut)
    blind = resolve_task("BlindCraftsman").automaton
    with pytest.raises(DistillationError, match=r"t.npz does not fit this task: .* states x .* labels"):
        AutomatonQTable.load(good, blind)
    assert AutomatonQTable.load(good, automaton).kind == "static"
