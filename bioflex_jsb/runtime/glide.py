"""The steady glide of an aircraft without an engine (docs/aircraft.md, "An aircraft without
an engine flies its steady glide").

JSBSim's trim (``FGFDMExec::DoTrim``) trims u̇ with the throttle; an aircraft without an
engine (SGS.xml's ``<propulsion>`` is empty) cannot hold its speed in level flight ("udot
doesn't appear to be trimmable"). The physically consistent steady state at a given airspeed
is the steady glide: drag balanced by the weight's component along the path, D = −W sin γ,
L = W cos γ. :func:`glide_trim` solves for the angle of attack α, the flight-path angle γ
(negative: descending) and the pitch-trim command that zero JSBSim's own u̇, ẇ (ft/s²) and
q̇ (rad/s²) in JSBSim's initial-condition evaluation (``RunIC``: the forces and moments of
the state, nothing integrated), wings level, by Newton's method with a finite-difference
Jacobian: the trim JSBSim would make with γ as its u̇ control.
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb.runtime.results import TrimError
from bioflex_jsb.simulation import jsbsim_properties as JP

# The glide trim's convergence: JSBSim's own trim tolerances are 1e-3 ft/s² on u̇, ẇ and
# 1e-4 rad/s² on q̇ (FGTrimAxis; runtime/fdm.py TRIM_TOLERANCE_*); Newton is asked for
# 1e-3 of them, which it reaches in 3-5 iterations (the tables are linear between their
# points: measured 4 iterations at 20-28 m/s for SGS, residuals below 1e-9).
GLIDE_TOL_FT_S2 = 1e-6
GLIDE_TOL_RAD_S2 = 1e-7
GLIDE_MAX_ITERATIONS = 30
# Finite-difference steps of the Jacobian [rad, rad, -]: 1e-7 rad moves α by a millionth
# of a table interval (1° = 0.0175 rad), so a step crosses a table point at most once in
# ten thousand evaluations; the residuals are O(10 ft/s²) per rad, so the differences keep
# 8 significant digits.
FD_STEP = 1e-7
# The γ search is bounded: a glide steeper than 45° is no glide (L/D < 1).
GAMMA_LIMIT_RAD = math.radians(45.0)
PITCH_TRIM = JP.FCS_PITCH_TRIM_CMD_NORM  # the control JSBSim's full trim moves for q̇



def glide_trim(fdm, speed_m_s: float) -> int:
    """Trim ``fdm`` (a JSBSim instance at its initial condition: wings level, true airspeed
    ``speed_m_s`` [m/s], controls zero) to the steady glide (module docstring); returns the
    Newton iterations taken. The instance is left at the trimmed initial condition.
    Raises :class:`TrimError` (one line) when no glide is found."""
    def residuals(x: np.ndarray) -> np.ndarray:
        fdm[JP.IC_GAMMA_RAD] = x[1]
        fdm[JP.IC_ALPHA_RAD] = x[0]
        fdm[PITCH_TRIM] = x[2]
        fdm.run_ic()
        return np.array([fdm[JP.ACCELERATIONS_UDOT_FT_SEC2], fdm[JP.ACCELERATIONS_WDOT_FT_SEC2],
                         fdm[JP.ACCELERATIONS_QDOT_RAD_SEC2]])

    tol = np.array([GLIDE_TOL_FT_S2, GLIDE_TOL_FT_S2, GLIDE_TOL_RAD_S2])
    x = np.zeros(3)
    r = residuals(x)
    for iteration in range(1, GLIDE_MAX_ITERATIONS + 1):
        jac = np.empty((3, 3))
        for j in range(3):
            xj = x.copy()
            xj[j] += FD_STEP
            jac[:, j] = (residuals(xj) - r) / FD_STEP
        if not np.all(np.isfinite(jac)) or abs(np.linalg.det(jac)) < 1e-300:
            break
        x = x - np.linalg.solve(jac, r)
        if abs(x[1]) > GAMMA_LIMIT_RAD or abs(x[2]) > 1.0:
            x[1] = float(np.clip(x[1], -GAMMA_LIMIT_RAD, GAMMA_LIMIT_RAD))
            x[2] = float(np.clip(x[2], -1.0, 1.0))
        r = residuals(x)
        if np.all(np.abs(r) <= tol):
            return iteration
    what = ("the pitch trim at its stop" if abs(x[2]) >= 1.0 else
            f"the glide steeper than {math.degrees(GAMMA_LIMIT_RAD):g} deg"
            if abs(x[1]) >= GAMMA_LIMIT_RAD else "no convergence")
    raise TrimError(f"cannot trim a steady glide at {speed_m_s:g} m/s ({what}: alpha "
                    f"{math.degrees(x[0]):.2f} deg, gamma {math.degrees(x[1]):.2f} deg; "
                    f"udot {r[0]:.1e} ft/s2, wdot {r[1]:.1e} ft/s2, qdot {r[2]:.1e} rad/s2)")



def glide_elevator_norm(fdm) -> float:
    """A glider's trimmed elevator, −1..1: its normalised command (elevator command + the
    pitch trim :func:`glide_trim` moves, clipped to ±1), what an FCS like SGS.xml's moves
    the surface by; that FCS writes only the deflection in rad, and its never-written
    ``fcs/elevator-pos-norm`` read 0 whatever the trim."""
    command = float(fdm[JP.FCS_ELEVATOR_CMD_NORM]) + float(fdm[PITCH_TRIM])
    return min(1.0, max(-1.0, command))
