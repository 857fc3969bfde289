"""Task specs: the built-in ones load; bad ones fail at load time naming file, field, problem."""

from __future__ import annotations

import re
import textwrap

import gymnasium as gym
import pytest

import craftsuite
from craftsuite.spec import SpecError, builtin_specs, load_spec

GOOD = """
name = "Treasure"
formula = "F(coin) & G(!trap)"

[propositions]
coin = { obtained = "coin" }
trap = { arrived = "trap" }

[items.coin]
count = 2

[places.trap]
count = 1

[grid]
sizes = [5]
max_steps = 50
"""


def write(tmp_path, text, name="treasure.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_builtin_specs():
    specs = builtin_specs()
    assert set(specs) == {"Reach", "FirstWood", "FirstTool", "KeySwordDragon", "ToolHome", "TwoToolsHome",
                          "BlindCraftsman", "BlindCraftsmanObstacles", "DungeonQuest", "DiamondMine", "GoldMine"}
    bc = specs["BlindCraftsman"]
    assert bc.proposition_names == ("wood", "factory", "tools3", "home")
    assert bc.inventory == ("wood", "tools")
    assert bc.items[0].capacity == 2
    dm = specs["DiamondMine"]
    assert len(dm.propositions) == 13
    assert {i.name: i.count for i in dm.items}["iron"] == 30
    assert {i.name: i.reward for i in dm.items}["iron"] == 0.0


def test_extends_merges_the_base_spec():
    specs = builtin_specs()
    obstacles, base = specs["BlindCraftsmanObstacles"], specs["BlindCraftsman"]
    assert obstacles.formula == base.formula and obstacles.items == base.items
    assert obstacles.grid.sizes == (7, 10)
    assert (3, 5) in obstacles.grid.obstacles
    assert obstacles.grid.max_steps == base.grid.max_steps


def test_a_variant_does_not_inherit_its_bases_tags(tmp_path):
    write(tmp_path, GOOD.replace('name = "Treasure"', 'name = "Treasure"\ntags = ["paper", "hard"]'), "base.toml")
    write(tmp_path, 'extends = "base"\nname = "TreasureVariant"', "variant.toml")
    assert load_spec(tmp_path / "base.toml").tags == ("paper", "hard")
    variant = load_spec(tmp_path / "variant.toml")
    assert variant.tags == () and variant.level is None  # off the ladder and out of the suites


def test_good_spec_loads(tmp_path):
    spec = load_spec(write(tmp_path, GOOD))
    assert spec.name == "Treasure" and spec.automaton.n_states >= 2


BAD = [
    # (edit to GOOD, field named, problem named)
    (('F(coin) & G(!trap)', 'F(coin) & G(!lava)'), "formula", "unknown proposition 'lava'; "
     "propositions: coin, trap (declared in [propositions])"),
    (('F(coin) & G(!trap)', 'F(coin & '), "formula", "expected"),
    (('coin = { obtained = "coin" }', 'coin = { obtained = "gem" }'), "propositions.coin.obtained",
     "unknown inventory name 'gem'"),
    (('trap = { arrived = "trap" }', 'trap = { arrived = "coin" }'), "propositions.trap.arrived",
     "unknown place 'coin'"),
    (('trap = { arrived = "trap" }', 'trap = { smells = "trap" }'), "propositions.trap", "unknown kind 'smells'"),
    (("count = 2", "count = -2"), "items.coin.count", "must be >= 0"),
    (("count = 2", "count = 30"), "grid.sizes", "do not fit a 5x5 grid"),
    (("count = 2", "count = 2\nrequires = { gem = 1 }"), "items.coin.requires", "unknown inventory name 'gem'"),
    (("count = 2", "count = 2\nwings = 3"), "items.coin", "unknown key 'wings'; keys: "),
    (('name = "Treasure"', 'name = "treasure hunt"'), "name", "CamelCase"),
    (("max_steps = 50", "max_steps = 50\nobstacles = [[9, 9]]"), "grid.obstacles", "outside the 5x5 grid"),
    (("[places.trap]", "[places.trap]\nplacement = \"middle\""), "places.trap.placement", "'random' or 'corner'"),
    (('name = "Treasure"', 'name = "Treasure"\ntags = "easy"'), "tags", "must be a list of lower-case identifiers"),
    (('name = "Treasure"', 'name = "Treasure"\ntags = ["Easy"]'), "tags", "must be a list of lower-case identifiers"),
    (('name = "Treasure"', 'name = "Treasure"\ntags = ["easy", "easy"]'), "tags", "lists a tag twice"),
    (("[grid]", "[continuous]\ncontrol_period = 0\n[grid]"), "continuous.control_period", "must be > 0 seconds"),
    (("[grid]", "[continuous]\ncontrol_period = -0.25\n[grid]"), "continuous.control_period", "must be > 0"),
    (("[grid]", "[continuous]\ncontrol_period = inf\n[grid]"), "continuous.control_period",
     "must be a finite number, got inf"),  # TOML reads inf: one step would never end
    (("[grid]", "[continuous]\narena = inf\n[grid]"), "continuous.arena", "must be a finite number, got inf"),
    (("[places.trap]", "[places.trap]\nkinematic = { reward = \"lots\" }"), "places.trap.kinematic.reward",
     "must be a finite number, got 'lots'"),
    (("[places.trap]", "[places.trap]\nkinematic = { label = \"near\" }"), "places.trap.kinematic.label",
     "must be 'acts' or 'cell'"),
    (("count = 2", "count = 2\nkinematic = { label = \"cell\" }"), "items.coin.kinematic.label",
     "only a place can be labelled by its cell"),
    (("[places.trap]", "[places.trap]\nkinematic = { ends = true }"), "places.trap.kinematic",
     "unknown key 'ends'; keys: consumable, ends_episode, label"),
    (("[places.trap]", "[places.trap]\nkinematic = { requires = { gem = 1 } }"), "places.trap.kinematic.requires",
     "unknown inventory name 'gem'"),
    (('trap = { arrived = "trap" }', 'trap = { exactly = { coin = 0 } }'), "propositions.trap.exactly.coin",
     "must be a positive integer"),
]


def test_exactly_is_a_level_and_kinematic_tables_round_trip():
    from craftsuite.labelling import Labeller

    spec = builtin_specs()["GoldMine"]
    labeller = Labeller(spec)
    inv = [0, 0, 2, 0]  # gold, motherlode, silver, copper
    assert labeller.names(labeller.levels(inv)) == ("s2",)  # true while holding exactly 2, not 1
    home = spec.places[0].kinematic
    assert home.requires == {"silver": 10} and home.ends_episode and home.label == "cell"
    assert load_spec(spec.to_data()).digest() == spec.digest()


@pytest.mark.parametrize("edit, field, problem", BAD, ids=[b[1] + ":" + b[2][:20] for b in BAD])
def test_bad_spec_names_file_field_and_problem(tmp_path, edit, field, problem):
    old, new = edit
    assert old in GOOD
    path = write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(SpecError) as err:
        load_spec(path)
    message = str(err.value)
    assert message.startswith(str(path)), message
    assert f": {field}:" in message, message
    assert problem in message, message


def test_recipe_that_feeds_itself_is_rejected(tmp_path):
    text = GOOD + """
[[recipes]]
at = "trap"
consume = { coin = 1 }
produce = { coin = 1, gem = 1 }
repeat = true
"""
    with pytest.raises(SpecError, match="recipes\\[0\\].repeat: .*never stop"):
        load_spec(write(tmp_path, text))


def test_bad_toml_and_missing_file(tmp_path):
    with pytest.raises(SpecError, match=re.escape("not valid TOML")):
        load_spec(write(tmp_path, "name = \n"))
    with pytest.raises(SpecError, match="no such task spec file"):
        load_spec(tmp_path / "nope.toml")


def test_extends_cycle(tmp_path):
    write(tmp_path, 'extends = "b"\nname = "A"', "a.toml")
    write(tmp_path, 'extends = "a"\nname = "B"', "b.toml")
    with pytest.raises(SpecError, match="cycle"):
        load_spec(tmp_path / "a.toml")


def test_user_spec_registers_and_runs(tmp_path):
    ids = craftsuite.register_task(write(tmp_path, GOOD))
    assert ids == ["CraftSuite/Treasure-Grid5-v0", "CraftSuite/Treasure-Cont-v0", "CraftSuite/Treasure-Kinematic-v0"]
    env = gym.make(ids[0], product=True)
    obs, info = env.reset(seed=1)
    assert obs.shape == env.observation_space.shape
    assert env.unwrapped.automaton.propositions == ("coin", "trap")
    assert env.spec.max_episode_steps == 50
    env.close()


def test_a_directory_or_an_empty_file_is_named_as_such(tmp_path):
    with pytest.raises(SpecError, match=re.escape(f"{tmp_path}: is a directory; give a task spec file in it")):
        load_spec(tmp_path)
    with pytest.raises(SpecError, match=re.escape(f"{tmp_path / 'empty.toml'}: is empty; a task spec needs")):
        load_spec(write(tmp_path, "\n", "empty.toml"))


def test_what_is_no_spec_file_nor_spec_data_is_named():
    with pytest.raises(SpecError, match=r"^a task spec is given as its file's path or its data \(a dict\), got "
                                        r"NoneType$"):
        craftsuite.register_task(None)
    with pytest.raises(SpecError, match=r"^a task spec is given as its file's path or its data, got TOML text: give "
                                        r"tomllib.loads\(text\)"):
        load_spec(textwrap.dedent(GOOD))  # pathlib said the file name was too long
    data = {"extends": "first_wood", "name": "Woods"}  # was ignored: the spec then lacked every object
    with pytest.raises(SpecError, match=r"^<dict>: extends: a spec given as data has no folder to find 'first_wood'"):
        load_spec(data)


def test_an_objective_that_can_never_be_satisfied_is_refused_when_added(tmp_path):
    from craftsuite import task_registry

    path = write(tmp_path, GOOD.replace('"F(coin) & G(!trap)"', '"F(coin) & G(!coin)"').replace("Treasure", "Never"))
    with pytest.raises(SpecError, match=re.escape(f"{path}: formula: 'F(coin) & G(!coin)' can never be satisfied")):
        craftsuite.register_task(path)
    assert "Never" not in task_registry.tasks() and not [i for i in gym.registry if "Never" in i]
    spec = load_spec(write(tmp_path, GOOD))  # a satisfiable one: the automaton reaches acceptance
    assert spec.automaton.satisfiable and spec.automaton.accepts([spec.automaton.mask({"coin"})])


def test_an_arena_too_small_for_the_objects_names_the_least_that_holds_them(tmp_path):
    small = GOOD + "\n[continuous]\narena = 1.0\npickup_radius = 0.5\n"
    path = write(tmp_path, small)
    with pytest.raises(SpecError) as err:
        load_spec(path)
    assert str(err.value) == (f"{path}: continuous.arena: 3 objects and the agent need 4 non-overlapping pickup "
                              "zones 1 wide (2 x pickup_radius), which an arena of 1 cannot hold; make arena at "
                              "least 3 (or pickup_radius at most 0.166)")
    load_spec(write(tmp_path, small.replace("arena = 1.0", "arena = 3")))  # either fix it names loads
    load_spec(write(tmp_path, small.replace("pickup_radius = 0.5", "pickup_radius = 0.166")))
