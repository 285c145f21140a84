"""Validation of the vortex-lattice spanwise aerodynamics (bioflex_jsb.aerodynamics).

Analytic and published limits used here, each with its source:

* Biot–Savart law of a straight vortex segment, checked against direct quadrature;
* 2-D lumped-vortex lattice: lift slope 4π·r for control points r panel chords aft of the
  bound vortices (r = ½: 2π, thin-aerofoil theory), for any number of equal panels;
* textbook horseshoe lattice: Bertin & Cummings, "Aerodynamics for Engineers", worked
  example of the vortex-lattice method (AR 5, taper 1, 45° sweep, 4 horseshoes per half
  span): C_Lα = 0.0601 per degree;
* exact lifting-surface solution for the circular wing (Kinner 1937): C_Lα = 1.790 per rad;
* Prandtl lifting-line theory for elliptic wings (the AR → ∞ limit):
  C_Lα = a_0/(1 + a_0/(π AR)) and, for α = p y/V, C_lp = −(a_0/8)/(1 + 2a_0/(π AR));
* Helmbold's formula C_Lα = 2π AR/(2 + √(AR² + 4)) and the 2-D limit 2π for AR → ∞.

Run ``pytest -s tests/test_aerodynamics.py`` to see the printed figures.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.integrate import quad

from bioflex_jsb.aerodynamics import vortex_lattice as ll
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM, Planform

TWO_PI = 2.0 * math.pi


@dataclasses.dataclass(frozen=True)
class EllipticPlanform:
    """Elliptic chord distribution with one straight, unswept chord-fraction line [m]."""

    semispan_m: float
    root_chord_m: float
    straight_line_fraction: float = 0.25

    def chord_at(self, y_m):
        eta = np.abs(np.asarray(y_m, dtype=float)) / self.semispan_m
        return self.root_chord_m * np.sqrt(np.clip(1.0 - eta**2, 0.0, None))

    def leading_edge_x_at(self, y_m):
        f = self.straight_line_fraction
        return f * (self.root_chord_m - self.chord_at(y_m))


def elliptic(aspect_ratio: float, straight_line_fraction: float = 0.25) -> EllipticPlanform:
    """Elliptic wing of unit semispan: S = π b c_0 / 4, so c_0 = 4 b/(π AR) with b = 2.

    ``straight_line_fraction``: the chord fraction whose line is straight and unswept
    (0.5 for a true ellipse, e.g. the circular wing).
    """
    return EllipticPlanform(1.0, 8.0 / (math.pi * aspect_ratio), straight_line_fraction)


def rectangular(aspect_ratio: float) -> Planform:
    """Unswept rectangular wing of unit semispan (chord 2/AR)."""
    return Planform(1.0, 2.0 / aspect_ratio, 0.5, 0.0, 0.0)


def lifting_line_elliptic(ar: float, a0: float = TWO_PI) -> float:
    return a0 / (1.0 + a0 / (math.pi * ar))


def helmbold(ar: float) -> float:
    return TWO_PI * ar / (2.0 + math.sqrt(ar**2 + 4.0))


# --------------------------------------------------------------------------------------
# Building blocks
# --------------------------------------------------------------------------------------


def test_segment_velocity_matches_biot_savart_quadrature():
    rng = np.random.default_rng(3)
    for _ in range(5):
        a, b, p = rng.normal(size=(3, 3))
        exact = np.zeros(3)
        for comp in range(3):

            def integrand(s, comp=comp, a=a, b=b, p=p):
                x = a + s * (b - a)
                r = p - x
                return np.cross(b - a, r)[comp] / (4.0 * math.pi * np.linalg.norm(r) ** 3)

            exact[comp] = quad(integrand, 0.0, 1.0, epsabs=1e-13, epsrel=1e-12)[0]
        got = ll._segment_velocity(p[None, None, :], a[None, None, :], b[None, None, :])[0, 0]
        # quadrature of a smooth integrand (p is O(1) away from the segment): ~1e-12
        assert np.allclose(got, exact, rtol=1e-9, atol=1e-12)


def test_semi_infinite_filament_is_the_limit_of_a_long_segment():
    rng = np.random.default_rng(4)
    a, p = rng.normal(size=(2, 3))
    length = 1e7
    far = a + np.array([length, 0.0, 0.0])
    seg = ll._segment_velocity(p[None, None], a[None, None], far[None, None])[0, 0]
    semi = ll._semi_infinite_velocity(p[None, None], a[None, None], np.ones((1, 1)))[0, 0]
    # the missing tail beyond L contributes O(h/L²) relative to O(1/h): ~1e-14 here
    assert np.allclose(semi, seg, rtol=1e-9, atol=1e-12)


def test_horseshoe_sign_lift_up_gives_downwash_behind_it():
    a = np.array([[0.0, -1.0, 0.0]])
    b = np.array([[0.0, 1.0, 0.0]])
    w = ll.horseshoe_normalwash(np.array([[0.5, 0.0, 0.0], [-0.05, 0.0, 0.0]]), a, b)
    assert w[0, 0] < 0.0  # downwash behind a lifting (Γ > 0) bound vortex
    assert w[1, 0] > 0.0  # upwash just ahead of it
    # far behind, on the centre line, the trailing legs at y = ±1 look like two infinite
    # lines, each inducing Γ/(2π·1) downward: w → −1/π for Γ = 1 (1e-6: the finite bound
    # segment and the legs' starting ends contribute O(1/x²) = 1e-12 at x = 1e6)
    far = ll.horseshoe_normalwash(np.array([[1e6, 0.0, 0.0]]), a, b)
    assert far[0, 0] == pytest.approx(-1.0 / math.pi, rel=1e-6)


@pytest.mark.parametrize("a0", [TWO_PI, 5.5, 7.0])
@pytest.mark.parametrize("n_chordwise", [1, 2, 4, 8])
def test_2d_lattice_has_the_section_lift_slope(a0, n_chordwise):
    r = ll.control_point_fraction(a0)
    # a direct linear solve of a ≤ 8×8 system: round-off only
    assert ll._lift_slope_2d(r, n_chordwise) == pytest.approx(a0, rel=1e-12)


def test_bertin_cummings_textbook_example():
    """AR 5, taper 1, Λ = 45°, 4 uniform horseshoes per half span, 3/4-chord rule."""
    swept = Planform(1.0, 0.4, 0.0, math.radians(45.0), 0.0)  # b = 2, c = 0.4: AR 5
    aero = ll.solve_spanwise_aerodynamics(swept, n_spanwise=4, n_chordwise=1, spacing="uniform")
    per_deg = aero.wing_lift_slope_per_rad * math.pi / 180.0
    print(f"\nBertin & Cummings example: C_Lα = {per_deg:.5f} /deg (book: 0.0601 /deg)")
    # the book prints three significant figures: ±0.00005 /deg
    assert per_deg == pytest.approx(0.0601, abs=0.00005)
    # ... and that coarse lattice is not converged: the 40 × 4 cosine lattice is 7.5 % lower
    fine = ll.solve_spanwise_aerodynamics(swept, n_spanwise=40, n_chordwise=4)
    assert fine.wing_lift_slope_per_rad < 0.95 * aero.wing_lift_slope_per_rad


# --------------------------------------------------------------------------------------
# (a) elliptic wings
# --------------------------------------------------------------------------------------


def test_circular_wing_matches_kinner_exact_solution():
    aero = ll.solve_spanwise_aerodynamics(elliptic(4.0 / math.pi, 0.5), n_chordwise=8)
    print(f"\ncircular wing: C_Lα = {aero.wing_lift_slope_per_rad:.4f} /rad (Kinner: 1.790)")
    # 0.5 %: 1.790 is given to 4 digits (±0.03 %); the lattice changes by < 0.05 % from
    # 8 to 32 chordwise panels and its polygonal area differs from π b c_0/4 by 0.03 %.
    assert aero.wing_lift_slope_per_rad == pytest.approx(1.790, rel=0.005)


def test_elliptic_lift_slope_tends_to_lifting_line_theory():
    rows = []
    for ar in (6.0, 8.0, 10.0, 12.0, 20.0, 50.0):
        aero = ll.solve_spanwise_aerodynamics(elliptic(ar))
        theory = lifting_line_elliptic(ar)
        gap = 1.0 - aero.wing_lift_slope_per_rad / theory
        rows.append((ar, aero.wing_lift_slope_per_rad, theory, helmbold(ar), gap))
    print("\nAR   VLM C_Lα   2πAR/(AR+2)   Helmbold   gap to lifting line")
    for ar, vlm, theory, helm, gap in rows:
        print(f"{ar:4.0f}  {vlm:.4f}     {theory:.4f}       {helm:.4f}     {100 * gap:.2f} %")
    gaps = np.array([r[4] for r in rows])
    ars = np.array([r[0] for r in rows])
    # Lifting-line theory is the AR → ∞ limit; a lifting surface lies below it by a
    # correction of order ln(AR)/AR² (second-order lifting-line theory). The lattice must
    # (i) approach the limit monotonically, (ii) stay inside that order with a constant of
    # 2.2 (measured: 1.4–1.8 for AR 6–50; a first-order 1/AR error would break it at large
    # AR), (iii) be within 2 % of it from AR 20 up. At AR 6–12 the gap is 2.7–6.8 %: the
    # brief's "2 % for AR 6–12" is a lifting-line, not a lifting-surface, expectation
    # (docs/aerodynamics.md).
    assert np.all(np.diff(gaps) < 0.0)
    assert np.all(gaps > 0.0)
    assert np.all(gaps < 2.2 * np.log(ars) / ars**2)
    assert gaps[ars >= 20.0].max() < 0.02
    # Helmbold's interpolation formula is within 3.5 % of the lattice for AR 6–12
    # (measured 1.5–3.0 %; Helmbold is itself 2.2 % above Kinner's exact circular wing).
    for ar, vlm, _, helm, _ in rows[:4]:
        assert vlm == pytest.approx(helm, rel=0.035), ar


@pytest.mark.parametrize(
    "ar, y_max_frac, tol",
    [
        # lifting-surface tip effect: c_l falls within ~1 chord of the tip; 3 % over the
        # inner 80 % of the span at AR 6–12 (measured ≤ 1.9 %) ...
        (6.0, 0.8, 0.03),
        (12.0, 0.8, 0.03),
        # ... and the affected region shrinks as AR grows (measured 0.74 % at AR 50)
        (50.0, 0.95, 0.01),
    ],
)
def test_elliptic_wing_has_constant_section_lift_coefficient(ar, y_max_frac, tol):
    aero = ll.solve_spanwise_aerodynamics(elliptic(ar))
    inner = aero.stations_m <= y_max_frac * aero.semispan_m
    cl_ratio = aero.local_lift_slope_per_rad[inner] / aero.wing_lift_slope_per_rad
    assert np.max(np.abs(cl_ratio - 1.0)) < tol


@pytest.mark.parametrize("a0", [5.5, TWO_PI])
def test_elliptic_high_aspect_ratio_with_section_lift_slope(a0):
    ar = 100.0
    for n_chordwise in (1, 4):
        aero = ll.solve_spanwise_aerodynamics(
            elliptic(ar), n_chordwise=n_chordwise, section_lift_slope_per_rad=a0
        )
        # at AR 100 the lifting-surface correction is < 0.1 % (measured 0.08–0.09 %)
        assert aero.wing_lift_slope_per_rad == pytest.approx(
            lifting_line_elliptic(ar, a0), rel=0.003
        )
        clp_theory = -(a0 / 8.0) / (1.0 + 2.0 * a0 / (math.pi * ar))
        # antisymmetric loading has a larger tip correction: measured 0.21–0.25 %
        assert aero.roll_damping_clp() == pytest.approx(clp_theory, rel=0.005)


def test_elliptic_roll_damping_tends_to_lifting_line_theory():
    gaps = []
    for ar in (12.0, 50.0, 100.0):
        aero = ll.solve_spanwise_aerodynamics(elliptic(ar))
        theory = -(math.pi / 4.0) * ar / (ar + 4.0)
        gaps.append(1.0 - aero.roll_damping_clp() / theory)
        print(f"\nAR {ar:.0f}: C_lp = {aero.roll_damping_clp():.4f}, lifting line {theory:.4f}")
    assert np.all(np.diff(gaps) < 0.0) and min(gaps) > 0.0
    assert gaps[1] < 0.01  # AR 50 (measured 0.73 %)


# --------------------------------------------------------------------------------------
# (b) rectangular wings: the 2-D limit
# --------------------------------------------------------------------------------------


def test_rectangular_wing_tends_to_two_pi():
    slopes = []
    for ar in (20.0, 50.0, 100.0, 200.0, 2000.0):
        aero = ll.solve_spanwise_aerodynamics(rectangular(ar))
        slopes.append(aero.wing_lift_slope_per_rad)
        print(f"\nrectangular AR {ar:5.0f}: C_Lα/2π = {aero.wing_lift_slope_per_rad / TWO_PI:.4f}")
        if 50.0 <= ar <= 200.0:
            # Helmbold is an elliptic-wing formula; a rectangular wing carries less lift
            # (tip loss): measured 2.6 %, 1.6 %, 1.0 % below it
            assert aero.wing_lift_slope_per_rad == pytest.approx(helmbold(ar), rel=0.03)
    assert np.all(np.diff(slopes) > 0.0)
    # AR 2000: rectangular-wing tip loss decays like ln(AR)/AR; measured 0.26 % below 2π
    assert slopes[-1] == pytest.approx(TWO_PI, rel=0.005)
    assert slopes[-1] < TWO_PI


# --------------------------------------------------------------------------------------
# (c) convergence
# --------------------------------------------------------------------------------------


def test_default_planform_converges_with_panel_count():
    spanwise = [
        ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_spanwise=n, n_chordwise=4)
        for n in (20, 40, 80, 160)
    ]
    slopes = np.array([a.wing_lift_slope_per_rad for a in spanwise])
    acs = np.array([a.wing_ac_x_m for a in spanwise])
    steps = np.abs(np.diff(slopes))
    assert np.all(np.diff(steps) < 0.0)  # successive refinements change less and less
    default = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    assert default.wing_lift_slope_per_rad == slopes[1]  # default is n = 40, 4 chordwise
    # 0.2 %: measured 0.06 % between 40 and 160 strips (the kink converges like 1/n)
    assert slopes[1] == pytest.approx(slopes[-1], rel=0.002)
    # AC within 0.1 % of the chord (measured 0.02 %)
    assert abs(acs[1] - acs[-1]) < 0.001 * DEFAULT_PLANFORM.chord_m

    chordwise = [ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_chordwise=m)
                 for m in (1, 2, 4, 8)]
    c_slopes = np.array([a.wing_lift_slope_per_rad for a in chordwise])
    # 4 → 8 chordwise panels: measured 0.06 %; 1 panel (Weissinger) is 0.5 % low
    assert c_slopes[2] == pytest.approx(c_slopes[3], rel=0.002)
    assert abs(chordwise[2].wing_ac_x_m - chordwise[3].wing_ac_x_m) < 0.002 * (
        DEFAULT_PLANFORM.chord_m
    )


# --------------------------------------------------------------------------------------
# (d) the default planform
# --------------------------------------------------------------------------------------


def test_default_planform_numbers_are_plausible():
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    c = DEFAULT_PLANFORM.chord_m
    s = DEFAULT_PLANFORM.semispan_m
    print(
        f"\ndefault planform: AR {aero.aspect_ratio:.3f}, S {aero.reference_area_m2:.4f} m², "
        f"C_Lα {aero.wing_lift_slope_per_rad:.4f} /rad, x_ac {aero.wing_ac_x_m:.5f} m "
        f"= {aero.wing_ac_x_m / c:.4f} c, C_lp {aero.roll_damping_clp():.4f}"
    )
    for frac in (0.0, 0.25, 0.45, 0.6, 0.8, 0.95):
        clac = np.interp(frac * s, aero.stations_m, aero.cl_alpha_c_m_per_rad)
        xac = np.interp(frac * s, aero.stations_m, aero.x_ac_m)
        print(f"  y/(b/2) = {frac:4.2f}: C_lα c = {clac:.4f} m/rad, x_ac = {xac:.4f} m")
    assert aero.reference_area_m2 == pytest.approx(DEFAULT_PLANFORM.area_m2, rel=1e-12)
    unswept = ll.solve_spanwise_aerodynamics(
        dataclasses.replace(DEFAULT_PLANFORM, outer_sweep_rad=0.0)
    )
    # Lift slope: below the unswept wing of the same AR (sweep lowers the normal-velocity
    # component that counts, ~cos Λ on the outer half) and above that wing times cos 20°.
    assert (
        unswept.wing_lift_slope_per_rad * math.cos(math.radians(20.0))
        < aero.wing_lift_slope_per_rad
        < unswept.wing_lift_slope_per_rad
    )
    # A lifting surface of AR 9.29 lies below lifting-line 2πAR/(AR+2) = 5.17 /rad
    # (the elliptic gap at AR 8-10 is 3.4-4.7 %; this wing is not elliptic): 4.5-5.1 /rad.
    assert 4.5 < aero.wing_lift_slope_per_rad < 5.1
    # Unswept, the AC is at the quarter chord (within 1 % c: tip loading slightly forward);
    # the swept outer panel moves it aft, here by about 0.2 c.
    assert unswept.wing_ac_x_m == pytest.approx(0.25 * c, abs=0.01 * c)
    assert aero.wing_ac_x_m > 0.25 * c + 0.1 * c
    # The AC is the lift-weighted mean of the local AC line; local centres of pressure
    # differ from the quarter-chord line by a few % c only (measured: 0.5 % c on the wing).
    lift_weight = aero.weights_m * aero.cl_alpha_c_m_per_rad
    assert aero.wing_ac_x_m == pytest.approx(
        np.sum(lift_weight * aero.x_ac_m) / np.sum(lift_weight), abs=1e-12
    )
    x_qc_mean = np.sum(lift_weight * aero.x_quarter_chord_m) / np.sum(lift_weight)
    assert abs(aero.wing_ac_x_m - x_qc_mean) < 0.02 * c
    # the roll damping of a wing of AR 9.3 is ≈ −(π/4)·AR/(AR+4) (lifting line, elliptic)
    # less a lifting-surface correction: −0.55 .. −0.50 ... (measured −0.54)
    assert -0.60 < aero.roll_damping_clp() < -0.50


def test_default_lattice_has_a_node_on_the_kink_and_consistent_weights():
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    assert DEFAULT_PLANFORM.outer_panel_start_m in aero.edges_m
    s = DEFAULT_PLANFORM.semispan_m
    assert np.sum(aero.weights_m) == pytest.approx(s, rel=1e-14)
    assert np.all((aero.stations_m > aero.edges_m[:-1]) & (aero.stations_m < aero.edges_m[1:]))
    # ∫_0^s y² dy = s³/3 by the station quadrature: second-order rule, 40 strips: ~1e-3
    assert np.sum(aero.weights_m * aero.stations_m**2) == pytest.approx(s**3 / 3.0, rel=2e-3)
    assert np.sum(aero.weights_m * aero.chord_m) == pytest.approx(0.5 * aero.reference_area_m2)


# --------------------------------------------------------------------------------------
# (e) influence matrices
# --------------------------------------------------------------------------------------


def _full_span_strip_loads(planform, alpha_starboard, antisymmetric, n_spanwise=24, n_chord=3):
    """Both halves as explicit unknowns, no mirror images: starboard l'/q and l'·x/q."""
    r = ll.control_point_fraction(TWO_PI)
    edges = ll.spanwise_nodes(planform, n_spanwise)
    lat = ll.build_lattice(planform, edges, n_chord, r, "cosine")[0]
    m = np.array([1.0, -1.0, 1.0])
    a = np.vstack([lat.a_m, lat.b_m * m])  # port panels: bound segment still along +y
    b = np.vstack([lat.b_m, lat.a_m * m])
    ctrl = np.vstack([lat.control_m, lat.control_m * m])
    sign = -1.0 if antisymmetric else 1.0
    alpha_panels = np.concatenate(
        [alpha_starboard[lat.strip_index], sign * alpha_starboard[lat.strip_index]]
    )
    gamma = np.linalg.solve(ll.horseshoe_normalwash(ctrl, a, b), -alpha_panels)
    g_star = gamma[: lat.strip_index.size]
    x_mid = 0.5 * (lat.a_m[:, 0] + lat.b_m[:, 0])
    lift = 2.0 * np.bincount(lat.strip_index, weights=g_star)
    lift_x = 2.0 * np.bincount(lat.strip_index, weights=g_star * x_mid)
    return lift, lift_x


@pytest.mark.parametrize("antisymmetric", [False, True])
def test_influence_matrices_match_a_full_span_solution(antisymmetric):
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_spanwise=24, n_chordwise=3)
    rng = np.random.default_rng(11)
    alpha = rng.normal(size=aero.stations_m.size) * 0.05
    lift, lift_x = _full_span_strip_loads(DEFAULT_PLANFORM, alpha, antisymmetric)
    got = aero.lift_per_span_for_alpha(alpha, antisymmetric=antisymmetric)
    # same equations, different linear system (2× size, no images): round-off, ~1e-13
    assert np.allclose(got, lift, rtol=1e-9, atol=1e-12)
    x_cp = aero.centre_of_pressure_x_for_alpha(alpha, antisymmetric=antisymmetric)
    assert np.allclose(x_cp, lift_x / lift, rtol=1e-9, atol=1e-12)


def test_uniform_alpha_through_the_influence_matrix_reproduces_the_strips():
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    ones = np.ones_like(aero.stations_m)
    assert np.allclose(aero.lift_per_span_for_alpha(ones), aero.cl_alpha_c_m_per_rad, rtol=1e-12)
    assert np.allclose(aero.centre_of_pressure_x_for_alpha(ones), aero.x_ac_m, rtol=1e-12)
    # Weissinger (1 chordwise panel): the load sits on the quarter-chord line, so the local
    # AC equals the quarter-chord point up to the sweep times the offset between the strip
    # centroid and its station (< 0.05 % c here)
    w1 = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_chordwise=1)
    assert np.allclose(w1.x_ac_m, w1.x_quarter_chord_m, atol=5e-4 * DEFAULT_PLANFORM.chord_m)
    # strip theory would give 2π c = 1.150 m/rad everywhere; the lattice is below it
    assert np.all(aero.cl_alpha_c_m_per_rad < TWO_PI * DEFAULT_PLANFORM.chord_m)


def test_twist_loads_are_not_strip_theory():
    """A linear washout loads the wing differently from strip theory, but lift is linear."""
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    y = aero.stations_m
    twist = -0.05 * y / aero.semispan_m  # tip 0.05 rad nose down [rad]
    lift = aero.lift_per_span_for_alpha(twist)
    strip = aero.cl_alpha_c_m_per_rad * twist
    assert np.sum(aero.weights_m * lift) < 0.0
    assert not np.allclose(lift, strip, rtol=0.05)
    both = aero.lift_per_span_for_alpha(twist + 0.1)
    assert np.allclose(both, lift + 0.1 * aero.cl_alpha_c_m_per_rad, rtol=1e-12, atol=1e-15)


def test_bad_inputs_are_rejected():
    aero = ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_spanwise=10, n_chordwise=1)
    with pytest.raises(ValueError):
        aero.lift_per_span_for_alpha(np.ones(9))
    with pytest.raises(ValueError):
        ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, section_lift_slope_per_rad=-1.0)
    with pytest.raises(ValueError):
        ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, spacing="random")
    with pytest.raises(ValueError):
        ll.solve_spanwise_aerodynamics(DEFAULT_PLANFORM, n_chordwise=0)
