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


class Console:
    """A vehicle (``bioflex-jsb sitl`` on a free loopback udpin port, ``args`` more) and
    MAVProxy driven through its console (stdin), its output lines collected."""

    def __init__(self, tmp_path, *args: str) -> None:
        probe = __import__("socket").socket(2, 2)
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
        probe.close()
        self.vehicle = subprocess.Popen(
            [sys.executable, "-m", "bioflex_jsb", "sitl", "--mavlink",
             f"udpin:127.0.0.1:{port}", "--speedup", "2", "--duration", "400", *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        env = {**os.environ, "HOME": str(tmp_path)}
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "MAVProxy.mavproxy", f"--master=udpout:127.0.0.1:{port}",
             f"--state-basedir={tmp_path}", "--aircraft=bioflex", "--dialect=common"],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
            text=True, env=env, cwd=tmp_path)
        self.lines: list[str] = []
        threading.Thread(target=lambda: self.lines.extend(x.rstrip() for x in self.proc.stdout),
                         daemon=True).start()

    def wait(self, pattern: str, timeout: float = TIMEOUT_S) -> re.Match:
        """The first output line matching ``pattern``; fails if the vehicle ended."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            assert self.vehicle.poll() is None, ("the vehicle ended:\n"
                                                 + self.vehicle.stderr.read())
            for x in list(self.lines):
                if (m := re.search(pattern, x)) is not None:
                    return m
            time.sleep(0.1)
        raise AssertionError(f"MAVProxy never printed {pattern!r}:\n" + "\n".join(self.lines))

    def cmd(self, text: str) -> None:
        self.proc.stdin.write(text + "\n")
        self.proc.stdin.flush()

    def stop(self) -> tuple[int, str]:
        """Stop MAVProxy, then the vehicle (SIGTERM); the vehicle's status and stderr."""
        for p in (self.proc, self.vehicle):
            if p.poll() is None:
                p.terminate()
        try:
            self.proc.wait(5.0)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        try:
            _, err = self.vehicle.communicate(timeout=30.0)
        except subprocess.TimeoutExpired:
            self.vehicle.kill()
            _, err = self.vehicle.communicate()
        return self.vehicle.returncode, err


def test_mavproxy_names_and_sets_modes_uploads_a_mission_and_sees_no_loss(tmp_path):
    """MAVProxy driven through its console (stdin): mode names from the HEARTBEAT, mode
    changes, a mission upload and download, and its own link report: < 1 % loss."""
    (tmp_path / "wp.txt").write_text(WAYPOINTS)
    c = Console(tmp_path, "--no-log")
    try:
        c.wait(r"Detected vehicle 1:1")
        c.wait(r"Mode CRUISE")
        c.cmd("mode LOITER")
        c.wait(r"AP: Mode LOITER")
        c.cmd("wp load wp.txt")
        c.wait(r"MISSION_ACK: TYPE_MISSION: ACCEPTED")
        c.cmd("wp list")
        c.wait(r"Saved 4 waypoints")
        c.cmd("mode AUTO")
        c.wait(r"AP: Mode AUTO")
        c.wait(r"AP: Reached waypoint #1", 60.0)
        c.lines.clear()
        c.cmd("link")
        m = c.wait(r"link 1 OK \((\d+) packets.*?(\d+) lost, ([\d.]+)% loss")
    finally:
        c.stop()
    packets, lost, loss_pct = int(m.group(1)), int(m.group(2)), float(m.group(3))
    assert packets > 1000 and loss_pct < 1.0, (packets, lost, loss_pct)


BAD_WAYPOINTS = """QGC WPL 110
0\t1\t0\t16\t0\t0\t0\t0\t-35.363261\t149.165230\t584.000000\t1
1\t0\t3\t16\t0\t30\t0\t0\t-35.360563\t149.165230\t1000000000.000000\t1
"""


def test_mavproxy_guided_wp_param_set_and_rc_never_end_the_vehicle(tmp_path):
    """A MAVProxy session that uses ``guided`` (COMMAND_INT DO_REPOSITION, MAVProxy
    1.8.75's default, and the MISSION_ITEM_INT current = 2 it sends with
    guided_use_reposition off), ``wp`` with an out-of-range altitude, ``param set`` out of
    range and ``rc`` overrides: the vehicle flies on, says each refusal, and logs them."""
    log = tmp_path / "session.mcap"
    (tmp_path / "bad.txt").write_text(BAD_WAYPOINTS)
    c = Console(tmp_path, "--out", str(log))
    wait, cmd = c.wait, c.cmd
    try:
        wait(r"Detected vehicle 1:1")
        wait(r"Mode CRUISE")
        cmd("mode GUIDED")
        wait(r"AP: Mode GUIDED")
        cmd("guided -35.3600 149.1660 120")  # COMMAND_INT DO_REPOSITION, relative frame
        wait(r"Got COMMAND_ACK: DO_REPOSITION: ACCEPTED")
        cmd("guided -35.3600 149.1660 100000000")
        wait(r"Got COMMAND_ACK: DO_REPOSITION: DENIED")
        wait(r"AP: DO_REPOSITION: z altitude 1e\+08 m")
        cmd("guided 1000 149.1660 120")  # latitude 1000°: MAVProxy itself cannot pack it
        cmd("set guided_use_reposition 0")
        cmd("guided -35.3620 149.1640 150")  # MISSION_ITEM_INT with current = 2
        wait(r"MISSION_ACK: TYPE_MISSION: ACCEPTED")
        cmd("wp load bad.txt")
        wait(r"AP: Mission rejected: item 1: altitude 1e\+09 m")
        wait(rf"Saved {len(SitlParameters.names)} parameters", 90.0)  # before param set
        cmd("param set AIRSPEED_MS 99")
        wait(r"AP: PARAM_SET AIRSPEED_MS must be in 12\.\.22 m/s")
        cmd("param set AP_ALT_M 1e9")
        wait(r"AP: PARAM_SET AP_ALT_M")
        cmd("param set WP_RADIUS_M -5")
        wait(r"AP: PARAM_SET WP_RADIUS_M must be in 5\.\.500 m")
        cmd("rc 1 1800")  # in GUIDED: said, not obeyed
        wait(r"AP: Sticks ignored in GUIDED")
        cmd("mode FBWA")
        wait(r"AP: Mode FBWA")
        cmd("rc 1 1800")  # channel 1 alone (the others 0): rolls right
        cmd("rc 2 4000")
        wait(r"AP: RC override channel 2: 4000 us outside 800\.\.2200")
        cmd("rc 3 1600")
        wait(r"AP: RC override channel 3: not used")
        cmd("rc all 0")
        cmd("mode LOITER")
        wait(r"AP: Mode LOITER")
        c.lines.clear()
        cmd("status GLOBAL_POSITION_INT")
        wait(r"GLOBAL_POSITION_INT")
        assert c.vehicle.poll() is None
    finally:
        status, err = c.stop()  # SIGTERM: exit 130, the log finished
    assert status == 130, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 2, err  # start + stop
    from bioflex_jsb.sinks.mcap.reader import summarise

    events = [e["text"] for e in summarise(log)["events"]]
    for start in ("DO_REPOSITION: z altitude", "Mission rejected: item 1",
                  "PARAM_SET AIRSPEED_MS", "Sticks ignored in GUIDED",
                  "RC override channel 2"):
        assert any(t.startswith(start) for t in events), (start, events)
