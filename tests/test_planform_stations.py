"""Planforms linear between span stations (parameters/wing.py ``Planform.from_stations``):
tapered, multi-panel and dihedral wings in the vortex lattice and the Table B1 strips,
against published and closed-form results (docs/aerodynamics.md, "Tapered wings and
dihedral"). ``pytest -s`` prints the figures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.aerodynamics.vortex_lattice import solve_spanwise_aerodynamics
from bioflex_jsb.flight_dynamics.modal_coefficients import modal_coefficients, spanwise_geometry
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM, Planform
from bioflex_jsb.structures.modal_data import ModalData


def _tapered(semispan, root, tip, x_cg=0.0, sweep_le_rad=None, dihedral_rad=0.0):
    """A straight-tapered wing; quarter-chord line unswept unless a LE sweep is given."""
    x_tip = (0.25 * (root - tip) if sweep_le_rad is None
             else semispan * math.tan(sweep_le_rad))
    return Planform.from_stations([0.0, semispan], [root, tip], [0.0, x_tip],
                                  [0.0, semispan * math.tan(dihedral_rad)], x_cg)


def test_warren_12_against_its_published_lifting_surface_values():
    # The Warren-12 planform (AR 2√2, taper 1/3, leading edge swept 53.54°, root chord
    # 1.5, semispan √2, c̄ = 1): the classic check of lifting-surface methods, with
    # C_Lα = 2.743 /rad and C_mα = -3.10 /rad about the apex on c̄ (Garner, Hewitt &
    # Labrujere, ARC R&M 3597, 1968; the values the VLM checks of OpenVSP's VSPAERO and of
    # FLOWVLM compare with). Measured with the default 40 x 4 lattice: 2.7415 (-0.06 %),
    # -3.082 (-0.6 %); 160 x 8: 2.7450 (+0.07 %), -3.095 (-0.2 %). Bars 0.5 % and 1.5 %:
    # above the lattice's own spread with refinement (0.14 %, 0.4 %).
    s = math.sqrt(2.0)
    pf = _tapered(s, 1.5, 0.5, sweep_le_rad=math.radians(53.54))
    aero = solve_spanwise_aerodynamics(pf)
    assert aero.reference_area_m2 == pytest.approx(2.0 * s, rel=1e-12)
    cla = aero.wing_lift_slope_per_rad
    cma = -cla * aero.wing_ac_x_m / 1.0  # about the apex (root leading edge), c̄ = 1
    print(f"Warren-12: C_La {cla:.4f} /rad (published 2.743), C_ma {cma:.4f} (-3.10)")
    assert cla == pytest.approx(2.743, rel=5e-3)
    assert cma == pytest.approx(-3.10, rel=1.5e-2)


def _lifting_line_slope(semispan, root, tip, a0=2.0 * math.pi, n=81):
    """C_Lα [1/rad] of Prandtl's lifting line for a straight-tapered wing (Glauert's odd
    sine series, n terms, collocation at the half-span's n interior points)."""
    b = 2.0 * semispan
    th = (np.arange(1, n + 1) - 0.5) * (0.5 * math.pi) / n
    c = root + (tip - root) * np.cos(th)
    mu = a0 * c / (4.0 * b)
    k = 2 * np.arange(n) + 1
    a = np.sin(np.outer(th, k)) * (mu[:, None] * k[None, :] + np.sin(th)[:, None])
    coeffs = np.linalg.solve(a, mu * np.sin(th))
    aspect = b * b / ((root + tip) * semispan)
    return math.pi * aspect * coeffs[0]


@pytest.mark.parametrize("taper", [0.5, 0.3])
def test_taper_against_lifting_line_at_high_aspect_ratio(taper):
    # At AR 50 lifting-line theory is the lattice's limit within the lifting-surface tip
    # correction (the elliptic wing's gap there is 0.28 %, the rectangular wing's 0.78 %:
    # docs/aerodynamics.md). Measured: taper 0.5 -0.48 %, 0.3 -0.38 %; bar 0.6 %. The
    # taper's own effect, C_Lα(λ)/C_Lα(1), against lifting line's: measured 0.30 % and
    # 0.40 % apart (the rectangular tip's larger correction); bar 0.5 %. A chord read
    # constant would give a ratio of 1 against lifting line's 1.012 and 1.015.
    semispan, aspect = 1.0, 50.0

    def slopes(lam):
        root = 4.0 * semispan / (aspect * (1.0 + lam))
        lattice = solve_spanwise_aerodynamics(_tapered(semispan, root, lam * root))
        return lattice.wing_lift_slope_per_rad, _lifting_line_slope(semispan, root, lam * root)

    vlm, ll = slopes(taper)
    vlm_1, ll_1 = slopes(1.0)
    print(f"taper {taper}: lattice {vlm:.4f}, lifting line {ll:.4f} ({vlm / ll - 1:+.3%}); "
          f"taper effect {vlm / vlm_1:.5f} vs {ll / ll_1:.5f}")
    assert vlm == pytest.approx(ll, rel=6e-3)
    assert vlm / vlm_1 == pytest.approx(ll / ll_1, rel=5e-3)
    assert ll / ll_1 > 1.01  # the check has something to see


def test_multi_panel_wing_has_a_strip_edge_on_its_kink_and_is_between_its_panels():
    # a constant-chord inner panel and a tapered outer one (a C172's planform): the kink is
    # a break of the lattice, and its lift slope lies between those of the rectangular
    # wing and the straight taper of the same span and tip chord
    s, c, tip, kink = 5.5, 1.6, 1.1, 2.5
    pf = Planform.from_stations([0.0, kink, s], [c, c, tip], [0.0, 0.0, 0.125 * (c - tip)],
                                [0.0, 0.0, 0.0], 0.4)
    assert pf.breaks_m == (kink,)
    aero = solve_spanwise_aerodynamics(pf)
    assert np.any(np.isclose(aero.edges_m, kink, rtol=0.0, atol=1e-12))
    assert aero.reference_area_m2 == pytest.approx(pf.area_m2, rel=1e-12)
    assert aero.reference_area_m2 == pytest.approx(2 * (c * kink + 0.5 * (c + tip) * (s - kink)))
    # chords at the control points are the linear interpolation of the stations
    assert np.allclose(aero.chord_m, np.interp(aero.stations_m, [0, kink, s], [c, c, tip]),
                       rtol=0, atol=1e-14)
    # a station on a straight line is not a kink
    straight = Planform.from_stations([0.0, 2.0, 4.0], [2.0, 1.5, 1.0], [0.0, 0.1, 0.2],
                                      [0.0, 0.0, 0.0], 0.0)
    assert straight.breaks_m == ()


def test_station_form_of_the_prototype_planform_is_the_constant_chord_form():
    p = DEFAULT_PLANFORM
    x_tip = (p.semispan_m - p.outer_panel_start_m) * math.tan(p.outer_sweep_rad)
    st = Planform.from_stations([0.0, p.outer_panel_start_m, p.semispan_m], [p.chord_m] * 3,
                                [0.0, 0.0, x_tip], [0.0] * 3, p.x_cg_m)
    assert st.breaks_m == (p.outer_panel_start_m,)
    a, b = solve_spanwise_aerodynamics(p), solve_spanwise_aerodynamics(st)
    # the same lattice: equal to round-off (measured 0)
    assert b.wing_lift_slope_per_rad == pytest.approx(a.wing_lift_slope_per_rad, rel=1e-13)
    assert np.allclose(b.influence_m, a.influence_m, rtol=1e-12, atol=0.0)
    assert np.allclose(b.x_ac_m, a.x_ac_m, rtol=1e-12, atol=0.0)


def test_strip_integrals_of_a_tapered_wing_against_closed_forms():
    # Table B1's strip sums on a linearly tapered wing, c(y) = c_r + (c_t - c_r) y/s, for a
    # uniform twist θ = 1 and a linear one θ = y/s:
    #   C_mac^Q ∝ ∫ θ c² dy: s (c_r² + c_r c_t + c_t²)/3 and s (c_r²/2 + 2 c_r Δ/3 + Δ²/4);
    #   Σ w c = s (c_r + c_t)/2; C_Lη of θ = 1 is the lattice's own C_Lα (on its area).
    # The strips' chords sit at the control points (cosine placement), a second-order rule:
    # measured 1.9e-4, 3.3e-4 and 8.3e-5 with 40 strips, a quarter of that with 80; bar 5e-4.
    s, cr, ct = 5.0, 1.6, 0.64
    d = ct - cr
    y = np.linspace(0.0, s, 11)
    modes = ModalData(frequencies_rad_s=[10.0, 20.0], damping_ratios=[0.0, 0.0],
                      generalised_masses_kg_m2=[1.0, 1.0], stations_m=y,
                      bending_m=np.zeros((2, 11)), twist_rad=np.vstack([np.ones(11), y / s]),
                      x_elastic_frac=np.full(11, 0.4), x_inertial_frac=np.full(11, 0.4),
                      source="uniform and linear twist")
    errors = {}
    for n in (40, 80):
        pf = _tapered(s, cr, ct, x_cg=0.3)
        aero = solve_spanwise_aerodynamics(pf, n_spanwise=n)
        strips = spanwise_geometry(aero, pf, modes.x_elastic_frac, modes.stations_m)
        area, cbar = pf.area_m2, pf.chord_m
        assert cbar == pytest.approx(0.5 * (cr + ct), rel=1e-15)  # S/b of the taper
        c = modal_coefficients(modes, strips, reference_area_m2=area, cbar_m=cbar)
        closed = np.array([s * (cr * cr + cr * ct + ct * ct) / 3.0,
                           s * (cr * cr / 2.0 + 2.0 * cr * d / 3.0 + d * d / 4.0)])
        errors[n] = np.concatenate([
            c.c_mac_q / (2.0 * closed / (area * cbar)) - 1.0,
            [np.sum(strips.weights_m * strips.chord_m) / (0.5 * (cr + ct) * s) - 1.0]])
        assert c.c_l_eta[0] * area / aero.reference_area_m2 == pytest.approx(
            aero.wing_lift_slope_per_rad, rel=1e-12)
        # e(y) and d(y) on the tapered line: x_E = x_le + 0.4 c, d = x_cg - x_ac
        x_le = pf.leading_edge_x_at(strips.stations_m)
        assert np.allclose(strips.e_m, x_le + 0.4 * strips.chord_m - aero.x_ac_m, atol=1e-15)
        assert np.allclose(strips.d_m, 0.3 - aero.x_ac_m, atol=1e-15)
    print("strip integral errors, 40 and 80 strips:", errors[40], errors[80])
    assert np.all(np.abs(errors[40]) < 5e-4)
    assert np.all(np.abs(errors[80]) < 0.3 * np.abs(errors[40]))  # second order


def test_dihedral_lowers_the_lift_slope_as_cos_gamma_in_the_two_dimensional_limit():
    # A dihedral strip sees a body angle of attack α as α cos Γ in its own plane, and its
    # vertical lift per unit y is ρVΓ: on slender strips C_Lα ∝ cos Γ (not cos² Γ, which
    # counts the panel's length along its slope as well). At AR 100 the induced correction
    # of the difference, a_0 (1 - cos Γ)/(π AR), is 3e-4 at 10°: measured ratio 0.98544
    # against cos 10° = 0.98481 (+6.4e-4; cos² 10° = 0.96985); bar 1e-3. At AR 10, 5°:
    # 0.99759 (a small angle changes the lift slope by O(Γ²)).
    s = 50.0
    flat = solve_spanwise_aerodynamics(_tapered(s, 1.0, 1.0))
    ten = solve_spanwise_aerodynamics(_tapered(s, 1.0, 1.0, dihedral_rad=math.radians(10)))
    ratio = ten.wing_lift_slope_per_rad / flat.wing_lift_slope_per_rad
    print(f"dihedral 10 deg, AR 100: C_La ratio {ratio:.5f}, cos {math.cos(math.radians(10)):.5f}")
    assert ratio == pytest.approx(math.cos(math.radians(10.0)), rel=1e-3)
    assert ten.cos_dihedral == pytest.approx(math.cos(math.radians(10.0)), rel=1e-14)
    assert flat.cos_dihedral is None
    small = solve_spanwise_aerodynamics(_tapered(5.0, 1.0, 1.0, dihedral_rad=math.radians(5)))
    base = solve_spanwise_aerodynamics(_tapered(5.0, 1.0, 1.0))
    assert abs(small.wing_lift_slope_per_rad / base.wing_lift_slope_per_rad - 1.0) < 0.004


def test_dihedral_symmetry_image_against_the_full_span_lattice():
    # the port half as the image of the starboard one, with dihedral: the same circulation
    # as an explicit lattice of both halves (each with its own normals)
    from bioflex_jsb.aerodynamics import vortex_lattice as ll

    pf = _tapered(3.0, 1.0, 0.6, dihedral_rad=math.radians(8.0))
    aero = solve_spanwise_aerodynamics(pf, n_spanwise=12, n_chordwise=2)
    edges = ll.spanwise_nodes(pf, 12)
    lat = ll.build_lattice(pf, edges, 2, ll.control_point_fraction(ll.TWO_PI), "cosine")[0]
    normals = ll._strip_normals(pf, edges)[lat.strip_index]
    mirror = np.array([1.0, -1.0, 1.0])
    a = np.vstack([lat.a_m, lat.b_m * mirror])
    b = np.vstack([lat.b_m, lat.a_m * mirror])
    ctrl = np.vstack([lat.control_m, lat.control_m * mirror])
    n_all = np.vstack([normals, normals * mirror])
    w = np.sum(ll._horseshoe_velocity(ctrl, a, b) * n_all[:, None, :], axis=-1)
    cos_g = n_all[:, 2]
    gamma = np.linalg.solve(w, -cos_g)  # uniform body α = 1 rad, V = 1
    half = gamma[: lat.a_m.shape[0]]
    lift = 2.0 * np.bincount(lat.strip_index, weights=half)
    assert np.allclose(lift, aero.cl_alpha_c_m_per_rad, rtol=1e-10, atol=0.0)
