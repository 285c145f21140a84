"""The modal wing's matrices in per-unit form: the one builder for the co-simulation step
(:mod:`bioflex_jsb.simulation.modal_wing`) and the native JSBSim export
(:mod:`bioflex_jsb.generators.native_wing`).

Model (Eq. 2-4 and Table B1/B2 of the paper; the modal coordinates are perturbations Δη
from the static deformation at trim; ``docs/conventions.md`` for signs):

    η̈ = −(Ω² − Q K_a) η − (2ζΩ − (Q/V) D_a) η̇ + Q b_α Δα + (Q/V) b_q q + b_0 ΔQ

with Q the dynamic pressure [Pa], V the airspeed [m/s], Ω = diag(ω_i) [rad/s], and per mode
i (m_i its generalised mass [kg·m²], S, c̄ the reference area [m²] and chord [m]):

* K_a = S c̄ C_ηj^Qi / m_i           [1/(Pa·s²)]  aerodynamic stiffness per unit Q;
* D_a = S c̄² C_η̇j^Qi / (2 m_i)      [m/(Pa·s)]   aerodynamic damping per unit Q/V;
* b_α = S c̄ C_α^Qi / m_i            [1/(Pa·s²)]  forcing per unit Q per rad of Δα;
* b_q = S c̄² C_q^Qi / (2 m_i)       [m/(Pa·s)]   per unit Q/V per rad/s of pitch rate;
* b_0 = S c̄ C_0^Qi / m_i            [1/(Pa·s²)]  per unit change ΔQ of the dynamic pressure,
  C_0^Qi = α_w C_α^Qi + C_mac C_mac^Qi the generalised force of the trimmed wing per unit Q
  (α_w = C_L0 / C_Lα,wing the wing's angle of attack at trim).

Incremental loads per unit Q S (``load_eta``, ``load_etadot``, rows lift, drag, moment·c̄):
ΔL = Q S (C_Lη·Δη + C_Lη̇·Δη̇ c̄/2V), ΔD = k₂ ΔL with k₂ = 2 k C_L0 (induced drag),
ΔM = Q S c̄ (C_mη·Δη + C_mη̇·Δη̇ c̄/2V).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm

from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.parameters.airframe import (
    RigidAerodynamics,
)


@dataclass(frozen=True, eq=False)
class ModalMatrices:
    """The modal wing in per-unit form (SI; module docstring). Arrays per mode i."""

    n: int
    mass_kg_m2: np.ndarray  # m_i
    omega: np.ndarray  # ω_i [rad/s]
    zeta: np.ndarray  # ζ_i [-]
    k_aero: np.ndarray  # (n, n) K_a [1/(Pa·s²)]
    d_aero: np.ndarray  # (n, n) D_a [m/(Pa·s)]
    b_alpha: np.ndarray  # b_α [1/(Pa·s²)]
    b_q: np.ndarray  # b_q [m/(Pa·s)]
    b_0: np.ndarray  # b_0 [1/(Pa·s²)]
    load_eta: np.ndarray  # (3, n) [C_L, C_D, C_m·c̄ (m)] per rad
    load_etadot: np.ndarray  # (3, n) per unit η̇·c̄/(2V) [rad]

    def a_matrix(self, q_pa: float, q_over_v: float) -> np.ndarray:
        """Continuous A (2n×2n) of x = [Δη, Δη̇] at dynamic pressure ``q_pa`` [Pa] and
        ``q_over_v`` = Q/V [Pa·s/m]."""
        n = self.n
        k = np.diag(self.omega**2) - q_pa * self.k_aero
        d = np.diag(2.0 * self.zeta * self.omega) - q_over_v * self.d_aero
        return np.block([[np.zeros((n, n)), np.eye(n)], [-k, -d]])

    def b_matrix(self, q_pa: float, q_over_v: float) -> np.ndarray:
        """Continuous B (2n×3) for the inputs f = [Δα [rad], q [rad/s], ΔQ [Pa]]."""
        n = self.n
        b = np.zeros((2 * n, 3))
        b[n:, 0] = q_pa * self.b_alpha
        b[n:, 1] = q_over_v * self.b_q
        b[n:, 2] = self.b_0
        return b

    def forcing_columns(self) -> np.ndarray:
        """(n, 3) per-unit forcing of η̈ by (Q Δα, Q q / V, ΔQ)."""
        return np.column_stack([self.b_alpha, self.b_q, self.b_0])

    def discrete(self, q_pa: float, q_over_v: float, dt_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Exact zero-order-hold step at (Q, Q/V): Φ = e^{A Δt} (2n×2n) and Ψ (2n×n), the
        columns of ∫_0^Δt e^{A τ} dτ that the η̈ forcing enters."""
        a = self.a_matrix(q_pa, q_over_v)
        n2 = a.shape[0]
        aug = np.zeros((2 * n2, 2 * n2))
        aug[:n2, :n2] = a
        aug[:n2, n2:] = np.eye(n2)
        e = expm(aug * dt_s)
        return e[:n2, :n2], e[:n2, n2 + self.n :]

    def quasi_static_eta(self, q_pa: float, f: np.ndarray) -> np.ndarray:
        """Δη with η̇ = η̈ = 0 (Eq. 9-10) under the forcing ``f`` = (Q Δα, Q q / V, ΔQ) [rad]."""
        k = np.diag(self.omega**2) - q_pa * self.k_aero
        return np.linalg.solve(k, self.forcing_columns() @ f)


def modal_matrices(wing: ElasticWingModel, cl_trim: float,
                   aero: RigidAerodynamics | None = None) -> ModalMatrices:
    """Per-unit modal matrices of ``wing`` with the trim lift coefficient ``cl_trim`` [-]
    (S, c̄ and k of the wing's airframe; ``aero`` replaces its derivatives)."""
    aero = wing.airframe.aero if aero is None else aero
    c = wing.coefficients
    s, cb = wing.airframe.reference.area_m2, wing.airframe.reference.mean_chord_m
    m = np.asarray(wing.generalised_masses_kg_m2, dtype=float)
    c_alpha = np.asarray(c.c_alpha_q, dtype=float)
    alpha_wing = cl_trim / wing.wing_lift_slope_per_rad
    c_0 = alpha_wing * c_alpha + wing.cm_ac * np.asarray(c.c_mac_q, dtype=float)
    k2 = 2.0 * aero.k_induced * cl_trim
    c_l_eta, c_l_etadot = np.asarray(c.c_l_eta, float), np.asarray(c.c_l_etadot, float)
    return ModalMatrices(
        n=wing.n_modes,
        mass_kg_m2=m,
        omega=np.asarray(wing.frequencies_rad_s, dtype=float),
        zeta=np.asarray(wing.damping_ratios, dtype=float),
        k_aero=(s * cb / m)[:, None] * np.asarray(c.c_eta_q, dtype=float),
        d_aero=(s * cb**2 / (2.0 * m))[:, None] * np.asarray(c.c_etadot_q, dtype=float),
        b_alpha=s * cb / m * c_alpha,
        b_q=s * cb**2 / (2.0 * m) * np.asarray(c.c_q_q, dtype=float),
        b_0=s * cb * c_0 / m,
        load_eta=np.vstack([c_l_eta, k2 * c_l_eta, np.asarray(c.c_m_eta, float) * cb]),
        load_etadot=np.vstack([c_l_etadot, k2 * c_l_etadot,
                               np.asarray(c.c_m_etadot, float) * cb]),
    )
