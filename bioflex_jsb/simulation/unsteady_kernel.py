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
∂Φ/∂V are diagonal too: :func:`dense_rows` finds how many leading rows are not (86 of 166
here) by testing for exact zeros, and the kernel multiplies only those densely (exactly the
Python step's products, whose other terms are zeros). The dense products are reductions
compiled with reassociation allowed (SIMD): the sums are taken in another order than BLAS
takes them, which changes the last digits only (``tests/test_unsteady_kernel.py``).
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
BLOCKS = ("header", "phi", "dphi", "psi_b", "load_poly", "key", "n_dense", "trim",
          "load_eta", "load_etadot", "consts", "dt", "k_induced2", "refresh_rel",
          "reactions", "out_flow", "stall_steps", "last", "inputs", "scratch")
H_PHI, H_DPHI, H_PSI, H_LOAD, H_KEY, H_DENSE, H_TRIM, H_LE, H_LD, H_C, H_DT, H_K2, \
    H_RR, H_REACT, H_FLOW, H_STALL, H_LAST, H_F, H_SCRATCH = range(1, len(BLOCKS))
FASTMATH = {"reassoc", "contract"}  # SIMD sums and fused multiply-adds; NaN and inf kept


def layout(n_modes: int, n_states: int) -> dict[str, tuple[int, int]]:
    """Where each block sits in the flat parameter array of :func:`unsteady_kernel` for
    ``n_modes`` modes and ``n_states`` wing states: name → (offset, length). The offsets are
    also written into the array's header (block 0), which is how the kernel finds them.

    Blocks: phi, dphi (n_x × n_x, row-major): Φ_r and ∂Φ/∂V [1/(m/s)]; psi_b (3, n_x, 8):
    Ψ_r B_p, p = 0, 1, 2 (the powers of V); load_poly (3, 2, n_x + 8): the increments' body
    loads [Z [N, down]; M [N·m, nose up]] per power of V on [x; f]; key: (Q_r [Pa], V_r
    [m/s]); n_dense: rows of phi and dphi multiplied densely; trim: α_0 [rad], θ_0 [rad],
    Q_0 [Pa], V_0 [m/s]; load_eta, load_etadot: (3, n) modal loads per unit Q S; consts: as
    the quasi-steady kernel's; dt [s]; k_induced2: induced drag per unit lift 2 k C_L0 [-];
    refresh_rel; out: reactions [lbf, lbf, lbf·ft], out_flow (α [rad], q [rad/s], Q [Pa],
    V [m/s]), stall_steps; last: (stepped yet, α_i [rad], q [rad/s]) of the last step;
    inputs: its f; scratch."""
    n, nx = n_modes, n_states
    sizes = {"header": len(BLOCKS), "phi": nx * nx, "dphi": nx * nx,
             "psi_b": 3 * nx * N_INPUTS, "load_poly": 3 * 2 * (nx + N_INPUTS), "key": 2,
             "n_dense": 1, "trim": 4, "load_eta": 3 * n, "load_etadot": 3 * n,
             "consts": N_CONSTS, "dt": 1, "k_induced2": 1, "refresh_rel": 1, "reactions": 3,
             "out_flow": 4, "stall_steps": 1, "last": 3, "inputs": N_INPUTS,
             "scratch": nx}
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


def dense_rows(phi: np.ndarray, dphi: np.ndarray) -> int:
    """How many leading rows of Φ and ∂Φ/∂V carry entries off the diagonal: every row after
    them is diagonal in both (exact zeros elsewhere), so multiplying only their diagonal
    is the same product."""
    off = (phi != 0.0) | (dphi != 0.0)
    np.fill_diagonal(off, False)
    rows = np.flatnonzero(off.any(axis=1))
    return int(rows[-1]) + 1 if rows.size else 0


def load_reference(views: dict[str, np.ndarray], phi_stack: np.ndarray, psi_b, load_poly,
                   key: tuple[float, float]) -> None:
    """Copy a reference step of the Python wing (its ``_phi`` = [Φ_r; ∂Φ/∂V], ``_psi_b``,
    ``_load_poly`` and ``_key``) into the parameter blocks."""
    nx = phi_stack.shape[1]
    phi, dphi = phi_stack[:nx], phi_stack[nx:]
    views["phi"][:] = np.ravel(phi)
    views["dphi"][:] = np.ravel(dphi)
    views["psi_b"][:] = np.ravel(np.stack(psi_b))
    views["load_poly"][:] = np.ravel(np.stack(load_poly))
    views["n_dense"][0] = dense_rows(phi, dphi)
    views["key"][:] = key


@numba.njit(cache=True, nogil=True, fastmath=FASTMATH)
def _advance(params, x, f, vt, n):
    """x ← Φ x + ΔV ∂Φ/∂V x + Σ_p V^p Ψ B_p f (in place) and the increments' loads of the
    new state (Z [N, down], M [N·m, nose up]) at the speed ``vt`` [m/s]. The rows of Φ,
    ∂Φ/∂V from ``n_dense`` on are diagonal. Measured (166 states, 86 dense rows, loaded
    machine): Φ x and ∂Φ/∂V x as two passes 4.3 µs, (Φ + ΔV ∂Φ/∂V) x in one 2.9 µs; on flat
    offsets into the parameter array instead of 2-D views numba checked every index for
    wrap-around and the loops lost their SIMD (12.6 µs)."""
    nx = x.shape[0]
    o_phi, o_dphi, o_psi = int(params[H_PHI]), int(params[H_DPHI]), int(params[H_PSI])
    o_y, o_key, o_lp = int(params[H_SCRATCH]), int(params[H_KEY]), int(params[H_LOAD])
    phi = params[o_phi:o_phi + nx * nx].reshape((nx, nx))
    dphi = params[o_dphi:o_dphi + nx * nx].reshape((nx, nx))
    psi = params[o_psi:o_psi + 3 * nx * N_INPUTS].reshape((3, nx, N_INPUTS))
    y = params[o_y:o_y + nx]
    nd = int(params[int(params[H_DENSE])])
    dv, v2 = vt - params[o_key + 1], vt * vt
    for i in range(nd):  # (Φ + ΔV ∂Φ/∂V) x, row by row: one pass over both matrices
        a = 0.0
        for j in range(nx):
            a += (phi[i, j] + dv * dphi[i, j]) * x[j]
        y[i] = a
    for i in range(nd, nx):
        y[i] = (phi[i, i] + dv * dphi[i, i]) * x[i]
    for i in range(nx):
        p0 = p1 = p2 = 0.0
        for j in range(N_INPUTS):
            p0 += psi[0, i, j] * f[j]
            p1 += psi[1, i, j] * f[j]
            p2 += psi[2, i, j] * f[j]
        x[i] = y[i] + p0 + vt * p1 + v2 * p2
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
