"""Where a suite's jobs run: local worker processes or a Ray cluster, a Future per job either way.

Local workers are spawned processes (one torch thread each: they share the cores). Each
exits soon after the process that started it is gone, and ``close(abort=True)`` stops the
running ones at once (on Ray, it cancels the tasks submitted, which a cluster joined at an
address would otherwise train to the end); every run resumes from its last checkpoint when
asked for again.
"""

from __future__ import annotations

import multiprocessing as mp
import multiprocessing.connection  # mp.connection.wait: which workers have ended
import os
import sys
import threading
import time
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from .methods import external_rows, register_rows


def _exit_with(driver: int, period: float = 0.5) -> None:
    """Exit this worker soon after ``driver``, the process that started it, is gone.

    Killing ``craftsuite transfer`` with SIGTERM or SIGKILL gives it no chance to stop its
    workers; without this they would train on unseen. Their checkpoints let a rerun resume.
    """
    def watch():
        while os.getppid() == driver:  # an orphan is re-parented: its parent pid changes
            time.sleep(period)
        os._exit(1)

    threading.Thread(target=watch, name="craftsuite-driver-watch", daemon=True).start()


def _report_and_watch(driver: int, started, stopping, rows=()) -> None:
    """A local worker's initializer: report this process's pid to the pool (``started``, a
    queue), then watch the driver. A worker that reports after the pool began to stop
    (``stopping``, an event, set before the pool reads the pids) runs nothing. ``rows``:
    the method rows the driver registered from outside the package (a spawned worker
    starts with the package's rows alone)."""
    started.put(os.getpid())
    if stopping.is_set():
        os._exit(1)
    register_rows(rows)
    _exit_with(driver)


def _run_with_rows(rows, job, *args):
    """A Ray task: register ``rows``, the method rows the driver registered from outside the
    package (a Ray worker, like a spawned one, starts with the package's rows alone; a worker
    that ran one already has them, and registering a row twice is nothing), then run ``job``."""
    register_rows(rows)
    return job(*args)


def connect_ray(address: str):
    """Ray, joined to the cluster at ``address`` (``"local"``: one started in this process;
    one already joined is kept); returns the module and whether this call joined it.

    Raises:
        RuntimeError: one line naming ``--ray`` and ``address``, where Ray is not installed,
            nothing answers at the address, or Ray cannot join the cluster there.
    """
    try:
        import ray
    except ImportError:
        raise RuntimeError(f"--ray {address}: Ray is not installed here; pip install 'craftsuite[ray]', or leave "
                           "out --ray to run on local processes") from None
    if ray.is_initialized():
        return ray, False
    if address != "local":
        _check_reachable(address)
    try:
        ray.init(address=None if address == "local" else address, include_dashboard=False, log_to_driver=False,
                 ignore_reinit_error=True)
    except Exception as err:  # ConnectionError, or Ray's own errors of an address that holds no cluster
        raise RuntimeError(f"--ray {address}: no Ray cluster could be joined there ({type(err).__name__}: "
                           f"{str(err).strip().splitlines()[0] if str(err).strip() else 'no reason given'}); "
                           "give the address of a running head node, or --ray local") from None
    return ray, True


def _check_reachable(address: str, timeout: float = 5.0) -> None:
    """Raise unless something accepts a connection at ``address``'s host and port (``host:port``
    or ``ray://host:port``; other forms, e.g. ``auto``, are left to Ray): Ray itself retries
    an unreachable cluster for about 20 s, and logs a warning a second while it does."""
    import socket

    host, _, port = address.removeprefix("ray://").rpartition(":")
    if not host or not port.isdigit():
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout).close()
    except OSError as err:
        why = "no answer" if isinstance(err, TimeoutError) else (err.strerror or type(err).__name__).lower()
        raise RuntimeError(f"--ray {address}: nothing answers there ({why}); start a head node there "
                           f"(ray start --head --port {port}), give the address of a running one, or use "
                           "--ray local") from None


LOST_WAIT = 2.0  # seconds a broken pool waits for a worker to have ended


def ray_worker_lost(err: BaseException) -> str | None:
    """How a Ray worker was lost, where ``err`` is Ray's word that one was (its worker or node
    died, or Ray's memory monitor killed it), else None. Ray, when used, is imported already:
    an error of a Ray never imported is none of these."""
    exceptions = sys.modules.get("ray.exceptions")
    if exceptions is None:
        return None
    if isinstance(err, exceptions.OutOfMemoryError):
        return ("a Ray worker was killed by Ray's memory monitor (out of memory): fewer seeds to a population "
                "(--members) use less")
    if isinstance(err, (exceptions.WorkerCrashedError, exceptions.NodeDiedError, exceptions.LocalRayletDiedError)):
        return f"a Ray worker died ({type(err).__name__})"
    return None


class WorkerPool:
    """``workers`` local processes (None: one per job, up to the cores), or with ``ray`` a
    Ray cluster (``"local"`` starts one in this process, an address joins one)."""

    def __init__(self, jobs: int, workers: int | None = None, ray: str | None = None):
        self.ray, self.started, self._task = None, False, None
        self.lost: list[int] = []  # the signals that had killed local workers when the pool broke
        self._looked = False  # whether a break's workers have been looked at
        self.processes = None  # local processes, all on this machine (None on Ray: a cluster's are not counted)
        if ray is not None:
            self.ray, self.started = connect_ray(ray)
            self._rows = external_rows()
            self._refs = []  # the tasks submitted: what an abort cancels on a cluster that outlives this process
        else:
            context = mp.get_context("spawn")
            # the workers' pids, as each reports them: what an abort stops
            self._pids, self._reported, self._stopping = set(), context.SimpleQueue(), context.Event()
            self.processes = workers or max(1, min(jobs, os.cpu_count() or 1))
            self.pool = ProcessPoolExecutor(self.processes, mp_context=context,
                                            initializer=_report_and_watch,
                                            initargs=(os.getpid(), self._reported, self._stopping,
                                                      external_rows()))

    def submit(self, job, *args) -> Future:
        if self.ray is not None:
            if self._task is None:
                self._task = self.ray.remote(num_cpus=1)(_run_with_rows)
            ref = self._task.remote(self._rows, job, *args)
            self._refs.append(ref)
            return ref.future()
        future = self.pool.submit(job, *args)
        future.add_done_callback(self._note_lost)
        self._wake_manager()
        return future

    def _wake_manager(self) -> None:
        """Make the executor's manager thread look again at which workers it watches.

        ``submit`` wakes that thread before it starts the worker the new job may need, so the
        thread can go back to waiting on the workers it knew: a worker started then and later
        killed (the out-of-memory killer) would go unseen until another worker's job returned,
        hours in a suite. Woken now, with the new worker listed, it watches every worker."""
        wakeup = getattr(self.pool, "_executor_manager_thread_wakeup", None)
        lock = getattr(self.pool, "_shutdown_lock", None)
        if wakeup is not None and lock is not None:  # (the executor's own: where a Python has them not, nothing)
            with lock:  # as ``submit`` wakes it
                wakeup.wakeup()

    def _note_lost(self, future: Future) -> None:
        """Once a job has failed because the pool broke (a worker died), the signals that had
        killed workers by then (SIGKILL: the kernel's out-of-memory killer, say). The executor
        fails its jobs before it stops the workers still alive (SIGTERM), so those are not
        among them; its processes are its own attribute: where a Python has it not, none is
        known. Looked at once a break. The executor can see a dead worker's pipe close before
        the kernel has made it reapable (its exit code still None), so each worker that has
        ended (its sentinel ready; LOST_WAIT seconds at most for one to be) is reaped first;
        the live ones are not waited for."""
        if (self._looked or future.cancelled() or not isinstance(future.exception(), BrokenProcessPool)
                or not getattr(self.pool, "_broken", True)):  # a job's own BrokenProcessPool: the pool is whole
            return
        self._looked = True
        processes = list((getattr(self.pool, "_processes", None) or {}).values())
        ended = set(mp.connection.wait([p.sentinel for p in processes], timeout=LOST_WAIT)) if processes else set()
        for process in processes:
            if process.sentinel in ended:
                process.join(LOST_WAIT)
        codes = [process.exitcode for process in processes]
        self.lost = sorted({-code for code in codes if code is not None and code < 0})

    def close(self, abort: bool = False) -> None:
        """Wait for the jobs; or, with ``abort`` (a job failed, or the driver was interrupted),
        stop them now."""
        if self.ray is None:
            if abort:
                self._stopping.set()  # before the pids are read: a worker that reports later exits itself
                manager = getattr(self.pool, "_executor_manager_thread", None)  # (the executor's own)
                if getattr(self.pool, "_broken", False) and manager is not None:
                    manager.join(timeout=30)  # it ends once it has failed every job: `lost` is read by then
                else:
                    self._looked = True  # the SIGTERMs below are this pool's own, not what broke it
            self.pool.shutdown(wait=not abort, cancel_futures=True)
            if abort:  # shutdown alone would still let each running job finish (hours, in a suite)
                workers = self._workers()
                for process in workers:
                    process.terminate()
                for process in workers:  # gone, their runs' locks with them, before the caller goes on
                    process.join(timeout=30)
        else:
            if abort:  # a cluster this process joined trains on after it: its tasks are stopped by name
                for ref in self._refs:
                    self.ray.cancel(ref, force=True)  # a finished task's is nothing; a running one's worker is killed
            if self.started:
                self.ray.shutdown()

    def _workers(self) -> list[mp.process.BaseProcess]:
        """The live local workers: this process's children whose pids the workers reported."""
        while not self._reported.empty():
            self._pids.add(self._reported.get())
        return [p for p in mp.active_children() if p.pid in self._pids]
