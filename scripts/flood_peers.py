#!/usr/bin/env python3
"""Floods from another local port against the two peer links: rates before, during, after.

    python scripts/flood_peers.py [ardupilot|sitl|all] [--rate 100000] [--before-s 3]
        [--flood-s 6] [--after-s 4] [--kinds ...] [--json]

A benchmark, not a test: it prints what one run measured on this machine (the figures
depend on its load; the load average is printed with them). Each case runs the session,
its one legitimate peer and a flooder (a process of its own sending from one other
loopback port at ``--rate`` datagrams per second, as fast as it can up to that), in three
phases of wall time: before the flood, during it, after it.

* ``ardupilot``: the backend (``bioflex-jsb ardupilot --no-log``, launcher 100 m up, trim
  throttle) against ArduPilot's stand-in (``tests/ardupilot_standin.py``, lock-step as
  fast as the backend answers, the launch switch held): lock-step frames per second in
  each phase. Kinds: ``foreign`` (valid 40-byte servo packets, frame 0, from the other
  port), ``malformed`` (40 bytes, wrong magic).
* ``sitl``: the SITL vehicle (the session's loop, :func:`bioflex_jsb.drivers.sitl.run_paced`,
  at 1x, ``udpin`` on a loopback port, no log) with one ground station (a heartbeat a
  second, as QGroundControl sends, and a PARAM_REQUEST_READ every 0.2 s): ATTITUDE messages
  the station receives per second (50 Hz asked), the share of its requests answered, the
  pacing error p50/p99/max [ms] and the resyncs of the session's loop in each phase.
  Kinds: ``heartbeat`` (valid MAVLink 2 HEARTBEATs of another system), ``malformed`` (a
  MAVLink 2 start byte and header, then bytes whose checksum fails).

The CPU share of the session and of the flooder in each phase (processor time over wall
time, Linux ``/proc``) is printed too.

``--json`` prints one JSON document; otherwise a table (the one in docs/reliability.md).
"""

from __future__ import annotations

import argparse
import json
import os
import select
import socket
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
STANDIN = REPO / "tests" / "ardupilot_standin.py"
KINDS = {"ardupilot": ("foreign", "malformed"), "sitl": ("heartbeat", "malformed")}
ATTITUDE_MSG_ID = 30  # MAVLink common.xml
PARAM_VALUE_MSG_ID = 22
REQUEST_PERIOD_S = 0.2  # the station asks for a parameter this often
MAVLINK2_STX = 0xFD


# ----------------------------------------------------------------- the child processes
def _flood_payload(kind: str) -> bytes:
    import struct

    if kind == "foreign":  # ArduPilot's servo_packet_16: magic 18458, 1200 Hz, frame 0
        return struct.pack("<HHI16H", 18458, 1200, 0, *([1500] * 16))
    if kind == "malformed" and os.environ.get("FLOOD_TARGET") == "ardupilot":
        return struct.pack("<HHI16H", 1234, 1200, 0, *([1500] * 16))
    if kind == "heartbeat":
        from pymavlink.dialects.v20 import common as M

        mav = M.MAVLink(None, srcSystem=250, srcComponent=190)
        return mav.heartbeat_encode(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0).pack(mav)
    if kind == "malformed":  # a heartbeat's header, its payload and checksum mangled
        return bytes([MAVLINK2_STX, 9, 0, 0, 7, 250, 190, 0, 0, 0]) + bytes(range(11))
    raise ValueError(kind)


def flood_child(target: tuple[str, int], rate: float, kind: str) -> None:
    """Wait for "go" on stdin, send ``rate`` datagrams a second until "stop" (stdin), then
    print {"sent", "errors", "wall_s"} as JSON."""
    data = _flood_payload(kind)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.setblocking(False)
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    sys.stdin.readline()  # "go"
    sent = errors = 0
    t0 = time.monotonic()
    stdin = sys.stdin.fileno()
    while True:
        now = time.monotonic()
        if select.select([stdin], [], [], 0.0)[0]:
            break  # "stop"
        quota = int((now - t0) * rate) - sent
        if quota <= 0:
            time.sleep(2e-4)
            continue
        for _ in range(min(quota, 2000)):
            try:
                sock.sendto(data, target)
            except OSError:  # a full send buffer, a refusal: counted, the flood goes on
                errors += 1
            sent += 1
    print(json.dumps({"sent": sent, "errors": errors, "wall_s": time.monotonic() - t0}))


def station_child(port: int) -> None:
    """A ground station on udpout to the vehicle: a HEARTBEAT a second and a
    PARAM_REQUEST_READ every REQUEST_PERIOD_S; prints the arrival times (monotonic [s]) of
    ATTITUDE messages, the times of its requests and of the PARAM_VALUE answers when its
    stdin closes."""
    from pymavlink.dialects.v20 import common as M

    mav = M.MAVLink(None, srcSystem=255, srcComponent=190)
    beat = mav.heartbeat_encode(M.MAV_TYPE_GCS, M.MAV_AUTOPILOT_INVALID, 0, 0, 0)
    ask = mav.param_request_read_encode(1, 1, b"", 0)
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    target = ("127.0.0.1", port)
    arrivals: list[float] = []
    asked: list[float] = []
    answers: list[float] = []
    last_beat = last_ask = -1.0
    stdin = sys.stdin.fileno()
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    while True:
        now = time.monotonic()
        if now - last_beat >= 1.0:
            sock.sendto(beat.pack(mav), target)
            last_beat = now
        if now - last_ask >= REQUEST_PERIOD_S:
            sock.sendto(ask.pack(mav), target)
            asked.append(now)
            last_ask = now
        ready = select.select([sock, stdin], [], [], 0.05)[0]
        if stdin in ready:
            break
        if sock in ready:
            data = sock.recv(65536)
            if len(data) >= 10 and data[0] == MAVLINK2_STX:
                msg_id = int.from_bytes(data[7:10], "little")
                if msg_id == ATTITUDE_MSG_ID:
                    arrivals.append(time.monotonic())
                elif msg_id == PARAM_VALUE_MSG_ID:
                    answers.append(time.monotonic())
    print(json.dumps({"attitude": arrivals, "asked": asked, "answers": answers}))


# ------------------------------------------------------------------------ the parent
def _child(args: list[str], env: dict | None = None) -> subprocess.Popen:
    proc = subprocess.Popen([sys.executable, __file__, *args], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True, env=env)
    if proc.stdout.readline().strip() != "ready":
        raise RuntimeError(f"child {args[0]} did not start")
    return proc


def _tell(proc: subprocess.Popen, word: str) -> None:
    proc.stdin.write(word + "\n")
    proc.stdin.flush()


def _finish(proc: subprocess.Popen):
    out, _ = proc.communicate(timeout=60)
    return json.loads(out.strip().splitlines()[-1])


def _cpu_s(pid: int) -> float | None:
    """Processor time (user + system) of process ``pid`` so far [s] (Linux /proc; None
    elsewhere)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _cpu_share(pid: int, before: float | None, wall_s: float) -> float | None:
    after = _cpu_s(pid)
    return None if before is None or after is None else (after - before) / wall_s


def _flooder(target, rate: float, kind: str, name: str) -> subprocess.Popen:
    return _child(["_flood", f"{target[0]}:{target[1]}", str(rate), kind],
                  env=dict(os.environ, FLOOD_TARGET=name))


def ardupilot_case(kind: str, rate: float, phases_s: tuple[float, float, float]) -> dict:
    """Lock-step frames a second before, during and after a flood of ``kind``."""
    import importlib.util

    from bioflex_jsb.drivers.bench_speedup import _wait_for_port
    from bioflex_jsb.runtime.fdm import Airframe

    spec = importlib.util.spec_from_file_location("ardupilot_standin", STANDIN)
    standin = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = standin  # its dataclasses look their module up
    spec.loader.exec_module(standin)
    speed_m_s = 15.0
    throttle_us = round(1000.0 + 1000.0 * Airframe().trim(speed_m_s).throttle)
    backend = subprocess.Popen(
        [sys.executable, "-m", "bioflex_jsb", "ardupilot", "--port", "0", "--speed",
         f"{speed_m_s:g}", "--launch-height", "100", "--no-log", "--json"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        port = _wait_for_port(backend, 300.0)
        import threading

        threading.Thread(target=backend.stderr.read, daemon=True).start()
        target = ("127.0.0.1", port)
        ap = standin.PacedStandin(target, throttle_us=throttle_us)
        flood = _flooder(target, rate, kind, "ardupilot")
        try:
            ap.fly(3000)  # launch and settle
            rows = []
            for phase, seconds in zip(("before", "during", "after"), phases_s, strict=True):
                if phase == "during":
                    _tell(flood, "go")
                elif phase == "after":
                    _tell(flood, "stop")
                frames, t0 = 0, time.monotonic()
                cpu = {p: _cpu_s(p) for p in (backend.pid, flood.pid, os.getpid())}
                gave_up = False
                while time.monotonic() - t0 < seconds and not gave_up:
                    try:
                        frames += ap.fly(200).frames
                    except TimeoutError:  # no reply to 60 re-sends of one frame (60 s)
                        gave_up = True
                wall = time.monotonic() - t0
                rows.append({"phase": phase, "frames_per_s": frames / wall,
                             "gave_up": gave_up,
                             "cpu_session": _cpu_share(backend.pid, cpu[backend.pid], wall),
                             "cpu_flooder": _cpu_share(flood.pid, cpu[flood.pid], wall),
                             "cpu_peer": _cpu_share(os.getpid(), cpu[os.getpid()], wall)})
            sent = _finish(flood)
        finally:
            ap.close()
            if flood.poll() is None:
                flood.kill()
    finally:
        import signal

        backend.send_signal(signal.SIGINT)
        out, _ = backend.communicate(timeout=120)
    session = json.loads(out)
    return {"target": "ardupilot", "kind": kind, "rate_asked": rate,
            "rate_sent": sent["sent"] / sent["wall_s"], "send_errors": sent["errors"],
            "phases": rows, "session": {
                "foreign_packets": session["source_check"]["foreign_packets"],
                "rejected": session["frames"]["rejected"],
                "resets": session["frames"]["resets"]}}


def sitl_case(kind: str, rate: float, phases_s: tuple[float, float, float]) -> dict:
    """Telemetry (ATTITUDE) a second at the station and the session's pacing, before,
    during and after a flood of ``kind``."""
    from bioflex_jsb.drivers.sitl import SitlParameters, SitlSim, run_paced
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.links.mavlink import MavlinkLink

    build = build_wing(VARIANTS["optimised"])
    sim = SitlSim(build.model, build.modes, speedup=1.0)
    link = MavlinkLink("udpin:127.0.0.1:0", SitlParameters(sim), sim.vehicle)
    target = link.local_address
    station = _child(["_station", str(target[1])])
    flood = _flooder(target, rate, kind, "sitl")
    rows = []
    try:
        run_paced(sim, 2.0, link)  # the station's first heartbeat; the kernel compiled
        bounds = []
        for phase, seconds in zip(("before", "during", "after"), phases_s, strict=True):
            if phase == "during":
                _tell(flood, "go")
            elif phase == "after":
                _tell(flood, "stop")
            t0 = time.monotonic()
            cpu = {p: _cpu_s(p) for p in (flood.pid, os.getpid())}
            stats = run_paced(sim, seconds, link)
            t1 = time.monotonic()
            bounds.append((t0, t1))
            rows.append({"phase": phase, **{k: stats.summary()[k] for k in
                                            ("p50_ms", "p99_ms", "max_ms", "resyncs")},
                         "cpu_session": _cpu_share(os.getpid(), cpu[os.getpid()], t1 - t0),
                         "cpu_flooder": _cpu_share(flood.pid, cpu[flood.pid], t1 - t0)})
        sent = _finish(flood)
        station.stdin.close()
        heard = json.loads(station.stdout.read().strip().splitlines()[-1])
    finally:
        link.close()
        for p in (flood, station):
            if p.poll() is None:
                p.kill()
    for row, (t0, t1) in zip(rows, bounds, strict=True):
        row["attitude_hz"] = sum(t0 <= t < t1 for t in heard["attitude"]) / (t1 - t0)
        asked = sum(t0 <= t < t1 for t in heard["asked"])
        # an answer within REQUEST_PERIOD_S of the phase's end belongs to it
        answered = sum(t0 <= t < t1 + REQUEST_PERIOD_S for t in heard["answers"])
        row["requests_answered"] = min(1.0, answered / asked) if asked else None
    st = link.stats
    return {"target": "sitl", "kind": kind, "rate_asked": rate,
            "rate_sent": sent["sent"] / sent["wall_s"], "send_errors": sent["errors"],
            "phases": rows, "session": {
                "datagrams": st.datagrams, "bad": st.bad, "peers_expired": st.peers_expired,
                "sent": st.sent,
                **{k: getattr(st, k) for k in ("unknown_dropped", "drained_max",
                                               "peer_datagrams_dropped") if hasattr(st, k)}}}


def _table(results: list[dict]) -> str:
    lines = ["| target | flood | sent [1/s] | phase | service | pacing p99 [ms] | resyncs | "
             "session CPU | flooder CPU |", "|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        for row in r["phases"]:
            if r["target"] == "ardupilot":
                service, pace, resync = f"{row['frames_per_s']:.0f} frames/s", "—", "—"
                if row.get("gave_up"):
                    service += " (a frame unanswered through 60 re-sends: stand-in gave up)"
            else:
                answered = row.get("requests_answered")
                service = f"{row['attitude_hz']:.1f} Hz ATTITUDE" + (
                    "" if answered is None else f", {100 * answered:.0f} % of requests answered")
                pace, resync = f"{row['p99_ms']:.2f}", str(row["resyncs"])
            cpu = " | ".join("—" if row.get(k) is None else f"{100 * row[k]:.0f} %"
                             for k in ("cpu_session", "cpu_flooder"))
            lines.append(f"| {r['target']} | {r['kind']} | {r['rate_sent']:.0f} | "
                         f"{row['phase']} | {service} | {pace} | {resync} | {cpu} |")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "_flood":
        host, port = argv[1].rsplit(":", 1)
        flood_child((host, int(port)), float(argv[2]), argv[3])
        return 0
    if argv and argv[0] == "_station":
        station_child(int(argv[1]))
        return 0
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("target", nargs="?", choices=("ardupilot", "sitl", "all"), default="all")
    p.add_argument("--rate", type=float, default=100_000.0,
                   help="datagrams a second the flooder aims at (default 100000)")
    p.add_argument("--kinds", default="", help="comma-separated kinds (default: both of the "
                   "target's: ardupilot foreign,malformed; sitl heartbeat,malformed)")
    p.add_argument("--before-s", type=float, default=3.0)
    p.add_argument("--flood-s", type=float, default=6.0)
    p.add_argument("--after-s", type=float, default=4.0)
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    if not 0 < args.rate <= 1e7:
        p.error(f"--rate must be in (0, 1e7] datagrams/s, got {args.rate:g}")
    phases = (args.before_s, args.flood_s, args.after_s)
    if not all(0.5 <= s <= 600 for s in phases):
        p.error("each phase must last 0.5..600 s")
    targets = ("ardupilot", "sitl") if args.target == "all" else (args.target,)
    load0 = list(os.getloadavg())
    results = []
    for target in targets:
        kinds = [k for k in args.kinds.split(",") if k] or list(KINDS[target])
        for kind in kinds:
            if kind not in KINDS[target]:
                p.error(f"kind {kind!r} is not one of {target}'s: {', '.join(KINDS[target])}")
            case = ardupilot_case if target == "ardupilot" else sitl_case
            results.append(case(kind, args.rate, phases))
    doc = {"results": results, "load_average_before": load0,
           "load_average_after": list(os.getloadavg()), "cpus": os.cpu_count()}
    if args.json:
        print(json.dumps(doc, indent=1))
    else:
        print(_table(results))
        print(f"load average {load0[0]:.2f} before, {doc['load_average_after'][0]:.2f} after; "
              f"{doc['cpus']} CPUs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
