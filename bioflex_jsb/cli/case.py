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

from bioflex_jsb.cli.common import UsageError, check_output
from bioflex_jsb.parameters.airframe import AIRSPEED_RANGE_M_S

DEFAULT_WING = "optimised"  # the paper's Fig. 21 case
DEFAULT_SPEED_M_S = 15.0
DEFAULT_GUST = "sharp:3"
SPEED_MIN_M_S, SPEED_MAX_M_S = AIRSPEED_RANGE_M_S
SPEED_RANGE_TEXT = (f"{SPEED_MIN_M_S:g} to {SPEED_MAX_M_S:g} m/s (the native export and the "
                    "flutter scan end at 40 m/s; the aircraft flies 10-25 m/s and cannot trim "
                    "below about 9 m/s)")

# Longest simulated run of gust/compare [s]: 600 s at the default step is 576 000 steps,
# ~100 MB of channels per model; longer records belong in a sweep of shorter cases.
MAX_DURATION_S = 600.0
MAX_STEPS = 2_000_000  # steps per run (--duration / --dt), whatever the step


def airspeed(text: str) -> float:
    """argparse type: an airspeed in :data:`AIRSPEED_RANGE_M_S` [m/s]."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"speed must be a number in m/s, got {text!r}") from None
    if not (math.isfinite(value) and SPEED_MIN_M_S <= value <= SPEED_MAX_M_S):
        raise argparse.ArgumentTypeError(
            f"speed {text} m/s is outside {SPEED_MIN_M_S:g}..{SPEED_MAX_M_S:g} m/s, the range "
            "every command accepts")
    return value


airspeed.__name__ = "speed"


def speed_help(default: float | None = DEFAULT_SPEED_M_S, extra: str = "") -> str:
    """The --speed help line: unit, valid range, default."""
    tail = f"; default {default:g}" if default is not None else ""
    return f"airspeed [m/s], {SPEED_RANGE_TEXT}{extra}{tail}"


def add_force_argument(parser: argparse.ArgumentParser) -> None:
    """--force (replace an existing output file that bioflex-jsb did not write), once."""
    if "--force" not in parser._option_string_actions:  # another helper may have added it
        parser.add_argument("--force", action="store_true",
                            help="replace existing output files that bioflex-jsb did not write")


def plot_formats() -> dict[str, str]:
    """File suffixes matplotlib can write (without the dot) and their descriptions."""
    from bioflex_jsb.sinks.plotting import supported_formats

    return supported_formats()


def check_plot_path(path: str | None, force: bool) -> None:
    """Refuse a plot file before any work: a suffix matplotlib cannot write, or an existing
    file that is not a plot of ours (:func:`~bioflex_jsb.sinks.plotting.is_our_plot`) without
    --force. One-line UsageError."""
    if not path:
        return
    suffix = Path(path).suffix.lower().lstrip(".")
    formats = plot_formats()
    if suffix not in formats:
        shown = ", ".join(f".{s}" for s in ("png", "pdf", "svg") if s in formats)
        what = f".{suffix}" if suffix else "a file without a suffix"
        raise UsageError(f"plot file {path!r}: cannot write {what}; "
                         f"give a name ending in {shown} (or any of "
                         f"{', '.join('.' + s for s in sorted(formats))})")
    from bioflex_jsb.sinks.plotting import is_our_plot

    check_output(path, force, "plot file", ours=is_our_plot)
    parent = Path(path).parent
    if not parent.is_dir():
        raise UsageError(f"plot file {path!r}: the directory {str(parent)!r} does not exist")


def check_run_length(duration_s: float, dt_s: float) -> None:
    """--duration and --dt within :data:`MAX_DURATION_S` and :data:`MAX_STEPS`."""
    if duration_s > MAX_DURATION_S:
        raise UsageError(f"--duration {duration_s:g} s is too long; accepted: up to "
                         f"{MAX_DURATION_S:g} s per run (longer records: a sweep of cases)")
    steps = duration_s / dt_s
    if steps > MAX_STEPS:
        raise UsageError(f"--duration {duration_s:g} s at --dt {dt_s:g} s is {steps:.3g} steps; "
                         f"accepted: up to {MAX_STEPS:g} steps per run")
