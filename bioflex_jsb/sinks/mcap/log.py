"""The run log: an open MCAP file that runs write every step into.

A gust run hands its steps to the log a chunk at a time (:meth:`RunLog.recorder`: one call
per chunk of rows, nothing per step); a loop without a table (SITL) gives its steps as dicts
(:meth:`RunLog.sample`); an ArduPilot session adds its servo frames (:meth:`RunLog.autopilot`);
events (a run that stopped, a SITL vehicle's STATUSTEXT) are ``foxglove.Log`` messages on
``/bioflex/events`` (:meth:`RunLog.event`), in the chunk in progress in time order.
Messages are protobuf, built a chunk at a time (:mod:`.formatting`).
Chunks are closed every :data:`CHUNK_SPAN_S` of simulated time (or
:data:`CHUNK_WALL_S` of wall time, or 4096 steps) and handed to the operating system at once,
so a process killed hard loses at most the chunk in progress.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from itertools import chain
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from bioflex_jsb import __version__
from bioflex_jsb.sinks.mcap.formatting import (
    AutopilotRecords,
    ModelChannels,
    log_message,
    lti_records,
)
from bioflex_jsb.sinks.mcap.lateral_topic import lateral_modes
from bioflex_jsb.sinks.mcap.loads_topic import GROUP as LOADS_GROUP
from bioflex_jsb.sinks.mcap.loads_topic import LoadsTopic, prediction_loads
from bioflex_jsb.sinks.mcap.metadata import run_metadata
from bioflex_jsb.sinks.mcap.scene import SAMPLE_BIN_EPS, SCENE_RATE_HZ
from bioflex_jsb.sinks.mcap.schemas import (
    EVENT_LEVELS,
    EVENTS_PROTO_SCHEMA,
    EVENTS_TOPIC,
    FRAME_METADATA,
    PROTO_SCHEMAS,
    RUN_METADATA,
    WORLD_FRAME,
    sensor_group,
    topic,
)
from bioflex_jsb.sinks.mcap_io.errors import LogWriteError
from bioflex_jsb.sinks.mcap_io.writer import (
    CHUNK_SPAN_S,
    McapFileWriter,
    signals_deferred,
)

if TYPE_CHECKING:
    from bioflex_jsb.simulation.run import RunDescription

_WGS84_A_M = 6378137.0  # WGS-84 semi-major axis [m]
_WGS84_E2 = 6.69437999014e-3  # WGS-84 first eccentricity squared [-]


class RunLog:
    """An open MCAP file that runs write their samples into (see the module docstring)."""

    def __init__(self, path: Path, stream, writer: McapFileWriter) -> None:
        self.path = path
        self._stream = stream
        self._writer = writer
        self._schema_ids: dict[str, int] = {}
        self._models: dict[str, ModelChannels] = {}
        self._origin: tuple[float, float, float, float, float] | None = None
        # the steps of the chunk in progress: one model's, times [s] and value tuples
        self._ts: list[float] = []
        self._rows: list[tuple] = []
        self._pending: ModelChannels | None = None
        self._streams: list[AutopilotRecorder] = []  # their frames go into the same chunks
        self._events_id: int | None = None  # the events channel, made at the first event
        self.events = 0  # events logged
        self.scene = None  # the aircraft in 3-D (scene.SceneLog, RunLog.open(scene=)) or None
        # the scene's samples of the steps kept, written as a chunk of their own after the
        # steps' chunk (in it they would follow later steps and autopilot frames: out of
        # log-time order, which readers and `doctor --strict-message-order` refuse)
        self._scene_blocks: list = []
        # a controller in the loop of the sampled steps (log_controller): its meta, its topic
        # per model and the steps kept for it, written as chunks after the steps' (as a
        # recorded run's: TableRecorder.controller)
        self._controller_meta: dict | None = None
        self._controllers: dict[str, Any] = {}
        self._controller_rows: list[tuple[str, tuple[str, ...], np.ndarray, np.ndarray]] = []
        # the sampled steps of both wing halves (rows with asym_eta<i>): their antisymmetric
        # wing on /bioflex/<model>/lateral, chunks after the steps' (as a recorded run's:
        # TableRecorder.lateral)
        self._laterals: dict[str, Any] = {}
        self._lateral_rows: list[tuple[str, tuple[str, ...], np.ndarray, np.ndarray]] = []
        self._first_t = 0.0
        self._due_t = -math.inf  # the chunk closes at this simulated time …
        self._due_wall = 0.0  # … or at this wall (monotonic) time
        # the most bytes one step's messages took once formatted (size_bound's estimate of
        # the steps kept but not formatted yet; before any is formatted: 4 kB, a step of
        # ~0.6 kB with a wide margin)
        self._row_bytes, self._row_bytes_measured = 4096, False
        self.closed = False

    @classmethod
    def open(cls, path: str | Path, description: RunDescription,
             wing_variant: Mapping[str, Any] | None = None,
             overrides: Mapping[str, float] | None = None,
             scene: float | None = None, build=None) -> RunLog:
        """Create ``path`` and write the ``bioflex.run`` metadata of the run ``description``
        (:func:`~bioflex_jsb.sinks.mcap.metadata.run_metadata`; ``wing_variant``: the wing
        build's variant as a dict, ``overrides``: its coefficient overrides, plain data).
        ``scene``: also log the aircraft in 3-D (:mod:`.scene`, topics
        ``/bioflex/<model>/scene``) with this exaggeration of the deformation [-]; None: not;
        ``build``: the run's ``WingBuild`` the scene draws (its planform and airframe; default
        the wing built from ``wing_variant`` on the prototype's airframe).
        Served live (``--live``): :mod:`bioflex_jsb.sinks.live`, teed at the writer.
        A file that cannot be created is a :class:`LogWriteError` (one line)."""
        p = Path(path)
        meta = run_metadata(description, wing_variant, overrides)
        if build is not None:  # what each η_i does at the tip: how `plot` draws the modes
            import json

            from bioflex_jsb.simulation.channels import mode_tips

            meta["mode_tips"] = json.dumps(mode_tips(build.modes))
        try:
            stream = open(p, "wb")  # noqa: SIM115 - closed in close()
        except OSError as exc:
            raise LogWriteError(f"cannot write log {str(p)!r}: {exc.strerror}") from None
        log = cls.local(p, stream, meta)
        if scene is not None:
            from bioflex_jsb.sinks.mcap.scene import SceneLog

            log.scene = SceneLog.for_run(log._writer, description, wing_variant, scene,
                                         build=build)
        return log

    @classmethod
    def local(cls, path: Path, stream, meta: dict[str, str]) -> RunLog:
        writer = McapFileWriter(stream, library=f"bioflex-jsb {__version__}")
        log = cls(path, stream, writer)
        writer.add_metadata(RUN_METADATA, meta)
        writer.flush()  # header and run metadata on disk before the first step
        return log

    # -- channels -----------------------------------------------------------------------
    def schema_id(self, group: str) -> int:
        """The id of ``group``'s protobuf schema in this log, written at its first use."""
        if group not in self._schema_ids:
            name, data = PROTO_SCHEMAS[group]
            self._schema_ids[group] = self._writer.add_schema(name, "protobuf", data)
        return self._schema_ids[group]

    def channel_id(self, model: str, group: str, metadata: dict[str, str] | None = None
                   ) -> int:
        """A new channel of ``model``'s ``group`` topic (its schema written first if new)."""
        return self._writer.add_channel(topic(model, group), self.schema_id(group),
                                        {"model": model, **(metadata or {})})

    def sensor_channel_id(self, model: str, kind: str, name: str, columns) -> int:
        """The topic of the sensor ``name`` (``imu`` or ``airspeed``) of the run ``model``:
        ``/bioflex/<model>/<kind>_<name>`` (its metadata: the sensor, the run's channels
        it holds)."""
        group = "imu" if kind == "imu" else "airspeed_probe"
        return self._writer.add_channel(
            topic(model, sensor_group(kind, name)), self.schema_id(group),
            {"model": model, "sensor": name, "kind": kind, "channels": ",".join(columns),
             "axes": "the sensor's own (its mounting from body axes x forward, y starboard, "
                     "z down; docs/aircraft.md)"})

    def _model(self, model: str, names) -> ModelChannels:
        ch = self._models.get(model)
        if ch is None:
            # pose and location at the 3-D scene's samples (the scene's rate and rule, so
            # the body pose and the wing drawn agree), with or without a scene in the log
            rate = SCENE_RATE_HZ if self.scene is None else self.scene.rate_hz
            ch = self._models[model] = ModelChannels(self.channel_id, model, names, rate,
                                                     SAMPLE_BIN_EPS, self.sensor_channel_id)
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
        """A recorder of the run of ``model`` for ``run_gust(..., recorder=)``: it logs every
        step (a message on each run topic; pose and location at the 3-D scene's samples,
        :class:`~.formatting.ModelChannels`), handed a chunk of rows at a time, so a step
        costs the run nothing beyond its share of one call per chunk."""
        return TableRecorder(self, model)

    def sample(self, model: str, t_s: float, row: dict[str, float]) -> None:
        """Log one step given as a dict of channel values (a loop without a table, such as
        the SITL loop; a run of ``run_gust`` is logged faster by :meth:`recorder`). The
        steps are kept and formatted a chunk at a time; the chunk closes every CHUNK_SPAN_S
        of simulated time or CHUNK_WALL_S of wall time."""
        ch = self._models.get(model)
        if ch is None:
            ch = self._model(model, tuple(row))
        if (self._pending is None and not self._rows and self._first_t <= t_s < self._due_t
                and time.monotonic() < self._due_wall
                and any(s._frames for s in self._streams)):
            self._pending = ch  # the chunk of an autopilot's frames in progress: join it
        if (self._pending is not ch or not self._first_t <= t_s < self._due_t
                or time.monotonic() >= self._due_wall or len(self._rows) >= _MAX_PENDING_STEPS):
            self._next_chunk(ch, t_s)
        self._ts.append(t_s)
        self._rows.append(tuple([row[k] for k in ch.names]))

    def log_controller(self, meta: Mapping[str, Any]) -> None:
        """The steps :meth:`sample` is given hold a controller's commands and signals
        (``meta``: :func:`~bioflex_jsb.simulation.controller.controller_meta`): log them on
        ``/bioflex/<model>/controller`` (:mod:`.controller_topic`), a chunk after each of
        the steps' chunks."""
        self._controller_meta = dict(meta)

    def _next_chunk(self, ch: ModelChannels, t_s: float) -> None:
        """Close the chunk in progress (if any) and start one for ``ch`` at ``t_s``."""
        if self._rows or any(s._frames for s in self._streams):
            self.flush()
        self._pending = ch
        self._first_t = t_s
        # closes at the first step ≥ CHUNK_SPAN_S later (as in ns; a step's time is
        # rounded to ns), or after _MAX_PENDING_STEPS steps, or CHUNK_WALL_S of wall time
        # (LIVE_CHUNK_WALL_S while a live client is subscribed: writer.chunk_wall_s)
        self._due_t = t_s + CHUNK_SPAN_S - 0.5e-9
        self._due_wall = time.monotonic() + self._writer.chunk_wall_s  # short when live

    def _format_pending(self) -> None:
        """Serialise the kept steps into the chunk in progress (see ModelChannels.format)."""
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
        block, index = ch.format(ts[:n], v.reshape(n, len(ch.names)), self._origin)
        scene = None if self.scene is None else self.scene.build(
            next(m for m, c in self._models.items() if c is ch), ch.names, ts[:n],
            v.reshape(n, len(ch.names)))  # the 3-D scene's samples of these steps
        size = len(block) + (len(scene[0]) if scene else 0)  # the scene's bytes count too
        if self._controller_meta is not None:  # its steps, and a bound of their bytes
            model = next(m for m, c in self._models.items() if c is ch)
            self._controller_rows.append((model, ch.names, np.array(ts[:n], dtype=float),
                                          v.reshape(n, len(ch.names)).copy()))
            size += n * (CONTROLLER_STEP_BYTES + 8 * len(self._controller_meta["inputs"]))
        n_lateral = lateral_modes(ch.names)
        if n_lateral:  # both wing halves: their topic's steps, and a bound of their bytes
            model = next(m for m, c in self._models.items() if c is ch)
            self._lateral_rows.append((model, ch.names, np.array(ts[:n], dtype=float),
                                       v.reshape(n, len(ch.names)).copy()))
            size += n * (LATERAL_STEP_BYTES + 16 * n_lateral)
        if not self._row_bytes_measured or size > n * self._row_bytes:
            self._row_bytes = -(-size // n)  # the first measure, then the largest
            self._row_bytes_measured = True
        rows.clear()
        ts.clear()
        self._writer.append_block(block, index)
        if scene:
            self._scene_blocks.append(scene)

    def size_bound(self, more_steps: int = 0) -> int:
        """An upper bound [bytes] of this file's size if it were closed now after
        ``more_steps`` more steps (:meth:`McapFileWriter.size_bound`; the steps kept and
        the ones to come at the most bytes a step has taken, ``_row_bytes``). For a log of
        :meth:`sample` steps (and events); autopilot frames are not counted."""
        scene = sum(len(block) for block, _ in self._scene_blocks)  # not yet in the writer
        # the scene's samples go in a chunk of their own (flush): its overhead too (with the
        # 3.0 kB wing messages of 17 stations a file comes out 188 bytes over its limit
        # without it; 7.2 kB ones would hide it in the per-step margin)
        own_chunk = self._writer.chunk_overhead_bound() if self.scene is not None else 0
        return self._writer.size_bound((len(self._rows) + more_steps) * self._row_bytes
                                       + scene) + own_chunk

    def event(self, t_s: float, level: int | str, text: str, name: str = "bioflex-jsb") -> None:
        """An event at the log time ``t_s`` [s]: a ``foxglove.Log`` message on
        ``/bioflex/events`` (``level``: a ``foxglove.Log.Level`` name of
        :data:`~.schemas.EVENT_LEVELS`, DEBUG … FATAL, or its number; ``text``: what
        happened; ``name``: who reports it). It goes into the chunk in progress after the
        steps and frames kept so far (serialised now, the chunk stays open), so an event no
        earlier than the last step logged keeps the chunk, and the file, in log-time order.
        ValueError (one line) for an unknown level."""
        if isinstance(level, str):
            if level.upper() not in EVENT_LEVELS:
                raise ValueError(f"event level {level!r} is not one of "
                                 f"{', '.join(EVENT_LEVELS[1:])}")
            number = EVENT_LEVELS.index(level.upper())
        else:
            number = int(level)
            if not 0 <= number < len(EVENT_LEVELS):
                raise ValueError(f"event level {level!r} is not one of 0..{len(EVENT_LEVELS) - 1}")
        w = self._writer
        if self._events_id is None:
            schema_name, data = EVENTS_PROTO_SCHEMA
            sid = self._writer.add_schema(schema_name, "protobuf", data)
            self._events_id = w.add_channel(EVENTS_TOPIC, sid, {})
        with signals_deferred():
            self._format_pending()  # the steps before the event go first
            for stream in self._streams:
                stream._format()
            log_ns = int(round(t_s * 1e9))
            w.append(self._events_id, log_ns, self.events,
                     log_message(log_ns, number, str(text), str(name)))
            self.events += 1

    def autopilot(self, model: str) -> AutopilotRecorder:
        """The recorder of an autopilot's servo frames on ``/bioflex/<model>/autopilot``
        (``bioflex.Autopilot``: one message per frame, :meth:`AutopilotRecorder.frame`), in
        the same chunks as the run's steps (:meth:`sample`)."""
        for stream in self._streams:
            if stream.model == model:
                return stream
        stream = AutopilotRecorder(self, model)
        self._streams.append(stream)
        return stream

    def prediction(self, model: str, history) -> None:
        """Log the LTI prediction ``history`` (a ``TimeHistory`` of the linear model of
        ``model``) on ``/bioflex/<model>/lti_prediction``, one message per sample, with its
        section loads where it has them (:func:`~.loads_topic.prediction_loads`)."""
        fields, load_cols, metadata = prediction_loads(history)
        cid = self.channel_id(model, "lti_prediction", metadata)
        etas = sorted((k for k in history.channels if k.startswith("eta") and k[3:].isdigit()),
                      key=lambda k: int(k[3:]))
        t = np.asarray(history.time_s, dtype=float)
        zeros = np.zeros(len(t))
        cols = [np.asarray(history.channels.get(c, zeros), dtype=float)
                for c in ("u", "alpha", "q", "theta", "n_z", *etas)] + load_cols
        values = np.column_stack(cols) if cols else np.empty((len(t), 0))
        records = lti_records(cid, len(etas), fields)
        ns = np.rint(t * 1e9).astype(np.int64)
        w = self._writer
        self.flush()
        with signals_deferred():
            for k0 in range(0, len(t), _MAX_PENDING_STEPS):
                k1 = min(len(t), k0 + _MAX_PENDING_STEPS)
                block, index = records.build(ns[k0:k1], values[k0:k1], k0)
                w.append_block(block, index)
                w.close_chunk()

    def flush(self) -> None:
        """Write the kept steps as a chunk and hand it to the operating system."""
        with signals_deferred():
            self._format_pending()
            for stream in self._streams:
                stream._format()
            self._writer.close_chunk()
            if self._scene_blocks:
                for scene in self._scene_blocks:
                    self._writer.append_block(*scene)
                self._scene_blocks.clear()
                self._writer.close_chunk()
            for model, names, ts, rows in self._controller_rows:
                self._controller_topic(model, names).rows(ts, rows)  # a chunk each
            self._controller_rows.clear()
            for model, names, ts, rows in self._lateral_rows:
                self._lateral_topic(model, names).rows(ts, rows)  # a chunk each
            self._lateral_rows.clear()
        self._pending = None

    def _lateral_topic(self, model: str, names: tuple[str, ...]):
        """The lateral topic of ``model``'s sampled steps (made at its first rows)."""
        out = self._laterals.get(model)
        if out is None:
            from bioflex_jsb.sinks.mcap.lateral_topic import GROUP, LateralTopic

            out = self._laterals[model] = LateralTopic(self._writer, self.schema_id(GROUP),
                                                       model, names)
        return out

    def _controller_topic(self, model: str, names: tuple[str, ...]):
        """The controller topic of ``model``'s sampled steps (made at its first rows)."""
        out = self._controllers.get(model)
        if out is None:
            from bioflex_jsb.sinks.mcap.controller_topic import GROUP, ControllerTopic

            out = self._controllers[model] = ControllerTopic(
                self._writer, self.schema_id(GROUP), model, names, self._controller_meta)
        return out

    def close(self) -> None:
        """Finish the file (summary, indexes, footer) and close it; safe to call twice."""
        if not self.closed:
            try:
                self.flush()
                self._writer.finish()
            finally:
                self._writer.shutdown()
                self._stream.close()
                self.closed = True


_MAX_PENDING_STEPS = 4096  # also bounds the chunk size (~0.6 kB per step)
# A bound of a controller's message [bytes] but its signals (8 bytes each): the record's
# opcode, length, channel, sequence and two times (31), two tagged doubles and the signals'
# tag and length (21), its message-index entry (16), with room to spare.
CONTROLLER_STEP_BYTES = 80
# The same of a lateral message but its modal coordinates (16 bytes a mode: η and η̇): the
# record (31), four tagged doubles (36), two packed arrays' tags and lengths (4), its
# message-index entry (16), with room to spare.
LATERAL_STEP_BYTES = 96


def chunk_steps(dt_s: float) -> int:
    """Steps per chunk of a run at the step ``dt_s`` [s]: the first step at least
    CHUNK_SPAN_S after a chunk's first step begins the next chunk (at most
    _MAX_PENDING_STEPS)."""
    return max(1, min(_MAX_PENDING_STEPS, math.ceil((CHUNK_SPAN_S - 0.5e-9) / dt_s)))


class TableRecorder:
    """Logs a run's steps as the run hands them over, a chunk of rows at a time
    (``drivers.gust.StepRecorder``).

    ``start`` says how many steps a chunk holds (:func:`chunk_steps`: CHUNK_SPAN_S of
    simulated time); the run calls ``rows`` with each chunk's complete rows as soon as the
    chunk is flown (and with the rows left when it stops), and each call writes one chunk
    and hands it to the operating system. Writing holds SIGINT/SIGTERM, so an interrupt
    never logs a row twice or not at all.
    """

    def __init__(self, log: RunLog, model: str) -> None:
        self._log = log
        self._model = model
        self._ch: ModelChannels | None = None
        self.steps = 0  # rows logged

    def start(self, names, dt_s: float) -> int:
        """Before the first step: the channel names and the step [s]; returns the number of
        steps per chunk."""
        log = self._log
        log.flush()  # steps kept for another model go first
        self._ch = log._model(self._model, names)
        log._writer.flush()  # schemas and channels on disk before the first step
        return chunk_steps(dt_s)

    def rows(self, time_s: np.ndarray, rows: np.ndarray) -> None:
        """Log the complete rows ``rows`` (steps × channels, in the names' order) at the
        times ``time_s`` [s] as one chunk (the arrays may be reused once this returns)."""
        log, ch = self._log, self._ch
        if ch is None or not len(rows):
            return
        with signals_deferred():
            if log._origin is None:
                log._set_origin(*rows[0, [ch.i_lat, ch.i_lon, ch.i_alt]].tolist())
            block, index = ch.format(time_s, rows, log._origin)
            log._writer.append_block(block, index)
            log._writer.close_chunk()
            if log.scene is not None:  # its samples in a chunk of their own, after the
                # steps' (in one chunk they would follow later steps: out of log-time order)
                log.scene.rows(self._model, ch.names, time_s, rows)
                log._writer.close_chunk()
            self.steps += len(rows)

    def stop(self, n: int) -> None:
        """The run is over (``n`` complete rows): nothing is pending, every chunk was
        written by :meth:`rows`."""

    def controller(self, names, meta: dict):
        """The run's controller on ``/bioflex/<model>/controller`` (``names``: the run's
        channels, ``meta``: the controller's, ``simulation.controller.controller_meta``), a
        chunk per block after the steps' (:mod:`.controller_topic`)."""
        from bioflex_jsb.sinks.mcap.controller_topic import GROUP, ControllerTopic

        return ControllerTopic(self._log._writer, self._log.schema_id(GROUP), self._model,
                               names, meta)

    def lateral(self, names):
        """A full-span run's antisymmetric wing on ``/bioflex/<model>/lateral`` (``names``:
        the run's channels), a chunk per block after the steps' (:mod:`.lateral_topic`)."""
        from bioflex_jsb.sinks.mcap.lateral_topic import GROUP, LateralTopic

        return LateralTopic(self._log._writer, self._log.schema_id(GROUP), self._model, names)

    def loads(self, layout: dict):
        """The run's section loads on ``/bioflex/<model>/loads`` (``layout``: the run's
        ``meta["loads"]``), a chunk per block after the steps' (:mod:`.loads_topic`)."""
        out = LoadsTopic(self._log._writer, self._log.schema_id(LOADS_GROUP), self._model, layout)
        scene = self._log.scene  # with the scene: also drawn as markers (scene_loads.py)
        return out if scene is None else scene.with_loads(out, self._model, layout)


class AutopilotRecorder:
    """Logs an autopilot's servo frames (ArduPilot's JSON SITL) on
    ``/bioflex/<model>/autopilot``, one message per frame answered, formatted a chunk at a
    time with the run's steps (:meth:`RunLog.autopilot`)."""

    def __init__(self, log: RunLog, model: str) -> None:
        self._log = log
        self.model = model
        self._records = AutopilotRecords(log.channel_id(model, "autopilot"))
        self._frames: list[tuple] = []  # the frames of the chunk in progress
        self.seq = 0
        self.frames = 0  # frames logged

    def frame(self, t_s: float, frame_count: int, frame_rate_hz: int, pwm_us, commands,
              action: int, phase: int, timestamp_s: float) -> None:
        """One frame at the log time ``t_s`` [s]: ArduPilot's ``frame_count`` and
        ``frame_rate_hz`` [Hz], its ``pwm_us`` [µs] (16 or 32), the four mapped ``commands``
        (aileron, elevator, throttle, rudder [-]), the server's ``action`` and the ``phase``
        (enum codes: :data:`~.schemas.AUTOPILOT_ACTIONS`, :data:`~.schemas.AUTOPILOT_PHASES`)
        and the reply's physics time ``timestamp_s`` [s]. The chunk closes as
        :meth:`RunLog.sample`'s do."""
        log = self._log
        if (not log._first_t <= t_s < log._due_t or time.monotonic() >= log._due_wall
                or len(self._frames) >= _MAX_PENDING_STEPS):
            log._next_chunk(log._pending, t_s)
        self._frames.append((t_s, frame_count, frame_rate_hz, tuple(pwm_us), tuple(commands),
                             action, phase, timestamp_s))
        self.frames += 1

    def _format(self) -> None:
        """Serialise the kept frames into the chunk in progress (the caller holds signals)."""
        frames = self._frames
        n = len(frames)
        if not n:
            return
        start = 0
        for k in range(1, n + 1):  # runs of frames with the same number of PWM values
            if k < n and len(frames[k][3]) == len(frames[start][3]):
                continue
            run = frames[start:k]
            ns = np.rint(np.array([f[0] for f in run], dtype=float) * 1e9).astype(np.int64)
            block, index = self._records.build(
                ns, self.seq, [f[1] for f in run], [f[2] for f in run],
                np.array([f[3] for f in run], dtype=np.int64).reshape(len(run), -1),
                np.array([f[4] for f in run], dtype=float).reshape(len(run), 4),
                [f[5] for f in run], [f[6] for f in run], [f[7] for f in run])
            self.seq += len(run)
            self._log._writer.append_block(block, index)
            start = k
        del frames[:n]
