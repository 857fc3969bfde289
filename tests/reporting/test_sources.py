"""A directory of runs as the reports find it: its students, suite and sessions."""

import json

import pytest

from craftsuite.cli import main
from craftsuite.reporting.sources import read_runs, session_line

from .fakes import fake_run


def test_a_transfer_output_and_a_directory_of_student_runs_read_alike(tmp_path):
    fake_run(tmp_path / "out" / "students", "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    (tmp_path / "out" / "suite.json").write_text(json.dumps({"name": "quick"}))
    transfer = read_runs(tmp_path / "out", transfer=True)
    assert transfer.students == tmp_path / "out" / "students" and transfer.suite == {"name": "quick"}
    assert [e.method for e in transfer.board] == ["td3"] and transfer.sessions == []
    students = read_runs(tmp_path / "out" / "students")
    assert students.students == students.path and students.suite == {}
    with pytest.raises(FileNotFoundError, match="no students/"):
        read_runs(tmp_path / "out" / "students", transfer=True)
    with pytest.raises(FileNotFoundError, match="no run directory at"):
        read_runs(tmp_path / "nope")


def test_a_directory_holding_only_a_damaged_run_names_the_file_not_just_no_runs(tmp_path, capsys):
    run = fake_run(tmp_path / "students", "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    (run / "result.json").write_text("{torn")
    with pytest.raises(ValueError,
                       match=r"no finished student runs under .*; not read: .*result.json is not valid JSON"):
        read_runs(tmp_path)
    assert main(["leaderboard", str(tmp_path)]) == 2
    [line] = capsys.readouterr().err.strip().splitlines()
    assert str(run / "result.json") in line and "not valid JSON" in line
    assert (run / "result.json").read_text() == "{torn"  # nothing on disk is touched


def test_a_path_a_level_off_names_the_runs_directory_to_give(tmp_path, capsys):
    """An archive given for one of its suites, or one run's directory for the runs around
    it: no runs there, and the line says where they are."""
    run = fake_run(tmp_path / "results" / "standard" / "students", "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    (tmp_path / "results" / "hard" / "students").mkdir(parents=True)
    for given, where in ((tmp_path / "results", f"; its folders hold runs: give one or more of them "
                                                f"({tmp_path}/results/hard {tmp_path}/results/standard)"),
                         (run, f"; it is one run's directory: give the directory of runs that holds it "
                               f"({tmp_path}/results/standard)")):
        with pytest.raises(ValueError, match="no finished student runs under ") as refused:
            read_runs(given)
        assert str(refused.value).endswith(where)
    with pytest.raises(ValueError) as refused:
        read_runs(tmp_path / "results" / "hard")
    assert str(refused.value) == f"no finished student runs under {tmp_path}/results/hard/students"


def test_sessions_read_to_the_day_or_to_the_minute():
    session = {"command": "craftsuite transfer quick", "started": "2026-01-02T03:04:05+00:00", "commit": None,
               "machine": "Linux", "seconds": 90.0}
    assert session_line(session, to_the_minute=True) == (
        "- `craftsuite transfer quick`: 2026-01-02 03:04 UTC, commit unknown, 1.5 min on Linux")
    assert session_line({**session, "seconds": None}, to_the_minute=False) == (
        "- `craftsuite transfer quick`: 2026-01-02, commit unknown, did not finish on Linux")


def test_a_leaderboard_narrowed_to_tasks_and_worlds_reads_their_runs_alone(tmp_path, capsys):
    """--tasks and --worlds make the board of those rungs alone, the others' logs never read
    (a user's rung beside an archive took minutes: every run's logs were read); a filter
    that leaves no run, or one beside --page, is refused in one line and writes nothing."""
    runs = tmp_path / "runs"
    for task, world in (("Reach", "Grid10"), ("Reach", "Cont"), ("FirstWood", "Cont")):
        method = "dqn" if world == "Grid10" else "td3"
        fake_run(runs, method, 0, [(500, 0.5), (1000, 1.0)], [(995, 1.0, 1)], task=task, world=world)
    (runs / "student-FirstWood-Cont-td3-s0" / "evals.csv").write_text("damaged\n")  # never read when left out
    assert main(["leaderboard", str(runs), "--tasks", "Reach", "--worlds", "Cont", "--out", str(tmp_path / "b")]) == 0
    board = (tmp_path / "b" / "leaderboard.md").read_text()
    assert "## Reach (Cont)" in board and "Grid10" not in board and "FirstWood" not in board
    assert "Not read" not in capsys.readouterr().out  # the damaged run was left out unread
    refused = {
        ("--tasks", "FirstTool"): f"craftsuite leaderboard: error: no finished student runs of --tasks FirstTool under "
                                  f"{runs}\n",
        ("--tasks", "Reach", "--worlds", "Kinematic"):
            f"craftsuite leaderboard: error: no finished student runs of --tasks Reach --worlds Kinematic under "
            f"{runs}\n",
        ("--worlds", "Cont", "--page", str(tmp_path / "p.md")):
            "craftsuite leaderboard: error: --tasks and --worlds narrow a leaderboard; a page (--page, --reproduction) "
            "shows every run of its directories: leave them out\n",
    }
    refused[("--tasks", "Reach")] = ("craftsuite leaderboard: error: --tasks and --worlds make a board of some of "
                                     "the runs: give --out DIR for it\n")  # not over the directory's own board
    for flags, message in refused.items():
        out = [] if "--page" in flags or flags == ("--tasks", "Reach") else ["--out", str(tmp_path / "c")]
        assert main(["leaderboard", str(runs), *flags, *out]) == 2
        assert capsys.readouterr().err == message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["b", "runs"]
    # beside a directory that holds the rung, one that holds none of it is no error
    mine = tmp_path / "mine"
    fake_run(mine, "my-agent", 0, [(500, 0.5), (1000, 1.0)], [(995, 1.0, 1)], task="FirstWood", world="Cont")
    assert main(["leaderboard", str(mine), str(runs), "--tasks", "Reach", "--out", str(tmp_path / "d")]) == 0
    assert main(["leaderboard", str(mine), str(runs), "--tasks", "FirstTool", "--out", str(tmp_path / "e")]) == 2
    assert capsys.readouterr().err.endswith(f"error: no finished student runs of --tasks FirstTool under {mine}, "
                                            f"{runs}\n")


def test_a_damaged_suite_record_is_named_with_what_to_do(tmp_path, capsys):
    fake_run(tmp_path / "out" / "students", "td3", 0, [(1000, 1.0)], [(995, 1.0)])
    for text, problem in (("{torn", "is not valid JSON"), ("[1]", "is not a suite's record (a JSON object)")):
        (tmp_path / "out" / "suite.json").write_text(text)
        assert main(["leaderboard", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"craftsuite leaderboard: error: {tmp_path / 'out' / 'suite.json'} {problem}")
        assert err.endswith(": move it aside (the suite's next transfer into the directory writes it again), or give "
                            "another directory\n") and err.count("\n") == 1
        assert (tmp_path / "out" / "suite.json").read_text() == text
