"""The sweep loop: missing cases → executor → results store, with counts and progress.

Two kinds of stop besides the end of the campaign (docs/reliability.md):

* ``interrupted``: Ctrl-C or SIGTERM; every finished row is kept.
* ``stopped``: the machine could not run or record a case (a
  :class:`~bioflex_jsb.sweep.campaign.RecordingError` from a worker: no space for a log, a
  log directory that cannot be written, a lost Dask scheduler or workers; or an OSError
  writing the results table). The case is *not* recorded as failed: it stays missing, with
  every case not yet run, for ``--resume``. ``summary.stopped`` is the one-line reason.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from typing import Any

from bioflex_jsb.sweep.campaign import Case, RecordingError


@dataclass
class SweepSummary:
    """What a sweep did: cases in the campaign, already done before (resume), run now by
    status, and wall time [s]."""

    total: int
    skipped: int
    counts: dict[str, int] = field(default_factory=lambda: {"ok": 0, "diverged": 0,
                                                             "failed": 0})
    wall_time_s: float = 0.0
    interrupted: bool = False
    stopped: str | None = None  # the environment error that stopped the sweep (one line)

    @property
    def run(self) -> int:
        return sum(self.counts.values())

    @property
    def remaining(self) -> int:
        return self.total - self.skipped - self.run

    def as_dict(self) -> dict[str, Any]:
        return {"cases": self.total, "already_done": self.skipped, "run": self.run,
                **self.counts, "remaining": self.remaining, "wall_time_s": self.wall_time_s,
                "interrupted": self.interrupted, "stopped": self.stopped}


class MissingCases:
    """The cases of ``cases`` whose ids are not in ``done_ids``, lazily, in campaign order;
    ``skipped`` counts the others passed so far (all of them once iterated to the end)."""

    def __init__(self, cases: Iterable[Case], done_ids: set[str]) -> None:
        self._cases = iter(cases)
        self._done = done_ids
        self._first: list[Case] = []
        self.skipped = 0
        self.on_skip: Callable[[], None] | None = None

    def _next(self) -> Case | None:
        for c in self._cases:
            if c.case_id not in self._done:
                return c
            self.skipped += 1
            if self.on_skip is not None:
                self.on_skip()
        return None

    def any(self) -> bool:
        """Whether a case is left to run (found lazily and kept for the iteration)."""
        if not self._first:
            c = self._next()
            if c is None:
                return False
            self._first.append(c)
        return True

    def __iter__(self) -> Iterator[Case]:
        while self._first:
            yield self._first.pop()
        while (c := self._next()) is not None:
            yield c

    def count_rest(self) -> int:
        """Consume the rest; the number of cases still to run (skipped updated)."""
        return sum(1 for _ in self)


def missing_cases(cases: Iterable[Case], done_ids: set[str]) -> list[Case]:
    """The cases whose ids are not in ``done_ids``, in campaign order (a list)."""
    return list(MissingCases(cases, done_ids))


def run_sweep(cases: Iterable[Case], store, executor, total: int | None = None,
              on_row: Callable[[SweepSummary, dict[str, Any]], None] | None = None
              ) -> SweepSummary:
    """Run ``cases`` on ``executor``, appending each row to ``store`` as it arrives.

    ``cases``: a list, or a :class:`MissingCases` of the whole campaign (read lazily; its
    ``skipped`` fills ``summary.skipped``). ``total``: cases in the whole campaign (default
    ``len(cases)``). ``on_row(summary, row)`` after each row is written (progress). A
    KeyboardInterrupt stops the sweep with every finished row kept
    (``summary.interrupted``); an environment error stops it with the reason in
    ``summary.stopped`` and the case unrecorded.
    """
    lazy = isinstance(cases, MissingCases)
    if total is None:
        total = len(cases)  # type: ignore[arg-type]
    summary = SweepSummary(total=total, skipped=0 if lazy else total - len(cases))
    t0 = time.perf_counter()
    try:
        for _case, row in executor.run(cases):
            try:
                store.append(row)
            except OSError as exc:  # the results table cannot be written (disk full, ...)
                raise RecordingError(f"cannot write the results table: "
                                     f"{exc.strerror or exc}") from None
            status = row.get("status") or "failed"
            summary.counts[status] = summary.counts.get(status, 0) + 1
            if lazy:
                summary.skipped = cases.skipped
            if on_row is not None:
                on_row(summary, row)
    except KeyboardInterrupt:
        summary.interrupted = True
    except RecordingError as exc:
        summary.stopped = str(exc)
    finally:
        summary.wall_time_s = time.perf_counter() - t0
    if lazy:
        if summary.interrupted or summary.stopped:
            cases.count_rest()  # so that "remaining" is exact
        summary.skipped = cases.skipped
    return summary
