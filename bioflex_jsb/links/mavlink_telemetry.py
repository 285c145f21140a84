"""The SITL vehicle's streamed MAVLink messages: rates and encoding (SI → MAVLink units).

Rates are wall-clock rates (``--speedup`` does not change them); ground stations change
them with MAV_CMD_SET_MESSAGE_INTERVAL or REQUEST_DATA_STREAM, read them with
MAV_CMD_GET_MESSAGE_INTERVAL. The time fields are the simulated clock (``mavlink`` module
docstring), except SYSTEM_TIME's ``time_unix_usec``, the host's wall clock.
"""

from __future__ import annotations

import math
import struct
import time

from pymavlink.dialects.v20 import common as mavlink

from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.links.mavlink_setup import VehicleState

M = mavlink
# Default rates [Hz] of the streamed messages.
DEFAULT_RATES_HZ = {
    M.MAVLINK_MSG_ID_HEARTBEAT: 1.0,
    M.MAVLINK_MSG_ID_SYS_STATUS: 1.0,
    M.MAVLINK_MSG_ID_SYSTEM_TIME: 1.0,
    M.MAVLINK_MSG_ID_ATTITUDE: 50.0,
    M.MAVLINK_MSG_ID_ATTITUDE_QUATERNION: 10.0,
    M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT: 10.0,
    M.MAVLINK_MSG_ID_GPS_RAW_INT: 5.0,
    M.MAVLINK_MSG_ID_VFR_HUD: 10.0,
    M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT: 10.0,
    M.MAVLINK_MSG_ID_HOME_POSITION: 0.5,
    M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE: 1.0,
    M.MAVLINK_MSG_ID_BATTERY_STATUS: 1.0,
    M.MAVLINK_MSG_ID_MISSION_CURRENT: 1.0,
    M.MAVLINK_MSG_ID_HIGHRES_IMU: 25.0,
}
HIGHRES_IMU_FIELDS = 0b111111  # fields_updated: x/y/z acceleration and x/y/z gyro
PROTOCOL_VERSION_ID = 300  # not in pymavlink's common dialect: encoded here
# Messages sent once on request (MAV_CMD_REQUEST_MESSAGE) but not streamed.
ON_REQUEST = frozenset({M.MAVLINK_MSG_ID_AUTOPILOT_VERSION, PROTOCOL_VERSION_ID})
# REQUEST_DATA_STREAM (deprecated, still sent by MAVProxy and QGC for ArduPilot): stream ids
# → the messages they rate.
STREAMS = {
    M.MAV_DATA_STREAM_RAW_SENSORS: (M.MAVLINK_MSG_ID_GPS_RAW_INT,
                                    M.MAVLINK_MSG_ID_HIGHRES_IMU),
    M.MAV_DATA_STREAM_EXTENDED_STATUS: (M.MAVLINK_MSG_ID_SYS_STATUS,
                                        M.MAVLINK_MSG_ID_MISSION_CURRENT),
    M.MAV_DATA_STREAM_POSITION: (M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT,),
    M.MAV_DATA_STREAM_EXTRA1: (M.MAVLINK_MSG_ID_ATTITUDE,),
    M.MAV_DATA_STREAM_EXTRA2: (M.MAVLINK_MSG_ID_VFR_HUD,),
    M.MAV_DATA_STREAM_EXTRA3: (M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT,
                               M.MAVLINK_MSG_ID_BATTERY_STATUS),
}
STREAMS[M.MAV_DATA_STREAM_ALL] = tuple(m for ids in STREAMS.values() for m in ids)
CAPABILITIES = (M.MAV_PROTOCOL_CAPABILITY_MAVLINK2 | M.MAV_PROTOCOL_CAPABILITY_PARAM_FLOAT
                | M.MAV_PROTOCOL_CAPABILITY_MISSION_INT | M.MAV_PROTOCOL_CAPABILITY_COMMAND_INT
)
SENSORS = (M.MAV_SYS_STATUS_SENSOR_3D_GYRO | M.MAV_SYS_STATUS_SENSOR_3D_ACCEL
           | M.MAV_SYS_STATUS_SENSOR_ABSOLUTE_PRESSURE
           | M.MAV_SYS_STATUS_SENSOR_DIFFERENTIAL_PRESSURE
           | M.MAV_SYS_STATUS_SENSOR_GPS | M.MAV_SYS_STATUS_SENSOR_ANGULAR_RATE_CONTROL
           | M.MAV_SYS_STATUS_SENSOR_ATTITUDE_STABILIZATION | M.MAV_SYS_STATUS_SENSOR_BATTERY)


class ProtocolVersion(mavlink.MAVLink_message):
    """PROTOCOL_VERSION (id 300, MAVLink 2 only): version 200, min 100, max 200, no hashes."""

    id = PROTOCOL_VERSION_ID
    msgname = "PROTOCOL_VERSION"
    fieldnames = ["version", "min_version", "max_version", "spec_version_hash",
                  "library_version_hash"]
    CRC_EXTRA = 217

    def __init__(self) -> None:
        super().__init__(self.id, self.msgname)
        self._fieldnames = self.fieldnames
        self.version, self.min_version, self.max_version = 200, 100, 200
        self.spec_version_hash = self.library_version_hash = [0] * 8

    def pack(self, mav, force_mavlink1: bool = False) -> bytes:
        payload = struct.pack("<HHH8B8B", self.version, self.min_version, self.max_version,
                              *self.spec_version_hash, *self.library_version_hash)
        return self._pack(mav, self.CRC_EXTRA, payload, force_mavlink1=force_mavlink1)


def encode(mav, mid: int, s: VehicleState) -> list:
    """The messages of id ``mid`` for the state ``s`` (NAMED_VALUE_FLOAT: one per value)."""
    boot_ms = int(s.time_s * 1000.0 + 1e-6) & 0xFFFFFFFF  # ⌊1000 t⌋ (+1 ns: k·dt rounding)
    if mid == M.MAVLINK_MSG_ID_HEARTBEAT:
        status = M.MAV_STATE_ACTIVE if s.armed else M.MAV_STATE_STANDBY
        return [mav.heartbeat_encode(M.MAV_TYPE_FIXED_WING, M.MAV_AUTOPILOT_ARDUPILOTMEGA,
                                     MODES.base_mode(s.custom_mode, s.armed), s.custom_mode,
                                     status)]
    if mid == M.MAVLINK_MSG_ID_SYS_STATUS:
        # health also says "no geofence breach" (there is no fence: MAVProxy reads a missing
        # health bit as a breach)
        return [mav.sys_status_encode(SENSORS, SENSORS, SENSORS | M.MAV_SYS_STATUS_GEOFENCE,
                                      0, _u16(s.battery_voltage_v * 1000.0),
                                      _i16(s.battery_current_a * 100.0),
                                      max(-1, min(100, s.battery_remaining_pct)),
                                      0, 0, 0, 0, 0, 0)]
    if mid == M.MAVLINK_MSG_ID_SYSTEM_TIME:
        return [mav.system_time_encode(int(time.time() * 1e6), boot_ms)]
    if mid == M.MAVLINK_MSG_ID_ATTITUDE:
        return [mav.attitude_encode(boot_ms, s.roll_rad, s.pitch_rad, s.yaw_rad,
                                    s.p_rad_s, s.q_rad_s, s.r_rad_s)]
    if mid == M.MAVLINK_MSG_ID_ATTITUDE_QUATERNION:
        q = quaternion(s.roll_rad, s.pitch_rad, s.yaw_rad)
        return [mav.attitude_quaternion_encode(boot_ms, *q, s.p_rad_s, s.q_rad_s, s.r_rad_s)]
    if mid == M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT:
        return [mav.global_position_int_encode(
            boot_ms, deg_e7(s.latitude_rad), deg_e7(s.longitude_rad),
            _i32(s.altitude_m * 1000.0), _i32(s.relative_altitude_m * 1000.0),
            _i16(s.v_north_m_s * 100.0), _i16(s.v_east_m_s * 100.0),
            _i16(s.v_down_m_s * 100.0), heading_cdeg(s.yaw_rad))]
    if mid == M.MAVLINK_MSG_ID_GPS_RAW_INT:
        vg = math.hypot(s.v_north_m_s, s.v_east_m_s)
        cog = math.atan2(s.v_east_m_s, s.v_north_m_s)
        return [mav.gps_raw_int_encode(
            int(s.time_s * 1e6 + 1e-3), M.GPS_FIX_TYPE_3D_FIX, deg_e7(s.latitude_rad),
            deg_e7(s.longitude_rad), _i32(s.altitude_m * 1000.0), 80, 120,
            min(int(vg * 100.0), 65534), heading_cdeg(cog), 12)]
    if mid == M.MAVLINK_MSG_ID_VFR_HUD:
        vg = math.hypot(s.v_north_m_s, s.v_east_m_s)
        heading = int(round(math.degrees(s.yaw_rad))) % 360
        return [mav.vfr_hud_encode(s.airspeed_m_s, vg, heading, int(round(100.0 * s.throttle)),
                                   s.altitude_m, -s.v_down_m_s)]
    if mid == M.MAVLINK_MSG_ID_NAMED_VALUE_FLOAT:
        return [mav.named_value_float_encode(boot_ms, name.encode()[:10], float(value))
                for name, value in s.named.items()]
    if mid == M.MAVLINK_MSG_ID_HOME_POSITION:
        return [mav.home_position_encode(
            deg_e7(s.home_latitude_rad), deg_e7(s.home_longitude_rad),
            _i32(s.home_altitude_m * 1000.0), 0.0, 0.0, 0.0, [1.0, 0.0, 0.0, 0.0],
            0.0, 0.0, 0.0, int(s.time_s * 1e6 + 1e-3))]
    if mid == M.MAVLINK_MSG_ID_EXTENDED_SYS_STATE:
        return [mav.extended_sys_state_encode(M.MAV_VTOL_STATE_UNDEFINED,
                                              M.MAV_LANDED_STATE_IN_AIR)]
    if mid == M.MAVLINK_MSG_ID_BATTERY_STATUS:
        cells = [_u16(s.battery_voltage_v * 1000.0 / 3.0)] * 3 + [65535] * 7
        t_rem = s.battery_time_remaining_s
        return [mav.battery_status_encode(
            0, M.MAV_BATTERY_FUNCTION_ALL, M.MAV_BATTERY_TYPE_LIPO, 32767, cells,
            _i16(s.battery_current_a * 100.0), _i32(s.battery_consumed_mah),
            _i32(s.battery_energy_j / 100.0), max(0, min(100, s.battery_remaining_pct)),
            _i32(t_rem) if math.isfinite(t_rem) else 0)]
    if mid == M.MAVLINK_MSG_ID_MISSION_CURRENT:
        total = max(0, s.mission_total - 1) if s.mission_total else 0
        state = (M.MISSION_STATE_NO_MISSION if s.mission_total < 2
                 else M.MISSION_STATE_ACTIVE if s.custom_mode == MODES.AUTO
                 else M.MISSION_STATE_PAUSED)
        return [mav.mission_current_encode(s.mission_seq, total, state,
                                           1 if s.custom_mode == MODES.AUTO else 2)]
    if mid == M.MAVLINK_MSG_ID_HIGHRES_IMU:
        # the autopilot's IMU at its station (docs/aircraft.md, "Sensors"): specific force
        # and rates in its axes; no magnetometer, barometer or temperature (NaN, not
        # flagged in fields_updated: bits 0-5, the accelerometer and gyro)
        ax, ay, az = s.imu_accel_m_s2
        gx, gy, gz = s.imu_gyro_rad_s
        nan = math.nan
        return [mav.highres_imu_encode(int(s.time_s * 1e6 + 1e-3), ax, ay, az, gx, gy, gz,
                                       nan, nan, nan, nan, nan, nan, nan, HIGHRES_IMU_FIELDS)]
    if mid == M.MAVLINK_MSG_ID_AUTOPILOT_VERSION:
        return [mav.autopilot_version_encode(CAPABILITIES, 0, 0, 0, 0, [0] * 8, [0] * 8,
                                             [0] * 8, 0, 0, 0)]
    if mid == PROTOCOL_VERSION_ID:
        return [ProtocolVersion()]
    return []


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """(w, x, y, z) of the NED-to-FRD rotation with these Euler angles (3-2-1) [rad]."""
    cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
    cp, sp = math.cos(0.5 * pitch), math.sin(0.5 * pitch)
    cy, sy = math.cos(0.5 * yaw), math.sin(0.5 * yaw)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


def _i32(x: float) -> int:
    return max(-(2**31), min(2**31 - 1, int(round(x)))) if math.isfinite(x) else 0


def _i16(x: float) -> int:
    return max(-32768, min(32767, int(round(x)))) if math.isfinite(x) else 0


def _u16(x: float) -> int:
    return max(0, min(65534, int(round(x)))) if math.isfinite(x) else 65535


def deg_e7(rad: float) -> int:
    return _i32(math.degrees(rad) * 1e7)


def heading_cdeg(rad: float) -> int:
    return int(round(math.degrees(rad) * 100.0)) % 36000 if math.isfinite(rad) else 65535
