"""The lateral half of a comparison of a run with both wing halves (``span="full"``) with its
linear model: the lateral-directional model of the run's wing model (``rigid``, ``coupled``,
``qsd``; docs/lateral.md) at the run's trim, driven by what the run flew.

The nonlinear run (:mod:`bioflex_jsb.simulation.full_span`) flies the antisymmetric modes on
quasi-steady strips with the roll rate, their own η_a, η̇_a, JSBSim's ailerons, the gust
roll rate p_g, the yaw rate and the sideslip (and their side force and yawing moment); its
linear model is :func:`bioflex_jsb.api.lateral_model`'s, the coupled lateral model of the
same strips with the aileron's generalised force on the modes and the yaw rate's and
sideslip's terms linearised about the trim, a rigid one: η_s = 0 (one builder:
:func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`), its
rigid block identified from the run's JSBSim airframe at the same trim
(:func:`~bioflex_jsb.runtime.identification.identify_lateral`). Its inputs, each held over
a step and exactly discretised (zero-order hold, as the run holds them):

* ``v_g`` [m/s], the run's lateral gust (JSBSim's wind: β − v_g/V in its tables);
* ``aileron`` [rad], the run's ``aileron_rad`` over its first sample (JSBSim's δa; a gust
  run's stays at the trim's unless an aileron step or doublet was given);
* ``p_g`` [rad/s], the run's gust roll rate. The run applies it as p − p_g in JSBSim's
  rolling and yawing moments (``runtime/gust_loads.py``: C_lp and C_np only, no side force)
  and on the antisymmetric strips (their elastic increments), so its column is minus the
  model's p column without the terms p has alone: B_pg = −A[:, p] with the β row (the
  kinematic w₀/V and C_Yp, which the run's gust does not apply) and the φ row (φ̇ = p) set
  to zero; a quasi-static model's η outputs likewise D_pg = −C[η, p];
* the rudder stays at the trim's (a gust run does not move it).

The compared channels: β, p, r, φ (``beta_rad``, ``p_rad_s``, ``r_rad_s``, ``phi_rad``: the
run's absolute values, so the prediction is the trim's, the run's first sample, plus the
model's increment; JSBSim's trim is not exactly wings level, the prototype's and the c172's
bank −0.16 mrad, held in calm air), the
first antisymmetric mode ``asym_eta1`` [rad] and the modes' rolling moment
``modal_roll_n_m`` [N·m] = Q Σ R^η_i η_i + (Q/V) Σ R^η̇_i η̇_i at the trim's Q and V (the
quasi-static model: its η̇ is zero; the run's also holds the rolling moment of r and β on
the symmetric deflection, which from a rigid trim is of second order); the rigid model has
neither of the last two.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bioflex_jsb.flight_dynamics.wing_model import WingBuild
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.state_space import StateSpace

RIGID_CHANNELS = ("beta_rad", "p_rad_s", "r_rad_s", "phi_rad")
ELASTIC_CHANNELS = ("asym_eta1", "modal_roll_n_m")
UNITS = {"beta_rad": "rad", "p_rad_s": "rad/s", "r_rad_s": "rad/s", "phi_rad": "rad",
         "asym_eta1": "rad", "modal_roll_n_m": "N*m"}
INPUTS = ("v_g", "aileron", "p_g")  # the driven inputs, in this order


@dataclass(frozen=True)
class FullSpanLateralModel:
    """The linear lateral model of a full-span run: ``ss`` with the inputs v_g [m/s],
    aileron [rad], p_g [rad/s] (:data:`INPUTS`; module docstring) and the outputs of the
    lateral model; ``strips`` the antisymmetric strips (None for the rigid model), ``q_pa``
    and ``speed_m_s`` the trim's dynamic pressure [Pa] and airspeed [m/s]; ``roll_rows``
    the unsteady strips' rolling moment [N·m] on the states and on their rates (None:
    quasi-steady strips)."""

    ss: StateSpace
    strips: object | None
    q_pa: float
    speed_m_s: float
    roll_rows: tuple[np.ndarray, np.ndarray] | None = None


def full_span_lateral_model(build: WingBuild, airframe: Airframe, model: str,
                            speed_m_s: float, aileron=None, altitude_m: float = 0.0,
                            aero: str = "quasi-steady") -> FullSpanLateralModel:
    """The lateral model (module docstring) of the wing model ``model`` of ``build`` on the
    JSBSim ``airframe`` trimmed at ``speed_m_s`` [m/s], ``altitude_m`` [m]; ``aileron`` the
    run's :class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface` (None: none on
    the strips). The model is :func:`bioflex_jsb.api.lateral_model`'s (one builder:
    :func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`;
    ``aero="unsteady"``, coupled only: that model on the unsteady strips,
    :func:`~bioflex_jsb.aeroelasticity.antisymmetric.with_unsteady_strips`) with the inputs
    v_g, aileron, p_g."""
    from bioflex_jsb.aeroelasticity.antisymmetric_strips import lateral_model_with_aileron
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        antisymmetric_wing,
        build_lateral_elastic,
    )
    from bioflex_jsb.runtime.identification import identify_lateral

    point = identify_lateral(airframe, speed_m_s, build.airframe.reference, altitude_m)
    wing_a = None if model == "rigid" else antisymmetric_wing(build, point.trim.ixx_kg_m2)
    ss, strips = lateral_model_with_aileron(model, point.trim, point.aero, wing_a, aileron,
                                            build.aero.chord_m)
    rows = None
    if aero == "unsteady":
        ss, rows = _unsteady(ss, point.trim, build, wing_a)
    rigid = build_lateral_elastic("rigid", point.trim, point.aero, None)
    return FullSpanLateralModel(_with_gust_roll(ss, rigid), strips,
                                point.trim.dynamic_pressure_pa, point.trim.speed_m_s, rows)


def _unsteady(ss: StateSpace, trim, build: WingBuild, wing_a):
    """(the coupled model ``ss`` on the unsteady strips, the increments' rolling moment on
    its states and on their rates [N·m])."""
    from bioflex_jsb.aeroelasticity.antisymmetric import (
        Layout,
        aircraft_strips,
        strip_loads,
        with_unsteady_strips,
    )

    sections = aircraft_strips(build, wing_a, trim.ixx_kg_m2)
    unsteady = with_unsteady_strips(ss, trim, sections)
    n, k, n0 = sections.n_modes, sections.n_strips, ss.n_states
    layout = Layout(unsteady.n_states, 1, slice(4, 4 + n), slice(4 + n, n0),
                    (slice(n0, n0 + k), slice(n0 + k, n0 + 2 * k)))
    loads = strip_loads(sections, layout, trim.speed_m_s, trim.density_kg_m3,
                        quasi_steady=False, unsteady=True)
    return unsteady, (loads.roll_x, loads.roll_xd)


def _with_gust_roll(ss: StateSpace, rigid: StateSpace) -> StateSpace:
    """``ss`` with the inputs v_g, aileron, p_g (the rudder dropped; p_g's column: module
    docstring): in the β and φ rows the p column less the ``rigid`` model's (the kinematic
    w₀/V, C_Yp and φ̇ = p), so that the elastic side force of p − p_g stays."""
    p = ss.states.index("p")
    b_pg = -np.asarray(ss.a, dtype=float)[:, p].copy()
    a_rigid, p_rigid = np.asarray(rigid.a, dtype=float), rigid.states.index("p")
    for name in ("beta", "phi"):
        b_pg[ss.states.index(name)] += a_rigid[rigid.states.index(name), p_rigid]
    c, d = np.asarray(ss.c, dtype=float), np.asarray(ss.d, dtype=float)
    d_pg = np.zeros(len(ss.outputs))
    for i, name in enumerate(ss.outputs):  # a quasi-static model's η: its static response
        if name.startswith("eta") and name[3:].isdigit() and name not in ss.states:
            d_pg[i] = -c[i, p]
    cols = [ss.inputs.index(n) for n in INPUTS[:2]]
    b = np.column_stack([np.asarray(ss.b, dtype=float)[:, cols], b_pg])
    d = np.column_stack([d[:, cols], d_pg])
    units = tuple(ss.input_units[k] for k in cols) + ("rad/s",)
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=b, c=c, d=d,
                      states=ss.states, state_units=ss.state_units, inputs=INPUTS,
                      input_units=units, outputs=ss.outputs, output_units=ss.output_units,
                      notes={**ss.notes, "p_g": "gust roll rate, as p - p_g in the rolling "
                             "and yawing moments and on the strips (drivers/compare_lateral)"})


def respond(lm: FullSpanLateralModel, time_s, inputs: np.ndarray) -> dict[str, np.ndarray]:
    """The outputs of ``lm`` from rest under ``inputs`` (steps × :data:`INPUTS`, each held
    over its step) at the uniformly spaced ``time_s`` [s]: the compared channels (module
    docstring)."""
    from scipy.linalg import expm

    ss = lm.ss
    t = np.asarray(time_s, dtype=float)
    a, b = np.asarray(ss.a, dtype=float), np.asarray(ss.b, dtype=float)
    n, m = a.shape[0], b.shape[1]
    aug = np.zeros((n + m, n + m))
    aug[:n, :n], aug[:n, n:] = a, b
    e = expm(aug * float(t[1] - t[0]))
    phi, gam = e[:n, :n], e[:n, n:]
    u = np.asarray(inputs, dtype=float)
    x = np.zeros((t.size, n))
    for k in range(t.size - 1):
        x[k + 1] = phi @ x[k] + gam @ u[k]
    y = x @ np.asarray(ss.c, dtype=float).T + u @ np.asarray(ss.d, dtype=float).T
    out = dict(zip(ss.outputs, y.T, strict=True))
    channels = {c: out[s] for c, s in zip(RIGID_CHANNELS, ("beta", "p", "r", "phi"),
                                          strict=True)}
    if lm.strips is not None:
        s = lm.strips
        eta = np.column_stack([out[f"eta{i + 1}"] for i in range(s.n_modes)])
        roll = lm.q_pa * eta @ s.roll_eta
        if "eta1_dot" in out:  # the coupled model; the quasi-static one has η̇ = 0
            eta_dot = np.column_stack([out[f"eta{i + 1}_dot"] for i in range(s.n_modes)])
            roll = roll + lm.q_pa / lm.speed_m_s * eta_dot @ s.roll_etadot
        if lm.roll_rows is not None:  # the unsteady increments' (ẋ = A x + B u): the
            # strips see p − p_g, the apparent mass the body's ṗ
            x_dot = x @ a.T + u @ b.T
            roll_x, roll_xd = lm.roll_rows
            p_g = u[:, INPUTS.index("p_g")]
            roll = (roll + x @ roll_x - p_g * roll_x[ss.states.index("p")]
                    + x_dot @ roll_xd)
        channels["asym_eta1"] = eta[:, 0]
        channels["modal_roll_n_m"] = roll
    return channels


def closed_loop_respond(lm: FullSpanLateralModel, controller, dt_s: float, v_g, p_g
                        ) -> dict[str, np.ndarray]:
    """The outputs of ``lm`` with ``controller`` (a LinearController commanding the
    ``aileron``) in the loop at the run's step ``dt_s`` [s] with its one step of delay
    (:func:`~bioflex_jsb.simulation.closed_loop.close_loop`), from rest under the run's
    ``v_g`` [m/s] and ``p_g`` [rad/s] samples (the loop is linear: the two responses
    added): the compared channels and the command ``ctrl_aileron_rad``."""
    from bioflex_jsb.simulation.closed_loop import close_loop, lateral_signal_outputs
    from bioflex_jsb.simulation.closed_loop import respond as respond_closed

    plant = lateral_signal_outputs(lm.ss)
    out: dict[str, np.ndarray] = {}
    for name, samples in (("v_g", v_g), ("p_g", p_g)):
        if not np.any(samples):
            continue
        run = respond_closed(close_loop(plant, controller, dt_s, disturbance=name), samples)
        for key, values in run.channels.items():
            out[key] = out.get(key, 0.0) + np.asarray(values, dtype=float)
    size = np.asarray(p_g).size
    channels = {c: out.get(c, np.zeros(size)) for c in (*RIGID_CHANNELS, "ctrl_aileron_rad")}
    if lm.strips is not None:
        s = lm.strips
        eta = np.column_stack([out.get(f"asym_eta{i + 1}", np.zeros(size))
                               for i in range(s.n_modes)])
        roll = lm.q_pa * eta @ s.roll_eta
        if "asym_eta1_dot" in plant.outputs:  # the coupled model
            eta_dot = np.column_stack([out.get(f"asym_eta{i + 1}_dot", np.zeros(size))
                                       for i in range(s.n_modes)])
            roll = roll + lm.q_pa / lm.speed_m_s * eta_dot @ s.roll_etadot
        channels["asym_eta1"] = eta[:, 0]
        channels["modal_roll_n_m"] = roll
    return channels


def add_full_span_lateral(linear: TimeHistory, nonlinear: TimeHistory, build: WingBuild,
                          model: str, speed_m_s: float, airframe: Airframe, aileron=None,
                          aero: str = "quasi-steady", controller=None) -> None:
    """Add to ``linear`` the lateral model's response (module docstring) to what the
    full-span run ``nonlinear`` flew: its v_g, aileron and p_g (channels absent: zero); the
    run's strips ``aero``; with ``controller`` (commanding the aileron) the closed loop's to
    v_g and p_g (:func:`closed_loop_respond`), its command ``ctrl_aileron_rad`` too."""
    lm = full_span_lateral_model(build, airframe, model, speed_m_s, aileron, aero=aero)
    t = np.asarray(nonlinear.time_s, dtype=float)
    zeros = np.zeros(t.size)

    def flown(name: str) -> np.ndarray:
        return np.asarray(nonlinear[name], dtype=float) if name in nonlinear.channels \
            else zeros

    delta = flown("aileron_rad")
    inputs = np.column_stack([flown("v_g"), delta - (delta[0] if delta.size else 0.0),
                              flown("p_g")])
    if controller is None:
        response = respond(lm, t, inputs)
    else:
        dt = float(nonlinear.meta.get("dt_s") or t[1] - t[0])
        response = closed_loop_respond(lm, controller, dt, inputs[:, 0], inputs[:, 2])
        linear.channels["ctrl_aileron_rad"] = response.pop("ctrl_aileron_rad")
        linear.units["ctrl_aileron_rad"] = "rad"
    for name, values in response.items():
        # β, p, r, φ are the run's absolute values, the model's their increments over the
        # trim: the trim's own (its first sample) added
        start = float(nonlinear[name][0]) if name in RIGID_CHANNELS and t.size else 0.0
        linear.channels[name] = start + values
        linear.units[name] = UNITS[name]
    linear.meta["lateral_model"] = f"{lm.ss.model} (drivers/compare_lateral.py)"
