"""The fixed-pitch propeller of the airframe: C_T(J), C_P(J) by blade-element momentum theory.

The blade (diameter, pitch, chord stations, section polar) is the drive's
:class:`~bioflex_jsb.parameters.airframe.Propulsion` (an airframe's ``propulsion``, passed
in); the JSBSim airframe generator (:mod:`bioflex_jsb.generators.airframe`) tabulates
:func:`propeller_tables` per rotor, the LTI model trims its drive on them
(:mod:`bioflex_jsb.flight_dynamics.lti`).
"""

from __future__ import annotations

import math

import numpy as np

from bioflex_jsb.parameters.airframe import Propulsion

PROPELLER_TABLE_ROWS = 27  # J stations of the C_T, C_P tables (ΔJ = 0.05 up to J = 1.3)
PROPELLER_BLADE_STATIONS = 40  # blade-element annuli of the momentum calculation


def propeller_coefficients(
    advance_ratio: float, prop: Propulsion, stations: int = PROPELLER_BLADE_STATIONS
) -> tuple[float, float]:
    """Thrust and power coefficients (C_T = T/(ρn²D⁴), C_P = P/(ρn³D⁵)) at J = V/(nD).

    Blade-element momentum theory, swirl neglected, Prandtl tip loss: on each annulus the
    axial induced velocity v makes the blade-element thrust equal the momentum thrust
    4πrρ(V+v)vF. Evaluated at n = 1 rev/s, ρ = 1 (the coefficients are scale-free).
    """
    from scipy.optimize import brentq  # when the tables are computed (build time)

    radius = prop.prop_diameter_m / 2.0
    n_rev_s, rho = 1.0, 1.0
    speed = advance_ratio * n_rev_s * prop.prop_diameter_m
    omega = 2.0 * math.pi * n_rev_s
    blades = prop.prop_blades
    r_frac, c_frac = zip(*prop.prop_chord_stations, strict=True)
    edges = np.linspace(prop.prop_hub_radius_fraction * radius, radius, stations + 1)
    thrust = torque = 0.0
    for r0, r1 in zip(edges[:-1], edges[1:], strict=True):
        r = 0.5 * (r0 + r1)
        chord = float(np.interp(r / radius, r_frac, c_frac)) * radius
        pitch_angle = math.atan(prop.prop_pitch_m / (2.0 * math.pi * r))

        def loads(v: float, r: float = r, chord: float = chord, pa: float = pitch_angle):
            ua, ut = speed + v, omega * r
            phi = math.atan2(ua, ut)
            w2 = ua * ua + ut * ut
            cl = prop.prop_section_lift_slope_per_rad * (pa - phi - prop.prop_section_zero_lift_rad)
            cl = max(-prop.prop_section_cl_max, min(prop.prop_section_cl_max, cl))
            cd = prop.prop_section_cd0 + prop.prop_section_cd_k * cl * cl
            f_tip = blades * (radius - r) / (2.0 * r * max(math.sin(phi), 1e-9))
            tip_loss = 2.0 / math.pi * math.acos(math.exp(-f_tip))
            dq = 0.5 * rho * w2 * blades * chord
            d_thrust = dq * (cl * math.cos(phi) - cd * math.sin(phi))
            d_torque = dq * (cl * math.sin(phi) + cd * math.cos(phi)) * r
            return d_thrust - 4.0 * math.pi * r * rho * ua * v * tip_loss, d_thrust, d_torque

        v = brentq(lambda v: loads(v)[0], -0.5 * speed * (1.0 - 1e-9), omega * radius, xtol=1e-12)
        _, d_thrust, d_torque = loads(v)
        thrust += d_thrust * (r1 - r0)
        torque += d_torque * (r1 - r0)
    d = prop.prop_diameter_m
    return thrust / (rho * n_rev_s**2 * d**4), omega * torque / (rho * n_rev_s**3 * d**5)


def propeller_tables(prop: Propulsion) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(J, C_T, C_P) of the drive ``prop`` on ``PROPELLER_TABLE_ROWS`` stations from 0 to its
    ``advance_ratio_max``."""
    j = np.linspace(0.0, prop.advance_ratio_max, PROPELLER_TABLE_ROWS)
    ct, cp = zip(*(propeller_coefficients(float(x), prop) for x in j), strict=True)
    return j, np.array(ct), np.array(cp)
