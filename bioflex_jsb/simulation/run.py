"""A run described as data: what was flown, so that a log can record it and ``rerun`` can fly
it again.

The CLI builds a :class:`RunDescription` from its arguments, the sweep from a case, the API
from its keyword arguments; sinks (the MCAP log) take it, never command-line arguments.
:meth:`RunDescription.to_dict` / :meth:`from_dict` are its JSON form (the log's ``bioflex.run``
metadata).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields
from typing import Any

from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

# What a run can be: a gust run of one or more models, one sweep case (a gust run), a
# comparison of the co-simulation with the LTI model, a SITL session, a benchmark, an
# ArduPlane SITL session (bioflex-jsb ardupilot: ArduPilot flies it, so it is not repeatable).
RUN_KINDS = ("gust", "sweep", "compare", "sitl", "bench", "ardupilot")
REPEATABLE_KINDS = ("gust", "sweep", "compare")


class RunDescriptionError(InputError):
    """A run description that cannot describe a run (one line: the field and what is
    accepted)."""


# Longest simulated run of gust/compare [s]: 6 h. A run keeps one block of rows plus a
# bounded-rate envelope beyond 120 s (memory flat in the run's length, drivers/gust.py),
# so the limit is the wall time (6 h of flight is ~20 M steps, ~3 min) and the steps'
# count. The CLI (cli/case.py) and the API (api.fly_gust, api.compare) refuse longer runs.
MAX_DURATION_S = 6 * 3600.0
MAX_STEPS = 50_000_000  # steps per run (duration / dt), whatever the step
# Turbulence is synthesised for the whole run up front (an inverse FFT of its spectrum, 8
# bytes per step and a power-of-two transform twice that long): bounded at 1 h of flight.
MAX_TURBULENCE_DURATION_S = 3600.0


def check_run_length(duration_s: float, dt_s: float, turbulence: bool = False) -> None:
    """A run of ``duration_s`` [s] at ``dt_s`` [s] within MAX_DURATION_S (a Dryden or von
    Kármán record, ``turbulence``: MAX_TURBULENCE_DURATION_S) and MAX_STEPS; else
    InputError, one line (the CLI's and the API's limits)."""
    limit = MAX_TURBULENCE_DURATION_S if turbulence else MAX_DURATION_S
    if duration_s > limit:
        raise InputError(f"duration {duration_s:g} s is too long; accepted: up to {limit:g} s "
                         "per run" + (" of turbulence (synthesised for the whole run up "
                                      "front)" if turbulence else " (longer records: a sweep "
                                      "of cases)"))
    if duration_s / dt_s > MAX_STEPS:
        raise InputError(f"duration {duration_s:g} s at a step of {dt_s:g} s is "
                         f"{duration_s / dt_s:.3g} steps; accepted: up to {MAX_STEPS:g} steps "
                         "per run")


@dataclass(frozen=True)
class RunDescription:
    """One run. Units in the names; ``gust`` is a gust specification as ``--gust`` takes it
    (``sharp:3``: m/s; ``1cos:A:L``: m/s, m; ``dryden:SIGMA:SCALE[:SEED]``).

    kind: one of :data:`RUN_KINDS`; wing: a named variant or a variant file's path;
    mass_basis: ``consistent`` or ``paper`` (``docs/decisions.md``); models: the wing models
    flown (rigid, coupled, qsd; ``compare`` takes one); extra: anything a kind needs beyond
    these (a sweep's case id, SITL options), JSON-serialisable.
    """

    kind: str
    wing: str
    speed_m_s: float
    gust: str = "sharp:3"
    models: tuple[str, ...] = ("rigid", "coupled", "qsd")
    duration_s: float = 5.0
    gust_start_s: float = 0.5
    altitude_m: float = 0.0
    dt_s: float = DEFAULT_DT_S
    mass_basis: str = "consistent"
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.kind not in RUN_KINDS:
            raise RunDescriptionError(
                f"unknown run kind {self.kind!r}; accepted: {', '.join(RUN_KINDS)}")
        for name in ("speed_m_s", "duration_s", "dt_s"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v) and v > 0.0):
                raise RunDescriptionError(f"{name} must be a finite number > 0, got {v!r}")
        for name in ("gust_start_s", "altitude_m"):
            v = getattr(self, name)
            if not (isinstance(v, int | float) and math.isfinite(v)):
                raise RunDescriptionError(f"{name} must be a finite number, got {v!r}")
        object.__setattr__(self, "models", tuple(self.models))

    @property
    def repeatable(self) -> bool:
        """Whether ``rerun`` can fly it again (a SITL session follows its ground station)."""
        return self.kind in REPEATABLE_KINDS

    def to_dict(self) -> dict[str, Any]:
        """The JSON form (plain types)."""
        d = asdict(self)
        d["models"] = list(self.models)
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> RunDescription:
        """The description of :meth:`to_dict`; unknown keys are refused."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(d) - known)
        if unknown:
            raise RunDescriptionError(f"unknown run description fields {unknown}")
        missing = sorted({"kind", "wing", "speed_m_s"} - set(d))
        if missing:
            raise RunDescriptionError(f"run description lacks {missing}")
        return cls(**{**d, "models": tuple(d.get("models", cls.models))})
