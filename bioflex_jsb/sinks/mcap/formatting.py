"""A chunk's steps as protobuf message records, built at once by one compiled pass.

Every message of a step has a fixed protobuf layout: each double is a one- or two-byte tag
and 8 bytes, strings (frame ids) and the covariance are constant, and the only varints that
change, a ``google.protobuf.Timestamp``'s seconds and nanoseconds, have lengths that change
only a few times a second. A step is therefore one of a few byte layouts (templates,
compiled once per pair of varint lengths and per kind of step: with every record, or with
the every-step ones only, :class:`Records` ``every``), and one compiled pass per chunk
(:func:`_fill_steps`) writes each step's template, doubles, record headers, varints and
index entries in turn. A wing model's step is seven records, pose and location only at the
steps sampled at the rate log.py gives (:class:`ModelChannels`). The protobuf written is
canonical (shortest varints, fields in order); NaN and infinities are just doubles.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from bioflex_jsb.sinks.mcap.schemas import (
    PROTO_FIELDS,
    RIGID_FIELDS,
    RIGID_OPTIONAL,
    WORLD_FRAME,
    body_frame,
)
from bioflex_jsb.sinks.mcap_io.protobuf import (
    I64,
    LEN,
    VARINT,
    length_delimited,
    string_field,
    tag,
    varint,
)
from bioflex_jsb.sinks.mcap_io.records import Records, doubles, packed, sample_steps, timestamp
from bioflex_jsb.sinks.mcap_io.writer import OP_MESSAGE

STEP_GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location")


# the topics of a step written at every step; the others (SAMPLED_GROUPS: the 3-D panel's
# body pose and the map's fix, whose values rigid_body holds at every step) only at the
# steps sampled at the rate given to ModelChannels
EVERY_STEP_GROUPS = STEP_GROUPS[:5]
SAMPLED_GROUPS = STEP_GROUPS[5:]


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


class ModelChannels:
    """Channel ids and the protobuf records of one step of one wing model: seven messages
    (rigid_body … location), the last two (:data:`SAMPLED_GROUPS`) only at the steps
    sampled at ``rate_hz`` [Hz] (:func:`sample_steps` with ``bin_eps``; the rule and rate
    are the caller's, log.py's: the 3-D scene's, so the body pose and the wing drawn agree);
    :meth:`format` builds a chunk of steps at once."""

    def __init__(self, channel_id: Callable[[str, str, dict[str, str] | None], int], model: str,
                 names, rate_hz: float, bin_eps: float,
                 sensor_channel_id: Callable[[str, str, str, tuple[str, ...]], int]) -> None:
        self.names = tuple(names)
        self.rate_hz, self.bin_eps = float(rate_hz), float(bin_eps)
        col = {name: i for i, name in enumerate(self.names)}
        n = sum(1 for k in self.names if k.startswith("eta") and not k.endswith("_dot"))
        rate = {"rate_hz": repr(self.rate_hz),
                "sampling": "the first step of each 1/rate_hz of log time (the run's first "
                            "step too); every step: rigid_body"}
        self.ids = {g: channel_id(model, g, rate if g in SAMPLED_GROUPS else None)
                    for g in STEP_GROUPS}
        # the sensor stations' topics (every step, after the other every-step ones)
        sensors = sensor_columns(self.names)
        sensor_ids = [sensor_channel_id(model, kind, name, cols)
                      for kind, name, cols in sensors]
        sensor_pieces = [doubles(range(1, len(cols) + 1)) for _, _, cols in sensors]
        self.seq = 0  # messages on each every-step topic so far (their sequence numbers)
        self.sampled_seq = 0  # messages on each sampled topic so far
        self.last_bin: int | None = None  # the sample bin of the last step formatted
        optional = [f for f, _ in RIGID_OPTIONAL if f in col]
        rigid_keys = [k for _, k, _ in RIGID_FIELDS] + optional
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
        rigid_numbers = [number[f] for f, _, _ in RIGID_FIELDS] + [number[f] for f in optional]
        frame = body_frame(model)
        covariance = length_delimited(4, bytes(72)) + b"\x28\x00"  # 9 zeros, type 0

        def pieces(ls: int, ln: int) -> list[list]:
            ts_pose, ts_loc = timestamp(1, ls, ln), timestamp(6, ls, ln)
            return [
                doubles(rigid_numbers),
                packed(1, n) + packed(2, n),
                doubles((1, 2, 3)),
                doubles((1,)),
                doubles((1, 2)),
                *sensor_pieces,
                ts_pose + [string_field(2, WORLD_FRAME) + string_field(3, frame)
                           + tag(4, LEN) + varint(27)] + doubles((1, 2, 3))
                + [tag(5, LEN) + varint(36)] + doubles((1, 2, 3, 4)),
                ts_loc + [string_field(7, frame)] + doubles((1, 2, 3)) + [covariance],
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
    pieces = doubles(scalars) + packed(number["eta_rad"], n_eta)
    for field, n in loads:
        pieces += packed(number[field], n)
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
        from bioflex_jsb.sinks.mcap_io.protobuf import I32, VARINT

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

        put("op", "u1", 1, OP_MESSAGE)
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
