"""MAVProxy (PyPI ``mavproxy``, non-interactive) connects to the SITL vehicle on loopback,
detects it and receives its parameters; once plainly and once with MAVLink 2 signing, the
key derived by MAVProxy itself from a passphrase (``signing key P``: SHA-256 of P)."""

from __future__ import annotations

import hashlib
import math
import os
import re
import subprocess
import sys
import threading
import time

import pytest

from bioflex_jsb.drivers.sitl import SitlParameters
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.links.mavlink import MavlinkLink
from tests.test_sitl import Session, make_sim

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset

PASSPHRASE = "elastic-wing-sitl"
TIMEOUT_S = 40.0


def run_mavproxy(port: int, state_dir, extra: list[str], until) -> tuple[list[str], bool]:
    """MAVProxy sending to the vehicle's udpin port; its output lines, and whether
    ``until(lines)`` became true before TIMEOUT_S (then MAVProxy is stopped)."""
    env = {**os.environ, "HOME": str(state_dir)}  # no user mavinit.scr or signing.keys
    proc = subprocess.Popen(
        [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpout:127.0.0.1:{port}",
         "--non-interactive", f"--state-basedir={state_dir}", "--aircraft=bioflex",
         "--dialect=common", *extra],
        stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env=env, cwd=state_dir)
    lines: list[str] = []

    def read():
        for line in proc.stdout:
            lines.append(line.rstrip("\n"))

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    done = False
    end = time.monotonic() + TIMEOUT_S
    try:
        while time.monotonic() < end and proc.poll() is None:
            if until(list(lines)):
                done = True
                break
            time.sleep(0.05)
    finally:
        if proc.poll() is None:
            proc.terminate()
            try:
                proc.wait(5.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        reader.join(5.0)
    return lines, done


@pytest.mark.parametrize("signed", [False, True], ids=["plain", "signed"])
def test_mavproxy_detects_the_vehicle_and_receives_its_parameters(signed, tmp_path):
    sim = make_sim(build_wing(VARIANTS["optimised"]))
    params = SitlParameters(sim)
    params.set("GUST_LEN_M", 42.5)  # values MAVProxy can only know from the vehicle
    params.set("AP_HDG_RAD", 0.75)
    key = hashlib.sha256(PASSPHRASE.encode("ascii")).digest() if signed else None
    link = MavlinkLink("udpin:127.0.0.1:0", params, sim.vehicle, signing_key=key)
    extra = ["--mav20", f"--cmd=signing key {PASSPHRASE}"] if signed else []
    n = len(SitlParameters.names)

    def saved(lines):
        return any(re.search(rf"Saved {n} parameters to \S+mav\.parm", x) for x in lines)

    with Session(sim, link=link) as session:
        lines, done = run_mavproxy(session.port, tmp_path, extra, saved)
        values = {name: params.get(name) for name in SitlParameters.names}
    text = "\n".join(lines)
    assert done, f"MAVProxy did not save the parameters within {TIMEOUT_S} s:\n{text}"
    assert "Detected vehicle 1:1" in text, text
    assert f"Received {n} parameters" in text, text
    assert "fence breach" not in text  # SYS_STATUS health says no breach
    parm = re.search(rf"Saved {n} parameters to (\S+mav\.parm)", text).group(1)
    got = {}
    with open(os.path.join(tmp_path, parm) if not os.path.isabs(parm) else parm) as f:
        for row in f:
            name, value = row.split()
            got[name] = float(value)
    assert set(got) == set(SitlParameters.names)
    for name, value in values.items():  # MAVProxy writes 6 decimals
        assert math.isclose(got[name], value, abs_tol=1e-6), (name, got[name], value)
    assert got["GUST_LEN_M"] == 42.5 and got["AP_HDG_RAD"] == 0.75
    assert link.stats.by_type.get("PARAM_REQUEST_LIST", 0) >= 1
    if signed:  # everything the vehicle accepted carried MAVProxy's signature
        assert "Setup signing key" in text
        assert link.stats.received > 0 and link.signing


WAYPOINTS = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t-35.363261\t149.165230\t584.000000\t1
1\t0\t3\t16\t0\t30\t0\t0\t-35.360563\t149.165230\t100.000000\t1
2\t0\t3\t16\t0\t30\t0\t0\t-35.360563\t149.168537\t100.000000\t1
3\t0\t3\t16\t0\t30\t0\t0\t-35.363261\t149.168537\t100.000000\t1
"""


def test_mavproxy_names_and_sets_modes_uploads_a_mission_and_sees_no_loss(tmp_path):
    """MAVProxy driven through its console (stdin): mode names from the HEARTBEAT, mode
    changes, a mission upload and download, and its own link report: < 1 % loss."""
    port_probe = __import__("socket").socket(2, 2)
    port_probe.bind(("127.0.0.1", 0))
    port = port_probe.getsockname()[1]
    port_probe.close()
    vehicle = subprocess.Popen(
        [sys.executable, "-m", "bioflex_jsb", "sitl", "--mavlink", f"udpin:127.0.0.1:{port}",
         "--speedup", "2", "--no-log", "--duration", "400"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    (tmp_path / "wp.txt").write_text(WAYPOINTS)
    env = {**os.environ, "HOME": str(tmp_path)}
    proc = subprocess.Popen(
        [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpout:127.0.0.1:{port}",
         f"--state-basedir={tmp_path}", "--aircraft=bioflex", "--dialect=common"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
        env=env, cwd=tmp_path)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(x.rstrip() for x in proc.stdout),
                              daemon=True)
    reader.start()

    def wait(pattern: str, timeout: float = TIMEOUT_S) -> re.Match:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for x in list(lines):
                if (m := re.search(pattern, x)) is not None:
                    return m
            time.sleep(0.1)
        raise AssertionError(f"MAVProxy never printed {pattern!r}:\n" + "\n".join(lines))

    def cmd(text: str) -> None:
        proc.stdin.write(text + "\n")
        proc.stdin.flush()

    try:
        wait(r"Detected vehicle 1:1")
        wait(r"Mode CRUISE")
        cmd("mode LOITER")
        wait(r"AP: Mode LOITER")
        cmd("wp load wp.txt")
        wait(r"MISSION_ACK: TYPE_MISSION: ACCEPTED")
        cmd("wp list")
        wait(r"Saved 4 waypoints")
        cmd("mode AUTO")
        wait(r"AP: Mode AUTO")
        wait(r"AP: Reached waypoint #1", 60.0)
        lines.clear()
        cmd("link")
        m = wait(r"link 1 OK \((\d+) packets.*?(\d+) lost, ([\d.]+)% loss")
    finally:
        for p in (proc, vehicle):
            p.terminate()
            try:
                p.wait(5.0)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()
    packets, lost, loss_pct = int(m.group(1)), int(m.group(2)), float(m.group(3))
    assert packets > 1000 and loss_pct < 1.0, (packets, lost, loss_pct)
