"""Sensor stations as data: where an IMU or an airspeed probe sits and what it adds.

A definition's ``[[sensors.imu]]`` and ``[[sensors.airspeed]]`` tables
(``docs/aircraft.md``, "Sensors") are read into these objects by
:mod:`bioflex_jsb.definition.sensors`, with every position resolved to **body axes from the
centre of gravity** (x forward, y starboard, z down [m]); the numerical core that turns the
flight state into their readings is :mod:`bioflex_jsb.simulation.sensors`.

The noise parameters mean what ArduPilot's SITL parameters of the same role mean
(``libraries/AP_InertialSensor/AP_InertialSensor_SITL.cpp``): a bias added to every sample
(``SIM_ACCn_BIAS`` [m/s²], ``SIM_GYRn_BIAS`` [rad/s]); a random noise ``RND``: each sample
each axis gets ``RND · U(−1, 1)`` (uniform, so its RMS is RND/√3), ``SIM_ACCn_RND``
[m/s²] and ``SIM_GYRn_RND`` (ArduPilot's in deg/s, here in rad/s); a vibration frequency
``SIM_VIB_FREQ`` [Hz] per axis: when any is set the uniform noise is replaced by a sine of
that frequency whose amplitude is ``RND · (1 + 0.05 · U(−1, 1))`` each sample. ArduPilot
also adds a floor (0.01 m/s², 0.04°/s) always and scales the gyro's RND by the throttle;
here neither: a sensor without noise parameters reads exactly the physics. All are off by
default and seeded (``seed``): the same seed gives the same samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

Vector3 = tuple[float, float, float]
ZERO3: Vector3 = (0.0, 0.0, 0.0)
# The relative spread of a vibration's amplitude from sample to sample: ArduPilot's
# ``noise_variation`` (AP_InertialSensor_SITL.cpp, calculate_noise).
VIBRATION_AMPLITUDE_SPREAD = 0.05


@dataclass(frozen=True)
class SensorNoise:
    """An IMU's errors, ArduPilot's SITL meanings (module docstring): ``accel_bias_m_s2``
    (SIM_ACCn_BIAS) [m/s²], ``accel_noise_m_s2`` (SIM_ACCn_RND: uniform ±RND) [m/s²],
    ``gyro_bias_rad_s`` (SIM_GYRn_BIAS) [rad/s], ``gyro_noise_rad_s`` (SIM_GYRn_RND, in
    rad/s) [rad/s], ``vibration_hz`` (SIM_VIB_FREQ per sensor axis) [Hz], ``seed`` of the
    random samples."""

    accel_bias_m_s2: Vector3 = ZERO3
    accel_noise_m_s2: float = 0.0
    gyro_bias_rad_s: Vector3 = ZERO3
    gyro_noise_rad_s: float = 0.0
    vibration_hz: Vector3 = ZERO3
    seed: int = 0

    @property
    def active(self) -> bool:
        """Whether the sensor reads anything but the physics."""
        return any(v != 0.0 for v in (*self.accel_bias_m_s2, *self.gyro_bias_rad_s,
                                       self.accel_noise_m_s2, self.gyro_noise_rad_s))

    def as_dict(self) -> dict[str, object]:
        return {"accel_bias_m_s2": list(self.accel_bias_m_s2),
                "accel_noise_m_s2": self.accel_noise_m_s2,
                "gyro_bias_rad_s": list(self.gyro_bias_rad_s),
                "gyro_noise_rad_s": self.gyro_noise_rad_s,
                "vibration_hz": list(self.vibration_hz), "seed": self.seed}


@dataclass(frozen=True)
class WingPoint:
    """Where on the elastic wing a sensor sits: ``y_m`` [m] along the span from the plane of
    symmetry (starboard positive, port negative: the symmetric modes move a port station as
    its starboard mirror, its roll slope mirrored; a full-span run's antisymmetric modes move
    it the opposite way, simulation/sensors.py), ``chord_position`` [fraction
    of the local chord aft of the leading edge], ``height_m`` [m] above the chord plane, and
    the wing's elastic axis there (``elastic_axis_offset_m``: the sensor's distance aft of
    the elastic axis [m]), all of the undeformed wing."""

    y_m: float
    chord_position: float
    height_m: float
    elastic_axis_offset_m: float


@dataclass(frozen=True)
class ImuSpec:
    """One IMU (accelerometer and gyro on one board).

    ``name``: its name (channels ``imu_<name>_…``, topic ``/bioflex/<model>/imu_<name>``);
    ``position_m``: its point in body axes from the CG (x forward, y starboard, z down)
    [m]; ``orientation_rad``: the sensor axes' roll, pitch, yaw from the body axes (3-2-1
    Euler angles) [rad]; ``wing``: the point on the elastic wing it is fixed to
    (:class:`WingPoint`; None: on the rigid airframe); ``noise`` (:class:`SensorNoise`);
    ``autopilot``: the IMU whose readings an autopilot gets (ArduPilot's JSON backend, the
    MAVLink vehicle's HIGHRES_IMU)."""

    name: str
    position_m: Vector3
    orientation_rad: Vector3 = ZERO3
    wing: WingPoint | None = None
    noise: SensorNoise = field(default_factory=SensorNoise)
    autopilot: bool = False

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "position_m": list(self.position_m),
                "frame": "body axes from the CG: x forward, y starboard, z down [m]",
                "orientation_rad": list(self.orientation_rad),
                "wing": None if self.wing is None else {
                    "y_m": self.wing.y_m, "chord_position": self.wing.chord_position,
                    "height_m": self.wing.height_m,
                    "elastic_axis_offset_m": self.wing.elastic_axis_offset_m},
                "noise": self.noise.as_dict(), "autopilot": self.autopilot}


@dataclass(frozen=True)
class AirspeedSpec:
    """One airspeed probe (a pitot-static tube): ``name`` (channel
    ``airspeed_<name>_m_s``), ``position_m`` in body axes from the CG [m], ``wing`` (a
    :class:`WingPoint`, or None: on the rigid airframe), ``noise_m_s``: a uniform noise
    ±noise [m/s] each sample (the role of ArduPilot's SIM_ARSPD_RND), ``seed``.
    It reads the true airspeed of the air at its point, |v_air + ω × r + the wing's modal
    velocity| (a pitot reads within 1 % up to 15-20° of flow angle: its axis is not
    modelled)."""

    name: str
    position_m: Vector3
    wing: WingPoint | None = None
    noise_m_s: float = 0.0
    seed: int = 0

    def as_dict(self) -> dict[str, object]:
        return {"name": self.name, "position_m": list(self.position_m),
                "wing": None if self.wing is None else {
                    "y_m": self.wing.y_m, "chord_position": self.wing.chord_position,
                    "height_m": self.wing.height_m},
                "noise_m_s": self.noise_m_s, "seed": self.seed}


@dataclass(frozen=True)
class Sensors:
    """An aircraft's sensor stations: its IMUs and airspeed probes (none: the autopilot's
    IMU is at the CG, as without a ``[sensors]`` table)."""

    imus: tuple[ImuSpec, ...] = ()
    airspeeds: tuple[AirspeedSpec, ...] = ()

    def __bool__(self) -> bool:
        return bool(self.imus or self.airspeeds)

    @property
    def autopilot_imu(self) -> ImuSpec:
        """The IMU the autopilot reads: the one marked ``autopilot``, else the first, else
        an ideal IMU at the CG (today's, and every aircraft's without sensors)."""
        for imu in self.imus:
            if imu.autopilot:
                return imu
        return self.imus[0] if self.imus else CG_IMU

    def as_dict(self) -> dict[str, object]:
        return {"imus": [s.as_dict() for s in self.imus],
                "airspeeds": [s.as_dict() for s in self.airspeeds]}


# The IMU of an aircraft without sensor stations: ideal, at the CG, body axes.
CG_IMU = ImuSpec(name="cg", position_m=ZERO3, autopilot=True)
NO_SENSORS = Sensors()


def euler_matrix(roll_rad: float, pitch_rad: float, yaw_rad: float
                 ) -> tuple[Vector3, Vector3, Vector3]:
    """The rotation (rows) taking a body-axes vector into the axes turned from the body's by
    the 3-2-1 Euler angles [rad] (as NED → body: R_x(φ) R_y(θ) R_z(ψ))."""
    cr, sr = math.cos(roll_rad), math.sin(roll_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
    return ((cp * cy, cp * sy, -sp),
            (sr * sp * cy - cr * sy, sr * sp * sy + cr * cy, sr * cp),
            (cr * sp * cy + sr * sy, cr * sp * sy - sr * cy, cr * cp))
