"""The rigid wing's roll damping C_lp and aileron power C_lδa from the vortex lattice.

Both are antisymmetric loadings of the lattice (:mod:`bioflex_jsb.aerodynamics.vortex_lattice`,
"Symmetry": the port half the mirror image with the opposite sign):

* C_lp: α(y) = p y/V on the starboard half (``SpanwiseAerodynamics.roll_damping_clp``), per
  p̂ = p b/(2V), on S b;
* C_lδa: the aileron as an angle of attack τ δ on the strips it covers (χ_k of each strip's
  width, :func:`~bioflex_jsb.aeroelasticity.control_surface.strip_coverage`), τ = c_lδ/2π the
  thin-aerofoil flap effectiveness of its hinge (Glauert 1927; the project's section,
  :mod:`~bioflex_jsb.aeroelasticity.control_surface`), the lattice's own induced flow
  then acting on that loading. Per radian of ``aileron`` in JSBSim's sense: ½ (left −
  right) surface angle, positive left trailing edge down, starboard up: a roll to the right
  (positive). The surface's chordwise load (aft of the quarter chord) and its interaction
  with the lattice's chordwise panels are left out: the lift is the section's.

The strip-theory closed form (:func:`strip_theory_clp`) is the second check: on a straight
tapered wing, c(y) = c_r [1 − (1 − λ) 2y/b], each strip lifting a (p y/V) without induced
flow, L = −2 ∫_0^{b/2} q a c (p y/V) y dy, hence
C_lp = −(4 a/(S b²)) ∫_0^{b/2} c y² dy = −(a/12)(1 + 3λ)/(1 + λ) (−a/6 rectangular): the
classical estimate (with a the wing's C_Lα: e.g. R. C. Nelson, *Flight Stability and
Automatic Control*, 2nd ed., Ch. 5's roll-damping estimate), which the lattice approaches
as the aspect ratio grows (tests/test_roll_derivatives.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aerodynamics.vortex_lattice import (
    DEFAULT_N_CHORDWISE,
    DEFAULT_N_SPANWISE,
    solve_spanwise_aerodynamics,
)
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    flap_lift_slope_per_rad,
    strip_coverage,
)


@dataclass(frozen=True)
class RollDerivatives:
    """``cl_p`` C_lp [per rad of p̂ = p b/(2V)], ``cl_delta_a`` C_lδa [per rad of aileron,
    JSBSim's sense], ``cl_alpha`` the wing's C_Lα [1/rad] (symmetric loading), on
    ``area_m2`` S and ``span_m`` b."""

    cl_p: float
    cl_delta_a: float
    cl_alpha: float
    area_m2: float
    span_m: float


def lattice_roll_derivatives(planform, aileron: ControlSurface, *,
                             n_spanwise: int = DEFAULT_N_SPANWISE,
                             n_chordwise: int = DEFAULT_N_CHORDWISE) -> RollDerivatives:
    """:class:`RollDerivatives` of ``planform`` (a lattice planform: put a break on each of
    the aileron's ends for whole strips) with ``aileron`` on both halves (module
    docstring)."""
    aero = solve_spanwise_aerodynamics(planform, n_spanwise=n_spanwise,
                                       n_chordwise=n_chordwise)
    tau = flap_lift_slope_per_rad(aileron.hinge) / TWO_PI
    chi = strip_coverage(aero.weights_m, aileron)
    y, w = aero.stations_m, aero.weights_m
    # starboard trailing edge up: α = −τ δ where covered; L = −2 ∫ y l' dy
    lift = aero.influence_antisymmetric_m @ (-tau * chi)
    rolling = -2.0 * float(np.sum(w * y * lift))
    s, b = aero.reference_area_m2, aero.span_m
    return RollDerivatives(aero.roll_damping_clp(), rolling / (s * b),
                           aero.wing_lift_slope_per_rad, s, b)


def strip_theory_clp(lift_slope_per_rad: float, taper_ratio: float) -> float:
    """The strip-theory closed form C_lp = −(a/12)(1 + 3λ)/(1 + λ) [per rad of p̂] of a
    straight tapered wing (module docstring), ``lift_slope_per_rad`` a, ``taper_ratio``
    λ = c_tip/c_root."""
    lam = float(taper_ratio)
    return -float(lift_slope_per_rad) / 12.0 * (1.0 + 3.0 * lam) / (1.0 + lam)
