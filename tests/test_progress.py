"""Progress output: plain lines in a log, rates of this session's work only, reuse and resume
announced on lines of their own."""

from __future__ import annotations

import dataclasses
import io
import json
from concurrent.futures import Future

import pytest
from tqdm import tqdm

import craftsuite.progress
from craftsuite.configs import StudentConfig
from craftsuite.progress import LineProgress, progress_bar
from craftsuite.runs import RunDir
from craftsuite.training import train_student

TINY = {"learning_starts": 50, "buffer_size": 2_000, "policy_kwargs": {"net_arch": [16]}}
CONFIG = StudentConfig(method="dqn", world="Grid7", steps=300, eval_every=100, eval_episodes=1, hyperparameters=TINY)


class _Terminal(io.StringIO):
    def isatty(self):
        return True


class _Clock:
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_a_log_gets_plain_lines_a_terminal_a_bar():
    log = io.StringIO()
    with progress_bar(100, "runs", stream=log) as bar:
        assert isinstance(bar, LineProgress)
        for _ in range(100):
            bar.update(1)
    text = log.getvalue()
    assert "\r" not in text and text.count("\n") == 10  # one line a tenth
    assert text.splitlines()[-1].startswith("runs: 100% (100/100 steps, ")
    terminal = _Terminal()
    with progress_bar(100, "runs", initial=40, stream=terminal) as bar:
        assert isinstance(bar, tqdm) and bar.n == 40 and bar.format_dict["initial"] == 40
    assert "\r" in terminal.getvalue()
    assert isinstance(progress_bar(100, "quiet", enabled=False, stream=io.StringIO()), tqdm)  # a worker's: silent


def test_lines_come_every_tenth_or_every_30_seconds_and_count_this_sessions_rate():
    log, clock = io.StringIO(), _Clock()
    bar = LineProgress(1_000, "2 student runs", "step", 600, log, clock=clock)  # resumed at 600
    clock.now = 10.0
    bar.update(50)  # 65%: no new tenth, 10 s
    assert log.getvalue() == ""
    clock.now = 31.0
    bar.update(10)  # 66%, 31 s: a line for the time
    clock.now = 40.0
    bar.update(40)  # 70%: a line for the tenth
    bar.set_postfix(success="0.50")
    bar.close()  # nothing new since the last line: none more
    lines = log.getvalue().splitlines()
    # the rate: the 100 steps of this session over 40 s, not the 700 counted
    assert lines == ["2 student runs: 66% (660/1,000 steps, 2 steps/s, 00:31 elapsed)",
                     "2 student runs: 70% (700/1,000 steps, 2 steps/s, 00:40 elapsed)"]
    clock.now = 100.0
    bar.update(300)
    assert log.getvalue().splitlines()[-1] == "2 student runs: 100% (1,000/1,000 steps, 4 steps/s, 01:40 elapsed, " \
        "success 0.50)"


def test_a_message_gets_a_line_of_its_own(capsys):
    bar = progress_bar(10, "runs", stream=io.StringIO())
    bar.write("teacher Reach: done")
    assert capsys.readouterr().out == "teacher Reach: done\n"


@pytest.fixture
def killed(tmp_path, monkeypatch):
    """``CONFIG``'s population run killed after its checkpoint at 300, the one before at 200,
    the newer set aside: it resumes from 200."""
    from craftsuite.population.train import saved_steps

    monkeypatch.setattr(RunDir, "write_result", lambda self, result: (_ for _ in ()).throw(KeyboardInterrupt))
    with pytest.raises(KeyboardInterrupt):
        train_student(CONFIG, tmp_path, progress=False)
    monkeypatch.undo()
    run = tmp_path / CONFIG.run_name()
    assert max(saved_steps(run)) == 300
    (run / "checkpoint").rename(run / "checkpoint-aside")
    assert max(saved_steps(run)) == 200
    return run


def _bars(monkeypatch) -> list[dict]:
    made = []
    real = craftsuite.progress.progress_bar

    def recording(total, desc, unit="step", initial=0, enabled=True, stream=None):
        made.append({"total": total, "desc": desc, "initial": initial})
        return real(total, desc, unit, initial, enabled, stream)

    monkeypatch.setattr(craftsuite.progress, "progress_bar", recording)
    return made


def test_a_resumed_population_counts_its_earlier_steps_as_done_before(killed, monkeypatch):
    made = _bars(monkeypatch)
    train_student(CONFIG, killed.parent, progress=False)
    assert [bar["initial"] for bar in made] == [200]


class _Pool:
    """Runs nothing: each population job "finishes" at once, as a worker that found its runs done."""

    processes = None  # as a Ray cluster's: no memory of its own to check

    def __init__(self, root):
        self.root, self.closed, self.submitted = root, False, []

    def submit(self, job, configs, root, *_):
        names = [StudentConfig(**c).run_name() for c in configs]
        self.submitted += names
        for name in names:
            (self.root / name / "result.json").write_text("{}")
        future = Future()
        future.set_result([str(self.root / name) for name in names])
        return future

    def close(self, abort=False):
        self.closed = True


def test_the_suites_bar_announces_reuse_and_resume_and_starts_past_them(killed, monkeypatch, capsys):
    import craftsuite.suite_runner as suite_runner

    root = killed.parent
    done = StudentConfig(method="dqn", world="Grid7", seed=1, steps=300, eval_every=100, eval_episodes=1,
                         hyperparameters=TINY, engine="sb3")
    (root / done.run_name()).mkdir()
    (root / done.run_name() / "result.json").write_text(json.dumps({"steps": 300}))
    made = []
    real = suite_runner.progress_bar
    monkeypatch.setattr(suite_runner, "progress_bar",
                        lambda total, desc, initial=0, enabled=True: made.append((total, initial))
                        or real(total, desc, initial=initial, enabled=enabled, stream=io.StringIO()))
    said = []
    pool = _Pool(root)
    suite_runner.run_students([CONFIG, done], root, pool=pool, log=said.append)
    assert said == [f"reused 1 finished student run from {root}",
                    f"resuming {CONFIG.run_name()} from step 200 (its checkpoint)"]
    assert made == [(600, 500)] and pool.closed  # 300 reused and 200 resumed: done before this session
    assert pool.submitted == [CONFIG.run_name()]  # the finished sb3 run is reused without a worker


def test_a_suite_announces_the_step_a_population_resumes_from_not_a_members_newest(killed, monkeypatch):
    """A kill between two members' commits: one member holds a newer checkpoint than the
    other, and the population resumes from the newest step both hold."""
    import shutil

    import craftsuite.suite_runner as suite_runner

    root = killed.parent
    ahead = dataclasses.replace(CONFIG, seed=1)  # the same cell: one population with CONFIG's run
    shutil.copytree(killed, root / ahead.run_name())
    (root / ahead.run_name() / "checkpoint-aside").rename(root / ahead.run_name() / "checkpoint")  # 300 and 200
    made = []
    real = suite_runner.progress_bar
    monkeypatch.setattr(suite_runner, "progress_bar",
                        lambda total, desc, initial=0, enabled=True: made.append((total, initial))
                        or real(total, desc, initial=initial, enabled=enabled, stream=io.StringIO()))
    said, pool = [], _Pool(root)
    suite_runner.run_students([CONFIG, ahead], root, pool=pool, log=said.append)
    assert said == [f"resuming {CONFIG.run_name()} from step 200 (its checkpoint)",
                    f"resuming {ahead.run_name()} from step 200 (its checkpoint)"]  # not 300
    assert made == [(600, 400)] and pool.submitted == [CONFIG.run_name(), ahead.run_name()]


def test_a_workers_prints_never_reach_the_drivers_bar(capsys):
    from craftsuite.suite_runner import _quiet

    with _quiet():
        print("resuming from its checkpoint")
    print("the driver")
    assert capsys.readouterr().out == "the driver\n"


@pytest.mark.slow  # a real transfer, twice, in a subprocess
def test_a_transfer_logged_to_files_writes_lines_and_announces_reuse(tmp_path):
    import subprocess
    import sys

    out = tmp_path / "out"
    command = [sys.executable, "-m", "craftsuite", "transfer", "--suite", "quick", "--tasks", "Reach", "--seeds", "1",
               "--methods", "td3", "--steps", "1001", "--no-video", "--out", str(out)]
    first = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert first.returncode == 0, first.stderr
    assert "\r" not in first.stderr and "1 student runs: 100% (1,001/1,001 steps, " in first.stderr
    again = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    assert f"reused 1 finished student run from {out / 'students'}\n" in again.stdout
