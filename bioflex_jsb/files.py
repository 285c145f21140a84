"""Opening and reading the program's input files: the one place that does it.

The promise (docs/reliability.md): **every input file is a regular file of bounded size,
read with a bound.** Every reader of a file a user names, or a file names (definitions,
variants, campaigns, modal data, aircraft XML, signing keys, MCAP logs, model files,
result tables), opens it here:

* only a regular file is opened: a FIFO, a device (``/dev/zero``), a socket or a directory
  is refused at once, without reading a byte (the file is opened non-blocking, so opening a
  FIFO with no writer does not hang, and checked with ``fstat`` on the open descriptor);
  so is a file of the kernel's ``/proc`` or ``/sys`` (``/proc/self/mem`` is "regular" to
  ``fstat``, with size 0, and fails or never ends when read);
* the caller gives the size bound: a larger file is refused on its size before anything is
  read, and :func:`read_input_bytes` reads at most that many bytes (a file that grows
  while it is read cannot exceed it either);
* each refusal is the caller's ``error`` class (by default
  :class:`~bioflex_jsb.errors.InputError`: exit 2) with one line naming the file and why.

:func:`open_input` gives the checked file to a reader that reads it in bounded pieces
itself (an MCAP log, mapped or read record by record); :func:`read_input_bytes` and
:func:`read_input_text` read a whole small file.
"""

from __future__ import annotations

import errno
import os
import stat
from functools import cache
from pathlib import Path
from typing import BinaryIO

from bioflex_jsb.errors import InputError

MIB = 1024 * 1024


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


def size_text(n: int) -> str:
    """``n`` bytes for a message: whole MiB (GiB) above one, else bytes."""
    if n >= 1024 * MIB:
        return f"{n / 1024 / MIB:.0f} GiB"
    return f"{n / MIB:.0f} MiB" if n >= MIB else f"{n} bytes"


@cache
def _kernel_devices() -> frozenset[int]:
    """The devices of the kernel's pseudo file systems (``/proc``, ``/sys``): their files
    are "regular" with a size of 0 or 4096 whatever they hold."""
    devices = set()
    for root in ("/proc", "/sys"):
        try:
            devices.add(os.stat(root).st_dev)
        except OSError:  # not mounted here (not Linux, a container without /sys)
            pass
    return frozenset(devices)


def _name(path: str | Path) -> str:
    """The file name for a message: quoted, control characters escaped, cut at 200."""
    text = repr(str(path))
    return text if len(text) <= 200 else text[:150] + "…" + text[-40:]


def open_input(path: str | Path, what: str, limit: int,
               error: type[Exception] = InputError) -> BinaryIO:
    """The regular file ``path`` of at most ``limit`` bytes, opened for reading (binary,
    unbuffered); else ``error`` with one line naming it as a ``what`` (e.g. "log",
    "signing key"). The caller reads it with its own bound and closes it."""
    where = f"cannot read {what} {_name(path)}"
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    try:
        fd = os.open(path, flags)
    except FileNotFoundError:
        raise error(f"{where}: not found") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL in the name
        if isinstance(exc, OSError) and exc.errno == errno.ENXIO:  # a socket
            raise error(f"{where}: not a regular file") from None
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        if isinstance(exc, OSError) and exc.errno == errno.ENAMETOOLONG:
            why += f" ({len(os.fsencode(str(path)))} bytes)"
        raise error(f"{where}: {why}") from None
    opened = None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{where}: {_kind(st.st_mode)}, not a regular file")
        if st.st_dev in _kernel_devices():
            raise error(f"{where}: a file of the kernel's /proc or /sys, not a regular file "
                        "on a disk")
        if st.st_size > limit:
            raise error(f"{where}: {size_text(st.st_size)}, more than the limit of "
                        f"{size_text(limit)}")
        os.set_blocking(fd, True)  # a regular file: O_NONBLOCK only guarded the open
        opened = os.fdopen(fd, "rb", buffering=0)
        return opened
    finally:
        if opened is None:  # refused: the descriptor is not handed over
            os.close(fd)


def read_input_bytes(path: str | Path, what: str, limit: int,
                     error: type[Exception] = InputError) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` (:func:`open_input`),
    read with that bound; else ``error``, one line."""
    with open_input(path, what, limit, error) as f:
        chunks, total = [], 0
        try:
            while True:
                chunk = f.read(min(MIB, limit + 1 - total))
                if not chunk:
                    break
                chunks.append(chunk)
                total += len(chunk)
                if total > limit:
                    raise error(f"cannot read {what} {_name(path)}: more than the limit of "
                                f"{size_text(limit)}")
        except OSError as exc:
            raise error(f"cannot read {what} {_name(path)}: {exc.strerror or exc}") from None
    return b"".join(chunks)


def read_input_text(path: str | Path, what: str, limit: int,
                    error: type[Exception] = InputError) -> str:
    """:func:`read_input_bytes` decoded as UTF-8; a leading byte-order mark is refused in
    a line that says so (TOML does not allow one; tomllib said "Invalid statement (at line
    1, column 1)")."""
    data = read_input_bytes(path, what, limit, error)
    if data.startswith(b"\xef\xbb\xbf"):
        raise error(f"cannot read {what} {_name(path)}: it starts with a UTF-8 byte-order "
                    "mark, which TOML does not allow; save it as UTF-8 without a BOM")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise error(f"cannot read {what} {_name(path)}: not UTF-8 text (byte "
                    f"0x{data[exc.start]:02x} on line {line})") from None
