"""``bioflex-jsb export``: write the LTI model with named states, inputs, outputs and units."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.case import (
    DEFAULT_SPEED_M_S,
    DEFAULT_WING,
    SPEED_RANGE_TEXT,
    add_force_argument,
    aircraft_speeds,
    airspeed,
    speed_help,
)
from bioflex_jsb.cli.common import (
    UsageError,
    add_wing_arguments,
    check_output,
    print_json,
    wing_from_args,
)

HELP = f"""Write the rigid, coupled (Eq. 4) or QSD (Eq. 9-10) model at --speed [m/s] to a .npz
or .mat file: matrices A, B, C, D and the names and units of its signals. States: u [m/s],
alpha [rad], q [rad/s], theta [rad], eta_i [rad], eta_i_dot [rad/s] (QSD: the four rigid
states). Inputs: w_g [m/s] (vertical gust, up), elevator [rad] (+ trailing edge down) and
throttle [-] (fraction of the motor's maximum shaft power). Outputs: the states (QSD: and
its quasi-static eta_i [rad]), n_z [-] (load-factor perturbation, up; q is the pitch rate)
and, for the coupled and QSD models, tip_twist [rad] (wing tip section twist, leading edge
up; the rigid model has no wing to twist). The file's "metadata" entry
(JSON text) records the wing, speed, mass basis, aerodynamic model and overrides. Read it
back in Python with bioflex_jsb.sinks.model_export.read_state_space(path), or as a
python-control StateSpace with to_python_control(path) (pip install ".[control]").
Valid range: --speed {SPEED_RANGE_TEXT}. Default: the {DEFAULT_WING} wing at
{DEFAULT_SPEED_M_S:g} m/s (the paper's Fig. 21 case). An existing --out is replaced only if
it is a model file bioflex-jsb wrote, else give --force. --axis lateral writes the
lateral-directional model instead (api.lateral_model, docs/lateral.md): states beta [rad],
p [rad/s], r [rad/s], phi [rad] and, coupled, the antisymmetric modes eta_i [rad],
eta_i_dot [rad/s]; inputs v_g [m/s] (lateral gust), aileron, rudder [rad]; outputs the
states (QSD: and its quasi-static eta_i) and n_y [-]."""


def register(sub) -> None:
    p = sub.add_parser("export", help="write the LTI model to .npz or .mat", description=HELP)
    add_wing_arguments(p, default=DEFAULT_WING)
    p.add_argument("--speed", type=airspeed, default=None, metavar="V",
                   help="trim " + speed_help(extra="; an --aircraft's own cruise speed"))
    p.add_argument("--model", choices=("rigid", "coupled", "qsd"), default="coupled",
                   help="which linear model (default coupled)")
    p.add_argument("--axis", choices=("longitudinal", "lateral"), default="longitudinal",
                   help="longitudinal (default: Eq. 4) or lateral (the lateral-directional "
                   "model of the aircraft's JSBSim airframe and the wing's antisymmetric "
                   "modes)")
    from bioflex_jsb.cli.lateral_options import add_lateral_aero_argument

    add_lateral_aero_argument(p, "; with --axis lateral")
    p.add_argument("--out", required=True, metavar="FILE.npz|FILE.mat",
                   help="the model file (required)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(run=run)


def _is_our_model(path) -> bool:
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.sinks.model_export import read_state_space

    try:
        return str(read_state_space(path).notes.get("software", "")).startswith("bioflex-jsb")
    except InputError:
        return False


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb import __version__, api
    from bioflex_jsb.sinks.model_export import FORMATS, write_state_space

    if not args.out.endswith(FORMATS):
        raise UsageError(f"unknown model file type of {args.out!r}; accepted: "
                         f"{', '.join(FORMATS)}")
    check_output(args.out, args.force, "model file", ours=_is_our_model)
    from bioflex_jsb.cli.lateral_options import check_lateral_aero

    check_lateral_aero(args, args.axis == "lateral", "give --axis lateral")
    build = wing_from_args(args)
    if args.speed is None:
        args.speed = aircraft_speeds(args)[0]
    if args.axis == "lateral":  # its JSBSim airframe's trim (api.lateral_model)
        aircraft = getattr(args, "aircraft_definition", None)
        ss = api.lateral_model(aircraft if aircraft is not None else build, args.speed,
                               args.model, lateral_aero=args.lateral_aero)
    else:  # the API's model (one builder): the wing's own aircraft (its S, mass, derivatives)
        ss = api.linear_model(build, args.speed, args.model)
    metadata = {"software": f"bioflex-jsb {__version__}", "wing": build.variant.name,
                "wing_variant": build.variant.as_dict(), "speed_m_s": args.speed,
                "mass_basis": build.mass_basis, "model": args.model, "axis": args.axis,
                "altitude_m": float(ss.notes.get("altitude_m", 0.0)),
                "overrides": dict(build.model.coefficients.overrides)}
    if args.lateral_aero is not None:  # the default's metadata unchanged
        metadata["lateral_aero"] = args.lateral_aero
    try:
        write_state_space(ss, args.out, metadata)
    except OSError as exc:
        raise UsageError(f"cannot write {args.out!r}: {exc.strerror}") from None
    info = {"out": args.out, "model": ss.model, "wing": build.variant.name,
            "speed_m_s": ss.speed_m_s, "mass_basis": build.mass_basis,
            "states": list(ss.states), "inputs": list(ss.inputs),
            "input_units": list(ss.input_units), "outputs": list(ss.outputs),
            "output_units": list(ss.output_units),
            "aerodynamics": ss.notes.get("aerodynamics"),
            "overrides": dict(build.model.coefficients.overrides),
            **({} if args.lateral_aero is None else {"lateral_aero": args.lateral_aero})}
    if args.json:
        print_json(info)
    else:
        print(f"{ss.model} model of wing {build.variant.name} at {ss.speed_m_s:g} m/s "
              f"(mass basis {build.mass_basis}; {len(ss.states)} states; inputs "
              f"{', '.join(f'{n} [{u}]' for n, u in zip(ss.inputs, ss.input_units, strict=True))};"
              f" {len(ss.outputs)} outputs: {', '.join(ss.outputs)}) written to {args.out}")
    return 0
