"""Nonlinear gust runs: convergence in the time step, LTI agreement, divergence, CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bioflex_jsb.cli import main
from bioflex_jsb.drivers.gust import WINDOW_S, RunConfig, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S


@pytest.fixture(scope="module")
def airframe():
    return Airframe()


def peaks(run):
    after = run.time_s >= 0.5
    return {c: float(np.max(np.abs(run[c][after]))) for c in ("u", "alpha", "q", "theta", "eta1")}


@pytest.mark.parametrize("gust", ["sharp:0.3", "sharp:3"])
def test_halving_the_time_step_changes_peaks_by_less_than_1_percent(airframe, gust):
    # The Section 5 case (optimised wing, 15 m/s) at the default step and at half of it.
    wing = build_wing(VARIANTS["optimised"]).model
    coarse = run_gust(airframe, wing, "coupled", RunConfig(15.0, parse_gust(gust), 3.0))
    fine = run_gust(airframe, wing, "coupled",
                    RunConfig(15.0, parse_gust(gust), 3.0, dt_s=DEFAULT_DT_S / 2))
    pc, pf = peaks(coarse), peaks(fine)
    for name in pc:
        assert pc[name] == pytest.approx(pf[name], rel=0.01), name


def test_fig21_run_converges_with_the_step(airframe):
    """Optimised wing, 15 m/s, 3 m/s sharp gust (Fig. 21), 3 s: the default step against a
    quarter of it, on the coarse run's times. Measured: u 0.15 %, α 0.6 %, q 0.5 %, θ 0.3 %,
    η₁ 0.8 % (with the elastic loads one step behind the rigid ones, as before, η₁ was 1.8 %)."""
    from bioflex_jsb.simulation.results import nrmse

    wing = build_wing(VARIANTS["optimised"]).model
    coarse = run_gust(airframe, wing, "coupled", RunConfig(15.0, parse_gust("sharp:3"), 3.0))
    fine = run_gust(airframe, wing, "coupled",
                    RunConfig(15.0, parse_gust("sharp:3"), 3.0, dt_s=DEFAULT_DT_S / 4))
    errors = {c: nrmse(np.interp(coarse.time_s, fine.time_s, fine[c]), coarse[c])
              for c in ("u", "alpha", "q", "theta", "eta1")}
    assert max(errors.values()) < 0.01, errors


def test_rigid_run_has_no_modal_loads_and_coupled_run_has(airframe):
    wing = build_wing(VARIANTS["original"]).model
    setup = RunConfig(15.0, parse_gust("sharp:0.5"), duration_s=1.5)
    rigid = run_gust(airframe, wing, "rigid", setup)
    coupled = run_gust(airframe, wing, "coupled", setup)
    assert np.all(rigid["lift_n"] == 0.0)
    assert np.max(np.abs(coupled["lift_n"])) > 0.05  # N: a visible elastic load
    # washout under an upward gust (C_alpha^Q1 < 0 for the original wing): eta1 goes negative
    assert np.min(coupled["eta1"]) < 0.0


def test_progress_is_reported_once_a_block_up_to_every_step(airframe):
    """``progress`` (a progress bar's hook, drivers/gust.py) sees the steps flown after each
    block of WINDOW_S: increasing, the last the whole run, and nothing per step."""
    wing = build_wing(VARIANTS["original"]).model
    setup = RunConfig(15.0, parse_gust("sharp:0.5"), duration_s=2.0)
    seen: list[int] = []
    run = run_gust(airframe, wing, "coupled", setup, progress=seen.append)
    n = len(run.time_s)
    block = int(round(WINDOW_S / DEFAULT_DT_S))
    assert n == int(round(2.0 / DEFAULT_DT_S)) and run.stopped is None
    assert seen == [min(n, (i + 1) * block) for i in range(-(-n // block))]


def test_before_the_gust_the_trimmed_aircraft_stays_put(airframe):
    wing = build_wing(VARIANTS["original"]).model
    run = run_gust(airframe, wing, "coupled", RunConfig(15.0, parse_gust("sharp:1"), 1.0,
                                                       gust_start_s=0.9))
    before = run.time_s < 0.9
    # trim residuals only: |Δα| < 0.01° and |q| < 0.01°/s over 0.9 s
    assert np.max(np.abs(run["alpha"][before])) < np.radians(0.01)
    assert np.max(np.abs(run["q"][before])) < np.radians(0.01)


@pytest.mark.parametrize("wing", ["original", "optimised"])
def test_small_gust_lti_and_nonlinear_agree_within_5_percent(capsys, wing):
    code = main(["compare", "--wing", wing, "--speed", "15", "--gust", "sharp:0.3", "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0
    flight = {c: v for c, v in data["nrmse"].items() if not c.startswith("loads_")}
    assert set(flight) == {"u", "alpha", "q", "theta", "eta1"}  # and the section loads:
    for channel, value in flight.items():  # tests/test_loads_run.py
        assert value <= 0.05, (channel, value)


def test_above_its_flutter_speed_elastic_backward_diverges_cleanly(capsys, tmp_path):
    out = tmp_path / "run.mcap"
    code = main(["gust", "--wing", "elastic-backward", "--speed", "22", "--gust", "sharp:0.3",
                 "--models", "coupled", "--duration", "4", "--out", str(out), "--json"])
    captured = capsys.readouterr()
    assert code == 3
    assert "diverged" in captured.err and "aeroelastic_1" in captured.err
    assert "Traceback" not in captured.err
    data = json.loads(captured.out)
    assert data["stopped"] and out.stat().st_size > 1000  # the log up to the stop is kept


def test_main_job_runs_three_models(capsys, tmp_path):
    png = tmp_path / "g.png"
    code = main(["gust", "--duration", "2", "--plot", str(png), "--json"])
    data = json.loads(capsys.readouterr().out)
    assert code == 0, data["stopped"]
    assert set(data["summary"]) == {"rigid", "coupled", "qsd"}
    assert data["wing"] == "optimised" and data["gust"] == "sharp:3"
    s = data["summary"]
    for metrics in s.values():
        assert metrics["peak_dalpha_rad"] > 0.0
    # Section 5: the elastic wing lowers the pitch-rate peak against rigid
    assert s["coupled"]["peak_dq_rad_s"] < s["rigid"]["peak_dq_rad_s"]
    assert png.stat().st_size > 20_000


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["gust", "--gust", "gusty:3"], "unknown gust form"),
        (["gust", "--gust", "1cos:3:-5"], "length must be > 0"),
        (["gust", "--duration", "0"], "duration must be"),
        (["gust", "--duration", "-1"], "duration must be"),
        (["gust", "--models", "rigid,floppy"], "unknown model"),
        (["compare", "--wing", "nope"], "valid names"),
    ],
)
def test_bad_gust_input_is_one_line_and_exit_2(capsys, argv, needle):
    code = main(argv)
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and needle in lines[0], err
