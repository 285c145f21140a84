"""The SITL loop: the one coupled step paced to the wall clock.

The one coupled step (:class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`), on the
``bioflex_sitl`` aircraft, whose autopilot (``systems/bioflex_autopilot.xml`` and
``systems/bioflex_autothrottle.xml``, see :mod:`bioflex_jsb.generators.autopilot`) flies the
modes of :mod:`bioflex_jsb.drivers.sitl_vehicle`, for as long as asked (or until stopped);
or on another aircraft without an engine (a glider: :func:`glider_airframe`, its speed held
with pitch by the glider's autopilot), whose arrival at the ground is a landing, or on
another aircraft with engines (:func:`powered_airframe`: the powered aircraft's autopilot,
its gains scaled for it).

Where it flies: home is a point on the ground (latitude, longitude, ground altitude AMSL;
default :data:`DEFAULT_HOME`, the Canberra model aircraft field ArduPilot's SITL also
uses); the aircraft starts in trim ``start_height_m`` (default 100 m) above home, heading
north, in CRUISE. JSBSim's terrain is the flat ground at home's altitude: an aircraft that
reaches it (or leaves the valid range in any other way: divergence, stall) is reported and
**reset** to trim at the start point (``SitlSim.resets``, STATUSTEXT), and the session goes
on; the simulated clock keeps running.

Pacing: step k is due at wall time W_0 + (t_k − t_0)/speedup. The loop sleeps until a step is
due and runs late steps at once (catch-up); the *pacing error* of a step is its start minus
its due time [s] (:class:`PacingStats`, a fixed histogram: constant memory for any session
length; ``sitl_p99_ms`` in ``bioflex-jsb bench``). A loop more than :data:`RESYNC_S` behind
(a stall: debugger, swapped-out process, a reset's trim) starts a new schedule from now
instead of racing to catch up; the number of such resyncs is reported. Changing the time
scale (parameter ``SIM_SPEEDUP``) starts a new schedule too.

The MAVLink link (:mod:`bioflex_jsb.links.mavlink`) is serviced every
:data:`LINK_PERIOD_S` of simulated time; its reads are bounded per call, so a flood costs at
most a fixed time per call.

Parameters a ground station sees (:class:`SitlParameters`, all REAL32 in MAVLink):

=============== =========================================================================
AP_ENABLE       1: autopilot engaged; 0: MANUAL (controls at trim without sticks)
AP_LOITER       1: CIRCLE (fixed 20° bank); 0: back to CRUISE
AP_ALT_M        altitude held [m AMSL], home's ground + 20 m .. + 1500 m
AP_HDG_RAD      heading held in CRUISE [rad, from north, clockwise]; sets CRUISE
WP_RADIUS_M     default waypoint acceptance radius [m], 5..500
LOIT_RAD_M      loiter radius [m], 20..1000
RTL_ALT_M       return altitude [m above home], 20..1000
AIRSPEED_MS     airspeed held by the autothrottle [m/s], 12..22 (MAV_CMD_DO_CHANGE_SPEED);
                another aircraft's: within its definition's flight speeds (a glider's held
                with pitch)
GUST_AMP_MS     peak of the 1-cosine vertical gust [m/s, up], ±5
GUST_LEN_M      length of that gust [m], 1..500
GUST_TRIG       write 1: the gust starts now; reads 1 while it blows, then 0
GUST_ROLL_RADS  peak of a 1-cosine rolling gust p_g over GUST_LEN_M [rad/s, + right wing
                down], ±2 (w_g = −p_g·y; docs/gusts.md)
GUST_LAT_MS     peak of a 1-cosine lateral gust v_g over GUST_LEN_M [m/s, + to starboard], ±5
GUST_FRONT_DEG  the vertical gust's front to the span [deg, + starboard wing first], ±80
GUST_TAIL       1: the tail meets the vertical gust l_t/V after the wing; 0: at once
WING_COUPLED    1: the elastic wing's modal loads act (coupled); 0: rigid wing
SIM_SPEEDUP     simulated seconds per wall-clock second, 0.1..50
=============== =========================================================================
"""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Callable

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.drivers.sitl_vehicle import (
    AIRSPEED_RANGE_M_S,
    GUIDANCE_PERIOD_S,
    HOME_ALTITUDE_RANGE_M,
    HOME_LATITUDE_RANGE_DEG,
    HOME_LONGITUDE_RANGE_DEG,
    SitlVehicle,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.generators.autopilot import (
    GLIDER_SYSTEM_FILE,
    POWERED_SYSTEM_FILE,
    SITL_AIRCRAFT,
    powered_gains,
    render_glider_autopilot,
    render_powered_autopilot,
)
from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.links.mavlink import VehicleState
from bioflex_jsb.parameters.sensors import NO_SENSORS, Sensors
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.gust_loads import GustLoads, field_for
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.gusts import GustField, parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.sensors import AutopilotImu, SensorSet

LINK_PERIOD_S = 1.0 / 200.0  # simulated time between link services [s]
RESYNC_S = 0.25  # a loop this far behind its schedule starts a new one [s]
SLEEP_MARGIN_S = 50e-6  # steps due within this are started at once (sleep overshoot)
SPEEDUP_RANGE = (0.1, 50.0)
# Canberra Model Aircraft Club field (ArduPilot SITL's default home): lat, lon [deg], ground
# altitude [m AMSL]
DEFAULT_HOME = (-35.363261, 149.165230, 584.0)
DEFAULT_START_HEIGHT_M = 100.0
START_HEIGHT_RANGE_M = (20.0, 3000.0)
ALT_HOLD_RANGE_ABOVE_HOME_M = (20.0, 1500.0)
MAX_RESETS_PER_MINUTE = 30  # a run that keeps diverging: each reset still costs a trim
# A glider's guidance (SitlSim with an airframe without an engine; docs/sitl.md "A glider"):
# LOIT_RAD_M's default is a circle it flies within the guidance's ±30° bank at 25 m/s, the
# SGS's cruise (V²/(g tan 30°) = 110 m; 150 m needs 23°), and the L1 period is longer than
# the prototype's 17 s (L1 = ζPV/π = 149 m at 25 m/s): with 17 s (L1 101 m) the SGS's slow
# roll (≈ 0.5 rad/s per unit aileron) made its 150 m loiter wander between 94 and 319 m from
# the centre; with 25 s it holds 144-146 m (tests/test_glider_sitl.py).
GLIDER_LOITER_RADIUS_M = 150.0
GLIDER_L1_PERIOD_S = 25.0


def powered_airframe(aircraft, speed_m_s: float, altitude_m: float):
    """The JSBSim airframe of an aircraft definition with engines (``--aircraft``: its own
    JSBSim aircraft) with a powered aircraft's autopilot added
    (:func:`~bioflex_jsb.generators.autopilot.render_powered_autopilot`), its gains scaled
    for the aircraft (:func:`~bioflex_jsb.generators.autopilot.powered_gains`) from its
    rigid short period at ``speed_m_s`` [m/s] (the definition's linear model at the air
    density of ``altitude_m`` [m], the session's start) and the control power its JSBSim
    model gives at the trim there (runtime/control_power.py, measured on a copy loaded for
    that alone): (the airframe, the gains). Raises FdmError (one line) where it cannot be
    trimmed or a control moves nothing; an aircraft without an engine is refused (the
    glider's autopilot: :func:`glider_airframe`)."""
    from bioflex_jsb.flight_dynamics.eigen import modes_at
    from bioflex_jsb.runtime.control_power import measure_control_power
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
    from bioflex_jsb.runtime.results import TrimError

    probe = airframe_for(aircraft)
    if probe.glider:
        raise TrimError(f"aircraft {aircraft.name!r} has no engine: it flies the glider's "
                        "autopilot")
    power = measure_control_power(probe, speed_m_s, altitude_m)
    density = float(probe["atmosphere/rho-slugs_ft3"]) * U.KG_M3_PER_SLUG_FT3
    sp = modes_at("rigid", [speed_m_s], aircraft.wing().model,
                  density_kg_m3=density)[0].get("short_period")
    try:
        gains = powered_gains(speed_m_s, sp.frequency_rad_s, sp.damping, power)
    except ValueError as exc:
        raise TrimError(f"aircraft {aircraft.name!r}: {exc}") from None
    engines = probe.engine_count
    del probe
    text = render_powered_autopilot(gains, engines)
    return airframe_for(aircraft, systems={POWERED_SYSTEM_FILE: text}), gains


def sitl_airframe(aircraft, speed_m_s: float, altitude_m: float):
    """The SITL airframe of another JSBSim aircraft: without an engine the glider's
    (:func:`glider_airframe`), with engines the powered aircraft's
    (:func:`powered_airframe`): (the airframe, its gains, None for a glider)."""
    from bioflex_jsb.runtime.engines import engines_of
    from bioflex_jsb.runtime.jsbsim_aircraft import complete

    if not engines_of(complete(aircraft).airframe.jsbsim_path):
        return glider_airframe(aircraft), None
    return powered_airframe(aircraft, speed_m_s, altitude_m)


def loiter_radius_m(speed_m_s: float) -> float:
    """A powered aircraft's LOIT_RAD_M default [m]: the circle flown at the CIRCLE mode's
    20° bank (V²/(g tan 20°), within the guidance's 30° limit), in whole tens of metres,
    within the parameter's range (c172 at 57.8 m/s: 940 m)."""
    from bioflex_jsb.drivers.sitl_vehicle import LOITER_RADIUS_RANGE_M
    from bioflex_jsb.generators.autopilot import LOITER_BANK_RAD
    from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2

    r = speed_m_s**2 / (STANDARD_GRAVITY_M_S2 * math.tan(LOITER_BANK_RAD))
    lo, hi = LOITER_RADIUS_RANGE_M
    return float(min(hi, max(lo, 10.0 * math.ceil(r / 10.0))))


# The L1 distance against the tightest turn the guidance may fly (V²/(g tan 30°)): the
# prototype's 17 s period at 15 m/s gives 1.5 of it (61 m against 40 m), the glider's 25 s
# at 25 m/s 1.35; shorter, the guidance saturates its bank and circles a waypoint it cannot
# turn onto (measured on the c172 with the prototype's 17 s: 235 m against 590 m).
L1_TURN_RATIO = 1.5


def l1_period_s(speed_m_s: float, damping: float) -> float:
    """A powered aircraft's L1 period [s]: its L1 distance ζ P V/π is L1_TURN_RATIO times
    its tightest turn at the guidance's bank limit (c172 at 57.8 m/s: 64 s, L1 885 m;
    the rule gives the prototype's 16.6 s and the glider's 27.7 s)."""
    from bioflex_jsb.generators.autopilot import BANK_CMD_MAX_RAD
    from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2

    turn_m = speed_m_s**2 / (STANDARD_GRAVITY_M_S2 * math.tan(BANK_CMD_MAX_RAD))
    return math.pi * L1_TURN_RATIO * turn_m / (damping * speed_m_s)


def glider_airframe(aircraft) -> Airframe:
    """The JSBSim airframe of an aircraft definition (``--aircraft``: its own JSBSim
    aircraft, runtime/aircraft_files.py) with the glider's autopilot system added
    (:func:`~bioflex_jsb.generators.autopilot.render_glider_autopilot`)."""
    from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for

    return airframe_for(aircraft, systems={GLIDER_SYSTEM_FILE: render_glider_autopilot()})


class PacingStats:
    """|step start − due time| of every paced step in a fixed log-spaced histogram (1 µs to
    100 s, 20 bins per decade: percentiles to ±6 %; memory independent of the session's
    length), the exact largest value, and the resyncs."""

    LO_S, DECADES, PER_DECADE = 1e-6, 8, 20

    def __init__(self) -> None:
        self.counts = np.zeros(self.DECADES * self.PER_DECADE + 2, dtype=np.int64)
        self.max_s = 0.0
        self.steps = 0
        self.resyncs = 0
        self._log_lo = math.log10(self.LO_S)

    def add(self, error_s: float) -> None:
        e = abs(error_s)
        self.steps += 1
        if e > self.max_s:
            self.max_s = e
        if e < self.LO_S:
            self.counts[0] += 1
            return
        i = 1 + int((math.log10(e) - self._log_lo) * self.PER_DECADE)
        self.counts[min(i, len(self.counts) - 1)] += 1

    def percentile_ms(self, q: float) -> float:
        """The q-th percentile [ms] (the geometric middle of its bin; q = 100: the max)."""
        if not self.steps:
            return math.nan
        if q >= 100.0:
            return self.max_s * 1e3
        rank = q / 100.0 * self.steps
        i = int(np.searchsorted(np.cumsum(self.counts), max(rank, 1e-9)))
        if i == 0:
            return 0.0
        lo = self.LO_S * 10.0 ** ((i - 1) / self.PER_DECADE)
        mid = lo * 10.0 ** (0.5 / self.PER_DECADE)
        return min(mid, self.max_s) * 1e3

    def summary(self) -> dict[str, float]:
        return {"p50_ms": self.percentile_ms(50), "p99_ms": self.percentile_ms(99),
                "max_ms": self.percentile_ms(100), "steps": self.steps,
                "resyncs": self.resyncs}


# The parameters of a gust's parts that vary over the aircraft: (lowest, highest, unit). The
# rolling gust up to 2 rad/s (the prototype's tips then meet ±1.7 m/s; its steady roll rate
# at full aileron is of that order), the lateral gust as GUST_AMP_MS, the front as the gust
# specification's (simulation/gusts.py MAX_FRONT_ANGLE_DEG).
SPANWISE_PARAMETERS = {"GUST_ROLL_RADS": (-2.0, 2.0, " rad/s"),
                       "GUST_LAT_MS": (-5.0, 5.0, " m/s"),
                       "GUST_FRONT_DEG": (-80.0, 80.0, " deg"), "GUST_TAIL": (0.0, 1.0, "")}


def spanwise_text(parts: dict[str, float], length_m: float) -> str:
    """The ``+…`` parts of the triggered 1-cos gust (simulation/gusts.py) from the GUST_*
    parameters ``parts``, each over ``length_m`` [m]; "" for none."""
    text = ""
    if parts["GUST_ROLL_RADS"]:
        text += f"+roll:{parts['GUST_ROLL_RADS']!r}:{length_m!r}"
    if parts["GUST_LAT_MS"]:
        text += f"+lateral:1cos:{parts['GUST_LAT_MS']!r}:{length_m!r}"
    if parts["GUST_FRONT_DEG"]:
        text += f"+front:{parts['GUST_FRONT_DEG']!r}"
    if parts["GUST_TAIL"]:
        text += "+tail"
    return text


class SitlParameters:
    """The parameter set of the module docstring; ``set`` applies to the running sim."""

    names = ("AP_ENABLE", "AP_LOITER", "AP_ALT_M", "AP_HDG_RAD", "WP_RADIUS_M", "LOIT_RAD_M",
             "RTL_ALT_M", "AIRSPEED_MS", "GUST_AMP_MS", "GUST_LEN_M", "GUST_TRIG",
             "GUST_ROLL_RADS", "GUST_LAT_MS", "GUST_FRONT_DEG", "GUST_TAIL",
             "WING_COUPLED", "SIM_SPEEDUP")

    def __init__(self, sim: SitlSim) -> None:
        self._sim = sim

    def get(self, name: str) -> float:
        s = self._sim
        v, st = s.vehicle, s.vehicle.settings
        return float({
            "AP_ENABLE": 0.0 if v.mode == MODES.MANUAL else 1.0,
            "AP_LOITER": 1.0 if v.mode == MODES.CIRCLE else 0.0,
            "AP_ALT_M": v.alt_target_m,
            "AP_HDG_RAD": v.heading_target_rad,
            "WP_RADIUS_M": st.wp_radius_m, "LOIT_RAD_M": st.loiter_radius_m,
            "RTL_ALT_M": st.rtl_altitude_m, "AIRSPEED_MS": v.speed_target_m_s,
            "GUST_AMP_MS": s.gust_amplitude_m_s,
            "GUST_LEN_M": s.gust_length_m,
            "GUST_TRIG": 1.0 if s.gust_active else 0.0,
            **s.gust_parts,
            "WING_COUPLED": 1.0 if s.wing.model == "coupled" else 0.0,
            "SIM_SPEEDUP": s.speedup,
        }[name])

    @staticmethod
    def _range(name: str, value: float, lo: float, hi: float, unit: str = "") -> None:
        if not lo <= value <= hi:
            raise ValueError(f"{name} must be in {lo:g}..{hi:g}{unit}")

    def set(self, name: str, value: float) -> float:
        s = self._sim
        v, st = s.vehicle, s.vehicle.settings
        if name not in self.names:
            raise KeyError(name)
        if not math.isfinite(value):
            raise ValueError(f"{name}: not a finite number")
        if name in ("AP_ENABLE", "AP_LOITER", "WING_COUPLED", "GUST_TRIG"):
            if value not in (0.0, 1.0):
                raise ValueError(f"{name} must be 0 or 1")
        if name == "AP_ENABLE":
            if value == 0.0:
                v.set_mode(MODES.MANUAL)
            elif v.mode == MODES.MANUAL:
                v.set_mode(MODES.CRUISE)
        elif name == "AP_LOITER":
            if value == 1.0:
                v.set_mode(MODES.CIRCLE)
            elif v.mode == MODES.CIRCLE:
                v.set_mode(MODES.CRUISE)
        elif name == "AP_ALT_M":
            reason = v.change_altitude(value)
            if reason:
                raise ValueError(f"AP_ALT_M: {reason}")
        elif name == "AP_HDG_RAD":
            v.set_heading(value)
        elif name == "WP_RADIUS_M":
            self._range(name, value, 5.0, 500.0, " m")
            st.wp_radius_m = value
        elif name == "LOIT_RAD_M":
            self._range(name, value, 20.0, 1000.0, " m")
            st.loiter_radius_m = value
        elif name == "RTL_ALT_M":
            self._range(name, value, 20.0, 1000.0, " m")
            st.rtl_altitude_m = value
        elif name == "AIRSPEED_MS":
            self._range(name, value, *s.airspeed_range_m_s, " m/s")
            v.change_speed(value)
        elif name == "GUST_AMP_MS":
            self._range(name, value, -5.0, 5.0, " m/s")
            s.gust_amplitude_m_s = value
        elif name == "GUST_LEN_M":
            self._range(name, value, 1.0, 500.0, " m")
            s.gust_length_m = value
        elif name == "GUST_TRIG":
            if value == 1.0:
                s.trigger_gust()
        elif name in SPANWISE_PARAMETERS:
            self._range(name, value, *SPANWISE_PARAMETERS[name])
            s.gust_parts[name] = 1.0 if name == "GUST_TAIL" and value else value
        elif name == "WING_COUPLED":
            s.set_wing_model("coupled" if value == 1.0 else "rigid")
        elif name == "SIM_SPEEDUP":
            self._range(name, value, *SPEEDUP_RANGE)
            s.speedup = value
            s.resync = True
        return self.get(name)


def check_home(lat_deg: float, lon_deg: float, ground_m: float, start_height_m: float) -> None:
    """InputError (one line) for a home or start height outside the accepted ranges."""
    for label, value, (lo, hi), unit in (
            ("latitude", lat_deg, HOME_LATITUDE_RANGE_DEG, " deg"),
            ("longitude", lon_deg, HOME_LONGITUDE_RANGE_DEG, " deg"),
            ("ground altitude", ground_m, HOME_ALTITUDE_RANGE_M, " m")):
        if not (math.isfinite(value) and lo <= value <= hi):
            raise InputError(f"home {label} {value:g}{unit} is outside {lo:g}..{hi:g}"
                             + (" m AMSL" if unit == " m" else ""))
    lo, hi = START_HEIGHT_RANGE_M
    if not (math.isfinite(start_height_m) and lo <= start_height_m <= hi):
        raise InputError(f"start height {start_height_m:g} m is outside {lo:g}..{hi:g} m "
                         "above home")


class SitlSim:
    """The co-simulation state between steps: the one coupled step (airframe trimmed,
    autopilot engaged, modal wing), the vehicle (modes, mission) and the gust in progress.

    ``home``: (latitude [deg], longitude [deg], ground altitude [m AMSL]);
    ``start_height_m``: the start (and reset) point's height above home [m].
    ``on_reset(reason)``: called after each reset (the CLI starts a new log file)."""

    def __init__(self, wing_model, modes, model: str = "coupled", speed_m_s: float = 15.0,
                 home: tuple[float, float, float] = DEFAULT_HOME,
                 start_height_m: float = DEFAULT_START_HEIGHT_M, dt_s: float = DEFAULT_DT_S,
                 speedup: float = 1.0, airframe: Airframe | None = None,
                 trim_mode: str = "rigid", aero: str = "quasi-steady",
                 airspeed_range_m_s: tuple[float, float] = AIRSPEED_RANGE_M_S,
                 sensors: Sensors | None = None, controller=None, span: str = "half",
                 aileron=None) -> None:
        """``wing_model``: the ElasticWingModel, or the WingBuild (needed for
        ``trim_mode="elastic"``: the session starts from the static aeroelastic equilibrium,
        :class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`'s ``trim_mode``; and for
        ``aero="unsteady"``). ``aero``: the coupled wing's strips, ``quasi-steady`` or
        ``unsteady`` (Jones lag states, apparent mass, Küssner gust), handed to the coupled
        step as they are (an unsupported combination is refused there in one line,
        InputError; both strips run on the compiled step). ``airframe``: the prototype's
        SITL aircraft by default, or an aircraft without an engine with the glider's
        autopilot (:func:`glider_airframe`): the vehicle then flies as a glider (its speed
        held with pitch, no altitude hold; ``glider``). ``airspeed_range_m_s``: the
        speed targets accepted [m/s] (AIRSPEED_MS, DO_CHANGE_SPEED). ``sensors``: the
        aircraft's sensor stations (None: the WingBuild's, an aircraft definition's
        ``[sensors]``): each is channels of the rows (and a log topic), and the autopilot's
        IMU is reported as HIGHRES_IMU (without sensors: an ideal IMU at the CG).
        ``controller``: a controller in the loop (:mod:`bioflex_jsb.simulation.controller`),
        its commands added to the autopilot's (the elevator through the pitch trim, the
        throttle on the lever the autothrottle adds to:
        :mod:`bioflex_jsb.runtime.control_surfaces`, "Over an autopilot"), in every mode
        (MANUAL too: it adds to the sticks); its commands are channels of the rows
        (``ctrl_<command>``); a reset binds it anew (a linear controller's state back to 0,
        a Python one's ``reset`` called). ``span``: ``half`` or ``full`` (both wing halves,
        ``wing_model`` the WingBuild: the antisymmetric modes driven by the roll rate and the
        ailerons the autopilot flies, ``aileron`` their surface;
        :mod:`bioflex_jsb.simulation.full_span`)."""
        self.span, self.aileron = span, aileron
        check_home(*home, start_height_m)
        self.trim_mode = trim_mode
        self.aero = aero
        self.airframe = airframe or Airframe(aircraft=SITL_AIRCRAFT)
        self.glider = bool(self.airframe.glider)
        # another JSBSim aircraft with engines, flying the powered aircraft's autopilot
        self.powered_file = self.airframe.has_property("ap/elevator-trim-norm")
        self.airspeed_range_m_s = tuple(float(v) for v in airspeed_range_m_s)
        self._wing_model, self._model0 = wing_model, model
        self.home_deg = tuple(float(x) for x in home)
        self.start_height_m = float(start_height_m)
        self.start_altitude_m = self.home_deg[2] + self.start_height_m
        self.speed_m_s = speed_m_s
        self.speedup = float(speedup)
        self.resync = False
        self.resets = 0
        self.crashes = 0  # resets after ground contact (the others: the model diverged)
        self.landings = 0  # a glider's arrivals at the ground (reset, not crashes)
        self.last_reset: str | None = None
        self.on_reset: Callable[[str], None] | None = None
        self._k_base = 0  # steps flown by the cores before the present one
        self._reset_walls: list[float] = []
        self._dt0 = dt_s
        self._controller = controller
        if sensors is None:
            sensors = getattr(wing_model, "sensors", None) or NO_SENSORS
        n_flown = getattr(getattr(wing_model, "model", wing_model), "n_modes", None)
        self._sensor_set = SensorSet(sensors, modes, n_flown) if sensors else None
        self._autopilot_imu = AutopilotImu(sensors.autopilot_imu, modes, n_flown, dt_s)
        self._new_core(model)
        self.dt_s = self.core.dt_s
        self.n_modes = self.core.n_modes
        twist = np.asarray(modes.twist_rad, dtype=float)
        tip = int(np.argmax(np.abs(np.asarray(modes.stations_m, dtype=float))))
        # a mode without twist (a pure bending mode of another wing) adds no tip twist
        peak = np.max(np.abs(twist), axis=1)
        self._tip_twist_per_mode = np.divide(np.abs(twist[:, tip]), peak,
                                             out=np.zeros_like(peak), where=peak > 0.0)
        self.h0_m = self.start_altitude_m
        ground = self.home_deg[2]
        self.altitude_hold_range_m = (ground + ALT_HOLD_RANGE_ABOVE_HOME_M[0],
                                      ground + ALT_HOLD_RANGE_ABOVE_HOME_M[1])
        # the battery feeds the motors of an electric aircraft (the prototype's); another
        # aircraft's engines burn fuel: its battery feeds the avionics only (as a glider's)
        electric = (not self.airframe.engines  # the generated prototype's: its motors
                    or all(e.kind == "electric" for e in self.airframe.engines))
        self.power_properties = tuple(f"propulsion/engine[{i}]/power-hp"
                                      for i in range(self.airframe.engine_count)
                                      if electric)
        self.gust_amplitude_m_s = 1.0
        self.gust_length_m = 30.0
        self._gust: GustField | None = None
        self.gust_parts = dict.fromkeys(SPANWISE_PARAMETERS, 0.0)  # the GUST_* of its parts
        self._gust_loads: GustLoads | None = None
        self._gust_start_k = 0
        self._gust_end_s = 0.0
        self.units = self.core.units
        self.names = list(self.core.names)
        self.stopped: str | None = None
        home_rad = (math.radians(self.home_deg[0]), math.radians(self.home_deg[1]),
                    self.home_deg[2])
        self.vehicle = SitlVehicle(self, home_rad)
        if self.glider:
            self.vehicle.settings.loiter_radius_m = GLIDER_LOITER_RADIUS_M
            self.vehicle.settings.l1_period_s = GLIDER_L1_PERIOD_S
        elif self.powered_file:
            self.vehicle.settings.loiter_radius_m = loiter_radius_m(speed_m_s)
            self.vehicle.settings.l1_period_s = l1_period_s(
                speed_m_s, self.vehicle.settings.l1_damping)
        self._guide_every = max(1, int(round(GUIDANCE_PERIOD_S / self.dt_s)))

    def _new_core(self, model: str) -> None:
        """Trim at the start altitude (JSBSim's trim flies at 45° N, 0° E), then move the
        trimmed aircraft over home, its terrain at home's ground altitude."""
        a = self.airframe

        def disengage(af: Airframe) -> None:
            for name in ("ap/engage", "ap/autothrottle", "ap/manual", "ap/loiter",
                         "ap/roll-mode", "ap/pitch-mode"):
                af[name] = 0.0  # the trim and the RPM settling see no autopilot
            af["ap/armed"] = 1.0

        elastic = self.trim_mode == "elastic" and model != "rigid"
        wing = self._wing_model
        if not elastic and self.aero != "unsteady" and hasattr(wing, "model") \
                and self.span == "half" \
                and "flaperon" not in getattr(self._controller, "outputs", ()):
            # a WingBuild: the model is enough for the quasi-steady strips (a flaperon's
            # strips are the build's)
            wing = wing.model
        self.core = CoupledStep(a, wing, model, self.speed_m_s, self.start_altitude_m,
                                self._dt0, before_trim=disengage,
                                trim_mode="elastic" if elastic else "rigid", aero=self.aero,
                                sensors=self._sensor_set, controller=self._controller,
                                over_autopilot=True, span=self.span, aileron=self.aileron)
        self._autopilot_imu.dt_s = self.core.dt_s
        self._autopilot_imu.follow(self.core)  # both halves: the antisymmetric modes too
        self.trim = self.core.trim
        self._relocate()
        self._get = self.core.get
        self.wing = self.core.wing
        if self.powered_file:  # the autopilot's increments are on the trim's commands
            for surface in ("elevator", "aileron", "rudder"):
                a[f"ap/{surface}-trim-norm"] = a[f"fcs/{surface}-cmd-norm"]
            for i in range(a.engine_count):
                a[f"ap/throttle-trim-norm[{i}]"] = a[f"fcs/throttle-cmd-norm[{i}]"]
        a["ap/theta-trim-rad"] = self.trim.theta_rad
        a["ap/altitude-hold-m"] = self.start_altitude_m
        a["ap/heading-hold-rad"] = math.remainder(self._get["psi"](), 2 * math.pi)
        a["ap/airspeed-hold-mps"] = self.speed_m_s
        a["ap/engage"] = 1.0
        a["ap/autothrottle"] = 1.0
        self.core.prepare(0.0)
        self._state = self.core.sense(0.0)

    def _relocate(self) -> None:
        """Re-initialise JSBSim at its present (trimmed) state, over home. JSBSim's RunIC
        keeps the propeller RPM (its reset property would stop the propellers):
        :meth:`Airframe.restart_from_initial_conditions`."""
        a = self.airframe
        lat, lon, ground = self.home_deg
        state = {
            "ic/h-sl-ft": a["position/h-sl-ft"], "ic/phi-rad": a["attitude/phi-rad"],
            "ic/theta-rad": a["attitude/theta-rad"], "ic/psi-true-rad": a["attitude/psi-rad"],
            "ic/u-fps": a["velocities/u-fps"], "ic/v-fps": a["velocities/v-fps"],
            "ic/w-fps": a["velocities/w-fps"], "ic/p-rad_sec": a["velocities/p-rad_sec"],
            "ic/q-rad_sec": a["velocities/q-rad_sec"], "ic/r-rad_sec": a["velocities/r-rad_sec"],
        }
        a["ic/lat-geod-rad"] = math.radians(lat)
        a["ic/long-gc-rad"] = math.radians(lon)
        a["ic/terrain-elevation-ft"] = ground * U.FT_PER_M
        for name, value in state.items():
            a[name] = value
        a.restart_from_initial_conditions()

    @property
    def controller_meta(self) -> dict | None:
        """What the controller in the loop is (None without one:
        :func:`~bioflex_jsb.simulation.controller.controller_meta`), for the log."""
        if self.core.control is None:
            return None
        from bioflex_jsb.simulation.controller import controller_meta

        meta = controller_meta(self.core.control)
        if self.core.flaperon is not None:  # its surface: the log's section loads need it
            meta["flaperon"] = self.core.flaperon.deriv.as_dict()
        return meta

    @property
    def k(self) -> int:
        """Steps flown (over every reset)."""
        return self._k_base + self.core.k

    @property
    def t_s(self) -> float:
        """Simulated time now [s] (over every reset)."""
        return self.k * self.dt_s

    # -- commands from the link -------------------------------------------------------------
    @property
    def gust_active(self) -> bool:
        return self._gust is not None and self.t_s < self._gust_end_s

    def trigger_gust(self) -> None:
        """Start the 1-cosine gust (GUST_AMP_MS, GUST_LEN_M, and the parts GUST_ROLL_RADS,
        GUST_LAT_MS, GUST_FRONT_DEG, GUST_TAIL) now."""
        parts = spanwise_text(self.gust_parts, self.gust_length_m)
        if self.gust_amplitude_m_s == 0.0 and "roll" not in parts and "lateral" not in parts:
            return
        try:
            spec = parse_gust(f"1cos:{self.gust_amplitude_m_s!r}:{self.gust_length_m!r}"
                              + parts)
            # the gust's own clock starts at this step (step 0 of the field)
            build = self._wing_model if isinstance(self._wing_model, WingBuild) else None
            field = field_for(spec, self.core.airframe_data, build, self.speed_m_s, 0.0,
                              60.0, self.dt_s)
        except InputError as exc:  # GustSpecError too: the parameter is refused
            raise ValueError(str(exc)) from None
        self._clear_gust()
        self._gust = field
        if getattr(field, "varies", False):  # its loads, written before each step
            self._gust_loads = GustLoads(self.airframe, field, self.core.airframe_data.aero,
                                         self.airframe[JP.ATTITUDE_PSI_RAD])
        self._gust_start_k = self.k
        self._gust_end_s = self.t_s + self.gust_length_m / self.speed_m_s
        self.vehicle.status(5, f"Gust {self.gust_amplitude_m_s:g} m/s over "
                               f"{self.gust_length_m:g} m{parts}")

    def _clear_gust(self) -> None:
        """No gust any more (and none of its loads left in the airframe)."""
        if self._gust_loads is not None:
            self._gust_loads.clear()
        self._gust, self._gust_loads = None, None

    def set_wing_model(self, model: str) -> None:
        """Switch the wing (WING_COUPLED); the unsteady wing cannot be switched
        (ValueError: the parameter is refused, the session goes on)."""
        if self.aero == "unsteady" and model != self.core.model:
            raise ValueError(f"WING_COUPLED: the unsteady coupled wing cannot be switched to "
                             f"{model} (the session flies --aero unsteady)")
        self.core.set_model(model)

    def manual(self, pitch: float | None, roll: float | None) -> bool:
        """Stick increments (−1..1; pitch + = nose down), or None: released."""
        return self.vehicle.manual(pitch, roll)

    # -- the step -----------------------------------------------------------------------
    def step(self) -> tuple:
        """One co-simulation step (the one coupled step); returns the logged row's values
        (in ``self.names`` order). A run that leaves its valid range is reset (module
        docstring); ``self.stopped`` then says why until the next step."""
        core = self.core
        self._autopilot_imu.before_step(core.eta, core.eta_dot)
        p_g = 0.0  # the gust's roll rate [rad/s] on both wing halves' strips (span full)
        if self._gust_loads is not None:
            self._gust_loads.apply(self.k - self._gust_start_k)
            if core.lateral is not None:
                p_g = self._gust_loads.roll_rate_rad_s
        values = core.advance(self._w_g(self.k), p_g)
        self._state = None  # the snapshot of t_k+1 is read when asked for (vehicle_state)
        if core.stopped:
            self.reset(core.stopped)
            return values
        self.stopped = None
        if core.k % self._guide_every == 0:
            self.vehicle.update(self.t_s)
        return values

    def reset(self, reason: str) -> None:
        """Report why the flight ended: a crash (STATUSTEXT CRITICAL "Crashed: ground
        contact …", :meth:`ground_contact`) or the model leaving its valid range (ERROR
        "Diverged: ``reason``"); put the aircraft back in trim at the start point over
        home. ``stopped`` and ``last_reset`` say which."""
        impact = self.ground_contact()
        if impact is not None and self.glider:  # its glide's end: where a glider lands
            self.landings += 1
            reason = f"ground reached at t = {self.t_s:.3f} s: {impact}"
            self.vehicle.status(5, "Landed: " + reason)
        elif impact is not None:  # the ground, not the model, ended the flight
            self.crashes += 1
            reason = f"ground contact at t = {self.t_s:.3f} s: {impact}"
            self.vehicle.status(2, "Crashed: " + reason)
        else:
            self.vehicle.status(3, "Diverged: " + reason)
        self.stopped = self.last_reset = reason
        self.resets += 1
        now = time.monotonic()
        self._reset_walls = [w for w in self._reset_walls if now - w < 60.0] + [now]
        model = self.core.model
        self._k_base += self.core.k
        self._clear_gust()
        self._new_core(model)
        self.vehicle.after_reset()
        self.vehicle.status(4, "Reset to trim over home")
        self.resync = True  # the trim took wall time: a new schedule
        if self.on_reset is not None:
            self.on_reset(reason)

    def ground_contact(self) -> str | None:
        """The impact (height of the centre of gravity above the ground, airspeed, descent
        rate, pitch, roll at this step) when the aircraft touches the ground: any of its
        contact points (skids, wing tips) carries a ground force, or its centre of gravity
        is at or below the ground; None when it is in the air. A ground contact makes the
        angle of attack jump (the skid's reaction), so the valid range's message may name
        α: the contact is what is reported."""
        a = self.airframe
        touching = any(a[f"forces/fb{c}-gear-lbs"] != 0.0 for c in "xyz")
        agl_m = a["position/h-agl-ft"] * U.M_PER_FT
        if not touching and agl_m > 0.0:
            return None
        return (f"{agl_m:.2f} m above ground, {a['velocities/vt-fps'] * U.M_PER_FT:.1f} m/s, "
                f"descending {a['velocities/v-down-fps'] * U.M_PER_FT:.1f} m/s, pitch "
                f"{round(math.degrees(a['attitude/theta-rad']))} deg, roll "
                f"{round(math.degrees(a['attitude/phi-rad']))} deg")

    @property
    def resetting_too_often(self) -> bool:
        return len(self._reset_walls) >= MAX_RESETS_PER_MINUTE

    def _w_g(self, k: int) -> float:
        """The gust [m/s, up] at step ``k``."""
        gust = self._gust
        return gust.at_step(k - self._gust_start_k) if gust is not None else 0.0

    def vehicle_state(self) -> VehicleState:
        """The vehicle now (t_k, k steps flown), with the flow of this step's gust."""
        get, v = self._get, self.vehicle
        if self._state is None:
            self._state = self.core.sense(self._w_g(self.k))
        h = get["h"]() * U.M_PER_FT
        eta = self.core.eta
        named = {f"eta{i + 1}": float(eta[i]) for i in range(min(3, self.n_modes))}
        named["tip_twist"] = float(np.asarray(self._tip_twist_per_mode) @ eta)
        b = v.battery
        home = v.home
        core = self.core
        accel, gyro = self._autopilot_imu.read(
            core.rigid_kinematics(-self._w_g(self.k) * U.FT_PER_M), eta,
            core.eta_dot, self.t_s, core.model_rate_state)
        return VehicleState(
            imu_accel_m_s2=accel, imu_gyro_rad_s=gyro,
            time_s=self.t_s, roll_rad=self._state.phi_rad, pitch_rad=self._state.theta_rad,
            yaw_rad=math.remainder(get["psi"](), 2.0 * math.pi),
            p_rad_s=get["p"](), q_rad_s=get["q"](), r_rad_s=get["r"](),
            latitude_rad=get["lat"](), longitude_rad=get["lon"](), altitude_m=h,
            relative_altitude_m=h - home[2],
            v_north_m_s=get["vn"]() * U.M_PER_FT, v_east_m_s=get["ve"]() * U.M_PER_FT,
            v_down_m_s=get["vd"]() * U.M_PER_FT, airspeed_m_s=self._state.flow.airspeed_m_s,
            throttle=get["throttle"](), named=named,
            autopilot=v.mode != MODES.MANUAL, manual=v.mode in MODES.STICK_MODES,
            custom_mode=v.mode, armed=v.armed,
            home_latitude_rad=home[0], home_longitude_rad=home[1], home_altitude_m=home[2],
            mission_seq=v.mission_seq, mission_total=len(v.mission),
            battery_voltage_v=b.voltage_v, battery_current_a=b.current_a,
            battery_consumed_mah=b.consumed_mah, battery_energy_j=b.energy_j,
            battery_remaining_pct=b.remaining_pct,
            battery_time_remaining_s=b.time_remaining_s(),
        )


def run_paced(
    sim: SitlSim,
    duration_s: float | None,
    link=None,
    on_sample: Callable[[float, str, tuple], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    clock: Callable[[], float] = time.perf_counter,
    sleep: Callable[[float], None] = time.sleep,
    idle: Callable[[float], None] | None = None,
    stats: PacingStats | None = None,
) -> PacingStats:
    """Fly ``sim`` paced to the wall clock for ``duration_s`` simulated seconds (None: until
    ``should_stop()``; Ctrl-C raises KeyboardInterrupt; a run that leaves its valid range is
    reset by ``sim.step`` and flies on). ``link``: a
    :class:`~bioflex_jsb.links.mavlink.MavlinkLink`, serviced every LINK_PERIOD_S;
    ``on_sample(t_s, model, values)`` after every step (logging); ``idle(slack_s)`` when the
    next step is not due for ``slack_s`` [s] (a place for work that may wait, such as writing
    a log chunk, without delaying a step). ``stats``: the pacing statistics to add the steps
    to (returned; the caller's own holds them when Ctrl-C ends the session)."""
    n_end = None if duration_s is None else sim.k + int(round(duration_s / sim.dt_s))
    # DECISION: what is alive when the paced loop starts (modules, the airframe, the wing, the
    # link: 73 000-143 000 objects the collector tracks) is kept out of the cyclic
    # collector's generations while it runs (gc.freeze), so a full collection in flight
    # scans only the session's own objects: one over all of them took 25-34 ms on a quiet
    # machine (143 000 tracked, as in the bench's process), and without the freeze a 2x run
    # of the bench's sitl_speedup stalled 75-81 ms (p99 75 ms against the 5 ms bar; 0.1-0.5
    # ms in every other run). They go back to the collector when the loop ends, unless
    # the caller has frozen some itself (``bioflex-jsb ardupilot``): its choice stands.
    thawed = gc.get_freeze_count() == 0
    gc.freeze()
    try:
        return _run_paced(sim, n_end, link, on_sample, should_stop, clock, sleep, idle,
                          PacingStats() if stats is None else stats)
    finally:
        if thawed:
            gc.unfreeze()


def _run_paced(sim: SitlSim, n_end: int | None, link, on_sample, should_stop, clock, sleep,
               idle, stats: PacingStats) -> PacingStats:
    """:func:`run_paced`'s loop, up to step ``n_end`` (None: until ``should_stop()``)."""
    add = stats.add
    dt = sim.dt_s
    link_every = max(1, int(round(LINK_PERIOD_S / dt)))
    wall0, k0, speedup = clock(), sim.k, sim.speedup
    with sim.airframe.capturing():
        while n_end is None or sim.k < n_end:
            if sim.resync or sim.speedup != speedup:
                sim.resync = False
                wall0, k0, speedup = clock(), sim.k, sim.speedup
            due = wall0 + (sim.k - k0) * dt / speedup
            now = clock()
            if idle is not None and due - now > SLEEP_MARGIN_S:
                idle(due - now)
                now = clock()
            if due - now > SLEEP_MARGIN_S:
                sleep(due - now - SLEEP_MARGIN_S * 0.5)
                now = clock()
                while now < due - SLEEP_MARGIN_S:  # woke early: wait the rest
                    now = clock()
            late = now - due
            if late > RESYNC_S:
                stats.resyncs += 1
                wall0, k0 = now, sim.k
                late = 0.0
            add(late)
            t = sim.t_s
            model = sim.wing.model
            values = sim.step()
            if on_sample is not None:
                on_sample(t, model, values)
            if link is not None and sim.k % link_every == 0:
                link.service(sim.vehicle_state())
            if should_stop is not None and sim.k % link_every == 0 and should_stop():
                break
    return stats


# When a session's log writes its kept steps as a chunk (``bioflex-jsb sitl`` and the
# pacing benchmark): once at least LOG_FLUSH_STEPS are kept and the loop has
# LOG_FLUSH_SLACK_S [s] of slack before the next step, and at LOG_FLUSH_MAX_STEPS whatever
# the slack (faster than real time there is less slack: smaller chunks, ≈ 1.6 ms each).
LOG_FLUSH_STEPS = 24
LOG_FLUSH_SLACK_S = 0.7e-3
LOG_FLUSH_MAX_STEPS = 96


def log_flush_due(pending_steps: int, slack_s: float) -> bool:
    """Whether a session log with ``pending_steps`` kept should write them now."""
    return (pending_steps >= LOG_FLUSH_STEPS and slack_s >= LOG_FLUSH_SLACK_S
            or pending_steps >= LOG_FLUSH_MAX_STEPS)


def measure_pacing(duration_s: float = 2.0, speedup: float = 1.0, wing: str = "optimised",
                   speed_m_s: float = 15.0, mavlink: str = "udpin:127.0.0.1:0",
                   log_path: str | None = None) -> dict:
    """Pacing error of a real-time SITL run (for ``bioflex-jsb bench``: ``sitl_p50_ms``,
    ``sitl_p99_ms``): ``duration_s`` simulated seconds of the coupled wing at ``speedup``,
    with the MAVLink link serviced as in a session (default: listening on a loopback port,
    telemetry at its default rates, 50 Hz ATTITUDE) and, with ``log_path``, every step
    logged to that MCAP file as ``bioflex-jsb sitl`` logs it (chunks written when the loop
    has slack). Returns :meth:`PacingStats.summary` ([ms] and counts) with ``dt_s``,
    ``speedup`` and ``logged``."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.links.mavlink import MavlinkLink

    build = build_wing(VARIANTS[wing])
    sim = SitlSim(build.model, build.modes, speed_m_s=speed_m_s, speedup=speedup)
    link = MavlinkLink(mavlink, SitlParameters(sim), sim.vehicle)
    log = on_sample = idle = None
    if log_path is not None:
        from bioflex_jsb.simulation.run import RunDescription
        from bioflex_jsb.sinks.mcap import RunLog

        log = RunLog.open(log_path, RunDescription("sitl", wing, speed_m_s, gust="none",
                                                   models=("coupled",), duration_s=duration_s,
                                                   extra={"speedup": speedup}))
        names, pending = sim.names, [0]

        def on_sample(t, model, values):
            log.sample(model, t, dict(zip(names, values, strict=True)))
            pending[0] += 1

        def idle(slack_s: float) -> None:  # as the CLI's session log
            if log_flush_due(pending[0], slack_s):
                log.flush()
                pending[0] = 0
    try:
        stats = run_paced(sim, duration_s, link, on_sample, idle=idle)
    finally:
        link.close()
        if log is not None:
            log.close()
    return {**stats.summary(), "dt_s": sim.dt_s, "speedup": speedup,
            "logged": log_path is not None}
