"""Issue 25, ground stations: every command the SITL vehicle supports, as COMMAND_LONG and as
COMMAND_INT; values out of range or not numbers refused with one COMMAND_ACK (DENIED) and a
STATUSTEXT naming the field and the range; MAVProxy's guided item (current = 2); override
channels one by one; refusals in the session log.

The link is driven without sockets: messages packed by a pymavlink ground station are parsed
by the link's own parser (``_handle_bytes``) and everything the vehicle sends is kept."""

from __future__ import annotations

import math

import pytest
from pymavlink.dialects.v20 import common as M

from bioflex_jsb.drivers.sitl import SitlParameters
from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.links.mavlink import MavlinkLink, Peer
from bioflex_jsb.simulation import guidance as G
from tests.test_sitl import build, make_sim  # noqa: F401  (the module's wing fixture)

HOME = (-35.363261, 149.165230, 584.0)
FRAMES_INT = (M.MAV_FRAME_GLOBAL, M.MAV_FRAME_GLOBAL_RELATIVE_ALT, M.MAV_FRAME_GLOBAL_INT,
              M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)


def north_east(north_m: float, east_m: float) -> tuple[float, float]:
    lat, lon = G.latlon_from_ne(north_m, east_m, math.radians(HOME[0]), math.radians(HOME[1]))
    return math.degrees(lat), math.degrees(lon)


class Bench:
    """The vehicle's link with a ground station in the same process (module docstring)."""

    def __init__(self, sim) -> None:
        self.sim = sim
        self.link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
        self.out: list = []
        self.link._send = self.out.append  # everything the vehicle sends, unpacked
        self.link.mission._send = self.out.append
        self.gcs = M.MAVLink(None, srcSystem=255, srcComponent=190)
        self.peer = Peer(("127.0.0.1", 9), self.link._new_parser())
        self.events: list[tuple[float, int, str]] = []
        sim.vehicle.on_status = lambda t, sev, text: self.events.append((t, sev, text))

    def close(self) -> None:
        self.link.close()

    def send(self, msg) -> list:
        """Hand ``msg`` to the link, service it once; what the vehicle sent in answer."""
        self.out.clear()
        data = msg.pack(self.gcs)
        self.gcs.seq = (self.gcs.seq + 1) % 256
        self.link._handle_bytes(self.peer, data, self.sim.vehicle_state())
        self.link.service(self.sim.vehicle_state())  # the vehicle's queued STATUSTEXT
        return list(self.out)

    def long(self, cmd: int, *p: float) -> list:
        p = list(p) + [0.0] * (7 - len(p))
        return self.send(self.gcs.command_long_encode(1, 1, cmd, 0, *p))

    def int_(self, cmd: int, frame: int, p1=0.0, p2=0.0, p3=0.0, p4=0.0, x=0, y=0,
             z=0.0) -> list:
        return self.send(self.gcs.command_int_encode(1, 1, frame, cmd, 0, 0, p1, p2, p3, p4,
                                                     x, y, z))


def acks(out, cmd=None) -> list[int]:
    return [m.result for m in out if m.get_type() == "COMMAND_ACK"
            and (cmd is None or m.command == cmd)]


def texts(out) -> list[str]:
    """The STATUSTEXTs, chunks (same id, chunk_seq 0, 1, ...) joined as a station does."""
    whole: list[str] = []
    ids: dict[int, int] = {}
    for m in out:
        if m.get_type() != "STATUSTEXT":
            continue
        if m.id and m.id in ids:
            whole[ids[m.id]] += m.text
        else:
            ids[m.id] = len(whole)
            whole.append(m.text)
    return whole


@pytest.fixture
def bench(build):  # noqa: F811
    b = Bench(make_sim(build))
    yield b
    b.close()


def _mission(sim):
    from bioflex_jsb.links.mavlink_mission import MissionItem

    items = [MissionItem(0, 0, M.MAV_CMD_NAV_WAYPOINT)]
    for k, (n, e) in enumerate(((300.0, 0.0), (300.0, 300.0)), start=1):
        lat, lon = north_east(n, e)
        items.append(MissionItem(k, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, M.MAV_CMD_NAV_WAYPOINT,
                                 x=int(round(lat * 1e7)), y=int(round(lon * 1e7)), z=100.0))
    assert sim.vehicle.set_mission(items) is None


# Each supported command with valid values: (param1..4, position (north, east) [m] or None,
# altitude above home [m] or None). Positional commands carry it in x, y, z.
VALID = {
    M.MAV_CMD_SET_MESSAGE_INTERVAL: ((M.MAVLINK_MSG_ID_ATTITUDE, 100000.0), None, None),
    M.MAV_CMD_GET_MESSAGE_INTERVAL: ((M.MAVLINK_MSG_ID_ATTITUDE,), None, None),
    M.MAV_CMD_REQUEST_MESSAGE: ((M.MAVLINK_MSG_ID_HOME_POSITION,), None, None),
    M.MAV_CMD_REQUEST_PROTOCOL_VERSION: ((1.0,), None, None),
    M.MAV_CMD_REQUEST_AUTOPILOT_CAPABILITIES: ((1.0,), None, None),
    M.MAV_CMD_COMPONENT_ARM_DISARM: ((1.0,), None, None),
    M.MAV_CMD_DO_SET_MODE: ((1.0, MODES.LOITER), None, None),
    M.MAV_CMD_NAV_RETURN_TO_LAUNCH: ((), None, None),
    M.MAV_CMD_NAV_LOITER_UNLIM: ((0.0, 0.0, -80.0), (200.0, 100.0), None),
    M.MAV_CMD_DO_CHANGE_SPEED: ((0.0, 16.0, -1.0), None, None),
    M.MAV_CMD_DO_CHANGE_ALTITUDE: ((700.0, M.MAV_FRAME_GLOBAL), None, None),
    M.MAV_CMD_DO_REPOSITION: ((-1.0, 1.0, 70.0, 1.0), (400.0, -250.0), 120.0),
    M.MAV_CMD_DO_SET_HOME: ((0.0,), (30.0, 40.0), 0.0),
    M.MAV_CMD_MISSION_START: ((0.0, 0.0), None, None),
    M.MAV_CMD_DO_SET_MISSION_CURRENT: ((2.0,), None, None),
}


def test_the_table_covers_every_supported_command(bench):
    assert set(VALID) == bench.link.commands.supported and len(VALID) == 15


def _send_valid(bench, cmd, kind, frame=M.MAV_FRAME_GLOBAL):
    params, ne, rel_alt = VALID[cmd]
    p = list(params) + [0.0] * (4 - len(params))
    lat, lon = north_east(*ne) if ne is not None else (0.0, 0.0)
    relative = frame in (M.MAV_FRAME_GLOBAL_RELATIVE_ALT, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT)
    z = 0.0 if rel_alt is None else rel_alt + (0.0 if relative else HOME[2])
    if kind == "long":
        return bench.long(cmd, *p, lat, lon, z)
    return bench.int_(cmd, frame, *p, x=int(round(lat * 1e7)), y=int(round(lon * 1e7)), z=z)


@pytest.mark.parametrize("kind,frame", [("long", M.MAV_FRAME_GLOBAL)]
                         + [("int", f) for f in FRAMES_INT],
                         ids=["COMMAND_LONG"] + [f"COMMAND_INT-{f}" for f in FRAMES_INT])
def test_every_supported_command_is_accepted_as_long_and_as_int(kind, frame, bench):
    """Issue 25: any COMMAND_INT ended the vehicle (AttributeError: no param7). Each command,
    each message and frame: one ACK, ACCEPTED, with the same effect."""
    sim, v = bench.sim, bench.sim.vehicle
    # position resolution: degE7 = 1.1 cm (COMMAND_INT); COMMAND_LONG's float32 degrees round
    # to half an ulp: 1.9e-6 deg of latitude (0.21 m) and 7.6e-6 deg of longitude near 149°
    # (0.69 m east at 35° S)
    tol_m = 0.02 if kind == "int" else 0.75
    tol_deg = 1e-7 if kind == "int" else 8e-6
    _mission(sim)
    for cmd in VALID:
        if cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            assert v.set_mode(MODES.AUTO) is None
        out = _send_valid(bench, cmd, kind, frame)
        assert acks(out) == [M.MAV_RESULT_ACCEPTED], (cmd, acks(out), texts(out))
        if cmd == M.MAV_CMD_DO_REPOSITION:
            assert v.mode == MODES.GUIDED
            assert v.alt_target_m == pytest.approx(HOME[2] + 120.0)
            assert v._guided_target == pytest.approx((400.0, -250.0), abs=tol_m)
            assert v._guided_loiter == (70.0, False)  # param4 1: counter-clockwise
        elif cmd == M.MAV_CMD_DO_SET_HOME:
            lat, lon = north_east(30.0, 40.0)
            assert math.degrees(v.home[0]) == pytest.approx(lat, abs=tol_deg)
            assert math.degrees(v.home[1]) == pytest.approx(lon, abs=tol_deg)
            assert v.home[2] == pytest.approx(HOME[2])
            v.home = tuple(math.radians(x) for x in HOME[:2]) + (HOME[2],)
        elif cmd == M.MAV_CMD_NAV_LOITER_UNLIM:
            assert v.mode == MODES.LOITER and v._nav[0] == "circle"
            assert v._nav[1] == pytest.approx((200.0, 100.0), abs=tol_m)
            assert v._nav[2:] == (80.0, False)
        elif cmd == M.MAV_CMD_DO_SET_MISSION_CURRENT:
            assert v.mission_seq == 2
        elif cmd == M.MAV_CMD_DO_CHANGE_ALTITUDE:
            assert v.alt_target_m == 700.0
        elif cmd == M.MAV_CMD_DO_CHANGE_SPEED:
            assert v.speed_target_m_s == 16.0
    get = [m for m in bench.out if m.get_type() == "MESSAGE_INTERVAL"]
    assert bench.link.intervals_s[M.MAVLINK_MSG_ID_ATTITUDE] == pytest.approx(0.1)
    assert not get or get[0].interval_us == 100000


def test_change_altitude_and_set_home_frames_are_relative_to_home(bench):
    v = bench.sim.vehicle
    out = bench.long(M.MAV_CMD_DO_CHANGE_ALTITUDE, 150.0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT)
    assert acks(out) == [M.MAV_RESULT_ACCEPTED] and v.alt_target_m == HOME[2] + 150.0
    lat, lon = north_east(10.0, 0.0)
    out = bench.int_(M.MAV_CMD_DO_SET_HOME, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, 0.0,
                     x=int(round(lat * 1e7)), y=int(round(lon * 1e7)), z=5.0)
    assert acks(out) == [M.MAV_RESULT_ACCEPTED] and v.home[2] == HOME[2] + 5.0


def _home_lat_lon(dn=0.0, de=0.0):
    lat, lon = north_east(dn, de)
    return int(round(lat * 1e7)), int(round(lon * 1e7))


# (what is sent, the words the STATUSTEXT must hold): each DENIED with one ACK
X, Y = _home_lat_lon(300.0, 0.0)
DENIED = [
    ("long", M.MAV_CMD_DO_SET_HOME, (0, 0, 0, 0, HOME[0], 1e38, HOME[2]),
     ("longitude", "-180..180")),
    ("long", M.MAV_CMD_DO_SET_HOME, (0, 0, 0, 0, HOME[0], HOME[1], 1e38),
     ("altitude", "-400..5000")),
    ("int", M.MAV_CMD_DO_SET_HOME, (M.MAV_FRAME_GLOBAL_INT, 0, 0, 0, 0, X, Y, math.inf),
     ("z altitude", "finite")),
    ("long", M.MAV_CMD_DO_SET_HOME, (0.5,), ("param1", "0..1")),
    ("long", M.MAV_CMD_DO_REPOSITION, (-1, 1, 0, 0, 1e9, HOME[1], 700.0),
     ("latitude", "-90..90")),
    ("long", M.MAV_CMD_DO_REPOSITION, (-1, 1, math.inf, 0, HOME[0], HOME[1] + 0.01, 700.0),
     ("radius", "20..1000")),
    ("int", M.MAV_CMD_DO_REPOSITION, (M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, -1, 1, 0, 0, X, Y,
                                      1e9), ("z altitude", "604..2084 m AMSL")),
    ("int", M.MAV_CMD_DO_REPOSITION, (M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, -1, 1, 0, 0, X, Y,
                                      -1e9), ("z altitude", "ground + 20..+1500 m")),
    ("int", M.MAV_CMD_DO_REPOSITION, (M.MAV_FRAME_LOCAL_NED, -1, 1, 0, 0, X, Y, 100.0),
     ("frame 1", "GLOBAL")),
    ("long", M.MAV_CMD_DO_REPOSITION, (-1, 1, 0, 7.0, HOME[0], HOME[1] + 0.01, 700.0),
     ("param4", "counter-clockwise")),
    ("long", M.MAV_CMD_SET_MESSAGE_INTERVAL, (M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, math.nan),
     ("param2 interval", "finite")),
    ("long", M.MAV_CMD_SET_MESSAGE_INTERVAL, (M.MAVLINK_MSG_ID_GLOBAL_POSITION_INT, -5.0),
     ("param2 interval", "-1 (off)")),
    ("long", M.MAV_CMD_SET_MESSAGE_INTERVAL, (math.inf, 1000.0), ("param1 message id",)),
    ("long", M.MAV_CMD_DO_CHANGE_SPEED, (0, math.nan), ("param2 airspeed", "finite")),
    ("long", M.MAV_CMD_DO_CHANGE_SPEED, (0, 99.0), ("airspeed", "12..22")),
    ("long", M.MAV_CMD_DO_CHANGE_ALTITUDE, (1e9, 0), ("param1 altitude", "604..2084")),
    ("long", M.MAV_CMD_DO_CHANGE_ALTITUDE, (700.0, math.nan), ("param2 frame",)),
    ("long", M.MAV_CMD_NAV_LOITER_UNLIM, (0, 0, 5.0), ("radius", "20..1000")),
    ("long", M.MAV_CMD_COMPONENT_ARM_DISARM, (math.nan,), ("param1",)),
    ("long", M.MAV_CMD_DO_SET_MODE, (math.inf, 12.0), ("param1 base mode",)),
    ("long", M.MAV_CMD_DO_SET_MODE, (1.0, math.nan), ("param2 custom mode",)),
    ("long", M.MAV_CMD_MISSION_START, (math.inf, 0.0), ("param1 first item",)),
    ("long", M.MAV_CMD_MISSION_START, (0.0, 0.5), ("param2 last item",)),
    ("long", M.MAV_CMD_DO_SET_MISSION_CURRENT, (-math.inf,), ("param1 item",)),
    ("long", M.MAV_CMD_GET_MESSAGE_INTERVAL, (math.nan,), ("param1 message id",)),
    ("long", M.MAV_CMD_REQUEST_MESSAGE, (1e30,), ("param1 message id",)),
]


@pytest.mark.parametrize("kind,cmd,values,words", DENIED,
                         ids=[f"{c}-{k}-{i}" for i, (k, c, _, _) in enumerate(DENIED)])
def test_values_out_of_range_are_denied_once_naming_the_field(kind, cmd, values, words, bench):
    """Issue 25: accepted and flown (home at longitude 1e38, reposition to latitude 1e9°),
    position telemetry stopped by a NaN interval, 9 of 15 commands unanswered with NaN."""
    v, link = bench.sim.vehicle, bench.link
    before = (v.home, v.alt_target_m, v.speed_target_m_s, v.mode, dict(link.intervals_s))
    out = bench.long(cmd, *values) if kind == "long" else bench.int_(cmd, *values)
    assert acks(out) == [M.MAV_RESULT_DENIED], (acks(out), texts(out))
    said = " ".join(texts(out))
    assert all(w in said for w in words), said
    assert (v.home, v.alt_target_m, v.speed_target_m_s, v.mode, link.intervals_s) == before
    assert [e for e in bench.events if e[1] == 4] and v.refusals == 1  # in the session log


def test_nan_where_mavlink_means_not_given_is_accepted(bench):
    """MAVSDK fills unused parameters with NaN: arm with param2 NaN (no force) and a
    mission start with NaN items (the first) are accepted; a disarm with NaN is not forced."""
    _mission(bench.sim)
    assert acks(bench.long(M.MAV_CMD_COMPONENT_ARM_DISARM, 1.0, *[math.nan] * 6)) == [
        M.MAV_RESULT_ACCEPTED]
    out = bench.long(M.MAV_CMD_COMPONENT_ARM_DISARM, 0.0, *[math.nan] * 6)
    assert acks(out) == [M.MAV_RESULT_DENIED] and bench.sim.vehicle.armed
    assert acks(bench.long(M.MAV_CMD_MISSION_START, *[math.nan] * 7)) == [
        M.MAV_RESULT_ACCEPTED]
    assert bench.sim.vehicle.mode == MODES.AUTO and bench.sim.vehicle.mission_seq == 1


def test_reposition_radius_nan_or_zero_is_the_default_as_mavlink_says(bench):
    """MAV_CMD_DO_REPOSITION param3: "a value of zero or NaN is ignored" (common.xml)."""
    v = bench.sim.vehicle
    for r in (math.nan, 0.0):
        out = bench.long(M.MAV_CMD_DO_REPOSITION, -1, 1, r, math.nan, HOME[0] + 0.002,
                         HOME[1], math.nan)
        assert acks(out) == [M.MAV_RESULT_ACCEPTED] and v._guided_loiter == (0.0, True)


def test_nan_and_inf_in_every_parameter_of_every_command_get_exactly_one_ack(bench):
    """Each of the 15 commands with NaN, +inf, -inf, 1e38 in each of its 7 parameters (and
    COMMAND_INT's z): one COMMAND_ACK each, and the vehicle's state stays finite."""
    n = 0
    for cmd, (params, _, _) in VALID.items():
        base = list(params) + [0.0] * (7 - len(params))
        for i in range(7):
            for bad in (math.nan, math.inf, -math.inf, 1e38):
                p = list(base)
                p[i] = bad
                out = bench.long(cmd, *p)
                assert len(acks(out, cmd)) == 1, (cmd, i, bad, acks(out))
                if i < 4:
                    out = bench.int_(cmd, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, *p[:4], z=bad)
                    assert len(acks(out, cmd)) == 1, (cmd, i, bad, acks(out))
                n += 1
    _assert_finite(bench)
    assert n == 15 * 7 * 4


def _assert_finite(bench):
    sim = bench.sim
    s = sim.vehicle_state()
    for name in ("latitude_rad", "longitude_rad", "altitude_m", "relative_altitude_m",
                 "home_latitude_rad", "home_longitude_rad", "home_altitude_m"):
        assert math.isfinite(getattr(s, name)), name
    v = sim.vehicle
    assert all(math.isfinite(x) for x in (v.alt_target_m, v.speed_target_m_s,
                                          v.heading_target_rad, *v.home))
    lo, hi = v.altitude_range_m
    assert lo <= v.alt_target_m <= hi
    assert all(math.isfinite(i) and i >= 0.0 for i in bench.link.intervals_s.values())
    for name in SitlParameters.names:
        assert math.isfinite(SitlParameters(sim).get(name)), name


def test_param_set_nan_inf_or_out_of_range_is_refused_and_never_applied(bench):
    params = SitlParameters(bench.sim)
    for name in SitlParameters.names:
        before = params.get(name)
        for bad in (math.nan, math.inf, -math.inf, 3e38, -3e38):
            out = bench.send(bench.gcs.param_set_encode(1, 1, name.encode(), bad,
                                                        M.MAV_PARAM_TYPE_REAL32))
            if name == "AP_HDG_RAD" and math.isfinite(bad):
                continue  # any finite heading is accepted, wrapped
            errors = [m for m in out if m.get_type() == "PARAM_ERROR"]
            values = [m.param_value for m in out if m.get_type() == "PARAM_VALUE"]
            assert len(errors) == 1 and values == [pytest.approx(before)], (name, bad, out)
            assert params.get(name) == pytest.approx(before)
            assert any(name in t for t in texts(out))
    _assert_finite(bench)


# ---------------------------------------------------------------------- missions, guided


def _item(bench, seq, frame, z, cmd=M.MAV_CMD_NAV_WAYPOINT, current=0, dn=300.0, p=(0, 0, 0, 0)):
    x, y = _home_lat_lon(dn, 0.0)
    return bench.gcs.mission_item_int_encode(1, 1, seq, frame, cmd, current, 1, *p, x, y, z,
                                             M.MAV_MISSION_TYPE_MISSION)


@pytest.mark.parametrize("z,frame,ok", [
    (100.0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, True),
    (1e9, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, False),
    (-1e9, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, False),
    (10.0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, False),  # below ground + 20 m
    (1600.0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, False),
    (700.0, M.MAV_FRAME_GLOBAL_INT, True),
    (100.0, M.MAV_FRAME_GLOBAL_INT, False),  # AMSL: under the ground (584 m)
])
def test_waypoint_altitudes_outside_ground_plus_20_to_1500_m_are_rejected(z, frame, ok, bench):
    """Issue 25: waypoints at z = ±1e9 m were accepted and flown."""
    out = bench.send(bench.gcs.mission_count_encode(1, 1, 2, M.MAV_MISSION_TYPE_MISSION))
    assert [m.seq for m in out if m.get_type() == "MISSION_REQUEST_INT"] == [0]
    bench.send(_item(bench, 0, M.MAV_FRAME_GLOBAL, 0.0))
    out = bench.send(_item(bench, 1, frame, z))
    result = [m.type for m in out if m.get_type() == "MISSION_ACK"]
    if ok:
        assert result == [M.MAV_MISSION_ACCEPTED] and len(bench.sim.vehicle.mission) == 2
    else:
        assert result == [M.MAV_MISSION_INVALID_PARAM7], (result, texts(out))
        assert any("altitude" in t and "604..2084 m AMSL" in t for t in texts(out)), texts(out)
        assert bench.sim.vehicle.mission == []


@pytest.mark.parametrize("p,bad", [((0, -3.0, 0, 0), "param2"), ((0, math.inf, 0, 0), "param2")])
def test_waypoint_acceptance_radius_out_of_range_is_rejected(p, bad, bench):
    bench.send(bench.gcs.mission_count_encode(1, 1, 2, M.MAV_MISSION_TYPE_MISSION))
    bench.send(_item(bench, 0, M.MAV_FRAME_GLOBAL, 0.0))
    out = bench.send(_item(bench, 1, M.MAV_FRAME_GLOBAL_RELATIVE_ALT_INT, 100.0, p=p))
    assert [m.type for m in out if m.get_type() == "MISSION_ACK"] == [
        M.MAV_MISSION_INVALID_PARAM2]
    assert any(bad in t and "5..500" in t for t in texts(out)), texts(out)


def test_mavproxy_guided_item_current_2_flies_there_and_3_changes_the_altitude(bench):
    """MAVProxy's ``guided LAT LON ALT`` with ``guided_use_reposition`` off sends a
    MISSION_ITEM_INT with current = 2 (MAVProxy/modules/mavproxy_mode.py, cmd_guided)."""
    v = bench.sim.vehicle
    out = bench.send(_item(bench, 0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT, 150.0, current=2,
                           dn=500.0))
    assert [m.type for m in out if m.get_type() == "MISSION_ACK"] == [M.MAV_MISSION_ACCEPTED]
    assert v.mode == MODES.GUIDED and v.alt_target_m == HOME[2] + 150.0
    assert v._guided_target == pytest.approx((500.0, 0.0), abs=0.02)
    out = bench.send(_item(bench, 0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT, 1e9, current=2))
    assert [m.type for m in out if m.get_type() == "MISSION_ACK"] == [M.MAV_MISSION_DENIED]
    assert any("604..2084" in t for t in texts(out)) and v.alt_target_m == HOME[2] + 150.0
    out = bench.send(_item(bench, 0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT, 200.0, current=3))
    assert [m.type for m in out if m.get_type() == "MISSION_ACK"] == [M.MAV_MISSION_ACCEPTED]
    assert v.alt_target_m == HOME[2] + 200.0
    legacy = bench.gcs.mission_item_encode(1, 1, 0, M.MAV_FRAME_GLOBAL_RELATIVE_ALT,
                                           M.MAV_CMD_NAV_WAYPOINT, 2, 0, 0, 0, 0, 0, math.nan,
                                           HOME[1], 100.0)
    out = bench.send(legacy)  # float latitude NaN (MISSION_ITEM): refused, not a crash
    assert [m.type for m in out if m.get_type() == "MISSION_ACK"] == [M.MAV_MISSION_DENIED]


# -------------------------------------------------------------------------------- sticks


def _rc(bench, *channels):
    ch = list(channels) + [0] * (18 - len(channels))
    return bench.send(bench.gcs.rc_channels_override_encode(1, 1, *ch))


def test_rc_override_channels_apply_one_by_one(bench):
    """Issue 25: ``rc 1 1800`` (channel 2 = 0) was read as "sticks released" and ignored
    without a word. MAVLink: channels 1-8, 0 = release, UINT16_MAX = ignore."""
    v = bench.sim.vehicle
    assert v.set_mode(MODES.STABILIZE) is None
    _rc(bench, 1800)  # MAVProxy's rc 1 1800: the others 0
    assert v._sticks == pytest.approx((0.0, 0.6))
    _rc(bench, 65535, 1700)  # channel 1 ignored: kept
    assert v._sticks == pytest.approx((0.4, 0.6))
    out = _rc(bench, 3000, 65535)  # out of range: refused, said, kept
    assert v._sticks == pytest.approx((0.4, 0.6))
    assert any("channel 1" in t and "800..2200" in t for t in texts(out)), texts(out)
    out = _rc(bench, 65535, 65535, 1600)  # throttle: not used, said
    assert any("channel 3" in t and "not used" in t for t in texts(out)), texts(out)
    _rc(bench, 0, 1700)  # channel 1 released: centred
    assert v._sticks == pytest.approx((0.4, 0.0))
    _rc(bench, 0, 0)  # both released: the autopilot's
    assert v._stick_t_s is None and bench.link.sticks.controller is None
    assert v.set_mode(MODES.CRUISE) is None
    out = _rc(bench, 1800)
    assert any("Sticks ignored in CRUISE" in t for t in texts(out)), texts(out)
    assert v.refusals == 3


# ---------------------------------------------------------------------- property-based


def _strategies(hypothesis, gcs):
    """The random messages of the property test (hypothesis strategies)."""
    st = hypothesis.strategies
    floats = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=32),
                       st.sampled_from([0.0, -1.0, 1.0, 1e9, -1e9, 3e38, math.nan, math.inf]))
    int32 = st.integers(-2**31, 2**31 - 1)
    commands = st.one_of(st.sampled_from(sorted(VALID)), st.integers(0, 65535))

    @st.composite
    def messages(draw):
        kind = draw(st.sampled_from(["long", "int", "param", "item", "count", "rc"]))
        f = [draw(floats) for _ in range(7)]
        if kind == "long":
            return "cmd", gcs.command_long_encode(1, 1, draw(commands), 0, *f)
        if kind == "int":
            frame = draw(st.one_of(st.sampled_from(FRAMES_INT), st.integers(0, 255)))
            return "cmd", gcs.command_int_encode(1, 1, frame, draw(commands), 0, 0, *f[:4],
                                                 draw(int32), draw(int32), f[6])
        if kind == "param":
            name = draw(st.sampled_from(SitlParameters.names)).encode()
            return "param", gcs.param_set_encode(1, 1, name, f[0], M.MAV_PARAM_TYPE_REAL32)
        if kind == "count":
            return "other", gcs.mission_count_encode(1, 1, draw(st.integers(0, 3)),
                                                     M.MAV_MISSION_TYPE_MISSION)
        if kind == "rc":
            return "other", gcs.rc_channels_override_encode(
                1, 1, *[draw(st.sampled_from([0, 65535, 65534, 1500, 1900, 900, 3000]))
                        for _ in range(18)])
        return "other", gcs.mission_item_int_encode(
            1, 1, draw(st.integers(0, 3)), draw(st.integers(0, 12)),
            draw(st.sampled_from([16, 17, 18, 19, 20, 22, 178, 999])),
            draw(st.integers(0, 3)), 1, *f[:4], draw(int32), draw(int32), f[6],
            M.MAV_MISSION_TYPE_MISSION)

    return st.lists(messages(), min_size=1, max_size=6)


@pytest.mark.slow  # a randomised command session: 16.5 s measured; full suite only
def test_random_commands_params_and_items_never_crash_and_keep_the_state_finite(build):  # noqa: F811,E501
    """Random COMMAND_LONG / COMMAND_INT (any command, NaN, inf, huge), PARAM_SET,
    MISSION_COUNT / MISSION_ITEM_INT and RC overrides: no exception, exactly one ack per
    command (and one PARAM_VALUE per PARAM_SET), the state finite, the sim flying on."""
    hypothesis = pytest.importorskip("hypothesis")
    bench = Bench(make_sim(build))

    # derandomized: the same 400 batches on every machine (no example database)
    @hypothesis.settings(max_examples=400, deadline=None, database=None, derandomize=True,
                         suppress_health_check=list(hypothesis.HealthCheck))
    @hypothesis.given(_strategies(hypothesis, bench.gcs))
    def run(batch):
        for what, msg in batch:
            out = bench.send(msg)
            if what == "cmd":
                assert len(acks(out, msg.command)) == 1, (msg, out)
            elif what == "param":
                assert len([m for m in out if m.get_type() == "PARAM_VALUE"]) == 1
        with bench.sim.airframe.capturing():
            for _ in range(10):
                bench.sim.step()
        _assert_finite(bench)

    try:
        run()
    finally:
        bench.close()
