"""Spanwise and lateral gusts flown through JSBSim: the hooks carry the moments the strip
integral and C_lp give, a rolling gust rolls the rigid aircraft as the rigid lateral model
predicts for the equivalent input, a lateral gust goes through JSBSim's wind with the
lateral model's sign, and the tail's penetration delay pitches it as the longitudinal model's
elevator-equivalent input does."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from scipy.linalg import expm

from bioflex_jsb import api
from bioflex_jsb import units as U
from bioflex_jsb.errors import InputError
from bioflex_jsb.parameters.airframe import REFERENCE_GEOMETRY, RIGID_AERODYNAMICS
from bioflex_jsb.runtime.fdm import load_airframe
from bioflex_jsb.runtime.gust_loads import GustLoads, field_for
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.spanwise_gusts import (
    SpanStations,
    SpanwiseGustField,
    TailGust,
    rectangular_rolling_moment_n_m,
)

V = 15.0  # [m/s] the prototype's cruise (Table 1)


def _zoh(a: np.ndarray, b: np.ndarray, u: np.ndarray, dt: float) -> np.ndarray:
    """x_k of ẋ = A x + B u from rest, u held over each step (as the co-simulation holds
    its inputs over a JSBSim step)."""
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n], aug[:n, n:] = a, b
    e = expm(aug * dt)
    phi, gam = e[:n, :n], e[:n, n:]
    x = np.zeros((len(u), n))
    for k in range(len(u) - 1):
        x[k + 1] = phi @ x[k] + gam @ u[k]
    return x


def _nrmse(nonlinear: np.ndarray, linear: np.ndarray) -> float:
    return float(np.sqrt(np.mean((nonlinear - linear) ** 2)) / np.abs(linear).max())


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("optimised")


@pytest.fixture(scope="module")
def trimmed():
    airframe = load_airframe()
    airframe.set_dt(1 / 120)
    airframe.trim(V)
    return airframe


def test_gust_roll_hook_carries_the_strip_integral_of_a_linear_gust(trimmed):
    """With the C_lp of a rectangular wing's strips (−C_Lα/6, S = b c̄), the rolling moment
    JSBSim applies for w = −p_g y is the strip integral's closed form Q p_g C_lα c b³/(12 V)
    (JSBSim's own Q, V: 1e-9), and C_np's yawing moment goes with it."""
    airframe = trimmed
    ref = REFERENCE_GEOMETRY
    strips = SpanStations.rectangular(ref.span_m, ref.mean_chord_m, 5.3)
    aero = dataclasses.replace(RIGID_AERODYNAMICS, cl_p_per_rad=-5.3 / 6.0)
    field = SpanwiseGustField(parse_gust("none+roll:0.5:15"), V, strips, None, 0.0, 1.0,
                              1 / 120)
    loads = GustLoads(airframe, field, aero, 0.0)
    try:
        k = 60  # the middle of the 1 s gust: p_g = 0.5 rad/s
        loads.apply(k)
        q_pa = airframe[JP.AERO_QBAR_PSF] * U.PA_PER_PSF
        v = airframe["velocities/vt-fps"] * U.M_PER_FT
        airframe.run(1)
        roll = airframe["moments/l-external-lbsft"] * U.N_M_PER_LBF_FT
        yaw = airframe["moments/n-external-lbsft"] * U.N_M_PER_LBF_FT
    finally:
        loads.clear()
    p_g = loads.last[0]
    assert p_g == pytest.approx(0.5, rel=1e-12)
    closed = rectangular_rolling_moment_n_m(p_g, q_pa, v, 5.3, ref.mean_chord_m, ref.span_m)
    assert roll == pytest.approx(closed, rel=1e-6)
    assert yaw == pytest.approx(roll * RIGID_AERODYNAMICS.cn_p_per_rad / aero.cl_p_per_rad,
                                rel=1e-6)


def test_an_aircraft_without_gust_hooks_is_refused_in_one_line():
    class NoHooks:
        aircraft = "other"

        @staticmethod
        def property_node(name):
            raise KeyError(name)

    field = field_for(parse_gust("none+roll:0.5:15"), api.load_wing("optimised").airframe,
                      speed_m_s=V)
    with pytest.raises(InputError, match="no gust hooks"):
        GustLoads(NoHooks(), field, RIGID_AERODYNAMICS, 0.0)


def test_rolling_gust_rolls_the_aircraft_as_the_lateral_model_predicts(wing):
    """roll:0.5:15 (p_g 1-cos, 0.5 rad/s over 1 s) on the rigid aircraft: JSBSim's p against
    the rigid lateral model's (api.lateral_model, identified from the same airframe) response
    to the equivalent input B = −(A's aerodynamic p column) = [0, −L'_p, −N'_p, 0] p_g.
    Measured: peak p 0.4824 rad/s both (positive: right wing down, with p_g), NRMSE of p
    0.07 %, of r 2.7 %, of φ 1.5 % (the longitudinal coupling of the nonlinear run)."""
    run = api.fly_gust(wing, speed_m_s=V, gust="none+roll:0.5:15", models=("rigid",),
                       duration_s=4.0)["rigid"]
    lat = api.lateral_model(None, V)
    b = np.zeros((4, 1))
    b[1, 0], b[2, 0] = -lat.a[1, 1], -lat.a[2, 1]
    dt = float(run.time_s[1] - run.time_s[0])
    x = _zoh(lat.a, b, run.channels["p_g"][:, None], dt)
    p = run.channels["p_rad_s"]
    assert p.max() > 0.4 and abs(p.min()) < 0.05 * p.max()  # it rolls right, with p_g
    assert p.max() == pytest.approx(x[:, 1].max(), rel=0.01)
    assert _nrmse(p, x[:, 1]) < 0.01
    assert _nrmse(run.channels["r_rad_s"], x[:, 2]) < 0.05
    assert _nrmse(run.channels["phi_rad"], x[:, 3]) < 0.04
    assert run.channels["p_g"].max() == pytest.approx(0.5, rel=1e-3)


def test_lateral_gust_goes_through_jsbsims_wind_with_the_lateral_models_sign(wing):
    """lateral:1cos:2:15 (v_g to starboard): JSBSim's β (inertial), p, r against the lateral
    model's v_g input. Measured NRMSE 0.1-0.6 %, peaks within 1 %."""
    run = api.fly_gust(wing, speed_m_s=V, gust="none+lateral:1cos:2:15", models=("rigid",),
                       duration_s=4.0)["rigid"]
    lat = api.lateral_model(None, V)
    dt = float(run.time_s[1] - run.time_s[0])
    x = _zoh(lat.a, lat.b[:, :1], run.channels["v_g"][:, None], dt)
    for i, name in ((0, "beta_rad"), (1, "p_rad_s"), (2, "r_rad_s"), (3, "phi_rad")):
        assert _nrmse(run.channels[name], x[:, i]) < 0.02, name
    assert run.channels["r_rad_s"].max() == pytest.approx(x[:, 2].max(), rel=0.02)


def test_tail_penetration_delay_pitches_as_the_elevator_equivalent_input(wing):
    """1cos:3:20 with and without +tail: the difference of the rigid runs against the
    longitudinal model's response to the elevator that lifts the tail as the delay does,
    δe = a_t,S (1 − dε/dα) (w_t − w̄)/(V C_Lδe) (its moment follows: l_t = −c̄ C_mδe/C_Lδe).
    Measured: Δq peak −0.0883 (JSBSim) vs −0.0906 rad/s (LTI), Δα 0.0115 vs 0.0114 rad;
    the delay lowers the peak pitch rate from 0.398 to 0.330 rad/s."""
    runs = {g: api.fly_gust(wing, speed_m_s=V, gust=g, models=("rigid",),
                            duration_s=3.0)["rigid"] for g in ("1cos:3:20", "1cos:3:20+tail")}
    plain, delayed = runs["1cos:3:20"], runs["1cos:3:20+tail"]
    tail = TailGust.from_derivatives(RIGID_AERODYNAMICS, REFERENCE_GEOMETRY.mean_chord_m)
    w_t, w = delayed.channels["w_g_tail"], delayed.channels["w_g"]
    assert np.array_equal(w, plain.channels["w_g"])
    dt = float(plain.time_s[1] - plain.time_s[0])
    assert np.argmax(w_t) - np.argmax(w) == round(tail.arm_m / V / dt)  # 31 ms late
    elevator = tail.lift_slope_per_rad * (w_t - w) / (V * RIGID_AERODYNAMICS.cl_delta_e_per_rad)
    ss = api.linear_model(wing, speed_m_s=V, model="rigid")
    x = _zoh(ss.a, ss.b[:, 1:2], elevator[:, None], dt)
    for name in ("alpha", "q"):
        i = ss.states.index(name)
        diff = delayed.channels[name] - plain.channels[name]
        peak_nl, peak_li = diff[np.argmax(np.abs(diff))], x[np.argmax(np.abs(x[:, i])), i]
        assert peak_nl == pytest.approx(peak_li, rel=0.05), name
        assert _nrmse(diff, x[:, i]) < 0.06, name
    assert np.abs(delayed.channels["q"]).max() < 0.9 * np.abs(plain.channels["q"]).max()


def test_oblique_front_rolls_left_when_it_lifts_the_right_wing_first(wing):
    """sharp:1+front:30: the starboard wing meets the step first, its lift rolls the
    aircraft left (p < 0), and p_g's peak is −1.5 A/b-like (the lattice's weights)."""
    run = api.fly_gust(wing, speed_m_s=V, gust="sharp:1+front:30", models=("rigid",),
                       duration_s=1.5)["rigid"]
    p_g, p = run.channels["p_g"], run.channels["p_rad_s"]
    assert p_g.min() < -0.5 and p.min() < -0.3 and p.max() < 0.05
    assert math.isclose(run.channels["w_g"][-1], 1.0, rel_tol=1e-12)


def test_sitl_triggers_a_rolling_gust_from_its_parameters(wing):
    """GUST_ROLL_RADS 0.5 over GUST_LEN_M 15, the vertical amplitude 0, the autopilot off:
    GUST_TRIG rolls the rigid aircraft as the gust command does (peak p 0.48 rad/s); a
    parameter out of range is refused with its range."""
    from bioflex_jsb.drivers.sitl import SitlParameters, SitlSim

    sim = SitlSim(wing, wing.modes, model="rigid", speed_m_s=V)
    params = SitlParameters(sim)
    for name, value in (("AP_ENABLE", 0.0), ("GUST_AMP_MS", 0.0), ("GUST_ROLL_RADS", 0.5),
                        ("GUST_LEN_M", 15.0)):
        params.set(name, value)
    i_p = sim.names.index("p_rad_s")
    calm = [sim.step()[i_p] for _ in range(100)]
    params.set("GUST_TRIG", 1.0)
    assert params.get("GUST_TRIG") == 1.0
    rolled = [sim.step()[i_p] for _ in range(1500)]
    assert max(abs(p) for p in calm) < 1e-3  # the trim: 3e-5 rad/s (propeller torque)
    assert max(rolled) == pytest.approx(0.4824, rel=0.02)  # the gust command's peak
    with pytest.raises(ValueError, match="-2..2 rad/s"):
        params.set("GUST_ROLL_RADS", 3.0)


def test_compare_predicts_the_tail_delay_and_the_rolling_gust(wing):
    """compare on 1cos:1:20+tail (coupled): the tail delay's elevator-equivalent input in
    Eq. (4) keeps α within 2 % NRMSE (measured 1.4 %; without it the LTI would miss the
    delay's Δα of ~15 % of the peak) and the root shear within 3 % (1.7 %); none+roll:0.2:20
    (rigid): p, φ by the rigid lateral model within 1 % (0.15 %, 0.20 %; the prediction
    starts from the trim's bank, as the run does)."""
    c = api.compare(wing, V, gust="1cos:1:20+tail", model="coupled", duration_s=3.0)
    assert c.nrmse["alpha"] < 0.02 and c.nrmse["loads_fs_shear_n_s0"] < 0.03
    assert "p_rad_s" not in c.channels  # nothing rolls it
    r = api.compare(wing, V, gust="none+roll:0.2:20", model="rigid", duration_s=3.0)
    assert r.nrmse["p_rad_s"] < 0.01 and r.nrmse["phi_rad"] < 0.01
