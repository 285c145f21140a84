"""Published data of the bio-inspired elastic-wing prototype: one parameter set, one source.

Source (cited everywhere below as "the paper"):
    "Flight dynamic coupling analysis of a bio-inspired elastic-wing aircraft",
    copy in ``shared/reference/paper.md``.

Every value here is either printed in the paper (its table or equation is named next to it)
or is a *decision* about an inconsistency in the paper, which is labelled ``DECISION`` and
explained in ``docs/decisions.md``. Values that are not in the paper (estimates and
calibrations of the airframe, the planform and the wing structure) live in
:mod:`bioflex_jsb.parameters.airframe` and :mod:`bioflex_jsb.parameters.wing`, each with the
quantity it was calibrated to.

Units are SI throughout (m, kg, s, rad, N, Pa); the unit is in every name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from bioflex_jsb.parameters import constants as _C

# --------------------------------------------------------------------------------------
# Table 1: general parameters of the prototype
# --------------------------------------------------------------------------------------
FUSELAGE_LENGTH_M = 0.85  # Table 1
SPAN_M = 1.7  # Table 1, b
REFERENCE_AREA_PRINTED_M2 = 0.174  # Table 1, S as printed (inconsistent; see below)
MEAN_AERODYNAMIC_CHORD_M = 0.183  # Table 1, c̄
ASPECT_RATIO = 9.29  # Table 1, AR
MASS_KG = 2.5  # Table 1, m ("weight")
PITCH_INERTIA_KG_M2 = 0.0928  # Table 1, I_y
CRUISE_SPEED_M_S = 15.0  # Table 1, u_0
ENDURANCE_S = 20.0 * 60.0  # Table 1

# DECISION (docs/decisions.md, "Reference area"): b·c̄ = 0.3111 m² and b²/AR = 0.3111 m²
# agree with each other to 0.1 %; the printed 0.174 m² agrees with neither. We use
# S = b·c̄ for every coefficient; the printed value is kept above for the record.
REFERENCE_AREA_M2 = SPAN_M * MEAN_AERODYNAMIC_CHORD_M  # 0.3111 m²

# --------------------------------------------------------------------------------------
# Table 2: structural dynamic parameters of the first three modes (half wing, root clamped)
# Generalised masses are in kg·m²: modal coordinates are normalised on a twist angle [rad].
# --------------------------------------------------------------------------------------
MODE_FREQUENCIES_RIBS_HZ = (30.9, 71.9, 107.2)  # Table 2, "with ribs"
MODE_FREQUENCIES_NO_RIBS_HZ = (20.8, 49.6, 79.6)  # Table 2, "without ribs"
GENERALISED_MASSES_RIBS_KG_M2 = (6.57e-5, 5.70e-5, 8.37e-6)  # Table 2, "with ribs"
GENERALISED_MASSES_NO_RIBS_KG_M2 = (1.50e-5, 9.29e-7, 4.48e-6)  # Table 2, "without ribs"
# Section 3.1 (after Table 2): "Structural damping is neglected here".
STRUCTURAL_DAMPING_RATIO = 0.0

# --------------------------------------------------------------------------------------
# Table A1: mechanical properties of the membrane materials
# --------------------------------------------------------------------------------------
CARBON_DENSITY_KG_M3 = 1.6e3  # Table A1, 1.6 g/cm³
CARBON_YOUNGS_MODULUS_PA = 90e9  # Table A1, 90 GPa
CARBON_TENSILE_STRENGTH_PA = 4.1e9  # Table A1
KEVLAR_DENSITY_KG_M3 = 1.4e3  # Table A1, 1.4 g/cm³
KEVLAR_YOUNGS_MODULUS_PA = 40e9  # Table A1, 40 GPa
KEVLAR_TENSILE_STRENGTH_PA = 2.8e9  # Table A1
KEVLAR_THICKNESS_RANGE_M = (0.15e-3, 0.20e-3)  # Appendix A text, "0.15~0.2 mm"
# Section 3.1 / 3.2: the membrane wing weighs "less than 10% of the overall weight".
WING_MASS_FRACTION_MAX = 0.10

# --------------------------------------------------------------------------------------
# Wing axis positions and the published first-mode coefficient C_η1^Q1
# (x_I, x_E: chordwise position of inertial and elastic axis, fraction of chord from the
# leading edge, Eq. 11-12)
# --------------------------------------------------------------------------------------


@dataclass(frozen=True)
class PublishedVariant:
    """Axis positions and C_η1^Q1 as the paper states them for one wing variant.

    ``x_inertial_frac`` / ``x_elastic_frac`` are fractions of the local chord measured aft
    from the leading edge [-]; ``None`` where the paper gives no number.
    ``c_eta1_q1`` is the published C_η1^Q1 [-] (Table B1 definition).
    """

    name: str
    x_inertial_frac: float | None
    x_elastic_frac: float | None
    c_eta1_q1: float
    source: str


PUBLISHED_VARIANTS: dict[str, PublishedVariant] = {
    "original": PublishedVariant("original", 0.5, 0.5, -0.03, "Table 8; Section 3.2 text"),
    "optimised": PublishedVariant("optimised", 0.25, 0.22, -0.14, "Table 8 (Section 5: -0.138)"),
    "inertial-forward": PublishedVariant(
        "inertial-forward", None, 0.5, -0.10, "Section 4.2: 'adjusted to -0.1'; Table 6"
    ),
    "elastic-forward": PublishedVariant(
        "elastic-forward", 0.5, None, -0.10, "Section 4.2: 'adjusted to -0.1' (Table 7 held out)"
    ),
    "inertial-backward": PublishedVariant(
        "inertial-backward", None, 0.5, 0.10, "Section 4.1: 'adjusted to 0.1' (Table 4 held out)"
    ),
    "elastic-backward": PublishedVariant(
        "elastic-backward", 0.5, None, 0.10, "Section 4.1: 'adjusted to 0.1' (Table 5 held out)"
    ),
}

# --------------------------------------------------------------------------------------
# Validation data: short-period eigenvalues [rad/s] (re, im) by analysis type and airspeed
# --------------------------------------------------------------------------------------
TABLE3_SHORT_PERIOD = {  # Table 3, original wing
    (15.0, "rigid"): (-5.6, 9.0),
    (15.0, "coupled"): (-5.3, 8.5),
    (15.0, "qsd"): (-5.4, 8.5),
    (20.0, "rigid"): (-7.4, 12.0),
    (20.0, "coupled"): (-7.0, 10.9),
    (20.0, "qsd"): (-7.0, 10.8),
}
TABLE6_SHORT_PERIOD = {  # Table 6, inertial axis moved forward (C_η1^Q1 = -0.1)
    (15.0, "rigid"): (-5.6, 9.0),
    (15.0, "coupled"): (-5.0, 7.2),
    (15.0, "qsd"): (-5.1, 7.1),
    (20.0, "rigid"): (-7.4, 12.0),
    (20.0, "coupled"): (-6.3, 8.1),
    (20.0, "qsd"): (-6.4, 7.9),
}

# Section 5: the gust case of Figs. 21 and 22.
SECTION5_GUST_AMPLITUDE_M_S = 3.0  # sharp-edged, vertical (w_g of Eq. 4)
SECTION5_AIRSPEED_M_S = 15.0
# Section 3.2 / Figs. 15-19: the airspeed range of the root loci.
ROOT_LOCUS_SPEED_RANGE_M_S = (5.0, 25.0)

# Physical constants (ISA sea-level density, standard gravity): parameters/constants.py;
# kept under these names for the paper-data readers (the paper's flight condition is
# unstated; we fly at sea level ISA unless told otherwise).
SEA_LEVEL_DENSITY_KG_M3 = _C.SEA_LEVEL_DENSITY_KG_M3
STANDARD_GRAVITY_M_S2 = _C.STANDARD_GRAVITY_M_S2


def table2_frequencies_rad_s(ribs: bool = True) -> tuple[float, float, float]:
    """Table 2 natural frequencies converted to [rad/s]."""
    hz = MODE_FREQUENCIES_RIBS_HZ if ribs else MODE_FREQUENCIES_NO_RIBS_HZ
    return tuple(2.0 * math.pi * f for f in hz)  # type: ignore[return-value]
