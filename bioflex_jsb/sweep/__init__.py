"""Parameter sweeps ("campaigns") of gust runs and LTI metrics.

* :mod:`~bioflex_jsb.sweep.campaign` (pure): campaign files, validation, case expansion,
  stable case ids, result columns.
* :mod:`~bioflex_jsb.sweep.evaluate`: one case in a worker (the row of inputs and metrics).
* :mod:`~bioflex_jsb.sweep.store`: results tables written as cases finish (CSV, Parquet).
* :mod:`~bioflex_jsb.sweep.local`, :mod:`~bioflex_jsb.sweep.dask_cluster`: executors (local
  processes; Dask, the only module importing it).
* :mod:`~bioflex_jsb.sweep.driver`: the loop joining them, with progress and resume.

``docs/sweeps.md`` describes the campaign format and the command.
"""
