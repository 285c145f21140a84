"""Force summation of the unsteady wing (``aero="unsteady"``, loads/unsteady.py): the lag
and Küssner states recovered from the run's rows against a replay of the Python reference
wing, the quasi-steady limit of a long gust, the trim (1 g) row, the blocks, and the
methods a run reports."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.loads.model import build_loads_model
from bioflex_jsb.loads.stream import LoadStream
from bioflex_jsb.loads.unsteady import UnsteadyStripLoads
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import FlowState, TrimReference
from bioflex_jsb.simulation.unsteady_wing import UnsteadyModalWing

SPEED_M_S = 15.0


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("optimised")


def _fly(wing, gust: str, duration_s: float):
    return run_gust(Airframe(), wing, "coupled",
                    RunConfig(SPEED_M_S, parse_gust(gust), duration_s, 0.5,
                              models=("coupled",), aero="unsteady"),
                    loads=wing)


@pytest.fixture(scope="module")
def sharp_run(wing):
    return _fly(wing, "sharp:3", 1.2)


def _rows(run):
    names = list(run.channels)
    return names, np.column_stack([run[c] for c in names])


def _model(wing, run):
    return build_loads_model(wing, SPEED_M_S, density_kg_m3=run.meta["loads"]["density_kg_m3"])


def test_the_recovered_states_are_the_reference_wings(wing, sharp_run):
    """Replay the Python reference wing (UnsteadyModalWing, which the compiled kernel is
    held to) on the run's flows: its η is the logged one within 1e-4 rad (measured 1.3e-5
    against a peak of 0.1: the replay's Q takes the trim's density, the run's its altitude's),
    and the increments' loads of the recovered states (each lag state integrated on its own
    with η, η̇ linear between rows) are the replay's within 3e-3 of their peak (measured
    6e-4 to 9.6e-4 over the 12 loads: the wing integrates η with the lags), η̈ within 5e-2
    of its peak (measured 1.4e-2 to 2.5e-2: the stiffness ω² ≈ 4e4 s⁻² of the third mode
    on the η difference above)."""
    names, rows = _rows(sharp_run)
    lm = _model(wing, sharp_run)
    fast, eta_ddot = UnsteadyStripLoads(lm, names, sharp_run.meta["dt_s"]).block(rows)
    cl = level_flight_condition(SPEED_M_S, airframe=wing.airframe).cl_trim
    alpha0 = float(sharp_run["alpha_rad"][0] - sharp_run["alpha"][0])
    ref = UnsteadyModalWing.from_build(wing, TrimReference(alpha0, lm.dynamic_pressure_pa, cl),
                                       dt_s=sharp_run.meta["dt_s"], aero=wing.airframe.aero)
    states, inputs = [], []
    rho = lm.density_kg_m3
    for k in range(len(rows)):
        v = float(sharp_run["airspeed_m_s"][k])
        states.append(ref.state)
        ref.step(FlowState(float(sharp_run["alpha_rad"][k]), float(sharp_run["q"][k]), v,
                           0.5 * rho * v * v), float(sharp_run["w_g"][k]))
        inputs.append(ref._f.copy())
    x, f = np.array(states), np.array(inputs)
    logged = np.column_stack([sharp_run[f"eta{i + 1}"] for i in range(3)])
    assert np.max(np.abs(x[:, :3] - logged)) < 1e-4
    # the replay's rows through the same station rows (the states swapped in)
    replay = UnsteadyStripLoads(lm, names, sharp_run.meta["dt_s"])
    v = sharp_run["airspeed_m_s"]
    n = 3
    want_ddot = sum((v**p)[:, None] * (x @ replay._a[p][n:2 * n].T + f @ replay._b[p][n:2 * n].T)
                    for p in range(3))
    full = np.zeros((len(x), 4 + x.shape[1]))
    full[:, 1], full[:, 2], full[:, 4:] = f[:, 3], f[:, 4], x
    rate = np.zeros_like(full)
    rate[:, 1], rate[:, 2], rate[:, 4 + n:4 + 2 * n] = f[:, 5], f[:, 6], want_ddot
    rw = replay._rows
    want = sum((v**p)[:, None] * (full @ rw["x"][p].T + rate @ rw["xd"][p].T
                                  + np.outer(f[:, 7], rw["w"][p])) for p in range(3))
    peak = np.max(np.abs(want), axis=0)
    assert np.all(np.max(np.abs(fast - want), axis=0) < 3e-3 * peak)
    peak_ddot = np.max(np.abs(want_ddot), axis=0)
    assert np.all(np.max(np.abs(eta_ddot - want_ddot), axis=0) < 5e-2 * peak_ddot)


def _qs_part(lm, run):
    """The quasi-steady force summation of the same rows (the unsteady increments out):
    the stream of a quasi-steady coupled run on them."""
    names, rows = _rows(run)
    static = run.meta.get("static_eta_rad")
    stream = LoadStream(lm, names, run.meta["dt_s"], "coupled", static)
    parts = [stream.add(run.time_s, rows)[2], stream.finish()[2]]
    return np.vstack(parts)[:, :12]


def _departure(wing, gust: str, duration_s: float) -> np.ndarray:
    """max |unsteady FS − quasi-steady FS of the same rows| over the largest |increment
    over 1 g|, root shear, bending, torque."""
    run = _fly(wing, gust, duration_s)
    lm = _model(wing, run)
    qs = _qs_part(lm, run)
    total = np.column_stack([run[c] for c in run.meta["loads"]["names"][:12]])
    static = lm.static_loads()["force_summation"].reshape(-1)
    return np.array([np.max(np.abs(total[:, j] - qs[:, j]))
                     / np.max(np.abs(total[:, j] - static[j])) for j in (0, 4, 8)])


def test_a_long_gust_tends_to_the_quasi_steady_loads(wing):
    """k → 0: the unsteady force summation of a run against the quasi-steady force
    summation of the same rows (the increments and the unsteady η̈ out), relative to the
    root load increments, 1-cos gusts of 1 m/s at 15 m/s. Measured (shear, bending,
    torque): 10 m (k = ω b/V ≈ 0.06) 35, 38, 8.7 %; 60 m 6.8, 15, 1.5 %; 120 m (8 s, k ≈
    0.005) 3.5, 6.7, 0.8 %: about ∝ 1/L (1 m: 109, 134, 22 %). Checked: at 120 m every
    one under 10 %, and at most a quarter of its 10 m value (measured 0.10, 0.17, 0.09;
    1/L would be 0.083)."""
    short = _departure(wing, "1cos:1:10", 2.5)
    long = _departure(wing, "1cos:1:120", 9.5)
    assert np.all(long < 0.10), long
    assert np.all(long < 0.25 * short), (long, short)


def test_the_trim_row_is_the_quasi_steady_one(wing, sharp_run):
    """At the trim (the run's first row: no perturbation, every lag state zero) the
    increments vanish: the unsteady force summation is the quasi-steady one of that row
    (1 g), to rounding."""
    lm = _model(wing, sharp_run)
    names, rows = _rows(sharp_run)
    extra, _ = UnsteadyStripLoads(lm, names, sharp_run.meta["dt_s"]).block(rows[:1])
    # the trim's α and ΔQ are zero to rounding (1e-17 rad): so are the increments
    static = lm.static_loads()["force_summation"].reshape(-1)
    assert np.all(np.abs(extra) < 1e-12 * np.max(np.abs(static)))
    qs = _qs_part(lm, sharp_run)
    total = np.array([sharp_run[c][0] for c in sharp_run.meta["loads"]["names"][:12]])
    np.testing.assert_allclose(total, qs[0], rtol=1e-12, atol=1e-12 * np.max(np.abs(total)))


@pytest.mark.parametrize("block", [1, 97, 500])
def test_the_blocks_do_not_change_the_loads(wing, sharp_run, block):
    """The stream's loads of the unsteady run are the run's own (its blocks: the log's
    chunks) whatever the blocks, to rounding (the lag states carry from block to block)."""
    names, rows = _rows(sharp_run)
    lm = _model(wing, sharp_run)
    stream = LoadStream(lm, names, sharp_run.meta["dt_s"], "coupled", None, "unsteady")
    got = []
    for i in range(0, len(rows), block):
        got.append(stream.add(sharp_run.time_s[i:i + block], rows[i:i + block])[2])
    got.append(stream.finish()[2])
    got = np.vstack(got)
    want = np.column_stack([sharp_run[c] for c in sharp_run.meta["loads"]["names"]])
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * np.max(np.abs(want)))
    assert sharp_run.meta["loads"]["methods"] == ["force_summation", "mode_displacement"]


def test_the_methods_converge_as_modes_are_added():
    """A 1-cos gust (3 m/s, 5 m) on unsteady wings of 1, 2, 3 and 5 modes: the largest
    |FS − MD| of the root torque increment over 1 g, relative to the FS's peak increment,
    falls with every mode added (measured 72, 48, 26, 16 %; the quasi-steady wing's 73, 50,
    27, 16 %: the same convergence, docs/loads.md)."""
    from bioflex_jsb.flight_dynamics.wing_model import build_wing, get_variant

    variant = get_variant("optimised")
    diff = []
    for n in (1, 2, 3, 5):
        build = build_wing(variant, n_modes=n)
        run = _fly(build, "1cos:3:5", 1.5)
        st = run.meta["loads"]["static_1g"]
        fs = run["loads_fs_torque_n_m_s0"] - st["loads_fs_torque_n_m_s0"]
        md = run["loads_md_torque_n_m_s0"] - st["loads_md_torque_n_m_s0"]
        diff.append(float(np.max(np.abs(fs - md)) / np.max(np.abs(fs))))
    assert diff[0] > diff[1] > diff[2] > diff[3], diff
    assert diff[2] < 0.35 and diff[3] < 0.25, diff
