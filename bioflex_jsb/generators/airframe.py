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
blade-element C_T(J), C_P(J) of
:func:`~bioflex_jsb.aerodynamics.propeller.propeller_tables` and 1/2 of the rotor inertia, so at
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
aerodynamic reference point; the polars C_L(α), ΔC_D,sep(α) are
:mod:`bioflex_jsb.aerodynamics.airframe_polars`, tabulated here):

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
External reactions, all zero by default, let the Python modal wing add its lift, drag and
moment increments to the rigid airframe (and a spanwise gust its own loads). Each is set by
writing its ``magnitude`` property (JSBSim units) before the step in which it is to act:

================================================  ======  ===================================
property                                          unit    direction and point of action
================================================  ======  ===================================
``external_reactions/modal-lift/magnitude``       lbs     force along body −z (up, normal to
                                                          the fuselage axis), at the CG
``external_reactions/modal-drag/magnitude``       lbs     force along body −x (aft), at the CG
``external_reactions/modal-pitch/magnitude-lbsft`` lbs*ft moment about body +y (nose up)
``external_reactions/modal-roll/magnitude-lbsft``  lbs*ft moment about body +x (right wing
                                                          down)
``external_reactions/modal-side/magnitude``       lbs     force along body +y (to starboard),
                                                          at the CG
``external_reactions/modal-yaw/magnitude-lbsft``  lbs*ft moment about body +z (nose right)
``external_reactions/gust-lift/magnitude``        lbs     force along body −z (up), at the CG
``external_reactions/gust-pitch/magnitude-lbsft`` lbs*ft moment about body +y (nose up)
``external_reactions/gust-roll/magnitude-lbsft``  lbs*ft moment about body +x (right wing
                                                          down)
``external_reactions/gust-yaw/magnitude-lbsft``   lbs*ft moment about body +z (nose right)
================================================  ======  ===================================

The four ``gust-*`` hooks carry the loads of a gust that varies over the aircraft which
JSBSim's uniform wind does not give: the rolling gust's moments and the tail's lift of its
penetration delay (:mod:`bioflex_jsb.runtime.gust_loads`); the ``modal-*`` hooks stay the
elastic wing's.

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

from bioflex_jsb import units as U
from bioflex_jsb.aerodynamics.airframe_polars import alpha_peak_rad, lift_curve, separated_drag
from bioflex_jsb.aerodynamics.propeller import propeller_tables
from bioflex_jsb.generators.xml_writer import XmlWriter, num_9g, serialise
from bioflex_jsb.parameters.airframe import (
    AIRFRAME_GEOMETRY,
    CONTROL_LIMITS,
    CRUISE_SPEED_M_S,
    MASS_PROPERTIES,
    POST_STALL,
    PROPULSION,
    REFERENCE_GEOMETRY,
    RIGID_AERODYNAMICS,
    AirframeGeometry,
    ControlLimits,
    MassProperties,
    PostStall,
    Propulsion,
    RigidAerodynamics,
)
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2

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
    # the antisymmetric modes' side force (simulation/full_span.py)
    "modal-side": ((0.0, 1.0, 0.0), "force along body +y (to starboard) at the CG [lbs]"),
    # the gust's loads that JSBSim's uniform wind does not give (runtime/gust_loads.py)
    "gust-lift": ((0.0, 0.0, -1.0), "gust: tail lift of its delay, body -z (up) at the CG [lbs]"),
}
EXTERNAL_MOMENTS = {
    "modal-pitch": ((0.0, 1.0, 0.0), "moment about body +y, nose up [lbs*ft]"),
    "modal-roll": ((1.0, 0.0, 0.0), "moment about body +x, right wing down [lbs*ft]"),
    "modal-yaw": ((0.0, 0.0, 1.0), "moment about body +z, nose right [lbs*ft]"),
    "gust-pitch": ((0.0, 1.0, 0.0), "gust: tail delay's moment about body +y, nose up [lbs*ft]"),
    "gust-roll": ((1.0, 0.0, 0.0), "gust: rolling gust's moment about body +x [lbs*ft]"),
    "gust-yaw": ((0.0, 0.0, 1.0), "gust: rolling gust's moment about body +z, nose right "
                 "[lbs*ft]"),
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
INIT_SPEED_M_S = CRUISE_SPEED_M_S
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


# ======================================================================================
# Table stations and XML helpers
# ======================================================================================


def alpha_table_rad(
    aero: RigidAerodynamics = RIGID_AERODYNAMICS, stall: PostStall = POST_STALL
) -> np.ndarray:
    """α stations of the lift/drag tables [rad]: a uniform grid plus the break points."""
    n = round((stall.alpha_table_max_rad - stall.alpha_table_min_rad) / stall.alpha_table_step_rad)
    grid = np.linspace(stall.alpha_table_min_rad, stall.alpha_table_max_rad, n + 1)
    breaks = [aero.alpha_stall_rad, stall.alpha_negative_stall_rad, alpha_peak_rad(aero)]
    return np.unique(np.round(np.concatenate([grid, breaks]), 12))


# The α range of the generated airframe's aerodynamic tables [rad] (its first and last
# stations, alpha_table_rad): a run of it stops when α leaves it (simulation/limits.py).
ALPHA_TABLE_RANGE_RAD = (POST_STALL.alpha_table_min_rad, POST_STALL.alpha_table_max_rad)



W = XmlWriter(num_9g)
el, comment, num = W.el, W.comment, W.number

# Header of the airframe's files (after the XML declaration).
HEADER = (
    "<!-- GENERATED by bioflex_jsb.generators.airframe from bioflex_jsb/parameters:\n"
    "     do not edit; run `python -m bioflex_jsb.generators.airframe` to regenerate. -->\n"
)


def _xyz(parent: ET.Element, tag: str, xyz_m: Iterable[float], **attrib: str) -> ET.Element:
    """A <tag unit="FT"><x/><y/><z/></tag> triplet from SI metres."""
    e = el(parent, tag, unit="FT", **attrib)
    for axis, value in zip("xyz", xyz_m, strict=True):
        el(e, axis, value * U.FT_PER_M)
    return e


def _product(parent: ET.Element, name: str, description: str, factors: list):
    """<function name=..><description/><product>factors</product></function>.

    ``factors`` are property names (str) or numbers (float)."""
    f = el(parent, "function", name=name)
    el(f, "description", description)
    W.product(f, *factors)
    return f



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
    return serialise(airframe_tree(aero, mass, geom, stall, prop, trim_companion), HEADER)


def airframe_tree(
    aero: RigidAerodynamics = RIGID_AERODYNAMICS,
    mass: MassProperties = MASS_PROPERTIES,
    geom: AirframeGeometry = AIRFRAME_GEOMETRY,
    stall: PostStall = POST_STALL,
    prop: Propulsion = PROPULSION,
    trim_companion: bool = False,
) -> ET.Element:
    """The aircraft of :func:`render_aircraft` as a tree (``<fdm_config>``, not yet indented),
    for the generators of aircraft derived from it (SITL, native modal wing) to modify and
    serialise with :func:`~bioflex_jsb.generators.xml_writer.serialise`. A new tree at every
    call. Children of the root, in order: fileheader, metrics, mass_balance,
    ground_reactions, propulsion, ``<system file="bioflex_flight_controls">``, aerodynamics
    (alphalimits, functions, axes LIFT, DRAG, SIDE, ROLL, PITCH, YAW), external_reactions."""
    name = TRIM_AIRCRAFT_NAME if trim_companion else AIRCRAFT_NAME
    propeller_file = TRIM_PROPELLER_FILE if trim_companion else PROPELLER_FILE
    root = ET.Element(
        "fdm_config",
        {"name": name, "version": "2.0", "release": "PRODUCTION"},
    )
    root.set("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance")
    root.set("xsi:noNamespaceSchemaLocation", "http://jsbsim.sourceforge.net/JSBSim.xsd")

    hdr = el(root, "fileheader")
    el(hdr, "author", "bioflex-jsb (generated)")
    el(hdr, "filecreationdate", "2026-11-23")
    el(hdr, "version", "1")
    el(
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
    el(
        hdr,
        "reference",
        refID="paper",
        author="see shared/reference/paper.md",
        title="Flight dynamic coupling analysis of a bio-inspired elastic-wing aircraft",
        date="",
    )

    cg = (geom.cg_x_m, 0.0, geom.cg_z_m)

    # ---- metrics ----
    met = el(root, "metrics")
    comment(met, "S = b*cbar (prototype.REFERENCE_AREA_M2, DECISION), b and cbar: Table 1")
    el(met, "wingarea", REFERENCE_GEOMETRY.area_m2 * U.FT2_PER_M2, unit="FT2")
    el(met, "wingspan", REFERENCE_GEOMETRY.span_m * U.FT_PER_M, unit="FT")
    el(met, "chord", REFERENCE_GEOMETRY.mean_chord_m * U.FT_PER_M, unit="FT")
    comment(met, "aerodynamic reference point at the CG: moment coefficients are about the CG")
    _xyz(met, "location", cg, name="AERORP")
    _xyz(met, "location", cg, name="EYEPOINT")
    _xyz(met, "location", cg, name="VRP")

    # ---- mass ----
    mb = el(root, "mass_balance")
    comment(mb, "parameters.airframe.MASS_PROPERTIES (I_y: Table 1; I_x, I_z: ESTIMATE)")
    el(mb, "ixx", mass.ixx_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    el(mb, "iyy", mass.iyy_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    el(mb, "izz", mass.izz_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    el(mb, "ixz", mass.ixz_kg_m2 * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    comment(mb, "emptywt is the weight at standard gravity: m*g0 [N] in lbs; m = 2.5 kg Table 1")
    el(mb, "emptywt", mass.mass_kg * STANDARD_GRAVITY_M_S2 * U.LBF_PER_N, unit="LBS")
    _xyz(mb, "location", cg, name="CG")

    # ---- ground reactions ----
    gr = el(root, "ground_reactions")
    comment(gr, "structure contact points (AIRFRAME_GEOMETRY); the analyses fly in the air")
    k_lbs_ft = CONTACT_SPRING_N_PER_M * U.LBF_PER_N / U.FT_PER_M
    c_lbs_ft_s = CONTACT_DAMPING_N_S_PER_M * U.LBF_PER_N / U.FT_PER_M
    for name, x, y, z in geom.contact_points_m:
        c = el(gr, "contact", type="STRUCTURE", name=name)
        _xyz(c, "location", (x, y, z))
        el(c, "static_friction", CONTACT_STATIC_FRICTION)
        el(c, "dynamic_friction", CONTACT_DYNAMIC_FRICTION)
        el(c, "spring_coeff", k_lbs_ft, unit="LBS/FT")
        el(c, "damping_coeff", c_lbs_ft_s, unit="LBS/FT/SEC")

    # ---- propulsion ----
    prop_el = el(root, "propulsion")
    comment(
        prop_el,
        "contra-rotating pair (parameters.airframe.PROPULSION): identical electric motors and "
        "fixed-pitch propellers at the same point, opposite senses, so that gyroscopic moments "
        "and reaction torques cancel and the longitudinal model stays symmetric",
    )
    prop_xyz = (geom.propeller_x_m, 0.0, geom.propeller_z_m)
    for i in range(prop.rotor_count):
        sense = 1.0 if i % 2 == 0 else -1.0
        eng = el(prop_el, "engine", file=ENGINE_FILE)
        thr = el(eng, "thruster", file=propeller_file)
        _xyz(thr, "location", prop_xyz)
        orient = el(thr, "orient", unit="RAD")
        for axis in ("roll", "pitch", "yaw"):
            el(orient, axis, 0.0)
        turn = "clockwise" if sense > 0 else "counter-clockwise"
        comment(thr, f"sense {sense:+.0f}: {turn} seen from behind; no p-factor model")
        el(thr, "sense", sense)
        el(thr, "p_factor", 0.0)

    # ---- systems ----
    el(root, "system", file=SYSTEM_FILE)

    # ---- aerodynamics ----
    _render_aerodynamics(root, aero, stall)

    # ---- external reactions ----
    ext = el(root, "external_reactions")
    comment(
        ext,
        "hooks for the modal wing, zero by default; set external_reactions/<name>/magnitude "
        "(forces, lbs) or .../magnitude-lbsft (moments); see airframe_xml.py docstring",
    )
    for name, (direction, text) in EXTERNAL_FORCES.items():
        comment(ext, text)
        f = el(ext, "force", name=name, frame="BODY", unit="LBS")
        _xyz(f, "location", cg)
        d = el(f, "direction")
        for axis, value in zip("xyz", direction, strict=True):
            el(d, axis, value)
    for name, (direction, text) in EXTERNAL_MOMENTS.items():
        comment(ext, text)
        m = el(ext, "moment", name=name, frame="BODY", unit="LBSFT")
        d = el(m, "direction")
        for axis, value in zip("xyz", direction, strict=True):
            el(d, axis, value)

    return root


def flight_controls_include(root: ET.Element) -> ET.Element:
    """The ``<system file="bioflex_flight_controls">`` child of an :func:`airframe_tree`
    (where derived aircraft include their own systems). Raises ValueError when there is not
    exactly one."""
    found = [e for e in root.findall("system") if e.get("file") == SYSTEM_FILE]
    if len(found) != 1:
        raise ValueError(f"the airframe tree has {len(found)} <system file={SYSTEM_FILE!r}>")
    return found[0]


def _render_aerodynamics(root: ET.Element, aero: RigidAerodynamics, stall: PostStall) -> None:
    ae = el(root, "aerodynamics")
    lim = el(ae, "alphalimits", unit="DEG")
    comment(lim, "trim search range: negative stall .. lift peak (C_L,max)")
    el(lim, "min", math.degrees(stall.alpha_negative_stall_rad))
    el(lim, "max", math.degrees(alpha_peak_rad(aero)))

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
    f = el(ae, "function", name="aero/bioflex/cl-alpha")
    el(
        f,
        "description",
        "C_L(alpha) at de = 0: C_L0 + C_La*alpha from -10 to 11 deg (RIGID_AERODYNAMICS), "
        "round-over to cl_max and post-stall decay (POST_STALL)",
    )
    W.table(f, alpha, zip(a_tab, lift_curve(a_tab, aero, stall), strict=True), width=14)
    _product(
        ae,
        "aero/bioflex/cl-elevator",
        "C_L due to elevator: C_Lde*de",
        [de, aero.cl_delta_e_per_rad],
    )
    f = el(ae, "function", name="aero/bioflex/cl-total")
    el(f, "description", "total lift coefficient C_L")
    s = el(f, "sum")
    el(s, "property", "aero/bioflex/cl-alpha")
    el(s, "property", "aero/bioflex/cl-elevator")

    ax = el(ae, "axis", name="LIFT")
    comment(ax, "C_Lq = C_Ladot = 0: the paper's A_RR has Z_q = 0")
    _product(ax, "aero/force/lift", "lift: qbar*S*C_L", qs + ["aero/bioflex/cl-total"])

    ax = el(ae, "axis", name="DRAG")
    _product(ax, "aero/force/drag-cd0", "zero-lift drag: qbar*S*C_D0", qs + [aero.cd0])
    _product(
        ax,
        "aero/force/drag-induced",
        "induced drag: qbar*S*k*C_L^2 (k = 1/(pi*AR*0.85))",
        qs + ["aero/bioflex/cl-total", "aero/bioflex/cl-total", aero.k_induced],
    )
    f = el(ax, "function", name="aero/force/drag-separated")
    el(f, "description", "separated-flow drag beyond the linear range (POST_STALL)")
    prod = el(f, "product")
    for x in qs:
        el(prod, "property", x)
    W.table(prod, alpha, zip(a_tab, separated_drag(a_tab, aero, stall), strict=True), width=14)

    ax = el(ae, "axis", name="SIDE")
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

    ax = el(ae, "axis", name="ROLL")
    _product(ax, "aero/moment/roll-beta", "qbar*S*b*C_lb*beta", qsb + [beta, aero.cl_beta_per_rad])
    _product(ax, "aero/moment/roll-p", "qbar*S*b*C_lp*p*b/2V", qsb + p_hat + [aero.cl_p_per_rad])
    _product(ax, "aero/moment/roll-r", "qbar*S*b*C_lr*r*b/2V", qsb + r_hat + [aero.cl_r_per_rad])
    _product(
        ax, "aero/moment/roll-aileron", "qbar*S*b*C_lda*da", qsb + [da, aero.cl_delta_a_per_rad]
    )

    ax = el(ae, "axis", name="PITCH")
    comment(ax, "about the CG; C_malpha, C_mq, C_madot CALIBRATED to Table 3 (airframe.py)")
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

    ax = el(ae, "axis", name="YAW")
    _product(ax, "aero/moment/yaw-beta", "qbar*S*b*C_nb*beta", qsb + [beta, aero.cn_beta_per_rad])
    _product(ax, "aero/moment/yaw-p", "qbar*S*b*C_np*p*b/2V", qsb + p_hat + [aero.cn_p_per_rad])
    _product(ax, "aero/moment/yaw-r", "qbar*S*b*C_nr*r*b/2V", qsb + r_hat + [aero.cn_r_per_rad])
    _product(ax, "aero/moment/yaw-rudder", "qbar*S*b*C_ndr*dr", qsb + [dr, aero.cn_delta_r_per_rad])


def render_engine(prop: Propulsion = PROPULSION) -> str:
    """Text of ``aircraft/bioflex/Engines/bioflex_motor.xml``."""
    root = ET.Element("electric_engine", name=ENGINE_FILE)
    comment(
        root,
        "one motor of the contra-rotating pair: "
        "PROPULSION.motor_max_shaft_power_w / rotor_count (ESTIMATE, airframe.py)",
    )
    el(root, "power", prop.motor_max_shaft_power_w / prop.rotor_count, unit="WATTS")
    return serialise(root, HEADER)


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
    comment(
        root,
        f"one rotor of the contra-rotating pair, PROPULSION (ESTIMATE, airframe.py): {inertia}, "
        "diameter, blades",
    )
    total = prop.trim_rotor_inertia_kg_m2 if trim_companion else prop.rotor_inertia_kg_m2
    ixx = total / prop.rotor_count
    el(root, "ixx", ixx * U.SLUG_FT2_PER_KG_M2, unit="SLUG*FT2")
    el(root, "diameter", prop.prop_diameter_m * U.FT_PER_M, unit="FT")
    el(root, "numblades", str(prop.prop_blades))
    el(root, "constspeed", "0")
    j, ct, cp = propeller_tables(prop)
    comment(
        root,
        "C_T(J), C_P(J): blade-element momentum theory on the PROPULSION blade, divided by "
        "rotor_count (each rotor gives its share of the thrust and absorbs its share of the power)",
    )
    for name, values in (("C_THRUST", ct / prop.rotor_count), ("C_POWER", cp / prop.rotor_count)):
        t = el(root, "table", name=name, type="internal")
        W.table_data(t, zip(j, values, strict=True), width=14, indent=6)
    return serialise(root, HEADER)


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
    comment(root, "deflection limits: parameters.airframe.CONTROL_LIMITS (ESTIMATE)")
    surfaces = (
        ("Pitch", "elevator", "pitch", limits.elevator_max_rad, ("fcs/elevator-pos",)),
        ("Roll", "aileron", "roll", limits.aileron_max_rad, ("fcs/left-aileron-pos",)),
        ("Yaw", "rudder", "yaw", limits.rudder_max_rad, ("fcs/rudder-pos",)),
    )
    for channel, surface, axis, max_rad, outputs in surfaces:
        ch = el(root, "channel", name=channel)
        sm = el(ch, "summer", name=f"fcs/{surface}-sum-norm")
        el(sm, "input", f"fcs/{surface}-cmd-norm")
        el(sm, "input", f"fcs/{axis}-trim-cmd-norm")
        clip = el(sm, "clipto")
        el(clip, "min", -1.0)  # normalised travel
        el(clip, "max", 1.0)
        for out in outputs:
            el(sm, "output", f"{out}-norm")
        gain = el(ch, "pure_gain", name=f"fcs/{surface}-scale-rad")
        el(gain, "input", f"fcs/{surface}-sum-norm")
        el(gain, "gain", max_rad)
        for out in outputs:
            el(gain, "output", f"{out}-rad")
        if surface == "aileron":
            comment(ch, "right aileron deflects opposite to the left one")
            inv = el(ch, "pure_gain", name="fcs/right-aileron-inverter")
            el(inv, "input", "fcs/aileron-sum-norm")
            el(inv, "gain", -1.0)
            el(inv, "output", "fcs/right-aileron-pos-norm")
            inv = el(ch, "pure_gain", name="fcs/right-aileron-scale-rad")
            el(inv, "input", "fcs/right-aileron-pos-norm")
            el(inv, "gain", max_rad)
            el(inv, "output", "fcs/right-aileron-pos-rad")
    ch = el(root, "channel", name="Throttle")
    comment(ch, "one lever for the contra-rotating pair: every motor gets the same throttle")
    g = el(ch, "pure_gain", name="fcs/throttle-pos-gain")
    el(g, "input", "fcs/throttle-cmd-norm")
    el(g, "gain", 1.0)  # direct: no throttle lag in the rigid analyses
    clip = el(g, "clipto")
    el(clip, "min", 0.0)  # throttle range 0..1
    el(clip, "max", 1.0)
    for i in range(prop.rotor_count):
        el(g, "output", f"fcs/throttle-pos-norm[{i}]")
    return serialise(root, HEADER)


def render_initial_condition() -> str:
    """Text of ``aircraft/bioflex/reset_cruise.xml`` (level, wings level, Table 1 cruise)."""
    root = ET.Element("initialize", name=INIT_FILE)
    comment(root, "Table 1 cruise speed at ISA sea level; ground TERRAIN_CLEARANCE_M below")
    el(root, "vt", INIT_SPEED_M_S * U.FT_PER_M, unit="FT/SEC")
    comment(root, "JSBSim reads <elevation> (terrain) before <altitudeMSL> (above sea level)")
    el(root, "elevation", (INIT_ALTITUDE_M - TERRAIN_CLEARANCE_M) * U.FT_PER_M, unit="FT")
    el(root, "altitudeMSL", INIT_ALTITUDE_M * U.FT_PER_M, unit="FT")
    for tag in ("phi", "theta", "psi"):
        el(root, tag, 0.0, unit="RAD")  # level attitude, wings level, heading north
    el(root, "latitude", INIT_LATITUDE_RAD, unit="RAD")
    el(root, "longitude", 0.0, unit="RAD")  # arbitrary meridian
    el(root, "running", "-1")  # all engines running (electric motors: no start sequence)
    return serialise(root, HEADER)


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
