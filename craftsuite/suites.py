"""Benchmark suites and the transfer pipeline: teacher, distillation, students, leaderboard.

A ``Suite`` is data: tasks, student worlds, methods, seeds and budgets. ``transfer`` runs
one end to end under an output directory::

    <out>/teachers/teacher-<Task>-Grid7-s0-<key>/     teacher.zip, table.npz, evals.csv
    <out>/students/student-<Task>-Cont-<method>-s<seed>-<key>/
    <out>/leaderboard.md, leaderboard.csv, curves-<Task>-<world>[-<settings>].png, best-<...>.mp4

Student runs go to local processes (``workers`` at a time) or, with ``ray``, to a Ray
cluster (``"local"`` starts one in-process; a real cluster needs ``out`` on a filesystem
every node sees). Runs that already finished are reused.
"""

from __future__ import annotations

import dataclasses
import json
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from .runs import atomic_write
from .training import StudentConfig, TeacherConfig, train_student, train_teacher

GRID_METHODS = ("dynamic", "static", "dqn", "product-dqn", "crm")
CONT_METHODS = ("td3-dynamic", "td3-static", "td3", "product-td3")


@dataclass(frozen=True)
class Suite:
    name: str
    description: str
    tasks: tuple[str, ...]
    worlds: tuple[str, ...]  # student worlds: "Cont" (MuJoCo, TD3 methods), "Grid10" (DQN methods)
    methods: tuple[str, ...]  # each runs in the worlds it is made for
    seeds: int
    student_steps: int
    teacher_max_steps: int = 300_000
    eval_every: int = 2_000
    eval_episodes: int = 10
    # overrides of each student algorithm's defaults (craftsuite.agents.methods): MuJoCo
    # students are TD3, grid students DQN, so one network size never reaches the other
    td3_hyperparameters: dict = field(default_factory=dict)
    dqn_hyperparameters: dict = field(default_factory=dict)
    # grid students learn one fixed instance, generated independently of the teacher's (layout 0),
    # as the paper's did; None gives them a new layout every episode
    grid_layout_seed: int | None = 1
    # gymnasium.make keywords of the MuJoCo students' world, e.g. {"frame_skip": 10, "max_episode_steps": 200}
    cont_world_kwargs: dict = field(default_factory=dict)

    def student_configs(self, tables: dict[str, str]) -> list[StudentConfig]:
        unknown = [m for m in self.methods if m not in GRID_METHODS + CONT_METHODS]
        if unknown:
            raise KeyError(f"unknown method(s) {unknown}; methods: {sorted(GRID_METHODS + CONT_METHODS)}")
        out = []
        for task in self.tasks:
            for world in self.worlds:
                fits = CONT_METHODS if world == "Cont" else GRID_METHODS
                for method in (m for m in self.methods if m in fits):
                    for seed in range(self.seeds):
                        out.append(StudentConfig(
                            task=task, method=method, world=world, seed=seed, steps=self.student_steps,
                            table=tables[task] if method.endswith("dynamic") else None,
                            eval_every=self.eval_every, eval_episodes=self.eval_episodes,
                            hyperparameters=dict(self.td3_hyperparameters if world == "Cont"
                                                 else self.dqn_hyperparameters),
                            layout_seed=self.grid_layout_seed if world.startswith("Grid") else None,
                            world_kwargs=dict(self.cont_world_kwargs) if world == "Cont" else {}))
        if not out:
            raise ValueError(f"no method of {list(self.methods)} runs in the worlds {list(self.worlds)} "
                             f"(grid: {list(GRID_METHODS)}; Cont: {list(CONT_METHODS)})")
        return out


SUITES = {s.name: s for s in (
    # quick runs where the teacher was measured to help on Blind Craftsman (docs/benchmarks.md,
    # "The quick suite"): a control period on the grid teacher's scale, a persistent exploration
    # noise, the teacher's values kept on the automaton's edges (rho 1, no self-loops), and a
    # small net updated every second step, so 100k steps per student fit the 15 minutes.
    Suite("quick", "Blind Craftsman: grid teacher -> MuJoCo TD3 student, dynamic distillation vs scratch "
          "(about 12 minutes on 2 cores)",
          tasks=("BlindCraftsman",), worlds=("Cont",), methods=("td3-dynamic", "td3"), seeds=2,
          student_steps=100_000, eval_every=5_000, eval_episodes=5,
          td3_hyperparameters={"rho": 1.0, "self_loops": False, "train_freq": 2,
                               "policy_kwargs": {"net_arch": [64, 64]},
                               "action_noise": {"type": "persistent", "sigma": 0.6, "resample": 0.1}},
          cont_world_kwargs={"frame_skip": 10, "max_episode_steps": 200}),
    Suite("standard", "all three tasks in MuJoCo: dynamic, static and scratch TD3, 5 seeds, 200k steps",
          tasks=("BlindCraftsman", "DungeonQuest", "DiamondMine"), worlds=("Cont",),
          methods=("td3-dynamic", "td3-static", "td3"), seeds=5, student_steps=200_000,
          eval_every=10_000, eval_episodes=20),
    Suite("paper", "everything the paper ran: grid and MuJoCo students, all baselines, 20 seeds, 2M steps",
          tasks=("BlindCraftsman", "DungeonQuest", "DiamondMine"), worlds=("Grid10", "Cont"),
          methods=GRID_METHODS + CONT_METHODS, seeds=20, student_steps=2_000_000,
          eval_every=50_000, eval_episodes=20),
)}


def _student_job(config: dict, root: str) -> str:
    """One student run in a worker process (one thread: the workers share the cores)."""
    import torch

    torch.set_num_threads(1)
    import craftsuite  # noqa: F401  (registers the ids in this process)

    return str(train_student(StudentConfig(**config), root, progress=False))


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


def run_students(configs: list[StudentConfig], root, workers: int | None = None, ray: str | None = None,
                 progress: bool = True) -> list[Path]:
    """Run students in parallel (processes or Ray) with one progress bar over all their steps."""
    from tqdm import tqdm

    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    jobs = [dataclasses.asdict(c) for c in configs]
    total = sum(c.steps for c in configs)
    with tqdm(total=total, desc=f"{len(configs)} student runs", unit="step", disable=not progress,
              dynamic_ncols=True) as bar:
        def poll():
            done = 0
            for c in configs:
                run = root / c.run_name()
                if (run / "result.json").exists():
                    done += c.steps
                elif (run / "progress.json").exists():
                    try:
                        done += json.loads((run / "progress.json").read_text())["step"]
                    except (ValueError, KeyError, OSError):
                        pass
            bar.update(done - bar.n)

        if ray is not None:
            paths = _run_on_ray(jobs, str(root), ray, poll)
        else:
            workers = workers or min(len(jobs), os.cpu_count() or 1)
            import multiprocessing as mp

            with ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn"), initializer=_exit_with,
                                     initargs=(os.getpid(),)) as pool:
                futures = [pool.submit(_student_job, job, str(root)) for job in jobs]
                while not all(f.done() for f in futures):
                    time.sleep(1.0)
                    poll()
                paths = [f.result() for f in futures]  # re-raises a worker's error
        poll()
    return [Path(p) for p in paths]


def _run_on_ray(jobs: list[dict], root: str, address: str, poll) -> list[str]:
    try:
        import ray
    except ImportError:
        raise RuntimeError("--ray needs Ray: pip install 'craftsuite[ray]'") from None
    started = not ray.is_initialized()
    if started:
        ray.init(address=None if address == "local" else address, include_dashboard=False,
                 log_to_driver=False, ignore_reinit_error=True)
    try:
        remote = ray.remote(num_cpus=1)(_student_job)
        pending = [remote.remote(job, root) for job in jobs]
        while True:
            ready, waiting = ray.wait(pending, num_returns=len(pending), timeout=1.0)
            poll()
            if not waiting:
                return ray.get(pending)
    finally:
        if started:
            ray.shutdown()


@dataclass(frozen=True)
class TransferResult:
    out: Path
    teachers: dict
    students: list
    leaderboard: Path
    plots: list
    video: Path | None


def transfer(suite: Suite, out, *, workers: int | None = None, ray: str | None = None, video: bool = True,
             progress: bool = True, log=print) -> TransferResult:
    """The suite end to end: teachers, distillation, students, leaderboard, plots, video."""
    from . import leaderboard

    _check_students(suite.student_configs({task: "" for task in suite.tasks}))  # fail before any training
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "suite.json", json.dumps(dataclasses.asdict(suite), indent=2) + "\n")
    teachers, tables = {}, {}
    for task in suite.tasks:
        config = TeacherConfig(task=task, max_steps=suite.teacher_max_steps)
        path = train_teacher(config, out / "teachers", progress=progress)
        result = json.loads((path / "result.json").read_text())
        log(f"teacher {task}: {result['steps']:,} steps, greedy success {result['success']:.2f} "
            f"({'reached' if result['reached_target'] else 'did NOT reach'} {config.target_success:.0%}) -> {path}")
        teachers[task], tables[task] = path, str((path / "table.npz").resolve())
    configs = suite.student_configs(tables)
    students = run_students(configs, out / "students", workers=workers, ray=ray, progress=progress)
    board = leaderboard.build(out / "students")
    board_md = leaderboard.write(board, out)
    plots = leaderboard.plot_curves(out / "students", out)
    log("")
    log(board_md.read_text())
    movie = None
    if video:
        movie = _best_student_video(students, out)
    return TransferResult(out, teachers, students, board_md, plots, movie)


def _check_students(configs: list[StudentConfig]) -> None:
    """Build each kind of student once, untrained, from scratch (the teachers' tables do not
    exist yet): a misspelt world setting or algorithm setting (``--env``, ``--td3-hyper``) is
    named now, not in a worker after the teachers have trained."""
    import craftsuite  # noqa: F401  (registers the ids)

    from .agents.methods import make_agent

    kinds = {(c.env_id, c.world, json.dumps(c.env_kwargs, sort_keys=True), json.dumps(c.hyperparameters, sort_keys=True))
             for c in configs}
    for env_id, world, env_kwargs, hyper in kinds:
        agent = make_agent("td3" if world == "Cont" else "dqn", env_id, env_kwargs=json.loads(env_kwargs),
                           **{**json.loads(hyper), "buffer_size": 16})
        agent.get_env().close()


def _best_student_video(students: list[Path], out: Path) -> Path | None:
    """A rollout of the best of this suite's student runs (highest final success, then
    return); runs of another config in the same directory are not candidates."""
    from .rollouts import record_video
    from .runs import read_csv

    runs = []
    for run in students:
        result = run / "result.json"
        if result.exists():
            r = json.loads(result.read_text())
            evals = read_csv(run / "evals.csv")
            last = evals[-1] if evals else {"success": 0, "return": float("-inf")}
            runs.append((float(last["success"]), float(last["return"]), run, r))
    if not runs:
        return None
    _, _, run, r = max(runs, key=lambda x: (x[0], x[1]))
    name = f"best-{r['env_id'].split('/')[1]}-{r['method']}-s{r['seed']}.mp4"
    rec = record_video(r["env_id"], str(run / r["model"]), 1, str(out / name), seed=10**8,
                       product=r["product"], progress=False, env_kwargs=r.get("env_kwargs"))
    return Path(rec.path)
