"""Recovery of a log whose writer was killed or whose file was damaged, and a check of every
chunk.

A chunk checks when it decompresses to its stated size (a zstd frame with its content
checksum, XXH64, as :class:`~.writer.McapFileWriter` writes them, fails to decompress when
damaged), its CRC-32 matches where one is written (uncompressed chunks, and the logs of
earlier versions, which wrote one for every chunk; 0 means none, as the MCAP specification
says) and its records fit. Both read the file sequentially, record by record
(``opcode``, ``length``, body), without its summary: a chunk whose checksum, CRC,
compression or records do not check is *skipped* and the scan goes on with the next
record (or, where the damage hit a record's length, with the next place that holds a
whole, valid chunk), so every intact chunk after a damaged one is kept.
A finished file whose summary is intact (its CRC checks) is recovered from it instead: its
schemas, channels and the metadata records its index points at first, then each chunk read
where its Chunk Index says (a damaged record length before them cannot make the scan skip
schemas or intact chunks). In a scan, a channel whose schema record is lost is not copied
(its messages would be undecodable) and its messages are reported skipped.
The recovered file is written by our own :class:`~.writer.McapFileWriter`: finished and
indexed like any log (the tests run ``pymcap-cli doctor`` on it).
"""

from __future__ import annotations

import mmap
import os
import struct
import zlib
from collections.abc import Iterator
from pathlib import Path

from bioflex_jsb.files import size_text
from bioflex_jsb.sinks.mcap_io.errors import LogError, LogWriteError, bad_data_errors, open_log
from bioflex_jsb.sinks.mcap_io.writer import CHUNK_MAX_BYTES, MAGIC, McapFileWriter

_OP_HEADER, _OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, OP_MESSAGE, _OP_CHUNK = 1, 2, 3, 4, 5, 6
_OP_METADATA, _OP_DATA_END = 0x0C, 0x0F
_KNOWN_OPS = set(range(0x01, 0x10))
_COMPRESSIONS = (b"", b"zstd", b"lz4")
_MAX_RESYNC_TRIES = 100_000  # candidate chunk starts tried after a damaged record length
# Largest chunk read [bytes], uncompressed as it declares and compressed: 16 times the
# project's own (writer.CHUNK_MAX_BYTES, 4 MiB); other MCAP writers' defaults are 1-8 MiB
# (the mcap library's 1 MiB, ROS 2's 4 MiB). A chunk beyond it is refused before anything
# is decompressed, and nothing decompresses to more than its chunk declares: a 65 kB file
# holding a zstd chunk of 2 GiB of zeros took 4.2 GB to read before.
MAX_CHUNK_BYTES = 64 * 1024 * 1024


class ChunkTooLarge(LogError):
    """A chunk larger than :data:`MAX_CHUNK_BYTES`: the file is refused (one line)."""


def _too_large(what: str, n: int) -> ChunkTooLarge:
    return ChunkTooLarge(f"a chunk {what} {size_text(n)}, more than the "
                         f"{size_text(MAX_CHUNK_BYTES)} a chunk may hold here (bioflex-jsb "
                         f"writes at most {size_text(CHUNK_MAX_BYTES)})")


def check_chunk_sizes(size: int, n_bytes: int) -> None:
    """ChunkTooLarge unless a chunk's declared uncompressed ``size`` and its compressed
    ``n_bytes`` are both within :data:`MAX_CHUNK_BYTES`."""
    if size > MAX_CHUNK_BYTES:
        raise _too_large("declares", size)
    if n_bytes > MAX_CHUNK_BYTES:
        raise _too_large("holds", n_bytes)


def check_zstd_frame(header: bytes, size: int) -> None:
    """ValueError (a damaged chunk) when the zstd frame that starts with ``header`` declares
    another size than its chunk's ``size`` (the decoder allocates what the frame says)."""
    import zstandard

    framed = zstandard.frame_content_size(header)  # -1: not in the frame's header
    if framed not in (-1, size):
        raise ValueError(f"its zstd frame declares {framed} bytes, the chunk {size}")


def decompress_chunk(name: bytes, raw, size: int) -> bytes:
    """The records of a chunk compressed with ``name`` (``zstd``, ``lz4`` or none) that
    declares ``size`` bytes, never more than that decompressed: ChunkTooLarge beyond
    :data:`MAX_CHUNK_BYTES`; ValueError (a damaged chunk) when a zstd frame declares
    another size or an lz4 frame holds more; a zstd frame's checksum checked by the
    decoder."""
    check_chunk_sizes(size, len(raw))
    if name == b"zstd":
        import zstandard

        check_zstd_frame(bytes(raw[:18]), size)
        return zstandard.ZstdDecompressor().decompress(raw, max_output_size=size)
    if name == b"lz4":
        import lz4.frame

        decoder = lz4.frame.LZ4FrameDecompressor()
        data = decoder.decompress(raw, max_length=size + 1)
        if len(data) > size:
            raise ValueError(f"chunk decompresses to more than the {size} bytes it declares")
        if not decoder.eof:
            raise ValueError("chunk's lz4 frame is cut short")
        return data
    return bytes(raw)


def _open_data(p: Path):
    with open_log(p) as f:  # the map outlives the file object; freed with its last view
        if os.fstat(f.fileno()).st_size == 0:
            raise LogError(f"{str(p)!r} is empty: its writer was killed before writing the "
                           "MCAP header; there is nothing to recover")
        data = mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ)
    if data[:len(MAGIC)] != MAGIC:
        raise LogError(f"{str(p)!r} is not an MCAP file (no MCAP magic at the start)")
    return data


def _chunk_records(body) -> tuple[int, list[tuple[int, bytes]]]:
    """(uncompressed CRC, the records) of a Chunk body, decompressed (a zstd frame's checksum
    checked by the decoder) and CRC-checked where it has a CRC;
    ValueError (or a zstd/lz4 error) if anything does not check."""
    if len(body) < 36:
        raise ValueError("chunk record too short")
    _start, _end, size, crc, name_len = struct.unpack_from("<QQQII", body, 0)
    at = 32
    name = bytes(body[at:at + name_len])
    if name not in _COMPRESSIONS:
        raise ValueError(f"unknown chunk compression {name[:16]!r}")
    at += name_len
    (n_bytes,) = struct.unpack_from("<Q", body, at)
    at += 8
    if at + n_bytes != len(body):
        raise ValueError("chunk records length does not match the record length")
    data = decompress_chunk(name, body[at:at + n_bytes], size)
    if len(data) != size:
        raise ValueError(f"chunk decompresses to {len(data)} bytes, not {size}")
    if crc and zlib.crc32(data) != crc:
        raise ValueError("chunk CRC mismatch")
    records, pos = [], 0
    while pos < size:
        if pos + 9 > size:
            raise ValueError("chunk ends inside a record")
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        if pos + 9 + length > size:
            raise ValueError("chunk record overruns the chunk")
        records.append((op, data[pos + 9:pos + 9 + length]))
        pos += 9 + length
    return crc, records


def _next_chunk(data, start: int) -> int | None:
    """The offset of the next whole, valid Chunk record at or after ``start`` (a scan after
    a damaged record length), or None."""
    size, pos, tries = len(data), start, 0
    while tries < _MAX_RESYNC_TRIES:
        pos = data.find(b"\x06", pos)
        if pos < 0 or pos + 9 > size:
            return None
        tries += 1
        length = struct.unpack_from("<Q", data, pos + 1)[0]
        if pos + 9 + length <= size:
            try:
                _chunk_records(memoryview(data)[pos + 9:pos + 9 + length])
                return pos
            except bad_data_errors():
                pass
        pos += 1
    return None


def scan(data) -> Iterator[tuple[int, int, object]]:
    """(offset, opcode, body or the error) of every record of the data section, in file
    order: a chunk's body is (crc, inner records) when it checks, else the error; the
    scan stops at Data End, a Footer or the end of the file (an incomplete record at the
    end is yielded as (offset, 0, the error))."""
    view = memoryview(data)
    size, pos = len(data), len(MAGIC)
    while pos < size:
        if pos + 9 > size:
            yield pos, 0, EOFError(f"incomplete record at byte {pos} (the file ends)")
            return
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        end = pos + 9 + length
        if op not in _KNOWN_OPS or end > size:
            nxt = _next_chunk(data, pos + 1)
            if nxt is None:
                yield pos, 0, EOFError(
                    f"incomplete or damaged record at byte {pos} (nothing valid after it)")
                return
            yield pos, _OP_CHUNK, ValueError(f"damaged record header ({nxt - pos} bytes "
                                             "skipped)")
            pos = nxt
            continue
        body = view[pos + 9:end]
        if op == _OP_CHUNK:
            try:
                yield pos, op, _chunk_records(body)
            except ChunkTooLarge as exc:
                raise ChunkTooLarge(f"{exc} (at byte {pos})") from None
            except bad_data_errors() as exc:
                yield pos, op, exc
        elif op in (_OP_DATA_END, _OP_FOOTER):
            yield pos, op, body
            return
        else:
            yield pos, op, body
        pos = end


def _string(b, at: int) -> tuple[str, int]:
    (n,) = struct.unpack_from("<I", b, at)
    return bytes(b[at + 4:at + 4 + n]).decode(), at + 4 + n


def _bytes(b, at: int, width: str = "<I") -> tuple[bytes, int]:
    (n,) = struct.unpack_from(width, b, at)
    w = struct.calcsize(width)
    return bytes(b[at + w:at + w + n]), at + w + n


def _string_map(b, at: int) -> tuple[dict[str, str], int]:
    (n,) = struct.unpack_from("<I", b, at)
    at += 4
    end, out = at + n, {}
    while at < end:
        k, at = _string(b, at)
        v, at = _string(b, at)
        out[k] = v
    return out, at


class _Copier:
    """Writes the records of the source into a new log, renumbering schemas and channels."""

    def __init__(self, writer: McapFileWriter) -> None:
        self.w = writer
        self.schemas: dict[int, int] = {0: 0}
        self.channels: dict[int, int | None] = {}  # None: its schema is lost, not copied
        self.lost: dict[int, int] = {}  # messages not copied, per channel whose schema is lost
        self.messages = 0
        self.last_ns: int | None = None

    def record(self, op: int, b) -> None:
        if op == _OP_SCHEMA:
            (sid,) = struct.unpack_from("<H", b, 0)
            name, at = _string(b, 2)
            encoding, at = _string(b, at)
            data, _ = _bytes(b, at)
            if sid not in self.schemas:
                self.schemas[sid] = self.w.add_schema(name, encoding, data)
        elif op == _OP_CHANNEL:
            cid, sid = struct.unpack_from("<HH", b, 0)
            topic, at = _string(b, 4)
            encoding, at = _string(b, at)
            meta, _ = _string_map(b, at)
            if cid not in self.channels:
                # a channel whose schema record is lost would be written without one (its
                # protobuf messages undecodable): not copied, its messages counted lost
                self.channels[cid] = (None if sid not in self.schemas else
                                      self.w.add_channel(topic, self.schemas[sid], meta,
                                                         encoding))
        elif op == _OP_METADATA:
            name, at = _string(b, 0)
            meta, _ = _string_map(b, at)
            self.w.add_metadata(name, meta)
        elif op == OP_MESSAGE:
            cid, seq, log_ns, _pub = struct.unpack_from("<HIQQ", b, 0)
            if cid not in self.channels:
                raise ValueError(f"message on channel {cid} before its channel record")
            out = self.channels[cid]
            if out is None:
                self.lost[cid] = self.lost.get(cid, 0) + 1
                return
            self.w.append(out, log_ns, seq, bytes(b[22:]))
            self.messages += 1
            self.last_ns = log_ns if self.last_ns is None else max(self.last_ns, log_ns)


def recover(path: str | Path, out: str | Path, library: str) -> dict:
    """Copy every intact record of a (killed or damaged) log into a finished, indexed file
    ``out``: every chunk that checks (module docstring), also those after a damaged one
    (each skipped chunk is listed in ``skipped``: its byte offset and why). Returns counts,
    the last log time kept [s] and where and why the read stopped."""
    p = Path(path)
    dst = Path(out)
    if dst.exists() and dst.resolve() == p.resolve():
        raise LogError("--recover must name a new file, not the log itself")
    data = _open_data(p)
    try:
        fout = open(dst, "wb")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise LogWriteError(f"cannot write {str(dst)!r}: {exc.strerror}") from None
    try:
        with fout:
            writer = McapFileWriter(fout, library=library,
                                    background=False)
            copier = _Copier(writer)
            skipped: list[str] = []
            stop, chunks = "end of file", 0
            # an intact summary (its CRC checks) gives the schemas, channels and metadata first:
            # a damaged record before the first chunk (the header's length) loses them otherwise
            taken, chunk_offsets = _from_summary(data, copier)
            # with it, the chunks are read where its chunk index says they are (a damaged record
            # length cannot make the scan skip an intact chunk); without it, the file is scanned
            records = scan(data) if chunk_offsets is None else _indexed_chunks(data, chunk_offsets)
            for offset, op, body in records:
                if isinstance(body, BaseException):
                    if op == _OP_CHUNK:
                        skipped.append(f"chunk at byte {offset} ({body})")
                        continue
                    stop = str(body)
                    break
                if op in (_OP_DATA_END, _OP_FOOTER):
                    stop = "the end of the data section (the file was finished)"
                    break
                if op == _OP_CHUNK:
                    _crc, records = body
                    try:
                        for inner_op, inner in records:
                            copier.record(inner_op, inner)
                    except (ValueError, struct.error, UnicodeDecodeError) as exc:
                        skipped.append(f"chunk at byte {offset} ({exc})")
                        writer.close_chunk()
                        continue
                    writer.close_chunk()  # one chunk out per chunk in
                    chunks += 1
                elif op != _OP_HEADER and not (op == _OP_METADATA and offset in taken):
                    try:
                        copier.record(op, body)
                    except (ValueError, struct.error, UnicodeDecodeError) as exc:
                        skipped.append(f"record at byte {offset} ({exc})")
            writer.finish()
    except ChunkTooLarge as exc:  # refused whole: the partial copy is removed
        dst.unlink(missing_ok=True)
        raise ChunkTooLarge(f"{str(p)!r}: {exc}") from None
    skipped += [f"{n} messages of channel {cid} (its schema record is lost)"
                for cid, n in copier.lost.items()]
    last = copier.last_ns
    return {"file": str(p), "out": str(dst), "messages": copier.messages,
            "channels": len(copier.channels), "chunks": chunks,
            "last_time_s": None if last is None else last * 1e-9, "stopped_at": stop,
            "skipped": skipped}


_FOOTER_BYTES = 9 + 20  # opcode, length, summary start, summary offset start, summary CRC
_OP_CHUNK_INDEX, _OP_METADATA_INDEX = 0x08, 0x0D


def _summary_span(data) -> tuple[int, int] | None:
    """(start, end) of the summary's records when the file has a footer whose summary CRC
    checks, else None."""
    footer = len(data) - len(MAGIC) - _FOOTER_BYTES
    if footer <= len(MAGIC) or data[footer] != _OP_FOOTER:
        return None
    length, start, offsets, crc = struct.unpack_from("<QQQI", data, footer + 1)
    if length != 20 or not len(MAGIC) < start <= footer:
        return None
    if zlib.crc32(data[start:footer + _FOOTER_BYTES - 4]) != crc:
        return None
    return start, (offsets if start <= offsets <= footer else footer)


def _from_summary(data, copier: _Copier) -> tuple[set[int], list[int] | None]:
    """The schemas and channels of an intact summary into ``copier``, and the metadata
    records its Metadata Index points at; returns those records' offsets (the scan then
    skips them) and the chunks' offsets of its Chunk Index (None when the summary is absent
    or damaged: then nothing is taken from it)."""
    span = _summary_span(data)
    taken: set[int] = set()
    if span is None:
        return taken, None
    chunks: list[int] = []
    pos, end = span
    while pos + 9 <= end:
        op, length = data[pos], struct.unpack_from("<Q", data, pos + 1)[0]
        body = memoryview(data)[pos + 9:pos + 9 + length]
        if op in (_OP_SCHEMA, _OP_CHANNEL):
            copier.record(op, body)
        elif op == _OP_METADATA_INDEX:
            at, size = struct.unpack_from("<QQ", body, 0)
            if data[at] == _OP_METADATA and at + size <= len(data):
                copier.record(_OP_METADATA, memoryview(data)[at + 9:at + size])
                taken.add(at)
        elif op == _OP_CHUNK_INDEX:
            chunks.append(struct.unpack_from("<Q", body, 16)[0])  # chunk_start_offset
        pos += 9 + length
    return taken, sorted(chunks)


def _indexed_chunks(data, offsets: list[int]) -> Iterator[tuple[int, int, object]]:
    """(offset, opcode, body or the error) of the chunks at ``offsets`` (a Chunk Index's),
    as :func:`scan` yields them, then the end of the data section."""
    view = memoryview(data)
    for at in offsets:
        if at + 9 > len(data) or data[at] != _OP_CHUNK:
            yield at, _OP_CHUNK, ValueError("no chunk record where the chunk index says")
            continue
        end = at + 9 + struct.unpack_from("<Q", data, at + 1)[0]
        if end > len(data):
            yield at, _OP_CHUNK, ValueError("damaged chunk length")
            continue
        try:
            yield at, _OP_CHUNK, _chunk_records(view[at + 9:end])
        except ChunkTooLarge as exc:
            raise ChunkTooLarge(f"{exc} (at byte {at})") from None
        except bad_data_errors() as exc:
            yield at, _OP_CHUNK, exc
    yield len(data), _OP_DATA_END, b""


def check_chunks(path: str | Path) -> dict:
    """Every byte of a log checked against its checksums: each chunk decompressed and checked
    (module docstring), the data section's CRC (header, schemas, channels, chunks, metadata: every
    byte before Data End), the summary's CRC (summary, summary offsets and the footer's
    fields) and the footer's place and magic. Returns ``chunks``, ``bad`` (byte offset and
    why, per chunk that fails), ``data_crc`` and ``summary_crc`` (``ok``, ``bad``,
    ``absent`` (not written) or ``unfinished``), ``finished`` (Data End, summary and footer
    present), ``missing`` (what an unfinished file lacks) and ``problems`` (one phrase each
    for everything that does not check; empty for a sound, finished file)."""
    p = Path(path)
    data = _open_data(p)
    try:
        return _check(p, data)
    except ChunkTooLarge as exc:
        raise ChunkTooLarge(f"{str(p)!r}: {exc}") from None


def _check(p: Path, data) -> dict:
    """:func:`check_chunks` of the mapped file ``data`` (of ``p``)."""
    chunks, bad, data_crc, stop, data_end = 0, [], "unfinished", None, None
    problems: list[str] = []
    for offset, op, body in scan(data):
        if isinstance(body, BaseException):
            if op == _OP_CHUNK:
                chunks += 1
                bad.append(f"chunk at byte {offset}: {body}")
                continue
            stop = str(body)
            break
        if offset == len(MAGIC) and op != _OP_HEADER:
            problems.append(f"the first record is not a Header (opcode {op})")
        if op == _OP_CHUNK:
            chunks += 1
        elif op == _OP_DATA_END:
            (stored,) = struct.unpack_from("<I", body, 0)
            if stored == 0:
                data_crc = "absent"
            else:
                data_crc = "ok" if zlib.crc32(data[:offset]) == stored else "bad"
            data_end = offset + 9 + len(body)
            break
        elif op == _OP_FOOTER:
            problems.append(f"a Footer at byte {offset} without a Data End record")
            break
    summary_crc, missing = _check_tail(data, data_end, problems)
    if bad:
        problems.append(f"{len(bad)} of {chunks} chunks fail their check ({bad[0]}"
                        + (", …" if len(bad) > 1 else "") + ")")
    if data_crc == "bad":
        problems.append("the data section's CRC does not match")
    if stop is not None and not missing:
        problems.append(f"the data section is damaged ({stop})")
    return {"file": str(p), "chunks": chunks, "bad": bad, "data_crc": data_crc,
            "summary_crc": summary_crc, "stopped_at": stop, "finished": not missing,
            "missing": missing, "problems": problems}


def _check_tail(data, data_end: int | None, problems: list[str]) -> tuple[str, list[str]]:
    """The summary's CRC and the footer: (summary_crc, what is missing). A file without
    the closing magic and without Data End is unfinished (its writer stopped before the
    end); a file that has one and not the other is damaged."""
    size = len(data)
    tail_magic = size >= len(MAGIC) * 2 + _FOOTER_BYTES and data[size - len(MAGIC):] == MAGIC
    if not tail_magic:
        if data_end is None:
            return "unfinished", ["Data End", "summary", "footer"]
        problems.append("the footer or the closing magic is damaged")
        return "unfinished", []
    at = size - len(MAGIC) - _FOOTER_BYTES
    op, length = data[at], struct.unpack_from("<Q", data, at + 1)[0]
    if op != _OP_FOOTER or length != 20:
        problems.append(f"no Footer record before the closing magic (byte {at})")
        return "unfinished", []
    start, offsets, stored = struct.unpack_from("<QQI", data, at + 9)
    if data_end is None:
        problems.append("the data section ends without a Data End record")
    elif start not in (0, data_end):
        problems.append(f"the footer's summary start ({start}) is not the end of the data "
                        f"section ({data_end})")
        return "bad", []
    if start and not start <= offsets <= at or not start and offsets:
        problems.append("the footer's summary offsets point outside the summary")
        return "bad", []
    if stored == 0:
        return "absent", []
    crc = zlib.crc32(data[start if start else at:at + 9 + 16])
    if crc != stored:
        problems.append("the summary's CRC does not match (summary or footer damaged)")
        return "bad", []
    return "ok", []
