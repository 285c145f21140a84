"""The process's memory allocator, told to keep what a run frees (glibc's malloc only).

A logged gust run allocates and frees a few MB of buffers every chunk (0.9 s of flight): the
steps' records, their compressed copy, the section loads, the 3-D scene. glibc's malloc hands
freed memory at the top of its heap back to the operating system as soon as more than its
trim threshold is free there (by default twice the largest block it has mapped, about 0.75
MB for these buffers), so each chunk's buffers come back as fresh pages, one page fault
each: 0.14-0.20 faults a step of a gust log, 0.01-0.08 of an unlogged run, at about 1 µs a
fault on this project's virtual machines (measured: 0.9-1.1 µs a 4 kB page
touched for the first time, Intel Xeon guest). :func:`keep_freed_memory` raises the
threshold, so freed memory stays in the process for the next chunk: no faults after the
first chunk (0.001-0.014 faults a step), at the price of up to ``trim_bytes`` held free.

The ``bioflex-jsb`` program calls it once at its start (``cli.main``); code that imports the
package is left with its allocator as it was (a library should not retune its host's
memory) and may call it itself.
"""

from __future__ import annotations

import ctypes
import platform

# glibc's mallopt parameters (malloc.h)
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
# DECISION: keep up to 64 MB free at the heap's top (a 60 s gust log's buffers are a few MB;
# the history table of a run of KEEP_ALL_MAX_S is ~17 MB) and map blocks of 32 MB or more
# on their own (glibc's own ceiling for its dynamic threshold), so the largest buffers are
# not returned on every free either
TRIM_BYTES = 64 * 1024 * 1024
MMAP_BYTES = 32 * 1024 * 1024


def keep_freed_memory(trim_bytes: int = TRIM_BYTES, mmap_bytes: int = MMAP_BYTES) -> bool:
    """Tell glibc's malloc to keep up to ``trim_bytes`` [bytes] of freed memory in the
    process and to map on their own only blocks of at least ``mmap_bytes`` [bytes] (module
    docstring). Returns whether the allocator took both settings: False on a C library
    other than glibc (musl, macOS, Windows), which is left as it is."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return False
    try:
        libc = ctypes.CDLL(None)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = (ctypes.c_int, ctypes.c_int)
    mallopt.restype = ctypes.c_int
    # mallopt returns 1 on success, 0 for a value it refuses
    return bool(mallopt(_M_MMAP_THRESHOLD, int(mmap_bytes))
                and mallopt(_M_TRIM_THRESHOLD, int(trim_bytes)))
