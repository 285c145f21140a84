"""One run configuration: what a nonlinear gust run flies, validated once, in one place.

A :class:`RunConfig` is built by the CLI (``gust``, ``compare``, ``loads``) and by the API
(``fly_gust``, ``compare``) from what the user gave, and the drivers take it
(:func:`bioflex_jsb.drivers.gust.run_gust`): the operating point (airspeed [m/s],
altitude [m]), the gust and its start [s], the duration and the co-simulation step [s], the
wing models flown and their aerodynamics and trim. What runs is decided by enumerations
(:class:`WingModel`, :class:`Aero`, :class:`TrimMode`), not by strings compared in many
places; each is a ``StrEnum`` so that a log, a table or JSON shows the name it always
showed.

The rules, every one checked when the configuration is made (one line, InputError):

* the wing models: one or more of ``rigid`` (no wing loads), ``coupled`` (dynamic modal
  states), ``qsd`` (quasi-static deformation), ``native`` (the wing in the aircraft's XML);
* ``aero = unsteady`` (Jones lag states, apparent mass, Küssner gust) is the coupled wing's
  only: the rigid model has no wing loads and flies as it is, the quasi-static deflection
  has no lag states (``qsd`` refused), and the unsteady states are linearised about the
  rigid trim (``trim = elastic`` refused with it);
* ``trim = elastic`` (the static aeroelastic equilibrium) is for the elastic wings: the
  rigid model always starts from the rigid trim, and a run of the rigid model alone with it
  is refused;
* the numbers: finite, the run's length within the run limits
  (:func:`~bioflex_jsb.simulation.run.check_run_length`), the gust inside the run and
  resolved by the step (:func:`~bioflex_jsb.simulation.gusts.check_gust_resolution`), the
  step within :data:`~bioflex_jsb.simulation.modal_wing.MIN_DT_S` ..
  :data:`~bioflex_jsb.simulation.modal_wing.MAX_DT_S`.

The airspeed's own range is the aircraft's (its flight speeds: checked where the aircraft
is known, ``cli/case.py check_speed``, ``api``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum, StrEnum

from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.gusts import GustSpec, check_gust_resolution
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S, MAX_DT_S, MIN_DT_S
from bioflex_jsb.simulation.run import check_run_length
from bioflex_jsb.values import is_real


class WingModel(StrEnum):
    """The wing a run flies (module docstring)."""

    RIGID = "rigid"
    COUPLED = "coupled"
    QSD = "qsd"
    NATIVE = "native"


class Aero(StrEnum):
    """The wing's strip aerodynamics."""

    QUASI_STEADY = "quasi-steady"
    UNSTEADY = "unsteady"


class TrimMode(StrEnum):
    """The trim a run starts from: ``rigid`` (the paper's reading: JSBSim's trim of the
    airframe, the wing's static deformation inside the rigid tables) or ``elastic`` (the
    static aeroelastic equilibrium carried by JSBSim's trim; docs/decisions.md)."""

    RIGID = "rigid"
    ELASTIC = "elastic"


ALL_MODELS = (WingModel.RIGID, WingModel.COUPLED, WingModel.QSD)


def _enum(kind: type[Enum], value, what: str):
    try:
        return kind(value)
    except ValueError:
        accepted = ", ".join(m.value for m in kind)
        raise InputError(f"unknown {what} {value!r}; accepted: {accepted}") from None


def _number(value, what: str) -> float:
    if not is_real(value):
        raise InputError(f"{what} must be a number, got {value!r}")
    if not math.isfinite(value):
        raise InputError(f"{what} must be finite, got {value!r}")
    return float(value)


@dataclass(frozen=True)
class RunConfig:
    """A nonlinear gust run (module docstring): trim airspeed ``speed_m_s`` [m/s], ``gust``
    (a parsed :class:`~bioflex_jsb.simulation.gusts.GustSpec`), ``duration_s`` [s],
    ``gust_start_s`` [s], ``altitude_m`` [m above sea level], co-simulation step ``dt_s``
    [s], the wing ``models`` flown, their ``aero`` and ``trim``. Frozen; every field checked
    when it is made."""

    speed_m_s: float
    gust: GustSpec
    duration_s: float = 6.0
    gust_start_s: float = 0.5
    altitude_m: float = 0.0
    dt_s: float = DEFAULT_DT_S
    models: tuple[WingModel, ...] = ALL_MODELS
    aero: Aero = Aero.QUASI_STEADY
    trim: TrimMode = TrimMode.RIGID

    def __post_init__(self) -> None:
        set_ = object.__setattr__  # frozen: the checked values replace the given ones
        set_(self, "aero", _enum(Aero, self.aero, "aerodynamics"))
        set_(self, "trim", _enum(TrimMode, self.trim, "trim"))
        models = self.models
        if isinstance(models, str) or not hasattr(models, "__iter__"):
            raise InputError(f"models must be a tuple of model names "
                             f"({', '.join(m.value for m in WingModel)}), got {models!r}")
        models = tuple(_enum(WingModel, m, "model") for m in models)
        if not models:
            raise InputError("models: give one or more of "
                             f"{', '.join(m.value for m in WingModel)}")
        set_(self, "models", models)
        for name, what in (("speed_m_s", "speed_m_s [m/s]"), ("duration_s", "duration_s [s]"),
                           ("gust_start_s", "gust_start_s [s]"),
                           ("altitude_m", "altitude_m [m]"), ("dt_s", "dt_s [s]")):
            set_(self, name, _number(getattr(self, name), what))
        if self.speed_m_s <= 0.0:
            raise InputError(f"speed_m_s must be > 0 m/s, got {self.speed_m_s:g}")
        if self.duration_s <= 0.0:
            raise InputError(f"duration_s must be > 0 s, got {self.duration_s:g}")
        if not MIN_DT_S <= self.dt_s <= MAX_DT_S:
            raise InputError(f"the step {self.dt_s:g} s is outside {MIN_DT_S:g}..{MAX_DT_S:g} s")
        check_run_length(self.duration_s, self.dt_s, self.turbulence)
        if self.gust_start_s < 0.0 or (self.gust.kind != "none"
                                       and self.gust_start_s >= self.duration_s):
            raise InputError(f"the gust start {self.gust_start_s:g} s must be within the run: "
                             f"0 <= gust start < duration ({self.duration_s:g} s)")
        check_gust_resolution(self.gust, self.speed_m_s, self.dt_s)
        for model in models:
            self.settings_for(model)
        if self.trim is TrimMode.ELASTIC and set(models) <= {WingModel.RIGID,
                                                             WingModel.NATIVE}:
            raise InputError("the elastic trim starts the elastic-wing runs from the wing's "
                             "static deflection; the rigid model has no elastic wing (it "
                             "always starts from the rigid trim): fly coupled or qsd, or the "
                             "rigid trim")

    @property
    def turbulence(self) -> bool:
        """The gust is turbulence (Dryden, von Kármán): longer runs are allowed."""
        return self.gust.kind in ("dryden", "vonkarman")

    def settings_for(self, model) -> tuple[Aero, TrimMode]:
        """(the aerodynamics, the trim) ``model`` flies with in this run (module docstring:
        the unsteady strips and the elastic trim are the elastic wings'); InputError for a
        combination that cannot fly."""
        model = _enum(WingModel, model, "model")
        unsteady = self.aero is Aero.UNSTEADY
        if unsteady and model is WingModel.QSD:
            raise InputError("the unsteady aerodynamics are the coupled wing's (rigid has no "
                             "wing loads); the quasi-static model has no unsteady form: drop "
                             "qsd from the models")
        if unsteady and model is WingModel.NATIVE:
            raise InputError("the native wing (in the aircraft's XML) is quasi-steady")
        if unsteady and self.trim is TrimMode.ELASTIC:
            raise InputError("the unsteady aerodynamics fly from the rigid trim (their lag "
                             "states are linearised about it); accepted with them: the rigid "
                             "trim")
        aero = Aero.UNSTEADY if unsteady and model is WingModel.COUPLED else Aero.QUASI_STEADY
        elastic = self.trim is TrimMode.ELASTIC and model in (WingModel.COUPLED,
                                                             WingModel.QSD)
        return aero, TrimMode.ELASTIC if elastic else TrimMode.RIGID

    def needs_build(self, model) -> bool:
        """Whether ``model`` needs the wing's whole build (its strips and modes: the
        unsteady strips, the elastic trim), not only its LTI model."""
        aero, trim = self.settings_for(model)
        return aero is Aero.UNSTEADY or trim is TrimMode.ELASTIC
