"""The MCAP file writer: chunked, indexed, many small messages per step.

The header (and whatever the caller writes before the first chunk: metadata, schemas,
channels) is handed to the operating system when the writer is created and by
:meth:`McapFileWriter.flush`, so a process killed before its first step leaves a file that
:func:`~bioflex_jsb.sinks.mcap_io.recover.recover` turns into a finished, empty log.

Every record other than the messages in a chunk is serialised with the ``mcap`` package's
record classes; the messages themselves are written here (the package's ``Writer`` costs
~6.5 µs per message, more than the logging overhead budget allows).
"""

from __future__ import annotations

import signal
import struct
import zlib
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

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

from bioflex_jsb.interrupts import critical_section

MAGIC = b"\x89MCAP0\r\n"
# simulated time per chunk [s]: the most a SIGKILL can lose (with one step, < 1 s); long
# chunks spread the fixed cost of writing one (≈ 0.7 ms measured in a run) over more steps
CHUNK_SPAN_S = 0.9
CHUNK_WALL_S = 0.9  # wall time per chunk [s] (runs slower than real time, SITL sessions)
# DECISION: wall time per chunk [s] while a live client is subscribed (the tee's
# ``subscribed``): a message reaches it at most this long after its step (plus the send),
# within the ~50 ms a live plot looks immediate at; a chunk's fixed cost (≈ 0.7
# ms, see above) every 20 ms of a real-time session is ≈ 3 % of a core, only while watched
LIVE_CHUNK_WALL_S = 0.02
CHUNK_MAX_BYTES = 4 * 1024 * 1024  # uncompressed chunk size limit [bytes]
COMPRESSION = "zstd"
ZSTD_LEVEL = -3  # zstd's fast level: see McapFileWriter
# DECISION: a kind of chunk (the set of its channels) that zstd shrinks by less than
# RAW_BELOW is stored uncompressed for its next RAW_CHUNKS chunks of that kind, then tried
# again. The section loads' own chunk (24 doubles a step: mantissas that look like noise)
# compresses 1.12:1 (measured on a gust run's chunks) at 0.59 ns a byte: 0.14 µs
# a step alone, for 12 % of its bytes; the steps' chunk compresses 2.07:1, the scene's 4.4:1
# and the load markers' 5.7:1, so they stay compressed.
RAW_BELOW = 0.15  # [-] of the chunk's size
RAW_CHUNKS = 15
_OP_SCHEMA, _OP_CHANNEL, OP_MESSAGE, _OP_CHUNK = 0x03, 0x04, 0x05, 0x06
_OP_CHUNK_INDEX, _OP_STATISTICS, _OP_METADATA_INDEX = 0x08, 0x0B, 0x0D
_MSG_HEADER = struct.Struct("<BQHIQQ")  # opcode, record length, channel, sequence, log, publish
# Upper bounds for McapFileWriter.size_bound [bytes]: a Message record is ≥ 31 bytes (its
# header) and costs 16 bytes in its Message Index; a Message Index record has 15 bytes of its
# own per channel; zstd's output is at most n + n/256 + 64 (ZSTD_compressBound, for
# n ≥ 128 kB; less below); a Chunk record's header with "zstd" is 53 bytes; a Chunk Index
# record is 77 bytes + 10 per channel + the compression name; DataEnd 13, the footer with
# the magic 37, a Statistics record 58 + 10 per channel, a Metadata Index 25 + its name,
# one Summary Offset 26 (five groups at most).
_MSG_MIN_BYTES, _INDEX_ENTRY_BYTES, _INDEX_PER_CHANNEL = 31, 16, 15
_CHUNK_HEADER_BYTES, _CHUNK_INDEX_BYTES, _PER_CHANNEL_BYTES = 53, 81, 10
_FINISH_FIXED_BYTES = 13 + 37 + 58 + 5 * 26


@contextmanager
def signals_deferred():
    """Hold SIGINT/SIGTERM while a chunk or the summary is written (no half-written record):
    blocked at the operating system, and a handler already due deferred
    (:func:`~bioflex_jsb.interrupts.critical_section`)."""
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    except (AttributeError, ValueError, OSError):  # not Unix or not the main thread
        old = None
    try:
        with critical_section():
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

    def __init__(self, stream, library: str, background: bool = False) -> None:
        import zstandard

        self._stream = stream
        # zstd at level -3 with a small hash table and window: protobuf doubles are mostly
        # incompressible mantissa bytes, so every level from -3 to 3 gives ≈ 2:1 on a
        # gust-run chunk; measured (alone, per step of 702 bytes): level -3 0.5 µs, level 1
        # 0.9 µs, both 2.06:1 / 2.1:1 (docs/logging.md, Overhead)
        # Integrity: each zstd frame carries its content checksum (XXH64, 4 bytes, checked
        # by every zstd decoder: a damaged chunk fails to decompress), so its MCAP chunk CRC
        # is 0 ("not computed", as the MCAP specification allows): XXH64 cost 0.05 ns a byte
        # against CRC-32's 0.15 (measured on a gust run's chunks), ~0.13 µs a
        # step less. A chunk stored uncompressed (RAW_BELOW) has its CRC-32; the data
        # section's CRC covers every byte written either way.
        self._compress = zstandard.ZstdCompressor(
            compression_params=zstandard.ZstdCompressionParameters.from_level(
                ZSTD_LEVEL, window_log=17, hash_log=11, min_match=7,
                write_checksum=True)).compress
        self._raw_left: dict[tuple[int, ...], int] = {}  # kind → chunks left to store raw
        self._crc = 0
        self._offset = 0
        self._records_bytes = 0  # schema and channel records: repeated in the summary
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
        self._dirty: set[int] = set()  # the channels with messages in the chunk in progress
        self.finished = False
        # the tee (bioflex_jsb.sinks.live): called on the run's thread with each closed
        # chunk's uncompressed message records (bytes: Message records back to back, as in
        # the file) and the channel and schema records so far (lists, id = index + 1); its
        # ``subscribed`` (bool) shortens the chunks while a client listens (chunk_wall_s)
        self.on_chunk = None
        self._pending = None  # the Future of the chunk being written in the background
        # background=True: one writer thread compresses and writes a closed chunk (zstd and
        # the file write release the GIL) while the run flies the next, at most one pending;
        # off by default: a SIGKILL can then also lose the chunk in flight (≈ 1 ms of wall
        # time), a write error surfaces a chunk later, and on this shared 2-vCPU machine the
        # gain could not be measured above the noise (docs/logging.md, Overhead)
        self._pool = (ThreadPoolExecutor(max_workers=1, thread_name_prefix="mcap-chunk")
                      if background else None)
        self._write(MAGIC + _record_bytes(Header(profile="", library=library)))
        self._stream.flush()

    @property
    def chunk_wall_s(self) -> float:
        """The wall time [s] a chunk begun now may stay open (the run log's policy):
        :data:`LIVE_CHUNK_WALL_S` while the tee has a subscribed client, so that it sees each
        message within that; :data:`CHUNK_WALL_S` otherwise (fewer, cheaper chunks)."""
        tee = self.on_chunk
        return LIVE_CHUNK_WALL_S if tee is not None and tee.subscribed else CHUNK_WALL_S

    def _write(self, data: bytes) -> None:
        self._wait()
        self._write_now(data)

    def _write_now(self, data: bytes) -> None:
        # the bytes and their count are one step: a stop between them (a schema or channel
        # record written outside a chunk's deferred block) would leave every later offset
        # and the data section's CRC wrong
        with critical_section():
            self._stream.write(data)
            self._crc = zlib.crc32(data, self._crc)
            self._offset += len(data)

    def flush(self) -> None:
        """Hand everything written so far to the operating system."""
        self._wait()
        self._stream.flush()

    def _wait(self) -> None:
        """Wait for the chunk being written in the background (its error, if any, is raised
        here: a full disk surfaces at the next chunk or at finish)."""
        pending, self._pending = self._pending, None
        if pending is not None:
            pending.result()

    def add_schema(self, name: str, encoding: str, data: bytes) -> int:
        """A Schema record (``encoding``: ``protobuf``, ``jsonschema``, …); its id."""
        schema = Schema(id=len(self._schemas) + 1, name=name, encoding=encoding, data=data)
        self._schemas.append(schema)
        record = _record_bytes(schema)
        self._records_bytes += len(record)
        self._write(record)
        return schema.id

    def add_channel(self, topic_name: str, schema_id: int, metadata: dict[str, str],
                    message_encoding: str = "protobuf") -> int:
        channel = Channel(id=len(self._channels) + 1, topic=topic_name,
                          message_encoding=message_encoding,
                          schema_id=schema_id, metadata=metadata)
        self._channels.append(channel)
        self._index[channel.id] = []
        self._blocks[channel.id] = []
        self._counts[channel.id] = 0
        record = _record_bytes(channel)
        self._records_bytes += len(record)
        self._write(record)
        return channel.id

    def add_metadata(self, name: str, data: dict[str, str]) -> None:
        record = _record_bytes(Metadata(name=name, metadata=data))
        self._wait()  # self._offset includes the chunk being written
        self._metadata_indexes.append(MetadataIndex(offset=self._offset, length=len(record),
                                                    name=name))
        self._write(record)

    def append(self, channel_id: int, log_ns: int, sequence: int, data: bytes) -> None:
        """One message into the chunk in progress (log time = publish time = ``log_ns``)."""
        record = _MSG_HEADER.pack(OP_MESSAGE, 22 + len(data), channel_id, sequence, log_ns,
                                  log_ns) + data
        self._index[channel_id].append((log_ns, self._size))
        self._dirty.add(channel_id)
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
                self._dirty.add(cid)
        self._parts.append(block)
        self._size += len(block)

    def chunk_bytes(self) -> int:
        return self._size

    def size_bound(self, more_bytes: int = 0) -> int:
        """An upper bound [bytes] of the file's size if the chunk in progress, with
        ``more_bytes`` more of message records, were closed and the file finished now (the
        bounds of the constants above): what has been written, the chunk compressed (no
        smaller than it is), its message indexes and its chunk index, and the summary."""
        n = self._size + more_bytes
        channels = len(self._channels)
        per_index = _CHUNK_INDEX_BYTES + _PER_CHANNEL_BYTES * channels
        chunk = 0
        if n:
            chunk = (n + n // 256 + (n // _MSG_MIN_BYTES) * _INDEX_ENTRY_BYTES
                     + self.chunk_overhead_bound())
        summary = (self._records_bytes + _FINISH_FIXED_BYTES + _PER_CHANNEL_BYTES * channels
                   + per_index * len(self._chunk_indexes)
                   + sum(25 + len(m.name) for m in self._metadata_indexes))
        return self._offset + chunk + summary

    def chunk_overhead_bound(self) -> int:
        """An upper bound [bytes] of what one more chunk costs besides its records: its
        header, zstd's fixed margin, a message index per channel and its chunk index (for a
        caller that writes part of its records as a chunk of their own)."""
        channels = len(self._channels)
        return (_CHUNK_HEADER_BYTES + 64 + _INDEX_PER_CHANNEL * channels
                + _CHUNK_INDEX_BYTES + _PER_CHANNEL_BYTES * channels)

    def close_chunk(self) -> None:
        """Compress and write the chunk in progress with its message indexes; flush."""
        with signals_deferred():
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
        # in offset order (a block's entries are, and so are single messages'): the ones
        # within the chunk's bytes are a prefix; a mask over every entry instead costs ~10 µs
        # a channel a chunk (0.08 µs a step of a gust log's steps' chunk)
        if len(entries) and entries[-1, 1] >= n:
            entries = entries[:int(np.searchsorted(entries[:, 1], n))]
        return entries if len(entries) else None

    def _close_chunk(self) -> None:
        parts = self._parts
        data = parts[0] if len(parts) == 1 else b"".join(parts)  # no copy of a lone block
        n = len(data)
        indexes = {}
        for cid in sorted(self._dirty):  # the channels with messages, in id order
            entries = self._entries(cid, n)
            if entries is not None:
                indexes[cid] = entries
            self._index[cid].clear()
            self._blocks[cid].clear()
        self._dirty.clear()
        self._parts = []
        self._size = 0
        if not indexes:
            return
        if self.on_chunk is not None:
            self.on_chunk(data, self._channels, self._schemas)
        times = np.concatenate([e[:, 0] for e in indexes.values()])
        start, end = int(times.min()), int(times.max())
        for cid, entries in indexes.items():
            self._counts[cid] += len(entries)
            self._n_messages += len(entries)
        self._start_ns = start if self._start_ns is None else min(self._start_ns, start)
        self._end_ns = max(self._end_ns, end)
        # the message indexes do not depend on where the chunk lands: serialised here
        index_records = [(cid, _message_index(cid, entries)) for cid, entries in indexes.items()]
        self._wait()
        if self._pool is None:
            self._write_chunk(data, index_records, start, end)
        else:  # compressed and written while the run goes on; the next chunk waits for it
            self._pending = self._pool.submit(self._write_chunk, data, index_records, start,
                                              end)

    def _write_chunk(self, data, index_records: list[tuple[int, bytes]], start: int,
                     end: int) -> None:
        """Compress ``data`` and write it as a Chunk record (opcode 0x06) followed by its
        Message Index records, and hand it to the operating system."""
        n = len(data)
        kind = tuple(cid for cid, _ in index_records)
        raw_left = self._raw_left.get(kind, 0)
        if raw_left:  # this kind did not compress (RAW_BELOW): stored as it is, with its CRC
            self._raw_left[kind] = raw_left - 1
            compressed, crc, compression = data, zlib.crc32(data), ""
        else:
            compressed, crc, compression = self._compress(data), 0, COMPRESSION
            if len(compressed) > (1.0 - RAW_BELOW) * n:
                self._raw_left[kind] = RAW_CHUNKS
        name = compression.encode()
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
            message_index_length=at - chunk_start - chunk_length, compression=compression,
            compressed_size=len(compressed), uncompressed_size=n))
        self._write_now(b"".join([header, compressed, *(r for _, r in index_records)]))
        self._stream.flush()

    def finish(self) -> None:
        """Close the last chunk, write the summary and the footer, flush."""
        if self.finished:
            return
        with signals_deferred():
            self._close_chunk()
            self._wait()  # the data section's CRC and length include the last chunk
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
        self.shutdown()

    def shutdown(self) -> None:
        """Stop the writer thread (after finish, or when the file is abandoned)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None
