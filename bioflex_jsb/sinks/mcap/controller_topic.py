"""A gust run's controller on ``/bioflex/<model>/controller``.

``bioflex.Controller`` (:data:`~.schemas.SCHEMAS` ``["controller"]``): per step the commands
the controller wrote (``elevator_cmd_rad``, ``throttle_cmd``, ``flaperon_cmd_rad``,
``aileron_cmd_rad``:
increments over the trim, NaN for a command it does not write) and the signals it read
(``signals``, a packed array in the order the channel's metadata lists them). The run hands
the step rows over a block at a time (``drivers.gust.StepRecorder``'s optional
``controller``), and each block is written as a chunk of its own right after the steps'
chunk, so every chunk is in log-time order. The channel's metadata says what the controller
was (:func:`~bioflex_jsb.simulation.controller.controller_meta`) and the signals' trim
values.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from bioflex_jsb.sinks.mcap.schemas import PROTO_FIELDS, topic
from bioflex_jsb.sinks.mcap_io.records import Records, doubles, packed
from bioflex_jsb.sinks.mcap_io.writer import signals_deferred

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

GROUP = "controller"
COMMAND_FIELDS = {"ctrl_elevator_rad": "elevator_cmd_rad", "ctrl_throttle": "throttle_cmd",
                  "ctrl_flaperon_rad": "flaperon_cmd_rad", "ctrl_aileron_rad": "aileron_cmd_rad"}


def channel_metadata(model: str, meta: dict) -> dict[str, str]:
    """The controller channel's metadata (strings): the model, the controller's name, kind,
    signals (JSON list, the order of ``signals``), commands, states and sample time [s], and
    for a controller that flies flaperons their surface and derivatives (``flaperon``, JSON:
    :meth:`~bioflex_jsb.aeroelasticity.flaperon.FlaperonDerivatives.as_dict`), which the
    section loads of the log read back need."""
    extra = {"flaperon": json.dumps(meta["flaperon"])} if meta.get("flaperon") else {}
    return {**extra, "model": model, "name": str(meta["name"]), "kind": str(meta["kind"]),
            "signals": json.dumps(list(meta["inputs"])),
            "commands": ",".join(meta["outputs"]),
            "n_states": json.dumps(meta.get("n_states")), "dt_s": json.dumps(meta.get("dt_s")),
            "units": "elevator_cmd_rad rad, throttle_cmd -, flaperon_cmd_rad rad, "
                     "aileron_cmd_rad rad, signals: the channels' "
                     "(docs/api.md)"}


class ControllerTopic:
    """The controller of one run on ``/bioflex/<model>/controller`` (module docstring):
    ``names`` the run's channels (the table's columns), ``meta`` the controller's."""

    def __init__(self, writer: McapFileWriter, schema_id: int, model: str, names, meta: dict
                 ) -> None:
        self._writer = w = writer
        self.channel_id = w.add_channel(topic(model, GROUP), schema_id,
                                        channel_metadata(model, meta))
        w.flush()  # the channel on disk before its first message
        names = tuple(names)
        self.command_cols = [names.index(c) if c in names else -1 for c in COMMAND_FIELDS]
        self.signal_cols = np.array([names.index(s) for s in meta["inputs"]], dtype=np.intp)
        number = {name: num for name, num, _ in PROTO_FIELDS[GROUP]}
        pieces = doubles([number[f] for f in COMMAND_FIELDS.values()]) + \
            packed(number["signals"], len(self.signal_cols))
        self._records = Records([self.channel_id], lambda ls, ln: [pieces], timestamped=False)
        self.seq = 0
        self.messages = 0  # logged

    def rows(self, time_s: np.ndarray, rows: np.ndarray) -> None:
        """Log the controller's part of the step rows ``rows`` (steps × the run's channels)
        at ``time_s`` [s] as one chunk."""
        if not len(time_s):
            return
        n = len(time_s)
        k = len(self.command_cols)
        values = np.empty((n, k + len(self.signal_cols)))
        for j, c in enumerate(self.command_cols):
            values[:, j] = rows[:, c] if c >= 0 else np.nan
        values[:, k:] = rows[:, self.signal_cols]
        ns = np.rint(np.asarray(time_s, dtype=float) * 1e9).astype(np.int64)
        w = self._writer
        with signals_deferred():
            block, index = self._records.build(ns, values, self.seq)
            self.seq += n
            w.append_block(block, index)
            w.close_chunk()
            self.messages += n

    def stop(self) -> None:
        """The run is over: every block was written by :meth:`rows`."""
