"""COMMAND_LONG / COMMAND_INT of the SITL vehicle: each answered by one COMMAND_ACK.

ACCEPTED when done; DENIED with a STATUSTEXT naming the reason when the vehicle refuses
(a value out of range, disarm in flight without force, no mission); UNSUPPORTED for any
other command. Positions: COMMAND_INT x, y [degE7] in its frame; COMMAND_LONG params 5, 6
[deg], altitude param7 AMSL (MAV_FRAME_GLOBAL) unless COMMAND_INT says relative.

========================================= ================================================
MAV_CMD_SET_MESSAGE_INTERVAL (511)        param1 message id, param2 interval [µs]; 0 the
                                          default, −1 off
MAV_CMD_GET_MESSAGE_INTERVAL (510)        MESSAGE_INTERVAL (−1: off, 0: not available)
MAV_CMD_REQUEST_MESSAGE (512)             the message param1 once (also PROTOCOL_VERSION,
                                          AUTOPILOT_VERSION, HOME_POSITION)
MAV_CMD_REQUEST_PROTOCOL_VERSION (519)    PROTOCOL_VERSION
MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES    AUTOPILOT_VERSION
MAV_CMD_COMPONENT_ARM_DISARM (400)        param1 1 arm, 0 disarm (in flight only with
                                          param2 21196: the motor stops)
MAV_CMD_DO_SET_MODE (176)                 param1 base mode with CUSTOM_MODE_ENABLED,
                                          param2 ArduPlane mode number
MAV_CMD_NAV_RETURN_TO_LAUNCH (20)         RTL
MAV_CMD_NAV_LOITER_UNLIM (17)             LOITER about param5/6 (0, 0: here), param3
                                          radius [m] (< 0 counter-clockwise)
MAV_CMD_DO_CHANGE_SPEED (178)             param2 airspeed [m/s] (−1: unchanged)
MAV_CMD_DO_CHANGE_ALTITUDE (186)          param1 altitude [m], param2 frame (0 AMSL,
                                          3 relative to home)
MAV_CMD_DO_REPOSITION (192)               GUIDED to param5/6, altitude param7 (NaN: kept)
MAV_CMD_DO_SET_HOME (179)                 param1 1: here; else param5/6/7 (AMSL)
MAV_CMD_MISSION_START (300)               AUTO from param1 (0: the first item)
MAV_CMD_DO_SET_MISSION_CURRENT (224)      the mission's current item param1
========================================= ================================================
"""

from __future__ import annotations

import math

from pymavlink.dialects.v20 import common as M

from bioflex_jsb.links.mavlink_mission import AMSL_FRAMES
from bioflex_jsb.links.mavlink_telemetry import (
    DEFAULT_RATES_HZ,
    ON_REQUEST,
    PROTOCOL_VERSION_ID,
)

FORCE_DISARM = 21196
RELATIVE_FRAMES = frozenset({M.MAV_FRAME_GLOBAL_RELATIVE_ALT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT,
                             M.MAV_FRAME_GLOBAL_TERRAIN_ALT, M.MAV_FRAME_GLOBAL_TERRAIN_ALT_INT})


class CommandHandler:
    def __init__(self, link, vehicle) -> None:
        self.link, self.vehicle = link, vehicle

    def _ack(self, msg, result: int) -> None:
        self.link.send(self.link.mav.command_ack_encode(
            msg.command, result, 0, 0, msg.get_srcSystem(), msg.get_srcComponent()))

    def _done(self, msg, reason: str | None) -> None:
        if reason is None:
            self._ack(msg, M.MAV_RESULT_ACCEPTED)
        else:
            self.link.statustext(M.MAV_SEVERITY_WARNING, reason)
            self._ack(msg, M.MAV_RESULT_DENIED)

    @staticmethod
    def _position(msg):
        """(lat_rad, lon_rad) of params 5, 6, or None when both are 0 / NaN."""
        if msg.get_type() == "COMMAND_INT":
            lat, lon = msg.x * 1e-7, msg.y * 1e-7
        else:
            lat, lon = float(msg.param5), float(msg.param6)
        if not (math.isfinite(lat) and math.isfinite(lon)) or (lat == 0.0 and lon == 0.0):
            return None
        return math.radians(lat), math.radians(lon)

    def _altitude_amsl(self, msg, alt: float, state) -> float | None:
        if not math.isfinite(alt):
            return None
        frame = msg.frame if msg.get_type() == "COMMAND_INT" else M.MAV_FRAME_GLOBAL
        return alt if frame in AMSL_FRAMES else state.home_altitude_m + alt

    def handle(self, msg, state) -> None:
        cmd, link, v = msg.command, self.link, self.vehicle
        if cmd == M.MAV_CMD_SET_MESSAGE_INTERVAL:
            mid, interval_us = int(msg.param1), msg.param2
            if mid not in DEFAULT_RATES_HZ or mid == M.MAVLINK_MSG_ID_HEARTBEAT:
                self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
                return
            hz = (0.0 if interval_us < 0 else DEFAULT_RATES_HZ[mid] if interval_us == 0
                  else 1e6 / interval_us)
            link.set_rate(mid, hz)
            self._ack(msg, M.MAV_RESULT_ACCEPTED)
        elif cmd == M.MAV_CMD_GET_MESSAGE_INTERVAL:
            mid = int(msg.param1)
            interval = link.intervals_s.get(mid)
            us = 0 if interval is None else -1 if interval <= 0.0 else int(round(interval * 1e6))
            self._ack(msg, M.MAV_RESULT_ACCEPTED)
            link.send(link.mav.message_interval_encode(mid, us))
        elif cmd in (M.MAV_CMD_REQUEST_MESSAGE, M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES,
                     M.MAV_CMD_REQUEST_PROTOCOL_VERSION):
            mid = {M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: M.MAVLINK_MSG_ID_AUTOPILOT_VERSION,
                   M.MAV_CMD_REQUEST_PROTOCOL_VERSION: PROTOCOL_VERSION_ID}.get(
                       cmd, int(msg.param1))
            if mid in ON_REQUEST or mid in DEFAULT_RATES_HZ:
                self._ack(msg, M.MAV_RESULT_ACCEPTED)
                link.send_message(mid, state)
            else:
                self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
        elif v is None:
            self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
        elif cmd == M.MAV_CMD_COMPONENT_ARM_DISARM:
            if msg.param1 not in (0.0, 1.0):
                self._done(msg, "arm: param1 must be 0 or 1")
            else:
                self._done(msg, v.arm(msg.param1 == 1.0, int(msg.param2) == FORCE_DISARM))
        elif cmd == M.MAV_CMD_DO_SET_MODE:
            if not int(msg.param1) & M.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED:
                self._done(msg, "set mode: only custom (ArduPlane) modes")
            else:
                self._done(msg, v.set_mode(int(msg.param2)))
        elif cmd == M.MAV_CMD_NAV_RETURN_TO_LAUNCH:
            self._done(msg, v.set_mode(11))
        elif cmd == M.MAV_CMD_NAV_LOITER_UNLIM:
            pos = self._position(msg)
            lat, lon = pos if pos is not None else (None, None)
            self._done(msg, v.loiter_at(lat, lon, float(msg.param3)))
        elif cmd == M.MAV_CMD_DO_CHANGE_SPEED:
            speed = float(msg.param2)
            self._done(msg, None if speed < 0 else v.change_speed(speed))
        elif cmd == M.MAV_CMD_DO_CHANGE_ALTITUDE:
            alt = float(msg.param1)
            frame = int(msg.param2)
            if not math.isfinite(alt):
                self._done(msg, "change altitude: not a number")
            else:
                amsl = alt if frame in AMSL_FRAMES else state.home_altitude_m + alt
                self._done(msg, v.change_altitude(amsl))
        elif cmd == M.MAV_CMD_DO_REPOSITION:
            pos = self._position(msg)
            if pos is None:
                self._done(msg, "reposition: no position")
            else:
                self._done(msg, v.reposition(*pos, self._altitude_amsl(msg, msg.param7, state)))
        elif cmd == M.MAV_CMD_DO_SET_HOME:
            if msg.param1 == 1.0:
                self._done(msg, v.set_home(state.latitude_rad, state.longitude_rad,
                                           state.home_altitude_m))
            else:
                pos = self._position(msg)
                alt = self._altitude_amsl(msg, msg.param7, state)
                if pos is None or alt is None:
                    self._done(msg, "set home: no position")
                else:
                    self._done(msg, v.set_home(*pos, alt))
        elif cmd == M.MAV_CMD_MISSION_START:
            self._done(msg, v.mission_start(int(msg.param1), int(msg.param2)))
        elif cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            self._done(msg, v.set_mission_current(int(msg.param1)))
        else:
            self._ack(msg, M.MAV_RESULT_UNSUPPORTED)
