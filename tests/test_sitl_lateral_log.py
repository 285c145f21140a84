"""The session log of a sitl vehicle with both wing halves (span='full'): the antisymmetric
wing on /bioflex/<model>/lateral, as a gust run's log has it (sinks/mcap/lateral_topic.py;
docs/logging.md): read back, every lateral channel is the rows' to the bit, the files keep
their size limit with the topic in them (measured 295.0, 296.9, 271.0 kB of 300), and pass
pymcap's strict doctor."""

from __future__ import annotations

import os

import numpy as np

from bioflex_jsb import api
from bioflex_jsb.definition.flying import flight_speeds
from bioflex_jsb.drivers.sitl import (
    DEFAULT_HOME,
    DEFAULT_START_HEIGHT_M,
    SitlSim,
    sitl_airframe,
)
from bioflex_jsb.links import mavlink_modes as MODES

C172 = "c172_elastic"
SPEED_M_S = 57.8  # its cruise [m/s]
LATERAL = ("aileron_rad", "modal_roll_n_m", "tip_twist_starboard_rad", "tip_twist_port_rad",
           "asym_eta1", "asym_eta2", "asym_eta3", "asym_eta1_dot", "asym_eta3_dot")
STEPS = 1440  # 1.5 s at 960 Hz: the loiter entry's first roll, ailerons moving
MAX_MB = 0.3  # each file's limit [MB]: the session's steps go into several files


def test_the_session_log_holds_both_wing_halves(tmp_path):
    from bioflex_jsb.cli.gust import open_log
    from bioflex_jsb.cli.sitl import SplitLog
    from bioflex_jsb.simulation.run import RunDescription
    from tests.test_events import doctor_strict

    ac = api.load_aircraft(C172)
    build = ac.wing()
    airframe, _ = sitl_airframe(ac, SPEED_M_S, DEFAULT_HOME[2] + DEFAULT_START_HEIGHT_M)
    sim = SitlSim(build, build.modes, speed_m_s=SPEED_M_S, airframe=airframe, span="full",
                  airspeed_range_m_s=tuple(flight_speeds(ac)[1]))
    sim.vehicle.set_mode(MODES.CIRCLE)
    path = tmp_path / "s.mcap"
    log = SplitLog(str(path), RunDescription("sitl", C172, SPEED_M_S, gust="none",
                                             models=("coupled",), duration_s=1.5),
                   build, MAX_MB, open_log)
    on_sample = log.attach(sim)
    rows = []
    for _ in range(STEPS):
        t = sim.t_s
        values = sim.step()
        on_sample(t, sim.wing.model, values)
        rows.append(values)  # no idle flushes: whole chunks pending, as a busy loop has
    log.close()
    assert sim.stopped is None
    flown = dict(zip(sim.names, np.array(rows).T, strict=True))
    assert np.ptp(flown["aileron_rad"]) > 1e-3  # the autopilot rolls into its circle
    assert np.max(np.abs(flown["asym_eta1"])) > 1e-6
    assert len(log.paths) > 1
    back: dict[str, list[np.ndarray]] = {name: [] for name in LATERAL}
    for p in log.paths:
        assert os.path.getsize(p) <= MAX_MB * 1e6, p
        run = api.read_log(p)["coupled"]
        for name in LATERAL:
            back[name].append(run.channels[name])
        doctor_strict(p)
    for name in LATERAL:
        np.testing.assert_array_equal(np.concatenate(back[name]), flown[name], err_msg=name)


def test_a_half_wing_session_has_no_lateral_topic(tmp_path):
    """The half wing's rows have no antisymmetric modes: no lateral topic, no lateral
    channels read back (the session log as before)."""
    from mcap.reader import make_reader

    from bioflex_jsb.cli.gust import open_log
    from bioflex_jsb.cli.sitl import SplitLog
    from bioflex_jsb.simulation.run import RunDescription

    build = api.load_aircraft("bioflex_optimised").wing()
    sim = SitlSim(build.model, build.modes)
    path = tmp_path / "h.mcap"
    log = SplitLog(str(path), RunDescription("sitl", "optimised", 15.0, gust="none",
                                             models=("coupled",), duration_s=0.1),
                   build, 256.0, open_log)
    on_sample = log.attach(sim)
    for _ in range(96):
        t = sim.t_s
        on_sample(t, sim.wing.model, sim.step())
    log.close()
    assert "asym_eta1" not in api.read_log(path)["coupled"].channels
    with open(path, "rb") as f:
        topics = {c.topic for c in make_reader(f).get_summary().channels.values()}
    assert "/bioflex/coupled/rigid_body" in topics
    assert not any(t.endswith("/lateral") for t in topics)
