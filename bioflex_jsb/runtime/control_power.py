"""What an aircraft's controls do at a trim, measured on its own JSBSim model: the numbers an
autopilot's gains are scaled with (generators/autopilot.py ``powered_gains``; docs/sitl.md,
"A powered aircraft").

At a level-flight trim (:meth:`~bioflex_jsb.runtime.fdm.Airframe.trim`) each quantity is a
central difference of JSBSim's own forces and moments at perturbed states, evaluated as the
rigid derivatives are (:class:`~bioflex_jsb.runtime.identification.Evaluator`: the model
evaluated at a state, its accelerations held, the propeller at its steady RPM), per unit of
the normalised command the autopilot writes (so the flight controls' gearing, travel and
limits are included), divided by JSBSim's own mass and moments of inertia of the loaded
aircraft:

* pitch, roll and yaw accelerations per unit elevator, aileron and rudder command
  [rad/s²]; the roll damping L_p [1/s] (∂ṗ/∂p) and the weathercock stiffness N_β [1/s²]
  (∂ṙ/∂β);
* the pitch stiffness M_α [1/s²] (∂q̇/∂α) and damping M_q [1/s] (∂q̇/∂q), and the lift
  slope over the momentum, L_α/(m V) [1/s] (the α a pull-up at q needs is q/(L_α/(m V)));
* the forward acceleration per unit throttle at the trim [m/s²] (thrust along the trim's
  stability x axis over the mass) and the steady climb angles the thrust left at full
  throttle and at idle would give, (T(δ) − T_trim)/W [rad] (a glider: 0).

Products of inertia are left out (c172p's I_xz is 0, as most of the package's aircraft).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bioflex_jsb import units as U
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.runtime.identification import (
    ALPHA_STEP_RAD,
    BETA_STEP_RAD,
    CONTROL_STEP,
    RATE_STEP,
    Evaluator,
    State,
)
from bioflex_jsb.runtime.results import LinearizationError
from bioflex_jsb.simulation import jsbsim_properties as JP

SLUG_FT2_TO_KG_M2 = U.KG_PER_SLUG * U.M_PER_FT**2


@dataclass(frozen=True)
class ControlPower:
    """Measured at a trim at ``speed_m_s`` [m/s], ``altitude_m`` [m] (module docstring):
    accelerations per unit command [rad/s²], ``roll_damping_1_s`` L_p [1/s, negative: it
    damps], ``yaw_stiffness_1_s2`` N_β [1/s², positive: weathercock stable],
    ``throttle_m_s2`` [m/s² per unit throttle], ``climb_angle_full_rad`` and
    ``climb_angle_idle_rad`` [rad], the trim's θ [rad] and throttle [-], M_α [1/s²], M_q
    [1/s], L_α/(m V) [1/s] and the mass [kg] JSBSim flies."""

    speed_m_s: float
    altitude_m: float
    pitch_rad_s2: float
    roll_rad_s2: float
    yaw_rad_s2: float
    roll_damping_1_s: float
    yaw_stiffness_1_s2: float
    throttle_m_s2: float
    climb_angle_full_rad: float
    theta_trim_rad: float
    throttle_trim: float
    climb_angle_idle_rad: float = 0.0
    pitch_alpha_1_s2: float = 0.0
    pitch_rate_1_s: float = 0.0
    lift_alpha_1_s: float = 0.0
    mass_kg: float = 0.0

    def as_dict(self) -> dict[str, float]:
        return dict(self.__dict__)


def measure_control_power(airframe, speed_m_s: float, altitude_m: float = 0.0
                          ) -> ControlPower:
    """The :class:`ControlPower` of ``airframe`` (an aircraft loaded with the modal wing's
    hooks: :meth:`Airframe.from_file`) at its level-flight trim at ``speed_m_s`` [m/s],
    ``altitude_m`` [m]. The airframe is left at the trim state. Raises TrimError where it
    cannot be trimmed, LinearizationError when a control moves nothing."""
    trim = airframe.trim(speed_m_s, altitude_m)
    fdm = airframe.jsbsim
    ev = Evaluator(airframe)
    powered = bool(airframe.engines)
    throttle = float(fdm[JP.throttle_cmd(0)]) if powered else 0.0
    base = State(trim.speed_m_s, trim.alpha_rad,
                 elevator_cmd=float(fdm[JP.FCS_ELEVATOR_CMD_NORM]),
                 aileron_cmd=float(fdm[JP.FCS_AILERON_CMD_NORM]),
                 rudder_cmd=float(fdm[JP.FCS_RUDDER_CMD_NORM]), throttle=throttle)
    mass_kg = float(fdm[JP.INERTIA_MASS_SLUGS]) * U.KG_PER_SLUG
    ixx, iyy, izz = (float(fdm[JP.inertia_slugs_ft2(f"i{a}{a}")]) * SLUG_FT2_TO_KG_M2
                     for a in "xyz")

    def at(**changes) -> State:
        return State(**{**base.__dict__, **changes})

    def diff(field: str, step: float, read):
        lo = ev(at(**{field: getattr(base, field) - step}))
        hi = ev(at(**{field: getattr(base, field) + step}))
        return (read(hi) - read(lo)) / (2.0 * step)

    pitch = diff("elevator_cmd", CONTROL_STEP, lambda r: r.pitch) / iyy
    roll = diff("aileron_cmd", CONTROL_STEP, lambda r: r.roll) / ixx
    yaw = diff("rudder_cmd", CONTROL_STEP, lambda r: r.yaw) / izz
    p_step = RATE_STEP * 2.0 * base.speed_m_s / airframe_span_m(fdm)
    lp = diff("p_rad_s", p_step, lambda r: r.roll) / ixx
    nb = diff("beta_rad", BETA_STEP_RAD, lambda r: r.yaw) / izz
    for name, value in (("elevator", pitch), ("aileron", roll)):
        if value == 0.0 or not math.isfinite(value):
            raise LinearizationError(f"{airframe.aircraft!r}: its {name} command moves "
                                     "nothing at the trim (at a stop?)")
    cos0, sin0 = math.cos(base.alpha_rad), math.sin(base.alpha_rad)

    def thrust(r) -> float:  # along the trim's stability x axis [N]
        return r.thrust_x * cos0 + r.thrust_z * sin0

    m_alpha = diff("alpha_rad", ALPHA_STEP_RAD, lambda r: r.pitch) / iyy
    q_step = RATE_STEP * 2.0 * base.speed_m_s / (float(fdm[JP.METRICS_CBARW_FT]) * U.M_PER_FT)
    m_q = diff("q_rad_s", q_step, lambda r: r.pitch) / iyy
    l_alpha = diff("alpha_rad", ALPHA_STEP_RAD, lambda r: r.lift) / (mass_kg * base.speed_m_s)
    per_throttle = climb = idle = 0.0
    if powered:
        t_lo, t_hi = max(0.0, throttle - CONTROL_STEP), min(1.0, throttle + CONTROL_STEP)
        per_throttle = (thrust(ev(at(throttle=t_hi))) - thrust(ev(at(throttle=t_lo)))) / (
            (t_hi - t_lo) * mass_kg)
        weight = mass_kg * STANDARD_GRAVITY_M_S2
        t_trim = thrust(ev(base))

        def angle(delta: float) -> float:
            return math.asin(max(-1.0, min(1.0, (thrust(ev(at(throttle=delta))) - t_trim)
                                           / weight)))
        climb, idle = angle(1.0), angle(0.0)
    ev(base)  # leave the airframe at the trim state
    return ControlPower(trim.speed_m_s, trim.altitude_m, pitch, roll, yaw, lp, nb,
                        per_throttle, climb, trim.theta_rad, throttle, idle, m_alpha, m_q,
                        l_alpha, mass_kg)


def airframe_span_m(fdm) -> float:
    """The wing span of the loaded aircraft [m] (JSBSim's ``metrics/bw-ft``)."""
    return float(fdm[JP.METRICS_BW_FT]) * U.M_PER_FT
