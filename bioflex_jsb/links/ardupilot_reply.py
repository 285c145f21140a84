"""ArduPilot's JSON SITL interface, simulator → ArduPilot: the state and the reply's text.

The other half of :mod:`bioflex_jsb.links.ardupilot_json` (packets, lock-step server), from
the same sources (``libraries/SITL/SIM_JSON.cpp`` and ``SIM_JSON.h`` of ArduPilot master
90700977c553).

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
"""

from __future__ import annotations

import json
import math
import struct
from dataclasses import dataclass

# SIM_JSON.h: sensor_buffer[65000] holds the replies; one reply must fit with room to spare.
MAX_REPLY_BYTES = 32000
QUATERNION_NORM_TOLERANCE = 1e-3  # ArduPilot's rotation_matrix assumes a unit quaternion


class JsonStateError(ValueError):
    """A physics state that cannot be sent to ArduPilot; one line."""


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
