"""Hyperparameters checked by name and type (craftsuite.hyperparameters) before anything runs."""

from __future__ import annotations

import inspect

import numpy as np

import pytest

from craftsuite.hyperparameters import (DQN_DEFAULTS, TD3_DEFAULTS, HyperparameterError, algorithm_settings,
                                        check_hyperparameters, hyperparameter_examples)


@pytest.mark.parametrize("overrides,message", [
    ({"batch_size": "big"}, "batch_size must be an integer (default 64), got 'big'"),
    ({"batch_size": 64.0}, "batch_size must be an integer"),
    ({"learning_starts": True}, "learning_starts must be an integer"),
    ({"learning_rate": "fast"}, "learning_rate must be a number"),
    ({"learning_rate": False}, "learning_rate must be a number"),
    ({"prioritized": 1}, "prioritized must be true or false"),
    ({"policy_kwargs": [64]}, "policy_kwargs must be an object"),
    ({"train_freq": 4.0}, "train_freq must be an integer or a list"),
])
def test_a_value_of_the_wrong_type_is_named(overrides, message):
    with pytest.raises(HyperparameterError, match="^--hyper: " + message.replace("(", r"\(").replace(")", r"\)")):
        check_hyperparameters("dqn", overrides, source="--hyper")


@pytest.mark.parametrize("algorithm,overrides,message", [
    ("dqn", {"batch_size": -1}, "batch_size must be at least 1 (default 64), got -1"),
    ("dqn", {"learning_rate": -1}, "learning_rate must be above 0 (default 0.0005), got -1"),
    ("dqn", {"learning_rate": 0}, "learning_rate must be above 0"),
    ("dqn", {"gamma": 1.5}, "gamma must be between 0 and 1 (default 0.99), got 1.5"),
    ("dqn", {"exploration_final_eps": -0.1}, "exploration_final_eps must be between 0 and 1"),
    ("td3", {"tau": 0}, "tau must be above 0 and at most 1 (default 0.005), got 0"),
    ("td3", {"policy_delay": 0}, "policy_delay must be at least 1 (e.g. 2), got 0"),
    ("td3", {"buffer_size": 0}, "buffer_size must be at least 1"),
    ("dqn", {"n_steps": 0}, "n_steps must be between 1 and 100 (e.g. 1), got 0"),
    ("td3", {"n_steps": 101}, "n_steps must be between 1 and 100 (e.g. 1), got 101"),
    # JSON's Infinity (or 1e400) passes every lower bound: a run would train to NaN thrust
    ("td3", {"learning_rate": float("inf")}, "learning_rate must be a finite number (default 0.0001), got inf"),
    ("dqn", {"max_grad_norm": float("inf")}, "max_grad_norm must be a finite number (e.g. 10.0; a large one, e.g. "
     "1e9, caps nothing), got inf"),
    ("td3", {"gamma": float("nan")}, "gamma must be a finite number (default 0.99), got nan"),
])
def test_a_number_out_of_its_range_is_named(algorithm, overrides, message):
    with pytest.raises(HyperparameterError, match="^--hyper: " + message.replace("(", r"\(").replace(")", r"\)")):
        check_hyperparameters(algorithm, overrides, source="--hyper")


def test_the_edges_of_the_ranges_pass():
    edges = {"gamma": 1, "learning_starts": 0, "exploration_final_eps": 0.0, "batch_size": 1, "gradient_steps": -1,
             "n_steps": 100}
    assert check_hyperparameters("dqn", edges) == edges
    assert (check_hyperparameters("td3", {"tau": 1.0, "target_policy_noise": 0})
            == {"tau": 1.0, "target_policy_noise": 0})


def test_an_unknown_setting_lists_the_valid_ones():
    with pytest.raises(HyperparameterError) as err:
        check_hyperparameters("td3", {"learning_rat": 1e-3})
    text = str(err.value)
    assert "TD3 has no setting 'learning_rat'" in text
    assert all(name in text for name in (*TD3_DEFAULTS, "n_steps", "delay_schedule", "prioritized"))
    assert isinstance(err.value, TypeError)  # as the constructor's unknown keyword was


def test_values_of_the_right_type_pass_unchanged():
    good = {"learning_rate": 1, "batch_size": 32, "prioritized": False, "policy_kwargs": None,
            "train_freq": [2, "episode"], "n_steps": 3, "double": False}
    assert check_hyperparameters("dqn", good) == good
    assert algorithm_settings("dqn", good)["batch_size"] == 32
    with pytest.raises(HyperparameterError, match="DQN has no setting 'action_noise'"):
        algorithm_settings("dqn", {"action_noise": None})


@pytest.mark.parametrize("algorithm", ["dqn", "td3"])
def test_every_setting_is_a_keyword_of_the_agent_and_every_data_keyword_a_setting(algorithm):
    from craftsuite.agents.factory import CLASSES

    cls = CLASSES[algorithm]
    sb3 = cls.__bases__[-1]  # SB3's DQN or TD3
    assert sb3.__module__.startswith("stable_baselines3")
    keywords = {}
    for klass in (sb3, cls):  # the agent's keywords over SB3's
        keywords.update({k: p.default for k, p in inspect.signature(klass.__init__).parameters.items()})
    not_data = {"self", "policy", "env", "kwargs", "replay_buffer_class", "tensorboard_log", "verbose", "seed",
                "_init_setup_model", "distill", "args"}
    examples = hyperparameter_examples(algorithm)
    assert set(examples) - set(keywords) == set()
    assert set(keywords) - not_data - set(examples) == set()
    defaults = TD3_DEFAULTS if algorithm == "td3" else DQN_DEFAULTS
    for name, default in keywords.items():  # the library's default fits each setting's type
        if name in examples and name not in defaults and default is not None and name != "delay_schedule":
            check_hyperparameters(algorithm, {name: default})


def test_python_objects_are_the_constructors_to_judge_and_nulls_mean_the_default():
    """make_agent is also a Python API: a schedule or an ActionNoise is no JSON value to type
    check, and a null setting (policy_delay: the schedule; replay_buffer_kwargs: none)."""
    from stable_baselines3.common.noise import NormalActionNoise

    from craftsuite.agents.factory import make_agent

    noise = NormalActionNoise(np.zeros(2), np.full(2, 0.1))
    agent = make_agent("td3", "CraftSuite/Reach-Cont-v0", learning_rate=lambda progress: 1e-4 * progress,
                       action_noise=noise, policy_delay=None, buffer_size=64)
    assert isinstance(agent.action_noise, NormalActionNoise) and agent.lr_schedule(1.0) == pytest.approx(1e-4)
    assert agent.policy_delay == agent.policy_delay_at(0)  # None leaves the schedule in force
    crm = make_agent("crm", "CraftSuite/Reach-Grid7-v0", replay_buffer_kwargs=None, buffer_size=64)
    assert crm.replay_buffer.automaton is crm.get_env().get_attr("automaton", [0])[0]


def test_a_library_setting_is_shown_by_example_not_as_craftsuites_default():
    # policy_delay's library default (2) is not what a CraftSuite run gets (its schedule)
    with pytest.raises(HyperparameterError, match=r"policy_delay must be an integer or null \(e\.g\. 2\)"):
        check_hyperparameters("td3", {"policy_delay": "often"})
