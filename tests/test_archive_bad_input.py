"""Bad input to ``craftsuite archive``: a run without its evaluations, a directory without
runs, runs of another suite and an archive path that is a file are each named in one line,
and a refused command leaves the archive as it was (nothing made where there was none)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from craftsuite.cli import main
from craftsuite.runs import EVAL_FIELDS, record_key, write_csv


def _run(root, task="Reach", world="Cont", method="td3", seed=0, kind="student", steps=1000):
    """A finished run whose name carries its record's key, as a real run's does."""
    record = {"task": task, "format": 2, "provenance": []}
    if kind == "student":
        record.update(world=world, method=method, seed=seed, steps=steps)
    else:
        record.update(size=7, seed=seed, max_steps=steps)
    name = f"{kind}-{task}-{world}-{method}-s{seed}" if kind == "student" else f"teacher-{task}-Grid7-s{seed}"
    run = root / f"{name}-{record_key(record)}"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps(record))
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": steps, "success": 0.5, "return": 1.0, "episodes": 4}])
    (run / "result.json").write_text(json.dumps({"kind": kind, "steps": steps}))
    return run


def _files(root):
    """Every file and folder under ``root`` with its bytes: what a command left there."""
    return {str(p.relative_to(root)): p.read_bytes() if p.is_file() else None for p in root.rglob("*")} \
        if root.exists() else None


def _archive(tmp_path, *sources, suite="standard"):
    return main(["archive", *map(str, sources), "--suite", suite, "--archive", str(tmp_path / "results")])


@pytest.mark.parametrize("kind", ["student", "teacher"])
@pytest.mark.parametrize("text, problem", [
    (None, "evals.csv is missing: a finished run's record has its evaluations"),
    ("step,success,return,episodes,length\n", "evals.csv holds no evaluation"),
    ("garbage\n", "evals.csv does not read as a run's log (its header lacks step, success"),
])
def test_a_run_without_its_evaluations_is_named_and_not_archived(tmp_path, capsys, kind, text, problem):
    source = tmp_path / "out"
    run = _run(source / f"{kind}s", kind=kind)
    if text is None:
        (run / "evals.csv").unlink()
    else:
        (run / "evals.csv").write_text(text)
    assert _archive(tmp_path, source) == 2
    captured = capsys.readouterr()
    assert f"skipped {run / 'evals.csv'}" in captured.out and problem in captured.out
    assert captured.err.strip().endswith("each is named above with why; give finished runs of that suite")
    assert not (tmp_path / "results").exists()


def test_beside_a_good_run_one_without_evaluations_is_skipped_and_the_leaderboard_reads_the_archive(
        tmp_path, capsys):
    source = tmp_path / "out" / "students"
    good, bad = _run(source, seed=0), _run(source, seed=1)
    (bad / "evals.csv").unlink()
    assert _archive(tmp_path, source) == 0
    out = capsys.readouterr().out
    assert f"skipped {bad / 'evals.csv'} is missing" in out and "kept 1 student runs and 0 teachers" in out
    students = tmp_path / "results" / "standard" / "students"
    assert [p.name for p in students.iterdir()] == [good.name]
    assert main(["leaderboard", str(students), "--out", str(tmp_path / "board")]) == 0


@pytest.mark.parametrize("layout", ["empty", "folders", "transfer output"])
def test_a_directory_without_runs_is_refused_and_nothing_is_made(tmp_path, capsys, layout):
    source = tmp_path / "elsewhere"
    source.mkdir()
    if layout == "folders":  # e.g. the archive's root given for a suite's directory
        for name in ("hard", "standard"):
            (source / name).mkdir()
    elif layout == "transfer output":
        (source / "students").mkdir()
        (source / "teachers").mkdir()
    assert _archive(tmp_path, source) == 2
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith(f"craftsuite archive: error: no runs found under {source}")
    assert line.endswith(": give a transfer output or a directory of student runs")
    if layout == "folders":
        assert "its folders hard, standard hold no run's record" in line
    assert not (tmp_path / "results").exists()  # no archive directory, suite.json or provenance.json


def test_every_source_is_read_before_anything_is_kept(tmp_path, capsys):
    good = tmp_path / "good"
    _run(good)
    (tmp_path / "empty").mkdir()
    assert _archive(tmp_path, good, tmp_path / "empty") == 2
    assert "no runs found under" in capsys.readouterr().err
    assert not (tmp_path / "results").exists()  # the good source's run was not kept either


ELSEWHERE = "archive it with --suite set to a suite that runs it"
OWN = "no suite runs it: run its transfer again with the same --out and --archive DIR"


@pytest.mark.parametrize("suite, run, problem, fix", [
    ("hard", dict(task="Reach"), "task Reach is not one of suite hard's tasks (BlindCraftsman",
     f"{ELSEWHERE} (standard)"),
    ("standard", dict(world="Kinematic"), "world Kinematic is not one of suite standard's worlds (Grid10, Cont)",
     f"{OWN}"),  # the kinematic board's runs of Reach: no suite's (the paper suite runs the paper's tasks)
    # a method another suite runs, but not on this task: no suite is named that would refuse it too
    ("standard", dict(method="td3-crm-edges"), "method td3-crm-edges is not one of suite standard's methods", OWN),
    ("standard", dict(method="td3-crm-edges", task="BlindCraftsman"), "task BlindCraftsman is not one of suite "
     "standard's tasks", f"{ELSEWHERE} (transfer)"),
    # a row of a user's own, which a suite's transfer runs but no suite's archive keeps
    ("standard", dict(method="td3-mine"), "method td3-mine is not one of suite standard's methods",
     f"{OWN} (an archive of its own, not results) to keep it, or read it where it is beside this archive "
     "(craftsuite leaderboard RUNS ARCHIVE/standard --out DIR)"),
    ("hard", dict(task="Reach", kind="teacher"), "task Reach is not one of suite hard's tasks",
     f"{ELSEWHERE} (standard)"),
])
def test_a_run_of_another_suite_is_named_and_not_filed_under_this_one(tmp_path, capsys, suite, run, problem, fix):
    kind = run.get("kind", "student")
    source = tmp_path / "out"
    run = _run(source / f"{kind}s", **run)
    assert _archive(tmp_path, source, suite=suite) == 2
    out = capsys.readouterr().out
    assert f"skipped {run}: {problem}" in out and fix in out
    assert not (tmp_path / "results").exists()


def test_runs_of_the_suite_are_kept_beside_the_skipped_ones_other_budgets_too(tmp_path, capsys):
    source = tmp_path / "out"
    mine, smoke = _run(source, seed=0), _run(source, seed=1, steps=500)  # --steps 500: kept, as the suite's own
    other = _run(source, task="DiamondMine", seed=0)
    assert _archive(tmp_path, source) == 0
    out = capsys.readouterr().out
    assert f"skipped {other}: task DiamondMine" in out and "kept 2 student runs" in out
    kept = tmp_path / "results" / "standard" / "students"
    assert sorted(p.name for p in kept.iterdir()) == sorted([mine.name, smoke.name])


def test_a_refused_archive_leaves_the_archive_as_it_was(tmp_path):
    assert _archive(tmp_path, _run(tmp_path / "first").parent) == 0
    before = _files(tmp_path / "results")
    assert {"standard/suite.json", "standard/provenance.json"} <= set(before)
    assert _archive(tmp_path, _run(tmp_path / "second", task="DiamondMine").parent) == 2  # another suite's run
    (tmp_path / "nothing-here").mkdir()
    assert _archive(tmp_path, tmp_path / "nothing-here") == 2
    assert _files(tmp_path / "results") == before  # no new session, suite.json as it was


def test_runs_the_archive_holds_already_change_nothing(tmp_path, capsys):
    source = _run(tmp_path / "out").parent
    assert _archive(tmp_path, source) == 0
    before = _files(tmp_path / "results")
    capsys.readouterr()
    assert _archive(tmp_path, source) == 0
    assert "kept 0 student runs and 0 teachers" in capsys.readouterr().out
    assert _files(tmp_path / "results") == before  # no session recorded for keeping nothing


def test_another_suites_suite_json_is_not_recorded_over_this_ones(tmp_path, capsys):
    source = tmp_path / "out"
    _run(source / "students")
    (source / "suite.json").write_text(json.dumps({"name": "hard", "tags": ["hard"]}))
    assert _archive(tmp_path, source) == 0
    assert f"skipped {source / 'suite.json'} is suite hard's, not standard's" in capsys.readouterr().out
    assert json.loads((tmp_path / "results" / "standard" / "suite.json").read_text())["name"] == "standard"


@pytest.mark.parametrize("archive, problem", [
    ("a-file", "--archive a-file is a file, not a directory: give a directory to write in"),
    ("a-file/results", "--archive a-file/results: a-file/results cannot be made: a-file is a file"),
])
def test_an_archive_path_that_is_a_file_is_named_before_anything_is_read(tmp_path, monkeypatch, capsys,
                                                                         archive, problem):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a-file").write_text("kept as it was")
    before = _files(tmp_path)
    assert main(["archive", "no-such-runs", "--suite", "standard", "--archive", archive]) == 2
    [line] = capsys.readouterr().err.splitlines()
    assert line.startswith("craftsuite archive: error: ") and problem in line and "Errno" not in line
    assert _files(tmp_path) == before


def test_the_suites_directory_as_a_file_is_named(tmp_path, capsys):
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "standard").write_text("not an archive")
    assert _archive(tmp_path, _run(tmp_path / "out").parent) == 2
    assert f"--archive {tmp_path / 'results' / 'standard'} is a file, not a directory" in capsys.readouterr().err


def test_an_archive_that_cannot_be_written_is_named(tmp_path, monkeypatch, capsys):
    import craftsuite.files

    locked = tmp_path / "results"
    locked.mkdir()
    # (no chmod: the tests may run as root, who writes anywhere)
    monkeypatch.setattr(craftsuite.files.os, "access", lambda path, mode: Path(path) != locked)
    assert _archive(tmp_path, _run(tmp_path / "out").parent) == 2
    assert f"--archive {locked}: {locked} is not writable here; give a directory you can write in" in (
        capsys.readouterr().err)
    assert not any(locked.iterdir())

def test_a_run_given_for_its_directory_names_the_directory(tmp_path, capsys):
    run = _run(tmp_path / "out")
    assert _archive(tmp_path, run) == 2
    assert f"{run} is a run, not a directory of runs: give the directory that holds it ({run.parent})" in (
        capsys.readouterr().err)
    assert not (tmp_path / "results").exists()


@pytest.mark.parametrize("file, text, problem", [
    ("evals.csv", "step,success,return,episodes\n1000,0.5,nan,4\n", "evals.csv: line 2: return is nan"),
    ("evals.csv", "step,success,return,episodes\n9000,0.5,1.0,4\n", "step 9000 is not a step of the run"),
    ("episodes.csv", "step,return,length,success\n10,1.0,10,1\n20,1.0,10,0.5\n", "line 3: success 0.5 is not 0 or 1"),
    ("episodes.csv", "step,return,length,success\n10.5,1.0,10,1\n", "line 2: step 10.5 is not a step of the run"),
    ("episodes.csv", "step,return,success\n10,1.0,1\n", "episodes.csv does not read as a run's log (its header "
     "lacks length"),
    ("result.json", json.dumps({"kind": "student", "steps": 10}), "steps 10 is short of the budget"),
    ("result.json", json.dumps({"kind": "student", "steps": 1000, "task": "DungeonQuest"}), "another run's result"),
])
def test_a_record_that_breaks_the_format_is_named_and_not_archived(tmp_path, capsys, file, text, problem):
    source = tmp_path / "out"
    run = _run(source / "students")
    (run / file).write_text(text)
    assert _archive(tmp_path, source) == 2
    out = capsys.readouterr().out
    assert problem in out and str(run) in out
    assert not (tmp_path / "results").exists()
