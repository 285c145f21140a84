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
