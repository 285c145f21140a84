#!/usr/bin/env python3
"""Build ArduPlane SITL from an ArduPilot checkout and fly bioflex through it (docs/ardupilot.md).

    python scripts/ardupilot_sitl.py build /path/to/ardupilot [--jobs 1] [--venv DIR]
    python scripts/ardupilot_sitl.py fly /path/to/ardupilot [--timeout-s 900] [--out DIR]
        [--speedup 1] [--rate HZ] [--defaults EXTRA.parm] [--square-m 300] [--home-radius-m 100]

``build`` runs ``./waf configure --board sitl --no-submodule-update`` and ``./waf plane`` at
``nice 19`` (the checkout must have its submodules: waf, mavlink + pymavlink, DroneCAN
DSDL / dronecan_dsdlc / libcanard / pydronecan, littlefs, lwip; ``--disable-networking``
builds without lwip). ``--venv`` is a virtual environment with the build's Python
packages (empy==3.3.4, pexpect, future, dronecan, pymavlink); its ``bin`` goes first on PATH.

``fly`` always runs inside a new network namespace with loopback only (ArduPilot's TCP ports
5760, 5762, 5763 listen on all interfaces): it re-executes itself under ``unshare -n`` (as
root) or ``unshare -rn`` (as a user), brings ``lo`` up, starts the physics
(``--physics-cmd``, default the bioflex JSON backend on UDP 9002), starts ArduPlane with
``bioflex_jsb/data/ardupilot/bioflex_plane.parm`` (then each ``--defaults`` file, whose
values win), and flies a takeoff + 4-waypoint + RTL mission over MAVLink (pymavlink, TCP
5760): a square of ``--square-m`` a side (300 m, the prototype's; 3000 m for the c172's
341 m turn radius), ended in RTL within ``--home-radius-m`` of home (100 m; it must exceed
the aircraft's loiter radius ``WP_LOITER_RAD``). ``--speedup N`` is ArduPlane's ``--speedup`` (it
paces its frames to N times real time; lock-stepped, the backend sets the pace it reaches)
and ``--rate HZ`` its ``--rate`` (``SIM_RATE_HZ``, ArduPilot's default 1200 when not given);
the script's own waits in wall time (the arming retry, the launch switch) are divided by N
so that they last as long in ArduPlane's time. It prints one JSON summary: waypoints
reached, the cross-track error [m] twice (``xtrack_from_8s_into_leg_m``: from 8 s after each
waypoint switch, the line being flown; ``xtrack_including_turns_m``: every sample, the turn
at each waypoint included, where the error jumps to the next leg's ~30 m at the switch),
ArduPilot's STATUSTEXT messages, simulated and wall time [s], three real-time factors (the
backend's, ArduPlane's from boot and ArduPlane's in flight), each named with its definition
(``real_time_factors``), whether the backend's held the requested speed-up within 5 %
(``speedup_held``), the load average before and after and the CPU time [s] of the script,
the physics and ArduPlane (``cpu_s``).

The flight ends with ArduPlane stopped first; the physics (started with ``--end-when-silent
2``) then ends by itself, a normal end (exit 0, its summary's ``ended``: "ArduPilot
silent", ``interrupted`` false), and ``physics_end`` says so (``by``: "itself", ``status``:
0); a physics that has not ended within 60 s is stopped with SIGTERM (``by``: "SIGTERM",
status 130: an interrupt).

Exit status: 0 the mission was completed (every waypoint of the square reached, then home
in RTL); 1 the mission was not completed (timeout, a process exited, waypoints missed: the
summary's ``incomplete`` says which); 2 the script could not run (bad arguments, no
binary, no namespace, no heartbeat; one line on stderr).
Nothing here is ArduPilot's code; the checkout is only built and run.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
PARAM_FILE = REPO / "bioflex_jsb" / "data" / "ardupilot" / "bioflex_plane.parm"
NETNS_ENV = "BIOFLEX_ARDUPILOT_NETNS"  # set inside the private namespace
MAVLINK_URL = "tcp:127.0.0.1:5760"  # ArduPilot SITL SERIAL0, instance 0
# The bioflex side: the co-simulation as ArduPilot's JSON physics (``bioflex-jsb ardupilot``,
# bioflex_jsb/drivers/ardupilot.py): the optimised wing, coupled, a 2 m/s 1-cosine gust of
# 30 m (2 s at 15 m/s) 30 s after the launch (on the square's second leg); its JSON summary
# goes to physics.json and its frames to physics.npz in --out. Override with --physics-cmd.
# The physics ends by itself once ArduPlane, stopped first, has been silent for
# PHYSICS_END_SILENCE_S (--end-when-silent): a normal end, exit 0, not an interrupt.
PHYSICS_END_SILENCE_S = 2.0
# How long the script waits for the physics to end by itself [s]: the silence, the server's
# 0.5 s poll, and the log's close (its last chunk and summary, seconds for a long flight).
PHYSICS_END_WAIT_S = 60.0
DEFAULT_PHYSICS_CMD = (f"{shlex.quote(sys.executable)} -m bioflex_jsb ardupilot "
                       "--wing optimised --model coupled --gust 1cos:2:30 --gust-at 30 "
                       f"--end-when-silent {PHYSICS_END_SILENCE_S:g} "
                       "--summary physics.json --table physics.npz")
# Mission (metres from home, NED; altitude above home [m]): a square flown clockwise, 300 m a
# side unless --square-m.
TAKEOFF_ALT_M = 40.0  # NAV_TAKEOFF altitude
TAKEOFF_PITCH_DEG = 12.0  # NAV_TAKEOFF minimum pitch (ArduPlane docs suggest 10..15 deg)
MISSION_ALT_M = 60.0
SQUARE_SIDE_M = 300.0  # the prototype's: 13 of its 22.9 m turn radii at 45 deg of bank
# the corners, in units of the side, flown in this order
SQUARE_CORNERS = ((1.0, 0.0), (1.0, 1.0), (0.0, 1.0), (0.0, 0.0))
# RTL ends the flight when the aircraft is this near home [m] (the prototype's loiter circle,
# WP_LOITER_RAD, is within it; a larger aircraft's is not: --home-radius-m)
HOME_RADIUS_M = 100.0
LAUNCH_SWITCH_PWM_US = 1900  # RC 5 "fire" (the physics fires at 1880..1920 us held 0.5 s)
RTL_WATCH_S = 30.0  # the flight ends after this long [s] in RTL near home
LAUNCH_SWITCH_S = 2.0  # how long the switch is held [s of wall time at --speedup 1]
LAUNCH_RESEND_S = 0.2  # RC override re-sent this often [s of wall time at --speedup 1]
ARM_RETRY_S = 5.0  # arming re-sent this often while refused [s of wall time at --speedup 1]
# MAVLink streams asked for, at STREAM_RATE_HZ of ArduPlane's time: only those holding the
# messages read here (EXTENDED_STATUS: MISSION_CURRENT, GPS_RAW_INT, NAV_CONTROLLER_OUTPUT;
# POSITION: GLOBAL_POSITION_INT; EXTRA3: SYSTEM_TIME; libraries/GCS_MAVLink/
# GCS_MAVLink_Parameters.cpp). MAV_DATA_STREAM_ALL covers up to 55 kinds of message there,
# up to 550 a simulated second at 10 Hz for Python to parse: 11 000 a wall second at
# --speedup 20, processor time taken from the two lock-stepped processes.
STREAMS = ("MAV_DATA_STREAM_EXTENDED_STATUS", "MAV_DATA_STREAM_POSITION",
           "MAV_DATA_STREAM_EXTRA3")
STREAM_RATE_HZ = 10
# DEFINITION: a speed-up is held when the backend's real-time factor is within
# this fraction of it (docs/ardupilot.md, "Faster than real time").
HELD_TOLERANCE = 0.05
PLANE_MODE_RTL = 11  # ArduPlane custom_mode of RTL
NO_OVERRIDE = 65535  # RC_CHANNELS_OVERRIDE: leave this channel alone
EARTH_RADIUS_M = 6378137.0  # WGS-84 equatorial radius: metres → degrees near home
# DEFINITION: the cross-track error of a leg is measured from this long after the waypoint
# switch that starts it [s]: the turn onto the new line (90 deg at 15 m/s, 30 m WP_RADIUS,
# 43 m L1 distance) is over by then in the documented flight (docs/ardupilot.md quotes the
# error from 8 s into each leg).
LEG_SETTLE_S = 8.0
EXIT_OK, EXIT_INCOMPLETE, EXIT_ERROR = 0, 1, 2


class ScriptError(Exception):
    """One line for the user."""


def build(ap: Path, jobs: int, venv: Path | None, disable_networking: bool) -> None:
    if not (ap / "waf").is_file() or not (ap / "modules" / "waf").is_dir():
        raise ScriptError(f"{ap} is not an ArduPilot checkout with its submodules")
    env = dict(os.environ)
    if venv is not None:
        env["PATH"] = f"{venv / 'bin'}{os.pathsep}{env['PATH']}"
    configure = ["nice", "-n", "19", "./waf", "configure", "--board", "sitl",
                 "--no-submodule-update"]
    if disable_networking:
        configure.append("--disable-networking")
    for cmd in (configure, ["nice", "-n", "19", "./waf", "plane", f"-j{jobs}"]):
        print("+", " ".join(cmd), flush=True)
        if subprocess.run(cmd, cwd=ap, env=env).returncode != 0:
            raise ScriptError(f"{' '.join(cmd)} failed")
    print(ap / "build" / "sitl" / "bin" / "arduplane")


def _in_private_netns() -> None:
    """Re-execute this script in a loopback-only network namespace (does not return)."""
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        raise ScriptError("fly needs unshare(1) and ip(8) for a loopback-only namespace")
    flags = "-n" if os.geteuid() == 0 else "-rn"
    inner = f"ip link set lo up && exec {shlex.join([sys.executable, *sys.argv])}"
    env = dict(os.environ, **{NETNS_ENV: "1"})
    os.execvpe("unshare", ["unshare", flags, "sh", "-c", inner], env)


def _offset(lat_deg: float, lon_deg: float, north_m: float, east_m: float):
    lat = lat_deg + math.degrees(north_m / EARTH_RADIUS_M)
    lon = lon_deg + math.degrees(east_m / (EARTH_RADIUS_M * math.cos(math.radians(lat_deg))))
    return lat, lon


def _mission(mav, home_lat: float, home_lon: float, side_m: float = SQUARE_SIDE_M):
    from pymavlink import mavutil

    m = mavutil.mavlink
    rel = m.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT
    items = [(m.MAV_CMD_NAV_WAYPOINT, 0.0, 0.0, 0.0)]  # item 0: home (ArduPilot overwrites it)
    items.append((m.MAV_CMD_NAV_TAKEOFF, TAKEOFF_PITCH_DEG, 0.0, TAKEOFF_ALT_M))
    items += [(m.MAV_CMD_NAV_WAYPOINT, n * side_m, e * side_m, MISSION_ALT_M)
              for n, e in SQUARE_CORNERS]
    items.append((m.MAV_CMD_NAV_RETURN_TO_LAUNCH, 0.0, 0.0, 0.0))
    messages = []
    for seq, (cmd, a, b, alt) in enumerate(items):
        if cmd == m.MAV_CMD_NAV_TAKEOFF:
            p1, lat, lon = a, home_lat, home_lon
        else:
            p1 = 0.0
            lat, lon = _offset(home_lat, home_lon, a, b)
        messages.append(m.MAVLink_mission_item_int_message(
            mav.target_system, mav.target_component, seq, rel, cmd, 0, 1, p1, 0, 0, 0,
            int(lat * 1e7), int(lon * 1e7), alt, m.MAV_MISSION_TYPE_MISSION))
    mav.mav.mission_count_send(mav.target_system, mav.target_component, len(messages),
                               m.MAV_MISSION_TYPE_MISSION)
    while True:
        req = mav.recv_match(type=["MISSION_REQUEST_INT", "MISSION_REQUEST", "MISSION_ACK"],
                             blocking=True, timeout=10)
        if req is None:
            raise ScriptError("mission upload: no request from ArduPlane in 10 s")
        if req.get_type() == "MISSION_ACK":
            if req.type != m.MAV_MISSION_ACCEPTED:
                raise ScriptError(f"mission upload refused: MISSION_ACK type {req.type}")
            return len(messages)
        mav.mav.send(messages[req.seq])


def fly(ap: Path, physics_cmd: str, timeout_s: float, out: Path, speedup: float = 1.0,
        rate_hz: int | None = None, defaults: tuple[Path, ...] = (),
        square_m: float = SQUARE_SIDE_M, home_radius_m: float = HOME_RADIUS_M) -> dict:
    if os.environ.get(NETNS_ENV) != "1":
        _in_private_netns()
    from pymavlink import mavutil

    binary = ap / "build" / "sitl" / "bin" / "arduplane"
    if not binary.is_file():
        raise ScriptError(f"{binary} not built: run the build step first")
    out.mkdir(parents=True, exist_ok=True)
    procs = []
    summary: dict = {"speedup": speedup, "sim_rate_hz": rate_hz, "square_m": square_m,
                     "home_radius_m": home_radius_m,
                     "loadavg_start": list(os.getloadavg()),
                     "statustext": [], "reached": [], "xtrack_m": []}
    ap_cmd = [str(binary), "--model", "JSON:127.0.0.1", "--speedup", f"{speedup:g}",
              "--slave", "0", "--defaults", ",".join(map(str, (PARAM_FILE, *defaults))),
              "-I0", "--wipe"]
    if rate_hz is not None:
        ap_cmd += ["--rate", str(rate_hz)]
    summary["arduplane_cmd"] = shlex.join(ap_cmd)
    cpu0 = os.times()
    wall0 = time.monotonic()
    try:
        with open(out / "physics.log", "w") as plog, open(out / "arduplane.log", "w") as alog:
            env = dict(os.environ)
            env["PYTHONPATH"] = os.pathsep.join(
                p for p in (str(REPO), env.get("PYTHONPATH", "")) if p)
            procs.append(subprocess.Popen(shlex.split(physics_cmd), cwd=out, stdout=plog,
                                          stderr=subprocess.STDOUT, env=env))
            procs.append(subprocess.Popen(ap_cmd, cwd=out, stdout=alog,
                                          stderr=subprocess.STDOUT))
            mav = _connect(mavutil, procs)
            _run_mission(mav, procs, timeout_s, summary, speedup, square_m, home_radius_m)
    finally:
        summary["physics_end"] = end_processes(procs, PHYSICS_END_WAIT_S)
    summary["wall_s"] = time.monotonic() - wall0
    summary["loadavg_end"] = list(os.getloadavg())
    cpu1 = os.times()
    summary["cpu_s"] = {  # processor time (user + system) [s] over the flight
        "script": (cpu1.user + cpu1.system) - (cpu0.user + cpu0.system),
        "physics_and_arduplane": ((cpu1.children_user + cpu1.children_system)
                                  - (cpu0.children_user + cpu0.children_system))}
    physics_summary = out / "physics.json"  # written by bioflex-jsb ardupilot when stopped
    if physics_summary.is_file():
        try:
            summary["physics"] = json.loads(physics_summary.read_text())
        except ValueError as exc:
            summary["physics"] = f"unreadable {physics_summary}: {exc}"
    summary["real_time_factors"] = real_time_factors(summary)
    summary["speedup_held"] = speedup_held(summary["real_time_factors"]["physics"], speedup)
    summary.update(cross_track_report(summary.pop("xtrack_m")))
    summary["incomplete"] = incomplete(summary)
    return summary


def _stop(p: subprocess.Popen) -> str:
    """SIGTERM, then SIGKILL after 10 s; which one ended it."""
    p.terminate()
    try:
        p.wait(timeout=10)
        return "SIGTERM"
    except subprocess.TimeoutExpired:
        p.kill()
        p.wait()
        return "SIGKILL"


def end_processes(procs: list, physics_wait_s: float) -> dict:
    """End a flight: ArduPlane (``procs[1:]``) stopped first (SIGTERM), then the physics
    (``procs[0]``) given ``physics_wait_s`` [s] to end by itself (``--end-when-silent``:
    ArduPlane's silence), and stopped only if it has not. How the physics ended:
    ``by`` ("itself", "SIGTERM", "SIGKILL", or None if it never started) and its exit
    ``status`` (0: a normal end; 130: it was interrupted)."""
    for p in reversed(procs[1:]):
        if p.poll() is None:
            _stop(p)
    if not procs:
        return {"by": None, "status": None}
    physics = procs[0]
    by = "itself"
    try:
        physics.wait(timeout=physics_wait_s)
    except subprocess.TimeoutExpired:
        by = _stop(physics)
    return {"by": by, "status": physics.returncode}


def real_time_factors(summary: dict) -> dict:
    """The three real-time factors of a flight, each with what it divides."""
    physics = summary.get("physics")
    rtf = physics.get("real_time_factor") if isinstance(physics, dict) else None
    in_flight = None
    if "launch_sent_wall_s" in summary and summary.get("end_wall_s"):
        wall = summary["end_wall_s"] - summary["launch_sent_wall_s"]
        if wall > 0:
            in_flight = (summary["sim_s"] - summary["launch_sent_at_s"]) / wall
    return {
        "physics": rtf,
        "physics_definition": (physics.get("real_time_factor_definition")
                               if isinstance(physics, dict) else "physics.json missing"),
        "arduplane_boot_to_end": (summary["sim_s"] / summary["wall_s"]
                                  if summary.get("sim_s") and summary.get("wall_s") else None),
        "arduplane_boot_to_end_definition": (
            "ArduPlane's SYSTEM_TIME time_boot_ms at the end over this script's wall time, "
            "ArduPlane's boot, EKF alignment and the waits for the physics included"),
        "arduplane_launch_to_end": in_flight,
        "arduplane_launch_to_end_definition": (
            "the change of ArduPlane's SYSTEM_TIME time_boot_ms from the launch switch to the "
            "end over the script's wall time between them: the flight only"),
    }


def speedup_held(real_time_factor: float | None, speedup: float) -> bool | None:
    """Whether the backend's real-time factor is within :data:`HELD_TOLERANCE` of the
    speed-up asked for (None without a factor)."""
    if real_time_factor is None:
        return None
    return abs(real_time_factor - speedup) <= HELD_TOLERANCE * speedup


def _percentile(values: list[float], q: float) -> float:
    """The q-quantile (0..1) of ``values``, linear between order statistics."""
    v = sorted(values)
    pos = q * (len(v) - 1)
    lo = math.floor(pos)
    hi = min(lo + 1, len(v) - 1)
    return v[lo] + (v[hi] - v[lo]) * (pos - lo)


def _stats(values: list[float]) -> dict | None:
    if not values:
        return None
    a = [abs(x) for x in values]
    return {"p95": _percentile(a, 0.95), "max": max(a),
            "rms": math.sqrt(sum(x * x for x in a) / len(a)), "samples": len(a)}


def cross_track_report(samples: list[tuple[float, int, float]]) -> dict:
    """The cross-track error [m] of (time into the leg [s], mission item, error [m])
    samples, twice: from :data:`LEG_SETTLE_S` into each leg, and every sample (the turn at
    each waypoint included); each p95 / max / rms of |error|, and the max per leg."""
    settled = [(t, seq, x) for t, seq, x in samples if t >= LEG_SETTLE_S]
    by_leg: dict[str, dict] = {}
    for seq in sorted({seq for _, seq, _ in samples}):
        by_leg[str(seq)] = {
            "from_8s_max": max((abs(x) for t, q, x in settled if q == seq), default=None),
            "including_turn_max": max(abs(x) for _, q, x in samples if q == seq)}
    return {"xtrack_from_8s_into_leg_m": _stats([x for _, _, x in settled]),
            "xtrack_including_turns_m": _stats([x for _, _, x in samples]),
            "xtrack_by_item_m": by_leg}


def incomplete(summary: dict) -> list[str]:
    """Why the mission was not completed ([] when it was)."""
    why = [f"waypoint item {seq} not reached" for seq in range(2, 2 + len(SQUARE_CORNERS))
           if seq not in summary.get("reached", [])]
    if summary.get("ended") != "home reached in RTL":
        why.append(f"ended: {summary.get('ended', 'timeout')}")
    return why


def exit_status(summary: dict) -> int:
    """EXIT_OK for a completed mission, EXIT_INCOMPLETE otherwise (module docstring)."""
    return EXIT_INCOMPLETE if summary["incomplete"] else EXIT_OK


def _connect(mavutil, procs, timeout_s: float = 60.0):
    """The MAVLink connection to ArduPlane's SERIAL0, once its first HEARTBEAT came.

    One connection, kept: SITL's SERIAL0 accepts a single TCP client (ArduPlane waits for
    it before it boots, then waits for the physics), so a second connection opened while
    the first waits for a heartbeat is never served."""
    deadline = time.monotonic() + timeout_s
    mav = None
    while time.monotonic() < deadline:
        if any(p.poll() is not None for p in procs):
            raise ScriptError("the physics or ArduPlane exited at start (see their logs)")
        if mav is None:
            try:
                # pymavlink prints "[Errno 111] Connection refused sleeping" on stdout while
                # ArduPlane boots: stdout is the JSON summary's, so that goes to stderr
                with contextlib.redirect_stdout(sys.stderr):
                    mav = mavutil.mavlink_connection(MAVLINK_URL, source_system=255)
            except OSError:
                time.sleep(1.0)
                continue
        wait_s = min(1.0, max(0.0, deadline - time.monotonic()))
        if mav.wait_heartbeat(timeout=wait_s) is not None:
            return mav
    raise ScriptError(f"no HEARTBEAT on {MAVLINK_URL} within {timeout_s:.0f} s")


class _Mission:
    """The mission flown over MAVLink, one message at a time (:func:`_run_mission`): what
    each message records, then the next step of the flight it allows (home, mission upload
    and arming, the launch switch, RTL and the end). The waits in wall time are divided by
    ``speedup``: as long in ArduPlane's time. ``square_m`` the square's side [m];
    ``home_radius_m`` how near home [m] RTL ends the flight."""

    def __init__(self, mav, summary: dict, speedup: float, square_m: float = SQUARE_SIDE_M,
                 home_radius_m: float = HOME_RADIUS_M) -> None:
        from pymavlink import mavutil

        self.m = mavutil.mavlink
        self.mav = mav
        self.summary = summary
        self.arm_retry_s = ARM_RETRY_S / speedup
        self.launch_hold_s = LAUNCH_SWITCH_S / speedup
        self.launch_resend_s = LAUNCH_RESEND_S / speedup
        self.square_m, self.home_radius_m = square_m, home_radius_m
        self.state = "wait_gps"
        self.home = None
        self.n_items = 0
        self.sim_s = 0.0
        self.asked_home_s = 0.0
        self.armed = False
        self.arm_sent_s = 0.0
        self.launch_until = 0.0  # wall time [s] until which the launch switch is held
        self.launch_sent_s = 0.0
        self.launch_released = False
        self.current_seq = -1
        self.leg_start_s = 0.0  # ArduPlane's time of the switch to the current item [s]
        self.track = []  # (sim time [s], north [m], east [m], alt above home [m], item)

    def _own_heartbeat(self, msg, kind: str) -> bool:
        return kind == "HEARTBEAT" and msg.get_srcSystem() == self.mav.target_system

    def record(self, msg, kind: str) -> None:
        """What the message says about the flight (times, waypoints, track, error)."""
        summary = self.summary
        if kind == "STATUSTEXT":
            summary["statustext"].append(msg.text)
        elif kind == "SYSTEM_TIME":
            self.sim_s = msg.time_boot_ms * 1e-3
        elif kind == "MISSION_ITEM_REACHED":
            summary["reached"].append(msg.seq)
            summary.setdefault("reached_at_s", []).append(self.sim_s)
        elif kind == "MISSION_CURRENT":
            if msg.seq != self.current_seq:
                self.leg_start_s = self.sim_s
            self.current_seq = msg.seq
        elif self._own_heartbeat(msg, kind):
            self.armed = bool(msg.base_mode & self.m.MAV_MODE_FLAG_SAFETY_ARMED)
            if self.armed and "armed_at_s" not in summary:
                summary["armed_at_s"] = self.sim_s
        elif kind == "GLOBAL_POSITION_INT" and self.state == "auto" and self.home is not None:
            self._track(msg)
        elif kind == "NAV_CONTROLLER_OUTPUT" and self.state == "auto":
            # the square's legs only (items 3..5 fly from corner to corner; item 2 from the
            # end of the take-off)
            if 2 <= self.current_seq <= 1 + len(SQUARE_CORNERS):
                summary["xtrack_m"].append((self.sim_s - self.leg_start_s, self.current_seq,
                                            msg.xtrack_error))
        elif kind == "GPS_RAW_INT" and self.state == "wait_gps" and msg.fix_type >= 3:
            self.state = "wait_ready"
        elif kind == "HOME_POSITION" and self.home is None:
            self.home = (msg.latitude * 1e-7, msg.longitude * 1e-7)

    def _track(self, msg) -> None:
        home = self.home
        dn = math.radians(msg.lat * 1e-7 - home[0]) * EARTH_RADIUS_M
        de = (math.radians(msg.lon * 1e-7 - home[1]) * EARTH_RADIUS_M
              * math.cos(math.radians(home[0])))
        self.track.append((self.sim_s, dn, de, msg.relative_alt * 1e-3, self.current_seq))

    def start(self) -> None:
        """Once GPS has a fix: ask for home until it comes, then upload the mission, AUTO
        and arm; re-send the arming while pre-arm checks refuse it."""
        mav, m = self.mav, self.m
        if self.state == "wait_ready" and self.home is None \
                and time.monotonic() - self.asked_home_s > 1.0:
            self.asked_home_s = time.monotonic()
            mav.mav.command_long_send(mav.target_system, mav.target_component,
                                      m.MAV_CMD_GET_HOME_POSITION, 0, 0, 0, 0, 0, 0, 0, 0)
        if self.state == "wait_ready" and self.home is not None:
            # SITL boots in MANUAL (seen in the documented flight); AUTO only (re)starts the
            # mission on entering it, so go through FBWA first, then start at the take-off
            mav.set_mode("FBWA")
            self.n_items = _mission(mav, *self.home, self.square_m)
            mav.waypoint_set_current_send(1)
            mav.set_mode("AUTO")
            mav.arducopter_arm()
            self.arm_sent_s = time.monotonic()
            self.state = "auto"
        if self.state == "auto" and not self.armed \
                and time.monotonic() - self.arm_sent_s > self.arm_retry_s:
            mav.arducopter_arm()  # pre-arm checks (EKF, GPS) may refuse at first: again
            self.arm_sent_s = time.monotonic()

    def launch(self) -> None:
        """Once armed in AUTO: the launch switch (RC 5 high, SERVO5_FUNCTION 55 passes it
        to the physics) held and re-sent, then released (0: back to RC input)."""
        mav, summary = self.mav, self.summary
        if self.state == "auto" and self.armed and "launch_sent_at_s" not in summary:
            summary["launch_sent_at_s"] = self.sim_s
            summary["launch_sent_wall_s"] = time.monotonic()
            self.launch_until = time.monotonic() + self.launch_hold_s
        if self.state == "auto" and self.armed and time.monotonic() < self.launch_until \
                and time.monotonic() - self.launch_sent_s > self.launch_resend_s:
            self.launch_sent_s = time.monotonic()
            mav.mav.rc_channels_override_send(
                mav.target_system, mav.target_component,
                *([NO_OVERRIDE] * 4), LAUNCH_SWITCH_PWM_US, *([NO_OVERRIDE] * 3))
        elif self.launch_until and time.monotonic() >= self.launch_until \
                and not self.launch_released:
            self.launch_released = True
            mav.mav.rc_channels_override_send(
                mav.target_system, mav.target_component,
                *([NO_OVERRIDE] * 4), 0, *([NO_OVERRIDE] * 3))

    def home_reached(self, msg, kind: str) -> bool:
        """Whether the mission's RTL has been flown: RTL_WATCH_S in RTL, then near home."""
        summary = self.summary
        if self.state == "auto" and self._own_heartbeat(msg, kind) \
                and msg.custom_mode == PLANE_MODE_RTL and "rtl_at_s" not in summary:
            summary["rtl_at_s"] = self.sim_s
        if self.state == "auto" and "rtl_at_s" in summary \
                and self.sim_s - summary["rtl_at_s"] > RTL_WATCH_S:
            # the mission's RTL flown: home and loitering there
            return self.mav.location().alt is not None and _near_home(
                self.mav, self.home, self.home_radius_m)
        return False


def _run_mission(mav, procs, timeout_s: float, summary: dict, speedup: float = 1.0,
                 square_m: float = SQUARE_SIDE_M, home_radius_m: float = HOME_RADIUS_M) -> None:
    """Wait for a GPS fix and home, upload the mission, AUTO + arm, watch until home.
    The waits in wall time are divided by ``speedup``: as long in ArduPlane's time."""
    flight = _Mission(mav, summary, speedup, square_m, home_radius_m)
    for stream in STREAMS:
        mav.mav.request_data_stream_send(mav.target_system, mav.target_component,
                                         getattr(flight.m, stream), STREAM_RATE_HZ, 1)
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if any(p.poll() is not None for p in procs):
            summary["ended"] = "a process exited"
            break
        msg = mav.recv_match(blocking=True, timeout=1.0)
        if msg is None:
            continue
        kind = msg.get_type()
        flight.record(msg, kind)
        flight.start()
        flight.launch()
        if flight.home_reached(msg, kind):
            summary["ended"] = "home reached in RTL"
            break
    summary["sim_s"] = flight.sim_s
    summary["end_wall_s"] = time.monotonic()
    summary["mission_items"] = flight.n_items
    summary["track"] = flight.track[::10]  # ≈ 1 s apart at the 10 Hz stream


def _near_home(mav, home, radius_m: float = HOME_RADIUS_M) -> bool:
    loc = mav.location()
    dn = math.radians(loc.lat - home[0]) * EARTH_RADIUS_M
    de = math.radians(loc.lng - home[1]) * EARTH_RADIUS_M * math.cos(math.radians(home[0]))
    return math.hypot(dn, de) < radius_m


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build", help="build ArduPlane SITL in an ArduPilot checkout")
    b.add_argument("ardupilot", type=Path)
    b.add_argument("--jobs", type=int, default=1)
    b.add_argument("--venv", type=Path, default=None)
    b.add_argument("--disable-networking", action="store_true")
    f = sub.add_parser("fly", help="fly the mission in a loopback-only network namespace")
    f.add_argument("ardupilot", type=Path)
    f.add_argument("--physics-cmd", default=DEFAULT_PHYSICS_CMD)
    f.add_argument("--timeout-s", type=float, default=900.0)
    f.add_argument("--out", type=Path, default=Path("ardupilot_run"))
    f.add_argument("--speedup", type=float, default=1.0,
                   help="ArduPlane's --speedup (default 1)")
    f.add_argument("--rate", type=int, default=None,
                   help="ArduPlane's --rate: SIM_RATE_HZ [Hz] (default ArduPilot's, 1200)")
    f.add_argument("--defaults", type=Path, action="append", default=[],
                   help="a parameter file loaded after bioflex_plane.parm (its values win; "
                   "ArduPlane's --defaults takes them comma-separated); repeatable")
    f.add_argument("--square-m", type=float, default=SQUARE_SIDE_M,
                   help="the mission square's side [m] (default 300, the prototype's; "
                   "scale it with the turn radius, e.g. 3000 for the c172)")
    f.add_argument("--home-radius-m", type=float, default=HOME_RADIUS_M,
                   help="RTL ends the flight this near home [m] (default 100; above the "
                   "aircraft's WP_LOITER_RAD)")
    args = parser.parse_args(argv)
    try:
        if args.command == "build":
            if args.jobs < 1:
                raise ScriptError(f"--jobs must be >= 1, got {args.jobs}")
            build(args.ardupilot.resolve(), args.jobs, args.venv, args.disable_networking)
        else:
            if not (math.isfinite(args.speedup) and args.speedup > 0):
                raise ScriptError(f"--speedup must be > 0, got {args.speedup:g}")
            if args.rate is not None and args.rate < 1:
                raise ScriptError(f"--rate must be >= 1 Hz, got {args.rate}")
            for name, value in (("--square-m", args.square_m),
                                ("--home-radius-m", args.home_radius_m)):
                if not (math.isfinite(value) and value > 0):
                    raise ScriptError(f"{name} must be > 0 m, got {value:g}")
            for extra in args.defaults:
                if not extra.is_file() or "," in str(extra.resolve()):
                    raise ScriptError(f"--defaults {extra}: not a file (or a comma in its path)")
            summary = fly(args.ardupilot.resolve(), args.physics_cmd, args.timeout_s,
                          args.out.resolve(), args.speedup, args.rate,
                          tuple(p.resolve() for p in args.defaults), args.square_m,
                          args.home_radius_m)
            print(json.dumps(summary, indent=1))
            if summary["incomplete"]:
                print(f"ardupilot_sitl: mission not completed: {'; '.join(summary['incomplete'])}",
                      file=sys.stderr)
            return exit_status(summary)
    except ScriptError as exc:
        print(f"ardupilot_sitl: {exc}", file=sys.stderr)
        return EXIT_ERROR
    return EXIT_OK


if __name__ == "__main__":
    sys.exit(main())
