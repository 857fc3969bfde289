"""``craftsuite.training``: teacher and student runs on the population engine, in the world
their config names; runs of the sb3 engine reused when finished, refused otherwise; any
agent's greedy evaluation. The engine's own runs are ``tests/population``."""

import dataclasses
import json

import numpy as np
import pytest

from craftsuite.configs import StudentConfig, TeacherConfig
from craftsuite.population import train as population_train
from craftsuite.runs import RunDir, read_csv
from craftsuite.training import evaluate, train_student, train_teacher

TINY_DQN = {"learning_starts": 100, "buffer_size": 5_000, "policy_kwargs": {"net_arch": [16]}}


def _made_envs(monkeypatch) -> list:
    """Spy on the envs the population engine makes: (how many, world keywords) each time."""
    seen, real = [], population_train.make_envs

    def make_envs(env_id, n, env_kwargs, product):
        seen.append((n, env_kwargs))
        return real(env_id, n, env_kwargs, product)

    monkeypatch.setattr(population_train, "make_envs", make_envs)
    return seen


def test_a_grid_student_trains_and_is_evaluated_on_one_fixed_instance(tmp_path, monkeypatch):
    seen = _made_envs(monkeypatch)
    config = StudentConfig(method="dqn", world="Grid7", steps=300, eval_every=300, eval_episodes=2,
                           hyperparameters={**TINY_DQN, "learning_starts": 200}, layout_seed=3)
    path = train_student(config, tmp_path, progress=False)
    assert seen == [(1, {"layout_seed": 3}), (2, {"layout_seed": 3})]  # its envs, then its evaluation's
    assert json.loads((path / "result.json").read_text())["engine"] == "population"
    with pytest.raises(ValueError, match="the Cont world has none"):
        StudentConfig(world="Cont", layout_seed=3)
    with pytest.raises(ValueError, match="layout_seed must be a non-negative integer"):
        StudentConfig(method="dqn", world="Grid7", layout_seed=-1)  # refused before a run directory is made


def test_a_student_trains_and_is_evaluated_in_the_world_its_config_names(tmp_path, monkeypatch):
    seen = _made_envs(monkeypatch)
    world = {"frame_skip": 10, "max_episode_steps": 40}
    config = StudentConfig(method="td3", steps=200, eval_every=200, eval_episodes=1, world_kwargs=world,
                           hyperparameters={"learning_starts": 100, "policy_kwargs": {"net_arch": [16]},
                                            "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}})
    path = train_student(config, tmp_path, progress=False)
    assert {int(e["length"]) for e in read_csv(path / "episodes.csv")} == {40}  # 200 steps: 5 truncated episodes
    assert [kwargs for _, kwargs in seen] == [world, world]
    assert json.loads((path / "result.json").read_text())["env_kwargs"] == world  # for its video
    with pytest.raises(ValueError, match=r"may not set product: "):
        StudentConfig(world_kwargs={"product": False})


def _finished(config, root, result: dict):
    """A finished run of ``config`` under ``root``, as the SB3 trainer left one."""
    with RunDir(root / config.run_name(), config) as run:
        run.write_result(result)
    return run.path


@pytest.mark.parametrize("kind", ["student", "teacher"])
def test_the_sb3_engine_reuses_a_finished_run_and_trains_none(kind, tmp_path):
    train = train_student if kind == "student" else train_teacher
    config = (StudentConfig(method="dqn", world="Grid7", steps=300, engine="sb3") if kind == "student"
              else TeacherConfig(max_steps=400, engine="sb3"))
    path = _finished(config, tmp_path, {"steps": 300})
    records = [(path / name).read_text() for name in ("config.json", "result.json")]
    assert train(config, tmp_path, progress=False) == path
    assert [(path / name).read_text() for name in ("config.json", "result.json")] == records  # left as it was
    unfinished = dataclasses.replace(config, seed=7)
    with pytest.raises(ValueError, match=r"^\S+-s7-\S+: the sb3 engine no longer trains .*--engine population$"):
        train(unfinished, tmp_path, progress=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # nothing written for it


def test_evaluate_reports_every_step_to_on_step():
    class Wanderer:  # one straight line: it cannot finish Blind Craftsman, so every episode runs 40 steps
        def predict(self, obs, deterministic=True):
            return np.tile([[0.7, -0.4]], (len(obs), 1)).astype(np.float32), None

    seen = {}
    success, mean_return, mean_length = evaluate(
        Wanderer(), "CraftSuite/BlindCraftsman-Cont-v0", 3, seed=5, product=False,
        env_kwargs={"max_episode_steps": 40}, on_step=lambda i, r, info: seen.setdefault(i, []).append(r))
    assert sorted(seen) == [0, 1, 2] and all(len(r) == 40 for r in seen.values())
    assert success == 0.0 and mean_length == 40.0
    assert np.isclose(mean_return, np.mean([sum(r) for r in seen.values()]))

