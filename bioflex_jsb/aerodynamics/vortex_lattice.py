"""Spanwise aerodynamics of the flat wing by a vortex-lattice (Weissinger-type) method.

This is the "classic vortex method" of Section 3.2 of the paper: it supplies the strip
quantities C_lα(y)·c(y) and the local aerodynamic-centre line x_ac(y) that the Table B1
integrals need, and an influence matrix that turns any spanwise distribution of local angle
of attack (Eq. 3: twist of a mode, p·y/u_0, ...) into lift per unit span, so that the elastic
wing is loaded by lifting-surface theory and not by strip theory.

Method (docs/aerodynamics.md):

* The starboard half wing is divided into ``n_spanwise`` strips (nodes fine at the tip,
  full-span cosine spacing, with a node exactly on every planform kink) and each strip into
  ``n_chordwise`` equal chordwise panels. Each panel carries a horseshoe vortex: a straight
  bound segment on the panel's quarter-chord line and two trailing legs running aft to
  infinity, parallel to x, in the wing plane (flat wake, small angles).
* The normal-velocity condition is applied at one control point per panel. With the default
  2-D lift slope 2π the control point is at the panel's three-quarter chord (Weissinger's
  3/4-chord rule when ``n_chordwise = 1``); another section lift slope a_0 moves it, see
  :func:`control_point_fraction`.
* Symmetric and antisymmetric loadings are solved on the starboard half with the port half
  as a mirror image (sum or difference of the mirrored horseshoe's influence).
* Lift by Kutta–Joukowski on the bound segments, linear (incompressible, inviscid, no
  thickness, no fuselage).
* Dihedral (a planform with ``has_dihedral`` and ``height_at``: the leading edge's height
  z(y), linear between stations): the panels, their control points and the trailing legs
  (parallel to x from each bound segment's ends) sit at that height, the boundary
  condition is the velocity normal to each strip's plane, n = (0, −dz/dy, 1)/√(1 + (dz/dy)²),
  and l'(y) is the vertical force per unit y (Kutta–Joukowski: ρ V Γ Δy; the side forces
  of the two halves cancel in symmetric flight). α(y) of the influence matrices is the
  angle in each strip's own normal plane (a twist about the panel's axis enters whole); a
  body angle of attack α gives α cos Γ there, so ``cl_alpha_c_m_per_rad`` (uniform body
  α) carries cos Γ per strip. On 2-D strips that makes C_Lα ∝ cos Γ (docs/aerodynamics.md).

Frames and signs: wing frame of :mod:`bioflex_jsb.parameters.wing`: origin at the root
leading edge, x positive **aft**, y positive to **starboard**, z positive **up** (x × y = z).
The free stream flows along +x; a positive local angle of attack α(y) is flow from below,
normal velocity +V·α. Lift and circulation are positive **up**. Everything is per unit dynamic
pressure q = ½ρV², so lift per unit span appears in metres: l'(y)/q [m].
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

TWO_PI = 2.0 * math.pi
"""Thin-aerofoil lift slope of a flat or cambered thin plate [1/rad] (the default a_0)."""

# Defaults from the convergence study (docs/aerodynamics.md, tests): with 40 strips and 4
# chordwise panels the prototype's planform's C_Lα is within 0.05 % of the 160 × 8 lattice and
# its aerodynamic centre within 0.01 % of the chord; the solve takes a few hundredths of a
# second.
DEFAULT_N_SPANWISE = 40
DEFAULT_N_CHORDWISE = 4


class PlanformLike(Protocol):
    """What the solver needs from a planform (``bioflex_jsb.parameters.wing.Planform`` fits).

    ``chord_at`` and ``leading_edge_x_at`` are streamwise [m], wing frame, starboard half.
    Optional attributes: ``breaks_m`` (sequence of spanwise kink stations [m]) or
    ``outer_panel_start_m`` (the single kink of ``Planform``); the lattice puts a strip edge
    on each so that every bound segment is straight.
    """

    semispan_m: float

    def chord_at(self, y_m: np.ndarray | float) -> np.ndarray: ...

    def leading_edge_x_at(self, y_m: np.ndarray | float) -> np.ndarray: ...


@dataclass(frozen=True, eq=False)
class SpanwiseAerodynamics:
    """Strip quantities of the starboard half wing from the vortex lattice.

    Arrays of shape (k,) are per strip, k = ``n_spanwise``; strip j spans
    [``edges_m[j]``, ``edges_m[j+1]``].

    Attributes:
        stations_m: spanwise stations y_j [m], 0 < y_j < b/2: the strips' control-point
            stations (:func:`control_point_stations`), where the lattice imposes α.
        weights_m: strip widths [m]; ∫_0^{b/2} f(y) dy ≈ Σ_j weights_m[j]·f(y_j) (a
            second-order rule; exact for the lattice's strip-wise constant loads, so
            Σ w·C_lα c is the lattice's lift).
        edges_m: (k+1,) strip edges [m], 0 … b/2.
        chord_m: streamwise chord at the stations [m].
        cl_alpha_c_m_per_rad: C_lα(y)·c(y) [m/rad], lift per unit span per unit dynamic
            pressure per radian of a *uniform* angle of attack on the whole wing.
        x_ac_m: local aerodynamic-centre line [m aft of the root leading edge]: the centre
            of pressure of each strip's load under uniform α (chordwise panels' loads
            times their bound-segment midpoints). For a flat wing this makes
            Σ w·x_ac·C_lα c reproduce the lattice's pitching moment exactly. With
            ``n_chordwise = 1`` it is the quarter-chord point of the strip's centroid.
        x_quarter_chord_m: the quarter-chord point at the stations [m aft of the root LE].
        wing_lift_slope_per_rad: C_Lα of the whole wing on ``reference_area_m2`` [1/rad].
        wing_ac_x_m: x of the wing's aerodynamic centre (neutral point of the wing alone)
            [m aft of the root leading edge].
        reference_area_m2: planform area of both halves as discretised [m²] (equals b·c for
            the constant-chord planform).
        semispan_m: b/2 [m].
        section_lift_slope_per_rad: the 2-D lift slope a_0 the lattice was tuned to [1/rad].
        n_chordwise: chordwise panels per strip [-].
        influence_m: (k, k) symmetric-loading influence matrix [m/rad]:
            l'/q at the stations = ``influence_m`` @ α, for α(y) = α(−y) given at the
            stations (α uniform over each strip's chord).
        influence_x_m2: (k, k) [m²/rad]: first moment of the strip loads about the root
            leading edge, (l'·x_cp)/q = ``influence_x_m2`` @ α, symmetric loading.
        influence_antisymmetric_m: (k, k) [m/rad], as ``influence_m`` for α(−y) = −α(y);
            the result is the starboard l'/q (the port one is its negative).
        influence_antisymmetric_x_m2: (k, k) [m²/rad], first moment, antisymmetric.
    """

    stations_m: np.ndarray
    weights_m: np.ndarray
    edges_m: np.ndarray
    chord_m: np.ndarray
    cl_alpha_c_m_per_rad: np.ndarray
    x_ac_m: np.ndarray
    x_quarter_chord_m: np.ndarray
    wing_lift_slope_per_rad: float
    wing_ac_x_m: float
    reference_area_m2: float
    semispan_m: float
    section_lift_slope_per_rad: float
    n_chordwise: int
    influence_m: np.ndarray = field(repr=False)
    influence_x_m2: np.ndarray = field(repr=False)
    influence_antisymmetric_m: np.ndarray = field(repr=False)
    influence_antisymmetric_x_m2: np.ndarray = field(repr=False)
    # cos Γ of each strip's dihedral [-] (None: a flat wing): a body angle of attack α is
    # α cos Γ in the strip's normal plane (module docstring)
    cos_dihedral: np.ndarray | None = field(default=None, repr=False)

    @property
    def span_m(self) -> float:
        """b [m]."""
        return 2.0 * self.semispan_m

    @property
    def aspect_ratio(self) -> float:
        """b²/S of the discretised wing [-]."""
        return self.span_m**2 / self.reference_area_m2

    @property
    def local_lift_slope_per_rad(self) -> np.ndarray:
        """C_lα(y) = (C_lα c)/c at the stations [1/rad]."""
        return self.cl_alpha_c_m_per_rad / self.chord_m

    def lift_per_span_for_alpha(
        self, alpha_distribution_rad: np.ndarray, *, antisymmetric: bool = False
    ) -> np.ndarray:
        """Lift per unit span per unit dynamic pressure l'(y)/q [m] at the stations.

        ``alpha_distribution_rad`` (k,) is the local angle of attack [rad] at ``stations_m``
        (e.g. a mode's twist θ_i(y) per unit η_i). By default the distribution is mirrored
        symmetrically onto the port half; ``antisymmetric=True`` mirrors it with a change of
        sign (rolling, α = p·y/V). Returns the starboard values.
        """
        alpha = self._check(alpha_distribution_rad)
        matrix = self.influence_antisymmetric_m if antisymmetric else self.influence_m
        return matrix @ alpha

    def centre_of_pressure_x_for_alpha(
        self, alpha_distribution_rad: np.ndarray, *, antisymmetric: bool = False
    ) -> np.ndarray:
        """Local centre of pressure x_cp(y) [m aft of root LE] of the load due to α(y).

        NaN where that strip carries no lift.
        """
        alpha = self._check(alpha_distribution_rad)
        if antisymmetric:
            lift, moment = self.influence_antisymmetric_m, self.influence_antisymmetric_x_m2
        else:
            lift, moment = self.influence_m, self.influence_x_m2
        l_q = lift @ alpha
        m_q = moment @ alpha
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(l_q != 0.0, m_q / l_q, np.nan)

    def roll_damping_clp(self) -> float:
        """Roll damping C_lp of the wing alone [1/rad], on S·b and p̂ = p·b/(2V).

        Antisymmetric α(y) = p·y/V (Eq. 3); rolling moment positive right wing down,
        L = −∫ y·l'(y) dy over the span (lift up on the starboard wing rolls it up, i.e.
        negative). C_l = L/(q S b). Negative (damping).
        """
        y = self.stations_m
        alpha_per_phat = 2.0 * y / self.span_m  # α for p̂ = 1 [rad]
        l_q = self.influence_antisymmetric_m @ alpha_per_phat
        rolling_moment_q_m3 = -2.0 * float(np.sum(self.weights_m * y * l_q))
        return rolling_moment_q_m3 / (self.reference_area_m2 * self.span_m)

    def _check(self, alpha: np.ndarray) -> np.ndarray:
        a = np.asarray(alpha, dtype=float)
        if a.shape != self.stations_m.shape:
            raise ValueError(
                f"alpha distribution has shape {a.shape}, expected {self.stations_m.shape} "
                "(one value per station)"
            )
        return a


# --------------------------------------------------------------------------------------
# Geometry
# --------------------------------------------------------------------------------------


def _planform_breaks(planform: PlanformLike) -> list[float]:
    s = float(planform.semispan_m)
    raw = getattr(planform, "breaks_m", None)
    if raw is None:
        start = getattr(planform, "outer_panel_start_m", None)
        raw = [] if start is None else [start]
    return sorted(float(b) for b in raw if 0.0 < float(b) < s)


SPACINGS = ("cosine", "uniform")
"""Spanwise node distributions accepted by :func:`spanwise_nodes`."""


def _t_to_y(t: np.ndarray, semispan_m: float, spacing: str) -> np.ndarray:
    if spacing == "cosine":
        return semispan_m * np.sin(0.5 * math.pi * t)
    return semispan_m * t


def _y_to_t(y: np.ndarray, semispan_m: float, spacing: str) -> np.ndarray:
    ratio = np.clip(np.asarray(y, dtype=float) / semispan_m, 0.0, 1.0)
    if spacing == "cosine":
        return 2.0 / math.pi * np.arcsin(ratio)
    return ratio


def spanwise_nodes(planform: PlanformLike, n_spanwise: int, spacing: str = "cosine") -> np.ndarray:
    """Strip edges y [m] on the starboard half, with a node on every planform kink.

    ``"cosine"`` (default): full-span cosine spacing, y = (b/2)·sin(π t/2) for t uniform in
    [0, 1]; fine at the tip, where the loading falls like a square root, and coarse at the
    root, which is a symmetry plane. ``"uniform"``: y = (b/2)·t (the textbook lattices).
    Each kink y_k is put on a node: t is split at t(y_k) and every sub-interval gets a share
    of the n strips proportional to its length in t (at least one).
    """
    if spacing not in SPACINGS:
        raise ValueError(f"spacing must be one of {SPACINGS}, not {spacing!r}")
    if n_spanwise < 2:
        raise ValueError("n_spanwise must be at least 2")
    s = float(planform.semispan_m)
    breaks = _planform_breaks(planform)
    t_breaks = np.concatenate([[0.0], _y_to_t(np.array(breaks), s, spacing), [1.0]])
    lengths = np.diff(t_breaks)
    counts = np.maximum(1, np.round(lengths / lengths.sum() * n_spanwise).astype(int))
    # make the counts add up to n_spanwise by adjusting the longest interval
    counts[int(np.argmax(lengths))] += n_spanwise - int(counts.sum())
    if np.any(counts < 1):
        raise ValueError("n_spanwise too small for the number of planform kinks")
    pieces = [
        np.linspace(t_breaks[i], t_breaks[i + 1], counts[i] + 1)[:-1] for i in range(counts.size)
    ]
    y = _t_to_y(np.concatenate(pieces + [np.array([1.0])]), s, spacing)
    for b in breaks:  # exact kink positions (remove round-off of sin∘asin)
        y[int(np.argmin(np.abs(y - b)))] = b
    y[0], y[-1] = 0.0, s
    return y


def control_point_stations(edges_m: np.ndarray, spacing: str = "cosine") -> np.ndarray:
    """Spanwise control-point stations [m]: the midpoints of the strips in the parameter t.

    For cosine spacing, strip j's control point is at t = (t_j + t_{j+1})/2, i.e. at
    y = (b/2)·sin(π(t_j + t_{j+1})/4) (the "semicircle" placement of the cosine lattices of
    Lan and of James). Compared with the arithmetic mid-strip it removes the O(1/n) tip error
    of the lift: on an elliptic wing of aspect ratio 6 the lift slope with 20 strips is within
    0.01 % of its converged value, against 1.4 % with mid-strip control points
    (docs/aerodynamics.md). For uniform spacing it is the mid-strip.
    """
    s = float(edges_m[-1])
    t = _y_to_t(edges_m, s, spacing)
    return _t_to_y(0.5 * (t[:-1] + t[1:]), s, spacing)


def control_point_fraction(section_lift_slope_per_rad: float) -> float:
    """Distance from bound vortex to control point as a fraction of the panel chord [-].

    Lumped-vortex argument for one panel of chord c: the bound vortex Γ at c/4 induces
    Γ/(2π r c) at the control point r·c behind it; the boundary condition makes that equal
    to V·α, and c_l = 2Γ/(V c) = 4π r·α. So r = a_0/(4π): r = 1/2 (the 3/4-chord rule) for
    a_0 = 2π. The same r makes the 2-D lattice of several equal panels give exactly a_0 too
    (checked for 1–8 panels by ``_lift_slope_2d`` in the tests). On the wing this is the
    classical way of feeding a section lift slope into Weissinger's method; its lifting-line
    limit is Γ = ½·a_0·c·V·(α − α_i).
    """
    a0 = float(section_lift_slope_per_rad)
    r = a0 / (4.0 * math.pi)
    # the control point must stay on its own panel behind its bound vortex: 0 < r ≤ 3/4,
    # i.e. 0 < a_0 ≤ 3π
    if not 0.0 < r <= 0.75:
        raise ValueError(f"section lift slope {a0} rad⁻¹ is outside (0, 3π]")
    return r


def _lift_slope_2d(r: float, n_chordwise: int) -> float:
    """Lift slope [1/rad] of the 2-D lattice with control points r panel chords aft."""
    m = np.arange(n_chordwise)
    x_vortex = (m + 0.25) / n_chordwise  # chord = 1
    x_control = (m + 0.25 + r) / n_chordwise
    # 2-D vortex Γ (lift-up positive) induces w = −Γ/(2π(x − ξ)) at x; BC: w + V α = 0
    a = -1.0 / (TWO_PI * (x_control[:, None] - x_vortex[None, :]))
    gamma = np.linalg.solve(a, -np.ones(n_chordwise))  # V = 1, α = 1
    return float(2.0 * gamma.sum())  # c_l = ρVΣΓ/(q c)


@dataclass(frozen=True)
class _Lattice:
    a_m: np.ndarray  # (n, 3) bound-segment inner end (smaller y) [m]
    b_m: np.ndarray  # (n, 3) bound-segment outer end [m]
    control_m: np.ndarray  # (n, 3) control points [m]
    strip_index: np.ndarray  # (n,) strip of each panel


def build_lattice(planform: PlanformLike, edges_m: np.ndarray, n_chordwise: int, r: float,
                  spacing: str):
    x_le = np.asarray(planform.leading_edge_x_at(edges_m), dtype=float)
    chord = np.asarray(planform.chord_at(edges_m), dtype=float)
    height = _heights(planform, edges_m)
    k = edges_m.size - 1
    m = np.arange(n_chordwise)
    f_bound = (m + 0.25) / n_chordwise  # chord fractions of the bound segments
    f_control = (m + 0.25 + r) / n_chordwise
    # panel index p = j*n_chordwise + m
    j = np.repeat(np.arange(k), n_chordwise)
    fm_b = np.tile(f_bound, k)
    fm_c = np.tile(f_control, k)
    zeros = np.zeros(j.size)
    a = np.column_stack([x_le[j] + fm_b * chord[j], edges_m[j], zeros])
    b = np.column_stack([x_le[j + 1] + fm_b * chord[j + 1], edges_m[j + 1], zeros])
    # control points at the strips' parameter midpoints, on the straight panel edges
    y_ctrl = control_point_stations(edges_m, spacing)
    frac = (y_ctrl - edges_m[:-1]) / np.diff(edges_m)  # position inside the strip [-]
    x_le_ctrl = (1.0 - frac) * x_le[:-1] + frac * x_le[1:]
    c_ctrl = (1.0 - frac) * chord[:-1] + frac * chord[1:]
    ctrl = np.column_stack([x_le_ctrl[j] + fm_c * c_ctrl[j], y_ctrl[j], zeros])
    if height is not None:  # dihedral: every point at its leading edge's height
        a[:, 2] = height[j]
        b[:, 2] = height[j + 1]
        ctrl[:, 2] = ((1.0 - frac) * height[:-1] + frac * height[1:])[j]
    return _Lattice(a, b, ctrl, j), x_le, chord, y_ctrl, c_ctrl


def _heights(planform: PlanformLike, edges_m: np.ndarray) -> np.ndarray | None:
    """The leading edge's height z [m] at the strip edges, or None for a flat wing."""
    if not getattr(planform, "has_dihedral", False):
        return None
    return np.asarray(planform.height_at(edges_m), dtype=float)


def _strip_normals(planform: PlanformLike, edges_m: np.ndarray) -> np.ndarray | None:
    """(k, 3) unit normals of the strips' planes (0, −dz/dy, 1)/√(1 + (dz/dy)²) of a wing
    with dihedral (starboard half), or None for a flat wing."""
    height = _heights(planform, edges_m)
    if height is None:
        return None
    slope = np.diff(height) / np.diff(edges_m)
    norm = np.sqrt(1.0 + slope**2)
    return np.column_stack([np.zeros_like(slope), -slope / norm, 1.0 / norm])


# --------------------------------------------------------------------------------------
# Biot–Savart
# --------------------------------------------------------------------------------------

_X_HAT = np.array([1.0, 0.0, 0.0])
# A point closer than this fraction of the segment length to a vortex line's axis is treated
# as lying on it (the line then induces nothing there: collinear points off the segment).
_ON_LINE_REL = 1e-10


def _segment_velocity(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Velocity at p induced by the straight filament a → b with unit circulation [1/m].

    p (n, 1, 3), a and b (1, m, 3); result (n, m, 3). Biot–Savart for a finite segment.
    """
    r1 = p - a
    r2 = p - b
    r0 = b - a
    cross = np.cross(r1, r2)
    cross2 = np.einsum("...i,...i->...", cross, cross)
    n1 = np.linalg.norm(r1, axis=-1)
    n2 = np.linalg.norm(r2, axis=-1)
    len2 = np.einsum("...i,...i->...", r0, r0)
    on_line = cross2 <= (_ON_LINE_REL**2) * len2 * len2
    with np.errstate(divide="ignore", invalid="ignore"):
        proj = np.einsum("...i,...i->...", r0, r1 / n1[..., None] - r2 / n2[..., None])
        factor = np.where(on_line, 0.0, proj / (4.0 * math.pi * cross2))
    return factor[..., None] * cross


def _semi_infinite_velocity(p: np.ndarray, a: np.ndarray, length_m: np.ndarray) -> np.ndarray:
    """Velocity at p induced by the filament from a to +∞ along +x, unit circulation [1/m].

    Integral of Biot–Savart along a + s·x̂, s ∈ [0, ∞): v = (x̂ × r)/(4π h²)·(1 + x̂·r/|r|),
    r = p − a, h = |x̂ × r| the distance from the line. ``length_m`` is a length scale for
    the on-line test.
    """
    r = p - a
    u = np.broadcast_to(_X_HAT, r.shape)
    uxr = np.cross(u, r)
    h2 = np.einsum("...i,...i->...", uxr, uxr)
    nr = np.linalg.norm(r, axis=-1)
    on_line = h2 <= (_ON_LINE_REL * length_m) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        factor = np.where(on_line, 0.0, (1.0 + r[..., 0] / nr) / (4.0 * math.pi * h2))
    return factor[..., None] * uxr


def horseshoe_normalwash(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Upward velocity w at ``points`` (n, 3) due to unit-Γ horseshoes a → b (m, 3) [1/m].

    Horseshoe: trailing leg from +∞ to a, bound segment a → b, trailing leg b → +∞. With
    the bound segment pointing to +y, positive Γ means lift up (ρ V x̂ × Γ ŷ = +ẑ).
    """
    return _horseshoe_velocity(points, a, b)[..., 2]


def _horseshoe_velocity(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(n, m, 3) velocity at ``points`` (n, 3) due to unit-Γ horseshoes a → b (m, 3) [1/m]
    (:func:`horseshoe_normalwash`'s horseshoes)."""
    p = points[:, None, :]
    aa = a[None, :, :]
    bb = b[None, :, :]
    length = np.linalg.norm(b - a, axis=-1)[None, :]
    v = (
        -_semi_infinite_velocity(p, aa, length)
        + _segment_velocity(p, aa, bb)
        + _semi_infinite_velocity(p, bb, length)
    )
    return v


# --------------------------------------------------------------------------------------
# Solver
# --------------------------------------------------------------------------------------


def solve_spanwise_aerodynamics(
    planform: PlanformLike,
    *,
    n_spanwise: int = DEFAULT_N_SPANWISE,
    n_chordwise: int = DEFAULT_N_CHORDWISE,
    section_lift_slope_per_rad: float = TWO_PI,
    spacing: str = "cosine",
) -> SpanwiseAerodynamics:
    """Vortex-lattice solution of the flat symmetric wing ``planform``.

    ``n_spanwise`` strips on the half wing, ``n_chordwise`` panels per strip (1: Weissinger's
    3/4-chord method), ``section_lift_slope_per_rad`` the 2-D lift slope a_0 the lattice is
    tuned to [1/rad] (2π: thin plate, flat or cambered), ``spacing`` the spanwise node
    distribution (:func:`spanwise_nodes`; ``"uniform"`` only to reproduce textbook lattices).
    """
    if n_chordwise < 1:
        raise ValueError("n_chordwise must be at least 1")
    r = control_point_fraction(section_lift_slope_per_rad)
    edges = spanwise_nodes(planform, n_spanwise, spacing)
    lat, x_le_nodes, chord_nodes, stations, chord = build_lattice(
        planform, edges, n_chordwise, r, spacing
    )

    mirror = np.array([1.0, -1.0, 1.0])
    normals = _strip_normals(planform, edges)
    if normals is None:
        w_self = horseshoe_normalwash(lat.control_m, lat.a_m, lat.b_m)
        # the port image of a starboard horseshoe a → b is the horseshoe b' → a' (bound
        # segment still pointing to +y), which carries the same Γ in symmetric flight
        w_image = horseshoe_normalwash(lat.control_m, lat.b_m * mirror, lat.a_m * mirror)
    else:  # dihedral: the velocity normal to each control point's strip
        n_panel = normals[lat.strip_index][:, None, :]
        w_self = np.sum(_horseshoe_velocity(lat.control_m, lat.a_m, lat.b_m) * n_panel,
                        axis=-1)
        w_image = np.sum(_horseshoe_velocity(lat.control_m, lat.b_m * mirror,
                                             lat.a_m * mirror) * n_panel, axis=-1)

    k = edges.size - 1
    widths = np.diff(edges)
    # E: strip α → every control point of the strip; S: panel Γ → strip sum
    expand = np.zeros((k * n_chordwise, k))
    expand[np.arange(k * n_chordwise), lat.strip_index] = 1.0
    x_bound_mid = 0.5 * (lat.a_m[:, 0] + lat.b_m[:, 0])  # load centroid of each bound segment

    def influence(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # BC with V = 1: w_induced + α = 0 → Γ = −A⁻¹ E α;  l'/q = 2ΣΓ/V per strip
        gamma_per_alpha = np.linalg.solve(matrix, -expand)  # (panels, k)
        lift = 2.0 * (expand.T @ gamma_per_alpha)
        lift_x = 2.0 * (expand.T @ (x_bound_mid[:, None] * gamma_per_alpha))
        return lift, lift_x

    infl_s, infl_s_x = influence(w_self + w_image)
    infl_a, infl_a_x = influence(w_self - w_image)

    # a uniform body angle of attack: 1 rad on a flat wing, cos Γ in a dihedral strip's plane
    ones = np.ones(k) if normals is None else normals[:, 2]
    cl_alpha_c = infl_s @ ones
    x_ac = (infl_s_x @ ones) / cl_alpha_c
    frac = (stations - edges[:-1]) / widths
    x_qc = (1.0 - frac) * x_le_nodes[:-1] + frac * x_le_nodes[1:] + 0.25 * chord
    area = float(np.sum(widths * (chord_nodes[:-1] + chord_nodes[1:])))  # both halves
    half_lift = float(np.sum(widths * cl_alpha_c))
    return SpanwiseAerodynamics(
        stations_m=stations,
        weights_m=widths,
        edges_m=edges,
        chord_m=chord,
        cl_alpha_c_m_per_rad=cl_alpha_c,
        x_ac_m=x_ac,
        x_quarter_chord_m=x_qc,
        wing_lift_slope_per_rad=2.0 * half_lift / area,
        wing_ac_x_m=float(np.sum(widths * cl_alpha_c * x_ac)) / half_lift,
        reference_area_m2=area,
        semispan_m=float(planform.semispan_m),
        section_lift_slope_per_rad=float(section_lift_slope_per_rad),
        n_chordwise=int(n_chordwise),
        influence_m=infl_s,
        influence_x_m2=infl_s_x,
        influence_antisymmetric_m=infl_a,
        influence_antisymmetric_x_m2=infl_a_x,
        cos_dihedral=None if normals is None else normals[:, 2].copy(),
    )
