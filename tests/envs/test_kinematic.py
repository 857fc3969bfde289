"""The kinematic world: the authors' step, bounds, pickup distance, episode length, tiles,
labels and observation; the task's automaton; no MuJoCo."""

from __future__ import annotations

import subprocess
import sys

import gymnasium as gym
import numpy as np
import pytest

import craftsuite
from craftsuite.envs.kinematic import KinematicWorldEnv
from craftsuite.episodes import rollout
from craftsuite.ids import world_kind
from craftsuite.scripted import KinematicScriptedPolicy

BC = "CraftSuite/BlindCraftsman-Kinematic-v0"


def fresh(task="BlindCraftsman", seed=0) -> KinematicWorldEnv:
    env = KinematicWorldEnv(task)
    env.reset(seed=seed)
    return env


def clear_objects(env):
    """Park every object far from the agent's moves (still present)."""
    env._positions[:] = -100.0


def test_every_task_has_a_kinematic_id_of_kind_cont():
    ids = craftsuite.registered_ids()
    for name in craftsuite.tasks():
        assert f"CraftSuite/{name}-Kinematic-v0" in ids
    assert world_kind("Kinematic") == "Cont"
    assert gym.spec(BC).max_episode_steps == 1000


def test_step_moves_three_times_the_clipped_action():
    env = fresh()
    clear_objects(env)
    env._position = np.array([3.0, 3.0])
    _, reward, *_ = env.step(np.array([0.5, -0.25], dtype=np.float32))
    np.testing.assert_allclose(env.agent_position, [4.5, 2.25])
    assert reward == pytest.approx(env.task.step_reward)
    env._position = np.array([1.0, 1.0])
    env.step(np.array([7.0, -0.0]))  # clipped to 1: moves 3, not 21
    np.testing.assert_allclose(env.agent_position, [4.0, 1.0])


@pytest.mark.parametrize("start, action", [((6.0, 3.0), (0.5, 0.0)),   # ends at x = 7.5
                                           ((1.0, 3.0), (-0.5, 0.0)),  # x = -0.5
                                           ((3.0, 5.0), (0.0, 0.7))])  # y = 7.1: the board is [0, 7)
def test_an_off_board_move_is_rejected_with_the_penalty(start, action):
    env = fresh()
    clear_objects(env)
    env._position = np.array(start)
    obs, reward, *_ = env.step(np.array(action, dtype=np.float32))
    np.testing.assert_allclose(env.agent_position, start)  # the agent stays
    assert reward == pytest.approx(env.task.step_reward - 0.1)
    np.testing.assert_allclose(obs[:2], np.array(start) / 7, atol=1e-6)  # the authors' x / 7, y / 7


def test_a_rejected_move_touches_nothing_even_beside_an_object():
    env = fresh()
    clear_objects(env)
    wood = env.kinds.index(0)
    env._position = np.array([6.5, 3.0])
    env._positions[wood] = (6.6, 3.0)  # within reach, but the move is rejected
    env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert env._present[wood] and sum(env.inventory_counts) == 0


@pytest.mark.parametrize("gap, picked", [(0.0, True), (0.39, True), (0.41, False)])
def test_pickup_within_0_4(gap, picked):
    env = fresh()
    clear_objects(env)
    wood = env.kinds.index(0)  # BlindCraftsman's first item: wood, free to pick up
    env._position = np.array([2.0, 2.0])
    env._positions[wood] = (5.0 + gap, 2.0)
    env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert (not env._present[wood]) == picked
    assert (env.inventory["wood"] == 1) == picked


def test_home_is_the_corner_and_the_first_slot():
    for seed in range(5):
        env = fresh(seed=seed)
        home = env.kinds.index(env.task.objects.index(next(p for p in env.task.places if p.name == "home")))
        assert home == 0 and tuple(env._positions[0]) == (0.0, 0.0)
        assert not any((p == 0).all() for p in env._positions[1:])  # nothing else on (0, 0)


def test_wood_touched_at_capacity_is_used_up_and_clipped():
    env = fresh()
    clear_objects(env)
    woods = [j for j, k in enumerate(env.kinds) if k == 0]
    env.inventory_counts[0] = 2  # already carrying two
    env._position = np.array([1.0, 1.0])
    env._positions[woods[0]] = (4.0, 1.0)
    _, reward, *_ = env.step(np.array([1.0, 0.0], dtype=np.float32))
    assert not env._present[woods[0]] and env.inventory["wood"] == 2  # gone, not carried
    assert reward == pytest.approx(-0.1 + 1.0)  # the wood's +1 all the same


def test_the_factory_turns_one_wood_a_step_while_in_reach():
    env = fresh()
    clear_objects(env)
    factory = env.kinds.index(1)
    env.inventory_counts[0] = 2
    env._position = np.array([3.0, 3.0])
    env._positions[factory] = (3.0, 3.0)
    rewards = [env.step(np.zeros(2, dtype=np.float32))[1] for _ in range(3)]
    assert rewards == pytest.approx([-0.1 + 1, -0.1 + 1, -0.1])  # a tool a step, then no wood
    assert env.inventory == {"wood": 0, "tools": 2}


def test_home_with_three_tools_pays_100_ends_the_episode_and_accepts():
    env = fresh()
    clear_objects(env)
    env._positions[0] = (0.0, 0.0)  # home
    env.inventory_counts[1] = 3
    env._level_mask = env.labeller.levels(env.inventory_counts)
    env._position = np.array([0.9, 0.9])
    # inside home's cell but not within reach: at_home and tools3 hold, home does not act
    obs, reward, term, _, info = env.step(np.array([-0.1, -0.1], dtype=np.float32))
    assert not term and reward == pytest.approx(-0.1) and set(info["labels"]) >= {"home", "tools3"}
    # the automaton accepts there, but the task is not complete: the board's home has not acted
    assert env.automaton.accepting[info["automaton_state"]] and not info["is_success"]
    obs, reward, term, _, info = env.step(np.array([-0.15, -0.15], dtype=np.float32))  # to (0.15, 0.15)
    assert term and info["is_success"] and reward == pytest.approx(-0.1 + 100)


def test_a_tile_that_ends_the_episode_with_the_objective_unmet_is_no_success():
    """Gold Mine's home acts with ten silver even where the automaton was violated (the
    agent crossed home's cell before the tenth silver): +100 and the end, but no success."""
    env = gym.make("CraftSuite/GoldMine-Kinematic-v0").unwrapped
    env.reset(seed=0)
    clear_objects(env)
    home = env.kinds.index(next(k for k, o in enumerate(env.task.objects) if o.name == "home"))
    env._positions[home] = (0.0, 0.0)
    env._position = np.array([0.9, 0.9])
    _, _, term, _, info = env.step(np.array([-0.1, -0.1], dtype=np.float32))  # in home's cell, no silver
    assert not term and info["violation"]
    env.inventory_counts[env.rules.inventory_names.index("silver")] = 10
    _, reward, term, _, info = env.step(np.array([-0.15, -0.15], dtype=np.float32))  # home acts
    assert term and reward == pytest.approx(-0.1 + 100) and not info["is_success"]


@pytest.mark.parametrize("mode", ["single", "vector"])
def test_random_play_completes_blind_craftsman_as_often_as_the_authors_board(mode):
    """Uniformly random actions end 11.9-12.4% of 1,000-step episodes at home on the authors'
    own board (5,000 episodes); the automaton alone accepts in about 41%. Success here is
    completion: each env's first episode, so that short episodes are not over-counted."""
    n = 3000 if mode == "vector" else 300
    rng = np.random.default_rng(0)
    if mode == "vector":
        env = gym.make_vec(BC, num_envs=n, vectorization_mode="vector_entry_point", autoreset_mode="SameStep")
        env.reset(seed=0)
        over, success = np.zeros(n, dtype=bool), np.zeros(n, dtype=bool)
        while not over.all():
            _, _, term, trunc, info = env.step(rng.uniform(-1, 1, (n, 2)))
            ended = (term | trunc) & ~over
            if ended.any():
                success[ended] = info["final_info"]["is_success"][ended]
            over |= ended
    else:
        env = gym.make(BC)
        success = np.array([rollout(env, lambda obs: rng.uniform(-1, 1, 2).astype(np.float32), 1, s)[0].success
                            for s in range(n)])
    half_width = 2.5 * np.sqrt(0.12 * 0.88 / n)  # 2.5 standard errors around the authors' figure
    assert 0.119 - half_width <= success.mean() <= 0.124 + half_width, success.mean()


def test_the_authors_observation_and_craftsuites():
    env = fresh()
    layout = env.observation_layout
    obs = env._obs
    np.testing.assert_allclose(obs[layout["agent_position"]], env.agent_position / 7, atol=1e-6)
    dists = np.linalg.norm(env._positions - env.agent_position, axis=1) / 7
    np.testing.assert_allclose(obs[layout["distances"]], dists, atol=1e-6)
    assert layout["object_names"][0] == "home" and env.observation_space.shape == (2 + 5 + 2,)
    ours = KinematicWorldEnv("BlindCraftsman", observation="craftsuite")
    assert ours.observation_space.shape == (2 + 3 * 5 + 2,)
    with pytest.raises(ValueError, match=r"^observation='pixels': use one of 'authors', 'craftsuite'$"):
        KinematicWorldEnv("BlindCraftsman", observation="pixels")


def test_board_size_10_and_bad_sizes():
    env = gym.make(BC, size=10)
    env.reset(seed=3)
    assert env.unwrapped.arena == 10.0 and env.unwrapped._positions.max() <= 9
    with pytest.raises(ValueError, match=r"^size=8: the kinematic board is 7 or 10 units a side$"):
        gym.make(BC, size=8)
    vec = gym.make_vec(BC, num_envs=2, vectorization_mode="vector_entry_point", size=10)
    assert vec.single_observation_space.shape == env.observation_space.shape


class AuthorsBlindCraftsman:
    """The authors' continuous Blind Craftsman, re-implemented from their
    ``MineWorldEnvContinuous.step`` and ``obs`` (mineworldenv.py), their blind_craftsman_7
    config, the ``RewEveryStep(-0.1)`` wrapper and their training loop's labels; laid out
    as ``tiles`` ((x, y) -> name, their dict order) and ``start``."""

    TILES = {"wood": dict(consumable=True, mod={"wood": 1}, req={}, reward=1, terminal=False),
             "factory": dict(consumable=False, mod={"wood": -1, "tool": 1}, req={}, reward=1, terminal=False),
             "home": dict(consumable=False, mod={}, req={"tool": 3}, reward=100, terminal=True)}
    CAPACITY = {"wood": 2, "tool": 3}

    def __init__(self, tiles: dict, start):
        self.tiles, self.start_tiles = dict(tiles), list(tiles)
        self.pos = tuple(start)
        self.inv = {"wood": 0, "tool": 0}
        self.done = False

    def step(self, action):
        names = set()
        prev = self.pos
        new = (self.pos[0] + 3.0 * action[0], self.pos[1] + 3.0 * action[1])
        reward = 0
        if 0 <= new[0] < 7 and 0 <= new[1] < 7:
            self.pos = new
            for where in list(self.tiles):
                tile = self.TILES[self.tiles[where]]
                after = {k: self.inv[k] + tile["mod"].get(k, 0) for k in self.inv}
                meets = all(self.inv[k] >= v for k, v in tile["req"].items()) and min(after.values()) >= 0
                if meets and np.linalg.norm([self.pos[0] - where[0], self.pos[1] - where[1]]) < 0.4:
                    self.inv = {k: min(v, self.CAPACITY[k]) for k, v in after.items()}
                    names.add(self.tiles[where])
                    if tile["consumable"]:
                        del self.tiles[where]
                    self.done |= tile["terminal"]
                    reward += tile["reward"]
                    break
        else:
            self.pos = prev
            reward += -0.1
        labels = {"wood"} & names | {"factory"} & names
        if (int(self.pos[0]), int(self.pos[1])) == (0, 0):
            labels.add("home")
        if self.inv["tool"] == 3:
            labels.add("tools3")
        dists = [np.linalg.norm([w[0] - self.pos[0], w[1] - self.pos[1]]) if w in self.tiles else 0.0
                 for w in self.start_tiles]
        obs = np.concatenate([np.array(self.pos) / 7, np.array(dists) / 7, [self.inv["wood"], self.inv["tool"]]])
        return obs, reward - 0.1, self.done, labels


def test_random_play_matches_a_reimplementation_of_the_authors_step():
    """Same layouts, same actions: the same positions, rewards, ends, inventories,
    observations and labels as the authors' step, for 60 random episodes."""
    env = gym.make(BC)
    u = env.unwrapped
    rng = np.random.default_rng(0)
    names = [env.unwrapped.task.objects[k].name for k in u.kinds]
    completed, at_capacity_losses = 0, 0
    for seed in range(60):
        obs, _ = env.reset(seed=seed)
        theirs = AuthorsBlindCraftsman({tuple(p): n for p, n in zip(u._positions.tolist(), names)}, u.agent_position)
        for _ in range(1000):
            action = rng.uniform(-1, 1, 2).astype(np.float32)
            obs, reward, term, trunc, info = env.step(action)
            their_obs, their_reward, their_done, their_labels = theirs.step(action.astype(np.float64))
            np.testing.assert_allclose(u.agent_position, theirs.pos)
            assert reward == pytest.approx(their_reward) and term == their_done
            assert u.inventory == {"wood": theirs.inv["wood"], "tools": theirs.inv["tool"]}
            assert set(info["labels"]) == their_labels
            np.testing.assert_allclose(obs, their_obs, atol=1e-5)
            if term or trunc:
                break
        completed += bool(term)
        at_capacity_losses += sum(n == "wood" for n in theirs.tiles.values()) == 0 and theirs.inv["tool"] < 3
    assert 0 < completed < 60  # random play completes some episodes, not all
    assert at_capacity_losses > 0  # and some lose a wood picked up at capacity, as theirs do


def test_labels_and_transitions_are_the_tasks_automaton():
    """The kinematic world's automaton is the task's (the grid's and MuJoCo's), and every
    transition it reports is that automaton's step on the label it reports."""
    kin = gym.make(BC, product=True)
    grid = gym.make("CraftSuite/BlindCraftsman-Grid7-v0")
    assert kin.unwrapped.automaton is grid.unwrapped.automaton
    policy = KinematicScriptedPolicy(kin)
    moved = set()
    for seed in range(3):
        obs, info = kin.reset(seed=seed)
        prev, done = info["automaton_state"], False
        while not done:
            obs, _, term, trunc, info = kin.step(policy(obs))
            w, sigma, w2 = info["automaton_transition"]
            assert w == prev and w2 == kin.unwrapped.automaton.step(w, sigma) == info["automaton_state"]
            moved |= {w2} - {w}
            prev, done = w2, term or trunc
    assert len(moved) >= 2  # the scripted play went through the automaton, not just stayed


def test_episodes_truncate_at_1000_steps():
    env = gym.make("CraftSuite/Reach-Kinematic-v0")
    env.reset(seed=0)
    # standing still far from the goal: the episode can only run out
    env.unwrapped._position = np.array([0.5, 0.5])
    env.unwrapped._positions[:] = (6.0, 6.0)
    for t in range(1, 1001):  # noqa: B007  (t: how long the episode ran)
        _, _, term, trunc, _ = env.step(np.zeros(2, dtype=np.float32))
        assert not term
        if trunc:
            break
    assert t == 1000 and trunc


def test_bad_actions_and_frames_are_clear_errors():
    env = fresh()
    with pytest.raises(ValueError, match="expected 2 numbers"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="NaN or infinite"):
        env.step(np.array([np.nan, 0.0]))
    with pytest.raises(ValueError, match=r"^width must be a whole number of pixels"):
        KinematicWorldEnv("Reach", width=0)


def test_rendering_is_the_frame_asked_for():
    env = gym.make(BC, render_mode="rgb_array", width=320, height=200)
    env.reset(seed=1)
    frame = env.render()
    assert frame.shape == (200, 320, 3) and frame.dtype == np.uint8
    col, row = env.unwrapped.world_to_pixel(*env.unwrapped.agent_position)
    assert frame[row, col].max() < 60  # the agent, drawn dark where it stands


def test_importing_the_world_does_not_import_mujoco():
    code = ("import sys, gymnasium as gym, craftsuite\n"
            "from craftsuite.envs.kinematic import KinematicWorldEnv\n"
            "env = gym.make('CraftSuite/DiamondMine-Kinematic-v0', render_mode='rgb_array')\n"
            "env.reset(seed=0); env.step(env.action_space.sample()); env.render()\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('mujoco', 'dm_control')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"


def test_the_scripted_policy_completes_blind_craftsman():
    env = gym.make(BC)
    policy = KinematicScriptedPolicy(env)
    wins = sum(rollout(env, policy, 1, s)[0].success for s in range(10))
    assert wins == 10
