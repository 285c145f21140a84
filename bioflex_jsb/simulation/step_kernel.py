"""The coupled step's per-step numerics as one compiled function (numba).

:class:`bioflex_jsb.runtime.coupled_step.CoupledStep` runs either the readable Python step
(:class:`~bioflex_jsb.simulation.modal_wing.ModalWing`, the reference) or this kernel, which
does the same arithmetic in one call: the flow at the wing from the snapshot and the wind,
the exact modal step with its Fréchet correction (or the quasi-static deflection), the
loads and their rotation to body axes in JSBSim's units, the row of the step and the range
checks that need no JSBSim state after the step. Python keeps the gust, the property reads
and writes, JSBSim's step and the (rare) reference refreshes. ``tests/test_step_kernel.py``
holds both paths to 1e-9 of each channel's range on the golden cases.

Why numba: the per-step work is ~40 scalar operations and three 6×6 products; in Python
each costs an object allocation (the measured profile: 6.5 µs for the wing step, 3.2 µs for
the loads, 2.9 µs for the row, 2.7 µs for the range check, against 7.7 µs for JSBSim's own
step). Compiled, they cost well under a microsecond; numba compiles from the same Python
source, caches the machine code on disk (``cache=True``: paid once per machine) and needs no
build step or compiler at install time.
"""

from __future__ import annotations

import math

import numba
import numpy as np

# Layout of the snapshot array the runtime fills (its property keys, in this order).
READ_KEYS = ("u", "v", "w", "q", "p", "r", "theta", "phi", "psi", "rho", "nz", "h", "agl",
             "lat", "lon", "vn", "ve", "vd", "elevator", "throttle")
# The kernel's output slots, by channel name (the runtime maps them to the table's columns
# by name: ``cols[slot]`` is the column of ``KERNEL_SLOTS[slot]``); η, η̇ follow.
KERNEL_SLOTS = ("u", "alpha", "q", "theta", "n_z", "w_g", "airspeed_m_s", "altitude_m",
                "lift_n", "drag_n", "pitch_moment_n_m", "latitude_rad", "longitude_rad",
                "phi_rad", "theta_rad", "psi_rad", "p_rad_s", "r_rad_s", "elevator_rad",
                "throttle", "alpha_rad", "beta_rad", "v_north_m_s", "v_east_m_s",
                "v_down_m_s")
MODEL_CODES = {"rigid": 0, "coupled": 1, "qsd": 2}
# Status codes of :func:`step_kernel`.
OK = 0
NEEDS_REFRESH = 1  # nothing was done: renew the reference at out_flow[2], out_flow[3]
NON_FINITE = 10
ALPHA_OUT = 11
ETA_OUT = 12

@numba.njit(cache=True, fastmath=False, nogil=True)
def step_kernel(reads, wind_down_fps, w_g, model, x, stack, input_cols, key, refresh_rel,
                trim, k_aero, omega2, forcing, load_eta, load_etadot, consts, cols, row,
                reactions, out_flow):
    """One step of the wing (module docstring). Arrays in SI unless named otherwise.

    reads: the snapshot in :data:`READ_KEYS` order (JSBSim units); wind_down_fps: the NED
    down wind written for this step [ft/s]; w_g: the gust [m/s, up]; model: :data:`MODEL_CODES`;
    x: [Δη, Δη̇] (updated in place to η_{k+1}); stack, input_cols, key: the reference step
    (:meth:`ModalWing._compute_reference`) and its (Q_r [Pa], V_r [m/s]); trim: α_0 [rad],
    θ_0 [rad], Q_0 [Pa], V_0 [m/s]; k_aero, omega2, forcing: the QSD terms; load_eta,
    load_etadot: (3, n) loads per unit Q S; consts: ft→m, slug/ft³→kg/m³, S [m²], c̄ [m],
    N→lbf, N·m→lbf·ft, η limit [rad], α min, α max, α peak [rad]; cols: the table column of
    each slot; row: the table row, filled; reactions: body-axis modal reactions written to
    JSBSim [lbf, lbf, lbf·ft]; out_flow: α [rad], q [rad/s], Q [Pa], V [m/s], beyond-stall
    flag. Returns a status code."""
    m_per_ft, rho_si, s_ref, cbar = consts[0], consts[1], consts[2], consts[3]
    u, v, w, q = reads[0], reads[1], reads[2], reads[3]
    theta, phi = reads[6], reads[7]
    # air-relative body velocity: subtract the NED wind seen in body axes (FGAuxiliary)
    ua = u + wind_down_fps * math.sin(theta)
    va = v - wind_down_fps * math.sin(phi) * math.cos(theta)
    wa = w - wind_down_fps * math.cos(phi) * math.cos(theta)
    vt_fps = math.sqrt(ua * ua + va * va + wa * wa)
    vt = vt_fps * m_per_ft
    alpha = math.atan2(wa, ua)
    qbar = 0.5 * reads[9] * rho_si * vt * vt
    out_flow[0], out_flow[1], out_flow[2], out_flow[3] = alpha, q, qbar, vt
    n2 = x.shape[0]
    n = n2 // 2
    # (written as "not within" so that the NaN key of a wing with no reference yet refreshes)
    if model == 1 and not (abs(qbar - key[0]) <= refresh_rel * abs(key[0])
                           and abs(vt - key[1]) <= refresh_rel * abs(key[1])):
        return NEEDS_REFRESH
    # the row's modal state: η_k, η̇_k (before the step)
    base = len(cols) - 2 * n
    for i in range(n2):
        row[cols[base + i]] = x[i]
    f0 = qbar * (alpha - trim[0])
    f1 = qbar / vt * q
    f2 = qbar - trim[2]
    lift = drag = moment = 0.0
    if model == 1:
        q_r, v_r = key[0], key[1]
        dq, dqv = qbar - q_r, qbar / vt - q_r / v_r
        x_new = np.empty(n2)
        for i in range(n2):
            acc = 0.0
            for j in range(n2):
                acc += (stack[i, j] + dq * stack[n2 + i, j] + dqv * stack[2 * n2 + i, j]) * x[j]
            x_new[i] = acc + input_cols[i, 0] * f0 + input_cols[i, 1] * f1 + input_cols[i, 2] * f2
        for i in range(n2):
            x[i] = x_new[i]
    elif model == 2:
        kq = np.empty((n, n))
        rhs = np.empty(n)
        for i in range(n):
            for j in range(n):
                kq[i, j] = -qbar * k_aero[i, j]
            kq[i, i] += omega2[i]
            rhs[i] = forcing[i, 0] * f0 + forcing[i, 1] * f1 + forcing[i, 2] * f2
        eta_qs = np.linalg.solve(kq, rhs)
        for i in range(n):
            x[i] = eta_qs[i]
            x[n + i] = 0.0
    if model != 0:
        rate = cbar / (2.0 * vt)
        l0 = l1 = l2 = 0.0
        for i in range(n):
            l0 += load_eta[0, i] * x[i] + load_etadot[0, i] * rate * x[n + i]
            l1 += load_eta[1, i] * x[i] + load_etadot[1, i] * rate * x[n + i]
            l2 += load_eta[2, i] * x[i] + load_etadot[2, i] * rate * x[n + i]
        qs = qbar * s_ref
        lift, drag, moment = qs * l0, qs * l1, qs * l2
    ca, sa = math.cos(alpha), math.sin(alpha)
    reactions[0] = (lift * ca + drag * sa) * consts[4]
    reactions[1] = (drag * ca - lift * sa) * consts[4]
    reactions[2] = moment * consts[5]
    # the row of t_k, by slot (KERNEL_SLOTS)
    vals = (vt - trim[3], alpha - trim[0], q, theta - trim[1], reads[10], w_g, vt,
            reads[11] * m_per_ft, lift, drag, moment, reads[13], reads[14], phi, theta,
            reads[8], reads[4], reads[5], reads[18], reads[19], alpha,
            math.asin(va / vt_fps) if vt_fps > 0.0 else 0.0,
            reads[15] * m_per_ft, reads[16] * m_per_ft, reads[17] * m_per_ft)
    for s in range(len(vals)):
        row[cols[s]] = vals[s]
    out_flow[4] = 1.0 if alpha > consts[9] else 0.0
    for c in range(len(cols)):
        if not math.isfinite(row[cols[c]]):
            return NON_FINITE
    if not consts[7] <= alpha <= consts[8]:
        return ALPHA_OUT
    for i in range(n):
        if abs(x[i]) > consts[6]:
            return ETA_OUT
    return OK
