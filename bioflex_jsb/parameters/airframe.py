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
from dataclasses import dataclass, replace

from bioflex_jsb.parameters import prototype as P

# DECISION: the airspeeds every command accepts [m/s], one range for all of them (gust,
# compare, modes, export, trim, linearize, sitl, export-jsbsim, bench). Top: the native
# export's modal tables and the flutter scan end at 40 m/s (above it nothing here is
# tabulated or checked); the paper's aircraft flies 10-25 m/s (Table 1). Bottom: 5 m/s,
# where the paper's root loci (Figs. 15-19) start; the linear models are defined there, but
# the JSBSim airframe cannot trim below about 9 m/s (C_L beyond the lift peak), so the
# commands that trim say so with a one-line reason.
AIRSPEED_RANGE_M_S = (5.0, 40.0)


@dataclass(frozen=True)
class ReferenceGeometry:
    """The reference geometry of the aerodynamic coefficients [m², m]: area S, span b, mean
    aerodynamic chord c̄ (pitch rates non-dimensional with c̄/(2V), roll/yaw with b/(2V))."""

    area_m2: float
    span_m: float
    mean_chord_m: float

    @property
    def aspect_ratio(self) -> float:
        """b²/S [-]."""
        return self.span_m**2 / self.area_m2


# Table 1: b, c̄; S = b·c̄ (DECISION "Reference area", parameters/prototype.py).
REFERENCE_GEOMETRY = ReferenceGeometry(area_m2=P.REFERENCE_AREA_M2, span_m=P.SPAN_M,
                                       mean_chord_m=P.MEAN_AERODYNAMIC_CHORD_M)
CRUISE_SPEED_M_S = P.CRUISE_SPEED_M_S  # Table 1, u_0: the airframe's initial/trim speed
FUSELAGE_LENGTH_M = P.FUSELAGE_LENGTH_M  # Table 1


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
    # Terms the paper's Table B2 leaves out (0: the prototype's model), identified from a
    # JSBSim aircraft (runtime/identification.py) or typed. Rates non-dimensional with
    # c̄/(2V); speed derivatives are V ∂C/∂V at constant α and throttle [-].
    cl_q_per_rad: float = 0.0  # ∂C_L/∂(q c̄/2V)
    cl_alphadot_per_rad: float = 0.0  # ∂C_L/∂(α̇ c̄/2V)
    cl_u: float = 0.0  # V ∂C_L/∂V (compressibility, Reynolds number, propwash)
    cd_u: float = 0.0  # V ∂C_D/∂V
    # V ∂C_m/∂V of the whole pitching moment about the CG, the thrust's included (thrust
    # line off the CG, propwash on the tail)
    cm_u: float = 0.0
    # The thrust along the trim's stability x axis [-]: V/(Q S) ∂T/∂V at constant throttle
    # with the engines at their steady RPM (a fixed-pitch propeller at constant power:
    # about −C_T; a jet: about 0), and per unit of throttle, ∂T/∂δt/(Q S) and its pitching
    # moment ∂M/∂δt/(Q S c̄). Zero for a glider, and for the prototype, whose propeller
    # model gives them (flight_dynamics/lti.py).
    ct_u: float = 0.0
    ct_delta_t: float = 0.0
    cm_delta_t: float = 0.0


# CALIBRATED (docs/decisions.md, "Rigid short period"): with S = b·c̄ and C_Lα fixed by the
# planform, C_mα and C_mq + C_mα̇ are solved from the trace and determinant of the 2×2
# short-period matrix so that the rigid eigenvalues are −5.6 ± 9.0i at 15 m/s (Table 3).
# The same constant non-dimensional derivatives give −7.4 ± 12.0i at 20 m/s (Table 3) because
# the short-period roots scale with airspeed. The split C_mα̇ = 0.34 C_mq is the tail-lag
# estimate dε/dα = 2 C_Lα/(π AR) = 0.34. C_mα = −1.05 means a static margin of 0.20 c̄.
# Checked in JSBSim: the full linearization of the generated airframe (drag, thrust, trim α,
# RPM quasi-static) reproduces both Table 3 rigid rows within 1 %
# (tests/test_trim_linearize.py), so these three values needed no re-calibration.
# Because they were fitted to them, Table 3's (and Table 6's identical) rigid rows are
# calibration checks, not validation (tests/test_paper_validation.py::
# test_calibration_rigid_short_period; docs/validation.md lists what was fitted to what).
# C_Lα = 5.3 /rad: lifting-line slope of the AR 9.3 wing (≈ 5.0) plus the small tail (≈ 0.3).
RIGID_AERODYNAMICS = RigidAerodynamics(
    # ESTIMATE: cambered thin membrane aerofoil, zero-lift angle −C_L0/C_Lα ≈ −4.3° (thin-
    # aerofoil theory puts α_0L ≈ −2h/c for a circular-arc camber line: ≈ 3.8 % camber, at the
    # low end of bird-wing sections). Raised from 0.25 so that 10 m/s (C_L = 1.29 in level
    # flight) trims inside the linear lift range that ends at alpha_stall_rad = 11°.
    cl0=0.40,
    cl_alpha_per_rad=5.3,
    # ESTIMATE: thin cambered membrane at Re ≈ 1.2e5–3e5; gliding birds' wings reach
    # C_L,max ≈ 1.4–1.6. Must exceed the linear curve's C_L(α_stall) = 1.42: the lift curve
    # rounds over from there to this peak (see POST_STALL).
    cl_max=1.50,
    alpha_stall_rad=math.radians(11.0),
    cl_delta_e_per_rad=0.35,  # ESTIMATE: tail lift per elevator, S_t/S·C_Lα,t·τ
    cd0=0.030,  # ESTIMATE: small UAV with fuselage and tails at Re ≈ 2e5
    k_induced=1.0 / (math.pi * P.ASPECT_RATIO * 0.85),  # Oswald e = 0.85
    cm0=0.05,  # ESTIMATE: JSBSim trims at ≈ 1.8° α with ≈ +1° elevator at 15 m/s cruise
    cm_alpha_per_rad=-1.05,  # CALIBRATED to Table 3 rigid rows
    cm_q_per_rad=-7.3,  # CALIBRATED to Table 3 rigid rows
    cm_alphadot_per_rad=-2.5,  # CALIBRATED to Table 3 rigid rows (0.34 × C_mq)
    cm_delta_e_per_rad=-0.9,  # ESTIMATE: tail volume 0.4 × C_Lα,t 3.5 × τ 0.65
    cy_beta_per_rad=-0.30,  # ESTIMATE: fuselage + fin
    cl_beta_per_rad=-0.06,  # ESTIMATE: small dihedral effect
    # ESTIMATE: strip theory, −C_Lα/8 · (1+3λ)/(1+λ) for λ = 1 ≈ −0.66, less tip loss
    cl_p_per_rad=-0.45,
    cl_r_per_rad=0.08,  # ESTIMATE: C_L/4 at cruise
    cl_delta_a_per_rad=0.20,  # ESTIMATE: outboard ailerons, 25 % chord, 40 % span
    cn_beta_per_rad=0.06,  # ESTIMATE: small fin on a short arm
    cn_p_per_rad=-0.03,  # ESTIMATE: −C_L/8
    cn_r_per_rad=-0.08,  # ESTIMATE: fin damping
    cn_delta_r_per_rad=-0.05,  # ESTIMATE
    cy_delta_r_per_rad=0.10,  # ESTIMATE
)


# --------------------------------------------------------------------------------------
# Beyond the linear range: the shape of the stall (used by the JSBSim lift and drag tables)
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class PostStall:
    """Shape of the lift and drag curves outside the linear range of :class:`RigidAerodynamics`.

    Positive side: from ``alpha_stall_rad`` the lift curve rounds over (a parabola that leaves
    the linear curve with its slope C_Lα and peaks at ``cl_max``), then decays towards the
    flat-plate value C_N90·sin α·cos α with the angle constant ``decay_rad``. The negative side
    is the mirror image about ``alpha_negative_stall_rad`` (peak C_L(α_neg) − (C_L,max − C_L(α_s))).
    Separated-flow drag C_N90·(sin²α − sin²α_edge) is added beyond either edge.

    Attributes:
        alpha_negative_stall_rad: end of the linear range at negative α [rad].
        normal_force_90deg: C_N at α = 90° of the whole wing [-] (flat plate of AR ≈ 9).
        decay_rad: angle over which post-peak lift relaxes to the flat-plate value [rad].
        alpha_table_min_rad, alpha_table_max_rad: extent of the JSBSim α tables [rad].
        alpha_table_step_rad: spacing of the JSBSim α tables (plus the break points) [rad].
    """

    alpha_negative_stall_rad: float
    normal_force_90deg: float
    decay_rad: float
    alpha_table_min_rad: float
    alpha_table_max_rad: float
    alpha_table_step_rad: float


POST_STALL = PostStall(
    alpha_negative_stall_rad=math.radians(-10.0),  # ESTIMATE: the spec's linear range −10°..11°
    normal_force_90deg=1.25,  # ESTIMATE: flat plate of aspect ratio ≈ 9 broadside (Hoerner)
    decay_rad=math.radians(4.0),  # ESTIMATE: abrupt thin-aerofoil leading-edge stall
    alpha_table_min_rad=math.radians(-30.0),  # the specification asks for at least −20°..+30°
    alpha_table_max_rad=math.radians(30.0),
    alpha_table_step_rad=math.radians(1.0),  # resolution of the stall region
)


# --------------------------------------------------------------------------------------
# Geometry needed by the JSBSim airframe: CG, propeller, contact points
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class AirframeGeometry:
    """Positions in the JSBSim *structural frame*, SI [m].

    Structural frame: origin at the fuselage nose, x positive **aft**, y positive to
    starboard, z positive **up** (JSBSim's convention; docs/conventions.md). The wing frame of
    :mod:`bioflex_jsb.parameters.wing` has its origin at the root leading edge, which sits at
    ``wing_root_leading_edge_x_m`` here.

    Attributes:
        wing_root_leading_edge_x_m: x of the root leading edge [m].
        cg_x_m, cg_z_m: centre of gravity [m]; also the aerodynamic reference point, so the
            pitching-moment coefficients are about the CG as in RIGID_AERODYNAMICS.
        propeller_x_m, propeller_z_m: propeller hub [m] (tractor; thrust line through the CG).
        contact_points_m: (name, x, y, z) of the structure contact points [m].
    """

    wing_root_leading_edge_x_m: float
    cg_x_m: float
    cg_z_m: float
    propeller_x_m: float
    propeller_z_m: float
    contact_points_m: tuple[tuple[str, float, float, float], ...]


_WING_ROOT_LE_X_M = 0.30  # ESTIMATE: Fig. 1, wing root a little over 1/3 of the 0.85 m fuselage
_CG_X_M = _WING_ROOT_LE_X_M + 0.30 * P.MEAN_AERODYNAMIC_CHORD_M  # wing.DEFAULT_PLANFORM.x_cg_m

AIRFRAME_GEOMETRY = AirframeGeometry(
    wing_root_leading_edge_x_m=_WING_ROOT_LE_X_M,
    cg_x_m=_CG_X_M,
    cg_z_m=0.0,  # ESTIMATE: on the fuselage axis (defines z = 0)
    propeller_x_m=-0.03,  # ESTIMATE: tractor propeller 3 cm ahead of the nose
    propeller_z_m=0.0,  # ESTIMATE: thrust line through the CG (no thrust pitching moment)
    contact_points_m=(
        # ESTIMATE: belly skid under the nose, tail skid, and the two wing tips (z = 0);
        # they only matter on the ground, the analyses here fly in the air.
        ("nose-skid", 0.05, 0.0, -0.05),  # 5 cm behind the nose, 5 cm below the axis
        ("tail-skid", P.FUSELAGE_LENGTH_M - 0.05, 0.0, -0.03),  # Table 1 length, 3 cm below
        ("left-wing-tip", _CG_X_M, -P.SPAN_M / 2.0, 0.0),  # Table 1 span
        ("right-wing-tip", _CG_X_M, P.SPAN_M / 2.0, 0.0),
    ),
)


# --------------------------------------------------------------------------------------
# Electric propulsion (not in the paper: an ESTIMATE sized for 10-25 m/s level flight)
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Propulsion:
    """Electric drive: a contra-rotating pair of fixed-pitch propellers on one motor power.

    The propeller's thrust and power coefficient tables are computed from this blade
    geometry by blade-element momentum theory in :mod:`bioflex_jsb.aerodynamics.propeller`.

    Contra-rotating pair (DECISION, ``rotor_count`` = 2): the paper's model is longitudinal,
    and a symmetric (vertical) gust must leave the airframe symmetric. A single propeller's
    angular momentum I_p·ω·x̂ gives a gyroscopic moment PQR × (I_p ω x̂) that turns pitch rate
    into yaw (r ≈ 0.5 q at 8 × the physical ``rotor_inertia_kg_m2``) and its reaction
    torque needs aileron at trim. The JSBSim rendering therefore splits the drive described
    here (one blade geometry, ``motor_max_shaft_power_w``, ``rotor_inertia_kg_m2``: the
    totals) into ``rotor_count`` identical electric engines, each with 1/rotor_count of the
    power, driving identical propellers at the same point of the thrust line with opposite
    senses; each propeller has 1/rotor_count of the C_T(J), C_P(J) tables and of the rotor
    inertia. At a common throttle every rotor then turns at the single propeller's RPM, the
    total thrust, power and RPM response are the single propeller's, and the angular momenta
    and reaction torques cancel exactly.

    Attributes:
        motor_max_shaft_power_w: total shaft power at full throttle [W], all motors (JSBSim
            ``electric`` engine: power = throttle × this, independent of RPM).
        prop_diameter_m, prop_pitch_m: propeller diameter and geometric pitch [m].
        prop_blades: number of blades [-].
        prop_chord_stations: (r/R, c/R) pairs of the blade chord distribution [-].
        prop_hub_radius_fraction: r/R where the blade starts [-].
        prop_section_lift_slope_per_rad: blade-section lift slope [1/rad].
        prop_section_zero_lift_rad: section zero-lift angle relative to the pitch line [rad].
        prop_section_cl_max: section lift limit (stall) [-].
        prop_section_cd0, prop_section_cd_k: section drag c_d = cd0 + k c_l² [-].
        rotor_inertia_kg_m2: propellers plus motor rotors polar moment of inertia, total of
            the pair [kg·m²] (physical: the flying aircraft's rotors).
        trim_rotor_inertia_kg_m2: effective rotor inertia of the trim companion aircraft,
            total of the pair [kg·m²] (numerical: JSBSim's trim RPM iteration, see below).
        advance_ratio_max: end of the J = V/(nD) tables [-] (past zero thrust).
        rotor_count: number of contra-rotating rotors the drive is split into [-] (2: a
            pair with opposite senses; must be even so that the senses cancel).
    """

    motor_max_shaft_power_w: float
    prop_diameter_m: float
    prop_pitch_m: float
    prop_blades: int
    prop_chord_stations: tuple[tuple[float, float], ...]
    prop_hub_radius_fraction: float
    prop_section_lift_slope_per_rad: float
    prop_section_zero_lift_rad: float
    prop_section_cl_max: float
    prop_section_cd0: float
    prop_section_cd_k: float
    rotor_inertia_kg_m2: float
    trim_rotor_inertia_kg_m2: float
    advance_ratio_max: float
    rotor_count: int = 2

    def __post_init__(self) -> None:
        if self.rotor_count < 2 or self.rotor_count % 2:
            raise ValueError(
                f"rotor_count must be even and >= 2 (contra-rotating pairs), got {self.rotor_count}"
            )


_INCH_M = 0.0254  # definition of the inch, for propeller sizes quoted in inches
PROPULSION = Propulsion(
    # ESTIMATE: level flight needs D·V ≈ 1.8 N × 15 m/s = 28 W at cruise and 3.8 N × 25 m/s =
    # 95 W at 25 m/s (RIGID_AERODYNAMICS drag polar); with a propeller efficiency ≈ 0.6–0.7 a
    # 300 W motor (120 W/kg, usual for 2–3 kg hand-launched UAVs) flies 25 m/s at under half
    # throttle and tops out at ≈ 32 m/s (JSBSim trim). Cruise electrical power ≈ 28 W /
    # (0.6 propeller × 0.8 motor) ≈ 60 W for 20 min (Table 1 endurance) ≈ 20 Wh, a 4-cell
    # 2.2 Ah pack: consistent with Table 1's 2.5 kg.
    motor_max_shaft_power_w=300.0,
    prop_diameter_m=12.0 * _INCH_M,  # ESTIMATE: 12×8 in, a common size on 300 W motors
    prop_pitch_m=8.0 * _INCH_M,  # ESTIMATE: p/D = 0.67 keeps thrust to well above 25 m/s
    prop_blades=2,  # ESTIMATE
    # ESTIMATE: chord distribution of a typical thin-electric (APC-E-like) blade
    prop_chord_stations=((0.15, 0.10), (0.40, 0.18), (0.75, 0.15), (1.00, 0.07)),
    prop_hub_radius_fraction=0.15,  # ESTIMATE: spinner radius
    prop_section_lift_slope_per_rad=0.9 * 2.0 * math.pi,  # ESTIMATE: thin section, low Re
    prop_section_zero_lift_rad=math.radians(-2.0),  # ESTIMATE: cambered flat-bottom section
    prop_section_cl_max=1.1,  # ESTIMATE: low-Re section stall
    prop_section_cd0=0.020,  # ESTIMATE: Re ≈ 1e5 section drag
    prop_section_cd_k=0.02,  # ESTIMATE
    # ESTIMATE (total of the pair, each rotor has half): 25 g of blades ≈ m D²/12 × 0.6
    # tapered = 1.2e-4 kg·m², motor bells 0.3e-4. The flying aircraft (bioflex.xml) has this
    # physical value: RPM time constant ≈ 0.3 s at cruise, so the thrust follows the airspeed
    # quasi-statically on the phugoid time scale, as in JSBSim's linearization.
    rotor_inertia_kg_m2=1.5e-4,
    # NUMERICAL (an effective value, only in the trim companion aircraft bioflex_trim.xml):
    # JSBSim's trim brings each rotor's RPM to steady state by explicit Euler steps of a fixed
    # 0.5 s (FGPropulsion::GetSteadyState), stable only if I > ½ · 0.5 s · |∂(Q_motor −
    # Q_prop)/∂ω| per rotor. Each rotor has half the torques and half the inertia, so the
    # condition is the single propeller's: ≈ 1.0e-3 kg·m² in total from 3 to 80 m/s at any
    # throttle; 1.2e-3 adds 20 % margin (8 × physical). The steady state (trim, and the
    # linearization with the RPM residualised) does not depend on the inertia; the adapter
    # trims the companion and sets the flying aircraft to that trim (jsbsim_fdm.Airframe).
    trim_rotor_inertia_kg_m2=1.2e-3,
    advance_ratio_max=1.3,  # beyond the ≈ 0.9 zero-thrust J of a 12×8
    rotor_count=2,  # DECISION: contra-rotating pair, symmetric gust response (class docstring)
)


# --------------------------------------------------------------------------------------
# Control-surface travel
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ControlLimits:
    """Maximum deflection of each surface, symmetric about zero [rad].

    Signs (JSBSim's): +elevator = trailing edge down (nose down); +aileron = left aileron
    trailing edge down, right up (roll right); +rudder = trailing edge left (nose left).
    """

    elevator_max_rad: float
    aileron_max_rad: float
    rudder_max_rad: float


CONTROL_LIMITS = ControlLimits(
    elevator_max_rad=math.radians(20.0),  # ESTIMATE: usual small-UAV servo throw
    aileron_max_rad=math.radians(20.0),  # ESTIMATE
    rudder_max_rad=math.radians(25.0),  # ESTIMATE
)


# --------------------------------------------------------------------------------------
# One aircraft's rigid data as one object (passed into every linear analysis)
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DerivativeSchedule:
    """Rigid derivatives identified at several speeds (a JSBSim aircraft's, whose tables
    depend on α: the trim α, and so the derivatives, change with speed):
    ``speeds_m_s`` ascending [m/s], ``points`` the :class:`RigidAerodynamics` at each,
    ``source`` where they come from (the JSBSim aircraft, the altitude). :meth:`at`
    interpolates every field linearly in speed and holds the end values beyond the speeds
    identified (outside its flight envelope an aircraft cannot be trimmed; the
    non-dimensional derivatives of its nearest edge are kept)."""

    speeds_m_s: tuple[float, ...]
    points: tuple[RigidAerodynamics, ...]
    source: str

    def __post_init__(self) -> None:
        if len(self.speeds_m_s) != len(self.points) or not self.points:
            raise ValueError("a derivative schedule needs one point per speed, at least one")
        if any(b <= a for a, b in zip(self.speeds_m_s[:-1], self.speeds_m_s[1:], strict=True)):
            raise ValueError(f"speeds must ascend, got {self.speeds_m_s}")

    def at(self, speed_m_s: float) -> RigidAerodynamics:
        """The derivatives at ``speed_m_s`` [m/s] (class docstring)."""
        v = float(speed_m_s)
        speeds = self.speeds_m_s
        if v <= speeds[0]:
            return self.points[0]
        if v >= speeds[-1]:
            return self.points[-1]
        k = next(i for i in range(1, len(speeds)) if v <= speeds[i])
        w = (v - speeds[k - 1]) / (speeds[k] - speeds[k - 1])
        a, b = self.points[k - 1], self.points[k]
        return RigidAerodynamics(**{f: (1.0 - w) * getattr(a, f) + w * getattr(b, f)
                                    for f in RigidAerodynamics.__dataclass_fields__})


@dataclass(frozen=True)
class AirframeData:
    """What the linear analyses take from an aircraft besides its elastic wing: the reference
    geometry of the coefficients (S [m²], b [m], c̄ [m]), the mass properties about the CG
    [kg, kg·m²], the rigid derivatives (per rad, moments about the CG) and the propulsion
    (``None``: no engine, a glider: the throttle column of the LTI model is zero).

    Built by the loader (:meth:`bioflex_jsb.definition.aircraft.Aircraft.airframe_data`);
    :data:`PROTOTYPE_AIRFRAME` is the prototype's, the default of the two constructors
    that start an analysis (:func:`bioflex_jsb.flight_dynamics.rigid.level_flight_condition`
    and :func:`bioflex_jsb.flight_dynamics.wing_model.build_wing`); everything below reads
    the object it is handed (the flight condition's or the wing's)."""

    name: str
    reference: ReferenceGeometry
    mass: MassProperties
    aero: RigidAerodynamics
    propulsion: Propulsion | None = None
    # derivatives identified at several speeds (a JSBSim aircraft's); ``aero`` is then the
    # schedule's at the cruise speed, and :meth:`at_speed` gives each speed's
    schedule: DerivativeSchedule | None = None

    def at_speed(self, speed_m_s: float) -> AirframeData:
        """This airframe with the derivatives at ``speed_m_s`` [m/s] (itself without a
        schedule)."""
        if self.schedule is None:
            return self
        aero = self.schedule.at(speed_m_s)
        return self if aero == self.aero else replace(self, aero=aero)


PROTOTYPE_AIRFRAME = AirframeData("bioflex", REFERENCE_GEOMETRY, MASS_PROPERTIES,
                                  RIGID_AERODYNAMICS, PROPULSION)
