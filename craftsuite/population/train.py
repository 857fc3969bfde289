"""Population runs: the seeds of one suite cell trained in one process, each an ordinary run.

``train_population(configs, root)`` takes the ``StudentConfig`` of every seed of one
(task, world, method) cell and trains the unfinished ones together (``engine.Population``).
Each member writes the run directory every other command reads, as ``train_student``
does: ``config.json`` (its settings, ``engine`` among them, and provenance), ``episodes.csv``,
``evals.csv``, ``progress.json``, and at the end ``model.zip`` (an SB3 agent that
``load_agent`` loads) and ``result.json``. At each evaluation every member checkpoints its
own state (``checkpoint/population.pt``: networks, optimizer moments, replay, counts,
noise), after the step's updates; a killed population resumes from the newest step every
member has a checkpoint of.
Each member also logs to TensorBoard under SB3's tag names (``scalars.Scalars``).
"""

from __future__ import annotations

import contextlib
import json
import shutil
import time
import warnings
from pathlib import Path

import numpy as np
import torch as th

from ..configs import StudentConfig
from ..files import atomic_path, atomic_write
from ..ids import world_kind
from ..methods import METHODS
from ..reached import Reached, check_automaton
from ..runs import EPISODE_FIELDS, EVAL_FIELDS, RunDir, eval_seed, reached_target
from .engine import EngineError, Population, check_supported, make_replay, sparse_width
from .envs import make_envs, observation_planes, step_records
from .scalars import Scalars

CHECKPOINT, STEP = "population.pt", "step.json"  # a member's state, and the step it was saved at


def check_cell(configs: list[StudentConfig]) -> None:
    """Raise ``EngineError`` unless ``configs`` are seeds of one cell: equal but for the seed."""
    if not configs:
        raise EngineError("a population needs at least one run")
    first = configs[0].cell()
    for c in configs[1:]:
        other = c.cell()
        differ = sorted(k for k in first if first[k] != other[k])
        if differ:
            raise EngineError(f"a population trains the seeds of one cell; these runs also differ in {differ}")
    seeds = [c.seed for c in configs]
    if len(set(seeds)) != len(seeds):
        raise EngineError(f"a population's seeds must differ, got {seeds}")


def check_device(device: str) -> th.device:
    """The torch device ``device`` names, if this machine has it (one clear line otherwise)."""
    try:
        dev = th.device(device)
    except (RuntimeError, TypeError):
        raise EngineError(f"--device {device!r} is not a torch device: use cpu or cuda") from None
    if dev.type not in ("cpu", "cuda"):
        raise EngineError(f"--device {device}: the population engine runs on cpu or cuda")
    if dev.type == "cuda" and not th.cuda.is_available():
        raise EngineError(f"--device {device}: this machine has no CUDA GPU; use --device cpu, or run on a "
                          "machine with one")
    if dev.type == "cuda" and (dev.index or 0) >= th.cuda.device_count():  # else it fails once runs are made
        raise EngineError(f"--device {device}: this machine has {th.cuda.device_count()} CUDA GPU(s), "
                          f"cuda:0 to cuda:{th.cuda.device_count() - 1}; use one of them, or --device cuda")
    return dev


def train_population(configs: list[StudentConfig], root, progress: bool = True, device: str = "cpu",
                     desc: str | None = None, on_evaluation=None, check_memory: bool = True) -> list[Path]:
    """Train every seed of one cell together; returns each config's run directory.

    ``on_evaluation(population, step, results)``, if given, is called after each
    evaluation (``results``: each member's (success, mean return, mean length), in seed
    order): the hook an experiment measures more with, as an SB3 callback would (the
    population's members, their networks and replay, are ``population``'s).
    ``check_memory``: warn where its replay at the budget exceeds the memory available
    (False where the caller has checked it with the populations beside it)."""
    from ..agents import AutomatonQTable
    from ..task_registry import resolve_task

    check_cell(configs)
    dev = check_device(device)
    config = configs[0]
    method = METHODS[config.method]
    settings = config.effective()["hyperparameters"]
    check_supported(config.method, settings)  # before any run directory exists
    root = Path(root)
    names = [c.run_name() for c in configs]
    spec = resolve_task(config.task)
    check_automaton(spec.automaton, config.task)  # before any run directory exists
    table = None
    if method.needs_table and not all((root / n / "result.json").exists() for n in names):
        if config.table is None:
            raise ValueError(f"method {config.method!r} needs a teacher's table (table.npz of a teacher run)")
        table = AutomatonQTable.load(config.table, spec.automaton)
    with contextlib.ExitStack() as stack:
        runs = [stack.enter_context(RunDir(root / n, c)) for n, c in zip(names, configs)]
        todo = [(c, r) for c, r in zip(configs, runs) if not r.finished()]
        if todo:
            _train(todo, settings, table, spec, dev, progress,
                   desc or f"{config.method} {config.task} {config.world} x{len(todo)}", on_evaluation,
                   check_memory=check_memory)
    return [root / n for n in names]


def _train(todo, settings, table, spec, device, progress, desc, on_evaluation=None, stop_at=None,
           finish=None, check_memory: bool = True) -> None:
    """Train the ``todo`` (config, run) pairs together to their budget, or until every
    member's greedy success reaches ``stop_at`` (a teacher's target); then
    ``finish(pop, k, config, run, seconds)`` each member (a student's model and result by
    default; ``seconds``: the population's wall time this session, and the member's share of
    every session's since step 0, None where a checkpoint it resumed from did not record it)."""
    from ..progress import progress_bar

    configs, runs = [c for c, _ in todo], [r for _, r in todo]
    config = configs[0]
    K, n = len(configs), config.n_envs
    start = time.perf_counter()
    stack = contextlib.ExitStack()
    envs = make_envs(config.env_id, K * n, config.env_kwargs, config.product)
    stack.callback(envs.close)
    try:
        if device.type == "cpu":
            stack.enter_context(cpu_settings())
        pop = build_population(config, [c.seed for c in configs], settings, spec, table, device, envs)
        if check_memory:
            warn_if_replay_exceeds_memory(pop)
        earlier = _resume(pop, runs)

        def shares() -> list[float | None]:
            # each member's share of the wall time since step 0: a population of K shares each
            # session's among its members, so a cell regrouped between sessions still sums right
            session = (time.perf_counter() - start) / K
            return [None if e is None else e + session for e in earlier]

        logs = [Scalars(run, pop.num_timesteps) for run in runs]
        for log in logs:
            stack.callback(log.close)
        total = config.steps
        eval_envs = make_envs(config.env_id, K * config.eval_episodes, config.env_kwargs, config.product)
        stack.callback(eval_envs.close)
        with progress_bar(K * total, desc, initial=K * pop.num_timesteps, enabled=progress) as bar:
            _loop(pop, envs, eval_envs, configs, runs, logs, bar, spec.automaton, shares, on_evaluation, stop_at)
        session, share = time.perf_counter() - start, shares()
        for k, (c, run) in enumerate(todo):
            if finish is None:
                _finish(pop, k, c, run, table, (session, share[k]), str(device))
            else:
                finish(pop, k, c, run, (session, share[k]))
    finally:
        stack.close()


def warn_if_replay_exceeds_memory(pop: Population, available: int | None = None) -> None:
    """Warn, as SB3's replay buffer does, where the population's replays at its budget would
    hold more than the machine has available now (``available`` bytes; by default Linux's
    ``MemAvailable``, within a container's memory limit; nothing said where it is unknown):
    they fill as the run goes, so such a run would be killed for memory hours in, not at its
    start. Each population sees only itself: others started beside it have filled little yet."""
    if available is None:
        available = _available_memory()
    rows = min(pop.replay.capacity, pop.total_steps)
    needed = held_at_budget(pop.replay, pop.total_steps)
    if available is not None and needed > available:
        warnings.warn(f"this population's replay will hold {needed / 2**30:.1f} GiB at its budget ({pop.K} members x "
                      f"{rows:,} transitions), more than the {available / 2**30:.1f} GiB this machine has "
                      "available: train fewer seeds a population (--members) or fewer populations at once "
                      "(--workers)", RuntimeWarning, stacklevel=2)


def warn_if_replays_exceed_memory(jobs: list[list[StudentConfig]], at_once: int, available: int | None = None) -> None:
    """Warn, before any of ``jobs`` (populations, each the configs it trains) starts, where
    the ``at_once`` largest, training side by side, would hold more replay at their budgets
    than the machine has available now (``available`` bytes; by default as
    ``warn_if_replay_exceeds_memory`` reads it): each population alone may fit where they
    together would be killed for memory hours in. Replays only, the bulk of a long run's
    memory: a process's networks and envs (a few hundred MB) and the teachers' replays (a
    Grid7 budget's) are not counted. The fixes it names fit at those sizes; smaller
    populations are more jobs, which a pool of one process a core would run more of at
    once, so ``--members`` is named with the ``--workers`` it fits at."""
    if not jobs:
        return
    if available is None:
        available = _available_memory()
    if available is None:
        return
    cells = [json.dumps(job[0].cell(), sort_keys=True) for job in jobs]
    member: dict[str, int] = {}  # one member's bytes, by cell (a population of K holds K times as much)
    for cell, job in zip(cells, jobs):
        if cell not in member:
            member[cell] = member_replay_bytes(job[0])
    sizes = sorted(((member[cell] * len(job), len(job)) for cell, job in zip(cells, jobs)), reverse=True)
    running = sizes[:at_once]
    needed = sum(size for size, _ in running)
    if needed <= available:
        return
    largest = max(member.values())
    fixes = []
    members = available // (at_once * largest)  # with populations of that many, at_once of the largest fit
    if 1 <= members < max(k for _, k in sizes):
        fixes.append(f"fewer seeds a population (--members {members} --workers {at_once})")
    fit = next((w for w in range(len(running) - 1, 0, -1) if sum(size for size, _ in running[:w]) <= available), 0)
    if fit:
        fixes.append(f"fewer populations at once (--workers {fit})")
    if not fixes:
        fixes.append("a smaller replay (buffer_size, in --dqn-hyper or --td3-hyper)")
    together = (f"the {len(running)} largest populations, training at once, will hold {needed / 2**30:.1f} GiB of "
                "replay at their budgets" if len(running) > 1 else
                f"the largest population will hold {needed / 2**30:.1f} GiB of replay at its budget")
    warnings.warn(f"{together} "
                  f"({largest / 2**30:.2f} GiB a member at most), more than the {available / 2**30:.1f} GiB this "
                  f"machine has available, and may be killed for memory hours in: train with "
                  + " or ".join(fixes), RuntimeWarning, stacklevel=2)


def member_replay_bytes(config: StudentConfig) -> int:
    """The bytes one member of ``config``'s cell holds in its replay at its budget."""
    from ..task_registry import resolve_task

    spec = resolve_task(config.task)
    envs = make_envs(config.env_id, 1, config.env_kwargs, config.product)
    try:
        replay = make_replay(config.method, config.effective()["hyperparameters"], 1, config.n_envs,
                             envs.single_observation_space.shape[0], envs.single_action_space, spec.automaton,
                             spec.completion_reward, sparse_width(spec, world_kind(config.world), config.product))
    finally:
        envs.close()
    return held_at_budget(replay, config.steps)


def held_at_budget(replay, steps: int) -> int:
    """The bytes ``replay`` holds once each member has collected ``steps`` transitions (a
    replay fills to its capacity, then overwrites)."""
    return replay.nbytes * min(replay.capacity, steps) // replay.capacity


def _available_memory(root: Path = Path("/")) -> int | None:
    """Linux's ``MemAvailable``, or less within a container's memory limit (cgroup v2's
    ``memory.max`` as the container sees it, less its ``memory.current``); None where unknown."""
    try:
        available = next(int(line.split()[1]) * 1024 for line in (root / "proc/meminfo").read_text().splitlines()
                         if line.startswith("MemAvailable:"))
    except (OSError, ValueError, IndexError, StopIteration):
        return None
    try:
        limit = (root / "sys/fs/cgroup/memory.max").read_text().strip()
        if limit != "max":
            used = int((root / "sys/fs/cgroup/memory.current").read_text())
            available = min(available, max(int(limit) - used, 0))
    except (OSError, ValueError):
        pass
    return available


def flushing_subnormals() -> bool:
    """Whether torch flushes subnormal float32s to zero on this thread now (it has no getter)."""
    return th.tensor(1e-40, dtype=th.float32).mul(1.0).item() == 0.0


@contextlib.contextmanager
def cpu_settings():
    """A CPU population's settings while it trains, the caller's restored after: one thread
    (small nets: one is fastest, and leaves the other cores to other cells) and subnormal
    floats flushed to zero. Late in a run about a sixth of the Adam moments are subnormal,
    and arithmetic on them is slow on x86: flushed, an update costs a fifth less and leaves
    the weights of 100 updates bit-identical (experiments/flush-denormal). The flush is a
    setting of the calling thread, which with one torch thread does all the training's work
    (the worlds' stepping too: MuJoCo's float64 physics runs under it as well)."""
    threads, flushing = th.get_num_threads(), flushing_subnormals()
    try:
        th.set_num_threads(1)
        th.set_flush_denormal(True)  # False where the CPU cannot (not x86): then nothing changes
        yield
    finally:
        th.set_flush_denormal(flushing)
        th.set_num_threads(threads)


def build_population(config, seeds: list[int], settings: dict, spec, table, device, envs) -> Population:
    """The population of ``config``'s cell (a student's or a teacher's) for ``seeds``, its
    spaces read from ``envs`` (any vector env of the run's world)."""
    return Population(config.method, settings, seeds, config.n_envs, envs.single_observation_space.shape[0],
                      envs.single_action_space, spec.automaton, spec.completion_reward, config.steps, table,
                      str(device), sparse_width(spec, world_kind(config.world), config.product),
                      observation_planes(config.env_id, config.env_kwargs, config.product, settings))


def _loop(pop: Population, envs, eval_envs, configs, runs, logs, bar, automaton, shares, on_evaluation=None,
          stop_at=None) -> None:
    config = configs[0]
    K, n, total, every = pop.K, pop.n_envs, config.steps, config.eval_every
    if stop_at is not None and all(reached_target(run.path, stop_at) for run in runs):
        return  # killed after the evaluation that reached it: its checkpoint is that step's
    seeds = [c.seed + j for c in configs for j in range(n)]  # as SB3's make_vec_env seeds each run's envs
    obs, _ = envs.reset(seed=seeds)
    pop.restart_noise()
    returns, lengths = np.zeros(K * n), np.zeros(K * n, dtype=np.int64)
    reached = Reached(automaton, K * n, config.task)  # every env starts an episode here
    pending: list[list[dict]] = [[] for _ in range(K)]
    next_eval = (pop.num_timesteps // every + 1) * every
    next_flush = pop.num_timesteps + 1_000
    while pop.num_timesteps < total:
        obs, rewards, ended, success, transitions = pop.step(envs, obs)
        returns += rewards
        lengths += 1
        # an ended env's transition is its episode's last (same-step autoreset), so it is
        # counted before ``take`` starts the env's next episode
        reached.step(transitions[:, 1], transitions[:, 2])
        if ended.any():
            ended_at = np.flatnonzero(ended)
            seen, states = reached.take(ended_at)
            for i, s, q in zip(ended_at.tolist(), seen, states):
                pending[i // n].append({"step": pop.num_timesteps, "return": round(float(returns[i]), 4),
                                        "length": int(lengths[i]), "success": int(success[i]),
                                        "seen": s, "states": q})
            returns[ended], lengths[ended] = 0.0, 0
        bar.update(K * n)
        t = pop.num_timesteps
        if t >= next_flush:
            _flush(runs, logs, pending, t, total)
            next_flush = t + 1_000
        evaluate = t >= next_eval or t >= total
        if evaluate:  # before this step's updates, as SB3's callback runs before its train()
            next_eval += every
            _flush(runs, logs, pending, t, total)
            results = _evaluate(pop, configs, runs, logs, t, bar, eval_envs)
            if on_evaluation is not None:
                on_evaluation(pop, t, results)
            if stop_at is not None and all(r[0] >= stop_at for r in results):
                _checkpoint(pop, runs, shares())  # a teacher's replay, which `craftsuite distill` reads again
                return  # before this step's updates, as SB3's callback stops a teacher before its train()
        pop.train()
        if evaluate:  # after them, so that a resumed population has taken every update of its steps
            _checkpoint(pop, runs, shares())


def _flush(runs, logs, pending, step: int, total: int) -> None:
    for run, log, rows in zip(runs, logs, pending):
        if rows:
            run.append("episodes.csv", EPISODE_FIELDS, rows)
            log.episodes(rows, step)
            rows.clear()
        run.write_progress(step, total)


def evaluate_members(pop: Population, config: StudentConfig, seed: int, envs=None) -> list[tuple[float, float, float]]:
    """Each member's greedy (success, mean return, mean length) over ``config.eval_episodes``
    fresh-seed episodes (seed + i, as ``training.evaluate``), all members' episodes stepped
    as one vector env: ``envs`` (K x episodes of the run's world, kept between evaluations
    by the caller, which closes it), else one made and closed here."""
    K, E = pop.K, config.eval_episodes
    own = envs is None
    if own:
        envs = make_envs(config.env_id, K * E, config.env_kwargs, config.product)
    try:
        obs, _ = envs.reset(seed=[seed + i for _ in range(K) for i in range(E)])
        active = np.ones(K * E, dtype=bool)
        returns, lengths, wins = np.zeros(K * E), np.zeros(K * E), np.zeros(K * E, dtype=bool)
        while active.any():
            actions = pop.greedy(obs.reshape(K, E, -1))
            obs, rewards, terminated, truncated, info = envs.step(actions.reshape(K * E, *actions.shape[2:]))
            ended = terminated | truncated
            _, _, success = step_records(info, ended, obs)
            returns += np.where(active, rewards, 0.0)
            lengths += active
            finishing = active & ended
            wins[finishing] = success[finishing]
            active &= ~ended
    finally:
        if own:
            envs.close()
    shape = (K, E)
    return [(float(w.mean()), float(r.mean()), float(n.mean()))
            for w, r, n in zip(wins.reshape(shape), returns.reshape(shape), lengths.reshape(shape))]


def _evaluate(pop, configs, runs, logs, step, bar, envs=None) -> list[tuple[float, float, float]]:
    config = configs[0]
    results = evaluate_members(pop, config, seed=eval_seed(step), envs=envs)
    for run, log, (success, ret, length) in zip(runs, logs, results):
        log.evaluation(step, success, ret, length)
        run.append("evals.csv", EVAL_FIELDS, [{"step": step, "success": success, "return": round(ret, 4),
                                                "episodes": config.eval_episodes, "length": round(length, 2)}])
    bar.set_postfix(success=" ".join(f"{r[0]:.2f}" for r in results))
    return results


def _checkpoint(pop: Population, runs, shares: list[float | None]) -> None:
    """Every member's state into its run's next checkpoint (``population.pt``, and
    ``step.json`` saying its step and its share of the wall time since step 0, read on resume
    without loading the state), then each committed (``RunDir.commit_checkpoint``: the one
    before is kept)."""
    for k, run in enumerate(runs):
        new = run.new_checkpoint()
        with atomic_path(new / CHECKPOINT) as tmp:
            th.save(pop.member_state(k), tmp)
        share = {} if shares[k] is None else {"seconds_share": round(shares[k], 1)}
        atomic_write(new / STEP, json.dumps({"num_timesteps": pop.num_timesteps, **share}))
    for run in runs:
        run.commit_checkpoint()


def read_member_state(path: Path) -> dict:
    """A member's checkpoint (``population.pt``), for ``Population.load_states``: on the CPU,
    since the replay's rows go into NumPy arrays (``load_states`` moves the networks' and
    optimizers' tensors to the learner's device), and mapped from the file rather than read,
    so that a resume, which loads every member before copying their rows into the replay,
    does not hold every member's rows twice. A file that is not a zip archive, as every
    checkpoint is, is damaged: it is read, so that its error says what is wrong with it."""
    with open(path, "rb") as f:
        archive = f.read(4) == b"PK\x03\x04"
    return th.load(path, weights_only=False, map_location="cpu", mmap=archive)


def saved_steps(run: Path) -> dict[int, Path]:
    """A member's complete checkpoints (its run directory's), their files by step, the newest
    directory's for a step held twice: what a population resumes from (``_resume``: the newest
    step every member holds) and what a suite announces before it does."""
    found = {}
    for folder in RunDir.checkpoints_in(run, (CHECKPOINT, STEP)):
        try:
            step = int(json.loads((folder / STEP).read_text())["num_timesteps"])
        except (OSError, ValueError, KeyError, TypeError):
            continue  # written only in part: not a checkpoint
        found.setdefault(step, folder / CHECKPOINT)
    return found


def shared_steps(found: list[dict[int, Path]]) -> set[int]:
    """The steps a population can resume from: those every member (``found``: each one's
    ``saved_steps``) holds a complete checkpoint of. Members differ after a kill between two
    of their commits, the newest step of one then not the population's."""
    return set(found[0]).intersection(*found[1:]) if found else set()


def _saved_share(checkpoint: Path) -> float | None:
    """A member's share of the wall time since step 0 that its checkpoint's ``step.json``
    records (time after a session's last checkpoint is not in it); None where it records
    none (a checkpoint written before it did): that run's time is then not known whole."""
    try:
        share = json.loads((checkpoint.parent / STEP).read_text()).get("seconds_share")
        return None if share is None else float(share)
    except (OSError, ValueError, TypeError, AttributeError):
        return None


def _resume(pop: Population, runs) -> list[float | None]:
    """Load the newest step every member has a checkpoint of that loads (a kill between two
    members' commits leaves the one before), and trim each member's logs to it. With no
    checkpoint at all, the population starts at step 0. A checkpoint that cannot be loaded
    (a truncated file, say) is passed over for the step before it, with a warning, and kept
    aside as ``checkpoint-unloadable`` (a member's newest such; its other checkpoints newer
    than the step resumed from are removed, so that the next commits keep the one resumed
    from); when no step loads, the error names each file, why, and what to do, and nothing
    is moved or deleted. So is a population whose members share no step. Returns each
    member's share of the wall time its checkpoint records (``_saved_share``; 0 from step 0)."""
    from ..runs import CheckpointError

    found = [saved_steps(run.path) for run in runs]
    if not any(found):
        for run in runs:
            run.trim_logs(0)
        return [0.0] * len(runs)
    common = shared_steps(found)
    if not common:
        raise CheckpointError(
            f"the population of {', '.join(str(r.path) for r in runs)} cannot resume: its members' checkpoints "
            f"are at different steps ({', '.join(str(sorted(f)) for f in found)}). Move their checkpoint "
            "directories aside to train them again from step 0, or choose another output directory")
    failed = []  # (run, checkpoint file, why), newest first
    for step in sorted(common, reverse=True):
        states = _load_step(pop, runs, found, step, failed)
        if states is not None:
            break
    else:
        raise CheckpointError(
            "the population cannot resume: " + "; ".join(why for _, _, why in failed) + ". Move "
            + " and ".join(str(path.parent) for _, path, _ in failed) + " aside to train it again from step 0 "
            "(its logs are trimmed to match), or choose another output directory")
    for run, steps in zip(runs, found):  # what is newer than ``step`` leaves the rotation of checkpoints
        damaged = [(path, why) for r, path, why in failed if r is run]  # newest first
        if damaged:
            aside = run.set_aside(damaged[0][0].parent)
            warnings.warn(f"{run.path}: resuming from step {step}, the newest its population loads; "
                          f"{damaged[0][1]} (kept as {aside})", RuntimeWarning, stacklevel=2)
        for newer in [path.parent for at, path in steps.items() if at > step and path.parent.exists()]:
            shutil.rmtree(newer)  # damaged too, or of the steps the population cannot resume from
    earlier = [_saved_share(steps[step]) for steps in found]  # before a commit below renames a directory
    pop.load_states(states)
    print(f"{', '.join(str(r.path) for r in runs)}: resuming from their checkpoints at step {step} "
          "(episodes logged after it are dropped and played again)")
    for run, steps in zip(runs, found):
        if steps[step].parent.name == run.CHECKPOINTS[0]:  # a kill came between its writing and its commit
            run.commit_checkpoint()  # as a single run does: the next checkpoint keeps this one
        run.trim_logs(step)
    return earlier


def _load_step(pop: Population, runs, found, step: int, failed: list) -> list[dict] | None:
    """Every member's state at ``step``, or None after adding the first that does not load
    to ``failed``."""
    from ..runs import machine_errors

    states = []
    for run, steps in zip(runs, found):
        path = steps[step]
        try:
            states.append(read_member_state(path))
        except machine_errors():
            raise  # the machine's limits, not the file's fault
        except Exception as err:  # a damaged file
            failed.append((run, path, f"{path} cannot be loaded ({type(err).__name__}: {err})"))
            return None
    return states


def save_member(pop: Population, k: int, config, path: Path, table=None) -> None:
    """Member ``k`` as an SB3 agent of its method (a student's or a teacher's config), saved
    at ``path``: what ``load_agent`` and SB3's own ``load`` open."""
    from ..agents.factory import make_agent

    hyper = config.effective()["hyperparameters"]
    # built with a replay of one row: model.zip holds none, and SB3 allocates a whole one up front
    # (CRM's, a row per live automaton state: 35 GiB on Diamond Mine's grid); the model says the run's size
    agent = make_agent(config.method, config.env_id, table=table, seed=config.seed, n_envs=1,
                       env_kwargs=config.env_kwargs, automaton_state=config.automaton_state,
                       **{**hyper, "buffer_size": 1})
    agent.buffer_size = hyper["buffer_size"]
    pop.learner.store_member(k, agent)
    agent.num_timesteps, agent.n_updates = pop.num_timesteps, pop.learner.n_updates
    if pop.learner.targets is not None:
        agent.distill = pop.learner.targets.member(k)
    with atomic_path(path) as tmp:
        agent.save(tmp)
    agent.get_env().close()


def _finish(pop: Population, k: int, config: StudentConfig, run: RunDir, table, seconds: tuple[float, float | None],
            device: str) -> None:
    """Member ``k``'s model as an SB3 agent (``model.zip``), its result, its checkpoints gone."""
    from ..configs import student_result

    save_member(pop, k, config, run.path / "model.zip", table)
    run.write_result(student_result(config, pop.learner.algorithm, pop.num_timesteps, pop.learner.n_updates, seconds,
                                    engine="population", members=pop.K, device=device))
    run.remove_checkpoints()
