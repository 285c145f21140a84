"""The Python API of bioflex-jsb: the same runs the ``bioflex-jsb`` command makes, as data.

The CLI is one client of these functions (README, "Python API"). Everything is SI; results
are data objects with named channels and units (``TimeHistory``) or named signals
(``StateSpace``); plots and logs are separate (:mod:`bioflex_jsb.sinks`).

>>> from bioflex_jsb import api
>>> wing = api.load_wing("optimised")
>>> runs = api.fly_gust(wing, speed_m_s=15.0, gust="sharp:3", models=("rigid", "coupled"))
>>> runs["coupled"]["q"]               # pitch rate [rad/s] at runs["coupled"].time_s [s]
>>> runs["coupled"].describe()["alpha"]  # unit, perturbation or absolute, frame and sign
>>> api.read_log("gust.mcap")         # a log's runs, every channel, as fly_gust returns them
>>> api.plot_runs(runs, "gust.png")   # the figure of `bioflex-jsb gust`
>>> api.modes(wing, 15.0)["short_period"].damping  # [-]; a ModeSet is a sequence of modes
>>> api.modes(wing, [10.0, 15.0, 20.0])  # one ModeSet per speed [m/s]
>>> lti = api.linear_model(wing, speed_m_s=15.0, model="coupled")
>>> unsteady = api.fly_gust(wing, gust="sharp:0.3", aero="unsteady")  # Jones/Küssner strips
>>> api.flutter(wing).flutter_speed_m_s  # [m/s]
>>> api.flutter("goland", clamped=True).as_dict()  # a clamped wing from its definition
>>> aircraft = api.load_aircraft("bioflex_optimised")  # an aircraft definition (TOML)
>>> api.fly_gust(aircraft, models=("coupled",))  # every analysis takes it
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.aeroelasticity.free_aircraft import (
    AERO_MODELS,
    FREE_DEFAULT_AERO,
    free_flutter,
    free_scan_step_m_s,
    unsteady_mode_sets,
    unsteady_state_space,
    with_damping,
)
from bioflex_jsb.definition import Definition
from bioflex_jsb.definition import load_definition as _load_definition
from bioflex_jsb.definition.aircraft import Aircraft, default_aircraft
from bioflex_jsb.definition.aircraft import load_aircraft as _load_aircraft
from bioflex_jsb.definition.clamped import free_speed_range_m_s as _free_speed_range_m_s
from bioflex_jsb.definition.flying import SHIPPED_AIRCRAFT, flight_refusal, flight_speeds
from bioflex_jsb.definition.loader import (
    DAMPING_RANGE,
    DENSITY_RANGE_KG_M3,
    LIFT_SLOPES,
    SPEED_LIMIT_M_S,
)
from bioflex_jsb.drivers.compare import (
    Comparison,
    check_comparable,
    check_gust_excites,
    compare_run,
)
from bioflex_jsb.drivers.gust import RunConfig, StepRecorder, run_gust
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.eigen import FlutterResult, ModeSet, find_flutter, modes_at
from bioflex_jsb.flight_dynamics.flutter_engine import METHODS
from bioflex_jsb.flight_dynamics.lti import MODELS, StateSpace, build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import (
    DEFAULT_MASS_BASIS,
    WingBuild,
    build_wing,
    resolve_variant,
    with_lateral_aero,
)
from bioflex_jsb.inputs import Choice, Flag, Interval, Real, argument
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.runtime.jsbsim_aircraft import complete as complete_aircraft
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.results import GustMetrics, TimeHistory, gust_metrics
from bioflex_jsb.simulation.run import check_run_length
from bioflex_jsb.simulation.run_checks import check_recorders

__all__ = [
    "DEFAULT_DT_S", "Aircraft", "Comparison", "FlutterResult", "GustMetrics", "StateSpace",
    "TimeHistory", "WingBuild", "compare", "flutter", "fly_fig21", "fly_gust", "lateral_model",
    "lateral_modes", "linear_model", "load_aircraft", "load_definition", "load_wing", "metrics",
    "modes", "plot_runs", "read_log", "section_loads", "to_python_control", "load_controller",
    "linear_controller", "predict_alleviation", "design_alleviation", "closed_loop_flutter",
    "design_flutter_suppression",
]


RUN_MODELS = MODELS  # the models fly_gust flies, the LTI models (native: fly_fig21)

def load_wing(name_or_file: str = "optimised", mass_basis: str = DEFAULT_MASS_BASIS
              ) -> WingBuild:
    """The elastic wing ``name_or_file``: a named variant (``original``, ``optimised``,
    ``inertial-forward``, ``elastic-forward``, ``inertial-backward``, ``elastic-backward``)
    or a variant file (``docs/wing_variants.md``): modes, strips and the Table B1/B2
    model. ``mass_basis``: ``consistent`` or ``paper`` (``docs/decisions.md``).

    A shorthand: ``load_wing("optimised")`` is the wing of
    ``load_aircraft("bioflex_optimised")``; a shipped aircraft name (``bioflex_<variant>``)
    is accepted too."""
    if isinstance(name_or_file, Path):  # a variant file as a Path, as load_aircraft takes
        name_or_file = str(name_or_file)
    if not isinstance(name_or_file, str):
        raise InputError(f"a wing is a variant name or a variant file's path, got "
                         f"{name_or_file!r}")
    if name_or_file in SHIPPED_AIRCRAFT:
        return _load_aircraft(name_or_file).wing(mass_basis)
    return build_wing(resolve_variant(name_or_file), mass_basis=mass_basis)


def load_aircraft(name_or_file: str = "bioflex_optimised") -> Aircraft:
    """The aircraft definition ``name_or_file`` (docs/aircraft.md): a shipped one by name
    (``bioflex_original``, ``bioflex_optimised``, ``bioflex_inertial-forward``,
    ``bioflex_elastic-forward``, ``bioflex_inertial-backward``,
    ``bioflex_elastic-backward``) or a TOML file with an ``[airframe]``: the JSBSim
    airframe, reference geometry, mass properties, the elastic wing. Every field is checked
    when read (one line naming it). What the file leaves out of its ``[airframe]`` (mass,
    CG, inertia, S, b, c̄, the speeds, the rigid derivatives) is read or identified from its
    JSBSim aircraft, and what it gives is checked against it. Pass the :class:`Aircraft` to
    :func:`fly_gust`, :func:`compare`, :func:`linear_model`, :func:`modes`, :func:`flutter`
    in place of a wing (``aircraft.wing()`` is its :class:`WingBuild`)."""
    return complete_aircraft(_load_aircraft(name_or_file))


def _prototype_airframe():
    """The airframe data of the default aircraft, the prototype (the loader's
    :func:`~bioflex_jsb.definition.aircraft.default_aircraft`): a bare wing's airframe, and
    the object an analysis' airframe is compared with (``is``) to learn whether it is the
    prototype's."""
    return default_aircraft().airframe_data()


def _prototype_cruise_m_s() -> float:
    """The default aircraft's cruise speed [m/s] (the prototype's 15 m/s, Table 1)."""
    return flight_speeds(default_aircraft())[0]


@dataclass(frozen=True)
class _Subject:
    """What an analysis below is given, read once (:meth:`of`): an :class:`Aircraft` (its
    wing, JSBSim airframe, speeds and air) or a bare :class:`WingBuild` (flown on the
    prototype's airframe, at the prototype's speeds), or None (the prototype's rigid
    aircraft, linear analyses only). Every analysis asks it, not the argument's type."""

    aircraft: Aircraft | None
    build: WingBuild | None

    @classmethod
    def of(cls, wing) -> _Subject:
        """``wing`` read: anything else than an Aircraft, a WingBuild or None is refused in
        one line saying what to pass."""
        if isinstance(wing, Aircraft):
            return cls(wing, wing.wing())
        if wing is None or isinstance(wing, WingBuild):
            return cls(None, wing)
        hint = ("; a name or file is loaded first (api.load_wing, api.load_aircraft), and a "
                "clamped wing's definition is analysed with clamped=True"
                if isinstance(wing, str | Path | Definition) else "")
        raise InputError(f"give a wing (a WingBuild) or an Aircraft, not {wing!r}{hint}")

    def flying_build(self) -> WingBuild:
        """The wing of a nonlinear JSBSim run (docs/aircraft.md, "What runs with another
        airframe"): an Aircraft flies on its own JSBSim airframe when
        :func:`~bioflex_jsb.definition.flying.flight_refusal` has no objection (else one
        line); a bare WingBuild only on the prototype's (another airframe's wing needs its
        Aircraft: the JSBSim aircraft is in the definition), never with the prototype's
        numbers."""
        if self.aircraft is not None:
            problem = flight_refusal(self.aircraft)
            if problem:
                raise InputError(problem)
        build = self.build
        if build is None:
            raise InputError("give a wing (a WingBuild: api.load_wing) or an Aircraft "
                             "(api.load_aircraft) to fly, not None")
        if self.aircraft is None and build.model.airframe is not _prototype_airframe():
            raise InputError(f"wing {build.variant.name!r} is built for airframe "
                             f"{build.model.airframe.name!r}: a bare wing flies on the "
                             "prototype's airframe only; pass its Aircraft "
                             "(api.load_aircraft), whose definition names the JSBSim "
                             "aircraft")
        return build

    def flight_speed(self, speed_m_s: float | None) -> float:
        """The trim speed [m/s] of a nonlinear run: ``speed_m_s``, within an Aircraft's
        flight speeds, default its cruise speed; the prototype's 15 m/s (Table 1) for a bare
        wing."""
        if self.aircraft is None:
            return _prototype_cruise_m_s() if speed_m_s is None else speed_m_s
        cruise, (lo, hi) = flight_speeds(self.aircraft)
        v = cruise if speed_m_s is None else _real(speed_m_s, "speed_m_s", "m/s")
        if not lo <= v <= hi:
            raise InputError(f"speed {v:g} m/s is outside aircraft {self.aircraft.name!r}'s "
                             f"flight speeds {lo:g}..{hi:g} m/s (airframe.speed_range_m_s)")
        return v

    def jsbsim_airframe(self) -> Airframe:
        """The JSBSim airframe a nonlinear run flies: the Aircraft's own, else the
        prototype's."""
        return Airframe() if self.aircraft is None else airframe_for(self.aircraft)

    def density(self, density_kg_m3: float | None) -> dict:
        """The air density [kg/m^3] of an analysis as keyword arguments: given, else an
        Aircraft definition's [air], else none (the analyses' sea-level default)."""
        if density_kg_m3 is not None:
            return {"density_kg_m3": _check_density(density_kg_m3)}
        if self.aircraft is not None:
            return {"density_kg_m3": float(self.aircraft.definition.air.density_kg_m3)}
        return {}

    def analysis_speed(self, speed_m_s: float | None) -> float:
        """The speed [m/s] of a linear analysis: ``speed_m_s`` when given, else an
        Aircraft's cruise speed (the prototype's 15 m/s on its airframe, Table 1; the
        file's ``airframe.cruise_speed_m_s`` on another), or the prototype's for a bare wing
        built on the prototype's airframe (or None, the rigid prototype); one line when no
        cruise speed is known (a wing of another airframe without its Aircraft, an aircraft
        without the field)."""
        if speed_m_s is not None:
            return _linear_speed(speed_m_s)
        if self.aircraft is not None:
            a = self.aircraft
            cruise = (_prototype_cruise_m_s() if a.flight_problem() is None
                      else a.airframe.cruise_speed_m_s)
            if cruise is None:
                raise InputError(f"aircraft {a.name!r} has no airframe.cruise_speed_m_s: "
                                 "give speed_m_s [m/s]")
            return float(cruise)
        if self.build is None or self.build.model.airframe is _prototype_airframe():
            return _prototype_cruise_m_s()
        raise InputError(f"wing {self.build.variant.name!r} is built for airframe "
                         f"{self.build.model.airframe.name!r}: give speed_m_s [m/s] (or pass "
                         "its Aircraft, whose cruise speed is the default)")


# The lowest speed of a linear analysis [m/s]: its dynamic pressure at sea level is 6 mPa,
# nothing an aircraft flies on; at 1e-300 m/s V² underflows to 0 and the rigid model would
# divide by it (ZeroDivisionError).
LINEAR_SPEED_MIN_M_S = 0.1


def _linear_speed(speed_m_s, name: str = "speed_m_s") -> float:
    """A linear analysis' speed [m/s]: finite, LINEAR_SPEED_MIN_M_S <= V <= SPEED_LIMIT_M_S
    (the strips are incompressible; a speed of 1e5 m/s took 71 s and answered nothing
    physical)."""
    return argument(LINEAR_SPEED, speed_m_s, name)


def _lateral_aero(wing, lateral_aero: str | None):
    """``wing`` (a WingBuild, an Aircraft, None) with its lateral elastic models' loading
    ``lateral_aero`` (``strips`` or ``lattice``: aerodynamics/antisymmetric_loading.py;
    None: the wing's own, ``strips`` unless set); one line for anything else."""
    from bioflex_jsb.aerodynamics.antisymmetric_loading import LATERAL_AERO

    if lateral_aero is None:
        return wing
    _check_choice("lateral aerodynamics", lateral_aero, LATERAL_AERO)
    if isinstance(wing, WingBuild):
        return with_lateral_aero(wing, lateral_aero)
    if isinstance(wing, Aircraft):
        return wing.with_lateral_aero(lateral_aero)
    if lateral_aero == "strips":
        return wing
    raise InputError("lateral_aero='lattice' loads an elastic wing's antisymmetric modes: "
                     f"give a WingBuild or an Aircraft, not {wing!r}")


def fly_gust(wing: WingBuild, speed_m_s: float | None = None, gust: str = "sharp:3",
             models: Iterable[str] | None = None, duration_s: float = 5.0,
             gust_start_s: float = 0.5, altitude_m: float = 0.0, dt_s: float = DEFAULT_DT_S,
             recorders: dict[str, StepRecorder] | None = None,
             aero: str = "quasi-steady", trim: str = "rigid",
             controller=None, span: str = "half", aileron_step_deg: float | None = None,
             aileron_start_s: float = 0.5, lateral_aero: str | None = None
             ) -> dict[str, TimeHistory]:
    """Nonlinear 6-DoF gust runs of the JSBSim airframe with ``wing`` (a WingBuild or an
    Aircraft), one per model of ``models`` (``rigid``, ``coupled``, ``qsd``; None: all
    three, or ``coupled`` alone with ``aero="unsteady"``): trim at ``speed_m_s`` [m/s] and
    ``altitude_m`` [m], then fly ``duration_s`` [s] at the step ``dt_s`` [s] through
    ``gust`` (``sharp:A``, ``1cos:A:L``, ``dryden:SIGMA:SCALE[:SEED]``, ``vonkarman:…``;
    m/s, m) starting at ``gust_start_s`` [s]. ``recorders``: a step recorder (an MCAP log)
    per model. ``aero``: the wing's strips, ``quasi-steady`` (the paper's) or ``unsteady``
    (Jones lag states, apparent mass, Küssner gust:
    :mod:`bioflex_jsb.simulation.unsteady_wing`; the coupled model only, compiled:
    :mod:`bioflex_jsb.simulation.unsteady_kernel`). ``trim``: ``rigid`` (the paper's
    reading) or ``elastic`` (start from the static aeroelastic equilibrium: the wing's
    static deflection and its loads carried by JSBSim's trim; the rigid model is flown from
    the rigid trim). ``speed_m_s`` None: the aircraft's cruise speed (the prototype's 15
    m/s).

    Returns {model: TimeHistory} (``run.describe()``: every channel's unit, whether it is a
    perturbation from the trim or absolute, its frame and sign); a run that left the valid
    range has ``stopped`` set (the reason, the time and the mode) and holds every step up to
    then. Each run carries the wing's section loads at the root, 25, 50 and 75 % semispan as
    channels ``loads_<fs|md>_<quantity>_s<j>`` (:func:`bioflex_jsb.drivers.gust.run_gust`'s
    ``loads``; docs/loads.md), and :func:`metrics` their peaks. An :class:`Aircraft` flies
    on its own JSBSim airframe (an aircraft without an engine in its steady glide;
    docs/aircraft.md).

    ``controller``: a controller in the loop of every run (:func:`load_controller`'s
    sources: a controller file, a shipped controller's name, a LinearController,
    python-control's StateSpace or an object with ``inputs``, ``outputs`` and ``step``;
    :mod:`bioflex_jsb.simulation.controller`): it reads the run's signals every step and
    commands the elevator [rad] and throttle [-] over the trim; each run has its commands
    as channels ``ctrl_<command>`` and ``meta["controller"]``.

    ``span``: ``half`` (the half wing, default) or ``full`` (both halves: the antisymmetric
    modes driven by the roll rate and the ailerons, their rolling moment to JSBSim; the
    aircraft definition's ``[aileron]`` on the strips; channels ``asym_eta<i>``,
    ``tip_twist_port_rad``, ``tip_twist_starboard_rad``, ``modal_roll_n_m``,
    ``aileron_rad``; docs/lateral.md "Both halves in the co-simulation"; with
    ``aero="unsteady"`` the antisymmetric modes on unsteady strips too, "Both halves on
    unsteady strips").
    ``aileron_step_deg``: an aileron step over the trim [deg, JSBSim's (left − right)/2, +
    rolls right, |δa| <= 30] from ``aileron_start_s`` [s] (None: none). ``lateral_aero``
    the antisymmetric strips' loading of ``span="full"``: ``strips`` or ``lattice`` (the
    vortex lattice's antisymmetric loading; docs/lateral.md, "The lattice in the lateral
    elastic model"); None: the wing's own (``strips`` unless set); ``lattice`` with the
    half wing is refused (one line)."""
    return _fly_gust(_lateral_aero(wing, lateral_aero), speed_m_s, gust, models, duration_s,
                     gust_start_s, altitude_m, dt_s, recorders, aero, trim, controller,
                     lateral=(span, aileron_step_deg, aileron_start_s))[0]


def _gust_text(gust) -> str:
    """``gust`` if it is a gust text, else one line saying what one is."""
    if not isinstance(gust, str):
        raise InputError(f"gust must be a gust text (sharp:A, 1cos:A:L, ...), got {gust!r}")
    return gust


def _fly_gust(wing, speed_m_s, gust, models, duration_s, gust_start_s, altitude_m, dt_s,
              recorders, aero, trim, controller=None, lateral=("half", None, 0.5)):
    """:func:`fly_gust`'s runs, the JSBSim airframe flown and the wing's build: the run's
    configuration made (and so checked) before the airframe loads."""
    if models is None:
        models = ("rigid", "coupled", "qsd") if aero == "quasi-steady" else ("coupled",)
    subject = _Subject.of(wing)
    build = subject.flying_build()  # what the aircraft cannot fly first: the more basic refusal
    if not isinstance(models, str) and "native" in tuple(models):
        raise InputError(f"unknown model 'native'; give one or more of {', '.join(MODELS)} "
                         "(the native wing is an exported aircraft's: docs/native.md)")
    chord = build.airframe.reference.mean_chord_m  # the shortest gust: one mean chord
    config = RunConfig(subject.flight_speed(speed_m_s), parse_gust(_gust_text(gust), chord),
                       duration_s, gust_start_s, altitude_m, dt_s, models=models, aero=aero,
                       trim=trim)
    check_recorders(recorders, config.models)
    if controller is not None:
        controller = load_controller(controller)
    options = _lateral_options(subject, build, *lateral)
    if "flaperon" in getattr(controller, "outputs", ()) and "aileron" not in options:
        options["aileron"] = _aileron_surface(subject, build)  # the half wing's flaperon
    airframe = subject.jsbsim_airframe()
    out = {}
    for model in map(str, config.models):
        recorder = (recorders or {}).get(model)
        flown = build if config.needs_build(model) or options else build.model
        out[model] = run_gust(airframe, flown, model, config, recorder=recorder, loads=build,
                              controller=controller, **options)
        # which wing flew, as the command's runs say (plot_runs' title, a user's table)
        out[model].meta.update(wing=build.variant.name, mass_basis=build.mass_basis)
        if build.lateral_aero != "strips":  # the default's meta unchanged
            out[model].meta.update(lateral_aero=build.lateral_aero)
    return out, airframe, build, config.speed_m_s


def _lateral_options(subject, build, span: str, aileron_step_deg, aileron_start_s) -> dict:
    """run_gust's ``span``, ``aileron``, ``aileron_input`` of :func:`fly_gust`'s arguments
    ({} for the half wing without an aileron step)."""
    from bioflex_jsb.simulation.full_span import AileronInput

    _check_choice("span", span, ("half", "full"))
    if span == "half" and build.lateral_aero != "strips":
        raise InputError(f"lateral_aero={build.lateral_aero!r} loads the antisymmetric modes "
                         "of both halves: not with span='half' (accepted: span='full')")
    options: dict = {}
    if aileron_step_deg is not None:
        deg = argument(AILERON_STEP, aileron_step_deg, "aileron_step_deg")
        options["aileron_input"] = AileronInput("step", float(np.radians(deg)),
                                                _real(aileron_start_s, "aileron_start_s", "s"))
    if span == "half":
        return options
    return {**options, "span": "full", "aileron": _aileron_surface(subject, build)}


def fly_fig21(model: str = "coupled", duration_s: float = 3.0) -> TimeHistory:
    """The paper's Fig. 21 case (optimised wing, 15 m/s, 3 m/s sharp-edged gust at 0.5 s)
    through ``model``: ``rigid``, ``coupled``, ``qsd``, or ``native`` (the repository's
    native XML wing, ``aircraft/bioflex_optimised``), flown for ``duration_s`` [s]. The
    golden check cases."""
    _check_choice("model", model, (*RUN_MODELS, "native"))
    # 0 s returned an empty run, −1 s a numpy "negative dimensions"
    duration_s = argument(Real("s", positive=True), duration_s, "duration_s")
    check_run_length(duration_s, DEFAULT_DT_S, turbulence=False)
    setup = RunConfig(15.0, parse_gust("sharp:3"), duration_s)
    if model == "native":
        from bioflex_jsb.generators.native_wing import aircraft_name

        return run_gust(Airframe(aircraft=aircraft_name("optimised")), None, "native", setup)
    return run_gust(Airframe(), load_wing("optimised").model, model, setup)


def compare(wing: WingBuild, speed_m_s: float | None = None, gust: str = "sharp:0.3",
            model: str = "coupled", duration_s: float = 5.0, gust_start_s: float = 0.5,
            aero: str = "quasi-steady", trim: str = "rigid",
            recorder: StepRecorder | None = None, controller=None, span: str = "half",
            lateral_aero: str | None = None) -> Comparison:
    """The nonlinear gust run of ``model`` with ``wing`` (as :func:`fly_gust`: ``speed_m_s``
    [m/s], ``gust``, ``duration_s`` [s] from ``gust_start_s`` [s]) and the LTI model of Eq. (4)
    driven by the same gust samples at the same trim (its rigid block JSBSim's own
    linearisation, so the two differ only by the nonlinearity), with the NRMSE [-] and the
    largest difference of u, α, q, θ, η₁ (:class:`Comparison`; ``.plot(path, title)``).
    Small gusts (``sharp:0.3``) agree to a few per cent; a diverged run has no errors (None).
    ``aero``/``trim`` as for :func:`fly_gust` (unsteady: coupled only; elastic: coupled or
    qsd). ``wing`` an :class:`Aircraft`: its own airframe, linearised at its trim (a
    glider's steady glide), ``speed_m_s`` None its cruise speed. ``recorder``: a step
    recorder (an MCAP log) of the nonlinear run.

    ``controller``: a linear controller in the loop of both (:func:`load_controller`'s
    sources but a Python object: the LTI model closes the loop with its state space, at the
    run's step with the run's one step of delay, :mod:`bioflex_jsb.simulation.closed_loop`);
    its commands are compared too (``ctrl_<command>``). The quasi-steady ``coupled``,
    ``qsd`` or ``rigid`` model about the rigid trim.

    ``span="full"``: both wing halves in the run (as :func:`fly_gust`'s) and the lateral
    model of the same wing model beside Eq. (4), driven by the run's gust roll rate, lateral
    gust and aileron (:mod:`bioflex_jsb.drivers.compare_lateral`): β, p, r, φ, ``asym_eta1``
    and ``modal_roll_n_m`` compared too (about the rigid trim; ``aero="unsteady"``: the
    run's antisymmetric modes and the lateral model both on the unsteady strips);
    ``lateral_aero`` as :func:`fly_gust`'s (the lateral model then on the same loading)."""
    wing = _lateral_aero(wing, lateral_aero)
    _check_choice("model", model, MODELS)
    _check_choice("span", span, ("half", "full"))
    check_comparable(model, aero, trim, controller is not None, span)  # before flying
    check_gust_excites(parse_gust(_gust_text(gust)))
    if controller is not None:
        controller = linear_controller(controller)
    runs, airframe, build, speed = _fly_gust(
        wing, speed_m_s, gust, (model,), duration_s, gust_start_s, 0.0, DEFAULT_DT_S,
        {model: recorder} if recorder is not None else None, aero, trim, controller,
        lateral=(span, None, 0.5))
    drift = None
    if airframe.glider:  # the glide's own drift in calm air (drivers/compare.py)
        drift = _fly_gust(wing, speed, "none", (model,), duration_s, gust_start_s, 0.0,
                          DEFAULT_DT_S, None, aero, trim, controller,
                          lateral=(span, None, 0.5))[0][model]
    aileron = None if span == "half" else _lateral_options(
        _Subject.of(wing), build, span, None, 0.5)["aileron"]
    return compare_run(build, runs[model], model, speed, aero, trim, airframe=airframe,
                       drift=drift, controller=controller, aileron=aileron)


def metrics(run: TimeHistory, gust_start_s: float | None = None) -> GustMetrics:
    """Peaks of the response of ``run`` (a :class:`TimeHistory`) to a gust starting at
    ``gust_start_s`` [s] (None: the run's own, ``run.meta["gust_start_s"]``, else 0.5 s;
    units in the field names): :class:`GustMetrics` (RMS values for turbulence)."""
    if not isinstance(run, TimeHistory):
        raise InputError(f"run: a TimeHistory (fly_gust's), not {type(run).__name__}")
    if gust_start_s is None:
        gust_start_s = run.meta.get("gust_start_s", 0.5)
    gust_start_s = _real(gust_start_s, "gust_start_s", "s")
    return gust_metrics(run, gust_start_s)


def read_log(path: str | Path, *, start_s: float | None = None,
             end_s: float | None = None) -> dict[str, TimeHistory]:
    """The runs of the MCAP log ``path`` (``bioflex-jsb gust``'s, a sweep case's, a log of
    :func:`fly_gust`'s ``recorders``) as :func:`fly_gust` returned them: {model:
    TimeHistory} with every channel under the same names and units, the section loads and
    their layout (so :func:`metrics` and :func:`section_loads` take them), ``stopped`` from
    the log's stop event; an LTI prediction (``compare``'s log) as ``"<model>_lti"``.
    Latitude and longitude are logged at 60 Hz and interpolated to every step
    (``meta["resampled"]``); times are the log's, to the nanosecond. ``start_s`` and
    ``end_s`` [s]: the steps logged at start_s <= t < end_s only (a read takes at most
    :data:`~bioflex_jsb.sinks.mcap.READ_MAX_STEPS` steps). One line (InputError) for a file
    that is not a finished log of ours."""
    from bioflex_jsb.sinks.mcap import histories

    runs, _ = histories(path, loads=True, start_s=start_s, end_s=end_s)
    return {r.model + ("_lti" if "label" in r.meta else ""): r for r in runs}


def plot_runs(runs, path: str | Path, title: str | None = None, force: bool = False) -> Path:
    """The gust figure of ``runs`` (a :class:`TimeHistory`, a sequence of them or the dict
    :func:`fly_gust` returns) written to ``path`` (a figure suffix: ``.png``, ``.svg``,
    ``.pdf`` …; an existing file only if it is a plot of ours, or with ``force``): Δu, Δα,
    q, Δθ, n_z, the gust w_g and η₁ against time [s], the command's ``gust.png``; its path.
    ``title`` None: the first run's wing, speed and gust, as ``bioflex-jsb gust`` titles
    it.

    >>> api.plot_runs(api.fly_gust(wing, gust="sharp:3"), "gust.png", "sharp:3 at 15 m/s")
    """
    from bioflex_jsb.sinks.plotting import gust_figure

    return gust_figure(runs, path, title, force)


def linear_model(wing: WingBuild | None, speed_m_s: float | None = None,
                 model: str = "coupled", aero: str = "quasi-steady",
                 trim: str = "rigid", flaperon: bool = False) -> StateSpace:
    """The paper's LTI model (Eq. 4) of ``wing`` at ``speed_m_s`` [m/s] (None: the
    aircraft's cruise speed, the prototype's 15 m/s): ``model`` ``rigid`` (A_RR),
    ``coupled`` or ``qsd`` (Eq. 9-10), with named states, inputs, outputs and their units.
    ``aero`` ``quasi-steady`` (the paper's strips) or ``unsteady``; ``trim`` ``rigid`` or
    ``elastic``.

    Quasi-steady about the rigid trim: the model ``bioflex-jsb export`` writes
    (:func:`~bioflex_jsb.flight_dynamics.lti.build_state_space` with ``controls``): inputs
    w_g [m/s] (gust, up), elevator [rad] (+ trailing edge down) and throttle [-]; outputs
    the states (QSD: and its quasi-static η), n_z [-] (load-factor perturbation, up) and,
    for an elastic wing model, tip_twist [rad] (leading edge up). The rigid block is the
    analytic Table B2 one (``notes["rigid_block"]``; ``compare`` uses JSBSim's).

    ``aero="unsteady"`` (``coupled`` only): Eq. (4) on unsteady strips with the Küssner gust
    (:func:`bioflex_jsb.aeroelasticity.free_aircraft.unsteady_state_space`, ``gust=True``),
    the model the co-simulation's unsteady wing integrates: states u, α, q, θ, η, η̇ and
    per strip k lag1[k], lag2[k], kussner1[k], kussner2[k] [m/s].

    ``trim="elastic"`` (``coupled``, ``qsd``): linearised about the elastic trim
    (:func:`bioflex_jsb.flight_dynamics.elastic_trim.linearise_about_elastic_trim`: the
    modes' force per unit airspeed from the deflected wing); ``notes["eta_static_rad"]``
    holds the static deflection η₀ the states are measured from. The unsteady and the
    elastic-trim models take the gust w_g alone and output their states.

    ``flaperon`` (the quasi-steady coupled model about the rigid trim): the input
    ``flaperon`` [rad] after the others, the wing's ``[aileron]`` deflected together, both
    trailing edges down positive (:mod:`bioflex_jsb.aeroelasticity.flaperon`: its lift and
    moment on the rigid rows, its strip loads on the modes; ``notes["flaperon"]`` its
    derivatives), as a controller's ``flaperon`` command flies it.

    ``wing`` an :class:`Aircraft` (or its wing): the model is its own (S, c̄, mass, I_yy, the
    derivatives of its file, its planform; the air of its [air]); ``None`` the prototype's
    rigid aircraft."""
    subject = _Subject.of(wing)
    air = subject.density(None)
    speed_m_s = subject.analysis_speed(speed_m_s)
    wing = subject.build
    _check_choice("trim", trim, ("rigid", "elastic"))
    if trim == "elastic":
        if aero != "quasi-steady" or wing is None:
            raise InputError("trim='elastic' linearises the quasi-steady coupled or qsd model "
                             "of an elastic wing")
        from bioflex_jsb.flight_dynamics.elastic_trim import (
            elastic_trim,
            linearise_about_elastic_trim,
        )

        return linearise_about_elastic_trim(model, elastic_trim(wing, speed_m_s, **air),
                                            wing.model)
    _check_choice("aerodynamics", aero, AERO_MODELS)
    _check_choice("model", model, MODELS)
    if aero == "unsteady":
        if model != "coupled" or wing is None:
            raise InputError("aero='unsteady' is the coupled model of an elastic wing")
        return unsteady_state_space(wing, speed_m_s, gust=True, **air)
    airframe = _prototype_airframe() if wing is None else wing.model.airframe
    condition = level_flight_condition(speed_m_s, airframe=airframe, **air)
    ss = build_state_space(model, condition, None if wing is None else wing.model,
                           controls=True)
    if not flaperon:
        return ss
    if wing is None or model != "coupled":
        raise InputError("flaperon=True is the quasi-steady coupled model of an elastic wing")
    from bioflex_jsb.aeroelasticity.flaperon import flaperon_derivatives, with_flaperon

    deriv = flaperon_derivatives(wing, _aileron_surface(subject, wing))
    return with_flaperon(ss, condition, deriv, wing.model.generalised_masses_kg_m2)


def _aileron_surface(subject, build):
    """The aircraft's aileron (what the full-span strips carry, a flaperon deflects and the
    lateral model loads the modes with): the aircraft definition's ``[aileron]``, else the
    prototype variant's shipped definition's (None: none)."""
    from bioflex_jsb.simulation.full_span import prototype_aileron

    if subject.aircraft is not None:
        return subject.aircraft.definition.aileron
    return prototype_aileron(build.variant.name)



def _lateral_point(wing, speed_m_s: float | None):
    """(the subject, the identified lateral point) of ``wing`` (an Aircraft, a bare
    prototype wing or None): its JSBSim airframe trimmed at the speed [m/s]."""
    from bioflex_jsb.runtime.identification import identify_lateral
    from bioflex_jsb.runtime.jsbsim_aircraft import isa_altitude_m

    subject = _Subject.of(wing)
    if subject.aircraft is not None:  # its speeds and mass as the JSBSim model says them
        subject = _Subject(complete_aircraft(subject.aircraft), subject.build)
        problem = flight_refusal(subject.aircraft)
        if problem:
            raise InputError(problem)
        reference = subject.aircraft.airframe_data().reference
        altitude = isa_altitude_m(subject.aircraft.definition.air.density_kg_m3)
    elif subject.build is None or subject.build.model.airframe is _prototype_airframe():
        reference, altitude = _prototype_airframe().reference, 0.0
    else:
        raise InputError(f"wing {subject.build.variant.name!r} is built for airframe "
                         f"{subject.build.model.airframe.name!r}: pass its Aircraft "
                         "(api.load_aircraft), whose definition names the JSBSim aircraft")
    speed = subject.flight_speed(speed_m_s)
    airframe = subject.jsbsim_airframe()
    name = subject.aircraft.name if subject.aircraft is not None else "bioflex"
    source = (f"derivatives identified from the JSBSim airframe of {name!r} at its trim "
              f"at {speed:g} m/s, {altitude:.0f} m (not the paper's: it has no lateral "
              "data)")
    return subject, identify_lateral(airframe, speed, reference, altitude, source)


def _lateral(wing, speed_m_s, model: str, aero: str = "quasi-steady",
             lateral_aero: str | None = None, actuated: bool = False, flap_terms: bool = True):
    """(the model, its rigid model, the antisymmetric wing or None) of :func:`lateral_model`;
    ``aero`` ``unsteady``: (the unsteady model, its labelled modes, None). ``actuated``: the
    model behind the aircraft's ``[aileron.actuator]`` when it has one (the modes are the
    model's without it: the actuator's roots are its own); ``flap_terms`` the aileron's
    unsteady loads on the unsteady strips (with an actuator)."""
    from bioflex_jsb.aeroelasticity import antisymmetric as anti
    from bioflex_jsb.aeroelasticity.actuated_aileron import with_actuator
    from bioflex_jsb.aeroelasticity.antisymmetric_strips import lateral_model_with_aileron
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        LATERAL_MODELS,
        antisymmetric_wing,
        build_lateral_elastic,
    )

    _check_choice("model", model, LATERAL_MODELS)
    _check_choice("aerodynamics", aero, anti.LATERAL_AERO)
    wing = _lateral_aero(wing, lateral_aero)
    if aero == "unsteady" and model != "coupled":
        raise InputError(f"aero='unsteady' is the coupled lateral model's (the wing's strips "
                         f"on its antisymmetric modes), not the {model} one")
    subject, point = _lateral_point(wing, speed_m_s)
    actuator = (subject.aircraft.definition.aileron_actuator
                if actuated and subject.aircraft is not None else None)

    def behind(ss):
        return ss if actuator is None else with_actuator(ss, actuator)

    rigid = build_lateral_elastic("rigid", point.trim, point.aero, None)
    if model == "rigid":
        return behind(rigid), rigid, None
    if subject.build is None:
        raise InputError(f"the lateral {model} model needs an elastic wing: pass a wing or "
                         "an Aircraft, not None")
    wing_a = antisymmetric_wing(subject.build, point.trim.ixx_kg_m2)
    # the model compare --span full drives (drivers/compare_lateral.py): the aircraft's
    # aileron on the strips, its generalised force on the modes; the unsteady model is
    # that coupled model with the unsteady strips' increments
    surface = _aileron_surface(subject, subject.build)
    if aero == "unsteady":
        strips = anti.aircraft_strips(subject.build, wing_a, point.trim.ixx_kg_m2)
        return (*anti.unsteady_lateral_mode_set(point.trim, point.aero, wing_a, strips,
                                                surface, subject.build.aero.chord_m,
                                                actuator=actuator, flap_terms=flap_terms),
                None)
    ss, _ = lateral_model_with_aileron(model, point.trim, point.aero, wing_a, surface,
                                       subject.build.aero.chord_m)
    return behind(ss), rigid, wing_a


def lateral_model(wing=None, speed_m_s: float | None = None, model: str = "rigid",
                  aero: str = "quasi-steady", lateral_aero: str | None = None,
                  flap_terms: bool = True) -> StateSpace:
    """The linear lateral-directional model at ``speed_m_s`` [m/s] (None: the aircraft's
    cruise speed, the prototype's 15 m/s), about its JSBSim trim there (docs/lateral.md):
    states beta [rad] (sideslip, air from the right), p, r [rad/s] (roll right, yaw right,
    body axes), phi [rad] (bank, right wing down); inputs v_g [m/s] (lateral gust, to
    starboard), aileron [rad] (+ roll right) and rudder [rad] (+ trailing edge left, nose
    left); outputs the states and n_y [-] (lateral load factor, to starboard). Its rigid
    derivatives are identified from the aircraft's JSBSim model at the trim
    (``notes["derivatives"]``, body axes; the prototype's are those of its generated JSBSim
    airframe, estimates: the paper has no lateral data).

    ``model``: ``rigid`` (default), ``coupled`` (with the wing's antisymmetric modes:
    states eta1.. [rad] and eta1_dot.. [rad/s] after phi, quasi-steady strips;
    :mod:`bioflex_jsb.flight_dynamics.lateral_elastic`) or ``qsd`` (their static
    deformation residualised; outputs also the quasi-static eta). In both, the aileron
    column carries the aircraft's aileron's generalised force on the modes (its
    ``[aileron]`` on the strips, thin-aerofoil flap lift and moment; qsd: in their static
    balance) beside JSBSim's rigid C_l_delta_a: the model ``compare --span full`` drives
    (:func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`;
    ``notes["aileron_on_modes"]``). ``aero``
    ``quasi-steady`` (default) or ``unsteady`` (coupled only: that coupled model, the
    aileron's quasi-steady load and the yaw rate's and sideslip's terms included, with the
    strips' Jones lag states lag1[k], lag2[k] [m/s] and apparent mass on the modes and the
    roll rate; :mod:`bioflex_jsb.aeroelasticity.antisymmetric`). ``wing`` an
    :class:`Aircraft` (its JSBSim airframe and wing), the prototype's wing or None (the
    prototype, rigid only). ``lateral_aero``: the strips' antisymmetric loading, ``strips``
    (C_lα c of each strip alone) or ``lattice`` (the vortex lattice's antisymmetric loading
    of the whole distribution: docs/lateral.md, "The lattice in the lateral elastic
    model"; quasi-steady only); None: the wing's own (``strips`` unless set). One line
    (InputError) when the aircraft cannot be trimmed at that speed, or its wing has no beam
    (a modal-data file: no antisymmetric modes).

    An aircraft whose definition has an ``[aileron.actuator]`` (docs/lateral.md, "The
    aileron's actuator and unsteady flap") gets, in every model, the states aileron [rad]
    and aileron_dot [rad/s] (appended; outputs too) and the input aileron_cmd [rad] in
    the aileron's place; with ``aero="unsteady"`` the aileron's own unsteady loads
    (Theodorsen's T-functions: circulatory lift through the lags, apparent mass in its rate
    and acceleration) are on the strips, unless ``flap_terms`` is False (the aileron's
    quasi-steady load only, for comparison; no effect without an actuator)."""
    flap_terms = argument(Flag(), flap_terms, "flap_terms")
    return _lateral(wing, speed_m_s, model, aero, lateral_aero, actuated=True,
                    flap_terms=flap_terms)[0]


def lateral_modes(wing=None, speed_m_s: float | Iterable[float] | None = None,
                  model: str = "rigid", aero: str = "quasi-steady",
                  lateral_aero: str | None = None) -> ModeSet | list[ModeSet]:
    """The labelled lateral-directional modes of :func:`lateral_model` of ``wing`` (an
    :class:`Aircraft`, the prototype's wing or None: the prototype) at ``speed_m_s``
    [m/s] (or a list, one per speed of a sequence), ``model`` rigid, coupled or qsd:
    ``roll`` (roll subsidence), ``spiral`` (unstable when its ``re`` > 0), ``dutch_roll``
    and the coupled model's ``antisymmetric_k`` [rad/s]; ``aero`` as
    :func:`lateral_model`'s (unsteady: the quasi-steady model's labels carried over by
    continuation, the lag roots left out), ``lateral_aero`` as :func:`lateral_model`'s."""
    from bioflex_jsb.flight_dynamics.lateral import lateral_mode_set
    from bioflex_jsb.flight_dynamics.lateral_elastic import coupled_mode_set

    if isinstance(speed_m_s, Iterable) and not isinstance(speed_m_s, str | bytes):
        speeds = list(speed_m_s)
        if not speeds:
            raise InputError("speed_m_s: give a speed [m/s] or a non-empty sequence of them")
        return [lateral_modes(wing, v, model, aero, lateral_aero) for v in speeds]
    ss, rigid, wing_a = _lateral(wing, speed_m_s, model, aero, lateral_aero)
    if aero == "unsteady":
        return rigid  # the unsteady model's labelled modes (_lateral)
    if model == "coupled":
        return coupled_mode_set(ss, rigid, wing_a)
    return lateral_mode_set(ss)

def to_python_control(ss: StateSpace):
    """``ss`` (a :class:`StateSpace`, a model file's path or its arrays) as a
    python-control ``StateSpace`` (named signals); needs the ``control`` extra
    (``pip install "bioflex-jsb[control]"``)."""
    from bioflex_jsb.sinks.model_export import to_python_control as convert

    return convert(ss)


def load_definition(name_or_file: str = "goland") -> Definition:
    """The aircraft definition ``name_or_file`` (docs/aircraft.md): a shipped name
    (``goland``) or a TOML file; today a clamped wing (a definition without an airframe).
    Checked when read."""
    return _load_definition(name_or_file)


def _definition(definition, what: str = "clamped=True analyses") -> Definition:
    """A definition, a shipped name or a TOML file as a :class:`Definition` (``what`` begins
    the refusal of anything else)."""
    if isinstance(definition, str | Path):
        return load_definition(str(definition))
    if isinstance(definition, Definition):
        return definition
    # a WingBuild, an Aircraft, None: an AttributeError deep in the model before
    raise InputError(f"{what} a clamped wing's definition (a name such as "
                     f"'goland', a TOML file or api.load_definition's result), not "
                     f"{type(definition).__name__}")


def _clamped(definition, lift_slope: str | None):
    from bioflex_jsb.definition.clamped import clamped_model

    d = _definition(definition)
    if lift_slope is not None:
        _check_choice("lift_slope", lift_slope, LIFT_SLOPES)
    return d, clamped_model(d, lift_slope)


# The API's arguments are checked by bioflex_jsb.inputs' kinds and reported by
# inputs.argument as one line, "<argument>: <what is wrong; what is accepted>".
def _check_choice(what: str, value, accepted) -> None:
    """``value`` one of ``accepted``: "<argument>: unknown <what> 'x'; accepted: …"."""
    name = {"aerodynamics": "aero", "lateral aerodynamics": "lateral_aero"}.get(what, what)
    argument(Choice(tuple(accepted), noun=what), value, name)


def _real(value, name: str, unit: str) -> float:
    """A finite number [unit]: "<name>: must be a finite number in <unit>, got …"."""
    return argument(Real(unit), value, name)


def _speed_range(range_m_s, kind: Interval) -> tuple[float, float]:
    """A (low, high) speed range [m/s] (any sequence of two numbers: a tuple, a list, a
    numpy array) checked by ``kind``: "range_m_s: must be [low, high] m/s with …"."""
    if isinstance(range_m_s, Iterable) and not isinstance(range_m_s, str | bytes | Mapping):
        range_m_s = tuple(range_m_s)
    return argument(kind, range_m_s, "range_m_s")


# A linear analysis' speed [m/s]: LINEAR_SPEED_MIN_M_S..SPEED_LIMIT_M_S (the strips are
# incompressible; a speed of 1e5 m/s took 71 s and answered nothing physical)
LINEAR_SPEED = Real("m/s", LINEAR_SPEED_MIN_M_S, SPEED_LIMIT_M_S,
                    hint=" (the strip aerodynamics are incompressible)")
# A flutter search's speed range [m/s]: above 0, within the definitions' speed limit
SPEED_RANGE = Interval("m/s", 0.0, SPEED_LIMIT_M_S)
# An aileron step [deg]: within the prototype aileron's ±30 deg travel
AILERON_STEP = Real("deg", -30.0, 30.0)


# Air density [kg/m^3] and structural damping ratio ζ [-] of the API's analyses: the
# definition files' ranges (definition/ranges.py, with their reasons)
DENSITY = Real("kg/m^3", *DENSITY_RANGE_KG_M3,
               hint=" (about 33 km altitude to denser than any surface air)")
STRUCTURAL_DAMPING = Real("(fraction of critical damping)", *DAMPING_RANGE)


def _check_density(rho: float) -> float:
    return argument(DENSITY, rho, "density_kg_m3")


def _check_damping(zeta: float | None) -> float | None:
    """A structural damping ratio ζ [-] (None: the wing's own): finite, within the
    definition files' DAMPING_RANGE, 0 <= ζ <= 0.3 (built-up wings measure 0.005-0.05; the
    p-k method failed with an IndexError at 0.95, where modes are overdamped)."""
    if zeta is None:
        return None
    return argument(STRUCTURAL_DAMPING, zeta, "structural_damping")


def modes(wing, speed_m_s: float | Iterable[float] | None = None, model: str = "coupled", *,
          aero: str = "quasi-steady", clamped: bool = False, method: str = "state-space",
          structural_damping: float | None = None) -> ModeSet | list[ModeSet]:
    """Labelled eigenvalues of ``wing`` at ``speed_m_s`` [m/s] (free aircraft, None: its
    cruise speed, the prototype's 15 m/s; clamped: required): a :class:`ModeSet`, or for a
    sequence of speeds (``[10, 15, 20]``) a list of them, one per speed in its order.

    Free aircraft (``wing`` a :class:`WingBuild`): ``model`` rigid, coupled or qsd of the
    paper (short period, phugoid, aeroelastic_i), ``aero="unsteady"`` the coupled model on
    unsteady strips (lag roots left out). Clamped (``clamped=True``, ``wing`` a definition
    or its name/file): the wing's branches tracked from the bottom of its derived range by
    ``method`` (``pk`` or ``state-space``) on ``aero`` strips (lag roots left out).
    ``structural_damping`` ζ [-] replaces the wing's (None: its own).
    An :class:`Aircraft` is analysed with its own airframe, planform and air."""
    _check_choice("aerodynamics", aero, AERO_MODELS)
    structural_damping = _check_damping(structural_damping)
    if isinstance(speed_m_s, Iterable) and not isinstance(speed_m_s, str | bytes):
        speeds = list(speed_m_s)
        if not speeds:
            raise InputError("speed_m_s: give a speed [m/s] or a non-empty sequence of them")
        return [modes(wing, v, model, aero=aero, clamped=clamped, method=method,
                      structural_damping=structural_damping) for v in speeds]
    if clamped:
        if speed_m_s is None:
            raise InputError("a clamped wing's modes need speed_m_s [m/s]")
        speed_m_s = _linear_speed(speed_m_s)
        return _clamped_modes(wing, speed_m_s, aero, method, structural_damping)
    subject = _Subject.of(wing)
    air = subject.density(None)
    speed_m_s = subject.analysis_speed(speed_m_s)
    wing = subject.build
    if aero == "unsteady":
        if model != "coupled":
            raise InputError("aero='unsteady' is the coupled model of an elastic wing")
        return unsteady_mode_sets(wing, [speed_m_s], structural_damping, **air)[0]
    w = wing.model if structural_damping is None else with_damping(wing, structural_damping)
    if model == "rigid":
        return modes_at(model, [speed_m_s], None, airframe=w.airframe, **air)[0]
    return modes_at(model, [speed_m_s], w, **air)[0]


def _clamped_modes(definition, speed_m_s, aero, method, structural_damping) -> ModeSet:
    from bioflex_jsb.aeroelasticity.pk import PkFamily
    from bioflex_jsb.aeroelasticity.state_space import state_space_family
    from bioflex_jsb.definition.clamped import derived_speed_range_m_s, scan_step_m_s
    from bioflex_jsb.flight_dynamics import flutter_engine as engine
    from bioflex_jsb.flight_dynamics.eigen import Mode

    _check_choice("method", method, METHODS)
    d, m = _clamped(definition, None)
    zeta = d.structure.damping_ratio if structural_damping is None else structural_damping
    rho = d.air.density_kg_m3
    kw = dict(density_kg_m3=rho, aero=aero, structural_damping=zeta, name=d.name)
    fam = PkFamily(m, **kw) if method == "pk" else state_space_family(m, **kw)
    lo = min(derived_speed_range_m_s(m, rho)[0], float(speed_m_s))
    step = scan_step_m_s((lo, max(float(speed_m_s), lo + 1.0)))
    grid = np.union1d(np.arange(lo, float(speed_m_s), step), [float(speed_m_s)])
    last = engine.scan(fam, grid).points[-1]
    out = []
    for name in dict.fromkeys(lab for lab, c in zip(fam.labels, fam.considered, strict=True)
                              if c):
        roots = [r for r, lab in zip(last.roots, fam.labels, strict=True) if lab == name]
        r = max(roots, key=lambda z: z.imag)
        out.append(Mode(name, float(r.real), float(abs(r.imag))))
    return ModeSet(float(speed_m_s), f"clamped-{method}-{aero}", tuple(out))


def flutter(wing, range_m_s: tuple[float, float] | None = None, *,
            aero: str | None = None, method: str | None = None, clamped: bool = False,
            structural_damping: float | None = None, density_kg_m3: float | None = None,
            lift_slope: str | None = None, progress=None,
            full_scan: bool = False, symmetry: str = "symmetric") -> FlutterResult:
    """The first instability of ``wing`` in ``range_m_s`` [m/s]: flutter, body-freedom
    flutter or static divergence, its frequency [rad/s], k, modes, mechanism, and whether it
    is already present at the range's lower end (:class:`FlutterResult`, ``.as_dict()``,
    ``.plot(path)`` the V-g / V-f diagram; ``speed_m_s`` is ``None`` when nothing crosses
    and when the system is unstable at and below the lower end, ``present_at_lower_end``).

    Free aircraft (``wing`` a :class:`WingBuild`): Eq. (4) on ``aero`` strips, default
    ``unsteady`` (Jones lag states); ``quasi-steady`` is the paper's model, its single-mode
    torsion instability flagged (``quasi_steady_artefact``, ``caveat``); range default 5-40
    m/s for the prototype, derived from the wing for another aircraft
    (:func:`free_speed_range_m_s`); ``structural_damping`` ζ [-] replaces the wing's.
    Clamped (``clamped=True``; ``wing`` a definition, a shipped name or a TOML file):
    ``aero``, ``method`` (``pk`` or ``state-space``), ``lift_slope``, ζ and
    ``density_kg_m3`` [kg/m^3] default to the definition's; the range to the one derived
    from the wing (:func:`bioflex_jsb.definition.clamped.derived_speed_range_m_s`).
    ``progress`` is called as ``progress(speed, top)`` [m/s] while the scan goes;
    ``full_scan``: scan the whole range (for the diagram).

    ``symmetry``: ``symmetric`` (default: the symmetric modes, Eq. 4), ``antisymmetric``
    (the antisymmetric modes with the roll freedom, the aircraft's I_xx; a clamped wing's
    root held: the same problem as its symmetric one) or ``both`` (the one that goes
    unstable first, ``settings["first_symmetry"]`` saying which and
    ``settings["other_symmetry"]`` the other's result; docs/aeroelasticity.md,
    "Antisymmetric flutter")."""
    from bioflex_jsb.aeroelasticity.antisymmetric import SYMMETRIES

    _check_choice("symmetry", symmetry, SYMMETRIES)
    if symmetry != "symmetric":
        return _flutter_by_symmetry(wing, range_m_s, symmetry, aero=aero, method=method,
                                    clamped=clamped, structural_damping=structural_damping,
                                    density_kg_m3=density_kg_m3, lift_slope=lift_slope,
                                    progress=progress, full_scan=full_scan)
    if range_m_s is not None:
        _speed_range(range_m_s, SPEED_RANGE)
    if density_kg_m3 is not None:
        _check_density(density_kg_m3)
    structural_damping = _check_damping(structural_damping)
    scan = dict(progress=progress, full_scan=bool(full_scan))
    if clamped:
        return _clamped_flutter(wing, range_m_s, aero, method, structural_damping,
                                density_kg_m3, lift_slope, scan)
    subject = _Subject.of(wing)
    air = subject.density(density_kg_m3)
    wing = subject.build
    aero = aero or FREE_DEFAULT_AERO
    _check_choice("aerodynamics", aero, AERO_MODELS)
    if method not in (None, "state-space"):
        raise InputError("the free aircraft's flutter is by state-space eigen-analysis; "
                         "method='pk' is for clamped wings")
    if lift_slope is not None:
        raise InputError("lift_slope is for clamped wings; the free aircraft takes the "
                         "vortex lattice's span loading (Table B1)")
    rng = free_speed_range_m_s(wing, air.get("density_kg_m3")) if range_m_s is None \
        else range_m_s
    step = free_scan_step_m_s(rng)  # 0.1 m/s, or the range in 350 steps
    if aero == "unsteady":
        return free_flutter(wing, aero="unsteady", structural_damping=structural_damping,
                            range_m_s=rng, step_m_s=step, **air, **scan)
    model = wing.model if structural_damping is None else with_damping(wing,
                                                                       structural_damping)
    return find_flutter(model, rng, step, **air, **scan)


def _flutter_by_symmetry(wing, range_m_s, symmetry: str, **kw) -> FlutterResult:
    """:func:`flutter` of the antisymmetric modes, or of both symmetries (the first)."""
    from bioflex_jsb.aeroelasticity import antisymmetric as anti
    from bioflex_jsb.aeroelasticity.free_aircraft import FREE_TOL_M_S
    from bioflex_jsb.flight_dynamics.eigen import SCAN_START_M_S

    sym = flutter(wing, range_m_s, **kw)  # the symmetric search: its checks and defaults
    if kw["clamped"]:
        d, m = _clamped(wing, kw["lift_slope"])
        zeta = d.structure.damping_ratio if kw["structural_damping"] is None \
            else float(kw["structural_damping"])
        if sym.method == "pk":  # the root held: the antisymmetric problem is this one
            res = replace(sym, settings=dict(sym.settings, symmetry="antisymmetric"))
        else:
            from bioflex_jsb.aeroelasticity.state_space import DEFAULT_SPEED_STEP_M_S
            from bioflex_jsb.definition.clamped import scan_step_m_s

            step = min(DEFAULT_SPEED_STEP_M_S, scan_step_m_s(sym.range_m_s))
            res = anti.antisymmetric_flutter(
                anti.clamped_strips(m, zeta, d.name), range_m_s=sym.range_m_s,
                step_m_s=step, density_kg_m3=sym.density_kg_m3, aero=sym.aero,
                structural_damping=zeta, tol_m_s=1e-7,
                divergence_speed_m_s=sym.divergence_speed_m_s,
                divergence_is_instability=True, progress=kw["progress"],
                full_scan=kw["full_scan"])
            res = replace(res, settings=dict(sym.settings, **res.settings))
    else:
        build = _Subject.of(wing).build
        res = anti.aircraft_flutter(
            build, range_m_s=sym.range_m_s, step_m_s=free_scan_step_m_s(sym.range_m_s),
            density_kg_m3=sym.density_kg_m3, aero=sym.aero,
            structural_damping=kw["structural_damping"], tol_m_s=FREE_TOL_M_S,
            start_m_s=SCAN_START_M_S, progress=kw["progress"], full_scan=kw["full_scan"])
    return res if symmetry == "antisymmetric" else anti.first_of(sym, res)


def free_speed_range_m_s(build, density_kg_m3: float | None = None) -> tuple[float, float]:
    """The default speed range [m/s] of a free aircraft's flutter search
    (:func:`bioflex_jsb.definition.clamped.free_speed_range_m_s`): the paper's 5-40 m/s for
    the prototype's airframe; another aircraft's derived from its wing (150 % of the wing's
    static divergence speed in the aircraft, the body held, down to 5 % of that; a fixed
    5-40 m/s told the SGS sailplane "no instability" while it flutters at 59 m/s).
    ``build``: a :class:`WingBuild` or an :class:`Aircraft` (its wing); ``density_kg_m3``
    [kg/m^3]: the air's (None: an Aircraft's [air], else sea level)."""
    subject = _Subject.of(build)
    return _free_speed_range_m_s(subject.build,
                                 subject.density(density_kg_m3).get("density_kg_m3"))


def _clamped_flutter(definition, range_m_s, aero, method, zeta, rho, lift_slope, scan):
    from bioflex_jsb.aeroelasticity import pk, state_space
    from bioflex_jsb.definition.clamped import derived_speed_range_m_s, scan_step_m_s

    d, m = _clamped(definition, lift_slope)
    aero = aero or d.aero.model
    method = method or d.analysis.method
    _check_choice("aerodynamics", aero, AERO_MODELS)
    _check_choice("method", method, METHODS)
    rho = d.air.density_kg_m3 if rho is None else rho
    zeta = d.structure.damping_ratio if zeta is None else float(zeta)
    rng = range_m_s or d.analysis.speed_range_m_s or derived_speed_range_m_s(m, rho)
    solve = pk.pk_flutter if method == "pk" else state_space.state_space_flutter
    step = pk.DEFAULT_SPEED_STEP_M_S if d.analysis.speed_range_m_s or range_m_s else \
        scan_step_m_s(rng)
    res = solve(m, density_kg_m3=rho, aero=aero, structural_damping=zeta,
                speed_range_m_s=tuple(rng), speed_step_m_s=min(step, scan_step_m_s(rng)),
                name=d.name, **scan)
    return replace(res, settings=dict(res.settings, definition=d.path or d.name,
                                      range_derived=range_m_s is None
                                      and d.analysis.speed_range_m_s is None))


def aileron_effectiveness(wing="goland_aileron", range_m_s: tuple[float, float] | None = None,
                          *, aileron=None, density_kg_m3: float | None = None,
                          lift_slope: str | None = None, lateral_aero: str | None = None):
    """Aileron effectiveness and reversal of an elastic wing
    (:class:`bioflex_jsb.aeroelasticity.aileron.AileronResult`: ``.as_dict()``,
    ``.plot(path)``; docs/aeroelasticity.md, "Aileron effectiveness and reversal"): against
    airspeed, the rolling moment per aileron angle elastic over rigid (root held), the
    steady roll rate p b/(2V) per radian of aileron and its ratio to the rigid wing's; the
    reversal speed [m/s] (None: none), the divergence speeds, the rigid C_lδ, C_lp.

    ``wing``: a clamped wing, i.e. a definition (``api.load_definition``'s), a shipped name
    or a TOML file with a beam wing (an aircraft definition's wing is analysed clamped, as
    ``flutter --clamped`` does: the beam's modes on Gauss strips); or an aircraft, i.e. an
    :class:`Aircraft` or a :class:`WingBuild`: the flight model's wing (its flown modes on
    the vortex lattice's strips, the aircraft's rigid C_lδa and C_lp reported beside).
    ``aileron``: the definition's ``[aileron]`` (None; a WingBuild has none), or (start, end,
    hinge): the span range as fractions of the semispan and the hinge line's chord fraction
    (checked as a file's), or a
    :class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface`. ``range_m_s``
    (low, high) [m/s], 0 <= low < high <= 400 (default 0 to 1.5 × the reversal speed);
    ``density_kg_m3`` [kg/m^3] defaults to the definition's (a WingBuild's: sea level);
    ``lift_slope`` (``strip``, ``vlm``: a clamped wing's; an aircraft's is the lattice's)
    to the definition's. ``lateral_aero`` an aircraft's antisymmetric loading: ``strips``
    (each strip's C_lα c) or ``lattice`` (the vortex lattice's antisymmetric loading;
    docs/lateral.md, "The lattice in the lateral elastic model"); None: the wing's own."""
    from bioflex_jsb.aeroelasticity import aileron as A

    if range_m_s is not None:
        range_m_s = _speed_range(range_m_s, Interval("m/s", 0.0, SPEED_LIMIT_M_S,
                                                     from_lo=True))
    if lift_slope is not None:
        _check_choice("lift_slope", lift_slope, LIFT_SLOPES)
    cruise = None
    if isinstance(wing, Aircraft | WingBuild):
        wing = _lateral_aero(wing, lateral_aero)
        strips, rho, name, settings = _aircraft_roll_strips(wing, aileron, density_kg_m3,
                                                            lift_slope)
        if isinstance(wing, Aircraft) or wing.airframe is _prototype_airframe():
            cruise = _Subject.of(wing).flight_speed(None)  # its cruise speed [m/s]
    else:
        if lateral_aero not in (None, "strips"):
            raise InputError("lateral_aero is an aircraft's (its flight model's lattice); a "
                             "clamped wing takes lift_slope ('strip' or 'vlm')")
        strips, rho, name, settings = _clamped_roll_strips(wing, aileron, density_kg_m3,
                                                           lift_slope)
    return A.aileron_effectiveness(strips, density_kg_m3=rho, range_m_s=range_m_s, name=name,
                                   settings=dict(settings, aero=(
                                       "steady strips" if strips.lift_matrix_m is None else
                                       "steady strips, the lattice's antisymmetric loading"),
                                                 range_derived=range_m_s is None),
                                   reference_speed_m_s=cruise)


def _clamped_roll_strips(wing, aileron, density_kg_m3, lift_slope):
    """(RollStrips, ρ, name, settings) of a clamped wing's definition (its beam's modes on
    Gauss strips with edges at the surface's ends)."""
    from bioflex_jsb.aeroelasticity.aileron import clamped_roll_strips
    from bioflex_jsb.definition.clamped import clamped_model

    d = _definition(wing, "aileron_effectiveness analyses an Aircraft, a WingBuild or")
    surface = _surface(d.name, d.aileron, d.semispan_m, aileron)
    rho = d.air.density_kg_m3 if density_kg_m3 is None else _check_density(density_kg_m3)
    model = clamped_model(d, lift_slope, breaks_m=(surface.start_m, surface.end_m))
    return clamped_roll_strips(model, surface), rho, d.name, {
        "definition": d.path or d.name, "clamped": True, "semispan_m": d.semispan_m,
        "lift_slope": model.lift_slope}


def _aircraft_roll_strips(wing, aileron, density_kg_m3, lift_slope):
    """(RollStrips, ρ, name, settings) of an aircraft's flight model of its wing, with the
    aircraft's own rigid C_lδa and C_lp for comparison."""
    from bioflex_jsb.aeroelasticity.aileron import flight_roll_strips

    if lift_slope is not None:
        raise InputError("lift_slope is for clamped wings; an aircraft's wing takes the "
                         "vortex lattice's span loading (its flight model's)")
    subject = _Subject.of(wing)
    own = None if subject.aircraft is None else subject.aircraft.definition.aileron
    build = subject.build
    semispan = float(build.aero.semispan_m)
    surface = _surface(build.variant.name, own, semispan, aileron)
    from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3

    rho = subject.density(density_kg_m3).get("density_kg_m3", SEA_LEVEL_DENSITY_KG_M3)
    rigid = build.airframe.aero
    return flight_roll_strips(build, surface), rho, build.variant.name, {
        "definition": (wing.definition.path or wing.name) if isinstance(wing, Aircraft)
        else build.variant.name, "clamped": False, "semispan_m": semispan,
        "lift_slope": "vlm", "n_flown_modes": build.model.n_modes,
        "e_shift_frac": float(build.e_shift_frac),
        **({} if build.lateral_aero == "strips" else {"lateral_aero": build.lateral_aero}),
        "aircraft": {"name": build.airframe.name,
                     "cl_delta_a_per_rad": float(rigid.cl_delta_a_per_rad),
                     "cl_p_per_rad": float(rigid.cl_p_per_rad)}}


def _surface(name: str, own, semispan_m: float, aileron):
    """The control surface of ``aileron_effectiveness`` (its docstring): ``aileron`` over
    the wing's ``own`` (None: none) on a semispan of ``semispan_m`` [m]."""
    from bioflex_jsb.aeroelasticity.control_surface import ControlSurface
    from bioflex_jsb.definition.loader import parse_aileron

    if aileron is None:
        if own is None:
            raise InputError(f"wing {name!r} has no [aileron]: add one to its definition "
                             "(docs/aircraft.md) or give one (aileron=(start, end, hinge); "
                             "the command's --aileron START:END:HINGE): the span as fractions "
                             "of the semispan and the hinge's chord fraction")
        return own
    if isinstance(aileron, ControlSurface):
        if aileron.end_m > semispan_m * (1.0 + 1e-12):
            raise InputError(f"aileron ends at {aileron.end_m:g} m, beyond the semispan "
                             f"{semispan_m:g} m")
        return aileron
    if isinstance(aileron, str) or not isinstance(aileron, Iterable) \
            or len(tuple(aileron)) != 3:
        raise InputError(f"aileron must be (start, end, hinge): the span as fractions of the "
                         f"semispan and the hinge's chord fraction, got {aileron!r}")
    start, end, hinge = tuple(aileron)
    return parse_aileron({"span": [start, end], "hinge": hinge}, semispan_m,
                         "aileron argument")


def section_loads(wing, run: TimeHistory, stations=None, *,
                  static: str | None = None, density_kg_m3: float | None = None):
    """Wing section loads of the gust ``run`` (from :func:`fly_gust` with ``wing``) at the
    monitoring ``stations`` (fractions of the semispan; default the wing's, an aircraft
    definition's ``[loads] stations``, else root, 25, 50, 75 %): shear
    [N, up +], bending moment [N·m, tip up +] and torque about the elastic axis [N·m,
    leading edge up +] by force summation and by mode displacement, with their difference
    (:class:`bioflex_jsb.loads.SectionLoads`: ``.values``, ``.difference()``, ``.plot()``;
    :func:`bioflex_jsb.loads.loads_metrics` the metrics' ``loads`` sub-dict; docs/loads.md).
    ``static``: the 1 g part, ``elastic`` (default for coupled/qsd) or ``rigid``;
    ``density_kg_m3`` [kg/m^3]: the air's (None: the run's own)."""
    from bioflex_jsb.loads import section_loads as _section_loads

    build = _Subject.of(wing).build
    if build is None:
        raise InputError("section loads need the wing the run flew (a WingBuild or an "
                         "Aircraft), not None")
    if isinstance(run, dict):
        raise InputError("give one run (e.g. runs['coupled'] of fly_gust's dict), not the "
                         "dict of runs")
    if not isinstance(run, TimeHistory):
        raise InputError(f"run: a TimeHistory (fly_gust's), not {type(run).__name__}")
    if stations is not None:
        if isinstance(stations, str | bytes) or not isinstance(stations, Iterable):
            raise InputError(f"stations: a sequence of fractions of the semispan (e.g. "
                             f"(0.0, 0.5)), not {stations!r}")
        stations = [_real(x, "stations", "fraction of the semispan") for x in stations]
    if density_kg_m3 is not None:
        density_kg_m3 = _check_density(density_kg_m3)
    return _section_loads(build, run, stations, static=static, density_kg_m3=density_kg_m3)


def load_controller(source):
    """A controller for :func:`fly_gust` and :func:`compare` (docs/api.md, "Controllers in
    the loop"): ``source`` a controller file's path (``.npz`` or ``.toml``: A, B, C, D,
    ``dt_s`` [s] (0: continuous), the signals it reads and the commands it writes), a
    shipped controller's name (``gla_optimised``), a
    :class:`~bioflex_jsb.simulation.controller.LinearController`, the package's or
    python-control's ``StateSpace`` (its input names the signals, its output names the
    commands), or any object with ``inputs``, ``outputs`` and ``step(t_s, signals)``.
    Unknown signal or command names are one line (InputError)."""
    from bioflex_jsb.simulation.controller import load_controller as _load

    return _load(source)


def linear_controller(source):
    """The controller of ``source`` (:func:`load_controller`'s sources), refusing one that is
    not linear (one line): the LTI model closes the loop with the controller's state
    space."""
    from bioflex_jsb.simulation.controller import LinearController

    controller = load_controller(source)
    if not isinstance(controller, LinearController):
        raise InputError(f"the LTI model needs a linear controller (a state space), not "
                         f"{type(controller).__name__}")
    return controller


def _gla_plant(wing, speed_m_s, flaperon: bool = False):
    """(the WingBuild, the trim speed [m/s], the GLA plant of loads/alleviation.py with
    JSBSim's rigid block at the trim and the loads at the trim's density; ``flaperon``: with
    the flaperon input, loads/alleviation_flaperon.py)."""
    from bioflex_jsb.loads.alleviation import gla_plant
    from bioflex_jsb.loads.model import build_loads_model

    subject = _Subject.of(wing)
    build = subject.flying_build()
    v = subject.flight_speed(speed_m_s)
    airframe = subject.jsbsim_airframe()
    lin = airframe.linearize(v)
    rho = airframe[JP.ATMOSPHERE_RHO_SLUGS_FT3] * U.KG_M3_PER_SLUG_FT3  # the trim's air
    lm = build_loads_model(build, v, density_kg_m3=rho, static="elastic")
    if flaperon:
        from bioflex_jsb.loads.alleviation_flaperon import flaperon_plant

        return build, v, flaperon_plant(build, v, lm, _aileron_surface(subject, build),
                                        a_rr=lin.a)
    return build, v, gla_plant(build, v, lm, a_rr=lin.a)


def _gla_gradients(wing, speed_m_s: float):
    """The tuned gust's gradients [m] of the alleviation's prediction and design for
    ``wing`` (a WingBuild or an Aircraft) at ``speed_m_s`` [m/s]: those ``loads --tuned``
    flies for its aircraft (:func:`bioflex_jsb.loads.tuned.gust_scales`): the prototype's
    defaults on its airframe (1.5 of its chords to 15 m), another aircraft's own (1.5 of its
    chords to V·T_sp of its rigid short period at the speed, in its definition's air)."""
    from bioflex_jsb.loads.tuned import gust_scales

    subject = _Subject.of(wing)
    return gust_scales(subject.flying_build(), speed_m_s, **subject.density(None)
                       ).gradients_m()


def predict_alleviation(wing, controller, speed_m_s: float | None = None,
                        u_ref_m_s: float = 3.0, dt_s: float = DEFAULT_DT_S):
    """What ``controller`` (a linear one, :func:`linear_controller`) does to the root bending
    moment of ``wing`` (a WingBuild or an Aircraft) at ``speed_m_s`` [m/s] (None: the
    cruise speed) by the LTI model (:mod:`bioflex_jsb.loads.alleviation`: Eq. 4 with its
    controls and JSBSim's rigid block, the loop closed at the step ``dt_s`` [s] with the
    run's one step of delay): the tuned 1-cosine gust's peak increment over the gradients
    of ``loads --tuned`` (``u_ref_m_s`` [m/s] at the longest) and the von Kármán
    turbulence RMS, open and closed loop (a
    :class:`~bioflex_jsb.loads.alleviation.Prediction`: ``tuned_ratio``, ``rms_ratio``,
    ``peak_ratios``, ``as_dict()``)."""
    from bioflex_jsb.loads.alleviation import predict

    controller = linear_controller(controller)
    u_ref = argument(Real("m/s", positive=True), u_ref_m_s, "u_ref_m_s")
    _, v, plant = _gla_plant(wing, speed_m_s, flaperon="flaperon" in controller.outputs)
    return predict(plant, controller, _real(dt_s, "dt_s", "s"),
                   gradients_m=_gla_gradients(wing, v), u_ref_m_s=u_ref)


def design_alleviation(wing, speed_m_s: float | None = None,
                       signals: tuple[str, ...] = ("alpha", "q"),
                       elevator_limit_rad: float = 0.17453292519943295,
                       u_ref_m_s: float = 3.0, dt_s: float = DEFAULT_DT_S):
    """A gust load alleviation controller for ``wing`` (a WingBuild or an Aircraft) at
    ``speed_m_s`` [m/s] (None: the cruise speed), designed on the LTI model
    (:func:`bioflex_jsb.loads.alleviation.design_output_feedback`): a static feedback from
    ``signals`` (the run's channels; default the angle of attack [rad] and the pitch rate
    [rad/s]) to the elevator [rad] minimising the root bending moment's tuned-gust peak
    (``u_ref_m_s`` [m/s]) with the elevator's increment within ``elevator_limit_rad`` [rad]
    (default 10°), at the step ``dt_s`` [s]. Returns (the LinearController, continuous so
    that it flies at any step; the design's record: gains, cost, iterations)."""
    from bioflex_jsb.loads.alleviation import design_output_feedback, static_gain
    from bioflex_jsb.simulation.controller import check_signals

    signals = check_signals(signals)
    limit = argument(Real("rad", hi=0.5, positive=True), elevator_limit_rad,
                     "elevator_limit_rad")
    _, v, plant = _gla_plant(wing, speed_m_s)
    ctrl, record = design_output_feedback(plant, _real(dt_s, "dt_s", "s"), signals,
                                          gradients_m=_gla_gradients(wing, v),
                                          u_ref_m_s=_real(u_ref_m_s, "u_ref_m_s", "m/s"),
                                          elevator_limit_rad=limit)
    record["speed_m_s"] = v
    gains = [record["gains"][s] for s in signals]
    return static_gain(gains, signals, None, name="gla"), record


def closed_loop_flutter(wing, controller=None, range_m_s: tuple[float, float] = (10.0, 30.0),
                        *, step_m_s: float = 0.25, tol_m_s: float = 1e-3,
                        dt_s: float = DEFAULT_DT_S):
    """The flutter speed of ``wing`` (a WingBuild) with ``controller`` in the loop
    (:func:`linear_controller`'s sources; None: the open loop by the same path) by the
    unsteady LTI model with the elevator (:mod:`bioflex_jsb.simulation.flutter_suppression`):
    the closed loop at the run's step ``dt_s`` [s] with its one step of delay, the first speed
    in ``range_m_s`` [m/s] at which any of its roots grows (the phugoid included), scanned every
    ``step_m_s`` and bisected to ``tol_m_s`` [m/s]. Returns a
    :class:`~bioflex_jsb.simulation.flutter_suppression.ClosedLoopFlutter` (``speed_m_s``,
    ``frequency_rad_s``, ``as_dict()``). The shipped ``fs_inertial-backward`` raises the
    inertial-backward wing's 18.86 m/s to 20.81 m/s (docs/aeroelasticity.md)."""
    from bioflex_jsb.simulation.flutter_suppression import closed_loop_flutter as _search

    build = _Subject.of(wing).build
    if build is None:
        raise InputError("closed-loop flutter needs an elastic wing")
    ctrl = None if controller is None else linear_controller(controller)
    lo, hi = _speed_range(range_m_s, Interval("m/s", LINEAR_SPEED_MIN_M_S, SPEED_LIMIT_M_S,
                                              from_lo=True))
    return _search(build, ctrl, (lo, hi), step_m_s=_real(step_m_s, "step_m_s", "m/s"),
                   tol_m_s=_real(tol_m_s, "tol_m_s", "m/s"), dt_s=_real(dt_s, "dt_s", "s"))


def design_flutter_suppression(wing, design_speed_m_s: float = 21.0,
                               signals: tuple[str, ...] = ("q",), *,
                               dt_s: float = DEFAULT_DT_S):
    """A flutter suppression controller for ``wing`` (a WingBuild) designed on the unsteady
    LTI model with the elevator
    (:func:`bioflex_jsb.simulation.flutter_suppression.design_static_feedback`): a static
    feedback from ``signals`` (the run's channels; default the pitch rate [rad/s]) to the
    elevator [rad] minimising the closed loop's largest growth rate from 17 m/s to
    ``design_speed_m_s`` [m/s] at the step ``dt_s`` [s]. Returns (the LinearController,
    continuous; the design's record: gains, cost [1/s], grid, iterations)."""
    from bioflex_jsb.simulation.flutter_suppression import design_static_feedback

    build = _Subject.of(wing).build
    if build is None:
        raise InputError("flutter suppression needs an elastic wing")
    v = _linear_speed(design_speed_m_s, "design_speed_m_s")
    return design_static_feedback(build, v, signals, low_speed_m_s=min(17.0, v - 1.0),
                                  dt_s=_real(dt_s, "dt_s", "s"))
