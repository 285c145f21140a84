"""Gusts that vary over the aircraft: the specification, the field's spanwise decomposition
against strip-theory closed forms, and MIL-F-8785C's rolling-turbulence spectrum."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from bioflex_jsb.errors import InputError
from bioflex_jsb.parameters.airframe import RIGID_AERODYNAMICS
from bioflex_jsb.simulation.gusts import GustField, GustSpecError, check_gust_resolution, parse_gust
from bioflex_jsb.simulation.spanwise_gusts import (
    SpanStations,
    SpanwiseGustField,
    TailGust,
    gust_field,
    rectangular_rolling_moment_n_m,
    rolling_psd,
    rolling_variance,
)

B, C, A = 1.7, 0.183, 5.3  # the prototype's span, chord [m] (Table 1), C_Lα [1/rad]
V, Q = 15.0, 0.5 * 1.225 * 15.0**2  # [m/s], [Pa]
TAIL = TailGust(0.47, 0.36)


@pytest.mark.parametrize("text", [
    "1cos:3:20+roll:0.5:15+lateral:dryden:1:50:3+tail", "dryden:1:50:0+pg+tail",
    "sharp:3+front:30", "none+roll:1:20", "1cos:3:20+lateral:1cos:2:10+front:-20"])
def test_spec_round_trips(text):
    assert parse_gust(parse_gust(text).text()) == parse_gust(text)
    assert parse_gust(text).text() == text


@pytest.mark.parametrize("text, says", [
    ("1cos:3:20+front:90", "<= 80 deg"), ("1cos:3:20+pg", "pg is the rolling part"),
    ("dryden:1:50+front:10", "front needs a sharp or 1cos"), ("1cos:3:20+tail+tail", "twice"),
    ("none+lateral:none", "lateral takes one of"), ("none+tail", "there is none"),
    ("sharp:3+roll:6:20", "<= 5 rad/s"), ("sharp:3+roll:1", "roll takes"),
    ("sharp:3+wobble", "unknown component"), ("sharp:3+tail:1", "takes no value"),
    ("sharp:3+roll:1:0.01", "shorter than one mean chord")])
def test_bad_specs_say_what_is_accepted(text, says):
    with pytest.raises(GustSpecError, match=says) as exc:
        parse_gust(text)
    assert "\n" not in str(exc.value)


def test_uniform_field_refuses_spanwise_parts_and_short_components_are_refused():
    with pytest.raises(GustSpecError, match="flown by gust, compare and sitl"):
        GustField(parse_gust("sharp:3+tail"), V)
    with pytest.raises(GustSpecError, match="steps"):
        check_gust_resolution(parse_gust("none+roll:1:0.5"), V, 1 / 60)


def test_without_spanwise_parts_the_symmetric_gust_is_todays():
    """The uniform path is unchanged: gust_field gives the GustField itself, and a field
    with only a tail delay carries the same w_g at the wing, bit for bit."""
    for text in ("1cos:3:20", "dryden:1:30:4", "sharp:3"):
        spec = parse_gust(text)
        plain = GustField(spec, V, 0.5, 3.0, 1 / 120).samples(360)
        assert isinstance(gust_field(spec, V), GustField)
        with_tail = SpanwiseGustField(parse_gust(text + "+tail"), V,
                                      SpanStations.rectangular(B, C, A), TAIL, 0.5, 3.0, 1 / 120)
        assert np.array_equal(with_tail.samples(360), plain)


def test_linear_gust_rolling_moment_against_strip_integral_closed_form():
    """w = −p_g y on a rectangular wing: the strips' moment against Q p_g C_lα c b³/(12 V)
    (midpoint rule on 400 strips a side: relative error 1/(4·400²) ~ 2e-6), and the strip
    roll damping against −C_lα/6."""
    st = SpanStations.rectangular(B, C, A, n_half=400)
    p_g = 0.4
    moment = float(st.rolling_moment_n_m(-p_g * st.y_m, Q, V))
    closed = rectangular_rolling_moment_n_m(p_g, Q, V, A, C, B)
    assert moment == pytest.approx(closed, rel=1e-5)
    assert closed > 0.0  # the air rolls right: the right wing sees downwash, drops
    assert st.roll_damping_per_rad() == pytest.approx(-A / 6.0, rel=1e-5)
    # the moment is −L_p p_g with the strips' own damping: L_p = C_lp Q S b²/(2V)
    l_p = st.roll_damping_per_rad() * Q * st.area_m2 * B**2 / (2.0 * V)
    assert moment == pytest.approx(-l_p * p_g, rel=1e-12)


def test_first_moment_equivalence_is_exact_for_the_linear_gust_of_any_planform():
    """On the prototype's lattice strips (elliptic-like C_lα c): the equivalent roll rate of
    w = −p y is p, the symmetric part 0; a uniform gust has no roll rate."""
    from bioflex_jsb import api

    aero = api.load_wing("optimised").aero
    st = SpanStations.from_half_wing(aero.stations_m, aero.weights_m, aero.cl_alpha_c_m_per_rad,
                                     aero.reference_area_m2, 2 * aero.semispan_m)
    assert float(st.equivalent_roll_rate(-0.7 * st.y_m)) == pytest.approx(0.7, rel=1e-12)
    assert float(st.symmetric_gust(-0.7 * st.y_m)) == pytest.approx(0.0, abs=1e-12)
    assert float(st.equivalent_roll_rate(np.full(st.y_m.shape, 3.0))) == pytest.approx(0.0,
                                                                                       abs=1e-12)


def test_oblique_sharp_front_against_its_closed_form():
    """A step A with its front at Λ to the span, starboard first, on a rectangular wing:
    when the front crosses station y_f, the hit part y ≥ y_f gives w̄ = A (b/2 − y_f)/b and
    p_g = −6 A (b²/4 − y_f²)/b³ (first moment over ∫ y² = b³/12); at the centreline
    y_f = 0: w̄ = A/2, p_g = −1.5 A/b (the right wing lifted: roll left)."""
    amp, angle = 3.0, math.radians(40.0)
    st = SpanStations.rectangular(B, C, A, n_half=2000)
    dt = 1e-3
    f = SpanwiseGustField(parse_gust(f"sharp:{amp}+front:40"), V, st, None, 0.5, 2.0, dt)
    cross = B * math.tan(angle) / V  # the front crosses the span in this time [s]
    for frac in (0.25, 0.5, 0.75):
        t = 0.5 - cross / 2 + frac * cross
        k = round(t / dt)
        y_f = -V * (k * dt - 0.5) / math.tan(angle)
        parts = f.parts(1, k)
        assert float(parts.w_sym[0]) == pytest.approx(amp * (B / 2 - y_f) / B, rel=2e-3)
        assert float(parts.p_g[0]) == pytest.approx(-6 * amp * (B**2 / 4 - y_f**2) / B**3,
                                                    rel=2e-3)
    before = f.parts(1, round((0.5 - cross) / dt) - 2)
    after = f.parts(1, round((0.5 + cross) / dt) + 2)
    assert before.w_sym[0] == 0.0 and after.w_sym[0] == pytest.approx(amp)
    assert after.p_g[0] == pytest.approx(0.0, abs=1e-12)


def test_tail_meets_the_gust_lt_over_v_late():
    dt = 1 / 120
    f = SpanwiseGustField(parse_gust("1cos:3:20+tail"), V, SpanStations.rectangular(B, C, A),
                          TAIL, 0.5, 4.0, dt)
    parts = f.parts(480)
    t = np.arange(480) * dt
    expected = np.where((t - 0.5 - TAIL.arm_m / V >= 0) & ((t - 0.5 - TAIL.arm_m / V) * V <= 20),
                        1.5 * (1 - np.cos(2 * math.pi * (t - 0.5 - TAIL.arm_m / V) * V / 20)), 0)
    assert np.max(np.abs(parts.w_tail - expected)) < 1e-12
    turb = SpanwiseGustField(parse_gust("dryden:1:30+tail"), V, SpanStations.rectangular(B, C, A),
                             TailGust(V * 3 * dt, 0.36), 0.5, 4.0, dt)  # a delay of 3 steps
    p = turb.parts(400)
    assert np.allclose(p.w_tail[3:], p.w_sym[:-3], rtol=0, atol=1e-12)


def test_prototype_tail_from_its_derivatives():
    tail = TailGust.from_derivatives(RIGID_AERODYNAMICS, C)
    assert tail.arm_m == pytest.approx(0.9 / 0.35 * C, rel=1e-12)  # 0.4706 m
    slope = 7.3 / (2 * (0.9 / 0.35) ** 2)  # 0.552: a_t,S from C_mq
    assert tail.lift_slope_per_rad == pytest.approx(slope * (1 - 2.5 / 7.3), rel=1e-12)
    assert slope == pytest.approx(0.35 / 0.65, rel=0.03)  # its estimate S_t/S C_Lα,t (τ 0.65)
    from dataclasses import replace
    with pytest.raises(InputError, match="elevator"):
        TailGust.from_derivatives(replace(RIGID_AERODYNAMICS, cl_delta_e_per_rad=0.0), C)


@pytest.mark.parametrize("sigma, scale, span", [(1.0, 50.0, 1.7), (2.0, 300.0, 10.0)])
def test_rolling_spectrum_integrates_to_its_closed_form(sigma, scale, span):
    numeric, _ = quad(lambda om: float(rolling_psd(om, sigma, scale, span)), 0.0, np.inf,
                      limit=200)
    assert numeric == pytest.approx(rolling_variance(sigma, scale, span), rel=1e-8)


@pytest.mark.parametrize("kind", ["dryden", "vonkarman"])
def test_synthesised_rolling_turbulence_has_the_standards_variance(kind):
    """p_g of σ_w 1 m/s, L_w 50 m over the prototype's 1.7 m span at 15 m/s, 8 seeds of 300 s:
    the ensemble variance against the band-limited integral ∫_0^{Ω_N} Φ_p dΩ (the series has
    no power above Nyquist, 60 Hz: Ω_N = 25.1 rad/m; 1.2 % of σ_p² lies above it) within 2 %
    (the spread of 8 × 300 s: one seed's variance scatters by ~2 %, the mean by ~0.7 %),
    and the closed form within 3 %."""
    dt, duration = 1 / 120, 300.0
    st = SpanStations.rectangular(B, C, A)
    var = []
    for seed in range(8):
        f = SpanwiseGustField(parse_gust(f"{kind}:1:50:{seed}+pg"), V, st, None, 0.0, duration,
                              dt)
        var.append(float(np.var(f.roll_rate_samples(int(duration / dt)))))
    omega_n = math.pi / dt / V
    band, _ = quad(lambda om: float(rolling_psd(om, 1.0, 50.0, B)), 0.0, omega_n, limit=200)
    assert np.mean(var) == pytest.approx(band, rel=0.02)
    assert np.mean(var) == pytest.approx(rolling_variance(1.0, 50.0, B), rel=0.03)
    # independent of the vertical series of the same seed
    f = SpanwiseGustField(parse_gust(f"{kind}:1:50:0+pg"), V, st, None, 0.0, duration, dt)
    parts = f.parts(int(duration / dt))
    assert abs(np.corrcoef(parts.w_sym, parts.p_g)[0, 1]) < 0.05


def test_lateral_turbulence_variance_and_one_cosine():
    dt = 1 / 120
    st = SpanStations.rectangular(B, C, A)
    var = [float(np.var(SpanwiseGustField(parse_gust(f"none+lateral:dryden:2:40:{s}"), V, st,
                                          None, 0.0, 300.0, dt).parts(36000).v_g))
           for s in range(6)]
    assert np.mean(var) == pytest.approx(4.0, rel=0.06)  # σ_v² (Dryden: 0.5 % above Nyquist)
    f = SpanwiseGustField(parse_gust("none+lateral:1cos:2:15"), V, st, None, 0.5, 3.0, dt)
    v = f.parts(360).v_g
    assert v.max() == pytest.approx(2.0, rel=1e-3) and v[:60].max() == 0.0
