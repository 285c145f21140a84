"""COMMAND_LONG / COMMAND_INT of the SITL vehicle: each answered by exactly one COMMAND_ACK.

Both messages are first put into one form, :class:`Command` (:func:`command_from_message`):
param1..param4 as sent; x, y the position (latitude, longitude [deg]: COMMAND_LONG's param5,
param6, COMMAND_INT's degE7 integers × 1e-7, INT32_MAX: NaN, not given); z the altitude
[m] (param7 / z) in ``frame`` (COMMAND_INT's frame; COMMAND_LONG: MAV_FRAME_GLOBAL, i.e.
AMSL). The handlers read only that form, so every command means the same in either message.

Results: ACCEPTED when done; DENIED with a STATUSTEXT naming the command, the field, the value
and the range accepted when a value is out of range or not a number (NaN, ±inf) where a
number is needed, or when the vehicle refuses (disarm in flight without force, no mission);
UNSUPPORTED for any other command. A refusal is also an event of the session log
(``Vehicle.refused``). Parameters a command does not use are ignored whatever they hold
(MAVLink leaves them reserved: 0 or NaN).

Positions (x, y; COMMAND_INT in the frames of :data:`POSITION_FRAMES`, any other frame is
DENIED): latitude −90..90°, longitude −180..180°, finite; (0, 0) and (NaN, NaN) mean "no
position". Altitudes z: GLOBAL(_INT) AMSL, GLOBAL_RELATIVE_ALT(_INT)
and GLOBAL_TERRAIN_ALT(_INT) above home (the ground is flat); NaN: keep the altitude; the
result must lie in the vehicle's altitude range (home's ground + 20 … + 1500 m).

========================================= ================================================
MAV_CMD_SET_MESSAGE_INTERVAL (511)        param1 message id (integer), param2 interval
                                          [µs]: −1 off, 0 the default, > 0
MAV_CMD_GET_MESSAGE_INTERVAL (510)        MESSAGE_INTERVAL (−1: off, 0: not available)
MAV_CMD_REQUEST_MESSAGE (512)             the message param1 once (also PROTOCOL_VERSION,
                                          AUTOPILOT_VERSION, HOME_POSITION)
MAV_CMD_REQUEST_PROTOCOL_VERSION (519)    PROTOCOL_VERSION
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES    AUTOPILOT_VERSION
MAV_CMD_COMPONENT_ARM_DISARM (400)        param1 1 arm, 0 disarm (in flight only with
                                          param2 21196: the motor stops; other values,
                                          NaN too: no force)
MAV_CMD_DO_SET_MODE (176)                 param1 base mode with CUSTOM_MODE_ENABLED,
                                          param2 ArduPlane mode number
MAV_CMD_NAV_RETURN_TO_LAUNCH (20)         RTL
MAV_CMD_NAV_LOITER_UNLIM (17)             LOITER about x, y (none: here), param3 radius
                                          [m] (0/NaN: LOIT_RAD_M; |r| 20..1000, < 0
                                          counter-clockwise); z ignored (altitude kept)
MAV_CMD_DO_CHANGE_SPEED (178)             param2 airspeed [m/s] 12..22 (< 0: unchanged)
MAV_CMD_DO_CHANGE_ALTITUDE (186)          param1 altitude [m], param2 its frame (0 AMSL,
                                          3/10 relative to home)
MAV_CMD_DO_REPOSITION (192)               GUIDED to x, y at z (NaN: kept); param3 loiter
                                          radius there (0/NaN: LOIT_RAD_M; 20..1000 m),
                                          param4 loiter direction (0/NaN clockwise, 1
                                          counter-clockwise); param1 (speed) and param2
                                          (flags) ignored: the airspeed target holds
MAV_CMD_DO_SET_HOME (179)                 param1 1: here; 0: x, y, z (home's ranges:
                                          Vehicle.set_home)
MAV_CMD_MISSION_START (300)               AUTO from param1 (0 or NaN: the first item)
MAV_CMD_DO_SET_MISSION_CURRENT (224)      the mission's current item param1
========================================= ================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pymavlink.dialects.v20 import common as M

from bioflex_jsb.links.mavlink_mission import AMSL_FRAMES
from bioflex_jsb.links.mavlink_telemetry import (
    DEFAULT_RATES_HZ,
    ON_REQUEST,
    PROTOCOL_VERSION_ID,
)

FORCE_DISARM = 21196
POSITION_FRAMES = frozenset({
    M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_INT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
    M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, M.MAV_FRAME_GLOBAL_TERRAIN_ALT,
    M.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT})
RELATIVE_FRAMES = POSITION_FRAMES - AMSL_FRAMES
MAX_MESSAGE_ID = 16_777_215  # MAVLink 2 message ids are 24-bit
INT32_MAX = 2**31 - 1  # COMMAND_INT x, y: "not given" (as NaN in COMMAND_LONG)
LOITER_RADIUS_RANGE_M = (20.0, 1000.0)  # as LOIT_RAD_M
ANSWERED = object()  # a handler that sent its COMMAND_ACK itself (before its reply)


@dataclass(frozen=True)
class Command:
    """One command in the form both messages are put into (module docstring): ``x``, ``y``
    latitude, longitude [deg] (NaN when COMMAND_LONG sent NaN); ``z`` [m] in ``frame``
    (a MAV_FRAME); ``kind`` the message type; ``source`` its (system, component)."""

    command: int
    param1: float
    param2: float
    param3: float
    param4: float
    x: float
    y: float
    z: float
    frame: int
    kind: str
    source: tuple[int, int]

    @property
    def name(self) -> str:
        entry = M.enums["MAV_CMD"].get(self.command)
        return entry.name.removeprefix("MAV_CMD_") if entry is not None else str(self.command)


def command_from_message(msg) -> Command:
    """The :class:`Command` of a COMMAND_LONG or COMMAND_INT."""
    src = (msg.get_srcSystem(), msg.get_srcComponent())
    p = (float(msg.param1), float(msg.param2), float(msg.param3), float(msg.param4))
    if msg.get_type() == "COMMAND_INT":
        x, y = (math.nan if v == INT32_MAX else v * 1e-7 for v in (int(msg.x), int(msg.y)))
        return Command(int(msg.command), *p, x, y, float(msg.z), int(msg.frame),
                       "COMMAND_INT", src)
    return Command(int(msg.command), *p, float(msg.param5), float(msg.param6),
                   float(msg.param7), M.MAV_FRAME_GLOBAL, "COMMAND_LONG", src)


class Denied(Exception):
    """A command refused: its one-line reason (the STATUSTEXT)."""


def integer(c: Command, label: str, value: float, lo: int, hi: int) -> int:
    """``value`` as an integer in lo..hi, or Denied naming ``label``."""
    if not (math.isfinite(value) and value == int(value) and lo <= value <= hi):
        raise Denied(f"{c.name}: {label} {value:g} is not an integer in {lo}..{hi}")
    return int(value)


def finite(c: Command, label: str, value: float) -> float:
    if not math.isfinite(value):
        raise Denied(f"{c.name}: {label} {value:g} is not a finite number")
    return value


def position(c: Command, required: bool) -> tuple[float, float] | None:
    """(lat_rad, lon_rad) of x, y; None for "no position" (module docstring), Denied when
    ``required`` and absent, or out of range."""
    if c.kind == "COMMAND_INT" and c.frame not in POSITION_FRAMES:
        raise Denied(f"{c.name}: frame {c.frame} unsupported (GLOBAL, GLOBAL_RELATIVE_ALT, "
                     "GLOBAL_TERRAIN_ALT and their _INT forms)")
    lat, lon = c.x, c.y
    if (lat == 0.0 and lon == 0.0) or (math.isnan(lat) and math.isnan(lon)):
        if required:
            raise Denied(f"{c.name}: no position (x, y = 0, 0)")
        return None
    if not (math.isfinite(lat) and -90.0 <= lat <= 90.0):
        raise Denied(f"{c.name}: latitude {lat:g} deg outside -90..90")
    if not (math.isfinite(lon) and -180.0 <= lon <= 180.0):
        raise Denied(f"{c.name}: longitude {lon:g} deg outside -180..180")
    return math.radians(lat), math.radians(lon)


def altitude_amsl(c: Command, alt: float, frame: int, state, vehicle,
                  label: str = "z altitude") -> float | None:
    """``alt`` [m] in ``frame`` as m AMSL (relative frames: above home), None for NaN
    (keep); Denied for ±inf, an unknown frame or outside the vehicle's altitude range."""
    if math.isnan(alt):
        return None
    finite(c, label, alt)
    if frame not in POSITION_FRAMES:
        raise Denied(f"{c.name}: altitude frame {frame} unsupported (0, 3, 10 or _INT forms)")
    amsl = alt if frame in AMSL_FRAMES else state.home_altitude_m + alt
    lo, hi = vehicle.altitude_range_m
    if not lo <= amsl <= hi:
        ground = vehicle.ground_altitude_m
        raise Denied(f"{c.name}: {label} {alt:g} m ({amsl:.0f} m AMSL) outside "
                     f"{lo:.0f}..{hi:.0f} m AMSL (ground + {lo - ground:.0f}..+"
                     f"{hi - ground:.0f} m)")
    return amsl


def loiter_radius(c: Command, value: float, signed: bool) -> float:
    """A loiter radius [m]: 0 or NaN → 0 (the vehicle's LOIT_RAD_M); else |value| within
    LOITER_RADIUS_RANGE_M (negative allowed when ``signed``: counter-clockwise)."""
    if math.isnan(value) or value == 0.0:
        return 0.0
    lo, hi = LOITER_RADIUS_RANGE_M
    r = abs(value) if signed else value
    if not (math.isfinite(r) and lo <= r <= hi):
        sign = "±" if signed else ""
        raise Denied(f"{c.name}: param3 radius {value:g} m outside {sign}{lo:g}..{hi:g} "
                     "(0 or NaN: LOIT_RAD_M)")
    return value


def _nan_0(value: float) -> float:
    return 0.0 if math.isnan(value) else value


class CommandHandler:
    def __init__(self, link, vehicle) -> None:
        self.link, self.vehicle = link, vehicle
        self._handlers = {
            M.MAV_CMD_SET_MESSAGE_INTERVAL: self._set_interval,
            M.MAV_CMD_GET_MESSAGE_INTERVAL: self._get_interval,
            M.MAV_CMD_REQUEST_MESSAGE: self._request,
            M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: self._request,
            M.MAV_CMD_REQUEST_PROTOCOL_VERSION: self._request,
        }
        self._vehicle_handlers = {
            M.MAV_CMD_COMPONENT_ARM_DISARM: self._arm,
            M.MAV_CMD_DO_SET_MODE: self._set_mode,
            M.MAV_CMD_NAV_RETURN_TO_LAUNCH: lambda c, s: self.vehicle.set_mode(11),
            M.MAV_CMD_NAV_LOITER_UNLIM: self._loiter,
            M.MAV_CMD_DO_CHANGE_SPEED: self._change_speed,
            M.MAV_CMD_DO_CHANGE_ALTITUDE: self._change_altitude,
            M.MAV_CMD_DO_REPOSITION: self._reposition,
            M.MAV_CMD_DO_SET_HOME: self._set_home,
            M.MAV_CMD_MISSION_START: self._mission_start,
            M.MAV_CMD_DO_SET_MISSION_CURRENT: self._mission_current,
        }

    @property
    def supported(self) -> frozenset[int]:
        """The commands answered other than UNSUPPORTED (with a vehicle)."""
        return frozenset(self._handlers) | frozenset(self._vehicle_handlers)

    def _ack(self, c: Command, result: int) -> None:
        self.link.send(self.link.mav.command_ack_encode(c.command, result, 0, 0, *c.source))

    def handle(self, msg, state) -> None:
        """Answer the COMMAND_LONG / COMMAND_INT ``msg``: one COMMAND_ACK, after any reply
        (MESSAGE_INTERVAL, the requested message) and after the STATUSTEXT of a refusal."""
        c = command_from_message(msg)
        handler = self._handlers.get(c.command)
        if handler is None and self.vehicle is not None:
            handler = self._vehicle_handlers.get(c.command)
        if handler is None:
            self._ack(c, M.MAV_RESULT_UNSUPPORTED)
            return
        try:
            reason = handler(c, state)
        except Denied as exc:
            reason = str(exc)
        if reason is ANSWERED:
            return
        if isinstance(reason, int):  # a MAV_RESULT of the handler's own
            self._ack(c, reason)
        elif reason is None:
            self._ack(c, M.MAV_RESULT_ACCEPTED)
        else:
            self.refuse(reason if reason.startswith(c.name) else f"{c.name}: {reason}")
            self._ack(c, M.MAV_RESULT_DENIED)

    def refuse(self, text: str) -> None:
        """A refusal's STATUSTEXT (WARNING), sent now, and its event in the session log."""
        self.link.statustext(M.MAV_SEVERITY_WARNING, text)
        if self.vehicle is not None:
            self.vehicle.refused(text)

    # -- the link's own commands ----------------------------------------------------------
    def _set_interval(self, c: Command, state):
        mid = integer(c, "param1 message id", c.param1, 0, MAX_MESSAGE_ID)
        us = finite(c, "param2 interval [us]", c.param2)
        if us < 0.0 and us != -1.0:
            raise Denied(f"{c.name}: param2 interval {us:g} us: -1 (off), 0 (default) or > 0")
        if mid not in DEFAULT_RATES_HZ or mid == M.MAVLINK_MSG_ID_HEARTBEAT:
            return M.MAV_RESULT_UNSUPPORTED
        hz = 0.0 if us < 0 else DEFAULT_RATES_HZ[mid] if us == 0 else 1e6 / us
        self.link.set_rate(mid, hz)
        return None

    def _get_interval(self, c: Command, state):
        mid = integer(c, "param1 message id", c.param1, 0, MAX_MESSAGE_ID)
        interval = self.link.intervals_s.get(mid)
        us = 0 if interval is None else -1 if interval <= 0.0 else int(round(interval * 1e6))
        self._ack(c, M.MAV_RESULT_ACCEPTED)
        self.link.send(self.link.mav.message_interval_encode(mid, us))
        return ANSWERED

    def _request(self, c: Command, state):
        if c.command == M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES:
            mid = M.MAVLINK_MSG_ID_AUTOPILOT_VERSION
        elif c.command == M.MAV_CMD_REQUEST_PROTOCOL_VERSION:
            mid = PROTOCOL_VERSION_ID
        else:
            mid = integer(c, "param1 message id", c.param1, 0, MAX_MESSAGE_ID)
        if mid not in ON_REQUEST and mid not in DEFAULT_RATES_HZ:
            return M.MAV_RESULT_UNSUPPORTED
        self._ack(c, M.MAV_RESULT_ACCEPTED)
        self.link.send_message(mid, state)
        return ANSWERED

    # -- the vehicle's commands -----------------------------------------------------------
    def _arm(self, c: Command, state):
        arm = integer(c, "param1 (1 arm, 0 disarm)", c.param1, 0, 1)
        # param2 21196 forces a disarm in flight; anything else (MAVSDK sends NaN) does not
        return self.vehicle.arm(arm == 1, c.param2 == FORCE_DISARM)

    def _set_mode(self, c: Command, state):
        base = integer(c, "param1 base mode", c.param1, 0, 255)
        if not base & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
            raise Denied(f"{c.name}: only custom (ArduPlane) modes (param1 with flag 1)")
        return self.vehicle.set_mode(integer(c, "param2 custom mode", c.param2, 0, 2**32 - 1))

    def _loiter(self, c: Command, state):
        radius = loiter_radius(c, c.param3, signed=True)
        pos = position(c, required=False)
        lat, lon = pos if pos is not None else (None, None)
        return self.vehicle.loiter_at(lat, lon, radius)

    def _change_speed(self, c: Command, state):
        speed = finite(c, "param2 airspeed [m/s]", c.param2)
        return None if speed < 0 else self.vehicle.change_speed(speed)

    def _change_altitude(self, c: Command, state):
        frame = integer(c, "param2 frame", c.param2, 0, 255)
        amsl = altitude_amsl(c, finite(c, "param1 altitude", c.param1), frame, state,
                             self.vehicle, "param1 altitude")
        return self.vehicle.change_altitude(amsl)

    def _reposition(self, c: Command, state):
        radius = loiter_radius(c, c.param3, signed=False)
        if not (math.isnan(c.param4) or c.param4 in (0.0, 1.0)):
            raise Denied(f"{c.name}: param4 loiter direction {c.param4:g}: 0 or NaN "
                         "(clockwise) or 1 (counter-clockwise)")
        pos = position(c, required=True)
        amsl = altitude_amsl(c, c.z, c.frame, state, self.vehicle)
        return self.vehicle.reposition(*pos, amsl, radius, c.param4 != 1.0)

    def _set_home(self, c: Command, state):
        here = integer(c, "param1 (1: here, 0: x, y, z)", c.param1, 0, 1)
        v = self.vehicle
        if here:
            return v.set_home(state.latitude_rad, state.longitude_rad, state.home_altitude_m)
        pos = position(c, required=True)
        alt = finite(c, "z altitude", c.z)
        if c.frame in RELATIVE_FRAMES:
            alt += state.home_altitude_m
        return v.set_home(*pos, alt)

    def _mission_start(self, c: Command, state):
        # NaN: not given (MAVLink's unused value), as 0
        first = integer(c, "param1 first item", _nan_0(c.param1), 0, 65535)
        last = integer(c, "param2 last item", _nan_0(c.param2), 0, 65535)
        return self.vehicle.mission_start(first, last)

    def _mission_current(self, c: Command, state):
        return self.vehicle.set_mission_current(integer(c, "param1 item", c.param1, 0, 65535))
