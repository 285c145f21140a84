"""The yaw rate, sideslip, side force and yawing moment of the full-span step (docs/lateral.md,
"Yaw rate, sideslip, side force and yawing moment of the elastic wing";
bioflex_jsb.simulation.full_span): the strips' sums against strip theory's closed forms on
rigid rectangular and elliptic loadings, the side force of an imposed antisymmetric bending
against its integral, the sign of the adverse yaw, the compiled kernel against the Python step
with sideslip and yaw rate, and the hooks in JSBSim's aircraft."""

from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    dihedral_rad,
    yaw_sideslip_terms,
)
from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing
from bioflex_jsb.generators.airframe import EXTERNAL_FORCES, EXTERNAL_MOMENTS
from bioflex_jsb.runtime.coupled_step import CoupledStep
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation import jsbsim_properties as JP

C172 = "c172_elastic"  # a wing with dihedral (its stations' z_m)
PROTOTYPE = "bioflex_optimised"


@pytest.fixture(scope="module")
def c172():
    return api.load_aircraft(C172)


@pytest.fixture(scope="module")
def c172_wing(c172):
    build = c172.wing()
    return build, antisymmetric_wing(build, 2500.0)


def _loaded(wing, loading: str):
    """``wing`` with the strips' lift per unit α replaced by a rectangular (constant) or
    elliptic (√(1 − (y/s)²)) loading, and one symmetric 'mode' of uniform unit twist (no
    bending): its deflection η_s is a uniform angle of attack, its lift the rigid wing's."""
    y, s = wing.stations_m, float(wing.stations_m[-1] + 0.5 * wing.weights_m[-1])
    shape = np.ones_like(y) if loading == "rectangular" else np.sqrt(1.0 - (y / s) ** 2)
    loaded = dataclasses.replace(wing, cl_alpha_c_m=5.0 * shape)
    grid = np.linspace(0.0, s, 201)
    symmetric = SimpleNamespace(stations_m=grid, twist_rad=np.ones((1, grid.size)),
                                bending_m=np.zeros((1, grid.size)))
    return loaded, symmetric, s


# Strip theory's closed forms (both per C_L of the loading): a yaw rate's rolling moment
# C_lr = 4 ∫ y² l dy / (L b²/2), 1/3 for a rectangular and 1/4 for an elliptic loading; a
# roll rate's lift tilt C_np = −2 ∫ y² l dy / (L b²/2), −1/6 and −1/8. Measured on the
# c172's 40 strips (their control points and widths, the lattice's cosine spacing): both
# within 2.6e-4 (rectangular) and 2.2e-5 (elliptic) of the closed form
CLOSED_FORM = {"rectangular": (1 / 3, -1 / 6, 1e-3), "elliptic": (1 / 4, -1 / 8, 2e-4)}


@pytest.mark.parametrize("loading", ["rectangular", "elliptic"])
def test_yaw_rate_rolling_moment_and_roll_rate_yaw_against_strip_theory(c172_wing, loading):
    """C_lr and C_np of a rigid loading (a uniform angle of attack on the strips) from the
    step's own sums, against strip theory's closed forms; C_lr > 0 (nose right rolls the
    advancing left wing up: right wing down) and C_np < 0 (adverse)."""
    build, wing = c172_wing
    loaded, symmetric, s = _loaded(wing, loading)
    t = yaw_sideslip_terms(loaded, symmetric, 1, build.planform, 2.0 * s)
    q_pa, v, rate, alpha = 2000.0, 50.0, 0.1, 0.05
    lift_n = 2.0 * q_pa * float(loaded.cl_alpha_c_m @ loaded.weights_m) * alpha
    b = 2.0 * s
    hat = rate * b / (2.0 * v)  # r̂ = p̂ = ω b/(2V)
    roll = t.roll_n_m(q_pa, v, rate, 0.0, np.array([alpha]))
    yaw = t.yaw_n_m(q_pa, v, 0.0, rate, np.zeros(wing.n_modes), np.array([alpha]), 0.0)
    # coefficients per unit C_L: moment / (L b) / r̂
    clr, cnp = roll / (lift_n * b) / hat, yaw / (lift_n * b) / hat
    want_lr, want_np, rtol = CLOSED_FORM[loading]
    assert clr == pytest.approx(want_lr, rel=rtol)
    assert cnp == pytest.approx(want_np, rel=rtol)
    assert clr > 0.0 > cnp


def _bent(wing, s: float):
    """``wing`` whose first antisymmetric mode is the bending φ = (y/s)² [m, down] alone."""
    grid = np.linspace(0.0, s, 401)
    bend = np.zeros((wing.n_modes, grid.size))
    bend[0] = (grid / s) ** 2
    modes = SimpleNamespace(stations_m=grid, bending_m=bend,
                            twist_rad=np.zeros_like(bend))
    phi = np.array([np.interp(wing.stations_m, grid, b) for b in bend])
    return dataclasses.replace(wing, modes=modes, phi=phi, theta=np.zeros_like(phi))


# The side force of the bending (y/s)² under the wing's lift L_w, Y = 2 L_w ∫ l̂ dφ/dy dy
# (l̂ the lift per unit span over L_w): rectangular 2 L_w ∫ (1/b)(2y/s²) dy = L_w/s,
# elliptic 8 L_w/(3π s). Measured within 2.0e-7 (rectangular) and 1.9e-4 (elliptic) on the
# c172's strips
SIDE_CLOSED_FORM = {"rectangular": (1.0, 1e-5), "elliptic": (8.0 / (3.0 * math.pi), 1e-3)}


@pytest.mark.parametrize("loading", ["rectangular", "elliptic"])
def test_side_force_of_an_imposed_antisymmetric_bending(c172_wing, loading):
    """A starboard half bent down (tip down, port tip up) leans both halves' lift to
    starboard: Y > 0 along body +y, against the analytic integral."""
    build, wing = c172_wing
    loaded, symmetric, s = _loaded(wing, loading)
    bent = _bent(loaded, s)
    flat = SimpleNamespace(has_dihedral=False)
    t = yaw_sideslip_terms(bent, symmetric, 1, flat, 2.0 * s)
    lift_n, eta = 12000.0, 0.01
    eta_a = np.zeros(wing.n_modes)
    eta_a[0] = eta
    side = t.side_n(2000.0, 50.0, lift_n, eta_a, np.zeros(wing.n_modes))
    want, rtol = SIDE_CLOSED_FORM[loading]
    assert side == pytest.approx(want * lift_n * eta / s, rel=rtol)
    assert side > 0.0
    # a flat wing: no side force from the deformation's own lift (no dihedral to lean on)
    assert np.all(t.side_dihedral_eta == 0.0) and np.all(t.side_dihedral_etadot == 0.0)


def test_adverse_yaw_and_the_induced_drag_of_the_elastic_roll(c172_wing):
    """The signs of the yawing moment: a wing rolling right (p > 0) with more lift (its
    symmetric twist up) yaws left, more so with more lift; an antisymmetric plunge rate of
    the starboard half down (as the roll's onset bends it) tilts its lift forward, nose
    left; an elastic rolling moment to the right (less lift starboard, so less induced drag
    there) yaws left, by α_i = L_w/(Q π b²) of it."""
    build, wing = c172_wing
    loaded, symmetric, s = _loaded(wing, "elliptic")
    t = yaw_sideslip_terms(loaded, symmetric, 1, build.planform, 2.0 * s)
    q_pa, v, lift_n = 2000.0, 50.0, 10000.0
    none = np.zeros(wing.n_modes)
    one = t.yaw_n_m(q_pa, v, lift_n, 0.3, none, np.array([0.02]), 0.0)
    two = t.yaw_n_m(q_pa, v, lift_n, 0.3, none, np.array([0.04]), 0.0)
    assert one < 0.0 and two == pytest.approx(2.0 * one, rel=1e-12)
    plunge = np.zeros(wing.n_modes)
    plunge[0] = 1.0 if wing.phi[0, -1] > 0.0 else -1.0  # starboard tip moving down
    assert t.yaw_n_m(q_pa, v, lift_n, 0.0, plunge, np.zeros(1), 0.0) < 0.0
    induced = t.yaw_n_m(q_pa, v, lift_n, 0.0, none, np.zeros(1), 100.0)
    assert induced == pytest.approx(-lift_n / (q_pa * math.pi * (2.0 * s) ** 2) * 100.0,
                                    rel=1e-12)


def test_the_dihedral_and_the_sideslip_forcing(c172, c172_wing):
    """The c172's geometric dihedral from its stations' heights (0.077 m over 2.54 m inboard,
    0.088 m over 2.916 m outboard) and the sideslip's rolling moment of a symmetric bending
    that raises the tips (more dihedral: wind from the right rolls left)."""
    build, wing = c172_wing
    gamma = dihedral_rad(build.planform, wing.stations_m)
    inboard = wing.stations_m < 2.5
    outboard = wing.stations_m > 2.6
    np.testing.assert_allclose(gamma[inboard], math.atan(0.077 / 2.54), rtol=1e-9)
    np.testing.assert_allclose(gamma[outboard], math.atan(0.088 / 2.916), rtol=1e-9)
    grid = np.linspace(0.0, 5.456, 201)
    up = SimpleNamespace(stations_m=grid, twist_rad=np.zeros((1, grid.size)),
                         bending_m=-(grid / 5.456)[None, :] ** 2)  # tips up
    t = yaw_sideslip_terms(wing, up, 1, build.planform, 2.0 * 5.456)
    assert t.roll_n_m(2000.0, 50.0, 0.0, 0.05, np.array([0.1])) < 0.0
    # the geometric dihedral's forcing is the strips' lift of β Γ on the modes' work
    work = wing.e_m * wing.theta - wing.phi
    np.testing.assert_allclose(t.force_beta, work @ (wing.cl_alpha_c_m * wing.weights_m * gamma),
                               rtol=1e-12)


def _rudder_step(ac, model: str, compiled: bool, duration_s: float = 0.4):
    """(table, names) of a rudder step (sideslip and yaw rate) with an aileron step."""
    a = Airframe() if ac.name == PROTOTYPE else airframe_for(ac)
    speed = 15.0 if ac.name == PROTOTYPE else 57.8
    st = CoupledStep(a, ac.wing(), model, speed, span="full", compiled=compiled,
                     aileron=ac.definition.aileron)
    n = int(round(duration_s / st.dt_s))
    table = np.zeros((n, len(st.names)))
    for k in range(n):
        if k == 10:
            a[JP.FCS_RUDDER_CMD_NORM] = 0.3
            a["fcs/aileron-cmd-norm"] = 0.02
        assert st.advance_into(0.0, table, k, 0.0) is None
    st.release()
    return table, st.names


@pytest.mark.parametrize("name", [PROTOTYPE, C172])
@pytest.mark.parametrize("model", ["coupled", "qsd"])
def test_kernel_matches_the_python_step_in_sideslip(name, model):
    """A rudder and aileron step (β, r, p and the antisymmetric modes all moving): the
    compiled step against the Python one, channel by channel, to 1e-9 of each channel's
    range (tests/test_full_span.py's tolerance); the side force and yawing moment flown."""
    ac = api.load_aircraft(name)
    fast, names = _rudder_step(ac, model, True)
    slow, names_slow = _rudder_step(ac, model, False)
    assert names == names_slow
    for c, channel in enumerate(names):
        a, b = fast[:, c], slow[:, c]
        span = max(np.ptp(b), 1e-300)
        assert np.max(np.abs(a - b)) <= 1e-9 * span + 1e-300, channel
    col = {n: i for i, n in enumerate(names)}
    assert np.ptp(slow[:, col["beta_rad"]]) > 1e-4
    assert np.ptp(slow[:, col["modal_side_n"]]) > 0.0
    assert np.ptp(slow[:, col["modal_yaw_n_m"]]) > 0.0


def test_the_hooks_are_in_jsbsims_aircraft(c172):
    """modal-side (force, body +y) and modal-yaw (moment, body +z) in the generated
    prototype and in another aircraft's copy; set_external_reactions converts N and N·m
    once, at the boundary."""
    assert EXTERNAL_FORCES["modal-side"][0] == (0.0, 1.0, 0.0)
    assert EXTERNAL_MOMENTS["modal-yaw"][0] == (0.0, 0.0, 1.0)
    for airframe in (Airframe(), airframe_for(c172)):
        airframe.set_external_reactions(side_force_n=100.0, yaw_moment_n_m=10.0)
        assert airframe["external_reactions/modal-side/magnitude"] == pytest.approx(
            100.0 / 4.4482216152605, rel=1e-12)
        assert airframe["external_reactions/modal-yaw/magnitude-lbsft"] == pytest.approx(
            10.0 / (4.4482216152605 * 0.3048), rel=1e-12)
        airframe.set_external_reactions()
        assert airframe["external_reactions/modal-side/magnitude"] == 0.0
