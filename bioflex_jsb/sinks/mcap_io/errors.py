"""The MCAP sink's errors: one line each, for the user; the CLI maps them to exit status 2;
and the one way a log is opened for reading (:func:`open_log`)."""

from __future__ import annotations

import struct

from bioflex_jsb.errors import InputError
from bioflex_jsb.files import open_input

# Largest log read [bytes]: a regular file of at most this size (bioflex_jsb.files). The
# longest run allowed (simulation.run.MAX_STEPS, 5e7 steps) at ≈ 450 bytes a step
# (docs/logging.md) is ≈ 22 GB; a sitl file is at most --log-max-mb (≤ this, cli/sitl.py).
MAX_LOG_BYTES = 64 * 1024**3


class LogError(InputError):
    """A file that is not a readable, finished MCAP log, or whose run metadata cannot be
    read back (one line)."""


class LogWriteError(OSError):
    """A log file that cannot be written (one line)."""


def bad_data_errors() -> tuple[type[BaseException], ...]:
    """The exceptions that reading a damaged or foreign file raises (the ``mcap`` package's
    errors, CRC failures, short records, zstd frames, undecodable JSON or UTF-8); anything
    else is a bug and propagates."""
    import zstandard
    from mcap.exceptions import McapError
    from mcap.stream_reader import CRCValidationError

    return (McapError, CRCValidationError, struct.error, zstandard.ZstdError, EOFError,
            UnicodeDecodeError, ValueError)


def open_log(path):
    """The log ``path`` opened for reading (binary, unbuffered): a regular file of at most
    :data:`MAX_LOG_BYTES` (:func:`bioflex_jsb.files.open_input`); LogError otherwise (a
    FIFO, a device, ``/proc/self/mem``, a directory: one line, before reading a byte)."""
    return open_input(path, "log", MAX_LOG_BYTES, LogError)
