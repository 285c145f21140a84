"""Clamped-free half-wing beam: finite elements for coupled bending and torsion.

Model (``docs/structures.md``):

* the half wing is a straight beam along y, root (y = 0) clamped, tip (y = b/2) free. The
  outer panel's sweep (:mod:`bioflex_jsb.parameters.wing`) is neglected for the structure:
  the beam runs along the span, not along the swept panel's axis;
* Euler–Bernoulli bending of the elastic axis, w(y) positive DOWN [m], bending stiffness
  EI(y) [N·m²]; St-Venant torsion about the elastic axis, θ(y) positive LEADING EDGE UP
  [rad], torsional stiffness GJ(y) [N·m²]. The elastic axis is the shear centre, so the
  stiffness does not couple w and θ;
* inertia per unit span: mass m'(y) [kg/m] and torsional inertia about the elastic axis
  I_α'(y) [kg·m]; a point at distance d aft of the elastic axis moves down by w + d θ, so the
  kinetic energy per span is ½ (m' ẇ² + 2 S_α' ẇ θ̇ + I_α' θ̇²) with
  S_α' = m' (x_I − x_E) c [kg] (positive when the inertial axis lies aft of the elastic axis);
* elements: 3 dof per node (w, w' = dw/dy, θ); Hermite cubic interpolation of w, linear of θ;
  section properties interpolated linearly between the given stations and integrated with
  4-point Gauss–Legendre quadrature per element (exact for the cubic × cubic × linear
  integrands of the bending mass matrix);
* point masses (:class:`PointMass`: fuel, an engine, a pod, a tip mass) and vertical
  springs (:class:`VerticalSpring`: the strut of a braced wing) at any station y_p: added
  consistently, with the element's own shape functions at y_p (exact at a node, and no
  mesh dependence of where the mass sits). A mass m at d aft of the elastic axis moves down
  by w + d θ and turns with θ, so it adds m (N_w + d N_θ)ᵀ(N_w + d N_θ) + I_cg N_θᵀ N_θ to M
  (I_cg its pitch inertia about its own centre of mass); a spring k adds k N_wᵀ N_w to K.
  Neither adds rotary inertia of bending (the mass's roll inertia about y is left out);
* generalised eigenproblem K φ = ω² M φ solved with :func:`scipy.linalg.eigh` as the inverted
  pencil M φ = μ K φ, μ = 1/ω², for its largest μ (:func:`_lowest_modes`): K's condition
  number is about 2e11 for the prototype's wing, and the direct pencil's lowest ω² came out
  to only ~1e-6 relative, in digits that changed with the BLAS kernels (ω₁ 193.0776982,
  193.0775168 and 193.0775475 rad/s with OpenBLAS's SkylakeX, Haswell and SandyBridge
  kernels; accurate 193.0774781). The lowest modes are the inverted pencil's dominant ones,
  which a backward-stable solver returns to round-off relative to themselves (3e-13 across
  those kernels).

Modes are returned as :class:`~bioflex_jsb.structures.modal_data.ModalData` in the project's
normalisation (max |twist| = 1 rad/rad, tip twist positive), with the generalised masses of
the half wing that belong to that scaling.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg import eigh

from bioflex_jsb.errors import InputError
from bioflex_jsb.structures.modal_data import ModalData
from bioflex_jsb.structures.sections import (
    ChordwiseLayup,
    Ribs,
    elastic_axis_frac,
    inertial_axis_frac,
    mass_per_length_kg_m,
    open_section_torsional_stiffness_n_m2,
    torsional_inertia_kg_m,
)

# Gauss–Legendre points on [0, 1] (4 points: exact to degree 7).
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(4)
_GAUSS_X = 0.5 * (_GAUSS_X + 1.0)
_GAUSS_W = 0.5 * _GAUSS_W

# Default number of elements. ESTIMATE from the convergence study in tests/test_structures.py:
# with 40 linear torsion elements the third torsion frequency of a uniform beam is within
# (5π/2 · 1/40)²/24 ≈ 0.16 % of the exact value; bending (Hermite) converges much faster.
DEFAULT_N_ELEMENTS = 40


class BeamInputError(InputError):
    """Invalid beam section data; the message names the offending field."""


@dataclass(frozen=True)
class PointMass:
    """A concentrated mass on the half wing (fuel, an engine, a pod, a tip mass).

    ``y_m`` [m] its spanwise station (0 < y ≤ b/2); ``mass_kg`` [kg]; ``x_frac`` [-] the
    chordwise position of its centre of mass as a fraction of the local chord aft of the
    leading edge (negative ahead of the leading edge: a wing-mounted engine); its offset aft
    of the elastic axis is (x_frac − x_E(y)) c(y); ``pitch_inertia_kg_m2`` [kg·m²] its own
    moment of inertia about a spanwise axis through its centre of mass; ``name`` for
    reports."""

    y_m: float
    mass_kg: float
    x_frac: float
    pitch_inertia_kg_m2: float = 0.0
    name: str = ""


@dataclass(frozen=True)
class VerticalSpring:
    """A vertical (bending) spring to ground at ``y_m`` [m], ``stiffness_n_m`` [N/m]: the
    strut of a braced wing at its attachment (a strut of axial stiffness EA/L at an angle γ
    to the wing gives k = (EA/L) sin²γ); it acts on the elastic axis's deflection only."""

    y_m: float
    stiffness_n_m: float
    name: str = ""


@dataclass(frozen=True, eq=False)
class BeamSections:
    """Section properties of the half-wing beam at spanwise stations (linear in between).

    Attributes (all arrays (k,), at ``stations_m``):
        stations_m: 0 = root … b/2 = tip, strictly increasing [m].
        bending_stiffness_n_m2: EI(y) [N·m²].
        torsional_stiffness_n_m2: GJ(y) [N·m²].
        mass_per_length_kg_m: m'(y) [kg/m].
        torsional_inertia_kg_m: I_α'(y), mass moment of inertia per span about the elastic
            axis [kg·m]; must be ≥ m' ((x_I − x_E) c)² (parallel-axis theorem).
        chord_m: c(y) [m].
        x_elastic_frac, x_inertial_frac: axes as chord fractions aft of the leading edge [-].
        description: what these sections represent (copied into ModalData.source).
        point_masses: concentrated masses on the beam (:class:`PointMass`).
        springs: vertical springs to ground (:class:`VerticalSpring`: a strut).
    """

    stations_m: np.ndarray
    bending_stiffness_n_m2: np.ndarray
    torsional_stiffness_n_m2: np.ndarray
    mass_per_length_kg_m: np.ndarray
    torsional_inertia_kg_m: np.ndarray
    chord_m: np.ndarray
    x_elastic_frac: np.ndarray
    x_inertial_frac: np.ndarray
    description: str = "beam sections"
    point_masses: tuple[PointMass, ...] = ()
    springs: tuple[VerticalSpring, ...] = ()

    def __post_init__(self) -> None:
        y = np.array(self.stations_m, dtype=float)
        if y.ndim != 1 or y.size < 2 or not np.all(np.isfinite(y)):
            raise BeamInputError("BeamSections.stations_m: need ≥ 2 finite stations")
        if y[0] != 0.0 or np.any(np.diff(y) <= 0.0):
            raise BeamInputError(
                "BeamSections.stations_m: must start at the root (0) and strictly increase"
            )
        y.setflags(write=False)
        object.__setattr__(self, "stations_m", y)
        names = ("bending_stiffness_n_m2", "torsional_stiffness_n_m2", "mass_per_length_kg_m",
                 "torsional_inertia_kg_m", "chord_m", "x_elastic_frac", "x_inertial_frac")
        for name in names:
            arr = np.array(getattr(self, name), dtype=float)
            if arr.ndim == 0:
                arr = np.full(y.size, float(arr))
            if arr.shape != y.shape:
                raise BeamInputError(
                    f"BeamSections.{name}: length {arr.shape} does not match stations {y.shape}"
                )
            if not np.all(np.isfinite(arr)):
                raise BeamInputError(f"BeamSections.{name}: non-finite value")
            if name not in ("x_elastic_frac", "x_inertial_frac") and np.any(arr <= 0.0):
                raise BeamInputError(f"BeamSections.{name}: must be positive everywhere")
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        d = self.inertial_offset_m
        if np.any(self.torsional_inertia_kg_m < self.mass_per_length_kg_m * d**2 * (1.0 - 1e-12)):
            raise BeamInputError(
                "BeamSections.torsional_inertia_kg_m: smaller than m'·((x_I − x_E)c)², "
                "impossible for inertia about the elastic axis (mass matrix not positive)"
            )
        object.__setattr__(self, "point_masses", tuple(self.point_masses))
        object.__setattr__(self, "springs", tuple(self.springs))
        semispan = float(y[-1])
        for i, p in enumerate(self.point_masses):
            values = (p.y_m, p.mass_kg, p.x_frac, p.pitch_inertia_kg_m2)
            if not all(np.isfinite(v) for v in values):
                raise BeamInputError(f"BeamSections.point_masses[{i}]: non-finite value")
            if not 0.0 < p.y_m <= semispan:
                raise BeamInputError(f"BeamSections.point_masses[{i}].y_m: {p.y_m:g} m is "
                                     f"outside the beam (0, {semispan:g}] m (a mass at the "
                                     "clamped root does not move)")
            if not p.mass_kg > 0.0 or p.pitch_inertia_kg_m2 < 0.0:
                raise BeamInputError(f"BeamSections.point_masses[{i}]: mass_kg must be "
                                     "positive and pitch_inertia_kg_m2 not negative")
        for i, k in enumerate(self.springs):
            if not (np.isfinite(k.y_m) and 0.0 < k.y_m <= semispan):
                raise BeamInputError(f"BeamSections.springs[{i}].y_m: {k.y_m:g} m is outside "
                                     f"the beam (0, {semispan:g}] m")
            if not (np.isfinite(k.stiffness_n_m) and k.stiffness_n_m > 0.0):
                raise BeamInputError(f"BeamSections.springs[{i}].stiffness_n_m: must be "
                                     "positive")

    @property
    def semispan_m(self) -> float:
        """Beam length b/2 [m]."""
        return float(self.stations_m[-1])

    @property
    def inertial_offset_m(self) -> np.ndarray:
        """(x_I − x_E)·c [m], positive when the inertial axis is aft of the elastic axis."""
        return (self.x_inertial_frac - self.x_elastic_frac) * self.chord_m

    @property
    def static_moment_kg(self) -> np.ndarray:
        """S_α' = m' (x_I − x_E) c [kg·m/m], the bending–torsion inertial coupling."""
        return self.mass_per_length_kg_m * self.inertial_offset_m

    @property
    def half_wing_mass_kg(self) -> float:
        """∫ m' dy over the half wing [kg] (trapezoid rule: exact for linear m'), plus the
        point masses."""
        return (float(np.trapezoid(self.mass_per_length_kg_m, self.stations_m))
                + sum(p.mass_kg for p in self.point_masses))

    def point_mass_offset_m(self, mass: PointMass) -> float:
        """(x_p − x_E(y_p)) c(y_p) [m]: the point mass's centre of mass aft of the elastic
        axis (the chord and the axis interpolated at its station)."""
        at = np.array([mass.y_m])
        chord = float(np.interp(at, self.stations_m, self.chord_m)[0])
        x_e = float(np.interp(at, self.stations_m, self.x_elastic_frac)[0])
        return (mass.x_frac - x_e) * chord

    def at(self, y_m: np.ndarray) -> dict[str, np.ndarray]:
        """Linearly interpolated properties at ``y_m`` (EI, GJ, m', I_α', S_α')."""
        y = np.asarray(y_m, dtype=float)

        def f(v):
            return np.interp(y, self.stations_m, v)

        return {
            "EI": f(self.bending_stiffness_n_m2),
            "GJ": f(self.torsional_stiffness_n_m2),
            "m": f(self.mass_per_length_kg_m),
            "I": f(self.torsional_inertia_kg_m),
            "S": f(self.static_moment_kg),
        }


def uniform_sections(
    semispan_m: float,
    *,
    bending_stiffness_n_m2: float,
    torsional_stiffness_n_m2: float,
    mass_per_length_kg_m: float,
    torsional_inertia_kg_m: float,
    chord_m: float,
    x_elastic_frac: float = 0.5,
    x_inertial_frac: float = 0.5,
    description: str = "uniform beam",
) -> BeamSections:
    """Spanwise-uniform sections (root and tip stations only)."""
    return BeamSections(
        stations_m=np.array([0.0, semispan_m]),
        bending_stiffness_n_m2=bending_stiffness_n_m2,
        torsional_stiffness_n_m2=torsional_stiffness_n_m2,
        mass_per_length_kg_m=mass_per_length_kg_m,
        torsional_inertia_kg_m=torsional_inertia_kg_m,
        chord_m=chord_m,
        x_elastic_frac=x_elastic_frac,
        x_inertial_frac=x_inertial_frac,
        description=description,
    )


# ------------------------------------------------------------------------------------------
# Element shape functions on ξ ∈ [0, 1], element length h. Element dofs: (w1, w1', θ1, w2,
# w2', θ2).
# ------------------------------------------------------------------------------------------
def hermite_shapes(xi: np.ndarray, h: float) -> np.ndarray:
    """(len(xi), 4) Hermite cubic shape functions for (w1, w1', w2, w2')."""
    xi = np.asarray(xi, dtype=float)
    return np.stack(
        [1 - 3 * xi**2 + 2 * xi**3, h * (xi - 2 * xi**2 + xi**3), 3 * xi**2 - 2 * xi**3,
         h * (-(xi**2) + xi**3)],
        axis=-1,
    )


def _hermite_dd(xi: np.ndarray, h: float) -> np.ndarray:
    """(len(xi), 4) second derivatives d²N/dy² of the Hermite functions [1/m², 1/m, …]."""
    xi = np.asarray(xi, dtype=float)
    return np.stack(
        [(-6 + 12 * xi) / h**2, (-4 + 6 * xi) / h, (6 - 12 * xi) / h**2, (-2 + 6 * xi) / h],
        axis=-1,
    )


_W_DOFS = np.array([0, 1, 3, 4])  # positions of (w1, w1', w2, w2') in the element vector
_T_DOFS = np.array([2, 5])  # positions of (θ1, θ2)


def _element_matrices(y0: float, h: float, sections: BeamSections):
    """6×6 stiffness and mass matrices of the element [y0, y0 + h]."""
    props = sections.at(y0 + _GAUSS_X * h)
    nw = hermite_shapes(_GAUSS_X, h)  # (4 points, 4)
    nwdd = _hermite_dd(_GAUSS_X, h)
    nt = np.stack([1 - _GAUSS_X, _GAUSS_X], axis=-1)  # (4, 2)
    ntd = np.array([-1.0 / h, 1.0 / h])
    wq = _GAUSS_W * h
    k = np.zeros((6, 6))
    m = np.zeros((6, 6))
    k[np.ix_(_W_DOFS, _W_DOFS)] = np.einsum("g,gi,gj->ij", wq * props["EI"], nwdd, nwdd)
    k[np.ix_(_T_DOFS, _T_DOFS)] = np.sum(wq * props["GJ"]) * np.outer(ntd, ntd)
    m[np.ix_(_W_DOFS, _W_DOFS)] = np.einsum("g,gi,gj->ij", wq * props["m"], nw, nw)
    m[np.ix_(_T_DOFS, _T_DOFS)] = np.einsum("g,gi,gj->ij", wq * props["I"], nt, nt)
    coupling = np.einsum("g,gi,gj->ij", wq * props["S"], nw, nt)
    m[np.ix_(_W_DOFS, _T_DOFS)] = coupling
    m[np.ix_(_T_DOFS, _W_DOFS)] = coupling.T
    return k, m


def assemble(sections: BeamSections, n_elements: int = DEFAULT_N_ELEMENTS):
    """Global stiffness K and mass M of the clamped beam (root dofs removed) and node y [m].

    Free dofs are ordered node by node, (w, w', θ) for nodes 1 … n_elements.
    """
    k_glob, m_glob, nodes = assemble_unrestrained(sections, n_elements)
    return k_glob[3:, 3:], m_glob[3:, 3:], nodes


def assemble_unrestrained(sections: BeamSections, n_elements: int = DEFAULT_N_ELEMENTS):
    """K and M of the beam with its root dofs kept (node by node, (w, w', θ) for nodes
    0 … n_elements) and the node y [m]: what :func:`assemble` clamps, and what another root
    condition (the antisymmetric modes' roll freedom, structures/antisymmetric.py)
    restrains otherwise."""
    if n_elements < 1:
        raise BeamInputError(f"n_elements: need at least 1, got {n_elements}")
    nodes = np.linspace(0.0, sections.semispan_m, n_elements + 1)
    ndof = 3 * (n_elements + 1)
    k_glob = np.zeros((ndof, ndof))
    m_glob = np.zeros((ndof, ndof))
    for e in range(n_elements):
        h = nodes[e + 1] - nodes[e]
        ke, me = _element_matrices(nodes[e], h, sections)
        idx = np.arange(3 * e, 3 * e + 6)
        k_glob[np.ix_(idx, idx)] += ke
        m_glob[np.ix_(idx, idx)] += me
    for p in sections.point_masses:
        idx, n_w, n_t = _point_shape(nodes, p.y_m)
        n_p = n_w + sections.point_mass_offset_m(p) * n_t  # the mass's vertical motion
        m_glob[np.ix_(idx, idx)] += (p.mass_kg * np.outer(n_p, n_p)
                                     + p.pitch_inertia_kg_m2 * np.outer(n_t, n_t))
    for spring in sections.springs:
        idx, n_w, _ = _point_shape(nodes, spring.y_m)
        k_glob[np.ix_(idx, idx)] += spring.stiffness_n_m * np.outer(n_w, n_w)
    return k_glob, m_glob, nodes


def _point_shape(nodes: np.ndarray, y_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The element dofs at station ``y_m`` [m] and the rows N_w (deflection w, down) and
    N_θ (twist) that interpolate w(y_m) and θ(y_m) from them (the element's own Hermite
    and linear shape functions)."""
    e = int(np.clip(np.searchsorted(nodes, y_m, side="right") - 1, 0, nodes.size - 2))
    h = float(nodes[e + 1] - nodes[e])
    xi = (float(y_m) - float(nodes[e])) / h
    n_w = np.zeros(6)
    n_t = np.zeros(6)
    n_w[_W_DOFS] = hermite_shapes(np.array([xi]), h)[0]
    n_t[_T_DOFS] = (1.0 - xi, xi)
    return np.arange(3 * e, 3 * e + 6), n_w, n_t


@dataclass(frozen=True, eq=False)
class BeamSolution:
    """Eigen-solution of the beam.

    frequencies_rad_s (n,); vectors (3·n_elements, n): M-orthonormal eigenvectors over the
    free dofs (φᵀ M φ = 1); nodes_m (n_elements + 1,); torsion_energy_fraction (n,): share of
    each mode's strain energy stored in torsion (1 = pure twist, 0 = pure bending).
    """

    sections: BeamSections
    frequencies_rad_s: np.ndarray
    vectors: np.ndarray
    nodes_m: np.ndarray
    torsion_energy_fraction: np.ndarray

    def _full(self, i: int) -> np.ndarray:
        """(n_nodes, 3) nodal (w, w', θ) of mode i, root row zero."""
        return np.vstack([np.zeros(3), self.vectors[:, i].reshape(-1, 3)])

    def sample(self, stations_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Raw (bending [m], twist [rad]) of all modes at ``stations_m``, each (n, k)."""
        return sample_nodal_modes(self.nodes_m, [self._full(i) for i in
                                                 range(self.frequencies_rad_s.size)],
                                  stations_m)


def _lowest_modes(k: np.ndarray, m: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The ``n`` lowest eigenvalues ω² [rad²/s²] (ascending) of K φ = ω² M φ and their
    eigenvectors with unit generalised mass (φᵀ M φ = 1), from the inverted pencil
    M φ = μ K φ (module docstring). A stiffness matrix that is not positive definite (a
    section with no bending or torsional stiffness: a mechanism) is refused."""
    size = k.shape[0]
    try:
        mu, vec = eigh(m, k, subset_by_index=[size - n, size - 1])
    except np.linalg.LinAlgError:
        raise BeamInputError("the stiffness matrix is not positive definite: every section "
                             "needs EI > 0 and GJ > 0 (a clamped beam without either is a "
                             "mechanism)") from None
    mu, vec = mu[::-1], vec[:, ::-1]
    vec = vec / np.sqrt(np.einsum("ij,ik,kj->j", vec, m, vec))
    return 1.0 / mu, vec


def solve_beam(
    sections: BeamSections, n_modes: int = 3, n_elements: int = DEFAULT_N_ELEMENTS
) -> BeamSolution:
    """Lowest ``n_modes`` natural frequencies and modes of the clamped-free beam."""
    k_glob, m_glob, nodes = assemble(sections, n_elements)
    if not 1 <= n_modes <= k_glob.shape[0]:
        raise BeamInputError(f"n_modes: need 1..{k_glob.shape[0]}, got {n_modes}")
    t_mask = np.zeros(k_glob.shape[0], dtype=bool)
    t_mask[2::3] = True
    if np.any(m_glob[np.ix_(~t_mask, t_mask)] != 0.0):
        lam, vec = _lowest_modes(k_glob, m_glob, n_modes)
    else:
        # x_I = x_E everywhere: bending and torsion are exactly uncoupled. Solving the two
        # blocks separately keeps the uncoupled modes exactly pure (a joint solve leaks
        # round-off of relative size ~1e-9 between the blocks).
        lam_parts, vec_parts = [], []
        for mask in (~t_mask, t_mask):
            kb, mb = k_glob[np.ix_(mask, mask)], m_glob[np.ix_(mask, mask)]
            nb = min(n_modes, kb.shape[0])
            lb, vb = _lowest_modes(kb, mb, nb)
            full = np.zeros((k_glob.shape[0], nb))
            full[mask] = vb
            lam_parts.append(lb)
            vec_parts.append(full)
        lam = np.concatenate(lam_parts)
        order = np.argsort(lam, kind="stable")[:n_modes]
        lam, vec = lam[order], np.hstack(vec_parts)[:, order]
    omega = np.sqrt(np.maximum(lam, 0.0))
    # Strain energy split: K has no w–θ coupling, so U = U_bending + U_torsion exactly.
    u_t = np.einsum("ij,ik,kj->j", vec[t_mask], k_glob[np.ix_(t_mask, t_mask)], vec[t_mask])
    u_all = np.einsum("ij,ik,kj->j", vec, k_glob, vec)
    return BeamSolution(
        sections=sections,
        frequencies_rad_s=omega,
        vectors=vec,
        nodes_m=nodes,
        torsion_energy_fraction=u_t / u_all,
    )


def beam_modes(
    sections: BeamSections,
    n_modes: int = 3,
    *,
    n_elements: int = DEFAULT_N_ELEMENTS,
    stations_m: np.ndarray | None = None,
    damping_ratio: float = 0.0,
    notes: str = "",
) -> ModalData:
    """The first ``n_modes`` modes as normalised :class:`ModalData`.

    ``stations_m`` defaults to the finite-element nodes. ``damping_ratio`` is given to every
    mode (default 0: Section 3.1 neglects structural damping). The raw eigenvectors have unit
    generalised mass; :meth:`ModalData.normalised` rescales shapes and masses together.
    """
    sol = solve_beam(sections, n_modes, n_elements)
    y = sol.nodes_m if stations_m is None else np.asarray(stations_m, dtype=float)
    bend, twist = sol.sample(y)
    xe = np.interp(y, sections.stations_m, sections.x_elastic_frac)
    xi = np.interp(y, sections.stations_m, sections.x_inertial_frac)
    text = (
        f"beam FE, {n_elements} elements; torsion strain-energy fraction per mode: "
        + ", ".join(f"{f:.3f}" for f in sol.torsion_energy_fraction)
    )
    raw = ModalData(
        frequencies_rad_s=sol.frequencies_rad_s,
        damping_ratios=np.full(n_modes, float(damping_ratio)),
        generalised_masses_kg_m2=np.ones(n_modes),
        stations_m=y,
        bending_m=bend,
        twist_rad=twist,
        x_elastic_frac=xe,
        x_inertial_frac=xi,
        source=sections.description,
        notes=(text + ("; " + notes if notes else "")),
    )
    free = raw.twist_free()
    if np.any(free):
        idx = ", ".join(str(i + 1) for i in np.flatnonzero(free))
        extra = f"; twist-free mode(s) {idx} scaled on tip deflection/semispan"
        raw = replace(raw, notes=raw.notes + extra)
    return raw.normalised()


# ------------------------------------------------------------------------------------------
# Sections from physical wing data
# ------------------------------------------------------------------------------------------
# Width of the step in m' and I_α' at the arm/hand boundary: the hand's sections start this far
# outboard of the kink station (BeamSections needs strictly increasing stations). DEFINITION:
# 1e-6 of the semispan (0.85 µm) is far inside any element (a 40-element mesh has its first
# Gauss point 1.5 mm from a node), so the step is sharp for the quadrature.
HAND_STEP_WIDTH_FRAC = 1e-6


def wing_from_membrane(
    *,
    semispan_m: float,
    chord_m: float,
    layup: ChordwiseLayup,
    ribs: Ribs | None,
    torsional_stiffness_root_n_m2: float,
    torsional_stiffness_tip_ratio: float | None,
    bending_stiffness_n_m2: float,
    x_inertial_frac: float | None = None,
    x_elastic_frac: float | None = None,
    n_stations: int = 41,
    description: str = "membrane wing",
    hand_start_m: float | None = None,
    torsional_stiffness_kink_ratio: float | None = None,
    hand_inertia_ratio: float = 1.0,
) -> BeamSections:
    """Beam sections of a constant-chord membrane wing.

    Mass and inertia come from the layup (Table A1 materials) and the ribs; the axes from
    Eq. (11) (x_I, mass centroid, ribs included) and Eq. (12) (x_E, centroid of E·th).

    Stiffness: the membrane's spanwise bending and torsional stiffness depend on the camber,
    the leading-edge region and the ribs' restraint of aerofoil distortion, which the paper
    does not give; they are effective values: a uniform EI [N·m²] and a GJ [N·m²] that is
    ``torsional_stiffness_root_n_m2`` at the root and ``torsional_stiffness_tip_ratio`` × that
    at the tip (``None``: the tip keeps exactly the bare membrane's open-section stiffness
    G c th³/3, :func:`open_section_torsional_stiffness_n_m2`, the physical floor). See
    :mod:`bioflex_jsb.parameters.wing_structure` for the calibration.

    * ``hand_start_m is None``: GJ tapers linearly from root to tip, uniform mass.
    * Arm/hand wing (``hand_start_m`` = the planform kink, 0 < y_k < b/2): GJ is piecewise
      linear, root → ``torsional_stiffness_kink_ratio`` × root at y_k → tip value; the hand
      (y > y_k) carries ``hand_inertia_ratio`` (h) × the arm's mass per span AND torsional
      inertia. The hand's mass is reduced uniformly over its chord, so its mass centre, x_I,
      is unchanged (Section 4.1: the feathered hand is light). This also reduces the wing mass.

    Axis overrides (the sensitivity study of Section 4): ``x_inertial_frac`` /
    ``x_elastic_frac`` replace the Eq. (11)/(12) values over the whole span (arm and hand).
    Moving an axis models a redistribution (ballast, a different layup) that keeps the section
    mass and its centroidal inertia; the inertia about the (possibly moved) elastic axis follows
    from the parallel-axis theorem: I_α' = I_cg' + m' ((x_I − x_E) c)² (arm and hand alike, so
    the hand's I_α' and S_α' are h × the arm's for any override).
    """
    if n_stations < 2:
        raise BeamInputError(f"n_stations: need ≥ 2, got {n_stations}")
    if not hand_inertia_ratio > 0.0:
        raise BeamInputError(f"hand_inertia_ratio: must be positive, got {hand_inertia_ratio}")
    if hand_start_m is None:
        if torsional_stiffness_kink_ratio is not None or hand_inertia_ratio != 1.0:
            raise BeamInputError(
                "hand_start_m: needed with torsional_stiffness_kink_ratio or hand_inertia_ratio"
            )
    else:
        if not 0.0 < hand_start_m < semispan_m:
            raise BeamInputError(f"hand_start_m: must lie inside (0, {semispan_m}) m")
        if torsional_stiffness_kink_ratio is None or not torsional_stiffness_kink_ratio > 0.0:
            raise BeamInputError("torsional_stiffness_kink_ratio: a positive value is needed "
                                 "with hand_start_m")
    xi_layup = inertial_axis_frac(layup, ribs)
    xe_layup = elastic_axis_frac(layup)
    x_i = xi_layup if x_inertial_frac is None else float(x_inertial_frac)
    x_e = xe_layup if x_elastic_frac is None else float(x_elastic_frac)
    mass = mass_per_length_kg_m(layup, chord_m, ribs)
    i_cg = torsional_inertia_kg_m(layup, chord_m, xi_layup, ribs)
    i_ea = i_cg + mass * ((x_i - x_e) * chord_m) ** 2
    gj_root = float(torsional_stiffness_root_n_m2)
    if torsional_stiffness_tip_ratio is None:
        gj_tip = open_section_torsional_stiffness_n_m2(layup, chord_m)
    else:
        gj_tip = gj_root * float(torsional_stiffness_tip_ratio)
    y = np.linspace(0.0, semispan_m, n_stations)
    if hand_start_m is None:
        gj = gj_root + (gj_tip - gj_root) * y / semispan_m
        scale = np.ones_like(y)
        shape = "linear GJ taper"
    else:
        yk = float(hand_start_m)
        step = HAND_STEP_WIDTH_FRAC * semispan_m
        keep = np.abs(y - yk) > 10.0 * step  # a grid station at the kink is replaced by it
        y = np.concatenate([y[keep], [yk, yk + step]])
        y.sort()
        gj_kink = gj_root * float(torsional_stiffness_kink_ratio)
        gj = np.interp(y, [0.0, yk, semispan_m], [gj_root, gj_kink, gj_tip])
        scale = np.where(y > yk, float(hand_inertia_ratio), 1.0)
        shape = (f"arm/hand: GJ kink at y = {yk:.4f} m ({torsional_stiffness_kink_ratio:.4g} x "
                 f"root), hand inertia x {hand_inertia_ratio:.4g}")
    n = y.size
    return BeamSections(
        stations_m=y,
        bending_stiffness_n_m2=np.full(n, bending_stiffness_n_m2),
        torsional_stiffness_n_m2=gj,
        mass_per_length_kg_m=mass * scale,
        torsional_inertia_kg_m=i_ea * scale,
        chord_m=np.full(n, chord_m),
        x_elastic_frac=np.full(n, x_e),
        x_inertial_frac=np.full(n, x_i),
        description=f"{description}; x_I = {x_i:.3f} c, x_E = {x_e:.3f} c; {shape}",
    )


def sample_nodal_modes(nodes_m: np.ndarray, modes: list[np.ndarray], stations_m
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(bending [m], twist [rad]) of each mode at ``stations_m`` [m], each (n, k), from its
    nodal (w, w', θ) rows (``modes[i]``: (len(nodes_m), 3)) as the elements interpolate
    them: Hermite cubics for the bending, linear for the twist."""
    y = np.asarray(stations_m, dtype=float)
    nodes = nodes_m
    e = np.clip(np.searchsorted(nodes, y, side="right") - 1, 0, nodes.size - 2)
    h = nodes[e + 1] - nodes[e]
    xi = (y - nodes[e]) / h
    bend = np.empty((len(modes), y.size))
    twist = np.empty((len(modes), y.size))
    for i, q in enumerate(modes):
        for j in range(y.size):
            nw = hermite_shapes(np.array([xi[j]]), h[j])[0]
            a, b = q[e[j]], q[e[j] + 1]
            bend[i, j] = nw @ np.array([a[0], a[1], b[0], b[1]])
            twist[i, j] = (1.0 - xi[j]) * a[2] + xi[j] * b[2]
    return bend, twist
