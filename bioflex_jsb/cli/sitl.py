"""``bioflex-jsb sitl``: the co-simulation in real time, as a MAVLink vehicle."""

from __future__ import annotations

import argparse
import sys

from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    log_path,
    positive_float,
    print_json,
    wing_from_args,
)

# The log is written in small chunks when the loop has time for them: a chunk of the default
# 0.5 s (480 steps) takes ≈ 10 ms to format and compress, and would make the steps after it late.
LOG_FLUSH_STEPS = 24
LOG_FLUSH_SLACK_S = 0.7e-3
LOG_FLUSH_MAX_STEPS = 96  # faster than real time there is less slack: smaller chunks (≈ 1.6 ms)

HELP = """Fly the JSBSim airframe with the elastic wing paced to the wall clock (--speedup N:
N simulated seconds per second) and stream it as a MAVLink 2 vehicle (system 1, component 1,
fixed wing) to a ground station: QGroundControl, MAVProxy, MAVSDK. A simple autopilot
(JSBSim systems: altitude/pitch hold on the elevator, heading/roll hold on the ailerons)
keeps it in level flight; parameters AP_*, GUST_*, WING_COUPLED and SIM_SPEEDUP change the
run from the ground station (docs in bioflex_jsb/drivers/sitl.py). --mavlink:
udpout:HOST:PORT (send to a listening ground station; default udpout:127.0.0.1:14550),
udpin:HOST:PORT or tcpin:HOST:PORT (listen); without HOST, 127.0.0.1. Runs --duration
simulated seconds, or until Ctrl-C. Prints the pacing error (step start minus its wall-clock
due time: p50, p99 [ms]). The vehicle's MAVLink clock (time_boot_ms) is the simulated time
since the start, the time axis of the MCAP log that every session writes (--out, --no-log).
--signing-key FILE turns on MAVLink 2 signing: FILE holds the 32-byte secret as 64
hexadecimal digits (to share it with MAVProxy's "signing key P", the SHA-256 of the
passphrase P: python -c "import hashlib; print(hashlib.sha256(b'P').hexdigest())"); the
vehicle then signs all it sends and ignores unsigned or wrongly signed messages
(except RADIO_STATUS)."""


def register(sub) -> None:
    p = sub.add_parser("sitl", help="real-time MAVLink vehicle (QGC, MAVProxy, MAVSDK)",
                       description=HELP)
    add_wing_arguments(p, default="optimised")
    p.add_argument("--speed", type=positive_float("speed", "m/s"), default=15.0,
                   help="trim airspeed [m/s] (default 15)")
    p.add_argument("--model", choices=("coupled", "rigid"), default="coupled",
                   help="elastic wing coupled (default) or rigid; parameter WING_COUPLED")
    p.add_argument("--mavlink", default="udpout:127.0.0.1:14550", metavar="ENDPOINT",
                   help="udpout:HOST:PORT, udpin:HOST:PORT or tcpin:HOST:PORT "
                   "(default udpout:127.0.0.1:14550)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=None,
                   help="simulated time [s] (default: until Ctrl-C)")
    p.add_argument("--speedup", type=positive_float("speed-up", "x"), default=1.0,
                   help="simulated seconds per wall-clock second (default 1, 0.1..50)")
    p.add_argument("--signing-key", metavar="FILE",
                   help="MAVLink 2 signing key file: 64 hex digits (32 bytes); sign what is "
                   "sent, accept only signed messages")
    add_log_arguments(p)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.drivers.sitl import (
        SPEEDUP_RANGE,
        SitlParameters,
        SitlSim,
        run_paced,
    )
    from bioflex_jsb.links.mavlink import (
        LinkError,
        MavlinkLink,
        parse_endpoint,
        read_signing_key,
    )
    from bioflex_jsb.runtime.fdm import FdmError

    lo, hi = SPEEDUP_RANGE
    if not lo <= args.speedup <= hi:
        raise UsageError(f"--speedup {args.speedup:g} is outside {lo:g}..{hi:g}")
    try:
        endpoint = parse_endpoint(args.mavlink)
        key = None if args.signing_key is None else read_signing_key(args.signing_key)
    except LinkError as exc:
        raise UsageError(str(exc)) from None
    build = wing_from_args(args)
    try:
        sim = SitlSim(build.model, build.modes, model=args.model, speed_m_s=args.speed,
                      speedup=args.speedup)
    except (FdmError, ValueError) as exc:
        raise UsageError(str(exc)) from None
    try:
        link = MavlinkLink(endpoint, SitlParameters(sim), on_manual=sim.manual,
                           signing_key=key)
    except LinkError as exc:
        raise UsageError(str(exc)) from None
    log = None
    on_sample = idle = None
    try:
        args.out = log_path(args, "sitl", args.wing)
    except UsageError:
        link.close()
        raise
    if args.out:
        from bioflex_jsb.cli.gust import open_log
        from bioflex_jsb.simulation.run import RunDescription

        # a session follows its ground station: the description says how it began
        description = RunDescription(
            kind="sitl", wing=args.wing, speed_m_s=args.speed, gust="none",
            models=(args.model,), mass_basis=args.mass_basis,
            **({} if args.duration is None else {"duration_s": args.duration}),
            extra={"until_stopped": args.duration is None, "speedup": args.speedup,
                   "mavlink": endpoint.text(), "signed": key is not None})
        try:
            log = open_log(args.out, description, build)
        except UsageError:
            link.close()
            raise
        names = sim.names

        pending = [0]

        def on_sample(t, model, values):
            log.sample(model, t, dict(zip(names, values, strict=True)))
            pending[0] += 1

        def idle(slack_s):  # write the chunk while there is time (≈ 0.5 ms + 20 µs/step)
            if (pending[0] >= LOG_FLUSH_STEPS and slack_s >= LOG_FLUSH_SLACK_S
                    or pending[0] >= LOG_FLUSH_MAX_STEPS):
                log.flush()
                pending[0] = 0

    host, port = link.local_address
    if not args.json:
        print(f"bioflex-jsb sitl: MAVLink 2 on {endpoint.text()} (local {host}:{port}"
              f"{', signed' if key else ''}), {args.speedup:g}x real time; Ctrl-C stops",
              file=sys.stderr)
    interrupted = False
    try:
        stats = run_paced(sim, args.duration, link, on_sample, idle=idle)
    except KeyboardInterrupt:
        interrupted = True
        stats = None
    finally:
        link.close()
        if log is not None:
            log.close()
    summary = {
        "simulated_s": sim.t_s,
        "steps": sim.k,
        "pacing": stats.summary() if stats else None,
        "link": {"received": link.stats.received, "bad": link.stats.bad,
                 "rejected_signature": link.stats.rejected_signature,
                 "sent": link.stats.sent, "datagrams": link.stats.datagrams,
                 "signing": link.signing},
        "stopped": sim.stopped,
        "out": args.out,
    }
    if args.json:
        print_json(summary)
    else:
        pacing = summary["pacing"]
        line = f"flew {sim.t_s:.2f} s simulated"
        if pacing:
            line += (f"; pacing error p50 {pacing['p50_ms']:.3f} ms, p99 {pacing['p99_ms']:.3f}"
                     f" ms, {pacing['resyncs']} resyncs")
        print(line)
        if args.out:
            print(f"log written to {args.out}")
    if interrupted:
        print("bioflex-jsb sitl: interrupted" + (f"; the log {args.out} holds every step flown"
                                                if args.out else ""), file=sys.stderr)
        return 130
    if sim.stopped:
        print(f"bioflex-jsb sitl: diverged: {sim.stopped}", file=sys.stderr)
        return EXIT_DIVERGED
    return 0
