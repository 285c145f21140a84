"""The geometry-consistent aircraft (parameters/airframe_consistent.py): its derivatives from
the stated geometry, the CG calibration, and the paper's tables with either parameter set.

* :func:`consistent_derivatives`: wing + tail vortex lattice at a CG, downwash lag, Munk's
  fuselage moment → a :class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics`;
* :func:`calibrate_cg_fraction`: the CG whose rigid short period at 15 m/s has Table 3's
  natural frequency (the one calibration);
* :class:`AircraftSet` and :data:`AIRCRAFT_SETS` (``default``, ``consistent``): a rigid
  parameter set with the planform carrying its CG;
* :func:`modes_with`, :func:`flutter_with`: :mod:`bioflex_jsb.flight_dynamics.eigen`'s
  labelling, tracking and flutter search with a set's ``aero`` (eigen itself always uses
  the default set; with an ``aero`` argument there, these two can go).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq

from bioflex_jsb.aerodynamics.wing_tail import (
    WingTailDerivatives,
    munk_moment_slope_per_rad,
    prolate_spheroid_apparent_mass_factor,
    wing_tail_derivatives,
)
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.elastic_trim import StaticWingLoads, linear_rigid_trim
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.rigid import (
    level_flight_condition,
    rigid_derivatives,
    rigid_matrices,
)
from bioflex_jsb.parameters import airframe as default_set
from bioflex_jsb.parameters import airframe_consistent as consistent_set
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import (
    CRUISE_SPEED_M_S,
    MASS_PROPERTIES,
    PROTOTYPE_AIRFRAME,
    REFERENCE_GEOMETRY,
    RigidAerodynamics,
)
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_M_S2
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM, Planform

CBAR_M = REFERENCE_GEOMETRY.mean_chord_m
TABLE3_RIGID_15 = complex(*P.TABLE3_SHORT_PERIOD[(15.0, "rigid")])


@dataclass(frozen=True)
class ConsistentDerivatives:
    """What the stated geometry gives at one CG: the lattice's derivatives, the fuselage's
    Munk moment slope [1/rad], and the resulting rigid aerodynamics (C_m0 set so that the
    linear rigid trim at 15 m/s needs the default set's elevator)."""

    cg_fraction: float
    lattice: WingTailDerivatives
    fuselage_cm_alpha_per_rad: float
    aero: RigidAerodynamics

    @property
    def static_margin(self) -> float:
        return -self.aero.cm_alpha_per_rad / self.aero.cl_alpha_per_rad


def cm0_for_elevator(aero: RigidAerodynamics, elevator_rad: float,
                     speed_m_s: float = CRUISE_SPEED_M_S) -> float:
    """C_m0 [-] that makes the linear rigid trim of ``aero`` at ``speed_m_s`` need
    ``elevator_rad`` (the tail incidence that does it)."""
    cond = level_flight_condition(speed_m_s, aero=aero, airframe=PROTOTYPE_AIRFRAME)
    # α from the lift balance with that elevator, then C_m0 from the moment balance
    qs = cond.dynamic_pressure_pa * REFERENCE_GEOMETRY.area_m2
    alpha = ((MASS_PROPERTIES.mass_kg * STANDARD_GRAVITY_M_S2 / qs - aero.cl0
              - aero.cl_delta_e_per_rad * elevator_rad) / aero.cl_alpha_per_rad)
    return -(aero.cm_alpha_per_rad * alpha + aero.cm_delta_e_per_rad * elevator_rad)


def consistent_derivatives(
    cg_fraction: float = consistent_set.CG_FRACTION_OF_CHORD,
    *,
    tail=consistent_set.TAIL,
    fuselage=consistent_set.FUSELAGE,
    planform: Planform = DEFAULT_PLANFORM,
    base: RigidAerodynamics = default_set.RIGID_AERODYNAMICS,
) -> ConsistentDerivatives:
    """Derivatives of wing + ``tail`` + ``fuselage`` about the CG at ``cg_fraction`` of c̄
    aft of the root leading edge; every other coefficient is ``base``'s."""
    x_cg = cg_fraction * CBAR_M
    lat = wing_tail_derivatives(
        planform, tail, tail_height_m=tail.height_m, x_cg_m=x_cg, cbar_m=CBAR_M,
        tail_efficiency=tail.efficiency, elevator_chord_fraction=tail.elevator_chord_fraction,
    )
    k = prolate_spheroid_apparent_mass_factor(fuselage.fineness_ratio)
    d_cm_f = munk_moment_slope_per_rad(fuselage.volume_m3, k, REFERENCE_GEOMETRY.area_m2, CBAR_M)
    aero = replace(
        base,
        cl_alpha_per_rad=lat.cl_alpha,
        cm_alpha_per_rad=lat.cm_alpha + d_cm_f,
        cm_q_per_rad=lat.cm_q,
        cm_alphadot_per_rad=lat.cm_alphadot,
        cl_delta_e_per_rad=lat.cl_delta_e,
        cm_delta_e_per_rad=lat.cm_delta_e,
    )
    base_trim = linear_rigid_trim(level_flight_condition(CRUISE_SPEED_M_S, aero=base,
                                                         airframe=PROTOTYPE_AIRFRAME),
                                  base)(StaticWingLoads())
    aero = replace(aero, cm0=cm0_for_elevator(aero, base_trim.elevator_rad))
    return ConsistentDerivatives(cg_fraction, lat, d_cm_f, aero)


def rigid_short_period(aero: RigidAerodynamics, speed_m_s: float,
                       density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> complex:
    """The rigid short-period root (upper half plane) of A_RR with ``aero`` [rad/s]."""
    cond = level_flight_condition(speed_m_s, density_kg_m3, aero, airframe=PROTOTYPE_AIRFRAME)
    lam = np.linalg.eigvals(rigid_matrices(rigid_derivatives(cond, aero))[0])
    root = lam[np.argmax(np.abs(lam))]
    return complex(root.real, abs(root.imag))


def calibrate_cg_fraction(target_frequency_rad_s: float = abs(TABLE3_RIGID_15),
                          speed_m_s: float = 15.0,
                          bracket: tuple[float, float] = (0.32, 0.46)) -> float:
    """The CG [fraction of c̄] whose rigid short period at ``speed_m_s`` has the natural
    frequency ``target_frequency_rad_s`` (default Table 3's 10.60 rad/s); brentq to 1e-6."""
    def miss(f: float) -> float:
        return abs(rigid_short_period(consistent_derivatives(f).aero, speed_m_s)) \
            - target_frequency_rad_s

    return float(brentq(miss, *bracket, xtol=1e-6))


@dataclass(frozen=True)
class AircraftSet:
    """A rigid parameter set: its aerodynamics and the planform carrying its CG."""

    name: str
    aero: RigidAerodynamics
    planform: Planform
    source: str


AIRCRAFT_SETS = {
    "default": AircraftSet("default", default_set.RIGID_AERODYNAMICS, DEFAULT_PLANFORM,
                           "parameters/airframe.py (calibrated to Table 3)"),
    "consistent": AircraftSet("consistent", consistent_set.RIGID_AERODYNAMICS,
                              consistent_set.PLANFORM, consistent_set.SOURCE),
}


# --------------------------------------------------------------------------------------
# eigen's labelling, tracking and flutter search (the one engine) with a set's aero
# --------------------------------------------------------------------------------------
def modes_with(model: str, speeds_m_s: Sequence[float], wing: ElasticWingModel | None,
               aero: RigidAerodynamics,
               density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> list[eigen.ModeSet]:
    """:func:`eigen.modes_at` with ``aero`` (labels tracked from 2 m/s, 0.25 m/s grid)."""
    return eigen.modes_at(model, speeds_m_s, wing, density_kg_m3, aero,
                          airframe=PROTOTYPE_AIRFRAME if wing is None else None)


def flutter_with(wing: ElasticWingModel, aero: RigidAerodynamics,
                 range_m_s: tuple[float, float] = (5.0, 40.0), step_m_s: float = 0.1,
                 tol_m_s: float = 0.01,
                 density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> eigen.FlutterResult:
    """:func:`eigen.find_flutter` with ``aero`` (phugoid left out, as there)."""
    return eigen.find_flutter(wing, range_m_s, step_m_s, tol_m_s, density_kg_m3, aero)


def relative_error(model: complex, paper: complex) -> tuple[float, float]:
    """((re_m − re_p)/|re_p|, (im_m − im_p)/|im_p|) [-]."""
    return ((model.real - paper.real) / abs(paper.real),
            (model.imag - paper.imag) / abs(paper.imag) if paper.imag else math.nan)
