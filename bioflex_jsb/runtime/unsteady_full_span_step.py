"""Both wing halves on unsteady strips in the compiled coupled step: the parameter array,
state and columns of :func:`~bioflex_jsb.simulation.unsteady_full_span_kernel
.unsteady_full_span_kernel` bound for a :class:`~bioflex_jsb.runtime.coupled_step.CoupledStep`
with ``span="full"`` and ``aero="unsteady"`` (the physics: :mod:`bioflex_jsb.simulation
.unsteady_full_span`). The full-span step's closure (``_bind_full_span_step``) calls it as it
calls the quasi-steady full-span kernel: the same snapshot, reactions and refresh.
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb import units as U
from bioflex_jsb.simulation import step_kernel as K
from bioflex_jsb.simulation.limits import ETA_LIMIT_RAD

# The yaw rate's and sideslip's arrays of the block (YawSideslipTerms' names)
TERMS = ("force_r", "force_beta", "force_beta_s", "roll_r_s", "roll_beta_s", "side_eta",
         "side_dihedral_eta", "side_dihedral_etadot", "yaw_etadot", "yaw_p_s")


def setup_kernel(step) -> None:
    """One parameter array, state and column index for both wings of ``step`` (a
    CoupledStep whose unsteady half wing's kernel is set up): the half wing's block as
    ``_setup_kernel`` made it, the antisymmetric block after it, the sizes last; the
    half wing's views, state and reactions rebound onto them."""
    from bioflex_jsb.simulation import unsteady_full_span_kernel as UFK
    from bioflex_jsb.simulation import unsteady_kernel as UK
    from bioflex_jsb.simulation.full_span import full_span_columns, joined_state

    lat, n_s, wing = step.lateral, step.n_modes, step.wing
    n_a, n_k = lat.n_modes, lat.n_strips
    nxs = wing.state.size
    sym_size = step._params.size
    block, parts = UFK.new_block(n_a, n_s, n_k, sym_size)
    params = np.zeros(sym_size + block.size + UFK.N_DIMS)
    params[:sym_size] = step._params
    params[sym_size:sym_size + block.size] = block
    step._params = params
    step._views = {name: params[o:o + size]
                   for name, (o, size) in UK.layout(n_s, nxs).items()}
    lv = {name: params[sym_size + sl.start:sym_size + sl.stop] for name, sl in parts.items()}
    s, t = lat.strips, lat.terms
    lv["force_delta"][:] = s.force_delta
    lv["roll_eta"][:] = s.roll_eta
    lv["roll_etadot"][:] = s.roll_etadot
    lv["tip_anti"][:] = s.tip_twist_rad
    lv["tip_sym"][:] = lat.symmetric_tip_twist_rad
    lv["consts"][:] = (U.LBF_FT_PER_N_M, ETA_LIMIT_RAD, U.LBF_PER_N, step._weight_n,
                       t.induced_per_lift, lat.dt_s)
    for name in TERMS:
        lv[name][:] = np.ravel(getattr(t, name))
    lv["static_s"][:] = step._static_eta_s
    lv["key"][:] = np.nan  # no reference yet: the first step asks for one
    step._lat_views = lv
    params[-UFK.N_DIMS:] = (sym_size, step._cols.size, nxs, n_s, n_a, n_k)
    step._reactions = lv["reactions"]  # lift, drag, pitch, roll, side, yaw (lbf, lbf·ft)
    step._out_flow = step._views["out_flow"]
    step._x_full, wing._x, lat._x = joined_state(wing._x, lat._x)  # views: the kernel updates x
    step._cols = np.concatenate([step._cols, full_span_columns(step.names, n_a)])
    step._kernel = UFK.unsteady_full_span_kernel
    K.say_if_compiling(step._kernel, "full-span unsteady step")
    if lat._key is not None:
        load_reference(step)


def load_reference(step) -> None:
    """Copy the antisymmetric wing's reference step (after its ``reference``) into the
    parameter array: Φ and its changes, Ψ B and its changes, the increments' load rows."""
    lat, lv = step.lateral, step._lat_views
    lv["stack"][:] = np.ravel(lat._stack)
    lv["psi_b"][:] = np.ravel(lat._psi_b)
    lv["rows"][:] = np.ravel(np.stack([c["rows"][:2] for c in lat._continuous]))
    lv["key"][:] = lat._key
