"""Chordwise section properties of the membrane wing: Eq. (11)–(12) and the beam inputs.

A section of the membrane wing (Appendix A, Fig. A1) is a thin sheet made of layers of
carbon-fibre composite and Kevlar, each covering part of the chord, plus (optionally) stiff
chordwise ribs. Positions along the chord are fractions s = x/c of the local chord measured
aft from the leading edge (``docs/conventions.md``).

* Eq. (11), inertial axis x_I: ∫ (x − x_I) m_c(x) th(x) dx = 0, i.e. x_I is the centroid of
  the areal mass ρ(x)·th(x) [kg/m²]. The smeared mass of the ribs belongs to the section mass.
* Eq. (12), elastic axis x_E: ∫ (x − x_E) E(x) th(x) Δθ_t dx = 0, i.e. x_E is the centroid
  of the membrane's spanwise stiffness E(x)·th(x) [N/m] (Δθ_t, a constant small twist,
  cancels). Chordwise ribs carry no spanwise stress (Section 3.1: "hardly any elastic force
  along the spanwise direction"), so they do not enter Eq. (12).

Layers are piecewise constant along the chord, so the integrals are evaluated exactly.
:func:`eq11_residual` and :func:`eq12_residual` evaluate the integrals of Eq. (11)–(12) by
quadrature on any chordwise grid, for checking an axis position independently.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Material:
    """An isotropic sheet material.

    density_kg_m3 [kg/m³], youngs_modulus_pa [Pa], poisson_ratio [-].
    """

    name: str
    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float

    @property
    def shear_modulus_pa(self) -> float:
        """Isotropic shear modulus G = E / (2 (1 + ν)) [Pa]."""
        return self.youngs_modulus_pa / (2.0 * (1.0 + self.poisson_ratio))


@dataclass(frozen=True)
class Layer:
    """One layer of the membrane: ``material`` of ``thickness_m`` [m] over the chord fraction
    ``start_frac`` … ``end_frac`` (0 = leading edge, 1 = trailing edge)."""

    material: Material
    thickness_m: float
    start_frac: float = 0.0
    end_frac: float = 1.0

    def __post_init__(self) -> None:
        if not (0.0 <= self.start_frac < self.end_frac <= 1.0):
            raise ValueError(
                f"Layer.start_frac/end_frac: need 0 ≤ start < end ≤ 1, got "
                f"{self.start_frac}..{self.end_frac}"
            )
        if not self.thickness_m > 0.0:
            raise ValueError(f"Layer.thickness_m: must be positive, got {self.thickness_m}")


@dataclass(frozen=True)
class Ribs:
    """Stiff chordwise ribs (Fig. 2(b), the "rachis" of Fig. 9), smeared along the span.

    material; cross_section_m2: rib cross-section area [m²]; pitch_m: spanwise spacing [m].
    A rib spans the whole chord with a uniform cross-section, so its mass is spread
    uniformly over the chord: areal mass ρ A / pitch [kg/m²].
    """

    material: Material
    cross_section_m2: float
    pitch_m: float

    @property
    def areal_mass_kg_m2(self) -> float:
        """Rib mass smeared over the wing area [kg/m²]."""
        return self.material.density_kg_m3 * self.cross_section_m2 / self.pitch_m


@dataclass(frozen=True)
class ChordwiseLayup:
    """The membrane of one section: a set of (possibly overlapping, stacked) layers."""

    layers: tuple[Layer, ...]

    def breakpoints(self) -> np.ndarray:
        """Chord fractions where the layup changes, 0 … 1."""
        pts = {0.0, 1.0}
        for layer in self.layers:
            pts.update((layer.start_frac, layer.end_frac))
        return np.array(sorted(pts))

    def _sum(self, s: np.ndarray, value) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        out = np.zeros_like(s)
        for layer in self.layers:
            inside = (s >= layer.start_frac) & (s <= layer.end_frac)
            out = out + np.where(inside, value(layer), 0.0)
        return out

    def thickness_m(self, s: np.ndarray) -> np.ndarray:
        """Total thickness th(s) [m] at chord fractions ``s``."""
        return self._sum(s, lambda la: la.thickness_m)

    def areal_mass_kg_m2(self, s: np.ndarray) -> np.ndarray:
        """Σ ρ_i t_i [kg/m²] at chord fractions ``s`` (the m_c·th of Eq. 11)."""
        return self._sum(s, lambda la: la.material.density_kg_m3 * la.thickness_m)

    def membrane_stiffness_n_m(self, s: np.ndarray) -> np.ndarray:
        """Σ E_i t_i [N/m] at chord fractions ``s`` (the E·th of Eq. 12)."""
        return self._sum(s, lambda la: la.material.youngs_modulus_pa * la.thickness_m)

    def segments(self):
        """Yield (s0, s1, areal mass [kg/m²], E·t [N/m], G·t [N/m], t [m]) per constant piece."""
        pts = self.breakpoints()
        for s0, s1 in zip(pts[:-1], pts[1:], strict=True):
            mid = np.array([0.5 * (s0 + s1)])
            yield (
                float(s0),
                float(s1),
                float(self.areal_mass_kg_m2(mid)[0]),
                float(self.membrane_stiffness_n_m(mid)[0]),
                float(self._sum(mid, lambda la: la.material.shear_modulus_pa * la.thickness_m)[0]),
                float(self.thickness_m(mid)[0]),
            )


def _moments(pieces) -> tuple[float, float, float]:
    """Zeroth, first and second moments ∫ w ds, ∫ w s ds, ∫ w s² ds of piecewise-constant w."""
    m0 = m1 = m2 = 0.0
    for s0, s1, w in pieces:
        m0 += w * (s1 - s0)
        m1 += w * (s1**2 - s0**2) / 2.0
        m2 += w * (s1**3 - s0**3) / 3.0
    return m0, m1, m2


def _mass_pieces(layup: ChordwiseLayup, ribs: Ribs | None):
    rib = ribs.areal_mass_kg_m2 if ribs is not None else 0.0
    return [(s0, s1, mass + rib) for s0, s1, mass, _, _, _ in layup.segments()]


def inertial_axis_frac(layup: ChordwiseLayup, ribs: Ribs | None = None) -> float:
    """x_I / c from Eq. (11): the centroid of the section's areal mass (membrane + ribs) [-]."""
    m0, m1, _ = _moments(_mass_pieces(layup, ribs))
    return m1 / m0


def elastic_axis_frac(layup: ChordwiseLayup) -> float:
    """x_E / c from Eq. (12): the centroid of the membrane's spanwise stiffness E·th [-]."""
    m0, m1, _ = _moments([(s0, s1, et) for s0, s1, _, et, _, _ in layup.segments()])
    return m1 / m0


def eq11_residual(
    x_frac: np.ndarray, areal_mass_kg_m2: np.ndarray, x_inertial_frac: float
) -> float:
    """∫ (s − x_I) m_c th ds / ∫ m_c th ds on a chordwise grid (trapezoid rule) [-].

    Zero when ``x_inertial_frac`` satisfies Eq. (11); normalised so it is a chord fraction.
    """
    s = np.asarray(x_frac, dtype=float)
    w = np.asarray(areal_mass_kg_m2, dtype=float)
    return float(np.trapezoid((s - x_inertial_frac) * w, s) / np.trapezoid(w, s))


def eq12_residual(
    x_frac: np.ndarray, modulus_thickness_n_m: np.ndarray, x_elastic_frac: float
) -> float:
    """∫ (s − x_E) E th Δθ ds / ∫ E th Δθ ds on a chordwise grid (trapezoid rule) [-]."""
    s = np.asarray(x_frac, dtype=float)
    w = np.asarray(modulus_thickness_n_m, dtype=float)
    return float(np.trapezoid((s - x_elastic_frac) * w, s) / np.trapezoid(w, s))


def mass_per_length_kg_m(layup: ChordwiseLayup, chord_m: float, ribs: Ribs | None = None) -> float:
    """Section mass per unit span m' = c ∫ (ρ th + rib) ds [kg/m]."""
    m0, _, _ = _moments(_mass_pieces(layup, ribs))
    return chord_m * m0


def torsional_inertia_kg_m(
    layup: ChordwiseLayup, chord_m: float, about_frac: float, ribs: Ribs | None = None
) -> float:
    """Mass moment of inertia per unit span about the axis at ``about_frac`` [kg·m].

    I = c³ ∫ (ρ th + rib)(s − s_a)² ds (thin sheet: the through-thickness part is neglected,
    it is of relative order (th/c)² ≈ 1e-6).
    """
    m0, m1, m2 = _moments(_mass_pieces(layup, ribs))
    a = about_frac
    return chord_m**3 * (m2 - 2.0 * a * m1 + a * a * m0)


def open_section_torsional_stiffness_n_m2(layup: ChordwiseLayup, chord_m: float) -> float:
    """St-Venant stiffness of the membrane alone as a thin open section, G J = c ∫ G th³/3 ds.

    With stacked layers the thickness-weighted shear modulus is used. This is the floor of the
    wing's torsional stiffness: any real section (ribs, leading-edge cell, camber) is stiffer.
    [N·m²]
    """
    total = 0.0
    for s0, s1, _, _, gt, t in layup.segments():
        if t > 0.0:
            total += (gt / t) * t**3 / 3.0 * (s1 - s0)
    return chord_m * total
