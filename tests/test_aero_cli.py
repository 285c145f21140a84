"""--aero and --structural-damping on gust, compare and modes (issue 15)."""

from __future__ import annotations

import json

import pytest

from bioflex_jsb.cli import main


def run_json(argv, capsys):
    status = main(argv)
    return status, json.loads(capsys.readouterr().out)


def test_compare_unsteady_cosimulation_agrees_with_the_unsteady_lti(capsys):
    """Issue 15's done-when: NRMSE <= 0.05 on u, alpha, q, theta, eta1 on a small gust."""
    status, data = run_json(["compare", "--aero", "unsteady", "--gust", "sharp:0.3",
                             "--duration", "3", "--no-log", "--json"], capsys)
    assert status == 0
    assert max(data["nrmse"].values()) <= 0.05, data["nrmse"]


def test_gust_unsteady_flies_rigid_and_coupled_and_refuses_qsd(capsys):
    status, data = run_json(["gust", "--aero", "unsteady", "--duration", "1", "--no-log",
                             "--json"], capsys)
    assert status == 0 and set(data["summary"]) == {"rigid", "coupled"}
    assert main(["gust", "--aero", "unsteady", "--models", "qsd", "--no-log", "--json"]) == 2
    err = capsys.readouterr().err
    assert "qsd" in err and err.count("\n") == 1


def test_modes_unsteady_backward_wing_short_period_unstable_at_20_not_15(capsys):
    """The unsteady model's body-freedom flutter of the backward-axis wing lies between 15 and
    20 m/s (docs/aeroelasticity.md: 18.86 m/s): its short period is stable at 15, not at 20."""
    status, data = run_json(["modes", "--aero", "unsteady", "--wing", "inertial-backward",
                             "--speed", "15", "--speed", "20", "--models", "coupled",
                             "--json"], capsys)
    assert status == 0
    sp = {r["speed_m_s"]: m for r in data["results"] for m in r["modes"]
          if m["mode"] == "short_period"}
    assert sp[15.0]["re"] < 0.0 < sp[20.0]["re"]


@pytest.mark.parametrize("value", ["-0.1", "1", "nan", "x"])
def test_structural_damping_out_of_range_is_one_line(value, capsys):
    assert main(["modes", "--structural-damping", value]) == 2
    err = capsys.readouterr().err
    assert "damping" in err and err.count("\n") == 1


def test_structural_damping_moves_the_aeroelastic_roots(capsys):
    _, low = run_json(["modes", "--models", "coupled", "--structural-damping", "0", "--json"],
                      capsys)
    _, high = run_json(["modes", "--models", "coupled", "--structural-damping", "0.2",
                        "--json"], capsys)

    def ae1(data):
        return next(m for r in data["results"] for m in r["modes"]
                    if m["mode"] == "aeroelastic_1")

    assert ae1(high)["re"] < ae1(low)["re"] - 1.0


def test_trim_with_a_wing_reports_its_elastic_trim_and_refuses_beyond_divergence(capsys):
    status, data = run_json(["trim", "--wing", "inertial-backward", "--speed", "15", "--json"],
                            capsys)
    assert status == 0
    e = data["elastic"]
    # the backward-axis wing twists leading edge up at 15 m/s (docs/decisions.md: +2.3 deg)
    assert 1.0 < e["tip_twist_deg"] < 4.0 and e["converged"]
    assert e["divergence_speed_m_s"] == pytest.approx(18.73, abs=0.05)
    assert main(["trim", "--wing", "inertial-backward", "--speed", "20"]) == 2
    err = capsys.readouterr().err
    assert "divergence speed 18.73 m/s" in err and err.count("\n") == 1


def test_rerun_flies_an_unsteady_damped_run_as_it_was():
    from bioflex_jsb.cli.rerun import argv_for
    from bioflex_jsb.simulation.run import RunDescription

    d = RunDescription("gust", "optimised", 15.0, models=("rigid", "coupled"),
                       extra={"aero": "unsteady", "structural_damping": 0.02})
    argv = dict(a.split("=", 1) for a in argv_for(d)[1:])
    assert argv["--aero"] == "unsteady"
    assert float(argv["--structural-damping"]) == 0.02
