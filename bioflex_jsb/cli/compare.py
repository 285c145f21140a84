"""``bioflex-jsb compare``: the same gust through the LTI model (Eq. 4) and the nonlinear run."""

from __future__ import annotations

import argparse
import dataclasses
import sys

from bioflex_jsb.cli.case import (
    DEFAULT_GUST,
    DEFAULT_SPEED_M_S,
    DEFAULT_WING,
    add_force_argument,
    check_plot_path,
)
from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    check_distinct_outputs,
    closing,
    log_path,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.gust import (
    Interrupted,
    add_aero_arguments,
    add_controller_argument,
    add_run_arguments,
    controller_from_args,
    controller_line,
    fly,
    open_log,
    run_config,
    run_description,
    wing_for_run,
)
from bioflex_jsb.cli.lateral_options import (
    add_lateral_arguments,
    lateral_aero_extra,
    span_aileron,
)

HELP = f"""Fly --gust through the nonlinear JSBSim co-simulation and through the linear model
of Eq. (4) with its gust input G (same wing model, same time grid, same gust samples) and
report, per channel, the normalised RMS difference NRMSE = RMS(linear - nonlinear) /
RMS(nonlinear) [-] for u, alpha, q, theta and eta1, and the largest difference with its unit
and time. The linear model's rigid block A_RR is JSBSim's own linearization of the airframe
at the same trim, so the two differ only by the nonlinearity. With no arguments: the
{DEFAULT_WING} wing at {DEFAULT_SPEED_M_S:g} m/s through {DEFAULT_GUST} (the paper's Fig. 21
case, as for gust); small gusts (--gust sharp:0.3) agree to a few per cent, large ones show
where the linear model leaves the nonlinear one. A nonlinear run that diverges has no NRMSE
(null in --json) and the command exits with status 3. Valid ranges: as for gust. The MCAP log
holds every step of the nonlinear run and the linear model's response on
/bioflex/<model>/lti_prediction (docs/logging.md; --out, --no-log). With --controller the
same linear controller flies in both: the LTI model with its controls closes the loop at the
run's step, with the run's one step of delay, and the commands are compared too. With
--span full (both wing halves; implied by --aileron-step or --aileron-doublet) the lateral
model of the same wing model (beta, p, r, phi and the antisymmetric modes, docs/lateral.md)
is driven by the run's gust roll rate, lateral gust and aileron, and beta_rad, p_rad_s,
r_rad_s, phi_rad, asym_eta1 and modal_roll_n_m are compared too; with --aero unsteady both
the run's antisymmetric modes and the lateral model are on the unsteady strips."""

# The table's unit of each channel's largest difference, and its factor from SI.
DISPLAY_UNITS = {"u": ("m/s", 1.0), "alpha": ("deg", 57.29577951308232),
                 "q": ("deg/s", 57.29577951308232), "theta": ("deg", 57.29577951308232),
                 "eta1": ("deg", 57.29577951308232)}


def register(sub) -> None:
    p = sub.add_parser("compare", help="LTI model vs nonlinear run on the same gust",
                       description=HELP)
    add_wing_arguments(p, default=DEFAULT_WING)
    add_run_arguments(p, DEFAULT_GUST)
    p.add_argument("--model", choices=("coupled", "qsd", "rigid"), default="coupled",
                   help="wing model of both runs (default coupled)")
    add_aero_arguments(p)
    add_controller_argument(p, linear=True)
    add_lateral_arguments(p)  # --span full: the lateral model too (drivers/compare_lateral)
    add_log_arguments(p)
    p.add_argument("--plot", metavar="FILE.png",
                   help="overlay of both time histories, NRMSE in the legends (.png, .pdf, "
                   ".svg; an existing file is replaced only if bioflex-jsb wrote it)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    """Check the arguments, fly the nonlinear run and the linear model, report both."""
    build, full_span, controller, config = _checked(args)
    flown = _fly_and_predict(args, build, full_span, controller, config)
    if flown is None:
        return 130
    nonlinear, linear, stops, drift = flown
    from bioflex_jsb.drivers.compare import compare_run

    result = compare_run(build, nonlinear, args.model, args.speed, args.aero, args.trim,
                         linear=linear, drift=drift)
    if args.plot:
        try:
            result.plot(args.plot, force=True, title=f"{build.variant.name} wing, "
                        f"{args.speed:g} m/s, gust "
                        f"{args.gust.text()}: LTI (Eq. 4) vs JSBSim, {args.model} model")
        except OSError as exc:
            raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
    if args.json:
        print_json(_payload(args, build, result, nonlinear, stops))
    else:
        _print_report(args, build, result, nonlinear, full_span)
    if stops:
        for stop in stops:
            print(f"bioflex-jsb compare: diverged: {stop}", file=sys.stderr)
        return EXIT_DIVERGED
    return 0


def _checked(args: argparse.Namespace):
    """Every argument checked before anything flies (exit 2, one line): the wing model, the
    span (an aileron input needs both halves), the comparable combination of model, aero and
    trim, a linear controller, a gust that excites the aircraft, the output paths. Returns
    (wing build, full span?, controller or None, run configuration)."""
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.drivers.compare import check_comparable, check_gust_excites
    from bioflex_jsb.errors import InputError

    resolve_flight(args)  # --speed and --gust of the aircraft
    build = wing_for_run(wing_from_args(args), args)
    aileron_input = args.aileron_step is not None or args.aileron_doublet is not None
    if aileron_input and args.span == "half":
        raise UsageError("--span half: an aileron input is compared with both wing halves "
                         "(the lateral model); drop --span half")
    full_span = (args.span or ("full" if aileron_input else "half")) == "full"
    try:
        check_comparable(args.model, args.aero, args.trim, args.controller is not None,
                         "full" if full_span else "half")
    except InputError as exc:
        span = " --span full" if full_span else ""
        raise UsageError(f"--model {args.model} --aero {args.aero} --trim {args.trim}{span}: "
                         f"{exc}") from None
    controller = controller_from_args(args)
    if controller is not None:
        from bioflex_jsb.simulation.controller import LinearController

        if not isinstance(controller, LinearController):  # a file is always linear
            raise UsageError("--controller: the LTI model needs a linear controller")
        if "aileron" in controller.outputs:  # both halves' lateral loop (drivers/compare)
            if args.span == "half":
                raise UsageError("--controller commands the aileron, which needs both wing "
                                 "halves: drop --span half (accepted: --span full)")
            full_span = True
    if not aileron_input:  # an aileron input excites the aircraft
        try:
            check_gust_excites(args.gust)
        except InputError as exc:
            raise UsageError(f"--gust {exc}") from None
    config = run_config(args, (args.model,))
    check_plot_path(args.plot, args.force)
    check_distinct_outputs(("--out", args.out), ("--plot", args.plot))
    args.out = log_path(args, "compare", args.wing)
    return build, full_span, controller, config


def _fly_and_predict(args, build, full_span, controller, config):
    """The nonlinear run (and, for a glider, its drift in calm air) and the linear model's
    prediction of it, both in the log when there is one. Returns (nonlinear run, linear
    prediction, stops, drift run or None), or None when interrupted (the log keeps every step
    flown)."""
    from bioflex_jsb.cli.aircraft_option import airframe_from_args
    from bioflex_jsb.drivers.compare import linear_prediction
    from bioflex_jsb.runtime.fdm import FdmError
    from bioflex_jsb.simulation.gusts import parse_gust

    log = None
    try:
        airframe = airframe_from_args(args)
    except FdmError as exc:
        raise UsageError(str(exc)) from None
    if args.out:
        log = open_log(args.out, run_description(args, "compare", (args.model,)), build)
    drift = None
    try:
        try:
            runs, stops = fly(args, build, config, log, airframe)
            if airframe.glider and not stops:  # a glide's drift in calm air (drivers/compare)
                calm = dataclasses.replace(config, gust=parse_gust("none"))
                drift = fly(args, build, calm, None, airframe)[0][0]
        except Interrupted:
            kept = f"; the log {args.out} holds every step flown" if args.out else ""
            print(f"bioflex-jsb compare: interrupted{kept}", file=sys.stderr)
            return None
        nonlinear = runs[0]
        try:
            linear = linear_prediction(build, nonlinear, args.model, args.speed, args.aero,
                                       args.trim, airframe, controller,
                                       span_aileron(args, build) if full_span else None)
        except FdmError as exc:
            raise UsageError(str(exc)) from None
        if log is not None:
            log.prediction(args.model, linear)
    finally:
        if log is not None:
            with closing():  # a stop signal now waits until the log is finished
                log.close()
    return nonlinear, linear, stops, drift


def _payload(args, build, result, nonlinear, stops) -> dict:
    """The --json record: the case, each channel's NRMSE and largest difference, the stops."""
    return {
        "wing": build.variant.name, "speed_m_s": args.speed, "gust": args.gust.text(),
        "model": args.model, "mass_basis": build.mass_basis,
        "overrides": dict(build.model.coefficients.overrides),
        "nrmse": result.nrmse, "worst": result.worst, "stopped": stops,
        "diverged": result.diverged, "divergence_time_s": nonlinear.stop_time_s,
        "controller": nonlinear.meta.get("controller"),
        "duration_s": float(nonlinear.time_s[-1]) if len(nonlinear.time_s) else 0.0,
        "plot": args.plot, "out": args.out, **lateral_aero_extra(args),
    }


def _print_report(args, build, result, nonlinear, full_span) -> None:
    """The text report: the case, the table of channels (NRMSE, largest difference, unit,
    time), the section loads, the controller and what was written."""
    print(f"{build.variant.name} wing, {args.speed:g} m/s, gust {args.gust.text()}, "
          f"{args.model} model: LTI (Eq. 4) vs nonlinear JSBSim run")
    if result.diverged:
        print(f"the nonlinear run diverged at t = {nonlinear.stop_time_s:.3f} s: no "
              "comparison (NRMSE null); see the reason below")
    else:
        _print_table(result)
        line = controller_line(nonlinear)
        if line:
            print(f"{line}; the LTI model closes the loop at the run's step, with its "
                  "one step of delay")
        if full_span and (args.gust.kind == "none" or args.gust.amplitude_m_s == 0.0):
            print("no vertical gust: the longitudinal LTI model is not excited (NRMSE 1 "
                  "on u ... eta1: the run's roll couples into them, the linear models "
                  "keep the axes apart)")
        print("NRMSE = RMS(LTI - JSBSim) / RMS(JSBSim) over the run; max |diff| the "
              "largest difference and when it occurs")
    if args.plot:
        print(f"time histories written to {args.plot}")
    if args.out:
        print(f"log written to {args.out}")


def _print_table(result) -> None:
    """One row per channel, the largest difference in its display unit, then section loads."""
    channels, errors, worst = result.channels, result.nrmse, result.worst
    width = max(8, *(len(c) for c in channels))  # a controller's command is longer
    print(f"{'channel':<{width}} {'NRMSE [-]':>9} {'max |diff|':>11} {'unit':<6} "
          f"{'at t [s]':>9}")
    for c in channels:
        unit, scale = DISPLAY_UNITS.get(c, (worst[c]["unit"], 1.0))
        print(f"{c:<{width}} {errors[c]:9.4f} "
              f"{worst[c]['max_abs_difference'] * scale:11.5f} "
              f"{unit:<6} {worst[c]['at_time_s']:9.3f}")
    print(result.loads_table(), end="")  # section loads (drivers/compare.py)
