"""``bioflex-jsb flutter``: the lowest airspeed at which the coupled model goes unstable."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import add_wing_arguments, print_json, wing_from_args
from bioflex_jsb.flight_dynamics import eigen

HELP = """Scan the coupled model (Eq. 4) over --range in 0.1 m/s steps and bisect the first
root that crosses into the right half plane to 0.01 m/s (printed to 0.1 m/s). Reports the
speed [m/s], the mode that goes unstable, its frequency [rad/s] at the crossing and whether
it is an oscillatory flutter or a static divergence; null when nothing crosses in range.
The phugoid is left out, as in the paper (its linear model is unstable below ~10 m/s for the
rigid aircraft too)."""


def speed_range(text: str) -> tuple[float, float]:
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"range must be LOW:HIGH in m/s, e.g. 5:40, got {text!r}"
        ) from None
    if not (0.0 < lo < hi < 200.0):
        raise argparse.ArgumentTypeError(
            f"range must satisfy 0 < LOW < HIGH < 200 m/s, got {text!r}"
        )
    return lo, hi


def register(sub) -> None:
    p = sub.add_parser("flutter", help="flutter / divergence speed of the coupled model",
                       description=HELP)
    add_wing_arguments(p)
    p.add_argument("--range", type=speed_range, default=(5.0, 40.0), metavar="LOW:HIGH",
                   help="airspeed range to search [m/s], default 5:40")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    build = wing_from_args(args)
    res = eigen.find_flutter(build.model, args.range)
    payload = res.as_dict()
    payload["mass_basis"] = build.mass_basis
    payload["overrides"] = dict(build.model.coefficients.overrides)
    if res.flutter_speed_m_s is not None:
        payload["flutter_speed_m_s"] = round(res.flutter_speed_m_s, 1)
    if args.json:
        print_json(payload)
        return 0
    lo, hi = args.range
    if res.flutter_speed_m_s is None:
        print(f"wing {build.variant.name}: no instability between {lo:g} and {hi:g} m/s")
    else:
        print(f"wing {build.variant.name}: {res.kind} at {res.flutter_speed_m_s:.1f} m/s, "
              f"mode {res.mode}, frequency {res.frequency_rad_s:.2f} rad/s")
    return 0
