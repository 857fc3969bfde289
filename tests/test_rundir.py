"""Run directories: locking, config mismatch, atomic writes, log trimming."""

import dataclasses
import json
import os
import subprocess
import sys

import pytest

from craftsuite.configs import StudentConfig
from craftsuite.files import atomic_write
from craftsuite.runs import EPISODE_FIELDS, RunDir, RunError, load_config, read_columns, read_csv, settings


def test_two_live_runs_never_share_a_directory(tmp_path):
    config = StudentConfig(steps=10)
    with RunDir(tmp_path / "r", config):
        with pytest.raises(RunError, match="in use by another run"):
            with RunDir(tmp_path / "r", config):
                pass
    with RunDir(tmp_path / "r", config):  # released: usable again
        pass


def test_a_dead_owners_lock_is_taken_over(tmp_path):
    holder = ("import sys, time; from craftsuite.runs import RunDir; from craftsuite.configs import StudentConfig\n"
              "with RunDir(sys.argv[1], StudentConfig(steps=10)):\n    print('held', flush=True); time.sleep(60)")
    proc = subprocess.Popen([sys.executable, "-c", holder, str(tmp_path / "r")], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "held"
        with pytest.raises(RunError, match=f"process .* {proc.pid}"):
            with RunDir(tmp_path / "r", StudentConfig(steps=10)):
                pass
    finally:
        proc.kill()
        proc.wait()
    with RunDir(tmp_path / "r", StudentConfig(steps=10)) as run:  # its holder died: free at once
        assert (run.path / ".lock").read_text().endswith(str(os.getpid()))


def test_another_users_lock_is_named_not_raised_as_a_permission_error(tmp_path, monkeypatch):
    import craftsuite.runs
    from craftsuite.runs import in_use

    with RunDir(tmp_path / "r", StudentConfig(steps=10)):
        pass
    real_open = os.open

    def other_users(path, flags, *args):  # (the tests run as root, whom no file mode refuses)
        if str(path).endswith(".lock"):
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, flags, *args)

    monkeypatch.setattr(craftsuite.runs.os, "open", other_users)
    for call in (lambda: in_use(tmp_path / "r"), lambda: RunDir(tmp_path / "r", StudentConfig(steps=10)).__enter__()):
        with pytest.raises(RunError, match=r"r/.lock cannot be opened here \(Permission denied\): the run belongs "
                                           "to another user; run this as the user who trained it"):
            call()
    monkeypatch.undo()

    def read_only(path, flags, *args):  # a lock this user may read, not write
        if str(path).endswith(".lock") and flags & (os.O_WRONLY | os.O_RDWR):
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, flags, *args)

    with RunDir(tmp_path / "r", StudentConfig(steps=10)):  # its owner holds it
        monkeypatch.setattr(craftsuite.runs.os, "open", read_only)
        assert in_use(tmp_path / "r")
    assert not in_use(tmp_path / "r")  # released: a read-only descriptor tells that too
    assert not in_use(tmp_path / "none") and not in_use(tmp_path / "r" / "config.json")  # no run, a file


def test_a_directory_in_the_locks_place_is_named_and_kept(tmp_path):
    from craftsuite.runs import in_use

    (tmp_path / "r" / ".lock").mkdir(parents=True)
    (tmp_path / "r" / ".lock" / "kept").write_text("x")
    for call in (lambda: in_use(tmp_path / "r"), lambda: RunDir(tmp_path / "r", StudentConfig(steps=10)).__enter__()):
        with pytest.raises(RunError, match=r"r/.lock is a directory where a run keeps its lock file; remove it"):
            call()
    assert sorted(p.name for p in (tmp_path / "r").rglob("*")) == [".lock", "kept"]  # nothing written, nothing lost


def test_a_directory_of_another_config_is_refused_and_kept(tmp_path):
    with RunDir(tmp_path / "r", StudentConfig(steps=10)) as run:
        run.append("episodes.csv", EPISODE_FIELDS, [{"step": 5, "return": 1.0, "length": 5, "success": 1}])
    with pytest.raises(RunError, match="another configuration"):
        with RunDir(tmp_path / "r", StudentConfig(steps=20)):
            pass
    assert json.loads((tmp_path / "r" / "config.json").read_text())["steps"] == 10
    assert len(read_csv(tmp_path / "r" / "episodes.csv")) == 1
    with RunDir(tmp_path / "r", StudentConfig(steps=10)):  # the refused open released its lock
        pass


def test_trim_logs_drops_rows_after_the_checkpoint(tmp_path):
    with RunDir(tmp_path / "r", StudentConfig(steps=10)) as run:
        run.append("episodes.csv", EPISODE_FIELDS,
                   [{"step": s, "return": 0.0, "length": 1, "success": 0} for s in (100, 200, 300)])
        run.trim_logs(200)
        assert [int(r["step"]) for r in read_csv(run.path / "episodes.csv")] == [100, 200]


def test_read_csv_ignores_a_torn_last_line(tmp_path):
    path = tmp_path / "e.csv"
    path.write_text("step,return,length,success\n1,0.5,1,0\n2,0.")
    assert [r["step"] for r in read_csv(path)] == ["1"]
    path.write_text("step,return,length,success\n1,0.5,1,0\n2,0.5,1,1")  # torn inside its last field
    assert [r["step"] for r in read_csv(path)] == ["1"]
    assert read_columns(path, ("success",))["success"] == ("0",)
    path.write_text("step,return,length,success\r\n1,0.5,1,0\r")  # torn between its line end's bytes: whole
    assert [r["success"] for r in read_csv(path)] == ["0"]


def test_read_csv_reads_rows_as_the_standard_dict_reader_does(tmp_path):
    """Its own row reader (a page reads millions of rows) against csv.DictReader on what a
    log can hold: blank lines, a short row before the last, a long row, quoted commas."""
    import csv

    text = ("step,return,success\n\n1,0.5,0\n2,1.5\n3,\"-1,5\",1\n\n4,2,1,extra,more\n5,0.0,1\n")
    path = tmp_path / "e.csv"
    path.write_text(text)
    with open(path, newline="") as f:
        theirs = list(csv.DictReader(f))
    assert [r for r in theirs if None not in r.values()] == read_csv(path)
    assert [r["step"] for r in read_csv(path)] == ["1", "3", "4", "5"]  # the short row 2 left out, as a torn one
    with pytest.raises(ValueError, match="has fewer fields than its header"):
        read_csv(path, fields=("step",))
    (tmp_path / "empty.csv").write_text("")
    assert read_csv(tmp_path / "empty.csv") == []
    with pytest.raises(ValueError, match="empty"):
        read_csv(tmp_path / "empty.csv", fields=("step",))


def test_read_columns_holds_the_rows_read_csv_reads(tmp_path):
    """The columnar reading (a page's) is the row reading transposed: the same rows, a torn
    last line left out, a short row before it refused, the archive's .gz read alike."""
    import gzip

    path = tmp_path / "e.csv"
    path.write_text("step,return,success\n\n1,0.5,0\n3,\"-1,5\",1\n4,2,1,extra\n5,0.")
    rows = read_csv(path, ("step", "return"))
    columns = read_columns(path, ("step", "return"))
    assert columns == {name: tuple(r[name] for r in rows) for name in ("step", "return", "success")}
    assert columns["return"] == ("0.5", "-1,5", "2")
    packed = tmp_path / "p.csv.gz"
    packed.write_bytes(gzip.compress(path.read_bytes()))
    assert read_columns(tmp_path / "p.csv", ("step",)) == columns
    path.write_text("step,return\n1\n2,3\n")
    with pytest.raises(ValueError, match="line 2 has fewer fields than its header"):
        read_columns(path, ("step",))
    path.write_text("step,return\n")  # a header and no episode yet
    assert read_columns(path, ("step",)) == {"step": (), "return": ()}
    assert read_columns(tmp_path / "missing.csv", ("step",)) == {"step": ()}
    with pytest.raises(FileNotFoundError):
        read_columns(tmp_path / "missing.csv", ("step",), required=True)


def test_a_log_whose_gzip_stream_or_csv_is_damaged_is_named_as_a_damaged_record(tmp_path):
    """zlib's and csv's own errors are neither OSError nor ValueError: read through
    read_log_columns they come out as the RunError that names the file, as a torn .gz does."""
    import gzip

    from craftsuite.runs import RunError, read_log_columns

    packed = gzip.compress(("step,return\n" + "".join(f"{i},{i % 7}\n" for i in range(5000))).encode())
    # the deflate stream's first block given the reserved block type (bits 1-2 of its first byte,
    # after gzip's 10-byte header): zlib's "invalid block type", whatever zlib compressed it
    (tmp_path / "e.csv.gz").write_bytes(packed[:10] + bytes([packed[10] | 0b110]) + packed[11:])
    with pytest.raises(RunError, match=r"e\.csv does not read as a run's log .*compressed bytes are damaged"):
        read_log_columns(tmp_path / "e.csv", ("step",))
    (tmp_path / "f.csv").write_text("step,return\n" + "x" * 200_000 + ",1\n")  # beyond csv's field limit
    with pytest.raises(RunError, match=r"f\.csv does not read as a run's log .*does not parse as CSV"):
        read_log_columns(tmp_path / "f.csv", ("step",))


def test_atomic_write_leaves_no_temporary_files(tmp_path):
    atomic_write(tmp_path / "a.json", "{}")
    atomic_write(tmp_path / "a.json", "[]")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]
    assert (tmp_path / "a.json").read_text() == "[]"


def test_atomic_write_takes_bytes_and_keeps_the_old_file_when_a_writer_fails(tmp_path):
    from craftsuite.files import atomic_path

    path = tmp_path / "model.zip"
    atomic_write(path, b"\x00old")
    with pytest.raises(RuntimeError), atomic_path(path) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("killed while writing")
    assert path.read_bytes() == b"\x00old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.zip"]
    with pytest.raises(FileNotFoundError, match="nothing was written"), atomic_path(path):
        pass  # a writer that wrote nothing does not replace the file with nothing
    assert path.read_bytes() == b"\x00old"


def test_a_failed_atomic_write_removes_the_folders_made_for_it_while_empty(tmp_path):
    """A writer that fails leaves none of the folders made for its file; a folder that held
    something before, or was filled meanwhile, stays."""
    from craftsuite.files import atomic_path

    (tmp_path / "kept").mkdir()
    with pytest.raises(RuntimeError), atomic_path(tmp_path / "kept" / "new" / "deeper" / "a.png") as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("dot failed")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["kept"]
    with pytest.raises(RuntimeError), atomic_path(tmp_path / "kept" / "new" / "deeper" / "a.png"):
        (tmp_path / "kept" / "new" / "other.txt").write_text("another writer's")
        raise RuntimeError("dot failed")
    assert sorted(p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*")) == ["kept", "kept/new",
                                                                                         "kept/new/other.txt"]


def test_atomic_path_keeps_the_suffix_writers_add_when_it_is_missing(tmp_path):
    import numpy as np

    from craftsuite.files import atomic_path

    with atomic_path(tmp_path / "table.npz") as tmp:
        assert tmp.suffix == ".npz" and tmp.parent == tmp_path
        np.savez(tmp, q=np.arange(3))  # numpy appends .npz only when it is missing
    with np.load(tmp_path / "table.npz") as f:
        assert f["q"].tolist() == [0, 1, 2]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.npz"]


def test_a_run_that_fails_before_training_leaves_no_directory(tmp_path):
    from craftsuite.training import train_student

    bad = StudentConfig(method="td3", steps=100, hyperparameters={"learning_rat": 1e-3})  # misspelt
    with pytest.raises(TypeError, match="learning_rat"):
        train_student(bad, tmp_path)
    assert list(tmp_path.iterdir()) == []
    # a killed run's directory (its config only, nothing trained yet) is not this run's to remove
    killed = tmp_path / "killed"
    with RunDir(killed, StudentConfig()):
        pass
    with pytest.raises(RuntimeError), RunDir(killed, StudentConfig()):
        raise RuntimeError("boom")
    assert (killed / "config.json").exists()
    # a directory that held something before is left as it was
    run = tmp_path / "kept"
    run.mkdir()
    (run / "notes.txt").write_text("mine")
    with pytest.raises(RuntimeError), RunDir(run, StudentConfig()):
        raise RuntimeError("boom")
    assert (run / "notes.txt").read_text() == "mine" and (run / "config.json").exists()
    # as is one that the failed run had begun to fill
    fresh = tmp_path / "fresh"
    with pytest.raises(RuntimeError), RunDir(fresh, StudentConfig()) as r:
        r.append("episodes.csv", EPISODE_FIELDS, [{"step": 1, "return": 0, "length": 1, "success": 0}])
        raise RuntimeError("boom")
    assert len(read_csv(fresh / "episodes.csv")) == 1


def test_a_failed_run_removes_the_empty_folders_it_made_above_it_and_no_others(tmp_path):
    before = tmp_path / "before"
    before.mkdir()  # empty, but there before the run: not the run's to remove
    with pytest.raises(RuntimeError), RunDir(before / "new" / "out" / "run", StudentConfig()):
        raise RuntimeError("boom")  # (an agent that could not be built, in a new --out)
    assert [p.name for p in tmp_path.iterdir()] == ["before"] and list(before.iterdir()) == []
    # a folder it made that something filled meanwhile stays, and the folders above it
    with pytest.raises(RuntimeError), RunDir(before / "new" / "out" / "run", StudentConfig()):
        (before / "new" / "notes.txt").write_text("not the run's")
        raise RuntimeError("boom")
    assert [p.name for p in before.iterdir()] == ["new"] and [p.name for p in (before / "new").iterdir()] == [
        "notes.txt"]


def test_checkpoints_rotate_keeping_the_one_before_the_last(tmp_path):
    def save(run, step):
        new = run.new_checkpoint()
        for name in ("model.zip", "replay.pkl"):
            (new / name).write_text(str(step))
        run.commit_checkpoint()

    def steps(run):
        return [(d.name, (d / "model.zip").read_text()) for d in run.checkpoint_dirs()]

    with RunDir(tmp_path / "run", StudentConfig(steps=10)) as run:
        assert run.checkpoint_dirs() == [] and run.last_checkpoint() is None
        for step in (1, 2, 3):
            save(run, step)
        assert steps(run) == [("checkpoint", "3"), ("checkpoint-old", "2")]  # the first is gone
        (run.new_checkpoint() / "model.zip").write_text("4")  # killed before the replay was written
        assert run.last_checkpoint().name == "checkpoint"  # an incomplete one is no checkpoint
        save(run, 4)  # what the kill left is cleared first
        assert steps(run) == [("checkpoint", "4"), ("checkpoint-old", "3")]
        run.remove_checkpoints(keep_last=True)
        assert steps(run) == [("checkpoint", "4")]
        run.remove_checkpoints()
        assert not any((run.path / name).exists() for name in RunDir.CHECKPOINTS)


def test_a_field_at_its_default_is_left_out_of_the_key_and_old_records_load_but_are_not_resumed(tmp_path):
    plain, skipped = StudentConfig(), StudentConfig(world_kwargs={"frame_skip": 10})
    assert plain.run_name() != skipped.run_name() != StudentConfig(n_envs=4).run_name()
    assert not {"world_kwargs", "n_envs"} & set(settings(plain))  # fields added later, at their default
    # a record of format 1: the config's fields alone, without the effective settings
    saved = {k: v for k, v in dataclasses.asdict(plain).items() if k not in ("world_kwargs", "n_envs")}
    old = tmp_path / plain.run_name()
    old.mkdir()
    (old / "config.json").write_text(json.dumps(saved))
    assert load_config(StudentConfig, old) == plain  # it loads
    with pytest.raises(RunError, match=r"recorded without its effective settings \(record format 1\)"):
        with RunDir(old, plain):  # but is not taken for a run of these settings
            pass
    assert json.loads((old / "config.json").read_text()) == saved  # and is left as it was
