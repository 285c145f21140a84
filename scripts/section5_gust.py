"""Section 5 against the model: each of the paper's Fig. 21 claims beside the nonlinear JSBSim
runs, Fig. 22's claim, and where the elastic wing's slow phugoid comes from.

Run:  python scripts/section5_gust.py [--duration 5] [--plot-dir .] [--no-plot] [--json]

* Fig. 21: the optimised wing at 15 m/s through a 3 m/s sharp-edged vertical gust, rigid vs
  coupled vs QSD. The paper (Section 5): the elastic wing gives "a lower velocity change, a
  lower overshoot, and a shorter stabilisation time than the rigid response", and "the
  response of the dynamic coupling model and the QSD model are almost identical".
* Fig. 22: original vs optimised wing, QSD model (as the paper uses), same gust: the forward
  axes "efficiently alleviate gust perturbation".
* The phugoid of the linear models at 15 m/s (rigid, coupled, QSD), with every Table B1
  coefficient and every Table B2 derivative of the modes changed one at a time, the paper's
  literal Table B2 (H_iu over the aircraft mass), and the propeller's thrust change with
  airspeed that JSBSim flies and Table B2 leaves out.

Every claim is printed as: paper's claim, rigid, coupled, QSD, verdict (agrees / disagrees,
with what is off). Figures are rounded; a metric that has no value says why (e.g. "does not
settle within 4.5 s"). The settling times are defined in
``bioflex_jsb.simulation.results.GustMetrics``: the paper's "stabilisation time" is compared
with the short-period settling time (the paper's transfer functions are those of the
short-period response and it leaves the phugoid out); the settling of the whole motion,
phugoid included, is printed beside it. ``--json`` prints the same as one JSON document
(numbers in SI, null where there is no value, and the printed text beside it).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics import lti
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import MASS_PROPERTIES, PROTOTYPE_AIRFRAME
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import GustSpec
from bioflex_jsb.simulation.results import gust_metrics

# "lower" / "almost identical": a difference of less than 5 % of the rigid (or coupled) value
# is not counted as lower, and is counted as identical. 5 %: twice the scatter between the
# paper's own coupled and QSD rows, which it calls "similar" (Tables 3 and 6: up to 2.5 %).
SIMILAR_REL = 0.05
STATES = (  # the four longitudinal states of Eq. (4) that Figs. 21-22 show: key, label, scale
    ("peak_du_m_s", "peak |Δu| [m/s]", 1.0),
    ("peak_dalpha_rad", "peak |Δα| [deg]", 180.0 / math.pi),
    ("peak_dq_rad_s", "peak |Δq| [deg/s]", 180.0 / math.pi),
    ("peak_dtheta_rad", "peak |Δθ| [deg]", 180.0 / math.pi),
)
MODELS = ("rigid", "coupled", "qsd")
PHUGOID_SPEED_M_S = P.SECTION5_AIRSPEED_M_S
PHUGOID_MAX_RAD_S = 3.0  # the phugoid is the slowest complex pair, well below the SP's 8+


def rounded(x: float | None, digits: int = 3) -> str:
    """``x`` to ``digits`` significant figures (never a raw None: callers say why)."""
    if x is None:
        raise ValueError("no value: say why instead")
    if x == 0.0 or not math.isfinite(x):
        return f"{x:g}"
    if abs(x) < 10 ** -(digits + 1):
        return f"{x:.{digits - 1}e}"
    return f"{x:#.{digits}g}".rstrip(".")  # trailing zeros kept: 1.50, not 1.5


def settling_text(t: float | None, after_gust_s: float) -> str:
    return f"{rounded(t)} s" if t is not None else \
        f"does not settle within {rounded(after_gust_s, 2)} s"


# --------------------------------------------------------------------------------------
# Fig. 21 and Fig. 22 claims
# --------------------------------------------------------------------------------------
def lower_verdict(rigid: float, elastic: dict[str, float], what: str) -> tuple[str, str]:
    """(verdict, what is off) of the claim that each elastic value is lower than ``rigid``."""
    worst = max(elastic.values())
    change = {m: (v - rigid) / rigid for m, v in elastic.items()}
    text = ", ".join(f"{m} {100 * c:+.0f} %" for m, c in change.items())
    if worst < (1.0 - SIMILAR_REL) * rigid:
        return "agrees", f"{what}: {text} of rigid"
    return "disagrees", f"{what} is not lower: {text} of rigid"


def fig21_claims(metrics: dict[str, dict], after_gust_s: float, alpha_gap_rad: float) -> list:
    """The paper's four Fig. 21 claims against the runs' metrics (``GustMetrics.as_json``)."""
    r, c, q = (metrics[m] for m in MODELS)
    rows = []

    def row(claim, metric, unit, scale, verdict, off, key, extra=None):
        values = {m: metrics[m][key] for m in MODELS}
        shown = {m: (f"{rounded(v * scale)} {unit}" if v is not None
                     else settling_text(None, after_gust_s)) for m, v in values.items()}
        out = {"claim": claim, "metric": metric, "unit": unit, "values_si": values,
               "shown": shown, "verdict": verdict, "off": off}
        out.update(extra or {})
        rows.append(out)

    v, off = lower_verdict(r["peak_du_m_s"], {"coupled": c["peak_du_m_s"],
                                              "qsd": q["peak_du_m_s"]}, "peak |Δu|")
    row("lower velocity change", "peak |Δu|", "m/s", 1.0, v, off, "peak_du_m_s")
    v, off = lower_verdict(r["overshoot"], {"coupled": c["overshoot"], "qsd": q["overshoot"]},
                           "overshoot of Δα")
    row("lower overshoot", "overshoot of Δα past 0 after its peak", "%", 100.0, v, off,
        "overshoot")
    # stabilisation time: the short-period settling (the paper's measure), the whole motion
    # beside it
    sp = {m: metrics[m]["short_period_settling_time_s"] for m in MODELS}
    full = {m: metrics[m]["settling_time_s"] for m in MODELS}
    full_shown = {m: settling_text(full[m], after_gust_s) for m in MODELS}
    if any(x is None for x in sp.values()):
        v = "disagrees"
        off = "the short period of " + ", ".join(m for m in MODELS if sp[m] is None) + \
            f" does not settle within {rounded(after_gust_s, 2)} s"
    else:
        later = {m: sp[m] - sp["rigid"] for m in ("coupled", "qsd")}
        if max(later.values()) < -SIMILAR_REL * sp["rigid"]:
            v, off = "agrees", "short period settles " + ", ".join(
                f"{m} {rounded(-d, 2)} s sooner" for m, d in later.items())
        else:
            v = "disagrees"
            off = ("the elastic wing's short period settles later: " + ", ".join(
                f"{m} {rounded(d, 2)} s ({100 * d / sp['rigid']:+.0f} %)"
                for m, d in later.items()) + " after rigid")
    off += ("; short-period Re λ (linear models): " + ", ".join(
        f"{m} {rounded(x)} 1/s" for m, x in short_period_re().items())
        + " (the paper's Table 6 too: rigid -5.6, coupled -5.0)")
    full_off = ("whole motion (phugoid included): rigid " + full_shown["rigid"] + ", coupled "
                + full_shown["coupled"] + ", QSD " + full_shown["qsd"])
    row("shorter stabilisation time", "short-period settling of Δα (5 % of its peak)", "s",
        1.0, v, off + "; " + full_off, "short_period_settling_time_s",
        {"whole_motion_settling_s": full, "whole_motion_shown": full_shown})
    # coupled ≈ QSD on the four states
    diffs = {key: abs(q[key] - c[key]) / abs(c[key]) for key, _, _ in STATES}
    worst_key = max(diffs, key=diffs.get)
    worst = diffs[worst_key]
    v = "agrees" if worst <= SIMILAR_REL else "disagrees"
    worst_label = dict((k, lab) for k, lab, _ in STATES)[worst_key].split(" [")[0]
    off = (f"largest difference of the four state peaks {100 * worst:.1f} % ({worst_label}); "
           f"|Δα coupled − Δα QSD| ≤ {rounded(alpha_gap_rad, 2)} rad from 1 s after the gust"
           f"; peak |Δn_z| differs by "
           f"{100 * abs(q['peak_dn_z'] - c['peak_dn_z']) / c['peak_dn_z']:.0f} % (the "
           "coupled wing's 42 Hz ripple at the gust's edge; not one of the figure's states)")
    rows.append({"claim": "coupled ≈ QSD (almost identical)",
                 "metric": "largest relative difference of the peaks of Δu, Δα, Δq, Δθ",
                 "unit": "%", "values_si": {"coupled_vs_qsd": worst,
                                            "alpha_gap_after_1_s_rad": alpha_gap_rad},
                 "shown": {"rigid": "(not compared)", "coupled": f"{100 * worst:.1f} % from QSD",
                           "qsd": f"{100 * worst:.1f} % from coupled"},
                 "verdict": v, "off": off})
    return rows


def short_period_re(speed_m_s: float = P.SECTION5_AIRSPEED_M_S) -> dict[str, float]:
    """Re λ of the short period [1/s] of the optimised wing's linear models: the decay rate
    of its envelope, which sets the settling time."""
    cond = level_flight_condition(speed_m_s, airframe=PROTOTYPE_AIRFRAME)
    wing = build_wing(VARIANTS["optimised"]).model
    out = {}
    for m in MODELS:
        lam = np.linalg.eigvals(lti.build_state_space(m, cond, None if m == "rigid"
                                                      else wing).a)
        sp = lam[(lam.imag > 1e-6) & (np.abs(lam) > PHUGOID_MAX_RAD_S) & (np.abs(lam) < 50.0)]
        out[m] = float(sp[np.argmin(np.abs(sp))].real)
    return out


def fig22_claim(original: dict, optimised: dict) -> dict:
    """The forward axes alleviate the gust: the peaks of Δu, Δq, Δθ and the overshoot lower
    on the optimised wing. Not the peak of Δα: a sharp-edged gust sets Δα = w_g/u_0 at its
    edge, before any wing can respond, so that peak is the same for every wing."""
    keys = ("peak_du_m_s", "peak_dq_rad_s", "peak_dtheta_rad", "overshoot")
    change = {key: (optimised[key] - original[key]) / original[key]
              for key in keys + ("peak_dalpha_rad",)}
    lower = all(change[k] < -SIMILAR_REL for k in keys)
    labels = {"peak_du_m_s": "peak |Δu|", "peak_dq_rad_s": "peak |Δq|",
              "peak_dtheta_rad": "peak |Δθ|", "overshoot": "overshoot of Δα",
              "peak_dalpha_rad": "peak |Δα| (the gust's edge, any wing)"}
    text = ", ".join(f"{labels[k]} {100 * c:+.0f} %" for k, c in change.items())
    return {"claim": "forward axes alleviate the gust (optimised vs original, QSD)",
            "change_si": change, "verdict": "agrees" if lower else "disagrees",
            "off": text + " (optimised vs original)"}


def alpha_gap_after(runs: dict, start_s: float) -> float:
    """max |Δα coupled − Δα QSD| [rad] from ``start_s`` on (same step, same samples)."""
    c, q = runs["coupled"], runs["qsd"]
    n = min(len(c.time_s), len(q.time_s))
    sel = c.time_s[:n] >= start_s
    return float(np.max(np.abs(c["alpha"][:n][sel] - q["alpha"][:n][sel])))


# --------------------------------------------------------------------------------------
# The phugoid of the linear models
# --------------------------------------------------------------------------------------
def phugoid(a: np.ndarray) -> dict[str, float]:
    """The slowest complex pair of ``a``: damping ζ [-], ω_n [rad/s], Re λ [1/s]."""
    lam = np.linalg.eigvals(a)
    lam = lam[(lam.imag > 1e-6) & (np.abs(lam) < PHUGOID_MAX_RAD_S)]
    if len(lam) == 0:
        raise ValueError("no complex pair below 3 rad/s: no phugoid to report")
    root = lam[np.argmin(np.abs(lam))]
    return {"damping": float(-root.real / abs(root)), "omega_n_rad_s": float(abs(root)),
            "re_1_s": float(root.real)}


def phugoid_study(speed_m_s: float = PHUGOID_SPEED_M_S) -> dict:
    """Phugoid of rigid/coupled/QSD and its sensitivity (module docstring)."""
    cond = level_flight_condition(speed_m_s, airframe=PROTOTYPE_AIRFRAME)
    wing = build_wing(VARIANTS["optimised"]).model
    coeffs = wing.coefficients
    out: dict = {"speed_m_s": speed_m_s, "wing": "optimised"}
    out["models"] = {m: phugoid(lti.build_state_space(m, cond, None if m == "rigid"
                                                        else wing).a) for m in MODELS}

    def coupled(w=wing, elastic=None):
        return phugoid(lti.build_state_space("coupled", cond, w, elastic=elastic).a)

    b1 = []
    for name in ("c_l_eta", "c_l_etadot", "c_m_eta", "c_m_etadot", "c_mac_q", "c_alpha_q",
                 "c_q_q", "c_eta_q", "c_etadot_q"):
        base = np.asarray(getattr(coeffs, name), dtype=float)
        for factor in (0.0, 0.9, 1.1):
            w = replace(wing, coefficients=replace(coeffs, **{name: factor * base}))
            b1.append({"coefficient": name, "factor": factor, **coupled(w)})
    out["table_b1_one_at_a_time"] = b1
    ed = lti.elastic_derivatives(wing, cond)
    b2 = []
    for name in ("x_eta", "x_etadot", "z_eta", "z_etadot", "m_eta", "m_etadot", "h_u",
                 "h_alpha", "h_q"):
        zero = replace(ed, **{name: np.zeros_like(getattr(ed, name))})
        b2.append({"derivative": name, "factor": 0.0, **coupled(elastic=zero)})
    out["table_b2_zeroed_one_at_a_time"] = b2
    mi = np.asarray(wing.generalised_masses_kg_m2, dtype=float)
    literal = replace(ed, h_u=ed.h_u * mi / MASS_PROPERTIES.mass_kg)
    out["table_b2_literal_h_iu_over_aircraft_mass"] = coupled(elastic=literal)
    out["paper_mass_basis"] = coupled(build_wing(VARIANTS["optimised"],
                                                 mass_basis="paper").model)
    dtdv = lti.thrust_speed_derivative_n_s_m(cond)
    with_thrust = {}
    for m in MODELS:
        a = lti.build_state_space(m, cond, None if m == "rigid" else wing).a.copy()
        a[0, 0] += dtdv / MASS_PROPERTIES.mass_kg  # X_u of the propeller, ∂T/∂V / m [1/s]
        with_thrust[m] = phugoid(a)
    out["with_propeller_dT_dV"] = {"dT_dV_n_s_m": dtdv, **with_thrust}
    rigid = lti.build_state_space("rigid", cond).a
    qsd = lti.build_state_space("qsd", cond, wing).a
    out["qsd_minus_rigid_speed_column"] = {  # the u column of A: X_u, Z_u/u0, M_u rows
        "x_u_1_s": float(qsd[0, 0] - rigid[0, 0]),
        "z_u_over_u0_1_m": float(qsd[1, 0] - rigid[1, 0]),
        "m_u_1_m_s": float(qsd[2, 0] - rigid[2, 0]),
    }
    out["rigid_m_u_1_m_s"] = float(rigid[2, 0])
    return out


def print_phugoid(study: dict) -> None:
    def z(d):
        return f"ζ {d['damping']:+.4f}  ω_n {d['omega_n_rad_s']:.3f} rad/s"

    print(f"Phugoid of the linear models, optimised wing, {study['speed_m_s']:g} m/s")
    for m in MODELS:
        print(f"  {m:<8} {z(study['models'][m])}")
    s = study["qsd_minus_rigid_speed_column"]
    print(f"  the wing's speed derivatives (QSD − rigid): M_u {s['m_u_1_m_s']:+.3f} 1/(m·s) "
          f"(rigid {study['rigid_m_u_1_m_s']:+.3f}), Z_u/u0 {s['z_u_over_u0_1_m']:+.4f} 1/m, "
          f"X_u {s['x_u_1_s']:+.4f} 1/s")
    print("  coupled, one Table B1 coefficient (all modes) scaled:")
    for r in study["table_b1_one_at_a_time"]:
        print(f"    {r['coefficient']:<11} x{r['factor']:<4g} {z(r)}")
    print("  coupled, one Table B2 derivative of the modes set to 0:")
    for r in study["table_b2_zeroed_one_at_a_time"]:
        print(f"    {r['derivative']:<11}       {z(r)}")
    print(f"  Table B2 as printed (H_iu over the aircraft mass m): "
          f"{z(study['table_b2_literal_h_iu_over_aircraft_mass'])}")
    print(f"  the paper's mass basis (half-wing m_i):              "
          f"{z(study['paper_mass_basis'])}")
    t = study["with_propeller_dT_dV"]
    print(f"  with the propeller's dT/dV = {t['dT_dV_n_s_m']:+.3f} N/(m/s) in X_u (JSBSim "
          "has it, Table B2 not):")
    for m in MODELS:
        print(f"    {m:<8} {z(t[m])}")
    print()


# --------------------------------------------------------------------------------------
def print_claims(title: str, rows: list) -> None:
    print(title)
    print(f"  {'paper claim':<32} {'rigid':>16} {'coupled':>18} {'QSD':>18}  verdict")
    for r in rows:
        s = r["shown"]
        print(f"  {r['claim']:<32} {s['rigid']:>16} {s['coupled']:>18} {s['qsd']:>18}  "
              f"{r['verdict']}")
        print(f"  {'':<32} {r['metric']}; {r['off']}")
    print()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--duration", type=float, default=5.0,
                        help="run length [s], at least 2.5 (default 5, the paper's figure)")
    parser.add_argument("--plot-dir", default=".", help="where fig21.png and fig22.png go")
    parser.add_argument("--no-plot", action="store_true", help="do not draw the figures")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    args = parser.parse_args(argv)
    gust_start_s = 0.5
    if not (math.isfinite(args.duration) and args.duration >= gust_start_s + 2.0):
        print(f"section5_gust.py: --duration {args.duration:g} is too short; accepted: at "
              f"least {gust_start_s + 2.0:g} s (2 s after the gust at {gust_start_s:g} s, for "
              "the short-period settling)", file=sys.stderr)
        return 2
    gust = GustSpec("sharp", P.SECTION5_GUST_AMPLITUDE_M_S)
    setup = RunConfig(P.SECTION5_AIRSPEED_M_S, gust, args.duration, gust_start_s=gust_start_s)
    airframe = Airframe()
    optimised = build_wing(VARIANTS["optimised"]).model
    original = build_wing(VARIANTS["original"]).model
    runs = {m: run_gust(airframe, optimised, m, setup) for m in MODELS}
    run_orig = run_gust(airframe, original, "qsd", setup)
    for name, run in {**runs, "original-qsd": run_orig}.items():
        if run.stopped:  # a diverged run has no response to compare: say so and stop
            print(f"section5_gust.py: the {name} run stopped: {run.stopped}", file=sys.stderr)
            return 3
    metrics = {m: gust_metrics(r, gust_start_s).as_json() for m, r in runs.items()}
    after_gust_s = float(runs["rigid"].time_s[-1]) - gust_start_s
    gap = alpha_gap_after(runs, gust_start_s + 1.0)
    claims = fig21_claims(metrics, after_gust_s, gap)
    orig = gust_metrics(run_orig, gust_start_s).as_json()
    f22 = fig22_claim(orig, metrics["qsd"])
    study = phugoid_study()
    if args.json:
        print(json.dumps({"case": {"speed_m_s": setup.speed_m_s, "gust": gust.text(),
                                   "gust_start_s": gust_start_s, "duration_s": args.duration},
                          "fig21": {"metrics": metrics, "claims": claims},
                          "fig22": {"metrics": {"original": orig, "optimised": metrics["qsd"]},
                                    "claim": f22},
                          "phugoid": study}, indent=1))
    else:
        print(f"Fig. 21: optimised wing, {setup.speed_m_s:g} m/s, {gust.text()} gust at "
              f"{gust_start_s:g} s, {args.duration:g} s (nonlinear JSBSim runs)")
        print_claims("The paper's claims against the model:", claims)
        print("Fig. 22: original vs optimised wing, QSD model, same gust")
        print(f"  {f22['claim']}: {f22['verdict']}; {f22['off']}")
        print()
        print_phugoid(study)
    if not args.no_plot:
        from bioflex_jsb.sinks import plotting

        out = Path(args.plot_dir)
        plotting.time_histories(list(runs.values()), out / "fig21.png",
                                "Fig. 21 case: optimised wing, 15 m/s, sharp 3 m/s")
        run_orig.meta.update(label="original (QSD)", linestyle="--")
        runs["qsd"].meta.update(label="optimised (QSD)")
        plotting.time_histories([run_orig, runs["qsd"]], out / "fig22.png",
                                "Fig. 22 case: original vs optimised, QSD")
        if not args.json:
            print(f"plots: {out / 'fig21.png'}, {out / 'fig22.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
