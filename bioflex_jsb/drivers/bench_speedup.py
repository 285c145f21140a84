"""Autopilots faster than real time: ArduPlane's lock step and the sitl vehicle's pacing.

Benchmarks (commands print their figures; tests/test_bench.py checks only their shape and
the rules below on synthetic runs):

* :func:`ardupilot_speedup`: the ``bioflex-jsb ardupilot`` backend against the stand-in of
  ArduPilot's side (``tests/ardupilot_standin.py``, in a process of its own as ArduPlane
  is), at each of ArduPilot's physics rates asked for (SIM_RATE_HZ; the stand-in plays
  ArduPlane's ``rate_hz``, which the backend follows with k steps of 1/960 s per frame:
  ``bioflex_jsb/links/ardupilot_rate.py``): frames answered per second, the free real-time
  factor and the highest ``--speedup`` held within :data:`SPEEDUP_TOLERANCE`;
* :func:`sitl_speedup`: the ``sitl`` vehicle's pacing error at each speed-up.

A speed-up is *held* when the paced run's real-time factor is within
:data:`SPEEDUP_TOLERANCE` of it (docs/ardupilot.md's criterion), and the figure is the highest held
with every lower one held too, per round.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from pathlib import Path

from bioflex_jsb.drivers.bench import Spread
from bioflex_jsb.links.ardupilot_json import PEER_SILENCE_S
from bioflex_jsb.runtime.fdm import Airframe

# Speed-ups ArduPlane is asked for (its --speedup) against the lock-stepped backend.
ARDUPILOT_SPEEDUPS = (1.0, 2.0, 5.0, 8.0, 10.0, 12.0, 15.0, 20.0, 30.0, 40.0)
# ArduPilot's physics rates measured [Hz]: SITL's default SIM_RATE_HZ (libraries/SITL/
# SITL.cpp, 1200: the backend answers it at its own 960 Hz, one step a frame) and 240 Hz
# (4 steps a frame, 4.17 ms; ArduPlane's main loop runs at 50 Hz, SCHED_LOOP_RATE's default)
ARDUPILOT_SIM_RATES_HZ = (1200, 240)
SPEEDUP_TOLERANCE = 0.05
SITL_SPEEDUPS = (1.0, 2.0, 5.0, 8.0, 10.0, 12.0, 15.0, 20.0, 30.0)
SITL_P99_BAR_MS = 5.0  # the sitl vehicle's pacing error bar at a speed-up (docs/sitl.md)
STANDIN = Path(__file__).resolve().parents[2] / "tests" / "ardupilot_standin.py"
BACKEND_START_S = 300.0  # the backend's pre-flight check, imports and trim, under load
# Between two stand-in processes: the backend re-binds to a new ArduPilot process (a reset)
# only after the old one's silence of PEER_SILENCE_S; 0.5 s more for the process start.
STANDIN_GAP_S = PEER_SILENCE_S + 0.5


def held(rtf: float, speedup: float) -> bool:
    """Whether a run at ``speedup`` kept its real-time factor ``rtf`` within
    :data:`SPEEDUP_TOLERANCE` of it."""
    return abs(rtf - speedup) <= SPEEDUP_TOLERANCE * speedup


def max_held(runs: Sequence[dict]) -> dict[str, object]:
    """From the stand-in's runs (dicts with ``speedup``, ``real_time_factor``, ``repeat``,
    ``grounded``): the real-time factor per speed-up (median, min, max over the repeats),
    the highest speed-up held in each repeat (every lower one held too) and its spread."""
    repeats = sorted({r["repeat"] for r in runs})
    speedups = sorted({r["speedup"] for r in runs if r["speedup"] is not None})
    best = []
    for i in repeats:
        top = 0.0
        for s in speedups:
            r = next(r for r in runs if r["repeat"] == i and r["speedup"] == s)
            if not held(r["real_time_factor"], s):
                break
            top = s
        best.append(top)
    by_speedup = {f"{s:g}": Spread.of([r["real_time_factor"] for r in runs
                                       if r["speedup"] == s]).as_dict() for s in speedups}
    return {"max_speedup_held": Spread.of(best).as_dict(), "per_repeat": best,
            "real_time_factor_by_speedup": by_speedup}


def _wait_for_port(proc, deadline_s: float) -> int:
    """The UDP port from the backend's start line (``physics on UDP HOST:PORT``)."""
    end = time.monotonic() + deadline_s
    while time.monotonic() < end:
        line = proc.stderr.readline()
        if not line:
            break
        if "physics on UDP" in line:
            return int(line.split("physics on UDP ", 1)[1].split()[0].rsplit(":", 1)[1])
    raise RuntimeError("the ardupilot backend did not start: " + (proc.stderr.read() or "")[-400:])


def rate_figures(runs: Sequence[dict], dt_s: float) -> dict[str, object]:
    """One rate's figures from its stand-in runs (each with ``repeat``): the free runs'
    frames answered per second, frames per second of the loop and real-time factor; the
    physics steps per frame they advanced (physics time per frame over ``dt_s`` [s]: the k
    the backend chose); and :func:`max_held` of the paced runs."""
    free = [r for r in runs if r["speedup"] is None]
    paced = [r for r in runs if r["speedup"] is not None]
    return {
        "answered_per_s": Spread.of([r["answered_per_s"] for r in free]).as_dict(),
        "loop_frames_per_s": Spread.of([r["frames_per_s"] for r in free]).as_dict(),
        "free_real_time_factor": Spread.of([r["real_time_factor"] for r in free]).as_dict(),
        "steps_per_frame": Spread.of([r["physics_s"] / r["frames"] / dt_s
                                      for r in free]).as_dict(),
        **max_held(paced),
        "grounded_frames": sum(r["grounded"] for r in runs),
    }


def ardupilot_speedup(frames: int = 3000, repeat: int = 3,
                      speedups: Sequence[float] = ARDUPILOT_SPEEDUPS,
                      logged: bool = True, speed_m_s: float = 15.0,
                      sim_rates_hz: Sequence[int] = ARDUPILOT_SIM_RATES_HZ
                      ) -> dict[str, object]:
    """The lock-stepped ArduPilot JSON backend (``bioflex-jsb ardupilot``, its MCAP log
    written when ``logged``, as a session logs by default) against the stand-in: ``repeat``
    rounds, each a stand-in process per rate of ``sim_rates_hz`` [Hz] (the stand-in's
    ``--sim-rate-hz``: ArduPlane's rate_hz towards that SIM_RATE_HZ; a new process is an
    ArduPilot restart for the backend: launched again, k back to 1) flying a warm-up
    (launch and settle), a free run (frames as fast as the backend answers them) and a run
    paced to each speed-up as ArduPilot paces itself, ``frames`` frames each. Returns, per
    rate (``by_sim_rate``), :func:`rate_figures`, and the load average before and after;
    ``available`` False (and why) without the stand-in (an installed package has no
    tests/)."""
    import signal
    import threading

    if not STANDIN.is_file():
        return {"available": False, "reason": f"the stand-in {STANDIN} is not here (a "
                "source checkout has it)"}
    load0 = list(os.getloadavg())
    throttle_us = round(1000.0 + 1000.0 * Airframe().trim(speed_m_s).throttle)
    runs: dict[int, list[dict]] = {int(r): [] for r in sim_rates_hz}
    with tempfile.TemporaryDirectory() as tmp:
        log = ["--out", str(Path(tmp) / "ardupilot.mcap")] if logged else ["--no-log"]
        # the launcher 100 m up: the trimmed aircraft, surfaces at trim, flies the whole
        # measurement without reaching the ground (a stop would leave it at rest)
        backend = subprocess.Popen(
            [sys.executable, "-m", "bioflex_jsb", "ardupilot", "--port", "0", "--speed",
             f"{speed_m_s:g}", "--launch-height", "100", "--json", *log],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            port = _wait_for_port(backend, BACKEND_START_S)
            drain = threading.Thread(target=backend.stderr.read, daemon=True)
            drain.start()
            first = True
            for i in range(repeat):
                for rate in runs:
                    if not first:
                        time.sleep(STANDIN_GAP_S)
                    first = False
                    run = subprocess.run(
                        [sys.executable, str(STANDIN), "--target", f"127.0.0.1:{port}",
                         "--frames", str(frames), "--repeat", "1", "--throttle-us",
                         str(throttle_us), "--sim-rate-hz", str(rate),
                         "--speedups", ",".join(f"{s:g}" for s in speedups)],
                        capture_output=True, text=True, check=True, timeout=3600)
                    runs[rate] += [{**r, "repeat": i} for r in json.loads(run.stdout)["runs"]]
        finally:
            backend.send_signal(signal.SIGINT)
            out, _ = backend.communicate(timeout=120)
    session = json.loads(out)
    dt_s = session["dt_s"]
    by_rate = {f"{rate}": rate_figures(rs, dt_s) for rate, rs in runs.items()}
    grounded = sum(b["grounded_frames"] for b in by_rate.values())
    stops = session["stop_count"]
    return {
        "available": True, "logged": logged, "frames_per_run": frames, "repeat": repeat,
        "dt_s": dt_s, "physics_rate_hz": 1.0 / dt_s, "sim_rates_hz": list(runs),
        "by_sim_rate": by_rate, "tolerance": SPEEDUP_TOLERANCE,
        "trusted": grounded == 0 and stops == 0,
        "reason": None if grounded == 0 and stops == 0 else
        f"the aircraft was not flying in {grounded} measured frames ({stops} valid-range "
        "stops)",
        "session_real_time_factor": session["real_time_factor"],
        "load_average_before": load0, "load_average": list(os.getloadavg()),
    }


def sitl_speedup(duration_s: float = 2.0, speedups: Sequence[float] = SITL_SPEEDUPS,
                 repeat: int = 1) -> dict[str, object]:
    """The ``sitl`` vehicle's pacing error at each speed-up (``duration_s`` of wall time
    each, ``duration_s`` × speed-up simulated; logged and serviced as a session,
    :func:`~bioflex_jsb.drivers.sitl.measure_pacing`), ``repeat`` times interleaved; the
    highest speed-up with p99 ≤ :data:`SITL_P99_BAR_MS` and no resync in each repeat
    (every lower one too), with the load average."""
    from bioflex_jsb.drivers.sitl import measure_pacing

    rows: list[dict] = []
    load0 = list(os.getloadavg())
    with tempfile.TemporaryDirectory() as tmp:
        # not timed: the first session of a process loads the link's and the log's code
        measure_pacing(duration_s=0.2, log_path=str(Path(tmp) / "warm-up.mcap"))
        for i in range(repeat):
            for s in speedups:
                r = measure_pacing(duration_s=duration_s * s, speedup=s,
                                   log_path=str(Path(tmp) / f"sitl{i}-{s:g}.mcap"))
                rows.append({**r, "repeat": i, "load_average": os.getloadavg()[0]})
    best = []
    for i in range(repeat):
        top = 0.0
        for s in speedups:
            r = next(r for r in rows if r["repeat"] == i and r["speedup"] == s)
            if not (r["p99_ms"] <= SITL_P99_BAR_MS and r["resyncs"] == 0):
                break
            top = s
        best.append(top)
    return {"max_speedup_p99_within_bar": Spread.of(best).as_dict(), "per_repeat": best,
            "bar_p99_ms": SITL_P99_BAR_MS, "runs": rows, "load_average_before": load0,
            "load_average": list(os.getloadavg())}
