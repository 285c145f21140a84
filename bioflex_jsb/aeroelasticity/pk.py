"""p-k flutter solution of a modal wing on frequency-domain strip aerodynamics.

At airspeed V the modal equations with harmonic aerodynamics are, for the eigenvalue p [1/s]
of one branch with frequency ω = Im p,

    [(I + M_a) p² + (C_s + B_a − D C E) p + (K − D C W)] η = 0,   C = diag(C(ω b_k / V))

(:mod:`bioflex_jsb.aeroelasticity.strip_aero`). Only C(k) is frozen at the branch's own
frequency; the apparent-mass and upwash terms keep their exact p-dependence, so the damping
is right at the flutter boundary (Re p = 0), where the p-k and the exact k-method agree
(Hassig 1971, "An approximate true damping solution of the flutter equation by determinant
iteration", J. Aircraft 8(11), 885-889). The frozen-C eigenproblem is solved by its
first-order companion form; each branch iterates ω until it repeats.

Tracking: branches start at the wind-off roots p = iω_i(1 + iζ) at the lowest speed and are
followed in small steps from their linear extrapolation over the two previous speeds; the
roots are shared out among the branches by joint nearest assignment (Hungarian algorithm),
so that two branches cannot settle on one root near a coalescence. The first sign change of a
branch's Re p is refined by Brent's method on that branch.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq, linear_sum_assignment

from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.aeroelasticity.flutter import (
    FlutterResult,
    classify_mechanism,
    divergence_speed_m_s,
)
from bioflex_jsb.aeroelasticity.strip_aero import (
    check_aero,
    circulation_functions,
    modal_strip_matrices,
)

# DEFINITIONS of the iteration: the frequency iteration stops when ω changes by less than
# this fraction of the lowest natural frequency, or after the maximum number of passes.
_OMEGA_TOL_FRAC = 1e-10
_MAX_ITER = 100
# Speed step of the tracking sweep [m/s]. ESTIMATE: 2 m/s keeps every Goland branch's root
# change per step far below the gap between branches (no swaps; checked in the tests).
DEFAULT_SPEED_STEP_M_S = 2.0


def _roots(model, mats, damping, omega_ref, aero):
    """All 2n eigenvalues of the frozen-C quadratic problem with C at ω_ref."""
    c = circulation_functions(mats, max(omega_ref, 0.0), aero)
    n = model.n_modes
    m_t = model.mass + mats.apparent_mass
    c_t = damping + mats.apparent_damping - mats.force @ (c[:, None] * mats.upwash_rate)
    k_t = model.stiffness - mats.force @ (c[:, None] * mats.upwash_displacement)
    a = np.zeros((2 * n, 2 * n), dtype=complex)
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -np.linalg.solve(m_t, k_t)
    a[n:, n:] = -np.linalg.solve(m_t, c_t)
    return np.linalg.eigvals(a)


def _branch_root(model, mats, damping, aero, guesses: np.ndarray, branch: int) -> complex:
    """The root of one branch at one speed, iterated on its own frequency.

    ``guesses`` (n,) are the predicted roots of all branches. At each pass the roots of the
    problem frozen at this branch's frequency are shared out among all branches by joint
    nearest assignment, and this branch takes its share: near a coalescence two branches
    then cannot both settle on the same (stable) root.
    """
    tol = _OMEGA_TOL_FRAC * float(model.natural_frequencies_rad_s.min())
    guesses = np.asarray(guesses, dtype=complex)
    p = complex(guesses[branch])
    for _ in range(_MAX_ITER):
        roots = _roots(model, mats, damping, abs(p.imag), aero)
        upper = roots[roots.imag >= -1e-9 * np.abs(roots).max()]
        cost = np.abs(guesses[:, None] - upper[None, :])
        rows, cols = linear_sum_assignment(cost)
        new = complex(upper[cols[list(rows).index(branch)]])
        if abs(abs(new.imag) - abs(p.imag)) <= tol:
            return new
        p = new
    return p


def structural_damping_matrix(model: ClampedWingModel, zeta: float) -> np.ndarray:
    """Modal viscous damping diag(2 ζ ω_i) [1/s] (ζ [-] the same for every mode)."""
    return np.diag(2.0 * float(zeta) * model.natural_frequencies_rad_s)


def pk_sweep(
    model: ClampedWingModel,
    speeds_m_s: np.ndarray,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
) -> np.ndarray:
    """Tracked branch roots p [1/s], shape (len(speeds), n_modes), over increasing speeds."""
    check_aero(aero)
    speeds = np.asarray(speeds_m_s, dtype=float)
    if np.any(np.diff(speeds) <= 0.0) or speeds[0] <= 0.0:
        raise ValueError("speeds_m_s must be positive and increasing")
    damping = structural_damping_matrix(model, structural_damping)
    w0 = model.natural_frequencies_rad_s
    zeta = float(structural_damping)
    prev = [1j * w0 * math.sqrt(max(1.0 - zeta * zeta, 0.0)) - zeta * w0]
    out = np.empty((speeds.size, model.n_modes), dtype=complex)
    for i, v in enumerate(speeds):
        mats = modal_strip_matrices(model, speed_m_s=v, density_kg_m3=density_kg_m3)
        if len(prev) >= 2 and i >= 2:
            h0, h1 = speeds[i - 1] - speeds[i - 2], v - speeds[i - 1]
            guess = prev[-1] + (prev[-1] - prev[-2]) * (h1 / h0)
        else:
            guess = prev[-1]
        out[i] = [_branch_root(model, mats, damping, aero, guess, b)
                  for b in range(model.n_modes)]
        prev.append(out[i].copy())
    return out


def pk_flutter(
    model: ClampedWingModel,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    speed_step_m_s: float = DEFAULT_SPEED_STEP_M_S,
) -> FlutterResult:
    """First flutter or divergence of ``model`` in ``speed_range_m_s`` by the p-k method."""
    lo, hi = (float(x) for x in speed_range_m_s)
    speeds = np.arange(lo, hi + 0.5 * speed_step_m_s, speed_step_m_s)
    roots = pk_sweep(model, speeds, density_kg_m3=density_kg_m3, aero=aero,
                     structural_damping=structural_damping)
    labels = model.mode_labels()
    w0 = model.natural_frequencies_rad_s
    v_div = divergence_speed_m_s(model, density_kg_m3)
    base = dict(natural_frequencies_rad_s=tuple(float(x) for x in w0), mode_labels=labels,
                divergence_speed_m_s=v_div, method="pk", aero=aero,
                lift_slope=model.lift_slope, structural_damping=float(structural_damping),
                speeds_m_s=speeds, branch_roots=roots)
    unstable = roots.real > 0.0
    hits = np.argwhere(unstable[1:] & ~unstable[:-1])
    if hits.size == 0:
        return FlutterResult(None, None, None, None, None, None, **base)
    j = int(hits[:, 0].min())
    branch = int(hits[hits[:, 0] == j][:, 1][0])
    damping = structural_damping_matrix(model, structural_damping)

    def root_at(v: float) -> np.ndarray:
        mats = modal_strip_matrices(model, speed_m_s=v, density_kg_m3=density_kg_m3)
        frac = (v - speeds[j]) / (speeds[j + 1] - speeds[j])
        guess = roots[j] + frac * (roots[j + 1] - roots[j])
        return np.array([_branch_root(model, mats, damping, aero, guess, b)
                         for b in range(model.n_modes)])

    v_f = brentq(lambda v: root_at(v)[branch].real, speeds[j], speeds[j + 1], xtol=1e-6)
    r = root_at(v_f)
    omega = abs(r[branch].imag)
    mech, partner = classify_mechanism(np.abs(r.imag), w0, branch, omega)
    b_ref = float(np.mean(model.semichord_m))
    return FlutterResult(
        speed_m_s=float(v_f), frequency_rad_s=float(omega),
        reduced_frequency=float(omega * b_ref / v_f), mode=labels[branch],
        partner_mode=None if partner is None else labels[partner], mechanism=mech, **base,
    )
