"""The comparison of a nonlinear gust run with the linear model of Eq. (4) on the same gust.

:func:`linear_prediction` drives the LTI model of the same wing at the same trim with the gust
samples the nonlinear run flew (held over each step, exactly discretised:
:func:`bioflex_jsb.simulation.lti_response.simulate`); the rigid block A_RR is JSBSim's own
linearisation of the airframe at that trim, so the two differ only by the nonlinearity.
:func:`compare_run` adds the per-channel errors. ``bioflex-jsb compare`` and
:func:`bioflex_jsb.api.compare` are its clients.

Errors: NRMSE = RMS(linear − nonlinear) / RMS(nonlinear) [-] per channel over the run, and the
largest absolute difference (in the channel's SI unit) with its time [s]. A nonlinear run that
diverged is no reference: its errors are None.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.lti_response import simulate
from bioflex_jsb.simulation.results import TimeHistory, nrmse

CHANNELS = ("u", "alpha", "q", "theta", "eta1")


@dataclass
class Comparison:
    """A nonlinear run and the LTI model's prediction of it, with the errors per channel.

    ``nrmse[c]`` [-] and ``worst[c]`` (``max_abs_difference`` in ``unit``, ``at_time_s``) for
    each compared channel ``c``; both None for a run that diverged (``diverged``)."""

    model: str
    nonlinear: TimeHistory
    linear: TimeHistory
    nrmse: dict[str, float | None]
    worst: dict[str, dict[str, object]]
    channels: tuple[str, ...] = field(default=CHANNELS)

    @property
    def diverged(self) -> bool:
        return self.nonlinear.stopped is not None

    def as_dict(self) -> dict[str, object]:
        """Plain data (JSON-ready): model, channels, nrmse, worst, diverged and when."""
        return {"model": self.model, "channels": list(self.channels), "nrmse": self.nrmse,
                "worst": self.worst, "diverged": self.diverged,
                "divergence_time_s": self.nonlinear.stop_time_s,
                "duration_s": float(self.nonlinear.time_s[-1])
                if len(self.nonlinear.time_s) else 0.0}

    def plot(self, path: str | Path, title: str) -> Path:
        """Both time histories on the gust figure's panels, NRMSE in each panel's legend."""
        from bioflex_jsb.sinks import plotting

        return plotting.time_histories([self.nonlinear, self.linear], path, title,
                                       nrmse=None if self.diverged else self.nrmse)


def check_comparable(model: str, aero: str, trim: str) -> None:
    """Raise InputError (one line) for a model, aerodynamics and trim with no linear model."""
    if trim == "elastic" and (aero == "unsteady" or model == "rigid"):
        raise InputError("the elastic trim is compared for the quasi-steady coupled or qsd "
                         "model (the rigid model has no wing; the unsteady one is "
                         "linearised about the rigid trim)")
    if aero == "unsteady" and model != "coupled":
        raise InputError("unsteady aerodynamics are compared for the coupled model (rigid "
                         "has no wing loads; the quasi-static model has no unsteady form)")


def linear_prediction(build: WingBuild, nonlinear: TimeHistory, model: str, speed_m_s: float,
                      aero: str = "quasi-steady", trim: str = "rigid",
                      airframe: Airframe | None = None) -> TimeHistory:
    """The LTI model's response to the gust samples ``nonlinear["w_g"]`` [m/s] at its times.

    ``model``: ``rigid``, ``coupled`` or ``qsd``; ``aero="unsteady"`` (coupled only): Eq. (4)
    on unsteady strips with Küssner's gust; ``trim="elastic"`` (coupled, qsd; quasi-steady):
    linearised about the static aeroelastic equilibrium. Raises InputError for a combination
    that has no linear model (:func:`check_comparable`)."""
    check_comparable(model, aero, trim)
    lin = (airframe or Airframe()).linearize(speed_m_s)
    if aero == "unsteady":
        from bioflex_jsb.aeroelasticity.free_aircraft import unsteady_state_space

        ss = unsteady_state_space(build, speed_m_s, gust=True, a_rr=lin.a)
    elif trim == "elastic":
        from bioflex_jsb.flight_dynamics.elastic_trim import (
            elastic_trim,
            linearise_about_elastic_trim,
        )

        ss = linearise_about_elastic_trim(model, elastic_trim(build, speed_m_s), build.model,
                                          a_rr=lin.a)
    else:
        ss = build_state_space(model, level_flight_condition(speed_m_s), build.model,
                               a_rr=lin.a)
    return simulate(ss, nonlinear.time_s, nonlinear["w_g"])


def compare_run(build: WingBuild, nonlinear: TimeHistory, model: str, speed_m_s: float,
                aero: str = "quasi-steady", trim: str = "rigid",
                linear: TimeHistory | None = None) -> Comparison:
    """Compare ``nonlinear`` (a gust run of ``model``) with the LTI prediction (``linear``,
    computed by :func:`linear_prediction` when not given); see the module docstring."""
    if linear is None:
        linear = linear_prediction(build, nonlinear, model, speed_m_s, aero, trim)
    channels = tuple(c for c in CHANNELS if c in linear.channels and c in nonlinear.channels)
    errors: dict[str, float | None] = {}
    worst: dict[str, dict[str, object]] = {}
    diverged = nonlinear.stopped is not None
    for c in channels:
        unit = nonlinear.units.get(c, linear.units.get(c, ""))
        if diverged:
            errors[c] = None
            worst[c] = {"max_abs_difference": None, "unit": unit, "at_time_s": None}
            continue
        errors[c] = nrmse(nonlinear[c], linear[c])
        diff = np.abs(linear[c] - nonlinear[c])
        k = int(np.argmax(diff))
        worst[c] = {"max_abs_difference": float(diff[k]), "unit": unit,
                    "at_time_s": float(nonlinear.time_s[k])}
    strips = ", unsteady strips" if aero == "unsteady" else ""
    linear.meta.update(label=f"LTI {model} (Eq. 4{strips})", linestyle="--",
                       color="tab:orange", linewidth=1.6, source="lti")
    nonlinear.meta.update(label=f"JSBSim {model}", color="tab:blue", linestyle="-",
                          linewidth=2.2)
    return Comparison(model, nonlinear, linear, errors, worst, channels)
