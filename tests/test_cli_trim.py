"""``bioflex-jsb trim`` and ``linearize``: output formats and one-line errors."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from bioflex_jsb import cli
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.runtime import fdm as jsbsim_fdm


def _run(capsys, argv):
    """Exit status of ``cli.main(argv)``: its return value, or the SystemExit code argparse
    raises for arguments it rejects itself."""
    try:
        code = cli.main(argv)
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def _assert_usage_error(code, out, err):
    assert code == 2
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


def test_trim_json_is_si_with_unit_keys(capsys):
    code, out, err = _run(capsys, ["trim", "--speed", "15", "--json"])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["speed_m_s"] == 15.0 and data["altitude_m"] == 0.0
    assert data["converged"] is True
    for key in ("alpha_rad", "theta_rad", "elevator_rad", "elevator_norm", "throttle"):
        assert math.isfinite(data[key])
    assert abs(data["alpha_rad"]) < 0.2  # radians, not degrees
    assert 0.0 < data["throttle"] < 1.0
    assert set(data["residuals"]) >= {"udot_m_s2", "wdot_m_s2", "qdot_rad_s2"}


def test_trim_table_has_degree_columns(capsys):
    code, out, err = _run(capsys, ["trim", "--speed", "20"])
    assert code == 0 and err == ""
    rows = {line.split()[0]: line for line in out.splitlines()[1:]}
    assert "deg" in rows["alpha"] and "deg" in rows["theta"]
    assert "throttle" in rows
    alpha_deg = float(rows["alpha"].split()[1])
    assert alpha_deg == pytest.approx(math.degrees(jsbsim_fdm.trim(20.0).alpha_rad), abs=0.01)


def test_linearize_json_keys_and_table3(capsys):
    code, out, err = _run(capsys, ["linearize", "--speed", "15", "--json"])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert list(data)[:4] == ["speed_m_s", "states", "A", "eigenvalues"]
    assert data["inputs"] == ["w_g", "elevator", "throttle"]
    assert len(data["B"]) == 4 and all(len(row) == 3 for row in data["B"])
    assert data["speed_m_s"] == 15.0
    assert data["states"] == ["u", "alpha", "q", "theta"]
    assert len(data["A"]) == 4 and all(len(row) == 4 for row in data["A"])
    assert [e["mode"] for e in data["eigenvalues"]] == ["short_period", "phugoid"]
    for e in data["eigenvalues"]:
        assert set(e) == {"mode", "re", "im", "damping", "frequency_rad_s"}
        assert e["im"] >= 0.0
    sp = data["eigenvalues"][0]
    re, im = P.TABLE3_SHORT_PERIOD[(15.0, "rigid")]
    # 5 %: the acceptance figure; Table 3 prints 2 significant digits
    assert sp["re"] == pytest.approx(re, rel=0.05) and sp["im"] == pytest.approx(im, rel=0.05)


def test_linearize_table(capsys):
    code, out, err = _run(capsys, ["linearize", "--speed", "20"])
    assert code == 0 and err == ""
    assert "short_period" in out and "phugoid" in out and "rad/s" in out


def test_help_explains_units(capsys):
    for command in ("trim", "linearize"):
        code, out, err = _run(capsys, [command, "--help"])  # main returns argparse's status
        assert code == 0 and err == ""
        assert "m/s" in out and "rad" in out


@pytest.mark.parametrize(
    ("command", "argv", "fragment"),
    [
        ("trim", ["--speed", "0"], "outside 5..40 m/s"),
        ("trim", ["--speed", "-4"], "outside 5..40 m/s"),
        ("trim", ["--speed", "nan"], "outside 5..40 m/s"),
        ("trim", ["--speed", "fast"], "must be a number"),
        ("trim", ["--speed", "15", "--altitude", "high"], "altitude"),
        ("trim", ["--speed", "15", "--altitude", "40000"], "altitude"),
        ("trim", ["--speed", "5"], "stall"),
        ("trim", ["--speed", "35"], "more thrust than the motor gives"),
        ("trim", ["--speed", "500"], "outside 5..40 m/s"),
        ("linearize", ["--speed", "0"], "outside 5..40 m/s"),
        ("linearize", ["--speed", "6"], "stall"),
        ("linearize", ["--speed", "35", "--json"], "throttle saturated"),
    ],
)
def test_bad_input_exits_2_with_one_line(capsys, command, argv, fragment):
    code, out, err = _run(capsys, [command, *argv])
    line = _assert_usage_error(code, out, err)
    assert fragment in line


def test_missing_aircraft_root(capsys, tmp_path):
    code, out, err = _run(capsys, ["trim", "--speed", "15", "--jsbsim-root", str(tmp_path)])
    line = _assert_usage_error(code, out, err)
    assert "no aircraft file" in line


def test_malformed_aircraft_file(capsys, tmp_path):
    craft = tmp_path / "aircraft" / "bioflex"
    craft.mkdir(parents=True)
    (tmp_path / "systems").mkdir()
    (craft / "bioflex.xml").write_text("<fdm_config name='bioflex'><metrics>", encoding="utf-8")
    code, out, err = _run(capsys, ["linearize", "--speed", "15", "--jsbsim-root", str(tmp_path)])
    line = _assert_usage_error(code, out, err)
    assert "not valid XML" in line


def test_aircraft_file_jsbsim_rejects(capsys, tmp_path):
    craft = tmp_path / "aircraft" / "bioflex"
    craft.mkdir(parents=True)
    (tmp_path / "systems").mkdir()
    (craft / "bioflex.xml").write_text(
        '<?xml version="1.0"?>\n<fdm_config name="bioflex" version="2.0" release="PRODUCTION">'
        "<fileheader/></fdm_config>\n",
        encoding="utf-8",
    )
    code, out, err = _run(capsys, ["trim", "--speed", "15", "--jsbsim-root", str(tmp_path)])
    line = _assert_usage_error(code, out, err)
    assert "JSBSim could not load" in line


def test_root_from_environment_is_not_skipped_when_wrong(capsys, tmp_path, monkeypatch):
    monkeypatch.setenv(jsbsim_fdm.ROOT_ENV_VAR, str(tmp_path / "nowhere"))
    code, out, err = _run(capsys, ["trim", "--speed", "15"])
    line = _assert_usage_error(code, out, err)
    assert jsbsim_fdm.ROOT_ENV_VAR in line and "not a directory" in line


def test_linearize_takes_an_aircraft_definition(capsys):
    """``linearize --aircraft sgs_elastic``: the glider's own JSBSim aircraft at its cruise
    speed (25 m/s), the analytic columns from its file (C_Lδe 0.342, C_mδe −1.0088; no
    engine: a zero throttle column and no thrust term), not the prototype's. Before, the
    name was refused and ``--aircraft SGS`` printed the prototype's B and phugoid."""
    from bioflex_jsb import api
    from bioflex_jsb.flight_dynamics.lti import control_columns
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    code, out, err = _run(capsys, ["linearize", "--aircraft", "sgs_elastic", "--json"])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["speed_m_s"] == 25.0 and data["inputs"] == ["w_g", "elevator", "throttle"]
    sgs = api.load_aircraft("sgs_elastic")
    lin = airframe_for(sgs).linearize(25.0)
    assert data["A"] == [[float(x) for x in row] for row in lin.a]  # the glider's, to the bit
    expected = control_columns(level_flight_condition(25.0, airframe=sgs.airframe_data()))
    b = [row[1:] for row in data["B"]]
    np.testing.assert_allclose(b, expected, rtol=1e-12, atol=1e-15)
    assert all(row[2] == 0.0 for row in data["B"])  # no engine
    assert data["phugoid_comparison"]["thrust_term_1_s"] == 0.0
    proto = json.loads(_run(capsys, ["linearize", "--speed", "25", "--json"])[1])
    assert b != [row[1:] for row in proto["B"]]


def test_linearize_of_a_bare_jsbsim_aircraft_prints_only_what_it_knows(capsys):
    """A JSBSim aircraft by name from another root (no definition): JSBSim's A and the gust
    column; no analytic columns or phugoid borrowed from the prototype."""
    import jsbsim

    code, out, err = _run(capsys, ["linearize", "--jsbsim-root", jsbsim.get_default_root_dir(),
                                   "--aircraft", "SGS", "--speed", "25", "--json"])
    assert code == 0 and err == ""
    data = json.loads(out)
    assert data["inputs"] == ["w_g"] and all(len(row) == 1 for row in data["B"])
    assert data["phugoid_comparison"] is None
    code, out, _ = _run(capsys, ["linearize", "--jsbsim-root", jsbsim.get_default_root_dir(),
                                 "--aircraft", "SGS", "--speed", "25"])
    assert code == 0 and "need the aircraft's analytic model" in out
    assert "Table B2" not in out and "propeller" not in out


def test_trim_wing_prints_the_jsbsim_elastic_trim_the_runs_fly(capsys):
    """``trim --wing`` is ``Airframe.trim(wing=)``: JSBSim's trim carrying the wing's static
    loads, the trim a run with ``--trim elastic`` starts from, and says so; not the linear
    airframe model's elastic trim (flight_dynamics.elastic_trim), which differs from it."""
    from bioflex_jsb.flight_dynamics.elastic_trim import elastic_trim
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.runtime.coupled_step import CoupledStep

    code, out, err = _run(capsys, ["trim", "--wing", "inertial-backward", "--speed", "15",
                                   "--json"])
    assert code == 0, err
    e = json.loads(out)["elastic"]
    assert e["trim"] == "jsbsim" and e["converged"]
    build = build_wing(VARIANTS["inertial-backward"])
    step = CoupledStep(jsbsim_fdm.Airframe(), build, "coupled", 15.0, trim_mode="elastic")
    flown = step.elastic_trim
    step.release()
    # the run configures its integrators and step before its trim: 2.2e-15 rad apart
    assert e["alpha_rad"] == pytest.approx(flown.alpha_rad, abs=1e-12)
    assert e["elevator_rad"] == pytest.approx(flown.elevator_rad, abs=1e-12)
    # measured at 15 m/s, sea level: alpha 1.1412 deg, elevator 0.2021 deg; the linear
    # model's elastic trim there is 1.1537 deg, 0.1932 deg (0.0125 deg and 0.0089 deg apart)
    assert math.degrees(e["alpha_rad"]) == pytest.approx(1.1412, abs=1e-4)
    assert math.degrees(e["elevator_rad"]) == pytest.approx(0.2021, abs=1e-4)
    linear = elastic_trim(build, 15.0, density_kg_m3=e["density_kg_m3"])  # JSBSim's ρ
    assert math.degrees(e["alpha_rad"] - linear.alpha_rad) == pytest.approx(-0.0125, abs=1e-3)
    assert math.degrees(e["elevator_rad"] - linear.elevator_rad) == pytest.approx(0.0089,
                                                                                 abs=1e-3)
    code, out, err = _run(capsys, ["trim", "--wing", "inertial-backward", "--speed", "15"])
    assert code == 0, err
    assert "JSBSim's trim with the wing's static loads" in out
