"""``bioflex-jsb export``: write the LTI model with named states and units."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import (
    UsageError,
    add_wing_arguments,
    positive_float,
    print_json,
    wing_from_args,
)

HELP = """Write the rigid, coupled (Eq. 4) or QSD (Eq. 9-10) model at --speed [m/s] to a .npz
or .mat file: matrices A, B, C, D and the names and units of states (u [m/s], alpha [rad],
q [rad/s], theta [rad], eta_i [rad], eta_i_dot [rad/s]), input (w_g [m/s], up) and
outputs. In Python, bioflex_jsb.sinks.model_export.to_python_control gives a python-control
StateSpace with the same names."""


def register(sub) -> None:
    p = sub.add_parser("export", help="write the LTI model to .npz or .mat", description=HELP)
    add_wing_arguments(p)
    p.add_argument("--speed", type=positive_float("speed", "m/s"), required=True,
                   help="trim airspeed [m/s]")
    p.add_argument("--model", choices=("rigid", "coupled", "qsd"), default="coupled")
    p.add_argument("--out", required=True, metavar="FILE.npz|FILE.mat")
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.flight_dynamics.lti import build_state_space
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
    from bioflex_jsb.sinks.model_export import write_state_space

    build = wing_from_args(args)
    ss = build_state_space(args.model, level_flight_condition(args.speed), build.model)
    try:
        write_state_space(ss, args.out)
    except OSError as exc:
        raise UsageError(f"cannot write {args.out!r}: {exc.strerror}") from None
    info = {"out": args.out, "model": ss.model, "speed_m_s": ss.speed_m_s,
            "states": list(ss.states), "inputs": list(ss.inputs),
            "overrides": dict(build.model.coefficients.overrides)}
    if args.json:
        print_json(info)
    else:
        print(f"{ss.model} model of wing {build.variant.name} at {ss.speed_m_s:g} m/s "
              f"({len(ss.states)} states) written to {args.out}")
    return 0
