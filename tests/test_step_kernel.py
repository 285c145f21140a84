"""The compiled step kernel against the readable Python step it replaces (issue 14: the
golden cases agree to 1e-9 through both paths), and its stops."""

from __future__ import annotations

import pytest

from bioflex_jsb.drivers.gust import RunSetup, run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from tests.golden_cases import GOLDEN_DIR, compare, read_csv

# the kernel does the Python step's arithmetic in the same order but with fused loops
# instead of BLAS calls: the last digits of a sum may differ, nothing more
KERNEL_RTOL_OF_RANGE = 1e-9


@pytest.mark.parametrize("model", ["rigid", "coupled", "qsd"])
def test_kernel_and_python_step_agree_on_the_golden_case(model):
    wing = build_wing(VARIANTS["optimised"]).model
    setup = RunSetup(15.0, parse_gust("sharp:3"), 3.0)
    fast = run_gust(Airframe(), wing, model, setup, compiled=True)
    slow = run_gust(Airframe(), wing, model, setup, compiled=False)
    assert fast.stopped is None and slow.stopped is None
    worst = {name: float(abs(fast[name] - slow[name]).max()
                         / max(float(slow[name].max() - slow[name].min()), 1e-300))
             for name in slow.channels if float(slow[name].max() - slow[name].min()) > 0}
    assert max(worst.values()) < KERNEL_RTOL_OF_RANGE, worst
    # and both are the stored golden history
    stored = read_csv(GOLDEN_DIR / f"fig21_{model}.csv")
    assert max(compare(stored, slow).values()) < 1e-7


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
