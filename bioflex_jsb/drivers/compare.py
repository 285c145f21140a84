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

A glide (an aircraft without an engine, trimmed to its steady glide: runtime/trim.py)
is not steady in the nonlinear run: as it sinks the air gets denser (ISA: +0.0096 % per m)
and at a constant attitude the glider slows (SGS at 25 m/s, 1.0 m/s sink: u −0.011 m/s, θ
+0.26 mrad in 8 s of calm air), a drift the LTI model (ρ held) cannot have and that is no
gust's response. :func:`compare_run`'s ``drift`` is the calm-air run of the same trim;
it is added to the linear prediction (the nonlinear run stays as flown), so the errors are
those of the gust's increments. The CLI and :func:`bioflex_jsb.api.compare` fly it for a
glider.

Section loads: a nonlinear run with load channels (``loads_<fs|md>_<quantity>_s<j>``,
``drivers/gust.py``) is compared on them too. The LTI model's loads are its load outputs
(:func:`bioflex_jsb.loads.lti.with_load_outputs`: y = C x + D w_g, perturbations from 1 g)
plus the same 1 g values as the run's (the same loads model: stations, static part,
density), for the methods the run reports (the unsteady wing: mode displacement only, K_md
on its η outputs). Their NRMSE is that of the **increments over 1 g** (the static part,
common to both, would only dilute it); the largest difference is the same either way.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.loads.lti import with_load_outputs
from bioflex_jsb.loads.model import QUANTITIES, LoadsModel, build_loads_model
from bioflex_jsb.loads.stream import layout_for_methods
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.lti_response import simulate
from bioflex_jsb.simulation.results import TimeHistory, nrmse

CHANNELS = ("u", "alpha", "q", "theta", "eta1")
# a controller's commands
COMMANDS = ("ctrl_elevator_rad", "ctrl_throttle", "ctrl_flaperon_rad", "ctrl_aileron_rad")
# a gust with a rolling or lateral part: the rigid lateral model's (_add_lateral)
LATERAL_CHANNELS = ("beta_rad", "p_rad_s", "r_rad_s", "phi_rad")
# both wing halves: the first antisymmetric mode and the modes' rolling moment
# (drivers/compare_lateral.py)
FULL_SPAN_CHANNELS = ("asym_eta1", "modal_roll_n_m")
LOADS_PREFIX = "loads_"


@dataclass
class Comparison:
    """A nonlinear run and the LTI model's prediction of it, with the errors per channel.

    ``nrmse[c]`` [-] and ``worst[c]`` (``max_abs_difference`` in ``unit``, ``at_time_s``) for
    each compared channel ``c``; both None for a run that diverged (``diverged``). The
    section loads compared (``load_channels``, module docstring: NRMSE of the increments
    over 1 g) are in the same two dicts."""

    model: str
    nonlinear: TimeHistory
    linear: TimeHistory
    nrmse: dict[str, float | None]
    worst: dict[str, dict[str, object]]
    channels: tuple[str, ...] = field(default=CHANNELS)
    load_channels: tuple[str, ...] = ()

    @property
    def diverged(self) -> bool:
        return self.nonlinear.stopped is not None

    def loads_table(self) -> str:
        """The section loads' rows of the comparison as text (one per load channel: NRMSE
        of the increments, largest difference [N or N*m] and its time), ending in a
        newline; empty without load channels or for a run that diverged."""
        if self.diverged or not self.load_channels:
            return ""
        lines = [f"{'section load':<24} {'NRMSE [-]':>9} {'max |diff|':>11} {'unit':<6} "
                 f"{'at t [s]':>9}"]
        for c in self.load_channels:
            w = self.worst[c]
            lines.append(f"{c[len(LOADS_PREFIX):]:<24} {self.nrmse[c]:9.4f} "
                         f"{w['max_abs_difference']:11.5f} {w['unit']:<6} "
                         f"{w['at_time_s']:9.3f}")
        lines.append("section loads: <fs|md>_<quantity>_s<station> (docs/loads.md); their "
                     "NRMSE is that of the increments over 1 g")
        return "\n".join(lines) + "\n"

    def as_dict(self) -> dict[str, object]:
        """Plain data (JSON-ready): model, channels, load channels, nrmse, worst, diverged
        and when."""
        return {"model": self.model, "channels": list(self.channels),
                "load_channels": list(self.load_channels), "nrmse": self.nrmse,
                "worst": self.worst, "diverged": self.diverged,
                "divergence_time_s": self.nonlinear.stop_time_s,
                "duration_s": float(self.nonlinear.time_s[-1])
                if len(self.nonlinear.time_s) else 0.0}

    def plot(self, path: str | Path, title: str, force: bool = False) -> Path:
        """Both time histories on the gust figure's panels, NRMSE in each panel's legend,
        written to ``path`` (a figure suffix; an existing file only if it is a plot of ours,
        or with ``force``: :func:`~bioflex_jsb.plot_files.check_plot_target`)."""
        from bioflex_jsb.plot_files import check_plot_target
        from bioflex_jsb.sinks import plotting

        check_plot_target(path, force)
        return plotting.time_histories([self.nonlinear, self.linear], path, title,
                                       nrmse=None if self.diverged else self.nrmse)


def check_gust_excites(gust) -> None:
    """Raise InputError (one line) for a ``gust`` (a parsed
    :class:`~bioflex_jsb.simulation.gusts.GustSpec`) that excites nothing: a comparison's
    errors are normalised by the response to the gust, so without one they read 1.0 on
    every channel (the trim's 1e-6 drift against itself)."""
    parts = gust.spanwise
    moves = parts is not None and (parts.roll_peak_rad_s != 0.0 or (
        parts.lateral is not None and parts.lateral.amplitude_m_s != 0.0))
    if (gust.kind == "none" or gust.amplitude_m_s == 0.0) and not moves:
        raise InputError(f"{gust.text()}: a comparison needs a gust that excites the "
                         "aircraft (its errors are relative to the response to it)")


def check_comparable(model: str, aero: str, trim: str, controller: bool = False,
                     span: str = "half") -> None:
    """Raise InputError (one line) for a model, aerodynamics and trim with no linear model
    (with a ``controller``: one with the controls, quasi-steady about the rigid trim; with
    ``span`` ``full``, both wing halves: the lateral model about the rigid trim, on the
    run's strips)."""
    if span == "full" and trim != "rigid":
        raise InputError("both wing halves are compared on the lateral model about the "
                         "rigid trim (--trim rigid)")
    if controller and (aero != "quasi-steady" or trim != "rigid"):
        raise InputError("a controller is compared on the quasi-steady model about the rigid "
                         "trim (the unsteady and elastic-trim LTI models have no controls)")
    if trim == "elastic" and (aero == "unsteady" or model == "rigid"):
        raise InputError("the elastic trim is compared for the quasi-steady coupled or qsd "
                         "model (the rigid model has no wing; the unsteady one is "
                         "linearised about the rigid trim)")
    if aero == "unsteady" and model != "coupled":
        raise InputError("unsteady aerodynamics are compared for the coupled model (rigid "
                         "has no wing loads; the quasi-static model has no unsteady form)")


def linear_prediction(build: WingBuild, nonlinear: TimeHistory, model: str, speed_m_s: float,
                      aero: str = "quasi-steady", trim: str = "rigid",
                      airframe: Airframe | None = None, controller=None, aileron=None
                      ) -> TimeHistory:
    """The LTI model's response to the gust samples ``nonlinear["w_g"]`` [m/s] at its times.

    ``model``: ``rigid``, ``coupled`` or ``qsd``; ``aero="unsteady"`` (coupled only): Eq. (4)
    on unsteady strips with Küssner's gust; ``trim="elastic"`` (coupled, qsd; quasi-steady):
    linearised about the static aeroelastic equilibrium. Raises InputError for a combination
    that has no linear model (:func:`check_comparable`).

    ``controller``: the linear controller the run flew with
    (:class:`~bioflex_jsb.simulation.controller.LinearController`): the model with its
    controls closes the loop at the run's step with its one step of delay
    (:mod:`bioflex_jsb.simulation.closed_loop`); the prediction has its commands too. A
    controller commanding the ``aileron`` (alone: one axis's loop) closes the full-span
    run's lateral model instead, the longitudinal model then flying open loop.

    A run with both wing halves (``nonlinear.meta["span"] == "full"``): the lateral model of
    the same wing model is added, driven by the run's v_g, aileron and gust roll rate
    (:mod:`bioflex_jsb.drivers.compare_lateral`; ``aileron`` the run's
    :class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface`, None: none)."""
    check_comparable(model, aero, trim, controller is not None,
                     nonlinear.meta.get("span", "half"))
    lateral_controller = None  # a controller of the aileron: the lateral loop's
    if controller is not None and "aileron" in controller.outputs:
        if tuple(controller.outputs) != ("aileron",) or \
                nonlinear.meta.get("span") != "full":
            raise InputError("a controller commanding the aileron is compared on both wing "
                             "halves' lateral model, as its only command (outputs "
                             f"{list(controller.outputs)})")
        lateral_controller, controller = controller, None
    # the JSBSim airframe the run flew (the prototype's by default): A_RR at its trim (an
    # aircraft without an engine: its steady glide, runtime/trim.py)
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
        ss = build_state_space(model, level_flight_condition(speed_m_s,
                                                             airframe=build.airframe),
                               build.model, a_rr=lin.a)
    layout = nonlinear.meta.get("loads")
    lm = None if layout is None else _loads_model(build, nonlinear, model, speed_m_s)
    if controller is not None:
        ss = build_state_space(model, level_flight_condition(speed_m_s,
                                                             airframe=build.airframe),
                               build.model, a_rr=lin.a, controls=True)
        if "flaperon" in controller.outputs:  # its input and its strips' loads
            ss, lm = _with_flaperon(build, nonlinear, speed_m_s, ss, lm)
    if lm is not None and aero != "unsteady":
        ss = with_load_outputs(ss, lm)
    if controller is not None:
        linear = _closed_loop_response(ss, controller, nonlinear)
    else:
        linear = simulate(ss, nonlinear.time_s, nonlinear["w_g"])
    full_span = nonlinear.meta.get("span") == "full"
    if "w_g_tail" in nonlinear.channels:  # a gust that varies over the aircraft
        _add_tail_delay(linear, nonlinear, build, model, speed_m_s, lin.a, lm,
                        controller is None and aero == "quasi-steady" and trim == "rigid")
        if not full_span:
            _add_lateral(linear, nonlinear, build, speed_m_s, airframe or Airframe())
    if full_span:  # both wing halves: the lateral model of the run's wing model
        from bioflex_jsb.drivers.compare_lateral import add_full_span_lateral

        add_full_span_lateral(linear, nonlinear, build, model, speed_m_s,
                              airframe or Airframe(), aileron, aero, lateral_controller)
    if lm is not None:
        _add_linear_loads(linear, lm, layout)
    return linear


def _with_flaperon(build: WingBuild, nonlinear: TimeHistory, speed_m_s: float, ss, lm):
    """The LTI model ``ss`` with the ``flaperon`` input of the surface the run flew
    (``meta["flaperon"]``, :mod:`bioflex_jsb.aeroelasticity.flaperon`) and the loads model
    ``lm`` (None: none) with its strips' loads."""
    from bioflex_jsb.aeroelasticity.control_surface import ControlSurface
    from bioflex_jsb.aeroelasticity.flaperon import flaperon_derivatives, with_flaperon
    from bioflex_jsb.loads.flaperon import with_flaperon as loads_with_flaperon

    record = nonlinear.meta.get("flaperon")
    if not isinstance(record, dict) or not isinstance(record.get("surface"), dict):
        raise InputError("the run has no record of its flaperon (meta['flaperon']): fly it "
                         "again to compare it")
    s = record["surface"]
    surface = ControlSurface(float(s["start_m"]), float(s["end_m"]),
                             float(s["hinge_chord_fraction"]), str(s["name"]))
    deriv = flaperon_derivatives(build, surface)
    cond = level_flight_condition(speed_m_s, airframe=build.airframe)
    ss = with_flaperon(ss, cond, deriv, build.model.generalised_masses_kg_m2)
    return ss, None if lm is None else loads_with_flaperon(lm, deriv)


def _add_lateral(linear: TimeHistory, nonlinear: TimeHistory, build: WingBuild,
                 speed_m_s: float, airframe: Airframe) -> None:
    """Add to ``linear`` the rigid lateral model's response (identified from the run's
    airframe at the trim, as ``bioflex-jsb modes --lateral``) to the run's gust roll rate
    p_g and lateral gust v_g: the channels of :data:`LATERAL_CHANNELS` (none when both are
    zero), each the run's absolute value predicted as the trim's (the run's first sample:
    JSBSim's trim is not exactly wings level, the c172's bank −0.16 mrad) plus the model's
    increment, as the full-span comparison does (drivers/compare_lateral.py)."""
    from bioflex_jsb.flight_dynamics.lateral import build_lateral_state_space
    from bioflex_jsb.runtime.identification import identify_lateral
    from bioflex_jsb.simulation.spanwise_gusts import lateral_gust_response

    p_g, v_g = nonlinear["p_g"], nonlinear["v_g"]
    if not (np.any(p_g != 0.0) or np.any(v_g != 0.0)):
        return
    point = identify_lateral(airframe, speed_m_s, build.airframe.reference)
    ss = build_lateral_state_space(point.trim, point.aero)
    for name, values in lateral_gust_response(ss, nonlinear.time_s, p_g, v_g).items():
        linear.channels[name] = values + float(nonlinear[name][0])
        linear.units[name] = "rad/s" if name.endswith("_s") else "rad"


def _add_tail_delay(linear: TimeHistory, nonlinear: TimeHistory, build: WingBuild,
                    model: str, speed_m_s: float, a_rr: np.ndarray, lm, comparable: bool
                    ) -> None:
    """Add to ``linear`` the response to the tail's penetration delay of the run's gust (its
    channels w_g, w_g_tail), the elevator that lifts the tail as the delay does
    (:func:`~bioflex_jsb.simulation.spanwise_gusts.tail_delay_elevator_rad`), on the
    quasi-steady model with controls about the rigid trim (else one line: InputError)."""
    from bioflex_jsb.simulation.spanwise_gusts import TailGust, tail_delay_elevator_rad

    w_t, w = nonlinear["w_g_tail"], nonlinear["w_g"]
    if not np.any(w_t != w):
        return
    if not comparable:
        raise InputError("the tail's penetration delay is compared on the quasi-steady model "
                         "about the rigid trim without a controller (the elevator it is "
                         "flown with there)")
    data = build.airframe.at_speed(speed_m_s)
    tail = TailGust.from_derivatives(data.aero, data.reference.mean_chord_m)
    elevator = tail_delay_elevator_rad(tail, data.aero, w_t, w, speed_m_s)
    ss = build_state_space(model, level_flight_condition(speed_m_s, airframe=build.airframe),
                           build.model, a_rr=a_rr, controls=True)
    if lm is not None:  # the section loads of the same response
        ss = with_load_outputs(ss, lm)
    column = ss.inputs.index("elevator")
    ss_e = replace(ss, b=ss.b[:, [column]], d=ss.d[:, [column]], inputs=("elevator",),
                   input_units=("rad",))
    # simulate's gust conventions aside (its alpha adds w/V): the states' own response
    extra = simulate(ss_e, nonlinear.time_s, elevator)
    extra.channels["alpha"] = extra["alpha_inertial"]
    for name in set(linear.channels) & set(extra.channels) - {"w_g"}:
        linear.channels[name] = linear[name] + extra[name] - (name == "n_z")


def _closed_loop_response(ss, controller, nonlinear: TimeHistory) -> TimeHistory:
    """The closed loop's response to the run's gust samples, on the run's channels (the
    LTI's own extra signals left out: its airspeed and absolute angles would be
    perturbations under an absolute channel's name)."""
    from bioflex_jsb.simulation.closed_loop import close_loop, respond, signal_outputs

    dt = float(nonlinear.meta.get("dt_s") or nonlinear.time_s[1] - nonlinear.time_s[0])
    cl = close_loop(signal_outputs(ss), controller, dt)
    linear = respond(cl, nonlinear["w_g"])
    for extra in ("airspeed_m_s", "theta_rad", "alpha_rad"):
        linear.channels.pop(extra, None)
        linear.units.pop(extra, None)
    linear.time_s = np.asarray(nonlinear.time_s, dtype=float)
    linear.channels["w_g"] = np.asarray(nonlinear["w_g"], dtype=float)
    return linear


def _loads_model(build: WingBuild, nonlinear: TimeHistory, model: str, speed_m_s: float
                 ) -> LoadsModel:
    """The loads model of the nonlinear run's loads (its stations, density, static part)."""
    layout = nonlinear.meta["loads"]
    return build_loads_model(build, speed_m_s, layout["station_fractions"],
                             density_kg_m3=layout["density_kg_m3"],
                             static="rigid" if model == "rigid" else "elastic")


def _add_linear_loads(linear: TimeHistory, lm, layout: dict) -> None:
    """The LTI loads as the run's channels (totals: the run's 1 g values plus the LTI's
    perturbations), for the run's methods; mode displacement of an LTI model without load
    outputs (the unsteady one) from its η outputs, and its run's force summation left out
    (it has none)."""
    if not any(c.startswith("fs_") for c in linear.channels):  # the unsteady LTI model
        layout = layout_for_methods(layout, ("mode_displacement",))
    static = layout["static_1g"]
    s = lm.n_stations
    for name in layout["names"]:
        row = name[len(LOADS_PREFIX):]
        if row in linear.channels:
            perturbation = linear.channels.pop(row)
            linear.units.pop(row, None)
        elif row.startswith("md_"):
            quantity, j = row[3:].rsplit("_s", 1)
            k = QUANTITIES.index(quantity) * s + int(j)
            eta = np.column_stack([linear[f"eta{i + 1}"] for i in range(lm.n_modes)])
            perturbation = eta @ lm.md_matrix[k]
        else:
            raise InputError(f"the LTI model has no output for the run's {name!r}")
        linear.channels[name] = static[name] + perturbation
        linear.units[name] = layout["units"][name]
    for row in [c for c in linear.channels if c[:3] in ("fs_", "md_")]:  # not the run's
        linear.channels.pop(row)
        linear.units.pop(row, None)
    linear.meta["loads"] = dict(layout)


def _add_drift(linear: TimeHistory, nonlinear: TimeHistory, drift: TimeHistory) -> None:
    """``linear`` += the calm-air run ``drift`` on the compared channels (the same steps as
    ``nonlinear``: a drift that stopped early, or of other times, is refused)."""
    n = len(nonlinear.time_s)
    if drift.stopped is not None or len(drift.time_s) < n or not np.array_equal(
            drift.time_s[:n], nonlinear.time_s):
        raise InputError(f"the calm-air run is no reference for the comparison "
                         f"({drift.stopped or 'other times than the gust run'})")
    for c in CHANNELS:
        if c in linear.channels and c in drift.channels:
            linear.channels[c] = linear.channels[c] + drift[c][:n]
    linear.meta["drift"] = "calm-air run of the same trim added (a glide's drift)"


def compare_run(build: WingBuild, nonlinear: TimeHistory, model: str, speed_m_s: float,
                aero: str = "quasi-steady", trim: str = "rigid",
                linear: TimeHistory | None = None, airframe: Airframe | None = None,
                drift: TimeHistory | None = None, controller=None, aileron=None
                ) -> Comparison:
    """Compare ``nonlinear`` (a gust run of ``model``) with the LTI prediction (``linear``,
    computed by :func:`linear_prediction` on ``airframe``, the JSBSim airframe flown, when
    not given); ``drift``: the calm-air run of the same trim and steps, added to the
    prediction (a glide's drift: module docstring); ``controller``: the linear controller
    the run flew with (:func:`linear_prediction`), whose commands are compared too; see
    the module docstring."""
    if linear is None:
        linear = linear_prediction(build, nonlinear, model, speed_m_s, aero, trim, airframe,
                                   controller, aileron)
    if drift is not None:
        _add_drift(linear, nonlinear, drift)
    channels = tuple(c for c in CHANNELS + COMMANDS + LATERAL_CHANNELS + FULL_SPAN_CHANNELS
                     if c in linear.channels and c in nonlinear.channels)
    load_channels = tuple(c for c in nonlinear.channels
                          if c.startswith(LOADS_PREFIX) and c in linear.channels)
    static = (nonlinear.meta.get("loads") or {}).get("static_1g", {})
    errors: dict[str, float | None] = {}
    worst: dict[str, dict[str, object]] = {}
    diverged = nonlinear.stopped is not None
    for c in channels + load_channels:
        unit = nonlinear.units.get(c, linear.units.get(c, ""))
        if diverged:
            errors[c] = None
            worst[c] = {"max_abs_difference": None, "unit": unit, "at_time_s": None}
            continue
        base = static.get(c, 0.0)  # a load: its increment over 1 g (module docstring)
        errors[c] = nrmse(nonlinear[c] - base, linear[c] - base)
        diff = np.abs(linear[c] - nonlinear[c])
        k = int(np.argmax(diff))
        worst[c] = {"max_abs_difference": float(diff[k]), "unit": unit,
                    "at_time_s": float(nonlinear.time_s[k])}
    strips = ", unsteady strips" if aero == "unsteady" else ""
    linear.meta.update(label=f"LTI {model} (Eq. 4{strips})", linestyle="--",
                       color="tab:orange", linewidth=1.6, source="lti")
    nonlinear.meta.update(label=f"JSBSim {model}", color="tab:blue", linestyle="-",
                          linewidth=2.2)
    return Comparison(model, nonlinear, linear, errors, worst, channels, load_channels)
