"""The figure of docs/performance.md "Sensor stations": what the sensor stations and a
controller on them cost a step, and the controller's one step of delay.

Left: µs a step of the co-simulation alone, with the bench's 10-state controller, with the
bench's two IMUs (the CG's and a wing-tip accelerometer) and with both (the controller on the
tip's a_z), timed as ``bioflex-jsb bench`` times them (drivers/bench.py: interleaved runs of
STEPS × 1, 2, 4 steps, REPEATS times, the slope of the least times; process CPU time), each
with its ratio to the co-simulation. Right: two runs from the same trim in calm air with a
Python controller reading the tip's a_z, one commanding an elevator step of KICK_RAD at step
KICK_STEP: the difference of the CG's and the tip's a_z between the runs, row by row: 0 up to
and including the command's row, the first change in the next (tests/test_controller_sensors.py
checks the same to the bit).

    python scripts/sensor_controller_figure.py [OUT.png]   (default docs/img/sensor_controller.png)
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from bioflex_jsb.drivers import bench
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

STEPS, REPEATS = 300, 5
CONFIGS = ("cosim", "controlled", "sensors", "sensed_controlled")
LABELS = ("co-simulation", "+ controller\n(q, α, n_z)", "+ 2 IMUs",
          "+ 2 IMUs\n+ controller\n(tip a_z)")
KICK_STEP, KICK_RAD = 150, 0.05
TIP_AZ, CG_AZ = f"imu_{bench.BENCH_TIP_IMU}_az_m_s2", "imu_cg_az_m_s2"


class _Kick:
    """Reads the tip's a_z; commands KICK_RAD of elevator from step KICK_STEP (0: never)."""

    inputs = (TIP_AZ,)
    outputs = ("elevator",)

    def __init__(self, kick_rad: float) -> None:
        self.kick_rad, self.k = kick_rad, 0

    def step(self, t_s, signals):
        self.k += 1
        return {"elevator": self.kick_rad if self.k - 1 >= KICK_STEP else 0.0}


def costs(build) -> dict:
    """µs a step of :data:`CONFIGS` and their ratios to the co-simulation (bench's way)."""
    sb = bench.StepBench(build, steps=STEPS)
    try:
        configs = {k: v for k, v in sb.configurations(()).items() if k in CONFIGS}
        lengths = [f * STEPS for f in bench.LENGTH_FACTORS]
        times = {k: np.zeros((REPEATS, len(lengths))) for k in configs}
        load0 = list(os.getloadavg())
        for run in configs.values():  # warm-up, not timed
            run(STEPS)
        for i in range(REPEATS):
            for j, n in enumerate(lengths):
                for k, run in configs.items():
                    times[k][i, j] = run(n)[0]
        est = {k: bench.estimate_figure(lengths, v) for k, v in times.items()}
    finally:
        sb.close()
    return {"us_per_step": {k: est[k].as_dict() for k in CONFIGS},
            "ratio_to_cosim": {k: bench.ratio(est[k], est["cosim"]) for k in CONFIGS[1:]},
            "load_average": [load0, list(os.getloadavg())]}


def delay(build) -> dict[str, np.ndarray]:
    """The two runs' a_z differences (kick − none) [m/s²] at the CG and the tip."""
    cfg = RunConfig(15.0, parse_gust("none"), 0.2, 0.05, 0.0, DEFAULT_DT_S,
                    models=("coupled",))
    runs = [run_gust(Airframe(), build.model, "coupled", cfg, sensors=bench.bench_sensors(build),
                     controller=_Kick(kick)) for kick in (0.0, KICK_RAD)]
    return {name: runs[1][name] - runs[0][name] for name in (CG_AZ, TIP_AZ)}


def main(argv: list[str]) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = argv[0] if argv else "docs/img/sensor_controller.png"
    build = build_wing(VARIANTS["optimised"])
    c = costs(build)
    d = delay(build)
    print(json.dumps({**c, "delay_diff_m_s2": {k: v[KICK_STEP - 1:KICK_STEP + 3].tolist()
                                                for k, v in d.items()}}, indent=1))
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    us = [c["us_per_step"][k]["value"] or np.nan for k in CONFIGS]
    lo = [c["us_per_step"][k]["min"] or np.nan for k in CONFIGS]
    hi = [c["us_per_step"][k]["max"] or np.nan for k in CONFIGS]
    ax.bar(range(len(CONFIGS)), us, color=["0.6", "C0", "C1", "C2"],
           yerr=[np.subtract(us, lo), np.subtract(hi, us)], capsize=4)
    for i, k in enumerate(CONFIGS[1:], start=1):
        r = c["ratio_to_cosim"][k]["value"]
        ax.text(i, us[i] * 1.02, "—" if r is None else f"×{r:.2f}", ha="center", va="bottom")
    ax.set_xticks(range(len(CONFIGS)), LABELS, fontsize=8)
    ax.set_ylabel("µs a step (process CPU time)")
    load = c["load_average"][0][0]
    ax.set_title(f"cost a step, optimised wing, 15 m/s (load {load:.1f})", fontsize=10)
    k = np.arange(len(d[CG_AZ]))
    window = slice(KICK_STEP - 5, KICK_STEP + 12)
    bx.plot(k[window], d[CG_AZ][window], "o-", label="CG IMU a_z")
    bx.plot(k[window], d[TIP_AZ][window], "s-", label="tip accelerometer a_z (on the elastic axis)")
    bx.axvline(KICK_STEP, color="0.5", ls="--", label=f"command {KICK_RAD} rad (row {KICK_STEP})")
    bx.set_xlabel("row k (step of 1/960 s)")
    bx.set_ylabel("a_z with the command − without [m/s²]")
    bx.set_title("the command first shows in the next sample", fontsize=10)
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"figure written to {out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
