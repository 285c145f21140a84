"""The one coupled step: JSBSim's rigid airframe and the Python modal wing, one step at a time.

Every driver (gust runs, comparisons, SITL, the benchmark, the sweep's evaluator) advances
the aircraft through :class:`CoupledStep`; nothing else configures the airframe for a run,
senses the flow, applies the wing's loads or checks the valid range.

Per step k (time t_k = k Δt, airframe state x_k), :meth:`CoupledStep.advance`:

1. writes the gust w_g(t_k) to JSBSim's wind (``atmosphere/wind-down-fps`` = −w_g);
2. reads the airframe's state x_k in one snapshot (:func:`state_reader`: attitude, rates,
   position, velocities, n_z, controls) with the flow at the wing (α, β, V, Q against the
   air, q) computed from x_k and that wind, as JSBSim's FGAuxiliary computes it;
3. advances the wing η_k → η_{k+1} with that flow held over the step (exact discretisation,
   :class:`~bioflex_jsb.simulation.modal_wing.ModalWing`) and writes the loads of η_{k+1}
   in that flow into ``external_reactions`` (lift and drag turned from wind to body axes
   with α_k);
   With a controller in the loop (``controller=``, :mod:`bioflex_jsb.simulation.controller`)
   the row of t_k (step 5's) is built here, with the sensor stations' channels of t_k (the
   rigid body of x_k, the wing's η̈_k from η_{k−1}, η_k and the η_{k+1} just reached: all
   known before JSBSim's step), the controller reads its signals and its
   commands go into the row (``ctrl_<command>``) and to JSBSim's flight controls
   (:mod:`bioflex_jsb.runtime.control_surfaces`), which move the surface in step 4: the
   forces of x_{k+1} carry it, one step after the LTI model's zero-order hold would;
4. runs JSBSim's step: it integrates x_k → x_{k+1} and computes the forces of x_{k+1},
   which it applies over the next step — with the wing's loads of η_{k+1}, the same time,
   so the elastic loads do not lag the rigid aerodynamics;
5. builds the row of t_k by channel name (the snapshot of 2, the loads of 3, η_k, η̇_k;
   :mod:`bioflex_jsb.simulation.channels`) and checks the valid range
   (:mod:`bioflex_jsb.simulation.limits`); a run out of range sets :attr:`stopped`.

Model ``native``: the wing is JSBSim's own (an aircraft exported by
:mod:`bioflex_jsb.generators.native_wing`); step 3 is left out and η, η̇ and the loads are
read from its properties.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import NamedTuple

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.aerodynamics.airframe_polars import alpha_peak_rad
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.fdm import Airframe, TrimResult
from bioflex_jsb.runtime.full_span_step import FullSpanSteps, check_span
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation import step_kernel as K
from bioflex_jsb.simulation.channels import channel_units, eta_names, row_getter
from bioflex_jsb.simulation.controller_kernel import linear_step
from bioflex_jsb.simulation.jsbsim_settings import INTEGRATORS
from bioflex_jsb.simulation.limits import ETA_LIMIT_RAD, mode_labels, out_of_range
from bioflex_jsb.simulation.modal_wing import (
    DEFAULT_DT_S,
    WING_MODELS,
    FlowState,
    ModalWing,
    TrimReference,
    WingLoads,
)
from bioflex_jsb.simulation.sensors import KINEMATICS as SENSOR_KINEMATICS
from bioflex_jsb.simulation.sensors import SensorRows, SensorSet

STEP_MODELS = (*WING_MODELS, "native")
TRIM_MODES = ("rigid", "elastic")  # the trim a run starts from (``trim_mode``)
AERO_MODELS = ("quasi-steady", "unsteady")  # the wing's strip aerodynamics (``aero``)
# The JSBSim properties of a snapshot (JSBSim units, as the names say).
PROPERTIES: Mapping[str, str] = MappingProxyType({
    "u": JP.VELOCITIES_U_FPS, "v": JP.VELOCITIES_V_FPS, "w": JP.VELOCITIES_W_FPS,
    "q": JP.VELOCITIES_Q_RAD_SEC, "p": JP.VELOCITIES_P_RAD_SEC, "r": JP.VELOCITIES_R_RAD_SEC,
    "theta": JP.ATTITUDE_THETA_RAD, "phi": JP.ATTITUDE_PHI_RAD, "psi": JP.ATTITUDE_PSI_RAD,
    "rho": JP.ATMOSPHERE_RHO_SLUGS_FT3, "nz": JP.ACCELERATIONS_NZ, "h": JP.POSITION_H_SL_FT,
    "agl": JP.POSITION_H_AGL_FT, "lat": JP.POSITION_LAT_GEOD_RAD, "lon": JP.POSITION_LONG_GC_RAD,
    "vn": JP.VELOCITIES_V_NORTH_FPS, "ve": JP.VELOCITIES_V_EAST_FPS, "vd": JP.VELOCITIES_V_DOWN_FPS,
    "elevator": JP.FCS_ELEVATOR_POS_RAD, "throttle": JP.FCS_THROTTLE_POS_NORM,
})
WIND_DOWN = JP.ATMOSPHERE_WIND_DOWN_FPS
# The native wing's published state and loads (bioflex_jsb.generators.native_wing).
NATIVE_PREFIX = "bioflex/modal"
NATIVE_LOADS = (JP.AERO_FORCE_MODAL_LIFT, JP.AERO_FORCE_MODAL_DRAG, JP.AERO_MOMENT_MODAL_PITCH)


class Sensed(NamedTuple):
    """The airframe at one instant, as the wing and the logs see it (SI; aerospace frames:
    NED Euler angles, FRD body rates, NED velocities; ``docs/conventions.md``). ``flow``:
    the air data at the wing with the current wind (α, q, V, Q); β likewise against the
    air."""

    flow: FlowState
    theta_rad: float
    phi_rad: float
    psi_rad: float
    beta_rad: float
    p_rad_s: float
    r_rad_s: float
    n_z: float
    altitude_m: float
    latitude_rad: float
    longitude_rad: float
    v_north_m_s: float
    v_east_m_s: float
    v_down_m_s: float
    elevator_rad: float
    throttle: float


def state_reader(get: Mapping[str, Callable[[], float]]) -> Callable[[float], Sensed]:
    """``read(wind_down_fps)``: the airframe's state now and the flow the wing sees with the
    NED vertical wind ``wind_down_fps`` [ft/s, down], as JSBSim's FGAuxiliary computes it.

    ``get`` maps the keys of :data:`PROPERTIES` to property readers (bound once, for the
    per-step call). Everything is read at the same instant: the state JSBSim reached at the
    end of its last step (its n_z is that of this state), so a row is one snapshot.
    """
    g_u, g_v, g_w, g_q = get["u"], get["v"], get["w"], get["q"]
    g_theta, g_phi, g_psi, g_p, g_r = get["theta"], get["phi"], get["psi"], get["p"], get["r"]
    g_rho, g_nz, g_h, g_lat, g_lon = get["rho"], get["nz"], get["h"], get["lat"], get["lon"]
    g_vn, g_ve, g_vd = get["vn"], get["ve"], get["vd"]
    g_elevator, g_throttle = get["elevator"], get["throttle"]
    m_per_ft, rho_si = U.M_PER_FT, U.KG_M3_PER_SLUG_FT3
    sin, cos, make = math.sin, math.cos, tuple.__new__

    def read(wind_down_fps: float) -> Sensed:
        theta, phi = g_theta(), g_phi()
        # air-relative body velocity: subtract the NED wind seen in body axes
        ua = g_u() + wind_down_fps * sin(theta)
        va = g_v() - wind_down_fps * sin(phi) * cos(theta)
        wa = g_w() - wind_down_fps * cos(phi) * cos(theta)
        vt_fps = math.sqrt(ua * ua + va * va + wa * wa)
        vt = vt_fps * m_per_ft
        flow = FlowState(math.atan2(wa, ua), g_q(), vt, 0.5 * g_rho() * rho_si * vt * vt)
        return make(Sensed, (
            flow, theta, phi, g_psi(), math.asin(va / vt_fps) if vt_fps > 0.0 else 0.0,
            g_p(), g_r(), g_nz(), g_h() * m_per_ft, g_lat(), g_lon(), g_vn() * m_per_ft,
            g_ve() * m_per_ft, g_vd() * m_per_ft, g_elevator(), g_throttle()))

    return read


def configure_airframe(airframe: Airframe, dt_s: float, modal_hooks: bool = True) -> None:
    """Set ``airframe`` up for a run at the step ``dt_s`` [s]: no modal loads left in its
    external reactions (``modal_hooks``: the aircraft has them), the run's integrators, and
    the step — before a trim, so that JSBSim's multistep integrators and the propeller start
    from a history at the step they will run with."""
    if modal_hooks:
        airframe.set_external_reactions()
    for name, value in INTEGRATORS.items():
        airframe[name] = value
    airframe.set_dt(dt_s)


class CoupledStep(FullSpanSteps):
    """One aircraft (JSBSim airframe + modal wing) advanced one step at a time.

    Args:
        airframe: the JSBSim airframe (configured here; trimmed unless ``trim`` is given).
        wing: the elastic wing model (modes, derivatives); None only for ``native``.
        model: ``rigid`` (no modal loads), ``coupled`` (dynamic modal states), ``qsd``
            (quasi-static deformation) or ``native`` (the wing is in the aircraft's XML).
        speed_m_s: trim true airspeed [m/s]; altitude_m: trim altitude [m above sea level].
        dt_s: the co-simulation (JSBSim) step [s].
        trim: the airframe was just trimmed to this (skip the trim).
        before_trim: called with the configured airframe before the trim (e.g. to disengage
            an autopilot).
        trim_mode: ``rigid`` (the paper's reading: JSBSim's trim of the airframe, the wing
            at its static deformation with no loads of its own) or ``elastic`` (the static
            aeroelastic equilibrium: the wing's static deflection η₀ and its loads carried
            by JSBSim's trim; Δη is measured from η₀; needs the WingBuild;
            ``docs/decisions.md``, "Elastic trim").
        compiled: run the per-step numerics as the compiled kernel
            (:mod:`bioflex_jsb.simulation.step_kernel`); False: the readable Python step, the
            reference the kernel is tested against. The native model has no wing step.
        aero: the wing's strips, ``quasi-steady`` (the paper's, default) or ``unsteady``
            (:class:`~bioflex_jsb.simulation.unsteady_wing.UnsteadyModalWing`: Jones lag
            states, apparent mass, Küssner gust; the coupled model from the rigid trim only;
            ``wing`` then a :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild`; its
            compiled step: :mod:`bioflex_jsb.simulation.unsteady_kernel`). ``wing`` may be a
            WingBuild for either (its ``model`` is used).
        sensors: the aircraft's IMUs and airspeed probes
            (:class:`~bioflex_jsb.simulation.sensors.SensorSet`, the wing's modes in it):
            each row then also holds their channels at t_k (``imu_<name>_…``,
            ``airspeed_<name>_m_s``; :class:`~bioflex_jsb.simulation.sensors.SensorRows`
            from JSBSim's forces, rates and their rates of the snapshot and η_{k−1}, η_k,
            η_{k+1}); None: no sensor channels (and no cost).
        controller: a controller in the loop (:mod:`bioflex_jsb.simulation.controller`: a
            Python object or a LinearController), or None. Every step it reads the row of
            t_k (its signals, the sensor channels among them), its commands are logged in
            the row (channels ``ctrl_<command>``) and written to JSBSim before its step
            (:meth:`_attach_controller`).
        over_autopilot: the airframe's own autopilot writes the elevator command inside
            JSBSim's step (the SITL aircraft): the controller's commands are added to the
            autopilot's (:mod:`bioflex_jsb.runtime.control_surfaces`, "Over an autopilot").
        span: ``half`` (default: the half wing's symmetric modes, as the paper's) or
            ``full``: both halves, the antisymmetric modes beside the symmetric ones driven by
            the roll rate, JSBSim's ailerons and a gust roll rate, their rolling moment to
            JSBSim's modal-roll (:mod:`bioflex_jsb.simulation.full_span`; needs the wing's
            build; with ``aero="unsteady"`` the antisymmetric modes' own unsteady strips,
            :mod:`bioflex_jsb.simulation.unsteady_full_span`); the rows gain the channels of
            :func:`~bioflex_jsb.simulation.full_span.lateral_channel_units`.
        aileron: the wing's aileron (a
            :class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface`, the
            definition's ``[aileron]``) for ``span="full"``; None: no aileron load on the
            modes (the roll rate still drives them).

    After :meth:`advance`, ``k`` is the number of steps flown and ``stopped`` says why the
    run left its valid range (None while it is in range).
    """

    def __init__(self, airframe: Airframe, wing: ElasticWingModel | WingBuild | None, model: str,
                 speed_m_s: float, altitude_m: float = 0.0, dt_s: float = DEFAULT_DT_S,
                 trim: TrimResult | None = None,
                 before_trim: Callable[[Airframe], None] | None = None,
                 compiled: bool = True, aero: str = "quasi-steady",
                 trim_mode: str = "rigid", sensors: SensorSet | None = None,
                 controller=None, over_autopilot: bool = False, span: str = "half",
                 aileron=None) -> None:
        build, wing = _step_options(wing, model, aero, trim_mode, trim)
        check_span(span, build, model, aero)
        native = model == "native"
        self.native, self.model, self.aero, self.trim_mode = native, model, aero, trim_mode
        self.speed_m_s = float(speed_m_s)
        self.compiled = bool(compiled) and not native  # the native wing has no step of ours
        # the aircraft's own data (S, c̄, derivatives at this speed): its wing model's, or for a
        # native wing given alone its aircraft definition's
        data = (_native_airframe_data(airframe) if wing is None else wing.airframe
                ).at_speed(speed_m_s)
        self.airframe_data = data
        # C_L0 of the linear model's level flight, W/(Q S) at sea level, as the LTI model
        # takes it; a glide's W cos γ/(Q S) differs by 1 − cos γ (γ −2.3°: 0.08 %)
        cl_trim = level_flight_condition(self.speed_m_s, airframe=data).cl_trim
        self.alpha_peak_rad = alpha_peak_rad(data.aero)
        controller = self._controller_outputs(controller, sensors, build, aileron)
        # the JSBSim side: the airframe configured and trimmed, its readers and writers
        nodes = self._take_airframe(airframe, dt_s, before_trim, trim, build, speed_m_s,
                                    altitude_m, cl_trim)
        # the wing, its sensors, the controller, the compiled step
        self._make_wing(model, aero, build, wing)
        self.units = channel_units(self.n_modes)
        self.lateral = self._make_lateral(span, aileron, build, model)
        # the names of the range check's modal coordinates (None: the half wing's, all
        # symmetric), made once rather than at every Python step
        self._mode_labels = (None if self.lateral is None
                             else mode_labels(self.n_modes, len(self.lateral.eta)))
        self._sensors = self._sensor_rows(sensors)
        if self._sensors is not None:
            self.units.update(sensors.units)
        self.names = tuple(self.units)
        self._eta_names, self._etadot_names = eta_names(self.n_modes)
        if controller is not None:
            self._attach_controller(controller, over_autopilot)
        self._row = row_getter(self.names)
        if self.compiled:
            self._setup_kernel(nodes)
            if self.lateral is not None:
                self._setup_full_span_kernel()
        if controller is not None:
            self._map_commands()
        if self.compiled and self.flaperon is not None:  # its loads after the controller
            from bioflex_jsb.runtime.flaperon_step import compiled_flaperon_control

            self._control_step = compiled_flaperon_control(self, self._control_step)
        self._stall_steps = 0  # steps flown beyond the lift peak (Python step)
        self.k = 0
        self.stopped: str | None = None
        self.sensed: Sensed | None = None  # the snapshot of the last step's start
        self.w_g_m_s = 0.0

    def _controller_outputs(self, controller, sensors, build, aileron):
        """The controller checked before the airframe is touched (None without one), and the
        step's attributes its outputs decide (a flaperon: runtime/flaperon_step.py)."""
        self._build, self._aileron = build, aileron  # a controller's flaperon's strips
        self.flaperon = None  # a controller's flaperon (runtime/flaperon_step.py)
        self._kin_get = None  # the readers of _kinematics, bound at its first call
        self.control = None  # the controller in the loop (_attach_controller)
        self._control_step = None
        self._control_fast = None
        if controller is None:
            return None
        if sensors is not None and len(sensors) and self.native:
            # the sensors' row of t_k needs η_{k+1}, which the native wing reaches only inside
            # JSBSim's step, after the controller has written its commands
            raise InputError("a controller in the loop and sensor stations ([sensors]) on the "
                             "native wing: its modes step inside JSBSim, after the "
                             "controller; fly the coupled, qsd or rigid model")
        from bioflex_jsb.simulation.controller import check_controller

        return check_controller(controller)

    def _take_airframe(self, airframe: Airframe, dt_s: float, before_trim, trim,
                       build, speed_m_s: float, altitude_m: float, cl_trim: float) -> dict:
        """The JSBSim side of the step, all of it before the wing: ``airframe`` configured
        (:func:`configure_airframe`) and trimmed (unless ``trim`` is given), the snapshot's
        property nodes (returned, by :data:`PROPERTIES` key), the readers and writers the
        step binds, the trim reference the wing linearises about, and the native wing's
        published state."""
        if not self.native:  # one aircraft, before it is touched
            _check_pair(airframe, self.airframe_data)
        self.airframe = airframe
        configure_airframe(airframe, dt_s, modal_hooks=not self.native)
        if before_trim is not None:
            before_trim(airframe)
        elastic = self.trim_mode == "elastic"
        if elastic or trim is None:
            trim = airframe.trim(speed_m_s, altitude_m, wing=build if elastic else None)
        if not self.native:  # the Python wing's loads go into the external reactions
            self._write_reactions = airframe.external_reaction_writer()
            self._set_reactions = airframe.external_reaction_setters()
        # the wing's static state of the elastic trim; None flying from the rigid trim
        self.elastic_trim = trim.elastic if elastic else None
        self.trim = trim
        self.dt_s = airframe.dt_s
        nodes = {k: airframe.property_node(v) for k, v in PROPERTIES.items()
                 if not (k == "throttle" and airframe.glider)}
        if airframe.glider:  # no engine, no throttle property: the throttle channel is 0
            nodes["throttle"] = _NO_THROTTLE
        self.alpha_range_rad = airframe.alpha_table_range_rad
        self._set_wind = airframe.property_node(WIND_DOWN).set_double_value
        if self.native:
            self._bind_native_wing(airframe)
        self.get = MappingProxyType({k: n.get_double_value for k, n in nodes.items()})
        self._read = state_reader(self.get)
        self._agl_m = self.get["agl"]
        # the reference dynamic pressure is JSBSim's own at trim (same density as the run)
        rho0 = self.get["rho"]() * U.KG_M3_PER_SLUG_FT3
        self.reference = TrimReference(trim.alpha_rad, 0.5 * rho0 * speed_m_s**2, cl_trim)
        return nodes

    def _bind_native_wing(self, airframe: Airframe) -> None:
        """The native wing's modal state and loads: JSBSim's properties (its readers)."""
        self.n_modes = _native_mode_count(airframe)
        get_node = airframe.property_node
        self._native_eta = [get_node(f"{NATIVE_PREFIX}/eta{i + 1}").get_double_value
                            for i in range(self.n_modes)]
        self._native_etadot = [get_node(f"{NATIVE_PREFIX}/eta{i + 1}-dot").get_double_value
                               for i in range(self.n_modes)]
        self._native_loads = [get_node(p).get_double_value for p in NATIVE_LOADS]

    def _make_wing(self, model: str, aero: str, build, wing) -> None:
        """The wing of the step (``self.wing``, ``self.n_modes``): none for the native wing
        (its modes are JSBSim's), the unsteady strips or the quasi-steady modal wing, about
        the trim reference of the JSBSim side."""
        if model == "native":
            self.wing = None
            return
        if aero == "unsteady":
            # imported here: the unsteady strips pull in scipy's integrators and optimisers,
            # ~15 MB a quasi-steady run does not need
            from bioflex_jsb.simulation.unsteady_wing import UnsteadyModalWing

            self.wing = UnsteadyModalWing.from_build(build, self.reference, dt_s=self.dt_s,
                                                     aero=self.airframe_data.aero)
        else:
            static = None if self.elastic_trim is None else self.elastic_trim.eta_rad
            self.wing = ModalWing(wing, self.reference, model=model, dt_s=self.dt_s,
                                  static_eta=static, aero=self.airframe_data.aero)
        self.n_modes = wing.n_modes

    # -- the sensors ------------------------------------------------------------------------
    def _sensor_rows(self, sensors: SensorSet | None) -> SensorRows | None:
        """The rows' sensor channels (None without sensors)."""
        if sensors is None or not len(sensors):
            return None
        if sensors.n_modes not in (0, self.n_modes):
            raise InputError(f"the sensors carry {sensors.n_modes} modes, the wing flies "
                             f"{self.n_modes}")
        if self.lateral is not None:  # both halves: the antisymmetric modes' columns too
            wing_a = self.antisymmetric_wing
            sensors = sensors.with_antisymmetric(wing_a.modes, wing_a.root_slope)
        return SensorRows(sensors, self.dt_s, rate_state=self.model_rate_state,
                          lateral=self.lateral)

    @property
    def sensor_set(self) -> SensorSet | None:
        """The sensors the rows read (both halves: with the antisymmetric modes' columns
        after the symmetric ones); None without sensors."""
        return None if self._sensors is None else self._sensors.set

    def rigid_kinematics(self, wind_down_fps: float) -> np.ndarray:
        """The rigid body's kinematics now, as the sensor channels take them
        (:meth:`_kinematics`; a reused array): for a driver that reads a sensor at the
        state a step reached (the ArduPilot backend)."""
        return self._kinematics(wind_down_fps)

    @property
    def model_rate_state(self) -> bool:
        """Whether the wing's η̇ is a state (not the quasi-static wing's, which is 0)."""
        return getattr(self.wing, "model", "native") != "qsd"

    def _kinematics(self, wind_down_fps: float) -> np.ndarray:
        """The rigid body's :data:`~bioflex_jsb.simulation.sensors.KINEMATICS` now (SI,
        body axes; a reused array): the specific force at the CG (JSBSim's total forces
        over its mass, as the ArduPilot backend's IMU), the rates and their rates, the CG's
        velocity against the air with the wind ``wind_down_fps`` [ft/s, down]
        (FGAuxiliary's, as :func:`state_reader`)."""
        if self._kin_get is None:
            node = self.airframe.property_node
            self._kin_get = tuple(node(p).get_double_value for p in (
                JP.FORCES_FBX_TOTAL_LBS, JP.FORCES_FBY_TOTAL_LBS, JP.FORCES_FBZ_TOTAL_LBS,
                JP.INERTIA_MASS_SLUGS, JP.ACCELERATIONS_PDOT_RAD_SEC2,
                JP.ACCELERATIONS_QDOT_RAD_SEC2, JP.ACCELERATIONS_RDOT_RAD_SEC2))
            self._kin = np.zeros(len(SENSOR_KINEMATICS))
        g = self.get
        fx, fy, fz, mass, pd, qd, rd = (f() for f in self._kin_get)
        theta, phi = g["theta"](), g["phi"]()
        m_per_ft = U.M_PER_FT
        k = m_per_ft / mass
        ua = g["u"]() + wind_down_fps * math.sin(theta)
        va = g["v"]() - wind_down_fps * math.sin(phi) * math.cos(theta)
        wa = g["w"]() - wind_down_fps * math.cos(phi) * math.cos(theta)
        kin = self._kin
        kin[:] = (fx * k, fy * k, fz * k, g["p"](), g["q"](), g["r"](), pd, qd, rd,
                  ua * m_per_ft, va * m_per_ft, wa * m_per_ft)
        return kin

    # -- the controller ---------------------------------------------------------------------
    def _attach_controller(self, controller, over_autopilot: bool = False) -> None:
        """Put ``controller`` in the loop: its command channels join the row, it is bound to
        the row's channels with every channel's trim value (the row the step would log at
        the trim in calm air) and its commands go to JSBSim through the writers of
        :mod:`bioflex_jsb.runtime.control_surfaces` (the JSBSim boundary)."""
        from bioflex_jsb.runtime.control_surfaces import commands_for
        from bioflex_jsb.simulation.controller import (
            COMMAND_CHANNELS,
            CONTROL_OUTPUTS,
            ControlLoop,
        )

        if "flaperon" in controller.outputs:  # runtime/flaperon_step.py
            from bioflex_jsb.runtime.flaperon_step import flaperon_for

            self.flaperon = flaperon_for(self, self._build, self._aileron)
            self.units["flaperon_rad"] = "rad"
        for o in controller.outputs:
            self.units[COMMAND_CHANNELS[o]] = CONTROL_OUTPUTS[o]
        self.names = tuple(self.units)
        zeros = np.zeros(self.n_modes)
        trim = self._row_dict(self._read(0.0), 0.0, WingLoads(0.0, 0.0, 0.0), zeros, zeros)
        trim.update({COMMAND_CHANNELS[o]: 0.0 for o in controller.outputs})
        if self._sensors is not None:  # their true reading at the trim, the wing at rest
            trim.update(self._sensors.set.clean(self._kinematics(0.0), zeros, zeros, zeros))
        loop = ControlLoop(controller, self.names, self.dt_s, trim, compiled=self.compiled)
        aileron = None
        if "aileron" in controller.outputs:  # JSBSim's aileron: both halves only
            from bioflex_jsb.runtime.aileron_input import controller_aileron

            aileron = controller_aileron(self.airframe, self.lateral is not None,
                                         over_autopilot)
        commands = commands_for(self.airframe, loop.outputs, over_autopilot,
                                None if self.flaperon is None else self.flaperon.command(),
                                aileron)
        self._commands = commands  # their maps go into the compiled update last
        binding = loop.binding
        step = loop.step
        if binding is not None:
            values = binding.values

            def control(table: np.ndarray, k: int) -> None:
                step(table, k)
                for c, value in zip(commands, values(), strict=True):
                    c.write_value(value)
        else:
            def control(table: np.ndarray, k: int) -> None:
                for c, delta in zip(commands, step(table, k), strict=True):
                    c.write(delta)

        self.control = loop
        self._control_step = control
        self._scratch_py = np.zeros((1, len(self.names)))  # the Python step's row

    def _map_commands(self) -> None:
        """The compiled controller's update maps its commands to the surfaces' JSBSim
        values (each command's offset, scale and limits) and returns the first; one command
        with one setter flies the fast path (:meth:`_bind_fast_step`: the update's machine
        code, then the setter), unless it is a flaperon (its loads follow the controller:
        runtime/flaperon_step.py)."""
        binding, commands = self.control.binding, self._commands
        if binding is None:
            return
        for i, c in enumerate(commands):
            binding.set_map(i, c.offset, c.angle, c.down, c.up)
        if (len(commands) == 1 and len(commands[0].setters) == 1
                and commands[0].adds == (0.0,) and self.flaperon is None):
            self._control_fast = (binding, commands[0].setters[0])

    # -- the wing ---------------------------------------------------------------------------
    @property
    def eta(self) -> np.ndarray:
        """Modal coordinates Δη now [rad]."""
        if self.native:
            return np.array([g() for g in self._native_eta])
        return self.wing.eta

    @property
    def eta_dot(self) -> np.ndarray:
        """Modal rates Δη̇ now [rad/s]."""
        if self.native:
            return np.array([g() for g in self._native_etadot])
        return self.wing.eta_dot

    def set_model(self, model: str) -> None:
        """Switch the Python wing between ``rigid``, ``coupled`` and ``qsd`` mid-run; a wing
        that becomes coupled starts undeformed."""
        if self.native or model not in WING_MODELS:
            raise InputError(f"cannot switch a {self.model} wing to {model!r}")
        if self.aero == "unsteady" and model != self.model:
            raise InputError(f"cannot switch the unsteady coupled wing to {model!r}")
        if model != self.wing.model:
            self.wing.model = model
            self.wing.eta = np.zeros(self.n_modes)
            self.wing.eta_dot = np.zeros(self.n_modes)
            self.model = model
            if self._sensors is not None:
                self._sensors.rate_state = self.model_rate_state
            if self.compiled:
                self._views["model"][0] = K.MODEL_CODES[model]
                self.wing.prepare_arrays()
                self._fast = None  # rebind: the wing's state array was replaced
            if self.lateral is not None:  # the antisymmetric wing switches with it
                self._switch_lateral(model)

    def prepare(self, w_g_m_s: float = 0.0) -> None:
        """Compute the wing's step matrices for the flow now (the first step would do it),
        for real-time loops: the first paced step then costs what the others do."""
        self._set_wind(-w_g_m_s * U.FT_PER_M)
        if not self.native:
            self.wing.prepare(self._read(-w_g_m_s * U.FT_PER_M).flow)
            if self.compiled and self.wing._key is not None:
                self._load_reference()
        if self.lateral is not None:
            self._prepare_lateral(w_g_m_s)

    def sense(self, w_g_m_s: float) -> Sensed:
        """Write the vertical gust ``w_g_m_s`` [m/s, up] to JSBSim's wind and read the
        airframe's snapshot with the flow the wing sees then."""
        wind_down_fps = -w_g_m_s * U.FT_PER_M
        self._set_wind(wind_down_fps)
        return self._read(wind_down_fps)

    # -- the step ---------------------------------------------------------------------------
    def advance(self, w_g_m_s: float, p_g_rad_s: float = 0.0) -> tuple[float, ...]:
        """Fly step k with the gust ``w_g_m_s`` [m/s, up] at t_k (module docstring); the row
        of t_k (values in :attr:`names` order). Sets :attr:`stopped` when out of range.
        ``p_g_rad_s``: the gust roll rate [rad/s] the full-span wing's strips see
        (:mod:`bioflex_jsb.aeroelasticity.antisymmetric_strips`); a half wing takes 0 only."""
        if self.compiled:
            self.advance_into(w_g_m_s, self._scratch, 0, p_g_rad_s)
            return tuple(self._scratch[0].tolist())
        t = self.k * self.dt_s
        state = self.sense(w_g_m_s)
        flow = state.flow
        sensors = self._sensors
        if sensors is not None:  # the rigid body and the wing at t_k, before the step
            kin = self._kinematics(-w_g_m_s * U.FT_PER_M).copy()
            sensors.before(self.eta, self.eta_dot)
        if self.native:
            eta, eta_dot = self.eta, self.eta_dot
            lift_lbf, drag_lbf, moment_lbf_ft = (g() for g in self._native_loads)
            loads = WingLoads(lift_lbf * U.N_PER_LBF, drag_lbf * U.N_PER_LBF,
                              moment_lbf_ft * U.N_M_PER_LBF_FT)
            if self.control is not None:
                values = self._controlled_row(state, w_g_m_s, loads, eta, eta_dot)
            self.airframe.step()
            new_eta = self.eta
        else:
            mw = self.wing
            eta, eta_dot = mw.eta, mw.eta_dot
            if self.aero == "unsteady":  # the lag states need the gust apart from α
                mw.step(flow, w_g_m_s)
                loads = mw.loads(flow, w_g_m_s)
            else:
                mw.step(flow)  # η_k → η_{k+1} over [t_k, t_k+1] with the flow of t_k held
                loads = mw.loads(flow)
            alpha = flow.alpha_rad
            ca, sa = math.cos(alpha), math.sin(alpha)
            self._write_reactions(loads.lift_n * ca + loads.drag_n * sa,
                                  loads.drag_n * ca - loads.lift_n * sa,
                                  loads.pitch_moment_n_m)
            if self.lateral is not None:  # the antisymmetric wing (FullSpanSteps)
                self._lateral_python_step(state, eta, p_g_rad_s)
            if self.control is not None:
                if sensors is not None:  # the row of t_k with η_{k+1}, before the controller
                    sensed = sensors.row(kin, mw.eta, t)
                values = self._controlled_row(state, w_g_m_s, loads, eta, eta_dot,
                                              sensed if sensors is not None else None)
                if self.flaperon is not None:
                    from bioflex_jsb.runtime.flaperon_step import apply_flaperon

                    values = apply_flaperon(self, flow, loads, values)
            self.airframe.step()
            new_eta = mw.eta
            if self.lateral is not None:  # both wings' η against the limit
                new_eta = np.concatenate([new_eta, self.lateral.eta])
        if self.control is None:
            row = self._row_dict(state, w_g_m_s, loads, eta, eta_dot)
            if sensors is not None:
                sym_eta = new_eta[:len(eta)]  # the symmetric modes (the sensors' wing)
                row.update(zip(sensors.channels, sensors.row(kin, sym_eta, t).tolist(),
                               strict=True))
            values = self._row(row)
        self.sensed, self.w_g_m_s = state, w_g_m_s
        self.k += 1
        alpha = flow.alpha_rad
        self._stall_steps += alpha > self.alpha_peak_rad
        self.stopped = out_of_range(self.names, values, t, alpha, new_eta,
                                    self._agl_m() * U.M_PER_FT, self.alpha_range_rad,
                                    self._mode_labels)
        return values

    def _controlled_row(self, s: Sensed, w_g: float, loads: WingLoads, eta, eta_dot,
                        sensed: np.ndarray | None = None) -> tuple[float, ...]:
        """The row of the Python step with a controller: built before JSBSim's step (with
        the sensor channels ``sensed`` of t_k, :attr:`channels` order), the controller run
        on it (its commands into the row and into JSBSim)."""
        row = self._row_dict(s, w_g, loads, eta, eta_dot)
        if sensed is not None:
            row.update(zip(self._sensors.channels, sensed.tolist(), strict=True))
        row.update({c: 0.0 for c in self.control.command_names})
        scratch = self._scratch_py
        scratch[0] = self._row(row)
        self._control_step(scratch, 0)
        return tuple(scratch[0].tolist())

    def _row_dict(self, s: Sensed, w_g: float, loads: WingLoads, eta, eta_dot) -> dict:
        """The row of one step by channel name: the snapshot ``s`` at t_k, the gust then,
        the wing loads applied over the step and the modal state η_k, η̇_k."""
        f, trim = s.flow, self.trim
        row = {
            "u": f.airspeed_m_s - self.speed_m_s, "alpha": f.alpha_rad - trim.alpha_rad,
            "q": f.q_rad_s, "theta": s.theta_rad - trim.theta_rad, "n_z": s.n_z, "w_g": w_g,
            "airspeed_m_s": f.airspeed_m_s, "altitude_m": s.altitude_m,
            "lift_n": loads.lift_n, "drag_n": loads.drag_n,
            "pitch_moment_n_m": loads.pitch_moment_n_m,
            "latitude_rad": s.latitude_rad, "longitude_rad": s.longitude_rad,
            "phi_rad": s.phi_rad, "theta_rad": s.theta_rad, "psi_rad": s.psi_rad,
            "p_rad_s": s.p_rad_s, "r_rad_s": s.r_rad_s, "elevator_rad": s.elevator_rad,
            "throttle": s.throttle, "alpha_rad": f.alpha_rad, "beta_rad": s.beta_rad,
            "v_north_m_s": s.v_north_m_s, "v_east_m_s": s.v_east_m_s,
            "v_down_m_s": s.v_down_m_s,
        }
        for i in range(self.n_modes):
            row[self._eta_names[i]] = float(eta[i])
            row[self._etadot_names[i]] = float(eta_dot[i])
        if self.lateral is not None:
            row.update(self._lateral_row)
        if self.flaperon is not None:
            row["flaperon_rad"] = self.flaperon.applied_rad
        return row

    @property
    def stall_steps(self) -> int:
        """Steps flown with α beyond the lift peak."""
        if self.compiled:
            return int(self._views["stall_steps"][0])
        return self._stall_steps

    # -- the compiled step ------------------------------------------------------------------
    def _setup_kernel(self, nodes) -> None:
        """Bind what the kernel needs once: the property readers in its order, the writers
        of the reactions, the wing's arrays packed into one parameter array, and the table
        column of each of its slots (by channel name). The unsteady wing has a kernel of
        its own (:mod:`bioflex_jsb.simulation.unsteady_kernel`) with the same arguments."""
        mw, mm = self.wing, self.wing.matrices
        self._getters = tuple(nodes[k].get_double_value for k in K.READ_KEYS)
        if self.aero == "unsteady":
            from bioflex_jsb.simulation import unsteady_kernel as UK

            self._kernel = UK.unsteady_kernel
            K.say_if_compiling(self._kernel, "unsteady wing's step")
            self._params, v = UK.new_params(self.n_modes, mw.state.size)
            v["dt"][0] = mw.dt_s
            v["k_induced2"][0] = mw._k2
        else:
            self._kernel = K.step_kernel
            K.say_if_compiling(self._kernel, "coupled step")
            lay = K.layout(self.n_modes)
            self._params = np.zeros(sum(size for _, size in lay.values()))
            v = {name: self._params[o:o + size] for name, (o, size) in lay.items()}
            v["k_aero"][:] = np.ravel(mm.k_aero)
            v["omega2"][:] = np.asarray(mm.omega, dtype=float) ** 2
            v["forcing"][:] = np.ravel(mm.forcing_columns())
            v["static_load"][:] = mw._static_load
            v["model"][0] = K.MODEL_CODES[mw.model]
            mw.prepare_arrays()
            if self.flaperon is not None:  # its block (runtime/flaperon_step.py)
                from bioflex_jsb.runtime.flaperon_step import pack_flaperon

                pack_flaperon(self, v)
        self._views = v
        lo, hi = self.alpha_range_rad
        ref = self.airframe_data.reference
        v["consts"][:] = (U.M_PER_FT, U.KG_M3_PER_SLUG_FT3, ref.area_m2,
                          ref.mean_chord_m, U.LBF_PER_N, U.LBF_FT_PER_N_M,
                          ETA_LIMIT_RAD, lo, hi, self.alpha_peak_rad)
        v["trim"][:] = (self.trim.alpha_rad, self.trim.theta_rad,
                        self.reference.dynamic_pressure_pa, self.speed_m_s)
        v["key"][:] = np.nan  # no reference yet: the first step computes it
        v["load_eta"][:] = np.ravel(mm.load_eta)
        v["load_etadot"][:] = np.ravel(mm.load_etadot)
        v["refresh_rel"][0] = mw.refresh_rel
        self._reactions, self._out_flow = v["reactions"], v["out_flow"]
        slots = K.KERNEL_SLOTS + self._eta_names + self._etadot_names
        self._cols = np.array([self.names.index(s) for s in slots], dtype=np.int64)
        self._scratch = np.zeros((1, len(self.names)))
        self._fast = None
        if mw._key is not None:
            self._load_reference()

    def _load_reference(self) -> None:
        """Copy the wing's reference step (after a refresh) into the parameter array."""
        mw, v = self.wing, self._views
        if self.aero == "unsteady":
            from bioflex_jsb.simulation.unsteady_kernel import load_reference

            load_reference(v, mw._phi, mw._psi_b, mw._load_poly, mw._key)
            return
        v["stack"][:] = np.ravel(mw._stack)
        v["input_cols"][:] = np.ravel(mw._input_cols)
        if mw._flap_cols is not None:  # a flaperon's step column, renewed with the others
            v["flap_cols"][:] = mw._flap_cols
        v["key"][:] = mw._key

    def advance_into(self, w_g_m_s: float, table: np.ndarray, k: int,
                     p_g_rad_s: float = 0.0) -> str | None:
        """Fly step k as :meth:`advance` does, writing its row into ``table[k]`` (a run's
        table, channel order); returns :attr:`stopped`."""
        if p_g_rad_s and self.lateral is None:
            raise InputError("a gust roll rate needs both wing halves (span='full')")
        if not self.compiled:
            table[k] = self.advance(w_g_m_s, p_g_rad_s)
            return self.stopped
        if self._fast is None:
            self._fast = self._bind_sensing()
        if p_g_rad_s:
            return self._fast(w_g_m_s, table, k, p_g_rad_s)
        return self._fast(w_g_m_s, table, k)

    def stepper(self):
        """``step(w_g_m_s, table, k) -> stopped``: :meth:`advance_into` bound once, for a
        driver's loop."""
        if not self.compiled:
            return self.advance_into
        if self._fast is None:
            self._fast = self._bind_sensing()
        return self._fast

    def _bind_sensing(self):
        """The compiled step (:meth:`_bind_fast_step`) with the sensor channels of the row
        (:meth:`_sensor_rows`): the rigid body and the wing read before the step, the
        channels written after it; with a controller, written after the wing's step (η_{k+1}
        known) and before the controller, which reads them (the row of t_k: "Timing" in
        :mod:`bioflex_jsb.simulation.controller`). Without sensors the step itself (a run
        without them pays nothing)."""
        sensors = self._sensors
        if sensors is None:
            return self._bind_fast_step()
        # x: updated in place by the kernel (both halves: the full-span kernel's state, the
        # two wings' states views into it)
        x, parts = self.wing._x, None
        if self.lateral is not None:
            x, parts = self._x_full, (self.wing._x, self.lateral._x)
        dt = self.dt_s
        cols = np.array([self.names.index(c) for c in sensors.channels], dtype=np.int64)
        ft_per_m = U.FT_PER_M
        hold, write = sensors.compiled(x, cols, U.M_PER_FT, parts)
        (g_fx, g_fy, g_fz, g_mass, g_pd, g_qd, g_rd, g_u, g_v, g_w, g_theta, g_phi, g_p, g_q,
         g_r) = self._kinematics_readers()
        if self._control_step is not None:
            w_col = self.names.index("w_g")

            def sense(table: np.ndarray, k: int) -> None:
                # JSBSim has not stepped: its forces and rates are still those of x_k
                write((g_fx(), g_fy(), g_fz(), g_mass(), g_pd(), g_qd(), g_rd(), g_u(), g_v(),
                       g_w(), g_theta(), g_phi(), g_p(), g_q(), g_r()),
                      -table[k, w_col] * ft_per_m, table, k, self.k * dt)

            fast = self._bind_fast_step(sense)

            def fast_before(w_g_m_s: float, table: np.ndarray, k: int, *p_g) -> str | None:
                hold()
                return fast(w_g_m_s, table, k, *p_g)

            return fast_before
        fast = self._bind_fast_step()

        def fast_sensing(w_g_m_s: float, table: np.ndarray, k: int, *p_g) -> str | None:
            reads = (g_fx(), g_fy(), g_fz(), g_mass(), g_pd(), g_qd(), g_rd(), g_u(), g_v(),
                     g_w(), g_theta(), g_phi(), g_p(), g_q(), g_r())  # x_k, before the step
            hold()
            t_s = self.k * dt
            stopped = fast(w_g_m_s, table, k, *p_g)  # p_g: a full-span step's gust roll rate
            write(reads, -w_g_m_s * ft_per_m, table, k, t_s)
            return stopped

        return fast_sensing

    def _kinematics_readers(self) -> tuple:
        """The property readers of :data:`~bioflex_jsb.simulation.sensors.KINEMATICS_READS`,
        in that order (the compiled sensor row's; :meth:`_kinematics` the readable one)."""
        node = self.airframe.property_node
        g = self.get
        forces = tuple(node(p).get_double_value for p in (
            JP.FORCES_FBX_TOTAL_LBS, JP.FORCES_FBY_TOTAL_LBS, JP.FORCES_FBZ_TOTAL_LBS,
            JP.INERTIA_MASS_SLUGS, JP.ACCELERATIONS_PDOT_RAD_SEC2,
            JP.ACCELERATIONS_QDOT_RAD_SEC2, JP.ACCELERATIONS_RDOT_RAD_SEC2))
        return forces + tuple(g[key] for key in ("u", "v", "w", "theta", "phi", "p", "q", "r"))

    def _bind_fast_step(self, before_control=None):
        """The compiled path of :meth:`advance_into` as a closure over everything it uses,
        bound once (each attribute lookup saved is ~40 ns of a ~10 µs step);
        ``before_control`` ``(table, k)``: called before the controller, after the wing's
        step (the sensor channels it reads: :meth:`_bind_sensing`)."""
        if self.lateral is not None:  # both halves: the full-span kernel (FullSpanSteps)
            return self._bind_full_span_step(before_control)
        params, cols = self._params, self._cols
        x = self.wing._x  # updated in place by the kernel
        # the snapshot's readers as locals, called in one tuple literal: the cheapest way
        # from Python into the kernel (a list into the array costs 0.5 µs more per step)
        (g_u, g_v, g_w, g_q, g_p, g_r, g_theta, g_phi, g_psi, g_rho, g_nz, g_h, g_agl, g_lat,
         g_lon, g_vn, g_ve, g_vd, g_elevator, g_throttle) = self._getters
        kernel, needs_refresh, ok = self._kernel, K.NEEDS_REFRESH, K.OK
        # the kernel's machine code without numba's type dispatch (0.67 µs a step,
        # K.direct_entry) for a table it accepts, checked once per table; else the dispatcher
        entry, accepts = K.direct_entry(kernel, params, x, cols)
        checked, call = None, kernel
        set_wind, jsbsim_step, agl = self._set_wind, self.airframe.step_function(), self._agl_m
        set_lift, set_drag, set_pitch = self._set_reactions
        reactions, out_flow = self._reactions, self._out_flow
        ft_per_m, alpha_range = U.FT_PER_M, self.alpha_range_rad
        control = self._control_step  # None without a controller
        # a compiled controller of one command: its machine code for the tables the step
        # kernel's entry accepts (the same table type), then the command's setter
        fast_control = self._control_fast
        if fast_control is not None:
            binding, set_command = fast_control
            c_params, c_entry = binding.params, binding.entry
        c_call = None
        # the snapshot's height above ground is the one read after the last JSBSim step (the
        # same state: the wind written before the snapshot does not move the aircraft), not
        # read again: no kernel uses it (one property read a step, 0.03-0.1 µs)
        agl_ft = agl()

        def fast(w_g_m_s: float, table: np.ndarray, k: int) -> str | None:
            nonlocal checked, call, c_call, agl_ft
            if table is not checked:
                checked, call = table, (entry if accepts(table) else kernel)
                if fast_control is not None:
                    c_call = c_entry if call is entry else linear_step
            wind_down_fps = -w_g_m_s * ft_per_m
            set_wind(wind_down_fps)
            reads = (g_u(), g_v(), g_w(), g_q(), g_p(), g_r(), g_theta(), g_phi(), g_psi(),
                     g_rho(), g_nz(), g_h(), agl_ft, g_lat(), g_lon(), g_vn(), g_ve(), g_vd(),
                     g_elevator(), g_throttle())
            status = call(reads, params, x, cols, table, k, wind_down_fps, w_g_m_s)
            if status == needs_refresh:
                self._renew_reference()
                status = call(reads, params, x, cols, table, k, wind_down_fps, w_g_m_s)
            # as floats in one call: three numpy scalars (reactions[i]) cost 50 ns more
            lift_lbf, drag_lbf, pitch_lbf_ft = reactions.tolist()
            set_lift(lift_lbf)
            set_drag(drag_lbf)
            set_pitch(pitch_lbf_ft)
            if before_control is not None:
                before_control(table, k)
            if c_call is not None:  # its commands from row k, before JSBSim's step
                set_command(c_call(table, k, c_params))
            elif control is not None:
                control(table, k)
            jsbsim_step()
            step_k = self.k  # steps flown (``k`` is the table row)
            self.k = step_k + 1
            agl_ft = agl()
            if status != ok or agl_ft <= 0.0:
                self.stopped = out_of_range(self.names, table[k].tolist(), step_k * self.dt_s,
                                            out_flow[0], self.wing.eta, agl_ft * U.M_PER_FT,
                                            alpha_range)
                return self.stopped
            return None

        return fast

    def _renew_reference(self) -> None:
        """The flow moved beyond the wing's reference: renew it (off the hot path)."""
        if self.lateral is None or self.wing.model == "coupled":
            self.wing._reference(self._out_flow[2], self._out_flow[3])
            self._load_reference()
        if self.lateral is not None:
            self._renew_lateral(self._out_flow[2], self._out_flow[3])

    def release(self) -> None:
        """Leave no modal loads behind in the airframe for its next user."""
        if not self.native:
            self.airframe.set_external_reactions()


def _step_options(wing, model: str, aero: str, trim_mode: str, trim) -> tuple:
    """(the wing's build or None, its ElasticWingModel or None) of a step's options, each
    combination it cannot fly refused in one line (InputError): the unsteady strips are the
    coupled wing's and need its build (its strips), from the rigid trim; the elastic trim
    needs the build of a coupled or qsd wing and is made here; the native model has its wing
    in the aircraft's XML. A run's configuration gives each model options that pass
    (simulation/run_config.py RunConfig.settings_for)."""
    if trim_mode not in TRIM_MODES:
        raise InputError(f"unknown trim {trim_mode!r}; accepted: {', '.join(TRIM_MODES)}")
    if trim_mode == "elastic" and (not isinstance(wing, WingBuild)
                                   or model not in ("coupled", "qsd") or trim is not None):
        raise InputError("the elastic trim needs the wing's build (its modes) and the "
                         f"coupled or qsd wing, trimmed here (got {model!r})")
    if aero not in AERO_MODELS:
        raise InputError(f"unknown aerodynamics {aero!r}; accepted: {', '.join(AERO_MODELS)}")
    if model not in STEP_MODELS:
        raise InputError(f"unknown wing model {model!r}; accepted: {', '.join(STEP_MODELS)}")
    if aero == "unsteady":
        if model != "coupled":
            raise InputError(f"aero='unsteady' is for the coupled wing, not {model!r} (the "
                             "rigid, qsd and native wings are quasi-steady)")
        if not isinstance(wing, WingBuild):
            raise InputError("aero='unsteady' needs the wing's build (its strips), not only "
                             "its ElasticWingModel")
        if trim_mode == "elastic":
            raise InputError("aero='unsteady' flies from the rigid trim (its lag states are "
                             "linearised about it); accepted with it: trim_mode='rigid'")
    build = wing if isinstance(wing, WingBuild) else None
    model_ = build.model if build is not None else wing
    if model_ is None and model != "native":
        raise InputError(f"the {model} model needs a wing")
    return build, model_


def _check_pair(airframe: Airframe, data) -> None:
    """The JSBSim airframe and the wing's aircraft are one aircraft: a definition's JSBSim
    aircraft (``airframe.definition_name``, runtime/aircraft_files.py) with that
    definition's :class:`AirframeData`, any other (the generated prototype's family) with
    the data named as the generated aircraft (``generators.airframe.AIRCRAFT_NAME``); else
    InputError, one line (a wing's loads are in its aircraft's S, c̄)."""
    mine = airframe.definition_name or airframe_xml.AIRCRAFT_NAME
    if data.name != mine:
        raise InputError(f"the wing is built for aircraft {data.name!r}, the JSBSim airframe "
                         f"is {airframe.definition_name or airframe.aircraft!r}: fly a wing on "
                         "its own aircraft's airframe (runtime/jsbsim_aircraft.py airframe_for)")


def _native_airframe_data(airframe: Airframe):
    """The :class:`AirframeData` of a native aircraft flown without its wing: the aircraft
    definition of its name (the one it was exported from: ``bioflex_<variant>``,
    ``sgs_elastic`` …), completed from its JSBSim model as ``--aircraft`` is; InputError,
    one line, for a native aircraft of no shipped definition (give its wing then)."""
    # imported here: the definitions' loader and the identification behind it add ~0.9 s
    # to this module's import, which only a native run without its wing needs
    from bioflex_jsb.definition.aircraft import load_aircraft
    from bioflex_jsb.runtime.jsbsim_aircraft import complete

    name = airframe.aircraft
    try:
        return complete(load_aircraft(name)).airframe_data()
    except InputError as exc:
        raise InputError(f"the native aircraft {name!r} takes its data (S, c̄, derivatives) "
                         f"from the aircraft definition of its name, which cannot be used "
                         f"({exc}); give its wing (wing=)") from None


class _ZeroNode:
    """A property node that reads 0: the throttle of an aircraft without an engine."""

    @staticmethod
    def get_double_value() -> float:
        return 0.0


_NO_THROTTLE = _ZeroNode()


def _native_mode_count(airframe: Airframe) -> int:
    """How many modes the native aircraft publishes (``bioflex/modal/eta<i>``)."""
    n = 0
    while True:
        try:
            airframe.property_node(f"{NATIVE_PREFIX}/eta{n + 1}")
        except KeyError:
            return n
        n += 1
