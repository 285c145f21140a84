"""JSBSim's linear model reduced to the paper's rigid longitudinal states (pure numerics).

:meth:`Airframe.linearize` trims, then runs ``jsbsim.FGLinearization``, whose state vector is
[Vt, α, θ, q, RPM(s), β, φ, p, ψ, r, latitude, longitude, altitude]. It is turned into the
paper's rigid longitudinal model x_R = [u, α, q, θ] (u the airspeed perturbation [m/s]; α,
θ [rad]; q [rad/s]) by

* residualising the propeller RPM states r (``Rpm0``, ``Rpm1``: one per rotor of the pair)
  as quasi-static: A = A_xx − A_xr A_rr⁻¹ A_rx
  (the RPM settles in ≈ 0.3 s at the physical rotor inertia; JSBSim's state space already
  re-solves the RPM to steady state at every
  perturbation, so A_xr is zero to rounding and the thrust change with airspeed is in the u
  column). The rotors of the contra-rotating pair are identical and identically driven, so a
  longitudinal perturbation moves their RPMs together: the RPM states are first reduced to
  their symmetric combination (δRpm0 = δRpm1: columns summed, rows averaged); the
  antisymmetric one (one rotor faster than the other) is lateral, like β, φ, p, ψ, r, and is
  dropped with them. JSBSim's own 2×2 RPM block is singular (perturbing Rpm1 changes
  nothing), the symmetric 1×1 block is not;
* dropping the lateral states (β, φ, p, ψ, r), decoupled from the longitudinal ones at a
  wings-level trim, and the position states (latitude, longitude, altitude: the paper's x_R
  has no altitude; the density gradient over the short period's height change is negligible);
* converting Vt from ft/s to m/s (rows and columns).

The eigenvalues are labelled by frequency: the two of larger modulus are the short period,
the two of smaller modulus the phugoid.
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.runtime.results import LinearizationError
from bioflex_jsb.simulation import jsbsim_properties as JP

# JSBSim state names (FGStateSpace) of the rigid longitudinal model, in x_R order, and
# the factor from JSBSim's unit to SI.
_RIGID_JSBSIM = (("Vt", "ft/s", U.M_PER_FT), ("Alpha", "rad", 1.0), ("Q", "rad/s", 1.0),
                 ("Theta", "rad", 1.0))  # fmt: skip
_FAST_PREFIXES = ("Rpm", "PropPitch")  # engine states residualised as quasi-static
_DROPPED = {"Beta", "Phi", "P", "Psi", "R", "Latitude", "Longitude", "Alt"}


def reduce_to_rigid(
    a_full: np.ndarray, names: tuple[str, ...], units: tuple[str, ...]
) -> tuple[np.ndarray, tuple[str, ...]]:
    """JSBSim's system matrix → 4×4 A in x_R = [u, α, q, θ], SI (see module docstring).

    Returns the matrix and the names of the residualised (quasi-static) states.
    """
    index = {n: i for i, n in enumerate(names)}
    keep = []
    scale = []
    for name, unit, to_si in _RIGID_JSBSIM:
        if name not in index:
            raise LinearizationError(f"JSBSim's linear model has no {name!r} state: {names}")
        if units[index[name]] != unit:
            raise LinearizationError(
                f"JSBSim's {name!r} state is in {units[index[name]]!r}, expected {unit!r}"
            )
        keep.append(index[name])
        scale.append(to_si)
    fast = [i for i, n in enumerate(names) if n.startswith(_FAST_PREFIXES)]
    unknown = [n for n in names if n not in _DROPPED and not n.startswith(_FAST_PREFIXES)]
    unknown = [n for n in unknown if n not in {r[0] for r in _RIGID_JSBSIM}]
    if unknown:
        raise LinearizationError(f"JSBSim's linear model has unexpected states {unknown}")
    a_xx = a_full[np.ix_(keep, keep)]
    if fast:
        # symmetric combination of identical rotors: one state per prefix (Rpm, PropPitch)
        groups = sorted({p for n in (names[i] for i in fast) for p in _FAST_PREFIXES
                         if n.startswith(p)})  # fmt: skip
        e = np.zeros((len(fast), len(groups)))
        for row, i in enumerate(fast):
            e[row, next(g for g, p in enumerate(groups) if names[i].startswith(p))] = 1.0
        mean = np.linalg.solve(e.T @ e, e.T)  # average over the rotors of each group
        a_xr = a_full[np.ix_(keep, fast)] @ e
        a_rx = mean @ a_full[np.ix_(fast, keep)]
        a_rr = mean @ a_full[np.ix_(fast, fast)] @ e
        if not np.all(np.isfinite(a_rr)) or np.linalg.cond(a_rr) > 1e12:
            raise LinearizationError("the propeller RPM block of JSBSim's model is singular")
        a_xx = a_xx - a_xr @ np.linalg.solve(a_rr, a_rx)
    s = np.diag(scale)
    a_si = s @ a_xx @ np.linalg.inv(s)
    if not np.all(np.isfinite(a_si)):
        raise LinearizationError("JSBSim's linear model has non-finite entries")
    return a_si, tuple(names[i] for i in fast)


# Central-difference steps of the glider's A_RR (:func:`rigid_jacobian`): 0.01 m/s of
# airspeed and 1e-4 rad (rad/s) of α, θ, q: inside one interval of SGS.xml's tables (1°
# = 0.0175 rad), and large enough that JSBSim's accelerations (~10 ft/s² per rad, printed
# to 1e-12 relative) keep 7 digits in the differences.
JACOBIAN_STEPS = (0.01, 1e-4, 1e-4, 1e-4)
# JSBSim's α̇ (in C_mα̇) is computed from the previous evaluation's accelerations: three
# evaluations of one state make it that state's own (ẇ does not depend on α̇: the second
# is already exact; the third confirms it).
ALPHADOT_PASSES = 3



def rigid_jacobian(fdm, powered: bool = False) -> np.ndarray:
    """A_RR (4×4, x_R = [u [m/s], α [rad], q [rad/s], θ [rad]], SI) of ``fdm`` at its
    current state (the glide trim, wings level, no wind), by central differences of JSBSim's
    own state derivatives: V̇ = (u u̇ + w ẇ)/V, α̇ = (u ẇ − w u̇)/(u² + w²), q̇, θ̇ = q
    (body axes), each state evaluated until its α̇ is its own (:data:`ALPHADOT_PASSES`)
    and, ``powered``, with the propellers at their steady RPM (quasi-static, as JSBSim's
    trim and the linear model take them). The glider's replacement for JSBSim's
    FGLinearization, which reads the throttle of engine 0 and fails on an aircraft without
    one (it crashed the process in JSBSim 1.3.3), and the exact linearisation of JSBSim's
    model the identified derivatives are checked against (FGLinearization takes α̇ after
    one evaluation: tests/test_identification.py). The state is put back at the end."""
    m = 0.3048  # m per ft (exact), JSBSim's velocities and accelerations are in ft
    u0, w0 = fdm[JP.VELOCITIES_U_FPS] * m, fdm[JP.VELOCITIES_W_FPS] * m
    x0 = np.array([math.hypot(u0, w0), math.atan2(w0, u0), fdm[JP.VELOCITIES_Q_RAD_SEC],
                   fdm[JP.ATTITUDE_THETA_RAD]])

    def derivatives(x: np.ndarray) -> np.ndarray:
        v, alpha, q, theta = x
        u, w = v * math.cos(alpha), v * math.sin(alpha)
        fdm[JP.IC_U_FPS], fdm[JP.IC_V_FPS], fdm[JP.IC_W_FPS] = u / m, 0.0, w / m
        fdm[JP.IC_THETA_RAD], fdm[JP.IC_Q_RAD_SEC] = theta, q
        fdm[JP.IC_P_RAD_SEC], fdm[JP.IC_R_RAD_SEC] = 0.0, 0.0
        for _ in range(ALPHADOT_PASSES):
            fdm.run_ic()
            if powered:  # the propellers at their steady RPM, as JSBSim's trim puts them
                fdm.get_propulsion().get_steady_state()
        udot = fdm[JP.ACCELERATIONS_UDOT_FT_SEC2] * m
        wdot = fdm[JP.ACCELERATIONS_WDOT_FT_SEC2] * m
        return np.array([(u * udot + w * wdot) / v, (u * wdot - w * udot) / (u * u + w * w),
                         fdm[JP.ACCELERATIONS_QDOT_RAD_SEC2], q])

    a = np.empty((4, 4))
    for j, h in enumerate(JACOBIAN_STEPS):
        dx = np.zeros(4)
        dx[j] = h
        a[:, j] = (derivatives(x0 + dx) - derivatives(x0 - dx)) / (2.0 * h)
    derivatives(x0)  # back at the trim state
    return a


# JSBSim state names (FGStateSpace) of the lateral-directional model, in the order of
# flight_dynamics/lateral.py's x = [β, p, r, φ], with their units.
_LATERAL_JSBSIM = (("Beta", "rad"), ("P", "rad/s"), ("R", "rad/s"), ("Phi", "rad"))


def reduce_to_lateral(a_full: np.ndarray, names: tuple[str, ...],
                      units: tuple[str, ...]) -> np.ndarray:
    """JSBSim's system matrix → the 4×4 lateral block in x = [β, p, r, φ] (rad, rad/s):
    its rows and columns of Beta, P, R, Phi. The longitudinal states, the heading ψ (which
    nothing depends on), the position and the engine states are dropped: at a wings-level
    trim they are decoupled from the lateral ones but for a single propeller's gyroscopic
    and torque terms (the c172p: its full matrix's lateral roots within 2.2 % of the
    block's, the spiral's the farthest; docs/lateral.md)."""
    index = {n: i for i, n in enumerate(names)}
    keep = []
    for name, unit in _LATERAL_JSBSIM:
        if name not in index:
            raise LinearizationError(f"JSBSim's linear model has no {name!r} state: {names}")
        if units[index[name]] != unit:
            raise LinearizationError(f"JSBSim's {name!r} state is in "
                                     f"{units[index[name]]!r}, expected {unit!r}")
        keep.append(index[name])
    a = np.asarray(a_full, dtype=float)[np.ix_(keep, keep)]
    if not np.all(np.isfinite(a)):
        raise LinearizationError("JSBSim's linear model has non-finite entries")
    return a


# Central-difference steps of the lateral Jacobian (:func:`lateral_jacobian`): 1e-4 rad of
# β and φ, 1e-4 rad/s of p and r, the longitudinal steps' sizes (JACOBIAN_STEPS).
LATERAL_STEPS = (1e-4, 1e-4, 1e-4, 1e-4)


def lateral_jacobian(fdm, powered: bool = False) -> np.ndarray:
    """The lateral block A (4×4, x = [β [rad], p, r [rad/s], φ [rad]], body axes) of
    ``fdm`` at its current state (a wings-level trim, no wind), by central differences of
    JSBSim's own state derivatives: β̇ = (V v̇ − v V̇)/(V² cos β) with V̇ = (u u̇ + v v̇ +
    w ẇ)/V, ṗ, ṙ, φ̇ = p + (q sin φ + r cos φ) tan θ, each state evaluated until its α̇ is
    its own (:data:`ALPHADOT_PASSES`) and, ``powered``, with the propellers at their steady
    RPM; α, θ, V and q held at the trim's. The glider's replacement for FGLinearization
    (which needs an engine) and a second reference for the powered aircraft. The state is
    put back at the end."""
    m = 0.3048  # m per ft (exact)
    u0, v0, w0 = (fdm[k] * m for k in (JP.VELOCITIES_U_FPS, JP.VELOCITIES_V_FPS,
                                       JP.VELOCITIES_W_FPS))
    speed = math.sqrt(u0 * u0 + v0 * v0 + w0 * w0)
    alpha = math.atan2(w0, u0)
    theta, q0 = fdm[JP.ATTITUDE_THETA_RAD], fdm[JP.VELOCITIES_Q_RAD_SEC]
    x0 = np.array([math.asin(v0 / speed), fdm[JP.VELOCITIES_P_RAD_SEC],
                   fdm[JP.VELOCITIES_R_RAD_SEC], fdm[JP.ATTITUDE_PHI_RAD]])

    def derivatives(x: np.ndarray) -> np.ndarray:
        beta, p, r, phi = x
        u = speed * math.cos(alpha) * math.cos(beta)
        v = speed * math.sin(beta)
        w = speed * math.sin(alpha) * math.cos(beta)
        fdm[JP.IC_U_FPS], fdm[JP.IC_V_FPS], fdm[JP.IC_W_FPS] = u / m, v / m, w / m
        fdm[JP.IC_THETA_RAD], fdm[JP.IC_PHI_RAD] = theta, phi
        fdm[JP.IC_P_RAD_SEC], fdm[JP.IC_Q_RAD_SEC], fdm[JP.IC_R_RAD_SEC] = p, q0, r
        for _ in range(ALPHADOT_PASSES):
            fdm.run_ic()
            if powered:
                fdm.get_propulsion().get_steady_state()
        udot, vdot, wdot = (fdm[k] * m for k in (JP.ACCELERATIONS_UDOT_FT_SEC2,
                                                 JP.ACCELERATIONS_VDOT_FT_SEC2,
                                                 JP.ACCELERATIONS_WDOT_FT_SEC2))
        vt_dot = (u * udot + v * vdot + w * wdot) / speed
        return np.array([(speed * vdot - v * vt_dot) / (speed**2 * math.cos(beta)),
                         fdm[JP.ACCELERATIONS_PDOT_RAD_SEC2],
                         fdm[JP.ACCELERATIONS_RDOT_RAD_SEC2],
                         p + (q0 * math.sin(phi) + r * math.cos(phi)) * math.tan(theta)])

    a = np.empty((4, 4))
    for j, h in enumerate(LATERAL_STEPS):
        dx = np.zeros(4)
        dx[j] = h
        a[:, j] = (derivatives(x0 + dx) - derivatives(x0 - dx)) / (2.0 * h)
    derivatives(x0)  # back at the trim state
    return a
