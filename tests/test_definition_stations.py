"""Monitoring stations in the definition (issue 24: "monitoring stations belong to the
definition"): ``[loads] stations``, fractions of the semispan, read into
``Definition.monitoring_stations`` and checked when the file is read (one line naming the
field, exit 2 in the CLI)."""

from __future__ import annotations

import re

import pytest

from bioflex_jsb.definition import DefinitionError, load_definition
from bioflex_jsb.definition.loader import DEFAULT_MONITORING_STATIONS, shipped_path
from tests.cli_helpers import assert_one_line_error, run_cli

GOLAND_TEXT = shipped_path("goland").read_text(encoding="utf-8")
PROTO_TEXT = shipped_path("bioflex_original").read_text(encoding="utf-8")


def _write(tmp_path, text: str):
    path = tmp_path / "wing.toml"
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.parametrize("name", ["goland", "bioflex_original", "sgs_wing"])
def test_default_is_the_root_and_quarter_points(name):
    assert DEFAULT_MONITORING_STATIONS == (0.0, 0.25, 0.5, 0.75)
    assert load_definition(name).monitoring_stations == (0.0, 0.25, 0.5, 0.75)


@pytest.mark.parametrize("text", [GOLAND_TEXT, PROTO_TEXT])
def test_stations_are_read_from_the_file(tmp_path, text):
    path = _write(tmp_path, text + "\n[loads]\nstations = [0, 0.1, 0.6, 0.95]\n")
    stations = load_definition(path).monitoring_stations
    assert stations == (0.0, 0.1, 0.6, 0.95)
    assert all(isinstance(s, float) for s in stations)


BAD = [
    ("[1.0]", "0 <= s < 1"),  # the tip carries no load
    ("[0.0, 1.2]", "outside the valid range 0..1"),
    ("[-0.1, 0.5]", "outside the valid range 0..1"),
    ("[0.5, 0.25]", "sorted and distinct"),
    ("[0.25, 0.25]", "sorted and distinct"),
    ("[]", "a list of 1..50"),
    ("0.5", "a list of 1..50"),
    ('["root"]', "finite number"),
    ("[true]", "finite number"),
]


@pytest.mark.parametrize("value, reason", BAD)
def test_bad_stations_are_one_line(tmp_path, value, reason):
    path = _write(tmp_path, GOLAND_TEXT + f"\n[loads]\nstations = {value}\n")
    with pytest.raises(DefinitionError, match=re.escape("loads.stations")) as info:
        load_definition(path)
    assert reason in str(info.value) and "\n" not in str(info.value)


def test_unknown_loads_field_is_refused(tmp_path, capsys):
    path = _write(tmp_path, GOLAND_TEXT + "\n[loads]\nstation = [0.5]\n")
    with pytest.raises(DefinitionError, match="loads: unknown key 'station'; accepted: "
                       "stations"):
        load_definition(path)
    code, _, err = run_cli(capsys, "flutter", "--clamped", str(path))
    assert_one_line_error(code, err, "loads: unknown key 'station'")
