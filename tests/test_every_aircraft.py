"""Every shipped aircraft through every command (a JSBSim aircraft's own speeds, its own
gust sizes): the prototype (one variant: the six share the airframe), JSBSim's SGS glider
and JSBSim's Cessna 172 with their elastic wings. Each command must finish with exit 0 and
report the aircraft's own trim speed where it flies one; the physics of each is checked in
its own test file."""

from __future__ import annotations

import json

import pytest

from tests.cli_helpers import run_cli

pytestmark = pytest.mark.slow

# (definition, a 1-cos gust of a few of its chords, its cruise speed [m/s]: the file's, or
# its JSBSim model's for the c172, runtime/jsbsim_aircraft.py)
AIRCRAFT = [("bioflex_optimised", "1cos:1:5", 15.0), ("sgs_elastic", "1cos:1:25", 25.0),
            ("c172_elastic", "1cos:2:30", 57.8)]
FLIGHT = {
    "trim": ["trim", "--json"],
    "gust": ["gust", "--duration", "1", "--no-log", "--json"],
    "compare": ["compare", "--duration", "1", "--no-log", "--json"],
    "loads": ["loads", "--duration", "1", "--json"],
}
LINEAR = {
    "modes": ["modes", "--json"],
    "flutter": ["flutter", "--json"],
    "linearize": ["linearize", "--json"],
    # an aileron on the outer 35 % for the aircraft that have none in their definition
    "aileron": ["aileron", "--aileron", "0.6:0.95:0.75", "--json"],
}


@pytest.mark.parametrize("name, gust, cruise", AIRCRAFT)
@pytest.mark.parametrize("command", sorted(FLIGHT))
def test_every_aircraft_flies_every_flight_command(tmp_path, monkeypatch, capsys, name, gust,
                                                   cruise, command):
    monkeypatch.chdir(tmp_path)
    argv = FLIGHT[command] + ["--aircraft", name]
    if command in ("gust", "compare", "loads"):
        argv += ["--gust", gust]
    if command == "loads":
        argv += ["--plot", str(tmp_path / "loads.png")]
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    payload = json.loads(out)
    if command == "trim":
        assert payload["speed_m_s"] == pytest.approx(cruise)


@pytest.mark.parametrize("name, gust, cruise", AIRCRAFT)
@pytest.mark.parametrize("command", sorted(LINEAR))
def test_every_aircraft_through_every_linear_command(tmp_path, monkeypatch, capsys, name, gust,
                                                     cruise, command):
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, *LINEAR[command], "--aircraft", name)
    assert code == 0, err
    json.loads(out)


@pytest.mark.parametrize("name, gust, cruise", AIRCRAFT)
def test_every_aircraft_exports_its_linear_model(tmp_path, capsys, name, gust, cruise):
    code, _, err = run_cli(capsys, "export", "--aircraft", name, "--out",
                           str(tmp_path / "m.npz"))
    assert code == 0, err
    assert (tmp_path / "m.npz").stat().st_size > 0
