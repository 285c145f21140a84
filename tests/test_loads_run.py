"""Section loads in every gust run (drivers/gust.py ``loads=``, loads/stream.py): the loads
computed block by block equal the post-process of the whole run, an envelope keeps their
peaks, the metrics, the methods per model, the log's ``/bioflex/<model>/loads`` topic
(decoded by Google's protobuf runtime), ``compare`` on the loads, the gust summary."""

from __future__ import annotations

import json
import math
import subprocess

import numpy as np
import pytest

from bioflex_jsb import api, cli
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.loads import loads_metrics, section_loads
from bioflex_jsb.loads.model import QUANTITIES, build_loads_model
from bioflex_jsb.loads.stream import LoadStream, channel_names
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.results import TimeHistory, gust_metrics, section_load_metrics
from tests.tools import channel_metadata, decode_topic, env_program

# Rounding only: the stream and the post-process do the same products on the same numbers,
# in other groupings (a block's rows at a time, numpy.gradient's non-uniform formula for
# q_dot); measured worst 8e-16 of each channel's peak, so 1e-12 leaves a margin of 1e3.
ROUNDING = 1e-12
TAGS = {"force_summation": "fs", "mode_displacement": "md"}


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("optimised")


def _fly(wing, model="coupled", gust="sharp:3", duration_s=1.5, aero="quasi-steady", **kw):
    setup = RunConfig(15.0, parse_gust(gust), duration_s, 0.5, models=(model,), aero=aero)
    flown_by = wing if aero == "unsteady" else wing.model
    return run_gust(Airframe(), flown_by, model, setup, loads=wing, **kw)


def _without_loads(run: TimeHistory) -> TimeHistory:
    return TimeHistory(run.model, run.time_s,
                       {k: v for k, v in run.channels.items() if not k.startswith("loads_")},
                       dict(run.units), {k: v for k, v in run.meta.items() if k != "loads"},
                       run.stopped)


@pytest.fixture(scope="module")
def coupled_run(wing):
    return _fly(wing)


@pytest.mark.parametrize("model, methods", [
    ("coupled", ("force_summation", "mode_displacement")),
    ("qsd", ("force_summation", "mode_displacement")),
    ("rigid", ("force_summation",)),
])
def test_run_loads_equal_the_post_process_of_the_whole_run(wing, coupled_run, model, methods):
    """Every step's loads as the post-process of H10 (section_loads) gives them from the
    finished run (same stations, density, static part), for each model; the rigid wing has
    no modes and reports force summation only (with the undeformed wing's 1 g part)."""
    run = coupled_run if model == "coupled" else _fly(wing, model)
    layout = run.meta["loads"]
    assert tuple(layout["methods"]) == methods
    assert tuple(layout["names"]) == channel_names(methods, 4)
    assert [c for c in run.channels if c.startswith("loads_")] == layout["names"]
    assert layout["station_fractions"] == [0.0, 0.25, 0.5, 0.75]
    post = section_loads(wing, _without_loads(run), density_kg_m3=layout["density_kg_m3"])
    assert post.methods == methods
    for method in methods:
        for qi, q in enumerate(QUANTITIES):
            for j in range(4):
                name = f"loads_{TAGS[method]}_{q}_s{j}"
                ref = post.values[method][:, qi, j]
                assert np.max(np.abs(run[name] - ref)) <= ROUNDING * np.max(np.abs(ref)), name
                assert layout["static_1g"][name] == pytest.approx(post.static[method][qi, j],
                                                                  rel=1e-14, abs=1e-14)
    assert run.units["loads_fs_bending_n_m_s0"] == "N*m" and run.units["loads_fs_shear_n_s1"] == "N"
    assert (model == "rigid") == ("loads_md_torque_n_m_s0" not in run.channels)


@pytest.mark.parametrize("block", [1, 2, 7, 864, 10_000])
def test_the_blocks_do_not_change_the_loads(wing, coupled_run, block):
    """A row's loads wait for the next row (q_dot's central difference): any block size
    gives the same loads, the first and last rows by one-sided differences."""
    run = coupled_run
    names = tuple(c for c in run.channels if not c.startswith("loads_"))
    rows = np.column_stack([run[c] for c in names])
    lm = build_loads_model(wing, 15.0, density_kg_m3=run.meta["loads"]["density_kg_m3"])
    stream = LoadStream(lm, names, run.meta["dt_s"], "coupled")
    got_t, got = [], []
    for a in range(0, len(rows), block):
        t, _, values = stream.add(run.time_s[a:a + block], rows[a:a + block])
        got_t.append(t)
        got.append(values)
    t, _, values = stream.finish()
    got_t.append(t)
    got.append(values)
    np.testing.assert_array_equal(np.concatenate(got_t), run.time_s)
    loads = np.concatenate(got)
    for c, name in enumerate(stream.names):
        ref = run[name]
        assert np.max(np.abs(loads[:, c] - ref)) <= ROUNDING * np.max(np.abs(ref)), name
    with pytest.raises(RuntimeError, match="no row held"):
        stream.finish()


@pytest.mark.parametrize("model, aero", [("coupled", "quasi-steady"), ("qsd", "quasi-steady"),
                                         ("rigid", "quasi-steady"), ("coupled", "unsteady")])
def test_the_compiled_loads_are_the_numpy_ones(wing, coupled_run, model, aero):
    """A block's loads by the compiled pass (LoadStream._loads) are the readable numpy's
    (_loads_numpy) to the last bit: the same element-wise operations in the same order and
    the same matrix products (numpy's), on every row of a run and on NaN rows."""
    run = coupled_run if (model, aero) == ("coupled", "quasi-steady") else _fly(
        wing, model, duration_s=0.6, aero=aero)
    names = tuple(c for c in run.channels if not c.startswith("loads_"))
    rows = np.column_stack([run[c] for c in names])
    rows[5] = np.nan  # a diverged row stays NaN in both
    lm = build_loads_model(wing, 15.0, density_kg_m3=run.meta["loads"]["density_kg_m3"])
    # a stream each: the unsteady wing's strip states are replayed from the rows
    stream, again = (LoadStream(lm, names, run.meta["dt_s"], model, aero=aero)
                     for _ in range(2))
    q_dot = np.gradient(run["q"], run.time_s)
    got = stream._loads(rows, q_dot)
    assert got.shape == (len(rows), stream.n_channels)
    np.testing.assert_array_equal(got, again._loads_numpy(rows, q_dot))
    assert np.isnan(got[5]).all()
    # the quasi-steady loads are a row's own; the unsteady strips' lag carries the NaN on
    assert np.isfinite(got[6:]).all() == (aero == "quasi-steady")


def test_a_stop_signal_in_the_compiled_pass_is_a_keyboard_interrupt(wing, coupled_run):
    """A stop signal (the CLI raises KeyboardInterrupt from it) landing while a block's loads
    are computed ends as KeyboardInterrupt, never as numba's ``SystemError: … returned a
    result with an exception set`` (which a kernel returning a tuple gave for 9 in 10 such
    signals, measured; tests/test_signal_faults.py met it once in a run)."""
    import random
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signal handlers are the main thread's")
    names = tuple(c for c in coupled_run.channels if not c.startswith("loads_"))
    rows = np.column_stack([coupled_run[c] for c in names])[:864]
    lm = build_loads_model(wing, 15.0)
    stream = LoadStream(lm, names, coupled_run.meta["dt_s"], "coupled")
    q_dot = np.zeros(len(rows))
    stream._loads(rows, q_dot)

    def stop(signum, frame):
        raise KeyboardInterrupt

    rng = random.Random(5)
    old = signal.signal(signal.SIGALRM, stop)
    got = []
    try:
        for _ in range(100):
            try:
                signal.setitimer(signal.ITIMER_REAL, rng.uniform(1e-5, 3e-4))
                while True:
                    stream._loads(rows, q_dot)
            except BaseException as exc:  # noqa: BLE001 - which one is the test
                got.append(type(exc).__name__)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0.0)
    finally:
        signal.signal(signal.SIGALRM, old)
    assert got == ["KeyboardInterrupt"] * 100


def test_an_envelope_keeps_every_load_peak(wing):
    """keep="envelope" (a long run's bounded history) gives the metrics of every step: each
    load's extremes and each FS − MD difference's are among the rows it keeps."""
    full = _fly(wing, keep="all", duration_s=3.0)
    env = _fly(wing, keep="envelope", duration_s=3.0)
    assert env.meta["history"] == "envelope" and len(env.time_s) < 0.1 * len(full.time_s)
    a, b = gust_metrics(full, 0.5).loads, gust_metrics(env, 0.5).loads
    assert a["methods"] and a == b
    assert a["max_abs_difference"] == b["max_abs_difference"]


def test_the_metrics_report_peaks_times_and_increments(wing, coupled_run):
    """GustMetrics.loads is H10's loads_metrics of the same run (to rounding): the root
    bending peak of the paper's 3 m/s sharp gust is 10.42 N·m at the gust's first step
    (docs/loads.md), 7.43 N·m over 1 g."""
    run = coupled_run
    m = gust_metrics(run, 0.5)
    ref = loads_metrics(section_loads(wing, _without_loads(run),
                                      density_kg_m3=run.meta["loads"]["density_kg_m3"]), 0.5)
    for method in ("force_summation", "mode_displacement"):
        for q in QUANTITIES:
            for mine, theirs in zip(m.loads["methods"][method][q], ref["methods"][method][q],
                                    strict=True):
                assert mine.keys() == theirs.keys()
                for k in ("max", "min", "static_1g", "increment_up", "increment_down"):
                    assert mine[k] == pytest.approx(theirs[k], rel=1e-12, abs=1e-12), (q, k)
                assert mine["time_max_s"] == theirs["time_max_s"]
                assert mine["station"] == theirs["station"]
    # the post-process of a run with loads takes the run's own density by default
    again = section_loads(wing, run).values["force_summation"][:, 1, 0]
    ref_m = run["loads_fs_bending_n_m_s0"]
    assert np.max(np.abs(again - ref_m)) <= ROUNDING * np.max(np.abs(ref_m))
    root = m.loads["methods"]["force_summation"]["bending_n_m"][0]
    assert root["station"] == "root" and root["time_max_s"] == pytest.approx(0.5)
    assert root["max"] == pytest.approx(10.42, abs=0.01)
    assert root["increment_up"] == pytest.approx(7.43, abs=0.01)
    assert m.as_json()["loads"] is m.loads
    assert "loads" not in m.as_dict()  # the numeric table stays flat


def test_a_diverged_run_and_a_run_without_loads(wing, coupled_run):
    stopped = coupled_run.truncated(700)
    stopped.stopped = "mode aeroelastic_1 diverged (test)"
    assert gust_metrics(stopped, 0.5).loads is None  # no response metrics once diverged
    assert section_load_metrics(_without_loads(coupled_run), 0.5) is None
    plain = run_gust(Airframe(), wing.model, "coupled", RunConfig(15.0, parse_gust("sharp:1"),
                                                                 0.2, 0.1))
    assert "loads" not in plain.meta and not any(c.startswith("loads") for c in plain.channels)


def test_unsteady_wing_reports_both_methods(wing):
    """The unsteady wing: force summation (its lag states recovered from the rows:
    tests/test_loads_unsteady.py) and mode displacement (K_md on the run's own η)."""
    run = _fly(wing, aero="unsteady", duration_s=0.8)
    assert run.meta["loads"]["methods"] == ["force_summation", "mode_displacement"]
    lm = build_loads_model(wing, 15.0, density_kg_m3=run.meta["loads"]["density_kg_m3"])
    eta = lm.static_eta_rad + np.column_stack([run[f"eta{i + 1}"] for i in range(3)])
    np.testing.assert_allclose(run["loads_md_torque_n_m_s0"], eta @ lm.md_matrix[8],
                               rtol=1e-13, atol=1e-15)
    assert all(np.all(np.isfinite(run[c])) for c in run.channels if c.startswith("loads_fs"))


def test_a_wing_without_section_loads_says_why(wing):
    """A modes-file wing (no EI, GJ: the loads model refuses it) and the native wing fly;
    their runs say why they have no loads, and so do their metrics."""
    from dataclasses import replace

    modes_file = replace(wing, variant=replace(wing.variant, modes_file="x.toml"))
    setup = RunConfig(15.0, parse_gust("sharp:1"), 0.2, 0.1)
    run = run_gust(Airframe(), wing.model, "coupled", setup, loads=modes_file)
    assert "modes file" in run.meta["loads_unavailable"] and "loads" not in run.meta
    assert not any(c.startswith("loads_") for c in run.channels)
    assert gust_metrics(run, 0.1).loads == {"unavailable": run.meta["loads_unavailable"]}
    from bioflex_jsb.generators.native_wing import aircraft_name

    native = run_gust(Airframe(aircraft=aircraft_name("optimised")), None, "native", setup,
                      loads=wing)
    assert "native wing" in native.meta["loads_unavailable"]


@pytest.fixture(scope="module")
def logged(wing, tmp_path_factory):
    """A coupled and a rigid run logged through the log's recorder, with their histories."""
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import RunLog

    path = tmp_path_factory.mktemp("loads") / "run.mcap"
    desc = RunDescription("gust", "optimised", 15.0, gust="sharp:3",
                          models=("coupled", "rigid"), duration_s=2.0, gust_start_s=0.5)
    log = RunLog.open(path, desc, wing_variant=wing.variant.as_dict())
    runs = {}
    try:
        for model in ("coupled", "rigid"):
            runs[model] = run_gust(Airframe(), wing.model, model,
                                   RunConfig(15.0, parse_gust("sharp:3"), 2.0, 0.5),
                                   recorder=log.recorder(model), loads=wing)
    finally:
        log.close()
    return path, runs


@pytest.mark.parametrize("model", ["coupled", "rigid"])
def test_the_log_topic_is_the_runs_load_channels(logged, model):
    """/bioflex/<model>/loads: one message per step at the step's log time, each field
    the stations' values of one method and quantity, equal to the TimeHistory's channels
    bit for bit; the channel's metadata names the stations and the 1 g values."""
    path, runs = logged
    run = runs[model]
    msgs = decode_topic(path, f"/bioflex/{model}/loads")
    meta = channel_metadata(path, f"/bioflex/{model}/loads")
    assert [ns for ns, _ in msgs] == [round(t * 1e9) for t in run.time_s]
    assert json.loads(meta["stations_m"]) == run.meta["loads"]["stations_m"]
    assert meta["methods"].split(",") == run.meta["loads"]["methods"]
    static = json.loads(meta["static_1g"])
    for tag in ("fs", "md"):
        for q in QUANTITIES:
            field = f"{tag}_{q}"
            got = np.array([list(getattr(m, field)) for _, m in msgs])
            if model == "rigid" and tag == "md":
                assert got.size == 0 and field not in static  # no modes: no MD
                continue
            want = np.column_stack([run[f"loads_{field}_s{j}"] for j in range(4)])
            np.testing.assert_array_equal(got, want)
            assert static[field] == [run.meta["loads"]["static_1g"][f"loads_{field}_s{j}"]
                                     for j in range(4)]


@pytest.mark.slow  # the strict pymcap-cli doctor: 13-32 s
def test_info_lists_the_topic_and_doctor_passes(logged, capsys):
    path, _ = logged
    assert cli.main(["info", str(path)]) == 0
    out = capsys.readouterr().out
    for model in ("coupled", "rigid"):
        assert f"/bioflex/{model}/loads" in out and "bioflex.SectionLoads" in out
    exe = env_program("pymcap-cli")
    # strict: every chunk in log-time order (the loads have chunks of their own)
    res = subprocess.run([exe, "doctor", "--strict-message-order", str(path)],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and "passed" in res.stdout, res.stdout + res.stderr


def test_compare_covers_the_loads(wing):
    """The LTI model's load outputs beside the nonlinear run's, NRMSE of the increments
    over 1 g per load channel, in the linear regime (sharp:0.3): below 6 % (measured 1.7 %
    at the root, up to 3.5 % at 75 % semispan for the coupled wing; the airframes' own
    difference, u 2 %, eta1 2.6 %, is of the same size)."""
    c = api.compare(wing, 15.0, "sharp:0.3", "coupled", duration_s=2.0)
    assert len(c.load_channels) == 24 and c.channels == ("u", "alpha", "q", "theta", "eta1")
    for name in c.load_channels:
        assert 0.0 < c.nrmse[name] < 0.06, name
        assert c.worst[name]["unit"] in ("N", "N*m")
    lin, run = c.linear, c.nonlinear
    # the same 1 g values: the LTI starts at them (x = 0); the run within 1e-4: at trim its
    # n_z (JSBSim's, body axis) is cos(alpha_0) = 1 - 5.1e-4, whose weight of the wing moves
    # the root moment by 2.6e-5 of it (measured)
    static = run.meta["loads"]["static_1g"]
    assert lin.meta["loads"]["static_1g"] == static
    for name in c.load_channels:
        assert lin[name][0] == static[name]
    root = "loads_fs_bending_n_m_s0"
    assert abs(run[root][0] - static[root]) < 1e-4 * abs(static[root])
    assert "section load" in c.loads_table() and c.as_dict()["load_channels"] == list(
        c.load_channels)


def test_the_lti_prediction_topic_carries_the_lti_loads(wing, tmp_path):
    """compare's log: /bioflex/<model>/lti_prediction holds the LTI model's section loads
    under the loads topic's field names, at the run's log times, equal to the prediction's
    load channels bit for bit (totals: the run's 1 g part plus C x + D w_g), its channel's
    metadata naming the same stations and 1 g values as the run's loads channel; a
    prediction without loads has the fields empty."""
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import RunLog

    path = tmp_path / "compare.mcap"
    desc = RunDescription("compare", "optimised", 15.0, gust="sharp:0.3", models=("coupled",),
                          duration_s=1.0, gust_start_s=0.5)
    log = RunLog.open(path, desc, wing_variant=wing.variant.as_dict())
    try:
        c = api.compare(wing, 15.0, "sharp:0.3", "coupled", duration_s=1.0,
                        recorder=log.recorder("coupled"))
        log.prediction("coupled", c.linear)
        log.prediction("rigid", _without_loads(c.linear))  # another channel, no loads
    finally:
        log.close()
    lti = decode_topic(path, "/bioflex/coupled/lti_prediction")
    run = decode_topic(path, "/bioflex/coupled/loads")
    assert len(lti) == len(c.linear.time_s) > 0
    assert [ns for ns, _ in lti] == [ns for ns, _ in run]
    meta_lti = channel_metadata(path, "/bioflex/coupled/lti_prediction")
    meta_run = channel_metadata(path, "/bioflex/coupled/loads")
    assert meta_lti == meta_run
    for tag in ("fs", "md"):
        for q in QUANTITIES:
            field = f"{tag}_{q}"
            got = np.array([list(getattr(m, field)) for _, m in lti])
            want = np.column_stack([c.linear[f"loads_{field}_s{j}"] for j in range(4)])
            np.testing.assert_array_equal(got, want)
            assert len(getattr(run[0][1], field)) == got.shape[1] == 4
    assert lti[10][1].q_rad_s == c.linear["q"][10]
    bare = decode_topic(path, "/bioflex/rigid/lti_prediction")
    assert len(bare) == len(lti) and all(len(m.fs_bending_n_m) == 0 for _, m in bare)
    assert "stations_m" not in channel_metadata(path, "/bioflex/rigid/lti_prediction")


def test_compare_command_json_and_table(capsys):
    assert cli.main(["compare", "--gust", "sharp:0.3", "--duration", "1.5", "--no-log",
                     "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["nrmse"]["loads_md_torque_n_m_s0"] < 0.06
    assert data["worst"]["loads_fs_bending_n_m_s0"]["unit"] == "N*m"
    assert cli.main(["compare", "--gust", "sharp:0.3", "--duration", "1.5", "--no-log"]) == 0
    out = capsys.readouterr().out
    assert "fs_bending_n_m_s0" in out and "increments over 1 g" in out


def test_gust_summary_prints_root_bending_and_torque(capsys):
    assert cli.main(["gust", "--duration", "1.2", "--models", "rigid,coupled", "--no-log",
                     "--plot", ""]) == 0
    out = capsys.readouterr().out
    lines = out.splitlines()
    assert any(ln.startswith("root loads") and "bending moment M [N*m]" in ln for ln in lines)
    rows = {tuple(ln.split()[:2]): ln.split()[2:] for ln in lines
            if ln.split()[:2] in (["rigid", "FS"], ["coupled", "FS"], ["coupled", "MD"])}
    assert set(rows) == {("rigid", "FS"), ("coupled", "FS"), ("coupled", "MD")}
    assert not any(ln.split()[:2] == ["rigid", "MD"] for ln in lines)
    peak, inc = float(rows[("coupled", "FS")][0]), float(rows[("coupled", "FS")][1])
    assert math.isclose(peak, 10.424, abs_tol=1e-3) and math.isclose(inc, 7.432, abs_tol=1e-3)
