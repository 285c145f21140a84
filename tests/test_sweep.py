"""Sweeps: campaign files, local processes vs a Dask LocalCluster, resume, failures.

Dask (``dask[distributed]``) and pyarrow are dependencies of the project: these tests do
not skip without them.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path

import pytest

from bioflex_jsb import cli
from bioflex_jsb.sweep.campaign import (
    RUN_INFO_COLUMNS,
    CampaignError,
    failed_row,
    load_campaign,
    parse_campaign,
)
from bioflex_jsb.sweep.driver import missing_cases, run_sweep
from bioflex_jsb.sweep.local import LocalExecutor
from bioflex_jsb.sweep.store import open_store, read_results

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "scripts" / "campaigns" / "example.toml"

# 4 short cases: one ok, one that diverges (elastic axis aft, past its flutter speed), two
# that cannot trim (below the stall speed) and are recorded as failed.
SMALL = """
name = "small"
metrics = ["gust", "flutter", "eigenvalues", "coefficients"]

[run]
duration_s = 1.0
gust_start_s = 0.2

[axes]
wings = ["optimised", "elastic-backward"]
speeds_m_s = [6.0, 15.0]
gusts = ["sharp:3"]
models = ["coupled"]
"""


def sweep(argv, monkeypatch):
    """``bioflex-jsb sweep ARGV`` through the real entry point (exit status)."""
    if "sweep" not in cli.COMMAND_MODULES:
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli.COMMAND_MODULES + ("sweep",))
    return cli.main(["sweep", *map(str, argv)])


def comparable(rows):
    """Rows without where/when they ran."""
    return [{k: v for k, v in r.items() if k not in RUN_INFO_COLUMNS} for r in rows]


@pytest.fixture()
def small(tmp_path):
    path = tmp_path / "small.toml"
    path.write_text(SMALL)
    return path


# ---------------------------------------------------------------------------------------
# Campaign files (pure)
# ---------------------------------------------------------------------------------------
def test_example_campaign_has_24_cases_with_stable_unique_ids():
    a = load_campaign(EXAMPLE).cases()
    b = load_campaign(EXAMPLE).cases()
    assert len(a) == 24
    assert len({c.case_id for c in a}) == 24
    assert [c.case_id for c in a] == [c.case_id for c in b]
    # seeds multiply the turbulence only
    assert sorted({c.gust for c in a}) == ["dryden:1:100:1", "dryden:1:100:2", "sharp:3"]
    assert {c.speed_m_s for c in a} == {15.0, 18.0}


def test_case_id_is_the_inputs_not_the_position():
    base = {"axes": {"wings": ["original"], "speeds_m_s": [15.0, 18.0], "gusts": ["sharp:3"]}}
    ids = {c.speed_m_s: c.case_id for c in parse_campaign(base).cases()}
    other = {"name": "other",
             "axes": {"wings": ["original"], "speeds_m_s": [18.0], "gusts": ["sharp:3"]}}
    assert parse_campaign(other).cases()[0].case_id == ids[18.0]
    longer = {"run": {"duration_s": 6.0}, **other}
    assert parse_campaign(longer).cases()[0].case_id != ids[18.0]


def test_ranges_and_axis_positions():
    c = parse_campaign({
        "metrics": ["coefficients"],
        "axes": {"x_inertial_frac": {"start": 0.2, "stop": 0.8, "num": 4},
                 "x_elastic_frac": {"start": 0.25, "stop": 0.5, "step": 0.125},
                 "speeds_m_s": {"start": 12.0, "stop": 15.0, "step": 1.5}},
    })
    assert [w.x_inertial_frac for w in c.wings[::3]] == [0.2, 0.4, 0.6, 0.8]
    assert [w.x_elastic_frac for w in c.wings[:3]] == [0.25, 0.375, 0.5]
    assert all(w.pinned_c_eta1_q1 is None for w in c.wings)
    assert c.speeds_m_s == (12.0, 13.5, 15.0)
    assert c.gusts == ("none",) and c.n_cases == 12 * 3


@pytest.mark.parametrize("text, key", [
    ("speed = 3\n[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3']", "speed"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3']\nspeed=[1]",
     "axes: unknown key 'speed'; accepted: "),
    ("[axes]\nwings=['original']\nspeeds_m_s=[]\ngusts=['sharp:3']", "axes.speeds_m_s"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15, -1]\ngusts=['sharp:3']",
     "axes.speeds_m_s[1]"),
    ("[axes]\nwings=['original']\nspeeds_m_s={start=15, stop=12, step=1}\ngusts=['sharp:3']",
     "axes.speeds_m_s"),
    ("[axes]\nwings=['nope']\nspeeds_m_s=[15]\ngusts=['sharp:3']", "axes.wings[0]"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3', 'gentle:1']",
     "axes.gusts[1]"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3']\nmodels=['stiff']",
     "axes.models[0]"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3']\nseeds=[1]",
     "axes.seeds"),
    ("[axes]\nx_inertial_frac=[0.2, 1.5]\nx_elastic_frac=[0.3]\nspeeds_m_s=[15]\n"
     "gusts=['sharp:3']", "axes.x_inertial_frac[1]"),
    ("metrics=['gust','lift']\n[axes]\nwings=['original']\nspeeds_m_s=[15]\n"
     "gusts=['sharp:3']", "metrics"),
    ("[run]\nduration_s=1\ngust_start_s=2\n[axes]\nwings=['original']\nspeeds_m_s=[15]\n"
     "gusts=['sharp:3']", "run.gust_start_s"),
    ("[run]\ndt=0.01\n[axes]\nwings=['original']\nspeeds_m_s=[15]\ngusts=['sharp:3']",
     "run: unknown key 'dt'; accepted: aero, dt_s, duration_s"),
    ("[axes]\nwings=['original']\nspeeds_m_s=[15]", "axes.gusts"),
    ("[axes\nwings=['original']", "not valid TOML"),
    # num = 1e8 built the list before any check: the command hung (the review, 2026-12-03)
    ("[axes]\nwings=['original']\nspeeds_m_s={start=10.0, stop=40.0, num=100000000}\n"
     "gusts=['sharp:3']", "axes.speeds_m_s: 100000000 values is too many"),
])
def test_bad_campaign_exits_2_with_one_line_naming_the_key(tmp_path, monkeypatch, capsys,
                                                           text, key):
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(CampaignError):
        load_campaign(bad)
    code = sweep([bad, "--out", tmp_path / "r.csv"], monkeypatch)
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1, err
    assert key in err, err
    assert not (tmp_path / "r.csv").exists()


@pytest.mark.parametrize("argv, needle", [
    (["--out", "r.txt"], "suffix"),
    (["--workers", "0"], "--workers"),
    (["--scheduler", "http://x"], "--scheduler"),
])
def test_bad_arguments_exit_2_one_line(small, tmp_path, monkeypatch, capsys, argv, needle):
    monkeypatch.chdir(tmp_path)
    code = sweep([small, *argv], monkeypatch)
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and needle in err, err


# ---------------------------------------------------------------------------------------
# Runs
# ---------------------------------------------------------------------------------------
@pytest.mark.slow  # process pools and a Dask cluster: 6-12 s
def test_local_processes_and_dask_localcluster_give_identical_tables(small, tmp_path,
                                                                     monkeypatch, capsys):
    local, dask = tmp_path / "local.csv", tmp_path / "dask.parquet"
    assert sweep([small, "--out", local, "--workers", 2], monkeypatch) == 0
    # --scheduler local: LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
    # dashboard_address=None) on loopback
    assert sweep([small, "--out", dask, "--scheduler", "local", "--workers", 2],
                 monkeypatch) == 0
    capsys.readouterr()
    a, b = read_results(local), read_results(dask)
    assert len(a) == 4
    assert comparable(a) == comparable(b)
    assert len({r["worker"] for r in b}) == 2  # both Dask workers took cases
    by = {(r["wing"], r["speed_m_s"]): r for r in a}
    ok = by[("optimised", 15.0)]
    assert ok["status"] == "ok" and ok["error"] is None
    assert 0.5 < ok["peak_dn_z"] < 5.0 and ok["short_period_damping"] > 0.0
    assert ok["flutter_speed_m_s"] is None and ok["c_eta1_q1"] == pytest.approx(-0.14)
    div = by[("elastic-backward", 15.0)]
    assert div["status"] == "diverged" and "aeroelastic_1" in div["error"]
    # a diverged run has no response metrics (issue 18: null, not the zeros of a stopped run)
    assert div["peak_dn_z"] is None and div["time_flown_s"] < 1.0
    assert div["flutter_speed_m_s"] == pytest.approx(15.45, abs=0.5)
    slow = by[("optimised", 6.0)]
    assert slow["status"] == "failed" and slow["error"].startswith("TrimError")
    assert slow["peak_dn_z"] is None


class StopAfter:
    """An executor that is interrupted (Ctrl-C) after ``n`` cases."""

    name = "local"

    def __init__(self, inner, n):
        self.inner, self.n = inner, n

    def run(self, cases):
        for k, item in enumerate(self.inner.run(cases)):
            yield item
            if k + 1 == self.n:
                raise KeyboardInterrupt


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_resume_runs_only_the_missing_cases(small, tmp_path, monkeypatch, capsys, suffix):
    out = tmp_path / f"r{suffix}"
    campaign = load_campaign(small)
    cases = campaign.cases()
    store = open_store(out, campaign.columns(), resume=False)
    with LocalExecutor(2) as ex:
        summary = run_sweep(cases, store, StopAfter(ex, 2))
    store.close()
    assert summary.interrupted and summary.run == 2
    first = {r["case_id"]: r["started_unix_s"] for r in read_results(out)}
    assert len(first) == 2

    # without --resume an existing output is refused
    assert sweep([small, "--out", out], monkeypatch) == 2
    assert "--resume" in capsys.readouterr().err

    assert sweep([small, "--out", out, "--resume", "--json"], monkeypatch) == 0
    assert '"already_done": 2' in capsys.readouterr().out
    rows = read_results(out)
    assert sorted(r["case_id"] for r in rows) == sorted(c.case_id for c in cases)
    for r in rows:  # the finished cases were not run again
        if r["case_id"] in first:
            assert r["started_unix_s"] == first[r["case_id"]]
    # and a complete table needs nothing more
    assert sweep([small, "--out", out, "--resume", "--json"], monkeypatch) == 0
    assert '"run": 0' in capsys.readouterr().out
    if suffix == ".parquet":
        assert [p.name for p in out.iterdir() if not p.name.startswith(".")] == [
            "results.parquet"]  # merged: one visible file
        assert not list(out.rglob("part-*.parquet"))


def test_resume_refuses_another_campaigns_table(small, tmp_path, monkeypatch, capsys):
    """``--resume`` onto a table whose rows are not this campaign's cases (another campaign,
    or this one with other settings) is refused in one line and the table left as it was;
    it merged them silently (the review, 2026-12-03)."""
    out = tmp_path / "r.csv"
    campaign = load_campaign(small)
    store = open_store(out, campaign.columns(), resume=False)
    with LocalExecutor(1) as ex:
        run_sweep(campaign.cases()[:1], store, ex)
    store.close()
    before = out.read_bytes()
    other = tmp_path / "other.toml"
    other.write_text(SMALL.replace("duration_s = 1.0", "duration_s = 1.5"))
    assert sweep([other, "--out", out, "--resume"], monkeypatch) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "1 of its 1 cases are not cases of campaign" in err[0], err
    assert out.read_bytes() == before


def test_csv_row_cut_off_by_a_kill_is_dropped_on_resume(small, tmp_path):
    out = tmp_path / "r.csv"
    campaign = load_campaign(small)
    store = open_store(out, campaign.columns(), resume=False)
    store.append(failed_row(campaign.cases()[0], "x"))
    store.close()
    with open(out, "a") as fh:
        fh.write(campaign.cases()[1].case_id + ",1,optimis")  # half a row
    store = open_store(out, campaign.columns(), resume=True)
    assert store.done_ids == {campaign.cases()[0].case_id}
    store.close()
    assert missing_cases(campaign.cases(), store.done_ids) == campaign.cases()[1:]


# ---------------------------------------------------------------------------------------
# Worker death: retried once, then recorded failed
# ---------------------------------------------------------------------------------------
def dying_case(case, log_dir):
    """Stand-in for run_case: counts attempts in ``log_dir``; 6 m/s kills its worker."""
    marks = Path(log_dir)
    with open(marks / f"{case.case_id}.{os.getpid()}.{len(list(marks.iterdir()))}", "w"):
        pass
    if case.speed_m_s == 6.0 and case.wing.name == "optimised":
        os._exit(9)
    row = failed_row(case, "")
    row.update(status="ok", error=None)
    return row


def _attempts(marks: Path, case_id: str) -> int:
    return sum(1 for p in marks.iterdir() if p.name.startswith(case_id))


def test_local_worker_death_is_retried_once_then_recorded_failed(small, tmp_path):
    marks = tmp_path / "marks"
    marks.mkdir()
    cases = load_campaign(small).cases()
    with LocalExecutor(2, log_dir=str(marks), fn=dying_case) as ex:
        rows = {c.case_id: row for c, row in ex.run(cases)}
    assert len(rows) == 4
    killer = next(c for c in cases if c.speed_m_s == 6.0 and c.wing.name == "optimised")
    assert rows[killer.case_id]["status"] == "failed"
    assert "died twice" in rows[killer.case_id]["error"]
    assert _attempts(marks, killer.case_id) == 2
    others = [c for c in cases if c is not killer]
    assert all(rows[c.case_id]["status"] == "ok" for c in others)
    assert all(_attempts(marks, c.case_id) <= 2 for c in others)


@pytest.mark.slow  # a Dask cluster: 16 s
def test_dask_worker_death_is_retried_once_then_recorded_failed(small, tmp_path):
    from bioflex_jsb.sweep.dask_cluster import DaskExecutor

    marks = tmp_path / "marks"
    marks.mkdir()
    cases = load_campaign(small).cases()
    with DaskExecutor(None, workers=2, log_dir=str(marks), fn=dying_case) as ex:
        rows = {c.case_id: row for c, row in ex.run(cases)}
    killer = next(c for c in cases if c.speed_m_s == 6.0 and c.wing.name == "optimised")
    assert rows[killer.case_id]["status"] == "failed"
    assert "KilledWorker" in rows[killer.case_id]["error"]
    assert _attempts(marks, killer.case_id) == 2
    assert sum(r["status"] == "ok" for r in rows.values()) == 3


def test_dask_modules_only_in_the_dask_adapter():
    for path in (ROOT / "bioflex_jsb").rglob("*.py"):
        text = path.read_text()
        if path.name != "dask_cluster.py":
            assert "import dask" not in text and "from distributed" not in text \
                and "import distributed" not in text, path


def test_lti_only_campaign_and_per_case_logs(tmp_path, monkeypatch, capsys):
    lti = tmp_path / "lti.toml"
    lti.write_text('metrics = ["eigenvalues", "coefficients"]\n[axes]\n'
                   'x_inertial_frac = [0.25]\nx_elastic_frac = [0.22, 0.5]\n'
                   'speeds_m_s = [15.0]\nmodels = ["rigid", "coupled"]\n')
    out = tmp_path / "lti.csv"
    assert sweep([lti, "--out", out, "--workers", 1], monkeypatch) == 0
    rows = read_results(out)
    assert len(rows) == 4 and all(r["status"] == "ok" for r in rows)
    assert all(r["gust"] == "none" and "peak_dn_z" not in r for r in rows)
    rigid = [r for r in rows if r["model"] == "rigid"]
    assert all(r["aeroelastic_1_re_rad_s"] is None for r in rigid)
    fwd = next(r for r in rows if r["x_elastic_frac"] == 0.22)
    aft = next(r for r in rows if r["x_elastic_frac"] == 0.5)
    assert fwd["c_eta1_q1"] < aft["c_eta1_q1"]  # the elastic axis forward is the stable side

    one = tmp_path / "one.toml"
    one.write_text('[run]\nduration_s = 0.5\ngust_start_s = 0.1\n[axes]\n'
                   'wings = ["optimised"]\nspeeds_m_s = [15.0]\ngusts = ["1cos:2:10"]\n')
    logs = tmp_path / "logs"
    assert sweep([one, "--out", tmp_path / "one.csv", "--workers", 1, "--logs", logs],
                 monkeypatch) == 0
    (row,) = read_results(tmp_path / "one.csv")
    log = logs / f"{row['case_id']}.mcap"
    assert log.is_file() and log.read_bytes()[:8] == b"\x89MCAP0\r\n"
    # the case's log has the 3-D scene of a gust run, at the gust command's exaggeration
    from mcap.reader import make_reader

    from bioflex_jsb.cli.gust import SCENE_EXAGGERATION
    from bioflex_jsb.sweep.evaluate import SCENE_EXAGGERATION as SWEEP_SCENE

    assert SWEEP_SCENE == SCENE_EXAGGERATION
    with open(log, "rb") as f:
        topics = {c.topic for c in make_reader(f).get_summary().channels.values()}
    assert f"/bioflex/{row['model']}/scene" in topics, sorted(topics)


# ------------------------------------------------------------------ unsteady strips, reuse
REUSE = """
name = "reuse"
metrics = ["gust", "eigenvalues", "coefficients"]

[run]
duration_s = 0.6
gust_start_s = 0.1

[axes]
wings = ["optimised"]
speeds_m_s = [15.0]
gusts = ["sharp:1", "sharp:3"]
models = ["coupled", "qsd"]
"""


@pytest.mark.parametrize("extra, needle", [
    ('aero = "lagged"', "run.aero: unknown aerodynamics 'lagged'"),
    ('aero = "unsteady"', "run.aero: 'unsteady' is for the coupled model"),
])
def test_unsupported_aero_is_refused_in_one_line(extra, needle):
    data = tomllib.loads(REUSE.replace("[run]", f"[run]\n{extra}"))
    with pytest.raises(CampaignError) as err:
        parse_campaign(data)
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_unsteady_with_the_lti_metrics_is_refused():
    data = tomllib.loads(REUSE.replace("[run]", '[run]\naero = "unsteady"')
                         .replace('"coupled", "qsd"', '"coupled"'))
    with pytest.raises(CampaignError, match="metric 'eigenvalues' is the quasi-steady"):
        parse_campaign(data)


def test_the_default_aero_keeps_case_ids_and_columns():
    """aero = "quasi-steady" written out is the campaign without the key: same ids, same
    columns (old results resume); "unsteady" gives new ids and an aero column."""
    plain = parse_campaign(tomllib.loads(REUSE))
    said = parse_campaign(tomllib.loads(REUSE.replace("[run]", '[run]\naero = "quasi-steady"')))
    assert [c.case_id for c in plain.cases()] == [c.case_id for c in said.cases()]
    assert plain.columns() == said.columns() and "aero" not in plain.columns()
    from bioflex_jsb.sweep.campaign import case_id

    assert all(case_id(c) == c.case_id for c in said.cases())
    uns = parse_campaign(tomllib.loads(
        REUSE.replace("[run]", '[run]\naero = "unsteady"').replace('"coupled", "qsd"',
                                                                    '"coupled"')
        .replace('"gust", "eigenvalues", "coefficients"', '"gust"')))
    assert "aero" in uns.columns()
    assert not {c.case_id for c in uns.cases()} & {c.case_id for c in plain.cases()}


def test_unsteady_campaign_flies_the_unsteady_strips(monkeypatch):
    """The case's aero reaches the coupled step (recorded from CoupledStep's constructor)
    and its row says so; the quasi-steady case of the same inputs flies quasi-steady."""
    from bioflex_jsb.runtime import coupled_step
    from bioflex_jsb.sweep.evaluate import run_case

    seen = []
    real_init = coupled_step.CoupledStep.__init__

    def spy(self, *a, **kw):
        seen.append(kw.get("aero"))
        real_init(self, *a, **kw)

    monkeypatch.setattr(coupled_step.CoupledStep, "__init__", spy)
    text = REUSE.replace('"coupled", "qsd"', '"coupled"').replace(
        '"gust", "eigenvalues", "coefficients"', '"gust"')
    rows = {}
    for aero in ("quasi-steady", "unsteady"):
        camp = parse_campaign(tomllib.loads(text.replace("[run]", f'[run]\naero = "{aero}"')))
        rows[aero] = run_case(camp.cases()[1])
    assert seen == ["quasi-steady", "unsteady"]
    assert rows["unsteady"]["aero"] == "unsteady" and "aero" not in rows["quasi-steady"]
    assert rows["unsteady"]["status"] == rows["quasi-steady"]["status"] == "ok"
    assert rows["unsteady"]["peak_dn_z"] != rows["quasi-steady"]["peak_dn_z"]


def test_a_worker_reuses_the_wing_its_eigenvalues_and_the_kernel(monkeypatch):
    """The second case of a wing in a worker builds nothing again: one wing build, one
    eigenvalue search per (wing, model, speed), the kernel loaded before the first case
    (counted calls); the rows equal those of cases run with every cache emptied."""
    from bioflex_jsb.flight_dynamics import eigen, wing_model
    from bioflex_jsb.simulation import step_kernel
    from bioflex_jsb.sweep import evaluate

    cases = parse_campaign(tomllib.loads(REUSE)).cases()
    calls = {"build": 0, "modes": 0, "compile": 0}

    def counting(name, fn):
        def wrapper(*a, **kw):
            calls[name] += 1
            return fn(*a, **kw)
        return wrapper

    monkeypatch.setattr(eigen, "modes_at", counting("modes", eigen.modes_at))
    monkeypatch.setattr(step_kernel, "compile_now", counting("compile", step_kernel.compile_now))
    monkeypatch.setattr(wing_model, "_build", counting("build", wing_model._build))
    wing_model._BUILD_CACHE.clear()
    evaluate._EIGEN_CACHE.clear()
    evaluate.warm_worker()
    reused = [evaluate.run_case(c) for c in cases]
    assert calls == {"build": 1, "modes": 2, "compile": 1}  # 1 wing; coupled and qsd
    fresh = []
    for c in cases:
        wing_model._BUILD_CACHE.clear()
        evaluate._EIGEN_CACHE.clear()
        fresh.append(evaluate.run_case(c))
    assert calls["build"] == 1 + len(cases) and calls["modes"] == 2 + len(cases)
    assert comparable(reused) == comparable(fresh)
    assert {r["status"] for r in reused} == {"ok"}


def kernel_loaded(case, log_dir):
    """A worker's view before it runs ``case``: is the step kernel already compiled/loaded?"""
    from bioflex_jsb.simulation import step_kernel

    return {"case_id": case.case_id, "pid": os.getpid(),
            "signatures": len(step_kernel.step_kernel.signatures)}


def test_local_workers_start_with_the_kernel_loaded():
    """The forkserver warms the workers (sweep.worker_warm): the first case a worker is
    handed finds the compiled kernel loaded (numba's dispatcher has its signature)."""
    cases = parse_campaign(tomllib.loads(REUSE)).cases()[:2]
    with LocalExecutor(2, fn=kernel_loaded) as ex:
        rows = [row for _, row in ex.run(cases)]
    assert len(rows) == 2 and all(r["signatures"] >= 1 for r in rows), rows
