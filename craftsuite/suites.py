"""Benchmark suites and the transfer pipeline: teachers, distillation, students, leaderboard.

A ``Suite`` is data: rungs of the task ladder (by tag or name), student worlds, methods,
seeds, a budget per rung level and each world's collection regime. ``transfer`` runs one
end to end under an output directory::

    <out>/teachers/teacher-<Task>-Grid7-s0-<key>/     teacher.zip, table.npz, evals.csv
    <out>/students/student-<Task>-Cont-<method>-s<seed>-<key>/
    <out>/leaderboard.md, leaderboard.csv, curves-<Task>-<world>[-<settings>].png, profile-<world>.png,
          best-<...>.mp4

Teachers and students share one pool of local processes (``workers`` at a time) or, with
``ray``, a Ray cluster (``"local"`` starts one in-process; a real cluster needs ``out`` on
a filesystem every node sees): students that need no teacher start at once, the others
as soon as their rung's teacher is distilled. Runs that already finished are reused.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from .configs import StudentConfig, TeacherConfig
from .ids import CONT, KINEMATIC, file_stem, world_kind
from .methods import METHODS, check_methods, methods_for
from .files import atomic_write
from .spec import TaskSpec
from .task_registry import carried, ladder, resolve_task


@dataclass(frozen=True)
class Suite:
    name: str
    description: str
    tags: tuple[str, ...] = ()  # rungs: every task with any of these tags (registration.ladder)
    tasks: tuple[str, ...] = ()  # rungs by name, besides those by tag
    worlds: tuple[str, ...] = ("Cont",)  # student worlds: "Cont" (MuJoCo), "Grid10", "Grid7"
    methods: tuple[str, ...] = ("td3",)  # each runs in the worlds its METHODS row is for
    seeds: int = 5
    # each run's budget in transitions, by world kind and rung level (TaskSpec.level), e.g.
    # {"Cont": {"easy": 150_000, "hard": 100_000}, "Grid": {...}}: the two worlds' students
    # collect at different rates and learn at different rates per transition. student_steps,
    # when set, is one budget for every run.
    budgets: dict = field(default_factory=dict)
    student_steps: int | None = None
    teacher_max_steps: int = 300_000
    # the teachers' protocol: their grid instance (None: a new layout every episode, as the
    # paper's authors' code drew), envs per gradient step and DQN overrides
    teacher_layout_seed: int | None = 0
    teacher_n_envs: int = 1
    teacher_hyperparameters: dict = field(default_factory=dict)
    eval_every: int | None = None  # None: 20 evaluations per run
    eval_episodes: int = 20
    # each world's collection regime: envs stepped side by side per agent step, and
    # overrides of its algorithm's defaults (craftsuite.agents.methods): MuJoCo students
    # are TD3, grid students DQN, so one network size never reaches the other
    td3_hyperparameters: dict = field(default_factory=dict)
    dqn_hyperparameters: dict = field(default_factory=dict)
    td3_n_envs: int = 1
    dqn_n_envs: int = 1
    # grid students learn one fixed instance, generated independently of the teacher's (layout 0),
    # as the paper's did; None gives them a new layout every episode
    grid_layout_seed: int | None = 1
    # whether the distilled students see the automaton state (their automaton enters through
    # the target either way; the authors' did not see it); the other methods keep their rows'
    students_see_automaton: bool = True
    # gymnasium.make keywords of the MuJoCo students' world beyond the registered one; the
    # leaderboard names each in its world label
    cont_world_kwargs: dict = field(default_factory=dict)
    # the same for the kinematic board (its ``size``)
    kinematic_world_kwargs: dict = field(default_factory=dict)
    # what trains the students: "population" (the seeds of each cell in one process,
    # craftsuite.population) or "sb3" (one SB3 agent per run); teachers are SB3 agents
    engine: str = "population"

    def rungs(self) -> list[TaskSpec]:
        """The suite's tasks, easiest first."""
        if not self.tags and not self.tasks:
            raise ValueError(f"suite {self.name!r} selects no rung: give it tags or tasks")
        chosen = {s.name: s for s in ladder(*self.tags)} if self.tags else {}
        chosen.update({name: resolve_task(name) for name in self.tasks})
        return sorted(chosen.values(), key=lambda s: s.rung)

    def budget(self, spec: TaskSpec, world: str) -> int:
        """A student's budget in transitions on a rung in a world."""
        if self.student_steps is not None:
            return self.student_steps
        kind = world_kind(world)
        if spec.level not in self.budgets.get(kind, {}):
            raise ValueError(f"suite {self.name!r} has no {kind} budget for {spec.name}'s level {spec.level!r} "
                             f"(tags {list(spec.tags)}); budgets: {self.budgets}. Give every run the same "
                             "budget (--steps N, Suite.student_steps) or tag the task with a level the suite has")
        return self.budgets[kind][spec.level]

    def teachers(self) -> dict[str, TeacherConfig]:
        """One grid teacher per rung whose students need a teacher's table."""
        if not any(METHODS[m].needs_table for w in self.worlds for m in methods_for(w) if m in self.methods):
            return {}  # e.g. grid-only distillers in a MuJoCo-only suite: no teacher would be used
        return {spec.name: TeacherConfig(task=spec.name, max_steps=self.teacher_max_steps,
                                         layout_seed=self.teacher_layout_seed, n_envs=self.teacher_n_envs,
                                         hyperparameters=dict(self.teacher_hyperparameters))
                for spec in self.rungs()}

    def student_configs(self, teacher_root) -> list[StudentConfig]:
        """Every student run; a distilled student reads its rung's teacher's table from
        under ``teacher_root`` (where ``transfer`` trains it first)."""
        check_methods(self.methods)
        teachers = self.teachers()
        out = []
        for spec in self.rungs():
            for world in self.worlds:
                methods = [m for m in methods_for(world) if m in self.methods]
                if not methods:
                    continue
                steps = self.budget(spec, world)
                cont = world_kind(world) == CONT
                for method in methods:
                    table = None
                    if METHODS[method].needs_table:
                        table = str((Path(teacher_root) / teachers[spec.name].run_name() / "table.npz").resolve())
                    for seed in range(self.seeds):
                        out.append(StudentConfig(
                            task=spec.name, method=method, world=world, seed=seed, steps=steps, table=table,
                            eval_every=self.eval_every or max(1, steps // 20), eval_episodes=self.eval_episodes,
                            hyperparameters=dict(self.td3_hyperparameters if cont else self.dqn_hyperparameters),
                            layout_seed=None if cont else self.grid_layout_seed,
                            # each continuous world its own keywords (MuJoCo's frame_skip, the board's size)
                            world_kwargs=dict(self.cont_world_kwargs if world == CONT else
                                              self.kinematic_world_kwargs if world == KINEMATIC else {}),
                            n_envs=self.td3_n_envs if cont else self.dqn_n_envs,
                            # hidden from distilled students where the suite says so, but for
                            # those whose counterfactual replay relabels it (crm-edges)
                            automaton_state=None if self.students_see_automaton or not METHODS[method].distill
                            or METHODS[method].crm else False, engine=self.engine))
        if not out:
            raise ValueError(f"no method of {list(self.methods)} runs in the worlds {list(self.worlds)} "
                             f"({', '.join(f'{w}: {methods_for(w)}' for w in self.worlds)})")
        return out


# The collection regimes measured to learn most per wall-clock second on two cores
# (experiments/collection-regime): TD3 collects from 10 envs per gradient update (as the
# authors collected too), with batch 256, lr 1e-3, a [64, 64] network, uniform replay and a
# persistent exploration noise; DQN from 4 envs with 2 updates per step (one update per two
# transitions) and its target network updated every 100 updates.
TD3_REGIME = dict(td3_n_envs=10, td3_hyperparameters={
    "batch_size": 256, "learning_rate": 1e-3, "policy_kwargs": {"net_arch": [64, 64]}, "prioritized": False,
    "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}})
DQN_REGIME = dict(dqn_n_envs=4, dqn_hyperparameters={"gradient_steps": 2, "target_update_interval": 200})

# The paper's authors' protocol, as their code ran it (the paper leaves most of it unsaid):
# a new layout every episode for teachers and students; 10 envs per gradient step; DQN with
# a constant epsilon of 0.1, a hard target update every 1,000 gradient steps, the squared TD
# error, importance exponent 0.9, lr 1e-3 and a residual CNN over the grid planes; TD3 with
# constant N(0, 0.2) exploration, actor delay 2 throughout, lr 3e-4, 800-600 networks and no
# importance weights; distilled students without the automaton state in their input.
# docs/decisions.md lists what CraftSuite still does otherwise.
AUTHORS_DQN = {"learning_rate": 1e-3, "buffer_size": 150_000, "batch_size": 64, "learning_starts": 1_000,
               "exploration_initial_eps": 0.1, "exploration_final_eps": 0.1, "target_update_interval": 1_000,
               "target_update_unit": "gradient_steps", "loss": "mse", "features_extractor": "residual-cnn",
               "replay_buffer_kwargs": {"beta": 0.9}}
AUTHORS_TD3 = {"learning_rate": 3e-4, "batch_size": 64, "tau": 0.005, "target_policy_noise": 0.2,
               "target_noise_clip": 0.5, "action_noise": {"type": "normal", "sigma": 0.2}, "policy_delay": 2,
               "policy_kwargs": {"net_arch": [800, 600]}, "replay_buffer_kwargs": {"beta": 0.0}}
PAPER_PROTOCOL = dict(teacher_layout_seed=None, teacher_n_envs=10, teacher_hyperparameters=AUTHORS_DQN,
                      grid_layout_seed=None, dqn_n_envs=10, dqn_hyperparameters=AUTHORS_DQN,
                      td3_n_envs=10, td3_hyperparameters=AUTHORS_TD3, students_see_automaton=False)

# The methods of the paper and its baselines (every row before the transfer method): what
# the standard and paper suites compare. The transfer method's counterfactual replay holds
# one copy of each step per automaton state, which the 1M-transition TD3 buffer cannot
# afford on Diamond Mine (13 copies of 154 numbers); the transfer suite runs it.
PAPER_METHODS = tuple(name for name, m in METHODS.items() if not (m.crm and m.distill))
TRANSFER_METHODS = ("dqn", "dynamic", "crm-edges", "td3", "td3-dynamic", "td3-crm-edges")

# Budgets, in transitions: TD3 students on the easy and medium rungs get enough to pass the
# collapse that follows their first success (greedy success falls for 30-80k transitions
# before it settles: experiments/collection-regime, "Stability"), so that the last
# evaluation reads what was learned; the hard rungs get what is left of about 3 hours
# on 2 cores for the standard suite (no TD3 student learns them in so few).
SUITES = {s.name: s for s in (
    Suite("quick", "the calibration rung and the two-stage rung in MuJoCo: TD3 from scratch and distilled "
          "(about 10 minutes on 2 cores)",
          tags=("calibration", "medium"), worlds=("Cont",), methods=("td3", "td3-dynamic-edges"), seeds=2,
          budgets={"Cont": {"easy": 200_000, "medium": 800_000}}, **TD3_REGIME),
    Suite("standard", "every rung x the paper's methods and baselines, 5 seeds (about 3 hours on 2 cores with "
          "SB3 agents; its students' rates with populations project 1.2 h)",
          tags=("easy", "medium", "hard"), worlds=("Grid10", "Cont"), methods=PAPER_METHODS, seeds=5,
          budgets={"Cont": {"easy": 250_000, "medium": 800_000, "hard": 60_000},
                   "Grid": {"easy": 30_000, "medium": 60_000, "hard": 60_000}},
          **TD3_REGIME, **DQN_REGIME),
    Suite("paper", "the paper's protocol as the authors' code ran it: the paper's methods and baselines on its tasks "
          "in the grid, MuJoCo and kinematic worlds, 20 seeds, 2M steps of 10 envs (20M transitions) per run",
          tags=("paper",), worlds=("Grid10", "Cont", "Kinematic"), methods=PAPER_METHODS, seeds=20,
          student_steps=20_000_000, eval_every=500_000, teacher_max_steps=20_000_000, **PAPER_PROTOCOL,
          engine="sb3"),  # the authors' residual CNN is not in the population engine
    # the transfer target (a distilled student at 80% greedy success in at most half the
    # transitions its algorithm needs from scratch) on the paper's three tasks: scratch, the
    # paper's method and the transfer method, in the standard suite's collection regimes, with
    # a 200k-transition replay (see PAPER_METHODS) for every TD3 method alike. A DQN's replay
    # holds its whole budget: crm-edges on Diamond Mine's grid fills about 7.5 GB (13 copies
    # of 721 numbers), so on 24 GiB run the grids with --workers 1
    Suite("transfer", "the paper's three tasks: scratch, the paper's method and the transfer method (crm-edges), "
          "Grid10 and MuJoCo, 5 seeds (about 4 hours on 2 cores)",
          tasks=("BlindCraftsman", "DungeonQuest", "DiamondMine"), worlds=("Grid10", "Cont"),
          methods=TRANSFER_METHODS, seeds=5, budgets={"Cont": {"hard": 600_000}, "Grid": {"hard": 100_000}},
          td3_n_envs=TD3_REGIME["td3_n_envs"], td3_hyperparameters={**TD3_REGIME["td3_hyperparameters"],
                                                                    "buffer_size": 200_000},
          **DQN_REGIME),
)}


def _population_job(configs: list[dict], root: str, task: str | dict | None = None, device: str = "cpu") -> list[str]:
    """The seeds of one cell in a worker process, as one population (``craftsuite.population``)."""
    _start_worker(task)
    from .population import train_population

    return [str(p) for p in train_population([StudentConfig(**c) for c in configs], root, progress=False,
                                             device=device)]


def cells(configs: list[StudentConfig]) -> list[list[StudentConfig]]:
    """The population engine's jobs: configs equal but for the seed, together, in order;
    each SB3 config alone."""
    groups: dict[str, list[StudentConfig]] = {}
    for c in {c.run_name(): c for c in configs}.values():  # a run asked for twice is one run
        key = json.dumps(c.cell(), sort_keys=True) if c.engine == "population" else c.run_name()
        groups.setdefault(key, []).append(c)
    return list(groups.values())


def _student_job(config: dict, root: str, task: str | dict | None = None) -> str:
    """One student run in a worker process (one thread: the workers share the cores);
    ``task``: its task as ``task_registry.carried`` gives it (a user task's data)."""
    _start_worker(task)
    from .training import train_student  # torch: only where runs train, not to list the suites

    return str(train_student(StudentConfig(**config), root, progress=False))


def _teacher_job(config: dict, root: str, task: str | dict | None = None) -> str:
    """One teacher run (training, then distillation) in a worker process."""
    _start_worker(task)
    from .training import train_teacher

    return str(train_teacher(TeacherConfig(**config), root, progress=False))


def _start_worker(task: str | dict | None) -> None:
    """One torch thread; the ids registered in this process, with the run's task if it is a
    user task (a spec file the driver read: a worker, or a Ray node, may not see the file)."""
    import torch

    torch.set_num_threads(1)
    import craftsuite  # (registers the built-in ids in this process)

    if isinstance(task, dict):
        craftsuite.register_task(task)


def _carried(task: str) -> str | dict:
    return carried(resolve_task(task))


def _exit_with(driver: int, period: float = 0.5) -> None:
    """Exit this worker soon after ``driver``, the process that started it, is gone.

    Killing ``craftsuite transfer`` with SIGTERM or SIGKILL gives it no chance to stop its
    workers; without this they would train on unseen. Their checkpoints let a rerun resume.
    """
    import threading

    def watch():
        while os.getppid() == driver:  # an orphan is re-parented: its parent pid changes
            time.sleep(period)
        os._exit(1)

    threading.Thread(target=watch, name="craftsuite-driver-watch", daemon=True).start()


class _Workers:
    """Where jobs run: local worker processes, or a Ray cluster; ``submit`` gives a Future either way."""

    def __init__(self, jobs: int, workers: int | None, ray: str | None):
        self.ray, self.started, self.remote = None, False, {}
        if ray is not None:
            try:
                import ray as ray_module
            except ImportError:
                raise RuntimeError("--ray needs Ray: pip install 'craftsuite[ray]'") from None
            self.ray, self.started = ray_module, not ray_module.is_initialized()
            if self.started:
                ray_module.init(address=None if ray == "local" else ray, include_dashboard=False,
                                log_to_driver=False, ignore_reinit_error=True)
        else:
            import multiprocessing as mp

            self.pool = ProcessPoolExecutor(workers or max(1, min(jobs, os.cpu_count() or 1)),
                                            mp_context=mp.get_context("spawn"), initializer=_exit_with,
                                            initargs=(os.getpid(),))

    def submit(self, job, *args) -> Future:
        if self.ray is not None:
            if job not in self.remote:
                self.remote[job] = self.ray.remote(num_cpus=1)(job)
            return self.remote[job].remote(*args).future()
        return self.pool.submit(job, *args)

    def close(self, abort: bool = False) -> None:
        """Wait for the jobs; or, with ``abort`` (a job failed, or the driver was interrupted),
        stop them now: every run resumes from its last checkpoint when asked for again."""
        if self.ray is None:
            processes = list((getattr(self.pool, "_processes", None) or {}).values())  # shutdown forgets them
            self.pool.shutdown(wait=not abort, cancel_futures=True)
            if abort:  # shutdown alone would still let each running job finish (hours, in a suite)
                for process in processes:
                    process.terminate()
        elif self.started:
            self.ray.shutdown()


def run_students(configs: list[StudentConfig], root, workers: int | None = None, ray: str | None = None,
                 progress: bool = True, teachers: dict[str, TeacherConfig] | None = None, teacher_root=None,
                 log=print, device: str = "cpu") -> list[Path]:
    """Run students in parallel (processes or Ray) with one progress bar over all their
    transitions: one job per SB3 run, one per population (the seeds of a cell, ``cells``).
    With ``teachers`` (by task, trained under ``teacher_root``), each teacher runs first in
    the same pool and its task's distilled students start when it is done; the other
    students start at once. ``device`` is the populations' torch device."""
    from tqdm import tqdm

    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    teachers = teachers or {}
    jobs = cells(configs)
    waiting = {task: [job for job in jobs if job[0].task == task and METHODS[job[0].method].needs_table]
               for task in teachers}
    ready = [job for job in jobs if not (job[0].task in teachers and METHODS[job[0].method].needs_table)]
    total = sum(c.steps for c in configs)
    workers_ = _Workers(len(jobs) + len(teachers), workers, ray)
    with tqdm(total=total, desc=f"{len(configs)} student runs", unit="step", disable=not progress,
              dynamic_ncols=True) as bar:
        runs = [(c, root / c.run_name()) for c in configs]  # named once: a name hashes the run's settings

        def submit(job: list[StudentConfig]) -> Future:
            if job[0].engine == "population":
                return workers_.submit(_population_job, [dataclasses.asdict(c) for c in job], str(root),
                                       _carried(job[0].task), device)
            return workers_.submit(_student_job, dataclasses.asdict(job[0]), str(root), _carried(job[0].task))

        def poll():
            done = 0
            for c, run in runs:
                if (run / "result.json").exists():
                    done += c.steps
                elif (run / "progress.json").exists():
                    try:
                        done += json.loads((run / "progress.json").read_text())["step"]
                    except (ValueError, KeyError, OSError):
                        pass
            bar.update(done - bar.n)

        try:
            pending = {workers_.submit(_teacher_job, dataclasses.asdict(t), str(teacher_root), _carried(t.task)): task
                       for task, t in teachers.items()}
            futures = {id(job): (job, submit(job)) for job in ready}
            while pending or not all(f.done() for _, f in futures.values()):
                time.sleep(0.5)
                poll()
                for future in [f for f in pending if f.done()]:
                    task = pending.pop(future)
                    path = Path(future.result())  # re-raises a teacher's error
                    result = json.loads((path / "result.json").read_text())
                    reached = "reached" if result["reached_target"] else "did NOT reach"
                    (bar.write if progress else log)(
                        f"teacher {task}: {result['steps']:,} steps, greedy success {result['success']:.2f} "
                        f"({reached} {teachers[task].target_success:.0%}) -> {path}")
                    for job in waiting.pop(task):
                        futures[id(job)] = (job, submit(job))
                for _, future in futures.values():
                    if future.done() and future.exception() is not None:
                        raise future.exception()  # a worker's error, at once rather than at the end
            paths = {}
            for job, future in futures.values():
                result = future.result()
                for c, path in zip(job, result if isinstance(result, list) else [result]):
                    paths[c.run_name()] = path
        except BaseException:
            workers_.close(abort=True)
            raise
        workers_.close()
        poll()
    return [Path(paths[c.run_name()]) for c in configs]


@dataclass(frozen=True)
class TransferResult:
    out: Path
    teachers: dict
    students: list
    leaderboard: Path
    plots: list
    video: Path | None


def transfer(suite: Suite, out, *, workers: int | None = None, ray: str | None = None, video: bool = True,
             progress: bool = True, log=print, command: list[str] | None = None, device: str = "cpu") -> TransferResult:
    """The suite end to end: teachers and distillation, students, leaderboard, plots, video.

    ``device``: the torch device of the population engine's students (``cpu``, ``cuda``).
    ``command``: how this run was asked for, as ``provenance.json`` records it (the CLI
    passes its command line); by default, this Python call."""
    from .provenance import read, record_session, start_session
    from .reporting.board import build
    from .reporting.pages import write_leaderboard
    from .reporting.plots import plot_curves

    if command is None:
        command = f"python: craftsuite.suites.transfer(suite {suite.name!r}, out {str(out)!r})"
    session, clock = start_session(command), time.perf_counter()
    out = Path(out)
    configs = suite.student_configs(out / "teachers")
    _check_students(configs, device)  # fail before any training
    read(out)  # a damaged provenance record, too
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "suite.json", json.dumps(dataclasses.asdict(suite), indent=2) + "\n")
    record_session(out, session, None)  # if this session is killed, its command and commit stay on record
    teachers = suite.teachers()
    students = run_students(configs, out / "students", workers=workers, ray=ray, progress=progress,
                            teachers=teachers, teacher_root=out / "teachers", log=log, device=device)
    board = build(out / "students")
    board_md = write_leaderboard(board, out)
    plots = plot_curves(board, out)
    log("")
    log(board_md.read_text())
    movie = None
    if video:
        movie = _best_student_video(students, out)
    record_session(out, session, time.perf_counter() - clock)
    return TransferResult(out, {task: out / "teachers" / t.run_name() for task, t in teachers.items()},
                          students, board_md, plots, movie)


def _check_students(configs: list[StudentConfig], device: str = "cpu") -> None:
    """Build each kind of student once, untrained, from scratch (the teachers' tables do not
    exist yet): a misspelt world setting or algorithm setting (``--env``, ``--td3-hyper``),
    or a run the population engine cannot train, is named now, not in a worker after the
    teachers have trained."""
    import craftsuite  # noqa: F401  (registers the ids)

    from .agents.methods import make_agent

    if any(c.engine == "population" for c in configs):
        from .population import check_supported
        from .population.train import check_device

        check_device(device)
        for c in configs:
            if c.engine == "population":
                check_supported(c.method, c.effective()["hyperparameters"])

    kinds = {(c.env_id, c.world, c.n_envs, json.dumps(c.env_kwargs, sort_keys=True),
              json.dumps(c.hyperparameters, sort_keys=True)) for c in configs}
    for env_id, world, n_envs, env_kwargs, hyper in kinds:
        plain = next(m for m in methods_for(world) if not METHODS[m].needs_table)
        agent = make_agent(plain, env_id, n_envs=n_envs, env_kwargs=json.loads(env_kwargs),
                           **{**json.loads(hyper), "buffer_size": 16})
        agent.get_env().close()


def _best_student_video(students: list[Path], out: Path) -> Path | None:
    """A rollout of the best of this suite's student runs (highest final success, then
    the hardest rung, then return); runs of another config in the same directory are not
    candidates."""
    from .rollouts import record_video
    from .runs import read_csv

    runs = []
    for run in students:
        result = run / "result.json"
        if result.exists():
            r = json.loads(result.read_text())
            evals = read_csv(run / "evals.csv")
            last = evals[-1] if evals else {"success": 0, "return": float("-inf")}
            level = resolve_task(r["task"]).rung[0]
            runs.append(((float(last["success"]), level, float(last["return"])), run, r))
    if not runs:
        return None
    _, run, r = max(runs, key=lambda x: x[0])
    name = f"best-{file_stem(r['env_id'])}-{r['method']}-s{r['seed']}.mp4"
    rec = record_video(r["env_id"], str(run / r["model"]), 1, str(out / name), seed=10**8,
                       product=r["product"], progress=False,
                       env_kwargs={"status_panel": True, **(r.get("env_kwargs") or {})})  # for people
    return Path(rec.path)
