"""Per-step cost of the 3-D scene (docs/logging.md): 10 s gust runs (coupled, the Fig. 21
case) without a log, logged, logged with the scene; interleaved repeats after one warm-up
round; process CPU time of run_gust. Writes cost_*.mcap in the current directory. (The live
server's cost with no client: tests/test_live.py and docs/logging.md, "Live view".)

    python scripts/scene_cost.py [REPEATS]   (default 7)
"""

from __future__ import annotations

import json
import os
import sys
import time

import numpy as np

from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks.mcap import RunLog

MODES = ("none", "log", "scene")
DURATION_S = 10.0


def _spread(values) -> dict[str, float]:
    return {"median": float(np.median(values)), "min": float(min(values)),
            "max": float(max(values))}


def main(argv: list[str]) -> int:
    repeats = int(argv[0]) if argv else 7
    build = build_wing(VARIANTS["optimised"])
    desc = RunDescription("gust", "optimised", 15.0, gust="sharp:3", models=("coupled",),
                          duration_s=DURATION_S)
    setup = RunConfig(15.0, parse_gust("sharp:3"), DURATION_S, 0.5)
    air = Airframe()
    cpu: dict[str, list[float]] = {m: [] for m in MODES}
    sizes = {}
    for r in range(repeats + 1):
        for mode in MODES:
            log = None
            if mode != "none":
                log = RunLog.open(f"cost_{mode}.mcap", desc, wing_variant=build.variant.as_dict(),
                                  scene=1.0 if mode == "scene" else None)
            t0 = time.process_time()
            run_gust(air, build.model, "coupled", setup,
                     recorder=log.recorder("coupled") if log else None, keep="envelope")
            if log:
                log.close()
                sizes[mode] = os.path.getsize(f"cost_{mode}.mcap")
            if r:  # the first round warms up (kernel load, caches)
                cpu[mode].append(time.process_time() - t0)
    steps = round(DURATION_S / setup.dt_s)
    per = {m: np.array(v) * 1e6 / steps for m, v in cpu.items()}  # [µs per step]
    res = {f"{m}_us_per_step": _spread(per[m]) for m in MODES}
    res["log_cost_us_per_step"] = _spread(per["log"] - per["none"])
    res["scene_cost_us_per_step"] = _spread(per["scene"] - per["log"])
    res["logged_ratio_no_scene"] = float(np.median(per["log"] / per["none"]))
    res["logged_ratio_scene"] = float(np.median(per["scene"] / per["none"]))
    res["sizes_bytes"] = sizes
    res["load_average"] = os.getloadavg()
    res["repeats"] = repeats
    print(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
