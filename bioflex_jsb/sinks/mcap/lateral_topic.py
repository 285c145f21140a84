"""A full-span run's antisymmetric wing on ``/bioflex/<model>/lateral``.

``bioflex.Lateral`` (:data:`~.schemas.SCHEMAS` ``["lateral"]``): per step JSBSim's aileron
δa, the elastic rolling moment, side force and yawing moment applied, the tip twist of each
half and the antisymmetric modal coordinates η_a, η̇_a (packed arrays, as the ``modal`` topic's η, η̇;
:mod:`bioflex_jsb.simulation.full_span`). The run hands the rows over a block at a time
(``drivers.gust.StepRecorder``'s optional ``lateral``), each block a chunk of its own after
the steps' chunk (log-time order), as the controller's topic does.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from bioflex_jsb.sinks.mcap.schemas import PROTO_FIELDS, topic
from bioflex_jsb.sinks.mcap_io.records import Records, doubles, packed
from bioflex_jsb.sinks.mcap_io.writer import signals_deferred

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

GROUP = "lateral"
# the run's channels → the message's scalar fields (the same names)
SCALARS = ("aileron_rad", "modal_roll_n_m", "tip_twist_starboard_rad", "tip_twist_port_rad",
           "modal_side_n", "modal_yaw_n_m")


def lateral_modes(names) -> int:
    """How many antisymmetric modes the run's channels ``names`` carry."""
    return sum(1 for n in names if n.startswith("asym_eta") and not n.endswith("_dot"))


class LateralTopic:
    """The antisymmetric wing of one run on ``/bioflex/<model>/lateral`` (module docstring);
    ``names`` the run's channels (the table's columns)."""

    def __init__(self, writer: McapFileWriter, schema_id: int, model: str, names) -> None:
        self._writer = w = writer
        names = tuple(names)
        n = lateral_modes(names)
        self.channel_id = w.add_channel(topic(model, GROUP), schema_id,
                                        {"model": model, "n_modes": str(n)})
        w.flush()  # the channel on disk before its first message
        self.cols = np.array([names.index(c) for c in (
            *SCALARS, *(f"asym_eta{i + 1}" for i in range(n)),
            *(f"asym_eta{i + 1}_dot" for i in range(n)))], dtype=np.intp)
        number = {name: num for name, num, _ in PROTO_FIELDS[GROUP]}
        pieces = doubles([number[f] for f in SCALARS]) + packed(number["asym_eta_rad"], n) \
            + packed(number["asym_eta_dot_rad_s"], n)
        self._records = Records([self.channel_id], lambda ls, ln: [pieces], timestamped=False)
        self.seq = 0
        self.messages = 0  # logged

    def rows(self, time_s: np.ndarray, rows: np.ndarray) -> None:
        """Log the lateral part of the step rows ``rows`` (steps × the run's channels) at
        ``time_s`` [s] as one chunk."""
        if not len(time_s):
            return
        n = len(time_s)
        ns = np.rint(np.asarray(time_s, dtype=float) * 1e9).astype(np.int64)
        w = self._writer
        with signals_deferred():
            block, index = self._records.build(ns, rows[:, self.cols], self.seq)
            self.seq += n
            w.append_block(block, index)
            w.close_chunk()
            self.messages += n

    def stop(self) -> None:
        """The run is over: every block was written by :meth:`rows`."""
