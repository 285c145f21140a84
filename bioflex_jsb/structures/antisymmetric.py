"""The wing's antisymmetric modes with the fuselage's roll freedom (docs/lateral.md).

The symmetric modes (Eq. 3, :mod:`bioflex_jsb.structures.beam`) are the half wing's,
clamped at the root. In an antisymmetric motion the starboard half bends down where the
port half bends up (w(−y) = −w(y), the same for the twist): at the centreline the deflection
and the twist are zero, but the root section turns with the fuselage, which rolls. The half
wing's root is then

* w(0) = 0 and θ(0) = 0 (antisymmetry: the fuselage can neither heave nor pitch one way for
  one half and the other way for the other);
* w'(0) = φ free, the fuselage's roll angle (w positive down, y to starboard: a roll right
  wing down of the whole aircraft is w = φ y), carrying half the fuselage's roll inertia
  I_x,f/2 [kg·m²] (the other half belongs to the port wing).

The same beam elements as the symmetric modes; the free-free pencil has the rigid roll
(ω = 0, w = φ y) among its roots, which the solve keeps apart: the elastic antisymmetric
modes are the roots above it, M-orthogonal to the rigid roll (free-free modes, mean axes:
an elastic mode carries no net rolling momentum, so the rigid aircraft's roll rate p and
the modal coordinates are not coupled by inertia). The pencil is solved shifted,
M φ = μ (K + σ M) φ, ω² = 1/μ − σ, σ the clamped half wing's first ω² (K alone is singular
with the roll free).

Checked against the closed form of a uniform Euler-Bernoulli beam with a rigid central rotary
inertia (:func:`uniform_beam_antisymmetric_bending_rad_s`) and, for J → ∞, the clamped
beam's 1.8751²; for J → 0 the pinned-free beam's 3.9266² (tests/test_antisymmetric.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh
from scipy.optimize import brentq

from bioflex_jsb.structures.beam import (
    DEFAULT_N_ELEMENTS,
    BeamInputError,
    BeamSections,
    assemble,
    assemble_unrestrained,
    sample_nodal_modes,
)

# The rigid roll's root is zero to the shifted solve's round-off, √(ε σ) at most: below
# this fraction of the first elastic ω (measured: at most 7.5e-5 of it on the test beams,
# the prototype's and the c172's wings, roll inertias 0 to 460 kg·m²)
RIGID_TOL_REL = 1e-3


@dataclass(frozen=True, eq=False)
class AntisymmetricSolution:
    """Antisymmetric modes of a half-wing beam with the fuselage's roll freedom.

    ``frequencies_rad_s`` (n,) the elastic modes' ω [rad/s] (ascending; the rigid roll
    left out); ``vectors`` (n_dof, n) their M-orthonormal vectors over the dofs
    [w'(0) = φ, then (w, w', θ) of nodes 1 … n_elements] (generalised mass 1 kg·m² of
    the half aircraft: half wing and half fuselage); ``roll_slope`` (n,) each mode's
    root slope φ [rad per unit]; ``half_roll_inertia_kg_m2`` the rigid roll mode's
    generalised mass, the half aircraft's roll inertia about x [kg·m²] (half wing's
    ∫ m' y² dy with its point masses and S_α terms, plus I_x,f/2); ``nodes_m``."""

    sections: BeamSections
    frequencies_rad_s: np.ndarray
    vectors: np.ndarray
    roll_slope: np.ndarray
    half_roll_inertia_kg_m2: float
    nodes_m: np.ndarray

    def _full(self, i: int) -> np.ndarray:
        """(n_nodes, 3) nodal (w, w', θ) of mode i: the root row (0, φ, 0)."""
        v = self.vectors[:, i]
        return np.vstack([np.array([0.0, v[0], 0.0]), v[1:].reshape(-1, 3)])

    def sample(self, stations_m) -> tuple[np.ndarray, np.ndarray]:
        """(bending [m, down], twist [rad, leading edge up]) of every mode on the
        starboard half at ``stations_m`` [m], each (n, k); the port half is their negative
        at −y."""
        return sample_nodal_modes(self.nodes_m, [self._full(i) for i in
                                                 range(self.frequencies_rad_s.size)],
                                  stations_m)


def solve_antisymmetric(sections: BeamSections, fuselage_roll_inertia_kg_m2: float,
                        n_modes: int = 3, n_elements: int = DEFAULT_N_ELEMENTS
                        ) -> AntisymmetricSolution:
    """The lowest ``n_modes`` elastic antisymmetric modes of the wing described by the
    half-wing ``sections`` on a fuselage of roll inertia ``fuselage_roll_inertia_kg_m2``
    [kg·m²] about x (the whole fuselage's, everything but the wing; module docstring)."""
    j_f = float(fuselage_roll_inertia_kg_m2)
    if not (math.isfinite(j_f) and j_f >= 0.0):
        raise BeamInputError(f"fuselage_roll_inertia_kg_m2: need a finite value >= 0, got "
                             f"{fuselage_roll_inertia_kg_m2!r}")
    k_full, m_full, nodes = assemble_unrestrained(sections, n_elements)
    keep = np.r_[1, np.arange(3, k_full.shape[0])]  # w'(0) = φ, then nodes 1 …
    k = k_full[np.ix_(keep, keep)]
    m = m_full[np.ix_(keep, keep)].copy()
    m[0, 0] += 0.5 * j_f
    if not 1 <= n_modes <= k.shape[0] - 1:
        raise BeamInputError(f"n_modes: need 1..{k.shape[0] - 1}, got {n_modes}")
    k_c, m_c, _ = assemble(sections, n_elements)
    sigma = float(eigh(k_c, m_c, eigvals_only=True, subset_by_index=[0, 0])[0])
    size = k.shape[0]
    mu, vec = eigh(m, k + sigma * m, subset_by_index=[size - n_modes - 1, size - 1])
    mu, vec = mu[::-1], vec[:, ::-1]
    omega2 = 1.0 / mu - sigma
    vec = vec / np.sqrt(np.einsum("ij,ik,kj->j", vec, m, vec))
    omega = np.sqrt(np.maximum(omega2, 0.0))
    if not omega[0] < RIGID_TOL_REL * omega[1]:
        raise BeamInputError(f"the antisymmetric pencil's lowest root {omega[0]:.3g} rad/s is "
                             f"not the rigid roll (the next is {omega[1]:.3g} rad/s)")
    # the rigid roll w = φ y: its generalised mass per unit φ is the half aircraft's I_x
    roll = np.zeros(size)
    roll[0] = 1.0
    roll[1:] = np.column_stack([nodes[1:], np.ones(nodes.size - 1),
                                np.zeros(nodes.size - 1)]).ravel()
    half_ix = float(roll @ m @ roll)
    elastic = vec[:, 1:]
    return AntisymmetricSolution(sections, omega[1:], elastic, elastic[0].copy(), half_ix,
                                 nodes)


def uniform_beam_antisymmetric_bending_rad_s(
        semispan_m: float, bending_stiffness_n_m2: float, mass_per_length_kg_m: float,
        fuselage_roll_inertia_kg_m2: float, n_modes: int = 3) -> np.ndarray:
    """The closed form: the antisymmetric bending frequencies [rad/s] of a uniform
    Euler-Bernoulli beam of span 2 L (``semispan_m`` L, EI, m') on a rigid central body
    of roll inertia J (``fuselage_roll_inertia_kg_m2``), no torsion. On the half beam,
    w = a₁ sin βy + a₂ sinh βy + a₃ (cos βy − cosh βy) (w(0) = 0), the free tip
    w''(L) = w'''(L) = 0 and the root's moment balance EI w''(0) = −ω² (J/2) w'(0) (the
    variation of ½∫EI w''² − ½ω²∫m' w² − ½ω² (J/2) w'(0)²), with ω² = β⁴ EI/m': the roots
    of the 3×3 determinant, found on a fine grid in βL and refined by Brent's method."""
    big_l, ei, mp, j = (float(semispan_m), float(bending_stiffness_n_m2),
                        float(mass_per_length_kg_m), float(fuselage_roll_inertia_kg_m2))

    def det(bl: float) -> float:
        b = bl / big_l
        w2 = b**4 * ei / mp
        s, c, sh, ch = math.sin(bl), math.cos(bl), math.sinh(bl), math.cosh(bl)
        # rows scaled by cosh βL at the tip, to keep the determinant of order one
        rows = np.array([
            [0.5 * j * w2 * b, 0.5 * j * w2 * b, -2.0 * ei * b**2],
            [-s / ch, sh / ch, (-c - ch) / ch],
            [-c / ch, 1.0, (s - sh) / ch],
        ])
        rows[0] /= max(abs(rows[0]).max(), 1e-300)
        return float(np.linalg.det(rows))

    grid = np.linspace(0.05, 4.0 * n_modes + 4.0, 4000)
    values = [det(x) for x in grid]
    roots = []
    for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True):
        if fa == 0.0 or fa * fb < 0.0:
            roots.append(brentq(det, a, b, xtol=1e-14))
        if len(roots) == n_modes:
            break
    bl = np.array(roots)
    return (bl / big_l) ** 2 * math.sqrt(ei / mp)
