"""The natively vectorized MuJoCo world gives exactly what SyncVectorEnv over the single envs
gives (bitwise: same observations, rewards, flags, infos and MjData state)."""

from __future__ import annotations

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import craftsuite  # noqa: F401  (registers the ids; chooses MUJOCO_GL before mujoco is imported)
import mujoco  # noqa: E402,I001
from craftsuite.envs.continuous_vector import ContinuousVectorEnv
from tests.envs.test_vector import MODES, assert_same, compare, make_pair

CONT_IDS = [f"CraftSuite/{t}-Cont-v0" for t in ("Reach", "BlindCraftsman", "DungeonQuest")]
N_ENVS = 4
# (steps, seed) per id: enough for pickups, truncations and each task's ending (Reach and
# BlindCraftsman succeed; DungeonQuest's random envs also walk into violations)
RUNS = {"Reach": (240, 3), "BlindCraftsman": (240, 3), "DungeonQuest": (240, 8)}


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", CONT_IDS)
def test_native_mujoco_vector_env_equals_sync_vector_env(env_id, mode):
    task = env_id.split("/")[1].split("-")[0]
    steps, seed = RUNS[task]
    events = compare(env_id, mode, steps=steps, seed=seed, n=N_ENVS, max_episode_steps=40)
    assert events["truncated"] and events["success"], events
    if task != "Reach":  # item rewards on steps that did not complete the task: pickups
        assert events["pickup"] > events["success"], events
    if task == "DungeonQuest":
        assert events["violation"], events


def test_physics_state_is_the_single_envs_bit_for_bit():
    """After resets, steps and autoresets, each env's MjData integration state equals the
    single env's (qpos, qvel, ctrl, warm start, time), with a non-default frame_skip."""
    native, sync = make_pair("CraftSuite/BlindCraftsman-Cont-v0", "SameStep", n=3, max_episode_steps=15,
                             frame_skip=4)
    assert isinstance(native, ContinuousVectorEnv) and native.frame_skip == 4
    native.reset(seed=11), sync.reset(seed=11)
    sync.action_space.seed(0)
    for _ in range(40):  # two autoresets per env
        actions = sync.action_space.sample() * 1.5  # also out of range: both clip
        got, want = native.step(actions), sync.step(actions)
        assert_same(got[0], want[0])
        for data, env in zip(native._datas, sync.envs):
            assert np.array_equal(state(native.model, data), state(env.unwrapped.model, env.unwrapped.data))
    assert native.metadata["autoreset_mode"].value == "SameStep"


def state(model, data):
    """The MjData's integration state: time, qpos, qvel, act, warm start, ctrl, ..."""
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    out = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, out, spec)
    return out


def test_plain_observations_equal_sync():
    assert compare("CraftSuite/Reach-Cont-v0", "NextStep", steps=60, n=3, product=False,
                   max_episode_steps=20)["truncated"]


def test_registered_cont_ids_make_it_and_check_keywords():
    envs = gym.make_vec("CraftSuite/Reach-Cont-v0", num_envs=2, product=True)  # the default mode
    assert isinstance(envs, ContinuousVectorEnv)
    assert (envs.num_envs, envs.max_episode_steps, envs.frame_skip) == (2, 200, 10)
    assert envs.spec.kwargs["num_envs"] == 2 and envs.product is True
    assert type(gym.make("CraftSuite/Reach-Cont-v0").unwrapped).__name__ == "ContinuousWorldEnv"
    mode = {"vectorization_mode": "vector_entry_point"}
    cont = "CraftSuite/Reach-Cont-v0"
    with pytest.raises(ValueError,
                       match=r"^unknown keyword 'layout_seed' for the vectorized MuJoCo world; it accepts product"):
        gym.make_vec(cont, num_envs=2, layout_seed=3, **mode)
    with pytest.raises(ValueError, match="does not render.*gymnasium.make"):
        gym.make_vec(cont, num_envs=2, render_mode="rgb_array", **mode)
    with pytest.raises(ValueError, match="frame_skip must be a positive integer"):
        gym.make_vec(cont, num_envs=2, frame_skip=0, **mode)
    with pytest.raises(ValueError, match="autoreset_mode 'Disabled'"):
        gym.make_vec(cont, num_envs=2, autoreset_mode="Disabled", **mode)
    with pytest.raises(RuntimeError, match="reset"):
        envs.step(np.zeros((2, 2)))
    envs.reset(seed=0)
    with pytest.raises(ValueError, match="NaN or infinite.*rows \\[1\\]"):
        envs.step(np.array([[0.0, 0.0], [np.inf, 0.0]]))
    with pytest.raises(ValueError, match="2 rows of 2 numbers"):
        envs.step(np.zeros(2))
    with pytest.raises(NotImplementedError, match="does not render"):
        envs.render()


def test_importing_craftsuite_and_the_other_vector_envs_does_not_import_mujoco():
    code = ("import sys, gymnasium as gym, craftsuite, craftsuite.envs.vector; "
            "gym.make_vec('CraftSuite/Reach-Kinematic-v0', num_envs=2).reset(seed=0); "
            "assert 'mujoco' not in sys.modules, 'mujoco imported'")
    subprocess.run([sys.executable, "-c", code], check=True)
