"""Sweep scaling: the same campaign on 1 and 2 local worker processes, and on a Dask
LocalCluster of 2 single-threaded worker processes.

    python scripts/bench_sweep.py [CAMPAIGN.toml] [--repeat N] [--json]

Prints, per configuration, the wall time [s] of the sweep with and without starting the
workers (forkserver / LocalCluster), the speedup of 2 local workers over 1 and the overhead
of Dask against 2 local processes (targets of issue 7: speedup ≥ 1.7 on 2 cores, Dask
overhead ≤ 15 %). Rows go to a CSV store in a temporary directory, as a real sweep writes
them. Each figure is the best of --repeat runs. Needs at least 2 cores to mean anything.
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


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("campaign", nargs="?",
                        default=str(ROOT / "scripts" / "campaigns" / "example.toml"))
    parser.add_argument("--repeat", type=int, default=1, help="runs per configuration")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)

    from bioflex_jsb.sweep.dask_cluster import DaskExecutor
    from bioflex_jsb.sweep.local import LocalExecutor, default_workers

    campaign = load_campaign(args.campaign)
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
    if args.json:
        print(json.dumps(figures, indent=2))
        return 0
    print(f"campaign {campaign.name}: {campaign.n_cases} cases; {figures['cores']} cores "
          f"available; best of {max(1, args.repeat)}")
    print(f"{'executor':<10} {'start [s]':>10} {'sweep [s]':>10} {'total [s]':>10} "
          f"{'per case [ms]':>14}")
    for name, r in results.items():
        print(f"{name:<10} {r['startup_s']:10.2f} {r['sweep_s']:10.2f} {r['total_s']:10.2f} "
              f"{1e3 * r['sweep_s'] / campaign.n_cases:14.1f}")
    print(f"speedup 2 vs 1 local workers: {figures['speedup_2_over_1_sweep']:.2f} (sweep), "
          f"{figures['speedup_2_over_1_total']:.2f} (with start-up); target ≥ 1.7")
    print(f"Dask LocalCluster(2) vs 2 local processes: "
          f"{100 * figures['dask_overhead_sweep']:+.1f} % (sweep), "
          f"{100 * figures['dask_overhead_total']:+.1f} % (with start-up); target ≤ 15 %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
