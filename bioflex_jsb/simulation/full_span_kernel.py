"""The full-span step compiled: the half wing's kernel and the antisymmetric wing in one call.

:func:`full_span_kernel` takes the arguments of :func:`~bioflex_jsb.simulation.step_kernel
.step_kernel` (one call from Python a step, as the half wing's: numba's per-call typing is
paid once) with three more snapshot entries, :data:`EXTRA_READS`, and the parameter array,
state and columns of both wings end to end: the half wing's block first (its own
:func:`~bioflex_jsb.simulation.step_kernel.layout`, read by the half wing's kernel as it
is), the antisymmetric block after it (:func:`lateral_layout`) and :data:`N_DIMS` sizes
last. It does the arithmetic of :class:`~bioflex_jsb.simulation.full_span
.AntisymmetricModalWing` (the reference it is tested against): the antisymmetric modal step
with the flow of t_k (the yaw rate's and sideslip's forcing with it), the rolling moment,
side force and yawing moment of η_{k+1} into the reactions (lbf·ft, lbf, lbf·ft) and the
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
# refresh_rel, ft→m, slug/ft³→kg/m³, N·m→lbf·ft, η limit [rad], N→lbf, the weight W [N],
# 1/(π b²) [1/m²] (the induced angle per unit L_w/Q)
N_LAT_CONSTS = 8
N_FIXED = 6  # the full-span row's fixed channels (full_span.LATERAL_FIXED)
BETA_SLOT = K.KERNEL_SLOTS.index("beta_rad")  # the row's β [rad], written by the half wing's


def lateral_layout(n_modes: int, n_symmetric: int) -> dict[str, tuple[int, int]]:
    """The antisymmetric block (``n_modes`` antisymmetric, ``n_symmetric`` symmetric
    modes), offsets from its start; the yaw rate's and sideslip's terms are
    :class:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.YawSideslipTerms`' arrays."""
    n, n2, ns = n_modes, 2 * n_modes, n_symmetric
    sizes = (("stack", 3 * n2 * n2), ("input_cols", n2 * 2), ("key", 2),
             ("force_eta", n * n), ("force_p", n), ("force_delta", n), ("stiffness", n),
             ("roll_eta", n), ("roll_etadot", n), ("tip_anti", n), ("model", 1),
             ("reactions", 6), ("consts", N_LAT_CONSTS), ("scratch", n2 + n),
             ("force_map", n2 * n), ("force_r", n), ("force_beta", n), ("force_beta_s", n * ns),
             ("roll_r_s", ns), ("roll_beta_s", ns), ("side_eta", n), ("side_dihedral_eta", n),
             ("side_dihedral_etadot", n), ("yaw_etadot", n), ("yaw_p_s", ns),
             ("static_s", ns), ("tip_sym", ns))
    out, offset = {}, 0
    for name, size in sizes:
        out[name] = (offset, size)
        offset += size
    return out


def lateral_block_size(n_modes: int, n_symmetric: int) -> int:
    """The antisymmetric block's length."""
    return sum(s for _, s in lateral_layout(n_modes, n_symmetric).values())


# --------------------------------------------------------------------------------------
# The pieces both full-span kernels share (this one and unsteady_full_span_kernel): the
# terms of the quasi-steady strips that do not depend on how the antisymmetric modes are
# stepped. Each takes its offsets into params, so either kernel's layout serves; each is
# inlined into its caller (numba's IR inlining: a call per step would cost the hot path).
# --------------------------------------------------------------------------------------
@numba.njit(cache=True, nogil=True, inline="always")
def start_lateral(params, xs, xa, row, cols, base, ns, na, o_ts, o_ta, o_ss, o_fbs, o_g):
    """Before the half wing's step: η_a, η̇_a of t_k into the row's full-span columns; the
    sideslip's forcing's symmetric part with η_s of t_k, Σ_j F^βs_ij (η_static + Δη)_j, into
    params[o_g + i] (per unit Q β); returns the symmetric and antisymmetric starboard tip
    twists [rad] of t_k."""
    for i in range(2 * na):
        row[cols[base + N_FIXED + i]] = xa[i]
    tip = 0.0
    for i in range(ns):  # η_s of t_k, before the half wing's step
        tip += params[o_ts + i] * xs[i]
    anti = 0.0
    for i in range(na):
        anti += params[o_ta + i] * xa[i]
    for i in range(na):
        acc = 0.0
        for j in range(ns):
            acc += params[o_fbs + ns * i + j] * (params[o_ss + j] + xs[j])
        params[o_g + i] = acc
    return tip, anti


@numba.njit(cache=True, nogil=True, inline="always")
def modal_loads(params, xs, xa, ns, na, qbar, qv, vt, lift, p_rate, r_rate, beta, moment,
                side, induced, o_re, o_rd, o_ss, o_rrs, o_rbs, o_yps, o_se, o_sge, o_sgd,
                o_yd):
    """The quasi-steady strips' loads of η_{k+1} added to ``moment`` [N·m, right wing down]
    and ``side`` [N, body +y] (what the kernel's own strips gave: 0, or the unsteady
    increments'), and the yawing moment [N·m, nose right]: the modes' rolling moment, the
    yaw rate's and sideslip's rolling moment and the yawing moment of the symmetric
    deflection after the half wing's step (η_s of t_k+1), the side force on the dihedral,
    the yawing moment of η̇_a's lift and the induced drag's, −``induced`` L_w/Q · moment.
    Returns (moment, side, yaw)."""
    for i in range(na):
        moment += qbar * params[o_re + i] * xa[i] + qv * params[o_rd + i] * xa[na + i]
    roll_s, yaw_s = 0.0, 0.0
    for j in range(ns):
        eta_s = params[o_ss + j] + xs[j]
        roll_s += (qv * r_rate * params[o_rrs + j] + qbar * beta * params[o_rbs + j]) * eta_s
        yaw_s += qv * p_rate * params[o_yps + j] * eta_s
    moment += roll_s
    yaw = 0.0
    for i in range(na):
        side += ((lift * params[o_se + i] + qbar * params[o_sge + i]) * xa[i]
                 + qv * params[o_sgd + i] * xa[na + i])
        yaw += lift / vt * params[o_yd + i] * xa[na + i]
    yaw += yaw_s - induced * lift / qbar * moment
    return moment, side, yaw


@numba.njit(cache=True, nogil=True, inline="always")
def finish_lateral(params, row, cols, base, na, xa, status, o_rx, o_half, to_lbf_ft, to_lbf,
                   eta_limit, aileron, moment, tip, anti, side, yaw):
    """The reactions JSBSim applies (the half wing's three from params[o_half:], then the
    roll [lbf·ft], side [lbf] and yaw [lbf·ft] from N·m and N by ``to_lbf_ft``,
    ``to_lbf``), the row's fixed full-span channels, then the step's status: the half
    wing's when not OK, NON_FINITE for a full-span channel, ETA_OUT for |η_a| above
    ``eta_limit`` [rad]."""
    params[o_rx] = params[o_half]
    params[o_rx + 1] = params[o_half + 1]
    params[o_rx + 2] = params[o_half + 2]
    params[o_rx + 3] = moment * to_lbf_ft
    params[o_rx + 4] = side * to_lbf
    params[o_rx + 5] = yaw * to_lbf_ft
    row[cols[base]] = aileron
    row[cols[base + 1]] = moment
    row[cols[base + 2]] = tip + anti
    row[cols[base + 3]] = tip - anti
    row[cols[base + 4]] = side
    row[cols[base + 5]] = yaw
    if status != K.OK:
        return status
    for c in range(base, base + N_FIXED + 2 * na):
        if not math.isfinite(row[cols[c]]):
            return K.NON_FINITE
    for i in range(na):
        if abs(xa[i]) > eta_limit:
            return K.ETA_OUT
    return K.OK


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
    # the offsets of lateral_layout, in its order
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
    o_c = o_rx + 6
    o_scr = o_c + N_LAT_CONSTS
    o_fm = o_scr + n2a + na
    o_fr = o_fm + n2a * na
    o_fb = o_fr + na
    o_fbs = o_fb + na
    o_rrs = o_fbs + na * ns
    o_rbs = o_rrs + ns
    o_se = o_rbs + ns
    o_sge = o_se + na
    o_sgd = o_sge + na
    o_yd = o_sgd + na
    o_yps = o_yd + na
    o_ss = o_yps + ns
    o_ts = o_ss + ns  # the symmetric modes' tip twist per unit η_s
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
    o_g = o_scr + n2a  # the generalised force on the antisymmetric modes [N·m]
    tip, anti = start_lateral(params, xs, xa, row, cols, base, ns, na, o_ts, o_ta, o_ss,
                              o_fbs, o_g)
    status = K.step_kernel(reads, params[:p_sym], xs, cols[:c_sym], table, k, wind_down_fps,
                           w_g)
    if status == K.NEEDS_REFRESH:
        return status
    qbar, vt = params[o_flow + 2], params[o_flow + 3]  # the flow of t_k (step_kernel's)
    aileron = 0.5 * (reads[20] - reads[21])  # JSBSim's δa: + rolls right
    delta_s = -aileron  # the starboard surface, trailing edge down
    qv = qbar / vt
    p_rate, r_rate = reads[4], reads[5]
    rel_p = p_rate - reads[22]
    beta = row[cols[BETA_SLOT]]  # the row's β of t_k (step_kernel.finish_row)
    lift = reads[10] * params[o_c + 6]  # the wing's lift n_z W [N]
    for i in range(na):
        params[o_g + i] = (lift * r_rate / vt * params[o_fr + i]
                           + qbar * beta * (params[o_fb + i] + params[o_g + i]))
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
            for j in range(na):
                acc += params[o_fm + na * i + j] * params[o_g + j]
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
            rhs[i] = (qbar * params[o_fd + i] * delta_s + qv * params[o_fp + i] * rel_p
                      + params[o_g + i])
        eta = np.linalg.solve(kq, rhs)
        for i in range(na):
            xa[i] = eta[i]
            xa[na + i] = 0.0
    moment, side, yaw = 0.0, 0.0, 0.0
    if model != 0:
        moment, side, yaw = modal_loads(params, xs, xa, ns, na, qbar, qv, vt, lift, p_rate,
                                        r_rate, beta, moment, side, params[o_c + 7], o_re,
                                        o_rd, o_ss, o_rrs, o_rbs, o_yps, o_se, o_sge, o_sgd,
                                        o_yd)
    # the half wing's reactions: the block before its out_flow (step_kernel.layout)
    return finish_lateral(params, row, cols, base, na, xa, status, o_rx, o_flow - 3,
                          params[o_c + 3], params[o_c + 5], params[o_c + 4], aileron, moment,
                          tip, anti, side, yaw)


K.guard_cache(start_lateral)
K.guard_cache(modal_loads)
K.guard_cache(finish_lateral)
K.guard_cache(full_span_kernel)
