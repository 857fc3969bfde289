"""Where a result came from: sessions appended to provenance.json, named as users type them."""

from __future__ import annotations

import json
import os
import platform
from pathlib import Path
import sys
import pytest

from craftsuite import provenance
from craftsuite.provenance import read, record_session, start_session


def test_sessions_append_with_command_commit_machine_and_versions(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["/somewhere/craftsuite/__main__.py", "transfer", "--suite", "quick"])
    session = start_session()
    monkeypatch.setattr(provenance, "git_commit", lambda: "committed-while-it-ran")
    record_session(tmp_path, session, 61.3)
    record_session(tmp_path, start_session(command=["my_script.py", "--seed", "1"]), 2.0)
    first, second = read(tmp_path)
    assert first["command"] == "craftsuite transfer --suite quick"  # python -m craftsuite, as typed
    assert first["seconds"] == 61.3 and first["started"].endswith("+00:00")
    assert first["commit"] == session["commit"] != "committed-while-it-ran"  # the code at the start
    assert "cores" in first["machine"]
    assert {"craftsuite", "torch", "stable-baselines3", "gymnasium", "mujoco"} <= set(first["versions"])
    assert second["command"] == "my_script.py --seed 1" and second["commit"] == "committed-while-it-ran"


def test_a_damaged_record_is_named_and_kept(tmp_path):
    (tmp_path / "provenance.json").write_text("{not json")
    with pytest.raises(ValueError, match="provenance.json is not valid JSON: delete it"):
        record_session(tmp_path, start_session(), 1.0)
    assert (tmp_path / "provenance.json").read_text() == "{not json"  # nothing overwritten
    (tmp_path / "provenance.json").write_text(json.dumps({"a": 1}))
    with pytest.raises(ValueError, match="holds no list of sessions"):
        read(tmp_path)


def test_a_session_is_on_record_from_its_start_and_updated_when_it_ends(tmp_path):
    killed, finished = start_session(command=["craftsuite", "transfer"]), start_session(command=["craftsuite", "x"])
    twin = start_session(command=["craftsuite", "x"])  # the same command, started in the same second
    record_session(tmp_path, killed, None)  # never updated: killed
    record_session(tmp_path, finished, None)
    record_session(tmp_path, twin, None)
    record_session(tmp_path, finished, 12.34)
    assert [(s["command"], s["seconds"]) for s in read(tmp_path)] == [("craftsuite transfer", None),
                                                                       ("craftsuite x", 12.3), ("craftsuite x", None)]


def test_a_run_records_its_effective_settings_and_the_code_that_trained_it(tmp_path, monkeypatch):
    from craftsuite.hyperparameters import TD3_DEFAULTS
    from craftsuite.runs import FORMAT, RunDir, load_config, read_config, run_settings, settings
    from craftsuite.configs import StudentConfig

    config = StudentConfig(method="td3-dynamic-edges", steps=500, table="t.npz",
                           hyperparameters={"batch_size": 32})
    with RunDir(tmp_path / "r", config):
        pass
    monkeypatch.setattr(provenance, "git_commit", lambda: "a-later-commit")
    with RunDir(tmp_path / "r", config):  # resumed under other code: a second session on record
        pass
    record = read_config(tmp_path / "r")
    assert record["format"] == FORMAT and load_config(StudentConfig, tmp_path / "r") == config  # the round trip
    assert run_settings(record) == run_settings(json.loads(json.dumps(settings(config)))) and record["table"] == "t.npz"
    effective = record["effective"]
    assert effective["hyperparameters"]["batch_size"] == 32  # the override
    assert effective["hyperparameters"]["learning_rate"] == TD3_DEFAULTS["learning_rate"]  # the default merged in
    assert effective["hyperparameters"]["buffer_size"] == 500  # no larger than the budget
    assert effective["method"]["target"] == {"rho": 1.0, "self_loops": False}  # the row's own target
    assert effective["world"] == {"id": "CraftSuite/BlindCraftsman-Cont-v0", "kwargs": {},
                                  "rules": craftsuite_task_digest("BlindCraftsman")}
    first, second = record["provenance"]
    assert {"craftsuite", "torch", "stable-baselines3", "gymnasium", "mujoco"} <= set(first["versions"])
    assert first["commit"] != "a-later-commit"  # the code that started the run
    assert second["commit"] == "a-later-commit" and second["at"] >= first["at"]


def craftsuite_task_digest(task: str) -> str:
    from craftsuite.task_registry import resolve_task

    return resolve_task(task).digest()


def test_a_change_of_a_default_or_of_the_rules_gives_a_new_run_key(monkeypatch):
    import dataclasses

    from craftsuite import hyperparameters, task_registry
    from craftsuite.configs import StudentConfig, TeacherConfig

    student, teacher = StudentConfig(method="td3"), TeacherConfig()
    keys = student.run_name(), teacher.run_name()
    monkeypatch.setitem(hyperparameters.TD3_DEFAULTS, "learning_rate", 3e-4)
    assert student.run_name() != keys[0] and teacher.run_name() == keys[1]  # DQN's defaults did not change
    monkeypatch.setitem(hyperparameters.DQN_DEFAULTS, "target_update_interval", 1_000)
    assert teacher.run_name() != keys[1]
    monkeypatch.undo()
    assert (student.run_name(), teacher.run_name()) == keys
    # the task's rules: a longer episode is another benchmark; a new description is not
    spec = task_registry.resolve_task("BlindCraftsman")
    known = dict(task_registry.tasks())
    monkeypatch.setattr(task_registry, "tasks", lambda: {**known, "BlindCraftsman": dataclasses.replace(
        spec, continuous=dataclasses.replace(spec.continuous, max_steps=300))})
    assert student.run_name() != keys[0]
    monkeypatch.setattr(task_registry, "tasks", lambda: {**known, "BlindCraftsman": dataclasses.replace(
        spec, description="reworded")})
    assert student.run_name() == keys[0]
    wood = dataclasses.replace(spec.items[0], color="#000000", symbol="W")  # another look, the same rules
    monkeypatch.setattr(task_registry, "tasks", lambda: {**known, "BlindCraftsman": dataclasses.replace(
        spec, items=(wood, *spec.items[1:]))})
    assert student.run_name() == keys[0]


def test_where_the_teachers_table_lies_is_recorded_but_not_hashed(tmp_path):
    from craftsuite.runs import RunDir, read_config
    from craftsuite.configs import StudentConfig

    here = StudentConfig(method="td3-dynamic", table="/mnt/a/runs/teachers/teacher-X-k1/table.npz")
    moved = StudentConfig(method="td3-dynamic", table="/home/b/runs/teachers/teacher-X-k1/table.npz")
    other = StudentConfig(method="td3-dynamic", table="/mnt/a/runs/teachers/teacher-X-k2/table.npz")
    assert here.run_name() == moved.run_name() != other.run_name()  # another teacher is another run
    with RunDir(tmp_path / "r", here):
        pass
    with RunDir(tmp_path / "r", moved):  # the directory moved: the run resumes, and records its new table
        pass
    record = read_config(tmp_path / "r")
    assert record["table"] == moved.table and record["effective"]["teacher"] == "teacher-X-k1/table.npz"


def test_a_copied_tree_names_its_commit_from_the_environment(tmp_path, monkeypatch):
    import subprocess

    monkeypatch.delenv(provenance.COMMIT_VARIABLE, raising=False)
    if (Path(__file__).resolve().parents[1] / ".git").exists():
        assert provenance.git_commit()  # this checkout's own
    # a copy of the tree on another machine may carry a .git of another commit: the variable wins
    monkeypatch.setenv(provenance.COMMIT_VARIABLE, "5009c5b0aa")
    assert provenance.git_commit() == "5009c5b0aa"

    def no_checkout(*args, **kwargs):
        return subprocess.CompletedProcess(args, 128, "", "fatal: not a git repository")

    monkeypatch.setattr(provenance.subprocess, "run", no_checkout)
    assert provenance.git_commit() == "5009c5b0aa"
    monkeypatch.delenv(provenance.COMMIT_VARIABLE)
    assert provenance.git_commit() is None


def test_sessions_written_at_once_into_one_directory_are_all_kept(tmp_path, monkeypatch):
    """A campaign's processes archive into one archive at once: each merge reads, adds and
    rewrites the record, and none may write back a record that lacks another's session."""
    import threading
    import time

    real = provenance.read

    def slow_read(out):  # widens the window between reading the record and writing it back
        found = real(out)
        time.sleep(0.01)
        return found

    monkeypatch.setattr(provenance, "read", slow_read)

    def write(n):
        for i in range(5):
            record_session(tmp_path, start_session(command=f"writer {n} session {i}"), 1.0)

    writers = [threading.Thread(target=write, args=(n,)) for n in range(6)]
    for w in writers:
        w.start()
    for w in writers:
        w.join()
    assert sorted(s["command"] for s in real(tmp_path)) == sorted(f"writer {n} session {i}" for n in range(6)
                                                                  for i in range(5))


def test_the_machine_names_its_cpu_and_its_widest_vector_instructions():
    from craftsuite.provenance import cpu
    from craftsuite.reporting.timing import _machine_kind

    one = "model name\t: AMD EPYC\ncpu family\t: 23\nmodel\t\t: 1\nflags\t\t: fpu sse2 avx avx2 fma\n"
    two = f"processor\t: 0\n{one}\nprocessor\t: 1\n{one.replace('avx2 fma', 'avx2 fma avx512f')}"
    assert cpu(two) == "AMD EPYC (family 23 model 1, AVX2)"  # the first processor's
    assert cpu(one.replace("avx2 fma", "avx2 fma avx512f avx512bw")) == "AMD EPYC (family 23 model 1, AVX-512)"
    assert cpu("model name\t: Some CPU\nflags\t\t: fpu sse2\n") == "Some CPU"  # nothing more known: the model
    assert cpu("processor\t: 0\nBogoMIPS\t: 50.00\nFeatures\t: fp asimd\n") == ""  # no model or flags: nothing
    assert cpu("") == ""
    # as the records name it, and as the timing lines count it (a model may hold a comma)
    here = provenance.machine()
    assert here.startswith(f"{platform.system()} {platform.machine()}, ") and f", {os.cpu_count()} cores, " in here
    assert _machine_kind(here, "?") == f"{os.cpu_count()} cores" + (f" of {cpu()}" if cpu() else "")
    assert _machine_kind("Linux x86_64, Foo, Bar CPU (AVX), 2 cores, 8 GiB", "?") == "2 cores of Foo, Bar CPU (AVX)"
    assert _machine_kind("Linux x86_64, 2 cores, 23.5 GiB, Python 3.11.7", "?") == "2 cores"  # an older record
    assert _machine_kind("Linux", "?") == _machine_kind(None, "?") == "?"
