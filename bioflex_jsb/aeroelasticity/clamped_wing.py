"""A clamped cantilever wing as a modal structural model with aerodynamic strips.

The structure is :mod:`bioflex_jsb.structures.beam` (Euler-Bernoulli bending and St-Venant
torsion about the elastic axis, Hermite/linear finite elements): its sign conventions are
those of Theodorsen's typical section (:mod:`bioflex_jsb.aerodynamics.theodorsen`), so no
sign changes are needed:

* bending w [m] of the elastic axis positive **down** = Theodorsen's heave h;
* twist θ [rad] positive **leading edge up** = Theodorsen's pitch α;
* S_α' = m'(x_I − x_E)c [kg] positive when the centre of mass is aft of the elastic axis,
  the coupling of a point d aft of the axis moving down by w + dθ: Theodorsen's S_α = m x_α b.

The modal model keeps the beam's M-orthonormal eigenvectors (generalised masses 1 kg·m² in
the units of the raw vectors) sampled at the strips' stations: heave and twist per unit
modal coordinate. Strips: spanwise stations y_k [m] with integration weights [m] and a
circulatory lift slope a₀(y_k) [1/rad] each; ``lift_slope="strip"`` gives every strip the
thin-aerofoil 2π on Gauss-Legendre stations; ``lift_slope="vlm"`` the local lift slope
C_lα(y) = (C_lα c)/c of the vortex lattice of the wing's rectangular planform (its root a
symmetry plane, as for a wall-mounted cantilever), on the lattice's own strips.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.aerodynamics import vortex_lattice
from bioflex_jsb.aerodynamics.theodorsen import TWO_PI, elastic_axis_a
from bioflex_jsb.parameters import goland as G
from bioflex_jsb.structures.beam import BeamSections, solve_beam, uniform_sections

# Defaults. ESTIMATE (measured while writing tests/test_goland.py): 6 modes, 40 elements and
# 24 Gauss-Legendre strips put the Goland flutter speed within 0.01 % (136.963 m/s) of 10
# modes, 80 elements and 40 strips (136.953 m/s), the first three frequencies within 0.04 %.
DEFAULT_N_MODES = 6
DEFAULT_N_ELEMENTS = 40
DEFAULT_N_STRIPS = 24
DEFAULT_VLM_SPANWISE = 40
DEFAULT_VLM_CHORDWISE = 4
LIFT_SLOPES = ("strip", "vlm")
# Gauss-Legendre strips on each piece of the span between breaks (a control surface's ends):
# at least this many (a 4-point rule is exact for polynomials to degree 7 on the piece)
MIN_PIECE_STRIPS = 4


@dataclass(frozen=True)
class RectangularPlanform:
    """Unswept constant-chord half wing for the vortex lattice (``PlanformLike``).

    Wing frame of :mod:`bioflex_jsb.aerodynamics.lifting_line`: x aft from the root leading
    edge [m], y to starboard [m]. ``semispan_m`` b/2 [m], ``chord_m`` c [m].
    """

    semispan_m: float
    chord_m: float

    def chord_at(self, y_m) -> np.ndarray:
        """c(y) [m]."""
        return np.full_like(np.abs(np.asarray(y_m, dtype=float)), self.chord_m)

    def leading_edge_x_at(self, y_m) -> np.ndarray:
        """x_le(y) = 0 [m] (unswept)."""
        return np.zeros_like(np.asarray(y_m, dtype=float))


@dataclass(frozen=True, eq=False)
class ClampedWingModel:
    """Modal structure of a clamped wing and its aerodynamic strips.

    Attributes:
        natural_frequencies_rad_s: (n,) wind-off natural frequencies ω_i [rad/s].
        torsion_energy_fraction: (n,) share of each mode's strain energy in torsion [-].
        stiffness: (n, n) diag(ω_i²) [N·m/rad per unit generalised mass] (modes are
            M-orthonormal, so the modal mass is the identity).
        stations_m: (k,) strip stations y_k [m] from the root.
        weights_m: (k,) strip integration weights [m] (Σ = semi-span).
        heave_m: (n, k) heave h (down) of the elastic axis per unit modal coordinate [m].
        pitch_rad: (n, k) twist α (leading edge up) per unit modal coordinate [rad].
        semichord_m: (k,) semichord b [m].
        elastic_axis_a: (k,) elastic axis, semichords aft of mid-chord [-].
        lift_slope_per_rad: (k,) circulatory lift slope a₀ of each strip [1/rad].
        lift_slope: ``"strip"`` or ``"vlm"``; ``description`` text for reports.
    """

    natural_frequencies_rad_s: np.ndarray
    torsion_energy_fraction: np.ndarray
    stations_m: np.ndarray
    weights_m: np.ndarray
    heave_m: np.ndarray = field(repr=False)
    pitch_rad: np.ndarray = field(repr=False)
    semichord_m: np.ndarray = field(repr=False)
    elastic_axis_a: np.ndarray = field(repr=False)
    lift_slope_per_rad: np.ndarray = field(repr=False)
    lift_slope: str = "strip"
    description: str = ""

    @property
    def n_modes(self) -> int:
        return int(self.natural_frequencies_rad_s.size)

    @property
    def mass(self) -> np.ndarray:
        """(n, n) modal mass (identity: M-orthonormal modes)."""
        return np.eye(self.n_modes)

    @property
    def stiffness(self) -> np.ndarray:
        """(n, n) modal stiffness diag(ω_i²)."""
        return np.diag(self.natural_frequencies_rad_s**2)

    def mode_labels(self) -> tuple[str, ...]:
        """"mode 1 (bending)", … : the index, and whether bending or torsion holds most of
        the mode's strain energy (a strongly coupled mode may be named after either)."""
        return tuple(
            f"mode {i + 1} ({'torsion' if frac > 0.5 else 'bending'})"
            for i, frac in enumerate(self.torsion_energy_fraction)
        )


def goland_sections(*, inertia_about: str = G.DEFAULT_INERTIA_AXIS) -> BeamSections:
    """Beam sections of the Goland wing (:mod:`bioflex_jsb.parameters.goland`).

    ``inertia_about``: the axis of the published 8.64 kg·m, ``"elastic-axis"`` (default,
    the reading the published natural frequencies support) or ``"centre-of-mass"`` (the
    specification's wording); see
    :func:`bioflex_jsb.parameters.goland.inertia_about_elastic_axis_kg_m`.
    """
    return uniform_sections(
        G.SEMISPAN_M,
        bending_stiffness_n_m2=G.BENDING_STIFFNESS_N_M2,
        torsional_stiffness_n_m2=G.TORSIONAL_STIFFNESS_N_M2,
        mass_per_length_kg_m=G.MASS_PER_LENGTH_KG_M,
        torsional_inertia_kg_m=G.inertia_about_elastic_axis_kg_m(inertia_about),
        chord_m=G.CHORD_M,
        x_elastic_frac=G.X_ELASTIC_FRAC,
        x_inertial_frac=G.X_INERTIAL_FRAC,
        description=f"Goland wing ({G.MASS_MOMENT_OF_INERTIA_KG_M} kg·m about the "
                    f"{inertia_about})",
    )


def _gauss_strips(semispan_m: float, n: int, breaks_m=()) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre strips on [0, semispan]; with ``breaks_m`` [m] inside the span, on
    each piece between them (the piece's share of ``n``, at least MIN_PIECE_STRIPS), so
    that a strip edge (the cumulative weights: the Gauss nodes lie between them) falls on
    every break."""
    inner = sorted({float(b) for b in breaks_m if 0.0 < float(b) < semispan_m})
    if not inner:
        x, w = np.polynomial.legendre.leggauss(n)
        return 0.5 * semispan_m * (x + 1.0), 0.5 * semispan_m * w
    ends = [0.0, *inner, float(semispan_m)]
    ys, ws = [], []
    for lo, hi in zip(ends[:-1], ends[1:], strict=True):
        k = max(MIN_PIECE_STRIPS, math.ceil(n * (hi - lo) / semispan_m))
        x, w = np.polynomial.legendre.leggauss(k)
        ys.append(lo + 0.5 * (hi - lo) * (x + 1.0))
        ws.append(0.5 * (hi - lo) * w)
    return np.concatenate(ys), np.concatenate(ws)


def clamped_wing_model(
    sections: BeamSections,
    *,
    lift_slope: str = "strip",
    n_modes: int = DEFAULT_N_MODES,
    n_elements: int = DEFAULT_N_ELEMENTS,
    n_strips: int = DEFAULT_N_STRIPS,
    section_lift_slope_per_rad: float = TWO_PI,
    vlm_spanwise: int = DEFAULT_VLM_SPANWISE,
    vlm_chordwise: int = DEFAULT_VLM_CHORDWISE,
    breaks_m: tuple[float, ...] = (),
) -> ClampedWingModel:
    """Modal model of the clamped beam ``sections`` with aerodynamic strips.

    ``lift_slope="strip"``: ``n_strips`` Gauss-Legendre strips, each with the 2-D lift
    slope ``section_lift_slope_per_rad``; with ``breaks_m`` [m] (a control surface's ends)
    Gauss-Legendre strips on each piece of the span between them, each piece its share of
    ``n_strips`` (at least 4), so that strip edges fall on the breaks (none: the strips of
    before, bit for bit). ``lift_slope="vlm"``: the strips of the vortex
    lattice (``vlm_spanwise`` × ``vlm_chordwise`` panels on the half wing, tuned to the same
    2-D slope) with its local C_lα(y); this needs a constant chord (a rectangular planform).
    """
    if lift_slope not in LIFT_SLOPES:
        raise ValueError(f"lift_slope must be one of {LIFT_SLOPES}, not {lift_slope!r}")
    sol = solve_beam(sections, n_modes, n_elements)
    semispan = sections.semispan_m
    if lift_slope == "strip":
        y, w = _gauss_strips(semispan, n_strips, breaks_m)
        a0 = np.full(y.size, float(section_lift_slope_per_rad))
        text = f"strip theory, a0 = {section_lift_slope_per_rad:.4f}/rad, {y.size} strips"
    else:
        chord = sections.chord_m
        if np.ptp(chord) > 1e-12 * chord[0]:
            raise ValueError("lift_slope='vlm' needs a constant chord (rectangular planform)")
        aero = vortex_lattice.solve_spanwise_aerodynamics(
            RectangularPlanform(semispan, float(chord[0])),
            n_spanwise=vlm_spanwise, n_chordwise=vlm_chordwise,
            section_lift_slope_per_rad=section_lift_slope_per_rad,
        )
        y, w = aero.stations_m, aero.weights_m
        a0 = aero.local_lift_slope_per_rad
        text = (f"vortex-lattice span loading ({vlm_spanwise}x{vlm_chordwise}), wing "
                f"C_La = {aero.wing_lift_slope_per_rad:.4f}/rad")
    heave, pitch = sol.sample(y)
    chord_y = np.interp(y, sections.stations_m, sections.chord_m)
    xe_y = np.interp(y, sections.stations_m, sections.x_elastic_frac)
    return ClampedWingModel(
        natural_frequencies_rad_s=sol.frequencies_rad_s,
        torsion_energy_fraction=sol.torsion_energy_fraction,
        stations_m=y,
        weights_m=w,
        heave_m=heave,
        pitch_rad=pitch,
        semichord_m=0.5 * chord_y,
        elastic_axis_a=np.array([elastic_axis_a(x) for x in xe_y]),
        lift_slope_per_rad=a0,
        lift_slope=lift_slope,
        description=f"{sections.description}; {n_modes} modes, {n_elements} elements; {text}",
    )


def reduced_frequency(frequency_rad_s: float, speed_m_s: float, semichord_m: float) -> float:
    """k = ωb/V [-]; ∞ at zero speed."""
    return math.inf if speed_m_s == 0.0 else abs(frequency_rad_s) * semichord_m / speed_m_s


def structural_damping_matrix(model: ClampedWingModel, zeta: float) -> np.ndarray:
    """Modal viscous damping diag(2 ζ ω_i) [1/s] (ζ [-] the same for every mode)."""
    return np.diag(2.0 * float(zeta) * model.natural_frequencies_rad_s)
