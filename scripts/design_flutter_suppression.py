"""Design the shipped flutter suppression controller and print its closed-loop flutter speed.

Run:  python scripts/design_flutter_suppression.py [--wing inertial-backward]
          [--signals q] [--design-speed 21] [--out FILE.toml] [--force]

The design (bioflex_jsb.simulation.flutter_suppression.design_static_feedback through
api.design_flutter_suppression): a static output feedback δe = K s from the run's signals
(default the pitch-rate gyro q [rad/s]: a pitch damper) to the elevator [rad], minimising by
Nelder-Mead the largest growth rate of the closed loop's oscillatory and fast roots over
17 m/s to the design speed every 0.5 m/s, plus 0.1 Σ K² (the elevator's travel), on the
unsteady LTI model (Eq. 4 on unsteady strips with Küssner's gust and the elevator, the loop
closed at 960 Hz with the run's one step of delay). It then finds the open- and closed-loop
flutter speeds (api.closed_loop_flutter, 15-26 m/s, 0.25 m/s grid, bisection to 1 mm/s) and
writes the controller file (bioflex_jsb/data/controllers/fs_<wing>.toml by default) with the
design and the prediction in its notes; `bioflex-jsb gust --controller fs_inertial-backward
--aero unsteady --models coupled --speed 20` flies it. About 3 minutes on one core.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from bioflex_jsb import api
from bioflex_jsb.simulation.controller import SHIPPED_DIR, LinearController


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--wing", default="inertial-backward")
    p.add_argument("--signals", default="q", help="comma-separated run signals")
    p.add_argument("--design-speed", type=float, default=21.0, help="[m/s]")
    p.add_argument("--out", default=None, help="controller file (.toml or .npz)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    args = p.parse_args()
    wing = api.load_wing(args.wing)
    signals = tuple(args.signals.split(","))
    ctrl, record = api.design_flutter_suppression(wing, args.design_speed, signals)
    open_loop = api.closed_loop_flutter(wing, None, (15.0, 26.0))
    closed = api.closed_loop_flutter(wing, ctrl, (15.0, 26.0))
    gains = record["gains"]
    print(f"{args.wing}: delta_e = " + " + ".join(f"{k:.4f} {s}" for s, k in gains.items())
          + f"  ({record['iterations']} iterations, J {record['cost_1_s']:.3f} 1/s)")
    print(f"flutter: open loop {open_loop.speed_m_s:.3f} m/s at "
          f"{open_loop.frequency_rad_s:.2f} rad/s; closed loop {closed.speed_m_s:.3f} m/s at "
          f"{closed.frequency_rad_s:.2f} rad/s: margin "
          f"{closed.speed_m_s - open_loop.speed_m_s:+.3f} m/s "
          f"({100 * (closed.speed_m_s / open_loop.speed_m_s - 1):+.1f} %)")
    notes = {
        "design": "static output feedback to the elevator minimising the closed loop's "
                  "largest growth rate over 17 m/s to the design speed on the unsteady LTI "
                  "model (simulation/flutter_suppression.py; "
                  "scripts/design_flutter_suppression.py)",
        "wing": args.wing, "aero": "unsteady",
        "design_speed_m_s": args.design_speed,
        "open_loop_flutter_m_s": round(open_loop.speed_m_s, 3),
        "closed_loop_flutter_m_s": round(closed.speed_m_s, 3),
        "closed_loop_flutter_rad_s": round(closed.frequency_rad_s, 3),
        "units": "elevator [rad] per " + ", ".join(
            f"{s} [{'rad/s' if s == 'q' else '-' if s == 'n_z' else 'SI'}]" for s in signals),
    }
    out = Path(args.out) if args.out else SHIPPED_DIR / f"fs_{args.wing}.toml"
    final = LinearController.from_arrays(None, None, None, [list(gains.values())], 0.0,
                                         list(gains), ["elevator"], f"fs_{args.wing}", notes)
    final.save(out, overwrite=args.force)
    print(f"written {out}")


if __name__ == "__main__":
    main()
