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


def _free_udp_port() -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


OTHERS = {
    "export-jsbsim": lambda tmp: ["export-jsbsim", "--out", str(tmp / "root"), "--gust",
                                  "none", "--json"],
    # the amplitude of each aircraft's own gust (AIRCRAFT): the paper's default 3 m/s
    # takes the SGS below its tables' −1° (α 1.96° at 25 m/s, 3/25 rad down): exit 3
    "loads-tuned": lambda tmp: ["loads", "--tuned", "--gradients", "2,4", "--workers", "1",
                                "--json"],
    "loads-frequency": lambda tmp: ["loads", "--frequency", "--record", "17", "--sigmas",
                                    "0.1", "--json"],
    "sitl": lambda tmp: ["sitl", "--duration", "1", "--speedup", "50", "--no-log",
                         "--mavlink", f"udpout:127.0.0.1:{_free_udp_port()}", "--json"],
    "ardupilot-parm": lambda tmp: ["ardupilot", "--write-parm", str(tmp / "a.parm"),
                                   "--json"],
}


@pytest.mark.parametrize("name, gust, cruise", AIRCRAFT)
@pytest.mark.parametrize("command", sorted(OTHERS))
def test_every_aircraft_through_the_other_commands(tmp_path, monkeypatch, capsys, name, gust,
                                                   cruise, command):
    """export-jsbsim (the engine files carried for the c172), the tuned gust and the
    frequency study of loads, a second of sitl and ardupilot's parameter file: exit 0 for
    every shipped aircraft."""
    monkeypatch.chdir(tmp_path)
    argv = OTHERS[command](tmp_path) + ["--aircraft", name]
    if command == "loads-tuned":
        argv += ["--amplitude", gust.split(":")[1]]
    code, out, err = run_cli(capsys, *argv)
    assert code == 0, err
    json.loads(out)
