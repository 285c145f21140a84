"""How far the golden cases, the kernel-vs-Python agreement and the native export move when
only the platform changes: each configuration runs in its own subprocess.

Configurations (those the host's processor can run; ``/proc/cpuinfo`` flags): the host as
it is; numba compiling for a generic x86-64 instead of the host CPU (``NUMBA_CPU_NAME``,
with a fresh ``NUMBA_CACHE_DIR`` so that no machine code is shared); numba without
optimisation (``NUMBA_OPT=0``); one OpenBLAS thread instead of the default; OpenBLAS's
SkylakeX, Haswell, Zen and SandyBridge kernels (``OPENBLAS_CORETYPE``; threadpoolctl reports
the kernel that ran); glibc's libm without its FMA/AVX2 variants (``GLIBC_TUNABLES``); and
all of these changes at once.

Per configuration it reports, as fractions of each channel's range over the run (the metric
of ``tests/golden_cases.py``), against the stored histories: every case flown with the stored
wing, the coupled and QSD cases with the wing built in that configuration; the compiled
kernel against the Python step; the wing built there against the stored wing (per array, of
its largest magnitude); the repository's native files regenerated there against the
committed ones (largest relative change of a number; ``bioflex_jsb.generators.xml_writer.
number_difference``). Then the spread per channel: the largest over the configurations.

    python scripts/platform_spread.py            # a table
    python scripts/platform_spread.py --json     # the same as JSON
    python scripts/platform_spread.py --configs host,blas-zen

Takes about 15 s per configuration.
"""

from __future__ import annotations

import argparse
import json
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
# name → (environment changes, /proc/cpuinfo flags the configuration needs)
CONFIGS: dict[str, tuple[dict[str, str], tuple[str, ...]]] = {
    "host": ({}, ()),
    "numba-generic": ({"NUMBA_CPU_NAME": "generic", "NUMBA_CACHE_DIR": "<fresh>"}, ()),
    "numba-opt0": ({"NUMBA_OPT": "0", "NUMBA_CACHE_DIR": "<fresh>"}, ()),
    "blas-1-thread": ({"OPENBLAS_NUM_THREADS": "1"}, ()),
    "blas-skylakex": ({"OPENBLAS_CORETYPE": "SkylakeX"}, ("avx512f",)),
    "blas-haswell": ({"OPENBLAS_CORETYPE": "Haswell"}, ("avx2", "fma")),
    "blas-zen": ({"OPENBLAS_CORETYPE": "Zen"}, ("avx2", "fma")),
    "blas-sandybridge": ({"OPENBLAS_CORETYPE": "SandyBridge"}, ("avx",)),
    "libm-no-fma": ({"GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX512F,-AVX2_Usable,"
                                       "-FMA_Usable,-AVX512F_Usable"}, ()),
    "all-changed": ({"NUMBA_CPU_NAME": "generic", "NUMBA_CACHE_DIR": "<fresh>",
                     "OPENBLAS_CORETYPE": "Zen", "OPENBLAS_NUM_THREADS": "1",
                     "GLIBC_TUNABLES": "glibc.cpu.hwcaps=-AVX2,-FMA,-AVX2_Usable,-FMA_Usable"},
                    ("avx2", "fma")),
}
WORKER_TIMEOUT_S = 600  # one configuration takes ~15 s; this only stops a hung one


def cpu_flags() -> set[str]:
    """The processor's feature flags (empty where /proc/cpuinfo has none: not Linux x86)."""
    try:
        text = Path("/proc/cpuinfo").read_text(encoding="utf-8")
    except OSError:
        return set()
    for line in text.splitlines():
        if line.startswith("flags"):
            return set(line.split(":", 1)[1].split())
    return set()


# -- the worker: one configuration --------------------------------------------------------------
def worker(out: Path) -> None:
    """Fly, compare and regenerate in this process's configuration; pickle to ``out``."""
    sys.path.insert(0, str(REPO))
    import numpy as np
    import scipy.linalg  # noqa: F401  (loads scipy's OpenBLAS, for threadpoolctl's report)
    from threadpoolctl import threadpool_info

    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.drivers.native import repository_files
    from bioflex_jsb.generators.xml_writer import number_difference
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from tests import golden_cases as G

    result: dict = {"blas": sorted({f"{i.get('architecture')} x{i.get('num_threads')}"
                                    for i in threadpool_info() if i.get("user_api") == "blas"})}
    stored_wing, built = G.stored_wing(), G.built_wing()
    result["wing"] = G.compare_wing(stored_wing, built)
    result["omega_rad_s"] = [float(w) for w in built.frequencies_rad_s]
    golden, histories = {}, {}
    for wing, cases in (("stored", G.CASES), ("built", G.WING_CASES)):
        for case in cases:
            run = G.fly_case(case, stored_wing if wing == "stored" else built)
            golden[(case, wing)] = G.compare(G.stored(case), run)
            # wrapped angles unwrapped, so that the spread between configurations is the
            # golden comparison's
            histories[(case, wing)] = {
                n: (np.unwrap if n in G.WRAPPED_CHANNELS else np.asarray)(v)[::G.DECIMATE]
                for n, v in run.channels.items()}
    result["golden"], result["histories"] = golden, histories
    setup = RunConfig(G.SPEED_M_S, parse_gust(G.GUST), G.DURATION_S)
    kernel = {}
    for model in ("rigid", "coupled", "qsd"):
        fast = run_gust(Airframe(), stored_wing, model, setup, compiled=True)
        slow = run_gust(Airframe(), stored_wing, model, setup, compiled=False)
        kernel[model] = G.compare_runs(slow, fast)
    result["kernel"] = kernel
    files = {}
    for rel, text in repository_files().items():
        committed = (REPO / rel).read_text(encoding="utf-8")
        files[rel] = number_difference(committed, text)
    result["files"] = files
    out.write_bytes(pickle.dumps(result))


# -- the parent: every configuration -------------------------------------------------------------
def run_config(name: str, changes: dict[str, str]) -> dict:
    with tempfile.TemporaryDirectory(prefix=f"spread-{name}-") as tmp:
        env = dict(os.environ)
        for key, value in changes.items():
            env[key] = str(Path(tmp) / "numba-cache") if value == "<fresh>" else value
        out = Path(tmp) / "result.pickle"
        proc = subprocess.run([sys.executable, str(Path(__file__).resolve()), "--worker",
                               str(out)], env=env, capture_output=True, text=True,
                              timeout=WORKER_TIMEOUT_S, cwd=REPO)
        if proc.returncode != 0:
            raise SystemExit(f"configuration {name} failed:\n{proc.stderr[-3000:]}")
        return pickle.loads(out.read_bytes())


def summarise(results: dict[str, dict]) -> dict:
    """Per configuration the worst of each check; per (case, wing) and channel the largest
    over the configurations, against the stored history and between configurations."""
    import numpy as np

    configs = {}
    for name, r in results.items():
        def worst(errors: dict[str, float]) -> dict:
            key = max(errors, key=errors.get)
            return {"channel": key, "value": errors[key]}
        files = r["files"]
        configs[name] = {
            "blas": r["blas"],
            "omega_1_rad_s": r["omega_rad_s"][0],
            "wing": worst(r["wing"]),
            "golden": {f"{c}/{w}": worst(e) for (c, w), e in r["golden"].items()},
            "kernel_vs_python": {m: worst(e) for m, e in r["kernel"].items()},
            "files_text_differs": sum(1 for v in files.values() if v != 0.0),
            "files_structure_differs": sorted(k for k, v in files.items() if v is None),
            "files_number_rel": max((v for v in files.values() if v is not None), default=0.0),
        }
    per_channel = {}
    first = next(iter(results.values()))
    for key in first["golden"]:
        stored_err = {n: max(r["golden"][key][n] for r in results.values())
                      for n in first["golden"][key]}
        hist = [r["histories"][key] for r in results.values()]
        between = {}
        for n in hist[0]:
            span = float(np.ptp(hist[0][n])) or 1.0
            stack = np.array([h[n] for h in hist])
            between[n] = float(np.max(np.ptp(stack, axis=0)) / span)
        per_channel[f"{key[0]}/{key[1]}"] = {"vs_stored": stored_err, "between_configs": between}
    return {"configs": configs, "per_channel": per_channel,
            "wing_per_array": {a: max(r["wing"][a] for r in results.values())
                               for a in first["wing"]}}


def print_table(summary: dict) -> None:
    print("Per configuration (fractions of a channel's range; wing: of the array's largest "
          "magnitude; files: relative change of a number)")
    keys = list(next(iter(summary["configs"].values()))["golden"])
    for name, c in summary["configs"].items():
        print(f"\n{name}: BLAS {', '.join(c['blas'])}; omega_1 {c['omega_1_rad_s']!r} rad/s")
        print(f"  wing vs stored        {c['wing']['value']:.2e} ({c['wing']['channel']})")
        for k in keys:
            g = c["golden"][k]
            print(f"  {k:22s}{g['value']:.2e} ({g['channel']})")
        kv = ", ".join(f"{m} {v['value']:.1e}" for m, v in c["kernel_vs_python"].items())
        print(f"  kernel vs Python      {kv}")
        print(f"  native files          {c['files_text_differs']} differ in text, largest "
              f"number change {c['files_number_rel']:.2e}"
              + (f", structure differs: {c['files_structure_differs']}"
                 if c["files_structure_differs"] else ""))
    print("\nSpread per channel, largest over the configurations (vs the stored history / "
          "between configurations), channels above 1e-12:")
    for key, d in summary["per_channel"].items():
        rows = sorted(d["vs_stored"].items(), key=lambda kv: -kv[1])
        shown = ", ".join(f"{n} {v:.1e}/{d['between_configs'][n]:.1e}" for n, v in rows
                          if v > 1e-12)
        print(f"  {key:22s}{shown or 'all below 1e-12'}")
    print("\nWing arrays, largest over the configurations: " + ", ".join(
        f"{a} {v:.1e}" for a, v in summary["wing_per_array"].items() if v > 0.0))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--configs", help="comma-separated subset of: " + ", ".join(CONFIGS))
    parser.add_argument("--worker", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.worker)
        return 0
    names = list(CONFIGS) if not args.configs else args.configs.split(",")
    unknown = [n for n in names if n not in CONFIGS]
    if unknown:
        print(f"unknown configuration {unknown[0]!r}; accepted: {', '.join(CONFIGS)}",
              file=sys.stderr)
        return 2
    flags = cpu_flags()
    skipped = {n: CONFIGS[n][1] for n in names if not set(CONFIGS[n][1]) <= flags}
    results = {n: run_config(n, CONFIGS[n][0]) for n in names if n not in skipped}
    if not results:
        print("no configuration this processor can run", file=sys.stderr)
        return 2
    summary = summarise(results)
    summary["skipped"] = {n: f"needs {', '.join(f)}" for n, f in skipped.items()}
    summary["inherited"] = {k: v for k, v in os.environ.items()
                            if k.startswith(("OPENBLAS", "NUMBA", "GLIBC_TUNABLES", "OMP"))}
    if args.json:
        print(json.dumps(summary, indent=1))
    else:
        print(f"inherited environment: {summary['inherited'] or 'none of OPENBLAS*/NUMBA*'}")
        if skipped:
            print("skipped (processor lacks the kernel's instructions): "
                  + ", ".join(f"{n} ({v})" for n, v in summary["skipped"].items()))
        print_table(summary)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
