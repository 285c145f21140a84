"""The results table of a campaign with turbulence has the RMS of each perturbation, the
metrics ``gust`` reports for turbulence (they were computed and dropped); a table of
discrete gusts keeps its columns, and an earlier table of a turbulence campaign resumes
without them."""

from __future__ import annotations

import csv

import pytest

from bioflex_jsb.simulation.results import RMS_METRICS
from bioflex_jsb.sweep.campaign import METRICS, parse_campaign
from bioflex_jsb.sweep.columns import METRIC_COLUMNS, TURBULENCE_COLUMNS
from bioflex_jsb.sweep.store import StoreError, open_store, read_results


def campaign(gusts: list[str], duration_s: float = 1.0):
    return parse_campaign({
        "name": "rms", "metrics": ["gust"],
        "run": {"duration_s": duration_s, "gust_start_s": 0.2},
        "axes": {"wings": ["optimised"], "speeds_m_s": [15.0], "gusts": gusts,
                 "models": ["coupled"]}})


def test_turbulence_campaigns_have_the_rms_columns_and_discrete_ones_keep_theirs():
    discrete, mixed = campaign(["sharp:3"]), campaign(["sharp:3", "dryden:1:50"])
    assert not set(TURBULENCE_COLUMNS) & set(discrete.columns())
    cols = list(mixed.columns())
    assert [c for c in cols if c not in TURBULENCE_COLUMNS] == list(discrete.columns())
    at = cols.index("time_flown_s") + 1  # right after the gust metrics
    assert cols[at:at + len(RMS_METRICS)] == list(RMS_METRICS)
    assert all(c.columns() == mixed.columns() for c in mixed.cases())
    assert tuple(METRIC_COLUMNS) == METRICS  # the columns' order is the metrics'


def test_a_turbulence_case_row_has_the_rms_of_its_run(tmp_path):
    """The row's RMS is that of the same case flown through the API (``gust``'s numbers);
    a discrete gust of the same campaign leaves them empty."""
    from bioflex_jsb import api
    from bioflex_jsb.sweep.evaluate import run_case

    camp = campaign(["sharp:3", "dryden:1:50:4"])
    out = tmp_path / "rms.csv"
    store = open_store(out, camp.columns(), resume=False)
    for case in camp.cases():
        store.append(run_case(case))
    store.close()
    rows = {r["gust"]: r for r in read_results(out)}
    run = api.fly_gust(api.load_wing("optimised"), 15.0, "dryden:1:50:4", ("coupled",),
                       duration_s=1.0, gust_start_s=0.2)["coupled"]
    expected = api.metrics(run)
    for name in RMS_METRICS:
        assert rows["dryden:1:50:4"][name] == getattr(expected, name) > 0.0, name
        assert rows["sharp:3"][name] is None, name


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_table_written_before_the_rms_columns_resumes_without_them(tmp_path, suffix):
    camp = campaign(["dryden:1:50"])
    old = {k: v for k, v in camp.columns().items() if k not in TURBULENCE_COLUMNS}
    out = tmp_path / f"old{suffix}"
    first, second = camp.cases()[0], {"case_id": "b" * 16, "status": "ok"}
    store = open_store(out, old, resume=False)
    store.append({"case_id": first.case_id, "status": "ok", "rms_du_m_s": 1.0})
    store.close()
    store = open_store(out, camp.columns(), resume=True)
    assert store.done_ids == {first.case_id}
    store.append({**second, "rms_du_m_s": 2.0})
    store.close()
    if suffix == ".csv":
        with open(out, newline="") as fh:
            assert next(csv.reader(fh)) == list(old)
    rows = read_results(out)
    assert {r["case_id"] for r in rows} == {first.case_id, "b" * 16}
    assert all("rms_du_m_s" not in r or r["rms_du_m_s"] is None for r in rows)


def test_a_table_of_other_columns_is_still_refused(tmp_path):
    camp = campaign(["dryden:1:50"])
    out = tmp_path / "other.csv"
    out.write_text("case_id,status,something\n")
    with pytest.raises(StoreError, match="other columns than this campaign"):
        open_store(out, camp.columns(), resume=True)
