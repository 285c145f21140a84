"""One case of a campaign, run in a worker process: the row with every input and metric.

This is the code both executors (local processes, Dask) ship to their workers. It builds
the wing (cached per process), computes the LTI metrics and flies the gust run through
JSBSim (``bioflex_jsb.drivers.gust``).

What a worker process keeps from case to case (the fixed cost of a case, measured in
``docs/sweeps.md``): the imports and the compiled step kernel (:func:`warm_worker`, run once
in the local forkserver before it forks the workers, so every worker has them for nothing;
a Dask worker loads them with its first case), the wing's build (``build_wing``'s cache), its
flutter search (:data:`_FLUTTER_CACHE`) and the eigenvalues of a wing, model and speed
(:data:`_EIGEN_CACHE`: a campaign's gusts and seeds share them). Each is a pure function of
its key, so a row does not depend on which cases its worker ran before.

Each case still loads its own :class:`Airframe`. Reusing one per worker would save the load
(≈ 11 ms of a ≈ 200 ms case, measured) but JSBSim's trim starts from the state the previous
run left (the propellers' RPM), so the last digits of a case's result would depend on which
cases its worker ran before (up to 4.5e-9 in the example campaign's histories, measured):
the local and the Dask executors, which share the cases out differently, would then not
give identical tables.

``run.aero = "unsteady"`` flies the gust runs with the unsteady strips
(:class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`'s ``aero``, on its compiled step;
the campaign refuses it with other models or the LTI metrics).

A case never raises for a problem of its own: a failing build or run is a row with status
``failed`` and the error; a run that leaves the model's valid range is a row with status
``diverged``, the reason and the metrics up to that point. A problem of the machine is not
the case's: an ``OSError`` (no space for the case's log, a log directory that cannot be
written, a file that vanished) raises :class:`~bioflex_jsb.sweep.campaign.RecordingError`,
which stops the sweep and leaves the case for ``--resume`` (docs/reliability.md).
"""

from __future__ import annotations

import math
import os
import socket
import time
from pathlib import Path
from typing import Any

from bioflex_jsb.sinks.mcap.scene import DEFAULT_EXAGGERATION
from bioflex_jsb.sweep.campaign import Case, RecordingError, failed_row
from bioflex_jsb.sweep.columns import EIGEN_MODES

_FLUTTER_CACHE: dict[tuple, Any] = {}
_EIGEN_CACHE: dict[tuple, Any] = {}
_AIRCRAFT_BUILDS: dict[tuple, Any] = {}  # an aircraft's wing (its own airframe's model)
# What a case imports beyond the executors' preload (measured: a first case imported these
# and numba, 1-2 s under load): imported, and the step kernel loaded, once per worker.
# A case's log has the 3-D scene a gust run's has, at the scene's default exaggeration (true
# scale), as the gust command's (cli/gust.py SCENE_EXAGGERATION; a test holds them equal).
SCENE_EXAGGERATION = DEFAULT_EXAGGERATION
WARM_MODULES = ("bioflex_jsb.flight_dynamics.eigen", "bioflex_jsb.flight_dynamics.flutter_engine",
                "bioflex_jsb.flight_dynamics.wing_model", "bioflex_jsb.structures.wing_model",
                "bioflex_jsb.simulation.results", "bioflex_jsb.drivers.gust")


def warm_worker() -> None:
    """Import what a case needs and load the compiled step kernel (numba's cache, or a
    compile on a fresh machine) before the first case: the local executor's forkserver runs
    it once, before it forks its workers (:mod:`bioflex_jsb.sweep.worker_warm`)."""
    import importlib

    for name in WARM_MODULES:
        importlib.import_module(name)
    from bioflex_jsb.simulation import step_kernel

    step_kernel.compile_now()


def airframe(aircraft=None):
    """A freshly loaded JSBSim airframe (see the module docstring for why not reused): the
    prototype's, or the one ``aircraft`` (an Aircraft definition) flies on."""
    if aircraft is None:
        from bioflex_jsb.runtime.fdm import Airframe

        return Airframe()
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    return airframe_for(aircraft)


def worker_name() -> str:
    return f"{socket.gethostname()}:{os.getpid()}"


def _num(x: Any) -> float | None:
    if x is None:
        return None
    x = float(x)
    return x if math.isfinite(x) else None


def case_errors() -> tuple[type[Exception], ...]:
    """What a case can fail with that is a result, not a bug: a validated-input problem
    (InputError: the airframe cannot trim, e.g. below the stall speed; a wing, gust or run
    description that is not valid), a singular matrix at an extreme design point. A log
    that cannot be written (OSError) is not a result: see :func:`run_case`."""
    import numpy as np

    from bioflex_jsb.errors import InputError

    return (InputError, np.linalg.LinAlgError)


def _os_reason(exc: OSError) -> str:
    where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
    return f"{exc.strerror or exc}{where}"


def run_case(case: Case, log_dir: str | None = None) -> dict[str, Any]:
    """Run ``case``; the returned row has every column of the campaign's results table.
    :class:`RecordingError` if the machine stopped it (an OSError: disk full, permissions)."""
    started = time.time()
    t0 = time.perf_counter()
    try:
        row = _evaluate(case, log_dir)
    except case_errors() as exc:  # recorded as the case's error; anything else is a bug
        row = failed_row(case, f"{type(exc).__name__}: {exc}")
    except OSError as exc:  # the machine, not the case: the sweep stops, --resume runs it
        raise RecordingError(f"case {case.case_id} on {worker_name()}: "
                             f"{_os_reason(exc)}") from None
    row["worker"] = worker_name()
    row["started_unix_s"] = started
    row["wall_time_s"] = time.perf_counter() - t0
    return row


def _wing_key(case: Case) -> tuple:
    """What identifies a case's wing build (the per-process caches' key)."""
    aircraft = None
    if case.aircraft is not None:
        from bioflex_jsb.sweep.aircraft_axis import aircraft_identity

        aircraft = aircraft_identity(case.aircraft)["definition_sha256"]
    return (repr(sorted(case.wing.as_dict().items())), case.settings.mass_basis, aircraft)


def _build(case: Case):
    """The case's wing: its variant's build (``build_wing``'s cache), or its aircraft's
    (cached here per definition content and mass basis)."""
    from bioflex_jsb.flight_dynamics.wing_model import build_wing

    if case.aircraft is None:
        return build_wing(case.wing, mass_basis=case.settings.mass_basis)
    key = _wing_key(case)
    if key not in _AIRCRAFT_BUILDS:
        _AIRCRAFT_BUILDS[key] = case.aircraft.wing(case.settings.mass_basis)
    return _AIRCRAFT_BUILDS[key]


def _evaluate(case: Case, log_dir: str | None) -> dict[str, Any]:
    row: dict[str, Any] = {name: None for name in case.columns()}
    row.update(case.inputs())
    row["status"] = "ok"
    build = _build(case)
    if "coefficients" in case.metrics:
        row["c_eta1_q1"] = float(build.model.coefficients.c_eta_q[0, 0])
        row["c_eta1_q1_physical"] = _num(build.physical_c_eta1_q1)
        row["e_shift_frac"] = _num(build.e_shift_frac)
        for i, w in enumerate(build.model.frequencies_rad_s):
            key = f"mode{i + 1}_frequency_hz"
            if key in row:
                row[key] = float(w) / (2.0 * math.pi)
    if "eigenvalues" in case.metrics:
        mode_set = _modes(case, build)
        for name in EIGEN_MODES:
            try:
                m = mode_set.get(name)
            except KeyError:
                continue  # this model has no such mode: left empty
            row[f"{name}_re_rad_s"] = m.re
            row[f"{name}_im_rad_s"] = m.im
            row[f"{name}_damping"] = m.damping
            row[f"{name}_frequency_rad_s"] = m.frequency_rad_s
    if "flutter" in case.metrics:
        f = _flutter(case, build)
        # empty means none in the range: an instability at and below the range's lower end
        # (the result has no speed then) is written as that end, as in every stored table
        row["flutter_speed_m_s"] = f.flutter_speed_m_s if not f.present_at_lower_end \
            else f.unstable_at_and_below_m_s
        row["flutter_mode"] = f.mode
        row["flutter_frequency_rad_s"] = f.frequency_rad_s
        row["flutter_kind"] = f.kind
    if "gust" in case.metrics:
        _gust_run(case, build, row, log_dir)
    return row


def _modes(case: Case, build):
    """The case's LTI modes at its speed (cached per process, wing, model and speed: the
    gusts and seeds of a campaign share them)."""
    from bioflex_jsb.flight_dynamics.eigen import modes_at

    key = (*_wing_key(case), case.model, case.speed_m_s)
    if key not in _EIGEN_CACHE:
        _EIGEN_CACHE[key] = modes_at(case.model, [case.speed_m_s], build.model)[0]
    return _EIGEN_CACHE[key]


def _flutter(case: Case, build):
    """Flutter of the case's wing (the coupled model; cached per process and wing)."""
    from bioflex_jsb.flight_dynamics.eigen import find_flutter

    key = (*_wing_key(case), case.settings.flutter_range_m_s)
    if key not in _FLUTTER_CACHE:
        rng = case.settings.flutter_range_m_s
        if rng is None:  # the wing's own default (the prototype's: 5-40 m/s)
            from bioflex_jsb.definition.clamped import free_speed_range_m_s

            rng = free_speed_range_m_s(build)
        _FLUTTER_CACHE[key] = find_flutter(build.model, rng)
    return _FLUTTER_CACHE[key]


def case_description(case: Case):
    """The run description of ``case``'s gust run (what its log records; ``rerun`` flies it
    again as the gust run it is)."""
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.run import RunDescription

    s = case.settings
    return RunDescription(kind="sweep", wing=case.wing.name, speed_m_s=case.speed_m_s,
                          gust=parse_gust(case.gust).text(), models=(case.model,),
                          duration_s=s.duration_s, gust_start_s=s.gust_start_s,
                          dt_s=s.dt_s, mass_basis=s.mass_basis,
                          extra={"case_id": case.case_id, "aero": s.aero,
                                 **({"aircraft": case.aircraft.source}
                                    if case.aircraft is not None else {}),
                                 **({"controller": case.controller}
                                    if case.controller is not None else {})})


def _gust_run(case: Case, build, row: dict[str, Any], log_dir: str | None) -> None:
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import gust_metrics, stop_event_text
    from bioflex_jsb.simulation.sensors import SensorSet

    s = case.settings
    chord_m = build.model.airframe.reference.mean_chord_m  # the shortest gust: one chord
    if case.aircraft is not None:
        from bioflex_jsb.definition.flying import flight_speeds
        from bioflex_jsb.errors import InputError

        _cruise, (lo, hi) = flight_speeds(case.aircraft)
        if not lo <= case.speed_m_s <= hi:  # a row: the campaign's speeds are shared
            raise InputError(f"speed {case.speed_m_s:g} m/s is outside aircraft "
                             f"{case.aircraft.name!r}'s flight speeds {lo:g}..{hi:g} m/s "
                             "(airframe.speed_range_m_s)")
    setup = RunConfig(case.speed_m_s, parse_gust(case.gust, chord_m), s.duration_s,
                      s.gust_start_s, dt_s=s.dt_s, models=(case.model,), aero=s.aero)
    log = None
    recorder = None
    if log_dir:
        from bioflex_jsb.sinks.mcap import RunLog

        Path(log_dir).mkdir(parents=True, exist_ok=True)
        log = RunLog.open(Path(log_dir) / f"{case.case_id}.mcap", case_description(case),
                          wing_variant=build.variant.as_dict(),
                          overrides=dict(build.model.coefficients.overrides),
                          scene=SCENE_EXAGGERATION)
        recorder = log.recorder(case.model)

    try:
        # the unsteady strips need the wing's build (its strips); the quasi-steady its model
        wing = build if setup.needs_build(case.model) else build.model
        # the aircraft's [sensors] with the build's mode shapes (none: no sensor channels)
        sensors = (SensorSet(build.sensors, build.modes, build.model.n_modes)
                   if build.sensors else None)
        controller = None
        if case.controller is not None:  # a fresh one per run (a file read bounded)
            from bioflex_jsb.simulation.controller import load_controller

            controller = load_controller(case.controller)
            if "flaperon" in controller.outputs:  # its strips are the build's
                wing = build
        run = run_gust(airframe(case.aircraft), wing, case.model, setup, recorder=recorder,
                       sensors=sensors, controller=controller)
        if log is not None and run.stopped:  # as a gust log says it: read_log's stopped
            log.event(run.stop_time_s, "ERROR", stop_event_text(case.model, run.stopped),
                      name=case.model)
    finally:
        if log is not None:
            log.close()
    if run.meta.get("interrupted"):
        raise KeyboardInterrupt  # not a result: the case stays missing for --resume
    if len(run.time_s) and run.time_s[-1] >= s.gust_start_s:
        for k, v in gust_metrics(run, s.gust_start_s).as_dict().items():
            row[k] = _num(v)
    # else: stopped before the gust arrived, no gust response to summarise (left empty)
    row["time_beyond_stall_s"] = _num(run.meta.get("time_beyond_stall_s"))
    row["time_flown_s"] = float(len(run.time_s) * run.meta["dt_s"])
    for name in ("ctrl_elevator_rad", "ctrl_throttle", "ctrl_flaperon_rad"):
        if f"peak_{name}" in row and name in run.channels and len(run[name]):
            row[f"peak_{name}"] = _num(abs(run[name]).max())
    if run.stopped:
        row["status"] = "diverged"
        row["error"] = " ".join(str(run.stopped).split())
