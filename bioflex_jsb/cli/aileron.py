"""``bioflex-jsb aileron``: aileron effectiveness and reversal of an elastic wing, clamped
(``--clamped``) or the aircraft's flight model of its wing (``--aircraft``).

:func:`bioflex_jsb.api.aileron_effectiveness` (this module only reads the arguments and
formats its :class:`~bioflex_jsb.aeroelasticity.aileron.AileronResult`); the physics in
:mod:`bioflex_jsb.aeroelasticity.aileron` and docs/aeroelasticity.md.
"""

from __future__ import annotations

import argparse
import math

from bioflex_jsb.cli.case import add_force_argument, check_plot_path
from bioflex_jsb.cli.common import UsageError, print_json
from bioflex_jsb.cli.flutter import density
from bioflex_jsb.definition.loader import SPEED_LIMIT_M_S

DEFAULT_WING = "goland_aileron"
LIFT_SLOPE_CHOICES = ("strip", "vlm")
TABLE_ROWS = 9  # speeds printed, evenly over the range

HELP = """Aileron effectiveness and reversal of an elastic wing (steady strips on its modes, one
half wing under antisymmetric ailerons; docs/aeroelasticity.md, "Aileron effectiveness and
reversal"). Reports against airspeed [m/s]: the rolling moment per aileron
angle of the wing held at its root, elastic over rigid [-]; the steady roll rate
p b/(2V) per radian of aileron [1/rad] (the wing's roll damping balancing the aileron) and
its ratio to the rigid wing's; the aileron reversal speed [m/s] (where both reach zero), its
dynamic pressure over the divergence's (q_R/q_D) beside the typical section's
-e c_l_delta/(c c_m_delta); the divergence speed (root held, and free to roll) and the rigid
wing's C_l_delta and C_lp [1/rad] (both halves, on S and b). The aileron's section: thin
aerofoil (Glauert 1927: c_l_delta = 2(pi - theta_h + sin theta_h), cos theta_h = 1 - 2 hinge).

--clamped NAME|FILE.toml: a definition with a beam wing (docs/aircraft.md) clamped at its
root, the beam's modes on Gauss strips; default goland_aileron (the Goland wing with a
20 %-chord aileron on its outer 40 %: reversal 168.1 m/s, divergence 252.3 m/s).
--aircraft NAME|FILE.toml: an aircraft's flight model of its wing (its flown modes on the
vortex lattice's strips, the aircraft's own C_l_delta_a and C_lp beside; bioflex_optimised's
estimated outboard aileron reverses at 12.8 m/s). The aileron: the definition's [aileron]
(span range, hinge) or --aileron. --plot FILE.png
(.pdf, .svg): effectiveness and roll rate against airspeed, the reversal marked."""


def aileron_spec(text: str) -> tuple[float, float, float]:
    """--aileron START:END:HINGE: three numbers (their ranges are checked as a file's)."""
    parts = text.split(":")
    try:
        start, end, hinge = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"aileron must be START:END:HINGE, the span as fractions of the semispan and the "
            f"hinge's chord fraction, e.g. 0.6:1:0.8, got {text!r}") from None
    return start, end, hinge


def speed_range(text: str) -> tuple[float, float]:
    """--range LOW:HIGH [m/s], 0 <= LOW < HIGH <= 400."""
    parts = text.split(":")
    try:
        lo, hi = (float(p) for p in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"range must be LOW:HIGH in m/s, e.g. 0:250, got {text!r}") from None
    if not (0.0 <= lo < hi <= SPEED_LIMIT_M_S):
        raise argparse.ArgumentTypeError(
            f"range must satisfy 0 <= LOW < HIGH <= {SPEED_LIMIT_M_S:g} m/s, got {text!r}")
    return lo, hi


def register(sub) -> None:
    p = sub.add_parser("aileron", help="aileron effectiveness and reversal speed of a clamped "
                       "elastic wing", description=HELP)
    p.add_argument("--clamped", default=None, metavar="NAME|FILE",
                   help="a definition with a beam wing, clamped: a shipped name or a .toml "
                   f"file (docs/aircraft.md); default {DEFAULT_WING}")
    p.add_argument("--aircraft", default=None, metavar="NAME|FILE",
                   help="an aircraft definition (a shipped name such as bioflex_optimised, or "
                   "a .toml file): its flight model's wing instead of a clamped one")
    p.add_argument("--aileron", type=aileron_spec, default=None, metavar="START:END:HINGE",
                   help="the aileron instead of the definition's [aileron]: span START to END "
                   "as fractions of the semispan (0 <= START < END <= 1, at least 0.01 "
                   "apart), hinge line at HINGE chord fractions aft of the leading edge "
                   "(0.5..0.95; a 25 %% aileron is 0.75)")
    p.add_argument("--density", type=density, default=None, metavar="RHO",
                   help="air density [kg/m^3], 0.01 <= RHO <= 2; default the definition's")
    p.add_argument("--lift-slope", choices=LIFT_SLOPE_CHOICES, default=None,
                   help="strip lift slope: strip (the definition's 2-D slope on every strip) "
                   "or vlm (the vortex lattice's spanwise C_la(y), a rectangular wing); "
                   "default the definition's")
    from bioflex_jsb.cli.lateral_options import add_lateral_aero_argument

    add_lateral_aero_argument(p, "; with --aircraft (a clamped wing takes --lift-slope)")
    p.add_argument("--range", type=speed_range, default=None, metavar="LOW:HIGH",
                   help=f"airspeeds [m/s], 0 <= LOW < HIGH <= {SPEED_LIMIT_M_S:g}; default 0 "
                   "to 1.5 x the reversal speed (to 1.1 x the divergence speed when that is "
                   "within 2 x the reversal speed)")
    p.add_argument("--plot", metavar="FILE.png",
                   help="draw effectiveness and roll rate against airspeed, the reversal "
                   "marked, to FILE (.png, .pdf, .svg; an existing file is replaced only if "
                   "bioflex-jsb wrote it)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true",
                   help="print JSON (the curves at every speed included)")
    p.set_defaults(run=run)


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb import api

    check_plot_path(args.plot, args.force)
    if args.aircraft is not None:
        if args.clamped is not None:
            raise UsageError("--clamped analyses a clamped wing, --aircraft an aircraft's "
                             "flight model of its wing: give one of them")
        if args.lift_slope is not None:
            raise UsageError("--lift-slope is for --clamped; an aircraft's wing takes the "
                             "vortex lattice's span loading (its flight model's)")
        wing = api.load_aircraft(args.aircraft)
    else:
        if args.lateral_aero is not None:
            raise UsageError("--lateral-aero is for --aircraft (its flight model's lattice); "
                             "a clamped wing takes --lift-slope")
        wing = args.clamped or DEFAULT_WING
    res = api.aileron_effectiveness(wing, args.range, aileron=args.aileron,
                                    density_kg_m3=args.density, lift_slope=args.lift_slope,
                                    lateral_aero=args.lateral_aero)
    payload = res.as_dict()
    payload["plot"] = None
    if args.plot:
        try:
            res.plot(args.plot, force=True)  # check_plot_path refused what --force must allow
        except OSError as exc:
            raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
        payload["plot"] = args.plot
    if args.json:
        print_json(payload)
        return 0
    print(text_report(res, payload))
    return 0


def _speed_text(v: float | None, top: float) -> str:
    if v is None:
        return "none"
    if v > SPEED_LIMIT_M_S:  # a number the incompressible strips cannot vouch for
        return f"none below {SPEED_LIMIT_M_S:g} m/s"
    return f"{v:.1f} m/s" + (" (above the range)" if v > top else "")


def text_report(res, p: dict) -> str:
    s = p["surface"]
    semispan = s["end_m"] if res.settings.get("semispan_m") is None else \
        res.settings["semispan_m"]
    what = "clamped" if p["clamped"] else (
        f"the aircraft {p['aircraft']['name']}'s flight model: {p['n_flown_modes']} modes on "
        f"the lattice's {p['n_strips']} strips")
    lines = [
        f"wing {p['wing']} ({what}): {s['name']} {s['start_m']:.4g}-{s['end_m']:.4g} m "
        f"({s['start_m'] / semispan:.3g}-{s['end_m'] / semispan:.3g} of the semispan), hinge "
        f"{s['hinge_chord_fraction']:g} c ({100 * s['flap_chord_ratio']:.3g} % chord); steady "
        f"strips, lift slope {p['lift_slope']}"
        + (", the lattice's antisymmetric loading" if p.get("lateral_aero") == "lattice"
           else "") + f", rho {p['density_kg_m3']:g} kg/m^3",
        f"  section: c_l_delta {s['flap_lift_per_rad']:.4g} /rad, c_m_delta (quarter chord) "
        f"{s['flap_moment_quarter_chord_per_rad']:.4g} /rad",
        f"  rigid wing: C_l_delta {p['rigid']['cl_delta_per_rad']:.4g} /rad, C_lp "
        f"{p['rigid']['cl_p_per_rad']:.4g} /rad, steady roll p b/(2V) "
        f"{p['rigid']['roll_rate_pb_2v_per_rad']:.4g} per rad of aileron",
    ]
    if not p["clamped"]:
        air = p["aircraft"]
        lines.append(f"  the aircraft's own (rigid, its tail and fuselage included): C_l_delta_a "
                     f"{air['cl_delta_a_per_rad']:.4g} /rad, C_lp {air['cl_p_per_rad']:.4g} /rad")
    top = p["range_m_s"][1]
    vr, vd = p["reversal_speed_m_s"], p["divergence_speed_m_s"]
    if vr is None or vr > SPEED_LIMIT_M_S:
        lines.append(f"  no aileron reversal below {SPEED_LIMIT_M_S:g} m/s")
    else:
        ratio = p["reversal_over_divergence"]
        rel = "" if ratio is None else (f" (q_R/q_D {ratio:.3f}; the typical section's "
                                        f"{p['typical_section_ratio']:.3f})")
        lines.append(f"  aileron reversal at {_speed_text(vr, top)}{rel}"
                     + ("; the wing diverges first" if p["reversal_above_divergence"] else ""))
    lines.append(f"  divergence: root held {_speed_text(vd, top)}, free to roll "
                 f"{_speed_text(p['roll_divergence_speed_m_s'], top)}")
    ref = p.get("at_reference_speed")
    if ref is not None:
        lines.append(f"  at the aircraft's cruise speed {ref['speed_m_s']:g} m/s: R/R_rigid "
                     f"{ref['effectiveness']:.4g}, p/p_rigid {ref['roll_effectiveness']:.4g}, "
                     f"p b/(2V) {ref['roll_rate_per_rad']:.4g} per rad"
                     + (" (reversed)" if ref["effectiveness"] < 0.0 else ""))
    lines.append("  V [m/s]   R/R_rigid   p/p_rigid   p b/(2V) per rad")
    lo = p["range_m_s"][0]
    for v in [lo + (top - lo) * i / (TABLE_ROWS - 1) for i in range(TABLE_ROWS)]:
        at = res.at(v)
        lines.append(f"  {v:7.1f}  {_num(at['effectiveness'])}  "
                     f"{_num(at['roll_effectiveness'])}  {_num(at['roll_rate_per_rad'])}")
    if p.get("plot"):
        lines.append(f"  effectiveness figure written to {p['plot']}")
    return "\n".join(lines)


def _num(x: float) -> str:
    return f"{x:10.4f}" if math.isfinite(x) and abs(x) < 1e5 else f"{x:10.3g}"
