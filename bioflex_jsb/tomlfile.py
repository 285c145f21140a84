"""Reading the project's input files (variants, campaigns, modal data) with one-line errors.

Every input file goes through :func:`read_input_bytes`, which promises (docs/reliability.md):

* only a regular file is read: a FIFO, a device (``/dev/zero``), a socket or a directory is
  refused at once, without reading a byte (the file is opened non-blocking, so opening a
  FIFO with no writer does not hang, and checked with ``fstat`` on the open descriptor);
* at most ``limit`` bytes are read: a larger file is refused (checked on the size and again
  on what the read returns, so a file growing while it is read cannot exceed it either);
* text must be UTF-8, and TOML nested deeper than the parser's recursion allows (about
  1000 levels; the project's files nest fewer than 5) is refused.

Each refusal is the caller's ``error`` class with one line naming the file.
"""

from __future__ import annotations

import errno
import os
import stat
import tomllib
from pathlib import Path

MAX_TOML_BYTES = 16 * 1024 * 1024  # campaign and variant files: a few kB in practice


def _kind(mode: int) -> str:
    if stat.S_ISDIR(mode):
        return "a directory"
    if stat.S_ISFIFO(mode):
        return "a FIFO (named pipe)"
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        return "a device"
    if stat.S_ISSOCK(mode):
        return "a socket"
    return "not a regular file"


def _size(n: int) -> str:
    return f"{n / 1024 / 1024:.0f} MiB" if n >= 1024 * 1024 else f"{n} bytes"


def read_input_bytes(path: str | Path, what: str, error: type[Exception],
                     limit: int = MAX_TOML_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit``); else ``error`` (one line)."""
    p = Path(path)
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(p, flags)
    except FileNotFoundError:
        raise error(f"cannot read {what} {str(p)!r}: not found") from None
    except OSError as exc:
        if exc.errno == errno.ENXIO:  # a socket or a FIFO opened for writing only
            raise error(f"cannot read {what} {str(p)!r}: not a regular file") from None
        raise error(f"cannot read {what} {str(p)!r}: {exc.strerror}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"cannot read {what} {str(p)!r}: {_kind(st.st_mode)}, not a "
                        "regular file")
        if st.st_size > limit:
            raise error(f"cannot read {what} {str(p)!r}: {_size(st.st_size)}, more than "
                        f"the limit of {_size(limit)}")
        chunks, total = [], 0
        while True:
            chunk = os.read(fd, min(1 << 20, limit + 1 - total))
            if not chunk:
                break
            chunks.append(chunk)
            total += len(chunk)
            if total > limit:
                raise error(f"cannot read {what} {str(p)!r}: more than the limit of "
                            f"{_size(limit)}")
    except OSError as exc:
        raise error(f"cannot read {what} {str(p)!r}: {exc.strerror}") from None
    finally:
        os.close(fd)
    return b"".join(chunks)


def read_input_text(path: str | Path, what: str, error: type[Exception],
                    limit: int = MAX_TOML_BYTES) -> str:
    """:func:`read_input_bytes` decoded as UTF-8; a leading byte-order mark is refused in
    a line that says so (TOML does not allow one; tomllib said "Invalid statement (at line
    1, column 1)")."""
    data = read_input_bytes(path, what, error, limit)
    if data.startswith(b"\xef\xbb\xbf"):
        raise error(f"cannot read {what} {str(path)!r}: it starts with a UTF-8 byte-order "
                    "mark, which TOML does not allow; save it as UTF-8 without a BOM")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise error(f"cannot read {what} {str(path)!r}: not UTF-8 text (byte "
                    f"0x{data[exc.start]:02x} on line {line})") from None


def loads_toml(text: str, name: str, error: type[Exception]) -> dict:
    """``tomllib.loads`` with one-line errors (syntax, nesting too deep) naming ``name``."""
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{name} is not valid TOML: {' '.join(str(exc).split())}") from None
    except RecursionError:  # nesting deeper than the interpreter's recursion limit
        raise error(f"{name} nests arrays or tables too deep to parse (the project's "
                    "files nest fewer than 5 levels)") from None


def read_toml(path: str | Path, what: str, error: type[Exception],
              limit: int = MAX_TOML_BYTES) -> dict:
    """Parse the TOML file ``path``; any problem raises ``error`` with one line naming the
    file as a ``what`` (e.g. "variant file") and the reason."""
    text = read_input_text(path, what, error, limit)
    return loads_toml(text, f"{what} {str(path)!r}", error)
