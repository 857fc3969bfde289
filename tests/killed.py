"""A small SB3 run killed after its checkpoints, as the resume tests start from."""

from __future__ import annotations

import pytest

from craftsuite.configs import StudentConfig
from craftsuite.runs import RunDir
from craftsuite.training import train_student

TINY = {"learning_starts": 50, "buffer_size": 2_000, "policy_kwargs": {"net_arch": [16]}}
CONFIG = StudentConfig(method="dqn", world="Grid7", steps=300, eval_every=100, eval_episodes=1, hyperparameters=TINY,
                       engine="sb3")  # the SB3 trainer's checkpoints


def killed_run(root, monkeypatch):
    """``CONFIG``'s run under ``root``, killed after its last checkpoint (at 300), with the
    one before it (at 200)."""
    monkeypatch.setattr(RunDir, "write_result", lambda self, result: (_ for _ in ()).throw(KeyboardInterrupt))
    with pytest.raises(KeyboardInterrupt):
        train_student(CONFIG, root, progress=False)
    monkeypatch.undo()
    run = root / CONFIG.run_name()
    assert (run / "checkpoint" / "replay.pkl").is_file() and (run / "checkpoint-old" / "model.zip").is_file()
    return run
