"""``loads --tuned`` and ``loads --frequency`` on another JSBSim aircraft (JSBSim's c172p with
its elastic wing, ``c172_elastic``): the tuned gust's gradients and settling time from the
aircraft's own chord and short period, its loads against Pratt and Walker's gust load
factor, and the frequency-domain study on the aircraft's own JSBSim rigid block with its
default intensities inside its aerodynamic tables."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.loads.tuned import (
    CODE_H_MAX_M,
    DEFAULT_H_MIN_CHORDS,
    aircraft_gust_scales,
    default_gradients_m,
    default_scales,
)
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from tests.cli_helpers import run_cli

G_M_S2 = 9.80665


@pytest.fixture(scope="module")
def c172():
    return api.load_aircraft("c172_elastic")


def test_an_aircrafts_gust_scales_are_its_chord_and_short_period():
    """Closed forms of aircraft_gust_scales: H from 1.5 c̄ to V 2π/ω_n (at most the codes'
    107 m), 2·2π/ω_n after the gust; the prototype keeps its own defaults."""
    s = aircraft_gust_scales(1.5, 50.0, 2.0 * math.pi)  # T_sp = 1 s
    assert (s.h_min_m, s.h_max_m, s.settle_after_s) == pytest.approx((2.25, 50.0, 2.0))
    assert aircraft_gust_scales(1.5, 200.0, 1.0).h_max_m == pytest.approx(CODE_H_MAX_M)
    assert CODE_H_MAX_M == pytest.approx(106.68)  # 350 ft, CS/FAR 25.341
    chord_m = PROTOTYPE_AIRFRAME.reference.mean_chord_m
    assert np.array_equal(default_scales(chord_m).gradients_m(), default_gradients_m(chord_m))
    from bioflex_jsb.errors import InputError

    with pytest.raises(InputError, match="give --gradients"):
        aircraft_gust_scales(1.5, 2.0, 2.0 * math.pi)  # 2 m, below 1.5 chords


def test_tuned_gust_on_the_c172_takes_its_own_scales(c172, tmp_path, capsys):
    """The default gradients are 1.5 c̄ = 2.24 m to V T_sp = 45.9 m (ω_n 7.91 rad/s of the
    rigid short period at the 57.8 m/s cruise, computed here through the API), each run
    lasting 0.2 s + 2H/V + 2 T_sp; before, --tuned refused every airframe but the
    prototype's."""
    code, out, err = run_cli(capsys, "loads", "--aircraft", "c172_elastic", "--tuned",
                             "--workers", "2", "--json", "--plot", str(tmp_path / "e.png"))
    assert code == 0, err
    data = json.loads(out)
    st = data["settings"]
    speed = st["speed_m_s"]
    chord = c172.wing().model.airframe.reference.mean_chord_m
    wn = api.modes(c172, speed, "rigid").get("short_period").frequency_rad_s
    expected = np.geomspace(DEFAULT_H_MIN_CHORDS * chord, speed * 2.0 * math.pi / wn, 10)
    assert st["gradients_m"] == pytest.approx(expected, rel=1e-9)
    assert st["gradients_m"][0] == pytest.approx(2.24, abs=0.01)
    assert st["gradients_m"][-1] == pytest.approx(45.9, abs=0.1)
    assert st["settle_after_s"] == pytest.approx(4.0 * math.pi / wn, rel=1e-9)
    for case in data["cases"]:
        assert case["duration_s"] == pytest.approx(
            0.2 + 2.0 * case["gradient_m"] / speed + st["settle_after_s"])
    assert {r["station"] for r in data["critical"]} >= {"root"}
    assert (tmp_path / "e.png").stat().st_size > 0


def test_a_twelve_and_a_half_chord_gust_loads_the_root_as_pratts_load_factor(c172, capsys):
    """A 1-cos gust of H = 12.5 c̄ (Pratt and Walker's, NACA Report 1206), U = 3 m/s: the
    root bending moment's increment over its 1 g value, ΔM/M₁g, is the load factor
    increment Δn = K_g ρ V a U / (2 W/S) with K_g = 0.88 μ/(5.3 + μ),
    μ = 2 (W/S)/(ρ c̄ a g) (a the aircraft's C_Lα), the plunging aircraft's: 0.637 for the
    c172 (μ 11.0, K_g 0.595). The flown aircraft also pitches into the gust, which
    relieves it: measured 0.574 up and 0.584 down by force summation (0.90, 0.92 of Δn),
    0.59 and 0.60 by mode displacement."""
    build = c172.wing()
    airframe = build.model.airframe
    chord, area = airframe.reference.mean_chord_m, airframe.reference.area_m2
    rho = c172.definition.air.density_kg_m3
    cruise = 57.8
    a = airframe.at_speed(cruise).aero.cl_alpha_per_rad
    w_s = airframe.mass.mass_kg * G_M_S2 / area
    mu = 2.0 * w_s / (rho * chord * a * G_M_S2)
    k_g = 0.88 * mu / (5.3 + mu)
    dn = k_g * rho * cruise * a * 3.0 / (2.0 * w_s)
    assert dn == pytest.approx(0.637, abs=0.005)
    code, out, err = run_cli(capsys, "loads", "--aircraft", "c172_elastic", "--tuned",
                             "--workers", "1", "--gradients", f"{12.5 * chord:.4f}",
                             "--scaling", "fixed", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["settings"]["speed_m_s"] == cruise
    for r in data["critical"]:
        if r["station"] == "root" and r["quantity"] == "bending_n_m":
            ratio = abs(r["increment"] / r["static_1g"]) / dn
            assert 0.8 < ratio <= 1.0, r


def test_frequency_study_on_the_c172_with_its_own_rigid_block(capsys):
    """--frequency on the c172: JSBSim's c172p linearised at its trim (its α −0.42 deg, the
    tables from −5.16 deg: default intensities 0.1 and 1.1 m/s, whose 4σ gust angle stays
    inside them; the prototype's 2.5 m/s left them at 4.3 s); the LTI and nonlinear RMS of
    q, n_z and the root bending moment agree within 15 % over 24 s (measured 30 s: +2.4 to
    +4.3 %), the LTI PSD inside the Welch band in at least 85 % of the bins (measured 99 %)."""
    code, out, err = run_cli(capsys, "loads", "--aircraft", "c172_elastic", "--frequency",
                             "--record", "24", "--json")
    assert code == 0, err
    data = json.loads(out)
    assert data["speed_m_s"] == 57.8
    assert [c["sigma_m_s"] for c in data["cases"]] == [0.1, 1.1]
    assert data["stopped"] == []
    for case in data["cases"]:
        for name, row in case["outputs"].items():
            assert row["fraction_in_band"] >= 0.85, (name, row)
            assert 0.85 < row["rms_ratio_band"] < 1.15, (name, row)
