"""The ``[sensors]`` table of an aircraft definition: IMUs and airspeed probes at stations.

Read by :func:`parse_sensors` into :class:`SensorStation` objects as the file gives them (a
point of the airframe in body axes from the CG or in the structural frame, or a point on
the wing); :func:`resolve_sensors` places them in body axes from the CG with the airframe's
CG and the wing's attachment (``[airframe] cg_m``, ``wing_root_leading_edge_m``: known
once the aircraft is complete) into :class:`~bioflex_jsb.parameters.sensors.Sensors`, the
numerical core's input. ``docs/aircraft.md``, "Sensors", has the fields.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.definition.reader import DefinitionError, Reader
from bioflex_jsb.parameters.sensors import (
    AirspeedSpec,
    ImuSpec,
    SensorNoise,
    Sensors,
    WingPoint,
)

MAX_IMUS = 16  # an autopilot's, a few accelerometers along the span, a tail's
MAX_AIRSPEEDS = 8
FRAMES = ("body", "structural")
# Position of a sensor [m]: the [airframe] positions' range (a unit mistake, not an aircraft)
POSITION_RANGE_M = (-200.0, 200.0)
ORIENTATION_LIMIT_DEG = 180.0
# Sensor errors (ArduPilot's SITL meanings, parameters/sensors.py). Bounds that catch a unit
# mistake: 100 m/s² (10 g) of bias or noise is a broken accelerometer already, ArduPilot's
# SIM_ACC1_RND default is 0 and its examples 1-5 m/s²; 10 rad/s (573°/s) of gyro bias or
# noise likewise (a value in deg/s, ArduPilot's SIM_GYR1_RND unit, would be 57 times the
# rad/s one: the docs say rad/s).
ACCEL_ERROR_LIMIT_M_S2 = 100.0
GYRO_ERROR_LIMIT_RAD_S = 10.0
VIBRATION_LIMIT_HZ = 5000.0  # above the IMU rates ArduPilot samples at (1-8 kHz) it aliases
AIRSPEED_NOISE_LIMIT_M_S = 20.0
SEED_RANGE = (0, 2**32 - 1)
CHORD_POSITION_RANGE = (0.0, 1.0)  # on the wing: between its leading and trailing edges
NAME_HINT = "lower-case letters, digits and _, starting with a letter, at most 32"
_IMU_NOISE_FIELDS = ("accel_bias_m_s2", "accel_noise_m_s2", "gyro_bias_rad_s",
                     "gyro_noise_rad_s", "vibration_hz", "seed")
_PLACE_FIELDS = ("position_m", "frame", "wing_y_m", "chord_position", "height_m")


@dataclass(frozen=True)
class SensorStation:
    """A sensor as the file places it: ``kind`` (``imu`` or ``airspeed``), ``name``; on the
    airframe ``position_m`` in ``frame`` (``body``: x forward, y starboard, z down from the
    CG; ``structural``: the [airframe] frame, x aft, y starboard, z up from the JSBSim
    aircraft's origin) or on the wing (``wing_y_m`` [m, port negative], ``chord_position``
    [chord fraction aft of the leading edge], ``height_m`` [m above the chord plane]);
    ``orientation_rad`` (roll, pitch, yaw of its axes from the body's), ``noise``
    (:class:`SensorNoise`; an airspeed probe: ``airspeed_noise_m_s``, ``noise.seed``),
    ``autopilot``."""

    kind: str
    name: str
    frame: str
    position_m: tuple[float, float, float] | None
    wing_y_m: float | None
    chord_position: float
    height_m: float
    orientation_rad: tuple[float, float, float]
    noise: SensorNoise
    airspeed_noise_m_s: float
    autopilot: bool


def _name(r: Reader, row: dict, where: str, seen: set[str]) -> str:
    import re

    name = r.text(row, where, "name")
    if not re.fullmatch(r"[a-z][a-z0-9_]{0,31}", name):
        raise r.fail(f"{where}.name", f"{name!r}: accepted {NAME_HINT} (it names channels "
                     "and log topics)")
    if name in seen:
        raise r.fail(f"{where}.name", f"{name!r} is used twice")
    seen.add(name)
    return name


def _place(r: Reader, row: dict, where: str, semispan_m: float
           ) -> tuple[str, tuple[float, float, float] | None, float | None, float, float]:
    on_wing = "wing_y_m" in row
    if on_wing == ("position_m" in row):
        raise r.fail(where, "give either position_m (a point of the airframe) or wing_y_m "
                     "(a point on the elastic wing), not both or neither")
    if on_wing:
        for key in ("position_m", "frame"):
            if key in row:
                raise r.fail(f"{where}.{key}", "a wing sensor is placed by wing_y_m, "
                             "chord_position and height_m")
        y = r.number(row, where, "wing_y_m", -semispan_m, semispan_m, "m",
                     hint=f" (|y| up to the semispan, {semispan_m:g} m; port negative)")
        c = r.number(row, where, "chord_position", *CHORD_POSITION_RANGE, "chord fraction",
                     default=0.25, hint=" (a fraction of the local chord aft of the "
                     "leading edge)")
        h = r.number(row, where, "height_m", -1.0, 1.0, "m", default=0.0)
        return "wing", None, y, c, h
    for key in ("chord_position", "height_m"):
        if key in row:
            raise r.fail(f"{where}.{key}", "only for a wing sensor (wing_y_m)")
    frame = r.choice(row, where, "frame", FRAMES, "body")
    return frame, r.vector(row, where, "position_m", *POSITION_RANGE_M, "m"), None, 0.0, 0.0


def _imu(r: Reader, row: dict, where: str, semispan_m: float, seen: set[str]
         ) -> SensorStation:
    r.keys(row, where, ("name", "orientation_deg", "autopilot", *_PLACE_FIELDS,
                        *_IMU_NOISE_FIELDS))
    name = _name(r, row, where, seen)
    frame, pos, y, c, h = _place(r, row, where, semispan_m)
    lim = ORIENTATION_LIMIT_DEG
    orient = r.vector(row, where, "orientation_deg", -lim, lim, "deg", default=(0.0, 0.0, 0.0))
    acc, gyr = ACCEL_ERROR_LIMIT_M_S2, GYRO_ERROR_LIMIT_RAD_S
    noise = SensorNoise(
        accel_bias_m_s2=r.vector(row, where, "accel_bias_m_s2", -acc, acc, "m/s^2",
                                 default=(0.0, 0.0, 0.0)),
        accel_noise_m_s2=r.number(row, where, "accel_noise_m_s2", 0.0, acc, "m/s^2",
                                  default=0.0),
        gyro_bias_rad_s=r.vector(row, where, "gyro_bias_rad_s", -gyr, gyr, "rad/s",
                                 default=(0.0, 0.0, 0.0)),
        gyro_noise_rad_s=r.number(row, where, "gyro_noise_rad_s", 0.0, gyr, "rad/s",
                                  default=0.0, hint=" (rad/s: ArduPilot's SIM_GYR1_RND is "
                                  "in deg/s)"),
        vibration_hz=r.vector(row, where, "vibration_hz", 0.0, VIBRATION_LIMIT_HZ, "Hz",
                              default=(0.0, 0.0, 0.0)),
        seed=r.integer(row, where, "seed", *SEED_RANGE, 0))
    return SensorStation("imu", name, frame, pos, y, c, h,
                         tuple(math.radians(a) for a in orient), noise, 0.0,
                         r.boolean(row, where, "autopilot", False))


def _airspeed(r: Reader, row: dict, where: str, semispan_m: float, seen: set[str]
              ) -> SensorStation:
    r.keys(row, where, ("name", "noise_m_s", "seed", *_PLACE_FIELDS))
    name = _name(r, row, where, seen)
    frame, pos, y, c, h = _place(r, row, where, semispan_m)
    return SensorStation("airspeed", name, frame, pos, y, c, h, (0.0, 0.0, 0.0),
                         SensorNoise(seed=r.integer(row, where, "seed", *SEED_RANGE, 0)),
                         r.number(row, where, "noise_m_s", 0.0, AIRSPEED_NOISE_LIMIT_M_S,
                                  "m/s", default=0.0), False)


def _rows(r: Reader, t: dict, key: str, limit: int) -> list[dict]:
    rows = t.get(key, [])
    if not isinstance(rows, list) or not all(isinstance(x, dict) for x in rows):
        raise r.fail(f"sensors.{key}", f"must be an array of tables [[sensors.{key}]]")
    if len(rows) > limit:
        raise r.fail(f"sensors.{key}", f"{len(rows)} entries; accepted at most {limit}")
    return rows


def parse_sensors(r: Reader, data: dict, semispan_m: float, has_airframe: bool
                  ) -> tuple[SensorStation, ...]:
    """The ``[sensors]`` table (none: no stations; the autopilot's IMU is then at the CG)."""
    if "sensors" not in data:
        return ()
    if not has_airframe:
        raise r.fail("[sensors]", "sensors are an aircraft's: a clamped wing (no [airframe]) "
                     "has none")
    t = r.table("sensors", ("imu", "airspeed"))
    seen: set[str] = set()
    imus = [_imu(r, row, f"sensors.imu[{i}]", semispan_m, seen)
            for i, row in enumerate(_rows(r, t, "imu", MAX_IMUS))]
    seen_air: set[str] = set()
    probes = [_airspeed(r, row, f"sensors.airspeed[{i}]", semispan_m, seen_air)
              for i, row in enumerate(_rows(r, t, "airspeed", MAX_AIRSPEEDS))]
    pilots = [s.name for s in imus if s.autopilot]
    if len(pilots) > 1:
        raise r.fail("sensors.imu.autopilot", f"true on {', '.join(pilots)}: the autopilot "
                     "reads one IMU")
    return tuple(imus + probes)


def _interp(y: float, ys: np.ndarray, values: np.ndarray) -> float:
    return float(np.interp(abs(y), ys, values))


def resolve_sensors(stations: tuple[SensorStation, ...], definition) -> Sensors:
    """``stations`` in body axes from the CG (module docstring) for ``definition`` (its
    wing stations and its complete ``[airframe]``: ``cg_m``, ``wing_root_leading_edge_m``);
    a wing point's elastic axis from the stations (linear between them)."""
    if not stations:
        return Sensors()
    a = definition.airframe
    if a.cg_m is None or a.wing_root_leading_edge_m is None:
        raise DefinitionError(f"definition {definition.name!r}: the sensors need the CG and "
                              "the wing's attachment (airframe.cg_m, wing_root_leading_edge_m,"
                              " or the JSBSim aircraft's: load it with load_aircraft)")
    cg, root = np.asarray(a.cg_m, dtype=float), np.asarray(a.wing_root_leading_edge_m,
                                                           dtype=float)
    ys = definition.column("y_m")
    imus, probes = [], []
    for s in stations:
        wing = None
        if s.wing_y_m is not None:
            chord = _interp(s.wing_y_m, ys, definition.column("chord_m"))
            le_x = _interp(s.wing_y_m, ys, definition.column("leading_edge_x_m"))
            le_z = _interp(s.wing_y_m, ys, definition.column("z_m"))
            ea = _interp(s.wing_y_m, ys, definition.column("elastic_axis"))
            # the point in the structural frame (x aft, y starboard, z up)
            point = root + np.array([le_x + s.chord_position * chord, s.wing_y_m,
                                     le_z + s.height_m])
            wing = WingPoint(s.wing_y_m, s.chord_position, s.height_m,
                             (s.chord_position - ea) * chord)
        elif s.frame == "structural":
            point = np.asarray(s.position_m, dtype=float)
        else:
            point = None
        if point is None:
            body = tuple(float(v) for v in s.position_m)
        else:  # structural → body axes from the CG: x forward, y starboard, z down
            d = point - cg
            body = (float(-d[0]) + 0.0, float(d[1]) + 0.0, float(-d[2]) + 0.0)  # no -0.0
        if s.kind == "imu":
            imus.append(ImuSpec(s.name, body, s.orientation_rad, wing, s.noise, s.autopilot))
        else:
            probes.append(AirspeedSpec(s.name, body, wing, s.airspeed_noise_m_s,
                                       s.noise.seed))
    return Sensors(tuple(imus), tuple(probes))
