"""``bioflex-jsb sitl``: the co-simulation in real time, as a MAVLink vehicle."""

from __future__ import annotations

import argparse
import sys

from bioflex_jsb.cli.case import airspeed, speed_help
from bioflex_jsb.cli.common import (
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    log_path,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.live_option import add_live_arguments, live_opener, start_live, stop_live
from bioflex_jsb.cli.preflight import add_allow_unstable, checked

AERO_CHOICES = ("quasi-steady", "unsteady")

# The log is written in small chunks when the loop has time for them (a chunk of 0.5 s, 480
# steps, takes ≈ 10 ms to format and compress and would make the steps after it late):
# drivers.sitl.log_flush_due says when.
# MAV_SEVERITY (0 EMERGENCY … 7 DEBUG) → the foxglove.Log level of the event in the log
# (crashes, CRITICAL, and divergences, ERROR, are both ERROR: the session goes on)
EVENT_LEVEL = {0: "FATAL", 1: "FATAL", 2: "ERROR", 3: "ERROR", 4: "WARNING", 5: "INFO",
               6: "INFO", 7: "DEBUG"}
EVENT_NAME = "vehicle"  # the events' reporter (foxglove.Log name)
LOG_MAX_MB_MIN = 0.1  # the smallest --log-max-mb: a file's fixed part (≈ 20 kB) and a chunk
# The largest --log-max-mb: a file info, plot and rerun still read (sinks/mcap_io/errors.py
# MAX_LOG_BYTES, 64 GiB).
LOG_MAX_MB_MAX = 65_536.0
# What a session writes [MB per second of simulated time]: 11.92 MB for 30 s of the default
# session (sitl --duration 30, optimised wing, 28 800 steps: 414 bytes a step at 960 steps/s;
# tests/test_sitl_log.py holds the bytes per step), so ≈ 1.4 GB an hour at --speedup 1.
LOG_MB_PER_SIMULATED_S = 0.40

HELP = """Fly the JSBSim airframe with the elastic wing paced to the wall clock (--speedup N:
N simulated seconds per second) and stream it as a MAVLink 2 vehicle (system 1, component 1,
fixed wing, ArduPlane modes) to a ground station: QGroundControl, MAVProxy, MAVSDK. It
starts 100 m above home (--home, default the CMAC field near Canberra) in CRUISE; ground
stations set modes (MANUAL, STABILIZE, CRUISE, LOITER, AUTO, RTL, GUIDED), fly missions and
change parameters (AP_*, WP_RADIUS_M, LOIT_RAD_M, RTL_ALT_M, AIRSPEED_MS, GUST_*,
WING_COUPLED, SIM_SPEEDUP); docs/sitl.md. A crash or divergence is reported and the aircraft
is reset to trim over home; the session goes on. Sticks (MANUAL_CONTROL, RC_CHANNELS_OVERRIDE)
steer in MANUAL, STABILIZE and FBWA; sticks older than 1 s of simulated time (not wall time:
a paused or slowed session keeps them) mean "Manual control lost" and RTL. --mavlink:
udpout:HOST:PORT (send to a listening ground station; default udpout:127.0.0.1:14550),
udpin:HOST:PORT or tcpin:HOST:PORT (listen); without HOST, 127.0.0.1. Runs --duration
simulated seconds, or until Ctrl-C (the log grows ≈ 0.4 MB per simulated second, ≈ 1.4 GB
an hour at --speedup 1 and N times that at --speedup N: --log-max-total-mb bounds what a
session keeps). Prints the pacing error (step start minus its wall-clock
due time: p50, p99 [ms]). The vehicle's MAVLink clock (time_boot_ms) is the simulated time
since the start, the time axis of the MCAP log that every session writes (--out, --no-log).
--signing-key FILE turns on MAVLink 2 signing: FILE holds the 32-byte secret as 64
hexadecimal digits (to share it with MAVProxy's "signing key P", the SHA-256 of the
passphrase P: python -c "import hashlib; print(hashlib.sha256(b'P').hexdigest())"); the
vehicle then signs all it sends and ignores unsigned or wrongly signed messages
(except RADIO_STATUS). --aero unsteady flies the coupled wing with unsteady strips (Jones lag
states, apparent mass, Kuessner gust) on the compiled step: the backward-axis wings,
unstable with quasi-steady strips at their cruise, fly that way. Before the session the
chosen model's stability at the trim speed is checked (eigenvalues of the linear model, the
phugoid left out, as the ardupilot command does): an unstable one is refused (exit 2, one
line) unless --allow-unstable. --aircraft flies another JSBSim aircraft: a glider (no engine)
holds its speed with pitch and glides down; a powered one (e.g. c172_elastic, JSBSim's
c172p) flies its own autopilot laws (altitude and pitch, bank and heading, sideslip to the
rudder, a PI autothrottle) with gains scaled from its rigid short period and the control
power and thrust its JSBSim model gives at the trim (docs/sitl.md, "A powered aircraft").
Speeds: --speed and the airspeed targets (AIRSPEED_MS, DO_CHANGE_SPEED) within the
aircraft's flight speeds: the prototype 12..22 m/s, a definition its
airframe.speed_range_m_s (c172_elastic 31.1..68.9 m/s, cruise 57.8 m/s). --controller FILE
adds a controller in the loop to the autopilot: its elevator over the trim is added to the
autopilot's (through the pitch trim), its throttle to the lever the autothrottle adds to; its
commands and signals are logged (/bioflex/<model>/controller; docs/sitl.md)."""


def register(sub) -> None:
    p = sub.add_parser("sitl", help="real-time MAVLink vehicle (QGC, MAVProxy, MAVSDK)",
                       description=HELP)
    add_wing_arguments(p, default="optimised")
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    p.add_argument("--speed", type=airspeed, default=cruise_speed_default(),
                   help="trim " + speed_help(extra="; with --aircraft: its cruise_speed_m_s, "
                   "within its speed_range_m_s"))
    p.add_argument("--trim", choices=("rigid", "elastic"), default="rigid",
                   help="the trim the session starts from (and resets to): rigid (the paper's "
                   "reading, default) or elastic (the static aeroelastic equilibrium: the "
                   "wing's static deflection and its loads carried by the trim; `bioflex-jsb "
                   "trim --wing W` shows it)")
    p.add_argument("--model", choices=("coupled", "rigid"), default="coupled",
                   help="elastic wing coupled (default) or rigid; parameter WING_COUPLED")
    p.add_argument("--aero", choices=AERO_CHOICES, default="quasi-steady",
                   help="the coupled wing's strips: quasi-steady (the paper's, default) or "
                   "unsteady (Jones lag states, apparent mass, Kuessner gust; --model "
                   "coupled, --trim rigid); both on the compiled step")
    p.add_argument("--span", choices=("half", "full"), default="half",
                   help="half (the half wing's symmetric modes, default) or full (both "
                   "halves: the antisymmetric modes driven by the roll rate and the ailerons "
                   "the autopilot flies in its turns, their rolling moment to JSBSim; on "
                   "--aero's strips; docs/lateral.md)")
    from bioflex_jsb.cli.lateral_options import add_lateral_aero_argument

    add_lateral_aero_argument(p, "; with --span full")
    add_allow_unstable(p)
    from bioflex_jsb.cli.gust import add_controller_argument

    add_controller_argument(p)
    p.add_argument("--mavlink", default="udpout:127.0.0.1:14550", metavar="ENDPOINT",
                   help="udpout:HOST:PORT, udpin:HOST:PORT or tcpin:HOST:PORT "
                   "(default udpout:127.0.0.1:14550)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=None,
                   help="simulated time [s], > 0 (default: until Ctrl-C)")
    p.add_argument("--speedup", type=positive_float("speed-up", "x"), default=1.0,
                   help="simulated seconds per wall-clock second (default 1, 0.1..50)")
    p.add_argument("--home", metavar="LAT,LON,ALT", default=None,
                   help="home on the ground: latitude, longitude [deg], ground altitude "
                   "[m AMSL] (default -35.363261,149.165230,584: the CMAC field ArduPilot's "
                   "SITL uses)")
    p.add_argument("--start-height", type=positive_float("start height", "m"), default=100.0,
                   help="start (and reset) height above home [m], 20 to 3000 (default 100)")
    p.add_argument("--log-max-mb", type=positive_float("log size", "MB"), default=256.0,
                   help="start a new log file (NAME-001.mcap, ...) when one reaches this size "
                   f"[MB], {LOG_MAX_MB_MIN:g}..{LOG_MAX_MB_MAX:g} (default 256); each file is "
                   "a finished MCAP")
    p.add_argument("--log-max-total-mb", type=positive_float("log total", "MB"), default=None,
                   help="keep at most this much of the session's log on disk [MB], at least "
                   "--log-max-mb: when a new file starts, the session's oldest files are "
                   "removed until the kept ones and the new file's limit fit (the summary "
                   "lists them; default: keep every file, ≈ 1.4 GB an hour at --speedup 1)")
    p.add_argument("--signing-key", metavar="FILE",
                   help="MAVLink 2 signing key file: 64 hex digits (32 bytes); sign what is "
                   "sent, accept only signed messages")
    add_log_arguments(p)
    add_live_arguments(p)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.drivers.sitl import (
        DEFAULT_HOME,
        PacingStats,
        SitlParameters,
        SitlSim,
        run_paced,
    )
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.links.mavlink import LinkError, MavlinkLink
    from bioflex_jsb.runtime.fdm import FdmError

    endpoint, key = _check_session_options(args)
    from bioflex_jsb.cli.aircraft_option import resolve_flight

    resolve_flight(args)  # --speed of the aircraft (its cruise speed by default)
    args.speed = float(args.speed)
    home = _parse_home(args.home, DEFAULT_HOME)
    if args.aero == "unsteady" and (args.model != "coupled" or args.trim != "rigid"):
        raise UsageError(f"--aero unsteady is for --model coupled from --trim rigid, not "
                         f"--model {args.model} --trim {args.trim} (its lag states are "
                         "linearised about the rigid trim; the rigid wing is quasi-steady)")
    build = wing_from_args(args)
    from bioflex_jsb.cli.gust import controller_from_args

    controller = controller_from_args(args)  # a bad file: one line before the trim
    if "aileron" in getattr(controller, "outputs", ()):
        raise UsageError("--controller commands the aileron, which the SITL aircraft's "
                         "autopilot writes itself (fcs/aileron-cmd-norm); accepted over it: "
                         "elevator, throttle")
    from bioflex_jsb.cli.lateral_options import span_options

    check = checked(args, build, UsageError)  # the pre-flight check (cli/preflight.py)
    try:
        airframe, speeds = _airframe(args, home[2] + args.start_height)
        sim = SitlSim(build, build.modes, model=args.model, speed_m_s=args.speed,
                      home=home, start_height_m=args.start_height, speedup=args.speedup,
                      trim_mode=args.trim, aero=args.aero, airframe=airframe,
                      controller=controller,
                      **({} if speeds is None else {"airspeed_range_m_s": speeds}),
                      **span_options(args, build, home[2] + args.start_height))
    except (FdmError, InputError) as exc:  # it cannot be trimmed, a control moves nothing,
        raise UsageError(str(exc)) from None  # a home out of range
    from bioflex_jsb.cli.lateral_options import print_pending_notes

    print_pending_notes(args)  # the reversal note, the session set up
    try:
        link = MavlinkLink(endpoint, SitlParameters(sim), sim.vehicle, signing_key=key)
    except LinkError as exc:
        raise UsageError(str(exc)) from None
    try:
        log = _session_log(args, build, sim, home, endpoint, key, check, airframe)
    except UsageError:
        link.close()
        raise
    on_sample, idle = (None, None) if log is None else (log.attach(sim), log.idle)
    host, port = link.local_address
    if not args.json:
        print(f"bioflex-jsb sitl: MAVLink 2 on {endpoint.text()} (local {host}:{port}"
              f"{', signed' if key else ''}), {args.speedup:g}x real time, {args.aero} "
              f"{args.model} wing{'; a glider: speed held with pitch' if sim.glider else ''}"
              "; Ctrl-C stops", file=sys.stderr)
    if not check["stable"]:
        print(f"bioflex-jsb sitl: warning: flying a model unstable at the trim speed "
              f"(--allow-unstable): largest growth {check['max_growth_1_s']:+.3g} 1/s",
              file=sys.stderr)
    interrupted = False
    stats = PacingStats()  # filled as the session flies: Ctrl-C, its usual end, keeps it
    try:
        run_paced(sim, args.duration, link, on_sample, idle=idle, stats=stats)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        link.close()
        if log is not None:
            log.close()
        stop_live(args)
    _report(args, _summary(args, sim, log, check, stats, link), sim, log)
    if interrupted:
        print("bioflex-jsb sitl: interrupted" + (f"; the log {args.out} holds every step flown"
                                                if args.out else ""), file=sys.stderr)
        return 130
    return 0


def _check_session_options(args: argparse.Namespace):
    """--speedup and the log's size bounds in range; the MAVLink endpoint and the signing
    key read: (endpoint, key or None); one line otherwise."""
    from bioflex_jsb.drivers.sitl import SPEEDUP_RANGE
    from bioflex_jsb.links.mavlink import LinkError, parse_endpoint, read_signing_key

    lo, hi = SPEEDUP_RANGE
    if not lo <= args.speedup <= hi:
        raise UsageError(f"--speedup {args.speedup:g} is outside {lo:g}..{hi:g}")
    if args.log_max_mb < LOG_MAX_MB_MIN:
        raise UsageError(f"--log-max-mb {args.log_max_mb:g} is below {LOG_MAX_MB_MIN:g} MB "
                         "(a file holds its header, one chunk and its summary)")
    if args.log_max_mb > LOG_MAX_MB_MAX:
        raise UsageError(f"--log-max-mb {args.log_max_mb:g} is above {LOG_MAX_MB_MAX:g} MB "
                         "(the largest log info, plot and rerun read)")
    if args.log_max_total_mb is not None and args.log_max_total_mb < args.log_max_mb:
        raise UsageError(f"--log-max-total-mb {args.log_max_total_mb:g} is below --log-max-mb "
                         f"{args.log_max_mb:g}: the file being written must fit")
    try:
        endpoint = parse_endpoint(args.mavlink)
        key = None if args.signing_key is None else read_signing_key(args.signing_key)
    except LinkError as exc:
        raise UsageError(str(exc)) from None
    return endpoint, key


def _session_log(args, build, sim, home, endpoint, key, check, airframe):
    """The session's split log (None with --no-log): its description says how the session
    began (a session follows its ground station); the live view started first, so that its
    refusal leaves no file."""
    start_live(args, "sitl")
    args.out = log_path(args, "sitl", args.wing)
    if not args.out:
        return None
    from bioflex_jsb.cli.gust import open_log
    from bioflex_jsb.cli.lateral_options import lateral_aero_extra
    from bioflex_jsb.simulation.run import RunDescription

    description = RunDescription(
        kind="sitl", wing=args.wing, speed_m_s=args.speed, gust="none",
        models=(args.model,), mass_basis=args.mass_basis,
        altitude_m=home[2] + args.start_height,  # where it starts, above sea level
        **({} if args.duration is None else {"duration_s": args.duration}),
        extra={"until_stopped": args.duration is None, "speedup": args.speedup,
               "home": list(home), "start_height_m": args.start_height,
               "mavlink": endpoint.text(), "signed": key is not None,
               "trim": args.trim, "aero": args.aero,
               "preflight_stable": check["stable"], "glider": sim.glider,
               **_controller_extra(args), **lateral_aero_extra(args),
               # both halves: which step flies them
               **({"span": "full", "step": "compiled kernel" if sim.core.compiled
                   else "python"} if args.span == "full" else {}),
               **({"aircraft": _aircraft_source(args)} if airframe is not None else {})})
    return SplitLog(args.out, description, build, args.log_max_mb,
                    live_opener(args, open_log), replace=args.force,
                    max_total_mb=args.log_max_total_mb)


def _controller_extra(args) -> dict:
    """The run description's ``controller`` (a file by its absolute path), or nothing."""
    import os

    c = getattr(args, "controller", None)
    if c is None:
        return {}
    return {"controller": os.path.abspath(c) if os.path.isfile(c) else c}


def _summary(args, sim, log, check, stats, link) -> dict:
    """The session's summary (``--json``): resets, crashes, the files, pacing, the link."""
    return {
        "resets": sim.resets,
        "crashes": sim.crashes,
        "landings": sim.landings,
        "last_reset": sim.last_reset,
        "refusals": sim.vehicle.refusals,
        "log_files": log.paths if log is not None else [],
        "log_files_removed": log.removed if log is not None else [],
        "simulated_s": sim.t_s,
        "steps": sim.k,
        "aero": args.aero,
        "controller": sim.controller_meta,
        "preflight": check,
        "pacing": stats.summary() if stats.steps else None,
        "link": {"received": link.stats.received, "bad": link.stats.bad,
                 "rejected_signature": link.stats.rejected_signature,
                 "sent": link.stats.sent, "datagrams": link.stats.datagrams,
                 "signing": link.signing},
        "out": args.out,
    }


def _report(args, summary: dict, sim, log) -> None:
    """The summary as JSON, or its lines: time flown, pacing, resets, the files written."""
    if args.json:
        print_json(summary)
        return
    pacing = summary["pacing"]
    line = f"flew {sim.t_s:.2f} s simulated"
    if pacing:
        line += (f"; pacing error p50 {pacing['p50_ms']:.3f} ms, p99 {pacing['p99_ms']:.3f}"
                 f" ms, {pacing['resyncs']} resyncs")
    print(line)
    if sim.resets:
        print(f"{sim.resets} resets (last: {sim.last_reset})")
    if args.out:
        print(f"log written to {', '.join(log.paths)}" + (
            f" ({len(log.removed)} older files removed: --log-max-total-mb "
            f"{args.log_max_total_mb:g})" if log.removed else ""))


def _airframe(args: argparse.Namespace, start_altitude_m: float):
    """(the JSBSim airframe, the accepted speed targets [m/s]) of ``--aircraft`` when it
    is another JSBSim aircraft than the prototype's: an aircraft without an engine with the
    glider's autopilot (drivers/sitl.py glider_airframe), one with engines with the powered
    aircraft's autopilot, its gains scaled for it at --speed and ``start_altitude_m`` [m]
    (drivers/sitl.py powered_airframe); its speeds: its definition's flight speeds.
    (None, None): the prototype's SITL aircraft."""
    from bioflex_jsb.definition.flying import flight_speeds
    from bioflex_jsb.drivers.sitl import sitl_airframe

    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is None or aircraft.flight_problem() is None:
        return None, None
    airframe, _gains = sitl_airframe(aircraft, args.speed, start_altitude_m)
    return airframe, tuple(flight_speeds(aircraft)[1])


def _aircraft_source(args: argparse.Namespace) -> str:
    aircraft = args.aircraft_definition
    return aircraft.source


def _parse_home(text: str | None, default: tuple[float, float, float]):
    if text is None:
        return default
    parts = text.split(",")
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        raise UsageError(f"--home {text!r}: expected LAT,LON,ALT (three numbers)") from None
    if len(values) != 3:
        raise UsageError(f"--home {text!r}: expected LAT,LON,ALT (three numbers)")
    return values


class SplitLog:
    """The session's MCAP log in files of at most ``max_mb`` [MB] (NAME.mcap, NAME-001.mcap,
    ...), each closed (finished) before the next opens; a reset also starts a new file, whose
    run description records the reason (``extra.after_reset``). Chunks are written when the
    loop has slack (``idle``).

    The size limit holds whether or not the loop has slack: before each step the file's
    size if it were closed after that step is bounded from above (:meth:`RunLog.size_bound`:
    what is written, the chunk in progress and the step uncompressed, their indexes, the
    summary); when the bound passes ``max_mb`` the chunk in progress is written (its size
    then exact) and, if the bound still passes it, the file is closed first. A file
    therefore never exceeds the limit and ends below it by at most about one step and one
    chunk's overhead, a few kB (docs/sitl.md gives the measured figures); near the limit a
    few small chunks are written (the gap halves at each, ≈ log2(gap / step) of them). A file
    holds at least one step.

    Every STATUSTEXT of the vehicle (``status``, its ``on_status`` hook) is an event
    (``RunLog.event``, level :data:`EVENT_LEVEL`) at its simulated time, written after the
    sample of the step it happened in (so a crash follows the last step flown); a reset
    (``reset``, called within that step after the vehicle's "Reset to trim" STATUSTEXT)
    starts the new file after that sample and the step's events: the reset's event is the
    last record of the file that ends and the first of the new one.

    With ``max_total_mb`` the files kept on disk stay within it: when a new file starts,
    the session's oldest finished files are removed (listed in ``removed``; ``paths`` keeps
    the rest) until their sizes and the new file's limit ``max_mb`` fit in it."""

    def __init__(self, path: str, description, build, max_mb: float, open_log,
                 replace: bool = False, max_total_mb: float | None = None) -> None:
        import dataclasses
        from pathlib import Path

        self._base = Path(path)
        self._replace_files = replace  # --force: a later file may replace an existing one
        self._description, self._build, self._open = description, build, open_log
        self._replace = dataclasses.replace
        self.max_bytes = int(max_mb * 1e6)
        self.max_total_bytes = None if max_total_mb is None else int(max_total_mb * 1e6)
        self.paths: list[str] = []
        self.removed: list[str] = []  # the oldest files, removed to keep max_total_mb
        self._files = 0  # files opened (the next one's number)
        self._pending = 0
        self._steps = 0  # steps in the file being written
        self._events: list[tuple[float, int, str]] = []  # (t_s, MAV_SEVERITY, text)
        self._reset: tuple[str, tuple[float, int, str] | None] | None = None
        self._controller: dict | None = None  # the controller in the loop's (attach)
        self._log = self._next(None)

    def _next(self, reason: str | None):
        n = self._files
        removed = self._keep_within_total()
        path = self._base if n == 0 else self._free_name(n)
        d = self._description
        if n:
            extra = dict(d.extra, segment=n, **({"after_reset": reason} if reason else {}),
                         **({"removed_before": removed} if removed else {}))
            d = self._replace(d, extra=extra)
        log = self._open(str(path), d, self._build)
        if self._controller is not None:
            log.log_controller(self._controller)
        self.paths.append(str(path))
        self._files += 1
        return log

    def _keep_within_total(self) -> list[str]:
        """Remove the oldest finished files until they and a new file of ``max_bytes`` fit
        in ``max_total_bytes``; returns their names (the new file's run description lists
        them, ``extra.removed_before``; the first removal is said on stderr)."""
        import os

        if self.max_total_bytes is None:
            return []
        before = len(self.removed)
        sizes = []
        for p in self.paths:
            try:
                sizes.append(os.path.getsize(p))
            except OSError:  # removed by someone else: it takes no room
                sizes.append(0)
        while self.paths and sum(sizes) + self.max_bytes > self.max_total_bytes:
            oldest = self.paths.pop(0)
            sizes.pop(0)
            try:
                os.unlink(oldest)
            except FileNotFoundError:
                pass
            self.removed.append(oldest)
        if before == 0 and self.removed:
            print(f"bioflex-jsb sitl: the session's log reached --log-max-total-mb "
                  f"{self.max_total_bytes / 1e6:g}: its oldest files are removed as new ones "
                  "start", file=sys.stderr)
        return [os.path.basename(p) for p in self.removed[before:]]

    def _free_name(self, n: int):
        """The name of the file after ``n`` others: ``<stem>-NNN<suffix>`` with the first
        number from ``n`` whose file does not exist, created here (``O_EXCL``: a user's
        file of that name is never replaced, without ``--force``, nor one another process
        made meanwhile); with ``--force`` the ``n``-th name, replaced."""
        import os

        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0)
        for k in range(n, n + 10_000):
            path = self._base.with_name(f"{self._base.stem}-{k:03d}{self._base.suffix}")
            if self._replace_files:
                return path
            try:
                os.close(os.open(path, flags, 0o644))
            except FileExistsError:
                continue
            return path
        raise UsageError(f"no free name for the log after {str(self._base)!r}: 10000 taken")

    def attach(self, sim):
        """Log the session of ``sim``: its resets and its vehicle's STATUSTEXT; returns the
        ``on_sample`` of :func:`~bioflex_jsb.drivers.sitl.run_paced` (``idle``: :meth:`idle`)."""
        sim.on_reset = self.reset
        sim.vehicle.on_status = self.status
        names = sim.names
        self._controller = sim.controller_meta
        if self._controller is not None:
            self._log.log_controller(self._controller)

        def on_sample(t, model, values):
            self.sample(model, t, dict(zip(names, values, strict=True)))

        return on_sample

    def sample(self, model, t, row) -> None:
        if self._steps and self._bound() > self.max_bytes:
            self._log.flush()  # the chunk in progress written: its size is now exact
            self._pending = 0
            if self._bound() > self.max_bytes:
                self._roll(None)  # this step could take the file past max_bytes
        self._log.sample(model, t, row)
        self._steps += 1
        self._pending += 1
        if self._events or self._reset is not None:
            self._write_events()

    def _bound(self) -> int:
        """The file's size bound after this step and the events waiting for it (a
        ``foxglove.Log`` message: its text and < 128 bytes of fields and record)."""
        return self._log.size_bound(1) + sum(128 + 4 * len(e[2]) for e in self._events)

    def status(self, t_s: float, severity: int, text: str) -> None:
        """A STATUSTEXT at ``t_s`` [s]: logged after the sample of the step in progress."""
        self._events.append((t_s, severity, text))

    def _event(self, event: tuple[float, int, str]) -> None:
        t_s, severity, text = event
        self._log.event(t_s, EVENT_LEVEL.get(severity, "UNKNOWN"), text, name=EVENT_NAME)

    def _write_events(self) -> None:
        events, self._events = self._events, []
        for e in events:
            self._event(e)
        if self._reset is not None:
            (reason, last), self._reset = self._reset, None
            self._roll(reason)
            if last is not None:
                self._event(last)

    def idle(self, slack_s: float) -> None:
        from bioflex_jsb.drivers.sitl import log_flush_due

        if log_flush_due(self._pending, slack_s):
            self._log.flush()
            self._pending = 0

    def _roll(self, reason: str | None) -> None:
        self._log.close()
        self._log = self._next(reason)
        self._pending = self._steps = 0

    def reset(self, reason: str) -> None:
        """The aircraft was reset (``reason``): a new file once the step's sample is in."""
        self._reset = (reason, self._events[-1] if self._events else None)

    def close(self) -> None:
        if self._events or self._reset is not None:
            self._write_events()
        self._log.close()
