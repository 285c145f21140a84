"""The aileron's actuator ([aileron.actuator]) in the lateral models and the aileron's
unsteady (Theodorsen) terms on the unsteady strips (aeroelasticity/actuated_aileron.py,
docs/lateral.md "The aileron's actuator and unsteady flap")."""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aerodynamics.indicial import JONES_WAGNER, jones_c
from bioflex_jsb.aerodynamics.theodorsen import flap_section_loads, theodorsen_c
from bioflex_jsb.aeroelasticity.actuated_aileron import (
    flap_strip_loads,
    step_response,
    with_actuator,
)
from bioflex_jsb.aeroelasticity.control_surface import SurfaceActuator, strip_coverage
from bioflex_jsb.definition import DefinitionError, load_definition
from bioflex_jsb.definition.aircraft import Aircraft
from bioflex_jsb.definition.loader import shipped_path
from tests.cli_helpers import assert_one_line_error, run_cli

ROOT = Path(__file__).resolve().parents[1]
FIXTURE = ROOT / "tests" / "fixtures" / "lateral_without_actuator.npz"
SCRIPT = ROOT / "scripts" / "aileron_actuator_response.py"
ACTUATOR_TABLE = "[aileron.actuator]\nnatural_frequency_rad_s = 40.0\ndamping_ratio = 0.7\n"


def _script():
    spec = importlib.util.spec_from_file_location("aileron_actuator_response", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def c172():
    """The c172_elastic with the script's estimated aileron and 40 rad/s, ζ 0.7 actuator."""
    return _script().c172_with_aileron()


# --------------------------------------------------------------------------------------
# the definition
# --------------------------------------------------------------------------------------
def _with(tmp_path, tables: str) -> Path:
    path = tmp_path / "c172_actuated.toml"
    text = shipped_path("c172_elastic").read_text(encoding="utf-8")
    path.write_text(text + "\n[aileron]\nspan = [0.55, 0.97]\nhinge = 0.75\n" + tables,
                    encoding="utf-8")
    return path


def test_actuator_is_read_and_absent_is_none(tmp_path):
    d = load_definition(_with(tmp_path, ACTUATOR_TABLE))
    assert d.aileron_actuator == SurfaceActuator(40.0, 0.7)
    assert load_definition(_with(tmp_path, "")).aileron_actuator is None
    assert api.load_aircraft("bioflex_optimised").definition.aileron_actuator is None


BAD = [
    ("natural_frequency_rad_s = 0.5\ndamping_ratio = 0.7", "natural_frequency_rad_s",
     "1..1000"),
    ("natural_frequency_rad_s = 5000.0\ndamping_ratio = 0.7", "natural_frequency_rad_s",
     "not Hz"),
    ("natural_frequency_rad_s = 40.0\ndamping_ratio = 70", "damping_ratio",
     "70 % of critical is 0.7"),
    ("natural_frequency_rad_s = 40.0\ndamping_ratio = 0.05", "damping_ratio", "0.1..3"),
    ("natural_frequency_rad_s = 40.0", "damping_ratio", "missing"),
    ("natural_frequency_rad_s = nan\ndamping_ratio = 0.7", "natural_frequency_rad_s",
     "finite number"),
    ("natural_frequency_rad_s = 40.0\ndamping_ratio = 0.7\nbandwidth_hz = 6",
     "aileron.actuator", "unknown key 'bandwidth_hz'"),
]


@pytest.mark.parametrize(("table", "field", "reason"), BAD)
def test_bad_actuator_is_one_line_naming_the_field(tmp_path, table, field, reason):
    with pytest.raises(DefinitionError, match=re.escape(field)) as info:
        load_definition(_with(tmp_path, "[aileron.actuator]\n" + table + "\n"))
    assert reason in str(info.value) and "\n" not in str(info.value)


def test_actuator_not_a_table_and_cli_exit_2(tmp_path, capsys):
    path = tmp_path / "c172_bad.toml"
    path.write_text(shipped_path("c172_elastic").read_text(encoding="utf-8")
                    + "\n[aileron]\nspan = [0.55, 0.97]\nhinge = 0.75\nactuator = 40\n",
                    encoding="utf-8")
    with pytest.raises(DefinitionError, match=re.escape("aileron.actuator")):
        load_definition(path)
    code, _, err = run_cli(capsys, "modes", "--axis", "lateral", "--aircraft",
                           str(_with(tmp_path, "[aileron.actuator]\n"
                                               "natural_frequency_rad_s = 0.1\n"
                                               "damping_ratio = 0.7\n")))
    assert_one_line_error(code, err, "natural_frequency_rad_s")


# --------------------------------------------------------------------------------------
# without an actuator: the models as they were
# --------------------------------------------------------------------------------------
def test_without_actuator_every_array_is_unchanged():
    """The prototype's four lateral models (rigid, coupled, qsd, unsteady coupled) at its
    cruise, every A, B, C, D array equal to those of the models before the actuator existed
    (the fixture: the same four models built by the code just before the actuator was
    merged; measured here: bit for bit). Tolerance 1e-12 of each array's largest entry: a
    LAPACK solve on another processor may differ in its last bits (~1e-15 relative for
    these well-conditioned E matrices), while a 0.1 % change of any term moves its entries
    by 1e-3 relative."""
    ref = np.load(FIXTURE)
    ac = api.load_aircraft("bioflex_optimised")
    for model, aero in (("rigid", "quasi-steady"), ("coupled", "quasi-steady"),
                        ("qsd", "quasi-steady"), ("coupled", "unsteady")):
        ss = api.lateral_model(ac, None, model, aero=aero)
        assert "aileron" in ss.inputs and "aileron_actuator" not in ss.notes
        for k in "abcd":
            want = ref[f"{model}-{aero}-{k}"]
            np.testing.assert_allclose(np.asarray(getattr(ss, k)), want, rtol=0.0,
                                       atol=1e-12 * max(float(np.max(np.abs(want))), 1e-300),
                                       err_msg=f"{model} {aero} {k}")


# --------------------------------------------------------------------------------------
# with an actuator
# --------------------------------------------------------------------------------------
def test_actuator_step_is_the_second_order_response(c172):
    """The aileron state after an aileron_cmd step is the closed-form second-order step
    1 − e^{−ζωt} (cos ω_d t + ζ/√(1−ζ²) sin ω_d t), ω_d = ω √(1 − ζ²), in every model (the
    actuator does not feel the aircraft), and A's eigenvalues hold −ζω ± iω_d: measured
    5.6e-16 (rigid, qsd), 2.1e-14 (unsteady, through E⁻¹) and 9e-17 relative."""
    w, z = 40.0, 0.7
    wd = w * math.sqrt(1.0 - z * z)
    t = np.array([0.01, 0.03, 0.05, 0.1, 0.2, 0.5])
    closed = 1.0 - np.exp(-z * w * t) * (np.cos(wd * t) + z / math.sqrt(1.0 - z * z)
                                          * np.sin(wd * t))
    for model, aero in (("rigid", "quasi-steady"), ("qsd", "quasi-steady"),
                        ("coupled", "unsteady")):
        ss = api.lateral_model(c172, None, model, aero=aero)
        assert ss.inputs == ("v_g", "aileron_cmd", "rudder")
        assert ss.states[-2:] == ("aileron", "aileron_dot")
        y = step_response(ss, "aileron_cmd", 1.0, t)
        got = y[:, ss.outputs.index("aileron")]
        assert np.max(np.abs(got - closed)) < 1e-12, (model, got - closed)
        lam = np.linalg.eigvals(ss.a)
        root = complex(-z * w, wd)
        assert np.min(np.abs(lam - root)) < 1e-9 * w, model


def test_actuator_in_series_without_the_flap_terms(c172):
    """The coupled model behind the actuator is the coupled model without it in series
    with the actuator (with_actuator): arrays equal; and the unsteady model without the
    flap terms (flap_terms=False) has the frequency response of the unsteady model
    without an actuator times the actuator's ω²/(ω² − Ω² + 2iζωΩ): measured 1.6e-13."""
    bare = Aircraft(dataclasses.replace(c172.definition, aileron_actuator=None))
    act = c172.definition.aileron_actuator
    plain = api.lateral_model(bare, None, "coupled")
    series = with_actuator(plain, act)
    actuated = api.lateral_model(c172, None, "coupled")
    for k in "abcd":
        assert np.array_equal(getattr(series, k), getattr(actuated, k)), k
    uns = api.lateral_model(bare, None, "coupled", aero="unsteady")
    uns_act = api.lateral_model(c172, None, "coupled", aero="unsteady", flap_terms=False)
    assert "quasi-steady load only" in uns_act.notes["aileron_unsteady"]
    col, col_a = uns.inputs.index("aileron"), uns_act.inputs.index("aileron_cmd")
    rows = [uns.outputs.index(n) for n in ("p", "r", "eta1", "n_y")]
    rows_a = [uns_act.outputs.index(n) for n in ("p", "r", "eta1", "n_y")]
    w, z = act.natural_frequency_rad_s, act.damping_ratio
    worst = 0.0
    for om in (0.3, 3.0, 30.0, 100.0):
        s = 1j * om

        def fr(ss, c, r, s=s):
            x = np.linalg.solve(s * np.eye(ss.n_states) - ss.a, ss.b[:, c])
            return ss.c[r] @ x + ss.d[r, c]
        g = fr(uns, col, rows) * w * w / (w * w + s * s + 2.0 * z * w * s)
        worst = max(worst, float(np.max(np.abs(fr(uns_act, col_a, rows_a) - g)
                                        / np.abs(g))))
    assert worst < 1e-9, worst


def test_flap_terms_vanish_in_a_steady_state(c172):
    """The aileron's unsteady terms vanish in a steady state (δ̇ = 0, the lags settled at
    their share of the upwash): the steady response to aileron_cmd is the quasi-steady
    coupled model's (measured 3.6e-15 relative)."""
    qs = api.lateral_model(c172, None, "coupled")
    uns = api.lateral_model(c172, None, "coupled", aero="unsteady")
    assert "Theodorsen" in uns.notes["aileron_unsteady"]
    x_qs = -np.linalg.solve(qs.a, qs.b[:, qs.inputs.index("aileron_cmd")])
    x_un = -np.linalg.solve(uns.a, uns.b[:, uns.inputs.index("aileron_cmd")])
    keep = [uns.states.index(s) for s in qs.states]
    assert np.max(np.abs(x_un[keep] - x_qs)) < 1e-10 * np.max(np.abs(x_qs))


def test_strip_flap_loads_are_theodorsens_section_with_jones_lag():
    """The rolling moment of the aileron's strips at a harmonic δa (the quasi-steady flap
    lift the base model carries plus the unsteady increments of flap_strip_loads, the lags
    solved at Ω) equals the strip integral of Theodorsen's flap lift with Jones's C(k) per
    strip (flap_section_loads; circulatory part × C_lα c/2πc, apparent mass thin-plate) to
    1e-12 (measured 4.3e-16); against the exact C(k) the lag's error is measured (the
    tolerance beside it)."""
    from tests.test_antisymmetric_flutter import _lateral_subject

    point, _wing, strips, surface, _chord = _lateral_subject(
        api.load_aircraft("bioflex_optimised"), 15.0)
    v, rho = point.trim.speed_m_s, point.trim.density_kg_m3
    k = strips.n_strips
    n_all = 2 * k + 2
    lags = (slice(0, k), slice(k, 2 * k))
    roll_x, roll_xd, _fx, _fxd, lag_a, *_side = flap_strip_loads(strips, surface, n_all, lags,
                                                         2 * k, 2 * k + 1, v, rho)
    chi = strip_coverage(strips.weights_m, surface)
    b = 0.5 * strips.chord_m
    c_hinge = 2.0 * surface.hinge - 1.0
    half = 0.5 * rho * v * strips.cl_alpha_c_m
    worst_exact = 0.0
    for om in (0.5, 5.0, 20.0, 80.0):
        s = 1j * om
        u = np.zeros(n_all, dtype=complex)
        u[2 * k], u[2 * k + 1] = 1.0, s  # δa = e^{iΩt}
        # lags: ẋ = lag_a x (their own decay is strip_loads' diagonal, here by hand)
        rate = np.concatenate([JONES_WAGNER.exponents[j] * v / b for j in range(2)])
        lag = (lag_a[:, 2 * k:] @ u[2 * k:]) / (s + rate)
        u[:2 * k] = lag
        # the lags' own lift (strip_loads carries it, on every strip)
        lag_lift = half * (lag[:k] + lag[k:])
        qs_lift = -half * chi * v * (
            np.array([flap_section_loads(0, 0, 1, 0.0, speed_m_s=v, semichord_m=bj,
                                         elastic_axis_a=aj, hinge_c=c_hinge,
                                         density_kg_m3=rho)[0].real for bj, aj
                      in zip(b, strips.a, strict=True)]) / (2.0 * np.pi * rho * v * v * b))
        roll = (roll_x @ u + roll_xd @ (s * u)
                - 2.0 * (strips.weights_m * strips.stations_m) @ (lag_lift + qs_lift))

        def theodorsen(c_of_k, om=om):
            lift = np.zeros(k, dtype=complex)
            for j in np.flatnonzero(chi):
                kk = om * b[j] / v
                nc = flap_section_loads(0, 0, -1.0, om, speed_m_s=v, semichord_m=b[j],
                                        elastic_axis_a=strips.a[j], hinge_c=c_hinge,
                                        density_kg_m3=rho, circulation=0.0)[0]
                circ = flap_section_loads(0, 0, -1.0, om, speed_m_s=v, semichord_m=b[j],
                                          elastic_axis_a=strips.a[j], hinge_c=c_hinge,
                                          density_kg_m3=rho,
                                          circulation=complex(c_of_k(kk)))[0] - nc
                lift[j] = chi[j] * (nc + circ * strips.cl_alpha_c_m[j] / (4.0 * np.pi
                                                                           * b[j]))
            return -2.0 * (strips.weights_m * strips.stations_m) @ lift
        want = theodorsen(jones_c)
        assert abs(roll - want) < 1e-12 * abs(want), (om, roll, want)
        exact = theodorsen(theodorsen_c)
        worst_exact = max(worst_exact, abs(want - exact) / abs(exact))
    # Jones's lag against the exact C(k) on the prototype's aileron strips, Ω 0.5..80 rad/s
    # (reduced frequencies up to about 0.6): measured 2.36 %, C(k)'s own error
    assert worst_exact < 0.03, worst_exact


def test_roll_rate_after_a_command_step_with_and_without_the_t_terms(c172):
    """scripts/aileron_actuator_response.py: the c172 (estimated aileron, 40 rad/s ζ 0.7
    actuator) at its 57.8 m/s cruise, p after a 0.5 deg aileron_cmd step. Measured: p(0.1 s)
    0.01078 rad/s with the Theodorsen terms against 0.01686 without (−36.1 %: the
    circulatory flap lift starts at Wagner's half and grows with the wake's lag);
    p(0.02 s) +27 % (the apparent mass's δ̈ lift while the surface accelerates); by 2 s
    within 1.3 %. The tolerances: the sign and size of the early loss (−20 % … −50 %) and
    the late agreement (5 %)."""
    res = _script().roll_rate_response(c172)
    assert res["speed_m_s"] == pytest.approx(57.8)
    ch = dict(zip(res["times_s"], res["change"], strict=True))
    assert -0.5 < ch[0.1] < -0.2, ch
    assert ch[0.02] > 0.0, ch
    assert abs(ch[2.0]) < 0.05, ch
    assert res["without_t_terms"][2] == pytest.approx(0.01686, rel=2e-3)
    assert res["with_t_terms"][2] == pytest.approx(0.01078, rel=2e-3)


def test_cli_lists_the_actuator_and_unchanged_modes(tmp_path, capsys):
    """modes --axis lateral --aero unsteady of an actuated aircraft: the actuator in the
    JSON; the modes those of the same aircraft without it (the actuator's roots are its
    own)."""
    path = _with(tmp_path, ACTUATOR_TABLE)
    (tmp_path / "plain").mkdir()
    plain = _with(tmp_path / "plain", "")
    argv = ("modes", "--axis", "lateral", "--models", "coupled", "--aero", "unsteady",
            "--json")
    code, out, _ = run_cli(capsys, *argv, "--aircraft", str(path))
    assert code == 0
    with_act = json.loads(out)
    code, out, _ = run_cli(capsys, *argv, "--aircraft", str(plain))
    assert code == 0
    without = json.loads(out)
    r = with_act["results"][0]
    assert "40 rad/s" in r["aileron_actuator"] and "Theodorsen" in r["aileron_unsteady"]
    assert "aileron_actuator" not in without["results"][0]
    assert r["modes"] == without["results"][0]["modes"]


def test_modes_help_states_the_checked_ranges(capsys):
    """modes --help's [aileron.actuator] ranges are the definition's checks."""
    from bioflex_jsb.definition.ranges import (
        ACTUATOR_DAMPING_RANGE,
        ACTUATOR_FREQUENCY_RANGE_RAD_S,
    )

    code, out, _ = run_cli(capsys, "modes", "--help")
    assert code == 0
    flat = " ".join(out.split())
    lo, hi = ACTUATOR_FREQUENCY_RANGE_RAD_S
    assert f"natural_frequency_rad_s ({lo:g}..{hi:g} rad/s)" in flat
    lo, hi = ACTUATOR_DAMPING_RANGE
    assert f"damping_ratio ({lo:g}..{hi:g})" in flat
