"""Teachers on the population engine: a product-DQN population of one on its grid, stopped at
its greedy-success target, then distilled from its own replay.

``train_teacher(config, root)`` (``training.train_teacher`` for the population engine) writes:
``teacher.zip`` (an SB3 agent), ``table.npz`` (``distill``: per automaton transition (w,
sigma), the mean Q of the actions its replay took there) and ``result.json``; its last
checkpoint stays, so that ``distill_run`` (``craftsuite distill RUN``) reads the same replay
again.
"""

from __future__ import annotations

import contextlib
from pathlib import Path

import numpy as np
import torch as th

from ..agents.distillation import AutomatonQTable, dynamic_distillation
from ..configs import TeacherConfig, teacher_result
from ..reached import check_automaton
from ..runs import RunDir, last_success
from .engine import Population, check_supported
from .replay import SparseRows
from .train import CHECKPOINT, STEP, _train, build_population, check_device, read_member_state, save_member


def train_teacher(config: TeacherConfig, root, progress: bool = True, device: str = "cpu") -> Path:
    """A teacher run under ``root``, trained by the population engine; returns its directory."""
    from ..task_registry import resolve_task

    dev = check_device(device)
    settings = config.effective()["hyperparameters"]
    check_supported(config.method, settings)  # before a run directory exists
    spec = resolve_task(config.task)
    check_automaton(spec.automaton, config.task)
    with RunDir(Path(root) / config.run_name(), config) as run:
        if not run.finished():
            _train([(config, run)], settings, None, spec, dev, progress, f"teacher {config.task}",
                   stop_at=config.target_success, finish=_finish_teacher)
        return run.path


def _finish_teacher(pop: Population, k: int, config: TeacherConfig, run: RunDir,
                    seconds: tuple[float, float | None]) -> None:
    from ..task_registry import resolve_task

    distill(pop, resolve_task(config.task).automaton)[k].save(run.path / "table.npz")
    save_member(pop, k, config, run.path / "teacher.zip")
    run.write_result(teacher_result(config, pop.learner.algorithm, pop.num_timesteps, pop.learner.n_updates,
                                    last_success(run.path), seconds, engine="population"))
    run.remove_checkpoints(keep_last=True)  # after the result: a kill before it resumes


def distill(pop: Population, automaton, chunk: int = 4096) -> list[AutomatonQTable]:
    """Each member's dynamic table from its replay: the mean Q of the action taken, per
    (w, sigma) of its stored transitions (``dynamic_distillation``)."""
    if not pop.discrete:
        raise ValueError("dynamic distillation reads a DQN's Q-values; this population is TD3")
    replay, rows = pop.replay, pop.replay.size
    if rows == 0:
        raise ValueError("the teacher's replay buffer is empty: train it first")
    taken = np.empty((pop.K, rows))
    learner = pop.learner
    with th.no_grad(), learner.evaluating():  # as the greedy policy reads Q (a CNN's running statistics)
        for start in range(0, rows, chunk):
            at = slice(start, min(start + chunk, rows))
            if replay.sparse_width is None:
                obs = replay.observations[:, at]
            else:
                obs = SparseRows(replay.obs_index[:, at], replay.obs_value[:, at])
            q = learner.q_values(learner.q_net, learner.inputs(obs)).cpu().numpy()
            actions = replay.actions[:, at].astype(np.int64)
            taken[:, at] = np.take_along_axis(q, actions[..., None], axis=-1)[..., 0]
    return [dynamic_distillation(automaton, replay.w[k, :rows], replay.sigma[k, :rows], taken[k])
            for k in range(pop.K)]


def distill_run(path) -> tuple[AutomatonQTable, object]:
    """The dynamic table of the population-trained teacher run at ``path``, from the replay
    of its last checkpoint, and the task's automaton.

    Raises:
        FileNotFoundError: no checkpoint there (the message says what is missing).
    """
    from ..runs import load_config
    from ..task_registry import resolve_task
    from .envs import make_envs

    config = load_config(TeacherConfig, path)
    saved = RunDir(path, config).last_checkpoint((CHECKPOINT, STEP))
    if saved is None:
        raise FileNotFoundError(f"{path} has no checkpoint ({CHECKPOINT}, with the replay) to distil from")
    spec = resolve_task(config.task)
    with contextlib.closing(make_envs(config.env_id, 1, config.env_kwargs, True)) as envs:
        pop = build_population(config, [config.seed], config.effective()["hyperparameters"], spec, None, "cpu", envs)
    pop.load_states([read_member_state(saved / CHECKPOINT)])
    return distill(pop, spec.automaton)[0], spec.automaton
