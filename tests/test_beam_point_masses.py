"""Point masses and struts on the beam (structures/beam.py ``PointMass``,
``VerticalSpring``) against closed forms, and their definition fields
(``[[structure.point_masses]]``, ``[[structure.struts]]``, docs/aircraft.md)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.optimize import brentq

from bioflex_jsb.definition import DefinitionError, load_definition
from bioflex_jsb.definition.clamped import beam_sections
from bioflex_jsb.definition.loader import shipped_path
from bioflex_jsb.structures.beam import (
    BeamInputError,
    PointMass,
    VerticalSpring,
    solve_beam,
    uniform_sections,
)

L, EI, GJ, M_PER_L, I_PER_L = 2.0, 1.0e4, 5.0e3, 3.0, 0.05
BASE = uniform_sections(L, bending_stiffness_n_m2=EI, torsional_stiffness_n_m2=GJ,
                        mass_per_length_kg_m=M_PER_L, torsional_inertia_kg_m=I_PER_L,
                        chord_m=0.5)


def _tip_mass_root(ratio: float) -> float:
    """λ of the first bending mode of a uniform cantilever with a tip mass M = ratio m L
    (no rotary inertia): 1 + cos λ cosh λ + ratio λ (cos λ sinh λ - sin λ cosh λ) = 0
    (Blevins, Formulas for Natural Frequency and Mode Shape, Table 8-8; the exact
    Euler-Bernoulli frequency equation), ω = λ² √(EI/(m L⁴))."""
    def f(lam):
        return (1.0 + math.cos(lam) * math.cosh(lam)
                + ratio * lam * (math.cos(lam) * math.sinh(lam) - math.sin(lam) * math.cosh(lam)))
    return brentq(f, 0.3, 1.8751041 + 1e-6)


@pytest.mark.parametrize("ratio", [0.2, 1.0, 5.0])
def test_tip_mass_first_bending_against_the_exact_frequency_equation(ratio):
    # Measured with 40 elements: +9.6e-10, +7.1e-11, -4.8e-11 (the Hermite element is
    # exact for the cubic statics; the mass is put with the element's own shape functions);
    # bar 1e-6. Rayleigh's/Blevins' one-term estimate √(3EI/(L³(M + 0.24 m L))) is within
    # 0.43 %, 0.054 %, 0.003 % of it (it improves as the tip mass dominates); bar 1 %.
    tip = ratio * M_PER_L * L
    sections = replace(BASE, point_masses=(PointMass(L, tip, 0.5),))
    omega = solve_beam(sections, 2, 40).frequencies_rad_s[0]
    exact = _tip_mass_root(ratio) ** 2 * math.sqrt(EI / (M_PER_L * L**4))
    rayleigh = math.sqrt(3.0 * EI / (L**3 * (tip + 0.2357 * M_PER_L * L)))
    print(f"tip mass {ratio} m L: FE {omega:.8g}, exact {exact:.8g} rad/s; "
          f"Rayleigh {rayleigh / exact - 1:+.2e}")
    assert omega == pytest.approx(exact, rel=1e-6)
    assert rayleigh == pytest.approx(exact, rel=1e-2)
    assert sections.half_wing_mass_kg == pytest.approx(M_PER_L * L + tip, rel=1e-15)


@pytest.mark.parametrize("ratio", [0.5, 2.0])
def test_tip_pitch_inertia_first_torsion_against_the_exact_equation(ratio):
    # A shaft with a tip disc of inertia J = ratio I' L: β tan β = I' L / J, ω = (β/L)
    # √(GJ/I') (Blevins, Table 8-19's torsion analogue of the tip mass). Measured with 40
    # linear torsion elements: +1.3e-5, +1.7e-6 (the h² error of the linear element); bar
    # 1e-4.
    disc = ratio * I_PER_L * L
    sections = replace(BASE, point_masses=(PointMass(L, 1e-9, 0.5, disc),))
    sol = solve_beam(sections, 4, 40)
    torsion = sol.frequencies_rad_s[sol.torsion_energy_fraction > 0.5][0]
    beta = brentq(lambda b: b * math.tan(b) - 1.0 / ratio, 1e-6, math.pi / 2 - 1e-9)
    exact = beta / L * math.sqrt(GJ / I_PER_L)
    assert torsion == pytest.approx(exact, rel=1e-4)


def test_stiff_strut_at_the_tip_gives_the_propped_cantilever():
    # a very stiff vertical spring at the tip pins it: clamped-pinned beam, λ = 3.92660
    # (Blevins Table 8-1); measured +5.1e-8 with k = 1e9 EI/L³; bar 1e-6
    sections = replace(BASE, springs=(VerticalSpring(L, 1e9 * EI / L**3),))
    omega = solve_beam(sections, 2, 40).frequencies_rad_s[0]
    assert omega == pytest.approx(3.92660231**2 * math.sqrt(EI / (M_PER_L * L**4)), rel=1e-6)
    # a soft one moves it a little above the cantilever's 1.8751²: between the two
    soft = replace(BASE, springs=(VerticalSpring(0.6 * L, 0.5 * EI / L**3),))
    free = solve_beam(BASE, 1, 40).frequencies_rad_s[0]
    assert free < solve_beam(soft, 1, 40).frequencies_rad_s[0] < omega


def test_offset_point_mass_is_the_same_as_that_mass_smeared_over_a_short_span():
    # an engine 0.3 c ahead of the leading edge, with its own pitch inertia, against the
    # same mass, static moment and inertia spread over one element (2 cm of 2 m, between
    # two nodes: the distributed mass matrix's exact quadrature; an independent path). The
    # two differ by the smear's width: measured 1.3e-5, 1.2e-5, 3.8e-5 on the first three
    # modes (a quarter of that with half the width: the width squared); bar 1e-4.
    n, h = 100, L / 100
    y0, mass, x_frac, own = 55.5 * h, 4.0, -0.3, 0.02
    lumped = replace(BASE, x_elastic_frac=np.full(2, 0.35), x_inertial_frac=np.full(2, 0.35),
                     point_masses=(PointMass(y0, mass, x_frac, own),))
    d = lumped.point_mass_offset_m(lumped.point_masses[0])
    assert d == pytest.approx((x_frac - 0.35) * 0.5)
    eps = 1e-9 * L
    y = np.array([0.0, 55 * h, 55 * h + eps, 56 * h - eps, 56 * h, L])
    inside = np.array([False, False, True, True, False, False])
    m_extra = mass / h
    m = M_PER_L + np.where(inside, m_extra, 0.0)
    x_i = (0.35 * M_PER_L + np.where(inside, m_extra * x_frac, 0.0)) / m
    i_ea = I_PER_L + np.where(inside, (own + mass * d * d) / h, 0.0)
    smeared = replace(BASE, stations_m=y, bending_stiffness_n_m2=np.full(6, EI),
                      torsional_stiffness_n_m2=np.full(6, GJ), mass_per_length_kg_m=m,
                      torsional_inertia_kg_m=i_ea, chord_m=np.full(6, 0.5),
                      x_elastic_frac=np.full(6, 0.35), x_inertial_frac=x_i)
    a = solve_beam(lumped, 3, n).frequencies_rad_s
    b = solve_beam(smeared, 3, n).frequencies_rad_s
    print("point vs smeared:", a / b - 1.0)
    assert np.allclose(a, b, rtol=1e-4, atol=0.0)
    assert not np.allclose(a, solve_beam(BASE, 3, n).frequencies_rad_s, rtol=1e-2)
    # and the mass ahead of the axis couples bending and torsion
    coupled = solve_beam(lumped, 3, 40).torsion_energy_fraction
    assert np.all((coupled > 1e-6) & (coupled < 1 - 1e-6))


def test_point_masses_and_springs_are_checked():
    with pytest.raises(BeamInputError, match="outside the beam"):
        replace(BASE, point_masses=(PointMass(L * 1.01, 1.0, 0.5),))
    with pytest.raises(BeamInputError, match="mass_kg must be positive"):
        replace(BASE, point_masses=(PointMass(1.0, 0.0, 0.5),))
    with pytest.raises(BeamInputError, match="stiffness_n_m"):
        replace(BASE, springs=(VerticalSpring(1.0, -1.0),))


SGS_WING = shipped_path("sgs_wing").read_text(encoding="utf-8")


def _with(tmp_path, extra: str):
    path = tmp_path / "wing.toml"
    path.write_text(SGS_WING.replace("[air]", extra + "\n[air]", 1), encoding="utf-8")
    return path


def test_point_masses_and_struts_are_read_into_the_beam(tmp_path):
    path = _with(tmp_path, """
[[structure.point_masses]]
name = "fuel"
y_m = 2.0
mass_kg = 40.0
chord_position = 0.3
pitch_inertia_kg_m2 = 1.5

[[structure.point_masses]]
y_m = 7.036
mass_kg = 2.0
chord_position = -0.2

[[structure.struts]]
y_m = 3.0
stiffness_n_m = 2.0e6
""")
    d = load_definition(path)
    sections = beam_sections(d)
    assert sections.point_masses == (PointMass(2.0, 40.0, 0.3, 1.5, "fuel"),
                                     PointMass(7.036, 2.0, -0.2, 0.0, ""))
    assert sections.springs == (VerticalSpring(3.0, 2.0e6, ""),)
    assert "2 point mass(es), 42 kg; 1 strut(s)" in sections.description
    # heavier and propped: the first bending frequency moves (down with the masses, up
    # with the strut), so the fields reach the solver
    plain = beam_sections(load_definition("sgs_wing"))
    f_plain = solve_beam(plain, 1).frequencies_rad_s[0]
    f_mass = solve_beam(replace(sections, springs=()), 1).frequencies_rad_s[0]
    f_both = solve_beam(sections, 1).frequencies_rad_s[0]
    assert f_mass < f_plain < f_both


@pytest.mark.parametrize("extra, field", [
    ("[[structure.point_masses]]\ny_m = 0.0\nmass_kg = 1.0\nchord_position = 0.3",
     "point_masses[0].y_m"),
    ("[[structure.point_masses]]\ny_m = 8.0\nmass_kg = 1.0\nchord_position = 0.3",
     "point_masses[0].y_m"),
    ("[[structure.point_masses]]\ny_m = 1.0\nmass_kg = 1.0\nchord_position = 30",
     "point_masses[0].chord_position"),
    ("[[structure.point_masses]]\ny_m = 1.0\nmass_kg = -1.0\nchord_position = 0.3",
     "point_masses[0].mass_kg"),
    ("[[structure.point_masses]]\ny_m = 1.0\nmass_kg = 1.0\nchord_position = 0.3\nx = 1",
     "point_masses[0]: unknown key 'x'"),
    ("[[structure.struts]]\ny_m = 1.0\nstiffness_n_m = 0.0", "struts[0].stiffness_n_m"),
    ("[[structure.struts]]\nstiffness_n_m = 1e6", "struts[0].y_m"),
])
def test_bad_point_masses_and_struts_are_one_line(tmp_path, extra, field):
    with pytest.raises(DefinitionError) as err:
        load_definition(_with(tmp_path, extra))
    text = str(err.value)
    assert f"structure.{field}" in text and "\n" not in text
