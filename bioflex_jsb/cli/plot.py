"""``bioflex-jsb plot``: time histories of the runs in an MCAP log."""

from __future__ import annotations

import argparse
import sys

from bioflex_jsb.cli.case import add_force_argument, check_plot_path
from bioflex_jsb.cli.common import UsageError, print_json

HELP = """Draw the time histories logged in FILE.mcap against simulation time [s]. A gust or
compare log (every wing model's run, and the LTI prediction where one was logged):
perturbations of airspeed u [m/s], angle of attack alpha [deg], pitch rate q [deg/s] and
pitch angle theta [deg], load factor n_z [-], the gust w_g [m/s] and the first wing mode
as the tip twist [deg] (or, for a bending mode, the tip deflection [m]) it makes. A sitl or
ardupilot session is drawn as a flight: altitude [m], airspeed [m/s], bank, pitch and
heading [deg], every wing mode, n_z, alpha (and the gust), the track north against east
[m] and the session's events (mode changes, waypoints). Read through the mcap package;
every chunk is checked first, and damage where the figure does not read (the 3-D scene,
the section loads) is said on stderr, the figure drawn from the intact chunks."""


def register(sub) -> None:
    p = sub.add_parser("plot", help="time histories of an MCAP log", description=HELP)
    p.add_argument("file", metavar="FILE.mcap", help="the log")
    p.add_argument("--out", metavar="FILE.png", default=None,
                   help="the figure (.png, .pdf, .svg; default: FILE.png beside the log; an "
                   "existing file is replaced only if bioflex-jsb drew it, else give --force)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from bioflex_jsb.sinks.mcap import LogError, check_chunks, histories

    out = args.out or str(Path(args.file).with_suffix(".png"))
    check_plot_path(out, args.force)  # before reading the log: nothing is overwritten
    # every chunk checked, not only the ones plotted: a figure drawn from a log damaged
    # elsewhere (its scene, its loads) would say nothing of it
    try:
        damage = check_chunks(args.file)["problems"]
    except LogError as exc:
        raise UsageError(str(exc)) from None
    recover = "`bioflex-jsb info FILE --recover FIXED.mcap` copies its intact chunks"
    try:
        runs, meta = histories(args.file)
    except LogError as exc:
        raise UsageError(f"{exc}; {recover}" if damage else str(exc)) from None
    if not runs or all(len(r.time_s) == 0 for r in runs):
        raise UsageError(f"{args.file!r} holds no bioflex run topics to plot")
    title = _title(meta, runs, Path(args.file).name)
    from bioflex_jsb.sinks import plotting

    flight = meta.get("command") in FLIGHT_COMMANDS
    try:
        if flight:  # a session: a flight, not a gust response (no gust onset, no trim)
            from bioflex_jsb.sinks.flight_plot import flight_figure
            from bioflex_jsb.sinks.mcap import summarise

            flight_figure(runs, out, title, summarise(args.file)["events"])
        else:
            plotting.time_histories(runs, out, title)
    except OSError as exc:
        raise UsageError(f"cannot write plot {out!r}: {exc.strerror}") from None
    if damage:  # the figure is of intact chunks (each read is checked); the rest is not
        print(f"bioflex-jsb plot: warning: {args.file!r} is damaged where the figure does "
              f"not read ({'; '.join(damage[:2])}); {recover}", file=sys.stderr)
    if args.json:
        print_json({"file": args.file, "plot": out, "damaged": damage,
                    "figure": "flight" if flight else "gust",
                    "runs": [{"model": r.model, "label": str(r.meta.get("label", r.model)),
                              "samples": len(r.time_s)} for r in runs]})
    else:
        what = "the flight" if flight else f"time histories of {len(runs)} run(s)"
        print(f"{what} written to {out}")
    return 0


FLIGHT_COMMANDS = ("sitl", "ardupilot")  # logs drawn as a flight (sinks/flight_plot.py)


def _title(meta: dict, runs, file_name: str) -> str:
    """The figure's title from the run description; the gust as flown: a SITL or ArduPilot
    session is described with gust ``none`` and may be given one in flight, so its title
    says when the logged gust ``w_g`` [m/s] first acted and how strong it was."""
    if not meta:
        return file_name
    import numpy as np

    head = f"{meta.get('wing', '?')} wing, {meta.get('speed_m_s', '?')} m/s"
    gust = str(meta.get("gust", "?"))
    if meta.get("command") in ("sitl", "ardupilot"):
        head = f"{meta.get('wing', '?')} wing, {meta['command']} session"
        flown = [r for r in runs if "w_g" in r.channels and len(r.time_s)
                 and np.any(r["w_g"] != 0.0)]
        if flown:
            r = flown[0]
            first = int(np.flatnonzero(r["w_g"] != 0.0)[0])
            peak = float(np.max(np.abs(r["w_g"])))
            return (f"{head}, gust from t = {float(r.time_s[first]):.1f} s "
                    f"(|w_g| up to {peak:.2f} m/s)")
        return f"{head}, still air"
    return f"{head}, gust {gust}"
