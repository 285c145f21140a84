"""``--speed``: an airspeed [m/s] typed on the command line and its range, the aircraft's
own (an aircraft definition's flight speeds; without ``--aircraft`` the default aircraft's,
the prototype's 5-40 m/s: definition/flying.py flight_speeds), checked once the whole
command line is read (:func:`check_speed`)."""

from __future__ import annotations

import argparse
import math

from bioflex_jsb.cli.usage import UsageError
from bioflex_jsb.definition.aircraft import default_aircraft
from bioflex_jsb.definition.flying import flight_speeds

# The default aircraft's cruise speed and flight speeds [m/s] (the prototype's: Table 1's
# 15 m/s cruise, the paper's Fig. 21 case; 5-40 m/s)
DEFAULT_SPEED_M_S, (SPEED_MIN_M_S, SPEED_MAX_M_S) = flight_speeds(default_aircraft())
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


def speed_help(default: float | None = DEFAULT_SPEED_M_S, extra: str = "") -> str:
    """The --speed help line: unit, valid range, default."""
    tail = f"; default {default:g}" if default is not None else ""
    return f"airspeed [m/s]: {SPEED_RANGE_TEXT}{extra}{tail}"
