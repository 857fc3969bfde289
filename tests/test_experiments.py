"""Every research folder in experiments/ says what it asked and found, and its scripts import."""

from __future__ import annotations

import importlib.util
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest


EXPERIMENTS = sorted(p for p in (Path(__file__).resolve().parents[1] / "experiments").iterdir() if p.is_dir())


def test_there_are_experiments():
    assert EXPERIMENTS


@pytest.mark.parametrize("folder", EXPERIMENTS, ids=lambda p: p.name)
def test_each_experiment_has_a_readme_with_question_date_commit_command_conclusion(folder):
    readme = (folder / "README.md").read_text()
    for part in ("**Question**", "**Date**", "**Commit**", "**Conclusion**", "```bash"):
        assert part in readme, f"{folder.name}/README.md lacks {part}"


@pytest.mark.parametrize("script", [s for f in EXPERIMENTS for s in sorted(f.glob("*.py"))],
                         ids=lambda p: f"{p.parent.name}/{p.name}")
def test_each_experiment_script_imports(script, monkeypatch):
    monkeypatch.syspath_prepend(str(script.parent))  # scripts import their neighbours, as when run there
    spec = importlib.util.spec_from_file_location(f"experiment_{script.parent.name}_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    try:  # (a script's own method rows go with the test: conftest)
        spec.loader.exec_module(module)
        assert callable(getattr(module, "main", None)), f"{script} has no main()"
    finally:
        sys.modules.pop(spec.name, None)


def _load(script: Path):
    spec = importlib.util.spec_from_file_location(f"experiment_{script.parent.name}_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_learner_regime_wave_3_combines_wave_2s_winners_beside_wave_1s():
    run = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "run.py")
    settings = run.wave_3("Cont", 3, ["layernorm", "gaussian"])
    assert settings == {"n3-layernorm-gaussian": {"n_steps": 3, "layer_norm": True,
                                                  "action_noise": {"type": "normal", "sigma": 0.3}},
                        "n3": {"n_steps": 3}}
    # the combination is the incumbent: wave 1's winner must beat it by the rule
    assert run.factors(3, "Cont", 3, ["layernorm", "gaussian"]) == [["n3-layernorm-gaussian", "n3"]]
    assert run.factors(3, "Grid10", 3, []) == []  # no wave-2 winner: nothing to confirm
    with pytest.raises(SystemExit, match="Grid10 has no wave-2 setting \\['gaussian'\\]"):
        run.wave_3("Grid10", 3, ["gaussian"])


def test_the_learner_regime_budget_rule_reads_the_curve_as_fixed():
    budgets = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "budgets.py")
    curve = [(100_000, 0.0), (200_000, 0.35), (300_000, 0.55), (400_000, 0.9)]
    assert budgets.choose(curve, 400_000) == (300_000, "mean 0.55 at 300,000")
    assert budgets.choose(curve, 250_000)[0] == 200_000  # never beyond today's budget
    assert budgets.choose([(100_000, 0.1), (200_000, 0.2)], 200_000)[0] == 200_000  # below the band: kept
    assert budgets.choose([(100_000, 0.1), (200_000, 0.9)], 200_000)[0] == 100_000  # jumps past it


def test_the_hard_grid_budget_rule_takes_the_first_candidate_that_learns():
    rule = _load(Path(__file__).resolve().parents[1] / "experiments" / "suite-campaign" / "grid_budgets.py")
    assert rule.choose({50_000: 1.0}) == 50_000
    assert rule.choose({50_000: 0.4, 100_000: 0.8, 200_000: 1.0}) == 100_000  # 0.8 counts as learned
    assert rule.choose({50_000: 0.4, 100_000: 0.79}) == rule.FALLBACK == 1_000_000  # none learns: 1M


def test_the_learner_regime_grid_rule_takes_the_largest_in_the_zone_else_the_nearest():
    budgets = _load(Path(__file__).resolve().parents[1] / "experiments" / "learner-regime" / "budgets.py")
    assert budgets.grid_choice({10_000: 0.31, 15_000: 0.74, 20_000: 0.78, 30_000: 1.0})[0] == 20_000
    assert budgets.grid_choice({10_000: 0.9, 15_000: 1.0})[0] == 10_000  # none inside: the nearest
    assert budgets.grid_choice({10_000: 0.85, 15_000: 0.85})[0] == 10_000  # a tie: the smaller budget


PART = Path(__file__).resolve().parents[1] / "experiments" / "suite-campaign" / "part.sh"


def _part(tmp_path, queue_text: str, cutoff: str | None = None, run=subprocess.run, **kwargs):
    """Runs part.sh over ``queue_text`` with a stand-in python that prints its command line and
    the status part.sh wrote for it (and exits as a transfer its time limit stopped where the
    line says ``--stops``, fails where it says ``--fails``, is killed by SIGKILL where it says
    ``--killed``; waits until the file HOLD names exists, where that is set); by
    default its cut-off is this time tomorrow, in the dated form a cut-off past midnight takes.
    ``run`` (subprocess.Popen: in the background) and ``kwargs`` go to the process."""
    from craftsuite.cli import TIME_LIMIT_STATUS
    cutoff = cutoff or time.strftime("%Y-%m-%d %H:%M", time.gmtime(time.time() + 86_400))
    stub = tmp_path / "python"
    stub.write_text('#!/bin/sh\necho "pwd=$PWD commit=$CRAFTSUITE_COMMIT $*"\n'
                    'for a; do last=$a; done; echo "status=$(cat "$last.status")"\n'  # --out OUT/NAME last
                    'while [ -n "$HOLD" ] && [ ! -e "$HOLD" ]; do sleep 0.05; done\n'
                    f'case "$*" in *--stops*) exit {TIME_LIMIT_STATUS};; *--fails*) exit 1;; *--killed*) kill -9 $$;; '
                    'esac\n')
    stub.chmod(0o755)
    queue = tmp_path / "A.queue"
    queue.write_text(queue_text)
    env = {**os.environ, "PYTHON": str(stub), **kwargs.pop("env", {})}
    if run is subprocess.run:
        kwargs = {"capture_output": True, "text": True, "timeout": 60} | kwargs
    return run(["bash", str(PART), str(PART.parents[2]), cutoff, "out", str(queue)], cwd=tmp_path, env=env, **kwargs)


def test_a_campaign_part_runs_its_queue_in_order_and_skips_what_the_time_left_cannot_cover(tmp_path):
    done = _part(tmp_path, "# seeds 20-34\nfirst 0 --suite hard --tasks GoldMine\n"
                           "long 100000 --suite hard --tasks DiamondMine\nsecond 0 --suite standard --workers 2\n")
    assert done.returncode == 0, done.stderr
    said = [line.split(" ", 1)[1] for line in done.stdout.splitlines()]
    assert [s.split(":")[0] for s in said] == ["first", "first", "long", "second", "second", "queue done"]
    assert "skipped" in said[2] and "needs 100000" in said[2]
    out = tmp_path / "out"
    first = (out / "first.log").read_text()
    commit = subprocess.run(["git", "-C", str(PART.parents[2]), "rev-parse", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    assert f"pwd={PART.parents[2]} commit={commit} -m craftsuite transfer --workers 1 --suite hard --tasks GoldMine " \
        in first
    assert f"--archive {tmp_path / 'results'} --out {out / 'first'}" in first and "--time-limit " in first
    assert not (out / "long.log").exists() and (out / "long.status").read_text() == "skipped\n"
    assert (out / "second.status").read_text() == "exit 0\n"
    # a line's own --workers comes after part.sh's one core, so the transfer takes it (argparse keeps the last)
    assert "transfer --workers 1 --suite standard --workers 2 --no-video " in (out / "second.log").read_text()
    # run again over an amended queue: only the line not yet started runs
    again = _part(tmp_path, "first 0 --suite hard\nlong 0 --suite hard\nsecond 0 --suite standard\nthird 0 --x\n")
    ran = [line.split(" ", 1)[1].split(":")[0] for line in again.stdout.splitlines()]
    assert ran == ["third", "third", "queue done"]


def test_a_campaign_part_resumes_a_transfer_its_cut_off_stopped_in_its_next_call(tmp_path):
    def said(done):
        assert done.returncode == 0, done.stderr
        return [line.split(" ", 1)[1] for line in done.stdout.splitlines()]

    queue = "long 0 --suite hard --stops\nshort 0 --suite standard\n"
    first = said(_part(tmp_path, queue))
    assert [s.split(",")[0] for s in first] == ["long: start", "long: exit 3", "short: start", "short: exit 0",
                                                "queue done"]
    out = tmp_path / "out"
    # the next call resumes the stopped one first (before a line never started), once, and
    # leaves the finished one alone
    again = said(_part(tmp_path, "short 0 --suite standard\nnew 0 --x\nlong 0 --suite hard --stops\n"))
    assert [s.split(",")[0] for s in again] == ["long: resume", "long: exit 3", "new: start", "new: exit 0",
                                                "queue done"]
    log = (out / "long.log").read_text()
    assert log.count("== part.sh: start ") == 1 and log.count("== part.sh: resume ") == 1
    assert log.count("-m craftsuite transfer --workers 1 --suite hard --stops") == 2  # the first call's lines kept
    # one the time left cannot cover is not resumed, and stays resumable
    late = said(_part(tmp_path, "long 100000 --suite hard --stops\n"))
    assert late[0].startswith("long: not resumed") and late[0].endswith("needs 100000")
    assert (out / "long.status").read_text() == "exit 3\n" and (out / "long.log").read_text() == log


def test_a_campaign_part_resumes_a_transfer_killed_by_a_signal_but_not_one_that_failed(tmp_path):
    def said(done):
        assert done.returncode == 0, done.stderr
        return [line.split(" ", 1)[1].split(",")[0] for line in done.stdout.splitlines()]

    queue = "oom 0 --suite hard --killed\nbug 0 --suite hard --fails\n"
    assert said(_part(tmp_path, queue)) == ["oom: start", "oom: exit 137", "bug: start", "bug: exit 1", "queue done"]
    # the next call takes up the one killed (as the kernel kills for memory), once a call, and
    # leaves the one that failed on its own to whoever reads its log
    assert said(_part(tmp_path, queue)) == ["oom: resume", "oom: exit 137", "queue done"]
    assert (tmp_path / "out" / "bug.log").read_text().count("== part.sh: ") == 1


def test_a_campaign_part_refuses_a_queue_line_without_minutes_and_a_cut_off_not_ahead(tmp_path):
    bad = _part(tmp_path, "first soon --suite hard\n")
    assert bad.returncode == 2 and "line first: MINUTES 'soon' is not a whole number" in bad.stderr
    assert not (tmp_path / "out" / "first.status").exists()
    late = _part(tmp_path, "first 0 --suite hard\n", cutoff="quarter past")
    assert late.returncode == 2 and "give it as HH:MM" in late.stderr and not (tmp_path / "out").exists()
    past = _part(tmp_path, "first 0 --suite hard\n", cutoff="00:00")
    assert past.returncode == 2 and "has passed" in past.stderr and "YYYY-MM-DD HH:MM" in past.stderr
    assert not (tmp_path / "out").exists()


def test_a_second_campaign_part_over_the_same_out_is_refused_while_the_first_runs(tmp_path):
    if shutil.which("flock") is None:
        pytest.skip("part.sh locks OUT with flock (util-linux); without it the lock is not taken")
    hold, out = tmp_path / "go", tmp_path / "out"
    first = _part(tmp_path, "slow 0 --x\n", run=subprocess.Popen, env={"HOLD": str(hold)},
                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        for _ in range(600):  # the first has started its transfer
            if (out / "slow.status").exists() and (out / "slow.status").read_text().startswith("started"):
                break
            time.sleep(0.05)
        second = _part(tmp_path, "slow 0 --x\nother 0 --x\n")
        assert second.returncode == 2 and "another part.sh runs over OUT" in second.stderr
        assert not (out / "other.status").exists()
        # the lock is part.sh's own: killed alone, the transfer it left running holds none, and the
        # next call runs the other lines and leaves that one to its transfer
        first.kill()
        first.wait(timeout=60)
        third = _part(tmp_path, "slow 0 --x\nother 0 --x\n")
        assert third.returncode == 0, third.stderr
        assert (out / "other.status").read_text() == "exit 0\n"
        assert (out / "slow.status").read_text().startswith("started")
    finally:
        hold.touch()


def test_a_campaign_part_resumes_a_transfer_whose_part_sh_was_interrupted_and_leaves_a_running_one(tmp_path):
    boot = Path("/proc/sys/kernel/random/boot_id")
    if not boot.exists():
        pytest.skip("needs Linux's /proc")
    out = tmp_path / "out"
    out.mkdir()
    this_boot = boot.read_text().strip()

    def started(pid, start=None, on=this_boot):  # a status as part.sh writes it
        start = start or Path(f"/proc/{pid}/stat").read_text().rsplit(") ", 1)[1].split()[19]
        return f"started {pid} {start} {on}\n"

    gone = subprocess.run(["sh", "-c", "echo $$"], capture_output=True, text=True).stdout.strip()
    statuses = {"killed": started(gone, start="1"),  # its part.sh died
                "rebooted": started(os.getpid(), on="another-boot"),  # a PID of an earlier boot
                "reused": started(os.getpid(), start="1"),  # a PID another process took since
                "running": started(os.getpid()),  # its part.sh still runs
                "orphan+1": started(gone, start="1"),  # its part.sh died, its transfer runs on
                "old": "started\n"}  # an older part.sh's: nothing tells whether it runs
    for name, status in statuses.items():
        (out / f"{name}.status").write_text(status)
    orphan = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)", "--out", str(out / "orphan+1")])
    try:
        done = _part(tmp_path, "".join(f"{name} 0 --x\n" for name in statuses))
    finally:
        orphan.kill()
    assert done.returncode == 0, done.stderr
    said = [line.split(" ", 1)[1].split(",")[0] for line in done.stdout.splitlines()]
    assert said == ["killed: resume", "killed: exit 0", "rebooted: resume", "rebooted: exit 0",
                    "reused: resume", "reused: exit 0", "queue done"]
    for name in ("running", "orphan+1", "old"):  # left as they were
        assert (out / f"{name}.status").read_text() == statuses[name] and not (out / f"{name}.log").exists()
    assert (out / "killed.status").read_text() == "exit 0\n"
    # while its transfer ran, the status named the part.sh that ran it, as the next call reads it
    assert re.search(rf"^status=started [0-9]+ [0-9]+ {this_boot}$",
                     (out / "killed.log").read_text(), re.M)


LAND = PART.with_name("land.sh")


def _watcher_root(tmp_path, docs: str = "echo rebuilt > pages.txt"):
    """A project root for land.sh (results/, a Makefile whose docs target runs ``docs``), its
    OUT folder, and a stand-in python that logs its command line and fails for a line named bad."""
    (tmp_path / "results").mkdir()
    (tmp_path / "Makefile").write_text(f"docs:\n\t{docs}\n")
    out = tmp_path / "C"
    out.mkdir()
    stub = tmp_path / "python"
    stub.write_text(f'#!/bin/sh\necho "$*" >> {tmp_path / "calls"}\necho kept\n'
                    'case "$*" in */bad\\ *) exit 1;; esac\n')
    stub.chmod(0o755)
    return out, {**os.environ, "PYTHON": str(stub), "LAND_POLL": "0.05"}


def _said(stdout: str) -> list[str]:
    return [re.sub(r"^\d\d:\d\d:\d\d ", "", line) for line in stdout.splitlines()]  # less its time


def test_the_watcher_archives_each_ended_line_in_order_then_rebuilds_the_pages(tmp_path):
    out, env = _watcher_root(tmp_path)
    for name, status in (("a", "exit 0"), ("b", "skipped"), ("bad", "exit 1")):
        (out / f"{name}.status").write_text(status + "\n")
    watcher = subprocess.Popen(["bash", str(LAND), str(out), "hard", "a", "b", "bad", "c"], cwd=tmp_path,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    time.sleep(0.5)  # c: stopped by the cut-off while the watcher waits for it
    (out / "c.status").write_text("exit 3\n")
    stdout, stderr = watcher.communicate(timeout=60)
    assert watcher.returncode == 0, stderr
    assert (tmp_path / "calls").read_text().splitlines() == [f"-m craftsuite archive {out / n} --suite hard"
                                                             for n in ("a", "bad", "c")]
    said = _said(stdout)
    assert said[:6] == ["a: exit 0", "kept", "a: archived", "b: skipped", "bad: exit 1", "kept"]
    assert said[6] == "bad: NOT archived (craftsuite archive failed: its lines above)" and said[7] == "c: exit 3"
    assert said[-1].startswith("pages rebuilt (make docs exit 0") and (tmp_path / "pages.txt").exists()
    again = subprocess.run(["bash", str(LAND), str(out), "hard", "a"], cwd=tmp_path, capture_output=True, text=True,
                           timeout=60, env={**env, "LAND_DOCS": "0"})
    assert again.returncode == 0 and "pages rebuilt" not in again.stdout  # one of several watchers


def test_the_watcher_waits_for_a_resumed_line_and_says_a_failed_rebuild(tmp_path):
    out, env = _watcher_root(tmp_path, docs="false")
    (out / "a.status").write_text("exit 3\n")  # an earlier part's cut-off: part.sh resumes it
    watcher = subprocess.Popen(["bash", str(LAND), str(out), "hard", "a"], cwd=tmp_path, stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True, env=env)
    time.sleep(0.5)
    assert watcher.poll() is None and not (tmp_path / "calls").exists()  # still waiting: not archived half-done
    (out / "a.status").write_text("exit 0\n")  # the resume finished it
    stdout, _ = watcher.communicate(timeout=60)
    said = _said(stdout)
    assert said[0] == "a: exit 0" and said[-1].startswith("pages rebuilt (make docs exit 2")


@pytest.mark.parametrize("args, where, message", [
    ([], "root", "usage: land.sh OUT SUITE NAME"),
    (["nowhere", "hard", "a"], "root", "no OUT directory"),
    (["C", "hard", "a"], "elsewhere", "run it from the project root"),
])
def test_the_watcher_refuses_a_call_it_cannot_serve_in_one_line(tmp_path, args, where, message):
    (tmp_path / "root" / "results").mkdir(parents=True)
    (tmp_path / "root" / "Makefile").write_text("")
    (tmp_path / "root" / "C").mkdir()
    (tmp_path / "elsewhere").mkdir()
    done = subprocess.run(["bash", str(LAND), *args], cwd=tmp_path / where, capture_output=True, text=True, timeout=60)
    assert done.returncode == 2 and message in done.stderr and len(done.stderr.splitlines()) == 1
