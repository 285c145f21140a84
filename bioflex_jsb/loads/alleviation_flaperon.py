"""Gust load alleviation with the elevator and the flaperons together: the plant with the
flaperon input, the design on it and its prediction (the elevator-only design and its
tuned-gust and turbulence measures: :mod:`bioflex_jsb.loads.alleviation`).

**Plant** (:func:`flaperon_plant`): Eq. (4) with its controls and the ``flaperon`` input
(:func:`bioflex_jsb.aeroelasticity.flaperon.with_flaperon`: both ailerons down together, +
trailing edges down), the section loads with the flaperon's own strip loads
(:mod:`bioflex_jsb.loads.flaperon`) and the run's signals as outputs; JSBSim's rigid block at
the trim when given, as the elevator design's.

**Why both surfaces.** The elevator lowers the wing's load through the pitch motion it
commands (the short period, 0.75 s at 15 m/s): little for the short gusts that are critical
for the wing (docs/loads.md: the root's tuned gradient 1.04 m, a 0.14 s gust). A flaperon
takes lift off the outboard wing at once (C_Lδf 0.96 /rad on the optimised wing's 0.51-0.85 m
aileron, its lift 0.62 m out on a 0.85 m semispan), so its command relieves the root within
the gust; its nose-down moment with the trailing edges down (C_mδf −0.72 /rad: the aileron
lies aft of the CG) pitches the aircraft the other way, which the elevator can hold.

**Design** (:func:`design_two_surface`): static output feedback [δe, δf] = K s from signals
s (default α, an α vane that sees the gust at once, and q), minimising the root bending
moment's tuned-gust peak ratio with its turbulence RMS ratio held within a cap (0.9,
below the elevator-only controller's 0.907) by the LTI model with each
command's peak in the reference gusts within its limit (a quadratic penalty beyond, 100 per
degree² over), the loop stable, by Nelder-Mead (as
:func:`~bioflex_jsb.loads.alleviation.design_output_feedback`).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import fftconvolve

from bioflex_jsb.aeroelasticity.flaperon import (
    FLAPERON,
    FLAPERON_LIMIT_RAD,
    flaperon_derivatives,
    with_flaperon,
)
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.loads.alleviation import (
    DEFAULT_SIGNALS,
    ELEVATOR_LIMIT_RAD,
    ROOT_BENDING,
    gust_samples,
    impulse,
    open_loop,
    tuned_cases,
    tuned_peaks,
    turbulence_rms,
)
from bioflex_jsb.loads.flaperon import with_flaperon as loads_with_flaperon
from bioflex_jsb.loads.lti import with_load_outputs
from bioflex_jsb.loads.model import LoadsModel
from bioflex_jsb.loads.tuned import DEFAULT_AMPLITUDE_M_S
from bioflex_jsb.simulation.closed_loop import close_loop, signal_outputs
from bioflex_jsb.simulation.controller import COMMAND_CHANNELS, LinearController
from bioflex_jsb.state_space import StateSpace

OUTPUTS = ("elevator", FLAPERON)
# The design's largest flaperon increment [rad]: below the co-simulation's travel
# (FLAPERON_LIMIT_RAD, 10°), so that the reference gusts never clip it.
FLAPERON_DESIGN_LIMIT_RAD = min(math.radians(8.0), FLAPERON_LIMIT_RAD)


def flaperon_plant(build, speed_m_s: float, loads_model: LoadsModel, aileron,
                   a_rr: np.ndarray | None = None) -> StateSpace:
    """The GLA plant with the flaperon input (module docstring); ``aileron`` the wing's
    (the definition's ``[aileron]``), ``a_rr`` JSBSim's rigid block at the trim (None: the
    analytic one)."""
    cond = level_flight_condition(speed_m_s, airframe=build.airframe)
    deriv = flaperon_derivatives(build, aileron)
    ss = build_state_space("coupled", cond, build.model, a_rr=a_rr, controls=True)
    ss = with_flaperon(ss, cond, deriv, build.model.generalised_masses_kg_m2)
    return signal_outputs(with_load_outputs(ss, loads_with_flaperon(loads_model, deriv)))


def command_peaks(cl: StateSpace, speed_m_s: float, gradients_m=None,
                  u_ref_m_s: float = DEFAULT_AMPLITUDE_M_S) -> dict[str, np.ndarray]:
    """Per tuned gust (:func:`~bioflex_jsb.loads.alleviation.tuned_cases`), the peak
    |command| [rad] of each of the closed loop ``cl``'s commands, by command name."""
    cases = tuned_cases(speed_m_s, gradients_m, u_ref_m_s)
    outs = tuple(COMMAND_CHANNELS[o] for o in OUTPUTS if COMMAND_CHANNELS[o] in cl.outputs)
    n = max(int(round(c["duration_s"] / cl.dt_s)) for c in cases)
    h = impulse(cl, outs, n)
    peaks = np.zeros((len(cases), len(outs)))
    for i, c in enumerate(cases):
        w = gust_samples(c["gust"], speed_m_s, c["duration_s"], cl.dt_s, c["gust_start_s"])
        y = fftconvolve(w[:, None], h[:len(w)], axes=0)[:len(w)]
        peaks[i] = np.abs(y).max(axis=0)
    return {o: peaks[:, j] for j, o in enumerate(outs)}


def static_gains(gains, signals=DEFAULT_SIGNALS, dt_s: float | None = None,
                 name: str = "gla_flaperon", notes: dict | None = None) -> LinearController:
    """[δe, δf] = K s [rad] as a LinearController: ``gains`` (2, len(signals)), rows the
    elevator's and the flaperon's (``dt_s`` None: continuous, the run's step)."""
    k = np.asarray(gains, dtype=float).reshape(2, len(tuple(signals)))
    return LinearController.from_arrays(None, None, None, k.tolist(), dt_s, signals,
                                        list(OUTPUTS), name, notes)


def design_two_surface(plant: StateSpace, dt_s: float, signals=DEFAULT_SIGNALS,
                       output: str = ROOT_BENDING, gradients_m=None,
                       u_ref_m_s: float = DEFAULT_AMPLITUDE_M_S,
                       elevator_limit_rad: float = ELEVATOR_LIMIT_RAD,
                       flaperon_limit_rad: float = FLAPERON_DESIGN_LIMIT_RAD,
                       rms_cap: float = 0.9, start=None,
                       max_iter: int = 600) -> tuple[LinearController, dict]:
    """Static output feedback from ``signals`` to the elevator and the flaperon minimising
    the tuned peak ratio of ``output`` with its turbulence RMS ratio
    (:data:`~bioflex_jsb.loads.alleviation.TURBULENCE`) held within ``rms_cap`` (a penalty
    of 10 per unit over: on the tuned peak alone the optimum, 0.858, raised the RMS to 1.156
    of the open loop's; on their sum the tuned ratio rose to 0.991, measured) and each
    command within its limit (module docstring),
    from ``start`` (2, m) (default: the elevator's 2 rad/rad on α and 0.1 s on q, the
    flaperon's 0.7 rad/rad and 0.03 s, near the tuned-peak-only optimum: from zero
    flaperon gains Nelder-Mead's first simplex
    is too small to leave the elevator-only optimum, measured): (the controller, the
    optimiser's record)."""
    from scipy.optimize import minimize

    signals = tuple(signals)
    m = len(signals)
    x0 = np.zeros((2, m))
    if start is not None:
        x0 = np.asarray(start, dtype=float).reshape(2, m)
    else:
        x0[0] = [{"alpha": 2.0, "q": 0.1}.get(s, 0.0) for s in signals]
        x0[1] = [{"alpha": 0.7, "q": 0.03}.get(s, 0.0) for s in signals]
    v = plant.speed_m_s
    ol = open_loop(plant, dt_s)
    base = tuned_peaks(ol, v, output, gradients_m, u_ref_m_s).tuned_peak
    base_rms = turbulence_rms(ol, v, output)
    limits = {COMMAND_CHANNELS["elevator"]: elevator_limit_rad,
              COMMAND_CHANNELS[FLAPERON]: flaperon_limit_rad}

    def cost(k: np.ndarray) -> float:
        cl = close_loop(plant, static_gains(k, signals, dt_s), dt_s)
        if np.abs(np.linalg.eigvals(cl.a)).max() >= 1.0:
            return 1e3  # unstable
        p = tuned_peaks(cl, v, output, gradients_m, u_ref_m_s)
        over = sum(max(0.0, math.degrees(peaks.max() - limits[name])) ** 2
                   for name, peaks in command_peaks(cl, v, gradients_m, u_ref_m_s).items())
        rms = turbulence_rms(cl, v, output) / base_rms
        return p.tuned_peak / base + 10.0 * max(0.0, rms - rms_cap) + 100.0 * over

    res = minimize(cost, x0.ravel(), method="Nelder-Mead",
                   options={"maxiter": max_iter, "xatol": 1e-4, "fatol": 1e-6})
    gains = res.x.reshape(2, m)
    record = {"gains": {o: dict(zip(signals, row.tolist(), strict=True))
                        for o, row in zip(OUTPUTS, gains, strict=True)},
              "cost": float(res.fun), "iterations": int(res.nit),
              "elevator_limit_deg": math.degrees(elevator_limit_rad),
              "flaperon_limit_deg": math.degrees(flaperon_limit_rad),
              "objective": f"tuned-gust peak ratio of {output} (U_ref {u_ref_m_s:g} m/s), "
                           f"its turbulence RMS ratio held within {rms_cap:g}"}
    return static_gains(gains, signals, dt_s), record
