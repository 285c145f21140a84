"""What a MAVLink link is set up with and what it reports: endpoints, signing keys, the
vehicle state a link sends, the parameters it serves (no sockets here; the link itself is
:mod:`bioflex_jsb.links.mavlink`)."""

from __future__ import annotations

import ipaddress
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

from bioflex_jsb.files import read_input_bytes

SIGNING_KEY_BYTES = 32
# Largest signing-key file read [bytes]: 64 hexadecimal digits and the white space around
# them (a newline, CRLF, a few blanks) fit many times over.
SIGNING_KEY_FILE_BYTES = 1024
SIGNING_EPOCH_UNIX_S = 1420070400  # 2015-01-01T00:00:00Z: origin of signing timestamps


class LinkError(Exception):
    """A malformed or unusable endpoint or signing key; one line for the user."""


def read_signing_key(path: str | Path) -> bytes:
    """The 32-byte MAVLink 2 signing secret in the file ``path``: 64 hexadecimal digits
    (surrounding white space ignored). MAVProxy's ``signing key P`` (and ``signing setup
    P``) signs with SHA-256 of the passphrase P, so its key file is ``python -c "import
    hashlib; print(hashlib.sha256(b'P').hexdigest())" > key.hex``. LinkError (one line)
    when the file is missing, unreadable, or does not hold exactly 32 bytes of hex, or
    holds the all-zero key (which means "signing off" in MAVLink)."""
    where = f"signing key {str(path)!r}"
    # a regular file of at most SIGNING_KEY_FILE_BYTES, read with that bound (a FIFO, a
    # device such as /dev/zero or a large file: refused before reading it)
    raw = read_input_bytes(path, "signing key", SIGNING_KEY_FILE_BYTES, LinkError)
    try:
        text = raw.decode("ascii").strip()
    except UnicodeDecodeError:
        raise LinkError(f"{where}: expected {2 * SIGNING_KEY_BYTES} hexadecimal digits, "
                        "found binary data") from None
    if len(text) != 2 * SIGNING_KEY_BYTES:
        raise LinkError(f"{where}: expected {2 * SIGNING_KEY_BYTES} hexadecimal digits "
                        f"({SIGNING_KEY_BYTES} bytes), found {len(text)} characters")
    try:
        key = bytes.fromhex(text)
    except ValueError:
        raise LinkError(f"{where}: not hexadecimal (expected {2 * SIGNING_KEY_BYTES} digits "
                        "0-9, a-f)") from None
    if not any(key):
        raise LinkError(f"{where}: the all-zero key means 'no signing' in MAVLink; use a "
                        "random key")
    return key


def signing_time_10us(unix_s: float | None = None) -> int:
    """MAVLink signing timestamp: 10 µs units since 2015-01-01 UTC (wall clock)."""
    now = time.time() if unix_s is None else unix_s
    return int(max(now - SIGNING_EPOCH_UNIX_S, 0.0) * 100_000)


@dataclass(frozen=True)
class Endpoint:
    kind: str  # udpout, udpin, tcpin
    host: str
    port: int

    def text(self) -> str:
        return f"{self.kind}:{self.host}:{self.port}"


def parse_endpoint(text: str) -> Endpoint:
    """``udpout:HOST:PORT``, ``udpin:[HOST:]PORT``, ``tcpin:[HOST:]PORT`` (module docstring)."""
    kind, sep, rest = str(text).partition(":")
    if not sep or kind not in ("udpout", "udpin", "tcpin"):
        raise LinkError(f"MAVLink endpoint {text!r}: expected udpout:HOST:PORT, "
                        "udpin:HOST:PORT or tcpin:HOST:PORT")
    host, sep, port_text = rest.rpartition(":")
    if not sep:
        host, port_text = "", rest
    host = host.strip() or "127.0.0.1"
    try:
        port = int(port_text)
    except ValueError:
        raise LinkError(f"MAVLink endpoint {text!r}: port {port_text!r} is not a number") from None
    lowest = 1 if kind == "udpout" else 0  # listening on port 0: the system picks one
    if not lowest <= port <= 65535:
        raise LinkError(f"MAVLink endpoint {text!r}: port {port} is outside {lowest}..65535")
    if host == "localhost":
        host = "127.0.0.1"
    try:
        addr = ipaddress.IPv4Address(host)
    except ValueError:
        raise LinkError(f"MAVLink endpoint {text!r}: host {host!r} is not an IPv4 address "
                        "(or localhost)") from None
    if kind == "udpout" and (addr.is_unspecified or addr.is_multicast or str(addr).endswith(
            ".255")):
        raise LinkError(f"MAVLink endpoint {text!r}: udpout needs one destination host, "
                        f"not {host}")
    return Endpoint(kind, host, port)


@dataclass
class VehicleState:
    """What the telemetry reports, SI: simulation time [s]; Euler angles [rad]; body rates
    [rad/s]; latitude/longitude [rad]; altitude above sea level and above the start [m];
    NED ground velocity [m/s]; true airspeed [m/s]; throttle 0..1; named values (modal
    states, tip twist) [rad]."""

    time_s: float = 0.0
    roll_rad: float = 0.0
    pitch_rad: float = 0.0
    yaw_rad: float = 0.0
    p_rad_s: float = 0.0
    q_rad_s: float = 0.0
    r_rad_s: float = 0.0
    latitude_rad: float = 0.0
    longitude_rad: float = 0.0
    altitude_m: float = 0.0
    relative_altitude_m: float = 0.0
    v_north_m_s: float = 0.0
    v_east_m_s: float = 0.0
    v_down_m_s: float = 0.0
    airspeed_m_s: float = 0.0
    throttle: float = 0.0
    named: dict[str, float] = field(default_factory=dict)
    autopilot: bool = True
    manual: bool = False
    custom_mode: int = 7
    armed: bool = True
    home_latitude_rad: float = 0.0
    home_longitude_rad: float = 0.0
    home_altitude_m: float = 0.0
    mission_seq: int = 0
    mission_total: int = 0
    battery_voltage_v: float = 12.6
    battery_current_a: float = 0.0
    battery_consumed_mah: float = 0.0
    battery_energy_j: float = 0.0
    battery_remaining_pct: int = 100
    battery_time_remaining_s: float = 0.0
    # the autopilot's IMU (HIGHRES_IMU): specific force [m/s²] and rates [rad/s] in its axes
    imu_accel_m_s2: tuple[float, float, float] = (0.0, 0.0, -9.80665)
    imu_gyro_rad_s: tuple[float, float, float] = (0.0, 0.0, 0.0)


class Parameters(Protocol):
    """The vehicle's parameters: names in a fixed order, float values, validated set."""

    names: tuple[str, ...]

    def get(self, name: str) -> float: ...

    def set(self, name: str, value: float) -> float:
        """Apply; return the value now in force. ValueError: rejected (value unchanged)."""
        ...


class Vehicle(Protocol):
    """What the link asks of the vehicle (:class:`bioflex_jsb.drivers.sitl_vehicle.SitlVehicle`).
    Every command returns None when done, or a one-line reason it was refused; values are SI
    (rad, m AMSL, m/s)."""

    events: object  # deque of (MAV_SEVERITY, text) for STATUSTEXT, taken by the link
    reached: object  # deque of mission item numbers reached, for MISSION_ITEM_REACHED

    def set_mode(self, number: int) -> str | None: ...
    def arm(self, armed: bool, force: bool) -> str | None: ...
    def manual(self, pitch: float | None, roll: float | None) -> bool: ...
    def change_speed(self, speed_m_s: float) -> str | None: ...
    def change_altitude(self, alt_amsl_m: float) -> str | None: ...
    altitude_range_m: tuple[float, float]  # altitudes commanded [m AMSL]
    ground_altitude_m: float  # the flat ground [m AMSL]
    mode_name: str  # the mode flown (ArduPlane's name)

    def refused(self, text: str) -> None:
        """A refusal the link told the ground station (counted, logged as an event)."""
        ...

    def reposition(self, lat_rad: float, lon_rad: float, alt_amsl_m: float | None,
                   radius_m: float = 0.0, clockwise: bool = True) -> str | None: ...
    def guided_item(self, item) -> str | None: ...
    def item_problem(self, item) -> tuple[int, str] | None: ...
    def loiter_at(self, lat_rad: float | None, lon_rad: float | None,
                  radius_m: float) -> str | None: ...
    def set_home(self, lat_rad: float, lon_rad: float, alt_amsl_m: float) -> str | None: ...
    def mission_start(self, first: int, last: int) -> str | None: ...
    def status(self, severity: int, text: str) -> None: ...
