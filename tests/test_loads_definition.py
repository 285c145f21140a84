"""The monitoring stations from the aircraft definition (``[loads] stations``,
Definition.monitoring_stations): ``bioflex-jsb loads --aircraft FILE`` reports the loads at
the file's stations when the command line gives none, ``--stations`` overrides them, and a
definition without the table (or no definition) has the default stations."""

from __future__ import annotations

import json

import pytest

from bioflex_jsb.cli import main
from bioflex_jsb.definition.loader import load_definition, shipped_path
from bioflex_jsb.loads import DEFAULT_STATION_FRACTIONS, monitoring_stations

OTHER_STATIONS = (0.1, 0.6)  # not the default's, and not a subset of it


@pytest.fixture(scope="module")
def definition_file(tmp_path_factory):
    """The shipped optimised aircraft with other monitoring stations."""
    text = shipped_path("bioflex_optimised").read_text(encoding="utf-8")
    path = tmp_path_factory.mktemp("aircraft") / "stations.toml"
    path.write_text(text.replace('name = "bioflex_optimised"', 'name = "other_stations"')
                    + "\n[loads]\nstations = [0.1, 0.6]\n", encoding="utf-8")
    return path


def test_the_stations_of_a_definition(definition_file):
    assert monitoring_stations(load_definition(definition_file)) == OTHER_STATIONS
    assert monitoring_stations(load_definition("bioflex_optimised")) == \
        DEFAULT_STATION_FRACTIONS
    assert monitoring_stations(None) == DEFAULT_STATION_FRACTIONS


def _stations(argv, capsys) -> list[str]:
    assert main(["loads", "--gust", "sharp:0.3", "--duration", "1", "--json", *argv]) == 0
    data = json.loads(capsys.readouterr().out)
    return [r["station"] for r in data["loads"]["methods"]["force_summation"]["bending_n_m"]]


def test_the_command_takes_the_definitions_stations_unless_told(definition_file, capsys):
    assert _stations(["--aircraft", str(definition_file)], capsys) == ["10% b/2", "60% b/2"]
    assert _stations(["--aircraft", str(definition_file), "--stations", "0,0.5"],
                     capsys) == ["root", "50% b/2"]
    assert _stations(["--aircraft", "bioflex_optimised"], capsys) == [
        "root", "25% b/2", "50% b/2", "75% b/2"]


def test_the_tuned_gust_ships_the_aircraft_to_its_workers(definition_file, capsys):
    """--tuned --aircraft: the workers build the definition's wing (the Aircraft is the
    case's wing source) and the loads are at the definition's stations."""
    assert main(["loads", "--tuned", "--aircraft", str(definition_file), "--gradients", "0.5",
                 "--workers", "2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["station_fractions"] == list(OTHER_STATIONS)
    assert len(data["cases"]) == 2 and len(data["critical"]) == 2 * 3 * 2 * 2
