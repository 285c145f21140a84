"""Golden check cases: the paper's Fig. 21 run stored as reference time histories.

The case (Section 5 of the paper): the optimised wing at 15 m/s through a 3 m/s sharp-edged
gust that starts at 0.5 s, flown for 3 s at the default co-simulation step (1/960 s) through
the rigid, coupled and quasi-static-deformation (QSD) models of the co-simulation and through
the native XML modal wing (``aircraft/bioflex_optimised``).

Each history is stored in ``tests/golden/fig21_<model>.csv``: every 8th step (120 samples per
second), every channel, 17 significant digits. ``tests/test_golden.py`` flies the same cases
and compares them channel by channel, as JSBSim's own check cases do, so that a change which
moves every channel together is seen.

Re-record only after a deliberate change of the physics, and say so in the commit:

    python tests/golden_cases.py           # compare with the stored files, print the worst
    python tests/golden_cases.py --write   # re-record
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
GOLDEN_DIR = REPO / "tests" / "golden"
CASES = ("fig21_rigid", "fig21_coupled", "fig21_qsd", "fig21_native")
DECIMATE = 8  # store every 8th step: 120 samples per simulated second
# Tolerance of the comparison, as a fraction of each channel's range over the run: the runs
# are deterministic, so what is left is floating-point reordering (a different BLAS or LAPACK
# build changes the last digits of the eigen-solutions: 1.9e-12 was seen between machines);
# 1e-7 leaves five decades for that and still sees any change of the physics or the step.
RTOL_OF_RANGE = 1e-7


def fly_case(case: str):
    """Fly one golden case; a TimeHistory (every step)."""
    from bioflex_jsb.api import fly_fig21

    return fly_fig21(case.removeprefix("fig21_"))


def write_csv(path: Path, run) -> None:
    names = list(run.channels)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["time_s", *names])
        w.writerow(["s", *(run.units.get(n, "") for n in names)])
        for k in range(0, len(run.time_s), DECIMATE):
            w.writerow([repr(float(run.time_s[k])), *(repr(float(run.channels[n][k]))
                                                      for n in names)])


def read_csv(path: Path) -> tuple[np.ndarray, dict[str, np.ndarray], dict[str, str]]:
    with path.open(newline="") as fh:
        rows = list(csv.reader(fh))
    names, units = rows[0], rows[1]
    data = np.array([[float(x) for x in r] for r in rows[2:]])
    channels = {n: data[:, i] for i, n in enumerate(names)}
    return channels.pop("time_s"), channels, dict(zip(names, units, strict=True))


def compare(stored, run) -> dict[str, float]:
    """Largest |run − stored| of every stored channel, as a fraction of the stored range."""
    time_s, channels, _ = stored
    got_t = np.asarray(run.time_s)[::DECIMATE]
    if len(got_t) != len(time_s) or np.max(np.abs(got_t - time_s)) > 1e-12:
        raise AssertionError(f"time axis differs: {len(got_t)} samples vs {len(time_s)} stored")
    out = {}
    for name, ref in channels.items():
        if name not in run.channels:
            raise AssertionError(f"channel {name} is missing from the run")
        got = np.asarray(run.channels[name])[::DECIMATE]
        span = float(np.max(ref) - np.min(ref))
        scale = span if span > 0.0 else max(1.0, float(np.max(np.abs(ref))))
        out[name] = float(np.max(np.abs(got - ref)) / scale)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Record or check the golden cases.")
    parser.add_argument("--write", action="store_true", help="re-record the stored files")
    args = parser.parse_args(argv)
    GOLDEN_DIR.mkdir(exist_ok=True)
    for case in CASES:
        run = fly_case(case)
        path = GOLDEN_DIR / f"{case}.csv"
        if args.write:
            write_csv(path, run)
            print(f"wrote {path.relative_to(REPO)} ({len(run.time_s)} steps)")
        else:
            worst = compare(read_csv(path), run)
            name, err = max(worst.items(), key=lambda kv: kv[1])
            print(f"{case:14s} worst channel {name:18s} {err:.3e} of its range")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(REPO))
    raise SystemExit(main())
