"""Execution adapter: the cases on a Dask distributed cluster (the only module importing Dask).

``scheduler="tcp://HOST:PORT"`` connects to a running scheduler (``dask scheduler`` and
``dask worker`` started by hand, each worker in an environment with bioflex-jsb
installed); ``scheduler=None`` starts a :class:`distributed.LocalCluster` of ``workers``
single-threaded worker processes on loopback, which is what the tests and the benchmark use.

A worker that dies while running a case: the scheduler reruns the case elsewhere; after
``allowed_failures`` deaths it gives up (``KilledWorker``) and the case is recorded failed.
Our LocalCluster allows 1 (retried once) and gives each single-threaded worker one case at
a time (``worker-saturation`` 1.0), so only the case that was running is charged. A cluster
started by hand uses its own settings: start its scheduler with
``DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES=1`` and
``DASK_DISTRIBUTED__SCHEDULER__WORKER_SATURATION=1.0`` and its workers with ``--nthreads 1``
for the same behaviour (Dask's defaults: 3 and 1.1).
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Iterator
from typing import Any

from bioflex_jsb.sweep.campaign import Case, failed_row
from bioflex_jsb.sweep.evaluate import run_case

CONNECT_TIMEOUT_S = 10.0
WORKER_IMPORTS = ("bioflex_jsb.sweep.evaluate", "bioflex_jsb.drivers.gust")


class DaskUnavailable(RuntimeError):
    """The scheduler cannot be reached (one line)."""


class DaskExecutor:
    """Run cases on a Dask cluster; ``fn(case, log_dir) -> row``."""

    name = "dask"

    def __init__(self, scheduler: str | None = None, workers: int = 2,
                 log_dir: str | None = None,
                 fn: Callable[[Case, str | None], dict[str, Any]] = run_case) -> None:
        self.scheduler = scheduler
        self.workers = workers
        self.log_dir = log_dir
        self.fn = fn
        self.cluster = None
        self.client = None

    def __enter__(self) -> DaskExecutor:
        from distributed import Client, LocalCluster

        if self.scheduler:
            try:
                self.client = Client(self.scheduler, timeout=CONNECT_TIMEOUT_S)
            except (OSError, TimeoutError, ValueError) as exc:
                raise DaskUnavailable(
                    f"--scheduler {self.scheduler}: cannot connect "
                    f"({' '.join(str(exc).split()) or type(exc).__name__})"
                ) from None
        else:
            import dask

            # worker-saturation 1.0: a single-threaded worker holds one case at a time, so
            # when it dies only that case is charged with the death (Dask's default, 1.1,
            # queues a second case on it, which would be charged too).
            with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
                self.cluster = LocalCluster(
                    n_workers=self.workers, threads_per_worker=1, processes=True,
                    dashboard_address=None, host="127.0.0.1",
                    scheduler_kwargs={"allowed_failures": 1},
                )
            self.client = Client(self.cluster)
        self._warm_up()
        return self

    def _warm_up(self) -> None:
        """Import the simulation on every worker now (as the local forkserver does), which
        also fails early, in one line, on workers that cannot import bioflex-jsb."""
        import importlib

        try:
            for module in WORKER_IMPORTS:
                self.client.run(importlib.import_module, module)
        except (ImportError, OSError) as exc:  # the worker's environment, in one line
            self.close()
            raise DaskUnavailable(f"the Dask workers cannot import {module}: "
                                  f"{type(exc).__name__}: {' '.join(str(exc).split())}"
                                  ) from None

    def __exit__(self, *exc) -> None:
        self.close()

    def close(self) -> None:
        if self.client is not None:
            self.client.close()
            self.client = None
        if self.cluster is not None:
            self.cluster.close()
            self.cluster = None

    @property
    def n_workers(self) -> int:
        return len(self.client.scheduler_info().get("workers", {})) if self.client else 0

    def run(self, cases: list[Case]) -> Iterator[tuple[Case, dict[str, Any]]]:
        """Yield ``(case, row)`` as cases finish (in finishing order)."""
        from distributed import as_completed
        from distributed.scheduler import KilledWorker

        token = uuid.uuid4().hex[:8]
        futures = {}
        for c in cases:
            fut = self.client.submit(self.fn, c, self.log_dir, pure=False,
                                     key=f"bioflex-case-{c.case_id}-{token}")
            futures[fut.key] = (fut, c)
        remaining = dict(futures)
        try:
            for fut in as_completed([f for f, _ in futures.values()]):
                _, c = remaining.pop(fut.key)
                try:
                    row = fut.result()
                except KilledWorker as exc:
                    row = failed_row(c, f"worker died running this case, also on retry "
                                        f"(Dask KilledWorker: {exc})")
                # any other exception from a worker is a bug in the evaluation (the physics
                # stopping a case is a row, not an exception): it propagates with its
                # traceback
                fut.release()
                yield c, row
        finally:
            if remaining:
                self.client.cancel([f for f, _ in remaining.values()])
