"""The aircraft definition as data: the objects a definition file loads into.

A definition has a wing (planform by span stations, :class:`WingStation`), its structure
(:class:`BeamStructure`: sections per station), the aerodynamic settings
(:class:`AeroSettings`), the air (:class:`Air`) and the analysis settings
(:class:`AnalysisSettings`). ``airframe`` is ``None`` for a clamped wing: "a clamped wing is
the same definition without an airframe"; the airframe part (a JSBSim aircraft, reference
geometry, mass properties) is the next step of the format and is refused until then.

SI throughout; frames: y [m] along the span from the clamped root (or the aircraft's plane
of symmetry) to the tip; x [m] aft, from the root leading edge; chord positions are
fractions of the local chord aft of its leading edge; twist [rad] positive leading edge up.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class WingStation:
    """One span station of the wing (linear in between).

    ``y_m`` [m] from the root; ``chord_m`` [m]; ``leading_edge_x_m`` [m] aft of the root
    leading edge; ``twist_rad`` [rad] (LE up); ``elastic_axis`` and ``centre_of_mass``:
    chord fractions aft of the leading edge [-]."""

    y_m: float
    chord_m: float
    leading_edge_x_m: float
    twist_rad: float
    elastic_axis: float
    centre_of_mass: float


@dataclass(frozen=True)
class BeamStructure:
    """Beam sections at the wing's stations (arrays aligned with them).

    ``bending_stiffness_n_m2`` EI [N·m²], ``torsional_stiffness_n_m2`` GJ [N·m²],
    ``mass_per_length_kg_m`` m' [kg/m], ``pitch_inertia_kg_m`` I_α' [kg·m] about
    ``inertia_axis`` (``elastic-axis`` or ``centre-of-mass``), ``damping_ratio`` ζ [-] of
    every mode (viscous, 2ζω), ``n_modes`` and ``n_elements`` of the finite-element
    solution."""

    bending_stiffness_n_m2: np.ndarray
    torsional_stiffness_n_m2: np.ndarray
    mass_per_length_kg_m: np.ndarray
    pitch_inertia_kg_m: np.ndarray
    inertia_axis: str
    damping_ratio: float
    n_modes: int
    n_elements: int


@dataclass(frozen=True)
class AeroSettings:
    """``model`` (``unsteady``: Theodorsen / Jones; ``quasi-steady``: C = 1),
    ``lift_slope`` (``strip``: ``section_lift_slope_per_rad`` on every strip; ``vlm``: the
    vortex lattice's spanwise loading), ``strips`` (Gauss-Legendre strips, ``strip``)."""

    model: str
    lift_slope: str
    section_lift_slope_per_rad: float
    strips: int


@dataclass(frozen=True)
class Air:
    """``density_kg_m3`` ρ [kg/m³] of the flutter analysis."""

    density_kg_m3: float


@dataclass(frozen=True)
class AnalysisSettings:
    """``method`` (``pk`` or ``state-space``); ``speed_range_m_s`` [m/s] or ``None`` (the
    range derived from the wing: :func:`bioflex_jsb.definition.derived_speed_range_m_s`)."""

    method: str
    speed_range_m_s: tuple[float, float] | None


@dataclass(frozen=True)
class Definition:
    """An aircraft (or a clamped wing: ``airframe is None``) as data."""

    name: str
    description: str
    source: str
    stations: tuple[WingStation, ...]
    structure: BeamStructure
    aero: AeroSettings
    air: Air
    analysis: AnalysisSettings
    airframe: None = None
    path: str = ""

    @property
    def clamped(self) -> bool:
        return self.airframe is None

    @property
    def semispan_m(self) -> float:
        return float(self.stations[-1].y_m)

    def column(self, name: str) -> np.ndarray:
        """The station attribute ``name`` as an array over the stations."""
        return np.array([getattr(s, name) for s in self.stations], dtype=float)
