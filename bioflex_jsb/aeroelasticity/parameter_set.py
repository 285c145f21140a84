"""The free aircraft on unsteady strips with another rigid parameter set (e.g. the
geometry-consistent one, parameters/airframe_consistent.py).

:mod:`bioflex_jsb.aeroelasticity.free_aircraft` assembles its descriptor system with the
default rigid aerodynamics and planform. The rigid set enters that system in exactly three
places, so it can be exchanged afterwards without touching the strips:

* the quasi-steady Eq. (4) block (``base.a``, the top-left 4+2n square of A, and ``base.b``);
* M_ẇ in the strips' pitch rows: q̇ gets M_ẇ·ΔZ/m, and ΔZ/m = u₀ × (the strips' α̇ row),
  on A (circulatory and apparent-mass terms on x) and on E (apparent-mass terms on ẋ);
* the CG, through the strips' arms: passed as ``geometry`` = ``strip_geometry(build,
  planform)`` of a wing built on the set's planform.

Exchanging them is exact (tests/test_consistent_aircraft.py: the default set gives back
``unsteady_state_space`` to round-off; a steady state of the exchanged system is the set's
quasi-steady Eq. (4), as on the default set). Once free_aircraft takes ``aero`` and
``planform`` itself, this module can go.
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb.aeroelasticity import free_aircraft as fa
from bioflex_jsb.flight_dynamics.lti import StateSpace, build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition, rigid_derivatives
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import RIGID_AERODYNAMICS, RigidAerodynamics
from bioflex_jsb.parameters.wing import Planform


def unsteady_state_space_with(build, speed_m_s: float, aero: RigidAerodynamics,
                              planform: Planform, *, structural_damping: float | None = None,
                              density_kg_m3: float = P.SEA_LEVEL_DENSITY_KG_M3) -> StateSpace:
    """:func:`free_aircraft.unsteady_state_space` (paper's gust input) with the rigid set
    ``aero`` and the CG of ``planform``; ``build`` must be built on ``planform``."""
    v = float(speed_m_s)
    geometry = fa.strip_geometry(build, planform)
    d = fa.unsteady_descriptor(build, v, structural_damping=structural_damping,
                               density_kg_m3=density_kg_m3, geometry=geometry)
    model = fa.with_damping(build, structural_damping)
    cond = level_flight_condition(v, density_kg_m3)
    new_base = build_state_space("coupled", level_flight_condition(v, density_kg_m3, aero),
                                 model, aero)
    n0 = d.base.n_states
    a, e, b = d.a.copy(), d.e.copy(), d.b.copy()
    strips_a = a.copy()
    strips_a[:n0, :n0] -= d.base.a  # what the strips add on x
    strips_e = np.eye(e.shape[0]) - e  # what the strips add on ẋ (apparent mass)
    d_m_wdot = (rigid_derivatives(cond, aero).m_wdot
                - rigid_derivatives(cond, RIGID_AERODYNAMICS).m_wdot)
    ia, iq = 1, 2
    a[:n0, :n0] += new_base.a - d.base.a
    a[iq] += d_m_wdot * v * strips_a[ia]
    e[iq] -= d_m_wdot * v * strips_e[ia]
    b[:n0] += new_base.b - d.base.b
    a_out = np.linalg.solve(e, a)
    b_out = np.linalg.solve(e, b)
    n_all = a_out.shape[0]
    notes = dict(d.base.notes, aero="unsteady", rigid_set="exchanged",
                 lag_states=n_all - n0)
    return StateSpace(model="coupled-unsteady", speed_m_s=v, a=a_out, b=b_out,
                      c=np.eye(n_all), d=np.zeros((n_all, 1)), states=d.states,
                      state_units=d.state_units, inputs=d.base.inputs,
                      input_units=d.base.input_units, outputs=d.states,
                      output_units=d.state_units, notes=notes)


def unsteady_flutter_with(build, aero: RigidAerodynamics, planform: Planform, *,
                          structural_damping: float | None = None,
                          range_m_s: tuple[float, float] = (5.0, 40.0),
                          step_m_s: float = 0.25, tol_m_s: float = 0.01,
                          density_kg_m3: float = P.SEA_LEVEL_DENSITY_KG_M3):
    """First speed [m/s] in ``range_m_s`` at which a root of the exchanged unsteady system
    other than the phugoid crosses into the right half plane, with its root [rad/s];
    (None, None) if none. The phugoid is the slowest complex pair of the rigid block at the
    range's start, followed by continuity of its eigenvalue (MAC-free: it stays below
    2 rad/s and far from every other root here)."""
    def roots(v):
        return np.linalg.eigvals(unsteady_state_space_with(
            build, v, aero, planform, structural_damping=structural_damping,
            density_kg_m3=density_kg_m3).a)

    def phugoid_near(lam, guess):
        return int(np.argmin(np.abs(lam - guess)))

    lo, hi = range_m_s
    grid = np.arange(lo, hi + 0.5 * step_m_s, step_m_s)
    rigid = np.linalg.eigvals(build_state_space(
        "rigid", level_flight_condition(lo, density_kg_m3, aero), aero=aero).a)
    guess = rigid[np.argmin(np.abs(rigid))]
    guess = complex(guess.real, abs(guess.imag))

    def growth(v):
        nonlocal guess
        lam = roots(v)
        j = phugoid_near(lam, guess)
        guess = complex(lam[j].real, abs(lam[j].imag))
        rest = np.delete(lam, [j] + [k for k in range(lam.size)
                                     if k != j and abs(lam[k] - np.conj(lam[j])) < 1e-9])
        k = int(np.argmax(rest.real))
        return float(rest[k].real), complex(rest[k])

    previous = None
    for v in grid:
        g, root = growth(float(v))
        if g > 1e-9:
            if previous is None:
                return float(v), root
            a_, b_ = previous, float(v)
            saved = guess
            while b_ - a_ > tol_m_s:
                mid = 0.5 * (a_ + b_)
                if growth(mid)[0] > 1e-9:
                    b_ = mid
                else:
                    a_ = mid
            guess = saved
            return round(b_, 2), growth(b_)[1]
        previous = float(v)
    return None, None
