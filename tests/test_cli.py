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


def test_scripted_writes_pictures(tmp_path, capsys):
    assert main(["scripted", "--task", "DungeonQuest", "--episodes", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "| CraftSuite/DungeonQuest-Grid7-v0 | 2/2 |" in out
    assert (tmp_path / "DungeonQuest-Grid10-v0.png").read_bytes().startswith(b"\x89PNG")
    drawn = {p.name for p in tmp_path.glob("*-automaton.*")}
    assert drawn and all(name.startswith("DungeonQuest-") for name in drawn)  # --task draws its automaton only
    import cv2

    from craftsuite.rendering import PANEL_HEIGHT
    picture = cv2.imread(str(tmp_path / "DungeonQuest-Grid10-v0.png"))
    assert picture.shape[0] == 32 * 10 + PANEL_HEIGHT  # start and end pictures show the status panel


def test_help_explains_commands(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")  # argparse wraps to the terminal's width
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    for command in ("tasks", "automaton", "scripted"):
        assert command in out
    assert "``" not in out  # plain text, not the docstring's markup
    with pytest.raises(SystemExit):  # a command's own help says what it does, as the list does
        main(["teacher", "--help"])
    assert "\nTrain a grid DQN teacher until 90% greedy success; distil it.\n" in capsys.readouterr().out


def test_video_loads_craftsuite_agents(tmp_path):
    from craftsuite.agents.factory import make_agent

    agent = make_agent("product-dqn", "CraftSuite/DungeonQuest-Grid7-v0", learning_starts=10, buffer_size=500)
    agent.save(tmp_path / "teacher.zip")
    out = tmp_path / "v.mp4"
    assert main(["video", "CraftSuite/DungeonQuest-Grid7-v0", "--product", "--policy",
                 str(tmp_path / "teacher.zip"), "--out", str(out)]) == 0
    assert out.stat().st_size > 0
    out.unlink()
    assert main(["video", "CraftSuite/DungeonQuest-Grid7-v0", "--policy",
                 str(tmp_path / "teacher.zip"), "--out", str(out)]) == 0  # without --product: as it was trained
    assert out.stat().st_size > 0


def test_an_output_path_that_cannot_be_written_is_one_line(tmp_path, capsys):
    (tmp_path / "file").write_text("")
    assert main(["video", "CraftSuite/Reach-Grid7-v0", "--out", str(tmp_path / "file" / "x.mp4")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("craftsuite video: error:") and "Traceback" not in err and len(err.splitlines()) == 1
    # (before any episode was rolled out: no progress bar came first)


def test_zero_episodes_is_a_clear_error(capsys):
    with pytest.raises(SystemExit):
        main(["scripted", "--episodes", "0"])
    assert "must be at least 1" in capsys.readouterr().err


@pytest.fixture
def spec_file(treasure_spec):
    """A user spec file the CLI has not seen; forgotten after the test."""
    return treasure_spec("CliTreasure", size=5, max_steps=30)


def test_version(capsys):
    import craftsuite

    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0 and capsys.readouterr().out.strip() == f"craftsuite {craftsuite.__version__}"


def _helps():
    from craftsuite.cli import build_parser

    parser = build_parser()
    [sub] = [a for a in parser._actions if a.choices and "student" in a.choices]
    return parser, sub.choices


def test_help_shows_every_default():
    _, commands = _helps()
    for name, command in commands.items():
        formatter = command._get_formatter()
        for action in command._actions:
            # a default of 0 is one to show (0 == False: compared by identity)
            if action.option_strings and not (action.default is None or action.default is False
                                              or action.default in ((), "==SUPPRESS==")):
                assert "default" in formatter._expand_help(action), (name, action.option_strings)
    text = " ".join(commands["student"].format_help().split())
    assert "--seed SEED (default: 0)" in text and "--eval-every EVAL_EVERY (default: 2000)" in text


def test_help_lists_the_choices_of_the_registries():
    from craftsuite import ids, task_registry
    from craftsuite.methods import METHODS
    from craftsuite.suites import SUITES

    _, commands = _helps()
    helps = {name: " ".join(command.format_help().split()) for name, command in commands.items()}
    for name in ("automaton", "teacher", "student"):
        assert all(task in helps[name] for task in task_registry.tasks()), name
        assert ".toml" in helps[name]
    assert all(method in helps["student"] for method in METHODS)
    assert all(f"{suite}:" in helps["transfer"] for suite in SUITES)
    sizes = {n for spec in task_registry.tasks().values() for n in spec.grid.sizes}
    for world in [*ids.CONT_WORLDS] + [ids.grid_world(n) for n in sizes]:
        assert world in helps["student"] and world in helps["transfer"]


def test_debug_shows_the_traceback(capsys):
    assert main(["automaton", "Nope"]) == 2  # without --debug: the error alone, on one line
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith("craftsuite automaton: error: unknown task 'Nope'; tasks: BlindCraftsman, ")
    for argv in (["--debug", "automaton", "Nope"], ["automaton", "Nope", "--debug"]):
        with pytest.raises(KeyError, match="unknown task 'Nope'"):
            main(argv)


@pytest.mark.parametrize("command", [["student", "Nope"], ["teacher", "Nope"], ["scripted", "--task", "Nope"],
                                     ["student", "Reach", "--world", "Grid5"], ["teacher", "Reach", "--size", "5"]])
def test_a_bad_task_or_world_is_named_and_nothing_is_written(tmp_path, capsys, command):
    out = tmp_path / "runs"
    assert main([*command, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "doesn't exist" not in err
    assert ("unknown task 'Nope'; tasks: " in err and " Reach, " in err) or \
        "task 'Reach' has no Grid5 world; its worlds: Cont, Grid10, Grid7, Kinematic" in err
    assert not out.exists()


def test_a_missing_or_bad_spec_file_is_named_and_nothing_is_written(tmp_path, capsys):
    out = tmp_path / "runs"
    assert main(["teacher", str(tmp_path / "missing.toml"), "--out", str(out)]) == 2
    assert "missing.toml: no such task spec file" in capsys.readouterr().err
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "Bad"\nformula = "F(x)"\n[propositions]\nx = { obtained = "gold" }\n'
                   '[items.coin]\ncount = 1\n')
    assert main(["student", str(bad), "--out", str(out)]) == 2
    assert "bad.toml: propositions.x.obtained: unknown inventory name 'gold'" in capsys.readouterr().err
    assert not out.exists() and not list(tmp_path.glob("teacher-*"))


def test_a_spec_file_stands_for_its_task(spec_file, capsys):
    assert main(["automaton", str(spec_file), "--describe"]) == 0
    assert "coin" in capsys.readouterr().out
    assert main(["tasks"]) == 0
    assert "CraftSuite/CliTreasure-Grid5-v0" in capsys.readouterr().out


def test_teacher_and_student_train_on_a_spec_file(spec_file, tmp_path, capsys):
    import json

    runs = tmp_path / "runs"
    tiny = ["--eval-every", "100", "--eval-episodes", "1", "--hyper", '{"learning_starts": 50, "buffer_size": 500}']
    assert main(["teacher", str(spec_file), "--size", "5", "--max-steps", "100", "--out", str(runs), *tiny]) == 0
    assert main(["student", str(spec_file), "--method", "dqn", "--world", "Grid5", "--steps", "100",
                 "--out", str(runs), *tiny]) == 0
    made = sorted(p.name for p in runs.iterdir())
    assert [n.rsplit("-", 1)[0] for n in made] == ["student-CliTreasure-Grid5-dqn-s0", "teacher-CliTreasure-Grid5-s0"]
    for run in runs.iterdir():
        assert json.loads((run / "result.json").read_text())["env_id"] == "CraftSuite/CliTreasure-Grid5-v0"


def test_video_takes_a_task_or_a_spec_file_in_a_world(spec_file, tmp_path, capsys):
    out = tmp_path / "v.mp4"
    assert main(["video", str(spec_file), "--world", "Grid5", "--out", str(out)]) == 0
    assert f"wrote {out}" in capsys.readouterr().out and out.stat().st_size > 0
    assert main(["video", "Reach", "--world", "Grid5", "--out", str(tmp_path / "w.mp4")]) == 2
    assert "task 'Reach' has no Grid5 world" in capsys.readouterr().err
    assert main(["video", "CraftSuite/Reach-Grid7-v0", "--world", "Grid7", "--out", str(tmp_path / "w.mp4")]) == 2
    assert "--world picks the world of a task" in capsys.readouterr().err
    assert not (tmp_path / "w.mp4").exists()


def test_where_a_video_goes_is_checked_as_every_command_checks_a_file(tmp_path, capsys):
    (tmp_path / "afile").write_text("kept\n")
    for out, message in ((tmp_path / "afile" / "v.mp4", f"--out {tmp_path / 'afile' / 'v.mp4'}: {tmp_path / 'afile'} "
                          "is a file, not a directory; give a path whose every folder is a directory"),
                         (tmp_path, f"--out {tmp_path} is a directory, not a file: give the file to write, e.g. "
                          f"{tmp_path / 'rollout.mp4'}"),
                         (tmp_path / "v.avi", f"--out {tmp_path / 'v.avi'}: a video is written as MP4; give a file "
                          f"name ending in .mp4, e.g. {tmp_path / 'v.mp4'}")):
        assert main(["video", "Reach", "--out", str(out)]) == 2
        assert capsys.readouterr().err == f"craftsuite video: error: {message}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile"] and (tmp_path / "afile").read_text() == "kept\n"


def test_an_id_given_as_a_task_is_named_as_an_id(tmp_path, capsys):
    out = tmp_path / "runs"
    assert main(["student", "CraftSuite/BlindCraftsman-Cont-v0", "--out", str(out)]) == 2
    assert "CraftSuite/BlindCraftsman-Cont-v0 is an id; give its task (BlindCraftsman) and the world with --world" \
        in capsys.readouterr().err
    assert main(["video", "CraftSuite/BlindCraftsman-Cont-v1", "--out", str(tmp_path / "v.mp4")]) == 2
    assert "is not a CraftSuite id (CraftSuite/<Task>-<World>-v0" in capsys.readouterr().err
    assert not out.exists() and not (tmp_path / "v.mp4").exists()


def test_env_keywords_the_run_sets_itself_are_refused_by_name(tmp_path, capsys):
    out = tmp_path / "runs"
    grid = ["student", "Reach", "--world", "Grid7", "--method", "dqn", "--out", str(out)]
    assert main([*grid, "--env", '{"size": 10}']) == 2
    assert "--env: size: the world (Grid7, Grid10) fixes the grid's size; leave it out of --env" \
        in capsys.readouterr().err
    assert main([*grid, "--env", '{"sze": 10}']) == 2
    err = capsys.readouterr().err
    assert "unknown keyword 'sze' for the grid world; it accepts " in err and "size" not in err.split(";")[1]
    assert "render_mode" not in err  # (the command's: below)
    assert main([*grid, "--env", '{"render_mode": "rgb_array"}']) == 2
    assert "--env: render_mode: the command sets it" in capsys.readouterr().err
    assert main(["student", "Reach", "--env", '{"product": true}', "--out", str(out)]) == 2
    assert "--env: product: whether the automaton state is observed" in capsys.readouterr().err
    assert not out.exists()


def test_distill_reads_an_sb3_teacher_run_as_distilling_its_saved_replay(tmp_path, capsys):
    """A teacher run as the SB3 trainer left one (its config.json, and its model and replay
    in ``checkpoint/``), built from the saved teacher ``tests/agents/saved/product-dqn``: the
    command finds the world in the config and the replay in the checkpoint."""
    import numpy as np
    from stable_baselines3.common.env_util import make_vec_env

    from craftsuite.agents.distillation import AutomatonQTable
    from craftsuite.agents.factory import distill_from_replay, load_agent
    from craftsuite.configs import TeacherConfig
    from craftsuite.runs import RunDir
    from craftsuite.task_registry import resolve_task

    from .agents.saved import make

    _, env_id, env_kwargs, settings, _ = make.CASES["product-dqn"]
    config = TeacherConfig(task="FirstTool", layout_seed=env_kwargs["layout_seed"],
                           hyperparameters={**make.SMALL, **settings}, engine="sb3")
    assert (config.env_id, config.env_kwargs) == (env_id, env_kwargs)  # the world the teacher was saved in
    run = tmp_path / "teachers" / config.run_name()
    with RunDir(run, config):  # its config.json
        pass
    (run / "checkpoint").mkdir()
    shutil.copyfile(make.HERE / "product-dqn.zip", run / "checkpoint" / "model.zip")
    shutil.copyfile(make.HERE / "product-dqn-replay.pkl", run / "checkpoint" / "replay.pkl")
    assert main(["distill", str(run), "--out", str(tmp_path / "table.npz")]) == 0  # (the default --task is another)
    assert "dynamic automaton Q-table for" in capsys.readouterr().out
    table = AutomatonQTable.load(tmp_path / "table.npz", resolve_task("FirstTool").automaton)
    teacher = load_agent(make.HERE / "product-dqn.zip",
                         env=make_vec_env(env_id, n_envs=1, env_kwargs={"product": True, **env_kwargs}))
    teacher.load_replay_buffer(make.HERE / "product-dqn-replay.pkl")
    direct = distill_from_replay(teacher)
    assert table.kind == "dynamic" and table.counts.sum() == 60  # the 60 transitions the teacher collected
    np.testing.assert_array_equal(table.counts, direct.counts)
    assert np.isfinite(table.q[table.seen]).all()
    np.testing.assert_allclose(table.q[table.seen], direct.q[direct.seen])


def test_transfer_hands_members_to_the_populations(tmp_path, monkeypatch):
    """``--members N`` reaches the students' jobs (a cell's seeds split into populations of N)."""
    import craftsuite.suite_runner as runner

    seen = {}

    class Stop(Exception):
        pass

    def fake_run_students(configs, root, **kwargs):
        seen.update(kwargs, jobs=[len(job) for job in runner.cells(configs, kwargs["members"])])
        kwargs["pool"].close()
        raise Stop

    monkeypatch.setattr(runner, "run_students", fake_run_students)
    with pytest.raises(Stop):
        main(["transfer", "--suite", "quick", "--tasks", "Reach", "--methods", "td3", "--seeds", "3",
              "--members", "2", "--workers", "1", "--no-archive", "--no-video", "--out", str(tmp_path / "out")])
    assert seen["members"] == 2 and seen["jobs"] == [2, 1]


@pytest.mark.parametrize("success", [0.68, 0.95])
def test_teacher_says_whether_it_reached_its_target(tmp_path, capsys, monkeypatch, success):
    """The teacher command says on its own line whether the teacher reached its target (it
    said so only inside the JSON), and what to do where it did not: as a suite says it."""
    import json

    import craftsuite.training as training

    def trained(config, out, device="cpu"):
        run = tmp_path / "teacher-Reach-Grid7-s0"
        run.mkdir()
        (run / "result.json").write_text(json.dumps({"kind": "teacher", "steps": 2000, "success": success,
                                                     "reached_target": success >= config.target_success}))
        return run

    monkeypatch.setattr(training, "train_teacher", trained)
    assert main(["teacher", "Reach", "--max-steps", "2000", "--out", str(tmp_path)]) == 0
    lines = capsys.readouterr().out.splitlines()
    reached = "reached" if success >= 0.9 else "did NOT reach"
    assert lines[1] == f"teacher run: {tmp_path / 'teacher-Reach-Grid7-s0'}: 2,000 steps, greedy success " \
                       f"{success:.2f} ({reached} 90%)"
    hint = "  its table distils what it learned so far; for a teacher at its target give it more than --max-steps 2,000"
    assert (hint in lines) == (success < 0.9)
