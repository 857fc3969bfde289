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
