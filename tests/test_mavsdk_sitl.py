"""MAVSDK (PyPI ``mavsdk`` 4.x: the MAVSDK C++ library through its C wrapper, an independent
MAVLink codec) against ``bioflex-jsb sitl --duration 20`` on loopback, checked against the
run's MCAP log.

How the values are matched to the log. The vehicle's MAVLink clock is the simulated time
(``mavlink_link`` module docstring): an ATTITUDE with ``time_boot_ms`` = m carries the state
of the step at a time in [m, m + 1) ms, which MAVSDK passes on as ``timestamp_us`` = 1000 m.
GLOBAL_POSITION_INT and VFR_HUD reach MAVSDK's Position and FixedwingMetrics without a
timestamp; they are sent in the same link service as an ATTITUDE or between two, so their
time lies between the timestamps of the ATTITUDE callbacks just before and just after them.
Log rows and MAVLink messages are snapshots of the same instants (the state JSBSim reached
at the end of a step, logged as the next step's row), so the windows are not widened. A
MAVSDK value must lie within the range of the logged values over its window, widened by the
tolerance of its transport:

* attitude [deg]: float32 in ATTITUDE (rad); MAVSDK forms its EulerAngle through a float32
  quaternion, whose round trip alone moves an angle by up to ≈ 3e-5 deg (a few float32 steps
  of 1 rad); the log's 9 significant digits are far finer; ATT_TOL_DEG = 1e-4;
* latitude/longitude [deg]: degE7 integers (±0.5e-7 deg) and the log's 9 significant
  digits of 45.xxxxxxx deg (±0.5e-7 deg); LATLON_TOL_DEG = 1.5e-7 (1.7 cm). The log's
  ``location`` is at 60 Hz (the 3-D scene's samples, every 16th step), so the steps' latitude
  and longitude are its samples interpolated linearly (only between its first and last
  sample): over h = 1/60 s the error is at most a·h²/8, 0.7 mm = 6e-9 deg at a = 20 m/s²
  (2 g, more than the session's turn and gust), far inside the tolerance;
* altitude [m]: integer mm (±0.5 mm) in float32; ALT_TOL_M = 1e-3;
* airspeed [m/s]: float32 in VFR_HUD and in MAVSDK (≤ 1e-6 m/s at 16 m/s); 1e-5.

The same comparison with the MAVSDK times shifted by 50 ms must fail during the turn: the
check resolves the time alignment.
"""

from __future__ import annotations

import json
import math
import socket
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from mavsdk import ComponentType, Configuration, Mavsdk
from mavsdk.plugins.mission_raw import MissionRaw
from mavsdk.plugins.param import Param
from mavsdk.plugins.telemetry import Telemetry

from bioflex_jsb.drivers.sitl import SitlParameters
from bioflex_jsb.sinks.mcap import messages_by_topic, topic
from tests.polling import wait_until

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset

DURATION_S = 20.0  # the issue's `bioflex-jsb sitl --duration 20`
SPEEDUP = 2.0  # 10 s of wall time; telemetry rates are wall-clock rates, unchanged
HEADING_RAD = math.radians(60.0)  # AP_HDG_RAD set over MAVSDK: a 60 deg turn
GUST_AMP_MS = 2.5
ATT_TOL_DEG = 1e-4
LATLON_TOL_DEG = 1.5e-7
ALT_TOL_M = 1e-3
AIRSPEED_TOL_M_S = 1e-5
SHIFT_S = 0.05  # the misalignment the check must detect


def free_udp_port() -> int:
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


class Recorder:
    """MAVSDK telemetry callbacks, in the order they arrive."""

    def __init__(self) -> None:
        self.events: list[tuple[str, object]] = []
        self._lock = threading.Lock()

    def callback(self, kind: str):
        def on_value(value, _user_data):
            with self._lock:
                self.events.append((kind, value))
        return on_value

    def snapshot(self) -> list[tuple[str, object]]:
        with self._lock:
            return list(self.events)

    def n_attitudes(self) -> int:
        """How many ATTITUDE callbacks have arrived."""
        return sum(1 for kind, _ in self.snapshot() if kind == "attitude")

    def last_attitude_s(self) -> float:
        for kind, v in reversed(self.snapshot()):
            if kind == "attitude":
                return v.timestamp_us * 1e-6
        return math.nan


class LogSeries:
    """The coupled run of the log as arrays over its step times [s]."""

    def __init__(self, path) -> None:
        msgs = messages_by_topic(path)
        rigid = msgs[topic("coupled", "rigid_body")]
        loc = msgs[topic("coupled", "location")]
        gust = msgs[topic("coupled", "gust")]
        self.t_s = np.array([ns for ns, _ in rigid], dtype=float) * 1e-9
        col = {k: np.array([m[k] for _, m in rigid], dtype=float)
               for k in ("roll_rad", "pitch_rad", "yaw_rad", "airspeed_m_s", "altitude_m")}
        self.deg = {k: np.degrees(col[f"{k}_rad"]) for k in ("roll", "pitch", "yaw")}
        self.airspeed_m_s = col["airspeed_m_s"]
        self.altitude_m = col["altitude_m"]
        self.w_g_m_s = np.array([m["w_g_m_s"] for _, m in gust], dtype=float)
        assert len(self.t_s) == len(self.w_g_m_s)
        # location at the steps that begin a 1/60 s (scene.py's bins), from the first
        bins = np.floor(self.t_s * 60.0 + 1e-6)
        sampled = np.flatnonzero(np.r_[True, bins[1:] != bins[:-1]])
        loc_t_s = np.array([ns for ns, _ in loc], dtype=float) * 1e-9
        assert np.array_equal(loc_t_s, self.t_s[sampled])
        inside = (self.t_s >= loc_t_s[0]) & (self.t_s <= loc_t_s[-1])
        self.lat_deg, self.lon_deg = (
            np.where(inside, np.interp(self.t_s, loc_t_s, [m[k] for _, m in loc]), np.nan)
            for k in ("latitude", "longitude"))  # NaN: after the last sample

    def miss(self, value: float, series: np.ndarray, t0_s: float, t1_s: float,
             period: float | None = None) -> tuple[float, float] | None:
        """(distance of ``value`` outside the range of ``series`` over [t0, t1], distance to
        the nearest logged value there), or None when the log has no step in the window."""
        i0 = np.searchsorted(self.t_s, t0_s - 1e-9, side="left")
        i1 = np.searchsorted(self.t_s, t1_s + 1e-9, side="right")
        if i1 <= i0:
            return None
        d = value - series[i0:i1]
        d = d[np.isfinite(d)]
        if not len(d):
            return None
        if period is not None:
            d = (d + 0.5 * period) % period - 0.5 * period
        outside = 0.0 if d.min() <= 0.0 <= d.max() else float(np.min(np.abs(d)))
        return outside, float(np.min(np.abs(d)))


def compare(log: LogSeries, events, shift_s: float = 0.0) -> dict[str, list[tuple]]:
    """Per quantity, (outside, nearest, tolerance, time [s]) of every MAVSDK sample."""
    out: dict[str, list[tuple]] = {k: [] for k in (
        "roll", "pitch", "yaw", "latitude", "longitude", "altitude", "airspeed")}

    def add(name, value, series, t0, t1, tol, period=None):
        r = log.miss(value, series, t0 + shift_s, t1 + shift_s, period)
        if r is not None:
            out[name].append((*r, tol, t0))

    att_times = [(i, v.timestamp_us * 1e-6) for i, (k, v) in enumerate(events)
                 if k == "attitude"]
    for k, v in events:  # attitude: its own time_boot_ms
        if k != "attitude":
            continue
        m = v.timestamp_us * 1e-6
        t0, t1 = m, m + 1e-3
        add("roll", v.roll_deg, log.deg["roll"], t0, t1, ATT_TOL_DEG)
        add("pitch", v.pitch_deg, log.deg["pitch"], t0, t1, ATT_TOL_DEG)
        add("yaw", v.yaw_deg, log.deg["yaw"], t0, t1, ATT_TOL_DEG, period=360.0)
    idx = np.array([i for i, _ in att_times])
    stamps = np.array([m for _, m in att_times])
    for i, (k, v) in enumerate(events):
        if k not in ("position", "fixedwing"):
            continue
        j = np.searchsorted(idx, i)
        if j == 0 or j == len(idx):
            continue  # no ATTITUDE on one side: no bracket
        t0, t1 = stamps[j - 1], stamps[j] + 1e-3
        if k == "position":
            add("latitude", v.latitude_deg, log.lat_deg, t0, t1, LATLON_TOL_DEG)
            add("longitude", v.longitude_deg, log.lon_deg, t0, t1, LATLON_TOL_DEG)
            add("altitude", v.absolute_altitude_m, log.altitude_m, t0, t1, ALT_TOL_M)
        else:
            add("airspeed", v.airspeed_m_s, log.airspeed_m_s, t0, t1, AIRSPEED_TOL_M_S)
    return out


def test_mavsdk_flies_with_the_sitl_vehicle_and_matches_the_log(tmp_path):
    port = free_udp_port()
    out = tmp_path / "run.mcap"
    mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    proc = None
    try:
        assert mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}").name == "SUCCESS"
        wall0 = time.monotonic()
        proc = subprocess.Popen(
            [sys.executable, "-m", "bioflex_jsb", "sitl", "--duration", str(DURATION_S),
             "--speedup", str(SPEEDUP), "--mavlink", f"udpout:127.0.0.1:{port}",
             "--out", str(out), "--json"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

        vehicle = mavsdk.first_autopilot(20.0)
        assert vehicle is not None, "MAVSDK saw no autopilot"
        assert vehicle.is_connected() and vehicle.has_autopilot()
        assert vehicle.get_system_id() == 1 and 1 in vehicle.component_ids()

        rec = Recorder()
        telemetry = Telemetry(vehicle)
        telemetry.subscribe_attitude_euler(rec.callback("attitude"), None)
        telemetry.subscribe_position(rec.callback("position"), None)
        telemetry.subscribe_fixedwing_metrics(rec.callback("fixedwing"), None)

        # parameters: the whole list, then sets that change the run
        param = Param(vehicle)
        listed = {p.name: p.value for p in param.get_all_params().float_params}
        assert set(listed) == set(SitlParameters.names)
        assert listed["SIM_SPEEDUP"] == SPEEDUP and listed["WING_COUPLED"] == 1.0
        assert listed["GUST_TRIG"] == 0.0 and listed["AP_ENABLE"] == 1.0
        param.set_param_float("AP_HDG_RAD", HEADING_RAD)
        assert param.get_param_float("AP_HDG_RAD") == pytest.approx(HEADING_RAD, rel=1e-6)
        param.set_param_float("GUST_AMP_MS", GUST_AMP_MS)
        before_trigger_s = wait_until(lambda: rec.n_attitudes() and rec.last_attitude_s(),
                                      30.0, "a first ATTITUDE")
        param.set_param_float("GUST_TRIG", 1.0)  # returns when the vehicle acknowledged it
        # the upper bound: an ATTITUDE sent after the acknowledgement (the vehicle's time
        # then is past the trigger's); the two delivered after the set returned (in order:
        # one socket, one stream), not a fixed wait that a loaded machine may not cover
        acked = rec.n_attitudes()
        wait_until(lambda: rec.n_attitudes() >= acked + 2, 30.0,
                   "two ATTITUDE messages after GUST_TRIG was acknowledged")
        after_trigger_s = rec.last_attitude_s()

        # the mission: only home (ArduPilot's item 0)
        items = MissionRaw(vehicle).download_mission()
        assert len(items) == 1 and items[0].seq == 0

        stdout, stderr = proc.communicate(timeout=DURATION_S / SPEEDUP + 60.0)
        wall_s = time.monotonic() - wall0
        assert proc.returncode == 0, stderr
        events = rec.snapshot()
    finally:
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.communicate()
        mavsdk.destroy()

    summary = json.loads(stdout)
    assert summary["simulated_s"] == pytest.approx(DURATION_S, abs=0.01)
    assert summary["resets"] == 0
    log = LogSeries(out)
    assert log.t_s[-1] == pytest.approx(DURATION_S, abs=0.01)

    # the parameters set over MAVSDK changed the run
    assert abs(math.remainder(log.deg["yaw"][0], 360.0)) < 0.5  # the log: JSBSim's [0, 360)
    assert abs(math.remainder(log.deg["yaw"][-1] - math.degrees(HEADING_RAD), 360.0)) < 2.0
    blowing = np.flatnonzero(log.w_g_m_s != 0.0)
    assert len(blowing) > 0, "GUST_TRIG set over MAVSDK started no gust"
    assert float(log.w_g_m_s.max()) == pytest.approx(GUST_AMP_MS, rel=1e-3)
    gust_start_s = log.t_s[blowing[0]]
    assert before_trigger_s - 0.01 <= gust_start_s <= after_trigger_s + 0.01, (
        before_trigger_s, gust_start_s, after_trigger_s)

    # telemetry over the whole run, at MAVLink's default rates (wall clock)
    kinds = [k for k, _ in events]
    n_att, n_pos, n_fw = (kinds.count(k) for k in ("attitude", "position", "fixedwing"))
    assert n_att >= 200 and n_pos >= 40 and n_fw >= 40, (n_att, n_pos, n_fw)
    stamps = [v.timestamp_us for k, v in events if k == "attitude"]
    assert stamps == sorted(stamps) and all(s % 1000 == 0 for s in stamps)
    assert stamps[-1] * 1e-6 > 0.8 * DURATION_S  # the MAVLink clock is the simulated time

    result = compare(log, events)
    report = {}
    for name, rows in result.items():
        assert len(rows) >= 0.9 * (n_att if name in ("roll", "pitch", "yaw") else
                                   (n_pos if name != "airspeed" else n_fw)) - 2, name
        bad = [r for r in rows if r[0] > r[2]]
        report[name] = (len(rows), max(r[1] for r in rows), max(r[0] for r in rows))
        assert not bad, f"{name}: {len(bad)} of {len(rows)} MAVSDK values off the log, " \
                        f"first (outside, nearest, tol, t) = {bad[0]}"
    print(f"\nMAVSDK vs MCAP log ({wall_s:.1f} s wall): name: samples, max |diff| to the "
          "nearest logged step in the window, max outside the window's range")
    for name, (n, nearest, outside) in report.items():
        print(f"  {name}: {n}, {nearest:.3g}, {outside:.3g}")

    # the same check with the times 50 ms off fails (the turn moves roll/yaw fast enough)
    shifted = compare(log, events, shift_s=SHIFT_S)
    for name, share in (("roll", 0.2), ("yaw", 0.2), ("latitude", 0.9)):
        off = sum(r[0] > r[2] for r in shifted[name])
        print(f"  times shifted {SHIFT_S * 1e3:.0f} ms: {name}: {off} of {len(shifted[name])} "
              "off the log")
        assert off >= share * len(shifted[name]), (name, off)


def test_mavsdk_arms_flies_a_raw_mission_and_returns_to_launch():
    """MAVSDK's Action, MissionRaw and Telemetry against the vehicle: flight-mode names,
    arm (already armed in flight), mission upload, download, progress and RTL."""
    from mavsdk.plugins.action import Action
    from mavsdk.plugins.mission_raw import MissionItem
    from mavsdk.plugins.telemetry import FlightMode

    port = free_udp_port()
    mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
    proc = None
    try:
        assert mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}").name == "SUCCESS"
        proc = subprocess.Popen(
            [sys.executable, "-m", "bioflex_jsb", "sitl", "--duration", "600", "--speedup",
             "4", "--mavlink", f"udpout:127.0.0.1:{port}", "--no-log"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        vehicle = mavsdk.first_autopilot(20.0)
        assert vehicle is not None
        telemetry, action, mission = Telemetry(vehicle), Action(vehicle), MissionRaw(vehicle)
        end = time.monotonic() + 10.0
        while time.monotonic() < end and not telemetry.armed():
            time.sleep(0.1)
        assert telemetry.armed()
        assert telemetry.flight_mode() == FlightMode.UNKNOWN  # CRUISE has no MAVSDK name
        action.arm()
        home = telemetry.home()
        lat0, lon0 = home.latitude_deg, home.longitude_deg
        assert (lat0, lon0) == pytest.approx((-35.363261, 149.165230), abs=1e-6)

        def item(seq, north_m, east_m, alt_m, frame=6):
            lat = lat0 + math.degrees(north_m / 6_371_000.0)
            lon = lon0 + math.degrees(east_m / (6_371_000.0 * math.cos(math.radians(lat0))))
            return MissionItem(seq=seq, frame=frame, command=16, current=int(seq == 1),
                               autocontinue=1, param1=0.0, param2=30.0, param3=0.0,
                               param4=0.0, x=int(round(lat * 1e7)), y=int(round(lon * 1e7)),
                               z=alt_m, mission_type=0)

        plan = [item(0, 0, 0, 584.0, frame=0), item(1, 250, 0, 100), item(2, 250, 250, 100)]
        mission.upload_mission(plan)
        back = mission.download_mission()
        assert [(i.seq, i.x, i.y) for i in back[1:]] == [(i.seq, i.x, i.y) for i in plan[1:]]
        progress = []
        mission.subscribe_mission_progress(
            lambda p, _u: progress.append((p.current, p.total)), None)
        mission.start_mission()
        end = time.monotonic() + 120.0
        while time.monotonic() < end and not any(c >= 2 for c, _ in progress):
            time.sleep(0.2)
        assert telemetry.flight_mode() == FlightMode.MISSION
        assert any(c >= 2 for c, _ in progress), progress
        action.return_to_launch()
        end = time.monotonic() + 10.0
        while time.monotonic() < end and telemetry.flight_mode() != FlightMode.RETURN_TO_LAUNCH:
            time.sleep(0.1)
        assert telemetry.flight_mode() == FlightMode.RETURN_TO_LAUNCH
        action.hold()
        wait_until(lambda: telemetry.flight_mode() == FlightMode.HOLD, 10.0,
                   "HOLD (ArduPlane LOITER) after action.hold()")
    finally:
        if proc is not None and proc.poll() is None:
            proc.terminate()
            proc.wait(20.0)
        mavsdk.destroy()
