"""Paper vs model, side by side: Tables 2, 3, 6 and 8, Section 4 trends, flutter.

Run:  python scripts/paper_tables.py [--mass-basis paper|consistent]

Every published number is printed beside the model's with the relative difference, and
marked by what it is (docs/validation.md, "Validation and calibration"): "fitted" (the model
was calibrated to it: a calibration check, not a validation), or a prediction that "agrees"
(within AGREEMENT_TOL) or "DISAGREES". Nothing is tuned per row.
"""

from __future__ import annotations

import argparse
import math

from bioflex_jsb import validation
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.wing_structure import RIBBED_WING, UNRIBBED_WING
from bioflex_jsb.structures.wing_model import wing_modes

# A prediction agrees within 5 %: twice the 2.5 % scatter between the paper's own coupled and
# QSD rows, which it calls "similar" (tests/test_paper_validation.py uses the same figure).
AGREEMENT_TOL = 0.05


def table2() -> None:
    print("Table 2: structural modes (beam model vs paper; masses normalised on twist)")
    print(f"{'':10}{'mode':>5} {'f paper [Hz]':>13} {'f model':>9} {'f is':>10} "
          f"{'m_i paper':>11} {'m_i model':>11} {'m_i is':>18}")
    for label, structure, f_p, m_p in (
        ("ribs", RIBBED_WING, P.MODE_FREQUENCIES_RIBS_HZ, P.GENERALISED_MASSES_RIBS_KG_M2),
        ("no ribs", UNRIBBED_WING, P.MODE_FREQUENCIES_NO_RIBS_HZ,
         P.GENERALISED_MASSES_NO_RIBS_KG_M2),
    ):
        modes = wing_modes(structure, 3)
        for i in range(3):
            f_m = modes.frequencies_rad_s[i] / (2 * math.pi)
            fitted = label == "ribs" or i < 2  # calibrate_default_wings: ribbed 3, unribbed 2
            f_kind = "fitted" if fitted else verdict(f_m / f_p[i] - 1.0)
            m_m = modes.generalised_masses_kg_m2[i]
            print(f"{label:10}{i + 1:5d} {f_p[i]:13.1f} {f_m:9.2f} {f_kind:>10} "
                  f"{m_p[i]:11.3g} {m_m:11.3g} {verdict(m_m / m_p[i] - 1.0):>9} "
                  f"({m_m / m_p[i]:.2f}x)")
    print()


def verdict(relative_error: float) -> str:
    return "agrees" if abs(relative_error) <= AGREEMENT_TOL else "DISAGREES"


def eigen_tables(mass_basis: str) -> None:
    for wing in validation.PUBLISHED_TABLES:
        rows = validation.short_period_rows(wing, mass_basis)
        print(f"{rows[0].table}: short period, wing {wing} (mass basis {mass_basis})")
        print(f"{'V':>4} {'model':<8} {'paper':>16} {'model':>18} {'Δre':>7} {'Δim':>7}")
        for r in rows:
            kind = ("fitted" if r.model == "rigid"  # C_mα, C_mq, C_mα̇: parameters/airframe.py
                    else verdict(max(abs(r.re_error), abs(r.im_error))))
            print(f"{r.speed_m_s:4.0f} {r.model:<8} {r.paper_re:7.1f} ±{r.paper_im:5.1f}i "
                  f"{r.model_re:8.2f} ±{r.model_im:6.2f}i {100 * r.re_error:6.1f}% "
                  f"{100 * r.im_error:6.1f}% {kind}")
        print()


def table8(mass_basis: str) -> None:
    print("C_η1^Q1 by variant: published, physical (strip model at the stated axes), used")
    print(f"{'wing':<18} {'x_I':>5} {'x_E':>5} {'published':>10} {'physical':>9} {'used':>7} "
          f"{'e shift [c]':>11}")
    for v in VARIANTS.values():
        b = build_wing(v, mass_basis=mass_basis)
        used = b.model.coefficients.c_eta_q[0, 0]
        print(f"{v.name:<18} {v.x_inertial_frac:5.2f} {v.x_elastic_frac:5.2f} "
              f"{v.published_c_eta1_q1:10.3f} {b.physical_c_eta1_q1:9.3f} {used:7.3f} "
              f"{b.e_shift_frac:11.3f}")
    print()


def trends(mass_basis: str) -> None:
    print("Section 4: short period, coupled minus rigid (paper: forward axes -> frequency down,")
    print("damping up; backward axes -> frequency up, damping down)")
    print(f"{'wing':<18} {'V':>4} {'Δω_n [rad/s]':>13} {'Δζ':>8} {'as paper':>9}")
    for r in validation.trend_rows(mass_basis=mass_basis):
        print(f"{r.wing:<18} {r.speed_m_s:4.0f} {r.d_frequency_rad_s:13.2f} {r.d_damping:8.3f} "
              f"{'yes' if r.as_paper else 'NO':>9}")
    print()


def flutter(mass_basis: str) -> None:
    print("Flutter / divergence, 5-30 m/s (paper: backward axes reach body-freedom flutter above")
    print("20 m/s; original, optimised and forward: none up to 25 m/s)")
    for r in validation.flutter_rows(mass_basis=mass_basis):
        backward = r.wing.endswith("backward")
        if r.present_at_lower_end:
            print(f"{r.wing:<18} {r.kind} at and below {r.unstable_at_and_below_m_s:g} m/s, "
                  f"{r.mode}  DISAGREES")
        elif r.flutter_speed_m_s is None:
            print(f"{r.wing:<18} none {'DISAGREES' if backward else 'agrees'}")
        else:
            agrees = backward and r.flutter_speed_m_s > 20.0
            print(f"{r.wing:<18} {r.kind} at {r.flutter_speed_m_s:.2f} m/s, {r.mode}, "
                  f"{r.frequency_rad_s:.1f} rad/s  {'agrees' if agrees else 'DISAGREES'}")
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--mass-basis", choices=("paper", "consistent"), default="consistent")
    args = parser.parse_args()
    table2()
    eigen_tables(args.mass_basis)
    table8(args.mass_basis)
    trends(args.mass_basis)
    flutter(args.mass_basis)


if __name__ == "__main__":
    main()
