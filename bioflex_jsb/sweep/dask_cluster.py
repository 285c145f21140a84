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

Cases are submitted lazily, a bounded window ahead of the workers (a million-case campaign
does not become a million futures). What stops a run instead of being recorded
(:class:`~bioflex_jsb.sweep.campaign.RecordingError`; the cases stay missing for
``--resume``, docs/reliability.md): a case's own RecordingError (its log could not be
written), the scheduler lost (the client cancels every future: ``scheduler-connection-lost``),
and no worker at all for :attr:`DaskExecutor.no_workers_s` seconds (every worker gone and
none coming back: the scheduler would wait forever). The LocalCluster's worker processes
die with the driver: Dask's own nanny watches its parent through a pipe.
"""

from __future__ import annotations

import logging
import time
import uuid
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import CancelledError
from typing import Any

from bioflex_jsb.sweep.campaign import Case, RecordingError, failed_row
from bioflex_jsb.sweep.evaluate import run_case

CONNECT_TIMEOUT_S = 10.0
POLL_S = 1.0  # how often a waiting driver looks at the cluster's workers
WORKER_IMPORTS = ("bioflex_jsb.sweep.evaluate", "bioflex_jsb.drivers.gust")


class DaskUnavailable(RuntimeError):
    """The scheduler cannot be reached (one line)."""


class DaskExecutor:
    """Run cases on a Dask cluster; ``fn(case, log_dir) -> row``; a case whose workers died
    is ``failed(case, error)``."""

    name = "dask"
    no_workers_s = 60.0  # a cluster with no worker this long stops the sweep
    window_per_worker = 4  # cases submitted ahead, per worker (at least 16 in all)

    def __init__(self, scheduler: str | None = None, workers: int = 2,
                 log_dir: str | None = None,
                 fn: Callable[[Case, str | None], dict[str, Any]] = run_case,
                 failed: Callable[[Any, str], dict[str, Any]] = failed_row) -> None:
        self.scheduler = scheduler
        self.workers = workers
        self.log_dir = log_dir
        self.fn = fn
        self.failed = failed  # failed(case, error) -> the row of a case that gave none
        self.cluster = None
        self.client = None
        self._client_log_level: int | None = None

    def __enter__(self) -> DaskExecutor:
        from distributed import Client, LocalCluster

        # the client logs a lost scheduler as tracebacks on stderr; the sweep reports it
        # in one line (RecordingError), so its logger is quieted while we hold it
        client_log = logging.getLogger("distributed.client")
        self._client_log_level = client_log.level
        client_log.setLevel(logging.CRITICAL)

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
        return self

    def _warm_up(self) -> None:
        """Import the simulation on every worker before the first case (as the local
        forkserver does), which also fails early, in one line, on workers that cannot
        import bioflex-jsb (:class:`DaskUnavailable`, a usage error). The rest of what a case
        needs and the compiled kernel load with a worker's first case, as they would here:
        a Dask worker is a process of its own, nothing is shared by a fork. A scheduler lost
        during the warm-up stops the sweep like one lost later (:class:`RecordingError`):
        its connection error is an OSError too, and is not the worker's environment."""
        import importlib

        from distributed.comm.core import CommClosedError

        try:
            for module in WORKER_IMPORTS:
                self.client.run(importlib.import_module, module)
        except (CommClosedError, TimeoutError) as exc:
            raise RecordingError(f"lost the Dask scheduler {self._address()} (before the "
                                 f"first case: {type(exc).__name__})") from None
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
        if self._client_log_level is not None:
            logging.getLogger("distributed.client").setLevel(self._client_log_level)
            self._client_log_level = None

    @property
    def n_workers(self) -> int:
        return len(self.client.scheduler_info().get("workers", {})) if self.client else 0

    def run(self, cases: Iterable[Case]) -> Iterator[tuple[Case, dict[str, Any]]]:
        """Yield ``(case, row)`` as cases finish (in finishing order); ``cases`` is read
        lazily. :class:`RecordingError` when the cluster cannot run them (see above)."""
        from distributed import wait
        from distributed.scheduler import KilledWorker

        self._warm_up()
        token = uuid.uuid4().hex[:8]
        pending = iter(cases)
        exhausted = False
        in_flight: dict[str, tuple[Any, Case]] = {}
        workers_seen = time.monotonic()
        n_workers, counted = self._workers_now(), time.monotonic()
        try:
            while not exhausted or in_flight:
                if time.monotonic() - counted > POLL_S:
                    n_workers, counted = self._workers_now(), time.monotonic()
                window = max(16, self.window_per_worker * max(1, n_workers or 0))
                while not exhausted and len(in_flight) < window:
                    c = next(pending, None)
                    if c is None:
                        exhausted = True
                        break
                    fut = self.client.submit(self.fn, c, self.log_dir, pure=False,
                                             key=f"bioflex-case-{c.case_id}-{token}")
                    in_flight[fut.key] = (fut, c)
                if not in_flight:
                    continue
                try:
                    done, _ = wait([f for f, _ in in_flight.values()], timeout=POLL_S,
                                   return_when="FIRST_COMPLETED")
                except TimeoutError:
                    done = set()
                except CancelledError:  # FuturesCancelledError: the scheduler is gone
                    raise RecordingError(
                        f"lost the Dask scheduler {self._address()} ({len(in_flight)} cases "
                        "cancelled: scheduler-connection-lost)") from None
                if not done:
                    self._check_cluster()
                    n_workers, counted = self._workers_now(), time.monotonic()
                    if n_workers:
                        workers_seen = time.monotonic()
                    elif time.monotonic() - workers_seen > self.no_workers_s:
                        raise RecordingError(
                            f"the Dask cluster has had no worker for {self.no_workers_s:g} s "
                            f"({len(in_flight)} cases waiting)")
                    continue
                workers_seen = time.monotonic()
                for fut in done:
                    _, c = in_flight.pop(fut.key)
                    try:
                        row = fut.result()
                    except KilledWorker as exc:
                        row = self.failed(c, f"worker died running this case, also on retry "
                                            f"(Dask KilledWorker: {exc})")
                    except RecordingError as exc:
                        raise RecordingError(str(exc)) from None
                    except CancelledError:  # the client cancelled it: the scheduler is gone
                        raise RecordingError(
                            f"lost the Dask scheduler {self._address()} (case {c.case_id} "
                            "cancelled: scheduler-connection-lost)") from None
                    # any other exception from a worker is a bug in the evaluation (the
                    # physics stopping a case is a row, not an exception): it propagates
                    # with its traceback
                    fut.release()
                    yield c, row
        finally:
            if in_flight and self.client is not None and self.client.status == "running":
                self.client.cancel([f for f, _ in in_flight.values()])

    def _workers_now(self) -> int | None:
        """Workers the scheduler knows now; None if it cannot be asked."""
        try:
            return self.n_workers
        except (OSError, TimeoutError):  # the scheduler is unreachable: see _check_cluster
            return None

    def _address(self) -> str:
        return self.scheduler or "(LocalCluster)"

    def _check_cluster(self) -> None:
        """RecordingError if the client has lost its scheduler for good."""
        if self.client is None or self.client.status in ("closed", "closing", "failed"):
            raise RecordingError(f"lost the Dask scheduler {self._address()} (client "
                                 f"{getattr(self.client, 'status', 'closed')})")
