"""Where a result came from: sessions appended to provenance.json, named as users type them."""

from __future__ import annotations

import json
import sys
from datetime import datetime, timezone

import pytest

from craftsuite.provenance import git_commit, read, record_session


def test_sessions_append_with_command_commit_machine_and_versions(tmp_path, monkeypatch):
    monkeypatch.setattr(sys, "argv", ["/somewhere/craftsuite/__main__.py", "transfer", "--suite", "quick"])
    started = datetime(2026, 11, 23, 8, 0, tzinfo=timezone.utc)
    record_session(tmp_path, started, 61.25)
    record_session(tmp_path, started, 2.0, command=["my_script.py", "--seed", "1"])
    first, second = read(tmp_path)
    assert first["command"] == "craftsuite transfer --suite quick"  # python -m craftsuite, as typed
    assert first["started"] == "2026-11-23T08:00:00+00:00" and first["seconds"] == 61.2
    assert first["commit"] == git_commit() and "cores" in first["machine"]
    assert {"craftsuite", "torch", "stable-baselines3", "gymnasium", "mujoco"} <= set(first["versions"])
    assert second["command"] == "my_script.py --seed 1"


def test_a_damaged_record_is_named_and_kept(tmp_path):
    (tmp_path / "provenance.json").write_text("{not json")
    with pytest.raises(ValueError, match="provenance.json is not valid JSON: delete it"):
        record_session(tmp_path, datetime.now(timezone.utc), 1.0)
    assert (tmp_path / "provenance.json").read_text() == "{not json"  # nothing overwritten
    (tmp_path / "provenance.json").write_text(json.dumps({"a": 1}))
    with pytest.raises(ValueError, match="holds no list of sessions"):
        read(tmp_path)
