"""The wing's antisymmetric modes with the fuselage's roll freedom
(structures/antisymmetric.py) against the closed form of a uniform beam on a rigid central
body and its clamped and pinned limits."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.errors import InputError
from bioflex_jsb.structures.antisymmetric import (
    solve_antisymmetric,
    uniform_beam_antisymmetric_bending_rad_s,
)
from bioflex_jsb.structures.beam import solve_beam, uniform_sections

L, EI, GJ, M_PER_L, I_ALPHA = 1.0, 100.0, 50.0, 2.0, 0.01  # a uniform test beam, SI
SECTIONS = uniform_sections(L, bending_stiffness_n_m2=EI, torsional_stiffness_n_m2=GJ,
                            mass_per_length_kg_m=M_PER_L, torsional_inertia_kg_m=I_ALPHA,
                            chord_m=0.2)


@pytest.mark.parametrize("roll_inertia", [0.0, 0.1, 1.0, 1e6])
def test_antisymmetric_bending_is_the_closed_form(roll_inertia):
    """The first three antisymmetric bending frequencies of the 40-element beam against the
    closed form's characteristic determinant: measured within 2e-8, 2e-7, 1.1e-6 relative
    (the Hermite elements' convergence); the tolerance 1e-5. Between the limits the central
    inertia moves the first from the pinned-free 109.0 rad/s (J = 0: βL = 3.9266) to the
    clamped 24.86 (J → ∞: βL = 1.8751)."""
    sol = solve_antisymmetric(SECTIONS, roll_inertia, n_modes=8)
    bend, twist = sol.sample(np.linspace(0.0, L, 11))
    pure_bending = np.max(np.abs(twist), axis=1) < 1e-6 * np.max(np.abs(bend), axis=1)
    bending = sol.frequencies_rad_s[pure_bending]  # x_I = x_E: bending and twist apart
    closed = uniform_beam_antisymmetric_bending_rad_s(L, EI, M_PER_L, roll_inertia, 3)
    np.testing.assert_allclose(bending[:3], closed, rtol=1e-5)


def _torsion(k: int) -> float:
    """The clamped-free uniform torsion frequency k [rad/s]: (2k − 1) π/(2L) √(GJ/I_α)."""
    return (2 * k - 1) * math.pi / (2 * L) * math.sqrt(GJ / I_ALPHA)


def test_the_limits_are_the_clamped_and_pinned_beams():
    """J → ∞: the clamped beam (1.8751² √(EI/m')/L² = 24.862 rad/s, and solve_beam's);
    J = 0: the pinned-free beam (3.9266²: 109.02 rad/s). The antisymmetric twist is the
    clamped twist (θ(0) = 0 either way): the same frequencies to 1e-12."""
    clamped = solve_beam(SECTIONS, 4).frequencies_rad_s
    stiff = solve_antisymmetric(SECTIONS, 1e9, n_modes=4).frequencies_rad_s
    np.testing.assert_allclose(stiff, clamped, rtol=1e-6)
    assert stiff[0] == pytest.approx(1.87510407**2 * math.sqrt(EI / M_PER_L) / L**2, rel=1e-5)
    free = solve_antisymmetric(SECTIONS, 0.0, n_modes=2).frequencies_rad_s
    assert free[0] == pytest.approx(3.92660231**2 * math.sqrt(EI / M_PER_L) / L**2, rel=1e-5)
    assert free[1] == pytest.approx(clamped[1], rel=1e-12)  # the first torsion mode


def test_the_rigid_roll_is_kept_apart_and_the_elastic_modes_carry_no_roll_momentum():
    """The rigid roll's generalised mass is the half aircraft's roll inertia, m' L³/3 +
    J/2 (exact: the Hermite cubics hold w = φ y); every elastic mode is M-orthogonal to it
    (mean axes: no inertial coupling with the aircraft's roll rate)."""
    from bioflex_jsb.structures.beam import assemble_unrestrained

    j = 0.4
    sol = solve_antisymmetric(SECTIONS, j, n_modes=4)
    assert sol.half_roll_inertia_kg_m2 == pytest.approx(M_PER_L * L**3 / 3 + j / 2, rel=1e-12)
    k_full, m_full, nodes = assemble_unrestrained(SECTIONS)
    keep = np.r_[1, np.arange(3, k_full.shape[0])]
    m = m_full[np.ix_(keep, keep)]
    m[0, 0] += j / 2
    roll = np.r_[1.0, np.column_stack([nodes[1:], np.ones(nodes.size - 1),
                                       np.zeros(nodes.size - 1)]).ravel()]
    assert np.max(np.abs(roll @ m @ sol.vectors)) < 1e-9
    bend, twist = sol.sample(np.array([0.0, L]))
    assert np.all(bend[:, 0] == 0.0) and np.all(twist[:, 0] == 0.0)


def test_a_bad_roll_inertia_is_one_line():
    with pytest.raises(InputError, match="fuselage_roll_inertia_kg_m2"):
        solve_antisymmetric(SECTIONS, -1.0)
