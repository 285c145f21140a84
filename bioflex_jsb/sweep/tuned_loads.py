"""The tuned discrete gust (:mod:`bioflex_jsb.loads.tuned`) on the sweep executors.

``bioflex-jsb loads --tuned`` flies its gusts (every gradient up and down) as cases of the
local process pool (:class:`~bioflex_jsb.sweep.local.LocalExecutor`: warm forkserver
workers, one case per worker in flight) or of a Dask cluster
(:class:`~bioflex_jsb.sweep.dask_cluster.DaskExecutor`), the way ``sweep`` runs a
campaign's. A :class:`TunedCase` carries everything its run needs (the wing's source, not
its build: a worker builds the wing once and keeps it, :data:`_BUILDS`); the worker returns
the case's :class:`~bioflex_jsb.loads.history.SectionLoads`, and :func:`run_tuned` hands
them back in the cases' order whatever order they finished in, so the critical-case table
(:func:`~bioflex_jsb.loads.tuned.tuned_result`) does not depend on the number of workers.

Each case loads its own JSBSim airframe, as a sweep case does (``sweep/evaluate.py``: a
reused one starts its trim from the previous run's state, and the last digits of a result
would depend on which cases its worker ran before).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from bioflex_jsb.sweep.campaign import RecordingError

_BUILDS: dict[str, Any] = {}  # wing key -> WingBuild, per worker process


@dataclass(frozen=True)
class TunedCase:
    """One gust of the tuned sweep. ``wing``: a WingVariant (``--wing``) or an Aircraft
    (``--aircraft``), built in the worker at ``mass_basis``; ``wing_key`` names that build
    (the worker's cache key). Speed [m/s], gust text, duration, gust start and step [s],
    model, trim, stations (fractions of the semispan), static part."""

    index: int
    wing: Any
    wing_key: str
    mass_basis: str
    speed_m_s: float
    gust: str
    duration_s: float
    gust_start_s: float
    dt_s: float
    model: str
    trim: str
    stations: tuple[float, ...]
    static: str | None
    case_id: str = ""


def tuned_case_list(cases: list[dict], wing, wing_key: str, mass_basis: str,
                    speed_m_s: float, dt_s: float, model: str, trim: str,
                    stations: tuple[float, ...], static: str | None) -> list[TunedCase]:
    """The :class:`TunedCase` of each of ``cases`` (:func:`~bioflex_jsb.loads.tuned.tuned_cases`),
    with an id hashing its inputs (the Dask task's key)."""
    out = []
    for i, c in enumerate(cases):
        inputs = {"wing": wing_key, "mass_basis": mass_basis, "speed_m_s": speed_m_s,
                  "gust": c["gust"], "duration_s": c["duration_s"],
                  "gust_start_s": c["gust_start_s"], "dt_s": dt_s, "model": model,
                  "trim": trim, "stations": list(stations), "static": static}
        cid = hashlib.sha256(json.dumps(inputs, sort_keys=True).encode()).hexdigest()[:16]
        out.append(TunedCase(i, wing, wing_key, mass_basis, speed_m_s, c["gust"],
                             c["duration_s"], c["gust_start_s"], dt_s, model, trim,
                             tuple(stations), static, cid))
    return out


def _build(case: TunedCase):
    if case.wing_key not in _BUILDS:
        from bioflex_jsb.flight_dynamics.wing_model import WingVariant, build_wing

        if isinstance(case.wing, WingVariant):
            _BUILDS[case.wing_key] = build_wing(case.wing, mass_basis=case.mass_basis)
        else:  # an Aircraft: the command has checked that it flies (flight_problem)
            _BUILDS[case.wing_key] = case.wing.wing(case.mass_basis)
    return _BUILDS[case.wing_key]


def fly_tuned_case(case: TunedCase, log_dir: str | None = None) -> dict[str, Any]:
    """Fly ``case`` (a fresh airframe) and return its row: ``status`` ok | diverged |
    failed, ``error``, ``loads`` (the SectionLoads, None when failed). ``log_dir`` is the
    executors' argument; the tuned gust writes no log."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.flight_dynamics.wing_model import WingVariant
    from bioflex_jsb.loads import section_loads
    from bioflex_jsb.runtime.fdm import FdmError
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
    from bioflex_jsb.simulation.gusts import parse_gust

    row: dict[str, Any] = {"case_id": case.case_id, "index": case.index, "gust": case.gust}
    try:
        build = _build(case)
        chord_m = build.model.airframe.reference.mean_chord_m  # the shortest gust
        setup = RunConfig(case.speed_m_s, parse_gust(case.gust, chord_m), case.duration_s,
                          case.gust_start_s, 0.0, case.dt_s, models=(case.model,),
                          trim=case.trim)
        # as api.fly_gust flies one model: the build for the elastic trim, else its model
        aircraft = None if isinstance(case.wing, WingVariant) else case.wing
        # the JSBSim airframe the wing's aircraft flies on (the prototype's for a variant)
        wing = build if setup.needs_build(case.model) else build.model
        run = run_gust(airframe_for(aircraft), wing, case.model, setup, loads=build)
        loads = section_loads(build, run, case.stations, static=case.static)
    except (FdmError, InputError) as exc:  # the case's own problem, in one line
        return dict(row, status="failed", error=" ".join(str(exc).split()), loads=None)
    except OSError as exc:  # the machine's (a file that vanished): not the case's
        raise RecordingError(f"case {case.gust}: {exc.strerror or exc}") from None
    if run.meta.get("interrupted"):
        raise KeyboardInterrupt  # not a result
    stopped = " ".join(str(run.stopped).split()) if run.stopped else None
    return dict(row, status="diverged" if stopped else "ok", error=stopped, loads=loads)


def tuned_failed_row(case: TunedCase, error: str) -> dict[str, Any]:
    """The row of a case the executor could not run (its worker died twice, ...): the
    machine's problem, not the case's (``lost``)."""
    return {"case_id": case.case_id, "index": case.index, "gust": case.gust,
            "status": "failed", "error": " ".join(str(error).split()), "loads": None,
            "lost": True}


def run_tuned(cases: list[TunedCase], executor,
              on_row: Callable[[int, int, dict[str, Any]], None] | None = None
              ) -> list[dict[str, Any]]:
    """Run ``cases`` on ``executor`` (entered by the caller) and return their rows in the
    cases' order. ``on_row(done, total, row)`` as each finishes (progress)."""
    rows: list[dict[str, Any] | None] = [None] * len(cases)
    done = 0
    for case, row in executor.run(cases):
        rows[case.index] = row
        done += 1
        if on_row is not None:
            on_row(done, len(cases), row)
    missing = [c.gust for c, r in zip(cases, rows, strict=True) if r is None]
    if missing:  # an executor returns every case or raises: a bug if not
        raise RuntimeError(f"the executor returned no row for {', '.join(missing)}")
    return rows  # type: ignore[return-value]
