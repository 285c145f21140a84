"""A campaign's controllers axis (sweep/campaign.py, sweep/evaluate.py): each case flies its
controller in the gust run, its row names it and its command peaks, its log holds the
controller's topic and reruns with --controller; a campaign without the axis keeps its ids
and columns, the "none" case its id; a bad controller is one line naming the key."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from bioflex_jsb.sweep.campaign import CampaignError, case_id, parse_campaign

BASE = """
name = "ctrl"
metrics = ["gust"]

[run]
duration_s = 0.5
gust_start_s = 0.1

[axes]
wings = ["optimised"]
speeds_m_s = [15.0]
gusts = ["1cos:1:2"]
models = ["coupled"]
"""
WITH_AXIS = BASE + 'controllers = ["none", "gla_optimised"]\n'


def test_the_axis_adds_cases_and_columns_and_keeps_the_ids_without_it():
    plain = parse_campaign(tomllib.loads(BASE))
    camp = parse_campaign(tomllib.loads(WITH_AXIS))
    none, gla = camp.cases()
    assert camp.n_cases == 2 and (none.controller, gla.controller) == (None, "gla_optimised")
    assert none.case_id == plain.cases()[0].case_id  # no controller: the id it had
    assert gla.case_id != none.case_id
    assert all(case_id(c) == c.case_id for c in camp.cases())
    cols = list(camp.columns())
    assert cols[cols.index("model") + 1] == "controller"
    assert "peak_ctrl_elevator_rad" in cols and "controller" not in plain.columns()
    assert none.inputs()["controller"] == "none"
    assert gla.inputs()["controller"] == "gla_optimised"


def test_a_file_enters_the_id_by_its_content(tmp_path):
    """A controller file relative to the campaign's folder, kept by its absolute path; its
    id follows the file's content (a changed gain is another case)."""
    f = tmp_path / "gain.toml"
    f.write_text('[controller]\ndt_s = 0\ninputs = ["q"]\noutputs = ["elevator"]\n'
                 'd = [[0.05]]\n')
    data = tomllib.loads(BASE + 'controllers = ["gain.toml"]\n')
    first = parse_campaign(data, base_dir=tmp_path).cases()[0]
    assert first.controller == str(f.resolve())
    f.write_text(f.read_text().replace("0.05", "0.06"))
    again = parse_campaign(data, base_dir=tmp_path).cases()[0]
    assert again.case_id != first.case_id and case_id(again) == again.case_id


@pytest.mark.parametrize("value, needle", [
    ('["no_such"]', "axes.controllers[0]: no controller 'no_such'"),
    ('["none", "none"]', "axes.controllers: None appears twice"),
    ("[3]", "axes.controllers[0]: must be a controller file"),
    # an aileron command needs both wing halves, which a campaign's runs do not fly
    ('["roll_damper_c172_elastic"]', "axes.controllers[0]: 'roll_damper_c172_elastic' "
     "commands the aileron"),
])
def test_a_bad_controller_is_one_line_naming_the_key(value, needle):
    with pytest.raises(CampaignError) as err:
        parse_campaign(tomllib.loads(BASE + f"controllers = {value}\n"))
    assert needle in str(err.value) and "\n" not in str(err.value)


def test_the_axis_needs_gust_runs():
    text = BASE.replace('metrics = ["gust"]', 'metrics = ["coefficients"]').replace(
        'gusts = ["1cos:1:2"]\n', "") + 'controllers = ["gla_optimised"]\n'
    with pytest.raises(CampaignError, match="metrics has no 'gust'"):
        parse_campaign(tomllib.loads(text))


def test_a_case_flies_its_controller_logs_it_and_reruns_with_it(tmp_path):
    """The gla_optimised case: its row's command peak is the run's, its log's controller
    topic reads back as the ctrl_elevator_rad channel, and rerun's argv flies it with
    --controller (a whitelisted run option); the "none" case has no command and no peak."""
    from bioflex_jsb import api
    from bioflex_jsb.cli.rerun import argv_from_log
    from bioflex_jsb.sweep.evaluate import run_case

    none, gla = parse_campaign(tomllib.loads(WITH_AXIS)).cases()
    row = run_case(gla, str(tmp_path))
    assert row["status"] == "ok" and row["controller"] == "gla_optimised"
    log = tmp_path / f"{gla.case_id}.mcap"
    back = api.read_log(log)["coupled"]
    assert back.meta["controller"]["inputs"] == ["alpha", "q"]
    assert row["peak_ctrl_elevator_rad"] == pytest.approx(
        np.abs(back["ctrl_elevator_rad"]).max(), rel=1e-12)
    assert row["peak_ctrl_elevator_rad"] > 1e-3  # rad: the gust moved it
    assert row["peak_ctrl_throttle"] is None  # not commanded
    assert "--controller=gla_optimised" in argv_from_log(str(log))
    plain = run_case(none)
    assert plain["controller"] == "none" and plain["peak_ctrl_elevator_rad"] is None
    assert plain["peak_dn_z"] != row["peak_dn_z"]


def test_a_flaperon_controller_fills_its_command_peak(tmp_path):
    """A case of the shipped elevator-and-flaperon controller: its row's flaperon peak is
    the run's largest |ctrl_flaperon_rad| (read back from its log), beside the elevator's;
    the elevator-only controller leaves the flaperon peak empty."""
    from bioflex_jsb import api
    from bioflex_jsb.sweep.evaluate import run_case

    text = BASE + 'controllers = ["gla_flaperon_optimised", "gla_optimised"]\n'
    flap, elevator_only = parse_campaign(tomllib.loads(text)).cases()
    assert "peak_ctrl_flaperon_rad" in parse_campaign(tomllib.loads(text)).columns()
    row = run_case(flap, str(tmp_path))
    assert row["status"] == "ok"
    back = api.read_log(tmp_path / f"{flap.case_id}.mcap")["coupled"]
    assert row["peak_ctrl_flaperon_rad"] == pytest.approx(
        np.abs(back["ctrl_flaperon_rad"]).max(), rel=1e-12)
    assert row["peak_ctrl_flaperon_rad"] > 1e-4  # rad: the gust moved it
    assert row["peak_ctrl_elevator_rad"] > 1e-3
    assert run_case(elevator_only)["peak_ctrl_flaperon_rad"] is None


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_controller_table_written_before_the_flaperon_column_resumes_without_it(
        tmp_path, suffix):
    from bioflex_jsb.sweep.store import StoreError, open_store, read_results

    camp = parse_campaign(tomllib.loads(WITH_AXIS))
    old = {k: v for k, v in camp.columns().items() if k != "peak_ctrl_flaperon_rad"}
    out = tmp_path / f"old{suffix}"
    first = camp.cases()[0]
    store = open_store(out, old, resume=False)
    store.append({"case_id": first.case_id, "status": "ok"})
    store.close()
    store = open_store(out, camp.columns(), resume=True)
    assert store.done_ids == {first.case_id}
    store.append({"case_id": "c" * 16, "status": "ok", "peak_ctrl_flaperon_rad": 0.01})
    store.close()
    rows = read_results(out)
    assert {r["case_id"] for r in rows} == {first.case_id, "c" * 16}
    assert all("peak_ctrl_flaperon_rad" not in r for r in rows)
    # a table lacking a column that is not a later one is still refused
    other = {k: v for k, v in camp.columns().items() if k != "peak_ctrl_elevator_rad"}
    out2 = tmp_path / f"other{suffix}"
    store = open_store(out2, other, resume=False)
    store.append({"case_id": first.case_id, "status": "ok"})
    store.close()
    with pytest.raises(StoreError, match="other columns than this campaign"):
        open_store(out2, camp.columns(), resume=True)
