"""MAVLink 2 link of the SITL aircraft: telemetry out, ground-station handshakes in.

The ``links.mavlink*`` modules are the only ones that import :mod:`pymavlink` (its MAVLink 2
``common`` codec; the sockets are ours). The vehicle is system 1, component 1 (the autopilot).

Endpoints (``parse_endpoint``):

* ``udpout:HOST:PORT``: send to a ground station listening there (QGroundControl's
  ``udp 14550``); its replies come back to our (ephemeral) port;
* ``udpin:HOST:PORT``: listen; send to the peers that sent us valid MAVLink (up to
  :data:`MAX_PEERS`);
* ``tcpin:HOST:PORT``: listen for up to :data:`MAX_PEERS` TCP clients.

HOST is an IPv4 address or ``localhost``; omitted (``udpin:14550``, ``udpout::14550``) it is
127.0.0.1: the link binds and sends to loopback only unless another address is given
explicitly.

Safety of the loop: every socket is non-blocking; malformed or truncated input is skipped
by the parser (robust parsing, CRC checked); a peer that is absent or gone never blocks
(sends that would block are dropped; a TCP client whose backlog exceeds
:data:`MAX_TCP_BACKLOG` is disconnected). Floods from other local ports and the ``udpin``
slots: :mod:`bioflex_jsb.links.mavlink_peers`.

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

Sequence numbers: one counter for everything the vehicle sends, +1 (mod 256) per packet,
as the MAVLink 2 spec asks (every peer sees the same numbers, so a peer's loss count is
right). Peers (``udpin``) that stay silent for :data:`PEER_TIMEOUT_S` are dropped, which
frees their slot; with signing on, only a peer whose message passed the signature check gets
a slot (an unsigned RADIO_STATUS is accepted but adds no peer).

MANUAL_CONTROL and RC_CHANNELS_OVERRIDE (:mod:`bioflex_jsb.links.mavlink_sticks`): obeyed
from one ground station only, the first (system, component) that sends sticks, until that
one is silent for :data:`CONTROLLER_TIMEOUT_S`, and only in the stick modes (MANUAL,
STABILIZE, FBWA); override channels one by one (0 / UINT16_MAX as MAVLink defines them);
refusals are said (STATUSTEXT) and logged.

Signing (``signing_key``, :func:`read_signing_key`): MAVLink 2 message signing with one
32-byte secret. Everything sent is signed (link id 0, timestamps from the wall clock in
10 µs since 2015-01-01 UTC, as the MAVLink signing spec asks); a received message is
accepted only with a valid signature whose timestamp is newer than the last one of its
stream (link id, system, component) and not more than 60 s older than the link's own
time (replay protection, shared by all peers of the link). Unsigned or wrongly signed
messages are dropped (counted in ``LinkStats.rejected_signature``) except RADIO_STATUS,
which radios send unsigned. A peer with no validly signed message is never added
(``udpin``), so it gets no telemetry either.
"""

from __future__ import annotations

import errno
import hashlib
import hmac
import socket
import struct
import time
from collections import deque

from pymavlink.dialects.v20 import common as mavlink

from bioflex_jsb.links.mavlink_commands import CommandHandler
from bioflex_jsb.links.mavlink_mission import MissionProtocol
from bioflex_jsb.links.mavlink_peers import (  # noqa: F401  (the link's peers and floods)
    DRAIN_RATE_PER_S,
    MAX_CANDIDATES,
    MAX_DRAIN,
    MAX_PARSE_BYTES,
    MAX_PEERS,
    MIN_DRAIN,
    NEW_SOURCE_DATAGRAMS_PER_CALL,
    NEW_SOURCES_PER_CALL,
    PEER_DATAGRAMS_PER_CALL,
    PRESENCE_S,
    RECV_BUFFER_BYTES,
    LinkStats,
    Peer,
    Slots,
)
from bioflex_jsb.links.mavlink_setup import (  # noqa: F401  (the link's set-up and state)
    SIGNING_EPOCH_UNIX_S,
    SIGNING_KEY_BYTES,
    Endpoint,
    LinkError,
    Parameters,
    Vehicle,
    VehicleState,
    parse_endpoint,
    read_signing_key,
    signing_time_10us,
)
from bioflex_jsb.links.mavlink_sticks import CONTROLLER_TIMEOUT_S, Sticks  # noqa: F401
from bioflex_jsb.links.mavlink_telemetry import (  # noqa: F401
    CAPABILITIES,
    DEFAULT_RATES_HZ,
    STREAMS,
    encode,
)
from bioflex_jsb.links.udp_guard import BLOCK_S, FLOOD_RATE_PER_S, FloodGuard

# What pymavlink's parser raises on bytes that are not MAVLink (hostile or corrupt input):
# its own MAVError, and the struct/array/decoding errors of a truncated or mangled payload.
_CODEC_ERRORS = (mavlink.MAVError, struct.error, ValueError, IndexError, KeyError, TypeError,
                 UnicodeDecodeError, OverflowError)

SYSTEM_ID = 1
COMPONENT_ID = 1
PEER_TIMEOUT_S = 5.0  # a udpin peer silent this long [wall s] is dropped
MAX_TCP_BACKLOG = 256 * 1024  # unsent bytes to one TCP client before it is dropped
PARAMS_PER_SERVICE = 8  # PARAM_VALUE messages of a list request sent per service call
STATUSTEXTS_PER_SERVICE = 4

M = mavlink
MAX_RATE_HZ = 200.0
SIGNING_STREAM_AGE_10US = 60 * 100_000  # a new stream may be this much older (60 s)
UNSIGNED_ALLOWED = frozenset({M.MAVLINK_MSG_ID_RADIO_STATUS})  # radios cannot sign
# MAVLink FTP (FILE_TRANSFER_PROTOCOL payload header): opcodes and error codes used here
FTP_OP_TERMINATE_SESSION = 1
FTP_OP_RESET_SESSIONS = 2
FTP_OP_ACK = 128
FTP_OP_NAK = 129
FTP_ERR_UNKNOWN_COMMAND = 7


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


class MavlinkLink:
    """The vehicle's MAVLink link (module docstring). Call :meth:`service` from the loop.

    ``vehicle``: what commands, modes, sticks and missions act on (:class:`Vehicle`; None: a
    link that only streams and serves parameters)."""

    def __init__(self, endpoint: Endpoint | str, params: Parameters,
                 vehicle: Vehicle | None = None, signing_key: bytes | None = None) -> None:
        self.endpoint = parse_endpoint(endpoint) if isinstance(endpoint, str) else endpoint
        self.params = params
        self.vehicle = vehicle
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
        self.slots = Slots(self.stats, self._notice, self._tell, self._send_pending_notices,
                           self._drop)
        self._peers = self.slots.peers  # the same list
        self._now = time.monotonic()  # the wall time of the service call in progress [s]
        self._last_service_s: float | None = None
        self._listener: socket.socket | None = None
        self._udp: socket.socket | None = None
        self.guard: FloodGuard | None = None  # UDP only: a flooding source blocked
        self.sticks = Sticks(self, vehicle)
        self._last_mission_seq: int | None = None
        self.mission = (MissionProtocol(self._mav, self._send, vehicle)
                        if vehicle is not None else None)
        self.commands = CommandHandler(self, vehicle)
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
                peer = Peer((ep.host, ep.port), self._new_parser())
                peer.fixed = True
                self._peers.append(peer)
            s.setblocking(False)
            try:  # a flood between two calls waits (module docstring: Floods)
                s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECV_BUFFER_BYTES)
            except OSError:  # a system that refuses the size keeps its default
                pass
            self.stats.recv_buffer_bytes = s.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF)
            self._udp = s
            self.guard = FloodGuard(s)
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

    @property
    def peer_addresses(self) -> list:
        """The peers' addresses ((host, port)), oldest first."""
        return [p.addr for p in self._peers]

    def close(self) -> None:
        for p in self._peers:
            if p.sock is not None:
                p.sock.close()
        for s in (self._listener, self._udp):
            if s is not None:
                s.close()
        self._peers.clear()

    def _send(self, msg) -> None:
        mav = self._mav
        if self._rx_signing is not None:  # signing timestamps follow the wall clock
            sig = mav.signing
            sig.timestamp = max(sig.timestamp, signing_time_10us())
        data = msg.pack(mav)
        mav.seq = (mav.seq + 1) % 256  # one sequence for all the vehicle sends
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

    def _flush_tcp(self, p: Peer) -> None:
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

    def _drop(self, p: Peer) -> None:
        if p in self._peers:
            self._peers.remove(p)
        if p.sock is not None:
            p.sock.close()

    def _expire_peers(self, now: float) -> None:
        if self.endpoint.kind != "udpin":
            return
        if self.guard.blocked:  # a flood goes on, dropped by the kernel: peers kept
            self.slots.flood_until = max(self.slots.flood_until, now + PEER_TIMEOUT_S)
        self.slots.expire(now, PEER_TIMEOUT_S)

    def _notice(self, severity: int, text: str) -> None:
        """Tell the peers (STATUSTEXT) and, with a vehicle, the session log."""
        if self.vehicle is not None:
            self.vehicle.status(severity, text)  # sent by service with the vehicle's events
        else:
            self.statustext(severity, text)

    # -- the loop's entry ---------------------------------------------------------------
    def service(self, state: VehicleState, now_s: float | None = None) -> None:
        """Read (bounded), answer, and send what is due at wall time ``now_s`` [s,
        monotonic]. Never blocks."""
        now = time.monotonic() if now_s is None else now_s
        self._now = now
        self._receive(state)
        self._expire_peers(now)
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
        v = self.vehicle
        if v is None:
            return
        self.mission.service(now)
        for _ in range(min(STATUSTEXTS_PER_SERVICE, len(v.events))):
            severity, text = v.events.popleft()
            self.statustext(severity, text)
        while v.reached:
            self._send(self._mav.mission_item_reached_encode(v.reached.popleft()))
        if state.mission_seq != self._last_mission_seq:
            self._last_mission_seq = state.mission_seq
            self._send_message(M.MAVLINK_MSG_ID_MISSION_CURRENT, state)

    def statustext(self, severity: int, text: str) -> None:
        """STATUSTEXT: up to 50 characters in one message, longer texts in chunks (id,
        chunk_seq)."""
        raw = text.encode("utf-8", "replace")
        if len(raw) <= 50:
            self._send(self._mav.statustext_encode(severity, raw))
            return
        self._text_id = (getattr(self, "_text_id", 0) % 65535) + 1
        for k in range(0, min(len(raw), 50 * 8), 50):
            self._send(self._mav.statustext_encode(severity, raw[k:k + 50], self._text_id,
                                                   k // 50))

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
        now, last = self._now, self._last_service_s
        self._last_service_s = now
        reads = MAX_DRAIN if last is None else int(min(MAX_DRAIN, max(
            MIN_DRAIN, DRAIN_RATE_PER_S * (now - last))))
        udp, stats, peers, tally = self._udp, self.stats, self._peers, self.guard.count
        parsed: dict[tuple, int] = {}  # datagrams parsed this call, per source
        n = 0
        while n < reads:
            try:
                data, addr = udp.recvfrom(65535)
            except (BlockingIOError, InterruptedError):
                break
            except OSError as exc:  # ICMP port unreachable of an earlier send, etc.
                if exc.errno in (errno.ECONNREFUSED, errno.ENETUNREACH, errno.EHOSTUNREACH):
                    continue
                break
            n += 1
            tally(addr)
            peer = None
            for p in peers:  # at most MAX_PEERS comparisons, before any parsing
                if p.addr == addr:
                    peer = p
                    break
            count = parsed.get(addr, 0)
            if peer is not None:
                if count >= PEER_DATAGRAMS_PER_CALL:
                    stats.peer_dropped += 1
                    continue
            elif count >= NEW_SOURCE_DATAGRAMS_PER_CALL or (
                    not count and len(parsed) >= NEW_SOURCES_PER_CALL + len(peers)):
                stats.unknown_dropped += 1
                continue
            parsed[addr] = count + 1
            chunk = data[:MAX_PARSE_BYTES]
            stats.bytes_dropped += len(data) - len(chunk)
            if peer is not None:
                self._handle_bytes(peer, chunk, state)
            else:
                self._newcomer(addr, chunk, state)
        stats.datagrams += n
        if n >= reads and reads >= MIN_DRAIN:
            self.slots.flooded(now, PEER_TIMEOUT_S)
        blocked, _ = self.guard.check(now)
        for addr in blocked:  # said once a block (10 s); a peer that floods loses its slot
            stats.blocked += 1
            self.slots.flooded(now, PEER_TIMEOUT_S)
            for p in peers:
                if p.addr == addr:
                    self._drop(p)
                    break
            self._notice(M.MAV_SEVERITY_WARNING,
                         f"{addr[0]}:{addr[1]} sends more than {FLOOD_RATE_PER_S:g} "
                         f"datagrams/s: dropped by the kernel for {BLOCK_S:g} s")

    def _newcomer(self, addr, data: bytes, state: VehicleState) -> None:
        """A datagram from a source without a slot: handled as any; a source of valid
        (with signing on, validly signed) MAVLink may take a slot (:class:`Slots`)."""
        slots = self.slots
        cand = slots.candidate(addr, self._now, self._new_parser)
        if self._handle_bytes(cand, data, state) and self.endpoint.kind == "udpin":
            slots.admit(cand, self._now, PEER_TIMEOUT_S)
        else:
            slots.remember(cand)

    def _tell(self, addr, text: str) -> None:
        """One STATUSTEXT (WARNING, up to 50 characters) to one address that is not a peer
        (a refusal)."""
        mav = self._mav
        msg = mav.statustext_encode(M.MAV_SEVERITY_WARNING, text.encode()[:50])
        if self._rx_signing is not None:
            mav.signing.timestamp = max(mav.signing.timestamp, signing_time_10us())
        data = msg.pack(mav)
        mav.seq = (mav.seq + 1) % 256
        self.stats.sent += 1
        try:
            self._udp.sendto(data, addr)
        except OSError:
            self.stats.send_dropped += 1

    def _send_pending_notices(self) -> None:
        """The vehicle's queued STATUSTEXTs now (an eviction's notice reaches the evicted)."""
        v = self.vehicle
        if v is None:
            return
        while v.events:
            severity, text = v.events.popleft()
            self.statustext(severity, text)

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
            self._peers.append(Peer(addr, self._new_parser(), conn))

    def _handle_bytes(self, peer: Peer, data: bytes, state: VehicleState) -> int:
        """Parse and handle; the number of messages that qualify their sender as a peer
        (valid MAVLink; with signing on, validly signed)."""
        try:
            msgs = peer.parser.parse_buffer(data) or []
        except _CODEC_ERRORS:  # a codec error on hostile input: drop the bytes
            peer.parser = self._new_parser()
            self.stats.bad += 1
            return 0
        good = 0
        signing = self._rx_signing is not None
        for msg in msgs:
            name = msg.get_type()
            # unknown message ids carry no checkable CRC (no CRC_EXTRA): noise, not MAVLink
            if name == "BAD_DATA" or name.startswith("UNKNOWN"):
                self.stats.bad += 1
                if name == "BAD_DATA" and "signature" in str(getattr(msg, "reason", "")):
                    self.stats.rejected_signature += 1
                continue
            self.stats.received += 1
            self.stats.by_type[name] = self.stats.by_type.get(name, 0) + 1
            if signing and not getattr(msg, "_signed", False):
                self._handle_unsigned(msg)
                continue
            good += 1
            peer.hear(self._now, signing)
            self._handle(msg, state)  # every field's value is checked where it is used
        return good

    def _handle_unsigned(self, msg) -> None:
        """An unsigned message let through with signing on (RADIO_STATUS): nothing to do
        (no peer slot, no answer)."""

    # -- protocol -----------------------------------------------------------------------
    def _for_us(self, msg) -> bool:
        ts = getattr(msg, "target_system", 0)
        tc = getattr(msg, "target_component", 0)
        return ts in (0, SYSTEM_ID) and tc in (0, COMPONENT_ID)

    def _handle(self, msg, state: VehicleState) -> None:
        """One message from a peer, dispatched by type (:data:`_HANDLERS`; MISSION_* to the
        mission protocol); a type the vehicle does not serve is ignored."""
        t = msg.get_type()
        if t.startswith("MISSION_"):
            self._on_mission(msg, t)
            return
        handler = _HANDLERS.get(t)
        if handler is not None:
            getattr(self, handler)(msg, state)

    def _on_command(self, msg, state: VehicleState) -> None:
        if self._for_us(msg):
            self.commands.handle(msg, state)

    def _on_param_request_list(self, msg, state: VehicleState) -> None:
        if self._for_us(msg):
            self._param_queue.clear()
            self._param_queue.extend(range(len(self.params.names)))

    def _on_param_request_read(self, msg, state: VehicleState) -> None:
        if not self._for_us(msg):
            return
        names = self.params.names
        name = _param_name(msg.param_id)
        if msg.param_index >= 0:
            if msg.param_index < len(names):
                self._send_param(msg.param_index)
            else:
                self._param_error(msg, b"", msg.param_index, M.MAV_PARAM_ERROR_DOES_NOT_EXIST)
        elif name in names:
            self._send_param(names.index(name))
        else:
            self._param_error(msg, name.encode()[:16], -1, M.MAV_PARAM_ERROR_DOES_NOT_EXIST)

    def _on_param_set(self, msg, state: VehicleState) -> None:
        if not self._for_us(msg):
            return
        name = _param_name(msg.param_id)
        if name not in self.params.names:
            self._param_error(msg, name.encode()[:16], -1, M.MAV_PARAM_ERROR_DOES_NOT_EXIST)
            return
        try:
            self.params.set(name, float(msg.param_value))
        except ValueError as exc:  # the PARAM_VALUE reports the value in force
            self._param_error(msg, name.encode()[:16], -1,
                              M.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE)
            self.commands.refuse(f"PARAM_SET {exc}")
        self._send_param(self.params.names.index(name))

    def _on_mission(self, msg, t: str) -> None:
        """The mission protocol's messages; without a mission, a list, count or clear is
        answered "unsupported"."""
        if self.mission is not None and self._for_us(msg):
            self.mission.handle(msg, t)
        elif self._for_us(msg) and t in ("MISSION_REQUEST_LIST", "MISSION_COUNT",
                                         "MISSION_CLEAR_ALL"):
            self._send(self._mav.mission_ack_encode(
                msg.get_srcSystem(), msg.get_srcComponent(), M.MAV_MISSION_UNSUPPORTED,
                getattr(msg, "mission_type", 0)))

    def _on_set_mode(self, msg, state: VehicleState) -> None:
        if (msg.target_system == SYSTEM_ID and self.vehicle is not None
                and msg.base_mode & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED):
            reason = self.vehicle.set_mode(int(msg.custom_mode))
            if reason:
                self.commands.refuse(f"SET_MODE: {reason}")

    def _on_timesync(self, msg, state: VehicleState) -> None:
        if msg.tc1 == 0:  # a request: answer with the vehicle's (simulated) clock [ns]
            self._send(self._mav.timesync_encode(max(1, int(state.time_s * 1e9)), msg.ts1))

    def _on_ftp(self, msg, state: VehicleState) -> None:
        if msg.target_system == SYSTEM_ID and msg.target_component in (0, COMPONENT_ID):
            self._ftp_reply(msg)

    def _on_ping(self, msg, state: VehicleState) -> None:
        if msg.target_system == 0 and msg.target_component == 0:
            self._send(self._mav.ping_encode(msg.time_usec, msg.seq, msg.get_srcSystem(),
                                             msg.get_srcComponent()))

    def _on_request_data_stream(self, msg, state: VehicleState) -> None:
        if self._for_us(msg):
            hz = float(msg.req_message_rate) if msg.start_stop else 0.0
            for mid in STREAMS.get(msg.req_stream_id, ()):
                self.set_rate(mid, hz)

    def _on_manual_control(self, msg, state: VehicleState) -> None:
        if msg.target in (0, SYSTEM_ID) and self.vehicle is not None:
            self.sticks.manual_control(msg)

    def _on_rc_override(self, msg, state: VehicleState) -> None:
        if self._for_us(msg) and self.vehicle is not None:
            self.sticks.rc_override(msg)

    def _param_error(self, msg, name: bytes, index: int, error: int) -> None:
        self._send(self._mav.param_error_encode(msg.get_srcSystem(), msg.get_srcComponent(),
                                                name, index, error))

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

    def set_rate(self, mid: int, hz: float) -> None:
        if mid == M.MAVLINK_MSG_ID_HEARTBEAT:
            return  # the heartbeat stays at 1 Hz
        hz = min(max(hz, 0.0), MAX_RATE_HZ)
        self.intervals_s[mid] = 1.0 / hz if hz > 0.0 else 0.0
        self._next_due.pop(mid, None)

    # -- outgoing messages ----------------------------------------------------------------
    def _send_param(self, index: int) -> None:
        names = self.params.names
        name = names[index]
        self._send(self._mav.param_value_encode(name.encode(), float(self.params.get(name)),
                                                M.MAV_PARAM_TYPE_REAL32, len(names), index))

    def _send_message(self, mid: int, s: VehicleState) -> None:
        for msg in encode(self._mav, mid, s):
            self._send(msg)

    def send_message(self, mid: int, s: VehicleState) -> bool:
        """Send message ``mid`` now (MAV_CMD_REQUEST_MESSAGE); False if it has no encoder."""
        msgs = encode(self._mav, mid, s)
        for msg in msgs:
            self._send(msg)
        return bool(msgs)

    def send(self, msg) -> None:
        self._send(msg)

    @property
    def mav(self):
        return self._mav


def _addr_text(addr) -> str:
    return f"{addr[0]}:{addr[1]}"


def _param_name(raw) -> str:
    if isinstance(raw, bytes):
        raw = raw.decode("ascii", "replace")
    return str(raw).split("\x00", 1)[0]


# MAVLink constants the simulation side needs without importing pymavlink itself.
MSG_IDS = {name: getattr(M, f"MAVLINK_MSG_ID_{name}") for name in (
    "HEARTBEAT", "SYS_STATUS", "ATTITUDE", "GLOBAL_POSITION_INT", "GPS_RAW_INT", "VFR_HUD",
    "NAMED_VALUE_FLOAT", "AUTOPILOT_VERSION", "HOME_POSITION", "BATTERY_STATUS")}


# The message types the vehicle serves and the MavlinkLink method that handles each
# (MISSION_* go to the mission protocol).
_HANDLERS = {
    "COMMAND_LONG": "_on_command",
    "COMMAND_INT": "_on_command",
    "PARAM_REQUEST_LIST": "_on_param_request_list",
    "PARAM_REQUEST_READ": "_on_param_request_read",
    "PARAM_SET": "_on_param_set",
    "SET_MODE": "_on_set_mode",
    "TIMESYNC": "_on_timesync",
    "FILE_TRANSFER_PROTOCOL": "_on_ftp",
    "PING": "_on_ping",
    "REQUEST_DATA_STREAM": "_on_request_data_stream",
    "MANUAL_CONTROL": "_on_manual_control",
    "RC_CHANNELS_OVERRIDE": "_on_rc_override",
}
