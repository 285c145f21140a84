"""Hostile and confused peers of the two links: floods from other local ports, squatted
ground-station slots, ArduPilot's frame counter wrapping, a stray packet binding the
ArduPilot session before ArduPlane, and a session's requested end.

Faults found by fault injection: ``ardupilot`` lock-step fell from 7689 to 36 frames/s under
199k foreign packets/s and ``sitl`` telemetry from 50 Hz to 0 Hz under 57-95k malformed
frames or heartbeats a second (scripts/flood_peers.py measures the rates; here only the
behaviour that keeps them: bounded batches, drops by address before any parsing, the bound
peer served in the same call); four sockets sending a heartbeat every 2 s held all four
``udpin`` slots and a new ground station got nothing; a frame counter wrapping past 2³² was
taken for a restart; a frame-0 packet from 127.0.0.2 bound the session for good; a normal
end of a flight read as an interrupt.

No test depends on the machine's pace: the ArduPilot server runs on a fake clock, the
MAVLink link is serviced with explicit wall times, and the only real waits are failure
limits.
"""

from __future__ import annotations

import socket

import pytest

from bioflex_jsb.links import ardupilot_json as aj
from tests.ardupilot_standin import ArduPilotStandin
from tests.test_ardupilot_json import DT_S, FakeClock, LevelTurn, _pwm

U32 = 2 ** 32


# ------------------------------------------------------------------------------ ArduPilot
@pytest.fixture
def server():
    """A lock-step server on a fake clock, its events, and the stand-ins made (closed)."""
    physics = LevelTurn()
    clock = FakeClock()
    events: list[tuple[str, str]] = []
    srv = aj.LockstepServer(physics, port=0, clock=clock,
                            on_event=lambda lvl, text: events.append((lvl, text)))
    made: list[ArduPilotStandin] = []

    def standin(address: str = "127.0.0.1") -> ArduPilotStandin:
        ap = ArduPilotStandin(srv.address, timeout_s=5.0)
        if address != "127.0.0.1":  # another loopback address (127.0.0.0/8 is all local)
            ap.sock.close()
            ap.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            ap.sock.bind((address, 0))
            ap.sock.settimeout(5.0)
        made.append(ap)
        return ap

    yield physics, srv, clock, events, standin
    for ap in made:
        ap.close()
    srv.close()


def _answered(srv, ap, pwm, clock, pace_s=1e-3):
    """One frame of ``ap``: sent, served (the calls a flood in front of it needs), read."""
    clock.t += pace_s
    ap.send_servos(pwm)
    for _ in range(64):
        assert srv.serve_once(5.0)
        if ap.pending():
            return ap.receive()
    raise AssertionError("the frame was never answered")


def test_a_frame_counter_wrapping_past_2_32_is_the_next_frame_not_a_restart(server):
    physics, srv, clock, events, standin = server
    ap = standin()
    ap.frame_counter = U32 - 3
    for k in range(6):  # 2^32-3, -2, -1, then 0, 1, 2
        parsed = _answered(srv, ap, _pwm(k), clock)
        assert parsed is not None and parsed.values["timestamp"] == (k + 1) * DT_S
        ap.frame_counter %= U32  # ArduPilot's uint32 frame_counter++
    assert physics.resets == 0 and srv.stats.resets == 0 and srv.stats.stale == 0
    assert srv.stats.frames_skipped == 0 and srv.stats.steps == 6
    assert srv.last_frame_count == 2 and not any("restart" in t for _, t in events)
    # a wrap that jumps (frames lost around it) is counted as skipped frames, modulo 2^32
    ap.frame_counter = U32 - 2
    _answered(srv, ap, _pwm(9), clock)
    ap.frame_counter = 5
    _answered(srv, ap, _pwm(10), clock)
    assert srv.stats.resets == 0 and srv.stats.frames_skipped == (U32 - 2 - 3) + 6
    # a restart far from the wrap is still a restart
    for k in range(3):
        ap.frame_counter = 1000 + k
        _answered(srv, ap, _pwm(k), clock)
    ap.restart()
    _answered(srv, ap, _pwm(0), clock)
    assert physics.resets == 1 and srv.stats.resets == 1


def test_a_stray_from_another_address_before_arduplane_does_not_hold_the_session(server):
    """A frame-0 packet from 127.0.0.2 reaches the port first and binds the session; the
    real ArduPlane (127.0.0.1) is ignored while the stray could still be alive, then, the
    stray silent for PEER_SILENCE_S, ArduPlane's re-sent frame 0 binds it: nothing reset,
    and the event does not call it a restart."""
    physics, srv, clock, events, standin = server
    stray = standin("127.0.0.2")
    stray.send_servos([1500] * 16)
    assert srv.serve_once(5.0) and srv.peer == stray.source and stray.pending()
    ardu = standin()
    clock.t += 0.5
    ardu.send_servos(_pwm(0))
    assert srv.serve_once(5.0)
    assert not ardu.pending() and srv.stats.foreign == 1
    assert "silent" in events[-1][1]  # the warning says when another sender is taken
    for _ in range(3):  # ArduPlane re-sends frame 0 every second
        clock.t += 1.0
        ardu.resend()
        assert srv.serve_once(5.0)
    parsed = ardu.receive()
    assert parsed is not None and srv.peer == ardu.source
    assert physics.resets == 0 and srv.stats.resets == 0 and srv.stats.strays == 1
    assert "restarted" not in events[-1][1] and "127.0.0.2" in events[-1][1]
    for k in range(1, 20):
        assert _answered(srv, ardu, _pwm(k), clock) is not None
    assert srv.peer == ardu.source and len(physics.steps) == 21  # the stray's, then 20


def test_a_same_address_stray_before_arduplane_is_not_reported_as_a_restart(server):
    physics, srv, clock, events, standin = server
    stray = standin()
    stray.send_servos([1500] * 16)
    assert srv.serve_once(5.0)
    ardu = standin()
    clock.t += aj.PEER_SILENCE_S
    ardu.send_servos(_pwm(0))
    assert srv.serve_once(5.0) and ardu.receive() is not None
    assert srv.peer == ardu.source and physics.resets == 0 and srv.stats.resets == 0
    assert not any("restarted" in t for _, t in events)


def test_a_new_arduplane_on_another_address_after_a_flight_is_bound_with_a_reset(server):
    physics, srv, clock, events, standin = server
    first = standin()
    for k in range(30):
        _answered(srv, first, _pwm(k), clock)
    second = standin("127.0.0.2")  # the first one killed; a new one elsewhere
    clock.t += 1.0
    second.send_servos(_pwm(0))
    assert srv.serve_once(5.0) and not second.pending()  # within the silence: foreign
    clock.t += aj.PEER_SILENCE_S
    second.frame_counter = 7  # not frame 0: not a new ArduPilot, still foreign
    second.send_servos(_pwm(0))
    assert srv.serve_once(5.0) and not second.pending() and srv.peer == first.source
    second.frame_counter = 0
    second.send_servos(_pwm(0))
    assert srv.serve_once(5.0)
    parsed = second.receive()
    assert parsed is not None and parsed.values["timestamp"] == DT_S
    assert srv.peer == second.source and physics.resets == 1 and srv.stats.rebinds == 1
    assert "physics reset" in events[-1][1] and "127.0.0.2" in events[-1][1]


def test_foreign_packets_are_dropped_by_address_before_parsing(server, monkeypatch):
    """A flood from another port in front of the peer's frame: each foreign datagram is
    counted without being parsed, the peer's frame is answered, warnings stay few."""
    physics, srv, clock, events, standin = server
    ap = standin()
    _answered(srv, ap, _pwm(0), clock)
    parsed = []
    real_parse = aj.parse_servo_packet
    monkeypatch.setattr(aj, "parse_servo_packet",
                        lambda data: parsed.append(len(data)) or real_parse(data))
    flood = standin()
    packet = flood.packet([1500] * 16, frame_count=0)
    for _ in range(150):
        flood.send_raw(packet)
        flood.send_raw(b"\xff" * 40)
    reply = _answered(srv, ap, _pwm(1), clock)
    assert reply is not None and reply.values["timestamp"] == 2 * DT_S
    assert parsed == [40]  # the peer's frame only
    assert srv.stats.foreign == 300 and srv.stats.rejected == 0
    warnings = [t for lvl, t in events if lvl == "WARNING"]
    assert len(warnings) == 3  # the 1st, the 10th, the 100th


def test_serve_once_reads_a_bounded_batch_and_returns_after_an_answer(server):
    physics, srv, clock, events, standin = server
    ap = standin()
    _answered(srv, ap, _pwm(0), clock)
    flood = standin()
    queued = 2 * aj.MAX_BATCH + 10
    for _ in range(queued):
        flood.send_raw(b"x" * 40)
    clock.t += 1e-3
    ap.send_servos(_pwm(1))
    calls, reads = 0, []
    while not ap.pending():
        before = srv.stats.received
        assert srv.serve_once(5.0)
        reads.append(srv.stats.received - before)
        calls += 1
        assert calls <= 4
    assert max(reads) <= aj.MAX_BATCH and sum(reads) == queued + 1  # + the frame
    assert reads[-1] <= aj.MAX_BATCH and calls == 3
    assert srv.stats.steps == 2


def test_the_receive_buffer_is_enlarged_within_the_kernels_limit(server):
    _, srv, _, _, _ = server
    granted = srv._sock.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
    try:
        with open("/proc/sys/net/core/rmem_max") as fh:
            rmem_max = int(fh.read())
    except OSError:
        pytest.skip("no /proc/sys/net/core/rmem_max here")
    # Linux reports twice what it grants (its bookkeeping); root may exceed rmem_max
    assert granted >= min(aj.RECV_BUFFER_BYTES, rmem_max)
