"""The geometry-consistent aircraft (parameters/airframe_consistent.py): its derivatives are
the wing + tail lattice's, its one calibration holds Table 3, the defaults are untouched,
and the helpers that run the paper's tables with either set are the library's own."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.aerodynamics.vortex_lattice import solve_spanwise_aerodynamics
from bioflex_jsb.aerodynamics.wing_tail import (
    prolate_spheroid_apparent_mass_factor,
    wing_tail_derivatives,
)
from bioflex_jsb.aeroelasticity.free_aircraft import unsteady_state_space
from bioflex_jsb.aeroelasticity.parameter_set import unsteady_state_space_with
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.consistent_aircraft import (
    AIRCRAFT_SETS,
    consistent_derivatives,
    flutter_with,
    modes_with,
    rigid_short_period,
)
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters import airframe as default_set
from bioflex_jsb.parameters import airframe_consistent as C
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM

ROOT = Path(__file__).resolve().parents[1]
STORED = ("cl_alpha_per_rad", "cm_alpha_per_rad", "cm_q_per_rad", "cm_alphadot_per_rad",
          "cl_delta_e_per_rad", "cm_delta_e_per_rad", "cm0")


@pytest.fixture(scope="module")
def computed():
    return consistent_derivatives()


def test_stored_derivatives_are_the_geometrys(computed):
    # the parameter file stores 4-5 significant figures of the computation: 0.1 %
    for name in STORED:
        assert getattr(C.RIGID_AERODYNAMICS, name) == pytest.approx(
            getattr(computed.aero, name), rel=1e-3), name
    # every other coefficient is the default set's
    rest = {k: v for k, v in C.RIGID_AERODYNAMICS.__dict__.items() if k not in STORED}
    assert rest == {k: v for k, v in default_set.RIGID_AERODYNAMICS.__dict__.items()
                    if k not in STORED}
    assert C.PLANFORM == replace(DEFAULT_PLANFORM, x_cg_m=C.CG_X_M)


def test_the_one_calibration_holds_table3_rigid_rows(computed):
    # calibrated: the CG gives Table 3's rigid natural frequency at 15 m/s (stored CG to 5
    # figures: 0.1 % on |λ|)
    table = P.TABLE3_SHORT_PERIOD
    target = abs(complex(*table[(15.0, "rigid")]))
    assert abs(rigid_short_period(computed.aero, 15.0)) == pytest.approx(target, rel=1e-3)
    # what follows: both rigid rows within the 5 % on real and imaginary parts
    for v in (15.0, 20.0):
        paper = complex(*table[(v, "rigid")])
        got = rigid_short_period(C.RIGID_AERODYNAMICS, v)
        assert abs(got.real - paper.real) <= 0.05 * abs(paper.real)
        assert abs(got.imag - paper.imag) <= 0.05 * abs(paper.imag)


def test_defaults_are_untouched():
    """The consistent set is a second set, not the default (Tables 3, 6, golden cases)."""
    a = default_set.RIGID_AERODYNAMICS
    assert (a.cl_alpha_per_rad, a.cm_alpha_per_rad, a.cm_q_per_rad, a.cm_alphadot_per_rad) == (
        5.3, -1.05, -7.3, -2.5)
    assert DEFAULT_PLANFORM.x_cg_m == pytest.approx(0.30 * P.MEAN_AERODYNAMIC_CHORD_M)
    assert AIRCRAFT_SETS["default"].aero is a
    assert AIRCRAFT_SETS["default"].planform is DEFAULT_PLANFORM


def test_the_lattice_is_the_wing_solvers_and_converged(computed):
    lat = computed.lattice
    wing = solve_spanwise_aerodynamics(DEFAULT_PLANFORM)
    # the wing alone is the wing-only solver's lattice: same aerodynamic centre (round-off)
    assert lat.wing_ac_x_m == pytest.approx(wing.wing_ac_x_m, rel=1e-9)
    # in the combination the tail's upwash raises the wing's share by under 1.5 %
    assert lat.cl_alpha_wing == pytest.approx(wing.wing_lift_slope_per_rad, rel=0.015)
    # tail lattice converged: doubling its panels moves the derivatives by < 0.5 %, the
    # elevator's by < 2.5 % (a flap's load has a log singularity at the hinge: lattice flap
    # derivatives converge like 1/n; they enter only the trim elevator, not Tables 3 and 6)
    fine = wing_tail_derivatives(
        DEFAULT_PLANFORM, C.TAIL, tail_height_m=C.TAIL.height_m, x_cg_m=C.CG_X_M,
        cbar_m=P.MEAN_AERODYNAMIC_CHORD_M, tail_efficiency=C.TAIL.efficiency,
        elevator_chord_fraction=C.TAIL.elevator_chord_fraction,
        tail_n_spanwise=32, tail_n_chordwise=20)
    for name in ("cl_alpha", "cm_alpha", "cm_q", "cm_alphadot"):
        assert getattr(fine, name) == pytest.approx(getattr(lat, name), rel=5e-3), name
    for name in ("cl_delta_e", "cm_delta_e"):
        assert getattr(fine, name) == pytest.approx(getattr(lat, name), rel=0.025), name
    # downwash at the tail of an AR 9.3 wing: below the far-wake 2 C_Lα/(π AR) = 0.32·…,
    # within 15 % of it (the tail sits 2.4 c̄ behind the wing's AC)
    far = 2.0 * wing.wing_lift_slope_per_rad / (math.pi * wing.aspect_ratio)
    assert lat.downwash_gradient == pytest.approx(far, rel=0.15)


def test_spheroid_apparent_mass():
    # Lamb §373: k₂ − k₁ → 1 for a slender spheroid; 0.945 at fineness 10.6 (tabulated k₁
    # 0.021, k₂ 0.960 at fineness 10; 1e-2 covers the interpolation)
    assert prolate_spheroid_apparent_mass_factor(10.0) == pytest.approx(0.960 - 0.021, abs=1e-2)
    assert prolate_spheroid_apparent_mass_factor(1000.0) == pytest.approx(1.0, abs=1e-3)


def test_tracking_with_the_default_set_is_eigens():
    build = build_wing(VARIANTS["inertial-backward"])
    aero = AIRCRAFT_SETS["default"].aero
    ours = modes_with("coupled", [15.0, 20.0], build.model, aero)
    theirs = eigen.modes_at("coupled", [15.0, 20.0], build.model)
    for a, b in zip(ours, theirs, strict=True):
        assert a.as_dict() == b.as_dict()
    # same scan and bisection: within the bisection tolerance (0.01 m/s) twice
    assert flutter_with(build.model, aero).flutter_speed_m_s == pytest.approx(
        eigen.find_flutter(build.model).flutter_speed_m_s, abs=0.02)


@pytest.mark.parametrize("set_name", ["default", "consistent"])
def test_exchanged_unsteady_system(set_name):
    aset = AIRCRAFT_SETS[set_name]
    build = build_wing(VARIANTS["elastic-backward"], planform=aset.planform)
    ss = unsteady_state_space_with(build, 17.0, aset.aero, aset.planform)
    if set_name == "default":  # nothing exchanged: free_aircraft's own system, bit for bit
        ref = unsteady_state_space(build, 17.0)
        np.testing.assert_array_equal(ss.a, ref.a)
        np.testing.assert_array_equal(ss.b, ref.b)
    # a steady state of the unsteady system is the set's quasi-steady Eq. (4) (the strips'
    # increments vanish in a steady state): static gust response to round-off (1e-9)
    qs = build_state_space("coupled", level_flight_condition(17.0, aero=aset.aero,
                                                             airframe=PROTOTYPE_AIRFRAME),
                           build.model, aset.aero)
    n0 = qs.n_states
    steady = -np.linalg.solve(ss.a, ss.b)[:n0]
    np.testing.assert_allclose(steady, -np.linalg.solve(qs.a, qs.b), rtol=1e-9, atol=1e-12)


@pytest.mark.slow  # the whole script in a child process: 15.6 s measured; full suite only
def test_script_json():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "consistent_aircraft.py"),
                          "--json"], capture_output=True, text=True, check=True, cwd=ROOT)
    data = json.loads(out.stdout)
    assert all(data["geometry"]["computed_matches_stored"].values())
    assert {r["name"] for r in data["derivatives"]} >= {"C_L_alpha", "C_m_q"}
    rows = [r for r in data["published_tables"] if r["model"] == "rigid"]
    assert all(max(map(abs, r["consistent_error"])) <= 0.05 for r in rows)
    assert len(data["six_wings"]) == len(VARIANTS)
