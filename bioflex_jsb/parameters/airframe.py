"""Rigid airframe data that the paper does not print: estimates and calibrations.

Each value says where it comes from:

* ``ESTIMATE``: from the geometry of Table 1 and textbook relations (the relation is named);
* ``CALIBRATED``: chosen so that a published result is reproduced; the result is named.

Frames and signs (see ``docs/conventions.md``): stability derivatives are per radian and
non-dimensionalised the usual way (rates with c̄/(2V) for pitch, b/(2V) for roll/yaw);
C_L is positive up, C_m positive nose-up, C_D positive aft, C_Y positive to starboard.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bioflex_jsb.parameters import prototype as P


@dataclass(frozen=True)
class MassProperties:
    """Rigid-body mass data about the centre of gravity, body axes [kg, kg·m²]."""

    mass_kg: float
    ixx_kg_m2: float
    iyy_kg_m2: float
    izz_kg_m2: float
    ixz_kg_m2: float


# I_y is Table 1. I_x and I_z are ESTIMATES (docs/decisions.md, "Roll and yaw inertia"):
# wing of mass m_w = 0.2 kg (under the 10 % of Section 3.1) as a uniform bar of span b,
# I = m_w b²/12 = 0.048 kg·m², plus fuselage/avionics of 2.3 kg as a slender body of radius
# 0.04 m (I_x += ½·m·r² = 0.0018). I_z ≈ I_x + I_y − (fuselage contribution to I_x), the
# usual near-planar-body relation, i.e. 0.0928 + 0.048 = 0.141 kg·m².
MASS_PROPERTIES = MassProperties(
    mass_kg=P.MASS_KG,
    ixx_kg_m2=0.050,
    iyy_kg_m2=P.PITCH_INERTIA_KG_M2,
    izz_kg_m2=0.141,
    ixz_kg_m2=0.0,
)


@dataclass(frozen=True)
class RigidAerodynamics:
    """Non-dimensional rigid-aircraft aerodynamic model, linear up to stall [per rad].

    Reference area ``P.REFERENCE_AREA_M2``, chord ``P.MEAN_AERODYNAMIC_CHORD_M``, span
    ``P.SPAN_M``; moments about the centre of gravity.
    """

    cl0: float  # C_L at α = 0, δe = 0 [-]
    cl_alpha_per_rad: float
    cl_max: float  # stall: C_L peak [-]
    alpha_stall_rad: float  # α at which the linear lift curve is cut [rad]
    cl_delta_e_per_rad: float
    cd0: float  # zero-lift drag [-]
    k_induced: float  # C_D = cd0 + k C_L² [-]
    cm0: float  # C_m at α = 0, δe = 0 [-]
    cm_alpha_per_rad: float
    cm_q_per_rad: float  # ∂C_m/∂(q c̄ / 2V)
    cm_alphadot_per_rad: float  # ∂C_m/∂(α̇ c̄ / 2V)
    cm_delta_e_per_rad: float
    cy_beta_per_rad: float
    cl_beta_per_rad: float  # rolling moment C_l
    cl_p_per_rad: float
    cl_r_per_rad: float
    cl_delta_a_per_rad: float
    cn_beta_per_rad: float
    cn_p_per_rad: float
    cn_r_per_rad: float
    cn_delta_r_per_rad: float
    cy_delta_r_per_rad: float


# CALIBRATED (docs/decisions.md, "Rigid short period"): with S = b·c̄ and C_Lα fixed by the
# planform, C_mα and C_mq + C_mα̇ are solved from the trace and determinant of the 2×2
# short-period matrix so that the rigid eigenvalues are −5.6 ± 9.0i at 15 m/s (Table 3).
# The same constant non-dimensional derivatives give −7.4 ± 12.0i at 20 m/s (Table 3) because
# the short-period roots scale with airspeed. The split C_mα̇ = 0.34 C_mq is the tail-lag
# estimate dε/dα = 2 C_Lα/(π AR) = 0.34. C_mα = −1.05 means a static margin of 0.20 c̄.
# C_Lα = 5.3 /rad: lifting-line slope of the AR 9.3 wing (≈ 5.0) plus the small tail (≈ 0.3).
RIGID_AERODYNAMICS = RigidAerodynamics(
    cl0=0.25,  # ESTIMATE: cambered membrane aerofoil, zero-lift angle ≈ −2.7°
    cl_alpha_per_rad=5.3,
    cl_max=1.2,  # ESTIMATE: thin cambered membrane at Re ≈ 2e5
    alpha_stall_rad=math.radians(11.0),
    cl_delta_e_per_rad=0.35,  # ESTIMATE: tail lift per elevator, S_t/S·C_Lα,t·τ
    cd0=0.030,  # ESTIMATE: small UAV with fuselage and tails at Re ≈ 2e5
    k_induced=1.0 / (math.pi * P.ASPECT_RATIO * 0.85),  # Oswald e = 0.85
    cm0=0.05,  # ESTIMATE: trims at ≈ 2.5° α with small elevator at cruise
    cm_alpha_per_rad=-1.05,  # CALIBRATED to Table 3 rigid rows
    cm_q_per_rad=-7.3,  # CALIBRATED to Table 3 rigid rows
    cm_alphadot_per_rad=-2.5,  # CALIBRATED to Table 3 rigid rows (0.34 × C_mq)
    cm_delta_e_per_rad=-0.9,  # ESTIMATE: tail volume 0.4 × C_Lα,t 3.5 × τ 0.65
    cy_beta_per_rad=-0.30,  # ESTIMATE: fuselage + fin
    cl_beta_per_rad=-0.06,  # ESTIMATE: small dihedral effect
    cl_p_per_rad=-0.45,  # ESTIMATE: strip theory, −C_Lα/8 · (1+3λ)/(1+λ) for λ = 1 ≈ −0.66, less tip loss
    cl_r_per_rad=0.08,  # ESTIMATE: C_L/4 at cruise
    cl_delta_a_per_rad=0.20,  # ESTIMATE: outboard ailerons, 25 % chord, 40 % span
    cn_beta_per_rad=0.06,  # ESTIMATE: small fin on a short arm
    cn_p_per_rad=-0.03,  # ESTIMATE: −C_L/8
    cn_r_per_rad=-0.08,  # ESTIMATE: fin damping
    cn_delta_r_per_rad=-0.05,  # ESTIMATE
    cy_delta_r_per_rad=0.10,  # ESTIMATE
)
