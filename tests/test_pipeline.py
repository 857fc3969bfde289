"""The CLI end to end on a tiny config, the same students on a local Ray instance, and a killed driver."""

import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time
from concurrent.futures import Future
from pathlib import Path
from types import SimpleNamespace

import pytest

from craftsuite import worker_pool
from craftsuite.cli import main
from craftsuite.configs import StudentConfig
from craftsuite.runs import FORMAT, read_csv
from craftsuite.suite_runner import TimeLimitReached, run_students
from craftsuite.suites import SUITES

TINY = '{"learning_starts": 100, "buffer_size": 5000}'


def test_cli_teacher_distill_student_leaderboard_video(tmp_path, capsys, gl_available):
    runs = tmp_path / "runs"
    assert main(["teacher", "BlindCraftsman", "--out", str(runs / "teachers"), "--max-steps", "400",
                 "--eval-every", "200", "--eval-episodes", "2", "--hyper", TINY]) == 0
    [teacher] = (runs / "teachers").iterdir()
    assert main(["distill", str(teacher), "--out", str(tmp_path / "again.npz"),
                 "--draw", str(tmp_path / "values.dot")]) == 0
    assert "dynamic automaton Q-table" in capsys.readouterr().out
    dot = (tmp_path / "values.dot").read_text()
    assert re.search(r'label="[^"]*-?\d+\.\d', dot), "no distilled value printed on an edge"
    for method, table in (("td3-dynamic", ["--table", str(tmp_path / "again.npz")]), ("td3", [])):
        assert main(["student", "BlindCraftsman", "--method", method, *table,
                     "--out", str(runs / "students"), "--steps", "300", "--eval-every", "150",
                     "--eval-episodes", "1", "--hyper", '{"learning_starts": 100}']) == 0
    capsys.readouterr()
    assert main(["leaderboard", str(runs)]) == 0
    out = capsys.readouterr().out
    assert "| td3-dynamic | 1 |" in out and "| td3 | 1 |" in out
    assert (runs / "leaderboard.csv").is_file() and (runs / "curves-BlindCraftsman-Cont.png").is_file()
    if not gl_available:
        pytest.skip(gl_available.reason)
    student = next((runs / "students").glob("*td3-dynamic*"))
    assert main(["video", "CraftSuite/BlindCraftsman-Cont-v0", "--policy", str(student / "model.zip"),
                 "--product", "--out", str(tmp_path / "student.mp4")]) == 0
    assert (tmp_path / "student.mp4").stat().st_size > 1000


def test_cli_errors_name_the_problem(tmp_path, capsys):
    assert main(["student", "BlindCraftsman", "--method", "td3-dynamic", "--out", str(tmp_path)]) == 2
    assert "needs --table" in capsys.readouterr().err
    assert main(["student", "BlindCraftsman", "--method", "td3", "--hyper", "{oops", "--out", str(tmp_path)]) == 2
    assert "--hyper is not JSON" in capsys.readouterr().err
    assert main(["student", "BlindCraftsman", "--method", "td3", "--env", "[10]", "--out", str(tmp_path)]) == 2
    assert "--env must be a JSON object, e.g. '{\"max_episode_steps\": 500}', not '[10]'" in capsys.readouterr().err
    assert main(["transfer", "--suite", "huge", "--out", str(tmp_path)]) == 2
    assert "unknown suite 'huge'" in capsys.readouterr().err
    assert main(["leaderboard", str(tmp_path / "nothing")]) == 2
    assert "no run directory" in capsys.readouterr().err
    assert main(["leaderboard", str(tmp_path), "--page", str(tmp_path / "r.md"), "--out", str(tmp_path)]) == 2
    assert "--page writes the page" in capsys.readouterr().err
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"not a table")
    assert main(["student", "BlindCraftsman", "--table", str(bad), "--out", str(tmp_path)]) == 2
    assert "not a CraftSuite distilled table" in capsys.readouterr().err
    assert main(["transfer", "--methods", "td3-dinamic", "--out", str(tmp_path)]) == 2
    assert "unknown method 'td3-dinamic' (did you mean td3-dynamic" in capsys.readouterr().err
    assert main(["transfer", "--methods", "crm", "--out", str(tmp_path)]) == 2  # a grid method, MuJoCo suite
    assert "no method of crm runs in the worlds Cont (Cont: td3, product-td3" in capsys.readouterr().err
    assert main(["transfer", "--worlds", "Grid10", "--methods", "td3", "--out", str(tmp_path)]) == 2
    assert "no method of td3 runs in the worlds Grid10 (Grid10: dqn, " in capsys.readouterr().err
    assert main(["distill", str(tmp_path), "--out", str(tmp_path / "t.npz")]) == 2
    assert "not a teacher run directory" in capsys.readouterr().err
    # a misspelt world setting is named before the teacher trains, and nothing is written
    assert main(["transfer", "--env", '{"frame_skp": 10}', "--out", str(tmp_path / "t")]) == 2
    assert "frame_skp" in capsys.readouterr().err and not (tmp_path / "t").exists()
    assert main(["transfer", "--td3-hyper", '{"learning_rat": 0.001}', "--out", str(tmp_path / "t")]) == 2
    err = capsys.readouterr().err
    assert "--td3-hyper" in err and "learning_rat" in err and not (tmp_path / "t").exists()
    assert main(["transfer", "--worlds", "Grid10", "--methods", "dqn", "--env", '{"frame_skip": 10}',
                 "--out", str(tmp_path / "t")]) == 2
    assert "these worlds have none: ['Grid10']" in capsys.readouterr().err
    # the kinematic board has TD3 students but not the MuJoCo world's keywords
    assert main(["transfer", "--worlds", "Kinematic", "--env", '{"frame_skip": 10}', "--out", str(tmp_path / "t")]) == 2
    assert ("--env sets the MuJoCo students' world (Cont); these worlds have none: ['Kinematic']"
            in capsys.readouterr().err)


def test_mujoco_keywords_reach_only_the_mujoco_students(tmp_path):
    suite = dataclasses.replace(SUITES["quick"], worlds=("Cont", "Kinematic"), cont_world_kwargs={"frame_skip": 2},
                                td3_hyperparameters={"learning_rate": 5e-4})
    configs = suite.student_configs(tmp_path)
    assert {c.world for c in configs} == {"Cont", "Kinematic"}
    for c in configs:
        assert c.world_kwargs == ({"frame_skip": 2} if c.world == "Cont" else {})
        assert c.hyperparameters["learning_rate"] == 5e-4  # TD3 settings reach both continuous worlds


def test_transfer_flags_reach_the_suite(tmp_path, monkeypatch):
    import craftsuite.suite_runner

    seen = []

    outs = []

    def fake_transfer(suite, out, **_):
        seen.append(suite)
        outs.append(out)
        return craftsuite.suite_runner.TransferResult(Path(out), {}, [], Path(out) / "leaderboard.md", [], None)

    monkeypatch.setattr(craftsuite.suite_runner, "transfer", fake_transfer)
    assert main(["transfer", "--out", str(tmp_path), "--env", '{"frame_skip": 2}',
                 "--td3-hyper", '{"learning_rate": 0.0005}', "--tags", "medium", "--tasks", "Reach"]) == 0
    [suite] = seen
    assert suite.cont_world_kwargs == {"frame_skip": 2}
    assert (suite.tags, suite.tasks) == (("medium",), ("Reach",))
    # over the suite's own TD3 settings (and its learner regime), not replacing them
    assert suite.td3_hyperparameters == SUITES["quick"].td3_hyperparameters
    assert {c.hyperparameters["learning_rate"] for c in suite.student_configs(tmp_path)} == {0.0005}
    assert all(c.hyperparameters["batch_size"] == SUITES["quick"].td3_hyperparameters["batch_size"]
               for c in suite.student_configs(tmp_path))
    # without --out, each suite writes to a directory of its own
    monkeypatch.chdir(tmp_path)
    assert main(["transfer", "--suite", "standard", "--tasks", "Reach", "--worlds", "Grid10", "--methods", "dqn"]) == 0
    assert seen[-1].name == "standard" and outs[-1] == "runs/standard"
    # --seeds N: every cell N, the rungs the suite gives more seeds too
    assert main(["transfer", "--suite", "standard", "--tasks", "ToolHome", "--worlds", "Grid10", "--seeds", "3"]) == 0
    assert {c.seed for c in seen[-1].student_configs(tmp_path)} == {0, 1, 2}


def test_suites_are_well_formed(tmp_path):
    from itertools import product

    from craftsuite.methods import METHODS
    from craftsuite.task_registry import ladder

    assert {"quick", "standard", "paper"} <= set(SUITES)
    quick = SUITES["quick"].student_configs(tmp_path)
    assert [c.task for c in quick][::4] == ["Reach", "FirstTool"]  # the calibration rung, the two-stage one
    assert {c.method for c in quick} == {"td3-dynamic-edges", "td3"}
    assert all(c.world == "Cont" and c.n_envs == SUITES["quick"].td3_n_envs for c in quick)
    teachers = SUITES["quick"].teachers()
    for c in quick:  # a distilled student reads its own rung's teacher's table
        expected = str((tmp_path / teachers[c.task].run_name() / "table.npz").resolve())
        assert c.table == (expected if c.method == "td3-dynamic-edges" else None)
    # quick's TD3 network stays with its TD3 students when the worlds are overridden
    both = dataclasses.replace(SUITES["quick"], worlds=("Cont", "Grid10"), methods=("td3", "dqn"),
                               budgets={**SUITES["quick"].budgets, "Grid": {"easy": 10, "medium": 20}})
    nets = {c.world: c.hyperparameters.get("policy_kwargs") for c in both.student_configs(tmp_path)}
    assert nets == {"Cont": {"net_arch": [64, 64]}, "Grid10": None}
    assert both.teachers() == {}  # no method needs a teacher
    grid_distiller = dataclasses.replace(SUITES["quick"], methods=("td3", "dynamic"))
    assert grid_distiller.teachers() == {}  # `dynamic` needs one, but runs on the grids, not in this suite's world
    # standard and hard: every rung x the paper's methods and baselines and the shaping baseline (each in its
    # world) x 10 seeds, budgets by level or by the rung's own name; the paper suite without shaping
    from craftsuite.suites import PAPER_METHODS, SUITE_METHODS

    standard = SUITES["standard"].student_configs(tmp_path)
    hard = SUITES["hard"].student_configs(tmp_path)
    assert {(c.task, c.method) for c in standard + hard} == set(product([s.name for s in ladder()], SUITE_METHODS))
    assert set(SUITE_METHODS) - set(PAPER_METHODS) == {m for m in METHODS if METHODS[m].shaping}
    assert not any(METHODS[m].shaping for m in SUITES["paper"].methods)
    assert {c.task for c in hard} == {s.name for s in ladder("paper")}
    assert {c.steps for c in hard if c.world == "Cont"} == {1_000_000}  # the paper's tasks at 1M in MuJoCo
    grid = {c.task: c.steps for c in hard if c.world == "Grid10"}  # on Grid10 where DQN from scratch learns them
    assert grid["DungeonQuest"] == grid["BlindCraftsman"] == 50_000
    assert set(grid.values()) <= {50_000, 100_000, 200_000, 500_000, 1_000_000}
    assert set(METHODS) - set(SUITE_METHODS) == {"crm-edges", "td3-crm-edges"}  # the transfer suite's
    transfer = SUITES["transfer"].student_configs(tmp_path)
    assert {c.method for c in transfer} == {"dqn", "dynamic", "crm-edges", "td3", "td3-dynamic", "td3-crm-edges"}
    # every TD3 method of the transfer suite gets the same replay, small enough for CRM's copies
    assert {c.hyperparameters["buffer_size"] for c in transfer if c.world == "Cont"} == {200_000}
    assert {c.table is not None for c in transfer if c.method.endswith("crm-edges")} == {True}
    seeds = {}  # 10 seeds a cell, 20 on Grid10's three cheap middle rungs
    for c in standard:
        seeds.setdefault((c.task, c.world, c.method), set()).add(c.seed)
    middle = {"KeySwordDragon", "ToolHome", "TwoToolsHome"}
    assert {cell: max(s) + 1 for cell, s in seeds.items()} == {
        cell: 20 if cell[1] == "Grid10" and cell[0] in middle else 10 for cell in seeds}
    assert all(s == set(range(max(s) + 1)) for s in seeds.values())
    from craftsuite.ids import world_kind
    from craftsuite.suites import seeds_text

    for each in SUITES.values():  # a misspelt world kind or rung would be silently ignored
        kinds, names = {world_kind(w) for w in each.worlds}, {r.name for r in each.rungs()}
        assert all(kind in kinds and set(by) <= names for kind, by in each.rung_seeds.items()), each.name
    more = SUITES["standard"].rung_seeds
    assert seeds_text(10, more) == "10 seeds a cell, 20 on KeySwordDragon, ToolHome, TwoToolsHome in the grid worlds"
    assert seeds_text(10, more, worlds=["Cont"]) == seeds_text(10, {}) == "10 seeds a cell"  # only what ran
    assert seeds_text(10, more, tasks=["ToolHome", "Reach"]) == "10 seeds a cell, 20 on ToolHome in the grid worlds"
    budgets, specs = SUITES["standard"].budgets, {s.name: s for s in ladder()}
    for c in standard:
        table = budgets["Cont" if c.world == "Cont" else "Grid"]
        assert c.steps == table.get(c.task, table[specs[c.task].level])
    assert {c.steps for c in standard if c.task == "TwoToolsHome" and c.world == "Cont"} == {300_000}
    assert {c.steps for c in standard if c.task == "ToolHome" and c.world == "Cont"} == {250_000}  # its own budget
    grid = {c.task: c.steps for c in standard if c.world == "Grid10" and c.task in ("KeySwordDragon", "ToolHome",
                                                                                        "TwoToolsHome")}
    assert grid == {"KeySwordDragon": 10_000, "ToolHome": 15_000, "TwoToolsHome": 15_000}  # DQN's calibration
    assert {c.steps for c in standard if c.world == "Cont"} != {c.steps for c in standard if c.world == "Grid10"}
    paper = SUITES["paper"].student_configs(tmp_path)
    assert {c.task for c in paper} == {s.name for s in ladder("paper")}
    assert {(c.world, c.method) for c in paper} >= {("Grid10", "crm"), ("Cont", "td3-static")}
    assert not any(c.world == "Cont" and c.method == "dqn" for c in paper)
    # grid students learn one instance of their own, as the paper's did; MuJoCo layouts vary
    assert {c.layout_seed for c in paper if c.world == "Grid10"} == {SUITES["paper"].grid_layout_seed} != {0}
    assert {c.layout_seed for c in paper if c.world == "Cont"} == {None}
    # the MuJoCo world's settings reach the MuJoCo students only
    skipped = dataclasses.replace(both, cont_world_kwargs={"frame_skip": 2})
    assert {c.world: c.env_kwargs for c in skipped.student_configs(tmp_path)} == \
        {"Cont": {"frame_skip": 2}, "Grid10": {"layout_seed": 1}}


def test_suite_selection_errors_name_the_problem(tmp_path):
    quick = SUITES["quick"]
    with pytest.raises(KeyError, match=r"^unknown tag 'hardest' \(did you mean hard\?\); tags: "):
        dataclasses.replace(quick, tags=("hardest",)).student_configs(tmp_path)
    with pytest.raises(ValueError, match="selects no rung"):
        dataclasses.replace(quick, tags=(), tasks=()).student_configs(tmp_path)
    with pytest.raises(ValueError, match="has no Grid budget for Reach's level 'easy'.*--steps N"):
        dataclasses.replace(quick, worlds=("Grid10",), methods=("dqn",)).student_configs(tmp_path)
    with pytest.raises(KeyError, match="unknown method"):
        dataclasses.replace(quick, methods=("td3", "td4")).student_configs(tmp_path)
    # more seeds on a rung: a misspelt kind or rung, or a count that is no count, is named, never ignored
    with pytest.raises(ValueError, match="rung_seeds key 'Grid10' is no world kind; use Grid or Cont"):
        dataclasses.replace(quick, rung_seeds={"Grid10": {"Reach": 20}}).student_configs(tmp_path)
    with pytest.raises(ValueError, match=r"rung_seeds\['Grid'\] is 20; map rung names to seeds"):
        dataclasses.replace(quick, rung_seeds={"Grid": 20}).student_configs(tmp_path)
    with pytest.raises(ValueError,
                       match=r"rung_seeds\['Cont'\] names 'Reech' \(did you mean Reach\?\), which is no registered"):
        dataclasses.replace(quick, rung_seeds={"Cont": {"Reech": 20}}).student_configs(tmp_path)
    with pytest.raises(ValueError, match=r"rung_seeds\['Cont'\]\['Reach'\] is 2.5; give a whole number"):
        dataclasses.replace(quick, rung_seeds={"Cont": {"Reach": 2.5}}).student_configs(tmp_path)
    narrowed = dataclasses.replace(quick, rung_seeds={"Cont": {"KeySwordDragon": 3}})  # a rung not run: allowed
    assert narrowed.student_configs(tmp_path) == quick.student_configs(tmp_path)


@pytest.mark.slow  # a whole suite in a pool of spawned workers
def test_transfer_trains_teachers_in_the_pool_and_writes_board_page_and_provenance(tmp_path, monkeypatch):
    from craftsuite import suite_runner
    from craftsuite.provenance import read
    from craftsuite.reporting.pages import write_results_page
    from craftsuite.suite_runner import transfer

    tiny = dataclasses.replace(SUITES["quick"], tags=("calibration",), tasks=(), seeds=1, student_steps=300,
                               eval_every=150, eval_episodes=1, teacher_max_steps=400, td3_n_envs=2,
                               teacher_hyperparameters={"learning_starts": 100},  # (it must train in 400)
                               td3_hyperparameters={"learning_starts": 100, "policy_kwargs": {"net_arch": [16]}})
    result = transfer(tiny, tmp_path / "out", workers=2, video=False, progress=False, log=lambda *_: None)
    [teacher] = result.teachers.values()
    assert (teacher / "table.npz").is_file()
    results = {json.loads((p / "result.json").read_text())["method"]: json.loads((p / "result.json").read_text())
               for p in result.students}
    assert set(results) == {"td3", "td3-dynamic-edges"}
    for r in results.values():  # budgets in transitions and in gradient updates, 2 envs per update
        assert r["steps"] == 300 and 0 < r["updates"] <= (300 - 100) // 2 + 1
    board = result.leaderboard.read_text()
    assert "## Reach (Cont)" in board and "| 300 / " in board and "- `td3-dynamic-edges`:" in board
    [session] = read(tmp_path / "out")
    assert session["command"] == ("python: craftsuite.suite_runner.transfer(suite 'quick', "
                                  f"out {str(tmp_path / 'out')!r})")
    assert session["machine"] and "torch" in session["versions"]
    page = write_results_page([tmp_path / "out"], tmp_path / "docs" / "results.md")
    text = page.read_text()
    assert "## quick:" in text and "### Reach (Cont)" in text and session["command"] in text
    assert "As last run: rungs tagged calibration; worlds Cont; methods td3, td3-dynamic-edges; 1 seed a cell." in text
    # the runs record their settings and the code that trained them
    record = json.loads((result.students[0] / "config.json").read_text())
    assert record["format"] == FORMAT and record["effective"]["hyperparameters"]["policy_kwargs"]["net_arch"] == [16]
    assert record["provenance"][0]["versions"]["craftsuite"]
    assert "images/results-out/curves-Reach-Cont.png" in text  # named after the directory
    assert (tmp_path / "docs" / "images" / "results-out" / "curves-Reach-Cont.png").is_file()
    transfer(tiny, tmp_path / "out", workers=2, video=False, progress=False, log=lambda *_: None)  # all reused
    assert len(read(tmp_path / "out")) == 2
    # the same transfer again: its scope is still the directory's
    text = write_results_page([tmp_path / "out"], tmp_path / "docs" / "results.md").read_text()
    assert "As last run: rungs tagged calibration" in text and "Gathered from" not in text

    def killed(*args, **kwargs):
        raise KeyboardInterrupt
    monkeypatch.setattr(suite_runner, "run_students", killed)
    with pytest.raises(KeyboardInterrupt):
        transfer(tiny, tmp_path / "out", workers=2, video=False, progress=False, log=lambda *_: None)
    assert [s["seconds"] is None for s in read(tmp_path / "out")] == [False, False, True]
    text = write_results_page([tmp_path / "out"], tmp_path / "docs" / "results.md").read_text()
    assert text.count("min on ") == 2 and text.count("did not finish on ") == 1


class _StaggeredPool:
    """Populations that "finish" one after another: the first at once, each next one a
    second later (its result.json written then), as workers of unequal cells do."""

    processes = 1  # a local pool's: the populations at once

    def __init__(self):
        self.timers, self.aborted = [], False

    def submit(self, job, configs, root, *_):
        import threading
        from concurrent.futures import Future

        future, runs = Future(), [Path(root) / StudentConfig(**c).run_name() for c in configs]

        def finish():
            for run in runs:
                run.mkdir(parents=True, exist_ok=True)
                (run / "result.json").write_text("{}")
            future.set_result([str(run) for run in runs])

        timer = threading.Timer(1.0 * len(self.timers), finish)  # the first at once
        self.timers.append(timer)
        timer.start()
        return future

    def close(self, abort=False):
        self.aborted = self.aborted or abort
        for timer in self.timers:
            timer.cancel()


def test_run_students_hands_over_each_population_as_it_finishes(tmp_path):
    configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=300) for s in (0, 1)]
    handed = []

    def finished(kind, paths):  # with whether the other population had finished by then
        handed.append((kind, [p.name for p in paths], sorted(r.parent.name for r in tmp_path.glob("*/result.json"))))

    run_students(configs, tmp_path, pool=_StaggeredPool(), progress=False, members=1, finished=finished)
    first, second = (c.run_name() for c in configs)
    assert handed == [("students", [first], [first]),  # handed over while the second still trained
                      ("students", [second], sorted([first, second]))]


def test_run_students_puts_the_seeds_still_to_train_in_one_population(tmp_path):
    configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=300) for s in range(5)]
    for c in configs[:3]:  # finished here already (a restored archive, an earlier part)
        (tmp_path / c.run_name()).mkdir()
        (tmp_path / c.run_name() / "result.json").write_text("{}")
    pool, jobs = _StaggeredPool(), []
    submit = pool.submit
    pool.submit = lambda job, configs, *rest: jobs.append([c["seed"] for c in configs]) or submit(job, configs, *rest)
    run_students(configs, tmp_path, pool=pool, progress=False, members=2)
    assert jobs[0] == [3, 4]  # not seeds 2 and 3, then 4 alone


def test_run_students_checks_the_memory_of_the_populations_at_once_and_not_again_in_each(tmp_path, monkeypatch):
    from craftsuite.population import train as population_train

    configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=300) for s in range(5)]
    for c in configs[:3]:  # finished already: their populations train nothing and hold no replay
        (tmp_path / c.run_name()).mkdir()
        (tmp_path / c.run_name() / "result.json").write_text("{}")
    checked, pool, sent = [], _StaggeredPool(), []
    pool.processes = 2
    monkeypatch.setattr(population_train, "warn_if_replays_exceed_memory",
                        lambda jobs, at_once: checked.append(([[c.seed for c in job] for job in jobs], at_once)))
    submit = pool.submit
    pool.submit = lambda job, configs, *rest: sent.append(rest[-1]) or submit(job, configs, *rest)
    run_students(configs, tmp_path, pool=pool, progress=False, members=2)
    assert checked == [([[3, 4]], 2)]  # the seeds still to train, as the pool's 2 processes run them
    assert sent and set(sent) == {False}  # no worker's population warns a second time


def test_a_deadline_stops_the_populations_still_training_and_says_how_many(tmp_path):
    configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=300) for s in (0, 1, 2)]
    handed, pool = [], _StaggeredPool()
    with pytest.raises(TimeLimitReached, match="with 2 of 3 student runs unfinished: those training were stopped"):
        run_students(configs, tmp_path, pool=pool, progress=False, members=1, deadline=time.monotonic() + 0.5,
                     finished=lambda kind, paths: handed.append([p.name for p in paths]))
    assert handed == [[configs[0].run_name()]]  # the one that finished in time, handed over
    assert pool.aborted and not (tmp_path / configs[1].run_name() / "result.json").exists()  # the others stopped
    # a deadline that passes as the last population finishes stops nothing: the runs are done
    [path] = run_students(configs[:1], tmp_path / "again", pool=_StaggeredPool(), progress=False,
                          deadline=time.monotonic() - 1)
    assert (path / "result.json").is_file()


@pytest.mark.slow  # starts a Ray instance
def test_students_on_a_local_ray_instance(tmp_path):
    pytest.importorskip("ray")
    configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=300, eval_every=150, eval_episodes=1,
                             hyperparameters={"learning_starts": 100, "buffer_size": 1000}) for s in (0, 1)]
    paths = run_students(configs, tmp_path, ray="local", progress=False)
    assert [p.name for p in paths] == [c.run_name() for c in configs]
    for p in paths:
        assert json.loads((p / "result.json").read_text())["steps"] == 300
        assert [int(r["step"]) for r in read_csv(p / "evals.csv")] == [150, 300]


class _JoinedRay:
    """The part of Ray the pool uses, as a cluster this process joined (not started): a task
    never finishes on its own, and the refs cancelled are recorded."""

    def __init__(self):
        self.cancelled, self.shut = [], False

    def remote(self, num_cpus):
        def task(function):
            def submit(*args):
                return SimpleNamespace(future=Future)
            return SimpleNamespace(remote=submit)
        return task

    def cancel(self, ref, force=False):
        self.cancelled.append((ref, force))

    def shutdown(self):
        self.shut = True


def test_the_pool_names_the_signal_that_killed_a_worker():
    """A worker killed by a signal (SIGKILL: what the kernel's out-of-memory killer sends)
    breaks the pool; the pool says which signal, for the transfer's exit status."""
    from concurrent.futures.process import BrokenProcessPool

    pool = worker_pool.WorkerPool(1, workers=1)
    try:
        killed = pool.submit(signal.raise_signal, signal.SIGKILL)
        with pytest.raises(BrokenProcessPool):
            killed.result(timeout=300)
    finally:
        pool.close(abort=True)
    assert pool.lost == [signal.SIGKILL]


def _say_started_then_sleep(path) -> None:
    """A job that writes its worker's pid to ``path`` once it runs, then holds the worker ten minutes."""
    Path(path).write_text(str(os.getpid()))
    time.sleep(600)


def _started(path, timeout=120) -> int:
    """The pid a job wrote to ``path`` once it ran (waiting for it ``timeout`` seconds at most)."""
    end = time.monotonic() + timeout
    while not (Path(path).is_file() and Path(path).read_text()):
        assert time.monotonic() < end, f"the job writing {path} did not start in {timeout} s"
        time.sleep(0.05)
    return int(Path(path).read_text())


def test_a_worker_started_for_a_later_job_is_watched_too(monkeypatch, tmp_path):
    """The executor wakes its manager thread before it starts the worker a new job needs; a
    worker started then and killed went unseen until the other worker's job returned (ten
    minutes here, hours in a suite). The pool wakes the thread again: the break is seen. The
    start is slowed here so that the thread surely waits on the old list of workers first."""
    from concurrent.futures.process import BrokenProcessPool

    pool = worker_pool.WorkerPool(2, workers=2)
    start_worker = pool.pool._adjust_process_count
    monkeypatch.setattr(pool.pool, "_adjust_process_count", lambda: (time.sleep(0.5), start_worker()))
    try:
        pool.submit(_say_started_then_sleep, tmp_path / "busy")
        _started(tmp_path / "busy")  # the first worker holds its job: the next needs a second worker
        killed = pool.submit(signal.raise_signal, signal.SIGKILL)
        with pytest.raises(BrokenProcessPool):
            killed.result(timeout=300)
    finally:
        pool.close(abort=True)
    assert pool.lost == [signal.SIGKILL]  # the live worker, stopped by the executor, not counted


def test_an_abort_stops_the_jobs_running_on_two_workers(tmp_path):
    """Two jobs of ten minutes, each running on a worker of its own, are stopped at once by an
    abort, their workers gone (reaped: no pid left) when ``close`` returns."""
    pool = worker_pool.WorkerPool(2, workers=2)
    start = None
    try:
        for name in ("first", "second"):
            pool.submit(_say_started_then_sleep, tmp_path / name)
        pids = {_started(tmp_path / name) for name in ("first", "second")}
        start = time.monotonic()
    finally:
        pool.close(abort=True)
    assert start is not None and time.monotonic() - start < 60 and len(pids) == 2

    def alive(pid):
        try:
            os.kill(pid, 0)  # a zombie, not yet reaped, would count as alive
        except ProcessLookupError:
            return False
        return True
    # (the executor's thread may reap a worker before this process's join does, so which of
    # them did is not asked: multiprocessing's own list can call such a worker alive a moment)
    assert not [pid for pid in pids if alive(pid)]


class _Worker:
    """A worker process as the executor holds it: its sentinel is ready once it has ended,
    and ``join`` reaps it (``code``: the exit code it then shows)."""

    def __init__(self, ended: bool, code=None):
        read, write = os.pipe()
        if ended:
            os.close(write)
        self._open = [read] if ended else [read, write]
        self.sentinel, self.code, self.exitcode, self.joins = read, code, None, 0

    def join(self, timeout=None):
        self.joins, self.exitcode = self.joins + 1, self.code

    def close(self):
        while self._open:
            os.close(self._open.pop())


@pytest.fixture
def worker():
    """Makes ``_Worker(ended, code)``s, their pipes closed after the test."""
    made = []
    yield lambda *args, **kwargs: made.append(_Worker(*args, **kwargs)) or made[-1]
    for each in made:
        each.close()


def _broken_pool(*workers, broken="a child process terminated abruptly"):
    """A ``WorkerPool``'s bookkeeping over a broken executor holding ``workers``, and a job
    failed by the break (no process starts)."""
    from concurrent.futures.process import BrokenProcessPool

    pool = object.__new__(worker_pool.WorkerPool)
    pool.lost, pool._looked = [], False
    pool.pool = SimpleNamespace(_broken=broken, _processes=dict(enumerate(workers)))
    failed = Future()
    failed.set_exception(BrokenProcessPool("a worker died"))
    return pool, failed


def test_a_broken_pool_waits_for_its_dead_worker_to_be_reapable(worker):
    """Under load the executor can see a killed worker's pipe close before the kernel has made
    the worker reapable (its exit code still None): the pool waits for it rather than report
    no signal (which would make a transfer killed for memory exit 1, a status a campaign does
    not resume), and leaves the live worker alone."""
    killed, alive = worker(ended=True, code=-signal.SIGKILL), worker(ended=False)
    pool, failed = _broken_pool(killed, alive)
    pool._note_lost(failed)
    assert pool.lost == [signal.SIGKILL] and killed.joins == 1 and alive.joins == 0


def test_a_pool_broken_without_a_signal_is_looked_at_once_and_at_once(worker):
    """A worker that exited by itself (status 1) names no signal, and the jobs failed with it
    do not each wait for the live workers."""
    exited = worker(ended=True, code=1)
    pool, failed = _broken_pool(exited, worker(ended=False))
    start = time.monotonic()
    for _ in range(5):
        pool._note_lost(failed)
    assert pool.lost == [] and exited.joins == 1 and time.monotonic() - start < worker_pool.LOST_WAIT


def test_a_jobs_own_broken_pool_error_is_not_a_break(worker):
    """A job that raised BrokenProcessPool itself, its pool whole, leaves the workers unread."""
    killed = worker(ended=True, code=-signal.SIGKILL)
    pool, failed = _broken_pool(killed, broken=False)
    pool._note_lost(failed)
    assert pool.lost == [] and killed.joins == 0 and not pool._looked


def test_an_abort_cancels_the_tasks_sent_to_a_joined_ray_cluster(monkeypatch):
    """A cluster joined at an address outlives the driver: an abort (a failed job, the time
    limit, an interrupt) has to stop its tasks by name, and leaves the cluster up."""
    ray = _JoinedRay()
    monkeypatch.setattr(worker_pool, "connect_ray", lambda address: (ray, False))
    pool = worker_pool.WorkerPool(2, ray="auto")
    pool.submit(print, "a")
    pool.submit(print, "b")
    pool.close()  # waiting for the jobs cancels nothing
    assert ray.cancelled == []
    pool.close(abort=True)
    assert len(ray.cancelled) == 2 and all(force for _, force in ray.cancelled)
    assert not ray.shut  # someone else's cluster: not shut down


@pytest.mark.slow  # starts a Ray instance
def test_the_time_limit_stops_a_student_on_a_ray_cluster_it_joined(tmp_path):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=1, include_dashboard=False, log_to_driver=False)  # as a cluster joined: it outlives the pool
    # the worker imports torch and the package before it takes the run's lock: minutes on a loaded machine
    try:
        config = StudentConfig(method="dqn", world="Grid7", seed=0, steps=1_000_000, eval_every=100_000,
                               hyperparameters={"learning_starts": 100, "buffer_size": 1000})
        lock = tmp_path / config.run_name() / ".lock"
        with pytest.raises(TimeLimitReached):
            run_students([config], tmp_path, ray="auto", progress=False, deadline=time.monotonic() + 150)
        owner = lock.read_text().split() if lock.exists() else []
        assert len(owner) == 2, f"the student did not start on Ray before the time limit: {sorted(tmp_path.rglob('*'))}"
        pid = int(owner[1])
        deadline = time.time() + 30
        while _alive(pid) and time.time() < deadline:
            time.sleep(0.2)
        assert not _alive(pid), "the Ray task trained on after the time limit"
        assert not (tmp_path / config.run_name() / "result.json").exists()  # stopped mid-run: resumable
    finally:
        ray.shutdown()


_DRIVER = """
import sys
from craftsuite.configs import StudentConfig
from craftsuite.suite_runner import run_students
configs = [StudentConfig(method="dqn", world="Grid7", seed=s, steps=1_000_000, eval_every=100_000,
                         hyperparameters={"learning_starts": 100, "buffer_size": 1000}) for s in (0, 1)]
run_students(configs, sys.argv[1], workers=2, progress=False)
"""


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, IndexError):
        return False
    return state not in ("Z", "X")  # an orphaned zombie waits for a reaper that may never come


@pytest.mark.slow  # spawns a driver and its workers, waits up to 120 s for them
def test_killing_the_driver_stops_its_student_processes(tmp_path):
    driver = subprocess.Popen([sys.executable, "-c", _DRIVER, str(tmp_path)])
    workers = []
    try:
        deadline = time.time() + 120
        while time.time() < deadline and len(workers) < 2:
            time.sleep(0.2)
            locks = [p.read_text().split() for p in tmp_path.glob("*/.lock")]
            workers = [int(lock[1]) for lock in locks if len(lock) == 2]
        assert len(workers) == 2, "the two students did not start in 120 s"
        assert all(_alive(pid) for pid in workers)
        driver.send_signal(signal.SIGTERM)  # no handler: the driver dies at once, as under `kill`
        driver.wait(30)
        deadline = time.time() + 30
        while time.time() < deadline and any(_alive(pid) for pid in workers):
            time.sleep(0.2)
        assert not any(_alive(pid) for pid in workers), "student processes outlived their driver"
    finally:
        driver.kill()
        for pid in workers:
            if _alive(pid):
                os.kill(pid, signal.SIGKILL)
    assert not any(tmp_path.glob("*/result.json"))  # killed mid-run: both stay resumable


@pytest.mark.slow  # spawned workers
def test_a_failing_student_stops_the_others_at_once(tmp_path):
    """A worker's error surfaces when it happens, and the other students are stopped (they
    resume when asked for again), rather than after they have run their budgets."""
    long = StudentConfig(method="dqn", world="Grid7", seed=0, steps=1_000_000, eval_every=100_000,
                         hyperparameters={"learning_starts": 100, "buffer_size": 1000})
    broken = StudentConfig(method="dynamic", world="Grid7", seed=0, steps=1_000, table=str(tmp_path / "none.npz"))
    start = time.time()
    with pytest.raises(Exception, match="none.npz"):
        run_students([long, broken], tmp_path, workers=2, progress=False)
    assert time.time() - start < 120  # the long one alone would take many minutes
    lock = tmp_path / long.run_name() / ".lock"
    pid = int(lock.read_text().split()[1]) if lock.exists() and len(lock.read_text().split()) == 2 else None
    deadline = time.time() + 10
    while pid is not None and _alive(pid) and time.time() < deadline:
        time.sleep(0.2)
    assert pid is None or not _alive(pid)
    assert not (tmp_path / long.run_name() / "result.json").exists()



@pytest.mark.slow  # two transfers in pools of spawned workers
def test_a_suite_accumulates_in_the_archive_and_nothing_trains_twice(tmp_path):
    from craftsuite.provenance import read
    from craftsuite.suite_runner import transfer

    tiny = dataclasses.replace(SUITES["quick"], tags=("calibration",), tasks=(), seeds=2, student_steps=300,
                               eval_every=150, eval_episodes=1, teacher_max_steps=400, td3_n_envs=2,
                               teacher_hyperparameters={"learning_starts": 100},  # (it must train in 400)
                               td3_hyperparameters={"learning_starts": 100, "policy_kwargs": {"net_arch": [16]}})
    said = []
    first = transfer(tiny, tmp_path / "here", workers=2, video=False, progress=False, log=said.append,
                     archive=tmp_path / "results")
    store = tmp_path / "results" / "quick"
    kept = sorted(p.name for p in (store / "students").iterdir())
    assert kept == sorted(p.name for p in first.students) and len(kept) == 4
    assert not list(store.rglob("*.zip")) and not list(store.rglob("checkpoint*"))
    assert len(list((store / "teachers").glob("*/table.npz"))) == 1
    # another machine, an empty output directory: every run comes from the archive, none trains
    said.clear()
    second = transfer(tiny, tmp_path / "elsewhere", workers=2, video=True, progress=False, log=said.append,
                      archive=tmp_path / "results")
    assert "4 of 4 student runs and 1 of 1 teachers copied from it" in " ".join(said)
    assert all(not (p / "model.zip").exists() for p in second.students)
    assert second.video is None and any(s.startswith("no video: the best student") for s in said)
    assert [json.loads((p / "result.json").read_text()) for p in second.students] == \
        [json.loads((p / "result.json").read_text()) for p in first.students]
    # the archive's record of the sessions holds the one that trained, once: the second, which
    # trained and kept nothing, is on record in its own output directory only
    [session] = read(store)
    assert session["seconds"] is not None and "out '" + str(tmp_path / "here") in session["command"]
    assert [s["seconds"] is not None for s in read(tmp_path / "elsewhere")] == [True]
