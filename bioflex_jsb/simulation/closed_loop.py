"""The LTI model with a controller in the loop, as the co-simulation flies it.

:func:`signal_outputs` gives the linear model (Eq. 4 with its controls and, where built, its
load outputs: :func:`bioflex_jsb.loads.lti.with_load_outputs`) the run's signals as outputs,
named and measured as the channels a controller reads (perturbations from the trim):
``alpha`` the aerodynamic angle α + w_g/u₀ (the model's state α is the inertial one, kept as
``alpha_inertial``), ``n_z`` the load-factor perturbation, ``w_g``, ``airspeed_m_s`` (= u),
``theta_rad`` and ``alpha_rad`` (= θ, α), the modal coordinates and rates.

:func:`close_loop` closes it with a :class:`~bioflex_jsb.simulation.controller.
LinearController` at the run's step Δt: the plant held over each step (zero-order hold),
the controller's difference equation on the signals of step k, and its commands reaching
the plant ``delay_steps`` later (the co-simulation's one step:
:mod:`bioflex_jsb.simulation.controller`, "Timing"):

    s_k = C_s x_k + D_sw w_k + D_su v_k                (signals; v the commands applied)
    c_k = C_c ξ_k + D_c s_k,  ξ_{k+1} = A_c ξ_k + B_c s_k   (the controller)
    x_{k+1} = Φ x_k + Γ_w w_k + Γ_u v_k,  v_k = c_{k−1}     (delay 1; delay 0: v_k = c_k)

The result is a discrete :class:`~bioflex_jsb.state_space.StateSpace` from ``w_g`` to every
output of the plant and the commands (``ctrl_<command>``); :func:`respond` is its time
response as a run's history (``n_z`` 1 + its perturbation, as the runs log it).

**The lateral axis** (a full-span run's controller commanding the ``aileron``):
:func:`lateral_signal_outputs` gives the lateral model (β, p, r, φ and the antisymmetric
modes, ``docs/lateral.md``; inputs v_g, aileron, p_g as ``drivers/compare_lateral.py``
builds it from the run's JSBSim airframe) the run's channel names as outputs (``beta_rad``,
``p_rad_s``, ``r_rad_s``, ``phi_rad``, ``asym_eta<i>``, ``asym_eta<i>_dot``), and
:func:`close_loop` closes it with the controller the same way, its disturbance the gust
roll rate ``p_g`` [rad/s] (or the lateral gust ``v_g`` [m/s]): the aileron written to
JSBSim before its step k reaches the rigid forces of x_{k+1} and the antisymmetric modes,
which read JSBSim's aileron positions at step k+1, both one step late as the elevator's.
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.controller import (
    COMMAND_CHANNELS,
    CONTROL_OUTPUTS,
    LinearController,
)
from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.state_space import StateSpace

GUST = "w_g"
# The lateral model's states and the run's channels they are (the antisymmetric modes:
# eta<i> -> asym_eta<i>, simulation/full_span.py lateral_names)
LATERAL_SIGNALS = {"beta": "beta_rad", "p": "p_rad_s", "r": "r_rad_s", "phi": "phi_rad"}
LATERAL_DISTURBANCES = ("p_g", "v_g")


def signal_outputs(ss: StateSpace) -> StateSpace:
    """``ss`` (continuous; states u, α, q, θ, η_i, η̇_i; inputs w_g and the controls; an
    ``n_z`` output, the perturbation) with the run's signals as outputs (module
    docstring), its other outputs (the loads, tip_twist) after them."""
    if not ss.continuous or GUST not in ss.inputs:
        raise ValueError("signal_outputs takes a continuous model with the gust input w_g")
    st, n, m = ss.states, ss.n_states, len(ss.inputs)
    ig = ss.inputs.index(GUST)
    if "n_z" not in ss.outputs:
        raise ValueError("the model needs its n_z output (build_state_space(controls=True))")

    def state(name: str) -> tuple[np.ndarray, np.ndarray]:
        c = np.zeros(n)
        c[st.index(name)] = 1.0
        return c, np.zeros(m)

    def output(name: str) -> tuple[np.ndarray, np.ndarray]:
        i = ss.outputs.index(name)
        return ss.c[i], ss.d[i]

    alpha_c, alpha_d = state("alpha")
    aero_d = alpha_d.copy()
    aero_d[ig] = 1.0 / ss.speed_m_s
    gust_d = np.zeros(m)
    gust_d[ig] = 1.0
    rows: dict[str, tuple[np.ndarray, np.ndarray, str]] = {
        "u": (*state("u"), "m/s"), "alpha": (alpha_c, aero_d, "rad"),
        "q": (*state("q"), "rad/s"), "theta": (*state("theta"), "rad"),
        "n_z": (*output("n_z"), "-"), "w_g": (np.zeros(n), gust_d, "m/s"),
        "airspeed_m_s": (*state("u"), "m/s"), "theta_rad": (*state("theta"), "rad"),
        "alpha_rad": (alpha_c, aero_d, "rad"), "alpha_inertial": (alpha_c, alpha_d, "rad"),
    }
    for name in st[4:]:  # eta<i>, eta<i>_dot
        rows[name] = (*state(name), ss.state_units[st.index(name)])
    rest = [o for o in ss.outputs if o not in rows and o not in st]
    names = tuple(rows) + tuple(rest)
    c = np.vstack([r[0] for r in rows.values()] + [ss.c[ss.outputs.index(o)] for o in rest])
    d = np.vstack([r[1] for r in rows.values()] + [ss.d[ss.outputs.index(o)] for o in rest])
    units = tuple(r[2] for r in rows.values()) + tuple(
        ss.output_units[ss.outputs.index(o)] for o in rest)
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=ss.b, c=c, d=d,
                      states=st, state_units=ss.state_units, inputs=ss.inputs,
                      input_units=ss.input_units, outputs=names, output_units=units,
                      notes={**ss.notes, "signals": "the run's channels, perturbations "
                             "(simulation/closed_loop.py)"})


def lateral_signal_outputs(ss: StateSpace) -> StateSpace:
    """The lateral model ``ss`` (continuous; states β, p, r, φ and, coupled, η_i, η̇_i of the
    antisymmetric modes; a quasi-static model's η_i outputs) with its outputs named as the
    run's channels (module docstring, "The lateral axis"); the others (``n_y``) kept."""
    if not ss.continuous or not all(s in ss.states for s in LATERAL_SIGNALS):
        raise ValueError("lateral_signal_outputs takes a continuous lateral model (states "
                         "beta, p, r, phi)")

    def channel(name: str) -> str:
        if name in LATERAL_SIGNALS:
            return LATERAL_SIGNALS[name]
        if name.startswith("eta") and name[3:].split("_")[0].isdigit():
            return "asym_" + name
        return name

    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=ss.b, c=ss.c, d=ss.d,
                      states=ss.states, state_units=ss.state_units, inputs=ss.inputs,
                      input_units=ss.input_units,
                      outputs=tuple(channel(o) for o in ss.outputs),
                      output_units=ss.output_units,
                      notes={**ss.notes, "signals": "the run's channels, perturbations "
                             "(simulation/closed_loop.py)"})


def close_loop(plant: StateSpace, controller: LinearController, dt_s: float,
               delay_steps: int = 1, disturbance: str = GUST) -> StateSpace:
    """The discrete closed loop at the step ``dt_s`` [s] (module docstring): ``plant`` a
    continuous model with the run's signals as outputs (:func:`signal_outputs`,
    :func:`lateral_signal_outputs`) and the controller's commands among its inputs;
    ``delay_steps`` 1 (the co-simulation) or 0; ``disturbance`` the plant's input the closed
    loop is driven by (``w_g``; the lateral model's ``p_g`` or ``v_g``). InputError (one
    line) for a signal the model does not have, a command it has no input for, or a
    controller that samples slower than the step."""
    if delay_steps not in (0, 1):
        raise ValueError("delay_steps is 0 or 1")
    if disturbance not in plant.inputs:
        raise InputError(f"the linear model has no input {disturbance!r} to be driven by "
                         f"(its inputs: {', '.join(plant.inputs)})")
    missing = [s for s in controller.inputs if s not in plant.outputs]
    if missing:
        raise InputError(f"the linear model has no signal {missing[0]!r} for the controller "
                         f"(it has {', '.join(plant.outputs[:12])}, ...)")
    absent = [o for o in controller.outputs if o not in plant.inputs]
    if absent:
        raise InputError(f"the linear model has no input {absent[0]!r} for the controller's "
                         "command (a model with controls: build_state_space(controls=True))")
    ctrl, every = controller.at_step(dt_s)
    if every != 1:
        raise InputError(f"controller {controller.name!r} samples every {every} steps: the "
                         "closed-loop LTI model is for a controller at the run's step")
    pd = plant.to_discrete(dt_s)
    ig = plant.inputs.index(disturbance)
    iu = [plant.inputs.index(o) for o in controller.outputs]
    isig = [plant.outputs.index(s) for s in controller.inputs]
    n, nc, nu = plant.n_states, ctrl.n_states, len(iu)
    phi, gam_w, gam_u = pd.a, pd.b[:, ig], pd.b[:, iu]
    c_s, d_sw, d_su = plant.c[isig], plant.d[isig, ig], plant.d[np.ix_(isig, iu)]
    ac, bc, cc, dc = ctrl.a, ctrl.b, ctrl.c, ctrl.d
    c_y, d_yw, d_yu = plant.c, plant.d[:, ig], plant.d[:, iu]
    if delay_steps == 1:  # z = [x, ξ, v]: v_k = c_{k−1}
        nz = n + nc + nu
        a = np.zeros((nz, nz))
        b = np.zeros((nz, 1))
        a[:n, :n], a[:n, n + nc:] = phi, gam_u
        b[:n, 0] = gam_w
        a[n:n + nc, :n], a[n:n + nc, n:n + nc] = bc @ c_s, ac
        a[n:n + nc, n + nc:] = bc @ d_su
        b[n:n + nc, 0] = bc @ d_sw
        a[n + nc:, :n], a[n + nc:, n:n + nc] = dc @ c_s, cc
        a[n + nc:, n + nc:] = dc @ d_su
        b[n + nc:, 0] = dc @ d_sw
        # outputs: the plant's with v the state; the commands c_k
        c_cmd = np.hstack([dc @ c_s, cc, dc @ d_su])
        d_cmd = dc @ d_sw
        c_out = np.vstack([np.hstack([c_y, np.zeros((len(c_y), nc)), d_yu]), c_cmd])
        d_out = np.concatenate([d_yw, d_cmd])[:, None]
        states = plant.states + tuple(f"ctrl_x{i + 1}" for i in range(nc)) + tuple(
            f"applied_{o}" for o in controller.outputs)
        units = plant.state_units + ("-",) * nc + tuple(
            CONTROL_OUTPUTS[o] for o in controller.outputs)
    else:  # v_k = c_k: (I − D_c D_su) v = C_c ξ + D_c (C_s x + D_sw w)
        solve = np.linalg.inv(np.eye(nu) - dc @ d_su)
        kx, kxi, kw = solve @ dc @ c_s, solve @ cc, solve @ dc @ d_sw
        nz = n + nc
        a = np.zeros((nz, nz))
        b = np.zeros((nz, 1))
        a[:n, :n], a[:n, n:] = phi + gam_u @ kx, gam_u @ kxi
        b[:n, 0] = gam_w + gam_u @ kw
        sx, sxi, sw = c_s + d_su @ kx, d_su @ kxi, d_sw + d_su @ kw
        a[n:, :n], a[n:, n:] = bc @ sx, ac + bc @ sxi
        b[n:, 0] = bc @ sw
        c_out = np.vstack([np.hstack([c_y + d_yu @ kx, d_yu @ kxi]), np.hstack([kx, kxi])])
        d_out = np.concatenate([d_yw + d_yu @ kw, kw])[:, None]
        states = plant.states + tuple(f"ctrl_x{i + 1}" for i in range(nc))
        units = plant.state_units + ("-",) * nc
    commands = tuple(COMMAND_CHANNELS[o] for o in controller.outputs)
    return StateSpace(
        model=f"{plant.model}+{controller.name}", speed_m_s=plant.speed_m_s, a=a, b=b,
        c=c_out, d=d_out, states=states, state_units=units, inputs=(disturbance,),
        input_units=(plant.input_units[ig],), outputs=plant.outputs + commands,
        output_units=plant.output_units + tuple(CONTROL_OUTPUTS[o]
                                                for o in controller.outputs),
        notes={**plant.notes, "controller": controller.name, "delay_steps": delay_steps},
        dt_s=float(dt_s))


def respond(cl: StateSpace, w_g_m_s: np.ndarray) -> TimeHistory:
    """The time response of the discrete closed loop ``cl`` to the samples ``w_g_m_s`` of
    its disturbance at its steps (the gust [m/s]; a lateral loop's p_g [rad/s] or v_g
    [m/s]), from the trim: a history with every output as a channel, ``n_z`` 1 + its
    perturbation (the runs' load factor)."""
    if cl.continuous:
        raise ValueError("respond takes a discrete model (close_loop)")
    w = np.asarray(w_g_m_s, dtype=float)
    x = np.zeros(cl.n_states)
    xs = np.empty((len(w), cl.n_states))
    a, b = cl.a, cl.b[:, 0]
    for k in range(len(w)):
        xs[k] = x
        x = a @ x + b * w[k]
    y = xs @ cl.c.T + np.outer(w, cl.d[:, 0])
    channels = {name: y[:, i] for i, name in enumerate(cl.outputs)}
    if "n_z" in channels:
        channels["n_z"] = 1.0 + channels["n_z"]
    units = dict(zip(cl.outputs, cl.output_units, strict=True))
    time_s = np.arange(len(w)) * cl.dt_s
    return TimeHistory(cl.model, time_s, channels, units,
                       {"source": "lti", "speed_m_s": cl.speed_m_s, "dt_s": cl.dt_s})
