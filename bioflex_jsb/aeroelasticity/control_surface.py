"""A trailing-edge control surface (aileron, flap) on a strip wing: its section
coefficients and its loads on the strips and the modes.

**Section (thin aerofoil, steady).** A plain flap hinged at ``hinge`` chord fractions aft of
the leading edge (flap chord ratio E = 1 − hinge), deflected δ [rad] trailing edge down.
With Glauert's angle θ_h of the hinge, cos θ_h = 1 − 2·hinge = 2E − 1:

    c_lδ  = 2 (π − θ_h + sin θ_h)                  [1/rad], lift per unit deflection
    c_mδ  = −½ sin θ_h (1 − cos θ_h)               [1/rad], about the quarter chord, nose up +

Sources: H. Glauert, "Theoretical relationships for an aerofoil with hinged flap", ARC R&M
1095 (1927); E. L. Houghton, P. W. Carpenter, *Aerodynamics for Engineering Students*,
§4.5, Eq. (4.52) (cos φ = 2F − 1); the same as the steady limit of Theodorsen's flap terms
(T. Theodorsen, NACA Report 496, 1935): with Theodorsen's hinge position c_T = 2·hinge − 1
[semichords aft of mid-chord], c_lδ = 2 T₁₀ and c_mδ,¼ = −(T₄ + T₁₀)/2, T₁₀ = √(1−c_T²) +
arccos c_T, T₄ = −arccos c_T + c_T √(1−c_T²) (tested against each other). A 25 %-chord flap
(hinge 0.75): c_lδ = 3.826 /rad (τ = c_lδ/2π = 0.609), c_mδ = −0.650 /rad.

A strip whose lift slope a₀ is not 2π (a real section's, or the vortex lattice's local
C_lα(y)) carries the flap lift in proportion, c_lδ a₀/2π (the thin-aerofoil flap
effectiveness τ = c_lδ/c_lα kept): the circulatory part. The quarter-chord moment keeps its
thin-aerofoil value: in Theodorsen's steady loads it is the non-circulatory term alone (the
circulatory lift acts at the quarter chord), as the apparent mass keeps its thin-plate
value in :mod:`bioflex_jsb.aerodynamics.theodorsen`.

**On a strip wing.** A surface spans ``start_m`` to ``end_m`` [m from the root] at one hinge
chord fraction. Strip k (width w_k, edges at the cumulative widths) carries the part
χ_k ∈ [0, 1] of its width that the surface covers: exactly 0 or 1 on strips whose edges
include the surface's ends (:func:`~bioflex_jsb.aeroelasticity.clamped_wing.clamped_wing_model`
with ``breaks_m``), a fraction otherwise (a lattice's strips).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# A flap hinge [chord fraction aft of the leading edge]: flap chords from 5 % (a trim tab)
# to 50 % (a split flap or a flaperon); thin-aerofoil theory has no limit, a wing does.
HINGE_RANGE = (0.5, 0.95)
SNAP = 1e-9  # coverage within this of 0 or 1 is 0 or 1 [-]


@dataclass(frozen=True)
class ControlSurface:
    """A trailing-edge surface on the half wing: ``start_m`` < ``end_m`` [m from the root,
    along y], hinge line at ``hinge`` [chord fraction aft of the leading edge, constant along
    the span], ``name`` (``aileron``, ``flap``) for reports. Deflection δ [rad] positive
    trailing edge down (more lift on this half wing)."""

    start_m: float
    end_m: float
    hinge: float
    name: str = "aileron"

    def __post_init__(self) -> None:
        if not (math.isfinite(self.start_m) and math.isfinite(self.end_m)
                and 0.0 <= self.start_m < self.end_m):
            raise ValueError(f"control surface span must satisfy 0 <= start < end [m], got "
                             f"{self.start_m!r}..{self.end_m!r}")
        if not HINGE_RANGE[0] <= self.hinge <= HINGE_RANGE[1]:
            raise ValueError(f"control surface hinge {self.hinge!r} is outside "
                             f"{HINGE_RANGE[0]:g}..{HINGE_RANGE[1]:g} chord fractions")

    @property
    def flap_chord_ratio(self) -> float:
        """E = 1 − hinge [-]: the surface's chord over the local chord."""
        return 1.0 - self.hinge

    def as_dict(self) -> dict:
        return {"name": self.name, "start_m": self.start_m, "end_m": self.end_m,
                "hinge_chord_fraction": self.hinge,
                "flap_chord_ratio": round(self.flap_chord_ratio, 12)}


@dataclass(frozen=True)
class SurfaceActuator:
    """A control surface's actuator as a second-order lag from the command δ_c to the
    surface angle δ [rad]: δ̈ = ω_n² (δ_c − δ) − 2 ζ ω_n δ̇, ``natural_frequency_rad_s`` ω_n
    [rad/s], ``damping_ratio`` ζ [-]; unit steady gain, no rate or travel limit (a linear
    model's). Its states δ, δ̇ carry the surface's rate and acceleration, which the flap's
    unsteady (apparent-mass) loads need."""

    natural_frequency_rad_s: float
    damping_ratio: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.natural_frequency_rad_s)
                and self.natural_frequency_rad_s > 0.0):
            raise ValueError(f"actuator natural frequency must be a positive number [rad/s], "
                             f"got {self.natural_frequency_rad_s!r}")
        if not (math.isfinite(self.damping_ratio) and self.damping_ratio > 0.0):
            raise ValueError(f"actuator damping ratio must be positive, got "
                             f"{self.damping_ratio!r}")

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """(A (2, 2), B (2, 1)) of the states (δ [rad], δ̇ [rad/s]) and the command [rad]."""
        w, z = float(self.natural_frequency_rad_s), float(self.damping_ratio)
        return (np.array([[0.0, 1.0], [-w * w, -2.0 * z * w]]), np.array([[0.0], [w * w]]))

    def as_dict(self) -> dict:
        return {"natural_frequency_rad_s": self.natural_frequency_rad_s,
                "damping_ratio": self.damping_ratio}


def hinge_angle_rad(hinge: float) -> float:
    """Glauert's θ_h [rad] of a hinge at ``hinge`` chord fractions: cos θ_h = 1 − 2·hinge."""
    return math.acos(1.0 - 2.0 * float(hinge))


def flap_lift_slope_per_rad(hinge: float) -> float:
    """Thin-aerofoil c_lδ = 2 (π − θ_h + sin θ_h) [1/rad] (module docstring)."""
    th = hinge_angle_rad(hinge)
    return 2.0 * (math.pi - th + math.sin(th))


def flap_moment_slope_per_rad(hinge: float) -> float:
    """Thin-aerofoil c_mδ about the quarter chord, −½ sin θ_h (1 − cos θ_h) [1/rad], nose up
    positive (negative: a trailing-edge-down flap pitches the section nose down)."""
    th = hinge_angle_rad(hinge)
    return -0.5 * math.sin(th) * (1.0 - math.cos(th))


def theodorsen_flap_slopes(hinge: float) -> tuple[float, float]:
    """(c_lδ, c_mδ about the quarter chord) [1/rad] from Theodorsen's (1935) T-functions in
    their steady limit: 2 T₁₀ and −(T₄ + T₁₀)/2 (an independent route to the same numbers)."""
    c = 2.0 * float(hinge) - 1.0
    root = math.sqrt(1.0 - c * c)
    t10 = root + math.acos(c)
    t4 = -math.acos(c) + c * root
    return 2.0 * t10, -0.5 * (t4 + t10)


def strip_coverage(weights_m: np.ndarray, surface: ControlSurface) -> np.ndarray:
    """χ_k [-]: the share of each strip's width that ``surface`` covers, the strips laid
    root to tip with widths ``weights_m`` [m] (edges at their cumulative sums)."""
    w = np.asarray(weights_m, dtype=float)
    edges = np.concatenate([[0.0], np.cumsum(w)])
    lo = np.maximum(edges[:-1], surface.start_m)
    hi = np.minimum(edges[1:], surface.end_m)
    chi = np.clip(hi - lo, 0.0, None) / w
    # the cumulative sums put a strip edge on a surface end to round-off: snap those strips
    # to wholly on or off
    return np.where(chi < SNAP, 0.0, np.where(chi > 1.0 - SNAP, 1.0, chi))
