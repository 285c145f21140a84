"""SITL: the paced co-simulation as a MAVLink vehicle, checked with a pymavlink client on
loopback (every socket on 127.0.0.1)."""

from __future__ import annotations

import math
import select
import socket
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("pymavlink")
from pymavlink import mavutil  # noqa: E402  (the test's own ground station)
from pymavlink.dialects.v20 import common as M  # noqa: E402

import bioflex_jsb.cli as cli  # noqa: E402
from bioflex_jsb.drivers.sitl import SitlParameters, SitlSim, run_paced  # noqa: E402
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing  # noqa: E402
from bioflex_jsb.generators import autopilot as autopilot_xml  # noqa: E402
from bioflex_jsb.links.mavlink import LinkError, MavlinkLink, parse_endpoint  # noqa: E402
from tests.polling import wait_until  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PACING_TARGET_MS = 2.0  # issue 6: p99 of the step start against the wall clock


@pytest.fixture(scope="module")
def build():
    return build_wing(VARIANTS["optimised"])


def make_sim(build, **kw) -> SitlSim:
    return SitlSim(build.model, build.modes, **kw)


def run_cli(argv, monkeypatch):
    if "sitl" not in cli.COMMAND_MODULES:
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli.COMMAND_MODULES + ("sitl",))
    return cli.main(argv)


class Session:
    """The vehicle flying in a background thread, serviced on udpin (or tcpin) loopback."""

    def __init__(self, sim: SitlSim, kind: str = "udpin", link: MavlinkLink | None = None):
        self.sim = sim
        self.link = link or MavlinkLink(f"{kind}:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
        self.port = self.link.local_address[1]
        self._stop = threading.Event()
        self.stats = None
        self.error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        try:
            self.stats = run_paced(self.sim, None, self.link, should_stop=self._stop.is_set)
        except BaseException as exc:  # noqa: BLE001 - reported by the test
            self.error = exc

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(5.0)
        self.link.close()
        assert not self._thread.is_alive()
        if self.error is not None:
            raise self.error


def client(port: int, kind: str = "udpout"):
    c = mavutil.mavlink_connection(f"{kind}:127.0.0.1:{port}", source_system=255,
                                   source_component=190, dialect="common")
    c.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
    return c


# A live session's deadline [s]: a message the vehicle sends every 0.1-1 s is here within it
# on any machine; it only bounds how long a failing test waits (a fast one never waits it).
LIVE_DEADLINE_S = 30.0


def wait_for(c, kind, timeout=LIVE_DEADLINE_S, cond=lambda m: True, poke=None):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if poke is not None:
            poke()
        m = c.recv_match(type=kind, blocking=True, timeout=0.2)
        if m is not None and cond(m):
            return m
    raise AssertionError(f"no {kind} within {timeout} s")


# ---------------------------------------------------------------------------- endpoints


def test_endpoints_default_to_loopback_and_bad_ones_are_one_line():
    assert parse_endpoint("udpin:14550").host == "127.0.0.1"
    assert parse_endpoint("udpout::14550").host == "127.0.0.1"
    assert parse_endpoint("tcpin:localhost:5760").host == "127.0.0.1"
    for bad in ("udp:1.2.3.4:1", "udpout:300.1.1.1:14550", "udpin:127.0.0.1:x",
                "tcpin:127.0.0.1:70000", "udpout:0.0.0.0:14550", "udpout:127.0.0.1:0",
                "udpin:example.com:14550", "nonsense"):
        with pytest.raises(LinkError) as err:
            parse_endpoint(bad)
        assert "\n" not in str(err.value)


@pytest.mark.parametrize("address", ["udpout:300.1.1.1:14550", "bogus", "tcpin:127.0.0.1:-1",
                                     "udpin:192.0.2.1:14550"])
def test_cli_bad_mavlink_address_exit_2_one_line(address, monkeypatch, capsys):
    # 192.0.2.1 (TEST-NET-1) is not an address of this machine: the bind fails, nothing is sent
    assert run_cli(["sitl", "--mavlink", address, "--duration", "1"], monkeypatch) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "sitl: error:" in err, err


def test_cli_port_in_use_exit_2(monkeypatch, capsys):
    busy = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    busy.bind(("127.0.0.1", 0))
    try:
        port = busy.getsockname()[1]
        assert run_cli(["sitl", "--mavlink", f"udpin:127.0.0.1:{port}"], monkeypatch) == 2
        assert "cannot listen on" in capsys.readouterr().err
    finally:
        busy.close()


# ---------------------------------------------------------------------------- autopilot


def test_generated_autopilot_files_are_in_step():
    for rel, text in autopilot_xml.render_all().items():
        assert (ROOT / rel).read_text(encoding="utf-8") == text, (
            f"{rel} is stale: run python -m bioflex_jsb.generators.autopilot")


def test_autopilot_holds_altitude_and_turns_to_a_heading(build):
    sim = make_sim(build)
    params = SitlParameters(sim)
    h0 = sim.h0_m
    sim.set_wing_model("coupled")
    params.set("AP_HDG_RAD", math.radians(90.0))
    with sim.airframe.capturing():
        for _ in range(int(25.0 / sim.dt_s)):  # unpaced: as fast as it goes
            sim.step()
            assert sim.stopped is None
    s = sim.vehicle_state()
    assert abs(math.remainder(s.yaw_rad - math.radians(90.0), 2 * math.pi)) < math.radians(3)
    assert abs(s.roll_rad) < math.radians(3)
    assert abs(s.altitude_m - h0) < 3.0
    # disengaged: the controls go back to the trim (no autopilot increments)
    params.set("AP_ENABLE", 0.0)
    with sim.airframe.capturing():
        sim.step()
        sim.step()
    assert sim.airframe["fcs/elevator-cmd-norm"] == 0.0
    assert sim.airframe["fcs/roll-trim-cmd-norm"] == 0.0


# ---------------------------------------------------------------------------- live link


def test_live_session_handshakes_telemetry_parameters(build):
    sim = make_sim(build)
    with Session(sim) as session:
        c = client(session.port)
        hb = wait_for(c, "HEARTBEAT", poke=lambda: c.mav.heartbeat_send(6, 8, 0, 0, 0),
                      cond=lambda m: m.get_srcSystem() == 1)
        assert (hb.get_srcSystem(), hb.get_srcComponent()) == (1, 1)
        assert hb.type == M.MAV_TYPE_FIXED_WING and hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA
        assert hb.custom_mode == 7 and hb.base_mode & M.MAV_MODE_FLAG_SAFETY_ARMED  # CRUISE
        assert hb.system_status == M.MAV_STATE_ACTIVE
        assert hb.get_msgbuf()[0] == 0xFD  # MAVLink 2 framing

        # time_boot_ms is the simulated time: an ATTITUDE sent after t0 is stamped between
        # t0 and the vehicle's time once it is here (bounds by order, not by wall time)
        t0_s = sim.t_s
        att = wait_for(c, "ATTITUDE", cond=lambda m: m.time_boot_ms / 1e3 >= t0_s - 1e-3)
        assert att.time_boot_ms / 1e3 <= sim.t_s + 1e-3
        assert abs(att.pitch - sim.trim.theta_rad) < 0.05 and abs(att.roll) < 0.05
        pos = wait_for(c, "GLOBAL_POSITION_INT")
        assert abs(pos.lat / 1e7 + 35.363261) < 0.01 and abs(pos.vx / 100.0 - 15.0) < 0.5
        assert abs(pos.relative_alt / 1e3 - 100.0) < 3.0  # 100 m above the CMAC field
        gps = wait_for(c, "GPS_RAW_INT")
        assert gps.fix_type == M.GPS_FIX_TYPE_3D_FIX
        hud = wait_for(c, "VFR_HUD")
        assert abs(hud.airspeed - 15.0) < 0.5
        wait_for(c, "SYS_STATUS")
        names = set()
        for _ in range(8):
            names.add(wait_for(c, "NAMED_VALUE_FLOAT").name)
        assert {"eta1", "eta2", "eta3", "tip_twist"} <= names

        # parameters: the full list, then a set that changes the run
        c.mav.param_request_list_send(1, 1)
        got = {}

        def whole_list() -> bool:
            m = c.recv_match(type="PARAM_VALUE", blocking=True, timeout=0.2)
            if m is not None:
                got[m.param_id] = (m.param_value, m.param_count)
            return bool(got) and len(got) >= next(iter(got.values()))[1]

        wait_until(whole_list, LIVE_DEADLINE_S, "the whole parameter list")
        assert set(got) == set(SitlParameters.names)
        assert got["WING_COUPLED"][0] == 1.0 and got["SIM_SPEEDUP"][0] == 1.0

        c.mav.param_set_send(1, 1, b"WING_COUPLED", 0.0, M.MAV_PARAM_TYPE_REAL32)
        pv = wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "WING_COUPLED")
        assert pv.param_value == 0.0 and sim.wing.model == "rigid"
        c.mav.param_set_send(1, 1, b"WING_COUPLED", 7.0, M.MAV_PARAM_TYPE_REAL32)  # rejected
        pv = wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "WING_COUPLED")
        assert pv.param_value == 0.0
        c.mav.param_set_send(1, 1, b"WING_COUPLED", 1.0, M.MAV_PARAM_TYPE_REAL32)
        wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "WING_COUPLED")
        assert sim.wing.model == "coupled"
        c.mav.param_set_send(1, 1, b"GUST_AMP_MS", 2.0, M.MAV_PARAM_TYPE_REAL32)
        wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "GUST_AMP_MS")
        c.mav.param_set_send(1, 1, b"GUST_TRIG", 1.0, M.MAV_PARAM_TYPE_REAL32)
        pv = wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "GUST_TRIG")
        assert pv.param_value == 1.0
        # the gust reaches the wing: the first mode answers (it is ~0 in still air)
        eta = wait_for(c, "NAMED_VALUE_FLOAT", cond=lambda m: m.name == "eta1"
                       and abs(m.value) > 1e-4)
        assert math.isfinite(eta.value)
        c.mav.param_request_read_send(1, 1, b"GUST_AMP_MS", -1)
        pv = wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "GUST_AMP_MS")
        assert pv.param_value == pytest.approx(2.0)

        # mission: only home (ArduPilot's item 0); no fence
        for mission_type, n in ((M.MAV_MISSION_TYPE_MISSION, 1), (M.MAV_MISSION_TYPE_FENCE, 0)):
            c.mav.mission_request_list_send(1, 1, mission_type)
            mc = wait_for(c, "MISSION_COUNT", cond=lambda m, t=mission_type: m.mission_type == t)
            assert mc.count == n and mc.target_system == 255

        # commands: unknown → UNSUPPORTED; AUTOPILOT_VERSION on request
        c.mav.command_long_send(1, 1, M.MAV_CMD_DO_SET_SERVO, 0, 1, 1500, 0, 0, 0, 0, 0)
        ack = wait_for(c, "COMMAND_ACK", cond=lambda m: m.command == M.MAV_CMD_DO_SET_SERVO)
        assert ack.result == M.MAV_RESULT_UNSUPPORTED
        c.mav.command_int_send(1, 1, 0, M.MAV_CMD_DO_REPOSITION, 0, 0, 0, 0, 0, 0, 0, 0, 0)
        ack = wait_for(c, "COMMAND_ACK", cond=lambda m: m.command == M.MAV_CMD_DO_REPOSITION)
        assert ack.result == M.MAV_RESULT_DENIED  # no position given
        c.mav.command_long_send(1, 1, M.MAV_CMD_REQUEST_MESSAGE, 0,
                                M.MAVLINK_MSG_ID_AUTOPILOT_VERSION, 0, 0, 0, 0, 0, 0)
        ack = wait_for(c, "COMMAND_ACK", cond=lambda m: m.command == M.MAV_CMD_REQUEST_MESSAGE)
        assert ack.result == M.MAV_RESULT_ACCEPTED
        av = wait_for(c, "AUTOPILOT_VERSION")
        assert av.capabilities & M.MAV_PROTOCOL_CAPABILITY_MAVLINK2

        # timesync (the vehicle's clock is the simulated time, as time_boot_ms) and ping
        t0_s = sim.t_s
        c.mav.timesync_send(0, 123456789)
        ts = wait_for(c, "TIMESYNC", cond=lambda m: m.ts1 == 123456789)
        assert t0_s - 1e-3 <= ts.tc1 * 1e-9 <= sim.t_s + 1e-3  # answered in between
        c.mav.ping_send(42, 7, 0, 0)
        ping = wait_for(c, "PING", cond=lambda m: m.seq == 7)
        assert ping.time_usec == 42 and ping.target_system == 255

        # MAVLink FTP: no file server, so a NAK (UnknownCommand) to the request's sequence + 1
        open_ro = struct.pack("<HBBBBBBI", 10, 3, 4, 13, 0, 0, 0, 0) + b"@PARAM/param.pck"
        c.mav.file_transfer_protocol_send(0, 1, 1, list(open_ro.ljust(251, b"\0")))
        ftp = wait_for(c, "FILE_TRANSFER_PROTOCOL")
        seq, session_id, opcode, size, req_opcode = struct.unpack("<HBBBB", bytes(ftp.payload[:6]))
        assert (seq, session_id, opcode, size, req_opcode) == (11, 3, 129, 1, 4)
        assert ftp.payload[12] == 7 and ftp.target_system == 255

        # message rates: ATTITUDE to 5 Hz by interval, VFR_HUD off by data stream
        c.mav.command_long_send(1, 1, M.MAV_CMD_SET_MESSAGE_INTERVAL, 0,
                                M.MAVLINK_MSG_ID_ATTITUDE, 200000, 0, 0, 0, 0, 0)
        ack = wait_for(c, "COMMAND_ACK",
                       cond=lambda m: m.command == M.MAV_CMD_SET_MESSAGE_INTERVAL)
        assert ack.result == M.MAV_RESULT_ACCEPTED
        c.mav.request_data_stream_send(1, 1, M.MAV_DATA_STREAM_EXTRA2, 0, 0)
        # a marker after it: the vehicle handles a peer's messages in order, so once the
        # marker's answer is here the stream is off; what came before it is read past
        c.mav.param_request_read_send(1, 1, b"SIM_SPEEDUP", -1)
        wait_for(c, "PARAM_VALUE", cond=lambda m: m.param_id == "SIM_SPEEDUP")
        assert session.link.intervals_s[M.MAVLINK_MSG_ID_ATTITUDE] == pytest.approx(0.2)
        assert session.link.intervals_s[M.MAVLINK_MSG_ID_VFR_HUD] == 0.0
        # what arrives while four ATTITUDEs come: no VFR_HUD (their wall-time spacing is
        # the scheduler's, tested with a given clock in test_message_intervals_...)
        counts = {"ATTITUDE": 0, "VFR_HUD": 0}

        def four_attitudes() -> bool:
            m = c.recv_match(type=list(counts), blocking=True, timeout=0.2)
            if m is not None:
                counts[m.get_type()] += 1
            return counts["ATTITUDE"] >= 4

        wait_until(four_attitudes, LIVE_DEADLINE_S, "four ATTITUDE messages")
        assert counts["VFR_HUD"] == 0
        c.close()
    assert session.error is None


def test_message_intervals_are_kept_on_the_links_clock(build, monkeypatch):
    """The streams' rates on a given clock (the live session's test reads them from the link:
    on a loaded machine its wall-time spacing is the scheduler's, not the rate's)."""
    sim = make_sim(build)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
    sent: list[int] = []
    monkeypatch.setattr(link, "_send_message", lambda mid, s: sent.append(mid))
    try:
        link.set_rate(M.MAVLINK_MSG_ID_ATTITUDE, 5.0)
        link.set_rate(M.MAVLINK_MSG_ID_VFR_HUD, 0.0)
        state = sim.vehicle_state()
        for i in range(400):  # 2 s at the link's 200 Hz service
            link.service(state, now_s=100.0 + i * 0.005)
    finally:
        link.close()
    assert sent.count(M.MAVLINK_MSG_ID_ATTITUDE) == 10  # at 0, 0.2, .., 1.8 s
    assert sent.count(M.MAVLINK_MSG_ID_VFR_HUD) == 0
    assert sent.count(M.MAVLINK_MSG_ID_HEARTBEAT) == 2  # 1 Hz, left as it was


def test_tcpin_client_sees_the_vehicle(build):
    sim = make_sim(build)
    with Session(sim, kind="tcpin") as session:
        c = client(session.port, kind="tcp")
        hb = wait_for(c, "HEARTBEAT", cond=lambda m: m.get_srcSystem() == 1)
        assert hb.type == M.MAV_TYPE_FIXED_WING
        c.mav.param_request_read_send(1, 1, b"SIM_SPEEDUP", -1)
        assert wait_for(c, "PARAM_VALUE").param_value == 1.0
        c.close()


FLOOD = """
import os, socket, sys, time
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
end = time.monotonic() + float(sys.argv[2])
n = 0
on = False
while time.monotonic() < end:
    for size in (1, 17, 280, 1400, 8000):
        try:
            s.sendto(os.urandom(size), ("127.0.0.1", int(sys.argv[1])))
            n += 1
        except OSError:
            pass
    s.sendto(bytes([0xFD, 9, 0, 0, 0, 1, 1, 0, 0, 0]) + os.urandom(5), ("127.0.0.1",
             int(sys.argv[1])))  # truncated MAVLink 2 headers
    if not on:
        on = True
        print("on", flush=True)  # the first datagrams are in the link's socket
print(n)
"""


def test_flood_of_random_bytes_does_not_stop_the_loop_or_the_link(build):
    sim = make_sim(build)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
    port = link.local_address[1]
    duration = 3.0
    flood = subprocess.Popen([sys.executable, "-c", FLOOD, str(port), str(duration + 0.5)],
                             stdout=subprocess.PIPE, text=True)
    try:
        # the flood is on before the loop starts: its first datagrams were sent
        wait_until(lambda: select.select([flood.stdout], [], [], 0.0)[0], 10.0,
                   "the flood's start")
        assert flood.stdout.readline() == "on\n"
        t0 = time.monotonic()
        stats = run_paced(sim, duration, link)
        wall = time.monotonic() - t0
    finally:
        sent = int((flood.communicate(timeout=10)[0] or "0").split()[-1])
    assert sent > 1000, "the flood did not run"
    # Random bytes can hold a valid frame by chance: a MAVLink frame is checked by a 16-bit
    # CRC (with the message's CRC_EXTRA), so about one candidate start byte in 65 536 passes
    # (CI once saw 1 VISION_POSITION_ESTIMATE in 7.8 MB); none may be more than chance.
    assert link.stats.datagrams > 100
    assert link.stats.received <= 5, link.stats
    assert sim.t_s == pytest.approx(duration, abs=sim.dt_s)
    # Function, not timing: the flood neither stops the loop nor makes it fall behind for
    # good (it flies the whole duration, every step has a pacing record). How fast it keeps
    # pace is a benchmark figure (`bioflex-jsb bench`: sitl_p50_ms, sitl_p99_ms): on a shared
    # 2-core machine, with the flood busy-looping on one core, wall times and percentiles
    # measure the machine's load, not the loop.
    assert stats.steps == sim.k and wall > 0.0
    # and the link still talks to a real ground station afterwards
    with Session(sim, link=link):
        c = client(port)
        wait_for(c, "HEARTBEAT", poke=lambda: c.mav.heartbeat_send(6, 8, 0, 0, 0),
                 cond=lambda m: m.get_srcSystem() == 1)
        c.close()


def test_cli_sitl_runs_and_logs(tmp_path, monkeypatch, capsys):
    listener = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the "ground station"
    listener.bind(("127.0.0.1", 0))
    listener.setblocking(False)
    port = listener.getsockname()[1]
    out = tmp_path / "sitl.mcap"
    try:
        rc = run_cli(["sitl", "--duration", "1.5", "--speedup", "2", "--out", str(out),
                      "--mavlink", f"udpout:127.0.0.1:{port}", "--json"], monkeypatch)
        data = listener.recv(65535)
    finally:
        listener.close()
    assert rc == 0
    assert data[0] == 0xFD  # MAVLink 2
    import json

    summary = json.loads(capsys.readouterr().out)
    assert summary["simulated_s"] == pytest.approx(1.5, abs=0.01)
    from bioflex_jsb.sinks.mcap import summarise

    info = summarise(out)
    assert info is not None and out.stat().st_size > 10000


def test_measure_pacing_for_bench():
    from bioflex_jsb.drivers.sitl import measure_pacing

    r = measure_pacing(0.5)
    assert r["steps"] == 480 and r["resyncs"] == 0
    # shape of the result only: the 2 ms target is judged by `bioflex-jsb bench`, not here
    assert 0.0 <= r["p50_ms"] <= r["p99_ms"] <= r["max_ms"]


# ------------------------------------------------------------------ --aero, pre-flight check
def _udp_sink():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    return s


def test_cli_sitl_refuses_a_wing_its_strips_cannot_fly(monkeypatch, capsys):
    """--wing inertial-backward: quasi-steady flutter at 14.9 m/s, below the 15 m/s trim;
    refused in one line by the ardupilot command's pre-flight check, which names the way
    out (the unsteady strips, stable to 18.9 m/s)."""
    assert run_cli(["sitl", "--wing", "inertial-backward", "--duration", "0.1", "--no-log"],
                   monkeypatch) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    for word in ("aeroelastic_1", "14.9 m/s", "--aero unsteady", "18.9 m/s",
                 "--allow-unstable"):
        assert word in err, err


def test_cli_sitl_flies_it_with_unsteady_strips(monkeypatch, capsys):
    sink = _udp_sink()
    try:
        rc = run_cli(["sitl", "--wing", "inertial-backward", "--aero", "unsteady",
                      "--duration", "0.5", "--speedup", "5", "--no-log", "--json",
                      "--mavlink", f"udpout:127.0.0.1:{sink.getsockname()[1]}"], monkeypatch)
    finally:
        sink.close()
    assert rc == 0
    import json

    s = json.loads(capsys.readouterr().out)
    assert s["aero"] == "unsteady" and s["preflight"]["stable"]
    assert s["preflight"]["aero"] == "unsteady" and s["preflight"]["max_growth_1_s"] < 0.0
    assert s["resets"] == 0 and s["steps"] == 480


def test_cli_sitl_allow_unstable_warns(monkeypatch, capsys):
    sink = _udp_sink()
    try:
        rc = run_cli(["sitl", "--wing", "inertial-backward", "--allow-unstable",
                      "--duration", "0.1", "--speedup", "5", "--no-log", "--json",
                      "--mavlink", f"udpout:127.0.0.1:{sink.getsockname()[1]}"], monkeypatch)
    finally:
        sink.close()
    assert rc == 0
    cap = capsys.readouterr()
    assert "warning: flying a model unstable at the trim speed" in cap.err
    import json

    s = json.loads(cap.out)
    assert not s["preflight"]["stable"] and s["preflight"]["allowed_unstable"]


@pytest.mark.parametrize("argv", [["--model", "rigid"], ["--trim", "elastic"]])
def test_cli_sitl_unsteady_combinations_refused_in_one_line(argv, monkeypatch, capsys):
    assert run_cli(["sitl", "--aero", "unsteady", *argv, "--duration", "0.1", "--no-log"],
                   monkeypatch) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--aero unsteady is for --model coupled" in err


def test_unsteady_sitl_wing_flies_and_cannot_be_switched():
    b = build_wing(VARIANTS["inertial-backward"])
    sim = SitlSim(b, b.modes, aero="unsteady", speedup=10.0)
    assert sim.core.aero == "unsteady" and sim.core.compiled
    params = SitlParameters(sim)
    with pytest.raises(ValueError, match="cannot be switched"):
        params.set("WING_COUPLED", 0.0)
    assert params.get("WING_COUPLED") == 1.0
    for _ in range(240):
        sim.step()
    assert sim.resets == 0 and abs(float(sim.core.eta[0])) > 0.0


def test_the_paced_loop_keeps_the_start_ups_objects_out_of_the_collector_while_it_runs():
    """A full collection in flight would scan every object alive at the start (a 25-80 ms
    stall, drivers/sitl.py run_paced): they are frozen while the loop runs and thawed after
    it, unless the caller had frozen some itself."""
    import contextlib
    import gc
    from types import SimpleNamespace

    seen = []

    class Fake:
        dt_s, k, speedup, resync, t_s = 1e-3, 0, 1000.0, False, 0.0
        wing = SimpleNamespace(model="coupled")
        airframe = SimpleNamespace(capturing=contextlib.nullcontext)

        def step(self):
            seen.append(gc.get_freeze_count())
            self.k += 1
            return ()

    gc.unfreeze()  # as a session starts (an in-process `ardupilot` test may have frozen)
    run_paced(Fake(), 0.005)
    assert len(seen) == 5 and min(seen) > 1000  # the test process's objects, frozen
    assert gc.get_freeze_count() == 0  # and given back
    seen.clear()
    gc.freeze()  # a caller's own freeze (bioflex-jsb ardupilot's) stands after the loop
    try:
        before = gc.get_freeze_count()
        run_paced(Fake(), 0.003)
        # not thawed (the count only falls by the frozen objects freed meanwhile: 11 of
        # 304 465 seen in a full suite run; thawing would take it to 0)
        assert min(seen) > before // 2 and gc.get_freeze_count() > before // 2
    finally:
        gc.unfreeze()
