"""scripts/ardupilot_sitl.py without ArduPilot: its report of a flight and its exit status.

Faults of the documented flight: ``fly`` exited 0 when the mission was not completed; its
cross-track error mixed the 30 m jump at each waypoint switch with the error on the line
(docs quote 0.57 m from 8 s into each leg); two real-time factors were printed unnamed.
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "ardupilot_sitl.py"


@pytest.fixture(scope="module")
def script():
    spec = importlib.util.spec_from_file_location("ardupilot_sitl_script", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _leg(seq: int, rate_hz: float = 10.0, length_s: float = 20.0):
    """A leg as NAV_CONTROLLER_OUTPUT reports it: 30 m off the new line at the switch,
    converging over 6 s, then 0.5 m peak-to-peak weave around it."""
    out = []
    for i in range(int(length_s * rate_hz)):
        t = i / rate_hz
        x = 30.0 * max(0.0, 1.0 - t / 6.0) + 0.25 * math.sin(2.0 * t)
        out.append((t, seq, x))
    return out


def test_cross_track_is_reported_settled_and_with_the_turns(script):
    samples = [s for seq in (2, 3, 4, 5) for s in _leg(seq)]
    rep = script.cross_track_report(samples)
    settled, turns = rep["xtrack_from_8s_into_leg_m"], rep["xtrack_including_turns_m"]
    assert settled["max"] == pytest.approx(0.25, abs=1e-3)  # the weave only
    assert settled["p95"] <= settled["max"] < 0.3
    assert turns["max"] == pytest.approx(30.0, abs=1e-9)  # the switch's jump
    assert settled["samples"] == 4 * 120 and turns["samples"] == 4 * 200
    assert set(rep["xtrack_by_item_m"]) == {"2", "3", "4", "5"}
    assert rep["xtrack_by_item_m"]["3"]["including_turn_max"] == pytest.approx(30.0)
    assert script.LEG_SETTLE_S == 8.0
    assert script.cross_track_report([])["xtrack_from_8s_into_leg_m"] is None


def test_incomplete_mission_exits_1(script, monkeypatch, capsys, tmp_path):
    done = {"reached": [1, 2, 3, 4, 5, 6], "ended": "home reached in RTL"}
    assert script.incomplete(done) == []
    missed = {"reached": [1, 2, 3], "ended": "a process exited"}
    why = script.incomplete(missed)
    assert why == ["waypoint item 4 not reached", "waypoint item 5 not reached",
                   "ended: a process exited"]
    assert script.incomplete({"reached": [2, 3, 4, 5]}) == ["ended: timeout"]
    summary = {**missed, "incomplete": why}
    monkeypatch.setattr(script, "fly", lambda *a: summary)
    assert script.main(["fly", str(tmp_path)]) == script.EXIT_INCOMPLETE == 1
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "mission not completed" in err
    monkeypatch.setattr(script, "fly", lambda *a: {**done, "incomplete": []})
    assert script.main(["fly", str(tmp_path)]) == 0


def test_missing_binary_is_exit_2(script, monkeypatch, capsys, tmp_path):
    monkeypatch.setenv(script.NETNS_ENV, "1")  # as inside the namespace: no unshare here
    assert script.main(["fly", str(tmp_path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "not built" in err


def test_real_time_factors_are_named(script):
    physics = {"real_time_factor": 0.97, "real_time_factor_definition": "session_s / ..."}
    rtf = script.real_time_factors({"physics": physics, "sim_s": 64.3, "wall_s": 100.0})
    assert rtf["physics"] == 0.97 and rtf["physics_definition"].startswith("session_s")
    assert rtf["arduplane_boot_to_end"] == pytest.approx(0.643)
    assert "boot" in rtf["arduplane_boot_to_end_definition"]
    assert rtf["arduplane_launch_to_end"] is None  # never launched
    flown = {"sim_s": 250.0, "wall_s": 30.0, "launch_sent_at_s": 50.0,
             "launch_sent_wall_s": 1000.0, "end_wall_s": 1020.0}
    rtf = script.real_time_factors(flown)
    assert rtf["arduplane_launch_to_end"] == pytest.approx(10.0)  # 200 s in 20 s
    assert "flight only" in rtf["arduplane_launch_to_end_definition"]


def test_speedup_held_within_5_percent(script):
    assert script.HELD_TOLERANCE == 0.05
    assert script.speedup_held(9.6, 10.0) and script.speedup_held(10.4, 10.0)
    assert not script.speedup_held(9.4, 10.0)
    assert not script.speedup_held(1.06, 1.0)
    assert script.speedup_held(None, 10.0) is None


def test_speedup_and_rate_reach_fly(script, monkeypatch, tmp_path):
    seen = []
    monkeypatch.setattr(script, "fly", lambda *a: seen.append(a) or {"incomplete": []})
    assert script.main(["fly", str(tmp_path), "--speedup", "12", "--rate", "240"]) == 0
    assert seen[-1][4:] == (12.0, 240, (), 300.0, 100.0)
    assert script.main(["fly", str(tmp_path)]) == 0
    assert seen[-1][4:] == (1.0, None, (), 300.0, 100.0)  # ArduPilot's own SIM_RATE_HZ
    extra = tmp_path / "fft.parm"
    extra.write_text("FFT_ENABLE 1\n")
    assert script.main(["fly", str(tmp_path), "--defaults", str(extra)]) == 0
    assert seen[-1][6] == (extra.resolve(),)  # loaded after bioflex_plane.parm


def test_the_square_and_the_home_radius_reach_fly(script, monkeypatch, tmp_path):
    """A larger aircraft's mission (the c172: 341 m turn radius at 45 deg, WP_RADIUS 443 m,
    WP_LOITER_RAD 590 m) needs a larger square and a home radius beyond its loiter circle."""
    seen = []
    monkeypatch.setattr(script, "fly", lambda *a: seen.append(a) or {"incomplete": []})
    assert script.main(["fly", str(tmp_path), "--square-m", "3000",
                        "--home-radius-m", "800"]) == 0
    assert seen[-1][7:] == (3000.0, 800.0)


class _MissionLink:
    """What _mission sends, and ArduPlane's requests for every item, then its ACK."""

    def __init__(self, m, n_items: int) -> None:
        self.m, self.target_system, self.target_component = m, 1, 1
        self.mav = self
        self.sent = []
        self._replies = [m.MAVLink_mission_request_int_message(1, 1, i)
                         for i in range(n_items)]
        self._replies.append(m.MAVLink_mission_ack_message(1, 1, m.MAV_MISSION_ACCEPTED))

    def mission_count_send(self, *a) -> None:
        pass

    def recv_match(self, **kw):
        return self._replies.pop(0)

    def send(self, msg) -> None:
        self.sent.append(msg)


def test_the_mission_square_scales_with_its_side(script, monkeypatch):
    """The four corners at north/east (s, 0), (s, s), (0, s), (0, 0) from home [m]. The
    MAVLink 2 messages: pymavlink switches its module to them at ArduPlane's first MAVLink 2
    packet, before the mission is sent."""
    from pymavlink import mavutil
    from pymavlink.dialects.v20 import ardupilotmega as m

    monkeypatch.setattr(mavutil, "mavlink", m)
    home = (47.0, 8.0)
    for side in (300.0, 3000.0):
        link = _MissionLink(m, 7)
        assert script._mission(link, *home, side) == 7
        corners = [(msg.x * 1e-7, msg.y * 1e-7) for msg in link.sent[2:6]]
        metres = [(math.radians(lat - home[0]) * script.EARTH_RADIUS_M,
                   math.radians(lon - home[1]) * script.EARTH_RADIUS_M
                   * math.cos(math.radians(home[0]))) for lat, lon in corners]
        want = [(side, 0.0), (side, side), (0.0, side), (0.0, 0.0)]
        for (n, e), (wn, we) in zip(metres, want, strict=True):
            assert n == pytest.approx(wn, abs=0.02) and e == pytest.approx(we, abs=0.02)


@pytest.mark.parametrize("bad", [["--speedup", "0"], ["--speedup", "-2"],
                                 ["--speedup", "nan"], ["--speedup", "inf"],
                                 ["--rate", "0"], ["--square-m", "0"],
                                 ["--home-radius-m", "-5"], ["--square-m", "nan"]])
def test_bad_speedup_or_rate_is_exit_2(script, monkeypatch, capsys, tmp_path, bad):
    monkeypatch.setattr(script, "fly", lambda *a: pytest.fail("flown with bad input"))
    assert script.main(["fly", str(tmp_path), *bad]) == script.EXIT_ERROR == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "must be" in err
