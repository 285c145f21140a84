"""ArduPilot JSON SITL link (bioflex_jsb.links.ardupilot_json) against a byte-exact stand-in of
ArduPilot's side (tests/ardupilot_standin.py), over loopback UDP, without ArduPilot.

The physics is a kinematic aircraft in a coordinated level turn whose IMU, position,
velocity and attitude are analytically consistent, so the frame checks below (specific
force + gravity = d(velocity)/dt in NED through ArduPilot's own rotation matrix; gyro =
the rotation matrix's rate; d(position)/dt = velocity) test what ArduPilot would see.
No test depends on timing: the server and the stand-in take turns in one thread (UDP
loopback buffers the datagram in between), except the one that runs ``serve`` in a thread,
whose only timeouts are failure limits.
"""

from __future__ import annotations

import json
import math
import struct
import threading

import numpy as np
import pytest

from bioflex_jsb.links import ardupilot_json as aj
from tests.ardupilot_standin import ArduPilotStandin, dcm_from_euler, dcm_of, parse_sensors

G_M_S2 = 9.80665  # standard gravity, as the fake physics uses it
DT_S = 1.0 / 960.0  # the co-simulation's step (simulation.modal_wing.DEFAULT_DT_S)


def _quaternion_from_euler(roll: float, pitch: float, yaw: float) -> tuple[float, ...]:
    """(w, x, y, z) of the 3-2-1 rotation body → NED (textbook half-angle products)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


class LevelTurn:
    """Kinematic aircraft: speed V, bank φ, constant altitude, turning right from north at
    ω = g tanφ / V about a centre R = V/ω east of home. Body rates (0, ω sinφ, ω cosφ) FRD;
    specific force (0, 0, −g/cosφ) FRD (coordinated: no side force)."""

    def __init__(self, speed_m_s: float = 15.0, bank_rad: float = math.radians(30.0),
                 altitude_m: float = 100.0, dt_s: float = DT_S, quaternion_order: str = "wxyz"):
        self.v, self.phi, self.h, self.dt = speed_m_s, bank_rad, altitude_m, dt_s
        self.omega = G_M_S2 * math.tan(bank_rad) / speed_m_s if bank_rad else 0.0
        self.quaternion_order = quaternion_order
        self.steps: list[tuple[tuple[int, ...], int]] = []
        self.resets = 0
        self.k = 0

    def reset(self) -> None:
        self.resets += 1
        self.k = 0

    def step(self, pwm_us: tuple[int, ...], frame_rate_hz: int) -> None:
        self.steps.append((pwm_us, frame_rate_hz))
        self.k += 1

    def state(self) -> aj.JsonState:
        t = self.k * self.dt
        psi = self.omega * t
        if self.omega:
            r = self.v / self.omega
            north, east = r * math.sin(psi), r * (1.0 - math.cos(psi))
        else:
            north, east = self.v * t, 0.0
        q = _quaternion_from_euler(self.phi, 0.0, psi)
        if self.quaternion_order == "xyzw":  # a wrong convention, for the negative control
            q = (q[1], q[2], q[3], q[0])
        return aj.JsonState(
            timestamp_s=t,
            gyro_rad_s=(0.0, self.omega * math.sin(self.phi), self.omega * math.cos(self.phi)),
            accel_body_m_s2=(0.0, 0.0, -G_M_S2 / math.cos(self.phi)),
            position_ned_m=(north, east, -self.h),
            velocity_ned_m_s=(self.v * math.cos(psi), self.v * math.sin(psi), 0.0),
            quaternion=q,
            attitude_rad=(self.phi, 0.0, math.atan2(math.sin(psi), math.cos(psi))),
            airspeed_m_s=self.v,
        )


@pytest.fixture
def link():
    physics = LevelTurn()
    records: list[aj.FrameRecord] = []
    server = aj.LockstepServer(physics, port=0, on_frame=records.append)
    ap = ArduPilotStandin(server.address)
    yield physics, server, ap, records
    ap.close()
    server.close()


def _frame(server, ap, pwm):
    """ArduPilot sends one frame, the server answers it, ArduPilot reads the answer."""
    ap.send_servos(pwm)
    assert server.serve_once(timeout_s=5.0)
    return ap.receive()


def _pwm(k: int) -> list[int]:
    return [1000 + (k + i) % 1000 for i in range(16)]


# ---------------------------------------------------------------------------------------
# Packets and replies
# ---------------------------------------------------------------------------------------

def test_servo_packets_16_and_32_channels_decode():
    p16 = struct.pack("<HHI16H", 18458, 1200, 7, *range(1100, 1116))
    p32 = struct.pack("<HHI32H", 29569, 400, 2**32 - 1, *range(1000, 1032))
    a, b = aj.parse_servo_packet(p16), aj.parse_servo_packet(p32)
    assert (a.frame_rate_hz, a.frame_count, a.pwm_us) == (1200, 7, tuple(range(1100, 1116)))
    assert (b.frame_rate_hz, b.frame_count, b.pwm_us) == (400, 2**32 - 1,
                                                          tuple(range(1000, 1032)))


@pytest.mark.parametrize("data, reason", [
    (struct.pack("<HHI16H", 29569, 1200, 0, *[1500] * 16), "magic"),  # 32-ch magic, 16 values
    (struct.pack("<HHI32H", 18458, 1200, 0, *[1500] * 32), "magic"),
    (struct.pack("<HHI15H", 18458, 1200, 0, *[1500] * 15), "length"),
    (b"", "length"),
    (b"\n{}\n", "length"),
])
def test_bad_packets_are_rejected_with_one_line(data, reason):
    with pytest.raises(aj.ServoPacketError) as info:
        aj.parse_servo_packet(data)
    assert info.value.reason == reason and "\n" not in str(info.value)
    assert isinstance(info.value, ValueError)


def test_reply_is_newline_compact_json_newline():
    state = LevelTurn().state()
    data = aj.encode_reply(state)
    assert data.startswith(b"\n{") and data.endswith(b"}\n") and data.count(b"\n") == 2
    assert b" " not in data
    doc = json.loads(data)
    assert list(doc) == ["timestamp", "imu", "position", "quaternion", "attitude", "velocity",
                         "airspeed"]
    assert list(doc["imu"]) == ["gyro", "accel_body"]


@pytest.mark.parametrize("change, text", [
    ({"gyro_rad_s": (0.0, math.nan, 0.0)}, "finite"),
    ({"timestamp_s": math.inf}, "finite"),
    ({"timestamp_s": -1.0}, ">= 0"),
    ({"quaternion": (1.0, 0.1, 0.0, 0.0)}, "unit"),
    ({"quaternion": None, "attitude_rad": None}, "quaternion or attitude"),
    ({"position_ned_m": (0.0, 0.0)}, "3 components"),
    ({"airspeed_m_s": -1.0}, ">= 0"),
    ({"accel_body_m_s2": (0.0, 4e38, 0.0)}, "C float"),
    ({"velocity_ned_m_s": (0.0, "x", 0.0)}, "could not convert"),
    ({"gyro_rad_s": 3.0}, "sequence of 3"),
])
def test_bad_states_raise_one_line_value_errors(change, text):
    good = LevelTurn().state()
    fields = {name: getattr(good, name) for name in good.__dataclass_fields__}
    fields.update(change)
    with pytest.raises(ValueError, match=text) as info:
        aj.JsonState(**fields)
    assert "\n" not in str(info.value)


def test_instance_ports():
    assert [aj.instance_port(i) for i in (0, 1, 2)] == [9002, 9012, 9022]
    for bad in (-1, 1.0, True, 7000):
        with pytest.raises(ValueError):
            aj.instance_port(bad)


# ---------------------------------------------------------------------------------------
# ArduPilot's parser (the stand-in) reading the replies
# ---------------------------------------------------------------------------------------

def test_standin_reads_every_field_of_the_reply():
    state = LevelTurn(dt_s=0.25)
    state.k = 37
    s = state.state()
    parsed = parse_sensors(aj.encode_reply(s).strip(b"\n"))
    v = parsed.values
    # timestamp and position are doubles in ArduPilot: exact; the rest are C floats.
    assert v["timestamp"] == s.timestamp_s and v["position"] == s.position_ned_m
    for key, ref in (("gyro", s.gyro_rad_s), ("accel_body", s.accel_body_m_s2),
                     ("quaternion", s.quaternion), ("attitude", s.attitude_rad),
                     ("velocity", s.velocity_ned_m_s), ("airspeed", (s.airspeed_m_s,))):
        got = v[key] if isinstance(v[key], tuple) else (v[key],)
        np.testing.assert_allclose(got, ref, rtol=1e-7, atol=1e-30, err_msg=key)
    names = {"timestamp", "gyro", "accel_body", "position", "attitude", "quaternion",
             "velocity", "airspeed"}
    assert set(v) == names


def test_space_after_colon_breaks_arduPilots_parser():
    """The two-character rule: with json's default separators the vectors do not scan."""
    s = LevelTurn().state()
    compact = aj.encode_reply(s).strip(b"\n")
    spaced = json.dumps(json.loads(compact)).encode()  # separators (', ', ': ')
    assert parse_sensors(compact).bitmask & 0b1111111 == 0b1111111
    broken = parse_sensors(spaced)
    assert "gyro" not in broken.values and "Failed to parse" in broken.message
    # and ArduPilot then refuses the frame: no attitude parsed, frame counter unchanged
    ap = ArduPilotStandin(("127.0.0.1", 9))
    try:
        assert ap.accept(b"\n" + spaced + b"\n") is None
        assert ap.frame_counter == 0 and ap.messages == ["Did not receive attitude or quaternion"]
        assert ap.accept(b"\n" + compact + b"\n") is not None and ap.frame_counter == 1
    finally:
        ap.close()


def test_standin_follows_the_substring_rule():
    """ArduPilot finds keys by substring: a key containing 'position' earlier in the line is
    read as the position (the reason encode_reply fixes its key order)."""
    line = (b'{"timestamp":1,"imu":{"gyro":[0,0,0],"accel_body":[0,0,-9.8]},'
            b'"home_position":[5,5,5],"position":[1,2,3],"attitude":[0,0,0],'
            b'"velocity":[0,0,0]}')
    assert parse_sensors(line).values["position"] == (5.0, 5.0, 5.0)
    readme = (b'{"timestamp":2500,"imu":{"gyro":[0,0,0],"accel_body":[0,0,0]},'
              b'"position":[0,0,0],"attitude":[0,0,0],"velocity":[0,0,0]}')
    assert parse_sensors(readme).values["timestamp"] == 2500.0


# ---------------------------------------------------------------------------------------
# Lock-step, resend, reset
# ---------------------------------------------------------------------------------------

def test_one_step_and_one_reply_per_frame(link):
    physics, server, ap, records = link
    for k in range(50):
        parsed = _frame(server, ap, _pwm(k))
        assert parsed is not None, ap.messages
        assert parsed.values["timestamp"] == (k + 1) * DT_S
    assert ap.frame_counter == 50 and len(physics.steps) == 50
    assert [p for p, _ in physics.steps] == [tuple(_pwm(k)) for k in range(50)]
    assert {rate for _, rate in physics.steps} == {1200}
    assert ap.time_now_us == pytest.approx(50 * DT_S * 1e6, rel=1e-12)
    assert [r.frame_count for r in records] == list(range(50))
    assert {r.action for r in records} == {aj.STEP}
    assert records[-1].timestamp_s == 50 * DT_S and records[-1].pwm_us == tuple(_pwm(49))
    assert records[-1].source == ap.sock.getsockname()
    assert server.stats.steps == 50 and server.stats.resends == 0


def test_repeated_frame_is_answered_again_without_a_step(link):
    physics, server, ap, records = link
    for k in range(3):
        _frame(server, ap, _pwm(k))
    ap.send_servos(_pwm(3))
    assert server.serve_once(5.0)
    first = ap.read_datagram()  # this reply is "lost": ArduPilot never parses it
    ap.resend()  # 1 s later ArduPilot sends frame 3 again
    assert server.serve_once(5.0)
    again = ap.receive()
    assert again is not None and again.values["timestamp"] == 4 * DT_S
    assert ap.last_packet and len(physics.steps) == 4 and server.stats.resends == 1
    ap.resend()
    assert server.serve_once(5.0)
    assert ap.read_datagram() == first  # the same bytes every time
    assert [r.action for r in records[-3:]] == [aj.STEP, aj.RESEND, aj.RESEND]
    assert records[-1].timestamp_s == records[-2].timestamp_s == 4 * DT_S
    nxt = _frame(server, ap, _pwm(99))  # the counter moved on after the parsed reply
    assert nxt is not None and nxt.values["timestamp"] == 5 * DT_S
    assert physics.steps[-1][0] == tuple(_pwm(99))


def test_resends_that_crossed_the_reply_are_dropped_so_arduPilot_never_lags(link):
    """A frame answered later than ArduPilot's 1 s re-send: its re-sends wait in the queue
    behind it. Each one answered would be one more reply in ArduPilot's socket, which reads
    one datagram per frame: it would read every later reply that many frames late, for the
    rest of the flight (measured with ArduPlane at 240 Hz: 6 re-sends, 25 ms of lag)."""
    physics, server, ap, records = link
    for k in range(3):
        _frame(server, ap, _pwm(k))
    ap.send_servos(_pwm(3))
    ap.resend()  # our step took over 1 s: ArduPilot sent frame 3 again, twice
    ap.resend()
    assert server.serve_once(5.0)  # frame 3 stepped and answered, its re-sends dropped
    assert server.stats.crossed_resends == 2 and server.stats.resends == 0
    assert ap.receive().values["timestamp"] == 4 * DT_S
    for k in range(4, 10):  # every later reply is the one for the frame just sent
        parsed = _frame(server, ap, _pwm(k))
        assert parsed is not None and parsed.values["timestamp"] == (k + 1) * DT_S
    assert not ap.pending()
    assert ap.frame_counter == 10 and ap.time_now_us == pytest.approx(10 * DT_S * 1e6)
    assert len(physics.steps) == 10 and [r.frame_count for r in records] == list(range(10))


def test_a_datagram_queued_behind_the_answered_frame_is_handled_next(link):
    physics, server, ap, _ = link
    _frame(server, ap, _pwm(0))
    ap.send_servos(_pwm(1))
    ap.send_raw(b"hello")  # queued behind frame 1: read after the reply, held, then handled
    assert server.serve_once(5.0)
    assert ap.receive().values["timestamp"] == 2 * DT_S
    assert server.stats.rejected == 0
    assert server.serve_once(0.0)
    assert server.stats.rejected == 1 and server.stats.crossed_resends == 0
    assert _frame(server, ap, _pwm(2)).values["timestamp"] == 3 * DT_S


def test_backward_frame_count_resets_the_physics(link):
    physics, server, ap, records = link
    for k in range(20):
        _frame(server, ap, _pwm(k))
    ap.restart()  # a new SITL process: frame_count 0 again
    parsed = _frame(server, ap, _pwm(0))
    assert physics.resets == 1 and server.stats.resets == 1
    assert parsed is not None and parsed.values["timestamp"] == DT_S  # reset, then one step
    assert records[-1].action == aj.RESET and records[-1].frame_count == 0
    assert ap.physics_resets_seen == 0  # ArduPilot's clock starts again cleanly
    for k in range(1, 5):
        _frame(server, ap, _pwm(k))
    assert ap.time_now_us == pytest.approx(5 * DT_S * 1e6)
    assert len(physics.steps) == 25 and records[-1].action == aj.STEP


def test_skipped_frames_are_counted_and_stepped_once(link):
    physics, server, ap, _ = link
    _frame(server, ap, _pwm(0))
    ap.frame_counter = 4  # frames 1..3 never arrived
    _frame(server, ap, _pwm(4))
    assert server.stats.frames_skipped == 3 and len(physics.steps) == 2


def test_bad_datagrams_are_counted_never_answered_and_the_link_goes_on(link):
    physics, server, ap, _ = link
    _frame(server, ap, _pwm(0))
    for junk in (b"hello", struct.pack("<HHI16H", 1234, 1200, 1, *[1500] * 16)):
        ap.send_raw(junk)
        assert server.serve_once(5.0)
    assert server.stats.rejected == 2
    assert server.stats.by_reason == {"length": 1, "magic": 1}
    assert "1234" in server.stats.last_error
    parsed = _frame(server, ap, _pwm(1))  # the next datagram the stand-in reads is this one
    assert parsed is not None and parsed.values["timestamp"] == 2 * DT_S
    assert len(physics.steps) == 2


def test_thirty_two_channels(link):
    physics, server, _, _ = link
    ap = ArduPilotStandin(server.address, channels=32, rate_hz=400)
    try:
        pwm = list(range(1000, 1032))
        assert _frame(server, ap, pwm) is not None
        assert physics.steps[-1] == (tuple(pwm), 400)
    finally:
        ap.close()


def test_serve_loop_in_a_thread_stops_when_asked():
    physics = LevelTurn()
    stop = threading.Event()
    with aj.LockstepServer(physics, port=0) as server:
        thread = threading.Thread(target=server.serve, args=(stop.is_set, 0.02), daemon=True)
        thread.start()
        ap = ArduPilotStandin(server.address)
        try:
            for k in range(30):
                ap.send_servos(_pwm(k))
                assert ap.receive() is not None
        finally:
            ap.close()
            stop.set()
            thread.join(timeout=5.0)
        assert not thread.is_alive() and len(physics.steps) == 30


def test_bind_failure_is_a_one_line_value_error():
    with aj.LockstepServer(LevelTurn(), port=0) as first:
        with pytest.raises(ValueError, match="cannot bind") as info:
            aj.LockstepServer(LevelTurn(), port=first.address[1])
        assert "\n" not in str(info.value)


# ---------------------------------------------------------------------------------------
# Units and frames as ArduPilot reads them
# ---------------------------------------------------------------------------------------

def _fly(order: str = "wxyz", frames: int = 200):
    physics = LevelTurn(quaternion_order=order)
    with aj.LockstepServer(physics, port=0) as server:
        ap = ArduPilotStandin(server.address)
        try:
            out = []
            for k in range(frames):
                parsed = _frame(server, ap, _pwm(k))
                assert parsed is not None, ap.messages
                out.append(parsed)
        finally:
            ap.close()
    return physics, out


def _frame_errors(parsed) -> dict[str, float]:
    """Largest inconsistencies of a parsed history, in ArduPilot's frames (central
    differences over the frames' timestamps)."""
    t = np.array([p.values["timestamp"] for p in parsed])
    pos = np.array([p.values["position"] for p in parsed])
    vel = np.array([p.values["velocity"] for p in parsed])
    acc_b = np.array([p.values["accel_body"] for p in parsed])
    gyro = np.array([p.values["gyro"] for p in parsed])
    dcm = np.array([dcm_of(p) for p in parsed])
    dt = t[2:] - t[:-2]
    # specific force rotated to NED plus gravity (NED down) = acceleration over ground
    acc_ned = np.einsum("kij,kj->ki", dcm[1:-1], acc_b[1:-1]) + [0.0, 0.0, G_M_S2]
    dv = (vel[2:] - vel[:-2]) / dt[:, None]
    # d(position)/dt = velocity
    dp = (pos[2:] - pos[:-2]) / dt[:, None]
    # Ṙ = R [ω]×  →  [ω]× = Rᵀ Ṙ (body rates in body FRD)
    rdot = (dcm[2:] - dcm[:-2]) / dt[:, None, None]
    w = np.einsum("kji,kjl->kil", dcm[1:-1], rdot)
    omega = np.stack([w[:, 2, 1], w[:, 0, 2], w[:, 1, 0]], axis=1)
    euler = np.array([dcm_from_euler(*p.values["attitude"]) for p in parsed])
    return {
        "accel_m_s2": float(np.abs(acc_ned - dv).max()),
        "velocity_m_s": float(np.abs(dp - vel[1:-1]).max()),
        "gyro_rad_s": float(np.abs(omega - gyro[1:-1]).max()),
        "euler_vs_quaternion": float(np.abs(euler - dcm).max()),
    }


def test_imu_position_velocity_attitude_are_consistent_in_arduPilots_frames():
    physics, parsed = _fly()
    err = _frame_errors(parsed)
    # float32 storage of velocity (15 m/s → 1e-6 m/s) over 2·dt = 2 ms gives ≈ 1e-3 m/s² of
    # differencing noise; the kinematics themselves are exact to O(dt²).
    assert err["accel_m_s2"] < 5e-3, err
    assert err["velocity_m_s"] < 1e-6, err
    assert err["gyro_rad_s"] < 5e-3, err
    assert err["euler_vs_quaternion"] < 1e-6, err
    # the turn is real: 1.1 g of specific force and a yaw rate of 0.38 rad/s are seen
    last = parsed[-1].values
    assert last["accel_body"][2] == pytest.approx(-G_M_S2 / math.cos(math.radians(30)), 1e-6)
    assert math.hypot(*last["gyro"][1:]) == pytest.approx(physics.omega, rel=1e-6)
    assert physics.omega == pytest.approx(0.3775, abs=1e-4)


def test_wrong_quaternion_order_is_caught_by_the_frame_check():
    """Negative control: (x, y, z, w) instead of ArduPilot's (w, x, y, z)."""
    _, parsed = _fly(order="xyzw", frames=20)
    err = _frame_errors(parsed)
    assert err["accel_m_s2"] > 1.0 and err["euler_vs_quaternion"] > 0.1


def test_level_at_rest_reads_minus_g_on_body_z():
    physics = LevelTurn(speed_m_s=1.0, bank_rad=0.0)
    physics.v = 0.0
    parsed = parse_sensors(aj.encode_reply(physics.state()).strip(b"\n"))
    assert parsed.values["accel_body"] == pytest.approx((0.0, 0.0, -G_M_S2), abs=1e-6)
    dcm = np.array(dcm_of(parsed))
    np.testing.assert_allclose(dcm, np.eye(3), atol=1e-7)


# ---------------------------------------------------------------------------------------
# The source check: one peer per session (faults found by fault injection: one stray
# 40-byte frame-0 packet reset a flight; a second sender caused 102 resets)
# ---------------------------------------------------------------------------------------

class FakeClock:
    """A wall clock the test advances [s]: no test here depends on the machine's pace."""

    def __init__(self) -> None:
        self.t = 1000.0

    def __call__(self) -> float:
        return self.t


@pytest.fixture
def bound():
    """A server on a fake clock, its events, and ArduPilot's stand-in bound as the peer."""
    physics = LevelTurn()
    clock = FakeClock()
    events: list[tuple[str, str]] = []
    records: list[aj.FrameRecord] = []
    server = aj.LockstepServer(physics, port=0, on_frame=records.append,
                               on_event=lambda lvl, text: events.append((lvl, text)),
                               clock=clock)
    ap = ArduPilotStandin(server.address)
    others: list[ArduPilotStandin] = []
    yield physics, server, ap, clock, events, others
    for o in (ap, *others):
        o.close()
    server.close()


def _paced_frame(server, ap, clock, pwm, pace_s):
    clock.t += pace_s
    return _frame(server, ap, pwm)


def test_stray_frame_zero_from_another_port_never_resets_the_flight(bound):
    physics, server, ap, clock, events, others = bound
    for k in range(50):
        assert _paced_frame(server, ap, clock, _pwm(k), 1e-3) is not None
    stray = ArduPilotStandin(server.address)
    others.append(stray)
    stray.send_servos([1500] * 16)  # 40 bytes, magic 18458, frame_count 0
    assert len(stray.last_packet) == 40
    assert server.serve_once(5.0)
    assert physics.resets == 0 and server.stats.resets == 0 and physics.k == 50
    assert server.stats.foreign == 1 and server.stats.first_foreign == stray.source
    assert not stray.pending()  # never answered
    assert [lvl for lvl, _ in events] == ["INFO", "WARNING"]
    assert f"{stray.source[1]}" in events[-1][1] and "ignored" in events[-1][1]
    # the flight goes on where it was
    parsed = _paced_frame(server, ap, clock, _pwm(50), 1e-3)
    assert parsed.values["timestamp"] == 51 * DT_S and server.peer == ap.source


def test_second_sender_interleaving_frames_causes_no_reset_and_no_step(bound):
    physics, server, ap, clock, events, others = bound
    second = ArduPilotStandin(server.address)
    others.append(second)
    _paced_frame(server, ap, clock, _pwm(0), 1e-3)
    for k in range(1, 121):
        second.send_servos(_pwm(1000 + k))  # its own counter, 0 every time (never answered)
        second.frame_counter = k % 7  # and any counts at all, going back and forth
        assert server.serve_once(5.0)
        assert _paced_frame(server, ap, clock, _pwm(k), 1e-3) is not None
    assert server.stats.resets == 0 and physics.resets == 0
    assert len(physics.steps) == 121 and server.stats.foreign == 120
    assert all(p == tuple(_pwm(k)) for k, (p, _) in enumerate(physics.steps))
    assert not second.pending()
    # reported: the first one, then at 10 and 100 (not 120 lines)
    warnings = [t for lvl, t in events if lvl == "WARNING"]
    assert len(warnings) == 3 and "10 packets" in warnings[1] \
        and "100 packets" in warnings[2]
    assert server.peer == ap.source


def test_restart_from_the_same_port_resets_and_a_stale_count_is_ignored(bound):
    physics, server, ap, clock, events, _ = bound
    for k in range(20):
        _paced_frame(server, ap, clock, _pwm(k), 1e-3)
    # a smaller frame_count other than 0: not a restart (ArduPilot restarts at frame 0)
    ap.sock.sendto(ap.packet(_pwm(0), frame_count=7), server.address)
    assert server.serve_once(5.0)
    assert server.stats.stale == 1 and physics.resets == 0 and not ap.pending()
    ap.restart()  # the same socket: frame 0 again from the peer's port
    parsed = _paced_frame(server, ap, clock, _pwm(0), 1e-3)
    assert physics.resets == 1 and server.stats.resets == 1 and server.stats.rebinds == 0
    assert parsed.values["timestamp"] == DT_S
    assert "restarted" in events[-1][1]


def test_killed_arduPilot_restarted_on_a_new_port_rebinds_after_the_silence(bound):
    physics, server, ap, clock, events, _ = bound
    for k in range(30):
        _paced_frame(server, ap, clock, _pwm(k), 1e-3)
    old = ap.source
    ap.restart(new_process=True)  # SIGKILL, then a new ArduPlane: new ephemeral port
    assert ap.source != old
    clock.t += 1.0  # its frame 0 within the silence: could be a second sender
    ap.send_servos(_pwm(0))
    assert server.serve_once(5.0)
    assert not ap.pending() and physics.resets == 0 and server.stats.foreign == 1
    clock.t += aj.PEER_SILENCE_S  # ArduPilot re-sends frame 0 every second
    ap.resend()
    assert server.serve_once(5.0)
    parsed = ap.receive()
    assert parsed is not None and parsed.values["timestamp"] == DT_S
    assert physics.resets == 1 and server.stats.rebinds == 1 and server.peer == ap.source
    assert "new port" in events[-1][1]
    # the old port, back from the dead, is now the foreign one
    stale = ArduPilotStandin(server.address)
    try:
        stale.send_servos(_pwm(0))
        assert server.serve_once(5.0)
        assert physics.resets == 1 and server.stats.foreign == 2
    finally:
        stale.close()


def test_connected_wall_time_excludes_waiting_and_the_dead_peer(bound):
    """The real-time factor's denominator at a known pace: 200 frames 2 ms apart (a pace
    of 1/960 s of physics per 2 ms: 0.52 x real time), a kill, 10 s of silence, a new
    ArduPilot, 100 more frames at the same pace."""
    physics, server, ap, clock, _, _ = bound
    clock.t += 25.0  # waiting for ArduPilot to boot: not connected time
    pace_s = 2e-3
    for k in range(200):
        _paced_frame(server, ap, clock, _pwm(k), pace_s)
    assert server.stats.connected_wall_s == pytest.approx(199 * pace_s, rel=1e-9)
    ap.restart(new_process=True)
    clock.t += 10.0
    for k in range(100):
        assert _paced_frame(server, ap, clock, _pwm(k), pace_s) is not None
    assert server.stats.rebinds == 1
    assert server.stats.connected_wall_s == pytest.approx(298 * pace_s, rel=1e-9)


def test_a_slow_step_of_ours_counts_as_connected_time():
    """A 4 s stall inside our step (a kernel compiling, a loaded machine) is the session
    being slow, not the peer being gone: it counts, and the peer is still the peer."""
    clock = FakeClock()

    class Stalling(LevelTurn):
        def step(self, pwm_us, frame_rate_hz):
            super().step(pwm_us, frame_rate_hz)
            if self.k == 10:
                clock.t += 4.0

    physics = Stalling()
    with aj.LockstepServer(physics, port=0, clock=clock) as server:
        ap = ArduPilotStandin(server.address)
        try:
            for k in range(20):
                assert _paced_frame(server, ap, clock, _pwm(k), 1e-3) is not None
        finally:
            ap.close()
    assert server.stats.connected_wall_s == pytest.approx(19e-3 + 4.0, rel=1e-9)
    assert server.stats.rebinds == 0 and physics.resets == 0


# ------------------------------------------------------------------ the fast reply, pacing
def _states(n: int, seed: int = 1):
    """Random states: every number class (zero, -0.0, subnormals of double and single,
    1e±300 in the doubles, up to ±3e38 in the C floats, long mantissas), each optional field
    present or not."""
    rng = np.random.default_rng(seed)

    def picks(top: int):
        return (lambda: rng.uniform(-1e3, 1e3), lambda: 0.0, lambda: -0.0, lambda: 5e-324,
                lambda: 1e-40, lambda: rng.standard_normal() * 10.0 ** rng.integers(-300, top),
                lambda: 123456789.123456789, lambda: 1e16)

    doubles, singles = picks(300), picks(38)

    def d() -> float:
        return float(doubles[rng.integers(len(doubles))]())

    def f() -> float:
        return float(singles[rng.integers(len(singles))]())

    for _ in range(n):
        q = rng.standard_normal(4)
        q = tuple(q / np.linalg.norm(q))
        has_q = rng.uniform() < 0.7
        yield aj.JsonState(
            abs(d()), (f(), f(), f()), (f(), f(), f()), (d(), d(), d()), (f(), f(), f()),
            quaternion=q if has_q else None,
            attitude_rad=(f(), f(), f()) if not has_q or rng.uniform() < 0.5 else None,
            airspeed_m_s=abs(f()) if rng.uniform() < 0.5 else None)


def _single(x: float) -> float:
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _same(a: float, b: float) -> bool:
    """Equal, with the sign of a zero."""
    return a == b and math.copysign(1.0, a) == math.copysign(1.0, b)


DOUBLE_KEYS = ("timestamp", "position")  # doubles in ArduPilot (SIM_JSON.h); the rest floats


def test_the_reply_is_json_dumps_document_in_arduPilots_precision():
    """The fast reply (one %-format, floats rounded to single precision) is the document
    ``json.dumps`` writes, key for key in the same order, each number the one ArduPilot
    stores: the doubles (timestamp, position) exactly, every other field as the float
    nearest the state's (what strtof of json.dumps's text gives: float32(x))."""
    rounded = 0
    for state in _states(5000):
        data = aj.encode_reply(state)
        assert data.startswith(b"\n{") and data.endswith(b"}\n") and b" " not in data
        mine = json.loads(data, parse_int=float)
        ref = json.loads(aj.encode_reply_json(state), parse_int=float)
        flat_mine = {**mine.pop("imu"), **mine}
        flat_ref = {**ref.pop("imu"), **ref}
        assert list(flat_mine) == list(flat_ref)
        for key, ref_value in flat_ref.items():
            a = flat_mine[key] if isinstance(flat_mine[key], list) else [flat_mine[key]]
            b = ref_value if isinstance(ref_value, list) else [ref_value]
            assert len(a) == len(b), key
            for x, y in zip(a, b, strict=True):
                if key in DOUBLE_KEYS:
                    assert _same(x, y), (key, x, y)
                else:
                    assert _same(_single(x), _single(y)), (key, x, y)
                    rounded += x != y
    assert rounded > 1000  # the floats' text is not json's: the test compares numbers


def test_the_floats_text_is_read_back_to_the_same_single_by_both_of_arduPilots_reads():
    """``sscanf("%f")`` (vectors: strtof, straight to single) and ``atof`` then the cast
    (airspeed: through a double) give the same float from the 9-digit text: the stand-in's
    two readers on every float of 2000 replies."""
    from tests.ardupilot_standin import c_atof

    for state in _states(2000, seed=5):
        line = aj.encode_reply(state).strip(b"\n")
        parsed = parse_sensors(line).values
        assert parsed["gyro"] == tuple(map(_single, state.gyro_rad_s))
        assert parsed["velocity"] == tuple(map(_single, state.velocity_ned_m_s))
        assert parsed["timestamp"] == state.timestamp_s
        assert parsed["position"] == state.position_ned_m
        if state.airspeed_m_s is not None:
            at = line.index(b'"airspeed":') + len(b'"airspeed":')
            assert _single(c_atof(line[at:])) == _single(state.airspeed_m_s)
            assert parsed["airspeed"] == _single(state.airspeed_m_s)


def test_the_standins_cheap_read_agrees_with_its_full_parse():
    from tests.ardupilot_standin import reply_timestamp

    rng = np.random.default_rng(2)
    for _ in range(500):  # magnitudes a flight sends (ArduPilot's floats are single)
        v = tuple(map(float, rng.uniform(-1e3, 1e3, 13)))
        state = aj.JsonState(abs(v[0]), v[1:4], v[4:7], v[7:10], v[10:13],
                             attitude_rad=(0.1, 0.2, 0.3),
                             airspeed_m_s=float(rng.uniform(0, 40)) if v[0] > 0 else None)
        data = aj.encode_reply(state)
        parsed = parse_sensors(data.strip(b"\n"))
        ts, airspeed = reply_timestamp(data)
        assert ts == parsed.values["timestamp"]
        assert airspeed == pytest.approx(parsed.values.get("airspeed", 0.0), rel=1e-7)


class _FakeBackend:
    """The stand-in's frames against a simulated clock: each reply takes ``cost_s`` [s]
    and advances the physics by DT_S (no sockets, no wall clock)."""

    def __init__(self, ap, cost_s: float) -> None:
        self.now = 0.0
        self.ts = 0.0
        self.cost_s = cost_s
        self.ap = ap
        ap.clock = lambda: self.now
        ap.sleep = self.sleep
        ap._frame = self.frame

    def sleep(self, s: float) -> None:
        self.now += s

    def frame(self, full: bool):
        self.now += self.cost_s
        self.ts += DT_S
        self.ap.last_timestamp_s = self.ts  # what the stand-in's own read keeps
        return self.cost_s, self.ts, 15.0


@pytest.mark.parametrize("cost_s, speedup", [(10e-6, 1.0), (10e-6, 10.0), (10e-6, 50.0),
                                             (100e-6, 5.0)])
def test_paced_standin_holds_a_speedup_the_backend_can_answer(cost_s, speedup):
    """Paced as ArduPilot paces itself (sleep debt, slept off above 5 ms): the real-time
    factor is the speed-up asked for, within the 5 ms of debt left at the end."""
    from tests.ardupilot_standin import MIN_SLEEP_S, PacedStandin

    ap = PacedStandin(("127.0.0.1", 9))
    try:
        _FakeBackend(ap, cost_s)
        st = ap.fly(20000, speedup)
    finally:
        ap.close()
    target_wall = st.physics_s / speedup
    assert st.wall_s == pytest.approx(target_wall, abs=MIN_SLEEP_S + 2 * cost_s)
    assert st.answered_per_s == pytest.approx(1.0 / cost_s)


@pytest.mark.parametrize("speedup", [None, 20.0])
def test_paced_standin_runs_at_the_backends_rate_when_asked_for_more(speedup):
    """A backend of 100 µs a frame (9.6 x real time at 960 Hz) asked for 20 x, or free: the
    real-time factor is what it answers, 9.6 (a slow frame is never made up by sleeping)."""
    from tests.ardupilot_standin import PacedStandin

    ap = PacedStandin(("127.0.0.1", 9))
    try:
        _FakeBackend(ap, 100e-6)
        st = ap.fly(5000, speedup)
    finally:
        ap.close()
    assert st.real_time_factor == pytest.approx(DT_S / 100e-6, rel=1e-9)
    assert st.grounded == 0 and st.frames_per_s == pytest.approx(1e4, rel=1e-9)
