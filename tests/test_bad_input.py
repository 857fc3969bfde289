"""Bad input of training named before a run directory exists; bad input to ``craftsuite
transfer`` refused before it writes anything (damaged checkpoints on resume:
``tests/population/test_runs.py``)."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import pytest

from craftsuite.cli import main
from craftsuite.configs import StudentConfig, TeacherConfig
from craftsuite.hyperparameters import HyperparameterError
from craftsuite.training import train_student, train_teacher

THIS_FILE = Path(__file__)  # a file given where a teacher .zip goes: its flags are checked before it is read


@pytest.mark.parametrize("hyper,message", [({"batch_size": "big"}, "batch_size must be an integer"),
                                           ({"batch_sise": 32}, "has no setting 'batch_sise'")])
def test_bad_hyperparameters_fail_before_a_run_directory_exists(tmp_path, hyper, message):
    with pytest.raises(HyperparameterError, match=message):
        train_teacher(TeacherConfig(max_steps=100, hyperparameters=hyper), tmp_path, progress=False)
    with pytest.raises(HyperparameterError, match=message):
        train_student(StudentConfig(method="td3", steps=100, hyperparameters=hyper), tmp_path, progress=False)
    assert list(tmp_path.iterdir()) == []


def test_the_cli_names_hyper_and_the_valid_settings(tmp_path, capsys):
    out = tmp_path / "runs"
    assert main(["student", "BlindCraftsman", "--method", "dqn", "--world", "Grid7", "--hyper",
                 '{"batch_size": "big"}', "--out", str(out)]) == 2
    assert "--hyper: batch_size must be an integer (default 64), got 'big'" in capsys.readouterr().err
    assert main(["teacher", "BlindCraftsman", "--hyper", '{"learning_rat": 0.1}', "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "--hyper: DQN has no setting 'learning_rat'" in err and "learning_rate" in err
    assert main(["student", "BlindCraftsman", "--method", "td3", "--hyper", '{"double": false}',
                 "--out", str(out)]) == 2
    assert "--hyper: TD3 has no setting 'double'" in capsys.readouterr().err
    assert not out.exists()


def test_a_bad_table_fails_before_a_run_directory_exists(tmp_path, capsys):
    bad = tmp_path / "table.npz"
    bad.write_text("oops")
    out = tmp_path / "runs"
    assert main(["student", "BlindCraftsman", "--method", "td3-dynamic", "--table", str(bad),
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert f"{bad} is not a CraftSuite distilled table: not an .npz archive" in err and "allow_pickle" not in err
    assert not out.exists()


@pytest.mark.parametrize("command,message", [
    (["student", "BlindCraftsman", "--method", "td3", "--env", '{"frame_skp": 10}'],
     "--env: unknown keyword 'frame_skp' (did you mean frame_skip?) for the MuJoCo world; it accepts "
     "width, height, frame_skip, status_panel, max_episode_steps"),
    (["student", "BlindCraftsman", "--method", "dqn", "--world", "Grid7", "--env", '{"width": 480}'],
     "--env: width: the grid world draws every cell 32 pixels a side"),
    (["student", "BlindCraftsman", "--method", "dqn", "--world", "Grid7", "--hyper", '{"batch_size": -1}'],
     "--hyper: batch_size must be at least 1 (default 64), got -1"),
    (["teacher", "BlindCraftsman", "--hyper", '{"learning_rate": -1}'],
     "--hyper: learning_rate must be above 0 (default 0.0005), got -1"),
    (["transfer", "--dqn-hyper", '{"batch_size": -1}'], "--dqn-hyper: batch_size must be at least 1"),
    (["transfer", "--env", '{"layout_seed": 1}'], "--env: unknown keyword 'layout_seed' for the MuJoCo world"),
    # the engine's vector world does not render: refused at the flag, not once the archive has the session
    (["transfer", "--env", '{"render_mode": "rgb_array"}'], "--env: render_mode: the command sets it (runs train "
     "unrendered; craftsuite video renders its frames itself); leave it out of --env"),
    (["student", "FirstTool", "--method", "td3", "--env", '{"render_mode": "human"}'], "--env: render_mode: the "
     "command sets it"),
    # gymnasium's own keywords, checked with the world's (its messages name no flag)
    (["transfer", "--env", '{"max_episode_steps": 0}'], "--env: max_episode_steps must be a positive integer (the "
     "decisions before an episode is cut short), got 0"),
    (["student", "Reach", "--env", '{"disable_env_checker": "x"}'], "--env: disable_env_checker must be True or "
     "False (whether gymnasium skips its env checker), got 'x'"),
    # a method of the other kind of world: DQN's first in the list, the world Cont by default
    (["student", "FirstTool", "--method", "dqn"],
     "method 'dqn' runs in the Grid worlds, not in Cont; give a Grid world (e.g. Grid10), or one of Cont's methods: "
     "['td3', 'product-td3'"),
    (["student", "FirstTool", "--method", "td3", "--world", "Grid10"],
     "method 'td3' runs in the Cont worlds, not in Grid10; give a Cont world (Cont or Kinematic)"),
    # a table the method does not read would be recorded in its config, and change its run key
    (["student", "FirstTool", "--method", "td3", "--table", "/etc/hostname"],
     "method 'td3' distils no teacher's table: leave out --table (the methods that take one: dynamic, "),
    # a budget with no gradient update in it, as transfer refuses it
    (["student", "FirstTool", "--method", "td3", "--steps", "100"],
     "--steps 100: too small to train FirstTool's td3 student (Cont): no gradient update comes in the first 1,000 "
     "transitions (learning_starts); use --steps 1001 or more"),
    # the engine's device is --device; as a setting it was ignored, though recorded in the run key
    (["student", "FirstTool", "--method", "td3", "--hyper", '{"device": "cuda"}'],
     "method 'td3': the population engine, which trains CraftSuite's runs, does not support device among the "
     "settings: the device is the command's --device"),
    (["student", "FirstTool", "--method", "td3", "--hyper", '{"policy_kwargs": {"net_arch": "big"}}'],
     "method 'td3': the population engine, which trains CraftSuite's runs, does not support net_arch 'big' (it "
     "takes the hidden layers' widths"),
    (["student", "CraftSuite/FirstTool-Cont-v0"],
     "CraftSuite/FirstTool-Cont-v0 is an id; give its task (FirstTool) and the world with --world"),
    (["scripted", "--task", "CraftSuite/Reach-Cont-v0"], "CraftSuite/Reach-Cont-v0 is an id; give its task (Reach)\n"),
    (["distill", "FirstTool"], "FirstTool is a task: distil its automaton alone with --static"),
    (["student", "FirstTool", "--method", "td3", "--device", "tpu"],
     "--device 'tpu' is not a torch device: use cpu or cuda"),
    (["teacher", "CraftSuite/FirstTool-Grid7-v0"], "CraftSuite/FirstTool-Grid7-v0 is an id; give its task "
     "(FirstTool) and the grid's side with --size (e.g. --size 10)"),
    (["distill", "no-such-teacher"], "no teacher at no-such-teacher: give a teacher run directory or its .zip "
                                     "(dynamic), or a task name with --static"),
    # a file that is no teacher was asked for a replay buffer (--replay), as if it were one
    (["distill", str(THIS_FILE)], f"{THIS_FILE} is not a teacher: give a teacher run directory or its model .zip "
                                  "(dynamic), or a task name with --static"),
    # a teacher .zip's flags where SOURCE answers them were ignored
    (["distill", "FirstTool", "--static", "--task", "DungeonQuest"],
     "--task: with --static the task is SOURCE (FirstTool) and no teacher is read; leave it out"),
    (["distill", str(THIS_FILE), "--task", "DungeonQuest", "--env-id",
      "CraftSuite/FirstTool-Grid7-v0"], "--task DungeonQuest --env-id CraftSuite/FirstTool-Grid7-v0: the env id "
     "names the teacher's task too; give one of them"),
])
def test_a_refused_command_names_its_flag_and_leaves_no_output_folder(tmp_path, capsys, command, message):
    out = tmp_path / "new" / "runs"
    assert main([*command, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"craftsuite {command[0]}: error: {message}") and err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_distill_refuses_the_flags_a_teacher_run_directory_answers(tmp_path, capsys):
    teacher = tmp_path / "teacher-FirstTool-Grid7-s0"
    teacher.mkdir()
    (teacher / "config.json").write_text("{}")
    assert main(["distill", str(teacher), "--task", "DungeonQuest", "--replay", "replay.pkl",
                 "--out", str(tmp_path / "table.npz")]) == 2
    err = capsys.readouterr().err
    assert err == (f"craftsuite distill: error: --task, --replay: {teacher} is a teacher run directory: its config "
                   "names the task and env, its checkpoint the replay; leave them out\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [teacher.name]
    # its directory with --static (a task's automaton alone), its table where the teacher goes
    assert main(["distill", str(teacher), "--static", "--out", str(tmp_path / "table.npz")]) == 2
    assert capsys.readouterr().err == (f"craftsuite distill: error: {teacher} is a run directory: --static distils a "
                                       "task's automaton alone; give the task's name, or leave out --static to "
                                       "distil this teacher's values\n")
    (teacher / "table.npz").write_bytes(b"PK\x05\x06" + bytes(18))  # (an empty zip: what an .npz is)
    assert main(["distill", str(teacher / "table.npz"), "--out", str(tmp_path / "table.npz")]) == 2
    assert capsys.readouterr().err == (f"craftsuite distill: error: {teacher / 'table.npz'} is a distilled table "
                                       "already: give it to a student (--table), or give its teacher's run directory "
                                       "to distil it again\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [teacher.name]


def test_where_a_command_writes_is_checked_before_it_computes(tmp_path, capsys):
    """A file where a directory goes, a directory where a file goes, a drawing in a format
    there is none of: refused in one line before the command computes or writes anything
    (distill wrote its table first; tasks rolled out every id for minutes)."""
    file, folder = tmp_path / "file", tmp_path / "folder"
    file.write_text("kept\n")
    folder.mkdir()
    table = tmp_path / "table.npz"
    refused = {
        ("student", "FirstTool", "--method", "td3", "--out", str(file)): f"--out {file} is a file, not a directory",
        ("teacher", "FirstTool", "--out", str(file)): f"--out {file} is a file, not a directory",
        ("scripted", "--task", "Reach", "--out", str(file)): f"--out {file} is a file, not a directory",
        ("distill", "FirstTool", "--static", "--out", str(folder)):
            f"--out {folder} is a directory, not a file: give the file to write, e.g. {folder / 'table.npz'}",
        ("distill", "FirstTool", "--static", "--out", str(table), "--draw", str(tmp_path / "v.jpg")):
            f"cannot draw to '{tmp_path / 'v.jpg'}': use a .png, .svg, .pdf or .dot file",
        ("tasks", "--markdown", str(folder)): f"--markdown {folder} is a directory, not a file",
        ("automaton", "FirstTool", "--out", "."): "--out . is a directory, not a file: give the file to write, e.g. "
                                                  "FirstTool.png",
        ("automaton", "FirstTool"): "give --out FILE to draw the automaton, --describe to print its states and edges",
    }
    for command, message in refused.items():
        assert main(list(command)) == 2, command
        err = capsys.readouterr().err
        assert err.startswith(f"craftsuite {command[0]}: error: {message}") and err.count("\n") == 1, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file", "folder"] and not any(folder.iterdir())
    assert file.read_text() == "kept\n"


@pytest.mark.parametrize("command, flag", [
    (["automaton", "FirstTool", "--out", ""], "--out"), (["student", "FirstTool", "--out", " "], "--out"),
    (["archive", "runs", "--archive", ""], "--archive"), (["transfer", "--out", ""], "--out"),
    (["leaderboard", "runs", "--page", ""], "--page"), (["leaderboard", ""], "runs"),
    (["records", "--markdown", ""], "--markdown"),
    (["distill", "FirstTool", "--static", "--out", "t.npz", "--draw", ""], "--draw"),
])
def test_an_empty_path_is_refused_by_its_flag(tmp_path, capsys, monkeypatch, command, flag):
    """An empty path is the working directory to Python: never what ``--out ''`` (or an unset
    variable) meant; some commands read it as not given, others wrote where they ran."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as refused:
        main(command)
    assert refused.value.code == 2
    assert capsys.readouterr().err.endswith(f"error: argument {flag}: is empty: give a path\n")
    assert list(tmp_path.iterdir()) == []


def test_an_empty_distill_source_names_both_kinds_of_source(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit):
        main(["distill", "", "--static", "--out", "t.npz"])
    assert capsys.readouterr().err.endswith("error: argument source: is empty: give a teacher run directory or its "
                                            ".zip, or with --static a task name\n")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("where", [{"out": ""}, {"out": "out", "archive": " "}])
def test_an_empty_path_from_python_is_refused_before_anything_is_written(tmp_path, monkeypatch, where):
    """The rule behind the flags holds for a Python caller, whom no parser stands before."""
    import craftsuite
    import craftsuite.suite_runner as suite_runner
    from craftsuite.suites import SUITES

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(suite_runner, "WorkerPool", lambda *a: pytest.fail("transfer went on to train"))
    name = next(k for k, v in where.items() if not v.strip())
    with pytest.raises(ValueError, match=f"^--{name} is empty: give a path$"):
        suite_runner.transfer(dataclasses.replace(SUITES["quick"], tasks=("Reach",), seeds=1), **where)
    with pytest.raises(ValueError, match="^out is empty: give a path$"):
        craftsuite.Recorder("CraftSuite/Reach-Grid10-v0", "", method="mine")
    assert list(tmp_path.iterdir()) == []


def test_a_directory_given_for_a_file_names_the_file_in_it(tmp_path, capsys):
    """A teacher's run directory where its table goes, a run directory where a checkpoint
    goes: the message names the file to give."""
    teacher = tmp_path / "teacher-FirstTool-Grid7-s0"
    teacher.mkdir()
    (teacher / "table.npz").write_bytes(b"")
    assert main(["student", "FirstTool", "--method", "td3-dynamic", "--table", str(teacher),
                 "--out", str(tmp_path / "runs")]) == 2
    assert (f"{teacher} is a directory, not a distilled table: give the distilled table file, e.g. "
            f"{teacher / 'table.npz'} (it is there)") in capsys.readouterr().err
    assert main(["video", "FirstTool", "--policy", str(teacher), "--out", str(tmp_path / "v.mp4")]) == 2
    assert f"{teacher} is a directory, not a checkpoint: give the checkpoint file, e.g. {teacher / 'model.zip'}\n" in (
        capsys.readouterr().err)
    (teacher / "teacher.zip").write_bytes(b"")  # a teacher's run directory: its checkpoint is named
    assert main(["video", "FirstTool", "--policy", str(teacher), "--out", str(tmp_path / "v.mp4")]) == 2
    assert f"give the checkpoint file, e.g. {teacher / 'teacher.zip'} (it is there)\n" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == [teacher.name]


def test_a_word_where_a_number_goes_is_named_as_a_number(capsys):
    """argparse names the type by its function: the message says integer or number."""
    for command, text in ((["transfer", "--seeds", "two"], "argument --seeds: invalid integer value: 'two'"),
                          (["teacher", "Reach", "--target-success", "high"],
                           "argument --target-success: invalid number value: 'high'")):
        with pytest.raises(SystemExit):
            main(command)
        assert text in capsys.readouterr().err


@pytest.mark.parametrize("command", [["student", "Reach", "--seed", "-1"], ["teacher", "Reach", "--seed", "-1"],
                                     ["student", "Reach", "--steps", "0"], ["teacher", "Reach", "--max-steps", "-5"],
                                     ["teacher", "Reach", "--target-success", "1.5"],
                                     ["transfer", "--steps", "0"]])
def test_a_number_out_of_range_is_refused_naming_the_flag(tmp_path, capsys, command):
    with pytest.raises(SystemExit):
        main([*command, "--out", str(tmp_path / "runs")])
    flag = command[-2]
    assert f"argument {flag}: must be" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


# -- craftsuite transfer: bad input refused before anything is written ----------------------------
QUICK_REACH = ["transfer", "--suite", "quick", "--tasks", "Reach", "--seeds", "1", "--no-video"]


def _refused(tmp_path, capsys, *flags, out=None) -> str:
    """Run ``transfer`` with ``flags``; assert it exits 2 with one line (on stderr, nothing on
    stdout: not the suite it would have run) and wrote nothing; return the line."""
    before = sorted(tmp_path.rglob("*"))
    assert main([*QUICK_REACH, *flags, "--out", str(out or tmp_path / "out")]) == 2
    said, err = capsys.readouterr()
    assert err.startswith("craftsuite transfer: error: ") and err.count("\n") == 1 and said == ""
    assert sorted(tmp_path.rglob("*")) == before
    return err.removeprefix("craftsuite transfer: error: ").strip()


@pytest.mark.parametrize("flags,message", [
    (["--steps", "100"], "--steps 100: too small to train Reach's td3 students (Cont): no gradient update comes in "
     "the first 1,000 transitions (learning_starts); use --steps 1001 or more"),
    (["--steps", "2000", "--teacher-steps", "1000"], "--teacher-steps 1000: too small to train the Reach teacher, "
     "which takes no gradient update in its first 1,000 transitions (learning_starts); use --teacher-steps 1001 or "
     "more"),
    (["--steps", "2000", "--eval-every", "5000"], "an evaluation every 5,000 transitions (--eval-every, or the "
     "suite's) is longer than the 2,000-transition budget of Reach's td3 students (Cont), which would be evaluated "
     "only at their end; use --eval-every 2000 or less, or a larger --steps"),
    (["--steps", "2000", "--eval-every", "5"], "--eval-every 5: shorter than one step of the 10 envs of Reach's td3 "
     "students (Cont), the least between two evaluations; use --eval-every 10 or more"),
])
def test_transfer_refuses_a_budget_too_small_to_train(tmp_path, capsys, flags, message):
    assert _refused(tmp_path, capsys, *flags) == message


def test_the_smallest_budget_named_is_the_first_that_trains(tmp_path):
    from craftsuite.suite_runner import smallest_budget

    hyper = {"learning_starts": 50, "buffer_size": 500, "batch_size": 8, "policy_kwargs": {"net_arch": [16]}}
    need = smallest_budget({"learning_starts": 50, "train_freq": 1}, 4)
    assert need == 49  # 13 steps of 4 envs: 52 transitions, past 50
    for steps, trains in ((need - 1, False), (need, True)):
        config = StudentConfig(method="dqn", world="Grid7", steps=steps, eval_every=steps, eval_episodes=1,
                               n_envs=4, hyperparameters=hyper)
        result = json.loads((train_student(config, tmp_path / str(steps), progress=False) / "result.json").read_text())
        assert (result["updates"] > 0) == trains, (steps, result["updates"])


def test_smallest_budget_waits_for_a_training_step():
    from craftsuite.suite_runner import smallest_budget

    assert smallest_budget({"learning_starts": 1_000}, 1) == 1_001
    assert smallest_budget({"learning_starts": 1_000}, 10) == 1_001
    assert smallest_budget({"learning_starts": 1_000, "train_freq": [4, "step"]}, 1) == 1_004  # updates at 1,004
    assert smallest_budget({"learning_starts": 0}, 10) == 1


class _Pool:
    def __init__(self, *args):
        self.closed = []

    def close(self, abort=False):
        self.closed.append(abort)


def test_a_budget_given_announces_the_evaluation_interval_it_sets(tmp_path, monkeypatch):
    import craftsuite.suite_runner as suite_runner
    from craftsuite.suites import SUITES

    said, pools = [], []
    monkeypatch.setattr(suite_runner, "_check_students", lambda *a: None)
    monkeypatch.setattr(suite_runner, "WorkerPool", lambda *a: pools.append(_Pool()) or pools[-1])
    monkeypatch.setattr(suite_runner, "run_students", lambda *a, **k: (_ for _ in ()).throw(KeyboardInterrupt))
    suite = dataclasses.replace(SUITES["quick"], tasks=("Reach",), seeds=1, student_steps=4_000)
    with pytest.raises(KeyboardInterrupt):
        suite_runner.transfer(suite, tmp_path / "out", log=said.append)
    assert said == [f"suite quick: {suite.description}",
                    "(students evaluated every 200 transitions, a 20th of their budget of 4,000; --eval-every N sets "
                    "another)"]
    assert [p.closed for p in pools] == [[True]]  # an interrupted transfer stops its pool


def test_transfer_on_the_sb3_engine_trains_nothing_and_names_the_run_it_would(tmp_path, capsys):
    out = tmp_path / "out"
    assert main([*QUICK_REACH, "--steps", "2000", "--engine", "sb3", "--no-archive", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("craftsuite transfer: error: teacher-Reach-Grid7-")
    assert err.endswith(": the sb3 engine no longer trains (finished sb3 runs are reused, and this one is not "
                        "finished); train it with --engine population, or give --archive DIR where the finished "
                        "runs are kept\n")
    assert not out.exists()  # a refused command leaves nothing behind: no suite.json, no provenance.json
    empty = tmp_path / "results"  # an archive that does not hold the run refuses it alike
    assert main([*QUICK_REACH, "--steps", "2000", "--engine", "sb3", "--archive", str(empty), "--out", str(out)]) == 2
    assert capsys.readouterr().err.endswith("or give --archive DIR where the finished runs are kept\n")
    assert not out.exists() and not empty.exists()


def test_transfer_refuses_a_device_the_machine_lacks(tmp_path, capsys, monkeypatch):
    import torch

    base = ["--steps", "2000"]
    assert _refused(tmp_path, capsys, *base, "--device", "nonsense") == (
        "--device 'nonsense' is not a torch device: use cpu or cuda")
    assert _refused(tmp_path, capsys, *base, "--device", "mps") == (
        "--device mps: the population engine runs on cpu or cuda")
    monkeypatch.setattr(torch.cuda, "is_available", lambda: False)
    assert _refused(tmp_path, capsys, *base, "--device", "cuda") == (
        "--device cuda: this machine has no CUDA GPU; use --device cpu, or run on a machine with one")
    monkeypatch.setattr(torch.cuda, "is_available", lambda: True)
    monkeypatch.setattr(torch.cuda, "device_count", lambda: 1)
    assert _refused(tmp_path, capsys, *base, "--device", "cuda:3") == (
        "--device cuda:3: this machine has 1 CUDA GPU(s), cuda:0 to cuda:0; use one of them, or --device cuda")


def test_a_world_setting_the_engine_refuses_is_refused_before_the_archive_changes(tmp_path):
    """A suite whose students' world the engine cannot build (from Python, where no flag is
    checked) is refused before the output or the archive's records change."""
    import craftsuite.suite_runner as suite_runner
    from craftsuite.suites import SUITES

    archive = tmp_path / "results" / "quick"
    archive.mkdir(parents=True)
    (archive / "suite.json").write_text("{}\n")  # the archive's record of the suite, kept as it is
    suite = dataclasses.replace(SUITES["quick"], tasks=("Reach",), seeds=1, student_steps=2_000,
                                cont_world_kwargs={"render_mode": "rgb_array"})
    with pytest.raises(ValueError, match="render_mode='rgb_array': the vectorized MuJoCo world does not render"):
        suite_runner.transfer(suite, tmp_path / "out", archive=tmp_path / "results", video=False, progress=False)
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == [
        "results", "results/quick", "results/quick/suite.json"]
    assert (archive / "suite.json").read_text() == "{}\n"


def test_transfer_refuses_a_file_where_its_directories_must_be(tmp_path, capsys):
    file = tmp_path / "file"
    file.write_text("kept\n")
    assert _refused(tmp_path, capsys, "--steps", "2000", out=file) == (
        f"--out {file} is a file, not a directory: give a directory to write in (it is made if missing)")
    assert _refused(tmp_path, capsys, "--steps", "2000", out=file / "runs") == (
        f"--out {file / 'runs'}: {file / 'runs'} cannot be made: {file} is a file, not a directory; give a path "
        "whose every folder is a directory")
    assert _refused(tmp_path, capsys, "--steps", "2000", "--archive", str(file)) == (
        f"--archive {file} is a file, not a directory: give a directory to write in (it is made if missing)")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "quick").write_text("")  # the suite's place in the archive
    assert "--archive" in _refused(tmp_path, capsys, "--steps", "2000", "--archive", str(tmp_path / "results"))
    assert file.read_text() == "kept\n"


def test_transfer_refuses_an_output_directory_of_another_suite(tmp_path, capsys):
    """Suites never share an output directory (a quick run's would join the standard suite's
    leaderboard, and its suite.json be replaced); the same suite's resumes as before."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "suite.json").write_text(json.dumps({"name": "standard"}))
    assert _refused(tmp_path, capsys, "--steps", "2000", out=out) == (
        f"--out {out} holds runs of the standard suite (its suite.json), which the quick suite's would join on one "
        "leaderboard; give another --out, e.g. runs/quick")
    assert json.loads((out / "suite.json").read_text()) == {"name": "standard"}


def _closed_port() -> int:
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class _FakeRay:
    """Stands in for Ray (the default run needs none): ``init`` fails as Ray's does."""

    def __init__(self):
        self.inits = []

    def is_initialized(self):
        return False

    def init(self, address=None, **_):
        self.inits.append(address)
        raise ConnectionError(f"Failed to connect to Ray cluster at {address}")


def test_transfer_refuses_ray_out_of_reach_before_writing_anything(tmp_path, capsys, monkeypatch):
    import socket
    import sys

    import craftsuite.suite_runner as suite_runner

    monkeypatch.setattr(suite_runner, "_check_students", lambda *a: None)  # (building the agents: seconds)
    base = ["--steps", "2000"]
    monkeypatch.setitem(sys.modules, "ray", None)  # not installed
    assert _refused(tmp_path, capsys, *base, "--ray", "10.255.255.1:6379") == (
        "--ray 10.255.255.1:6379: Ray is not installed here; pip install 'craftsuite[ray]', or leave out --ray to run "
        "on local processes")
    fake = _FakeRay()
    monkeypatch.setitem(sys.modules, "ray", fake)
    port = _closed_port()
    assert _refused(tmp_path, capsys, *base, "--ray", f"127.0.0.1:{port}") == (
        f"--ray 127.0.0.1:{port}: nothing answers there (connection refused); start a head node there (ray start "
        f"--head --port {port}), give the address of a running one, or use --ray local")
    assert fake.inits == []  # refused before Ray retries it for 20 s
    with socket.create_server(("127.0.0.1", 0)) as listening:  # something answers, but not Ray
        address = f"127.0.0.1:{listening.getsockname()[1]}"
        assert _refused(tmp_path, capsys, *base, "--ray", address) == (
            f"--ray {address}: no Ray cluster could be joined there (ConnectionError: Failed to connect to Ray "
            f"cluster at {address}); give the address of a running head node, or --ray local")


def test_a_drawing_makes_its_folders_and_a_failed_one_leaves_nothing(tmp_path, capsys, monkeypatch):
    """A drawing goes where it is asked, folders made as the other commands make them (the
    render wrote to a folder that was not there and failed on it); a render that fails, or a
    Graphviz that is missing, leaves no drawing and no table behind."""
    import craftsuite.automata.draw as draw

    assert main(["automaton", "FirstTool", "--out", str(tmp_path / "new" / "deeper" / "a.dot")]) == 0
    assert "digraph" in (tmp_path / "new" / "deeper" / "a.dot").read_text()
    assert main(["distill", "FirstTool", "--static", "--out", str(tmp_path / "t.npz"),
                 "--draw", str(tmp_path / "drawn" / "v.dot")]) == 0
    assert (tmp_path / "t.npz").is_file() and "digraph" in (tmp_path / "drawn" / "v.dot").read_text()
    capsys.readouterr()
    failing = tmp_path / "bin" / "dot"  # a Graphviz that writes half a file and fails
    failing.parent.mkdir()
    failing.write_text("#!/bin/sh\nfor a; do out=$a; done\necho half > \"$out\"\necho 'Error: no layout' >&2\n"
                       "exit 1\n")
    failing.chmod(0o755)
    monkeypatch.setattr(draw, "_dot", lambda: str(failing))
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    assert main(["distill", "FirstTool", "--static", "--out", str(tmp_path / "t2.npz"),
                 "--draw", str(tmp_path / "out" / "v.png")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"craftsuite distill: error: dot failed on {tmp_path / 'out' / 'v.png'}: Error: no layout")
    monkeypatch.setattr(draw, "_dot", lambda: None)
    assert main(["automaton", "FirstTool", "--out", str(tmp_path / "a.png")]) == 2
    err = capsys.readouterr().err
    assert err == (f"craftsuite automaton: error: cannot draw {tmp_path / 'a.png'}: Graphviz 'dot' is not installed "
                   "(Debian: apt-get install graphviz); write a .dot file instead\n")
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before
