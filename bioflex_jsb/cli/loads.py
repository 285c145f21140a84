"""``bioflex-jsb loads``: wing section loads of a gust run, or the tuned discrete gust."""

from __future__ import annotations

import argparse
import csv
import math
import re
import sys

from bioflex_jsb.cli.case import (
    DEFAULT_WING,
    add_force_argument,
    airspeed,
    check_plot_path,
    check_time_step,
    speed_help,
)
from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    EnvironmentFault,
    UsageError,
    add_wing_arguments,
    check_distinct_outputs,
    check_output,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.sweep import positive_int, scheduler_address
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, MAX_DT_S, MIN_DT_S
from bioflex_jsb.simulation.results import KEEP_ALL_MAX_S

_PLAIN = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?")
DEFAULT_GUST = "1cos:3:5"  # the paper's 3 m/s, 2.5 m gradient (between the tuned ends)
# the options of each study and their defaults (None in the parser: given or not is known)
TUNED_OPTIONS = {"gradients": None, "amplitude": 3.0, "scaling": "cs25", "csv": None}
# sigmas: 0.1 and 2.5 m/s, the docs' table (loads.md); at 3 m/s the optimised wing's 120 s
# von Kármán record leaves the valid range (|eta1| 0.53 rad at 76 s, measured)
FREQUENCY_OPTIONS = {"sigmas": (0.1, 2.5), "scale": 30.0, "spectrum": "vonkarman",
                     "record": 120.0, "bode": None}

HELP = f"""Fly one gust (--gust, default {DEFAULT_GUST}) with the elastic wing (--model,
default coupled) and report the wing's section loads at the monitoring stations (--stations,
fractions of the semispan; default the --aircraft definition's [loads] stations, else
0,0.25,0.5,0.75): vertical shear V [N, up +], bending
moment M [N*m, tip up +] and torque about the elastic axis T [N*m, leading edge up +], by
force summation (FS: the strips' aerodynamic loads, the gust's included, less the inertia
of the wing outboard) and by mode displacement (MD: EI phi'' eta, GJ theta' eta of the beam
modes), with their difference: largest and smallest value after the gust start with its time,
the 1 g value and the increments over it. With --tuned: 1-cos gusts over a range of gradient
lengths H, up and down (default {{h_min:.2g}}..{{h_max:g}} m, {{n}} lengths; another
--aircraft: 1.5 of its chords to V T_sp, T_sp its rigid short period's 2 pi/omega_n; amplitude
U_ref (H/H_max)^(1/6), U_ref = --amplitude, the airworthiness codes' shape; docs/loads.md
for the rationale), the critical gradient per station, quantity and method (--csv FILE
writes the table), and the correlated-load envelopes (bending vs torque per station) in
--plot (default loads_envelope.png). With --frequency: the LTI model's frequency response
from the gust to q, n_z and the root bending moment (--bode), the output PSDs under the
--spectrum turbulence, their RMS and N0, against Welch estimates (95 % bands) from nonlinear
runs of --record seconds at each of --sigmas (--plot, default loads_psd.png), on the
--aircraft's own JSBSim model linearised at its trim. The tuned gusts
run in parallel on the sweep's executors (--workers local processes, default one per core, or
--scheduler a Dask cluster; a progress bar on a terminal), the table the same whatever the
number of workers; the --frequency runs are sequential. No MCAP log
is written (the loads are a post-process of the runs). Exit 3 if a run diverged."""


def plain_number(text: str, what: str) -> float:
    """A finite plain ASCII decimal (``0.25``, ``-1e3``; not ``1_5``, ``nan``, ``0x10``)."""
    from bioflex_jsb.errors import InputError

    if not _PLAIN.fullmatch(text) or not math.isfinite(float(text)):
        raise InputError(f"{what} must be a plain decimal number, got {text!r}")
    return float(text)


def plain_integer(text: str, what: str) -> int:
    """A whole number of up to four ASCII digits."""
    from bioflex_jsb.errors import InputError

    if not re.fullmatch(r"[0-9]{1,4}", text):
        raise InputError(f"{what} must be a whole number, got {text!r}")
    return int(text)


def fractions(text: str) -> tuple[float, ...]:
    """argparse type: comma-separated fractions of the semispan, 0 <= f < 1, increasing."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.loads.model import station_positions_m

    try:
        values = tuple(plain_number(t, "a station") for t in text.split(","))
        station_positions_m(values, 1.0)
    except InputError as exc:
        raise argparse.ArgumentTypeError(f"--stations {text!r}: {exc}") from None
    return values


def gradients(text: str) -> tuple[float, ...]:
    """argparse type: ``MIN:MAX:N`` (log-spaced) or comma-separated gradients H [m]."""
    import numpy as np

    from bioflex_jsb.errors import InputError
    from bioflex_jsb.simulation.gusts import MAX_GUST_LENGTH_M, default_min_gust_length_m

    lo_h, hi_h = default_min_gust_length_m() / 2.0, MAX_GUST_LENGTH_M / 2.0
    try:
        if ":" in text:
            parts = text.split(":")
            if len(parts) != 3:
                raise InputError("give MIN:MAX:N")
            lo, hi = plain_number(parts[0], "MIN"), plain_number(parts[1], "MAX")
            n = plain_integer(parts[2], "N (2 to 200)")
            if not (0 < lo < hi) or not 2 <= n <= 200:
                raise InputError("need 0 < MIN < MAX and 2 <= N <= 200")
            values = tuple(float(x) for x in np.geomspace(lo, hi, n))
        else:
            values = tuple(plain_number(t, "a gradient") for t in text.split(","))
    except InputError as exc:
        raise argparse.ArgumentTypeError(f"--gradients {text!r}: {exc} (MIN:MAX:N log-spaced, "
                                         "or H1,H2,... in m)") from None
    if any(not lo_h <= h <= hi_h for h in values):
        raise argparse.ArgumentTypeError(
            f"--gradients {text!r}: each H must be within {lo_h:g}..{hi_h:g} m (the 1-cos "
            "gust's length 2H within the gust limits, docs/gusts.md)")
    return values


def sigma_list(text: str) -> tuple[float, ...]:
    """argparse type: comma-separated turbulence intensities sigma_w [m/s], 0 < sigma <= 10."""
    from bioflex_jsb.errors import InputError

    try:
        values = tuple(plain_number(t, "an intensity") for t in text.split(","))
    except InputError as exc:
        raise argparse.ArgumentTypeError(f"--sigmas {text!r}: {exc}") from None
    if any(not 0.0 < v <= 10.0 for v in values):
        raise argparse.ArgumentTypeError(f"--sigmas {text!r}: each sigma_w must satisfy "
                                         "0 < sigma <= 10 m/s")
    return values


def register(sub) -> None:
    from bioflex_jsb.cli.aircraft_option import default_airframe
    from bioflex_jsb.loads.tuned import DEFAULT_H_MAX_M, DEFAULT_N_LENGTHS, default_gradients_m

    h_min = default_gradients_m(default_airframe().reference.mean_chord_m)[0]
    text = HELP.format(h_min=h_min, h_max=DEFAULT_H_MAX_M,
                       n=DEFAULT_N_LENGTHS)
    p = sub.add_parser("loads", help="wing section loads in a gust; --tuned: critical 1-cos "
                       "gradients and load envelopes", description=text)
    add_wing_arguments(p, default=DEFAULT_WING)
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    # DEFAULT_SPEED_M_S, marked: an aircraft definition's cruise speed replaces it
    p.add_argument("--speed", type=airspeed, default=cruise_speed_default(), metavar="V",
                   help="trim " + speed_help() + "; with --aircraft: within its "
                   "airframe.speed_range_m_s, default its cruise_speed_m_s")
    p.add_argument("--gust", default=DEFAULT_GUST,
                   help=f"gust specification (default {DEFAULT_GUST}; forms as in `gust`)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=3.0,
                   help="simulated time [s] of a single run (default 3; up to "
                   f"{KEEP_ALL_MAX_S:g} s: the loads need every step kept)")
    p.add_argument("--gust-start", type=positive_float("gust start", "s"), default=0.5,
                   help="time the gust starts [s] (default 0.5)")
    p.add_argument("--dt", type=positive_float("time step", "s"), default=DEFAULT_DT_S,
                   help=f"co-simulation step [s], {MIN_DT_S:g} to {MAX_DT_S:g} (default "
                   f"{DEFAULT_DT_S:.6f})")
    p.add_argument("--model", choices=("coupled", "qsd", "rigid"), default="coupled",
                   help="wing model flown (default coupled; rigid: force summation only)")
    p.add_argument("--trim", choices=("rigid", "elastic"), default="rigid",
                   help="the trim the run starts from (as `gust --trim`)")
    p.add_argument("--stations", type=fractions, default=None,
                   help="monitoring stations as fractions of the semispan (default: the "
                   "--aircraft definition's [loads] stations, else 0,0.25,0.5,0.75)")
    p.add_argument("--static", choices=("elastic", "rigid"), default=None,
                   help="the 1 g static part: elastic (the elastic trim's deflection, default "
                   "for coupled/qsd) or rigid (undeformed wing; the rigid model's)")
    p.add_argument("--tuned", action="store_true", help="the tuned discrete gust (above)")
    p.add_argument("--frequency", action="store_true",
                   help="continuous turbulence in the frequency domain (above)")
    p.add_argument("--sigmas", type=sigma_list, default=None,
                   help="--frequency: turbulence intensities sigma_w [m/s] (default 0.1,2.5; "
                   "another airframe: 0.1 and the largest whose 4-sigma gust angle stays in "
                   "its aerodynamic tables, at most 2.5)")
    p.add_argument("--scale", type=positive_float("turbulence scale", "m"), default=None,
                   help="--frequency: turbulence length scale L_w [m] (default 30: "
                   "MIL-F-8785C's L_w = h at 30 m above ground)")
    p.add_argument("--spectrum", choices=("vonkarman", "dryden"), default=None,
                   help="--frequency: turbulence spectrum (default vonkarman)")
    p.add_argument("--record", type=positive_float("record", "s"), default=None,
                   help="--frequency: length of each nonlinear run [s] (default 120; at "
                   "least 2 Welch segments of 8 s, at most "
                   f"{KEEP_ALL_MAX_S:g} s: the loads need every step kept)")
    p.add_argument("--bode", metavar="FILE.png", default=None,
                   help="--frequency: Bode plots (default loads_bode.png without --json)")
    p.add_argument("--gradients", type=gradients, default=None,
                   help="--tuned gradients H [m]: MIN:MAX:N (log-spaced) or H1,H2,...")
    p.add_argument("--amplitude", type=positive_float("amplitude", "m/s"), default=None,
                   help="--tuned reference gust velocity U_ref [m/s] (default 3)")
    p.add_argument("--scaling", choices=("cs25", "fixed"), default=None,
                   help="--tuned amplitude: cs25 U_ref (H/H_max)^(1/6) (default) or fixed")
    p.add_argument("--csv", metavar="FILE.csv", default=None,
                   help="--tuned: the critical-case table as CSV")
    p.add_argument("--workers", type=positive_int, default=None,
                   help="--tuned: local worker processes (default: one per core); with "
                   "--scheduler local, the LocalCluster's workers (default 2)")
    p.add_argument("--scheduler", type=scheduler_address, default=None,
                   metavar="tcp://HOST:PORT",
                   help="--tuned: fly the gusts on this Dask scheduler ('local': a Dask "
                   "LocalCluster), as `sweep`")
    p.add_argument("--plot", metavar="FILE.png", default=None,
                   help="figure (loads time histories; --tuned: the envelopes); default "
                   "loads.png / loads_envelope.png without --json")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def _fly(args, build, gust_text: str, duration_s: float, gust_start_s: float):
    """One run of ``--model`` through ``gust_text`` on the JSBSim airframe of ``--aircraft``
    (the prototype's without it; as ``gust`` flies it) and its section loads."""
    from bioflex_jsb.cli.aircraft_option import airframe_from_args
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.loads import section_loads
    from bioflex_jsb.runtime.fdm import FdmError
    from bioflex_jsb.simulation.gusts import parse_gust

    try:
        chord = build.airframe.reference.mean_chord_m  # the shortest gust: one mean chord
        setup = RunConfig(args.speed, parse_gust(gust_text, chord), duration_s, gust_start_s,
                          0.0, args.dt, models=(args.model,), trim=args.trim)
        wing = build if setup.needs_build(args.model) else build.model
        run = run_gust(airframe_from_args(args), wing, args.model, setup, loads=build)
        return run, section_loads(build, run, args.stations, static=args.static)
    except (FdmError, InputError) as exc:
        raise UsageError(str(exc)) from None


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.loads import monitoring_stations

    resolve_flight(args)  # --speed: the aircraft's cruise speed, within its speeds
    check_time_step(args.dt)
    build = wing_from_args(args)
    aircraft = getattr(args, "aircraft_definition", None)
    if args.stations is None:  # the aircraft definition's, else the default stations
        args.stations = monitoring_stations(aircraft)
    sigmas_given = args.sigmas is not None  # else the airframe's own (_default_sigmas)
    _check_study_options(args)
    if args.tuned:
        return _tuned(args, build)
    if args.frequency:
        return _frequency(args, build, sigmas_given)
    return _single_gust(args, build)


def _check_study_options(args: argparse.Namespace) -> None:
    """One study (a gust, --tuned or --frequency) and only its options (never silently
    ignored); the others' defaults filled in."""
    if args.model == "rigid" and args.static == "elastic":
        raise UsageError("--model rigid has no static deflection; drop --static elastic")
    if args.tuned and args.frequency:
        raise UsageError("--tuned and --frequency are two studies; give one")
    for opt in ("workers", "scheduler"):
        if getattr(args, opt) is not None and not args.tuned:
            raise UsageError(f"--{opt} applies to --tuned (its gusts run in parallel)")
    for study, options in (("tuned", TUNED_OPTIONS), ("frequency", FREQUENCY_OPTIONS)):
        for opt, default in options.items():
            if getattr(args, opt) is not None and not getattr(args, study):
                raise UsageError(f"--{opt} applies to --{study}")
            if getattr(args, opt) is None:
                setattr(args, opt, default)
    longest = args.record if args.frequency else args.duration
    if not args.tuned and longest > KEEP_ALL_MAX_S:
        raise UsageError(f"--{'record' if args.frequency else 'duration'} {longest:g} s: the "
                         f"section loads need every step kept, up to {KEEP_ALL_MAX_S:g} s")
    if args.scheduler and args.scheduler != "local" and args.workers is not None:
        raise UsageError("--workers applies to local processes and --scheduler local; a "
                         "cluster's workers are started with it (dask worker)")


def _single_gust(args: argparse.Namespace, build) -> int:
    """The section loads of one gust run: the metrics printed or as JSON, the figure."""
    from bioflex_jsb.loads import loads_metrics
    from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust

    try:
        parse_gust(args.gust)
    except GustSpecError as exc:
        raise UsageError(f"--gust: {exc}") from None
    if args.gust_start >= args.duration:
        raise UsageError(f"--gust-start {args.gust_start:g} s must be before the end of the "
                         f"run (--duration {args.duration:g} s)")
    plot = args.plot if args.plot is not None else (None if args.json else "loads.png")
    check_plot_path(plot, args.force)
    run_, loads = _fly(args, build, args.gust, args.duration, args.gust_start)
    metrics = loads_metrics(loads, args.gust_start)
    if plot:
        loads.plot(plot, args.gust_start, force=True)  # check_plot_path judged it (--force)
    if args.json:
        print_json({"wing": build.variant.name, "speed_m_s": args.speed, "gust": args.gust,
                    "model": args.model, "static": loads.meta["static"],
                    "accelerations": loads.meta["accelerations"], "loads": metrics,
                    "plot": plot})
    else:
        _print_metrics(build, args, loads, metrics)
        if plot:
            print(f"section loads written to {plot}")
    if run_.stopped:
        print(f"bioflex-jsb loads: diverged: {args.model} run stopped: {run_.stopped}",
              file=sys.stderr)
        return EXIT_DIVERGED
    return 0


def _print_metrics(build, args, loads, metrics) -> None:
    print(f"Section loads: wing {build.variant.name}, {args.speed:g} m/s, gust {args.gust}, "
          f"{args.model} model; static part: {loads.meta['static']}")
    print("  V shear [N] up +, M bending [N*m] tip up +, T torque about the elastic axis "
          "[N*m] leading edge up +; increments over 1 g (time of the peak [s])")
    head = f"{'station':10s} {'load':3s} {'method':4s} {'1 g':>9s} {'incr up':>9s} " \
           f"{'(t)':>6s} {'incr down':>9s} {'(t)':>6s} {'max|FS-MD|':>10s}"
    print(head)
    short = {"shear_n": "V", "bending_n_m": "M", "torque_n_m": "T"}
    diff = metrics.get("max_abs_difference", {})
    if not metrics["methods"]:
        print(f"  no loads after the gust start: the run stopped at "
              f"{loads.time_s[-1] if len(loads.time_s) else 0.0:.3f} s")
        return
    for j in range(len(loads.stations_m)):
        for quantity in ("shear_n", "bending_n_m", "torque_n_m"):
            for method in loads.methods:
                r = metrics["methods"][method][quantity][j]
                tag = "FS" if method == "force_summation" else "MD"
                d = f"{diff[quantity][j]:10.4f}" if diff and tag == "FS" else ""
                print(f"{r['station']:10s} {short[quantity]:3s} {tag:4s} {r['static_1g']:9.4f} "
                      f"{r['increment_up']:+9.4f} {r['time_max_s']:6.3f} "
                      f"{r['increment_down']:+9.4f} {r['time_min_s']:6.3f} {d}")


def _tuned(args, build) -> int:
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.loads.tuned import plot_envelopes, tuned_cases, tuned_result

    plot = args.plot if args.plot is not None else (None if args.json else "loads_envelope.png")
    check_plot_path(plot, args.force)
    if args.csv:
        if not args.csv.lower().endswith(".csv"):
            raise UsageError(f"--csv {args.csv!r}: the file name must end in .csv")
        check_output(args.csv, args.force, "--csv")
    try:
        scales = _gust_scales(args, build)
        cases = tuned_cases(args.speed, args.gradients, u_ref_m_s=args.amplitude,
                            scaling=args.scaling, scales=scales)
    except InputError as exc:
        raise UsageError(str(exc)) from None
    rows = _fly_tuned(args, build, cases)
    lost = [r for r in rows if r.get("lost")]
    if lost:  # the machine's: a worker process died twice (crash, out of memory)
        raise EnvironmentFault(f"{lost[0]['gust']}: {lost[0]['error']}")
    failed = [r for r in rows if r["status"] == "failed"]
    if failed:  # as a single run's problem: one line (the first), exit 2
        raise UsageError(f"{failed[0]['gust']}: {failed[0]['error']}")
    stopped = [f"{r['gust']}: {r['error']}" for r in rows if r["status"] == "diverged"]
    result = tuned_result(cases, [r["loads"] for r in rows], args.speed,
                          u_ref_m_s=args.amplitude, scaling=args.scaling, scales=scales)
    if args.csv:
        with open(args.csv, "w", newline="", encoding="utf-8") as f:
            csv.writer(f).writerows(result.csv_rows())
    if plot:
        plot_envelopes(result, plot)
    if args.json:
        print_json(dict(result.as_dict(), plot=plot, csv=args.csv, stopped=stopped))
    else:
        st = result.settings
        print(f"Tuned 1-cos gust: wing {build.variant.name}, {args.speed:g} m/s, "
              f"{args.model} model, H = {', '.join(f'{h:.3g}' for h in st['gradients_m'])} m, "
              f"U = {args.amplitude:g} m/s x (H/{st['h_max_m']:.3g} m)^(1/6)"
              if args.scaling == "cs25" else
              f"Tuned 1-cos gust: wing {build.variant.name}, {args.speed:g} m/s, fixed "
              f"U = {args.amplitude:g} m/s")
        print(f"{'station':10s} {'load':12s} {'method':4s} {'dir':4s} {'H [m]':>6s} "
              f"{'gust':>4s} {'1 g':>9s} {'increment':>10s} {'t [s]':>6s}")
        for r in result.critical:
            tag = "FS" if r["method"] == "force_summation" else "MD"
            print(f"{r['station']:10s} {r['quantity']:12s} {tag:4s} {r['direction']:4s} "
                  f"{r['gradient_m']:6.3g} {r['sign']:>4s} {r['static_1g']:9.4f} "
                  f"{r['increment']:+10.4f} {r['time_s']:6.3f}")
        if args.csv:
            print(f"critical cases written to {args.csv}")
        if plot:
            print(f"load envelopes written to {plot}")
    for s in stopped:
        print(f"bioflex-jsb loads: diverged: {s}", file=sys.stderr)
    return EXIT_DIVERGED if stopped else 0


def _gust_scales(args, build):
    """The tuned gust's gradient range and settling time: the prototype's defaults on its
    airframe, else the aircraft's own (its mean chord, its rigid short period at --speed:
    loads.tuned.aircraft_gust_scales); given --gradients must be gusts of at least one of its
    chords (2H >= c̄)."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.loads.tuned import gust_scales

    chord_m = build.model.airframe.reference.mean_chord_m
    if args.gradients is not None and min(args.gradients) * 2.0 < chord_m:
        raise InputError(f"--gradients: H {min(args.gradients):g} m is a gust shorter than "
                         f"the aircraft's mean chord {chord_m:.3g} m; each H must be at least "
                         f"{chord_m / 2.0:.3g} m")
    aircraft = getattr(args, "aircraft_definition", None)
    density = None if aircraft is None else float(aircraft.definition.air.density_kg_m3)
    return gust_scales(build, args.speed, density)


def _fly_tuned(args, build, cases: list[dict]) -> list[dict]:
    """The tuned gusts on the sweep executors (``--workers``, ``--scheduler``; as `sweep`):
    their rows in the cases' order (:mod:`bioflex_jsb.sweep.tuned_loads`)."""
    import hashlib

    from bioflex_jsb.cli.sweep import executor_errors, progress_bar
    from bioflex_jsb.sweep.tuned_loads import (
        fly_tuned_case,
        run_tuned,
        tuned_case_list,
        tuned_failed_row,
    )

    aircraft = getattr(args, "aircraft_definition", None)
    wing = aircraft if aircraft is not None else build.variant
    key = hashlib.sha256(repr(aircraft.definition if aircraft is not None
                              else sorted(build.variant.as_dict().items())).encode())
    todo = tuned_case_list(cases, wing, key.hexdigest()[:16], args.mass_basis, args.speed,
                           args.dt, args.model, args.trim, args.stations, args.static)
    executor = tuned_executor(args, fly_tuned_case, tuned_failed_row)
    bar = progress_bar(len(todo), 0, "tuned gust")

    def on_row(done, total, row):
        if bar is not None:
            bar.update(1)
            bar.set_postfix_str(row["gust"], refresh=False)

    try:
        with executor:
            return run_tuned(todo, executor, on_row)
    except executor_errors() as exc:  # the cluster cannot be reached: nothing ran
        raise UsageError(str(exc)) from None
    finally:
        if bar is not None:
            bar.close()


def tuned_executor(args, fn, failed):
    """The executor of ``--workers``/``--scheduler`` (as `sweep`'s) running ``fn``."""
    if args.scheduler:
        from bioflex_jsb.sweep.dask_cluster import DaskExecutor

        workers = args.workers or 2
        return DaskExecutor(None if args.scheduler == "local" else args.scheduler,
                            workers=workers, fn=fn, failed=failed)
    from bioflex_jsb.sweep.local import LocalExecutor

    return LocalExecutor(args.workers, fn=fn, failed=failed)


FREQUENCY_OUTPUTS = ("q", "n_z", "fs_bending_n_m_s0")  # pitch rate, load factor, root M (FS)
FREQUENCY_UNITS = ("rad/s", "-", "N*m")
FREQUENCY_START_S = 1.0  # the record analysed starts here [s] (turbulence from 0.5 s)


# The larger default intensity of another airframe: its 4-sigma gust angle w/V stays
# inside its aerodynamic tables (a Gaussian record crosses 4 sigma about exp(-8) N0 T
# times: 0.1 times in 120 s at N0 = 3 Hz), at most the prototype's 2.5 m/s.
SIGMA_TABLE_MARGIN = 4.0


def _default_sigmas(args, build, lin, airframe) -> tuple[float, ...]:
    """--sigmas when not given: the prototype's (0.1, 2.5 m/s) on its airframe; on another
    the small one and the largest whose SIGMA_TABLE_MARGIN-sigma angle of attack w/V from
    the trim stays inside the airframe's tables (rounded down to 0.1 m/s; c172p at 57.8 m/s:
    α -0.42 deg, tables from -5.16 deg: 1.1 m/s)."""
    from bioflex_jsb.cli.aircraft_option import default_airframe

    small, large = FREQUENCY_OPTIONS["sigmas"]
    if build.airframe is default_airframe():
        return (small, large)
    lo, hi = airframe.alpha_table_range_rad
    margin_rad = min(lin.trim.alpha_rad - lo, hi - lin.trim.alpha_rad)
    fit = math.floor(10.0 * args.speed * math.tan(max(margin_rad, 0.0))
                     / SIGMA_TABLE_MARGIN) / 10.0
    return (small, min(fit, large)) if fit > small else (small,)


def _frequency(args, build, sigmas_given: bool = True) -> int:
    """The LTI model (Eq. 4 with JSBSim's rigid block, as `compare`) in the frequency domain
    against long nonlinear turbulence runs (bioflex_jsb.loads.spectral)."""
    import numpy as np

    from bioflex_jsb.cli.aircraft_option import airframe_from_args
    from bioflex_jsb.flight_dynamics.lti import build_state_space
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
    from bioflex_jsb.loads.lti import with_load_outputs
    from bioflex_jsb.loads.model import build_loads_model
    from bioflex_jsb.loads.spectral import compare_spectra, plot_bode, plot_psd
    from bioflex_jsb.runtime.fdm import FdmError

    if args.model != "coupled":
        raise UsageError("--frequency compares the coupled model (give --model coupled)")
    if args.record < 2 * 8.0 + FREQUENCY_START_S:
        raise UsageError(f"--record {args.record:g} s is too short: at least "
                         f"{2 * 8.0 + FREQUENCY_START_S:g} s (two Welch segments of 8 s)")
    plot = args.plot if args.plot is not None else (None if args.json else "loads_psd.png")
    bode = args.bode if args.bode is not None else (None if args.json else "loads_bode.png")
    check_distinct_outputs(("--plot", plot), ("--bode", bode))
    check_plot_path(plot, args.force)
    check_plot_path(bode, args.force)
    try:  # JSBSim's rigid block of the airframe the runs fly (the aircraft's own, as compare)
        airframe = airframe_from_args(args)
        lin = airframe.linearize(args.speed)
    except FdmError as exc:
        raise UsageError(str(exc)) from None
    a_rr = lin.a
    if not sigmas_given:
        args.sigmas = _default_sigmas(args, build, lin, airframe)
    ss = build_state_space("coupled", level_flight_condition(args.speed,
                                                             airframe=build.airframe),
                           build.model, a_rr=a_rr, controls=True)
    ss = with_load_outputs(ss, build_loads_model(build, args.speed, (0.0,)))
    cases, stopped = [], []
    args.stations = (0.0,)
    for sigma in args.sigmas:
        text = f"{args.spectrum}:{sigma:g}:{args.scale:g}:1"
        run_, loads = _fly(args, build, text, args.record, 0.5)
        if run_.stopped:
            stopped.append(f"{text}: {run_.stopped}")
            continue
        keep = run_.time_s >= FREQUENCY_START_S
        series = np.column_stack([run_["q"][keep], run_["n_z"][keep] - 1.0,
                                  loads.values["force_summation"][keep, 1, 0]])
        cases.append(compare_spectra(ss, FREQUENCY_OUTPUTS, FREQUENCY_UNITS, series,
                                     run_.meta["dt_s"], kind=args.spectrum, sigma_m_s=sigma,
                                     scale_m=args.scale, speed_m_s=args.speed))
    if bode:
        plot_bode(ss, FREQUENCY_OUTPUTS, FREQUENCY_UNITS, bode)
    if plot and cases:
        plot_psd(cases, plot)
    if args.json:
        print_json({"wing": build.variant.name, "speed_m_s": args.speed,
                    "rigid_block": ss.notes["rigid_block"],
                    "cases": [c.as_dict() for c in cases],
                    "stopped": stopped, "plot": plot, "bode": bode})
    else:
        print(f"Continuous turbulence ({args.spectrum}, L = {args.scale:g} m): wing "
              f"{build.variant.name}, {args.speed:g} m/s; LTI (Eq. 4, JSBSim's rigid block) vs "
              f"nonlinear runs of {args.record:g} s")
        print(f"{'sigma':>6s} {'output':18s} {'RMS LTI':>10s} {'RMS run':>10s} {'ratio':>6s} "
              f"{'N0 LTI':>7s} {'N0 run':>7s} {'in band':>7s}   (RMS, N0 [Hz] above "
              f"{cases[0].check_band_hz[0] if cases else 0.25:g} Hz)")
        for c in cases:
            d = c.as_dict()["outputs"]
            for o in c.outputs:
                r = d[o]
                print(f"{c.sigma_m_s:6.3g} {o:18s} {r['lti_rms_band']:10.4g} "
                      f"{r['run_rms_band']:10.4g} {r['rms_ratio_band']:6.3f} "
                      f"{r['lti_n0_hz']:7.3g} {r['run_n0_hz']:7.3g} {r['fraction_in_band']:7.1%}")
        for path, what in ((bode, "Bode plots"), (plot if cases else None, "PSDs")):
            if path:
                print(f"{what} written to {path}")
    for s_ in stopped:
        print(f"bioflex-jsb loads: diverged: {s_}", file=sys.stderr)
    return EXIT_DIVERGED if stopped else 0
