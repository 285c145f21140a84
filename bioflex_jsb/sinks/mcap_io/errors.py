"""The MCAP sink's errors: one line each, for the user; the CLI maps them to exit status 2."""

from __future__ import annotations

import struct

from bioflex_jsb.errors import InputError


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
