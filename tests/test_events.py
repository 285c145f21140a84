"""Events in the MCAP logs (``/bioflex/events``, Foxglove's ``foxglove.Log``): Foxglove's
published schema embedded byte for byte; a SITL session whose aircraft crashes (the crash
and the reset on either side of the log split, every STATUSTEXT an event); a gust run that
diverges; ``bioflex-jsb info`` lists them; pymcap-cli doctor (strict message order) and
@mcap/core accept the files."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from mcap.reader import NonSeekingReader, make_reader

from bioflex_jsb import cli
from bioflex_jsb.cli.gust import open_log
from bioflex_jsb.cli.sitl import SplitLog
from bioflex_jsb.drivers.sitl import run_paced
from bioflex_jsb.links import mavlink_modes as MODES
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from tests.test_mcap import _node_checker
from tests.test_sitl import build, make_sim  # noqa: F401  (the module's wing fixture)

EVENTS = "/bioflex/events"
DOCTOR = Path(sys.executable).parent / "pymcap-cli"  # the test extra, next to this Python
RESET_TEXT = "Reset to trim over home"


def doctor_strict(path: Path) -> None:
    """pymcap-cli doctor with non-monotonic log times (also within a chunk) as errors."""
    if not DOCTOR.exists():
        pytest.fail(f"{DOCTOR} is missing: install the test extra (pip install '.[test]')")
    out = subprocess.run([str(DOCTOR), "doctor", "--strict-message-order", str(path)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and "passed" in out.stdout, out.stdout + out.stderr


def file_order(path: Path) -> list[tuple[str, int]]:
    """(topic, log time [ns]) of every message in the order of the bytes of the file."""
    with open(path, "rb") as f:
        return [(ch.topic, m.log_time) for _, ch, m in NonSeekingReader(f).iter_messages()]


def time_order(path: Path) -> list[tuple[str, int]]:
    """(topic, log time [ns]) of every message as an indexed reader sorts them by log time."""
    with open(path, "rb") as f:
        return [(ch.topic, m.log_time)
                for _, ch, m in make_reader(f).iter_messages(log_time_order=True)]


def test_the_log_schema_is_foxglove_published_one_and_its_runtime_reads_our_events(tmp_path):
    pytest.importorskip("foxglove_schemas_protobuf")
    from foxglove_schemas_protobuf import Log_pb2

    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox

    published = Log_pb2.DESCRIPTOR
    assert fox.LOG_FILE == published.serialized_pb
    assert [fox.FILES[n] for n in fox.LOG_FILES[:-1]] == [
        d.serialized_pb for d in published.dependencies]
    path = tmp_path / "events.mcap"
    log = sink.RunLog.open(path, RunDescription("gust", "optimised", 15.0, gust="sharp:1",
                                                models=("coupled",), duration_s=1.0))
    try:
        log.event(1.25, "ERROR", "coupled run stopped: ünïcode ok", name="coupled")
        log.event(2.5, 2, "second")
        with pytest.raises(ValueError, match="event level 'LOUD'"):
            log.event(3.0, "LOUD", "x")
        with pytest.raises(ValueError, match="event level 9"):
            log.event(3.0, 9, "x")
    finally:
        log.close()
    with open(path, "rb") as f:
        got = []
        for schema, channel, message in make_reader(f).iter_messages():
            assert (channel.topic, schema.name, schema.encoding) == (EVENTS, "foxglove.Log",
                                                                     "protobuf")
            got.append(Log_pb2.Log.FromString(message.data))
    assert [(m.timestamp.seconds, m.timestamp.nanos, m.level, m.message, m.name) for m in got] \
        == [(1, 250_000_000, Log_pb2.Log.ERROR, "coupled run stopped: ünïcode ok", "coupled"),
            (2, 500_000_000, Log_pb2.Log.INFO, "second", "bioflex-jsb")]
    assert sink.summarise(path)["events"] == [
        {"time_s": 1.25, "level": "ERROR", "text": "coupled run stopped: ünïcode ok",
         "name": "coupled"},
        {"time_s": 2.5, "level": "INFO", "text": "second", "name": "bioflex-jsb"}]
    doctor_strict(path)


@pytest.fixture(scope="module")
def crash_session(build, tmp_path_factory):  # noqa: F811
    """A session whose aircraft is flown into the ground (MANUAL, stick forward, sent every
    step as a ground station would), logged as ``bioflex-jsb sitl`` logs it, flown on for
    0.5 s after the reset."""
    out = tmp_path_factory.mktemp("sitl") / "session.mcap"
    sim = make_sim(build, start_height_m=20.0, speedup=50.0)
    description = RunDescription(kind="sitl", wing="optimised", speed_m_s=15.0, gust="none",
                                 models=("coupled",), extra={"until_stopped": True})
    log = SplitLog(str(out), description, build, 256.0, open_log)
    logged = log.attach(sim)
    assert sim.vehicle.set_mode(MODES.MANUAL) is None

    def on_sample(t, model, values):
        logged(t, model, values)
        sim.manual(0.8, 0.0)  # ignored once the reset put it in LOITER

    reset_at: list[float] = []

    def should_stop() -> bool:
        if sim.resets and not reset_at:
            reset_at.append(sim.t_s)
        return bool(reset_at) and sim.t_s >= reset_at[0] + 0.5

    try:
        run_paced(sim, 60.0, None, on_sample, should_stop=should_stop, idle=log.idle)
    finally:
        log.close()
    return sim, [Path(p) for p in log.paths]


def test_a_crash_and_the_reset_are_events_on_either_side_of_the_split(crash_session):
    sim, paths = crash_session
    assert sim.resets == 1 and len(paths) == 2, sim.last_reset
    before, after = (sink.summarise(p)["events"] for p in paths)
    # every STATUSTEXT of the first file: the mode change, the crash, the reset (last)
    assert [e["text"] for e in before][0] == "Mode MANUAL" and before[0]["level"] == "INFO"
    crash = [e for e in before if e["text"].startswith(("Crashed: ", "Diverged: "))]
    assert len(crash) == 1 and crash[0]["level"] == "ERROR", before
    assert before[-1]["text"] == RESET_TEXT and before[-1]["level"] == "WARNING"
    assert {e["name"] for e in before} == {"vehicle"}
    t_reset_ns = round(before[-1]["time_s"] * 1e9)
    assert crash[0]["time_s"] == before[-1]["time_s"]  # the step that hit the ground
    # the reset's event is the last record of the file that ends and the first of the next
    for order in (file_order(paths[0]), time_order(paths[0])):
        assert order[-1] == (EVENTS, t_reset_ns)
        assert max(ns for _, ns in order) == t_reset_ns
        steps = [ns for top, ns in order if top != EVENTS]
        assert steps and max(steps) < t_reset_ns  # the last step flown is before its end
    assert after[0]["text"] == RESET_TEXT and round(after[0]["time_s"] * 1e9) == t_reset_ns
    for order in (file_order(paths[1]), time_order(paths[1])):
        assert order[0] == (EVENTS, t_reset_ns)
        assert min(ns for top, ns in order if top != EVENTS) == t_reset_ns  # trim at home
        # the session went on (0.5 s of steps): > 400 steps on the every-step topics
        assert sum(top.endswith("/rigid_body") for top, _ in order) > 400
    for path in paths:  # pose at the scene's 60 Hz instants in each file, from its first step
        order = time_order(path)
        pose = [ns for top, ns in order if top.endswith("/pose")]
        assert len(pose) >= 2 and pose == [ns for top, ns in order if top.endswith("/scene")]
        assert pose == [ns for top, ns in order if top.endswith("/location")]
        assert pose[0] == min(ns for top, ns in order if top.endswith("/rigid_body"))
    meta = sink.summarise(paths[1])["metadata"][sink.RUN_METADATA]
    assert "after_reset" in meta["description"]
    for p in paths:
        doctor_strict(p)


@pytest.fixture(scope="module")
def node_check(tmp_path_factory):
    return _node_checker(tmp_path_factory)


def test_mcap_core_reads_the_events_in_order(crash_session, node_check):
    _, paths = crash_session
    for p in paths:
        result = node_check(p)
        assert result["ordered"] is True and result["dataCrcOk"] is True
        assert result["schemas"][EVENTS] == "foxglove.Log"
        n = len(sink.summarise(p)["events"])
        assert result["counts"][EVENTS] == result["statistics"][EVENTS] == n
    first = node_check(paths[0])["samples"][EVENTS]  # protobufjs: the second event
    assert first["level"] == 4 and first["name"] == "vehicle"  # ERROR: the crash


def test_info_lists_the_events(crash_session, capsys):
    _, paths = crash_session
    assert cli.main(["info", str(paths[0])]) == 0
    out = capsys.readouterr().out
    n = len(sink.summarise(paths[0])["events"])
    assert f"events ({n}):" in out
    assert re.search(r"^  t = \d+\.\d{3} s  ERROR    (Crashed|Diverged): ", out, re.M), out
    assert re.search(rf"^  t = \d+\.\d{{3}} s  WARNING  {RESET_TEXT}$", out, re.M), out


def test_a_diverged_gust_run_logs_its_stop_event(tmp_path, capsys):
    out = tmp_path / "run.mcap"
    code = cli.main(["gust", "--wing", "elastic-backward", "--speed", "22", "--gust",
                     "sharp:0.3", "--models", "coupled", "--duration", "4", "--out", str(out),
                     "--json"])
    assert code == 3
    import json

    data = json.loads(capsys.readouterr().out)
    t_stop = data["summary"]["coupled"]["divergence_time_s"]
    (event,) = sink.summarise(out)["events"]
    assert event["level"] == "ERROR" and event["name"] == "coupled"
    assert event["time_s"] == pytest.approx(t_stop, abs=1e-9)
    assert event["text"].startswith("coupled run stopped (aeroelastic_1): mode aeroelastic_1 "
                                    "diverged"), event
    order = time_order(out)
    assert order[-1][0] == EVENTS and file_order(out)[-1][0] == EVENTS
    doctor_strict(out)
    assert cli.main(["info", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"  t = {t_stop:.3f} s  ERROR    coupled run stopped (aeroelastic_1)" in printed
