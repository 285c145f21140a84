"""Who a MAVLink link talks to: its peers, the newcomers without a slot, and floods.

The peer bookkeeping of :class:`~bioflex_jsb.links.mavlink.MavlinkLink` (no sockets and no
codec here: the link reads, parses and sends).

Floods (UDP): what another local port sends must not crowd out the peers, nor cost the loop
more than a bounded share of its time. Each call of
:meth:`~bioflex_jsb.links.mavlink.MavlinkLink.service`

* reads up to :data:`MAX_DRAIN` datagrams, fewer when the call comes soon after the last
  (:data:`DRAIN_RATE_PER_S` datagrams a second of wall time since it, at least
  :data:`MIN_DRAIN`): at about 2 µs a datagram read and sorted that is at most about 20 %
  of the loop's time, whatever arrives, and a 100k/s flood is read as fast as it comes at
  1x, so the peers' datagrams behind it are reached instead of dropped by the kernel with
  the flood;
* sorts them by source address before any parsing: a peer's datagrams are parsed (up to
  :data:`PEER_DATAGRAMS_PER_CALL` and :data:`MAX_PARSE_BYTES` of each peer's per call), an
  unknown source's first :data:`NEW_SOURCE_DATAGRAMS_PER_CALL` of the call are parsed (a new
  ground station must be able to say hello, and its first messages come in a burst), its
  others are dropped unread (``unknown_dropped``), and so are those of sources beyond
  :data:`NEW_SOURCES_PER_CALL` in a call;
* asks the kernel for a receive buffer of :data:`RECV_BUFFER_BYTES` (``net.core.rmem_max``
  caps it), so a flood arriving between two calls waits instead of pushing a ground
  station's datagram out;
* counts each source's datagrams: one that sends more than 2000 a second is blocked in the
  kernel for 10 s at a time (:mod:`bioflex_jsb.links.udp_guard`; ``blocked``, a STATUSTEXT
  each time; a peer that floods loses its slot), so a flood from one source soon costs
  nothing at all.

A call that reads a full batch means the kernel may have dropped datagrams of anyone, the
peers' heartbeats too: while that happens, and for the link's peer timeout after
(:data:`~bioflex_jsb.links.mavlink.PEER_TIMEOUT_S`, 5 s), no peer is forgotten for its
silence, and the link says so once when the flood starts and once when it ends (STATUSTEXT
and the session log): at most two lines a flood.

Slots (``udpin``, :data:`MAX_PEERS`): a new source of valid MAVLink takes a free slot. When
all are taken, it takes the slot of the quietest unsigned peer if it has been heard more
than that one: *heard* is the number of the last :data:`PRESENCE_S` one-second intervals in
which a valid message came (a ground station's 1 Hz HEARTBEAT scores 4 or 5 of 5; one sent
every 2 s, 2 or 3; a flood cannot score more than 5); ties go to the peer heard longest ago;
while a flood is in progress no peer is evicted (its silence may be the flood's drops). The
eviction is said to every peer (STATUSTEXT, and the session log) before the evicted one goes.
A newcomer that cannot take a slot (every peer heard at least as much, or, with signing on,
every peer signed) is told so in one STATUSTEXT sent to it alone, at most once per peer
timeout for it and once a second in all, and the session log notes it; its messages are
still obeyed, as any sender's are. Up to :data:`MAX_CANDIDATES` such newcomers are
remembered (the least recently heard forgotten first).
"""

from __future__ import annotations

import math
import socket
import time
from collections.abc import Callable
from dataclasses import dataclass, field

from pymavlink.dialects.v20 import common as M

MAX_PEERS = 4
# Reads per service call (module docstring: Floods). The link is serviced every 5 ms of
# simulated time (drivers.sitl.LINK_PERIOD_S); a datagram read and sorted by its address
# costs about 2 us (the project's machine, a 100k/s flood: service calls of 500 reads took
# 1.0 ms at the median, 2.1 ms at p99): 100 000 reads a second of wall time since the last
# call keep up with a 100k/s flood at 1x and cost at most about 20 % of the loop's time at
# any speed-up.
MAX_DRAIN = 512
MIN_DRAIN = 32
DRAIN_RATE_PER_S = 100_000.0
PEER_DATAGRAMS_PER_CALL = 16  # a peer's datagrams parsed per call (the rest dropped)
MAX_PARSE_BYTES = 4096  # bytes of one peer handed to the parser per call
NEW_SOURCES_PER_CALL = 8  # unknown sources whose first datagrams of the call are parsed
NEW_SOURCE_DATAGRAMS_PER_CALL = 4  # datagrams of one unknown source parsed per call
MAX_CANDIDATES = 16  # newcomers without a slot remembered (their presence, their notice)
PRESENCE_S = 5  # one-second intervals of a peer's presence (module docstring: Slots)
# The receive buffer asked for [bytes]: Linux counts a small datagram at about 830 bytes of
# buffer, so its default (212 992) holds 256 of them, 2.6 ms of a 100k/s flood; 4 MiB hold
# about 5000 (net.core.rmem_max caps it for a user).
RECV_BUFFER_BYTES = 4 * 1024 * 1024


@dataclass
class LinkStats:
    received: int = 0  # valid MAVLink messages
    bad: int = 0  # bad-CRC / unparseable chunks
    datagrams: int = 0
    bytes_dropped: int = 0  # read but not parsed (over the per-call budget)
    rejected_signature: int = 0  # unsigned, wrongly signed or replayed (signing on)
    sent: int = 0
    send_dropped: int = 0
    peers_expired: int = 0
    peers_evicted: int = 0  # quietest peers whose slot a newcomer took
    peers_refused: int = 0  # newcomers told that no slot could be freed
    unknown_dropped: int = 0  # datagrams of unknown sources dropped unread (floods)
    peer_dropped: int = 0  # a peer's datagrams over its per-call share, dropped unread
    full_batches: int = 0  # service calls that read a full batch (a flood)
    floods: int = 0  # floods noticed (a full batch after none for PEER_TIMEOUT_S)
    recv_buffer_bytes: int = 0  # the receive buffer the kernel granted [bytes]
    blocked: int = 0  # flooding sources blocked in the kernel (links/udp_guard.py)
    by_type: dict[str, int] = field(default_factory=dict)  # bounded: MAVLink's message names


class Peer:
    """One conversation: its own parser (stream state), and for TCP its socket."""

    def __init__(self, addr, parser, sock: socket.socket | None = None,
                 now: float | None = None) -> None:
        self.addr = addr
        self.sock = sock
        self.parser = parser
        self.backlog = bytearray()
        self.last_seen = time.monotonic() if now is None else now
        self.fixed = False  # udpout's one destination: never expires
        self.signed = False  # a message of it passed the signature check
        self.heard = 0  # bit i: a valid message in the one-second interval `second` - i
        self.second = 0
        self.told_s = -math.inf  # when a newcomer was last told there is no slot [s]

    def hear(self, now: float, signed: bool) -> None:
        """A valid message at wall time ``now`` [s]."""
        self.presence(now)
        self.heard |= 1
        self.last_seen = now
        self.signed = self.signed or signed

    def presence(self, now: float) -> int:
        """In how many of the last PRESENCE_S one-second intervals it was heard."""
        second = int(now)
        shift = second - self.second
        if shift > 0:
            self.heard = (self.heard << min(shift, PRESENCE_S)) & ((1 << PRESENCE_S) - 1)
            self.second = second
        return self.heard.bit_count()


class Slots:
    """The peers of a link (``udpin``: at most :data:`MAX_PEERS`), the newcomers without a
    slot (at most :data:`MAX_CANDIDATES`), and the flood in progress (module docstring).

    ``notice(severity, text)``: a STATUSTEXT to every peer and an event of the session;
    ``tell(addr, text)``: one STATUSTEXT to one address that is not a peer; ``flush()``: the
    notices queued, sent now; ``drop(peer)``: a peer removed (its socket closed). Times are
    wall times [s] (monotonic); ``timeout_s`` is the link's peer timeout, read where the
    link calls (a test may change it)."""

    def __init__(self, stats: LinkStats, notice: Callable[[int, str], None],
                 tell: Callable[[tuple, str], None], flush: Callable[[], None],
                 drop: Callable[[Peer], None]) -> None:
        self.stats = stats
        self.peers: list[Peer] = []
        self.candidates: dict[tuple, Peer] = {}
        self._notice, self._tell, self._flush, self._drop = notice, tell, flush, drop
        self.flood_until = -math.inf  # peers are kept until then [s]
        self._flood_dropped0: int | None = None  # unknown_dropped when the flood began
        self._told_s = -math.inf  # when a newcomer was last told there is no slot [s]
        self._said_s = -math.inf  # when refusals were last noted to the peers [s]
        self._unsaid = 0  # refusals since

    def flooded(self, now: float, timeout_s: float) -> None:
        """A call read a full batch: keep the peers; say so when a flood begins."""
        self.stats.full_batches += 1
        if self._flood_dropped0 is None:
            self.stats.floods += 1
            self._flood_dropped0 = self.stats.unknown_dropped
            self._notice(M.MAV_SEVERITY_WARNING, "link flooded: datagrams of other sources "
                         "dropped unread; silent ground stations kept until it ends")
        self.flood_until = now + timeout_s

    def expire(self, now: float, timeout_s: float) -> None:
        """Forget the peers silent for ``timeout_s`` (none while a flood lasts); say when a
        flood is over."""
        if now < self.flood_until:  # their silence may be the flood's drops
            return
        if self._flood_dropped0 is not None:
            dropped = self.stats.unknown_dropped - self._flood_dropped0
            self._flood_dropped0 = None
            self._notice(M.MAV_SEVERITY_INFO, f"link flood over: {dropped} datagrams of "
                         "other sources dropped unread")
        for p in list(self.peers):
            if not p.fixed and now - p.last_seen > timeout_s:
                self._drop(p)
                self.stats.peers_expired += 1

    def candidate(self, addr, now: float, new_parser: Callable[[], object]) -> Peer:
        """The newcomer at ``addr``: remembered, or new (never heard: ``last_seen`` -inf)."""
        cand = self.candidates.pop(addr, None)
        if cand is None:
            cand = Peer(addr, new_parser(), now=now)
            cand.last_seen = -math.inf
        return cand

    def admit(self, cand: Peer, now: float, timeout_s: float) -> None:
        """A newcomer heard (valid, with signing on validly signed, MAVLink): a free slot,
        the quietest unsigned peer's, or a refusal (module docstring: Slots)."""
        if len(self.peers) < MAX_PEERS:
            self.peers.append(cand)
            return
        presence = cand.presence(now)
        unsigned = [p for p in self.peers if not p.signed and not p.fixed]
        quietest = min(unsigned, key=lambda p: (p.presence(now), p.last_seen), default=None)
        flooded = now < self.flood_until  # the peers' silence may be the flood's drops
        if quietest is not None and not flooded and presence > quietest.presence(now):
            self.stats.peers_evicted += 1
            self._notice(M.MAV_SEVERITY_WARNING,
                         f"ground station {addr_text(quietest.addr)} gave its slot to "
                         f"{addr_text(cand.addr)}: {MAX_PEERS} slots, it was the quietest "
                         f"(heard in {quietest.presence(now)} of the last {PRESENCE_S} s)")
            self._flush()  # the evicted one hears why
            self._drop(quietest)
            self.peers.append(cand)
            return
        self._refuse(cand, now, timeout_s,
                     "a flood is in progress" if flooded and quietest is not None else
                     "every peer is signed" if quietest is None else
                     f"each peer is heard at least as often ({presence} of {PRESENCE_S} s)")
        self.remember(cand)

    def _refuse(self, cand: Peer, now: float, timeout_s: float, why: str) -> None:
        """Tell a newcomer there is no slot (one STATUSTEXT to it, at most once per
        ``timeout_s`` for it and once a second in all: a reply to a spoofed source must not
        multiply a flood) and note it to the peers once per ``timeout_s``."""
        self.stats.peers_refused += 1
        if now - cand.told_s >= timeout_s and now - self._told_s >= 1.0:
            cand.told_s = self._told_s = now
            self._tell(cand.addr, f"no ground-station slot: {MAX_PEERS} taken")
        self._unsaid += 1
        if now - self._said_s >= timeout_s:
            self._said_s = now
            self._notice(M.MAV_SEVERITY_INFO,
                         f"{self._unsaid} message(s) of ground station(s) without a slot, "
                         f"last {addr_text(cand.addr)}: {MAX_PEERS} taken, {why}")
            self._unsaid = 0

    def remember(self, cand: Peer) -> None:
        """Keep a newcomer that has been heard (the least recently heard forgotten first)."""
        if cand.last_seen == -math.inf:
            return
        cands = self.candidates
        cands[cand.addr] = cand
        if len(cands) > MAX_CANDIDATES:
            del cands[min(cands, key=lambda a: cands[a].last_seen)]


def addr_text(addr) -> str:
    """``host:port``."""
    return f"{addr[0]}:{addr[1]}"
