"""The trim of a loaded JSBSim aircraft: the one implementation behind
:meth:`bioflex_jsb.runtime.fdm.Airframe.trim` (every other module calls that method).

Level flight
------------
JSBSim's own trim routine, ``FGFDMExec::DoTrim`` in *full* mode (α, throttle and elevator
for u̇, ẇ, q̇; bank, aileron, rudder and sideslip for the lateral accelerations):
wings-level, constant-altitude flight at the requested true airspeed. The prototype's
propulsion is a contra-rotating pair (see :mod:`bioflex_jsb.generators.airframe`): JSBSim's
trim drives both motors' throttles together, the reaction torques cancel, and the lateral
controls come out at zero. Another aircraft's engines are started first as JSBSim expects
(:mod:`bioflex_jsb.runtime.engines`). When the trim fails, :class:`TrimError` carries one
line naming the control that ran out (throttle at 1, elevator at a stop, α at the stall
limit) or the condition that stayed out of tolerance (:func:`diagnose_trim_failure`).

Two JSBSim instances: the flying aircraft and its trim companion
------------------------------------------------------------------
JSBSim's trim finds the propeller's steady RPM by explicit Euler steps of a fixed 0.5 s
(``FGPropulsion::GetSteadyState``), stable only with a rotor inertia about 8 times the
physical one (the companion's propeller ``<ixx>``). The flying aircraft (``bioflex``)
has the physical rotor inertia, so that in time simulations the RPM, and the
thrust, follow the airspeed within ≈ 0.3 s (quasi-static on the phugoid time scale, as in
JSBSim's linearization); an 8-times inertia made the RPM lag the airspeed by seconds. The
generator writes a trim companion (``bioflex_trim``: the same aircraft, only the propeller
inertia differs), which the airframe loads beside the flying instance when its file exists.
The trim then:

1. trims the companion with ``DoTrim``. The Euler steps cannot start from the propeller at
   rest (an ``electric`` engine at 0 RPM applies its power over 1 rad/s): one normal time
   step with a throttle chosen for the purpose first brings both propellers to their
   windmilling RPM at the trim speed (:func:`spin_up_propellers`; the trim restarts the
   airframe from the initial condition; only the RPM carries over);
2. sets the flying instance to that trim (:func:`fly_at_companion_trim`): initial condition
   (position, Euler angles, body velocities and rates) and every control command copied from
   the companion; then, with JSBSim's integrators of the airframe state switched off
   (``eNone``: the airframe holds the trim state while the propeller model keeps
   integrating its RPM), time steps until both rotors' RPM equal the companion's trim RPM
   (the same steady state: the inertia does not enter it); finally ``RunIC`` from the trim
   initial condition with the integrators restored (the RPM carries over, the multistep
   integrators' history starts afresh);
3. checks the flying instance is in trim: its accelerations within JSBSim's trim tolerances
   (``TrimResult.residuals`` are the flying instance's).

An aircraft without a companion file (``<name>_trim``) is trimmed itself.

A glide
-------
JSBSim's trim trims u̇ with the throttle; an aircraft without an engine (SGS.xml's
``<propulsion>`` is empty) cannot hold its speed in level flight ("udot doesn't appear to be
trimmable"). The physically consistent steady state at a given airspeed is the steady glide
(docs/aircraft.md, "An aircraft without an engine flies its steady glide"): drag balanced by
the weight's component along the path, D = −W sin γ, L = W cos γ. :func:`glide_trim` solves
for the angle of attack α, the flight-path angle γ (negative: descending) and the pitch-trim
command that zero JSBSim's own u̇, ẇ (ft/s²) and q̇ (rad/s²) in JSBSim's initial-condition
evaluation (``RunIC``: the forces and moments of the state, nothing integrated), wings
level, by Newton's method with a finite-difference Jacobian: the trim JSBSim would make with
γ as its u̇ control.

Units: SI at the boundary (m, s, N, rad); JSBSim's ft/slug/lbf inside, converted with
:mod:`bioflex_jsb.units` where a result leaves.
"""

from __future__ import annotations

import contextlib
import math
import re
from functools import lru_cache
from pathlib import Path

import jsbsim
import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.aircraft_files import read_aircraft_xml, read_xml
from bioflex_jsb.runtime.engines import Engine, zero_thrust_advance_ratio
from bioflex_jsb.runtime.engines import start as start_engines
from bioflex_jsb.runtime.jsbsim_log import CapturingLogger, captured
from bioflex_jsb.runtime.results import TrimError, TrimResult
from bioflex_jsb.simulation import jsbsim_properties as JP

# JSBSim's trim modes (FGFDMExec::DoTrim): 0 longitudinal, 1 full.
TRIM_MODE_FULL = 1
# JSBSim's trim tolerances (FGTrimAxis): on udot, wdot [ft/s²] and on qdot, pdot, rdot
# [rad/s²]; the flying instance, set to the companion's trim, must meet them too.
TRIM_TOLERANCE_FT_S2 = 1e-3
TRIM_TOLERANCE_RAD_S2 = 1e-4
# Control commands JSBSim's full trim sets (FGTrimAxis), copied to the flying instance; the
# throttle commands of every engine are added per aircraft.
TRIM_CONTROLS = (
    JP.FCS_ELEVATOR_CMD_NORM,
    JP.FCS_AILERON_CMD_NORM,
    JP.FCS_RUDDER_CMD_NORM,
    JP.FCS_PITCH_TRIM_CMD_NORM,
    JP.FCS_ROLL_TRIM_CMD_NORM,
    JP.FCS_YAW_TRIM_CMD_NORM,
)
_WIND_PROPERTIES = (
    JP.ATMOSPHERE_WIND_NORTH_FPS,
    JP.ATMOSPHERE_WIND_EAST_FPS,
    JP.ATMOSPHERE_WIND_DOWN_FPS,
)


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


# ======================================================================================
# The trim
# ======================================================================================


def set_level_ic(fdm: jsbsim.FGFDMExec, v: float, h: float, log: CapturingLogger) -> None:
    """Set ``fdm`` to level, wings-level flight at true airspeed ``v`` [m/s] and altitude
    ``h`` [m] above sea level (ISA), at the latitude where JSBSim's gravity is the standard
    9.806 m/s², the ground ``TERRAIN_CLEARANCE_M`` below, the trim controls at zero, and run
    its initial condition (messages into ``log``)."""
    fdm[JP.IC_LAT_GEOD_RAD] = airframe_xml.INIT_LATITUDE_RAD  # standard gravity there
    fdm[JP.IC_LONG_GC_RAD] = 0.0
    fdm[JP.IC_TERRAIN_ELEVATION_FT] = (h - airframe_xml.TERRAIN_CLEARANCE_M) * U.FT_PER_M
    fdm[JP.IC_H_SL_FT] = h * U.FT_PER_M
    for name in (JP.IC_PHI_RAD, JP.IC_PSI_TRUE_RAD, JP.IC_BETA_RAD, JP.IC_GAMMA_RAD):
        fdm[name] = 0.0
    for name in (JP.IC_P_RAD_SEC, JP.IC_Q_RAD_SEC, JP.IC_R_RAD_SEC, JP.IC_ALPHA_RAD):
        fdm[name] = 0.0
    fdm[JP.IC_VT_FPS] = v * U.FT_PER_M
    for name in TRIM_CONTROLS:
        fdm[name] = 0.0
    with captured(log):
        fdm.run_ic()


def has_property(fdm: jsbsim.FGFDMExec, name: str) -> bool:
    """Whether the JSBSim instance ``fdm`` has the property ``name``."""
    return bool(fdm.get_property_manager().hasNode(name))


def total_thrust_n(fdm: jsbsim.FGFDMExec, engine_count: int) -> float:
    """Thrust of all engines of ``fdm`` (the prototype's contra-rotating pair) [N]."""
    lbs = sum(float(fdm[JP.engine(i, "thrust-lbs")]) for i in range(engine_count))
    return lbs * U.N_PER_LBF


def aileron_norm(fdm: jsbsim.FGFDMExec) -> float:
    """The aileron position −1..1 (+ roll right): the left surface's normalised position
    where the FCS writes one per side (c172p, the prototype), else the single
    ``fcs/aileron-pos-norm``, else the command with its trim (an FCS that writes only
    radians)."""
    for name in (JP.FCS_LEFT_AILERON_POS_NORM, JP.FCS_AILERON_POS_NORM):
        if has_property(fdm, name):
            return float(fdm[name])
    command = float(fdm[JP.FCS_AILERON_CMD_NORM]) + float(fdm[JP.FCS_ROLL_TRIM_CMD_NORM])
    return min(1.0, max(-1.0, command))


class JSBSimTrim:
    """The trim of one loaded aircraft (module docstring): its flying instance ``fdm``, the
    instance JSBSim's trim runs on ``trim_fdm`` (its companion, or ``fdm`` itself), the log
    both write their messages into, its engines (none: a glider), the trim instance's file
    and the α limits [rad] of its lift tables (the diagnosis names them).

    Attributes:
        last_rpm_settle_s: time the flying instance's RPM took to settle on the companion's
            trim RPM in the last trim [s] (0 until a companion was trimmed).
    """

    def __init__(self, fdm: jsbsim.FGFDMExec, trim_fdm: jsbsim.FGFDMExec,
                 log: CapturingLogger, engines: tuple[Engine, ...], trim_aircraft_path: Path,
                 alpha_limits_rad: tuple[float, float]) -> None:
        self.fdm = fdm
        self.trim_fdm = trim_fdm
        self.log = log
        self.engines = engines
        self.engine_count = len(engines)
        self.trim_aircraft_path = trim_aircraft_path
        self.alpha_limits_rad = alpha_limits_rad
        self.has_companion = trim_fdm is not fdm
        self.glider = not engines
        self.last_rpm_settle_s = 0.0

    def rigid(self, v: float, h: float) -> TrimResult:
        """Level flight in still air at ``v`` [m/s], ``h`` [m] (checked by the caller),
        or a glider's steady glide; the flying instance is left in that trim. Raises
        :class:`TrimError` (one line)."""
        instances = (self.fdm, self.trim_fdm) if self.has_companion else (self.fdm,)
        for fdm in instances:
            for name in _WIND_PROPERTIES:
                fdm[name] = 0.0
        tfdm = self.trim_fdm
        set_level_ic(tfdm, v, h, self.log)
        if self.glider:  # no engine: the steady glide at v
            with captured(self.log):
                glide_trim(tfdm, v)
            return self._checked_result(v, h)
        if self.has_companion:
            with captured(self.log):
                spin_up_propellers(tfdm, v, self.trim_aircraft_path, self.engine_count)
        else:
            with captured(self.log):
                start_engines(tfdm, self.engines)
        self.log.records.clear()
        with captured(self.log), trim_report(tfdm):
            try:
                tfdm.do_trim(TRIM_MODE_FULL)
                failed = False
            except jsbsim.TrimFailureError:
                failed = True
        if failed:
            if self.has_companion:  # leave the flying instance at a defined state
                set_level_ic(self.fdm, v, h, self.log)
            raise TrimError(self.diagnose_failure(v))
        if self.has_companion:
            with captured(self.log):
                self.last_rpm_settle_s = fly_at_companion_trim(
                    self.fdm, tfdm, v, TRIM_CONTROLS, self.engine_count)
        return self._checked_result(v, h)

    def _checked_result(self, v: float, h: float) -> TrimResult:
        """The flying instance's trim, its accelerations within JSBSim's trim tolerances."""
        result = self.result(v, h)
        r = result.residuals
        ft_s2 = max(abs(r["udot_m_s2"]), abs(r["wdot_m_s2"])) * U.FT_PER_M
        rad_s2 = max(abs(r["qdot_rad_s2"]), abs(r["pdot_rad_s2"]), abs(r["rdot_rad_s2"]))
        if ft_s2 > TRIM_TOLERANCE_FT_S2 or rad_s2 > TRIM_TOLERANCE_RAD_S2:
            worst = ", ".join(f"{k} {x:.1e}" for k, x in r.items())
            raise TrimError(
                f"cannot trim at {result.speed_m_s:g} m/s: the flying aircraft set to the trim "
                f"companion's trim is out of tolerance ({worst})"
            )
        return result

    def result(self, v: float, h: float) -> TrimResult:
        """The flying instance's state and controls as a :class:`TrimResult` (SI)."""
        fdm = self.fdm
        return TrimResult(
            speed_m_s=v,
            altitude_m=h,
            alpha_rad=float(fdm[JP.AERO_ALPHA_RAD]),
            theta_rad=float(fdm[JP.ATTITUDE_THETA_RAD]),
            elevator_norm=(glide_elevator_norm(fdm) if self.glider  # its command: SGS.xml
                           else float(fdm[JP.FCS_ELEVATOR_POS_NORM])),  # writes no position
            elevator_rad=float(fdm[JP.FCS_ELEVATOR_POS_RAD]),
            throttle=0.0 if self.glider else float(fdm[JP.FCS_THROTTLE_POS_NORM]),
            aileron_norm=aileron_norm(fdm),
            propeller_rpm=self._propeller_rpm(),
            thrust_n=total_thrust_n(fdm, self.engine_count),
            converged=True,
            residuals={
                "udot_m_s2": float(fdm[JP.ACCELERATIONS_UDOT_FT_SEC2]) * U.M_PER_FT,
                "wdot_m_s2": float(fdm[JP.ACCELERATIONS_WDOT_FT_SEC2]) * U.M_PER_FT,
                "qdot_rad_s2": float(fdm[JP.ACCELERATIONS_QDOT_RAD_SEC2]),
                "pdot_rad_s2": float(fdm[JP.ACCELERATIONS_PDOT_RAD_SEC2]),
                "rdot_rad_s2": float(fdm[JP.ACCELERATIONS_RDOT_RAD_SEC2]),
            },
            flight_path_rad=float(fdm[JP.FLIGHT_PATH_GAMMA_RAD]) if self.glider else 0.0,
        )

    def _propeller_rpm(self) -> float:
        """Engine 0's propeller speed [rev/min]; 0 for an aircraft without a propeller (a
        glider, a jet)."""
        name = JP.PROPULSION_ENGINE_0_PROPELLER_RPM
        return (float(self.fdm[name]) if self.engines and has_property(self.fdm, name)
                else 0.0)

    def _first_message(self, min_level: int) -> str:
        for r in self.log.records:
            if min_level <= r.level <= jsbsim.LogLevel.FATAL:
                return _one_line(r.text)
        return ""

    def diagnose_failure(self, v: float) -> str:
        """One line: which control saturated or which condition failed, from the trim's
        messages in the log; an engine that stopped during the trim is named first (its
        thrust was missing, not the throttle's)."""
        text = "\n".join(r.text for r in self.log.records)
        engine = "the motor gives" if self.has_companion else (
            "the engine gives" if len(self.engines) == 1 else "the engines give")
        line = diagnose_trim_failure(text, v, self.alpha_limits_rad,
                                     self._first_message(jsbsim.LogLevel.WARN), engine)
        stopped = [e for e in self.engines
                   if has_property(self.fdm, name := JP.engine(e.index, "engine-rpm"))
                   and self.trim_fdm[name] <= 0.0]
        if stopped and not self.has_companion:
            names = ", ".join(f"{e.index} ({e.kind}, {e.file})" for e in stopped)
            line = (f"cannot trim at {v:g} m/s: engine {names} stopped during the trim (0 "
                    "rev/min: its fuel feed or the aircraft's systems hold it; "
                    f"JSBSim's trim then says: {line.split(': ', 1)[-1]})")
        return line


# ======================================================================================
# Why JSBSim's trim failed: its messages read (pure text)
# ======================================================================================

# A normalised control this close to its stop counts as saturated in the trim diagnosis
# (JSBSim's trim report prints controls to 2 significant digits).
SATURATION_MARGIN = 0.01

# JSBSim's trim report: one line per axis, e.g.
# "  Throttle            : 1      udot : -3.68e+01 Tolerance: 1e-03  Failed"
REPORT_LINE = re.compile(
    r"^\s*(?P<control>[A-Za-z][A-Za-z ]*?)\s*:\s*(?P<value>\S+)\s+(?P<state>\w+)\s*:\s*"
    r"(?P<residual>\S+)\s+Tolerance:\s*\S+\s+(?P<verdict>Passed|Failed)\s*$",
    re.MULTILINE,
)
UNTRIMMABLE = re.compile(r"Sorry, (?P<state>\w+) doesn't appear to be trimmable")

def diagnose_trim_failure(text: str, v: float, alpha_limits_rad: tuple[float, float],
                          first_warning: str = "", engine: str = "the motor gives") -> str:
    """One line: which control saturated or which condition failed (from JSBSim's
    trim messages: the 'not trimmable' verdict and the final axis report); ``engine``: what
    gives the thrust, with its verb ("the motor gives", "the engines give")."""
    axes: dict[str, tuple[str, float, float, bool]] = {}
    for m in REPORT_LINE.finditer(text):
        try:
            value, residual = float(m["value"]), float(m["residual"])
        except ValueError:
            continue
        axes[m["state"]] = (m["control"], value, residual, m["verdict"] == "Passed")
    untrimmable = [m["state"] for m in UNTRIMMABLE.finditer(text)]
    where = f"at {v:g} m/s"
    lo_deg, hi_deg = (math.degrees(a) for a in alpha_limits_rad)

    def sign(state: str) -> float:
        return axes[state][2] if state in axes else 0.0

    def saturated(state: str, limit: float) -> bool:
        return state in axes and abs(axes[state][1] - limit) <= SATURATION_MARGIN

    if "udot" in untrimmable or saturated("udot", 1.0):
        if sign("udot") < 0.0 or saturated("udot", 1.0):
            return (
                f"cannot trim {where}: level flight needs more thrust than {engine} "
                "(throttle saturated at 1)"
            )
        return f"cannot trim {where}: the aircraft accelerates even at zero throttle"
    if "wdot" in untrimmable:
        if sign("wdot") >= 0.0:
            return (
                f"cannot trim {where}: level flight needs an angle of attack beyond the "
                f"stall limit {hi_deg:.1f} deg (speed below the stall speed)"
            )
        return (
            f"cannot trim {where}: level flight needs an angle of attack below the "
            f"negative-stall limit {lo_deg:.1f} deg"
        )
    if "qdot" in untrimmable or saturated("qdot", 1.0) or saturated("qdot", -1.0):
        stop = "nose-down" if sign("qdot") > 0.0 else "nose-up"
        return (
            f"cannot trim {where}: the elevator is at its {stop} stop and cannot balance "
            "the pitching moment"
        )
    if untrimmable:
        return f"cannot trim {where}: JSBSim finds {', '.join(untrimmable)} untrimmable"
    failed = [f"{s} (by {c.strip().lower()})" for s, (c, _, _, ok) in axes.items() if not ok]
    if failed:
        return (
            f"cannot trim {where}: JSBSim's trim did not converge; out of tolerance: "
            + ", ".join(failed)
        )
    reason = first_warning
    return f"cannot trim {where}: JSBSim's trim failed" + (f" ({reason})" if reason else "")


@contextlib.contextmanager
def trim_report(fdm):
    """JSBSim prints its trim's axis report, which :func:`diagnose_trim_failure` reads, only
    at a debug level of 1 or more, and that level is the process's (``FGJSBBase::debug_lvl``:
    any ``FGFDMExec.set_debug_level`` changes it for every instance; a test that silenced its
    own JSBSim made a later 60 m/s trim read "accelerates even at zero throttle"): at least 1
    during the trim, the level found restored after."""
    level = fdm.get_debug_level()
    fdm.set_debug_level(max(1, level))
    try:
        yield
    finally:
        fdm.set_debug_level(level)


# ======================================================================================
# A glider: its steady glide
# ======================================================================================

# The glide trim's convergence: JSBSim's own trim tolerances are 1e-3 ft/s² on u̇, ẇ and
# 1e-4 rad/s² on q̇ (FGTrimAxis; TRIM_TOLERANCE_* above); Newton is asked for
# 1e-3 of them, which it reaches in 3-5 iterations (the tables are linear between their
# points: measured 4 iterations at 20-28 m/s for SGS, residuals below 1e-9).
GLIDE_TOL_FT_S2 = 1e-6
GLIDE_TOL_RAD_S2 = 1e-7
GLIDE_MAX_ITERATIONS = 30
# Finite-difference steps of the Jacobian [rad, rad, -]: 1e-7 rad moves α by a millionth
# of a table interval (1° = 0.0175 rad), so a step crosses a table point at most once in
# ten thousand evaluations; the residuals are O(10 ft/s²) per rad, so the differences keep
# 8 significant digits.
FD_STEP = 1e-7
# The γ search is bounded: a glide steeper than 45° is no glide (L/D < 1).
GAMMA_LIMIT_RAD = math.radians(45.0)
PITCH_TRIM = JP.FCS_PITCH_TRIM_CMD_NORM  # the control JSBSim's full trim moves for q̇



def glide_trim(fdm, speed_m_s: float) -> int:
    """Trim ``fdm`` (a JSBSim instance at its initial condition: wings level, true airspeed
    ``speed_m_s`` [m/s], controls zero) to the steady glide (module docstring); returns the
    Newton iterations taken. The instance is left at the trimmed initial condition.
    Raises :class:`TrimError` (one line) when no glide is found."""
    def residuals(x: np.ndarray) -> np.ndarray:
        fdm[JP.IC_GAMMA_RAD] = x[1]
        fdm[JP.IC_ALPHA_RAD] = x[0]
        fdm[PITCH_TRIM] = x[2]
        fdm.run_ic()
        return np.array([fdm[JP.ACCELERATIONS_UDOT_FT_SEC2], fdm[JP.ACCELERATIONS_WDOT_FT_SEC2],
                         fdm[JP.ACCELERATIONS_QDOT_RAD_SEC2]])

    tol = np.array([GLIDE_TOL_FT_S2, GLIDE_TOL_FT_S2, GLIDE_TOL_RAD_S2])
    x = np.zeros(3)
    r = residuals(x)
    for iteration in range(1, GLIDE_MAX_ITERATIONS + 1):
        jac = np.empty((3, 3))
        for j in range(3):
            xj = x.copy()
            xj[j] += FD_STEP
            jac[:, j] = (residuals(xj) - r) / FD_STEP
        if not np.all(np.isfinite(jac)) or abs(np.linalg.det(jac)) < 1e-300:
            break
        x = x - np.linalg.solve(jac, r)
        if abs(x[1]) > GAMMA_LIMIT_RAD or abs(x[2]) > 1.0:
            x[1] = float(np.clip(x[1], -GAMMA_LIMIT_RAD, GAMMA_LIMIT_RAD))
            x[2] = float(np.clip(x[2], -1.0, 1.0))
        r = residuals(x)
        if np.all(np.abs(r) <= tol):
            return iteration
    what = ("the pitch trim at its stop" if abs(x[2]) >= 1.0 else
            f"the glide steeper than {math.degrees(GAMMA_LIMIT_RAD):g} deg"
            if abs(x[1]) >= GAMMA_LIMIT_RAD else "no convergence")
    raise TrimError(f"cannot trim a steady glide at {speed_m_s:g} m/s ({what}: alpha "
                    f"{math.degrees(x[0]):.2f} deg, gamma {math.degrees(x[1]):.2f} deg; "
                    f"udot {r[0]:.1e} ft/s2, wdot {r[1]:.1e} ft/s2, qdot {r[2]:.1e} rad/s2)")



def glide_elevator_norm(fdm) -> float:
    """A glider's trimmed elevator, −1..1: its normalised command (elevator command + the
    pitch trim :func:`glide_trim` moves, clipped to ±1), what an FCS like SGS.xml's moves
    the surface by; that FCS writes only the deflection in rad, and its never-written
    ``fcs/elevator-pos-norm`` read 0 whatever the trim."""
    command = float(fdm[JP.FCS_ELEVATOR_CMD_NORM]) + float(fdm[PITCH_TRIM])
    return min(1.0, max(-1.0, command))


# ======================================================================================
# The trim companion: propellers spun up, the flying instance set to its trim
# ======================================================================================

# Settling the flying instance's propeller RPM on the companion's trim RPM (airframe held):
# relative RPM agreement asked for [-], and the longest settling time allowed [s] (the
# physical rotor's time constant is ≈ 0.3 s at cruise).
RPM_SETTLE_REL_TOL = 1e-9
RPM_SETTLE_MAX_S = 60.0
# JSBSim's integrator choices (FGPropagate) and the one that holds a state: 0 = eNone.
_INTEGRATOR_PROPERTIES = JP.INTEGRATOR_PROPERTIES
_INTEGRATOR_NONE = 0


# JSBSim's units of the rotor data the spin-up reads (FGJSBBase's conversions): to ft, to
# slug·ft², to ft·lbf/s (one mechanical horsepower is 550 ft·lbf/s); a value without a unit is
# in the unit JSBSim converts it to (FGPropeller: FT, SLUG*FT2; FGElectric: WATTS).
_LENGTH_TO_FT = {"FT": 1.0, "IN": 1.0 / 12.0, "M": U.FT_PER_M}
_INERTIA_TO_SLUG_FT2 = {"SLUG*FT2": 1.0, "KG*M2": U.SLUG_FT2_PER_KG_M2}
_POWER_TO_FT_LBF_S = {"WATTS": U.LBF_FT_PER_N_M, "HP": 550.0}


def _xml_value(element, tag: str, units: dict[str, float], default_unit: str,
               source: Path) -> float:
    """``<tag unit=...>value</tag>`` of ``element`` in the unit the table converts to."""
    node = element.find(tag)
    unit = (node.get("unit", default_unit) if node is not None else default_unit).upper()
    try:
        return float(node.text) * units[unit]
    except (AttributeError, TypeError, ValueError, KeyError):
        raise TrimError(f"{str(source)!r}: no <{tag}> in {', '.join(units)} for the "
                        "propeller spin-up") from None


@lru_cache(maxsize=8)
def rotor_spin_up_data(aircraft_path: Path) -> tuple[float, float, float]:
    """(diameter [ft], rotor inertia [slug·ft²], motor power [ft·lbf/s]) of the first engine
    of the aircraft file ``aircraft_path`` (the trim companion's: its effective rotor
    inertia), read from its thruster and engine files as JSBSim reads them
    (``<diameter>``, ``<ixx>`` of the propeller, ``<power>`` of the electric motor)."""
    aircraft = read_aircraft_xml(aircraft_path).getroot()
    engine = aircraft.find(".//propulsion/engine")
    thruster = None if engine is None else engine.find("thruster")
    if thruster is None or not engine.get("file") or not thruster.get("file"):
        raise TrimError(f"{str(aircraft_path)!r} has no engine with a propeller to spin up")
    engines_dir = aircraft_path.parent / "Engines"
    prop_path = engines_dir / f"{thruster.get('file')}.xml"
    motor_path = engines_dir / f"{engine.get('file')}.xml"
    prop = read_xml(prop_path, "the propeller").getroot()
    motor = read_xml(motor_path, "the engine").getroot()
    return (_xml_value(prop, "diameter", _LENGTH_TO_FT, "FT", prop_path),
            _xml_value(prop, "ixx", _INERTIA_TO_SLUG_FT2, "SLUG*FT2", prop_path),
            _xml_value(motor, "power", _POWER_TO_FT_LBF_S, "WATTS", motor_path))


def spin_up_propellers(fdm, speed_m_s: float, aircraft_path: Path, engine_count: int) -> None:
    """Bring both propellers of ``fdm`` (the trim instance) from rest to their windmilling
    RPM at ``speed_m_s`` in one step.

    At 0 RPM JSBSim's propeller turns the engine power P [ft·lbf/s] into a torque of
    P/(1 rad/s), so one step of dt [s] gives ω = throttle·P·dt/I per rotor (P, I and the
    diameter D of one rotor, as the aircraft's files give them to JSBSim:
    :func:`rotor_spin_up_data`; the companion's effective inertia).
    The throttle for ω = 2πV/(J₀D) (J₀: zero-thrust advance ratio) is set on every
    engine for that step.
    """
    diameter_ft, inertia_slug_ft2, power_ft_lbf_s = rotor_spin_up_data(aircraft_path)
    omega_rad_s = (
        2.0 * math.pi * speed_m_s
        / (zero_thrust_advance_ratio(aircraft_path) * diameter_ft * U.M_PER_FT)
    )
    throttle = min(1.0, omega_rad_s * inertia_slug_ft2 / (power_ft_lbf_s * fdm.get_delta_t()))
    for i in range(engine_count):
        fdm[JP.throttle_cmd(i)] = throttle
    fdm.run()


# The flying instance's initial conditions from the companion's state, in this order:
# position and attitude first, then the body velocities in that attitude (JSBSim units).
_IC_FROM_STATE = (
    (JP.IC_LAT_GEOD_RAD, JP.POSITION_LAT_GEOD_RAD),
    (JP.IC_LONG_GC_RAD, JP.POSITION_LONG_GC_RAD),
    (JP.IC_TERRAIN_ELEVATION_FT, JP.POSITION_TERRAIN_ELEVATION_ASL_FT),
    (JP.IC_H_SL_FT, JP.POSITION_H_SL_FT),
    (JP.IC_PHI_RAD, JP.ATTITUDE_PHI_RAD),
    (JP.IC_THETA_RAD, JP.ATTITUDE_THETA_RAD),
    (JP.IC_PSI_TRUE_RAD, JP.ATTITUDE_PSI_RAD),
    (JP.IC_U_FPS, JP.VELOCITIES_U_FPS),
    (JP.IC_V_FPS, JP.VELOCITIES_V_FPS),
    (JP.IC_W_FPS, JP.VELOCITIES_W_FPS),
    (JP.IC_P_RAD_SEC, JP.VELOCITIES_P_RAD_SEC),
    (JP.IC_Q_RAD_SEC, JP.VELOCITIES_Q_RAD_SEC),
    (JP.IC_R_RAD_SEC, JP.VELOCITIES_R_RAD_SEC),
)


def fly_at_companion_trim(fdm, src, v: float, controls: tuple[str, ...],
                          engine_count: int) -> float:
    """Set the flying instance ``fdm`` to the companion ``src``'s trim at ``v`` [m/s]:
    state, ``controls`` and every engine's throttle, propeller RPM; returns the time
    the RPM took to settle [s]."""
    for ic, state in _IC_FROM_STATE:
        fdm[ic] = src[state]
    controls = controls + tuple(JP.throttle_cmd(i) for i in range(engine_count))
    for name in controls:
        fdm[name] = src[name]
    rpm_names = [JP.engine(i, "propeller-rpm") for i in range(engine_count)]
    targets = [float(src[name]) for name in rpm_names]
    integrators = {name: fdm[name] for name in _INTEGRATOR_PROPERTIES}
    dt = fdm.get_delta_t()
    steps = 0
    fdm.run_ic()
    try:  # hold the airframe at the trim state; the propellers integrate their RPM
        for name in _INTEGRATOR_PROPERTIES:
            fdm[name] = _INTEGRATOR_NONE
        limit = max(1, round(RPM_SETTLE_MAX_S / dt))
        while steps < limit:
            fdm.run()
            steps += 1
            if all(
                abs(fdm[name] - target) <= RPM_SETTLE_REL_TOL * abs(target)
                for name, target in zip(rpm_names, targets, strict=True)
            ):
                break
    finally:
        for name, value in integrators.items():
            fdm[name] = value
    fdm.run_ic()  # back to the trim state; the RPM carries over
    rpm = [float(fdm[name]) for name in rpm_names]
    worst = max(abs(r - t) / abs(t) for r, t in zip(rpm, targets, strict=True))
    if worst > RPM_SETTLE_REL_TOL:
        raise TrimError(
            f"cannot trim at {v:g} m/s: the flying aircraft's propeller RPM did not settle "
            f"on the trim RPM {targets[0]:.1f} rev/min in {RPM_SETTLE_MAX_S:g} s "
            f"(relative difference {worst:.1e})"
        )
    return steps * dt
