"""The protocol switches a suite selects, each on a tiny run: layouts per episode, envs per
gradient step, the loss and the target update's unit by name, the network, and students
with or without the automaton state; the paper suite's values; what a method cannot take
(the rules themselves: the frozen updates of ``tests/population/test_frozen_updates.py``)."""

from __future__ import annotations

import dataclasses
import json

import gymnasium as gym
import numpy as np
import pytest
import torch as th

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.agents.factory import make_agent
from craftsuite.cli import main
from craftsuite.configs import StudentConfig, TeacherConfig
from craftsuite.methods import METHODS, MethodError
from craftsuite.suites import AUTHORS_DQN, AUTHORS_TD3, SUITES
from craftsuite.training import train_student

GRID = "CraftSuite/BlindCraftsman-Grid10-v0"
TINY = dict(learning_starts=20, buffer_size=500, batch_size=8, policy_kwargs={"net_arch": [16]})


def _objects(env_id: str, env_kwargs: dict, seed: int) -> np.ndarray:
    """The object planes of a reset (the agent's plane left out: its start is always drawn)."""
    env = gym.make(env_id, **env_kwargs)
    obs, _ = env.reset(seed=seed)
    channels, size, _ = env.unwrapped.observation_layout["planes"]
    env.close()
    return obs[:channels * size * size].reshape(channels, size, size)[1:]


def test_layouts_per_episode_or_one_instance(tmp_path):
    per_episode = StudentConfig(task="BlindCraftsman", method="dqn", world="Grid10", layout_seed=None)
    fixed = StudentConfig(task="BlindCraftsman", method="dqn", world="Grid10", layout_seed=3)
    layouts = [_objects(per_episode.env_id, per_episode.env_kwargs, seed).tobytes() for seed in range(4)]
    assert len(set(layouts)) == 4  # a new layout every episode
    same = [_objects(fixed.env_id, fixed.env_kwargs, seed).tobytes() for seed in range(4)]
    assert len(set(same)) == 1
    # the suite's switches reach teachers and students
    paper = SUITES["paper"]
    assert all(t.layout_seed is None and t.env_kwargs == {} for t in paper.teachers().values())
    grid = [c for c in paper.student_configs(tmp_path) if c.world == "Grid10"]
    assert grid and all(c.layout_seed is None for c in grid)
    standard = SUITES["standard"]
    assert {t.layout_seed for t in standard.teachers().values()} == {0}


def test_envs_per_gradient_step(tmp_path):
    config = StudentConfig(task="Reach", method="dqn", world="Grid10", steps=400, eval_every=400, eval_episodes=1,
                           n_envs=5, hyperparameters={**TINY, "learning_starts": 100})
    result = json.loads((train_student(config, tmp_path, progress=False) / "result.json").read_text())
    assert result["steps"] == 400
    # one gradient step per agent step of 5 envs, after learning_starts transitions
    assert result["updates"] == (400 - 100) // 5


def test_a_loss_or_a_target_update_unit_of_another_name_is_refused():
    with pytest.raises(ValueError, match=r"loss must be one of huber, mse, got 'l1'"):
        make_agent("dqn", GRID, **{**TINY, "loss": "l1"})
    with pytest.raises(ValueError, match="target_update_unit must be one of"):  # named before any run starts
        TeacherConfig(hyperparameters={"target_update_unit": "updates"}).run_name()


def test_residual_cnn_reads_the_planes():
    from craftsuite.agents.networks import ResidualCNN

    agent = make_agent("product-dqn", GRID, features_extractor="residual-cnn", **TINY)
    extractor = agent.policy.q_net.features_extractor
    assert isinstance(extractor, ResidualCNN) and extractor.planes == (5, 10, 10)
    obs = agent.get_env().reset()
    assert agent.q_values(obs).shape == (1, 4)
    assert any(isinstance(m, th.nn.BatchNorm2d) for m in agent.q_net.modules())
    # Q-values (the greedy policy's, and the teacher's table's) read the running statistics and
    # leave them and the network's mode as they were
    agent.q_net.set_training_mode(True)
    before = [b.clone() for b in agent.q_net.features_extractor.buffers()]
    batch = np.stack([agent.get_env().observation_space.sample() for _ in range(7)])
    first, second = agent.q_values(batch), agent.q_values(batch[:3])
    # a row's value does not depend on its batch (up to the kernels' rounding)
    np.testing.assert_allclose(first[:3], second, rtol=1e-5, atol=1e-6)
    assert agent.q_net.training
    assert all((a == b).all() for a, b in zip(before, agent.q_net.features_extractor.buffers()))
    from craftsuite.agents.networks import features_policy_kwargs

    with pytest.raises(ValueError, match="reads grid planes"):
        features_policy_kwargs("residual-cnn", gym.make("CraftSuite/Reach-Kinematic-v0"), {})


@pytest.mark.parametrize("method", ["static", "td3-static"])
def test_students_without_the_automaton_state(tmp_path, method):
    world = "Grid10" if METHODS[method].world == "Grid" else "Kinematic"
    config = StudentConfig(task="Reach", method=method, world=world, steps=60, eval_every=60, eval_episodes=1,
                           automaton_state=False, hyperparameters=dict(TINY))
    run = train_student(config, tmp_path, progress=False)
    result = json.loads((run / "result.json").read_text())
    assert result["product"] is False
    base = gym.make(config.env_id).observation_space.shape
    from craftsuite.agents.factory import load_agent

    agent = load_agent(run / "model.zip")
    assert agent.observation_space.shape == base  # no automaton one-hot
    assert agent.distill is not None  # the automaton still reaches the target
    # the same student with the state is another run, told apart by its settings; asking a
    # method for what it does anyway is the same run
    seeing = dataclasses.replace(config, automaton_state=None)
    assert seeing.run_name() != config.run_name() and seeing.product
    assert dataclasses.replace(config, automaton_state=True).run_name() == seeing.run_name()


def test_a_method_that_cannot_go_without_the_automaton_state_is_refused(tmp_path, capsys):
    for method, state in (("crm", False), ("product-dqn", False), ("dqn", True), ("td3", True)):
        with pytest.raises(MethodError, match=f"method '{method}' cannot run with automaton_state={state}"):
            StudentConfig(task="Reach", method=method, world="Grid10" if METHODS[method].world == "Grid" else "Cont",
                          automaton_state=state)
    with pytest.raises(MethodError, match="counterfactual"):
        make_agent("crm", GRID, automaton_state=False, **TINY)
    assert main(["student", "Reach", "--world", "Grid10", "--method", "crm", "--automaton-state", "off",
                 "--out", str(tmp_path / "s")]) == 2
    err = capsys.readouterr().err
    assert "'crm'" in err and "automaton_state=False" in err and not (tmp_path / "s").exists()
    # a suite that hides the state from its students leaves CRM and the product baselines theirs
    suite = dataclasses.replace(SUITES["standard"], students_see_automaton=False, tags=(), tasks=("Reach",),
                                seeds=1)
    for c in suite.student_configs(tmp_path):
        assert c.product == (METHODS[c.method].product and not METHODS[c.method].distill)
    # ... and the counterfactual distilled students theirs too: their replay relabels it
    suite = dataclasses.replace(SUITES["transfer"], students_see_automaton=False, tasks=("BlindCraftsman",), seeds=1)
    edges = [c for c in suite.student_configs(tmp_path) if c.method in ("crm-edges", "td3-crm-edges")]
    assert edges and all(c.automaton_state is None for c in edges)


def test_board_size_reaches_the_kinematic_students_only(tmp_path, capsys):
    suite = dataclasses.replace(SUITES["paper"], tasks=("BlindCraftsman",), tags=(), seeds=1,
                                worlds=("Cont", "Kinematic"), kinematic_world_kwargs={"size": 10})
    worlds = {c.world: c.world_kwargs for c in suite.student_configs(tmp_path)}
    assert worlds == {"Cont": {}, "Kinematic": {"size": 10}}
    assert main(["transfer", "--suite", "quick", "--board-size", "10", "--out", str(tmp_path / "q")]) == 2
    assert "--board-size sets the kinematic board" in capsys.readouterr().err and not (tmp_path / "q").exists()


def test_the_paper_suite_runs_the_authors_protocol(tmp_path):
    paper = SUITES["paper"]
    assert (paper.td3_n_envs, paper.dqn_n_envs, paper.teacher_n_envs) == (10, 10, 10)
    assert set(paper.worlds) == {"Grid10", "Cont", "Kinematic"} and paper.student_steps == 20_000_000
    for config in [*paper.teachers().values(), *paper.student_configs(tmp_path)]:
        settings = config.effective()["hyperparameters"]
        if settings.get("exploration_final_eps") is not None:  # DQN
            assert settings["exploration_initial_eps"] == settings["exploration_final_eps"] == 0.1
            assert (settings["target_update_interval"], settings["target_update_unit"]) == (1_000, "gradient_steps")
            assert settings["loss"] == "mse" and settings["features_extractor"] == "residual-cnn"
        else:  # TD3
            assert settings["action_noise"] == {"type": "normal", "sigma": 0.2}
            assert settings["policy_delay"] == 2 and settings["learning_rate"] == 3e-4
        if isinstance(config, StudentConfig) and METHODS[config.method].distill:
            assert config.product is False
    assert isinstance(paper.teachers()["BlindCraftsman"], TeacherConfig)
    assert AUTHORS_DQN["replay_buffer_kwargs"] == {"beta": 0.9} and AUTHORS_TD3["replay_buffer_kwargs"] == {"beta": 0.0}


def test_dqn_hyper_reaches_grid_students_and_teachers(tmp_path, monkeypatch):
    import craftsuite.suite_runner

    seen = []

    def fake_transfer(suite, out, **_):
        seen.append(suite)
        return craftsuite.suite_runner.TransferResult(out, {}, [], out, [], None)

    monkeypatch.setattr(craftsuite.suite_runner, "transfer", fake_transfer)
    assert main(["transfer", "--suite", "paper", "--dqn-hyper", '{"features_extractor": "flatten"}',
                 "--out", str(tmp_path)]) == 0
    [suite] = seen
    for settings in ({**suite.dqn_hyperparameters, **suite.dqn_overrides}, suite.teacher_hyperparameters):
        assert settings == {**AUTHORS_DQN, "features_extractor": "flatten"}  # merged over the suite's
    assert main(["transfer", "--dqn-hyper", '{"los": "mse"}', "--out", str(tmp_path / "t")]) == 2
