"""MCAP logs of runs: writing (every step of a run), reading back, recovering a killed log.

This is the only package that imports ``mcap``. Topics (protobuf messages whose schemas,
``FileDescriptorSet`` records, are in the file; older logs: JSON, still read;
``<model>`` is ``rigid``, ``coupled`` or ``qsd``; units in every field name and in the schema
descriptions; the full table is in ``docs/logging.md``):

* ``/bioflex/<model>/rigid_body`` (``bioflex.RigidBody``): perturbations from trim, the
  absolute attitude, body rates, airspeed, load factor, altitude (the position is on
  ``pose`` and ``location``);
* ``/bioflex/<model>/modal`` (``bioflex.Modal``): modal coordinates η [rad], rates η̇ [rad/s];
* ``/bioflex/<model>/modal_loads`` (``bioflex.ModalLoads``): the elastic wing's loads applied;
* ``/bioflex/<model>/gust`` (``bioflex.Gust``): the vertical gust w_g [m/s, up];
* ``/bioflex/<model>/controls`` (``bioflex.Controls``): elevator [rad], throttle [-];
* ``/bioflex/<model>/pose`` (``foxglove.FrameTransform``): ``world`` → ``<model>_body``, at
  60 Hz;
* ``/bioflex/<model>/location`` (``foxglove.LocationFix``): latitude, longitude [deg], altitude,
  at 60 Hz;
* ``/bioflex/<model>/lti_prediction`` (``bioflex.LtiPrediction``): the linear model's response
  to the same gust, where one ran alongside (:meth:`RunLog.prediction`);
* ``/bioflex/<model>/autopilot`` (``bioflex.Autopilot``): an ArduPilot SITL session's servo
  frames: ArduPilot's frame count and rate [Hz], the PWM values [µs], the mapped controls,
  the lock-step action and the launcher phase (:meth:`RunLog.autopilot`);
* ``/bioflex/events`` (``foxglove.Log``, one per file): what happened (a run that stopped, a
  SITL vehicle's STATUSTEXT): time, level, text, reporter (:meth:`RunLog.event`).

The run topics carry every step but ``pose`` and ``location`` (for Foxglove's 3D and Map
panels; ``rigid_body`` holds the same position and attitude at every step), which carry the
steps the 3-D scene samples: at :data:`.scene.SCENE_RATE_HZ` (60 Hz), the first step of each
1/60 s of log time (a run's first step too), the scene's own instants whether or not the log
has a scene (channel metadata ``rate_hz``; their sequence numbers count their own messages).

Frames: ``world`` is a local East-North-Up frame [m] whose origin is the aircraft's position
at the first sample of the file (flat-Earth tangent plane on the WGS-84 ellipsoid);
``<model>_body`` is the body frame with x forward, y to port (left), z up (FLU, as Foxglove and
ROS expect). Log and publish times are simulation time [ns from the run's start].

Metadata records: ``bioflex.run`` (the run description,
:class:`~bioflex_jsb.simulation.run.RunDescription`, as JSON, which ``rerun`` flies again;
readable copies of its wing, speed, gust and seed, models and time step; the wing variant and
overrides; package, JSBSim and mcap versions: :mod:`.metadata`) and ``bioflex.world_frame``
(the ENU origin).

Chunks are closed every :data:`CHUNK_SPAN_S` of simulated time (or :data:`CHUNK_WALL_S` of
wall time, or 4096 steps) and written to the operating system at once, so a process killed
hard (SIGKILL) loses at most the chunk in progress; :func:`recover` rebuilds an indexed
file from the intact chunks of such a log (skipping damaged ones) and :func:`check_chunks`
verifies every chunk (zstd checksum or CRC). A gust run hands the log a chunk of rows at a time
(:meth:`RunLog.recorder`, nothing per step) and a chunk's protobuf records are built at once
by one compiled pass (:mod:`.formatting`, ``docs/logging.md``, Encoding and Overhead).

The writer is our own (the ``mcap`` package's ``Writer`` costs ~6.5 µs per message, more than
the 20 % overhead budget allows at five messages per step and two at 60 Hz); every record
other than the messages in a chunk is serialised with the ``mcap`` package's record classes,
and the files are checked by independent readers in the tests (``@mcap/core``,
``pymcap-cli doctor``).

Modules: :mod:`.schemas` (topics, frames, fields, protobuf schemas), :mod:`.protobuf` (the
wire format, schemas and a decoder), :mod:`.foxglove_descriptors` (Foxglove's published
schemas), :mod:`.writer` (the MCAP file writer), :mod:`.formatting` (a chunk's steps as
protobuf records), :mod:`.log` (:class:`RunLog`, :class:`TableRecorder`,
:class:`AutopilotRecorder`), :mod:`.metadata` (the ``bioflex.run`` record),
:mod:`.reader` (summaries, messages), :mod:`.history` (a log's runs as time histories,
every channel), :mod:`.recover`, :mod:`.compare`
(two logs message by message), :mod:`.errors`. A sink takes a run description and the run's
data, never command-line arguments, and raises its own one-line errors
(:class:`LogError`, :class:`LogWriteError`), which the CLI reports.
"""

from bioflex_jsb.sinks.mcap.compare import compare_logs
from bioflex_jsb.sinks.mcap.formatting import enu_quaternion
from bioflex_jsb.sinks.mcap.history import READ_MAX_STEPS, histories
from bioflex_jsb.sinks.mcap.log import AutopilotRecorder, RunLog, TableRecorder
from bioflex_jsb.sinks.mcap.metadata import description_from_metadata, run_metadata
from bioflex_jsb.sinks.mcap.reader import (
    check_file,
    messages_by_topic,
    open_reader,
    read_metadata,
    summarise,
)
from bioflex_jsb.sinks.mcap.schemas import (
    AUTOPILOT_ACTIONS,
    AUTOPILOT_PHASES,
    EVENT_LEVELS,
    EVENTS_TOPIC,
    FRAME_METADATA,
    GROUPS,
    PROTO_SCHEMAS,
    RUN_METADATA,
    SCHEMAS,
    WORLD_FRAME,
    body_frame,
    topic,
)
from bioflex_jsb.sinks.mcap.writers import recover
from bioflex_jsb.sinks.mcap_io.errors import LogError, LogWriteError
from bioflex_jsb.sinks.mcap_io.recover import check_chunks
from bioflex_jsb.sinks.mcap_io.writer import (
    CHUNK_MAX_BYTES,
    CHUNK_SPAN_S,
    CHUNK_WALL_S,
    MAGIC,
    McapFileWriter,
)

__all__ = [
    "AUTOPILOT_ACTIONS", "AUTOPILOT_PHASES", "AutopilotRecorder",
    "CHUNK_MAX_BYTES", "CHUNK_SPAN_S", "CHUNK_WALL_S", "EVENTS_TOPIC", "EVENT_LEVELS",
    "FRAME_METADATA", "GROUPS", "MAGIC", "READ_MAX_STEPS",
    "PROTO_SCHEMAS", "RUN_METADATA", "SCHEMAS", "WORLD_FRAME", "LogError", "LogWriteError",
    "McapFileWriter",
    "RunLog", "TableRecorder", "body_frame", "check_chunks", "check_file", "compare_logs",
    "description_from_metadata", "enu_quaternion", "histories",
    "messages_by_topic", "open_reader", "read_metadata", "recover", "run_metadata",
    "summarise", "topic",
]
