"""Teachers on the population engine: stopped at their target, distilled from their own
replay as the SB3 teacher's network would read it, resumed after a kill, re-distilled by
``craftsuite distill``."""

import json

import numpy as np
import pytest
import torch as th

from craftsuite.agents import AutomatonQTable
from craftsuite.agents.factory import load_agent
from craftsuite.configs import TeacherConfig
from craftsuite.population import teacher as teachers
from craftsuite.runs import RunDir, read_csv
from craftsuite.task_registry import resolve_task
from craftsuite.training import train_teacher

# Reach on the fixed 7x7 instance: reached within a few thousand steps
CONFIG = TeacherConfig(task="Reach", max_steps=20_000, eval_every=1_000, eval_episodes=5, engine="population",
                       hyperparameters={"learning_starts": 500, "buffer_size": 20_000,
                                        "exploration_fraction": 0.1})


@pytest.fixture(scope="module")
def teacher_run(tmp_path_factory):
    return train_teacher(CONFIG, tmp_path_factory.mktemp("teachers"), progress=False)


def test_a_teacher_stops_at_its_target_and_writes_what_an_sb3_teacher_writes(teacher_run):
    result = json.loads((teacher_run / "result.json").read_text())
    evals = read_csv(teacher_run / "evals.csv")
    assert result["engine"] == "population" and result["reached_target"]
    assert float(evals[-1]["success"]) >= CONFIG.target_success > max(float(e["success"]) for e in evals[:-1])
    assert result["steps"] == int(evals[-1]["step"]) < CONFIG.max_steps  # stopped at the evaluation that reached it
    assert (teacher_run / "checkpoint" / teachers.CHECKPOINT).is_file()  # kept: `craftsuite distill` reads it
    assert json.loads((teacher_run / "config.json").read_text())["engine"] == "population"


def test_the_table_is_the_mean_q_of_the_taken_actions_as_the_saved_sb3_teacher_reads_them(teacher_run):
    """The table from the engine's stacked network equals the one computed by hand from the
    saved SB3 model's Q-values over the replay's (densified) observations."""
    state = th.load(teacher_run / "checkpoint" / teachers.CHECKPOINT, weights_only=False)["replay"]
    agent = load_agent(teacher_run / "teacher.zip")
    obs_dim = agent.observation_space.shape[0]
    if "observations" in state:
        obs = np.asarray(state["observations"])
    else:  # stored as their nonzero entries (padded with index 0, value 0): densified
        index, value = np.asarray(state["obs_index"]), np.asarray(state["obs_value"])
        obs = np.zeros((len(index), obs_dim), dtype=np.float32)
        np.add.at(obs, (np.arange(len(index))[:, None], index), value)
    q = agent.q_values(obs)
    taken = q[np.arange(len(obs)), np.asarray(state["actions"]).astype(int)]
    automaton = resolve_task("Reach").automaton
    sums, counts = np.zeros(automaton.delta.shape), np.zeros(automaton.delta.shape, dtype=int)
    w, sigma = np.asarray(state["w"]), np.asarray(state["sigma"])
    np.add.at(sums, (w, sigma), taken)
    np.add.at(counts, (w, sigma), 1)
    table = AutomatonQTable.load(teacher_run / "table.npz", automaton)
    assert table.kind == "dynamic" and (table.counts == counts).all() and counts.sum() == len(obs)
    seen = counts > 0
    np.testing.assert_allclose(table.q[seen], sums[seen] / counts[seen], rtol=1e-5, atol=1e-4)


def test_distill_reads_the_same_table_again_from_the_checkpoint(teacher_run, tmp_path):
    from craftsuite.cli import main

    out = tmp_path / "again.npz"
    assert main(["distill", str(teacher_run), "--out", str(out)]) == 0
    again, saved = AutomatonQTable.load(out), AutomatonQTable.load(teacher_run / "table.npz")
    assert (again.counts == saved.counts).all()
    np.testing.assert_allclose(again.q, saved.q, rtol=1e-6)


def test_a_teacher_killed_after_reaching_its_target_finishes_without_training_more(tmp_path, monkeypatch):
    """Killed between the evaluation that reached the target (and its checkpoint) and its
    result: the next call writes the model, table and result at that step."""
    def killed(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(teachers, "_finish_teacher", killed)
    with pytest.raises(KeyboardInterrupt):
        train_teacher(CONFIG, tmp_path, progress=False)
    monkeypatch.undo()
    run = tmp_path / CONFIG.run_name()
    reached = read_csv(run / "evals.csv")
    assert not (run / "result.json").exists() and float(reached[-1]["success"]) >= CONFIG.target_success
    train_teacher(CONFIG, tmp_path, progress=False)
    assert read_csv(run / "evals.csv") == reached  # no evaluation, no step more
    assert json.loads((run / "result.json").read_text())["steps"] == int(reached[-1]["step"])
    assert RunDir(run, CONFIG).finished() and (run / "table.npz").is_file()


def test_the_engine_is_part_of_a_teachers_run_key_and_sb3_keeps_the_old_one():
    from craftsuite.runs import config_dict, config_from

    sb3 = TeacherConfig(task="Reach", engine="sb3")
    assert TeacherConfig(task="Reach").engine == "population" != sb3.engine
    assert TeacherConfig(task="Reach").run_name() != sb3.run_name()
    assert "engine" not in config_dict(sb3)  # the records made before the field keep their keys
    assert config_from(TeacherConfig, config_dict(sb3)).engine == "sb3"  # and are read back as SB3 runs
    with pytest.raises(ValueError, match="engine must be one of"):
        TeacherConfig(engine="jax")
