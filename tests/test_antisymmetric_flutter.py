"""Unsteady strips on the antisymmetric modes and antisymmetric flutter
(aeroelasticity/antisymmetric.py): the clamped wing's two problems are one, the roll freedom's
clamped limit, the quasi-steady limit of the unsteady lateral model, the prototype's wings."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aerodynamics.indicial import JONES_WAGNER
from bioflex_jsb.aeroelasticity import antisymmetric as A
from bioflex_jsb.aeroelasticity.clamped_wing import clamped_wing_model, goland_sections
from bioflex_jsb.aeroelasticity.state_space import state_space_flutter
from bioflex_jsb.errors import InputError
from bioflex_jsb.parameters import goland as G
from bioflex_jsb.structures.antisymmetric import solve_antisymmetric


def _goland():
    return clamped_wing_model(goland_sections(inertia_about=G.DEFAULT_INERTIA_AXIS))


@pytest.mark.parametrize("aero, speed", [("unsteady", 137.347), ("quasi-steady", 64.531)])
def test_clamped_antisymmetric_flutter_is_the_symmetric_one(aero, speed):
    # A clamped root: the antisymmetric problem is the symmetric one. Built independently
    # (this module's strips on the clamped modes against strip_aero.py's Theodorsen/Jones
    # sections), the two searches agree to the bisection's 1e-7 m/s (measured 1e-9 m/s);
    # Goland state space 137.347 m/s (published 137.2, Patil, Hodges & Cesnik 2001).
    m = _goland()
    rho = G.FLUTTER_DENSITY_KG_M3
    sym = state_space_flutter(m, density_kg_m3=rho, aero=aero, speed_range_m_s=(20.0, 260.0))
    anti = A.antisymmetric_flutter(A.clamped_strips(m), range_m_s=(20.0, 260.0), step_m_s=2.0,
                                   density_kg_m3=rho, aero=aero, structural_damping=0.0,
                                   tol_m_s=1e-7)
    assert anti.speed_m_s == pytest.approx(sym.speed_m_s, abs=1e-6)
    assert anti.speed_m_s == pytest.approx(speed, abs=1e-3)
    assert anti.frequency_rad_s == pytest.approx(sym.frequency_rad_s, rel=1e-8)
    assert anti.mode == sym.mode and anti.mechanism == sym.mechanism
    assert anti.settings["symmetry"] == "antisymmetric"


def _roll_free_goland(j_fuselage_kg_m2: float) -> A.AntisymmetricStrips:
    """The Goland wing's antisymmetric modes with a fuselage of roll inertia J [kg m^2] on
    the clamped model's strips (Theodorsen sections, as clamped_strips)."""
    sections = goland_sections(inertia_about=G.DEFAULT_INERTIA_AXIS)
    m = _goland()
    sol = solve_antisymmetric(sections, j_fuselage_kg_m2, n_modes=m.n_modes)
    bend, twist = sol.sample(m.stations_m)
    base = A.clamped_strips(m)
    from dataclasses import replace
    return replace(base, phi=bend, theta=twist, frequencies_rad_s=sol.frequencies_rad_s,
                   roll_inertia_kg_m2=2.0 * sol.half_roll_inertia_kg_m2,
                   mode_labels=tuple(f"antisymmetric_{i + 1}" for i in range(m.n_modes)))


def test_roll_freedom_tends_to_the_clamped_root():
    # J → ∞ holds the root: the roll-free wing's flutter tends to the clamped one's
    # (measured: 137.347 at J = 1e9 kg m^2, |Δ| < 1e-3 m/s); a light fuselage moves it.
    rho = G.FLUTTER_DENSITY_KG_M3
    kw = dict(range_m_s=(20.0, 260.0), step_m_s=2.0, density_kg_m3=rho, aero="unsteady",
              structural_damping=0.0, tol_m_s=1e-5)
    clamped = A.antisymmetric_flutter(A.clamped_strips(_goland()), **kw)
    stiff = A.antisymmetric_flutter(_roll_free_goland(1e9), **kw)
    assert stiff.speed_m_s == pytest.approx(clamped.speed_m_s, abs=0.01)
    assert stiff.frequency_rad_s == pytest.approx(clamped.frequency_rad_s, rel=1e-3)


def _lateral_subject(wing_or_aircraft, speed_m_s):
    """(the trim point, the antisymmetric wing, the unsteady strips, the aircraft's aileron,
    the builder's chords) of ``wing_or_aircraft`` at ``speed_m_s`` (None: its cruise), as
    api._lateral builds them."""
    from bioflex_jsb.api import _aileron_surface, _lateral_point
    from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing

    subject, point = _lateral_point(wing_or_aircraft, speed_m_s)
    wing = antisymmetric_wing(subject.build, point.trim.ixx_kg_m2)
    return (point, wing, A.aircraft_strips(subject.build, wing, point.trim.ixx_kg_m2),
            _aileron_surface(subject, subject.build), subject.build.aero.chord_m)


@pytest.fixture(scope="module")
def prototype_lateral():
    return _lateral_subject(api.load_wing("optimised"), 15.0)


@pytest.fixture(scope="module")
def c172_lateral():
    return _lateral_subject(api.load_aircraft("c172_elastic"), None)


@pytest.mark.parametrize("subject", ["prototype_lateral", "c172_lateral"])
def test_unsteady_lateral_model_quasi_steady_limit(subject, request):
    # unsteadiness 0: the rows and columns of β … η̇ of A, B, C, D are the one builder's
    # coupled model's exactly (the aileron's load on the modes, the yaw rate's and
    # sideslip's terms; measured difference 0.0) and the lags only listen: the roots are the
    # quasi-steady ones and the lags' −β_j V/b_k. In a steady state (constant inputs) the
    # unsteady model's response is the quasi-steady one (measured 7e-15 relative, prototype;
    # 9e-17, c172).
    from bioflex_jsb.aeroelasticity.antisymmetric_strips import lateral_model_with_aileron

    point, wing, strips, surface, chord = request.getfixturevalue(subject)
    qs, _ = lateral_model_with_aileron("coupled", point.trim, point.aero, wing, surface, chord)
    assert "yaw_sideslip" in qs.notes and "aileron_on_modes" in qs.notes
    n0 = qs.n_states
    u0 = A.unsteady_lateral_model(point.trim, point.aero, wing, strips, surface, chord,
                                  unsteadiness=0.0)
    assert np.array_equal(u0.a[:n0, :n0], qs.a) and not np.any(u0.a[:n0, n0:])
    assert np.array_equal(u0.b[:n0], qs.b)
    i_ny, j_ny = qs.outputs.index("n_y"), u0.outputs.index("n_y")
    assert np.array_equal(u0.c[:n0, :n0], qs.c[:n0]) and not np.any(u0.c[:n0, n0:])
    assert np.array_equal(u0.c[j_ny, :n0], qs.c[i_ny]) and not np.any(u0.c[j_ny, n0:])
    assert np.array_equal(u0.d[:n0], qs.d[:n0]) and np.array_equal(u0.d[j_ny], qs.d[i_ny])
    assert u0.notes["yaw_sideslip"] == qs.notes["yaw_sideslip"]
    v, b = point.trim.speed_m_s, 0.5 * strips.chord_m
    lags = np.concatenate([-beta * v / b for beta in JONES_WAGNER.exponents])
    expect = np.sort_complex(np.concatenate([np.linalg.eigvals(qs.a), lags]))
    assert np.allclose(np.sort_complex(np.linalg.eigvals(u0.a)), expect, rtol=1e-9, atol=1e-9)
    u = A.unsteady_lateral_model(point.trim, point.aero, wing, strips, surface, chord)
    x_u = np.linalg.solve(u.a, -u.b)[:n0]
    x_q = np.linalg.solve(qs.a, -qs.b)
    assert np.max(np.abs(x_u - x_q)) < 1e-10 * np.max(np.abs(x_q))
    assert u.states[n0] == "lag1[0]" and u.outputs[-1] == "n_y"


def test_the_unsteady_model_carries_the_aileron_and_the_yaw_sideslip_terms(prototype_lateral):
    # The one builder's terms are in the unsteady model: its aileron column on the modes is
    # the quasi-steady one through the apparent mass's E⁻¹ (the steady response to the
    # aileron is the coupled model's, above), and the yaw rate's forcing of the modes moves
    # the spiral as it moves the quasi-steady one (docs/lateral.md: −0.18 rad/s against
    # +0.018 without the yaw rate's and sideslip's terms).
    # The aileron's load is in B alone: the model without it has the same A.
    point, wing, strips, surface, chord = prototype_lateral
    u = A.unsteady_lateral_model(point.trim, point.aero, wing, strips, surface, chord)
    col, e0 = u.inputs.index("aileron"), u.states.index("eta1_dot")
    assert np.any(u.b[e0:e0 + wing.n_modes, col] != 0.0)
    bare = A.unsteady_lateral_model(point.trim, point.aero, wing, strips, None, chord)
    assert np.array_equal(bare.a, u.a) and not np.array_equal(bare.b, u.b)
    _, ms = A.unsteady_lateral_mode_set(point.trim, point.aero, wing, strips, surface, chord)
    assert ms["spiral"].re < -0.1


def test_unsteady_lateral_modes_are_labelled(prototype_lateral):
    # The quasi-steady strips leave the prototype's third antisymmetric mode neutral
    # (+0.017 rad/s at 15 m/s: no pitch damping, docs/lateral.md); Theodorsen's strips damp
    # every antisymmetric mode (measured −121 ± 92i, −132 ± 292i, −124 ± 473i rad/s, as the
    # symmetric unsteady model's aeroelastic_1..3: −127 ± 83i, −136 ± 290i, −131 ± 470i).
    point, wing, strips, surface, chord = prototype_lateral
    _, ms = A.unsteady_lateral_mode_set(point.trim, point.aero, wing, strips, surface, chord)
    names = [m.mode for m in ms]
    assert names[:3] == ["roll", "spiral", "dutch_roll"]
    assert names[3:] == ["antisymmetric_1", "antisymmetric_2", "antisymmetric_3"]
    for m in ms.modes[3:]:
        assert m.re < -50.0
    assert ms["dutch_roll"].im == pytest.approx(6.45, abs=0.1)  # quasi-steady 6.31


def test_the_c172s_unsteady_lateral_modes_are_labelled(c172_lateral):
    # The c172_elastic at its cruise (57.8 m/s): the homotopy keeps every label, and each
    # antisymmetric mode stays within 10 % of its quasi-steady frequency (measured 2.1 %,
    # 2.3 %, 5.0 %: 80.3, 168.3, 198.8 against 82.0, 172.3, 209.3 rad/s); the wake's lag
    # makes the roll subsidence an oscillation (measured −5.78 ± 2.02i against −8.66).
    from bioflex_jsb.aeroelasticity.antisymmetric_strips import lateral_model_with_aileron
    from bioflex_jsb.flight_dynamics.lateral_elastic import (
        build_lateral_elastic,
        coupled_mode_set,
    )

    point, wing, strips, surface, chord = c172_lateral
    _, ms = A.unsteady_lateral_mode_set(point.trim, point.aero, wing, strips, surface, chord)
    qs, _ = lateral_model_with_aileron("coupled", point.trim, point.aero, wing, surface, chord)
    qs_modes = coupled_mode_set(qs, build_lateral_elastic("rigid", point.trim, point.aero,
                                                          None), wing)
    assert [m.mode for m in ms] == [m.mode for m in qs_modes]
    for k in (1, 2, 3):
        name = f"antisymmetric_{k}"
        assert ms[name].im == pytest.approx(qs_modes[name].im, rel=0.10)
    assert ms["roll"].im > 1.0 and ms["roll"].re > qs_modes["roll"].re


def test_prototype_backward_axis_antisymmetric_flutter():
    # inertial-backward, unsteady strips, ζ 0.02: the symmetric body-freedom flutter
    # (18.86 m/s, short period) comes first; the antisymmetric branch's is the roll coupled
    # to the first antisymmetric mode near the wing's divergence (measured 19.588 m/s,
    # 59.8 rad/s), its mechanism the engine's body-freedom (the roll a rigid branch).
    r = api.flutter(api.load_wing("inertial-backward"), symmetry="both")
    d = r.as_dict()
    assert d["first_symmetry"] == "symmetric" and d["mode"] == "short_period"
    assert d["speed_m_s"] == pytest.approx(18.858, abs=0.01)
    o = d["other_symmetry"]
    assert o["symmetry"] == "antisymmetric" and o["mode"] == "roll"
    assert o["speed_m_s"] == pytest.approx(19.588, abs=0.01)
    assert o["mechanism"] == "body-freedom" and o["frequency_rad_s"] == pytest.approx(59.8,
                                                                                     abs=0.5)


def test_quasi_steady_antisymmetric_flutter_comes_first_and_is_flagged():
    # Quasi-steady strips: the backward axes' antisymmetric torsion goes unstable first
    # (measured 9.31 m/s, antisymmetric_1, against the symmetric 14.90), single-mode: the
    # quasi-steady artefact, flagged as the symmetric one is.
    r = api.flutter(api.load_wing("inertial-backward"), aero="quasi-steady", symmetry="both")
    assert r.settings["first_symmetry"] == "antisymmetric"
    assert r.speed_m_s == pytest.approx(9.309, abs=0.01) and r.mode == "antisymmetric_1"
    assert r.quasi_steady_artefact and r.caveat
    assert r.settings["other_symmetry"]["speed_m_s"] == pytest.approx(14.90, abs=0.01)


def test_cli_symmetry_both_goland(capsys):
    from tests.cli_helpers import run_cli

    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--symmetry",
                           "both", "--json")
    assert code == 0
    d = json.loads(out)
    assert d["first_symmetry"] == "both" and d["symmetry"] == "symmetric"
    assert d["other_symmetry"]["speed_m_s"] == d["speed_m_s"]
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--symmetry",
                           "antisymmetric", "--method", "state-space")
    assert code == 0 and "antisymmetric modes" in out and "flutter at 137.3 m/s" in out


def test_bad_symmetry_is_refused(capsys):
    from tests.cli_helpers import run_cli

    with pytest.raises(InputError, match="symmetry"):
        api.flutter("goland", clamped=True, symmetry="sideways")
    code, _, err = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--symmetry",
                           "sideways")
    assert code == 2 and "--symmetry" in err
