"""A chunk's steps as protobuf message records, built at once with numpy.

Every message of a step has a fixed protobuf layout: each double is a one- or two-byte tag
and 8 bytes, strings (frame ids) and the covariance are constant, and the only varints that
change, a ``google.protobuf.Timestamp``'s seconds and nanoseconds, have lengths that change
only a few times a second. The steps of a chunk are therefore split into runs of consecutive
steps whose varint lengths agree; within a run every step is the same byte layout (a
template, compiled once per pair of lengths) with the doubles, the record headers and the
varints written into their columns by one structured copy each. The protobuf written is
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


def varint_lengths(v: np.ndarray) -> np.ndarray:
    """Canonical varint lengths of non-negative integers < 2^35 (1 … 5 bytes)."""
    n = np.ones(len(v), dtype=np.int64)
    for k in (7, 14, 21, 28):
        n += v >= (1 << k)
    return n


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
def _fill_steps(flat, at, template, float_at, head_at, sec_at, nsec_at, record_at,
                float_bytes, ns, seq0, a, b, ls, ln, offsets):
    """Steps ``a`` … ``b`` − 1 of a chunk (one layout: timestamp varints of ``ls``, ``ln``
    bytes) into ``flat`` from byte ``at``, one step after the other: the template; each
    record's header (sequence seq0 + step, log and publish time ``ns``, little-endian) at
    ``head_at``; each double's 8 bytes (``float_bytes``: the chunk's doubles as bytes, a row a
    step) at ``float_at``; the timestamp's seconds and nanoseconds varints; and each record's
    offset into ``offsets`` (records × steps). One pass over each step's bytes in memory
    order: the structured numpy copies this replaces wrote one field across the whole chunk
    at a time (a pass over ~0.6 MB per field) and cost 1.5-2× as much inside a run as alone,
    the run's own data evicted (measured 2026-12-02)."""
    size = template.shape[0]
    nf = float_at.shape[0]
    for r in range(a, b):
        base = at + (r - a) * size
        row = flat[base:base + size]
        for i in range(size):
            row[i] = template[i]
        seq = (seq0 + r) & 0xFFFFFFFF
        t = ns[r]
        for h in range(head_at.shape[0]):
            p = head_at[h]
            for k in range(4):
                row[p + k] = (seq >> (8 * k)) & 0xFF
            for k in range(8):
                byte = (t >> (8 * k)) & 0xFF
                row[p + 4 + k] = byte
                row[p + 12 + k] = byte
        for j in range(nf):
            p, q = float_at[j], 8 * j
            for k in range(8):
                row[p + k] = float_bytes[r, q + k]
        if ls > 0:
            sec, nsec = t // 1_000_000_000, t % 1_000_000_000
            for p in sec_at:
                _write_varint(row, p, sec, ls)
            for p in nsec_at:
                _write_varint(row, p, nsec, ln)
        for j in range(record_at.shape[0]):
            offsets[j, r] = base + record_at[j]


guard_cache(_write_varint)
guard_cache(_fill_steps)


class Records:
    """A kind of step (one or more message records, each on its channel) whose records are
    built a chunk at a time: ``pieces(ls, ln)`` gives each record's pieces for timestamp
    varints of ``ls`` and ``ln`` bytes (ignored by records without a timestamp)."""

    def __init__(self, channel_ids: list[int], pieces, timestamped: bool) -> None:
        self.ids = channel_ids
        self._pieces = pieces
        self.timestamped = timestamped
        self._layouts: dict[tuple[int, int], _Layout] = {}

    def layout(self, ls: int, ln: int) -> _Layout:
        key = (ls, ln) if self.timestamped else (0, 0)
        lay = self._layouts.get(key)
        if lay is None:
            lay = self._layouts[key] = _Layout(list(zip(self.ids, self._pieces(ls, ln),
                                                        strict=True)))
        return lay

    def build(self, ns: np.ndarray, floats: np.ndarray, seq0: int
              ) -> tuple[memoryview, dict[int, np.ndarray]]:
        """The records of the steps at log times ``ns`` [ns] whose doubles are the rows of
        ``floats`` (in piece order), sequence numbers from ``seq0``; and their index entries
        ((log time, offset) per channel)."""
        n = len(ns)
        ns = np.ascontiguousarray(ns, dtype=np.int64)
        float_bytes = np.ascontiguousarray(floats, dtype="<f8").view(np.uint8)  # (n, 8 nf)
        if self.timestamped:
            sec, nsec = np.divmod(ns, 1_000_000_000)
            ls, ln = varint_lengths(sec), varint_lengths(nsec)
            cls = ls * 8 + ln
            cuts = np.flatnonzero(cls[1:] != cls[:-1]) + 1
            bounds = [0, *cuts.tolist(), n]
        else:
            ls = ln = None
            bounds = [0, n]
        runs = []
        for a, b in zip(bounds[:-1], bounds[1:], strict=True):
            if b > a:
                lay = self.layout(int(ls[a]), int(ln[a])) if self.timestamped else \
                    self.layout(0, 0)
                runs.append((a, b, lay, int(ls[a]) if self.timestamped else 0,
                             int(ln[a]) if self.timestamped else 0))
        flat = np.empty(sum((b - a) * lay.size for a, b, lay, _, _ in runs), dtype=np.uint8)
        offsets = np.empty((len(self.ids), n), dtype=np.int64)
        at = 0
        for a, b, lay, w_sec, w_nsec in runs:
            _fill_steps(flat, at, lay.template, lay.float_at, lay.head_at, lay.sec_at,
                        lay.nsec_at, lay.record_offsets, float_bytes, ns, seq0, a, b, w_sec,
                        w_nsec, offsets)
            at += (b - a) * lay.size
        index = {}
        for cid, offs in zip(self.ids, offsets, strict=True):
            entries = np.empty((n, 2), dtype=np.int64)
            entries[:, 0], entries[:, 1] = ns, offs
            index[cid] = entries
        return memoryview(flat), index


class _ModelChannels:
    """Channel ids and the protobuf records of one step of one wing model: seven messages
    (rigid_body … location); :meth:`format` builds a chunk of steps at once."""

    def __init__(self, log: RunLog, model: str, names) -> None:
        self.names = tuple(names)
        col = {name: i for i, name in enumerate(self.names)}
        n = sum(1 for k in self.names if k.startswith("eta") and not k.endswith("_dot"))
        self.ids = {g: log._channel_id(model, g) for g in STEP_GROUPS}
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
                ts_pose + [string_field(2, WORLD_FRAME) + string_field(3, frame)
                           + tag(4, LEN) + varint(27)] + _doubles((1, 2, 3))
                + [tag(5, LEN) + varint(36)] + _doubles((1, 2, 3, 4)),
                ts_loc + [string_field(7, frame)] + _doubles((1, 2, 3)) + [covariance],
            ]

        self.records = Records([self.ids[g] for g in STEP_GROUPS], pieces, timestamped=True)

    def floats(self, v: np.ndarray, origin) -> np.ndarray:
        """The doubles of each step (rows of the raw values ``v``), in record order."""
        lat0, lon0, h0, r_north, r_east = origin
        lat, lon, h = v[:, self.i_lat], v[:, self.i_lon], v[:, self.i_alt]
        qx, qy, qz, qw = enu_quaternion(*(v[:, i] for i in self.i_att))
        return np.column_stack([
            v[:, self.copy_cols], (lon - lon0) * r_east, (lat - lat0) * r_north, h - h0,
            qx, qy, qz, qw, np.degrees(lat), np.degrees(lon), h])

    def format(self, t_s, v: np.ndarray, seq0: int, origin) -> tuple[memoryview,
                                                                    dict[int, np.ndarray]]:
        """The message records of the steps ``v`` (steps × channels in :attr:`names` order)
        at times ``t_s`` [s] and their index entries ((log time, offset) per channel)."""
        ns = np.rint(np.asarray(t_s, dtype=float) * 1e9).astype(np.int64)
        return self.records.build(ns, self.floats(v, origin), seq0)


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
