"""ArduPilot's JSON SITL interface: the simulator side of the protocol and a lock-step server.

ArduPilot SITL started with ``--model JSON:127.0.0.1`` flies a physics model it talks to over
UDP (``libraries/SITL/SIM_JSON.cpp`` and ``SIM_JSON.h`` of ArduPilot master 90700977c553;
``libraries/SITL/examples/JSON/readme.md``). This module is the physics side of that link,
without the physics: it imports neither JSBSim nor the co-simulation. A physics object that
satisfies :class:`JsonPhysics` is driven one ``step`` call per servo frame.

ArduPilot → simulator (:func:`parse_servo_packet`): one datagram per SITL frame, little
endian, to ``127.0.0.1:9002 + 10·instance`` (:func:`instance_port`):

* ``<HHI16H>`` (40 bytes): magic 18458, frame_rate [Hz] (ArduPilot's ``SIM_RATE_HZ``,
  default 1200), frame_count, 16 PWM values [µs];
* ``<HHI32H>`` (72 bytes, ArduPilot parameter ``SERVO_32_ENABLE = 1``): magic 29569, the
  same with 32 PWM values.

Any other datagram is rejected (:class:`ServoPacketError`, counted in
:class:`ServerStats`) and never answered.

Simulator → ArduPilot (:func:`encode_reply`): ``"\\n" + one line of JSON + "\\n"`` to the
datagram's source. ArduPilot turns every ``\\n`` into NUL and parses the text between the
last two NULs; its parser (``JSON::parse_sensors``) looks each key up by substring and reads
the value exactly two characters after the key's first letter past its end (closing quote
and colon), so the JSON must be compact (separators ``","`` and ``":"``): a space after a
colon makes ``sscanf("[%f, %f, %f]")`` miss the ``[``. Key order here is fixed and no key
is a substring of an earlier one. Booleans would be read with ``strtoull`` (``true`` reads as
0), so none are sent. Non-finite numbers are refused (``json`` would write ``NaN``).

Fields (:class:`JsonState`, SI, converted by the physics object, not here):

================ ============================================================================
``timestamp``    physics time [s] (double in ArduPilot; its clock advances by its change)
``imu.gyro``     body angular rate (p, q, r) [rad/s], body FRD
``imu.accel_body`` specific force (accelerometer) [m/s²], body FRD; ≈ (0, 0, −9.81) level at
                 rest
``position``     position from home (north, east, down) [m], NED (double in ArduPilot)
``quaternion``   attitude (w, x, y, z), rotates body FRD vectors into NED; used if present
``attitude``     (roll, pitch, yaw) [rad], 3-2-1 Euler angles body FRD against NED
``velocity``     velocity over ground (north, east, down) [m/s], NED
``airspeed``     optional: true airspeed [m/s]; without it ArduPilot computes it from
                 ``velocity`` with zero wind
================ ============================================================================

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
  re-sends it every second until it is answered.

Source check (the peer): the session binds to the source (address, port) of the first
servo packet. Servo packets from any other source are counted (``foreign``), reported to
``on_event`` (the first one, then at 10, 100, 1000 ... of them), never answered and never
stepped, so a stray packet or a second sender cannot reset or advance the flight. The one
exception is ArduPilot restarted as a new process: SITL's socket is not bound, so the new
process sends from the same address with a new ephemeral port. A packet from the peer's
address with frame_count 0, after the peer has been silent for at least
:data:`PEER_SILENCE_S` of wall time, re-binds the session to the new port and resets the
physics (a live ArduPilot is never silent that long: it re-sends its frame every second).

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
:mod:`bioflex_jsb.links.ardupilot_rate`). frame_count
is ArduPilot's uint32 and would wrap after 2³² frames (41 days at 1200 Hz); a wrap would be
taken for a restart.
"""

from __future__ import annotations

import json
import math
import select
import socket
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import NamedTuple, Protocol

# SIM_JSON.h, servo_packet_16 / servo_packet_32: magic, frame_rate, frame_count, pwm[]
MAGIC_16 = 18458
MAGIC_32 = 29569
SERVO_16 = struct.Struct("<HHI16H")
SERVO_32 = struct.Struct("<HHI32H")
# SIM_JSON.h, control_port = 9002; SITL adds 10 per instance (-I): 9002, 9012, ...
BASE_PORT = 9002
PORT_STEP_PER_INSTANCE = 10
DEFAULT_HOST = "127.0.0.1"
# SIM_JSON.h: sensor_buffer[65000] holds the replies; one reply must fit with room to spare.
MAX_REPLY_BYTES = 32000
RECV_BYTES = 512  # larger datagrams are truncated and then rejected by their length
QUATERNION_NORM_TOLERANCE = 1e-3  # ArduPilot's rotation_matrix assumes a unit quaternion
# DEFINITION: the peer is taken for gone (killed, stopped) after this much wall time without a
# frame [s]: three of ArduPilot's 1 s re-send intervals (JSON::recv_fdm re-sends the frame
# after 1 s without a reply), so a live ArduPilot, however slow its host, never reaches it.
PEER_SILENCE_S = 3.0


class ServoPacketError(ValueError):
    """A datagram that is not an ArduPilot JSON servo packet; one line.

    ``reason`` is "length" or "magic" (the key of :attr:`ServerStats.by_reason`).
    """

    def __init__(self, message: str, reason: str) -> None:
        super().__init__(message)
        self.reason = reason


class JsonStateError(ValueError):
    """A physics state that cannot be sent to ArduPilot; one line."""


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
    if isinstance(instance, bool) or not isinstance(instance, int) or instance < 0:
        raise ValueError(f"SITL instance must be an integer >= 0, got {instance!r}")
    port = BASE_PORT + PORT_STEP_PER_INSTANCE * instance
    if port > 65535:
        raise ValueError(f"SITL instance {instance} gives port {port} > 65535")
    return port


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


def _vector(name: str, value, length: int) -> tuple[float, ...]:
    """``value`` as a tuple of ``length`` floats (finiteness: :meth:`JsonState._check`)."""
    try:
        out = tuple(map(float, value))  # (map: a third of a generator's cost, per frame)
    except TypeError as exc:
        raise JsonStateError(f"{name} must be a sequence of {length} numbers: {exc}") from None
    if len(out) != length:
        raise JsonStateError(f"{name} must have {length} components, got {len(out)}")
    return out


_isfinite = math.isfinite
# The largest IEEE single-precision number: ArduPilot keeps every field but timestamp and
# position as a C float (SIM_JSON.h state: Vector3f, Quaternion, float)
FLT_MAX = 3.4028234663852886e38
_DOUBLE_FIELDS = ("timestamp_s", "position_ned_m")  # doubles in ArduPilot (SIM_JSON.h)


@dataclass(frozen=True)
class JsonState:
    """The state ArduPilot reads after one physics step (SI; frames as named).

    timestamp_s: physics time [s], ≥ 0, non-decreasing between resets.
    gyro_rad_s: body angular rate (p, q, r) [rad/s], body FRD.
    accel_body_m_s2: specific force (what an accelerometer reads: acceleration minus
        gravity) [m/s²], body FRD; (0, 0, −g) level at rest.
    position_ned_m: position from home (north, east, down) [m], NED.
    velocity_ned_m_s: velocity over ground (north, east, down) [m/s], NED.
    quaternion: attitude (w, x, y, z), unit, rotating body-FRD vectors into NED; or None.
    attitude_rad: (roll, pitch, yaw) [rad], 3-2-1 Euler angles of body FRD against NED; or
        None. At least one of quaternion and attitude_rad; ArduPilot uses the quaternion
        when both are sent.
    airspeed_m_s: true airspeed [m/s] or None (ArduPilot then derives it from the velocity
        with zero wind, which is wrong in a gust: send it).
    """

    timestamp_s: float
    gyro_rad_s: tuple[float, float, float]
    accel_body_m_s2: tuple[float, float, float]
    position_ned_m: tuple[float, float, float]
    velocity_ned_m_s: tuple[float, float, float]
    quaternion: tuple[float, float, float, float] | None = None
    attitude_rad: tuple[float, float, float] | None = None
    airspeed_m_s: float | None = None

    def __post_init__(self) -> None:
        quat, att, air = self.quaternion, self.attitude_rad, self.airspeed_m_s
        if quat is None and att is None:
            raise JsonStateError("JsonState needs a quaternion or attitude_rad (or both)")
        try:  # every number converted by one map (8 tuple(map(...)) cost 2.5 times more)
            lengths = (len(self.gyro_rad_s), len(self.accel_body_m_s2),
                       len(self.position_ned_m), len(self.velocity_ned_m_s),
                       4 if quat is None else len(quat), 3 if att is None else len(att))
            flat = tuple(map(float, (self.timestamp_s, *self.gyro_rad_s,
                                     *self.accel_body_m_s2, *self.position_ned_m,
                                     *self.velocity_ned_m_s, *(quat or ()), *(att or ()),
                                     *(() if air is None else (air,)))))
        except (TypeError, ValueError):
            lengths = ()
        if lengths != (3, 3, 3, 3, 4, 3):  # not numbers, or a wrong length: which one
            self._convert()
            return
        set_ = object.__setattr__
        set_(self, "timestamp_s", flat[0])
        set_(self, "gyro_rad_s", flat[1:4])
        set_(self, "accel_body_m_s2", flat[4:7])
        set_(self, "position_ned_m", flat[7:10])
        set_(self, "velocity_ned_m_s", flat[10:13])
        k = 13
        if quat is not None:
            set_(self, "quaternion", flat[13:17])
            k = 17
        if att is not None:
            set_(self, "attitude_rad", flat[k:k + 3])
        if air is not None:
            set_(self, "airspeed_m_s", flat[-1])
        self._validate()

    def _convert(self) -> None:
        """Each field converted on its own: the one-line error names the field."""
        for name, length in (("timestamp_s", 1), ("gyro_rad_s", 3), ("accel_body_m_s2", 3),
                             ("position_ned_m", 3), ("velocity_ned_m_s", 3),
                             ("quaternion", 4), ("attitude_rad", 3), ("airspeed_m_s", 1)):
            value = getattr(self, name)
            if value is None:
                continue
            if length == 1:
                (value,) = _vector(name, (value,), 1)
            else:
                value = _vector(name, value, length)
            object.__setattr__(self, name, value)
        self._validate()

    def _validate(self) -> None:
        t, pos = self.timestamp_s, self.position_ned_m
        floats = self.gyro_rad_s + self.accel_body_m_s2 + self.velocity_ned_m_s + (
            self.quaternion or ()) + (self.attitude_rad or ()) + (
            () if self.airspeed_m_s is None else (self.airspeed_m_s,))
        # one test of all the numbers (the sum is finite when every term is: a NaN or an
        # infinity makes it not; only doubles near 1e308 could overflow it), then the C
        # floats' range (their largest magnitude, meaningful once all are finite); the
        # field-by-field search (_check) only to name the culprit
        if not (_isfinite(t + sum(pos) + sum(floats)) and max(map(abs, floats)) <= FLT_MAX):
            self._check()
        if t < 0.0:
            raise JsonStateError(f"timestamp_s must be >= 0, got {t}")
        if self.quaternion is not None:
            w, x, y, z = self.quaternion
            norm = math.sqrt(w * w + x * x + y * y + z * z)
            if abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE:
                raise JsonStateError(f"quaternion must be a unit quaternion, |q| = {norm:.6g}")
        if self.airspeed_m_s is not None and self.airspeed_m_s < 0.0:
            raise JsonStateError(f"airspeed_m_s must be >= 0, got {self.airspeed_m_s}")

    def _check(self) -> None:
        """The field that is not finite, or a C float's beyond ±FLT_MAX (JsonStateError);
        a sum that only overflowed (doubles near 1e308) passes."""
        for name in ("timestamp_s", "gyro_rad_s", "accel_body_m_s2", "position_ned_m",
                     "velocity_ned_m_s", "quaternion", "attitude_rad", "airspeed_m_s"):
            value = getattr(self, name)
            if value is None:
                continue
            values = value if isinstance(value, tuple) else (value,)
            if not all(map(_isfinite, values)):
                raise JsonStateError(f"{name} must be finite, got {value}")
            if name not in _DOUBLE_FIELDS and max(map(abs, values)) > FLT_MAX:
                raise JsonStateError(f"{name} must be within +-{FLT_MAX:.8g} (a C float in "
                                     f"ArduPilot), got {value}")


def encode_reply(state: JsonState) -> bytes:
    """The datagram answering one servo frame: ``\\n`` + compact JSON + ``\\n`` (ASCII).

    Keys in this order: timestamp, imu (gyro, accel_body), position, quaternion, attitude,
    velocity, airspeed (the optional ones only when set), the document
    :func:`encode_reply_json` writes with ``json.dumps``; written by one %-format
    (:func:`_reply_layout`) with each number in the precision ArduPilot keeps it in:

    * ``timestamp`` and ``position`` (doubles in ArduPilot) as ``%.17g``: 17 significant
      digits, which read back (``atof``, ``sscanf``) to the very double sent;
    * every other field (C floats in ArduPilot) rounded to IEEE single precision here
      (``struct`` ``f``: round to nearest) and written ``%.9g``: 9 significant digits read
      back to that float exactly (``sscanf("%f")``, and ``atof`` then the cast: the nearest
      double of the text is far closer to the float than to a rounding midpoint), so
      ArduPilot holds float32(x), the correctly rounded value.

    ``json.dumps`` (``float.__repr__``, the shortest text of each double) cost 29.9 µs a
    reply in flight, ``%r`` in one format string 25-30 µs, this 6.8 µs (timeit, best of 5,
    the same machine and load; tests/test_ardupilot_json.py holds the numbers ArduPilot
    reads to the state's). Every number was checked finite, and the floats within ±FLT_MAX,
    by :class:`JsonState`: no ``inf``/``nan`` text can appear.
    """
    quat, att, air = state.quaternion, state.attitude_rad, state.airspeed_m_s
    fmt, singles = _reply_layout(quat is not None, att is not None, air is not None)
    f = singles.unpack(singles.pack(*state.gyro_rad_s, *state.accel_body_m_s2,
                                    *(quat or ()), *(att or ()), *state.velocity_ned_m_s,
                                    *(() if air is None else (air,))))
    data = (fmt % (state.timestamp_s, *f[:6], *state.position_ned_m, *f[6:])).encode("ascii")
    if len(data) > MAX_REPLY_BYTES:  # cannot happen with the fixed fields above
        raise JsonStateError(f"reply of {len(data)} bytes exceeds {MAX_REPLY_BYTES}")
    return data


DOUBLE_FORMAT = "%.17g"  # round-trips any double (DBL_DECIMAL_DIG)
FLOAT_FORMAT = "%.9g"  # round-trips any single (FLT_DECIMAL_DIG)
_LAYOUTS: dict[tuple[bool, bool, bool], tuple[str, struct.Struct]] = {}


def _reply_layout(quaternion: bool, attitude: bool, airspeed: bool
                  ) -> tuple[str, struct.Struct]:
    """The reply's %-format for the optional fields present and the ``struct`` that rounds
    its C floats (gyro, accel_body, quaternion, attitude, velocity, airspeed, in that order)
    to single precision; built once per combination."""
    key = (quaternion, attitude, airspeed)
    if key not in _LAYOUTS:
        def vec(n: int, spec: str = FLOAT_FORMAT) -> str:
            return "[" + ",".join([spec] * n) + "]"

        text = ('\n{"timestamp":' + DOUBLE_FORMAT + ',"imu":{"gyro":' + vec(3)
                + ',"accel_body":' + vec(3) + '},"position":' + vec(3, DOUBLE_FORMAT))
        n = 9
        if quaternion:
            text += ',"quaternion":' + vec(4)
            n += 4
        if attitude:
            text += ',"attitude":' + vec(3)
            n += 3
        text += ',"velocity":' + vec(3)
        if airspeed:
            text += ',"airspeed":' + FLOAT_FORMAT
            n += 1
        _LAYOUTS[key] = (text + "}\n", struct.Struct(f"<{n}f"))
    return _LAYOUTS[key]


def encode_reply_json(state: JsonState) -> bytes:
    """The reply's document through ``json.dumps`` (the shortest text of each double, no
    rounding to single precision): the reference :func:`encode_reply`'s keys, layout and
    numbers are held to (tests/test_ardupilot_json.py)."""
    doc: dict[str, object] = {
        "timestamp": state.timestamp_s,
        "imu": {"gyro": list(state.gyro_rad_s), "accel_body": list(state.accel_body_m_s2)},
        "position": list(state.position_ned_m),
    }
    if state.quaternion is not None:
        doc["quaternion"] = list(state.quaternion)
    if state.attitude_rad is not None:
        doc["attitude"] = list(state.attitude_rad)
    doc["velocity"] = list(state.velocity_ned_m_s)
    if state.airspeed_m_s is not None:
        doc["airspeed"] = state.airspeed_m_s
    text = json.dumps(doc, separators=(",", ":"), allow_nan=False)
    data = ("\n" + text + "\n").encode("ascii")
    if len(data) > MAX_REPLY_BYTES:  # cannot happen with the fixed fields above
        raise JsonStateError(f"reply of {len(data)} bytes exceeds {MAX_REPLY_BYTES}")
    return data


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
    rebinds: int = 0  # of them, restarts as a new process (same address, new port)
    connected_wall_s: float = 0.0  # wall time while a peer was connected [s] (module doc)


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
        self._peer_wall_s: float | None = None  # wall time of the peer's last frame [s]
        self._peer_reply_s = -math.inf  # wall time the last frame was answered [s]
        self.last_frame_count: int | None = None
        self._last_reply: bytes | None = None
        self._last_time_s = math.nan
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
        if st.first_foreign is None:
            st.first_foreign = source
            self._event("WARNING", f"ignored a servo packet from {source[0]}:{source[1]}: the "
                        f"session is bound to ArduPilot at {self.peer[0]}:{self.peer[1]}; "
                        "packets from other sources are counted, never answered")
        elif math.log10(st.foreign).is_integer():
            self._event("WARNING", f"{st.foreign} servo packets from other sources than "
                        f"{self.peer[0]}:{self.peer[1]} ignored so far")

    def _restart(self, text: str) -> None:
        self.stats.resets += 1
        self._event("WARNING", text)
        self.physics.reset()

    def handle(self, data: bytes, source: tuple[str, int] = ("", 0),
               now_s: float | None = None) -> bytes | None:
        """Apply the source check and the lock-step rules to one datagram (arrived at wall
        time ``now_s`` [s], default the clock); the reply to send, or None (rejected,
        foreign or stale: not answered)."""
        try:
            packet = parse_servo_packet(data)
        except ServoPacketError as exc:
            self._reject(exc.reason, str(exc))
            return None
        now = self._clock() if now_s is None else now_s
        source = (str(source[0]), int(source[1]))
        last = self.last_frame_count
        restart = ""
        if self.peer is None:
            self.peer = source
            self._event("INFO", f"bound to ArduPilot at {source[0]}:{source[1]} (frame "
                        f"{packet.frame_count}); other sources are ignored")
        elif source != self.peer:
            silent = now - self._peer_reply_s >= PEER_SILENCE_S
            if source[0] == self.peer[0] and packet.frame_count == 0 and silent:
                restart = (f"ArduPilot restarted: frame 0 from {source[0]}:{source[1]} after "
                           f"{now - self._peer_reply_s:.1f} s of silence of "
                           f"{self.peer[0]}:{self.peer[1]}; bound to the new port, physics "
                           "reset")
                self.stats.rebinds += 1
                self.peer = source
                self._peer_wall_s = None
                last = None
            else:
                self._foreign(source)
                return None
        elif last is not None and packet.frame_count < last:
            if packet.frame_count != 0:
                self.stats.stale += 1
                return None
            restart = (f"ArduPilot restarted: frame 0 after frame {last} from "
                       f"{source[0]}:{source[1]}; physics reset")
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
            elif last is not None and packet.frame_count > last + 1:
                self.stats.frames_skipped += packet.frame_count - last - 1
            self.physics.step(packet.pwm_us, packet.frame_rate_hz)
            self.stats.steps += 1
            state = self.physics.state()
            reply = encode_reply(state)
            self._last_reply = reply
            self._last_time_s = state.timestamp_s
            self.last_frame_count = packet.frame_count
        if self.on_frame is not None:
            self.on_frame(FrameRecord(
                frame_count=packet.frame_count, frame_rate_hz=packet.frame_rate_hz,
                pwm_us=packet.pwm_us, action=action, timestamp_s=self._last_time_s,
                source=source))
        self._peer_reply_s = self._clock()  # the peer waits from here: its silence
        return reply

    def serve_once(self, timeout_s: float | None = None) -> bool:
        """Wait up to ``timeout_s`` [s] (None: forever) for one datagram and answer it.

        True if a datagram was read (answered or rejected), False on timeout.
        """
        if timeout_s is not None and timeout_s < 0:
            raise ValueError(f"timeout_s must be >= 0 or None, got {timeout_s}")
        readable, _, _ = select.select([self._sock], [], [], timeout_s)
        if not readable:
            return False
        try:
            data, source = self._sock.recvfrom(RECV_BYTES)
        except BlockingIOError:
            return False
        self.stats.received += 1
        reply = self.handle(data, source, self._clock())
        if reply is not None:
            try:
                self._sock.sendto(reply, source)
            except BlockingIOError:
                pass  # ArduPilot re-sends the frame after 1 s; it is answered then
        return True

    def serve(self, should_stop: Callable[[], bool] | None = None,
              poll_s: float = 0.1) -> None:
        """Answer datagrams until ``should_stop()`` is true (checked every ``poll_s`` [s] of
        idle time and after each datagram)."""
        if poll_s <= 0:
            raise ValueError(f"poll_s must be > 0, got {poll_s}")
        while should_stop is None or not should_stop():
            self.serve_once(poll_s)

