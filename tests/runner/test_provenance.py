"""Where a result came from: sessions appended to provenance.json, named as users type them."""

from __future__ import annotations

import json
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
