"""The aileron in the public lateral model (api.lateral_model, coupled and qsd): its
generalised force on the antisymmetric modes against the strip integral, the steady roll
rate per aileron against the aileron-effectiveness analysis (``bioflex-jsb aileron
--aircraft``), and the one builder that the API and ``compare --span full`` share
(aeroelasticity/antisymmetric_strips.py lateral_model_with_aileron; docs/lateral.md)."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aeroelasticity.control_surface import (
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
)
from bioflex_jsb.drivers.compare_lateral import full_span_lateral_model
from bioflex_jsb.flight_dynamics.lateral_elastic import (
    antisymmetric_wing,
    build_lateral_elastic,
    residualised,
)
from bioflex_jsb.parameters.airframe import REFERENCE_GEOMETRY
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.identification import identify_lateral

pytest.importorskip("jsbsim")

PROTOTYPE = "bioflex_optimised"
SPEED_M_S = 15.0  # its cruise [m/s]


@pytest.fixture(scope="module")
def prototype():
    """The prototype (its estimated outboard aileron, 0.51-0.85 m, hinge 0.75 c), its API
    models and the independently identified point the API's prototype is trimmed at."""
    ac = api.load_aircraft(PROTOTYPE)
    point = identify_lateral(Airframe(), SPEED_M_S, REFERENCE_GEOMETRY)
    models = {m: api.lateral_model(ac, SPEED_M_S, m) for m in ("rigid", "coupled", "qsd")}
    return ac, point, models


def test_the_coupled_models_aileron_column_on_the_modes_is_the_strip_integral(prototype):
    """B[η̇_i, aileron] = −Q F^δ_i / m_i (δ_s = −δa, the starboard surface trailing edge
    down), F^δ_i = Σ_k w_k χ_k [C_lα c_k (c_lδ/2π)(e_k θ_ik − φ_ik) + c_k² c_mδ θ_ik] over
    the lattice's strips the aileron covers (thin aerofoil: c_lδ 3.826, c_mδ −0.650 /rad
    for the 25 % flap); the rigid rows stay JSBSim's C_lδa. Measured: the two agree to
    round-off (1e-15 of the column)."""
    ac, point, models = prototype
    build = ac.wing()
    surface = ac.definition.aileron
    wing = antisymmetric_wing(build, point.trim.ixx_kg_m2)
    chord = np.asarray(build.aero.chord_m, dtype=float)
    chi = strip_coverage(wing.weights_m, surface)
    assert chi.sum() > 0.0
    flap_lift = wing.cl_alpha_c_m * flap_lift_slope_per_rad(surface.hinge) / TWO_PI
    flap_moment = chord**2 * flap_moment_slope_per_rad(surface.hinge)
    force = np.array([np.sum(wing.weights_m * chi * (flap_lift * (wing.e_m * th - ph)
                                                     + flap_moment * th))
                      for th, ph in zip(wing.theta, wing.phi, strict=True)])
    want = -point.trim.dynamic_pressure_pa * force / wing.modes.generalised_masses_kg_m2
    ss, rigid = models["coupled"], models["rigid"]
    col = ss.inputs.index("aileron")
    rows = [ss.states.index(f"eta{i + 1}_dot") for i in range(wing.n_modes)]
    np.testing.assert_allclose(ss.b[rows, col], want, rtol=1e-12, atol=0.0)
    assert np.all(np.abs(want) > 1e3)  # the modes are loaded (6.9e4, −2.4e4, −2.3e4 /s²)
    np.testing.assert_array_equal(ss.b[:4, col], rigid.b[:4, col])
    assert "0.51-0.85 m" in ss.notes["aileron_on_modes"]


def test_the_qsd_model_is_the_coupled_one_residualised_with_its_aileron(prototype):
    """qsd: the coupled model's modes residualised, the aileron's load in their balance;
    without it (a wing without an aileron) the qsd model is build_lateral_elastic('qsd')."""
    ac, point, models = prototype
    want = residualised(models["coupled"])
    for m in ("a", "b", "c", "d"):
        np.testing.assert_array_equal(getattr(models["qsd"], m), getattr(want, m), err_msg=m)
    wing = antisymmetric_wing(ac.wing(), point.trim.ixx_kg_m2)
    bare = build_lateral_elastic("qsd", point.trim, point.aero, wing)
    plain = residualised(build_lateral_elastic("coupled", point.trim, point.aero, wing))
    np.testing.assert_allclose(plain.b, bare.b, rtol=1e-9, atol=1e-12 * np.abs(bare.b).max())
    # the reversed aileron: its load on the modes turns the roll the other way
    col = models["qsd"].inputs.index("aileron")
    assert models["rigid"].b[1, col] > 0.0 > models["qsd"].b[1, col]


def test_the_qsd_steady_roll_rate_is_the_aileron_analysis(prototype):
    """The steady roll rate per aileron (ṗ = 0 on the roll row alone: p = −L'_δa/L'_p, exact
    here as the prototype's I_xz = 0) of the API's qsd model against ``bioflex-jsb aileron
    --aircraft bioflex_optimised`` at 15 m/s (api.aileron_effectiveness, its
    ``at_reference_speed``), p b/(2V) per rad of aileron.

    The analysis is of the wing's strips alone (rigid C_lδ 0.3702, C_lp −0.6598); the
    lateral model's rigid part is the JSBSim airframe's (the prototype's estimates C_lδa
    0.20, C_lp −0.45). So the model's elastic increments (qsd minus rigid, the modes') are
    put on the analysis's rigid wing: measured −0.192765 against the analysis's −0.192676
    (4.6e-4: the free-free antisymmetric modes against the clamped flown ones), rigid
    0.561138 both. With the aileron's load left off the modes (the aileron on the rigid
    moment only) the same sum gives +0.991, the wrong sign. On the JSBSim derivatives the
    model's own is −1.479 (rigid 0.444): the prototype's estimated tables, not the strips."""
    ac, point, models = prototype
    analysis = api.aileron_effectiveness(ac)
    assert analysis.reference["speed_m_s"] == SPEED_M_S
    rigid, qsd = models["rigid"], models["qsd"]
    assert point.trim.ixz_kg_m2 == 0.0
    col = qsd.inputs.index("aileron")
    p = qsd.states.index("p")
    derivs = rigid.notes["derivatives"]
    # the rigid roll row on the analysis's wing: the same q S b / I_xx, its coefficients
    lp = rigid.a[p, p] * analysis.cl_p_per_rad / derivs["cl_p"]
    lda = rigid.b[p, col] * analysis.cl_delta_per_rad / derivs["cl_delta_a"]
    d_lp, d_lda = qsd.a[p, p] - rigid.a[p, p], qsd.b[p, col] - rigid.b[p, col]
    to_hat = point.trim.span_m / (2.0 * SPEED_M_S)  # p̂ = p b/(2V) per p [s]
    assert -lda / lp * to_hat == pytest.approx(analysis.rigid_roll_rate_per_rad, rel=1e-9)
    elastic = -(lda + d_lda) / (lp + d_lp) * to_hat
    assert elastic == pytest.approx(analysis.reference["roll_rate_per_rad"], rel=1e-3)
    own = -qsd.b[p, col] / qsd.a[p, p] * to_hat
    assert own == pytest.approx(-1.479, abs=2e-3)


def test_compare_and_the_api_build_one_model(prototype):
    """compare --span full's lateral model (drivers/compare_lateral.py, at the same trim) is
    the API's: A and the aileron column equal."""
    ac, _, models = prototype
    for model in ("coupled", "qsd"):
        lm = full_span_lateral_model(ac.wing(), Airframe(), model, SPEED_M_S,
                                     ac.definition.aileron)
        ss = models[model]
        np.testing.assert_array_equal(lm.ss.a, ss.a)
        np.testing.assert_array_equal(lm.ss.b[:, lm.ss.inputs.index("aileron")],
                                      ss.b[:, ss.inputs.index("aileron")])


def test_an_aircraft_without_an_aileron_has_none_on_its_modes():
    """The c172_elastic's definition has no [aileron]: its modes' aileron column is zero and
    the model says so (its roll by aileron is JSBSim's C_lδa alone)."""
    ss = api.lateral_model(api.load_aircraft("c172_elastic"), None, "coupled")
    col = ss.inputs.index("aileron")
    assert not np.any(ss.b[4:, col])
    assert ss.notes["aileron_on_modes"].startswith("none")


@pytest.mark.parametrize("name", [PROTOTYPE, "c172_elastic"])
def test_the_unsteady_api_model_is_the_coupled_one_with_the_unsteady_strips(name):
    """api.lateral_model(..., "coupled", aero="unsteady") at the aircraft's cruise: its
    quasi-steady part is the API's coupled model (the aileron's load on the modes, the yaw
    rate's and sideslip's terms), so in a steady state every input's response of β … η̇
    and n_y is the coupled model's (measured 7e-15 of the largest state, 9e-16 of n_y,
    prototype; 9e-17, 4e-16, c172); the notes say both terms, the lag states follow η̇."""
    ac = api.load_aircraft(name)
    qs = api.lateral_model(ac, None, "coupled")
    u = api.lateral_model(ac, None, "coupled", aero="unsteady")
    assert u.model == "unsteady-lateral" and u.speed_m_s == qs.speed_m_s
    n0 = qs.n_states
    assert u.states[:n0] == qs.states and u.states[n0] == "lag1[0]"
    assert u.inputs == qs.inputs and u.outputs[-1] == "n_y"
    for key in ("aileron_on_modes", "yaw_sideslip"):
        assert u.notes[key] == qs.notes[key]
    x_u, x_q = np.linalg.solve(u.a, -u.b), np.linalg.solve(qs.a, -qs.b)
    y_u = u.c[-1] @ x_u + u.d[-1]
    y_q = qs.c[qs.outputs.index("n_y")] @ x_q + qs.d[qs.outputs.index("n_y")]
    assert np.max(np.abs(x_u[:n0] - x_q)) < 1e-10 * np.max(np.abs(x_q))
    assert np.max(np.abs(y_u - y_q)) < 1e-10 * np.max(np.abs(y_q))
