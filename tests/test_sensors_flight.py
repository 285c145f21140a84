"""Sensor stations in flight: the coupled step's channels, the ArduPilot backend's IMU, the
MAVLink vehicle's HIGHRES_IMU and the MCAP topics (simulation/sensors.py wired in)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import units as U
from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.drivers.gust import run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters.sensors import (
    CG_IMU,
    ImuSpec,
    SensorNoise,
    Sensors,
    WingPoint,
)
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.run_config import RunConfig

ARMED_IDLE = (1500, 1500, 1050, 1500) + (0,) * 12
DT = 1.0 / 960.0


@pytest.fixture(scope="module")
def build():
    return build_wing(VARIANTS["optimised"])


def _tip(build, name="tip", chord_position=1.0, **kw) -> ImuSpec:
    """An IMU at the starboard tip's trailing edge of the prototype (the tip's leading edge
    0.1702 m aft of the root's, chord 0.183 m, elastic axis 0.22 c; CG 0.0549 m aft of the
    root leading edge: bioflex_optimised.toml)."""
    x_ea_frac = float(build.modes.x_elastic_frac[-1])
    x = 0.17015608451944958 + chord_position * 0.183
    return ImuSpec(name, (0.0549 - x, 0.85, 0.0),
                   wing=WingPoint(0.85, chord_position, 0.0,
                                  (chord_position - x_ea_frac) * 0.183), **kw)


def _fly(ph, n):
    for _ in range(n):
        ph.step(ARMED_IDLE, 1200)


def _todays_imu(ph):
    """The ArduPilot backend's IMU before sensor stations: JSBSim's total forces over its
    mass and its body rates, at the state the step reached."""
    get, k = ph.core.get, U.M_PER_FT / ph._mass()
    return ((ph._fx() * k, ph._fy() * k, ph._fz() * k), (get["p"](), get["q"](), get["r"]()))


@pytest.mark.parametrize("model, sensors", [
    ("coupled", None),                                  # no [sensors]: the CG, as before
    ("rigid", Sensors(imus=(ImuSpec("cg", (0.0, 0.0, 0.0), autopilot=True),))),
    ("coupled", Sensors(imus=(CG_IMU,))),               # at the CG the wing is not felt
])
def test_the_cg_imu_is_todays_to_the_bit(build, model, sensors):
    ph = ad.ArduPilotPhysics(Airframe(), build, model, gust=parse_gust("1cos:2:5"),
                             gust_at_s=0.05, sensors=sensors)
    _fly(ph, ph.launch_hold_steps + ph.stroke_steps)
    assert ph.phase == ad.FLIGHT
    sent = []
    for _ in range(400):
        _fly(ph, 1)
        st = ph.state()
        accel, gyro = _todays_imu(ph)
        assert st.accel_body_m_s2 == accel and st.gyro_rad_s == gyro
        sent.append(accel[2])
    assert np.ptp(sent) > 1.0  # the gust moved it: the comparison saw something


def test_a_wing_tip_autopilot_imu_feels_the_wing(build):
    """The autopilot's IMU at the tip's trailing edge reads the CG's specific force plus the
    wing's modes (a sharp gust rings them); its rows carry both IMUs, and what is sent at
    the state of t_{k+1} is the row of t_{k+1} but for the modal acceleration's estimate
    (the last step's mean, half a step old, against the central difference: at the first
    mode's 42 Hz and 960 Hz, ω Δt / 2 = 0.14 rad of phase, so within 20 % of the range)."""
    sensors = Sensors(imus=(_tip(build, autopilot=True), CG_IMU))
    ph = ad.ArduPilotPhysics(Airframe(), build, "coupled", gust=parse_gust("sharp:1"),
                             gust_at_s=0.05, sensors=sensors)
    assert ph.autopilot_imu.name == "tip"
    _fly(ph, ph.launch_hold_steps + ph.stroke_steps)
    diff, sent, rows = [], [], []
    for _ in range(400):
        _fly(ph, 1)
        st = ph.state()
        sent.append(st.accel_body_m_s2[2])
        diff.append(st.accel_body_m_s2[2] - _todays_imu(ph)[0][2])
        rows.append(ph._last_row)
    names = ph.core.names
    assert "imu_tip_az_m_s2" in names and "imu_cg_az_m_s2" in names
    tip_rows = np.array([r[names.index("imu_tip_az_m_s2")] for r in rows])
    cg_rows = np.array([r[names.index("imu_cg_az_m_s2")] for r in rows])
    assert np.ptp(diff) > 20.0 and np.ptp(tip_rows - cg_rows) > 20.0  # m/s²: the modes
    sent = np.array(sent)
    assert np.max(np.abs(sent[:-1] - tip_rows[1:])) < 0.2 * np.ptp(tip_rows)


def test_a_resend_repeats_the_noisy_sample(build):
    noisy = ImuSpec("cg", (0.0, 0.0, 0.0), autopilot=True,
                    noise=SensorNoise(accel_noise_m_s2=1.0, seed=3))
    ph = ad.ArduPilotPhysics(Airframe(), build, "coupled", sensors=Sensors(imus=(noisy,)))
    _fly(ph, ph.launch_hold_steps + ph.stroke_steps + 5)
    a, b = ph.state(), ph.state()
    assert a.accel_body_m_s2 == b.accel_body_m_s2
    _fly(ph, 1)
    assert ph.state().accel_body_m_s2 != a.accel_body_m_s2


def test_compiled_and_python_steps_give_the_same_sensor_channels(build):
    sensors = Sensors(imus=(_tip(build), CG_IMU))
    cfg = RunConfig(15.0, parse_gust("1cos:3:5"), 0.6, 0.1, 0.0, DT, models=("coupled",))
    runs = [run_gust(Airframe(), build.model, "coupled", cfg, compiled=c, sensors=sensors,
                     loads=build) for c in (True, False)]
    for name in runs[0].channels:
        if name.startswith("imu_"):
            a, b = runs[0][name], runs[1][name]
            assert np.max(np.abs(a - b)) <= 1e-9 * max(np.ptp(a), 1.0), name
    assert runs[0].meta["sensors"]["imus"][0]["name"] == "tip"


def _peak_hz(signal: np.ndarray, dt_s: float) -> float:
    """The frequency [Hz] of the largest spectral peak above 10 Hz: a Hann-windowed FFT
    zero-padded 16 times, the peak's bin refined by a parabola through its neighbours."""
    x = (signal - signal.mean()) * np.hanning(signal.size)
    n = 16 * signal.size
    spec = np.abs(np.fft.rfft(x, n))
    f = np.fft.rfftfreq(n, dt_s)
    i = int(np.argmax(np.where(f > 10.0, spec, 0.0)))
    a, b, c = np.log(spec[i - 1: i + 2])
    return float(f[i] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0]))


def test_the_tip_imu_rings_at_the_first_wing_mode_of_modes(build):
    """After a sharp gust in the linear regime (0.1 m/s) the tip accelerometer rings at the
    coupled model's first aeroelastic mode: its damped frequency from `modes` (api.modes,
    15 m/s, 42.02 Hz), measured +0.10 % (the spectral peak of a 2.5 s decay, ζ = 0.018);
    bar 0.5 %. (At 1 m/s the nonlinear run itself, η₁ as much as the sensor, rings 0.8 %
    higher.)"""
    from bioflex_jsb import api

    sensors = Sensors(imus=(_tip(build),))
    cfg = RunConfig(15.0, parse_gust("sharp:0.1"), 3.0, 0.5, 0.0, DT, models=("coupled",))
    run = run_gust(Airframe(), build.model, "coupled", cfg, sensors=sensors, loads=build)
    t = run.time_s
    measured = _peak_hz(run["imu_tip_az_m_s2"][t > 0.5], DT)
    mode = api.modes(build, 15.0).get("aeroelastic_1")
    expected = abs(mode.eigenvalue.imag) / (2 * math.pi)
    assert measured == pytest.approx(expected, rel=0.005)


def test_every_sensor_is_an_mcap_topic_holding_its_channels(build, tmp_path):
    """A gust run's log: one topic per IMU and per airspeed probe
    (/bioflex/<model>/imu_<name>, airspeed_<name>), a message per step holding exactly the
    history's channels; the file passes pymcap-cli's doctor."""
    import subprocess
    import sys
    from pathlib import Path

    from bioflex_jsb.parameters.sensors import AirspeedSpec
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks import mcap as sink
    from bioflex_jsb.sinks.mcap.reader import messages_by_topic

    sensors = Sensors(imus=(_tip(build), CG_IMU),
                      airspeeds=(AirspeedSpec("pitot", (0.3, 0.0, 0.0)),))
    cfg = RunConfig(15.0, parse_gust("sharp:1"), 0.3, 0.1, 0.0, DT, models=("coupled",))
    path = tmp_path / "sensors.mcap"
    log = sink.RunLog.open(path, RunDescription(kind="gust", wing="optimised", speed_m_s=15.0,
                                                gust="sharp:1", models=("coupled",),
                                                duration_s=0.3))
    try:
        run = run_gust(Airframe(), build.model, "coupled", cfg, sensors=sensors, loads=build,
                       recorder=log.recorder("coupled"))
    finally:
        log.close()
    msgs = messages_by_topic(path)
    tip = msgs[sink.topic("coupled", "imu_tip")]
    assert len(tip) == len(run.time_s)
    for field in ("ax_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s"):
        np.testing.assert_array_equal([m[field] for _, m in tip], run[f"imu_tip_{field}"])
    cg = msgs[sink.topic("coupled", "imu_cg")]
    np.testing.assert_array_equal([m["az_m_s2"] for _, m in cg], run["imu_cg_az_m_s2"])
    pitot = msgs[sink.topic("coupled", "airspeed_pitot")]
    np.testing.assert_array_equal([m["airspeed_m_s"] for _, m in pitot],
                                  run["airspeed_pitot_m_s"])
    exe = Path(sys.executable).with_name("pymcap-cli")
    if exe.exists():
        out = subprocess.run([str(exe), "doctor", str(path)], capture_output=True, text=True,
                             timeout=120)
        assert out.returncode == 0 and "error" not in out.stdout.lower(), out.stdout


@pytest.mark.parametrize("with_tip", [False, True])
def test_the_mavlink_vehicle_reports_its_autopilot_imu_as_highres_imu(build, with_tip):
    """The SITL vehicle's HIGHRES_IMU: without sensors the CG's specific force and the body
    rates (JSBSim's forces over the mass); with a wing-tip autopilot IMU its channels are in
    the rows and the message carries the tip's reading."""
    from pymavlink.dialects.v20 import common as mavlink

    from bioflex_jsb.drivers.sitl import SitlSim
    from bioflex_jsb.links.mavlink_telemetry import encode

    sensors = Sensors(imus=(_tip(build, autopilot=True),)) if with_tip else None
    sim = SitlSim(build, build.modes, sensors=sensors)
    sim.trigger_gust()
    for _ in range(300):
        sim.step()
    st = sim.vehicle_state()
    get, k = sim.core.get, U.M_PER_FT / sim.core.airframe["inertia/mass-slugs"]
    cg = tuple(sim.core.airframe[f"forces/fb{c}-total-lbs"] * k for c in "xyz")
    if with_tip:
        assert "imu_tip_az_m_s2" in sim.names
        assert st.imu_accel_m_s2 != cg
        assert abs(st.imu_accel_m_s2[2] - cg[2]) < 100.0  # the wing's modes, not nonsense
    else:
        assert st.imu_accel_m_s2 == cg
        assert st.imu_gyro_rad_s == (get["p"](), get["q"](), get["r"]())
        assert not any(n.startswith("imu_") for n in sim.names)
    mav = mavlink.MAVLink(None, srcSystem=1, srcComponent=1)
    (msg,) = encode(mav, mavlink.MAVLINK_MSG_ID_HIGHRES_IMU, st)
    back = mav.decode(bytearray(msg.pack(mav)))
    assert back.get_type() == "HIGHRES_IMU" and back.fields_updated == 0b111111
    assert back.zacc == pytest.approx(st.imu_accel_m_s2[2], rel=1e-6)  # a float32 field
    assert back.ygyro == pytest.approx(st.imu_gyro_rad_s[1], rel=1e-6, abs=1e-9)


def test_a_wing_sensor_without_the_mode_shapes_is_refused(build):
    from bioflex_jsb.errors import InputError

    cfg = RunConfig(15.0, parse_gust("sharp:1"), 0.1, 0.05, 0.0, DT, models=("coupled",))
    with pytest.raises(InputError, match="mode shapes"):
        run_gust(Airframe(), build.model, "coupled", cfg, sensors=Sensors(imus=(_tip(build),)))
