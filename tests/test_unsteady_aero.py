"""Theodorsen's and Sears' functions, Wagner's and Küssner's indicial functions, and the
finite-state strip model, against closed forms, tabulated values and each other."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import hankel2

from bioflex_jsb.aerodynamics import indicial as I
from bioflex_jsb.aerodynamics import theodorsen as T

# A Goland-like strip (tests only): semichord 0.9144 m, axis at 33 % chord, 100 m/s.
STRIP = dict(speed_m_s=100.0, semichord_m=0.9144, elastic_axis_a=T.elastic_axis_a(0.33),
             density_kg_m3=1.225)


# --------------------------------------------------------------------------------------
# Theodorsen's C(k)
# --------------------------------------------------------------------------------------
def test_theodorsen_limits():
    # C(0) = 1 (steady flow) and C(∞) = ½ (Theodorsen 1935). At k = 1e4 the next term of the
    # expansion is O(1/k) ≈ 1e-5; tolerance 1e-4 leaves room for it.
    assert T.theodorsen_c(0.0) == 1.0
    assert abs(T.theodorsen_c(1e-8) - 1.0) < 1e-6  # continuity: 1 − C ~ k ln k → 2e-7
    assert abs(T.theodorsen_c(1e4) - 0.5) < 1e-4


@pytest.mark.parametrize(
    "k, f, g",
    # Tabulated C(k) = F + iG (Theodorsen 1935; BAH 1955, Chapter 5), given to 4 digits.
    [(0.1, 0.8319, -0.1723), (0.2, 0.7276, -0.1886), (0.5, 0.5979, -0.1507),
     (1.0, 0.5394, -0.1003)],
)
def test_theodorsen_tabulated(k, f, g):
    c = T.theodorsen_c(k)
    # tolerance: half a unit in the table's last digit
    assert abs(c.real - f) <= 5e-5 + 1e-12
    assert abs(c.imag - g) <= 5e-5 + 1e-12


def test_theodorsen_large_k_asymptote():
    # C(k) → ½ − i/(8k) for large k (from the Hankel asymptotic expansions). The neglected
    # terms are O(1/k²) relative: at k = 50 that is 4e-4, tolerance 1e-3 relative on k·G.
    k = 50.0
    c = T.theodorsen_c(k)
    assert c.imag * k == pytest.approx(-1.0 / 8.0, rel=1e-3)


def test_jones_approximation_error():
    # Jones's fit (Jones 1940) against the exact C(k): its largest error over 1e-3 ≤ k ≤ 100
    # is 0.0145 at k ≈ 0.41 (measured here; 2.3 % of |C| there). Tolerance 0.016: the
    # measured maximum plus a margin, so a change to the fit or to C(k) shows.
    k = np.logspace(-3, 2, 600)
    err = np.abs(I.jones_c(k) - T.theodorsen_c(k))
    assert err.max() < 0.016
    assert I.jones_c(0.0) == pytest.approx(1.0, abs=1e-15)  # exact at k = 0 by construction
    assert abs(I.jones_c(1e6) - 0.5) < 1e-5  # and at k → ∞ (1 − 0.165 − 0.335)


# --------------------------------------------------------------------------------------
# Sears' function
# --------------------------------------------------------------------------------------
def test_sears_closed_form_identity():
    # An independent closed form: S(k) = 2 / (π k [H₀⁽²⁾(k) − i H₁⁽²⁾(k)]) (follows from the
    # Wronskian of the Bessel functions). Both are evaluated in double precision: 1e-12.
    k = np.array([0.05, 0.2, 0.7, 1.5, 4.0])
    other = 2.0 / (math.pi * k * (hankel2(0, k) - 1j * hankel2(1, k)))
    assert np.max(np.abs(T.sears_s(k) - other)) < 1e-12


def test_sears_limits():
    # S(0) = 1 (quasi-steady gust); |S(k)| → 1/√(2πk) as k → ∞ (Sears 1941). At k = 200
    # the relative correction is O(1/k) = 0.5 %; tolerance 1 %.
    assert T.sears_s(0.0) == pytest.approx(1.0, abs=1e-15)
    k = 200.0
    assert abs(T.sears_s(k)) * math.sqrt(2.0 * math.pi * k) == pytest.approx(1.0, rel=1e-2)
    # leading-edge reference only changes the phase
    assert abs(T.sears_s(k, reference="leading-edge")) == pytest.approx(abs(T.sears_s(k)))


# --------------------------------------------------------------------------------------
# Indicial functions
# --------------------------------------------------------------------------------------
def test_wagner_known_points():
    # φ(0) = ½ exactly (Wagner; the impulsive lift is half the steady one) for the exact
    # function and Jones's fit; φ(s) → 1 for large s. The numerical inversion is checked
    # against Garrick's algebraic approximation (s + 2)/(s + 4) (Garrick 1938, NACA Report
    # 629; quoted in BAH 1955): measured deviation ≤ 0.018 (at s = 10); tolerance 0.02.
    assert I.wagner_exact(0.0) == 0.5
    assert I.wagner_jones(0.0) == pytest.approx(0.5, abs=1e-15)
    s = np.array([1.0, 2.0, 5.0, 10.0])
    assert np.max(np.abs(I.wagner_exact(s) - (s + 2.0) / (s + 4.0))) < 0.02
    assert I.wagner_exact(1000.0) == pytest.approx(1.0, abs=2e-3)  # slow algebraic approach


def test_wagner_jones_vs_exact():
    # Jones's exponentials against the exact φ(s): largest deviation measured 0.0092 (at
    # s = 100, where the exact function's algebraic tail is slower than any exponential);
    # tolerance 0.01.
    s = np.array([0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0])
    assert np.max(np.abs(I.wagner_jones(s) - I.wagner_exact(s))) < 0.01


def test_kussner_known_points_and_approximation():
    # ψ(0) = 0, ψ(∞) = 1 (Küssner). Sears & Sparks's two exponentials are a coarse fit: the
    # largest deviation measured here is 0.078 at s = 0.5 (the exact ψ rises like √s at
    # first, which no exponential sum reproduces) and 0.032 at s = 20; tolerance 0.08.
    assert I.kussner_exact(0.0) == 0.0
    assert I.kussner_sears_sparks(0.0) == pytest.approx(0.0, abs=1e-15)
    s = np.array([0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0])
    assert np.max(np.abs(I.kussner_sears_sparks(s) - I.kussner_exact(s))) < 0.08
    assert I.kussner_exact(1000.0) == pytest.approx(1.0, abs=3e-3)
    assert np.all(np.diff(I.kussner_exact(s)) > 0.0)  # monotonic rise


def test_indicial_transfer_is_fourier_pair():
    # The step response rebuilt from an approximation's own transfer function (the same
    # Fourier inversion as wagner_exact) equals the closed exponential form: checks the
    # inversion itself. QUADPACK accuracy: tolerance 1e-6.
    s = np.array([0.3, 3.0, 30.0])
    rebuilt = [I._step_from_transfer(lambda k: I.JONES_WAGNER.transfer(k), si) for si in s]
    assert np.max(np.abs(np.array(rebuilt) - I.wagner_jones(s))) < 1e-6


# --------------------------------------------------------------------------------------
# Section loads and the finite-state model
# --------------------------------------------------------------------------------------
def test_quasi_steady_pitch_damping_zero_at_mid_chord():
    # With C = 1 and the axis at mid-chord the circulatory α̇ moment πρVb³/2 and the
    # apparent-mass one −πρVb³/2 cancel (Theodorsen 1935): no pitch damping.
    kw = dict(STRIP, elastic_axis_a=0.0)
    w = 10.0
    a = T.section_force_matrix(w, circulation="quasi-steady", **kw)
    a0 = T.section_force_matrix(0.0, circulation="quasi-steady", **kw)
    damping = (a - a0 - w * w * T.section_matrices(**kw).apparent_mass) / (1j * w)
    assert abs(damping[1, 1]) < 1e-9 * abs(a0[1, 1])


def test_steady_lift_and_moment():
    # At ω = 0: lift = q·2b·a₀·α and moment = lift·b(a + ½) about the axis (quarter-chord
    # lift). Exact algebra: 1e-12 relative.
    a0 = 5.5
    kw = dict(STRIP, lift_slope_per_rad=a0)
    lift, moment = T.section_lift_moment(0.0, 1.0, 0.0, **kw)
    q = 0.5 * STRIP["density_kg_m3"] * STRIP["speed_m_s"] ** 2
    b = STRIP["semichord_m"]
    assert lift.real == pytest.approx(q * 2 * b * a0, rel=1e-12)
    assert moment.real == pytest.approx(q * 2 * b * a0 * b * (STRIP["elastic_axis_a"] + 0.5),
                                        rel=1e-12)


@pytest.mark.parametrize("omega", [0.3, 5.0, 70.0, 400.0])
def test_finite_state_frequency_response_equals_jones(omega):
    # The state-space strip model's frequency response is Theodorsen's loads with C(k)
    # replaced by Jones's C(k), and its gust response is d·(Sears & Sparks transfer):
    # identical algebra, tolerance 1e-10 relative (round-off of a 4×4 solve).
    kw = dict(STRIP, lift_slope_per_rad=5.2)
    ss = I.strip_state_space(**kw)
    k = omega * STRIP["semichord_m"] / STRIP["speed_m_s"]
    ref = T.section_force_matrix(omega, circulation=complex(I.jones_c(k)), **kw)
    assert np.max(np.abs(ss.force_matrix(omega) - ref)) < 1e-10 * np.max(np.abs(ref))
    gust_ref = ss.section.force_vector * I.SEARS_SPARKS_KUSSNER.transfer(k)
    assert np.max(np.abs(ss.gust_force(omega) - gust_ref)) < 1e-10 * np.max(np.abs(gust_ref))
    assert ss.state_names == ("wagner_lag_1_m", "wagner_lag_2_m", "kussner_lag_1_m",
                              "kussner_lag_2_m")


def test_finite_state_step_response_is_wagner():
    # A step in pitch α = 1 rad (no rates): the circulatory lift follows a₀ρVb·V·φ(s) with
    # Jones's φ. Integrate the lag states exactly (they are decoupled first-order filters)
    # and compare: tolerance 1e-12 relative.
    ss = I.strip_state_space(**STRIP, gust=False)
    v, b = STRIP["speed_m_s"], STRIP["semichord_m"]
    t = np.array([0.0, 0.01, 0.1, 1.0])
    q = np.array([0.0, 1.0])
    poles = np.diag(ss.a)
    drive = ss.b_q @ q
    x = drive[None, :] * (np.expm1(poles[None, :] * t[:, None]) / poles[None, :])
    force = x @ ss.c.T + (ss.d_q @ q)[None, :]
    lift = -force[:, 0]
    expected = 2 * math.pi * STRIP["density_kg_m3"] * v * b * v * I.wagner_jones(v * t / b)
    assert np.max(np.abs(lift - expected)) < 1e-12 * expected.max()
