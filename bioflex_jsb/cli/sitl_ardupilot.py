"""``bioflex-jsb ardupilot``: the co-simulation as ArduPlane's JSON SITL physics backend."""

from __future__ import annotations

import argparse
import json
import sys
import time

from bioflex_jsb.cli.common import (
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    finite_float,
    log_path,
    positive_float,
    print_json,
    wing_from_args,
)

HELP = """Be ArduPilot's physics: answer ArduPlane SITL started with --model JSON:127.0.0.1
(UDP 9002 + 10 x --instance) lock-step, one co-simulation step per ArduPilot frame, with the
JSBSim airframe and the elastic wing (--model rigid, coupled, qsd or native). The aircraft
starts at rest on a launcher; ArduPlane armed in AUTO at a NAV_TAKEOFF (throttle above
1020 us for 0.5 s) fires it (--launch-accel m/s^2 up to the trim speed --speed); a run that
leaves the valid range is put back on the launcher, not ended. Servo map, frames and the
parameter file: docs/ardupilot.md, bioflex_jsb/drivers/ardupilot.py,
bioflex_jsb/data/ardupilot/bioflex_plane.parm. --gust starts --gust-at seconds after the
launch. Runs until Ctrl-C/SIGTERM or --duration simulated seconds, then prints a JSON
summary (frames, resends, resets, stops, the gust's eta1 peak). Every frame is logged to
the MCAP log as for any run (--out, --no-log; docs/logging.md): ArduPilot's frame count,
rate and servo PWM, the mapped controls, the lock-step action and the launcher phase on
/bioflex/<model>/autopilot, and every coupled step in flight on the run topics.
--table FILE.npz also keeps every --record-every-th frame (servos 1-4, ArduPilot's frame
count, the step's channels) as a numpy table. Never expose ArduPlane's TCP ports: run both inside a
loopback-only network namespace (scripts/ardupilot_sitl.py fly)."""

NATIVE = "native"


def register(sub) -> None:
    p = sub.add_parser("ardupilot", help="ArduPlane SITL physics backend (JSON, lock-step)",
                       description=HELP)
    add_wing_arguments(p, default="optimised")
    p.add_argument("--model", choices=("coupled", "rigid", "qsd", NATIVE), default="coupled",
                   help="wing model (default coupled; native: the exported JSBSim wing)")
    p.add_argument("--speed", type=positive_float("speed", "m/s"), default=15.0,
                   help="trim and launcher exit airspeed [m/s] (default 15)")
    p.add_argument("--altitude", type=finite_float("altitude", "m"), default=0.0,
                   help="launch altitude [m above sea level, ISA] (default 0)")
    p.add_argument("--launch-accel", type=positive_float("launch acceleration", "m/s^2"),
                   default=40.0, help="launcher push [m/s^2] (default 40, 5..200)")
    p.add_argument("--launch-height", type=positive_float("launcher height", "m"),
                   default=2.0, help="launcher above the ground [m] (default 2, 0.5..100)")
    p.add_argument("--gust", default="none", metavar="SPEC",
                   help="gust: 1cos:AMP_m_s:LENGTH_m, sharp:AMP, dryden:SIGMA:SCALE[:SEED], "
                   "vonkarman:..., none (default none)")
    p.add_argument("--gust-at", type=finite_float("gust start", "s"), default=60.0,
                   help="gust start [s after the launch] (default 60)")
    p.add_argument("--instance", type=int, default=0,
                   help="ArduPilot SITL instance (-I): UDP port 9002 + 10 x N (default 0)")
    p.add_argument("--port", type=int, default=None,
                   help="UDP port to listen on instead (0: any free port)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=None,
                   help="stop after this much physics time [s] (default: until Ctrl-C)")
    p.add_argument("--table", metavar="FILE.npz", default=None,
                   help="write the recorded frames to this .npz (names, units, table)")
    p.add_argument("--record-every", type=int, default=8,
                   help="record every N-th frame in --table (default 8: 120 Hz)")
    p.add_argument("--summary", metavar="FILE.json", default=None,
                   help="also write the summary to this file")
    add_log_arguments(p)
    p.set_defaults(run=run)


def _build(args: argparse.Namespace):
    """The physics, and the wing's variant and coefficient overrides for the log (dicts)."""
    from bioflex_jsb.drivers.ardupilot import ArduPilotPhysics, Launcher
    from bioflex_jsb.runtime.fdm import Airframe, FdmError
    from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust

    try:
        gust = parse_gust(args.gust)
    except GustSpecError as exc:
        raise UsageError(str(exc)) from None
    if args.gust_at < 0.0:
        raise UsageError(f"--gust-at must be >= 0 s, got {args.gust_at:g}")
    if args.record_every < 0:
        raise UsageError(f"--record-every must be >= 0, got {args.record_every}")
    if args.table is not None and not args.table.endswith(".npz"):
        raise UsageError(f"--table must name a .npz file, got {args.table!r}")
    try:
        launcher = Launcher(args.launch_accel, args.launch_height)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if args.model == NATIVE:
        from bioflex_jsb.flight_dynamics.wing_model import VARIANTS
        from bioflex_jsb.generators import native_wing as J

        if args.wing not in VARIANTS:
            raise UsageError(f"--model native needs a named wing ({', '.join(VARIANTS)}), "
                             f"got {args.wing!r}")
        aircraft, wing = J.aircraft_name(args.wing), None
        variant, overrides = VARIANTS[args.wing].as_dict(), {}
    else:
        build = wing_from_args(args)
        aircraft, wing = None, build.model
        variant = build.variant.as_dict()
        overrides = dict(build.model.coefficients.overrides)
    try:
        airframe = Airframe() if aircraft is None else Airframe(aircraft=aircraft)
        physics = ArduPilotPhysics(airframe, wing, args.model, speed_m_s=args.speed,
                                   altitude_m=args.altitude, gust=gust, gust_at_s=args.gust_at,
                                   launcher=launcher, record_every=args.record_every)
    except FdmError as exc:  # the airframe cannot load or trim (InputErrors reach the CLI)
        raise UsageError(str(exc)) from None
    return physics, variant, overrides


def _open_log(args: argparse.Namespace, physics, variant: dict, overrides: dict, port: int):
    """The session's MCAP log (None with --no-log); a one-line UsageError if it cannot be
    written."""
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import LogWriteError, RunLog

    args.out = log_path(args, "ardupilot", args.wing)
    if not args.out:
        return None
    # a session follows ArduPlane: the description says how it began (rerun refuses it)
    description = RunDescription(
        kind="ardupilot", wing=args.wing, speed_m_s=args.speed, gust=args.gust,
        models=(args.model,), gust_start_s=args.gust_at, altitude_m=args.altitude,
        dt_s=physics.dt_s, mass_basis=args.mass_basis,
        **({} if args.duration is None else {"duration_s": args.duration}),
        extra={"autopilot": "ardupilot", "until_stopped": args.duration is None,
               "gust_start": "s after the launch", "udp_port": port,
               "instance": args.instance, "launch_accel_m_s2": physics.launch_accel_m_s2,
               "launch_height_m": physics.launcher.height_m,
               "record_every": args.record_every})
    try:
        return RunLog.open(args.out, description, wing_variant=variant, overrides=overrides)
    except LogWriteError as exc:
        raise UsageError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.links.ardupilot_json import LockstepServer

    physics, variant, overrides = _build(args)
    try:
        server = LockstepServer(physics, port=args.port, instance=args.instance,
                                on_frame=physics.on_frame)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    host, port = server.address
    log = None
    opened = False
    try:
        log = _open_log(args, physics, variant, overrides, port)
        opened = True
    finally:
        if not opened:  # a log that cannot be created: the port is given back
            server.close()
    if log is not None:
        physics.log_to(log)
    print(f"bioflex-jsb ardupilot: physics on UDP {host}:{port} ({args.model} wing "
          f"{args.wing}, step {physics.dt_s:.6g} s); "
          f"{'log ' + args.out if args.out else 'no log'}; waiting for ArduPilot; Ctrl-C stops",
          file=sys.stderr, flush=True)
    wall0 = time.monotonic()
    first_frame_wall = None
    interrupted = False
    try:
        while args.duration is None or physics.t_s < args.duration:
            if server.serve_once(0.5) and first_frame_wall is None and server.stats.steps:
                first_frame_wall = time.monotonic()
    except KeyboardInterrupt:
        interrupted = True
    finally:
        server.close()
        if log is not None:
            log.close()
    wall_s = time.monotonic() - (first_frame_wall or wall0)
    st = server.stats
    summary = physics.summary()
    summary.update(
        frames={"steps": st.steps, "resends": st.resends, "resets": st.resets,
                "skipped": st.frames_skipped, "rejected": st.rejected,
                "last_frame_count": server.last_frame_count},
        wall_s=wall_s,
        real_time_factor=physics.t_s / wall_s if wall_s > 0 and physics.t_s > 0 else None,
        table=args.table, out=args.out, interrupted=interrupted)
    if args.table is not None:
        _write_table(args.table, physics)
    print_json(summary)
    if args.summary is not None:
        try:
            with open(args.summary, "w") as fh:
                json.dump(summary, fh, indent=1, allow_nan=False)
        except OSError as exc:
            raise UsageError(f"cannot write --summary {args.summary!r}: {exc.strerror}") from None
    return 130 if interrupted else 0


def _write_table(path: str, physics) -> None:
    import numpy as np

    from bioflex_jsb.drivers.ardupilot import ACTIONS, PHASES

    names = physics.record_names
    units = ("s", "count", "index:" + ",".join(ACTIONS), "index:" + ",".join(PHASES),
             "us", "us", "us", "us", "m/s") + tuple(physics.core.units.values())
    try:
        np.savez_compressed(path, names=np.array(names), units=np.array(units),
                            table=physics.table())
    except OSError as exc:
        raise UsageError(f"cannot write --table {path!r}: {exc.strerror}") from None
