"""``bioflex-jsb bench``: the estimator's properties on synthetic timings (never negative,
robust to the noise of a shared machine, says when it cannot tell) and the JSON shape. No
timing bars here: figures of a shared machine are noise, benchmarks print them."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from bioflex_jsb.cli import main
from bioflex_jsb.drivers import bench
from bioflex_jsb.drivers.bench import (
    BARS,
    DEFAULT_REPEAT,
    DEFAULT_STEPS,
    GROUPS,
    LENGTH_FACTORS,
    MAX_DISAGREEMENT,
    MAX_RESIDUAL,
    Figure,
    PerStep,
    difference,
    estimate_figure,
    estimate_per_step,
    ratio,
)
from bioflex_jsb.drivers.bench_speedup import (
    ARDUPILOT_SIM_RATES_HZ,
    ARDUPILOT_SPEEDUPS,
    SITL_SPEEDUPS,
    held,
    max_held,
    rate_figures,
)

LENGTHS = (1200, 2400, 4800)


def synthetic(per_step_s, fixed_s, repeats, rng, spikes=0.0, jitter=0.0):
    """Timings [s] (repeats × LENGTHS) of a linear cost plus the noise of a loaded machine:
    multiplicative jitter (±``jitter``) and, with probability 0.3, a one-sided spike (a
    run slowed by up to ``spikes`` × its time: preemption)."""
    n = np.asarray(LENGTHS, dtype=float)
    t = fixed_s + per_step_s * n
    out = np.tile(t, (repeats, 1))
    out *= 1.0 + jitter * rng.uniform(-1.0, 1.0, out.shape)
    hit = rng.uniform(size=out.shape) < 0.3
    out += hit * spikes * rng.uniform(size=out.shape) * out
    return out


def test_exact_timings_give_the_slope_and_the_fixed_cost():
    times = synthetic(10e-6, 2e-3, 4, np.random.default_rng(0))
    est = estimate_per_step(LENGTHS, times)
    assert est.trusted
    assert est.slope_s == pytest.approx(10e-6, rel=1e-9)
    assert est.fixed_s == pytest.approx(2e-3, rel=1e-6)
    assert all(p == pytest.approx(10e-6, rel=1e-9) for p in est.per_repeat_s)


def test_one_sided_noise_is_absorbed_by_the_least_times():
    """Spikes up to 3x a run's time in 30 % of the runs (load 4-10 on 2 cores): the
    estimate stays within 5 % of the truth in the least repeat; the spread shows the rest."""
    rng = np.random.default_rng(1)
    trusted = 0
    for _ in range(200):
        est = estimate_per_step(LENGTHS, synthetic(12e-6, 1e-3, 5, rng, spikes=3.0,
                                                   jitter=0.005))
        if est.trusted:
            trusted += 1
            assert min(est.per_repeat_s) == pytest.approx(12e-6, rel=0.05)
        else:
            assert est.per_repeat_s is None and est.reason
    assert trusted >= 180  # measured: all 200 trusted, worst 0.9 % off


def test_the_noise_here_made_the_two_length_difference_negative():
    """The timings these tests feed are as bad as the machine's: the estimator bench used
    before, (T(2N) − T(N)) / N, went below zero on them (it printed ratio min −0.32)."""
    rng = np.random.default_rng(2)
    negative = 0
    for _ in range(200):
        times = synthetic(1e-6, 0.05, 5, rng, spikes=3.0)
        negative += int(np.any(times[:, 1] - times[:, 0] < 0.0))
        est = estimate_per_step(LENGTHS, times)
        assert est.per_repeat_s is None or min(est.per_repeat_s) > 0.0
    assert negative > 50


@pytest.mark.parametrize("seed", range(20))
def test_never_negative_whatever_the_timings(seed):
    """Timings with no relation to the steps at all (pure noise, decreasing with N, a long
    run faster than the fixed cost): never a negative figure, and said when not trusted."""
    rng = np.random.default_rng(seed)
    cases = [rng.uniform(0.0, 1.0, (5, 3)),  # noise
             np.tile([0.05, 0.03, 0.01], (3, 1)),  # decreasing
             np.tile([0.02, 0.02, 0.02], (2, 1)),  # constant
             synthetic(-5e-6, 0.1, 4, rng),  # a negative slope, as two lengths gave
             synthetic(1e-6, 0.05, 3, rng, spikes=20.0)]
    for times in cases:
        est = estimate_per_step(LENGTHS, times)
        if est.trusted:
            assert all(p > 0.0 for p in est.per_repeat_s)
            assert est.fixed_s >= 0.0
        else:
            assert est.per_repeat_s is None and est.reason
        d = est.as_dict()
        for key in ("median", "min", "max"):
            assert d[key] is None or d[key] > 0.0


def test_a_line_crossing_below_zero_is_fitted_through_the_origin():
    """Long runs slowed more than short ones (a loaded machine: a long run is more often
    interrupted, and comes back to cold caches): the least-squares line would give a
    negative fixed cost; the fixed cost is held at zero instead, the per-step cost is then
    an upper bound, and a residual within the bound keeps it trusted."""
    n = np.asarray(LENGTHS, dtype=float)
    times = np.tile(10e-6 * n * (1.0 + 0.05 * n / n[-1]), (3, 1))
    assert np.polyfit(n, times[0], 1)[1] < 0.0  # the unconstrained line's fixed cost
    est = estimate_per_step(LENGTHS, times)
    assert est.trusted and est.fixed_s == 0.0
    assert all(p == pytest.approx(10.5e-6, rel=1e-9) for p in est.per_repeat_s)


def test_a_decreasing_time_is_not_trusted():
    est = estimate_per_step(LENGTHS, np.tile([0.05, 0.03, 0.01], (3, 1)))
    assert not est.trusted and "does not grow" in est.reason
    assert est.as_dict()["median"] is None


def test_nonlinear_timings_are_not_trusted():
    times = np.tile([0.010, 0.011, 0.050], (3, 1))  # the residual is far above the bound
    est = estimate_per_step(LENGTHS, times)
    assert not est.trusted and "not linear" in est.reason
    assert MAX_RESIDUAL < 0.5 and MAX_DISAGREEMENT < 0.5


def _figure(all_slope, group_slopes, reason=None):
    def est(slope):
        return PerStep((slope,), slope, 0.0, 0.0, reason)
    return Figure(est(all_slope), tuple(est(g) for g in group_slopes))


def test_ratio_is_of_the_slopes_group_by_group_and_refuses_untrusted_figures():
    a = _figure(2.4e-5, (2.2e-5, 2.6e-5, 2.5e-5))
    b = _figure(1e-5, (1e-5, 1e-5, 1e-5))
    r = ratio(a, b)
    assert r["value"] == pytest.approx(2.4)
    assert (r["min"], r["median"], r["max"]) == pytest.approx((2.2, 2.5, 2.6))
    fail = PerStep(None, -1e-6, 0.0, 0.0, "does not grow")
    one_bad = Figure(b.all, (b.groups[0], fail, b.groups[2]))
    r = ratio(a, one_bad)  # two groups of three trusted in both: the spread is theirs
    assert r["trusted"] and r["value"] == pytest.approx(2.4)
    assert (r["min"], r["max"]) == pytest.approx((2.2, 2.5))
    assert one_bad.as_dict()["groups_trusted"] == 2
    other_bad = Figure(a.all, (fail, a.groups[1], a.groups[2]))
    r = ratio(other_bad, one_bad)  # only group 3 is trusted in both
    assert r["value"] is None and r["median"] is None and not r["trusted"]
    assert r["reason"].startswith("1 of 3 groups trusted, fewer than 2 (group 1: ")
    two_bad = Figure(b.all, (fail, fail, b.groups[2]))
    assert "1 of 3 groups trusted" in two_bad.reason and two_bad.as_dict()["value"] is None
    assert ratio(a, two_bad)["reason"] == two_bad.reason


def test_a_figure_or_ratio_that_its_estimates_do_not_reproduce_is_refused():
    """Without a third of the repeats the estimate may move by 20 % (MAX_SPREAD), no more;
    and no ratio of bench is below 1 (the co-simulation is JSBSim's step and more)."""
    wide = _figure(10e-6, (10e-6, 12.5e-6, 10.5e-6))
    assert "not reproducible" in wide.reason and wide.as_dict()["value"] is None
    assert _figure(10e-6, (10e-6, 11.9e-6, 10.5e-6)).reason is None
    fast = _figure(8e-6, (8e-6, 8.2e-6, 8.1e-6))
    slow = _figure(9e-6, (9e-6, 9.5e-6, 9.2e-6))
    r = ratio(fast, slow)
    assert r["value"] is None and "below 1" in r["reason"]
    assert ratio(fast, slow, floor=None)["value"] == pytest.approx(8 / 9)
    swing = ratio(_figure(14e-6, (14e-6, 16e-6, 14.5e-6)), _figure(10e-6, (10e-6, 8.5e-6,
                                                                             10.2e-6)))
    assert swing["value"] is None and "not reproducible" in swing["reason"]  # 16/8.5: +34 %


def test_a_difference_within_the_groups_spread_is_not_resolved_never_negative():
    """The cost of a piece (the scene, the loads) is the difference of two figures: one
    that a group does not see above zero gets no figure, only the reason."""
    with_it = _figure(12e-6, (12e-6, 12.5e-6, 11.8e-6))
    without = _figure(10e-6, (10e-6, 10.2e-6, 10.1e-6))
    d = difference(with_it, without)
    assert d["trusted"] and d["value"] == pytest.approx(2.0)
    assert (d["min"], d["median"], d["max"]) == pytest.approx((1.7, 2.0, 2.3))
    close = _figure(10.1e-6, (10.3e-6, 9.9e-6, 10.2e-6))
    d = difference(close, without)
    assert not d["trusted"] and d["value"] is None and "not resolved" in d["reason"]
    d = difference(without, with_it)  # a negative cost: never a figure
    assert not d["trusted"] and d["value"] is None


def _run_time(work_s, rng, state_s=0.03, slow=1.4):
    """CPU time of ``work_s`` seconds of the fast machine's work on a machine whose speed
    switches between 1 and 1/``slow`` in states of exponential length (mean ``state_s``),
    each run starting in either state: the 2-core KVM guest of the project measured
    (drivers/bench.py: a fixed workload 1.0-1.65 ms, states of ~10-50 ms)."""
    t, left, fast = 0.0, work_s, rng.uniform() < 0.5
    while True:
        dur = rng.exponential(state_s)
        rate = 1.0 if fast else 1.0 / slow
        if left <= dur * rate:
            return t + left / rate
        left, t, fast = left - dur * rate, t + dur, not fast


def _speed_state_timings(lengths, repeats, rng, per_step_s=7e-6, fixed_s=1e-3):
    return np.array([[_run_time(fixed_s + per_step_s * n, rng) for n in lengths]
                     for _ in range(repeats)])


def test_short_runs_find_the_fast_state_that_long_runs_mix():
    """Why the runs are short and many. On the machine of speed states, the earlier
    defaults (runs of 1200-4800 steps, 8-34 ms at 7 µs/step, 5 repeats; on the real
    machine, quiet, a residual of 11 %) mix the states in their long runs and come out
    biased high; the defaults now (300-1200 steps, 12 repeats) give the fast state's cost.
    Measured over these 200 seeds: old 20 untrusted, bias 16 % at the 95th percentile
    (worst 25 %); new 6 untrusted (estimates 20 % apart), bias 0 at the 95th percentile
    and worst (every least time a fast run): the bounds below leave margin on both sides."""
    old = [1200 * f for f in LENGTH_FACTORS]
    new = [DEFAULT_STEPS * f for f in LENGTH_FACTORS]
    untrusted = {"old": 0, "new": 0}
    bias = {"old": [], "new": []}
    for seed in range(200):
        for name, lengths, repeats in (("old", old, 5), ("new", new, DEFAULT_REPEAT)):
            rng = np.random.default_rng([seed, len(name), lengths[0]])
            f = estimate_figure(lengths, _speed_state_timings(lengths, repeats, rng))
            if f.reason is not None:
                untrusted[name] += 1
                assert f.as_dict()["value"] is None
            else:
                bias[name].append(abs(f.all.slope_s / 7e-6 - 1.0))
    p95 = {k: float(np.percentile(v, 95)) for k, v in bias.items()}
    assert p95["old"] > 0.08, (untrusted, p95)
    assert untrusted["new"] <= 15 and p95["new"] < 0.03, (untrusted, p95)


def test_each_figures_spread_is_the_estimate_without_each_interleaved_group():
    """Estimate g leaves out group g (repeats g, g + GROUPS, ...: each spans the whole
    measurement). Only group 1 ran on the fast machine here: the figure has it, the
    estimate without it shows how much the figure hangs on those repeats."""
    rng = np.random.default_rng(3)
    times = synthetic(10e-6, 1e-3, 12, rng, jitter=0.002)
    fast = np.arange(12) % GROUPS == 0
    times[~fast] *= 1.15
    f = estimate_figure(LENGTHS, times)
    assert len(f.groups) == GROUPS and f.reason is None
    assert f.all.slope_s == pytest.approx(10e-6, rel=0.02)
    slopes = f.slopes()
    assert slopes[0] == pytest.approx(11.5e-6, rel=0.02)  # without the fast group
    assert slopes[1] == pytest.approx(10e-6, rel=0.02) and slopes[2] == pytest.approx(
        10e-6, rel=0.02)
    d = f.as_dict()
    assert d["value"] == pytest.approx(10.0, rel=0.02)
    assert (d["median"], d["max"]) == pytest.approx((10.0, 11.5), rel=0.02)
    assert d["groups"] == GROUPS
    assert len(estimate_figure(LENGTHS, times[:2]).groups) == 2  # fewer repeats than groups
    one = estimate_figure(LENGTHS, times[:1])  # one repeat: its own estimate, once
    assert one.slopes() == (one.all.slope_s,)


def test_the_cli_defaults_and_the_scene_are_the_drivers_and_the_gust_commands():
    from bioflex_jsb.cli import bench as cli_bench
    from bioflex_jsb.cli import gust as cli_gust

    assert (cli_bench.DEFAULT_STEPS, cli_bench.DEFAULT_REPEAT) == (DEFAULT_STEPS,
                                                                  DEFAULT_REPEAT)
    assert bench.GUST_SCENE_EXAGGERATION == cli_gust.SCENE_EXAGGERATION


def test_bad_timings_are_a_bug_not_a_figure():
    with pytest.raises(ValueError):
        estimate_per_step((100, 100), np.ones((2, 2)))
    with pytest.raises(ValueError):
        estimate_per_step(LENGTHS, np.full((2, 3), np.nan))


@pytest.mark.slow  # real runs of every configuration and two child processes
def test_bench_json_has_every_figure(capsys):
    assert main(["bench", "--steps", "100", "--repeat", "2", "--sitl-seconds", "0.5",
                 "--ardupilot-frames", "300", "--ardupilot-repeat", "1",
                 "--sitl-speedups-seconds", "0.2", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert (BARS["logged_ratio"], BARS["logged_rows_ratio"]) == (2.0, 1.8)  # decided
    for key in ("ratio", "logged_ratio", "logged_rows_ratio", "log_ratio", "unsteady_ratio",
                "native_ratio", "python_ratio", "full_span_ratio",
                *(f"cost {k}" for k in bench.LOG_COSTS)):
        d = data[key] if key in data else data["log_costs_us_per_step"][key[5:]]
        # shape, not values: 100-step timings on a shared machine may not be trusted
        if d["trusted"]:
            assert 0.0 < d["min"] <= d["median"] <= d["max"] and d["value"] > 0.0, key
        else:
            assert d["value"] is None and d["median"] is None and d["reason"], key
        if key in BARS:
            assert d["bar"] == BARS[key]
            assert d["meets_bar"] in (None, True, False)
    for key in ("bare", "cosim", "logged", "logged_rows", "logged_no_scene", "unsteady",
                "native", "python", "full_span"):
        d = data["us_per_step"][key]
        assert (d["value"] is None) == (d["median"] is None) == (not d["trusted"]), key
        assert d["value"] is None or d["value"] > 0.0, key
        assert key in data["wall"]["us_per_step"]
    assert set(data["cosim_us_per_step_by_gust"]) == {"sharp:0.3", "sharp:3",
                                                      "dryden:1.5:100:7"}
    assert "controlled" in data["us_per_step"]
    assert "value" in data["controller_in_loop_us_per_step"]
    for key in ("sensors", "sensed_controlled"):  # measured in the same run
        assert key in data["us_per_step"] and key in data["wall"]["us_per_step"]
    for key in ("sensors_ratio", "controlled_ratio", "sensed_controlled_ratio"):
        d = data[key]
        assert d["value"] is None or d["value"] >= 1.0, key  # a floor of 1: never cheaper
    for key in ("sensor_stations_us_per_step", "sensor_controller_in_loop_us_per_step"):
        assert "value" in data[key]
    c = data["controller_us"]
    assert c["n_states"] == 10 and c["bar_us"] == 1.0 and c["meets_bar"] in (True, False)
    assert 0.0 < c["update"]["least"] <= c["in_step"]["median"]
    c = data["kernel_compile_s"]
    assert c["cold"] > 0.0 and c["cached"] > 0.0
    assert set(c["cold_by_kernel"]) == {"step_kernel", "unsteady_kernel"}
    assert data["refresh_ms"]["median"] > 0.0 and data["unsteady_refresh_ms"]["median"] > 0.0
    assert 0.0 <= data["sitl"]["p50_ms"] <= data["sitl"]["p99_ms"]
    assert data["steps"] == 100 and data["repeat"] == 2
    assert data["run_lengths"] == [100, 200, 400]
    assert data["run_lengths_by_configuration"] == {"unsteady": [400, 800, 1600],
                                                    "full_span": [6400, 12800, 25600]}
    assert len(data["load_average"]) == 3 and all(math.isfinite(x)
                                                  for x in data["load_average"])
    assert len(data["load_average_before"]) == 3
    a = data["ardupilot"]  # the backend against the stand-in: shape, not values
    assert a["available"] and a["logged"] and a["trusted"], a.get("reason")
    assert a["physics_rate_hz"] == 960.0
    assert a["sim_rates_hz"] == list(ARDUPILOT_SIM_RATES_HZ) == [1200, 240]
    for rate, k in (("1200", 1.0), ("240", 4.0)):  # the steps a frame the backend chose
        b = a["by_sim_rate"][rate]
        assert b["steps_per_frame"]["median"] == pytest.approx(k, rel=1e-9), rate
        assert b["answered_per_s"]["median"] > 0.0
        assert set(b["real_time_factor_by_speedup"]) == {f"{x:g}" for x in ARDUPILOT_SPEEDUPS}
        assert b["max_speedup_held"]["median"] in (0.0, *ARDUPILOT_SPEEDUPS)
    assert len(a["load_average"]) == 3
    s = data["sitl_speedup"]
    assert [r["speedup"] for r in s["runs"]] == list(SITL_SPEEDUPS)
    assert s["max_speedup_p99_within_bar"]["median"] in (0.0, *SITL_SPEEDUPS)


def test_max_speedup_held_is_the_top_of_an_unbroken_run_of_held_speedups():
    """Within 5 % of the speed-up asked for; a speed-up missed ends the count (a higher one
    held by chance does not count), repeat by repeat."""
    assert held(9.6, 10.0) and held(10.4, 10.0) and not held(9.4, 10.0)

    def runs(rtfs, repeat):
        return [{"speedup": s, "real_time_factor": r, "repeat": repeat, "grounded": 0}
                for s, r in zip((1.0, 2.0, 5.0, 10.0), rtfs, strict=True)]

    m = max_held(runs((1.0, 2.0, 4.0, 9.9), 0) + runs((1.0, 1.99, 4.9, 9.0), 1)
                 + runs((0.9, 2.0, 5.0, 10.0), 2))
    assert m["per_repeat"] == [2.0, 5.0, 0.0]
    assert m["max_speedup_held"] == {"median": 2.0, "min": 0.0, "max": 5.0}
    assert m["real_time_factor_by_speedup"]["10"] == {"median": 9.9, "min": 9.0, "max": 10.0}


def test_rate_figures_take_the_free_runs_and_the_steps_a_frame():
    """The free runs give the frames per second and the steps a frame (physics time over
    frames × dt: the backend's k), the paced ones the speed-ups held."""
    dt = 1 / 960
    rows = []
    for repeat in (0, 1):
        rows.append({"speedup": None, "frames": 100, "physics_s": 100 * 4 * dt,
                     "answered_per_s": 1000.0 + repeat, "frames_per_s": 900.0,
                     "real_time_factor": 4.0, "grounded": 0, "repeat": repeat})
        rows += [{"speedup": s, "frames": 100, "physics_s": 1.0, "answered_per_s": 0.0,
                  "frames_per_s": 0.0, "real_time_factor": r, "grounded": repeat, "repeat": repeat}
                 for s, r in ((1.0, 1.0), (2.0, 2.0), (5.0, 4.0))]
    f = rate_figures(rows, dt)
    assert f["steps_per_frame"]["median"] == pytest.approx(4.0, rel=1e-12)
    assert f["answered_per_s"] == {"median": 1000.5, "min": 1000.0, "max": 1001.0}
    assert f["per_repeat"] == [2.0, 2.0] and f["grounded_frames"] == 3


def test_bench_bad_input_is_one_line_and_exit_2(capsys):
    for argv, word in ((["bench", "--steps", "5"], "--steps"),
                       (["bench", "--speed", "1000"], "--speed"),
                       (["bench", "--steps", "1e8"], "--steps"),
                       (["bench", "--sitl-seconds", "-1"], "--sitl-seconds"),
                       (["bench", "--sitl-speedups-seconds", "99"], "--sitl-speedups-seconds"),
                       (["bench", "--ardupilot-frames", "-3"], "--ardupilot-frames"),
                       (["bench", "--ardupilot-sim-rates", "1200,20"], "--ardupilot-sim-rates"),
                       (["bench", "--ardupilot-sim-rates", "fast"], "--ardupilot-sim-rates"),
                       (["bench", "--only", "ardupilot", "--ardupilot-frames", "0"],
                        "--ardupilot-frames")):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert word in err and err.count("\n") == 1, (argv, err)


def test_the_bench_sensors_and_their_controller_fly_the_cosims_run():
    """The bench's stations (the CG IMU and a tip accelerometer on the elastic axis) and the
    10-state controller reading the tip's a_z: a run through the bench's gust stays in range
    and the tip reads the wing (its a_z less the CG's moves: 0.40 m/s² measured through
    sharp:0.3, the modes rung by the gust)."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust

    build = build_wing(VARIANTS["optimised"])
    ctrl = bench.bench_controller(signals=bench.SENSOR_CONTROLLER_SIGNALS)
    assert ctrl.inputs == ("q", "alpha", "imu_tip_az_m_s2")
    run = run_gust(Airframe(), build.model, "coupled",
                   RunConfig(15.0, parse_gust("sharp:0.3"), 0.3, 0.05, models=("coupled",)),
                   sensors=bench.bench_sensors(build), controller=ctrl)
    assert run.stopped is None
    assert np.ptp(run["imu_tip_az_m_s2"] - run["imu_cg_az_m_s2"]) > 0.2
    assert np.abs(run["ctrl_elevator_rad"]).max() < math.radians(1.0)


def test_controller_cost_is_the_step_s_own_calls():
    """The controller's figure times what the compiled step calls (its update's machine
    code and the setter of JSBSim's elevator command) for a 10-state controller; the
    readable Python update beside it is tens of times slower (18 µs against 0.5 µs a step
    measured at load 9 on the 2-core machine)."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

    c = bench.controller_cost_us(build_wing(VARIANTS["optimised"]), calls=500, repeat=3)
    assert c["n_states"] == bench.CONTROLLER_STATES == 10
    assert c["signals"] == ["q", "alpha", "n_z"]
    assert 0.0 < c["update"]["least"] <= c["update"]["median"]
    assert c["python_reference"]["least"] > 5.0 * c["update"]["least"]
    assert c["meets_bar"] == (c["in_step"]["least"] <= c["bar_us"])
