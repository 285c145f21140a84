"""The live view: a run's log served as it is written over the Foxglove WebSocket protocol.

One :class:`LiveServer` per command (a SITL session's files come and go, the server stays):
the Foxglove SDK's WebSocket server (``foxglove-sdk``, the optional extra ``live``) on its
own SDK context. Each MCAP log the run writes is *teed* (:meth:`LiveServer.attach`: the
writer's ``on_chunk`` hook, :class:`~bioflex_jsb.sinks.mcap_io.writer.McapFileWriter`): every
chunk's message records, the bytes the file gets, are forwarded with the topic, schema
(name, encoding, the embedded ``FileDescriptorSet``), channel metadata and log time of the
file's channel, so a live client decodes exactly what Foxglove would read from the file.
An SDK channel is made per (topic, schema) at the first chunk that holds it and shared by
the session's files.

Cost and isolation:

* **No client subscribed**: a chunk costs a look-up of its new channels and one integer
  test; nothing per message (``docs/logging.md``, Live view: measured).
* **Clients subscribed**: the run's thread only puts the chunk (one ``bytes`` object) in a
  bounded queue (:data:`QUEUE_CHUNKS`); a sender thread splits it into messages and hands
  them to the SDK. A full queue drops the chunk (counted: ``dropped_chunks``,
  ``dropped_messages``), so the run never waits for the sender.
* **Slow or vanished clients**: the SDK queues at most :data:`BACKLOG_MESSAGES` messages per
  client and drops the oldest when a client does not read (measured: 200 000 messages of
  1 kB logged to a client that never reads, 2.5 µs a call, none blocked; ``tests/
  test_live.py`` runs a session with such a client).

Latency: a message is served when its chunk closes; while a client is subscribed (the
tee's ``subscribed``) the run log closes its chunks every ``LIVE_CHUNK_WALL_S`` = 20 ms of
wall time (``McapFileWriter.chunk_wall_s``; else ``CHUNK_WALL_S`` = 0.9 s), so a paced
session's message reaches the client ≈ 15 ms (median), 29 ms (p99) after its step
(``docs/logging.md``, Live view: measured), plus the sender's split (≈ 3 µs a message).
"""

from __future__ import annotations

import ipaddress
import queue
import struct
import threading
import time

DEFAULT_HOST = "127.0.0.1"
# Outgoing messages the SDK keeps per client before dropping the oldest: two chunks of a
# gust run (0.9 s at 960 Hz: 864 steps x 7 topics ≈ 6000 messages, plus 54 scene samples),
# so a client that keeps up never loses a message to a chunk's burst; ≈ 4 MB per client.
BACKLOG_MESSAGES = 16384
QUEUE_CHUNKS = 32  # chunks waiting for the sender thread (≥ 29 s of a run at 0.9 s each)
# At the end, the time [s] a subscribed client gets to receive the last chunk before the
# server stops (a 0.9 s chunk of 6000 messages reached a reading client here in < 0.1 s)
LINGER_S = 0.3
CLOSE_WAIT_S = 2.0  # at the end of a run, the longest the sender may take to empty its queue
# the longest the end of a run waits for the server to stop (a stalled client holds it: left
# to the process's exit, which it does not delay: measured)
STOP_WAIT_S = 2.0
# An MCAP Message record: opcode u8, record length u64, channel id u16, sequence u32, log
# time u64, publish time u64, then the message data (the record length counts from the
# channel id: 22 bytes of fields + the data)
_MESSAGE = struct.Struct("<BQHIQQ")
_DATA_AT = _MESSAGE.size  # 31
# The sender gives up the GIL every this many messages (≈ 0.2 ms of its work at ≈ 3 µs a
# message), so a paced loop (SITL: a step every 1.04 ms) never waits for a whole chunk's
# split (Python hands the GIL over only every 5 ms otherwise: sys.getswitchinterval)
_YIELD_EVERY = 64


class LiveError(Exception):
    """The live view cannot start: no SDK, an address it cannot bind (one line)."""


def is_loopback(host: str) -> bool:
    """Whether ``host`` is this machine only: ``localhost`` or a loopback address
    (127.0.0.0/8, ::1). Other names are not resolved: they count as the network."""
    if host.lower() == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class _Listener:
    """The SDK server's callbacks (its threads): the number of subscriptions held."""

    def __init__(self) -> None:
        self.subscriptions = 0
        self.clients: set[int] = set()
        self._lock = threading.Lock()

    def on_subscribe(self, client, channel) -> None:
        with self._lock:
            self.subscriptions += 1
            self.clients.add(client.id)

    def on_unsubscribe(self, client, channel) -> None:
        with self._lock:
            self.subscriptions = max(0, self.subscriptions - 1)


class LiveServer:
    """The Foxglove WebSocket server of one command's run (module docstring).

    ``host``/``port``: where to listen (port 0: any free one, :attr:`port` says which);
    ``name``: the server's name shown by Foxglove. :class:`LiveError` if the SDK is missing
    or the address cannot be bound."""

    def __init__(self, host: str = DEFAULT_HOST, port: int = 8765,
                 name: str = "bioflex-jsb") -> None:
        try:
            import foxglove
        except ImportError:
            raise LiveError("--live needs the Foxglove SDK: pip install "
                            "'bioflex-jsb[live]' (or foxglove-sdk)") from None
        self._fox = foxglove
        self._context = foxglove.Context()
        self._listener = _Listener()
        try:
            self._server = foxglove.start_server(
                name=name, host=host, port=port, context=self._context,
                server_listener=self._listener, message_backlog_size=BACKLOG_MESSAGES)
        except RuntimeError as exc:  # the SDK's error for an address it cannot bind
            raise LiveError(f"--live {host}:{port}: cannot listen there ({exc})") from None
        self.host = host
        self.port = int(self._server.port)
        self._channels: dict[tuple, object] = {}  # (topic, schema…) -> SDK channel
        self._queue: queue.Queue = queue.Queue(maxsize=QUEUE_CHUNKS)
        self.chunks = 0  # chunks queued for the clients
        self.sent_messages = 0  # messages handed to the SDK
        self.dropped_chunks = 0  # chunks the sender had no room for
        self.dropped_messages = 0
        self._sender = threading.Thread(target=self._send_loop, name="bioflex-live",
                                        daemon=True)
        self._sender.start()
        self.closed = False
        self.stop_held = False  # a client that did not read held the server's stop

    @property
    def url(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"ws://{host}:{self.port}"

    @property
    def clients(self) -> int:
        """Clients that subscribed to something during the run."""
        return len(self._listener.clients)

    def attach(self, log) -> None:
        """Serve what the open run log ``log`` (a ``RunLog``) writes from now on."""
        tee = _Tee(self)
        log._writer.on_chunk = tee

    def _channel(self, channel, schemas) -> object:
        schema = schemas[channel.schema_id - 1] if channel.schema_id else None
        key = (channel.topic, channel.message_encoding,
               None if schema is None else (schema.name, schema.encoding, schema.data))
        ch = self._channels.get(key)
        if ch is None:
            fox = self._fox
            ch = self._channels[key] = fox.Channel(
                channel.topic, message_encoding=channel.message_encoding,
                schema=None if schema is None else fox.Schema(
                    name=schema.name, encoding=schema.encoding, data=bytes(schema.data)),
                context=self._context, metadata=dict(channel.metadata))
        return ch

    def _offer(self, data: bytes, by_id: dict) -> None:
        """A chunk for the clients (the run's thread): queued, or dropped if the queue is
        full; nothing when no client subscribes to anything."""
        if not self._listener.subscriptions:
            return
        if type(data) is not bytes:  # a view of the writer's buffers: copied while valid
            data = bytes(data)
        try:
            self._queue.put_nowait((data, by_id))
            self.chunks += 1
        except queue.Full:
            self.dropped_chunks += 1
            self.dropped_messages += _count(data)

    def _send_loop(self) -> None:
        while True:
            item = self._queue.get()
            if item is None:
                return
            data, by_id = item
            n, pos, unpack = len(data), 0, _MESSAGE.unpack_from
            while pos < n:
                _op, length, cid, _seq, log_ns, _pub = unpack(data, pos)
                end = pos + 9 + length
                ch = by_id.get(cid)
                if ch is not None:
                    ch.log(data[pos + _DATA_AT:end], log_time=log_ns)
                    self.sent_messages += 1
                    if not self.sent_messages % _YIELD_EVERY:
                        time.sleep(0)  # the GIL to the run's thread: its pacing first
                pos = end

    def close(self) -> None:
        """Let the sender empty its queue (at most CLOSE_WAIT_S), then stop the server."""
        if self.closed:
            return
        self.closed = True
        deadline = time.monotonic() + CLOSE_WAIT_S
        while True:
            try:
                self._queue.put(None, timeout=max(0.0, deadline - time.monotonic()))
                break
            except queue.Full:  # the sender is stuck: drop what waits
                self._drain()
        self._sender.join(timeout=max(0.0, deadline - time.monotonic()))
        if self._listener.subscriptions:
            time.sleep(LINGER_S)  # the SDK's queues to a reading client: the last chunk too
        # the SDK's stop waits for its clients' connections to close, and a client that
        # stopped reading with messages queued for it holds it (measured: > 5 s, the
        # connection never closes): stopped from a daemon thread, waited for STOP_WAIT_S
        stopper = threading.Thread(target=self._server.stop, name="bioflex-live-stop",
                                   daemon=True)
        stopper.start()
        stopper.join(STOP_WAIT_S)
        self.stop_held = stopper.is_alive()

    def _drain(self) -> None:
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is not None:
                self.dropped_chunks += 1
                self.dropped_messages += _count(item[0])

    def summary(self) -> dict:
        return {"url": self.url, "clients": self.clients, "chunks": self.chunks,
                "sent_messages": self.sent_messages, "dropped_chunks": self.dropped_chunks,
                "dropped_messages": self.dropped_messages, "stop_held": self.stop_held}


class _Tee:
    """One log file's ``on_chunk``: its channel ids mapped to the server's channels."""

    def __init__(self, server: LiveServer) -> None:
        self._server = server
        self._by_id: dict[int, object] = {}

    @property
    def subscribed(self) -> bool:
        """A client subscribes to something: the writer then closes its chunks every
        LIVE_CHUNK_WALL_S of wall time (McapFileWriter.chunk_wall_s)."""
        return self._server._listener.subscriptions > 0

    def __call__(self, data: bytes, channels, schemas) -> None:
        by_id = self._by_id
        if len(by_id) < len(channels):  # channels new since the last chunk: advertised now
            for ch in channels[len(by_id):]:
                by_id[ch.id] = self._server._channel(ch, schemas)
        self._server._offer(data, by_id)


def _count(data: bytes) -> int:
    """The number of Message records in a chunk's records."""
    n, pos, count = len(data), 0, 0
    while pos < n:
        pos += 9 + struct.unpack_from("<Q", data, pos + 1)[0]
        count += 1
    return count
