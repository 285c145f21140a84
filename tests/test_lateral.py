"""The rigid lateral-directional model (flight_dynamics/lateral.py) and its derivatives
identified from JSBSim (runtime/identification.py identify_lateral): against the c172p's own
XML coefficients, JSBSim's FGLinearization and central differences of JSBSim's state
derivatives, closed forms and the classical approximations."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.flight_dynamics.lateral import (
    LATERAL_INPUTS,
    LATERAL_STATES,
    LateralAerodynamics,
    LateralTrim,
    build_lateral_state_space,
    classical_approximations,
    lateral_derivatives,
    lateral_mode_labels,
    lateral_mode_set,
)
from bioflex_jsb.parameters.airframe import REFERENCE_GEOMETRY, ReferenceGeometry

jsbsim = pytest.importorskip("jsbsim")
PACKAGE = Path(jsbsim.get_default_root_dir()) / "aircraft"
M_PER_IN = 0.0254  # the inch, exact


def _zero_aero(**given) -> LateralAerodynamics:
    fields = {k: 0.0 for k in LateralAerodynamics.__dataclass_fields__}
    return LateralAerodynamics(**{**fields, **given})


def _trim(**changes) -> LateralTrim:
    base = dict(speed_m_s=20.0, density_kg_m3=1.225, alpha_rad=0.0, theta_rad=0.0,
                mass_kg=10.0, ixx_kg_m2=2.0, izz_kg_m2=3.0, ixz_kg_m2=0.0, area_m2=1.0,
                span_m=3.0)
    return LateralTrim(**{**base, **changes})


# -- the model alone (no JSBSim) ------------------------------------------------------------
def test_a_pure_roll_damper_has_the_closed_form_roll_root():
    """Only C_lp: the roll root is L_p = C_lp Q S b²/(2 V I_xx) exactly (the roll row is
    ṗ = L_p p alone; sideslip, yaw and bank of an aircraft without directional aerodynamics
    are neutral, roots at 0)."""
    trim = _trim()
    ss = build_lateral_state_space(trim, _zero_aero(cl_p=-0.5))
    q = 0.5 * 1.225 * 20.0**2
    lp = -0.5 * q * 1.0 * 3.0**2 / (2 * 20.0 * 2.0)
    lam = np.linalg.eigvals(ss.a)
    assert min(lam.real) == pytest.approx(lp, rel=1e-12)
    assert ss.states == LATERAL_STATES and ss.inputs == LATERAL_INPUTS
    assert ss.outputs[-1] == "n_y" and ss.output_units[-1] == "-"


def test_the_inertia_product_couples_roll_and_yaw_as_euler_equations_say():
    """With I_xz the primed derivatives are J⁻¹ [L, N]: a pure rolling moment L gives
    ṙ/ṗ = I_xz/I_zz (Etkin & Reid, Eq. 4.9,6)."""
    trim = _trim(ixz_kg_m2=0.4)
    d = lateral_derivatives(trim, _zero_aero(cl_delta_a=0.2))
    assert d.n_prime["delta_a"] / d.l_prime["delta_a"] == pytest.approx(0.4 / 3.0, rel=1e-12)


def test_the_gust_is_a_sideslip_and_n_y_the_side_force():
    """A lateral gust v_g is the sideslip −v_g/V in the aerodynamic terms: B[:, v_g] =
    −A[:, β]/V; n_y = Y/(m g) of β − v_g/V (a steady gust equal to the aircraft's sideslip
    V β loads nothing)."""
    aero = _zero_aero(cy_beta=-0.4, cl_beta=-0.1, cn_beta=0.06, cy_delta_r=0.2)
    ss = build_lateral_state_space(_trim(), aero)
    np.testing.assert_allclose(ss.b[:, 0], -ss.a[:, 0] / 20.0, rtol=0, atol=1e-15)
    x = np.array([0.01, 0.0, 0.0, 0.0])
    u = np.array([0.01 * 20.0, 0.0, 0.0])
    assert abs((ss.c @ x + ss.d @ u)[-1]) < 1e-15
    ny = (ss.c @ x)[-1]
    assert ny == pytest.approx(-0.4 * 0.5 * 1.225 * 400.0 * 0.01 / (10.0 * 9.80665), rel=1e-12)


def test_the_modes_are_labelled_by_kind_not_by_order():
    """One pair and two real roots: the pair is the Dutch roll, the faster real root the
    roll, the slower the spiral; four real roots: the roll is the root nearest L'_p."""
    lam = np.array([-0.5 + 2j, -0.5 - 2j, -8.0, 0.01])
    assert lateral_mode_labels(lam) == ("dutch_roll", "dutch_roll", "roll", "spiral")
    lam = np.array([-9.0, -3.0, -0.02, -0.8])
    assert lateral_mode_labels(lam, roll_estimate_rad_s=-2.5) == (
        "dutch_roll", "roll", "spiral", "dutch_roll")
    lam = np.array([-0.5 + 2j, -0.5 - 2j, -0.1 + 0.3j, -0.1 - 0.3j])
    assert lateral_mode_labels(lam) == ("dutch_roll", "dutch_roll", "roll_spiral",
                                        "roll_spiral")


# -- JSBSim aircraft ------------------------------------------------------------------------
def _jsbsim_point(name: str, speed: float):
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.runtime.identification import identify_lateral
    from bioflex_jsb.runtime.jsbsim_aircraft import probe

    if name == "bioflex":
        airframe, ref = Airframe(), REFERENCE_GEOMETRY
    else:
        path = str(PACKAGE / name / f"{name}.xml")
        values = probe(path)
        ref = ReferenceGeometry(values.reference_area_m2, values.span_m, values.mean_chord_m)
        airframe = Airframe.from_file(path, values.cg_m, name)
    return airframe, identify_lateral(airframe, speed, ref)


def test_c172p_lateral_derivatives_are_its_xml_coefficients():
    """c172p.xml (aerodynamics: CYb, CYp, CYr, CYdr, Clb, Clp, Clr, ClDa, Cldr, Cnb, Cnp,
    Cnr, Cnda, Cndr) at the 55 m/s trim, flaps up, carried to the identified derivatives'
    axes: its SIDE axis is in wind axes, so the body-axis C_Yβ holds −C_D at the perturbed
    states (the trim's C_D and its CDbeta of 0.17 |β| at β = ±1e-3); its moments are taken
    about the AERORP (43.2, 0, 59.4 in) and JSBSim carries them to the CG: ΔC_l =
    (z_arp − z_cg) C_Y/b, ΔC_n = −(x_arp − x_cg) C_Y/b (structural frame, z up); Cndr is on
    the propwash's dynamic pressure (aero/function/qbar-induced-psf over aero/qbar-psf at
    the trim); CYp, CYr, Clr are tables in α, read at the trim's. Measured: every derivative
    within 1e-9 relative but C_nβ, 7.4e-6 (4.5e-7 absolute: the carry from the AERORP
    above, whose arm x_arp − x_cg is 2.75 cm, is 4e-4 short of JSBSim's); 1e-5 still fails
    a change in the last digit the XML prints (0.0205 to 0.0206 is 5e-3)."""
    airframe, point = _jsbsim_point("c172p", 55.0)
    fdm = airframe.jsbsim
    b = point.trim.span_m
    dz = (fdm["metrics/aero-rp-z-in"] - fdm["inertia/cg-z-in"]) * M_PER_IN / b
    dx = (fdm["metrics/aero-rp-x-in"] - fdm["inertia/cg-x-in"]) * M_PER_IN / b
    induced = fdm["aero/function/qbar-induced-psf"] / fdm["aero/qbar-psf"]
    alpha = point.trim.alpha_rad

    def table(at_0: float, at_0094: float) -> float:  # the α tables, flaps 0 column
        return float(np.interp(alpha, (0.0, 0.094), (at_0, at_0094)))

    cy = {"beta": -0.137 / 0.349 - point.cd_trim - 0.17 * 1e-3, "p": table(-0.075, -0.145),
          "r": table(0.214, 0.267), "delta_a": 0.0, "delta_r": 0.187}
    cl = {"beta": -0.0322 / 0.349, "p": -0.484, "r": table(0.0798, 0.1869),
          "delta_a": 0.229, "delta_r": 0.0147}
    cn = {"beta": 0.0205 / 0.349, "p": -0.0278, "r": -0.0937, "delta_a": -0.0053,
          "delta_r": -0.0430 * induced}
    a = point.aero
    for k in ("beta", "p", "r", "delta_a", "delta_r"):
        expect = {"cy": cy[k], "cl": cl[k] + dz * cy[k], "cn": cn[k] - dx * cy[k]}
        for axis, value in expect.items():
            got = getattr(a, f"{axis}_{k}")
            assert got == pytest.approx(value, rel=1e-5, abs=1e-12), (axis, k, got, value)


# The lateral roots of the model built from the identified derivatives against JSBSim's own
# linear models of the same trim. Measured (roll / Dutch roll / spiral, |Δλ|/|λ|):
# c172p at 55 m/s against FGLinearization 0.003 % / 0.015 % / 0.11 % (the propeller's
# P-factor moments, which the aerodynamic derivatives leave out), the prototype at 15 m/s
# 1e-7 / 2e-7 / 1e-6 (its contra-rotating pair has none), the SGS at 30 m/s (a glider:
# central differences, FGLinearization needs an engine) 1e-8 or less. Tolerance 0.5 %.
LATERAL_CASES = [("c172p", 55.0, "FGLinearization"), ("bioflex", 15.0, "FGLinearization"),
                 ("SGS", 30.0, "central differences")]


@pytest.mark.parametrize("name, speed, method", LATERAL_CASES)
def test_the_lateral_roots_agree_with_jsbsims_linearisation(name, speed, method):
    airframe, point = _jsbsim_point(name, speed)
    ss = build_lateral_state_space(point.trim, point.aero)
    mine = lateral_mode_set(ss)
    lin = airframe.linearize_lateral(speed, method=method)
    assert lin.method == method
    theirs = lateral_mode_set(dataclasses.replace(ss, a=lin.a))
    for mode in ("roll", "spiral", "dutch_roll"):
        m, t = mine[mode].eigenvalue, theirs[mode].eigenvalue
        assert abs(m - t) <= 5e-3 * abs(t), (name, mode, m, t)


def test_jsbsims_product_of_inertia_is_minus_ixz():
    """JSBSim integrates J ω̇ = M with J₁₃ = its ``inertia/ixz-slugs_ft2`` (SGS.xml: −54.5
    slug·ft²): a pure rolling moment gives ṙ/ṗ = −J₁₃/I_zz, so I_xz = ∫ x z dm = −J₁₃, as
    identify_lateral stores it (measured ratio −J₁₃/I_zz to 1e-12)."""
    airframe, point = _jsbsim_point("SGS", 30.0)
    fdm = airframe.jsbsim

    def rates(moment_n_m: float):
        airframe.set_external_reactions(roll_moment_n_m=moment_n_m)
        fdm.run_ic()
        return np.array([fdm["accelerations/pdot-rad_sec2"], fdm["accelerations/rdot-rad_sec2"]])

    d = rates(1000.0) - rates(0.0)
    airframe.set_external_reactions()
    assert d[1] / d[0] == pytest.approx(point.trim.ixz_kg_m2 / point.trim.izz_kg_m2, rel=1e-9)
    assert point.trim.ixz_kg_m2 > 0.0  # SGS.xml's −54.5


@pytest.mark.parametrize("name, speed, method", LATERAL_CASES)
def test_the_classical_approximations_hold(name, speed, method):
    """Sanity checks (Nelson Sec. 5.6, Etkin & Reid Sec. 6.7): the roll root within 8 % of
    L'_p (measured c172p 1.4 %, prototype 0.4 %, SGS 6.6 %), the Dutch roll's ω_n within
    15 % of the sideslip-yaw approximation (c172p 8.4 %, prototype 5.8 %; not the SGS, 1.50
    against 0.82 rad/s: a sailplane's weak C_nβ, 0.017, and strong C_np, −0.18, make its
    Dutch roll a rolling motion the two-degree-of-freedom approximation leaves out), and
    the spiral stable exactly when E = L'_β N'_r − L'_r N'_β > 0 (Routh's last
    coefficient at θ_0 = 0; the prototype's estimates make E = 0, its spiral is set by the
    other terms)."""
    _, point = _jsbsim_point(name, speed)
    ss = build_lateral_state_space(point.trim, point.aero)
    modes = lateral_mode_set(ss)
    approx = classical_approximations(point.trim, point.aero)
    assert modes["roll"].re == pytest.approx(approx.roll_rad_s, rel=0.08)
    if name != "SGS":  # the sailplane's Dutch roll is a rolling one (module docstring)
        assert modes["dutch_roll"].frequency_rad_s == pytest.approx(
            approx.dutch_roll_frequency_rad_s, rel=0.15)
    d = lateral_derivatives(point.trim, point.aero)
    e = d.l_prime["beta"] * d.n_prime["r"] - d.l_prime["r"] * d.n_prime["beta"]
    if abs(e) > 1e-6 * abs(d.l_prime["beta"] * d.n_prime["r"]):  # the prototype's E = 0
        assert (modes["spiral"].re < 0.0) == (e > 0.0), (name, modes["spiral"].re, e)
    assert math.isfinite(approx.spiral_rad_s)


# -- the API and the command ----------------------------------------------------------------
def test_the_api_model_is_the_identified_one_with_named_signals():
    """api.lateral_model of the prototype at 15 m/s: its JSBSim airframe's derivatives, the
    typed estimates of parameters/airframe.py (C_lp −0.45, C_nr −0.08, C_lδa 0.20; the
    generated tables are linear in them: 1e-9), and python-control's model carries the
    names."""
    from bioflex_jsb import api
    from bioflex_jsb.parameters.airframe import RIGID_AERODYNAMICS as R

    ss = api.lateral_model(None, 15.0)
    d = ss.notes["derivatives"]
    for mine, typed in (("cl_p", R.cl_p_per_rad), ("cn_r", R.cn_r_per_rad),
                        ("cl_delta_a", R.cl_delta_a_per_rad), ("cn_beta", R.cn_beta_per_rad),
                        ("cn_delta_r", R.cn_delta_r_per_rad)):
        assert d[mine] == pytest.approx(typed, rel=1e-8), mine
    assert "not the paper's" in ss.notes["source"]
    sys_ctrl = ss.to_control()
    assert list(sys_ctrl.input_labels) == ["v_g", "aileron", "rudder"]
    assert list(sys_ctrl.output_labels) == ["beta", "p", "r", "phi", "n_y"]
    assert [m.mode for m in api.lateral_modes(None, [15.0, 20.0])[1]] == [
        "roll", "spiral", "dutch_roll"]


def test_modes_axis_lateral_lists_roll_spiral_and_dutch_roll(capsys):
    from tests.cli_helpers import run_cli

    code, out, _ = run_cli(capsys, "modes", "--axis", "lateral", "--aircraft", "sgs_elastic",
                           "--speed", "25", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["axis"] == "lateral" and data["aircraft"] == "sgs_elastic"
    names = [m["mode"] for m in data["results"][0]["modes"]]
    assert names == ["roll", "spiral", "dutch_roll"]
    # SGS.xml's Clp −0.47 (measured −0.469986 on the sgs_elastic definition's airframe)
    assert data["results"][0]["derivatives"]["cl_p"] == pytest.approx(-0.47, rel=1e-4)


@pytest.mark.parametrize("argv, needle", [
    (("--plot", "x.png"), "--plot does not apply"),
    (("--structural-damping", "0.02"), "--structural-damping does not apply"),
    (("--aircraft", "sgs_elastic", "--models", "coupled"), "use --models rigid"),
    (("--speed", "5"), "cannot trim at 5 m/s"),
])
def test_modes_axis_lateral_bad_input_is_one_line(capsys, tmp_path, monkeypatch, argv, needle):
    from tests.cli_helpers import assert_one_line_error, run_cli

    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(capsys, "modes", "--axis", "lateral", *argv)
    assert_one_line_error(code, err, needle)


# -- the wing's antisymmetric modes coupled (flight_dynamics/lateral_elastic.py) ----------------
def _c172_coupling(speed=None):
    from bioflex_jsb import api
    from bioflex_jsb.api import _lateral_point
    from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing

    aircraft = api.load_aircraft("c172_elastic")
    _, point = _lateral_point(aircraft, speed)
    return point, antisymmetric_wing(aircraft.wing(), point.trim.ixx_kg_m2)


def test_without_air_the_coupled_roots_are_the_rigid_and_structural_ones():
    """At a dynamic pressure 1e-12 of the trim's (the derivatives kept) the coupled model's
    roots are the rigid lateral model's and each antisymmetric mode's −ζω ± iω√(1 − ζ²)
    (measured within 1e-9 of each root's modulus)."""
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        build_lateral_elastic,
        strip_terms,
        with_density,
    )

    point, wing = _c172_coupling()
    trim = with_density(point.trim, point.trim.density_kg_m3 * 1e-12)
    coupled = build_lateral_elastic("coupled", trim, point.aero, wing)
    rigid = build_lateral_elastic("rigid", trim, point.aero, None)
    om, z = wing.modes.frequencies_rad_s, wing.modes.damping_ratios
    expect = np.concatenate([np.linalg.eigvals(rigid.a), -z * om + 1j * om * np.sqrt(1 - z**2),
                             -z * om - 1j * om * np.sqrt(1 - z**2)])
    got = np.linalg.eigvals(coupled.a)
    for e in expect:
        assert np.min(np.abs(got - e)) <= 1e-9 * max(abs(e), 1e-3), e
    t = strip_terms(wing, trim.dynamic_pressure_pa, trim.speed_m_s)
    assert np.all(np.abs(t.roll_eta) < 1e-6)


def test_the_antisymmetric_strips_give_the_strip_theory_roll_damping():
    """Strip theory's roll damping on the strips the modes' loads are summed on (the lift of
    Δα = p y/V: C_lp = −4 ∫ C_lα c y² dy / (S b²), Etkin & Reid Sec. 5.5) against JSBSim's
    C_lp −0.484 of c172p.xml: measured −0.598, 24 % more (strip theory with the symmetric
    loading's C_lα c has none of the antisymmetric loading's larger tip relief); within
    30 %. A sanity check of the strips' size and sign, not a validation."""
    point, wing = _c172_coupling()
    t = point.trim
    clp_strip = -4.0 * np.sum(wing.weights_m * wing.cl_alpha_c_m * wing.stations_m**2) / (
        t.area_m2 * t.span_m**2)
    assert clp_strip == pytest.approx(-0.484, rel=0.30)


def test_the_flexible_wing_changes_roll_damping_the_way_its_elastic_axis_says():
    """The c172's elastic axis lies aft of the aerodynamic centre (e > 0, 0.38 c against
    about 0.25 c): the down-going wing's extra lift twists it leading edge up, adding lift,
    so the flexible wing damps roll more than the rigid one, more so with speed (QSD L'_p
    over the rigid: measured 1.056 at 57.8 m/s, 1.082 at 68.9); the QSD roll root is the
    coupled one within 1 % (the modes at 82 rad/s and above are far from the roll's 8)."""
    from bioflex_jsb.flight_dynamics.lateral import lateral_mode_set
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        build_lateral_elastic,
        coupled_mode_set,
    )

    ratios = []
    for speed in (None, 68.9):
        point, wing = _c172_coupling(speed)
        assert np.all(wing.e_m > 0.0)
        rigid = build_lateral_elastic("rigid", point.trim, point.aero, None)
        qsd = build_lateral_elastic("qsd", point.trim, point.aero, wing)
        coupled = build_lateral_elastic("coupled", point.trim, point.aero, wing)
        ratios.append(qsd.a[1, 1] / rigid.a[1, 1])
        roll_c = coupled_mode_set(coupled, rigid, wing)["roll"].re
        assert lateral_mode_set(qsd)["roll"].re == pytest.approx(roll_c, rel=1e-2)
    assert 1.0 < ratios[0] < ratios[1]
    assert coupled.states[4:7] == ("eta1", "eta2", "eta3")
