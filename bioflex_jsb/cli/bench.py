"""``bioflex-jsb bench``: cost of the co-simulation against bare JSBSim, measured in one run."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import UsageError, positive_float, print_json

STEPS_RANGE = (100, 100_000)
REPEAT_RANGE = (1, 50)
# drivers.bench.DEFAULT_STEPS and DEFAULT_REPEAT (not imported at start-up: it loads JSBSim;
# tests/test_bench.py holds them equal)
DEFAULT_STEPS = 300
DEFAULT_REPEAT = 12
SITL_SECONDS_RANGE = (0.0, 3600.0)
SPEEDUP_RANGE = (0.1, 50.0)

HELP = """Time bare JSBSim (the same airframe and step, no Python beyond the step call), the
co-simulation (JSBSim + the compiled coupled step: flow, modal wing, loads, range checks), the
co-simulation logged as a gust run logs (its rows, the section loads and the 3-D scene; also
with the rows alone and without the scene, for the cost of each), the compiled unsteady wing
(Jones lag and Küssner states), the readable Python step, and the native XML wing (JSBSim
alone, the wing exported as JSBSim systems), all at the co-simulation's default step (1/960
s), interleaved --repeat times in one process, each at --steps, 2x and 4x --steps (the
unsteady wing, whose first reference step costs tens of ms, at 4x those). The runs are short
(the machine's own speed changes in states of ~10-50 ms on a shared host: a run that long
mixes them) and many: per-step costs are the slope of a line through the least time of each
run length (noise only adds time; the line's offset is the fixed cost per run), for all the
repeats (the figure), and again without each of 3 interleaved groups of them in turn (its
spread: median [min .. max] of the estimates trusted, at least 2);
an estimate the timings do not support is reported as not trusted, with the reason, instead
of a figure (never negative). Timed on the process's CPU clock (a run preempted by other
work is not charged for the wait; wall-clock figures beside them in --json). Ratios, the
figure and its groups': ratio = co-simulation / bare, logged_ratio = logged co-simulation /
bare (the whole gust log), logged_rows_ratio = the co-simulation logging its rows alone /
bare, log_ratio = logged / unlogged, unsteady_ratio = unsteady co-simulation / bare,
native_ratio = native / bare, python_ratio = Python step / bare, full_span_ratio = the
co-simulation of both wing halves (span full: the antisymmetric modes, the ailerons) / bare;
each ratio with a bar (on a
quiet 2-core machine) printed against it; the logging costs [µs/step]: the rows, the section
loads, the scene. A controller in the loop: the co-simulation with a 10-state linear
controller (q, alpha, n_z to the elevator) and its difference from the co-simulation, and
the controller's own per-step cost (its compiled update and the command written to JSBSim,
the least of 15 timings of 20000 calls; bar 1 µs). Sensor stations: the co-simulation with
two IMUs (the CG's and a wing-tip one) and with them and the controller reading the tip's
a_z, q and alpha; sensors_ratio, controlled_ratio, sensed_controlled_ratio against the
co-simulation and their costs [µs/step], measured in the same run. Also: µs per step
through sharp:0.3, sharp:3 and Dryden gusts (a large gust renews the wing's reference step
more often), the cost of one reference renewal [ms] of both wings, the step kernels' cold
compile and cached load [s], the load average, and the SITL pacing error (step start
against the wall clock, p50/p99 [ms] and resyncs) over --sitl-seconds of simulated time at
--sitl-speedup. Autopilots faster than real time
(--ardupilot-frames, 0 skips): the ardupilot backend (its log written, as a session logs)
lock-stepped with the stand-in of ArduPilot's side (tests/ardupilot_standin.py, in its own
process as ArduPlane is) at each ArduPilot physics rate of --ardupilot-sim-rates (its
SIM_RATE_HZ; default 1200,240: the backend advances 1 and 4 steps of 1/960 s a frame):
frames per second it answers, the free real-time factor, and the highest --speedup at which
its real-time factor stays within 5 % of the speed-up asked for (ArduPilot's own pacing:
sleep debt), each over --ardupilot-repeat rounds (median [min .. max]); and the sitl
vehicle's pacing error at speed-ups 1..30 (--sitl-speedups-seconds of wall time each, 0
skips): the highest with p99 <= 5 ms. Each with the load average. --only ardupilot (or
speedups: with the sitl vehicle's) measures those alone, without the step timings. Machines
are shared and noisy: compare the ratios, not the absolute times."""


def _rates(text: str) -> tuple[int, ...]:
    """--ardupilot-sim-rates: comma-separated whole numbers of Hz, each 50..10000 (ArduPlane's
    loop rate up to the backend's absurd bound, links/ardupilot_rate.py)."""
    try:
        rates = tuple(int(x) for x in text.split(",") if x.strip())
    except ValueError:
        rates = ()
    if not rates or not all(50 <= r <= 10_000 for r in rates):
        raise argparse.ArgumentTypeError(
            f"--ardupilot-sim-rates must be comma-separated whole numbers of Hz in 50..10000 "
            f"(e.g. 1200,240), got {text!r}")
    return rates


def _int_in(label: str, lo: int, hi: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{label} must be a whole number in {lo}..{hi}, "
                                             f"got {text!r}") from None
        if not lo <= value <= hi:
            raise argparse.ArgumentTypeError(f"{label} must be in {lo}..{hi}, got {value}")
        return value

    return parse


def register(sub) -> None:
    p = sub.add_parser("bench", help="µs per step: bare JSBSim vs co-simulation",
                       description=HELP)
    p.add_argument("--steps", type=_int_in("--steps", *STEPS_RANGE), default=DEFAULT_STEPS,
                   help=f"steps of the shortest timing, {STEPS_RANGE[0]}..{STEPS_RANGE[1]} "
                   f"(default {DEFAULT_STEPS}; the others are 2x and 4x that)")
    p.add_argument("--repeat", type=_int_in("--repeat", *REPEAT_RANGE), default=DEFAULT_REPEAT,
                   help=f"interleaved repeats, {REPEAT_RANGE[0]}..{REPEAT_RANGE[1]} (default "
                   f"{DEFAULT_REPEAT}; 3 groups of them give each figure's spread)")
    p.add_argument("--speed", type=positive_float("speed", "m/s"), default=15.0,
                   help="trim airspeed [m/s], 5..40 (default 15)")
    p.add_argument("--sitl-seconds", type=float, default=2.0,
                   help="simulated seconds of the SITL pacing run, 0..3600 (0: skip; default 2)")
    p.add_argument("--sitl-speedup", type=positive_float("SITL speed-up", ""), default=1.0,
                   help="SITL speed-up of the pacing run, 0.1..50 (default 1)")
    p.add_argument("--ardupilot-frames", type=_int_in("--ardupilot-frames", 0, 100_000),
                   default=3000, help="frames of each run against the ArduPilot stand-in, "
                   "0..100000 (0: skip; default 3000)")
    p.add_argument("--ardupilot-repeat", type=_int_in("--ardupilot-repeat", 1, 20), default=3,
                   help="rounds of the ArduPilot speed-up runs, 1..20 (default 3)")
    p.add_argument("--ardupilot-sim-rates", type=_rates, default="1200,240",
                   help="ArduPilot's SIM_RATE_HZ of the ArduPilot runs, comma-separated Hz "
                   "in 50..10000 (default 1200,240)")
    p.add_argument("--only", choices=("ardupilot", "speedups"), default=None,
                   help="measure only the ArduPilot backend (ardupilot), or it and the sitl "
                   "vehicle's speed-ups (speedups); default everything")
    p.add_argument("--sitl-speedups-seconds", type=float, default=1.0,
                   help="wall seconds of each sitl speed-up run, 0..60 (0: skip; default 1)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.drivers import bench
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    if not 5.0 <= args.speed <= 40.0:
        raise UsageError(f"--speed {args.speed:g} m/s is outside 5..40 m/s")
    lo, hi = SITL_SECONDS_RANGE
    if not lo <= args.sitl_seconds <= hi:
        raise UsageError(f"--sitl-seconds {args.sitl_seconds:g} is outside {lo:g}..{hi:g} s")
    lo, hi = SPEEDUP_RANGE
    if not lo <= args.sitl_speedup <= hi:
        raise UsageError(f"--sitl-speedup {args.sitl_speedup:g} is outside {lo:g}..{hi:g}")
    if not 0.0 <= args.sitl_speedups_seconds <= 60.0:
        raise UsageError(f"--sitl-speedups-seconds {args.sitl_speedups_seconds:g} is outside "
                         "0..60 s")
    if args.only is not None:
        if args.ardupilot_frames == 0:
            raise UsageError(f"--only {args.only} with --ardupilot-frames 0 measures nothing "
                             "of the ArduPilot backend; give --ardupilot-frames 1..100000")
        payload = _speedups(args, sitl=args.only == "speedups")
        if args.json:
            print_json(payload)
        else:
            _print_speedups(payload)
        return 0
    build = build_wing(VARIANTS["optimised"])
    compile_s = bench.compile_cost_s()
    sb = bench.StepBench(build, args.speed, args.steps)
    try:
        figures = sb.measure(args.repeat, progress=_progress(args))
    except bench.BenchmarkStopped as exc:
        raise UsageError(str(exc)) from None
    finally:
        sb.close()
    payload = {**figures, "controller_us": bench.controller_cost_us(build, args.speed),
               "refresh_ms": bench.refresh_cost_ms(build),
               "unsteady_refresh_ms": bench.unsteady_refresh_cost_ms(build),
               "kernel_compile_s": compile_s, "dt_s": bench.DEFAULT_DT_S, "steps": args.steps,
               "repeat": args.repeat}
    if args.sitl_seconds > 0.0:
        import tempfile
        from pathlib import Path

        from bioflex_jsb.drivers.sitl import measure_pacing

        with tempfile.TemporaryDirectory() as tmp:  # the session logged, as sitl does
            payload["sitl"] = measure_pacing(duration_s=args.sitl_seconds,
                                             speedup=args.sitl_speedup,
                                             log_path=str(Path(tmp) / "sitl.mcap"))
    payload.update(_speedups(args, sitl=True))
    if args.json:
        print_json(payload)
    else:
        _print(payload)
    return 0


def _speedups(args: argparse.Namespace, sitl: bool) -> dict:
    """The autopilots' speed-up figures asked for: the ArduPilot backend's (unless
    --ardupilot-frames 0) and, with ``sitl``, the sitl vehicle's (unless
    --sitl-speedups-seconds 0)."""
    from bioflex_jsb.drivers import bench_speedup

    out = {}
    if args.ardupilot_frames:
        out["ardupilot"] = bench_speedup.ardupilot_speedup(
            args.ardupilot_frames, args.ardupilot_repeat, sim_rates_hz=args.ardupilot_sim_rates)
    if sitl and args.sitl_speedups_seconds > 0.0:
        out["sitl_speedup"] = bench_speedup.sitl_speedup(args.sitl_speedups_seconds)
    return out


def _progress(args):
    """A progress bar over the repeats on a terminal (the benchmark takes minutes)."""
    import sys

    if args.json or not sys.stderr.isatty():
        return None
    from tqdm import tqdm

    return tqdm(total=args.repeat, desc="bench", unit="repeat", leave=False, file=sys.stderr)


def _spread(d: dict, unit: str = "") -> str:
    """value [min .. max of its groups] of a figure, or why it is not trusted."""
    if d["value"] is None:
        return f"not trusted: {d['reason']}"
    return f"{d['value']:7.2f}{unit}  [{d['min']:.2f} .. {d['max']:.2f}]"


def _against_bar(d: dict) -> str:
    if "bar" not in d:
        return ""
    if d["meets_bar"] is None:
        return f"   bar <= {d['bar']:g}: not judged"
    return f"   bar <= {d['bar']:g}: {'meets it' if d['meets_bar'] else 'ABOVE IT'}"


def _against_bar_us(c: dict) -> str:
    return f"   bar <= {c['bar_us']:g} µs: {'meets it' if c['meets_bar'] else 'ABOVE IT'}"


def _print(p: dict) -> None:
    us = p["us_per_step"]
    load = ", ".join(f"{x:.2f}" for x in p["load_average"])
    print(f"time step {p['dt_s']:.6f} s; runs of {', '.join(map(str, p['run_lengths']))} "
          f"steps, {p['repeat']} interleaved repeats; CPU clock; figure [min .. max without "
          f"a third of the repeats]; load average before {_load(p['load_average_before'])}, "
          f"after {load}")
    rows = (("bare JSBSim", "bare", None), ("co-simulation", "cosim", "ratio"),
            ("  logged (gust log)", "logged", "logged_ratio"),
            ("  logged (rows only)", "logged_rows", "logged_rows_ratio"),
            ("  unsteady strips", "unsteady", "unsteady_ratio"),
            ("  Python step", "python", "python_ratio"),
            ("  both halves", "full_span", "full_span_ratio"),
            ("native XML wing", "native", "native_ratio"))
    for label, key, ratio_key in rows:
        print(f"{label:20s} {_spread(us[key], ' µs/step')}")
        if ratio_key is not None:
            r = p[ratio_key]
            print(f"{'':20s} {ratio_key:17s} {_spread(r)}{_against_bar(r)}")
    print(f"{'':20s} {'log_ratio':17s} {_spread(p['log_ratio'])}")
    for key, label in (("rows", "the rows"), ("section_loads", "section loads"),
                       ("scene", "3-D scene"), ("all", "the whole log")):
        print(f"  logging cost, {label:15s} {_spread(p['log_costs_us_per_step'][key], ' µs/step')}")
    for gust, d in p["cosim_us_per_step_by_gust"].items():
        print(f"co-simulation, {gust:18s} {_spread(d, ' µs/step')}")
    print(f"{'  with a controller':20s} {_spread(us['controlled'], ' µs/step')}")
    print(f"{'':20s} {'/ cosim':17s} {_spread(p['controlled_ratio'])}")
    print(f"  controller in the loop (with - without) "
          f"{_spread(p['controller_in_loop_us_per_step'], ' µs/step')}")
    print(f"{'  with 2 IMUs':20s} {_spread(us['sensors'], ' µs/step')}")
    print(f"{'':20s} {'/ cosim':17s} {_spread(p['sensors_ratio'])}")
    print(f"  sensor stations (with - without) "
          f"{_spread(p['sensor_stations_us_per_step'], ' µs/step')}")
    print(f"{'  and a controller':20s} {_spread(us['sensed_controlled'], ' µs/step')}")
    print(f"{'':20s} {'/ cosim':17s} {_spread(p['sensed_controlled_ratio'])}")
    print(f"  its controller on the tip a_z (with - without) "
          f"{_spread(p['sensor_controller_in_loop_us_per_step'], ' µs/step')}")
    c = p["controller_us"]
    print(f"controller of {c['n_states']} states ({', '.join(c['signals'])} -> elevator), per "
          f"step: {c['in_step']['least']:.3f} µs (median {c['in_step']['median']:.3f}; the "
          f"update alone {c['update']['least']:.3f}, in Python "
          f"{c['python_reference']['least']:.2f}){_against_bar_us(c)}")
    fixed = ", ".join(f"{k} {us[k]['fixed_ms']:.2f} ms" for k in ("cosim", "logged", "unsteady")
                      if us[k]["fixed_ms"] is not None)
    print(f"fixed cost per run (fit): {fixed}")
    for label, key in (("quasi-steady", "refresh_ms"), ("unsteady", "unsteady_refresh_ms")):
        print(f"reference renewal of the {label} wing: {p[key]['median']:.3f} ms "
              f"(max {p[key]['max']:.3f} ms)")
    c = p["kernel_compile_s"]
    load = ", ".join(f"{x:.2f}" for x in c["load_average"])
    print(f"step kernels: cold compile {c['cold']:.2f} s (once per machine), cached load "
          f"{c['cached']:.2f} s (load average {load})")
    if "sitl" in p:
        s = p["sitl"]
        print(f"SITL pacing ({s['speedup']:g}x, logged, {s['steps']} steps): p50 "
              f"{s['p50_ms']:.3f} ms, p99 {s['p99_ms']:.3f} ms, resyncs {s['resyncs']}")
    _print_speedups(p)


def _load(values) -> str:
    return ", ".join(f"{x:.2f}" for x in values)


def _print_speedups(p: dict) -> None:
    a = p.get("ardupilot")
    if a is not None and not a["available"]:
        print(f"ArduPilot backend: not measured ({a['reason']})")
    elif a is not None:
        trust = "" if a["trusted"] else f"  NOT TRUSTED: {a['reason']}"
        print(f"ArduPilot backend ({'logged' if a['logged'] else 'no log'}, "
              f"{a['physics_rate_hz']:.0f} Hz physics, {a['repeat']} rounds of "
              f"{a['frames_per_run']} frames; load average {_load(a['load_average_before'])} "
              f"-> {_load(a['load_average'])}){trust}:")
        for rate, b in a["by_sim_rate"].items():
            n, m, f = b["answered_per_s"], b["max_speedup_held"], b["free_real_time_factor"]
            print(f"  SIM_RATE_HZ {rate} ({b['steps_per_frame']['median']:.2f} steps a frame):"
                  f" frames answered per second {n['median']:.0f}  [{n['min']:.0f} .. "
                  f"{n['max']:.0f}], free real-time factor {f['median']:.2f}  [{f['min']:.2f}"
                  f" .. {f['max']:.2f}]")
            print(f"    highest --speedup held within {100 * a['tolerance']:.0f} %: "
                  f"{m['median']:g}  [{m['min']:g} .. {m['max']:g}] (per round "
                  f"{', '.join(f'{x:g}' for x in b['per_repeat'])})")
            for s_, r in b["real_time_factor_by_speedup"].items():
                print(f"      {s_:>4s}x: real-time factor {r['median']:6.2f}  [{r['min']:.2f} "
                      f".. {r['max']:.2f}]")
    s = p.get("sitl_speedup")
    if s is not None:
        m = s["max_speedup_p99_within_bar"]
        print(f"sitl vehicle (logged): highest --speedup with pacing p99 <= "
              f"{s['bar_p99_ms']:g} ms and no resync: {m['median']:g}  [{m['min']:g} .. "
              f"{m['max']:g}] (load average {_load(s['load_average_before'])} -> "
              f"{_load(s['load_average'])})")
        for r in s["runs"]:
            print(f"    {r['speedup']:>4g}x: p50 {r['p50_ms']:.3f} ms, p99 {r['p99_ms']:.3f} ms, "
                  f"resyncs {r['resyncs']} (load {r['load_average']:.2f})")
