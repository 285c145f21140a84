"""Rigid derivatives identified from JSBSim aircraft (runtime/identification.py) checked
against the aircraft's own XML, against the exact linearisation of the same JSBSim model at
the same trim, and against JSBSim's own FGLinearization (issue: "its rigid short period
agrees with JSBSim's own linearisation")."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.flight_dynamics.rigid import (
    level_flight_condition,
    rigid_derivatives,
    rigid_matrices,
)
from bioflex_jsb.parameters.airframe import AirframeData
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.identification import identify_point
from bioflex_jsb.runtime.jsbsim_aircraft import probe
from bioflex_jsb.runtime.linearization import rigid_jacobian

jsbsim = pytest.importorskip("jsbsim")
PACKAGE = Path(jsbsim.get_default_root_dir()) / "aircraft"


def _setup(name: str, speed: float):
    path = str(PACKAGE / name / f"{name}.xml")
    values = probe(path)
    from bioflex_jsb.parameters.airframe import MassProperties, ReferenceGeometry

    ref = ReferenceGeometry(values.reference_area_m2, values.span_m, values.mean_chord_m)
    i = values.inertia
    mass = MassProperties(values.mass_kg, i.ixx_kg_m2, i.iyy_kg_m2, i.izz_kg_m2, i.ixz_kg_m2)
    airframe = Airframe.from_file(path, values.cg_m, name)
    point = identify_point(airframe, speed, ref, values.mass_kg)
    data = AirframeData(name, ref, mass, point.aero, None)
    a_model, _ = rigid_matrices(rigid_derivatives(level_flight_condition(speed, 1.225,
                                                                         airframe=data)))
    return airframe, point, a_model


def _modes(a: np.ndarray) -> tuple[complex, complex]:
    """(short-period, phugoid) eigenvalues with positive imaginary part (or the larger real
    root of an over-damped short period)."""
    eig = np.linalg.eigvals(a)
    eig = sorted(eig, key=abs)
    phugoid = max(eig[:2], key=lambda z: z.imag)
    short = max(eig[2:], key=lambda z: (z.imag, z.real))
    return short, phugoid


def test_c172p_derivatives_are_its_xml_coefficients():
    """Where c172p.xml gives a derivative as a constant, the identification returns it (the
    central differences of a linear term are exact to rounding; 1e-6 relative): CLq 3.9,
    CLadot 1.7, CLDe 0.43, Clda 0.229, CYdr 0.187 (c172p.xml, aerodynamics). A change of
    0.1 % in any of them fails."""
    _, point, _ = _setup("c172p", 50.0)
    a = point.aero
    for field, xml in (("cl_q_per_rad", 3.9), ("cl_alphadot_per_rad", 1.7),
                       ("cl_delta_e_per_rad", 0.43), ("cl_delta_a_per_rad", 0.229),
                       ("cy_delta_r_per_rad", 0.187)):
        assert getattr(a, field) == pytest.approx(xml, rel=1e-6), field


# Speeds: each aircraft's cruise, inside its trim range (runtime/jsbsim_aircraft.py).
CASES = [("c172p", 55.0), ("J3Cub", 30.0), ("pa28", 50.0), ("737", 100.0)]


@pytest.mark.parametrize("name, speed", CASES)
def test_the_identified_model_is_the_exact_linearisation_of_jsbsims(name, speed):
    """The rigid block built from the identified derivatives (Table B2 with C_Lq, C_Lα̇,
    the speed and thrust derivatives) against central differences of JSBSim's own state
    derivatives at the same trim with α̇ converged and the propellers at their steady RPM
    (linearization.rigid_jacobian): the short-period and phugoid eigenvalues within 0.6 %
    of their modulus. Measured (short period / phugoid): c172p 0.006 % / 0.013 %, J3Cub
    (over-damped short period) 0.04 % / 0.40 %, pa28 0.003 % / 0.012 %, 737 0.006 % /
    0.04 %; what is left is the level-flight idealisation (W/(Q S) for C_L, thrust along
    the trim's stability axis, g 9.80665 against JSBSim's 9.806 at 45°). JSBSim's model is
    deterministic: the spread across processors is far below these."""
    airframe, point, a_model = _setup(name, speed)
    airframe.trim(speed)
    with airframe.capturing():
        a_jsbsim = rigid_jacobian(airframe.jsbsim, powered=True)
    for mine, theirs in zip(_modes(a_model), _modes(a_jsbsim), strict=True):
        assert abs(mine - theirs) <= 6e-3 * abs(theirs), (name, mine, theirs)


@pytest.mark.parametrize("name, speed", CASES)
def test_the_short_period_agrees_with_fglinearization(name, speed):
    """JSBSim's own FGLinearization of the same trimmed aircraft (runtime/fdm.py
    linearize, the RPM residualised): the short period within 1 % of its modulus (measured
    c172p 0.006 %, J3Cub 0.03 %, pa28 0.11 %, 737 0.008 %). Its phugoid is not compared:
    FGLinearization reads α̇ from JSBSim's auxiliary model, which computes it from the
    previous evaluation's body accelerations, so its Z_u depends on what was evaluated
    before it (pa28 at 50 m/s: a phugoid of 0.339 rad/s after an identification, 0.247 after
    a trim alone, against 0.261 from the converged central differences of
    test_the_identified_model_is_the_exact_linearisation_of_jsbsims and of the identified
    model); the exact linearisation is that test's reference."""
    airframe, point, a_model = _setup(name, speed)
    lin = airframe.linearize(speed)
    short, _ = _modes(a_model)
    j_short, _ = _modes(lin.a)
    assert abs(short - j_short) <= 1e-2 * abs(j_short), (name, short, j_short)


def test_the_stall_and_the_speeds_of_the_c172():
    """c172p.xml's CLwbh table peaks at 1.5 (0.3 rad): the identified C_L,max; its stall
    speed at 852.8 kg (its pilot and fuel), sea level, 23.7 m/s (46 kt; the C172P's
    handbook gives 44-48 kt with the flaps up, by weight and CG)."""
    _, point, _ = _setup("c172p", 50.0)
    assert point.aero.cl_max == pytest.approx(1.5, rel=2e-3)
    stall = math.sqrt(2 * 852.75 * 9.80665 / (1.225 * 16.165 * point.aero.cl_max))
    assert 22.5 < stall < 24.7
