"""The arguments of a gust run from the Python API, checked before anything is flown: one
line (InputError) per problem, saying what is accepted (``api.fly_gust``, ``api.compare``;
the CLI's own checks are in ``cli/case.py``)."""

from __future__ import annotations

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.values import is_real


def finite_number(value, what: str) -> float:
    """``value`` as a finite float (InputError, one line, for anything else); ``what``
    names it, with its unit."""
    if not is_real(value):
        raise InputError(f"{what} must be a number, got {value!r}")
    if not np.isfinite(value):
        raise InputError(f"{what} must be finite, got {value!r}")
    return float(value)


def check_recorders(recorders, models: tuple[str, ...]) -> None:
    """``recorders`` (model → step recorder) for models that are flown; None: none."""
    if recorders is None:
        return
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
