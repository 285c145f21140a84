"""Section 5 with numbers: the paper's Fig. 21 and Fig. 22 cases as nonlinear JSBSim runs.

Run:  python scripts/section5_gust.py [--duration 5] [--plot-dir .]

* Fig. 21: the optimised wing at 15 m/s through a 3 m/s sharp-edged vertical gust, rigid vs
  coupled vs QSD. The paper: the elastic wing gives "a lower velocity change, a lower
  overshoot, and a shorter stabilisation time than the rigid response", and coupled ≈ QSD.
* Fig. 22: original vs optimised wing, QSD model (as the paper uses), same gust. The paper:
  the forward axes "efficiently alleviate gust perturbation".

For every metric the script prints both values, which is better and by how much, and
whether that agrees with the paper's claim. Where the nonlinear run disagrees, it says so.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from bioflex_jsb.drivers.gust import RunSetup, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import GustSpec
from bioflex_jsb.simulation.results import gust_metrics
from bioflex_jsb.sinks import plotting

METRICS = (  # name, unit scale, label, paper's expectation for the elastic/forward wing
    ("peak_du_m_s", 1.0, "peak Δu [m/s]", "lower"),
    ("peak_dalpha_rad", 180 / math.pi, "peak Δα [deg]", None),
    ("peak_dq_rad_s", 180 / math.pi, "peak Δq [deg/s]", "lower"),
    ("peak_dtheta_rad", 180 / math.pi, "peak Δθ [deg]", "lower"),
    ("peak_dn_z", 1.0, "peak Δn_z [-]", "lower"),
    ("overshoot", 100.0, "overshoot of α [%]", "lower"),
    ("settling_time_s", 1.0, "settling time of α [s]", "lower"),
)


SIMILAR_REL = 0.05  # "almost identical": within 5 % (the scatter of the paper's curves)


def compare(label_a, a, label_b, b, claim: str = "lower") -> None:
    """Print a against b; ``claim``: the paper says b is "lower" or "similar"."""
    print(f"{'metric':<24} {label_a:>12} {label_b:>12}  better   by     paper's claim")
    for key, scale, label, expect in METRICS:
        va, vb = a[key], b[key]
        if va is None or vb is None:
            print(f"{label:<24} {str(va):>12} {str(vb):>12}  (not settled within the run)")
            continue
        va_s, vb_s = va * scale, vb * scale
        better = label_b if vb_s < va_s else label_a if va_s < vb_s else "equal"
        by = (vb_s - va_s) / va_s * 100 if va_s else float("nan")
        verdict = ""
        if claim == "similar":
            verdict = "agrees" if abs(vb_s - va_s) <= SIMILAR_REL * abs(va_s) else "DIFFERS"
        elif expect == "lower":
            verdict = "agrees" if vb_s < va_s else "DISAGREES"
        print(f"{label:<24} {va_s:12.3f} {vb_s:12.3f}  {better:<8} {by:+6.1f}%  {verdict}")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--duration", type=float, default=5.0, help="run length [s]")
    parser.add_argument("--plot-dir", default=".", help="where fig21.png and fig22.png go")
    args = parser.parse_args()
    gust = GustSpec("sharp", P.SECTION5_GUST_AMPLITUDE_M_S)
    setup = RunSetup(P.SECTION5_AIRSPEED_M_S, gust, args.duration, gust_start_s=0.5)
    airframe = Airframe()
    optimised = build_wing(VARIANTS["optimised"]).model
    original = build_wing(VARIANTS["original"]).model

    runs21 = {m: run_gust(airframe, optimised, m, setup) for m in ("rigid", "coupled", "qsd")}
    metrics21 = {m: gust_metrics(r, setup.gust_start_s).as_dict() for m, r in runs21.items()}
    print("Fig. 21: optimised wing, 15 m/s, 3 m/s sharp-edged gust (nonlinear JSBSim runs)")
    compare("rigid", metrics21["rigid"], "coupled", metrics21["coupled"])
    print("coupled vs QSD (paper: almost identical):")
    compare("coupled", metrics21["coupled"], "qsd", metrics21["qsd"], claim="similar")

    run_orig = run_gust(airframe, original, "qsd", setup)
    metrics22 = {"original": gust_metrics(run_orig, setup.gust_start_s).as_dict(),
                 "optimised": metrics21["qsd"]}
    print("Fig. 22: original vs optimised wing, QSD model, same gust")
    compare("original", metrics22["original"], "optimised", metrics22["optimised"])

    out = Path(args.plot_dir)
    plotting.time_histories(list(runs21.values()), out / "fig21.png",
                            "Fig. 21 case: optimised wing, 15 m/s, sharp 3 m/s")
    run_orig.meta.update(label="original (QSD)", linestyle="--")
    runs21["qsd"].meta.update(label="optimised (QSD)")
    plotting.time_histories([run_orig, runs21["qsd"]], out / "fig22.png",
                            "Fig. 22 case: original vs optimised, QSD")
    for name, run in {**runs21, "original-qsd": run_orig}.items():
        if run.stopped:
            print(f"note: the {name} run stopped: {run.stopped}")
    print(f"plots: {out / 'fig21.png'}, {out / 'fig22.png'}")


if __name__ == "__main__":
    main()
