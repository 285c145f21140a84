"""The lattice's antisymmetric loading in the nonlinear full-span step and on the command line
(docs/lateral.md, "The lattice in the lateral elastic model"): the co-simulation with both
halves on the lattice is the lateral LTI model on the lattice; ``--lateral-aero`` is refused
in one line where no lateral elastic model is built; a run description records it and a
rerun flies it again."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bioflex_jsb import api
from tests.cli_helpers import assert_one_line_error, run_cli


@pytest.fixture(scope="module")
def rolling_air():
    """The prototype in air rolling at 0.1 rad/s (15 m scale), coupled, 1 s, both halves,
    on the strips and on the lattice (test_compare_full_span's api case)."""
    ac = api.load_aircraft("bioflex_optimised")
    return {la: api.compare(ac, 15.0, gust="none+roll:0.1:15", model="coupled",
                            duration_s=1.0, span="full", lateral_aero=la)
            for la in ("strips", "lattice")}


def test_full_span_step_on_the_lattice_is_its_lateral_model(rolling_air):
    """The nonlinear step on the lattice against the lateral LTI on the lattice: within the
    strips' tolerances of test_compare_full_span (NRMSE measured p 0.0053, asym_eta1 0.0310,
    phi 0.0085, beta 0.0233 on the lattice; 0.0085, 0.0306, 0.0135, 0.0578 on the strips)."""
    c = rolling_air["lattice"]
    assert c.nonlinear.meta["lateral_aero"] == "lattice"
    assert "lateral_aero" not in rolling_air["strips"].nonlinear.meta  # the default's meta
    assert c.nrmse["p_rad_s"] < 0.02 and c.nrmse["asym_eta1"] < 0.05
    assert c.nrmse["phi_rad"] < 0.02 and c.nrmse["beta_rad"] < 0.07


def test_the_lattice_changes_the_flown_modes(rolling_air):
    """The lattice's smaller antisymmetric lift (C_lp −0.542 against the strips' −0.660)
    twists the wing less: the peak |asym_eta1| and elastic rolling moment fall (measured
    5.09e-4 against 7.67e-4 rad, 0.0143 against 0.0269 N·m: ratios 0.66, 0.53), a change
    a lattice not reaching the step would not make: below 0.95 of the strips'."""
    peak = {la: {k: float(np.max(np.abs(np.asarray(c.nonlinear[k], dtype=float))))
                 for k in ("asym_eta1", "modal_roll_n_m")}
            for la, c in rolling_air.items()}
    for k in ("asym_eta1", "modal_roll_n_m"):
        assert peak["lattice"][k] < 0.95 * peak["strips"][k], (k, peak)


@pytest.mark.parametrize(("argv", "needle"), [
    (("gust", "--lateral-aero", "lattice", "--duration", "1"), "give --span full"),
    (("compare", "--lateral-aero", "lattice", "--span", "half", "--gust", "sharp:0.3"),
     "give --span full"),
    (("compare", "--lateral-aero", "lattice", "--span", "full", "--aero", "unsteady",
      "--gust", "none+roll:0.1:15"), "quasi-steady"),
    (("modes", "--lateral-aero", "lattice"), "give --axis lateral"),
    (("modes", "--axis", "lateral", "--models", "coupled", "--aero", "unsteady",
      "--lateral-aero", "lattice"), "quasi-steady"),
    (("export", "--lateral-aero", "lattice", "--out", "x.npz"), "give --axis lateral"),
    (("aileron", "--lateral-aero", "lattice"), "a clamped wing takes --lift-slope"),
    (("modes", "--axis", "lateral", "--lateral-aero", "panels"), "invalid choice"),
])
def test_lateral_aero_refusals(capsys, argv, needle):
    code, _, err = run_cli(capsys, *argv, *(("--no-log",) if argv[0] in ("gust", "compare")
                                          else ()))
    assert_one_line_error(code, err, needle)


def test_aileron_cli_lattice(capsys):
    """aileron --aircraft ... --lateral-aero lattice --json: the lattice's rigid C_lp and the
    reversal (docs/lateral.md's table), the choice in the JSON; the default's JSON has no
    lateral_aero key."""
    code, out, err = run_cli(capsys, "aileron", "--aircraft", "bioflex_optimised",
                             "--lateral-aero", "lattice", "--json")
    assert code == 0, err
    d = json.loads(out)
    assert d["lateral_aero"] == "lattice"
    assert d["rigid"]["cl_p_per_rad"] == pytest.approx(-0.54196, rel=1e-3)
    assert d["reversal_speed_m_s"] == pytest.approx(12.885, rel=1e-3)
    code, out, err = run_cli(capsys, "aileron", "--aircraft", "bioflex_optimised", "--json")
    assert code == 0 and "lateral_aero" not in json.loads(out)


def test_rerun_flies_the_lattice_with_both_halves():
    from bioflex_jsb.cli.rerun import argv_for
    from bioflex_jsb.simulation.run import RunDescription

    d = RunDescription("gust", "optimised", 15.0, models=("coupled",),
                       extra={"lateral_aero": "lattice", "span": "full"})
    argv = dict(a.split("=", 1) for a in argv_for(d)[1:])
    assert argv["--lateral-aero"] == "lattice" and argv["--span"] == "full"
    plain = argv_for(RunDescription("gust", "optimised", 15.0, models=("coupled",)))
    assert not any(a.startswith(("--lateral-aero", "--span")) for a in plain)


def test_ardupilot_backend_flies_the_lattice():
    """``ardupilot --span full --lateral-aero lattice`` without ArduPlane (servo frames, as
    tests/test_ardupilot_full_span.py): a right-aileron step's roll rate 0.3 s on, elastic
    over rigid, measured −2.83 on the strips and −1.31 on the lattice. The aileron's lift
    on the modes and the modes' rolling moment are each about 0.8 of the strips' (docs/
    lateral.md), so the reversing increment, 1 − ratio = 3.83 on the strips, is about 0.64
    of it: 1 − 0.64 × 3.83 = −1.45 expected; the lattice's is within 0.5 of that and less
    reversed than the strips'."""
    from bioflex_jsb.drivers import ardupilot as ad
    from bioflex_jsb.runtime.fdm import Airframe

    idle, right = (1500, 1500, 1050, 1500) + (0,) * 12, (1510, 1500, 1050, 1500) + (0,) * 12
    ac = api.load_aircraft("bioflex_optimised")

    def roll(aircraft, model):
        ph = ad.ArduPilotPhysics(Airframe(), aircraft.wing(), model, span="full",
                                 aileron=aircraft.definition.aileron)
        for _ in range(ph.launch_hold_steps + ph.stroke_steps + int(round(0.25 / ph.dt_s))):
            ph.step(idle, 1200)
        p0 = ph.core.get["p"]()
        for _ in range(int(round(0.3 / ph.dt_s))):
            ph.step(right, 1200)
        return ph.core.get["p"]() - p0, ph

    p_rigid, _ = roll(ac, "rigid")
    p_strips, ph_strips = roll(ac, "coupled")
    p_lattice, ph_lattice = roll(ac.with_lateral_aero("lattice"), "coupled")
    assert ph_strips.core.antisymmetric_wing.lift_matrix_m is None
    assert ph_lattice.core.antisymmetric_wing.lift_matrix_m is not None
    assert p_strips / p_rigid < p_lattice / p_rigid < 0.0
    assert p_lattice / p_rigid == pytest.approx(1.0 - 0.64 * (1.0 - p_strips / p_rigid),
                                                abs=0.5)


def test_a_logged_lattice_run_is_flown_again_by_rerun(capsys, tmp_path):
    """gust --span full --lateral-aero lattice --out: the log's description records the
    loading and rerun flies it (both halves, the lattice) to the same messages."""
    first, again = tmp_path / "g.mcap", tmp_path / "r.mcap"
    code, out, err = run_cli(capsys, "gust", "--span", "full", "--lateral-aero", "lattice",
                             "--gust", "sharp:0.3", "--duration", "0.6", "--models",
                             "coupled", "--out", str(first), "--json")
    assert code == 0, err
    assert json.loads(out)["lateral_aero"] == "lattice"
    from bioflex_jsb.cli.rerun import argv_from_log

    argv = dict(a.split("=", 1) for a in argv_from_log(str(first))[1:])
    assert argv["--lateral-aero"] == "lattice" and argv["--span"] == "full"
    code, out, err = run_cli(capsys, "rerun", str(first), "--out", str(again))
    assert code == 0, err
    assert "same result" in out


def test_c172_rolling_gust_on_the_lattice_is_its_lateral_model():
    """The c172_elastic's rolling gust (0.1 rad/s over 40 m, 3 s, coupled, both halves;
    test_compare_full_span's case, its tolerances) on the lattice, against the lateral LTI on
    the lattice. Measured NRMSE beta 0.0044, p 0.0022, phi 0.0006, asym_eta1 0.0086,
    modal_roll_n_m 0.0113 (strips 0.0044, 0.0021, 0.0005, 0.0086, 0.0113); the peak elastic
    rolling moment 24.4 against the strips' 37.7 N·m (its dihedral's sideslip terms on the
    lattice too)."""
    c = api.compare(api.load_aircraft("c172_elastic"), 57.8, gust="none+roll:0.1:40",
                    model="coupled", duration_s=3.0, span="full", lateral_aero="lattice")
    tolerance = {"p_rad_s": 0.01, "beta_rad": 0.01, "r_rad_s": 0.01, "phi_rad": 0.002,
                 "asym_eta1": 0.025, "modal_roll_n_m": 0.03}
    for channel, tol in tolerance.items():
        assert c.nrmse[channel] < tol, (channel, c.nrmse[channel])
    peak = float(np.max(np.abs(np.asarray(c.nonlinear["modal_roll_n_m"], dtype=float))))
    assert 20.0 < peak < 30.0  # the strips' 37.7 N·m
