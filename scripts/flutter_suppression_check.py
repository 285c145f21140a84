"""Check the shipped flutter suppression controller in the nonlinear co-simulation and draw
its figure.

Run:  python scripts/flutter_suppression_check.py [--controller fs_inertial-backward]
          [--plot docs/img/flutter_suppression.png] [--force]

1. LTI (api.closed_loop_flutter's model): the largest growth rate Re s [1/s] of the open and
   the closed loop against speed, 15-24 m/s.
2. Nonlinear runs (api.fly_gust, unsteady strips, coupled, sharp:0.05, 6 s) with the
   controller at 20.5, 20.75, 21.0 m/s: the logarithmic decrement's growth rate of η₁ from
   0.7 s (simulation/flutter_suppression.growth_from_response) and σ = 0 interpolated
   between the last bounded and the first diverging run; the open loop at 20.0 m/s.
3. Saturation: the closed loop through sharp:1 (a 1 m/s gust) at 19-22 m/s: the elevator's
   total deflection (trim + command) and its rate against the airframe's travel
   (systems/bioflex_flight_controls.xml: the command clipped to ±1, 0.34906585 rad per unit:
   ±20°; the flight controls have no rate limit and no actuator lag), and what stops a
   diverging run first (the wing's |η| beyond its linear range, or the elevator at its stop).
About 5 minutes on one core.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.plot_files import check_plot_target
from bioflex_jsb.simulation import flutter_suppression as FS

TRAVEL_RAD = 0.34906585  # systems/bioflex_flight_controls.xml: elevator-scale-rad, |norm| <= 1
FLUTTER_W_RAD_S = 13.5  # the closed loop's flutter frequency (api.closed_loop_flutter)


def fly(wing, v, gust, controller, duration=6.0):
    return api.fly_gust(wing, v, gust, models=("coupled",), duration_s=duration,
                        aero="unsteady", controller=controller)["coupled"]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--controller", default="fs_inertial-backward")
    p.add_argument("--wing", default="inertial-backward")
    p.add_argument("--plot", default="docs/img/flutter_suppression.png")
    p.add_argument("--force", action="store_true")
    args = p.parse_args()
    check_plot_target(args.plot, args.force)
    wing = api.load_wing(args.wing)
    ctrl = api.linear_controller(args.controller)
    speeds = np.arange(15.0, 24.01, 0.25)
    growth = {"open": [], "closed": [], "branch": []}
    for v in speeds:
        plant = FS.controlled_plant(wing, float(v))
        growth["open"].append(FS.growth_rate_1_s(plant, None)[0])
        growth["closed"].append(FS.growth_rate_1_s(plant, ctrl)[0])
        s = FS.closed_loop_roots(plant, ctrl)
        branch = s.real[(s.imag > 5.0) & (s.imag < 40.0)]  # none once the roots are real
        growth["branch"].append(float(np.max(branch)) if branch.size else math.nan)
    runs, sigma = {}, {}
    for v in (20.5, 20.75, 21.0):
        r = fly(wing, v, "sharp:0.05", ctrl)
        runs[("closed", v)] = r
        sigma[v] = FS.growth_from_response(r.time_s, r["eta1"], FLUTTER_W_RAD_S, 0.7)[0]
        print(f"closed loop {v:5.2f} m/s: sigma {sigma[v]:+.3f} 1/s, "
              f"{'stopped: ' + r.stopped if r.stopped else 'bounded over 6 s'}")
    runs[("open", 20.0)] = fly(wing, 20.0, "sharp:0.05", None)
    print(f"open loop 20.00 m/s: {runs[('open', 20.0)].stopped}")
    vs = sorted(sigma)
    for a, b in zip(vs, vs[1:], strict=False):
        if sigma[a] < 0.0 < sigma[b]:
            cross = a + (b - a) * (-sigma[a]) / (sigma[b] - sigma[a])
            print(f"nonlinear closed-loop flutter: {cross:.3f} m/s (sigma = 0 between "
                  f"{a:g} and {b:g} m/s)")
    print("saturation, sharp:1 closed loop: speed, trim elevator [deg], peak total [deg], "
          "peak rate [deg/s], stopped")
    for v in (19.0, 20.0, 20.5, 21.0, 22.0):
        r = fly(wing, v, "sharp:1", ctrl, duration=4.0)
        e = np.asarray(r["elevator_rad"])
        rate = np.diff(e) / np.diff(r.time_s)
        hit = np.nonzero(np.abs(e) >= TRAVEL_RAD * (1 - 1e-6))[0]
        stop = f"elevator at its stop at t = {r.time_s[hit[0]]:.3f} s; " if hit.size else ""
        print(f"  {v:5.2f}  {math.degrees(e[0]):6.2f}  {math.degrees(np.max(np.abs(e))):6.2f}"
              f"  {math.degrees(np.max(np.abs(rate))):8.1f}  "
              f"{stop}{r.stopped or 'bounded'}")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(1, 3, figsize=(16, 5))
    ax[0].plot(speeds, growth["open"], "k-", label="open loop (LTI)")
    ax[0].plot(speeds, growth["closed"], "b-", label=f"closed loop {ctrl.name} (LTI)")
    ax[0].plot(speeds, growth["branch"], "b--",
               label="closed loop, its flutter branch (5-40 rad/s)")
    ax[0].plot(list(sigma), list(sigma.values()), "ro", label="nonlinear, log decrement")
    ax[0].axhline(0.0, color="grey", lw=0.8)
    ax[0].set_xlabel("airspeed [m/s]")
    ax[0].set_ylabel("largest growth rate Re s [1/s]")
    ax[0].set_ylim(-3.0, 6.0)
    ax[0].legend(loc="upper left")
    ax[0].set_title(f"{args.wing}, unsteady strips")
    for key, style in ((("closed", 20.75), "b-"), (("closed", 21.0), "r-"),
                       (("open", 20.0), "k-")):
        r = runs[key]
        lab = f"{key[0]} loop {key[1]:g} m/s"
        ax[1].plot(r.time_s, r["eta1"], style, lw=0.8, label=lab)
        ax[2].plot(r.time_s, np.degrees(r["elevator_rad"]), style, lw=0.8, label=lab)
    ax[1].set_xlabel("time [s]")
    ax[1].set_ylabel("eta1 [rad]")
    ax[1].legend()
    ax[1].set_title("nonlinear runs, sharp:0.05 at 0.5 s")
    ax[2].set_xlabel("time [s]")
    ax[2].set_ylabel("elevator (trim + command) [deg]")
    ax[2].legend()
    fig.tight_layout()
    from bioflex_jsb.sinks.plotting import save_figure

    save_figure(fig, args.plot)
    print(f"written {args.plot}")


if __name__ == "__main__":
    main()
