"""A flooding source dropped by the kernel: a socket filter on a UDP socket.

Reading a datagram and dropping it by its source address costs Python about 2 µs (a 100k/s
flood: a fifth of a core), and a flood that fills the receive buffer pushes the peers'
datagrams out of it. So a source that sends more than :data:`FLOOD_RATE_PER_S` datagrams a
second (over :data:`WINDOW_S` of wall time) is *blocked*: a classic BPF program attached to
the socket (``SO_ATTACH_FILTER``, Linux) drops its datagrams before they are queued, at no
cost to the session and without taking buffer space, for :data:`BLOCK_S`; then it is let
through again, and blocked again if it still floods. At most :data:`MAX_BLOCKED` sources are
blocked at once. No peer sends at such rates (ArduPilot sends one frame and waits for the
reply; a ground station sends tens of messages a second), and the links never block their
bound peer. Where the kernel has no socket filters (not Linux) nothing is blocked: the flood
is read and dropped by its address, as it is before it is blocked.

The program, for the blocked (IPv4 address, port) pairs: load the source address (the IP
header, at ``SKF_NET_OFF + 12``) and the source port (the UDP header, at offset 0: the
filter of a UDP socket sees the datagram from its UDP header) and drop the datagram (return
0) on a match; accept it whole otherwise.
"""

from __future__ import annotations

import array
import socket
import struct
import sys

# DEFINITION: a source sending more than this is flooding [datagrams/s]: ArduPilot sends one
# frame per reply (and re-sends a frame once a second when it gets none), a ground station's
# messages come at tens a second (MAVLink's streams, at most 200 Hz each here, go the other
# way); 2000/s is a hundred times a busy ground station's and a fiftieth of the floods seen.
FLOOD_RATE_PER_S = 2000.0
WINDOW_S = 0.2  # the counting window [s of wall time]
BLOCK_S = 10.0  # how long a flooding source is blocked [s]
MAX_BLOCKED = 8  # sources blocked at once (the program grows by 4 instructions each)
MAX_COUNTED = 1024  # sources counted in one window (a flood from many ports: the first ones)

# linux/filter.h: classic BPF instruction classes and modes, the socket options
_BPF_LD_W_ABS = 0x00 | 0x00 | 0x20  # BPF_LD | BPF_W | BPF_ABS
_BPF_LD_H_ABS = 0x00 | 0x08 | 0x20  # BPF_LD | BPF_H | BPF_ABS
_BPF_JEQ_K = 0x05 | 0x10 | 0x00  # BPF_JMP | BPF_JEQ | BPF_K
_BPF_RET_K = 0x06 | 0x00  # BPF_RET | BPF_K
_SKF_NET_OFF = -0x100000  # a load relative to the network (IP) header
_SO_ATTACH_FILTER = getattr(socket, "SO_ATTACH_FILTER", 26)
_SO_DETACH_FILTER = getattr(socket, "SO_DETACH_FILTER", 27)
_INSN = struct.Struct("=HBBI")  # struct sock_filter: code, jt, jf, k


def filter_program(sources) -> bytes:
    """The classic BPF program (struct sock_filter[]) that drops datagrams from the
    (IPv4 address, port) pairs ``sources`` and accepts every other datagram whole."""
    out = []
    n = len(sources)
    for i, (host, port) in enumerate(sources):
        address = struct.unpack("!I", socket.inet_aton(host))[0]
        to_drop = 4 * (n - i - 1) + 1  # from the port test: the entries after, the accept
        out += [_INSN.pack(_BPF_LD_W_ABS, 0, 0, _SKF_NET_OFF + 12 & 0xFFFFFFFF),
                _INSN.pack(_BPF_JEQ_K, 0, 2, address),  # not this address: the next entry
                _INSN.pack(_BPF_LD_H_ABS, 0, 0, 0),
                _INSN.pack(_BPF_JEQ_K, to_drop, 0, int(port))]
    out += [_INSN.pack(_BPF_RET_K, 0, 0, 0xFFFFFFFF), _INSN.pack(_BPF_RET_K, 0, 0, 0)]
    return b"".join(out)


class FloodGuard:
    """Counts each source's datagrams on ``sock`` and blocks the flooding ones (module
    docstring). ``count(source)`` per datagram read; ``check(now)`` once per read batch
    (``now``: wall time [s], monotonic) returns the sources blocked and released by it."""

    def __init__(self, sock: socket.socket) -> None:
        self._sock = sock
        self.supported = sys.platform.startswith("linux")
        self.blocked: dict[tuple, float] = {}  # source -> blocked until [s]
        self.counts: dict[tuple, int] = {}
        self._window_start: float | None = None
        self.blocks = 0  # sources blocked so far (a source blocked again counts again)
        self.failure: str | None = None  # why the kernel refused the filter, if it did

    def count(self, source: tuple) -> None:
        counts = self.counts
        n = counts.get(source)
        if n is not None:
            counts[source] = n + 1
        elif len(counts) < MAX_COUNTED:
            counts[source] = 1

    def check(self, now: float, never: tuple | None = None) -> tuple[list, list]:
        """At the end of a window, block the sources that flooded in it (never ``never``,
        the bound peer); release those whose time is up. (blocked, released) sources."""
        if self._window_start is None:
            self._window_start = now
        released = [s for s, until in self.blocked.items() if now >= until]
        for s in released:
            del self.blocked[s]
        blocked = []
        span = now - self._window_start
        if span >= WINDOW_S:
            limit = FLOOD_RATE_PER_S * span
            for source, n in sorted(self.counts.items(), key=lambda kv: -kv[1]):
                if n <= limit or len(self.blocked) >= MAX_BLOCKED:
                    break
                if source != never and self.supported:
                    self.blocked[source] = now + BLOCK_S
                    blocked.append(source)
            self.counts.clear()
            self._window_start = now
        if blocked or released:
            try:
                self._apply()
            except OSError as exc:  # a kernel without socket filters for us: read as before
                self.failure = f"the kernel refused a socket filter ({exc.strerror or exc})"
                self.supported = False
                self.blocked.clear()
                return [], released
            self.blocks += len(blocked)
        return blocked, released

    def _apply(self) -> None:
        """Attach the program for the blocked sources (detach it when there is none)."""
        if not self.blocked:
            try:
                self._sock.setsockopt(socket.SOL_SOCKET, _SO_DETACH_FILTER, 0)
            except OSError:  # none attached
                pass
            return
        code = array.array("B", filter_program(list(self.blocked)))
        address, _ = code.buffer_info()  # the kernel copies the program while attaching
        fprog = struct.pack("@HP", len(code) // _INSN.size, address)  # struct sock_fprog
        self._sock.setsockopt(socket.SOL_SOCKET, _SO_ATTACH_FILTER, fprog)
