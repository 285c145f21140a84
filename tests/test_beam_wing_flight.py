"""A ``beam`` wing on an airframe flies (definition/aircraft.py, structures/beam_wing.py):
its modes are computed once per process from the definition's beam and take a modal
file's place in the flight build, so the Table B1/B2 model, modes, flutter and gust runs
take it as they take a modes file. Tapered chords, dihedral, point masses and a strut on
the same path (docs/aircraft.md, "The wing on an airframe")."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.definition import load_definition
from bioflex_jsb.definition.aircraft import load_aircraft
from bioflex_jsb.definition.clamped import beam_sections
from bioflex_jsb.definition.flying import flight_refusal
from bioflex_jsb.definition.loader import shipped_path
from bioflex_jsb.structures.beam import solve_beam

SGS = shipped_path("sgs_elastic").read_text(encoding="utf-8")
SGS_WING = shipped_path("sgs_wing").read_text(encoding="utf-8")
BEAM = SGS_WING[SGS_WING.index("[structure]"):SGS_WING.index("[air]")]
SGS_BEAM = (SGS[:SGS.index("[structure]")] + BEAM + SGS[SGS.index("[aero]"):]).replace(
    'name = "sgs_elastic"', 'name = "sgs_beam"', 1)

# The SGS airframe with a wing a user might bring: a constant-chord inner panel and a
# tapered outer one (a C172's planform), 3° of dihedral on the outer panel, the beam's
# sections per station, fuel in the inner wing, a tip mass and a strut.
TAPERED_WING = """
[wing]
name = "tapered"
stations = [
  { y_m = 0.0, chord_m = 1.2, elastic_axis = 0.38, centre_of_mass = 0.40 },
  { y_m = 3.0, chord_m = 1.2, elastic_axis = 0.38, centre_of_mass = 0.40 },
  TIP
]

[structure]
kind = "beam"
bending_stiffness_n_m2 = [9.0e5, 5.0e5, 1.0e5]
torsional_stiffness_n_m2 = [2.0e5, 1.2e5, 4.0e4]
mass_per_length_kg_m = [9.0, 7.0, 4.0]
pitch_inertia_kg_m = [0.9, 0.7, 0.15]
damping_ratio = 0.02
n_modes = 4

[[structure.point_masses]]
name = "fuel"
y_m = 1.5
mass_kg = 30.0
chord_position = 0.35
pitch_inertia_kg_m2 = 2.0

[[structure.point_masses]]
name = "tip light"
y_m = 7.036
mass_kg = 0.5
chord_position = 0.2

[[structure.struts]]
y_m = 2.6
stiffness_n_m = 2.0e6

[aero]
lift_slope = "vlm"
pin_c_eta1_q1 = "physical"
"""
TAPERED_WING = TAPERED_WING.replace("TIP", "{ y_m = 7.036, chord_m = 0.7, leading_edge_x_m = "
                                    "0.125, z_m = 0.2115, elastic_axis = 0.38, "
                                    "centre_of_mass = 0.41 },", 1)
SGS_TAPERED = (SGS[:SGS.index("[wing]")] + TAPERED_WING + SGS[SGS.index("[air]"):]).replace(
    'name = "sgs_elastic"', 'name = "sgs_tapered"', 1)


def _write(tmp_path, text, name="aircraft.toml"):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_the_beam_flies_as_its_modes_file_does(tmp_path):
    # sgs_elastic flies sgs_wing's beam through a modal file written from it
    # (sgs_elastic_modes.toml); the same beam given as kind = "beam" is the same wing:
    # frequencies, generalised masses and every Table B1 coefficient equal (measured: 0
    # difference: the file's repr-written numbers round-trip), the short period and the
    # free aircraft's flutter speed within 1e-12
    beam = load_aircraft(_write(tmp_path, SGS_BEAM))
    modal = load_aircraft("sgs_elastic")
    assert beam.linear_problem() is None and flight_refusal(beam) is None
    wb, wm = beam.wing(), modal.wing()
    assert wb.variant.beam is not None and wb.variant.modes_file is None
    assert wb.variant.as_dict()["beam"] == "sha256:" + wb.variant.beam.digest
    assert wb.variant.as_dict()["ribs"] is None
    np.testing.assert_allclose(wb.model.frequencies_rad_s, wm.model.frequencies_rad_s,
                               rtol=1e-13)
    np.testing.assert_allclose(wb.model.generalised_masses_kg_m2,
                               wm.model.generalised_masses_kg_m2, rtol=1e-13)
    cb, cm = wb.model.coefficients.as_dict(), wm.model.coefficients.as_dict()
    for key in cb:
        if key != "overrides":
            np.testing.assert_allclose(cb[key], cm[key], rtol=1e-12, atol=1e-15, err_msg=key)
    sp_b = api.modes(beam, 25.0).get("short_period").eigenvalue
    sp_m = api.modes(modal, 25.0).get("short_period").eigenvalue
    assert abs(sp_b - sp_m) <= 1e-12 * abs(sp_m)
    assert api.flutter(beam).speed_m_s == pytest.approx(api.flutter(modal).speed_m_s,
                                                          rel=1e-12)


def test_modes_are_computed_once_per_process_and_keyed_on_the_content(tmp_path, monkeypatch):
    from bioflex_jsb.structures import beam_wing

    calls = []
    solve = beam_wing.beam_modes
    monkeypatch.setattr(beam_wing, "beam_modes", lambda *a, **k: calls.append(1) or solve(*a, **k))
    monkeypatch.setattr(beam_wing, "_MODES", type(beam_wing._MODES)())
    a = load_aircraft(_write(tmp_path, SGS_BEAM, "a.toml"))
    b = load_aircraft(_write(tmp_path, SGS_BEAM.replace('name = "sgs_beam"',
                                                        'name = "other name"', 1), "b.toml"))
    va, vb = a.variant(), b.variant()
    assert va.beam == vb.beam and hash(va.beam) == hash(vb.beam)  # the same beam content
    ma, mb = va.beam.modes(3), vb.beam.modes(3)
    assert len(calls) == 1  # computed once, for both definitions
    np.testing.assert_array_equal(ma.twist_rad, mb.twist_rad)
    assert ma.source.startswith("sgs_beam") and mb.source.startswith("other name")
    stiffer = load_aircraft(_write(tmp_path, SGS_BEAM.replace(
        "bending_stiffness_n_m2 = 4.93e5", "bending_stiffness_n_m2 = 4.94e5", 1), "c.toml"))
    assert stiffer.variant().beam != va.beam
    assert stiffer.wing().model.frequencies_rad_s[0] > a.wing().model.frequencies_rad_s[0]


def test_a_tapered_dihedral_beam_wing_with_masses_and_a_strut_is_analysed(tmp_path):
    aircraft = load_aircraft(_write(tmp_path, SGS_TAPERED))
    assert aircraft.linear_problem() is None and flight_refusal(aircraft) is None
    pf = aircraft.planform()
    assert pf.stations_m == (0.0, 3.0, 7.036) and pf.breaks_m == (3.0,)
    assert pf.has_dihedral
    assert pf.chord_at(5.018) == pytest.approx(0.95)
    build = aircraft.wing()
    assert build.planform == pf
    assert build.aero.cos_dihedral is not None
    assert build.aero.reference_area_m2 == pytest.approx(2 * (3.6 + 0.95 * 4.036), rel=1e-12)
    # the flight model's modes are the beam's, point masses and strut included
    sections = beam_sections(aircraft.definition)
    assert len(sections.point_masses) == 2 and len(sections.springs) == 1
    np.testing.assert_allclose(build.model.frequencies_rad_s,
                               solve_beam(sections, 3).frequencies_rad_s, rtol=1e-12)
    assert build.modes.stations_m[-1] == pytest.approx(7.036)
    # the axes vary along the span (centre of mass 0.40 -> 0.41): the modes carry them
    assert build.modes.x_inertial_frac[-1] == pytest.approx(0.41)
    assert build.variant.x_inertial_frac == pytest.approx(np.mean([0.40, 0.40, 0.41]))
    modes = api.modes(aircraft, 25.0)
    assert modes.get("short_period").eigenvalue.real < 0.0
    result = api.flutter(aircraft)
    assert result.speed_m_s is None or result.speed_m_s > 25.0
    lti = api.linear_model(aircraft, 25.0, "coupled")
    assert "eta3" in lti.states


def test_a_strut_braced_beam_wing_flies_a_gust_and_says_why_it_has_no_loads(tmp_path):
    aircraft = load_aircraft(_write(tmp_path, SGS_TAPERED))
    runs = api.fly_gust(aircraft, 25.0, gust="1cos:1:25", models=("coupled",), duration_s=1.0)
    run = runs["coupled"]
    assert run.stopped is None
    assert float(np.max(np.abs(run["eta1"]))) > 0.0
    # a strut: the force summation has no signal of the deflection its reaction needs
    assert "strut-braced" in run.meta["loads_unavailable"]


def test_a_plain_beam_wing_gets_both_load_methods(tmp_path):
    aircraft = load_aircraft(_write(tmp_path, SGS_BEAM))
    from bioflex_jsb.loads.model import build_loads_model

    lm = build_loads_model(aircraft.wing(), 25.0)
    assert lm.md_matrix is not None and lm.md_unavailable is None
    assert lm.half_wing_mass_kg == pytest.approx(7.0 * 7.036, rel=1e-12)


def test_a_beam_wing_on_the_prototype_airframe_flies_on_it(tmp_path):
    # the prototype's airframe and planform with a beam of the same length: the generated
    # airframe flies it (flight_problem None); a tapered chord there is refused in one line
    text = shipped_path("bioflex_original").read_text(encoding="utf-8")
    start, end = text.index("[structure]"), text.index("[aero]")
    beam = """[structure]
kind = "beam"
bending_stiffness_n_m2 = 3118.0
torsional_stiffness_n_m2 = 1.0
mass_per_length_kg_m = 0.07
pitch_inertia_kg_m = 2.0e-4
damping_ratio = 0.02
"""
    aircraft = load_aircraft(_write(tmp_path, text[:start] + beam + text[end:]))
    assert aircraft.flight_problem() is None
    assert aircraft.wing().variant.beam is not None
    tapered = (text[:start] + beam + text[end:]).replace(
        "{ y_m = 0.85,   chord_m = 0.183,", "{ y_m = 0.85,   chord_m = 0.15,", 1)
    problem = load_aircraft(_write(tmp_path, tapered, "t.toml")).flight_problem()
    assert "planform (tapered" in problem and "\n" not in problem


@pytest.mark.parametrize("edit, field", [
    (("z_m = 0.2115", "z_m = 3.0"), "wing.stations[2].z_m"),  # 37° of dihedral
    (("{ y_m = 0.0, chord_m = 1.2,", "{ y_m = 0.0, z_m = 0.1, chord_m = 1.2,"),
     "wing.stations[0].z_m"),
])
def test_bad_heights_are_one_line(tmp_path, edit, field):
    from bioflex_jsb.definition import DefinitionError

    with pytest.raises(DefinitionError) as err:
        load_definition(_write(tmp_path, SGS_TAPERED.replace(*edit, 1)))
    assert field in str(err.value) and "\n" not in str(err.value)


def test_a_point_mass_in_the_force_summation_is_that_mass_smeared_over_one_element(tmp_path):
    # 20 kg (its own pitch inertia 1 kg m², 0.15 c ahead of the elastic axis) in the middle
    # of the SGS beam's 18th element (3.08 m), against the same mass, static moment and
    # inertia spread over that element in the beam's distributed sections (the force
    # summation's cell path, independent of the point's rows). Root, 25, 50, 75 % stations
    # (the mass between the second and third). Gravity and pitch-acceleration columns:
    # geometry only, off by the smear's 1e-9 m ramps (1.1e-7 kg): measured 1.5e-9, bar
    # 1e-8; the modal acceleration columns: measured
    # 2.5e-3 (the two beams' modes differ by the smear), bar 1e-2 of the column's largest
    # entry. And the root shear per g is the half wing's weight.
    from bioflex_jsb.loads.model import build_loads_model, signal_names

    h = 7.036 / 40
    y0, c, x_e, m0, i0 = 17.5 * h, 1.0, 0.38, 7.0, 0.4375
    point = SGS_BEAM.replace("[air]", f"""[[structure.point_masses]]
y_m = {y0!r}
mass_kg = 20.0
chord_position = 0.23
pitch_inertia_kg_m2 = 1.0

[air]""", 1)
    d = (0.23 - x_e) * c
    m_extra = 20.0 / h
    ys = [0.0, 17 * h, 17 * h + 1e-9, 18 * h - 1e-9, 18 * h, 7.036]
    bump = [False, False, True, True, False, False]
    mass = [m0 + (m_extra if b else 0.0) for b in bump]
    x_i = [(x_e * m0 + (m_extra * 0.23 if b else 0.0)) / m for b, m in zip(bump, mass, strict=True)]
    inertia = [i0 + ((1.0 + 20.0 * d * d) / h if b else 0.0) for b in bump]
    stations = ",\n".join(f"  {{ y_m = {y!r}, chord_m = 1.0, elastic_axis = 0.38, "
                           f"centre_of_mass = {xi!r} }}" for y, xi in zip(ys, x_i, strict=True))
    smeared = (SGS_BEAM[:SGS_BEAM.index("stations = [")] + "stations = [\n" + stations
               + "\n]\n\n" + SGS_BEAM[SGS_BEAM.index("[structure]"):])
    smeared = smeared.replace("mass_per_length_kg_m = 7.0", f"mass_per_length_kg_m = {mass!r}", 1)
    smeared = smeared.replace("pitch_inertia_kg_m = 0.4375", f"pitch_inertia_kg_m = {inertia!r}", 1)
    a = build_loads_model(load_aircraft(_write(tmp_path, point, "p.toml")).wing(), 25.0,
                          static="rigid")
    b = build_loads_model(load_aircraft(_write(tmp_path, smeared, "s.toml")).wing(), 25.0,
                          static="rigid")
    names = signal_names(3)
    for col in ("g*n_z", "q_dot"):
        k = names.index(col)
        scale = np.max(np.abs(b.fs_matrix[:, k]))
        off = np.max(np.abs(a.fs_matrix[:, k] - b.fs_matrix[:, k])) / scale
        print(f"point mass vs smeared, {col}: {off:.2e}")
        assert off < 1e-8, col
    worst = 0.0
    for col in ("eta1_ddot", "eta2_ddot", "eta3_ddot"):
        k = names.index(col)
        scale = np.max(np.abs(b.fs_matrix[:, k]))
        worst = max(worst, np.max(np.abs(a.fs_matrix[:, k] - b.fs_matrix[:, k])) / scale)
    print(f"point mass vs smeared, modal acceleration columns: {worst:.2e}")
    assert worst < 1e-2
    root_shear_per_g = a.fs_matrix[0, names.index("g*n_z")]
    assert root_shear_per_g == pytest.approx(-(7.0 * 7.036 + 20.0), rel=1e-12)
    assert a.half_wing_mass_kg == pytest.approx(7.0 * 7.036 + 20.0, rel=1e-12)
