"""The published cases against the model, in three kinds (docs/validation.md, "Validation and
calibration", lists each with the paper's value and the model's):

* calibration checks (``test_calibration_*``): the model was fitted to these numbers; the
  test shows the fit holds, it validates nothing;
* validation (predicted, agrees): not fitted; the tolerance says why it is what it is;
* expected disagreements (``test_disagreement_*``): predicted and not reproduced. Each is
  pinned at the model's measured value (paper's and model's numbers in the docstring), so
  the test fails if the disagreement disappears or grows: then look at what changed and
  update the figure here and in docs/validation.md.
"""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import validation
from bioflex_jsb.flight_dynamics import eigen, lti
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.simulation.results import TimeHistory, gust_metrics

ROOT = Path(__file__).resolve().parents[1]
TABLE3 = validation.short_period_rows("original")
TABLE6 = validation.short_period_rows("inertial-forward")
BACKWARD = ("inertial-backward", "elastic-backward")

# Calibration: C_mα, C_mq, C_mα̇ rounded to 2-3 significant figures (−1.05, −7.3, −2.5) are
# what was fitted; worst measured residual 0.6 % (Re at 20 m/s). 1 %: the paper prints the
# rows to two figures (±0.05 in 5.6 is ±0.9 %), so a tighter fit is not defined by it.
CALIBRATION_TOL = 0.01
# Agreement of a predicted row: 5 %, twice the scatter between the paper's own coupled and
# QSD rows, which it calls "similar" (Tables 3 and 6: up to 2.5 %, 8.1 vs 7.9 rad/s).
AGREEMENT_TOL = 0.05
# A pinned disagreement: the model's eigenvalue within 0.02 rad/s of its measured value, a
# fifth of the paper's printing step (0.1 rad/s). An eigenvalue of these ≤ 10-state matrices
# repeats to ~1e-12 across BLAS kernels, so only a change of the model moves it this far.
PIN_RAD_S = 0.02

# Predicted rows that the model does not reproduce within AGREEMENT_TOL: (table, speed,
# model) -> measured model Im λ [rad/s] (paper's value in the row). Measured 2026-12-01.
DISAGREEING_IM = {
    ("Table 3", 20.0, "coupled"): 10.2416,  # paper 10.9: −6.0 %
    ("Table 3", 20.0, "qsd"): 10.2452,  # paper 10.8: −5.1 %
    ("Table 6", 20.0, "coupled"): 8.5747,  # paper 8.1: +5.9 %
    ("Table 6", 20.0, "qsd"): 8.5812,  # paper 7.9: +8.6 %
}


def _rid(r) -> str:
    return f"{r.table.replace(' ', '')}-{r.speed_m_s:g}-{r.model}"


# --------------------------------------------------------------------------------------
# Calibration checks
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("row", [r for r in TABLE3 + TABLE6 if r.model == "rigid"], ids=_rid)
def test_calibration_rigid_short_period(row):
    """Fitted: C_mα, C_mq, C_mα̇ (parameters/airframe.py) were solved from the trace and
    determinant of the rigid short period to Table 3's 15 m/s row (−5.6 ± 9.0i). The 20 m/s
    row (−7.4 ± 12.0i) follows from the same constant non-dimensional derivatives (the roots
    scale with airspeed), and Table 6's rigid rows are Table 3's (same airframe): neither is
    an independent check of the aerodynamics. Model: −5.60 ± 8.98i, −7.44 ± 11.97i."""
    assert abs(row.re_error) <= CALIBRATION_TOL
    assert abs(row.im_error) <= CALIBRATION_TOL


# --------------------------------------------------------------------------------------
# Tables 3 and 6: coupled and QSD rows (predicted: C_η1^Q1 pinned to the published value,
# modes calibrated to Table 2's frequencies, nothing fitted to these rows; the generalised
# mass basis is the one of two readings that these rows select, docs/decisions.md)
# --------------------------------------------------------------------------------------
PREDICTED = [r for r in TABLE3 + TABLE6 if r.model != "rigid"]


@pytest.mark.parametrize("row", [r for r in PREDICTED if (r.table, r.speed_m_s, r.model)
                                 not in DISAGREEING_IM], ids=_rid)
def test_predicted_short_period_rows_agree(row):
    assert abs(row.re_error) <= AGREEMENT_TOL, row
    assert abs(row.im_error) <= AGREEMENT_TOL, row


@pytest.mark.parametrize("row", [r for r in PREDICTED if (r.table, r.speed_m_s, r.model)
                                 in DISAGREEING_IM], ids=_rid)
def test_disagreement_short_period_frequency_at_20_m_s(row):
    """At 20 m/s the coupled/QSD short-period frequency is off the paper's by more than the
    agreement band: Table 3 (original wing) 10.9 / 10.8 rad/s, model 10.24 / 10.25 (−6.0 %,
    −5.1 %: the model's frequency drop with the elastic wing is larger); Table 6
    (inertial-forward) 8.1 / 7.9, model 8.57 / 8.58 (+5.9 %, +8.6 %: smaller). The real
    parts agree within 3.1 %."""
    measured = DISAGREEING_IM[(row.table, row.speed_m_s, row.model)]
    assert row.model_im == pytest.approx(measured, abs=PIN_RAD_S)
    assert abs(row.im_error) > AGREEMENT_TOL
    assert abs(row.re_error) <= AGREEMENT_TOL


def test_paper_mass_basis_overshoots_table3():
    """The literal Table B2 reading (half-wing m_i against whole-span forces) doubles the H
    terms and overshoots Table 3's frequency drop: measured −11 % to −16 % on the coupled and
    QSD rows, against −4 % to −6 % with the consistent basis. This is the comparison that
    chose the default basis (docs/decisions.md): a selection by these rows, so the rows above
    are not fully independent of it."""
    rows = validation.short_period_rows("original", mass_basis="paper")
    worst = max(abs(r.im_error) for r in rows if r.model != "rigid")
    assert worst == pytest.approx(0.160, abs=0.005)  # measured 16.0 % (20 m/s coupled)


def test_named_variants_carry_their_published_c_eta1_q1_and_report_the_pin():
    for name, variant in VARIANTS.items():
        build = build_wing(variant)
        c = build.model.coefficients
        assert c.c_eta_q[0, 0] == pytest.approx(variant.published_c_eta1_q1, abs=1e-9), name
        assert c.overrides["C_eta1^Q1"] == variant.published_c_eta1_q1
        assert build.summary()["c_eta1_q1_physical"] == build.physical_c_eta1_q1


# --------------------------------------------------------------------------------------
# Section 4 trends
# --------------------------------------------------------------------------------------
TRENDS = validation.trend_rows()


@pytest.mark.parametrize("row", [r for r in TRENDS if not (r.expected == "backward"
                                                           and r.speed_m_s == 20.0)],
                         ids=lambda r: f"{r.wing}-{r.speed_m_s:g}")
def test_short_period_trend_as_paper(row):
    """Sections 4.1-4.2: forward axes lower the short-period frequency and raise its damping;
    backward axes raise the frequency and lower the damping. Qualitative claims: the test is
    the sign of both changes (measured: forward Δω −0.86 to −4.06 rad/s, Δζ +0.015 to
    +0.074; backward at 15 m/s Δω +5.66 / +5.67 rad/s, Δζ −0.022 / −0.024)."""
    assert row.as_paper, row


@pytest.mark.parametrize("name", BACKWARD)
def test_disagreement_backward_axes_at_20_m_s(name):
    """The paper's backward-axis aircraft is still stable at 20 m/s (Tables 4 and 5 give its
    20 m/s short period; Section 4.1: the modes "become strongly coupled as the airspeed
    reaches 20 m/s" and one crosses into instability above it), with the short period's
    frequency up and damping down. The model at 20 m/s is past its flutter (14.9 / 15.45
    m/s): aeroelastic_1 grows at Re λ = +31.28 (inertial) / +34.32 (elastic) 1/s, the
    short period has split into two real roots (Δζ against rigid +0.472, where the paper has
    the damping down), and the QSD model diverges statically (+39.14 / +39.47 1/s)."""
    wing = build_wing(VARIANTS[name]).model
    (coupled,) = eigen.modes_at("coupled", [20.0], wing)
    (qsd,) = eigen.modes_at("qsd", [20.0], wing)
    measured_ae1 = {"inertial-backward": 31.28, "elastic-backward": 34.32}[name]
    measured_div = {"inertial-backward": 39.14, "elastic-backward": 39.47}[name]
    assert coupled.get("aeroelastic_1").re == pytest.approx(measured_ae1, abs=0.05)
    short = [m for m in coupled.modes if m.branch == "short_period"]
    assert len(short) == 2 and all(m.im == 0.0 for m in short)
    assert qsd.get("divergence").re == pytest.approx(measured_div, abs=0.05)
    row = next(r for r in TRENDS if r.wing == name and r.speed_m_s == 20.0)
    assert row.d_damping == pytest.approx(0.472, abs=0.005) and not row.as_paper


@pytest.mark.parametrize("name", BACKWARD)
def test_disagreement_backward_qsd_is_close_to_coupled_at_15_m_s(name):
    """Section 4.1 (after Table 5): with the axes backward, the QSD eigenvalues "are
    considerably different from the eigenvalues of the coupling model". In the model at
    15 m/s they are within 1.1 / 0.86 % of each other (|Δλ|/|λ_coupled|; inertial −8.24 ± 14.00i vs
    −8.06 ± 13.96i), less than the 2.5 % scatter the paper calls "similar" in Tables 3/6.
    (At 20 m/s the model is past flutter, see the test above.)"""
    wing = build_wing(VARIANTS[name]).model
    (c,) = eigen.modes_at("coupled", [15.0], wing)
    (q,) = eigen.modes_at("qsd", [15.0], wing)
    a, b = c.get("short_period").eigenvalue, q.get("short_period").eigenvalue
    gap = abs(a - b) / abs(a)
    assert gap == pytest.approx({"inertial-backward": 0.0111,
                                 "elastic-backward": 0.0086}[name], abs=0.001)
    assert gap < 0.025


@pytest.mark.parametrize("name", list(VARIANTS))
def test_first_aeroelastic_frequency_moves_with_the_axis_position(name):
    """Section 4 / Conclusions: forward axes make the first aeroelastic frequency rise with
    airspeed, backward axes make it fall. Measured 5 → 15 m/s: original 196 → 212,
    optimised 202 → 264, inertial-forward 134 → 165, elastic-forward 152 → 187; inertial-
    backward 125 → 77, elastic-backward 141 → 87 rad/s. The claim is a direction: the test
    asks for a change of at least 5 % of the 5 m/s value (original: +7.9 %)."""
    sets = eigen.modes_at("coupled", [5.0, 15.0], build_wing(VARIANTS[name]).model)
    lo, hi = (s.get("aeroelastic_1").frequency_rad_s for s in sets)
    change = (hi - lo) / lo
    if name in BACKWARD:
        assert change < -0.05
    else:
        assert change > 0.05


# --------------------------------------------------------------------------------------
# Flutter
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", BACKWARD)
def test_disagreement_backward_axes_flutter_below_20_m_s(name):
    """Paper (Section 4.1): the backward-axis aircraft reaches body-freedom flutter above
    20 m/s (the speed itself is held out of our copy). Model (quasi-steady strips, the
    paper's Eq. 4): flutter of aeroelastic_1 at 14.90 m/s (inertial, 78.2 rad/s) and 15.45
    m/s (elastic, 82.2 rad/s), at least 4.5 m/s below the paper's lower bound. The unstable
    branch is that of the paper's description (the first aeroelastic mode, coupled with the
    short period). Pin ±0.1 m/s: the scan's step (bisected to 0.01 m/s)."""
    res = eigen.find_flutter(build_wing(VARIANTS[name]).model, (5.0, 30.0))
    measured = {"inertial-backward": 14.90, "elastic-backward": 15.45}[name]
    speed = res.flutter_speed_m_s
    assert speed is not None and speed == pytest.approx(measured, abs=0.1)
    assert speed <= 20.0 - 4.5
    assert res.mode == "aeroelastic_1"


@pytest.mark.parametrize("name", ["original", "optimised", "inertial-forward",
                                  "elastic-forward"])
def test_forward_and_original_axes_do_not_flutter_up_to_25_m_s(name):
    """Figs. 15, 19: no instability of the original and forward-axis wings up to 25 m/s
    (the original's "regular flutter at a higher airspeed" lies beyond). Agrees."""
    res = eigen.find_flutter(build_wing(VARIANTS[name]).model, (5.0, 25.0))
    assert res.flutter_speed_m_s is None, res


# --------------------------------------------------------------------------------------
# Section 5, Fig. 21 (scripts/section5_gust.py: nonlinear JSBSim runs, 5 s)
# --------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def section5():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "section5_gust.py"),
                          "--json", "--no-plot"], capture_output=True, text=True, check=True,
                         cwd=ROOT, timeout=600)
    data = json.loads(out.stdout)
    return data, {c["claim"]: c for c in data["fig21"]["claims"]}


def test_fig21_lower_velocity_change_and_overshoot_agree(section5):
    """Paper: the elastic wing gives a lower velocity change and a lower overshoot than the
    rigid one. Model: peak |Δu| 1.50 → 1.18 m/s (−21 %), overshoot of Δα 18.9 → 11.6 %
    (−39 %). The claim is "lower": the script counts it so when at least 5 % lower (less is
    within the paper's "similar" scatter)."""
    _, claims = section5
    du = claims["lower velocity change"]
    over = claims["lower overshoot"]
    assert du["verdict"] == "agrees" and over["verdict"] == "agrees"
    assert du["values_si"]["coupled"] / du["values_si"]["rigid"] == pytest.approx(0.79,
                                                                                  abs=0.03)
    assert over["values_si"]["coupled"] / over["values_si"]["rigid"] == pytest.approx(
        0.61, abs=0.03)


def test_disagreement_fig21_stabilisation_time(section5):
    """Paper: a shorter stabilisation time with the elastic wing. Model: the short period
    settles (5 % of the Δα peak) in 0.45 s rigid and 0.57 s coupled and QSD, 0.13 s later,
    because its envelope decays more slowly (Re λ −4.82 against −5.60 1/s; the paper's own
    Table 6 has −5.0 against −5.6). The whole motion does not settle within the 4.5 s after
    the gust (rigid 0.45 s): the elastic wing's phugoid carries |Δα| above the band (its
    damping 0.0025 against 0.035 in the linear models, from the wing's speed derivative
    H_iu; docs/validation.md). Pins: ±0.03 s, the measured spread of the short-period
    settling over record lengths of 2.5 to 60 s (rigid 0.427-0.446 s, coupled 0.545-0.572
    s: the slow-part fit window moves with the record)."""
    _, claims = section5
    row = claims["shorter stabilisation time"]
    sp = row["values_si"]
    assert row["verdict"] == "disagrees"
    assert sp["rigid"] == pytest.approx(0.446, abs=0.03)
    assert sp["coupled"] == pytest.approx(0.572, abs=0.03)
    assert sp["coupled"] - sp["rigid"] > 0.08
    full = row["whole_motion_settling_s"]
    assert full["rigid"] == pytest.approx(0.449, abs=0.03)
    assert full["coupled"] is None and full["qsd"] is None
    assert row["whole_motion_shown"]["coupled"] == "does not settle within 4.5 s"


def test_fig21_coupled_and_qsd_almost_identical(section5):
    """Paper: the coupled and QSD responses are almost identical. Model: the peaks of Δu, Δα,
    Δq, Δθ within 2.4 % (Δq), and Δα within 2.2e-5 rad from 1 s after the gust. Tolerance:
    5 %, the paper's own coupled/QSD scatter doubled."""
    _, claims = section5
    row = claims["coupled ≈ QSD (almost identical)"]
    assert row["verdict"] == "agrees"
    assert row["values_si"]["coupled_vs_qsd"] <= 0.05
    assert row["values_si"]["alpha_gap_after_1_s_rad"] < 1e-3  # 0.5 % of the 0.197 peak


def test_fig22_forward_axes_alleviate_the_gust(section5):
    """Fig. 22: the optimised (forward-axes) wing alleviates the gust against the original
    (QSD). Model: peak |Δu| −9 %, |Δq| −25 %, |Δθ| −13 %, overshoot −27 %; the peak of Δα is
    the gust's edge (w_g/u_0) for any wing."""
    data, _ = section5
    claim = data["fig22"]["claim"]
    assert claim["verdict"] == "agrees"
    assert claim["change_si"]["peak_dq_rad_s"] == pytest.approx(-0.25, abs=0.03)


@pytest.mark.slow  # the Section 5 script once more, in text form: 7.9 s; full suite only
def test_section5_text_has_no_raw_none():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "section5_gust.py"),
                          "--no-plot"], capture_output=True, text=True, check=True,
                         cwd=ROOT, timeout=600).stdout
    assert "None" not in out and "does not settle within 4.5 s" in out
    assert out.count("agrees") + out.count("disagrees") >= 5


# --------------------------------------------------------------------------------------
# The short-period settling metric and the elastic phugoid
# --------------------------------------------------------------------------------------
def _lti_gust_response(model: str, t: np.ndarray, w_g: float = 3.0):
    """Step response to a w_g [m/s] updraft at t = 0 of the optimised wing's linear model
    at 15 m/s, as (TimeHistory with α to the relative wind, the fast modes' part of it)."""
    cond = level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME)
    ss = lti.build_state_space(model, cond, None if model == "rigid"
                               else build_wing(VARIANTS["optimised"]).model)
    lam, vec = np.linalg.eig(ss.a)
    x_ss = -np.linalg.solve(ss.a, ss.b[:, 0] * w_g)
    weights = np.linalg.solve(vec, -x_ss)
    parts = vec[:, None, :] * (weights * np.exp(np.outer(t, lam)))[None]  # state, t, mode
    x = x_ss[:, None] + parts.sum(axis=2).real
    alpha_air = x[1] + w_g / 15.0  # the state α is to the ground; the gust adds w_g/u_0
    fast = parts[1][:, np.abs(lam) > 3.0].sum(axis=1).real  # all but the phugoid
    run = TimeHistory(model, t, {"u": x[0], "alpha": alpha_air, "q": x[2], "theta": x[3],
                                 "n_z": np.ones_like(t)}, {}, {"gust": "sharp:3"})
    return run, fast


@pytest.mark.parametrize("model", ["rigid", "qsd"])
def test_short_period_settling_is_the_settling_of_the_fast_modes(model):
    """GustMetrics.short_period_settling_time_s on a linear step response equals the 5 %
    settling of the fast modes' part of Δα, computed from the modal decomposition (exact):
    measured rigid 0.446 vs 0.447 s, QSD 0.569 vs 0.572 s on a 1 ms grid. 0.01 s: ten
    samples, a tenth of the 0.12 s rigid/elastic difference the Fig. 21 verdict rests on.
    The whole-motion settling of the QSD model is None (its phugoid, ζ 0.0025, keeps |Δα|
    above 5 % of the peak for the whole 4.5 s)."""
    t = np.arange(0.0, 4.5, 1e-3)
    run, fast = _lti_gust_response(model, t)
    m = gust_metrics(run, 0.0)
    band = 0.05 * m.peak_dalpha_rad
    exact = t[np.nonzero(np.abs(fast) > band)[0][-1] + 1]
    assert m.short_period_settling_time_s == pytest.approx(exact, abs=0.01)
    if model == "qsd":
        assert m.settling_time_s is None
    else:
        assert m.settling_time_s == pytest.approx(exact, abs=0.02)


def test_short_period_settling_needs_two_seconds_after_the_gust():
    t = np.arange(0.0, 1.9, 1e-3)
    run, _ = _lti_gust_response("rigid", t)
    m = gust_metrics(run, 0.0)
    assert m.short_period_settling_time_s is None and m.settling_time_s is not None


def test_elastic_phugoid_damping_comes_from_the_wing_speed_derivative():
    """Optimised wing, 15 m/s: phugoid ζ 0.0347 rigid, 0.0025 coupled. Setting H_iu (Table
    B2: the trim load's generalised force growing with u, 2 C_0^Qi Q S c̄/(m_i u_0)) to zero
    gives back 0.0343, as does Table B2 as printed (H_iu over the aircraft mass m, 1.3e-5 of
    m_i/m: dimensionally not a generalised acceleration). With the propeller's dT/dV that
    JSBSim flies in X_u: 0.071 rigid, 0.032 coupled (the nonlinear runs' u decay: 0.069,
    0.036). Pins ±0.0005: a tenth of the smallest gap the conclusion rests on."""
    cond = level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME)
    wing = build_wing(VARIANTS["optimised"]).model

    def zeta(a):
        lam = np.linalg.eigvals(a)
        lam = lam[(lam.imag > 1e-6) & (np.abs(lam) < 3.0)]
        root = lam[np.argmin(np.abs(lam))]
        return -root.real / abs(root)

    rigid = zeta(lti.build_state_space("rigid", cond).a)
    coupled = zeta(lti.build_state_space("coupled", cond, wing).a)
    ed = lti.elastic_derivatives(wing, cond)
    no_h_u = zeta(lti.build_state_space("coupled", cond, wing,
                                        elastic=replace(ed, h_u=0.0 * ed.h_u)).a)
    assert rigid == pytest.approx(0.0347, abs=5e-4)
    assert coupled == pytest.approx(0.0025, abs=5e-4)
    assert no_h_u == pytest.approx(0.0343, abs=5e-4)
