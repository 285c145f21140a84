"""The generated JSBSim airframe: one source, clean load, coefficients as rendered, hooks."""

from __future__ import annotations

import math
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import units as U
from bioflex_jsb.aerodynamics.propeller import propeller_tables
from bioflex_jsb.generators import airframe as X
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import POST_STALL, PROPULSION, RIGID_AERODYNAMICS
from bioflex_jsb.runtime import fdm as jsbsim_fdm
from bioflex_jsb.runtime.engines import zero_thrust_advance_ratio
from tests.tools import env_program

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def airframe() -> jsbsim_fdm.Airframe:
    return jsbsim_fdm.load_airframe(REPO)


def test_committed_files_are_the_generated_rendering():
    rendered = X.render_all()
    assert set(rendered) == {
        "aircraft/bioflex/bioflex.xml",
        "aircraft/bioflex/Engines/bioflex_motor.xml",
        "aircraft/bioflex/Engines/bioflex_propeller.xml",
        "aircraft/bioflex/reset_cruise.xml",
        "aircraft/bioflex_trim/bioflex_trim.xml",
        "aircraft/bioflex_trim/Engines/bioflex_motor.xml",
        "aircraft/bioflex_trim/Engines/bioflex_trim_propeller.xml",
        "systems/bioflex_flight_controls.xml",
    }
    for rel, text in rendered.items():
        committed = (REPO / rel).read_text(encoding="utf-8")
        assert committed == text, f"{rel} is stale: run python -m bioflex_jsb.generators.airframe"


def test_write_all_writes_a_loadable_root(tmp_path):
    written = X.write_all(tmp_path)
    assert len(written) == len(X.render_all()) and all(p.is_file() for p in written)
    af = jsbsim_fdm.load_airframe(tmp_path)
    assert af.root == tmp_path.resolve()
    assert af.trim_aircraft == X.TRIM_AIRCRAFT_NAME
    assert af.warnings == []


def test_loads_without_warnings_in_python(airframe):
    # JSBSim printed its usual startup report (captured), and nothing at WARN level or above,
    # for the flying aircraft and for its trim companion (loaded beside it)
    assert airframe.trim_aircraft == X.TRIM_AIRCRAFT_NAME
    assert len(airframe.load_messages) > 10
    assert len(airframe.trim_load_messages) > 10
    assert airframe.warnings == []
    # the engine and propeller were found in aircraft/bioflex/Engines/
    assert airframe.engine_count == PROPULSION.rotor_count == 2
    assert airframe.total_thrust_n == pytest.approx(0.0, abs=1e-9)
    assert "Could not" not in " ".join(r.text for r in airframe.load_messages)


@pytest.mark.parametrize("aircraft", [X.AIRCRAFT_NAME, X.TRIM_AIRCRAFT_NAME])
def test_each_aircraft_file_loads_alone_without_warnings(aircraft):
    af = jsbsim_fdm.load_airframe(REPO, aircraft)
    assert len(af.load_messages) > 10
    assert af.warnings == []
    assert af.engine_count == PROPULSION.rotor_count
    text = " ".join(r.text for r in af.load_messages)
    assert "Could not" not in text and aircraft in text


def test_trim_companion_differs_only_in_the_rotor_inertia():
    flying = (REPO / "aircraft/bioflex/bioflex.xml").read_text(encoding="utf-8")
    companion = (REPO / "aircraft/bioflex_trim/bioflex_trim.xml").read_text(encoding="utf-8")
    changed = [
        (a, b)
        for a, b in zip(flying.splitlines(), companion.splitlines(), strict=True)
        if a != b
    ]
    assert changed and all(
        X.AIRCRAFT_NAME in a and X.TRIM_AIRCRAFT_NAME in b or "description" in a
        for a, b in changed
    )
    assert (REPO / "aircraft/bioflex_trim/Engines/bioflex_motor.xml").read_text() == (
        REPO / "aircraft/bioflex/Engines/bioflex_motor.xml"
    ).read_text()
    engines = REPO / "aircraft/bioflex/Engines"
    phys = ET.parse(engines / "bioflex_propeller.xml").getroot()
    eff = ET.parse(REPO / "aircraft/bioflex_trim/Engines/bioflex_trim_propeller.xml").getroot()
    ixx_phys = float(phys.findtext("ixx")) / U.SLUG_FT2_PER_KG_M2 * PROPULSION.rotor_count
    ixx_eff = float(eff.findtext("ixx")) / U.SLUG_FT2_PER_KG_M2 * PROPULSION.rotor_count
    assert ixx_phys == pytest.approx(PROPULSION.rotor_inertia_kg_m2, rel=1e-8)
    assert ixx_eff == pytest.approx(PROPULSION.trim_rotor_inertia_kg_m2, rel=1e-8)
    assert ixx_eff > 5.0 * ixx_phys  # effective (trim iteration) vs physical
    for tag in ("diameter", "numblades", "constspeed"):
        assert phys.findtext(tag) == eff.findtext(tag)
    for name in ("C_THRUST", "C_POWER"):
        q = f"table[@name='{name}']/tableData"
        assert phys.find(q).text == eff.find(q).text


def test_console_program_runs_a_script_without_warnings(tmp_path):
    exe = env_program("jsbsim")  # the jsbsim package's console script
    script = tmp_path / "smoke.xml"
    script.write_text(
        '<?xml version="1.0"?>\n'
        '<runscript name="bioflex smoke">\n'
        '  <use aircraft="bioflex" initialize="reset_cruise"/>\n'
        '  <run start="0.0" end="0.25" dt="0.008333333"/>\n'
        "</runscript>\n",
        encoding="utf-8",
    )
    proc = subprocess.run(
        [exe, f"--root={REPO}", "--nohighlight", str(script)],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=tmp_path,
    )
    output = proc.stdout + proc.stderr
    assert proc.returncode == 0, output[-2000:]
    assert "Reading Aircraft Configuration File: bioflex" in output
    assert "JSBSim Execution beginning" in output
    for word in ("warning", "error", "ignored", "could not", "not found"):
        assert word not in output.lower(), f"{word!r} in the console output"


def _xml() -> ET.Element:
    return ET.parse(REPO / "aircraft/bioflex/bioflex.xml").getroot()


def _function_value(root: ET.Element, name: str) -> float:
    """The single <value> of the product function ``name`` (the coefficient)."""
    f = root.find(f".//function[@name='{name}']")
    assert f is not None, name
    values = f.findall("product/value")
    assert len(values) == 1, name
    return float(values[0].text)


def _table(root: ET.Element, name: str) -> np.ndarray:
    data = root.find(f".//function[@name='{name}']//tableData")
    return np.array([[float(x) for x in line.split()] for line in data.text.strip().splitlines()])


def test_lift_table_linear_range_and_stall():
    cl = _table(_xml(), "aero/bioflex/cl-alpha")
    alpha, c = cl[:, 0], cl[:, 1]
    aero = RIGID_AERODYNAMICS
    # the issue asks for at least -20..+30 deg
    assert alpha.min() <= math.radians(-20.0) and alpha.max() >= math.radians(30.0)
    linear = (alpha >= math.radians(-10.0) - 1e-9) & (alpha <= aero.alpha_stall_rad + 1e-9)
    slope, intercept = np.polyfit(alpha[linear], c[linear], 1)
    assert slope == pytest.approx(aero.cl_alpha_per_rad, rel=1e-6)
    assert intercept == pytest.approx(aero.cl0, rel=1e-6)
    # stall: the peak is C_L,max just past the linear range, and the lift falls off beyond
    k = int(np.argmax(c))
    assert c[k] == pytest.approx(aero.cl_max, rel=1e-6)
    assert aero.alpha_stall_rad < alpha[k] < math.radians(14.0)
    assert c[alpha >= math.radians(20.0)].max() < 0.5 * aero.cl_max
    assert np.all(np.diff(c[(alpha > alpha[k]) & (alpha <= math.radians(18.0))]) < 0.0)
    # negative stall below -10 deg
    assert c[alpha < POST_STALL.alpha_negative_stall_rad].min() > c[linear].min() - aero.cl_max
    # trim searches alpha only up to the lift peak
    lim = _xml().find("aerodynamics/alphalimits")
    assert float(lim.findtext("max")) == pytest.approx(math.degrees(alpha[k]), rel=1e-6)


def test_rendered_coefficients_are_the_parameters():
    root = _xml()
    aero = RIGID_AERODYNAMICS
    expected = {
        "aero/moment/pitch-alpha": aero.cm_alpha_per_rad,
        "aero/moment/pitch-q": aero.cm_q_per_rad,
        "aero/moment/pitch-alphadot": aero.cm_alphadot_per_rad,
        "aero/moment/pitch-elevator": aero.cm_delta_e_per_rad,
        "aero/moment/roll-p": aero.cl_p_per_rad,
        "aero/moment/yaw-r": aero.cn_r_per_rad,
        "aero/force/drag-cd0": aero.cd0,
        "aero/bioflex/cl-elevator": aero.cl_delta_e_per_rad,
    }
    for name, value in expected.items():
        assert _function_value(root, name) == pytest.approx(value, rel=1e-8), name
    # damping terms use JSBSim's rate normalisation c/(2V) and b/(2V)
    props = [e.text for e in root.find(".//function[@name='aero/moment/pitch-q']/product")]
    assert "aero/ci2vel" in props and "velocities/q-aero-rad_sec" in props
    props = [e.text for e in root.find(".//function[@name='aero/moment/pitch-alphadot']/product")]
    assert "aero/ci2vel" in props and "aero/alphadot-rad_sec" in props
    # C_Lq = C_Lalphadot = 0: no rate term anywhere in the LIFT axis
    lift_props = {e.text for e in root.iterfind(".//axis[@name='LIFT']//property")}
    lift_props |= {
        e.text for e in root.iterfind(".//function[@name='aero/bioflex/cl-total']//property")
    }
    assert not any("q-aero" in p or "alphadot" in p for p in lift_props)


def test_propeller_tables_are_plausible_and_size_the_motor():
    j, ct, cp = propeller_tables(PROPULSION)
    # static thrust and power coefficients in the range of 12-inch thin-electric propellers
    assert 0.08 < ct[0] < 0.14 and 0.03 < cp[0] < 0.07
    eta = j * ct / np.where(cp > 0, cp, np.nan)
    assert 0.6 < np.nanmax(eta) < 0.85  # peak propulsive efficiency
    k = int(np.argmax(ct <= 0.0))
    j0 = float(j[k - 1] + (j[k] - j[k - 1]) * ct[k - 1] / (ct[k - 1] - ct[k]))
    assert 0.6 < j0 < 1.0 and j[-1] > j0  # the table runs past zero thrust
    # and the runtime reads the same zero-thrust point from the file JSBSim flies
    path = jsbsim_fdm.aircraft_file(REPO, jsbsim_fdm.DEFAULT_AIRCRAFT)
    assert zero_thrust_advance_ratio(path) == pytest.approx(j0, rel=1e-9)


def test_hand_derived_short_period_matches_jsbsim_linearization():
    """2x2 short period built from the numbers in the generated XML, against JSBSim.

    The 2x2 approximation (alpha, q) neglects the coupling with the speed mode, an effect of
    order (phugoid/short-period frequency)^2 ~ 1 %: tolerance 2 % on re and im."""
    root = _xml()
    s_m2 = float(root.findtext("metrics/wingarea")) / U.FT2_PER_M2
    c_m = float(root.findtext("metrics/chord")) / U.FT_PER_M
    mass_kg = float(root.findtext("mass_balance/emptywt")) * U.N_PER_LBF / P.STANDARD_GRAVITY_M_S2
    iyy = float(root.findtext("mass_balance/iyy")) / U.SLUG_FT2_PER_KG_M2
    cl = _table(root, "aero/bioflex/cl-alpha")
    lin_rows = (cl[:, 0] > -0.1) & (cl[:, 0] < 0.1)
    cl_alpha = np.polyfit(cl[lin_rows, 0], cl[lin_rows, 1], 1)[0]
    cd0 = _function_value(root, "aero/force/drag-cd0")
    k = _function_value(root, "aero/force/drag-induced")
    cm_a = _function_value(root, "aero/moment/pitch-alpha")
    cm_q = _function_value(root, "aero/moment/pitch-q")
    cm_ad = _function_value(root, "aero/moment/pitch-alphadot")
    for v in (15.0, 20.0):
        qs = 0.5 * P.SEA_LEVEL_DENSITY_KG_M3 * v**2 * s_m2
        cl_trim = mass_kg * P.STANDARD_GRAVITY_M_S2 / qs
        z_a = -(cl_alpha + cd0 + k * cl_trim**2) * qs / mass_kg  # thrust ≈ drag
        m_a = cm_a * qs * c_m / iyy
        m_q = cm_q * qs * c_m**2 / (2 * iyy * v)
        m_ad = cm_ad * qs * c_m**2 / (2 * iyy * v)
        a2 = np.array([[z_a / v, 1.0], [m_a + m_ad * z_a / v, m_q + m_ad]])
        hand = np.linalg.eigvals(a2)
        hand = hand[np.argmax(hand.imag)]
        sp = jsbsim_fdm.linearize(v, root=REPO).mode("short_period")
        assert sp.re == pytest.approx(hand.real, rel=0.02)
        assert sp.im == pytest.approx(hand.imag, rel=0.02)


def test_external_reactions_apply_si_inputs_in_body_axes(airframe):
    airframe.set_initial_conditions(15.0)
    airframe.set_external_reactions(
        lift_n=2.0, drag_n=0.5, pitch_moment_n_m=0.3, roll_moment_n_m=-0.1
    )
    airframe.run(1)
    assert airframe["forces/fbz-external-lbs"] == pytest.approx(-2.0 * U.LBF_PER_N, rel=1e-9)
    assert airframe["forces/fbx-external-lbs"] == pytest.approx(-0.5 * U.LBF_PER_N, rel=1e-9)
    assert airframe["moments/m-external-lbsft"] == pytest.approx(0.3 * U.LBF_FT_PER_N_M, rel=1e-9)
    assert airframe["moments/l-external-lbsft"] == pytest.approx(-0.1 * U.LBF_FT_PER_N_M, rel=1e-9)
    # forces act at the CG: no moment from them
    airframe.set_external_reactions(lift_n=5.0)
    airframe.run(1)
    assert airframe["moments/m-external-lbsft"] == pytest.approx(0.0, abs=1e-12)
    assert X.external_property("modal-lift") == "external_reactions/modal-lift/magnitude"
    airframe.set_external_reactions()
    airframe.run(1)
    assert airframe["forces/fbz-external-lbs"] == 0.0


def test_flight_controls_scale_to_the_deflection_limits(airframe):
    airframe.set_initial_conditions(15.0)
    airframe["fcs/elevator-cmd-norm"] = 0.5
    airframe["fcs/pitch-trim-cmd-norm"] = 0.8  # sum clipped at the stop
    airframe["fcs/aileron-cmd-norm"] = 0.25
    airframe.run(1)
    from bioflex_jsb.parameters.airframe import CONTROL_LIMITS as L

    assert airframe["fcs/elevator-pos-norm"] == pytest.approx(1.0)
    assert airframe["fcs/elevator-pos-rad"] == pytest.approx(L.elevator_max_rad)
    assert airframe["fcs/left-aileron-pos-rad"] == pytest.approx(0.25 * L.aileron_max_rad)
    assert airframe["fcs/right-aileron-pos-rad"] == pytest.approx(-0.25 * L.aileron_max_rad)
    airframe["fcs/elevator-cmd-norm"] = 0.0
    airframe["fcs/pitch-trim-cmd-norm"] = 0.0
    airframe["fcs/aileron-cmd-norm"] = 0.0


def test_motor_power_is_the_parameter():
    # each motor of the contra-rotating pair has half the total shaft power
    root = ET.parse(REPO / "aircraft/bioflex/Engines/bioflex_motor.xml").getroot()
    assert root.tag == "electric_engine"
    power = float(root.findtext("power")) * PROPULSION.rotor_count
    assert power == pytest.approx(PROPULSION.motor_max_shaft_power_w, rel=1e-9)
    assert root.find("power").get("unit") == "WATTS"


def test_propulsion_is_a_contra_rotating_pair():
    """Two identical engines and propellers at one point, opposite senses; each propeller
    has half the tables and half the inertia of the single equivalent propeller."""
    engines = _xml().findall("propulsion/engine")
    assert len(engines) == 2
    assert {e.get("file") for e in engines} == {X.ENGINE_FILE}
    thrusters = [e.find("thruster") for e in engines]
    assert [float(t.findtext("sense")) for t in thrusters] == [1.0, -1.0]
    locations = {tuple(t.findtext(f"location/{a}") for a in "xyz") for t in thrusters}
    assert len(locations) == 1
    prop = ET.parse(REPO / "aircraft/bioflex/Engines/bioflex_propeller.xml").getroot()
    ixx = float(prop.findtext("ixx")) / U.SLUG_FT2_PER_KG_M2
    assert ixx == pytest.approx(PROPULSION.rotor_inertia_kg_m2 / 2, rel=1e-8)  # physical
    _, ct, cp = propeller_tables(PROPULSION)
    for name, full in (("C_THRUST", ct), ("C_POWER", cp)):
        text = prop.find(f"table[@name='{name}']/tableData").text
        half = np.array([float(line.split()[1]) for line in text.strip().splitlines()])
        np.testing.assert_allclose(half, full / 2, rtol=1e-8)
    with pytest.raises(ValueError):
        type(PROPULSION)(**{**PROPULSION.__dict__, "rotor_count": 1})


def test_one_throttle_lever_drives_both_motors(airframe):
    airframe.set_initial_conditions(15.0)
    airframe["fcs/throttle-cmd-norm"] = 0.3
    airframe.run(5)
    assert airframe["fcs/throttle-pos-norm[0]"] == pytest.approx(0.3)
    assert airframe["fcs/throttle-pos-norm[1]"] == pytest.approx(0.3)
    rpm0 = airframe["propulsion/engine[0]/propeller-rpm"]
    assert rpm0 > 0.0 and airframe["propulsion/engine[1]/propeller-rpm"] == rpm0
    # opposite spin: the propellers' reaction torques and angular momenta cancel
    assert airframe["moments/l-prop-lbsft"] == pytest.approx(0.0, abs=1e-12)
    assert airframe["moments/n-prop-lbsft"] == pytest.approx(0.0, abs=1e-12)
    airframe["fcs/throttle-cmd-norm"] = 0.0


def test_time_step_and_property_nodes(airframe):
    airframe.set_dt(1.0 / 240.0)
    airframe.linearize(15.0)  # FGLinearization zeroes the step; the adapter puts it back
    assert airframe.dt_s == pytest.approx(1.0 / 240.0)
    node = airframe.property_node("velocities/vt-fps")
    assert node.get_double_value() * U.M_PER_FT == pytest.approx(15.0, rel=1e-3)
    with pytest.raises(KeyError):
        airframe.property_node("velocities/no-such-property")
    with pytest.raises(KeyError):
        airframe["fcs/elevatr-cmd-norm"] = 0.1  # a typo must not create a new property
    with pytest.raises(ValueError):
        airframe.set_dt(0.0)
    airframe.set_dt(1.0 / 120.0)


def test_per_step_loop_helpers_match_the_public_ones(airframe):
    """step() inside capturing() is run(1); the writer is set_external_reactions."""
    airframe.set_initial_conditions(15.0)
    write = airframe.external_reaction_writer()
    with airframe.capturing():
        write(2.0, 0.5, 0.3)
        airframe.step()
    assert airframe["forces/fbz-external-lbs"] == pytest.approx(-2.0 * U.LBF_PER_N, rel=1e-12)
    assert airframe["forces/fbx-external-lbs"] == pytest.approx(-0.5 * U.LBF_PER_N, rel=1e-12)
    assert airframe["moments/m-external-lbsft"] == pytest.approx(
        0.3 * U.LBF_FT_PER_N_M, rel=1e-12
    )
    t0 = airframe["simulation/sim-time-sec"]
    with airframe.capturing():
        for _ in range(3):
            airframe.step()
    assert airframe["simulation/sim-time-sec"] == pytest.approx(t0 + 3 * airframe.dt_s)
    airframe.set_external_reactions()


def test_the_capturing_logger_keeps_each_message_whole_with_its_level_and_nothing_else():
    """JSBSim's per-step set_level/flush pairs with nothing said in between keep nothing;
    a message keeps its level (an int), its location and its text, and none of it leaks into
    the next (the logger's cheap path for silent steps, runtime/jsbsim_log.py)."""
    import jsbsim

    from bioflex_jsb.runtime.jsbsim_log import CapturingLogger

    log = CapturingLogger()
    for _ in range(3):  # silent steps
        log.set_level(jsbsim.LogLevel.INFO)
        log.flush()
    assert log.records == []
    log.set_level(jsbsim.LogLevel.WARN)
    log.file_location("FGTrim.cpp", 12)
    log.message("trim failed")
    log.flush()
    log.set_level(jsbsim.LogLevel.INFO)
    log.message("   ")  # whitespace only: not kept
    log.flush()
    log.set_level(jsbsim.LogLevel.ERROR)
    log.message("second")
    log.set_level(jsbsim.LogLevel.INFO)  # a new message before the flush drops the old parts
    log.message("third")
    log.flush()
    assert [(r.level, r.text) for r in log.records] == [
        (int(jsbsim.LogLevel.WARN), "FGTrim.cpp:12: trim failed"),
        (int(jsbsim.LogLevel.INFO), "third")]
    assert all(type(r.level) is int for r in log.records)
