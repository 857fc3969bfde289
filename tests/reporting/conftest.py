import json

import pytest

from .fakes import fake_run


@pytest.fixture
def runs(tmp_path):
    root = tmp_path / "students"
    # fast: 80% at step 500 on both seeds; returns in the last 10% (step > 900): 10 and 20
    fake_run(root, "td3-dynamic", 0, [(250, 0.2), (500, 0.8), (750, 1.0), (1000, 1.0)],
             [(100, -50.0, 1), (920, 10.0, 1), (950, 10.0, 0), (980, 10.0, 1), (1000, 10.0, 1)])
    fake_run(root, "td3-dynamic", 1, [(250, 0.4), (500, 0.8), (750, 0.8), (1000, 0.6)],
             [(900, -99.0), (990, 20.0)])
    # slow: one seed reaches 80% at 1000, the other never does
    fake_run(root, "td3", 0, [(250, 0.0), (500, 0.0), (750, 0.4), (1000, 0.8)], [(995, 0.0)])
    fake_run(root, "td3", 1, [(250, 0.0), (500, 0.0), (750, 0.0), (1000, 0.0)], [(995, -100.0)])
    (root / "student-unfinished").mkdir()  # no record at all: not a run
    teacher = root / "teacher-BlindCraftsman-Grid7"  # a teacher run: not on the board
    teacher.mkdir()
    (teacher / "config.json").write_text(json.dumps({"task": "BlindCraftsman", "max_steps": 10}))
    (teacher / "result.json").write_text(json.dumps({"kind": "teacher", "steps": 10}))
    return root
