"""RSS of a long ``bioflex-jsb sitl`` session: runs it as a subprocess and samples its
resident set size (/proc/PID/status VmRSS) against the simulated time it reports over
MAVLink. ``python scripts/sitl_rss.py --minutes 30 --speedup 8 [--log DIR]``; prints JSON
(samples and the growth after warm-up)."""

from __future__ import annotations

import argparse
import json
import socket
import subprocess
import sys
import time
from pathlib import Path

from pymavlink import mavutil


def rss_mb(pid: int) -> float:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1]) / 1024.0
    return float("nan")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=30.0)
    ap.add_argument("--speedup", type=float, default=8.0)
    ap.add_argument("--log", default=None, help="directory for the split MCAP log")
    ap.add_argument("--log-max-mb", type=float, default=50.0)
    ap.add_argument("--warmup-minutes", type=float, default=3.0)
    a = ap.parse_args(argv)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    duration = a.minutes * 60.0
    cmd = [sys.executable, "-m", "bioflex_jsb", "sitl", "--mavlink", f"udpin:127.0.0.1:{port}",
           "--speedup", str(a.speedup), "--duration", str(duration), "--json"]
    if a.log:
        cmd += ["--out", str(Path(a.log) / "session.mcap"), "--log-max-mb", str(a.log_max_mb),
                "--force"]
    else:
        cmd += ["--no-log"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    c = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=255,
                                   dialect="common")
    samples, last_beat, last_sample, t_sim = [], 0.0, 0.0, 0.0
    while proc.poll() is None:
        now = time.monotonic()
        if now - last_beat > 1.0:
            c.mav.heartbeat_send(6, 8, 0, 0, 0)
            last_beat = now
        m = c.recv_match(type="SYSTEM_TIME", blocking=True, timeout=0.2)
        if m is not None:
            t_sim = m.time_boot_ms / 1000.0
        if now - last_sample > 5.0:
            last_sample = now
            try:
                samples.append((round(t_sim / 60.0, 2), round(rss_mb(proc.pid), 1)))
            except FileNotFoundError:
                break
    out, err = proc.communicate()
    warm = [r for t, r in samples if t >= a.warmup_minutes]
    result = {"samples_min_mb": samples,
              "rss_after_warmup_mb": [min(warm), max(warm)] if warm else None,
              "growth_after_warmup_mb": (warm[-1] - warm[0]) if len(warm) > 1 else None,
              "exit": proc.returncode, "summary": json.loads(out) if out.strip() else err}
    print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
