"""A chunk's steps as protobuf message records, built at once by one compiled pass.

Every message of a step has a fixed protobuf layout: each double is a one- or two-byte tag
and 8 bytes, strings (frame ids) and the covariance are constant, and the only varints that
change, a ``google.protobuf.Timestamp``'s seconds and nanoseconds, have lengths that change
only a few times a second. A step is therefore one of a few byte layouts (templates,
compiled once per pair of varint lengths and per kind of step: with every record, or with
the every-step ones only, :class:`Records` ``every``), and one compiled pass per chunk
(:func:`_fill_steps`) writes each step's template, doubles, record headers, varints and
index entries in turn. A wing model's step is seven records, pose and location only at the
steps sampled at the rate log.py gives (:class:`_ModelChannels`). The protobuf written is
canonical (shortest varints, fields in order); NaN and infinities are just doubles.
"""

from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING

import numba
import numpy as np

from bioflex_jsb.simulation.step_kernel import guard_cache
from bioflex_jsb.sinks.mcap.protobuf import (
    I64,
    LEN,
    VARINT,
    length_delimited,
    string_field,
    tag,
    varint,
)
from bioflex_jsb.sinks.mcap.schemas import (
    _RIGID_FIELDS,
    _RIGID_OPTIONAL,
    PROTO_FIELDS,
    WORLD_FRAME,
    body_frame,
)
from bioflex_jsb.sinks.mcap.writer import _OP_MESSAGE

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap.log import RunLog

# A record's pieces: bytes (constant), F (a double, the next column of the chunk's float
# matrix), SEC / NSEC (the timestamp's seconds / nanoseconds varint).
F, SEC, NSEC = "f", "sec", "nsec"
STEP_GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location")
_HEAD = 20  # sequence (4), log time (8), publish time (8) after opcode, length, channel


def _doubles(fields) -> list:
    """Pieces of scalar doubles: (field number) for each."""
    out = []
    for number in fields:
        out += [tag(number, I64), F]
    return out


def _packed(number: int, n: int) -> list:
    return [tag(number, LEN) + varint(8 * n)] + [F] * n if n else []


def _timestamp(number: int, ls: int, ln: int) -> list:
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
            template += struct.pack("<BQH", _OP_MESSAGE, _HEAD + 2 + size, cid)
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


# the topics of a step written at every step; the others (SAMPLED_GROUPS: the 3-D panel's
# body pose and the map's fix, whose values rigid_body holds at every step) only at the
# steps sampled at the rate given to _ModelChannels
EVERY_STEP_GROUPS = STEP_GROUPS[:5]
SAMPLED_GROUPS = STEP_GROUPS[5:]


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


def sensor_columns(names) -> list[tuple[str, str, tuple[str, ...]]]:
    """The sensor stations among a run's channel ``names``: (kind ``imu`` or ``airspeed``,
    name, its channels in the topic's field order), in the names' order."""
    from bioflex_jsb.simulation.sensors import IMU_AXES

    have = set(names)
    out = []
    for c in names:
        if c.startswith("imu_") and c.endswith("_" + IMU_AXES[0]):
            name = c[len("imu_"):-len(IMU_AXES[0]) - 1]
            cols = tuple(f"imu_{name}_{a}" for a in IMU_AXES)
            if name and all(x in have for x in cols):
                out.append(("imu", name, cols))
        elif c.startswith("airspeed_") and c.endswith("_m_s") and len(c) > len("airspeed__m_s"):
            out.append(("airspeed", c[len("airspeed_"):-len("_m_s")], (c,)))
    return out


class _ModelChannels:
    """Channel ids and the protobuf records of one step of one wing model: seven messages
    (rigid_body … location), the last two (:data:`SAMPLED_GROUPS`) only at the steps
    sampled at ``rate_hz`` [Hz] (:func:`sample_steps` with ``bin_eps``; the rule and rate
    are the caller's, log.py's: the 3-D scene's, so the body pose and the wing drawn agree);
    :meth:`format` builds a chunk of steps at once."""

    def __init__(self, log: RunLog, model: str, names, rate_hz: float, bin_eps: float
                 ) -> None:
        self.names = tuple(names)
        self.rate_hz, self.bin_eps = float(rate_hz), float(bin_eps)
        col = {name: i for i, name in enumerate(self.names)}
        n = sum(1 for k in self.names if k.startswith("eta") and not k.endswith("_dot"))
        rate = {"rate_hz": repr(self.rate_hz),
                "sampling": "the first step of each 1/rate_hz of log time (the run's first "
                            "step too); every step: rigid_body"}
        self.ids = {g: log._channel_id(model, g, rate if g in SAMPLED_GROUPS else None)
                    for g in STEP_GROUPS}
        # the sensor stations' topics (every step, after the other every-step ones)
        sensors = sensor_columns(self.names)
        sensor_ids = [log._sensor_channel_id(model, kind, name, cols)
                      for kind, name, cols in sensors]
        sensor_pieces = [_doubles(range(1, len(cols) + 1)) for _, _, cols in sensors]
        self.seq = 0  # messages on each every-step topic so far (their sequence numbers)
        self.sampled_seq = 0  # messages on each sampled topic so far
        self.last_bin: int | None = None  # the sample bin of the last step formatted
        optional = [f for f, _ in _RIGID_OPTIONAL if f in col]
        rigid_keys = [k for _, k, _ in _RIGID_FIELDS] + optional
        modal_keys = [f"eta{i + 1}" for i in range(n)] + [f"eta{i + 1}_dot" for i in range(n)]
        # the raw columns copied as they are, in message order
        self.copy_cols = np.array([col[k] for k in (
            *rigid_keys, *modal_keys, "lift_n", "drag_n", "pitch_moment_n_m", "w_g",
            "elevator_rad", "throttle", *(c for _, _, cols in sensors for c in cols))],
            dtype=np.intp)
        self.i_lat, self.i_lon = col["latitude_rad"], col["longitude_rad"]
        self.i_alt = col["altitude_m"]
        self.i_att = [col["phi_rad"], col["theta_rad"], col["psi_rad"]]
        number = {name: num for name, num, _ in PROTO_FIELDS["rigid_body"]}
        rigid_numbers = [number[f] for f, _, _ in _RIGID_FIELDS] + [number[f] for f in optional]
        frame = body_frame(model)
        covariance = length_delimited(4, bytes(72)) + b"\x28\x00"  # 9 zeros, type 0

        def pieces(ls: int, ln: int) -> list[list]:
            ts_pose, ts_loc = _timestamp(1, ls, ln), _timestamp(6, ls, ln)
            return [
                _doubles(rigid_numbers),
                _packed(1, n) + _packed(2, n),
                _doubles((1, 2, 3)),
                _doubles((1,)),
                _doubles((1, 2)),
                *sensor_pieces,
                ts_pose + [string_field(2, WORLD_FRAME) + string_field(3, frame)
                           + tag(4, LEN) + varint(27)] + _doubles((1, 2, 3))
                + [tag(5, LEN) + varint(36)] + _doubles((1, 2, 3, 4)),
                ts_loc + [string_field(7, frame)] + _doubles((1, 2, 3)) + [covariance],
            ]

        ids = ([self.ids[g] for g in EVERY_STEP_GROUPS] + sensor_ids
               + [self.ids[g] for g in SAMPLED_GROUPS])
        self.records = Records(ids, pieces, timestamped=True,
                               every=len(EVERY_STEP_GROUPS) + len(sensor_ids))

    def floats(self, v: np.ndarray, origin, sampled: np.ndarray | None = None) -> np.ndarray:
        """The doubles of each step (rows of the raw values ``v``), in record order; those of
        pose and location only in the rows ``sampled`` (None: all; the others unset)."""
        lat0, lon0, h0, r_north, r_east = origin
        n, k = len(v), len(self.copy_cols)
        out = np.empty((n, k + 10))
        out[:, :k] = v[:, self.copy_cols]
        s = v if sampled is None else v[sampled]
        lat, lon, h = s[:, self.i_lat], s[:, self.i_lon], s[:, self.i_alt]
        qx, qy, qz, qw = enu_quaternion(*(s[:, i] for i in self.i_att))
        out[slice(None) if sampled is None else sampled, k:] = np.column_stack([
            (lon - lon0) * r_east, (lat - lat0) * r_north, h - h0,
            qx, qy, qz, qw, np.degrees(lat), np.degrees(lon), h])
        return out

    def format(self, t_s, v: np.ndarray, origin) -> tuple[memoryview, dict[int, np.ndarray]]:
        """The message records of the steps ``v`` (steps × channels in :attr:`names` order)
        at times ``t_s`` [s], the next steps of the model (its sequence numbers and sample
        bin carried on), and their index entries ((log time, offset) per channel)."""
        t = np.asarray(t_s, dtype=float)
        sampled, last_bin = sample_steps(t, self.rate_hz, self.bin_eps, self.last_bin)
        ns = np.rint(t * 1e9).astype(np.int64)
        out = self.records.build(ns, self.floats(v, origin, sampled), self.seq, sampled,
                                 self.sampled_seq)
        self.last_bin = last_bin
        self.seq += len(t)
        self.sampled_seq += len(sampled)
        return out


def lti_records(channel_id: int, n_eta: int, loads: tuple[tuple[str, int], ...] = ()
                ) -> Records:
    """The records of ``bioflex.LtiPrediction`` with ``n_eta`` modal coordinates and the
    section loads ``loads`` ((field, stations) in column order; none: empty fields)."""
    number = {name: num for name, num, _ in PROTO_FIELDS["lti_prediction"]}
    scalars = [number[f] for f in ("du_m_s", "dalpha_rad", "q_rad_s", "dtheta_rad", "n_z")]
    pieces = _doubles(scalars) + _packed(number["eta_rad"], n_eta)
    for field, n in loads:
        pieces += _packed(number[field], n)
    return Records([channel_id], lambda ls, ln: [pieces], timestamped=False)


class AutopilotRecords:
    """The records of ``bioflex.Autopilot`` on one channel, built a chunk at a time: every
    field is fixed-width (``fixed32`` integers, doubles, one-byte enum varints, always
    written, zeros included), so the messages of one PWM count share one layout, a numpy
    structured type over the record bytes (a record header, then the fields in number
    order)."""

    def __init__(self, channel_id: int) -> None:
        self.channel_id = channel_id
        self._dtypes: dict[int, tuple[np.dtype, dict[str, int]]] = {}
        number = {name: num for name, num, _ in PROTO_FIELDS["autopilot"]}
        self._number = number

    def _layout(self, n_pwm: int) -> tuple[np.dtype, dict[str, int]]:
        got = self._dtypes.get(n_pwm)
        if got is not None:
            return got
        from bioflex_jsb.sinks.mcap.protobuf import I32, VARINT

        num = self._number
        names, formats, offsets, consts = [], [], [], {}
        at = 0

        def put(name: str, fmt: str, size: int, const: int | None = None) -> None:
            nonlocal at
            names.append(name)
            formats.append(fmt)
            offsets.append(at)
            if const is not None:
                consts[name] = const
            at += size

        def const_bytes(label: str, data: bytes) -> None:
            for i, b in enumerate(data):
                put(f"{label}{i}", "u1", 1, b)

        put("op", "u1", 1, _OP_MESSAGE)
        put("length", "<u8", 8)
        put("channel", "<u2", 2, self.channel_id)
        put("sequence", "<u4", 4)
        put("log_ns", "<u8", 8)
        put("publish_ns", "<u8", 8)
        start = at
        for field in ("frame_count", "frame_rate_hz"):
            const_bytes(f"t_{field}", tag(num[field], I32))
            put(field, "<u4", 4)
        const_bytes("t_pwm", tag(num["pwm_us"], LEN) + varint(4 * n_pwm))
        put("pwm_us", f"({n_pwm},)<u4", 4 * n_pwm)
        for field in ("aileron_cmd_norm", "elevator_cmd_norm", "throttle_cmd_norm",
                      "rudder_cmd_norm"):
            const_bytes(f"t_{field}", tag(num[field], I64))
            put(field, "<f8", 8)
        for field in ("action", "phase"):
            const_bytes(f"t_{field}", tag(num[field], VARINT))
            put(field, "u1", 1)
        const_bytes("t_timestamp_s", tag(num["timestamp_s"], I64))
        put("timestamp_s", "<f8", 8)
        consts["length"] = 22 + at - start  # channel, sequence, times and the message
        dtype = np.dtype({"names": names, "formats": formats, "offsets": offsets,
                          "itemsize": at})
        self._dtypes[n_pwm] = (dtype, consts)
        return dtype, consts

    def build(self, ns: np.ndarray, seq0: int, frame_count, frame_rate_hz, pwm_us,
              commands, action, phase, timestamp_s) -> tuple[bytes, dict[int, np.ndarray]]:
        """The records of n frames at log times ``ns`` [ns] (sequence numbers from ``seq0``):
        ``pwm_us`` an (n, channels) array, ``commands`` (n, 4) (aileron, elevator, throttle,
        rudder), ``action`` and ``phase`` enum codes (< 128); and their index entries."""
        n = len(ns)
        pwm_us = np.asarray(pwm_us)
        dtype, consts = self._layout(pwm_us.shape[1])
        rec = np.zeros(n, dtype=dtype)
        for name, value in consts.items():
            rec[name] = value
        rec["sequence"] = (seq0 + np.arange(n)) & 0xFFFFFFFF
        rec["log_ns"] = ns
        rec["publish_ns"] = ns
        rec["frame_count"] = frame_count
        rec["frame_rate_hz"] = frame_rate_hz
        rec["pwm_us"] = pwm_us
        commands = np.asarray(commands, dtype=float)
        for j, field in enumerate(("aileron_cmd_norm", "elevator_cmd_norm",
                                   "throttle_cmd_norm", "rudder_cmd_norm")):
            rec[field] = commands[:, j]
        rec["action"] = action
        rec["phase"] = phase
        rec["timestamp_s"] = timestamp_s
        offsets = np.arange(n, dtype=np.int64) * dtype.itemsize
        return rec.tobytes(), {self.channel_id: np.column_stack([ns, offsets])}


def log_message(log_ns: int, level: int, text: str, name: str) -> bytes:
    """A ``foxglove.Log`` message (the events topic): its timestamp (the log time
    ``log_ns`` [ns], seconds and nanoseconds always written, as on the other Foxglove
    topics), ``level`` (``foxglove.Log.Level``), the ``text`` and the reporter's ``name``."""
    sec, nsec = divmod(int(log_ns), 1_000_000_000)
    stamp = b"\x08" + varint(sec) + b"\x10" + varint(nsec)
    return (length_delimited(1, stamp) + tag(2, VARINT) + varint(int(level))
            + string_field(3, text) + string_field(4, name))


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
