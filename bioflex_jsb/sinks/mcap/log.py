"""MCAP logs of runs: writing (every step of a run), reading back, recovering a killed log.

This is the only module that imports ``mcap``. Topics (JSON messages with JSON schemas;
``<model>`` is ``rigid``, ``coupled`` or ``qsd``; units in every field name and in the schema
descriptions; the full table is in ``docs/logging.md``):

* ``/bioflex/<model>/rigid_body`` (``bioflex.RigidBody``): perturbations from trim, the
  absolute attitude, body rates, airspeed, load factor, altitude (the position is on
  ``pose`` and ``location``);
* ``/bioflex/<model>/modal`` (``bioflex.Modal``): modal coordinates η [rad], rates η̇ [rad/s];
* ``/bioflex/<model>/modal_loads`` (``bioflex.ModalLoads``): the elastic wing's loads applied;
* ``/bioflex/<model>/gust`` (``bioflex.Gust``): the vertical gust w_g [m/s, up];
* ``/bioflex/<model>/controls`` (``bioflex.Controls``): elevator [rad], throttle [-];
* ``/bioflex/<model>/pose`` (``foxglove.FrameTransform``): ``world`` → ``<model>_body``;
* ``/bioflex/<model>/location`` (``foxglove.LocationFix``): latitude, longitude [deg], altitude;
* ``/bioflex/<model>/lti_prediction`` (``bioflex.LtiPrediction``): the linear model's response
  to the same gust, where one ran alongside (:meth:`RunLog.prediction`).

Frames: ``world`` is a local East-North-Up frame [m] whose origin is the aircraft's position
at the first sample of the file (flat-Earth tangent plane on the WGS-84 ellipsoid);
``<model>_body`` is the body frame with x forward, y to port (left), z up (FLU, as Foxglove and
ROS expect). Log and publish times are simulation time [ns from the run's start].

Metadata records: ``bioflex.run`` (command, its arguments as JSON, the argument list that
repeats the run, wing variant and overrides, speed, gust and seed, models, time step, package
and JSBSim versions) and ``bioflex.world_frame`` (the ENU origin).

Chunks are closed every :data:`CHUNK_SPAN_S` of simulated time (or :data:`CHUNK_WALL_S` of
wall time, or 4096 steps) and written to the operating system at once, so a process killed
hard (SIGKILL) loses at most the chunk in progress; :func:`recover` rebuilds an indexed
file from the complete chunks of such a log. A gust run is logged from the run's own table
of steps (:meth:`RunLog.recorder`, nothing copied per step) and a chunk's steps are
formatted at once, vectorised, in fixed-width numbers (:func:`fixed_e`), so record lengths and index
offsets are known in advance (``docs/logging.md``, Overhead).

The writer is our own (the ``mcap`` package's ``Writer`` costs ~6.5 µs per message, more than
the 20 % overhead budget allows at seven messages per step); every record other than the
messages in a chunk is serialised with the ``mcap`` package's record classes, and the files are
checked by independent readers in the tests (``@mcap/core``, ``pymcap-cli doctor``).
"""

from __future__ import annotations

import json
import math
import platform
import signal
import struct
import time
import zlib
from collections.abc import Iterator
from contextlib import contextmanager
from itertools import chain
from pathlib import Path

import numpy as np
from mcap.data_stream import RecordBuilder
from mcap.records import (
    Channel,
    ChunkIndex,
    DataEnd,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

from bioflex_jsb import __version__

MAGIC = b"\x89MCAP0\r\n"
# simulated time per chunk [s]: the most a SIGKILL can lose (with one step, < 1 s); long
# chunks spread the fixed cost of writing one (≈ 0.7 ms measured in a run) over more steps
CHUNK_SPAN_S = 0.9
CHUNK_WALL_S = 0.9  # wall time per chunk [s] (runs slower than real time, SITL sessions)
CHUNK_MAX_BYTES = 4 * 1024 * 1024  # uncompressed chunk size limit [bytes]
COMPRESSION = "zstd"
RUN_METADATA = "bioflex.run"
FRAME_METADATA = "bioflex.world_frame"
WORLD_FRAME = "world"
GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location",
          "lti_prediction")

_OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK = 0x03, 0x04, 0x05, 0x06
_OP_CHUNK_INDEX, _OP_STATISTICS, _OP_METADATA_INDEX = 0x08, 0x0B, 0x0D
NUMBER = "%.9g"  # numbers of the general path: 9 significant digits (relative ≤ 5e-10)
_MSG_HEADER = struct.Struct("<BQHIQQ")  # opcode, record length, channel, sequence, log, publish
FIXED_NUMBER = "% .8e"  # fixed-width numbers of the fast path (same 9 significant digits)
_WGS84_A_M = 6378137.0
_WGS84_E2 = 6.69437999014e-3


def topic(model: str, group: str) -> str:
    """The topic of ``group`` (one of :data:`GROUPS`) for the wing ``model``."""
    return f"/bioflex/{model}/{group}"


def body_frame(model: str) -> str:
    return f"{model}_body"


def _num(description: str) -> dict:
    return {"type": "number", "description": description}


_TIME = {
    "type": "object",
    "title": "time",
    "description": "simulation time since the start of the run",
    "properties": {"sec": {"type": "integer", "minimum": 0, "description": "whole seconds [s]"},
                   "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999,
                            "description": "nanoseconds [ns]"}},
}

# Fields of rigid_body, in message order: (field, row key, description).
_RIGID_FIELDS = (
    ("du_m_s", "u", "airspeed perturbation from trim [m/s]"),
    ("dalpha_rad", "alpha", "angle-of-attack perturbation from trim, against the air [rad]"),
    ("dtheta_rad", "theta", "pitch-angle perturbation from trim [rad]"),
    ("airspeed_m_s", "airspeed_m_s", "true airspeed [m/s]"),
    ("n_z", "n_z", "load factor, up, 1 in level flight [-]"),
    ("roll_rad", "phi_rad", "roll angle φ, right wing down positive (NED Euler) [rad]"),
    ("pitch_rad", "theta_rad", "pitch angle θ, nose up positive (NED Euler) [rad]"),
    ("yaw_rad", "psi_rad", "heading ψ, clockwise from north (NED Euler) [rad]"),
    ("p_rad_s", "p_rad_s", "roll rate about body x (forward) [rad/s]"),
    ("q_rad_s", "q", "pitch rate about body y (starboard), nose up [rad/s]"),
    ("r_rad_s", "r_rad_s", "yaw rate about body z (down) [rad/s]"),
    ("altitude_m", "altitude_m", "altitude above sea level [m]"),
)
# Fields logged only when the run provides them (row key = field name).
_RIGID_OPTIONAL = (
    ("alpha_rad", "angle of attack against the air [rad]"),
    ("beta_rad", "sideslip angle, wind from starboard positive [rad]"),
    ("v_north_m_s", "inertial velocity, north [m/s]"),
    ("v_east_m_s", "inertial velocity, east [m/s]"),
    ("v_down_m_s", "inertial velocity, down [m/s]"),
)

SCHEMAS: dict[str, dict] = {
    "rigid_body": {
        "title": "bioflex.RigidBody",
        "description": "Airframe state after each step; perturbations (d…) are from the trim "
        "at the run start. The position is on the pose topic (world frame, local ENU) and "
        "the location topic (WGS-84); the time is the message's log time.",
        "type": "object",
        "properties": {
            **{f: _num(d) for f, _, d in _RIGID_FIELDS},
            **{f: _num(d) for f, d in _RIGID_OPTIONAL},
        },
    },
    "modal": {
        "title": "bioflex.Modal",
        "description": "Modal coordinates of the elastic wing (perturbations from trim); "
        "modes normalised on twist, positive leading edge up (docs/conventions.md).",
        "type": "object",
        "properties": {
            "eta_rad": {"type": "array", "items": {"type": "number"},
                        "description": "η_i, element i is mode i+1 [rad]"},
            "eta_dot_rad_s": {"type": "array", "items": {"type": "number"},
                              "description": "η̇_i, element i is mode i+1 [rad/s]"},
        },
    },
    "modal_loads": {
        "title": "bioflex.ModalLoads",
        "description": "Incremental loads of the elastic wing applied to the airframe.",
        "type": "object",
        "properties": {
            "lift_n": _num("lift, up, normal to the air velocity [N]"),
            "drag_n": _num("drag, aft, along the air velocity [N]"),
            "pitch_moment_n_m": _num("pitching moment about the CG, nose up [N*m]"),
        },
    },
    "gust": {
        "title": "bioflex.Gust",
        "description": "Wind field applied to the airframe (vertical gust only).",
        "type": "object",
        "properties": {
            "w_g_m_s": _num("vertical gust velocity, up [m/s] (JSBSim wind-down = -w_g)"),
        },
    },
    "controls": {
        "title": "bioflex.Controls",
        "description": "Control inputs (held at trim in gust runs).",
        "type": "object",
        "properties": {
            "elevator_rad": _num("elevator deflection, trailing edge down positive [rad]"),
            "throttle": _num("throttle, 0 to 1 [-]"),
        },
    },
    "pose": {
        "title": "foxglove.FrameTransform",
        "description": "Aircraft pose: transform from the parent frame `world` (local ENU, "
        "origin at the first sample of the file) to the child frame `<model>_body` (x "
        "forward, y left, z up).",
        "type": "object",
        "properties": {
            "timestamp": _TIME,
            "parent_frame_id": {"type": "string", "description": "parent frame (world)"},
            "child_frame_id": {"type": "string", "description": "child frame (<model>_body)"},
            "translation": {
                "type": "object", "title": "foxglove.Vector3",
                "description": "body origin (CG) in the world frame [m]",
                "properties": {"x": _num("east [m]"), "y": _num("north [m]"),
                               "z": _num("up [m]")},
            },
            "rotation": {
                "type": "object", "title": "foxglove.Quaternion",
                "description": "rotation of the body frame in the world frame [-]",
                "properties": {"x": _num("x [-]"), "y": _num("y [-]"), "z": _num("z [-]"),
                               "w": _num("w [-]")},
            },
        },
    },
    "location": {
        "title": "foxglove.LocationFix",
        "description": "Aircraft position on the WGS-84 ellipsoid (exact, from the simulation).",
        "type": "object",
        "properties": {
            "timestamp": _TIME,
            "frame_id": {"type": "string", "description": "frame at the position (body)"},
            "latitude": _num("geodetic latitude [deg]"),
            "longitude": _num("longitude [deg]"),
            "altitude": _num("altitude above sea level [m]"),
            "position_covariance": {
                "type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9,
                "description": "ENU position covariance, row-major [m^2] (zero: exact)"},
            "position_covariance_type": {
                "type": "integer", "enum": [0, 1, 2, 3],
                "description": "0 unknown, 1 approximated, 2 diagonal known, 3 known"},
        },
    },
    "lti_prediction": {
        "title": "bioflex.LtiPrediction",
        "description": "Response of the linear model (Eq. 4) to the same gust samples, as "
        "perturbations from trim.",
        "type": "object",
        "properties": {
            "du_m_s": _num("airspeed perturbation [m/s]"),
            "dalpha_rad": _num("angle-of-attack perturbation, against the air [rad]"),
            "q_rad_s": _num("pitch rate [rad/s]"),
            "dtheta_rad": _num("pitch-angle perturbation [rad]"),
            "n_z": _num("load factor [-]"),
            "eta_rad": {"type": "array", "items": {"type": "number"},
                        "description": "modal coordinates, element i is mode i+1 [rad]"},
        },
    },
}
for _s in SCHEMAS.values():
    _s["$schema"] = "https://json-schema.org/draft/2020-12/schema"


def _version(package: str) -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(package)
    except PackageNotFoundError:
        return "unknown"


@contextmanager
def _signals_deferred():
    """Hold SIGINT/SIGTERM while a chunk or the summary is written (no half-written record)."""
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    except (AttributeError, ValueError, OSError):  # not Unix or not the main thread
        old = None
    try:
        yield
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _message_index(channel_id: int, entries) -> bytes:
    """A Message Index record (opcode 0x07): channel id, then (log time, offset) pairs
    (``entries``: an (n, 2) integer array)."""
    n = len(entries)
    return (struct.pack("<BQHI", 0x07, 6 + 16 * n, channel_id, 16 * n)
            + np.ascontiguousarray(entries, dtype="<u8").tobytes())


def _record_bytes(record) -> bytes:
    b = RecordBuilder()
    record.write(b)
    return b.end()


class McapFileWriter:
    """A chunked, indexed MCAP writer built for many small messages per step.

    Messages go into the chunk in progress one at a time with :meth:`append` or as whole
    serialised blocks with :meth:`append_block` (the index entries as arrays); the chunk is
    closed by the caller's policy, and each closed chunk is compressed, written with its
    message indexes and flushed to the operating system. :meth:`finish` writes the summary
    (schemas, channels, statistics, chunk and metadata indexes, summary offsets) and the
    footer with its CRC.
    """

    def __init__(self, stream, library: str) -> None:
        import zstandard

        self._stream = stream
        # zstd's level 1 with a small hash table and window and long minimum matches: the
        # chunks repeat one step's layout every ~1.4 kB, so recent long matches are all it
        # needs; measured on a gust-run chunk: 0.75 ms and 9.2:1 against level 1's 1.04 ms
        # and 7.9:1 and the default level 3's 1.6 ms and 7.0:1
        self._compress = zstandard.ZstdCompressor(
            compression_params=zstandard.ZstdCompressionParameters.from_level(
                1, window_log=17, hash_log=11, min_match=7)).compress
        self._crc = 0
        self._offset = 0
        self._schemas: list[Schema] = []
        self._channels: list[Channel] = []
        self._chunk_indexes: list[ChunkIndex] = []
        self._metadata_indexes: list[MetadataIndex] = []
        self._counts: dict[int, int] = {}
        self._start_ns: int | None = None
        self._end_ns = 0
        self._n_messages = 0
        self._parts: list[bytes] = []  # the chunk in progress
        self._size = 0
        # per channel: (log time, offset) tuples of single messages, arrays of blocks
        self._index: dict[int, list[tuple[int, int]]] = {}
        self._blocks: dict[int, list[np.ndarray]] = {}
        self.finished = False
        self._write(MAGIC + _record_bytes(Header(profile="", library=library)))

    def _write(self, data: bytes) -> None:
        self._stream.write(data)
        self._crc = zlib.crc32(data, self._crc)
        self._offset += len(data)

    def add_schema(self, name: str, data: dict) -> int:
        schema = Schema(id=len(self._schemas) + 1, name=name, encoding="jsonschema",
                        data=json.dumps(data, ensure_ascii=False).encode())
        self._schemas.append(schema)
        self._write(_record_bytes(schema))
        return schema.id

    def add_channel(self, topic_name: str, schema_id: int, metadata: dict[str, str]) -> int:
        channel = Channel(id=len(self._channels) + 1, topic=topic_name, message_encoding="json",
                          schema_id=schema_id, metadata=metadata)
        self._channels.append(channel)
        self._index[channel.id] = []
        self._blocks[channel.id] = []
        self._counts[channel.id] = 0
        self._write(_record_bytes(channel))
        return channel.id

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        record = _record_bytes(Metadata(name=name, metadata=data))
        self._metadata_indexes.append(MetadataIndex(offset=self._offset, length=len(record),
                                                    name=name))
        self._write(record)

    def append(self, channel_id: int, log_ns: int, sequence: int, data: bytes) -> None:
        """One message into the chunk in progress (log time = publish time = ``log_ns``)."""
        record = _MSG_HEADER.pack(_OP_MESSAGE, 22 + len(data), channel_id, sequence, log_ns,
                                  log_ns) + data
        self._index[channel_id].append((log_ns, self._size))
        self._parts.append(record)
        self._size += len(record)

    def append_block(self, block: bytes, index: dict[int, np.ndarray]) -> None:
        """Message records already serialised: ``index`` maps a channel id to the (n, 2)
        array of (log time, offset in ``block``) of its messages. Callers hold signals
        (see RunLog.flush)."""
        base = self._size
        for cid, entries in index.items():
            if len(entries):
                if base:
                    entries = entries + np.array([0, base], dtype=entries.dtype)
                self._blocks[cid].append(entries)
        self._parts.append(block)
        self._size += len(block)

    def chunk_bytes(self) -> int:
        return self._size

    def close_chunk(self) -> None:
        """Compress and write the chunk in progress with its message indexes; flush."""
        with _signals_deferred():
            self._close_chunk()

    def _entries(self, cid: int, n: int) -> np.ndarray | None:
        """The chunk's (log time, offset) entries of channel ``cid``, in offset order, without
        any past the chunk's ``n`` bytes (a message interrupted before its bytes)."""
        parts = self._blocks[cid]
        if self._index[cid]:
            parts = [*parts, np.array(self._index[cid], dtype=np.int64).reshape(-1, 2)]
        if not parts:
            return None
        entries = parts[0] if len(parts) == 1 else np.concatenate(parts)
        if len(parts) > 1:
            entries = entries[np.argsort(entries[:, 1], kind="stable")]
        entries = entries[entries[:, 1] < n]
        return entries if len(entries) else None

    def _close_chunk(self) -> None:
        parts = self._parts
        data = parts[0] if len(parts) == 1 else b"".join(parts)  # no copy of a lone block
        n = len(data)
        indexes = {}
        for cid in self._index:
            entries = self._entries(cid, n)
            if entries is not None:
                indexes[cid] = entries
            self._index[cid].clear()
            self._blocks[cid].clear()
        self._parts = []
        self._size = 0
        if not indexes:
            return
        start = int(min(e[:, 0].min() for e in indexes.values()))
        end = int(max(e[:, 0].max() for e in indexes.values()))
        for cid, entries in indexes.items():
            self._counts[cid] += len(entries)
            self._n_messages += len(entries)
        self._start_ns = start if self._start_ns is None else min(self._start_ns, start)
        self._end_ns = max(self._end_ns, end)
        # the message indexes do not depend on where the chunk lands: serialised here
        index_records = [(cid, _message_index(cid, entries)) for cid, entries in indexes.items()]
        self._write_chunk(data, index_records, start, end)

    def _write_chunk(self, data, index_records: list[tuple[int, bytes]], start: int,
                     end: int) -> None:
        """Compress ``data`` and write it as a Chunk record (opcode 0x06) followed by its
        Message Index records, and hand it to the operating system."""
        n = len(data)
        compressed = self._compress(data)
        crc = zlib.crc32(data)
        name = COMPRESSION.encode()
        body = struct.pack(f"<QQQII{len(name)}sQ", start, end, n, crc, len(name), name,
                           len(compressed))
        header = struct.pack("<BQ", _OP_CHUNK, len(body) + len(compressed)) + body
        chunk_length = len(header) + len(compressed)
        chunk_start = self._offset
        offsets, at = {}, chunk_start + chunk_length
        for cid, record in index_records:
            offsets[cid] = at
            at += len(record)
        self._chunk_indexes.append(ChunkIndex(
            message_start_time=start, message_end_time=end, chunk_start_offset=chunk_start,
            chunk_length=chunk_length, message_index_offsets=offsets,
            message_index_length=at - chunk_start - chunk_length, compression=COMPRESSION,
            compressed_size=len(compressed), uncompressed_size=n))
        self._write(b"".join([header, compressed, *(r for _, r in index_records)]))
        self._stream.flush()

    def finish(self) -> None:
        """Close the last chunk, write the summary and the footer, flush."""
        if self.finished:
            return
        with _signals_deferred():
            self._close_chunk()
            self._write(_record_bytes(DataEnd(data_section_crc=self._crc)))
            summary_start = self._offset
            summary = bytearray()
            groups = []

            def group(opcode: int, records) -> None:
                start = len(summary)
                for r in records:
                    summary.extend(_record_bytes(r))
                if len(summary) > start:
                    groups.append(SummaryOffset(group_opcode=opcode,
                                                group_start=summary_start + start,
                                                group_length=len(summary) - start))

            group(_OP_SCHEMA, self._schemas)
            group(_OP_CHANNEL, self._channels)
            group(_OP_STATISTICS, [Statistics(
                message_count=self._n_messages, schema_count=len(self._schemas),
                channel_count=len(self._channels), attachment_count=0,
                metadata_count=len(self._metadata_indexes),
                chunk_count=len(self._chunk_indexes),
                message_start_time=self._start_ns or 0, message_end_time=self._end_ns,
                channel_message_counts=dict(self._counts))])
            group(_OP_CHUNK_INDEX, self._chunk_indexes)
            group(_OP_METADATA_INDEX, self._metadata_indexes)
            summary_offset_start = summary_start + len(summary)
            for g in groups:
                summary.extend(_record_bytes(g))
            footer_prefix = struct.pack("<BQQQ", 0x02, 20, summary_start, summary_offset_start)
            crc = zlib.crc32(footer_prefix, zlib.crc32(summary))
            self._write(bytes(summary) + footer_prefix + struct.pack("<I", crc) + MAGIC)
            self._stream.flush()
            self.finished = True


# Look-up tables of the vectorised formatting: the characters of 0000 … 9999 as one 4-byte
# word each, of 00 … 99 as one 2-byte word; powers of ten 1e-400 … 1e400 (0 and inf beyond).
_CHARS4 = np.frombuffer(b"".join(b"%04d" % i for i in range(10000)), dtype="<u4")
_CHARS2 = np.frombuffer(b"".join(b"%02d" % i for i in range(100)), dtype="<u2")
with np.errstate(all="ignore"):
    _POW10 = 10.0 ** np.arange(-400, 401)
_P0 = 400  # index of 1e0 in _POW10
# "% .8e" text: sign, lead digit, '.', 8 digits (two words of 4), 'e', exponent sign, 2 digits
_E15 = np.dtype({"names": ["sign", "lead", "dot", "upper", "lower", "e", "esign", "exp"],
                 "formats": ["u1", "u1", "u1", "<u4", "<u4", "u1", "u1", "<u2"],
                 "offsets": [0, 1, 2, 3, 7, 11, 12, 13], "itemsize": 15})


def fixed_e(x: np.ndarray, out: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``x`` formatted as ``"% .8e" % x`` does, all at once: (characters, shape x.shape +
    (15,), uint8; True where the number fits that width, i.e. finite with |exponent| < 100).
    ``out``: a work array of at least ``x.size`` elements of dtype ``_E15`` to write into
    (reused from chunk to chunk, so its memory is not faulted in anew each time).

    The mantissa is rounded from x × 10^(8−e) in binary floating point: the 9th significant
    digit can differ from correct rounding only when x lies within a few 1e-16 (relative) of
    a half-way point, an error far below the format's own resolution of 5e-9.
    """
    shape = x.shape
    x = np.ravel(x)
    a = np.abs(x)
    with np.errstate(all="ignore"):
        finite = np.isfinite(a)
        a = np.where(finite, a, 0.0)
        _, b = np.frexp(a)  # a = f × 2^b, f in [0.5, 1): 10^e ≤ a < 10^(e+1) for e below
        e = ((b.astype(np.int64) - 1) * 78913) >> 18  # ⌊(b − 1) log10 2⌋ (or one less)
        # (no clip needed: e in [-324, 308] keeps both _POW10 indices below in range)
        e += a >= _POW10[e + (_P0 + 1)]
        m = np.rint(a * _POW10[(_P0 + 8) - e])
        nonzero = a > 0
        for _ in range(2):  # 10^k is inexact beyond 1e22; rounding may carry to 1e9
            hi = m >= 1e9
            lo = nonzero & (m < 1e8)
            if not (hi.any() or lo.any()):
                break
            fix = hi | lo
            e[fix] += hi[fix].astype(np.int64) - lo[fix]
            m[fix] = np.rint(a[fix] * _POW10[(_P0 + 8) - e[fix]])
    ok = finite & (np.abs(e) < 100) & (m < 1e9) & (~nonzero | (m >= 1e8))
    if not ok.all():
        m[~ok] = 0
        e[~ok] = 0
    e[~nonzero] = 0
    m = m.astype(np.int32)  # < 1e9
    lead, rest = np.divmod(m, np.int32(100_000_000))
    upper, lower = np.divmod(rest, np.int32(10_000))
    out = np.empty(len(x), dtype=_E15) if out is None else out[:len(x)]
    out["sign"] = np.signbit(x).view(np.uint8) * np.uint8(13) + np.uint8(32)  # '-' or ' '
    out["lead"] = lead + 48
    out["dot"] = 46  # '.'
    out["upper"] = _CHARS4[upper]
    out["lower"] = _CHARS4[lower]
    out["e"] = 101  # 'e'
    out["esign"] = (e < 0).view(np.uint8) * np.uint8(2) + np.uint8(43)  # '-' or '+'
    out["exp"] = _CHARS2[np.abs(e)]
    return out.view(np.uint8).reshape(shape + (15,)), ok.reshape(shape)


_DIGITS10 = 10 ** np.arange(9, -1, -1, dtype=np.int64)  # place values of a 10-digit integer
_SPACES4 = np.frombuffer(b"    ", dtype="<u4")[0]


def fixed_d(n: np.ndarray) -> np.ndarray:
    """Non-negative integers (< 1e10) formatted as ``"%10d" % n`` does: shape n.shape + (10,).

    Three table look-ups per number (digits 2 + 4 + 4, :data:`_CHARS4`), then the leading
    zeros become spaces.
    """
    shape = n.shape
    n = np.ravel(n).astype(np.int64)
    top, rest = np.divmod(n, 100_000_000)
    mid, low = np.divmod(rest, 10_000)
    out = np.empty((len(n), 3), dtype="<u4")  # characters 0-3 (2 used), 2-5, 6-9 of "%010d"
    out[:, 0] = _CHARS4[top]
    out[:, 1] = _CHARS4[mid]
    out[:, 2] = _CHARS4[low]
    chars = out.view(np.uint8)[:, 2:]  # drop the two leading digits of the top group (0)
    # the number of leading zeros: 10 − digits (a zero has one digit)
    lead = 10 - np.maximum(np.searchsorted(_DIGITS10[::-1], n, side="right"), 1)
    chars = chars - (np.arange(10) < lead[:, None]).view(np.uint8) * np.uint8(16)  # '0' → ' '
    return chars.reshape(shape + (10,))


class _ModelChannels:
    """Channel ids and the fixed-width byte layout of one step of one wing model.

    A step is seven message records (rigid_body … location) back to back; with every number
    in fixed width (floats ``% .8e``, 15 characters; the integer seconds and nanoseconds
    ``%10d``) each record has a fixed length, so a chunk's steps are one (steps × bytes)
    array: the layout with the numbers' characters written into their columns.
    """

    def __init__(self, log: RunLog, model: str, names) -> None:
        self.names = tuple(names)
        col = {name: i for i, name in enumerate(self.names)}
        n = sum(1 for k in self.names if k.startswith("eta") and not k.endswith("_dot"))
        self.ids = {g: log._channel_id(model, g) for g in GROUPS if g != "lti_prediction"}
        self.seq = 0
        optional = [f for f, _ in _RIGID_OPTIONAL if f in col]
        rigid_keys = [k for _, k, _ in _RIGID_FIELDS] + optional
        modal_keys = [f"eta{i + 1}" for i in range(n)] + [f"eta{i + 1}_dot" for i in range(n)]
        # the raw columns copied as they are, in message order
        self.copy_cols = np.array([col[k] for k in (
            *rigid_keys, *modal_keys, "lift_n", "drag_n", "pitch_moment_n_m", "w_g",
            "elevator_rad", "throttle")], dtype=np.intp)
        self.i_lat, self.i_lon = col["latitude_rad"], col["longitude_rad"]
        self.i_alt = col["altitude_m"]
        self.i_att = [col["phi_rad"], col["theta_rad"], col["psi_rad"]]
        rigid_fields = [f for f, _, _ in _RIGID_FIELDS] + optional
        eta = ",".join(["%s"] * n)
        frame = body_frame(model)
        # JSON templates, "%s" for each number (pose and location: sec and nsec first)
        templates_s = {
            "rigid_body": "{" + ",".join(f'"{f}":%s' for f in rigid_fields) + "}",
            "modal": f'{{"eta_rad":[{eta}],"eta_dot_rad_s":[{eta}]}}',
            "modal_loads": '{"lift_n":%s,"drag_n":%s,"pitch_moment_n_m":%s}',
            "gust": '{"w_g_m_s":%s}',
            "controls": '{"elevator_rad":%s,"throttle":%s}',
            "pose": '{"timestamp":{"sec":%s,"nsec":%s},"parent_frame_id":"' + WORLD_FRAME
            + '","child_frame_id":"' + frame + '","translation":{"x":%s,"y":%s,"z":%s},'
            '"rotation":{"x":%s,"y":%s,"z":%s,"w":%s}}',
            "location": '{"timestamp":{"sec":%s,"nsec":%s},"frame_id":"' + frame
            + '","latitude":%s,"longitude":%s,"altitude":%s,'
            '"position_covariance":[0,0,0,0,0,0,0,0,0],"position_covariance_type":0}',
        }
        order = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location")
        self.id_list = [self.ids[g] for g in order]
        self.templates_s = [templates_s[g] for g in order]
        self.n_ints = [2 if g in ("pose", "location") else 0 for g in order]
        self.n_floats = [t.count("%s") - k for t, k in zip(self.templates_s, self.n_ints,
                                                           strict=True)]
        layout = bytearray()
        float_at, int_at, head_at, self.offsets = [], [], [], []
        for cid, tpl, n_int in zip(self.id_list, self.templates_s, self.n_ints, strict=True):
            pieces = tpl.encode().split(b"%s")
            size = sum(map(len, pieces)) + 10 * n_int + 15 * (len(pieces) - 1 - n_int)
            self.offsets.append(len(layout))
            layout += struct.pack("<BQH", _OP_MESSAGE, 22 + size, cid)
            head_at.append(len(layout))
            layout += bytes(20)  # sequence, log time, publish time
            for i, piece in enumerate(pieces):
                layout += piece
                if i < len(pieces) - 1:
                    at = int_at if i < n_int else float_at
                    width = 10 if i < n_int else 15
                    at.append(len(layout))
                    layout += b" " * width
        self.layout = np.frombuffer(bytes(layout), dtype=np.uint8)
        self.step_size = len(layout)
        self.float_at, self.int_at, self.head_at = float_at, int_at, head_at
        self.offsets = np.array(self.offsets, dtype=np.int64)
        # where the characters go: one structured copy per kind writes every column of a
        # chunk at once (fields at the layout's columns ← fields of the packed source)
        def fields(at, width, packed_offsets, packed_size):
            names = [f"f{j}" for j in range(len(at))]
            return (np.dtype({"names": names, "formats": [f"V{width}"] * len(at),
                              "offsets": list(at), "itemsize": self.step_size}),
                    np.dtype({"names": names, "formats": [f"V{width}"] * len(at),
                              "offsets": packed_offsets, "itemsize": packed_size}))

        nf, ni = len(float_at), len(int_at)
        self._float_dst, self._float_src = fields(float_at, 15, [15 * j for j in range(nf)],
                                                  15 * nf)
        self._int_dst, self._int_src = fields(int_at, 10, [10 * j for j in range(ni)], 10 * ni)
        # every record of a step has the same header tail (sequence, log and publish time)
        self._head_dst, self._head_src = fields(head_at, 20, [0] * len(head_at), 20)
        empty = np.empty((0, self.step_size), dtype=np.uint8)
        self._space = (empty, None)

    def floats(self, v: np.ndarray, origin) -> np.ndarray:
        """The float fields of each step (rows of the raw values ``v``), in record order."""
        lat0, lon0, h0, r_north, r_east = origin
        lat, lon, h = v[:, self.i_lat], v[:, self.i_lon], v[:, self.i_alt]
        qx, qy, qz, qw = enu_quaternion(*(v[:, i] for i in self.i_att))
        return np.column_stack([
            v[:, self.copy_cols], (lon - lon0) * r_east, (lat - lat0) * r_north, h - h0,
            qx, qy, qz, qw, np.degrees(lat), np.degrees(lon), h])

    def general_step(self, head: bytes, floats, ints) -> bytes:
        """The seven records of a step in variable width; non-finite numbers become null."""
        parts, kf, ki = [], 0, 0
        for cid, tpl, nf, ni in zip(self.id_list, self.templates_s, self.n_floats,
                                    self.n_ints, strict=True):
            nums = [*ints[ki:ki + ni], *(_json_number(x) for x in floats[kf:kf + nf])]
            kf += nf
            ki += ni
            data = (tpl % tuple(nums)).encode()
            parts.append(struct.pack("<BQH", _OP_MESSAGE, 22 + len(data), cid) + head + data)
        return b"".join(parts)

    def _workspace(self, n: int) -> tuple[np.ndarray, np.ndarray]:
        """The (steps × bytes) layout array and the fixed_e work array for ``n`` steps,
        kept from chunk to chunk: the layout's constant characters stay in place and no
        fresh memory is faulted in at every chunk. (A chunk's block is compressed before the
        next chunk is formatted: RunLog closes the chunk right after formatting it.)"""
        out, work = self._space
        if len(out) < n:
            size = max(n, 2 * len(out), 256)
            out = np.empty((size, self.step_size), dtype=np.uint8)
            out[:] = self.layout
            work = np.empty(size * len(self.float_at), dtype=_E15)
            self._space = (out, work)
        return out[:n], work

    def format(self, t_s, v: np.ndarray, seq0: int, origin) -> tuple[memoryview,
                                                                    dict[int, np.ndarray]]:
        """The message records of the steps ``v`` (steps × channels in :attr:`names` order)
        at times ``t_s`` [s] and their index entries ((log time, offset) per channel).

        Vectorised: every number of the chunk is formatted by :func:`fixed_e` at once and
        written into the step layout; a step with a number that does not fit (NaN,
        infinity, |exponent| ≥ 100) is written by :meth:`general_step` instead. The block
        returned may be a view of a work array that the next chunk reuses.
        """
        n = len(v)
        ns = np.rint(np.asarray(t_s, dtype=float) * 1e9).astype(np.int64)
        f = self.floats(v, origin)
        out, work = self._workspace(n)
        chars, ok = fixed_e(f, work)  # (step, field, character)
        sec, nsec = np.divmod(ns, 1_000_000_000)
        int_chars = fixed_d(np.column_stack([sec, nsec, sec, nsec]))  # pose, location
        head = np.empty((n, 20), dtype=np.uint8)
        head[:, :4] = (seq0 + np.arange(n)).astype("<u4").view(np.uint8).reshape(n, 4)
        head[:, 4:12] = ns.astype("<u8").view(np.uint8).reshape(n, 8)
        head[:, 12:] = head[:, 4:12]
        out.view(self._float_dst)[:, 0] = chars.reshape(n, -1).view(self._float_src)[:, 0]
        out.view(self._int_dst)[:, 0] = (np.ascontiguousarray(int_chars).reshape(n, -1)
                                         .view(self._int_src)[:, 0])
        out.view(self._head_dst)[:, 0] = head.view(self._head_src)[:, 0]
        good = ok.all(axis=1)
        if good.all():
            block = memoryview(out).cast("B")
            starts = np.arange(n, dtype=np.int64) * self.step_size
        else:  # variable-width steps among the fixed ones
            parts, starts, offset = [], [], 0
            for i in range(n):
                b = (out[i].tobytes() if good[i] else
                     self.general_step(head[i].tobytes(), f[i].tolist(),
                                       [sec[i], nsec[i], sec[i], nsec[i]]))
                parts.append(b)
                starts.append(offset)
                offset += len(b)
            block = memoryview(b"".join(parts))
            starts = np.array(starts, dtype=np.int64)
        index = {}
        for j, cid in enumerate(self.id_list):
            if good.all():
                offs = starts + self.offsets[j]
            else:  # record j's offset within each step, from the record lengths
                offs = np.array([_record_offset(block, s, j) for s in starts], dtype=np.int64)
            index[cid] = np.column_stack([ns, offs])
        return block, index


def _record_offset(block: bytes, start: int, j: int) -> int:
    """The offset of the ``j``-th record of the step at ``start`` in ``block``."""
    for _ in range(j):
        start += 9 + struct.unpack_from("<Q", block, start + 1)[0]
    return start


def enu_quaternion(roll_rad, pitch_rad, yaw_rad) -> tuple:
    """(x, y, z, w) of the FLU body frame in the ENU world frame from NED Euler angles
    (numbers or arrays).

    NED/FRD Euler angles (φ right wing down, θ nose up, ψ clockwise from north) become the
    ENU/FLU angles roll φ, pitch −θ, yaw π/2 − ψ; the quaternion is their Z-Y-X product.
    """
    hr = 0.5 * np.asarray(roll_rad, dtype=float)
    hp = -0.5 * np.asarray(pitch_rad, dtype=float)
    hy = 0.5 * (0.5 * math.pi - np.asarray(yaw_rad, dtype=float))
    cr, sr = np.cos(hr), np.sin(hr)
    cp, sp = np.cos(hp), np.sin(hp)
    cy, sy = np.cos(hy), np.sin(hy)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def _json_number(v) -> str:
    """A number as JSON text (as NUMBER formats it), null if not finite."""
    v = float(v)
    return NUMBER % v if math.isfinite(v) else "null"


class RunLog:
    """An open MCAP file that runs write their samples into (see the module docstring)."""

    def __init__(self, path: Path, stream, writer: McapFileWriter) -> None:
        self.path = path
        self._stream = stream
        self._writer = writer
        self._schema_ids: dict[str, int] = {}
        self._models: dict[str, _ModelChannels] = {}
        self._origin: tuple[float, float, float, float, float] | None = None
        # the steps of the chunk in progress: one model's, times [s] and value tuples
        self._ts: list[float] = []
        self._rows: list[tuple] = []
        self._pending: _ModelChannels | None = None
        self._first_t = 0.0
        self._due_t = -math.inf  # the chunk closes at this simulated time …
        self._due_wall = 0.0  # … or at this wall (monotonic) time
        self.closed = False

    @classmethod
    def open(cls, path: str | Path, command: str, args, build) -> RunLog:
        """Create ``path`` and write the run metadata of ``command`` run with ``args``."""
        p = Path(path)
        try:
            stream = open(p, "wb")  # noqa: SIM115 - closed in close()
        except OSError as exc:
            from bioflex_jsb.cli.common import UsageError

            raise UsageError(f"cannot write log {str(p)!r}: {exc.strerror}") from None
        return cls.local(p, stream, run_metadata(command, args, build))

    @classmethod
    def local(cls, path: Path, stream, meta: dict[str, str]) -> RunLog:
        writer = McapFileWriter(stream, library=f"bioflex-jsb {__version__}")
        log = cls(path, stream, writer)
        writer.add_metadata(RUN_METADATA, meta)
        return log

    # -- channels -----------------------------------------------------------------------
    def _channel_id(self, model: str, group: str) -> int:
        if group not in self._schema_ids:
            schema = SCHEMAS[group]
            self._schema_ids[group] = self._writer.add_schema(schema["title"], schema)
        return self._writer.add_channel(topic(model, group), self._schema_ids[group],
                                        {"model": model})

    def _model(self, model: str, names) -> _ModelChannels:
        ch = self._models.get(model)
        if ch is None:
            ch = self._models[model] = _ModelChannels(self, model, names)
        elif ch.names != tuple(names):
            raise ValueError(f"the {model} samples changed their channels")
        return ch

    def _set_origin(self, lat0: float, lon0: float, h0: float) -> None:
        s2 = math.sin(lat0) ** 2
        n_m = _WGS84_A_M / math.sqrt(1.0 - _WGS84_E2 * s2)  # prime vertical radius
        m_m = n_m * (1.0 - _WGS84_E2) / (1.0 - _WGS84_E2 * s2)  # meridian radius
        self._origin = (lat0, lon0, h0, (m_m + h0), (n_m + h0) * math.cos(lat0))
        self._writer.add_metadata(FRAME_METADATA, {
            "frame": WORLD_FRAME, "axes": "x east, y north, z up [m]",
            "origin_latitude_rad": repr(lat0), "origin_longitude_rad": repr(lon0),
            "origin_altitude_m": repr(h0),
            "projection": "local tangent plane on WGS-84 at the origin (flat Earth)",
        })

    # -- writing --------------------------------------------------------------------------
    def recorder(self, model: str) -> TableRecorder:
        """A recorder of the run of ``model`` for ``cosim.run_gust(..., recorder=)``: it logs
        every step (seven messages, one per run topic) from the run's own table, a chunk at
        a time, so a step costs the run one call and a comparison."""
        return TableRecorder(self, model)

    def sample(self, model: str, t_s: float, row: dict[str, float]) -> None:
        """Log one step given as a dict of channel values (a loop without a table, such as
        the SITL loop; a run of ``run_gust`` is logged faster by :meth:`recorder`). The
        steps are kept and formatted a chunk at a time; the chunk closes every CHUNK_SPAN_S
        of simulated time or CHUNK_WALL_S of wall time."""
        ch = self._models.get(model)
        if ch is None:
            ch = self._model(model, tuple(row))
        if (self._pending is not ch or not self._first_t <= t_s < self._due_t
                or time.monotonic() >= self._due_wall or len(self._rows) >= _MAX_PENDING_STEPS):
            self._next_chunk(ch, t_s)
        self._ts.append(t_s)
        self._rows.append(tuple([row[k] for k in ch.names]))

    def _next_chunk(self, ch: _ModelChannels, t_s: float) -> None:
        """Close the chunk in progress (if any) and start one for ``ch`` at ``t_s``."""
        if self._rows:
            self.flush()
        self._pending = ch
        self._first_t = t_s
        # closes at the first step ≥ CHUNK_SPAN_S later (as in ns; a step's time is
        # rounded to ns), or after _MAX_PENDING_STEPS steps, or CHUNK_WALL_S of wall time
        self._due_t = t_s + CHUNK_SPAN_S - 0.5e-9
        self._due_wall = time.monotonic() + CHUNK_WALL_S

    def _format_pending(self) -> None:
        """Serialise the kept steps into the chunk in progress (see _ModelChannels.format)."""
        ch, rows, ts = self._pending, self._rows, self._ts
        n = len(rows)  # an interrupt between the two appends leaves one time more
        if ch is None or not n:
            rows.clear()
            ts.clear()
            return
        if self._origin is None:
            first = rows[0]
            self._set_origin(first[ch.i_lat], first[ch.i_lon], first[ch.i_alt])
        v = np.fromiter(chain.from_iterable(rows), dtype=float, count=n * len(ch.names))
        block, index = ch.format(ts[:n], v.reshape(n, len(ch.names)), ch.seq, self._origin)
        ch.seq += n
        rows.clear()
        ts.clear()
        self._writer.append_block(block, index)

    def prediction(self, model: str, history) -> None:
        """Log the LTI prediction ``history`` (a ``TimeHistory`` of the linear model of
        ``model``) on ``/bioflex/<model>/lti_prediction``, one message per sample."""
        cid = self._channel_id(model, "lti_prediction")
        etas = sorted((k for k in history.channels if k.startswith("eta") and k[3:].isdigit()),
                      key=lambda k: int(k[3:]))
        zeros = [0.0] * len(history.time_s)

        def col(name):
            return history.channels[name] if name in history.channels else zeros

        cols = [col(c) for c in ("u", "alpha", "q", "theta", "n_z")]
        eta_cols = [history.channels[k] for k in etas]
        w = self._writer
        for k, t in enumerate(history.time_s):
            t_s = float(t)
            payload = {}
            for name, c in zip(("du_m_s", "dalpha_rad", "q_rad_s", "dtheta_rad", "n_z"), cols,
                               strict=True):
                payload[name] = _finite_or_none(float(c[k]))
            payload["eta_rad"] = [_finite_or_none(float(c[k])) for c in eta_cols]
            ns = int(round(t_s * 1e9))
            w.append(cid, ns, k, json.dumps(payload).encode())
            if w.chunk_bytes() >= CHUNK_MAX_BYTES:
                w.close_chunk()
        w.close_chunk()

    def flush(self) -> None:
        """Write the kept steps as a chunk and hand it to the operating system."""
        with _signals_deferred():
            self._format_pending()
            self._writer.close_chunk()
        self._pending = None

    def close(self) -> None:
        """Finish the file (summary, indexes, footer) and close it; safe to call twice."""
        if not self.closed:
            try:
                self.flush()
                self._writer.finish()
            finally:
                self._stream.close()
                self.closed = True


_MAX_PENDING_STEPS = 4096  # also bounds the chunk size (~1.2 kB per step)
_WALL_CHECK_MASK = 63  # a recorder looks at the wall clock every 64 steps


class TableRecorder:
    """Logs a run's steps from the table the run fills (``cosim.StepRecorder``).

    The steps of a chunk are rows [k0, k_end) of the table, k_end the first step at least
    CHUNK_SPAN_S after step k0 (as the chunks of :meth:`RunLog.sample`), at most
    _MAX_PENDING_STEPS rows; the chunk is written as soon as its last row is complete, or
    when CHUNK_WALL_S of wall time have passed since it began (checked every 64 steps).
    Writing a chunk holds SIGINT/SIGTERM, so an interrupt never logs a row twice or not at
    all; :meth:`stop` writes the rows left.
    """

    def __init__(self, log: RunLog, model: str) -> None:
        self._log = log
        self._model = model
        self._ch: _ModelChannels | None = None
        self._time_s = self._table = None
        self._k0 = 0
        self._last_k = -1
        self._due_wall = math.inf

    def start(self, names, time_s: np.ndarray, table: np.ndarray) -> None:
        log = self._log
        log.flush()  # steps kept for another model go first
        self._ch = log._model(self._model, names)
        self._time_s, self._table = time_s, table
        self._begin(0)

    def _begin(self, k0: int) -> None:
        t = self._time_s
        self._k0 = k0
        if k0 >= len(t):
            self._last_k = len(t)
            return
        k_end = int(np.searchsorted(t, t[k0] + CHUNK_SPAN_S - 0.5e-9, side="left"))
        self._last_k = min(max(k_end, k0 + 1), k0 + _MAX_PENDING_STEPS, len(t)) - 1
        self._due_wall = time.monotonic() + CHUNK_WALL_S

    def step(self, k: int) -> None:
        if k >= self._last_k or (not k & _WALL_CHECK_MASK
                                 and time.monotonic() >= self._due_wall):
            self._write(k + 1)

    def stop(self, n: int) -> None:
        if self._ch is not None and n > self._k0:
            self._write(n)

    def _write(self, n: int) -> None:
        """Write rows [k0, n) as a chunk and begin the next at n."""
        log, ch, k0 = self._log, self._ch, self._k0
        with _signals_deferred():
            rows = self._table[k0:n]
            if log._origin is None:
                log._set_origin(*rows[0, [ch.i_lat, ch.i_lon, ch.i_alt]].tolist())
            block, index = ch.format(self._time_s[k0:n], rows, ch.seq, log._origin)
            ch.seq += n - k0
            log._writer.append_block(block, index)
            log._writer.close_chunk()
            self._begin(n)


def _finite_or_none(v: float):
    return v if math.isfinite(v) else None


def run_metadata(command: str, args, build) -> dict[str, str]:
    """The ``bioflex.run`` metadata record: everything needed to repeat the run."""
    arguments = {k: (v.text() if hasattr(v, "text") else v)
                 for k, v in vars(args).items() if k != "run"}
    gust = getattr(args, "gust", None)
    meta = {
        "command": command,
        "arguments": json.dumps(arguments, default=str),
        "argv": (json.dumps(rerun_argv(command, arguments))
                 if command in REPEATABLE_COMMANDS else ""),
        "wing": build.variant.name,
        "wing_variant": json.dumps(build.variant.as_dict(), default=str),
        "overrides": json.dumps(dict(build.model.coefficients.overrides), default=str),
        "mass_basis": build.mass_basis,
        "speed_m_s": repr(getattr(args, "speed", None)),
        "gust": gust.text() if gust is not None else "",
        "gust_seed": str(getattr(gust, "seed", "")),
        "models": ",".join(getattr(args, "models", None)
                           or ((args.model,) if hasattr(args, "model") else ())),
        "dt_s": repr(getattr(args, "dt", None)),
        "time_base": "log and publish times are simulation time [ns from the run start]",
        "bioflex_jsb_version": __version__,
        "jsbsim_version": _version("jsbsim"),
        "mcap_version": _version("mcap"),
        "python": platform.python_version(),
    }
    return meta


REPEATABLE_COMMANDS = ("gust", "sweep", "compare")


def rerun_argv(command: str, arguments: dict) -> list[str]:
    """The ``bioflex-jsb`` argument list (without --out/--plot/--json) of a logged run:
    a ``gust`` run, a ``sweep`` case (repeated as the gust run it is) or a ``compare``."""
    if command not in REPEATABLE_COMMANDS:
        raise ValueError(f"only gust runs, sweep cases and comparisons can be repeated; this "
                         f"log was written by {command!r} (a SITL session follows the wall "
                         "clock and its ground station)")
    common = ["--wing", str(arguments["wing"]),
              "--mass-basis", str(arguments["mass_basis"]),
              "--speed", repr(float(arguments["speed"])),
              "--gust", str(arguments["gust"]),
              "--duration", repr(float(arguments["duration"])),
              "--gust-start", repr(float(arguments["gust_start"])),
              "--dt", repr(float(arguments["dt"]))]
    if command == "compare":
        return ["compare", *common, "--model", str(arguments["model"])]
    return ["gust", *common, "--models", ",".join(arguments["models"])]


# ---------------------------------------------------------------------------- reading


class LogError(Exception):
    """A file that is not a readable, finished MCAP log (one line, for the user)."""


def check_file(path: str | Path) -> Path:
    """``path`` as a Path if it is an existing file starting with the MCAP magic."""
    p = Path(path)
    if not p.exists():
        raise LogError(f"{str(p)!r}: no such file")
    if not p.is_file():
        raise LogError(f"{str(p)!r} is not a file")
    with open(p, "rb") as f:
        head = f.read(len(MAGIC))
    if head != MAGIC:
        raise LogError(f"{str(p)!r} is not an MCAP file (no MCAP magic at the start)")
    return p


def _truncated(p: Path) -> LogError:
    return LogError(
        f"{str(p)!r} is truncated (the writer was killed before finishing it); recover the "
        f"complete chunks with: bioflex-jsb info {str(p)!r} --recover FIXED.mcap"
    )


@contextmanager
def open_reader(path: str | Path):
    """An indexed ``mcap`` reader of a finished log, with its summary; LogError otherwise."""
    from mcap.reader import make_reader

    p = check_file(path)
    with open(p, "rb") as f:
        f.seek(0, 2)
        size = f.tell()
        if size < 2 * len(MAGIC) + 29:
            raise _truncated(p)
        f.seek(size - len(MAGIC))
        if f.read(len(MAGIC)) != MAGIC:
            raise _truncated(p)
        f.seek(0)
        try:
            reader = make_reader(f)
            summary = reader.get_summary()
        except Exception as exc:  # the mcap package raises several types on bad files
            raise LogError(f"{str(p)!r}: unreadable MCAP summary ({exc})") from None
        if summary is None:
            raise _truncated(p)
        yield reader, summary


def read_metadata(reader) -> dict[str, dict[str, str]]:
    try:
        return {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    except Exception as exc:
        raise LogError(f"unreadable metadata ({exc})") from None


def iter_json(reader, topics: list[str] | None = None) -> Iterator[tuple[str, int, dict]]:
    """(topic, log time [ns], decoded JSON) of every message, in log-time order."""
    try:
        for _schema, channel, message in reader.iter_messages(topics=topics,
                                                              log_time_order=True):
            yield channel.topic, message.log_time, json.loads(message.data)
    except LogError:
        raise
    except Exception as exc:
        raise LogError(f"unreadable message data ({exc})") from None


def summarise(path: str | Path) -> dict:
    """Channels (topic, schema, count), duration, chunks and metadata of a finished log."""
    with open_reader(path) as (reader, summary):
        stats = summary.statistics
        counts = dict(stats.channel_message_counts) if stats else {}
        channels = []
        for cid, ch in sorted(summary.channels.items()):
            schema = summary.schemas.get(ch.schema_id)
            channels.append({"topic": ch.topic, "schema": schema.name if schema else "",
                             "encoding": ch.message_encoding, "messages": counts.get(cid, 0)})
        start = stats.message_start_time if stats else 0
        end = stats.message_end_time if stats else 0
        meta = read_metadata(reader)
        return {
            "file": str(path),
            "library": reader.get_header().library,
            "channels": channels,
            "messages": stats.message_count if stats else sum(counts.values()),
            "chunks": len(summary.chunk_indexes),
            "start_s": start * 1e-9,
            "end_s": end * 1e-9,
            "duration_s": (end - start) * 1e-9,
            "metadata": meta,
        }


def histories(path: str | Path) -> tuple[list, dict[str, str]]:
    """The runs of a log rebuilt as TimeHistory objects (JSBSim runs, then LTI predictions),
    and its ``bioflex.run`` metadata."""
    import numpy as np

    from bioflex_jsb.simulation.results import TimeHistory

    with open_reader(path) as (reader, summary):
        meta = read_metadata(reader).get(RUN_METADATA, {})
        wanted = [ch.topic for ch in summary.channels.values()
                  if ch.topic.rsplit("/", 1)[-1] in ("rigid_body", "modal", "gust",
                                                      "lti_prediction")]
        cols: dict[tuple[str, str], dict[str, list]] = {}
        for top, ns, msg in iter_json(reader, wanted):
            _, _, model, group = top.split("/", 3)
            key = (model, "lti" if group == "lti_prediction" else "run")
            d = cols.setdefault(key, {})
            if group == "rigid_body" or group == "lti_prediction":
                d.setdefault("time_s", []).append(ns * 1e-9)
                for name, field in (("u", "du_m_s"), ("alpha", "dalpha_rad"), ("q", "q_rad_s"),
                                    ("theta", "dtheta_rad"), ("n_z", "n_z")):
                    d.setdefault(name, []).append(msg.get(field))
                if group == "lti_prediction":
                    for i, v in enumerate(msg.get("eta_rad") or []):
                        d.setdefault(f"eta{i + 1}", []).append(v)
            elif group == "modal":
                for i, v in enumerate(msg["eta_rad"]):
                    d.setdefault(f"eta{i + 1}", []).append(v)
            elif group == "gust":
                d.setdefault("w_g", []).append(msg["w_g_m_s"])
    units = {"u": "m/s", "alpha": "rad", "q": "rad/s", "theta": "rad", "n_z": "-",
             "w_g": "m/s"}
    runs = []
    for (model, kind), d in sorted(cols.items(), key=lambda kv: kv[0][1] == "lti"):
        t = np.asarray(d.pop("time_s", []), dtype=float)
        n = len(t)
        channels = {k: np.asarray([np.nan if x is None else x for x in v[:n]], dtype=float)
                    for k, v in d.items() if len(v) >= n}
        run = TimeHistory(model, t, channels,
                          {k: units.get(k, "rad") for k in channels}, {})
        if kind == "lti":
            run.meta.update(label=f"LTI {model}", linestyle="--")
        runs.append(run)
    return runs, meta


def messages_by_topic(path: str | Path) -> dict[str, list[tuple[int, dict]]]:
    """Every message of a finished log, per topic, in log-time order."""
    out: dict[str, list[tuple[int, dict]]] = {}
    with open_reader(path) as (reader, _summary):
        for top, ns, msg in iter_json(reader):
            out.setdefault(top, []).append((ns, msg))
    return out


def recover(path: str | Path, out: str | Path) -> dict:
    """Copy every complete record of a (killed) log into a finished, indexed file ``out``.

    Reads ``path`` sequentially with the ``mcap`` package's non-indexed stream reader
    (checking each chunk's CRC) and stops at the first incomplete or damaged record.
    Returns counts and the last log time kept [s].
    """
    from mcap.records import Channel as _Channel
    from mcap.records import Chunk as _Chunk
    from mcap.records import Message
    from mcap.records import Schema as _Schema
    from mcap.stream_reader import StreamReader, breakup_chunk
    from mcap.writer import CompressionType, Writer

    p = check_file(path)
    dst = Path(out)
    if dst.resolve() == p.resolve():
        raise LogError("--recover must name a new file, not the log itself")
    schemas: dict[int, int] = {}
    channels: dict[int, int] = {}
    n_messages, last_ns, stop = 0, None, "end of file"
    try:
        fout = open(dst, "wb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise LogError(f"cannot write {str(dst)!r}: {exc.strerror}") from None
    with open(p, "rb") as fin, fout:
        writer = Writer(fout, chunk_size=1024 * 1024, compression=CompressionType.ZSTD)
        writer.start(profile="", library=f"bioflex-jsb {__version__} (recovered)")

        def handle(record) -> None:
            nonlocal n_messages, last_ns
            if isinstance(record, _Schema):
                if record.id not in schemas:
                    schemas[record.id] = writer.register_schema(record.name, record.encoding,
                                                                record.data)
            elif isinstance(record, _Channel):
                if record.id not in channels:
                    channels[record.id] = writer.register_channel(
                        record.topic, record.message_encoding,
                        schemas.get(record.schema_id, 0), dict(record.metadata))
            elif isinstance(record, Message):
                writer.add_message(channels[record.channel_id], record.log_time, record.data,
                                   record.publish_time, record.sequence)
                n_messages += 1
                last_ns = record.log_time if last_ns is None else max(last_ns, record.log_time)
            elif isinstance(record, Metadata):
                writer.add_metadata(record.name, dict(record.metadata))

        records = StreamReader(fin, emit_chunks=True, validate_crcs=True).records
        try:
            for record in records:
                if isinstance(record, _Chunk):
                    inner = breakup_chunk(record, validate_crc=True)  # whole chunk or nothing
                    for r in inner:
                        handle(r)
                else:
                    handle(record)
        except Exception as exc:  # truncated or damaged tail: keep what came before
            stop = f"{type(exc).__name__} {exc}".strip()
        writer.finish()
    return {"file": str(p), "out": str(dst), "messages": n_messages,
            "channels": len(channels),
            "last_time_s": None if last_ns is None else last_ns * 1e-9, "stopped_at": stop}

