"""``bioflex-jsb gust``: nonlinear 6-DoF gust runs of the JSBSim airframe with the modal wing."""

from __future__ import annotations

import argparse
import math
import os
import sys

from bioflex_jsb.cli.case import (
    DEFAULT_GUST,
    DEFAULT_SPEED_M_S,
    DEFAULT_WING,
    SPEED_RANGE_TEXT,
    add_force_argument,
    airspeed,
    check_plot_path,
    check_time_step,
    speed_help,
)
from bioflex_jsb.cli.common import (
    EXIT_DIVERGED,
    UsageError,
    add_log_arguments,
    add_wing_arguments,
    check_distinct_outputs,
    closing,
    log_path,
    models_list,
    number_type,
    positive_float,
    print_json,
    wing_from_args,
)
from bioflex_jsb.cli.lateral_options import (
    add_lateral_arguments,
    lateral_aero_extra,
    lateral_description,
    lateral_run_options,
    lateral_summary,
    print_pending_notes,
)
from bioflex_jsb.cli.live_option import add_live_arguments, live_opener, start_live, stop_live
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, MAX_DT_S, MIN_DT_S
from bioflex_jsb.simulation.run import MAX_DURATION_S

HELP = f"""Trim the JSBSim airframe at --speed [m/s], fly it through --gust with the elastic
wing as each of --models (rigid: wing loads off; coupled: dynamic modal states; qsd:
quasi-static deformation) and summarise each run: peak perturbations of airspeed u [m/s],
angle of attack alpha [deg], pitch rate q [deg/s], pitch angle theta [deg] and load factor
n_z [-]. A discrete gust (sharp, 1cos) adds the overshoot of alpha past trim after its first
peak [% of that peak] and the settling time [s] until |alpha - trim| stays within 5 % of its
peak ("-": not settled by the end of the run); turbulence (dryden, vonkarman) adds the RMS
of each perturbation instead. A run that leaves the valid range (a diverging wing mode, the
angle of attack beyond the aerodynamic tables) shows "diverged" with the time and mode of
its divergence instead of metrics, in the table and in --json (null metrics), and the
command exits with status 3. Gusts are vertical, positive up: sharp:AMPLITUDE_m_s,
1cos:AMPLITUDE_m_s:LENGTH_m, dryden:SIGMA_m_s:SCALE_m[:SEED], vonkarman:SIGMA_m_s:SCALE_m[:SEED];
amplitudes up to 50 m/s, LENGTH and SCALE 0.183 m (one mean chord) to 10 km, and a 1cos gust
lasting at least 10 steps of --dt (its peak then sampled within 2.4 %). Parts that vary over
the aircraft follow, each once, after "+" (docs/gusts.md): roll:PEAK_rad_s:LENGTH_m (a 1-cos
rolling gust w_g = -p_g*y, |PEAK| <= 5 rad/s, p_g + = right wing down), lateral:FORM (a
lateral gust v_g [m/s], + to starboard, FORM any vertical form above), front:ANGLE_deg (the
sharp/1cos front at ANGLE to the span, |ANGLE| <= 80, + = starboard wing first), pg (the
MIL-F-8785C rolling part p_g of dryden/vonkarman turbulence), tail (the tail meets the gust
l_t/V after the wing); e.g. 1cos:3:20+roll:0.5:20+tail. Their channels: p_g [rad/s], v_g
[m/s], w_g_tail [m/s].
Valid ranges: --speed {SPEED_RANGE_TEXT}; --duration up to {MAX_DURATION_S:g} s; --dt
{MIN_DT_S:g} to {MAX_DT_S:g} s.
With no arguments: the {DEFAULT_WING} wing at {DEFAULT_SPEED_M_S:g} m/s through {DEFAULT_GUST}
(the paper's Fig. 21 case), all three models. Every step of every run is logged to an MCAP
file (topics and units: docs/logging.md; --out, --no-log)."""


def gust_type(text: str):
    from bioflex_jsb.simulation.gusts import GustSpecError, parse_gust

    try:
        return parse_gust(text)
    except GustSpecError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


gust_type.plain_numbers = True  # type: ignore[attr-defined]  # parse_gust reads plain numbers


def add_run_arguments(p: argparse.ArgumentParser, default_gust: str = DEFAULT_GUST) -> None:
    from bioflex_jsb.cli.aircraft_option import cruise_speed_default

    p.add_argument("--speed", type=airspeed, default=cruise_speed_default(), metavar="V",
                   help="trim " + speed_help(extra="; with --aircraft: within its airframe."
                                             "speed_range_m_s, default its cruise_speed_m_s"))
    p.add_argument("--gust", type=gust_type, default=gust_type(default_gust),
                   help=f"gust specification (default {default_gust}): sharp:A, 1cos:A:L, "
                   "dryden|vonkarman:SIGMA:SCALE[:SEED], none [m/s, m], then optional "
                   "+roll:P:L, +lateral:FORM, +front:DEG, +pg, +tail (see `gust --help`)")
    p.add_argument("--duration", type=positive_float("duration", "s"), default=5.0,
                   help=f"simulated time [s], up to {MAX_DURATION_S:g} (default 5)")
    p.add_argument("--gust-start", type=positive_float("gust start", "s"), default=0.5,
                   help="time the gust starts [s], before the end of --duration (default 0.5)")
    p.add_argument("--dt", type=positive_float("time step", "s"), default=DEFAULT_DT_S,
                   help=f"co-simulation (JSBSim) time step [s] (default {DEFAULT_DT_S:.6f})")


def register(sub) -> None:
    p = sub.add_parser("gust", help="nonlinear gust runs (rigid, coupled, QSD)", description=HELP)
    add_wing_arguments(p, default=DEFAULT_WING)
    add_run_arguments(p)
    p.add_argument("--models", type=models_list, default=None,
                   help="comma-separated subset of rigid,coupled,qsd (default: all three; "
                   "with --aero unsteady: rigid,coupled)")
    add_aero_arguments(p)
    add_controller_argument(p)
    add_lateral_arguments(p)
    add_log_arguments(p)
    add_live_arguments(p)
    p.add_argument("--plot", metavar="FILE.png", default=None,
                   help="time histories to FILE.png (.png, .pdf, .svg; default gust.png when "
                   "run without --json; an existing file is replaced only if bioflex-jsb "
                   "wrote it, else give --force)")
    add_force_argument(p)
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(run=run)


def add_aero_arguments(p: argparse.ArgumentParser) -> None:
    """--aero and --structural-damping, shared by gust and compare."""
    p.add_argument("--aero", choices=("quasi-steady", "unsteady"), default="quasi-steady",
                   help="the wing's strip aerodynamics: quasi-steady (the paper's Eq. 3, "
                   "default) or unsteady (Theodorsen/Wagner strips with named lag states and "
                   "Küssner gust penetration; the coupled model only; docs/aeroelasticity.md)")
    p.add_argument("--structural-damping", type=damping_ratio, default=None, metavar="Z",
                   help="structural damping ratio ζ of every wing mode, 0 <= Z < 1 (default: "
                   "the wing's own, docs/wing_variants.md)")
    p.add_argument("--trim", choices=("rigid", "elastic"), default="rigid",
                   help="the trim the elastic-wing runs start from: rigid (the paper's "
                   "reading, default) or elastic (the static aeroelastic equilibrium: the "
                   "wing's static deflection and its loads carried by JSBSim's trim; "
                   "`bioflex-jsb trim --wing W` shows it; docs/decisions.md); the rigid "
                   "model has no elastic wing and starts from the rigid trim either way")


def add_controller_argument(p: argparse.ArgumentParser, linear: bool = False) -> None:
    """--controller FILE (gust, compare)."""
    what = ("a linear controller (the LTI model closes the loop with it)" if linear
            else "a controller")
    p.add_argument("--controller", metavar="FILE", default=None,
                   help=f"fly with {what} in the loop: a .npz or .toml file (A, B, C, D, "
                   "dt_s [s], the signals it reads: the run's channels such as alpha, q, "
                   "n_z, eta1; the commands it writes: elevator [rad], throttle [-], "
                   "flaperon [rad], aileron [rad, (left - right)/2, + rolls right: both wing "
                   "halves, implies --span full] over the trim) or a shipped one by name "
                   "(gla_optimised, fs_inertial-backward, roll_damper_c172_elastic, ...); "
                   "its commands are logged as ctrl_<command>[_rad] (docs/api.md)")


def controller_from_args(args, linear: bool = False):
    """The --controller of ``args`` loaded (None without one), one line (exit 2) for a
    file that cannot be read or names an unknown signal; kept as
    ``args.controller_object`` for :func:`fly`."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.simulation.controller import load_controller

    args.controller_object = None
    if getattr(args, "controller", None) is None:
        return None
    try:
        args.controller_object = load_controller(args.controller)
    except InputError as exc:
        raise UsageError(f"--controller: {exc}") from None
    return args.controller_object


def controller_line(run) -> str | None:
    """One line on the controller a run flew with (None without one)."""
    c = run.meta.get("controller")
    if not c:
        return None
    peaks = ", ".join(
        f"{ch} peak {abs(run[ch]).max() * (57.29577951308232 if ch.endswith('_rad') else 1):.3g}"
        f" {'deg' if ch.endswith('_rad') else '-'}" for ch in c["channels"] if len(run[ch]))
    states = "" if c["n_states"] is None else f", {c['n_states']} states"
    return (f"controller {c['name']} ({c['kind']}{states}) reads {', '.join(c['inputs'])}, "
            f"commands {', '.join(c['outputs'])} over the trim: {peaks}")


damping_ratio = number_type("damping ratio", low=0.0, high=1.0, high_open=True, symbol="Z")
"""argparse type: a structural damping ratio 0 <= ζ < 1 [-]."""


def resolve_models(args) -> tuple[str, ...]:
    """The models to fly: --models, or the default of the chosen aerodynamics (QSD has no
    unsteady form: a quasi-static deflection carries no lag states); which of them may fly
    together is the run configuration's rule (:func:`run_config`)."""
    unsteady = args.aero == "unsteady"
    return args.models or (("rigid", "coupled") if unsteady else ("rigid", "coupled", "qsd"))


def wing_for_run(build, args):
    """The wing build a run flies: with ``--structural-damping`` every mode's ζ set."""
    if args.structural_damping is None:
        return build
    import dataclasses

    from bioflex_jsb.aeroelasticity.free_aircraft import with_damping

    return dataclasses.replace(build, model=with_damping(build, args.structural_damping))


class Interrupted(Exception):
    """The user stopped the runs (Ctrl-C, SIGTERM); ``runs`` holds what was flown."""

    def __init__(self, runs):
        super().__init__("interrupted")
        self.runs = runs


def progress_bar(total: int, label: str):
    """A tqdm bar on a terminal, nothing otherwise (so pipes and CI stay clean).

    The bar writes to its own duplicate of the terminal's file descriptor: during a run
    JSBSim's output is captured (file descriptors 1 and 2 point at a capture file), and a bar
    on ``sys.stderr`` would be captured with it and never seen."""
    if not sys.stderr.isatty():
        return None
    import os

    from tqdm import tqdm

    stream = os.fdopen(os.dup(sys.stderr.fileno()), "w", buffering=1, encoding="utf-8",
                       errors="replace")
    bar = tqdm(total=total, desc=label, unit="step", leave=False, file=stream,
               mininterval=0.2, unit_scale=True)
    bar.stream = stream  # closed with the bar: close_bar
    return bar


def close_bar(bar) -> None:
    """Close a :func:`progress_bar` and its terminal stream."""
    if bar is None:
        return
    bar.close()
    bar.stream.close()


def run_config(args, models):
    """The run's :class:`~bioflex_jsb.simulation.run_config.RunConfig` from the options
    (made before any file is written: one line, exit 2, for each problem it finds; --dt's
    range named as the option)."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.simulation.run_config import RunConfig

    check_time_step(args.dt)
    try:
        return RunConfig(args.speed, args.gust, args.duration, args.gust_start, dt_s=args.dt,
                         models=tuple(models), aero=getattr(args, "aero", "quasi-steady"),
                         trim=getattr(args, "trim", "rigid"))
    except InputError as exc:
        raise UsageError(str(exc)) from None


def run_description(args, kind: str, models):
    """The :class:`~bioflex_jsb.simulation.run.RunDescription` of a ``gust`` (``compare``)
    run from its checked arguments: what the log records and ``rerun`` flies again."""
    from bioflex_jsb.simulation.run import RunDescription

    extra = {}
    if getattr(args, "aero", "quasi-steady") != "quasi-steady":
        extra["aero"] = args.aero
    if getattr(args, "structural_damping", None) is not None:
        extra["structural_damping"] = args.structural_damping
    if getattr(args, "trim", "rigid") != "rigid":
        extra["trim"] = args.trim
    extra.update(lateral_aero_extra(args))
    aircraft = getattr(args, "aircraft_definition", None)
    if aircraft is not None and aircraft.flight_problem():  # another airframe: its file
        extra["aircraft"] = aircraft.source
    extra.update(lateral_description(args))  # both halves, an aileron input ({}: none)
    if getattr(args, "controller", None) is not None:  # a file by its absolute path
        c = args.controller
        extra["controller"] = os.path.abspath(c) if os.path.isfile(c) else c
    wing = args.wing  # a variant file by its absolute path: rerun reads it from anywhere
    if wing.lower().endswith(".toml") and os.path.isfile(wing):
        wing = os.path.abspath(wing)
    return RunDescription(kind=kind, wing=wing, speed_m_s=args.speed,
                          gust=args.gust.text(), models=tuple(models),
                          duration_s=args.duration, gust_start_s=args.gust_start,
                          dt_s=args.dt, mass_basis=args.mass_basis, extra=extra)


# The 3-D scene in every gust and compare log (sinks/mcap/scene.py, docs/logging.md): the wing
# deformed at true scale (exaggeration 1: the paper's 3 m/s gust twists the tip ~10 deg).
SCENE_EXAGGERATION = 1.0


def open_log(path: str, description, build):
    """The MCAP log of the run ``description`` with the wing ``build`` (its variant and
    overrides as plain data); a file that cannot be written is a one-line UsageError."""
    from bioflex_jsb.sinks.mcap import LogWriteError, RunLog

    # the 3-D scene draws the run's own build: its planform (a definition's stations) and its
    # airframe (sinks/mcap/scene.py: another aircraft's outline is the prototype's scaled)
    try:
        return RunLog.open(path, description, wing_variant=build.variant.as_dict(),
                           overrides=dict(build.model.coefficients.overrides),
                           scene=SCENE_EXAGGERATION, build=build)
    except LogWriteError as exc:
        raise UsageError(str(exc)) from None


def fly(args, build, config, log=None, airframe=None):
    """Run each model of ``config`` (a RunConfig: all of them, also after one stops) on
    ``airframe`` (default: the JSBSim airframe of ``--aircraft``, the prototype's without
    it); return (runs, stop messages)."""
    from bioflex_jsb.cli.aircraft_option import airframe_from_args
    from bioflex_jsb.drivers.gust import run_gust
    from bioflex_jsb.runtime.fdm import FdmError

    runs, stops = [], []
    # both wing halves and an aileron input (cli/lateral_options.py; {} for a half wing)
    controller = getattr(args, "controller_object", None)
    lateral = (lateral_run_options(args, build, controller) if hasattr(args, "aileron_step")
               else {})
    flaperon = "flaperon" in getattr(controller, "outputs", ())
    if flaperon and "aileron" not in lateral:  # the aileron it deflects: --aircraft's
        aircraft = getattr(args, "aircraft_definition", None)  # (None: the prototype's)
        lateral = {**lateral, "aileron": None if aircraft is None
                   else aircraft.definition.aileron}
    try:
        if airframe is None:
            airframe = airframe_from_args(args)
        for model in map(str, config.models):
            steps = int(round(config.duration_s / config.dt_s))
            bar = progress_bar(steps, f"{build.variant.name} {model}")
            recorder = log.recorder(model) if log is not None else None
            # the bar moved once a block (0.9 s of flight), not by a callback every step
            progress = None if bar is None else (lambda k, bar=bar: bar.update(k - bar.n))
            wing = build if config.needs_build(model) or lateral.get("span") == "full" \
                or flaperon else build.model  # a flaperon's strips are the build's
            try:
                run = run_gust(airframe, wing, model, config, progress=progress,
                               recorder=recorder, loads=build, controller=controller,
                               **lateral)
            finally:
                close_bar(bar)
            run.meta.update(wing=build.variant.name, mass_basis=build.mass_basis,
                            overrides=dict(build.model.coefficients.overrides))
            runs.append(run)
            print_pending_notes(args)  # the reversal note, once a run was set up
            if run.meta.get("interrupted"):
                raise Interrupted(runs)
            if run.stopped:
                stops.append(f"{model} run stopped: {run.stopped}")
                if log is not None:  # the stop is an event in the log, at the last step
                    from bioflex_jsb.simulation.results import divergence_mode

                    log.event(run.stop_time_s, "ERROR", f"{model} run stopped "
                              f"({divergence_mode(run.stopped)}): {run.stopped}", name=model)
    except FdmError as exc:  # the airframe cannot load or trim at --speed
        raise UsageError(str(exc)) from None
    return runs, stops


def run(args: argparse.Namespace) -> int:
    from bioflex_jsb.cli.aircraft_option import resolve_flight
    from bioflex_jsb.simulation.results import gust_metrics

    resolve_flight(args)  # --speed and --gust of the aircraft
    build = wing_for_run(wing_from_args(args), args)
    args.models = resolve_models(args)
    config = run_config(args, args.models)
    controller_from_args(args)
    plot = args.plot if args.plot is not None else (None if args.json else "gust.png")
    check_plot_path(plot, args.force)
    log = None
    start_live(args, "gust")  # before log_path creates the file: a refusal leaves none
    check_distinct_outputs(("--out", args.out), ("--plot", plot))
    args.out = log_path(args, "gust", args.wing)
    if args.out:
        log = live_opener(args, open_log)(args.out, run_description(args, "gust", args.models),
                                          build)
    try:
        runs, stops = fly(args, build, config, log)
    except Interrupted as stop:
        last = stop.runs[-1]
        kept = f"; the log {args.out} holds every step flown" if args.out else ""
        print(f"bioflex-jsb gust: interrupted during the {last.model} run at "
              f"t = {last.time_s[-1] if len(last.time_s) else 0.0:.3f} s{kept}", file=sys.stderr)
        return 130
    finally:
        if log is not None:
            with closing():  # a stop signal now waits until the log is finished
                log.close()
        stop_live(args)
    summary = {}
    for r in runs:
        summary[r.model] = gust_metrics(r, args.gust_start).as_json()
        summary[r.model]["time_beyond_stall_s"] = r.meta["time_beyond_stall_s"]
        summary[r.model].update(lateral_peaks(r, args.gust_start))
    if plot:
        from bioflex_jsb.sinks import plotting

        try:
            plotting.time_histories(
                runs, plot,
                f"{build.variant.name} wing, {args.speed:g} m/s, gust {args.gust.text()}",
            )
        except OSError as exc:
            raise UsageError(f"cannot write plot {plot!r}: {exc.strerror}") from None
    if args.json:
        print_json({
            "wing": build.variant.name,
            "speed_m_s": args.speed,
            "gust": args.gust.text(),
            "mass_basis": build.mass_basis,
            "overrides": dict(build.model.coefficients.overrides),
            "summary": summary,
            "diverged": [r.model for r in runs if r.stopped is not None],
            "controller": runs[0].meta.get("controller") if runs else None,
            "lateral": {r.model: lateral_summary(r) for r in runs
                        if r.meta.get("span") == "full"},
            **lateral_aero_extra(args),
            "stopped": stops,
            "plot": plot,
            "out": args.out,
        })
    else:
        print_summary(build, args, summary)
        for r in runs:
            line = controller_line(r)
            if line:
                print(f"{r.model}: {line}")
            lateral = summary[r.model]
            if "peak_p_rad_s" in lateral:  # a gust that rolls or sideslips it
                print(f"{r.model}: lateral peaks |p| {math.degrees(lateral['peak_p_rad_s']):.2f} "
                      f"deg/s, |r| {math.degrees(lateral['peak_r_rad_s']):.2f} deg/s, |phi| "
                      f"{math.degrees(lateral['peak_phi_rad']):.2f} deg, |beta| "
                      f"{math.degrees(lateral['peak_beta_rad']):.2f} deg")
            if r.meta.get("span") == "full":
                lat = lateral_summary(r)
                print(f"{r.model}: both halves: roll rate {lat['p_min_deg_s']:+.2f} .. "
                      f"{lat['p_max_deg_s']:+.2f} deg/s, bank {lat['phi_min_deg']:+.2f} .. "
                      f"{lat['phi_max_deg']:+.2f} deg, tip twist starboard "
                      f"{lat['tip_twist_starboard_max_abs_deg']:.3f}, port "
                      f"{lat['tip_twist_port_max_abs_deg']:.3f} deg (largest), elastic "
                      f"rolling moment {lat['modal_roll_max_abs_n_m']:.4g} N m")
        if plot:
            print(f"time histories written to {plot}")
        if args.out:
            print(f"log written to {args.out}")
    for stop in stops:
        print(f"bioflex-jsb gust: diverged: {stop}", file=sys.stderr)
    if stops:
        return EXIT_DIVERGED
    return 0


def lateral_peaks(run, gust_start_s: float) -> dict[str, float]:
    """The largest |p|, |r| [rad/s], |phi|, |beta| [rad] after the gust start of a run whose
    gust has parts that vary over the aircraft (its channel p_g); {} for any other run or a
    diverged one."""
    if "p_g" not in run.channels or run.stopped is not None:
        return {}
    after = run.time_s >= gust_start_s
    if not after.any():
        return {}
    return {f"peak_{c}": float(abs(run[c][after]).max())
            for c in ("p_rad_s", "r_rad_s", "phi_rad", "beta_rad")}


def _cell(value, scale: float, width: int, digits: int = 3) -> str:
    return f"{'-':>{width}}" if value is None else f"{value * scale:{width}.{digits}f}"


def print_summary(build, args, summary) -> None:
    """The table of :func:`run`: one row per model (docstring of GustMetrics)."""
    deg = 180.0 / math.pi
    print(f"wing {build.variant.name}, {args.speed:g} m/s, gust {args.gust.text()} "
          f"(mass basis {build.mass_basis})")
    turbulence = any(m["kind"] == "turbulence" for m in summary.values())
    tail = (f"{'rms Δα [deg]':>13} {'rms Δn_z [-]':>13}" if turbulence
            else f"{'overshoot':>10} {'settling [s]':>13}")
    print(f"{'model':<8} {'Δu [m/s]':>9} {'Δα [deg]':>9} {'Δq [deg/s]':>11} {'Δθ [deg]':>9} "
          f"{'Δn_z [-]':>9} {tail}")
    for model, m in summary.items():
        if m["diverged"]:
            print(f"{model:<8} diverged at t = {m['divergence_time_s']:.3f} s "
                  f"({m['divergence_mode']}): no response metrics (see below)")
            continue
        row = (f"{model:<8} {_cell(m['peak_du_m_s'], 1.0, 9)} "
               f"{_cell(m['peak_dalpha_rad'], deg, 9)} {_cell(m['peak_dq_rad_s'], deg, 11)} "
               f"{_cell(m['peak_dtheta_rad'], deg, 9)} {_cell(m['peak_dn_z'], 1.0, 9)} ")
        if turbulence:
            row += f"{_cell(m['rms_dalpha_rad'], deg, 13)} {_cell(m['rms_dn_z'], 1.0, 13)}"
        else:
            over = "-" if m["overshoot"] is None else f"{100 * m['overshoot']:.1f}%"
            row += f"{over:>10} {_cell(m['settling_time_s'], 1.0, 13, 2)}"
        print(row)
    print("peaks: largest |perturbation from trim| after the gust start; "
          + ("rms: root mean square after the gust start (turbulence has no overshoot or "
             "settling time)" if turbulence else
             "overshoot: of α past trim after its first peak [% of that peak]; settling: "
             "until |Δα| stays within 5 % of its peak, '-' = not settled by the end of the run"))
    from bioflex_jsb.loads.summary import root_loads_lines

    for line in root_loads_lines(summary):  # root M and T peaks, both methods
        print(line)
    for model, m in summary.items():
        if m["time_beyond_stall_s"] > 0.0:
            print(f"note: {model}: angle of attack beyond the lift peak for "
                  f"{m['time_beyond_stall_s']:.2f} s (post-stall aerodynamics of the airframe; "
                  "the modal derivatives are linear and only indicative there)")
