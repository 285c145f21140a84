"""Planform of the membrane wing (not printed in the paper: a documented estimate).

Frame (``docs/conventions.md``): wing geometry is given in the *wing frame*: origin at the
leading edge of the root chord, ``x`` positive **aft** along the root chord [m], ``y``
positive to starboard [m]. Only the starboard half is described; the wing is symmetric.

DECISION (docs/decisions.md, "Planform"): b·c̄ = S exactly (Table 1, with S = b·c̄) is only
possible for a constant-chord wing (the mean aerodynamic chord equals the mean geometric
chord only then). We therefore use a constant chord c̄ = 0.183 m. Birds' wings (and the
prototype's, Fig. 1) are swept back over the outer "hand" part; we model that as an outer
panel whose leading edge is swept back from ``outer_panel_start_m`` to the tip. The sweep
leaves S, b, c̄ and AR unchanged, and it moves the aerodynamic centre of the outer wing aft
of the centre of gravity, which is what Table B1's (x_E + e)(y) integrals see.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.parameters import prototype as P


@dataclass(frozen=True)
class Planform:
    """The half wing's planform: a straight inner panel and a swept-back outer panel of
    constant chord (the prototype's), or, with ``stations_m`` given
    (:meth:`from_stations`), any wing whose chord, leading edge and height vary linearly
    between span stations (a straight-tapered wing, a multi-panel wing, dihedral).

    Attributes:
        semispan_m: b/2 [m].
        chord_m: the constant chord [m]; for a station planform its mean geometric chord
            S/b [m] (the length that makes a chord fraction of a uniform shift a length:
            ``WingBuild.e_shift_frac``).
        outer_panel_start_m: spanwise station where the swept outer panel starts [m] (a
            station planform: the semispan, unused).
        outer_sweep_rad: leading-edge sweep of the outer panel, positive swept back [rad]
            (a station planform: 0, unused).
        x_cg_m: centre-of-gravity position aft of the root leading edge [m] (wing frame).
        stations_m: span stations y [m], 0 … b/2 strictly increasing, or ``None`` (the
            constant-chord form above).
        chords_m: the chord c [m] at each station (linear between).
        leading_edges_x_m: the leading edge x [m] aft of the root's at each station.
        heights_m: the leading edge's height z [m] above the root's (positive up) at each
            station: dihedral, tan Γ = Δz/Δy per panel.
    """

    semispan_m: float
    chord_m: float
    outer_panel_start_m: float
    outer_sweep_rad: float
    x_cg_m: float
    stations_m: tuple[float, ...] | None = None
    chords_m: tuple[float, ...] | None = None
    leading_edges_x_m: tuple[float, ...] | None = None
    heights_m: tuple[float, ...] | None = None

    @classmethod
    def from_stations(cls, stations_m, chords_m, leading_edges_x_m, heights_m,
                      x_cg_m: float) -> Planform:
        """A planform linear between span stations (class docstring); ValueError if the
        stations do not start at the root and increase, a chord is not positive, or the
        root's leading edge is not the origin (x = z = 0)."""
        y = tuple(float(v) for v in stations_m)
        c = tuple(float(v) for v in chords_m)
        x = tuple(float(v) for v in leading_edges_x_m)
        z = tuple(float(v) for v in heights_m)
        if len(y) < 2 or not len(y) == len(c) == len(x) == len(z):
            raise ValueError("a planform needs >= 2 stations, each with a chord, leading "
                             "edge and height")
        if y[0] != 0.0 or any(b <= a for a, b in zip(y, y[1:], strict=False)):
            raise ValueError(f"planform stations must start at 0 and increase, got {y}")
        if any(not v > 0.0 for v in c) or not all(math.isfinite(v) for v in y + c + x + z):
            raise ValueError("planform chords must be positive and every value finite")
        if x[0] != 0.0 or z[0] != 0.0:
            raise ValueError("the root leading edge is the wing frame's origin (x = z = 0)")
        area_half = sum(0.5 * (c[i] + c[i + 1]) * (y[i + 1] - y[i]) for i in range(len(y) - 1))
        return cls(semispan_m=y[-1], chord_m=area_half / y[-1], outer_panel_start_m=y[-1],
                   outer_sweep_rad=0.0, x_cg_m=float(x_cg_m), stations_m=y, chords_m=c,
                   leading_edges_x_m=x, heights_m=z)

    def chord_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Local chord c(y) [m] at spanwise stations ``y_m`` (|y| ≤ b/2)."""
        y = np.abs(np.asarray(y_m, dtype=float))
        if self.stations_m is None:
            return np.full_like(y, self.chord_m)
        return np.interp(y, self.stations_m, self.chords_m)

    def leading_edge_x_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Leading-edge position x_le(y) aft of the root leading edge [m]."""
        y = np.abs(np.asarray(y_m, dtype=float))
        if self.stations_m is None:
            return np.maximum(y - self.outer_panel_start_m, 0.0) * math.tan(self.outer_sweep_rad)
        return np.interp(y, self.stations_m, self.leading_edges_x_m)

    def height_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Leading-edge height z(y) above the root's [m] (positive up; the same on both
        halves: dihedral)."""
        y = np.abs(np.asarray(y_m, dtype=float))
        if self.stations_m is None:
            return np.zeros_like(y)
        return np.interp(y, self.stations_m, self.heights_m)

    @property
    def has_dihedral(self) -> bool:
        """True when any station's leading edge is off the root's plane (z ≠ 0)."""
        return self.heights_m is not None and any(z != 0.0 for z in self.heights_m)

    @property
    def breaks_m(self) -> tuple[float, ...]:
        """Span stations [m] strictly inside the half wing where the planform kinks (the
        slope of the chord, the leading edge or the height changes): the vortex lattice
        puts a strip edge on each so that every panel edge is straight. The constant-chord
        form: its outer panel's start."""
        if self.stations_m is None:
            return (self.outer_panel_start_m,)
        y = np.array(self.stations_m)
        out = []
        for i in range(1, y.size - 1):
            for v in (self.chords_m, self.leading_edges_x_m, self.heights_m):
                left = (v[i] - v[i - 1]) / (y[i] - y[i - 1])
                right = (v[i + 1] - v[i]) / (y[i + 1] - y[i])
                # a slope change above 1e-9 (the rounding of a file's numbers) is a kink
                if abs(right - left) > 1e-9 * max(1.0, abs(left), abs(right)):
                    out.append(float(y[i]))
                    break
        return tuple(out)

    @property
    def area_m2(self) -> float:
        """Planform area of both halves [m²] (projected on the wing's plane: the
        chords times the spanwise widths)."""
        if self.stations_m is None:
            return 2.0 * self.semispan_m * self.chord_m
        y, c = self.stations_m, self.chords_m
        return sum((c[i] + c[i + 1]) * (y[i + 1] - y[i]) for i in range(len(y) - 1))

    @property
    def span_m(self) -> float:
        return 2.0 * self.semispan_m


# ESTIMATE: the inner 45 % of the half span is the straight "arm wing"; the outer panel is
# swept back 20° at the leading edge. CG at 0.30 c̄ aft of the root leading edge, just behind
# the inner wing's quarter chord. These three numbers are the planform assumptions the elastic
# coupling results depend on most; docs/decisions.md lists their effect.
DEFAULT_PLANFORM = Planform(
    semispan_m=P.SPAN_M / 2.0,
    chord_m=P.MEAN_AERODYNAMIC_CHORD_M,
    outer_panel_start_m=0.45 * P.SPAN_M / 2.0,
    outer_sweep_rad=math.radians(20.0),
    x_cg_m=0.30 * P.MEAN_AERODYNAMIC_CHORD_M,
)

# ESTIMATE (docs/decisions.md, "Structural damping"): the paper neglects structural damping
# (Section 3.1, "much lower than the aerodynamic damping"), but the quasi-steady strip
# aerodynamics of Eq. (3) give a pure twist mode no aerodynamic damping at all (there is no
# pitch-rate term for the section). Undamped, the first mode is then pushed unstable at any
# airspeed by arbitrarily weak coupling with the rigid-body plunge. We give every mode the
# 2 % of critical damping typical of cured carbon-fibre laminates (1–3 %); it moves the
# short-period roots of Tables 3 and 6 by less than 0.01 rad/s.
MODAL_DAMPING_RATIO = 0.02

# The published C_η1^Q1 [-] of the paper's six named variants (Table 8; parameters/
# prototype.py PUBLISHED_VARIANTS, the paper's data): what a named variant pins.
PUBLISHED_C_ETA1_Q1 = {name: v.c_eta1_q1 for name, v in P.PUBLISHED_VARIANTS.items()}
