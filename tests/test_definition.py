"""Clamped wings as data (bioflex_jsb/definition, docs/aircraft.md): the shipped Goland file
gives today's result, and units and ranges are checked when a file is read (one line naming
the field, exit 2 in the CLI)."""

from __future__ import annotations

import re

import pytest

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity import goland_flutter
from bioflex_jsb.definition import DefinitionError, load_definition
from bioflex_jsb.definition.clamped import clamped_model, derived_speed_range_m_s
from bioflex_jsb.definition.loader import shipped_path
from tests.cli_helpers import assert_one_line_error, run_cli

GOLAND_TEXT = shipped_path("goland").read_text(encoding="utf-8")


def test_goland_file_gives_the_goland_result():
    # The shipped file holds parameters/goland.py's numbers: same flutter point to 1e-6
    # (measured 1.2e-8 m/s: the two searches bisect different brackets to 1e-7 m/s).
    ref = goland_flutter()
    res = api.flutter("goland", clamped=True)
    assert res.speed_m_s == pytest.approx(ref.speed_m_s, abs=1e-6)
    assert res.frequency_rad_s == pytest.approx(ref.frequency_rad_s, abs=1e-6)
    assert (res.mode, res.partner_mode, res.mechanism) == (ref.mode, ref.partner_mode,
                                                           "coalescence")
    assert res.settings["range_derived"] and not res.present_at_lower_end


def test_derived_range_rule():
    # 5 % .. 150 % of the divergence speed (252.30 m/s for Goland at 1.225 kg/m^3).
    d = load_definition("goland")
    lo, hi = derived_speed_range_m_s(clamped_model(d), d.air.density_kg_m3)
    assert hi == pytest.approx(1.5 * 252.300, rel=1e-5) and lo == pytest.approx(0.05 * hi)


def _write(tmp_path, text: str):
    path = tmp_path / "wing.toml"
    path.write_text(text, encoding="utf-8")
    return path


BAD = [
    # a definition in millimetres: semispan 6096 for 6.096 m
    (("y_m = 6.096", "y_m = 6096.0"), "wing.stations[1].y_m", "millimetres"),
    # a damping ratio of 5 (a percentage)
    (("damping_ratio = 0.0", "damping_ratio = 5.0"), "structure.damping_ratio",
     "not a percentage"),
    # pitch inertia below m' d^2: a non-positive-definite section mass matrix
    (("pitch_inertia_kg_m = 8.64\ninertia_axis = \"elastic-axis\"",
      "pitch_inertia_kg_m = 0.5\ninertia_axis = \"elastic-axis\""),
     "structure.pitch_inertia_kg_m", "not positive definite"),
    # a pure-bending structure (no torsional stiffness)
    (("torsional_stiffness_n_m2 = 0.987e6", "torsional_stiffness_n_m2 = 0.0"),
     "structure.torsional_stiffness_n_m2", "pure-bending"),
    (("density_kg_m3 = 1.225", "density_kg_m3 = 1e-300"), "air.density_kg_m3", "0.01..2"),
    (("strips = 24", "strips = 24\nstrip_count = 3"), "aero.strip_count", "unknown field"),
    (("elastic_axis = 0.33, centre_of_mass = 0.43 },\n  { y_m = 6.096",
      "elastic_axis = 33, centre_of_mass = 0.43 },\n  { y_m = 6.096"),
     "wing.stations[0].elastic_axis", "chord fraction"),
]


@pytest.mark.parametrize("edit, field, reason", BAD)
def test_bad_definition_is_one_line_naming_the_field(tmp_path, capsys, edit, field, reason):
    old, new = edit
    assert old in GOLAND_TEXT
    path = _write(tmp_path, GOLAND_TEXT.replace(old, new, 1))
    with pytest.raises(DefinitionError, match=re.escape(field)) as info:
        api.flutter(str(path), clamped=True)
    assert reason in str(info.value) and "\n" not in str(info.value)
    code, _, err = run_cli(capsys, "flutter", "--clamped", str(path))
    assert_one_line_error(code, err, field)


def test_no_torsion_mode_is_refused(tmp_path):
    # torsion so stiff that the 2 lowest modes are bending: a pure-bending modal basis
    text = GOLAND_TEXT.replace("torsional_stiffness_n_m2 = 0.987e6",
                               "torsional_stiffness_n_m2 = 1e11").replace("n_modes = 6",
                                                                          "n_modes = 2")
    with pytest.raises(DefinitionError, match="structure.n_modes: the 2 lowest modes are all "
                       "bending"):
        clamped_model(load_definition(_write(tmp_path, text)))


def test_unknown_definition_name(capsys):
    code, _, err = run_cli(capsys, "flutter", "--clamped", "concorde")
    assert_one_line_error(code, err, "--clamped takes a clamped-wing definition")
