"""The Python API of bioflex-jsb: the same runs the ``bioflex-jsb`` command makes, as data.

The CLI is one client of these functions (README, "Python API"). Everything is SI; results
are data objects with named channels and units (``TimeHistory``) or named signals
(``StateSpace``); plots and logs are separate (:mod:`bioflex_jsb.sinks`).

>>> from bioflex_jsb import api
>>> wing = api.load_wing("optimised")
>>> runs = api.fly_gust(wing, speed_m_s=15.0, gust="sharp:3", models=("rigid", "coupled"))
>>> runs["coupled"]["q"]               # pitch rate [rad/s] at runs["coupled"].time_s [s]
>>> lti = api.linear_model(wing, speed_m_s=15.0, model="coupled")
>>> unsteady = api.fly_gust(wing, gust="sharp:0.3", aero="unsteady")  # Jones/Küssner strips
>>> api.flutter(wing).flutter_speed_m_s  # [m/s]
"""

from __future__ import annotations

from collections.abc import Iterable

from bioflex_jsb.aeroelasticity.free_aircraft import AERO_MODELS, unsteady_state_space
from bioflex_jsb.drivers.gust import RunSetup, StepRecorder, run_gust
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.eigen import FlutterResult, ModeSet, find_flutter, modes_at
from bioflex_jsb.flight_dynamics.lti import MODELS, StateSpace, build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import (
    DEFAULT_MASS_BASIS,
    WingBuild,
    build_wing,
    resolve_variant,
)
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.results import GustMetrics, TimeHistory, gust_metrics

__all__ = [
    "DEFAULT_DT_S", "FlutterResult", "GustMetrics", "StateSpace", "TimeHistory", "WingBuild",
    "flutter", "fly_fig21", "fly_gust", "linear_model", "load_wing", "metrics", "modes",
    "to_python_control",
]


def load_wing(name_or_file: str = "optimised", mass_basis: str = DEFAULT_MASS_BASIS
              ) -> WingBuild:
    """The elastic wing of a named variant (``original``, ``optimised``,
    ``inertial-forward``, ``elastic-forward``, ``inertial-backward``, ``elastic-backward``)
    or of a variant file (``docs/wing_variants.md``): modes, strips and the Table B1/B2
    model. ``mass_basis``: ``consistent`` or ``paper`` (``docs/decisions.md``)."""
    return build_wing(resolve_variant(name_or_file), mass_basis=mass_basis)


def fly_gust(wing: WingBuild, speed_m_s: float = 15.0, gust: str = "sharp:3",
             models: Iterable[str] | None = None, duration_s: float = 5.0,
             gust_start_s: float = 0.5, altitude_m: float = 0.0, dt_s: float = DEFAULT_DT_S,
             recorders: dict[str, StepRecorder] | None = None,
             aero: str = "quasi-steady", trim: str = "rigid") -> dict[str, TimeHistory]:
    """Nonlinear 6-DoF gust runs of the JSBSim airframe with ``wing``, one per model
    (``rigid``, ``coupled``, ``qsd``; default all three, or ``coupled`` alone with
    ``aero="unsteady"``): trim at ``speed_m_s`` [m/s] and ``altitude_m`` [m],
    then fly ``duration_s`` [s] at the step ``dt_s`` [s] through ``gust`` (``sharp:A``,
    ``1cos:A:L``, ``dryden:SIGMA:SCALE[:SEED]``, ``vonkarman:…``; m/s, m) starting at
    ``gust_start_s`` [s]. ``recorders``: a step recorder (an MCAP log) per model.
    ``aero``: the wing's strips, ``quasi-steady`` (the paper's) or ``unsteady`` (Jones lag
    states, apparent mass, Küssner gust: :mod:`bioflex_jsb.simulation.unsteady_wing`; the
    coupled model only, on the Python step). ``trim``: ``rigid`` (the paper's reading) or
    ``elastic`` (start from the static aeroelastic equilibrium: the wing's static deflection
    and its loads carried by JSBSim's trim; the rigid model is flown from the rigid trim).

    Returns {model: TimeHistory}; a run that left the valid range has ``stopped`` set (the
    reason, the time and the mode) and holds every step up to then."""
    if aero not in AERO_MODELS:
        raise InputError(f"unknown aerodynamics {aero!r}; accepted: {', '.join(AERO_MODELS)}")
    if models is None:
        models = ("rigid", "coupled", "qsd") if aero == "quasi-steady" else ("coupled",)
    setup = RunSetup(speed_m_s, parse_gust(gust), duration_s, gust_start_s, altitude_m, dt_s)
    airframe = Airframe()
    out = {}
    for model in models:
        recorder = (recorders or {}).get(model)
        elastic = trim == "elastic" and model != "rigid"
        if aero == "unsteady" or elastic:
            out[model] = run_gust(airframe, wing, model, setup, recorder=recorder,
                                  aero=aero, trim_mode="elastic" if elastic else "rigid")
        else:
            out[model] = run_gust(airframe, wing.model, model, setup, recorder=recorder)
    return out


def fly_fig21(model: str = "coupled", duration_s: float = 3.0) -> TimeHistory:
    """The paper's Fig. 21 case (optimised wing, 15 m/s, 3 m/s sharp-edged gust at 0.5 s)
    through ``model``: ``rigid``, ``coupled``, ``qsd``, or ``native`` (the repository's
    native XML wing, ``aircraft/bioflex_optimised``). The golden check cases."""
    setup = RunSetup(15.0, parse_gust("sharp:3"), duration_s)
    if model == "native":
        from bioflex_jsb.generators.native_wing import aircraft_name

        return run_gust(Airframe(aircraft=aircraft_name("optimised")), None, "native", setup)
    return run_gust(Airframe(), load_wing("optimised").model, model, setup)


def metrics(run: TimeHistory, gust_start_s: float = 0.5) -> GustMetrics:
    """Peaks of the response to a gust starting at ``gust_start_s`` [s] (units in the
    field names)."""
    return gust_metrics(run, gust_start_s)


def linear_model(wing: WingBuild | None, speed_m_s: float = 15.0, model: str = "coupled",
                 aero: str = "quasi-steady", trim: str = "rigid") -> StateSpace:
    """The paper's LTI model (Eq. 4) at ``speed_m_s`` [m/s]: ``rigid`` (A_RR), ``coupled``
    or ``qsd`` (Eq. 9-10), with named states, inputs, outputs and their units.

    ``aero="unsteady"`` (``coupled`` only): Eq. (4) on unsteady strips with the Küssner gust
    (:func:`bioflex_jsb.aeroelasticity.free_aircraft.unsteady_state_space`, ``gust=True``),
    the model the co-simulation's unsteady wing integrates: states u, α, q, θ, η, η̇ and
    per strip k lag1[k], lag2[k], kussner1[k], kussner2[k] [m/s].

    ``trim="elastic"`` (``coupled``, ``qsd``): linearised about the elastic trim
    (:func:`bioflex_jsb.flight_dynamics.elastic_trim.linearise_about_elastic_trim`: the
    modes' force per unit airspeed from the deflected wing); ``notes["eta_static_rad"]``
    holds the static deflection η₀ the states are measured from."""
    if trim not in ("rigid", "elastic"):
        raise InputError(f"unknown trim {trim!r}; accepted: rigid, elastic")
    if trim == "elastic":
        if aero != "quasi-steady" or wing is None:
            raise InputError("trim='elastic' linearises the quasi-steady coupled or qsd model "
                             "of an elastic wing")
        from bioflex_jsb.flight_dynamics.elastic_trim import (
            elastic_trim,
            linearise_about_elastic_trim,
        )

        return linearise_about_elastic_trim(model, elastic_trim(wing, speed_m_s), wing.model)
    if aero not in AERO_MODELS:
        raise InputError(f"unknown aerodynamics {aero!r}; accepted: {', '.join(AERO_MODELS)}")
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; accepted: {', '.join(MODELS)}")
    if aero == "unsteady":
        if model != "coupled" or wing is None:
            raise InputError("aero='unsteady' is the coupled model of an elastic wing")
        return unsteady_state_space(wing, speed_m_s, gust=True)
    return build_state_space(model, level_flight_condition(speed_m_s),
                             None if wing is None else wing.model)


def to_python_control(ss: StateSpace):
    """``ss`` as a python-control ``StateSpace`` (named signals); needs the ``control``
    extra (``pip install "bioflex-jsb[control]"``)."""
    from bioflex_jsb.sinks.model_export import to_python_control as convert

    return convert(ss)


def modes(wing: WingBuild, speed_m_s: float = 15.0, model: str = "coupled") -> ModeSet:
    """Labelled eigenvalues (short period, phugoid, aeroelastic_i) of ``model`` at
    ``speed_m_s`` [m/s]."""
    return modes_at(model, [speed_m_s], wing.model)[0]


def flutter(wing: WingBuild, range_m_s: tuple[float, float] = (5.0, 40.0)) -> FlutterResult:
    """The lowest airspeed [m/s] in ``range_m_s`` at which a mode of the coupled model goes
    unstable, its frequency [rad/s] and kind (flutter or divergence)."""
    return find_flutter(wing.model, range_m_s)
