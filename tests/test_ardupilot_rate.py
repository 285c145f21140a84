"""ArduPilot's frame rate honoured: k co-simulation steps per JSON frame
(bioflex_jsb.links.ardupilot_rate, bioflex_jsb.drivers.ardupilot).

Checks: k from the frame_rate field (1200 → 1, 960 → 1, 480 → 2, 240 → 4; 0, above 10 kHz
and below ArduPlane's loop rate as documented, with an event), ArduPilot's own rate_hz rule
(its SIM_RATE_HZ reached through the ±1 Hz nudges, no oscillation between two rates), a
frame of k steps being the same physics as k frames of one step, the reply's timestamp and
ArduPilot's clock advancing k·dt, every step logged with one autopilot message per frame,
a valid-range stop inside a frame reported at its own step, and a restart back to k = 1.
No timing: every figure is a count or a state.
"""

from __future__ import annotations

import math

import pytest

from bioflex_jsb.drivers import ardupilot as ad
from bioflex_jsb.links.ardupilot_rate import MAX_FRAME_RATE_HZ, MIN_FRAME_RATE_HZ, FrameRate
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.sinks import mcap as sink
from tests.ardupilot_standin import ArduPilotStandin, _single
from tests.test_ardupilot_driver import ARMED_IDLE, DISARMED, Link, open_log

NOSE_DOWN = (1500, 1000, 1000, 1500)  # elevator full nose down, idle: leaves the valid range


@pytest.fixture(scope="module")
def wing():
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    return build_wing(VARIANTS["optimised"]).model


def _physics(wing, **kw):
    return ad.ArduPilotPhysics(Airframe(), wing, "coupled", **kw)


@pytest.mark.parametrize("rate, k", [(1200, 1), (960, 1), (480, 2), (320, 3), (240, 4),
                                     (200, 5), (100, 10), (MIN_FRAME_RATE_HZ, 19),
                                     (MAX_FRAME_RATE_HZ, 1)])
def test_k_from_a_requested_rate(rate, k):
    fr = FrameRate(DEFAULT_DT_S)
    got, event = fr.steps(rate)
    assert got == k == fr.k
    assert fr.rate_hz == pytest.approx(960.0 / k)
    assert (event is None) == (k == 1)  # a change of k is reported, none is not
    assert fr.steps(rate) == (k, None)  # the same rate again: no change, no event


def test_zero_absurd_and_too_slow_rates_are_warned_and_bounded():
    fr = FrameRate(DEFAULT_DT_S)
    assert fr.steps(240)[0] == 4
    k, (level, text) = fr.steps(0)  # not a rate: the steps per frame are kept
    assert (k, level) == (4, "WARNING") and "0 Hz" in text
    assert fr.steps(0) == (4, None)  # warned once while it stays
    k, (level, text) = fr.steps(MAX_FRAME_RATE_HZ + 1)
    assert (k, level) == (1, "WARNING") and "above" in text
    k, (level, text) = fr.steps(MIN_FRAME_RATE_HZ - 20)
    assert (k, level) == (19, "WARNING") and "loop rate" in text
    assert 960.0 / 19 >= MIN_FRAME_RATE_HZ > 960.0 / 20
    k, (level, text) = fr.steps(480)  # a rate changed mid-session: followed, reported
    assert (k, level) == (2, "INFO") and "480 Hz" in text and "was 19" in text


def _arduplane(sim_rate_hz: int, frames: int, dt_s: float = DEFAULT_DT_S) -> list[int]:
    """k per frame against ArduPilot's rate_hz rule, through the stand-in's model of it."""
    fr = FrameRate(dt_s)
    ap = ArduPilotStandin(("127.0.0.1", 9), sim_rate_hz=sim_rate_hz)
    ks = []
    try:
        for _ in range(frames):
            k = fr.steps(ap.rate_hz)[0]
            ks.append(k)
            ap.follow_rate(k * dt_s)
    finally:
        ap.close()
    return ks


@pytest.mark.parametrize("sim_rate_hz, settled_k", [(1200, 1), (960, 1), (480, 2), (240, 4),
                                                    (200, 4), (300, 3), (50, 19), (20, 19)])
def test_arduplanes_sim_rate_is_reached_through_its_nudges(sim_rate_hz, settled_k):
    """ArduPilot starts at 1200 Hz and reports 1/Δt moved ≤ 1 Hz towards SIM_RATE_HZ: k
    climbs one a frame and then holds; between two of our rates (200, 300 Hz) it settles on
    the faster one after one overshoot instead of alternating."""
    ks = _arduplane(sim_rate_hz, 60)
    assert ks[0] == 1  # ArduPilot's first frame says 1200
    assert set(ks[30:]) == {settled_k}
    # one step of k a frame at most
    assert all(abs(a - b) <= 1 for a, b in zip(ks[:-1], ks[1:], strict=True))
    if sim_rate_hz == 240:
        assert ks[:5] == [1, 2, 3, 4, 4]


def test_standin_reports_arduplanes_rate_hz():
    ap = ArduPilotStandin(("127.0.0.1", 9), sim_rate_hz=240)
    try:
        assert ap.rate_hz == 1200
        ap.follow_rate(1 / 960)
        assert ap.rate_hz == 959  # 960 moved 1 Hz towards 240
        ap.follow_rate(4 / 960)
        assert ap.rate_hz == 240 and _single(240.0) == 240.0
        ap.restart()
        assert ap.rate_hz == 1200
    finally:
        ap.close()


def _fly(ph, pwm_per_frame, rate):
    """Frames straight into the physics (no server): the states after each."""
    out = []
    for pwm in pwm_per_frame:
        ph.step(pwm + (0,) * 12, rate)
        out.append(ph.state())
    return out


def test_a_frame_of_k_steps_is_k_frames_of_one_step(wing):
    """Servo outputs held over the k steps: the same physics as one step a frame, state for
    state (bit for bit), the timestamp k·dt a frame."""
    one, four = _physics(wing), _physics(wing)
    hold = one.launch_hold_steps + one.stroke_steps
    n = 4 * math.ceil((hold + 200) / 4)
    pwm = [ARMED_IDLE] * n
    s1 = _fly(one, pwm, 1200)
    s4 = _fly(four, pwm[::4], 240)
    assert one.phase == four.phase == ad.FLIGHT and four.frame_steps == 4
    assert [s.timestamp_s for s in s4] == [s.timestamp_s for s in s1[3::4]]
    assert s4 == s1[3::4]
    assert four.frame_k == one.frame_k == n and four.core.k == one.core.k > 100
    assert s4[-1].timestamp_s == pytest.approx(n * four.dt_s, rel=1e-12)
    four.flush_events()  # (the server's on_frame does it after each frame)
    assert [e[2] for e in four.events if "frame rate" in e[2]] == [
        "ArduPilot's frame rate 240 Hz: 4 step(s) of 1.042 ms per frame, 240 Hz "
        "(was 1, 960 Hz)"]


def test_a_stop_inside_a_frame_is_reported_at_its_step(wing):
    """The stop's step is the one-step flight's; the frame's remaining steps are at rest on
    the launcher (grounded) and the reply is the frame's end."""
    ref = _physics(wing)
    hold = ref.launch_hold_steps + ref.stroke_steps
    lead = 60 * math.ceil(hold / 60)  # whole frames at k = 3, 4 and 5
    _fly(ref, [ARMED_IDLE] * lead, 1200)
    n = 0
    while not ref.stops and n < 5000:
        _fly(ref, [NOSE_DOWN], 1200)
        n += 1
    assert ref.stops, "no stop"
    stop_step = round(ref.stops[0]["time_s"] / ref.dt_s)
    k = next(k for k in (3, 4, 5) if stop_step % k)  # a k that puts it inside a frame
    ph = _physics(wing)
    _fly(ph, [ARMED_IDLE] * (lead // k), 960 // k)
    frames = 0
    while not ph.stops:
        (state,) = _fly(ph, [NOSE_DOWN], 960 // k)
        frames += 1
    assert ph.frame_steps == k and ph.stops[0]["time_s"] == ref.stops[0]["time_s"]
    assert ph.stops[0]["reason"] == ref.stops[0]["reason"]
    assert ph.frame_k == lead + frames * k > stop_step  # the frame went on past the stop
    assert state.timestamp_s == pytest.approx(ph.frame_k * ph.dt_s, rel=1e-12)
    assert ph.phase == ad.REST and ph.grounded and state.velocity_ned_m_s == (0.0, 0.0, 0.0)
    ph.flush_events()
    (err,) = [e for e in ph.events if e[1] == "ERROR"]
    assert err[0] == pytest.approx(ph.stops[0]["session_s"])


def test_lockstep_at_240_hz_logs_every_step_and_one_message_per_frame(wing, tmp_path):
    """Over the server with the stand-in playing ArduPlane at SIM_RATE_HZ 240: k reaches 4
    in three frames, ArduPilot's clock advances 4·dt a frame, the log has every step's row
    at its own start and one autopilot message per frame; a restart goes back to k = 1."""
    path = tmp_path / "rate.mcap"
    ph = _physics(wing)
    log = open_log(ph, path)
    lk = Link(ph)
    lk.ap.sim_rate_hz = 240
    lk.ap.restart()
    stamps, rates = [], []
    try:
        frames = 0
        while ph.phase != ad.FLIGHT:
            rates.append(lk.ap.rate_hz)
            stamps.append(lk.frame(ARMED_IDLE).values["timestamp"])
            frames += 1
        flight_frames = 50
        for _ in range(flight_frames):
            rates.append(lk.ap.rate_hz)
            stamps.append(lk.frame(ARMED_IDLE).values["timestamp"])
        frames += flight_frames
        steps_in_flight = ph.core.k
        lk.ap.restart()
        lk.frame(DISARMED)
        assert ph.frame_steps == 1 and ph.restarts == 1
    finally:
        lk.close()
        log.close()
    assert rates[:5] == [1200, 959, 479, 319, 240] and set(rates[4:]) == {240}
    steps = [round(b / ph.dt_s) - round(a / ph.dt_s)
             for a, b in zip(stamps[:-1], stamps[1:], strict=True)]
    assert steps[:3] == [2, 3, 4] and set(steps[3:]) == {4}
    assert steps_in_flight >= 4 * flight_frames
    msgs = sink.messages_by_topic(path)
    ap = msgs[sink.topic("coupled", "autopilot")]
    assert len(ap) == frames + 1  # one a frame, the restart's too
    rigid = msgs[sink.topic("coupled", "rigid_body")]
    assert len(rigid) == steps_in_flight  # every step in flight
    times = [ns for ns, _ in rigid]
    assert times == sorted(times) and len(set(times)) == len(times)
    gaps = {round((b - a) * 1e-9 / ph.dt_s) for a, b in zip(times[:-1], times[1:], strict=True)}
    assert gaps == {1}  # consecutive steps, none left out
    assert [m["frame_rate_hz"] for _, m in ap[:5]] == rates[:5]
    ap_times = [ns for ns, _ in ap]
    assert ap_times == sorted(ap_times)
