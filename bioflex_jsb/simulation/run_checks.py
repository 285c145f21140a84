"""The arguments of a gust run from the Python API, checked before anything is flown: one
line (InputError) per problem, saying what is accepted (``api.fly_gust``, ``api.compare``;
the CLI's own checks are in ``cli/case.py``)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import MODELS
from bioflex_jsb.simulation.gusts import GustSpec
from bioflex_jsb.simulation.modal_wing import MAX_DT_S, MIN_DT_S
from bioflex_jsb.simulation.run import check_run_length

TRIMS = ("rigid", "elastic")  # the rigid trim (the paper's reading), the static equilibrium


def finite_number(value, what: str) -> float:
    """``value`` as a finite float (InputError, one line, for anything else); ``what``
    names it, with its unit."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise InputError(f"{what} must be a number, got {value!r}")
    if not np.isfinite(value):
        raise InputError(f"{what} must be finite, got {value!r}")
    return float(value)


def check_run_arguments(gust: GustSpec, models, duration_s, gust_start_s, dt_s, trim,
                        recorders) -> tuple[tuple[str, ...], float, float, float]:
    """(models, duration_s [s], gust_start_s [s], dt_s [s]) checked: ``models`` a tuple of
    known names (a string of names is one name), ``0 < duration_s`` within the run limits
    (:func:`~bioflex_jsb.simulation.run.check_run_length`), ``0 <= gust_start_s`` and, with
    a ``gust``, before the end of the run; ``dt_s`` in MIN_DT_S..MAX_DT_S; ``trim`` one of
    :data:`TRIMS`; ``recorders`` (model → step recorder) for models that are flown."""
    if isinstance(models, str) or not isinstance(models, Iterable):
        raise InputError(f"models must be a tuple of model names ({', '.join(MODELS)}), "
                         f"got {models!r}")
    models = tuple(models)
    bad = [m for m in models if m not in MODELS]
    if not models or bad:
        raise InputError(f"unknown model {bad[0] if bad else models!r}; give one or more of "
                         f"{', '.join(MODELS)}")
    duration_s = finite_number(duration_s, "duration_s [s]")
    gust_start_s = finite_number(gust_start_s, "gust_start_s [s]")
    dt_s = finite_number(dt_s, "dt_s [s]")
    if duration_s <= 0.0:
        raise InputError(f"duration_s must be > 0 s, got {duration_s:g}")
    check_run_length(duration_s, dt_s, gust.kind in ("dryden", "vonkarman"))
    if gust_start_s < 0.0 or (gust.kind != "none" and gust_start_s >= duration_s):
        raise InputError(f"gust_start_s {gust_start_s:g} s must be within the run: 0 <= "
                         f"gust_start_s < duration_s ({duration_s:g} s)")
    if not MIN_DT_S <= dt_s <= MAX_DT_S:
        raise InputError(f"dt_s {dt_s:g} s is outside {MIN_DT_S:g}..{MAX_DT_S:g} s")
    if trim not in TRIMS:
        raise InputError(f"unknown trim {trim!r}; accepted: {', '.join(TRIMS)}")
    if recorders is not None:
        _check_recorders(recorders, models)
    return models, duration_s, gust_start_s, dt_s


def _check_recorders(recorders, models: tuple[str, ...]) -> None:
    if not isinstance(recorders, dict):
        raise InputError(f"recorders must be a dict model -> recorder, got {recorders!r}")
    unflown = sorted(set(recorders) - set(models))
    if unflown:
        raise InputError(f"recorders for {', '.join(unflown)}, which is not flown "
                         f"(models {', '.join(models)})")
    for model, rec in recorders.items():  # a file name: "'str' has no attribute start"
        if not all(callable(getattr(rec, m, None)) for m in ("start", "rows", "stop")):
            raise InputError(f"the recorder of {model} must be a StepRecorder (start, "
                             f"rows, stop: e.g. RunLog.open(path, …).recorder(model)), "
                             f"not {rec!r}")
