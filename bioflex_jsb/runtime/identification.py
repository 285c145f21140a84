"""A JSBSim aircraft's rigid derivatives, identified from its own model at a trim
(docs/aircraft.md, "Derivatives from JSBSim").

At a level-flight trim (:meth:`~bioflex_jsb.runtime.fdm.Airframe.trim`: JSBSim's own trim,
the engines running) the aircraft's forces and moments are evaluated at perturbed states by
JSBSim itself (``RunIC``: the models evaluated at a state, nothing integrated) and the
derivatives are central differences of them, non-dimensional as
:class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics` defines them (moments about the
CG: JSBSim's ``moments/*-aero-lbsft`` are about the CG; rates with c̄/(2V) and b/(2V)).

Each state is evaluated with its accelerations held: JSBSim computes α̇ from the body
accelerations u̇, ẇ of the state (``FGAuxiliary``), so a perturbed α or q, which accelerate
the aircraft, would carry a spurious α̇ into the tables. The modal wing's two force hooks
(``modal-lift``, ``modal-drag``: forces at the CG, no moment) are set by a fixed-point
iteration so that u̇ = 0 and ẇ = α̇ (u² + w²)/u for the α̇ asked for (0 but for the α̇
derivatives): the aerodynamic forces are then those of exactly the state asked for. The
propellers are at their steady RPM for each state's airspeed and throttle
(``FGPropulsion::GetSteadyState``, what JSBSim's trim does): quasi-static on the time scale
of the rigid modes (a propeller's RPM settles in tenths of a second).

Which forces each derivative takes:

* α, q, α̇, elevator, β, p, r, aileron, rudder: the aerodynamic forces and moments alone
  (the thrust is fixed in the body, and so in the trim's stability axes, whatever α);
  lift and drag in wind axes, the lateral forces and moments in body axes;
* airspeed (at constant α and throttle) and throttle: aerodynamics and propulsion; the
  thrust is taken along the trim's stability x axis, the pitching moment is the whole one
  (a thrust line off the CG, propwash on the tail).

The constant terms are chosen so that the linear model reproduces JSBSim's trim at this
speed: C_L0 = C_L,trim − C_Lα α_0 − C_Lδe δe_0 with C_L,trim = W/(Q S) (the level-flight
lift the linear model uses), C_m0 = −C_mα α_0 − C_mδe δe_0 (aerodynamic and thrust moments
balance at the trim), C_D0 and k from the drag and its α slope at the trim (C_Dα =
2 k C_L C_Lα: k is the polar's local slope ∂C_D/∂(C_L²) there). C_L,max is the largest lift
coefficient of a sweep in α from the trim to the top of the aircraft's α range (its
``<alphalimits>``), and α_stall is set so that the linear model's rounded lift curve peaks at
the same α (:func:`bioflex_jsb.aerodynamics.airframe_polars.alpha_peak_rad`).

β̇ terms, which a few aircraft of the jsbsim package have (f22, global5000), are evaluated at
each lateral state's own β̇.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.flight_dynamics.lateral import LateralAerodynamics, LateralTrim
from bioflex_jsb.parameters.airframe import ReferenceGeometry, RigidAerodynamics
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.runtime.results import LinearizationError, TrimError
from bioflex_jsb.simulation import jsbsim_properties as JP

# Central-difference steps, each inside one interval of the usual JSBSim table (1° = 0.0175
# rad of α or β; 0.1 of a normalised rate) and large enough that the forces (printed by
# JSBSim to 1e-12 relative) keep 7 significant digits in the difference.
ALPHA_STEP_RAD = 1e-3
BETA_STEP_RAD = 1e-3
RATE_STEP = 1e-3  # of the non-dimensional rates q c̄/2V, α̇ c̄/2V, p b/2V, r b/2V
SPEED_STEP_REL = 2e-3
CONTROL_STEP = 0.01  # of a normalised command (elevator, aileron, rudder, throttle)
# The α sweep for C_L,max [rad]: a quarter degree, finer than the tables' 1° points.
STALL_SWEEP_STEP_RAD = math.radians(0.25)
# The acceleration-holding iteration (module docstring): it converges by a factor of the
# α̇ terms' share of the lift (C_Lα̇ c̄/(2V) against m V: under 1e-2 for every aircraft of
# the package), so 8 passes reach 1e-12 of the first correction.
HOLD_PASSES = 8
# What "held" means [ft/s²]: JSBSim's own trim tolerance on u̇, ẇ is 1e-3 ft/s²; 1e-6
# leaves an α̇ of 1e-8 rad/s against the 0.04 rad/s of the α̇ step (J3Cub at 30 m/s ended
# at 4e-7 ft/s², the rounding of its forces).
HOLD_TOLERANCE_FT_S2 = 1e-6

HOOK_LIFT = JP.external_force_magnitude("modal-lift")  # along body −z [lbf]
HOOK_DRAG = JP.external_force_magnitude("modal-drag")  # along body −x [lbf]


@dataclass(frozen=True)
class Reading:
    """Forces [N] and moments [N·m] at one evaluated state: ``lift``, ``drag`` (wind axes,
    aerodynamic), ``side`` (body y, aerodynamic), ``roll``, ``pitch``, ``yaw`` (body axes,
    about the CG, aerodynamic), ``thrust_x``, ``thrust_z``, ``thrust_pitch`` (propulsion,
    body axes), the dynamic pressure ``q_pa`` [Pa] and the surface angles [rad]
    ``elevator``, ``aileron``, ``rudder``."""

    lift: float
    drag: float
    side: float
    roll: float
    pitch: float
    yaw: float
    thrust_x: float
    thrust_z: float
    thrust_pitch: float
    q_pa: float
    elevator: float
    aileron: float
    rudder: float


@dataclass(frozen=True)
class State:
    """A state to evaluate: airspeed [m/s], α, β [rad], p, q, r [rad/s], α̇ [rad/s], the
    normalised commands (elevator, aileron, rudder) and the throttle of every engine."""

    speed_m_s: float
    alpha_rad: float
    beta_rad: float = 0.0
    p_rad_s: float = 0.0
    q_rad_s: float = 0.0
    r_rad_s: float = 0.0
    alphadot_rad_s: float = 0.0
    elevator_cmd: float = 0.0
    aileron_cmd: float = 0.0
    rudder_cmd: float = 0.0
    throttle: float = 0.0


@dataclass(frozen=True)
class IdentifiedPoint:
    """The derivatives at one trim: ``aero`` (:class:`RigidAerodynamics`) and the trim they
    were taken at (speed [m/s], α [rad], elevator [rad], throttle [-], altitude [m])."""

    aero: RigidAerodynamics
    speed_m_s: float
    alpha_rad: float
    elevator_rad: float
    throttle: float
    altitude_m: float


def _first(manager, *names: str) -> str | None:
    return next((n for n in names if manager.hasNode(n)), None)


class Evaluator:
    """Evaluates JSBSim's forces at states of ``airframe`` (a loaded
    :class:`~bioflex_jsb.runtime.fdm.Airframe` of an aircraft with the modal wing's hooks),
    held as the module docstring says. The airframe is left at the last state evaluated:
    trim it again before flying it. ``steady_rpm``: bring the propellers to their steady
    RPM at each state (False: keep the trim's, for states at the trim's airspeed and
    throttle on an airframe whose flying instance cannot take JSBSim's steady-state step:
    the prototype, whose trim companion exists for that, runtime/fdm.py)."""

    def __init__(self, airframe, steady_rpm: bool = True) -> None:
        self.airframe = airframe
        self.steady_rpm = steady_rpm
        fdm = airframe.jsbsim
        self.fdm = fdm
        m = fdm.get_property_manager()
        for hook in (HOOK_LIFT, HOOK_DRAG):
            if not m.hasNode(hook):
                raise LinearizationError(f"{airframe.aircraft!r} has no modal-wing hook {hook!r}"
                                         " (load it with Airframe.from_file)")
        self.engines = airframe.engines
        self.elevator = _first(m, JP.FCS_ELEVATOR_POS_RAD)
        left, right = JP.FCS_LEFT_AILERON_POS_RAD, JP.FCS_RIGHT_AILERON_POS_RAD
        self.ailerons = ((left, right) if m.hasNode(left) and m.hasNode(right)
                         else (_first(m, JP.FCS_AILERON_POS_RAD),))
        self.rudder = _first(m, JP.FCS_RUDDER_POS_RAD)
        if self.elevator is None:
            raise LinearizationError(f"{airframe.aircraft!r}: its flight controls write no "
                                     "fcs/elevator-pos-rad: the elevator's angle is unknown")

    def _surface(self, names) -> float:
        values = [self.fdm[n] for n in names if n is not None]
        if not values:
            return math.nan
        return 0.5 * (values[0] - values[1]) if len(values) == 2 else values[0]

    def __call__(self, s: State) -> Reading:
        with self.airframe.capturing():  # JSBSim's messages (a mass report per RunIC)
            return self._evaluate(s)

    def _evaluate(self, s: State) -> Reading:
        fdm = self.fdm
        fdm[JP.IC_VT_FPS] = s.speed_m_s * U.FT_PER_M
        fdm[JP.IC_ALPHA_RAD] = s.alpha_rad
        fdm[JP.IC_BETA_RAD] = s.beta_rad
        fdm[JP.IC_P_RAD_SEC], fdm[JP.IC_Q_RAD_SEC], fdm[JP.IC_R_RAD_SEC] = (
            s.p_rad_s, s.q_rad_s, s.r_rad_s)
        fdm[JP.FCS_ELEVATOR_CMD_NORM] = s.elevator_cmd
        fdm[JP.FCS_AILERON_CMD_NORM] = s.aileron_cmd
        fdm[JP.FCS_RUDDER_CMD_NORM] = s.rudder_cmd
        for e in self.engines:
            fdm[JP.throttle_cmd(e.index)] = s.throttle
        lift_hook = drag_hook = 0.0
        for k in range(HOLD_PASSES):
            fdm[HOOK_LIFT], fdm[HOOK_DRAG] = lift_hook, drag_hook
            fdm.run_ic()
            if k == 0 and self.engines and self.steady_rpm:
                fdm.get_propulsion().get_steady_state()
                fdm.run_ic()
            u, w = fdm[JP.VELOCITIES_U_FPS], fdm[JP.VELOCITIES_W_FPS]
            udot = fdm[JP.ACCELERATIONS_UDOT_FT_SEC2]
            wdot = fdm[JP.ACCELERATIONS_WDOT_FT_SEC2] - s.alphadot_rad_s * (u * u + w * w) / u
            slugs = fdm[JP.INERTIA_MASS_SLUGS]
            lift_hook += wdot * slugs  # +lift hook (up) lowers ẇ by F/m
            drag_hook += udot * slugs
        if max(abs(udot), abs(wdot)) > HOLD_TOLERANCE_FT_S2:
            raise LinearizationError(
                f"{self.airframe.aircraft!r}: the accelerations of the state at "
                f"{s.speed_m_s:g} m/s, alpha {math.degrees(s.alpha_rad):.2f} deg could not be "
                f"held (udot {udot:.1e}, wdot {wdot:.1e} ft/s2 left)")
        n, nm = U.N_PER_LBF, U.N_M_PER_LBF_FT
        powered = bool(self.engines)  # a glider's JSBSim has no propulsion forces at all
        return Reading(
            lift=fdm[JP.FORCES_FWZ_AERO_LBS] * n, drag=fdm[JP.FORCES_FWX_AERO_LBS] * n,
            side=fdm[JP.FORCES_FBY_AERO_LBS] * n, roll=fdm[JP.MOMENTS_L_AERO_LBSFT] * nm,
            pitch=fdm[JP.MOMENTS_M_AERO_LBSFT] * nm, yaw=fdm[JP.MOMENTS_N_AERO_LBSFT] * nm,
            thrust_x=fdm[JP.FORCES_FBX_PROP_LBS] * n if powered else 0.0,
            thrust_z=fdm[JP.FORCES_FBZ_PROP_LBS] * n if powered else 0.0,
            thrust_pitch=fdm[JP.MOMENTS_M_PROP_LBSFT] * nm if powered else 0.0,
            q_pa=fdm[JP.AERO_QBAR_PSF] * U.PA_PER_PSF,
            elevator=fdm[self.elevator], aileron=self._surface(self.ailerons),
            rudder=self._surface((self.rudder,)))


def _central(evaluate, minus: State, plus: State):
    return evaluate(minus), evaluate(plus)


def identify_point(airframe, speed_m_s: float, reference: ReferenceGeometry,
                   mass_kg: float, altitude_m: float = 0.0) -> IdentifiedPoint:
    """The rigid derivatives of ``airframe`` (module docstring) at a level-flight trim at
    ``speed_m_s`` [m/s] and ``altitude_m`` [m], non-dimensional on ``reference`` (S, b, c̄)
    with the weight of ``mass_kg`` [kg] for C_L,trim. Raises :class:`TrimError` when the
    aircraft cannot be trimmed there."""
    trim = airframe.trim(speed_m_s, altitude_m)
    fdm = airframe.jsbsim
    ev = Evaluator(airframe)
    v, a0 = trim.speed_m_s, trim.alpha_rad
    s_ref, b, c = reference.area_m2, reference.span_m, reference.mean_chord_m
    throttle = float(fdm[JP.FCS_THROTTLE_CMD_NORM_0]) if airframe.engines else 0.0
    base = State(v, a0, elevator_cmd=float(fdm[JP.FCS_ELEVATOR_CMD_NORM]),
                 aileron_cmd=float(fdm[JP.FCS_AILERON_CMD_NORM]),
                 rudder_cmd=float(fdm[JP.FCS_RUDDER_CMD_NORM]), throttle=throttle)

    def at(**changes) -> State:
        return State(**{**base.__dict__, **changes})

    r0 = ev(base)
    q0 = r0.q_pa
    qs = q0 * s_ref
    cl_trim = mass_kg * STANDARD_GRAVITY_M_S2 / qs

    def d_coeffs(lo: Reading, hi: Reading, step: float):
        """(C_L, C_D, C_m, C_Y, C_l, C_n) differences over ``step`` (aerodynamic)."""
        def coeffs(r: Reading) -> np.ndarray:
            qsr = r.q_pa * s_ref
            return np.array([r.lift / qsr, r.drag / qsr, r.pitch / (qsr * c),
                             r.side / qsr, r.roll / (qsr * b), r.yaw / (qsr * b)])
        return (coeffs(hi) - coeffs(lo)) / step

    d_alpha = d_coeffs(*_central(ev, at(alpha_rad=a0 - ALPHA_STEP_RAD),
                                 at(alpha_rad=a0 + ALPHA_STEP_RAD)), 2 * ALPHA_STEP_RAD)
    q_step = RATE_STEP * 2.0 * v / c
    d_q = d_coeffs(*_central(ev, at(q_rad_s=-q_step), at(q_rad_s=q_step)), 2 * RATE_STEP)
    d_ad = d_coeffs(*_central(ev, at(alphadot_rad_s=-q_step), at(alphadot_rad_s=q_step)),
                    2 * RATE_STEP)
    lo, hi = _central(ev, at(elevator_cmd=base.elevator_cmd - CONTROL_STEP),
                      at(elevator_cmd=base.elevator_cmd + CONTROL_STEP))
    if hi.elevator == lo.elevator:
        raise LinearizationError(f"{airframe.aircraft!r}: the elevator command does not move "
                                 "fcs/elevator-pos-rad at the trim (at a stop?)")
    d_de = d_coeffs(lo, hi, hi.elevator - lo.elevator)
    d_beta = d_coeffs(*_central(ev, at(beta_rad=-BETA_STEP_RAD), at(beta_rad=BETA_STEP_RAD)),
                      2 * BETA_STEP_RAD)
    pr_step = RATE_STEP * 2.0 * v / b
    d_p = d_coeffs(*_central(ev, at(p_rad_s=-pr_step), at(p_rad_s=pr_step)), 2 * RATE_STEP)
    d_r = d_coeffs(*_central(ev, at(r_rad_s=-pr_step), at(r_rad_s=pr_step)), 2 * RATE_STEP)
    lo, hi = _central(ev, at(aileron_cmd=base.aileron_cmd - CONTROL_STEP),
                      at(aileron_cmd=base.aileron_cmd + CONTROL_STEP))
    d_da = d_coeffs(lo, hi, hi.aileron - lo.aileron) if hi.aileron != lo.aileron \
        else np.zeros(6)
    lo, hi = _central(ev, at(rudder_cmd=base.rudder_cmd - CONTROL_STEP),
                      at(rudder_cmd=base.rudder_cmd + CONTROL_STEP))
    d_dr = d_coeffs(lo, hi, hi.rudder - lo.rudder) if hi.rudder != lo.rudder else np.zeros(6)
    # airspeed at constant α and throttle: aerodynamics and propulsion (module docstring)
    dv = SPEED_STEP_REL * v
    lo, hi = _central(ev, at(speed_m_s=v - dv), at(speed_m_s=v + dv))
    cos0, sin0 = math.cos(a0), math.sin(a0)

    def thrust_sx(r: Reading) -> float:  # along the trim's stability x axis [N]
        return r.thrust_x * cos0 + r.thrust_z * sin0

    def lift_total(r: Reading) -> float:  # −Z along the trim's stability z axis [N]
        return r.lift + r.thrust_x * sin0 - r.thrust_z * cos0

    cd_u = v * (hi.drag / (hi.q_pa * s_ref) - lo.drag / (lo.q_pa * s_ref)) / (2 * dv)
    ct_u = v / qs * (thrust_sx(hi) - thrust_sx(lo)) / (2 * dv)
    cl_u = v / qs * (lift_total(hi) - lift_total(lo)) / (2 * dv) - 2.0 * cl_trim
    cm_u = v / (qs * c) * ((hi.pitch + hi.thrust_pitch) - (lo.pitch + lo.thrust_pitch)) / (
        2 * dv)
    ct_dt = cm_dt = 0.0
    if airframe.engines:
        t_lo, t_hi = max(0.0, throttle - CONTROL_STEP), min(1.0, throttle + CONTROL_STEP)
        lo, hi = _central(ev, at(throttle=t_lo), at(throttle=t_hi))
        ct_dt = (thrust_sx(hi) - thrust_sx(lo)) / (t_hi - t_lo) / qs
        cm_dt = (hi.thrust_pitch - lo.thrust_pitch) / (t_hi - t_lo) / (qs * c)
    cl_max, alpha_peak = _lift_peak(ev, at, a0, airframe.alpha_limits_rad[1], s_ref)
    cla, cda, cma = d_alpha[0], d_alpha[1], d_alpha[2]
    de0 = r0.elevator
    cl0 = cl_trim - cla * a0 - d_de[0] * de0
    cd_trim = r0.drag / qs
    k = cda / (2.0 * cl_trim * cla)
    alpha_stall = 2.0 * (cl_max - cl0) / cla - alpha_peak
    aero = RigidAerodynamics(
        cl0=cl0, cl_alpha_per_rad=cla, cl_max=cl_max, alpha_stall_rad=alpha_stall,
        cl_delta_e_per_rad=d_de[0], cd0=cd_trim - k * cl_trim**2, k_induced=k,
        cm0=-cma * a0 - d_de[2] * de0, cm_alpha_per_rad=cma, cm_q_per_rad=d_q[2],
        cm_alphadot_per_rad=d_ad[2], cm_delta_e_per_rad=d_de[2],
        cy_beta_per_rad=d_beta[3], cl_beta_per_rad=d_beta[4], cl_p_per_rad=d_p[4],
        cl_r_per_rad=d_r[4], cl_delta_a_per_rad=d_da[4], cn_beta_per_rad=d_beta[5],
        cn_p_per_rad=d_p[5], cn_r_per_rad=d_r[5], cn_delta_r_per_rad=d_dr[5],
        cy_delta_r_per_rad=d_dr[3], cl_q_per_rad=d_q[0], cl_alphadot_per_rad=d_ad[0],
        cl_u=cl_u, cd_u=cd_u, cm_u=cm_u, ct_u=ct_u, ct_delta_t=ct_dt, cm_delta_t=cm_dt)
    ev(base)  # leave the airframe at the trim state
    return IdentifiedPoint(aero, v, a0, de0, throttle, altitude_m)


def _lift_peak(ev: Evaluator, at, alpha0: float, alpha_top: float, s_ref: float
               ) -> tuple[float, float]:
    """(C_L,max [-], its α [rad]) of a sweep in α from ``alpha0`` to ``alpha_top`` [rad]
    (module docstring); the top itself when the lift still rises there."""
    if not alpha_top > alpha0:
        raise TrimError(f"the trim's alpha {math.degrees(alpha0):.2f} deg is at or above "
                        f"the aircraft's alpha limit {math.degrees(alpha_top):.2f} deg")
    alphas = np.arange(alpha0, alpha_top, STALL_SWEEP_STEP_RAD).tolist() + [alpha_top]
    best, best_alpha = -math.inf, alpha0
    for a in alphas:
        r = ev(at(alpha_rad=a))
        cl = r.lift / (r.q_pa * s_ref)
        if cl > best:
            best, best_alpha = cl, a
        elif cl < best - 0.05:  # well past the peak
            break
    return best, best_alpha


@dataclass(frozen=True)
class LateralPoint:
    """The lateral-directional derivatives at one trim (:func:`identify_lateral`):
    ``trim`` (:class:`~bioflex_jsb.flight_dynamics.lateral.LateralTrim`: speed, density,
    α_0, θ_0, the mass and inertia JSBSim flies with, S, b) and ``aero``
    (:class:`~bioflex_jsb.flight_dynamics.lateral.LateralAerodynamics`, body axes), the
    trim's drag coefficient ``cd_trim`` [-] (the body-axis C_Yβ holds −C_D of a SIDE axis
    in wind axes: docs/lateral.md) and the surface positions at the trim [rad]."""

    trim: LateralTrim
    aero: LateralAerodynamics
    cd_trim: float
    aileron_rad: float
    rudder_rad: float


def identify_lateral(airframe, speed_m_s: float, reference: ReferenceGeometry,
                     altitude_m: float = 0.0, source: str = "") -> LateralPoint:
    """The lateral-directional derivatives of ``airframe`` at its trim at ``speed_m_s``
    [m/s], ``altitude_m`` [m] (JSBSim's full trim; a glider's steady glide), by the
    module's method: central differences of JSBSim's aerodynamic side force, rolling and
    yawing moments (body axes, about the CG, ``forces/fby-aero-lbs``,
    ``moments/l-aero-lbsft``, ``moments/n-aero-lbsft``) at β ± 1e-3 rad, p̂, r̂ ± 1e-3
    (p̂ = p b/2V, body rates) and the aileron and rudder commands ± 0.01 (per radian of the
    surfaces' own positions), each state with its u̇, ẇ held (:class:`Evaluator`),
    non-dimensional on ``reference`` (S, b). The mass and inertia are JSBSim's at the trim
    (``inertia/*``: the pilot's and the fuel's included). Raises :class:`TrimError` when
    the aircraft cannot be trimmed there, :class:`LinearizationError` when a surface
    command moves nothing."""
    trim = airframe.trim(speed_m_s, altitude_m)
    fdm = airframe.jsbsim
    # every state has the trim's airspeed and throttle: the propellers stay at the trim's RPM
    ev = Evaluator(airframe, steady_rpm=False)
    v, a0 = trim.speed_m_s, trim.alpha_rad
    theta0 = float(fdm[JP.ATTITUDE_THETA_RAD])
    slug_ft2 = U.KG_PER_SLUG * U.M_PER_FT**2
    mass = float(fdm[JP.INERTIA_MASS_SLUGS]) * U.KG_PER_SLUG
    ixx, izz, j13 = (float(fdm[JP.inertia_slugs_ft2(k)]) * slug_ft2
                     for k in ("ixx", "izz", "ixz"))
    rho = float(fdm[JP.ATMOSPHERE_RHO_SLUGS_FT3]) * U.KG_PER_SLUG / U.M_PER_FT**3
    s_ref, b = reference.area_m2, reference.span_m
    throttle = float(fdm[JP.FCS_THROTTLE_CMD_NORM_0]) if airframe.engines else 0.0
    base = State(v, a0, elevator_cmd=float(fdm[JP.FCS_ELEVATOR_CMD_NORM]),
                 aileron_cmd=float(fdm[JP.FCS_AILERON_CMD_NORM]),
                 rudder_cmd=float(fdm[JP.FCS_RUDDER_CMD_NORM]), throttle=throttle)

    def at(**changes) -> State:
        return State(**{**base.__dict__, **changes})

    def coeffs(r: Reading) -> np.ndarray:
        qsr = r.q_pa * s_ref
        return np.array([r.side / qsr, r.roll / (qsr * b), r.yaw / (qsr * b)])

    def slope(lo: Reading, hi: Reading, step: float) -> np.ndarray:
        return (coeffs(hi) - coeffs(lo)) / step

    r0 = ev(base)
    cd_trim = r0.drag / (r0.q_pa * s_ref)
    d_beta = slope(ev(at(beta_rad=-BETA_STEP_RAD)), ev(at(beta_rad=BETA_STEP_RAD)),
                   2 * BETA_STEP_RAD)
    pr_step = RATE_STEP * 2.0 * v / b
    d_p = slope(ev(at(p_rad_s=-pr_step)), ev(at(p_rad_s=pr_step)), 2 * RATE_STEP)
    d_r = slope(ev(at(r_rad_s=-pr_step)), ev(at(r_rad_s=pr_step)), 2 * RATE_STEP)
    surfaces = []
    for field, angle in (("aileron_cmd", "aileron"), ("rudder_cmd", "rudder")):
        cmd = getattr(base, field)
        lo, hi = ev(at(**{field: cmd - CONTROL_STEP})), ev(at(**{field: cmd + CONTROL_STEP}))
        travel = getattr(hi, angle) - getattr(lo, angle)
        if not travel or not math.isfinite(travel):
            raise LinearizationError(f"{airframe.aircraft!r}: the {angle} command does not "
                                     f"move its surface at the trim at {v:g} m/s (at a "
                                     "stop, or no fcs/*-pos-rad)")
        surfaces.append(slope(lo, hi, travel))
    d_da, d_dr = surfaces
    aero = LateralAerodynamics(
        cy_beta=d_beta[0], cy_p=d_p[0], cy_r=d_r[0], cy_delta_a=d_da[0], cy_delta_r=d_dr[0],
        cl_beta=d_beta[1], cl_p=d_p[1], cl_r=d_r[1], cl_delta_a=d_da[1], cl_delta_r=d_dr[1],
        cn_beta=d_beta[2], cn_p=d_p[2], cn_r=d_r[2], cn_delta_a=d_da[2], cn_delta_r=d_dr[2])
    # I_xz = ∫ x z dm is the negative of the J₁₃ JSBSim integrates with (flight_dynamics/
    # lateral.py; measured: tests/test_lateral.py)
    lat_trim = LateralTrim(v, rho, a0, theta0, mass, ixx, izz, -j13, s_ref, b,
                           source or f"JSBSim aircraft {airframe.aircraft!r} identified at "
                           f"{v:g} m/s, {altitude_m:g} m")
    ev(base)  # leave the airframe at the trim state, its hooks unloaded
    airframe.set_external_reactions()
    return LateralPoint(lat_trim, aero, cd_trim, r0.aileron, r0.rudder)
