"""``bioflex-jsb trim``: level-flight trim of the rigid JSBSim airframe."""

from __future__ import annotations

import argparse
import math

from bioflex_jsb.cli.case import DEFAULT_SPEED_M_S, SPEED_RANGE_TEXT, airspeed, speed_help
from bioflex_jsb.cli.common import UsageError, finite_float, print_json

HELP = f"""Trim the rigid JSBSim airframe for wings-level, constant-altitude flight with
JSBSim's own trim routine. Units: --speed is the true airspeed in m/s, --altitude the
height above sea level in m (standard atmosphere; default 0 m, rho = 1.225 kg/m^3). The
table gives angles in degrees (alpha, theta, elevator; + elevator = trailing edge down),
the elevator also as a fraction -1..1 of its travel and the throttle as 0..1 of the motor's
maximum shaft power. With --json, angles are in rad (keys ending in _rad), residual
accelerations in m/s^2 and rad/s^2. Valid range: --speed {SPEED_RANGE_TEXT}, default
{DEFAULT_SPEED_M_S:g} (the paper's cruise); a speed in it that the aircraft cannot fly (below
the stall speed, beyond the motor's thrust at about 32 m/s) ends with a one-line reason and
exit status 2. With --wing W: also the elastic trim of that wing, the one the co-simulation
flies from (--trim elastic): JSBSim's trim carrying the wing's static loads (the static
aeroelastic equilibrium under the trim loads, with the aerodynamic stiffness at the trim's
dynamic pressure, iterated with JSBSim's trim to a fixed point; --json: elastic.trim
"jsbsim"): the modal deflections eta_i [rad],
the tip twist [deg, leading edge up], alpha and elevator rigid -> elastic, the wing's loads
and its static divergence speed; at or beyond that speed it ends with one line naming it
(docs/decisions.md, "Elastic trim"). With --aircraft NAME|FILE.toml naming an aircraft
definition (docs/aircraft.md; a name that is not a JSBSim aircraft under aircraft/): its own
JSBSim airframe, its speeds (--speed within its airframe.speed_range_m_s, default its
cruise_speed_m_s) and the elastic trim of its wing; an aircraft without an engine (the SGS
glider) is trimmed to its steady glide at --speed (the flight-path angle gamma < 0 that
holds the speed: runtime/trim.py), the throttle row then 0."""


def add_flight_condition_arguments(p: argparse.ArgumentParser) -> None:
    """--speed, --altitude and the JSBSim model options shared by trim and linearize."""
    p.add_argument(
        "--speed", type=airspeed, default=DEFAULT_SPEED_M_S, metavar="V",
        help="true " + speed_help(),
    )  # fmt: skip
    p.add_argument(
        "--altitude", type=finite_float("altitude", "m"), default=0.0, metavar="M",
        help="altitude above sea level [m], -500 to 11000 (ISA, up to the tropopause; "
        "default 0: sea level)",
    )  # fmt: skip
    p.add_argument(
        "--jsbsim-root", metavar="DIR", default=None,
        help="JSBSim root holding aircraft/ and systems/ (default: the package's own files, "
        "or $BIOFLEX_JSBSIM_ROOT)",
    )  # fmt: skip
    p.add_argument(
        "--aircraft", metavar="NAME", default=None,
        help="aircraft name under aircraft/ (default: bioflex), or an aircraft definition, "
        "NAME|FILE.toml (docs/aircraft.md: its JSBSim aircraft, speeds and airframe numbers)",
    )  # fmt: skip


def load_airframe(args: argparse.Namespace):
    """The JSBSim airframe the options name; adapter errors become UsageError."""
    from bioflex_jsb.runtime import fdm as jsbsim_fdm
    aircraft = args.aircraft or jsbsim_fdm.DEFAULT_AIRCRAFT
    try:
        return jsbsim_fdm.load_airframe(args.jsbsim_root, aircraft)
    except jsbsim_fdm.FdmError as exc:
        raise UsageError(str(exc)) from None


def register(sub) -> None:
    from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_MASS_BASIS, MASS_BASES, VARIANTS

    p = sub.add_parser("trim", help="level-flight trim of the JSBSim airframe", description=HELP)
    add_flight_condition_arguments(p)
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    # DEFAULT_SPEED_M_S, marked: an aircraft definition's cruise speed replaces it
    p.set_defaults(speed=cruise_speed_default())
    p.add_argument("--wing", default=None, metavar="NAME|FILE.toml",
                   help=f"also the elastic trim of this wing: {', '.join(VARIANTS)}, or a "
                   "variant file (default: the rigid trim only)")
    p.add_argument("--mass-basis", choices=MASS_BASES, default=DEFAULT_MASS_BASIS,
                   help=f"generalised-mass basis of --wing (default {DEFAULT_MASS_BASIS})")
    p.add_argument("--json", action="store_true", help="print JSON (SI, rad) instead of a table")
    p.set_defaults(run=run)


def trim_payload(result) -> dict:
    """JSON form of a :class:`~bioflex_jsb.runtime.fdm.TrimResult` (SI, rad)."""
    return {
        "speed_m_s": result.speed_m_s,
        "altitude_m": result.altitude_m,
        "alpha_rad": result.alpha_rad,
        "theta_rad": result.theta_rad,
        "elevator_rad": result.elevator_rad,
        "elevator_norm": result.elevator_norm,
        "throttle": result.throttle,
        "aileron_norm": result.aileron_norm,
        "propeller_rpm": result.propeller_rpm,
        "thrust_n": result.thrust_n,
        "converged": result.converged,
        "residuals": dict(result.residuals),
        "flight_path_rad": result.flight_path_rad,
    }


def aircraft_definition(args: argparse.Namespace):
    """The aircraft definition ``--aircraft`` names (``None``: a JSBSim aircraft name or no
    option): a ``.toml`` file, or a shipped definition that is no JSBSim aircraft of the
    root (``bioflex_optimised`` is both: the native aircraft, as before). Read and checked
    for flight (one line, exit 2)."""
    from bioflex_jsb.definition.flying import SHIPPED_AIRCRAFT
    from bioflex_jsb.runtime import fdm as jsbsim_fdm

    name = args.aircraft
    if name is None:
        return None
    if not name.endswith(".toml"):
        try:
            root = jsbsim_fdm.locate_root(args.jsbsim_root, name)
        except jsbsim_fdm.FdmError:
            root = None
        if root is not None or name in SHIPPED_AIRCRAFT:
            return None
    from bioflex_jsb.definition.aircraft import load_aircraft
    from bioflex_jsb.definition.flying import flight_refusal
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.runtime.jsbsim_aircraft import complete

    try:
        aircraft = complete(load_aircraft(name))  # JSBSim's numbers where it has none
        problem = flight_refusal(aircraft)
    except InputError as exc:
        raise UsageError(f"--aircraft: {exc}") from None
    if problem:
        raise UsageError(f"--aircraft: {problem}")
    if getattr(args, "wing", None) is not None:
        raise UsageError(f"--aircraft {name} and --wing {args.wing}: give one of them (the "
                         "aircraft's definition holds its wing)")
    return aircraft


def definition_airframe(args: argparse.Namespace, aircraft):
    """The JSBSim airframe of the aircraft definition ``aircraft`` (``--speed`` resolved
    against its speeds first); its errors one line (UsageError)."""
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.runtime.fdm import FdmError
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    args.aircraft_definition = aircraft
    resolve_flight(args)
    try:
        return airframe_for(aircraft, args.jsbsim_root)
    except FdmError as exc:
        raise UsageError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    aircraft = aircraft_definition(args)
    if aircraft is None:
        airframe = load_airframe(args)
        args.speed = float(args.speed)
    else:
        airframe = definition_airframe(args, aircraft)
    result = airframe.trim(args.speed, args.altitude)
    if aircraft is not None:
        elastic = _elastic_trim(args, airframe, aircraft.wing(args.mass_basis))
    else:
        elastic = _elastic_trim(args, airframe) if args.wing else None
    if args.json:
        payload = trim_payload(result)
        if elastic is not None:
            # which elastic trim: JSBSim's with the wing's loads, not the linear model's
            payload["elastic"] = {**elastic.as_dict(), "trim": "jsbsim"}
        print_json(payload)
        return 0
    deg = math.degrees
    rows = [
        ("speed", f"{result.speed_m_s:.2f}", "m/s"),
        ("altitude", f"{result.altitude_m:.1f}", "m"),
        ("alpha", f"{deg(result.alpha_rad):.2f}", "deg"),
        ("theta", f"{deg(result.theta_rad):.2f}", "deg"),
        ("elevator", f"{deg(result.elevator_rad):.2f}", "deg (+ trailing edge down)"),
        ("elevator", f"{result.elevator_norm:.3f}", "of travel, -1..1"),
        ("throttle", f"{result.throttle:.3f}", "0..1"),
        ("propeller", f"{result.propeller_rpm:.0f}", "rev/min"),
        ("thrust", f"{result.thrust_n:.3f}", "N"),
    ]
    if airframe.glider:  # no engine: the steady glide (runtime/trim.py)
        rows[5] = ("elevator", f"{result.elevator_norm:.3f}", "command with pitch trim, -1..1")
        rows[6:9] = [("gamma", f"{deg(result.flight_path_rad):.3f}", "deg (flight path, + up)"),
                     ("sink", f"{-result.speed_m_s * math.sin(result.flight_path_rad):.3f}",
                      "m/s"),
                     ("L/D", f"{-1.0 / math.tan(result.flight_path_rad):.2f}", "-")]
        print(f"Trim ({airframe.aircraft}, wings level, steady glide: no engine), converged: "
              f"{result.converged}")
    else:
        print(f"Trim (JSBSim, wings level, level flight), converged: {result.converged}")
    for name, value, unit in rows:
        print(f"  {name:<10} {value:>10}  {unit}")
    if elastic is not None:
        _print_elastic(elastic.as_dict())
    return 0


def _elastic_trim(args, airframe, build=None):
    """The elastic trim of --wing (or ``build``, an aircraft definition's wing) at --speed
    and --altitude: JSBSim's trim carrying the wing's static loads to their fixed point
    (``Airframe.trim(wing=)``, the trim a run with ``--trim elastic`` starts from)."""
    from bioflex_jsb.cli.common import wing_from_args

    wing = wing_from_args(args) if build is None else build
    try:
        return airframe.trim(args.speed, args.altitude, wing=wing).elastic
    finally:
        airframe.set_external_reactions()  # no wing loads left behind in the airframe


def _print_elastic(e: dict) -> None:
    deg = math.degrees
    print(f"Elastic trim of the {e['wing']} wing at {e['speed_m_s']:g} m/s, JSBSim's trim "
          f"with the wing's static loads (Q = {e['dynamic_pressure_pa']:.1f} Pa; converged: "
          f"{e['converged']} in {e['iterations']} iterations)")
    for i, eta in enumerate(e["eta_rad"]):
        print(f"  eta{i + 1:<7} {eta:10.5f}  rad (modal deflection)")
    print(f"  {'tip twist':<10} {e['tip_twist_deg']:10.2f}  deg (+ leading edge up)")
    print(f"  {'alpha':<10} {deg(e['alpha_rigid_rad']):10.2f} -> {deg(e['alpha_rad']):.2f}  "
          "deg (rigid -> elastic)")
    print(f"  {'elevator':<10} {deg(e['elevator_rigid_rad']):10.2f} -> "
          f"{deg(e['elevator_rad']):.2f}  deg (rigid -> elastic)")
    loads = e["wing_loads"]
    # the modal wing's loads are the deformation's increments over the rigid aircraft's
    # (JSBSim's aerodynamics carry the rigid wing: docs/aircraft.md), not the wing's lift
    print(f"  {'d lift':<10} {loads['lift_n']:10.3f}  N (the deformation's);  pitching "
          f"moment {loads['pitch_moment_n_m']:.4f} N*m")
    div = e["divergence_speed_m_s"]
    print(f"  {'divergence':<10} {'none' if div is None else f'{div:.2f} m/s':>10}  "
          "(static, body held)")
