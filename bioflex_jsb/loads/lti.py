"""Section loads as outputs of the LTI model (Eq. 4): y = C x + D w_g.

The loads are perturbations from the 1 g trim (:meth:`LoadsModel.static_loads` adds the
static part). Mode displacement is exact in the states: ΔM = K_md Δη (Δη the coupled
model's states, or the QSD model's η outputs). Force summation is linear in the signals z
(:func:`bioflex_jsb.loads.model.signal_names`), and each signal, linearised about the trim,
is a row of the state, its derivative or the input (ΔQ = ρ u₀ Δu):

* Q α_s → ΔQ (α_w + Δα_trim) + Q₀ (α + w_g/u₀)   (α the inertial angle, the state)
* Q q/V → Q₀ q / u₀;   Q η_i → ΔQ η₀_i + Q₀ Δη_i;   Q η̇_i/V → Q₀ Δη̇_i / u₀;   Q → ΔQ
* g n_z → u₀ (q − α̇) (the n_z output of ``lti._with_outputs``)
* q̇ and η̈ → rows of A x + B w_g (the state derivative)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import StateSpace
from bioflex_jsb.loads.model import QUANTITIES, QUANTITY_UNITS, LoadsModel


@dataclass(frozen=True)
class LoadOutputs:
    """Loads output matrices of a :class:`StateSpace`: ``c`` (rows, states), ``d`` (rows,
    inputs: the gust's column, and the controls' of a model with them) per method; row names
    ``<fs|md>_<quantity>_s<j>`` and units; ``static`` the 1 g loads of the rows."""

    names: tuple[str, ...]
    units: tuple[str, ...]
    c: np.ndarray
    d: np.ndarray
    static: np.ndarray


def _signal_rows(ss: StateSpace, lm: LoadsModel) -> tuple[np.ndarray, ...]:
    """(Z_x, Z_w, E_x, E_w): the signals' perturbation z = Z_x x + Z_w w_g and the modal
    deflection Δη = E_x x + E_w w_g (module docstring). The other inputs' columns (the
    elevator, the throttle: they reach the wing's loads through n_z and q̇ alone, the tail
    and the thrust line being off the wing): :func:`_input_signal_column`."""
    n = lm.n_modes
    nx = ss.n_states
    u0, q0, rho = lm.speed_m_s, lm.dynamic_pressure_pa, lm.density_kg_m3
    if abs(ss.speed_m_s - u0) > 1e-9:
        raise InputError(f"the LTI model is at {ss.speed_m_s:g} m/s, the loads model at {u0:g}")
    st = ss.states
    iu, ia, iq = st.index("u"), st.index("alpha"), st.index("q")
    ig = ss.inputs.index("w_g")
    a, b = ss.a, ss.b[:, ig]

    def unit(i):
        e = np.zeros(nx)
        e[i] = 1.0
        return e

    if ss.model == "coupled":
        eta_x = np.vstack([unit(st.index(f"eta{i + 1}")) for i in range(n)])
        eta_w = np.zeros(n)
        etad_x = np.vstack([unit(st.index(f"eta{i + 1}_dot")) for i in range(n)])
        acc_x, acc_w = a[[st.index(f"eta{i + 1}_dot") for i in range(n)]], \
            b[[st.index(f"eta{i + 1}_dot") for i in range(n)]]
    elif ss.model == "qsd":
        rows = [ss.outputs.index(f"eta{i + 1}") for i in range(n)]
        eta_x, eta_w = ss.c[rows], ss.d[rows, ig]
        etad_x, acc_x, acc_w = np.zeros((n, nx)), np.zeros((n, nx)), np.zeros(n)
    else:
        eta_x, eta_w = np.zeros((n, nx)), np.zeros(n)
        etad_x, acc_x, acc_w = np.zeros((n, nx)), np.zeros((n, nx)), np.zeros(n)
    dq_x = rho * u0 * unit(iu)  # ΔQ per state
    zx = np.zeros((5 + 3 * n, nx))
    zw = np.zeros(5 + 3 * n)
    zx[0] = dq_x * (lm.alpha_wing_rad + lm.static_alpha_rad) + q0 * unit(ia)
    zw[0] = q0 / u0
    zx[1] = q0 / u0 * unit(iq)
    zx[2:2 + n] = np.outer(lm.static_eta_rad, dq_x) + q0 * eta_x
    zw[2:2 + n] = q0 * eta_w
    zx[2 + n:2 + 2 * n] = q0 / u0 * etad_x
    zx[2 + 2 * n] = dq_x
    zx[3 + 2 * n] = u0 * (unit(iq) - a[ia])
    zw[3 + 2 * n] = -u0 * b[ia]
    zx[4 + 2 * n], zw[4 + 2 * n] = a[iq], b[iq]
    zx[5 + 2 * n:] = acc_x
    zw[5 + 2 * n:] = acc_w
    return zx, zw, eta_x, eta_w


def _input_signal_column(ss: StateSpace, lm: LoadsModel, j: int) -> tuple[np.ndarray, ...]:
    """(Z_u, E_u) of the input ``j`` that is not the gust (an elevator [rad], a throttle
    [-]): it enters the force summation through the state derivative alone, g n_z (−u₀ of
    the α row's B), q̇ and η̈ (their rows of B), and the QSD model's η through its D."""
    n = lm.n_modes
    st = ss.states
    ia, iq = st.index("alpha"), st.index("q")
    b = ss.b[:, j]
    zu = np.zeros(5 + 3 * n)
    eta_u = np.zeros(n)
    if ss.model == "qsd":
        eta_u = ss.d[[ss.outputs.index(f"eta{i + 1}") for i in range(n)], j]
        zu[2:2 + n] = lm.dynamic_pressure_pa * eta_u
    elif ss.model == "coupled":
        zu[5 + 2 * n:] = b[[st.index(f"eta{i + 1}_dot") for i in range(n)]]
    zu[3 + 2 * n] = -lm.speed_m_s * b[ia]
    zu[4 + 2 * n] = b[iq]
    return zu, eta_u


def load_outputs(ss: StateSpace, lm: LoadsModel) -> LoadOutputs:
    """C_loads, D_loads of ``ss`` (rigid, coupled or qsd) for ``lm``'s stations: force
    summation rows first, then mode displacement (not for ``rigid``, nor for a wing without
    EI, GJ: ``lm.md_matrix`` None). D has a column per input of ``ss``: the gust's, and
    for a model with controls (the elevator, the throttle) theirs, which reach the loads
    through n_z, q̇ and η̈ (:func:`_input_signal_column`)."""
    zx, zw, eta_x, eta_w = _signal_rows(ss, lm)
    ig = ss.inputs.index("w_g")
    s = lm.n_stations
    names = [f"fs_{q}_s{j}" for q in QUANTITIES for j in range(s)]
    static_all = lm.static_loads()
    c = [lm.fs_matrix @ zx]
    dw = [lm.fs_matrix @ zw]
    others = [j for j in range(ss.b.shape[1]) if j != ig]
    columns = {j: _input_signal_column(ss, lm, j) for j in others}
    du = {j: [lm.fs_matrix @ columns[j][0]] for j in others}
    if "flaperon" in ss.inputs and lm.flaperon is not None:  # its strips' own loads
        du[ss.inputs.index("flaperon")][0] += lm.dynamic_pressure_pa * lm.flaperon.fs_rows
    elif "flaperon" in ss.inputs:
        raise InputError("the model has a flaperon input: give the loads model its "
                         "flaperon (loads.flaperon.with_flaperon)")
    static = [static_all["force_summation"].reshape(-1)]
    if ss.model != "rigid" and lm.md_matrix is not None:
        names += [f"md_{q}_s{j}" for q in QUANTITIES for j in range(s)]
        c.append(lm.md_matrix @ eta_x)
        dw.append(lm.md_matrix @ eta_w)
        for j in others:
            du[j].append(lm.md_matrix @ columns[j][1])
        static.append(static_all["mode_displacement"].reshape(-1))
    d = np.zeros((len(names), ss.b.shape[1]))
    d[:, ig] = np.concatenate(dw)
    for j in others:
        d[:, j] = np.concatenate(du[j])
    units = tuple(QUANTITY_UNITS[nm.split("_", 1)[1].rsplit("_s", 1)[0]] for nm in names)
    return LoadOutputs(tuple(names), units, np.vstack(c), d, np.concatenate(static))


def with_load_outputs(ss: StateSpace, lm: LoadsModel) -> StateSpace:
    """``ss`` with the loads rows appended to its outputs (perturbations from 1 g:
    ``notes['loads_static']`` holds the 1 g values)."""
    lo = load_outputs(ss, lm)
    notes = dict(ss.notes, loads_static=dict(zip(lo.names, lo.static.tolist(), strict=True)),
                 loads_stations_m=lm.stations_m.tolist())
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=ss.b,
                      c=np.vstack([ss.c, lo.c]), d=np.vstack([ss.d, lo.d]), states=ss.states,
                      state_units=ss.state_units, inputs=ss.inputs, input_units=ss.input_units,
                      outputs=ss.outputs + lo.names, output_units=ss.output_units + lo.units,
                      notes=notes)
