"""Logs under faults: a kill before the first step, damaged and truncated files, chunk CRC
checks, recovered files that independent tools accept; a long run's bounded history."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import cli
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink

DESCRIPTION = RunDescription(kind="gust", wing="optimised", speed_m_s=15.0, gust="sharp:3",
                             models=("coupled",), duration_s=2.0)


@pytest.fixture(scope="module")
def log2s(tmp_path_factory) -> Path:
    """A 2 s coupled run: three chunks (864 + 864 + 192 steps)."""
    path = tmp_path_factory.mktemp("faults") / "run.mcap"
    assert cli.main(["gust", "--duration", "2", "--models", "coupled", "--out", str(path),
                     "--json", "--plot", ""]) == 0
    return path


def _chunks(path: Path) -> list:
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return make_reader(f).get_summary().chunk_indexes


def _doctor_ok(path: Path) -> None:
    exe = shutil.which("pymcap-cli")
    if exe is None:
        return  # the test extra is not installed here: the other checks still run
    out = subprocess.run([exe, "doctor", str(path)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and "passed" in out.stdout, out.stdout + out.stderr


def test_header_and_metadata_are_on_disk_before_the_first_step(tmp_path, capsys):
    """A log killed right after it was opened (no step flown) is a file --recover turns
    into a finished, empty log that keeps the run's description."""
    path = tmp_path / "opened.mcap"
    log = sink.RunLog.open(path, DESCRIPTION, {"name": "optimised"}, {})
    try:
        data = path.read_bytes()  # what another process sees now (as after a SIGKILL)
    finally:
        log.close()
    assert data.startswith(sink.MAGIC) and b"bioflex.run" in data
    killed = tmp_path / "killed.mcap"
    killed.write_bytes(data)
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(killed), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["messages"] == 0 and report["skipped"] == []
    assert sink.description_from_metadata(
        sink.summarise(fixed)["metadata"][sink.RUN_METADATA]) == DESCRIPTION
    _doctor_ok(fixed)


def test_an_empty_file_is_one_line_exit_2(tmp_path, capsys):
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    assert cli.main(["info", str(empty), "--recover", str(tmp_path / "x.mcap")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "empty" in err


def test_recover_skips_a_damaged_chunk_and_keeps_every_intact_one_after_it(log2s, tmp_path,
                                                                           capsys):
    chunks = _chunks(log2s)
    assert len(chunks) == 3
    data = bytearray(log2s.read_bytes())
    data[chunks[0].chunk_start_offset + 400] ^= 0xFF  # inside the compressed records
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    # info --check finds it (exit 1), the intact file passes (exit 0)
    assert cli.main(["info", str(log2s), "--check"]) == 0
    assert "ok: 3 chunks" in capsys.readouterr().out
    assert cli.main(["info", str(damaged), "--check", "--json"]) == 1
    check = json.loads(capsys.readouterr().out)
    assert check["chunks"] == 3 and len(check["bad"]) == 1
    assert str(chunks[0].chunk_start_offset) in check["bad"][0]
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(damaged), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert len(report["skipped"]) == 1 and "CRC" in report["skipped"][0]
    kept = 1920 - 864  # the second and third chunks
    assert report["messages"] == 7 * kept and report["chunks"] == 2
    rigid = sink.messages_by_topic(fixed)["/bioflex/coupled/rigid_body"]
    assert [ns for ns, _ in rigid] == [round(k / 960 * 1e9) for k in range(864, 1920)]
    _doctor_ok(fixed)


def test_recover_resyncs_after_a_damaged_record_length(log2s, tmp_path, capsys):
    chunks = _chunks(log2s)
    data = bytearray(log2s.read_bytes())
    data[chunks[1].chunk_start_offset + 6] = 0x7F  # the second chunk's length: nonsense
    damaged = tmp_path / "length.mcap"
    damaged.write_bytes(bytes(data))
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(damaged), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["chunks"] == 2 and len(report["skipped"]) == 1
    assert report["messages"] == 7 * (864 + 192)
    _doctor_ok(fixed)


def test_a_truncated_log_recovers_every_complete_chunk(log2s, tmp_path, capsys):
    chunks = _chunks(log2s)
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(log2s.read_bytes()[:chunks[2].chunk_start_offset + 100])
    assert cli.main(["info", str(cut)]) == 2  # no summary: says how to recover
    assert "--recover" in capsys.readouterr().err
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(cut), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["messages"] == 7 * 1728 and report["skipped"] == []
    assert report["last_time_s"] == pytest.approx(1727 / 960, abs=1e-9)
    _doctor_ok(fixed)


def test_embedded_foxglove_schemas_are_the_published_ones():
    pb = pytest.importorskip("foxglove_schemas_protobuf")
    from foxglove_schemas_protobuf import FrameTransform_pb2, LocationFix_pb2

    from bioflex_jsb.sinks.mcap import foxglove_descriptors as fox

    published = {}

    def add(fd):
        for dep in fd.dependencies:
            add(dep)
        published[fd.name] = fd.serialized_pb

    add(FrameTransform_pb2.DESCRIPTOR)
    add(LocationFix_pb2.DESCRIPTOR)
    assert fox.FILES == published, pb.__name__


def test_protobuf_messages_decode_with_the_protobuf_package(log2s):
    """Google's own protobuf runtime reads our messages with the file's schemas."""
    pytest.importorskip("google.protobuf")
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
    from mcap.reader import make_reader

    ours = sink.messages_by_topic(log2s)
    seen = set()
    with open(log2s, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if channel.topic in seen:
                continue
            seen.add(channel.topic)
            pool = descriptor_pool.DescriptorPool()
            for fd in descriptor_pb2.FileDescriptorSet.FromString(schema.data).file:
                pool.Add(fd)
            cls = message_factory.GetMessageClass(pool.FindMessageTypeByName(schema.name))
            msg = cls.FromString(message.data)
            mine = ours[channel.topic][0][1]
            for field, value in mine.items():
                if field == "timestamp":
                    assert (msg.timestamp.seconds, msg.timestamp.nanos) == (
                        value["sec"], value["nsec"])
                elif isinstance(value, dict):
                    assert {k: getattr(getattr(msg, field), k) for k in value} == value
                elif isinstance(value, list):
                    assert list(getattr(msg, field)) == value
                else:
                    assert getattr(msg, field) == value, field
    assert len(seen) == 7


def test_a_long_run_keeps_an_envelope_with_the_exact_peaks():
    """keep="envelope": a bounded history whose gust summary has the peaks of every step
    (and the settling time to ENVELOPE_S); keep="all" is every step."""
    from bioflex_jsb.api import load_wing
    from bioflex_jsb.drivers.gust import ENVELOPE_S, RunSetup, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import gust_metrics

    wing = load_wing().model
    setup = RunSetup(15.0, parse_gust("sharp:3"), 4.0, 0.5)
    full = run_gust(Airframe(), wing, "coupled", setup, keep="all")
    env = run_gust(Airframe(), wing, "coupled", setup, keep="envelope")
    assert full.meta["history"] == "all" and env.meta["history"] == "envelope"
    assert env.meta["steps"] == len(full.time_s) == 3840
    assert len(env.time_s) < 0.1 * len(full.time_s)
    assert np.all(np.diff(env.time_s) > 0)
    a, b = gust_metrics(full, 0.5), gust_metrics(env, 0.5)
    for name in ("peak_du_m_s", "peak_dalpha_rad", "peak_dq_rad_s", "peak_dtheta_rad",
                 "peak_dn_z"):
        assert getattr(a, name) == getattr(b, name), name
    if a.settling_time_s is not None and b.settling_time_s is not None:
        assert abs(a.settling_time_s - b.settling_time_s) <= ENVELOPE_S
    with pytest.raises(ValueError, match="keep"):
        run_gust(Airframe(), wing, "coupled", setup, keep="some")
