"""The full-span step compiled: the half wing's kernel and the antisymmetric wing in one call.

:func:`full_span_kernel` takes the arguments of :func:`~bioflex_jsb.simulation.step_kernel
.step_kernel` (one call from Python a step, as the half wing's: numba's per-call typing is
paid once) with three more snapshot entries, :data:`EXTRA_READS`, and the parameter array,
state and columns of both wings end to end: the half wing's block first (its own
:func:`~bioflex_jsb.simulation.step_kernel.layout`, read by the half wing's kernel as it
is), the antisymmetric block after it (:func:`lateral_layout`) and :data:`N_DIMS` sizes
last. It does the arithmetic of :class:`~bioflex_jsb.simulation.full_span
.AntisymmetricModalWing` (the reference it is tested against): the antisymmetric modal step
with the flow of t_k, the rolling moment of η_{k+1} into the reactions (lbf·ft) and the
row's full-span channels. A half-wing run does not call it (its step is unchanged).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from bioflex_jsb.simulation import step_kernel as K

# The snapshot's entries after step_kernel.READ_KEYS: JSBSim's left and right aileron
# positions [rad, each trailing edge down] and the gust roll rate p_g [rad/s] (not JSBSim's:
# the step's input).
EXTRA_READS = ("left_aileron", "right_aileron", "p_g")
N_DIMS = 5  # the sizes at the end of params: (half wing's params, its cols, n_s, n_a, out_flow)
N_LAT_CONSTS = 5  # refresh_rel, ft→m, slug/ft³→kg/m³, N·m→lbf·ft, η limit [rad]


def lateral_layout(n_modes: int) -> dict[str, tuple[int, int]]:
    """The antisymmetric block (``n_modes`` antisymmetric modes), offsets from its start."""
    n, n2 = n_modes, 2 * n_modes
    sizes = (("stack", 3 * n2 * n2), ("input_cols", n2 * 2), ("key", 2),
             ("force_eta", n * n), ("force_p", n), ("force_delta", n), ("stiffness", n),
             ("roll_eta", n), ("roll_etadot", n), ("tip_anti", n), ("model", 1),
             ("reactions", 4), ("consts", N_LAT_CONSTS), ("scratch", n2))
    out, offset = {}, 0
    for name, size in sizes:
        out[name] = (offset, size)
        offset += size
    return out


def lateral_block_size(n_modes: int, n_symmetric: int) -> int:
    """The antisymmetric block's length with the symmetric tip twists (n_symmetric)."""
    return sum(s for _, s in lateral_layout(n_modes).values()) + n_symmetric


@numba.njit(cache=True, nogil=True)
def full_span_kernel(reads, params, x, cols, table, k, wind_down_fps, w_g):
    """One full-span step (module docstring), writing row ``k`` of ``table``; returns the
    half wing's status codes (step_kernel.OK, NEEDS_REFRESH: renew both references at
    out_flow's Q, V, nothing done; NON_FINITE; ALPHA_OUT; ETA_OUT, either wing's η)."""
    size = params.shape[0]
    p_sym = int(params[size - 5])
    c_sym = int(params[size - 4])
    ns = int(params[size - 3])
    na = int(params[size - 2])
    o_flow = int(params[size - 1])  # the half wing's out_flow block
    n2s, n2a = 2 * ns, 2 * na
    o_stack = p_sym
    o_in = o_stack + 3 * n2a * n2a
    o_key = o_in + 2 * n2a
    o_fe = o_key + 2
    o_fp = o_fe + na * na
    o_fd = o_fp + na
    o_st = o_fd + na
    o_re = o_st + na
    o_rd = o_re + na
    o_ta = o_rd + na
    o_model = o_ta + na
    o_rx = o_model + 1
    o_c = o_rx + 4
    o_scr = o_c + N_LAT_CONSTS
    o_ts = o_scr + n2a  # the symmetric modes' tip twist per unit η_s
    model = int(params[o_model])
    key0, key1 = params[o_key], params[o_key + 1]
    # Both references are renewed together at one flow (CoupledStep._renew_reference), so
    # the half wing's check of the flow against its key is this wing's too: a key that is
    # not the half wing's (none yet: NaN) asks for a renewal at this flow.
    o_key_s = 3 * n2s * n2s + 3 * n2s  # the half wing's key (step_kernel.layout)
    if model == 1 and not (key0 == params[o_key_s] and key1 == params[o_key_s + 1]):
        va, vt_fps, vt, alpha, qbar = K.air_flow(reads, wind_down_fps, params[o_c + 1],
                                                  params[o_c + 2])
        params[o_flow], params[o_flow + 1] = alpha, reads[3]
        params[o_flow + 2], params[o_flow + 3] = qbar, vt
        return K.NEEDS_REFRESH
    xs = x[:n2s]
    xa = x[n2s:n2s + n2a]
    base = c_sym  # the full-span channels' columns: LATERAL_FIXED, η_a, η̇_a
    row = table[k]
    for i in range(n2a):
        row[cols[base + 4 + i]] = xa[i]
    tip = 0.0
    for i in range(ns):  # η_s of t_k, before the half wing's step
        tip += params[o_ts + i] * xs[i]
    anti = 0.0
    for i in range(na):
        anti += params[o_ta + i] * xa[i]
    status = K.step_kernel(reads, params[:p_sym], xs, cols[:c_sym], table, k, wind_down_fps,
                           w_g)
    if status == K.NEEDS_REFRESH:
        return status
    qbar, vt = params[o_flow + 2], params[o_flow + 3]  # the flow of t_k (step_kernel's)
    aileron = 0.5 * (reads[20] - reads[21])  # JSBSim's δa: + rolls right
    delta_s = -aileron  # the starboard surface, trailing edge down
    qv = qbar / vt
    rel_p = reads[4] - reads[22]
    if model == 1:
        dq, dqv = qbar - key0, qv - key0 / key1
        s1, s2 = n2a * n2a, 2 * n2a * n2a
        f0, f1 = qbar * delta_s, qv * rel_p
        for i in range(n2a):
            acc = 0.0
            r = o_stack + i * n2a
            for j in range(n2a):
                acc += (params[r + j] + dq * params[r + s1 + j] + dqv * params[r + s2 + j]) * xa[j]
            c = o_in + 2 * i
            params[o_scr + i] = acc + params[c] * f0 + params[c + 1] * f1
        for i in range(n2a):
            xa[i] = params[o_scr + i]
    elif model == 2:
        kq = np.empty((na, na))
        rhs = np.empty(na)
        for i in range(na):
            for j in range(na):
                kq[i, j] = -qbar * params[o_fe + na * i + j]
            kq[i, i] += params[o_st + i]
            rhs[i] = qbar * params[o_fd + i] * delta_s + qv * params[o_fp + i] * rel_p
        eta = np.linalg.solve(kq, rhs)
        for i in range(na):
            xa[i] = eta[i]
            xa[na + i] = 0.0
    moment = 0.0
    if model != 0:
        for i in range(na):
            moment += qbar * params[o_re + i] * xa[i] + qv * params[o_rd + i] * xa[na + i]
    params[o_rx] = params[o_flow - 3]  # the half wing's reactions (lbf, lbf, lbf·ft), the
    params[o_rx + 1] = params[o_flow - 2]  # block before its out_flow (step_kernel.layout) …
    params[o_rx + 2] = params[o_flow - 1]
    params[o_rx + 3] = moment * params[o_c + 3]  # … and the roll [lbf·ft]
    row[cols[base]] = aileron
    row[cols[base + 1]] = moment
    row[cols[base + 2]] = tip + anti
    row[cols[base + 3]] = tip - anti
    if status != K.OK:
        return status
    for c in range(base, base + 4 + n2a):
        if not math.isfinite(row[cols[c]]):
            return K.NON_FINITE
    for i in range(na):
        if abs(xa[i]) > params[o_c + 4]:
            return K.ETA_OUT
    return K.OK


K.guard_cache(full_span_kernel)
