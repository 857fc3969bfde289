"""The tasks page's references are played once per code version and read from the cache after."""

import json
import logging
from pathlib import Path

import pytest

import craftsuite.references as references_module
from craftsuite import paths
from craftsuite.paths import files_digest
from craftsuite.references import POLICIES, Reference, references

IDS = ["CraftSuite/Reach-Grid7-v0", "CraftSuite/Reach-Cont-v0"]


@pytest.fixture
def played(monkeypatch, tmp_path):
    """A fresh cache, and a count of the references played (each a cheap stand-in)."""
    monkeypatch.setenv("CRAFTSUITE_CACHE_DIR", str(tmp_path / "cache"))
    calls = []

    def fake(env_id, policy, episodes=100, seed=0):
        calls.append((env_id, policy))
        return Reference(env_id, policy, episodes, 0.5, float("nan"), 1.25, 0.0)

    monkeypatch.setattr(references_module, "reference", fake)
    return calls


def _cache_files(tmp_path):
    return sorted((tmp_path / "cache" / "references").glob("*.json"))


def test_references_are_played_once_then_read_from_the_cache(played, tmp_path):
    first = references(IDS, episodes=3, progress=False)
    assert len(played) == len(IDS) * len(POLICIES)
    again = references(IDS, episodes=3, progress=False)
    assert len(played) == len(IDS) * len(POLICIES)  # nothing played the second time
    assert again.keys() == first.keys()
    for key in first:  # nan == nan fails: compare the fields as text
        assert repr(again[key]) == repr(first[key])
    assert len(_cache_files(tmp_path)) == 1


@pytest.mark.parametrize("change", ["code", "episodes", "ids", "task", "library"])
def test_a_change_to_what_references_hang_on_plays_them_again(played, tmp_path, monkeypatch, change):
    references(IDS, episodes=3, progress=False)
    ids, episodes = IDS, 3
    if change == "code":
        monkeypatch.setattr(paths, "code_digest", lambda: "another version of the code")
    elif change == "episodes":
        episodes = 4
    elif change == "ids":
        ids = IDS[:1]
    elif change == "task":  # a task registered again from Python under the same name: in no file
        from craftsuite import task_registry

        specs = dict(task_registry.tasks())
        reach = specs["Reach"]
        monkeypatch.setattr(task_registry, "tasks", lambda: {**specs, "Reach": _Respecified(reach)})
    else:
        from importlib import metadata

        real = metadata.version
        monkeypatch.setattr(metadata, "version", lambda name: "0.0-other" if name == "mujoco" else real(name))
    before = len(played)
    references(ids, episodes=episodes, progress=False)
    assert len(played) == before + len(ids) * len(POLICIES)
    assert len(_cache_files(tmp_path)) == 2


class _Respecified:
    def __init__(self, spec):
        self.spec = spec

    def to_data(self):
        data = self.spec.to_data()
        data["continuous"] = {**data["continuous"], "max_steps": data["continuous"]["max_steps"] + 1}
        return data


@pytest.mark.parametrize("text", ["{torn", "[]", '[{"env_id": "x"}]', "not json at all"])
def test_an_unreadable_cache_file_is_passed_by_with_a_warning_and_rewritten(played, tmp_path, caplog, text):
    references(IDS, episodes=3, progress=False)
    (path,) = _cache_files(tmp_path)
    path.write_text(text)
    with caplog.at_level(logging.WARNING, logger="craftsuite.references"):
        refs = references(IDS, episodes=3, progress=False)
    assert len(played) == 2 * len(IDS) * len(POLICIES)
    assert "ignoring unreadable references cache" in caplog.text and str(path) in caplog.text
    assert len(json.loads(path.read_text())) == len(refs) == len(IDS) * len(POLICIES)


def test_a_cache_that_cannot_be_written_does_not_stop_the_references(played, tmp_path, monkeypatch, caplog):
    blocker = tmp_path / "a-file"
    blocker.write_text("")
    monkeypatch.setenv("CRAFTSUITE_CACHE_DIR", str(blocker))  # its references/ cannot be made
    with caplog.at_level(logging.WARNING, logger="craftsuite.references"):
        refs = references(IDS, episodes=3, progress=False)
    assert len(refs) == len(IDS) * len(POLICIES)
    assert "could not write the references cache" in caplog.text


def test_files_digest_follows_names_and_bytes_but_not_compiled_python(tmp_path):
    root = tmp_path / "pkg"
    (root / "sub").mkdir(parents=True)
    (root / "a.py").write_text("x = 1\n")
    (root / "sub" / "b.toml").write_text("k = 2\n")
    before = files_digest([root])
    (root / "__pycache__").mkdir()
    (root / "__pycache__" / "a.cpython-311.pyc").write_bytes(b"\0compiled")
    assert files_digest([root]) == before
    (root / "a.py").write_text("x = 2\n")
    assert files_digest([root]) != before
    (root / "a.py").write_text("x = 1\n")
    assert files_digest([root]) == before
    (root / "sub" / "b.toml").rename(root / "sub" / "c.toml")
    assert files_digest([root]) != before


def test_the_code_digest_covers_the_package_its_tasks_and_its_assets():
    import craftsuite

    package = Path(craftsuite.__file__).parent
    assert paths.code_digest() == files_digest([package, paths.tasks_dir(), paths.assets_dir()])
