"""Reading finished MCAP logs back: summaries, messages, time histories, run metadata.

Read through the ``mcap`` package's indexed reader; a file that is missing, not MCAP,
truncated or damaged is a :class:`LogError` with one line for the user.
"""

from __future__ import annotations

import io
import json
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from bioflex_jsb.sinks.mcap.schemas import EVENT_LEVELS, EVENTS_TOPIC
from bioflex_jsb.sinks.mcap_io.errors import LogError, bad_data_errors, open_log
from bioflex_jsb.sinks.mcap_io.protobuf import decoder
from bioflex_jsb.sinks.mcap_io.writer import MAGIC
from bioflex_jsb.values import is_real


def check_file(path: str | Path) -> Path:
    """``path`` as a Path if it is a regular file (:func:`open_log`) starting with the MCAP
    magic."""
    p = Path(path)
    with open_log(p) as f:
        head = f.read(len(MAGIC))
    if head != MAGIC:
        raise LogError(f"{str(p)!r} is not an MCAP file (no MCAP magic at the start)")
    return p


def _truncated(p: Path) -> LogError:
    from bioflex_jsb.sinks.mcap.writers import unfinished_message

    return LogError(unfinished_message(p))


def verify(path: str | Path) -> dict:
    """Every CRC and record of the log checked (:func:`.recover.check_chunks`); LogError,
    one line, for a file that is unfinished (being written, or its writer killed:
    :mod:`.writers`) or damaged anywhere (header, chunks, metadata, summary, footer)."""
    from bioflex_jsb.sinks.mcap.writers import unfinished_message
    from bioflex_jsb.sinks.mcap_io.recover import check_chunks

    p = check_file(path)
    result = check_chunks(p)
    if result["missing"] and not result["problems"]:
        raise LogError(unfinished_message(p, f"no {', '.join(result['missing'])}"))
    if result["problems"]:
        raise LogError(f"{str(p)!r} is damaged: {'; '.join(result['problems'])}; recover the "
                       f"intact chunks with: bioflex-jsb info {str(p)!r} --recover FIXED.mcap")
    return result


@contextmanager
def open_reader(path: str | Path, verified: bool = False):
    """An indexed ``mcap`` reader of a finished log, with its summary; LogError otherwise.
    ``verified``: check every CRC first (:func:`verify`); without it the chunks read are
    checked against their CRCs as they are read."""
    from mcap.reader import make_reader

    p = verify(path) and Path(path) if verified else check_file(path)
    with open_log(p) as raw, io.BufferedReader(raw) as f:
        f.seek(0, 2)
        size = f.tell()
        if size < 2 * len(MAGIC) + 29:
            raise _truncated(p)
        f.seek(size - len(MAGIC))
        if f.read(len(MAGIC)) != MAGIC:
            raise _truncated(p)
        f.seek(0)
        try:
            reader = make_reader(f, validate_crcs=True)
            summary = reader.get_summary()
        except bad_data_errors() as exc:
            why = str(exc) or type(exc).__name__  # some of mcap's errors carry no text
            raise LogError(f"{str(p)!r}: unreadable MCAP summary ({why}): the file is "
                           "damaged; `bioflex-jsb info FILE --check` says where, "
                           "`--recover FIXED.mcap` copies its intact chunks") from None
        if summary is None:
            raise _truncated(p)
        _check_chunk_sizes(f, summary, p)
        f.seek(0)
        yield reader, summary


def _check_chunk_sizes(f, summary, p: Path) -> None:
    """The ``mcap`` reader decompresses a chunk to what its zstd frame declares (whatever
    the chunk says) and an lz4 chunk without a bound: before it reads any, every chunk the
    summary indexes is checked to decompress to at most what it declares, within
    :data:`.recover.MAX_CHUNK_BYTES` (LogError, one line, otherwise): its Chunk record's
    sizes, a zstd frame's declared size, an lz4 chunk decompressed with that bound."""
    import struct

    from bioflex_jsb.sinks.mcap_io.recover import (
        ChunkTooLarge,
        check_chunk_sizes,
        check_zstd_frame,
        decompress_chunk,
    )

    head = struct.Struct("<BQQQQII")  # opcode, length, start, end, uncompressed size, CRC, name
    for index in summary.chunk_indexes:
        f.seek(index.chunk_start_offset)
        raw = f.read(head.size)
        if len(raw) < head.size:
            raise LogError(f"{str(p)!r}: its chunk index points past the end of the file")
        _op, _length, _start, _end, size, _crc, name_len = head.unpack(raw)
        name = f.read(min(name_len, 8))
        if name_len > 8 or name not in (b"", b"zstd", b"lz4"):
            raise LogError(f"{str(p)!r}: the chunk at byte {index.chunk_start_offset} is "
                           "compressed in a way MCAP does not define (zstd, lz4 or none)")
        (n_bytes,) = struct.unpack("<Q", f.read(8).ljust(8, b"\0"))
        try:
            check_chunk_sizes(max(size, index.uncompressed_size), n_bytes)
            if name == b"lz4":  # decompressed by mcap without a bound: first by ours
                decompress_chunk(name, f.read(n_bytes), size)
            elif name == b"zstd":  # decompressed by mcap to what its frame's header says
                check_zstd_frame(f.read(min(n_bytes, 18)), size)
        except ChunkTooLarge as exc:
            raise LogError(f"{str(p)!r}: {exc} (at byte {index.chunk_start_offset})") from None
        except bad_data_errors() as exc:
            raise LogError(f"{str(p)!r}: the chunk at byte {index.chunk_start_offset} is "
                           f"damaged ({exc}); `bioflex-jsb info FILE --check` says where, "
                           "`--recover FIXED.mcap` copies the intact chunks") from None


def read_metadata(reader) -> dict[str, dict[str, str]]:
    try:
        return {m.name: dict(m.metadata) for m in reader.iter_metadata()}
    except bad_data_errors() as exc:
        raise LogError(f"unreadable metadata ({exc})") from None


def message_decoder(schema, channel):
    """A function from a message's bytes to a dict: JSON (logs written before protobuf) or
    protobuf with the file's own schema (:func:`.protobuf.decoder`); LogError for another
    encoding."""
    encoding = channel.message_encoding
    if encoding == "json":
        return json.loads
    if encoding == "protobuf" and schema is not None and schema.encoding == "protobuf":
        return decoder(schema.data, schema.name)
    raise LogError(f"channel {channel.topic!r}: message encoding {encoding!r} is not one "
                   "that bioflex-jsb writes (protobuf, or json in older logs)")


def iter_messages(reader, topics: list[str] | None = None, start_ns: int | None = None,
                  end_ns: int | None = None) -> Iterator[tuple[str, int, dict]]:
    """(topic, log time [ns], decoded message) of every message, in log-time order; with
    ``start_ns``/``end_ns`` those logged at start_ns <= t < end_ns only (the chunks outside
    are not read)."""
    decoders: dict[int, object] = {}
    where = ""  # the record being decoded, for the message of a failure
    try:
        for schema, channel, message in reader.iter_messages(
                topics=topics, log_time_order=True, **_time_bounds(reader, start_ns, end_ns)):
            where = f" of the message on {channel.topic!r} at log time " \
                    f"{message.log_time * 1e-9:.6g} s"
            decode = decoders.get(channel.id)
            if decode is None:
                decode = decoders[channel.id] = message_decoder(schema, channel)
            msg = decode(message.data)
            if not isinstance(msg, dict):
                raise NotOurs(channel.topic, message.log_time,
                              f"a {type(msg).__name__}, not a message object")
            yield channel.topic, message.log_time, msg
    except bad_data_errors() as exc:
        if isinstance(exc, LogError):
            raise
        raise LogError(f"unreadable message data{where} ({exc})") from None


def _time_bounds(reader, start_ns: int | None, end_ns: int | None) -> dict[str, int]:
    """The ``iter_messages`` keywords of start_ns <= t < end_ns: ``starting_at`` and
    ``ending_before`` where the installed mcap has them (``start_time``/``end_time``, the
    same bounds, are deprecated there), else the older names."""
    import inspect

    new = "starting_at" in inspect.signature(reader.iter_messages).parameters
    names = ("starting_at", "ending_before") if new else ("start_time", "end_time")
    return {k: v for k, v in zip(names, (start_ns, end_ns), strict=True) if v is not None}


class NotOurs(LogError):
    """A record on one of our topics that bioflex-jsb did not write (another program's
    MCAP with our topic names): one line naming the record."""

    def __init__(self, topic: str, log_time_ns: int, why: str) -> None:
        super().__init__(f"the message on {topic!r} at log time {log_time_ns * 1e-9:.6g} s is "
                         f"not one bioflex-jsb writes ({why}); is this log from another "
                         "program?")


def _number(msg: dict, field: str, topic: str, ns: int, optional: bool = False):
    """``msg[field]`` as a number (None if ``optional`` and absent); NotOurs otherwise."""
    value = msg.get(field)
    if value is None and optional:
        return None
    if not is_real(value):
        raise NotOurs(topic, ns, f"field {field!r} is {type(value).__name__}, not a number")
    return value


def _numbers(msg: dict, field: str, topic: str, ns: int, optional: bool = False) -> list:
    """``msg[field]`` as a list of numbers; NotOurs otherwise."""
    value = msg.get(field)
    if value is None and optional:
        return []
    if not isinstance(value, (list, tuple)) or not all(
            isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        raise NotOurs(topic, ns, f"field {field!r} is not a list of numbers")
    return list(value)


iter_json = iter_messages  # the JSON-log name of iter_messages, kept for its callers


def read_events(reader, summary) -> list[dict]:
    """The events of a log (``/bioflex/events``, ``foxglove.Log``) in log-time order: time
    [s], level name, text and reporter's name (only the chunks that hold events are read)."""
    if not any(ch.topic == EVENTS_TOPIC for ch in summary.channels.values()):
        return []
    out = []
    for _, ns, msg in iter_messages(reader, [EVENTS_TOPIC]):
        level = msg.get("level", 0)
        known = isinstance(level, int) and 0 <= level < len(EVENT_LEVELS)
        out.append({"time_s": ns * 1e-9,
                    "level": EVENT_LEVELS[level] if known else str(level),
                    "text": str(msg.get("message", "")), "name": str(msg.get("name", ""))})
    return out


def summarise(path: str | Path) -> dict:
    """Channels (topic, schema, count), duration, chunks, metadata and events
    (:func:`read_events`) of a finished log."""
    with open_reader(path, verified=True) as (reader, summary):
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
            "events": read_events(reader, summary),
        }


def messages_by_topic(path: str | Path) -> dict[str, list[tuple[int, dict]]]:
    """Every message of a finished log, per topic, in log-time order."""
    out: dict[str, list[tuple[int, dict]]] = {}
    with open_reader(path) as (reader, _summary):
        for top, ns, msg in iter_messages(reader):
            out.setdefault(top, []).append((ns, msg))
    return out

