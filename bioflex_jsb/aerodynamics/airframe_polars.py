"""Lift and drag polars of the rigid airframe over the whole α range (wing and body, δe = 0).

The coefficients are the airframe's :class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics`
and the post-stall shape its :class:`~bioflex_jsb.parameters.airframe.PostStall` (the
prototype's, passed in by the generator of its JSBSim files):

* lift C_L(α): linear, C_L0 + C_Lα·α, from ``alpha_negative_stall_rad`` (−10°) to
  ``alpha_stall_rad`` (11°), rounded over by a parabola to ``cl_max`` (at
  :func:`alpha_peak_rad`), then relaxing exponentially to the flat plate's
  C_N,90·sin α·cos α; the negative side mirrors it about the negative edge;
* separated-flow drag ΔC_D(α): zero in the linear range, C_N,90·(sin²α − sin²α_edge) beyond.

Used by the JSBSim airframe generator (:mod:`bioflex_jsb.generators.airframe`, which tabulates
them) and by the runtime's stall count (:func:`alpha_peak_rad`).
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb.parameters.airframe import PostStall, RigidAerodynamics


def lift_curve(
    alpha_rad: np.ndarray,
    aero: RigidAerodynamics,
    stall: PostStall,
) -> np.ndarray:
    """Wing-body lift coefficient C_L(α) at δe = 0 [-] (see :class:`PostStall`)."""
    a = np.asarray(alpha_rad, dtype=float)
    cla = aero.cl_alpha_per_rad
    a_pos, a_neg = aero.alpha_stall_rad, stall.alpha_negative_stall_rad
    cl_pos_edge = aero.cl0 + cla * a_pos
    cl_neg_edge = aero.cl0 + cla * a_neg
    rise = aero.cl_max - cl_pos_edge  # lift gained while rounding over [-]
    if rise <= 0.0:
        raise ValueError(
            f"cl_max = {aero.cl_max} must exceed the linear C_L at alpha_stall ({cl_pos_edge:.3f})"
        )
    width = 2.0 * rise / cla  # α from the end of the linear range to the peak [rad]
    cn90 = stall.normal_force_90deg

    def flat_plate(x: np.ndarray) -> np.ndarray:
        return cn90 * np.sin(x) * np.cos(x)

    out = aero.cl0 + cla * a
    # positive side: parabola to the peak, then exponential relaxation to the flat plate
    peak = a_pos + width
    m = (a > a_pos) & (a <= peak)
    out[m] = cl_pos_edge + cla * (a[m] - a_pos) - cla / (2.0 * width) * (a[m] - a_pos) ** 2
    m = a > peak
    out[m] = flat_plate(a[m]) + (aero.cl_max - flat_plate(peak)) * np.exp(
        -(a[m] - peak) / stall.decay_rad
    )
    # negative side: mirror image about the negative edge
    trough = a_neg - width
    cl_min = cl_neg_edge - rise
    m = (a < a_neg) & (a >= trough)
    out[m] = cl_neg_edge + cla * (a[m] - a_neg) + cla / (2.0 * width) * (a[m] - a_neg) ** 2
    m = a < trough
    out[m] = flat_plate(a[m]) + (cl_min - flat_plate(trough)) * np.exp(
        (a[m] - trough) / stall.decay_rad
    )
    return out


def alpha_peak_rad(aero: RigidAerodynamics) -> float:
    """α of the lift peak C_L,max [rad] (end of the round-over parabola)."""
    cl_edge = aero.cl0 + aero.cl_alpha_per_rad * aero.alpha_stall_rad
    return aero.alpha_stall_rad + 2.0 * (aero.cl_max - cl_edge) / aero.cl_alpha_per_rad


def separated_drag(
    alpha_rad: np.ndarray,
    aero: RigidAerodynamics,
    stall: PostStall,
) -> np.ndarray:
    """Separated-flow drag increment ΔC_D(α) [-], zero inside the linear range."""
    a = np.asarray(alpha_rad, dtype=float)
    cn90 = stall.normal_force_90deg
    out = np.zeros_like(a)
    hi = a > aero.alpha_stall_rad
    lo = a < stall.alpha_negative_stall_rad
    out[hi] = cn90 * (np.sin(a[hi]) ** 2 - math.sin(aero.alpha_stall_rad) ** 2)
    out[lo] = cn90 * (np.sin(a[lo]) ** 2 - math.sin(stall.alpha_negative_stall_rad) ** 2)
    return out
