"""Rigid longitudinal derivatives (Table B2) and the A_RR, G_R blocks of Eq. (4).

Conventions (docs/conventions.md):

* stability axes at a wings-level, constant-altitude trim (θ_0 = γ_0 + α_0 with γ_0 = 0; the
  gravity term of the u-equation is −g, as in Appendix B);
* state x_R = [u, α, q, θ]: u the airspeed perturbation [m/s], α the angle of attack [rad],
  q the pitch rate [rad/s], θ the pitch angle [rad];
* gust input w_g [m/s] positive for an **upward** gust: it raises α by w_g/u_0
  (Appendix B's G_R = [X_α, Z_α/u_0, M_α + M_ẇ Z_α, 0]ᵀ/u_0).

Dimensional derivatives follow Table B2 with Q = ½ρu_0², S = b·c̄ (docs/decisions.md):
Z-derivatives are accelerations [m/s² per unit], M-derivatives angular accelerations.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.parameters.airframe import AirframeData, RigidAerodynamics
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_M_S2

RIGID_STATES = ("u", "alpha", "q", "theta")
RIGID_STATE_UNITS = ("m/s", "rad", "rad/s", "rad")


@dataclass(frozen=True)
class FlightCondition:
    """Trim flight condition: level, wings-level flight.

    Attributes:
        speed_m_s: true airspeed u_0 [m/s].
        density_kg_m3: air density ρ [kg/m³].
        cl_trim: lift coefficient in trim, C_L0 = W/(Q S) [-] (level flight).
        cd_trim: drag coefficient in trim [-].
        alpha_trim_rad: angle of attack in trim [rad] (linear lift curve).
        airframe: the aircraft trimmed (S, c̄, mass, I_yy, rigid derivatives): what the
            derivatives built at this condition read.
    """

    speed_m_s: float
    density_kg_m3: float
    cl_trim: float
    cd_trim: float
    alpha_trim_rad: float
    airframe: AirframeData

    @property
    def dynamic_pressure_pa(self) -> float:
        """Q = ½ ρ u_0² [Pa]."""
        return 0.5 * self.density_kg_m3 * self.speed_m_s**2


def level_flight_condition(
    speed_m_s: float,
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    mass_kg: float | None = None,
    *,
    airframe: AirframeData,
) -> FlightCondition:
    """Level-flight trim of the linear aerodynamic model at ``speed_m_s`` [m/s].

    C_L0 = m g / (Q S); α_0 from the linear lift curve (elevator lift neglected, as the
    paper's A_RR does); C_D from the drag polar. Valid as a *linear model* at any speed, also
    below the stall speed where the real aircraft cannot trim (the paper's root loci start at
    5 m/s); callers that need a flyable trim use the JSBSim adapter.
    """
    if not (np.isfinite(speed_m_s) and speed_m_s > 0.0):
        raise ValueError(f"speed_m_s must be finite and > 0, got {speed_m_s!r}")
    if aero is None:
        airframe = airframe.at_speed(speed_m_s)  # an identified schedule's derivatives
    elif aero is not airframe.aero:
        airframe = replace(airframe, aero=aero)
    if mass_kg is not None and mass_kg != airframe.mass.mass_kg:
        airframe = replace(airframe, mass=replace(airframe.mass, mass_kg=float(mass_kg)))
    aero = airframe.aero
    q_pa = 0.5 * density_kg_m3 * speed_m_s**2
    cl = airframe.mass.mass_kg * STANDARD_GRAVITY_M_S2 / (q_pa * airframe.reference.area_m2)
    cd = aero.cd0 + aero.k_induced * cl**2
    alpha = (cl - aero.cl0) / aero.cl_alpha_per_rad
    return FlightCondition(speed_m_s, density_kg_m3, cl, cd, alpha, airframe)


@dataclass(frozen=True)
class RigidDerivatives:
    """Dimensional longitudinal derivatives of Table B2 at one flight condition.

    Units: X_u, Z_u [1/s]; X_α, Z_α [m/s²/rad]; M_u [rad/(s²·m/s)]; M_α [1/s²];
    M_q [1/s]; M_ẇ [1/m] (M_ẇ·u_0 = M_α̇ [1/s]); Z_q [m/s per rad/s] and Z_ẇ [-] (the lift
    of pitch rate and of α̇ = ẇ/u_0: C_Lq, C_Lα̇; zero in Table B2).
    """

    condition: FlightCondition
    x_u: float
    x_alpha: float
    z_u: float
    z_alpha: float
    m_u: float
    m_alpha: float
    m_q: float
    m_wdot: float
    z_q: float = 0.0
    z_wdot: float = 0.0


def rigid_derivatives(
    condition: FlightCondition,
    aero: RigidAerodynamics | None = None,
    mass_kg: float | None = None,
    iyy_kg_m2: float | None = None,
) -> RigidDerivatives:
    """Table B2 derivatives, with the terms Table B2 leaves out where the derivatives give
    them (:class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics`: 0 for the paper's
    aircraft, where C_Du = C_Lu = C_mu = 0, incompressible and no Reynolds effect, thrust
    speed-independent, no C_Lq, C_Lα̇): X_u = (C_Tu − 2 C_D − C_Du) Q S/(m u_0), Z_u =
    −(2 C_L + C_Lu) Q S/(m u_0), M_u = C_mu Q S c̄/(I_yy u_0), Z_q = −C_Lq Q S c̄/(2 m u_0),
    Z_ẇ = −C_Lα̇ Q S c̄/(2 m u_0²). C_Dα = 2 k C_L0 C_Lα from the parabolic polar. S, c̄, the
    mass, I_yy and the derivatives are the condition's airframe's; ``aero``, ``mass_kg``,
    ``iyy_kg_m2`` replace them."""
    af = condition.airframe
    aero = af.aero if aero is None else aero
    mass_kg = af.mass.mass_kg if mass_kg is None else mass_kg
    iyy_kg_m2 = af.mass.iyy_kg_m2 if iyy_kg_m2 is None else iyy_kg_m2
    u0 = condition.speed_m_s
    qs = condition.dynamic_pressure_pa * af.reference.area_m2
    cbar = af.reference.mean_chord_m
    cd_alpha = 2.0 * aero.k_induced * condition.cl_trim * aero.cl_alpha_per_rad
    # written so that the paper's aircraft (every extra term 0) gives Table B2 to the bit
    return RigidDerivatives(
        condition=condition,
        x_u=-(2.0 * condition.cd_trim + aero.cd_u - aero.ct_u) * qs / (mass_kg * u0),
        x_alpha=-(cd_alpha - condition.cl_trim) * qs / mass_kg,
        z_u=-(2.0 * condition.cl_trim + aero.cl_u) * qs / (mass_kg * u0),
        z_alpha=-(aero.cl_alpha_per_rad + condition.cd_trim) * qs / mass_kg,
        m_u=aero.cm_u * qs * cbar / (iyy_kg_m2 * u0),
        m_alpha=aero.cm_alpha_per_rad * qs * cbar / iyy_kg_m2,
        m_q=aero.cm_q_per_rad * qs * cbar**2 / (2.0 * iyy_kg_m2 * u0),
        m_wdot=aero.cm_alphadot_per_rad * qs * cbar**2 / (2.0 * iyy_kg_m2 * u0**2),
        z_q=-aero.cl_q_per_rad * qs * cbar / (2.0 * mass_kg * u0),
        z_wdot=-aero.cl_alphadot_per_rad * qs * cbar / (2.0 * mass_kg * u0**2),
    )


def alpha_rate_scale(d: RigidDerivatives) -> tuple[float, float]:
    """(the divisor of the α̇ equation u_0 (1 − Z_ẇ) [m/s], the factor u_0 divided by it
    [-]): with the lift of α̇ (Z_ẇ) the α equation u_0 α̇ = Z_u u + Z_α α + (u_0 + Z_q) q
    + Z_ẇ u_0 α̇ is solved for α̇. Without it the divisor is u_0 and the factor exactly 1."""
    u0 = d.condition.speed_m_s
    divisor = u0 - d.z_wdot * u0
    return divisor, u0 / divisor


def rigid_matrices(d: RigidDerivatives) -> tuple[np.ndarray, np.ndarray]:
    """A_RR (4×4) and G_R (4×1) of Appendix B, states [u, α, q, θ], input w_g [m/s]; the
    α row solved for α̇ (:func:`alpha_rate_scale`) and the pitch row with M_ẇ u_0 α̇."""
    u0 = d.condition.speed_m_s
    g = STANDARD_GRAVITY_M_S2
    div, f = alpha_rate_scale(d)
    a = np.array(
        [
            [d.x_u, d.x_alpha, 0.0, -g],
            [d.z_u / div, d.z_alpha / div, (u0 + d.z_q) / div, 0.0],
            [
                d.m_u + d.m_wdot * d.z_u * f,
                d.m_alpha + d.m_wdot * d.z_alpha * f,
                d.m_q + d.m_wdot * (u0 + d.z_q) * f,
                0.0,
            ],
            [0.0, 0.0, 1.0, 0.0],
        ]
    )
    g_r = np.array([d.x_alpha, d.z_alpha / div, d.m_alpha + d.m_wdot * d.z_alpha * f,
                    0.0]) / u0
    return a, g_r.reshape(4, 1)
