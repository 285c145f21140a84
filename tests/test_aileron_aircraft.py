"""Aileron effectiveness of an aircraft's flight model of its wing (aeroelasticity/aileron.py
``flight_roll_strips``): the same static problem as the aircraft's Eq. (4) model, the same
wing through the clamped path, and the prototype's estimated aileron."""

from __future__ import annotations

import math

import pytest

from bioflex_jsb import api
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.eigen import wing_divergence_speed_m_s
from tests.cli_helpers import assert_one_line_error, run_cli

PROTOTYPE_AILERON = (0.6, 1.0, 0.75)  # the shipped bioflex_*.toml [aileron] (an ESTIMATE)


@pytest.mark.parametrize("variant", ["inertial-backward", "elastic-backward"])
def test_divergence_is_the_aircraft_models_with_the_body_held(variant):
    # Two assemblies of the steady wing problem: the strips here, and A_EE = −ω² + H_η of
    # Eq. (4) from the Table B1 coefficients (flight_dynamics/eigen.py, bisected to 1e-4
    # m/s): 18.7308 / 18.7315 m/s both ways (measured to 5e-9).
    build = api.load_wing(variant)
    res = api.aileron_effectiveness(build, aileron=PROTOTYPE_AILERON)
    ref = wing_divergence_speed_m_s(build.model, 1.225, (2.0, 60.0))
    assert res.divergence_speed_m_s == pytest.approx(ref, abs=2e-4)


def test_prototype_estimated_aileron_reverses_below_cruise():
    # The prototype's ailerons are an ESTIMATE (parameters/airframe.py, C_l_delta_a 0.20:
    # outboard, 25 % chord, 40 % span). On the calibrated membrane wing (modal stiffness
    # ω₁² m₁ = 0.61 N m/rad) they reverse at 12.8-13.1 m/s for every variant, below the
    # 15 m/s cruise: the reversal hardly depends on the axes (the typical section's q_R =
    # −K c_lδ/(S c a₀ c_mδ) has no e in it), although the divergence does (none for the
    # forward and optimised wings, 18.73 m/s for the backward ones). Measured 12.82 (optimised)
    # to 13.09 m/s (inertial-backward).
    speeds = {}
    for variant in ("original", "optimised", "inertial-forward", "elastic-forward",
                    "inertial-backward", "elastic-backward"):
        res = api.aileron_effectiveness(api.load_aircraft(f"bioflex_{variant}"))
        assert res.surface["start_m"] == pytest.approx(0.6 * 0.85)
        assert res.reference["speed_m_s"] == 15.0 and res.reference["effectiveness"] < 0.0
        speeds[variant] = res.reversal_speed_m_s
    assert speeds["optimised"] == pytest.approx(12.82, abs=0.01)
    assert speeds["inertial-backward"] == pytest.approx(13.09, abs=0.01)
    assert max(speeds.values()) - min(speeds.values()) < 0.3
    opt = api.aileron_effectiveness(api.load_aircraft("bioflex_optimised"))
    d = opt.as_dict()
    assert d["clamped"] is False and d["n_flown_modes"] == 3 and d["lift_slope"] == "vlm"
    assert d["aircraft"] == {"name": "bioflex", "cl_delta_a_per_rad": 0.2,
                             "cl_p_per_rad": -0.45}
    # the lattice strips' rigid C_lp against the airframe's own strip-theory estimate
    # before its tip-loss allowance, ≈ −0.66 (parameters/airframe.py): measured −0.6598
    assert d["rigid"]["cl_p_per_rad"] == pytest.approx(-0.66, abs=0.005)
    # a bare WingBuild is the same flight model (its aileron given: it has none)
    bare = api.aileron_effectiveness(api.load_wing("optimised"), aileron=PROTOTYPE_AILERON)
    assert bare.reversal_speed_m_s == pytest.approx(opt.reversal_speed_m_s, rel=1e-12)
    with pytest.raises(InputError, match="has no \\[aileron\\]"):
        api.aileron_effectiveness(api.load_wing("optimised"))
    with pytest.raises(InputError, match="lift_slope is for clamped wings"):
        api.aileron_effectiveness(api.load_wing("optimised"), aileron=PROTOTYPE_AILERON,
                                  lift_slope="strip")


def test_the_same_wing_clamped_and_flown():
    # sgs_wing.toml (clamped) is the beam whose three modes sgs_elastic flies
    # (docs/aircraft.md), both on the vortex lattice's 40 strips (lift_slope "vlm"): the
    # rigid C_l_delta and C_lp are the same strips' (equal to round-off); the reversal
    # agrees to 0.06 % (measured 96.107 against 96.050 m/s; tolerance 0.5 %). The
    # divergence does not (124.98 against 121.61 m/s): the clamped strips' lift acts at
    # the quarter chord, the flight model's at the lattice's aerodynamic centre, and with
    # e = 0.13c the divergence feels a few millimetres; the reversal, like the typical
    # section's, hardly depends on e.
    aileron = (0.55, 0.95, 0.75)
    clamped = api.aileron_effectiveness("sgs_wing", aileron=aileron, lift_slope="vlm")
    flown = api.aileron_effectiveness(api.load_aircraft("sgs_elastic"), aileron=aileron)
    assert flown.cl_delta_per_rad == pytest.approx(clamped.cl_delta_per_rad, rel=1e-12)
    assert flown.cl_p_per_rad == pytest.approx(clamped.cl_p_per_rad, rel=1e-12)
    assert flown.reversal_speed_m_s == pytest.approx(clamped.reversal_speed_m_s, rel=5e-3)
    assert flown.divergence_speed_m_s == pytest.approx(121.61, abs=0.01)  # docs/aircraft.md
    assert math.isclose(flown.reference["speed_m_s"], 25.0)  # its cruise speed
    assert 0.9 < flown.reference["effectiveness"] < 1.0


def test_cli_aircraft(capsys):
    code, out, _ = run_cli(capsys, "aileron", "--aircraft", "bioflex_optimised")
    assert code == 0 and "aileron reversal at 12.8 m/s" in out
    assert "at the aircraft's cruise speed 15 m/s" in out and "(reversed)" in out
    code, _, err = run_cli(capsys, "aileron", "--aircraft", "bioflex_optimised", "--clamped",
                           "goland_aileron")
    assert_one_line_error(code, err, "give one of them")
    code, _, err = run_cli(capsys, "aileron", "--aircraft", "bioflex_optimised",
                           "--lift-slope", "strip")
    assert_one_line_error(code, err, "--lift-slope is for --clamped")


def test_a_full_span_run_near_or_above_reversal_says_so():
    """cli/lateral_options.reversal_note: the reversal speed of the run's wing and aileron
    is `aileron`'s exactly (the same static problem), and a run at 90 % of it or more gets
    one line saying which side it is on (the prototype: 12.82 m/s at sea level)."""
    from bioflex_jsb.aeroelasticity.aileron import flight_roll_strips, reversal_speed_m_s
    from bioflex_jsb.cli.lateral_options import reversal_note
    from bioflex_jsb.simulation.full_span import prototype_aileron

    build, aileron = api.load_wing("optimised"), prototype_aileron("optimised")
    v_r = reversal_speed_m_s(flight_roll_strips(build, aileron), 1.225)
    assert v_r == api.aileron_effectiveness(build, aileron=aileron).reversal_speed_m_s
    assert v_r == pytest.approx(12.82, abs=0.01)
    assert "is above" in reversal_note(build, aileron, 15.0, 0.0)
    assert "roll the elastic aircraft the other way" in reversal_note(build, aileron, 15.0, 0.0)
    assert "within 10 %" in reversal_note(build, aileron, 0.95 * v_r, 0.0)
    assert reversal_note(build, aileron, 0.89 * v_r, 0.0) is None
    # thinner air, the same speed: the reversal's dynamic pressure is reached at a higher
    # true airspeed (√(ρ₀/ρ)), so 12.9 m/s at 3000 m (ρ 0.909) is below 0.9 of it
    assert reversal_note(build, aileron, 12.9, 0.0) is not None
    assert reversal_note(build, aileron, 12.9, 3000.0) is None


def test_gust_above_reversal_prints_the_note_and_flies(capsys):
    code, _out, err = run_cli(capsys, "gust", "--aileron-step", "2", "--models", "coupled",
                              "--duration", "0.6", "--gust-start", "0.2", "--no-log")
    assert code == 0, err
    notes = [ln for ln in err.splitlines() if "aileron reversal speed" in ln]
    assert len(notes) == 1 and "15 m/s is above the optimised wing's" in notes[0], err
