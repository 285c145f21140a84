"""Execution adapter: the cases on local worker processes (``concurrent.futures``).

Workers come from a ``forkserver`` whose process has already imported the simulation, so
a worker starts in milliseconds and holds its JSBSim airframe for every case it runs. At
most one case per worker is in flight, so when a worker process dies (``BrokenProcessPool``:
a segfault, the OOM killer) the cases in flight are exactly the suspects: each is retried
once, alone in a fresh pool, and recorded as failed if its worker dies again.

Workers die with their driver, however it ends (SIGKILL included): each pool has a
*lifeline*, a pipe whose only write end the driver holds; every worker watches the read
end in a thread and exits the moment it reads end-of-file (the kernel closes the driver's
end when the driver dies). Workers also ask the kernel for SIGKILL when their parent, the
forkserver, dies (``PR_SET_PDEATHSIG``), and the forkserver exits by itself when the driver
goes (multiprocessing's own alive pipe); the resource tracker follows once the last of
them has gone. :meth:`LocalExecutor.close` after an interruption or an environment error
closes the lifeline, so cases in flight stop at once instead of finishing unseen.

A case that raises :class:`~bioflex_jsb.sweep.campaign.RecordingError` (its log could not
be written: the machine, not the case) stops the run: the error propagates and the other
cases in flight are abandoned (they stay missing for ``--resume``).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import sys
import threading
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from bioflex_jsb.sweep.campaign import Case, RecordingError, failed_row
from bioflex_jsb.sweep.evaluate import run_case

# imported by the forkserver before it forks a worker: the simulation, and (worker_warm)
# the rest of what a case imports with the compiled step kernel loaded
PRELOAD = ["bioflex_jsb.sweep.evaluate", "bioflex_jsb.drivers.gust",
           "bioflex_jsb.sweep.worker_warm"]
# One BLAS/OpenMP thread per worker process, as Dask's nanny sets for its workers
# (distributed.nanny.pre-spawn-environ): no oversubscription of the cores, and the same
# LAPACK code path, so eigenvalues agree to the last bit between the two executors.
WORKER_ENV = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def default_workers() -> int:
    """Cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


_PR_SET_PDEATHSIG = 1


def _die_with_parent() -> None:
    """SIGKILL this process when its parent dies (Linux; nothing elsewhere)."""
    if not sys.platform.startswith("linux"):  # pragma: no cover
        return
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - no prctl: the lifeline remains
        pass


def _watch_lifeline(lifeline) -> None:
    try:
        lifeline.recv_bytes()  # nothing is ever sent: returns only at end-of-file
    except (EOFError, OSError):
        pass
    os._exit(70)  # the driver is gone (or gave up on this pool): stop now, no cleanup


def _init_worker(lifeline=None) -> None:
    # Ctrl-C goes to the whole process group: the parent stops the sweep; workers must not
    # turn it into an "interrupted" result. SIGTERM likewise is the driver's to handle.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent()
    if lifeline is not None:
        threading.Thread(target=_watch_lifeline, args=(lifeline,), name="bioflex-lifeline",
                         daemon=True).start()


class LocalExecutor:
    """Run cases on ``workers`` local processes; ``fn(case, log_dir) -> row``; a case that
    gave no row (its worker died twice, it could not be sent) is ``failed(case, error)``."""

    name = "local"

    def __init__(self, workers: int | None = None, log_dir: str | None = None,
                 fn: Callable[[Case, str | None], dict[str, Any]] = run_case,
                 failed: Callable[[Any, str], dict[str, Any]] = failed_row) -> None:
        self.workers = workers or default_workers()
        self.log_dir = log_dir
        self.fn = fn
        self.failed = failed  # failed(case, error) -> the row of a case that gave none
        self._pool: ProcessPoolExecutor | None = None
        self._lifeline = None  # the write end of the current pool's lifeline …
        self._reader = None  # … and its read end, handed to each worker as it starts
        self._ctx = multiprocessing.get_context("forkserver")
        self._ctx.set_forkserver_preload(PRELOAD)

    def __enter__(self) -> LocalExecutor:
        return self

    def _start_forkserver(self) -> None:
        """Start the forkserver (once per process) with the worker environment."""
        from multiprocessing import forkserver

        saved = {k: os.environ.get(k) for k in WORKER_ENV}
        os.environ.update(WORKER_ENV)
        try:
            forkserver.ensure_running()
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v

    def _cut_lifeline(self) -> None:
        for end in (self._lifeline, self._reader):
            if end is not None:
                end.close()
        self._lifeline = self._reader = None

    def _new_pool(self) -> ProcessPoolExecutor:
        if self._pool is not None:
            self._cut_lifeline()  # what is left of the broken pool goes
            self._pool.shutdown(wait=False, cancel_futures=True)
        self._start_forkserver()
        # the read end is pickled into each worker as it starts (workers start on demand,
        # so it stays open here until the pool goes; only the write end keeps it alive)
        self._reader, self._lifeline = self._ctx.Pipe(duplex=False)
        self._pool = ProcessPoolExecutor(self.workers, mp_context=self._ctx,
                                         initializer=_init_worker, initargs=(self._reader,))
        return self._pool

    def close(self, abandon: bool = False) -> None:
        """Shut the pool down; ``abandon``: stop the cases in flight at once (their workers
        exit) instead of letting them finish."""
        if self._pool is not None:
            if abandon:
                self._cut_lifeline()
            self._pool.shutdown(wait=not abandon, cancel_futures=True)
            self._pool = None
        self._cut_lifeline()

    def __exit__(self, exc_type, *exc) -> None:
        self.close(abandon=exc_type is not None)

    def run(self, cases: Iterable[Case]) -> Iterator[tuple[Case, dict[str, Any]]]:
        """Yield ``(case, row)`` as cases finish (in finishing order); ``cases`` is read
        lazily, a case when a worker is free. :class:`RecordingError` from a case stops."""
        pending = iter(cases)
        exhausted = False
        suspects: deque[Case] = deque()  # in flight when a worker died: retried alone
        deaths: dict[str, int] = {}
        in_flight: dict[Future, Case] = {}
        pool = self._new_pool()
        try:
            while not exhausted or suspects or in_flight:
                if suspects:
                    if not in_flight:
                        c = suspects.popleft()
                        in_flight[pool.submit(self.fn, c, self.log_dir)] = c
                else:
                    while not exhausted and len(in_flight) < self.workers:
                        c = next(pending, None)
                        if c is None:
                            exhausted = True
                            break
                        in_flight[pool.submit(self.fn, c, self.log_dir)] = c
                if not in_flight:
                    continue
                done, _ = wait(list(in_flight), return_when=FIRST_COMPLETED)
                broken = False
                lost: list[Case] = []
                for fut in done:
                    c = in_flight.pop(fut)
                    exc = fut.exception()
                    if exc is None:
                        yield c, fut.result()
                    elif isinstance(exc, BrokenProcessPool):
                        broken = True
                        lost.append(c)
                    elif isinstance(exc, KeyboardInterrupt):
                        raise KeyboardInterrupt
                    elif isinstance(exc, RecordingError):
                        raise RecordingError(str(exc))
                    elif isinstance(exc, OSError):  # the machine, not the case
                        raise RecordingError(f"case {c.case_id}: {exc.strerror or exc}")
                    else:  # e.g. the case could not be sent to the worker
                        yield c, self.failed(c, f"{type(exc).__name__}: {exc}")
                if broken:
                    lost.extend(in_flight.values())  # their futures fail the same way
                    in_flight.clear()
                    for c in lost:
                        deaths[c.case_id] = deaths.get(c.case_id, 0) + 1
                        if deaths[c.case_id] >= 2:
                            yield c, self.failed(c, "worker process died twice running this "
                                                   "case (crash or out of memory)")
                        else:
                            suspects.append(c)
                    pool = self._new_pool()
        finally:
            if in_flight:  # stopped early (Ctrl-C, an environment error, the caller): the
                self.close(abandon=True)  # cases in flight are abandoned, their workers go
