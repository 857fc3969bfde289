"""The SB3 trainer (``engine="sb3"``): teacher and student runs, reuse, resume after a kill,
evaluation logs. The population engine's own are ``tests/population``."""

import dataclasses
import json
import signal
import subprocess
import sys
import time
import zipfile

import pytest

from craftsuite.configs import StudentConfig, TeacherConfig
from craftsuite.runs import RunDir, RunError, load_config, read_csv, settings
from craftsuite.training import train_student, train_teacher

from .scalars import hparams_sessions, scalar_steps

TINY_DQN = {"learning_starts": 100, "buffer_size": 5_000}


def test_teacher_run_writes_table_and_is_reused(tmp_path):
    config = TeacherConfig(max_steps=400, eval_every=200, eval_episodes=2, hyperparameters=TINY_DQN, engine="sb3")
    path = train_teacher(config, tmp_path, progress=False)
    result = json.loads((path / "result.json").read_text())
    assert result["steps"] == 400 and not result["reached_target"]
    assert (path / "table.npz").is_file() and (path / "teacher.zip").is_file()
    assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == [200, 400]
    before = (path / "teacher.zip").stat().st_mtime_ns
    assert train_teacher(config, tmp_path, progress=False) == path  # same config: reused, not retrained
    assert (path / "teacher.zip").stat().st_mtime_ns == before


def test_student_run_logs_every_episode(tmp_path):
    config = StudentConfig(method="dqn", world="Grid7", steps=900, eval_every=300, eval_episodes=2,
                           hyperparameters={**TINY_DQN, "learning_starts": 200}, engine="sb3")
    path = train_student(config, tmp_path, progress=False)
    episodes = read_csv(path / "episodes.csv")
    steps = [int(e["step"]) for e in episodes]
    assert steps == sorted(steps) and all(0 < s <= 900 for s in steps)
    assert sum(int(e["length"]) for e in episodes) <= 900
    assert [int(r["step"]) for r in read_csv(path / "evals.csv")] == [300, 600, 900]


def test_grid_student_keeps_one_fixed_instance(tmp_path, monkeypatch):
    import craftsuite.agents.factory as factory
    import craftsuite.training as training

    seen = []
    real_make, real_evaluate = factory.make_agent, training.evaluate

    def make_agent(*args, env_kwargs=None, **kwargs):
        seen.append(("train", env_kwargs))
        return real_make(*args, env_kwargs=env_kwargs, **kwargs)

    def evaluate(*args, env_kwargs=None, **kwargs):
        seen.append(("evaluate", env_kwargs))
        return real_evaluate(*args, env_kwargs=env_kwargs, **kwargs)

    monkeypatch.setattr(factory, "make_agent", make_agent)
    monkeypatch.setattr(training, "evaluate", evaluate)
    config = StudentConfig(method="dqn", world="Grid7", steps=300, eval_every=300, eval_episodes=1,
                           hyperparameters={**TINY_DQN, "learning_starts": 200}, layout_seed=3, engine="sb3")
    train_student(config, tmp_path, progress=False)
    assert seen == [("train", {"layout_seed": 3}), ("evaluate", {"layout_seed": 3})]
    with pytest.raises(ValueError, match="the Cont world has none"):
        StudentConfig(world="Cont", layout_seed=3)
    with pytest.raises(ValueError, match="layout_seed must be a non-negative integer"):
        StudentConfig(world="Grid7", layout_seed=-1)  # refused before a run directory is made


def test_evaluate_reports_every_step_to_on_step():
    import numpy as np

    from craftsuite.training import evaluate

    class Wanderer:  # one straight line: it cannot finish Blind Craftsman, so every episode runs 40 steps
        def predict(self, obs, deterministic=True):
            return np.tile([[0.7, -0.4]], (len(obs), 1)).astype(np.float32), None

    seen = {}
    success, mean_return, mean_length = evaluate(
        Wanderer(), "CraftSuite/BlindCraftsman-Cont-v0", 3, seed=5, product=False,
        env_kwargs={"max_episode_steps": 40}, on_step=lambda i, r, info: seen.setdefault(i, []).append(r))
    assert sorted(seen) == [0, 1, 2] and all(len(r) == 40 for r in seen.values())
    assert success == 0.0 and mean_length == 40.0
    assert np.isclose(mean_return, np.mean([sum(r) for r in seen.values()]))


_KILLABLE = """
import sys, craftsuite
from craftsuite.configs import StudentConfig
from craftsuite.training import train_student
config = StudentConfig(method="dqn", world="Grid7", steps=3_000, eval_every=500, eval_episodes=1,
                       hyperparameters={"learning_starts": 200, "buffer_size": 10_000}, engine="sb3")
train_student(config, sys.argv[1], progress=False)
"""


@pytest.mark.slow  # a training process killed after its second checkpoint, waited for up to 120 s
def test_a_killed_run_resumes_from_its_checkpoint(tmp_path):
    proc = subprocess.Popen([sys.executable, "-c", _KILLABLE, str(tmp_path)])
    try:
        deadline = time.time() + 120
        while time.time() < deadline:
            ckpt = list(tmp_path.glob("*/checkpoint/model.zip"))
            evals = read_csv(ckpt[0].parent.parent / "evals.csv") if ckpt else []
            if len(evals) >= 3:  # the checkpoint after the second evaluation is on disk
                break
            time.sleep(0.05)
        else:
            pytest.fail("the run made no checkpoint in 120 s")
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    finally:
        proc.kill()
    run = ckpt[0].parent.parent
    assert not (run / "result.json").exists(), "the run finished before it could be killed"
    assert (run / ".lock").exists()  # left behind by the killed process
    kept = [(r["step"], r["return"]) for r in read_csv(run / "episodes.csv")]
    config = load_config(StudentConfig, run)
    with zipfile.ZipFile(RunDir(run, config).last_checkpoint() / "model.zip") as z:
        checkpoint_step = json.loads(z.read("data"))["num_timesteps"]
    assert checkpoint_step >= 1_000  # so the resumed run must keep some episodes
    assert train_student(config, tmp_path, progress=False) == run  # takes the dead run's lock over
    episodes = read_csv(run / "episodes.csv")
    steps = [int(e["step"]) for e in episodes]
    assert steps == sorted(steps) and steps[-1] <= 3_000
    # one evaluation per interval: none lost, none repeated by the resumed run
    assert [int(r["step"]) for r in read_csv(run / "evals.csv")] == list(range(500, 3_001, 500))
    # episodes finished before the checkpoint the run resumed from are still there, unchanged
    assert [k for k in kept if int(k[0]) <= checkpoint_step] == \
        [(r["step"], r["return"]) for r in episodes if int(r["step"]) <= checkpoint_step]
    assert json.loads((run / "result.json").read_text())["steps"] == 3_000
    assert (run / "model.zip").is_file() and not (run / "checkpoint").exists()  # no replay buffer kept


def test_a_resumed_run_drops_what_tensorboard_logged_after_its_checkpoint(tmp_path, monkeypatch):
    import craftsuite.training as training

    config = StudentConfig(method="td3", steps=600, eval_every=200, eval_episodes=1,
                           world_kwargs={"frame_skip": 10, "max_episode_steps": 40},
                           hyperparameters={"learning_starts": 100, "policy_kwargs": {"net_arch": [16]}},
                           engine="sb3")
    on_step = training.RunCallback._on_step

    def dies_at_350(self):  # after the checkpoint at 200 and a rollout log at 320 (every 4 episodes of 40)
        if self.num_timesteps >= 350:
            raise KeyboardInterrupt
        return on_step(self)

    monkeypatch.setattr(training.RunCallback, "_on_step", dies_at_350)
    with pytest.raises(KeyboardInterrupt):
        train_student(config, tmp_path, progress=False)
    (log_dir,) = tmp_path.glob("*/tb/run_0")
    assert 320 in scalar_steps(log_dir)["rollout/ep_rew_mean"]  # logged, then lost with the kill
    monkeypatch.setattr(training.RunCallback, "_on_step", on_step)
    train_student(config, tmp_path, progress=False)  # resumes from step 200
    steps = scalar_steps(log_dir)
    # SB3's evaluation tags, each at its evaluation's step, none twice
    for tag in ("eval/mean_reward", "eval/success_rate", "eval/mean_ep_length"):
        assert steps[tag] == [200, 400, 600]
    assert steps["rollout/ep_rew_mean"] == [160, 360, 520]  # the killed run's 320 is gone
    assert all(s == sorted(set(s)) for s in steps.values())
    [hparams] = hparams_sessions(log_dir)  # logged once, by the session that started the run
    assert hparams["method"] == "td3" and hparams["steps"] == 600
    assert hparams["hyperparameters.learning_rate"] == 1e-4  # the default, as it ran
    assert hparams["hyperparameters.policy_kwargs.net_arch"] == "[16]"  # the override
    assert hparams["method.target"] == "null" and hparams["world.id"] == "CraftSuite/BlindCraftsman-Cont-v0"


def test_a_student_trains_and_is_evaluated_in_the_world_its_config_names(tmp_path, monkeypatch):
    import craftsuite.training as training

    seen = []
    real_evaluate = training.evaluate

    def evaluate(*args, env_kwargs=None, **kwargs):
        seen.append(env_kwargs)
        return real_evaluate(*args, env_kwargs=env_kwargs, **kwargs)

    monkeypatch.setattr(training, "evaluate", evaluate)
    world = {"frame_skip": 10, "max_episode_steps": 40}
    config = StudentConfig(method="td3", steps=200, eval_every=200, eval_episodes=1, world_kwargs=world,
                           hyperparameters={"learning_starts": 100, "policy_kwargs": {"net_arch": [16]},
                                            "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}},
                           engine="sb3")
    path = train_student(config, tmp_path, progress=False)
    assert {int(e["length"]) for e in read_csv(path / "episodes.csv")} == {40}  # 200 steps: 5 truncated episodes
    assert seen == [world]
    assert json.loads((path / "result.json").read_text())["env_kwargs"] == world  # for its video
    with pytest.raises(ValueError, match=r"may not set \['product'\]"):
        StudentConfig(world_kwargs={"product": False})


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
