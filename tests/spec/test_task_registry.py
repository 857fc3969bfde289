"""The task registry: what a task name means, and user tasks that travel as data."""

from __future__ import annotations

import dataclasses
import json
import tomllib

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.envs.registration import EnvSpec

import craftsuite
from craftsuite import task_registry
from craftsuite.spec import SpecError, builtin_specs, load_spec

from .test_load import GOOD, write


def test_the_package_exports_the_registry():
    assert craftsuite.tasks is task_registry.tasks and craftsuite.resolve_task is task_registry.resolve_task
    assert set(task_registry.builtin_names()) == set(builtin_specs()) <= set(task_registry.tasks())


@pytest.mark.parametrize("name", sorted(builtin_specs()))
def test_a_spec_as_data_rebuilds_itself(name):
    spec = task_registry.tasks()[name]
    data = json.loads(json.dumps(spec.to_data()))
    again = load_spec(data)
    assert again == dataclasses.replace(spec, path=None) and again.digest() == spec.digest()
    assert again.proposition_names == spec.proposition_names  # bit order kept
    assert task_registry.resolve_task(data) is spec  # the registered spec, not a copy
    assert task_registry.carried(spec) == name


def test_unknown_task_names_the_known_ones():
    with pytest.raises(KeyError, match="unknown task 'Nope'; tasks: .* Reach, .*spec file"):
        task_registry.resolve_task("Nope")


def test_bad_data_is_a_spec_error():
    with pytest.raises(SpecError, match="given as data.*formula"):
        task_registry.resolve_task({"name": "Bad", "formula": "F(x)", "propositions": {}, "items": {"x": {"count": 1}}})


@pytest.fixture
def user_task(tmp_path):
    """A user task registered for one test, then forgotten (ids and registry)."""
    text = GOOD.replace('name = "Treasure"', 'name = "TreasureAsData"')
    ids = craftsuite.register_task(write(tmp_path, text))
    yield ids
    for env_id in ids:
        del gym.registry[env_id]
    del task_registry.tasks()["TreasureAsData"]


def test_user_task_ids_carry_the_spec_as_data(user_task):
    spec = task_registry.tasks()["TreasureAsData"]
    for env_id in user_task:
        carried = gym.spec(env_id).kwargs["task"]
        assert carried == spec.to_data() and load_spec(carried).digest() == spec.digest()


def test_user_task_specs_round_trip_through_json(user_task):
    for env_id in user_task:
        text = gym.spec(env_id).to_json()
        back = EnvSpec.from_json(text)
        assert back.to_json() == text and back.max_episode_steps == gym.spec(env_id).max_episode_steps
        env, reference = gym.make(back, product=True), gym.make(env_id, product=True)
        obs, _ = env.reset(seed=3)
        assert np.array_equal(obs, reference.reset(seed=3)[0])
        assert env.unwrapped.task.digest() == task_registry.tasks()["TreasureAsData"].digest()
        env.close(), reference.close()


def test_a_json_spec_builds_its_world_where_the_task_was_never_registered(user_task):
    import subprocess
    import sys

    code = ("import sys, gymnasium as gym, craftsuite; from gymnasium.envs.registration import EnvSpec; "
            "assert 'TreasureAsData' not in craftsuite.tasks(); "
            "env = gym.make(EnvSpec.from_json(sys.stdin.read())); env.reset(seed=0); "
            "print(env.unwrapped.automaton.propositions)")
    out = subprocess.run([sys.executable, "-c", code], input=gym.spec(user_task[0]).to_json(), text=True,
                         capture_output=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "('coin', 'trap')"


def test_subprocess_vector_env_of_a_user_task(user_task):
    # spawned workers start afresh: they know the task only from the id's carried data
    envs = gym.make_vec(user_task[0], num_envs=2, vectorization_mode="async", vector_kwargs={"context": "spawn"})
    try:
        obs, _ = envs.reset(seed=0)
        assert obs.shape[0] == 2
        obs, reward, term, trunc, info = envs.step(envs.action_space.sample())
        assert reward.shape == (2,)
    finally:
        envs.close()


def test_a_user_task_named_as_a_built_in_is_refused_and_the_built_in_kept(tmp_path):
    """Runs are keyed by the task's name: another task called Reach would pool with Reach's
    runs on every leaderboard. The built-in's own spec, registered again, is the same task."""
    from craftsuite.spec import tasks_dir

    reach, ids = task_registry.tasks()["Reach"], craftsuite.registered_ids()
    text = (tasks_dir() / "first_wood.toml").read_text().replace('name = "FirstWood"', 'name = "Reach"')
    assert 'name = "Reach"' in text
    with pytest.raises(SpecError, match=r"my\.toml: name: 'Reach' is a built-in task's, whose runs this task's would "
                                        r"pool with: name yours otherwise, e.g. MyReach$"):
        craftsuite.register_task(write(tmp_path, text, "my.toml"))
    with pytest.raises(SpecError, match=r"^<task spec 'Reach' given as data>: name: 'Reach' is a built-in"):
        craftsuite.register_task(load_spec(tomllib.loads(text)).to_data())
    assert task_registry.tasks()["Reach"] is reach and craftsuite.registered_ids() == ids
    assert craftsuite.register_task(tasks_dir() / "reach.toml")  # the same task: its ids again
    assert task_registry.tasks()["Reach"] is reach


def test_a_user_task_registered_again_warns_only_where_its_rules_changed(tmp_path, user_task):
    import warnings

    text = GOOD.replace('name = "Treasure"', 'name = "TreasureAsData"')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        craftsuite.register_task(write(tmp_path, text))  # the same rules: its ids again, silently
    edited = text.replace("max_steps = ", "max_steps = 1").replace("count = 1", "count = 2")
    assert edited != text
    with pytest.warns(UserWarning, match="'TreasureAsData' was registered already, with other rules"):
        craftsuite.register_task(write(tmp_path, edited, "edited.toml"))
