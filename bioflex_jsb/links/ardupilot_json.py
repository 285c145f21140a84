"""ArduPilot's JSON SITL interface: the simulator side of the protocol and a lock-step server.

ArduPilot SITL started with ``--model JSON:127.0.0.1`` flies a physics model it talks to over
UDP (``libraries/SITL/SIM_JSON.cpp`` and ``SIM_JSON.h`` of ArduPilot master 90700977c553;
``libraries/SITL/examples/JSON/readme.md``). This module is the physics side of that link,
without the physics: it imports neither JSBSim nor the co-simulation. A physics object that
satisfies :class:`JsonPhysics` is driven one ``step`` call per servo frame. The other
direction, the state and the reply's text, is :mod:`bioflex_jsb.links.ardupilot_reply`
(its names are importable from here too).

ArduPilot → simulator (:func:`parse_servo_packet`): one datagram per SITL frame, little
endian, to ``127.0.0.1:9002 + 10·instance`` (:func:`instance_port`):

* ``<HHI16H>`` (40 bytes): magic 18458, frame_rate [Hz] (ArduPilot's ``SIM_RATE_HZ``,
  default 1200), frame_count, 16 PWM values [µs];
* ``<HHI32H>`` (72 bytes, ArduPilot parameter ``SERVO_32_ENABLE = 1``): magic 29569, the
  same with 32 PWM values.

Any other datagram is rejected (:class:`ServoPacketError`, counted in
:class:`ServerStats`) and never answered.

Lock-step rules (:meth:`LockstepServer.handle`), from ``JSON::recv_fdm``: ArduPilot sends
frame n, waits for the reply and only then sends frame n+1 (its ``frame_counter`` advances
only on a reply it could parse); without a reply for 1 s it sends frame n again.

* a frame_count greater than the last one: one ``physics.step`` with the packet's PWM and
  frame rate, one reply with the new state (a jump of more than one is counted in
  ``frames_skipped``);
* the same frame_count again: the same reply again, no step (ArduPilot's timestamp then
  does not change, so its clock does not advance either);
* frame_count 0 after a larger one: ArduPilot SITL restarted, so the physics is reset, then
  stepped once as for a new frame; a smaller frame_count other than 0 is a stale datagram
  (counted in ``stale``, not answered): a restarted ArduPilot always begins at frame 0 and
  re-sends it every second until it is answered. The one exception is the counter's wrap:
  frame_count is ArduPilot's uint32 (2³² frames are 41 days at 1200 Hz), so a count below
  :data:`FRAME_WRAP_WINDOW` after one within :data:`FRAME_WRAP_WINDOW` of 2³² is a later
  frame (counted modulo 2³², the frames between them in ``frames_skipped``), not a restart.

Binding (the peer): the session binds to the source (address, port) of the first servo
packet. Packets from any other source are dropped by their address before they are parsed,
counted (``foreign``), reported to ``on_event`` (the first one, then at 10, 100, 1000 ...
of them), never answered and never stepped, so a stray packet or a second sender cannot
reset or advance the flight, and a flood of them costs a read and a comparison each.
Another sender takes the session over only once the bound one has been silent (no frame
since our last reply) for :data:`PEER_SILENCE_S` of wall time, a silence a live ArduPilot
never keeps (it re-sends its frame every second), from any address:

* if the bound sender never lock-stepped (it never sent a later frame after our reply: a
  stray datagram, not an ArduPilot), any frame of the new sender re-binds the session and
  nothing is reset, since nothing restarted (counted in ``strays``);
* if it did, a frame 0 re-binds it: a new ArduPilot process (SITL's socket is not bound, so
  an ArduPilot restarted after a kill sends from a new ephemeral port, and one started on
  another address sends from there), and the physics is reset (``rebinds``, ``resets``).

So a frame-0 packet from another address that reaches the port before ArduPlane's first
frame holds the session for :data:`PEER_SILENCE_S` at most; ArduPlane, which re-sends its
frame 0 every second until it is answered, is bound at its first re-send after that.

Reads (:meth:`LockstepServer.serve_once`): at most :data:`MAX_BATCH` datagrams per call,
returning after the first one answered. A source that floods the port (more than 2000
datagrams a second; never the lock-stepping ArduPilot) is blocked in the kernel for 10 s at
a time (:mod:`bioflex_jsb.links.udp_guard`; ``blocked``, a WARNING each time): its datagrams
then cost nothing, take no buffer space and are not counted. The socket's receive buffer is
asked for :data:`RECV_BUFFER_BYTES` (the kernel grants at most ``net.core.rmem_max``): a
flood that arrives while a frame is stepped then waits in the buffer, to be dropped by its
address, instead of pushing the peer's next frame out of it (a lost frame costs ArduPilot's
1 s re-send).

Re-sends that crossed the reply (:meth:`LockstepServer.serve_once`): a frame answered more
than 1 s after ArduPilot sent it (a slow step: the compiled kernel's first step on a loaded
machine, a stalled host) has ArduPilot's re-sends of it queued behind it. They arrived
before the reply was sent, so ArduPilot gets that reply anyway; answering each again would
put one more reply in ArduPilot's socket per re-send, and ArduPilot reads one datagram per
frame (``JSON::recv_fdm``; a repeated timestamp advances its frame counter, not its clock),
so it would read every later reply that many frames late for the rest of the session: a
delay in the loop that depends on wall time (measured with ArduPlane at SIM_RATE_HZ 240: 6
re-sends, 25 ms between its servo outputs and the physics they act on, and a different
flight). So right after each reply the socket is read without waiting: the peer's re-sends
of the frame just answered are counted (``crossed_resends``) and dropped, and the first
other datagram is held for the next call. A re-send that arrives later (its reply lost) is
answered as before.

Wall time while connected (``ServerStats.connected_wall_s``, the denominator of the
session's real-time factor): the sum of the wall-time intervals between consecutive frames
of the peer, each counted when the peer's silence in it (from our reply to its next frame)
is shorter than :data:`PEER_SILENCE_S`; our own processing always counts (a slow step is
the session being slow), while waiting for the first peer, and the silence of a killed
ArduPilot until its restart, are not in it. The silence of the re-binding rule is measured
the same way: from our last reply to the peer.

ArduPilot adopts 1/Δtimestamp as its frame rate for 0 < Δt < 0.1 s, so the physics may
advance a frame by its own time; ``frame_rate_hz`` is passed to it, which may advance
several of its steps per frame at a low rate (the co-simulation's:
:mod:`bioflex_jsb.links.ardupilot_rate`).
"""

from __future__ import annotations

import math
import select
import socket
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple, Protocol

from bioflex_jsb.links.ardupilot_reply import (  # noqa: F401  (the reply's names, here too)
    FLT_MAX,
    MAX_REPLY_BYTES,
    QUATERNION_NORM_TOLERANCE,
    JsonState,
    JsonStateError,
    encode_reply,
    encode_reply_json,
)
from bioflex_jsb.links.udp_guard import BLOCK_S, FLOOD_RATE_PER_S, FloodGuard
from bioflex_jsb.values import is_whole

# SIM_JSON.h, servo_packet_16 / servo_packet_32: magic, frame_rate, frame_count, pwm[]
MAGIC_16 = 18458
MAGIC_32 = 29569
SERVO_16 = struct.Struct("<HHI16H")
SERVO_32 = struct.Struct("<HHI32H")
# SIM_JSON.h, control_port = 9002; SITL adds 10 per instance (-I): 9002, 9012, ...
BASE_PORT = 9002
PORT_STEP_PER_INSTANCE = 10
DEFAULT_HOST = "127.0.0.1"
RECV_BYTES = 512  # larger datagrams are truncated and then rejected by their length
# DEFINITION: the peer is taken for gone (killed, stopped) after this much wall time without a
# frame [s]: three of ArduPilot's 1 s re-send intervals (JSON::recv_fdm re-sends the frame
# after 1 s without a reply), so a live ArduPilot, however slow its host, never reaches it.
PEER_SILENCE_S = 3.0
# frame_count is ArduPilot's uint32 (SIM_JSON.h servo_packet: uint32_t frame_count)
FRAME_COUNT_MODULUS = 2 ** 32
# DEFINITION: a count below this after one within this of 2^32 is the counter's wrap, not a
# restart: 2^16 frames are 55 s at 1200 Hz, far more than any gap between two frames a live
# ArduPilot leaves, and a restart within 55 s of the wrap (41 days at 1200 Hz) is the one case
# read wrongly.
FRAME_WRAP_WINDOW = 2 ** 16
# Datagrams read per serve_once call at most (the call returns after the first it answers):
# ArduPilot has at most one frame in flight, so the rest are a flood or strays; a batch costs
# about 0.4 ms of reads and comparisons (1.4 us a datagram on the project's machine).
MAX_BATCH = 256
# The receive buffer asked for [bytes] (net.core.rmem_max caps it for a user; Linux counts
# each small datagram at about 830 bytes of buffer, so the default 212 992 holds 256 of them,
# 2.6 ms of a 100k/s flood, and a frame arriving behind a full buffer is lost): 4 MiB hold
# about 5000, 50 ms of such a flood, longer than a scheduler's time slice.
RECV_BUFFER_BYTES = 4 * 1024 * 1024


class ServoPacketError(ValueError):
    """A datagram that is not an ArduPilot JSON servo packet; one line.

    ``reason`` is "length" or "magic" (the key of :attr:`ServerStats.by_reason`).
    """

    def __init__(self, message: str, reason: str) -> None:
        super().__init__(message)
        self.reason = reason


class ServoPacket(NamedTuple):
    """One ArduPilot SITL output frame (a named tuple: built once per frame, a frozen
    dataclass's ``object.__setattr__`` per field cost 1.5 µs more).

    frame_rate_hz: ArduPilot's physics rate request [Hz] (SIM_RATE_HZ).
    frame_count: ArduPilot's frame counter (uint32).
    pwm_us: servo outputs [µs], channel 1 first; 16 or 32 values.
    """

    frame_rate_hz: int
    frame_count: int
    pwm_us: tuple[int, ...]


def instance_port(instance: int = 0) -> int:
    """The UDP port ArduPilot SITL instance ``instance`` (its ``-I``) sends servos to."""
    if not is_whole(instance) or instance < 0:
        raise ValueError(f"SITL instance must be an integer >= 0, got {instance!r}")
    port = BASE_PORT + PORT_STEP_PER_INSTANCE * instance
    if port > 65535:
        raise ValueError(f"SITL instance {instance} gives port {port} > 65535")
    return port


def _wrapped(last: int, count: int) -> bool:
    """Whether frame ``count`` after ``last`` (both uint32) is the counter's wrap: ``last``
    within :data:`FRAME_WRAP_WINDOW` of 2³² and ``count`` below it."""
    return last >= FRAME_COUNT_MODULUS - FRAME_WRAP_WINDOW and count < FRAME_WRAP_WINDOW


def _frame_count(data: bytes) -> int | None:
    """The frame count of a servo datagram, None if it is not one."""
    try:
        return parse_servo_packet(data).frame_count
    except ServoPacketError:
        return None


def parse_servo_packet(data: bytes) -> ServoPacket:
    """Decode one servo datagram; ServoPacketError (one line) for anything else."""
    if len(data) == SERVO_16.size:
        fields, magic_expected = SERVO_16.unpack(data), MAGIC_16
    elif len(data) == SERVO_32.size:
        fields, magic_expected = SERVO_32.unpack(data), MAGIC_32
    else:
        raise ServoPacketError(
            f"servo packet of {len(data)} bytes (expected {SERVO_16.size} or {SERVO_32.size})",
            "length")
    magic, rate_hz, frame_count = fields[0], fields[1], fields[2]
    if magic != magic_expected:
        raise ServoPacketError(
            f"servo packet of {len(data)} bytes with magic {magic} (expected {magic_expected})",
            "magic")
    return ServoPacket(rate_hz, frame_count, fields[3:])  # (a tuple already)


class JsonPhysics(Protocol):
    """What the lock-step server drives: one :meth:`step` per new ArduPilot frame."""

    def reset(self) -> None:
        """Back to the initial state (ArduPilot SITL restarted); timestamp back to its start."""

    def step(self, pwm_us: tuple[int, ...], frame_rate_hz: int) -> None:
        """Advance one frame with these servo outputs [µs, channel 1 first] at ArduPilot's
        frame rate ``frame_rate_hz`` [Hz] (the physics decides how far: the reply's
        timestamp says it)."""

    def state(self) -> JsonState:
        """The state after the last step (or reset)."""


# What the server did with a frame (FrameRecord.action).
STEP = "step"
RESEND = "resend"
RESET = "reset"  # physics reset, then the frame stepped


class FrameRecord(NamedTuple):
    """One answered servo frame, for logs (the ``on_frame`` callback; a named tuple, built
    once per frame).

    action: STEP, RESEND (same reply again, no step) or RESET (reset, then the frame stepped).
    timestamp_s: physics time of the state sent [s].
    source: (host, port) the packet came from and the reply went to.
    """

    frame_count: int
    frame_rate_hz: int
    pwm_us: tuple[int, ...]
    action: str
    timestamp_s: float
    source: tuple[str, int]


@dataclass
class ServerStats:
    """Counters of the lock-step server."""

    steps: int = 0  # frames stepped (physics.step calls: new frames, also after a reset)
    resends: int = 0  # repeated frame_count answered again without a step
    resets: int = 0  # the peer restarted (frame 0 again, or re-bound): physics reset
    frames_skipped: int = 0  # frame numbers jumped over (never stepped)
    rejected: int = 0  # datagrams that were not servo packets (not answered)
    last_error: str = ""  # the last rejection's reason
    received: int = 0  # datagrams read
    by_reason: dict[str, int] = field(default_factory=dict)
    foreign: int = 0  # servo packets from another source than the peer (ignored)
    first_foreign: tuple[str, int] | None = None  # the source of the first of them
    stale: int = 0  # the peer's packets with a smaller frame_count other than 0 (ignored)
    rebinds: int = 0  # new ArduPilot processes bound after the peer's silence (physics reset)
    strays: int = 0  # bound senders that never lock-stepped, replaced after their silence
    recv_buffer_bytes: int = 0  # the socket's receive buffer the kernel granted [bytes]
    blocked: int = 0  # flooding sources blocked in the kernel (links/udp_guard.py)
    connected_wall_s: float = 0.0  # wall time while a peer was connected [s] (module doc)
    # the peer's re-sends of a frame that were queued before its reply was sent (module
    # docstring: Re-sends that crossed the reply): dropped, never answered
    crossed_resends: int = 0


class LockstepServer:
    """ArduPilot's JSON physics peer over one UDP socket: one physics.step and one reply per frame.

    Binds ``host:port`` (default 127.0.0.1 and :func:`instance_port` of ``instance``; port 0
    picks a free port, see :attr:`address`) and replies to the peer (module docstring: the
    source check). The physics is not reset at start: the first frame, whatever its count,
    is stepped from the state it is in. Exceptions of the physics (a range check of the
    co-simulation, say) propagate to the caller of :meth:`serve_once` / :meth:`serve`; bad
    datagrams never do.

    ``on_event(level, text)``: what the session should report (foxglove.Log level names:
    INFO, WARNING): the first foreign packet and their count, a restart of the peer.
    ``clock``: the wall clock [s] (monotonic; a test passes its own).
    """

    def __init__(self, physics: JsonPhysics, *, host: str = DEFAULT_HOST,
                 port: int | None = None, instance: int = 0,
                 on_frame: Callable[[FrameRecord], None] | None = None,
                 on_event: Callable[[str, str], None] | None = None,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.physics = physics
        self.on_frame = on_frame
        self.on_event = on_event
        self._clock = clock
        self.stats = ServerStats()
        self.peer: tuple[str, int] | None = None  # the bound ArduPilot (address, port)
        self._peer_first: int | None = None  # the bound sender's first frame count
        self._lockstepped = False  # the bound sender sent a later frame after our reply
        self._peer_packets = 0  # servo packets of the bound sender
        self._next_foreign_report = 10  # the foreign count of the next WARNING
        self._peer_wall_s: float | None = None  # wall time of the peer's last frame [s]
        self._peer_reply_s = -math.inf  # wall time the last frame was answered [s]
        self.last_frame_count: int | None = None
        self._last_reply: bytes | None = None
        self._last_time_s = math.nan
        self._held: tuple[bytes, tuple[str, int]] | None = None  # read, not yet handled
        bind_port = instance_port(instance) if port is None else port
        if not 0 <= bind_port <= 65535:
            raise ValueError(f"UDP port must be in 0..65535, got {bind_port}")
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            self._sock.bind((host, bind_port))
        except OSError as exc:
            self._sock.close()
            raise ValueError(f"cannot bind UDP {host}:{bind_port}: {exc.strerror}") from None
        self._sock.setblocking(False)
        try:  # a flood waits in the buffer (module docstring: Reads)
            self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, RECV_BUFFER_BYTES)
        except OSError:  # a system that refuses the size keeps its default
            pass
        self.stats.recv_buffer_bytes = self._sock.getsockopt(socket.SOL_SOCKET,
                                                             socket.SO_RCVBUF)
        self.guard = FloodGuard(self._sock)

    @property
    def address(self) -> tuple[str, int]:
        """(host, port) the server listens on."""
        return self._sock.getsockname()

    def close(self) -> None:
        self._sock.close()

    def __enter__(self) -> LockstepServer:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def _reject(self, reason: str, detail: str) -> None:
        self.stats.rejected += 1
        self.stats.by_reason[reason] = self.stats.by_reason.get(reason, 0) + 1
        self.stats.last_error = detail

    def _event(self, level: str, text: str) -> None:
        if self.on_event is not None:
            self.on_event(level, text)

    def _foreign(self, source: tuple[str, int]) -> None:
        st = self.stats
        st.foreign += 1
        if st.first_foreign is None or st.foreign == self._next_foreign_report:
            self._report_foreign(source)

    def _report_foreign(self, source: tuple[str, int]) -> None:
        """The WARNING of the first foreign packet, and of the 10th, 100th, 1000th ..."""
        st = self.stats
        if st.first_foreign is None:
            st.first_foreign = source
            self._event("WARNING", f"ignored a packet from {source[0]}:{source[1]}: the "
                        f"session is bound to ArduPilot at {self.peer[0]}:{self.peer[1]}; "
                        "packets from other sources are counted, never answered, until it "
                        f"has been silent for {PEER_SILENCE_S:g} s (then a new ArduPilot's "
                        "frame 0 is bound)")
        elif st.foreign == self._next_foreign_report:  # 10, 100, 1000 ...: a flood says little
            self._next_foreign_report *= 10
            self._event("WARNING", f"{st.foreign} packets from other sources than "
                        f"{self.peer[0]}:{self.peer[1]} ignored so far")

    def _bind(self, source: tuple[str, int], frame_count: int) -> None:
        self.peer = source
        self._peer_first = frame_count
        self._lockstepped = False
        self._peer_packets = 0
        self._peer_wall_s = None

    def _takeover(self, source: tuple[str, int], packet: ServoPacket,
                  now: float) -> str | None:
        """A packet from another source while the peer has been silent for PEER_SILENCE_S:
        the restart text if it takes the session over (module docstring: Binding), "" if
        it does without a reset, None if it stays foreign."""
        old = self.peer
        silence = now - self._peer_reply_s
        if not self._lockstepped:
            self.stats.strays += 1
            self._event("WARNING", f"bound to {source[0]}:{source[1]} (frame "
                        f"{packet.frame_count}) instead of {old[0]}:{old[1]}, silent for "
                        f"{silence:.1f} s: it sent {self._peer_packets} packet(s) of frame "
                        f"{self._peer_first} and never lock-stepped (a stray packet, not "
                        "ArduPilot); nothing is reset")
            self._bind(source, packet.frame_count)
            self.last_frame_count = None
            return ""
        if packet.frame_count != 0:
            return None
        how = "restarted on a new port" if source[0] == old[0] else "a new ArduPilot"
        self.stats.rebinds += 1
        self._bind(source, packet.frame_count)
        return (f"ArduPilot at {source[0]}:{source[1]} ({how}: frame 0 after {silence:.1f} s "
                f"of silence of {old[0]}:{old[1]}); bound to it, physics reset")

    def _restart(self, text: str) -> None:
        self.stats.resets += 1
        self._event("WARNING", text)
        self.physics.reset()

    def handle(self, data: bytes, source: tuple[str, int] = ("", 0),
               now_s: float | None = None) -> bytes | None:
        """Apply the source check and the lock-step rules to one datagram (arrived at wall
        time ``now_s`` [s], default the clock); the reply to send, or None (rejected,
        foreign or stale: not answered)."""
        now = self._clock() if now_s is None else now_s
        source = (str(source[0]), int(source[1]))
        peer = self.peer
        if peer is not None and source != peer and now - self._peer_reply_s < PEER_SILENCE_S:
            self._foreign(source)  # dropped by its address, never parsed
            return None
        try:
            packet = parse_servo_packet(data)
        except ServoPacketError as exc:
            self._reject(exc.reason, str(exc))
            return None
        count = packet.frame_count
        last = self.last_frame_count
        restart = ""
        if peer is None:
            self._bind(source, count)
            self._event("INFO", f"bound to ArduPilot at {source[0]}:{source[1]} (frame "
                        f"{count}); other sources are ignored while it is not silent")
        elif source != peer:
            restart = self._takeover(source, packet, now)
            if restart is None:
                self._foreign(source)
                return None
            last = self.last_frame_count
        elif last is not None and count < last and not _wrapped(last, count):
            if count != 0:
                self.stats.stale += 1
                return None
            restart = (f"ArduPilot restarted: frame 0 after frame {last} from "
                       f"{source[0]}:{source[1]}; physics reset")
        self._peer_packets += 1
        if self._peer_wall_s is not None and now - self._peer_reply_s < PEER_SILENCE_S:
            self.stats.connected_wall_s += now - self._peer_wall_s
        self._peer_wall_s = now
        if not restart and last is not None and packet.frame_count == last \
                and self._last_reply is not None:
            action = RESEND
            self.stats.resends += 1
            reply = self._last_reply
        else:
            action = STEP
            if restart:
                action = RESET
                self._restart(restart)
                self._peer_first = count
                self._lockstepped = False
            elif last is not None:
                gap = (count - last) % FRAME_COUNT_MODULUS  # the wrap included
                self.stats.frames_skipped += gap - 1
                self._lockstepped = True
            self.physics.step(packet.pwm_us, packet.frame_rate_hz)
            self.stats.steps += 1
            state = self.physics.state()
            reply = encode_reply(state)
            self._last_reply = reply
            self._last_time_s = state.timestamp_s
            self.last_frame_count = count
        if self.on_frame is not None:
            self.on_frame(FrameRecord(
                frame_count=packet.frame_count, frame_rate_hz=packet.frame_rate_hz,
                pwm_us=packet.pwm_us, action=action, timestamp_s=self._last_time_s,
                source=source))
        self._peer_reply_s = self._clock()  # the peer waits from here: its silence
        return reply

    def serve_once(self, timeout_s: float | None = None) -> bool:
        """Wait up to ``timeout_s`` [s] (None: forever) for datagrams, then read at most
        :data:`MAX_BATCH` of them, up to and including the first one answered; after the
        answer, the peer's re-sends of the answered frame already queued are dropped
        (module docstring: Re-sends that crossed the reply).

        True if a datagram was read (answered, rejected or ignored), False on timeout.
        """
        if timeout_s is not None and timeout_s < 0:
            raise ValueError(f"timeout_s must be >= 0 or None, got {timeout_s}")
        held = self._held
        if held is None:
            readable, _, _ = select.select([self._sock], [], [], timeout_s)
            if not readable:
                return False
        sock, stats, clock, peer = self._sock, self.stats, self._clock, self.peer
        recvfrom, count = sock.recvfrom, self.guard.count
        # the peer's silence, once a batch: 3 s against a batch's 0.4 ms at most
        guarded = peer is not None and clock() - self._peer_reply_s < PEER_SILENCE_S
        for _ in range(MAX_BATCH):
            if held is not None:
                (data, source), held, self._held = held, None, None
            else:
                try:
                    data, source = recvfrom(RECV_BYTES)
                except BlockingIOError:
                    break
                stats.received += 1
            if guarded and source != peer:  # handle's first test, inline: a flood's path
                count(source)
                stats.foreign += 1
                if stats.foreign == self._next_foreign_report or stats.first_foreign is None:
                    self._report_foreign(source)
                continue
            if source != peer or not self._lockstepped:
                count(source)  # a stray that floods is blocked too; ArduPilot never
            reply = self.handle(data, source, clock())
            if reply is not None:
                try:
                    sock.sendto(reply, source)
                except BlockingIOError:
                    pass  # ArduPilot re-sends the frame after 1 s; it is answered then
                self._drop_crossed(source)
                break
        self._guard_check()
        return True

    def _drop_crossed(self, source: tuple[str, int]) -> None:
        """Right after a reply to ``source``: read what is queued; the re-sends of the frame
        just answered arrived before the reply was sent (ArduPilot sent them while it
        waited for it), so they are counted and dropped; the first other datagram is held
        for the next :meth:`serve_once`."""
        last = self.last_frame_count
        for _ in range(MAX_BATCH):
            try:
                data, src = self._sock.recvfrom(RECV_BYTES)
            except BlockingIOError:
                return
            self.stats.received += 1
            if src == source and last is not None and _frame_count(data) == last:
                self.stats.crossed_resends += 1
                continue
            self._held = (data, src)
            return

    def _guard_check(self) -> None:
        """Block the sources that flood (never the lock-stepping peer); say so."""
        blocked, _ = self.guard.check(self._clock(), self.peer if self._lockstepped else None)
        for host, port in blocked:
            self.stats.blocked += 1
            self._event("WARNING", f"{host}:{port} sends more than {FLOOD_RATE_PER_S:g} "
                        f"packets/s: dropped by the kernel for {BLOCK_S:g} s (not counted "
                        "meanwhile)")

    def silence_s(self) -> float | None:
        """Wall time since the bound peer's last frame was answered [s] (None: no peer)."""
        return None if self.peer is None else self._clock() - self._peer_reply_s

    def serve(self, should_stop: Callable[[], bool] | None = None,
              poll_s: float = 0.1) -> None:
        """Answer datagrams until ``should_stop()`` is true (checked every ``poll_s`` [s] of
        idle time and after each datagram)."""
        if poll_s <= 0:
            raise ValueError(f"poll_s must be > 0, got {poll_s}")
        while should_stop is None or not should_stop():
            self.serve_once(poll_s)

