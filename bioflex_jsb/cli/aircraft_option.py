"""``--aircraft NAME|FILE``: an aircraft definition (docs/aircraft.md) in place of ``--wing``.

Every command that builds the elastic wing takes it through the shared ``--wing`` helpers of
:mod:`bioflex_jsb.cli.common` (``add_wing_arguments`` adds this option, ``wing_from_args``
builds its wing). The definition is read, checked and its wing resolved while the command
line is parsed, so a bad file is one line and exit 2 before anything runs, and every part
of a command that names the wing (log file names, run descriptions, the native-wing path)
sees the aircraft's wing: ``args.wing`` becomes the wing's name when the wing is a named
variant's (the shipped ``bioflex_<variant>`` files), else ``aircraft:<definition name>``
(no variant has that name, so nothing can mistake it for one). ``--wing W --aircraft A``
with W other than the command's default is refused (give one of them).
"""

from __future__ import annotations

import argparse
import sys

AIRCRAFT_PREFIX = "aircraft:"
# The commands whose analyses are linear and take the aircraft's own airframe
# (definition/aircraft.py: Aircraft.linear_problem); the others fly JSBSim's prototype
# airframe and refuse another one (Aircraft.flight_problem).
LINEAR_COMMANDS = ("modes", "flutter", "export")
# The commands of the nonlinear co-simulation, each flying any airframe
# (definition/flying.py: flight_refusal: its own JSBSim aircraft, a glider in its steady
# glide; trim reads its own --aircraft: cli/trim.py; export-jsbsim writes the aircraft file's
# copy with the wing and the files it names: docs/native.md; sitl flies a glider's or a
# powered aircraft's own autopilot: cli/sitl.py; loads: cli/loads.py; ardupilot maps the
# servos by what the aircraft's commands do: cli/sitl_ardupilot.py).
FLIGHT_COMMANDS = ("gust", "compare", "export-jsbsim", "sitl", "loads", "ardupilot")


class CruiseSpeed(float):
    """The ``--speed`` default of the flight commands [m/s]: the prototype's cruise speed
    (Table 1, 15 m/s: cli/case.py DEFAULT_SPEED_M_S) marked as not given, so that an
    ``--aircraft``'s own cruise speed replaces it (:func:`resolve_flight`)."""


def cruise_speed_default() -> CruiseSpeed:
    """The marked default of ``--speed`` (:class:`CruiseSpeed`)."""
    from bioflex_jsb.cli.speed_option import DEFAULT_SPEED_M_S

    return CruiseSpeed(DEFAULT_SPEED_M_S)


class _ShippedOrFile(tuple):
    """The option's choices: it lists the shipped aircraft (for help and for tools that
    enumerate choices) and admits any text, a definition file's path being checked when it
    is read."""

    def __contains__(self, value) -> bool:
        return isinstance(value, str)


class WingAction(argparse._StoreAction):
    """``--wing``: remembers that it was given (``wing_given``), and refuses an
    ``--aircraft`` given before it (the other order: :class:`_AircraftAction`)."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        if getattr(namespace, "aircraft_definition", None) is not None:
            parser.error(f"--aircraft {namespace.aircraft} and --wing {values}: give one of "
                         "them (the aircraft's definition holds its wing)")
        setattr(namespace, self.dest, values)
        namespace.wing_given = True


class _AircraftAction(argparse._StoreAction):
    """Reads the definition when the option is parsed (module docstring); a store action,
    so that the shared parser refuses it given twice like every single-valued option."""

    def __init__(self, *args, wing_default: str | None = None, **kwargs) -> None:
        self.wing_default = wing_default
        super().__init__(*args, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        from bioflex_jsb.definition.aircraft import load_aircraft
        from bioflex_jsb.definition.flying import flight_refusal
        from bioflex_jsb.errors import InputError
        from bioflex_jsb.flight_dynamics.wing_model import VARIANTS
        from bioflex_jsb.runtime.jsbsim_aircraft import complete

        if getattr(namespace, "wing_given", False):  # --wing given, even its default
            parser.error(f"--aircraft {values} and --wing {namespace.wing}: give one of them "
                         "(the aircraft's definition holds its wing)")
        try:
            aircraft = complete(load_aircraft(values))  # JSBSim's numbers where it has none
            # the linear analyses take any airframe; the flight commands one that flies
            command = parser.prog.rsplit(" ", 1)[-1]
            if command in LINEAR_COMMANDS:
                problem = aircraft.linear_problem()
            else:  # every other command flies it (FLIGHT_COMMANDS)
                problem = flight_refusal(aircraft)
            variant = aircraft.variant()
        except InputError as exc:  # the definition's one line, naming the field
            parser.error(f"--aircraft: {exc}")
        if problem:
            parser.error(f"--aircraft: {problem}")
        named = VARIANTS.get(variant.name)
        namespace.wing = variant.name if named == variant else AIRCRAFT_PREFIX + aircraft.name
        namespace.aircraft = values
        namespace.aircraft_definition = aircraft


def add_aircraft_argument(parser: argparse.ArgumentParser, wing_default: str | None) -> None:
    """``--aircraft NAME|FILE`` (``wing_default``: the command's ``--wing`` default)."""
    from bioflex_jsb.definition.flying import SHIPPED_AIRCRAFT

    parser.add_argument(
        "--aircraft", action=_AircraftAction, wing_default=wing_default, default=None,
        metavar="NAME|FILE.toml", choices=_ShippedOrFile(SHIPPED_AIRCRAFT),
        help=f"an aircraft definition in place of --wing: {', '.join(SHIPPED_AIRCRAFT)}, or "
        "a TOML file with [airframe] (docs/aircraft.md); its wing is flown")
    parser.set_defaults(aircraft_definition=None)


def wing_from_aircraft(args: argparse.Namespace):
    """The elastic wing (a WingBuild) of ``--aircraft`` at ``--mass-basis``."""
    from bioflex_jsb.flight_dynamics.wing_model import modes_used_note

    aircraft = args.aircraft_definition
    build = aircraft.wing(args.mass_basis)
    note = modes_used_note(build.variant)
    if note:  # as wing_from_args says it for --wing (stderr: stdout may be JSON)
        print(f"bioflex-jsb: note: {note}", file=sys.stderr)
    return build


def resolve_flight(args: argparse.Namespace) -> None:
    """The trim speed and gust of a flight command from the aircraft (``--aircraft``, else
    the prototype): ``--speed`` not given (None or the marked :class:`CruiseSpeed`
    default) is the aircraft's cruise speed (the prototype's 15 m/s, Table 1), a given one
    must lie in its flight speeds (cli/case.py check_speed: the prototype's 5-40 m/s), and
    a 1-cos length or turbulence scale
    must be at least the aircraft's mean chord (simulation/gusts.py). One line (a
    UsageError, exit 2) otherwise."""
    from bioflex_jsb.cli.speed_option import DEFAULT_SPEED_M_S, check_speed
    from bioflex_jsb.cli.usage import UsageError
    from bioflex_jsb.definition.flying import flight_speeds

    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is None:
        cruise, chord = DEFAULT_SPEED_M_S, None
    else:
        (cruise, _speeds), chord = flight_speeds(aircraft), aircraft.airframe.mean_chord_m
    check_speed(args)
    if args.speed is None or isinstance(args.speed, CruiseSpeed):
        args.speed = float(cruise)
    gust = getattr(args, "gust", None)
    # a parsed gust (gust, compare, sitl) is read again with the chord; loads parses its
    # own text (str) with the chord when it flies
    if chord is not None and gust is not None and not isinstance(gust, str):
        from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust

        try:
            args.gust = parse_gust(gust.text(), chord)
        except GustSpecError as exc:
            raise UsageError(f"--gust: {exc} (aircraft {aircraft.name!r})") from None


def default_airframe():
    """The airframe data (an ``AirframeData``) of the default aircraft, the prototype
    (definition/aircraft.py default_aircraft): what a command without ``--aircraft``
    analyses, and the object an analysis' airframe is compared with (``is``) to learn
    whether it is the prototype's."""
    from bioflex_jsb.definition.aircraft import default_aircraft

    return default_aircraft().airframe_data()


def airframe_from_args(args: argparse.Namespace):
    """The JSBSim airframe of ``--aircraft`` (its own aircraft; the generated prototype
    without the option): runtime/jsbsim_aircraft.py ``airframe_for``."""
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    return airframe_for(getattr(args, "aircraft_definition", None))
