"""The pre-flight stability check of the commands that fly a session (``ardupilot``,
``sitl``): the chosen model's roots at the trim speed, refused in one line when one grows
unless ``--allow-unstable``."""

from __future__ import annotations

import argparse

NATIVE = "native"
# DEFINITION: a root is unstable when Re(lambda) exceeds this [1/s] (the flutter search's
# threshold, bioflex_jsb.flight_dynamics.eigen.find_flutter / free_aircraft.GROWTH_TOL_1_S).
GROWTH_TOL_1_S = 1e-9
PREFLIGHT_GRID_STEP_M_S = 0.5  # mode tracking from 2 m/s to the trim speed (labels only)


def add_allow_unstable(p: argparse.ArgumentParser) -> None:
    p.add_argument("--allow-unstable", action="store_true",
                   help="fly a model that is unstable at the trim speed (refused otherwise)")


def preflight(build, model: str, aero: str, speed_m_s: float) -> dict:
    """The chosen model's stability at the trim speed ``speed_m_s`` [m/s], phugoid left out
    (the autopilot flies it; the flutter search leaves it out too).

    Quasi-steady: the labelled eigenvalues of the linear model (``api.modes``; ``native``
    is the coupled wing JSBSim carries, ``rigid`` the short period alone). Unsteady (coupled
    only): Eq. 4 with the Jones lag states (``aeroelasticity.free_aircraft.track_free``).
    Returns ``stable``, the unstable roots (mode, Re [1/s], Im [rad/s]) and the largest
    growth rate [1/s] of the roots considered."""
    import numpy as np

    from bioflex_jsb import api

    if aero == "unsteady":
        from bioflex_jsb.aeroelasticity.free_aircraft import EXCLUDED, track_free

        grid = np.append(np.arange(2.0, speed_m_s, PREFLIGHT_GRID_STEP_M_S), speed_m_s)
        tr = track_free(build, grid, aero="unsteady")
        roots = [(lab, float(lam.real), float(lam.imag))
                 for lab, lam in zip(tr.labels, tr.eigenvalues[-1], strict=True)
                 if lab not in EXCLUDED]
    else:
        lti = "coupled" if model == NATIVE else model
        roots = [(m.mode, float(m.re), float(m.im)) for m in api.modes(build, speed_m_s, lti).modes
                 if m.mode != "phugoid"]
    unstable = sorted((r for r in roots if r[1] > GROWTH_TOL_1_S), key=lambda r: -r[1])
    return {"model": model, "aero": aero, "speed_m_s": speed_m_s, "stable": not unstable,
            "max_growth_1_s": max(r[1] for r in roots),
            "unstable": [{"mode": m, "re_1_s": re, "im_rad_s": im} for m, re, im in unstable]}


def refusal(args: argparse.Namespace, build, check: dict) -> str:
    """The one line that refuses an unstable model (``args``: wing, speed, aero, model),
    with the speeds that say why and, for the quasi-steady coupled wing, whether the
    unsteady strips fly it."""
    from bioflex_jsb import api
    from bioflex_jsb.aeroelasticity.free_aircraft import free_flutter

    worst = check["unstable"][0]
    text = (f"--wing {args.wing} cannot be flown at {args.speed:g} m/s with the {args.aero} "
            f"{args.model} wing: its {worst['mode']} root is unstable there "
            f"(Re = {worst['re_1_s']:+.3g} 1/s)")
    if args.model in ("coupled", NATIVE):
        first = api.flutter(build, aero="quasi-steady").flutter_speed_m_s \
            if args.aero == "quasi-steady" \
            else free_flutter(build, aero="unsteady").speed_m_s
        if first is not None:
            text += f"; its {args.aero} flutter speed is {first:.1f} m/s"
        if args.aero == "quasi-steady":
            other = free_flutter(build, aero="unsteady").speed_m_s
            if other is None or other > args.speed:
                how = "--aero unsteady" if args.model == "coupled" else \
                    "--model coupled --aero unsteady"
                stable_to = "up to 40 m/s" if other is None else f"to {other:.1f} m/s"
                text += f"; try {how} (stable {stable_to})"
    return text + "; --allow-unstable flies it anyway"


def checked(args: argparse.Namespace, build, usage_error) -> dict:
    """:func:`preflight` of ``args.model``/``args.aero`` at ``args.speed``, with
    ``allowed_unstable``; raises ``usage_error(refusal)`` for an unstable model without
    ``args.allow_unstable``."""
    check = preflight(build, args.model, args.aero, args.speed)
    check["allowed_unstable"] = bool(args.allow_unstable)
    if not check["stable"] and not args.allow_unstable:
        raise usage_error(refusal(args, build, check))
    return check
