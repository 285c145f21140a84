"""Leapfrog (Strang) splitting of the modal wing with each mode's structure integrated exactly.

The integrator of the native JSBSim wing (:mod:`bioflex_jsb.generators.native_wing`, whose
docstring derives it; ``docs/native.md``). Per mode i, A_i = [[0, 1], [−k_i, −c_i]] (the
structure and the mode's own aerodynamic stiffness and damping at a reference flow) is
integrated exactly; the rest of the acceleration is a kick at mid-step:
x_{k+1} = Φ_h K_k Φ_h x_k, Φ_h = e^{A Δt/2}. The stored state is y = Φ_h x.
:func:`leapfrog_step` is the Python mirror of the XML rows; :func:`leapfrog_eigen_error` the
accuracy check an export must pass.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from bioflex_jsb.flight_dynamics.modal_matrices import ModalMatrices
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3

# Speed range of the export [m/s]: its QSD tables are uniform in V_ref = sqrt(2Q/ρ_ref) from
# 0 to this speed (the aircraft's speed range with margin: Table 1 flies 10-25 m/s; JSBSim
# holds the end values beyond it), and the step's eigenvalues are checked over it.
GRID_SPEED_MAX_M_S = 40.0
GRID_SPEED_STEP_M_S = 0.5


@dataclass(frozen=True)
class LeapfrogCoefficients:
    """Numbers of the coupled model's step (module docstring), per mode i, SI.

    The exactly integrated part of mode i is A_i = [[0, 1], [−k_i, −c_i]] with the structure
    and the mode's own aerodynamic stiffness and damping at the reference flow:
    k_i = ω_i² − Q_r K_a[i, i], c_i = 2ζ_iω_i − (Q_r/V_r) D_a[i, i]. ``half_inv``: Φ_h⁻¹
    of mode i (2×2), Φ_h = e^{A_i Δt/2}: x_k = Φ_h⁻¹ y_k, the state at t_k from the stored
    half-step state. ``rate_eta``, ``rate_rate``: Φ_s[1, 0], Φ_s[1, 1] of Φ_s = e^{A_i Δt};
    ``kick``: Φ_s[1, 1] Δt, the gain of the rest of the acceleration in the new rate;
    ``eta_eta``, ``eta_rate``: the displacement row rewritten to read the new rate
    (Φ_s[0, 0] − Φ_s[0, 1] Φ_s[1, 0] / Φ_s[1, 1], Φ_s[0, 1] / Φ_s[1, 1])."""

    dt_s: float
    q_ref_pa: float
    q_over_v_ref: float  # [Pa s/m]
    half_inv: np.ndarray  # (n, 2, 2)
    rate_eta: np.ndarray  # (n,)  [1/s]
    rate_rate: np.ndarray  # (n,)
    kick: np.ndarray  # (n,)  [s]
    eta_eta: np.ndarray  # (n,)
    eta_rate: np.ndarray  # (n,)  [s]


def leapfrog_coefficients(nums: ModalMatrices, dt_s: float, q_ref_pa: float = 0.0,
                          q_over_v_ref: float = 0.0) -> LeapfrogCoefficients:
    """Φ_s = e^{A_i Δt}, Φ_h = e^{A_i Δt/2} of each mode's exactly integrated part at the
    reference flow (Q_r [Pa], Q_r/V_r [Pa s/m]) and the in-place rows built from them."""
    half_inv, full = [], []
    for i, (w, z) in enumerate(zip(nums.omega, nums.zeta, strict=True)):
        k = w**2 - q_ref_pa * nums.k_aero[i, i]
        c = 2.0 * z * w - q_over_v_ref * nums.d_aero[i, i]
        a = np.array([[0.0, 1.0], [-k, -c]])
        half_inv.append(expm(-a * dt_s / 2.0))
        full.append(expm(a * dt_s))
    f = np.array(full)
    return LeapfrogCoefficients(
        dt_s=float(dt_s),
        q_ref_pa=float(q_ref_pa),
        q_over_v_ref=float(q_over_v_ref),
        half_inv=np.array(half_inv),
        rate_eta=f[:, 1, 0],
        rate_rate=f[:, 1, 1],
        kick=f[:, 1, 1] * dt_s,
        eta_eta=f[:, 0, 0] - f[:, 0, 1] * f[:, 1, 0] / f[:, 1, 1],
        eta_rate=f[:, 0, 1] / f[:, 1, 1],
    )


def leapfrog_step(nums: ModalMatrices, co: LeapfrogCoefficients, y: np.ndarray, q_pa: float,
                  q_over_v: float, inputs: np.ndarray) -> np.ndarray:
    """One step of the stored state y = [η (n), η̇ (n)] in the order the JSBSim system
    computes it (rates first, in mode order, each reading the rates already updated; then the
    displacements from the new rates). ``inputs``: the flow forcing b_α QΔα + b_q (Q/V) q +
    b_0 ΔQ per mode [1/s²]. The Python mirror of the XML, for the checks."""
    n = nums.n
    y = np.array(y, dtype=float)
    eta, rate = y[:n], y[n:]
    eta_old = eta.copy()
    for i in range(n):
        acc = (q_pa * nums.k_aero[i] @ eta_old - co.q_ref_pa * nums.k_aero[i, i] * eta_old[i]
               + q_over_v * nums.d_aero[i] @ rate - co.q_over_v_ref * nums.d_aero[i, i] * rate[i]
               + inputs[i])
        rate[i] = co.rate_eta[i] * eta_old[i] + co.rate_rate[i] * rate[i] + co.kick[i] * acc
    for i in range(n):
        eta[i] = co.eta_eta[i] * eta_old[i] + co.eta_rate[i] * rate[i]
    return y


def leapfrog_matrix(nums: ModalMatrices, co: LeapfrogCoefficients, q_pa: float,
                    q_over_v: float) -> np.ndarray:
    """The step of :func:`leapfrog_step` with no flow input as a (2n×2n) matrix."""
    n2 = 2 * nums.n
    zero = np.zeros(nums.n)
    return np.column_stack([leapfrog_step(nums, co, e, q_pa, q_over_v, zero)
                            for e in np.eye(n2)])


def _continuous_eigenvalues(m: np.ndarray, dt_s: float) -> np.ndarray:
    """λ = ln(μ)/Δt [1/s] of the eigenvalues μ of the step matrix ``m``."""
    return np.log(np.linalg.eigvals(m).astype(complex)) / dt_s


def leapfrog_eigen_error(nums: ModalMatrices, co: LeapfrogCoefficients,
                         speed_max_m_s: float = GRID_SPEED_MAX_M_S,
                         rho_ref: float = SEA_LEVEL_DENSITY_KG_M3) -> tuple[float, float]:
    """(largest relative error of the step's eigenvalues against the exact e^{A(Q, V) Δt},
    the speed [m/s] where it is largest) over level flight at ``rho_ref`` from 0 to
    ``speed_max_m_s`` in 0.5 m/s steps. Eigenvalues compared as λ = ln(μ)/Δt [1/s], each
    exact one against the nearest of the step's."""
    dt_s = co.dt_s
    worst, where = 0.0, 0.0
    for v in np.arange(0.0, speed_max_m_s + 1e-9, GRID_SPEED_STEP_M_S):
        q = 0.5 * rho_ref * v * v
        qv = q / v if v > 0 else 0.0
        exact = _continuous_eigenvalues(expm(nums.a_matrix(q, qv) * dt_s), dt_s)
        step = _continuous_eigenvalues(leapfrog_matrix(nums, co, q, qv), dt_s)
        if not np.all(np.isfinite(step)):
            return math.inf, float(v)
        err = max(np.min(np.abs(step - e)) / abs(e) for e in exact)
        if err > worst:
            worst, where = float(err), float(v)
    return worst, where
