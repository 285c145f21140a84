"""A second rigid-airframe parameter set: one aircraft whose rigid derivatives follow from a
stated tail, fuselage and centre of gravity. NOT the default.

The default set (:mod:`bioflex_jsb.parameters.airframe`) calibrates C_mα, C_mq and C_mα̇
to Table 3's rigid short period with C_Lα = 5.3 /rad and the CG at 0.30 c̄: those values do
not come from one geometry (docs/consistent_aircraft.md). Here the geometry is stated and
the derivatives are what the wing + tail vortex lattice
(:mod:`bioflex_jsb.aerodynamics.wing_tail`), the downwash lag and Munk's fuselage moment give
for it; only the CG is calibrated (to Table 3's rigid short-period frequency at 15 m/s).

Every number below is ``PAPER`` (Table 1), ``ESTIMATE`` (its source named), ``COMPUTED``
(by ``bioflex_jsb.flight_dynamics.consistent_aircraft.consistent_derivatives`` from the
geometry; ``tests/test_consistent_aircraft.py`` recomputes each and holds it to 0.1 %) or
``CALIBRATED`` (what it was calibrated to named). Frames: wing frame (x aft of the wing's
root leading edge, m), docs/conventions.md.

Use: ``build_wing(variant, planform=PLANFORM)`` for the Table B1 arms about this CG, and
``RIGID_AERODYNAMICS`` wherever an ``aero=`` is taken (lti, rigid, modal_matrices,
elastic_trim); ``python scripts/consistent_aircraft.py`` shows both sets side by side.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.parameters import airframe as default
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM

SOURCE = "geometry-consistent set (docs/consistent_aircraft.md); derivatives by wing+tail VLM"


@dataclass(frozen=True)
class TailGeometry:
    """Rectangular, unswept horizontal tail; the lattice's planform (``PlanformLike``).

    semispan_m, chord_m [m]; leading_edge_x_m: aft of the wing's root leading edge [m];
    height_m: above the wing plane [m]; efficiency η_t: dynamic-pressure ratio at the tail
    [-]; elevator_chord_fraction: plain elevator, aft fraction of the tail chord [-].
    """

    semispan_m: float
    chord_m: float
    leading_edge_x_m: float
    height_m: float
    efficiency: float
    elevator_chord_fraction: float

    def chord_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Chord c_t(y) [m] (constant)."""
        return np.full_like(np.abs(np.asarray(y_m, dtype=float)), self.chord_m)

    def leading_edge_x_at(self, y_m: np.ndarray | float) -> np.ndarray:
        """Leading-edge x(y) [m aft of the wing's root leading edge] (unswept)."""
        return np.full_like(np.abs(np.asarray(y_m, dtype=float)), self.leading_edge_x_m)

    @property
    def area_m2(self) -> float:
        """S_t of both halves [m²]."""
        return 2.0 * self.semispan_m * self.chord_m

    @property
    def aspect_ratio(self) -> float:
        return (2.0 * self.semispan_m) ** 2 / self.area_m2


TAIL = TailGeometry(
    # ESTIMATE: the tail the default elevator derivatives imply. C_mδe/C_Lδe = −l_t/c̄ =
    # −0.9/0.35 puts its aerodynamic centre ≈ 0.47 m behind the CG, and S_t/S ≈ 0.15 for a
    # tail volume of 0.4 (airframe.py: C_mδe = −V_H a_t τ). 0.40 m × 0.12 m (AR 3.3, 0.048 m²).
    semispan_m=0.20,
    chord_m=0.12,
    # ESTIMATE: on the fuselage's tail cone (Section 2, "short distance between CG and the
    # tails"): leading edge at 0.80 m of the 0.85 m fuselage (Table 1), wing root leading edge
    # at 0.30 m (airframe.AIRFRAME_GEOMETRY), trailing edge 7 cm behind the pointed tail end.
    leading_edge_x_m=0.50,
    # ESTIMATE: tail on the fuselage axis, wing on top of the fusiform fuselage: 3 cm between
    # the planes (the downwash gradient changes by < 4 % between 0 and 6 cm, docs).
    height_m=0.03,
    # ESTIMATE: η_t = 0.9, the usual dynamic-pressure ratio of a fuselage-mounted tail
    # behind a wing (Etkin & Reid, Dynamics of Flight, §2.4; Raymer, Aircraft Design, §16.3).
    efficiency=0.9,
    # ESTIMATE: 30 % chord plain elevator (thin-aerofoil effectiveness τ ≈ 0.66, Glauert).
    elevator_chord_fraction=0.30,
)


@dataclass(frozen=True)
class FuselageGeometry:
    """The fusiform fuselage as a prolate spheroid (Section 2: "bigger diameter in the middle
    and two pointy ends"): length and maximum diameter [m]."""

    length_m: float
    max_diameter_m: float

    @property
    def volume_m3(self) -> float:
        """π/6 · L · d² [m³]."""
        return float(np.pi / 6.0 * self.length_m * self.max_diameter_m**2)

    @property
    def fineness_ratio(self) -> float:
        return self.length_m / self.max_diameter_m


FUSELAGE = FuselageGeometry(
    length_m=P.FUSELAGE_LENGTH_M,  # PAPER, Table 1
    max_diameter_m=0.08,  # ESTIMATE: Fig. 1, a 2.5 kg canister-launched UAV's battery bay
)

# CALIBRATED: the centre of gravity, the one free geometric quantity (the paper states none).
# Chosen so that the rigid short period's natural frequency at 15 m/s is Table 3's
# |−5.6 ± 9.0i| = 10.60 rad/s (consistent_aircraft.calibrate_cg_fraction, bisection to 1e-6).
# Its damping then follows from the geometry: −5.45 ± 9.09i (Table 3 −5.6 ± 9.0i: −2.7 %,
# +1.0 %) and −7.24 ± 12.12i at 20 m/s (−7.4 ± 12.0i: −2.1 %, +1.0 %).
CG_FRACTION_OF_CHORD = 0.37278  # aft of the root leading edge, fraction of c̄ [-]
CG_X_M = CG_FRACTION_OF_CHORD * P.MEAN_AERODYNAMIC_CHORD_M  # wing frame [m]

# The wing planform with this CG: Table B1's arms d(y) = x_cg − x_ac(y) follow it.
PLANFORM = replace(DEFAULT_PLANFORM, x_cg_m=CG_X_M)

# COMPUTED (consistent_aircraft.consistent_derivatives at CG_FRACTION_OF_CHORD; docs table):
# wing + tail lattice (40 × 4 wing panels, 16 × 10 tail), tail loads × η_t, plus Munk's
# fuselage moment (+0.0945 /rad) in C_mα. C_Lq = 8.2 and C_Lα̇ = 0.72 /rad are computed too
# but dropped, as the paper's A_RR drops them (Z_q = 0, docs/decisions.md).
RIGID_AERODYNAMICS = replace(
    default.RIGID_AERODYNAMICS,
    cl_alpha_per_rad=5.0240,  # COMPUTED: wing 4.712 + tail 0.312 in combination
    cm_alpha_per_rad=-1.0428,  # COMPUTED: static margin 0.208 c̄ (lattice −1.137, fuselage +0.095)
    cm_q_per_rad=-8.0083,  # COMPUTED: wing −1.584, tail −6.424
    cm_alphadot_per_rad=-1.8158,  # COMPUTED: downwash lag, dε/dα = 0.323, l_t = 0.459 m
    cl_delta_e_per_rad=0.34842,  # COMPUTED: 30 % elevator on the tail, × η_t
    cm_delta_e_per_rad=-0.83348,  # COMPUTED
    # CALIBRATED: the tail incidence is set so that the linear rigid trim at 15 m/s needs
    # the default set's elevator (+1.10°): C_m0 = −(C_mα α_r + C_mδe δe_r) there.
    cm0=0.050289,
)

# The JSBSim airframe's geometry with this CG (for a generator that takes a parameter set;
# the default aircraft files are not regenerated from it).
AIRFRAME_GEOMETRY = replace(
    default.AIRFRAME_GEOMETRY,
    cg_x_m=default.AIRFRAME_GEOMETRY.wing_root_leading_edge_x_m + CG_X_M,
)
MASS_PROPERTIES = default.MASS_PROPERTIES  # PAPER (m, I_y: Table 1) and the default estimates
