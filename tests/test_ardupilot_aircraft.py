"""``bioflex-jsb ardupilot --aircraft`` on another JSBSim aircraft (JSBSim's c172p with its
elastic wing, ``c172_elastic``): the JSON physics over its own airframe, driven by the
byte-exact ArduPilot stand-in (tests/ardupilot_standin.py): lock-step at rest, the launch,
the servos mapped to its commands in the directions its own model gives them (each PWM
above trim moving it the way ArduPilot means), the command line; and the ArduPlane parameter
file written for it from its envelope and its JSBSim model, checked against the closed
forms it states."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.generators import ardupilot_params as AP
from bioflex_jsb.runtime.control_power import measure_control_power
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from tests.cli_helpers import assert_one_line_error, run_cli
from tests.test_ardupilot_driver import ARMED_IDLE, DISARMED, Link, _cli_session, _free_port

SPEED_M_S = 57.8
G = ad.G0_M_S2
SHIPPED = Path(ad.__file__).resolve().parents[1] / "data" / "ardupilot" / "bioflex_plane.parm"


@pytest.fixture(scope="module")
def c172():
    aircraft = api.load_aircraft("c172_elastic")
    power = measure_control_power(airframe_for(aircraft), SPEED_M_S, 0.0)
    return aircraft, power


@pytest.fixture()
def link(c172):
    aircraft, power = c172
    physics = ad.ArduPilotPhysics(airframe_for(aircraft), aircraft.wing(), "coupled",
                                  speed_m_s=SPEED_M_S,
                                  channels=ad.aircraft_channels(power))
    lk = Link(physics)
    yield lk
    lk.close()


def test_the_c172s_servo_directions_are_its_models(c172):
    """c172p: +aileron command rolls right (+10.5 rad/s² per unit), +elevator pitches nose
    down (−14.2), +rudder yaws left (−1.54): PWM above trim maps to +aileron, −elevator,
    −rudder (the prototype's map); a model whose elevator is the other way round gets the
    other direction."""
    import dataclasses

    aircraft, power = c172
    assert power.roll_rad_s2 > 0 > power.pitch_rad_s2 and power.yaw_rad_s2 < 0
    channels = ad.aircraft_channels(power)
    assert [(c.prop, c.sign) for c in channels] == [(c.prop, c.sign) for c in ad.CHANNEL_MAP]
    flipped = ad.aircraft_channels(dataclasses.replace(power, pitch_rad_s2=14.0))
    assert flipped[1].sign == +1.0 and flipped[1].prop == "fcs/elevator-cmd-norm"


def _launch(link):
    ph = link.physics
    for _ in range(ph.launch_hold_steps + ph.stroke_steps):
        link.frame(ARMED_IDLE)
    assert ph.phase == ad.FLIGHT


def test_rest_launch_and_the_servos_move_the_c172_as_arduPilot_means(link):
    """At rest: lock-step, (0, 0, −g) rotated by the trim's pitch, airspeed 0. Launched to
    its 57.8 m/s. Then 2 s of throttle at 2000 after 2 s at 1000 adds thrust (the body-x
    specific force); 0.15 s of each surface at PWM 1750 (half a command above trim)
    against 1500: roll rate up (right), pitch rate up (nose up), yaw rate up (nose right)
    more than with the trim PWM."""
    ph = link.physics
    for n in range(1, 51):
        p = link.frame(DISARMED)
        assert link.ap.frame_counter == n
    ax, ay, az = p.values["accel_body"]
    assert math.sqrt(ax * ax + ay * ay + az * az) == pytest.approx(G, rel=1e-6)
    assert p.values["airspeed"] == 0.0 and ph.core.k == 0
    _launch(link)
    assert ph.airframe["velocities/vt-fps"] * 0.3048 == pytest.approx(SPEED_M_S, rel=1e-3)
    assert ph.airframe["propulsion/engine[0]/set-running"] == 1.0  # its engine runs

    def rates(pwm, frames=144):  # 0.15 s at 960 frames a second
        for _ in range(frames):
            p = link.frame(pwm)
        return p.values["gyro"], p.values["accel_body"][0]

    trim_pwm = (1500, 1500, 1750, 1500)
    _, ax_lo = rates((1500, 1500, 1000, 1500), 1920)
    _, ax_hi = rates((1500, 1500, 2000, 1500), 1920)
    # the propeller's speed follows the engine with a time constant of about a second, and
    # the aircraft slows at idle: measured −1.29 and +0.59 m/s² after 2 s each
    assert ax_hi > ax_lo + 1.0, (ax_lo, ax_hi)
    (p0, q0, r0), v0 = rates(trim_pwm)
    (p1, _, _), _ = rates((1750, 1500, 1750, 1500))
    assert p1 > p0 + 0.05, (p0, p1)  # rad/s: roll right
    rates(trim_pwm)
    (_, q1, _), _ = rates((1500, 1750, 1750, 1500))
    assert q1 > q0 + 0.05, (q0, q1)  # nose up
    rates(trim_pwm)
    (_, _, r1), _ = rates((1500, 1500, 1750, 1750))
    assert r1 > r0 + 0.01, (r0, r1)  # nose right
    assert ph.stops == []


def test_the_command_line_flies_the_c172(tmp_path, capsys):
    """``ardupilot --aircraft c172_elastic`` with the stand-in: its cruise speed, a session
    of 0.1 s at rest, exit 0 (it refused every airframe but the prototype's, naming
    commands that failed for it)."""
    summary = tmp_path / "s.json"
    rc, _ = _cli_session(["--aircraft", "c172_elastic", "--duration", "0.1", "--no-log",
                          "--summary", str(summary)], _free_port())
    assert rc == 0
    s = json.loads(summary.read_text())
    assert s["frames"]["steps"] >= 96 and s["phase"] == "rest" and s["stops"] == []
    err = capsys.readouterr().err
    assert "c172_elastic" in err and "Traceback" not in err


def test_the_command_line_logs_the_c172s_session(tmp_path, capsys):
    """``ardupilot --aircraft c172_elastic`` writing its MCAP log (as scripts/ardupilot_sitl.py
    fly's physics does without --no-log): the session runs and the log holds its frames. Found
    flying ArduPlane (docs/ardupilot.md, "Both wing halves with a real ArduPlane"; the
    session failed before it listened, for either span: the scene rebuilt the wing from its
    variant, whose beam is a digest string for an aircraft's wing.)"""
    from bioflex_jsb.cli import build_parser
    from bioflex_jsb.sinks import mcap as sink

    out = tmp_path / "c172.mcap"
    args = build_parser().parse_args(["ardupilot", "--port", str(_free_port()), "--aircraft",
                                      "c172_elastic", "--duration", "0.1", "--out", str(out)])
    opened = {}
    real_open = sink.RunLog.open

    def spy(*a, **kw):  # the log is opened before the session listens: no stand-in needed
        opened["log"] = real_open(*a, **kw)
        raise SystemExit(0)

    import bioflex_jsb.sinks.mcap.log as log_module

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(log_module.RunLog, "open", spy)
        with pytest.raises(SystemExit):
            args.run(args)
    opened["log"].close()
    assert out.is_file()


def test_the_parameter_file_is_the_c172s(c172, tmp_path, capsys):
    """--write-parm: the prototype's file's names (every one it sets, no other), the
    airspeeds from the c172's flight speeds (cruise 57.8, 31.1..68.9 m/s), its stall speed
    √(2W/(ρ S C_L,max)), its trim throttle (75 %), the rate feed-forwards 45 over the
    full-command rates its model gives, WP_LOITER_RAD V²/(g tan 30°), NAVL1_PERIOD for an
    L1 of 1.88 times the 45° turn radius; the file is not written over without --force."""
    aircraft, power = c172
    out = tmp_path / "c172.parm"
    code, text, err = run_cli(capsys, "ardupilot", "--aircraft", "c172_elastic",
                              "--write-parm", str(out))
    assert code == 0, err
    assert str(out) in text
    values = AP.read_parm(out.read_text(encoding="utf-8"))
    shipped = AP.read_parm(SHIPPED.read_text(encoding="utf-8"))
    assert set(values) == set(shipped)
    assert values["AIRSPEED_CRUISE"] == SPEED_M_S
    assert (values["AIRSPEED_MIN"], values["AIRSPEED_MAX"]) == pytest.approx((31.1, 68.9),
                                                                             abs=0.05)
    assert values["SCALING_SPEED"] == SPEED_M_S
    assert values["TRIM_THROTTLE"] == round(100 * power.throttle_trim) == 75
    data = aircraft.wing().model.airframe
    w = power.mass_kg * 9.80665
    stall = math.sqrt(2 * w / (1.225 * data.reference.area_m2
                               * data.at_speed(31.1).aero.cl_max))
    assert values["AIRSPEED_STALL"] == pytest.approx(stall, rel=1e-3)
    assert values["AIRSPEED_STALL"] * math.sqrt(math.sqrt(2)) < values["AIRSPEED_MIN"]
    p_full = math.degrees(power.roll_rad_s2 / abs(power.roll_damping_1_s))
    assert values["RLL_RATE_FF"] == pytest.approx(45 / p_full, rel=2e-3)
    assert values["WP_LOITER_RAD"] == pytest.approx(
        SPEED_M_S**2 / (9.80665 * math.tan(math.radians(30))), rel=1e-3)
    l1 = values["NAVL1_PERIOD"] * 0.75 * SPEED_M_S / math.pi
    assert l1 == pytest.approx(43 / 22.9 * SPEED_M_S**2 / 9.80665, rel=2e-3)
    assert 0 < values["TECS_CLMB_MAX"] and 0 < values["TECS_SINK_MIN"] \
        <= values["TECS_SINK_MAX"]
    for name in ("SERVO1_FUNCTION", "SERVO2_FUNCTION", "SERVO3_FUNCTION", "SERVO4_FUNCTION",
                 "SERVO5_FUNCTION", "FLTMODE1", "TKOFF_THR_MINACC"):
        assert values[name] == shipped[name], name
    code, _, err = run_cli(capsys, "ardupilot", "--aircraft", "c172_elastic",
                           "--write-parm", str(out))
    assert_one_line_error(code, err, "--write-parm")
    proto = tmp_path / "proto.parm"
    code, _, err = run_cli(capsys, "ardupilot", "--write-parm", str(proto))
    assert code == 0 and proto.read_text(encoding="utf-8") == SHIPPED.read_text(
        encoding="utf-8")

