"""The aircraft definition as data: the objects a definition file loads into.

A definition has a wing (planform by span stations, :class:`WingStation`), its structure
(:class:`BeamStructure`: sections per station), the aerodynamic settings
(:class:`AeroSettings`), the air (:class:`Air`) and the analysis settings
(:class:`AnalysisSettings`), and optionally the wing's aileron
(:class:`~bioflex_jsb.aeroelasticity.control_surface.ControlSurface`). ``airframe``
(:class:`AirframeDefinition`: the JSBSim aircraft, reference geometry, mass properties, the wing's
attachment, the rigid derivatives) is ``None`` for a clamped wing: "a clamped wing is the
same definition without an airframe".
The wing on an airframe has one more structure kind than a clamped wing
(:class:`MembraneStructure`: the prototype's calibrated membrane; :class:`ModalStructure`: a
modal file) and its flight-dynamics settings (:class:`FlyingWing`).

SI throughout; frames: y [m] along the span from the clamped root (or the aircraft's plane
of symmetry) to the tip; x [m] aft, from the root leading edge; chord positions are
fractions of the local chord aft of its leading edge; twist [rad] positive leading edge up.
Airframe positions are in the JSBSim aircraft's structural frame, in metres: x aft, y to
starboard, z up, from that aircraft's own origin (the generated prototype's: the fuselage
nose, parameters/airframe.py AirframeGeometry).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aeroelasticity.control_surface import ControlSurface, SurfaceActuator
from bioflex_jsb.parameters.airframe import DerivativeSchedule
from bioflex_jsb.structures.beam import PointMass, VerticalSpring

# The section loads' monitoring stations when a definition names none: root, 25, 50, 75 %
# of the semispan; the loads' default (loads/model.py) is this one.
DEFAULT_MONITORING_STATIONS = (0.0, 0.25, 0.5, 0.75)


@dataclass(frozen=True)
class WingStation:
    """One span station of the wing (linear in between).

    ``y_m`` [m] from the root; ``chord_m`` [m]; ``leading_edge_x_m`` [m] aft of the root
    leading edge; ``twist_rad`` [rad] (LE up); ``elastic_axis`` and ``centre_of_mass``:
    chord fractions aft of the leading edge [-]; ``z_m`` [m] the leading edge's height above
    the root's (positive up: dihedral)."""

    y_m: float
    chord_m: float
    leading_edge_x_m: float
    twist_rad: float
    elastic_axis: float
    centre_of_mass: float
    z_m: float = 0.0


@dataclass(frozen=True)
class BeamStructure:
    """Beam sections at the wing's stations (arrays aligned with them).

    ``bending_stiffness_n_m2`` EI [N·m²], ``torsional_stiffness_n_m2`` GJ [N·m²],
    ``mass_per_length_kg_m`` m' [kg/m], ``pitch_inertia_kg_m`` I_α' [kg·m] about
    ``inertia_axis`` (``elastic-axis`` or ``centre-of-mass``), ``damping_ratio`` ζ [-] of
    every mode (viscous, 2ζω), ``n_modes`` and ``n_elements`` of the finite-element
    solution; ``point_masses`` (fuel, engines, pods, tip masses) and ``struts`` (a braced
    wing's strut as a vertical spring at its attachment) on the beam."""

    bending_stiffness_n_m2: np.ndarray
    torsional_stiffness_n_m2: np.ndarray
    mass_per_length_kg_m: np.ndarray
    pitch_inertia_kg_m: np.ndarray
    inertia_axis: str
    damping_ratio: float
    n_modes: int
    n_elements: int
    point_masses: tuple[PointMass, ...] = ()
    struts: tuple[VerticalSpring, ...] = ()


@dataclass(frozen=True)
class MembraneStructure:
    """The prototype's membrane half wing as calibrated to Table 2 (ribbed or not:
    parameters/wing_structure.py, the beam of structures/wing_model.py); ``damping_ratio`` ζ
    [-] of every mode; ``n_modes`` flown (3: Table 2's)."""

    ribs: bool
    damping_ratio: float
    n_modes: int


@dataclass(frozen=True)
class ModalStructure:
    """A modal file (docs/structures.md: shapes, frequencies, generalised masses, axes):
    ``modes_file`` (absolute path), ``damping_ratio`` ζ [-] (the larger of it and each mode's
    own), ``n_modes`` flown."""

    modes_file: str
    damping_ratio: float
    n_modes: int


@dataclass(frozen=True)
class FlyingWing:
    """The elastic wing's settings on an airframe: ``name`` (the wing's name in reports and
    logs), ``pin_c_eta1_q1`` (C_η1^Q1 [-] pinned by a uniform shift of the aerodynamic
    offset, as the paper did, or ``None``: the strip model's own value),
    ``published_c_eta1_q1`` (the published value it is compared with, or ``None``)."""

    name: str
    pin_c_eta1_q1: float | None
    published_c_eta1_q1: float | None


@dataclass(frozen=True)
class Inertia:
    """Inertia about the centre of gravity in body axes [kg·m²] (x forward, y starboard, z
    down; ``ixz_kg_m2`` the product of inertia, JSBSim's sign: positive for a nose-down
    principal axis)."""

    ixx_kg_m2: float
    iyy_kg_m2: float
    izz_kg_m2: float
    ixz_kg_m2: float


@dataclass(frozen=True)
class AirframeDefinition:
    """The rigid aircraft the elastic wing is attached to.

    ``jsbsim``: ``bioflex`` (the generated prototype), or the name of an aircraft in the
    jsbsim package's ``aircraft/`` directory, or a directory holding ``<dir name>.xml``;
    ``jsbsim_path``: the aircraft file found (empty for ``bioflex``: it is generated).
    Reference geometry: ``reference_area_m2`` S [m²], ``span_m`` b [m], ``mean_chord_m`` c̄
    [m]. ``mass_kg`` [kg], ``cg_m`` (x, y, z) [m] and ``wing_root_leading_edge_m`` (x, y, z)
    [m] in the structural frame (module docstring), ``inertia`` (:class:`Inertia`).
    ``derivatives``: the rigid aerodynamic derivatives of
    :class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics` by field name [per rad,
    non-dimensional, moments about the CG], or ``None``: identified from the JSBSim
    aircraft (``schedule``). ``cruise_speed_m_s`` [m/s] (the flight commands' default
    speed) and ``speed_range_m_s`` (low, high) [m/s] (the speeds they accept).

    A field the file leaves out is ``None`` until the aircraft is completed from its JSBSim
    model (``runtime.jsbsim_aircraft.complete``: mass, CG and inertia with its point masses
    and fuel, S, b, c̄, the wing's attachment estimated from the aerodynamic reference
    point, the speeds from its trims, the derivatives identified at several speeds);
    ``from_jsbsim`` names the fields it gave, and ``checked`` is True once the file's own
    numbers were compared with the JSBSim aircraft's (or it is the generated prototype)."""

    jsbsim: str
    jsbsim_path: str
    reference_area_m2: float | None
    span_m: float | None
    mean_chord_m: float | None
    mass_kg: float | None
    cg_m: tuple[float, float, float] | None
    inertia: Inertia | None
    wing_root_leading_edge_m: tuple[float, float, float] | None
    derivatives: dict[str, float] | None
    cruise_speed_m_s: float | None = None
    speed_range_m_s: tuple[float, float] | None = None
    schedule: DerivativeSchedule | None = None
    from_jsbsim: tuple[str, ...] = ()
    checked: bool = False

    @property
    def wing_cg_x_m(self) -> float:
        """The CG aft of the wing's root leading edge [m] (the wing frame's x_cg)."""
        return self.cg_m[0] - self.wing_root_leading_edge_m[0]

    def missing(self) -> tuple[str, ...]:
        """The fields still to be taken from the JSBSim aircraft (class docstring)."""
        out = tuple(f for f in ("reference_area_m2", "span_m", "mean_chord_m", "mass_kg",
                                "cg_m", "inertia", "wing_root_leading_edge_m",
                                "cruise_speed_m_s", "speed_range_m_s")
                    if getattr(self, f) is None)
        if self.derivatives is None and self.schedule is None:
            out += ("derivatives",)
        return out


@dataclass(frozen=True)
class JSBSimValues:
    """What a JSBSim aircraft's own model gives (``runtime.jsbsim_aircraft``), in SI and
    the structural frame: S [m²], b [m], c̄ [m] (its ``<metrics>``); mass [kg], CG (x, y, z)
    [m] and inertia about the CG (its empty weight with its point masses and fuel, as it
    flies); ``aero_reference_point_m`` (x, y, z) [m] (AERORP); the speeds [m/s] from its
    trims (``stall_speed_m_s`` level flight at C_L,max; ``cruise_speed_m_s``;
    ``speed_range_m_s``) or None when not asked for; the identified derivatives
    (``schedule``) or None; ``source`` (the file, the altitude [m])."""

    reference_area_m2: float
    span_m: float
    mean_chord_m: float
    mass_kg: float
    cg_m: tuple[float, float, float]
    inertia: Inertia
    aero_reference_point_m: tuple[float, float, float]
    source: str
    stall_speed_m_s: float | None = None
    cruise_speed_m_s: float | None = None
    speed_range_m_s: tuple[float, float] | None = None
    schedule: DerivativeSchedule | None = None


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
    structure: BeamStructure | MembraneStructure | ModalStructure
    aero: AeroSettings
    air: Air
    analysis: AnalysisSettings
    airframe: AirframeDefinition | None = None
    path: str = ""
    flying: FlyingWing | None = None  # with an airframe
    # [loads] stations: the monitoring stations of the wing's section loads, fractions of
    # the semispan from the root [-], sorted, distinct, each 0 <= s < 1 (the tip carries no
    # load); default DEFAULT_MONITORING_STATIONS.
    monitoring_stations: tuple[float, ...] = DEFAULT_MONITORING_STATIONS
    # [sensors]: the IMUs and airspeed probes as the file places them
    # (definition/sensors.py SensorStation; Aircraft.sensors() in body axes from the CG)
    sensor_stations: tuple = ()
    # [aileron]: the wing's aileron (span range in metres, hinge line), or None: no surface
    aileron: ControlSurface | None = None
    # [aileron.actuator]: its second-order actuator, or None: the aileron is at its command
    aileron_actuator: SurfaceActuator | None = None

    @property
    def clamped(self) -> bool:
        return self.airframe is None

    @property
    def semispan_m(self) -> float:
        return float(self.stations[-1].y_m)

    def column(self, name: str) -> np.ndarray:
        """The station attribute ``name`` as an array over the stations."""
        return np.array([getattr(s, name) for s in self.stations], dtype=float)
