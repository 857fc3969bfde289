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


def test_sessions_read_to_the_day_or_to_the_minute():
    session = {"command": "craftsuite transfer quick", "started": "2026-01-02T03:04:05+00:00", "commit": None,
               "machine": "Linux", "seconds": 90.0}
    assert session_line(session, to_the_minute=True) == (
        "- `craftsuite transfer quick`: 2026-01-02 03:04 UTC, commit unknown, 1.5 min on Linux")
    assert session_line({**session, "seconds": None}, to_the_minute=False) == (
        "- `craftsuite transfer quick`: 2026-01-02, commit unknown, did not finish on Linux")
