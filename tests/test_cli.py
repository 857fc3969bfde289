"""The craftsuite command line."""

from __future__ import annotations

import shutil

import pytest

from craftsuite.cli import main


def test_tasks_lists_ids(capsys):
    assert main(["tasks"]) == 0
    out = capsys.readouterr().out
    assert "CraftSuite/DiamondMine-Grid10-v0" in out
    assert "15 states, 29 transitions" in out


def test_automaton_describe_and_draw(tmp_path, capsys):
    suffix = ".png" if shutil.which("dot") else ".dot"
    assert main(["automaton", "DungeonQuest", "--describe", "--out", str(tmp_path / f"a{suffix}")]) == 0
    assert "rejecting sink" in capsys.readouterr().out
    assert (tmp_path / f"a{suffix}").stat().st_size > 0


def test_unknown_task_is_a_clear_error(capsys):
    assert main(["automaton", "Nope"]) == 2
    err = capsys.readouterr().err
    assert "unknown task 'Nope'" in err and "Traceback" not in err


def test_demo_writes_pictures(tmp_path, capsys):
    assert main(["demo", "--task", "DungeonQuest", "--episodes", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| CraftSuite/DungeonQuest-Grid7-v0 | 2/2 |" in out
    assert (tmp_path / "DungeonQuest-Grid10-v0.png").read_bytes().startswith(b"\x89PNG")


def test_help_explains_commands(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    for command in ("tasks", "automaton", "demo"):
        assert command in out


def test_video_loads_craftsuite_agents(tmp_path, capsys):
    from craftsuite.agents.methods import make_agent

    agent = make_agent("product-dqn", "CraftSuite/DungeonQuest-Grid7-v0", learning_starts=10, buffer_size=500)
    agent.learn(50)
    agent.save(tmp_path / "teacher.zip")
    out = tmp_path / "v.mp4"
    assert main(["video", "CraftSuite/DungeonQuest-Grid7-v0", "--product", "--policy",
                 str(tmp_path / "teacher.zip"), "--out", str(out)]) == 0
    assert out.stat().st_size > 0
    assert main(["video", "CraftSuite/DungeonQuest-Grid7-v0", "--policy",
                 str(tmp_path / "teacher.zip"), "--out", str(out)]) == 2  # product=True missing
    assert "product=True missing" in capsys.readouterr().err


def test_zero_episodes_is_a_clear_error(capsys):
    with pytest.raises(SystemExit):
        main(["demo", "--episodes", "0"])
    assert "must be at least 1" in capsys.readouterr().err
