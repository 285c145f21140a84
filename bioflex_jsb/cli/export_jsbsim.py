"""``bioflex-jsb export-jsbsim``: the modal wing as JSBSim systems and an aircraft that flies it."""

from __future__ import annotations

import argparse
from pathlib import Path

from bioflex_jsb.cli.common import UsageError, add_wing_arguments, print_json, wing_from_args

HELP = """Write a JSBSim root under --out DIR: systems/bioflex_modal_<wing>.xml (the modal wing
integrated by JSBSim: each mode's structure exact, the aerodynamic coupling as a leapfrog kick)
and aircraft/bioflex_<wing>/ (the bioflex airframe including it, the modal loads in its
aerodynamics, with its trim companion). Fly it with `jsbsim --root=DIR
--aircraft=bioflex_<wing>`. The system holds for one time step, --dt [s] (default 1/960 s; a
step at which the integration's eigenvalues are more than 1 % off the exact ones up to 40 m/s
is refused, naming a halved step that is not); the trim lift coefficient and the reference
flow of the exact part are those of level flight at --speed [m/s]. See docs/native.md."""


def register(sub) -> None:
    from bioflex_jsb.generators.native_wing import EXPORT_MODELS
    from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

    p = sub.add_parser("export-jsbsim", help="write the modal wing as JSBSim systems",
                       description=HELP)
    add_wing_arguments(p)
    p.add_argument("--model", choices=EXPORT_MODELS, default="coupled")
    p.add_argument("--out", required=True, metavar="DIR", help="JSBSim root to write into")
    p.add_argument("--dt", type=float, default=DEFAULT_DT_S,
                   help=f"JSBSim step the system is exported for [s] (default {DEFAULT_DT_S:.6g})")
    p.add_argument("--speed", type=float, default=15.0,
                   help="trim airspeed of the trim lift coefficient and of the reference flow "
                        "[m/s] (default 15)")
    p.add_argument("--json", action="store_true", help="print what was written as JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.generators import native_wing as J
    from bioflex_jsb.generators.native_aircraft import export

    build = wing_from_args(args)
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise UsageError(f"--out {args.out!r} is not a directory")
    try:
        spec = J.ExportSpec(build.model, build.variant.name, args.model, args.dt, args.speed)
    except J.ExportError as exc:
        raise UsageError(str(exc)) from None
    try:
        written = export(spec, out)
    except OSError as exc:
        raise UsageError(f"cannot write into {args.out!r}: {exc.strerror or exc}") from None
    nums = J.modal_matrices(spec.wing, spec.cl_trim)
    info = {
        "out": str(out),
        "aircraft": J.aircraft_name(spec.variant, spec.model),
        "system": J.system_name(spec.variant, spec.model),
        "model": spec.model,
        "dt_s": spec.dt_s,
        "files": [str(p) for p in written],
    }
    if spec.model == "coupled":
        err, at = J.leapfrog_eigen_error(nums, spec.leapfrog(nums))
        info["eigenvalue_error_max"] = err
        info["eigenvalue_error_at_speed_m_s"] = at
    if args.json:
        print_json(info)
    else:
        print(f"{spec.model} modal wing {spec.variant!r} for a {spec.dt_s:.6g} s step: "
              f"aircraft {info['aircraft']} under {out} ({len(written)} files)")
    return 0
