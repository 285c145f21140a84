"""Execution adapter: the cases on local worker processes (``concurrent.futures``).

Workers come from a ``forkserver`` whose process has already imported the simulation, so
a worker starts in milliseconds and holds its JSBSim airframe for every case it runs. At
most one case per worker is in flight, so when a worker process dies (``BrokenProcessPool``:
a segfault, the OOM killer) the cases in flight are exactly the suspects: each is retried
once, alone in a fresh pool, and recorded as failed if its worker dies again.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
from collections import deque
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from bioflex_jsb.sweep.campaign import Case, failed_row
from bioflex_jsb.sweep.evaluate import run_case

PRELOAD = ["bioflex_jsb.sweep.evaluate", "bioflex_jsb.drivers.gust"]
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


def _init_worker() -> None:
    # Ctrl-C goes to the whole process group: the parent stops the sweep; workers must not
    # turn it into an "interrupted" result.
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class LocalExecutor:
    """Run cases on ``workers`` local processes; ``fn(case, log_dir) -> row``."""

    name = "local"

    def __init__(self, workers: int | None = None, log_dir: str | None = None,
                 fn: Callable[[Case, str | None], dict[str, Any]] = run_case) -> None:
        self.workers = workers or default_workers()
        self.log_dir = log_dir
        self.fn = fn
        self._pool: ProcessPoolExecutor | None = None
        self._ctx = multiprocessing.get_context("forkserver")
        self._ctx.set_forkserver_preload(PRELOAD)

    def __enter__(self) -> LocalExecutor:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

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

    def _new_pool(self) -> ProcessPoolExecutor:
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
        self._start_forkserver()
        self._pool = ProcessPoolExecutor(self.workers, mp_context=self._ctx,
                                         initializer=_init_worker)
        return self._pool

    def close(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=False, cancel_futures=True)
            self._pool = None

    def run(self, cases: list[Case]) -> Iterator[tuple[Case, dict[str, Any]]]:
        """Yield ``(case, row)`` as cases finish (in finishing order)."""
        pending = deque(cases)
        suspects: deque[Case] = deque()  # in flight when a worker died: retried alone
        deaths: dict[str, int] = {}
        in_flight: dict[Future, Case] = {}
        pool = self._new_pool()
        while pending or suspects or in_flight:
            if suspects:
                if not in_flight:
                    c = suspects.popleft()
                    in_flight[pool.submit(self.fn, c, self.log_dir)] = c
            else:
                while pending and len(in_flight) < self.workers:
                    c = pending.popleft()
                    in_flight[pool.submit(self.fn, c, self.log_dir)] = c
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
                else:  # e.g. the case could not be sent to the worker
                    yield c, failed_row(c, f"{type(exc).__name__}: {exc}")
            if broken:
                lost.extend(in_flight.values())  # their futures fail the same way
                in_flight.clear()
                for c in lost:
                    deaths[c.case_id] = deaths.get(c.case_id, 0) + 1
                    if deaths[c.case_id] >= 2:
                        yield c, failed_row(c, "worker process died twice running this case "
                                               "(crash or out of memory)")
                    else:
                        suspects.append(c)
                pool = self._new_pool()
