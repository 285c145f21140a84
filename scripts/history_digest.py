"""A digest of every channel of every step of a set of gust runs: run it on two trees and
compare, to show that a change to the step's or the driver's code leaves the results as
they were, to the bit.

    PYTHONPATH=<tree> python scripts/history_digest.py [--json] > digest_<tree>.txt
    diff digest_before.txt digest_after.txt        # no output: the same runs, bit for bit

Each case is a ``run_gust`` of the optimised prototype at 15 m/s (the compiled step; the
readable Python step for ``python``): the half wing (rigid, coupled, qsd through sharp:3;
coupled unsteady; coupled with section loads; a run of 130 s, kept as its envelope) and
both halves (``span`` full: rigid, coupled, qsd through 1cos:3:20+roll:0.5:20 with an
aileron step of 5°; coupled through Dryden turbulence with its rolling part; 20 s through
sharp:0.3; one that leaves the valid range after an aileron step of 2°). Per case it
prints the steps, the channels and a SHA-256 of the channel names, the time and the
channels' float64 bytes in name order, and ``stopped``.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math

import numpy as np

from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.coupled_step import configure_airframe
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.full_span import AileronInput, prototype_aileron
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

SPEED_M_S = 15.0
# name: (model, span, gust, duration [s], options)
CASES = {
    "half_rigid": ("rigid", "half", "sharp:3", 2.0, {}),
    "half_coupled": ("coupled", "half", "sharp:3", 2.0, {}),
    "half_qsd": ("qsd", "half", "sharp:3", 2.0, {}),
    "half_coupled_python": ("coupled", "half", "sharp:3", 0.5, {"compiled": False}),
    "half_coupled_unsteady": ("coupled", "half", "1cos:3:20", 1.0, {"aero": "unsteady"}),
    "half_coupled_loads": ("coupled", "half", "sharp:3", 1.0, {"loads": True}),
    "half_coupled_envelope": ("coupled", "half", "sharp:0.3", 130.0, {}),
    "full_rigid": ("rigid", "full", "1cos:3:20+roll:0.5:20", 2.0, {"aileron": 5.0}),
    "full_coupled": ("coupled", "full", "1cos:3:20+roll:0.5:20", 2.0, {"aileron": 5.0}),
    "full_qsd": ("qsd", "full", "1cos:3:20+roll:0.5:20", 2.0, {"aileron": 5.0}),
    "full_coupled_dryden": ("coupled", "full", "dryden:1:100:7+pg", 2.0, {}),
    "full_coupled_long": ("coupled", "full", "sharp:0.3", 20.0, {}),
    "full_coupled_stops": ("coupled", "full", "sharp:0.3", 6.0, {"aileron": 2.0}),
}


def digest(history) -> str:
    """SHA-256 of the names, the time and every channel's float64 bytes in name order."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(history.time_s, dtype=np.float64).tobytes())
    for name in sorted(history.channels):
        h.update(name.encode())
        h.update(np.ascontiguousarray(history.channels[name], dtype=np.float64).tobytes())
    return h.hexdigest()


def run_case(build, name: str) -> dict[str, object]:
    model, span, gust, duration_s, opts = CASES[name]
    aero = opts.get("aero", "quasi-steady")
    setup = RunConfig(SPEED_M_S, parse_gust(gust), duration_s=duration_s, gust_start_s=0.2,
                      dt_s=DEFAULT_DT_S, models=(model,), aero=aero)
    airframe = Airframe()
    configure_airframe(airframe, DEFAULT_DT_S)
    extra: dict[str, object] = {}
    if span == "full":
        extra = {"span": "full", "aileron": prototype_aileron(build.variant.name)}
        if "aileron" in opts:
            extra["aileron_input"] = AileronInput("step", math.radians(opts["aileron"]), 0.5)
    wing = build if span == "full" or aero == "unsteady" else build.model
    history = run_gust(airframe, wing, model, setup, compiled=opts.get("compiled", True),
                       loads=build if opts.get("loads") else None, **extra)
    return {"case": name, "steps": int(history.meta["steps"]),
            "history": history.meta["history"], "channels": len(history.channels),
            "stopped": history.stopped, "sha256": digest(history)}


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--cases", default=",".join(CASES),
                   help=f"comma-separated subset of {', '.join(CASES)} (default all)")
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    names = [c for c in a.cases.split(",") if c]
    unknown = [c for c in names if c not in CASES]
    if unknown:
        p.error(f"unknown cases {unknown}; accepted: {', '.join(CASES)}")
    build = build_wing(VARIANTS["optimised"])
    rows = [run_case(build, c) for c in names]
    if a.json:
        print(json.dumps(rows, indent=1))
        return
    for r in rows:
        print(f"{r['case']:24s} {r['steps']:7d} steps {r['channels']:3d} channels "
              f"{r['history']:8s} {r['sha256']}  stopped={r['stopped']}")


if __name__ == "__main__":
    main()
