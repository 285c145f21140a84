"""The ``[airframe]`` table of a definition file (docs/aircraft.md, "Airframe"): the JSBSim
aircraft, reference geometry, mass properties, the wing's attachment and the rigid
aerodynamic derivatives, each checked for its unit's range when read.

Valid ranges [unit], each with its reason, are below; a value outside is one line naming the
field (:class:`~bioflex_jsb.definition.reader.DefinitionError`). The ranges are wide on
purpose: they catch a unit mistake (mm for m, g for kg) or a sign, not an unusual aircraft
(a 2500 kg mass with a 1.7 m span is accepted; a negative or NaN one is not).
"""

from __future__ import annotations

import dataclasses
import importlib.util
import math
from pathlib import Path

import numpy as np

from bioflex_jsb.definition.model import AirframeDefinition, Inertia
from bioflex_jsb.definition.reader import Reader
from bioflex_jsb.inputs import Interval
from bioflex_jsb.parameters.airframe import (
    AIRSPEED_RANGE_M_S,
    CRUISE_SPEED_M_S,
    RigidAerodynamics,
)

GENERATED = "bioflex"  # the generated prototype (bioflex_jsb.generators)
# Reference area S [m²]: 1e-3 (a 3 cm × 3 cm model) to 1e4 (an A380 has 845 m²); a file in
# mm² (311100 for 0.3111) is outside.
AREA_RANGE_M2 = (1e-3, 1e4)
SPAN_RANGE_M = (0.1, 200.0)  # full span: 2 × the semispan range of a wing (0.05..100 m)
MEAN_CHORD_RANGE_M = (0.005, 30.0)  # the chord range of a wing station
# S / (b c̄): 1 for a rectangular wing; a tapered wing's mean aerodynamic chord exceeds its
# mean geometric chord S/b (a delta wing: S/(b c̄) = 0.75); 0.5..1.5 catches an S in other
# units or a printed inconsistency (the paper's Table 1 S = 0.174 m² is 0.56 of b·c̄: inside;
# the prototype uses b·c̄, docs/decisions.md "Reference area").
AREA_RATIO_RANGE = (0.5, 1.5)
# Mass [kg]: 1e-3 (a 1 g micro air vehicle) to 1e6 (an An-225 is 6.4e5 kg).
MASS_RANGE_KG = (1e-3, 1e6)
POSITION_RANGE_M = (-200.0, 200.0)  # structural-frame positions: within a 200 m aircraft
# Moments of inertia [kg·m²]: 1e-7 (a 1 g, 1 cm body) to 1e9 (a 747 has Iyy ≈ 4e7 kg·m²).
INERTIA_RANGE_KG_M2 = (1e-7, 1e9)
# Rigid derivatives [per rad or -]: |value| ≤ 50 per rad (the largest in use, C_mq of
# long-tailed aircraft, is about -30); the named ones below have tighter physical ranges.
DERIVATIVE_LIMIT = 50.0
DERIVATIVE_RANGES = {
    "cl_alpha_per_rad": (0.5, 2.0 * math.pi * 1.5),  # 2π per rad is thin-aerofoil 2-D
    "cl_max": (0.3, 4.0),  # a flat plate to a flapped high-lift wing
    "alpha_stall_rad": (math.radians(3.0), math.radians(35.0)),
    "cd0": (0.0, 0.5),
    "k_induced": (0.0, 1.0),  # 1/(π AR e): AR ≥ 0.4 at e = 0.8
}
DERIVATIVE_FIELDS = tuple(f.name for f in dataclasses.fields(RigidAerodynamics))
# the fields a typed table must give (the Table B2 set); the others default to 0
REQUIRED_DERIVATIVES = tuple(f.name for f in dataclasses.fields(RigidAerodynamics)
                             if f.default is dataclasses.MISSING)
FROM_JSBSIM = "jsbsim"  # derivatives = "jsbsim" (or no table): identified from JSBSim
AIRFRAME_FIELDS = ("jsbsim", "reference_area_m2", "span_m", "mean_chord_m", "mass_kg",
                   "cg_m", "inertia_kg_m2", "wing_root_leading_edge_m", "derivatives",
                   "cruise_speed_m_s", "speed_range_m_s")
# The speeds the flight commands trim at [m/s] (gust, compare, trim, sitl): above 0 and at
# most airframe.py's runtime limit of the incompressible model, 110 m/s (1/3 of the speed of
# sound; runtime/fdm.py SPEED_MAX_M_S, repeated here: the loader does not import the
# runtime). Optional: a file without them is analysed (modes, flutter) but not flown.
FLIGHT_SPEED_MAX_M_S = 110.0
INERTIA_FIELDS = ("ixx", "iyy", "izz", "ixz")


def _flight_speeds(r: Reader, t: dict) -> tuple[float | None, tuple[float, float] | None]:
    """``cruise_speed_m_s`` and ``speed_range_m_s`` (both or neither; the cruise inside)."""
    w = "airframe"
    if "cruise_speed_m_s" not in t and "speed_range_m_s" not in t:
        return None, None
    lo, hi = r.field(Interval("m/s", hi=FLIGHT_SPEED_MAX_M_S,
                              hint=" (given with cruise_speed_m_s)"), t, w, "speed_range_m_s")
    cruise = r.number(t, w, "cruise_speed_m_s", lo, hi, "m/s",
                      hint=" (inside airframe.speed_range_m_s)")
    return cruise, (lo, hi)


def jsbsim_aircraft_dir() -> Path | None:
    """The jsbsim package's ``aircraft/`` directory, found without importing jsbsim (only
    the runtime imports it); ``None`` when the package is not installed."""
    spec = importlib.util.find_spec("jsbsim")
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(list(spec.submodule_search_locations)[0]) / "aircraft"


def _jsbsim_path(r: Reader, name: str, base_dir: Path | None) -> str:
    """The aircraft file of ``name``: a package aircraft or a directory <dir>/<dir>.xml."""
    if name == GENERATED:
        return ""
    field = "airframe.jsbsim"
    looks_like_path = "/" in name or name.startswith(".")
    try:
        if not looks_like_path:
            pkg = jsbsim_aircraft_dir()
            if pkg is not None and (pkg / name / f"{name}.xml").is_file():
                return str(pkg / name / f"{name}.xml")
        path = Path(name)
        if base_dir is not None and not path.is_absolute():
            path = base_dir / path
        if path.is_dir() and (path / f"{path.name}.xml").is_file():
            return str((path / f"{path.name}.xml").resolve())
    except (OSError, ValueError) as exc:  # a name too long for the file system, a NUL
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise r.fail(field, f"{name[:60]!r}{'…' if len(name) > 60 else ''} "
                     f"({len(name)} characters) cannot be looked up: {why}") from None
    raise r.fail(field, f"{name!r} is neither {GENERATED!r} (the generated prototype), an "
                 "aircraft of the jsbsim package's aircraft/ directory (e.g. c172x, SGS), nor "
                 "a directory holding <its name>.xml")


def _inertia(r: Reader, t: dict) -> Inertia:
    where = "airframe.inertia_kg_m2"
    it = t.get("inertia_kg_m2")
    if not isinstance(it, dict):
        raise r.fail(where, "must be a table {ixx, iyy, izz, ixz} in kg m^2 (about the CG, "
                     "body axes)")
    r.keys(it, where, INERTIA_FIELDS)
    ixx, iyy, izz = (r.number(it, where, k, *INERTIA_RANGE_KG_M2, "kg m^2")
                     for k in ("ixx", "iyy", "izz"))
    ixz = r.number(it, where, "ixz", -INERTIA_RANGE_KG_M2[1], INERTIA_RANGE_KG_M2[1],
                   "kg m^2", default=0.0)
    # A rigid body's inertia tensor is positive definite and each principal moment is at most
    # the sum of the other two (the triangle inequality of the second moments); 1e-9
    # relative: the rounding of printed values.
    tensor = np.array([[ixx, 0.0, -ixz], [0.0, iyy, 0.0], [-ixz, 0.0, izz]])
    eig = np.linalg.eigvalsh(tensor)
    slack = 1e-9 * float(eig.sum())
    if eig[0] <= 0.0 or 2.0 * eig[-1] > eig.sum() + slack:
        raise r.fail(where, f"ixx {ixx:g}, iyy {iyy:g}, izz {izz:g}, ixz {ixz:g} kg m^2 is no "
                     "rigid body's inertia (it must be positive definite and each principal "
                     "moment at most the sum of the other two)")
    return Inertia(ixx, iyy, izz, ixz)


def _derivatives(r: Reader, t: dict) -> dict[str, float] | None:
    where = "airframe.derivatives"
    v = t.get("derivatives")
    if v == FROM_JSBSIM:
        return None
    if not isinstance(v, dict):
        raise r.fail(where, f"must be {FROM_JSBSIM!r} (from JSBSim's linearisation) or a table "
                     f"of the rigid derivatives {', '.join(DERIVATIVE_FIELDS)}")
    r.keys(v, where, DERIVATIVE_FIELDS)
    missing = [k for k in REQUIRED_DERIVATIVES if k not in v]
    if missing:
        raise r.fail(f"{where}.{missing[0]}", "missing (a typed table gives the "
                     f"{len(REQUIRED_DERIVATIVES)} derivatives of Table B2: {len(missing)} are "
                     "absent; leave the table out to take them from JSBSim)")
    out = {}
    for k in DERIVATIVE_FIELDS:
        if k not in v:
            continue  # a term beyond Table B2, 0 unless given
        lo, hi = DERIVATIVE_RANGES.get(k, (-DERIVATIVE_LIMIT, DERIVATIVE_LIMIT))
        unit = "-" if k in ("cl0", "cl_max", "cd0", "k_induced", "cm0", "cl_u", "cd_u",
                            "cm_u", "ct_u", "ct_delta_t", "cm_delta_t") else "1/rad"
        if k == "alpha_stall_rad":
            unit = "rad"
        out[k] = r.number(v, where, k, lo, hi, unit)
    return out


def parse_airframe(r: Reader, data: dict, base_dir: Path | None) -> AirframeDefinition:
    """The :class:`AirframeDefinition` of the ``[airframe]`` table (module docstring for the
    ranges).
    On a JSBSim aircraft every field but ``jsbsim`` is optional (None: taken from the
    JSBSim aircraft when the aircraft is completed); the generated prototype ``bioflex``
    needs its numbers written (they are the paper's, and its model is generated from
    them)."""
    t = r.table("airframe", AIRFRAME_FIELDS)
    name = r.text(t, "airframe", "jsbsim")
    path = _jsbsim_path(r, name, base_dir)
    generated = name == GENERATED
    w = "airframe"

    def given(key: str) -> bool:
        return generated or key in t

    area = r.number(t, w, "reference_area_m2", *AREA_RANGE_M2, "m^2",
                    hint=" (the format is SI: m^2, not mm^2 or ft^2)") \
        if given("reference_area_m2") else None
    span = r.number(t, w, "span_m", *SPAN_RANGE_M, "m", hint=" (the format is SI: m)") \
        if given("span_m") else None
    chord = r.number(t, w, "mean_chord_m", *MEAN_CHORD_RANGE_M, "m",
                     hint=" (the format is SI: m)") if given("mean_chord_m") else None
    if area is not None and span is not None and chord is not None:
        ratio = area / (span * chord)
        if not AREA_RATIO_RANGE[0] <= ratio <= AREA_RATIO_RANGE[1]:
            raise r.fail(f"{w}.reference_area_m2", f"{area:g} m^2 is {ratio:.3g} x span_m x "
                         f"mean_chord_m; accepted {AREA_RATIO_RANGE[0]:g}.."
                         f"{AREA_RATIO_RANGE[1]:g} (is one of the three in another unit?)")
    mass = r.number(t, w, "mass_kg", *MASS_RANGE_KG, "kg", hint=" (the format is SI: kg)") \
        if given("mass_kg") else None
    cg = r.vector(t, w, "cg_m", *POSITION_RANGE_M, "m") if given("cg_m") else None
    root = r.vector(t, w, "wing_root_leading_edge_m", *POSITION_RANGE_M, "m") \
        if given("wing_root_leading_edge_m") else None
    inertia = _inertia(r, t) if given("inertia_kg_m2") else None
    derivatives = _derivatives(r, t) if given("derivatives") else None
    if generated and derivatives is None:
        raise r.fail(f"{w}.derivatives", f"the generated prototype {GENERATED!r} needs its "
                     "table (its JSBSim model is generated from it)")
    cruise, speeds = _flight_speeds(r, t)
    if generated and cruise is None:  # the prototype's: Table 1's cruise, the paper's speeds
        cruise, speeds = CRUISE_SPEED_M_S, AIRSPEED_RANGE_M_S
    return AirframeDefinition(jsbsim=name, jsbsim_path=path, reference_area_m2=area, span_m=span,
                    mean_chord_m=chord, mass_kg=mass, cg_m=cg, inertia=inertia,
                    wing_root_leading_edge_m=root, derivatives=derivatives,
                    cruise_speed_m_s=cruise, speed_range_m_s=speeds, checked=generated)
