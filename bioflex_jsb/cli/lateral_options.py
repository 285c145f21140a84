"""``gust``'s options for both wing halves: ``--span`` and an aileron step or doublet
(docs/lateral.md, "Both halves in the co-simulation").

``--aileron-step DEG`` / ``--aileron-doublet DEG``: JSBSim's aileron δa = ½ (left − right)
[deg, + rolls right] over the trim, from ``--aileron-start`` [s] (a doublet: +DEG for
``--aileron-width`` [s], −DEG as long, then back to the trim). An aileron input flies both
halves unless ``--span half`` is given (then the modes stay symmetric and only JSBSim's rigid
tables roll). The aileron's strips are the definition's ``[aileron]`` (``--aircraft``), or
the prototype variant's shipped definition's (``--wing``); a wing without one flies its
antisymmetric modes driven by the roll rate alone (said on stderr).
"""

from __future__ import annotations

import argparse
import math
import sys

from bioflex_jsb.cli.common import UsageError, number_type

AILERON_MAX_DEG = 30.0  # |δa| accepted [deg]; the flight controls clip it to their travel
WIDTH_RANGE_S = (0.01, 10.0)  # a doublet's half width [s]

HELP_SPAN = ("half (the half wing's symmetric modes, the paper's) or full (both halves: the "
             "antisymmetric modes too, driven by the roll rate and the ailerons; their rolling "
             "moment to JSBSim; channels asym_eta<i>, tip_twist_port_rad, "
             "tip_twist_starboard_rad, modal_roll_n_m, aileron_rad; with --aero unsteady "
             "their own lag states and apparent mass). Default: full "
             "with an aileron input, else half")


LATERAL_AERO_CHOICES = ("strips", "lattice")  # aerodynamics/antisymmetric_loading.py
HELP_LATERAL_AERO = ("the antisymmetric loading of the wing's lateral elastic model (both "
                     "halves): strips (default: each strip's C_la c alone) or lattice (the "
                     "vortex lattice's antisymmetric loading of the whole distribution: the "
                     "roll rate's, the modes' and the aileron's lift; quasi-steady only; "
                     "docs/lateral.md, \"The lattice in the lateral elastic model\")")


def add_lateral_aero_argument(p: argparse.ArgumentParser, where: str = "") -> None:
    """--lateral-aero {strips,lattice}; ``where`` ends its help (when it applies)."""
    p.add_argument("--lateral-aero", choices=LATERAL_AERO_CHOICES, default=None,
                   help=HELP_LATERAL_AERO + where)


def check_lateral_aero(args, full_span: bool, what: str) -> None:
    """One line (UsageError) for ``--lateral-aero lattice`` where no lateral elastic model
    is built (``full_span`` False; ``what`` says where it would be)."""
    if getattr(args, "lateral_aero", None) == "lattice" and not full_span:
        raise UsageError(f"--lateral-aero lattice loads both wing halves' antisymmetric "
                         f"modes: {what}")
    if getattr(args, "lateral_aero", None) == "lattice" and \
            getattr(args, "aero", None) == "unsteady":
        raise UsageError("--lateral-aero lattice is quasi-steady (the unsteady strips are "
                         "Theodorsen's, strip by strip); accepted with --aero unsteady: "
                         "--lateral-aero strips")


def lateral_aero_extra(args) -> dict:
    """What a run description records of ``--lateral-aero`` (a rerun flies it again):
    ``lateral_aero`` and the ``span`` it loads, or nothing for the default."""
    if getattr(args, "lateral_aero", None) is None:
        return {}
    return {"lateral_aero": args.lateral_aero, "span": "full"}


def add_lateral_arguments(p: argparse.ArgumentParser) -> None:
    """--span, --aileron-step, --aileron-doublet, --aileron-start, --aileron-width,
    --lateral-aero."""
    p.add_argument("--span", choices=("half", "full"), default=None, help=HELP_SPAN)
    add_lateral_aero_argument(p, "; with --span full (or an aileron input)")
    angle = number_type("aileron angle", "deg", low=-AILERON_MAX_DEG, high=AILERON_MAX_DEG)
    group = p.add_mutually_exclusive_group()
    group.add_argument("--aileron-step", type=angle, default=None, metavar="DEG",
                       help="an aileron step over the trim [deg, JSBSim's delta_a = (left - "
                       f"right)/2, + rolls right], |DEG| <= {AILERON_MAX_DEG:g} (the surfaces "
                       "stop at their travel), from --aileron-start")
    group.add_argument("--aileron-doublet", type=angle, default=None, metavar="DEG",
                       help="an aileron doublet [deg]: +DEG for --aileron-width, -DEG as long, "
                       "then the trim's")
    p.add_argument("--aileron-start", type=number_type("aileron start", "s", low=0.0),
                   default=0.5, metavar="S",
                   help="when the aileron input starts [s], before the end of --duration "
                   "(default 0.5)")
    p.add_argument("--aileron-width", type=number_type(
        "aileron doublet width", "s", low=WIDTH_RANGE_S[0], high=WIDTH_RANGE_S[1]),
        default=0.5, metavar="S", help=f"each half of the doublet [s], {WIDTH_RANGE_S[0]:g} "
        f"to {WIDTH_RANGE_S[1]:g} (default 0.5)")


def lateral_run_options(args, build, controller=None) -> dict:
    """run_gust's ``span``, ``aileron``, ``aileron_input`` of the arguments (only those
    that differ from a half-wing run's: {} for one); a ``controller`` that commands the
    aileron flies both halves (``--span half`` and an aileron input beside it refused)."""
    from bioflex_jsb.simulation.full_span import AileronInput

    angle_deg = args.aileron_step if args.aileron_step is not None else args.aileron_doublet
    aileron_ctrl = "aileron" in getattr(controller, "outputs", ())
    if aileron_ctrl and angle_deg is not None:
        raise UsageError("--controller commands the aileron: drop --aileron-step / "
                         "--aileron-doublet (both write JSBSim's aileron command)")
    if aileron_ctrl and args.span == "half":
        raise UsageError("--controller commands the aileron, which needs both wing halves: "
                         "drop --span half (accepted: --span full)")
    span = args.span or ("full" if angle_deg is not None or aileron_ctrl else "half")
    options: dict = {}
    if angle_deg is not None:
        if args.aileron_start >= args.duration:
            raise UsageError(f"--aileron-start {args.aileron_start:g} s is not before the end "
                             f"of --duration {args.duration:g} s")
        kind = "step" if args.aileron_step is not None else "doublet"
        options["aileron_input"] = AileronInput(kind, math.radians(angle_deg),
                                                args.aileron_start, args.aileron_width)
    check_lateral_aero(args, span == "full", "give --span full (or an aileron input)")
    if span == "half":
        return options | {"span": "half"} if options else {}
    return options | {"span": "full", "aileron": _aileron(args, build)}


def lateral_description(args) -> dict:
    """The run description's entries of ``--span full`` and an aileron input (``rerun``
    flies them again; {} for a half-wing run without one, whose description is as before)."""
    angle = getattr(args, "aileron_step", None)
    kind = "aileron_step" if angle is not None else "aileron_doublet"
    if angle is None:
        angle = getattr(args, "aileron_doublet", None)
    out: dict = {}
    if getattr(args, "span", None) == "full" or angle is not None:
        out["span"] = getattr(args, "span", None) or "full"
    if angle is not None:
        out.update({kind: float(angle), "aileron_start": float(args.aileron_start),
                    "aileron_width": float(args.aileron_width)})
    return out


def span_options(args, build, altitude_m: float | None = None) -> dict:
    """``span`` and ``aileron`` of ``--span`` for a session (sitl, ardupilot) starting at
    ``altitude_m`` [m above sea level; None: ``--altitude``, else sea level]: {} for the
    half wing."""
    check_lateral_aero(args, args.span == "full", "give --span full")
    if args.span != "full":
        return {}
    if altitude_m is None:
        altitude_m = float(getattr(args, "altitude", None) or 0.0)
    return {"span": "full", "aileron": _aileron(args, build, altitude_m)}


def span_aileron(args, build):
    """The aileron of ``--aircraft``'s definition or of the prototype variant's, or None."""
    from bioflex_jsb.simulation.full_span import prototype_aileron

    aircraft = getattr(args, "aircraft_definition", None)
    return (aircraft.definition.aileron if aircraft is not None
            else prototype_aileron(build.variant.name))


def _aileron(args, build, altitude_m: float = 0.0):
    """:func:`span_aileron`, with a note on stderr when there is none, or when the run's
    speed at ``altitude_m`` [m above sea level] is near or above the wing's aileron reversal
    speed (:func:`reversal_note`)."""
    aileron = span_aileron(args, build)
    if aileron is None:
        print(f"bioflex-jsb: note: wing {build.variant.name!r} has no [aileron]: its "
              "antisymmetric modes are driven by the roll rate alone", file=sys.stderr)
        return None
    speed = getattr(args, "speed", None)
    if speed is not None:
        note = reversal_note(build, aileron, float(speed), altitude_m)
        if note:  # said once the run is set up: a refusal of the setup stays one line
            args.pending_notes = [*getattr(args, "pending_notes", []), note]
    return aileron


def print_pending_notes(args) -> None:
    """Print on stderr the notes :func:`_aileron` kept for after the run's setup (the
    reversal note), once."""
    for note in getattr(args, "pending_notes", []):
        print(f"bioflex-jsb: note: {note}", file=sys.stderr)
    args.pending_notes = []


REVERSAL_MARGIN = 0.9  # a run at 90 % of the reversal speed or more gets the note


def reversal_note(build, aileron, speed_m_s: float, altitude_m: float) -> str | None:
    """One line when ``speed_m_s`` [m/s] is at least :data:`REVERSAL_MARGIN` of the aileron
    reversal speed of ``build``'s wing with ``aileron`` in the ISA at ``altitude_m`` [m]
    (as `bioflex-jsb aileron` reports it: the flight model's modes, root held), else None:
    above it the ailerons roll the elastic aircraft the other way, and an autopilot's roll
    loop then drives the bank away from its target."""
    from bioflex_jsb.aeroelasticity.aileron import flight_roll_strips, reversal_speed_m_s
    from bioflex_jsb.runtime.jsbsim_aircraft import isa_density_kg_m3

    v_r = reversal_speed_m_s(flight_roll_strips(build, aileron), isa_density_kg_m3(altitude_m))
    if v_r is None or speed_m_s < REVERSAL_MARGIN * v_r:
        return None
    if speed_m_s >= v_r:
        what = "above", "its ailerons roll the elastic aircraft the other way"
    else:
        what = "within 10 % of", "its ailerons have lost most of their rolling power"
    return (f"{speed_m_s:g} m/s is {what[0]} the {build.variant.name} wing's aileron "
            f"reversal speed, {v_r:.1f} m/s (ISA at {altitude_m:g} m; `bioflex-jsb aileron "
            f"--aircraft`): {what[1]}")


def lateral_summary(run) -> dict[str, float]:
    """A full-span run's lateral peaks (its history's channels): roll rate and bank
    [deg/s, deg], the largest tip twist of each half [deg] and elastic rolling moment
    [N·m]."""
    import numpy as np

    c = run.channels

    def deg(name: str, f) -> float:
        v = np.asarray(c[name], dtype=float)
        return float(np.degrees(f(v))) if v.size else math.nan

    moment = np.asarray(c["modal_roll_n_m"], dtype=float)
    return {
        "p_min_deg_s": deg("p_rad_s", np.min), "p_max_deg_s": deg("p_rad_s", np.max),
        "phi_min_deg": deg("phi_rad", np.min), "phi_max_deg": deg("phi_rad", np.max),
        "tip_twist_starboard_max_abs_deg": deg("tip_twist_starboard_rad",
                                               lambda v: np.max(np.abs(v))),
        "tip_twist_port_max_abs_deg": deg("tip_twist_port_rad", lambda v: np.max(np.abs(v))),
        "modal_roll_max_abs_n_m": float(np.max(np.abs(moment))) if moment.size else math.nan,
    }
