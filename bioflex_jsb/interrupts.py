"""A stop request (SIGINT/SIGTERM) that cannot be raised where it landed: the flag the loops
check between steps, and the frames where a signal handler must not raise.

A Python signal handler runs at the next bytecode boundary of the main thread, wherever
that is. Two places cannot take an exception there:

* a Python function that native code calls back (JSBSim's logger, :func:`native_callback`):
  the C++ caller does not check for a Python error, so an exception raised inside ends as
  ``SystemError: <cyfunction FGFDMExec.run> returned a result with an exception set``;
* an import in progress: an extension module whose initialisation runs Python code turns the
  exception into ``ImportError: initialization failed``;
* a finalizer (a ``__del__`` method, a weakref callback: the garbage collector runs them at
  any bytecode boundary, numba's compiler drops many): Python prints an exception raised
  there as "Exception ignored in …" and goes on, so the stop is lost and its traceback
  printed (the re-delivered SIGINT of a deferred stop can land in llvmlite's
  ``ObjectRef.__del__`` while numba compiles on a fresh cache);
* llvmlite's bindings (``llvmlite/binding``, the Python wrappers that own LLVM objects, run
  while numba compiles or loads a kernel): an exception between an object's native free and
  its "closed" mark leaves it to be freed again by its finalizer (a "free(): double free"
  abort at exit of a stopped run).

The CLI's handler (:mod:`bioflex_jsb.cli.common`) looks at the interrupted frame and its
callers (:func:`unsafe_frame`); in such a frame it only sets :data:`STOP` ``.pending`` and
returns. The stop is then raised as ``KeyboardInterrupt`` at the first safe point: a loop's
check between steps (:func:`raise_if_stopped`, or ``STOP.pending`` read inline on a hot
path), the end of a block that captures JSBSim's output, or a re-delivery of the signal a
few milliseconds later (for code that has no check point, such as an import).

This module imports nothing of the project: every layer may read the flag.
"""

from __future__ import annotations

import importlib.util
import os
import weakref
from contextlib import contextmanager
from types import CodeType, FrameType


class StopFlag:
    """``pending``: a stop signal arrived in a frame that could not raise, and has not been
    raised yet (cleared by :func:`raise_if_stopped`). ``critical``: how many
    :func:`critical_section` blocks are running (a file's record half written: no frame is
    safe while one is)."""

    __slots__ = ("pending", "critical")

    def __init__(self) -> None:
        self.pending = False
        self.critical = 0


STOP = StopFlag()

_CALLBACK_CODES: set[CodeType] = set()
_IMPORT_FILES = ("<frozen importlib._bootstrap>", "<frozen importlib._bootstrap_external>")
# finalizers: any ``__del__``, and the module that runs weakref callbacks and finalize()
_FINALIZER_NAMES = ("__del__",)
_FINALIZER_FILES = (weakref.__file__,)
# the directories of wrappers of native objects (found without importing them)
_NATIVE_WRAPPER_DIRS = tuple(
    os.path.join(location, "binding") + os.sep
    for location in getattr(importlib.util.find_spec("llvmlite"), "submodule_search_locations",
                            None) or ())


def native_callback(func):
    """Mark ``func`` as called back by native code (decorator): a stop signal landing in it,
    or in anything it calls, is deferred to the next safe point instead of raised."""
    _CALLBACK_CODES.add(func.__code__)
    return func


def is_native_callback(func) -> bool:
    """Whether ``func`` was marked with :func:`native_callback`."""
    return getattr(func, "__code__", None) in _CALLBACK_CODES


@contextmanager
def critical_section():
    """A block that a stop must not cut in the middle (a log's chunk written and its offset
    and CRC counted): a stop signal whose handler runs inside it is deferred like one in
    native code (:func:`unsafe_frame`), then raised at the next safe point. Blocking the
    signals (``pthread_sigmask``) is not enough: a signal caught just before the block has
    its Python handler run at the block's first bytecodes (with the signals blocked only, a
    SIGINT of ``gust`` left 5 of 22 logs with a chunk counted twice)."""
    STOP.critical += 1
    try:
        yield
    finally:
        STOP.critical -= 1


def unsafe_frame(frame: FrameType | None) -> bool:
    """Whether an exception raised in ``frame`` now would cross native code that cannot
    carry it (``frame`` or one of its callers is a :func:`native_callback`, an import, a
    finalizer or a wrapper of native objects) or cut a :func:`critical_section`."""
    if STOP.critical:
        return True
    while frame is not None:
        code = frame.f_code
        if (code in _CALLBACK_CODES or code.co_filename in _IMPORT_FILES
                or code.co_name in _FINALIZER_NAMES or code.co_filename in _FINALIZER_FILES
                or code.co_filename.startswith(_NATIVE_WRAPPER_DIRS)):
            return True
        frame = frame.f_back
    return False


def raise_if_stopped() -> None:
    """A safe point: raise the deferred stop (``KeyboardInterrupt``) if one is pending."""
    if STOP.pending:
        STOP.pending = False
        raise KeyboardInterrupt
