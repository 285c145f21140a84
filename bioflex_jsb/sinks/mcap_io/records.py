"""Protobuf message records built a chunk at once, and the pieces they are made of: the
leaf that the run log's topics (formatting.py, loads_topic.py) and the 3-D scene's
(scene.py, scene_loads.py, scene_modes.py) share.

Every message of a step has a fixed protobuf layout: each double is a one- or two-byte tag
and 8 bytes, strings (frame ids) and the covariance are constant, and the only varints that
change, a ``google.protobuf.Timestamp``'s seconds and nanoseconds, have lengths that change
only a few times a second. A step is therefore one of a few byte layouts (templates,
compiled once per pair of varint lengths and per kind of step: with every record, or with
the every-step ones only, :class:`Records` ``every``), and one compiled pass per chunk
(:func:`_fill_steps`) writes each step's template, doubles, record headers, varints and
index entries in turn. The protobuf written is canonical (shortest varints, fields in
order); NaN and infinities are just doubles.
"""

from __future__ import annotations

import struct

import numba
import numpy as np

from bioflex_jsb.simulation.step_kernel import guard_cache
from bioflex_jsb.sinks.mcap_io.protobuf import I64, LEN, VARINT, string_field, tag, varint
from bioflex_jsb.sinks.mcap_io.writer import OP_MESSAGE

# A record's pieces: bytes (constant), F (a double, the next column of the chunk's float
# matrix), SEC / NSEC (the timestamp's seconds / nanoseconds varint).
F, SEC, NSEC = "f", "sec", "nsec"
_HEAD = 20  # sequence (4), log time (8), publish time (8) after opcode, length, channel


def doubles(fields) -> list:
    """Pieces of scalar doubles: (field number) for each."""
    out = []
    for number in fields:
        out += [tag(number, I64), F]
    return out


def packed(number: int, n: int) -> list:
    return [tag(number, LEN) + varint(8 * n)] + [F] * n if n else []


def timestamp(number: int, ls: int, ln: int) -> list:
    """A google.protobuf.Timestamp field: seconds (1) and nanos (2) as varints of ls, ln
    bytes."""
    return [tag(number, LEN) + varint(2 + ls + ln) + b"\x08", (SEC, ls), b"\x10", (NSEC, ln)]


class _Layout:
    """The bytes of one step (records back to back) for given timestamp varint lengths: a
    template and where the doubles, record headers and varints go."""

    def __init__(self, records: list[tuple[int, list]]) -> None:
        template = bytearray()
        float_at, head_at, sec_at, nsec_at, self.record_offsets = [], [], [], [], []
        for cid, pieces in records:
            size = sum(8 if p == F else (p[1] if isinstance(p, tuple) else len(p))
                       for p in pieces)
            self.record_offsets.append(len(template))
            template += struct.pack("<BQH", OP_MESSAGE, _HEAD + 2 + size, cid)
            head_at.append(len(template))
            template += bytes(_HEAD)
            for p in pieces:
                if p == F:
                    float_at.append(len(template))
                    template += bytes(8)
                elif isinstance(p, tuple):  # (SEC or NSEC, width)
                    (sec_at if p[0] == SEC else nsec_at).append(len(template))
                    template += bytes(p[1])
                else:
                    template += p
        self.template = np.frombuffer(bytes(template), dtype=np.uint8)
        self.size = len(template)
        self.record_offsets = np.array(self.record_offsets, dtype=np.int64)
        self.float_at = np.array(float_at, dtype=np.int64)
        self.head_at = np.array(head_at, dtype=np.int64)
        self.sec_at = np.array(sec_at, dtype=np.int64)
        self.nsec_at = np.array(nsec_at, dtype=np.int64)


@numba.njit(cache=True, nogil=True)
def _write_varint(row, p, v, width):
    """``v`` (≥ 0) as a varint of exactly ``width`` bytes at ``row[p:]``."""
    for k in range(width - 1):
        row[p + k] = (v & 0x7F) | 0x80
        v >>= 7
    row[p + width - 1] = v & 0x7F


@numba.njit(cache=True, nogil=True)
def _varint_length(v):
    """The canonical (shortest) varint length of ``v`` ≥ 0 [bytes]."""
    n = 1
    while v >= 128:
        v >>= 7
        n += 1
    return n


# A step's layout code: (ls · 8 + ln) · 2 + (1 if the step carries every record, 0 if only
# the every-step ones), ls and ln its timestamp's varint lengths (0 without a timestamp);
# varints of times < 2^35 s are at most 5 bytes, so codes stay below this
_N_CODES = (5 * 8 + 5 + 1) * 2


@numba.njit(cache=True, nogil=True)
def _step_codes(ns, full, timestamped, code, hist):
    """Each step's layout code into ``code`` (its log time ``ns[r]`` [ns], ``full[r]`` 1 if
    it carries every record) and how many steps have each code into ``hist``."""
    for r in range(ns.shape[0]):
        c = full[r]
        if timestamped:
            t = ns[r]
            c += 2 * (8 * _varint_length(t // 1_000_000_000) + _varint_length(t % 1_000_000_000))
        code[r] = c
        hist[c] += 1


@numba.njit(cache=True, nogil=True)
def _fill_steps(flat, code, lut, templates, tpl_at, float_at, fa_at, head_at, record_at,
                ha_at, sec_at, sa_at, nsec_at, na_at, counter, float_bytes, ns, seq0, seq1,
                entries, counts):
    """Every step of a chunk into ``flat``, one after the other, step r in the layout
    ``lut[code[r]]`` (:func:`_step_codes`). The layouts are packed back to back: layout L's
    template is ``templates[tpl_at[L]:tpl_at[L + 1]]``, its doubles go at ``float_at``
    (entries ``fa_at[L]`` … ``fa_at[L + 1]`` − 1, offsets in the step), its record headers at
    ``head_at`` and its records start at ``record_at`` (entries ``ha_at[L]`` …), its seconds
    and nanoseconds varints at ``sec_at`` / ``nsec_at`` (``sa_at``, ``na_at``). A step gets
    its template; each record's header (log and publish time ``ns[r]``, little-endian;
    sequence: record j with ``counter[j]`` 0 counts the steps from ``seq0``, with 1 the
    steps that carry every record from ``seq1``); its doubles (``float_bytes``: the chunk's
    doubles as bytes, a row a step, the first ones for a layout of fewer records); the
    timestamp's varints; and each record's index entry (log time, offset in ``flat``) as
    entry ``counts[j]`` of ``entries[j]`` (records × steps × 2), counted. One pass over each
    step's bytes in memory order: structured numpy copies, writing one field across the
    whole chunk at a time (a pass over ~0.6 MB per field), cost 1.5-2× as much inside a run
    as alone, the run's own data evicted (measured in a gust run); and one call per
    chunk, whatever its layouts. The template and the step's doubles are read through views
    of their own (``tpl``, ``fb``): indexed ``templates[t0 + i]`` instead, the kernel took
    0.27-0.28 µs a step of the gust log's chunks against 0.14."""
    base = 0
    for r in range(code.shape[0]):
        c = code[r]
        lay = lut[c]
        t0 = tpl_at[lay]
        size = tpl_at[lay + 1] - t0
        row = flat[base:base + size]
        tpl = templates[t0:t0 + size]
        for i in range(size):
            row[i] = tpl[i]
        t = ns[r]
        h0 = ha_at[lay]
        for h in range(h0, ha_at[lay + 1]):
            j = h - h0
            seq = (seq1 if counter[j] else seq0) & 0xFFFFFFFF
            p = head_at[h]
            for k in range(4):
                row[p + k] = (seq >> (8 * k)) & 0xFF
            for k in range(8):
                byte = (t >> (8 * k)) & 0xFF
                row[p + 4 + k] = byte
                row[p + 12 + k] = byte
            e = counts[j]
            entries[j, e, 0] = t
            entries[j, e, 1] = base + record_at[h]
            counts[j] = e + 1
        f0 = fa_at[lay]
        fb = float_bytes[r]
        for j in range(f0, fa_at[lay + 1]):
            p, q = float_at[j], 8 * (j - f0)
            for k in range(8):
                row[p + k] = fb[q + k]
        ls, ln = c >> 4, (c >> 1) & 7
        if ls > 0:
            sec, nsec = t // 1_000_000_000, t % 1_000_000_000
            for i in range(sa_at[lay], sa_at[lay + 1]):
                _write_varint(row, sec_at[i], sec, ls)
            for i in range(na_at[lay], na_at[lay + 1]):
                _write_varint(row, nsec_at[i], nsec, ln)
        base += size
        seq0 += 1
        seq1 += c & 1


guard_cache(_write_varint)
guard_cache(_varint_length)
guard_cache(_step_codes)
guard_cache(_fill_steps)


def _packed_layouts(layouts: list[_Layout]) -> tuple[np.ndarray, ...]:
    """The arrays of ``layouts`` back to back, as :func:`_fill_steps` reads them."""
    def pack(arrays):
        at = np.zeros(len(arrays) + 1, dtype=np.int64)
        at[1:] = np.cumsum([len(a) for a in arrays])
        return np.concatenate(arrays).astype(np.int64), at

    float_at, fa_at = pack([lay.float_at for lay in layouts])
    head_at, ha_at = pack([lay.head_at for lay in layouts])
    record_at, _ = pack([lay.record_offsets for lay in layouts])
    sec_at, sa_at = pack([lay.sec_at for lay in layouts])
    nsec_at, na_at = pack([lay.nsec_at for lay in layouts])
    templates = np.concatenate([lay.template for lay in layouts])
    tpl_at = np.zeros(len(layouts) + 1, dtype=np.int64)
    tpl_at[1:] = np.cumsum([lay.size for lay in layouts])
    return (templates, tpl_at, float_at, fa_at, head_at, record_at, ha_at, sec_at, sa_at,
            nsec_at, na_at)


class Records:
    """A kind of step (one or more message records, each on its channel) whose records are
    built a chunk at a time: ``pieces(ls, ln)`` gives each record's pieces for timestamp
    varints of ``ls`` and ``ln`` bytes (ignored by records without a timestamp).

    ``every``: how many of the records (the first ones) are written at every step; the
    others only at the steps that :meth:`build` is told are sampled (None: all at every
    step). The doubles of the every-step records come first in each row."""

    def __init__(self, channel_ids: list[int], pieces, timestamped: bool,
                 every: int | None = None) -> None:
        self.ids = channel_ids
        self._pieces = pieces
        self.timestamped = timestamped
        self.every = len(channel_ids) if every is None else every
        if not 0 < self.every <= len(channel_ids):
            raise ValueError(f"every = {every}: 1 … {len(channel_ids)} records")
        self._layouts: dict[tuple[int, int, bool], _Layout] = {}
        self._packs: dict[tuple[int, ...], tuple[np.ndarray, ...]] = {}
        # the sequence number's counter of each record: 0 the steps, 1 the sampled steps
        self._counter = (np.arange(len(channel_ids)) >= self.every).astype(np.int64)

    def layout(self, ls: int, ln: int, full: bool = True) -> _Layout:
        """The layout of a step with timestamp varints of ``ls``, ``ln`` bytes, with every
        record (``full``) or only the every-step ones."""
        key = (ls, ln, full) if self.timestamped else (0, 0, full)
        lay = self._layouts.get(key)
        if lay is None:
            records = list(zip(self.ids, self._pieces(*key[:2]), strict=True))
            lay = self._layouts[key] = _Layout(records if full else records[:self.every])
        return lay

    def _pack(self, codes: np.ndarray) -> tuple[np.ndarray, ...]:
        key = tuple(codes.tolist())
        got = self._packs.get(key)
        if got is None:
            got = self._packs[key] = _packed_layouts(
                [self.layout(c >> 4, (c >> 1) & 7, bool(c & 1)) for c in key])
        return got

    def build(self, ns: np.ndarray, floats: np.ndarray, seq0: int,
              sampled: np.ndarray | None = None, sampled_seq0: int = 0
              ) -> tuple[memoryview, dict[int, np.ndarray]]:
        """The records of the steps at log times ``ns`` [ns] whose doubles are the rows of
        ``floats`` (in piece order), sequence numbers from ``seq0``; and their index entries
        ((log time, offset) per channel). ``sampled``: the indices (increasing) of the steps
        that also carry the records after the first ``every`` (None: all steps), whose
        sequence numbers count those steps from ``sampled_seq0``; the rows of the other
        steps need no doubles for them."""
        n = len(ns)
        if not n:
            return memoryview(b""), {cid: np.empty((0, 2), dtype=np.int64) for cid in self.ids}
        ns = np.ascontiguousarray(ns, dtype=np.int64)
        float_bytes = np.ascontiguousarray(floats, dtype="<f8").view(np.uint8)  # (n, 8 nf)
        if sampled is None:
            full = np.ones(n, dtype=np.int64)
        else:
            if self.every == len(self.ids) and len(sampled) != n:
                raise ValueError("these records have no sampled ones")
            full = np.zeros(n, dtype=np.int64)
            full[sampled] = 1
        code = np.empty(n, dtype=np.int64)
        hist = np.zeros(_N_CODES, dtype=np.int64)
        _step_codes(ns, full, self.timestamped, code, hist)
        codes = np.flatnonzero(hist)
        pack = self._pack(codes)
        lut = np.zeros(_N_CODES, dtype=np.int64)
        lut[codes] = np.arange(len(codes))
        flat = np.empty(int(hist[codes] @ np.diff(pack[1])), dtype=np.uint8)
        entries = np.empty((len(self.ids), n, 2), dtype=np.int64)
        counts = np.zeros(len(self.ids), dtype=np.int64)
        _fill_steps(flat, code, lut, *pack, self._counter, float_bytes, ns, seq0, sampled_seq0,
                    entries, counts)
        return memoryview(flat), {cid: entries[j, :counts[j]]
                                  for j, cid in enumerate(self.ids)}


def sample_steps(t_s: np.ndarray, rate_hz: float, bin_eps: float, last_bin: int | None
                 ) -> tuple[np.ndarray, int | None]:
    """The indices of the steps at times ``t_s`` [s] that are samples at ``rate_hz`` [Hz]:
    those whose time enters a new 1/rate bin, ``floor(t · rate + bin_eps)``, the first step
    too when ``last_bin`` (the bin of the step before, None: none) is None; and the bin of
    the last step (``last_bin`` when there are no steps)."""
    t = np.asarray(t_s, dtype=float)
    if not len(t):
        return np.empty(0, dtype=np.intp), last_bin
    bins = np.floor(t * rate_hz + bin_eps).astype(np.int64)
    prev = np.empty_like(bins)
    prev[0] = bins[0] - 1 if last_bin is None else last_bin
    prev[1:] = bins[:-1]
    return np.flatnonzero(bins != prev), int(bins[-1])


# -- the protobuf layout of one message -----------------------------------------------------
def size_of(parts) -> int:
    return sum(8 if p == F else (p[1] if isinstance(p, tuple) else len(p)) for p in parts)


def sub(number: int, parts: list) -> list:
    """A length-delimited sub-message of ``parts``."""
    return [tag(number, LEN) + varint(size_of(parts))] + parts


def dbl(number: int, value: float) -> bytes:
    return tag(number, I64) + struct.pack("<d", value)


def consts(number: int, values) -> list:
    return sub(number, [b"".join(dbl(i + 1, v) for i, v in enumerate(values))])


def entity_head(frame: str, entity_id: str) -> list:
    return [string_field(2, frame) + string_field(3, entity_id) + tag(5, VARINT) + b"\x01"]


