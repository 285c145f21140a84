"""Design the shipped roll damper of the c172_elastic (δa = −K p on both wing halves) and
print its figure of merit on the linear lateral model.

Run:  python scripts/design_roll_damper.py [--aircraft c172_elastic] [--speed 57.8]
      [--factor 2] [--out FILE.toml] [--force]

The plant is the coupled lateral model of the aircraft's wing on its JSBSim airframe at the
trim (β, p, r, φ and three antisymmetric modes; inputs v_g, aileron, p_g:
drivers/compare_lateral.py, the model `compare --span full` checks against the flown runs).
The gain K [rad of aileron per rad/s of roll rate] is the one whose continuous closed loop
A − K B_δa C_p has its roll-subsidence root ``--factor`` times the open loop's (the time
constant τ_R divided by it), found by bisection (the root moves left monotonically with K
over the bracket). Printed: the roll root and τ_R open and closed, the Dutch roll
and the first antisymmetric mode before and after, and the peak roll rate and aileron of the
rolling gust `none+roll:0.1:40` through the discrete closed loop at 960 Hz with the run's
one step of delay (simulation/closed_loop.py), elastic and rigid. It writes
bioflex_jsb/data/controllers/roll_damper_<aircraft>.toml (a static gain from p_rad_s to
the aileron) with the design in its notes; `bioflex-jsb gust --aircraft c172_elastic
--controller roll_damper_c172_elastic --gust none+roll:0.1:40` flies it on both halves.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.drivers.compare_lateral import full_span_lateral_model
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.closed_loop import close_loop, lateral_signal_outputs, respond
from bioflex_jsb.simulation.controller import SHIPPED_DIR, LinearController

DT_S = 1.0 / 960.0  # the co-simulation's default step [s]
GUST = "none+roll:0.1:40"  # the reference rolling gust (tests/test_compare_full_span.py's)
GUST_P_RAD_S, GUST_LENGTH_M = 0.1, 40.0  # its peak roll rate and length
GUST_START_S, DURATION_S = 0.5, 3.0  # the gust runs' defaults [s]
K_BRACKET = (0.0, 1.0)  # [rad per rad/s]: 1 rad of aileron at 1 rad/s of roll rate


def roll_root(a: np.ndarray) -> float:
    """The roll-subsidence root [1/s] of a lateral model's A: the faster of its two real
    roots (the other the spiral; the Dutch roll and the antisymmetric modes are complex
    pairs, checked)."""
    lam = np.linalg.eigvals(a)
    real = sorted(v.real for v in lam if abs(v.imag) < 1e-9)
    if len(real) != 2:
        raise SystemExit(f"expected two real roots (spiral, roll), got {real}")
    return float(real[0])


def closed_a(ss, k: float) -> np.ndarray:
    """A − K B_δa C_p of the lateral model ``ss`` (continuous, no delay)."""
    b = np.asarray(ss.b, dtype=float)[:, ss.inputs.index("aileron")]
    c = np.asarray(ss.c, dtype=float)[ss.outputs.index("p")]
    return np.asarray(ss.a, dtype=float) - k * np.outer(b, c)


def design_gain(ss, factor: float) -> float:
    """K with the roll root ``factor`` times the open loop's (bisection on K_BRACKET)."""
    target = factor * roll_root(np.asarray(ss.a, dtype=float))
    lo, hi = K_BRACKET
    if roll_root(closed_a(ss, hi)) > target:
        raise SystemExit(f"no gain up to {hi} makes the roll root {factor} times faster")
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if roll_root(closed_a(ss, mid)) > target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def modes_line(a: np.ndarray) -> str:
    lam = np.linalg.eigvals(a)
    osc = sorted((v for v in lam if v.imag > 1e-9), key=abs)
    return ", ".join(f"{v.real:.3f}{v.imag:+.3f}j" for v in osc)


def gust_peaks(lm, ctrl: LinearController, p_g: np.ndarray) -> tuple[float, float, float]:
    """(open-loop peak p, closed-loop peak p [rad/s], closed-loop peak |δa| [rad]) of the
    rolling gust ``p_g`` through the discrete loop at DT_S (one step of delay)."""
    plant = lateral_signal_outputs(lm.ss)
    zero = LinearController.from_arrays(None, None, None, [[0.0]], None, ["p_rad_s"],
                                        ["aileron"], "open")
    open_run = respond(close_loop(plant, zero, DT_S, disturbance="p_g"), p_g)
    closed = respond(close_loop(plant, ctrl, DT_S, disturbance="p_g"), p_g)
    return (float(np.max(np.abs(open_run["p_rad_s"]))),
            float(np.max(np.abs(closed["p_rad_s"]))),
            float(np.max(np.abs(closed["ctrl_aileron_rad"]))))


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--aircraft", default="c172_elastic")
    p.add_argument("--speed", type=float, default=57.8, help="trim speed [m/s]")
    p.add_argument("--factor", type=float, default=2.0,
                   help="closed-loop roll root over the open loop's (> 1)")
    p.add_argument("--out", default=None, help="controller file (.toml or .npz)")
    p.add_argument("--force", action="store_true", help="replace an existing file")
    args = p.parse_args()
    ac = api.load_aircraft(args.aircraft)
    build, aileron = ac.wing(), ac.definition.aileron
    models = {m: full_span_lateral_model(build, airframe_for(ac), m, args.speed, aileron)
              for m in ("coupled", "rigid")}
    ss = models["coupled"].ss
    k = design_gain(ss, args.factor)
    name = f"roll_damper_{args.aircraft}"
    ctrl = LinearController.from_arrays(None, None, None, [[-k]], None, ["p_rad_s"],
                                        ["aileron"], name)
    open_root, closed_root = roll_root(np.asarray(ss.a)), roll_root(closed_a(ss, k))
    print(f"{args.aircraft}, {args.speed:g} m/s, coupled lateral model: K = {k:.6f} rad per "
          "rad/s (aileron = -K p)")
    print(f"roll root {open_root:.4f} -> {closed_root:.4f} 1/s (tau_R {-1 / open_root:.4f} -> "
          f"{-1 / closed_root:.4f} s)")
    print(f"oscillatory roots open:   {modes_line(np.asarray(ss.a))}")
    print(f"oscillatory roots closed: {modes_line(closed_a(ss, k))}")
    # the rolling gust's p_g = P/2 (1 − cos 2π x/L), x = V (t − start) over 0..L
    # (simulation/spanwise_gusts.py)
    x = args.speed * (np.arange(int(round(DURATION_S / DT_S))) * DT_S - GUST_START_S)
    inside = (x >= 0.0) & (x <= GUST_LENGTH_M)
    p_g = np.where(inside, 0.5 * GUST_P_RAD_S * (1.0 - np.cos(2.0 * np.pi * x / GUST_LENGTH_M)),
                   0.0)
    peaks = {m: gust_peaks(lm, ctrl, p_g) for m, lm in models.items()}
    for m, (po, pc, da) in peaks.items():
        print(f"{GUST} ({m}): peak p {po:.5f} -> {pc:.5f} rad/s (ratio {pc / po:.4f}), "
              f"peak aileron {np.degrees(da):.3f} deg")
    ratio = peaks["coupled"][1] / peaks["rigid"][1]
    print(f"elastic/rigid damped peak p {ratio:.5f}")
    notes = {
        "design": "static roll-rate feedback to the aileron, K placing the coupled lateral "
                  "model's roll-subsidence root at --factor times the open loop's "
                  "(scripts/design_roll_damper.py)",
        "aircraft": args.aircraft, "speed_m_s": args.speed, "factor": args.factor,
        "roll_root_open_1_s": round(open_root, 6), "roll_root_closed_1_s": round(closed_root, 6),
        "gust": GUST, "predicted_peak_ratio": round(peaks["coupled"][1] / peaks["coupled"][0], 6),
        "predicted_elastic_rigid_peak": round(ratio, 6),
        "units": "aileron [rad] (JSBSim's (left - right)/2, + rolls right) per p_rad_s [rad/s]",
    }
    ctrl = LinearController.from_arrays(None, None, None, [[-k]], None, ["p_rad_s"],
                                        ["aileron"], name, notes)
    out = Path(args.out) if args.out else SHIPPED_DIR / f"{name}.toml"
    ctrl.save(out, overwrite=args.force)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
