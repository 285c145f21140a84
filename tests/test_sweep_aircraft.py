"""Sweeps of aircraft definitions (issue 23; sweep/aircraft_axis.py): ``axes.aircraft`` names
shipped aircraft and definition files, a case's id hashes the definition file's content,
the table gains an ``aircraft`` column (only then), the cases run with the definition's
own wing on its own airframe (JSBSim's SGS glider's gust runs as the gust command flies
them), and a definition that cannot fly the gust runs is refused in one line naming the
key."""

from __future__ import annotations

import csv
import tomllib

import pytest

from bioflex_jsb import cli
from bioflex_jsb.definition.loader import shipped_path
from bioflex_jsb.sweep.campaign import CampaignError, case_id, parse_campaign

# The prototype's aircraft by name and as a copy of its file (another definition name), and
# the same wing as a plain variant: one speed, a short gust, the LTI metrics too.
CAMPAIGN = """
name = "definitions"
metrics = ["gust", "eigenvalues", "coefficients"]

[run]
duration_s = 1.0
gust_start_s = 0.2

[axes]
wings = ["original"]
aircraft = ["bioflex_original", "copy.toml"]
speeds_m_s = [15.0]
gusts = ["sharp:1"]
models = ["coupled"]
"""
# JSBSim's SGS glider (another airframe): its linear analyses only.
SGS_LINEAR = """
name = "sgs"
metrics = ["eigenvalues", "coefficients", "flutter"]

[axes]
aircraft = ["sgs_elastic", "bioflex_original"]
speeds_m_s = [25.0]
"""


@pytest.fixture()
def folder(tmp_path):
    text = shipped_path("bioflex_original").read_text(encoding="utf-8")
    (tmp_path / "copy.toml").write_text(
        text.replace('name = "bioflex_original"', 'name = "copy"'), encoding="utf-8")
    (tmp_path / "definitions.toml").write_text(CAMPAIGN, encoding="utf-8")
    (tmp_path / "sgs.toml").write_text(SGS_LINEAR, encoding="utf-8")
    return tmp_path


def _campaign(folder, text=CAMPAIGN):
    return parse_campaign(tomllib.loads(text), base_dir=folder)


def test_the_aircraft_axis_expands_with_its_own_ids_and_column(folder):
    c = _campaign(folder)
    cases = c.cases()
    assert c.n_cases == len(cases) == 3
    assert [(k.wing.name, k.aircraft and k.aircraft.name) for k in cases] == [
        ("original", None), ("original", "bioflex_original"), ("original", "copy")]
    assert len({k.case_id for k in cases}) == 3  # the same wing, three identities
    assert all(case_id(k) == k.case_id for k in cases)  # both hashing paths agree
    cols = list(c.columns())
    assert cols[cols.index("wing") + 1] == "aircraft"
    assert [k.inputs()["aircraft"] for k in cases] == [None, "bioflex_original", "copy"]
    # without the axis the table and the ids are the ones they were
    plain = _campaign(folder, CAMPAIGN.replace('aircraft = ["bioflex_original", "copy.toml"]\n',
                                               ""))
    assert "aircraft" not in plain.columns()
    assert plain.cases()[0].case_id == cases[0].case_id
    assert "aircraft" not in plain.cases()[0].inputs()


def test_a_case_id_hashes_the_definition_files_content(folder):
    """Any edit of the file gives new ids, one that leaves the wing as it was too (a
    comment here: the file's bytes are hashed, as a modes file's)."""
    from bioflex_jsb.sweep import aircraft_axis

    before = _campaign(folder).cases()[2]
    path = folder / "copy.toml"
    path.write_text(path.read_text(encoding="utf-8") + "\n# edited\n", encoding="utf-8")
    aircraft_axis._DIGESTS.clear()  # a new process reads the file again
    changed = _campaign(folder).cases()[2]
    assert changed.wing == before.wing and changed.case_id != before.case_id


@pytest.mark.parametrize("entry, needle", [
    ('"goland"', "has no [airframe]"),
    ('"nowhere.toml"', "not found"),
    ('"nothing"', "unknown definition 'nothing'"),
    ("3", "must be a shipped aircraft's name or a definition file"),
    ('"bioflex_original", "bioflex_original"', "appears twice"),
])
def test_an_aircraft_that_cannot_be_swept_is_refused_in_one_line(folder, entry, needle):
    text = CAMPAIGN.replace('aircraft = ["bioflex_original", "copy.toml"]',
                            f"aircraft = [{entry}]")
    with pytest.raises(CampaignError) as exc:
        _campaign(folder, text)
    msg = str(exc.value)
    assert msg.startswith("axes.aircraft") and needle in msg and "\n" not in msg


def _sweep(argv, monkeypatch, capsys):
    if "sweep" not in cli.COMMAND_MODULES:
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli.COMMAND_MODULES + ("sweep",))
    code = cli.main(["sweep", *map(str, argv)])
    return code, capsys.readouterr()


def test_the_definition_cases_run_with_the_definitions_wing(folder, monkeypatch, capsys):
    out = folder / "definitions.csv"
    code, _ = _sweep([folder / "definitions.toml", "--out", out, "--workers", "2"],
                     monkeypatch, capsys)
    assert code == 0
    rows = {r["aircraft"]: r for r in csv.DictReader(out.open(encoding="utf-8"))}
    assert set(rows) == {"", "bioflex_original", "copy"}
    assert all(r["status"] == "ok" for r in rows.values())
    # the shipped file is the prototype's original wing to the last bit (its definition
    # tests): the same gust peaks and eigenvalues as the plain variant's case
    for name in ("bioflex_original", "copy"):
        for col in ("peak_dn_z", "peak_dq_rad_s", "short_period_re_rad_s",
                    "aeroelastic_1_im_rad_s", "c_eta1_q1"):
            assert rows[name][col] == rows[""][col] != "", (name, col)


def test_another_airframes_linear_metrics_sweep(folder, monkeypatch, capsys):
    out = folder / "sgs.csv"
    code, _ = _sweep([folder / "sgs.toml", "--out", out, "--workers", "1"], monkeypatch,
                     capsys)
    assert code == 0
    rows = {r["aircraft"]: r for r in csv.DictReader(out.open(encoding="utf-8"))}
    assert rows["sgs_elastic"]["status"] == rows["bioflex_original"]["status"] == "ok"
    # its own wing: the SGS wing's first mode ~3 Hz (its modes file), the prototype's ~31 Hz
    f_sgs = float(rows["sgs_elastic"]["mode1_frequency_hz"])
    f_proto = float(rows["bioflex_original"]["mode1_frequency_hz"])
    assert f_sgs < 10.0 < 25.0 < f_proto
    assert rows["sgs_elastic"]["short_period_re_rad_s"] != \
        rows["bioflex_original"]["short_period_re_rad_s"]
    # flutter in each wing's own default range (the SGS's derived from its wing, 9.1-182
    # m/s: quasi-steady flutter at 59.1 m/s, docs/aircraft.md; the prototype's 5-40 m/s):
    # as `flutter --aircraft --aero quasi-steady` finds it (the sweep's flutter metric is the
    # paper's quasi-steady model). In a fixed 5-40 m/s the SGS's column was empty.
    from bioflex_jsb import api

    for name in ("sgs_elastic", "bioflex_original"):
        expected = api.flutter(api.load_aircraft(name).wing(), aero="quasi-steady").speed_m_s
        got = rows[name]["flutter_speed_m_s"]
        assert (float(got) if got else None) == expected, name
    assert 55.0 < float(rows["sgs_elastic"]["flutter_speed_m_s"]) < 65.0
    assert rows["bioflex_original"]["flutter_speed_m_s"] == ""  # none in 5-40 m/s (Fig. 11)


SGS_GUST = """
name = "sgs_gust"
metrics = ["gust"]

[run]
duration_s = 2.0

[axes]
aircraft = ["sgs_elastic"]
speeds_m_s = [15.0, 25.0]
gusts = ["1cos:1:25"]
"""
GUST_COLUMNS = ("peak_du_m_s", "peak_dalpha_rad", "peak_dq_rad_s", "peak_dtheta_rad",
                "peak_dn_z", "overshoot")


def test_another_airframe_flies_its_gust_runs_as_the_gust_command(folder, monkeypatch,
                                                                   capsys):
    """JSBSim's SGS glider on its own airframe (runtime/jsbsim_aircraft.py): the sweep's row
    is the gust command's summary to the last bit (the same code path), and a speed outside
    the aircraft's speed_range_m_s (20-28 m/s) is a failed row saying so."""
    import json

    (folder / "sgs_gust.toml").write_text(SGS_GUST, encoding="utf-8")
    out = folder / "sgs_gust.csv"
    code, said = _sweep([folder / "sgs_gust.toml", "--out", out, "--workers", "1"],
                        monkeypatch, capsys)
    assert code == 0  # one case of two has a result: the table is the sweep's result
    err = said.err.strip().splitlines()  # and the failed one is counted, in one line
    assert len(err) == 1 and "1 of the 2 cases run now failed" in err[0] and \
        "outside aircraft 'sgs_elastic'" in err[0]
    rows = {float(r["speed_m_s"]): r for r in csv.DictReader(out.open(encoding="utf-8"))}
    assert rows[15.0]["status"] == "failed" and "outside aircraft 'sgs_elastic'" in \
        rows[15.0]["error"] and "20..28" in rows[15.0]["error"]
    assert rows[25.0]["status"] == "ok"
    assert cli.main(["gust", "--aircraft", "sgs_elastic", "--speed", "25", "--gust",
                     "1cos:1:25", "--duration", "2", "--models", "coupled", "--json",
                     "--no-log"]) == 0
    summary = json.loads(capsys.readouterr().out)["summary"]["coupled"]
    for col in GUST_COLUMNS:
        assert float(rows[25.0][col]) == summary[col], col


def test_a_campaign_whose_every_case_failed_exits_1_in_one_line(folder, monkeypatch,
                                                                  capsys):
    """Every case outside the SGS's 20-28 m/s: each is a failed row, and the sweep, which
    has no result, says so in one line with the first error and exits 1 (not 0); a
    --resume that runs the missing case at 25 m/s gives the table a result: exit 0."""
    (folder / "sgs_low.toml").write_text(SGS_GUST.replace("[15.0, 25.0]", "[15.0, 16.0]"),
                                         encoding="utf-8")
    out = folder / "low.csv"
    code, said = _sweep([folder / "sgs_low.toml", "--out", out, "--workers", "1"],
                        monkeypatch, capsys)
    assert code == 1
    err = said.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("bioflex-jsb sweep: every case failed (2 run ")
    assert "outside aircraft 'sgs_elastic'" in err[0] and "15 m/s" in err[0]
    rows = list(csv.DictReader(out.open(encoding="utf-8")))
    assert [r["status"] for r in rows] == ["failed", "failed"]  # recorded all the same
    # a resume that adds a case with a result: the table has one, the failed rows stay
    (folder / "sgs_low.toml").write_text(
        SGS_GUST.replace("[15.0, 25.0]", "[15.0, 16.0, 25.0]"), encoding="utf-8")
    code, said = _sweep([folder / "sgs_low.toml", "--out", out, "--workers", "1",
                         "--resume"], monkeypatch, capsys)
    assert code == 0 and said.err.strip() == ""


def test_an_aircraft_that_cannot_fly_is_refused_for_gust_runs(folder, monkeypatch, capsys):
    """A copy of the SGS definition whose speeds are below its stall speed (17.7 m/s)
    cannot fly: refused when the campaign loads (its trim fails there), not case by case;
    with the linear metrics only it is swept."""
    data = shipped_path("sgs_elastic").parent
    text = (data / "sgs_elastic.toml").read_text(encoding="utf-8")
    (folder / "sgs_elastic_modes.toml").write_text(
        (data / "sgs_elastic_modes.toml").read_text(encoding="utf-8"), encoding="utf-8")
    nospeed = text.replace("cruise_speed_m_s = 25.0\n", "cruise_speed_m_s = 12.0\n").replace(
        "speed_range_m_s = [20.0, 28.0]\n", "speed_range_m_s = [10.0, 15.0]\n")
    assert "cruise_speed_m_s = 12.0" in nospeed and "speed_range_m_s = [10.0, 15.0]" in nospeed
    (folder / "nospeed.toml").write_text(nospeed, encoding="utf-8")
    (folder / "c.toml").write_text(SGS_GUST.replace('["sgs_elastic"]', '["nospeed.toml"]'),
                                   encoding="utf-8")
    code, out = _sweep([folder / "c.toml", "--out", folder / "x.csv"], monkeypatch, capsys)
    assert code == 2
    err = out.err.strip().splitlines()
    assert len(err) == 1 and "axes.aircraft[0]" in err[0] and "cannot trim" in err[0]
    assert not (folder / "x.csv").exists()
    linear = SGS_LINEAR.replace('["sgs_elastic", "bioflex_original"]', '["nospeed.toml"]')
    assert _campaign(folder, linear).n_cases == 1
