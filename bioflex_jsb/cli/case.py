"""The default case and the valid ranges that every command shares.

One default case, the paper's Fig. 21: the optimised wing at 15 m/s through a 3 m/s
sharp-edged gust. One airspeed range for every command,
:data:`~bioflex_jsb.parameters.airframe.AIRSPEED_RANGE_M_S` (its reason is there), stated in
each ``--help``. Plot files: the formats matplotlib writes, and an existing file is replaced
only when bioflex-jsb wrote it (a PNG with our Software tag) or with ``--force``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from bioflex_jsb.cli.common import UsageError, check_file_name, check_output
from bioflex_jsb.parameters.airframe import AIRSPEED_RANGE_M_S

DEFAULT_WING = "optimised"  # the paper's Fig. 21 case
DEFAULT_SPEED_M_S = 15.0
DEFAULT_GUST = "sharp:3"
SPEED_MIN_M_S, SPEED_MAX_M_S = AIRSPEED_RANGE_M_S
# The linear analyses (modes, export) of an aircraft definition take any speed from 1 m/s to
# the end of the incompressible airframe model (definition/airframe.py FLIGHT_SPEED_MAX_M_S):
# the linear model exists below the stall and above the fastest trim (root loci scan it).
LINEAR_SPEED_MIN_M_S = 1.0
SPEED_RANGE_TEXT = (f"the prototype {SPEED_MIN_M_S:g} to {SPEED_MAX_M_S:g} m/s (the native "
                    "export and the flutter scan end at 40 m/s; it flies 10-25 m/s and cannot "
                    "trim below about 9 m/s); an --aircraft its own: its airframe."
                    "speed_range_m_s, or from its JSBSim model 1.3 x stall to its fastest "
                    "level flight (docs/aircraft.md)")


class Speed(float):
    """An airspeed typed on the command line [m/s], with its text (for the message that
    refuses it: the range is the aircraft's, known once the whole line is read)."""

    text: str


def airspeed(text: str) -> float:
    """argparse type: an airspeed [m/s], a plain ASCII number
    (:func:`bioflex_jsb.errors.plain_number`) above 0 and at most the incompressible
    airframe model's 110 m/s; its own aircraft's range is checked once the whole line is
    read (:func:`check_speed`). nan, inf and 1e999 are outside every range."""
    from bioflex_jsb.errors import PLAIN_NUMBER_HELP, InputError, is_plain_number, plain_number

    try:
        value = plain_number(text, "speed")
    except InputError:
        if not (is_plain_number(text) or text.strip().lstrip("+-").lower() in _NOT_FINITE):
            raise argparse.ArgumentTypeError(
                f"speed must be a number in m/s ({PLAIN_NUMBER_HELP}), got {text!r}") from None
        value = math.nan  # nan, inf, 1e999: outside the range
    from bioflex_jsb.definition.airframe import FLIGHT_SPEED_MAX_M_S

    if not 0.0 < value <= FLIGHT_SPEED_MAX_M_S:
        raise argparse.ArgumentTypeError(
            f"speed {text} m/s is outside {SPEED_MIN_M_S:g}..{SPEED_MAX_M_S:g} m/s, the "
            f"prototype's speeds (an --aircraft's own, at most {FLIGHT_SPEED_MAX_M_S:g} m/s)")
    out = Speed(value)
    out.text = text
    return out


_NOT_FINITE = ("nan", "inf", "infinity")
airspeed.__name__ = "speed"
airspeed.plain_numbers = True  # type: ignore[attr-defined]  # checks its own text

LINEAR_COMMANDS = ("modes", "export")  # the commands whose --speed is a linear analysis's


def speed_bounds(args: argparse.Namespace) -> tuple[float, float, str]:
    """(lowest, highest speed [m/s], whose range it is) of ``args``' command: the
    prototype's 5-40 m/s without ``--aircraft``; an aircraft definition's flight speeds
    (its ``airframe.speed_range_m_s``, from the file or its JSBSim model) for a flight
    command, 1 m/s to the incompressible model's 110 m/s for a linear one."""
    from bioflex_jsb.definition.airframe import FLIGHT_SPEED_MAX_M_S

    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is None or aircraft.airframe.speed_range_m_s is None:
        return SPEED_MIN_M_S, SPEED_MAX_M_S, "the speeds every command takes for the prototype"
    if getattr(args, "command", None) in LINEAR_COMMANDS:
        return (LINEAR_SPEED_MIN_M_S, FLIGHT_SPEED_MAX_M_S,
                f"the linear analyses' speeds of aircraft {aircraft.name!r}")
    lo, hi = aircraft.airframe.speed_range_m_s
    whose = "its JSBSim model's" if "speed_range_m_s" in aircraft.airframe.from_jsbsim \
        else "its airframe.speed_range_m_s"
    return lo, hi, f"the flight speeds of aircraft {aircraft.name!r} ({whose})"


def check_speed(args: argparse.Namespace) -> None:
    """Every ``--speed`` typed (a :class:`Speed`) inside :func:`speed_bounds`; one line
    (UsageError, exit 2) for the first outside."""
    values = getattr(args, "speed", None)
    for v in values if isinstance(values, list) else [values]:
        if not isinstance(v, Speed):
            continue  # a default: the aircraft's own
        lo, hi, whose = speed_bounds(args)
        if not lo <= v <= hi:
            raise UsageError(f"speed {v.text} m/s is outside {lo:g}..{hi:g} m/s, {whose}")


def aircraft_speeds(args: argparse.Namespace) -> tuple[float, float | None]:
    """(default speed, top of the flight speeds or None) [m/s] of a linear command: an
    ``--aircraft`` with ``[airframe]`` speeds gives its cruise speed and the top of its speed
    range (the SGS: 25, 28 m/s; the prototype's 15 m/s is below its stall), else the
    prototype's :data:`DEFAULT_SPEED_M_S`."""
    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is not None and aircraft.airframe.cruise_speed_m_s is not None:
        return aircraft.airframe.cruise_speed_m_s, aircraft.airframe.speed_range_m_s[1]
    return DEFAULT_SPEED_M_S, None


def speed_help(default: float | None = DEFAULT_SPEED_M_S, extra: str = "") -> str:
    """The --speed help line: unit, valid range, default."""
    tail = f"; default {default:g}" if default is not None else ""
    return f"airspeed [m/s]: {SPEED_RANGE_TEXT}{extra}{tail}"


def add_force_argument(parser: argparse.ArgumentParser) -> None:
    """--force (replace an existing output file that bioflex-jsb did not write), once."""
    if "--force" not in parser._option_string_actions:  # another helper may have added it
        parser.add_argument("--force", action="store_true",
                            help="replace existing output files that bioflex-jsb did not write")


# The figure formats every --plot help and docs/ list; matplotlib writes more (.jpg with
# Pillow, .eps, .tif, ...), but a figure of ours is promised in these three: a PNG carries our
# Software tag (an existing one is replaced without --force), PDF and SVG are vector.
PLOT_FORMATS = ("png", "pdf", "svg")


def plot_formats() -> dict[str, str]:
    """The listed :data:`PLOT_FORMATS` that this matplotlib writes: suffix (no dot) ->
    description."""
    from bioflex_jsb.sinks.plotting import supported_formats

    available = supported_formats()
    return {s: available[s] for s in PLOT_FORMATS if s in available}


def check_plot_path(path: str | None, force: bool) -> None:
    """Refuse a plot file before any work: a name that is not a usable file name
    (:func:`~bioflex_jsb.cli.common.check_file_name`), a suffix not among
    :data:`PLOT_FORMATS`, or an existing file that is not a plot of ours
    (:func:`~bioflex_jsb.plot_files.is_our_plot`) without --force. One-line
    UsageError."""
    if not path:
        return
    check_file_name(path, "plot file")
    suffix = Path(path).suffix.lower().lstrip(".")
    formats = plot_formats()
    if suffix not in formats:
        what = f".{suffix}" if suffix else "a file without a suffix"
        raise UsageError(f"plot file {path!r}: cannot write {what}; give a name ending in "
                         f"{', '.join('.' + s for s in formats)}")
    from bioflex_jsb.plot_files import is_our_plot

    check_output(path, force, "plot file", ours=is_our_plot)
    parent = Path(path).parent
    if not parent.is_dir():
        raise UsageError(f"plot file {path!r}: the directory {str(parent)!r} does not exist")


def check_time_step(dt_s: float) -> None:
    """--dt within the co-simulation's MIN_DT_S..MAX_DT_S [s] (gust, loads, export-jsbsim);
    exit 2, one line."""
    from bioflex_jsb.simulation.modal_wing import MAX_DT_S, MIN_DT_S

    if not MIN_DT_S <= dt_s <= MAX_DT_S:
        raise UsageError(f"--dt {dt_s:g} s is outside {MIN_DT_S:g}..{MAX_DT_S:g} s")


def check_run_length(duration_s: float, dt_s: float, turbulence: bool = False) -> None:
    """--duration and --dt within the run's limits (:func:`bioflex_jsb.simulation.run.
    check_run_length`: MAX_DURATION_S, MAX_TURBULENCE_DURATION_S for a Dryden or von Kármán
    gust, MAX_STEPS); exit 2, one line."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.simulation.run import check_run_length as _check

    try:
        _check(duration_s, dt_s, turbulence)
    except InputError as exc:
        raise UsageError(f"--{exc}") from None  # "--duration … s is too long; …"
