"""Waiting in tests by polling a condition with a deadline, never by a fixed sleep.

``wait_until(condition, timeout_s, what)`` returns the condition's first true value; after
``timeout_s`` [s] of wall time without one it fails with ``what`` (an AssertionError), so a
slow machine only makes a test slower, never wrong, and a fast one does not wait.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

T = TypeVar("T")

POLL_S = 0.01  # between two looks at the condition [s]: a deadline's granularity, no more


def wait_until(condition: Callable[[], T], timeout_s: float, what: str,
               poll_s: float = POLL_S) -> T:
    """Poll ``condition()`` until it is true (returned) or ``timeout_s`` [s] have passed
    (AssertionError naming ``what``)."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() >= deadline:
            raise AssertionError(f"{what}: not within {timeout_s:g} s")
        time.sleep(poll_s)
