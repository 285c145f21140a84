"""JSBSim adapter for the rigid airframe: load, initial conditions, trim, linearization.

The runtime package is the only one of bioflex-jsb that imports :mod:`jsbsim`. Everything
crossing its boundary is SI (m, s, kg, N, rad); JSBSim's slug-ft-s/degree values are
converted here, once, with the constants of :mod:`bioflex_jsb.units`.

The JSBSim root (the directory holding ``aircraft/`` and ``systems/``) is found by
:mod:`bioflex_jsb.runtime.roots`. JSBSim's console output (very verbose) is captured, not
printed: see :attr:`Airframe.load_messages` and :attr:`Airframe.warnings`.

Trim
----
:meth:`Airframe.trim` is the one trim of a JSBSim aircraft: level flight by JSBSim's own
trim (``DoTrim``, full mode) or a glider's steady glide, the elastic trim with a wing. The
procedure (the trim companion of the generated prototype, the glide's Newton solver, the
one-line diagnosis of a failed trim) is :mod:`bioflex_jsb.runtime.trim`'s. The linear model
is JSBSim's linearization of the trim instance (the companion) at its trim: with the RPM
residualised as quasi-static the reduced model does not depend on the rotor inertia (it
only scales the RPM row), so the flying instance's is the same. In both instances the two
rotors' gyroscopic moments, equal and opposite, cancel exactly (a symmetric gust stays
symmetric).

Linearization: :mod:`bioflex_jsb.runtime.linearization` (the reduction to x_R = [u, α, q, θ]).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
from collections.abc import Callable, Iterator
from pathlib import Path

import jsbsim
import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.errors import InputError
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.aircraft_files import (
    alpha_limits_rad,
    alpha_table_range_rad,
    derived_root,
)
from bioflex_jsb.runtime.engines import engines_of
from bioflex_jsb.runtime.jsbsim_log import CapturingLogger, LogRecord, captured
from bioflex_jsb.runtime.linearization import (
    lateral_jacobian,
    reduce_to_lateral,
    reduce_to_rigid,
    rigid_jacobian,
)
from bioflex_jsb.runtime.results import (  # noqa: F401  (the runtime's errors and results)
    RIGID_STATE_UNITS,
    RIGID_STATES,
    AircraftLoadError,
    FdmError,
    LateralLinearization,
    LinearizationError,
    ModeEigenvalue,
    RigidLinearization,
    TrimError,
    TrimResult,
    label_modes,
)
from bioflex_jsb.runtime.roots import (  # noqa: F401  (where the JSBSim files are)
    ROOT_ENV_VAR,
    aircraft_file,
    candidate_roots,
    locate_root,
)
from bioflex_jsb.runtime.trim import (  # noqa: F401  (the trim's tolerances and controls)
    TRIM_CONTROLS,
    TRIM_TOLERANCE_FT_S2,
    TRIM_TOLERANCE_RAD_S2,
    JSBSimTrim,
    has_property,
    set_level_ic,
    total_thrust_n,
)
from bioflex_jsb.simulation import jsbsim_properties as JP

DEFAULT_AIRCRAFT = airframe_xml.AIRCRAFT_NAME

# Altitude range accepted for initial conditions [m]: sea level (the paper's Q uses
# ρ = 1.225 kg/m³) up to the tropopause; below −500 m ISA is undefined in practice.
ALTITUDE_RANGE_M = (-500.0, 11000.0)
# Airspeed range accepted before asking JSBSim [m/s]: above 0, below 1/3 of the speed of
# sound (the aerodynamic model is incompressible; Table 1's UAV flies at 10–25 m/s).
SPEED_MAX_M_S = 110.0

# The elastic trim's fixed point on α with JSBSim's trim [rad]: JSBSim's trim resolves α to
# its own tolerances (runtime/trim.py), 1e-6 rad is well within them.
ELASTIC_TRIM_TOL_RAD = 1e-6


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


# ======================================================================================
# The airframe
# ======================================================================================


def _check_speed(speed_m_s: float) -> float:
    v = float(speed_m_s)
    if not math.isfinite(v) or v <= 0.0:
        raise InputError(f"airspeed must be a finite number > 0 m/s, got {speed_m_s!r}")
    if v > SPEED_MAX_M_S:
        raise InputError(
            f"airspeed {v:g} m/s is above {SPEED_MAX_M_S:g} m/s, where the incompressible "
            "aerodynamic model ends"
        )
    return v


def _check_altitude(altitude_m: float) -> float:
    h = float(altitude_m)
    lo, hi = ALTITUDE_RANGE_M
    if not math.isfinite(h) or not lo <= h <= hi:
        raise InputError(f"altitude must be between {lo:g} and {hi:g} m, got {altitude_m!r}")
    return h


def load_fdm(root: Path, aircraft: str, path: Path, log: CapturingLogger) -> jsbsim.FGFDMExec:
    """A JSBSim instance with ``aircraft`` loaded and its initial condition run once
    (messages into ``log``): an aircraft JSBSim loads but cannot initialise (a system
    reading a property nobody defines: JSBSim raises from ``RunIC``) is one line here
    (AircraftLoadError), not a failure at the first trim."""
    with captured(log):
        fdm = jsbsim.FGFDMExec(str(root), None)
        try:
            loaded = fdm.load_model(aircraft)
        except jsbsim.BaseError as exc:
            raise AircraftLoadError(f"JSBSim rejected {str(path)!r}: {_one_line(exc)}") from None
    if not loaded:
        first = next(
            (
                _one_line(r.text)
                for r in log.records
                if jsbsim.LogLevel.ERROR <= r.level <= jsbsim.LogLevel.FATAL
            ),
            "",
        )
        raise AircraftLoadError(
            f"JSBSim could not load {str(path)!r}: {first or 'no reason given'}"
        )
    with captured(log):
        try:
            fdm.run_ic()
        except jsbsim.BaseError as exc:
            raise AircraftLoadError(f"JSBSim loads {str(path)!r} but cannot initialise it: "
                                    f"{_one_line(exc)}") from None
    return fdm


class Airframe:
    """One loaded JSBSim instance of the rigid airframe, with its trim companion.

    Args:
        root: JSBSim root (see :func:`locate_root`); None for the default search.
        aircraft: aircraft name (directory and file name under ``aircraft/``). When
            ``aircraft/<name>_trim/<name>_trim.xml`` exists it is loaded too, as the trim
            companion (module docstring); otherwise the aircraft trims itself.

    Attributes:
        trim_aircraft: name of the aircraft JSBSim's trim and linearization run on (the
            companion, or ``aircraft`` itself).
        load_messages, trim_load_messages: JSBSim's messages while loading the flying
            aircraft and the companion (empty without one).
    """

    def __init__(self, root: str | os.PathLike | None = None, aircraft: str = DEFAULT_AIRCRAFT):
        self.root = locate_root(root, aircraft)
        self.aircraft = aircraft
        self.aircraft_path = aircraft_file(self.root, aircraft)
        self.alpha_limits_rad = alpha_limits_rad(self.aircraft_path)
        self._log = CapturingLogger()
        self._fdm = load_fdm(self.root, aircraft, self.aircraft_path, self._log)
        self._dt_nominal_s = float(self._fdm.get_delta_t())
        self.engine_count = int(self._fdm.get_propulsion().get_num_engines())
        self.engines = engines_of(self.aircraft_path)
        if len(self.engines) != self.engine_count:
            raise AircraftLoadError(f"{str(self.aircraft_path)!r}: JSBSim loaded "
                                    f"{self.engine_count} engines, its file names "
                                    f"{len(self.engines)}")
        self.load_messages: tuple[LogRecord, ...] = tuple(self._log.records)
        self._log.records.clear()
        companion = aircraft + airframe_xml.TRIM_SUFFIX
        companion_path = aircraft_file(self.root, companion)
        self.trim_load_messages: tuple[LogRecord, ...] = ()
        self._trim_aircraft_path = self.aircraft_path
        # the generated prototype's electric pair trims on its companion (module docstring)
        self.has_companion = companion_path.is_file()
        if self.has_companion:
            self.trim_aircraft = companion
            self._trim_aircraft_path = companion_path
            self._trim_fdm = load_fdm(self.root, companion, companion_path, self._log)
            self._trim_fdm.set_dt(self._dt_nominal_s)
            self.trim_load_messages = tuple(self._log.records)
            self._log.records.clear()
            n = int(self._trim_fdm.get_propulsion().get_num_engines())
            if n != self.engine_count:
                raise AircraftLoadError(
                    f"trim companion {str(companion_path)!r} has {n} engines, "
                    f"{aircraft!r} has {self.engine_count}"
                )
        else:
            self.trim_aircraft = aircraft
            self._trim_fdm = self._fdm
        self._nodes: dict[str, object] = {}
        self._trim = JSBSimTrim(self._fdm, self._trim_fdm, self._log, self.engines,
                                self._trim_aircraft_path, self.alpha_limits_rad)
        # α range of the aerodynamic tables [rad]: the generated airframe's (its generator's)
        self.alpha_table_range_rad = airframe_xml.ALPHA_TABLE_RANGE_RAD
        self.definition_name: str | None = None  # the aircraft definition it flies
        self.glider = self.engine_count == 0  # trimmed to a glide (runtime/trim.py)
        self._workdir = None  # the temporary root of an aircraft from a file (aircraft_files.py)

    @classmethod
    def from_file(cls, jsbsim_path: str, cg_m: tuple[float, float, float],
                  definition_name: str | None = None,
                  systems: dict[str, str] | None = None) -> Airframe:
        """Another aircraft (``<dir>/<name>.xml``: a jsbsim package aircraft or a user's)
        with the modal wing's hooks at ``cg_m`` [m, structural frame], loaded from its
        private copy (:func:`~bioflex_jsb.runtime.aircraft_files.derived_root`, kept while
        the airframe lives), its α range its lift curve's; ``definition_name``: the aircraft
        definition it flies (the name of the AirframeData its wing carries: the coupled step
        checks the pair); ``systems``: system files added to the copy."""
        work, name = derived_root(jsbsim_path, cg_m, systems)
        airframe = cls(work.name, name)
        airframe._workdir = work
        airframe.alpha_table_range_rad = alpha_table_range_rad(jsbsim_path)
        airframe.definition_name = definition_name
        return airframe

    # ---- JSBSim messages ----------------------------------------------------------
    @property
    def warnings(self) -> list[str]:
        """Warnings and errors JSBSim printed while loading the aircraft and its trim
        companion (one per message)."""
        return [
            _one_line(r.text)
            for r in self.load_messages + self.trim_load_messages
            if jsbsim.LogLevel.WARN <= r.level <= jsbsim.LogLevel.FATAL
        ]

    # ---- properties ---------------------------------------------------------------
    @property
    def total_thrust_n(self) -> float:
        """Thrust of all engines (the contra-rotating pair) [N]."""
        return total_thrust_n(self._fdm, self.engine_count)

    @property
    def last_rpm_settle_s(self) -> float:
        """Time the flying instance's RPM took to settle on the trim companion's trim RPM
        in the last trim [s] (0 until a companion was trimmed)."""
        return self._trim.last_rpm_settle_s

    @property
    def jsbsim(self):
        """The flying JSBSim instance (``jsbsim.FGFDMExec``), for the runtime's own modules
        that evaluate the model at chosen states (runtime/identification.py); every other
        caller goes through this class's methods."""
        return self._fdm

    def __getitem__(self, name: str) -> float:
        """Raw JSBSim property value (JSBSim units, as the property name says)."""
        return float(self._fdm[name])

    def __setitem__(self, name: str, value: float) -> None:
        """Set an existing JSBSim property (a misspelt name raises KeyError instead of
        silently creating a new, unused property)."""
        if not self._fdm.get_property_manager().hasNode(name):
            raise KeyError(f"JSBSim has no property {name!r}")
        self._fdm[name] = float(value)

    def _instances(self) -> tuple[jsbsim.FGFDMExec, ...]:
        return (self._fdm,) if self._trim_fdm is self._fdm else (self._fdm, self._trim_fdm)

    def _restore_time_step(self) -> None:
        """FGLinearization leaves the time step at 0 (it suspends integration while
        perturbing); put back the step the model was loaded with (or set with set_dt), in
        the flying instance and in the companion."""
        for fdm in self._instances():
            if fdm.integration_suspended():
                fdm.resume_integration()
            if fdm.get_delta_t() != self._dt_nominal_s:
                fdm.set_dt(self._dt_nominal_s)

    # ---- initial conditions ---------------------------------------------------------
    def set_initial_conditions(self, speed_m_s: float, altitude_m: float = 0.0) -> None:
        """Level, wings-level flight at true airspeed ``speed_m_s`` [m/s] and altitude
        ``altitude_m`` [m] above sea level in JSBSim's standard atmosphere (ISA; 0 m = sea
        level, ρ = 1.225 kg/m³), at 45° latitude where JSBSim's gravity is the standard
        9.806 m/s². The ground is put ``TERRAIN_CLEARANCE_M`` below."""
        self._restore_time_step()
        set_level_ic(self._fdm, _check_speed(speed_m_s), _check_altitude(altitude_m), self._log)

    # ---- trim -----------------------------------------------------------------------
    def trim(self, speed_m_s: float, altitude_m: float = 0.0, wing=None) -> TrimResult:
        """The one trim of the airframe: level flight in still air at ``speed_m_s`` [m/s],
        ``altitude_m`` [m] (JSBSim's full trim of the trim companion, the flying instance set
        to it; an aircraft without an engine: its steady glide; the procedure:
        :class:`~bioflex_jsb.runtime.trim.JSBSimTrim`).

        ``wing``: a :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild` for the
        elastic trim: this rigid trim carrying the wing's static loads, solved to their
        fixed point by :func:`bioflex_jsb.flight_dynamics.elastic_trim.elastic_trim` with
        this trim as its rigid trim. The loads (lift and drag against the air) go into the
        external reactions in body axes at the trim's α; the airframe is left trimmed with
        them and the result carries the wing's static state in ``elastic``. None: the rigid
        trim (the external reactions as they are).

        Raises:
            InputError: speed or altitude outside the accepted range; with ``wing``, a
                speed at or beyond the wing's static divergence speed.
            TrimError: JSBSim's trim failed, or the flying instance is not in trim at the
                companion's trim point; one-line diagnosis.
        """
        if wing is None:
            return self._rigid_trim(speed_m_s, altitude_m)
        return self._elastic_trim(wing, speed_m_s, altitude_m)

    def _elastic_trim(self, build, speed_m_s: float, altitude_m: float) -> TrimResult:
        """The rigid trim with the wing's static loads at their fixed point (:meth:`trim`)."""
        from bioflex_jsb.flight_dynamics.elastic_trim import RigidTrimPoint, elastic_trim

        state = {"trim": self._rigid_trim(speed_m_s, altitude_m)}  # the start, and ρ

        def jsbsim_trim(loads) -> RigidTrimPoint:
            alpha = state["trim"].alpha_rad
            ca, sa = math.cos(alpha), math.sin(alpha)
            self.set_external_reactions(loads.lift_n * ca + loads.drag_n * sa,
                                        loads.drag_n * ca - loads.lift_n * sa,
                                        loads.pitch_moment_n_m)
            state["trim"] = self._rigid_trim(speed_m_s, altitude_m)
            return RigidTrimPoint(state["trim"].alpha_rad, state["trim"].elevator_rad)

        rho = float(self._fdm[JP.ATMOSPHERE_RHO_SLUGS_FT3]) * U.KG_M3_PER_SLUG_FT3
        elastic = elastic_trim(build, speed_m_s, density_kg_m3=rho, rigid_trim=jsbsim_trim,
                               tol_rad=ELASTIC_TRIM_TOL_RAD)
        jsbsim_trim(elastic.loads)  # leave the airframe trimmed with the final loads
        return dataclasses.replace(state["trim"], elastic=elastic)

    def _rigid_trim(self, speed_m_s: float, altitude_m: float) -> TrimResult:
        v = _check_speed(speed_m_s)
        h = _check_altitude(altitude_m)
        self._restore_time_step()
        return self._trim.rigid(v, h)

    def has_property(self, name: str) -> bool:
        """Whether the flying instance has the JSBSim property ``name`` (an engine's lever,
        an FCS output)."""
        return has_property(self._fdm, name)

    def _diagnose_trim_failure(self, v: float) -> str:
        """One line: why the last trim at ``v`` [m/s] failed (runtime/trim.py)."""
        return self._trim.diagnose_failure(v)

    # ---- linearization ----------------------------------------------------------------
    def linearize(self, speed_m_s: float, altitude_m: float = 0.0) -> RigidLinearization:
        """Trim at ``speed_m_s`` [m/s], then JSBSim's linear model reduced to x_R (SI).

        Raises:
            ValueError, TrimError: as :meth:`trim`.
            LinearizationError: JSBSim's state list lacks a rigid state, or the RPM block
                cannot be residualised.
        """
        trim = self.trim(speed_m_s, altitude_m)
        if self.glider:  # FGLinearization needs an engine: runtime/linearization.py
            with captured(self._log):
                a, names, residualised = rigid_jacobian(self._fdm), RIGID_STATES, ()
        else:
            with captured(self._log):  # the companion, at its trim (module docstring)
                lin = jsbsim.FGLinearization(self._trim_fdm)
                a_full = np.array(lin.system_matrix, dtype=float)
                names, units = tuple(lin.x_names), tuple(lin.x_units)
            self._restore_time_step()
            a, residualised = reduce_to_rigid(a_full, names, units)
        eig = label_modes(np.linalg.eigvals(a))
        return RigidLinearization(
            speed_m_s=trim.speed_m_s,
            trim=trim,
            a=a,
            eigenvalues=eig,
            jsbsim_states=names,
            residualised_states=residualised,
        )

    def linearize_lateral(self, speed_m_s: float, altitude_m: float = 0.0,
                          method: str = "FGLinearization") -> LateralLinearization:
        """Trim at ``speed_m_s`` [m/s], then JSBSim's lateral-directional linear model
        (states β, p, r, φ; SI): ``method`` ``FGLinearization`` (JSBSim's own, of the trim
        companion at its trim) or ``central differences`` (of the flying instance's state
        derivatives, :func:`~bioflex_jsb.runtime.linearization.lateral_jacobian`); a
        glider always the latter (FGLinearization needs an engine).

        Raises:
            ValueError, TrimError: as :meth:`trim`.
            LinearizationError: JSBSim's state list lacks a lateral state.
        """
        if method not in ("FGLinearization", "central differences"):
            raise ValueError(f"unknown method {method!r}")
        trim = self.trim(speed_m_s, altitude_m)
        if self.glider or method == "central differences":
            # the flying instance of an airframe with a trim companion keeps the trim's RPM
            # (JSBSim's steady-state step diverges at its physical rotor inertia)
            with captured(self._log):
                a = lateral_jacobian(self._fdm,
                                     powered=not (self.glider or self.has_companion))
            method = "central differences"
        else:
            with captured(self._log):
                lin = jsbsim.FGLinearization(self._trim_fdm)
                a_full = np.array(lin.system_matrix, dtype=float)
                names, units = tuple(lin.x_names), tuple(lin.x_units)
            self._restore_time_step()
            a = reduce_to_lateral(a_full, names, units)
        return LateralLinearization(trim.speed_m_s, trim, a, method)

    # ---- modal-wing hooks -----------------------------------------------------------------
    def set_external_reactions(
        self,
        lift_n: float = 0.0,
        drag_n: float = 0.0,
        pitch_moment_n_m: float = 0.0,
        roll_moment_n_m: float = 0.0,
        side_force_n: float = 0.0,
        yaw_moment_n_m: float = 0.0,
    ) -> None:
        """Set the external-reaction hooks (see :mod:`bioflex_jsb.generators.airframe`).

        lift_n: force along body −z (up) [N]; drag_n: along body −x (aft) [N];
        pitch_moment_n_m: about body +y, nose up [N·m]; roll_moment_n_m: about body +x,
        right wing down [N·m]; side_force_n: along body +y (to starboard) [N];
        yaw_moment_n_m: about body +z, nose right [N·m]. They act from the next time step
        on, in the flying instance and in the trim companion (so that a trim carries them:
        the elastic trim).
        """
        prop = airframe_xml.external_property
        values = {"modal-lift": float(lift_n) * U.LBF_PER_N,
                  "modal-drag": float(drag_n) * U.LBF_PER_N,
                  "modal-pitch": float(pitch_moment_n_m) * U.LBF_FT_PER_N_M,
                  "modal-roll": float(roll_moment_n_m) * U.LBF_FT_PER_N_M,
                  "modal-side": float(side_force_n) * U.LBF_PER_N,
                  "modal-yaw": float(yaw_moment_n_m) * U.LBF_FT_PER_N_M}
        for fdm in self._instances():
            manager = fdm.get_property_manager()
            for name, value in values.items():
                if not manager.hasNode(prop(name)):
                    raise KeyError(f"JSBSim has no property {prop(name)!r}")
                fdm[prop(name)] = value

    def external_reaction_writer(self) -> Callable[[float, float, float], None]:
        """A fast writer of the modal external reactions for a per-step loop:
        ``write(lift_n, drag_n, pitch_moment_n_m)`` [N, N, N·m], the same directions and
        units as :meth:`set_external_reactions` (the roll moment is left as it is). The
        property nodes are looked up once, here."""
        prop = airframe_xml.external_property
        set_lift = self.property_node(prop("modal-lift")).set_double_value
        set_drag = self.property_node(prop("modal-drag")).set_double_value
        set_pitch = self.property_node(prop("modal-pitch")).set_double_value
        lbf_per_n, lbf_ft_per_n_m = U.LBF_PER_N, U.LBF_FT_PER_N_M

        def write(lift_n: float, drag_n: float, pitch_moment_n_m: float) -> None:
            set_lift(lift_n * lbf_per_n)
            set_drag(drag_n * lbf_per_n)
            set_pitch(pitch_moment_n_m * lbf_ft_per_n_m)

        return write

    def external_reaction_setters(self) -> tuple[Callable[[float], None], ...]:
        """The raw setters of the modal external reactions, in JSBSim's units, for a
        compiled loop that converts once itself: (force along body −z [lbf], force along
        body −x [lbf], pitch moment about body +y [lbf·ft]) — the directions of
        :meth:`set_external_reactions`."""
        prop = airframe_xml.external_property
        return tuple(self.property_node(prop(name)).set_double_value
                     for name in ("modal-lift", "modal-drag", "modal-pitch"))

    def restart_from_initial_conditions(self) -> None:
        """JSBSim's ``RunIC`` on the flying instance: restart from the ``ic/*`` values set
        (position, attitude, velocities), keeping the propellers' RPM and every control (a
        SITL reset moves the trimmed aircraft to a new place this way; setting the state
        properties instead would stop the propellers)."""
        with captured(self._log):
            self._fdm.run_ic()

    def run(self, steps: int = 1) -> None:
        """Advance JSBSim by ``steps`` time steps of its integration step."""
        with captured(self._log):
            for _ in range(int(steps)):
                self._fdm.run()

    @contextlib.contextmanager
    def capturing(self) -> Iterator[None]:
        """Capture JSBSim's console output for a whole loop of :meth:`step` calls."""
        with captured(self._log):
            yield

    def step(self) -> None:
        """Advance JSBSim by one time step, without entering the output capture: for a
        per-step loop inside ``with airframe.capturing():``."""
        self._fdm.run()

    def step_function(self) -> Callable[[], bool]:
        """JSBSim's own one-step call, for a compiled loop inside ``capturing()`` (what
        :meth:`step` calls, without the Python method around it)."""
        return self._fdm.run

    @property
    def dt_s(self) -> float:
        """JSBSim's integration time step [s]."""
        return float(self._fdm.get_delta_t())

    def set_dt(self, dt_s: float) -> None:
        """Set JSBSim's integration time step [s] (kept across trims and linearizations)."""
        dt = float(dt_s)
        if not math.isfinite(dt) or not 0.0 < dt <= 0.1:
            raise InputError(f"time step must be in (0, 0.1] s, got {dt_s!r}")
        self._dt_nominal_s = dt
        self._restore_time_step()

    def property_node(self, name: str):
        """JSBSim's node of an existing property, for fast repeated reads in a loop
        (``node.get_double_value()``, JSBSim units as the name says)."""
        node = self._fdm.get_property_manager().get_node(name, False)
        if node is None:
            raise KeyError(f"JSBSim has no property {name!r}")
        return node


# ======================================================================================
# Convenience functions: a fresh airframe per call
# ======================================================================================


def load_airframe(root: str | os.PathLike | None = None,
                  aircraft: str = DEFAULT_AIRCRAFT) -> Airframe:
    """Load the airframe (JSBSim console output captured; see :attr:`Airframe.warnings`)."""
    return Airframe(root, aircraft)


def trim(
    speed_m_s: float,
    altitude_m: float = 0.0,
    root: str | os.PathLike | None = None,
    aircraft: str = DEFAULT_AIRCRAFT,
) -> TrimResult:
    """Level-flight trim at ``speed_m_s`` [m/s] and ``altitude_m`` [m] (ISA sea level default)."""
    return Airframe(root, aircraft).trim(speed_m_s, altitude_m)


def linearize(
    speed_m_s: float,
    altitude_m: float = 0.0,
    root: str | os.PathLike | None = None,
    aircraft: str = DEFAULT_AIRCRAFT,
) -> RigidLinearization:
    """Rigid longitudinal linear model x_R = [u, α, q, θ] at the trim for ``speed_m_s``."""
    return Airframe(root, aircraft).linearize(speed_m_s, altitude_m)
