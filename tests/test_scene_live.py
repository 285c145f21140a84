"""The log served live (bioflex_jsb/sinks/mcap/live.py, foxglove-sdk's WebSocket server on
loopback): an independent client, a plain WebSocket (RFC 6455) over a socket speaking the
Foxglove WebSocket protocol (subprotocol ``foxglove.sdk.v1``, below), subscribes and
receives the file's own message bytes, decoded with the advertised schema by Google's
protobuf runtime; a client that subscribes and stops reading never blocks the run."""

from __future__ import annotations

import base64
import hashlib
import json
import os
import socket
import struct
import threading
import time

import numpy as np
import pytest

from bioflex_jsb.simulation.channels import channel_units
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink

pytest.importorskip("foxglove")
pytest.importorskip("google.protobuf")

# The protocol's name as foxglove-sdk 0.30 serves it: the foxglove.websocket.v1 messages
# (serverInfo, advertise, subscribe, binary MessageData) under the subprotocol
# foxglove.sdk.v1; the server refuses a handshake offering only foxglove.websocket.v1
SUBPROTOCOL = "foxglove.sdk.v1"
NAMES = tuple(channel_units(3))
DT = 1 / 960


class Client:
    """A WebSocket client: handshake with the subprotocol, text and binary frames."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                           f"Sec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: "
                           f"{SUBPROTOCOL}\r\n\r\n").encode())
        self.buf = b""
        while b"\r\n\r\n" not in self.buf:
            self.buf += self.sock.recv(4096)
        head, self.buf = self.buf.split(b"\r\n\r\n", 1)
        lines = head.decode().split("\r\n")
        assert lines[0].split()[1] == "101", lines[0]
        fields = {k.lower(): v.strip() for k, _, v in (ln.partition(":") for ln in lines[1:])}
        accept = base64.b64encode(hashlib.sha1(
            (key + "258EAFA5-E914-47DA-95CA-C5AB0DC85B11").encode()).digest()).decode()
        assert fields["sec-websocket-accept"] == accept
        assert fields["sec-websocket-protocol"] == SUBPROTOCOL

    def _take(self, n: int) -> bytes:
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 16)
            if not chunk:
                raise ConnectionError("closed")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def frame(self) -> tuple[int, bytes]:
        """(opcode, payload) of the next whole message (continuations joined; pings
        answered)."""
        data, opcode = b"", None
        while True:
            b0, b1 = self._take(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._take(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._take(8))[0]
            mask = self._take(4) if b1 & 0x80 else None
            payload = self._take(n)
            if mask:
                payload = bytes(c ^ mask[i % 4] for i, c in enumerate(payload))
            op = b0 & 0x0F
            if op == 0x9:  # ping
                self._send(0xA, payload)
                continue
            opcode = op if op else opcode
            data += payload
            if b0 & 0x80:
                return opcode, data

    def _send(self, opcode: int, payload: bytes) -> None:
        mask = os.urandom(4)
        n = len(payload)
        head = bytes([0x80 | opcode]) + (bytes([0x80 | n]) if n < 126 else
                                         bytes([0x80 | 126]) + struct.pack(">H", n))
        self.sock.sendall(head + mask + bytes(c ^ mask[i % 4] for i, c in enumerate(payload)))

    def send_json(self, obj) -> None:
        self._send(0x1, json.dumps(obj).encode())

    def until_advertised(self, topics, timeout_s: float = 20.0) -> dict[str, dict]:
        seen: dict[str, dict] = {}
        end = time.monotonic() + timeout_s
        while not set(topics) <= set(seen):
            assert time.monotonic() < end, f"not advertised: {set(topics) - set(seen)}"
            op, data = self.frame()
            if op == 0x1:
                msg = json.loads(data)
                if msg.get("op") == "advertise":
                    seen.update({c["topic"]: c for c in msg["channels"]})
        return seen


def _feed(log, k0: int, n: int) -> None:
    for k in range(k0, k0 + n):
        row = dict.fromkeys(NAMES, 0.0)
        row.update(latitude_rad=0.7, longitude_rad=0.2, altitude_m=100.0, w_g=1.0,
                   airspeed_m_s=15.0, eta1=0.1 * np.sin(k * DT * 40), eta2=0.01, eta3=0.0)
        log.sample("coupled", k * DT, row)
    log.flush()


def _wait_subscribed(log, topics, timeout_s: float = 20.0) -> None:
    w = log._writer
    ids = [cid for cid, ch in w._channels.items() if ch.topic in topics]
    end = time.monotonic() + timeout_s
    while not all(w._channels[c].has_sinks() for c in ids):
        assert time.monotonic() < end, "the server never took the subscription"
        time.sleep(0.02)


def _decoder(channel: dict):
    from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

    assert channel["encoding"] == "protobuf" and channel["schemaEncoding"] == "protobuf"
    pool = descriptor_pool.DescriptorPool()
    fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    for fd in fds.file:
        pool.Add(fd)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(channel["schemaName"]))


def test_a_client_receives_the_files_messages(tmp_path):
    desc = RunDescription("sitl", "optimised", 15.0, models=("coupled",), duration_s=1.0)
    path = tmp_path / "live.mcap"
    log = sink.RunLog.open(path, desc, scene=1.0, live=("127.0.0.1", 0))
    try:
        client = Client(log._writer.port)
        op, info = client.frame()
        assert op == 0x1 and json.loads(info)["op"] == "serverInfo"
        _feed(log, 0, 480)  # channels made (advertised); nobody subscribed yet
        assert log._writer.published == 0
        topics = ["/bioflex/coupled/scene", "/bioflex/coupled/modal"]
        ads = client.until_advertised(topics)
        client.send_json({"op": "subscribe", "subscriptions": [
            {"id": i + 1, "channelId": ads[t]["id"]} for i, t in enumerate(topics)]})
        _wait_subscribed(log, topics)
        _feed(log, 480, 480)
        want = {1: 30, 2: 480}  # 0.5 s at 60 Hz; every step
        got: dict[int, list[tuple[int, bytes]]] = {1: [], 2: []}
        while any(len(got[s]) < n for s, n in want.items()):
            op, data = client.frame()
            if op == 0x2 and data[0] == 0x01:  # MessageData: sub id, log time, payload
                sub, ns = struct.unpack_from("<IQ", data, 1)
                got[sub].append((ns, data[13:]))
    finally:
        log.close()
    on_file = sink.messages_by_topic(path)
    raw = {}
    from mcap.reader import make_reader

    with open(path, "rb") as f:
        for _s, ch, m in make_reader(f).iter_messages(topics=topics):
            raw[(ch.topic, m.log_time)] = m.data
    for sub, top in ((1, topics[0]), (2, topics[1])):
        assert [ns for ns, _ in got[sub]] == [ns for ns, _ in on_file[top][-want[sub]:]]
        assert all(raw[(top, ns)] == payload for ns, payload in got[sub])  # the same bytes
    scene = _decoder(ads[topics[0]]).FromString(got[1][-1][1])
    assert scene.entities[0].id == "wing" and len(scene.entities[0].triangles) == 2
    modal = _decoder(ads[topics[1]]).FromString(got[2][-1][1])
    assert modal.eta_rad[1] == pytest.approx(0.01, abs=1e-15)


def test_a_client_that_stops_reading_never_blocks_the_run(tmp_path):
    """It subscribes to every channel and reads nothing: 30 s of steps (≈ 30 MB of messages,
    far beyond the sockets' buffers) are still written; the SDK drops its oldest messages."""
    desc = RunDescription("sitl", "optimised", 15.0, models=("coupled",), duration_s=30.0)
    path = tmp_path / "stalled.mcap"
    log = sink.RunLog.open(path, desc, scene=1.0, live=("127.0.0.1", 0))
    done = threading.Event()
    try:
        client = Client(log._writer.port)
        client.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        _feed(log, 0, 96)
        ads = client.until_advertised(["/bioflex/coupled/scene", "/bioflex/coupled/modal"])
        client.send_json({"op": "subscribe", "subscriptions": [
            {"id": i + 1, "channelId": c["id"]} for i, c in enumerate(ads.values())]})
        _wait_subscribed(log, list(ads))

        def run():
            _feed(log, 96, 30 * 960 - 96)
            done.set()

        worker = threading.Thread(target=run, daemon=True)
        worker.start()
        # a stall would hang here; 300 s is ~100x the time the feed takes on this machine
        worker.join(timeout=300)
        assert done.is_set(), "the run blocked on a client that does not read"
        assert log._writer.published >= 7 * (30 * 960 - 96)  # every step handed to the server
    finally:
        log.close()
    counts = {c["topic"]: c["messages"] for c in sink.summarise(path)["channels"]}
    assert counts["/bioflex/coupled/modal"] == 30 * 960  # the file has every step


@pytest.mark.parametrize("text, address", [("8765", ("127.0.0.1", 8765)),
                                           ("0.0.0.0:9000", ("0.0.0.0", 9000)),
                                           ("localhost:0", ("localhost", 0))])
def test_live_addresses(text, address):
    from bioflex_jsb.sinks.mcap.live import parse_address

    assert parse_address(text) == address


@pytest.mark.parametrize("text", ["", "host:", "host:port", "70000", ":-1"])
def test_bad_live_addresses_say_what_is_accepted(text):
    from bioflex_jsb.sinks.mcap.live import parse_address

    with pytest.raises(ValueError, match=r"\[HOST:\]PORT with PORT 0\.\.65535"):
        parse_address(text)
