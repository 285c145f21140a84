"""Cost of the section loads in a gust run (docs/loads.md, "In every gust run"): the same run
with and without ``loads=``, interleaved repeats (the machine is shared: the order alternates
and the medians are reported), and the loads model's build alone.

    python scripts/bench_loads.py [REPEATS [MODEL [DURATION_S]]]   # default 7 coupled 10
"""
import statistics
import sys
import time

from bioflex_jsb import api
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.loads.model import build_loads_model
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 7
model = sys.argv[2] if len(sys.argv) > 2 else "coupled"
duration = float(sys.argv[3]) if len(sys.argv) > 3 else 10.0
w = api.load_wing("optimised")
setup = RunConfig(15.0, parse_gust("1cos:3:5"), duration)
af = Airframe()
trim = None
run_gust(af, w.model, model, setup, loads=w)  # warm: compile, caches
times = {"without": [], "with": []}
for r in range(repeats):
    order = ("without", "with") if r % 2 == 0 else ("with", "without")
    for kind in order:
        t0 = time.perf_counter()
        run = run_gust(af, w.model, model, setup, loads=w if kind == "with" else None)
        times[kind].append(time.perf_counter() - t0)
steps = run.meta["steps"]
a, b = statistics.median(times["without"]), statistics.median(times["with"])
print(f"{model} {duration:g} s ({steps} steps), {repeats} interleaved repeats")
for kind, med in (("without", a), ("with", b)):
    runs = [round(x, 4) for x in times[kind]]
    print(f"{kind + ' loads:':<15} median {med:.4f} s = {1e6 * med / steps:.2f} us/step; "
          f"runs {runs}")

builds = []
for _ in range(repeats):
    t0 = time.perf_counter()
    build_loads_model(w, 15.0, static="rigid" if model == "rigid" else "elastic")
    builds.append(time.perf_counter() - t0)
build = statistics.median(builds)
print(f"loads: +{1e6 * (b - a) / steps:.2f} us/step ({100 * (b - a) / a:.1f} %), of which the "
      f"loads model once per run {1e3 * build:.1f} ms = {1e6 * build / steps:.2f} us/step")
