"""The results archive: records kept without models, restored so that nothing trains twice,
and damaged or foreign records named and skipped."""

from __future__ import annotations

import dataclasses
import json
import signal
from pathlib import Path

import pytest

from craftsuite import archive
from craftsuite.cli import main
from craftsuite.reporting.board import build
from craftsuite.runs import EPISODE_FIELDS, EVAL_FIELDS, read_csv, record_key, settings, write_csv
from craftsuite.suites import SUITES


def _run(root, name="student-Reach-Cont-td3-s0", seed=0, kind="student", steps=1000):
    """A finished run directory whose name carries its record's key, as a real run's does."""
    record = {"task": "Reach", "world": "Cont", "method": "td3", "seed": seed, "steps": steps,
              "format": 2, "provenance": [{"commit": "abc"}]}
    run = root / f"{name}-{record_key(record)}"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps(record))
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": steps, "success": 0.5, "return": 1.0, "episodes": 4}])
    write_csv(run / "episodes.csv", EPISODE_FIELDS,
              [{"step": s, "return": -1.5, "length": 10, "success": s % 2} for s in range(10, steps + 1, 10)])
    for junk in ("model.zip", "checkpoint/replay.pkl", "tb/events"):  # what the archive never keeps
        (run / junk).parent.mkdir(exist_ok=True)
        (run / junk).write_text("big")
    (run / "result.json").write_text(json.dumps({"kind": kind, "steps": steps, "model": "model.zip"}))
    return run


def test_a_kept_run_has_its_records_only_and_reads_the_same(tmp_path):
    run = _run(tmp_path / "out" / "students")
    kept = archive.keep(run, tmp_path / "results" / "quick", "students")
    assert sorted(p.name for p in kept.iterdir()) == ["config.json", "episodes.csv.gz", "evals.csv", "result.json"]
    assert read_csv(kept / "episodes.csv") == read_csv(run / "episodes.csv")  # read through the .gz
    assert (kept / "episodes.csv.gz").stat().st_size < (run / "episodes.csv").stat().st_size / 3
    # the leaderboard reads the archived run as it read the run itself
    before, after = build(run.parent).entries[0], build(kept.parent).entries[0]
    assert before.values == after.values
    # keeping it again writes the same bytes (a re-archived run is no change in the repository)
    packed = (kept / "episodes.csv.gz").read_bytes()
    archive.keep(run, tmp_path / "results" / "quick", "students")
    assert (kept / "episodes.csv.gz").read_bytes() == packed
    # kept again from an archive (another machine's), the compressed log comes along
    again = archive.keep(kept, tmp_path / "elsewhere", "students")
    assert read_csv(again / "episodes.csv") == read_csv(run / "episodes.csv")
    unfinished = _run(tmp_path / "out" / "students", seed=1)
    (unfinished / "result.json").unlink()
    with pytest.raises(RuntimeError, match="not finished"):
        archive.keep(unfinished, tmp_path / "results" / "quick", "students")


def test_damaged_and_foreign_records_are_named_and_skipped(tmp_path):
    store = tmp_path / "results" / "quick"
    good = archive.keep(_run(tmp_path / "a" / "students", seed=0), store, "students")
    damaged = archive.keep(_run(tmp_path / "a" / "students", seed=1), store, "students")
    (damaged / "result.json").write_text("{not json")
    renamed = archive.keep(_run(tmp_path / "a" / "students", seed=2), store, "students")
    renamed = renamed.rename(renamed.with_name("student-Reach-Cont-td3-s2-0123456789"))
    teacher = archive.keep(_run(tmp_path / "a" / "students", name="teacher-Reach", seed=3, kind="teacher"),
                           store, "students")
    mixed = archive.keep(_run(tmp_path / "a" / "students", seed=4), store, "students")
    (mixed / "result.json").write_text(json.dumps({"kind": "student", "steps": 1000, "seed": 9}))
    runs, skipped = archive.archived(store, "students")
    assert list(runs) == [good.name]
    assert len(skipped) == 4
    assert any(str(mixed / "result.json") in s and "another run's result (seed 9" in s for s in skipped)
    assert any(str(damaged / "result.json") in s and "damaged" in s for s in skipped)
    assert any(renamed.name in s and "not the name of the run its config.json records" in s for s in skipped)
    assert any(str(teacher / "result.json") in s and "teacher's result" in s for s in skipped)
    # restoring names each skipped record of the runs asked for (the others are not read) and
    # copies only the usable ones
    said = []
    names = {"students": {good.name, renamed.name, damaged.name}}
    assert archive.restore(store, tmp_path / "out", names, log=said.append) == {"teachers": 0, "students": 1}
    assert sorted(said) == sorted(f"results archive: skipped {archive.check_record(run)}" for run in (renamed, damaged))
    assert [p.name for p in (tmp_path / "out" / "students").iterdir()] == [good.name]


def test_restore_fills_what_is_missing_and_never_overwrites_a_finished_run(tmp_path):
    store = tmp_path / "results" / "quick"
    kept = archive.keep(_run(tmp_path / "a" / "students"), store, "students")
    out = tmp_path / "out"
    mine = _run(out / "students")  # the same run, finished here (with its model)
    assert archive.restore(store, out, {"students": {kept.name}}) == {"teachers": 0, "students": 0}
    assert (mine / "model.zip").exists()
    (mine / "result.json").unlink()  # unfinished here: the archive's finished record replaces it
    assert archive.restore(store, out, {"students": {kept.name}}) == {"teachers": 0, "students": 1}
    assert not (mine / "model.zip").exists() and (mine / "episodes.csv.gz").exists()


def test_the_archive_command_keeps_a_suites_runs_and_names_the_rest(tmp_path, capsys):
    suite = dataclasses.replace(SUITES["standard"], tags=(), tasks=("Reach",), worlds=("Cont",), methods=("td3",),
                                seeds=1)
    [config] = suite.student_configs(tmp_path)
    source = tmp_path / "elsewhere"
    run = source / config.run_name()
    run.mkdir(parents=True)
    record = {**json.loads(json.dumps(settings(config))), "format": 2, "provenance": []}  # as a run writes it
    (run / "config.json").write_text(json.dumps(record))
    (run / "result.json").write_text(json.dumps({"kind": "student", "steps": config.steps}))
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": config.steps, "success": 1.0, "return": 1.0, "episodes": 1}])
    foreign = _run(source)
    foreign.rename(foreign.with_name("student-Reach-Cont-td3-s0-0000000000"))  # not the run its record says
    assert main(["archive", str(source), "--suite", "standard", "--archive", str(tmp_path / "results")]) == 0
    out = capsys.readouterr().out
    assert "student-Reach-Cont-td3-s0-0000000000 is not the name of the run" in out
    assert "kept 1 student runs and 0 teachers" in out
    assert (tmp_path / "results" / "standard" / "students" / run.name / "result.json").exists()
    [session] = json.loads((tmp_path / "results" / "standard" / "provenance.json").read_text())
    assert session["archived"] == {"teachers": 0, "students": 1} and session["seconds"] == 0.0
    assert main(["archive", str(tmp_path / "nowhere"), "--suite", "standard"]) == 2
    assert "no run directory at" in capsys.readouterr().err
    assert main(["archive", str(source), "--suite", "biggest"]) == 2


def test_transfer_flags_choose_the_archive(tmp_path, monkeypatch, capsys):
    import craftsuite.suite_runner

    seen = {}

    def fake_transfer(suite, out, **kwargs):
        seen[suite.name] = kwargs["archive"]
        kwargs["log"](f"suite {suite.name}")  # as transfer says it, once it has checked its input
        return craftsuite.suite_runner.TransferResult(out, {}, [], out, [], None)

    monkeypatch.setattr(craftsuite.suite_runner, "transfer", fake_transfer)
    monkeypatch.chdir(tmp_path)
    args = ["transfer", "--tasks", "Reach", "--worlds", "Grid10", "--methods", "dqn"]
    assert main(args + ["--suite", "standard"]) == 0 and seen["standard"] == "results"
    assert main(["transfer", "--suite", "quick"]) == 0 and seen["quick"] is None  # the demo trains afresh
    assert main(args + ["--suite", "standard", "--archive", "elsewhere"]) == 0 and seen["standard"] == "elsewhere"
    assert main(args + ["--suite", "standard", "--no-archive"]) == 0 and seen["standard"] is None
    assert main(args + ["--suite", "standard", "--no-archive", "--archive", "x"]) == 2
    # settings beyond the suite's (a smoke test's budget) stay out of the archive unless asked for, as said
    capsys.readouterr()
    assert main(args + ["--suite", "standard", "--steps", "1000"]) == 0 and seen["standard"] is None
    assert capsys.readouterr().out.startswith(
        "suite standard\n(settings beyond the suite's: no results archive unless --archive DIR is given)\n")
    assert main(args + ["--suite", "standard", "--steps", "1000", "--archive", "x"]) == 0 and seen["standard"] == "x"
    # and so do rungs, worlds and methods the suite does not run: they are not its runs
    for beyond in (["--tasks", "Reach"], ["--worlds", "Kinematic", "--methods", "td3"], ["--methods", "crm-edges"]):
        assert main(["transfer", "--suite", "hard", "--worlds", "Grid10", "--tasks", "DungeonQuest", "--methods",
                     "dqn", *beyond]) == 0 and seen["hard"] is None, beyond
    assert main(["transfer", "--suite", "hard", "--worlds", "Grid10", "--tasks", "DungeonQuest", "--methods",
                 "dqn"]) == 0 and seen["hard"] == "results"  # a part of the suite is the suite's


def test_restore_leaves_a_run_a_live_process_holds(tmp_path):
    import fcntl
    import os

    store = tmp_path / "results" / "quick"
    kept = archive.keep(_run(tmp_path / "a" / "students"), store, "students")
    out = tmp_path / "out"
    busy = _run(out / "students")
    (busy / "result.json").unlink()  # unfinished, and training now: its lock is held
    (busy / ".lock").write_text("")
    fd = os.open(busy / ".lock", os.O_RDWR)
    fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    try:
        said = []
        assert archive.restore(store, out, {"students": {kept.name}}, log=said.append)["students"] == 0
        assert (busy / "model.zip").exists() and any("in use by a live run" in s for s in said)
    finally:
        os.close(fd)
    assert archive.restore(store, out, {"students": {kept.name}})["students"] == 1  # released: restored


class _InProcessPool:
    """A worker pool that runs each job here, at once: a reused sb3 run needs no worker, and
    training, were any asked for, would hit the spies this process holds."""

    processes = None  # no worker processes: each population checks its own memory

    def __init__(self, *args):
        self.jobs = []

    def submit(self, job, *args):
        from concurrent.futures import Future

        self.jobs.append(job.__name__)
        future = Future()
        try:
            future.set_result(job(*args))
        except Exception as err:
            future.set_exception(err)
        return future

    def close(self, abort=False):
        pass


def _finished_record(root, config, result: dict):
    """A finished run's record under ``root`` (a ``teachers`` or ``students`` folder), named
    and recorded as a run of ``config`` writes it."""
    from craftsuite.runs import FORMAT

    run = root / config.run_name()
    run.mkdir(parents=True)
    record = {**json.loads(json.dumps(settings(config))), "format": FORMAT, "provenance": [{"commit": "abc"}]}
    (run / "config.json").write_text(json.dumps(record))
    steps = result["steps"]
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": steps, "success": 0.75, "return": 1.0, "episodes": 4}])
    write_csv(run / "episodes.csv", EPISODE_FIELDS,
              [{"step": s, "return": -1.0, "length": 10, "success": 1} for s in (steps // 2, steps)])
    (run / "result.json").write_text(json.dumps(result))
    return run


def test_a_transfer_on_the_sb3_engine_reuses_the_finished_runs_its_archive_holds(tmp_path, monkeypatch):
    import torch

    import craftsuite.population
    import craftsuite.population.teacher
    import craftsuite.suite_runner as suite_runner

    def trains(*args, **kwargs):
        raise AssertionError("an sb3 run was trained, not reused")

    monkeypatch.setattr(craftsuite.population, "train_population", trains)
    monkeypatch.setattr(craftsuite.population.teacher, "train_teacher", trains)
    monkeypatch.setattr(torch, "set_num_threads", lambda n: None)  # a worker's setting, not this process's
    pools = []
    monkeypatch.setattr(suite_runner, "WorkerPool", lambda *a: pools.append(_InProcessPool()) or pools[-1])
    suite = dataclasses.replace(SUITES["quick"], tasks=("Reach",), seeds=1, engine="sb3")
    [teacher], students = suite.teachers().values(), suite.student_configs(tmp_path / "out" / "teachers")
    assert teacher.engine == "sb3" and sorted(c.method for c in students) == ["td3", "td3-dynamic-edges"]
    store = tmp_path / "results" / suite.name
    _finished_record(store / "teachers", teacher, {"kind": "teacher", "steps": 5_000, "success": 0.95,
                                                   "reached_target": True, "model": "teacher.zip"})
    for c in students:
        _finished_record(store / "students", c, {"kind": "student", "steps": c.steps, "task": c.task,
                                                 "method": c.method, "seed": c.seed, "model": "model.zip"})
    assert all(reason is None for reason in map(archive.check_record, (store / "students").iterdir()))
    (store / "suite.json").write_text('{"name": "quick", "as": "last run"}\n')
    (store / "provenance.json").write_text('[{"id": "earlier", "command": "craftsuite transfer", "seconds": 1.0}]\n')
    before = {name: (store / name).read_bytes() for name in ("suite.json", "provenance.json")}
    said = []
    result = suite_runner.transfer(suite, tmp_path / "out", video=False, progress=False, log=said.append,
                                   archive=tmp_path / "results")
    assert f"results archive {store}: 2 of 2 student runs and 1 of 1 teachers copied from it (not trained again)" \
        in said
    assert pools[0].jobs == ["_teacher_job"]  # the teacher's reuse goes through the pool; nothing trains
    # nothing kept: the archive's record of the suite as last run, and of its sessions, stays as it was
    assert {name: (store / name).read_bytes() for name in before} == before
    assert sorted(p.name for p in result.students) == sorted(c.run_name() for c in students)
    for run in result.students:
        assert json.loads((run / "result.json").read_text()) == json.loads(
            (store / "students" / run.name / "result.json").read_text())  # reused as archived
        assert not (run / "model.zip").exists()
    assert result.leaderboard.is_file() and "Reach" in result.leaderboard.read_text()


def test_a_transfer_archives_each_population_as_it_finishes(tmp_path, monkeypatch):
    """A population's runs are in the archive, with the session that trained them, as soon as
    it finishes: a campaign's process stopped later (a kill leaves no time to clean up)
    loses only the populations still training."""
    import craftsuite.suite_runner as suite_runner
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)
    suite = dataclasses.replace(SUITES["quick"], tasks=("Reach",), seeds=1)
    store = tmp_path / "results" / suite.name
    held = {}

    class Killed(Exception):
        pass

    def one_population_then_killed(configs, root, finished=None, **kwargs):
        first = configs[0]
        _finished_record(root, first, {"kind": "student", "steps": first.steps, "task": first.task,
                                       "method": first.method, "seed": first.seed, "model": "model.zip"})
        finished("students", [root / first.run_name()])
        held.update(runs=sorted(p.name for p in (store / "students").iterdir()), sessions=read(store),
                    first=first.run_name())
        raise Killed  # before the other population finishes, and before the session ends

    monkeypatch.setattr(suite_runner, "run_students", one_population_then_killed)
    with pytest.raises(Killed):
        suite_runner.transfer(suite, tmp_path / "out", video=False, progress=False, log=lambda *_: None,
                              archive=tmp_path / "results")
    assert held["runs"] == [held["first"]]
    [session] = held["sessions"]  # the session that trained it is named beside it, its time still open
    assert session["seconds"] is None and session["command"].startswith("python: craftsuite.suite_runner.transfer")


def test_a_transfer_whose_worker_was_killed_keeps_what_finished_and_exits_as_a_killed_process(tmp_path, monkeypatch,
                                                                                               capsys):
    """A worker the kernel's out-of-memory killer took breaks the process pool: the transfer
    says so in one line with the way on, keeps what finished, and exits 137 (not 2, a refused
    command), which a campaign's part takes up again."""
    from concurrent.futures.process import BrokenProcessPool

    import craftsuite.suite_runner as suite_runner

    class KilledPool(_InProcessPool):
        lost = [signal.SIGTERM, signal.SIGKILL]  # two workers killed: SIGKILL, the out-of-memory killer's, is named

    monkeypatch.setattr(suite_runner, "WorkerPool", KilledPool)

    def one_population_then_a_kill(configs, root, finished=None, **kwargs):
        first = configs[0]
        _finished_record(root, first, {"kind": "student", "steps": first.steps, "task": first.task,
                                       "method": first.method, "seed": first.seed, "model": "model.zip"})
        finished("students", [root / first.run_name()])
        raise BrokenProcessPool("A process in the process pool was terminated abruptly")

    monkeypatch.setattr(suite_runner, "run_students", one_population_then_a_kill)
    monkeypatch.chdir(tmp_path)
    status = main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods", "dqn",
                   "--seeds", "2", "--members", "1", "--no-video", "--out", "runs"])
    assert status == 128 + signal.SIGKILL
    said = capsys.readouterr().err.strip().splitlines()
    assert said == ["craftsuite transfer: error: a worker process was killed by SIGKILL, most likely out of memory: "
                    "fewer seeds to a population (--members) or populations at once (--workers) use less; the same "
                    "command resumes the unfinished runs from their checkpoints"]
    assert len(list((tmp_path / "results" / "standard" / "students").iterdir())) == 1
    from craftsuite.provenance import read

    [session] = read(tmp_path / "results" / "standard")  # the time it ran counts, as a stop's does
    assert session["seconds"] is not None


@pytest.mark.parametrize("died, how", [
    (("WorkerCrashedError",), "a Ray worker died (WorkerCrashedError)"),
    (("OutOfMemoryError", "Task was killed due to the node running low on memory."),
     "a Ray worker was killed by Ray's memory monitor (out of memory): fewer seeds to a population (--members) use "
     "less"),
])
def test_a_transfer_whose_ray_worker_died_says_so_in_one_line(tmp_path, monkeypatch, capsys, died, how):
    """On Ray a worker's death is Ray's own error, not a broken pool: the transfer says so as
    it does a local worker's, in one line with the way on (no traceback), and exits 1."""
    exceptions = pytest.importorskip("ray.exceptions")
    import craftsuite.suite_runner as suite_runner

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)

    def a_worker_dies(configs, root, **kwargs):
        raise getattr(exceptions, died[0])(*died[1:])

    monkeypatch.setattr(suite_runner, "run_students", a_worker_dies)
    monkeypatch.chdir(tmp_path)
    status = main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods", "dqn",
                   "--seeds", "1", "--no-video", "--out", "runs"])
    assert status == 1
    assert capsys.readouterr().err.strip().splitlines() == [
        f"craftsuite transfer: error: {how}; the same command resumes the unfinished runs from their checkpoints"]


def test_a_transfer_stopped_by_its_time_limit_keeps_what_finished_and_records_its_time(tmp_path, monkeypatch,
                                                                                        capsys):
    import time

    import craftsuite.suite_runner as suite_runner
    from craftsuite.cli import TIME_LIMIT_STATUS
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)
    given = {}

    def one_population_then_the_limit(configs, root, finished=None, deadline=None, **kwargs):
        given["left"] = deadline - time.monotonic()
        first = configs[0]
        _finished_record(root, first, {"kind": "student", "steps": first.steps, "task": first.task,
                                       "method": first.method, "seed": first.seed, "model": "model.zip"})
        finished("students", [root / first.run_name()])
        raise suite_runner.TimeLimitReached("time limit reached with 1 of 2 student runs unfinished")

    monkeypatch.setattr(suite_runner, "run_students", one_population_then_the_limit)
    monkeypatch.chdir(tmp_path)
    status = main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods", "dqn",
                   "--seeds", "2", "--members", "1", "--no-video", "--time-limit", "1.5", "--out", "runs"])
    assert status == TIME_LIMIT_STATUS and 80 < given["left"] <= 90  # 1.5 minutes, from the transfer's start
    said = capsys.readouterr().out
    assert ("time limit reached with 1 of 2 student runs unfinished; the finished runs are in runs and kept in "
            "results/standard") in said
    assert len(list((tmp_path / "results" / "standard" / "students").iterdir())) == 1
    [session] = read(tmp_path / "results" / "standard")  # ended, not killed: it ran its time
    assert session["seconds"] is not None
    with pytest.raises(SystemExit):
        main(["transfer", "--suite", "quick", "--time-limit", "0"])
    assert "--time-limit: must be a number above 0, got 0" in capsys.readouterr().err


def test_a_leaderboard_drawn_over_an_archive_directory_leaves_git_clean(tmp_path, capsys):
    """`craftsuite leaderboard results/standard` writes its board beside the archive's records,
    as over any directory of runs; git ignores every file it writes there (it showed them as
    new files in the repository), and none of the records."""
    import shutil
    import subprocess
    from pathlib import Path

    from .reporting.fakes import fake_run

    root = Path(__file__).resolve().parents[1]
    if shutil.which("git") is None or not (root / ".git").exists():
        pytest.skip("not a git checkout")
    for method in ("td3", "td3-dynamic"):
        fake_run(tmp_path / "runs" / "students", method, 0, [(500, 0.5), (1000, 1.0)], [(995, 1.0, 1)])
    assert main(["leaderboard", str(tmp_path / "runs")]) == 0
    capsys.readouterr()
    written = sorted(p.name for p in (tmp_path / "runs").iterdir() if p.is_file())
    assert "leaderboard.md" in written and any(name.endswith(".png") for name in written)

    def ignored(path: str) -> bool:
        return subprocess.run(["git", "-C", str(root), "-c", "core.excludesFile=/dev/null", "check-ignore", "-q",
                               "--no-index", path]).returncode == 0  # the repository's rules, not a user's own

    for archive_dir in ("results/standard", "results/n-step-returns/standard"):
        assert [n for n in written if not ignored(f"{archive_dir}/{n}")] == []
        records = ["suite.json", "provenance.json", "looks.json", "students/run/evals.csv",
                   "students/run/episodes.csv.gz", "teachers/run/table.npz"]
        assert [r for r in records if ignored(f"{archive_dir}/{r}")] == []


def _snapshot(root):
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_a_dry_run_counts_the_runs_it_would_reuse_and_train_and_writes_nothing(tmp_path):
    from craftsuite.archive import check_record
    from craftsuite.runs import RunDir
    from craftsuite.suite_runner import CellPlan, plan

    suite = dataclasses.replace(SUITES["standard"], tags=(), tasks=("Reach",), worlds=("Cont",),
                                methods=("td3", "td3-static"), seeds=3)
    configs = suite.student_configs(tmp_path / "out" / "teachers")
    store, out = tmp_path / "results" / "standard", tmp_path / "out"
    by = {(c.method, c.seed): c for c in configs}
    for method, seed, root in (("td3", 0, store), ("td3", 1, out), ("td3-static", 2, store)):
        c = by[method, seed]
        _finished_record(root / "students", c, {"kind": "student", "steps": c.steps, "task": c.task,
                                                "method": c.method, "seed": c.seed, "model": "model.zip"})
    begun = out / "students" / by["td3", 2].run_name()  # begun, not finished: resumes from its checkpoint
    saved = begun / RunDir.CHECKPOINTS[0]  # a member's checkpoint as the population engine writes it
    saved.mkdir(parents=True)
    (saved / "step.json").write_text(json.dumps({"num_timesteps": 1000}))
    (saved / "population.pt").write_bytes(b"state")
    c = by["td3-static", 1]
    damaged = _finished_record(store / "students", c, {"kind": "student", "steps": c.steps, "task": c.task,
                                                        "method": c.method, "seed": c.seed, "model": "model.zip"})
    (damaged / "config.json").write_text("{torn")  # the archive skips it: the run trains again
    before = _snapshot(tmp_path)
    found = plan(suite, out, archive=tmp_path / "results")
    steps = configs[0].steps
    assert found.cells == {("Cont", "Reach", "td3"): CellPlan(asked=3, finished=2, resumed=1, left=steps - 1000),
                           ("Cont", "Reach", "td3-static"): CellPlan(asked=3, finished=1, left=2 * steps)}
    assert found.left == 3 * steps - 1000 and found.teachers == (0, 0)
    lines = found.lines()
    assert [line for line in lines if damaged.name in line] == [f"results archive: skipped {check_record(damaged)}"]
    assert lines[-3] == (f"  Cont Reach td3: 3 seeds, 2 finished (reused), 1 to train, at least "
                         f"{(steps - 1000) / 1e6:,.2f}M transitions (1 resume from a checkpoint)")
    assert lines[-2] == f"  Cont Reach td3-static: 3 seeds, 1 finished (reused), 2 to train, {2 * steps / 1e6:,.2f}M " \
                        "transitions"
    assert lines[-1] == (f"students: 3 of 6 runs to train, at least {(3 * steps - 1000) / 1e6:,.2f}M transitions; "
                         "teachers: 0 of 0 to train")
    assert _snapshot(tmp_path) == before  # nothing written: no suite.json, provenance, restored run


def test_a_dry_run_names_a_run_a_live_process_trains_and_does_not_count_it_reused(tmp_path):
    """``archive.restore`` leaves a run in use alone, and a transfer could not take its lock:
    its archived record is not what a transfer now would reuse."""
    from craftsuite.runs import RunDir
    from craftsuite.suite_runner import CellPlan, plan

    suite = dataclasses.replace(SUITES["standard"], tags=(), tasks=("Reach",), worlds=("Cont",),
                                methods=("td3",), seeds=2)
    configs = suite.student_configs(tmp_path / "out" / "teachers")
    store, out = tmp_path / "results" / "standard", tmp_path / "out"
    for c in configs:
        _finished_record(store / "students", c, {"kind": "student", "steps": c.steps, "task": c.task,
                                                 "method": c.method, "seed": c.seed, "model": "model.zip"})
    live = out / "students" / configs[1].run_name()
    with RunDir(live, configs[1]):  # a live run's lock, as a training process holds it
        found = plan(suite, out, archive=tmp_path / "results")
    assert found.cells == {("Cont", "Reach", "td3"): CellPlan(asked=2, finished=1, left=configs[1].steps)}
    assert found.busy == (live,)
    assert [line for line in found.lines() if str(live) in line] == [
        f"{live} is in use by a live run: nothing is restored into it, and a transfer started now stops at it; "
        "wait for that run to end"]


def test_the_transfer_command_dry_run_says_what_it_would_train_and_refuses_what_transfer_refuses(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["transfer", "--suite", "standard", "--tasks", "Reach", "--worlds", "Cont", "--methods", "td3",
            "--seeds", "2", "--archive", str(tmp_path / "results"), "--out", str(out), "--dry-run"]
    assert main(args) == 0
    said = capsys.readouterr().out
    assert "a dry run: nothing is trained or written" in said and "Cont Reach td3: 2 seeds, 0 finished" in said
    assert "leaderboard" not in said
    assert not out.exists() and not (tmp_path / "results").exists()
    out.mkdir()
    (out / "suite.json").write_text(json.dumps({"name": "hard"}))  # another suite's runs: transfer refuses it
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "holds runs of the hard suite" in err and len(err.strip().splitlines()) == 1


def test_a_session_stopped_by_its_time_limit_before_any_run_finished_is_on_the_archives_record(tmp_path, monkeypatch):
    """Its time counts (the results page sums the sessions' wall time) though it kept no run."""
    import craftsuite.suite_runner as suite_runner
    from craftsuite.cli import TIME_LIMIT_STATUS
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)

    def stopped(configs, root, **kwargs):
        raise suite_runner.TimeLimitReached("time limit reached with 2 of 2 student runs unfinished")

    monkeypatch.setattr(suite_runner, "run_students", stopped)
    monkeypatch.chdir(tmp_path)
    assert main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods", "dqn",
                 "--seeds", "2", "--no-video", "--time-limit", "1.5", "--out", "runs"]) == TIME_LIMIT_STATUS
    [session] = read(tmp_path / "results" / "standard")
    assert session["seconds"] is not None


def test_a_session_whose_record_failed_as_a_population_finished_is_recorded_at_its_end(tmp_path, monkeypatch):
    import craftsuite.provenance as provenance
    import craftsuite.suite_runner as suite_runner
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)
    real, failed = provenance.merge, []

    def fails_once(where, sessions):
        if not failed and "results" in Path(where).parts:  # the archive's, not the output directory's
            failed.append(where)
            raise OSError("No space left on device")
        return real(where, sessions)

    monkeypatch.setattr(provenance, "merge", fails_once)

    def trains_all(configs, root, finished=None, **kwargs):
        paths = [_finished_record(root, c, {"kind": "student", "steps": c.steps, "task": c.task, "method": c.method,
                                            "seed": c.seed, "model": "model.zip"}) for c in configs]
        finished("students", paths)  # its record fails here: the session's end tries again
        return paths

    monkeypatch.setattr(suite_runner, "run_students", trains_all)
    monkeypatch.chdir(tmp_path)
    assert main(["transfer", "--suite", "standard", "--worlds", "Grid10", "--tasks", "Reach", "--methods", "dqn",
                 "--seeds", "1", "--no-video", "--out", "runs"]) == 0
    assert failed and [s["seconds"] is not None for s in read(tmp_path / "results" / "standard")] == [True]


def test_a_session_that_trains_nothing_but_keeps_a_run_is_recorded_though_its_first_record_failed(tmp_path,
                                                                                                  monkeypatch):
    """A run finished in --out that the archive lacks is kept by a session with nothing to
    train: its record (the session, the suite) is written, at the session's end if it failed before."""
    import craftsuite.provenance as provenance
    import craftsuite.suite_runner as suite_runner
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)
    suite = dataclasses.replace(SUITES["standard"], tags=(), tasks=("Reach",), worlds=("Grid10",), methods=("dqn",),
                                seeds=1)
    [config] = suite.student_configs(tmp_path / "out" / "teachers")
    _finished_record(tmp_path / "out" / "students", config, {"kind": "student", "steps": config.steps,
                                                             "task": config.task, "method": config.method,
                                                             "seed": config.seed, "model": "model.zip"})
    real, failed = provenance.merge, []

    def fails_once(where, sessions):
        if not failed and "results" in Path(where).parts:
            failed.append(where)
            raise OSError("No space left on device")
        return real(where, sessions)

    monkeypatch.setattr(provenance, "merge", fails_once)
    monkeypatch.setattr(suite_runner, "run_students", lambda configs, root, **kwargs: [root / c.run_name()
                                                                                       for c in configs])
    suite_runner.transfer(suite, tmp_path / "out", video=False, progress=False, log=lambda *_: None,
                          archive=tmp_path / "results")
    store = tmp_path / "results" / "standard"
    assert failed and (store / "students" / config.run_name() / "result.json").is_file()
    assert [s["seconds"] is not None for s in read(store)] == [True] and (store / "suite.json").is_file()


def test_a_session_that_reused_every_run_stays_off_the_archives_record_when_a_later_one_into_its_out_trains(
        tmp_path, monkeypatch):
    import craftsuite.suite_runner as suite_runner
    from craftsuite.provenance import read

    monkeypatch.setattr(suite_runner, "WorkerPool", _InProcessPool)

    def trains_the_unfinished(configs, root, finished=None, **kwargs):
        paths = [root / c.run_name() if (root / c.run_name() / "result.json").is_file() else
                 _finished_record(root, c, {"kind": "student", "steps": c.steps, "task": c.task, "method": c.method,
                                            "seed": c.seed, "model": "model.zip"}) for c in configs]
        finished("students", paths)
        return paths

    monkeypatch.setattr(suite_runner, "run_students", trains_the_unfinished)
    sessions = []
    for seeds in (1, 1, 2):  # trains seed 0; reuses it; trains seed 1
        suite = dataclasses.replace(SUITES["standard"], tags=(), tasks=("Reach",), worlds=("Grid10",),
                                    methods=("dqn",), seeds=seeds)
        suite_runner.transfer(suite, tmp_path / "out", video=False, progress=False, log=lambda *_: None,
                              archive=tmp_path / "results", command=f"transfer --seeds {seeds} ({len(sessions)})")
        sessions.append(read(tmp_path / "out")[-1])
    assert [s.get("reused_only", False) for s in sessions] == [False, True, False]
    assert [s["command"] for s in read(tmp_path / "results" / "standard")] == \
        [sessions[0]["command"], sessions[2]["command"]]
