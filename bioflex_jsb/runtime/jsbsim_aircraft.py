"""An aircraft definition completed from its JSBSim model (docs/aircraft.md, "Your JSBSim
aircraft"): what the file leaves out is read or identified from the JSBSim aircraft it
names, and what it gives is compared with it.

* Mass, CG and inertia: JSBSim's own totals, as it flies the aircraft (empty weight, point
  masses such as the pilot, fuel: ``inertia/*`` after the initial condition runs); S, b,
  c̄ and the aerodynamic reference point from its ``<metrics>``.
* The speeds (:func:`envelope`): the stall speed from the largest lift coefficient of an α
  sweep at a trim (:mod:`bioflex_jsb.runtime.identification`), the lowest speed
  1.3 × stall (the approach margin of the certification rules, FAR 23.73, 25.125: a gust
  of the flight commands' sizes does not stall it there); the highest the fastest level
  flight JSBSim trims with the engines' full throttle (a glider: its fastest steady glide
  inside its α tables), capped at the 110 m/s of the incompressible model, and every trim
  at least 1° inside the α range of its aerodynamic tables; the cruise the
  level-flight speed at 75 % throttle (the usual cruise setting of a light aircraft's
  operating handbook; a glider: its speed of best glide ratio).
* The derivatives (:func:`identify_schedule`): identified at :data:`SCHEDULE_POINTS`
  speeds across that range and the cruise speed (their non-dimensional values change with
  the trim α); a typed ``[airframe.derivatives]`` table replaces them.

All of it at the ISA altitude whose density is the definition's ``[air]`` density (sea
level for 1.225 kg/m³). Completions are kept per process, keyed on the aircraft's files'
contents and the numbers used.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.definition.model import Inertia, JSBSimValues
from bioflex_jsb.files import read_input_bytes
from bioflex_jsb.parameters.airframe import DerivativeSchedule, ReferenceGeometry
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.runtime.aircraft_files import (
    MAX_FILE_BYTES,
    derived_root,
    named_files,
    read_aircraft_xml,
)
from bioflex_jsb.runtime.fdm import Airframe, load_fdm
from bioflex_jsb.runtime.identification import identify_point
from bioflex_jsb.runtime.jsbsim_log import CapturingLogger, captured
from bioflex_jsb.runtime.results import AircraftLoadError, TrimError
from bioflex_jsb.simulation import jsbsim_properties as JP

INCH_M = 0.0254  # exact
SLUG_FT2_KG_M2 = U.KG_PER_SLUG * U.M_PER_FT**2
STALL_MARGIN = 1.3  # lowest flight speed / stall speed (module docstring)
CRUISE_THROTTLE = 0.75  # module docstring
SPEED_CAP_M_S = 110.0  # runtime/fdm.py SPEED_MAX_M_S: the incompressible model's end
SCHEDULE_POINTS = 6  # speeds of the derivative schedule across the range (plus the cruise)
# The speed sweep of the envelope [m/s]: steps of 5 % from the lowest speed, then bisection
# of the last step to 0.1 m/s (a tenth of the rounding of the speeds printed).
SWEEP_FACTOR = 1.05
BISECTION_TOL_M_S = 0.1
# The fastest trim keeps its α one degree (one interval of the usual JSBSim table) above the
# first point of the aircraft's α tables.
TABLE_MARGIN_RAD = math.radians(1.0)
# ISA troposphere: ρ = ρ0 (1 − L h/T0)^(g/(R L) − 1) (ICAO Doc 7488)
ISA_RHO0_KG_M3, ISA_T0_K, ISA_LAPSE_K_M = 1.225, 288.15, 0.0065
ISA_EXPONENT = STANDARD_GRAVITY_M_S2 / (287.05287 * ISA_LAPSE_K_M) - 1.0
ISA_TOP_M = 11000.0

_CACHE: dict[tuple, JSBSimValues] = {}


def isa_altitude_m(density_kg_m3: float) -> float:
    """The ISA (troposphere) altitude [m] where the density is ``density_kg_m3``."""
    h = ISA_T0_K / ISA_LAPSE_K_M * (1.0 - (density_kg_m3 / ISA_RHO0_KG_M3) ** (1.0 / ISA_EXPONENT))
    if not -500.0 <= h <= ISA_TOP_M:
        raise AircraftLoadError(f"air density {density_kg_m3:g} kg/m^3 is the ISA density at "
                                f"{h:.0f} m, outside -500..{ISA_TOP_M:g} m where JSBSim's "
                                "aircraft are trimmed")
    return h


def _fingerprint(jsbsim_path: str) -> str:
    """A hash of the aircraft file and every file it names (their bytes)."""
    path = Path(jsbsim_path)
    tree = read_aircraft_xml(path)
    digest = hashlib.sha256(read_input_bytes(path, "the JSBSim aircraft", MAX_FILE_BYTES,
                                             AircraftLoadError))
    for f in named_files(path, tree):
        digest.update(read_input_bytes(f.source, f"the file <{f.element} file={f.name!r}>",
                                       MAX_FILE_BYTES, AircraftLoadError))
    return digest.hexdigest()


def probe(jsbsim_path: str) -> JSBSimValues:
    """The JSBSim aircraft's geometry and mass properties (module docstring), SI."""

    work, name = derived_root(jsbsim_path, (0.0, 0.0, 0.0))
    log = CapturingLogger()
    try:
        fdm = load_fdm(Path(work.name), name, Path(jsbsim_path), log)
        with captured(log):
            fdm.run_ic()
        ft2 = U.M_PER_FT**2
        inertia = Inertia(*(fdm[JP.inertia_slugs_ft2(k)] * SLUG_FT2_KG_M2
                            for k in ("ixx", "iyy", "izz", "ixz")))
        return JSBSimValues(
            reference_area_m2=fdm[JP.METRICS_SW_SQFT] * ft2, span_m=fdm[JP.METRICS_BW_FT] *
            U.M_PER_FT, mean_chord_m=fdm[JP.METRICS_CBARW_FT] * U.M_PER_FT,
            mass_kg=fdm[JP.INERTIA_MASS_SLUGS] * U.KG_PER_SLUG,
            cg_m=tuple(fdm[JP.cg_in(a)] * INCH_M for a in "xyz"),
            inertia=inertia,
            aero_reference_point_m=tuple(fdm[JP.aero_rp_in(a)] * INCH_M
                                         for a in "xyz"),
            source=f"JSBSim aircraft {jsbsim_path}")
    finally:
        work.cleanup()


def _trims(airframe: Airframe, speed: float, altitude: float):
    """The trim at ``speed`` [m/s], or None where JSBSim cannot trim, or where the trim's α
    is within :data:`TABLE_MARGIN_RAD` of the lower end of the aircraft's α tables (beyond
    it JSBSim holds the tables' end values: the aerodynamics stop changing with α)."""
    try:
        trim = airframe.trim(speed, altitude)
    except TrimError:
        return None
    return trim if trim.alpha_rad >= airframe.alpha_table_range_rad[0] + TABLE_MARGIN_RAD \
        else None


def _edge(airframe: Airframe, ok: float, bad: float, altitude: float) -> float:
    """The fastest speed that trims between ``ok`` (trims) and ``bad`` (does not) [m/s]."""
    while abs(bad - ok) > BISECTION_TOL_M_S:
        mid = 0.5 * (ok + bad)
        if _trims(airframe, mid, altitude) is not None:
            ok = mid
        else:
            bad = mid
    return ok


def envelope(airframe: Airframe, reference: ReferenceGeometry, mass_kg: float,
             altitude_m: float) -> tuple[float, float, float, float]:
    """(stall speed, lowest, cruise, highest speed) [m/s] of the aircraft (module
    docstring). Raises :class:`TrimError` when it trims nowhere."""
    rho = isa_density_kg_m3(altitude_m)
    weight = mass_kg * STANDARD_GRAVITY_M_S2

    def level_speed(cl: float) -> float:
        return math.sqrt(2.0 * weight / (rho * reference.area_m2 * cl))

    start = None
    # a first trim: level-flight speeds of C_L 0.5, then the others of 0.2..1.2 in steps of
    # 0.05 nearest it first (an aircraft whose engine holds it in a narrow band of speeds,
    # the pa28 of the jsbsim package at 45-55 m/s, is found)
    for cl in sorted(np.arange(0.2, 1.2001, 0.05), key=lambda c: abs(c - 0.5)):
        v = min(level_speed(float(cl)), SPEED_CAP_M_S)
        if _trims(airframe, v, altitude_m) is not None:
            start = v
            break
    if start is None:
        v = min(level_speed(0.5), SPEED_CAP_M_S)
        try:
            airframe.trim(v, altitude_m)
            why = f"at {v:.1f} m/s its alpha leaves its tables"
        except TrimError as exc:
            why = str(exc)
        raise TrimError(f"aircraft {airframe.aircraft!r} trims at none of the level-flight "
                        f"speeds of C_L 0.2..1.2 ({level_speed(1.2):.1f}.."
                        f"{min(level_speed(0.2), SPEED_CAP_M_S):.1f} m/s); {why}")
    point = identify_point(airframe, start, reference, mass_kg, altitude_m)
    stall = level_speed(point.aero.cl_max)
    low = STALL_MARGIN * stall
    while _trims(airframe, low, altitude_m) is None:
        low *= SWEEP_FACTOR
        if low > start:
            raise TrimError(f"aircraft {airframe.aircraft!r} does not trim between "
                            f"{STALL_MARGIN:g} x its stall speed {stall:.1f} m/s and "
                            f"{start:.1f} m/s")
    speeds, results = [], []
    v = low
    while True:
        trim = _trims(airframe, v, altitude_m)
        if trim is None:
            high = _edge(airframe, speeds[-1], v, altitude_m)
            break
        speeds.append(v)
        results.append(trim)
        if v >= SPEED_CAP_M_S:
            high = SPEED_CAP_M_S
            break
        v = min(v * SWEEP_FACTOR, SPEED_CAP_M_S)
    if airframe.engines:
        throttle = np.array([r.throttle for r in results])
        above = np.flatnonzero(throttle >= CRUISE_THROTTLE)
        k = int(above[-1]) if above.size else -1
        if k <= 0 or throttle[np.argmin(throttle)] >= CRUISE_THROTTLE:
            cruise = speeds[-1] if k < 0 else speeds[k]
        else:  # the fast side of the power curve: throttle rises with speed
            j = k - 1
            w = (CRUISE_THROTTLE - throttle[j]) / (throttle[k] - throttle[j])
            cruise = speeds[j] + w * (speeds[k] - speeds[j])
        cruise = min(max(cruise, low), high)
    else:
        glide = [-math.tan(r.flight_path_rad) for r in results]  # sink/speed: 1/(L/D)
        cruise = speeds[int(np.argmin(glide))]
    return stall, low, cruise, high


def isa_density_kg_m3(altitude_m: float) -> float:
    """The ISA troposphere's density [kg/m³] at ``altitude_m`` [m above sea level]."""
    return ISA_RHO0_KG_M3 * (1.0 - ISA_LAPSE_K_M * altitude_m / ISA_T0_K) ** ISA_EXPONENT


def identify_schedule(airframe: Airframe, speeds: list[float], reference: ReferenceGeometry,
                      mass_kg: float, altitude_m: float) -> DerivativeSchedule:
    """The derivatives identified at each of ``speeds`` [m/s] (ascending, distinct)."""
    points = tuple(identify_point(airframe, v, reference, mass_kg, altitude_m).aero
                   for v in speeds)
    return DerivativeSchedule(tuple(speeds), points, f"JSBSim aircraft {airframe.aircraft!r}"
                              f" identified at {altitude_m:.0f} m (ISA)")


def complete(aircraft):
    """``aircraft`` (a :class:`~bioflex_jsb.definition.aircraft.Aircraft`) with what its
    file leaves out taken from its JSBSim aircraft and its own numbers checked against it
    (module docstring); the generated prototype as it is."""
    a = aircraft.airframe
    if not a.jsbsim_path:  # the generated prototype: its model is made from the file
        return aircraft
    if a.checked and not a.missing():
        return aircraft
    altitude = isa_altitude_m(aircraft.definition.air.density_kg_m3)
    key = (a.jsbsim_path, _fingerprint(a.jsbsim_path), altitude, a.reference_area_m2,
           a.span_m, a.mean_chord_m, a.mass_kg, a.cg_m,
           a.cruise_speed_m_s is None, a.derivatives is None)
    values = _CACHE.get(key)
    if values is None:
        values = _identify(aircraft, altitude)
        _CACHE[key] = values
    return aircraft.with_jsbsim(values)


def _identify(aircraft, altitude: float) -> JSBSimValues:
    a = aircraft.airframe
    values = probe(a.jsbsim_path)
    problems = aircraft.jsbsim_mismatches(values)
    if problems or (a.cruise_speed_m_s is not None and a.derivatives is not None):
        return values  # a mismatch is reported by with_jsbsim; nothing else to find
    reference = ReferenceGeometry(
        *(getattr(a, f) if getattr(a, f) is not None else getattr(values, f)
          for f in ("reference_area_m2", "span_m", "mean_chord_m")))
    mass = a.mass_kg if a.mass_kg is not None else values.mass_kg
    cg = a.cg_m if a.cg_m is not None else values.cg_m
    airframe = Airframe.from_file(a.jsbsim_path, cg, aircraft.name)
    if a.cruise_speed_m_s is None:
        stall, low, cruise, high = envelope(airframe, reference, mass, altitude)
        # to 0.1 m/s, inward: the range's ends are speeds that trim
        low, high = math.ceil(low * 10.0) / 10.0, math.floor(high * 10.0) / 10.0
        cruise = min(max(round(cruise, 1), low), high)
        speeds_out = {"stall_speed_m_s": stall, "cruise_speed_m_s": cruise,
                      "speed_range_m_s": (low, high)}
    else:
        cruise = a.cruise_speed_m_s
        low, high = a.speed_range_m_s
        speeds_out = {}
    schedule = None
    if a.derivatives is None:
        grid = sorted({*np.round(np.linspace(low, high, SCHEDULE_POINTS), 3).tolist(), cruise})
        schedule = identify_schedule(airframe, grid, reference, mass, altitude)
    return JSBSimValues(**{**values.__dict__, **speeds_out, "schedule": schedule})


def airframe_for(aircraft=None, root=None, systems: dict[str, str] | None = None) -> Airframe:
    """The JSBSim airframe an aircraft definition flies (an
    :class:`~bioflex_jsb.definition.aircraft.Aircraft`; None: the generated prototype): the
    prototype's generated ``bioflex`` (under ``root``, the default search without it) for
    the prototype's airframe, else its ``airframe.jsbsim`` aircraft, completed and checked
    (:func:`complete`), with the modal wing's hooks at its CG
    (:meth:`~bioflex_jsb.runtime.fdm.Airframe.from_file`) and ``systems`` added
    (the SITL glider's autopilot; the prototype's SITL aircraft has its own:
    generators/autopilot.py)."""
    if aircraft is None or not aircraft.airframe.jsbsim_path:
        return Airframe(root)
    aircraft = complete(aircraft)
    return Airframe.from_file(aircraft.airframe.jsbsim_path, aircraft.airframe.cg_m,
                              aircraft.name, systems)
