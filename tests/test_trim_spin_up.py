"""The trim companion's propeller spin-up reads its rotor from the companion's own files:
the values JSBSim flies, in the units JSBSim reads them."""

from __future__ import annotations

from pathlib import Path

import pytest

from bioflex_jsb import units as U
from bioflex_jsb.parameters.airframe import PROPULSION
from bioflex_jsb.runtime.results import TrimError
from bioflex_jsb.runtime.trim import rotor_spin_up_data

ROOT = Path(__file__).resolve().parents[1]


def test_the_prototypes_companion_gives_the_generators_rotor():
    diameter_ft, inertia_slug_ft2, power_ft_lbf_s = rotor_spin_up_data(
        ROOT / "aircraft" / "bioflex_trim" / "bioflex_trim.xml")
    n = PROPULSION.rotor_count
    assert diameter_ft * U.M_PER_FT == pytest.approx(PROPULSION.prop_diameter_m, rel=1e-12)
    # the file's <ixx> has 11 significant digits: 9.8e-11 from the generator's value
    assert inertia_slug_ft2 == pytest.approx(
        PROPULSION.trim_rotor_inertia_kg_m2 / n * U.SLUG_FT2_PER_KG_M2, rel=1e-9)
    assert power_ft_lbf_s == pytest.approx(
        PROPULSION.motor_max_shaft_power_w / n * U.LBF_FT_PER_N_M, rel=1e-12)


def _aircraft(tmp_path: Path, prop: str, motor: str) -> Path:
    (tmp_path / "Engines").mkdir()
    (tmp_path / "Engines" / "p.xml").write_text(f"<propeller name='p'>{prop}</propeller>")
    (tmp_path / "Engines" / "m.xml").write_text(f"<electric_engine name='m'>{motor}"
                                                "</electric_engine>")
    path = tmp_path / "a.xml"
    path.write_text("<fdm_config name='a'><propulsion><engine file='m'><thruster file='p'/>"
                    "</engine></propulsion></fdm_config>")
    return path


def test_jsbsims_units_are_converted(tmp_path):
    path = _aircraft(tmp_path, "<diameter unit='IN'>12</diameter>"
                               "<ixx unit='KG*M2'>0.001</ixx>", "<power unit='HP'>0.5</power>")
    diameter_ft, inertia_slug_ft2, power_ft_lbf_s = rotor_spin_up_data(path)
    assert diameter_ft == pytest.approx(1.0, rel=1e-15)
    assert inertia_slug_ft2 == pytest.approx(0.001 * U.SLUG_FT2_PER_KG_M2, rel=1e-15)
    assert power_ft_lbf_s == pytest.approx(275.0, rel=1e-15)  # 1 hp = 550 ft·lbf/s


def test_a_rotor_without_its_inertia_is_one_line(tmp_path):
    path = _aircraft(tmp_path, "<diameter unit='FT'>1</diameter>", "<power>150</power>")
    with pytest.raises(TrimError, match=r"no <ixx> in SLUG\*FT2, KG\*M2"):
        rotor_spin_up_data(path)
