"""The tuned discrete gust on the sweep executors (bioflex_jsb.sweep.tuned_loads): the same
critical-case table from 1 and 2 local workers and from a Dask LocalCluster, equal to the
sequential path, the rows in the cases' order whatever order they finish in, and the
command's one-line refusals."""

from __future__ import annotations

import json

import pytest

from bioflex_jsb.flight_dynamics.wing_model import build_wing, get_variant
from bioflex_jsb.loads.tuned import tuned_cases
from bioflex_jsb.sweep.tuned_loads import (
    fly_tuned_case,
    run_tuned,
    tuned_case_list,
    tuned_failed_row,
)

# Two gradients (a short one near the wing's first mode, a long one) up and down: 4 runs of
# 2 s, about 1 s each on one core.
GRADIENTS = "0.5,3"
STATIONS = (0.0, 0.5)


def _tuned(tmp_path, capsys, name, *extra):
    csv_path = tmp_path / f"{name}.csv"
    from bioflex_jsb.cli import main

    code = main(["loads", "--tuned", "--gradients", GRADIENTS, "--stations", "0,0.5", "--json",
                 "--csv", str(csv_path), *extra])
    out = capsys.readouterr()
    assert code == 0, out.err
    data = json.loads(out.out)
    assert data["csv"] == str(csv_path)
    data["csv"] = None  # the file's name differs between the runs, not its content
    return data, csv_path.read_bytes()


def test_one_and_two_workers_give_the_same_table(tmp_path, capsys):
    a, csv_a = _tuned(tmp_path, capsys, "w1", "--workers", "1")
    b, csv_b = _tuned(tmp_path, capsys, "w2", "--workers", "2")
    assert len(a["cases"]) == 4 and len(a["critical"]) == 2 * 3 * 2 * 2
    assert a == b  # every float to the last bit, the cases in the same order
    assert csv_a == csv_b


# The sequential path: tuned_gust flying the cases one after the other in one fresh
# process with one BLAS thread, as the workers have (sweep/local.py WORKER_ENV). With two
# BLAS threads the wing's modes (and so the loads) differ in the last bit (2e-16 relative
# measured), and a process's builds are cached, hence a process of its own.
SEQUENTIAL = """
import json
from bioflex_jsb.flight_dynamics.wing_model import get_variant
from bioflex_jsb.loads.tuned import tuned_cases, tuned_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.sweep.tuned_loads import fly_tuned_case, tuned_case_list
cases = tuned_case_list(tuned_cases(15.0, [0.5, 3.0]), get_variant("optimised"), "optimised",
                        "consistent", 15.0, DEFAULT_DT_S, "coupled", "rigid", (0.0, 0.5), None)
by_gust = {c.gust: c for c in cases}
def fly(gust, duration_s, gust_start_s):
    c = by_gust[gust]
    assert (c.duration_s, c.gust_start_s) == (duration_s, gust_start_s)
    return fly_tuned_case(c)["loads"]
r = tuned_gust(fly, 15.0, [0.5, 3.0])
print(json.dumps({"cases": r.cases, "critical": r.critical}))
"""


def test_the_pool_equals_the_sequential_path(tmp_path, capsys):
    import os
    import subprocess
    import sys

    from bioflex_jsb.sweep.local import WORKER_ENV

    pooled, _ = _tuned(tmp_path, capsys, "pool", "--workers", "2")
    done = subprocess.run([sys.executable, "-c", SEQUENTIAL], capture_output=True, text=True,
                          env={**os.environ, **WORKER_ENV}, timeout=600, check=True)
    seq = json.loads(done.stdout)
    assert seq["critical"] == pooled["critical"]
    assert seq["cases"] == pooled["cases"]


@pytest.mark.slow
def test_dask_localcluster_gives_the_local_table(tmp_path, capsys):
    a, csv_a = _tuned(tmp_path, capsys, "local", "--workers", "2")
    b, csv_b = _tuned(tmp_path, capsys, "dask", "--scheduler", "local", "--workers", "2")
    assert a == b and csv_a == csv_b


class _Reversed:
    """An executor that finishes the cases last first (the rows must come back in order)."""

    def run(self, cases):
        cases = list(cases)
        for c in reversed(cases):
            yield c, tuned_failed_row(c, f"row of {c.gust}")


def test_rows_come_back_in_the_cases_order():
    build = build_wing(get_variant("optimised"))
    cases = tuned_case_list(tuned_cases(15.0, [0.5, 1.0, 3.0]), build.variant, "k",
                            "consistent", 15.0, 0.01, "coupled", "rigid", STATIONS, None)
    seen = []
    rows = run_tuned(cases, _Reversed(), lambda k, n, row: seen.append((k, n, row["gust"])))
    assert [r["gust"] for r in rows] == [c.gust for c in cases]
    assert [r["error"] for r in rows] == [f"row of {c.gust}" for c in cases]
    assert seen == [(k + 1, 6, c.gust) for k, c in enumerate(reversed(cases))]
    assert len({c.case_id for c in cases}) == 6  # every gust its own id (Dask's task key)


def test_a_case_of_its_own_failing_is_a_row_not_an_exception():
    build = build_wing(get_variant("optimised"))
    # a trim speed far below the stall: the trim fails (a row with the one-line reason)
    case = tuned_case_list(tuned_cases(15.0, [0.5]), build.variant, "optimised",
                           "consistent", 2.0, 0.01, "coupled", "rigid", STATIONS, None)[0]
    row = fly_tuned_case(case)
    assert row["status"] == "failed" and row["loads"] is None
    assert "\n" not in row["error"] and row["error"]


@pytest.mark.parametrize("argv, needle", [
    (["--workers", "2"], "--workers applies to --tuned"),
    (["--scheduler", "local"], "--scheduler applies to --tuned"),
    (["--tuned", "--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"],
     "--workers applies to local processes"),
    (["--tuned", "--workers", "0"], "--workers must be"),
    (["--tuned", "--scheduler", "nowhere"], "--scheduler must be"),
])
def test_executor_options_are_refused_in_one_line(argv, needle, capsys):
    from bioflex_jsb.cli import main

    assert main(["loads", *argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err
