"""The default case and the valid ranges that every command shares.

One default case, the paper's Fig. 21: the optimised wing at 15 m/s through a 3 m/s
sharp-edged gust. One airspeed range for every command,
:data:`~bioflex_jsb.parameters.airframe.AIRSPEED_RANGE_M_S` (its reason is there), stated in
each ``--help``. Plot files: the formats matplotlib writes, and an existing file is replaced
only when bioflex-jsb wrote it (a PNG with our Software tag) or with ``--force``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from bioflex_jsb.cli.common import UsageError, check_file_name, check_output
from bioflex_jsb.cli.speed_option import (  # noqa: F401  (the commands take them from here)
    DEFAULT_SPEED_M_S,
    LINEAR_COMMANDS,
    SPEED_MAX_M_S,
    SPEED_MIN_M_S,
    SPEED_RANGE_TEXT,
    Speed,
    airspeed,
    check_speed,
    speed_bounds,
    speed_help,
)

DEFAULT_WING = "optimised"  # the paper's Fig. 21 case
DEFAULT_GUST = "sharp:3"
def aircraft_speeds(args: argparse.Namespace) -> tuple[float, float | None]:
    """(default speed, top of the flight speeds or None) [m/s] of a linear command: an
    ``--aircraft`` with ``[airframe]`` speeds gives its cruise speed and the top of its speed
    range (the SGS: 25, 28 m/s; the prototype's 15 m/s is below its stall), else the
    prototype's :data:`DEFAULT_SPEED_M_S`."""
    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is not None and aircraft.airframe.cruise_speed_m_s is not None:
        return aircraft.airframe.cruise_speed_m_s, aircraft.airframe.speed_range_m_s[1]
    return DEFAULT_SPEED_M_S, None


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
