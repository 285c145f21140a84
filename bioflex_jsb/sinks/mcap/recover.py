"""Recovery of a log whose writer was killed: its complete chunks into a finished file."""

from __future__ import annotations

from pathlib import Path

from mcap.records import Metadata

from bioflex_jsb import __version__
from bioflex_jsb.sinks.mcap.errors import LogError, LogWriteError, bad_data_errors
from bioflex_jsb.sinks.mcap.reader import check_file


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
        raise LogWriteError(f"cannot write {str(dst)!r}: {exc.strerror}") from None
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
        except bad_data_errors() as exc:  # truncated or damaged tail: keep the rest
            stop = f"{type(exc).__name__} {exc}".strip()
        writer.finish()
    return {"file": str(p), "out": str(dst), "messages": n_messages,
            "channels": len(channels),
            "last_time_s": None if last_ns is None else last_ns * 1e-9, "stopped_at": stop}
