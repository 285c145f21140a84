"""What the SITL aircraft does as a vehicle: modes, arming, home, missions, guidance, the
battery, and the events a pilot should see (docs/sitl.md).

The vehicle acts on the JSBSim autopilot (``systems/bioflex_autopilot.xml``,
``systems/bioflex_autothrottle.xml``; :mod:`bioflex_jsb.generators.autopilot`) through its
``ap/*`` properties, every :data:`GUIDANCE_PERIOD_S` of simulated time:

========== ===============================================================================
MANUAL     autopilot off; MANUAL_CONTROL x, y move elevator and ailerons about the trim
STABILIZE  (and FBWA) the sticks command bank (±30°) and pitch (θ_trim ∓ 15°); centred:
           wings level at the trim pitch; airspeed held
CRUISE     heading and altitude hold (AP_HDG_RAD, AP_ALT_M); airspeed held. The start mode
CIRCLE     a fixed 20° bank (AP_LOITER 1), altitude held
LOITER     L1 circle of LOIT_RAD_M about where it was entered (or the NAV_LOITER_UNLIM point)
AUTO       the mission (mavlink_mission), from its current item
RTL        L1 track to home at RTL_ALT_M above home, then LOITER about home
GUIDED     L1 track to the DO_REPOSITION point, then a loiter there
========== ===============================================================================

Lateral guidance: L1 (:mod:`bioflex_jsb.simulation.guidance`), bank commanded through
``ap/roll-mode`` 1. Waypoints are reached within their acceptance radius (item param2, else
WP_RADIUS_M) — not by passing abeam: an aircraft that misses one turns back for it.
The altitude of a waypoint is commanded from the start of its leg (no slope).

A glider (``sim.glider``: an aircraft without an engine flying the glider's autopilot,
:func:`bioflex_jsb.generators.autopilot.render_glider_autopilot`) flies the same modes with
its airspeed held by the pitch loop and no altitude hold: it descends along its glide.
Commands that set only an altitude (DO_CHANGE_ALTITUDE, AP_ALT_M, a guided item with
current = 3) are refused with the reason; the altitudes of positions (waypoints,
DO_REPOSITION, RTL_ALT_M) are not flown, which the mode's STATUSTEXT says once.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable

from bioflex_jsb import units as U
from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.links.mavlink_mission import (
    AMSL_FRAMES,
    DO_CHANGE_SPEED,
    INVALID_PARAM,
    INVALID_PARAM7,
    NAV_LOITER_TIME,
    NAV_LOITER_TURNS,
    NAV_LOITER_UNLIM,
    NAV_RETURN_TO_LAUNCH,
    NAV_TAKEOFF,
    NAV_WAYPOINT,
    RELATIVE_FRAMES,
    MissionItem,
    check_item,
)
from bioflex_jsb.simulation import guidance as G
from bioflex_jsb.simulation.battery import Battery

M_INVALID_PARAM, M_INVALID_PARAM7 = INVALID_PARAM, INVALID_PARAM7

GUIDANCE_PERIOD_S = 0.02  # simulated time between guidance updates [s]
# sticks older than this [simulated s]: control lost → RTL (a paused or slowed simulation keeps
# them; one faster than real time ages them in its own seconds)
MANUAL_TIMEOUT_S = 1.0
STICK_BANK_RAD = math.radians(30.0)
STICK_PITCH_RAD = math.radians(15.0)
FORCE_DISARM = 21196  # MAV_CMD_COMPONENT_ARM_DISARM param2: disarm in flight
AIRSPEED_RANGE_M_S = (12.0, 22.0)
# Home (--home, MAV_CMD_DO_SET_HOME): the local north-east frame divides by cos(latitude), so
# the poles are kept out; ground altitudes from the Dead Sea shore to high plateaus [m AMSL].
HOME_LATITUDE_RANGE_DEG = (-85.0, 85.0)
HOME_LONGITUDE_RANGE_DEG = (-180.0, 180.0)
HOME_ALTITUDE_RANGE_M = (-400.0, 5000.0)
WP_RADIUS_RANGE_M = (5.0, 500.0)  # as the parameter WP_RADIUS_M
LOITER_RADIUS_RANGE_M = (20.0, 1000.0)  # as LOIT_RAD_M
LOITER_TURNS_MAX = 1000.0  # NAV_LOITER_TURNS param1
LOITER_TIME_MAX_S = 86400.0  # NAV_LOITER_TIME param1: a day
SEVERITY = {"error": 3, "warning": 4, "notice": 5, "info": 6}


class VehicleSettings:
    """Navigation parameters (served as parameters by SitlParameters; SI)."""

    def __init__(self) -> None:
        self.wp_radius_m = 30.0
        self.loiter_radius_m = 50.0
        self.rtl_altitude_m = 100.0  # above home
        self.l1_period_s = 17.0
        self.l1_damping = 0.75


class SitlVehicle:
    """The vehicle behaviour of a :class:`~bioflex_jsb.drivers.sitl.SitlSim`."""

    def __init__(self, sim, home: tuple[float, float, float], start_mode: int = MODES.CRUISE):
        self.sim = sim
        self.settings = VehicleSettings()
        self.home = home  # latitude, longitude [rad], ground altitude [m AMSL]
        self.armed = True  # it starts in the air, motor running
        self.battery = Battery()
        self.events: deque[tuple[int, str]] = deque(maxlen=64)
        # on_status(t_s, severity, text): every STATUSTEXT as it is queued (the session log)
        self.on_status: Callable[[float, int, str], None] | None = None
        self.reached: deque[int] = deque(maxlen=16)
        self.mission: list[MissionItem] = []
        self.mission_seq = 0
        self.speed_target_m_s = sim.speed_m_s
        self.alt_target_m = sim.start_altitude_m
        self.heading_target_rad = 0.0
        self.mode = start_mode
        self._sticks = (0.0, 0.0)
        self._stick_t_s: float | None = None  # simulated time of the last sticks [s]
        self._nav: tuple = ("heading",)
        self._item_state: dict = {}
        self._last_t = 0.0
        self._guided_target: tuple[float, float] | None = None
        self._guided_loiter = (0.0, True)  # radius [m] (0: LOIT_RAD_M), clockwise
        self.refusals = 0  # commands, parameters, overrides and items refused
        self._battery_warned = False
        self.set_mode(start_mode, quiet=True)

    # -- events ---------------------------------------------------------------------------
    def status(self, severity: int, text: str) -> None:
        """Queue a STATUSTEXT (MAV_SEVERITY ``severity``; ≤ 50 characters are sent whole)
        and hand it to ``on_status`` with the simulated time [s]."""
        self.events.append((int(severity), str(text)))
        if self.on_status is not None:
            self.on_status(self.sim.t_s, int(severity), str(text))

    def refused(self, text: str) -> None:
        """A refusal the link has already told the ground station (STATUSTEXT WARNING):
        counted, and handed to ``on_status`` (an event of the session log)."""
        self.refusals += 1
        if self.on_status is not None:
            self.on_status(self.sim.t_s, 4, str(text))

    @property
    def mode_name(self) -> str:
        return MODES.mode_name(self.mode)

    @property
    def altitude_range_m(self) -> tuple[float, float]:
        """Altitudes commanded [m AMSL]: the ground + 20 … + 1500 m."""
        return self.sim.altitude_hold_range_m

    @property
    def ground_altitude_m(self) -> float:
        """The flat ground [m AMSL] (the start home's; DO_SET_HOME does not move it)."""
        return self.sim.home_deg[2]

    # -- where it is --------------------------------------------------------------------
    def position_ne(self) -> tuple[float, float]:
        g = self.sim.core.get
        return G.ne_from_latlon(g["lat"](), g["lon"](), self.home[0], self.home[1])

    def velocity_ne(self) -> tuple[float, float]:
        g = self.sim.core.get
        return g["vn"]() * U.M_PER_FT, g["ve"]() * U.M_PER_FT

    def altitude_m(self) -> float:
        return self.sim.core.get["h"]() * U.M_PER_FT

    def _ne(self, lat_rad: float, lon_rad: float) -> tuple[float, float]:
        return G.ne_from_latlon(lat_rad, lon_rad, self.home[0], self.home[1])

    def _item_alt_m(self, item: MissionItem) -> float:
        """The item's altitude [m AMSL] (relative and terrain frames: above home)."""
        return item.z if item.frame in AMSL_FRAMES else self.home[2] + item.z

    # -- modes ----------------------------------------------------------------------------
    def set_mode(self, number: int, quiet: bool = False) -> str | None:
        """Enter mode ``number`` (ArduPlane's); None, or why not."""
        number = int(number)
        if number not in MODES.MODE_NAMES:
            return f"mode {number} is not flown by this vehicle"
        if number == MODES.AUTO and len(self.mission) < 2:
            return "no mission to fly"
        pos = self.position_ne()
        a = self.sim.airframe
        self.mode = number
        if number in (MODES.CRUISE, MODES.CIRCLE):
            self.heading_target_rad = self.sim.core.get["psi"]()
            self.alt_target_m = self.altitude_m()
            a["ap/heading-hold-rad"] = math.remainder(self.heading_target_rad, 2 * math.pi)
            self._nav = ("heading",)
        elif number == MODES.LOITER:
            self.alt_target_m = self.altitude_m()
            self._nav = ("circle", pos, self.settings.loiter_radius_m, True)
        elif number == MODES.RTL:
            self.alt_target_m = self.home[2] + self.settings.rtl_altitude_m
            self._nav = ("goto", pos, (0.0, 0.0), "home")
        elif number == MODES.GUIDED:
            target = self._guided_target or pos
            self._nav = ("goto", pos, target, "guided")
        elif number == MODES.AUTO:
            if self.mission_seq < 1 or self.mission_seq >= len(self.mission):
                self.mission_seq = 1
            self._start_item(pos)
        else:  # stick modes
            self._nav = ("stick",)
        if not quiet:
            note = (" (glider: altitude not held)" if self.sim.glider and number not in
                    (MODES.MANUAL, MODES.STABILIZE, MODES.FLY_BY_WIRE_A) else "")
            self.status(6, f"Mode {MODES.mode_name(number)}{note}")
        self._apply_mode_flags()
        return None

    def _apply_mode_flags(self) -> None:
        a, m = self.sim.airframe, self.mode
        a["ap/engage"] = 0.0 if m == MODES.MANUAL else 1.0
        a["ap/manual"] = 1.0 if m == MODES.MANUAL else 0.0
        if m == MODES.MANUAL:
            a["ap/manual-elevator-norm"], a["ap/manual-aileron-norm"] = self._sticks
        a["ap/loiter"] = 1.0 if m == MODES.CIRCLE else 0.0
        a["ap/autothrottle"] = 0.0 if m == MODES.MANUAL else 1.0
        a["ap/airspeed-hold-mps"] = self.speed_target_m_s
        a["ap/armed"] = 1.0 if self.armed else 0.0
        stick = m in (MODES.STABILIZE, MODES.FLY_BY_WIRE_A)
        a["ap/pitch-mode"] = 1.0 if stick else 0.0
        a["ap/roll-mode"] = 1.0 if (stick or self._nav[0] in ("circle", "goto", "track")) \
            else 0.0
        a["ap/altitude-hold-m"] = self.alt_target_m

    def arm(self, armed: bool, force: bool) -> str | None:
        if armed == self.armed:
            return None
        if not armed and not force:
            return "disarm in flight refused (force with param2 = 21196)"
        self.armed = armed
        self.sim.airframe["ap/armed"] = 1.0 if armed else 0.0
        motor = "no motor (glider)" if self.sim.glider else "motor stopped"
        self.status(4 if not armed else 6, f"Disarmed: {motor}" if not armed else "Armed")
        return None

    def manual(self, pitch: float | None, roll: float | None) -> bool:
        """Sticks (−1..1; pitch + = nose down, roll + = right), or None: released. Obeyed
        only in MANUAL, STABILIZE and FBWA."""
        if pitch is None or roll is None:
            self._sticks, self._stick_t_s = (0.0, 0.0), None
            if self.mode == MODES.MANUAL:
                self._apply_mode_flags()
            return True
        if self.mode not in MODES.STICK_MODES:
            return False
        self._sticks = (max(-1.0, min(1.0, pitch)), max(-1.0, min(1.0, roll)))
        self._stick_t_s = self.sim.t_s
        if self.mode == MODES.MANUAL:
            a = self.sim.airframe
            a["ap/manual-elevator-norm"], a["ap/manual-aileron-norm"] = self._sticks
        return True

    # -- commands -------------------------------------------------------------------------
    def change_speed(self, speed_m_s: float) -> str | None:
        lo, hi = self.sim.airspeed_range_m_s
        if not lo <= speed_m_s <= hi:
            return f"airspeed must be in {lo:g}..{hi:g} m/s"
        self.speed_target_m_s = float(speed_m_s)
        self.sim.airframe["ap/airspeed-hold-mps"] = self.speed_target_m_s
        self.status(6, f"Airspeed target {speed_m_s:.1f} m/s")
        return None

    def change_altitude(self, alt_amsl_m: float) -> str | None:
        if self.sim.glider:
            return ("a glider cannot hold an altitude (no engine): it glides at the airspeed "
                    "target (AIRSPEED_MS)")
        lo, hi = self.sim.altitude_hold_range_m
        if not lo <= alt_amsl_m <= hi:
            return f"altitude must be in {lo:.0f}..{hi:.0f} m AMSL"
        self.alt_target_m = float(alt_amsl_m)
        self.sim.airframe["ap/altitude-hold-m"] = self.alt_target_m
        return None

    def set_heading(self, heading_rad: float) -> None:
        """CRUISE at ``heading_rad`` (parameter AP_HDG_RAD)."""
        if self.mode != MODES.CRUISE:
            self.set_mode(MODES.CRUISE)
        self.heading_target_rad = math.remainder(heading_rad, 2 * math.pi)
        self.sim.airframe["ap/heading-hold-rad"] = self.heading_target_rad

    def reposition(self, lat_rad: float, lon_rad: float, alt_amsl_m: float | None,
                   radius_m: float = 0.0, clockwise: bool = True) -> str | None:
        """GUIDED to (lat, lon) [rad] at ``alt_amsl_m`` (None: kept), then loiter there with
        ``radius_m`` [m] (0: LOIT_RAD_M) in the direction ``clockwise``."""
        if not (abs(lat_rad) <= 0.5 * math.pi and abs(lon_rad) <= math.pi):
            return "position out of range"
        if radius_m and not LOITER_RADIUS_RANGE_M[0] <= radius_m <= LOITER_RADIUS_RANGE_M[1]:
            return f"loiter radius must be in {LOITER_RADIUS_RANGE_M[0]:g}.." \
                   f"{LOITER_RADIUS_RANGE_M[1]:g} m"
        if alt_amsl_m is not None and not self.sim.glider:  # a glider flies to it gliding
            reason = self.change_altitude(alt_amsl_m)
            if reason:
                return reason
        self._guided_target = self._ne(lat_rad, lon_rad)
        self._guided_loiter = (float(radius_m), bool(clockwise))
        return self.set_mode(MODES.GUIDED)

    def guided_item(self, item: MissionItem) -> str | None:
        """A MISSION_ITEM(_INT) with current = 2 (ArduPilot's guided "fly to": MAVProxy's
        ``guided LAT LON ALT`` with guided_use_reposition off) or 3 (change the altitude
        only); None, or why it is refused (naming the field and the range)."""
        if item.frame not in AMSL_FRAMES | RELATIVE_FRAMES:
            return f"guided: frame {item.frame} unsupported"
        if not math.isfinite(item.z):
            return f"guided: z altitude {item.z:g} is not a finite number"
        alt = self._item_alt_m(item)
        lo, hi = self.altitude_range_m
        if not lo <= alt <= hi:
            return f"guided: z altitude {item.z:g} m ({alt:.0f} m AMSL) outside " \
                   f"{lo:.0f}..{hi:.0f} m AMSL"
        if item.current == 3:
            return self.change_altitude(alt)
        if not -90e7 <= item.x <= 90e7:
            return f"guided: latitude {item.x * 1e-7:g} deg outside -90..90"
        if not -180e7 <= item.y <= 180e7:
            return f"guided: longitude {item.y * 1e-7:g} deg outside -180..180"
        if item.x == 0 and item.y == 0:
            return "guided: no position (x, y = 0, 0)"
        return self.reposition(item.lat_rad, item.lon_rad, alt)

    def loiter_at(self, lat_rad: float | None, lon_rad: float | None,
                  radius_m: float) -> str | None:
        reason = self.set_mode(MODES.LOITER)
        if reason is None:
            centre = self.position_ne() if lat_rad is None else self._ne(lat_rad, lon_rad)
            r = abs(radius_m) if radius_m else self.settings.loiter_radius_m
            self._nav = ("circle", centre, max(r, 20.0), radius_m >= 0.0)
            self._apply_mode_flags()
        return reason

    def set_home(self, lat_rad: float, lon_rad: float, alt_amsl_m: float) -> str | None:
        """Home at (lat, lon) [rad], ``alt_amsl_m`` [m]; None, or why not (the field and its
        range: HOME_*_RANGE, as ``--home``)."""
        for label, value, (lo, hi), unit in (
                ("latitude", math.degrees(lat_rad), HOME_LATITUDE_RANGE_DEG, " deg"),
                ("longitude", math.degrees(lon_rad), HOME_LONGITUDE_RANGE_DEG, " deg"),
                ("altitude", alt_amsl_m, HOME_ALTITUDE_RANGE_M, " m AMSL")):
            if not (math.isfinite(value) and lo <= value <= hi):
                return f"home {label} {value:g}{unit} outside {lo:g}..{hi:g}"
        self.home = (lat_rad, lon_rad, alt_amsl_m)
        self.status(6, "Home position set")
        return None

    def mission_start(self, first: int, last: int) -> str | None:
        if len(self.mission) < 2:
            return "no mission to fly"
        if first >= 1:
            if first >= len(self.mission):
                return f"mission has no item {first}"
            self.mission_seq = first
        else:
            self.mission_seq = 1
        return self.set_mode(MODES.AUTO)

    # -- the mission store (mavlink_mission.MissionProtocol's vehicle) -------------------
    def mission_items(self) -> list[MissionItem]:
        lat, lon, alt = self.home
        home = MissionItem(0, 0, NAV_WAYPOINT, 0, 1, x=int(round(math.degrees(lat) * 1e7)),
                           y=int(round(math.degrees(lon) * 1e7)), z=alt)
        return [home] + self.mission[1:]

    def item_problem(self, item: MissionItem) -> tuple[int, str] | None:
        """(MAV_MISSION_RESULT, reason naming the field and its range) when ``item`` (not
        item 0, home) cannot be flown, else None: :func:`check_item`, then the altitude
        range (:attr:`altitude_range_m`), acceptance and loiter radii, turns, times and
        speeds within the ranges of the parameters that set their defaults."""
        bad = check_item(item)
        if bad is not None:
            return bad
        n, cmd = item.seq, item.command
        if item.has_position or cmd == NAV_TAKEOFF:
            alt = self._item_alt_m(item)
            lo, hi = self.altitude_range_m
            if not lo <= alt <= hi:
                return (M_INVALID_PARAM7, f"item {n}: altitude {item.z:g} m ({alt:.0f} m AMSL) "
                        f"outside {lo:.0f}..{hi:.0f} m AMSL")
        checks = []
        if cmd == NAV_WAYPOINT:
            checks.append((2, "acceptance radius", item.param2, WP_RADIUS_RANGE_M, False))
        if cmd in (NAV_LOITER_UNLIM, NAV_LOITER_TURNS, NAV_LOITER_TIME):
            checks.append((3, "loiter radius", item.param3, LOITER_RADIUS_RANGE_M, True))
        if cmd == NAV_LOITER_TURNS:
            checks.append((1, "turns", item.param1, (0.0, LOITER_TURNS_MAX), None))
        if cmd == NAV_LOITER_TIME:
            checks.append((1, "time [s]", item.param1, (0.0, LOITER_TIME_MAX_S), None))
        if cmd == DO_CHANGE_SPEED:
            checks.append((2, "speed [m/s]", item.param2, self.sim.airspeed_range_m_s, False))
        for k, label, value, (lo, hi), signed in checks:
            if signed is None:  # a count or a time: required, within lo..hi
                ok = math.isfinite(value) and lo <= value <= hi
            else:  # 0 or NaN (and < 0 for a speed: unchanged) means the default
                ok = (math.isnan(value) or value == 0.0 or (not signed and value < 0
                      and cmd == DO_CHANGE_SPEED and math.isfinite(value))
                      or (math.isfinite(value) and lo <= (abs(value) if signed else value) <= hi))
            if not ok:
                return (M_INVALID_PARAM[k], f"item {n}: param{k} {label} {value:g} outside "
                        f"{'±' if signed else ''}{lo:g}..{hi:g}")
        return None

    def set_mission(self, items: list[MissionItem]) -> str | None:
        for it in items[1:]:
            bad = self.item_problem(it)
            if bad is not None:
                return bad[1]
        self.mission = list(items)
        self.mission_seq = 1 if len(items) > 1 else 0
        if self.mode == MODES.AUTO:
            if len(items) < 2:
                self.set_mode(MODES.LOITER)
            else:
                self._start_item(self.position_ne())
        return None

    def set_mission_current(self, seq: int) -> str | None:
        if not 1 <= seq < len(self.mission):
            return f"mission has no item {seq}"
        self.mission_seq = seq
        if self.mode == MODES.AUTO:
            self._start_item(self.position_ne())
        return None

    # -- guidance -------------------------------------------------------------------------
    def _start_item(self, pos) -> None:
        """Begin mission item ``mission_seq`` from the position ``pos``: apply DO items,
        set the navigation target of the next NAV item."""
        while self.mission_seq < len(self.mission):
            it = self.mission[self.mission_seq]
            if it.command == DO_CHANGE_SPEED:
                if it.param2 > 0:
                    if self.change_speed(it.param2) is not None:
                        self.status(4, f"Item {it.seq}: speed {it.param2:g} m/s refused")
                self.mission_seq += 1
                continue
            break
        if self.mission_seq >= len(self.mission):
            self._mission_complete(pos)
            return
        it = self.mission[self.mission_seq]
        self._item_state = {"t0": None, "angle": None, "turned": 0.0}
        if it.command == NAV_RETURN_TO_LAUNCH:
            self.alt_target_m = self.home[2] + self.settings.rtl_altitude_m
            self._nav = ("goto", pos, (0.0, 0.0), "mission-rtl")
        elif it.command == NAV_TAKEOFF:
            self.alt_target_m = self._item_alt_m(it)
            self._nav = ("heading",)
            self.heading_target_rad = self.sim.core.get["psi"]()
            self.sim.airframe["ap/heading-hold-rad"] = math.remainder(self.heading_target_rad,
                                                                      2 * math.pi)
        else:
            self.alt_target_m = self._item_alt_m(it)
            self._nav = ("goto", pos, self._ne(it.lat_rad, it.lon_rad), "mission")
        self._apply_mode_flags()

    def _mission_complete(self, pos) -> None:
        self.status(6, "Mission complete: loitering")
        last = next((it for it in reversed(self.mission[1:]) if it.has_position), None)
        centre = self._ne(last.lat_rad, last.lon_rad) if last is not None else pos
        self._nav = ("circle", centre, self.settings.loiter_radius_m, True)
        self.mission_seq = len(self.mission) - 1
        self._apply_mode_flags()

    def _advance_item(self) -> None:
        it = self.mission[self.mission_seq]
        self.reached.append(it.seq)
        self.status(6, f"Reached waypoint #{it.seq}")
        self.mission_seq += 1
        self._start_item(self.position_ne())

    def update(self, t_s: float) -> None:
        """One guidance update (every GUIDANCE_PERIOD_S of simulated time)."""
        dt = t_s - self._last_t
        self._last_t = t_s
        self._battery(dt)
        if self._stick_t_s is not None and self.mode in MODES.STICK_MODES and \
                t_s - self._stick_t_s > MANUAL_TIMEOUT_S:
            self._stick_t_s = None
            self._sticks = (0.0, 0.0)
            self.status(4, "Manual control lost: RTL")
            self.set_mode(MODES.RTL)
        a = self.sim.airframe
        if self.mode in (MODES.STABILIZE, MODES.FLY_BY_WIRE_A):
            pitch, roll = self._sticks
            a["ap/bank-cmd-rad"] = roll * STICK_BANK_RAD
            a["ap/pitch-cmd-rad"] = self.sim.trim.theta_rad - pitch * STICK_PITCH_RAD
            return
        nav = self._nav
        if nav[0] not in ("goto", "circle"):
            return
        pos, vel = self.position_ne(), self.velocity_ne()
        s = self.settings
        l1 = G.l1_distance_m(math.hypot(*vel), s.l1_period_s, s.l1_damping)
        if nav[0] == "goto":
            _, start, target, why = nav
            if self.mode == MODES.AUTO and why == "mission":
                it = self.mission[self.mission_seq]
                radius = it.param2 if it.param2 > 0 else s.wp_radius_m
                if it.command in (NAV_LOITER_UNLIM, NAV_LOITER_TURNS, NAV_LOITER_TIME):
                    radius = max(radius, abs(it.param3) if it.param3 else s.loiter_radius_m)
            else:
                radius = s.wp_radius_m
            if G.distance_m(pos, target) <= radius:
                self._arrived(why, target, pos)
                nav = self._nav
                if nav[0] != "goto":
                    return self.update_circle(pos, vel, l1) if nav[0] == "circle" else None
                _, start, target, why = nav
            cmd = G.l1_track(pos, vel, start, target, l1)
        else:
            return self.update_circle(pos, vel, l1)
        a["ap/bank-cmd-rad"] = G.bank_for(cmd.accel_m_s2, STICK_BANK_RAD)

    def update_circle(self, pos, vel, l1) -> None:
        _, centre, radius, cw = self._nav
        cmd = G.l1_circle(pos, vel, centre, radius, cw, l1)
        self.sim.airframe["ap/bank-cmd-rad"] = G.bank_for(cmd.accel_m_s2, STICK_BANK_RAD)
        if self.mode == MODES.AUTO and self.mission_seq < len(self.mission):
            self._loiter_progress(pos, centre, radius)

    def _arrived(self, why: str, target, pos) -> None:
        s = self.settings
        if why == "home":
            self.status(6, "Home reached: loitering")
            self._nav = ("circle", (0.0, 0.0), s.loiter_radius_m, True)
        elif why == "guided":
            r, cw = self._guided_loiter
            self._nav = ("circle", target, r or s.loiter_radius_m, cw)
        elif why == "mission-rtl":
            self._advance_item() if self.mission_seq + 1 < len(self.mission) else None
            self._nav = ("circle", (0.0, 0.0), s.loiter_radius_m, True)
            self.status(6, "Home reached: loitering")
        else:
            it = self.mission[self.mission_seq]
            if it.command == NAV_WAYPOINT:
                self._advance_item()
            else:  # a loiter item: circle its point
                r = abs(it.param3) if it.param3 else s.loiter_radius_m
                self._nav = ("circle", target, max(r, 20.0), it.param3 >= 0.0)
        self._apply_mode_flags()

    def _loiter_progress(self, pos, centre, radius) -> None:
        it = self.mission[self.mission_seq]
        st = self._item_state
        if it.command == NAV_LOITER_TIME:
            if st["t0"] is None:
                st["t0"] = self._last_t
            elif self._last_t - st["t0"] >= it.param1:
                self._advance_item()
        elif it.command == NAV_LOITER_TURNS:
            ang = math.atan2(pos[1] - centre[1], pos[0] - centre[0])
            if st["angle"] is not None:
                st["turned"] += abs(math.remainder(ang - st["angle"], 2 * math.pi))
            st["angle"] = ang
            if st["turned"] >= 2 * math.pi * max(it.param1, 0.0):
                self._advance_item()

    def _battery(self, dt_s: float) -> None:
        if dt_s <= 0.0:
            return
        a = self.sim.airframe
        shaft_w = sum(a[p] for p in self.sim.power_properties) * U.WATT_PER_HP
        self.battery.draw(shaft_w, dt_s)
        if self.battery.soc < 0.2 and not self._battery_warned:
            self._battery_warned = True
            self.status(4, f"Battery low: {self.battery.remaining_pct} %")

    def after_reset(self) -> None:
        """The aircraft was put back at home in trim: loiter there."""
        self._sticks, self._stick_t_s = (0.0, 0.0), None
        self.armed = True
        self.set_mode(MODES.LOITER, quiet=True)
        self._nav = ("circle", (0.0, 0.0), self.settings.loiter_radius_m, True)
        self._apply_mode_flags()
