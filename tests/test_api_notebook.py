"""A notebook user's tasks with ``bioflex_jsb.api`` alone: what each channel of a run is, the
linear model the exported file holds, the modes at several speeds, a short summary of the
metrics, and a log read back as the runs that wrote it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.channels import ABSOLUTE, ALIASES, PERTURBATION
from bioflex_jsb.simulation.run import RunDescription

GUST_START_S, DURATION_S = 0.2, 0.8
# The ground track is logged at 60 Hz (the 3-D scene's rate) and interpolated to every step:
# measured 4.9e-11 rad of latitude (0.31 mm) and 1.9e-14 rad of longitude at 15 m/s through
# a 3 m/s sharp gust; 3e-10 rad is 1.9 mm, against 0.25 m flown between two samples.
TRACK_TOL_RAD = 3e-10


@pytest.fixture(scope="module")
def logged(optimised_wing, tmp_path_factory):
    """A rigid and a coupled run of fly_gust, logged through their recorders: (runs, log)."""
    from bioflex_jsb.sinks.mcap import RunLog

    path = tmp_path_factory.mktemp("log") / "runs.mcap"
    models = ("rigid", "coupled")
    description = RunDescription(kind="gust", wing="optimised", speed_m_s=15.0,
                                 gust="sharp:3", models=models, duration_s=DURATION_S,
                                 gust_start_s=GUST_START_S, dt_s=api.DEFAULT_DT_S,
                                 mass_basis=optimised_wing.mass_basis)
    log = RunLog.open(path, description, wing_variant=optimised_wing.variant.as_dict())
    try:
        runs = api.fly_gust(optimised_wing, models=models, duration_s=DURATION_S,
                            gust_start_s=GUST_START_S,
                            recorders={m: log.recorder(m) for m in models})
    finally:
        log.close()
    return runs, path


def test_every_channel_says_what_it_is(logged):
    """``describe()`` names each channel's unit (the run's own), kind, frame and sign; the
    perturbations are what they say: the absolute value minus the trim's (to 1e-12)."""
    run = logged[0]["coupled"]
    described = run.describe()
    assert list(described) == list(run.channels)
    unknown = [n for n, d in described.items() if d["kind"] not in (PERTURBATION, ABSOLUTE)]
    assert not unknown, unknown
    assert all(d["unit"] == run.units[n] for n, d in described.items())
    assert described["alpha"]["kind"] == PERTURBATION
    assert described["alpha_rad"]["kind"] == ABSOLUTE
    assert described["theta"]["kind"] == PERTURBATION
    assert described["theta_rad"]["kind"] == ABSOLUTE
    for alias, name in ALIASES.items():
        assert run[alias] is run[name] and alias in run, alias
    m = run.meta
    np.testing.assert_allclose(run["alpha_rad"] - run["dalpha_rad"], m["trim_alpha_rad"],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(run["theta_rad"] - run["dtheta_rad"], m["trim_theta_rad"],
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(run["airspeed_m_s"] - run["du_m_s"], m["speed_m_s"], rtol=0,
                               atol=1e-12)
    assert "dalpha_rad" in run and "nope" not in run


def test_a_log_reads_back_as_the_runs_that_wrote_it(logged):
    """``api.read_log``: every channel under the run's name and unit, in the run's order; the
    values bit for bit (the ground track within TRACK_TOL_RAD), the times to the log's
    nanosecond; the loads layout, so the metrics and the section loads are the run's."""
    runs, path = logged
    back = api.read_log(path)
    assert set(back) == set(runs)
    for model, run in runs.items():
        got = back[model]
        assert list(got.channels) == list(run.channels), model
        assert got.units == run.units
        assert np.max(np.abs(got.time_s - run.time_s)) <= 0.6e-9  # 0.5 ns and the rounding
        differ = [n for n in run.channels if not np.array_equal(got[n], run[n])]
        assert differ == ["latitude_rad", "longitude_rad"], differ
        for n in differ:
            assert np.max(np.abs(got[n] - run[n])) < TRACK_TOL_RAD, n
        assert got.meta["loads"] == run.meta["loads"]
        assert got.stopped is None
        for key in ("speed_m_s", "dt_s", "gust", "gust_start_s", "wing", "mass_basis"):
            assert got.meta[key] == run.meta[key], key
        mine, theirs = api.metrics(got).as_dict(), api.metrics(run).as_dict()
        assert mine == pytest.approx(theirs, abs=1e-9), model  # times to the nanosecond


def test_a_log_reads_a_window(logged):
    runs, path = logged
    part = api.read_log(path, start_s=0.3, end_s=0.5)["coupled"]
    run = runs["coupled"]
    keep = (run.time_s >= 0.3 - 1e-9) & (run.time_s < 0.5 - 1e-9)
    assert len(part.time_s) == int(np.sum(keep)) > 100
    assert np.array_equal(part["eta1"], run["eta1"][keep])
    assert np.array_equal(part["loads_fs_bending_n_m_s0"], run["loads_fs_bending_n_m_s0"][keep])


def test_a_read_is_bounded_and_bad_files_are_one_line(logged, tmp_path, monkeypatch):
    from bioflex_jsb.sinks.mcap import history

    path = logged[1]
    monkeypatch.setattr(history, "READ_MAX_STEPS", 100)
    with pytest.raises(InputError, match="more than one read takes .*start_s and end_s"):
        api.read_log(path)
    with pytest.raises(InputError, match="more than one read takes"):
        api.read_log(path, start_s=0.0, end_s=0.5)
    monkeypatch.undo()
    with pytest.raises(InputError, match="end after it starts"):
        api.read_log(path, start_s=0.5, end_s=0.5)
    with pytest.raises(InputError, match="finite time"):
        api.read_log(path, start_s=math.nan)
    text = tmp_path / "notes.mcap"
    text.write_text("not a log")
    with pytest.raises(InputError, match="not an MCAP file"):
        api.read_log(text)
    with pytest.raises(InputError, match="not found"):
        api.read_log(tmp_path / "missing.mcap")


def test_a_stopped_run_reads_back_stopped(tmp_path):
    """The gust command logs a run that left its valid range with its stop event: the log
    reads back with the same ``stopped`` as the run (the elastic-backward wing is past its
    flutter speed at 15 m/s and diverges within 1 s)."""
    from bioflex_jsb import cli

    out = tmp_path / "stop.mcap"
    argv = ["gust", "--wing", "elastic-backward", "--models", "coupled", "--duration", "1",
            "--gust-start", "0.2", "--out", str(out), "--json"]
    assert cli.main(argv) == 3
    back = api.read_log(out)["coupled"]
    run = api.fly_gust(api.load_wing("elastic-backward"), models=("coupled",), duration_s=1.0,
                       gust_start_s=0.2)["coupled"]
    assert run.stopped is not None
    assert back.stopped == run.stopped
    assert len(back.time_s) == len(run.time_s)


def test_the_linear_model_is_the_exported_files(optimised_wing, tmp_path):
    """``api.linear_model`` and ``bioflex-jsb export`` build one model: the same inputs (gust,
    elevator, throttle), outputs (n_z; tip_twist for an elastic wing model) and matrices, bit
    for bit; the rigid model has no tip twist."""
    from bioflex_jsb import cli
    from bioflex_jsb.sinks.model_export import read_state_space

    for model in ("rigid", "coupled", "qsd"):
        out = tmp_path / f"{model}.npz"
        assert cli.main(["export", "--model", model, "--out", str(out)]) == 0
        ss, file = api.linear_model(optimised_wing, 15.0, model), read_state_space(out)
        assert ss.inputs == file.inputs == ("w_g", "elevator", "throttle")
        assert ss.input_units == ("m/s", "rad", "-")
        assert ss.outputs == file.outputs and ss.output_units == file.output_units
        for m in "abcd":
            assert np.array_equal(getattr(ss, m), getattr(file, m)), (model, m)
        assert "n_z" in ss.outputs
        assert ("tip_twist" in ss.outputs) == (model != "rigid"), model


def test_modes_at_several_speeds(optimised_wing):
    """A sequence of speeds gives one ModeSet per speed, in its order, each the one of the
    speed alone; an empty sequence is refused in one line."""
    sets = api.modes(optimised_wing, [10, 15.0, 20])
    assert [s.speed_m_s for s in sets] == [10.0, 15.0, 20.0]
    for s in sets:
        assert s.as_dict() == api.modes(optimised_wing, s.speed_m_s).as_dict()
    assert len(api.modes(optimised_wing, (15.0,), "rigid")) == 1
    with pytest.raises(InputError, match="non-empty sequence"):
        api.modes(optimised_wing, [])
    with pytest.raises(InputError, match="speed_m_s: must be a finite number in m/s"):
        api.modes(optimised_wing, [15.0, "fast"])


def test_the_metrics_print_in_a_line(logged):
    """GustMetrics' repr is its numbers and a summary of its loads (it printed every station's
    loads dict, kilobytes); ``.loads`` keeps them."""
    m = api.metrics(logged[0]["coupled"])
    text = repr(m)
    assert len(text) < 600 and "\n" not in text, text
    assert f"peak_dq_rad_s={m.peak_dq_rad_s:.4g}" in text
    assert "loads=<force_summation, mode_displacement at 4 stations: .loads>" in text
    assert len(repr(m.loads)) > 2000


def test_the_docs_channel_table_is_the_channels():
    """docs/api.md lists every channel with its unit, kind and alias, as channels.py says."""
    from pathlib import Path

    from bioflex_jsb.simulation.channels import CHANNELS

    text = (Path(__file__).resolve().parents[1] / "docs" / "api.md").read_text("utf-8")
    for name, c in CHANNELS.items():
        alias = f"`{c.alias}`" if c.alias else ""
        assert f"| `{name}` | {c.unit} | {c.kind} | {c.meaning} | {alias} |" in text, name


def test_a_sweep_cases_log_reads_back_as_its_row_says(tmp_path):
    """A sweep case's log is read back like a gust run's: a diverged case (elastic-backward
    at 15 m/s, past its flutter speed) reads back stopped, as its row's error says."""
    from bioflex_jsb.sweep.campaign import parse_campaign
    from bioflex_jsb.sweep.evaluate import run_case

    camp = parse_campaign({
        "name": "stop", "metrics": ["gust"], "run": {"duration_s": 1.0, "gust_start_s": 0.2},
        "axes": {"wings": ["elastic-backward"], "speeds_m_s": [15.0], "gusts": ["sharp:3"],
                 "models": ["coupled"]}})
    case = camp.cases()[0]
    row = run_case(case, str(tmp_path))
    assert row["status"] == "diverged"
    back = api.read_log(tmp_path / f"{case.case_id}.mcap")["coupled"]
    assert " ".join(str(back.stopped).split()) == row["error"]
    assert back.meta["gust_start_s"] == 0.2 and api.metrics(back).diverged
