"""``bioflex-jsb modes``: eigenvalues of the rigid, coupled and QSD models with mode identity."""

from __future__ import annotations

import argparse

import numpy as np

from bioflex_jsb.cli.common import (
    UsageError,
    add_wing_arguments,
    models_list,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.flight_dynamics import eigen

HELP = """Eigenvalues of the linear models at each --speed, every mode labelled by identity
(short_period, phugoid, aeroelastic_1..3). Labels follow each mode through a speed sweep
from 2 m/s by eigenvector correlation, so crossings do not swap them. Units: speeds in m/s;
eigenvalues (re, im) and frequencies in rad/s; damping ratio dimensionless. One entry per
conjugate pair (im >= 0); real roots are listed with im = 0."""


def register(sub) -> None:
    p = sub.add_parser("modes", help="labelled eigenvalues of the LTI models", description=HELP)
    add_wing_arguments(p)
    p.add_argument(
        "--speed", type=positive_float("speed", "m/s"), action="append", required=True,
        metavar="V", help="airspeed [m/s]; repeat for several speeds",
    )
    p.add_argument(
        "--models", type=models_list, default=("rigid", "coupled", "qsd"),
        help="comma-separated subset of rigid,coupled,qsd (default: all three)",
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument(
        "--plot", metavar="FILE.png",
        help="draw root loci from 5 m/s to the largest --speed (at least 25 m/s) to FILE.png",
    )
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    build = wing_from_args(args)
    results = []
    for model in args.models:
        sets = eigen.modes_at(model, args.speed, None if model == "rigid" else build.model)
        results.extend(sets)
    payload = {
        "wing": build.variant.name,
        "mass_basis": build.mass_basis,
        "overrides": dict(build.model.coefficients.overrides),
        "results": [s.as_dict() for s in results],
    }
    if args.plot:
        _plot(args, build)
    if args.json:
        print_json(payload)
        return 0
    print(f"wing {build.variant.name}  (mass basis {build.mass_basis}"
          + (f", overrides {payload['overrides']}" if payload["overrides"] else "") + ")")
    print(f"{'V [m/s]':>8} {'model':<8} {'mode':<14} {'re [rad/s]':>11} {'im [rad/s]':>11} "
          f"{'damping':>8} {'ω_n [rad/s]':>12}")
    for s in results:
        for m in s.modes:
            print(f"{s.speed_m_s:8.2f} {s.model:<8} {m.mode:<14} {m.re:11.3f} {m.im:11.3f} "
                  f"{m.damping:8.3f} {m.frequency_rad_s:12.3f}")
    if args.plot:
        print(f"root loci written to {args.plot}")
    return 0


def _plot(args, build) -> None:
    from bioflex_jsb.sinks import plotting

    top = max(25.0, max(args.speed))
    grid = np.arange(5.0, top + 1e-9, 0.5)
    sweeps = []
    for model in args.models:
        full = eigen.track(model, np.concatenate([np.arange(2.0, 5.0, 0.5), grid]),
                           None if model == "rigid" else build.model)
        k0 = int(np.searchsorted(full.speeds_m_s, 5.0))
        sweeps.append(eigen.Sweep(model, full.speeds_m_s[k0:], full.eigenvalues[k0:],
                                  full.labels, full.eigenvectors[k0:], full.wing,
                                  full.density_kg_m3))
    try:
        plotting.root_locus(sweeps, args.plot, f"wing {build.variant.name}")
    except OSError as exc:
        raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
