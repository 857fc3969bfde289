"""Every registered CraftSuite id, checked the way Minigrid checks its envs."""

from __future__ import annotations

import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env
from stable_baselines3.common.env_checker import check_env as sb3_check_env

import craftsuite
from craftsuite.rendering.panel import PANEL_HEIGHT

IDS = craftsuite.registered_ids()


def actions(env, n, seed=0):
    space = env.action_space
    space.seed(seed)
    return [space.sample() for _ in range(n)]


def rollout(env, seed, n=60, action_seed=0):
    obs, info = env.reset(seed=seed)
    trace = [(obs, None, info["automaton_state"])]
    for a in actions(env, n, action_seed):
        obs, r, term, trunc, info = env.step(a)
        trace.append((obs, r, info["automaton_transition"]))
        if term or trunc:
            obs, info = env.reset()
            trace.append((obs, None, info["automaton_state"]))
    return trace


def same(a, b):
    return len(a) == len(b) and all(
        np.array_equal(x[0], y[0]) and x[1] == y[1] and x[2] == y[2] for x, y in zip(a, b))


def test_ids_cover_the_paper_tasks():
    tasks = ("BlindCraftsman", "DungeonQuest", "DiamondMine")
    expected = {f"CraftSuite/{t}-Grid{s}-v0" for t in tasks for s in (7, 10)}
    expected |= {"CraftSuite/BlindCraftsmanObstacles-Grid10-v0"}
    expected |= {f"CraftSuite/{t}-Cont-v0" for t in tasks + ("BlindCraftsmanObstacles",)}
    assert expected <= set(IDS)


@pytest.mark.parametrize("env_id", IDS)
def test_gymnasium_check_env(env_id):
    env = gym.make(env_id, disable_env_checker=True).unwrapped
    gym_check_env(env, skip_render_check=False)
    product = gym.make(env_id, product=True, disable_env_checker=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # check_env notes that the env is wrapped
        gym_check_env(product)


@pytest.mark.parametrize("env_id", IDS)
def test_sb3_check_env(env_id):
    for product in (False, True):
        sb3_check_env(gym.make(env_id, product=product), warn=True)


@pytest.mark.parametrize("env_id", IDS)
def test_same_seed_same_rollout(env_id):
    a = rollout(gym.make(env_id, product=True), seed=123)
    b = rollout(gym.make(env_id, product=True), seed=123)
    assert same(a, b)


@pytest.mark.parametrize("env_id", IDS)
def test_different_seeds_different_layouts(env_id):
    env = gym.make(env_id)
    layouts = set()
    for seed in range(5):  # positions as text: arrays are not hashable
        env.reset(seed=seed)
        layouts.add(repr((env.unwrapped.agent_position, env.unwrapped.object_positions())))
    assert len(layouts) == 5


@pytest.mark.parametrize("env_id", IDS)
def test_render_modes(env_id, gl_available):
    if "-Cont-" in env_id and not gl_available:
        pytest.skip(gl_available.reason)
    env = gym.make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    frame = env.render()
    assert frame.dtype == np.uint8 and frame.shape == env.unwrapped.frame_shape
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) > 5  # not blank
    # by default the frame is the world alone: what the env documents, nothing of the automaton
    if "ansi" in env.metadata["render_modes"]:
        size = env.unwrapped.size
        assert frame.shape == (size * 32, size * 32, 3)
    else:
        u = env.unwrapped
        assert frame.shape == (u.height, u.width, 3) == (240, 240, 3)
    env.close()
    shown = gym.make(env_id, render_mode="rgb_array", status_panel=True)
    shown.reset(seed=0)
    framed = shown.render()
    assert framed.shape == shown.unwrapped.frame_shape == (frame.shape[0] + PANEL_HEIGHT,) + frame.shape[1:]
    np.testing.assert_array_equal(framed[:frame.shape[0]], frame)
    shown.close()
    if "ansi" in env.metadata["render_modes"]:
        for status_panel, lines in ((False, size), (True, size + 1)):
            text = gym.make(env_id, render_mode="ansi", status_panel=status_panel)
            text.reset(seed=0)
            out = text.render()
            assert out.count("@") == 1 and len(out.splitlines()) == lines
            assert ("automaton state" in out) == status_panel


@pytest.mark.parametrize("env_id", IDS)
def test_pickling_mid_episode(env_id):
    env = gym.make(env_id, product=True)
    rollout(env, seed=5, n=7)
    clone = pickle.loads(pickle.dumps(env))
    for a in actions(env, 30, seed=9):
        x, y = env.step(a), clone.step(a)
        assert np.array_equal(x[0], y[0]) and x[1:4] == y[1:4]
        if x[2] or x[3]:
            break


@pytest.mark.parametrize("env_id", IDS)
@pytest.mark.parametrize("mode", ["sync", "async"])
def test_make_vec(env_id, mode):
    envs = gym.make_vec(env_id, num_envs=2, vectorization_mode=mode, product=True)
    try:
        obs, infos = envs.reset(seed=[1, 2])
        assert obs.shape == (2,) + envs.single_observation_space.shape
        assert not np.array_equal(obs[0], obs[1])
        for _ in range(20):
            obs, rewards, term, trunc, infos = envs.step(envs.action_space.sample())
        assert rewards.shape == (2,)
        assert "automaton_state" in infos
    finally:
        envs.close()


def test_the_automaton_state_is_added_once():
    from craftsuite import AutomatonObservation

    env = gym.make("CraftSuite/Reach-Grid7-v0", product=True)
    for wrapped in (env, gym.wrappers.ClipReward(env, -1, 1)):  # under another wrapper, too
        with pytest.raises(ValueError, match=r"^the env observes the automaton state already \(made with "
                                             r"product=True, or wrapped in AutomatonObservation\): wrap it once$"):
            AutomatonObservation(wrapped)
    assert AutomatonObservation(gym.make("CraftSuite/Reach-Grid7-v0")).observation_space == env.observation_space


@pytest.mark.parametrize("env_id", IDS)
def test_product_observation_tail_is_automaton_one_hot(env_id):
    env = gym.make(env_id, product=True)
    n = env.unwrapped.automaton.n_states
    base = env.unwrapped.observation_space.shape[0]
    assert env.observation_space.shape == (base + n,)
    obs, info = env.reset(seed=3)
    assert obs[base:].argmax() == info["automaton_state"] and obs[base:].sum() == 1
    prev = info["automaton_state"]
    for a in actions(env, 100):
        obs, r, term, trunc, info = env.step(a)
        w, sigma, w2 = info["automaton_transition"]
        assert w == prev and w2 == info["automaton_state"] == obs[base:].argmax()
        assert w2 == env.unwrapped.automaton.step(w, sigma)
        prev = w2
        if term or trunc:
            break


@pytest.mark.parametrize("env_id", IDS)
def test_observations_stay_in_the_space_through_whole_episodes(env_id):
    """check_env only looks at a few steps; scripted play reaches full inventories."""
    from craftsuite.scripted import scripted_policy

    for product in (False, True):
        env = gym.make(env_id, product=product)
        policy = scripted_policy(env)
        for seed in range(3):
            obs, _ = env.reset(seed=seed)
            done = False
            while not done:
                assert env.observation_space.contains(obs), (seed, obs[obs > 1], obs[obs < -1])
                obs, _, term, trunc, _ = env.step(policy(obs))
                done = term or trunc
            assert env.observation_space.contains(obs)


@pytest.mark.parametrize("world", ["Grid7", "Cont", "Kinematic"])
def test_the_public_view_of_the_objects_agrees_with_the_world_and_is_a_snapshot(world):
    """What the scripted policies read: the grid's ``cells``, the continuous worlds'
    ``objects``; the world moves on without them and they cannot be written."""
    from craftsuite.envs.cells import EMPTY, WALL
    from craftsuite.scripted import scripted_policy

    env = gym.make(f"CraftSuite/BlindCraftsman-{world}-v0").unwrapped
    env.reset(seed=3)
    names = [o.name for o in env.task.objects]
    policy = scripted_policy(env)
    if world == "Grid7":
        before = env.cells
        size = env.size
        on_map = {n: sorted(divmod(c, size)[::-1] for c, k in enumerate(before) if k == i) for i, n in enumerate(names)}
        assert on_map == {n: sorted(p) for n, p in env.object_positions().items()}
        assert before[env.agent_position[1] * size + env.agent_position[0]] != WALL
        for _ in range(100):  # until the agent picks something up
            env.step(policy())
            if sum(k >= 0 for k in env.cells) < sum(k >= 0 for k in before):
                break
        assert sum(k >= 0 for k in env.cells) == sum(k >= 0 for k in before) - 1
        assert set(before) - set(range(len(names))) <= {EMPTY, WALL}
        return
    before = env.objects
    for kind, (name, positions) in enumerate(env.object_positions().items()):
        assert name == names[kind]
        mine = before.positions[before.present & (before.kinds == kind)]
        assert np.allclose(sorted(map(tuple, mine)), sorted(positions), atol=1e-4)
    with pytest.raises(ValueError):
        before.present[0] = False
    for _ in range(300):
        env.step(policy())
        if env.objects.present.sum() < before.present.sum():
            break
    assert env.objects.present.sum() == before.present.sum() - 1 and before.present.all()


@pytest.mark.parametrize("env_id,keywords,problem", [
    ("CraftSuite/Reach-Grid7-v0", {"foo": 1}, "unknown keyword 'foo' for the grid world; it accepts size, product, "
                                               "render_mode, layout_seed, status_panel, max_episode_steps"),
    ("CraftSuite/Reach-Cont-v0", {"layout_seed": 3}, "unknown keyword 'layout_seed' for the MuJoCo world; "
                                                     "it accepts product, render_mode, width, height, frame_skip"),
    ("CraftSuite/Reach-Kinematic-v0", {"frame_skip": 2}, "unknown keyword 'frame_skip' for the kinematic world; "
                                                         "it accepts product, render_mode, width, height, "
                                                         "status_panel, size, observation"),
    ("CraftSuite/Reach-Grid7-v0", {"width": 480}, "width: the grid world draws every cell 32 pixels a side "
                                                  "(Grid7: 224x224 frames); it has no frame size to set"),
])
def test_an_unknown_keyword_names_the_keywords_the_world_accepts(env_id, keywords, problem):
    with pytest.raises(ValueError) as err:
        gym.make(env_id, **keywords)
    assert str(err.value).startswith(problem) and "unexpected keyword" not in str(err.value)


@pytest.mark.parametrize("world,product", [("Grid7", "no"), ("Cont", 1), ("Kinematic", None)])
def test_product_is_true_or_false(world, product):
    """Any other value would pass as a truth value ("no" would add the automaton state)."""
    with pytest.raises(ValueError, match=f"^product must be True or False \\(whether the observation has the "
                                         f"automaton state's one-hot\\), got {product!r}$"):
        gym.make(f"CraftSuite/Reach-{world}-v0", product=product)


def test_every_keyword_a_world_lists_is_taken():
    from craftsuite.registration import world_keywords

    values = {"product": True, "render_mode": "rgb_array", "layout_seed": 1, "status_panel": True, "width": 64,
              "height": 48, "frame_skip": 2, "size": 10, "observation": "craftsuite", "max_episode_steps": 5,
              "disable_env_checker": True}
    for world in ("Grid7", "Cont", "Kinematic"):
        keywords = {k: values[k] for k in world_keywords(world) if not (world == "Grid7" and k == "size")}
        env = gym.make(f"CraftSuite/Reach-{world}-v0", **keywords)
        env.reset(seed=0)
        assert env.spec.max_episode_steps == 5
        env.close()


@pytest.mark.parametrize("env_id", IDS)
def test_plain_sb3_algorithms_train_on_every_id(env_id):
    """SB3 stays where users meet it: its own DQN (grid worlds) and TD3 (continuous ones)
    train on each id, with and without the automaton state, as on any gymnasium env."""
    import stable_baselines3 as sb3

    for product in (False, True):
        env = gym.make(env_id, product=product)
        algorithm = sb3.DQN if isinstance(env.action_space, gym.spaces.Discrete) else sb3.TD3
        model = algorithm("MlpPolicy", env, learning_starts=16, batch_size=8, buffer_size=64, seed=0, device="cpu",
                          policy_kwargs={"net_arch": [8]})
        model.learn(24)
        assert model.num_timesteps == 24 and model._n_updates > 0
        env.close()
