"""``bioflex-jsb linearize``: JSBSim's linear model of the rigid airframe at a trim."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import print_json
from bioflex_jsb.cli.trim import add_flight_condition_arguments, load_airframe

HELP = """Trim the rigid JSBSim airframe at --speed, linearize it with JSBSim's
FGLinearization and reduce the model to the paper's longitudinal states x_R = [u, alpha,
q, theta]: u the airspeed perturbation in m/s, alpha and theta in rad, q in rad/s (the
propeller RPM is eliminated as quasi-static, the lateral states are dropped). Units:
--speed in m/s, --altitude in m above sea level (default 0, ISA). A is printed row by row
(row i = d x_i/dt); eigenvalues (re, im) and natural frequencies in rad/s, damping ratio
dimensionless, one entry per conjugate pair (im >= 0), labelled short_period or phugoid by
frequency. JSON keys: speed_m_s, states, A, eigenvalues."""


def register(sub) -> None:
    p = sub.add_parser(
        "linearize", help="rigid longitudinal linear model from JSBSim", description=HELP
    )
    add_flight_condition_arguments(p)
    p.add_argument("--json", action="store_true", help="print JSON (SI) instead of a table")
    p.set_defaults(run=run)


def linearization_payload(lin) -> dict:
    """JSON form: exactly the keys speed_m_s, states, A, eigenvalues."""
    return {
        "speed_m_s": lin.speed_m_s,
        "states": list(lin.states),
        "A": [[float(x) for x in row] for row in lin.a],
        "eigenvalues": [
            {
                "mode": ev.mode,
                "re": ev.re,
                "im": ev.im,
                "damping": ev.damping,
                "frequency_rad_s": ev.frequency_rad_s,
            }
            for ev in lin.eigenvalues
        ],
    }


def run(args: argparse.Namespace) -> int:
    airframe = load_airframe(args)
    lin = airframe.linearize(args.speed, args.altitude)
    if args.json:
        print_json(linearization_payload(lin))
        return 0
    print(f"Rigid longitudinal model at {lin.speed_m_s:g} m/s (JSBSim FGLinearization)")
    header = "".join(f"{s:>12}" for s in lin.states)
    print(f"  A, x_R = [u m/s, alpha rad, q rad/s, theta rad]\n  {'':8}{header}")
    for name, row in zip(lin.states, lin.a, strict=True):
        print(f"  {name + ' dot':<8}" + "".join(f"{x:12.4g}" for x in row))
    print(f"  {'mode':<14}{'re':>10}{'im':>10}{'damping':>10}{'freq':>10}  [rad/s]")
    for ev in lin.eigenvalues:
        print(
            f"  {ev.mode:<14}{ev.re:10.3f}{ev.im:10.3f}{ev.damping:10.3f}{ev.frequency_rad_s:10.3f}"
        )
    return 0
