"""``bioflex-jsb modes``: eigenvalues of the rigid, coupled and QSD models with mode identity."""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from bioflex_jsb.cli.case import (
    DEFAULT_SPEED_M_S,
    DEFAULT_WING,
    SPEED_MAX_M_S,
    SPEED_MIN_M_S,
    SPEED_RANGE_TEXT,
    add_force_argument,
    aircraft_speeds,
    airspeed,
    check_plot_path,
)
from bioflex_jsb.cli.common import (
    UsageError,
    add_wing_arguments,
    check_distinct_outputs,
    check_new_file,
    models_list,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.gust import damping_ratio, wing_for_run
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.lti import RIGID_BLOCK_ANALYTIC, rigid_block_note
from bioflex_jsb.sinks.mcap import scene_modes

PLOT_TOP_M_S = 25.0  # the root loci run to the largest --speed, at least this [m/s]

HELP = f"""Eigenvalues of the linear models (the paper's Eq. 4: analytic rigid block A_RR from the
Table B2 derivatives, quasi-steady Table B1 wing terms) at each --speed, every mode labelled
by identity (short_period, phugoid, aeroelastic_1..3). Labels follow each mode through a
speed sweep from 2 m/s by eigenvector correlation, so crossings do not swap them. A root in
the right half plane is marked UNSTABLE (JSON: "stable": false); an unstable real root is a
static divergence and is labelled "divergence", with the branch it was tracked on (e.g.
short_period) beside it. Units: speeds in m/s; eigenvalues (re, im) and frequencies in
rad/s; damping ratio dimensionless. One entry per conjugate pair (im >= 0); real roots are
listed with im = 0. Valid range: --speed {SPEED_RANGE_TEXT}; the linear models are defined
below the speed at which the aircraft can trim (the phugoid of the linear model goes unstable
there). Default: the {DEFAULT_WING} wing at {DEFAULT_SPEED_M_S:g} m/s (the paper's Fig. 21
case); with --aircraft its [airframe] cruise speed (the plot to 1.5 x its top flight
speed). The phugoid differs from `bioflex-jsb linearize` (JSBSim's linearization of the
airframe), which includes the thrust's change with airspeed; see its --help (JSON:
"rigid_block"). A mode is one conjugate pair or two real roots (an over-damped short period
is listed as two real short_period roots); the short period is the one of the larger
natural frequency at each speed.

--axis lateral: the lateral-directional modes instead (roll subsidence "roll", "spiral",
"dutch_roll" and, coupled, the wing's antisymmetric modes "antisymmetric_1..3";
eigenvalues in rad/s): sideslip, roll-rate, yaw-rate and bank equations whose rigid
derivatives are identified from the aircraft's JSBSim model at its trim at each --speed
(the prototype's generated JSBSim airframe, whose lateral tables are estimates: the paper
has no lateral data), --models rigid (the rigid aircraft), coupled (with the wing's
antisymmetric modes on quasi-steady strips that see the roll rate, the yaw rate, the
sideslip and the aileron, and their side force and yawing moment; --aero unsteady: the
same with Theodorsen strips, Jones lag states and apparent mass on the modes and the roll
rate, the lag roots not listed) and qsd (their static deformation); a wing given as a
modal-data file has no antisymmetric modes (rigid only). The aircraft must trim there (the
prototype 9..32 m/s; an --aircraft its flight speeds, default its cruise speed);
--structural-damping, --plot, --animate and --mode-sheet do not apply. An --aircraft whose
[aileron.actuator] gives natural_frequency_rad_s (1..1000 rad/s) and damping_ratio
(0.1..3) drives its aileron through that actuator: with --aero unsteady the aileron's
Theodorsen terms (circulatory lift through the lags, apparent mass in its rate and
acceleration) load the modes and the roll; the modes listed are unchanged (the actuator's
roots are its own), JSON "aileron_actuator", "aileron_unsteady".
JSON: "derivatives" (body axes, per rad; rates with b/2V) and "source" per result;
docs/lateral.md."""


def register(sub) -> None:
    p = sub.add_parser("modes", help="labelled eigenvalues of the LTI models", description=HELP)
    add_wing_arguments(p, default=DEFAULT_WING)
    p.add_argument(
        "--speed", type=airspeed, action="append", metavar="V",
        help=f"airspeed [m/s] (the prototype {SPEED_MIN_M_S:g}..{SPEED_MAX_M_S:g}; an "
        "--aircraft 1..110); repeat for several "
        f"speeds (default {DEFAULT_SPEED_M_S:g}; an --aircraft's own cruise speed)",
    )
    p.add_argument(
        "--models", type=models_list, default=DEFAULT_MODELS,
        help="comma-separated subset of rigid,coupled,qsd (default: all three)",
    )
    p.add_argument("--aero", choices=("quasi-steady", "unsteady"), default="quasi-steady",
                   help="the wing's strip aerodynamics for the coupled model: quasi-steady "
                   "(the paper's, default) or unsteady (Theodorsen strips with named lag "
                   "states; the lag roots are not listed; docs/aeroelasticity.md)")
    p.add_argument("--structural-damping", type=damping_ratio, default=None, metavar="Z",
                   help="structural damping ratio ζ of every wing mode, 0 <= Z < 1 (default: "
                   "the wing's own)")
    p.add_argument("--axis", choices=("longitudinal", "lateral"), default="longitudinal",
                   help="longitudinal (default: the paper's models) or lateral (roll, "
                   "spiral, Dutch roll from the JSBSim model's derivatives and the wing's "
                   "antisymmetric modes; eigenvalues in rad/s)")
    from bioflex_jsb.cli.lateral_options import add_lateral_aero_argument

    add_lateral_aero_argument(p, "; with --axis lateral")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument(
        "--plot", metavar="FILE.png",
        help=f"draw root loci from {SPEED_MIN_M_S:g} m/s to the largest --speed (at least "
        f"{PLOT_TOP_M_S:g} m/s) to FILE.png (.png, .pdf, .svg; an existing file is replaced "
        "only if bioflex-jsb wrote it)",
    )
    p.add_argument(
        "--animate", metavar="FILE.mcap",
        help="write an MCAP in which each structural mode of the wing and each aeroelastic "
        "mode of the coupled model at --speed (one speed) oscillates in turn, "
        f"{scene_modes.CYCLES} cycles each shown at {scene_modes.DISPLAY_PERIOD_S:g} s a "
        "cycle, labelled with frequency and damping ratio (a text in the 3-D scene and an "
        "event); open it in Foxglove with docs/foxglove/modes_layout.json",
    )
    p.add_argument(
        "--mode-sheet", metavar="FILE.png",
        help="draw the twist and bending of those modes along the span to FILE.png (.png, "
        ".pdf, .svg)",
    )
    add_force_argument(p)
    p.set_defaults(run=run)


def _check_shape_outputs(args, speeds) -> None:
    """--animate and --mode-sheet: one --speed, the quasi-steady model, files we may write."""
    if args.animate is None and args.mode_sheet is None:
        return
    if len(speeds) != 1:
        raise UsageError(f"--animate and --mode-sheet show the modes at one --speed; "
                         f"{len(speeds)} were given")
    if args.aero != "quasi-steady":
        raise UsageError("--animate and --mode-sheet show the quasi-steady coupled model's "
                         "modes; drop --aero unsteady")
    check_plot_path(args.mode_sheet, args.force)
    if args.animate is not None:
        check_new_file(args.animate, args.force, "animation file", (".mcap",))
    check_distinct_outputs(("--plot", args.plot), ("--mode-sheet", args.mode_sheet),
                           ("--animate", args.animate))


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.cli.lateral_options import check_lateral_aero

    check_lateral_aero(args, args.axis == "lateral", "give --axis lateral")
    if args.axis == "lateral":
        return _run_lateral(args)
    default_speed, flight_top = aircraft_speeds(args)
    speeds = args.speed or [default_speed]
    if args.aero == "unsteady" and "coupled" not in args.models:  # it would change nothing
        raise UsageError(f"--aero unsteady is the coupled model's; --models "
                         f"{','.join(args.models)} has none (add coupled)")
    check_plot_path(args.plot, args.force)
    _check_shape_outputs(args, speeds)
    build = wing_for_run(wing_from_args(args), args)
    from bioflex_jsb import api

    results = []
    for model in args.models:
        aero = args.aero if model == "coupled" else "quasi-steady"
        results.extend(api.modes(build, v, model, aero=aero) for v in speeds)
    payload = {
        "wing": build.variant.name,
        "mass_basis": build.mass_basis,
        "overrides": dict(build.model.coefficients.overrides),
        "rigid_block": rigid_block_note(None, build.model.airframe),
        "results": [s.as_dict() for s in results],
        "unstable": [{"speed_m_s": s.speed_m_s, "model": s.model, "mode": m.mode,
                      "branch": m.branch, "re": m.re, "im": m.im}
                     for s in results for m in s.modes if m.unstable],
        "plot": args.plot,
    }
    if args.plot:
        _plot(args, build, speeds, flight_top)
    if args.animate or args.mode_sheet:
        payload.update(_shapes(args, build, speeds[0]))
    if args.json:
        print_json(payload)
        return 0
    print(f"wing {build.variant.name}  (mass basis {build.mass_basis}"
          + (f", overrides {payload['overrides']}" if payload["overrides"] else "") + ")")
    print(f"{'V [m/s]':>8} {'model':<16} {'mode':<14} {'re [rad/s]':>11} {'im [rad/s]':>11} "
          f"{'damping':>8} {'ω_n [rad/s]':>12}  stability")
    for s in results:
        for m in s.modes:
            note = "UNSTABLE" if m.unstable else "stable"
            if m.branch != m.mode:
                note += f" (real root of the {m.branch} branch)"
            print(f"{s.speed_m_s:8.2f} {s.model:<16} {m.mode:<14} {m.re:11.3f} {m.im:11.3f} "
                  f"{m.damping:8.3f} {m.frequency_rad_s:12.3f}  {note}")
    n_bad = len(payload["unstable"])
    if n_bad:
        print(f"{n_bad} unstable root(s): Re λ > 0 (damping < 0); a real one is a static "
              "divergence, a complex one a flutter or an unstable oscillation")
    if args.plot:
        print(f"root loci written to {args.plot}")
    if args.animate:
        print(f"mode animation written to {args.animate} "
              f"({', '.join(payload['animation']['modes'])})")
    if args.mode_sheet:
        print(f"mode sheet written to {args.mode_sheet}")
    return 0


DEFAULT_MODELS = ("rigid", "coupled", "qsd")
LONGITUDINAL_ONLY = (("--structural-damping", lambda a: a.structural_damping is not None),
                     ("--plot", lambda a: a.plot is not None),
                     ("--animate", lambda a: a.animate is not None),
                     ("--mode-sheet", lambda a: a.mode_sheet is not None))


def _run_lateral(args: argparse.Namespace) -> int:
    """--axis lateral: the lateral-directional modes at each --speed (HELP)."""
    from bioflex_jsb import api

    given = [name for name, used in LONGITUDINAL_ONLY if used(args)]
    if given:
        raise UsageError(f"--axis lateral takes no plots and the wing's own damping: "
                         f"{', '.join(given)} does not apply")
    aircraft = args.aircraft_definition
    subject = aircraft if aircraft is not None else wing_from_args(args)
    build = subject.wing() if aircraft is not None else subject
    models = tuple(args.models)
    if build.variant.beam is None and build.variant.modes_file:
        if models != DEFAULT_MODELS:
            if set(models) - {"rigid"}:
                raise UsageError(f"wing {build.variant.name!r} is a modal-data file: no "
                                 "antisymmetric modes (they need its beam); use --models "
                                 "rigid")
        else:
            print(f"bioflex-jsb: note: wing {build.variant.name!r} is a modal-data file: "
                  "the rigid lateral model only (the antisymmetric modes need its beam)",
                  file=sys.stderr)
            models = ("rigid",)
    name = aircraft.name if aircraft is not None else f"bioflex (wing {build.variant.name})"
    results = []
    for model in models:
        for v in args.speed or [None]:
            # --aero unsteady is the coupled model's (rigid has no strips; the qsd's static
            # deformation is the same: the unsteady increments vanish in a steady state)
            aero = args.aero if model == "coupled" else "quasi-steady"
            ss = api.lateral_model(subject, v, model, aero, args.lateral_aero)
            results.append((ss, api.lateral_modes(subject, ss.speed_m_s, model, aero,
                                                  args.lateral_aero)))
    payload = {
        "axis": "lateral", "aircraft": name,
        **({} if args.lateral_aero is None else {"lateral_aero": args.lateral_aero}),
        "results": [{**ms.as_dict(), "derivatives": ss.notes["derivatives"],
                     "alpha_trim_rad": ss.notes["alpha_trim_rad"],
                     "source": ss.notes["source"], **_actuator_notes(ss)}
                    for ss, ms in results],
        "unstable": [{"speed_m_s": ms.speed_m_s, "model": ms.model, "mode": m.mode,
                      "re": m.re, "im": m.im}
                     for _, ms in results for m in ms.modes if m.unstable],
    }
    if args.json:
        print_json(payload)
        return 0
    print(f"aircraft {name}: lateral-directional modes (rigid derivatives from its JSBSim "
          "model at each trim)")
    print(f"{'V [m/s]':>8} {'model':<16} {'mode':<16} {'re [rad/s]':>11} {'im [rad/s]':>11} "
          f"{'damping':>8} {'ω_n [rad/s]':>12}  stability")
    for _, ms in results:
        for m in ms.modes:
            note = "UNSTABLE" if m.unstable else "stable"
            if m.mode == "spiral" and m.unstable:
                note += f" (doubles in {math.log(2.0) / m.re:.0f} s)"
            print(f"{ms.speed_m_s:8.2f} {ms.model:<16} {m.mode:<16} {m.re:11.4f} {m.im:11.4f} "
                  f"{m.damping:8.3f} {m.frequency_rad_s:12.4f}  {note}")
    for key, text in _actuator_notes(results[0][0] if results else None).items():
        print(f"{key.replace('_', ' ')}: {text}")
    return 0


def _actuator_notes(ss) -> dict:
    """The model's notes on the aircraft's ``[aileron.actuator]`` and the aileron's unsteady
    terms ({} without an actuator: its roots are its own, the modes unchanged)."""
    notes = {} if ss is None else ss.notes
    return {key: notes[key] for key in ("aileron_actuator", "aileron_unsteady")
            if key in notes}


def _shapes(args, build, speed_m_s: float) -> dict:
    from bioflex_jsb.sinks import plotting

    shapes = scene_modes.mode_shapes(build, speed_m_s)
    out: dict = {"mode_shapes": [s.as_dict() for s in shapes]}
    try:
        if args.animate:
            out["animation"] = {"file": args.animate,
                                **scene_modes.write_animation(args.animate, build, speed_m_s,
                                                              shapes)}
        if args.mode_sheet:
            scene_modes.draw_mode_sheet(args.mode_sheet, build, speed_m_s, shapes,
                                        software=plotting.SOFTWARE_TAG)
            out["mode_sheet"] = args.mode_sheet
    except OSError as exc:
        raise UsageError(f"cannot write {exc.filename!r}: {exc.strerror}") from None
    return out


def locus_note(build) -> str:
    """The root-locus figure's line on the models' rigid block (the phugoid depends on it:
    ``compare`` and ``loads --frequency`` use JSBSim's, whose phugoid is better damped)."""
    block = rigid_block_note(None, build.model.airframe)
    note = f"rigid block of every model here: {block}"
    if block == RIGID_BLOCK_ANALYTIC:
        note += ("; its phugoid is not JSBSim's (compare, loads --frequency), "
                 "docs/aeroelasticity.md: 'Two coupled LTI models and the phugoid'")
    return note


def _plot(args, build, speeds, flight_top_m_s: float | None = None) -> None:
    from bioflex_jsb.sinks import plotting

    # to 1.5 x the top of another aircraft's flight speeds (the SGS: 42 m/s), as the
    # prototype's 25 m/s is 1.7 x its 15 m/s cruise
    top = max(PLOT_TOP_M_S, max(speeds), 1.5 * (flight_top_m_s or 0.0))
    grid = np.arange(SPEED_MIN_M_S, top + 1e-9, 0.5)
    sweeps = []
    for model in args.models:
        # the rigid track needs the aircraft's airframe: it has no wing to carry it
        full = eigen.track(model, np.concatenate([np.arange(2.0, SPEED_MIN_M_S, 0.5), grid]),
                           None if model == "rigid" else build.model,
                           airframe=build.model.airframe)
        k0 = int(np.searchsorted(full.speeds_m_s, SPEED_MIN_M_S))
        sweeps.append(eigen.Sweep(model, full.speeds_m_s[k0:], full.eigenvalues[k0:],
                                  full.labels, full.eigenvectors[k0:], full.wing,
                                  full.density_kg_m3))
    try:
        plotting.root_locus(sweeps, args.plot, f"wing {build.variant.name}",
                            note=locus_note(build))
    except OSError as exc:
        raise UsageError(f"cannot write plot {args.plot!r}: {exc.strerror}") from None
