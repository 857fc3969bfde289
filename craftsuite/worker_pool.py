"""Where a suite's jobs run: local worker processes or a Ray cluster, a Future per job either way.

Local workers are spawned processes (one torch thread each: they share the cores). Each
exits soon after the process that started it is gone, and ``close(abort=True)`` stops the
running ones at once; every run resumes from its last checkpoint when asked for again.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import threading
import time
from concurrent.futures import Future, ProcessPoolExecutor


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


def _report_and_watch(driver: int, started, stopping) -> None:
    """A local worker's initializer: report this process's pid to the pool (``started``, a
    queue), then watch the driver. A worker that reports after the pool began to stop
    (``stopping``, an event, set before the pool reads the pids) runs nothing."""
    started.put(os.getpid())
    if stopping.is_set():
        os._exit(1)
    _exit_with(driver)


class WorkerPool:
    """``workers`` local processes (None: one per job, up to the cores), or with ``ray`` a
    Ray cluster (``"local"`` starts one in this process, an address joins one)."""

    def __init__(self, jobs: int, workers: int | None = None, ray: str | None = None):
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
            context = mp.get_context("spawn")
            # the workers' pids, as each reports them: what an abort stops
            self._pids, self._reported, self._stopping = set(), context.SimpleQueue(), context.Event()
            self.pool = ProcessPoolExecutor(workers or max(1, min(jobs, os.cpu_count() or 1)), mp_context=context,
                                            initializer=_report_and_watch,
                                            initargs=(os.getpid(), self._reported, self._stopping))

    def submit(self, job, *args) -> Future:
        if self.ray is not None:
            if job not in self.remote:
                self.remote[job] = self.ray.remote(num_cpus=1)(job)
            return self.remote[job].remote(*args).future()
        return self.pool.submit(job, *args)

    def close(self, abort: bool = False) -> None:
        """Wait for the jobs; or, with ``abort`` (a job failed, or the driver was interrupted),
        stop them now."""
        if self.ray is None:
            if abort:
                self._stopping.set()  # before the pids are read: a worker that reports later exits itself
            self.pool.shutdown(wait=not abort, cancel_futures=True)
            if abort:  # shutdown alone would still let each running job finish (hours, in a suite)
                for process in self._workers():
                    process.terminate()
        elif self.started:
            self.ray.shutdown()

    def _workers(self) -> list[mp.process.BaseProcess]:
        """The live local workers: this process's children whose pids the workers reported."""
        while not self._reported.empty():
            self._pids.add(self._reported.get())
        return [p for p in mp.active_children() if p.pid in self._pids]
