"""The task ladder: rungs as tagged specs, selected by tag, registered in every world, each
completed by the scripted planner; the tasks page generated from them."""

from __future__ import annotations

import re
from pathlib import Path

import gymnasium as gym
import pytest

import craftsuite
from craftsuite.cli import main
from craftsuite.ids import parse_id
from craftsuite.references import reference, tasks_page
from craftsuite.spec import LEVELS, builtin_specs
from craftsuite.task_registry import ladder

BUILTIN = builtin_specs()
BUILTIN_IDS = [i for i in craftsuite.registered_ids() if parse_id(i)[0] in BUILTIN]


def test_the_ladder_climbs_from_reach_to_the_paper_tasks():
    names = [s.name for s in ladder()]
    assert names[:3] == ["Reach", "FirstWood", "FirstTool"]
    assert set(names[3:6]) == {"KeySwordDragon", "ToolHome", "TwoToolsHome"}  # the middle rungs, level medium
    assert {s.name for s in ladder("middle")} == set(names[3:6])
    assert set(names[6:]) == {"BlindCraftsman", "BlindCraftsmanObstacles", "DungeonQuest", "DiamondMine", "GoldMine"}
    levels = [LEVELS.index(s.level) for s in ladder()]
    assert levels == sorted(levels)  # easiest first
    assert "calibration" in BUILTIN["Reach"].tags
    assert {s.name for s in ladder("paper")} == set(names[6:])
    assert [s.name for s in ladder("easy", "medium")] == names[:6]


def test_every_rung_has_a_level_and_the_second_stage_is_in_its_automaton():
    assert all(spec.level in LEVELS for spec in BUILTIN.values())
    # FirstTool's automaton has a middle state (a wood held) before acceptance, so a
    # teacher's values on its edges can tell the student about the second stage
    a = BUILTIN["FirstTool"].automaton
    wood, factory = a.mask(["wood"]), a.mask(["factory"])
    assert a.step(a.initial, factory) == a.initial  # the factory first does nothing
    holding = a.step(a.initial, wood)
    assert holding != a.initial and not a.accepting[holding]
    assert a.accepting[a.step(holding, factory)] and a.size()[0] == 3


def test_an_unknown_tag_is_named_with_the_tags_in_use(capsys):
    with pytest.raises(KeyError, match=r"^unknown tag 'eassy' \(did you mean easy\?\); tags: "
                                       r"calibration, easy, hard, medium, middle, paper \(the tags"):
        ladder("easy", "eassy")
    assert main(["tasks", "--tag", "eassy"]) == 2
    assert "tags: calibration, easy" in capsys.readouterr().err


def test_cli_lists_the_rungs_of_a_tag(capsys, tmp_path):
    assert main(["tasks", "--tag", "easy"]) == 0
    out = capsys.readouterr().out
    assert "Reach [calibration, easy]: F wood" in out and "FirstWood [easy]" in out
    assert "FirstTool" not in out and "BlindCraftsman" not in out
    assert "CraftSuite/Reach-Grid7-v0" in out and "CraftSuite/Reach-Cont-v0" in out
    # the page lists every rung: a --tag beside it is refused, not ignored
    assert main(["tasks", "--tag", "easy", "--markdown", str(tmp_path / "tasks.md")]) == 2
    assert "use one or the other" in capsys.readouterr().err and not (tmp_path / "tasks.md").exists()


@pytest.mark.parametrize("name", sorted(BUILTIN))
def test_every_rung_is_registered_in_every_world(name):
    ids = {parse_id(i)[1] for i in craftsuite.registered_ids() if parse_id(i)[0] == name}
    assert ids == {"Grid7", "Grid10", "Cont", "Kinematic"}


@pytest.mark.parametrize("env_id", BUILTIN_IDS)
def test_the_scripted_planner_completes_every_rung_in_every_world(env_id):
    spec = BUILTIN[parse_id(env_id)[0]]
    ref = reference(env_id, "scripted", episodes=3)
    assert ref.success == 1.0, (f"{spec.path}: formula: the scripted planner completes {ref.success:.0%} of 3 "
                                f"episodes of {env_id}: the rung cannot be played as specified")
    assert ref.steps < gym.spec(env_id).max_episode_steps / 2  # room to spare for a learner


def test_random_reference_is_deterministic_and_below_the_scripted_one():
    a = reference("CraftSuite/FirstTool-Cont-v0", "random", episodes=10)
    b = reference("CraftSuite/FirstTool-Cont-v0", "random", episodes=10)
    assert a == b
    assert a.success < 1.0 and 0.0 <= a.automaton_steps < 2.0
    with pytest.raises(ValueError, match="policy must be one of"):
        reference("CraftSuite/Reach-Grid7-v0", "greedy", episodes=1)


def test_tasks_page_is_generated_from_the_specs_and_lists_every_rung():
    page = tasks_page(episodes=1, progress=False)
    for spec in BUILTIN.values():
        assert f"## {spec.name}" in page and f"`CraftSuite/{spec.name}-Cont-v0`" in page
    assert page.index("## Reach") < page.index("## FirstTool") < page.index("## BlindCraftsman")


def test_the_committed_tasks_page_lists_every_builtin_rung():
    """docs/tasks.md is generated (craftsuite tasks --markdown docs/tasks.md): a rung added
    without regenerating it fails here."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "tasks.md").read_text()
    for spec in BUILTIN.values():
        assert f"## {spec.name}" in page, (f"docs/tasks.md lacks {spec.name}: "
                                           "run craftsuite tasks --markdown docs/tasks.md")
        for world in ("Grid7", "Grid10", "Cont", "Kinematic"):
            assert f"`CraftSuite/{spec.name}-{world}-v0`" in page
    # every id row's episode limit is the registered one (a changed limit or a stale id fails)
    rows = dict(re.findall(r"^\| `(CraftSuite/[\w-]+)` \| (\d+) \|", page, flags=re.M))
    assert set(rows) == {f"CraftSuite/{n}-{w}-v0" for n in BUILTIN for w in ("Grid7", "Grid10", "Cont", "Kinematic")}
    assert {i: int(limit) for i, limit in rows.items()} == {i: gym.spec(i).max_episode_steps for i in rows}
