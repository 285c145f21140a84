"""The free aircraft on unsteady strips with another rigid parameter set (e.g. the
geometry-consistent one, parameters/airframe_consistent.py).

:mod:`bioflex_jsb.aeroelasticity.free_aircraft` assembles its descriptor system with the
rigid aerodynamics of the wing's airframe and its planform. The rigid set enters that
system in exactly three places, so it can be exchanged afterwards without touching the
strips:

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
from bioflex_jsb.parameters.airframe import RigidAerodynamics
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3
from bioflex_jsb.parameters.wing import Planform


def unsteady_state_space_with(build, speed_m_s: float, aero: RigidAerodynamics,
                              planform: Planform, *, structural_damping: float | None = None,
                              density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3) -> StateSpace:
    """:func:`free_aircraft.unsteady_state_space` (paper's gust input) with the rigid set
    ``aero`` in place of the set of the airframe ``build`` was built for (its S, c̄, mass
    kept) and the CG of ``planform``; ``build`` must be built on ``planform``."""
    v = float(speed_m_s)
    geometry = fa.strip_geometry(build, planform)
    d = fa.unsteady_descriptor(build, v, structural_damping=structural_damping,
                               density_kg_m3=density_kg_m3, geometry=geometry)
    model = fa.with_damping(build, structural_damping)
    airframe = model.airframe  # the descriptor's: its rigid set is the one exchanged
    cond = level_flight_condition(v, density_kg_m3, airframe=airframe)
    new_base = build_state_space("coupled", level_flight_condition(v, density_kg_m3, aero,
                                                                   airframe=airframe),
                                 model, aero)
    n0 = d.base.n_states
    a, e, b = d.a.copy(), d.e.copy(), d.b.copy()
    strips_a = a.copy()
    strips_a[:n0, :n0] -= d.base.a  # what the strips add on x
    strips_e = np.eye(e.shape[0]) - e  # what the strips add on ẋ (apparent mass)
    d_m_wdot = rigid_derivatives(cond, aero).m_wdot - rigid_derivatives(cond).m_wdot
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
                          density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3):
    """The first instability of the exchanged unsteady system in ``range_m_s`` (the
    engine's search: labels from the set's quasi-steady Eq. 4 at 2 m/s, phugoid and lag
    roots left out, scan in ``step_m_s``, bisection to ``tol_m_s``)."""
    from bioflex_jsb.flight_dynamics import eigen
    from bioflex_jsb.flight_dynamics import flutter_engine as engine

    lo, hi = range_m_s
    start = min(eigen.SCAN_START_M_S, lo)
    model = fa.with_damping(build, structural_damping)
    ref = eigen.track("coupled", [start], model, density_kg_m3, aero)
    fam = engine.EigenFamily(
        lambda v: unsteady_state_space_with(build, v, aero, planform,
                                            structural_damping=structural_damping,
                                            density_kg_m3=density_kg_m3).a,
        ref.eigenvalues[0], ref.labels, rest_label="lag", excluded=fa.EXCLUDED,
        rigid_labels=eigen.RIGID_LABELS,
        natural_frequencies_rad_s=tuple(float(w) for w in model.frequencies_rad_s),
        reference_semichord_m=model.airframe.reference.mean_chord_m / 2.0, aero="unsteady",
        name=build.variant.name)
    return engine.first_instability(
        fam, engine.default_grid((lo, hi), step_m_s, start), (lo, hi), tol_m_s=tol_m_s,
        structural_damping=structural_damping, density_kg_m3=density_kg_m3)
