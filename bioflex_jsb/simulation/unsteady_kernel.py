"""The unsteady wing's step (``aero="unsteady"``) as one compiled function (numba).

:class:`bioflex_jsb.runtime.coupled_step.CoupledStep` runs either the readable Python step
(:class:`~bioflex_jsb.simulation.unsteady_wing.UnsteadyModalWing`, the reference) or this
kernel, which does the same arithmetic in one call, as
:mod:`bioflex_jsb.simulation.step_kernel` does for the quasi-steady wing: the flow at the
wing from the snapshot and the wind, the inputs f of the step (the backward-difference
accelerations from the last step's α_i and q kept in the parameter array), the exact step
at the reference speed with its first-order correction in V,

    x_{k+1} = Φ_r x_k + (V − V_r) ∂Φ/∂V x_k + (Ψ_r B_0 + V Ψ_r B_1 + V² Ψ_r B_2) f_k,

the loads (the quasi-steady modal ones plus the unsteady increments, quadratic in V), their
rotation to body axes in JSBSim's units, the row of the step and the range checks, with the
status codes of the quasi-steady kernel. Python keeps the gust, the property reads and
writes, JSBSim's step and the (rare) reference refreshes (the wing's ``_reference``).

Cost: with n modes and s strips the state has n_x = 2n + 4s entries (166 for the 3 modes
and 40 strips of the prototype) and Φ, ∂Φ/∂V are n_x × n_x. The Küssner states are driven by
the gust alone and decay on their own (their rows of A are diagonal), so their rows of Φ and
∂Φ/∂V are diagonal too and their only input is the gust: :func:`dense_rows` finds how many
leading rows are not (86 of 166 here) by testing for exact zeros, and the kernel multiplies
only those densely, the others from packed vectors of their nonzero entries (exactly the
Python step's products, whose other terms are zeros). The dense products are reductions
compiled with reassociation allowed (SIMD): the sums are taken in another order than BLAS
takes them, which changes the last digits only (``tests/test_unsteady_kernel.py``).
The diagonal rows of strips of one chord are the same numbers (two groups of 40 here):
their states, equal from rest, stay equal, and the dense rows and the loads are taken on
one state per group (:func:`state_groups`; 88 columns instead of 166), the whole state only
when a group's states differ (set from outside, or NaN).
Measured: the kernel's call (same state, the three variants interleaved, 15 rounds of
20 000 calls, load 0.1-0.15) 3.6-4.1 µs with the inputs as three 8-term dot products per
row and the diagonal rows read off the matrices, 3.4-3.6 µs with the inputs and diagonal
rows as in :func:`_advance` without the groups, 2.7-3.0 µs with the groups; the step
(``bioflex-jsb bench``'s estimator, bare, cosim and unsteady interleaved, 12 repeats, CPU
clock) 10.0-10.3 µs with those inputs and rows against 10.2-10.8 µs with the dot products
(load 1.0-1.5), 9.6-10.9 µs with the groups (unsteady_ratio 1.80-1.90, load 0.2-2.0; runs
without the groups in the same minutes were too noisy to pair).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from bioflex_jsb.simulation.step_kernel import (
    KERNEL_SLOTS,
    N_CONSTS,
    NEEDS_REFRESH,
    READ_KEYS,
    air_flow,
    finish_row,
    guard_cache,
)

N_INPUTS = 8  # f = [Q Δα, Q q/V, ΔQ, α_i, q, α̇_i, q̇, w_g] (unsteady_wing.INPUTS)
N_SLOTS = len(KERNEL_SLOTS)
# The blocks of the flat parameter array, in order (offsets in its header, see layout()).
BLOCKS = ("header", "phi", "dphi", "phi_c", "dphi_c", "psi_t", "diag", "load_poly",
          "load_poly_c", "groups", "key", "n_dense", "n_cols", "trim", "load_eta",
          "load_etadot", "consts", "dt", "k_induced2", "refresh_rel", "reactions", "out_flow",
          "stall_steps", "last", "inputs", "scratch")
H_PHI, H_DPHI, H_PHI_C, H_DPHI_C, H_PSI, H_DIAG, H_LOAD, H_LOAD_C, H_GROUPS, H_KEY, H_DENSE, \
    H_COLS, H_TRIM, H_LE, H_LD, H_C, H_DT, H_K2, H_RR, H_REACT, H_FLOW, H_STALL, H_LAST, H_F, \
    H_SCRATCH = range(1, len(BLOCKS))
GUST = N_INPUTS - 1  # the column of w_g in f: the only input of the Küssner states
N_DIAG = 5  # per diagonal row: Φ_ii, ∂Φ_ii/∂V, (Ψ_r B_p)[i, GUST] for p = 0, 1, 2
FASTMATH = {"reassoc", "contract"}  # SIMD sums and fused multiply-adds; NaN and inf kept


def layout(n_modes: int, n_states: int) -> dict[str, tuple[int, int]]:
    """Where each block sits in the flat parameter array of :func:`unsteady_kernel` for
    ``n_modes`` modes and ``n_states`` wing states: name → (offset, length). The offsets are
    also written into the array's header (block 0), which is how the kernel finds them.

    Blocks: phi, dphi (n_x × n_x, row-major): Φ_r and ∂Φ/∂V [1/(m/s)] (only the first
    n_dense rows are read); phi_c, dphi_c (n_dense × n_cols, row-major, at the start of
    blocks of n_x × n_x): their dense rows on the grouped state (:func:`state_groups`);
    psi_t (3·8, n_x): Ψ_r B_p transposed, row 8 p + j the column of input j for the power
    p = 0, 1, 2 of V; diag (5, n_x): the rows from n_dense on, entry i − n_dense of each row
    of :data:`N_DIAG`; load_poly (3, 2, n_x + 8): the increments' body loads [Z [N, down];
    M [N·m, nose up]] per power of V on [x; f]; load_poly_c (3, 2, n_cols + 8, at the start
    of a block as large as load_poly's): the same on the grouped state; groups (3, n_x):
    per row i − n_dense from n_dense on its group and its group's first row (both as
    offsets from n_dense), then per group its first row; key: (Q_r [Pa], V_r [m/s]);
    n_dense: rows of phi and dphi multiplied densely; n_cols: n_dense + the number of
    groups; trim: α_0 [rad], θ_0 [rad],
    Q_0 [Pa], V_0 [m/s]; load_eta, load_etadot: (3, n) modal loads per unit Q S; consts: as
    the quasi-steady kernel's; dt [s]; k_induced2: induced drag per unit lift 2 k C_L0 [-];
    refresh_rel; out: reactions [lbf, lbf, lbf·ft], out_flow (α [rad], q [rad/s], Q [Pa],
    V [m/s]), stall_steps; last: (stepped yet, α_i [rad], q [rad/s]) of the last step;
    inputs: its f; scratch: the new dense rows (n_x), [f, V f, V² f] (24), the grouped
    state (n_x)."""
    n, nx = n_modes, n_states
    sizes = {"header": len(BLOCKS), "phi": nx * nx, "dphi": nx * nx,
             "phi_c": nx * nx, "dphi_c": nx * nx, "psi_t": 3 * N_INPUTS * nx,
             "diag": N_DIAG * nx, "load_poly": 3 * 2 * (nx + N_INPUTS),
             "load_poly_c": 3 * 2 * (nx + N_INPUTS), "groups": 3 * nx, "key": 2,
             "n_dense": 1, "n_cols": 1, "trim": 4, "load_eta": 3 * n, "load_etadot": 3 * n,
             "consts": N_CONSTS, "dt": 1, "k_induced2": 1, "refresh_rel": 1, "reactions": 3,
             "out_flow": 4, "stall_steps": 1, "last": 3, "inputs": N_INPUTS,
             "scratch": 2 * nx + 3 * N_INPUTS}
    out, offset = {}, 0
    for name in BLOCKS:
        out[name] = (offset, sizes[name])
        offset += sizes[name]
    return out


def new_params(n_modes: int, n_states: int) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """A zeroed parameter array with its header written, and a view of each block."""
    lay = layout(n_modes, n_states)
    params = np.zeros(sum(size for _, size in lay.values()))
    params[:len(BLOCKS)] = [lay[name][0] for name in BLOCKS]
    return params, {name: params[o:o + size] for name, (o, size) in lay.items()}


def dense_rows(phi: np.ndarray, dphi: np.ndarray, psi_b=()) -> int:
    """How many leading rows of the step must be multiplied densely: every row after them
    is diagonal in Φ and ∂Φ/∂V (exact zeros elsewhere) and its inputs Ψ_r B_p (each of
    ``psi_b``, n_x × 8) are zero but for the gust's (column :data:`GUST`), so multiplying
    only those entries is the same product."""
    off = (phi != 0.0) | (dphi != 0.0)
    np.fill_diagonal(off, False)
    dense = off.any(axis=1)
    for p in psi_b:
        dense |= (p[:, :GUST] != 0.0).any(axis=1)
    rows = np.flatnonzero(dense)
    return int(rows[-1]) + 1 if rows.size else 0


def state_groups(diag: np.ndarray) -> np.ndarray:
    """The group of each diagonal row, from ``diag`` (5, rows: :data:`N_DIAG` per row): rows
    whose five entries are the same numbers (the same decay, the same gust input; the
    Küssner states of strips of one chord) are one group, numbered in order of their
    first row. States of one group that start equal stay equal, step after step."""
    seen: dict[tuple[float, ...], int] = {}
    return np.array([seen.setdefault(tuple(col), len(seen)) for col in diag.T.tolist()],
                    dtype=np.int64)


def load_reference(views: dict[str, np.ndarray], phi_stack: np.ndarray, psi_b, load_poly,
                   key: tuple[float, float]) -> None:
    """Copy a reference step of the Python wing (its ``_phi`` = [Φ_r; ∂Φ/∂V], ``_psi_b``,
    ``_load_poly`` and ``_key``) into the parameter blocks, in the kernel's layout: also
    the dense rows and the loads on the grouped state, the columns of each group's states
    summed."""
    nx = phi_stack.shape[1]
    phi, dphi = phi_stack[:nx], phi_stack[nx:]
    nd = dense_rows(phi, dphi, psi_b)
    nt = nx - nd
    views["phi"][:] = np.ravel(phi)
    views["dphi"][:] = np.ravel(dphi)
    views["psi_t"][:] = np.ravel(np.concatenate([np.transpose(p) for p in psi_b]))
    diag = np.zeros((N_DIAG, nx))
    rows = np.arange(nd, nx)
    diag[0, :nt], diag[1, :nt] = phi[rows, rows], dphi[rows, rows]
    for p in range(3):
        diag[2 + p, :nt] = psi_b[p][nd:, GUST]
    views["diag"][:] = np.ravel(diag)
    lp = np.stack(load_poly)
    views["load_poly"][:] = np.ravel(lp)
    group = state_groups(diag[:, :nt])
    ng = int(group.max()) + 1 if nt else 0
    first = np.array([int(np.flatnonzero(group == g)[0]) for g in range(ng)], dtype=np.int64)
    table = np.zeros((3, nx))
    table[0, :nt], table[1, :nt], table[2, :ng] = group, first[group], first

    def grouped(m: np.ndarray) -> np.ndarray:  # [..., n_x (+ inputs)] → [..., n_cols (+)]
        sums = [m[..., nd + np.flatnonzero(group == g)].sum(axis=-1) for g in range(ng)]
        return np.concatenate([m[..., :nd], np.stack(sums, axis=-1).reshape(
            m.shape[:-1] + (ng,)), m[..., nx:]], axis=-1)

    nc = nd + ng
    views["phi_c"][:nd * nc] = np.ravel(grouped(phi[:nd]))
    views["dphi_c"][:nd * nc] = np.ravel(grouped(dphi[:nd]))
    views["load_poly_c"][:6 * (nc + N_INPUTS)] = np.ravel(grouped(lp))
    views["groups"][:] = np.ravel(table)
    views["n_dense"][0], views["n_cols"][0] = nd, nc
    views["key"][:] = key


@numba.njit(cache=True, nogil=True, fastmath=FASTMATH)
def _dense(phi, dphi, z, y, dv):
    """y[i] += Σ_j (Φ + ΔV ∂Φ/∂V)[i, j] z[j] for the rows of ``phi``, row by row: one pass
    over both matrices, a SIMD reduction per row."""
    for i in range(phi.shape[0]):
        a = 0.0
        for j in range(phi.shape[1]):
            a += (phi[i, j] + dv * dphi[i, j]) * z[j]
        y[i] += a


@numba.njit(cache=True, nogil=True, fastmath=FASTMATH)
def _loads(lp, z, f, vt):
    """The increments' loads (Z [N, down], M [N·m, nose up]) of the state ``z`` and the
    inputs ``f`` at ``vt`` [m/s]: ``lp`` (3, 2, len(z) + 8) per power of V."""
    m, v2 = z.shape[0], vt * vt
    z_inc = m_inc = 0.0
    for j in range(m):
        z_inc += (lp[0, 0, j] + vt * lp[1, 0, j] + v2 * lp[2, 0, j]) * z[j]
        m_inc += (lp[0, 1, j] + vt * lp[1, 1, j] + v2 * lp[2, 1, j]) * z[j]
    for j in range(N_INPUTS):
        z_inc += (lp[0, 0, m + j] + vt * lp[1, 0, m + j] + v2 * lp[2, 0, m + j]) * f[j]
        m_inc += (lp[0, 1, m + j] + vt * lp[1, 1, m + j] + v2 * lp[2, 1, m + j]) * f[j]
    return z_inc, m_inc


@numba.njit(cache=True, nogil=True, fastmath=FASTMATH)
def _advance(params, x, f, vt, n):
    """x ← Φ x + ΔV ∂Φ/∂V x + Σ_p V^p Ψ B_p f (in place) and the increments' loads of the
    new state (Z [N, down], M [N·m, nose up]) at the speed ``vt`` [m/s]. The rows from
    ``n_dense`` on are diagonal with the gust as their only input (:func:`dense_rows`);
    when the states of each of their groups are equal (:func:`state_groups`; always, from
    rest) the dense rows and the loads are taken on the grouped state, one column per
    group (88 columns of 166 here), else on the whole state.
    Measured (166 states, 86 dense rows; each part alone, least of 9 interleaved rounds of
    20 000 calls, load 0.9): (Φ + ΔV ∂Φ/∂V) x over the dense rows on the whole state
    1.3-1.6 µs (the grouped state: 0.4-0.9 µs less per kernel call, module docstring; Φ x and
    ∂Φ/∂V x as two passes 4.3 µs, loaded machine); Σ_p V^p Ψ B_p f as 24 column updates
    of the dense rows (the inputs and their products with V and V² side by side, SIMD over
    the rows) 0.23 µs where three 8-term dot products per row take 0.77 µs; the diagonal
    rows from packed vectors 0.07 µs where reading them off the matrices' diagonals with
    their Ψ rows takes 0.2 µs. Blocking rows two or four at a time (2.1 µs), column-major Φ
    (2.4 µs) and Φ, ∂Φ/∂V interleaved row by row (2.2 µs) are slower. On flat offsets into
    the parameter array instead of 2-D views numba checks every index for wrap-around and
    the loops lose their SIMD (12.6 µs)."""
    nx = x.shape[0]
    o_psi, o_diag, o_y = int(params[H_PSI]), int(params[H_DIAG]), int(params[H_SCRATCH])
    o_key, o_grp = int(params[H_KEY]), int(params[H_GROUPS])
    nd = int(params[int(params[H_DENSE])])
    nc = int(params[int(params[H_COLS])])
    nt = nx - nd
    psi = params[o_psi:o_psi + 3 * N_INPUTS * nx].reshape((3 * N_INPUTS, nx))
    diag = params[o_diag:o_diag + N_DIAG * nx].reshape((N_DIAG, nx))
    y = params[o_y:o_y + nx]
    g = params[o_y + nx:o_y + nx + 3 * N_INPUTS]  # [f, V f, V² f]
    dv, v2 = vt - params[o_key + 1], vt * vt
    for j in range(N_INPUTS):
        g[j], g[N_INPUTS + j], g[2 * N_INPUTS + j] = f[j], vt * f[j], v2 * f[j]
    for i in range(nd):
        y[i] = 0.0
    for c in range(3 * N_INPUTS):  # Σ_p V^p Ψ B_p f, a column at a time
        gc = g[c]
        for i in range(nd):
            y[i] += psi[c, i] * gc
    grouped = True  # "not ==": a NaN state takes the whole state, where it shows
    for k in range(nt):
        if not x[nd + k] == x[nd + int(params[o_grp + nx + k])]:
            grouped = False
    w_g = f[GUST]
    if grouped:
        o_z, o_pc, o_dc = o_y + nx + 3 * N_INPUTS, int(params[H_PHI_C]), int(params[H_DPHI_C])
        z = params[o_z:o_z + nc]
        for i in range(nd):
            z[i] = x[i]
        for c in range(nc - nd):  # a group's state: that of its first row
            z[nd + c] = x[nd + int(params[o_grp + 2 * nx + c])]
        _dense(params[o_pc:o_pc + nd * nc].reshape((nd, nc)),
               params[o_dc:o_dc + nd * nc].reshape((nd, nc)), z, y, dv)
        for c in range(nc - nd):
            r = int(params[o_grp + 2 * nx + c])
            z[nd + c] = ((diag[0, r] + dv * diag[1, r]) * z[nd + c]
                         + (diag[2, r] + vt * diag[3, r] + v2 * diag[4, r]) * w_g)
        for i in range(nd):
            x[i] = z[i] = y[i]
        for k in range(nt):
            x[nd + k] = z[nd + int(params[o_grp + k])]
        o_lp = int(params[H_LOAD_C])
        return _loads(params[o_lp:o_lp + 6 * (nc + N_INPUTS)].reshape((3, 2, nc + N_INPUTS)),
                      z, f, vt)
    o_phi, o_dphi = int(params[H_PHI]), int(params[H_DPHI])
    _dense(params[o_phi:o_phi + nd * nx].reshape((nd, nx)),
           params[o_dphi:o_dphi + nd * nx].reshape((nd, nx)), x, y, dv)
    for k in range(nt):  # each diagonal row reads only its own state: in place
        x[nd + k] = ((diag[0, k] + dv * diag[1, k]) * x[nd + k]
                     + (diag[2, k] + vt * diag[3, k] + v2 * diag[4, k]) * w_g)
    for i in range(nd):
        x[i] = y[i]
    o_lp = int(params[H_LOAD])
    return _loads(params[o_lp:o_lp + 6 * (nx + N_INPUTS)].reshape((3, 2, nx + N_INPUTS)),
                  x, f, vt)


@numba.njit(cache=True, nogil=True)
def unsteady_kernel(reads, params, x, cols, table, k, wind_down_fps, w_g):
    """One step of the unsteady wing (module docstring), writing row ``k`` of ``table``;
    the arguments are the quasi-steady kernel's
    (:func:`~bioflex_jsb.simulation.step_kernel.step_kernel`), ``params`` laid out by
    :func:`layout` and ``x`` the whole wing state (η, η̇, the lag and Küssner states; updated
    in place to x_{k+1}). Returns a status code."""
    n = (len(cols) - N_SLOTS) // 2
    o_c, o_trim, o_key = int(params[H_C]), int(params[H_TRIM]), int(params[H_KEY])
    o_out, o_flow, o_last = int(params[H_REACT]), int(params[H_FLOW]), int(params[H_LAST])
    o_f = int(params[H_F])
    consts = params[o_c:o_c + N_CONSTS]
    s_ref, cbar = consts[2], consts[3]
    key0, key1 = params[o_key], params[o_key + 1]
    refresh_rel = params[int(params[H_RR])]
    row = table[k]
    q = reads[3]
    va, vt_fps, vt, alpha, qbar = air_flow(reads, wind_down_fps, consts[0], consts[1])
    params[o_flow], params[o_flow + 1] = alpha, q
    params[o_flow + 2], params[o_flow + 3] = qbar, vt
    # "not within", so that the NaN key of a wing with no reference yet refreshes
    if not (abs(qbar - key0) <= refresh_rel * abs(key0)
            and abs(vt - key1) <= refresh_rel * abs(key1)):
        return NEEDS_REFRESH
    for i in range(2 * n):  # the row's modal state η_k, η̇_k (before the step)
        row[cols[N_SLOTS + i]] = x[i]
    # the inputs held over the step (UnsteadyModalWing._inputs)
    d_alpha = alpha - params[o_trim]
    alpha_i = d_alpha - w_g / vt
    ad = qd = 0.0
    if params[o_last] != 0.0:
        dt = params[int(params[H_DT])]
        ad = (alpha_i - params[o_last + 1]) / dt
        qd = (q - params[o_last + 2]) / dt
    f = params[o_f:o_f + N_INPUTS]  # kept: the inputs of the last step
    f[0], f[1], f[2], f[3] = qbar * d_alpha, qbar / vt * q, qbar - params[o_trim + 2], alpha_i
    f[4], f[5], f[6], f[7] = q, ad, qd, w_g
    # the step and the increments' loads of x_{k+1}
    z_inc, m_inc = _advance(params, x, f, vt, n)
    params[o_last], params[o_last + 1], params[o_last + 2] = 1.0, alpha_i, q
    # the modal loads of x_{k+1} (ModalWing's), then the increments'
    o_le, o_ld = int(params[H_LE]), int(params[H_LD])
    rate = cbar / (2.0 * vt)
    l0 = l1 = l2 = 0.0
    r0 = r1 = r2 = 0.0
    for i in range(n):
        e, ed = x[i], x[n + i]
        l0 += params[o_le + i] * e
        l1 += params[o_le + n + i] * e
        l2 += params[o_le + 2 * n + i] * e
        r0 += params[o_ld + i] * ed
        r1 += params[o_ld + n + i] * ed
        r2 += params[o_ld + 2 * n + i] * ed
    qs = qbar * s_ref
    lift = qs * (l0 + rate * r0) - z_inc
    drag = qs * (l1 + rate * r1) - params[int(params[H_K2])] * z_inc
    moment = qs * (l2 + rate * r2) + m_inc
    ca, sa = math.cos(alpha), math.sin(alpha)
    params[o_out] = (lift * ca + drag * sa) * consts[4]
    params[o_out + 1] = (drag * ca - lift * sa) * consts[4]
    params[o_out + 2] = moment * consts[5]
    if alpha > consts[9]:
        params[int(params[H_STALL])] += 1.0  # steps beyond the lift peak
    return finish_row(row, cols, reads, params[o_trim:o_trim + 4], consts, x, n, va, vt_fps,
                      vt, alpha, w_g, lift, drag, moment)


# a damaged on-disk cache is discarded and compiled anew, as the quasi-steady kernel's (the
# helper too: it is loaded from its own cache when the kernel is compiled)
guard_cache(_dense)
guard_cache(_loads)
guard_cache(_advance)
guard_cache(unsteady_kernel)


def compile_now(n_modes: int = 3, n_strips: int = 40) -> None:
    """Compile (or load from numba's cache) the kernel for the types a run passes (as
    :func:`~bioflex_jsb.simulation.step_kernel.compile_now`)."""
    nx = 2 * n_modes + 4 * n_strips
    params, views = new_params(n_modes, nx)
    views["key"][:] = 1.0
    views["trim"][3] = 1.0
    views["consts"][:] = 1.0  # any finite flow will do
    views["dt"][0] = 1.0
    cols = np.arange(N_SLOTS + 2 * n_modes, dtype=np.int64)
    table = np.zeros((1, len(cols)))
    unsteady_kernel((1.0,) * len(READ_KEYS), params, np.zeros(nx), cols, table, 0, 0.0, 0.0)
