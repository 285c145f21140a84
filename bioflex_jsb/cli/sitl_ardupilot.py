"""``bioflex-jsb ardupilot``: the co-simulation as ArduPlane's JSON SITL physics backend."""

from __future__ import annotations

import argparse
import gc
import json
import sys
import time

from bioflex_jsb.cli.case import airspeed, check_time_step, speed_help
from bioflex_jsb.cli.common import (
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    check_distinct_outputs,
    check_new_file,
    closing,
    finite_float,
    log_path,
    number_type,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.live_option import (
    add_live_arguments,
    check_live,
    live_opener,
    start_live,
    stop_live,
)
from bioflex_jsb.cli.preflight import NATIVE, add_allow_unstable, checked, preflight
from bioflex_jsb.links.ardupilot_json import PEER_SILENCE_S
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

__all__ = ("preflight", "register", "run", "session_summary")

HELP = """Be ArduPilot's physics: answer ArduPlane SITL started with --model JSON:127.0.0.1
(UDP 9002 + 10 x --instance) lock-step, one co-simulation step per ArduPilot frame, with the
JSBSim airframe and the elastic wing (--model rigid, coupled, qsd or native; --aero unsteady
for the coupled wing's unsteady strips; both run on the compiled step). The session binds to
the first ArduPilot that sends (address and port); packets from any other source are counted
and reported, never answered, until the bound one has been silent for 3 s: then a new
ArduPilot's frame 0, from any address and port, is bound and resets the physics (a restart;
frame 0 again from the same port is one too), and a bound sender that never lock-stepped (a
stray packet that reached the port before ArduPlane) gives way to the next sender without a
reset (docs/ardupilot.md, "Sessions"). The aircraft starts at rest on a launcher. Armed in
AUTO at a NAV_TAKEOFF, ArduPlane keeps the throttle at 0 until the launch, so there the
launch switch fires it: servo 5 (SERVO5_FUNCTION 55, RC 5 passed through) at 1880..1920 us
for 0.5 s; in TAKEOFF mode the idle throttle on servo 3 above 1020 us for 0.5 s fires it too
(--launch-accel m/s^2 up to the trim speed --speed). A run that leaves the valid range is
put back on the launcher once, reported, and stays there until ArduPilot restarts (no
re-launch mid-mission). --gust starts --gust-at seconds after the launch, once per session
(--gust-repeat: after every launch). Before the flight the chosen model's stability at the
trim speed is checked (eigenvalues of the linear model; the phugoid left out): an unstable
wing is refused (exit 2) unless --allow-unstable. Servo map, frames and the parameter file:
docs/ardupilot.md, bioflex_jsb/drivers/ardupilot.py,
bioflex_jsb/data/ardupilot/bioflex_plane.parm. Runs until --duration simulated seconds, or
until ArduPilot has been silent for --end-when-silent seconds (ArduPlane stopped: the way a
script ends a flight), both normal ends (exit 0), or until Ctrl-C/SIGTERM (an interrupt:
exit 130); then prints a summary (--json: JSON; how it ended, frames, resends, restarts,
ignored packets, stops, re-launches, the real-time factor, the gust's eta1 peak). Every
frame is logged to the MCAP log as for any run (--out, --no-log; docs/logging.md):
ArduPilot's frame count, rate and servo PWM, the mapped controls, the lock-step action and
the launcher phase on /bioflex/<model>/autopilot, every coupled step in flight on the run
topics, and the session's events (binding, ignored packets, restarts, launches, stops, the
summary at the end) on /bioflex/events. --aircraft flies another JSBSim aircraft (its
cruise speed by default; its servos mapped by what its own commands do) and --write-parm
FILE.parm writes its ArduPlane parameter file (docs/ardupilot.md, "Another aircraft").
--table FILE.npz also keeps every --record-every-th
frame (servos 1-4, ArduPilot's frame count, the step's channels) as a numpy table. Never
expose ArduPlane's TCP ports: run both inside a loopback-only network namespace
(scripts/ardupilot_sitl.py fly)."""

AERO_CHOICES = ("quasi-steady", "unsteady")
# How a session ended (the summary's "ended"): the first two are normal ends (exit 0)
ENDED_DURATION = "duration"
ENDED_SILENT = "ArduPilot silent"
ENDED_INTERRUPTED = "interrupted"
RTF_DEFINITION = (
    "session_s / connected_wall_s: the physics time advanced (every frame stepped, k steps "
    "of dt_s each at ArduPilot's frame rate, across "
    "ArduPilot restarts) over the wall time while an ArduPilot peer was connected (gaps "
    "between its frames shorter than 3 s; waiting for a peer and a killed ArduPilot's "
    "silence are left out)")


def _span(args: argparse.Namespace, build) -> dict:
    """``span`` and ``aileron`` of ``--span`` (cli/lateral_options.py; {} for the half
    wing); the native wing has no antisymmetric modes of ours."""
    from bioflex_jsb.cli.lateral_options import span_options

    if args.span == "full" and args.model == NATIVE:
        raise UsageError("--span full flies our wing's antisymmetric modes: not with --model "
                         "native")
    if args.lateral_aero == "lattice" and args.model == NATIVE:
        raise UsageError("--lateral-aero lattice loads our wing's antisymmetric modes: not "
                         "with --model native")
    return span_options(args, build)


def register(sub) -> None:
    p = sub.add_parser("ardupilot", help="ArduPlane SITL physics backend (JSON, lock-step)",
                       description=HELP)
    add_wing_arguments(p, default="optimised")
    p.add_argument("--model", choices=("coupled", "rigid", "qsd", NATIVE), default="coupled",
                   help="wing model (default coupled; native: the exported JSBSim wing)")
    p.add_argument("--span", choices=("half", "full"), default="half",
                   help="half (the half wing's symmetric modes, default) or full (both "
                   "halves: the antisymmetric modes driven by the roll rate and the ailerons "
                   "ArduPlane flies, their rolling moment to JSBSim; on --aero's strips; "
                   "docs/lateral.md)")
    from bioflex_jsb.cli.lateral_options import add_lateral_aero_argument

    add_lateral_aero_argument(p, "; with --span full")
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    p.add_argument("--speed", type=airspeed, default=cruise_speed_default(),
                   help="trim and launcher exit " + speed_help(
                       extra="; with --aircraft: its cruise_speed_m_s, within its flight "
                       "speeds"))
    p.add_argument("--write-parm", metavar="FILE.parm", default=None,
                   help="write the ArduPlane parameter file of the aircraft (--aircraft: its "
                   "airspeeds from its flight speeds, trim throttle, rate feed-forwards, L1 "
                   "and TECS from its JSBSim model; else the prototype's "
                   "bioflex_plane.parm) and exit; start ArduPlane with --defaults FILE")
    p.add_argument("--altitude", type=finite_float("altitude", "m"), default=0.0,
                   help="launch altitude [m above sea level, ISA], -500 to 11000 (default 0)")
    p.add_argument("--dt", type=positive_float("time step", "s"), default=DEFAULT_DT_S,
                   help="the co-simulation step [s] (default 1/960): ArduPilot adopts 1/dt as "
                   "its physics rate, and its SITL IMU (registered at 1 kHz) takes one sample "
                   "a frame, so give 0.001 when ArduPilot's gyro spectrum, FFT or notch must "
                   "read true frequencies (docs/ardupilot.md, \"The wing in ArduPlane's "
                   "gyro\")")
    p.add_argument("--launch-accel", type=positive_float("launch acceleration", "m/s^2"),
                   default=40.0, help="launcher push [m/s^2] (default 40, 5..200)")
    p.add_argument("--launch-height", type=positive_float("launcher height", "m"),
                   default=2.0, help="launcher above the ground [m] (default 2, 0.5..100)")
    p.add_argument("--gust", default="none", metavar="SPEC",
                   help="gust: 1cos:AMP_m_s:LENGTH_m, sharp:AMP, dryden:SIGMA:SCALE[:SEED], "
                   "vonkarman:..., none (default none)")
    p.add_argument("--gust-at", type=finite_float("gust start", "s"), default=60.0,
                   help="gust start [s after the launch] (default 60)")
    p.add_argument("--gust-repeat", action="store_true",
                   help="blow the gust after every launch (default: once per session)")
    p.add_argument("--aero", choices=AERO_CHOICES, default="quasi-steady",
                   help="the coupled wing's strips: quasi-steady (the paper's) or unsteady "
                   "(Jones lag states, apparent mass, Kuessner gust); both on the compiled "
                   "step (the summary's 'step' says which ran); default quasi-steady")
    add_allow_unstable(p)
    p.add_argument("--instance", type=int, default=0,
                   help="ArduPilot SITL instance (-I): UDP port 9002 + 10 x N (default 0)")
    p.add_argument("--port", type=int, default=None,
                   help="UDP port to listen on instead (0: any free port)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=None,
                   help="stop after this much session physics time [s], ArduPilot restarts "
                   "included (default: until Ctrl-C)")
    p.add_argument("--end-when-silent", metavar="SECONDS", default=None,
                   type=number_type("--end-when-silent", "s", low=0.5, high=3600.0),
                   help="end the session normally (exit 0, the summary's ended: 'ArduPilot "
                   "silent') once the bound ArduPilot has sent nothing for this long [s of "
                   "wall time], 0.5..3600: stop ArduPlane, and the physics follows. A value "
                   f"under {PEER_SILENCE_S:g} s ends the session where a killed ArduPilot's "
                   "restart would have been bound (default: no such end)")
    p.add_argument("--table", metavar="FILE.npz", default=None,
                   help="write the recorded frames to this .npz (names, units, table)")
    p.add_argument("--record-every", type=int, default=8,
                   help="record every N-th frame in --table (default 8: 120 Hz)")
    p.add_argument("--summary", metavar="FILE.json", default=None,
                   help="also write the summary to this file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    add_log_arguments(p)
    add_live_arguments(p)
    p.set_defaults(run=run)


def _other_aircraft(args: argparse.Namespace):
    """The definition of ``--aircraft`` when it flies another JSBSim aircraft than the
    prototype's generated one, else None."""
    aircraft = getattr(args, "aircraft_definition", None)
    return aircraft if aircraft is not None and aircraft.flight_problem() else None


# An ArduPlane parameter file is a few kB (the shipped one 4 kB); 1 MiB bounds the read.
PARM_MAX_BYTES = 1 << 20


def _write_parm(args: argparse.Namespace) -> int:
    """``--write-parm``: the aircraft's ArduPlane parameter file (the prototype's shipped
    one without another --aircraft), never over a file of the user's without --force."""
    from pathlib import Path

    from bioflex_jsb.drivers.ardupilot import plane_numbers
    from bioflex_jsb.generators.ardupilot_params import render_plane_parm
    from bioflex_jsb.runtime.fdm import FdmError

    check_new_file(args.write_parm, args.force, "--write-parm", (".parm",))
    aircraft = _other_aircraft(args)
    if aircraft is None:
        from bioflex_jsb.files import read_input_text

        shipped = Path(__file__).resolve().parents[1] / "data" / "ardupilot" / "bioflex_plane.parm"
        text = read_input_text(shipped, "the shipped parameter file", PARM_MAX_BYTES, UsageError)
        what = "the prototype's bioflex_plane.parm"
    else:
        try:
            numbers, _power = plane_numbers(aircraft, args.speed, args.altitude)
        except FdmError as exc:
            raise UsageError(str(exc)) from None
        text = render_plane_parm(numbers)
        what = f"the parameters of aircraft {aircraft.name!r}"
    try:
        Path(args.write_parm).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise UsageError(f"cannot write --write-parm {args.write_parm!r}: "
                         f"{exc.strerror}") from None
    if args.json:
        print_json({"parm": args.write_parm, "what": what})
    else:
        print(f"{what} written to {args.write_parm}: arduplane --model JSON:127.0.0.1 "
              f"--defaults {args.write_parm}")
    return 0


def _build(args: argparse.Namespace):
    """The physics, the wing's variant and coefficient overrides for the log (dicts), and
    the pre-flight check (:func:`~bioflex_jsb.cli.preflight.preflight`)."""
    from bioflex_jsb.drivers.ardupilot import ArduPilotPhysics, Launcher
    from bioflex_jsb.runtime.fdm import Airframe, FdmError
    from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust

    try:
        gust = parse_gust(args.gust)
    except GustSpecError as exc:
        raise UsageError(str(exc)) from None
    if gust.spanwise is not None:  # the ArduPilot backend flies the uniform gust
        raise UsageError(f"--gust {gust.text()!r}: the ArduPilot backend flies a vertical gust "
                         f"alone ({gust.vertical().text()!r}); the parts after '+' fly in gust, "
                         "compare and sitl")
    check_time_step(args.dt)
    if args.gust_at < 0.0:
        raise UsageError(f"--gust-at must be >= 0 s, got {args.gust_at:g}")
    if args.record_every < 0:
        raise UsageError(f"--record-every must be >= 0, got {args.record_every}")
    # the session's outputs checked before it starts (a session of hours must not find at
    # its end that a file cannot be written, nor replace a user's file)
    if args.table is not None:
        check_new_file(args.table, args.force, "--table", (".npz",))
    if args.summary is not None:
        check_new_file(args.summary, args.force, "--summary", (".json",))
    check_distinct_outputs(("--out", args.out), ("--table", args.table),
                           ("--summary", args.summary))
    if args.aero == "unsteady" and args.model != "coupled":
        raise UsageError(f"--aero unsteady is for --model coupled, not {args.model} (the "
                         "rigid, qsd and native wings are quasi-steady)")
    try:
        launcher = Launcher(args.launch_accel, args.launch_height)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    if args.model == NATIVE:
        from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
        from bioflex_jsb.generators import native_wing as J

        if args.wing not in VARIANTS:
            raise UsageError(f"--model native needs a named wing ({', '.join(VARIANTS)}), "
                             f"got {args.wing!r}")
        aircraft, wing = J.aircraft_name(args.wing), None
        build = build_wing(VARIANTS[args.wing], mass_basis=args.mass_basis)
        variant, overrides = VARIANTS[args.wing].as_dict(), {}
    else:
        build = wing_from_args(args)
        aircraft, wing = None, build
        variant = build.variant.as_dict()
        overrides = dict(build.model.coefficients.overrides)
    check = checked(args, build, UsageError)  # the pre-flight check (cli/preflight.py)
    # both strip models have a compiled step (CoupledStep(compiled=True); the unsteady one
    # since simulation/unsteady_kernel.py); the summary's "step" says which one flew
    compiled = True
    other = _other_aircraft(args)
    try:
        extra = {}
        if other is not None:  # its own JSBSim aircraft, the servos by what its commands do
            from bioflex_jsb.drivers.ardupilot import aircraft_channels
            from bioflex_jsb.runtime.control_power import measure_control_power
            from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

            probe = airframe_for(other)
            extra["channels"] = aircraft_channels(
                measure_control_power(probe, args.speed, args.altitude))
            del probe
            airframe = airframe_for(other)
        else:
            airframe = Airframe() if aircraft is None else Airframe(aircraft=aircraft)
        physics = ArduPilotPhysics(airframe, wing, args.model, speed_m_s=args.speed,
                                   altitude_m=args.altitude, dt_s=args.dt,
                                   gust=gust, gust_at_s=args.gust_at,
                                   launcher=launcher, record_every=args.record_every,
                                   gust_repeat=args.gust_repeat, aero=args.aero,
                                   compiled=compiled, **extra, **_span(args, build))
    except FdmError as exc:  # the airframe cannot load or trim (InputErrors reach the CLI)
        raise UsageError(str(exc)) from None
    from bioflex_jsb.cli.lateral_options import print_pending_notes

    print_pending_notes(args)  # the reversal note, the physics set up
    return physics, variant, overrides, check


def _open_log(args: argparse.Namespace, physics, variant: dict, overrides: dict, port: int):
    """The session's MCAP log (None with --no-log); a one-line UsageError if it cannot be
    written."""
    from bioflex_jsb.cli.gust import SCENE_EXAGGERATION
    from bioflex_jsb.cli.lateral_options import lateral_aero_extra
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
               "record_every": args.record_every, "aero": args.aero,
               "step": physics.step_kind, "gust_repeat": args.gust_repeat,
               **({"span": "full"} if args.span == "full" else {}),
               **lateral_aero_extra(args),
               "duration": ("until stopped: the flown duration is in the session-end event "
                            "(session_s)") if args.duration is None else "--duration"})
    from bioflex_jsb.flight_dynamics.wing_model import WingBuild

    # the scene draws the wing flown: its build (an aircraft's wing is not rebuilt from its
    # variant); a wing model without one (modal data) the scene rebuilds from the variant
    build = physics.wing_model if isinstance(physics.wing_model, WingBuild) else None
    try:  # the aircraft in 3-D as in every gust, compare and sitl log (docs/logging.md)
        return live_opener(args, RunLog.open)(args.out, description, wing_variant=variant,
                                              overrides=overrides, scene=SCENE_EXAGGERATION,
                                              build=build)
    except LogWriteError as exc:
        raise UsageError(str(exc)) from None


def session_summary(physics, server, wall_s: float) -> dict:
    """The session's summary (JSON-ready): the physics' (:meth:`ArduPilotPhysics.summary`),
    the server's counters and source check, and one real-time factor
    (:data:`RTF_DEFINITION`); ``wall_s`` [s] is the whole session's wall time, waiting
    included (for information)."""
    st = server.stats
    summary = physics.summary()
    connected = st.connected_wall_s
    summary.update(
        frames={"steps": st.steps, "resends": st.resends, "resets": st.resets,
                "crossed_resends": st.crossed_resends,
                "skipped": st.frames_skipped, "rejected": st.rejected,
                "last_frame_count": server.last_frame_count},
        source_check={
            "peer": None if server.peer is None else f"{server.peer[0]}:{server.peer[1]}",
            "foreign_packets": st.foreign, "stale_packets": st.stale,
            "first_foreign": None if st.first_foreign is None
            else f"{st.first_foreign[0]}:{st.first_foreign[1]}",
            "restarts_new_port": st.rebinds, "strays": st.strays,
            "blocked_sources": st.blocked},
        wall_s=wall_s, connected_wall_s=connected,
        real_time_factor=physics.session_t_s / connected if connected > 0 else None,
        real_time_factor_definition=RTF_DEFINITION)
    return summary


def _text_report(s: dict) -> str:
    rtf = s["real_time_factor"]
    sc = s["source_check"]
    lines = [f"ended: {s['ended']}; flew {s['session_s']:.2f} s of physics "
             f"({s['flown_s']:.2f} s in flight), {s['frames']['steps']} frames, "
             f"{s['restarts']} ArduPilot restarts, "
             f"{s['launches']} launches ({s['relaunches']} re-launches), {s['stop_count']} "
             f"valid-range stops; {s['step']} step, {s['aero']} wing; last "
             f"{s['frame_steps']} step(s) a frame ({s['frame_rate_hz']:.4g} Hz)",
             "real-time factor " + ("n/a" if rtf is None else f"{rtf:.3f}")
             + " (physics time over wall time while ArduPilot was connected)"]
    if sc["foreign_packets"] or sc["stale_packets"]:
        lines.append(f"ignored {sc['foreign_packets']} packets from other sources than "
                     f"{sc['peer']} and {sc['stale_packets']} stale ones")
    for stop in s["stops"]:
        lines.append(f"stop after {stop['flight_s']:.2f} s of flight: {stop['reason']}")
    if s["out"]:
        lines.append(f"log written to {s['out']}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.links.ardupilot_json import LockstepServer

    wall0 = time.monotonic()
    resolve_flight(args)  # --speed of the aircraft (its cruise speed by default)
    args.speed = float(args.speed)
    if args.write_parm is not None:
        return _write_parm(args)
    check_live(args)  # its refusals before the UDP port is taken
    physics, variant, overrides, check = _build(args)
    try:
        server = LockstepServer(physics, port=args.port, instance=args.instance,
                                on_frame=physics.on_frame, on_event=physics.event)
    except ValueError as exc:
        raise UsageError(str(exc)) from None
    host, port = server.address
    log = None
    opened = False
    try:
        start_live(args, "ardupilot")  # before the log file is made: a refusal leaves none
        log = _open_log(args, physics, variant, overrides, port)
        opened = True
    finally:
        if not opened:  # a log that cannot be created: the port is given back
            server.close()
    if log is not None:
        physics.log_to(log)
    physics.on_event = lambda t, level, text: print(
        f"bioflex-jsb ardupilot: {level.lower()}: {text}", file=sys.stderr, flush=True)
    if not check["stable"]:
        physics.event("WARNING", f"flying a model unstable at the trim speed "
                      f"(--allow-unstable): largest growth {check['max_growth_1_s']:+.3g} 1/s")
    print(f"bioflex-jsb ardupilot: physics on UDP {host}:{port} ({args.model} wing "
          f"{args.wing}, {args.aero}, {physics.step_kind} step {physics.dt_s:.6g} s); "
          f"{'log ' + args.out if args.out else 'no log'}; waiting for ArduPilot; Ctrl-C stops",
          file=sys.stderr, flush=True)
    # the start-up's objects (modules, the airframe, the wing build: 67 000 tracked) out of
    # the collector's generations: a full collection in the session then scans only the
    # session's own (measured here at load 5: 78 ms without, 0.003 ms with; one in flight
    # is a stall of the lock step that ArduPlane's sleep debt, floored at -0.1 s, may not
    # make up)
    gc.freeze()
    interrupted = False
    ended = ENDED_DURATION
    try:
        while args.duration is None or physics.session_t_s < args.duration:
            server.serve_once(0.5)
            physics.flush_events()  # the server's events between frames
            silence = server.silence_s()
            if args.end_when_silent is not None and silence is not None \
                    and silence >= args.end_when_silent:
                ended = ENDED_SILENT
                physics.event("INFO", f"ArduPilot silent for {silence:.1f} s "
                              f"(--end-when-silent {args.end_when_silent:g}): session ended")
                break
    except KeyboardInterrupt:
        interrupted = True
        ended = ENDED_INTERRUPTED
    finally:
        with closing():  # a stop signal now waits until the log is finished
            server.close()
            summary = session_summary(physics, server, time.monotonic() - wall0)
            summary.update(preflight=check, table=args.table, out=args.out,
                           ended=ended, interrupted=interrupted)
            if log is not None:
                physics.flush_events()
                log.event(physics.session_t_s, "INFO", "session end: " + json.dumps(
                    summary, allow_nan=False, separators=(",", ":")))
                log.close()
            stop_live(args)
    if args.table is not None:
        _write_table(args.table, physics)
    if args.json:
        print_json(summary)
    else:
        print(_text_report(summary))
    if args.summary is not None:
        try:
            with open(args.summary, "w") as fh:
                json.dump(summary, fh, indent=1, allow_nan=False)
        except OSError as exc:
            raise UsageError(f"cannot write --summary {args.summary!r}: {exc.strerror}") from None
    if interrupted:
        print("bioflex-jsb ardupilot: interrupted" + (f"; the log {args.out} holds every frame"
                                                     if args.out else ""), file=sys.stderr)
        return 130
    return 0


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
