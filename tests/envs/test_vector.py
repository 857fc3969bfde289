"""The natively vectorized worlds give exactly what SyncVectorEnv over the single envs gives."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite.envs.vector import GridVectorEnv, KinematicVectorEnv
from craftsuite.scripted import scripted_policy

TASKS = ("Reach", "BlindCraftsman", "DungeonQuest", "DiamondMine", "BlindCraftsmanObstacles")
# Reach and BlindCraftsman end in success, DungeonQuest and DiamondMine mostly in violations
# on the grids; on the kinematic board the authors' tiles end the episode (Gold Mine's home
# visited early breaks its objective, which the episode outlives)
GRID_IDS = [f"CraftSuite/{t}-Grid{10 if 'Obstacles' in t or t == 'BlindCraftsman' else 7}-v0" for t in TASKS]
KINEMATIC_IDS = [f"CraftSuite/{t}-Kinematic-v0" for t in TASKS + ("GoldMine",)]
MODES = ("NextStep", "SameStep")
N_ENVS, STEPS, EPISODE = 6, 240, 60  # short episodes, so that truncations happen too


def make_pair(env_id, mode="NextStep", n=N_ENVS, **kwargs):
    """(native, SyncVectorEnv) for the same id and keywords."""
    native = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point",
                          autoreset_mode=mode, **kwargs)
    sync = gym.make_vec(env_id, num_envs=n, vectorization_mode="sync",
                        vector_kwargs={"autoreset_mode": AutoresetMode(mode)}, **kwargs)
    return native, sync


def assert_same(a, b, where=""):
    """Exact equality of what a vector env returns: arrays by dtype, shape and value; object
    arrays (label tuples, transitions, final observations) element by element; dicts by key."""
    if isinstance(b, dict):
        assert set(a) == set(b), f"{where}: keys differ by {set(a) ^ set(b)}"
        for key in b:
            assert_same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(b, np.ndarray) and b.dtype == object:
        assert isinstance(a, np.ndarray) and a.dtype == object and a.shape == b.shape, where
        for i, (x, y) in enumerate(zip(a, b)):
            assert_same(x, y, f"{where}[{i}]")
    elif isinstance(b, np.ndarray):
        assert isinstance(a, np.ndarray) and (a.dtype, a.shape) == (b.dtype, b.shape), \
            f"{where}: {getattr(a, 'dtype', type(a))} {getattr(a, 'shape', '')} vs {b.dtype} {b.shape}"
        assert np.array_equal(a, b), f"{where}: {a} != {b}"
    else:
        assert type(a) is type(b) and a == b, f"{where}: {a!r} != {b!r}"


def engine_part(info):
    """The native info without its engine-only ``transition`` keys (which SyncVectorEnv lacks)."""
    info = dict(info)
    return info.pop("transition"), info.pop("_transition"), info


def check_transitions(transition, stepped, info, mode):
    """``info["transition"]`` is the step's (w, sigma, w') wherever an env stepped."""
    if mode == "NextStep":
        # envs reset instead of stepping hold -1; the others' transition is in the info
        expected = [t if t is not None else (-1, -1, -1) for t in info["automaton_transition"]]
        assert stepped.tolist() == [t is not None for t in info["automaton_transition"]]
    else:
        assert stepped.all()
        final = info.get("final_info", {}).get("automaton_transition")
        expected = [final[i] if final is not None and info["_final_info"][i] else t
                    for i, t in enumerate(info["automaton_transition"])]
    assert transition.dtype == np.int64 and transition.shape == (len(stepped), 3)
    assert [tuple(r) for r in transition.tolist()] == expected


def actions_for(sync, policies, rng):
    """Even envs mostly scripted (so that episodes complete), odd ones at random (so that
    violations and truncations happen), from the sync envs' states."""
    actions = sync.action_space.sample()
    for i, policy in enumerate(policies):
        if i % 2 == 0 and rng.random() < 0.8:
            # the policy breaks ties with its env's generator: lend it another, so that the
            # sync envs' episodes draw what the native ones draw
            world = sync.envs[i].unwrapped
            own, world._np_random = world._np_random, rng
            try:
                actions[i] = policy()
            finally:
                world._np_random = own
    return actions


def compare(env_id, mode, steps=STEPS, seed=3, **kwargs):
    """Run both vector envs on the same actions; assert every output equal; count events."""
    kwargs = {"product": True, "max_episode_steps": EPISODE, **kwargs}
    native, sync = make_pair(env_id, mode, **kwargs)
    assert native.metadata["autoreset_mode"] == sync.metadata["autoreset_mode"] == AutoresetMode(mode)
    assert native.single_observation_space == sync.single_observation_space
    assert native.action_space == sync.action_space
    obs, info = native.reset(seed=seed)
    transition, stepped, info = engine_part(info)
    assert_same(obs, sync.reset(seed=seed)[0], "reset obs")
    assert_same(info, sync.reset(seed=seed)[1], "reset info")
    assert not stepped.any() and (transition == -1).all()
    policies = [scripted_policy(env.unwrapped) for env in sync.envs]
    rng = np.random.default_rng(seed)
    sync.action_space.seed(seed)
    events = {"pickup": 0, "success": 0, "violation": 0, "truncated": 0}
    for t in range(steps):
        actions = actions_for(sync, policies, rng)
        got, want = native.step(actions), sync.step(actions)
        for name, x, y in zip(("obs", "reward", "terminated", "truncated"), got, want):
            assert_same(x, y, f"step {t} {name}")
        transition, stepped, info = engine_part(got[4])
        assert_same(info, want[4], f"step {t} info")
        check_transitions(transition, stepped, info, mode)
        ends = info.get("final_info", info)  # SameStep: the ended steps' infos are the final ones
        events["pickup"] += int((got[1] > 0.5).sum())
        events["success"] += int(ends["is_success"].sum())
        events["violation"] += int(ends["violation"].sum())
        events["truncated"] += int(got[3].sum())
    native.close()
    sync.close()
    return events


@pytest.mark.parametrize("mode", MODES)
@pytest.mark.parametrize("env_id", GRID_IDS + KINEMATIC_IDS)
def test_native_vector_env_equals_sync_vector_env(env_id, mode):
    events = compare(env_id, mode)
    assert events["pickup"] and events["truncated"], events
    if env_id.split("/")[1].startswith(("Reach", "BlindCraftsman-")):
        assert events["success"], events
    if env_id in GRID_IDS and env_id.split("/")[1].startswith(("DungeonQuest", "DiamondMine")):
        assert events["violation"], events
    if env_id.endswith(("DungeonQuest-Kinematic-v0", "GoldMine-Kinematic-v0")):
        assert events["success" if "Dungeon" in env_id else "violation"], events


def test_board_size_and_observation_keywords_vectorize_too():
    for kwargs in ({"size": 10}, {"observation": "craftsuite"}):
        events = compare("CraftSuite/BlindCraftsman-Kinematic-v0", "SameStep", **kwargs)
        assert events["pickup"] and events["success"], (kwargs, events)


@pytest.mark.parametrize("env_id", ["CraftSuite/BlindCraftsman-Grid7-v0", "CraftSuite/Reach-Kinematic-v0"])
def test_plain_observations_equal_too(env_id):
    events = compare(env_id, "NextStep", steps=80, product=False)
    assert events["truncated"]


def test_fixed_grid_layout_equals_sync():
    assert compare("CraftSuite/DungeonQuest-Grid7-v0", "SameStep", steps=80, layout_seed=4)["truncated"]


@pytest.mark.parametrize("env_id", ["CraftSuite/DungeonQuest-Grid7-v0", "CraftSuite/DungeonQuest-Kinematic-v0",
                                    "CraftSuite/DungeonQuest-Cont-v0"])
def test_reset_mask_and_seed_lists_equal_sync(env_id):
    native, sync = make_pair(env_id, n=4, product=True)
    assert_same(native.reset(seed=[5, None, 7, 8])[0][[0, 2, 3]], sync.reset(seed=[5, None, 7, 8])[0][[0, 2, 3]])
    native.reset(seed=1), sync.reset(seed=1)
    for _ in range(3):
        actions = sync.action_space.sample()
        native.step(actions), sync.step(actions)
    mask = np.array([False, True, False, True])
    got, want = native.reset(options={"reset_mask": mask.copy()}), sync.reset(options={"reset_mask": mask.copy()})
    assert_same(got[0], want[0], "obs")
    assert_same(engine_part(got[1])[2], want[1], "info")
    actions = sync.action_space.sample()
    assert_same(native.step(actions)[0], sync.step(actions)[0], "obs after the masked reset")


def test_registered_ids_make_native_vector_envs():
    grid = gym.make_vec("CraftSuite/BlindCraftsman-Grid10-v0", num_envs=3, product=True)  # the default mode
    kinematic = gym.make_vec("CraftSuite/Reach-Kinematic-v0", num_envs=2, vectorization_mode="vector_entry_point")
    assert isinstance(grid, GridVectorEnv) and isinstance(kinematic, KinematicVectorEnv)
    assert (grid.num_envs, grid.size, grid.max_episode_steps) == (3, 10, 1000)
    assert grid.spec.kwargs["num_envs"] == 3 and grid.spec.kwargs["product"] is True
    assert kinematic.max_episode_steps == 1000 and not kinematic.product
    obs, _ = grid.reset(seed=0)
    assert obs.dtype == np.float32 and obs.shape == (3,) + grid.single_observation_space.shape
    # the single ids keep their entry points
    assert type(gym.make("CraftSuite/BlindCraftsman-Grid10-v0").unwrapped).__name__ == "GridWorldEnv"


def test_keywords_and_actions_are_checked():
    grid_id, kinematic_id = "CraftSuite/Reach-Grid7-v0", "CraftSuite/Reach-Kinematic-v0"
    mode = {"vectorization_mode": "vector_entry_point"}
    with pytest.raises(ValueError, match=r"^unknown keyword 'frame_skip' for the vectorized kinematic world; it "):
        gym.make_vec(kinematic_id, num_envs=2, frame_skip=3, **mode)
    with pytest.raises(ValueError, match="does not render.*gymnasium.make"):
        gym.make_vec(grid_id, num_envs=2, render_mode="rgb_array", **mode)
    with pytest.raises(ValueError, match="autoreset_mode 'Disabled'"):
        gym.make_vec(grid_id, num_envs=2, autoreset_mode="Disabled", **mode)
    with pytest.raises(ValueError, match="layout_seed"):
        gym.make_vec(grid_id, num_envs=2, layout_seed=-1, **mode)
    grid = gym.make_vec(grid_id, num_envs=2, **mode)
    with pytest.raises(RuntimeError, match="reset"):
        grid.step(np.array([0, 1]))
    for seed in (1.5, "7"):  # a float was read as a list of seeds ("'float' object is not iterable")
        with pytest.raises(ValueError, match=rf"^reset\(seed=...\) takes None, an integer or one seed per env, "
                                             rf"got {seed!r}$"):
            grid.reset(seed=seed)
    with pytest.raises(ValueError, match=r"got 3 seeds for num_envs=2"):
        grid.reset(seed=[0, 1, 2])
    for seeds, index, bad in (([0, True], 1, "True"), ([0, 1.5], 1, "1.5"), ([-1, None], 0, "-1")):
        with pytest.raises(ValueError, match=rf"^reset\(seed=...\)'s seed {index} is {bad}: each is None or an "):
            grid.reset(seed=seeds)
    first, _ = grid.reset(seed=0)
    for same in (np.int64(0), range(2), np.arange(2), [np.int64(0), 1]):  # numpy's integers as Python's
        again, _ = grid.reset(seed=same)
        assert np.array_equal(first, again), same
    with pytest.raises(ValueError, match=r"integer array of shape \(2,\)"):
        grid.step(np.array([0, 4]))
    board = gym.make_vec(kinematic_id, num_envs=2, **mode)
    board.reset(seed=0)
    with pytest.raises(ValueError, match="NaN or infinite.*rows \\[1\\]"):
        board.step(np.array([[0.0, 0.0], [np.nan, 0.0]]))
