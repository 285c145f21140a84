"""The sweep loop: missing cases → executor → results store, with counts and progress."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from bioflex_jsb.sweep.campaign import Case


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

    @property
    def run(self) -> int:
        return sum(self.counts.values())

    @property
    def remaining(self) -> int:
        return self.total - self.skipped - self.run

    def as_dict(self) -> dict[str, Any]:
        return {"cases": self.total, "already_done": self.skipped, "run": self.run,
                **self.counts, "remaining": self.remaining, "wall_time_s": self.wall_time_s,
                "interrupted": self.interrupted}


def missing_cases(cases: list[Case], done_ids: set[str]) -> list[Case]:
    """The cases whose ids are not in ``done_ids``, in campaign order."""
    return [c for c in cases if c.case_id not in done_ids]


def run_sweep(cases: list[Case], store, executor, total: int | None = None,
              on_row: Callable[[SweepSummary, dict[str, Any]], None] | None = None
              ) -> SweepSummary:
    """Run ``cases`` on ``executor``, appending each row to ``store`` as it arrives.

    ``total``: cases in the whole campaign (for the counts; default ``len(cases)``).
    ``on_row(summary, row)`` after each row is written (progress). A KeyboardInterrupt
    stops the sweep with every finished row kept; ``summary.interrupted`` says so.
    """
    total = len(cases) if total is None else total
    summary = SweepSummary(total=total, skipped=total - len(cases))
    t0 = time.perf_counter()
    try:
        for _case, row in executor.run(cases):
            store.append(row)
            status = row.get("status") or "failed"
            summary.counts[status] = summary.counts.get(status, 0) + 1
            if on_row is not None:
                on_row(summary, row)
    except KeyboardInterrupt:
        summary.interrupted = True
    finally:
        summary.wall_time_s = time.perf_counter() - t0
    return summary
