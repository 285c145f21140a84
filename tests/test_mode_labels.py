"""Rigid modes named as whole second-order factors: a conjugate pair or two real roots each,
the short period the one of the larger natural frequency, at every speed (an over-damped
short period, whose real roots the phugoid pair was listed under both names for)."""

from __future__ import annotations

import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics import flutter_engine as engine
from bioflex_jsb.runtime.results import label_modes
from tests.cli_helpers import run_cli

SP, PH = "short_period", "phugoid"


@pytest.mark.parametrize("roots, expected", [
    # two pairs: the larger modulus is the short period (the old rule, unchanged)
    ([-0.05 + 0.8j, -5.6 - 9.0j, -0.05 - 0.8j, -5.6 + 9.0j], [PH, SP, PH, SP]),
    # over-damped short period with one real root slower than the phugoid pair: ranked by
    # modulus the pair split between the names (-12, then the pair, then -0.3)
    ([-12.0, -0.3, -0.05 + 0.6j, -0.05 - 0.6j], [SP, SP, PH, PH]),
    # real phugoid (two slow real roots) and an oscillatory short period
    ([-0.02, -3.0 + 4.0j, -0.4, -3.0 - 4.0j], [PH, SP, PH, SP]),
    # four real roots: the two largest are the short period
    ([-0.1, -12.0, -0.4, -4.0], [PH, SP, PH, SP]),
])
def test_mode_labels_of_synthetic_root_sets(roots, expected):
    assert list(eigen.mode_labels_of_roots(np.array(roots))) == expected


def test_a_root_without_its_conjugate_is_refused():
    with pytest.raises(ValueError, match="no conjugate"):
        eigen.mode_labels_of_roots(np.array([-1.0 + 2.0j, -1.0 + 2.0j, -3.0, -4.0]))
    assert not engine.closed_under_conjugation(np.array([-1 + 2j, -3.0]))
    assert engine.closed_under_conjugation(np.array([-1 + 2j, -3.0, -1 - 2j]))


def test_jsbsim_linearizations_labels_keep_an_over_damped_short_period():
    ev = label_modes(np.array([-12.0, -0.3, -0.05 + 0.6j, -0.05 - 0.6j]))
    assert [(e.mode, e.re, e.im) for e in ev] == [(SP, -12.0, 0.0), (SP, -0.3, 0.0),
                                                 (PH, -0.05, 0.6)]


def test_tracked_names_are_shared_out_again_when_a_pair_carries_both():
    # the tracker gave one root of a pair to each name (a real short-period root met a
    # real phugoid root and the two became a pair): the partition names whole factors and
    # the tracker only orders the roots within a name
    labels = (SP, SP, PH, PH, "lag")
    lam = np.array([-1.7 + 0.7j, -3.8, -1.7 - 0.7j, -0.8, -50.0])
    order = np.arange(5)
    predicted = np.array([-1.5 + 0.5j, -3.7, -1.5 - 0.5j, -0.7, -50.0])
    new = engine.share_paired(labels, (SP, PH), eigen.mode_labels_of_roots, lam, order,
                              predicted)
    named = {lab: sorted(lam[new[j]].real for j in range(4) if labels[j] == lab)
             for lab in (SP, PH)}
    # the pair (ω_n 1.84) against the reals (sqrt(3.8 × 0.8) = 1.74): the pair is faster
    assert named == {SP: [-1.7, -1.7], PH: [-3.8, -0.8]} and new[4] == 4


J3CUB_FT, J3CUB_LB, J3CUB_SLUG_FT2 = 0.3048, 0.45359237, 1.35581795


def j3cub_airframe():
    """JSBSim's J3Cub (jsbsim package aircraft/J3Cub/J3Cub.xml) as a rigid longitudinal
    model: metrics (S 178.5 ft², b 35.25 ft, c̄ 5.25 ft), empty weight and pilot (765 + 137.22
    lb), I_yy 386.81 slug ft²; C_L0 0.534 and C_Lα 7.86 /rad (the Lift_alpha table, 0 to 5
    deg), C_mα −1.68 /rad (Pitch_alpha at Re 2.7e6), C_mq −12.70, C_mα̇ −7.59, C_mδe −1.20,
    C_Lδe 0.327, induced drag 0.0485 (the XML's); the rest the prototype's (unused by the
    longitudinal roots). Not moved from the AERORP to the CG: a test case, not a model."""
    from bioflex_jsb.parameters.airframe import (
        PROTOTYPE_AIRFRAME,
        AirframeData,
        MassProperties,
        ReferenceGeometry,
    )

    ft, lb, sf2 = J3CUB_FT, J3CUB_LB, J3CUB_SLUG_FT2
    aero = replace(PROTOTYPE_AIRFRAME.aero, cl0=0.534, cl_alpha_per_rad=7.86, cl_max=1.85,
                   alpha_stall_rad=0.26, cl_delta_e_per_rad=0.327, cd0=0.03,
                   k_induced=0.0485, cm0=0.0, cm_alpha_per_rad=-1.68, cm_q_per_rad=-12.70,
                   cm_alphadot_per_rad=-7.59, cm_delta_e_per_rad=-1.20)
    return AirframeData("j3cub", ReferenceGeometry(178.5 * ft**2, 35.25 * ft, 5.25 * ft),
                        MassProperties((765.0 + 137.22) * lb, 538.01 * sf2, 386.81 * sf2,
                                       871.03 * sf2, 0.0), aero)


def test_j3cub_over_damped_short_period_is_named_as_such():
    # Tracked root by root from 2 m/s, the J3Cub's over-damped short period met its phugoid
    # near 4.7 m/s and the phugoid pair came out under both names at every speed above,
    # the short period's real roots nowhere.
    for s in eigen.modes_at("rigid", [15.0, 25.0, 35.0], airframe=j3cub_airframe()):
        sp = [m for m in s if m.mode == SP]
        ph = [m for m in s if m.mode == PH]
        assert len(sp) == 2 and all(m.im == 0.0 and m.re < -1.0 for m in sp), s
        assert len(ph) == 1 and ph[0].im > 0.1 and ph[0].frequency_rad_s < 1.0, s


@pytest.fixture
def over_damped_sgs(tmp_path):
    """The shipped SGS aircraft with C_mα −0.2 and C_mq −25 (from −0.573, −9.0): its rigid
    short period over-damped (two real roots, −3.71 and −2.23 1/s at 25 m/s)."""
    data = Path(__file__).parents[1] / "bioflex_jsb" / "data" / "aircraft"
    shutil.copy(data / "sgs_elastic_modes.toml", tmp_path)
    text = (data / "sgs_elastic.toml").read_text()
    for old, new in (("cm_alpha_per_rad = -0.573", "cm_alpha_per_rad = -0.2"),
                     ("cm_q_per_rad = -9.0", "cm_q_per_rad = -25.0")):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "sgs_over_damped.toml"
    path.write_text(text)
    return str(path)


def test_modes_command_names_an_over_damped_short_period(capsys, over_damped_sgs):
    import json

    code, out, _ = run_cli(capsys, "modes", "--aircraft", over_damped_sgs, "--speed", "25",
                           "--json")
    assert code == 0
    data = json.loads(out)
    assert data["rigid_block"].startswith("analytic")
    for res in data["results"]:
        sp = [m for m in res["modes"] if m["mode"] == SP]
        ph = [m for m in res["modes"] if m["mode"] == PH]
        # before: the phugoid pair (-0.053 ± 0.195i) named short_period, the real
        # short-period roots named phugoid
        assert len(sp) == 2 and all(m["im"] == 0.0 for m in sp), res["model"]
        assert len(ph) == 1 and ph[0]["frequency_rad_s"] < 0.3, res["model"]
