"""``bioflex-jsb flutter --controller FILE``: the flutter speed with a linear controller in the
loop, beside the open loop's by the same search
(:func:`bioflex_jsb.api.closed_loop_flutter`: the unsteady LTI model with the elevator, the
loop closed at the run's step with its one step of delay; docs/aeroelasticity.md, "Active
flutter suppression")."""

from __future__ import annotations

import argparse

from bioflex_jsb.cli.common import UsageError, print_json, wing_from_args

DEFAULT_RANGE_M_S = (10.0, 30.0)  # simulation/flutter_suppression.py's: where JSBSim trims


def check_controller_options(args: argparse.Namespace, clamped: bool) -> None:
    """Refuse (UsageError, one line) what the closed-loop search does not take."""
    if clamped:
        raise UsageError("--controller flies the free aircraft's elevator; a clamped wing has "
                         "none (drop --clamped)")
    if args.aero not in (None, "unsteady"):
        raise UsageError("--controller is analysed on unsteady strips (the model the "
                         "co-simulation flies with --aero unsteady): drop --aero quasi-steady")
    for flag, value in (("--structural-damping", args.structural_damping),
                        ("--density", args.density), ("--method", args.method),
                        ("--plot", args.plot)):
        if value is not None:
            raise UsageError(f"{flag} is not taken with --controller (the closed-loop search "
                             "is at sea level with the wing's own damping)")


def run_with_controller(args: argparse.Namespace) -> int:
    """Print the open- and closed-loop flutter speeds (text or ``--json``)."""
    from bioflex_jsb import api

    build = wing_from_args(args)
    rng = args.range or DEFAULT_RANGE_M_S
    ctrl = api.linear_controller(args.controller)
    open_loop = api.closed_loop_flutter(build, None, rng)
    closed = api.closed_loop_flutter(build, ctrl, rng)
    margin = None if None in (open_loop.speed_m_s, closed.speed_m_s) else \
        closed.speed_m_s - open_loop.speed_m_s
    payload = {"wing": build.variant.name, "aero": "unsteady", "controller": ctrl.name,
               "open_loop": open_loop.as_dict(), "closed_loop": closed.as_dict(),
               "margin_m_s": margin}
    if args.json:
        print_json(payload)
        return 0

    def line(name: str, res) -> str:
        if res.speed_m_s is not None:
            return (f"{name:12s} {res.speed_m_s:8.3f} m/s at {res.frequency_rad_s:.2f} rad/s "
                    f"({res.frequency_rad_s / 6.283185307179586:.2f} Hz)")
        if res.present_at_lower_end:
            return f"{name:12s} unstable at and below {res.range_m_s[0]:g} m/s"
        return f"{name:12s} none in {res.range_m_s[0]:g}-{res.range_m_s[1]:g} m/s"

    print(f"{build.variant.name} wing, unsteady strips, controller {ctrl.name} (the loop "
          "closed at 960 Hz with one step of delay; every root, the phugoid included)")
    print(line("open loop", open_loop))
    print(line("closed loop", closed))
    if margin is not None:
        print(f"margin {margin:+.3f} m/s ({100.0 * margin / open_loop.speed_m_s:+.1f} %)")
    return 0
