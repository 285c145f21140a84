"""ArduPlane's JSON physics over the real coupled step (bioflex_jsb.drivers.ardupilot), driven
by the byte-exact ArduPilot stand-in (tests/ardupilot_standin.py) over loopback UDP.

Checks: lock-step (one step per frame, ArduPilot's counter and clock follow), resend (same
reply, no step), reset on a backward frame count, the IMU at rest, on the launcher and in
flight against the simulation's own state and kinematics (specific force + gravity =
d(velocity)/dt in NED through ArduPilot's rotation matrix; d(position)/dt = velocity), the
channel map, a valid-range stop putting the aircraft back on the launcher, the gust's η₁
report, the session's MCAP log (the autopilot topic carries what the stand-in sent, in
order; the run topics the state sent back; independent readers accept the file) and the
command line. The server and the stand-in take turns in one thread.
"""

from __future__ import annotations

import json
import math
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import units as U
from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.links import ardupilot_json as aj
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from bioflex_jsb.sinks.mcap.scene import SCENE_RATE_HZ
from tests.ardupilot_standin import ArduPilotStandin, dcm_of

G = ad.G0_M_S2
DISARMED = (1500, 1500, 1000, 1500)  # throttle at SERVO3_MIN
ARMED_IDLE = (1500, 1500, 1050, 1500)  # TKOFF_THR_IDLE 5 %: fires the launcher


@pytest.fixture(scope="module")
def wing():
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    return build_wing(VARIANTS["optimised"]).model


def _physics(wing, **kw):
    return ad.ArduPilotPhysics(Airframe(), wing, kw.pop("model", "coupled"), **kw)


class Link:
    """A server and a stand-in taking turns: one frame out, one reply in."""

    def __init__(self, physics, **server_kw):
        self.physics = physics
        self.server = aj.LockstepServer(physics, port=0, on_frame=physics.on_frame,
                                        on_event=physics.event, **server_kw)
        self.ap = ArduPilotStandin(self.server.address)

    def frame(self, pwm):
        self.ap.send_servos(pwm)
        assert self.server.serve_once(5.0)
        parsed = self.ap.receive()
        assert parsed is not None, self.ap.messages
        return parsed

    def close(self):
        self.ap.close()
        self.server.close()


@pytest.fixture
def link(wing):
    lk = Link(_physics(wing))
    yield lk
    lk.close()


def _ned_accel(parsed):
    """Specific force rotated to NED by ArduPilot's own DCM, plus gravity [m/s²]."""
    dcm = dcm_of(parsed)
    f = parsed.values["accel_body"]
    a = [sum(dcm[i][j] * f[j] for j in range(3)) for i in range(3)]
    a[2] += G
    return a


def test_rest_lockstep_and_imu(link):
    ph = link.physics
    theta = ph._theta0
    for n in range(1, 201):
        p = link.frame(DISARMED)
        assert link.ap.frame_counter == n and ph.frame_k == n
        assert p.values["timestamp"] == pytest.approx(n * ph.dt_s, abs=1e-12)
    assert ph.phase == ad.REST and link.server.stats.steps == 200
    assert link.ap.time_now_us == pytest.approx(200 * ph.dt_s * 1e6, rel=1e-9)
    ax, ay, az = p.values["accel_body"]
    # level at rest: (0, 0, −g) within the launcher's pitch θ_trim (1.8°)
    assert abs(theta) < math.radians(3.0)
    assert (ax, ay, az) == pytest.approx((0.0, 0.0, -G), abs=G * math.sin(abs(theta)) + 1e-4)
    assert ax == pytest.approx(G * math.sin(theta), abs=1e-5)
    assert math.sqrt(ax * ax + ay * ay + az * az) == pytest.approx(G, rel=1e-6)
    assert _ned_accel(p) == pytest.approx([0.0, 0.0, 0.0], abs=1e-5)
    assert p.values["position"] == (0.0, 0.0, 0.0) and p.values["velocity"] == (0, 0, 0)
    assert p.values["gyro"] == (0.0, 0.0, 0.0) and p.values["airspeed"] == 0.0
    assert ph.core.k == 0  # JSBSim waits, trimmed, unstepped


def test_launch_then_flight_kinematics_against_the_simulation(link):
    ph = link.physics
    hold = ph.launch_hold_steps
    for _ in range(hold):
        link.frame(ARMED_IDLE)
    assert ph.phase == ad.LAUNCH and ph.launches == 1
    prev = None
    worst_launch = worst_flight = worst_pos = 0.0
    n_launch = ph.stroke_steps
    for n in range(n_launch + 300):
        p = link.frame(ARMED_IDLE)
        if prev is not None:
            dt = p.values["timestamp"] - prev.values["timestamp"]
            vel, vel0 = p.values["velocity"], prev.values["velocity"]
            pos, pos0 = p.values["position"], prev.values["position"]
            dv = [(a - b) / dt for a, b in zip(vel, vel0, strict=True)]
            # constant acceleration on the launcher: the new state's specific force is the
            # acceleration of the step that reached it; in flight JSBSim's (multistep)
            # integration makes this true to the step's change of the force
            expect = _ned_accel(prev) if ph.phase == ad.FLIGHT else _ned_accel(p)
            err = max(abs(a - b) for a, b in zip(dv, expect, strict=True))
            v_mid = [(a + b) / 2 for a, b in zip(vel, vel0, strict=True)]
            dp = [(a - b) / dt for a, b in zip(pos, pos0, strict=True)]
            worst_pos = max(worst_pos, max(abs(a - b) for a, b in zip(dp, v_mid, strict=True)))
            if n < n_launch:
                worst_launch = max(worst_launch, err)
            else:
                worst_flight = max(worst_flight, err)
        if n == n_launch - 2:
            ax = p.values["accel_body"][0]  # the push seen by TKOFF_THR_MINACC
            assert ax > ad.DEFAULT_LAUNCH_ACCEL_M_S2 * 0.99
        prev = p
    assert ph.phase == ad.FLIGHT and ph.core.k == 300
    assert worst_launch < 3e-3, worst_launch  # float32 velocities: 1e-6 m/s / dt
    assert worst_flight < 0.05, worst_flight  # m/s² (JSBSim's Earth model vs ArduPilot's)
    assert worst_pos < 0.01, worst_pos  # m/s
    # fields against the simulation's state, units converted once
    get, v = ph.core.get, p.values
    assert v["gyro"] == pytest.approx((get["p"](), get["q"](), get["r"]()), abs=1e-6)
    assert v["velocity"] == pytest.approx(
        tuple(get[k]() * U.M_PER_FT for k in ("vn", "ve", "vd")), abs=1e-5)
    assert v["position"][2] == pytest.approx(
        ph._h_launch_m - get["h"]() * U.M_PER_FT + ph.stroke_m * ph._exit_dir[2], abs=1e-9)
    assert v["position"][0] == pytest.approx(ph.stroke_m + 300 * ph.dt_s * 15.0, rel=0.01)
    assert v["airspeed"] == pytest.approx(ph.airframe["velocities/vt-fps"] * U.M_PER_FT,
                                          rel=1e-6)
    assert v["attitude"] == pytest.approx((get["phi"](), get["theta"](),
                                           math.remainder(get["psi"](), 2 * math.pi)),
                                          abs=1e-6)
    m = ph.airframe["inertia/mass-slugs"]
    assert v["accel_body"][2] == pytest.approx(
        ph.airframe["forces/fbz-total-lbs"] / m * U.M_PER_FT, rel=1e-6)
    # near trim in flight the accelerometer still reads ≈ gravity's reaction
    assert math.dist(v["accel_body"], (0.0, 0.0, -G)) < 1.0
    assert link.ap.frame_counter == hold + n_launch + 300
    assert len(ph.records) > 0 and ph.table().shape[1] == len(ph.record_names)


def test_resend_answers_again_without_a_step(link):
    ph = link.physics
    for _ in range(20):
        link.frame(DISARMED)
    reply_before = link.server._last_reply
    k_before = ph.frame_k
    link.ap.resend()  # the same frame_count again (ArduPilot after 1 s without a reply)
    assert link.server.serve_once(5.0)
    data = link.ap.read_datagram()
    assert data == reply_before and ph.frame_k == k_before
    assert link.server.stats.resends == 1 and link.server.stats.steps == 20
    t = link.ap.time_now_us
    assert link.ap.accept(data) is not None and link.ap.time_now_us == t  # clock holds
    assert ph.records[-1][2] == ad.ACTIONS.index(aj.RESEND)


def test_backward_frame_count_resets_to_the_launcher(link):
    ph = link.physics
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + 50):
        link.frame(ARMED_IDLE)
    assert ph.phase == ad.FLIGHT
    link.ap.restart()  # a new SITL process: frame_count from 0 again
    p = link.frame(DISARMED)
    assert link.server.stats.resets == 1 and ph.restarts == 1
    assert ph.phase == ad.REST and ph.core.k == 0 and ph.frame_k == 1
    assert p.values["timestamp"] == pytest.approx(ph.dt_s)
    assert p.values["position"] == (0.0, 0.0, 0.0) and p.values["velocity"] == (0, 0, 0)
    assert np.all(ph.core.eta == 0.0)


def test_valid_range_stop_goes_back_to_the_launcher(link):
    """Full nose-down elevator from a 2 m launcher: the flight leaves the valid range, the
    server goes on with the aircraft at rest again and the clock keeps running."""
    ph = link.physics
    for _ in range(ph.launch_hold_steps + ph.stroke_steps):
        link.frame(ARMED_IDLE)
    last_t = 0.0
    for _ in range(3000):
        p = link.frame((1500, 1000, 1000, 1500))  # elevator full nose down, idle
        assert p.values["timestamp"] > last_t
        last_t = p.values["timestamp"]
        if ph.stops:
            break
    assert ph.stops, "no stop"  # deep stall (α < −30°) or the ground
    assert ph.phase == ad.REST and ph.restarts == 0
    p = link.frame(DISARMED)
    assert p.values["velocity"] == (0, 0, 0) and p.values["timestamp"] > last_t
    assert ph.airframe["position/h-agl-ft"] * U.M_PER_FT == pytest.approx(2.0, abs=1e-6)


def test_launch_switch_on_servo_5_fires_the_launcher(link):
    """In AUTO ArduPlane keeps the throttle at 0 until it detects the launch: the ground
    station's launch switch (RC 5 passed through to servo 5) fires it instead."""
    ph = link.physics
    for _ in range(ph.launch_hold_steps + 5):
        link.frame(DISARMED + (1800,))  # SITL's own RC 5 at boot: not the switch
    assert ph.phase == ad.REST
    for _ in range(ph.launch_hold_steps - 1):
        link.frame(DISARMED + (1900,))
    assert ph.phase == ad.REST
    link.frame(DISARMED + (1500,))  # released before the hold: the count starts again
    for _ in range(ph.launch_hold_steps):
        link.frame(DISARMED + (1900,))
    assert ph.phase == ad.LAUNCH


def test_channel_map(link):
    ch = {c.prop: c for c in ad.CHANNEL_MAP}
    assert ch["fcs/aileron-cmd-norm"].value(2000) == 1.0
    assert ch["fcs/elevator-cmd-norm"].value(2000) == -1.0  # nose up = − bioflex elevator
    assert ch["fcs/rudder-cmd-norm"].value(1250) == 0.5
    assert ch["fcs/throttle-cmd-norm"].value(1500) == 0.5
    assert ch["fcs/throttle-cmd-norm"].value(2300) == 1.0
    assert ch["fcs/aileron-cmd-norm"].value(0) == 0.0  # undriven: trim
    assert ch["fcs/throttle-cmd-norm"].value(0) == 0.0
    ph = link.physics
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + 1):
        link.frame(ARMED_IDLE)
    link.frame((1750, 1250, 1500, 1600))
    a = ph.airframe
    assert a["fcs/aileron-cmd-norm"] == pytest.approx(0.5)
    assert a["fcs/elevator-cmd-norm"] == pytest.approx(0.5)
    assert a["fcs/rudder-cmd-norm"] == pytest.approx(-0.2)
    assert all(a[f"fcs/throttle-cmd-norm[{i}]"] == pytest.approx(0.5)
               for i in range(a.engine_count))


def test_gust_report(wing):
    ph = _physics(wing, gust=parse_gust("1cos:2:15"), gust_at_s=0.1)
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + 1100):
        ph.step(ARMED_IDLE + (0,) * 12, 1200)
    rep = ph.gust_report
    assert rep["w_g_peak_m_s"] == pytest.approx(2.0, rel=1e-6)
    assert rep["start_flight_s"] == pytest.approx(0.1, abs=ph.dt_s)
    assert abs(rep["eta1_change_peak_rad"]) > 1e-4
    assert abs(rep["eta1_change_peak_in_gust_rad"]) > 1e-4
    assert rep["eta1_min_in_gust_rad"] <= rep["eta1_max_in_gust_rad"]
    assert rep["n_z_min_in_gust"] < 1.0 < rep["n_z_max_in_gust"]  # the 1-cosine's load
    json.dumps(ph.summary(), allow_nan=False)


@pytest.mark.parametrize("pull_up", [False, True])
def test_a_change_peak_at_the_end_of_its_search_is_flagged_as_no_peak(wing, pull_up):
    """Trim servos: η₁'s largest change after a 1 s gust is inside the search (the gust's);
    a pull-up that starts after the gust and grows until the search ends (as ArduPlane's
    turn at a waypoint does) puts it at the search's last step: flagged, one WARNING."""
    ph = _physics(wing, gust=parse_gust("1cos:2:15"), gust_at_s=0.1)
    end_s = 0.1 + 1.0 + ad.GUST_DECAY_S  # flight time the search ends at [s]
    for _ in range(ph.launch_hold_steps + ph.stroke_steps + int((end_s + 0.2) / ph.dt_s)):
        t = ph.core.k * ph.core.dt_s if ph.phase == ad.FLIGHT else 0.0
        elevator = 1500 + (int(200 * (t - 1.5)) if pull_up and t > 1.5 else 0)
        ph.step((1500, elevator, 1130, 1500, 1000) + (0,) * 11, 1200)
    ph.flush_events()
    rep = ph.gust_report
    warnings = [text for _, level, text in ph.events if level == "WARNING"]
    assert rep["eta1_change_peak_at_window_end"] is pull_up
    if pull_up:
        assert rep["eta1_change_peak_time_s"] == pytest.approx(
            rep["start_time_s"] + 1.0 + ad.GUST_DECAY_S, abs=2 * ph.dt_s)
        assert len(warnings) == 1 and "end of its search" in warnings[0]
        assert abs(rep["eta1_change_peak_rad"]) > abs(rep["eta1_change_peak_in_gust_rad"])
    else:
        assert rep["eta1_change_peak_time_s"] < rep["start_time_s"] + 1.0 + ad.GUST_DECAY_S
        assert warnings == []
    json.dumps(ph.summary(), allow_nan=False)


def test_bad_inputs_are_one_line_errors(wing):
    with pytest.raises(ValueError, match="launch acceleration"):
        ad.Launcher(accel_m_s2=1.0)
    with pytest.raises(ValueError, match="gust start"):
        _physics(wing, gust_at_s=-1.0)
    from bioflex_jsb.cli import main

    assert main(["ardupilot", "--gust", "1cos:2"]) == 2
    assert main(["ardupilot", "--table", "x.csv"]) == 2
    assert main(["ardupilot", "--port", "0", "--out", "x.mcap", "--no-log"]) == 2


def _pymcap_cli() -> str:
    """pymcap-cli of this interpreter's environment (the test extra), not whatever PATH has."""
    exe = Path(sys.executable).with_name("pymcap-cli")
    if exe.exists():
        return str(exe)
    found = shutil.which("pymcap-cli")
    if found is None:
        pytest.fail("pymcap-cli is missing: install the test extra (pip install '.[test]')")
    return found


def _doctor(path: Path) -> None:
    out = subprocess.run([_pymcap_cli(), "doctor", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "passed" in out.stdout and "error" not in out.stdout.lower(), out.stdout


def _servos(n: int, base: tuple[int, ...]) -> tuple[int, ...]:
    """``base`` on servos 1–4 (or 5), then values that change every frame on the servos the
    physics does not read (6–16): each frame's PWM is recognisable in the log."""
    tail = tuple(1000 + (7 * n + 13 * j) % 1000 for j in range(16 - len(base)))
    return base + tail


def open_log(ph, path):
    """``ph`` logging its frames into a new MCAP file at ``path`` (the caller closes it)."""
    desc = RunDescription(kind="ardupilot", wing="optimised", speed_m_s=15.0, gust="none",
                          models=("coupled",), dt_s=ph.dt_s, extra={"autopilot": "ardupilot"})
    log = sink.RunLog.open(path, desc)
    ph.log_to(log)
    return log


@pytest.fixture(scope="module")
def session_log(wing, tmp_path_factory):
    """A stand-in session logged to MCAP: rest, a resend, launch, flight with a resend,
    ArduPilot restarting, rest again. Returns (path, what was sent, the replies, physics)."""
    path = tmp_path_factory.mktemp("aplog") / "session.mcap"
    ph = _physics(wing, record_every=1)
    desc = RunDescription(kind="ardupilot", wing="optimised", speed_m_s=15.0, gust="none",
                          models=("coupled",), dt_s=ph.dt_s,
                          extra={"autopilot": "ardupilot"})
    log = sink.RunLog.open(path, desc)
    ph.log_to(log)
    lk = Link(ph)
    sent, replies = [], []  # (frame_count, pwm, action); (session time, phase, parsed)
    n = 0

    def frame(base):
        nonlocal n
        pwm = _servos(n, base)
        n += 1
        count = lk.ap.frame_counter
        p = lk.frame(pwm)
        action = aj.RESET if sent and count < sent[-1][0] else aj.STEP
        sent.append((count, pwm, action))
        replies.append((ph.session_t_s, ph.phase, p))

    def resend():
        lk.ap.resend()
        assert lk.server.serve_once(5.0)
        assert lk.ap.accept(lk.ap.read_datagram()) is not None
        sent.append((sent[-1][0], sent[-1][1], aj.RESEND))

    try:
        for _ in range(30):
            frame(DISARMED)
        resend()
        for _ in range(ph.launch_hold_steps + ph.stroke_steps + 150):
            frame(ARMED_IDLE)
        assert ph.phase == ad.FLIGHT
        resend()
        for _ in range(50):
            frame(ARMED_IDLE)
        lk.ap.restart()  # frame_count back to 0: a reset
        for _ in range(20):
            frame(DISARMED)
        assert lk.server.stats.resets == 1 and lk.server.stats.resends == 2
    finally:
        lk.close()
        log.close()
    return path, sent, replies, ph


def test_log_autopilot_topic_is_what_the_standin_sent(session_log):
    path, sent, replies, ph = session_log
    msgs = sink.messages_by_topic(path)
    ap = msgs[sink.topic("coupled", "autopilot")]
    assert len(ap) == len(sent)
    assert [m["frame_count"] for _, m in ap] == [c for c, _, _ in sent]  # in order
    assert [tuple(m["pwm_us"]) for _, m in ap] == [pwm for _, pwm, _ in sent]
    assert [sink.AUTOPILOT_ACTIONS[m.get("action", 0)] for _, m in ap] == [
        "ACTION_" + a.upper() for _, _, a in sent]
    assert sink.AUTOPILOT_ACTIONS == tuple("ACTION_" + a.upper() for a in ad.ACTIONS)
    assert sink.AUTOPILOT_PHASES == tuple("PHASE_" + p.upper() for p in ad.PHASES)
    assert all(m["frame_rate_hz"] == 1200 for _, m in ap)
    times = [ns for ns, _ in ap]
    assert times == sorted(times)  # the session's time goes on across the restart
    # steps and resets: at the start of their step; resends: at the state they repeat; the
    # timestamp is the reply's (back to dt after ArduPilot's restart)
    steps = [(ns, m) for ns, m in ap if m.get("action", 0) != 1]
    assert len(steps) == len(replies)
    for (ns, m), (t_after, phase, p) in zip(steps, replies, strict=True):
        assert ns == round((t_after - ph.dt_s) * 1e9)
        assert m["timestamp_s"] == p.values["timestamp"]
        assert sink.AUTOPILOT_PHASES[m.get("phase", 0)] == "PHASE_" + phase.upper()
    resends = [(ns, m) for ns, m in ap if m.get("action", 0) == 1]
    assert [m["frame_count"] for _, m in resends] == [c for c, _, a in sent if a == aj.RESEND]
    for ns, m in resends:  # the time and timestamp of the frame they repeat
        before = [m2 for ns2, m2 in ap if m2["frame_count"] == m["frame_count"]
                  and m2.get("action", 0) == 0]
        assert m["timestamp_s"] == before[0]["timestamp_s"]
        assert ns == round(m["timestamp_s"] * 1e9)  # the first session: session = physics
    reset = [m for _, m in ap if m.get("action", 0) == 2]
    assert len(reset) == 1 and reset[0]["frame_count"] == 0
    assert reset[0]["timestamp_s"] == pytest.approx(ph.dt_s, rel=1e-12)
    # the mapped commands: the channel map of what was sent
    for (_, m), (_, pwm, _) in zip(ap, sent, strict=True):
        assert (m.get("aileron_cmd_norm", 0.0), m.get("elevator_cmd_norm", 0.0),
                m.get("throttle_cmd_norm", 0.0), m.get("rudder_cmd_norm", 0.0)) == \
            ph.commands(pwm)
    assert ph.commands(ARMED_IDLE) == (0.0, 0.0, pytest.approx(0.05), 0.0)


def test_log_run_topics_are_the_state_sent(session_log):
    path, sent, replies, ph = session_log
    msgs = sink.messages_by_topic(path)
    rigid = msgs[sink.topic("coupled", "rigid_body")]
    flight_steps = 200  # 150 + 50 frames after the stroke, the resend not a step
    for group in ("rigid_body", "modal", "modal_loads", "gust", "controls"):
        assert len(msgs[sink.topic("coupled", group)]) == flight_steps, group
    # pose and location at the 3-D scene's samples: the first step in each 1/60 s of log time
    # (SCENE_RATE_HZ; floor(t·60 + 1e-6), scene.py's bins, the scene's instants), in this
    # log without a scene too
    assert sink.topic("coupled", "scene") not in msgs
    bins = [math.floor(ns * 1e-9 * SCENE_RATE_HZ + 1e-6) for ns, _ in rigid]
    samples = [ns for k, (ns, _) in enumerate(rigid) if k == 0 or bins[k] != bins[k - 1]]
    assert 10 <= len(samples) < flight_steps
    for group in ("pose", "location"):
        assert [ns for ns, _ in msgs[sink.topic("coupled", group)]] == samples, group
    at = dict(rigid)
    for ns, fix in msgs[sink.topic("coupled", "location")]:
        assert fix["altitude"] == at[ns]["altitude_m"]
    # the snapshot logged at t is the state the reply at t sent (float32 in ArduPilot)
    sent_at = {round(t * 1e9): p for t, phase, p in replies}
    for ns, m in rigid:
        p = sent_at[ns].values
        yaw = math.remainder(m["yaw_rad"], 2 * math.pi)  # ArduPilot's is in (−π, π]
        assert (m["roll_rad"], m["pitch_rad"], yaw) == pytest.approx(p["attitude"], abs=1e-6)
        assert (m["v_north_m_s"], m["v_east_m_s"], m["v_down_m_s"]) == pytest.approx(
            p["velocity"], abs=1e-5)
        assert m["airspeed_m_s"] == pytest.approx(p["airspeed"], rel=1e-6)
    # and every channel is the coupled step's row (the --table holds the same rows)
    table = ph.table()
    names = ph.record_names
    col = {k: i for i, k in enumerate(names)}
    rows = [r for r in table if r[col["action"]] != ad.ACTIONS.index(aj.RESEND)
            and math.isfinite(r[col["u"]])]
    assert len(rows) == flight_steps
    modal = msgs[sink.topic("coupled", "modal")]
    for (ns, m), (_, mm), r in zip(rigid, modal, rows, strict=True):
        assert ns == round((r[col["time_s"]] - ph.dt_s) * 1e9)
        assert m["du_m_s"] == r[col["u"]] and m["q_rad_s"] == r[col["q"]]
        assert m["altitude_m"] == r[col["altitude_m"]]
        assert mm["eta_rad"][0] == r[col["eta1"]] and mm["eta_dot_rad_s"][0] == r[
            col["eta1_dot"]]
    assert any(m["eta_rad"][0] != 0.0 for _, m in modal)  # the wing does move


def test_log_is_read_by_independent_readers_and_the_log_commands(session_log, tmp_path,
                                                                capsys):
    from bioflex_jsb.cli import main

    path, sent, _, _ = session_log
    _doctor(path)
    assert main(["info", str(path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    counts = {c["topic"]: c["messages"] for c in info["channels"]}
    assert counts[sink.topic("coupled", "autopilot")] == len(sent)
    schemas = {c["topic"]: c["schema"] for c in info["channels"]}
    assert schemas[sink.topic("coupled", "autopilot")] == "bioflex.Autopilot"
    assert info["metadata"]["bioflex.run"]["command"] == "ardupilot"
    png = tmp_path / "session.png"
    assert main(["plot", str(path), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000
    capsys.readouterr()
    assert main(["rerun", str(path), "--out", str(tmp_path / "again.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert "'ardupilot'" in err and len(err.splitlines()) == 1


def test_log_is_read_by_mcap_core_and_protobufjs(session_log, tmp_path_factory):
    from tests.test_mcap import _node_checker

    path, sent, _, _ = session_log
    result = _node_checker(tmp_path_factory)(path)  # skips without node/npm
    top = sink.topic("coupled", "autopilot")
    assert result["counts"][top] == result["statistics"][top] == len(sent)
    assert result["dataCrcOk"] is True and result["ordered"] is True
    assert result["schemas"][top] == "bioflex.Autopilot"
    theirs = result["samples"][top]  # the second message, decoded by protobufjs
    mine = sink.messages_by_topic(path)[top][1][1]
    mine = {k: v for k, v in mine.items() if v not in (0, 0.0)}  # proto3 defaults
    theirs = {k: v for k, v in theirs.items() if v not in (0, 0.0)}
    assert theirs == mine


def _free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _cli_session(argv: list[str], port: int, second_sender: bool = False,
                 restart_at: int | None = None) -> tuple[int, list[int]]:
    """Run ``bioflex-jsb ardupilot ARGV`` in a thread and fly the stand-in against it until
    it ends (``--duration``); with ``second_sender`` another stand-in sends a frame 0 after
    each of the first one's frames; with ``restart_at`` the stand-in is killed at that frame
    count and restarted as a new process (new port) after PEER_SILENCE_S + 0.5 s of
    silence. Returns (exit status, the stand-in's ports in the order used)."""
    from bioflex_jsb.cli import build_parser

    args = build_parser().parse_args(["ardupilot", "--port", str(port), *argv])
    result = {}
    th = threading.Thread(target=lambda: result.update(rc=args.run(args)), daemon=True)
    th.start()
    ap = ArduPilotStandin(("127.0.0.1", port), timeout_s=0.5)
    other = ArduPilotStandin(("127.0.0.1", port), timeout_s=0.5)
    ports = [ap.source[1]]
    try:
        for _ in range(800):
            if not th.is_alive():
                break
            ap.send_servos(DISARMED)
            try:
                ap.receive()
            except TimeoutError:
                continue
            if second_sender and ap.frame_counter > 1:  # once bound
                other.send_servos(DISARMED)
            if restart_at is not None and ap.frame_counter == restart_at and len(ports) == 1:
                ap.restart(new_process=True)
                ports.append(ap.source[1])
                time.sleep(aj.PEER_SILENCE_S + 0.5)
    finally:
        ap.close()
        other.close()
    th.join(10.0)
    return result.get("rc"), ports


def test_command_line_runs_and_writes_its_table(tmp_path, monkeypatch):
    port = _free_port()
    table, summary = tmp_path / "run.npz", tmp_path / "run.json"
    monkeypatch.setenv("BIOFLEX_LOG_DIR", str(tmp_path / "logs"))  # the default log place
    rc, _ = _cli_session(["--duration", "0.1", "--table", str(table), "--summary",
                          str(summary), "--record-every", "4"], port)
    assert rc == 0
    s = json.loads(summary.read_text())
    assert s["frames"]["steps"] >= 96 and s["phase"] == "rest" and s["stops"] == []
    with np.load(table) as z:
        names = list(z["names"])
        assert names[:3] == ["time_s", "frame_count", "action"]
        assert z["table"].shape == (s["frames"]["steps"] // 4, len(names))
    # the MCAP log, written as for any run: logs/ardupilot-<wing>-<UTC>.mcap
    (log,) = (tmp_path / "logs").glob("ardupilot-optimised-*.mcap")
    assert s["out"] == str(log)
    msgs = sink.messages_by_topic(log)
    ap = msgs[sink.topic("coupled", "autopilot")]
    assert len(ap) == s["frames"]["steps"] + s["frames"]["resends"]
    assert ap[-1][1]["frame_count"] == s["frames"]["last_frame_count"]
    assert sink.topic("coupled", "rigid_body") not in msgs  # at rest: no coupled step
    meta = sink.summarise(log)["metadata"]["bioflex.run"]
    d = sink.description_from_metadata(meta)
    assert d.kind == "ardupilot" and d.extra["autopilot"] == "ardupilot"
    assert d.extra["udp_port"] == port and d.dt_s == pytest.approx(ad.DEFAULT_DT_S)


# ---------------------------------------------------------------------------------------
# Sessions as a user flies them (faults of a flight with a real ArduPlane: re-launches
# mid-mission, the gust after every launch, the real-time factor after restarts, stops not
# in the log, an unflyable wing accepted)
# ---------------------------------------------------------------------------------------

CRUISE = (1500, 1000, 1500, 1500)  # mid-mission: throttle well up; elevator full nose down


class FakeClock:
    """The server's wall clock, advanced by the test [s] (no dependence on machine load)."""

    def __init__(self) -> None:
        self.t = 50.0

    def __call__(self) -> float:
        return self.t


def _launch(link, pwm=ARMED_IDLE):
    ph = link.physics
    for _ in range(ph.launch_hold_steps + ph.stroke_steps):
        link.frame(pwm)
    assert ph.phase == ad.FLIGHT


def _fly_to_a_stop(link, limit=3000):
    ph = link.physics
    n = len(ph.stops)
    for _ in range(limit):
        link.frame(CRUISE)
        if len(ph.stops) > n:
            return
    pytest.fail("no valid-range stop")


def test_a_stop_resets_once_and_no_relaunch_until_arduPilot_restarts(link):
    ph = link.physics
    _launch(link)
    _fly_to_a_stop(link)
    assert ph.phase == ad.REST and ph.grounded and ph.launches == 1
    # ArduPlane is still mid-mission: throttle up for 4 s (8 launch holds): no re-launch
    for _ in range(8 * ph.launch_hold_steps):
        p = link.frame(CRUISE)
    assert ph.launches == 1 and ph.phase == ad.REST and len(ph.stops) == 1
    assert p.values["velocity"] == (0, 0, 0)
    stop_events = [e for e in ph.events if e[1] == "ERROR"]
    assert len(stop_events) == 1 and "valid-range stop" in stop_events[0][2]
    assert stop_events[0][0] == pytest.approx(ph.stops[0]["session_s"])
    # ArduPilot restarts: the launcher is armed again
    link.ap.restart()
    link.frame(DISARMED)
    assert ph.restarts == 1 and not ph.grounded
    _launch(link)
    link.frame(ARMED_IDLE)  # one step of the second flight
    s = ph.summary()
    assert (s["launches"], s["relaunches"], s["stop_count"], s["restarts"]) == (2, 1, 1, 1)
    assert s["flown_s"] > s["stops"][0]["flight_s"] > 0.0


def _steps(ph, n, pwm=ARMED_IDLE):
    w = []
    for _ in range(n):
        ph.step(pwm + (0,) * 12, 1200)
        w.append(ph._last_w_g if ph.phase == ad.FLIGHT else 0.0)
    return np.array(w)


@pytest.mark.parametrize("repeat", [False, True])
def test_gust_blows_once_per_session_unless_repeated(wing, repeat):
    ph = _physics(wing, gust=parse_gust("1cos:2:15"), gust_at_s=0.1, gust_repeat=repeat)
    n_launch = ph.launch_hold_steps + ph.stroke_steps
    n_gust = int(1.3 / ph.dt_s)  # past the 1 s gust that starts 0.1 s into the flight
    first = _steps(ph, n_launch + n_gust)
    assert np.max(np.abs(first)) == pytest.approx(2.0, rel=1e-6)
    report = dict(ph.gust_report)
    ph.reset()  # ArduPilot restarts, launches again
    second = _steps(ph, n_launch + n_gust)
    assert ph.launches == 2 and ph.phase == ad.FLIGHT
    if repeat:
        assert np.max(np.abs(second)) == pytest.approx(2.0, rel=1e-6)
    else:
        assert np.all(second == 0.0) and ph.gust is None
        assert ph.gust_report == report  # the session's one gust
    assert ph.summary()["gust_applied"] and ph.summary()["gust_repeat"] == repeat


def test_real_time_factor_at_a_known_pace_across_a_kill_and_restart(wing):
    """300 frames 2 ms apart, ArduPilot killed, 10 s of silence, a new ArduPilot on a new
    port, 300 frames 2 ms apart: physics time 600/960 s over 598 x 2 ms connected."""
    from bioflex_jsb.cli.sitl_ardupilot import session_summary

    clock = FakeClock()
    lk = Link(_physics(wing), clock=clock)
    try:
        clock.t += 20.0  # ArduPlane booting: not connected
        for _ in range(300):
            clock.t += 2e-3
            lk.frame(DISARMED)
        lk.ap.restart(new_process=True)
        clock.t += 10.0
        lk.ap.send_servos(DISARMED)  # ArduPilot's frame 0, re-sent until answered
        assert lk.server.serve_once(5.0) and lk.ap.receive() is not None
        for _ in range(299):
            clock.t += 2e-3
            lk.frame(DISARMED)
        ph = lk.physics
        s = session_summary(ph, lk.server, wall_s=clock.t - 50.0)
    finally:
        lk.close()
    assert s["frames"]["resets"] == 1 and s["source_check"]["restarts_new_port"] == 1
    assert s["session_s"] == pytest.approx(600 * ph.dt_s)
    assert s["connected_wall_s"] == pytest.approx(598 * 2e-3)
    assert s["real_time_factor"] == pytest.approx((600 / 960) / (598 * 2e-3), rel=1e-9)
    assert s["real_time_factor"] == pytest.approx(0.5226, abs=1e-4)
    # the old figure: time since the last restart over the wall time from the first frame
    old = ph.t_s / (clock.t - 70.0)
    assert old < 0.5 * s["real_time_factor"]


def test_session_events_are_in_the_log(wing, tmp_path):
    path = tmp_path / "events.mcap"
    ph = _physics(wing)
    log = open_log(ph, path)
    lk = Link(ph)
    stray = ArduPilotStandin(lk.server.address)
    try:
        for _ in range(20):
            lk.frame(DISARMED)
        stray.send_servos(DISARMED)  # frame 0 from another port
        assert lk.server.serve_once(5.0)
        ph.flush_events()
        _launch(lk)
        _fly_to_a_stop(lk)
        lk.frame(DISARMED)
    finally:
        stray.close()
        lk.close()
        log.close()
    _doctor(path)
    events = [m for _, m in sink.messages_by_topic(path)[sink.EVENTS_TOPIC]]
    texts = [m["message"] for m in events]
    assert any("bound to ArduPilot" in t for t in texts)
    assert any("ignored a packet" in t for t in texts)
    assert any("launch 1" in t for t in texts)
    (stop,) = [m for m in events if "valid-range stop" in m["message"]]
    assert stop["level"] in ("ERROR", 4)
    assert ph.summary()["stop_count"] == 1 and lk.server.stats.resets == 0


@pytest.mark.parametrize("compiled, kind", [(True, "compiled kernel"), (False, "python")])
def test_unsteady_wing_flies_and_the_summary_says_which_step(compiled, kind):
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    build = build_wing(VARIANTS["inertial-backward"])
    ph = ad.ArduPilotPhysics(Airframe(), build, "coupled", aero="unsteady", compiled=compiled)
    assert ph.step_kind == kind and ph.core.aero == "unsteady"
    _steps(ph, ph.launch_hold_steps + ph.stroke_steps + 480)
    s = ph.summary()
    assert s["phase"] == ad.FLIGHT and s["stop_count"] == 0
    assert (s["aero"], s["step"]) == ("unsteady", kind)
    assert np.any(ph.core.eta != 0.0)


def test_unflyable_wing_is_refused_before_the_flight(capsys):
    """--wing inertial-backward: quasi-steady flutter at 14.9 m/s, below the 15 m/s trim
    (531 stops in 15 min when it was flown); the unsteady strips are stable to 18.9 m/s."""
    from bioflex_jsb.cli import main
    from bioflex_jsb.cli.sitl_ardupilot import preflight
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    assert main(["ardupilot", "--wing", "inertial-backward", "--port", "0", "--no-log"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    for word in ("15 m/s", "aeroelastic_1", "14.9 m/s", "--aero unsteady", "18.9 m/s",
                 "--allow-unstable"):
        assert word in err, err
    build = build_wing(VARIANTS["inertial-backward"])
    assert preflight(build, "coupled", "unsteady", 15.0)["stable"]
    assert not preflight(build, "coupled", "quasi-steady", 15.0)["stable"]
    ok = preflight(build_wing(VARIANTS["optimised"]), "coupled", "quasi-steady", 15.0)
    assert ok["stable"] and ok["max_growth_1_s"] < -1.0 and ok["unstable"] == []


def test_help_says_servo_5_fires_the_launcher_in_auto():
    from bioflex_jsb.cli.sitl_ardupilot import HELP

    text = " ".join(HELP.split())
    assert "in AUTO" not in text.split("launch switch fires it")[1][:20]
    assert "keeps the throttle at 0 until the launch, so there the launch switch fires it: " \
        "servo 5" in text
    assert "armed in AUTO at a NAV_TAKEOFF (throttle" not in text


def test_command_line_ignores_a_second_sender_and_prints_json(tmp_path, capsys):
    out = tmp_path / "s.mcap"
    rc, (ap_port,) = _cli_session(["--duration", "0.1", "--json", "--out", str(out)],
                                  _free_port(), second_sender=True)
    assert rc == 0
    captured = capsys.readouterr()
    s = json.loads(captured.out)
    assert s["frames"]["resets"] == 0 and s["source_check"]["foreign_packets"] >= 1
    assert s["source_check"]["peer"] == f"127.0.0.1:{ap_port}"
    assert s["step"] == "compiled kernel" and s["aero"] == "quasi-steady"
    assert s["real_time_factor"] > 0 and "connected" in s["real_time_factor_definition"]
    assert "ignored a packet" in captured.err
    events = [m["message"] for _, m in sink.messages_by_topic(out)[sink.EVENTS_TOPIC]]
    end = json.loads(events[-1].removeprefix("session end: "))
    assert end["session_s"] == s["session_s"] >= 0.1
    d = sink.description_from_metadata(sink.summarise(out)["metadata"]["bioflex.run"])
    assert d.duration_s == 0.1 and d.extra["duration"] == "--duration"
    assert d.extra["aero"] == "quasi-steady" and d.extra["step"] == "compiled kernel"


def test_command_line_session_across_a_killed_and_restarted_arduPilot(tmp_path):
    """The command with the real clock: 300 frames, ArduPilot killed (its port gone), 3.5 s
    of silence (> PEER_SILENCE_S), a new ArduPilot process on a new port; the session
    re-binds once, resets once, and the silence is not in the real-time factor."""
    summary = tmp_path / "s.json"
    rc, (first_port, second_port) = _cli_session(
        ["--duration", "0.6", "--no-log", "--summary", str(summary)], _free_port(),
        restart_at=300)
    assert rc == 0
    s = json.loads(summary.read_text())
    assert first_port != second_port
    assert s["frames"]["resets"] == 1 and s["restarts"] == 1
    assert s["source_check"]["restarts_new_port"] == 1
    assert s["source_check"]["peer"] == f"127.0.0.1:{second_port}"
    assert s["session_s"] == pytest.approx(0.6, abs=2 * ad.DEFAULT_DT_S)
    # the 3.5 s of silence is in wall_s, not in the real-time factor's denominator
    assert s["connected_wall_s"] < s["wall_s"] - aj.PEER_SILENCE_S
    assert s["real_time_factor"] == pytest.approx(s["session_s"] / s["connected_wall_s"])


def test_command_line_flies_the_unstable_wing_with_unsteady_strips(capsys):
    """The refusal's advice taken: --wing inertial-backward --aero unsteady passes the
    pre-flight check (stable to 18.9 m/s) and flies on the compiled unsteady step."""
    rc, _ = _cli_session(["--wing", "inertial-backward", "--aero", "unsteady", "--duration",
                          "0.1", "--json", "--no-log"], _free_port())
    assert rc == 0
    s = json.loads(capsys.readouterr().out)
    assert (s["aero"], s["step"]) == ("unsteady", "compiled kernel")
    assert s["preflight"]["stable"] and s["preflight"]["aero"] == "unsteady"
    assert s["preflight"]["max_growth_1_s"] < 0.0


def test_unchanged_servo_outputs_are_not_written_again_and_fly_the_same(wing):
    """ArduPlane's outputs change at its loop rate, not every frame: a PWM equal to the last
    one written is skipped (the controls already hold it); the flight is the same, bit for
    bit, as writing every frame, through PWM changes and a restart's new core."""
    rng = np.random.default_rng(3)
    held = [tuple(int(x) for x in rng.integers(1400, 1600, 4)) for _ in range(10)]
    # the last PWM held across the restart: after it, the first flight frame repeats it
    frames = [ARMED_IDLE] * 600 + [p for p in held for _ in range(20)] + [held[-1]] * 1000
    rows = []
    for always in (False, True):
        ph = _physics(wing, launcher=ad.Launcher(height_m=100.0))
        out = []
        for i, pwm in enumerate(frames):
            if i == 900:
                ph.reset()  # ArduPilot restarted: a new core, trimmed, its trim controls in
            if always:
                ph._written_pwm = None
            ph.step(pwm + (0,) * 12, 1200)
            out.append((ph.phase, *ph.state().position_ned_m))
        assert ph.phase == ad.FLIGHT
        rows.append(out)
    assert rows[0] == rows[1]


# ---------------------------------------------------------------------------------------
# The aircraft in 3-D in the session's log (issue 26: "the aircraft in 3-D in every log")
# ---------------------------------------------------------------------------------------

def _cli_flight(argv: list[str], port: int) -> int:
    """``bioflex-jsb ardupilot ARGV`` in a thread, flown by the stand-in holding ArduPlane's
    idle throttle in TAKEOFF mode (the launcher fires after 0.5 s) until ``--duration`` ends
    it; the exit status."""
    from bioflex_jsb.cli import build_parser

    args = build_parser().parse_args(["ardupilot", "--port", str(port), *argv])
    result = {}
    th = threading.Thread(target=lambda: result.update(rc=args.run(args)), daemon=True)
    th.start()
    ap = ArduPilotStandin(("127.0.0.1", port), timeout_s=0.5)
    try:
        for _ in range(5000):
            if not th.is_alive():
                break
            ap.send_servos(ARMED_IDLE)
            try:
                ap.receive()
            except TimeoutError:
                continue
    finally:
        ap.close()
    th.join(30.0)
    return result.get("rc")


def test_command_line_log_has_the_aircraft_in_3d(tmp_path):
    """The session's log carries the scene as gust, compare and sitl logs do: one wing
    message at the first step of each 1/60 s bin of the flight's steps (none on the
    launcher: no coupled step there), the tip twisted by the mode shapes times the logged
    η (exaggeration 1, cli.gust.SCENE_EXAGGERATION), the rigid airframe, the metadata."""
    pytest.importorskip("google.protobuf")
    pytest.importorskip("foxglove_schemas_protobuf")
    from bioflex_jsb.cli.gust import SCENE_EXAGGERATION
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.sinks.mcap import scene
    from tests.tools import decode_topic

    out = tmp_path / "session.mcap"
    assert _cli_flight(["--duration", "1.3", "--launch-height", "100", "--out", str(out)],
                       _free_port()) == 0
    modal = decode_topic(out, sink.topic("coupled", "modal"))
    wing = decode_topic(out, sink.topic("coupled", "scene"))
    assert len(modal) > 300  # 1.3 s less the launcher's 0.5 s hold and 0.375 s stroke
    steps = np.array([ns for ns, _ in modal])
    bins = np.floor(steps * 1e-9 * scene.SCENE_RATE_HZ + 1e-6)
    first = steps[np.flatnonzero(np.diff(np.concatenate([[bins[0] - 1], bins])))]
    assert [ns for ns, _ in wing] == first.tolist()
    assert len(wing) >= 20
    build = build_wing(VARIANTS["optimised"])
    eta_at = {ns: np.array(m.eta_rad) for ns, m in modal}
    moved = 0
    for ns, msg in wing:
        ent = msg.entities[0]
        assert (ent.frame_id, ent.id) == ("coupled_body", scene.ENTITY_ID)
        le, te = [(p.x, p.z) for p in ent.triangles[0].points][-2:]
        twist = math.atan2(le[1] - te[1], le[0] - te[0])
        expected = SCENE_EXAGGERATION * build.modes.twist_rad[:, -1] @ eta_at[ns]
        # rounding only: a few double operations on numbers below 1 m (tests/test_scene.py)
        assert twist == pytest.approx(expected, abs=1e-12)
        moved += abs(expected) > 1e-9
    assert moved  # the flight's wing is deformed: the check sees the η
    air = decode_topic(out, sink.topic("coupled", "airframe"))
    assert air and air[0][0] == wing[0][0]  # with the first sample of the flight
    info = sink.summarise(out)["metadata"][sink.schemas.SCENE_METADATA]
    assert float(info["exaggeration"]) == SCENE_EXAGGERATION
    _doctor(out)
