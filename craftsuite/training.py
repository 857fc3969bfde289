"""Teachers and students as runs: a config dataclass in, a finished run directory out.

``train_teacher`` trains a product-DQN teacher on a grid until its greedy policy completes
the task on ``target_success`` of fresh-seed evaluation episodes, then distils it into the
automaton (``table.npz``). ``train_student`` trains any method of ``METHODS`` for a fixed
budget. Both are one routine (``_train``) given what differs: the agent, the world's
observation, the budget and the stop, the files and result of a finished run. Both
evaluate (on ``eval_seed``'s episodes) and checkpoint every ``eval_every`` steps into a
``RunDir``; started again on the same directory, a finished run is reused and a killed one
resumes from its last checkpoint.
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import NamedTuple

import numpy as np
import torch
from stable_baselines3.common.callbacks import BaseCallback

from .configs import StudentConfig, TeacherConfig, student_result, teacher_result
from .files import atomic_path
from .runs import (EPISODE_FIELDS, EVAL_FIELDS, EVAL_METRICS, CheckpointError, RunDir, eval_seed, hparams,
                   last_success, machine_errors, reached_target)


class Evaluation(NamedTuple):
    success: float  # the share of episodes that completed the task
    mean_return: float
    mean_length: float  # decisions per episode


def evaluate(agent, env_id: str, episodes: int, seed: int, product: bool, env_kwargs: dict | None = None,
             on_step=None) -> Evaluation:
    """Greedy episodes on fresh seeds, played side by side so that the policy sees one
    batch per step (an untrained policy that never finishes costs one batched call per
    decision of the episode limit, not ``episodes`` times as many). ``on_step(episode,
    reward, info)``, if given, sees every step (for measures beyond an ``Evaluation``'s)."""
    from .evaluation import play

    played = play(lambda _: lambda obs: agent.predict(obs, deterministic=True)[0], env_id, env_kwargs or {},
                  product, episodes, seed, on_step)
    returns = np.array([e.total_reward for e in played])
    lengths = np.array([e.length for e in played], dtype=float)
    wins = np.array([e.success for e in played])
    return Evaluation(float(wins.mean()), float(returns.mean()), float(lengths.mean()))


class RunCallback(BaseCallback):
    """Logs episodes, evaluates, checkpoints, reports progress; stops at ``stop_at`` success.

    TensorBoard gets SB3's own evaluation tags (``eval/mean_reward``, ``eval/success_rate``,
    ``eval/mean_ep_length``, as its ``EvalCallback`` writes them) and the run's settings as
    an ``HParam``, so CraftSuite runs lie beside SB3 and RL Zoo runs in one TensorBoard."""

    def __init__(self, run: RunDir, total: int, eval_every: int, eval_episodes: int, evaluate_fn,
                 stop_at: float | None = None, bar=None):
        super().__init__()
        self.run, self.total, self.eval_every, self.eval_episodes = run, total, eval_every, eval_episodes
        self.evaluate_fn, self.stop_at, self.bar = evaluate_fn, stop_at, bar
        self.pending: list[dict] = []

    def _on_training_start(self) -> None:
        from .reached import Reached
        from .task_registry import resolve_task

        # learn() starts every env's episode afresh (SB3 resets them), a resumed run's too
        task = self.run.config.task
        self.reached = Reached(resolve_task(task).automaton, self.training_env.num_envs, task)
        if self.num_timesteps > 0:  # resumed from a checkpoint
            _purge_tensorboard(self.logger, self.num_timesteps)
        else:  # once per run: a resumed run's first session logged them
            if any((self.run.path / "tb").rglob("events.out.tfevents.*")):  # killed before its first checkpoint
                _purge_tensorboard(self.logger, 0)  # its scalars and HParams go: this session starts over
            from stable_baselines3.common.logger import HParam

            self.logger.record("hparams", HParam(hparams(self.run.config), dict(EVAL_METRICS)),
                               exclude=("stdout", "log", "json", "csv"))
        self.next_eval = (self.num_timesteps // self.eval_every + 1) * self.eval_every
        self.next_flush = self.num_timesteps + 1_000
        if self.bar is not None:
            self.bar.update(self.num_timesteps - self.bar.n)

    def _on_step(self) -> bool:
        infos = self.locals["infos"]
        # an ended env's info is its episode's last step's (SB3 keeps the reset's apart)
        self.reached.step(np.array([info["label_mask"] for info in infos], dtype=np.int64),
                          np.array([info["automaton_state"] for info in infos], dtype=np.int64))
        for i, info in enumerate(infos):
            if "episode" in info:
                (seen,), (states,) = self.reached.take([i])
                self.pending.append({"step": self.num_timesteps, "return": round(float(info["episode"]["r"]), 4),
                                     "length": int(info["episode"]["l"]), "success": int(bool(info.get("is_success"))),
                                     "seen": seen, "states": states})
        if self.bar is not None:
            self.bar.update(self.num_timesteps - self.bar.n)
        if self.num_timesteps >= self.next_flush:
            self._flush()
            self.next_flush = self.num_timesteps + 1_000
        if self.num_timesteps >= self.next_eval or self.num_timesteps >= self.total:
            self.next_eval += self.eval_every
            return self._evaluate_and_checkpoint()
        return True

    def _flush(self) -> None:
        if self.pending:
            self.run.append("episodes.csv", EPISODE_FIELDS, self.pending)
            self.pending = []
        self.run.write_progress(self.num_timesteps, self.total)

    def _evaluate_and_checkpoint(self) -> bool:
        self._flush()
        result = self.evaluate_fn(self.model, self.num_timesteps)
        self.run.append("evals.csv", EVAL_FIELDS, [{"step": self.num_timesteps, "success": result.success,
                                                     "return": round(result.mean_return, 4),
                                                     "episodes": self.eval_episodes,
                                                     "length": round(result.mean_length, 2)}])
        self.logger.record("eval/mean_reward", result.mean_return)
        self.logger.record("eval/mean_ep_length", result.mean_length)
        self.logger.record("eval/success_rate", result.success)
        self.logger.dump(self.num_timesteps)  # at the evaluation's step, as SB3's EvalCallback does
        save_checkpoint(self.model, self.run)
        if self.bar is not None:
            self.bar.set_postfix(success=f"{result.success:.2f}")
        return self.stop_at is None or result.success < self.stop_at


def _purge_tensorboard(logger, step: int) -> None:
    """Have TensorBoard drop what a killed run logged after ``step``, the checkpoint resumed
    from, as trim_logs does for the CSV logs. SB3 resumes into the same TensorBoard
    directory; a session start (TensorBoard's purge marker, SummaryWriter's ``purge_step``)
    at the head of its new event file drops every earlier event at or past the marker's step."""
    from stable_baselines3.common.logger import TensorBoardOutputFormat
    from tensorboard.compat.proto.event_pb2 import Event, SessionLog

    for output in logger.output_formats:
        if isinstance(output, TensorBoardOutputFormat):
            output.writer.file_writer.add_event(Event(step=step + 1, session_log=SessionLog(status=SessionLog.START)))


def save_checkpoint(agent, run: RunDir) -> None:
    """Model and replay buffer together, into the run's next checkpoint (each file flushed
    to disk), then committed (``RunDir.commit_checkpoint`` keeps the one before)."""
    new = run.new_checkpoint()
    with atomic_path(new / "model.zip") as tmp:
        agent.save(tmp)
    with atomic_path(new / "replay.pkl") as tmp:
        agent.save_replay_buffer(tmp)
    run.commit_checkpoint()


def _resume(run: RunDir, fresh):
    """The agent of the run's newest checkpoint that loads whole (model and replay buffer,
    both from one checkpoint), or None when the run has none. A checkpoint that cannot be
    loaded (a truncated file, say) is skipped with a warning for the one before it, and kept
    aside as ``checkpoint-unloadable``, so that the next commit keeps the one resumed from;
    when none loads, the error names each file, why, and what to do. Nothing is deleted."""
    import warnings

    failed = []
    for saved in run.checkpoint_dirs():
        try:
            agent = _load_checkpoint(saved, fresh)
        except CheckpointError as err:
            failed.append((saved, str(err)))
            continue
        if failed:
            aside = run.set_aside(failed[0][0])  # the newest failure; an older one is never rotated in again
            for other, _ in failed[1:]:
                shutil.rmtree(other, ignore_errors=True)  # older than ``aside``, and unloadable too
            warnings.warn(f"{run.path}: resuming from {saved.name}, the newest checkpoint that loads; "
                          f"{failed[0][1]} (kept as {aside})", RuntimeWarning, stacklevel=3)
        if saved.name == "checkpoint-new":
            run.commit_checkpoint()  # finish the commit a kill interrupted, so the next save keeps this one
        return agent
    if failed:
        raise CheckpointError(
            f"{run.path} cannot resume: " + "; ".join(text for _, text in failed) + ". Move "
            + " and ".join(str(d) for d, _ in failed)
            + " aside to train this run again from step 0 (its logs are trimmed to match), or choose "
              "another output directory")
    return None


def _load_checkpoint(saved: Path, fresh):
    model, replay = saved / "model.zip", saved / "replay.pkl"
    try:
        agent = type(fresh).load(model, env=fresh.get_env(), device=fresh.device)
    except machine_errors():
        raise  # the machine's limits, not the file's fault: the checkpoint stays a candidate
    except Exception as err:  # a damaged zip (BadZipFile, KeyError, EOFError, ...), or spaces that differ
        raise CheckpointError(f"{model} cannot be loaded ({type(err).__name__}: {err})") from None
    try:
        agent.load_replay_buffer(replay)
    except machine_errors():
        raise
    except Exception as err:  # a truncated pickle: UnpicklingError, EOFError, ...
        raise CheckpointError(f"{replay} cannot be loaded ({type(err).__name__}: {err})") from None
    agent.replay_buffer.device = agent.device
    return agent


def _learn(run: RunDir, fresh, total: int, eval_every: int, eval_episodes: int, evaluate_fn, stop_at=None,
           progress=True, desc: str = ""):
    """Train ``fresh`` (or the run's checkpoint, if there is one) up to ``total`` steps."""
    agent = _resume(run, fresh)
    if agent is not None:
        print(f"{run.path}: resuming from its checkpoint at step {agent.num_timesteps} of {total} "
              "(episodes logged after it are dropped and played again)")
        run.trim_logs(agent.num_timesteps)
    else:
        agent = fresh
        run.trim_logs(0)
    agent.tensorboard_log = str(run.path / "tb")
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # these nets are small: one thread is faster, and leaves cores to other runs
    try:
        return _learn_loop(run, agent, total, eval_every, eval_episodes, evaluate_fn, stop_at, progress, desc)
    finally:
        torch.set_num_threads(threads)


def _learn_loop(run, agent, total, eval_every, eval_episodes, evaluate_fn, stop_at, progress, desc):
    from .progress import progress_bar

    # a resumed run's steps are counted from the start, not as this session's: its rate stays true
    with progress_bar(total, desc, initial=agent.num_timesteps, enabled=progress) as bar:
        callback = RunCallback(run, total, eval_every, eval_episodes, evaluate_fn, stop_at, bar)
        if agent.num_timesteps < total and not _stopped(run, stop_at):
            agent.learn(total - agent.num_timesteps, callback=callback, reset_num_timesteps=False,
                        tb_log_name="run")
    return agent


def _stopped(run: RunDir, stop_at) -> bool:
    return stop_at is not None and reached_target(run.path, stop_at)


def _train(config, name: str, root, fresh, *, product: bool, total: int, stop_at: float | None, model: str,
           keep_checkpoint: bool, result, progress: bool, desc: str, write_more=None) -> Path:
    """The routine of every run: train ``fresh()`` (or resume the run's checkpoint) up to
    ``total`` steps or ``stop_at`` success, evaluating greedy episodes every
    ``config.eval_every`` steps in the run's world (``product``: with the automaton state);
    then save the agent as ``model`` and what ``write_more(run, agent)`` writes beside it
    (timed with the run), write ``result(run, agent, seconds)`` as the run's result and
    remove the checkpoints (but the last with ``keep_checkpoint``)."""
    from .reached import check_automaton
    from .task_registry import resolve_task

    check_automaton(resolve_task(config.task).automaton, config.task)  # before a run directory exists
    with RunDir(Path(root) / name, config) as run:
        if run.finished():
            return run.path
        start = time.perf_counter()

        def evaluate_fn(agent, step):
            return evaluate(agent, config.env_id, config.eval_episodes, seed=eval_seed(step), product=product,
                            env_kwargs=config.env_kwargs)

        agent = _learn(run, fresh(), total, config.eval_every, config.eval_episodes, evaluate_fn, stop_at=stop_at,
                       progress=progress, desc=desc)
        with atomic_path(run.path / model) as tmp:
            agent.save(tmp)
        if write_more is not None:
            write_more(run, agent)
        run.write_result(result(run, agent, time.perf_counter() - start))
        run.remove_checkpoints(keep_last=keep_checkpoint)  # after the result: a kill before it resumes
        return run.path


def train_teacher(config: TeacherConfig, root, progress: bool = True, device: str = "cpu") -> Path:
    """A teacher run under ``root``; returns its directory (with teacher.zip and table.npz).
    ``device``: the population engine's torch device (the sb3 engine takes its settings')."""
    from .agents.factory import distill_from_replay, make_agent

    if config.engine == "population":  # a population of one
        from .population.teacher import train_teacher as train_population_teacher

        return train_population_teacher(config, root, progress=progress, device=device)

    def fresh():
        return make_agent("product-dqn", config.env_id, seed=config.seed, n_envs=config.n_envs,
                          env_kwargs=config.env_kwargs, **config.effective()["hyperparameters"])

    def write_table(run, agent):
        distill_from_replay(agent).save(run.path / "table.npz")

    def result(run, agent, seconds):
        return teacher_result(config, agent.algorithm, agent.num_timesteps, agent.n_updates,
                              last_success(run.path), seconds)

    # the name checks the hyperparameters before a run directory exists; the last checkpoint
    # stays: `craftsuite distill` reads the replay there
    return _train(config, config.run_name(), root, fresh, product=True, total=config.max_steps,
                  stop_at=config.target_success, model="teacher.zip", keep_checkpoint=True, result=result,
                  progress=progress, desc=f"teacher {config.task}", write_more=write_table)


def check_sb3_engine(config: StudentConfig) -> None:
    """Raise ValueError, naming the engine that trains it, for a run the sb3 engine does
    not: reward shaping, and n-step CRM (the SB3 agents' CRM replay holds one-step
    counterfactuals; the population engine carries each counterfactual automaton state
    through a window). New learning rules are the population engine's."""
    from .methods import METHODS

    if METHODS[config.method].shaping:
        raise ValueError(f"method {config.method!r}: reward shaping is trained by the population engine only; "
                         "use --engine population (or leave the method out: --methods)")
    n_steps = config.effective()["hyperparameters"].get("n_steps", 1)
    if METHODS[config.method].crm and n_steps != 1:
        raise ValueError(f"method {config.method!r} with n_steps {n_steps}: n-step CRM is trained by the population "
                         "engine only; use --engine population (or leave the method out: --methods)")


def train_student(config: StudentConfig, root, progress: bool = True) -> Path:
    """A student (or baseline) run under ``root``; returns its directory."""
    from .agents import AutomatonQTable
    from .agents.factory import make_agent
    from .methods import METHODS

    if config.method not in METHODS:
        raise KeyError(f"unknown method {config.method!r}; methods: {sorted(METHODS)}")
    if config.engine == "population":  # a population of one
        from .population import train_population

        return train_population([config], root, progress=progress)[0]
    check_sb3_engine(config)
    method = METHODS[config.method]
    # bad input is named before a run directory exists: the settings (run_name checks the
    # hyperparameters), and the teacher's table, which must be made for this task's automaton
    name = config.run_name()
    table = None
    if method.needs_table and not (Path(root) / name / "result.json").exists():  # a finished run needs none
        from .task_registry import resolve_task

        if config.table is None:
            raise ValueError(f"method {config.method!r} needs a teacher's table (table.npz of a teacher run)")
        table = AutomatonQTable.load(config.table, resolve_task(config.task).automaton)

    def fresh():
        return make_agent(config.method, config.env_id, table=table, seed=config.seed, n_envs=config.n_envs,
                          env_kwargs=config.env_kwargs, automaton_state=config.automaton_state,
                          **config.effective()["hyperparameters"])

    def result(run, agent, seconds):
        return student_result(config, agent.algorithm, agent.num_timesteps, agent.n_updates, seconds)

    # a finished run is reused, never resumed (a larger budget is another run): its replay
    # buffer, up to gigabytes (CRM keeps one row per live automaton state), is dead weight
    return _train(config, name, root, fresh, product=config.product, total=config.steps, stop_at=None,
                  model="model.zip", keep_checkpoint=False, result=result, progress=progress,
                  desc=f"{config.method} {config.task} s{config.seed}")
