"""A pymavlink ground station flies a mission with the SITL vehicle (``bioflex-jsb sitl`` as
a subprocess, loopback), using only standard MAVLink: sequence numbers advance, HOME_POSITION
arrives, a 4-waypoint mission (waypoints 300 m apart, acceptance radius 30 m) is uploaded,
read back and started with MAV_CMD_MISSION_START; every waypoint is reached
(MISSION_ITEM_REACHED, and the track passes within the radius); MAV_CMD_NAV_RETURN_TO_LAUNCH
brings the aircraft within 60 m of home. Function, not timing: the waits are in simulated
time (time_boot_ms) with generous wall-clock bounds."""

from __future__ import annotations

import math
import socket
import subprocess
import sys
import time
from itertools import pairwise

import pytest
from pymavlink.dialects.v20 import common as M

from tests.sitl_station import EARTH_RADIUS_M, Station, distance_m, offset

pytestmark = pytest.mark.slow

SPEEDUP = 4.0
RADIUS_M = 30.0
LEGS_M = [(300.0, 0.0), (300.0, 300.0), (0.0, 300.0), (-300.0, 300.0)]  # north, east


def segment_miss_m(lat_w, lon_w, lat0, lon0, lat1, lon1) -> float:
    """The closest approach [m] to the waypoint (lat_w, lon_w) [deg] of the track's straight
    leg between two telemetry samples: the samples alone overstate it by up to half the
    distance flown between them (15 m/s over the position messages' interval), which is
    what a loaded machine's sparser samples showed (30.2 m against a 30 m radius that the
    vehicle's own MISSION_ITEM_REACHED had met)."""
    k = math.radians(1.0) * EARTH_RADIUS_M
    c = math.cos(math.radians(lat_w))
    a = ((lat0 - lat_w) * k, (lon0 - lon_w) * k * c)
    b = ((lat1 - lat_w) * k, (lon1 - lon_w) * k * c)
    d = (b[0] - a[0], b[1] - a[1])
    length2 = d[0] ** 2 + d[1] ** 2
    u = 0.0 if length2 == 0.0 else max(0.0, min(1.0, -(a[0] * d[0] + a[1] * d[1]) / length2))
    return math.hypot(a[0] + u * d[0], a[1] + u * d[1])


def free_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_pymavlink_station_flies_a_mission_and_returns_home():
    port = free_port()
    vehicle = subprocess.Popen(
        [sys.executable, "-m", "bioflex_jsb", "sitl", "--mavlink", f"udpin:127.0.0.1:{port}",
         "--speedup", str(SPEEDUP), "--no-log", "--duration", "900"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        st = Station(port)
        hb = st.hello(60.0)
        assert hb.autopilot == M.MAV_AUTOPILOT_ARDUPILOTMEGA and hb.custom_mode == 7
        st.pump(3.0, "HOME_POSITION")
        assert st.home is not None
        st.pump(2.0)
        seqs = st.seqs[:50]
        steps = [(b - a) % 256 for a, b in zip(seqs[:-1], seqs[1:], strict=True)]
        assert len(set(seqs)) > 40 and all(d == 1 for d in steps)
        lat0, lon0, alt0 = st.home
        assert (lat0, lon0, alt0) == pytest.approx((-35.363261, 149.165230, 584.0), abs=1e-6)

        items = [st.item(0, lat0, lon0, 0.0)]
        wps = []
        for i, (n, e) in enumerate(LEGS_M, 1):
            lat, lon = offset(lat0, lon0, n, e)
            wps.append((lat, lon))
            items.append(st.item(i, lat, lon, 100.0, radius_m=RADIUS_M))
        assert st.upload(items) == M.MAV_MISSION_ACCEPTED
        back = st.download()
        assert [it.seq for it in back] == [0, 1, 2, 3, 4]
        assert [(it.x, it.y) for it in back[1:]] == [(i.x, i.y) for i in items[1:]]

        assert st.command(M.MAV_CMD_MISSION_START, 0, 0) == M.MAV_RESULT_ACCEPTED
        t0 = st.track[-1][0]
        miss = [math.inf] * len(wps)
        wall_end = time.monotonic() + 400.0
        while (len(set(st.reached)) < 4 and st.track[-1][0] - t0 < 400.0
               and time.monotonic() < wall_end and vehicle.poll() is None):
            n = len(st.track)
            st.pump(0.5)
            for (_, la0, lo0, _), (_, la1, lo1, _) in pairwise(st.track[max(n - 2, 0):]):
                for i, (wl, wo) in enumerate(wps):
                    miss[i] = min(miss[i], segment_miss_m(wl, wo, la0, lo0, la1, lo1))
        print("waypoint miss distances [m]:", [round(x, 1) for x in miss])
        assert sorted(set(st.reached)) == [1, 2, 3, 4], (st.reached, st.texts)
        assert all(d <= RADIUS_M for d in miss), miss

        assert st.command(M.MAV_CMD_NAV_RETURN_TO_LAUNCH) == M.MAV_RESULT_ACCEPTED
        t1 = st.track[-1][0]
        best = math.inf
        wall_end = time.monotonic() + 200.0
        while st.track[-1][0] - t1 < 150.0 and time.monotonic() < wall_end and best > 60.0:
            n = len(st.track)
            st.pump(0.5)
            for _, la, lo, _ in st.track[n - 1:]:
                best = min(best, distance_m(lat0, lon0, la, lo))
        print(f"RTL: closest to home {best:.1f} m")
        assert best <= 60.0
        st.pump(1.0, "HEARTBEAT")
        assert st.heartbeat.custom_mode == 11  # RTL
        loss = st.c.mav_loss / max(1, st.c.mav_count + st.c.mav_loss)
        print(f"link loss seen by the station: {100 * loss:.2f} %")
        assert any("Reached waypoint #4" in t for t in st.texts)
    finally:
        vehicle.terminate()
        vehicle.wait(20.0)
