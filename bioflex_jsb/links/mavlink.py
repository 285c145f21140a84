"""MAVLink 2 link of the SITL aircraft: telemetry out, ground-station handshakes in.

This is the only module that imports :mod:`pymavlink` (its generated MAVLink 2 ``common``
codec; the sockets are ours). The vehicle is system 1, component 1 (the autopilot).

Endpoints (``parse_endpoint``):

* ``udpout:HOST:PORT``: send to a ground station listening there (QGroundControl's
  ``udp 14550``); its replies come back to our (ephemeral) port;
* ``udpin:HOST:PORT``: listen; send to the peers that sent us valid MAVLink (up to
  :data:`MAX_PEERS`);
* ``tcpin:HOST:PORT``: listen for up to :data:`MAX_PEERS` TCP clients.

HOST is an IPv4 address or ``localhost``; omitted (``udpin:14550``, ``udpout::14550``) it is
127.0.0.1: the link binds and sends to loopback only unless another address is given
explicitly.

Safety of the loop: every socket is non-blocking; :meth:`MavlinkLink.service` reads at most
:data:`MAX_DATAGRAMS` datagrams and parses at most :data:`MAX_PARSE_BYTES` bytes per call
(a flood is dropped by the kernel, not queued in the simulation); malformed or truncated
input is skipped by the parser (robust parsing, CRC checked); a peer that is absent or gone
never blocks (sends that would block are dropped; a TCP client whose backlog exceeds
:data:`MAX_TCP_BACKLOG` is disconnected).

Units: :class:`VehicleState` is SI (rad, m, m/s); conversion to MAVLink's integer units
(degE7, mm, cm/s, cdeg) happens here only.

Time base: the vehicle's clock is the *simulated* time t [s] since the start of the run, not
the wall clock: ``time_boot_ms`` = ⌊1000 t⌋ (ATTITUDE, GLOBAL_POSITION_INT,
NAMED_VALUE_FLOAT), GPS_RAW_INT ``time_usec`` = ⌊10⁶ t⌋, and TIMESYNC answers with t in ns.
A message carries the state at exactly that t (after the step that ended at t), so a
message with ``time_boot_ms`` = m matches the MCAP log's step at a time in [m, m + 1) ms:
its attitude and airspeed exactly; the log's position, heading and body rates p, r of a
step are read at the end of that step (as in ``cosim.run_gust``), so those match the
step one time step (1/960 s) earlier. With ``--speedup N`` this clock runs N times faster
than the wall clock.

Signing (``signing_key``, :func:`read_signing_key`): MAVLink 2 message signing with one
32-byte secret. Everything sent is signed (link id 0, timestamps from the wall clock in
10 µs since 2015-01-01 UTC, as the MAVLink signing spec asks); a received message is
accepted only with a valid signature whose timestamp is newer than the last one of its
stream (link id, system, component) and not more than 60 s older than the link's own
time (replay protection, shared by all peers of the link). Unsigned or wrongly signed
messages are dropped (counted in ``LinkStats.rejected_signature``) except RADIO_STATUS,
which radios send unsigned. A peer whose messages are all rejected is never added
(``udpin``), so it gets no telemetry either.
"""

from __future__ import annotations

import errno
import hashlib
import hmac
import math
import socket
import struct
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass, field

from pymavlink.dialects.v20 import common as mavlink

from bioflex_jsb.links.mavlink_setup import (  # noqa: F401  (the link's set-up and state)
    SIGNING_EPOCH_UNIX_S,
    SIGNING_KEY_BYTES,
    Endpoint,
    LinkError,
    Parameters,
    VehicleState,
    parse_endpoint,
    read_signing_key,
    signing_time_10us,
)

# What pymavlink's parser raises on bytes that are not MAVLink (hostile or corrupt input):
# its own MAVError, and the struct/array/decoding errors of a truncated or mangled payload.
_CODEC_ERRORS = (mavlink.MAVError, struct.error, ValueError, IndexError, KeyError, TypeError,
                 UnicodeDecodeError, OverflowError)

SYSTEM_ID = 1
COMPONENT_ID = 1
MAX_PEERS = 4
MAX_DATAGRAMS = 16  # datagrams read per service call
MAX_PARSE_BYTES = 4096  # bytes handed to the parser per service call
MAX_TCP_BACKLOG = 256 * 1024  # unsent bytes to one TCP client before it is dropped
PARAMS_PER_SERVICE = 8  # PARAM_VALUE messages of a list request sent per service call

M = mavlink
# Default rates [Hz] of the streamed messages.
DEFAULT_RATES_HZ = {
    M.MAVLINK_MSG_ID_HEARTBEAT: 1.0,
    M.MAVLINK_MSG_ID_SYS_STATUS: 1.0,
    M.MAVLINK_MSG_ID_ATTITUDE: 50.0,
    M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: 10.0,
    M.MAVLINK_MSG_ID_GPS_RAW_INT: 5.0,
    M.MAVLINK_MSG_ID_VFR_HUD: 10.0,
    M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT: 10.0,
}
# REQUEST_DATA_STREAM (deprecated, still sent by MAVProxy and QGC for ArduPilot): stream ids
# → the messages they rate.
_STREAMS = {
    M.MAV_DATA_STREAM_RAW_SENSORS: (M.MAVLINK_MSG_ID_GPS_RAW_INT,),
    M.MAV_DATA_STREAM_EXTENDED_STATUS: (M.MAVLINK_MSG_ID_SYS_STATUS,),
    M.MAV_DATA_STREAM_POSITION: (M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,),
    M.MAV_DATA_STREAM_EXTRA1: (M.MAVLINK_MSG_ID_ATTITUDE,),
    M.MAV_DATA_STREAM_EXTRA2: (M.MAVLINK_MSG_ID_VFR_HUD,),
    M.MAV_DATA_STREAM_EXTRA3: (M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT,),
}
_STREAMS[M.MAV_DATA_STREAM_ALL] = tuple(m for ids in _STREAMS.values() for m in ids)
MAX_RATE_HZ = 200.0
SIGNING_STREAM_AGE_10US = 60 * 100_000  # a new stream may be this much older (60 s)
UNSIGNED_ALLOWED = frozenset({M.MAVLINK_MSG_ID_RADIO_STATUS})  # radios cannot sign
# MAVLink FTP (FILE_TRANSFER_PROTOCOL payload header): opcodes and error codes used here
FTP_OP_TERMINATE_SESSION = 1
FTP_OP_RESET_SESSIONS = 2
FTP_OP_ACK = 128
FTP_OP_NAK = 129
FTP_ERR_UNKNOWN_COMMAND = 7
CAPABILITIES = (M.MAV_PROTOCOL_CAPABILITY_MAVLINK2 | M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                | M.MAV_PROTOCOL_CAPABILITY_MISSION_INT | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT)


class _Parser(mavlink.MAVLink):
    """pymavlink's MAVLink 2 parser with a stricter signature check: the stream's timestamp
    is recorded only once the signature is right (pymavlink records it first, so a forged
    packet with a far-future timestamp would lock the real sender's stream out)."""

    def check_signature(self, msgbuf, srcSystem: int, srcComponent: int) -> bool:
        sig = self.signing
        expected = hashlib.sha256(sig.secret_key + bytes(msgbuf[:-6])).digest()[:6]
        if not hmac.compare_digest(expected, bytes(msgbuf[-6:])):
            return False
        link_id = msgbuf[-13]
        stamp = int.from_bytes(bytes(msgbuf[-12:-6]), "little")
        stream = (link_id, srcSystem, srcComponent)
        last = sig.stream_timestamps.get(stream)
        if last is not None:
            if stamp <= last:
                return False  # replayed or reordered
        elif stamp + SIGNING_STREAM_AGE_10US < sig.timestamp:
            return False  # a new stream, but too old
        sig.stream_timestamps[stream] = stamp
        sig.timestamp = max(sig.timestamp, stamp)
        return True


@dataclass
class LinkStats:
    received: int = 0  # valid MAVLink messages
    bad: int = 0  # bad-CRC / unparseable chunks
    datagrams: int = 0
    bytes_dropped: int = 0  # read but not parsed (over the per-call budget)
    rejected_signature: int = 0  # unsigned, wrongly signed or replayed (signing on)
    sent: int = 0
    send_dropped: int = 0
    by_type: dict[str, int] = field(default_factory=dict)


class _Peer:
    """One conversation: its own parser (stream state), and for TCP its socket."""

    def __init__(self, addr, parser: mavlink.MAVLink, sock: socket.socket | None = None) -> None:
        self.addr = addr
        self.sock = sock
        self.parser = parser
        self.backlog = bytearray()
        self.last_seen = time.monotonic()


class MavlinkLink:
    """The vehicle's MAVLink link (module docstring). Call :meth:`service` from the loop."""

    def __init__(self, endpoint: Endpoint | str, params: Parameters,
                 on_manual: Callable[[float | None, float | None], None] | None = None,
                 signing_key: bytes | None = None) -> None:
        self.endpoint = parse_endpoint(endpoint) if isinstance(endpoint, str) else endpoint
        self.params = params
        self.on_manual = on_manual  # (pitch, roll) in -1..1; (None, None): released
        self.stats = LinkStats()
        self._mav = mavlink.MAVLink(None, srcSystem=SYSTEM_ID, srcComponent=COMPONENT_ID)
        self._rx_signing: mavlink.MAVLinkSigning | None = None
        if signing_key is not None:
            if len(signing_key) != SIGNING_KEY_BYTES:
                raise LinkError(f"a MAVLink signing key has {SIGNING_KEY_BYTES} bytes, "
                                f"not {len(signing_key)}")
            key = bytes(signing_key)
            tx = self._mav.signing
            tx.secret_key, tx.sign_outgoing, tx.link_id = key, True, 0
            tx.timestamp = signing_time_10us()
            rx = self._rx_signing = mavlink.MAVLinkSigning()  # shared by every peer's parser
            rx.secret_key, rx.timestamp = key, tx.timestamp
            rx.allow_unsigned_callback = lambda _mav, msg_id: msg_id in UNSIGNED_ALLOWED
        self.intervals_s = {mid: 1.0 / hz for mid, hz in DEFAULT_RATES_HZ.items()}
        self._next_due: dict[int, float] = {}
        self._param_queue: deque[int] = deque()
        self._peers: list[_Peer] = []
        self._listener: socket.socket | None = None
        self._udp: socket.socket | None = None
        self._open()

    # -- sockets ------------------------------------------------------------------------
    def _open(self) -> None:
        ep = self.endpoint
        try:
            if ep.kind == "tcpin":
                s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
                s.bind((ep.host, ep.port))
                s.listen(MAX_PEERS)
                s.setblocking(False)
                self._listener = s
                return
            s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            if ep.kind == "udpin":
                s.bind((ep.host, ep.port))
            else:
                probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
                try:  # a UDP connect sends nothing: it only asks for a route
                    probe.connect((ep.host, ep.port))
                    local = probe.getsockname()[0]
                finally:
                    probe.close()
                s.bind((local, 0))
                self._peers.append(_Peer((ep.host, ep.port), self._new_parser()))
            s.setblocking(False)
            self._udp = s
        except OSError as exc:
            verb = "send to" if ep.kind == "udpout" else "listen on"
            raise LinkError(f"cannot {verb} {ep.text()}: "
                            f"{exc.strerror or exc}") from None

    def _new_parser(self) -> mavlink.MAVLink:
        parser = _Parser(None, srcSystem=SYSTEM_ID, srcComponent=COMPONENT_ID)
        parser.robust_parsing = True
        if self._rx_signing is not None:
            parser.signing = self._rx_signing
        return parser

    @property
    def signing(self) -> bool:
        return self._rx_signing is not None

    @property
    def local_address(self) -> tuple[str, int]:
        s = self._listener or self._udp
        return s.getsockname()

    @property
    def peer_count(self) -> int:
        return len(self._peers)

    def close(self) -> None:
        for p in self._peers:
            if p.sock is not None:
                p.sock.close()
        for s in (self._listener, self._udp):
            if s is not None:
                s.close()
        self._peers.clear()

    def _send(self, msg) -> None:
        if self._rx_signing is not None:  # signing timestamps follow the wall clock
            sig = self._mav.signing
            sig.timestamp = max(sig.timestamp, signing_time_10us())
        data = msg.pack(self._mav)
        self.stats.sent += 1
        if self._udp is not None:
            for p in self._peers:
                try:
                    self._udp.sendto(data, p.addr)
                except OSError:  # refused, unreachable, buffer full: the loop goes on
                    self.stats.send_dropped += 1
            return
        for p in list(self._peers):
            p.backlog += data
            self._flush_tcp(p)

    def _flush_tcp(self, p: _Peer) -> None:
        try:
            while p.backlog:
                n = p.sock.send(p.backlog)
                del p.backlog[:n]
        except (BlockingIOError, InterruptedError):
            pass
        except OSError:
            self._drop(p)
            return
        if len(p.backlog) > MAX_TCP_BACKLOG:
            self._drop(p)

    def _drop(self, p: _Peer) -> None:
        if p in self._peers:
            self._peers.remove(p)
        if p.sock is not None:
            p.sock.close()

    # -- the loop's entry ---------------------------------------------------------------
    def service(self, state: VehicleState, now_s: float | None = None) -> None:
        """Read (bounded), answer, and send what is due at wall time ``now_s`` [s,
        monotonic]. Never blocks."""
        now = time.monotonic() if now_s is None else now_s
        self._receive(state)
        for mid, interval in self.intervals_s.items():
            if interval <= 0.0:
                continue
            due = self._next_due.get(mid, now)
            if now >= due:
                self._send_message(mid, state)
                due += interval
                self._next_due[mid] = due if due > now else now + interval  # no burst
        for _ in range(min(PARAMS_PER_SERVICE, len(self._param_queue))):
            self._send_param(self._param_queue.popleft())

    def _receive(self, state: VehicleState) -> None:
        budget = MAX_PARSE_BYTES
        if self._listener is not None:
            self._accept()
            for p in list(self._peers):
                if budget <= 0:
                    break
                try:
                    data = p.sock.recv(min(budget, 4096))
                except (BlockingIOError, InterruptedError):
                    continue
                except OSError:
                    self._drop(p)
                    continue
                if not data:
                    self._drop(p)
                    continue
                budget -= len(data)
                self._handle_bytes(p, data, state)
                if p.backlog:
                    self._flush_tcp(p)
            return
        for _ in range(MAX_DATAGRAMS):
            try:
                data, addr = self._udp.recvfrom(65535)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:  # ICMP port unreachable of an earlier send, etc.
                if exc.errno in (errno.ECONNREFUSED, errno.ENETUNREACH, errno.EHOSTUNREACH):
                    continue
                break
            self.stats.datagrams += 1
            if budget <= 0:
                self.stats.bytes_dropped += len(data)
                continue
            chunk = data[:budget]
            self.stats.bytes_dropped += len(data) - len(chunk)
            budget -= len(chunk)
            peer = next((p for p in self._peers if p.addr == addr), None)
            if peer is None:
                peer = _Peer(addr, self._new_parser())  # known once it sends valid MAVLink
                if self._handle_bytes(peer, chunk, state) and len(self._peers) < MAX_PEERS \
                        and self.endpoint.kind == "udpin":
                    self._peers.append(peer)
            else:
                self._handle_bytes(peer, chunk, state)

    def _accept(self) -> None:
        for _ in range(MAX_PEERS):
            try:
                conn, addr = self._listener.accept()
            except (BlockingIOError, InterruptedError, OSError):
                return
            if len(self._peers) >= MAX_PEERS:
                conn.close()
                continue
            conn.setblocking(False)
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self._peers.append(_Peer(addr, self._new_parser(), conn))

    def _handle_bytes(self, peer: _Peer, data: bytes, state: VehicleState) -> int:
        try:
            msgs = peer.parser.parse_buffer(data) or []
        except _CODEC_ERRORS:  # a codec error on hostile input: drop the bytes
            peer.parser = self._new_parser()
            self.stats.bad += 1
            return 0
        good = 0
        for msg in msgs:
            name = msg.get_type()
            # unknown message ids carry no checkable CRC (no CRC_EXTRA): noise, not MAVLink
            if name == "BAD_DATA" or name.startswith("UNKNOWN"):
                self.stats.bad += 1
                if name == "BAD_DATA" and "signature" in str(getattr(msg, "reason", "")):
                    self.stats.rejected_signature += 1
                continue
            good += 1
            self.stats.received += 1
            self.stats.by_type[name] = self.stats.by_type.get(name, 0) + 1
            peer.last_seen = time.monotonic()
            try:
                self._handle(msg, state)
            except (ValueError, TypeError, OverflowError, KeyError, struct.error):
                self.stats.bad += 1
        return good

    # -- protocol -----------------------------------------------------------------------
    def _for_us(self, msg) -> bool:
        ts = getattr(msg, "target_system", 0)
        tc = getattr(msg, "target_component", 0)
        return ts in (0, SYSTEM_ID) and tc in (0, COMPONENT_ID)

    def _handle(self, msg, state: VehicleState) -> None:
        t = msg.get_type()
        if t in ("COMMAND_LONG", "COMMAND_INT"):
            if self._for_us(msg):
                self._command(msg, state)
        elif t == "PARAM_REQUEST_LIST":
            if self._for_us(msg):
                self._param_queue.clear()
                self._param_queue.extend(range(len(self.params.names)))
        elif t == "PARAM_REQUEST_READ":
            if self._for_us(msg):
                names = self.params.names
                name = _param_name(msg.param_id)
                if msg.param_index >= 0:
                    if msg.param_index < len(names):
                        self._send_param(msg.param_index)
                elif name in names:
                    self._send_param(names.index(name))
        elif t == "PARAM_SET":
            if self._for_us(msg):
                name = _param_name(msg.param_id)
                if name in self.params.names:
                    try:
                        self.params.set(name, float(msg.param_value))
                    except ValueError:
                        pass  # the PARAM_VALUE below reports the value still in force
                    self._send_param(self.params.names.index(name))
        elif t == "MISSION_REQUEST_LIST":
            if self._for_us(msg):
                self._send(self._mav.mission_count_encode(
                    msg.get_srcSystem(), msg.get_srcComponent(), 0, msg.mission_type))
        elif t in ("MISSION_COUNT", "MISSION_CLEAR_ALL"):
            if self._for_us(msg):
                result = (M.MAV_MISSION_ACCEPTED if t == "MISSION_CLEAR_ALL" or msg.count == 0
                          else M.MAV_MISSION_UNSUPPORTED)
                self._send(self._mav.mission_ack_encode(
                    msg.get_srcSystem(), msg.get_srcComponent(), result, msg.mission_type))
        elif t == "TIMESYNC":
            if msg.tc1 == 0:  # a request: answer with the vehicle's (simulated) clock [ns]
                self._send(self._mav.timesync_encode(max(1, int(state.time_s * 1e9)),
                                                     msg.ts1))
        elif t == "FILE_TRANSFER_PROTOCOL":
            if msg.target_system == SYSTEM_ID and msg.target_component in (0, COMPONENT_ID):
                self._ftp_reply(msg)
        elif t == "PING":
            if msg.target_system == 0 and msg.target_component == 0:
                self._send(self._mav.ping_encode(msg.time_usec, msg.seq, msg.get_srcSystem(),
                                                 msg.get_srcComponent()))
        elif t == "REQUEST_DATA_STREAM":
            if self._for_us(msg):
                hz = float(msg.req_message_rate) if msg.start_stop else 0.0
                for mid in _STREAMS.get(msg.req_stream_id, ()):
                    self._set_rate(mid, hz)
        elif t == "MANUAL_CONTROL":
            if msg.target in (0, SYSTEM_ID) and self.on_manual is not None:
                # x: pitch (forward stick = nose down), y: roll; -1000..1000
                self.on_manual(_clip_unit(msg.x / 1000.0), _clip_unit(msg.y / 1000.0))
        elif t == "RC_CHANNELS_OVERRIDE":
            if self._for_us(msg) and self.on_manual is not None:
                roll, pitch = msg.chan1_raw, msg.chan2_raw
                if roll in (0, 65535) or pitch in (0, 65535):
                    self.on_manual(None, None)  # released: back to the autopilot
                else:
                    self.on_manual(_clip_unit((pitch - 1500) / 500.0),
                                   _clip_unit((roll - 1500) / 500.0))

    def _ftp_reply(self, msg) -> None:
        """The vehicle has no MAVLink FTP server: every request gets a NAK (UnknownCommand),
        session ends an ACK, so a ground station that tries FTP first (MAVProxy fetches its
        parameters that way) falls back to the parameter protocol at once."""
        payload = bytes(msg.payload)
        if len(payload) < 12:
            return
        seq = int.from_bytes(payload[0:2], "little")
        session, opcode = payload[2], payload[3]
        if opcode in (FTP_OP_TERMINATE_SESSION, FTP_OP_RESET_SESSIONS):
            reply, data = FTP_OP_ACK, b""
        else:
            reply, data = FTP_OP_NAK, bytes([FTP_ERR_UNKNOWN_COMMAND])
        header = struct.pack("<HBBBBBBI", (seq + 1) & 0xFFFF, session, reply, len(data),
                             opcode, 0, 0, 0)
        body = (header + data).ljust(251, b"\0")
        self._send(self._mav.file_transfer_protocol_encode(
            msg.target_network, msg.get_srcSystem(), msg.get_srcComponent(), body))

    def _set_rate(self, mid: int, hz: float) -> None:
        if mid == M.MAVLINK_MSG_ID_HEARTBEAT:
            return  # the heartbeat stays at 1 Hz
        hz = min(max(hz, 0.0), MAX_RATE_HZ)
        self.intervals_s[mid] = 1.0 / hz if hz > 0.0 else 0.0
        self._next_due.pop(mid, None)

    def _ack(self, msg, result: int) -> None:
        self._send(self._mav.command_ack_encode(msg.command, result, 0, 0, msg.get_srcSystem(),
                                                msg.get_srcComponent()))

    def _command(self, msg, state: VehicleState) -> None:
        cmd = msg.command
        if cmd == M.MAV_CMD_SET_MESSAGE_INTERVAL:
            mid, interval_us = int(msg.param1), msg.param2
            if mid not in DEFAULT_RATES_HZ or mid == M.MAVLINK_MSG_ID_HEARTBEAT:
                self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
                return
            if interval_us < 0:
                hz = 0.0
            elif interval_us == 0:
                hz = DEFAULT_RATES_HZ[mid]
            else:
                hz = 1e6 / interval_us
            self._set_rate(mid, hz)
            self._ack(msg, M.MAV_RESULT_ACCEPTED)
        elif cmd in (M.MAV_CMD_REQUEST_MESSAGE, M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES):
            mid = (M.MAVLINK_MSG_ID_AUTOPILOT_VERSION
                   if cmd == M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES else int(msg.param1))
            if mid == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION or mid in DEFAULT_RATES_HZ:
                self._ack(msg, M.MAV_RESULT_ACCEPTED)
                self._send_message(mid, state)
            else:
                self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
        else:
            self._ack(msg, M.MAV_RESULT_UNSUPPORTED)

    # -- outgoing messages ----------------------------------------------------------------
    def _send_param(self, index: int) -> None:
        names = self.params.names
        name = names[index]
        self._send(self._mav.param_value_encode(name.encode(), float(self.params.get(name)),
                                                M.MAV_PARAM_TYPE_REAL32, len(names), index))

    def _send_message(self, mid: int, s: VehicleState) -> None:
        mav = self._mav
        boot_ms = int(s.time_s * 1000.0 + 1e-6) & 0xFFFFFFFF  # ⌊1000 t⌋ (+1 ns: k·dt rounding)
        if mid == M.MAVLINK_MSG_ID_HEARTBEAT:
            mode = M.MAV_MODE_FLAG_SAFETY_ARMED | M.MAV_MODE_FLAG_STABILIZE_ENABLED
            mode |= M.MAV_MODE_FLAG_MANUAL_INPUT_ENABLED if s.manual else 0
            mode |= M.MAV_MODE_FLAG_AUTO_ENABLED if s.autopilot and not s.manual else 0
            self._send(mav.heartbeat_encode(M.MAV_TYPE_FIXED_WING, M.MAV_AUTOPILOT_GENERIC,
                                            mode, 0, M.MAV_STATE_ACTIVE))
        elif mid == M.MAVLINK_MSG_ID_SYS_STATUS:
            sensors = (M.MAV_SYS_STATUS_SENSOR_3D_GYRO | M.MAV_SYS_STATUS_SENSOR_3D_ACCEL
                       | M.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
                       | M.MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE
                       | M.MAV_SYS_STATUS_SENSOR_GPS | M.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
                       | M.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION)
            # health also says "no geofence breach" (there is no fence: MAVProxy reads a
            # missing health bit as a breach)
            self._send(mav.sys_status_encode(sensors, sensors,
                                             sensors | M.MAV_SYS_STATUS_GEOFENCE, 0, 16800,
                                             -1, -1, 0, 0, 0, 0, 0, 0))
        elif mid == M.MAVLINK_MSG_ID_ATTITUDE:
            self._send(mav.attitude_encode(boot_ms, s.roll_rad, s.pitch_rad, s.yaw_rad,
                                           s.p_rad_s, s.q_rad_s, s.r_rad_s))
        elif mid == M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT:
            self._send(mav.global_position_int_encode(
                boot_ms, _deg_e7(s.latitude_rad), _deg_e7(s.longitude_rad),
                _i32(s.altitude_m * 1000.0), _i32(s.relative_altitude_m * 1000.0),
                _i16(s.v_north_m_s * 100.0), _i16(s.v_east_m_s * 100.0),
                _i16(s.v_down_m_s * 100.0), _heading_cdeg(s.yaw_rad)))
        elif mid == M.MAVLINK_MSG_ID_GPS_RAW_INT:
            vg = math.hypot(s.v_north_m_s, s.v_east_m_s)
            cog = math.atan2(s.v_east_m_s, s.v_north_m_s)
            self._send(mav.gps_raw_int_encode(
                int(s.time_s * 1e6 + 1e-3), M.GPS_FIX_TYPE_3D_FIX, _deg_e7(s.latitude_rad),
                _deg_e7(s.longitude_rad), _i32(s.altitude_m * 1000.0), 80, 120,
                min(int(vg * 100.0), 65534), _heading_cdeg(cog), 12))
        elif mid == M.MAVLINK_MSG_ID_VFR_HUD:
            vg = math.hypot(s.v_north_m_s, s.v_east_m_s)
            heading = int(round(math.degrees(s.yaw_rad))) % 360
            self._send(mav.vfr_hud_encode(s.airspeed_m_s, vg, heading,
                                          int(round(100.0 * s.throttle)), s.altitude_m,
                                          -s.v_down_m_s))
        elif mid == M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT:
            for name, value in s.named.items():
                self._send(mav.named_value_float_encode(boot_ms, name.encode()[:10],
                                                        float(value)))
        elif mid == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
            self._send(mav.autopilot_version_encode(
                CAPABILITIES, 0, 0, 0, 0, [0] * 8, [0] * 8, [0] * 8, 0, 0, 0))


def _param_name(raw) -> str:
    if isinstance(raw, bytes):
        raw = raw.decode("ascii", "replace")
    return str(raw).split("\x00", 1)[0]


def _clip_unit(x: float) -> float:
    return max(-1.0, min(1.0, float(x)))


def _i32(x: float) -> int:
    return max(-(2**31), min(2**31 - 1, int(round(x)))) if math.isfinite(x) else 0


def _i16(x: float) -> int:
    return max(-32768, min(32767, int(round(x)))) if math.isfinite(x) else 0


def _deg_e7(rad: float) -> int:
    return _i32(math.degrees(rad) * 1e7)


def _heading_cdeg(rad: float) -> int:
    return int(round(math.degrees(rad) * 100.0)) % 36000 if math.isfinite(rad) else 65535


# MAVLink constants the simulation side needs without importing pymavlink itself.
MSG_IDS = {name: getattr(M, f"MAVLINK_MSG_ID_{name}") for name in (
    "HEARTBEAT", "SYS_STATUS", "ATTITUDE", "GLOBAL_POSITION_INT", "GPS_RAW_INT", "VFR_HUD",
    "NAMED_VALUE_FLOAT", "AUTOPILOT_VERSION")}
