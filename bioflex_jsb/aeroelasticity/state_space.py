"""Flutter by eigen-analysis of the modal structure with finite-state strip aerodynamics.

State vector z = (η [kg^½·m], η̇ [kg^½·m/s], x [m]): the M-orthonormal modal coordinates of
:mod:`bioflex_jsb.aeroelasticity.clamped_wing` (their heave shapes are in m per unit η, so η
carries kg^½·m), their rates, and the aerodynamic lag states of every strip
(:func:`bioflex_jsb.aeroelasticity.strip_aero.finite_state_model`: Jones's Wagner states,
optionally Küssner's gust states). With the modal mass I, stiffness K = diag(ω²) and viscous
damping C_s = diag(2ζω):

    (I + M_a) η̈ = −(K − D_q) η − (C_s − D_qd) η̇ + C x + D_g w_g
    ẋ = A x + B_q η + B_qd η̇ + B_g w_g

The eigenvalues are tracked over speed: each branch (one per structural mode, started at its
wind-off root) takes, at the next speed, the eigenvalue nearest to its linear prediction,
the branches being assigned jointly (Hungarian assignment) so that two cannot take the same
root. The lag roots are real and stable; the first root to cross into the right half plane
sets the flutter (or divergence) speed, refined by Brent's method on the largest real part.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, linear_sum_assignment

from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.aeroelasticity.flutter import (
    FlutterResult,
    classify_mechanism,
    divergence_speed_m_s,
)
from bioflex_jsb.aeroelasticity.pk import structural_damping_matrix
from bioflex_jsb.aeroelasticity.strip_aero import check_aero, finite_state_model

# Speed step of the tracking sweep [m/s]. ESTIMATE: as for the p-k sweep (2 m/s: no branch
# swaps on the Goland wing).
DEFAULT_SPEED_STEP_M_S = 2.0


@dataclass(frozen=True, eq=False)
class AeroelasticSystem:
    """ż = A z + B_g w_g of the wing at one speed; ``state_names`` / ``state_units``."""

    a: np.ndarray
    b_gust: np.ndarray
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    n_modes: int
    speed_m_s: float


def aeroelastic_system(
    model: ClampedWingModel, *, speed_m_s: float, density_kg_m3: float,
    aero: str = "unsteady", structural_damping: float = 0.0, gust: bool = False,
) -> AeroelasticSystem:
    """The first-order aeroelastic system of the module docstring at ``speed_m_s``."""
    check_aero(aero)
    fs = finite_state_model(model, speed_m_s=speed_m_s, density_kg_m3=density_kg_m3,
                            aero=aero, gust=gust)
    n, nx = model.n_modes, fs.n_states
    m_t = model.mass + fs.apparent_mass
    c_s = structural_damping_matrix(model, structural_damping)
    a = np.zeros((2 * n + nx, 2 * n + nx))
    a[:n, n:2 * n] = np.eye(n)
    a[n:2 * n, :n] = np.linalg.solve(m_t, fs.d_q - model.stiffness)
    a[n:2 * n, n:2 * n] = np.linalg.solve(m_t, fs.d_qd - c_s)
    b_g = np.zeros(2 * n + nx)
    b_g[n:2 * n] = np.linalg.solve(m_t, fs.d_g)
    if nx:
        a[n:2 * n, 2 * n:] = np.linalg.solve(m_t, fs.c)
        a[2 * n:, :n] = fs.b_q
        a[2 * n:, n:2 * n] = fs.b_qd
        a[2 * n:, 2 * n:] = fs.a
        b_g[2 * n:] = fs.b_g
    names = tuple(f"eta_{i + 1}" for i in range(n)) + tuple(
        f"eta_dot_{i + 1}" for i in range(n)) + fs.state_names
    units = ("kg^0.5 m",) * n + ("kg^0.5 m/s",) * n + fs.state_units
    return AeroelasticSystem(a, b_g, names, units, n, float(speed_m_s))


def _eigenvalues(model, v, density, aero, zeta) -> np.ndarray:
    sys = aeroelastic_system(model, speed_m_s=v, density_kg_m3=density, aero=aero,
                             structural_damping=zeta)
    return np.linalg.eigvals(sys.a)


def _assign(candidates: np.ndarray, predicted: np.ndarray) -> np.ndarray:
    """The candidate eigenvalue of each branch, nearest to its prediction, assigned jointly."""
    cost = np.abs(predicted[:, None] - candidates[None, :])
    rows, cols = linear_sum_assignment(cost)
    out = np.empty(predicted.size, dtype=complex)
    out[rows] = candidates[cols]
    return out


def state_space_sweep(
    model: ClampedWingModel, speeds_m_s: np.ndarray, *, density_kg_m3: float,
    aero: str = "unsteady", structural_damping: float = 0.0,
) -> tuple[np.ndarray, list[np.ndarray]]:
    """Tracked branch roots (len(speeds), n_modes) and all eigenvalues at every speed."""
    speeds = np.asarray(speeds_m_s, dtype=float)
    if np.any(np.diff(speeds) <= 0.0) or speeds[0] <= 0.0:
        raise ValueError("speeds_m_s must be positive and increasing")
    zeta = float(structural_damping)
    w0 = model.natural_frequencies_rad_s
    history = [1j * w0 * np.sqrt(max(1.0 - zeta * zeta, 0.0)) - zeta * w0]
    tracked = np.empty((speeds.size, model.n_modes), dtype=complex)
    every = []
    for i, v in enumerate(speeds):
        lam = _eigenvalues(model, v, density_kg_m3, aero, zeta)
        every.append(lam)
        cand = lam[lam.imag >= -1e-9 * np.abs(lam).max()]
        if i >= 2:
            h0, h1 = speeds[i - 1] - speeds[i - 2], v - speeds[i - 1]
            pred = history[-1] + (history[-1] - history[-2]) * (h1 / h0)
        else:
            pred = history[-1]
        tracked[i] = _assign(cand, pred)
        history.append(tracked[i].copy())
    return tracked, every


def state_space_flutter(
    model: ClampedWingModel,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    speed_step_m_s: float = DEFAULT_SPEED_STEP_M_S,
) -> FlutterResult:
    """First flutter or divergence of ``model`` in ``speed_range_m_s`` by eigen-analysis."""
    lo, hi = (float(x) for x in speed_range_m_s)
    speeds = np.arange(lo, hi + 0.5 * speed_step_m_s, speed_step_m_s)
    tracked, every = state_space_sweep(model, speeds, density_kg_m3=density_kg_m3, aero=aero,
                                       structural_damping=structural_damping)
    labels = model.mode_labels()
    w0 = model.natural_frequencies_rad_s
    base = dict(natural_frequencies_rad_s=tuple(float(x) for x in w0), mode_labels=labels,
                divergence_speed_m_s=divergence_speed_m_s(model, density_kg_m3),
                method="state-space", aero=aero, lift_slope=model.lift_slope,
                structural_damping=float(structural_damping), speeds_m_s=speeds,
                branch_roots=tracked)
    max_re = np.array([lam.real.max() for lam in every])
    hits = np.flatnonzero((max_re[1:] > 0.0) & (max_re[:-1] <= 0.0))
    if hits.size == 0:
        return FlutterResult(None, None, None, None, None, None, **base)
    j = int(hits[0])

    def growth(v: float) -> float:
        return float(_eigenvalues(model, v, density_kg_m3, aero, structural_damping).real.max())

    v_f = brentq(growth, speeds[j], speeds[j + 1], xtol=1e-6)
    lam = _eigenvalues(model, v_f, density_kg_m3, aero, structural_damping)
    crossing = complex(lam[np.argmax(lam.real)])
    frac = (v_f - speeds[j]) / (speeds[j + 1] - speeds[j])
    pred = tracked[j] + frac * (tracked[j + 1] - tracked[j])
    branches = _assign(lam[lam.imag >= -1e-9 * np.abs(lam).max()], pred)
    branch = int(np.argmin(np.abs(branches - complex(crossing.real, abs(crossing.imag)))))
    omega = abs(crossing.imag)
    mech, partner = classify_mechanism(np.abs(branches.imag), w0, branch, omega)
    b_ref = float(np.mean(model.semichord_m))
    return FlutterResult(
        speed_m_s=float(v_f), frequency_rad_s=float(omega),
        reduced_frequency=float(omega * b_ref / v_f), mode=labels[branch],
        partner_mode=None if partner is None else labels[partner], mechanism=mech, **base,
    )
