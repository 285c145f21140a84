"""The log served live: what a :class:`~.log.RunLog` writes, also sent over the Foxglove
WebSocket protocol (``foxglove.websocket.v1``) by the Foxglove SDK's server (``foxglove-sdk``,
an optional dependency), with the same topics, schemas and message bytes as the file.

:class:`LiveWriter` wraps the log's :class:`~.writer.McapFileWriter`: each schema and channel
it adds is advertised, each message it appends is published (a chunk's block of records at a
time, as the run hands them over: the live view is one chunk, ≤ 0.9 s of simulated time,
behind). A channel no client subscribes to costs one ``has_sinks`` call per chunk and
nothing per message. The SDK keeps at most ``message_backlog_size`` outgoing messages per
client and drops the oldest when a client does not read, so a slow or vanished client never
blocks the simulation. The server binds loopback unless told otherwise.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

from bioflex_jsb.sinks.mcap.errors import LogWriteError

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap.writer import McapFileWriter

DEFAULT_HOST = "127.0.0.1"
# A record's message data starts after opcode (1), record length (8), channel id (2),
# sequence (4), log time (8) and publish time (8) (MCAP Message record)
_DATA_AT = 31
# How long closing the log waits for the server to stop [s]: a reading client is closed
# within milliseconds; one that stopped reading never is (see LiveWriter.shutdown)
STOP_WAIT_S = 1.0


def parse_address(text: str) -> tuple[str, int]:
    """``[HOST:]PORT`` → (host, port); ValueError (one line) otherwise. Port 0: any free."""
    host, _, port = text.rpartition(":")
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise ValueError(f"live address {text!r}: give [HOST:]PORT with PORT 0..65535")
    return host or DEFAULT_HOST, int(port)


class LiveWriter:
    """A :class:`McapFileWriter` that also serves what it writes (module docstring)."""

    def __init__(self, writer: McapFileWriter, host: str = DEFAULT_HOST, port: int = 8765,
                 backlog: int = 1024) -> None:
        try:
            import foxglove
        except ImportError:
            raise LogWriteError("live view: the Foxglove SDK is not installed (pip install "
                                "foxglove-sdk)") from None
        self._fox = foxglove
        self._w = writer
        self.context = foxglove.Context()
        try:
            self.server = foxglove.start_server(name="bioflex-jsb", host=host, port=port,
                                                context=self.context,
                                                message_backlog_size=backlog)
        except RuntimeError as exc:  # the SDK's error for an address it cannot bind
            raise LogWriteError(f"live view: cannot serve on {host}:{port}: {exc}") from None
        self._schemas: dict[int, tuple[str, str, bytes]] = {}
        self._channels: dict[int, object] = {}
        self.published = 0  # messages handed to the server (subscribed channels only)

    @property
    def port(self) -> int:
        return int(self.server.port)

    def __getattr__(self, name: str):
        return getattr(self._w, name)

    def add_schema(self, name: str, encoding: str, data: bytes) -> int:
        sid = self._w.add_schema(name, encoding, data)
        self._schemas[sid] = (name, encoding, bytes(data))
        return sid

    def add_channel(self, topic_name: str, schema_id: int, metadata: dict[str, str],
                    message_encoding: str = "protobuf") -> int:
        cid = self._w.add_channel(topic_name, schema_id, metadata, message_encoding)
        name, encoding, data = self._schemas[schema_id]
        fox = self._fox
        self._channels[cid] = fox.Channel(
            topic_name, schema=fox.Schema(name=name, encoding=encoding, data=data),
            message_encoding=message_encoding, context=self.context, metadata=dict(metadata))
        return cid

    def append(self, channel_id: int, log_ns: int, sequence: int, data: bytes) -> None:
        self._w.append(channel_id, log_ns, sequence, data)
        ch = self._channels[channel_id]
        if ch.has_sinks():
            ch.log(bytes(data), log_time=int(log_ns))
            self.published += 1

    def append_block(self, block, index) -> None:
        self._w.append_block(block, index)
        view = memoryview(block)
        for cid, entries in index.items():
            ch = self._channels.get(cid)
            if ch is None or not len(entries) or not ch.has_sinks():
                continue
            for ns, at in entries.tolist():
                end = at + 9 + int.from_bytes(view[at + 1:at + 9], "little")
                ch.log(bytes(view[at + _DATA_AT:end]), log_time=int(ns))
                self.published += 1

    def shutdown(self) -> None:
        """Shut the writer, then the server. The SDK's ``stop`` waits for its clients'
        connections to close, which a client that stopped reading never lets happen: it is
        left to a daemon thread for at most :data:`STOP_WAIT_S`, then the process goes on
        (the server's threads end with it)."""
        try:
            self._w.shutdown()
        finally:
            for ch in self._channels.values():
                ch.close()
            stopper = threading.Thread(target=self.server.stop, name="live-stop", daemon=True)
            stopper.start()
            stopper.join(STOP_WAIT_S)
