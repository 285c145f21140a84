"""Paper vs default vs geometry-consistent aircraft, side by side.

Run:  python scripts/consistent_aircraft.py [--json]

Prints the consistent set's geometry (tail, fuselage, CG), its rigid derivatives beside the
default set's (the paper prints none), Tables 3 and 6 with both sets, the six named wings'
short period and flutter speeds (quasi-steady and unsteady strips) with both sets, and the
elastic trim with both. Consistent mass basis, ρ = 1.225 kg/m³; every
relative difference is (model − paper)/|paper|. See docs/consistent_aircraft.md.
"""

from __future__ import annotations

import argparse
import json
import math

from bioflex_jsb.aeroelasticity.parameter_set import unsteady_flutter_with
from bioflex_jsb.flight_dynamics.consistent_aircraft import (
    AIRCRAFT_SETS,
    consistent_derivatives,
    flutter_with,
    modes_with,
    rigid_short_period,
)
from bioflex_jsb.flight_dynamics.elastic_trim import elastic_trim
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import airframe_consistent as C
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import AIRFRAME_GEOMETRY
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM

SPEEDS = (15.0, 20.0)
PUBLISHED = {"original": ("Table 3", P.TABLE3_SHORT_PERIOD),
             "inertial-forward": ("Table 6", P.TABLE6_SHORT_PERIOD)}
DERIVATIVES = (
    ("C_L_alpha", "cl_alpha_per_rad", "/rad"), ("C_m_alpha", "cm_alpha_per_rad", "/rad"),
    ("C_m_q", "cm_q_per_rad", "/rad"), ("C_m_alphadot", "cm_alphadot_per_rad", "/rad"),
    ("C_L_delta_e", "cl_delta_e_per_rad", "/rad"), ("C_m_delta_e", "cm_delta_e_per_rad", "/rad"),
    ("C_m0", "cm0", "-"),
)


def _c(z: complex) -> list[float]:
    return [round(z.real, 3), round(z.imag, 3)]


def geometry() -> dict:
    d = consistent_derivatives()
    lat = d.lattice
    t, f = C.TAIL, C.FUSELAGE
    return {
        "cg_fraction_of_chord": {"default": DEFAULT_PLANFORM.x_cg_m / P.MEAN_AERODYNAMIC_CHORD_M,
                                 "consistent": C.CG_FRACTION_OF_CHORD},
        "cg_x_structural_m": {"default": AIRFRAME_GEOMETRY.cg_x_m,
                              "consistent": C.AIRFRAME_GEOMETRY.cg_x_m},
        "tail": {"area_m2": t.area_m2, "span_m": 2 * t.semispan_m, "chord_m": t.chord_m,
                 "aspect_ratio": t.aspect_ratio, "leading_edge_x_m": t.leading_edge_x_m,
                 "height_m": t.height_m, "efficiency": t.efficiency,
                 "elevator_chord_fraction": t.elevator_chord_fraction,
                 "ac_x_m": lat.tail_ac_x_m, "arm_from_cg_m": lat.tail_ac_x_m - lat.x_cg_m,
                 "volume_coefficient": t.area_m2 * (lat.tail_ac_x_m - lat.x_cg_m)
                 / (P.REFERENCE_AREA_M2 * P.MEAN_AERODYNAMIC_CHORD_M),
                 "lift_slope_isolated_per_rad": lat.tail_lift_slope_isolated_per_rad},
        "fuselage": {"length_m": f.length_m, "max_diameter_m": f.max_diameter_m,
                     "volume_m3": f.volume_m3,
                     "cm_alpha_munk_per_rad": d.fuselage_cm_alpha_per_rad},
        "lattice": {"cl_alpha_wing": lat.cl_alpha_wing, "cl_alpha_tail": lat.cl_alpha_tail,
                    "downwash_gradient": lat.downwash_gradient, "wing_ac_x_m": lat.wing_ac_x_m,
                    "cm_alpha_lattice": lat.cm_alpha, "cm_q_wing": lat.cm_q_wing,
                    "cm_q_tail": lat.cm_q_tail, "cl_q_dropped": lat.cl_q,
                    "cl_alphadot_dropped": lat.cl_alphadot},
        "static_margin": {"default": -AIRCRAFT_SETS["default"].aero.cm_alpha_per_rad
                          / AIRCRAFT_SETS["default"].aero.cl_alpha_per_rad,
                          "consistent": d.static_margin},
        "computed_matches_stored": {
            name: abs(getattr(d.aero, attr) - getattr(C.RIGID_AERODYNAMICS, attr))
            <= 1e-3 * abs(getattr(C.RIGID_AERODYNAMICS, attr)) for name, attr, _ in DERIVATIVES},
    }


def derivatives() -> list[dict]:
    rows = []
    for name, attr, unit in DERIVATIVES:
        rows.append({"name": name, "unit": unit, "paper": None,
                     **{s: getattr(AIRCRAFT_SETS[s].aero, attr) for s in AIRCRAFT_SETS}})
    rows.append({"name": "C_m_q + C_m_alphadot", "unit": "/rad", "paper": None,
                 **{s: a.aero.cm_q_per_rad + a.aero.cm_alphadot_per_rad
                    for s, a in AIRCRAFT_SETS.items()}})
    return rows


def published_tables() -> list[dict]:
    rows = []
    for wing, (table, data) in PUBLISHED.items():
        builds = {s: build_wing(VARIANTS[wing], planform=AIRCRAFT_SETS[s].planform)
                  for s in AIRCRAFT_SETS}
        for model in ("rigid", "coupled", "qsd"):
            got = {s: modes_with(model, SPEEDS, None if model == "rigid" else builds[s].model,
                                 AIRCRAFT_SETS[s].aero) for s in AIRCRAFT_SETS}
            for k, v in enumerate(SPEEDS):
                paper = complex(*data[(v, model)])
                row = {"table": table, "wing": wing, "speed_m_s": v, "model": model,
                       "paper": _c(paper)}
                for s in AIRCRAFT_SETS:
                    sp = got[s][k].get("short_period")
                    row[s] = [round(sp.re, 3), round(sp.im, 3)]
                    row[f"{s}_error"] = [round((sp.re - paper.real) / abs(paper.real), 4),
                                         round((sp.im - paper.imag) / abs(paper.imag), 4)]
                rows.append(row)
    return rows


def six_wings() -> list[dict]:
    rows = []
    for wing in VARIANTS:
        row: dict = {"wing": wing}
        for s, aset in AIRCRAFT_SETS.items():
            b = build_wing(VARIANTS[wing], planform=aset.planform)
            sp = modes_with("coupled", SPEEDS, b.model, aset.aero)
            row[f"{s}_short_period"] = {f"{v:g}": [round(m.get("short_period").re, 2),
                                                   round(m.get("short_period").im, 2)]
                                        for v, m in zip(SPEEDS, sp, strict=True)}
            qs = flutter_with(b.model, aset.aero)
            row[f"{s}_flutter_quasi_steady_m_s"] = qs.flutter_speed_m_s
            row[f"{s}_flutter_quasi_steady_mode"] = qs.mode
            for zeta in (0.0, 0.02):
                res = unsteady_flutter_with(b, aset.aero, aset.planform,
                                            structural_damping=zeta)
                row[f"{s}_flutter_unsteady_zeta{zeta:g}_m_s"] = (
                    None if res.speed_m_s is None else round(res.speed_m_s, 2))
                row[f"{s}_flutter_unsteady_zeta{zeta:g}_rad_s"] = (
                    None if res.frequency_rad_s is None else round(res.frequency_rad_s, 2))
        rows.append(row)
    return rows


def trims() -> list[dict]:
    rows = []
    for wing in VARIANTS:
        for s, aset in AIRCRAFT_SETS.items():
            b = build_wing(VARIANTS[wing], planform=aset.planform)
            for v in (15.0, 18.0):
                t = elastic_trim(b, v, aero=aset.aero)
                rows.append({
                    "wing": wing, "set": s, "speed_m_s": v,
                    "eta_rad": [round(x, 5) for x in t.eta_rad],
                    "tip_twist_deg": round(t.tip_twist_deg, 3),
                    "tip_twist_at_rigid_trim_deg": round(math.degrees(
                        float(b.modes.twist_rad[:, -1] @ t.eta_at_rigid_trim_rad)), 3),
                    "alpha_rigid_deg": round(math.degrees(t.rigid.alpha_rad), 3),
                    "alpha_deg": round(math.degrees(t.alpha_rad), 3),
                    "elevator_rigid_deg": round(math.degrees(t.rigid.elevator_rad), 3),
                    "elevator_deg": round(math.degrees(t.elevator_rad), 3),
                    "divergence_speed_m_s": None if math.isinf(t.divergence_speed_m_s)
                    else round(t.divergence_speed_m_s, 3),
                })
    return rows


def collect() -> dict:
    return {
        "rigid_short_period": {s: {f"{v:g}": _c(rigid_short_period(a.aero, v)) for v in SPEEDS}
                               for s, a in AIRCRAFT_SETS.items()},
        "geometry": geometry(), "derivatives": derivatives(),
        "published_tables": published_tables(), "six_wings": six_wings(), "elastic_trim": trims(),
    }


def _pct(x: float) -> str:
    return f"{100 * x:+.1f}%"


def _print(data: dict) -> None:
    g = data["geometry"]
    t = g["tail"]
    print("Consistent aircraft: geometry (parameters/airframe_consistent.py)")
    print(f"  CG {g['cg_fraction_of_chord']['consistent']:.4f} c̄ aft of the root LE "
          f"(default {g['cg_fraction_of_chord']['default']:.2f}); static margin "
          f"{g['static_margin']['consistent']:.3f} c̄ (default {g['static_margin']['default']:.3f})")
    print(f"  tail {t['span_m']:.2f} m × {t['chord_m']:.2f} m = {t['area_m2']:.3f} m² "
          f"(AR {t['aspect_ratio']:.2f}), LE {t['leading_edge_x_m']:.2f} m, "
          f"AC {t['ac_x_m']:.3f} m, "
          f"arm {t['arm_from_cg_m']:.3f} m, V_H {t['volume_coefficient']:.3f}, η_t "
          f"{t['efficiency']}, a_t {t['lift_slope_isolated_per_rad']:.3f} /rad")
    f, lat = g["fuselage"], g["lattice"]
    print(f"  fuselage {f['length_m']} m × {f['max_diameter_m']} m spheroid: Munk ΔC_mα "
          f"{f['cm_alpha_munk_per_rad']:+.4f} /rad")
    print(f"  lattice: C_Lα wing {lat['cl_alpha_wing']:.3f} + tail {lat['cl_alpha_tail']:.3f}; "
          f"dε/dα {lat['downwash_gradient']:.3f}; C_mq wing {lat['cm_q_wing']:.3f} + tail "
          f"{lat['cm_q_tail']:.3f}; dropped C_Lq {lat['cl_q_dropped']:.2f}, C_Lα̇ "
          f"{lat['cl_alphadot_dropped']:.2f}")
    print(f"  stored = computed (0.1 %): {all(g['computed_matches_stored'].values())}")
    print()
    print(f"{'derivative':<22}{'paper':>8}{'default':>10}{'consistent':>12}")
    for r in data["derivatives"]:
        print(f"{r['name']:<22}{'—':>8}{r['default']:10.4f}{r['consistent']:12.4f}")
    print()
    print("Short period [1/s, rad/s]: paper | default (Δre, Δim) | consistent (Δre, Δim)")
    for r in data["published_tables"]:
        d, c = r["default"], r["consistent"]
        print(f"{r['table']:<8}{r['speed_m_s']:4.0f} {r['model']:<8} "
              f"{r['paper'][0]:6.1f} ±{r['paper'][1]:5.1f}i | {d[0]:7.2f} ±{d[1]:6.2f}i "
              f"({_pct(r['default_error'][0])}, {_pct(r['default_error'][1])}) | "
              f"{c[0]:7.2f} ±{c[1]:6.2f}i ({_pct(r['consistent_error'][0])}, "
              f"{_pct(r['consistent_error'][1])})")
    print()
    print("Six wings, coupled short period 15/20 m/s and flutter [m/s] (QS ζ = variant's 0.02; "
          "unsteady ζ = 0 / 0.02)")
    for r in data["six_wings"]:
        for s in AIRCRAFT_SETS:
            sp = r[f"{s}_short_period"]
            print(f"  {r['wing']:<18}{s:<11} SP {sp['15'][0]:7.2f} ±{sp['15'][1]:6.2f}i  "
                  f"{sp['20'][0]:7.2f} ±{sp['20'][1]:6.2f}i  "
                  f"QS {r[f'{s}_flutter_quasi_steady_m_s']}"
                  f"  unsteady {r[f'{s}_flutter_unsteady_zeta0_m_s']} / "
                  f"{r[f'{s}_flutter_unsteady_zeta0.02_m_s']}")
    print()
    print("Elastic trim: tip twist [deg] (at the rigid trim's loads → fixed point), α and δe "
          "[deg] rigid → elastic")
    for r in data["elastic_trim"]:
        print(f"  {r['wing']:<18}{r['set']:<11}{r['speed_m_s']:4.0f}  tip "
              f"{r['tip_twist_at_rigid_trim_deg']:7.2f} → {r['tip_twist_deg']:7.2f}  α "
              f"{r['alpha_rigid_deg']:5.2f} → {r['alpha_deg']:5.2f}  δe "
              f"{r['elevator_rigid_deg']:5.2f} → {r['elevator_deg']:5.2f}  V_D "
              f"{r['divergence_speed_m_s']}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    data = collect()
    if args.json:
        print(json.dumps(data, indent=1))
    else:
        _print(data)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
