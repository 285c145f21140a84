"""Whether an unfinished log is still being written, or its writer died.

An MCAP log gets its summary and footer when its writer closes it, so an unfinished file is
either *being written* (a run in progress) or *cut off* (its writer was killed: SIGKILL,
power loss, a crash). The rule, in this order:

1. **An open descriptor for writing** (Linux): a process that has the file open with
   ``O_WRONLY`` or ``O_RDWR`` (``/proc/<pid>/fd`` and ``fdinfo``, matched by device and
   inode) is writing it: "being written by pid N". This is exact for the writers this
   user can see (every process of the same user; all of them for root); a writer on another
   machine (a network file system) or of another user is not visible, hence:
2. **Modified within RECENT_S** (any system): probably still being written. A log in
   progress is written at least once a second (a chunk per 0.9 s of simulated time in
   ``gust``; a SITL session's chunks every 24-96 steps), so a file untouched for longer has
   most likely lost its writer.
3. Otherwise: its writer was killed (``info --recover`` copies what it holds).
"""

from __future__ import annotations

import os
import time
from pathlib import Path

# A log in progress is modified at least every ~1 s (chunks); 10 s leaves a loaded machine
# (chunks delayed by a busy disk or CPU) a wide margin before "killed" is said.
RECENT_S = 10.0
_O_ACCMODE = 0o3  # the access mode bits of the open flags (O_RDONLY 0, O_WRONLY 1, O_RDWR 2)


def writing_pids(path: str | Path) -> list[int]:
    """Processes (other than this one) holding ``path`` open for writing, as far as
    ``/proc`` shows them; empty where there is no ``/proc``."""
    try:
        st = os.stat(path)
    except OSError:
        return []
    proc = Path("/proc")
    if not (proc / "self" / "fd").is_dir():
        return []
    target = os.path.realpath(path)
    found = []
    me = os.getpid()
    for entry in os.scandir(proc):
        if not entry.name.isdigit() or int(entry.name) == me:
            continue
        fd_dir = f"/proc/{entry.name}/fd"
        try:
            fds = os.listdir(fd_dir)
        except OSError:  # gone, or another user's
            continue
        for fd in fds:
            try:
                if os.readlink(f"{fd_dir}/{fd}") != target:
                    continue
                fst = os.stat(f"{fd_dir}/{fd}")
                with open(f"/proc/{entry.name}/fdinfo/{fd}") as info:
                    flags = next((int(line.split()[1], 8) for line in info
                                  if line.startswith("flags:")), 0)
            except OSError:  # closed meanwhile
                continue
            if (fst.st_dev, fst.st_ino) == (st.st_dev, st.st_ino) and flags & _O_ACCMODE:
                found.append(int(entry.name))
                break
    return sorted(found)


def unfinished_message(path: str | Path, missing: str = "no summary or footer") -> str:
    """One line for an unfinished log ``path`` lacking ``missing``: who is writing it, or
    that its writer was killed, and how to repair it (module docstring: the rule)."""
    name = str(path)
    recover = f"bioflex-jsb info {name!r} --recover FIXED.mcap"
    pids = writing_pids(path)
    if pids:
        return (f"{name!r} is still being written (open for writing by pid "
                f"{', '.join(map(str, pids))}; {missing} yet): it is finished when that run "
                f"ends; what it holds so far: {recover}")
    try:
        age_s = max(time.time() - os.stat(path).st_mtime, 0.0)
    except OSError:
        age_s = float("inf")
    if age_s < RECENT_S:
        return (f"{name!r} is unfinished ({missing}) and was modified {age_s:.1f} s ago: "
                f"probably still being written (no writer visible here); if its writer "
                f"was killed, {recover} repairs it")
    return (f"{name!r} is unfinished ({missing}): its writer was killed before closing it; "
            f"{recover} repairs it (every complete chunk)")


def recover(path: str | Path, out: str | Path) -> dict:
    """A killed or damaged log's intact chunks copied into the finished log ``out``
    (:func:`bioflex_jsb.sinks.mcap_io.recover.recover`), its library marked as bioflex-jsb's
    recovered copy."""
    from bioflex_jsb import __version__
    from bioflex_jsb.sinks.mcap_io.recover import recover as copy_intact

    return copy_intact(path, out, library=f"bioflex-jsb {__version__} (recovered)")
