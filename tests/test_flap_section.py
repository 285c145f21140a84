"""Theodorsen's flap T-functions and the flap section's loads (aerodynamics/theodorsen.py):
their closed forms against the thin-aerofoil integrals they come from (numeric quadrature),
the leading-edge limit (a flap hinged at the leading edge is a pitch about it), the steady
(Glauert) limit, the apparent mass's symmetry, and Jones's lag against the exact C(k)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from bioflex_jsb.aerodynamics.indicial import jones_c
from bioflex_jsb.aerodynamics.theodorsen import (
    flap_section_loads,
    flap_section_matrices,
    flap_t_functions,
    section_matrices,
    theodorsen_c,
)
from bioflex_jsb.aeroelasticity.control_surface import (
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
)

PI = math.pi
HINGES_C = (-0.6, -0.2, 0.0, 0.3, 0.5, 0.8, 0.9)
AXES_A = (-0.5, -0.24, 0.0, 0.2)
# quadrature of smooth integrands in θ (x = cos θ): QUADPACK's own error estimate is
# asked for 1e-13; measured differences from the closed forms ≤ 4.4e-16 (the integrals),
# 1.5e-16 of the largest load (the loads)
QUAD_TOL = 1e-13
SECTION = dict(speed_m_s=30.0, semichord_m=0.6, density_kg_m3=1.1)


def _q(f, theta_end: float) -> float:
    return quad(f, 0.0, theta_end, epsabs=1e-14, epsrel=1e-13, limit=200)[0]


@pytest.mark.parametrize("c", HINGES_C)
def test_thin_aerofoil_integrals(c):
    """The four integrals of the flap's downwash over its chord (x = cos θ from the hinge
    θ_c = arccos c to the trailing edge θ = 0) are the closed forms' T₁₀, T₁₁, T₄, T₁."""
    t = flap_t_functions(c, 0.0)
    th = math.acos(c)
    kutta = _q(lambda s: 1.0 + math.cos(s), th)  # ∫ √((1+x)/(1−x)) dx
    kutta_x = _q(lambda s: (math.cos(s) - c) * (1.0 + math.cos(s)), th)
    mass = _q(lambda s: math.sin(s) ** 2, th)  # ∫ √(1−x²) dx
    mass_x = _q(lambda s: (math.cos(s) - c) * math.sin(s) ** 2, th)
    got = np.array([kutta, kutta_x, mass, mass_x])
    want = np.array([t.t10, t.t11 / 2.0, -t.t4 / 2.0, -t.t1 / 2.0])
    assert np.max(np.abs(got - want)) < QUAD_TOL, (got, want)


def _quadrature_loads(c: float, a: float, omega: float, cc: complex) -> np.ndarray:
    """(3, 3) complex: (L, M_α, M_β-less) … the lift and moment about the axis of unit
    harmonic h, α, β from the thin aerofoil's weighted integrals of the downwash w(x)
    (x = cos θ): W = (2/π)∫ w √(1−x²), Q = (1/π)∫ w √((1+x)/(1−x)),
    X = ∫ w (x − 2a) √(1−x²); L = πρb² iω W + 2πρVb C Q,
    M_α = −ρb³ iω X + πρVb² W − πρVb² Q + 2πρVb² (a + ½) C Q (the apparent-mass
    potential's pressure with the Kutta flow's C-independent part moved to it)."""
    v, b, rho = SECTION["speed_m_s"], SECTION["semichord_m"], SECTION["density_kg_m3"]
    iw = 1j * omega
    shapes = (  # (downwash per unit displacement [m/s per unit], per unit rate), θ range
        (lambda x: 0.0, lambda x: 1.0, PI),
        (lambda x: v, lambda x: b * (x - a), PI),
        (lambda x: v, lambda x: b * (x - c), math.acos(c)),
    )
    out = np.zeros((2, 3), dtype=complex)
    for j, (disp, rate, th) in enumerate(shapes):
        def integral(weight, disp=disp, rate=rate, th=th):
            re = _q(lambda s: disp(math.cos(s)) * weight(s), th)
            im = _q(lambda s: rate(math.cos(s)) * weight(s), th)
            return re + iw * im
        w_nc = 2.0 / PI * integral(lambda s: math.sin(s) ** 2)
        q_c = 1.0 / PI * integral(lambda s: 1.0 + math.cos(s))
        x_m = integral(lambda s: (math.cos(s) - 2.0 * a) * math.sin(s) ** 2)
        out[0, j] = PI * rho * b * b * iw * w_nc + 2.0 * PI * rho * v * b * cc * q_c
        out[1, j] = (-rho * b**3 * iw * x_m + PI * rho * v * b * b * (w_nc - q_c)
                     + 2.0 * PI * rho * v * b * b * (a + 0.5) * cc * q_c)
    return out


@pytest.mark.parametrize("c", (-0.4, 0.2, 0.5, 0.8))
@pytest.mark.parametrize("a", (-0.5, 0.1))
def test_lift_and_moment_against_quadrature(c, a):
    """Lift and moment about the elastic axis of unit heave, pitch and flap motion at three
    reduced frequencies, the closed forms (T-functions) against the thin aerofoil's integrals
    of the downwash by quadrature: measured ≤ 1.5e-16 relative to the largest load."""
    b, v = SECTION["semichord_m"], SECTION["speed_m_s"]
    for k in (0.0, 0.1, 1.5):
        omega = k * v / b
        cc = complex(theodorsen_c(k))
        want = _quadrature_loads(c, a, omega, cc)
        got = np.zeros((2, 3), dtype=complex)
        for j in range(3):
            q = np.eye(3)[j]
            lift, m_a, _ = flap_section_loads(*q, omega, elastic_axis_a=a, hinge_c=c,
                                              **SECTION)
            got[:, j] = (lift, m_a)
        scale = np.max(np.abs(want))
        assert np.max(np.abs(got - want)) < QUAD_TOL * scale, (k, got, want)


@pytest.mark.parametrize("a", AXES_A)
def test_leading_edge_values(a):
    """c = −1: r = 0, arccos c = π."""
    t = flap_t_functions(-1.0, a)
    want = dict(t1=-PI, t2=-PI**2, t3=-9.0 * PI**2 / 8.0, t4=-PI, t5=-PI**2, t6=-PI**2,
                t7=-9.0 * PI / 8.0, t8=-PI, t9=-PI * a / 2.0, t10=PI, t11=3.0 * PI,
                t12=PI, t13=PI * (0.125 - a) / 2.0, t14=1.0 / 16.0 - a / 2.0)
    for name, value in want.items():
        assert getattr(t, name) == pytest.approx(value, rel=1e-15, abs=1e-15), name


@pytest.mark.parametrize("a", AXES_A)
@pytest.mark.parametrize("k", (0.0, 0.05, 0.4, 2.0))
def test_leading_edge_flap_is_a_pitch(a, k):
    """A flap hinged at the leading edge (c = −1) rotating by β is the section pitching by
    β about the leading edge (h = b (1 + a) β at the axis): the same lift and moment, and
    its hinge moment is the moment about the leading edge (a section with a = −1)."""
    b, v = SECTION["semichord_m"], SECTION["speed_m_s"]
    omega = k * v / b
    lift_f, m_f, hinge = flap_section_loads(0.0, 0.0, 1.0, omega, elastic_axis_a=a,
                                            hinge_c=-1.0, **SECTION)
    lift_p, m_p, _ = flap_section_loads(b * (1.0 + a), 1.0, 0.0, omega, elastic_axis_a=a,
                                        hinge_c=0.5, **SECTION)
    _, m_le, _ = flap_section_loads(0.0, 1.0, 0.0, omega, elastic_axis_a=-1.0, hinge_c=0.5,
                                    **SECTION)
    scale = abs(lift_p) * b + abs(m_p)
    assert abs(lift_f - lift_p) * b < 1e-13 * scale
    assert abs(m_f - m_p) < 1e-13 * scale
    assert abs(hinge - m_le) < 1e-13 * scale


@pytest.mark.parametrize("c", HINGES_C)
@pytest.mark.parametrize("a", AXES_A)
def test_matrices_structure(c, a):
    """The (h, α) block is section_matrices'; the apparent mass is symmetric and positive
    definite (a kinetic energy of the fluid)."""
    m = flap_section_matrices(elastic_axis_a=a, hinge_c=c, **SECTION)
    s = section_matrices(elastic_axis_a=a, **SECTION)
    assert np.allclose(m.apparent_mass[:2, :2], s.apparent_mass, rtol=1e-15, atol=0)
    assert np.allclose(m.apparent_damping[:2, :2], s.apparent_damping, rtol=1e-15, atol=0)
    assert np.allclose(m.force_vector[:2], s.force_vector, rtol=1e-15, atol=0)
    assert np.array_equal(m.apparent_mass, m.apparent_mass.T)
    assert np.all(np.linalg.eigvalsh(m.apparent_mass) > 0.0)


@pytest.mark.parametrize("hinge", (0.5, 0.6, 0.7, 0.75, 0.8, 0.9, 0.95))
def test_steady_glauert_limit(hinge):
    """k → 0: the flap's lift per radian is Glauert's c_lδ = 2 (π − arccos c' … ) =
    2 (arccos c + √(1 − c²)) (c = 2·hinge − 1) and its moment about the quarter chord
    c_mδ = −(T₄ + T₁₀)/2, control_surface.py's thin-aerofoil slopes, to round-off."""
    b, v, rho = SECTION["semichord_m"], SECTION["speed_m_s"], SECTION["density_kg_m3"]
    c = 2.0 * hinge - 1.0
    lift, m_qc, _ = flap_section_loads(0.0, 0.0, 1.0, 0.0, elastic_axis_a=-0.5, hinge_c=c,
                                       **SECTION)
    q = 0.5 * rho * v * v
    assert lift.imag == 0.0 and m_qc.imag == 0.0
    assert lift.real / (q * 2.0 * b) == pytest.approx(
        2.0 * (math.acos(c) + math.sqrt(1.0 - c * c)), rel=1e-14)
    assert lift.real / (q * 2.0 * b) == pytest.approx(flap_lift_slope_per_rad(hinge),
                                                      rel=1e-14)
    assert m_qc.real / (q * 4.0 * b * b) == pytest.approx(flap_moment_slope_per_rad(hinge),
                                                          rel=1e-13)


@pytest.mark.parametrize("c", (0.0, 0.5, 0.8))
def test_steady_hinge_moment_against_glauert_series(c):
    """The steady hinge moment, −(T₅ − T₄T₁₀ + T₁₀T₁₂)/2π per q c² per radian (trailing
    edge down), against the thin aerofoil's loading of the flap's camber summed from
    Glauert's series (2000 terms, θ quadrature): measured 1.5e-7, 5.1e-7, 1.6e-6 relative
    for c = 0, 0.5, 0.8 (the series' tail: 500 terms 2.4e-6, 8.1e-6, 2.6e-5)."""
    t = flap_t_functions(c, 0.0)
    closed = -(t.t5 - t.t4 * t.t10 + t.t10 * t.t12) / (2.0 * PI)
    # Glauert's angle from the leading edge, x/c = (1 − cos θ)/2: the hinge at θ_h with
    # cos θ_h = −c; camber slope dz/dx = −1 on the flap (θ > θ_h, z up): A₀ = (π − θ_h)/π,
    # A_n = (2/π) sin(n θ_h)/n
    th_h = math.acos(-c)
    a0 = (PI - th_h) / PI
    n = np.arange(1, 2001)
    an = 2.0 / PI * np.sin(n * th_h) / n

    def load(s):  # Δp/q = 4 (A₀ cot(θ/2) + Σ A_n sin nθ)
        return 4.0 * (a0 / math.tan(s / 2.0) + an @ np.sin(n * s))
    # hinge moment, trailing edge down, per q c²: −∫_flap (Δp/q) (x − x_h)/c d(x/c)
    hinge = -quad(lambda s: load(s) * (math.cos(th_h) - math.cos(s)) * math.sin(s),
                  th_h, PI, limit=400)[0] / 4.0
    assert hinge == pytest.approx(closed, rel=1e-5)


# Jones's lag against the exact C(k), k = 0.01 … 2 (40 points), a = −0.2: the largest
# relative error of each load [lift, moment about the axis, hinge moment], measured for
# c = 0.5 [0.0237, 0.0626, 0.0057] and c = 0.8 [0.0236, 0.0229, 0.0023]: the lift's is
# C(k)'s own (≤ 2.3 %); the moment about the axis is a difference of the circulatory and
# apparent-mass moments at low k, which magnifies it
JONES_TOLERANCE = {0.5: (0.03, 0.07, 0.01), 0.8: (0.03, 0.03, 0.01)}


@pytest.mark.parametrize("c", (0.5, 0.8))
def test_jones_lag_against_exact_c(c):
    """The flap's lift, moment and hinge moment with Jones's two-lag C(k) against the exact
    C(k) (:data:`JONES_TOLERANCE`, the measured errors beside it)."""
    b, v = SECTION["semichord_m"], SECTION["speed_m_s"]
    worst = np.zeros(3)
    for k in np.geomspace(0.01, 2.0, 40):
        omega = k * v / b
        exact = np.array(flap_section_loads(0.0, 0.0, 1.0, omega, elastic_axis_a=-0.2,
                                            hinge_c=c, **SECTION))
        lag = np.array(flap_section_loads(0.0, 0.0, 1.0, omega, elastic_axis_a=-0.2,
                                          hinge_c=c, circulation=complex(jones_c(k)),
                                          **SECTION))
        worst = np.maximum(worst, np.abs(lag - exact) / np.abs(exact))
    assert np.all(worst < JONES_TOLERANCE[c]), worst


@pytest.mark.parametrize("a", AXES_A)
def test_trailing_edge_limit(a):
    """c → 1 (a flap of no chord): every T but T₁₄ (1/16 + a c/2) vanishes, as the flap's
    loads must: at c = 1 − 1e-12 (r = √(1 − c²) = 1.4e-6) T₁₀ = r + arccos c ≈ 2r (the
    steady flap lift goes as the square root of the flap's chord), every other one below
    r² (measured ≤ 1.6e-18)."""
    t = flap_t_functions(1.0 - 1e-12, a)
    r = math.sqrt(1.0 - (1.0 - 1e-12) ** 2)
    assert t.t10 == pytest.approx(2.0 * r, rel=1e-6)
    for name in ("t1", "t2", "t3", "t4", "t5", "t6", "t7", "t8", "t9", "t11", "t12", "t13"):
        assert abs(getattr(t, name)) < r * r, (name, getattr(t, name))
    assert t.t14 == pytest.approx(1.0 / 16.0 + 0.5 * a, abs=1e-12)
