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

import json
import socket
import sys
import time

import pytest
from pymavlink.dialects.v20 import common as M

from bioflex_jsb.links import ardupilot_json as aj
from bioflex_jsb.links import mavlink as ml
from bioflex_jsb.links import udp_guard as ug
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


linux_only = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="socket filters (SO_ATTACH_FILTER) are Linux's")


def _drain(sock) -> list:
    out = []
    while True:
        try:
            out.append(sock.recvfrom(65536))
        except BlockingIOError:
            return out


@linux_only
def test_a_flooding_source_is_dropped_by_the_kernel_for_a_while_then_let_through():
    """The filter program on a real socket: the blocked source's datagrams never reach the
    queue, another source's do; after BLOCK_S it is let through (and blocked again only if
    it floods again)."""
    rx = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    rx.bind(("127.0.0.1", 0))
    rx.setblocking(False)
    flood, other = (socket.socket(socket.AF_INET, socket.SOCK_DGRAM) for _ in range(2))
    try:
        for s in (flood, other):
            s.bind(("127.0.0.1", 0))
        guard = ug.FloodGuard(rx)
        t = 100.0
        assert guard.check(t) == ([], [])
        n = int(1.5 * ug.FLOOD_RATE_PER_S * ug.WINDOW_S)  # half as fast again as the limit
        for _ in range(n):
            guard.count(flood.getsockname())
        guard.count(other.getsockname())
        blocked, released = guard.check(t + 1.01 * ug.WINDOW_S)
        assert blocked == [flood.getsockname()] and released == [] and guard.blocks == 1
        for _ in range(50):
            flood.sendto(b"flood", rx.getsockname())
        other.sendto(b"hello", rx.getsockname())
        _settle_port(rx.getsockname()[1])
        assert [(d, a) for d, a in _drain(rx)] == [(b"hello", other.getsockname())]
        assert guard.check(t + 1.01 * ug.WINDOW_S + ug.BLOCK_S) == ([], [flood.getsockname()])
        flood.sendto(b"flood", rx.getsockname())
        _settle_port(rx.getsockname()[1])
        assert [d for d, _ in _drain(rx)] == [b"flood"]
    finally:
        for s in (rx, flood, other):
            s.close()


@linux_only
def test_the_arduplane_server_blocks_a_flood_but_never_its_lockstepping_peer(server):
    physics, srv, clock, events, standin = server
    ap = standin()
    for k in range(5):
        _answered(srv, ap, _pwm(k), clock, pace_s=1e-4)
    flood = standin()
    n = int(1.5 * ug.FLOOD_RATE_PER_S * ug.WINDOW_S)
    # more than the flood rate from the flooder, and from ArduPilot too (frames 0.1 ms apart)
    for k in range(n):
        flood.send_raw(b"x" * 40)
        if k % 100 == 0:
            _answered(srv, ap, _pwm(k), clock, pace_s=1e-4)
    clock.t += 1.01 * ug.WINDOW_S  # the window's end
    _answered(srv, ap, _pwm(1), clock, pace_s=0.0)
    assert srv.stats.blocked == 1 and srv.guard.blocked == {flood.source: pytest.approx(
        clock.t + ug.BLOCK_S)}
    assert any("dropped by the kernel" in t and str(flood.source[1]) in t for _, t in events)
    received = srv.stats.received
    for _ in range(100):
        flood.send_raw(b"x" * 40)
    assert _answered(srv, ap, _pwm(2), clock) is not None
    assert srv.stats.received == received + 1  # the frame only: the flood never queued
    assert ap.source not in srv.guard.blocked


# ------------------------------------------------------------------------------- MAVLink
class Params:
    names = ("A",)

    def get(self, name: str) -> float:
        return 1.0

    def set(self, name: str, value: float) -> float:
        return 1.0


def _mav(system: int = 255):
    return M.MAVLink(None, srcSystem=system, srcComponent=190)


def _heartbeat(system: int = 255) -> bytes:
    mav = _mav(system)
    return mav.heartbeat_encode(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(mav)


class Station:
    """A UDP socket speaking MAVLink to the link (a ground station, a squatter, a flood)."""

    def __init__(self, target, system: int = 255) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.setblocking(False)
        self.target = target
        self.system = system
        self.parser = M.MAVLink(None)
        self.parser.robust_parsing = True

    @property
    def addr(self):
        return self.sock.getsockname()

    def send(self, data: bytes) -> None:
        self.sock.sendto(data, self.target)

    def beat(self) -> None:
        self.send(_heartbeat(self.system))

    def received(self) -> list:
        out = []
        while True:
            try:
                data = self.sock.recv(65536)
            except BlockingIOError:
                return out
            out += [m for m in (self.parser.parse_buffer(data) or [])
                    if m.get_type() != "BAD_DATA"]

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def udpin():
    link = ml.MavlinkLink("udpin:127.0.0.1:0", Params())
    made: list[Station] = []

    def station(system: int = 255) -> Station:
        s = Station(link.local_address, system)
        made.append(s)
        return s

    yield link, station
    for s in made:
        s.close()
    link.close()


def _queued_bytes(port: int) -> int | None:
    """The receive queue of the UDP socket on ``port`` [bytes] (/proc/net/udp), or None."""
    try:
        with open("/proc/net/udp") as fh:
            lines = fh.readlines()[1:]
    except OSError:
        return None
    for line in lines:
        f = line.split()
        if int(f[1].rsplit(":", 1)[1], 16) == port:
            return int(f[4].split(":")[1], 16)
    return None


def _settle(link) -> None:
    _settle_port(link.local_address[1])


def _settle_port(port: int) -> None:
    """Wait until what was sent to the socket on ``port`` is in its queue: loopback delivers
    it within the send, unless the kernel defers its network work to ksoftirqd on a busy
    machine; the queue's size unchanged over three looks 10 ms apart (a failure limit of
    5 s, not a measurement)."""
    seen, same = None, 0
    deadline = time.monotonic() + 5.0
    while time.monotonic() < deadline and same < 3:
        now = _queued_bytes(port)
        if now is None:
            return
        same = same + 1 if now == seen and now > 0 else 0
        seen = now
        time.sleep(0.01)


def test_a_flood_from_another_port_is_drained_and_the_station_answered_in_one_call(udpin):
    link, station = udpin
    state = ml.VehicleState()
    gs = station()
    gs.beat()
    link.service(state, now_s=100.0)
    assert link.peer_count == 1
    flood = station(250)
    junk = bytes([0xFD, 9, 0, 0, 7, 250, 190, 0, 0, 0]) + bytes(range(11))
    for _ in range(100):
        flood.send(junk)
    mav = _mav()
    gs.send(mav.param_request_read_encode(1, 1, b"A", -1).pack(mav))
    for _ in range(100):
        flood.send(_heartbeat(250))
    _settle(link)
    before = link.stats.datagrams
    link.service(state, now_s=100.01)
    assert link.stats.datagrams - before == 201  # drained in one call (bounded: MAX_DRAIN)
    assert 201 <= ml.MAX_DRAIN
    assert any(m.get_type() == "PARAM_VALUE" for m in gs.received())
    # the flood's source: its first few of the call parsed, the rest dropped unread
    assert link.stats.unknown_dropped >= 200 - ml.NEW_SOURCE_DATAGRAMS_PER_CALL
    assert link.peer_count <= 2


def test_each_service_call_reads_at_most_max_drain_datagrams(udpin):
    link, station = udpin
    state = ml.VehicleState()
    flood = station(250)
    n = ml.MAX_DRAIN + 40
    for _ in range(n):
        flood.send(b"\x00" * 30)
    _settle(link)
    link.service(state, now_s=10.0)
    assert link.stats.datagrams == ml.MAX_DRAIN
    link.service(state, now_s=10.005)
    assert link.stats.datagrams == n


def test_peers_are_kept_while_the_link_is_flooded_and_expire_after(udpin):
    """While service calls find a full batch waiting (the kernel may be dropping datagrams,
    the station's among them), a silent peer is not forgotten; once the flood is over it
    expires after PEER_TIMEOUT_S of silence as usual."""
    link, station = udpin
    state = ml.VehicleState()
    gs = station()
    gs.beat()
    t = 50.0
    link.service(state, now_s=t)
    flood = station(250)
    for _ in range(int(2 * ml.PEER_TIMEOUT_S) + 2):  # 12 s of a flood, 1 s apart
        t += 1.0
        for _ in range(ml.MAX_DRAIN):
            flood.send(b"\x00" * 30)
        _settle(link)
        link.service(state, now_s=t)
        assert link.peer_count == 1 and link.stats.peers_expired == 0, t
    link.service(state, now_s=t + 0.5)  # the flood stopped
    assert link.peer_count == 1
    link.service(state, now_s=t + ml.PEER_TIMEOUT_S + 1.0)
    assert link.peer_count == 0 and link.stats.peers_expired == 1


@linux_only
def test_a_source_flooding_the_link_is_blocked_and_loses_its_slot(udpin):
    """Valid heartbeats from one port, faster than FLOOD_RATE_PER_S: the source (it had
    taken a free slot) is blocked in the kernel and dropped from the slots, said in one
    STATUSTEXT; its next datagrams are never read; the ground station is served."""
    link, station = udpin
    state = ml.VehicleState()
    gs = station()
    gs.beat()
    link.service(state, now_s=20.0)
    flood = station(250)
    n = int(1.5 * ug.FLOOD_RATE_PER_S * ug.WINDOW_S)  # half as fast again as the limit
    t = 20.0
    for k in range(n):
        flood.beat()
        if k % 100 == 99:
            _settle(link)
            link.service(state, now_s=t)
            t += 0.001
    _settle(link)
    link.service(state, now_s=20.0 + 1.01 * ug.WINDOW_S)  # the window's end
    assert link.stats.blocked == 1 and flood.addr in link.guard.blocked
    assert flood.addr not in link.peer_addresses and gs.addr in link.peer_addresses
    texts = [m.text for m in gs.received() if m.get_type() == "STATUSTEXT"]
    assert any("dropped by the kernel" in x for x in texts), texts
    before = link.stats.datagrams
    for _ in range(200):
        flood.beat()
    mav = _mav()
    gs.send(mav.param_request_read_encode(1, 1, b"A", -1).pack(mav))
    _settle(link)
    link.service(state, now_s=20.3)
    assert link.stats.datagrams == before + 1  # the station's request only
    assert any(m.get_type() == "PARAM_VALUE" for m in gs.received())


def test_four_squatters_do_not_lock_out_a_new_ground_station(udpin):
    """Four sockets sending a heartbeat every 2 s hold all MAX_PEERS slots; a ground station
    that then sends its heartbeat every second is told at once that no slot is free, takes
    the slot of the quietest squatter as soon as it has been heard more (within PRESENCE_S),
    the eviction is said (STATUSTEXT to the peers), and it keeps the slot while the squatters
    go on, the evicted one included."""
    link, station = udpin
    state = ml.VehicleState()
    squatters = [station(200 + i) for i in range(ml.MAX_PEERS)]
    t = 10.0

    def second(k: int, gs=None) -> None:
        nonlocal t
        for i, s in enumerate(squatters):
            if (k + i) % 2 == 0:
                s.beat()
        if gs is not None:
            gs.beat()
        link.service(state, now_s=t)
        t += 1.0

    for k in range(10):
        second(k)
    assert link.peer_count == ml.MAX_PEERS
    gs = station()
    joined_after = None
    for k in range(10, 10 + ml.PRESENCE_S):
        second(k, gs)
        if gs.addr in link.peer_addresses:
            joined_after = k - 9
            break
    # a squatter is heard in 2 or 3 of the last 5 intervals: 3 or 4 heartbeats outdo it
    assert joined_after is not None and 3 <= joined_after <= 4, joined_after
    assert link.stats.peers_evicted == 1 and link.peer_count == ml.MAX_PEERS
    first = [m for m in gs.received() if m.get_type() == "STATUSTEXT"]
    if joined_after > 1:  # it waited: told once, at its first heartbeat
        assert "no ground-station slot" in first[0].text
    evicted = [s for s in squatters if s.addr not in link.peer_addresses]
    assert len(evicted) == 1
    texts = [m.text for s in squatters for m in s.received() if m.get_type() == "STATUSTEXT"]
    assert any(str(evicted[0].addr[1]) in x and "slot" in x for x in texts), texts
    for k in range(20, 40):  # the squatters go on (the evicted one too); 20 s
        second(k, gs)
        assert gs.addr in link.peer_addresses, k
    assert sum(m.get_type() == "HEARTBEAT" for m in gs.received()) >= 15


def test_a_new_station_is_told_when_no_slot_can_be_freed(udpin):
    """With every slot held by a peer that has sent more than the newcomer could have (a
    peer is evicted only when it is the quietest and the newcomer is not quieter), the
    newcomer is told in one STATUSTEXT, once per PEER_TIMEOUT_S, and the session notes it."""
    link, station = udpin
    state = ml.VehicleState()
    busy = [station(200 + i) for i in range(ml.MAX_PEERS)]
    t = 5.0
    for _ in range(6):
        for s in busy:
            for _ in range(5):
                s.beat()
        link.service(state, now_s=t)
        t += 0.2
    gs = station()
    for _ in range(3):
        gs.beat()
        link.service(state, now_s=t)
        t += 0.1
    texts = [m.text for m in gs.received() if m.get_type() == "STATUSTEXT"]
    assert len(texts) == 1 and "no ground-station slot" in texts[0]
    assert gs.addr not in link.peer_addresses and link.stats.peers_refused >= 1


# --------------------------------------------------------------- a requested end of a flight
def test_ardupilot_session_ends_normally_when_its_arduplane_goes_silent(tmp_path):
    """``--end-when-silent S``: the session ends by itself once the bound ArduPilot has sent
    nothing for S s (the fly script stops ArduPlane, then waits for the physics): exit 0,
    the summary's ``ended`` says why and ``interrupted`` is false."""
    from tests.test_ardupilot_driver import _cli_session, _free_port

    summary = tmp_path / "s.json"
    rc, _ = _cli_session(["--end-when-silent", "1", "--no-log", "--json", "--summary",
                          str(summary)], _free_port())
    assert rc == 0
    s = json.loads(summary.read_text())
    assert s["interrupted"] is False and s["ended"] == "ArduPilot silent"
    assert s["frames"]["steps"] >= 700


def test_the_fly_script_stops_arduplane_first_and_lets_the_physics_end_by_itself():
    """scripts/ardupilot_sitl.py ``fly`` used to SIGTERM the physics (every flight's summary
    read ``interrupted: true``, exit 130); now ArduPlane is stopped first and the physics,
    started with --end-when-silent, ends by itself. Played with stand-in processes: a
    "physics" that ends once its "ArduPlane" is gone, and one that never ends."""
    import importlib.util
    import subprocess
    import sys
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "scripts" / "ardupilot_sitl.py"
    spec = importlib.util.spec_from_file_location("ardupilot_sitl_script_end", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    assert f"--end-when-silent {script.PHYSICS_END_SILENCE_S:g}" in script.DEFAULT_PHYSICS_CMD
    arduplane = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    # the physics: waits until the "ArduPlane" process is gone, then exits 0 by itself
    follower = subprocess.Popen([sys.executable, "-c", (
        "import os, sys, time\n"
        f"while os.path.exists('/proc/{arduplane.pid}') and "
        f"open('/proc/{arduplane.pid}/stat').read().split(')')[1].split()[0] != 'Z':\n"
        "    time.sleep(0.05)\n"
        "sys.exit(0)\n")])
    try:
        end = script.end_processes([follower, arduplane], physics_wait_s=30.0)
    finally:
        for p in (follower, arduplane):
            if p.poll() is None:
                p.kill()
    assert end == {"by": "itself", "status": 0}
    assert arduplane.returncode is not None
    stuck = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(600)"])
    try:
        end = script.end_processes([stuck], physics_wait_s=0.2)
    finally:
        if stuck.poll() is None:
            stuck.kill()
    assert end["by"] == "SIGTERM" and end["status"] != 0


def test_the_help_states_the_silence_the_server_uses():
    from bioflex_jsb.cli.sitl_ardupilot import HELP

    text = " ".join(HELP.split())
    assert f"silent for {aj.PEER_SILENCE_S:g} s" in text and "--end-when-silent" in text
