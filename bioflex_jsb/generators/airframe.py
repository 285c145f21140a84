"""Generate the JSBSim rendering of the rigid airframe from the Python parameter set.

The numbers live in :mod:`bioflex_jsb.parameters` (SI); this module converts them once, with
the named constants of :mod:`bioflex_jsb.units`, and writes the JSBSim files:

====================================================  =========================================
``aircraft/bioflex/bioflex.xml``                      the aircraft (metrics, mass, contacts,
                                                      propulsion, systems, aerodynamics,
                                                      external reactions)
``aircraft/bioflex/Engines/bioflex_motor.xml``        ``electric`` engine (shaft power of one
                                                      motor of the pair)
``aircraft/bioflex/Engines/bioflex_propeller.xml``    fixed-pitch propeller, C_T(J) and C_P(J)
                                                      of one rotor of the pair
``aircraft/bioflex/reset_cruise.xml``                 initial condition: Table 1 cruise, ISA sea
                                                      level, for scripts and the console program
``aircraft/bioflex_trim/bioflex_trim.xml``            trim companion: the same aircraft with the
                                                      effective rotor inertia (see below)
``aircraft/bioflex_trim/Engines/...``                 its motor and ``bioflex_trim_propeller``
``systems/bioflex_flight_controls.xml``               elevator, aileron, rudder, throttle
====================================================  =========================================

Propulsion: a contra-rotating pair
----------------------------------
The paper's model is longitudinal, so the propulsion must not couple a symmetric manoeuvre
into the lateral axes. A single propeller does: its angular momentum I_p·ω·x̂ gives the
gyroscopic moment PQR × (I_p ω x̂), which turns pitch rate into yaw (with 8 times the
physical rotor inertia a 0.3 m/s vertical gust gave r ≈ 0.5 q). The drive is therefore
rendered as ``PROPULSION.rotor_count`` (2) identical
``electric`` engines, each with 1/2 of the motor power, driving identical propellers at the
same point of the thrust line with ``<sense>`` +1 and −1. Each propeller has 1/2 of the
blade-element C_T(J), C_P(J) of :func:`propeller_tables` and 1/2 of the rotor inertia, so at
a common throttle each rotor turns at the single propeller's RPM with half its thrust and
power: total thrust, power, trim throttle and RPM response are unchanged, while the angular
momenta and reaction torques cancel exactly (no aileron at trim, a symmetric gust stays
symmetric). One throttle lever, ``fcs/throttle-cmd-norm`` (engine 0's command), drives every
motor's ``fcs/throttle-pos-norm[i]``; JSBSim's trim sets all commands together. Per-rotor
properties are ``propulsion/engine[i]/...``; the total thrust is their sum.

Two aircraft from the same parameters
---------------------------------------
JSBSim's trim finds the propeller RPM by explicit Euler steps of a fixed 0.5 s
(``FGPropulsion::GetSteadyState``), stable only with a rotor inertia about 8 times the physical
one (``PROPULSION.trim_rotor_inertia_kg_m2``, see its comment). The flying aircraft
``bioflex`` has the physical ``rotor_inertia_kg_m2``, so the RPM (and the thrust) follows the
airspeed within ≈ 0.3 s in time simulations; the trim companion ``bioflex_trim`` is the same
rendering with the effective inertia in its propeller file ``bioflex_trim_propeller`` and
nothing else changed. Its steady states are the flying aircraft's; :mod:`jsbsim_fdm` trims it
and sets the flying aircraft to that trim.

The committed files are this module's output; ``python -m bioflex_jsb.generators.airframe``
rewrites them (``--root DIR`` writes elsewhere) and a test checks they are up to date. Edit the
parameters, never the XML.

Aerodynamic model (coefficients of :data:`~bioflex_jsb.parameters.airframe.RIGID_AERODYNAMICS`,
reference area S = b·c̄, chord c̄, span b; moments about the CG, which is also the
aerodynamic reference point):

* lift  C_L = C_L,table(α) + C_Lδe·δe; the table is linear, C_L0 + C_Lα·α, from
  ``POST_STALL.alpha_negative_stall_rad`` (−10°) to ``alpha_stall_rad`` (11°), rounds over to
  ``cl_max`` and falls off beyond (α tables over −30°..+30°). C_Lq = C_Lα̇ = 0 (the paper's
  A_RR has Z_q = 0).
* drag  C_D = C_D0 + k·C_L² + ΔC_D,sep(α) (separated-flow drag beyond the linear range);
* side force C_Y = C_Yβ·β + C_Yδr·δr;
* rolling moment C_l = C_lβ·β + C_lp·p̂ + C_lr·r̂ + C_lδa·δa, with p̂ = p·b/(2V) (JSBSim's
  ``aero/bi2vel``), r̂ likewise;
* pitching moment C_m = C_m0 + C_mα·α + C_mq·q̂ + C_mα̇·α̇̂ + C_mδe·δe with
  q̂ = q·c̄/(2V), α̇̂ = α̇·c̄/(2V) (JSBSim's ``aero/ci2vel``);
* yawing moment C_n = C_nβ·β + C_np·p̂ + C_nr·r̂ + C_nδr·δr.

Control signs (JSBSim's): +δe trailing edge down; +δa = left aileron down (roll right); +δr
trailing edge left (nose left). Positions: ``fcs/elevator-pos-rad``,
``fcs/left-aileron-pos-rad`` (δa; the right aileron is −δa), ``fcs/rudder-pos-rad``.

External reactions: hooks for the modal wing
---------------------------------------------
Four external reactions, all zero by default, let the Python modal wing add its lift, drag and
moment increments to the rigid airframe. Each is set by writing its ``magnitude`` property
(JSBSim units) before the step in which it is to act:

================================================  ======  ===================================
property                                          unit    direction and point of action
================================================  ======  ===================================
``external_reactions/modal-lift/magnitude``       lbs     force along body −z (up, normal to
                                                          the fuselage axis), at the CG
``external_reactions/modal-drag/magnitude``       lbs     force along body −x (aft), at the CG
``external_reactions/modal-pitch/magnitude-lbsft`` lbs*ft moment about body +y (nose up)
``external_reactions/modal-roll/magnitude-lbsft``  lbs*ft moment about body +x (right wing
                                                          down)
================================================  ======  ===================================

The forces are in **body** axes: a wind-axis lift increment ΔL and drag increment ΔD at angle
of attack α are written as modal-lift = ΔL·cos α + ΔD·sin α and
modal-drag = ΔD·cos α − ΔL·sin α. Convert from SI with ``units.LBF_PER_N`` and
``units.LBF_FT_PER_N_M``. JSBSim reports their sums as ``forces/f{x,y,z}-external-lbs`` and
``moments/{l,m,n}-external-lbsft``.
"""

from __future__ import annotations

import argparse
import math
import sys
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from bioflex_jsb import units as U
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import (
    AIRFRAME_GEOMETRY,
    CONTROL_LIMITS,
    MASS_PROPERTIES,
    POST_STALL,
    PROPULSION,
    RIGID_AERODYNAMICS,
    AirframeGeometry,
    ControlLimits,
    MassProperties,
    PostStall,
    Propulsion,
    RigidAerodynamics,
)

AIRCRAFT_NAME = "bioflex"
ENGINE_FILE = "bioflex_motor"
PROPELLER_FILE = "bioflex_propeller"
# Trim companion: the same aircraft with the effective rotor inertia (module docstring).
TRIM_SUFFIX = "_trim"
TRIM_AIRCRAFT_NAME = AIRCRAFT_NAME + TRIM_SUFFIX
TRIM_PROPELLER_FILE = PROPELLER_FILE.replace("bioflex", TRIM_AIRCRAFT_NAME, 1)
SYSTEM_FILE = "bioflex_flight_controls"
INIT_FILE = "reset_cruise"

# Names of the external-reaction hooks (see the module docstring for frames and units).
EXTERNAL_FORCES = {
    # name: (body-axis unit direction, description)
    "modal-lift": ((0.0, 0.0, -1.0), "force along body -z (up) at the CG [lbs]"),
    "modal-drag": ((-1.0, 0.0, 0.0), "force along body -x (aft) at the CG [lbs]"),
}
EXTERNAL_MOMENTS = {
    "modal-pitch": ((0.0, 1.0, 0.0), "moment about body +y, nose up [lbs*ft]"),
    "modal-roll": ((1.0, 0.0, 0.0), "moment about body +x, right wing down [lbs*ft]"),
}


def external_property(name: str) -> str:
    """JSBSim property that sets the magnitude of external reaction ``name``
    (``.../magnitude`` [lbs] for forces, ``.../magnitude-lbsft`` [lbs*ft] for moments)."""
    if name in EXTERNAL_FORCES:
        return f"external_reactions/{name}/magnitude"
    if name in EXTERNAL_MOMENTS:
        return f"external_reactions/{name}/magnitude-lbsft"
    raise KeyError(f"no external reaction named {name!r}")


# Initial condition of reset_cruise.xml: Table 1 cruise speed, sea level (ISA).
INIT_SPEED_M_S = P.CRUISE_SPEED_M_S
INIT_ALTITUDE_M = 0.0  # sea level: the paper's Q uses ρ = 1.225 kg/m³ (prototype.py)
# JSBSim's WGS84 gravity at sea level is 9.780 m/s² at the equator and 9.806 m/s² at 45°
# latitude, within 0.01 % of the standard gravity the paper's model (and prototype.py) uses.
INIT_LATITUDE_RAD = math.radians(45.0)
# The ground is put this far below the aircraft so the contact points never touch it in the
# air analyses (the terrain elevation is independent of the atmosphere's sea level).
TERRAIN_CLEARANCE_M = 300.0  # ESTIMATE: > any altitude loss in the analyses' simulations

# Ground contacts (structure points): stiffness and damping for a 2.5 kg airframe.
CONTACT_SPRING_N_PER_M = 2500.0  # ESTIMATE: ≈ 1 cm static deflection under 24.5 N
CONTACT_DAMPING_N_S_PER_M = 150.0  # ESTIMATE: ≈ critical, 2·sqrt(k·m) = 158 N·s/m
CONTACT_STATIC_FRICTION = 0.8  # ESTIMATE: skid on grass
CONTACT_DYNAMIC_FRICTION = 0.5  # ESTIMATE

PROPELLER_TABLE_ROWS = 27  # J stations of the C_T, C_P tables (ΔJ = 0.05 up to J = 1.3)
PROPELLER_BLADE_STATIONS = 40  # blade-element annuli of the momentum calculation


# ======================================================================================
# Numbers: lift/drag tables and propeller tables from the parameters
# ======================================================================================


def lift_curve(
    alpha_rad: np.ndarray,
    aero: RigidAerodynamics = RIGID_AERODYNAMICS,
    stall: PostStall = POST_STALL,
) -> np.ndarray:
    """Wing-body lift coefficient C_L(α) at δe = 0 [-] (see :class:`PostStall`)."""
    a = np.asarray(alpha_rad, dtype=float)
    cla = aero.cl_alpha_per_rad
    a_pos, a_neg = aero.alpha_stall_rad, stall.alpha_negative_stall_rad
    cl_pos_edge = aero.cl0 + cla * a_pos
    cl_neg_edge = aero.cl0 + cla * a_neg
    rise = aero.cl_max - cl_pos_edge  # lift gained while rounding over [-]
    if rise <= 0.0:
        raise ValueError(
            f"cl_max = {aero.cl_max} must exceed the linear C_L at alpha_stall ({cl_pos_edge:.3f})"
        )
    width = 2.0 * rise / cla  # α from the end of the linear range to the peak [rad]
    cn90 = stall.normal_force_90deg

    def flat_plate(x: np.ndarray) -> np.ndarray:
        return cn90 * np.sin(x) * np.cos(x)

    out = aero.cl0 + cla * a
    # positive side: parabola to the peak, then exponential relaxation to the flat plate
    peak = a_pos + width
    m = (a > a_pos) & (a <= peak)
    out[m] = cl_pos_edge + cla * (a[m] - a_pos) - cla / (2.0 * width) * (a[m] - a_pos) ** 2
    m = a > peak
    out[m] = flat_plate(a[m]) + (aero.cl_max - flat_plate(peak)) * np.exp(
        -(a[m] - peak) / stall.decay_rad
    )
    # negative side: mirror image about the negative edge
    trough = a_neg - width
    cl_min = cl_neg_edge - rise
    m = (a < a_neg) & (a >= trough)
    out[m] = cl_neg_edge + cla * (a[m] - a_neg) + cla / (2.0 * width) * (a[m] - a_neg) ** 2
    m = a < trough
    out[m] = flat_plate(a[m]) + (cl_min - flat_plate(trough)) * np.exp(
        (a[m] - trough) / stall.decay_rad
    )
    return out


def alpha_peak_rad(aero: RigidAerodynamics = RIGID_AERODYNAMICS) -> float:
    """α of the lift peak C_L,max [rad] (end of the round-over parabola)."""
    cl_edge = aero.cl0 + aero.cl_alpha_per_rad * aero.alpha_stall_rad
    return aero.alpha_stall_rad + 2.0 * (aero.cl_max - cl_edge) / aero.cl_alpha_per_rad


def separated_drag(
    alpha_rad: np.ndarray,
    aero: RigidAerodynamics = RIGID_AERODYNAMICS,
    stall: PostStall = POST_STALL,
) -> np.ndarray:
    """Separated-flow drag increment ΔC_D(α) [-], zero inside the linear range."""
    a = np.asarray(alpha_rad, dtype=float)
    cn90 = stall.normal_force_90deg
    out = np.zeros_like(a)
    hi = a > aero.alpha_stall_rad
    lo = a < stall.alpha_negative_stall_rad
    out[hi] = cn90 * (np.sin(a[hi]) ** 2 - math.sin(aero.alpha_stall_rad) ** 2)
    out[lo] = cn90 * (np.sin(a[lo]) ** 2 - math.sin(stall.alpha_negative_stall_rad) ** 2)
    return out


def alpha_table_rad(
    aero: RigidAerodynamics = RIGID_AERODYNAMICS, stall: PostStall = POST_STALL
) -> np.ndarray:
    """α stations of the lift/drag tables [rad]: a uniform grid plus the break points."""
    n = round((stall.alpha_table_max_rad - stall.alpha_table_min_rad) / stall.alpha_table_step_rad)
    grid = np.linspace(stall.alpha_table_min_rad, stall.alpha_table_max_rad, n + 1)
    breaks = [aero.alpha_stall_rad, stall.alpha_negative_stall_rad, alpha_peak_rad(aero)]
    return np.unique(np.round(np.concatenate([grid, breaks]), 12))


def propeller_coefficients(
    advance_ratio: float, prop: Propulsion = PROPULSION, stations: int = PROPELLER_BLADE_STATIONS
) -> tuple[float, float]:
    """Thrust and power coefficients (C_T = T/(ρn²D⁴), C_P = P/(ρn³D⁵)) at J = V/(nD).

    Blade-element momentum theory, swirl neglected, Prandtl tip loss: on each annulus the
    axial induced velocity v makes the blade-element thrust equal the momentum thrust
    4πrρ(V+v)vF. Evaluated at n = 1 rev/s, ρ = 1 (the coefficients are scale-free).
    """
    radius = prop.prop_diameter_m / 2.0
    n_rev_s, rho = 1.0, 1.0
    speed = advance_ratio * n_rev_s * prop.prop_diameter_m
    omega = 2.0 * math.pi * n_rev_s
    blades = prop.prop_blades
    r_frac, c_frac = zip(*prop.prop_chord_stations, strict=True)
    edges = np.linspace(prop.prop_hub_radius_fraction * radius, radius, stations + 1)
    thrust = torque = 0.0
    for r0, r1 in zip(edges[:-1], edges[1:], strict=True):
        r = 0.5 * (r0 + r1)
        chord = float(np.interp(r / radius, r_frac, c_frac)) * radius
        pitch_angle = math.atan(prop.prop_pitch_m / (2.0 * math.pi * r))

        def loads(v: float, r: float = r, chord: float = chord, pa: float = pitch_angle):
            ua, ut = speed + v, omega * r
            phi = math.atan2(ua, ut)
            w2 = ua * ua + ut * ut
            cl = prop.prop_section_lift_slope_per_rad * (pa - phi - prop.prop_section_zero_lift_rad)
            cl = max(-prop.prop_section_cl_max, min(prop.prop_section_cl_max, cl))
            cd = prop.prop_section_cd0 + prop.prop_section_cd_k * cl * cl
            f_tip = blades * (radius - r) / (2.0 * r * max(math.sin(phi), 1e-9))
            tip_loss = 2.0 / math.pi * math.acos(math.exp(-f_tip))
            dq = 0.5 * rho * w2 * blades * chord
            d_thrust = dq * (cl * math.cos(phi) - cd * math.sin(phi))
            d_torque = dq * (cl * math.sin(phi) + cd * math.cos(phi)) * r
            return d_thrust - 4.0 * math.pi * r * rho * ua * v * tip_loss, d_thrust, d_torque

        v = brentq(lambda v: loads(v)[0], -0.5 * speed * (1.0 - 1e-9), omega * radius, xtol=1e-12)
        _, d_thrust, d_torque = loads(v)
        thrust += d_thrust * (r1 - r0)
        torque += d_torque * (r1 - r0)
    d = prop.prop_diameter_m
    return thrust / (rho * n_rev_s**2 * d**4), omega * torque / (rho * n_rev_s**3 * d**5)


def propeller_tables(prop: Propulsion = PROPULSION) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(J, C_T, C_P) on ``PROPELLER_TABLE_ROWS`` stations from 0 to ``advance_ratio_max``."""
    j = np.linspace(0.0, prop.advance_ratio_max, PROPELLER_TABLE_ROWS)
    ct, cp = zip(*(propeller_coefficients(float(x), prop) for x in j), strict=True)
    return j, np.array(ct), np.array(cp)


# ======================================================================================
# XML helpers
# ======================================================================================


def _num(x: float) -> str:
    """Deterministic text for a number (9 significant digits)."""
    s = f"{float(x):.9g}"
    return "0" if s == "-0" else s


def _el(parent: ET.Element, tag: str, text: str | float | None = None, **attrib: str):
    e = ET.SubElement(parent, tag, attrib)
    if text is not None:
        e.text = text if isinstance(text, str) else _num(text)
    return e


def _comment(parent: ET.Element, text: str) -> None:
    parent.append(ET.Comment(f" {text} "))


def _xyz(parent: ET.Element, tag: str, xyz_m: Iterable[float], **attrib: str) -> ET.Element:
    """A <tag unit="FT"><x/><y/><z/></tag> triplet from SI metres."""
    e = _el(parent, tag, unit="FT", **attrib)
    for axis, value in zip("xyz", xyz_m, strict=True):
        _el(e, axis, value * U.FT_PER_M)
    return e


def _table(parent: ET.Element, rows: Iterable[tuple[float, float]], variable: str) -> ET.Element:
    t = _el(parent, "table")
    _el(t, "independentVar", variable, lookup="row")
    lines = "".join(f"\n          {_num(x):>14} {_num(y):>14}" for x, y in rows)
    _el(t, "tableData", lines + "\n        ")
    return t


def _product(parent: ET.Element, name: str, description: str, factors: list) -> ET.Element:
    """<function name=..><description/><product>factors</product></function>.

    ``factors`` are property names (str) or numbers (float)."""
    f = _el(parent, "function", name=name)
    _el(f, "description", description)
    prod = _el(f, "product")
    for x in factors:
        if isinstance(x, str):
            _el(prod, "property", x)
        else:
            _el(prod, "value", float(x))
    return f


def _serialise(root: ET.Element) -> str:
    ET.indent(root, space="  ")
    body = ET.tostring(root, encoding="unicode", short_empty_elements=True)
    header = (
        '<?xml version="1.0" encoding="utf-8"?>\n'
        "<!-- GENERATED by bioflex_jsb.generators.airframe from bioflex_jsb/parameters:\n"
        "     do not edit; run `python -m bioflex_jsb.generators.airframe` to regenerate. -->\n"
    )
    return header + body + "\n"


# ======================================================================================
# The files
# ======================================================================================


def render_aircraft(
    aero: RigidAerodynamics = RIGID_AERODYNAMICS,
    mass: MassProperties = MASS_PROPERTIES,
    geom: AirframeGeometry = AIRFRAME_GEOMETRY,
    stall: PostStall = POST_STALL,
    prop: Propulsion = PROPULSION,
    trim_companion: bool = False,
) -> str:
    """Text of ``aircraft/bioflex/bioflex.xml`` (``trim_companion``: of
    ``aircraft/bioflex_trim/bioflex_trim.xml``, the same with the effective-inertia propeller)."""
    name = TRIM_AIRCRAFT_NAME if trim_companion else AIRCRAFT_NAME
    propeller_file = TRIM_PROPELLER_FILE if trim_companion else PROPELLER_FILE
    root = ET.Element(
        "fdm_config",
        {"name": name, "version": "2.0", "release": "PRODUCTION"},
    )
    root.set("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance")
    root.set("xsi:noNamespaceSchemaLocation", "http://jsbsim.sourceforge.net/JSBSim.xsd")

    hdr = _el(root, "fileheader")
    _el(hdr, "author", "bioflex-jsb (generated)")
    _el(hdr, "filecreationdate", "2026-11-23")
    _el(hdr, "version", "1")
    _el(
        hdr,
        "description",
        "Rigid airframe of the 2.5 kg bio-inspired elastic-wing UAV (paper Table 1) with "
        "estimated aerodynamics calibrated to the rigid short period of Table 3."
        + (
            " Trim companion: effective rotor inertia for JSBSim's trim RPM iteration."
            if trim_companion
            else ""
        ),
    )
    _el(
        hdr,
        "reference",
        refID="paper",
        author="see shared/reference/paper.md",
        title="Flight dynamic coupling analysis of a bio-inspired elastic-wing aircraft",
        date="",
    )

    cg = (geom.cg_x_m, 0.0, geom.cg_z_m)

    # ---- metrics ----
    met = _el(root, "metrics")
    _comment(met, "S = b*cbar (prototype.REFERENCE_AREA_M2, DECISION), b and cbar: Table 1")
    _el(met, "wingarea", P.REFERENCE_AREA_M2 * U.FT2_PER_M2, unit="FT2")
    _el(met, "wingspan", P.SPAN_M * U.FT_PER_M, unit="FT")
    _el(met, "chord", P.MEAN_AERODYNAMIC_CHORD_M * U.FT_PER_M, unit="FT")
    _comment(met, "aerodynamic reference point at the CG: moment coefficients are about the CG")
    _xyz(met, "location", cg, name="AERORP")
    _xyz(met, "location", cg, name="EYEPOINT")
    _xyz(met, "location", cg, name="VRP")

    # ---- mass ----
    mb = _el(root, "mass_balance")
    _comment(mb, "parameters.airframe.MASS_PROPERTIES (I_y: Table 1; I_x, I_z: ESTIMATE)")
    _el(mb, "ixx", mass.ixx_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    _el(mb, "iyy", mass.iyy_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    _el(mb, "izz", mass.izz_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    _el(mb, "ixz", mass.ixz_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    _comment(mb, "emptywt is the weight at standard gravity: m*g0 [N] in lbs; m = 2.5 kg Table 1")
    _el(mb, "emptywt", mass.mass_kg * P.STANDARD_GRAVITY_M_S2 * U.LBF_PER_N, unit="LBS")
    _xyz(mb, "location", cg, name="CG")

    # ---- ground reactions ----
    gr = _el(root, "ground_reactions")
    _comment(gr, "structure contact points (AIRFRAME_GEOMETRY); the analyses fly in the air")
    k_lbs_ft = CONTACT_SPRING_N_PER_M * U.LBF_PER_N / U.FT_PER_M
    c_lbs_ft_s = CONTACT_DAMPING_N_S_PER_M * U.LBF_PER_N / U.FT_PER_M
    for name, x, y, z in geom.contact_points_m:
        c = _el(gr, "contact", type="STRUCTURE", name=name)
        _xyz(c, "location", (x, y, z))
        _el(c, "static_friction", CONTACT_STATIC_FRICTION)
        _el(c, "dynamic_friction", CONTACT_DYNAMIC_FRICTION)
        _el(c, "spring_coeff", k_lbs_ft, unit="LBS/FT")
        _el(c, "damping_coeff", c_lbs_ft_s, unit="LBS/FT/SEC")

    # ---- propulsion ----
    prop_el = _el(root, "propulsion")
    _comment(
        prop_el,
        "contra-rotating pair (parameters.airframe.PROPULSION): identical electric motors and "
        "fixed-pitch propellers at the same point, opposite senses, so that gyroscopic moments "
        "and reaction torques cancel and the longitudinal model stays symmetric",
    )
    prop_xyz = (geom.propeller_x_m, 0.0, geom.propeller_z_m)
    for i in range(prop.rotor_count):
        sense = 1.0 if i % 2 == 0 else -1.0
        eng = _el(prop_el, "engine", file=ENGINE_FILE)
        thr = _el(eng, "thruster", file=propeller_file)
        _xyz(thr, "location", prop_xyz)
        orient = _el(thr, "orient", unit="RAD")
        for axis in ("roll", "pitch", "yaw"):
            _el(orient, axis, 0.0)
        turn = "clockwise" if sense > 0 else "counter-clockwise"
        _comment(thr, f"sense {sense:+.0f}: {turn} seen from behind; no p-factor model")
        _el(thr, "sense", sense)
        _el(thr, "p_factor", 0.0)

    # ---- systems ----
    _el(root, "system", file=SYSTEM_FILE)

    # ---- aerodynamics ----
    _render_aerodynamics(root, aero, stall)

    # ---- external reactions ----
    ext = _el(root, "external_reactions")
    _comment(
        ext,
        "hooks for the modal wing, zero by default; set external_reactions/<name>/magnitude "
        "(forces, lbs) or .../magnitude-lbsft (moments); see airframe_xml.py docstring",
    )
    for name, (direction, text) in EXTERNAL_FORCES.items():
        _comment(ext, text)
        f = _el(ext, "force", name=name, frame="BODY", unit="LBS")
        _xyz(f, "location", cg)
        d = _el(f, "direction")
        for axis, value in zip("xyz", direction, strict=True):
            _el(d, axis, value)
    for name, (direction, text) in EXTERNAL_MOMENTS.items():
        _comment(ext, text)
        m = _el(ext, "moment", name=name, frame="BODY", unit="LBSFT")
        d = _el(m, "direction")
        for axis, value in zip("xyz", direction, strict=True):
            _el(d, axis, value)

    return _serialise(root)


def _render_aerodynamics(root: ET.Element, aero: RigidAerodynamics, stall: PostStall) -> None:
    ae = _el(root, "aerodynamics")
    lim = _el(ae, "alphalimits", unit="DEG")
    _comment(lim, "trim search range: negative stall .. lift peak (C_L,max)")
    _el(lim, "min", math.degrees(stall.alpha_negative_stall_rad))
    _el(lim, "max", math.degrees(alpha_peak_rad(aero)))

    qs = ["aero/qbar-psf", "metrics/Sw-sqft"]
    qsc = qs + ["metrics/cbarw-ft"]
    qsb = qs + ["metrics/bw-ft"]
    alpha, beta = "aero/alpha-rad", "aero/beta-rad"
    de = "fcs/elevator-pos-rad"
    da = "fcs/left-aileron-pos-rad"
    dr = "fcs/rudder-pos-rad"
    p_hat = ["aero/bi2vel", "velocities/p-aero-rad_sec"]
    r_hat = ["aero/bi2vel", "velocities/r-aero-rad_sec"]
    q_hat = ["aero/ci2vel", "velocities/q-aero-rad_sec"]
    ad_hat = ["aero/ci2vel", "aero/alphadot-rad_sec"]

    # lift coefficient, evaluated before the axes (pre-functions)
    a_tab = alpha_table_rad(aero, stall)
    f = _el(ae, "function", name="aero/bioflex/cl-alpha")
    _el(
        f,
        "description",
        "C_L(alpha) at de = 0: C_L0 + C_La*alpha from -10 to 11 deg (RIGID_AERODYNAMICS), "
        "round-over to cl_max and post-stall decay (POST_STALL)",
    )
    _table(f, zip(a_tab, lift_curve(a_tab, aero, stall), strict=True), alpha)
    _product(
        ae,
        "aero/bioflex/cl-elevator",
        "C_L due to elevator: C_Lde*de",
        [de, aero.cl_delta_e_per_rad],
    )
    f = _el(ae, "function", name="aero/bioflex/cl-total")
    _el(f, "description", "total lift coefficient C_L")
    s = _el(f, "sum")
    _el(s, "property", "aero/bioflex/cl-alpha")
    _el(s, "property", "aero/bioflex/cl-elevator")

    ax = _el(ae, "axis", name="LIFT")
    _comment(ax, "C_Lq = C_Ladot = 0: the paper's A_RR has Z_q = 0")
    _product(ax, "aero/force/lift", "lift: qbar*S*C_L", qs + ["aero/bioflex/cl-total"])

    ax = _el(ae, "axis", name="DRAG")
    _product(ax, "aero/force/drag-cd0", "zero-lift drag: qbar*S*C_D0", qs + [aero.cd0])
    _product(
        ax,
        "aero/force/drag-induced",
        "induced drag: qbar*S*k*C_L^2 (k = 1/(pi*AR*0.85))",
        qs + ["aero/bioflex/cl-total", "aero/bioflex/cl-total", aero.k_induced],
    )
    f = _el(ax, "function", name="aero/force/drag-separated")
    _el(f, "description", "separated-flow drag beyond the linear range (POST_STALL)")
    prod = _el(f, "product")
    for x in qs:
        _el(prod, "property", x)
    _table(prod, zip(a_tab, separated_drag(a_tab, aero, stall), strict=True), alpha)

    ax = _el(ae, "axis", name="SIDE")
    _product(
        ax,
        "aero/force/side-beta",
        "side force: qbar*S*C_Yb*beta",
        qs + [beta, aero.cy_beta_per_rad],
    )
    _product(
        ax,
        "aero/force/side-rudder",
        "side force: qbar*S*C_Ydr*dr",
        qs + [dr, aero.cy_delta_r_per_rad],
    )

    ax = _el(ae, "axis", name="ROLL")
    _product(ax, "aero/moment/roll-beta", "qbar*S*b*C_lb*beta", qsb + [beta, aero.cl_beta_per_rad])
    _product(ax, "aero/moment/roll-p", "qbar*S*b*C_lp*p*b/2V", qsb + p_hat + [aero.cl_p_per_rad])
    _product(ax, "aero/moment/roll-r", "qbar*S*b*C_lr*r*b/2V", qsb + r_hat + [aero.cl_r_per_rad])
    _product(
        ax, "aero/moment/roll-aileron", "qbar*S*b*C_lda*da", qsb + [da, aero.cl_delta_a_per_rad]
    )

    ax = _el(ae, "axis", name="PITCH")
    _comment(ax, "about the CG; C_malpha, C_mq, C_madot CALIBRATED to Table 3 (airframe.py)")
    _product(ax, "aero/moment/pitch-zero", "qbar*S*cbar*C_m0", qsc + [aero.cm0])
    _product(
        ax,
        "aero/moment/pitch-alpha",
        "qbar*S*cbar*C_ma*alpha",
        qsc + [alpha, aero.cm_alpha_per_rad],
    )
    _product(
        ax, "aero/moment/pitch-q", "qbar*S*cbar*C_mq*q*cbar/2V", qsc + q_hat + [aero.cm_q_per_rad]
    )
    _product(
        ax,
        "aero/moment/pitch-alphadot",
        "qbar*S*cbar*C_madot*alphadot*cbar/2V",
        qsc + ad_hat + [aero.cm_alphadot_per_rad],
    )
    _product(
        ax,
        "aero/moment/pitch-elevator",
        "qbar*S*cbar*C_mde*de",
        qsc + [de, aero.cm_delta_e_per_rad],
    )

    ax = _el(ae, "axis", name="YAW")
    _product(ax, "aero/moment/yaw-beta", "qbar*S*b*C_nb*beta", qsb + [beta, aero.cn_beta_per_rad])
    _product(ax, "aero/moment/yaw-p", "qbar*S*b*C_np*p*b/2V", qsb + p_hat + [aero.cn_p_per_rad])
    _product(ax, "aero/moment/yaw-r", "qbar*S*b*C_nr*r*b/2V", qsb + r_hat + [aero.cn_r_per_rad])
    _product(ax, "aero/moment/yaw-rudder", "qbar*S*b*C_ndr*dr", qsb + [dr, aero.cn_delta_r_per_rad])


def render_engine(prop: Propulsion = PROPULSION) -> str:
    """Text of ``aircraft/bioflex/Engines/bioflex_motor.xml``."""
    root = ET.Element("electric_engine", name=ENGINE_FILE)
    _comment(
        root,
        "one motor of the contra-rotating pair: "
        "PROPULSION.motor_max_shaft_power_w / rotor_count (ESTIMATE, airframe.py)",
    )
    _el(root, "power", prop.motor_max_shaft_power_w / prop.rotor_count, unit="WATTS")
    return _serialise(root)


def render_propeller(prop: Propulsion = PROPULSION, trim_companion: bool = False) -> str:
    """Text of ``aircraft/bioflex/Engines/bioflex_propeller.xml`` (physical rotor inertia) or,
    with ``trim_companion``, of ``aircraft/bioflex_trim/Engines/bioflex_trim_propeller.xml``
    (effective inertia for JSBSim's trim; everything else identical)."""
    root = ET.Element("propeller", name=TRIM_PROPELLER_FILE if trim_companion else PROPELLER_FILE)
    inertia = (
        "trim_rotor_inertia_kg_m2 / rotor_count (effective value, 8x physical: JSBSim's trim "
        "RPM iteration)"
        if trim_companion
        else "rotor_inertia_kg_m2 / rotor_count (physical)"
    )
    _comment(
        root,
        f"one rotor of the contra-rotating pair, PROPULSION (ESTIMATE, airframe.py): {inertia}, "
        "diameter, blades",
    )
    total = prop.trim_rotor_inertia_kg_m2 if trim_companion else prop.rotor_inertia_kg_m2
    ixx = total / prop.rotor_count
    _el(root, "ixx", ixx * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    _el(root, "diameter", prop.prop_diameter_m * U.FT_PER_M, unit="FT")
    _el(root, "numblades", str(prop.prop_blades))
    _el(root, "constspeed", "0")
    j, ct, cp = propeller_tables(prop)
    _comment(
        root,
        "C_T(J), C_P(J): blade-element momentum theory on the PROPULSION blade, divided by "
        "rotor_count (each rotor gives its share of the thrust and absorbs its share of the power)",
    )
    for name, values in (("C_THRUST", ct / prop.rotor_count), ("C_POWER", cp / prop.rotor_count)):
        t = _el(root, "table", name=name, type="internal")
        lines = "".join(
            f"\n      {_num(x):>14} {_num(y):>14}" for x, y in zip(j, values, strict=True)
        )
        _el(t, "tableData", lines + "\n    ")
    return _serialise(root)


def render_flight_controls(
    limits: ControlLimits = CONTROL_LIMITS, prop: Propulsion = PROPULSION
) -> str:
    """Text of ``systems/bioflex_flight_controls.xml``.

    Each surface: command + trim (JSBSim's trim drives the *-trim-cmd-norm properties),
    clipped to −1..1 → ``fcs/<surface>-pos-norm``, times the maximum deflection →
    ``fcs/<surface>-pos-rad``. No actuator lag (the rigid analyses use surface positions).
    One throttle lever: ``fcs/throttle-cmd-norm`` drives every motor of the contra-rotating
    pair (``fcs/throttle-pos-norm[i]``).
    """
    root = ET.Element("system", name="bioflex-flight-controls")
    _comment(root, "deflection limits: parameters.airframe.CONTROL_LIMITS (ESTIMATE)")
    surfaces = (
        ("Pitch", "elevator", "pitch", limits.elevator_max_rad, ("fcs/elevator-pos",)),
        ("Roll", "aileron", "roll", limits.aileron_max_rad, ("fcs/left-aileron-pos",)),
        ("Yaw", "rudder", "yaw", limits.rudder_max_rad, ("fcs/rudder-pos",)),
    )
    for channel, surface, axis, max_rad, outputs in surfaces:
        ch = _el(root, "channel", name=channel)
        sm = _el(ch, "summer", name=f"fcs/{surface}-sum-norm")
        _el(sm, "input", f"fcs/{surface}-cmd-norm")
        _el(sm, "input", f"fcs/{axis}-trim-cmd-norm")
        clip = _el(sm, "clipto")
        _el(clip, "min", -1.0)  # normalised travel
        _el(clip, "max", 1.0)
        for out in outputs:
            _el(sm, "output", f"{out}-norm")
        gain = _el(ch, "pure_gain", name=f"fcs/{surface}-scale-rad")
        _el(gain, "input", f"fcs/{surface}-sum-norm")
        _el(gain, "gain", max_rad)
        for out in outputs:
            _el(gain, "output", f"{out}-rad")
        if surface == "aileron":
            _comment(ch, "right aileron deflects opposite to the left one")
            inv = _el(ch, "pure_gain", name="fcs/right-aileron-inverter")
            _el(inv, "input", "fcs/aileron-sum-norm")
            _el(inv, "gain", -1.0)
            _el(inv, "output", "fcs/right-aileron-pos-norm")
            inv = _el(ch, "pure_gain", name="fcs/right-aileron-scale-rad")
            _el(inv, "input", "fcs/right-aileron-pos-norm")
            _el(inv, "gain", max_rad)
            _el(inv, "output", "fcs/right-aileron-pos-rad")
    ch = _el(root, "channel", name="Throttle")
    _comment(ch, "one lever for the contra-rotating pair: every motor gets the same throttle")
    g = _el(ch, "pure_gain", name="fcs/throttle-pos-gain")
    _el(g, "input", "fcs/throttle-cmd-norm")
    _el(g, "gain", 1.0)  # direct: no throttle lag in the rigid analyses
    clip = _el(g, "clipto")
    _el(clip, "min", 0.0)  # throttle range 0..1
    _el(clip, "max", 1.0)
    for i in range(prop.rotor_count):
        _el(g, "output", f"fcs/throttle-pos-norm[{i}]")
    return _serialise(root)


def render_initial_condition() -> str:
    """Text of ``aircraft/bioflex/reset_cruise.xml`` (level, wings level, Table 1 cruise)."""
    root = ET.Element("initialize", name=INIT_FILE)
    _comment(root, "Table 1 cruise speed at ISA sea level; ground TERRAIN_CLEARANCE_M below")
    _el(root, "vt", INIT_SPEED_M_S * U.FT_PER_M, unit="FT/SEC")
    _comment(root, "JSBSim reads <elevation> (terrain) before <altitudeMSL> (above sea level)")
    _el(root, "elevation", (INIT_ALTITUDE_M - TERRAIN_CLEARANCE_M) * U.FT_PER_M, unit="FT")
    _el(root, "altitudeMSL", INIT_ALTITUDE_M * U.FT_PER_M, unit="FT")
    for tag in ("phi", "theta", "psi"):
        _el(root, tag, 0.0, unit="RAD")  # level attitude, wings level, heading north
    _el(root, "latitude", INIT_LATITUDE_RAD, unit="RAD")
    _el(root, "longitude", 0.0, unit="RAD")  # arbitrary meridian
    _el(root, "running", "-1")  # all engines running (electric motors: no start sequence)
    return _serialise(root)


def render_all() -> dict[str, str]:
    """All generated files: path relative to the JSBSim root → text."""
    craft = f"aircraft/{AIRCRAFT_NAME}"
    companion = f"aircraft/{TRIM_AIRCRAFT_NAME}"
    return {
        f"{craft}/{AIRCRAFT_NAME}.xml": render_aircraft(),
        f"{craft}/Engines/{ENGINE_FILE}.xml": render_engine(),
        f"{craft}/Engines/{PROPELLER_FILE}.xml": render_propeller(),
        f"{craft}/{INIT_FILE}.xml": render_initial_condition(),
        f"{companion}/{TRIM_AIRCRAFT_NAME}.xml": render_aircraft(trim_companion=True),
        f"{companion}/Engines/{ENGINE_FILE}.xml": render_engine(),
        f"{companion}/Engines/{TRIM_PROPELLER_FILE}.xml": render_propeller(trim_companion=True),
        f"systems/{SYSTEM_FILE}.xml": render_flight_controls(),
    }


def write_files(files: dict[str, str], root_dir: Path) -> list[Path]:
    """Write generated ``files`` (path relative to the JSBSim root → text) under
    ``root_dir``; return the paths. Raises OSError when the directory cannot be written."""
    written = []
    for rel, text in files.items():
        path = Path(root_dir) / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
        written.append(path)
    return written


def write_all(root_dir: Path) -> list[Path]:
    """Write every generated file under ``root_dir`` (a JSBSim root); return the paths."""
    return write_files(render_all(), root_dir)


def default_output_root() -> Path:
    """The repository checkout that holds ``aircraft/`` and ``systems/`` beside the package."""
    return Path(__file__).resolve().parents[2]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bioflex_jsb.generators.airframe",
        description="Regenerate the JSBSim files of the bioflex airframe from the parameters.",
    )
    parser.add_argument(
        "--root",
        type=Path,
        default=default_output_root(),
        help="JSBSim root to write aircraft/ and systems/ into (default: the repository)",
    )
    args = parser.parse_args(argv)
    for path in write_all(args.root):
        print(path)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
