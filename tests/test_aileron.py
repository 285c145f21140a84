"""Aileron effectiveness and reversal of a clamped elastic wing (aeroelasticity/aileron.py,
control_surface.py) against the thin-aerofoil flap, the uniform wing's closed form and the
typical section (sources in the modules' docstrings and docs/aeroelasticity.md)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from bioflex_jsb.aeroelasticity.aileron import (
    aileron_effectiveness,
    clamped_roll_strips,
    static_roll_matrices,
    typical_section_reversal_ratio,
    uniform_wing_effectiveness,
)
from bioflex_jsb.aeroelasticity.clamped_wing import clamped_wing_model
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
    theodorsen_flap_slopes,
)
from bioflex_jsb.aeroelasticity.strip_aero import divergence_speed_m_s
from bioflex_jsb.parameters import goland as G
from bioflex_jsb.structures.beam import uniform_sections

L_M, C_M, GJ = G.SEMISPAN_M, G.CHORD_M, G.TORSIONAL_STIFFNESS_N_M2
RHO = 1.225
A0 = 2.0 * math.pi


def _sections(x_elastic: float, x_inertial: float | None = None,
              bending: float = G.BENDING_STIFFNESS_N_M2):
    """The Goland wing's beam (parameters/goland.py) with the axes moved."""
    return uniform_sections(
        L_M, bending_stiffness_n_m2=bending, torsional_stiffness_n_m2=GJ,
        mass_per_length_kg_m=G.MASS_PER_LENGTH_KG_M,
        torsional_inertia_kg_m=G.MASS_MOMENT_OF_INERTIA_KG_M, chord_m=C_M,
        x_elastic_frac=x_elastic,
        x_inertial_frac=x_elastic + 0.1 if x_inertial is None else x_inertial)


def _case(x_elastic=G.X_ELASTIC_FRAC, span=(0.0, 1.0), hinge=0.75, **kw):
    """(StaticRollMatrices, the closed form's keyword arguments) of a Goland-like wing."""
    s = ControlSurface(span[0] * L_M, span[1] * L_M, hinge)
    model = clamped_wing_model(_sections(x_elastic, **kw), breaks_m=(s.start_m, s.end_m))
    closed = dict(torsional_stiffness_n_m2=GJ, semispan_m=L_M, chord_m=C_M,
                  arm_m=(x_elastic - 0.25) * C_M, lift_slope_per_rad=A0,
                  flap_lift_per_rad=flap_lift_slope_per_rad(hinge),
                  flap_moment_per_rad=flap_moment_slope_per_rad(hinge),
                  start_m=s.start_m, end_m=s.end_m)
    return static_roll_matrices(clamped_roll_strips(model, s)), closed, model


def _divergence_q(arm_m: float) -> float:
    """Uniform torsion rod on strips: q_D = GJ (π/2l)² / (c a₀ e) [Pa] (BAH 1955, Ch. 8)."""
    return GJ * (math.pi / (2.0 * L_M)) ** 2 / (C_M * A0 * arm_m)


def _closed_reversal_q(closed: dict, top_pa: float) -> float:
    return brentq(lambda q: uniform_wing_effectiveness(q, **closed), 1e-3, top_pa,
                  xtol=1e-9, rtol=1e-13)


# --- the section -------------------------------------------------------------------------

@pytest.mark.parametrize("hinge", [0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 0.95])
def test_glauert_equals_theodorsen_steady_flap(hinge):
    # Two derivations of the thin-aerofoil flap: Glauert's angle (cos θ_h = 2E − 1) and
    # Theodorsen's T10, T4 (NACA Report 496) in the steady limit; round-off apart.
    cl, cm = theodorsen_flap_slopes(hinge)
    assert flap_lift_slope_per_rad(hinge) == pytest.approx(cl, rel=1e-13)
    assert flap_moment_slope_per_rad(hinge) == pytest.approx(cm, rel=1e-13)


def test_flap_section_values_and_limits():
    # 25 %-chord flap: θ_h = 2π/3, c_lδ = 2(π/3 + √3/2) = 3.8264, c_mδ = −(√3/2)(3/2)/2
    # = −0.6495 (Houghton & Carpenter §4.5); flap effectiveness τ = c_lδ/2π = 0.609.
    assert flap_lift_slope_per_rad(0.75) == pytest.approx(2 * (math.pi / 3 + math.sqrt(3) / 2),
                                                          rel=1e-14)
    assert flap_moment_slope_per_rad(0.75) == pytest.approx(-0.375 * math.sqrt(3), rel=1e-14)
    # the whole chord a flap (hinge at the leading edge): a plate at δ, 2π and no moment
    # about the quarter chord; no flap (hinge at the trailing edge): nothing
    assert flap_lift_slope_per_rad(0.0) == pytest.approx(2 * math.pi, rel=1e-14)
    assert flap_moment_slope_per_rad(0.0) == pytest.approx(0.0, abs=1e-14)
    assert flap_lift_slope_per_rad(1.0) == pytest.approx(0.0, abs=1e-14)


def test_strips_have_edges_at_the_surface_ends_and_none_without():
    # without breaks the strips are the Gauss-Legendre ones of before, bit for bit
    plain = clamped_wing_model(_sections(0.33), n_modes=3)
    x, w = np.polynomial.legendre.leggauss(24)
    assert np.array_equal(plain.stations_m, 0.5 * L_M * (x + 1.0))
    assert np.array_equal(plain.weights_m, 0.5 * L_M * w)
    s = ControlSurface(0.55 * L_M, 0.95 * L_M, 0.8)
    model = clamped_wing_model(_sections(0.33), n_modes=3, breaks_m=(s.start_m, s.end_m))
    chi = strip_coverage(model.weights_m, s)
    assert set(np.unique(chi)) == {0.0, 1.0}
    on = chi == 1.0
    # the covered strips' widths add up to the surface's span; their stations inside it
    assert model.weights_m[on].sum() == pytest.approx(0.4 * L_M, rel=1e-13)
    assert np.all((model.stations_m[on] > s.start_m) & (model.stations_m[on] < s.end_m))
    assert abs(model.weights_m.sum() - L_M) < 1e-12 * L_M


def test_partial_coverage_of_strips_without_edges():
    s = ControlSurface(1.25, 2.5, 0.8)
    chi = strip_coverage(np.ones(4), s)
    assert chi == pytest.approx([0.0, 0.75, 0.5, 0.0], abs=1e-15)


# --- the clamped wing against its closed forms --------------------------------------------

def test_modal_loads_of_a_unit_aileron_angle_deflect_the_beam_as_its_closed_forms():
    # The generalised forces F_δ of a full-span aileron on the wind-off wing (η = K⁻¹ F_δ
    # per Pa per rad): the twist of a uniform torsion rod under the uniform moment
    # m_δ = c (e c_lδ + c c_mδ), θ = (m_δ/GJ)(l y − y²/2), and the deflection of a
    # cantilever under the uniform lift c c_lδ (up), w = −c c_lδ y²(6l² − 4ly + y²)/(24 EI).
    # Measured with six modes (two of them torsion): twist 0.55 %, deflection 0.07 % of their
    # largest values; twelve modes 0.09 %, 0.02 % (modal truncation). Tolerance 1 %, 0.2 %.
    _, closed, model = _case(x_inertial=G.X_INERTIAL_FRAC)
    s = ControlSurface(0.0, L_M, 0.75)
    mats = static_roll_matrices(clamped_roll_strips(model, s))
    eta = np.linalg.solve(mats.stiffness, mats.force_delta)
    y = model.stations_m
    cl, cm = closed["flap_lift_per_rad"], closed["flap_moment_per_rad"]
    twist = (C_M * (closed["arm_m"] * cl + C_M * cm) / GJ) * (L_M * y - 0.5 * y * y)
    heave = -C_M * cl * y**2 * (6 * L_M**2 - 4 * L_M * y + y * y) / (
        24.0 * G.BENDING_STIFFNESS_N_M2)
    assert np.abs(model.pitch_rad.T @ eta - twist).max() < 1e-2 * np.abs(twist).max()
    assert np.abs(model.heave_m.T @ eta - heave).max() < 2e-3 * np.abs(heave).max()


def test_divergence_is_the_strip_models():
    # the same steady problem as strip_aero's divergence speed (different assembly)
    mats, closed, model = _case()
    v = math.sqrt(2.0 * mats.divergence_dynamic_pressure_pa() / RHO)
    assert v == pytest.approx(divergence_speed_m_s(model, RHO), rel=1e-10)


@pytest.mark.parametrize(("span", "hinge"), [((0.0, 1.0), 0.75), ((0.6, 1.0), 0.8),
                                             ((0.55, 0.95), 0.8), ((0.2, 0.7), 0.7)])
def test_reversal_against_the_uniform_wing_closed_form(span, hinge):
    # Closed form: uniform_wing_effectiveness (torsion only; Megson §13.2, BAH Ch. 8).
    # Measured 6e-5 (full span) to 2.8e-4 (partial span): the beam's linear torsion
    # elements (the divergence's eigenvalue error, 1.3e-4 with 40 elements, test_goland.py)
    # and 6 modes. Tolerance 1e-3; the acceptance bar is 2 %.
    mats, closed, _ = _case(span=span, hinge=hinge)
    q_d = _divergence_q(closed["arm_m"])
    q_r = _closed_reversal_q(closed, 0.999 * q_d)
    assert mats.reversal_dynamic_pressure_pa() == pytest.approx(q_r, rel=1e-3)
    # and the effectiveness curve below reversal, point by point (measured ≤ 4e-4)
    for q in np.linspace(0.1, 1.1, 6) * q_r:
        assert mats.effectiveness(q) == pytest.approx(
            uniform_wing_effectiveness(q, **closed), abs=2e-3)


def test_full_span_closed_form_is_the_classical_sec_formula():
    # Full span: 1 − (1 + c c_mδ/(e c_lδ)) [1 − 2 (sec λl − 1)/(λl)²] (the closed form's
    # Green's-function integral specialised; written out independently here).
    _, closed, _ = _case()
    e, cl, cm = closed["arm_m"], closed["flap_lift_per_rad"], closed["flap_moment_per_rad"]
    for q in (1e3, 1e4, 2e4, 3.5e4):
        x = L_M * math.sqrt(q * C_M * e * A0 / GJ)
        ref = 1.0 - (1.0 + C_M * cm / (e * cl)) * (1.0 - 2.0 * (1.0 / math.cos(x) - 1.0) / x**2)
        assert uniform_wing_effectiveness(q, **closed) == pytest.approx(ref, rel=1e-12)


def test_reversal_relative_to_divergence_and_the_typical_section():
    # Typical section: q_R/q_D = −e c_lδ/(c c_mδ) (Hodges & Pierce Ch. 3). The uniform wing
    # (full-span aileron) has its own ratio, from the closed form; as e → 0 it tends to
    # 48/(5π²) = 0.973 of the typical section's (expanding sec x to x⁴: the twist's
    # spanwise shape weighs the root less than a rigid section on a spring). Measured:
    # model/closed ratio within 1.2e-4; at e = 0.01c 0.9737 of the typical section's
    # (limit 0.9727), Goland's e = 0.08c 0.984.
    for x_e, rel_typ in ((0.26, 2e-3), (0.33, 0.02)):
        mats, closed, _ = _case(x_elastic=x_e)
        q_d = _divergence_q(closed["arm_m"])
        ratio = mats.reversal_dynamic_pressure_pa() / mats.divergence_dynamic_pressure_pa()
        assert ratio == pytest.approx(_closed_reversal_q(closed, 0.999 * q_d) / q_d, rel=5e-4)
        typical = typical_section_reversal_ratio(
            chord_m=C_M, arm_m=closed["arm_m"], flap_lift_per_rad=closed["flap_lift_per_rad"],
            flap_moment_per_rad=closed["flap_moment_per_rad"])
        assert ratio / typical == pytest.approx(48.0 / (5.0 * math.pi**2), rel=rel_typ)
        assert ratio < 1.0  # the aileron reverses before the wing diverges


def test_elastic_axis_ahead_of_the_lift_reverses_without_diverging():
    # e < 0: no divergence; the aileron's nose-down moment still reverses it. The closed
    # form in complex arithmetic (λ imaginary: cosh). Measured 9.6e-5.
    mats, closed, _ = _case(x_elastic=0.2)
    assert math.isinf(mats.divergence_dynamic_pressure_pa())
    q_r = _closed_reversal_q(closed, 1e7)
    assert mats.reversal_dynamic_pressure_pa() == pytest.approx(q_r, rel=1e-3)


def test_statics_do_not_depend_on_the_mass_and_bending():
    # Steady strips on an unswept wing load the twist only: the centre of mass (which
    # couples the modes) and EI move the reversal only through the modal truncation.
    # Measured 6.6e-5 (centre of mass on the elastic axis) and 5.0e-4 (EI 1e5 N m^2, 100x
    # softer: low bending modes crowd the six kept); tolerance 1e-3.
    ref = _case(x_inertial=0.43)[0].reversal_dynamic_pressure_pa()
    for kw in (dict(x_inertial=0.33), dict(x_inertial=0.5),
               dict(x_inertial=0.43, bending=1e5)):
        assert _case(**kw)[0].reversal_dynamic_pressure_pa() == pytest.approx(ref, rel=1e-3)


def test_rigid_roll_damping_and_roll_rate_of_strips():
    # Rectangular wing on strips: C_lp = −a₀/6 (∫ c a₀ (y/l) y dy over both halves, on
    # S b = 4 l² c); full-span aileron p b/2V per rad = 3 c_lδ/(2 a₀); partial span
    # C_lδ = c_lδ (y₂² − y₁²)/(4 l²). Exact on Gauss strips (polynomial integrands).
    mats, closed, _ = _case()
    cl = closed["flap_lift_per_rad"]
    coef = mats.coefficients()
    assert coef["cl_p_per_rad"] == pytest.approx(-A0 / 6.0, rel=1e-12)
    assert coef["cl_delta_per_rad"] == pytest.approx(cl / 4.0, rel=1e-12)
    assert mats.rigid_roll_rate_per_rad() == pytest.approx(1.5 * cl / A0, rel=1e-12)
    part, closed, _ = _case(span=(0.6, 1.0), hinge=0.8)
    assert part.coefficients()["cl_delta_per_rad"] == pytest.approx(
        closed["flap_lift_per_rad"] * (1.0 - 0.36) / 4.0, rel=1e-12)


def test_steady_roll_reverses_with_the_rolling_moment():
    # At q_R the rolling moment of the held wing is zero, so (η, p̂ = 0) solves the steady
    # roll: both reverse at one speed. Below it the rolling wing keeps less of its rigid
    # roll rate than the held wing of its rigid moment (the roll's own upwash twists it
    # too), and both fall monotonically from 1.
    mats, _, _ = _case(span=(0.6, 1.0), hinge=0.8)
    q_r = mats.reversal_dynamic_pressure_pa()
    assert abs(mats.roll_rate_per_rad(q_r)) < 1e-9 * mats.rigid_roll_rate_per_rad()
    assert mats.rolling_moment_per_rad(q_r) == pytest.approx(0.0, abs=1e-9 * q_r
                                                             * mats.moment_delta)
    qs = np.linspace(0.0, 0.99, 12) * q_r
    eff = np.array([mats.effectiveness(q) for q in qs])
    roll = np.array([mats.roll_rate_per_rad(q) for q in qs]) / mats.rigid_roll_rate_per_rad()
    assert eff[0] == 1.0 and roll[0] == pytest.approx(1.0, rel=1e-14)
    assert np.all(np.diff(eff) < 0) and np.all(np.diff(roll) < 0)
    assert np.all(roll[1:] < eff[1:])
    # the wing free to roll diverges far above the held one
    assert mats.roll_divergence_dynamic_pressure_pa() > mats.divergence_dynamic_pressure_pa()


def test_result_of_the_shipped_case():
    # goland_aileron: outer 40 %, hinge 0.8; reversal 168.13 m/s (q_R/q_D 0.444, the
    # typical section's 0.432), divergence 252.30 m/s; the closed form 168.11 m/s.
    mats, closed, model = _case(span=(0.6, 1.0), hinge=0.8, x_inertial=G.X_INERTIAL_FRAC)
    res = aileron_effectiveness(clamped_roll_strips(model, ControlSurface(
        0.6 * L_M, L_M, 0.8)), density_kg_m3=RHO, name="goland_aileron")
    q_r = _closed_reversal_q(closed, 0.999 * _divergence_q(closed["arm_m"]))
    assert res.reversal_speed_m_s == pytest.approx(math.sqrt(2 * q_r / RHO), rel=5e-4)
    assert res.divergence_speed_m_s == pytest.approx(252.30, abs=0.01)
    # the divergence lies within twice the reversal speed: the range shows it (1.1 V_D)
    assert res.range_m_s == (0.0, pytest.approx(1.1 * res.divergence_speed_m_s))
    assert res.at(res.reversal_speed_m_s)["effectiveness"] == pytest.approx(0.0, abs=2e-3)
    assert res.effectiveness[0] == 1.0 and res.roll_effectiveness[0] == pytest.approx(1.0)
    d = res.as_dict()
    assert d["reversal_over_divergence"] == pytest.approx(0.444, abs=1e-3)
    assert d["typical_section_ratio"] == pytest.approx(0.4318, abs=1e-4)
    assert not d["reversal_above_divergence"] and len(d["speeds_m_s"]) == 241
