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
Measured (``bioflex-jsb bench``'s estimator, bare, cosim and unsteady interleaved, 12
repeats, CPU clock, load 1.0-1.5): the unsteady step 10.0-10.3 µs against 10.2-10.8 µs with
the inputs as three 8-term dot products per row and the diagonal rows read off the matrices
(unsteady_ratio 1.86-1.87 against 1.93-2.03); the dense product is ~1.4 µs of it, the
rest of the kernel what the quasi-steady kernel costs (``_advance``).
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
BLOCKS = ("header", "phi", "dphi", "psi_t", "diag", "load_poly", "key", "n_dense", "trim",
          "load_eta", "load_etadot", "consts", "dt", "k_induced2", "refresh_rel",
          "reactions", "out_flow", "stall_steps", "last", "inputs", "scratch")
H_PHI, H_DPHI, H_PSI, H_DIAG, H_LOAD, H_KEY, H_DENSE, H_TRIM, H_LE, H_LD, H_C, H_DT, H_K2, \
    H_RR, H_REACT, H_FLOW, H_STALL, H_LAST, H_F, H_SCRATCH = range(1, len(BLOCKS))
GUST = N_INPUTS - 1  # the column of w_g in f: the only input of the Küssner states
N_DIAG = 5  # per diagonal row: Φ_ii, ∂Φ_ii/∂V, (Ψ_r B_p)[i, GUST] for p = 0, 1, 2
FASTMATH = {"reassoc", "contract"}  # SIMD sums and fused multiply-adds; NaN and inf kept


def layout(n_modes: int, n_states: int) -> dict[str, tuple[int, int]]:
    """Where each block sits in the flat parameter array of :func:`unsteady_kernel` for
    ``n_modes`` modes and ``n_states`` wing states: name → (offset, length). The offsets are
    also written into the array's header (block 0), which is how the kernel finds them.

    Blocks: phi, dphi (n_x × n_x, row-major): Φ_r and ∂Φ/∂V [1/(m/s)] (only the first
    n_dense rows are read); psi_t (3·8, n_x): Ψ_r B_p transposed, row 8 p + j the column of
    input j for the power p = 0, 1, 2 of V; diag (5, n_x): the rows from n_dense on, entry
    i − n_dense of each row of :data:`N_DIAG`; load_poly (3, 2, n_x + 8): the increments' body
    loads [Z [N, down]; M [N·m, nose up]] per power of V on [x; f]; key: (Q_r [Pa], V_r
    [m/s]); n_dense: rows of phi and dphi multiplied densely; trim: α_0 [rad], θ_0 [rad],
    Q_0 [Pa], V_0 [m/s]; load_eta, load_etadot: (3, n) modal loads per unit Q S; consts: as
    the quasi-steady kernel's; dt [s]; k_induced2: induced drag per unit lift 2 k C_L0 [-];
    refresh_rel; out: reactions [lbf, lbf, lbf·ft], out_flow (α [rad], q [rad/s], Q [Pa],
    V [m/s]), stall_steps; last: (stepped yet, α_i [rad], q [rad/s]) of the last step;
    inputs: its f; scratch: the new dense rows (n_x), then [f, V f, V² f] (24)."""
    n, nx = n_modes, n_states
    sizes = {"header": len(BLOCKS), "phi": nx * nx, "dphi": nx * nx,
             "psi_t": 3 * N_INPUTS * nx, "diag": N_DIAG * nx,
             "load_poly": 3 * 2 * (nx + N_INPUTS), "key": 2,
             "n_dense": 1, "trim": 4, "load_eta": 3 * n, "load_etadot": 3 * n,
             "consts": N_CONSTS, "dt": 1, "k_induced2": 1, "refresh_rel": 1, "reactions": 3,
             "out_flow": 4, "stall_steps": 1, "last": 3, "inputs": N_INPUTS,
             "scratch": nx + 3 * N_INPUTS}
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


def load_reference(views: dict[str, np.ndarray], phi_stack: np.ndarray, psi_b, load_poly,
                   key: tuple[float, float]) -> None:
    """Copy a reference step of the Python wing (its ``_phi`` = [Φ_r; ∂Φ/∂V], ``_psi_b``,
    ``_load_poly`` and ``_key``) into the parameter blocks, in the kernel's layout."""
    nx = phi_stack.shape[1]
    phi, dphi = phi_stack[:nx], phi_stack[nx:]
    nd = dense_rows(phi, dphi, psi_b)
    views["phi"][:] = np.ravel(phi)
    views["dphi"][:] = np.ravel(dphi)
    views["psi_t"][:] = np.ravel(np.concatenate([np.transpose(p) for p in psi_b]))
    diag = np.zeros((N_DIAG, nx))
    rows = np.arange(nd, nx)
    diag[0, :nx - nd], diag[1, :nx - nd] = phi[rows, rows], dphi[rows, rows]
    for p in range(3):
        diag[2 + p, :nx - nd] = psi_b[p][nd:, GUST]
    views["diag"][:] = np.ravel(diag)
    views["load_poly"][:] = np.ravel(np.stack(load_poly))
    views["n_dense"][0] = nd
    views["key"][:] = key


@numba.njit(cache=True, nogil=True, fastmath=FASTMATH)
def _advance(params, x, f, vt, n):
    """x ← Φ x + ΔV ∂Φ/∂V x + Σ_p V^p Ψ B_p f (in place) and the increments' loads of the
    new state (Z [N, down], M [N·m, nose up]) at the speed ``vt`` [m/s]. The rows from
    ``n_dense`` on are diagonal with the gust as their only input (:func:`dense_rows`).
    Measured (166 states, 86 dense rows; each part alone, least of 9 interleaved rounds of
    20 000 calls, load 0.9): (Φ + ΔV ∂Φ/∂V) x over the dense rows 1.3-1.6 µs (Φ x and
    ∂Φ/∂V x as two passes 4.3 µs, loaded machine); Σ_p V^p Ψ B_p f as 24 column updates
    of the dense rows (the inputs and their products with V and V² side by side, SIMD over
    the rows) 0.23 µs where three 8-term dot products per row took 0.77 µs; the diagonal
    rows from packed vectors 0.07 µs where they were read off the matrices' diagonals with
    their Ψ rows 0.2 µs. Blocking rows two or four at a time (2.1 µs), column-major Φ
    (2.4 µs) and Φ, ∂Φ/∂V interleaved row by row (2.2 µs) were slower. On flat offsets into
    the parameter array instead of 2-D views numba checked every index for wrap-around and
    the loops lost their SIMD (12.6 µs)."""
    nx = x.shape[0]
    o_phi, o_dphi, o_psi = int(params[H_PHI]), int(params[H_DPHI]), int(params[H_PSI])
    o_y, o_key, o_lp = int(params[H_SCRATCH]), int(params[H_KEY]), int(params[H_LOAD])
    o_diag = int(params[H_DIAG])
    nd = int(params[int(params[H_DENSE])])
    phi = params[o_phi:o_phi + nd * nx].reshape((nd, nx))
    dphi = params[o_dphi:o_dphi + nd * nx].reshape((nd, nx))
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
    for i in range(nd):  # (Φ + ΔV ∂Φ/∂V) x, row by row: one pass over both matrices
        a = 0.0
        for j in range(nx):
            a += (phi[i, j] + dv * dphi[i, j]) * x[j]
        y[i] += a
    w_g = f[GUST]
    for k in range(nx - nd):  # each diagonal row reads only its own state: in place
        x[nd + k] = ((diag[0, k] + dv * diag[1, k]) * x[nd + k]
                     + (diag[2, k] + vt * diag[3, k] + v2 * diag[4, k]) * w_g)
    for i in range(nd):
        x[i] = y[i]
    m = nx + N_INPUTS
    lp = params[o_lp:o_lp + 6 * m].reshape((3, 2, m))  # [power of V, Z or M, x and f]
    z_inc = m_inc = 0.0
    for j in range(nx):
        z_inc += (lp[0, 0, j] + vt * lp[1, 0, j] + v2 * lp[2, 0, j]) * x[j]
        m_inc += (lp[0, 1, j] + vt * lp[1, 1, j] + v2 * lp[2, 1, j]) * x[j]
    for j in range(N_INPUTS):
        z_inc += (lp[0, 0, nx + j] + vt * lp[1, 0, nx + j] + v2 * lp[2, 0, nx + j]) * f[j]
        m_inc += (lp[0, 1, nx + j] + vt * lp[1, 1, nx + j] + v2 * lp[2, 1, nx + j]) * f[j]
    return z_inc, m_inc


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
