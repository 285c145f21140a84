"""The antisymmetric loading of the wing by strips or by the vortex lattice: what the lateral
elastic models (docs/lateral.md, "The lattice in the lateral elastic model") load their
strips with.

An antisymmetric angle-of-attack distribution α(y) [rad] (α(−y) = −α(y): a roll rate's
p y/V, an antisymmetric mode's twist θ_i η_i or plunge rate φ_i η̇_i/V, the ailerons' τ χ δ)
given at the lattice's starboard strips k gives the lift per unit span per unit dynamic
pressure at the same strips, l'_k/q [m]:

* ``strips``: each strip alone, l'_k/q = (C_lα c)_k α_k, with C_lα c the lattice's loading
  of a *uniform* symmetric α (the symmetric wing's induced flow; a strip-theory
  approximation for an antisymmetric one): the matrix diag(C_lα c);
* ``lattice``: the lattice's antisymmetric influence matrix
  (:attr:`~bioflex_jsb.aerodynamics.vortex_lattice.SpanwiseAerodynamics.influence_antisymmetric_m`,
  the port half the mirror image with the opposite sign), l'/q = A α: every strip's lift
  feels the whole distribution's trailing vorticity, and a load spills past the ends of a
  part-span distribution (an aileron's lift reaches the strips beside it).

The matrix replaces the strips' lift slopes in every antisymmetric term (the lift's rolling
moment, its virtual work on the modes, the aileron's lift); where it acts (the lift's point,
e ahead of the elastic axis, and the flap's own section moment) stays the strips'. α is the
angle in each strip's own plane (the lattice's), which for a strip with dihedral Γ differs
from the strips' body-frame α by cos Γ: left out (the planforms flown are flat or within a
few degrees, cos 3° = 0.9986).
"""

from __future__ import annotations

import numpy as np

LATERAL_AERO = ("strips", "lattice")
"""The antisymmetric loadings accepted (module docstring); ``strips`` the default."""


def antisymmetric_lift_matrix(aero, lateral_aero: str) -> np.ndarray | None:
    """(k, k) l'/q per rad of antisymmetric α at ``aero``'s strips [m/rad] for
    ``lateral_aero`` ``lattice`` (its antisymmetric influence matrix); None for ``strips``
    (the strips' diagonal C_lα c: the callers keep their strip arithmetic). ``aero`` a
    :class:`~bioflex_jsb.aerodynamics.vortex_lattice.SpanwiseAerodynamics`."""
    if lateral_aero not in LATERAL_AERO:
        raise ValueError(f"unknown lateral aerodynamics {lateral_aero!r}; accepted: "
                         f"{', '.join(LATERAL_AERO)}")
    if lateral_aero == "strips":
        return None
    return np.asarray(aero.influence_antisymmetric_m, dtype=float).copy()


def lift_per_alpha(strip_lift_m: np.ndarray, matrix_m: np.ndarray | None,
                   alpha_rad: np.ndarray) -> np.ndarray:
    """l'/q [m] at the strips of the antisymmetric ``alpha_rad`` (…, k) [rad] (rows: one
    distribution each): ``strip_lift_m`` (k,) C_lα c [m/rad] times α when ``matrix_m`` is
    None (strips), else ``matrix_m`` @ α for each row (the lattice)."""
    alpha = np.asarray(alpha_rad, dtype=float)
    if matrix_m is None:
        return alpha * strip_lift_m
    return alpha @ np.asarray(matrix_m, dtype=float).T

