"""Success as completion: the kinematic board's tasks where acceptance and completion part,
and records that counted acceptance, re-read when archived and never resumed."""

from __future__ import annotations

import gzip
import json
import shutil

import gymnasium as gym
import numpy as np
import pytest

import craftsuite  # noqa: F401  (registers the ids)
from craftsuite import archive
from craftsuite.completion import needs_reread, reread, reread_in_place
from craftsuite.configs import StudentConfig
from craftsuite.envs.tiles import BoardRules
from craftsuite.labelling import Labeller
from craftsuite.runs import (EPISODE_CORE, EVAL_FIELDS, RunDir, RunError, read_config, read_csv, record_key, settings,
                             write_csv)
from craftsuite.task_registry import resolve_task

ENDING = ("BlindCraftsman", "DungeonQuest", "GoldMine")  # the tasks whose board has a tile that ends the episode


def acceptance_completes(task: str) -> bool:
    spec = resolve_task(task)
    return BoardRules(spec).acceptance_completes(spec.automaton, Labeller(spec, spec.automaton.propositions))


@pytest.mark.parametrize("task", ENDING)
def test_the_board_says_where_acceptance_is_completion_as_random_play_shows(task):
    """Where the check says acceptance completes, random play never accepts on a step that
    does not end the episode; where it does not (home labelled by its cell), play does."""
    n = 200
    env = gym.make_vec(f"CraftSuite/{task}-Kinematic-v0", num_envs=n, vectorization_mode="vector_entry_point",
                       autoreset_mode="SameStep")
    accepting = env.automaton.accepting.astype(bool)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    early = 0  # steps where the automaton accepts and the episode goes on
    for _ in range(1000):
        _, _, term, trunc, info = env.step(rng.uniform(-1, 1, (n, 2)))
        w2 = info["transition"][:, 2]
        early += int((accepting[w2] & ~term).sum())
    assert (early == 0) == acceptance_completes(task), early
    assert acceptance_completes(task) == (task == "DungeonQuest")


def record(task="BlindCraftsman", fmt=2):
    return {"task": task, "format": fmt,
            "effective": {"world": {"id": f"CraftSuite/{task}-Kinematic-v0", "kwargs": {}}}}


def test_a_record_that_counted_acceptance_is_re_read_as_completion():
    episodes = [{"step": 1, "return": 90.0, "length": 400, "success": 1},  # completed
                {"step": 2, "return": -99.0, "length": 1000, "success": 1},  # accepted, then cut at the limit
                {"step": 3, "return": -99.0, "length": 1000, "success": 0}]
    evals = [{"step": 10, "success": 0.0, "return": -1.0, "episodes": 20, "length": 500.0},
             {"step": 20, "success": 0.5, "return": -1.0, "episodes": 20, "length": 1000.0}]  # every one cut
    eps, evs = reread(record(), episodes, evals)
    assert [e["success"] for e in eps] == [1, 0, 0] and [e["success"] for e in evs] == [0.0, 0.0]
    assert [e["length"] for e in eps] == [400, 1000, 1000]  # the rest as it was
    # an evaluation with acceptances and early ends: which completed is not in the record
    with pytest.raises(RunError, match=r"evaluation at step 30 counted acceptance .*train the run again$"):
        reread(record(), [], [{"step": 30, "success": 0.5, "return": 0.0, "episodes": 20, "length": 700.0}])
    # this format's records, other worlds, and tasks whose acceptance is completion: as they are
    for other in (record(fmt=3), record("DungeonQuest"), {**record(), "effective": {"world": {
            "id": "CraftSuite/BlindCraftsman-Cont-v0", "kwargs": {}}}}):
        assert not needs_reread(other) and reread(other, episodes, evals) == (episodes, evals)


def _old_kinematic_run(root, name="student-BlindCraftsman-Kinematic-td3-s0"):
    config = {**record(), "world": "Kinematic", "method": "td3", "seed": 0, "steps": 2000,
              "provenance": [{"commit": "abc"}]}
    run = root / f"{name}-{record_key(config)}"
    run.mkdir(parents=True)
    (run / "config.json").write_text(json.dumps(config))
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": 2000, "success": 0.0, "return": -99.0, "episodes": 20,
                                               "length": 1000.0}])
    # a record of format 2 predates episodes.csv's seen and states
    write_csv(run / "episodes.csv", EPISODE_CORE, [{"step": 1000, "return": -99.0, "length": 1000, "success": 1},
                                                   {"step": 1400, "return": 60.0, "length": 400, "success": 1}])
    (run / "result.json").write_text(json.dumps({"kind": "student", "steps": 2000}))
    return run


def test_archiving_a_record_that_counted_acceptance_re_reads_it_under_its_key(tmp_path):
    run = _old_kinematic_run(tmp_path / "out" / "students")
    kept = archive.keep(run, tmp_path / "results" / "paper", "students")
    assert kept.name == run.name and archive.check_record(kept) is None  # the same run key: still usable
    assert [int(r["success"]) for r in read_csv(kept / "episodes.csv")] == [0, 1]
    assert list(read_csv(kept / "episodes.csv")[0]) == list(EPISODE_CORE)  # its own columns, no empty new ones
    config, result = (json.loads((kept / f).read_text()) for f in ("config.json", "result.json"))
    assert config["format"] == 3 and "re-read as completion" in result["success_reread"]
    assert not needs_reread(config)
    assert [int(r["success"]) for r in read_csv(run / "episodes.csv")] == [1, 1]  # the source is left as it was
    assert not list(kept.parent.glob(".*"))  # nothing half-built left beside it


def test_a_run_that_counted_acceptance_is_not_resumed(tmp_path):
    config = StudentConfig(task="BlindCraftsman", method="td3", world="Kinematic", steps=500)
    path = tmp_path / "r"
    path.mkdir()
    saved = {**json.loads(json.dumps(settings(config))), "format": 2, "provenance": []}
    (path / "config.json").write_text(json.dumps(saved))
    with pytest.raises(RunError, match=r"counted the automaton's acceptance \(record format 2\); it is not resumed"):
        with RunDir(path, config):
            pass
    assert json.loads((path / "config.json").read_text())["format"] == 2  # its record untouched


def test_the_board_skips_a_run_that_counted_acceptance_and_says_where_it_is_re_read(tmp_path):
    from craftsuite.reporting.board import build

    _old_kinematic_run(tmp_path / "students")
    board = build(tmp_path / "students")
    assert not board.entries
    [reason] = board.unreadable
    assert "counted the automaton's acceptance" in reason and "craftsuite archive" in reason


def test_a_record_whose_success_cannot_be_re_read_is_not_archived(tmp_path):
    run = _old_kinematic_run(tmp_path / "out" / "students")
    write_csv(run / "evals.csv", EVAL_FIELDS, [{"step": 2000, "success": 0.5, "return": 9.0, "episodes": 20,
                                               "length": 700.0}])  # accepted, some ended early: undecided
    reason = archive.check_record(run)
    assert reason.startswith(str(run)) and "cannot be read from the record" in reason


def test_a_record_that_counted_acceptance_copied_into_the_archive_is_re_read_when_kept_again(tmp_path):
    run = _old_kinematic_run(tmp_path / "out" / "students")
    store = tmp_path / "results" / "paper"
    shutil.copytree(run, store / "students" / run.name)  # copied in by hand, not through the archive
    kept = archive.keep_all(tmp_path / "out", store, {"students": {run.name}}, log=pytest.fail)
    assert kept["students"] == 1 and not needs_reread(read_config(store / "students" / run.name))
    # kept once, the same source is the archive's already: not kept again
    assert archive.keep_all(tmp_path / "out", store, {"students": {run.name}}, log=pytest.fail)["students"] == 0
    assert archive.add(archive.scan(tmp_path / "out"), store)["students"] == 0


def test_a_record_that_cannot_be_re_read_is_named_and_the_others_are_kept(tmp_path):
    bad = _old_kinematic_run(tmp_path / "out" / "students", name="student-BlindCraftsman-Kinematic-td3-s0")
    write_csv(bad / "evals.csv", EVAL_FIELDS, [{"step": 2000, "success": 0.5, "return": 9.0, "episodes": 20,
                                               "length": 700.0}])
    good = _old_kinematic_run(tmp_path / "out" / "students", name="student-BlindCraftsman-Kinematic-td3-s1")
    said = []
    kept = archive.keep_all(tmp_path / "out", tmp_path / "store", {"students": {bad.name, good.name}},
                            log=said.append)
    assert kept["students"] == 1 and (tmp_path / "store" / "students" / good.name).is_dir()
    assert not (tmp_path / "store" / "students" / bad.name).exists()
    [line] = said
    assert "not kept" in line and "cannot be read from the record" in line


def test_a_damaged_log_of_a_record_that_counted_acceptance_is_a_reason_not_a_crash(tmp_path):
    run = _old_kinematic_run(tmp_path / "out" / "students")
    (run / "episodes.csv").unlink()
    (run / "episodes.csv.gz").write_bytes(gzip.compress(b"step,return,length,success\n1,2,3,1\n")[:-12])  # torn
    reason = archive.check_record(run)
    assert reason and "episodes.csv" in reason and "does not read as a run's log" in reason


def test_transfer_re_reads_finished_runs_that_counted_acceptance_and_refuses_unfinished_ones(tmp_path):
    from craftsuite.suite_runner import _counting_acceptance

    finished = _old_kinematic_run(tmp_path / "students", name="student-BlindCraftsman-Kinematic-td3-s0")
    assert _counting_acceptance([finished, tmp_path / "students" / "absent"]) == [finished]
    unfinished = _old_kinematic_run(tmp_path / "students", name="student-BlindCraftsman-Kinematic-td3-s1")
    (unfinished / "result.json").unlink()
    with pytest.raises(RunError, match=r"unfinished kinematic run recorded when success counted .* move it aside"):
        _counting_acceptance([finished, unfinished])
    assert reread_in_place(finished) and not reread_in_place(finished)  # once: then it is of this format
    assert [int(r["success"]) for r in read_csv(finished / "episodes.csv")] == [0, 1]  # the plain log rewritten
    assert not (finished / "episodes.csv.gz").exists()
