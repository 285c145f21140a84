"""Roll damping C_lp and aileron power C_lδa of three planforms by AeroSandbox's vortex
lattice, the independent reference of tests/test_roll_derivatives.py.

Not a dependency of the package (AeroSandbox pulls CasADi: a 93 MB wheel, 736 MB of
environment with its numpy/scipy/pandas/matplotlib, 1 min 42 s to install here): run it in
its own environment and copy the printed numbers into the test with the version line.

    python3 -m venv /tmp/asb && /tmp/asb/bin/pip install aerosandbox
    /tmp/asb/bin/python scripts/aerosandbox_roll_derivatives.py [--resolution N]

AeroSandbox (P. D. Sharpe, https://github.com/peterdsharpe/AeroSandbox, ``VortexLatticeMethod``):
horseshoe vortices on the camber surface, bound vortex at each panel's quarter chord,
collocation at its three-quarter chord, trailing legs along x. Its C_lp is its own finite
difference in p (``run_with_stability_derivatives``: per p̂ = p b/(2V), body axes, positive
roll right). The aileron is geometry there, not an angle: each wing half is its own
``Wing`` per span segment, the aileron segments carry an aerofoil whose camber line is the
flat plate hinged at ``hinge`` (the trailing edge deflected by ±δ, a chordwise panel
edge on the hinge), starboard up and port down; C_lδa is the central difference of Cl in δ
(±1°); ``cl_delta_a_twist`` the same with the aileron segments' whole chord turned τ δ
instead (the project lattice's model of the surface: the two lattices compared on one
loading). The planforms, stations and ailerons are those of the test (CASES below).
"""

from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

# name: (stations y [m], chords [m], leading edges x [m]) of the half wing, aileron
# (start, end) [m] and hinge [chord fraction]; every aileron end is a station.
CASES = {
    # rectangular, aspect ratio 6, an outer-half aileron of 25 % chord
    "rectangular_ar6": ([0.0, 1.5, 3.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0], (1.5, 3.0), 0.75),
    # straight taper λ = 0.5, aspect ratio 8 (S = 8 m², b = 8 m), unswept quarter-chord line,
    # a 30 %-chord aileron from 60 to 95 % of the semispan
    "tapered_ar8": ([0.0, 2.4, 3.8, 4.0],
                    [4.0 / 3.0, 4.0 / 3.0 * (1 - 0.5 * 0.6), 4.0 / 3.0 * (1 - 0.5 * 0.95),
                     2.0 / 3.0],
                    [0.0, (4.0 / 3.0) * 0.5 * 0.6 / 4.0, (4.0 / 3.0) * 0.5 * 0.95 / 4.0,
                     (4.0 / 3.0 - 2.0 / 3.0) / 4.0], (2.4, 3.8), 0.7),
    # the prototype's planform (parameters/wing.py DEFAULT_PLANFORM: b = 1.7 m, c = 0.183 m,
    # the outer 55 % swept back 20° at the leading edge) with its definitions' aileron
    # (span 0.6-1.0 of the semispan, hinge 0.75: data/aircraft/bioflex_*.toml)
    "prototype": ([0.0, 0.3825, 0.51, 0.85], [0.183] * 4,
                  [0.0, 0.0, (0.51 - 0.3825) * math.tan(math.radians(20.0)),
                   (0.85 - 0.3825) * math.tan(math.radians(20.0))], (0.51, 0.85), 0.75),
}
DELTA_DEG = 1.0  # aileron deflection of the central difference [deg]
# chordwise panels, uniform: a panel edge on every hinge of CASES (0.7, 0.75)
CHORDWISE_PANELS = 20


def flap_airfoil(asb, hinge: float, delta_rad: float, model: str = "flap"):
    """A thin plate (thickness 1e-6 c) whose camber line is flat to ``hinge`` and turns
    ``delta_rad`` trailing edge down beyond it (negative: up); ``model`` ``twist``: the
    whole chord turned τ δ about the leading edge instead (τ = c_lδ/2π of the hinge,
    thin-aerofoil: the project lattice's model of the surface)."""
    x = np.unique(np.concatenate([np.linspace(0.0, 1.0, 41), [hinge]]))
    if model == "twist":
        th = math.acos(1.0 - 2.0 * hinge)
        tau = 2.0 * (math.pi - th + math.sin(th)) / (2.0 * math.pi)
        z = -x * math.tan(tau * delta_rad)
    else:
        z = np.where(x > hinge, -(x - hinge) * math.tan(delta_rad), 0.0)
    t = 1e-6
    upper = np.column_stack([x[::-1], (z + t)[::-1]])
    lower = np.column_stack([x[1:], (z - t)[1:]])
    return asb.Airfoil(name=f"flap{delta_rad:+.4f}", coordinates=np.vstack([upper, lower]))


def airplane(asb, case, delta_rad: float = 0.0, model: str = "flap"):
    """The whole wing as AeroSandbox wings, one per span segment and side (xsecs in
    increasing y on both sides), aileron segments cambered ±``delta_rad``."""
    ys, cs, xs, (a0, a1), hinge = case
    flat = flap_airfoil(asb, hinge, 0.0)
    wings = []
    for i in range(len(ys) - 1):
        on_aileron = ys[i] >= a0 - 1e-12 and ys[i + 1] <= a1 + 1e-12
        for side in (1.0, -1.0):
            # starboard trailing edge up (δ < 0 camber), port down: roll to the right
            foil = flap_airfoil(asb, hinge, -side * delta_rad, model) if on_aileron else flat
            idx = [i, i + 1] if side > 0 else [i + 1, i]
            xsecs = [asb.WingXSec(xyz_le=[xs[k], side * ys[k], 0.0], chord=cs[k], airfoil=foil)
                     for k in idx]
            wings.append(asb.Wing(name=f"seg{i}{'s' if side > 0 else 'p'}", xsecs=xsecs,
                                  symmetric=False))
    area = 2.0 * sum(0.5 * (cs[k] + cs[k + 1]) * (ys[k + 1] - ys[k]) for k in range(len(ys) - 1))
    span = 2.0 * ys[-1]
    return asb.Airplane(name="wing", xyz_ref=[0.0, 0.0, 0.0], wings=wings, s_ref=area,
                        b_ref=span, c_ref=area / span)


def vlm(asb, plane, alpha_deg: float, resolution: int):
    return asb.VortexLatticeMethod(
        airplane=plane, op_point=asb.OperatingPoint(velocity=10.0, alpha=alpha_deg),
        spanwise_resolution=resolution, chordwise_resolution=CHORDWISE_PANELS,
        chordwise_spacing_function=np.linspace)


def derivatives(asb, case, resolution: int) -> dict:
    """C_Lα, C_lp, C_lδa [per rad] of ``case`` at ``resolution`` panels per segment."""
    base = vlm(asb, airplane(asb, case), 0.0, resolution)
    stab = base.run_with_stability_derivatives(alpha=True, beta=False, p=True, q=False,
                                               r=False)
    d = math.radians(DELTA_DEG)
    out = {"cl_alpha": float(stab["CLa"]), "cl_p": float(stab["Clp"])}
    for model, key in (("flap", "cl_delta_a"), ("twist", "cl_delta_a_twist")):
        cl_plus = vlm(asb, airplane(asb, case, d, model), 0.0, resolution).run()["Cl"]
        cl_minus = vlm(asb, airplane(asb, case, -d, model), 0.0, resolution).run()["Cl"]
        out[key] = float((cl_plus - cl_minus) / (2.0 * d))
    return out


def main(argv=None) -> int:
    import aerosandbox as asb

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--resolution", type=int, action="append",
                   help="spanwise panels per segment (repeatable; default 16 and 32)")
    p.add_argument("--case", action="append", choices=tuple(CASES),
                   help="the planforms (repeatable; default all)")
    args = p.parse_args(argv)
    out = {"aerosandbox": asb.__version__, "chordwise_panels": CHORDWISE_PANELS,
           "delta_deg": DELTA_DEG,
           "cases": {}}
    for name in args.case or CASES:
        out["cases"][name] = {str(n): derivatives(asb, CASES[name], n)
                              for n in (args.resolution or [16, 32])}
    json.dump(out, sys.stdout, indent=1)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
