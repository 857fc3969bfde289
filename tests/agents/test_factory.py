"""Saved agents: the models the SB3 trainer saved (``saved/``, made at the commit
``saved/make.py`` names) still load with ``load_agent`` and SB3's own classes and act; SB3's
own classes go on training them with SB3's rule, but for CRM models, whose replay does not
collect; CraftSuite's classes do not learn, and say what trains instead."""

import json

import numpy as np
import pytest
import stable_baselines3 as sb3
from stable_baselines3.common.env_util import make_vec_env

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.distillation import DistilledTarget
from craftsuite.agents.factory import distill_from_replay, load_agent, make_agent
from craftsuite.methods import METHODS
from craftsuite.task_registry import resolve_task

from .saved import actions, make

SAVED = make.HERE
PLAIN = {"dqn": sb3.DQN, "td3": sb3.TD3}


def _env(name: str):
    """The world of saved model ``name``, with the automaton state where its method sees it."""
    method, env_id, env_kwargs, _, _ = make.CASES[name]
    return {"id": env_id, **env_kwargs, "product": METHODS[method].observes(None)}


@pytest.mark.parametrize("name", list(make.CASES))
def test_a_saved_model_loads_and_acts_as_it_did(name):
    """Its greedy actions, and the values behind them, on the observations ``saved/actions.json``
    holds, are the ones recorded there. The models cannot be made again (``make.py`` runs only
    at an older commit), so the answers were recorded from the saved files, after the SB3
    trainer was retired, by the loading code that has read them since they were saved
    (``saved/actions.py``): a change in how a model loads or acts fails here."""
    method = make.CASES[name][0]
    agent = load_agent(SAVED / f"{name}.zip")
    algorithm = agent.algorithm
    assert type(agent).__name__ == f"Automaton{algorithm.upper()}" and agent.num_timesteps == 60
    recorded = json.loads(actions.FILE.read_text())[name]
    batch = np.asarray(recorded["observations"], dtype=np.float32)
    answers = actions.answers(agent, batch)
    np.testing.assert_allclose(answers["actions"], recorded["actions"], rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(answers["values"], recorded["values"], rtol=1e-5, atol=1e-6)
    assert all(agent.action_space.contains(np.asarray(a, dtype=agent.action_space.dtype)) for a in answers["actions"])
    plain = PLAIN[algorithm].load(SAVED / f"{name}.zip", device="cpu")  # SB3 opens it too, and acts alike
    np.testing.assert_array_equal(plain.predict(batch, deterministic=True)[0],
                                  agent.predict(batch, deterministic=True)[0])
    if method == "td3-dynamic":
        assert isinstance(agent.distill, DistilledTarget) and agent.distill.student_counts.sum() > 0
        assert agent.policy_delay_at(0) == 4 and agent.layer_norm


@pytest.mark.parametrize("name", ["product-dqn", "td3-dynamic"])
def test_sb3s_own_class_goes_on_training_a_saved_model(name):
    world = _env(name)
    algorithm = METHODS[make.CASES[name][0]].algorithm
    env = make_vec_env(world.pop("id"), n_envs=1, env_kwargs=world)
    model = PLAIN[algorithm].load(SAVED / f"{name}.zip", env=env, device="cpu")
    model.learn(40, reset_num_timesteps=False)  # SB3's add and sample on the saved replay's class
    assert model.num_timesteps == 100 and model._n_updates > 30


def test_craftsuites_classes_do_not_learn_and_name_the_trainer():
    agent = make_agent("dqn", "CraftSuite/FirstTool-Grid7-v0", buffer_size=16)
    for call in (lambda: agent.learn(10), lambda: agent.train(1)):
        with pytest.raises(RuntimeError, match=r"^AutomatonDQN holds a CraftSuite model and does not learn: "
                                               r".*craftsuite\.population\.train_population.*\(not CRM models\)"):
            call()  # a fresh agent too: it holds no trained model, and still does not learn
    loaded = load_agent(SAVED / "td3-dynamic.zip")
    with pytest.raises(RuntimeError, match=r"^AutomatonTD3 .*`craftsuite student`"):
        loaded.learn(10)
    assert loaded.num_timesteps == 60


def test_a_saved_crm_model_trained_by_sb3s_class_names_the_trainer():
    env = make_vec_env(make.GRID, n_envs=1, env_kwargs={"layout_seed": 0, "product": True})
    model = sb3.DQN.load(SAVED / "crm.zip", env=env, device="cpu")
    with pytest.raises(RuntimeError, match="CRM's counterfactuals are made by the population engine"):
        model.learn(10)


def test_a_saved_teachers_replay_is_distilled_as_it_was():
    env = make_vec_env(make.GRID, n_envs=1, env_kwargs={"layout_seed": 0, "product": True})
    teacher = load_agent(SAVED / "product-dqn.zip", env=env)
    teacher.load_replay_buffer(SAVED / "product-dqn-replay.pkl")  # its filled rows only, as it was pickled
    assert teacher.replay_buffer.observations.shape[0] == 200 and teacher.replay_buffer.pos == 60
    table = distill_from_replay(teacher)
    table.check(resolve_task("FirstTool").automaton)
    assert table.counts.sum() == 60 and np.isfinite(table.q[table.seen]).all()
