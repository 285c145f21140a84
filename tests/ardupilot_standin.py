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
import time
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
    ``rate_hz``: the frame_rate field sent [Hz] (default 1200, ArduPilot's SIM_RATE_HZ
    default), fixed; or, with ``sim_rate_hz`` [Hz] set, ArduPilot's own ``rate_hz``: 1200
    at the start, after every accepted reply 1/Δtimestamp moved by at most 1 Hz towards
    ``sim_rate_hz`` and truncated to an integer (``JSON::recv_fdm``, ``JSON::update``).
    """

    def __init__(self, target: tuple[str, int], channels: int = 16, rate_hz: int = 1200,
                 timeout_s: float = DEFAULT_TIMEOUT_S, sim_rate_hz: int | None = None) -> None:
        if channels not in (16, 32):
            raise ValueError(f"channels must be 16 or 32, got {channels}")
        self.target = target
        self.channels = channels
        self.rate_hz = rate_hz
        self.sim_rate_hz = sim_rate_hz
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
        if self.sim_rate_hz is not None:
            self.rate_hz = ARDUPILOT_START_RATE_HZ
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
        self.follow_rate(dt_s)
        self.last_parsed = parsed
        return parsed

    def follow_rate(self, dt_s: float) -> None:
        """With ``sim_rate_hz``: ArduPilot's rate_hz after a reply that advanced ``dt_s``
        [s] (it adopts 1/Δt for 0 < Δt < 0.1 s, then moves 1 Hz at most towards
        SIM_RATE_HZ); the frame_rate field is its integer part (a C cast to uint16)."""
        if self.sim_rate_hz is None:
            return
        rate = float(self.rate_hz)
        if 0.0 < dt_s < 0.1:
            rate = _single(1.0 / dt_s)
        self.rate_hz = int(min(max(float(self.sim_rate_hz), rate - 1.0), rate + 1.0))


# ------------------------------------------------------------------ flying at a speed-up
# ArduPilot SITL paces its frames to --speedup (SIM_Aircraft.cpp, Aircraft::sync_frame_time,
# described here in our own words): each frame adds (target frame time - the wall time since
# the last frame) to a sleep debt, target = 1 / (rate x speed-up), rate the physics rate it
# adopted from the timestamps' steps; the debt is floored at -0.1 s (a slow stretch is not
# made up for ever after) and slept off whenever it exceeds 5 ms (its min_sleep_time).
SLEEP_DEBT_FLOOR_S = -0.1
MIN_SLEEP_S = 0.005
LAUNCH_SWITCH_US = 1900  # servo 5 in the backend's launch window (1880..1920 us)
ARDUPILOT_START_RATE_HZ = 1200  # SIM_Aircraft.h: rate_hz's initial value
RESEND_S = 1.0  # JSON::recv_fdm sends the frame again after 1 s without a reply
PATIENCE = 60  # re-sends before the stand-in gives up (a backend still starting up)


@dataclass
class FlightStats:
    """One paced (or free) run of the stand-in: ``frames`` answered in ``wall_s`` [s] of
    wall time, ``physics_s`` [s] of the backend's time advanced; ``answer_s`` [s] the sum of
    the waits for the replies (send to reply: the backend's share and loopback UDP);
    ``grounded`` frames whose reply had no airspeed (the aircraft was not flying)."""

    speedup: float | None
    frames: int
    wall_s: float
    physics_s: float
    answer_s: float
    grounded: int

    @property
    def real_time_factor(self) -> float:
        return self.physics_s / self.wall_s

    @property
    def frames_per_s(self) -> float:
        """Frames the loop completed per wall second (the stand-in's own work included)."""
        return self.frames / self.wall_s

    @property
    def answered_per_s(self) -> float:
        """Frames the backend answers per second of waiting for it."""
        return self.frames / self.answer_s

    def as_dict(self) -> dict:
        return {"speedup": self.speedup, "frames": self.frames, "wall_s": self.wall_s,
                "physics_s": self.physics_s, "answer_s": self.answer_s,
                "grounded": self.grounded, "real_time_factor": self.real_time_factor,
                "frames_per_s": self.frames_per_s, "answered_per_s": self.answered_per_s}


def reply_timestamp(datagram: bytes) -> tuple[float, float]:
    """(timestamp [s], airspeed [m/s]) of one reply, read as ``parse_sensors`` reads those two
    keys (strstr, skip the key's length + 2, atof) without the other fields: the cheap read
    for the frames between two full parses."""
    line = datagram.strip(b"\n")
    values = []
    for key in (b"timestamp", b"airspeed"):
        q = line.find(key)
        values.append(c_atof(line[q + len(key) + 2:]) if q >= 0 else 0.0)
    return values[0], values[1]


class PacedStandin(ArduPilotStandin):
    """The stand-in flying the backend frame after frame, free (as fast as the backend
    answers) or paced to a speed-up as ArduPilot paces itself, every ``check_every``-th reply
    parsed in full (:meth:`accept`) and the others by :func:`reply_timestamp`."""

    def __init__(self, target, throttle_us: int = 1500, check_every: int = 100, **kw) -> None:
        super().__init__(target, timeout_s=RESEND_S, **kw)
        self.patience = PATIENCE
        self.pwm = [1500, 1500, int(throttle_us), 1500, LAUNCH_SWITCH_US]
        self.check_every = check_every
        self._debt_s = 0.0
        self.clock = time.perf_counter  # wall clock and sleep: a test passes its own
        self.sleep = time.sleep

    def _frame(self, full: bool) -> tuple[float, float, float]:
        """One frame: (wait for the reply [s], timestamp [s], airspeed [m/s])."""
        t0 = self.clock()
        self.send_servos(self.pwm)
        for _ in range(self.patience):  # as recv_fdm: the same frame again after 1 s
            try:
                data = self.read_datagram()
                break
            except TimeoutError:
                self.resend()
        else:
            raise TimeoutError(f"no reply from {self.target} in {self.patience} s")
        wait = self.clock() - t0
        if full:
            parsed = self.accept(data)
            if parsed is None:
                raise RuntimeError(f"reply not accepted: {self.messages[-1:]}")
            return wait, float(parsed.values["timestamp"]), float(
                parsed.values.get("airspeed", 0.0))
        ts, airspeed = reply_timestamp(data)
        self.frame_counter += 1
        step = max(0.0, ts - self.last_timestamp_s)
        self.time_now_us += step * 1e6
        self.last_timestamp_s = ts
        self.follow_rate(step)
        return wait, ts, airspeed

    def fly(self, frames: int, speedup: float | None = None) -> FlightStats:
        """``frames`` frames, paced to ``speedup`` (None: free)."""
        grounded = 0
        answer = 0.0
        t_start = self.last_timestamp_s
        clock = self.clock
        wall0 = last = clock()
        self._debt_s = 0.0
        prev_ts = self.last_timestamp_s
        for i in range(frames):
            wait, ts, airspeed = self._frame(i % self.check_every == 0)
            answer += wait
            grounded += airspeed <= 0.0
            if speedup is not None:
                step = ts - prev_ts
                now = clock()
                if 0.0 < step < 0.1:  # the rate ArduPilot adopts from the timestamps
                    self._debt_s += step / speedup - (now - last)
                    self._debt_s = max(self._debt_s, SLEEP_DEBT_FLOOR_S)
                    if self._debt_s > MIN_SLEEP_S:
                        self.sleep(self._debt_s)
                        self._debt_s -= clock() - now
                last = clock()
            prev_ts = ts
        wall = clock() - wall0
        return FlightStats(speedup, frames, wall, self.last_timestamp_s - t_start, answer,
                           grounded)


def main(argv: list[str] | None = None) -> int:
    """``python tests/ardupilot_standin.py --target HOST:PORT [--warmup N] [--frames N]
    [--speedups S,S,...] [--repeat N] [--throttle-us US] [--frame-rate HZ | --sim-rate-hz
    HZ]``: fly the backend (the launch
    switch held, the surfaces at trim), ``--warmup`` frames first (launch and settle), then
    ``--repeat`` rounds of a free run and a run at each speed-up, ``--frames`` each; one JSON
    document on stdout (the runs in order, :meth:`FlightStats.as_dict`). ``--frame-rate``:
    the frame_rate field sent (default 1200, ArduPilot's SIM_RATE_HZ default); with
    ``--sim-rate-hz`` the field is ArduPilot's rate_hz following the replies' timestamps
    towards that SIM_RATE_HZ, as ArduPlane's (:class:`ArduPilotStandin`). The pacing follows
    the timestamps' step per frame (1/frame rate once the backend honours it), as
    ArduPilot's does."""
    import argparse
    import json

    p = argparse.ArgumentParser(description=main.__doc__.split("\n")[0])
    p.add_argument("--target", required=True)
    p.add_argument("--warmup", type=int, default=2000)
    p.add_argument("--frames", type=int, default=4000)
    p.add_argument("--speedups", default="")
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--throttle-us", type=int, default=1500)
    p.add_argument("--frame-rate", type=int, default=ARDUPILOT_START_RATE_HZ)
    p.add_argument("--sim-rate-hz", type=int, default=None)
    args = p.parse_args(argv)
    for name, value in (("--frame-rate", args.frame_rate), ("--sim-rate-hz", args.sim_rate_hz)):
        if value is not None and not 0 <= value <= 65535:
            p.error(f"{name} {value} is outside 0..65535 Hz (a uint16 field)")
    host, port = args.target.rsplit(":", 1)
    speedups = [float(s) for s in args.speedups.split(",") if s]
    ap = PacedStandin((host, int(port)), throttle_us=args.throttle_us,
                      rate_hz=args.frame_rate, sim_rate_hz=args.sim_rate_hz)
    runs = []
    try:
        warm = ap.fly(args.warmup)
        for _ in range(args.repeat):
            for s in (None, *speedups):
                runs.append(ap.fly(args.frames, s).as_dict())
    finally:
        ap.close()
    print(json.dumps({"warmup": warm.as_dict(), "runs": runs}))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
