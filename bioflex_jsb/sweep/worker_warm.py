"""Imported by the local executor's forkserver (:data:`bioflex_jsb.sweep.local.PRELOAD`):
:func:`~bioflex_jsb.sweep.evaluate.warm_worker` runs once there, so every worker forked from
it starts with the simulation imported and the compiled step kernel loaded (measured: the
first case of a worker paid 1-2 s for them under load, the others ≈ 0.2 s)."""

from bioflex_jsb.sweep.evaluate import warm_worker

warm_worker()
