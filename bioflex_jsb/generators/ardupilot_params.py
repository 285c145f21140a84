"""An ArduPlane parameter file for another aircraft flown through the JSON SITL backend
(``bioflex-jsb ardupilot --aircraft A --write-parm FILE``; docs/ardupilot.md, "Another
aircraft").

The prototype's file, ``bioflex_jsb/data/ardupilot/bioflex_plane.parm``, was written by hand
for the 2.5 kg prototype and checked against ArduPlane master 90700977c553 (V4.7.0-dev). The
one written here has its structure, names and every setting that does not depend on the
aircraft (the launch, the servo functions, the RC inputs and flight modes, logging), and the
numbers that do from the aircraft's own envelope and its JSBSim model
(:class:`PlaneNumbers`, gathered by :func:`bioflex_jsb.drivers.ardupilot.plane_numbers`),
each derived by the prototype's file's own rule:

* airspeeds: AIRSPEED_CRUISE its cruise speed, AIRSPEED_MIN and AIRSPEED_MAX its flight
  speeds' ends, AIRSPEED_STALL √(2W/(ρ S C_L,max)), SCALING_SPEED the cruise (older
  ArduPlane names: TRIM_ARSPD_CM, ARSPD_FBW_MIN, ARSPD_FBW_MAX; renamed in ArduPlane 4.5,
  the names used here are the checked commit's);
* TRIM_THROTTLE the trim throttle at the cruise speed [%];
* the rate controllers' feed-forward: 45 (full throw) over the steady roll and pitch rates
  a full command gives at the cruise speed [deg/s] (AP_FW_Controller: out = FF · rate ·
  SCALING_SPEED/V), the rate limits at most 0.75 of them (and the prototype's 90 deg/s);
* navigation: WP_RADIUS 1.3 times the turn radius at ROLL_LIMIT_DEG (45°), WP_LOITER_RAD the
  turn radius at 30°, NAVL1_PERIOD so that the L1 distance is 1.88 times the 45° turn radius
  (the prototype's 43 m against 22.9 m);
* TECS: TECS_CLMB_MAX two thirds of the climb rate the thrust left at full throttle gives at
  the cruise speed, TECS_SINK_MIN the idle descent there, TECS_SINK_MAX the idle dive at
  AIRSPEED_MAX (the larger of the polar's drag power over the weight and the idle descent
  scaled with the speed);
* TKOFF_THR_MINSPD the prototype's 4 m/s at 15 m/s scaled with the exit speed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2

ROLL_LIMIT_DEG = 45.0  # ArduPlane's default; the stall margin at it is in the file
L1_OVER_TURN45 = 43.0 / 22.9  # the prototype's file: L1 43 m, 45° turn radius 22.9 m
WP_RADIUS_OVER_TURN45 = 1.3  # the prototype's file: 30 m for 22.9 m
RATE_LIMIT_SHARE = 0.75  # of the rate a full command gives
PROTOTYPE_RATE_MAX_DEG_S = 90.0  # the prototype's file (plane.parm)
PROTOTYPE_MINSPD_M_S, PROTOTYPE_EXIT_M_S = 4.0, 15.0  # TKOFF_THR_MINSPD at its exit speed


@dataclass(frozen=True)
class PlaneNumbers:
    """What the file needs of the aircraft (SI): its name and where the numbers come from,
    cruise, lowest and highest flight speed [m/s], stall speed [m/s], trim throttle [-],
    the steady roll and pitch rates of a full command [rad/s], the climb angles the thrust
    gives at full throttle and idle at the cruise speed [rad], the idle dive at the highest
    speed [m/s, down], the control directions (+1/−1 per unit command for roll right,
    nose up, nose right) and the engine count."""

    name: str
    source: str
    cruise_m_s: float
    min_m_s: float
    max_m_s: float
    stall_m_s: float
    trim_throttle: float
    roll_rate_full_rad_s: float
    pitch_rate_full_rad_s: float
    climb_angle_full_rad: float
    climb_angle_idle_rad: float
    dive_sink_max_m_s: float
    signs: tuple[float, float, float]
    engines: int


def _turn_radius_m(v_m_s: float, bank_deg: float) -> float:
    return v_m_s**2 / (STANDARD_GRAVITY_M_S2 * math.tan(math.radians(bank_deg)))


def plane_values(n: PlaneNumbers) -> dict[str, tuple[float, str]]:
    """The aircraft's parameters: name → (value, the comment saying where it comes from)."""
    v = n.cruise_m_s
    r45, r30 = _turn_radius_m(v, ROLL_LIMIT_DEG), _turn_radius_m(v, 30.0)
    roll_deg_s = math.degrees(abs(n.roll_rate_full_rad_s))
    pitch_deg_s = math.degrees(abs(n.pitch_rate_full_rad_s))
    l1_m = L1_OVER_TURN45 * r45
    stall_45 = n.stall_m_s * math.sqrt(1.0 / math.cos(math.radians(ROLL_LIMIT_DEG)))
    climb = v * math.sin(n.climb_angle_full_rad)
    sink = -v * math.sin(n.climb_angle_idle_rad)
    return {
        "AIRSPEED_CRUISE": (v, "its cruise speed (older ArduPlane: TRIM_ARSPD_CM in cm/s)"),
        "AIRSPEED_STALL": (n.stall_m_s, "sqrt(2W/(rho S CL_max)), level, sea level"),
        "AIRSPEED_MIN": (n.min_m_s, f"its lowest flight speed (ARSPD_FBW_MIN); stall at the "
                         f"{ROLL_LIMIT_DEG:g} deg ROLL_LIMIT is {stall_45:.1f} m/s"),
        "AIRSPEED_MAX": (n.max_m_s, "its highest flight speed (ARSPD_FBW_MAX)"),
        "SCALING_SPEED": (v, "its cruise: the speed the rate gains are scaled at"),
        "TRIM_THROTTLE": (round(100.0 * n.trim_throttle),
                          f"trim throttle {n.trim_throttle:.3f} at {v:g} m/s [%]"),
        "RLL_RATE_FF": (45.0 / roll_deg_s,
                        f"45 / {roll_deg_s:.1f} deg/s, the roll rate of full aileron"),
        "RLL2SRV_RMAX": (math.floor(min(PROTOTYPE_RATE_MAX_DEG_S, RATE_LIMIT_SHARE * roll_deg_s)),
                         "[deg/s] 0.75 of full aileron's rate, at most the prototype's 90"),
        "PTCH_RATE_FF": (45.0 / pitch_deg_s,
                         f"45 / {pitch_deg_s:.1f} deg/s, the steady pull-up of full elevator"),
        "PTCH2SRV_RMAX_UP": (math.floor(min(PROTOTYPE_RATE_MAX_DEG_S,
                                            RATE_LIMIT_SHARE * pitch_deg_s)),
                             "[deg/s] 0.75 of full elevator's, at most 90"),
        "PTCH2SRV_RMAX_DN": (math.floor(min(PROTOTYPE_RATE_MAX_DEG_S,
                                            RATE_LIMIT_SHARE * pitch_deg_s)),
                             "[deg/s] as up"),
        "NAVL1_PERIOD": (min(60.0, math.pi * l1_m / (0.75 * v)),
                         f"L1 = period*0.75*V/pi = {l1_m:.0f} m, 1.88 x the {r45:.0f} m "
                         "turn radius at 45 deg (the prototype's ratio); at most 60"),
        "WP_RADIUS": (round(WP_RADIUS_OVER_TURN45 * r45),
                      f"1.3 x the {r45:.0f} m turn radius at 45 deg"),
        "WP_LOITER_RAD": (round(r30), "turn radius at 30 deg bank: V^2/(g tan 30)"),
        "TECS_CLMB_MAX": (2.0 / 3.0 * climb, f"2/3 of the {climb:.1f} m/s full throttle "
                          f"gives at {v:g} m/s"),
        "TECS_SINK_MIN": (sink, f"idle descent at {v:g} m/s (thrust at idle, JSBSim)"),
        "TECS_SINK_MAX": (max(n.dive_sink_max_m_s, sink * n.max_m_s / v, sink),
                          f"idle dive at {n.max_m_s:g} m/s"),
        "TKOFF_THR_MINSPD": (PROTOTYPE_MINSPD_M_S * v / PROTOTYPE_EXIT_M_S,
                             f"the prototype's 4 m/s at its 15 m/s exit, at {v:g} m/s"),
    }


def _num(x: float) -> str:
    x = float(x)
    if abs(x - round(x)) < 1e-9:
        return str(int(round(x)))
    return f"{x:.3g}" if abs(x) < 10 else f"{x:.1f}"


def _line(name: str, value, comment: str) -> str:
    text = value if isinstance(value, str) else _num(value)
    return f"{name:<16} {text:<6} # {comment}"


def render_plane_parm(n: PlaneNumbers) -> str:
    """The ArduPlane parameter file of ``n`` (module docstring)."""
    values = plane_values(n)
    lines = [
        f"# ArduPlane parameters for {n.name} flown through ArduPilot's JSON SITL backend",
        "# (bioflex-jsb ardupilot --aircraft; written by bioflex_jsb.generators.ardupilot_params",
        "# from the aircraft's own numbers; bioflex_jsb/data/ardupilot/bioflex_plane.parm is",
        "# the prototype's, written by hand: same structure, names checked against ArduPlane",
        "# master 90700977c553, V4.7.0-dev). Load with: arduplane --model JSON:127.0.0.1",
        "# --defaults <this file> (docs/ardupilot.md).",
        f"# Numbers from: {n.source}.",
        "# Channel directions, applied by the physics (SERVOn_REVERSED stays 0): the JSBSim",
        f"# command per unit of PWM above trim (roll right, nose up, nose right): aileron "
        f"{n.signs[0]:+g}, elevator {n.signs[1]:+g}, rudder {n.signs[2]:+g}; the throttle "
        f"to every engine ({n.engines}).",
        "",
        "# ---- Airspeed (m/s) ------------------------------------------------------------------",
        _line("ARSPD_TYPE", 100, "SITL airspeed sensor: the JSON \"airspeed\" field"),
        _line("ARSPD_USE", 1, "fly on airspeed (plane.parm)"),
    ]
    for name in ("AIRSPEED_CRUISE", "AIRSPEED_STALL", "AIRSPEED_MIN", "AIRSPEED_MAX",
                 "SCALING_SPEED"):
        lines.append(_line(name, *values[name]))
    lines += [
        "",
        "# ---- Attitude limits (deg) -----------------------------------------------------------",
        _line("ROLL_LIMIT_DEG", ROLL_LIMIT_DEG, "default"),
        _line("PTCH_LIM_MAX_DEG", 20, "default"),
        _line("PTCH_LIM_MIN_DEG", -25, "default"),
        _line("PTCH_TRIM_DEG", 0, "plane.parm; the trim attitude is left to TECS"),
        "",
        "# ---- Roll and pitch controllers ------------------------------------------------------",
        _line("RLL2SRV_TCONST", 0.5, "default"),
        _line("RLL2SRV_RMAX", *values["RLL2SRV_RMAX"]),
        _line("RLL_RATE_FF", *values["RLL_RATE_FF"]),
        _line("RLL_RATE_P", 0.08, "default"),
        _line("RLL_RATE_I", 0.15, "default"),
        _line("RLL_RATE_D", 0, "default"),
        _line("PTCH2SRV_TCONST", 0.5, "default"),
        _line("PTCH2SRV_RMAX_UP", *values["PTCH2SRV_RMAX_UP"]),
        _line("PTCH2SRV_RMAX_DN", *values["PTCH2SRV_RMAX_DN"]),
        _line("PTCH2SRV_RLL", 1, "plane.parm"),
        _line("PTCH_RATE_FF", *values["PTCH_RATE_FF"]),
        _line("PTCH_RATE_P", 0.04, "default"),
        _line("PTCH_RATE_I", 0.15, "default"),
        _line("PTCH_RATE_D", 0, "default"),
        _line("KFF_RDDRMIX", 0.5, "plane.parm: rudder follows aileron"),
        "",
        "# ---- Navigation (L1) and waypoints (m) -----------------------------------------------",
        _line("NAVL1_PERIOD", *values["NAVL1_PERIOD"]),
        _line("NAVL1_DAMPING", 0.75, "default"),
        _line("WP_RADIUS", *values["WP_RADIUS"]),
        _line("WP_LOITER_RAD", *values["WP_LOITER_RAD"]),
        _line("RTL_RADIUS", 0, "default: RTL loiters at WP_LOITER_RAD"),
        _line("RTL_AUTOLAND", 0, "default"),
        _line("MIS_RESTART", 1, "every entry into AUTO starts the mission from its first item"),
        "",
        "# ---- TECS (m/s) ----------------------------------------------------------------------",
        _line("TECS_CLMB_MAX", *values["TECS_CLMB_MAX"]),
        _line("TECS_SINK_MIN", *values["TECS_SINK_MIN"]),
        _line("TECS_SINK_MAX", *values["TECS_SINK_MAX"]),
        _line("TECS_TIME_CONST", 5, "default"),
        _line("TECS_SPDWEIGHT", 1, "default"),
        _line("TECS_PTCH_DAMP", 0.3, "default"),
        "",
        "# ---- Throttle (%) --------------------------------------------------------------------",
        _line("THR_MIN", 0, "default"),
        _line("THR_MAX", 100, "plane.parm"),
        _line("TRIM_THROTTLE", *values["TRIM_THROTTLE"]),
        _line("THR_SLEWRATE", 100, "default [%/s]"),
        "",
        "# ---- Launch from rest (docs/ardupilot.md, \"Start\"): as the prototype's file ------",
        _line("TKOFF_THR_MINACC", 15, "paramdoc: hand and bungee launches [m/s^2]"),
        _line("TKOFF_ACCEL_CNT", 1, "default"),
        _line("TKOFF_THR_DELAY", 2, "paramdoc: >= 2 (0.2 s) [ds]"),
        _line("TKOFF_THR_MINSPD", *values["TKOFF_THR_MINSPD"]),
        _line("TKOFF_THR_IDLE", 5, "armed-and-waiting throttle in TAKEOFF mode [%]"),
        _line("TKOFF_THR_MAX", 100, "full power for the climb-out"),
        _line("TKOFF_THR_MAX_T", 4, "default [s]"),
        _line("TKOFF_TIMEOUT", 0, "default: no ground roll"),
        "",
        "# ---- Servo outputs: the channel map (docs/ardupilot.md) ------------------------------",
    ]
    for i, (function, what) in enumerate(((4, "aileron"), (19, "elevator"), (70, "throttle"),
                                          (21, "rudder")), 1):
        lines.append(_line(f"SERVO{i}_FUNCTION", function, what))
        lines.append(_line(f"SERVO{i}_MIN", 1000, "plane.parm"))
        lines.append(_line(f"SERVO{i}_MAX", 2000, "plane.parm"))
        lines.append(_line(f"SERVO{i}_TRIM", 1000 if function == 70 else 1500, "plane.parm"))
        if function != 70:
            lines.append(_line(f"SERVO{i}_REVERSED", 0, "the physics applies the direction"))
    lines += [
        _line("SERVO5_FUNCTION", 55, "RCIN5 passthrough: the launcher's fire switch"),
        "",
        "# ---- SITL RC input and flight modes (plane.parm) -------------------------------------",
    ]
    for ch in (1, 2, 3, 4):
        lines += [f"RC{ch}_MIN 1000", f"RC{ch}_MAX 2000",
                  f"RC{ch}_TRIM {1000 if ch == 3 else 1500}"]
    lines += [
        _line("FLTMODE_CH", 8, "plane.parm"),
        _line("FLTMODE1", 10, "AUTO"), _line("FLTMODE2", 11, "RTL"),
        _line("FLTMODE3", 12, "LOITER"), _line("FLTMODE4", 5, "FBWA"),
        _line("FLTMODE5", 2, "STABILIZE"), _line("FLTMODE6", 0, "MANUAL"),
        "",
        "# ---- Logging and battery (plane.parm) ------------------------------------------------",
        "LOG_BITMASK      65535",
        "BATT_MONITOR     4",
        "",
    ]
    return "\n".join(lines)


def read_parm(text: str) -> dict[str, float]:
    """The parameters of a parameter file's text (``NAME VALUE`` per line, ``#`` comments):
    name → value (for checks; ArduPilot's own reader is the authority)."""
    out = {}
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        name, value = line.split()[:2]
        out[name] = float(value)
    return out
