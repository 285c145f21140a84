"""Wing + horizontal tail by one vortex lattice: the rigid longitudinal derivatives of a
stated geometry.

The wing's lattice of :mod:`bioflex_jsb.aerodynamics.vortex_lattice` (horseshoes on the
panels' quarter-chord lines, control points at r = a₀/4π panel chords behind them, flat
wake along +x, port half as mirror image) is extended by a second lifting surface, the
horizontal tail, at a height above the wing plane. Both surfaces are solved together, so
the tail sees the wing's downwash and the wing the tail's upwash. Unlike the wing-only
solver, the boundary condition is given **per panel**, which a pitch rate (α grows along
x) and a flap deflection (only the panels behind the hinge) need.

Derivatives (per rad; wing reference S, c̄; moments about the centre of gravity x_cg, nose
up; x aft of the wing's root leading edge, wing frame, docs/conventions.md):

* C_Lα, C_mα: uniform α on both surfaces; the tail's loads times the tail efficiency η_t
  (its dynamic-pressure ratio). Neutral point x_np = x_cg − C_mα c̄ / C_Lα.
* downwash gradient dε/dα = 1 − (tail lift in the combination)/(tail lift alone) at equal
  α, from the same lattice (the wing's trailing vortices at the tail).
* C_Lq, C_mq: α = q̂ (2/c̄)(x − x_cg) at every control point (q̂ = q c̄/2V), quasi-steady;
  the wing's share (C_mq of the wing alone in the combination) is reported apart.
* C_Lα̇, C_mα̇ by the downwash lag (Etkin & Reid, *Dynamics of Flight*, 3rd ed., §5.4 and
  §5.5): the tail feels the downwash shed l_ε/V earlier, l_ε the distance from the wing's
  aerodynamic centre to the tail's, so Δα_t = (dε/dα) α̇ l_ε / V and
  C_Lα̇ = 2 η_t (S_t/S) a_t (dε/dα)(l_ε/c̄), C_mα̇ = −C_Lα̇ (x_t − x_cg)/c̄, a_t the isolated
  tail's lift slope on S_t, x_t its aerodynamic centre. The wing's own α̇ (unsteady lift)
  is not in quasi-steady theory and not here.
* C_Lδe, C_mδe: unit incidence on the tail's panels behind the hinge (a plain flap of chord
  fraction E, its panels' edges put on the hinge), loads times η_t. Positive δe is trailing
  edge down (JSBSim's sign).

Nothing here knows the prototype: the geometry comes in as planforms, heights and the CG.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aerodynamics.vortex_lattice import (
    DEFAULT_N_CHORDWISE,
    DEFAULT_N_SPANWISE,
    TWO_PI,
    PlanformLike,
    build_lattice,
    control_point_fraction,
    horseshoe_normalwash,
    spanwise_nodes,
)

# NUMERICAL: tail lattice. 16 strips on its half span (cosine) and 10 chordwise panels, so
# that a 30 % flap hinge falls on a panel edge; convergence in tests/test_consistent_aircraft.py
# (C_Lα, C_mq, C_mδe change < 0.5 % on doubling both).
DEFAULT_TAIL_N_SPANWISE = 16
DEFAULT_TAIL_N_CHORDWISE = 10


@dataclass(frozen=True)
class _Surface:
    a_m: np.ndarray  # (p, 3) bound-segment ends
    b_m: np.ndarray
    control_m: np.ndarray  # (p, 3)
    force_x_m: np.ndarray  # (p,) x of each panel's load (bound-segment midpoint) [m]
    width_m: np.ndarray  # (p,) spanwise width of each panel's bound segment [m]
    chord_fraction: np.ndarray  # (p,) panel's control point as a fraction of the local chord
    area_m2: float  # both halves [m²]


def _surface(planform: PlanformLike, z_m: float, n_spanwise: int, n_chordwise: int,
             section_lift_slope_per_rad: float) -> _Surface:
    r = control_point_fraction(section_lift_slope_per_rad)
    edges = spanwise_nodes(planform, n_spanwise, "cosine")
    lat, _, chord_nodes, _, _ = build_lattice(planform, edges, n_chordwise, r, "cosine")
    lift_z = np.array([0.0, 0.0, z_m])
    m = np.arange(n_chordwise)
    widths = np.diff(edges)
    return _Surface(
        a_m=lat.a_m + lift_z, b_m=lat.b_m + lift_z, control_m=lat.control_m + lift_z,
        force_x_m=0.5 * (lat.a_m[:, 0] + lat.b_m[:, 0]),
        width_m=widths[lat.strip_index],
        chord_fraction=np.tile((m + 0.25 + r) / n_chordwise, edges.size - 1),
        area_m2=float(np.sum(widths * (chord_nodes[:-1] + chord_nodes[1:]))),
    )


def _influence(targets: _Surface, sources: _Surface) -> np.ndarray:
    """Upward velocity at the targets' control points per unit Γ of the sources' horseshoes
    (symmetric flight: each starboard horseshoe with its port image) [1/m]."""
    mirror = np.array([1.0, -1.0, 1.0])
    return (horseshoe_normalwash(targets.control_m, sources.a_m, sources.b_m)
            + horseshoe_normalwash(targets.control_m, sources.b_m * mirror,
                                    sources.a_m * mirror))


@dataclass(frozen=True)
class WingTailDerivatives:
    """Longitudinal derivatives of wing + tail (module docstring), per rad, on the wing's
    S and c̄, moments about ``x_cg_m`` [m, wing frame].

    Lift slopes: cl_alpha (total), cl_alpha_wing, cl_alpha_tail (shares in the combination,
    tail with η_t), tail_lift_slope_isolated_per_rad (the tail alone, on S_t);
    downwash_gradient dε/dα [-]; wing_ac_x_m, tail_ac_x_m: aerodynamic centres of the
    surfaces alone [m]; neutral_point_x_m [m]; static_margin (x_np − x_cg)/c̄ [-];
    cm_alpha; cl_q, cm_q (total), cm_q_wing, cm_q_tail (shares); cl_alphadot, cm_alphadot
    (downwash lag); cl_delta_e, cm_delta_e; tail_efficiency η_t [-]; areas [m²].
    """

    x_cg_m: float
    cbar_m: float
    wing_area_m2: float
    tail_area_m2: float
    tail_efficiency: float
    cl_alpha: float
    cl_alpha_wing: float
    cl_alpha_tail: float
    tail_lift_slope_isolated_per_rad: float
    downwash_gradient: float
    wing_ac_x_m: float
    tail_ac_x_m: float
    neutral_point_x_m: float
    static_margin: float
    cm_alpha: float
    cl_q: float
    cm_q: float
    cm_q_wing: float
    cm_q_tail: float
    cl_alphadot: float
    cm_alphadot: float
    cl_delta_e: float
    cm_delta_e: float

    def as_dict(self) -> dict[str, float]:
        return dict(self.__dict__)


def wing_tail_derivatives(
    wing: PlanformLike,
    tail: PlanformLike,
    *,
    tail_height_m: float,
    x_cg_m: float,
    cbar_m: float,
    tail_efficiency: float = 1.0,
    elevator_chord_fraction: float = 0.3,
    section_lift_slope_per_rad: float = TWO_PI,
    n_spanwise: int = DEFAULT_N_SPANWISE,
    n_chordwise: int = DEFAULT_N_CHORDWISE,
    tail_n_spanwise: int = DEFAULT_TAIL_N_SPANWISE,
    tail_n_chordwise: int = DEFAULT_TAIL_N_CHORDWISE,
) -> WingTailDerivatives:
    """Derivatives of ``wing`` + ``tail`` (planforms in the wing frame: the tail's
    ``leading_edge_x_at`` is aft of the wing's root leading edge) with the tail
    ``tail_height_m`` above the wing plane [m], about ``x_cg_m`` [m], chord ``cbar_m`` [m].

    ``elevator_chord_fraction`` E: the elevator is the aft E of the tail chord; E ×
    ``tail_n_chordwise`` must be a whole number (the hinge on a panel edge).
    """
    flap_panels = elevator_chord_fraction * tail_n_chordwise
    if not (0.0 < elevator_chord_fraction < 1.0) or abs(flap_panels - round(flap_panels)) > 1e-9:
        raise ValueError(
            f"elevator_chord_fraction × tail_n_chordwise must be a whole number of panels, "
            f"got {elevator_chord_fraction} × {tail_n_chordwise}"
        )
    w = _surface(wing, 0.0, n_spanwise, n_chordwise, section_lift_slope_per_rad)
    t = _surface(tail, tail_height_m, tail_n_spanwise, tail_n_chordwise,
                 section_lift_slope_per_rad)
    pw = w.a_m.shape[0]
    big = np.block([[_influence(w, w), _influence(w, t)], [_influence(t, w), _influence(t, t)]])
    tail_alone = _influence(t, t)
    s, cb, eta_t = w.area_m2, float(cbar_m), float(tail_efficiency)
    x_force = np.concatenate([w.force_x_m, t.force_x_m])
    width = np.concatenate([w.width_m, t.width_m])
    weight = np.concatenate([np.ones(pw), np.full(t.a_m.shape[0], eta_t)])  # η_t on the tail

    def loads(alpha_panels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(C_L, C_m) per panel for a panel α (V = 1, unit q): Γ = −A⁻¹α, force 2Γ·width
        per half, both halves."""
        gamma = np.linalg.solve(big, -alpha_panels)
        force = 2.0 * 2.0 * gamma * width * weight / s  # C_L share of each panel
        moment = -force * (x_force - x_cg_m) / cb
        return force, moment

    def split(values: np.ndarray) -> tuple[float, float]:
        return float(values[:pw].sum()), float(values[pw:].sum())

    # uniform α
    f_a, m_a = loads(np.ones(pw + t.a_m.shape[0]))
    cl_w, cl_t = split(f_a)
    cl_alpha, cm_alpha = cl_w + cl_t, float(m_a.sum())
    # the surfaces alone: tail lift slope on S_t, aerodynamic centres
    g_t = np.linalg.solve(tail_alone, -np.ones(t.a_m.shape[0]))
    lift_t_alone = 4.0 * g_t * t.width_m
    a_t = float(lift_t_alone.sum()) / t.area_m2
    x_ac_t = float(lift_t_alone @ t.force_x_m) / float(lift_t_alone.sum())
    g_w = np.linalg.solve(_influence(w, w), -np.ones(pw))
    lift_w_alone = 4.0 * g_w * w.width_m
    x_ac_w = float(lift_w_alone @ w.force_x_m) / float(lift_w_alone.sum())
    tail_alone_cl = eta_t * a_t * t.area_m2 / s  # on S, with η_t, same α
    downwash = 1.0 - cl_t / tail_alone_cl
    # pitch rate q̂ = 1: α = (2/c̄)(x − x_cg) at the control points
    x_ctrl = np.concatenate([w.control_m[:, 0], t.control_m[:, 0]])
    f_q, m_q = loads(2.0 / cb * (x_ctrl - x_cg_m))
    cm_q_w, cm_q_t = split(m_q)
    # downwash lag (Etkin & Reid §5.5)
    l_eps = x_ac_t - x_ac_w
    cl_adot = 2.0 * eta_t * (t.area_m2 / s) * a_t * downwash * (l_eps / cb)
    cm_adot = -cl_adot * (x_ac_t - x_cg_m) / cb
    # elevator: unit incidence on the tail panels behind the hinge
    flap = np.concatenate([np.zeros(pw),
                           (t.chord_fraction > 1.0 - elevator_chord_fraction).astype(float)])
    f_d, m_d = loads(flap)
    return WingTailDerivatives(
        x_cg_m=float(x_cg_m), cbar_m=cb, wing_area_m2=s, tail_area_m2=t.area_m2,
        tail_efficiency=eta_t, cl_alpha=cl_alpha, cl_alpha_wing=cl_w, cl_alpha_tail=cl_t,
        tail_lift_slope_isolated_per_rad=a_t, downwash_gradient=downwash,
        wing_ac_x_m=x_ac_w, tail_ac_x_m=x_ac_t,
        neutral_point_x_m=float(x_cg_m) - cm_alpha * cb / cl_alpha,
        static_margin=-cm_alpha / cl_alpha, cm_alpha=cm_alpha,
        cl_q=float(f_q.sum()), cm_q=cm_q_w + cm_q_t, cm_q_wing=cm_q_w, cm_q_tail=cm_q_t,
        cl_alphadot=cl_adot, cm_alphadot=cm_adot,
        cl_delta_e=float(f_d.sum()), cm_delta_e=float(m_d.sum()),
    )


def munk_moment_slope_per_rad(volume_m3: float, apparent_mass_factor: float,
                              reference_area_m2: float, cbar_m: float) -> float:
    """Slender body's free pitching moment dC_m/dα [1/rad] (Munk 1924, NACA Rep. 184):
    M = 2 (k₂ − k₁) Vol q α on a closed body with no net lift, destabilising (positive);
    ``apparent_mass_factor`` is k₂ − k₁ of the body's fineness ratio."""
    return 2.0 * apparent_mass_factor * volume_m3 / (reference_area_m2 * cbar_m)


def prolate_spheroid_apparent_mass_factor(fineness_ratio: float) -> float:
    """k₂ − k₁ of a prolate spheroid of length/diameter ``fineness_ratio`` (Lamb,
    *Hydrodynamics*, §373: the axial and transverse apparent-mass coefficients)."""
    if fineness_ratio <= 1.0:
        raise ValueError("fineness ratio of a prolate spheroid must exceed 1")
    e = math.sqrt(1.0 - 1.0 / fineness_ratio**2)
    log_term = math.log((1.0 + e) / (1.0 - e))
    alpha0 = 2.0 * (1.0 - e * e) / e**3 * (0.5 * log_term - e)
    beta0 = 1.0 / e**2 - (1.0 - e * e) / (2.0 * e**3) * log_term
    k1 = alpha0 / (2.0 - alpha0)
    k2 = beta0 / (2.0 - beta0)
    return k2 - k1
