"""The ArduPilot JSON backend with both wing halves (``ardupilot --span full``): the ailerons
ArduPlane commands load the antisymmetric modes through JSBSim's flight controls, as in
``sitl --span full`` (docs/lateral.md, "Both halves in the co-simulation"). Driven here by
servo frames without ArduPlane: the prototype's estimated outboard aileron is reversed at
15 m/s (`bioflex-jsb aileron --aircraft bioflex_optimised`: 12.8 m/s), so a right-aileron
servo step rolls the elastic aircraft left, the rigid one right."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.runtime.fdm import Airframe
from tests.cli_helpers import assert_one_line_error, run_cli

ARMED_IDLE = (1500, 1500, 1050, 1500)  # TKOFF_THR_IDLE 5 %: fires the launcher
RIGHT = (1510, 1500, 1050, 1500)  # servo 1 +10 µs: aileron command +0.02 (rolls right)
FLY_S = 0.3  # the step's duration [s]: within the roll's linear range
PEAK_RTOL = 0.01  # the open-loop roll's peak, linear against flown: measured below


@pytest.fixture(scope="module")
def prototype():
    return api.load_aircraft("bioflex_optimised")


def _roll_after_step(prototype, model: str, span: str):
    """(roll rate [rad/s] FLY_S after the aileron step, the physics) of a launch, 0.25 s at
    trim and the step."""
    ph = ad.ArduPilotPhysics(Airframe(), prototype.wing(), model, span=span,
                             aileron=prototype.definition.aileron)
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + int(round(0.25 / ph.dt_s))):
        ph.step(ARMED_IDLE + (0,) * 12, 1200)
    assert ph.phase == ad.FLIGHT
    p0 = ph.core.get["p"]()
    for _ in range(int(round(FLY_S / ph.dt_s))):
        ph.step(RIGHT + (0,) * 12, 1200)
    assert ph.summary()["stop_count"] == 0
    return ph.core.get["p"]() - p0, ph


def test_arduplanes_aileron_loads_the_antisymmetric_modes(prototype):
    """Measured: the roll rate 0.3 s after the step +0.0486 rad/s rigid, −0.1405 elastic
    (ratio −2.89; the same step flown by `gust` −2.978, the linear lateral model −2.980:
    docs/lateral.md "Validation"); asym_eta1 0.0119 rad, the tips twisted −0.0076 (port)
    and +0.0153 rad (starboard) with the symmetric part; the half wing's rows have no
    antisymmetric channels."""
    p_rigid, _ = _roll_after_step(prototype, "rigid", "full")
    p_elastic, ph = _roll_after_step(prototype, "coupled", "full")
    assert p_rigid > 0.0 and p_elastic < 0.0
    assert -3.3 < p_elastic / p_rigid < -2.5
    row = dict(zip(ph.core.names, ph._last_row, strict=True))
    assert abs(row["asym_eta1"]) > 1e-4 and row["aileron_rad"] > 1e-3  # JSBSim's δa, + right
    assert row["tip_twist_port_rad"] * row["tip_twist_starboard_rad"] < 0.0
    _, half = _roll_after_step(prototype, "coupled", "half")
    assert not any(n.startswith("asym_eta") for n in half.core.names)


FULL_RIGHT = (2000, 1500, 1050, 1500)  # servo 1 +500 µs: full right aileron


def test_a_diverged_antisymmetric_mode_is_named_as_such(prototype):
    """ArduPlane's full aileron at the launch (a real ArduPlane flight of the prototype with
    both halves stopped 0.26 s after it, docs/ardupilot.md): the first antisymmetric mode
    leaves the linear range (0.535 rad > 0.52 rad within 9 steps; its estimated aileron
    twists the light wing that much), and the stop must name that mode, asym_eta1, not a
    symmetric mode number the wing does not have."""
    ph = ad.ArduPilotPhysics(Airframe(), prototype.wing(), "coupled", span="full",
                             aileron=prototype.definition.aileron)
    while ph.phase != ad.FLIGHT:
        ph.step(ARMED_IDLE + (0,) * 12, 1200)
    for _ in range(int(round(0.1 / ph.dt_s))):
        ph.step(FULL_RIGHT + (0,) * 12, 1200)
        if ph.stops:
            break
    (stop,) = ph.summary()["stops"]
    n_symmetric = sum(1 for n in ph.core.names if n.startswith("eta") and "dot" not in n)
    assert "diverged" in stop["reason"]
    assert f"eta{n_symmetric + 1}" not in stop["reason"]
    assert "mode antisymmetric_1 diverged: |asym_eta1| = " in stop["reason"]


def test_native_wing_with_both_halves_is_refused(capsys):
    code, _, err = run_cli(capsys, "ardupilot", "--model", "native", "--span", "full",
                           "--duration", "1", "--no-log")
    assert_one_line_error(code, err, "--span full")


# -- scripts/ardupilot_full_span.py: the analysis of a flight's log -----------------------

# level: its trim throttle 0.754 and aileron 0.029 (docs/ardupilot.md, "Another aircraft")
C172_LEVEL = (1515, 1500, 1754, 1500)
ROLL_IN = (1715, 1500, 1754, 1450)  # servo 1 +200 µs (aileron +0.4), servo 4 −50 µs
LEVEL_S = 3.5  # level flight before the roll [s]: above the analysis' LEVEL_S (3 s)
ROLL_S = 2.0  # the roll's duration [s]: past 15 deg of bank


@pytest.fixture(scope="module")
def analysis():
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / "ardupilot_full_span.py"
    spec = importlib.util.spec_from_file_location("ardupilot_full_span_script", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def c172_roll_log(tmp_path_factory):
    """A c172_elastic session with both halves logged as `ardupilot` logs it: launched, level
    at 57.8 m/s, then an aileron and rudder step from servo frames (open loop). Returns (the
    log's path, JSBSim's rudder angle at every step [rad], the physics)."""
    from bioflex_jsb.links.ardupilot_json import STEP, FrameRecord
    from bioflex_jsb.runtime.control_power import measure_control_power
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
    from bioflex_jsb.simulation import jsbsim_properties as JP
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks import mcap as sink

    ac = api.load_aircraft("c172_elastic")
    channels = ad.aircraft_channels(measure_control_power(airframe_for(ac), 57.8, 0.0))
    ph = ad.ArduPilotPhysics(airframe_for(ac), ac.wing(), "coupled", speed_m_s=57.8,
                             channels=channels, span="full", aileron=ac.definition.aileron,
                             record_every=1)
    path = tmp_path_factory.mktemp("c172roll") / "session.mcap"
    desc = RunDescription(kind="ardupilot", wing="c172_elastic", speed_m_s=57.8, gust="none",
                          models=("coupled",), dt_s=ph.dt_s, extra={"autopilot": "ardupilot"})
    log = sink.RunLog.open(path, desc)
    ph.log_to(log)
    rudder = []
    n_launch = ph.launch_hold_steps + ph.stroke_steps
    n_level = n_launch + int(round(LEVEL_S / ph.dt_s))
    try:
        for n in range(n_level + int(round(ROLL_S / ph.dt_s))):
            base = ARMED_IDLE if n < n_launch else C172_LEVEL if n < n_level else ROLL_IN
            pwm = base + (0,) * 12
            flying = ph.phase == ad.FLIGHT  # the frame is a coupled step (a logged row)
            ph.step(pwm, 1200)
            if flying:  # the rudder JSBSim flew over that step
                rudder.append(ph.airframe[JP.FCS_RUDDER_POS_RAD])
            ph.on_frame(FrameRecord(n, 1200, pwm, STEP, ph.session_t_s, ("127.0.0.1", 1)))
        assert ph.summary()["stop_count"] == 0
    finally:
        log.close()
    # the session's --table, as the command writes it (cli/sitl_ardupilot.py)
    np.savez_compressed(path.with_suffix(".npz"), names=np.array(ph.record_names),
                        table=ph.table())
    return path, np.array(rudder), ph


def test_the_analysis_finds_the_roll_and_reads_the_surfaces_flown(analysis, c172_roll_log):
    """The script's reading of a session log: the roll's start from the rows, JSBSim's rudder
    from the frames' commands through the aircraft's rudder map, and the linear models driven
    by them reproduce the open-loop roll. Measured: the window from PRE_S before the step; the
    rudder read back to 1e-12 rad of JSBSim's; the peak roll rate 0.4494 rad/s flown, the
    coupled model's 0.4512 (0.4 %), the rigid model's 0.4727 (the elastic wing damps the
    roll: open-loop ratio 0.954); asym_eta1 up to 1.13e-4 rad, the modes' moment against p."""
    path, rudder, ph = c172_roll_log
    model, ch, frames = analysis._flight(path)
    assert model == "coupled"
    gain = analysis.rudder_gain_rad(api.load_aircraft("c172_elastic"))
    assert gain == pytest.approx(np.radians(16.0), rel=1e-3)  # c172p: ±16 deg of rudder
    t = ch["time_s"]
    read = gain * analysis.held(frames["time_s"], frames["rudder_cmd_norm"], t)
    assert read.size == rudder.size
    assert np.max(np.abs((read - read[0]) - (rudder - rudder[0]))) < 1e-12
    rep = analysis.flight_report(ch, frames, gain)
    assert len(rep["_windows"]) == 1
    t0 = rep["_windows"][0]["t0_s"]
    step_at = t[0] + LEVEL_S  # the first step of the roll's frames
    assert step_at - analysis.PRE_S - 0.01 < t0 < step_at - analysis.PRE_S + 0.01
    models = analysis.linear_models(api.load_aircraft("c172_elastic"), 57.8,
                                    float(rep["altitude_m_mean"]))
    turn = analysis.turn_figures(rep["_windows"][0], t, models)
    assert turn["coupled_model_peak_abs_p_rad_s"] == pytest.approx(
        turn["peak_abs_p_rad_s"], rel=PEAK_RTOL)
    assert turn["rigid_model_peak_abs_p_rad_s"] > turn["peak_abs_p_rad_s"]
    assert 0.94 < turn["open_loop_ratio"] < 0.99
    assert rep["peak_abs_asym_eta1_rad"] > 1e-5 and rep["tip_twists_opposite_at_peak_p"]
    assert rep["modal_roll_opposes_p_fraction"] > 0.9


def test_the_analysis_reads_the_sessions_table_as_its_log(analysis, c172_roll_log, tmp_path):
    """The session's --table (--record-every 1: a row a frame, the state after it, its
    servos) read as its log: the same rows (times one step later: the reply's), the rudder
    from servo 4 through the aircraft's channel map; a half wing's table, which has no
    aileron_rad, gets JSBSim's aileron from servo 1 through its aileron map (the c172p's
    15 deg down, 20 deg up): measured equal to the logged one to 1e-12 rad (one frame
    later: the row's aileron is JSBSim's as its step began)."""
    path, _, ph = c172_roll_log
    ac = api.load_aircraft("c172_elastic")
    _, ch, frames = analysis._flight(path)
    _, tab, tab_frames = analysis._flight_table(path.with_suffix(".npz"), ac)
    assert tab["time_s"].size == ch["time_s"].size  # one step a frame at 1200 Hz
    assert np.array_equal(tab["p_rad_s"], ch["p_rad_s"])
    assert np.allclose(tab["time_s"] - ch["time_s"], ph.dt_s, rtol=0.0, atol=1e-9)
    assert np.max(np.abs(tab_frames["rudder_cmd_norm"] - analysis.held(
        frames["time_s"], frames["rudder_cmd_norm"], ch["time_s"]))) < 1e-12
    gain = analysis.rudder_gain_rad(ac)
    rep_log = analysis.flight_report(ch, frames, gain)
    rep_tab = analysis.flight_report(tab, tab_frames, gain)
    assert rep_tab["_windows"][0]["t0_s"] == pytest.approx(
        rep_log["_windows"][0]["t0_s"] + ph.dt_s, abs=1e-9)
    assert rep_tab["peak_abs_p_rad_s"] == rep_log["peak_abs_p_rad_s"]
    up, down = analysis.aileron_gains_rad(ac)
    assert (up, down) == pytest.approx((np.radians(15.0), np.radians(20.0)), rel=1e-3)
    with np.load(path.with_suffix(".npz")) as z:  # as a half wing's table: no such column
        names = [str(n) for n in z["names"]]
        keep = [i for i, n in enumerate(names) if n != "aileron_rad"]
        half = tmp_path / "half.npz"
        np.savez_compressed(half, names=np.array([names[i] for i in keep]),
                            table=z["table"][:, keep])
    _, rebuilt, _ = analysis._flight_table(half, ac, need_modes=False)
    # a row's aileron_rad is JSBSim's as the step began: one frame behind its servo at one
    # step a frame (the first flight row: the trim's)
    assert np.max(np.abs(rebuilt["aileron_rad"][1:-1] - tab["aileron_rad"][2:])) < 1e-12
    assert np.ptp(tab["aileron_rad"]) > 0.1


def test_the_analysis_refuses_bad_input_in_one_line(analysis, c172_roll_log, capsys):
    """A missing log, a window out of range:
    exit 2 and one line."""
    path, _, _ = c172_roll_log
    for argv, words in (([str(path.with_name("missing.mcap"))], "no such log"),
                        ([str(path), "--window-s", "0.1"], "--window-s")):
        assert analysis.main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and words in err, err
