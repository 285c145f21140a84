"""``compare`` of a run with both wing halves (span='full') against the lateral model of the
same wing model (drivers/compare_lateral.py; docs/lateral.md, "Both halves in compare"):
a rolling gust on the c172_elastic, nonlinear against linear channel by channel, a model
without the wing's antisymmetric modes shown to be further off, the gust roll rate's input
column against its closed form, and what compare refuses in one line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers.compare import compare_run
from bioflex_jsb.drivers.compare_lateral import full_span_lateral_model, respond
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.results import nrmse
from tests.cli_helpers import assert_one_line_error, run_cli

C172 = "c172_elastic"
SPEED_M_S = 57.8  # its cruise [m/s]
# A 1-cos rolling gust of 0.1 rad/s peak over 40 m (0.69 s at cruise): p reaches 0.085 rad/s,
# the bank 2 deg, the linear range
GUST = "none+roll:0.1:40"
DURATION_S = 3.0


@pytest.fixture(scope="module")
def c172():
    return api.load_aircraft(C172)


@pytest.fixture(scope="module")
def rolling_gust(c172):
    """The rolling gust flown coupled with both halves, and its comparison."""
    build = c172.wing()
    airframe = airframe_for(c172)
    run = run_gust(airframe, build, "coupled",
                   RunConfig(SPEED_M_S, parse_gust(GUST), DURATION_S), span="full",
                   aileron=c172.definition.aileron)
    assert run.stopped is None
    return build, airframe, run, compare_run(build, run, "coupled", SPEED_M_S,
                                              airframe=airframe,
                                              aileron=c172.definition.aileron)


# NRMSE of the lateral channels, LTI against the nonlinear run: measured p 0.0021, beta
# 0.0044, r 0.0019, phi 0.00055, asym_eta1 0.0086, modal_roll_n_m 0.0113 (the run's Q and V
# move with the motion, the LTI's are the trim's); both with the yaw rate's and sideslip's
# terms (the LTI's linearised about the trim: without them in the LTI, 0.0022, 0.0068,
# 0.0038, 0.00095, 0.0327, 0.0414). phi over gust amplitudes 0.05, 0.1 and
# 0.2 rad/s: 0.00054, 0.00054, 0.00056 (beta 0.0050, 0.0044, 0.0033); a prediction from
# zero, without the trim's bank (-0.16 mrad), gives phi 0.0128, 0.0066, 0.0035, as an
# offset's error falls with the amplitude
LATERAL_NRMSE = {"p_rad_s": 0.01, "beta_rad": 0.01, "r_rad_s": 0.01, "phi_rad": 0.002,
                 "asym_eta1": 0.025, "modal_roll_n_m": 0.03}


def test_a_rolling_gust_with_both_halves_is_the_lateral_models(rolling_gust):
    """The rolling gust rolls the aircraft (measured: p to 0.0846 rad/s, the bank 1.96 deg,
    asym_eta1 9.9e-6 rad, the modes' moment 37.4 N·m) and the coupled lateral model with the
    run's p_g predicts each lateral channel within LATERAL_NRMSE; the modes' moment opposes
    the roll rate the strips see, p − p_g (the c172's wing damps it: 37.3 N·m at
    p − p_g = −0.040 rad/s)."""
    _, _, run, result = rolling_gust
    assert np.max(np.abs(run["p_rad_s"])) > 0.03
    assert np.max(np.abs(run["asym_eta1"])) > 1e-6
    for channel, tol in LATERAL_NRMSE.items():
        assert channel in result.channels, channel
        assert result.nrmse[channel] < tol, (channel, result.nrmse[channel])
    relative = run["p_rad_s"] - run["p_g"]  # the roll rate the strips see
    k = int(np.argmax(np.abs(relative)))
    assert run["modal_roll_n_m"][k] * relative[k] < 0.0


def test_the_rigid_lateral_model_is_further_off(rolling_gust, c172):
    """The comparison tells the elastic wing from a rigid one: the rigid lateral model driven
    by the same p_g misses the elastic run's roll rate by several times the coupled model's
    NRMSE (measured 0.022 against 0.0021; peak p 0.0833 rad/s rigid against 0.0846 flown: the
    twist that damps the aircraft's roll also adds to the gust's moment, both act on
    p − p_g)."""
    build, airframe, run, result = rolling_gust
    rigid = full_span_lateral_model(build, airframe, "rigid", SPEED_M_S)
    t = run.time_s
    u = np.column_stack([np.zeros(t.size), np.zeros(t.size), run["p_g"]])
    p_rigid = respond(rigid, t, u)["p_rad_s"]
    assert nrmse(run["p_rad_s"], p_rigid) > 4.0 * result.nrmse["p_rad_s"]


@pytest.mark.parametrize("model", ["rigid", "coupled", "qsd"])
def test_air_rolling_with_the_aircraft_leaves_no_moment(c172, model):
    """The gust roll rate's column (p − p_g in the moments and on the strips): a steady roll
    rate p in air rolling with it (p_g = p) leaves only the kinematics, φ̇ = p and β's
    w₀/V + Y_p/V (C_Yp, which the gust does not apply): ṗ, ṙ and the modes' forcing zero."""
    lm = full_span_lateral_model(c172.wing(), airframe_for(c172), model, SPEED_M_S)
    ss = lm.ss
    x = np.zeros(len(ss.states))
    x[ss.states.index("p")] = 1.0
    xdot = ss.a @ x + ss.b @ np.array([0.0, 0.0, 1.0])
    for name in ss.states:
        if name not in ("beta", "phi"):
            assert xdot[ss.states.index(name)] == pytest.approx(0.0, abs=1e-12), name
    assert xdot[ss.states.index("phi")] == pytest.approx(1.0, abs=1e-12)
    if model == "qsd":  # its quasi-static η too
        y = ss.c @ x + ss.d @ np.array([0.0, 0.0, 1.0])
        assert y[ss.outputs.index("eta1")] == pytest.approx(0.0, abs=1e-15)


def test_compare_span_full_prints_the_lateral_channels(capsys, tmp_path):
    """The CLI: the prototype through a rolling gust with both halves, --json holds the
    lateral channels' NRMSE (the qsd model, 0.1 rad/s over 15 m, 1.5 s; measured p 0.0089,
    phi 0.0039, asym_eta1 0.0408, modal_roll_n_m 0.0387; without the yaw rate's and
    sideslip's terms in the nonlinear step and the LTI 0.0077, 0.0040, 0.0376, 0.0364)."""
    code, out, err = run_cli(capsys, "compare", "--span", "full", "--model", "qsd",
                             "--gust", "none+roll:0.1:15", "--duration", "1.5", "--no-log",
                             "--json")
    assert code == 0, err
    payload = json.loads(out)
    for channel in ("p_rad_s", "phi_rad", "asym_eta1", "modal_roll_n_m"):
        assert payload["nrmse"][channel] < 0.06, channel


def test_compare_an_aileron_step(capsys):
    """compare --aileron-step (both halves implied, no gust needed): the prototype's
    estimated aileron, 0.5 deg at 0.5 s, coupled; measured NRMSE p 0.0052, phi 0.0016,
    asym_eta1 0.0128, modal_roll_n_m 0.0379 over 1.5 s with the yaw rate's and sideslip's
    terms in both (0.177, 0.101, 0.103, 0.112 with them in the nonlinear step alone; 0.0042,
    0.0017, 0.0119, 0.0353 without them in either: phi 0.0008 and 0.0004 at dt/2 and dt/4;
    0.0018 and 0.0015 at 0.25 and 1 deg)."""
    code, out, err = run_cli(capsys, "compare", "--aileron-step", "0.5", "--gust", "none",
                             "--duration", "1.5", "--no-log", "--json")
    assert code == 0, err
    nrmse = json.loads(out)["nrmse"]
    assert nrmse["p_rad_s"] < 0.01 and nrmse["phi_rad"] < 0.005
    assert nrmse["asym_eta1"] < 0.03 and nrmse["modal_roll_n_m"] < 0.06


@pytest.mark.parametrize(("argv", "needle"), [
    (("--span", "full", "--aero", "unsteady", "--model", "qsd"), "coupled model"),
    (("--span", "full", "--trim", "elastic"), "about the rigid trim"),
    (("--span", "half", "--aileron-step", "1"), "compared with both wing halves"),
])
def test_compare_refuses_what_the_lateral_model_has_not(capsys, argv, needle):
    code, _, err = run_cli(capsys, "compare", "--gust", "none+roll:0.1:15", "--no-log", *argv)
    assert_one_line_error(code, err, needle)


def test_the_prototype_airframe_has_a_lateral_model_per_wing_model():
    """The prototype's wing (its estimated aileron) has the three models, each with the
    inputs v_g, aileron, p_g."""
    build = api.load_aircraft("bioflex_optimised").wing()
    for model in ("rigid", "coupled", "qsd"):
        lm = full_span_lateral_model(build, Airframe(), model, 15.0)
        assert lm.ss.inputs == ("v_g", "aileron", "p_g")
        assert (lm.strips is None) == (model == "rigid")


def test_api_compare_span_full():
    """api.compare(span='full'): the same comparison from the API (the prototype, its
    estimated aileron on the strips; measured p 0.0086, asym_eta1 0.031, beta 0.058, phi
    0.0135 coupled, 1 s: the explicit coupling's lag of p, r and β, visible on its light
    wing, docs/lateral.md "Validation"; at dt/2 and dt/4 beta 0.028 and 0.014, asym_eta1
    0.016 and 0.0079, phi 0.0068 and 0.0035: test_the_prototypes_bank_error_halves_with_the_
    step. Without the yaw rate's and sideslip's terms in either, beta 0.042, asym_eta1
    0.033: the terms' r and β, held over the step as p is, add to the lag)."""
    c = api.compare(api.load_aircraft("bioflex_optimised"), 15.0, gust="none+roll:0.1:15",
                    model="coupled", duration_s=1.0, span="full")
    assert c.nonlinear.meta["span"] == "full"
    assert c.nrmse["p_rad_s"] < 0.02 and c.nrmse["asym_eta1"] < 0.05
    assert c.nrmse["phi_rad"] < 0.02 and c.nrmse["beta_rad"] < 0.07


def test_the_prototypes_bank_error_halves_with_the_step():
    """The prototype's rolling gust (coupled, 1 s) at the default step and at half of it:
    each lateral channel's error against the linear model is the explicit coupling's lag,
    first order, the bank's too (measured NRMSE ratios dt/(dt/2): phi 2.00, p 2.00, beta
    2.02; phi 0.0136, 0.0068, 0.0035 at dt, dt/2, dt/4). A prediction from zero, without
    the trim's bank (-0.158 mrad, JSBSim's trim, held in calm air to 2e-6 rad over 1 s),
    gives phi 0.0408, 0.0358, 0.0335: the offset's 0.032 does not halve."""
    ac = api.load_aircraft("bioflex_optimised")
    build, aileron, airframe = ac.wing(), ac.definition.aileron, Airframe()
    errors = []
    for dt_s in (DEFAULT_DT_S, DEFAULT_DT_S / 2.0):
        run = run_gust(airframe, build, "coupled",
                       RunConfig(15.0, parse_gust("none+roll:0.1:15"), 1.0, dt_s=dt_s),
                       span="full", aileron=aileron)
        errors.append(compare_run(build, run, "coupled", 15.0, airframe=airframe,
                                  aileron=aileron).nrmse)
    for channel in ("phi_rad", "p_rad_s", "beta_rad"):
        assert 1.8 < errors[0][channel] / errors[1][channel] < 2.2, channel


def test_the_half_wings_rolling_gust_prediction_has_no_gust_side_force(c172):
    """The half wing's compare predicts a rolling gust with the rigid lateral model
    (simulation/spanwise_gusts.lateral_gust_response); its p_g column carries what the run
    applies, C_lp and C_np with p − p_g, and no side force. Measured on the c172_elastic
    (C_Yp −0.075), 3 s: NRMSE β 0.0030, r 0.0018, p 0.0023 (with a −Y_p/V p_g side force in
    the prediction, as before: 0.042, 0.029, 0.0059)."""
    c = api.compare(c172, SPEED_M_S, gust=GUST, model="coupled", duration_s=DURATION_S)
    assert c.nonlinear.meta["span"] == "half" and "asym_eta1" not in c.channels
    assert c.nrmse["beta_rad"] < 0.01 and c.nrmse["r_rad_s"] < 0.01
    assert c.nrmse["p_rad_s"] < 0.01


def test_the_residualised_coupled_model_is_the_qsd_one(c172):
    """residualised of the coupled lateral model without the aileron's load is
    build_lateral_elastic('qsd') (its A, B and the η outputs' C, D) to round-off."""
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        antisymmetric_wing,
        build_lateral_elastic,
        residualised,
    )
    from bioflex_jsb.runtime.identification import identify_lateral

    build = c172.wing()
    point = identify_lateral(airframe_for(c172), SPEED_M_S, build.airframe.reference)
    wing_a = antisymmetric_wing(build, point.trim.ixx_kg_m2)
    qsd = build_lateral_elastic("qsd", point.trim, point.aero, wing_a)
    mine = residualised(build_lateral_elastic("coupled", point.trim, point.aero, wing_a))
    assert mine.outputs == qsd.outputs and mine.states == qsd.states
    for m in ("a", "b", "c", "d"):
        want = getattr(qsd, m)
        np.testing.assert_allclose(getattr(mine, m), want, rtol=1e-9,
                                   atol=1e-12 * np.max(np.abs(want)), err_msg=m)


def test_compare_an_aileron_step_on_the_quasi_static_wing(capsys):
    """The qsd model with its aileron's load in the balance (residualised): the prototype's
    reversed aileron, 0.5 deg; measured NRMSE p 0.0104, phi 0.0042, asym_eta1 0.0218 over
    1.5 s with the yaw rate's and sideslip's terms in both (0.177, 0.103, 0.105 with them in
    the nonlinear step alone; without them in either 0.0085, 0.0046, 0.0202; 1.83, 1.83 and
    1.33 with the aileron's load left out of the linear balance)."""
    code, out, err = run_cli(capsys, "compare", "--model", "qsd", "--aileron-step", "0.5",
                             "--gust", "none", "--duration", "1.5", "--no-log", "--json")
    assert code == 0, err
    nrmse = json.loads(out)["nrmse"]
    assert nrmse["p_rad_s"] < 0.02 and nrmse["phi_rad"] < 0.01 and nrmse["asym_eta1"] < 0.05
