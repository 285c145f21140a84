"""Logs under faults: a kill before the first step, damaged and truncated files, chunk CRC
checks, recovered files that independent tools accept; a long run's bounded history."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import cli
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from tests.tools import env_program, protobuf_class, published_files

DESCRIPTION = RunDescription(kind="gust", wing="optimised", speed_m_s=15.0, gust="sharp:3",
                             models=("coupled",), duration_s=2.0)


@pytest.fixture(scope="module")
def log2s(tmp_path_factory) -> Path:
    """A 2 s coupled run: the steps in three chunks (864 + 864 + 192 steps), each followed
    by a chunk of the section loads (sinks/mcap/loads_topic.py)."""
    path = tmp_path_factory.mktemp("faults") / "run.mcap"
    assert cli.main(["gust", "--duration", "2", "--models", "coupled", "--out", str(path),
                     "--json", "--plot", ""]) == 0
    return path


def _chunk_messages(path: Path) -> list[dict[str, list[int]]]:
    """Per chunk, in file order: {topic: log times [ns] of its messages} (from the message
    index records after each chunk), so that the expectations below follow the file."""
    from mcap.records import Channel, Chunk, MessageIndex
    from mcap.stream_reader import StreamReader

    topics: dict[int, str] = {}
    out: list[dict[str, list[int]]] = []
    with open(path, "rb") as f:
        for rec in StreamReader(f, emit_chunks=True).records:
            if isinstance(rec, Channel):
                topics[rec.id] = rec.topic
            elif isinstance(rec, Chunk):
                out.append({})
            elif isinstance(rec, MessageIndex) and out:
                out[-1][topics[rec.channel_id]] = [t for t, _ in rec.records]
    return out


def _count(chunks: list[dict[str, list[int]]]) -> int:
    return sum(len(v) for c in chunks for v in c.values())


RIGID = "/bioflex/coupled/rigid_body"


def _chunks(path: Path) -> list:
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        return make_reader(f).get_summary().chunk_indexes


def _doctor_ok(path: Path) -> None:
    exe = env_program("pymcap-cli")
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
    contents = _chunk_messages(log2s)
    assert len(chunks) == len(contents) >= 3
    assert [len(c.get(RIGID, [])) for c in contents if RIGID in c] == [864, 864, 192]
    data = bytearray(log2s.read_bytes())
    data[chunks[0].chunk_start_offset + 400] ^= 0xFF  # inside the compressed records
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    # info --check finds it (exit 1), the intact file passes (exit 0)
    assert cli.main(["info", str(log2s), "--check"]) == 0
    assert f"ok: {len(chunks)} chunks" in capsys.readouterr().out
    assert cli.main(["info", str(damaged), "--check", "--json"]) == 1
    check = json.loads(capsys.readouterr().out)
    assert check["chunks"] == len(chunks) and len(check["bad"]) == 1
    assert str(chunks[0].chunk_start_offset) in check["bad"][0]
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(damaged), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    # a zstd chunk is checked by its frame's content checksum (its MCAP CRC is 0: writer.py)
    assert len(report["skipped"]) == 1 and "checksum" in report["skipped"][0]
    assert report["messages"] == _count(contents[1:]) and report["chunks"] == len(chunks) - 1
    rigid = sink.messages_by_topic(fixed)[RIGID]
    assert [ns for ns, _ in rigid] == [t for c in contents[1:] for t in c.get(RIGID, [])]
    assert [ns for ns, _ in rigid][0] == round(864 / 960 * 1e9)  # the first chunk's steps
    _doctor_ok(fixed)


def test_plot_says_damage_it_does_not_read_and_refuses_damage_it_does(log2s, tmp_path,
                                                                      capsys):
    """A figure drawn from a log whose 3-D scene chunk was damaged said nothing of it (the
    review of 2026-12-03): now one warning line and ``damaged`` in the JSON; damage in what
    the figure reads stays exit 2, one line, pointing to ``--recover``."""
    from mcap.reader import make_reader

    with open(log2s, "rb") as f:
        summary = make_reader(f).get_summary()
    topics = {cid: ch.topic for cid, ch in summary.channels.items()}

    def damaged(name: str, topic: str) -> Path:
        chunk = next(c for c in summary.chunk_indexes
                     if topic in {topics[i] for i in c.message_index_offsets})
        data = bytearray(log2s.read_bytes())
        data[chunk.chunk_start_offset + 400] ^= 0xFF  # inside the compressed records
        out = tmp_path / name
        out.write_bytes(bytes(data))
        return out

    assert cli.main(["plot", str(log2s), "--out", str(tmp_path / "ok.png"), "--json"]) == 0
    captured = capsys.readouterr()
    assert json.loads(captured.out)["damaged"] == [] and captured.err == ""
    scene = damaged("scene.mcap", "/bioflex/coupled/scene")
    assert cli.main(["plot", str(scene), "--out", str(tmp_path / "s.png"), "--json"]) == 0
    captured = capsys.readouterr()
    line = _one_line(captured.err)
    assert "warning" in line and "damaged" in line and "--recover" in line
    assert any("1 of" in d for d in json.loads(captured.out)["damaged"])
    assert (tmp_path / "s.png").read_bytes()[:4] == b"\x89PNG"
    rigid = damaged("rigid.mcap", RIGID)
    assert cli.main(["plot", str(rigid), "--out", str(tmp_path / "r.png")]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "--recover" in line and not (tmp_path / "r.png").exists()


def test_recover_resyncs_after_a_damaged_record_length(log2s, tmp_path, capsys):
    chunks = _chunks(log2s)
    contents = _chunk_messages(log2s)
    data = bytearray(log2s.read_bytes())
    data[chunks[1].chunk_start_offset + 6] = 0x7F  # the second chunk's length: nonsense
    damaged = tmp_path / "length.mcap"
    damaged.write_bytes(bytes(data))
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(damaged), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["chunks"] == len(chunks) - 1 and len(report["skipped"]) == 1
    assert report["messages"] == _count(contents[:1] + contents[2:])
    _doctor_ok(fixed)


def test_recover_of_a_finished_log_reads_its_summary(log2s, tmp_path, capsys):
    """A damaged Header length (the review of 2026-12-03: the scan jumped past the schemas
    and the first chunk; the recovered file had every channel without its schema, and
    ``info --check`` passed it): with the summary intact, the schemas, channels and metadata
    come from it and each chunk is read where its index says. Every message comes back,
    decodable."""
    contents = _chunk_messages(log2s)
    data = bytearray(log2s.read_bytes())
    data[10] ^= 0x55  # the Header record's length
    damaged = tmp_path / "header.mcap"
    damaged.write_bytes(bytes(data))
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(damaged), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["messages"] == _count(contents) and report["skipped"] == []
    from mcap.reader import make_reader

    with open(log2s, "rb") as a, open(fixed, "rb") as b:
        old, new = make_reader(a), make_reader(b)
        assert {s.name for s in new.get_summary().schemas.values()} == \
            {s.name for s in old.get_summary().schemas.values()}
        assert all(c.schema_id in new.get_summary().schemas
                   for c in new.get_summary().channels.values())
        assert sorted(m.name for m in new.iter_metadata()) == \
            sorted(m.name for m in old.iter_metadata())
    _doctor_ok(fixed)


def test_a_channel_whose_schema_is_lost_is_not_copied_without_it():
    """In a scan (no summary), a channel record whose schema record was lost: its messages
    are counted lost, not written on a channel without a schema."""
    import io
    import struct

    from bioflex_jsb.sinks.mcap_io.recover import _Copier
    from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

    copier = _Copier(McapFileWriter(io.BytesIO(), library="test"))

    def string(text: str) -> bytes:
        return struct.pack("<I", len(text)) + text.encode()

    channel = struct.pack("<HH", 1, 7) + string("/t") + string("protobuf") + struct.pack("<I", 0)
    copier.record(4, channel)  # schema 7 was never seen
    copier.record(5, struct.pack("<HIQQ", 1, 0, 10, 10) + b"\x08\x01")
    assert copier.channels == {1: None} and copier.lost == {1: 1} and copier.messages == 0


def test_a_truncated_log_recovers_every_complete_chunk(log2s, tmp_path, capsys):
    chunks = _chunks(log2s)
    contents = _chunk_messages(log2s)
    last = len(chunks) - 1  # cut inside the last chunk: every one before it is complete
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(log2s.read_bytes()[:chunks[last].chunk_start_offset + 100])
    assert cli.main(["info", str(cut)]) == 2  # no summary: says how to recover
    assert "--recover" in capsys.readouterr().err
    fixed = tmp_path / "fixed.mcap"
    assert cli.main(["info", str(cut), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["messages"] == _count(contents[:last]) and report["skipped"] == []
    assert report["last_time_s"] == pytest.approx(
        max(t for c in contents[:last] for v in c.values() for t in v) * 1e-9, abs=1e-9)
    _doctor_ok(fixed)


def test_embedded_foxglove_schemas_are_the_published_ones():
    pb = pytest.importorskip("foxglove_schemas_protobuf")
    from foxglove_schemas_protobuf import FrameTransform_pb2, LocationFix_pb2

    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox

    published = published_files(FrameTransform_pb2.DESCRIPTOR, LocationFix_pb2.DESCRIPTOR)
    assert fox.FILES == published, pb.__name__


def test_protobuf_messages_decode_with_the_protobuf_package(log2s):
    """Google's own protobuf runtime reads our messages with the file's schemas."""
    pytest.importorskip("google.protobuf")
    from mcap.reader import make_reader

    ours = sink.messages_by_topic(log2s)
    seen = set()
    with open(log2s, "rb") as f:
        for schema, channel, message in make_reader(f).iter_messages():
            if channel.topic in seen or channel.topic.rsplit("/", 1)[1] in (
                    "scene", "airframe", "scene_loads"):
                continue  # the 3-D scene's nested messages: tests/test_scene*.py decode them
            seen.add(channel.topic)
            cls = protobuf_class(schema.name, schema.data)
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
    # the seven step topics and the section loads (sinks/mcap/loads_topic.py)
    assert {t.rsplit("/", 1)[1] for t in seen} >= {
        "rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location", "loads"}


def test_a_long_run_keeps_an_envelope_with_the_exact_peaks():
    """keep="envelope": a bounded history whose gust summary has the peaks of every step
    (and the settling time to ENVELOPE_S); keep="all" is every step."""
    from bioflex_jsb.api import load_wing
    from bioflex_jsb.drivers.gust import ENVELOPE_S, RunConfig, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import gust_metrics

    wing = load_wing().model
    setup = RunConfig(15.0, parse_gust("sharp:3"), 4.0, 0.5)
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


# ---------------------------------------------------------------------------------------
# info / info --check: unfinished, still written, or damaged in any part
# ---------------------------------------------------------------------------------------
def _independent_reader_opens(path: Path) -> bool:
    """Whether the mcap package's own indexed reader gets the file's summary."""
    from mcap.exceptions import McapError
    from mcap.reader import make_reader

    try:
        with open(path, "rb") as f:
            return make_reader(f).get_summary() is not None
    except (McapError, ValueError, EOFError):
        return False


def _doctor(path: Path) -> int | None:
    """pymcap-cli doctor's exit status (the tool beside this interpreter), None if absent."""
    exe = Path(sys.executable).with_name("pymcap-cli")
    if not exe.exists():
        return None
    return subprocess.run([str(exe), "doctor", str(path)], capture_output=True, text=True,
                          timeout=120).returncode


def _one_line(err: str) -> str:
    lines = [x for x in err.strip().splitlines() if x.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


def _old(path: Path) -> Path:
    """Set the file's modification time 1 h back (a log nobody has touched for long)."""
    t = time.time() - 3600
    os.utime(path, (t, t))
    return path


def test_check_reports_an_unfinished_log_as_not_ok(log2s, tmp_path, capsys):
    """Before: "ok", exit 0, on a file no independent reader opens."""
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(log2s.read_bytes()[: log2s.stat().st_size * 2 // 3])
    _old(cut)
    assert not _independent_reader_opens(cut)
    assert _doctor(cut) not in (0,)  # pymcap-cli doctor fails it too (None: not installed)
    assert cli.main(["info", "--check", str(cut)]) == 1
    captured = capsys.readouterr()
    assert "unfinished" in captured.out
    line = _one_line(captured.err)
    assert "no Data End, summary, footer" in line and "--recover" in line
    assert "writer was killed" in line
    assert cli.main(["info", "--check", str(log2s)]) == 0  # a finished log is ok
    assert capsys.readouterr().out.split(": ")[1] == "ok"


WRITER = """
import sys, time
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks.mcap import RunLog
log = RunLog.open(sys.argv[1], RunDescription(kind="gust", wing="optimised", speed_m_s=15.0,
                  models=("coupled",), duration_s=2.0), {"name": "optimised"}, {})
print("open", flush=True)
time.sleep(120)
"""


def test_info_tells_a_log_being_written_from_one_whose_writer_was_killed(tmp_path, capsys):
    """Before: "the writer was killed" while the writer was running."""
    path = tmp_path / "live.mcap"
    proc = subprocess.Popen([sys.executable, "-c", WRITER, str(path)], stdout=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout.readline().strip() == "open"
        _old(path)  # not the modification time: the open descriptor tells
        assert cli.main(["info", str(path)]) == 2
        line = _one_line(capsys.readouterr().err)
        assert f"still being written (open for writing by pid {proc.pid}" in line, line
        assert "killed" not in line
    finally:
        proc.kill()
        proc.wait()
    # the writer is gone: a file touched seconds ago may still be written elsewhere ...
    os.utime(path)
    assert cli.main(["info", str(path)]) == 2
    assert "probably still being written" in _one_line(capsys.readouterr().err)
    # ... one untouched for long lost its writer
    _old(path)
    assert cli.main(["info", str(path)]) == 2
    line = _one_line(capsys.readouterr().err)
    assert "writer was killed" in line and "--recover" in line


def _regions(path: Path) -> dict[str, tuple[int, int]]:
    """Byte ranges [start, end) of the parts of a finished log: header, first chunk, the
    metadata or records after the last chunk, the summary, the footer."""
    import struct

    from mcap.reader import make_reader

    data = path.read_bytes()
    with open(path, "rb") as f:
        summary = make_reader(f).get_summary()
    chunks = sorted(summary.chunk_indexes, key=lambda c: c.chunk_start_offset)
    (summary_start,) = struct.unpack_from("<Q", data, len(data) - 8 - 20)
    header_len = struct.unpack_from("<Q", data, 9)[0]
    return {
        "magic": (0, 8),
        "header": (8, 8 + 9 + header_len),
        "chunk": (chunks[0].chunk_start_offset,
                  chunks[0].chunk_start_offset + chunks[0].chunk_length),
        "last chunk": (chunks[-1].chunk_start_offset,
                       chunks[-1].chunk_start_offset + chunks[-1].chunk_length),
        "after the chunks": (chunks[-1].chunk_start_offset + chunks[-1].chunk_length,
                             summary_start),
        "summary": (summary_start, len(data) - 8 - 29),
        "footer": (len(data) - 8 - 29, len(data)),
    }


def _flipped(src: Path, dst: Path, offsets) -> Path:
    data = bytearray(src.read_bytes())
    for at, bit in offsets:
        data[at % len(data)] ^= 1 << bit
    dst.write_bytes(bytes(data))
    return dst


@pytest.mark.parametrize("region", ["magic", "header", "chunk", "last chunk",
                                    "after the chunks", "summary", "footer"])
def test_one_flipped_bit_in_any_part_of_a_log_is_found(log2s, tmp_path, capsys, region):
    lo, hi = _regions(log2s)[region]
    assert hi > lo, region
    for k, at in enumerate((lo, (lo + hi) // 2, hi - 1)):  # first, middle, last byte
        for bit in (0, 7):
            bad = _flipped(log2s, tmp_path / f"f{k}{bit}.mcap", [(at, bit)])
            status = cli.main(["info", str(bad)])
            err = capsys.readouterr().err
            assert status == 2, (region, at, bit)
            line = _one_line(err)
            assert "damaged" in line or "not an MCAP file" in line, line
            assert cli.main(["info", "--check", str(bad)]) in (1, 2)
            capsys.readouterr()


def test_random_flips_anywhere_are_found(log2s, tmp_path):
    """Before: 400 flipped bytes and ``info`` reported the file as fine."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    size = log2s.stat().st_size

    @settings(max_examples=30, deadline=None,
              suppress_health_check=[HealthCheck.function_scoped_fixture])
    @given(st.lists(st.tuples(st.integers(0, size - 1), st.integers(0, 7)), min_size=1,
                    max_size=400, unique=True))  # a bit flipped twice is no change
    def flips(offsets):
        bad = _flipped(log2s, tmp_path / "flipped.mcap", offsets)
        with pytest.raises(sink.LogError):
            sink.summarise(bad)

    flips()


FOREIGN_TOPICS = ["/bioflex/coupled/rigid_body", "/bioflex/coupled/modal",
                  "/bioflex/coupled/gust", "/bioflex/events", "/bioflex/rigid_body"]


def _foreign(path: Path, modal) -> Path:
    """An MCAP another program wrote, on our topic names, JSON messages of its own."""
    from mcap.writer import Writer

    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="", library="another program 1.0")
        sid = w.register_schema(name="Other", encoding="jsonschema", data=b"{}")
        ids = {t: w.register_channel(topic=t, message_encoding="json", schema_id=sid)
               for t in FOREIGN_TOPICS}
        w.add_metadata("bioflex.run", {"command": "gust", "argv": "[1, 2"})
        for i in range(5):
            for t, cid in ids.items():
                body = modal(i) if t.endswith("/modal") else {"foo": i, "level": "x"}
                w.add_message(cid, log_time=i * 10**6, publish_time=i * 10**6,
                              data=json.dumps(body).encode())
        w.finish()
    return path


@pytest.mark.parametrize("modal", [lambda i: [i, "x"], lambda i: {"eta_rad": "abc"},
                                   lambda i: {"other": i}], ids=["list", "text", "missing"])
@pytest.mark.parametrize("command", ["info", "plot", "rerun"])
def test_another_programs_mcap_with_our_topics_is_one_line(tmp_path, capsys, command, modal):
    path = _foreign(tmp_path / "foreign.mcap", modal)
    argv = {"info": ["info", str(path)],
            "plot": ["plot", str(path), "--out", str(tmp_path / "f.png")],
            "rerun": ["rerun", str(path), "--out", str(tmp_path / "again.mcap")]}[command]
    status = cli.main(argv)
    captured = capsys.readouterr()
    if command == "info":  # any MCAP is summarised
        assert status == 0 and "another program 1.0" in captured.out
        return
    assert status == 2
    line = _one_line(captured.err)
    if command == "plot":
        assert "'/bioflex/coupled/modal'" in line and "not one bioflex-jsb writes" in line


@pytest.mark.parametrize("schema,body", [(b"\x00garbage", b"\x01\x02"), (b"", b"\xff\xff")],
                         ids=["garbage-schema", "empty-schema"])
@pytest.mark.parametrize("command", ["info", "plot"])
def test_another_programs_protobuf_on_our_topics_names_the_record(tmp_path, capsys, command,
                                                                  schema, body):
    from mcap.writer import Writer

    path = tmp_path / "foreign.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="", library="another program 1.0")
        sid = w.register_schema(name="foxglove.Log", encoding="protobuf", data=schema)
        for topic in ("/bioflex/events", "/bioflex/coupled/modal"):
            cid = w.register_channel(topic=topic, message_encoding="protobuf", schema_id=sid)
            w.add_message(cid, log_time=10**6, publish_time=10**6, data=body)
        w.finish()
    argv = ["info", str(path)] if command == "info" else [
        "plot", str(path), "--out", str(tmp_path / "f.png")]
    assert cli.main(argv) == 2
    line = _one_line(capsys.readouterr().err)
    assert "message on '/bioflex/" in line and "at log time 0.001 s" in line, line
