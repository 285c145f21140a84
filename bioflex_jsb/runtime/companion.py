"""The generated prototype's trim companion (runtime/fdm.py module docstring, "Two JSBSim
instances"): its electric contra-rotating pair brought from rest to its windmilling RPM
before JSBSim's trim, and the flying instance set to the companion's trim with its
propellers settled on the trim RPM while the airframe is held. Functions of two JSBSim
instances; their messages are captured by the caller."""

from __future__ import annotations

import math
from pathlib import Path

from bioflex_jsb import units as U
from bioflex_jsb.parameters.airframe import PROPULSION
from bioflex_jsb.runtime.engines import zero_thrust_advance_ratio
from bioflex_jsb.runtime.results import TrimError
from bioflex_jsb.simulation import jsbsim_properties as JP

# Settling the flying instance's propeller RPM on the companion's trim RPM (airframe held):
# relative RPM agreement asked for [-], and the longest settling time allowed [s] (the
# physical rotor's time constant is ≈ 0.3 s at cruise).
RPM_SETTLE_REL_TOL = 1e-9
RPM_SETTLE_MAX_S = 60.0
# JSBSim's integrator choices (FGPropagate) and the one that holds a state: 0 = eNone.
_INTEGRATOR_PROPERTIES = JP.INTEGRATOR_PROPERTIES
_INTEGRATOR_NONE = 0


def spin_up_propellers(fdm, speed_m_s: float, aircraft_path: Path, engine_count: int) -> None:
    """Bring both propellers of ``fdm`` (the trim instance) from rest to their windmilling
    RPM at ``speed_m_s`` in one step.

    At 0 RPM JSBSim's propeller turns the engine power P [ft·lbf/s] into a torque of
    P/(1 rad/s), so one step of dt [s] gives ω = throttle·P·dt/I per rotor (each rotor
    has 1/rotor_count of the power and of the inertia, the companion's effective one).
    The throttle for ω = 2πV/(J₀D) (J₀: zero-thrust advance ratio) is set on every
    engine for that step.
    """
    n = PROPULSION.rotor_count
    omega_rad_s = (
        2.0 * math.pi * speed_m_s
        / (zero_thrust_advance_ratio(aircraft_path) * PROPULSION.prop_diameter_m)
    )
    inertia_slug_ft2 = PROPULSION.trim_rotor_inertia_kg_m2 / n * U.SLUG_FT2_PER_KG_M2
    power_ft_lbf_s = PROPULSION.motor_max_shaft_power_w / n * U.LBF_FT_PER_N_M
    throttle = min(1.0, omega_rad_s * inertia_slug_ft2 / (power_ft_lbf_s * fdm.get_delta_t()))
    for i in range(engine_count):
        fdm[JP.throttle_cmd(i)] = throttle
    fdm.run()



def fly_at_companion_trim(fdm, src, v: float, controls: tuple[str, ...],
                          engine_count: int) -> float:
    """Set the flying instance ``fdm`` to the companion ``src``'s trim at ``v`` [m/s]:
    state, ``controls`` and every engine's throttle, propeller RPM; returns the time
    the RPM took to settle [s]."""
    # position and attitude first, then the body velocities in that attitude
    fdm[JP.IC_LAT_GEOD_RAD] = src[JP.POSITION_LAT_GEOD_RAD]
    fdm[JP.IC_LONG_GC_RAD] = src[JP.POSITION_LONG_GC_RAD]
    fdm[JP.IC_TERRAIN_ELEVATION_FT] = src[JP.POSITION_TERRAIN_ELEVATION_ASL_FT]
    fdm[JP.IC_H_SL_FT] = src[JP.POSITION_H_SL_FT]
    fdm[JP.IC_PHI_RAD] = src[JP.ATTITUDE_PHI_RAD]
    fdm[JP.IC_THETA_RAD] = src[JP.ATTITUDE_THETA_RAD]
    fdm[JP.IC_PSI_TRUE_RAD] = src[JP.ATTITUDE_PSI_RAD]
    fdm[JP.IC_U_FPS] = src[JP.VELOCITIES_U_FPS]
    fdm[JP.IC_V_FPS] = src[JP.VELOCITIES_V_FPS]
    fdm[JP.IC_W_FPS] = src[JP.VELOCITIES_W_FPS]
    fdm[JP.IC_P_RAD_SEC] = src[JP.VELOCITIES_P_RAD_SEC]
    fdm[JP.IC_Q_RAD_SEC] = src[JP.VELOCITIES_Q_RAD_SEC]
    fdm[JP.IC_R_RAD_SEC] = src[JP.VELOCITIES_R_RAD_SEC]
    controls = controls + tuple(JP.throttle_cmd(i) for i in range(engine_count))
    for name in controls:
        fdm[name] = src[name]
    rpm_names = [JP.engine(i, "propeller-rpm") for i in range(engine_count)]
    targets = [float(src[name]) for name in rpm_names]
    integrators = {name: fdm[name] for name in _INTEGRATOR_PROPERTIES}
    dt = fdm.get_delta_t()
    steps = 0
    fdm.run_ic()
    try:  # hold the airframe at the trim state; the propellers integrate their RPM
        for name in _INTEGRATOR_PROPERTIES:
            fdm[name] = _INTEGRATOR_NONE
        limit = max(1, round(RPM_SETTLE_MAX_S / dt))
        while steps < limit:
            fdm.run()
            steps += 1
            if all(
                abs(fdm[name] - target) <= RPM_SETTLE_REL_TOL * abs(target)
                for name, target in zip(rpm_names, targets, strict=True)
            ):
                break
    finally:
        for name, value in integrators.items():
            fdm[name] = value
    fdm.run_ic()  # back to the trim state; the RPM carries over
    rpm = [float(fdm[name]) for name in rpm_names]
    worst = max(abs(r - t) / abs(t) for r, t in zip(rpm, targets, strict=True))
    if worst > RPM_SETTLE_REL_TOL:
        raise TrimError(
            f"cannot trim at {v:g} m/s: the flying aircraft's propeller RPM did not settle "
            f"on the trim RPM {targets[0]:.1f} rev/min in {RPM_SETTLE_MAX_S:g} s "
            f"(relative difference {worst:.1e})"
        )
    return steps * dt
