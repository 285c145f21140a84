"""Elastic trim (flight_dynamics/elastic_trim.py): the static aeroelastic equilibrium at a
trim, its refusal beyond the divergence speed, and the linearisation about it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.elastic_trim import (
    ElasticTrim,
    RigidTrimPoint,
    StaticWingLoads,
    divergence_speed_m_s,
    elastic_trim,
    linear_rigid_trim,
    linearise_about_elastic_trim,
)
from bioflex_jsb.flight_dynamics.lti import build_state_space, coupled_blocks
from bioflex_jsb.flight_dynamics.modal_matrices import modal_matrices
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.parameters.airframe import RIGID_AERODYNAMICS as AERO


def _direct_solution(build, v):
    """The fixed point as one linear system in (η, α, δe) with the linear rigid trim."""
    cond = level_flight_condition(v, airframe=PROTOTYPE_AIRFRAME)
    q = cond.dynamic_pressure_pa
    mm = modal_matrices(build.model, cond.cl_trim)
    n = mm.n
    qs, cb = q * P.REFERENCE_AREA_M2, P.MEAN_AERODYNAMIC_CHORD_M
    rigid = linear_rigid_trim(cond)(StaticWingLoads())
    m = np.zeros((n + 2, n + 2))
    rhs = np.zeros(n + 2)
    m[:n, :n] = np.diag(mm.omega**2) - q * mm.k_aero
    m[:n, n] = -q * mm.b_alpha
    rhs[:n] = q * (mm.b_0 - mm.b_alpha * rigid.alpha_rad)
    m[n, :n], m[n, n], m[n, n + 1] = mm.load_eta[0], AERO.cl_alpha_per_rad, AERO.cl_delta_e_per_rad
    rhs[n] = P.MASS_KG * P.STANDARD_GRAVITY_M_S2 / qs - AERO.cl0
    m[n + 1, :n] = mm.load_eta[2] / cb
    m[n + 1, n], m[n + 1, n + 1] = AERO.cm_alpha_per_rad, AERO.cm_delta_e_per_rad
    rhs[n + 1] = -AERO.cm0
    x = np.linalg.solve(m, rhs)
    return x[:n], x[n], x[n + 1]


@pytest.mark.parametrize("wing", ["original", "optimised", "inertial-backward"])
@pytest.mark.parametrize("speed", [15.0, 18.0])
def test_fixed_point_is_the_equilibrium_of_wing_and_trim(wing, speed):
    build = build_wing(VARIANTS[wing])
    t = elastic_trim(build, speed)
    eta, alpha, elevator = _direct_solution(build, speed)
    # the problem is linear: the secant fixed point must equal the direct solve to round-off
    # (1e-9 of the values: a 5x5 solve with condition number < 1e4)
    assert t.converged and t.iterations <= 3
    np.testing.assert_allclose(t.eta_rad, eta, rtol=1e-9, atol=1e-12)
    assert t.alpha_rad == pytest.approx(alpha, abs=1e-11)
    assert t.elevator_rad == pytest.approx(elevator, abs=1e-11)
    assert t.modal_residual < 1e-12  # Ω²η₀ = Q(b_0 + b_α Δα + K_a η₀), round-off only
    # the lift and moment the wing adds are carried by the trim (1e-9 N: round-off)
    qs = t.dynamic_pressure_pa * P.REFERENCE_AREA_M2
    lift = qs * (AERO.cl0 + AERO.cl_alpha_per_rad * t.alpha_rad
                 + AERO.cl_delta_e_per_rad * t.elevator_rad) + t.loads.lift_n
    assert lift == pytest.approx(P.MASS_KG * P.STANDARD_GRAVITY_M_S2, abs=1e-9)
    moment = qs * P.MEAN_AERODYNAMIC_CHORD_M * (
        AERO.cm0 + AERO.cm_alpha_per_rad * t.alpha_rad + AERO.cm_delta_e_per_rad * t.elevator_rad
    ) + t.loads.pitch_moment_n_m
    assert moment == pytest.approx(0.0, abs=1e-9)
    # the tip twist is the modes' tip twist times η₀ (modes normalised on it)
    tip = np.asarray(build.modes.twist_rad)[:, -1] @ t.eta_rad
    assert t.tip_twist_deg == pytest.approx(math.degrees(tip), rel=1e-12)


def test_the_whole_generalised_force_balances_the_structure():
    """C_0,e^Q = m ω² η₀ /(Q S c̄), and H_u about the elastic trim = 2 ω² η₀ / u₀."""
    build = build_wing(VARIANTS["optimised"])
    t = elastic_trim(build, 15.0)
    w = build.model
    sc = P.REFERENCE_AREA_M2 * P.MEAN_AERODYNAMIC_CHORD_M
    np.testing.assert_allclose(
        t.c_0_q_elastic * t.dynamic_pressure_pa * sc,
        w.generalised_masses_kg_m2 * w.frequencies_rad_s**2 * t.eta_rad, rtol=1e-12)
    np.testing.assert_allclose(t.h_u_elastic_per_m,
                               2.0 * w.frequencies_rad_s**2 * t.eta_rad / 15.0, rtol=1e-12)


def test_secant_converges_on_a_nonlinear_rigid_trim():
    """A rigid trim that is not linear in the loads (a stand-in for JSBSim's): the fixed point
    still converges, to the given tolerance, and satisfies α = T(α)."""
    build = build_wing(VARIANTS["original"])
    cond = level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME)
    linear = linear_rigid_trim(cond)

    def curved(loads: StaticWingLoads) -> RigidTrimPoint:
        p = linear(loads)
        return RigidTrimPoint(p.alpha_rad + 0.3 * (p.alpha_rad - 0.03) ** 2, p.elevator_rad)

    t = elastic_trim(build, 15.0, rigid_trim=curved, tol_rad=1e-12)
    assert t.converged and t.iterations <= 8
    mm = modal_matrices(build.model, cond.cl_trim)
    qs = cond.dynamic_pressure_pa * P.REFERENCE_AREA_M2
    lift, drag, moment = qs * (mm.load_eta @ t.eta_rad)
    again = curved(StaticWingLoads(lift, drag, moment))
    assert again.alpha_rad == pytest.approx(t.alpha_rad, abs=1e-11)


def test_beyond_the_divergence_speed_trim_refuses_with_one_line_naming_it():
    from bioflex_jsb.aeroelasticity.free_aircraft import wing_divergence_speed_m_s

    build = build_wing(VARIANTS["inertial-backward"])
    v_d = divergence_speed_m_s(build.model)
    # the closed form (eigenvalues of Ω⁻²K_a) and the scan of det A_EE of Eq. (4) agree to
    # the scan's brentq tolerance (1e-4 m/s)
    assert v_d == pytest.approx(wing_divergence_speed_m_s(build), abs=2e-4)
    assert elastic_trim(build, v_d - 0.05).converged
    with pytest.raises(InputError) as exc:
        elastic_trim(build, v_d + 0.01)
    message = str(exc.value)
    assert "\n" not in message and f"{v_d:.2f} m/s" in message and "divergence" in message
    # the forward and original wings do not diverge (C_η1^Q1 < 0 stiffens the wing)
    assert math.isinf(divergence_speed_m_s(build_wing(VARIANTS["original"]).model))


def test_linearised_about_a_zero_deflection_is_the_paper_model_and_qsd_is_consistent():
    build = build_wing(VARIANTS["optimised"])
    t = elastic_trim(build, 15.0)
    cond = level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME)
    # a trim whose H_u is the paper's gives back build_state_space exactly
    blk = coupled_blocks(build.model, cond)
    paper = ElasticTrim(**{**t.__dict__, "h_u_elastic_per_m": blk.a_er[:, 0].copy()})
    for model in ("coupled", "qsd"):
        base = build_state_space(model, cond, build.model)
        same = linearise_about_elastic_trim(model, paper, build.model)
        np.testing.assert_array_equal(same.a, base.a)
        np.testing.assert_array_equal(same.c, base.c)
    # QSD's deflection output is the coupled model's static solution with the same H_u
    coupled = linearise_about_elastic_trim("coupled", t, build.model)
    qsd = linearise_about_elastic_trim("qsd", t, build.model)
    n = build.model.n_modes
    a_er = coupled.a[4 + n:, :4]
    a_ee = coupled.a[4 + n:, 4:4 + n]
    x_r = np.array([0.3, 0.01, 0.02, 0.0])
    np.testing.assert_allclose(qsd.c[4:] @ x_r, -np.linalg.solve(a_ee, a_er @ x_r), rtol=1e-10)
    assert coupled.notes["trim"] == "elastic"
    np.testing.assert_allclose(coupled.notes["eta_static_rad"], t.eta_rad)


def test_linear_rigid_trim_is_close_to_jsbsim():
    """The default rigid trim against JSBSim's trim of the generated airframe at 15 m/s.
    Tolerance 0.05° on α and 0.15° on δe: the linear model leaves out the thrust's
    component along the lift (T sin α ≈ 1.8 N × 0.03) and the drag's pitching arm."""
    from bioflex_jsb.runtime import fdm as jsbsim_fdm

    jsb = jsbsim_fdm.load_airframe(None, jsbsim_fdm.DEFAULT_AIRCRAFT).trim(15.0)
    lin = linear_rigid_trim(level_flight_condition(15.0,
                                                   airframe=PROTOTYPE_AIRFRAME))(StaticWingLoads())
    assert math.degrees(lin.alpha_rad) == pytest.approx(math.degrees(jsb.alpha_rad), abs=0.05)
    assert math.degrees(lin.elevator_rad) == pytest.approx(math.degrees(jsb.elevator_rad),
                                                           abs=0.15)
