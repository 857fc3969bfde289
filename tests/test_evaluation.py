"""``craftsuite.evaluate`` plays the evaluation a suite's records hold, for any policy: a
trained run's model evaluated by it gives the run's own last evaluation, episode for
episode; plain callables and torch modules are taken; bad input is refused in one line."""

import dataclasses
from types import SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest
import torch as th

import craftsuite
from craftsuite.agents.factory import load_agent
from craftsuite.configs import StudentConfig
from craftsuite.population import train_population
from craftsuite.runs import eval_seed, read_csv
from craftsuite.suites import SUITES

TD3 = {"batch_size": 32, "learning_starts": 200, "policy_kwargs": {"net_arch": [16, 16]}, "prioritized": False}
DQN = {"batch_size": 32, "learning_starts": 200, "policy_kwargs": {"net_arch": [16, 16]}}


@pytest.mark.parametrize("world, task, hyper, layout_seed", [
    ("Kinematic", "Reach", TD3, None),
    ("Grid10", "FirstWood", DQN, SUITES["standard"].grid_layout_seed),  # the standard suite's grid instance
])
def test_a_runs_model_evaluated_gives_the_runs_own_last_evaluation(tmp_path, world, task, hyper, layout_seed):
    method = "td3" if world == "Kinematic" else "dqn"
    configs = [StudentConfig(task=task, method=method, world=world, seed=s, steps=1_200, eval_every=600,
                             eval_episodes=4, hyperparameters=hyper, n_envs=4, engine="population",
                             layout_seed=layout_seed) for s in (0, 1)]
    for config, path in zip(configs, train_population(configs, tmp_path, progress=False)):
        recorded = read_csv(path / "evals.csv")[-1]
        result = craftsuite.evaluate(load_agent(path / "model.zip"), config.env_id, step=1_200, episodes=4)
        assert result.success == pytest.approx(float(recorded["success"]))
        assert result.mean_return == pytest.approx(float(recorded["return"]), abs=1e-3)
        assert result.mean_length == pytest.approx(float(recorded["length"]), abs=1e-2)
        assert [e.seed for e in result.episodes] == [eval_seed(1_200) + i for i in range(4)]


def test_the_default_is_the_suites_last_evaluation_of_the_rung():
    standard = SUITES["standard"]
    result = craftsuite.evaluate(lambda obs: 0, "CraftSuite/Reach-Grid10-v0")
    budget = standard.budget(craftsuite.resolve_task("Reach"), "Grid10")
    assert result.step == budget and len(result.episodes) == standard.eval_episodes
    assert result.env_kwargs == {"layout_seed": standard.grid_layout_seed}
    assert result.episodes[0].seed == eval_seed(budget)
    assert 0.0 <= result.success <= 1.0 and result.mean_length > 0


def test_a_torch_module_acts_by_its_best_output():
    env = gym.make("CraftSuite/Reach-Grid10-v0")
    q = th.nn.Linear(env.observation_space.shape[0], env.action_space.n)
    result = craftsuite.evaluate(q, "CraftSuite/Reach-Grid10-v0", episodes=2)
    assert len(result.episodes) == 2 and np.isfinite(result.mean_return)


@pytest.mark.parametrize("policy, env, message", [
    (lambda obs: 7, "CraftSuite/Reach-Grid10-v0", r"the policy returned 7, outside the action space Discrete\(\d\)"),
    (lambda obs: np.array([2.0, 0.0]), "CraftSuite/Reach-Kinematic-v0", r"outside the action space Box.*clip"),
    (lambda obs: 0, "Reach-Grid10", "is not a CraftSuite id"),
    (lambda obs: 2.7, "CraftSuite/Reach-Grid10-v0", r"the policy returned 2.7, outside the action space"),
    (th.nn.Sequential(), "CraftSuite/Reach-Grid10-v0", "outside the action space"),  # the observation itself
    ("not a policy", "CraftSuite/Reach-Grid10-v0", "policy must be an SB3 model, a torch module or a callable"),
    (lambda obs: None, "CraftSuite/Reach-Grid10-v0", r"the policy returned None, outside the action space"),
    (lambda obs: "up", "CraftSuite/Reach-Grid10-v0", r"the policy returned 'up', outside the action space"),
    (lambda obs: {"move": 1}, "CraftSuite/Reach-Grid10-v0", r"the policy returned \{'move': 1\}, outside the"),
    (SimpleNamespace(predict=lambda batch, deterministic: (0, None)), "CraftSuite/Reach-Grid10-v0",
     r"the policy returned 0 for a batch of 1 observations: a batch policy \(predict, a torch module\) returns one"),
    (th.nn.Linear(3, 4), "CraftSuite/Reach-Grid10-v0",
     r"^the torch module cannot take this env's observations, of shape \(\d+,\) \(mat1 and mat2 shapes"),
    (SimpleNamespace(observation_space=gym.spaces.Box(0, 1, (5,)), predict=None), "CraftSuite/Reach-Grid10-v0",
     r"^the policy observes shape \(5,\), which CraftSuite/Reach-Grid10-v0's observations are not \(\(\d+,\), or "
     r"\(\d+,\) with the automaton state\): was it trained in another world\?$"),
])
def test_bad_input_is_one_line_naming_the_problem(policy, env, message):
    with pytest.raises(ValueError, match=message):
        craftsuite.evaluate(policy, env, episodes=1)


def test_an_unknown_suite_is_named():
    with pytest.raises(ValueError, match=r"^unknown suite 'nope'; suites: quick, standard, "):
        craftsuite.evaluate(lambda obs: 0, "CraftSuite/Reach-Grid10-v0", suite="nope")


def test_a_module_is_evaluated_in_eval_mode_and_left_as_it_was():
    class Seen(th.nn.Module):
        def __init__(self):
            super().__init__()
            self.modes = set()

        def forward(self, x):
            self.modes.add(self.training)
            return th.zeros(len(x), dtype=th.long)

    module = Seen().train()
    craftsuite.evaluate(module, "CraftSuite/Reach-Grid10-v0", episodes=1)
    assert module.modes == {False} and module.training


def test_a_rung_of_another_suite_names_the_suites_it_is_in():
    with pytest.raises(ValueError, match=r"DiamondMine in Grid10 is not a rung of the 'standard' suite.*'hard'"):
        craftsuite.evaluate(lambda obs: 0, "CraftSuite/DiamondMine-Grid10-v0", step=1000)


def test_a_suite_with_a_fault_of_its_own_is_refused_with_that_fault(monkeypatch):
    # a suite that does run the rung, but whose learner regime is misspelt: its own sentence,
    # not "not a rung of the suite"
    broken = dataclasses.replace(SUITES["standard"], name="broken", regime="n-step-wid")
    monkeypatch.setitem(SUITES, "broken", broken)
    with pytest.raises(ValueError, match=r"^suite 'broken': unknown learner regime 'n-step-wid' \(did you mean "
                                         r"n-step-wide") as refused:
        craftsuite.evaluate(lambda obs: 0, "CraftSuite/Reach-Grid10-v0", suite="broken", episodes=1)
    assert "not a rung" not in str(refused.value)


def test_a_modules_own_error_is_left_as_torch_raised_it():
    """Only a mismatch with the env's observations is worded as one."""
    class Broken(th.nn.Module):
        def forward(self, x):
            raise RuntimeError("my own fault")

    with pytest.raises(RuntimeError, match="^my own fault$"):
        craftsuite.evaluate(Broken(), "CraftSuite/Reach-Grid10-v0", episodes=1)
