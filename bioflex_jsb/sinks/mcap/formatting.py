"""Vectorised fixed-width formatting of a chunk's steps into MCAP message records.

A step of one wing model is seven JSON messages; with every number in fixed width each
record has a fixed length, so a chunk's steps are one (steps × bytes) array
(``docs/logging.md``, Overhead).
"""

from __future__ import annotations

import math
import struct
from typing import TYPE_CHECKING

import numpy as np

from bioflex_jsb.sinks.mcap.schemas import (
    _RIGID_FIELDS,
    _RIGID_OPTIONAL,
    GROUPS,
    WORLD_FRAME,
    body_frame,
)
from bioflex_jsb.sinks.mcap.writer import _OP_MESSAGE

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap.log import RunLog

NUMBER = "%.9g"  # numbers of the general path: 9 significant digits (relative ≤ 5e-10)
FIXED_NUMBER = "% .8e"  # fixed-width numbers of the fast path (same 9 significant digits)


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
