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
    """Straight inner panel and swept-back outer panel of constant chord.

    Attributes:
        semispan_m: b/2 [m].
        chord_m: constant chord [m].
        outer_panel_start_m: spanwise station where the outer panel starts [m].
        outer_sweep_rad: leading-edge sweep of the outer panel, positive swept back [rad].
        x_cg_m: centre-of-gravity position aft of the root leading edge [m] (wing frame).
    """

    semispan_m: float
    chord_m: float
    outer_panel_start_m: float
    outer_sweep_rad: float
    x_cg_m: float

    def chord_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Local chord c(y) [m] at spanwise stations ``y_m`` (|y| ≤ b/2)."""
        y = np.abs(np.asarray(y_m, dtype=float))
        return np.full_like(y, self.chord_m)

    def leading_edge_x_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Leading-edge position x_le(y) aft of the root leading edge [m]."""
        y = np.abs(np.asarray(y_m, dtype=float))
        return np.maximum(y - self.outer_panel_start_m, 0.0) * math.tan(self.outer_sweep_rad)

    @property
    def area_m2(self) -> float:
        """Planform area of both halves [m²]."""
        return 2.0 * self.semispan_m * self.chord_m

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
