"""The roll rate after an aileron command step, with and without the aileron's unsteady
(Theodorsen) terms: the c172_elastic with an estimated aileron and actuator.

The c172_elastic's definition has no ``[aileron]`` (JSBSim's c172p carries the rigid
aileron, C_lδa 0.229); this script gives it one, an ESTIMATE of the C172's: outboard of the
flaps from 0.55 to 0.97 of the semispan, 25 % of the chord (hinge 0.75), behind a
second-order actuator of 40 rad/s and damping 0.7 (a servo's bandwidth, ~6 Hz; a manual
aircraft's cables and pilot are slower). It builds the unsteady lateral model at the
aircraft's cruise speed (``api.lateral_model(..., "coupled", aero="unsteady")``) with the
aileron's Theodorsen terms (its circulatory lift through the wake's lag, its δ̇, δ̈
apparent mass) and without them (``flap_terms=False``: the aileron's quasi-steady load), and
prints the roll rate p [rad/s] after a step of the command ``aileron_cmd`` (0.5 deg,
+ rolls right) at a few times, exactly (matrix exponential). ``--json`` for the numbers.

    python scripts/aileron_actuator_response.py [--step-deg 0.5] [--speed 57.8] [--json]
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.actuated_aileron import COMMAND_INPUT, step_response
from bioflex_jsb.aeroelasticity.control_surface import ControlSurface, SurfaceActuator
from bioflex_jsb.definition.aircraft import Aircraft

AIRCRAFT = "c172_elastic"
# ESTIMATE of the C172's aileron: outboard of the flaps (which end near 0.55 of the
# semispan) to near the tip, 25 % of the chord (script docstring)
AILERON_SPAN = (0.55, 0.97)  # fractions of the semispan
AILERON_HINGE = 0.75  # chord fraction aft of the leading edge
ACTUATOR = SurfaceActuator(natural_frequency_rad_s=40.0, damping_ratio=0.7)
TIMES_S = (0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 1.0, 2.0)


def c172_with_aileron(actuator: SurfaceActuator = ACTUATOR) -> Aircraft:
    """The c172_elastic with the estimated aileron and ``actuator`` (module docstring)."""
    base = api.load_aircraft(AIRCRAFT)
    semi = base.definition.semispan_m
    surface = ControlSurface(AILERON_SPAN[0] * semi, AILERON_SPAN[1] * semi, AILERON_HINGE)
    return Aircraft(dataclasses.replace(base.definition, aileron=surface,
                                        aileron_actuator=actuator))


def roll_rate_response(aircraft, speed_m_s: float | None = None, step_deg: float = 0.5,
                       times_s=TIMES_S) -> dict:
    """p [rad/s] at ``times_s`` after an ``aileron_cmd`` step of ``step_deg`` [deg], the
    unsteady lateral model with and without the aileron's Theodorsen terms."""
    out = {"aircraft": aircraft.name, "step_deg": float(step_deg),
           "times_s": [float(t) for t in times_s]}
    for key, flap in (("with_t_terms", True), ("without_t_terms", False)):
        ss = api.lateral_model(aircraft, speed_m_s, "coupled", aero="unsteady",
                               flap_terms=flap)
        y = step_response(ss, COMMAND_INPUT, math.radians(step_deg), np.asarray(times_s))
        out[key] = [float(v) for v in y[:, ss.outputs.index("p")]]
        out["speed_m_s"] = float(ss.speed_m_s)
        out["actuator"] = ss.notes["aileron_actuator"]
    out["change"] = [w / wo - 1.0 for w, wo in zip(out["with_t_terms"],
                                                   out["without_t_terms"], strict=True)]
    return out


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--step-deg", type=float, default=0.5,
                   help="aileron command step [deg], + rolls right; -30..30 (default 0.5)")
    p.add_argument("--speed", type=float, default=None,
                   help="airspeed [m/s] (default: the aircraft's cruise, 57.8)")
    p.add_argument("--json", action="store_true", help="print the numbers as JSON")
    args = p.parse_args(argv)
    if not (math.isfinite(args.step_deg) and -30.0 <= args.step_deg <= 30.0):
        p.error(f"--step-deg must be within -30..30 deg, got {args.step_deg}")
    res = roll_rate_response(c172_with_aileron(), args.speed, args.step_deg)
    if args.json:
        print(json.dumps(res, indent=2))
        return 0
    print(f"{res['aircraft']} + estimated aileron at {res['speed_m_s']:g} m/s, "
          f"aileron_cmd step {res['step_deg']:g} deg; actuator: {res['actuator']}")
    print(f"{'t [s]':>6} {'p with T [rad/s]':>17} {'p without [rad/s]':>18} {'change':>8}")
    for t, w, wo, ch in zip(res["times_s"], res["with_t_terms"], res["without_t_terms"],
                            res["change"], strict=True):
        print(f"{t:6.2f} {w:17.5f} {wo:18.5f} {100.0 * ch:7.1f}%")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
