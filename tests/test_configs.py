"""Run configs live apart from training: reading and building them imports no torch."""

from __future__ import annotations

import subprocess
import sys

from craftsuite import configs, ids


def test_importing_the_configs_imports_no_torch():
    code = ("import sys; from craftsuite.configs import StudentConfig, TeacherConfig; "
            "StudentConfig(method='td3').run_name(); TeacherConfig().run_name(); "
            "heavy = sorted(m for m in ('torch', 'stable_baselines3') if m in sys.modules); "
            "print(heavy); sys.exit(1 if heavy else 0)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr


def test_a_configs_env_id_is_built_by_the_id_module():
    student = configs.StudentConfig(task="Reach", method="dqn", world="Grid10")
    assert student.env_id == ids.env_id("Reach", "Grid10") and ids.parse_id(student.env_id) == ("Reach", "Grid10")
    teacher = configs.TeacherConfig(task="Reach", size=10)
    assert ids.parse_id(teacher.env_id) == ("Reach", "Grid10")
    assert teacher.run_name().startswith("teacher-Reach-Grid10-s0-")


def test_a_config_of_an_unknown_world_is_a_clear_error():
    import pytest

    with pytest.raises(ValueError, match="unknown world 'Mujoco': use Cont"):
        configs.StudentConfig(world="Mujoco")
