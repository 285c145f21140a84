"""A clamped-wing definition as the analysis's model: beam sections, modes, strips, and the
speed range derived from the wing.

Default speed range (:func:`derived_speed_range_m_s`), the rule: the top is 1.5 × the
wing's static divergence speed V_div (steady strips, the same aerodynamics; flutter of a
wing that can diverge is found below it in every case measured here: Goland 0.54 V_div,
HALE 0.87 V_div), or, for a wing that cannot diverge (elastic axis ahead of the lift), the
speed at which the first torsion mode's reduced frequency ω_θ b / V falls to 0.1 (flutter
reduced frequencies of wings lie above it: Goland 0.47, HALE 0.34); capped at 400 m/s (the
strips are incompressible). The bottom is 5 % of the top (below it the dynamic pressure is
under 0.25 % of the top's: the roots are their wind-off ones). The scan step is the
smaller of 2 m/s and 1/120 of the range.
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel, clamped_wing_model
from bioflex_jsb.aeroelasticity.strip_aero import divergence_speed_m_s
from bioflex_jsb.definition.loader import SPEED_LIMIT_M_S, DefinitionError
from bioflex_jsb.definition.model import BeamStructure, Definition
from bioflex_jsb.structures.beam import BeamSections
from bioflex_jsb.structures.beam_wing import BeamWing

TOP_OVER_DIVERGENCE = 1.5
FLOOR_REDUCED_FREQUENCY = 0.1
BOTTOM_FRACTION = 0.05
MAX_STEP_M_S = 2.0
STEPS_PER_RANGE = 120


def beam_sections(d: Definition) -> BeamSections:
    """The definition's beam sections (pitch inertia carried to the elastic axis), with its
    point masses and struts (vertical springs)."""
    s = d.structure
    chord = d.column("chord_m")
    ea, cg = d.column("elastic_axis"), d.column("centre_of_mass")
    inertia = s.pitch_inertia_kg_m
    if s.inertia_axis == "centre-of-mass":
        inertia = inertia + s.mass_per_length_kg_m * ((cg - ea) * chord) ** 2
    return BeamSections(
        stations_m=d.column("y_m"), bending_stiffness_n_m2=s.bending_stiffness_n_m2,
        torsional_stiffness_n_m2=s.torsional_stiffness_n_m2,
        mass_per_length_kg_m=s.mass_per_length_kg_m, torsional_inertia_kg_m=inertia,
        chord_m=chord, x_elastic_frac=ea, x_inertial_frac=cg,
        description=f"{d.name} ({s.pitch_inertia_kg_m[0]:g} kg·m about the "
                    f"{s.inertia_axis}" + _extras(s) + ")",
        point_masses=s.point_masses, springs=s.struts)


def _extras(s: BeamStructure) -> str:
    """The point masses and struts in a few words (the modes' source line)."""
    out = ""
    if s.point_masses:
        total = sum(p.mass_kg for p in s.point_masses)
        out += f"; {len(s.point_masses)} point mass(es), {total:g} kg"
    if s.struts:
        out += f"; {len(s.struts)} strut(s)"
    return out


def beam_wing(d: Definition) -> BeamWing:
    """The beam wing of a definition with ``kind = 'beam'`` as the flight model takes it
    (its modes computed once per process: :class:`~bioflex_jsb.structures.beam_wing.
    BeamWing`), with the structure's mesh and damping ratio."""
    s = d.structure
    if not isinstance(s, BeamStructure):
        raise DefinitionError(f"definition {d.name!r}: structure.kind is not 'beam'")
    return BeamWing(beam_sections(d), n_elements=s.n_elements, damping_ratio=s.damping_ratio)


def clamped_model(d: Definition, lift_slope: str | None = None,
                  breaks_m: tuple[float, ...] = ()) -> ClampedWingModel:
    """The modal model with strips of the clamped wing ``d``; refuses what the clamped
    strip analysis does not model (a swept leading edge, no torsion mode). ``breaks_m``
    [m]: strip edges there (a control surface's ends; the flutter analyses take none)."""
    where = f"definition {d.name!r}" + (f" ({d.path})" if d.path else "")
    if not isinstance(d.structure, BeamStructure):
        raise DefinitionError(f"{where}: structure.kind: a clamped analysis needs beam "
                              "sections (kind = 'beam'); this wing's structure is the "
                              "aircraft's flight model (fly it: --aircraft)")
    x_le = d.column("leading_edge_x_m")
    if np.ptp(x_le) > 1e-9 * max(1.0, d.semispan_m):
        raise DefinitionError(f"{where}: wing.stations.leading_edge_x_m varies along the "
                              "span: a swept clamped wing is not modelled (strips normal to "
                              "an unswept elastic axis); give a constant leading_edge_x_m")
    slope = lift_slope or d.aero.lift_slope
    if slope == "vlm" and np.ptp(d.column("chord_m")) > 0.0:
        raise DefinitionError(f"{where}: aero.lift_slope = 'vlm' needs a constant chord "
                              "(rectangular planform); use 'strip'")
    model = clamped_wing_model(beam_sections(d), lift_slope=slope,
                               n_modes=d.structure.n_modes, n_elements=d.structure.n_elements,
                               n_strips=d.aero.strips,
                               section_lift_slope_per_rad=d.aero.section_lift_slope_per_rad,
                               breaks_m=tuple(breaks_m))
    if not np.any(model.torsion_energy_fraction > 0.5):
        raise DefinitionError(f"{where}: structure.n_modes: the {model.n_modes} lowest modes "
                              "are all bending (no torsion mode): raise n_modes, or check "
                              "torsional_stiffness_n_m2 and pitch_inertia_kg_m")
    return model


def derived_speed_range_m_s(model: ClampedWingModel, density_kg_m3: float
                            ) -> tuple[float, float]:
    """The default speed range [m/s] of a clamped wing (module docstring)."""
    v_div = divergence_speed_m_s(model, density_kg_m3)
    if math.isfinite(v_div):
        top = TOP_OVER_DIVERGENCE * v_div
    else:
        torsion = model.natural_frequencies_rad_s[model.torsion_energy_fraction > 0.5]
        top = float(torsion.min()) * float(np.mean(model.semichord_m)) / FLOOR_REDUCED_FREQUENCY
    top = min(top, SPEED_LIMIT_M_S)
    return BOTTOM_FRACTION * top, top


def scan_step_m_s(range_m_s: tuple[float, float]) -> float:
    """The scan step [m/s] for ``range_m_s`` (module docstring)."""
    return min(MAX_STEP_M_S, (range_m_s[1] - range_m_s[0]) / STEPS_PER_RANGE)


PAPER_FLUTTER_RANGE_M_S = (5.0, 40.0)  # the paper's scans of the prototype (Figs. 11-13)


def free_speed_range_m_s(build, density_kg_m3: float | None = None) -> tuple[float, float]:
    """The default speed range [m/s] of a free aircraft's flutter search for the wing
    ``build`` (a :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild`): the paper's
    5-40 m/s for the prototype's airframe; another aircraft's derived from its wing as a
    clamped wing's is (:func:`derived_speed_range_m_s`): 150 % of the wing's static
    divergence speed in the aircraft (A_EE singular, the body held:
    :func:`bioflex_jsb.flight_dynamics.eigen.wing_divergence_speed_m_s`) down to 5 % of
    that, the search's top at most 400 m/s (the strips are incompressible). A fixed
    5-40 m/s told the SGS sailplane "no instability" while it flutters at 59 m/s.
    ``density_kg_m3`` [kg/m³]: None, sea level."""
    from bioflex_jsb.flight_dynamics.eigen import wing_divergence_speed_m_s
    from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
    from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3

    if build.model.airframe.reference == PROTOTYPE_AIRFRAME.reference:
        return PAPER_FLUTTER_RANGE_M_S
    rho = SEA_LEVEL_DENSITY_KG_M3 if density_kg_m3 is None else density_kg_m3
    v_div = wing_divergence_speed_m_s(build.model, rho,
                                      (2.0, SPEED_LIMIT_M_S / TOP_OVER_DIVERGENCE))
    top = SPEED_LIMIT_M_S if v_div is None else TOP_OVER_DIVERGENCE * v_div
    return BOTTOM_FRACTION * top, top
