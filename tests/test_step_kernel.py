"""The compiled step kernel against the readable Python step it replaces (issue 14: the
golden cases agree to 1e-9 through both paths), and its stops."""

from __future__ import annotations

import pytest

from bioflex_jsb.drivers.gust import RunSetup, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from tests.golden_cases import (
    HISTORY_RTOL_OF_RANGE,
    compare,
    compare_runs,
    over,
    stored,
    stored_wing,
)

# The kernel does the Python step's arithmetic in the same order but in its own loops
# instead of BLAS calls: the last digits of a sum may differ, nothing more. Measured
# (scripts/platform_spread.py, docs/validation.md): at most 1.8e-14 of a channel's range on
# every configuration (numba for the host or a generic x86-64 CPU, NUMBA_OPT=0, OpenBLAS
# SkylakeX/Haswell/Zen/SandyBridge kernels, 1 or 2 threads, libm without FMA): numba
# compiles without fast-math, so LLVM neither fuses a*b+c into an FMA nor reorders a sum,
# on any target. The 6.6e-6 issue 22 reported here was this test's golden comparison of the
# freshly built wing, not the kernel (the wing is now the stored one). 1e-9 leaves five
# decades for a BLAS that sums a 6x6 product in another order.
KERNEL_RTOL_OF_RANGE = 1e-9


@pytest.mark.parametrize("model", ["rigid", "coupled", "qsd"])
def test_kernel_and_python_step_agree_on_the_golden_case(model):
    wing = stored_wing()  # the golden cases' wing: the comparison below is then the flight's
    setup = RunSetup(15.0, parse_gust("sharp:3"), 3.0)
    fast = run_gust(Airframe(), wing, model, setup, compiled=True)
    slow = run_gust(Airframe(), wing, model, setup, compiled=False)
    assert fast.stopped is None and slow.stopped is None
    worst = compare_runs(slow, fast)
    assert max(worst.values()) < KERNEL_RTOL_OF_RANGE, worst
    # and both are the stored golden history (tests/golden_cases.py: its tolerance, its reason)
    for run in (fast, slow):
        bad = over(compare(stored(f"fig21_{model}"), run), HISTORY_RTOL_OF_RANGE)
        assert not bad, bad


def test_kernel_stops_where_the_python_step_stops_with_the_same_message():
    """The backward-axis wing diverges at 20 m/s (issue 18): same step, same message. (Each
    run on a fresh airframe: a trim on a used one starts from another propeller history.)"""
    wing = build_wing(VARIANTS["elastic-backward"]).model
    setup = RunSetup(20.0, parse_gust("sharp:3"), 1.0)
    fast = run_gust(Airframe(), wing, "coupled", setup, compiled=True)
    slow = run_gust(Airframe(), wing, "coupled", setup, compiled=False)
    assert slow.stopped is not None and "aeroelastic" in slow.stopped
    assert fast.stopped == slow.stopped
    assert len(fast.time_s) == len(slow.time_s)
