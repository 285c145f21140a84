"""The allocator setting of the program's process (bioflex_jsb.allocator): freed buffers
stay in the process, so buffers allocated again are not fresh pages."""

from __future__ import annotations

import platform
import subprocess
import sys

import pytest

# A child process: three 1 MB buffers, touched and freed, eight times over; the page faults
# of the last seven rounds (the first round's pages are new whatever the setting).
_ROUNDS = """
import resource, sys
import numpy as np
from bioflex_jsb.allocator import keep_freed_memory
took = keep_freed_memory() if sys.argv[1] == "keep" else None
def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
counts = []
for _ in range(8):
    f0 = faults()
    buffers = [np.ones(1 << 17) for _ in range(3)]  # 3 x 1 MB, every page written
    del buffers
    counts.append(faults() - f0)
print(took, sum(counts[1:]))
"""


def _faults(mode: str) -> tuple[str, int]:
    out = subprocess.run([sys.executable, "-c", _ROUNDS, mode], capture_output=True,
                         text=True, check=True).stdout.split()
    return out[0], int(out[1])


@pytest.mark.skipif(platform.system() != "Linux" or platform.libc_ver()[0] != "glibc",
                    reason="glibc's malloc only")
def test_freed_buffers_stay_in_the_process_once_told_to():
    took, kept = _faults("keep")
    _, default = _faults("default")
    assert took == "True"
    # kept: no page came back fresh (0 measured; bound: a few for the interpreter's own
    # growth). glibc's default hands most of the 3 MB back every round: 3643 faults in
    # seven rounds here (2026-12-03, transparent huge pages on madvise); where the kernel
    # backs the heap with huge pages ("always") a fault maps 2 MB and the count is far
    # smaller, so the default's count is only compared, not bounded
    assert kept < 100
    assert default > kept


def test_another_c_library_is_left_as_it_is(monkeypatch):
    from bioflex_jsb import allocator

    monkeypatch.setattr(allocator.platform, "libc_ver", lambda: ("", ""))
    assert allocator.keep_freed_memory() is False
