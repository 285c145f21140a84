"""A pymavlink ground station for the SITL tests: only standard MAVLink messages and
commands (the mission protocol with ArduPilot's home item 0, MAV_CMD_MISSION_START,
MAV_CMD_NAV_RETURN_TO_LAUNCH)."""

from __future__ import annotations

import math
import time

from pymavlink import mavutil
from pymavlink.dialects.v20 import common as M

EARTH_RADIUS_M = 6_371_000.0


def offset(lat_deg: float, lon_deg: float, north_m: float, east_m: float):
    lat = lat_deg + math.degrees(north_m / EARTH_RADIUS_M)
    lon = lon_deg + math.degrees(east_m / (EARTH_RADIUS_M * math.cos(math.radians(lat_deg))))
    return lat, lon


def distance_m(lat1, lon1, lat2, lon2) -> float:
    n = math.radians(lat2 - lat1) * EARTH_RADIUS_M
    e = math.radians(lon2 - lon1) * EARTH_RADIUS_M * math.cos(math.radians(lat1))
    return math.hypot(n, e)


class Station:
    def __init__(self, port: int) -> None:
        self.c = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=255,
                                            source_component=190, dialect="common")
        self.seqs: list[int] = []
        self.track: list[tuple[float, float, float, float]] = []  # t_s, lat, lon, rel alt
        self.reached: list[int] = []
        self.texts: list[str] = []
        self.home = None
        self.heartbeat = None
        self._beat = 0.0

    def beat(self) -> None:
        """A GCS heartbeat at 1 Hz (the vehicle forgets silent peers)."""
        now = time.monotonic()
        if now - self._beat >= 1.0:
            self._beat = now
            self.c.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)

    def hello(self, timeout: float = 10.0):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            self.c.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
            if self.pump(0.3, until="HEARTBEAT"):
                return self.heartbeat
        raise AssertionError("no HEARTBEAT")

    def pump(self, seconds: float, until: str | None = None, cond=None):
        """Read for ``seconds``; return the first message of type ``until`` meeting ``cond``."""
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            self.beat()
            m = self.c.recv_match(blocking=True, timeout=0.05)
            if m is None:
                continue
            t = m.get_type()
            if m.get_srcSystem() == 1:
                self.seqs.append(m.get_seq())
            if t == "HEARTBEAT":
                self.heartbeat = m
            elif t == "GLOBAL_POSITION_INT":
                self.track.append((m.time_boot_ms * 1e-3, m.lat * 1e-7, m.lon * 1e-7,
                                   m.relative_alt * 1e-3))
            elif t == "MISSION_ITEM_REACHED":
                self.reached.append(m.seq)
            elif t == "STATUSTEXT":
                self.texts.append(m.text)
            elif t == "HOME_POSITION":
                self.home = (m.latitude * 1e-7, m.longitude * 1e-7, m.altitude * 1e-3)
            if until is not None and t == until and (cond is None or cond(m)):
                return m
        return None

    def command(self, cmd, *params, timeout: float = 3.0):
        p = list(params) + [0.0] * (7 - len(params))
        for _ in range(3):
            self.c.mav.command_long_send(1, 1, cmd, 0, *p)
            ack = self.pump(timeout / 3, "COMMAND_ACK", lambda m: m.command == cmd)
            if ack is not None:
                return ack.result
        raise AssertionError(f"no COMMAND_ACK for {cmd}")

    def upload(self, items, timeout: float = 10.0) -> int:
        """Upload ``items`` (seq 0 = home); the MISSION_ACK result."""
        self.c.mav.mission_count_send(1, 1, len(items), M.MAV_MISSION_TYPE_MISSION)
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            m = self.c.recv_match(type=["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"],
                                  blocking=True, timeout=0.5)
            if m is None:
                continue
            if m.get_type() == "MISSION_ACK":
                return m.type
            self.c.mav.send(items[m.seq])
        raise AssertionError("mission upload did not finish")

    def download(self, timeout: float = 10.0):
        self.c.mav.mission_request_list_send(1, 1, M.MAV_MISSION_TYPE_MISSION)
        count = self.c.recv_match(type="MISSION_COUNT", blocking=True, timeout=timeout)
        items = []
        for seq in range(count.count):
            self.c.mav.mission_request_int_send(1, 1, seq, M.MAV_MISSION_TYPE_MISSION)
            it = self.c.recv_match(type="MISSION_ITEM_INT", blocking=True, timeout=timeout,
                                   condition=f"MISSION_ITEM_INT.seq=={seq}")
            items.append(it)
        self.c.mav.mission_ack_send(1, 1, M.MAV_MISSION_ACCEPTED, M.MAV_MISSION_TYPE_MISSION)
        return items

    def item(self, seq, lat, lon, rel_alt_m, command=M.MAV_CMD_NAV_WAYPOINT, radius_m=0.0,
             p1=0.0, p3=0.0):
        return self.c.mav.mission_item_int_encode(
            1, 1, seq, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, command, 0, 1, p1, radius_m, p3,
            math.nan, int(round(lat * 1e7)), int(round(lon * 1e7)), rel_alt_m,
            M.MAV_MISSION_TYPE_MISSION)
