"""The tasks page's references are played once per code version and read from the cache after."""

import json
import logging

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


@pytest.mark.parametrize("change", ["code", "episodes", "ids", "task", "registration", "library"])
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
        monkeypatch.setattr(task_registry, "tasks", lambda: {**specs, "Reach": _Respecified(specs["Reach"])})
    elif change == "registration":  # the id registered again with another episode limit
        import gymnasium as gym

        spec = gym.spec(IDS[0])
        monkeypatch.setattr(spec, "max_episode_steps", spec.max_episode_steps + 1)
    else:
        from importlib import metadata

        real = metadata.version
        monkeypatch.setattr(metadata, "version", lambda name: "0.0-other" if name == "dm-control" else real(name))
    before = len(played)
    references(ids, episodes=episodes, progress=False)
    assert len(played) == before + len(ids) * len(POLICIES)
    assert len(_cache_files(tmp_path)) == 2


class _Respecified:
    def __init__(self, spec):
        self.spec = spec

    def digest(self):
        return "another " + self.spec.digest()


def test_references_played_while_the_code_changed_are_not_kept(played, tmp_path, monkeypatch):
    versions = iter(["the code as play began", "the code as play ended"])
    monkeypatch.setattr(paths, "code_digest", lambda: next(versions))
    assert len(references(IDS, episodes=3, progress=False)) == len(IDS) * len(POLICIES)
    assert _cache_files(tmp_path) == []


WRONG_TYPES = ('[{"env_id": "CraftSuite/Reach-Grid7-v0", "policy": "random", "episodes": 3, "success": "x", '
               '"steps": 1.0, "automaton_steps": 1.0, "violations": 0.0}]')


@pytest.mark.parametrize("text", ["{torn", "[]", '[{"env_id": "x"}]', "[1]", WRONG_TYPES])
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


@pytest.mark.parametrize("layout", ["checkout", "wheel"])
def test_the_code_digest_follows_the_package_its_tasks_and_its_assets(tmp_path, monkeypatch, layout):
    package = tmp_path / "craftsuite"
    data = package / "_data" if layout == "wheel" else tmp_path  # where tasks/ and assets/ sit
    for folder, name in ((package, "env.py"), (data / "tasks", "reach.toml"), (data / "assets", "scene.xml")):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text("v1")
    monkeypatch.setattr(paths, "_PACKAGE", package)
    before = paths.code_digest()
    for changed in (package / "env.py", data / "tasks" / "reach.toml", data / "assets" / "scene.xml"):
        changed.write_text("v2")
        assert paths.code_digest() != before, changed
        changed.write_text("v1")
    assert paths.code_digest() == before
