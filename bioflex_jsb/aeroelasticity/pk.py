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

Tracking and the flutter search are the one engine's
(:mod:`bioflex_jsb.flight_dynamics.flutter_engine`): :class:`PkFamily` gives it the branches,
started at the wind-off roots p = iω_i√(1 − ζ²) − ζω_i at the lowest speed and followed
from their linear extrapolation over the two previous speeds; at each pass of a branch's
frequency iteration the roots are shared out among all branches by the engine's joint
assignment, so that two branches cannot settle on one root near a coalescence.

**Over-damped (aperiodic) roots.** A branch whose mode is over-damped has a real root,
ω = 0, where C = C(0) = 1 and the frozen problem is real: its real roots are exact p-k
solutions (as in NASTRAN's PK method, aperiodic roots are solved at k = 0). Frozen at another
branch's ω > 0, C is complex and the roots near the real axis fall on either side of it
(the Patil-Hodges flying wing's first bending mode, over-damped from a few m/s, had both of
its near-real roots just below the axis at 19 rad/s: the upper-half filter kept five roots
for six branches). So the candidates a branch's pass shares out are the roots of the
problem frozen at its ω that lie clearly above the axis (Im p above the engine's static
frequency, :func:`real_root_tolerance_rad_s`) together with the real roots of the problem
at ω = 0 (computed once per speed); a branch that takes a real root has converged. The two
sets hold at least as many roots as branches when the upper-half roots at ω = 0 are added,
which they are when the first two fall short (one branch per mode: of an over-damped mode's
two real roots the branch follows the one nearest its prediction).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aeroelasticity.clamped_wing import (
    ClampedWingModel,
    structural_damping_matrix,
)
from bioflex_jsb.aeroelasticity.strip_aero import (
    check_aero,
    circulation_functions,
    divergence_speed_m_s,
    modal_strip_matrices,
)
from bioflex_jsb.flight_dynamics import flutter_engine as engine

# DEFINITIONS of the iteration: the frequency iteration stops when ω changes by less than
# this fraction of the lowest natural frequency, or after the maximum number of passes.
_OMEGA_TOL_FRAC = 1e-10
_MAX_ITER = 100
# Speed step of the tracking sweep [m/s]. ESTIMATE: 2 m/s keeps every Goland branch's root
# change per step far below the gap between branches (no swaps; checked in the tests).
DEFAULT_SPEED_STEP_M_S = 2.0
# Bisection tolerance of the clamped searches [m/s]: far below any figure reported (0.01).
CLAMPED_TOL_M_S = 1e-7


def _frozen_matrix(model, mats, damping, c: np.ndarray) -> np.ndarray:
    """The first-order companion matrix (2n, 2n) of the quadratic problem with C = ``c``."""
    n = model.n_modes
    m_t = model.mass + mats.apparent_mass
    c_t = damping + mats.apparent_damping - mats.force @ (c[:, None] * mats.upwash_rate)
    k_t = model.stiffness - mats.force @ (c[:, None] * mats.upwash_displacement)
    a = np.zeros((2 * n, 2 * n), dtype=complex)
    a[:n, n:] = np.eye(n)
    a[n:, :n] = -np.linalg.solve(m_t, k_t)
    a[n:, n:] = -np.linalg.solve(m_t, c_t)
    return a


def _roots(model, mats, damping, omega_ref, aero):
    """All 2n eigenvalues of the frozen-C quadratic problem with C at ω_ref."""
    c = circulation_functions(mats, max(omega_ref, 0.0), aero)
    return np.linalg.eigvals(_frozen_matrix(model, mats, damping, c))


def real_root_tolerance_rad_s(model: ClampedWingModel) -> float:
    """|Im p| [rad/s] at or below which a p-k root is real (aperiodic): the engine's static
    frequency (a fraction of the lowest natural frequency, at least its absolute floor)."""
    low = float(model.natural_frequencies_rad_s.min())
    return max(engine.IMAG_TOL_RAD_S, engine.STATIC_FREQUENCY_FRACTION * low)


@dataclass(frozen=True, eq=False)
class ZeroFrequencyRoots:
    """The roots of the problem at ω = 0 (C = 1, a real matrix): ``real`` (exact aperiodic
    p-k roots, Im = 0) and ``upper`` (Im > 0; candidates only when too few others)."""

    real: np.ndarray
    upper: np.ndarray


def zero_frequency_roots(model, mats, damping) -> ZeroFrequencyRoots:
    """The roots at ω = 0 of one speed's frozen problem (module docstring)."""
    c0 = np.ones(mats.semichord_m.size)
    lam = np.linalg.eigvals(_frozen_matrix(model, mats, damping, c0).real)
    real = lam.imag == 0.0  # a real matrix: LAPACK returns real roots with Im exactly 0
    return ZeroFrequencyRoots(real=lam[real].real.astype(complex), upper=lam[lam.imag > 0.0])


def candidates(roots: np.ndarray, zero: ZeroFrequencyRoots, n_branches: int,
               tol_rad_s: float) -> np.ndarray:
    """The roots one pass shares out among ``n_branches`` branches (module docstring):
    ``roots`` of the frozen problem with Im p > ``tol_rad_s``, the real roots at ω = 0, and,
    when these are fewer than the branches, the upper-half roots at ω = 0."""
    out = np.concatenate([roots[roots.imag > tol_rad_s], zero.real])
    if out.size < n_branches:
        out = np.concatenate([out, zero.upper])
    return out


def _branch_root(model, mats, damping, aero, guesses: np.ndarray, branch: int,
                 zero: ZeroFrequencyRoots) -> complex:
    """The root of one branch at one speed, iterated on its own frequency.

    ``guesses`` (n,) are the predicted roots of all branches. At each pass the
    :func:`candidates` of the problem frozen at this branch's frequency are shared out among
    all branches by joint nearest assignment, and this branch takes its share: near a
    coalescence two branches then cannot both settle on the same (stable) root. A real
    share is an aperiodic root at ω = 0, consistent as it stands.
    """
    n = model.n_modes
    tol = _OMEGA_TOL_FRAC * float(model.natural_frequencies_rad_s.min())
    tol_real = real_root_tolerance_rad_s(model)
    guesses = np.asarray(guesses, dtype=complex)
    p = complex(guesses[branch])
    for _ in range(_MAX_ITER):
        roots = _roots(model, mats, damping, abs(p.imag), aero)
        pool = candidates(roots, zero, n, tol_real)
        new = complex(pool[engine.assign(guesses, pool)[branch]])
        if new.imag == 0.0 or abs(abs(new.imag) - abs(p.imag)) <= tol:
            return new
        p = new
    return p


class PkFamily(engine.RootFamily):
    """The clamped wing's p-k branches (one per structural mode) for the engine."""

    extrapolate = True
    method = "pk"

    def __init__(self, model: ClampedWingModel, *, density_kg_m3: float,
                 aero: str = "unsteady", structural_damping: float = 0.0,
                 name: str = "") -> None:
        self.model = model
        self.density_kg_m3 = float(density_kg_m3)
        self.aero = check_aero(aero)
        self.zeta = float(structural_damping)
        self.damping = structural_damping_matrix(model, self.zeta)
        self.labels = model.mode_labels()
        self.mode_labels = self.labels
        self.considered = np.ones(model.n_modes, dtype=bool)
        self.natural_frequencies_rad_s = tuple(float(w) for w in
                                               model.natural_frequencies_rad_s)
        self.reference_semichord_m = float(np.mean(model.semichord_m))
        self.divergence_speed_m_s = finite_or_none(divergence_speed_m_s(
            model, self.density_kg_m3))
        self.divergence_is_instability = True
        self.name = name

    def _at(self, v: float, guesses: np.ndarray) -> engine.Point:
        mats = modal_strip_matrices(self.model, speed_m_s=v, density_kg_m3=self.density_kg_m3)
        zero = zero_frequency_roots(self.model, mats, self.damping)
        roots = np.array([_branch_root(self.model, mats, self.damping, self.aero, guesses, b,
                                       zero) for b in range(self.model.n_modes)])
        return engine.Point(float(v), roots)

    def first(self, speed_m_s: float) -> engine.Point:
        w0 = self.model.natural_frequencies_rad_s
        z = self.zeta
        return self._at(speed_m_s, 1j * w0 * math.sqrt(max(1.0 - z * z, 0.0)) - z * w0)

    def follow(self, speed_m_s, previous, predicted) -> engine.Point:
        return self._at(speed_m_s, predicted)


def finite_or_none(v: float) -> float | None:
    return v if math.isfinite(v) else None


def pk_sweep(
    model: ClampedWingModel,
    speeds_m_s: np.ndarray,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
) -> np.ndarray:
    """Tracked branch roots p [1/s], shape (len(speeds), n_modes), over increasing speeds."""
    fam = PkFamily(model, density_kg_m3=density_kg_m3, aero=aero,
                   structural_damping=structural_damping)
    return engine.scan(fam, speeds_m_s).roots


def pk_flutter(
    model: ClampedWingModel,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    speed_step_m_s: float = DEFAULT_SPEED_STEP_M_S,
    name: str = "",
    progress=None,
    full_scan: bool = False,
) -> engine.FlutterResult:
    """First flutter or divergence of ``model`` in ``speed_range_m_s`` by the p-k method
    (the engine's search, bisected to :data:`CLAMPED_TOL_M_S`; ``progress``, ``full_scan``:
    :func:`~bioflex_jsb.flight_dynamics.flutter_engine.first_instability`'s)."""
    fam = PkFamily(model, density_kg_m3=density_kg_m3, aero=aero,
                   structural_damping=structural_damping, name=name)
    return clamped_search(fam, model, speed_range_m_s, speed_step_m_s, progress=progress,
                          full_scan=full_scan)


def clamped_search(fam: engine.RootFamily, model: ClampedWingModel,
                   speed_range_m_s: tuple[float, float],
                   speed_step_m_s: float, *, progress=None,
                   full_scan: bool = False) -> engine.FlutterResult:
    """The engine's search over a clamped wing's family (p-k or state space) on a grid of
    ``speed_step_m_s`` [m/s], bisected to :data:`CLAMPED_TOL_M_S`."""
    return engine.first_instability(
        fam, engine.default_grid(speed_range_m_s, speed_step_m_s), speed_range_m_s,
        tol_m_s=CLAMPED_TOL_M_S, structural_damping=float(fam.zeta),
        density_kg_m3=fam.density_kg_m3, settings={"lift_slope": model.lift_slope},
        progress=progress, full_scan=full_scan)
