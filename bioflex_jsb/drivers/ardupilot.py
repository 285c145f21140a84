"""ArduPlane flies the co-simulation: the one coupled step as ArduPilot's JSON SITL physics.

:class:`ArduPilotPhysics` is the :class:`~bioflex_jsb.links.ardupilot_json.JsonPhysics` a
:class:`~bioflex_jsb.links.ardupilot_json.LockstepServer` drives: k
:class:`~bioflex_jsb.runtime.coupled_step.CoupledStep` steps of ``dt_s`` (1/960 s) per
ArduPilot frame, the servo outputs mapped to JSBSim's controls before them and the state
converted to ArduPilot's units and frames after them (once, here; ``docs/ardupilot.md``).

Frame rate: k follows the frame rate ArduPilot reports (its SIM_RATE_HZ, reached through
its ``rate_hz``: :class:`~bioflex_jsb.links.ardupilot_rate.FrameRate`; k = 1 at the
default 1200 Hz, 4 at 240 Hz; each change an INFO event, a rate out of range a WARNING).
The servo outputs are held over the k steps (a servo updated at ArduPilot's rate) and the
reply's timestamp advances k·dt, so ArduPilot's clock, and its IMU, GPS and airspeed
samples, run at 1/(k·dt); the co-simulation still steps at 1/dt, each step as it would be
with one frame per step and the same outputs. Everything per step (the launcher's hold and
stroke, the gust, the range checks, the log's run topics) counts steps, not frames; a
valid-range stop inside a frame is taken at its own step (its time in :attr:`stops`), and
the frame's remaining steps pass at rest on the launcher.

Channel map (ArduPilot's convention: PWM above trim = roll right, nose up, nose right, more
thrust; bioflex's JSBSim controls: + elevator = nose down, + rudder = nose left; see
:data:`CHANNEL_MAP`):

======= ============ ============================ ==========================================
servo   function     JSBSim property              value (clipped)
======= ============ ============================ ==========================================
1       4 aileron    ``fcs/aileron-cmd-norm``     +(pwm − 1500)/500 in [−1, 1]
2       19 elevator  ``fcs/elevator-cmd-norm``    −(pwm − 1500)/500 in [−1, 1]
3       70 throttle  ``fcs/throttle-cmd-norm[i]`` (pwm − 1000)/1000 in [0, 1], every engine
4       21 rudder    ``fcs/rudder-cmd-norm``      −(pwm − 1500)/500 in [−1, 1]
======= ============ ============================ ==========================================

A channel at 0 µs (ArduPilot sends 0 for a channel it does not drive) reads as its trim
(1500 µs; throttle 1000 µs). The elevator's trim from the cruise trim
(``fcs/pitch-trim-cmd-norm``) stays in, like a linkage trimmed on the bench: 1500 µs is the
elevator that flies level at the trim speed.

Start: at rest on a launcher (the prototype is canister/hand launched). JSBSim's ground
contact is not used for it: the airframe has only structure contact points (no gear), and
the modal wing and the trim are undefined at zero airspeed. Instead the physics has three
phases (:attr:`ArduPilotPhysics.phase`):

* ``rest``: held on the launcher at the trim attitude (wings level, pitch θ_trim, heading
  north), position (0, 0, 0) from home, velocity 0, airspeed 0, specific force
  R(θ)ᵀ(0, 0, −g) (level: (0, 0, −g)); JSBSim waits trimmed at the exit speed, unstepped.
* ``launch``: when for :data:`LAUNCH_HOLD_S` ArduPlane's throttle output (servo 3) has
  been above :data:`LAUNCH_THROTTLE_US` (armed in TAKEOFF mode, waiting for the launch at
  ``TKOFF_THR_IDLE``) or servo 5 within :data:`LAUNCH_SWITCH_US` (the launch switch: RC
  input 5 passed through, set by the ground station once ArduPlane is armed in AUTO),
  a constant push along the trim's velocity (horizontal,
  north) to the trim (exit) speed ``speed_m_s`` at ``launch_accel_m_s2`` (default 40 m/s²
  over 0.375 s, a 2.8 m stroke), exact constant-acceleration kinematics: specific force
  R(θ)ᵀ(a, 0, −g), the push seen by ArduPlane's ``TKOFF_THR_MINACC``.
* ``flight``: the coupled step, from the trim state at the end of the stroke (the same
  velocity, position and attitude: the hand-over is continuous).

The ground is put ``launch_height_m`` below the launcher. A run that leaves the valid range
(the ground, deep stall, a diverged mode: :mod:`bioflex_jsb.simulation.limits`) does not end
the server: the aircraft is put back on the launcher at rest once (re-trimmed, wing
undeformed), the stop is kept in :attr:`ArduPilotPhysics.stops` and reported as an ERROR
event, and the time goes on (ArduPilot's clock must not go back). It then stays on the
launcher (``grounded``) until ArduPilot restarts: ArduPlane, still mid-mission, holds its
throttle up and would otherwise fire the launcher again half a second later, every time
(a 20 m/s gust gave 38 stops and 39 re-launches in 5 min that way). ArduPilot restarting
(:meth:`ArduPilotPhysics.reset`) puts it on the launcher with the time back to 0 and the
launcher armed again: a re-launch needs ArduPilot's restart.

The state sent (:meth:`ArduPilotPhysics.state`), in flight:

* ``imu.gyro`` and ``imu.accel_body``: the autopilot's IMU
  (:attr:`~bioflex_jsb.parameters.sensors.Sensors.autopilot_imu`: the aircraft
  definition's ``[sensors]`` IMU marked ``autopilot``, else its first; without sensors an
  ideal IMU at the CG) at its station, in its axes (:mod:`bioflex_jsb.simulation.sensors`):
  the specific force at the CG, the non-gravitational forces ``forces/fbx-total-lbs`` …
  (aerodynamics, propulsion, the elastic wing's ``external_reactions``, ground) over
  ``inertia/mass-slugs`` [m/s²], and the rates ``velocities/p-rad_sec``, ``q-``, ``r-``
  (body FRD, against the Earth), carried to its point by ω̇ × r + ω × (ω × r) and, on the
  wing, by the modes (their η̈ the mean over the last step, half a step old:
  :func:`~bioflex_jsb.simulation.sensors.latest_modal_kinematics`); JSBSim computes the
  forces during the step for the state the step reached, the one sent. At the CG without
  noise this is the CG's specific force and the body rates to the bit;
* ``position``: north/east from the launch point on the local ellipsoid radii, down =
  −(h − h_launch) [m];
* ``velocity``: ``velocities/v-north-fps``, ``v-east-fps``, ``v-down-fps`` [m/s];
* ``attitude`` (roll, pitch, yaw) and the unit ``quaternion`` (w, x, y, z) body → NED;
* ``airspeed``: ``velocities/vt-fps`` [m/s], the true airspeed with the gust (JSBSim's, at
  the state reached with the wind of the step).

Gusts: any :class:`~bioflex_jsb.simulation.gusts.GustSpec`, starting ``gust_at_s`` [s] after
the launch (flight time), sampled by the coupled step's step number; once per session (the
first flight that reaches ``gust_at_s``), or after every launch with ``gust_repeat``. The
first modal coordinate's range and largest change from the gust's start while the gust blows
(``*_in_gust``, with n_z's range), and its peak and largest change until
:data:`GUST_DECAY_S` after it (which may include a manoeuvre of the autopilot's), are
measured on every step (:attr:`ArduPilotPhysics.gust_report`, [rad]). A largest change
still growing at the search's end (``eta1_change_peak_at_window_end``, a WARNING event) is
a manoeuvre's (ArduPlane's turn at a waypoint, say), not the gust's: its value is where the
search stopped, and it moves with the manoeuvre's timing, which varies from flight to flight
(docs/ardupilot.md, "Flights differ").

Events (:meth:`ArduPilotPhysics.event`): launches, valid-range stops and what the server
reports (its source check, ArduPilot's restarts) are kept in :attr:`ArduPilotPhysics.events`
(session time [s], foxglove.Log level, text), logged on ``/bioflex/events`` and handed to
``on_event`` (the command prints them on stderr). An event raised inside a frame is written
after the frame's messages, at the time of the state the frame's reply sends.

Recording: :meth:`ArduPilotPhysics.on_frame` (the server's ``on_frame``) keeps every
``record_every``-th frame, and every resend and reset, in :attr:`records` (columns
:attr:`record_names`: time, ArduPilot's frame count, the server's action, the phase, servos
1–4 [µs], then the coupled step's row in flight, NaN before).

The MCAP log (:meth:`ArduPilotPhysics.log_to`, a :class:`~bioflex_jsb.sinks.mcap.RunLog`;
``docs/logging.md``), every frame the server answers:

* ``/bioflex/<model>/autopilot``: one message per frame (steps, resends and resets, in the
  order they arrived; at the frame's first step): ArduPilot's frame count and rate [Hz],
  all 16 (or 32) PWM values [µs], the four commands the channel map gives for them (applied
  in flight only), the server's action, the phase after the frame and the reply's
  timestamp [s];
* the run topics (``rigid_body`` … ``location``) of every coupled step in flight (all k of a
  frame): the step's row, the snapshot at the step's start, as every run logs it (none at
  rest and on the launcher: there is no coupled step there).

Log time is the *session* time: the physics time, continued across ArduPilot restarts
(which send the reply's timestamp back to 0), so the file's time never goes back. A step's
messages are at the time of its start (the state the frame's PWM acts on, which is the state
the previous reply sent); a resend's at the time of the state it repeats.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.links.ardupilot_json import RESEND, RESET, FrameRecord, JsonState
from bioflex_jsb.links.ardupilot_rate import FrameRate
from bioflex_jsb.parameters.sensors import NO_SENSORS, Sensors
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import GustField, GustSpec
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.sensors import AutopilotImu, SensorSet
from bioflex_jsb.values import is_whole

G0_M_S2 = 9.80665  # standard gravity: JSBSim's at the airframe's 45° latitude
# WGS-84, for north/east from latitude/longitude near the launch point
WGS84_A_M = 6378137.0
WGS84_E2 = 6.69437999014e-3

PWM_TRIM_US = 1500.0  # SERVOn_TRIM of the surfaces (bioflex_plane.parm)
PWM_HALF_RANGE_US = 500.0  # SERVOn_MAX − SERVOn_TRIM
PWM_THROTTLE_MIN_US = 1000.0  # SERVO3_MIN
PWM_THROTTLE_RANGE_US = 1000.0  # SERVO3_MAX − SERVO3_MIN


@dataclass(frozen=True)
class Channel:
    """One servo output: ``index`` (0 = servo 1), the JSBSim property, the PWM [µs] that
    gives 0, the µs per unit of the property, the sign and the clip range."""

    index: int
    prop: str
    zero_us: float
    us_per_unit: float
    sign: float
    lo: float
    hi: float

    def value(self, pwm_us: int) -> float:
        """The normalised command for ``pwm_us`` [µs] (0 µs: the channel's trim)."""
        if pwm_us == 0:
            return min(self.hi, max(self.lo, 0.0))
        x = self.sign * (pwm_us - self.zero_us) / self.us_per_unit
        return min(self.hi, max(self.lo, x))


CHANNEL_MAP: tuple[Channel, ...] = (
    Channel(0, "fcs/aileron-cmd-norm", PWM_TRIM_US, PWM_HALF_RANGE_US, +1.0, -1.0, 1.0),
    Channel(1, "fcs/elevator-cmd-norm", PWM_TRIM_US, PWM_HALF_RANGE_US, -1.0, -1.0, 1.0),
    Channel(2, "fcs/throttle-cmd-norm", PWM_THROTTLE_MIN_US, PWM_THROTTLE_RANGE_US, +1.0,
            0.0, 1.0),
    Channel(3, "fcs/rudder-cmd-norm", PWM_TRIM_US, PWM_HALF_RANGE_US, -1.0, -1.0, 1.0),
)
THROTTLE_CHANNEL = 2


def aircraft_channels(power) -> tuple[Channel, ...]:
    """The channel map of another JSBSim aircraft: the same servos and JSBSim commands as
    :data:`CHANNEL_MAP` (every JSBSim aircraft's FCS reads ``fcs/aileron-cmd-norm``,
    ``fcs/elevator-cmd-norm``, ``fcs/rudder-cmd-norm``, ``fcs/throttle-cmd-norm[i]``), each
    surface's direction from what its command does in the aircraft's own model
    (``power``: :class:`~bioflex_jsb.runtime.control_power.ControlPower`): PWM above trim
    gives ArduPilot's roll right, nose up, nose right. c172p: aileron +1 (roll power +10.5
    rad/s² per unit), elevator −1 (−14.2), rudder −1 (−1.54): the prototype's map. A rudder
    that moves nothing keeps the prototype's direction."""
    def sign(x: float, default: float) -> float:
        return default if x == 0.0 else math.copysign(1.0, x)

    proto = {c.index: c for c in CHANNEL_MAP}
    signs = {0: sign(power.roll_rad_s2, 1.0), 1: sign(power.pitch_rad_s2, -1.0),
             3: sign(power.yaw_rad_s2, -1.0)}
    return tuple(Channel(c.index, c.prop, c.zero_us, c.us_per_unit,
                         signs.get(c.index, c.sign), c.lo, c.hi) for c in proto.values())


def plane_numbers(aircraft, speed_m_s: float, altitude_m: float):
    """(:class:`~bioflex_jsb.generators.ardupilot_params.PlaneNumbers`, the control power)
    of an aircraft definition on its own JSBSim aircraft at the cruise ``speed_m_s`` [m/s]
    and ``altitude_m`` [m]: its flight speeds, its stall speed from its identified C_L,max,
    the trim throttle, the steady rates of a full command and the climb angles at full
    throttle and idle measured on its JSBSim model (runtime/control_power.py, a copy loaded
    for that), and the idle dive at its highest speed from its drag polar (D V/W).
    Raises FdmError (one line) where it cannot be trimmed."""
    from bioflex_jsb.definition.flying import flight_speeds
    from bioflex_jsb.generators.ardupilot_params import PlaneNumbers
    from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
    from bioflex_jsb.runtime.control_power import measure_control_power
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    probe = airframe_for(aircraft)
    power = measure_control_power(probe, speed_m_s, altitude_m)
    rho = float(probe["atmosphere/rho-slugs_ft3"]) * U.KG_M3_PER_SLUG_FT3
    engines = probe.engine_count
    del probe
    _cruise, (lo, hi) = flight_speeds(aircraft)
    data = aircraft.wing().model.airframe
    s_m2 = data.reference.area_m2
    weight = power.mass_kg * STANDARD_GRAVITY_M_S2
    stall = math.sqrt(2.0 * weight / (rho * s_m2 * data.at_speed(lo).aero.cl_max))
    fast = data.at_speed(hi).aero
    q_hi = 0.5 * rho * hi * hi
    cl = weight / (q_hi * s_m2)
    dive = (fast.cd0 + fast.k_induced * cl * cl) * q_hi * s_m2 * hi / weight
    q_full = -power.pitch_rad_s2 / (power.pitch_alpha_1_s2 / power.lift_alpha_1_s
                                    + power.pitch_rate_1_s)
    p_full = power.roll_rad_s2 / abs(power.roll_damping_1_s)
    channels = aircraft_channels(power)
    signs = tuple(c.sign for c in channels if c.index in (0, 1, 3))
    numbers = PlaneNumbers(
        aircraft.name, f"its JSBSim model {aircraft.airframe.jsbsim!r} trimmed at "
        f"{speed_m_s:g} m/s, {altitude_m:g} m (runtime/control_power.py); its flight speeds "
        f"{lo:g}..{hi:g} m/s; its identified C_L,max and drag polar", float(speed_m_s),
        float(lo), float(hi), stall, power.throttle_trim, p_full, q_full,
        power.climb_angle_full_rad, power.climb_angle_idle_rad, dive, signs, engines)
    return numbers, power

# The launch fires when, for LAUNCH_HOLD_S [s], servo 3 has been above LAUNCH_THROTTLE_US
# (ArduPlane in TAKEOFF mode holds TKOFF_THR_IDLE, 5 % = 1050 µs, while it waits; disarmed
# it sends 1000) or servo 5 within LAUNCH_SWITCH_US (SERVO5_FUNCTION 55 passes RC input 5
# through: the launch switch a ground station sets with RC_CHANNELS_OVERRIDE. In AUTO this
# ArduPlane keeps the throttle at 0 until the launch is detected, so TKOFF_THR_IDLE cannot
# signal it there). The window is narrow because SITL's own RC 5 idles at 1800 µs, which
# would fire the launcher at boot with a switch "above 1700 µs".
LAUNCH_THROTTLE_US = 1020
LAUNCH_SWITCH_CHANNEL = 4  # servo 5
LAUNCH_SWITCH_US = (1880, 1920)
LAUNCH_HOLD_S = 0.5
DEFAULT_LAUNCH_ACCEL_M_S2 = 40.0  # a canister/bungee push, > TKOFF_THR_MINACC = 15 m/s²
DEFAULT_LAUNCH_HEIGHT_M = 2.0  # launcher above the ground [m]
GUST_DECAY_S = 3.0  # the gust's η₁ peak is searched until this long after the gust [s]

REST, LAUNCH, FLIGHT = "rest", "launch", "flight"
PHASES = (REST, LAUNCH, FLIGHT)
ACTIONS = ("step", RESEND, RESET)
RECORD_HEAD = ("time_s", "frame_count", "action", "phase", "servo1_us", "servo2_us",
               "servo3_us", "servo4_us", "w_g_m_s")


def quaternion_from_euler(roll_rad: float, pitch_rad: float,
                          yaw_rad: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) rotating body-FRD vectors into NED for the 3-2-1 Euler angles [rad]."""
    cr, sr = math.cos(0.5 * roll_rad), math.sin(0.5 * roll_rad)
    cp, sp = math.cos(0.5 * pitch_rad), math.sin(0.5 * pitch_rad)
    cy, sy = math.cos(0.5 * yaw_rad), math.sin(0.5 * yaw_rad)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def ned_to_body(vec_ned, roll_rad: float, pitch_rad: float, yaw_rad: float):
    """A NED vector in body FRD axes (the transpose of the 3-2-1 body → NED rotation)."""
    cr, sr = math.cos(roll_rad), math.sin(roll_rad)
    cp, sp = math.cos(pitch_rad), math.sin(pitch_rad)
    cy, sy = math.cos(yaw_rad), math.sin(yaw_rad)
    n, e, d = vec_ned
    x = cp * cy * n + cp * sy * e - sp * d
    y = (sr * sp * cy - cr * sy) * n + (sr * sp * sy + cr * cy) * e + sr * cp * d
    z = (cr * sp * cy + sr * sy) * n + (cr * sp * sy - sr * cy) * e + cr * cp * d
    return (x, y, z)


@dataclass(frozen=True)
class Launcher:
    """The launcher: exit speed = the trim speed; ``accel_m_s2`` [m/s²] horizontal push;
    ``height_m`` [m] above the ground."""

    accel_m_s2: float = DEFAULT_LAUNCH_ACCEL_M_S2
    height_m: float = DEFAULT_LAUNCH_HEIGHT_M

    def __post_init__(self) -> None:
        if not (math.isfinite(self.accel_m_s2) and 5.0 <= self.accel_m_s2 <= 200.0):
            raise InputError(f"launch acceleration must be 5..200 m/s^2, got {self.accel_m_s2!r}")
        if not (math.isfinite(self.height_m) and 0.5 <= self.height_m <= 100.0):
            raise InputError(f"launcher height must be 0.5..100 m, got {self.height_m!r}")


class ArduPilotPhysics:
    """The co-simulation as ArduPilot's JSON physics (module docstring).

    Args:
        airframe: the JSBSim airframe (the bioflex aircraft; for ``native`` the exported
            native aircraft).
        wing: the elastic wing (None for ``native``).
        model: rigid, coupled, qsd or native.
        speed_m_s: trim and launcher exit speed [m/s].
        altitude_m: launch altitude [m above sea level, ISA].
        dt_s: the co-simulation step [s] (ArduPilot adopts 1/dt as its physics rate).
        gust: the gust (None: still air); gust_at_s: its start [s after the launch];
        gust_repeat: after every launch (default: once per session).
        launcher: :class:`Launcher`.
        record_every: keep every n-th frame in :attr:`records` (0: none).
        aero: the wing's strips, ``quasi-steady`` or ``unsteady`` (coupled model, ``wing`` a
            WingBuild); compiled: the coupled step's compiled kernel (False: its Python step);
            both go to :class:`~bioflex_jsb.runtime.coupled_step.CoupledStep` as they are,
            and :meth:`summary` says which step runs (:attr:`step_kind`).
        sensors: the aircraft's sensor stations (None: the wing build's, an aircraft
            definition's ``[sensors]``): every one is logged (its channels in the run
            topics' rows, its own topic), the autopilot's IMU is sent (module docstring).
        span: ``half`` (default) or ``full``: both wing halves (``wing`` a WingBuild), the
            ailerons ArduPlane flies loading the antisymmetric modes through JSBSim's
            flight controls; ``aileron`` the strips' surface (None: none).
    """

    def __init__(self, airframe: Airframe, wing: ElasticWingModel | WingBuild | None,
                 model: str, speed_m_s: float = 15.0, altitude_m: float = 0.0,
                 dt_s: float = DEFAULT_DT_S, gust: GustSpec | None = None,
                 gust_at_s: float = 60.0, launcher: Launcher | None = None,
                 record_every: int = 8, gust_repeat: bool = False,
                 aero: str = "quasi-steady", compiled: bool = True,
                 sensors: Sensors | None = None,
                 channels: tuple[Channel, ...] = CHANNEL_MAP, span: str = "half",
                 aileron=None) -> None:
        if not (math.isfinite(gust_at_s) and gust_at_s >= 0.0):
            raise InputError(f"gust start must be >= 0 s after the launch, got {gust_at_s!r}")
        if not is_whole(record_every) or record_every < 0:
            raise InputError(f"record_every must be an integer >= 0, got {record_every!r}")
        self.airframe = airframe
        self.wing_model = wing
        self.model = model
        # both wing halves (CoupledStep's span, aileron): the ailerons ArduPlane flies load
        # the antisymmetric modes (docs/lateral.md, "Both halves in the co-simulation")
        self.span, self.aileron = span, aileron
        self.speed_m_s = float(speed_m_s)
        self.altitude_m = float(altitude_m)
        self.launcher = launcher or Launcher()
        self.gust_spec = gust if gust is not None and gust.kind != "none" else None
        self.gust_at_s = float(gust_at_s)
        self.record_every = record_every
        self.gust_repeat = bool(gust_repeat)
        self.aero = aero
        self.compiled = bool(compiled)
        self.channels = tuple(channels)  # the servo map (aircraft_channels: another's)
        self._gust_applied = False  # the gust has begun in a flight of this session
        self._controls: list[Callable[[float], None]] = []
        self.stops: list[dict] = []  # valid-range stops: reason, time [s]
        self.launches = 0
        self.restarts = 0  # ArduPilot restarts (reset())
        self.grounded = False  # stopped: on the launcher until ArduPilot restarts
        self.events: list[tuple[float, str, str]] = []  # (session time [s], level, text)
        self._pending_events: list[tuple[float, str, str]] = []
        self.on_event: Callable[[float, str, str], None] | None = None
        self.records: list[tuple[float, ...]] = []
        self._commands_of: tuple[tuple[int, ...] | None, tuple[float, ...]] = (None, ())
        self._log = None  # RunLog (log_to)
        self._autopilot_log = None
        # the last frame's flight rows: (step index since the start or restart, row)
        self._step_rows: list[tuple[int, tuple[float, ...]]] = []
        self._t_offset_s = 0.0  # session time at ArduPilot's last restart [s]
        self._frames_seen = 0
        self._flown_before_s = 0.0  # flight time of the flights before this one [s]
        if sensors is None:
            sensors = wing.sensors if isinstance(wing, WingBuild) else NO_SENSORS
        modes = wing.modes if isinstance(wing, WingBuild) else None
        self.sensors = sensors
        self._sensor_set = SensorSet(sensors, modes, _flown_modes(wing)) if sensors else None
        # the autopilot's IMU alone (its own noise stream: read once per reply)
        self.autopilot_imu = sensors.autopilot_imu
        self._autopilot = AutopilotImu(self.autopilot_imu, modes, _flown_modes(wing), dt_s)
        self._imu_sent: tuple[int, tuple, tuple] | None = None  # (frame, accel, gyro)
        self.core: CoupledStep = None  # type: ignore[assignment]
        self._new_core(dt_s)
        self.dt_s = self.core.dt_s
        self.record_names = RECORD_HEAD + self.core.names
        self._nan_row = (math.nan,) * len(self.core.names)
        self._last_row: tuple[float, ...] = self._nan_row
        self._last_w_g = 0.0
        self.pwm_us: tuple[int, ...] = ()
        self.frame_k = 0  # co-simulation steps since the start (or ArduPilot's last restart)
        self.frame_steps = 1  # steps the last frame advanced (k: links/ardupilot_rate.py)
        self.frame_rate = FrameRate(self.dt_s)
        self.gust_report: dict[str, float] = {}
        self._to_rest()

    # -- the aircraft on the launcher / in flight -------------------------------------------
    def _new_core(self, dt_s: float) -> None:
        """A fresh coupled step: trimmed at the exit speed, the wing undeformed, the ground
        ``launcher.height_m`` below; the control writers and the readers of the reply."""
        if self.core is not None:
            self._flown_before_s += self.core.k * self.core.dt_s
            self.core.release()
        core = CoupledStep(self.airframe, self.wing_model, self.model, self.speed_m_s,
                           self.altitude_m, dt_s, compiled=self.compiled, aero=self.aero,
                           sensors=self._sensor_set,
                           **({} if self.span == "half" else {"span": self.span,
                                                              "aileron": self.aileron}))
        self.core = core
        self._autopilot.dt_s = core.dt_s
        self._autopilot.follow(core)  # the wing at rest before the flight (both halves too)
        a = self.airframe
        node = a.property_node
        self._h_launch_m = core.get["h"]() * U.M_PER_FT
        a["position/terrain-elevation-asl-ft"] = (
            (self._h_launch_m - self.launcher.height_m) * U.FT_PER_M)
        self._lat0 = core.get["lat"]()
        self._lon0 = core.get["lon"]()
        self._theta0 = core.get["theta"]()
        # the launcher pushes along the trim's velocity over ground (NED): the hand-over to
        # JSBSim is continuous in velocity and position
        v_exit = tuple(core.get[c]() * U.M_PER_FT for c in ("vn", "ve", "vd"))
        speed = math.sqrt(sum(c * c for c in v_exit))
        self._exit_speed_m_s = speed
        self._exit_dir = tuple(c / speed for c in v_exit)
        self.dt_s = core.dt_s
        # where the stroke ends (NED from the launch point) [m]: the flight's position offset
        self._stroke_ned_m = tuple(self.stroke_m * c for c in self._exit_dir)
        s2 = math.sin(self._lat0) ** 2
        r_meridian = WGS84_A_M * (1 - WGS84_E2) / (1 - WGS84_E2 * s2) ** 1.5
        r_normal = WGS84_A_M / math.sqrt(1 - WGS84_E2 * s2)
        self._m_per_rad_n = r_meridian + self._h_launch_m
        self._m_per_rad_e = (r_normal + self._h_launch_m) * math.cos(self._lat0)
        self._fx, self._fy, self._fz = (node(f"forces/fb{c}-total-lbs").get_double_value
                                        for c in "xyz")
        self._mass = node("inertia/mass-slugs").get_double_value
        self._vt = node("velocities/vt-fps").get_double_value
        writers = []
        for ch in self.channels:
            if ch.index == THROTTLE_CHANNEL:
                engines = [node(f"{ch.prop}[{i}]").set_double_value
                           for i in range(a.engine_count)]

                def write(x: float, engines=engines) -> None:
                    for w in engines:
                        w(x)
                writers.append(write)
            else:
                writers.append(node(ch.prop).set_double_value)
        self._controls = writers
        self._written_pwm: tuple[int, ...] | None = None  # the trim's controls are in now
        blows = self.gust_spec is not None and (self.gust_repeat or not self._gust_applied)
        self.gust = None if not blows else GustField(
            self.gust_spec, self.speed_m_s, self.gust_at_s, self.gust_at_s + 600.0,
            core.dt_s)
        self._gust_steps = (-1, -1)
        self._gust_end_k = -1
        if blows:
            k0 = math.ceil(self.gust_at_s / core.dt_s - 1e-9)
            length_s = (self.gust_spec.length_m / self.speed_m_s
                        if self.gust_spec.kind == "1cos" else 600.0)
            self._gust_steps = (k0, k0 + int(round((length_s + GUST_DECAY_S) / core.dt_s)))
            self._gust_end_k = k0 + int(round(length_s / core.dt_s))
        core.prepare(0.0)

    @property
    def step_kind(self) -> str:
        """Which coupled step flies: ``compiled kernel`` or ``python`` (None for rest)."""
        return "compiled kernel" if self.core.compiled else "python"

    def event(self, level: str, text: str) -> None:
        """Report ``text`` (level INFO, WARNING or ERROR) at the session time now; written
        to the log and ``on_event`` by :meth:`flush_events` (after the frame in progress)."""
        self._pending_events.append((self.session_t_s, level, text))

    def flush_events(self) -> None:
        """Log and hand on the events raised since the last call."""
        pending, self._pending_events = self._pending_events, []
        for t, level, text in pending:
            self.events.append((t, level, text))
            if self._log is not None:
                self._log.event(t, level, text)
            if self.on_event is not None:
                self.on_event(t, level, text)

    def _to_rest(self) -> None:
        self.phase = REST
        self._throttle_hold_k = 0  # frames with the launch signalled (throttle or switch)
        self._stroke_k = 0

    @property
    def t_s(self) -> float:
        """Physics time [s] (the reply's timestamp)."""
        return self.frame_k * self.dt_s

    @property
    def session_t_s(self) -> float:
        """Session time [s]: the physics time, continued across ArduPilot restarts (the
        log's time axis)."""
        return self._t_offset_s + self.frame_k * self.dt_s

    @property
    def launch_hold_steps(self) -> int:
        """Steps of the launch signal (throttle or switch) that fire the launcher."""
        return max(1, math.ceil(LAUNCH_HOLD_S / self.dt_s - 1e-9))

    @property
    def stroke_steps(self) -> int:
        """Steps of the launcher's push (the exit speed is reached exactly at the last)."""
        return max(1, math.ceil(self._exit_speed_m_s / (self.launcher.accel_m_s2 * self.dt_s)))

    @property
    def launch_accel_m_s2(self) -> float:
        """The push actually applied [m/s²]: exit speed over a whole number of steps."""
        return self._exit_speed_m_s / (self.stroke_steps * self.dt_s)

    @property
    def stroke_m(self) -> float:
        """Length of the push [m]."""
        return 0.5 * self._exit_speed_m_s * self.stroke_steps * self.dt_s

    # -- JsonPhysics ------------------------------------------------------------------------
    def reset(self) -> None:
        """ArduPilot restarted: back on the launcher at rest, time 0, the launcher armed."""
        self.restarts += 1
        self.grounded = False
        self._new_core(self.dt_s)
        self._to_rest()
        self._t_offset_s += self.frame_k * self.dt_s
        self.frame_k = 0
        self.frame_rate.reset()

    def step(self, pwm_us: tuple[int, ...], frame_rate_hz: int) -> None:
        """One ArduPilot frame: k steps of ``dt_s`` with these servo outputs [µs, servo 1
        first] held over them, k from ArduPilot's ``frame_rate_hz`` [Hz]
        (:class:`~bioflex_jsb.links.ardupilot_rate.FrameRate`; a change of k is an event)."""
        k, note = self.frame_rate.steps(frame_rate_hz)
        if note is not None:
            self.event(*note)
        self.pwm_us = pwm_us
        self.frame_steps = k
        self._step_rows = []
        for _ in range(k):
            self._step(pwm_us)

    def _step(self, pwm_us: tuple[int, ...]) -> None:
        """One co-simulation step of ``dt_s`` (at rest, on the launcher or in flight)."""
        self.frame_k += 1
        if self.phase == REST:
            thr = pwm_us[THROTTLE_CHANNEL] if len(pwm_us) > THROTTLE_CHANNEL else 0
            switch = pwm_us[LAUNCH_SWITCH_CHANNEL] if len(pwm_us) > LAUNCH_SWITCH_CHANNEL else 0
            lo, hi = LAUNCH_SWITCH_US
            ready = thr > LAUNCH_THROTTLE_US or lo <= switch <= hi
            self._throttle_hold_k = self._throttle_hold_k + 1 if ready and not self.grounded \
                else 0
            if self._throttle_hold_k >= self.launch_hold_steps:
                self.phase = LAUNCH
                self.launches += 1
                self._stroke_k = 0
                self._launch_t_s = self.t_s
                self.event("INFO", f"launch {self.launches} at {self.t_s:.3f} s of ArduPilot's "
                           f"time ({self.step_kind} step, {self.aero} wing)")
            return
        if self.phase == LAUNCH:
            self._stroke_k += 1
            if self._stroke_k >= self.stroke_steps:
                self.phase = FLIGHT
            return
        core = self.core
        if pwm_us != self._written_pwm:  # ArduPlane's outputs change at its loop rate
            # (50-400 Hz) against 960 frames a second: the same PWM is not written again
            for ch, write in zip(self.channels, self._controls, strict=True):
                write(ch.value(pwm_us[ch.index]) if ch.index < len(pwm_us) else ch.value(0))
            self._written_pwm = pwm_us
        k = core.k
        w_g = self.gust.at_step(k) if self.gust is not None else 0.0
        self._autopilot.before_step(core.eta, core.eta_dot)
        self._last_row = row = core.advance(w_g)
        if self._log is not None:
            self._step_rows.append((self.frame_k - 1, row))
        self._last_w_g = w_g
        k0, k1 = self._gust_steps
        if k0 <= k <= k1:
            self._gust_applied = True
            self._track_gust(k, k0, k1)
        if core.stopped:
            flight_s = core.k * core.dt_s
            self.stops.append({"reason": core.stopped, "time_s": self.t_s,
                               "session_s": self.session_t_s, "flight_s": flight_s})
            self._new_core(self.dt_s)
            self._to_rest()
            self.grounded = True
            self._last_row = self._nan_row
            self.event("ERROR", f"valid-range stop after {flight_s:.2f} s of flight: "
                       f"{core.stopped}; the aircraft is back on the launcher at rest and "
                       "stays there until ArduPilot restarts")

    def _track_gust(self, k: int, k0: int, k1: int) -> None:
        rep = self.gust_report
        eta1 = float(self.core.eta[0])
        if k == k0:
            rep.clear()
            rep.update(start_time_s=self.t_s, start_flight_s=k * self.core.dt_s,
                       eta1_peak_rad=0.0, eta1_peak_time_s=math.nan,
                       eta1_at_start_rad=eta1, eta1_change_peak_rad=0.0,
                       eta1_change_peak_time_s=math.nan, eta1_change_peak_at_window_end=False,
                       w_g_peak_m_s=0.0, eta1_min_in_gust_rad=eta1, eta1_max_in_gust_rad=eta1,
                       eta1_change_peak_in_gust_rad=0.0, n_z_min_in_gust=math.inf,
                       n_z_max_in_gust=-math.inf)
        if not rep:
            return
        if abs(eta1) > abs(rep["eta1_peak_rad"]):
            rep["eta1_peak_rad"] = eta1
            rep["eta1_peak_time_s"] = self.t_s
        change = eta1 - rep["eta1_at_start_rad"]
        if abs(change) > abs(rep["eta1_change_peak_rad"]):
            rep["eta1_change_peak_rad"] = change
            rep["eta1_change_peak_time_s"] = self.t_s
            if k == k1:  # still growing when the search stops: no peak of the gust's
                rep["eta1_change_peak_at_window_end"] = True
                self.event("WARNING", (
                    f"eta1's largest change after the gust, {change:.4g} rad, is at the end "
                    f"of its search ({GUST_DECAY_S:g} s after the gust): a manoeuvre's, not "
                    "the gust's peak, and it moves with the manoeuvre's timing; the gust's "
                    f"own is eta1_change_peak_in_gust_rad "
                    f"({rep['eta1_change_peak_in_gust_rad']:.4g} rad)"))
        if k <= self._gust_end_k:  # while the gust blows (1-cosine: its length)
            rep["eta1_min_in_gust_rad"] = min(rep["eta1_min_in_gust_rad"], eta1)
            rep["eta1_max_in_gust_rad"] = max(rep["eta1_max_in_gust_rad"], eta1)
            if abs(change) > abs(rep["eta1_change_peak_in_gust_rad"]):
                rep["eta1_change_peak_in_gust_rad"] = change
            n_z = self.core.get["nz"]()  # of the state the step reached
            rep["n_z_min_in_gust"] = min(rep["n_z_min_in_gust"], n_z)
            rep["n_z_max_in_gust"] = max(rep["n_z_max_in_gust"], n_z)
        if abs(self._last_w_g) > abs(rep["w_g_peak_m_s"]):
            rep["w_g_peak_m_s"] = self._last_w_g

    def state(self) -> JsonState:
        """The state after the last step, in ArduPilot's units and frames."""
        if self.phase == FLIGHT:
            return self._flight_state()
        theta = self._theta0
        if self.phase == REST:
            v = s = a = 0.0
        else:  # constant acceleration a along the exit direction u
            tau = self._stroke_k * self.dt_s
            a = self.launch_accel_m_s2
            v, s = a * tau, 0.5 * a * tau * tau
        u = self._exit_dir
        return JsonState(
            timestamp_s=self.t_s, gyro_rad_s=(0.0, 0.0, 0.0),
            accel_body_m_s2=ned_to_body((a * u[0], a * u[1], a * u[2] - G0_M_S2),
                                        0.0, theta, 0.0),
            position_ned_m=tuple(s * c for c in u), velocity_ned_m_s=tuple(v * c for c in u),
            quaternion=quaternion_from_euler(0.0, theta, 0.0), attitude_rad=(0.0, theta, 0.0),
            airspeed_m_s=v)

    def _flight_state(self) -> JsonState:
        get = self.core.get
        phi, theta = get["phi"](), get["theta"]()
        psi = math.remainder(get["psi"](), 2.0 * math.pi)
        s_n, s_e, s_d = self._stroke_ned_m
        north = (get["lat"]() - self._lat0) * self._m_per_rad_n + s_n
        east = math.remainder(get["lon"]() - self._lon0, 2.0 * math.pi) * self._m_per_rad_e + s_e
        down = self._h_launch_m - get["h"]() * U.M_PER_FT + s_d
        f = U.M_PER_FT
        accel, gyro = self.autopilot_imu_now()
        return JsonState(
            timestamp_s=self.t_s, gyro_rad_s=gyro, accel_body_m_s2=accel,
            position_ned_m=(north, east, down),
            velocity_ned_m_s=(get["vn"]() * f, get["ve"]() * f, get["vd"]() * f),
            quaternion=quaternion_from_euler(phi, theta, psi), attitude_rad=(phi, theta, psi),
            airspeed_m_s=self._vt() * f)

    def autopilot_imu_now(self) -> tuple[tuple[float, float, float],
                                         tuple[float, float, float]]:
        """(specific force [m/s²], rates [rad/s]) of the autopilot's IMU at the state the
        last step reached, in its axes (module docstring); read once per physics time (a
        resend repeats the sample, its noise too)."""
        key = (self.restarts, self.frame_k)
        if self._imu_sent is not None and self._imu_sent[0] == key:
            return self._imu_sent[1], self._imu_sent[2]
        core = self.core
        accel, gyro = self._autopilot.read(core.rigid_kinematics(-self._last_w_g * U.FT_PER_M),
                                           core.eta, core.eta_dot, self.t_s,
                                           core.model_rate_state)
        self._imu_sent = (key, accel, gyro)
        return accel, gyro

    # -- recording --------------------------------------------------------------------------
    def log_to(self, log) -> None:
        """Log every frame answered from now on into ``log`` (a
        :class:`~bioflex_jsb.sinks.mcap.RunLog`; module docstring); the caller closes it."""
        self._log = log
        self._autopilot_log = log.autopilot(self.model)

    def commands(self, pwm_us: tuple[int, ...]) -> tuple[float, ...]:
        """The four normalised commands (aileron, elevator, throttle, rudder) the channel map
        gives for ``pwm_us`` [µs] (:attr:`channels`); the last PWM's kept (ArduPlane's
        outputs change at its loop rate, 50-400 Hz, against 960 frames a second)."""
        last_pwm, last = self._commands_of
        if pwm_us == last_pwm:
            return last
        out = tuple(ch.value(pwm_us[ch.index]) if ch.index < len(pwm_us) else ch.value(0)
                    for ch in self.channels)
        self._commands_of = (pwm_us, out)
        return out

    def _log_frame(self, rec: FrameRecord) -> None:
        # the state the frame arrived at: before its steps (step, reset), the one repeated
        k = self.frame_k if rec.action == RESEND else self.frame_k - self.frame_steps
        t = self._t_offset_s + k * self.dt_s
        rows, self._step_rows = self._step_rows, []
        if rec.action == RESEND:
            rows = []
        names, sample = self.core.names, self._log.sample
        first = 0
        if rows and rows[0][0] == k:  # the frame's first step: its row, then the frame
            sample(self.model, t, dict(zip(names, rows[0][1], strict=True)))
            first = 1
        self._autopilot_log.frame(
            t, rec.frame_count, rec.frame_rate_hz, rec.pwm_us, self.commands(rec.pwm_us),
            ACTIONS.index(rec.action), PHASES.index(self.phase), rec.timestamp_s)
        for i, row in rows[first:]:  # the frame's further steps, each at its own start
            sample(self.model, self._t_offset_s + i * self.dt_s,
                   dict(zip(names, row, strict=True)))

    def on_frame(self, rec: FrameRecord) -> None:
        """The server's callback: log the frame (:meth:`log_to`); keep every
        ``record_every``-th frame, resends and resets in :attr:`records`."""
        if self._log is not None:
            self._log_frame(rec)
        self._frames_seen += 1
        if self._pending_events:
            self.flush_events()
        n = self.record_every
        if n == 0 or (rec.action not in (RESEND, RESET) and self._frames_seen % n):
            return
        pwm = tuple(float(rec.pwm_us[i]) if i < len(rec.pwm_us) else 0.0 for i in range(4))
        row = self._last_row if self.phase == FLIGHT else self._nan_row
        self.records.append((rec.timestamp_s, float(rec.frame_count),
                             float(ACTIONS.index(rec.action)), float(PHASES.index(self.phase)),
                             *pwm, self._last_w_g if self.phase == FLIGHT else 0.0, *row))

    def table(self) -> np.ndarray:
        """:attr:`records` as a (rows × :attr:`record_names`) array."""
        return np.asarray(self.records, dtype=float).reshape(-1, len(self.record_names))

    def summary(self) -> dict:
        """Counts, stops and the gust's η₁ peak (SI; JSON-ready)."""
        return {
            "model": self.model, "aero": self.aero, "step": self.step_kind,
            "speed_m_s": self.speed_m_s, "altitude_m": self.altitude_m,
            "dt_s": self.dt_s, "time_s": self.t_s, "session_s": self.session_t_s,
            "frame_steps": self.frame_steps, "frame_rate_hz": self.frame_rate.rate_hz,
            "phase": self.phase, "grounded": self.grounded,
            "flight_s": self.core.k * self.dt_s if self.phase == FLIGHT else 0.0,
            "flown_s": self._flown_before_s + self.core.k * self.dt_s,
            "launches": self.launches, "relaunches": max(0, self.launches - 1),
            "restarts": self.restarts, "stop_count": len(self.stops), "stops": list(self.stops),
            "launch_accel_m_s2": self.launch_accel_m_s2, "stroke_m": self.stroke_m,
            "gust": None if self.gust_spec is None else self.gust_spec.text(),
            "gust_at_s": self.gust_at_s, "gust_repeat": self.gust_repeat,
            "gust_applied": self._gust_applied,
            "gust_report": {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                            for k, v in self.gust_report.items()},
        }


def _flown_modes(wing) -> int | None:
    """The modes the wing flies (its model's), None for the native wing (its own count)."""
    if isinstance(wing, WingBuild):
        return wing.model.n_modes
    return None if wing is None else wing.n_modes
