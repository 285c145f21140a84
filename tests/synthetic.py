"""Small synthetic elastic wings with known answers, for the flight-dynamics tests."""

from __future__ import annotations

import types

import numpy as np

from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_coefficients import (
    SpanwiseGeometry,
    modal_coefficients,
)
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM

SEMISPAN_M = P.SPAN_M / 2.0
CHORD_M = P.MEAN_AERODYNAMIC_CHORD_M


def strips(x_elastic_frac: float, n: int = 201) -> SpanwiseGeometry:
    """Elliptic loading on the default planform (swept outer panel), AC on the quarter chord."""
    y = np.linspace(0.0, SEMISPAN_M, n)
    w = np.full(n, y[1] - y[0])
    w[0] = w[-1] = 0.5 * w[1]
    clac = 2.0 * np.pi * 0.9 * CHORD_M * np.sqrt(1.0 - (y / SEMISPAN_M) ** 2)
    e = np.full(n, (x_elastic_frac - 0.25) * CHORD_M)
    x_ac = DEFAULT_PLANFORM.leading_edge_x_at(y) + 0.25 * CHORD_M
    d = DEFAULT_PLANFORM.x_cg_m - x_ac
    return SpanwiseGeometry(y, w, np.full(n, CHORD_M), clac, e, d)


def twist_modes(n_modes: int = 1, bending_per_twist_m: float = 0.0, n: int = 201):
    """Clamped-free torsion shapes sin((2i−1)πy/2L) with proportional bending."""
    y = np.linspace(0.0, SEMISPAN_M, n)
    theta = np.array([np.sin((2 * i + 1) * np.pi * y / (2 * SEMISPAN_M)) for i in range(n_modes)])
    return types.SimpleNamespace(
        stations_m=y, twist_rad=theta, bending_m=bending_per_twist_m * theta
    )


def wing(
    x_elastic_frac: float = 0.22,
    frequencies_hz=(30.9,),
    masses_kg_m2=(6.57e-5,),
    damping=None,
    bending_per_twist_m: float = 0.0,
    overrides=None,
) -> ElasticWingModel:
    n = len(frequencies_hz)
    coeffs = modal_coefficients(twist_modes(n, bending_per_twist_m), strips(x_elastic_frac),
                                reference_area_m2=PROTOTYPE_AIRFRAME.reference.area_m2,
                                cbar_m=PROTOTYPE_AIRFRAME.reference.mean_chord_m)
    if overrides:
        coeffs = coeffs.with_overrides(overrides)
    return ElasticWingModel(
        name="synthetic",
        frequencies_rad_s=2.0 * np.pi * np.asarray(frequencies_hz, dtype=float),
        damping_ratios=np.zeros(n) if damping is None else np.asarray(damping, dtype=float),
        generalised_masses_kg_m2=np.asarray(masses_kg_m2, dtype=float),
        coefficients=coeffs,
        wing_lift_slope_per_rad=5.0,
        cm_ac=-0.05,
        airframe=PROTOTYPE_AIRFRAME,
    )
