"""``bioflex-jsb flutter``: the lowest airspeed at which a wing goes unstable.

Two analyses, chosen by --wing and --clamped (docs/aeroelasticity.md):

* a paper wing (``original``, ``optimised``, ... or a variant file), free aircraft: the
  coupled model of Eq. (4) on the paper's quasi-steady strips (Table B1), eigen-analysis with
  mode tracking (:func:`bioflex_jsb.flight_dynamics.eigen.find_flutter`);
* ``--wing goland --clamped``: the Goland benchmark cantilever without a rigid body
  (:mod:`bioflex_jsb.aeroelasticity`), unsteady (Theodorsen) or quasi-steady strips with the
  2-D (2π) or vortex-lattice lift slope, by p-k or by state-space eigen-analysis.

Combinations that are not available are refused with one line (exit 2) naming what is.
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

import numpy as np

from bioflex_jsb.cli.common import UsageError, add_wing_arguments, print_json, wing_from_args

BENCHMARK_WINGS = ("goland",)
AERO_CHOICES = ("unsteady", "quasi-steady")
METHOD_CHOICES = ("pk", "state-space")
LIFT_SLOPE_CHOICES = ("strip", "vlm")
INERTIA_CHOICES = ("elastic-axis", "centre-of-mass")
MAX_SPEED_M_S = 400.0  # upper end of --range [m/s]
MAX_DENSITY_KG_M3 = 2.0  # upper end of --density [kg/m³]
PAPER_DEFAULT_RANGE_M_S = (5.0, 40.0)
GOLAND_DEFAULT_RANGE_M_S = (20.0, 260.0)

HELP = """Flutter (oscillatory) or static divergence: the first root that crosses into the
right half plane in --range. Reports the speed [m/s], the frequency of the crossing root
[rad/s], its reduced frequency k = omega*b/V [-] (b the semichord [m]), the unstable mode,
the mechanism (coalescence with another branch and which, single-mode, or static
divergence) and the wind-off natural frequencies [rad/s]; null when nothing crosses.

Paper wings (free aircraft, Eq. 4): --aero quasi-steady (default; the paper's strips) or
unsteady (Theodorsen strips with two Jones lag states per strip added to Eq. 4;
docs/aeroelasticity.md), eigen-analysis (--method state-space) scanned in 0.1 m/s steps
from 2 m/s with mode tracking and bisected (printed to 0.1 m/s); the phugoid is left out,
as in the paper; with unsteady strips also the wing's divergence speed with the body held.
Not available for them: --clamped, --method pk, --lift-slope, --inertia-about.

--wing goland --clamped: the Goland cantilever (semi-span 6.096 m, chord 1.8288 m; data and
published results with citations in bioflex_jsb/parameters/goland.py), published strip
theory result 137.2 m/s, 70.7 rad/s (Goland 1945, as tabulated by Patil, Hodges & Cesnik
2001). Defaults: --aero unsteady, --method pk, --lift-slope strip, --structural-damping 0,
--inertia-about elastic-axis, --density 1.225 kg/m^3 (the issue's literal reading of the
data is --inertia-about centre-of-mass --density 1.02)."""


def speed_range(text: str) -> tuple[float, float]:
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"range must be LOW:HIGH in m/s, e.g. 5:40, got {text!r}"
        ) from None
    if not (0.0 < lo < hi <= MAX_SPEED_M_S):
        raise argparse.ArgumentTypeError(
            f"range must satisfy 0 < LOW < HIGH <= {MAX_SPEED_M_S:g} m/s, got {text!r}"
        )
    return lo, hi


def damping_ratio(text: str) -> float:
    try:
        z = float(text)
    except ValueError:
        z = math.nan
    if not (0.0 <= z < 1.0):
        raise argparse.ArgumentTypeError(
            f"structural damping must be a ratio 0 <= Z < 1 (e.g. 0.02), got {text!r}")
    return z


def density(text: str) -> float:
    try:
        rho = float(text)
    except ValueError:
        rho = math.nan
    if not (0.0 < rho <= MAX_DENSITY_KG_M3):
        raise argparse.ArgumentTypeError(
            f"density must satisfy 0 < RHO <= {MAX_DENSITY_KG_M3:g} kg/m^3, got {text!r}")
    return rho


def register(sub) -> None:
    p = sub.add_parser("flutter", help="flutter / divergence speed (free aircraft or clamped "
                       "benchmark wing)", description=HELP)
    add_wing_arguments(p)
    wing_action = p._option_string_actions["--wing"]
    wing_action.help = (f"{wing_action.help}; or the benchmark wing {', '.join(BENCHMARK_WINGS)} "
                        "(with --clamped)")
    p.add_argument("--clamped", action="store_true",
                   help="clamped cantilever without the rigid body (--wing goland only)")
    p.add_argument("--aero", choices=AERO_CHOICES, default=None,
                   help="strip aerodynamics: unsteady (Theodorsen C(k); Jones lag states in "
                   "state-space) or quasi-steady (C = 1); default unsteady for --clamped, "
                   "quasi-steady (the paper's) for paper wings")
    p.add_argument("--method", choices=METHOD_CHOICES, default=None,
                   help="pk (frequency domain, --clamped only) or state-space "
                   "(eigen-analysis with mode tracking); default pk for --clamped, "
                   "state-space for paper wings")
    p.add_argument("--structural-damping", type=damping_ratio, default=None, metavar="Z",
                   help="viscous modal damping ratio zeta [-], 0 <= Z < 1, on every mode "
                   "(2 zeta omega_i); default 0 for --clamped, the variant's (0.02) for paper "
                   "wings")
    p.add_argument("--lift-slope", choices=LIFT_SLOPE_CHOICES, default=None,
                   help="strip lift slope, --clamped only: strip (2 pi on every strip, "
                   "default) or vlm (the vortex lattice's spanwise C_la(y))")
    p.add_argument("--inertia-about", choices=INERTIA_CHOICES, default=None,
                   help="axis of the Goland wing's published 8.64 kg m (--wing goland only): "
                   "elastic-axis (default) or centre-of-mass (the issue's wording)")
    p.add_argument("--density", type=density, default=None, metavar="RHO",
                   help=f"air density [kg/m^3], 0 < RHO <= {MAX_DENSITY_KG_M3:g}; default "
                   "1.225 (sea level)")
    p.add_argument("--range", type=speed_range, default=None, metavar="LOW:HIGH",
                   help=f"airspeed range to search [m/s], 0 < LOW < HIGH <= "
                   f"{MAX_SPEED_M_S:g}; default {PAPER_DEFAULT_RANGE_M_S[0]:g}:"
                   f"{PAPER_DEFAULT_RANGE_M_S[1]:g} for paper wings, "
                   f"{GOLAND_DEFAULT_RANGE_M_S[0]:g}:{GOLAND_DEFAULT_RANGE_M_S[1]:g} for "
                   "--clamped")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def check_combination(args: argparse.Namespace) -> None:
    """Refuse (UsageError, one line) what is not available for the chosen wing."""
    benchmark = args.wing in BENCHMARK_WINGS
    if benchmark:
        if not args.clamped:
            raise UsageError(f"--wing {args.wing} is a benchmark cantilever with no aircraft "
                             f"around it: give --clamped (accepted: --wing {args.wing} "
                             "--clamped)")
        return
    if args.clamped:
        raise UsageError(f"--clamped is available for the benchmark wing "
                         f"{', '.join(BENCHMARK_WINGS)} only; paper wings are analysed as the "
                         "free aircraft (drop --clamped)")
    if args.method == "pk":
        raise UsageError("--method pk is available with --wing goland --clamped only; paper "
                         "wings accept --method state-space")
    for flag, value in (("--lift-slope", args.lift_slope),
                        ("--inertia-about", args.inertia_about)):
        if value is not None:
            raise UsageError(f"{flag} is available with --wing goland --clamped only; paper "
                             "wings take the vortex lattice's span loading (Table B1)")


def run(args: argparse.Namespace) -> int:
    check_combination(args)
    if args.wing in BENCHMARK_WINGS:
        payload = goland_payload(args)
    else:
        payload = paper_payload(args)
    if args.json:
        print_json(payload)
        return 0
    print(text_report(payload))
    return 0


def _round(x: float | None, digits: int) -> float | None:
    return None if x is None else round(float(x), digits)


def goland_payload(args: argparse.Namespace) -> dict:
    """The clamped Goland wing's flutter point beside the published one."""
    from bioflex_jsb.aeroelasticity import goland_flutter
    from bioflex_jsb.parameters import goland as G

    aero = args.aero or "unsteady"
    method = args.method or "pk"
    lift_slope = args.lift_slope or "strip"
    zeta = 0.0 if args.structural_damping is None else args.structural_damping
    axis = args.inertia_about or G.DEFAULT_INERTIA_AXIS
    rho = G.FLUTTER_DENSITY_KG_M3 if args.density is None else args.density
    lo, hi = args.range or GOLAND_DEFAULT_RANGE_M_S
    res = goland_flutter(aero=aero, lift_slope=lift_slope, method=method,
                         structural_damping=zeta, speed_range_m_s=(lo, hi),
                         inertia_about=axis, density_kg_m3=rho)
    d = res.as_dict()
    kind = None
    if res.mechanism is not None:
        kind = "divergence" if res.mechanism == "static divergence" else "flutter"
    comparable = aero == "unsteady" and lift_slope == "strip" and zeta == 0.0
    pub_v, pub_w = G.PUBLISHED_FLUTTER_SPEED_M_S, G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S

    def rel(x, ref):
        return None if x is None else round(float(x) / ref - 1.0, 4)

    return {
        "wing": "goland",
        "clamped": True,
        "aero": aero,
        "method": method,
        "lift_slope": lift_slope,
        "structural_damping": zeta,
        "inertia_about": axis,
        "density_kg_m3": rho,
        "range_m_s": [lo, hi],
        "flutter_speed_m_s": _round(res.speed_m_s, 2),
        "frequency_rad_s": _round(res.frequency_rad_s, 2),
        "reduced_frequency": _round(res.reduced_frequency, 4),
        "semichord_m": G.CHORD_M / 2.0,
        "mode": res.mode,
        "partner_mode": res.partner_mode,
        "mechanism": res.mechanism,
        "kind": kind,
        "divergence_speed_m_s": _round(d["divergence_speed_m_s"], 2),
        "natural_frequencies_rad_s": [round(w, 2) for w in res.natural_frequencies_rad_s],
        "mode_labels": list(res.mode_labels),
        "published": {
            "flutter_speed_m_s": pub_v,
            "frequency_rad_s": pub_w,
            "natural_frequencies_rad_s": list(G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S),
            "source": G.PUBLISHED_SOURCE,
            "applies_to": "--aero unsteady --lift-slope strip --structural-damping 0",
            "comparable": comparable,
            "speed_rel_diff": rel(res.speed_m_s, pub_v) if comparable else None,
            "frequency_rel_diff": rel(res.frequency_rad_s, pub_w) if comparable else None,
        },
    }


def paper_payload(args: argparse.Namespace) -> dict:
    """The free aircraft's first instability (Eq. 4, quasi-steady strips)."""
    from bioflex_jsb.flight_dynamics import eigen
    from bioflex_jsb.parameters import prototype as P

    build = wing_from_args(args)
    model = build.model
    if args.structural_damping is not None:
        model = replace(model, damping_ratios=np.full(model.n_modes, args.structural_damping))
    rho = P.SEA_LEVEL_DENSITY_KG_M3 if args.density is None else args.density
    lo, hi = args.range or PAPER_DEFAULT_RANGE_M_S
    if args.aero == "unsteady":
        return paper_unsteady_payload(args, build, model, rho, (lo, hi))
    res = eigen.find_flutter(model, (lo, hi), density_kg_m3=rho)
    payload = res.as_dict()
    mech, partner = None, None
    k_red = None
    b = P.MEAN_AERODYNAMIC_CHORD_M / 2.0
    if res.flutter_speed_m_s is not None:
        mech, partner = paper_mechanism(model, res, rho)
        k_red = round(res.frequency_rad_s * b / res.flutter_speed_m_s, 4)
        payload["flutter_speed_m_s"] = round(res.flutter_speed_m_s, 1)
    payload.update(
        clamped=False,
        aero="quasi-steady",
        method="state-space",
        structural_damping=[float(z) for z in model.damping_ratios],
        density_kg_m3=rho,
        reduced_frequency=k_red,
        semichord_m=b,
        mechanism=mech,
        partner_mode=partner,
        natural_frequencies_rad_s=[round(float(w), 2) for w in model.frequencies_rad_s],
        mass_basis=build.mass_basis,
        overrides=dict(model.coefficients.overrides),
    )
    return payload


def paper_mechanism(model, res, density_kg_m3: float) -> tuple[str, str | None]:
    """Mechanism of the free aircraft's crossing by the rule of
    :class:`bioflex_jsb.aeroelasticity.free_aircraft.FreeFlutter` (static divergence,
    body-freedom, coalescence within ``COALESCENCE_RELATIVE_GAP``, single-mode), on the
    tracked roots of :func:`bioflex_jsb.flight_dynamics.eigen.track` at the crossing."""
    from bioflex_jsb.aeroelasticity.free_aircraft import COALESCENCE_RELATIVE_GAP
    from bioflex_jsb.flight_dynamics import eigen

    if res.kind == "divergence":
        return "static divergence", None
    if res.mode in eigen.RIGID_LABELS:
        return "body-freedom", None
    v = float(res.flutter_speed_m_s)
    grid = np.unique(np.append(np.arange(min(2.0, v), v, 0.1), v))
    last = eigen.track("coupled", grid, model, density_kg_m3).at(len(grid) - 1)
    names = [n for n in dict.fromkeys(m.mode for m in last.modes)
             if n not in eigen.EXCLUDED_FROM_FLUTTER and n != res.mode]
    w_u = float(res.frequency_rad_s)
    gaps = {n: abs(last.get(n).im - w_u) / w_u for n in names}
    nearest = min(gaps, key=gaps.get)
    if gaps[nearest] < COALESCENCE_RELATIVE_GAP:
        return "coalescence", nearest
    return "single-mode", None


def paper_unsteady_payload(args, build, model, rho: float, range_m_s) -> dict:
    """The free aircraft on unsteady strips (Eq. 4 + Jones lag states,
    :mod:`bioflex_jsb.aeroelasticity.free_aircraft`)."""
    from bioflex_jsb.aeroelasticity.free_aircraft import free_flutter
    from bioflex_jsb.parameters import prototype as P

    res = free_flutter(build, aero="unsteady", structural_damping=args.structural_damping,
                       range_m_s=range_m_s, density_kg_m3=rho)
    b = P.MEAN_AERODYNAMIC_CHORD_M / 2.0
    speed = res.speed_m_s
    kind = None
    if res.mechanism is not None:
        kind = "divergence" if res.mechanism == "static divergence" else "flutter"
    return {
        "wing": build.variant.name,
        "flutter_speed_m_s": None if speed is None else round(speed, 1),
        "mode": res.mode,
        "frequency_rad_s": res.frequency_rad_s,
        "kind": kind,
        "range_m_s": list(range_m_s),
        "clamped": False,
        "aero": "unsteady",
        "method": "state-space",
        "structural_damping": [float(z) for z in model.damping_ratios],
        "density_kg_m3": rho,
        "reduced_frequency": None if speed is None else round(
            res.frequency_rad_s * b / speed, 4),
        "semichord_m": b,
        "mechanism": res.mechanism,
        "partner_mode": res.partner_mode,
        "wing_divergence_speed_m_s": None if res.wing_divergence_speed_m_s is None else round(
            res.wing_divergence_speed_m_s, 2),
        "natural_frequencies_rad_s": [round(float(w), 2) for w in model.frequencies_rad_s],
        "mass_basis": build.mass_basis,
        "overrides": dict(model.coefficients.overrides),
    }


def text_report(p: dict) -> str:
    head = f"wing {p['wing']}" + (" (clamped)" if p["clamped"] else "")
    setup = f"{p['aero']}, {p['method']}"
    if p["clamped"]:
        setup += f", lift slope {p['lift_slope']}, rho {p['density_kg_m3']:g} kg/m^3"
    zeta = p["structural_damping"]
    zeta_text = f"{zeta:g}" if isinstance(zeta, float) else ", ".join(f"{z:g}" for z in zeta)
    setup += f", zeta {zeta_text}"
    nat = ", ".join(f"{w:.2f}" for w in p["natural_frequencies_rad_s"])
    lines = [f"{head}: {setup}", f"  natural frequencies [rad/s]: {nat}"]
    lo, hi = p["range_m_s"]
    if p["flutter_speed_m_s"] is None:
        lines.append(f"  no instability between {lo:g} and {hi:g} m/s")
    else:
        partner = f" with {p['partner_mode']}" if p.get("partner_mode") else ""
        lines.append(
            f"  {p['kind']} at {p['flutter_speed_m_s']:.1f} m/s, mode {p['mode']}, frequency "
            f"{p['frequency_rad_s']:.2f} rad/s, k = {p['reduced_frequency']:.3f}, mechanism "
            f"{p['mechanism']}{partner}")
    pub = p.get("published")
    if pub is not None:
        line = (f"  published: {pub['flutter_speed_m_s']} m/s, {pub['frequency_rad_s']} rad/s "
                f"({pub['source']})")
        if pub["comparable"] and pub["speed_rel_diff"] is not None:
            line += (f"; model {100 * pub['speed_rel_diff']:+.1f} % speed, "
                     f"{100 * pub['frequency_rel_diff']:+.1f} % frequency")
        elif not pub["comparable"]:
            line += f"; applies to {pub['applies_to']}"
        lines.append(line)
    if p.get("divergence_speed_m_s") is not None:
        lines.append(f"  static divergence at {p['divergence_speed_m_s']:.1f} m/s")
    if p.get("wing_divergence_speed_m_s") is not None:
        lines.append(f"  wing divergence with the body held at "
                     f"{p['wing_divergence_speed_m_s']:.1f} m/s")
    return "\n".join(lines)
