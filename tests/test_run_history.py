"""A gust run's rows on their way out: the history's columns are the table's, bit for bit,
and a run interrupted inside a block keeps every step it flew (the driver counts a block's
steps once, when the block ends or fails: drivers/gust.py ``_GustRun._block``)."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb.drivers.gust import COLUMN_BLOCK_ROWS, RunConfig, run_gust, table_columns
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust


@pytest.mark.parametrize("rows", [0, 1, COLUMN_BLOCK_ROWS - 1, COLUMN_BLOCK_ROWS,
                                  3 * COLUMN_BLOCK_ROWS + 7])
def test_columns_are_the_tables_columns_bit_for_bit(rows):
    rng = np.random.default_rng(rows)
    table = rng.normal(size=(rows + 3, 5)) * 10.0 ** rng.integers(-300, 300, size=(rows + 3, 5))
    table[0, 0] = np.nan
    names = ("a", "b", "c", "d", "e")
    got = table_columns(table[:rows], names)
    assert list(got) == list(names)
    for c, name in enumerate(names):
        want = table[:rows, c].copy()
        assert got[name].flags.c_contiguous and got[name].dtype == np.float64, name
        assert got[name].tobytes() == want.tobytes(), name  # NaN and every bit alike


class _Rows:
    """A recorder keeping how many rows it was handed and the count ``stop`` was told."""

    def __init__(self) -> None:
        self.handed, self.stopped_at = 0, None

    def start(self, names, dt_s) -> int:
        return 864

    def rows(self, time_s, rows) -> None:
        assert np.all(np.isfinite(rows[:, 0]))  # only flown rows
        self.handed += len(time_s)

    def stop(self, n) -> None:
        self.stopped_at = n


@pytest.mark.parametrize("at", [0, 500, 863, 864, 1000])
def test_a_run_interrupted_inside_a_block_keeps_every_step_it_flew(at):
    """Ctrl-C (KeyboardInterrupt, here from the per-step callback after step ``at``) inside
    a block of 864: the history and the recorder have steps 0..at, the recorder told so."""
    from bioflex_jsb.api import load_wing

    def on_sample(k, t_s, row):
        if k == at:
            raise KeyboardInterrupt

    recorder = _Rows()
    setup = RunConfig(15.0, parse_gust("sharp:3"), 1.5, 0.2)
    h = run_gust(Airframe(), load_wing().model, "coupled", setup, on_sample=on_sample,
                 recorder=recorder)
    assert h.meta["interrupted"] is True and h.meta["steps"] == at + 1
    assert len(h.time_s) == at + 1 and np.all(np.isfinite(h.channels["alpha"]))
    assert recorder.handed == at + 1 and recorder.stopped_at == at + 1
