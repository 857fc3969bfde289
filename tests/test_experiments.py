"""Every research folder in experiments/ says what it asked and found, and its scripts import."""

from __future__ import annotations

import importlib.util
import sys
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
    spec.loader.exec_module(module)
    assert callable(getattr(module, "main", None)), f"{script} has no main()"
    sys.modules.pop(spec.name, None)
