"""The Goland wing benchmark: model vs published, side by side (a sibling of paper_tables.py).

Run:  python scripts/goland_benchmark.py [--json]

Two readings of the published data (docs/aeroelasticity.md, bioflex_jsb/parameters/goland.py):

* ``default``: 8.64 kg·m about the elastic axis, ρ = 1.225 kg/m³ (the reading the published
  natural frequencies and flutter point both support; the library's default);
* ``issue``: 8.64 kg·m about the centre of mass, ρ = 1.02 kg/m³ (the specification's wording).

For each: the first three natural frequencies, and the flutter point by p-k (exact C(k)) and
by state-space (Jones lag states), unsteady and quasi-steady, with the 2-D (2π) and the
vortex-lattice lift slope, at ζ = 0. Published values exist for the natural frequencies and
for strip theory (2π) with Theodorsen's aerodynamics only; the other rows have none ("-").
"""

from __future__ import annotations

import argparse
import json
import re
import sys

from bioflex_jsb.aeroelasticity import goland_flutter
from bioflex_jsb.aeroelasticity.clamped_wing import clamped_wing_model, goland_sections
from bioflex_jsb.parameters import goland as G

READINGS = {
    "default": {"inertia_about": "elastic-axis", "density_kg_m3": G.FLUTTER_DENSITY_KG_M3},
    "issue": {"inertia_about": "centre-of-mass", "density_kg_m3": G.AIR_DENSITY_KG_M3},
}
CASES = [(lift, aero, method) for lift in ("strip", "vlm")
         for aero in ("unsteady", "quasi-steady") for method in ("pk", "state-space")]
MODE_NAMES = ("first bending", "first torsion", "second bending")


def _rel(x, ref):
    return None if x is None or ref is None else x / ref - 1.0


def compute() -> dict:
    out: dict = {"source": G.PUBLISHED_SOURCE, "readings": {}}
    for name, reading in READINGS.items():
        model = clamped_wing_model(goland_sections(inertia_about=reading["inertia_about"]))
        freqs = [
            {"mode": label, "published_rad_s": ref, "model_rad_s": float(w),
             "rel_diff": _rel(float(w), ref)}
            for label, ref, w in zip(MODE_NAMES, G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S,
                                     model.natural_frequencies_rad_s[:3], strict=True)
        ]
        rows = []
        for lift, aero, method in CASES:
            r = goland_flutter(aero=aero, lift_slope=lift, method=method, **reading)
            published = lift == "strip" and aero == "unsteady"
            pv = G.PUBLISHED_FLUTTER_SPEED_M_S if published else None
            pw = G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S if published else None
            rows.append({
                "lift_slope": lift, "aero": aero, "method": method,
                "speed_m_s": r.speed_m_s, "frequency_rad_s": r.frequency_rad_s,
                "reduced_frequency": r.reduced_frequency, "mechanism": r.mechanism,
                "mode": r.mode, "partner_mode": r.partner_mode,
                "divergence_speed_m_s": r.divergence_speed_m_s,
                "published_speed_m_s": pv, "published_frequency_rad_s": pw,
                "speed_rel_diff": _rel(r.speed_m_s, pv),
                "frequency_rel_diff": _rel(r.frequency_rad_s, pw),
            })
        out["readings"][name] = {**reading, "natural_frequencies": freqs, "flutter": rows}
    return out


def _fmt(x, spec: str) -> str:
    width = int(re.match(r"\d+", spec).group())
    return "-".rjust(width) if x is None else format(x, spec)


def _pct(x) -> str:
    return "-" if x is None else f"{100 * x:+.1f}%"


def print_tables(data: dict) -> None:
    print(f"Published: {data['source']}")
    for name, r in data["readings"].items():
        print(f"\nReading {name!r}: 8.64 kg·m about the {r['inertia_about']}, "
              f"rho = {r['density_kg_m3']} kg/m^3")
        print(f"  {'mode':16}{'published':>11}{'model':>9}{'diff':>8}   [rad/s]")
        for f in r["natural_frequencies"]:
            print(f"  {f['mode']:16}{f['published_rad_s']:11.1f}{f['model_rad_s']:9.2f}"
                  f"{_pct(f['rel_diff']):>8}")
        print(f"  {'lift':6}{'aero':13}{'method':12}{'V_F [m/s]':>10}{'pub':>7}{'diff':>8}"
              f"{'w_F [rad/s]':>12}{'pub':>6}{'diff':>8}{'k':>7}  mechanism")
        for row in r["flutter"]:
            mech = row["mechanism"] or "none in range"
            if row["partner_mode"]:
                mech += f" ({row['mode']} + {row['partner_mode']})"
            elif row["mode"]:
                mech += f" ({row['mode']})"
            print(f"  {row['lift_slope']:6}{row['aero']:13}{row['method']:12}"
                  f"{_fmt(row['speed_m_s'], '10.2f')}{_fmt(row['published_speed_m_s'], '7.1f')}"
                  f"{_pct(row['speed_rel_diff']):>8}{_fmt(row['frequency_rad_s'], '12.2f')}"
                  f"{_fmt(row['published_frequency_rad_s'], '6.1f')}"
                  f"{_pct(row['frequency_rel_diff']):>8}{_fmt(row['reduced_frequency'], '7.3f')}"
                  f"  {mech}")
        div = r["flutter"][0]["divergence_speed_m_s"]
        print(f"  static divergence (strip, steady): {div:.1f} m/s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args()
    data = compute()
    if args.json:
        json.dump(data, sys.stdout, indent=2, allow_nan=False, default=float)
        sys.stdout.write("\n")
    else:
        print_tables(data)


if __name__ == "__main__":
    main()
