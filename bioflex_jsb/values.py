"""What counts as a number in any input (definitions, variants, modal files, campaigns,
logs, API arguments): one place, so that every reader agrees.

A bool is never a number here, although Python's ``True == 1``: ``damping = true`` in a file
or ``speed_m_s=True`` in a call is a mistake, not 1. Numpy's scalars count (an API user's
``np.float64``); strings never do ("15" is refused, not parsed). Each reader keeps its own
one-line message, which names the field and what it accepts.
"""

from __future__ import annotations

import math
import numbers


def is_real(value) -> bool:
    """A real number (int, float, a numpy integer or float), not a bool; NaN and infinities
    included (see :func:`is_finite_real`)."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool)


def is_finite_real(value) -> bool:
    """A real number (:func:`is_real`) that is neither NaN nor infinite."""
    return is_real(value) and math.isfinite(value)


def is_whole(value) -> bool:
    """An integer (int or a numpy integer), not a bool; a float, even 3.0, is not."""
    return isinstance(value, numbers.Integral) and not isinstance(value, bool)
