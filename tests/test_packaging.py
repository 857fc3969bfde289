"""The wheel carries tasks/ and assets/, and works outside the repository."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
pytestmark = pytest.mark.slow  # builds a wheel and installs it


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    result = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "-q",
         "-w", str(out), str(ROOT)], capture_output=True, text=True)
    if result.returncode != 0 and "hatchling" in result.stderr:
        pytest.skip("hatchling is not installed (pip install -e '.[dev]')")
    assert result.returncode == 0, result.stderr
    (path,) = out.glob("craftsuite-*.whl")
    return path


def test_wheel_ships_task_specs(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    for spec in (ROOT / "tasks").glob("*.toml"):
        assert f"craftsuite/_data/tasks/{spec.name}" in names
    assert any(n.startswith("craftsuite/_data/assets/") for n in names)


def test_wheel_works_outside_the_repo(wheel, tmp_path):
    site = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(site)
    code = (
        "import craftsuite, gymnasium as gym; from craftsuite.paths import tasks_dir; "
        "print(craftsuite.__file__); print(tasks_dir()); "
        "env = gym.make('CraftSuite/DiamondMine-Grid7-v0', product=True); "
        "print(env.reset(seed=0)[0].shape)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            cwd=tmp_path, env={"PYTHONPATH": str(site), "HOME": str(tmp_path)})
    assert result.returncode == 0, result.stderr
    module, tasks, shape = result.stdout.splitlines()
    assert module.startswith(str(site)) and tasks.startswith(str(site / "craftsuite" / "_data"))
    assert shape.startswith("(")
