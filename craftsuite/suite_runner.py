"""Running a suite (``craftsuite.suites``): teachers, distillation, students, leaderboard, video.

``transfer`` runs one end to end under an output directory::

    <out>/teachers/teacher-<Task>-Grid7-s0-<key>/     teacher.zip, table.npz, evals.csv
    <out>/students/student-<Task>-Cont-<method>-s<seed>-<key>/
    <out>/leaderboard.md, leaderboard.csv, curves-<Task>-<world>[-<settings>].png, profile-<world>.png,
          best-<...>.mp4

Teachers and students share one ``WorkerPool``: local processes (``workers`` at a time)
or, with ``ray``, a Ray cluster (``"local"`` starts one in-process; a real cluster needs
``out`` on a filesystem every node sees). Students that need no teacher start at once, the
others as soon as their rung's teacher is distilled; the population engine trains the
seeds of a cell as one job (``cells``). Runs that already finished are reused.
"""

from __future__ import annotations

import dataclasses
import json
import time
from concurrent.futures import Future
from dataclasses import dataclass
from pathlib import Path

from .configs import StudentConfig, TeacherConfig
from .files import atomic_write
from .ids import file_stem
from .methods import METHODS, methods_for
from .suites import Suite
from .task_registry import carried, resolve_task
from .worker_pool import WorkerPool


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
    workers_ = WorkerPool(len(jobs) + len(teachers), workers, ray)
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
             progress: bool = True, log=print, command: list[str] | None = None, device: str = "cpu",
             archive=None) -> TransferResult:
    """The suite end to end: teachers and distillation, students, leaderboard, plots, video.

    ``device``: the torch device of the population engine's students (``cpu``, ``cuda``).
    ``command``: how this run was asked for, as ``provenance.json`` records it (the CLI
    passes its command line); by default, this Python call. ``archive``: a results archive
    (``craftsuite.archive``; e.g. ``results``): the runs it holds under ``<archive>/<suite>``
    are not trained again, and every run that finishes here is kept there, even if a later
    one fails."""
    from .archive import keep_all, restore
    from .archive import size as archive_size
    from .provenance import read, record_session, start_session
    from .reporting.board import build
    from .reporting.pages import write_leaderboard
    from .reporting.plots import plot_curves

    if command is None:
        command = f"python: craftsuite.suite_runner.transfer(suite {suite.name!r}, out {str(out)!r})"
    session, clock = start_session(command), time.perf_counter()
    out = Path(out)
    configs = suite.student_configs(out / "teachers")
    _check_students(configs, device)  # fail before any training
    read(out)  # a damaged provenance record, too
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "suite.json", json.dumps(dataclasses.asdict(suite), indent=2) + "\n")
    record_session(out, session, None)  # if this session is killed, its command and commit stay on record
    teachers = suite.teachers()
    names = {"teachers": {t.run_name() for t in teachers.values()}, "students": {c.run_name() for c in configs}}
    kept = None if archive is None else Path(archive) / suite.name
    if kept is not None:
        restored = restore(kept, out, names, log=log)
        log(f"results archive {kept}: {restored['students']} of {len(configs)} student runs and "
            f"{restored['teachers']} of {len(teachers)} teachers are there already (not trained again)")
    try:
        students = run_students(configs, out / "students", workers=workers, ray=ray, progress=progress,
                                teachers=teachers, teacher_root=out / "teachers", log=log, device=device)
    finally:  # what finished is kept, whatever stopped the rest
        if kept is not None:
            try:  # (the session is on record in out since it started)
                keep_all(out, kept, names, suite=dataclasses.asdict(suite))  # as run: pages read its settings
            except Exception as err:  # never in place of what stopped the runs
                log(f"results archive {kept}: not updated ({type(err).__name__}: {err})")
    board = build(out / "students")
    board_md = write_leaderboard(board, out)
    plots = plot_curves(board, out)
    log("")
    log(board_md.read_text())
    movie = None
    if video:
        movie = _best_student_video(students, out, log)
    record_session(out, session, time.perf_counter() - clock)
    if kept is not None:
        keep_all(out, kept, {})  # the runs are kept already: this session's duration
        log(f"results archive {kept}: {archive_size(kept) / 1e6:.1f} MB")
    return TransferResult(out, {task: out / "teachers" / t.run_name() for task, t in teachers.items()},
                          students, board_md, plots, movie)


def _check_students(configs: list[StudentConfig], device: str = "cpu") -> None:
    """Build each kind of student once, untrained, from scratch (the teachers' tables do not
    exist yet): a misspelt world setting or algorithm setting (``--env``, ``--td3-hyper``),
    or a run the population engine cannot train, is named now, not in a worker after the
    teachers have trained."""
    import craftsuite  # noqa: F401  (registers the ids)

    from .agents.factory import make_agent

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


def _best_student_video(students: list[Path], out: Path, log=print) -> Path | None:
    """A rollout of the best of this suite's student runs (``reporting.board.best_run``);
    runs of another config in the same directory are not candidates."""
    from .reporting.board import best_run, build
    from .rollouts import record_video

    best = best_run(build(out / "students"), among=students)
    if best is None:
        return None
    run = best[0]
    r = json.loads((run / "result.json").read_text())
    if not (run / r["model"]).exists():
        log(f"no video: the best student, {run.name}, has its records but not its model (restored from the "
            "results archive, which keeps no models)")
        return None
    name = f"best-{file_stem(r['env_id'])}-{r['method']}-s{r['seed']}.mp4"
    rec = record_video(r["env_id"], str(run / r["model"]), 1, str(out / name), seed=10**8,
                       product=r["product"], progress=False,
                       env_kwargs={"status_panel": True, **(r.get("env_kwargs") or {})})  # for people
    return Path(rec.path)
