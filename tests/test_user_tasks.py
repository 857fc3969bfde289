"""A user task (a spec file the driver registered) reaches the suites' worker processes."""

from __future__ import annotations

import json

import pytest

import craftsuite
from craftsuite import task_registry
from craftsuite.configs import StudentConfig
from craftsuite.suite_runner import run_students


@pytest.fixture
def user_task(treasure_spec):
    path = treasure_spec("WorkerTreasure", size=4, max_steps=20)
    craftsuite.register_task(path)
    return path


@pytest.mark.slow  # spawned workers
def test_students_of_a_user_task_run_in_fresh_worker_processes(user_task, tmp_path):
    # the pool's workers are spawned: they know only the built-in tasks, unless the job brings its task
    config = StudentConfig(task="WorkerTreasure", method="dqn", world="Grid4", steps=100, eval_every=100,
                           eval_episodes=1, hyperparameters={"learning_starts": 50, "buffer_size": 500})
    user_task.unlink()  # nor do they read the spec file: its data travels with the job
    [path] = run_students([config], tmp_path / "students", workers=1, progress=False)
    result = json.loads((path / "result.json").read_text())
    assert result["env_id"] == "CraftSuite/WorkerTreasure-Grid4-v0" and result["steps"] == 100
    record = json.loads((path / "config.json").read_text())
    assert record["effective"]["world"]["rules"] == task_registry.tasks()["WorkerTreasure"].digest()
