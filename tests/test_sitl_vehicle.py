"""The SITL vehicle without sockets or with a loopback pymavlink peer: guidance, reset on
the ground, pacing statistics, parameters, peers and sticks."""

from __future__ import annotations

import math
import re
import time

import pytest
from pymavlink import mavutil
from pymavlink.dialects.v20 import common as M

from bioflex_jsb.drivers import sitl_vehicle
from bioflex_jsb.drivers.sitl import PacingStats, SitlParameters
from bioflex_jsb.errors import InputError
from bioflex_jsb.links import mavlink as L
from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.links.mavlink import MavlinkLink
from bioflex_jsb.simulation import guidance as G
from tests.polling import wait_until
from tests.test_sitl import build, make_sim  # noqa: F401  (the module's wing fixture)


def test_l1_track_turns_towards_the_track_and_the_circle_is_held():
    # on the track, flying along it: no command; right of a northbound track: turn left
    assert G.l1_track((50.0, 0.0), (15.0, 0.0), (0.0, 0.0), (300.0, 0.0), 40.0).accel_m_s2 \
        == pytest.approx(0.0, abs=1e-12)
    g = G.l1_track((50.0, 20.0), (15.0, 0.0), (0.0, 0.0), (300.0, 0.0), 40.0)
    assert g.cross_track_m == pytest.approx(20.0) and g.accel_m_s2 < 0.0
    # on a clockwise circle of 50 m at 15 m/s the command is near the centripetal V²/R
    c = G.l1_circle((0.0, -50.0), (15.0, 0.0), (0.0, 0.0), 50.0, True, 40.0)
    assert c.accel_m_s2 == pytest.approx(15.0**2 / 50.0, rel=0.15)
    n, e = G.ne_from_latlon(*G.latlon_from_ne(300.0, -200.0, 0.6, 2.6), 0.6, 2.6)
    assert (n, e) == pytest.approx((300.0, -200.0), abs=1e-6)


def test_pacing_statistics_are_a_fixed_histogram():
    s = PacingStats()
    size = s.counts.nbytes
    for k in range(100_000):
        s.add(1e-4 * (1 + k % 10))
    assert s.counts.nbytes == size and s.steps == 100_000
    assert s.percentile_ms(50) == pytest.approx(0.55, rel=0.15)
    assert s.percentile_ms(100) == pytest.approx(1.0)


def test_bad_home_is_one_line(build):  # noqa: F811
    with pytest.raises(InputError, match="latitude"):
        make_sim(build, home=(95.0, 0.0, 0.0))


def test_sticks_time_out_in_simulated_seconds_not_wall_seconds(build, monkeypatch):  # noqa: F811
    """The sticks' age is simulated time: a wall clock that races ahead (a paused or slow
    simulation) keeps them, and MANUAL_TIMEOUT_S of simulated time without new sticks is
    control lost (RTL), however little wall time passed."""
    sim = make_sim(build)
    v = sim.vehicle
    wall = [0.0]
    monkeypatch.setattr(time, "monotonic", lambda: wall[0])
    assert v.set_mode(MODES.STABILIZE) is None
    assert sim.manual(0.0, 0.5)
    t0 = sim.t_s
    wall[0] += 3600.0  # an hour of wall time, no simulated time: the sticks hold
    v.update(sim.t_s)
    assert v.mode == MODES.STABILIZE and v._sticks == pytest.approx((0.0, 0.5))
    # simulated time only (the wall clock stands): held up to the timeout, lost past it
    v.update(t0 + sitl_vehicle.MANUAL_TIMEOUT_S)
    assert v.mode == MODES.STABILIZE and v._stick_t_s == t0
    v.update(t0 + sitl_vehicle.MANUAL_TIMEOUT_S + sim.dt_s)
    assert v.mode == MODES.RTL and v._stick_t_s is None
    assert "Manual control lost: RTL" in [t for _, t in v.events]


def test_a_crash_is_reported_and_reset_to_trim_over_home(build):  # noqa: F811
    sim = make_sim(build, start_height_m=20.0)
    v = sim.vehicle
    heard = []  # the on_status hook (the session log's events): every STATUSTEXT, timed
    v.on_status = lambda t_s, severity, text: heard.append((t_s, severity, text))
    assert v.set_mode(MODES.MANUAL) is None
    with sim.airframe.capturing():
        for k in range(int(30.0 / sim.dt_s)):
            if k % 96 == 0:  # stick forward, nose down into the ground, held (10 Hz, as a
                sim.manual(0.8, 0.0)  # station: sticks older than 1 simulated s mean RTL)
            sim.step()
            if sim.resets:
                break
    assert sim.resets == 1 and sim.stopped is not None
    texts = [t for _, t in v.events]
    # issue 25: the skid's reaction made α jump to -31°, reported as "Diverged: angle of
    # attack ..."; it is a crash, with the impact's state
    crash = next(t for t in texts if t.startswith(("Crashed", "Diverged")))
    assert re.fullmatch(r"Crashed: ground contact at t = \d+\.\d{3} s: -?\d+\.\d\d m above "
                        r"ground, \d+\.\d m/s, descending -?\d+\.\d m/s, pitch -?\d+ deg, "
                        r"roll -?\d+ deg", crash), crash
    assert sim.crashes == 1 and sim.last_reset.startswith("ground contact")
    assert "Reset to trim over home" in texts
    assert [(s, t) for _, s, t in heard] == list(v.events)
    assert heard[-1][0] == heard[-2][0] == sim.t_s > 0.0  # the crash and the reset: now
    s = sim.vehicle_state()
    assert v.mode == MODES.LOITER
    assert s.relative_altitude_m == pytest.approx(20.0, abs=0.5)
    assert math.degrees(s.latitude_rad) == pytest.approx(-35.363261, abs=1e-6)
    t_reset = sim.t_s
    with sim.airframe.capturing():
        for _ in range(960):
            sim.step()
    assert sim.stopped is None and sim.t_s > t_reset  # the session's clock goes on


def _peer(port: int, sysid: int = 255):
    c = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=sysid,
                                   source_component=190, dialect="common")
    c.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
    return c


def _service_until(link, sim, condition, what: str, timeout_s: float = 10.0):
    """Service the link until ``condition()`` is true (returned): the messages sent have
    been read and handled; ``timeout_s`` [s] only bounds a failure (a loaded machine makes
    the test slower, not wrong)."""
    def serviced():
        link.service(sim.vehicle_state())
        return condition()

    return wait_until(serviced, timeout_s, what, poll_s=0.005)


def _read(link, name: str) -> int:
    """How many ``name`` messages the link has read (and handled)."""
    return link.stats.by_type.get(name, 0)


def test_unknown_parameter_gets_param_error_and_peers_expire(build, monkeypatch):  # noqa: F811
    sim = make_sim(build)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
    try:
        c = _peer(link.local_address[1])
        _service_until(link, sim, lambda: link.peer_count == 1, "the peer's heartbeat")
        c.mav.param_request_read_send(1, 1, b"NO_SUCH", -1)
        c.mav.param_set_send(1, 1, b"WP_RADIUS_M", 1e6, M.MAV_PARAM_TYPE_REAL32)
        errors = []
        expected = {("NO_SUCH", M.MAV_PARAM_ERROR_DOES_NOT_EXIST),
                    ("WP_RADIUS_M", M.MAV_PARAM_ERROR_VALUE_OUT_OF_RANGE)}

        def both_answered() -> bool:
            while (m := c.recv_match(type="PARAM_ERROR", blocking=False)) is not None:
                errors.append((m.param_id, m.error))
            return expected <= set(errors)

        _service_until(link, sim, both_answered, f"two PARAM_ERRORs (got {errors})")
        monkeypatch.setattr(L, "PEER_TIMEOUT_S", 0.3)
        _service_until(link, sim, lambda: link.stats.peers_expired == 1, "the peer expired")
        assert link.peer_count == 0
    finally:
        link.close()


def test_unsigned_radio_status_takes_no_peer_slot_when_signing(build):  # noqa: F811
    sim = make_sim(build)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle,
                       signing_key=bytes(range(1, 33)))
    try:
        c = mavutil.mavlink_connection(f"udpout:127.0.0.1:{link.local_address[1]}",
                                       source_system=51, dialect="common")
        for _ in range(5):
            c.mav.radio_status_send(200, 190, 100, 10, 10, 0, 0)
        # all five datagrams taken in (the link's counter; an unknown source's datagrams past
        # the first few of one call are dropped unparsed, unknown_dropped), and none of the
        # RADIO_STATUS handled took a peer slot
        _service_until(link, sim, lambda: link.stats.datagrams == 5, "five datagrams read")
        assert _read(link, "RADIO_STATUS") >= 1 and link.peer_count == 0
    finally:
        link.close()


def test_sticks_only_from_the_controlling_station_and_only_in_stick_modes(build):  # noqa: F811
    sim = make_sim(build)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
    try:
        a, b = _peer(link.local_address[1], 255), _peer(link.local_address[1], 254)
        # each MANUAL_CONTROL is proven read (the link's counter) before what it did is
        # asserted, so that an ignored one is one that was read and ignored
        a.mav.manual_control_send(1, 500, 0, 500, 0, 0)  # CRUISE: not obeyed
        _service_until(link, sim, lambda: _read(link, "MANUAL_CONTROL") == 1,
                       "the first MANUAL_CONTROL read")
        assert sim.vehicle._stick_t_s is None
        sim.vehicle.set_mode(MODES.STABILIZE)
        a.mav.manual_control_send(1, 0, 400, 500, 0, 0)
        _service_until(link, sim, lambda: _read(link, "MANUAL_CONTROL") == 2,
                       "the second MANUAL_CONTROL read")
        assert sim.vehicle._sticks == pytest.approx((0.0, 0.4))
        b.mav.manual_control_send(1, 0, -900, 500, 0, 0)  # another station: ignored
        _service_until(link, sim, lambda: _read(link, "MANUAL_CONTROL") == 3,
                       "the other station's MANUAL_CONTROL read")
        assert sim.vehicle._sticks == pytest.approx((0.0, 0.4))
    finally:
        link.close()
