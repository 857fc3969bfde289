"""Rules and labelling through scripted play on the grid worlds."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import craftsuite
from craftsuite.labelling import Labeller
from craftsuite.rules import Rules
from craftsuite.episodes import rollout
from craftsuite.scripted import GridScriptedPolicy
from craftsuite.spec import builtin_specs

IDS = [i for i in craftsuite.registered_ids() if "-Grid" in i]


def kind_of(env, name):
    return [o.name for o in env.unwrapped.task.objects].index(name)


def visit(env, policy, name, max_steps=300):
    """Walk to the nearest object called ``name``; return the step results on the way."""
    kind = kind_of(env, name)
    steps = []
    start = env.unwrapped._cells.count(kind)
    for _ in range(max_steps):
        result = env.step(policy.toward(kind))
        steps.append(result)
        info = result[4]
        here = env.unwrapped._cells[env.unwrapped._agent]
        touched = env.unwrapped._cells.count(kind) < start or (
            here == kind and env.unwrapped.rules.is_place(kind))
        if touched or result[2] or result[3]:
            return steps, info
    raise AssertionError(f"did not reach {name}")


@pytest.mark.parametrize("env_id", IDS)
def test_scripted_policy_completes_every_task(env_id):
    env = gym.make(env_id)
    policy = GridScriptedPolicy(env)
    for seed in range(10):
        episode = rollout(env, policy, 1, seed)[0]
        assert episode.success, (seed, episode.length)
        a = env.unwrapped.automaton
        assert a.accepting[episode.info["automaton_state"]]
        assert episode.total_reward > 100 + env.unwrapped.task.step_reward * episode.length  # +100 earned, items on top


def test_completion_reward_exactly_on_the_accepting_step():
    env = gym.make("CraftSuite/BlindCraftsman-Grid7-v0")
    policy = GridScriptedPolicy(env)
    env.reset(seed=4)
    while True:
        obs, reward, term, trunc, info = env.step(policy())
        if term:
            break
        assert reward < 50
    assert info["is_success"] and reward == pytest.approx(100 - 0.1)
    assert "home" in info["labels"] and "tools3" in info["labels"]


def test_blind_craftsman_capacity_and_factory():
    env = gym.make("CraftSuite/BlindCraftsman-Grid10-v0")
    env.reset(seed=0)
    policy = GridScriptedPolicy(env)
    u = env.unwrapped
    _, info = visit(env, policy, "wood")
    assert u.inventory["wood"] == 1 and info["labels"] == ("wood",)
    visit(env, policy, "wood")
    assert u.inventory["wood"] == 2
    # a full agent cannot pick up the third wood: it stays on the map
    kind = kind_of(env, "wood")
    third = u._cells.index(kind)
    u._agent = third + 1 if third % u.size < u.size - 1 else third - 1
    if u._cells[u._agent] >= 0:
        pytest.skip("neighbour cell is occupied in this layout")
    env.step(3 if u._agent > third else 1)
    assert u._agent == third and u.inventory["wood"] == 2 and u._cells[third] == kind
    steps, info = visit(env, policy, "factory")
    assert u.inventory == {"wood": 0, "tools": 2}
    assert "factory" in info["labels"]
    obs = steps[-1][0]
    layout = u.observation_layout
    tools = layout["inventory_names"].index("tools")
    assert obs[layout["inventory"]][tools] == pytest.approx(2 / layout["inventory_scale"][tools])


def test_diamond_mine_wood_then_gold_is_a_violation():
    env = gym.make("CraftSuite/DiamondMine-Grid10-v0")
    env.reset(seed=2)
    policy = GridScriptedPolicy(env)
    visit(env, policy, "wood")
    steps, info = visit(env, policy, "gold")
    obs, reward, term, trunc, info = steps[-1]
    assert term and info["violation"] and not info["is_success"]
    assert env.unwrapped.automaton.rejecting[info["automaton_state"]]
    assert reward < 50  # no completion reward


@pytest.mark.parametrize("size", [7, 10])
def test_diamond_mine_diamond_route(size):
    """Wood and all 30 iron craft a pickaxe; the diamond then counts; home completes."""
    env = gym.make(f"CraftSuite/DiamondMine-Grid{size}-v0")
    env.reset(seed=1)
    policy = GridScriptedPolicy(env)
    u = env.unwrapped
    visit(env, policy, "wood")
    while u._cells.count(kind_of(env, "iron")):
        visit(env, policy, "iron")
    assert u.inventory["pickaxe"] == 1 and u.inventory["wood"] == 0
    _, info = visit(env, policy, "diamond")
    assert "diamond" in info["labels"]
    steps, info = visit(env, policy, "home")
    assert info["is_success"] and steps[-1][1] == pytest.approx(100 - 0.1)


def test_diamond_needs_the_pickaxe():
    rules = Rules(builtin_specs()["DiamondMine"])
    inv = rules.new_inventory()
    diamond = [o.name for o in rules.spec.objects].index("diamond")
    assert rules.touch(inv, diamond, arrived=True) is None
    inv[rules.inventory_names.index("pickaxe")] = 1
    assert rules.touch(inv, diamond, arrived=True).consumed
    gold = [o.name for o in rules.spec.objects].index("gold")
    assert rules.touch(inv, gold, arrived=True) is None  # excluded after the diamond


def test_dungeon_quest_unarmed_dragon_is_a_violation():
    env = gym.make("CraftSuite/DungeonQuest-Grid10-v0")
    env.reset(seed=0)
    policy = GridScriptedPolicy(env)
    steps, info = visit(env, policy, "dragon")
    assert steps[-1][2] and info["violation"] and info["labels"] == ("dragon",)


def test_dungeon_quest_chest_turns_key_into_sword():
    env = gym.make("CraftSuite/DungeonQuest-Grid7-v0")
    env.reset(seed=0)
    policy = GridScriptedPolicy(env)
    visit(env, policy, "chest")
    assert env.unwrapped.inventory["sword"] == 0  # no key, nothing happens
    visit(env, policy, "key")
    _, info = visit(env, policy, "chest")
    assert env.unwrapped.inventory == {"key": 0, "shield": 0, "sword": 1}
    assert info["labels"] == ("sword",)


def test_labeller_events_and_levels():
    spec = builtin_specs()["DiamondMine"]
    lab = Labeller(spec)
    rules = Rules(spec)
    inv = rules.new_inventory()
    gold = rules.inventory_names.index("gold")
    inv[gold] = 3
    assert lab.names(lab(inv, gained=1 << gold)) == ("gold3",)
    assert lab(inv, gained=0) == 0  # 'reached' is an event, not a level
    bc = builtin_specs()["BlindCraftsman"]
    lab = Labeller(bc)
    inv = [0, 3]
    assert lab.names(lab(inv)) == ("tools3",)  # 'at_least' is a level
    home = [o.name for o in bc.objects].index("home")
    assert lab.names(lab(inv, arrived=home)) == ("tools3", "home")


@pytest.mark.parametrize("action", [4, -1, 1.5, "up", None, np.array([1]), float("nan")])
def test_bad_actions_are_named(action):
    env = gym.make("CraftSuite/BlindCraftsman-Grid7-v0", disable_env_checker=True)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="invalid action .* expected an integer in \\[0, 4\\)"):
        env.step(action)


def test_numpy_integer_actions_work():
    env = gym.make("CraftSuite/BlindCraftsman-Grid7-v0")
    env.reset(seed=0)
    env.step(np.int64(1))
    env.step(np.array(2))  # 0-d, as SB3's predict returns
    with pytest.raises(ValueError, match="invalid action"):
        env.step(np.array(2.5))


def test_step_before_reset():
    env = craftsuite.make_grid("BlindCraftsman", 7)
    with pytest.raises(RuntimeError, match="reset"):
        env.step(0)


def test_bad_ids_and_tasks():
    with pytest.raises(gym.error.NameNotFound):
        gym.make("CraftSuite/BlindCraftsmen-Grid7-v0")
    with pytest.raises(KeyError, match="unknown task 'Nope'.*BlindCraftsman"):
        craftsuite.make_grid("Nope", 7)
    with pytest.raises(ValueError, match="render_mode 'human'"):
        craftsuite.make_grid("BlindCraftsman", 7, render_mode="human")


def test_module_prefix_without_import(tmp_path):
    import subprocess
    import sys
    code = ("import gymnasium as gym; e = gym.make('craftsuite:CraftSuite/DungeonQuest-Grid7-v0'); "
            "print(e.reset(seed=0)[0].shape)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().startswith("(")


def test_layout_seed_fixes_the_instance_not_the_start():
    env = gym.make("CraftSuite/DiamondMine-Grid7-v0", layout_seed=3)
    layouts, starts = set(), set()
    for seed in range(6):
        env.reset(seed=seed)
        layouts.add(repr(env.unwrapped.object_positions()))
        starts.add(env.unwrapped.agent_position)
    assert len(layouts) == 1 and len(starts) > 1
    other = gym.make("CraftSuite/DiamondMine-Grid7-v0", layout_seed=4)
    other.reset(seed=0)
    assert repr(other.unwrapped.object_positions()) not in layouts
    with pytest.raises(ValueError, match="layout_seed"):
        gym.make("CraftSuite/DiamondMine-Grid7-v0", layout_seed=-1)


def test_moves_are_what_the_action_names_say():
    """One table of moves (``envs.cells.MOVES``) drives the world and the scripted policy."""
    from craftsuite.envs.cells import ACTION_NAMES, EMPTY, MOVES, WALL
    from craftsuite.scripted import _bfs_first_step

    assert set(MOVES) == set(range(len(ACTION_NAMES)))
    named = {"up": (0, -1), "right": (1, 0), "down": (0, 1), "left": (-1, 0)}  # y grows downwards
    env = craftsuite.make_grid("BlindCraftsman", 7)
    u = env.unwrapped
    for action, name in enumerate(ACTION_NAMES):
        env.reset(seed=0)
        u._cells = [EMPTY] * 49  # nothing to touch
        u._agent = 3 * 7 + 3
        env.step(action)
        dx, dy = named[name]
        assert MOVES[action] == named[name] and u.agent_position == (3 + dx, 3 + dy)
        # the scripted policy's search takes the same action towards that cell
        goal = (3 + dy) * 7 + (3 + dx)
        assert _bfs_first_step(7, [EMPTY] * 49, 3 * 7 + 3, {goal}, lambda k: k == WALL) == action
    env.reset(seed=0)
    u._cells = [EMPTY] * 49
    u._cells[3 * 7 + 4] = WALL
    u._agent = 3 * 7 + 3
    env.step(ACTION_NAMES.index("right"))
    assert u.agent_position == (3, 3)  # walls hold


def test_cell_codes_belong_to_the_world_and_drawing_imports_them(tmp_path):
    import subprocess
    import sys

    from craftsuite.envs import cells
    from craftsuite.rendering import grid as drawing

    assert (drawing.EMPTY, drawing.WALL) == (cells.EMPTY, cells.WALL)  # older imports keep working
    assert cells.EMPTY < 0 and cells.WALL < 0 and cells.EMPTY != cells.WALL  # never an object kind
    # either side may be imported first in a fresh interpreter
    for first in ("craftsuite.rendering.grid", "craftsuite.envs.cells", "craftsuite.scripted"):
        out = subprocess.run([sys.executable, "-c", f"import {first}; import craftsuite.envs.grid"],
                             capture_output=True, text=True, cwd=tmp_path)
        assert out.returncode == 0, (first, out.stderr)


def test_grid_frame_is_the_grid_alone_unless_the_panel_is_asked_for():
    from craftsuite.envs.cells import WALL
    from craftsuite.rendering.grid import TILE

    plain = craftsuite.make_grid("BlindCraftsmanObstacles", 10, render_mode="rgb_array")
    shown = craftsuite.make_grid("BlindCraftsmanObstacles", 10, render_mode="rgb_array", status_panel=True)
    plain.reset(seed=1)
    shown.reset(seed=1)
    frame = plain.render()
    assert frame.shape == plain.frame_shape == (10 * TILE, 10 * TILE, 3)
    assert shown.render().shape == (10 * TILE + 40, 10 * TILE, 3)
    wall = plain._cells.index(WALL)
    y, x = divmod(wall, 10)
    tile = frame[y * TILE + 4:(y + 1) * TILE - 4, x * TILE + 4:(x + 1) * TILE - 4]
    assert (tile == tile[0, 0]).all() and tile[0, 0].tolist() == [60, 90, 150]  # a wall drawn as one
