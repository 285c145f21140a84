"""Reading a definition file (TOML, docs/aircraft.md) into a :class:`Definition`.

Every field is checked when the file is read: its type, its unit's plausible range (a
definition written in millimetres or in per cent is refused, not analysed), the structure's
positive definiteness. A problem is one line naming the field and what is accepted
(:class:`DefinitionError`, an :class:`~bioflex_jsb.errors.InputError`: exit 2 in the CLI).
"""

from __future__ import annotations

import math
from importlib import resources
from pathlib import Path

import numpy as np

from bioflex_jsb.aeroelasticity.control_surface import ControlSurface, SurfaceActuator
from bioflex_jsb.definition.airframe import parse_airframe
from bioflex_jsb.definition.flying import (
    FLYING_AERO_FIELDS,
    SHIPPED_AIRCRAFT,
    check_span,
    flying_structure,
    flying_wing,
)
from bioflex_jsb.definition.model import (
    DEFAULT_MONITORING_STATIONS,
    AeroSettings,
    Air,
    AnalysisSettings,
    BeamStructure,
    Definition,
    WingStation,
)
from bioflex_jsb.definition.ranges import (  # noqa: F401  (re-exported: api, cli)
    ACTUATOR_DAMPING_RANGE,
    ACTUATOR_FREQUENCY_RANGE_RAD_S,
    AERO_MODELS,
    CHORD_RANGE_M,
    DAMPING_RANGE,
    DENSITY_RANGE_KG_M3,
    DIHEDRAL_LIMIT_RAD,
    HINGE_RANGE,
    INERTIA_AXES,
    INERTIA_RANGE_KG_M,
    LEADING_EDGE_RANGE_M,
    LIFT_SLOPE_RANGE_PER_RAD,
    LIFT_SLOPES,
    MASS_PER_LENGTH_RANGE_KG_M,
    MAX_MONITORING_STATIONS,
    MAX_POINT_MASSES,
    MAX_STRUTS,
    METHODS,
    MIN_CONTROL_SPAN_FRACTION,
    N_ELEMENTS_RANGE,
    N_MODES_RANGE,
    POINT_MASS_CHORD_RANGE,
    POINT_MASS_INERTIA_RANGE_KG_M2,
    POINT_MASS_RANGE_KG,
    SEMISPAN_RANGE_M,
    SPEED_LIMIT_M_S,
    STIFFNESS_RANGE_N_M2,
    STRIPS_RANGE,
    STRUT_STIFFNESS_RANGE_N_M,
    TWIST_LIMIT_RAD,
    TWIST_UNITS,
)
from bioflex_jsb.definition.reader import DefinitionError, Reader
from bioflex_jsb.definition.sensors import parse_sensors
from bioflex_jsb.inputs import Interval
from bioflex_jsb.structures.beam import PointMass, VerticalSpring
from bioflex_jsb.tomlfile import read_toml

# Definitions in bioflex_jsb/data/aircraft/<name>.toml: the clamped (benchmark) wings, and
# the aircraft (definition.flying.SHIPPED_AIRCRAFT: the prototype's six variants).
SHIPPED = ("goland",)
# The second aircraft (JSBSim's SGS glider with an estimated elastic wing: docs/aircraft.md)
# and its wing clamped, the powered example (c172_elastic), and the Goland wing with an
# illustrative aileron (the aileron command's case): loaded by name too
# (load_aircraft("sgs_elastic"), load_definition("sgs_wing")); not benchmark wings.
OTHER_SHIPPED = ("sgs_wing", "sgs_elastic", "c172_elastic", "goland_aileron")
ALL_SHIPPED = SHIPPED + SHIPPED_AIRCRAFT + OTHER_SHIPPED
FORMAT_VERSION = 1



def _per_station(r: Reader, t: dict, key: str, n: int, lo: float, hi: float, unit: str,
                 hint: str = "") -> np.ndarray:
    """A number (uniform) or a list of one number per wing station."""
    v = t.get(key)
    where = "structure"
    if v is None:
        raise r.fail(f"{where}.{key}", f"missing (a number in {unit}, or one per station)")
    values = v if isinstance(v, list) else [v] * n
    if len(values) != n:
        raise r.fail(f"{where}.{key}", f"has {len(values)} values for {n} wing stations")
    out = [r.number({key: x}, where, key, lo, hi, unit, hint=hint) for x in values]
    return np.array(out, dtype=float)


def _stations(r: Reader, wing: dict) -> tuple[WingStation, ...]:
    unit = r.choice(wing, "wing", "twist_unit", TWIST_UNITS, "deg")
    rows = wing.get("stations")
    if not isinstance(rows, list) or len(rows) < 2 or not all(isinstance(x, dict)
                                                              for x in rows):
        raise r.fail("wing.stations", "need at least 2 stations (root y_m = 0, tip), each a "
                     "table {y_m, chord_m, leading_edge_x_m, twist, elastic_axis, "
                     "centre_of_mass}")
    allowed = ("y_m", "chord_m", "leading_edge_x_m", "z_m", "twist", "elastic_axis",
               "centre_of_mass")
    tip = rows[-1].get("y_m")
    mm_hint = ""
    if isinstance(tip, int | float) and tip > SEMISPAN_RANGE_M[1]:
        mm_hint = " (the format is SI: is the file in millimetres?)"
    out = []
    for i, row in enumerate(rows):
        w = f"wing.stations[{i}]"
        r.keys(row, w, allowed)
        y = r.number(row, w, "y_m", 0.0, SEMISPAN_RANGE_M[1], "m", hint=mm_hint)
        c = r.number(row, w, "chord_m", *CHORD_RANGE_M, "m", hint=mm_hint)
        x = r.number(row, w, "leading_edge_x_m", *LEADING_EDGE_RANGE_M, "m", default=0.0)
        z = r.number(row, w, "z_m", *LEADING_EDGE_RANGE_M, "m", default=0.0)
        lim = TWIST_LIMIT_RAD if unit == "rad" else math.degrees(TWIST_LIMIT_RAD)
        tw = r.number(row, w, "twist", -lim, lim, unit, default=0.0)
        ea = r.number(row, w, "elastic_axis", 0.0, 1.0, "chord fraction")
        cg = r.number(row, w, "centre_of_mass", 0.0, 1.0, "chord fraction")
        out.append(WingStation(y, c, x, tw if unit == "rad" else math.radians(tw), ea, cg, z))
    ys = [s.y_m for s in out]
    if ys[0] != 0.0 or any(b <= a for a, b in zip(ys, ys[1:], strict=False)):
        raise r.fail("wing.stations.y_m", f"must start at the root (0) and increase strictly, "
                     f"got {ys}")
    if out[0].z_m != 0.0:
        raise r.fail("wing.stations[0].z_m", "must be 0: heights are the leading edge's above "
                     "the root's")
    for i in range(1, len(out)):
        angle = math.atan2(out[i].z_m - out[i - 1].z_m, out[i].y_m - out[i - 1].y_m)
        if abs(angle) > DIHEDRAL_LIMIT_RAD:
            raise r.fail(f"wing.stations[{i}].z_m", f"the panel's dihedral "
                         f"{math.degrees(angle):.3g} deg is outside "
                         f"±{math.degrees(DIHEDRAL_LIMIT_RAD):g} deg (z_m is the height in m, "
                         "not an angle)")
    if not SEMISPAN_RANGE_M[0] <= ys[-1]:
        raise r.fail(f"wing.stations[{len(ys) - 1}].y_m", f"semispan {ys[-1]:g} m is below "
                     f"{SEMISPAN_RANGE_M[0]:g} m (is the file in another unit?)")
    return tuple(out)


def _rows(r: Reader, t: dict, key: str, limit: int, what: str) -> list[dict]:
    """An array of tables ``[[structure.<key>]]`` (none: empty)."""
    rows = t.get(key, [])
    if not isinstance(rows, list) or not all(isinstance(x, dict) for x in rows):
        raise r.fail(f"structure.{key}", f"must be an array of tables [[structure.{key}]], "
                     f"each {what}")
    if len(rows) > limit:
        raise r.fail(f"structure.{key}", f"{len(rows)} entries; accepted at most {limit}")
    return rows


def _point_masses(r: Reader, t: dict, semispan_m: float) -> tuple[PointMass, ...]:
    """``[[structure.point_masses]]``: y_m, mass_kg, chord_position, pitch_inertia_kg_m2,
    name (docs/aircraft.md)."""
    out = []
    for i, row in enumerate(_rows(r, t, "point_masses", MAX_POINT_MASSES,
                                  "{y_m, mass_kg, chord_position, pitch_inertia_kg_m2, name}")):
        w = f"structure.point_masses[{i}]"
        r.keys(row, w, ("y_m", "mass_kg", "chord_position", "pitch_inertia_kg_m2", "name"))
        y = r.number(row, w, "y_m", 0.0, semispan_m, "m")
        if y <= 0.0:
            raise r.fail(f"{w}.y_m", "0 is the clamped root, where a mass does not move; "
                         f"accepted 0 < y_m <= {semispan_m:g} m")
        out.append(PointMass(
            y_m=y, mass_kg=r.number(row, w, "mass_kg", *POINT_MASS_RANGE_KG, "kg"),
            x_frac=r.number(row, w, "chord_position", *POINT_MASS_CHORD_RANGE,
                            "chord fraction", hint=" (a fraction of the local chord aft of "
                            "the leading edge, negative ahead of it)"),
            pitch_inertia_kg_m2=r.number(row, w, "pitch_inertia_kg_m2",
                                         *POINT_MASS_INERTIA_RANGE_KG_M2, "kg m^2",
                                         default=0.0),
            name=r.text(row, w, "name", "")))
    return tuple(out)


def _struts(r: Reader, t: dict, semispan_m: float) -> tuple[VerticalSpring, ...]:
    """``[[structure.struts]]``: y_m (the attachment), stiffness_n_m, name."""
    out = []
    for i, row in enumerate(_rows(r, t, "struts", MAX_STRUTS, "{y_m, stiffness_n_m, name}")):
        w = f"structure.struts[{i}]"
        r.keys(row, w, ("y_m", "stiffness_n_m", "name"))
        y = r.number(row, w, "y_m", 0.0, semispan_m, "m")
        if y <= 0.0:
            raise r.fail(f"{w}.y_m", f"accepted 0 < y_m <= {semispan_m:g} m (the attachment "
                         "on the wing; the root is clamped already)")
        out.append(VerticalSpring(y, r.number(row, w, "stiffness_n_m",
                                              *STRUT_STIFFNESS_RANGE_N_M, "N/m"),
                                  r.text(row, w, "name", "")))
    return tuple(out)


def _structure(r: Reader, stations: tuple[WingStation, ...]) -> BeamStructure:
    allowed = ("kind", "bending_stiffness_n_m2", "torsional_stiffness_n_m2",
               "mass_per_length_kg_m", "pitch_inertia_kg_m", "inertia_axis", "damping_ratio",
               "n_modes", "n_elements", "point_masses", "struts")
    t = r.table("structure", allowed)
    r.choice(t, "structure", "kind", ("beam",), "beam")
    n = len(stations)
    pure = (" (zero torsional stiffness or pitch inertia is a pure-bending structure: no "
            "bending-torsion flutter to find)")
    ei = _per_station(r, t, "bending_stiffness_n_m2", n, *STIFFNESS_RANGE_N_M2, "N m^2")
    gj = _per_station(r, t, "torsional_stiffness_n_m2", n, *STIFFNESS_RANGE_N_M2, "N m^2",
                      pure)
    m = _per_station(r, t, "mass_per_length_kg_m", n, *MASS_PER_LENGTH_RANGE_KG_M, "kg/m")
    inertia = _per_station(r, t, "pitch_inertia_kg_m", n, *INERTIA_RANGE_KG_M, "kg m", pure)
    axis = r.choice(t, "structure", "inertia_axis", INERTIA_AXES, "elastic-axis")
    zeta = r.number(t, "structure", "damping_ratio", *DAMPING_RANGE, "(ratio)", default=0.0,
                    hint=" (a ratio, not a percentage: 2 % is 0.02)")
    chord = np.array([s.chord_m for s in stations])
    d = np.array([s.centre_of_mass - s.elastic_axis for s in stations]) * chord
    i_ea = inertia + (m * d**2 if axis == "centre-of-mass" else 0.0)
    bad = np.flatnonzero(i_ea < m * d**2 * (1.0 - 1e-12))
    if bad.size:
        k = int(bad[0])
        raise r.fail("structure.pitch_inertia_kg_m", f"{inertia[k]:g} kg m about the elastic "
                     f"axis at station {k} is below m'·d² = {m[k] * d[k] ** 2:g} kg m (d the "
                     "centre of mass's offset): the section mass matrix is not positive "
                     "definite")
    semispan = stations[-1].y_m
    return BeamStructure(ei, gj, m, inertia, axis, zeta,
                         r.integer(t, "structure", "n_modes", *N_MODES_RANGE, 6),
                         r.integer(t, "structure", "n_elements", *N_ELEMENTS_RANGE, 40),
                         _point_masses(r, t, semispan), _struts(r, t, semispan))


def _monitoring_stations(r: Reader) -> tuple[float, ...]:
    """``[loads] stations``: fractions of the semispan, each 0 <= s < 1, sorted, distinct."""
    t = r.table("loads", ("stations",), required=False)
    v = t.get("stations", list(DEFAULT_MONITORING_STATIONS))
    accepted = (f"a list of 1..{MAX_MONITORING_STATIONS} fractions of the semispan, each "
                "0 <= s < 1, sorted and distinct, e.g. [0.0, 0.25, 0.5, 0.75]")
    if not isinstance(v, list) or not 1 <= len(v) <= MAX_MONITORING_STATIONS:
        raise r.fail("loads.stations", f"must be {accepted}; got {v!r}")
    out = tuple(r.number({"stations": x}, "loads", "stations", 0.0, 1.0, "(fraction of the "
                         "semispan)") for x in v)
    if out[-1] >= 1.0 or any(b <= a for a, b in zip(out, out[1:], strict=False)):
        raise r.fail("loads.stations", f"must be {accepted}; got {list(out)!r}")
    return out


def _aileron(r: Reader, semispan_m: float) -> ControlSurface | None:
    """``[aileron]`` (optional): ``span = [start, end]`` as fractions of the semispan or
    ``y_m = [start, end]`` in metres (one of them), ``hinge`` the hinge line's chord
    fraction aft of the leading edge (docs/aircraft.md)."""
    t = r.table("aileron", ("span", "y_m", "hinge", "actuator"), required=False)
    if not t:
        return None
    given = [k for k in ("span", "y_m") if k in t]
    if len(given) != 1:
        raise r.fail("aileron", "give its span range once: span = [start, end] as fractions "
                     "of the semispan, or y_m = [start, end] in metres"
                     + (" (not both)" if given else ""))
    key = given[0]
    hi, unit = (1.0, "(fraction of the semispan)") if key == "span" else (semispan_m, "m")
    v = t[key]
    if not isinstance(v, list) or len(v) != 2:
        raise r.fail(f"aileron.{key}", f"must be [start, end] {unit}, got {v!r}")
    hint = " (a fraction: 60 % is 0.6)" if key == "span" else ""
    lo_v, hi_v = (r.number({key: x}, "aileron", key, 0.0, hi, unit, hint=hint) for x in v)
    scale = semispan_m if key == "span" else 1.0
    if hi_v - lo_v < MIN_CONTROL_SPAN_FRACTION * hi:
        raise r.fail(f"aileron.{key}", f"[{lo_v:g}, {hi_v:g}]: start must be below end by at "
                     f"least {MIN_CONTROL_SPAN_FRACTION:g} of the semispan (a narrower surface "
                     "is a tab)")
    hinge = r.number(t, "aileron", "hinge", *HINGE_RANGE, "chord fraction",
                     hint=" (the hinge line aft of the leading edge: a 25 %-chord aileron "
                     "is 0.75)")
    return ControlSurface(lo_v * scale, hi_v * scale, hinge, "aileron")


def _aileron_actuator(r: Reader) -> SurfaceActuator | None:
    """``[aileron.actuator]`` (optional): ``natural_frequency_rad_s`` and ``damping_ratio``
    of the aileron's second-order actuator (docs/lateral.md, "The aileron's actuator and
    unsteady flap")."""
    t = r.data.get("aileron")
    if not isinstance(t, dict) or "actuator" not in t:
        return None
    a = t["actuator"]
    if not isinstance(a, dict):
        raise r.fail("aileron.actuator", "must be a table [aileron.actuator] with "
                     "natural_frequency_rad_s and damping_ratio")
    r.keys(a, "aileron.actuator", ("natural_frequency_rad_s", "damping_ratio"))
    return SurfaceActuator(
        r.number(a, "aileron.actuator", "natural_frequency_rad_s",
                 *ACTUATOR_FREQUENCY_RANGE_RAD_S, "rad/s",
                 hint=" (rad/s, not Hz: a 10 Hz servo is 62.8)"),
        r.number(a, "aileron.actuator", "damping_ratio", *ACTUATOR_DAMPING_RANGE, "(ratio)",
                 hint=" (a ratio: 70 % of critical is 0.7)"))


def parse_aileron(table: dict, semispan_m: float, where: str) -> ControlSurface:
    """An ``[aileron]`` table given outside a file (the API's and the CLI's override),
    checked as a file's is (``where`` names it in the one-line error)."""
    surface = _aileron(Reader({"aileron": table}, where), semispan_m)
    if surface is None:
        raise DefinitionError(f"{where}: aileron: give span = [start, end] and hinge")
    return surface


def parse_definition(data: dict, where: str, path: str = "") -> Definition:
    """A :class:`Definition` from the parsed TOML ``data`` (``where`` names it in errors)."""
    r = Reader(data, where)
    r.keys(data, "(top level)", ("format", "name", "description", "source", "wing",
                                 "structure", "aero", "air", "analysis", "airframe",
                                 "loads", "sensors", "aileron"))
    fmt = data.get("format", FORMAT_VERSION)
    if fmt != FORMAT_VERSION:
        raise r.fail("format", f"must be {FORMAT_VERSION}, got {fmt!r}")
    name = r.text(data, "", "name")
    base_dir = Path(path).parent if path else None
    airframe = parse_airframe(r, data, base_dir) if "airframe" in data else None
    wing = r.table("wing", ("twist_unit", "stations") + (("name",) if airframe else ()))
    stations = _stations(r, wing)
    flying = None
    if airframe is None:
        structure = _structure(r, stations)
    else:
        check_span(r, stations, airframe)
        structure = flying_structure(r, stations, base_dir) or _structure(r, stations)
    at = r.table("aero", ("model", "lift_slope", "section_lift_slope_per_rad", "strips")
                 + (FLYING_AERO_FIELDS if airframe else ()), required=False)
    aero = AeroSettings(
        r.choice(at, "aero", "model", AERO_MODELS, "unsteady"),
        r.choice(at, "aero", "lift_slope", LIFT_SLOPES, "strip"),
        r.number(at, "aero", "section_lift_slope_per_rad", *LIFT_SLOPE_RANGE_PER_RAD,
                 "1/rad", default=2.0 * math.pi),
        r.integer(at, "aero", "strips", *STRIPS_RANGE, 24))
    if airframe is not None:
        flying = flying_wing(r, wing, at, aero, name, isinstance(structure, BeamStructure))
    air_t = r.table("air", ("density_kg_m3",))
    air = Air(r.number(air_t, "air", "density_kg_m3", *DENSITY_RANGE_KG_M3, "kg/m^3"))
    an = r.table("analysis", ("method", "speed_range_m_s"), required=False)
    rng = an.get("speed_range_m_s")
    if rng is not None:
        rng = r.field(Interval("m/s", hi=SPEED_LIMIT_M_S), an, "analysis", "speed_range_m_s")
    analysis = AnalysisSettings(r.choice(an, "analysis", "method", METHODS, "pk"), rng)
    return Definition(name=name, description=r.text(data, "", "description", ""),
                      source=r.text(data, "", "source", ""), stations=stations,
                      structure=structure, aero=aero, air=air, analysis=analysis,
                      airframe=airframe, path=path, flying=flying,
                      monitoring_stations=_monitoring_stations(r),
                      sensor_stations=parse_sensors(r, data, stations[-1].y_m,
                                                    airframe is not None),
                      aileron=_aileron(r, stations[-1].y_m),
                      aileron_actuator=_aileron_actuator(r))


def shipped_path(name: str) -> Path:
    """The shipped definition file ``name`` (bioflex_jsb/data/aircraft/<name>.toml)."""
    return Path(str(resources.files("bioflex_jsb") / "data" / "aircraft" / f"{name}.toml"))


def load_definition(name_or_file: str | Path) -> Definition:
    """A shipped definition by name (:data:`ALL_SHIPPED`) or a definition file (TOML)."""
    text = str(name_or_file)
    path = shipped_path(text) if text in ALL_SHIPPED else Path(text)
    if text not in ALL_SHIPPED and path.suffix != ".toml" and not path.exists():
        raise DefinitionError(f"unknown definition {text!r}: give a shipped name "
                              f"({', '.join(ALL_SHIPPED)}) or a .toml definition file")
    data = read_toml(path, "definition file", DefinitionError)
    return parse_definition(data, f"definition file {str(path)!r}", str(path))
