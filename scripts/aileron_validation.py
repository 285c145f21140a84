"""Aileron reversal of the Goland wing against the uniform wing's closed form.

Prints, for ailerons on the Goland wing (bioflex_jsb/data/aircraft/goland.toml), the
reversal speed of the model (steady strips on the beam's six modes,
:func:`bioflex_jsb.api.aileron_effectiveness`) and of the closed form
(:func:`bioflex_jsb.aeroelasticity.aileron.uniform_wing_effectiveness`), q_R/q_D beside the
typical section's, and the rigid C_l_delta, C_lp; ``--plot FILE`` draws the effectiveness of
both against airspeed (docs/img/aileron_goland.png). ``--json`` for the numbers.

    python scripts/aileron_validation.py [--plot docs/img/aileron_goland.png] [--json]
"""

from __future__ import annotations

import argparse
import json
import math

import numpy as np
from scipy.optimize import brentq

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.aileron import uniform_wing_effectiveness
from bioflex_jsb.aeroelasticity.control_surface import (
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
)
from bioflex_jsb.parameters import goland as G

RHO = 1.225  # goland.toml's air [kg/m^3]
# (label, span start, end [fractions of the semispan], hinge [chord fraction])
CASES = (("full span, 25 % chord", 0.0, 1.0, 0.75),
         ("outer 40 %, 20 % chord (goland_aileron)", 0.6, 1.0, 0.8),
         ("0.2-0.7, 30 % chord", 0.2, 0.7, 0.7))


def closed_form(start: float, end: float, hinge: float) -> dict:
    kw = dict(torsional_stiffness_n_m2=G.TORSIONAL_STIFFNESS_N_M2, semispan_m=G.SEMISPAN_M,
              chord_m=G.CHORD_M, arm_m=(G.X_ELASTIC_FRAC - 0.25) * G.CHORD_M,
              lift_slope_per_rad=2.0 * math.pi, flap_lift_per_rad=flap_lift_slope_per_rad(hinge),
              flap_moment_per_rad=flap_moment_slope_per_rad(hinge),
              start_m=start * G.SEMISPAN_M, end_m=end * G.SEMISPAN_M)
    q_d = G.TORSIONAL_STIFFNESS_N_M2 * (math.pi / (2 * G.SEMISPAN_M)) ** 2 / (
        G.CHORD_M * 2.0 * math.pi * kw["arm_m"])
    q_r = brentq(lambda q: uniform_wing_effectiveness(q, **kw), 1.0, 0.999 * q_d, xtol=1e-9)
    return {"kw": kw, "q_r": q_r, "q_d": q_d, "v_r": math.sqrt(2 * q_r / RHO),
            "v_d": math.sqrt(2 * q_d / RHO)}


def table() -> list[dict]:
    rows = []
    for label, start, end, hinge in CASES:
        res = api.aileron_effectiveness("goland", aileron=(start, end, hinge))
        ref = closed_form(start, end, hinge)
        rows.append({
            "case": label, "model_reversal_m_s": res.reversal_speed_m_s,
            "closed_form_reversal_m_s": ref["v_r"],
            "rel_diff": res.reversal_speed_m_s / ref["v_r"] - 1.0,
            "model_divergence_m_s": res.divergence_speed_m_s,
            "closed_form_divergence_m_s": ref["v_d"],
            "q_r_over_q_d": res.reversal_over_divergence,
            "closed_form_q_r_over_q_d": ref["q_r"] / ref["q_d"],
            "typical_section_ratio": res.typical_section_ratio,
            "cl_delta_per_rad": res.cl_delta_per_rad, "cl_p_per_rad": res.cl_p_per_rad,
            "roll_rate_pb_2v_per_rad": res.rigid_roll_rate_per_rad,
        })
    return rows


def plot(path: str) -> None:
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from bioflex_jsb import __version__

    fig = Figure(figsize=(8.0, 5.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    for i, (label, start, end, hinge) in enumerate(CASES):
        res = api.aileron_effectiveness("goland", (0.0, 250.0), aileron=(start, end, hinge))
        ref = closed_form(start, end, hinge)
        colour = f"C{i}"
        ax.plot(res.speeds_m_s, res.effectiveness, color=colour, lw=1.8,
                label=f"{label}: model, reversal {res.reversal_speed_m_s:.2f} m/s")
        v = np.linspace(5.0, 245.0, 25)
        ax.plot(v, uniform_wing_effectiveness(0.5 * RHO * v**2, **ref["kw"]), "o", ms=4,
                color=colour, mfc="none", label=f"closed form, reversal {ref['v_r']:.2f} m/s")
        ax.plot([res.reversal_speed_m_s], [0.0], "x", color=colour, ms=9, mew=2)
    ax.axhline(0.0, color="k", lw=0.9)
    ax.axvline(ref["v_d"], color="0.4", ls=":", lw=1.4,
               label=f"divergence {ref['v_d']:.1f} m/s (closed form)")
    ax.set_ylim(-1.5, 1.2)
    ax.set_xlim(0.0, 260.0)
    ax.grid(True, alpha=0.3)
    ax.set_xlabel("airspeed V [m/s]")
    ax.set_ylabel("rolling-moment effectiveness R/R_rigid [-]")
    ax.legend(fontsize=8, loc="lower left")
    fig.suptitle("Goland wing (ρ 1.225 kg/m³): aileron effectiveness, steady strips on six "
                 "beam modes (lines)\nagainst the uniform torsion rod's closed form (circles)",
                 fontsize=10)
    fig.savefig(path, dpi=90, metadata={"Software": f"bioflex-jsb {__version__}"})


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--plot", metavar="FILE.png")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    rows = table()
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        for r in rows:
            print(f"{r['case']}: reversal {r['model_reversal_m_s']:.2f} m/s, closed form "
                  f"{r['closed_form_reversal_m_s']:.2f} ({r['rel_diff']:+.1e}); q_R/q_D "
                  f"{r['q_r_over_q_d']:.4f} (closed form {r['closed_form_q_r_over_q_d']:.4f}, "
                  f"typical section {r['typical_section_ratio']:.4f}); C_l_delta "
                  f"{r['cl_delta_per_rad']:.4f}, C_lp {r['cl_p_per_rad']:.4f} /rad, p b/2V "
                  f"{r['roll_rate_pb_2v_per_rad']:.4f} /rad")
    if args.plot:
        plot(args.plot)


if __name__ == "__main__":
    main()
