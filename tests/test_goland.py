"""The Goland wing as a clamped cantilever: natural frequencies, divergence and flutter
against the published strip-theory solution (bioflex_jsb.parameters.goland for sources)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aeroelasticity import goland_flutter
from bioflex_jsb.aeroelasticity.clamped_wing import clamped_wing_model, goland_sections
from bioflex_jsb.aeroelasticity.flutter import divergence_speed_m_s
from bioflex_jsb.aeroelasticity.pk import pk_flutter
from bioflex_jsb.aeroelasticity.strip_aero import (
    finite_state_model,
    generalised_aero_matrix,
    modal_strip_matrices,
)
from bioflex_jsb.parameters import goland as G
from bioflex_jsb.structures.beam import solve_beam


@pytest.fixture(scope="module")
def strip_model():
    return clamped_wing_model(goland_sections())


@pytest.fixture(scope="module")
def pk_unsteady():
    return goland_flutter(aero="unsteady", lift_slope="strip", method="pk")


def test_uncoupled_bending_frequency_is_exact():
    # Without inertial coupling (x_I = x_E) the first bending frequency of the clamped
    # beam is 1.8751² √(EI/(m L⁴)) (Euler-Bernoulli); Hermite elements converge as h⁴:
    # tolerance 1e-5 relative.
    from dataclasses import replace

    sec = goland_sections()
    sec = replace(sec, x_inertial_frac=np.full(2, G.X_ELASTIC_FRAC))
    exact = 1.8751040687**2 * math.sqrt(
        G.BENDING_STIFFNESS_N_M2 / (G.MASS_PER_LENGTH_KG_M * G.SEMISPAN_M**4))
    assert solve_beam(sec, 1).frequencies_rad_s[0] == pytest.approx(exact, rel=1e-5)


def test_natural_frequencies_vs_published(strip_model):
    # Published 49.5, 97.0, 248.9 rad/s (Patil, Hodges & Cesnik 2001). Measured with the
    # elastic-axis reading of the inertia: 48.15, 95.71, 243.84 (−2.7, −1.3, −2.0 %). The
    # beam is converged (40 elements; the frequencies move < 0.04 % to 80 elements), so
    # the gap is in the data, not the discretisation: tolerance 3 %, what the published
    # data support (see goland.py, DECISION on the inertia's axis).
    got = strip_model.natural_frequencies_rad_s[:3]
    for w, ref in zip(got, G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S, strict=True):
        assert w == pytest.approx(ref, rel=0.03)
    # the centre-of-mass reading misses the torsion frequency by 8 %: it is the worse one
    com = clamped_wing_model(goland_sections(inertia_about="centre-of-mass"), n_modes=3)
    err_com = abs(com.natural_frequencies_rad_s[1] / G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S[1]
                  - 1.0)
    err_ea = abs(got[1] / G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S[1] - 1.0)
    assert err_com > 4.0 * err_ea


def test_divergence_speed_closed_form(strip_model):
    # Steady strip loads of an unswept wing do not couple bending: divergence is that of a
    # uniform torsion rod, q_D = GJ (π/2L)² / (c a₀ e), e = (x_E − ¼)c (BAH 1955, Ch. 8).
    # Linear torsion elements: eigenvalue error ≈ (π/2/40)²/12 ≈ 1.3e-4; tolerance 1e-3.
    e = (G.X_ELASTIC_FRAC - 0.25) * G.CHORD_M
    q_d = G.TORSIONAL_STIFFNESS_N_M2 * (math.pi / (2 * G.SEMISPAN_M)) ** 2 / (
        G.CHORD_M * TWO_PI * e)
    v_d = math.sqrt(2.0 * q_d / G.FLUTTER_DENSITY_KG_M3)
    assert divergence_speed_m_s(strip_model, G.FLUTTER_DENSITY_KG_M3) == pytest.approx(
        v_d, rel=1e-3)


def test_flutter_pk_unsteady_vs_published(pk_unsteady):
    # Goland (1945) exact strip-theory flutter, 137.2 m/s and 70.7 rad/s (as tabulated by
    # Patil, Hodges & Cesnik 2001). Measured: 136.96 m/s (−0.2 %), 70.02 rad/s (−1.0 %).
    # Tolerance 1 % on the speed (the "within a few per cent" of the issue, tightened to what
    # the converged model gives) and 2 % on the frequency (the published natural
    # frequencies themselves sit 1-3 % above what the published data give, test above).
    r = pk_unsteady
    assert r.speed_m_s == pytest.approx(G.PUBLISHED_FLUTTER_SPEED_M_S, rel=0.01)
    assert r.frequency_rad_s == pytest.approx(G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S, rel=0.02)
    # Classical bending-torsion flutter: the torsion branch closes on the bending one and
    # flutters first, far below divergence.
    assert r.mechanism == "coalescence"
    assert {r.mode, r.partner_mode} == {"mode 1 (bending)", "mode 2 (torsion)"}
    assert r.divergence_speed_m_s > 1.5 * r.speed_m_s


def test_flutter_state_space_agrees_with_pk(pk_unsteady):
    # The finite-state (Jones) eigen-analysis against the p-k on the exact C(k): Jones's
    # C(k) is within 0.015 of the exact one (test_unsteady_aero.py), which moves the flutter
    # point: measured +0.28 % in speed, −1.0 % in frequency. Tolerances 0.5 % and 1.5 %.
    r = goland_flutter(aero="unsteady", lift_slope="strip", method="state-space")
    assert r.speed_m_s == pytest.approx(pk_unsteady.speed_m_s, rel=0.005)
    assert r.frequency_rad_s == pytest.approx(pk_unsteady.frequency_rad_s, rel=0.015)
    assert r.mechanism == "coalescence"


def test_issue_reading_of_the_data(strip_model):
    # The issue's wording (8.64 kg·m about the centre of mass, ρ = 1.02 kg/m³) also gives
    # the published flutter speed: measured 137.29 m/s (+0.1 %), tolerance 1 % as above;
    # its frequency, 68.19 rad/s, is 3.5 % low (tolerance 4 %, recorded, not endorsed: see
    # goland.py).
    r = goland_flutter(inertia_about="centre-of-mass", density_kg_m3=G.AIR_DENSITY_KG_M3)
    assert r.speed_m_s == pytest.approx(G.PUBLISHED_FLUTTER_SPEED_M_S, rel=0.01)
    assert r.frequency_rad_s == pytest.approx(G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S, rel=0.04)


def test_quasi_steady_flutters_early_single_mode(pk_unsteady):
    # With C = 1 the torsion mode's aerodynamic damping is far too small (it vanishes for an
    # axis at mid-chord): the wing flutters in torsion alone at about half the speed
    # (measured 64.53 m/s, 87.70 rad/s). Same equations in both methods (no lag states):
    # p-k and eigen-analysis agree to the root-finding tolerance, 1e-6 relative.
    qs = goland_flutter(aero="quasi-steady", method="pk")
    qs_ss = goland_flutter(aero="quasi-steady", method="state-space")
    assert qs.speed_m_s < 0.6 * pk_unsteady.speed_m_s
    assert qs.mechanism == "single-mode" and qs.mode == "mode 2 (torsion)"
    assert qs_ss.speed_m_s == pytest.approx(qs.speed_m_s, rel=1e-6)


def test_finite_state_gaf_matches_jones_frequency_domain(strip_model):
    # The modal finite-state model's frequency response equals the frequency-domain
    # generalised forces with Jones's C(k) on every strip: same algebra, 1e-9 relative.
    v, rho = 120.0, G.FLUTTER_DENSITY_KG_M3
    fs = finite_state_model(strip_model, speed_m_s=v, density_kg_m3=rho)
    mats = modal_strip_matrices(strip_model, speed_m_s=v, density_kg_m3=rho)
    for w in (10.0, 70.0):
        ref = generalised_aero_matrix(mats, w, jones=True)
        assert np.max(np.abs(fs.force_matrix(w) - ref)) < 1e-9 * np.max(np.abs(ref))
    assert fs.state_names[0] == "wagner_lag_1_m[0]" and set(fs.state_units) == {"m"}


def test_vlm_span_loading_raises_flutter_speed(pk_unsteady):
    # The vortex lattice's span loading (aspect ratio 6.7: C_lα falls from ≈ 5 at the root
    # to 0 at the tip) unloads the outer wing, where the modes move most, so flutter moves
    # up: measured 182.9 m/s, 62.8 rad/s (p-k). No published strip-with-VLM-slope value
    # exists to compare with; 3-D unsteady vortex-lattice solutions of the same wing lie
    # at 163-169 m/s (secondary literature), also well above strip theory. Recorded here:
    # higher than strip theory by 20-40 %, still a coalescence.
    model = clamped_wing_model(goland_sections(), lift_slope="vlm", n_modes=4)
    assert model.lift_slope_per_rad.max() < TWO_PI
    r = pk_flutter(model, density_kg_m3=G.FLUTTER_DENSITY_KG_M3, speed_range_m_s=(120, 260),
                   speed_step_m_s=4.0)
    assert 1.2 < r.speed_m_s / pk_unsteady.speed_m_s < 1.4
    assert r.mechanism == "coalescence"


def _hale_model():
    # Patil, Hodges & Cesnik (2001) HALE wing (docs/aircraft.md): EA = CG at mid-chord
    from bioflex_jsb.aeroelasticity.clamped_wing import clamped_wing_model
    from bioflex_jsb.structures.beam import uniform_sections

    return clamped_wing_model(uniform_sections(
        16.0, bending_stiffness_n_m2=2e4, torsional_stiffness_n_m2=1e4,
        mass_per_length_kg_m=0.75, torsional_inertia_kg_m=0.1, chord_m=1.0,
        x_elastic_frac=0.5, x_inertial_frac=0.5))


@pytest.mark.parametrize("method", ["pk", "state-space"])
def test_unstable_at_every_speed_is_reported_by_both_methods(method):
    # Quasi-steady strips on the HALE wing (elastic axis at mid-chord): the torsion root is
    # unstable from the lowest speed on. Before the one engine p-k said "static divergence"
    # at 37.16 m/s and state space "no instability"; both must say: unstable at the lower
    # end, in torsion, oscillatory.
    from bioflex_jsb.aeroelasticity.flutter import clamped_flutter

    r = clamped_flutter(_hale_model(), method=method, aero="quasi-steady",
                        density_kg_m3=0.0889, speed_range_m_s=(3.0, 56.0))
    # no speed: the lower end is not an onset (a script reading the speed took it for one)
    assert r.present_at_lower_end and r.speed_m_s is None and r.unstable_at_and_below_m_s == 3.0
    assert r.mode == "mode 3 (torsion)" and r.kind == "flutter" and r.frequency_rad_s > 25.0
    assert r.quasi_steady_artefact and "no aerodynamic pitch damping" in r.caveat


@pytest.mark.parametrize("method", ["pk", "state-space"])
def test_crossing_below_the_range_is_present_at_lower_end(method):
    # Goland flutters at 136.96 m/s (p-k); a range from 140 m/s returned no flutter.
    r = goland_flutter(method=method, speed_range_m_s=(140.0, 260.0))
    assert r.present_at_lower_end and r.speed_m_s is None and r.mode == "mode 2 (torsion)"
    assert r.unstable_at_and_below_m_s == 140.0


def test_divergence_in_range_is_the_first_instability():
    # a divergence of the clamped system inside the range, with no dynamic crossing before
    # it, is reported as the instability (never "no instability" beside it): the Goland wing
    # with its flutter damped out by ζ = 0.3 (measured: no dynamic crossing below 252.3 m/s)
    r = goland_flutter(structural_damping=0.3, speed_range_m_s=(200.0, 300.0))
    assert r.mechanism == "static divergence" and r.kind == "divergence"
    assert r.speed_m_s == pytest.approx(r.divergence_speed_m_s) == pytest.approx(252.30,
                                                                                abs=0.01)
