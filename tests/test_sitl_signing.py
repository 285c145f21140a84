"""MAVLink 2 signing of the SITL vehicle (``--signing-key FILE``): key files, and pymavlink
clients on loopback with the right key (answered), a wrong key, no signature and a replayed
packet (all ignored)."""

from __future__ import annotations

import hashlib
import socket
import time

import pytest
from pymavlink.dialects.v20 import common as M

from bioflex_jsb.drivers.sitl import SitlParameters
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.links.mavlink import (
    LinkError,
    MavlinkLink,
    read_signing_key,
    signing_time_10us,
)
from tests.polling import wait_until
from tests.test_sitl import Session, make_sim, run_cli

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset

KEY = hashlib.sha256(b"bioflex signing test").digest()
WRONG_KEY = hashlib.sha256(b"not the key").digest()
LINK_ID = 7


def write_key(tmp_path, text: str, name: str = "key.hex"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_key_file_holds_64_hex_digits(tmp_path):
    assert read_signing_key(write_key(tmp_path, KEY.hex() + "\n")) == KEY
    assert read_signing_key(write_key(tmp_path, "  " + KEY.hex().upper() + " \n")) == KEY
    bad = {
        "missing": tmp_path / "absent.hex",
        "short": write_key(tmp_path, KEY.hex()[:-2], "short.hex"),
        "long": write_key(tmp_path, KEY.hex() + "00", "long.hex"),
        "not hex": write_key(tmp_path, "g" * 64, "g.hex"),
        "passphrase": write_key(tmp_path, "my secret passphrase", "pass.txt"),
        "zero": write_key(tmp_path, "0" * 64, "zero.hex"),
        "binary": tmp_path / "raw.bin",
        "empty": write_key(tmp_path, "", "empty.hex"),
    }
    bad["binary"].write_bytes(bytes(range(200, 232)))
    for why, path in bad.items():
        with pytest.raises(LinkError) as err:
            read_signing_key(path)
        msg = str(err.value)
        assert "\n" not in msg and "signing key" in msg and str(path) in msg, (why, msg)


@pytest.mark.parametrize("content", [None, "abc123", KEY.hex() + "ff", "0" * 64])
def test_cli_bad_signing_key_exit_2_one_line(content, tmp_path, monkeypatch, capsys):
    path = tmp_path / "key.hex"
    if content is not None:
        path.write_text(content)
    rc = run_cli(["sitl", "--signing-key", str(path), "--duration", "1",
                  "--mavlink", "udpin:127.0.0.1:0"], monkeypatch)
    err = capsys.readouterr().err.strip()
    assert rc == 2
    assert len(err.splitlines()) == 1 and "sitl: error:" in err and "signing key" in err, err


class Gcs:
    """A MAVLink 2 ground station on a UDP socket (pymavlink's codec, signing as pymavlink
    does it): signs what it sends with ``key`` (None: unsigned) and, with a key, accepts only
    messages signed with it."""

    def __init__(self, port: int, key: bytes | None, link_id: int = LINK_ID) -> None:
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.sock.connect(("127.0.0.1", port))
        self.sock.settimeout(0.1)
        self.mav = M.MAVLink(self, srcSystem=255, srcComponent=190)
        self.rx = M.MAVLink(None)
        self.rx.robust_parsing = True
        if key is not None:
            for m in (self.mav, self.rx):
                m.signing.secret_key, m.signing.link_id = key, link_id
                m.signing.timestamp = signing_time_10us()
            self.mav.signing.sign_outgoing = True

    def write(self, data: bytes) -> None:  # pymavlink's send() writes here
        self.sock.send(data)

    def heartbeat(self) -> None:
        self.mav.heartbeat_send(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)

    def set_len(self, value: float) -> None:
        self.mav.param_set_send(1, 1, b"GUST_LEN_M", value, M.MAV_PARAM_TYPE_REAL32)

    def wait(self, kind: str, timeout: float = 3.0, cond=lambda m: True, poke=None):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            if poke is not None:
                poke()
            try:
                data = self.sock.recv(65535)
            except (TimeoutError, ConnectionRefusedError):
                continue
            for m in self.rx.parse_buffer(data) or []:
                if m.get_type() == kind and cond(m):
                    return m
        return None

    def close(self) -> None:
        self.sock.close()


def test_signed_vehicle_answers_the_key_and_ignores_the_rest():
    sim = make_sim(build_wing(VARIANTS["optimised"]))
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle, signing_key=KEY)
    with Session(sim, link=link) as session:
        good = Gcs(session.port, KEY)
        good.mav.signing.sign_outgoing = False
        good.heartbeat()  # unsigned first, as a ground station before its key is set up
        good.mav.signing.sign_outgoing = True
        # the client rejects unsigned or wrongly signed input: what it gets is signed by KEY
        hb = good.wait("HEARTBEAT", poke=good.heartbeat, cond=lambda m: m.get_srcSystem() == 1)
        assert hb is not None, "no signed HEARTBEAT from the vehicle"
        raw = hb.get_msgbuf()
        assert raw[0] == 0xFD and raw[2] & M.MAVLINK_IFLAG_SIGNED
        assert len(raw) == 10 + raw[1] + 2 + 13  # header, payload, CRC, signature
        stamp = int.from_bytes(bytes(raw[-12:-6]), "little")
        assert abs(stamp - signing_time_10us()) < 10 * 100_000  # wall clock, within 10 s
        good.set_len(40.0)
        pv = good.wait("PARAM_VALUE", cond=lambda m: m.param_id == "GUST_LEN_M")
        assert pv is not None and pv.param_value == 40.0 and sim.gust_length_m == 40.0
        assert link.stats.rejected_signature >= 1  # the unsigned first heartbeat

        # a wrong key, no signature at all: ignored, and no telemetry for them
        wrong, plain = Gcs(session.port, WRONG_KEY), Gcs(session.port, None)
        rejected = link.stats.rejected_signature
        for n in range(1, 4):  # a round at a time: a new source's burst is parsed in part
            for c in (wrong, plain):
                c.heartbeat()
                c.set_len(77.0)
            wait_until(lambda n=n: link.stats.rejected_signature >= rejected + 4 * n, 10.0,
                       f"round {n}: the packets of the wrong key and of no key refused")
        assert sim.gust_length_m == 40.0
        assert link.peer_count == 1
        assert plain.wait("HEARTBEAT", timeout=0.5) is None

        # a replayed signed packet (same timestamp) is ignored
        replay = M.MAVLink(None, srcSystem=255, srcComponent=190)
        replay.signing.secret_key, replay.signing.sign_outgoing = KEY, True
        replay.signing.link_id, replay.signing.timestamp = 99, signing_time_10us()
        packet = replay.param_set_encode(1, 1, b"GUST_LEN_M", 55.0,
                                         M.MAV_PARAM_TYPE_REAL32).pack(replay)
        raw_sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        raw_sock.sendto(packet, ("127.0.0.1", session.port))
        wait_until(lambda: sim.gust_length_m == 55.0, 10.0,
                   "the signed packet applied the first time")  # a valid message then
        good.set_len(60.0)
        assert good.wait("PARAM_VALUE", cond=lambda m: m.param_value == 60.0) is not None
        rejected = link.stats.rejected_signature
        raw_sock.sendto(packet, ("127.0.0.1", session.port))
        # the replay is read and refused (counted), not merely not yet read
        wait_until(lambda: link.stats.rejected_signature == rejected + 1, 10.0,
                   "the replayed packet refused")
        assert sim.gust_length_m == 60.0

        # a forged packet with a far-future timestamp on the good client's stream does not
        # lock the good client out (the stream time moves only on a valid signature)
        forger = M.MAVLink(None, srcSystem=255, srcComponent=190)
        forger.signing.secret_key, forger.signing.sign_outgoing = WRONG_KEY, True
        forger.signing.link_id = LINK_ID
        forger.signing.timestamp = signing_time_10us() + 3600 * 100_000
        raw_sock.sendto(forger.param_set_encode(1, 1, b"GUST_LEN_M", 66.0,
                                                M.MAV_PARAM_TYPE_REAL32).pack(forger),
                        ("127.0.0.1", session.port))
        wait_until(lambda: link.stats.rejected_signature == rejected + 2, 10.0,
                   "the forged packet refused")
        assert sim.gust_length_m == 60.0
        good.set_len(61.0)
        assert good.wait("PARAM_VALUE", cond=lambda m: m.param_value == 61.0) is not None
        assert sim.gust_length_m == 61.0

        # RADIO_STATUS may come unsigned (radios cannot sign)
        radio = M.MAVLink(None, srcSystem=3, srcComponent=68)
        raw_sock.sendto(radio.radio_status_encode(200, 190, 80, 10, 5, 0, 0).pack(radio),
                        ("127.0.0.1", session.port))
        wait_until(lambda: "RADIO_STATUS" in link.stats.by_type, 10.0,
                   "the unsigned RADIO_STATUS read")
        assert link.stats.by_type.get("RADIO_STATUS") == 1
        raw_sock.close()
        for c in (good, wrong, plain):
            c.close()
