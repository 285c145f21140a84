"""``bioflex-jsb flutter``: the lowest airspeed at which a wing goes unstable.

Two analyses, chosen by --wing and --clamped (docs/aeroelasticity.md, docs/aircraft.md),
both :func:`bioflex_jsb.api.flutter` (this module only formats its result):

* a paper wing (``original``, ``optimised``, ... or a variant file) or ``--aircraft``, free
  aircraft: the coupled model of Eq. (4) on unsteady strips (default) or the paper's
  quasi-steady ones;
* ``--clamped FILE`` (or ``--clamped goland``, or ``--wing goland --clamped``): a clamped
  wing from its definition file, by p-k or by state-space eigen-analysis.

Combinations that are not available are refused with one line (exit 2) naming what is.
``--plot FILE`` draws the V-g / V-f diagram (:meth:`FlutterResult.plot`) of a scan over the
whole range; on a terminal a progress bar on stderr follows the scan.
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace

from bioflex_jsb.cli.case import add_force_argument, check_plot_path
from bioflex_jsb.cli.common import UsageError, add_wing_arguments, print_json, wing_from_args
from bioflex_jsb.definition.loader import DENSITY_RANGE_KG_M3, SHIPPED

BENCHMARK_WINGS = ("goland",)
AERO_CHOICES = ("unsteady", "quasi-steady")
METHOD_CHOICES = ("pk", "state-space")
LIFT_SLOPE_CHOICES = ("strip", "vlm")
INERTIA_CHOICES = ("elastic-axis", "centre-of-mass")
SYMMETRY_CHOICES = ("symmetric", "antisymmetric", "both")
MAX_SPEED_M_S = 400.0  # upper end of --range [m/s]
MIN_DENSITY_KG_M3, MAX_DENSITY_KG_M3 = DENSITY_RANGE_KG_M3  # --density [kg/m³], the
# definition format's range (definition/loader.py: about 33 km altitude to denser than any
# surface air)
PAPER_DEFAULT_RANGE_M_S = (5.0, 40.0)

HELP = """Flutter (oscillatory) or static divergence: the first root that crosses into the
right half plane in --range. Reports the speed [m/s], the frequency of the crossing root
[rad/s], its reduced frequency k = omega*b/V [-] (b the semichord [m]), the unstable mode,
the mechanism (coalescence with another branch and which, single-mode, or static
divergence) and the wind-off natural frequencies [rad/s]; null when nothing crosses.

Paper wings and --aircraft (free aircraft, Eq. 4): --aero unsteady (default: Theodorsen
strips with two Jones lag states per strip added to Eq. 4, docs/aeroelasticity.md) or
quasi-steady (the paper's strips, C = 1: the model of its tables). Quasi-steady strips have
no aerodynamic pitch damping: their single-mode torsion instability is the model's
artefact, its speed set by the assumed structural damping, and is marked so beside the
number ("quasi_steady_artefact": true and a "caveat" in --json). Eigen-analysis (--method
state-space) scanned from 2 m/s in 0.1 m/s steps (a range wider than 35 m/s: in 350 steps)
with mode tracking and bisected (printed to 0.1 m/s); the phugoid is left out, as in the
paper; also the wing's divergence speed with the body held (not an instability of the
aircraft). Not available for them:
--clamped, --method pk, --lift-slope, --inertia-about.

--clamped FILE.toml: any clamped wing from its definition file (docs/aircraft.md: span
stations, beam sections, aerodynamics, air; units and ranges checked when read). --clamped
goland (or --wing goland --clamped): the shipped Goland cantilever (semi-span 6.096 m,
chord 1.8288 m; bioflex_jsb/data/aircraft/goland.toml), published strip theory result
137.2 m/s, 70.7 rad/s (Goland 1945, as tabulated by Patil, Hodges & Cesnik 2001). Defaults
from the definition (Goland: --aero unsteady, --method pk, --lift-slope strip,
--structural-damping 0, --inertia-about elastic-axis, --density 1.225 kg/m^3; the other
literal reading of the data is --inertia-about centre-of-mass --density 1.02); default
--range derived from the wing: up to 1.5 x its static divergence speed, from 5 % of that
(docs/aircraft.md).
An instability already present at the range's lower end is reported as "unstable at and
below LOW m/s" with no speed (JSON: flutter_speed_m_s null, present_at_lower_end true,
unstable_at_and_below_m_s LOW), never as no instability. --plot FILE.png (.pdf, .svg):
the V-g / V-f diagram, damping ratio and frequency of every branch against airspeed over
the whole --range, the first instability marked. On a terminal a progress bar (stderr)
follows the scan."""


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
    """--structural-damping: a ratio within the definition files' DAMPING_RANGE (0..0.3;
    the p-k method failed with an IndexError at 0.95, where modes are overdamped)."""
    from bioflex_jsb.definition.loader import DAMPING_RANGE

    lo, hi = DAMPING_RANGE
    try:
        z = float(text)
    except ValueError:
        z = math.nan
    if not (lo <= z <= hi):
        raise argparse.ArgumentTypeError(
            f"structural damping must be a ratio {lo:g} <= Z <= {hi:g} (e.g. 0.02), got "
            f"{text!r}")
    return z


def density(text: str) -> float:
    try:
        rho = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"density must be a number in kg/m^3, got {text!r}") from None
    if not (MIN_DENSITY_KG_M3 <= rho <= MAX_DENSITY_KG_M3):
        raise argparse.ArgumentTypeError(
            f"density must satisfy {MIN_DENSITY_KG_M3:g} <= RHO <= {MAX_DENSITY_KG_M3:g} "
            f"kg/m^3 (about 33 km altitude to denser than any surface air), got {text!r}")
    return rho


def register(sub) -> None:
    p = sub.add_parser("flutter", help="flutter / divergence speed (free aircraft or a clamped "
                       "wing from its definition)", description=HELP)
    add_wing_arguments(p)
    wing_action = p._option_string_actions["--wing"]
    wing_action.help = (f"{wing_action.help}; or the benchmark wing {', '.join(SHIPPED)} "
                        "(with --clamped)")
    p.add_argument("--clamped", nargs="?", const="", default=None, metavar="FILE",
                   help="a clamped wing without the rigid body: a definition file (.toml, "
                   f"docs/aircraft.md) or a shipped name ({', '.join(SHIPPED)}); bare "
                   "--clamped takes the name from --wing")
    p.add_argument("--aero", choices=AERO_CHOICES, default=None,
                   help="strip aerodynamics: unsteady (Theodorsen C(k); Jones lag states in "
                   "state-space) or quasi-steady (C = 1, the paper's: no pitch damping, its "
                   "single-mode torsion flutter marked as an artefact); default the "
                   "definition's for --clamped, unsteady for the free aircraft")
    p.add_argument("--method", choices=METHOD_CHOICES, default=None,
                   help="pk (frequency domain, --clamped only) or state-space "
                   "(eigen-analysis with mode tracking); default the definition's for "
                   "--clamped, state-space for paper wings")
    p.add_argument("--structural-damping", type=damping_ratio, default=None, metavar="Z",
                   help="viscous modal damping ratio zeta [-], 0 <= Z <= 0.3, on every mode "
                   "(2 zeta omega_i); default the definition's for --clamped, the variant's "
                   "(0.02) for paper wings")
    p.add_argument("--lift-slope", choices=LIFT_SLOPE_CHOICES, default=None,
                   help="strip lift slope, --clamped only: strip (the definition's 2-D slope "
                   "on every strip) or vlm (the vortex lattice's spanwise C_la(y))")
    p.add_argument("--inertia-about", choices=INERTIA_CHOICES, default=None,
                   help="axis of the definition's pitch inertia (--clamped only): "
                   "elastic-axis or centre-of-mass (Goland's 8.64 kg m may be read either way)")
    p.add_argument("--density", type=density, default=None, metavar="RHO",
                   help=f"air density [kg/m^3], {MIN_DENSITY_KG_M3:g} <= RHO <= "
                   f"{MAX_DENSITY_KG_M3:g}; default the definition's for --clamped, 1.225 "
                   "(sea level) for paper wings")
    p.add_argument("--range", type=speed_range, default=None, metavar="LOW:HIGH",
                   help=f"airspeed range to search [m/s], 0 < LOW < HIGH <= "
                   f"{MAX_SPEED_M_S:g}; default {PAPER_DEFAULT_RANGE_M_S[0]:g}:"
                   f"{PAPER_DEFAULT_RANGE_M_S[1]:g} for the prototype's wings, derived from "
                   "the wing for another aircraft and for --clamped (5 %% to 150 %% of its "
                   "static divergence speed, at most 400)")
    p.add_argument("--plot", metavar="FILE.png",
                   help="draw the V-g / V-f diagram (damping ratio and frequency of each "
                   "branch against airspeed over the whole range, the first instability "
                   "marked) to FILE (.png, .pdf, .svg; an existing file is replaced only if "
                   "bioflex-jsb wrote it)")
    p.add_argument("--symmetry", choices=SYMMETRY_CHOICES, default="symmetric",
                   help="which modes: symmetric (default: the wing's symmetric modes, Eq. 4), "
                   "antisymmetric (its antisymmetric modes with the aircraft's roll freedom; "
                   "a clamped wing's root held: the same problem) or both (each searched, "
                   "the first reported and the other beside it; docs/aeroelasticity.md)")
    add_force_argument(p)
    p.add_argument("--controller", metavar="FILE", default=None,
                   help="a linear controller in the loop (a .npz/.toml file or a shipped "
                   "one: fs_inertial-backward): the open- and closed-loop flutter speeds on "
                   "unsteady strips (docs/aeroelasticity.md, \"Active flutter suppression\")")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def clamped_target(args: argparse.Namespace) -> str | None:
    """The definition (name or file) to analyse clamped, or None for the free aircraft;
    refuses (UsageError, one line) what is not available for the chosen wing."""
    if args.clamped is None:
        if args.wing in SHIPPED:
            raise UsageError(f"--wing {args.wing} is a benchmark cantilever with no aircraft "
                             f"around it: give --clamped (accepted: --wing {args.wing} "
                             "--clamped)")
        if args.method == "pk":
            raise UsageError("--method pk is available for clamped wings only; paper "
                             "wings accept --method state-space")
        for flag, value in (("--lift-slope", args.lift_slope),
                            ("--inertia-about", args.inertia_about)):
            if value is not None:
                raise UsageError(f"{flag} is available for clamped wings (--clamped) only; "
                                 "paper wings take the vortex lattice's span loading "
                                 "(Table B1)")
        return None
    from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_MASS_BASIS

    # what a clamped analysis does not take is refused, not ignored
    if getattr(args, "aircraft_definition", None) is not None:
        raise UsageError("--clamped analyses a clamped-wing definition; --aircraft is the free "
                         "aircraft's: give one of them")
    if args.clamped and getattr(args, "wing_given", False):
        raise UsageError(f"--clamped {args.clamped} and --wing {args.wing}: give one of them "
                         "(--wing NAME --clamped analyses that definition)")
    if args.mass_basis != DEFAULT_MASS_BASIS:
        raise UsageError("--mass-basis is the free aircraft's generalised masses; a clamped "
                         "wing's come from its beam (drop it)")
    target = args.clamped or args.wing
    if target not in SHIPPED and not target.endswith(".toml"):
        raise UsageError(f"--clamped takes a clamped-wing definition: a shipped name "
                         f"({', '.join(SHIPPED)}) or a .toml file (docs/aircraft.md), got "
                         f"{target!r}; paper wings are analysed as the free aircraft (drop "
                         "--clamped)")
    return target


def run(args: argparse.Namespace) -> int:
    target = clamped_target(args)
    if args.controller is not None:
        from bioflex_jsb.cli.flutter_control import check_controller_options, run_with_controller

        check_controller_options(args, target is not None)
        return run_with_controller(args)
    check_plot_path(args.plot, args.force)
    with ScanProgress() as progress:
        payload = paper_payload(args, progress) if target is None else \
            clamped_payload(args, target, progress)
    if args.json:
        print_json(payload)
        return 0
    print(text_report(payload))
    return 0


class ScanProgress:
    """A tqdm bar over the scanned airspeed [m/s] on a terminal (stderr), nothing
    otherwise: pipes and CI stay clean. Called with each scanned speed and the scan's top
    (:func:`bioflex_jsb.flight_dynamics.flutter_engine.first_instability`)."""

    def __init__(self) -> None:
        self.bar = None
        self.at = 0.0

    def __enter__(self):
        """The progress callable on a terminal, None otherwise."""
        return self if sys.stderr.isatty() else None

    def __call__(self, speed_m_s: float, top_m_s: float) -> None:
        if self.bar is None:
            from tqdm import tqdm

            self.bar = tqdm(total=round(top_m_s, 1), desc="flutter scan", leave=False,
                            file=sys.stderr, mininterval=0.2,
                            bar_format="{desc}: {n:.1f}/{total:.1f} m/s |{bar}| {elapsed}")
        if speed_m_s > self.at:
            self.bar.update(round(speed_m_s - self.at, 6))
            self.at = speed_m_s

    def __exit__(self, *exc) -> None:
        if self.bar is not None:
            self.bar.close()


def _round(x: float | None, digits: int) -> float | None:
    return None if x is None else round(float(x), digits)


def _formatted(res, digits: int) -> dict:
    """The api result's dictionary with the speeds and frequencies rounded for printing."""
    d = res.as_dict()
    # unstable already at the range's lower end: the result has no speed (null: a script
    # reading the speed alone took the lower end for a flutter speed); the lower end is
    # unstable_at_and_below_m_s
    d["flutter_speed_m_s"] = _round(res.speed_m_s, digits)
    d["speed_m_s"] = d["flutter_speed_m_s"]
    d["unstable_at_and_below_m_s"] = _round(res.unstable_at_and_below_m_s, digits)
    d["frequency_rad_s"] = _round(res.frequency_rad_s, 2)
    d["reduced_frequency"] = _round(res.reduced_frequency, 4)
    d["divergence_speed_m_s"] = _round(res.divergence_speed_m_s, 2)
    d["natural_frequencies_rad_s"] = [round(w, 2) for w in res.natural_frequencies_rad_s]
    d["range_m_s"] = [round(x, 2) for x in res.range_m_s]
    other = d.get("other_symmetry")
    if other is not None:  # --symmetry both: the other result rounded as this one
        for key in ("speed_m_s", "flutter_speed_m_s", "unstable_at_and_below_m_s"):
            other[key] = _round(other[key], digits)
        other["frequency_rad_s"] = _round(other["frequency_rad_s"], 2)
        other["reduced_frequency"] = _round(other["reduced_frequency"], 4)
        other["divergence_speed_m_s"] = _round(other["divergence_speed_m_s"], 2)
        other["natural_frequencies_rad_s"] = [round(w, 2) for w in
                                              other["natural_frequencies_rad_s"]]
    return d


def _symmetry(args: argparse.Namespace) -> dict:
    """api.flutter's ``symmetry`` when --symmetry is not the default (the default's call
    and output are the symmetric search's, unchanged)."""
    return {} if args.symmetry == "symmetric" else {"symmetry": args.symmetry}


def _other_line(p: dict) -> str | None:
    """--symmetry both: which symmetry goes unstable first, and the other's result."""
    if "first_symmetry" not in p:
        return None
    o = p["other_symmetry"]
    if o["present_at_lower_end"]:
        other = f"unstable at and below {o['range_m_s'][0]:g} m/s"
    elif o["speed_m_s"] is None:
        other = "no instability in the range"
    else:
        other = (f"{o['kind']} at {o['speed_m_s']:.1f} m/s, {o['mode']}, "
                 f"{o['frequency_rad_s']:.2f} rad/s, mechanism {o['mechanism']}")
    first = {"none": "neither symmetry is unstable in the range",
             "both": "both symmetries at the same speed (a clamped root: one problem)"}.get(
                 p["first_symmetry"], f"the {p['first_symmetry']} modes go unstable first")
    return f"  {first}; {o.get('symmetry', 'symmetric')}: {other}"


def _plot(res, args: argparse.Namespace) -> str | None:
    """Draw the V-g / V-f diagram to --plot (a one-line refusal if it cannot be written)."""
    if not args.plot:
        return None
    try:
        res.plot(args.plot, force=True)  # check_plot_path refused what --force must allow
    except OSError as exc:
        raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
    return args.plot


def clamped_payload(args: argparse.Namespace, target: str, progress=None) -> dict:
    """A clamped wing's first instability (:func:`bioflex_jsb.api.flutter`), beside the
    published one for the Goland wing."""
    from bioflex_jsb import api

    definition = api.load_definition(target)
    if args.inertia_about is not None:
        definition = replace(definition, structure=replace(
            definition.structure, inertia_axis=args.inertia_about))
    res = api.flutter(definition, args.range, aero=args.aero, method=args.method,
                      clamped=True, structural_damping=args.structural_damping,
                      density_kg_m3=args.density, lift_slope=args.lift_slope,
                      progress=progress,
                      full_scan=bool(args.plot), **_symmetry(args))
    d = _formatted(res, 2)
    d["plot"] = _plot(res, args)
    lift_slope = res.settings["lift_slope"]
    d.update(wing=definition.name, clamped=True, lift_slope=lift_slope,
             inertia_about=definition.structure.inertia_axis)
    if definition.name == "goland":
        d["published"] = goland_published(res, lift_slope)
    return d


def goland_published(res, lift_slope: str) -> dict:
    """The published Goland flutter point and the model's difference from it (when the
    model is the published one's: unsteady strips, 2π, no structural damping)."""
    from bioflex_jsb.parameters import goland as G

    comparable = (res.aero == "unsteady" and lift_slope == "strip"
                  and res.structural_damping == 0.0 and not res.present_at_lower_end)
    pub_v, pub_w = G.PUBLISHED_FLUTTER_SPEED_M_S, G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S

    def rel(x, ref):
        return None if x is None or not comparable else round(float(x) / ref - 1.0, 4)

    return {
        "flutter_speed_m_s": pub_v,
        "frequency_rad_s": pub_w,
        "natural_frequencies_rad_s": list(G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S),
        "source": G.PUBLISHED_SOURCE,
        "applies_to": "--aero unsteady --lift-slope strip --structural-damping 0",
        "comparable": comparable,
        "speed_rel_diff": rel(res.speed_m_s, pub_v),
        "frequency_rel_diff": rel(res.frequency_rad_s, pub_w),
    }


def paper_payload(args: argparse.Namespace, progress=None) -> dict:
    """The free aircraft's first instability (:func:`bioflex_jsb.api.flutter`)."""
    from bioflex_jsb import api
    from bioflex_jsb.aeroelasticity.free_aircraft import with_damping

    build = wing_from_args(args)
    model = build.model if args.structural_damping is None else with_damping(
        build, args.structural_damping)
    res = api.flutter(build, args.range, aero=args.aero, method=args.method,
                      structural_damping=args.structural_damping, density_kg_m3=args.density,
                      progress=progress, full_scan=bool(args.plot), **_symmetry(args))
    d = _formatted(res, 1)
    d["plot"] = _plot(res, args)
    d.update(
        wing=build.variant.name, clamped=False,
        structural_damping=[float(z) for z in model.damping_ratios],
        wing_divergence_speed_m_s=_round(res.wing_divergence_speed_m_s, 2),
        mass_basis=build.mass_basis, overrides=dict(model.coefficients.overrides))
    return d


def text_report(p: dict) -> str:
    head = f"wing {p['wing']}" + (" (clamped)" if p["clamped"] else "")
    setup = f"{p['aero']} strips, {p['method']}"
    if p["clamped"]:
        setup += f", lift slope {p['lift_slope']}, rho {p['density_kg_m3']:g} kg/m^3"
    zeta = p["structural_damping"]
    zeta_text = f"{zeta:g}" if isinstance(zeta, float) else ", ".join(f"{z:g}" for z in zeta)
    setup += f", zeta {zeta_text}"
    nat = ", ".join(f"{w:.2f}" for w in p["natural_frequencies_rad_s"])
    if p.get("symmetry"):
        setup += f", {p['symmetry']} modes"
    lines = [f"{head}: {setup}", f"  natural frequencies [rad/s]: {nat}"]
    lo, hi = p["range_m_s"]
    div = p.get("divergence_speed_m_s")
    own_divergence = p.get("divergence_is_instability")
    if p["flutter_speed_m_s"] is None and not p["present_at_lower_end"]:
        lines.append(f"  no instability between {lo:g} and {hi:g} m/s")
    else:
        partner = f" with {p['partner_mode']}" if p.get("partner_mode") else ""
        # beside the number: what a quasi-steady single-mode result is
        tag = " [quasi-steady artefact: see the caveat]" if p.get("quasi_steady_artefact") \
            else ""
        # a clamped wing's label is "mode 3 (torsion)", a free aircraft's "aeroelastic_3"
        mode = p["mode"] if str(p["mode"]).startswith("mode ") else f"mode {p['mode']}"
        what = (f"{p['kind']}{tag}, {mode}, frequency {p['frequency_rad_s']:.2f} rad/s, "
                f"k = {p['reduced_frequency']:.3f}, mechanism {p['mechanism']}{partner}")
        if p["present_at_lower_end"]:
            lines.append(f"  unstable at and below {lo:g} m/s (already at the range's lower "
                         f"end; lower LOW to find the onset): {what}")
        else:
            lines.append(f"  {p['kind']} at {p['flutter_speed_m_s']:.1f} m/s{tag}, "
                         f"{mode}, frequency {p['frequency_rad_s']:.2f} rad/s, k = "
                         f"{p['reduced_frequency']:.3f}, mechanism {p['mechanism']}{partner}")
        if p.get("caveat"):
            lines.append(f"  caveat: {p['caveat']}")
    other = _other_line(p)
    if other:
        lines.append(other)
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
    if div is not None and own_divergence:
        where = " (above the range)" if div > hi else ""
        lines.append(f"  static divergence at {div:.1f} m/s{where}")
    if p.get("wing_divergence_speed_m_s") is not None:
        lines.append(f"  wing divergence with the body held at "
                     f"{p['wing_divergence_speed_m_s']:.1f} m/s (not an instability of the "
                     "aircraft)")
    if p.get("plot"):
        lines.append(f"  V-g / V-f diagram written to {p['plot']}")
    return "\n".join(lines)
