"""Half-wing beam model, modal data, calibration against Table 2, axis coupling."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters import wing_structure as WS
from bioflex_jsb.structures.beam import (
    BeamInputError,
    BeamSections,
    beam_modes,
    solve_beam,
    uniform_sections,
    wing_from_membrane,
)
from bioflex_jsb.structures.modal_data import ModalData, ModalDataError
from bioflex_jsb.structures.sections import (
    ChordwiseLayup,
    Layer,
    elastic_axis_frac,
    eq11_residual,
    eq12_residual,
    inertial_axis_frac,
    mass_per_length_kg_m,
    open_section_torsional_stiffness_n_m2,
    torsional_inertia_kg_m,
)
from bioflex_jsb.structures.wing_model import (
    calibrate_default_wings,
    table2_comparison,
    tip_bending_twist_ratio_m,
    wing_modes,
    wing_sections,
)

# A uniform test beam with the prototype's semispan and magnitudes like the membrane wing.
L_M = 0.85  # Table 1 b/2
EI, GJ, MASS, INERTIA, CHORD = 50.0, 2.0, 0.07, 2.0e-4, 0.183  # ESTIMATE: test values only
BENDING_ROOTS = (1.8751040687, 4.6940911330, 7.8547574382)  # roots of 1 + cos βL cosh βL = 0


def uniform(**kw) -> BeamSections:
    args = dict(bending_stiffness_n_m2=EI, torsional_stiffness_n_m2=GJ,
                mass_per_length_kg_m=MASS, torsional_inertia_kg_m=INERTIA, chord_m=CHORD)
    args.update(kw)
    return uniform_sections(L_M, **args)


def split(sol):
    tors = sol.torsion_energy_fraction > 0.5
    return sol.frequencies_rad_s[~tors], sol.frequencies_rad_s[tors]


# --------------------------------------------------------------------------------------
# Uniform clamped-free beam against the analytic solutions
# --------------------------------------------------------------------------------------
def test_uniform_beam_matches_analytic_bending_and_torsion():
    sol = solve_beam(uniform(), n_modes=12, n_elements=40)
    bend, tors = split(sol)
    exact_b = np.array(BENDING_ROOTS) ** 2 * math.sqrt(EI / (MASS * L_M**4))
    exact_t = np.array([1, 3, 5]) * math.pi / 2 * math.sqrt(GJ / INERTIA) / L_M
    # 0.5 %: the linear torsion element with consistent mass overestimates ω_k by about
    # (β_k h)²/24 = 0.16 % for the 3rd mode at 40 elements (β_3 = 5π/2L); Hermite bending is
    # better than 1e-3 %. A wrong mass/stiffness factor or a wrong Hermite term would be off
    # by far more than 0.5 %.
    np.testing.assert_allclose(bend[:3], exact_b, rtol=5e-3)
    np.testing.assert_allclose(tors[:3], exact_t, rtol=5e-3)
    # FE with consistent mass is an upper bound (Rayleigh–Ritz): it must not undershoot by
    # more than round-off (1e-6 relative, far above double precision on a 120-dof problem).
    assert np.all(tors[:3] >= exact_t * (1 - 1e-6))


def test_mesh_convergence_uniform_and_calibrated():
    exact_t3 = 5 * math.pi / 2 * math.sqrt(GJ / INERTIA) / L_M
    errors = []
    for n in (10, 20, 40):
        _, tors = split(solve_beam(uniform(), 8, n))
        errors.append(tors[2] / exact_t3 - 1.0)
    # Linear elements: error ∝ h², so halving h divides it by ≈ 4 (3.5..4.5 allows for the
    # higher-order terms at 10 elements).
    assert 3.5 < errors[0] / errors[1] < 4.5 and 3.5 < errors[1] / errors[2] < 4.5
    # The calibrated ribbed wing (strongly tapered GJ): 40 elements are within 0.5 % of 160.
    f40 = solve_beam(wing_sections(WS.RIBBED_WING), 3, 40).frequencies_rad_s
    f160 = solve_beam(wing_sections(WS.RIBBED_WING), 3, 160).frequencies_rad_s
    np.testing.assert_allclose(f40, f160, rtol=5e-3)  # 0.5 %: well below the 2 % Table 2 check


def test_uniform_torsion_generalised_mass_and_normalisation():
    modes = beam_modes(uniform(), 4)
    tors = np.flatnonzero(~modes.twist_free())
    first = tors[0]
    # θ = sin(π y / 2L) with max 1 at the tip: m = ∫ I_α θ² dy = I_α L / 2. 0.5 %: FE shape
    # and trapezoid-free exact integration, the error is the mode's O(h²) shape error.
    assert modes.generalised_masses_kg_m2[first] == pytest.approx(INERTIA * L_M / 2, rel=5e-3)
    assert np.max(np.abs(modes.twist_rad[first])) == pytest.approx(1.0, abs=1e-12)
    assert modes.twist_rad[first, -1] > 0.0
    # Twist-free (pure bending) modes: scaled so that max |φ| = y_tip, tip positive (down).
    b = np.flatnonzero(modes.twist_free())[0]
    assert np.max(np.abs(modes.bending_m[b])) == pytest.approx(L_M, rel=1e-12)
    assert modes.bending_m[b, -1] > 0.0
    # Bending generalised mass: ∫ m' φ² dy with φ = L·ψ(y)/ψ(L) for the exact first mode.
    beta = BENDING_ROOTS[0] / L_M
    y = np.linspace(0, L_M, 2001)
    sig = (math.cosh(BENDING_ROOTS[0]) + math.cos(BENDING_ROOTS[0])) / (
        math.sinh(BENDING_ROOTS[0]) + math.sin(BENDING_ROOTS[0]))
    psi = np.cosh(beta * y) - np.cos(beta * y) - sig * (np.sinh(beta * y) - np.sin(beta * y))
    phi = L_M * psi / psi[-1]
    # 0.5 %: FE shape error (tiny for Hermite) plus trapezoid error on 2001 points (< 1e-5).
    assert modes.generalised_masses_kg_m2[b] == pytest.approx(
        np.trapezoid(MASS * phi**2, y), rel=5e-3)


# --------------------------------------------------------------------------------------
# Eq. (11)–(12) and the section properties
# --------------------------------------------------------------------------------------
def test_default_sections_satisfy_eq11_and_eq12():
    layup, ribs = WS.ORIGINAL_LAYUP, WS.RIBS
    s = (np.arange(20000) + 0.5) / 20000  # midpoints: no node on a layer boundary
    x_i = inertial_axis_frac(layup, ribs)
    x_e = elastic_axis_frac(layup)
    # 1e-4 chord: trapezoid on 20000 cells of a piecewise-constant integrand, error ≤ h.
    assert abs(eq11_residual(s, layup.areal_mass_kg_m2(s) + ribs.areal_mass_kg_m2, x_i)) < 1e-4
    assert abs(eq12_residual(s, layup.membrane_stiffness_n_m(s), x_e)) < 1e-4
    sections = wing_sections(WS.RIBBED_WING)
    assert np.allclose(sections.x_inertial_frac, x_i) and np.allclose(sections.x_elastic_frac, x_e)
    # Table 8, original wing: both axes at half chord.
    assert x_i == pytest.approx(0.5, abs=1e-12) and x_e == pytest.approx(0.5, abs=1e-12)


def test_kevlar_trailing_edge_moves_axes_forward():
    """Appendix A: Kevlar near the trailing edge moves both axes towards the leading edge."""
    layup = ChordwiseLayup((
        Layer(WS.CARBON, 0.2e-3, 0.0, 0.5),
        Layer(WS.KEVLAR, 0.18e-3, 0.5, 1.0),
    ))
    x_i, x_e = inertial_axis_frac(layup), elastic_axis_frac(layup)
    # Hand calculation: weights w1 = ρt or Et on [0, .5], w2 on [.5, 1]; centroid
    # (0.25 w1 + 0.75 w2)/(w1 + w2).
    w1, w2 = 1.6e3 * 0.2e-3, 1.4e3 * 0.18e-3
    assert x_i == pytest.approx((0.25 * w1 + 0.75 * w2) / (w1 + w2), rel=1e-12)
    e1, e2 = 90e9 * 0.2e-3, 40e9 * 0.18e-3
    assert x_e == pytest.approx((0.25 * e1 + 0.75 * e2) / (e1 + e2), rel=1e-12)
    assert x_e < x_i < 0.5
    s = (np.arange(20000) + 0.5) / 20000
    assert abs(eq11_residual(s, layup.areal_mass_kg_m2(s), x_i)) < 1e-4  # as above
    assert abs(eq12_residual(s, layup.membrane_stiffness_n_m(s), x_e)) < 1e-4


def test_section_mass_and_inertia_of_a_uniform_plate():
    c, t = 0.183, 0.2e-3
    layup = ChordwiseLayup((Layer(WS.CARBON, t),))
    m = mass_per_length_kg_m(layup, c)
    assert m == pytest.approx(1.6e3 * t * c, rel=1e-12)
    # plate about mid-chord: m c²/12; about the leading edge: m c²/3
    assert torsional_inertia_kg_m(layup, c, 0.5) == pytest.approx(m * c**2 / 12, rel=1e-12)
    assert torsional_inertia_kg_m(layup, c, 0.0) == pytest.approx(m * c**2 / 3, rel=1e-12)
    g = 90e9 / (2 * 1.3)
    assert open_section_torsional_stiffness_n_m2(layup, c) == pytest.approx(
        g * c * t**3 / 3, rel=1e-12)


# --------------------------------------------------------------------------------------
# Calibration against Table 2 (what was fitted: test_calibration_*) and what it predicts
# --------------------------------------------------------------------------------------
# The stored stiffnesses are rounded to 4 significant digits (≤ 5e-4 relative), which moves
# the fitted frequencies by less than 0.03 %; measured worst residual 0.008 % (ribbed mode 1).
CALIBRATION_FREQUENCY_TOL = 1e-3


def test_calibration_table2_ribbed_frequencies():
    """Fitted: the ribbed wing's arm/hand GJ (root, kink ratio) and hand inertia ratio h,
    three numbers, were solved so that its first three torsion modes are Table 2's "with
    ribs" 30.9, 71.9, 107.2 Hz (structures.wing_model.calibrate_default_wings). Model 30.898,
    71.895, 107.194 Hz: the fit holds; it validates nothing."""
    rows = table2_comparison(True)
    for row, f in zip(rows, P.MODE_FREQUENCIES_RIBS_HZ, strict=True):
        assert row.paper_frequency_hz == f
        assert abs(row.frequency_error) < CALIBRATION_FREQUENCY_TOL, row


def test_calibration_table2_unribbed_first_two_frequencies():
    """Fitted: the unribbed wing's linear GJ taper (root, tip ratio) on Table 2's "without
    ribs" modes 1-2, 20.8 and 49.6 Hz. Model 20.798, 49.596 Hz."""
    rows = table2_comparison(False)
    for row, f in zip(rows[:2], P.MODE_FREQUENCIES_NO_RIBS_HZ[:2], strict=True):
        assert row.paper_frequency_hz == f
        assert abs(row.frequency_error) < CALIBRATION_FREQUENCY_TOL, row


def test_unribbed_third_frequency_is_predicted():
    """Predicted (not fitted): the unribbed third torsion mode, Table 2 79.6 Hz, model
    79.63 Hz (+0.03 %). Tolerance 0.12 %: twice the paper's printing resolution (79.6 Hz is
    ±0.05 Hz, ±0.06 %)."""
    row = table2_comparison(False)[2]
    assert row.paper_frequency_hz == P.MODE_FREQUENCIES_NO_RIBS_HZ[2]
    assert abs(row.frequency_error) < 1.2e-3, row


def test_arm_hand_sections():
    ws = WS.RIBBED_WING
    sec = wing_sections(ws)
    yk = ws.hand_start_m
    assert yk == pytest.approx(0.45 * ws.semispan_m, rel=1e-12)  # planform kink (wing.py)
    floor = open_section_torsional_stiffness_n_m2(ws.layup, ws.chord_m)
    gj = sec.at(np.array([0.0, yk, ws.semispan_m]))["GJ"]
    # 1e-12: these are the interpolation nodes themselves (exact up to round-off)
    np.testing.assert_allclose(
        gj, [ws.torsional_stiffness_root_n_m2,
             ws.torsional_stiffness_root_n_m2 * ws.torsional_stiffness_kink_ratio, floor],
        rtol=1e-12)
    arm = sec.at(np.array([0.5 * yk]))
    hand = sec.at(np.array([0.5 * (yk + ws.semispan_m)]))
    for key in ("m", "I"):  # the hand carries h x the arm's mass and inertia per span
        assert hand[key][0] == pytest.approx(ws.hand_inertia_ratio * arm[key][0], rel=1e-12)
    # wing mass: arm at full m', hand at h m' (the step is 1e-6 b/2 wide: 1e-5 relative).
    uniform_mass = wing_sections(replace(ws, hand_inertia_ratio=1.0))
    expected = uniform_mass.half_wing_mass_kg * (
        yk + ws.hand_inertia_ratio * (ws.semispan_m - yk)) / ws.semispan_m
    assert sec.half_wing_mass_kg == pytest.approx(expected, rel=1e-5)
    # axis overrides move both axes on arm and hand: S = m'(x_I - x_E)c everywhere, and
    # the hand's I about the moved axis is h x the arm's (parallel axis on both).
    moved = wing_sections(ws, x_inertial_frac=0.7, x_elastic_frac=0.4)
    assert np.allclose(moved.x_inertial_frac, 0.7) and np.allclose(moved.x_elastic_frac, 0.4)
    np.testing.assert_allclose(moved.static_moment_kg,
                               moved.mass_per_length_kg_m * 0.3 * ws.chord_m, rtol=1e-12)
    arm_m, hand_m = (moved.at(np.array([y]))["I"][0] for y in (0.5 * yk,
                                                              0.5 * (yk + ws.semispan_m)))
    assert hand_m == pytest.approx(ws.hand_inertia_ratio * arm_m, rel=1e-12)
    assert arm_m == pytest.approx(sec.torsional_inertia_kg_m[0] + sec.mass_per_length_kg_m[0]
                                  * (0.3 * ws.chord_m) ** 2, rel=1e-12)


def test_arm_hand_inputs_are_checked():
    args = dict(semispan_m=0.85, chord_m=0.183, layup=WS.ORIGINAL_LAYUP, ribs=None,
                torsional_stiffness_root_n_m2=1.0, torsional_stiffness_tip_ratio=None,
                bending_stiffness_n_m2=100.0)
    with pytest.raises(BeamInputError, match="hand_start_m"):
        wing_from_membrane(**args, hand_inertia_ratio=0.5)
    with pytest.raises(BeamInputError, match="hand_start_m"):
        wing_from_membrane(**args, hand_start_m=0.9, torsional_stiffness_kink_ratio=0.1)
    with pytest.raises(BeamInputError, match="torsional_stiffness_kink_ratio"):
        wing_from_membrane(**args, hand_start_m=0.4)
    with pytest.raises(BeamInputError, match="hand_inertia_ratio"):
        wing_from_membrane(**args, hand_start_m=0.4, torsional_stiffness_kink_ratio=0.1,
                           hand_inertia_ratio=0.0)


def test_mode_identity_and_twist_dominated_modes():
    # Section 3.1 (Figs. 7-12): modes 1-3 are twist-dominated with and without ribs.
    for ribs in (True, False):
        rows = table2_comparison(ribs)
        assert [r.kind for r in rows] == ["torsion 1", "torsion 2", "torsion 3"]
        assert all(r.torsion_energy_fraction > 0.5 and not r.twist_free for r in rows)


@pytest.mark.parametrize("structure", [WS.RIBBED_WING, WS.UNRIBBED_WING])
def test_first_bending_mode_above_the_three_table2_modes(structure):
    sol = solve_beam(wing_sections(structure), 10)  # no-rib bending is the 7th mode
    f = sol.frequencies_rad_s / (2 * math.pi)
    bend = f[sol.torsion_energy_fraction <= 0.5]
    # 1.3 x the ribbed third Table 2 mode: the brief's separation (a bending mode near the
    # torsion modes would drive bending-torsion flutter the paper does not see).
    assert bend[0] >= 1.3 * P.MODE_FREQUENCIES_RIBS_HZ[2]
    assert bend[0] > np.max(f[sol.torsion_energy_fraction > 0.5][:3])


# Model/paper ratio of the ribbed generalised masses (not fitted: they follow from the mass
# estimates of wing_structure and the calibrated stiffness), measured 2026-12-01.
RIBBED_MASS_RATIOS = (0.2472, 0.1815, 1.394)
UNRIBBED_MASS_RATIOS = (2.841, 26.85, 4.682)


def test_ribbed_generalised_masses_are_twist_normalised_and_torsion_sized():
    """Twist-normalised torsion modes have generalised masses of 1e-6..1e-4 kg·m² (Table 2:
    6.57e-5, 5.70e-5, 8.37e-6); a bending mode normalised on twist is orders of magnitude
    larger (the old bending mode 3 gave 1.1e-2, 1300x Table 2)."""
    for r in table2_comparison(True):
        assert 1e-6 < r.model_generalised_mass_kg_m2 < 1e-4, r


def test_disagreement_ribbed_generalised_masses():
    """Predicted, not reproduced: Table 2 "with ribs" 6.57e-5, 5.70e-5, 8.37e-6 kg·m²; model
    1.62e-5, 1.03e-5, 1.17e-5 (0.25x, 0.18x, 1.39x). History (git log -L of this test): the
    linear-taper wing gave 0.74x / 0.42x for modes 1-2, inside the old 3x band; commit
    048dd75 (the arm/hand wing, three parameters fitted to the three ribbed frequencies,
    with a lighter hand: h = 0.47) moved them to 0.25x / 0.18x, and the band was widened to
    6x instead of recording the disagreement. The frequencies are fitted; the
    masses are what the fitted structure gives, and they do not match. Pin ±2 % of the
    ratio: re-running the calibration (4-digit rounding) moves them by < 0.1 %."""
    rows = table2_comparison(True)
    for r, measured in zip(rows, RIBBED_MASS_RATIOS, strict=True):
        ratio = r.model_generalised_mass_kg_m2 / r.paper_generalised_mass_kg_m2
        assert ratio == pytest.approx(measured, rel=0.02), r
        assert abs(ratio - 1.0) > 0.3  # outside ±30 % of Table 2: a disagreement


def test_disagreement_unribbed_generalised_masses():
    """Predicted, not reproduced: Table 2 "without ribs" 1.50e-5, 9.29e-7, 4.48e-6 kg·m²;
    model 4.26e-5, 2.49e-5, 2.10e-5 (2.8x, 27x, 4.7x). Table 2's second mass is below the
    other two by more than an order of magnitude, which a twist-normalised torsion mode of a
    smooth wing does not give. Pin ±2 % as above."""
    rows = table2_comparison(False)
    for r, measured in zip(rows, UNRIBBED_MASS_RATIOS, strict=True):
        ratio = r.model_generalised_mass_kg_m2 / r.paper_generalised_mass_kg_m2
        assert ratio == pytest.approx(measured, rel=0.02), r
        assert abs(ratio - 1.0) > 0.3


def test_stored_calibration_is_what_the_calibration_finds():
    ribbed, unribbed = calibrate_default_wings()
    # 1e-3: the stored values are rounded to 4 significant digits (≤ 5e-4 relative).
    assert WS.RIBBED_TORSIONAL_STIFFNESS_ROOT_N_M2 == pytest.approx(
        ribbed.torsional_stiffness_root_n_m2, rel=1e-3)
    assert WS.RIBBED_TORSIONAL_STIFFNESS_KINK_RATIO == pytest.approx(
        ribbed.torsional_stiffness_kink_ratio, rel=1e-3)
    assert WS.RIBBED_HAND_INERTIA_RATIO == pytest.approx(ribbed.hand_inertia_ratio, rel=1e-3)
    assert WS.BENDING_STIFFNESS_N_M2 == pytest.approx(ribbed.bending_stiffness_n_m2, rel=1e-3)
    assert WS.UNRIBBED_TORSIONAL_STIFFNESS_ROOT_N_M2 == pytest.approx(
        unribbed.torsional_stiffness_root_n_m2, rel=1e-3)
    assert WS.UNRIBBED_TORSIONAL_STIFFNESS_TIP_RATIO == pytest.approx(
        unribbed.torsional_stiffness_tip_ratio, rel=1e-3)


def test_calibrated_wing_is_physically_plausible():
    for structure in (WS.RIBBED_WING, WS.UNRIBBED_WING):
        sections = wing_sections(structure)
        # Section 3.1: the membrane wing weighs less than 10 % of the aircraft (both halves).
        assert 2 * sections.half_wing_mass_kg < P.WING_MASS_FRACTION_MAX * P.MASS_KG
        # The tip keeps at least the bare membrane's open-section torsional stiffness.
        floor = open_section_torsional_stiffness_n_m2(structure.layup, structure.chord_m)
        assert sections.torsional_stiffness_n_m2[-1] >= floor
        assert np.all(np.diff(sections.torsional_stiffness_n_m2) < 0)  # stiffest at the root


# --------------------------------------------------------------------------------------
# Bending–torsion coupling through the inertial-axis offset
# --------------------------------------------------------------------------------------
def test_coincident_axes_give_uncoupled_modes():
    modes = wing_modes(WS.RIBBED_WING, 5)
    for i in range(modes.n_modes):
        pure_bending = np.all(modes.twist_rad[i] == 0.0)
        pure_twist = np.all(modes.bending_m[i] == 0.0)
        assert pure_bending != pure_twist, i


def test_inertial_axis_aft_puts_downward_bending_into_mode_1():
    """Sign from the equations of motion of one section (w down, θ leading edge up):

    m ẅ + S θ̈ + k_w w = 0 and S ẅ + I θ̈ + k_θ θ = 0, S = m (x_I − x_E) c. In a mode at ω:
    (k_w − ω² m) w = ω² S θ. Mode 1 is torsion-dominated and below the bending frequency, so
    k_w − ω² m > 0 and w has the sign of S θ: with the inertial axis aft (S > 0) the elastic
    axis moves DOWN (w > 0) where the leading edge twists up (θ > 0).
    """
    aft = wing_modes(WS.RIBBED_WING, 3, x_inertial_frac=0.75)
    twist, bend = aft.twist_rad[0, 1:], aft.bending_m[0, 1:]
    assert np.all(twist > 0) and np.all(bend > 0)
    fwd = wing_modes(WS.RIBBED_WING, 3, x_inertial_frac=0.25)
    assert np.all(fwd.twist_rad[0, 1:] > 0) and np.all(fwd.bending_m[0, 1:] < 0)
    # Uniform sections with parallel-axis inertia: the offset ±d gives the same I_α, so the
    # ratio is exactly antisymmetric (1e-9: eigen-solver round-off).
    assert tip_bending_twist_ratio_m(fwd) == pytest.approx(-tip_bending_twist_ratio_m(aft),
                                                           rel=1e-9)


def test_coupling_grows_with_axis_offset():
    # Monotonic up to |x_I − x_E| ≈ c/√12 = 0.29 c: beyond it the growth of I_α = I_cg + m d²
    # lowers ω₁² faster than S = m d grows (docs/structures.md, "Coupling").
    offsets = (0.0, 0.05, 0.10, 0.15, 0.20, 0.25)
    ratios = [tip_bending_twist_ratio_m(wing_modes(WS.RIBBED_WING, 1, x_inertial_frac=0.5 + d))
              for d in offsets]
    assert ratios[0] == 0.0
    assert np.all(np.diff(ratios) > 0)
    # and the bending share of mode 1's strain energy grows too
    shares = [1 - solve_beam(wing_sections(WS.RIBBED_WING, x_inertial_frac=0.5 + d),
                             1).torsion_energy_fraction[0] for d in offsets]
    assert np.all(np.diff(shares) > 0)


def test_beam_rejects_inertia_below_parallel_axis_bound():
    with pytest.raises(BeamInputError, match="torsional_inertia_kg_m"):
        uniform(torsional_inertia_kg_m=1e-6, x_inertial_frac=0.9)


def test_wing_from_membrane_parallel_axis_inertia():
    base = wing_sections(WS.RIBBED_WING)
    moved = wing_sections(WS.RIBBED_WING, x_inertial_frac=0.85)
    d = 0.35 * WS.RIBBED_WING.chord_m
    m = base.mass_per_length_kg_m[0]
    assert moved.torsional_inertia_kg_m[0] == pytest.approx(
        base.torsional_inertia_kg_m[0] + m * d**2, rel=1e-12)
    assert moved.static_moment_kg[0] == pytest.approx(m * d, rel=1e-12)


# --------------------------------------------------------------------------------------
# ModalData validation
# --------------------------------------------------------------------------------------
def _modal(**kw):
    y = np.linspace(0.0, 0.85, 5)
    args = dict(
        frequencies_rad_s=[10.0, 20.0], damping_ratios=[0.0, 0.0],
        generalised_masses_kg_m2=[1e-4, 2e-4], stations_m=y,
        bending_m=np.zeros((2, 5)), twist_rad=np.vstack([y / 0.85, -y / 0.85]),
        x_elastic_frac=0.5, x_inertial_frac=0.5, source="test")
    args.update(kw)
    return ModalData(**args)


@pytest.mark.parametrize("field, value", [
    ("stations_m", [0.0, 0.2, 0.2, 0.6, 0.85]),
    ("twist_rad", np.full((2, 4), 0.1)),
    ("bending_m", np.array([[0, np.nan, 0, 0, 0], [0] * 5], dtype=float)),
    ("generalised_masses_kg_m2", [1e-4, -1.0]),
    ("frequencies_rad_s", [0.0, 20.0]),
    ("damping_ratios", [0.0]),
    ("x_elastic_frac", [0.5, 0.5, 0.5]),
])
def test_modal_data_errors_name_the_field(field, value):
    with pytest.raises(ModalDataError, match=field):
        _modal(**{field: value})


def test_modal_data_truncation_and_normalisation():
    raw = _modal()
    assert raw.n_modes == 2 and raw.truncated(1).n_modes == 1
    with pytest.raises(ModalDataError, match="truncated"):
        raw.truncated(3)
    norm = raw.normalised()
    assert np.all(norm.twist_rad[:, -1] == 1.0)  # second mode's sign flipped
    assert norm.is_normalised()
    # rescaling a mode by −3 and its mass by 9 is the same physics: same normalised data
    scaled = replace(raw, twist_rad=raw.twist_rad * np.array([[-3.0], [1.0]]),
                     generalised_masses_kg_m2=raw.generalised_masses_kg_m2 * [9.0, 1.0])
    np.testing.assert_allclose(scaled.normalised().twist_rad, norm.twist_rad, rtol=1e-14)
    np.testing.assert_allclose(scaled.normalised().generalised_masses_kg_m2,
                               norm.generalised_masses_kg_m2, rtol=1e-14)
    with pytest.raises(ValueError):
        norm.twist_rad[0, 0] = 2.0  # read-only arrays: ModalData is immutable


def test_wing_from_membrane_rejects_bad_station_count():
    with pytest.raises(BeamInputError, match="n_stations"):
        wing_from_membrane(
            semispan_m=0.85, chord_m=0.183, layup=WS.ORIGINAL_LAYUP, ribs=None,
            torsional_stiffness_root_n_m2=1.0, torsional_stiffness_tip_ratio=0.1,
            bending_stiffness_n_m2=100.0, n_stations=1)
