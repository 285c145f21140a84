"""``bioflex-jsb compare``: the same gust through the LTI model (Eq. 4) and the nonlinear run."""

from __future__ import annotations

import argparse
import sys

from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    log_path,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.gust import (
    Interrupted,
    add_run_arguments,
    check_run_arguments,
    fly,
    open_log,
    run_description,
)

HELP = """Fly --gust through the nonlinear JSBSim co-simulation and through the linear model of
Eq. (4) with its gust input G (same wing model, same time grid, same gust samples) and
report, per channel, the normalised RMS difference NRMSE = RMS(linear - nonlinear) /
RMS(nonlinear) [-] for u, alpha, q, theta and eta1. The linear model's rigid block A_RR is
JSBSim's own linearization of the airframe at the same trim, so the two differ only by the
nonlinearity. Small gusts (sharp:0.3 at 15 m/s) agree to a few per cent; large ones show
where the linear model leaves the nonlinear one (the largest error and when it occurs). The
MCAP log holds every step of the nonlinear run and the linear model's response on
/bioflex/<model>/lti_prediction (docs/logging.md; --out, --no-log)."""

CHANNELS = ("u", "alpha", "q", "theta", "eta1")


def register(sub) -> None:
    p = sub.add_parser("compare", help="LTI model vs nonlinear run on the same gust",
                       description=HELP)
    add_wing_arguments(p)
    add_run_arguments(p, "sharp:0.3")
    p.add_argument("--model", choices=("coupled", "qsd", "rigid"), default="coupled",
                   help="wing model of both runs (default coupled)")
    p.add_argument("--plot", metavar="FILE.png", help="overlay of both time histories")
    add_log_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    import numpy as np

    from bioflex_jsb.flight_dynamics.lti import build_state_space
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
    from bioflex_jsb.runtime.fdm import Airframe, FdmError
    from bioflex_jsb.simulation.lti_response import simulate
    from bioflex_jsb.simulation.results import nrmse

    build = wing_from_args(args)
    check_run_arguments(args)
    args.out = log_path(args, "compare", args.wing)
    log = None
    if args.out:
        log = open_log(args.out, run_description(args, "compare", (args.model,)), build)
    try:
        try:
            runs, stops = fly(args, build, (args.model,), log)
        except Interrupted:
            kept = f"; the log {args.out} holds every step flown" if args.out else ""
            print(f"bioflex-jsb compare: interrupted{kept}", file=sys.stderr)
            return 130
        nonlinear = runs[0]
        try:
            lin = Airframe().linearize(args.speed)
        except FdmError as exc:
            raise UsageError(str(exc)) from None
        ss = build_state_space(args.model, level_flight_condition(args.speed), build.model,
                               a_rr=lin.a)
        linear = simulate(ss, nonlinear.time_s, nonlinear["w_g"])
        if log is not None:
            log.prediction(args.model, linear)
    finally:
        if log is not None:
            log.close()
    linear.meta.update(label=f"LTI {args.model}", linestyle="--")
    nonlinear.meta.update(label=f"JSBSim {args.model}")
    channels = [c for c in CHANNELS if c in linear.channels and c in nonlinear.channels]
    errors = {c: nrmse(nonlinear[c], linear[c]) for c in channels}
    worst = {}
    for c in channels:
        diff = np.abs(linear[c] - nonlinear[c])
        k = int(np.argmax(diff))
        worst[c] = {"max_abs_difference": float(diff[k]), "at_time_s": float(nonlinear.time_s[k])}
    if args.plot:
        from bioflex_jsb.sinks import plotting

        try:
            plotting.time_histories([nonlinear, linear], args.plot,
                                    f"{build.variant.name}: LTI vs JSBSim, {args.gust.text()}")
        except OSError as exc:
            raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
    payload = {
        "wing": build.variant.name, "speed_m_s": args.speed, "gust": args.gust.text(),
        "model": args.model, "mass_basis": build.mass_basis,
        "overrides": dict(build.model.coefficients.overrides),
        "nrmse": errors, "worst": worst, "stopped": stops,
        "duration_s": float(nonlinear.time_s[-1]) if len(nonlinear.time_s) else 0.0,
        "out": args.out,
    }
    if args.json:
        print_json(payload)
    else:
        print(f"{build.variant.name} wing, {args.speed:g} m/s, gust {args.gust.text()}, "
              f"{args.model} model: LTI (Eq. 4) vs nonlinear JSBSim run")
        print(f"{'channel':<8} {'NRMSE':>8} {'max |diff|':>12} {'at t [s]':>9}")
        for c in channels:
            print(f"{c:<8} {errors[c]:8.4f} {worst[c]['max_abs_difference']:12.5f} "
                  f"{worst[c]['at_time_s']:9.3f}")
        if args.out:
            print(f"log written to {args.out}")
    if stops:
        for stop in stops:
            print(f"bioflex-jsb compare: diverged: {stop}", file=sys.stderr)
        return EXIT_DIVERGED
    return 0
