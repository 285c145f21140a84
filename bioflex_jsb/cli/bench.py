"""``bioflex-jsb bench``: cost of the co-simulation against bare JSBSim, measured in one run."""

from __future__ import annotations

import argparse
import time

from bioflex_jsb.cli.common import UsageError, positive_float, print_json

# Back-to-back (bare, native) timings per repeat, from one trim (module HELP).
NATIVE_PAIRS = 5

HELP = """Time bare JSBSim (the same airframe and time step, no Python in the loop beyond the
step call), the co-simulation (JSBSim + Python modal wing, coupled model, reading the flow and
writing the loads every step), the co-simulation with MCAP logging, and the native XML wing
(JSBSim alone, the wing exported as JSBSim systems), all at the co-simulation's default step,
interleaved --repeat times in one process. Prints microseconds per step (median over
repeats) and the ratios: ratio = co-simulation / bare, log_ratio = logged / unlogged
co-simulation, native_ratio = native / bare (the median of the ratios of native runs each timed
right after a bare one, 5 pairs per repeat); and the SITL pacing error (step start against
the wall clock, p50 and p99 over 2 s of real time). Machines are shared and noisy: compare
the ratios, not the absolute times."""


def register(sub) -> None:
    p = sub.add_parser("bench", help="µs per step: bare JSBSim vs co-simulation",
                       description=HELP)
    p.add_argument("--steps", type=int, default=1200, help="steps per timing (default 1200)")
    p.add_argument("--repeat", type=int, default=9, help="interleaved repeats (default 9)")
    p.add_argument("--speed", type=positive_float("speed", "m/s"), default=15.0,
                   help="trim airspeed [m/s]")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import statistics
    import tempfile
    from pathlib import Path

    from bioflex_jsb.drivers.gust import RunSetup, run_gust
    from bioflex_jsb.drivers.native import native_airframe
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.runtime.coupled_step import configure_airframe
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import RunLog

    if args.steps < 10 or args.repeat < 1:
        raise UsageError("--steps must be ≥ 10 and --repeat ≥ 1")
    airframe = Airframe()
    build = build_wing(VARIANTS["optimised"])
    dt = DEFAULT_DT_S
    setup = RunSetup(args.speed, parse_gust("sharp:0.3"), duration_s=args.steps * dt,
                     gust_start_s=0.5 * args.steps * dt, dt_s=dt)

    def timed(af) -> float:
        t0 = time.perf_counter()
        af.run(args.steps)
        return (time.perf_counter() - t0) / args.steps

    def bare() -> float:
        airframe.trim(args.speed)
        return timed(airframe)

    native = native_airframe("optimised")
    # every timing with the co-simulation's integrators and step
    configure_airframe(airframe, DEFAULT_DT_S)
    configure_airframe(native, DEFAULT_DT_S, modal_hooks=False)

    def cosim(log=None) -> float:
        recorder = log.recorder("coupled") if log else None
        trim = airframe.trim(args.speed)  # outside the timing, as for bare()
        t0 = time.perf_counter()
        run = run_gust(airframe, build.model, "coupled", setup, trim=trim, recorder=recorder)
        elapsed = time.perf_counter() - t0
        if run.stopped:
            raise UsageError(f"benchmark run stopped: {run.stopped}")
        return elapsed / len(run.time_s)

    bare_t, cosim_t, logged_t, native_t, native_pairs = [], [], [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(args.repeat):
            bare_t.append(bare())
            cosim_t.append(cosim())
            log = RunLog.open(Path(tmp) / f"bench{i}.mcap", RunDescription(
                kind="bench", wing="optimised", speed_m_s=args.speed, gust="sharp:0.3",
                models=("coupled",), duration_s=setup.duration_s,
                gust_start_s=setup.gust_start_s, dt_s=dt), build.variant.as_dict())
            try:
                logged_t.append(cosim(log))
            finally:
                log.close()
            # native against bare timed back to back, NATIVE_PAIRS times from one trim each:
            # native_ratio is the median of the pairs' ratios (the machine's load changes
            # less within a pair than across the repeat)
            airframe.trim(args.speed)
            native.trim(args.speed)
            for _ in range(NATIVE_PAIRS):
                pair_bare = timed(airframe)
                native_t.append(timed(native))
                native_pairs.append(native_t[-1] / pair_bare)
    b, c, lg, nat = (statistics.median(x) * 1e6 for x in (bare_t, cosim_t, logged_t, native_t))
    from bioflex_jsb.drivers.sitl import measure_pacing

    sitl = measure_pacing(duration_s=2.0)  # real time, coupled wing, MAVLink link serviced
    payload = {
        "bare_us_per_step": b,
        "cosim_us_per_step": c,
        "ratio": c / b,
        "logged_us_per_step": lg,
        "log_ratio": lg / c,
        "native_us_per_step": nat,
        "native_ratio": statistics.median(native_pairs),
        "sitl_p50_ms": sitl["p50_ms"],
        "sitl_p99_ms": sitl["p99_ms"],
        "dt_s": dt,
        "steps": args.steps,
        "repeat": args.repeat,
    }
    if args.json:
        print_json(payload)
    else:
        print(f"time step {dt:.5f} s, {args.steps} steps × {args.repeat} repeats (median)")
        print(f"bare JSBSim        {b:8.1f} µs/step")
        print(f"co-simulation      {c:8.1f} µs/step   ratio {c / b:5.2f}")
        print(f"co-sim + MCAP log  {lg:8.1f} µs/step   log_ratio {lg / c:5.2f}")
        print(f"native XML wing    {nat:8.1f} µs/step   native_ratio "
              f"{statistics.median(native_pairs):5.2f} (median of back-to-back pairs)")
        print(f"SITL pacing        p50 {sitl['p50_ms']:.3f} ms, p99 {sitl['p99_ms']:.3f} ms "
              "(step start against the wall clock, 2 s real time)")
    return 0
