"""A stand-in for ArduPilot SITL's side of the JSON physics interface, for tests without ArduPilot.

It is written from ArduPilot master 90700977c553, ``libraries/SITL/SIM_JSON.cpp`` and
``SIM_JSON.h`` (``JSON::output_servos``, ``JSON::recv_fdm``, ``JSON::parse_sensors``), and
deliberately shares no code with :mod:`bioflex_jsb.links.ardupilot_json`:

* servo packets: little-endian ``<HHI16H>`` (magic 18458) or ``<HHI32H>`` (magic 29569):
  magic, frame_rate [Hz], frame_count, PWM [µs];
* ``frame_counter`` advances only when a reply was parsed (``recv_fdm`` ends with
  ``frame_counter++`` after a successful parse; every early return leaves it);
* receive buffer: every ``\\n`` of a datagram becomes NUL; the line parsed is the text
  between the last two NULs of the buffer; the buffer then keeps its tail from the last NUL;
* ``parse_sensors``: for each key of the key table, ``strstr`` for the section (the empty
  section matches at the start), skip ``strlen(section) + 1``; ``strstr`` for the key, skip
  ``strlen(key) + 2`` (closing quote and colon: exactly two characters); then ``atof``,
  ``strtoull`` or ``sscanf("[%f, %f, %f]")``. A required key missing, or a vector that does
  not scan, ends the parse (a missing required key returns no fields at all);
* the clock: ``time_now_us += Δtimestamp·10⁶``; a timestamp that goes backwards is a
  "physics reset" (Δ = 0).

Floats (``Vector3f``, ``Quaternion``, ``float``) are rounded to IEEE single precision as
ArduPilot stores them; ``timestamp`` and ``position`` are doubles there.
"""

from __future__ import annotations

import math
import re
import select
import socket
import struct
from dataclasses import dataclass, field

MAGIC_16 = 18458  # SIM_JSON.h servo_packet_16
MAGIC_32 = 29569  # SIM_JSON.h servo_packet_32
DEFAULT_TIMEOUT_S = 5.0  # generous: only a broken server ever waits this long

# SIM_JSON.h keytable: (section, key, type, required), in ArduPilot's order; the bit of a key
# in the received bitmask is its index here.
KEYTABLE = (
    ("", "timestamp", "double", True),
    ("imu", "gyro", "vector3f", True),
    ("imu", "accel_body", "vector3f", True),
    ("", "position", "vector3d", True),
    ("", "attitude", "vector3f", False),
    ("", "quaternion", "quaternion", False),
    ("", "velocity", "vector3f", True),
    ("", "rng_1", "float", False),
    ("", "rng_2", "float", False),
    ("", "rng_3", "float", False),
    ("", "rng_4", "float", False),
    ("", "rng_5", "float", False),
    ("", "rng_6", "float", False),
    ("windvane", "direction", "float", False),
    ("windvane", "speed", "float", False),
    ("", "airspeed", "float", False),
    ("", "no_time_sync", "boolean", False),
)
EULER_ATT = 1 << 4
QUAT_ATT = 1 << 5

# A C floating-point number as strtod reads it (decimal, infinity, nan; no hex needed here).
_C_FLOAT = re.compile(rb"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)",
                      re.IGNORECASE)
_C_SPACE = b" \t\n\v\f\r"


def _single(x: float) -> float:
    """x rounded to IEEE single precision (a C ``float``)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def _skip_space(text: bytes, i: int) -> int:
    while i < len(text) and text[i] in _C_SPACE:
        i += 1
    return i


def c_atof(text: bytes) -> float:
    """C ``atof``: leading white space skipped, the longest number prefix, 0.0 if none."""
    m = _C_FLOAT.match(text, _skip_space(text, 0))
    return float(m.group()) if m else 0.0


def c_strtoull(text: bytes) -> int:
    """C ``strtoull(p, nullptr, 10)``: white space, optional sign, decimal digits; 0 if none."""
    m = re.compile(rb"[+-]?\d+").match(text, _skip_space(text, 0))
    return int(m.group()) if m else 0


def c_sscanf_floats(text: bytes, count: int) -> list[float]:
    """C ``sscanf(p, "[%f, %f, ...]")`` with ``count`` conversions: the numbers scanned
    before the first mismatch (the caller checks that there are ``count``).

    The format's ``[`` and ``,`` are ordinary characters and must match the input exactly
    (no white space skipped before them); the blank after each comma matches any white space,
    none included; each ``%f`` skips white space first.
    """
    values: list[float] = []
    i = 0
    if not text[i:i + 1] == b"[":
        return values
    i += 1
    for n in range(count):
        if n > 0:
            if text[i:i + 1] != b",":
                return values
            i = _skip_space(text, i + 1)
        m = _C_FLOAT.match(text, _skip_space(text, i))
        if not m:
            return values
        values.append(float(m.group()))
        i = m.end()
    return values


@dataclass
class Parsed:
    """What ``parse_sensors`` stored, by key name, and its bitmask (0: not usable)."""

    bitmask: int = 0
    values: dict[str, object] = field(default_factory=dict)
    message: str = ""


def parse_sensors(line: bytes) -> Parsed:
    """ArduPilot's ``JSON::parse_sensors`` on one NUL-free line."""
    out = Parsed()
    for bit, (section, key, kind, required) in enumerate(KEYTABLE):
        p = line.find(section.encode())
        if p < 0:
            if required:
                return Parsed(message=f"Failed to find {section}")
            continue
        p += len(section) + 1
        q = line.find(key.encode(), p)
        if q < 0:
            if required:
                return Parsed(message=f"Failed to find key {section}/{key}")
            continue
        out.bitmask |= 1 << bit
        rest = line[q + len(key) + 2:]
        if kind == "double":
            out.values[key] = c_atof(rest)
        elif kind == "float":
            out.values[key] = _single(c_atof(rest))
        elif kind == "boolean":
            out.values[key] = c_strtoull(rest) != 0
        else:
            n = 4 if kind == "quaternion" else 3
            got = c_sscanf_floats(rest, n)
            if len(got) != n:
                out.message = f"Failed to parse {kind} for {section}/{key}"
                return out
            out.values[key] = tuple(got) if kind == "vector3d" else tuple(_single(v) for v in got)
    return out


def dcm_from_quaternion(q: tuple[float, ...]) -> list[list[float]]:
    """ArduPilot's ``Quaternion::rotation_matrix``: q = (q1, q2, q3, q4) = (w, x, y, z), the
    matrix rotating body vectors into the earth (NED) frame."""
    q1, q2, q3, q4 = q
    return [
        [1 - 2 * (q3 * q3 + q4 * q4), 2 * (q2 * q3 - q1 * q4), 2 * (q2 * q4 + q1 * q3)],
        [2 * (q2 * q3 + q1 * q4), 1 - 2 * (q2 * q2 + q4 * q4), 2 * (q3 * q4 - q1 * q2)],
        [2 * (q2 * q4 - q1 * q3), 2 * (q3 * q4 + q1 * q2), 1 - 2 * (q2 * q2 + q3 * q3)],
    ]


def dcm_from_euler(roll: float, pitch: float, yaw: float) -> list[list[float]]:
    """ArduPilot's ``Matrix3::from_euler`` (3-2-1 rotation, body → earth)."""
    cr, sr = math.cos(roll), math.sin(roll)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    return [
        [cp * cy, sr * sp * cy - cr * sy, cr * sp * cy + sr * sy],
        [cp * sy, sr * sp * sy + cr * cy, cr * sp * sy - sr * cy],
        [-sp, sr * cp, cr * cp],
    ]


def dcm_of(parsed: Parsed) -> list[list[float]]:
    """Body → NED rotation ArduPilot builds: from the quaternion if sent, else Euler."""
    if parsed.bitmask & QUAT_ATT:
        return dcm_from_quaternion(parsed.values["quaternion"])
    return dcm_from_euler(*parsed.values["attitude"])


class ArduPilotStandin:
    """ArduPilot SITL's JSON backend, network side: send servos, read and parse replies.

    ``target``: (host, port) of the physics server. ``channels``: 16 or 32 (SERVO_32_ENABLE).
    ``rate_hz``: the frame_rate field (SIM_RATE_HZ; ArduPilot's default 1200).
    """

    def __init__(self, target: tuple[str, int], channels: int = 16, rate_hz: int = 1200,
                 timeout_s: float = DEFAULT_TIMEOUT_S) -> None:
        if channels not in (16, 32):
            raise ValueError(f"channels must be 16 or 32, got {channels}")
        self.target = target
        self.channels = channels
        self.rate_hz = rate_hz
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.settimeout(timeout_s)
        self.restart()

    def restart(self, new_process: bool = False) -> None:
        """SITL started again: counters, clock and buffer from zero. ``new_process``: as a
        new ArduPilot process after the old one was killed, a new socket, so the servo
        packets come from a new ephemeral port (SITL's JSON socket is never bound:
        ``JSON::set_interface_ports`` only sets the target); otherwise the socket is kept."""
        if new_process:
            timeout = self.sock.gettimeout()
            self.sock.close()
            self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
            self.sock.bind(("127.0.0.1", 0))
            self.sock.settimeout(timeout)
        self.frame_counter = 0
        self.last_timestamp_s = 0.0
        self.time_now_us = 0.0
        self.physics_resets_seen = 0
        self.buffer = bytearray()
        self.last_packet = b""
        self.last_parsed: Parsed | None = None
        self.messages: list[str] = []

    def close(self) -> None:
        self.sock.close()

    @property
    def source(self) -> tuple[str, int]:
        """(address, port) the servo packets come from."""
        return self.sock.getsockname()

    def pending(self) -> bool:
        """Whether a datagram waits to be read (without waiting)."""
        return bool(select.select([self.sock], [], [], 0.0)[0])

    def packet(self, pwm_us: list[int] | tuple[int, ...], frame_count: int | None = None) -> bytes:
        """The servo datagram for ``pwm_us`` (padded with 0 to the channel count)."""
        values = list(pwm_us) + [0] * (self.channels - len(pwm_us))
        if len(values) != self.channels:
            raise ValueError(f"{len(pwm_us)} PWM values for {self.channels} channels")
        magic = MAGIC_16 if self.channels == 16 else MAGIC_32
        count = self.frame_counter if frame_count is None else frame_count
        return struct.pack(f"<HHI{self.channels}H", magic, self.rate_hz, count, *values)

    def send_servos(self, pwm_us: list[int] | tuple[int, ...]) -> bytes:
        """``JSON::output_servos``: the current frame_counter and these PWM values [µs]."""
        self.last_packet = self.packet(pwm_us)
        self.sock.sendto(self.last_packet, self.target)
        return self.last_packet

    def resend(self) -> None:
        """What ``recv_fdm`` does after 1 s without a reply: the same packet again."""
        self.sock.sendto(self.last_packet, self.target)

    def send_raw(self, data: bytes) -> None:
        self.sock.sendto(data, self.target)

    def read_datagram(self) -> bytes:
        """One datagram from the server (socket.timeout if none within the timeout)."""
        data, _ = self.sock.recvfrom(65536)
        return data

    def receive(self) -> Parsed | None:
        """Read one datagram and :meth:`accept` it."""
        return self.accept(self.read_datagram())

    def accept(self, datagram: bytes) -> Parsed | None:
        """``JSON::recv_fdm`` on one datagram: the parsed state if it was accepted (then
        frame_counter advances and the clock follows the timestamp), else None."""
        self.buffer += datagram.replace(b"\n", b"\0")
        p2 = self.buffer.rfind(b"\0")
        if p2 <= 0:
            return None
        p1 = self.buffer.rfind(b"\0", 0, p2)
        if p1 < 0:
            return None
        parsed = parse_sensors(bytes(self.buffer[p1 + 1:p2]))
        if parsed.bitmask == 0:
            self.messages.append(parsed.message or "Did not contain all mandatory fields")
            return None
        if parsed.bitmask & (EULER_ATT | QUAT_ATT) == 0:
            self.messages.append("Did not receive attitude or quaternion")
            return None
        del self.buffer[:p2]
        timestamp_s = float(parsed.values["timestamp"])
        if timestamp_s < self.last_timestamp_s:
            self.physics_resets_seen += 1
            dt_s = 0.0
        else:
            dt_s = timestamp_s - self.last_timestamp_s
        self.time_now_us += dt_s * 1e6
        self.last_timestamp_s = timestamp_s
        self.frame_counter += 1
        self.last_parsed = parsed
        return parsed
