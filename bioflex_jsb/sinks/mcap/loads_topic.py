"""The wing's section loads of a gust run on ``/bioflex/<model>/loads``.

``bioflex.SectionLoads`` (:data:`~.schemas.SCHEMAS` ``["loads"]``: the fields, their units
and signs): per method (``fs`` force summation, ``md`` mode displacement) and quantity
(shear [N], bending moment [N·m], torque [N·m]) a packed array over the monitoring
stations, one message per step at the step's log time. The run hands the loads over a
block at a time (``drivers.gust.StepRecorder``'s ``loads``), one step behind its steps (a
step's pitch acceleration is the central difference of q), and each block is written as a
chunk of its own right after the steps' chunk, so every chunk is in log-time order. The
channel's metadata holds what a reader needs to label the arrays: the stations, the
methods, the 1 g values and where the static part comes from.

The LTI prediction of ``compare`` carries its loads under the same field names on
``/bioflex/<model>/lti_prediction`` (:func:`prediction_loads`, written by
``RunLog.prediction``), so the nonlinear and the linear loads plot side by side.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

import numpy as np

from bioflex_jsb.sinks.mcap.schemas import PROTO_FIELDS, topic
from bioflex_jsb.sinks.mcap_io.records import Records, packed
from bioflex_jsb.sinks.mcap_io.writer import signals_deferred

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

GROUP = "loads"
TAGS = {"force_summation": "fs", "mode_displacement": "md"}
QUANTITIES = ("shear_n", "bending_n_m", "torque_n_m")  # bioflex_jsb.loads.QUANTITIES


def channel_metadata(model: str, layout: dict) -> dict[str, str]:
    """The loads channel's metadata (strings): the model, the stations [m] and their
    fractions of the semispan, the methods, the 1 g value of each field's elements (JSON:
    field → list over the stations, N or N*m), the static part's source and the density."""
    s = len(layout["stations_m"])
    static = {f"{TAGS[m]}_{q}": [layout["static_1g"][f"loads_{TAGS[m]}_{q}_s{j}"]
                                 for j in range(s)]
              for m in layout["methods"] for q in QUANTITIES}
    return {"model": model, "wing": str(layout.get("wing", "")),
            "stations_m": json.dumps(list(layout["stations_m"])),
            "station_fractions": json.dumps(list(layout["station_fractions"])),
            "methods": ",".join(layout["methods"]),
            "static_1g": json.dumps(static),
            "static": str(layout.get("note", "")),
            "density_kg_m3": repr(float(layout["density_kg_m3"])),
            "units": "shear N, bending N*m, torque N*m (docs/loads.md)"}


def _fields(layout: dict) -> tuple[list[str], list[str]]:
    """The topic's fields of ``layout``'s methods and the load columns they hold, in the
    topic's order (method, quantity, station)."""
    s = len(layout["stations_m"])
    fields = [f"{TAGS[m]}_{q}" for m in ("force_summation", "mode_displacement")
              if m in layout["methods"] for q in QUANTITIES]
    return fields, [f"loads_{f}_s{j}" for f in fields for j in range(s)]


def prediction_loads(history) -> tuple[tuple[tuple[str, int], ...], list[np.ndarray],
                                       dict[str, str]]:
    """The section loads of an LTI prediction (``drivers.compare.linear_prediction``: the
    run's load channels, totals with the run's 1 g part) for ``bioflex.LtiPrediction``:
    ((field, stations) in column order, the columns, the channel's metadata as the loads
    channel's). A prediction without loads (its run had none): empty."""
    layout = history.meta.get("loads")
    if not layout:
        return (), [], {}
    fields, names = _fields(layout)
    missing = [n for n in names if n not in history.channels]
    if missing:
        raise ValueError(f"the LTI prediction lacks the load channels {missing[:3]} of its "
                         "layout")
    n = len(layout["stations_m"])
    metadata = channel_metadata(history.model, layout)
    del metadata["model"]  # the prediction channel's own
    return (tuple((f, n) for f in fields),
            [np.asarray(history.channels[c], dtype=float) for c in names], metadata)


class LoadsTopic:
    """The loads of one run on ``/bioflex/<model>/loads`` (module docstring): ``layout`` is
    the run's ``meta["loads"]`` (names in column order: method, quantity, station)."""

    def __init__(self, writer: McapFileWriter, schema_id: int, model: str, layout: dict
                 ) -> None:
        self._writer = w = writer
        self.channel_id = w.add_channel(topic(model, GROUP), schema_id,
                                        channel_metadata(model, layout))
        w.flush()  # the channel on disk before its first message
        s = len(layout["stations_m"])
        number = {name: num for name, num, _ in PROTO_FIELDS[GROUP]}
        fields, expected = _fields(layout)
        if list(layout["names"]) != expected:
            raise ValueError(f"load columns {list(layout['names'])[:3]}… are not in the "
                             "topic's order (method, quantity, station)")
        pieces = []
        for f in fields:
            pieces += packed(number[f], s)
        self._records = Records([self.channel_id], lambda ls, ln: [pieces], timestamped=False)
        self.n_columns = len(expected)
        self.seq = 0
        self.messages = 0  # logged

    def rows(self, time_s: np.ndarray, values: np.ndarray) -> None:
        """Log the loads ``values`` (steps × columns) at ``time_s`` [s] as one chunk."""
        if not len(time_s):
            return
        values = np.asarray(values, dtype=float)
        if values.shape != (len(time_s), self.n_columns):
            raise ValueError(f"loads of shape {values.shape}, expected "
                             f"({len(time_s)}, {self.n_columns})")
        ns = np.rint(np.asarray(time_s, dtype=float) * 1e9).astype(np.int64)
        w = self._writer
        with signals_deferred():
            block, index = self._records.build(ns, values, self.seq)
            self.seq += len(ns)
            w.append_block(block, index)
            w.close_chunk()
            self.messages += len(ns)

    def stop(self) -> None:
        """The run is over: every block was written by :meth:`rows`."""
