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

import contextlib
import dataclasses
import json
import os
import signal
import time
from concurrent.futures import Future
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path

from .configs import StudentConfig, TeacherConfig
from .files import atomic_write
from .ids import file_stem
from .methods import METHODS, methods_for
from .progress import progress_bar
from .runs import RunDir, read_result, teacher_outcome
from .suites import Suite
from .task_registry import carried, resolve_task
from .worker_pool import WorkerPool, ray_worker_lost


class TimeLimitReached(Exception):
    """A transfer's time limit passed with runs still training: they were stopped, each to
    resume from its population's newest checkpoint when asked for again, and the finished
    ones are kept."""


class WorkerLost(Exception):
    """A transfer's worker died while it trained (a local process killed by a signal: most
    often the kernel's out-of-memory killer, whose SIGKILL no process can catch; or a Ray
    worker, ``how`` saying what Ray said): the rest were stopped, each run resumes from its
    population's newest checkpoint when asked for again, and the finished ones are kept.
    ``status`` is a shell's for a process that signal killed (128 + its number: 137 for
    SIGKILL), so that a campaign's part takes the transfer up again as it would one killed
    itself; 1 where no signal is known."""

    def __init__(self, signals: list[int], how: str | None = None):
        self.signals = signals
        self.signal = signal.SIGKILL if signal.SIGKILL in signals else (signals[0] if signals else None)
        self.status = 1 if self.signal is None else 128 + self.signal
        super().__init__(f"{how or self._killed()}; the same command resumes the unfinished runs from their "
                         "checkpoints")

    def _killed(self) -> str:
        """What became of a local worker, by its signal."""
        if self.signal is None:
            return "a worker process ended abruptly"
        if self.signal == signal.SIGKILL:
            return ("a worker process was killed by SIGKILL, most likely out of memory: fewer seeds to a population "
                    "(--members) or populations at once (--workers) use less")
        try:
            name = signal.Signals(self.signal).name
        except ValueError:  # a real-time signal, say: no name
            name = f"signal {self.signal}"
        return f"a worker process was killed by {name}"


def _population_job(configs: list[dict], root: str, task: str | dict | None = None, device: str = "cpu",
                    check_memory: bool = True) -> list[str]:
    """The seeds of one cell in a worker process, as one population (``craftsuite.population``;
    ``check_memory`` False: the driver checked its replay's memory with the others')."""
    _start_worker(task)
    from .population import train_population

    with _quiet():
        return [str(p) for p in train_population([StudentConfig(**c) for c in configs], root, progress=False,
                                                 device=device, check_memory=check_memory)]


def cells(configs: list[StudentConfig], members: int | None = None, finished=None) -> list[list[StudentConfig]]:
    """The population engine's jobs: configs equal but for the seed, together, in order, at
    most ``members`` to a job (default: a cell's seeds all in one); each SB3 config alone (a
    finished run, reused). Smaller populations finish sooner and more of them run at once:
    on many cores, or on a GPU that one process cannot keep busy. ``finished(config)``, if
    given, says which runs train nothing: a cell's others come first, so that seeds added to
    a cell (``--seeds 27 --members 7`` over 20 finished) train as populations of ``members``
    rather than in groups counted from seed 0 (seed 20 alone, then 21-26)."""
    groups: dict[str, list[StudentConfig]] = {}
    for c in {c.run_name(): c for c in configs}.values():  # a run asked for twice is one run
        key = json.dumps(c.cell(), sort_keys=True) if c.engine == "population" else c.run_name()
        groups.setdefault(key, []).append(c)
    if finished is not None:  # (a stable sort: seed order within each side)
        groups = {key: sorted(group, key=lambda c: bool(finished(c))) for key, group in groups.items()}
    size = members or max(map(len, groups.values()), default=1)
    return [group[i:i + size] for group in groups.values() for i in range(0, len(group), size)]


def _teacher_job(config: dict, root: str, task: str | dict | None = None, device: str = "cpu") -> str:
    """One teacher run (training, then distillation) in a worker process (``device``: a
    population teacher's torch device)."""
    _start_worker(task)
    from .training import train_teacher

    with _quiet():
        return str(train_teacher(TeacherConfig(**config), root, progress=False, device=device))


@contextlib.contextmanager
def _quiet():
    """A worker's stdout dropped while it trains: the driver announces what a run would
    print (its resume) on lines of their own, where a worker's line lands inside the
    driver's progress bar (a Ray worker's stdout never reaches the driver either)."""
    with open(os.devnull, "w") as devnull, contextlib.redirect_stdout(devnull):
        yield


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
                 log=print, device: str = "cpu", pool: WorkerPool | None = None,
                 members: int | None = None, finished=None, deadline: float | None = None) -> list[Path]:
    """Run students in parallel (processes or Ray) with one progress bar over all their
    transitions: one job per population (the seeds of a cell, ``cells``); a finished run of
    the sb3 engine is reused, an unfinished one refused (``training.finished_sb3_run``).
    With ``teachers`` (by task, trained under ``teacher_root``), each teacher runs first in
    the same pool and its task's distilled students start when it is done; the other
    students start at once. ``device`` is the populations' torch device. ``pool``: the
    pool to run them in (``transfer`` makes it before it writes anything), closed here;
    else one of ``workers`` processes or on ``ray``. Reused and resumed runs are announced
    (``log``) before the bar starts, which counts their earlier steps as done before.
    ``finished(kind, paths)``, if given, is called as each teacher (``"teachers"``) and each
    population (``"students"``) finishes, with its run directories: ``transfer`` archives them
    then, so a process stopped later (a campaign's cut-off, a lost machine) loses only what
    was still training. ``deadline`` (a ``time.monotonic()`` value): once it passes, the runs
    still training are stopped and ``TimeLimitReached`` says how many."""
    root = Path(root)
    root.mkdir(parents=True, exist_ok=True)
    teachers = teachers or {}

    def trained_already(c: StudentConfig) -> bool:  # what a population skips: the engine trains the unfinished only
        return RunDir(root / c.run_name(), c).finished()

    jobs = cells(configs, members, finished=trained_already)
    waiting = {task: [job for job in jobs if job[0].task == task and METHODS[job[0].method].needs_table]
               for task in teachers}
    ready = [job for job in jobs if not (job[0].task in teachers and METHODS[job[0].method].needs_table)]
    total = sum(c.steps for c in configs)
    workers_ = pool or WorkerPool(len(jobs) + len(teachers), workers, ray)
    # local processes share this machine's memory: checked here for all at once, not again in each
    checked_here = workers_.processes is not None
    runs = [(c, root / c.run_name()) for c in configs]  # each run's directory: its name hashes its settings
    if teachers:
        _announce(log, "teacher", [[(Path(teacher_root) / t.run_name(), t.max_steps)] for t in teachers.values()],
                  teacher_root)
    start = _announce(log, "student", [[(root / c.run_name(), c.steps) for c in job] for job in jobs], root)
    if checked_here:
        from .population.train import warn_if_replays_exceed_memory

        unfinished = [[c for c in job if not trained_already(c)] for job in jobs if job[0].engine == "population"]
        warn_if_replays_exceed_memory([job for job in unfinished if job], workers_.processes)
    with progress_bar(total, f"{len(configs)} student runs", initial=sum(start.values()), enabled=progress) as bar:
        seen = {run: _stamp(run / "progress.json") for _, run in runs}  # a killed run's, until it writes anew

        def submit(job: list[StudentConfig]) -> Future:
            if job[0].engine == "population":
                return workers_.submit(_population_job, [dataclasses.asdict(c) for c in job], str(root),
                                       _carried(job[0].task), device, not checked_here)
            from .training import finished_sb3_run

            reused = Future()  # an sb3 run is reused, never trained: no worker
            try:
                reused.set_result(str(finished_sb3_run(job[0], root)))
            except Exception as err:
                reused.set_exception(err)
            return reused

        def poll():
            done = 0
            for c, run in runs:
                if (run / "result.json").exists():
                    done += c.steps
                elif _stamp(run / "progress.json") != seen[run]:  # written by this session's worker
                    done += max(_progress_step(run), start.get(run, 0))
                else:  # a resumed run replays from its checkpoint, not from the progress it had logged
                    done += start.get(run, 0)
            bar.update(done - bar.n)

        try:
            pending = {workers_.submit(_teacher_job, dataclasses.asdict(t), str(teacher_root), _carried(t.task),
                                       device if t.engine == "population" else "cpu"): task
                       for task, t in teachers.items()}
            futures = {id(job): (job, submit(job)) for job in ready}
            reported = set()  # the populations handed to ``finished``

            def check_populations():
                for key, (_, future) in futures.items():
                    if not future.done():
                        continue
                    if future.exception() is not None:
                        raise future.exception()  # a worker's error, at once rather than at the end
                    if finished is not None and key not in reported:
                        reported.add(key)
                        finished("students", [Path(p) for p in _job_runs(future.result())])

            while pending or not all(f.done() for _, f in futures.values()):
                time.sleep(0.5)
                poll()
                for future in [f for f in pending if f.done()]:
                    task = pending.pop(future)
                    path = Path(future.result())  # re-raises a teacher's error
                    if finished is not None:
                        finished("teachers", [path])
                    outcome = teacher_outcome(read_result(path), teachers[task].target_success)
                    (bar.write if progress else log)(f"teacher {task}: {outcome} -> {path}")
                    for job in waiting.pop(task):
                        futures[id(job)] = (job, submit(job))
                check_populations()
                if deadline is not None and time.monotonic() >= deadline:
                    left = [c for c, run in runs if not (run / "result.json").exists()]
                    if left or pending:  # (all finished in the last look: not stopped, done)
                        teaching = f" and {len(pending)} teacher{'s' * (len(pending) > 1)}" if pending else ""
                        raise TimeLimitReached(
                            f"time limit reached with {len(left)} of {len(configs)} student runs unfinished"
                            f"{teaching}: those training were stopped, and each resumes from its population's "
                            "newest checkpoint when the same command runs again")
            check_populations()  # those that finished after the loop's last look
            paths = {}
            for job, future in futures.values():
                for c, path in zip(job, _job_runs(future.result())):
                    paths[c.run_name()] = path
        except BaseException:
            workers_.close(abort=True)
            raise
        workers_.close()
        poll()
    return [Path(paths[c.run_name()]) for c in configs]


def _job_runs(result) -> list:
    """A job's run directories: a population's list, or a reused sb3 run's one path."""
    return result if isinstance(result, list) else [result]


def _announce(log, kind: str, populations: list[list[tuple[Path, int]]], root) -> dict[Path, int]:
    """Say, each on a line of its own, how many of the runs of ``populations`` (each its
    members' directories, each with its budget) are finished already (reused) and which
    resume from a checkpoint (and from which step: the newest their population's unfinished
    members all hold); return the step each of those starts this session from (a finished
    run's: its budget)."""
    from .population.train import saved_steps, shared_steps

    done, resumed = {}, {}
    for members in populations:
        done.update({run: budget for run, budget in members if (run / "result.json").exists()})
        todo = [run for run, _ in members if run not in done]
        step = max(shared_steps([saved_steps(run) for run in todo]), default=None)
        if step is not None:
            resumed.update(dict.fromkeys(todo, step))
    if done:
        log(f"reused {len(done)} finished {kind} run{'s' * (len(done) > 1)} from {root}")
    for run, step in resumed.items():
        log(f"resuming {run.name} from step {step:,} (its checkpoint)")
    return {**done, **resumed}


def _stamp(path: Path) -> int | None:
    """When ``path`` was last written (None: it is not there)."""
    try:
        return path.stat().st_mtime_ns
    except OSError:
        return None


def _progress_step(run: Path) -> int:
    try:
        return int(json.loads((run / "progress.json").read_text())["step"])
    except (ValueError, KeyError, TypeError, OSError):  # torn, or gone meanwhile
        return 0


@dataclass(frozen=True)
class TransferResult:
    out: Path
    teachers: dict
    students: list
    leaderboard: Path
    plots: list
    video: Path | None


def transfer(suite: Suite, out, *, workers: int | None = None, ray: str | None = None, video: bool = True,
             progress: bool = True, log=print, command: list[str] | None = None, device: str | None = None,
             archive=None, members: int | None = None, time_limit: float | None = None) -> TransferResult:
    """The suite end to end: teachers and distillation, students, leaderboard, plots, video.

    ``device``: the torch device of the population engine's students (``cpu``, the
    default, or ``cuda``). A suite of the ``sb3`` engine reuses its finished runs (from
    ``out`` or the archive) and refuses to train the others, before anything is written.
    ``command``: how this run was asked for, as ``provenance.json`` records it (the CLI
    passes its command line); by default, this Python call. ``archive``: a results archive (``craftsuite.archive``; e.g.
    ``results``): the runs it holds under ``<archive>/<suite>`` are not trained again, and
    every run that finishes here is kept there as its population (or teacher) finishes, so a
    later failure, or a kill that leaves no time to clean up, loses only what was training.
    ``time_limit``: seconds from the start after which the runs still training are stopped
    (``TimeLimitReached``; they resume when the same transfer runs again), the session
    recorded with the time it ran. A local worker process killed meanwhile (``WorkerLost``:
    the kernel's out-of-memory killer, say) stops the rest the same way.

    Bad input (a budget too small to train, a device this machine lacks, an output
    directory or archive that cannot be one, an output directory of another suite's runs,
    a Ray cluster out of reach, an sb3 run finished nowhere) is refused before anything is
    written."""
    from .archive import keep_all, restore
    from .archive import size as archive_size
    from .completion import reread_in_place
    from .provenance import record_session, start_session
    from .reporting.board import build
    from .reporting.pages import write_leaderboard
    from .reporting.plots import plot_curves

    if command is None:
        command = f"python: craftsuite.suite_runner.transfer(suite {suite.name!r}, out {str(out)!r})"
    session, clock = start_session(command), time.perf_counter()
    deadline = None if time_limit is None else time.monotonic() + time_limit
    out, configs, teachers, kept = _checked(suite, out, archive, device)
    # the pool, and a Ray cluster with it, before anything is written: one out of reach leaves no output behind
    pool = WorkerPool(len(cells(configs, members)) + len(teachers), workers, ray)
    log(f"suite {suite.name}: {suite.description}")  # (its input checked: a refused transfer says only why)
    if suite.eval_every is None and suite.student_steps is not None:  # the interval follows a budget given: say so
        every = sorted({c.eval_every for c in configs})
        log(f"(students evaluated every {' or '.join(f'{e:,}' for e in every)} transitions, a 20th of their "
            f"budget of {suite.student_steps:,}; --eval-every N sets another)")
    try:
        out.mkdir(parents=True, exist_ok=True)
        atomic_write(out / "suite.json", json.dumps(dataclasses.asdict(suite), indent=2) + "\n")
        record_session(out, session, None)  # if this session is killed, its command and commit stay on record
        names = {"teachers": {t.run_name() for t in teachers.values()}, "students": {c.run_name() for c in configs}}
        if kept is not None:
            restored = restore(kept, out, names, log=log)
            # counts what it copied: runs --out holds finished already are reused from there, said next
            log(f"results archive {kept}: {restored['students']} of {len(configs)} student runs and "
                f"{restored['teachers']} of {len(teachers)} teachers copied from it (not trained again)")
        for run in _counting_acceptance([out / "students" / name for name in sorted(names["students"])]):
            reread_in_place(run)  # (restored ones too)
            log(f"re-read {run.name}: its success counted the automaton's acceptance; now completion")
        _refuse_unfinished_sb3(out, configs, teachers.values())  # in case a restore left one out (a run in use)
        # Whether the archive records this session (in its provenance.json, with the suite as
        # run): one with runs to train always is (its time counts, finished runs or not); one
        # that trains nothing (every run reused) only once it keeps a run (one re-read here, or
        # one finished in --out that the archive lacks), so that checking a cell leaves the
        # archive as it was.
        on_record = any(not (out / kind / name / "result.json").is_file() for kind in names for name in names[kind])
    except BaseException:
        pool.close(abort=True)
        raise

    def archive_runs(kept_names: dict[str, set[str]]) -> None:
        nonlocal on_record
        try:
            now = keep_all(out, kept, kept_names, suite=dataclasses.asdict(suite), log=log, record_always=on_record)
        except Exception:
            on_record = True  # it may have kept runs before its record failed: the session's end records it
            raise
        on_record = on_record or any(now.values())

    def keep_finished(kind: str, paths: list[Path]) -> None:  # each population as it finishes
        try:
            archive_runs({kind: {p.name for p in paths}})
        except Exception as err:  # the runs train on; the end of the session tries again
            log(f"results archive {kept}: not updated ({type(err).__name__}: {err})")

    try:
        students = run_students(configs, out / "students", progress=progress, teachers=teachers,
                                teacher_root=out / "teachers", log=log, device=device or "cpu", pool=pool,
                                members=members, finished=keep_finished if kept is not None else None,
                                deadline=deadline)
    except TimeLimitReached:
        pool.close(abort=True)
        record_session(out, session, time.perf_counter() - clock)  # it ran its time: not a kill
        raise
    except BrokenProcessPool as err:  # a local worker died (run_students has stopped the rest already)
        pool.close(abort=True)
        record_session(out, session, time.perf_counter() - clock)  # this process ran to here: its time counts
        raise WorkerLost(pool.lost) from err
    except BaseException as err:
        pool.close(abort=True)  # (run_students closes it too, but not if it failed before its jobs; twice is harmless)
        how = ray_worker_lost(err)
        if how is not None:  # as a local worker's death: one line, and the same command resumes
            record_session(out, session, time.perf_counter() - clock)
            raise WorkerLost([], how) from err
        raise
    finally:  # what finished is kept, whatever stopped the rest (each population was, as it finished)
        if kept is not None:
            try:  # (the session is on record in out since it started)
                archive_runs(names)  # with the suite as run: pages read its settings
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
    record_session(out, session if on_record else {**session, "reused_only": True}, time.perf_counter() - clock)
    if kept is not None:
        # the runs are kept already: this session's duration (and its suite, where a record failed before)
        keep_all(out, kept, {}, suite=dataclasses.asdict(suite), record_always=on_record)
        log(f"results archive {kept}: {archive_size(kept) / 1e6:.1f} MB")
    return TransferResult(out, {task: out / "teachers" / t.run_name() for task, t in teachers.items()},
                          students, board_md, plots, movie)


def _counting_acceptance(runs: list[Path]) -> list[Path]:
    """The finished runs among ``runs`` whose success counted the automaton's acceptance
    (``completion``), to be re-read before they are reused.

    Raises:
        RunError: such a run unfinished (resumed, it would log two kinds of success), or one
            whose record cannot say what completed.
    """
    from .completion import needs_reread, reread_logs
    from .runs import RunError, counts_acceptance, read_config

    found = []
    for run in runs:
        config = read_config(run) if (run / "config.json").exists() else {}
        if config and counts_acceptance(config) and not (run / "result.json").exists():  # as RunDir refuses it
            raise RunError(f"{run} is an unfinished kinematic run recorded when success counted the automaton's "
                           "acceptance (record format 2): it cannot be resumed; move it aside, and it trains anew")
        if config and needs_reread(config):
            reread_logs(run, config)  # decidable, or named now
            found.append(run)
    return found


def _checked(suite: Suite, out, archive, device: str | None):
    """``transfer``'s input checked before anything is written (each refusal one line naming
    the fix): ``out`` as a Path, its student configs, its teachers, and the suite's place in
    the archive (None: no archive)."""
    from .provenance import read

    out, kept = _check_places(out, archive, suite.name)
    configs = suite.student_configs(out / "teachers")
    teachers = suite.teachers()
    check_budgets(configs, teachers)
    _check_out_suite(out, suite.name)
    _check_students(configs, device, teachers.values())  # fail before any training
    read(out)  # a damaged provenance record, too
    _counting_acceptance([out / "students" / c.run_name() for c in configs])  # none unfinished
    _refuse_sb3_not_kept(out, kept, configs, teachers.values())  # nothing written for a run it would not train
    return out, configs, teachers, kept


@dataclass(frozen=True)
class CellPlan:
    """One cell of a ``Plan``: its seeds asked, those finished already (reused), those with a
    checkpoint to resume from, and the transitions left to train (counted from each run's
    newest checkpoint; its population resumes from the newest step all its members hold,
    that or an earlier one: so at least this many)."""

    asked: int
    finished: int = 0
    resumed: int = 0
    left: int = 0


@dataclass(frozen=True)
class Plan:
    """What a transfer would train (``plan``): per cell (world, task, method), a ``CellPlan``;
    the teachers by count; the archive's records of its runs that it would skip as damaged
    (each with why: those runs train again); and its runs that a live process trains in
    ``out`` now (a transfer started now would stop at them)."""

    suite: Suite
    cells: dict[tuple[str, str, str], CellPlan]
    teachers: tuple[int, int]  # finished, asked
    skipped: tuple[str, ...] = ()
    busy: tuple[Path, ...] = ()  # unfinished runs in ``out`` that a live process trains now

    @property
    def left(self) -> int:
        return sum(cell.left for cell in self.cells.values())

    def lines(self) -> list[str]:
        """The plan in words: the records skipped, the runs busy, a line per cell, then the
        totals."""
        out = [f"suite {self.suite.name} ({self.suite.regime} learner regime), a dry run: nothing is trained or "
               "written", *(f"results archive: skipped {reason}" for reason in self.skipped),
               *(f"{run} is in use by a live run: nothing is restored into it, and a transfer started now "
                 "stops at it; wait for that run to end" for run in self.busy)]
        for (world, task, method), cell in self.cells.items():
            line = f"  {world} {task} {method}: {cell.asked} seeds, {cell.finished} finished (reused)"
            if cell.asked > cell.finished:
                line += f", {cell.asked - cell.finished} to train, "
                if cell.resumed:
                    line += f"at least {cell.left / 1e6:,.2f}M transitions ({cell.resumed} resume from a checkpoint)"
                else:
                    line += f"{cell.left / 1e6:,.2f}M transitions"
            out.append(line)
        to_train = sum(cell.asked - cell.finished for cell in self.cells.values())
        runs = sum(cell.asked for cell in self.cells.values())
        least = "at least " if any(cell.resumed for cell in self.cells.values()) else ""
        out.append(f"students: {to_train} of {runs} runs to train, {least}{self.left / 1e6:,.2f}M transitions; "
                   f"teachers: {self.teachers[1] - self.teachers[0]} of {self.teachers[1]} to train")
        return out


def plan(suite: Suite, out, *, archive=None, device: str | None = None) -> Plan:
    """What ``transfer`` with these arguments would do, with nothing trained or written: the
    suite, its settings and its places checked as ``transfer`` checks them (the same
    refusals; not the workers, which only a run starts), then each run it asks for found
    finished in ``out`` or in the archive (reused), or to train: from its newest checkpoint
    in ``out`` where it has one (its population resumes from the newest step all its
    members hold: that step, or an earlier one). A run that a live process trains in ``out``
    is named (``Plan.busy``): ``archive.restore`` leaves it alone and a transfer could not
    take it."""
    from .archive import reuse
    from .population.train import saved_steps

    out, configs, teachers, store = _checked(suite, out, archive, device)
    skipped, busy = [], []

    def finished(kind: str, name: str) -> bool:
        found, why = reuse(store, out, kind, name)
        if found == "busy":
            busy.append(out / kind / name)
        elif found == "skipped":
            skipped.append(why)
        return found in ("finished", "archived")

    counts: dict[tuple[str, str, str], list[int]] = {}
    for c in configs:
        cell = counts.setdefault((c.world, c.task, c.method), [0, 0, 0, 0])
        cell[0] += 1
        if finished("students", c.run_name()):
            cell[1] += 1
            continue
        step = max(saved_steps(out / "students" / c.run_name()), default=0)
        cell[2] += step > 0
        cell[3] += c.steps - step
    done = sum(finished("teachers", t.run_name()) for t in teachers.values())
    return Plan(suite, {key: CellPlan(*cell) for key, cell in counts.items()}, (done, len(teachers)), tuple(skipped),
                tuple(busy))


# where else a finished sb3 run can come from: ``--engine sb3`` alone turns the default archive off
ARCHIVE_FIX = ", or give --archive DIR where the finished runs are kept"


def _sb3_runs(out: Path, configs: list[StudentConfig], teachers) -> list[tuple[str, StudentConfig | TeacherConfig]]:
    """The runs of the sb3 engine not finished in ``out``, each with its kind (``teachers``,
    ``students``)."""
    runs = [*(("teachers", t) for t in teachers), *(("students", c) for c in configs)]
    return [(kind, config) for kind, config in runs
            if config.engine == "sb3" and not (out / kind / config.run_name() / "result.json").is_file()]


def _refuse_sb3_not_kept(out: Path, kept: Path | None, configs: list[StudentConfig], teachers) -> None:
    """Refuse, before anything is written, a run of the sb3 engine finished neither in
    ``out`` nor in the archive ``kept`` (None: none), whose usable runs ``archive.restore``
    copies into ``out``: that engine's runs are reused, never trained."""
    from .archive import reuse
    from .training import SB3_REFUSED

    for kind, config in _sb3_runs(out, configs, teachers):
        if reuse(kept, out, kind, config.run_name())[0] != "archived":
            raise ValueError(SB3_REFUSED.format(name=config.run_name(), also=ARCHIVE_FIX))


def _refuse_unfinished_sb3(out: Path, configs: list[StudentConfig], teachers) -> None:
    """Refuse, before any training, a run of the sb3 engine that is not finished in ``out``
    once the archive is restored there: that engine's runs are reused, never trained."""
    from .training import finished_sb3_run

    for kind, config in _sb3_runs(out, configs, teachers):
        finished_sb3_run(config, out / kind, also=ARCHIVE_FIX)  # raises, naming the run and the fix


def _check_students(configs: list[StudentConfig], device: str | None = None, teachers=()) -> None:
    """Build each kind of student once, untrained, from scratch (the teachers' tables do not
    exist yet): a misspelt world setting or algorithm setting (``--env``, ``--td3-hyper``),
    a run the population engine cannot train (a student or one of ``teachers``), or a device
    it cannot train on, is named now, not in a worker after the teachers have trained."""
    import craftsuite  # noqa: F401  (registers the ids)

    from .agents.factory import make_agent

    if any(c.engine == "population" for c in [*configs, *teachers]):
        from .population import check_supported
        from .population.envs import make_envs
        from .population.train import check_device

        check_device(device or "cpu")
        for c in [*configs, *teachers]:
            if c.engine == "population":
                check_supported(c.method, c.effective()["hyperparameters"])
        # the engine's own vector world, which refuses some keywords the single env takes (render_mode)
        for env_id, env_kwargs in {(c.env_id, json.dumps(c.env_kwargs, sort_keys=True))
                                   for c in configs if c.engine == "population"}:
            make_envs(env_id, 1, json.loads(env_kwargs), product=False).close()

    kinds = {(c.env_id, c.world, c.n_envs, json.dumps(c.env_kwargs, sort_keys=True),
              json.dumps(c.hyperparameters, sort_keys=True)) for c in configs}
    for env_id, world, n_envs, env_kwargs, hyper in kinds:
        plain = next(m for m in methods_for(world) if not METHODS[m].needs_table)
        agent = make_agent(plain, env_id, n_envs=n_envs, env_kwargs=json.loads(env_kwargs),
                           **{**json.loads(hyper), "buffer_size": 16})
        agent.get_env().close()


def check_budgets(configs: list[StudentConfig], teachers: dict[str, TeacherConfig]) -> None:
    """Refuse, before anything runs, a budget too small to train (no gradient update within
    it) and an evaluation interval longer than a student's budget (one evaluation, at its
    end) or shorter than one step of its envs; each message names the flag and the value
    that works. A teacher's interval is its own (``TeacherConfig.eval_every``): one longer
    than its budget only means it is evaluated, and may stop, at its end."""
    for task, t in teachers.items():
        settings = t.effective()["hyperparameters"]
        need = smallest_budget(settings, t.n_envs)
        if t.max_steps < need:
            raise ValueError(f"--teacher-steps {t.max_steps}: too small to train the {task} teacher, which takes no "
                             f"gradient update in its first {settings['learning_starts']:,} transitions "
                             f"(learning_starts); use --teacher-steps {need} or more")
    for c in configs:
        who = f"{c.task}'s {c.method} students ({c.world})"
        check_trains(c, who)
        if c.eval_every > c.steps:
            raise ValueError(f"an evaluation every {c.eval_every:,} transitions (--eval-every, or the suite's) is "
                             f"longer than the {c.steps:,}-transition budget of {who}, which would be evaluated only "
                             f"at their end; use --eval-every {c.steps} or less, or a larger --steps")
        if c.eval_every < c.n_envs:
            raise ValueError(f"--eval-every {c.eval_every}: shorter than one step of the {c.n_envs} envs of {who}, "
                             f"the least between two evaluations; use --eval-every {c.n_envs} or more")


def check_trains(config: StudentConfig, who: str) -> None:
    """Refuse a student's budget in which it takes no gradient update, naming ``--steps``
    and the least that trains (``who``: the runs, as the message names them)."""
    settings = config.effective()["hyperparameters"]
    need = smallest_budget(settings, config.n_envs)
    if config.steps < need:
        raise ValueError(f"--steps {config.steps}: too small to train {who}: no gradient update comes in the first "
                         f"{settings['learning_starts']:,} transitions (learning_starts); use --steps {need} or more")


def smallest_budget(settings: dict, n_envs: int) -> int:
    """The fewest transitions in which a run of these (effective) settings takes a gradient
    update: it collects ``n_envs`` a step and updates on the steps that are multiples of
    ``train_freq`` once more than ``learning_starts`` are collected (the population engine
    ends its budget on the step that reaches it)."""
    freq = settings.get("train_freq", 1)
    if isinstance(freq, (list, tuple)):  # [4, "step"]; in episodes, unknown ahead: as if every step
        freq = freq[0] if len(freq) == 2 and freq[1] == "step" else 1
    every = freq if isinstance(freq, int) and freq >= 1 else 1
    first = -(-(settings["learning_starts"] // n_envs + 1) // every) * every  # the step of the first update
    return (first - 1) * n_envs + 1


def _check_places(out, archive, suite: str) -> tuple[Path, Path | None]:
    """``out`` and the results archive (None: none) as directories to write in, else one
    line naming the flag, the path and the fix (an empty one too, before Path makes it the
    working directory); returns ``out`` and the suite's place in the archive."""
    from .files import directory_to_write

    out = directory_to_write(out, "--out")
    if archive is None:
        return out, None
    directory_to_write(archive, "--archive")
    return out, directory_to_write(Path(archive) / suite, "--archive")  # a file there, too


def _check_out_suite(out: Path, name: str) -> None:
    """Refuse an output directory that holds another suite's runs (its ``suite.json``): both
    would share one leaderboard, and the other's record of its suite would be replaced."""
    from .reporting.sources import suite_json

    held = suite_json(out).get("name")
    if held not in (None, name):
        raise ValueError(f"--out {out} holds runs of the {held} suite (its suite.json), which the {name} suite's "
                         f"would join on one leaderboard; give another --out, e.g. runs/{name}")


def _best_student_video(students: list[Path], out: Path, log=print) -> Path | None:
    """A rollout of the best of this suite's student runs (``reporting.board.best_run``);
    runs of another config in the same directory are not candidates."""
    from .reporting.board import best_run, build
    from .rollouts import record_video

    best = best_run(build(out / "students"), among=students)
    if best is None:
        return None
    run = best[0]
    r = read_result(run)
    if not (run / r["model"]).exists():
        log(f"no video: the best student, {run.name}, has its records but not its model (restored from the "
            "results archive, which keeps no models)")
        return None
    name = f"best-{file_stem(r['env_id'])}-{r['method']}-s{r['seed']}.mp4"
    rec = record_video(r["env_id"], str(run / r["model"]), 1, str(out / name), seed=10**8,
                       product=r["product"], progress=False,
                       env_kwargs={"status_panel": True, **(r.get("env_kwargs") or {})})  # for people
    return Path(rec.path)
