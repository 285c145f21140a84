"""Sweep scaling: the same campaign on 1 and 2 local worker processes, and on a Dask
LocalCluster of 2 single-threaded worker processes.

    python scripts/bench_sweep.py [CAMPAIGN.toml] [--repeat N] [--json]

Prints, per configuration, the wall time [s] of the sweep with and without starting the
workers (forkserver / LocalCluster), cases per second per worker (cases / sweep time /
workers) with the load average after each run, the speedup of 2 local workers over 1 and
the overhead of Dask against 2 local processes (targets of docs/sweeps.md: speedup ≥ 1.7 on 2
cores, Dask overhead ≤ 15 %), and the fixed cost of a case measured in a fresh process
(``--costs``, :data:`COSTS`: imports, the step kernel's load, the wing's build and flutter
search, the airframe's load, the trim, the eigenvalues; a worker's first case against a
later one). Rows go to a CSV store in a temporary directory, as a real sweep writes them.
Each figure is the best of --repeat runs. Needs at least 2 cores to mean anything.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bioflex_jsb.sweep.campaign import load_campaign  # noqa: E402
from bioflex_jsb.sweep.driver import run_sweep  # noqa: E402
from bioflex_jsb.sweep.store import open_store  # noqa: E402


def timed(make_executor, campaign, tmp: Path, tag: str) -> dict[str, float]:
    """Wall times [s]: ``total`` (start workers + sweep) and ``sweep`` (cases only)."""
    store = open_store(tmp / f"{tag}-{time.time_ns()}.csv", campaign.columns(), resume=False)
    t0 = time.perf_counter()
    with make_executor() as ex:
        t1 = time.perf_counter()
        summary = run_sweep(campaign.cases(), store, ex)
        t2 = time.perf_counter()
    store.close()
    t3 = time.perf_counter()
    if summary.counts["failed"]:
        print(f"warning: {summary.counts['failed']} cases failed in {tag}", file=sys.stderr)
    return {"total_s": t3 - t0, "startup_s": t1 - t0, "sweep_s": t2 - t1}


def best(runs: list[dict[str, float]]) -> dict[str, float]:
    return min(runs, key=lambda r: r["sweep_s"])


# The fixed cost of a case, part by part, in a fresh process (one BLAS thread, as a worker):
# what a worker pays before and during its first case, and what every case pays.
COSTS = """import json, os, time
T = time.perf_counter
out = {}
t = T(); import bioflex_jsb.sweep.evaluate as E, bioflex_jsb.drivers.gust  # noqa
out["import_preloaded_ms"] = (T() - t) * 1e3
t = T()
import bioflex_jsb.flight_dynamics.eigen, bioflex_jsb.flight_dynamics.flutter_engine  # noqa
import bioflex_jsb.structures.wing_model  # noqa
out["import_rest_ms"] = (T() - t) * 1e3
t = T(); from bioflex_jsb.simulation import step_kernel; step_kernel.compile_now()
out["kernel_load_ms"] = (T() - t) * 1e3
from bioflex_jsb.sweep.campaign import load_campaign
from bioflex_jsb.flight_dynamics.wing_model import build_wing
from bioflex_jsb.flight_dynamics.eigen import modes_at
cases = load_campaign(os.environ["CAMPAIGN"]).cases()
c = cases[0]
t = T(); b = build_wing(c.wing, mass_basis=c.settings.mass_basis)
out["wing_build_ms"] = (T() - t) * 1e3
t = T(); E._flutter(c, b); out["flutter_ms"] = (T() - t) * 1e3
t = T(); af = E.airframe(); out["airframe_ms"] = (T() - t) * 1e3
t = T(); af.trim(c.speed_m_s); out["trim_ms"] = (T() - t) * 1e3
t = T(); modes_at(c.model, [c.speed_m_s], b.model); out["eigenvalues_ms"] = (T() - t) * 1e3
later = [c2 for c2 in cases[1:] if c2.wing == c.wing][:4]
t = T()
for c2 in later:
    E.run_case(c2)
out["later_case_ms"] = (T() - t) * 1e3 / len(later)
out["load_average"] = list(os.getloadavg())
print(json.dumps(out))
"""


def fixed_costs(campaign_path: str) -> dict[str, float]:
    """:data:`COSTS` in a child process [ms] with the load average after it."""
    import subprocess

    env = {**os.environ, "CAMPAIGN": str(campaign_path), "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    run = subprocess.run([sys.executable, "-c", COSTS], env=env, capture_output=True,
                         text=True, check=True, timeout=600)
    return json.loads(run.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("campaign", nargs="?",
                        default=str(ROOT / "scripts" / "campaigns" / "example.toml"))
    parser.add_argument("--repeat", type=int, default=1, help="runs per configuration")
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--costs", action="store_true",
                        help="also measure the fixed cost of a case, part by part")
    args = parser.parse_args(argv)

    from bioflex_jsb.sweep.dask_cluster import DaskExecutor
    from bioflex_jsb.sweep.local import LocalExecutor, default_workers

    campaign = load_campaign(args.campaign)
    workers = {"local-1": 1, "local-2": 2, "dask-2": 2}
    configs = {
        "local-1": lambda: LocalExecutor(1),
        "local-2": lambda: LocalExecutor(2),
        "dask-2": lambda: DaskExecutor(None, workers=2),
    }
    results: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as d:
        timed(configs["local-1"], campaign, Path(d), "warm-up")  # caches, forkserver
        for name, make in configs.items():
            results[name] = best([timed(make, campaign, Path(d), name)
                                  for _ in range(max(1, args.repeat))])
            results[name]["cases_per_s_per_worker"] = (
                campaign.n_cases / results[name]["sweep_s"] / workers[name])
            results[name]["load_average"] = list(os.getloadavg())
    l1, l2, dk = results["local-1"], results["local-2"], results["dask-2"]
    figures = {
        "campaign": campaign.name,
        "cases": campaign.n_cases,
        "cores": default_workers(),
        "cpu_count": os.cpu_count(),
        "runs": results,
        "speedup_2_over_1_sweep": l1["sweep_s"] / l2["sweep_s"],
        "speedup_2_over_1_total": l1["total_s"] / l2["total_s"],
        "dask_overhead_sweep": dk["sweep_s"] / l2["sweep_s"] - 1.0,
        "dask_overhead_total": dk["total_s"] / l2["total_s"] - 1.0,
    }
    if args.costs:
        figures["fixed_costs_ms"] = fixed_costs(args.campaign)
    if args.json:
        print(json.dumps(figures, indent=2))
        return 0
    print(f"campaign {campaign.name}: {campaign.n_cases} cases; {figures['cores']} cores "
          f"available; best of {max(1, args.repeat)}")
    print(f"{'executor':<10} {'start [s]':>10} {'sweep [s]':>10} {'total [s]':>10} "
          f"{'per case [ms]':>14} {'cases/s/worker':>15}  load average")
    for name, r in results.items():
        load = ", ".join(f"{x:.1f}" for x in r["load_average"])
        print(f"{name:<10} {r['startup_s']:10.2f} {r['sweep_s']:10.2f} {r['total_s']:10.2f} "
              f"{1e3 * r['sweep_s'] / campaign.n_cases:14.1f} "
              f"{r['cases_per_s_per_worker']:15.2f}  {load}")
    print(f"speedup 2 vs 1 local workers: {figures['speedup_2_over_1_sweep']:.2f} (sweep), "
          f"{figures['speedup_2_over_1_total']:.2f} (with start-up); target ≥ 1.7")
    print(f"Dask LocalCluster(2) vs 2 local processes: "
          f"{100 * figures['dask_overhead_sweep']:+.1f} % (sweep), "
          f"{100 * figures['dask_overhead_total']:+.1f} % (with start-up); target ≤ 15 %")
    if "fixed_costs_ms" in figures:
        c = figures["fixed_costs_ms"]
        load = ", ".join(f"{x:.1f}" for x in c.pop("load_average"))
        print("fixed cost of a case [ms] (fresh process; load average " + load + "): "
              + ", ".join(f"{k.removesuffix('_ms')} {v:.0f}" for k, v in c.items()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
