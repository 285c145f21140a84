"""The published cases: Tables 3 and 6, the Section 4 trends, flutter (issue acceptance)."""

from __future__ import annotations

import pytest

from bioflex_jsb import validation
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

# Tolerances: the rigid rows are the calibration target and the foundation's acceptance
# figure is 5 %; the coupled and QSD rows are predictions and the acceptance figure is 10 %
# (the paper prints two significant figures, i.e. up to ±5 % rounding on its own).
TOL = {"rigid": 0.05, "coupled": 0.10, "qsd": 0.10}

TABLE3 = validation.short_period_rows("original")
TABLE6 = validation.short_period_rows("inertial-forward")


@pytest.mark.parametrize("row", TABLE3, ids=lambda r: f"{r.speed_m_s:g}-{r.model}")
def test_table3_original_wing(row):
    assert abs(row.re_error) <= TOL[row.model]
    assert abs(row.im_error) <= TOL[row.model]


@pytest.mark.parametrize("row", TABLE6, ids=lambda r: f"{r.speed_m_s:g}-{r.model}")
def test_table6_inertial_forward(row):
    assert abs(row.re_error) <= TOL[row.model]
    assert abs(row.im_error) <= TOL[row.model]


def test_paper_mass_basis_overshoots_table3():
    # The literal Table B2 reading (half-wing m_i against whole-span forces) doubles the H
    # terms; with the calibrated modes it overshoots Table 3's frequency drop by > 10 %,
    # which is why the consistent basis is the default (docs/decisions.md).
    rows = validation.short_period_rows("original", mass_basis="paper")
    worst = max(abs(r.im_error) for r in rows if r.model != "rigid")
    assert worst > TOL["coupled"]


def test_named_variants_carry_their_published_c_eta1_q1_and_report_the_pin():
    for name, variant in VARIANTS.items():
        build = build_wing(variant)
        c = build.model.coefficients
        assert c.c_eta_q[0, 0] == pytest.approx(variant.published_c_eta1_q1, abs=1e-9), name
        assert c.overrides["C_eta1^Q1"] == variant.published_c_eta1_q1
        assert build.summary()["c_eta1_q1_physical"] == build.physical_c_eta1_q1


@pytest.mark.parametrize("row", [r for r in validation.trend_rows()
                                 if r.expected == "forward"],
                         ids=lambda r: f"{r.wing}-{r.speed_m_s:g}")
def test_forward_axes_lower_frequency_and_raise_damping(row):
    assert row.as_paper


@pytest.mark.parametrize("name", ["inertial-backward", "elastic-backward"])
def test_backward_axes_raise_short_period_frequency_at_15_m_s(name):
    row = next(r for r in validation.trend_rows((15.0,)) if r.wing == name)
    assert row.d_frequency_rad_s > 0.0


@pytest.mark.parametrize("name", ["inertial-backward", "elastic-backward"])
def test_backward_axes_reach_flutter_between_5_and_30_m_s(name):
    res = eigen.find_flutter(build_wing(VARIANTS[name]).model, (5.0, 30.0))
    assert res.flutter_speed_m_s is not None and 5.0 < res.flutter_speed_m_s < 30.0
    assert res.mode in ("aeroelastic_1", "short_period")


@pytest.mark.parametrize("name", ["original", "optimised", "inertial-forward",
                                  "elastic-forward"])
def test_forward_and_original_axes_do_not_flutter_up_to_25_m_s(name):
    res = eigen.find_flutter(build_wing(VARIANTS[name]).model, (5.0, 25.0))
    assert res.flutter_speed_m_s is None, res
