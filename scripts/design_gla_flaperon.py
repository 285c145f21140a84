"""Design the shipped gust load alleviation controller with the elevator and the flaperons
and print its LTI prediction beside the elevator-only controller's.

Run:  python scripts/design_gla_flaperon.py [--wing optimised] [--speed 15] [--out FILE.toml]
      [--force]

The design (bioflex_jsb.loads.alleviation_flaperon.design_two_surface): static output
feedback [δe, δf] = K [Δα, q] from an α vane and the pitch rate to the elevator and the
flaperons (both ailerons, + trailing edges down), minimising the root bending moment's
tuned-gust peak (the 10 gradients of `loads --tuned`, U_ref 3 m/s) by the LTI model (Eq. 4
with its controls and the flaperon input, JSBSim's rigid block, the loop closed at 960 Hz
with the run's one step of delay), the elevator within 10° and the flaperon within 8° in
every reference gust. It writes bioflex_jsb/data/controllers/gla_flaperon_<wing>.toml with
the design and the prediction in its notes; `bioflex-jsb gust --controller
gla_flaperon_optimised` flies it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.loads.alleviation_flaperon import (
    command_peaks,
    design_two_surface,
    static_gains,
)
from bioflex_jsb.simulation.controller import SHIPPED_DIR


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--wing", default="optimised")
    p.add_argument("--speed", type=float, default=15.0, help="trim speed [m/s]")
    p.add_argument("--out", default=None, help="controller file (.toml or .npz)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    args = p.parse_args()
    wing = api.load_wing(args.wing)
    _, v, plant = api._gla_plant(wing, args.speed, flaperon=True)
    dt = 1.0 / 960.0
    gradients = api._gla_gradients(wing, v)  # the elevator-only design's tuned gradients [m]
    ctrl, record = design_two_surface(plant, dt, gradients_m=gradients)
    pred = api.predict_alleviation(wing, ctrl, v)
    elev = api.predict_alleviation(wing, "gla_optimised", v)
    gains = record["gains"]
    print(f"{args.wing} wing, {v:g} m/s: {gains} ({record['iterations']} iterations, "
          f"cost {record['cost']:.5f})")
    print(f"tuned-gust root bending peak ratio: elevator + flaperon {pred.tuned_ratio:.4f}, "
          f"elevator only {elev.tuned_ratio:.4f}")
    print("per gradient H [m]:", np.round(pred.open_peaks.gradients_m, 3).tolist())
    print("  ratio closed/open:", np.round(pred.peak_ratios, 4).tolist())
    peaks = command_peaks(pred.closed_model, v, gradients)
    for name, values in peaks.items():
        print(f"  {name} peak [deg]:", np.round(np.degrees(values), 2).tolist())
    print(f"von Karman 1 m/s, L 30 m, 0.25-150 Hz: RMS ratio elevator + flaperon "
          f"{pred.rms_ratio:.4f}, elevator only {elev.rms_ratio:.4f}")
    notes = {
        "design": "static output feedback to the elevator and the flaperons minimising the "
                  "root bending moment's tuned-gust peak on the LTI model "
                  "(loads/alleviation_flaperon.py; scripts/design_gla_flaperon.py)",
        "wing": args.wing, "speed_m_s": v,
        "elevator_limit_deg": record["elevator_limit_deg"],
        "flaperon_limit_deg": record["flaperon_limit_deg"],
        "objective": record["objective"],
        "predicted_tuned_ratio": round(pred.tuned_ratio, 6),
        "predicted_rms_ratio": round(pred.rms_ratio, 6),
        "units": "rows elevator, flaperon [rad] (+ trailing edge(s) down); per alpha [rad] "
                 "and per q [rad/s]",
    }
    out = Path(args.out) if args.out else SHIPPED_DIR / f"gla_flaperon_{args.wing}.toml"
    k = [list(gains[o].values()) for o in ("elevator", "flaperon")]
    final = static_gains(k, tuple(gains["elevator"]), 0.0, f"gla_flaperon_{args.wing}", notes)
    final.save(out, overwrite=args.force)
    print(f"written {out}")


if __name__ == "__main__":
    main()
