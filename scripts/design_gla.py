"""Design the shipped gust load alleviation controller and print its LTI prediction.

Run:  python scripts/design_gla.py [--wing optimised] [--speed 15] [--out FILE.toml] [--force]

The design (bioflex_jsb.loads.alleviation.design_output_feedback through
api.design_alleviation): static output feedback δe = K_α Δα + K_q q from the angle of attack
(an α vane: the gust at once) and the pitch rate to the elevator, minimising the root bending
moment's tuned-gust peak (the 10 gradients of `loads --tuned`, U_ref 3 m/s) by the LTI model
(Eq. 4 with its controls, JSBSim's rigid block, the loop closed at 960 Hz with the run's one
step of delay), the elevator's increment within 10°. It writes the controller file
(bioflex_jsb/data/controllers/gla_<wing>.toml by default) with the design and the prediction
in its notes; `bioflex-jsb gust --controller gla_optimised` flies it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.simulation.controller import SHIPPED_DIR, LinearController


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--wing", default="optimised")
    p.add_argument("--speed", type=float, default=15.0, help="trim speed [m/s]")
    p.add_argument("--out", default=None, help="controller file (.toml or .npz)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    args = p.parse_args()
    wing = api.load_wing(args.wing)
    ctrl, record = api.design_alleviation(wing, args.speed)
    pred = api.predict_alleviation(wing, ctrl, args.speed)
    gains = record["gains"]
    print(f"{args.wing} wing, {args.speed:g} m/s: delta_e = "
          + " + ".join(f"{k:.4f} {s}" for s, k in gains.items())
          + f"  ({record['iterations']} iterations)")
    print(f"tuned-gust root bending peak: open {pred.open_peaks.tuned_peak:.4f} N*m at "
          f"H = {pred.open_peaks.gradients_m[pred.open_peaks.critical]:.3f} m, closed "
          f"{pred.closed_peaks.tuned_peak:.4f} N*m at "
          f"H = {pred.closed_peaks.gradients_m[pred.closed_peaks.critical]:.3f} m: "
          f"ratio {pred.tuned_ratio:.4f}")
    print("per gradient H [m]:", np.round(pred.open_peaks.gradients_m, 3).tolist())
    print("  ratio closed/open:", np.round(pred.peak_ratios, 4).tolist())
    print("  elevator peak [deg]:",
          np.round(np.degrees(pred.closed_peaks.elevator_peaks_rad), 2).tolist())
    print(f"von Karman 1 m/s, L 30 m, 0.25-150 Hz: RMS open {pred.open_rms:.4f}, closed "
          f"{pred.closed_rms:.4f} N*m: ratio {pred.rms_ratio:.4f}")
    notes = {
        "design": "static output feedback to the elevator minimising the root bending "
                  "moment's tuned-gust peak on the LTI model (loads/alleviation.py; "
                  "scripts/design_gla.py)",
        "wing": args.wing, "speed_m_s": args.speed,
        "elevator_limit_deg": record["elevator_limit_deg"],
        "objective": record["objective"],
        "predicted_tuned_ratio": round(pred.tuned_ratio, 6),
        "predicted_rms_ratio": round(pred.rms_ratio, 6),
        "units": "elevator [rad] per alpha [rad] and per q [rad/s]",
    }
    out = Path(args.out) if args.out else SHIPPED_DIR / f"gla_{args.wing}.toml"
    final = LinearController.from_arrays(None, None, None, [list(gains.values())], 0.0,
                                         list(gains), ["elevator"], f"gla_{args.wing}", notes)
    final.save(out, overwrite=args.force)
    print(f"written {out}")


if __name__ == "__main__":
    main()
