"""Both wing halves on unsteady strips, compiled: the half wing's unsteady kernel and the
antisymmetric unsteady wing in one call.

:func:`unsteady_full_span_kernel` takes the arguments of the full-span kernel
(:func:`~bioflex_jsb.simulation.full_span_kernel.full_span_kernel`: the snapshot with its
:data:`~bioflex_jsb.simulation.full_span_kernel.EXTRA_READS`, the parameter array, state and
columns of both wings end to end) with the half wing's block laid out by
:func:`~bioflex_jsb.simulation.unsteady_kernel.layout` (read by
:func:`~bioflex_jsb.simulation.unsteady_kernel.unsteady_kernel` as it is), the antisymmetric
block after it (:func:`lateral_layout`, its own header of absolute offsets first) and
:data:`N_DIMS` sizes last. It does the arithmetic of
:class:`~bioflex_jsb.simulation.unsteady_full_span.UnsteadyAntisymmetricWing` (the reference
it is tested against): the inputs u = [p − p_g, ṗ, generalised force] held over the step,

    z_{k+1} = (Φ + ΔQ Φ_Q + Δ(Q/V) Φ_{Q/V}) z_k + (Ψ B + ΔQ Ψ B_Q + Δ(Q/V) Ψ B_{Q/V}) u,

the increments' rolling moment and side force of [z_{k+1}, u] to first order about the
reference, the quasi-steady full-span terms beside them, the reactions (lbf·ft, lbf,
lbf·ft) and the row's full-span channels.
"""

from __future__ import annotations

import numba
import numpy as np

from bioflex_jsb.simulation import unsteady_kernel as UK
from bioflex_jsb.simulation.full_span_kernel import (
    BETA_SLOT,
    EXTRA_READS,
    finish_lateral,
    modal_loads,
    start_lateral,
)
from bioflex_jsb.simulation.step_kernel import (
    NEEDS_REFRESH,
    READ_KEYS,
    air_flow,
    guard_cache,
)

# Where the snapshot's entries sit (step_kernel.READ_KEYS, then full_span_kernel.EXTRA_READS)
R_Q, R_P, R_R, R_NZ = (READ_KEYS.index(key) for key in ("q", "p", "r", "nz"))
R_LEFT, R_RIGHT, R_PG = (len(READ_KEYS) + EXTRA_READS.index(key)
                         for key in ("left_aileron", "right_aileron", "p_g"))

# The sizes at the end of params: (half wing's params, its cols, its states, n_s, n_a,
# strips)
N_DIMS = 6
# N·m→lbf·ft, η limit [rad], N→lbf, the weight W [N], 1/(π b²) [1/m²], the step [s]
N_LAT_CONSTS = 6
# The antisymmetric block's parts, in order; its header holds each part's absolute offset
LAT_BLOCKS = ("header", "stack", "psi_b", "rows", "key", "force_delta", "roll_eta",
              "roll_etadot", "tip_anti", "reactions", "consts", "last", "u", "scratch",
              "force_r", "force_beta", "force_beta_s", "roll_r_s", "roll_beta_s", "side_eta",
              "side_dihedral_eta", "side_dihedral_etadot", "yaw_etadot", "yaw_p_s",
              "static_s", "tip_sym")
(L_STACK, L_PSI, L_ROWS, L_KEY, L_FD, L_RE, L_RD, L_TA, L_REACT, L_C, L_LAST, L_U, L_SCR,
 L_FR, L_FB, L_FBS, L_RRS, L_RBS, L_SE, L_SGE, L_SGD, L_YD, L_YPS, L_SS, L_TS) = range(
    1, len(LAT_BLOCKS))
N_HEADER = len(LAT_BLOCKS)


def lateral_layout(n_modes: int, n_symmetric: int, n_strips: int
                   ) -> dict[str, tuple[int, int]]:
    """The antisymmetric block (``n_modes`` antisymmetric modes with 2 ``n_strips`` lag
    states, ``n_symmetric`` symmetric modes): name → (offset from the block's start,
    length). ``stack`` (3 n_z × n_z) Φ, Φ_Q, Φ_{Q/V}; ``psi_b`` (3, n_z, n_u) Ψ B and its
    changes; ``rows`` (3, 2, n_z + n_u) the increments' rolling moment and side force and
    their changes; ``key`` (Q_r, V_r); ``last`` (stepped yet, p [rad/s]) of the last step;
    ``u`` its inputs; the quasi-steady arrays as the full-span kernel's."""
    n, ns = n_modes, n_symmetric
    nz, nu = 2 * n + 2 * n_strips, n + 2
    sizes = {"header": len(LAT_BLOCKS), "stack": 3 * nz * nz, "psi_b": 3 * nz * nu,
             "rows": 3 * 2 * (nz + nu), "key": 2, "force_delta": n, "roll_eta": n,
             "roll_etadot": n, "tip_anti": n, "reactions": 6, "consts": N_LAT_CONSTS,
             "last": 2, "u": nu, "scratch": nz, "force_r": n, "force_beta": n,
             "force_beta_s": n * ns, "roll_r_s": ns, "roll_beta_s": ns, "side_eta": n,
             "side_dihedral_eta": n, "side_dihedral_etadot": n, "yaw_etadot": n,
             "yaw_p_s": ns, "static_s": ns, "tip_sym": ns}
    out, offset = {}, 0
    for name in LAT_BLOCKS:
        out[name] = (offset, sizes[name])
        offset += sizes[name]
    return out


@numba.njit(cache=True, nogil=True, fastmath=UK.FASTMATH)
def _advance(stack, psi, z, u, new, dq, ds):
    """new = (Φ + ΔQ Φ_Q + Δs Φ_s) z + (Ψ B + ΔQ Ψ B_Q + Δs Ψ B_s) u, row by row."""
    nz, nu = z.shape[0], u.shape[0]
    for i in range(nz):
        a = 0.0
        for j in range(nz):
            a += (stack[0, i, j] + dq * stack[1, i, j] + ds * stack[2, i, j]) * z[j]
        for c in range(nu):
            a += (psi[0, i, c] + dq * psi[1, i, c] + ds * psi[2, i, c]) * u[c]
        new[i] = a


@numba.njit(cache=True, nogil=True, fastmath=UK.FASTMATH)
def _increments(rows, z, u, dq, ds, which):
    """Row ``which`` (0 rolling moment, 1 side force) of the increments' loads on [z, u]."""
    nz, nu = z.shape[0], u.shape[0]
    a = 0.0
    for j in range(nz):
        a += (rows[0, which, j] + dq * rows[1, which, j] + ds * rows[2, which, j]) * z[j]
    for c in range(nu):
        j = nz + c
        a += (rows[0, which, j] + dq * rows[1, which, j] + ds * rows[2, which, j]) * u[c]
    return a


@numba.njit(cache=True, nogil=True)
def unsteady_full_span_kernel(reads, params, x, cols, table, k, wind_down_fps, w_g):
    """One full-span step on unsteady strips (module docstring), writing row ``k`` of
    ``table``; returns the half wing's status codes (NEEDS_REFRESH: renew both references
    at the half wing's out_flow, nothing done; NON_FINITE; ALPHA_OUT; ETA_OUT)."""
    size = params.shape[0]
    p_sym = int(params[size - 6])
    c_sym = int(params[size - 5])
    nxs = int(params[size - 4])
    ns = int(params[size - 3])
    na = int(params[size - 2])
    nk = int(params[size - 1])
    nz, nu = 2 * na + 2 * nk, na + 2
    h = params[p_sym:p_sym + N_HEADER]  # the antisymmetric block's offsets
    o_key, o_c, o_last = int(h[L_KEY]), int(h[L_C]), int(h[L_LAST])
    o_u, o_scr = int(h[L_U]), int(h[L_SCR])
    key0, key1 = params[o_key], params[o_key + 1]
    # both references are renewed together at one flow: a key that is not the half wing's
    # (none yet: NaN) asks for a renewal at this flow
    o_key_s, o_flow = int(params[UK.H_KEY]), int(params[UK.H_FLOW])
    if not (key0 == params[o_key_s] and key1 == params[o_key_s + 1]):
        o_cs = int(params[UK.H_C])
        va, vt_fps, vt, alpha, qbar = air_flow(reads, wind_down_fps, params[o_cs],
                                                params[o_cs + 1])
        params[o_flow], params[o_flow + 1] = alpha, reads[R_Q]
        params[o_flow + 2], params[o_flow + 3] = qbar, vt
        return NEEDS_REFRESH
    xs = x[:nxs]
    xa = x[nxs:nxs + nz]
    base = c_sym  # the full-span channels' columns: LATERAL_FIXED, η_a, η̇_a
    row = table[k]
    o_ts, o_ta, o_ss, o_fbs = int(h[L_TS]), int(h[L_TA]), int(h[L_SS]), int(h[L_FBS])
    u = params[o_u:o_u + nu]  # [p − p_g, ṗ, the generalised forces]
    tip, anti = start_lateral(params, xs, xa, row, cols, base, ns, na, o_ts, o_ta, o_ss,
                              o_fbs, o_u + 2)
    status = UK.unsteady_kernel(reads, params[:p_sym], xs, cols[:c_sym], table, k,
                                wind_down_fps, w_g)
    if status == NEEDS_REFRESH:
        return status
    qbar, vt = params[o_flow + 2], params[o_flow + 3]  # the flow of t_k
    aileron = 0.5 * (reads[R_LEFT] - reads[R_RIGHT])  # JSBSim's δa: + rolls right
    qv = qbar / vt
    p_rate, r_rate = reads[R_P], reads[R_R]
    beta = row[cols[BETA_SLOT]]  # the row's β of t_k
    lift = reads[R_NZ] * params[o_c + 3]  # the wing's lift n_z W [N]
    o_fr, o_fb, o_fd = int(h[L_FR]), int(h[L_FB]), int(h[L_FD])
    for i in range(na):
        u[2 + i] = (lift * r_rate / vt * params[o_fr + i]
                    + qbar * beta * (params[o_fb + i] + u[2 + i])
                    - qbar * params[o_fd + i] * aileron)
    u[0] = p_rate - reads[R_PG]
    u[1] = 0.0 if params[o_last] == 0.0 else (p_rate - params[o_last + 1]) / params[o_c + 5]
    params[o_last], params[o_last + 1] = 1.0, p_rate
    dq, ds = qbar - key0, qv - key0 / key1
    o_st, o_psi, o_rows = int(h[L_STACK]), int(h[L_PSI]), int(h[L_ROWS])
    stack = params[o_st:o_st + 3 * nz * nz].reshape((3, nz, nz))
    psi = params[o_psi:o_psi + 3 * nz * nu].reshape((3, nz, nu))
    rows = params[o_rows:o_rows + 6 * (nz + nu)].reshape((3, 2, nz + nu))
    new = params[o_scr:o_scr + nz]
    _advance(stack, psi, xa, u, new, dq, ds)
    for i in range(nz):
        xa[i] = new[i]
    moment = _increments(rows, xa, u, dq, ds, 0)
    side = _increments(rows, xa, u, dq, ds, 1)
    o_re, o_rd = int(h[L_RE]), int(h[L_RD])
    o_rrs, o_rbs, o_yps = int(h[L_RRS]), int(h[L_RBS]), int(h[L_YPS])
    o_se, o_sge, o_sgd, o_yd = int(h[L_SE]), int(h[L_SGE]), int(h[L_SGD]), int(h[L_YD])
    moment, side, yaw = modal_loads(params, xs, xa, ns, na, qbar, qv, vt, lift, p_rate, r_rate,
                                    beta, moment, side, params[o_c + 4], o_re, o_rd, o_ss,
                                    o_rrs, o_rbs, o_yps, o_se, o_sge, o_sgd, o_yd)
    return finish_lateral(params, row, cols, base, na, xa, status, int(h[L_REACT]),
                          int(params[UK.H_REACT]), params[o_c], params[o_c + 2],
                          params[o_c + 1], aileron, moment, tip, anti, side, yaw)


guard_cache(_advance)
guard_cache(_increments)
guard_cache(unsteady_full_span_kernel)


def new_block(n_modes: int, n_symmetric: int, n_strips: int, start: int
              ) -> tuple[np.ndarray, dict[str, slice]]:
    """A zeroed antisymmetric block with its header written for a block starting at
    ``start`` in the parameter array, and each part's slice within the block."""
    lay = lateral_layout(n_modes, n_symmetric, n_strips)
    block = np.zeros(sum(size for _, size in lay.values()))
    block[:len(LAT_BLOCKS)] = [start + lay[name][0] for name in LAT_BLOCKS]
    return block, {name: slice(o, o + size) for name, (o, size) in lay.items()}
