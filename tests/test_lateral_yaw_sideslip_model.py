"""The yaw rate's and sideslip's terms in the linear lateral model (coupled and, residualised,
qsd; aeroelasticity/antisymmetric_strips.py lateral_model_with_aileron; docs/lateral.md,
"Yaw rate, sideslip, side force and yawing moment of the elastic wing"): the model's new
entries against finite differences of the nonlinear step's own terms at the trim, the model
without them equal to the one before them, and the lateral gust's column on the sideslip's
terms."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    lateral_elastic_with_aileron,
    lateral_model_with_aileron,
    trim_wing_lift_n,
    wing_yaw_sideslip_terms,
)
from bioflex_jsb.flight_dynamics.lateral import inertia_matrix
from bioflex_jsb.flight_dynamics.lateral_elastic import (
    antisymmetric_wing,
    build_lateral_elastic,
    residualised,
)
from bioflex_jsb.runtime.identification import identify_lateral
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.full_span import AntisymmetricModalWing, LateralInputs

pytest.importorskip("jsbsim")

SPEEDS = {"bioflex_optimised": 15.0, "c172_elastic": 57.8}  # their cruise [m/s]


@pytest.fixture(scope="module", params=sorted(SPEEDS))
def point(request):
    """(aircraft, its build, the identified trim point, its antisymmetric wing)."""
    ac = api.load_aircraft(request.param)
    build = ac.wing()
    p = identify_lateral(airframe_for(ac), SPEEDS[request.param], build.airframe.reference)
    return ac, build, p, antisymmetric_wing(build, p.trim.ixx_kg_m2)


def _models(ac, build, p, wing, static_eta_s=None):
    """The coupled model with the terms and without them (the wing without its symmetric
    modes), and the strips."""
    with_terms, strips = lateral_model_with_aileron(
        "coupled", p.trim, p.aero, wing, ac.definition.aileron, build.aero.chord_m,
        static_eta_s=static_eta_s)
    bare = dataclasses.replace(wing, symmetric=None)
    without, _ = lateral_model_with_aileron("coupled", p.trim, p.aero, bare,
                                            ac.definition.aileron, build.aero.chord_m)
    return with_terms, without, strips


def test_the_new_entries_are_the_nonlinear_steps_terms_differentiated(point):
    """A_with − A_without = the derivatives of the nonlinear step's terms
    (AntisymmetricModalWing.forcing_n_m and .reactions, the YawSideslipTerms the run flies)
    by each state at the trim (L_w = m g, Q, V; a static symmetric deflection η_s of
    0.02, −0.01, 0.005 rad so that every η_s term is exercised): the modes' forcing ÷ m_i in
    the η̈ rows, J⁻¹ [ΔL_r + ΔL_β, N] in ṗ, ṙ (the elastic ΔL of η_a, η̇_a is already in
    the model), Y ÷ m V in β̇. Central differences of functions linear in the state: agree
    to 1e-9 of each block's largest entry."""
    ac, build, p, wing = point
    n_s = wing.n_symmetric
    eta_s = np.array([0.02, -0.01, 0.005, 0.002, -0.001][:n_s])
    ss, without, strips = _models(ac, build, p, wing, eta_s)
    terms = wing_yaw_sideslip_terms(wing)
    tip = np.asarray(wing.symmetric.twist_rad, dtype=float)[:n_s, -1]
    lat = AntisymmetricModalWing(strips, "coupled", 1e-3, tip, terms=terms)
    q, v, trim = p.trim.dynamic_pressure_pa, p.trim.speed_m_s, p.trim
    lift = trim_wing_lift_n(trim)
    n, states = strips.n_modes, ss.states
    e0, d0 = states.index("eta1"), states.index("eta1_dot")
    j_inv = np.linalg.inv(inertia_matrix(trim))

    def f(x):
        lat._x = np.concatenate([x[e0:e0 + n], x[d0:d0 + n]])
        inputs = LateralInputs(x[1], 0.0, 0.0, x[2], x[0], lift, eta_s)
        force = lat.forcing_n_m(q, v, inputs)
        roll, side, yaw = lat.reactions(q, v, inputs)
        roll -= lat.roll_moment_n_m(q, v)  # ΔL of η_a, η̇_a: the model had it before
        out = np.zeros(len(states))
        out[d0:d0 + n] = force / strips.mass_kg_m2
        out[1:3] = j_inv @ np.array([roll, yaw])
        out[0] = side / (trim.mass_kg * v)
        return out

    scale = {"beta": 1e-3, "p": 1e-2, "r": 1e-2, "phi": 1e-2}
    jac = np.zeros_like(ss.a)
    for k, name in enumerate(states):
        h = scale.get(name, 1e-4)
        x = np.zeros(len(states))
        x[k] = h
        jac[:, k] = (f(x) - f(-x)) / (2.0 * h)
    extra = np.asarray(ss.a) - np.asarray(without.a)
    for rows in (slice(0, 1), slice(1, 3), slice(d0, d0 + n)):
        tol = 1e-9 * np.max(np.abs(jac[rows]))
        np.testing.assert_allclose(extra[rows], jac[rows], rtol=0.0, atol=tol)
    assert np.max(np.abs(jac[d0:d0 + n, states.index("r")])) > 0.0
    assert np.max(np.abs(jac[0, e0:e0 + n])) > 0.0
    assert np.max(np.abs(jac[2, d0:d0 + n])) > 0.0
    # the rows of φ and η̇ = d/dt η take nothing
    assert not np.any(extra[3]) and not np.any(extra[e0:e0 + n])


def test_without_the_terms_the_model_is_the_one_before_them(point):
    """The wing without its symmetric modes (no YawSideslipTerms) gives exactly the coupled
    model of build_lateral_elastic with the aileron's column (the model before the terms)
    and its residualised qsd model; with a rigid trim's η_s = 0 the terms still change it
    (the yaw rate's forcing of the modes, the side force, the yawing moment)."""
    ac, build, p, wing = point
    with_terms, without, strips = _models(ac, build, p, wing)
    before = lateral_elastic_with_aileron(build_lateral_elastic("coupled", p.trim, p.aero, wing),
                                          strips, p.trim.dynamic_pressure_pa)
    for m in ("a", "b", "c", "d"):
        np.testing.assert_array_equal(getattr(without, m), getattr(before, m), err_msg=m)
        np.testing.assert_array_equal(getattr(residualised(without), m),
                                      getattr(residualised(before), m), err_msg=m)
    assert not np.array_equal(with_terms.a, before.a)


def test_the_lateral_gust_acts_on_the_sideslips_terms(point):
    """The nonlinear step reads JSBSim's sideslip, the wind's included (β − v_g/V): the
    coupled model's v_g column is its β column over −V in every row (the rigid rows as
    before, the modes' now that β forces them)."""
    ac, build, p, wing = point
    ss, _, _ = _models(ac, build, p, wing)
    a, b = np.asarray(ss.a), np.asarray(ss.b)
    col = -a[:, ss.states.index("beta")] / p.trim.speed_m_s
    np.testing.assert_allclose(b[:, ss.inputs.index("v_g")], col, rtol=1e-12,
                               atol=1e-15 * np.max(np.abs(col)))
