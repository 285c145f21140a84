"""The compiled step kernel against the readable Python step it replaces (issue 14: the
golden cases agree to 1e-9 through both paths), and its stops."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb.drivers.gust import RunConfig, run_gust
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
    setup = RunConfig(15.0, parse_gust("sharp:3"), 3.0)
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
    setup = RunConfig(20.0, parse_gust("sharp:3"), 1.0)
    fast = run_gust(Airframe(), wing, "coupled", setup, compiled=True)
    slow = run_gust(Airframe(), wing, "coupled", setup, compiled=False)
    assert slow.stopped is not None and "aeroelastic" in slow.stopped
    assert fast.stopped == slow.stopped
    assert len(fast.time_s) == len(slow.time_s)


# -- the kernel called without numba's dispatcher (step_kernel.direct_entry) --------------
def _kernel_case(seed=0, n_modes=3):
    """A flow and a wing for one call of the kernel: random reference-step blocks (the
    coupled model, no refresh: refresh_rel huge), the prototype's constants, a level
    snapshot at ~15 m/s in JSBSim units (ft/s, rad, slug/ft³, ft)."""
    from bioflex_jsb.simulation import step_kernel as K

    rng = np.random.default_rng(seed)
    lay = K.layout(n_modes)
    params = np.zeros(sum(size for _, size in lay.values()))
    v = {name: params[o:o + size] for name, (o, size) in lay.items()}
    for block in ("stack", "input_cols", "load_eta", "load_etadot"):
        v[block][:] = rng.normal(0.0, 0.05, v[block].size)
    v["key"][:] = (137.8, 15.0)
    v["trim"][:] = (0.05, 0.05, 137.8, 15.0)
    v["consts"][:] = (0.3048, 515.379, 0.5, 0.2, 0.224809, 0.737562, 0.5, -0.3, 0.5, 0.25)
    v["refresh_rel"][0] = 1e9
    v["model"][0] = K.MODEL_CODES["coupled"]
    x = rng.normal(0.0, 0.01, 2 * n_modes)
    cols = np.arange(len(K.KERNEL_SLOTS) + 2 * n_modes, dtype=np.int64)[::-1].copy()
    reads = (49.0, 0.1, 2.5, 0.01, 0.002, -0.001, 0.05, 0.01, 0.3, 0.00237, 1.0, 300.0,
             300.0, 0.6, -2.1, 48.0, 1.0, -0.5, -0.02, 0.4)
    assert len(reads) == len(K.READ_KEYS)
    return K, params, x, cols, reads


def test_the_direct_entry_is_the_dispatchers_machine_code():
    """Same code, same arguments: the same bits in the row, the state and the outputs."""
    K, params, x, cols, reads = _kernel_case()
    entry, accepts = K.direct_entry(K.step_kernel, params, x, cols)
    table = np.full((3, len(cols)), np.nan)
    assert accepts(table)
    p2, x2, t2 = params.copy(), x.copy(), table.copy()
    for k in range(3):  # three steps: the state carried from call to call
        s1 = K.step_kernel(reads, params, x, cols, table, k, 0.4, -0.12)
        s2 = entry(reads, p2, x2, cols, t2, k, 0.4, -0.12)
        assert s1 == s2 == K.OK
    assert np.array_equal(table, t2) and np.array_equal(x, x2)
    assert np.array_equal(params, p2) and not np.isnan(table).any()


def test_the_direct_entry_takes_only_the_table_it_was_compiled_for():
    """It converts without checking: a Fortran-ordered table gets its row written in the
    wrong places (shown here), so ``accepts`` refuses every other table type (the caller
    then goes through the dispatcher, which types it and is right)."""
    K, params, x, cols, reads = _kernel_case(1)
    entry, accepts = K.direct_entry(K.step_kernel, params, x, cols)
    good = np.zeros((4, len(cols)))
    fortran = np.asfortranarray(np.zeros((4, len(cols))))
    K.step_kernel(reads, params.copy(), x.copy(), cols, good, 1, 0.0, 0.0)
    entry(reads, params.copy(), x.copy(), cols, fortran, 1, 0.0, 0.0)
    assert not np.array_equal(fortran, good)  # why the check exists
    read_only = np.zeros((4, len(cols)))
    read_only.flags.writeable = False
    for table in (fortran, good[:, ::2], good.astype(np.float32), good[0], read_only,
                  good.tolist()):
        assert not accepts(table)
    assert accepts(good) and accepts(np.zeros((1, 3)))
    with pytest.raises(TypeError, match="arrays"):
        K.direct_entry(K.step_kernel, params.astype(np.float32), x, cols)


def test_the_unsteady_kernel_has_a_direct_entry_of_the_same_arguments():
    from bioflex_jsb.simulation import step_kernel as K
    from bioflex_jsb.simulation import unsteady_kernel as UK

    params, views = UK.new_params(3, 2 * 3 + 4 * 40)
    views["consts"][:] = _kernel_case()[1][K.layout(3)["consts"][0]:][:K.N_CONSTS]
    views["key"][:] = np.nan  # a wing with no reference step yet
    x = np.zeros(2 * 3 + 4 * 40)
    cols = np.arange(len(K.KERNEL_SLOTS) + 6, dtype=np.int64)
    entry, accepts = K.direct_entry(UK.unsteady_kernel, params, x, cols)
    assert accepts(np.zeros((2, len(cols))))
    reads = _kernel_case()[4]
    p2 = params.copy()
    # no reference step yet: both ask for one, with the flow they found written out
    assert (UK.unsteady_kernel(reads, params, x, cols, np.zeros((1, len(cols))), 0, 0.4, 0.1)
            == entry(reads, p2, x.copy(), cols, np.zeros((1, len(cols))), 0, 0.4, 0.1)
            == K.NEEDS_REFRESH)
    assert np.array_equal(params, p2, equal_nan=True) and views["out_flow"][3] > 0.0  # V
