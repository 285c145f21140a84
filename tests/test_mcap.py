"""MCAP logs: contents, independent readers, interruption (SIGINT, SIGKILL), reading back."""

from __future__ import annotations

import json
import math
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import cli
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from bioflex_jsb.sinks.mcap.scene import SCENE_RATE_HZ
from tests.tools import env_program

ROOT = Path(__file__).resolve().parents[1]
JS_CHECK = ROOT / "tests" / "js" / "check_mcap.cjs"
RUN_GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "pose", "location")
# pose and location (the 3-D panel's body pose, the map's fix) at the 3-D scene's samples only
# (SCENE_RATE_HZ: the first step of each 1/60 s, a run's first step too), with or without a
# scene in the log; the other run topics at every step
SAMPLED_GROUPS = ("pose", "location")
EVERY_STEP_GROUPS = tuple(g for g in RUN_GROUPS if g not in SAMPLED_GROUPS)
# a gust run's log: the steps' topics and the wing's section loads (sinks/mcap/loads_topic.py,
# one message per step, a chunk of their own per block)
LOG_GROUPS = RUN_GROUPS + ("loads",)
# The 3-D scene (sinks/mcap/scene.py) in every gust log: the wing at SCENE_RATE_HZ, the rigid
# parts once per chunk, the section-load markers at the wing's samples (scene_loads.py); not
# one message per step, so counted apart.
SCENE_GROUPS = ("scene", "airframe", "scene_loads")
# 960 steps a second, 60 samples: a run from t = 0 has a sample every 16th step, from its first
STEPS_PER_SAMPLE = 16
assert STEPS_PER_SAMPLE * DEFAULT_DT_S * SCENE_RATE_HZ == pytest.approx(1.0, abs=1e-12)


def samples(n_steps: int) -> int:
    """Pose and location messages of a run of ``n_steps`` steps from t = 0."""
    return -(-n_steps // STEPS_PER_SAMPLE)


def per_step(counts: dict[str, int]) -> dict[str, int]:
    """The topics' message counts without the scene's and pose and location (which are not
    one per step)."""
    return {t: n for t, n in counts.items()
            if t.rsplit("/", 1)[-1] not in SCENE_GROUPS + SAMPLED_GROUPS}


def sampled_counts(counts: dict[str, int]) -> dict[str, int]:
    """The message counts of pose and location."""
    return {t: n for t, n in counts.items() if t.rsplit("/", 1)[-1] in SAMPLED_GROUPS}


def expected_counts(model: str, n_steps: int, groups=LOG_GROUPS) -> dict[str, int]:
    """The per-step and pose/location counts of ``n_steps`` steps of ``model`` from t = 0."""
    return {sink.topic(model, g): samples(n_steps) if g in SAMPLED_GROUPS else n_steps
            for g in groups}


def step_messages(path) -> int:
    """Messages of a log on its per-step topics (the scene's, pose and location left out)."""
    info = sink.summarise(path)
    return sum(per_step({c["topic"]: c["messages"] for c in info["channels"]}).values())
NEW_COMMANDS = ("info", "plot", "rerun")


def main(argv: list[str]) -> int:
    """``bioflex_jsb.cli.main`` with the log commands registered (a no-op once they are)."""
    missing = tuple(m for m in NEW_COMMANDS if m not in cli.COMMAND_MODULES)
    saved = cli.COMMAND_MODULES
    cli.COMMAND_MODULES = saved + missing
    try:
        return cli.main(argv)
    finally:
        cli.COMMAND_MODULES = saved


@pytest.fixture(scope="module")
def gust_log(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("log") / "run.mcap"
    status = cli.main(["gust", "--duration", "1", "--models", "coupled", "--out", str(path),
                       "--json"])
    assert status == 0
    return path


STEPS_1S = int(round(1.0 / DEFAULT_DT_S))
# a log written before protobuf (JSON messages): gust --duration 0.3 --gust-start 0.1
OLD_JSON_LOG = ROOT / "tests" / "fixtures" / "old_json_log.mcap"
OLD_STEPS = int(round(0.3 / DEFAULT_DT_S))


def read_all(path: Path) -> dict[str, list[tuple[int, dict]]]:
    return sink.messages_by_topic(path)


def test_every_step_on_every_topic_with_schemas_and_metadata(gust_log):
    info = sink.summarise(gust_log)
    counts = {c["topic"]: c["messages"] for c in info["channels"]}
    assert per_step(counts) == {sink.topic("coupled", g): STEPS_1S
                                for g in LOG_GROUPS if g not in SAMPLED_GROUPS}
    # the scene: 60 samples over the second flown, the rigid parts once per chunk of steps;
    # pose and location at the same 60 samples
    assert counts[sink.topic("coupled", "scene")] == 60 == samples(STEPS_1S)
    assert sampled_counts(counts) == {sink.topic("coupled", g): 60 for g in SAMPLED_GROUPS}
    assert counts[sink.topic("coupled", "airframe")] == math.ceil(1.0 / sink.CHUNK_SPAN_S)
    schemas = {c["topic"]: c["schema"] for c in info["channels"]}
    assert schemas[sink.topic("coupled", "scene")] == "foxglove.SceneUpdate"
    assert schemas["/bioflex/coupled/pose"] == "foxglove.FrameTransform"
    assert schemas["/bioflex/coupled/location"] == "foxglove.LocationFix"
    assert info["duration_s"] == pytest.approx((STEPS_1S - 1) * DEFAULT_DT_S, abs=1e-9)
    run = info["metadata"][sink.RUN_METADATA]
    assert run["command"] == "gust" and run["wing"] == "optimised"
    assert run["gust"] == "sharp:3" and run["gust_seed"] == "0"
    assert float(run["dt_s"]) == DEFAULT_DT_S and run["jsbsim_version"] != "unknown"
    # the run description, as data: what rerun flies again (no command-line arguments)
    described = sink.description_from_metadata(run)
    assert described == RunDescription(kind="gust", wing="optimised", speed_m_s=15.0,
                                       gust="sharp:3", models=("coupled",), duration_s=1.0)
    assert "arguments" not in run and "argv" not in run
    # chunks close every CHUNK_SPAN_S of simulated time: what a SIGKILL can lose
    # steps, then their scene, then their loads, then the loads' markers in the scene
    assert info["chunks"] == 4 * math.ceil(1.0 / sink.CHUNK_SPAN_S)


def test_messages_follow_the_schemas_and_foxglove_field_names(gust_log):
    msgs = read_all(gust_log)
    for group in RUN_GROUPS:
        schema = sink.SCHEMAS[group]
        for _ns, m in msgs[sink.topic("coupled", group)][:3]:
            assert set(m) <= set(schema["properties"]), group
    pose = msgs["/bioflex/coupled/pose"]
    ns0, p0 = pose[0]
    assert set(p0) == {"timestamp", "parent_frame_id", "child_frame_id", "translation",
                       "rotation"}
    assert p0["parent_frame_id"] == "world" and p0["child_frame_id"] == "coupled_body"
    assert p0["translation"] == {"x": 0.0, "y": 0.0, "z": 0.0}  # the ENU origin
    ns, p = pose[-1]
    assert p["timestamp"]["sec"] * 10**9 + p["timestamp"]["nsec"] == ns
    q = p["rotation"]
    assert math.isclose(math.sqrt(sum(v * v for v in q.values())), 1.0, abs_tol=1e-7)
    # flying north (ψ ≈ 0) at 15 m/s for 1 s: the aircraft moved ~15 m north, not east
    assert 13.0 < p["translation"]["y"] < 17.0 and abs(p["translation"]["x"]) < 0.5
    fix = msgs["/bioflex/coupled/location"][-1][1]
    assert set(fix) == {"timestamp", "frame_id", "latitude", "longitude", "altitude",
                        "position_covariance", "position_covariance_type"}
    assert 44.9 < fix["latitude"] < 45.1 and len(fix["position_covariance"]) == 9
    rigid = msgs["/bioflex/coupled/rigid_body"]
    assert [m["airspeed_m_s"] for _, m in rigid[:1]] == [pytest.approx(15.0, abs=1e-6)]
    # the whole rigid-body state, one snapshot per step: before the gust (no wind) the
    # inertial speed is the airspeed, α = trim + Δα, the flight is symmetric (β = 0) and the
    # load factor is that of the trim
    first = rigid[0][1]
    assert {"alpha_rad", "beta_rad", "v_north_m_s", "v_east_m_s", "v_down_m_s"} <= set(first)
    speed = math.sqrt(sum(first[k] ** 2 for k in ("v_north_m_s", "v_east_m_s", "v_down_m_s")))
    assert speed == pytest.approx(first["airspeed_m_s"], rel=1e-6)
    assert first["dalpha_rad"] == pytest.approx(0.0, abs=1e-6) and abs(first["beta_rad"]) < 1e-6
    assert first["n_z"] == pytest.approx(1.0, abs=1e-3)
    assert first["v_north_m_s"] == pytest.approx(15.0 * math.cos(first["alpha_rad"]
                                                                 - first["pitch_rad"]), rel=1e-4)
    gust = [m["w_g_m_s"] for _, m in msgs["/bioflex/coupled/gust"]]
    assert max(gust) == pytest.approx(3.0)


def test_pose_and_location_at_the_scene_samples_with_rigid_body_values(gust_log):
    """Pose and location at the scene's 60 Hz instants (its rule and rate, so the body pose
    and the wing drawn agree), their values those of rigid_body at those steps, their
    sequence numbers counting their own messages, the rate in their channel metadata."""
    from mcap.reader import make_reader

    msgs = read_all(gust_log)
    rigid = msgs[sink.topic("coupled", "rigid_body")]
    scene_ns = [ns for ns, _ in msgs[sink.topic("coupled", "scene")]]
    assert len(rigid) == STEPS_1S and len(scene_ns) == samples(STEPS_1S)
    at = {ns: m for ns, m in rigid}
    pose, fix = msgs[sink.topic("coupled", "pose")], msgs[sink.topic("coupled", "location")]
    assert [ns for ns, _ in pose] == [ns for ns, _ in fix] == scene_ns
    assert scene_ns == [ns for ns, _ in rigid[::STEPS_PER_SAMPLE]]
    h0 = rigid[0][1]["altitude_m"]
    for (ns, p), (_, f) in zip(pose, fix, strict=True):
        r = at[ns]
        assert p["timestamp"] == f["timestamp"] == {"sec": ns // 10**9, "nsec": ns % 10**9}
        assert p["translation"]["z"] == r["altitude_m"] - h0  # the same double, offset
        assert f["altitude"] == r["altitude_m"]
        q = sink.enu_quaternion(r["roll_rad"], r["pitch_rad"], r["yaw_rad"])
        assert [p["rotation"][k] for k in "xyzw"] == pytest.approx(q, abs=1e-15)
    with open(gust_log, "rb") as f:
        reader = make_reader(f)
        channels = reader.get_summary().channels
        seqs: dict[str, list[int]] = {}
        for _schema, channel, message in reader.iter_messages(log_time_order=False):
            seqs.setdefault(channel.topic, []).append(message.sequence)
    meta = {c.topic.rsplit("/", 1)[-1]: dict(c.metadata) for c in channels.values()}
    for g in RUN_GROUPS:
        n = samples(STEPS_1S) if g in SAMPLED_GROUPS else STEPS_1S
        assert seqs[sink.topic("coupled", g)] == list(range(n)), g
        assert meta[g].get("rate_hz") == (repr(SCENE_RATE_HZ) if g in SAMPLED_GROUPS
                                          else None), g


def test_enu_quaternion_matches_the_rotation_matrix():
    rng = np.random.default_rng(1)
    for phi, theta, psi in rng.uniform(-1.2, 1.2, size=(20, 3)):
        x, y, z, w = sink.enu_quaternion(phi, theta, psi)
        r_q = np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ])
        cf, sf, ct, st, cp, sp = (np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta),
                                  np.cos(psi), np.sin(psi))
        # body FRD → NED (aerospace 3-2-1), then NED → ENU and FLU → FRD
        r_ned_frd = np.array([
            [ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp],
            [ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp],
            [-st, sf * ct, cf * ct],
        ])
        ned_to_enu = np.array([[0, 1, 0], [1, 0, 0], [0, 0, -1]])
        flu_to_frd = np.diag([1, -1, -1])
        assert np.allclose(r_q, ned_to_enu @ r_ned_frd @ flu_to_frd, atol=1e-12)


def _node_checker(tmp_path_factory):
    node, npm = shutil.which("node"), shutil.which("npm")
    if not node or not npm:
        pytest.skip("node/npm are not installed: the @mcap/core check cannot run")
    where = tmp_path_factory.mktemp("mcapjs")
    (where / "package.json").write_text('{"name": "mcap-check", "private": true}\n')
    done = subprocess.run([npm, "install", "--no-audit", "--no-fund", "@mcap/core",
                           "@foxglove/wasm-zstd", "protobufjs"], cwd=where,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    shutil.copy(JS_CHECK, where / JS_CHECK.name)

    def check(path: Path) -> dict:
        out = subprocess.run([node, JS_CHECK.name, str(path)], cwd=where, capture_output=True,
                             text=True, timeout=120)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)

    return check


@pytest.fixture(scope="module")
def node_check(tmp_path_factory):
    return _node_checker(tmp_path_factory)


def test_mcap_core_indexed_reader_with_crcs(gust_log, node_check):
    result = node_check(gust_log)
    expected = expected_counts("coupled", STEPS_1S)
    # through the chunk indexes, CRCs checked
    assert {**per_step(result["counts"]), **sampled_counts(result["counts"])} == expected
    assert {**per_step(result["statistics"]), **sampled_counts(result["statistics"])} == expected
    assert result["dataCrcOk"] is True and result["ordered"] is True
    assert result["schemas"]["/bioflex/coupled/location"] == "foxglove.LocationFix"
    assert set(result["encodings"].values()) == {"protobuf"}
    # protobufjs (Foxglove's decoder) reads every message as our own reader does
    ours = read_all(gust_log)
    for top, theirs in result["samples"].items():
        if top.rsplit("/", 1)[-1] in SCENE_GROUPS:
            continue  # nested messages: tests/test_scene.py compares their vertices
        mine = ours[top][1][1]
        if "timestamp" in theirs:  # google.protobuf.Timestamp: seconds/nanos
            ts = theirs.pop("timestamp")
            assert mine.pop("timestamp") == {"sec": ts.get("seconds", 0),
                                             "nsec": ts.get("nanos", 0)}
        mine = {k: v for k, v in mine.items() if v not in (0, 0.0)}  # proto3 defaults
        theirs = {k: v for k, v in theirs.items() if v not in (0, 0.0)}
        assert theirs == mine, top  # the same doubles, bit for bit


def test_old_json_log_reads_with_mcap_core(node_check):
    result = node_check(OLD_JSON_LOG)
    assert set(result["encodings"].values()) == {"json"}
    assert result["counts"][sink.topic("coupled", "pose")] == OLD_STEPS


def test_pymcap_cli_doctor(gust_log):
    exe = env_program("pymcap-cli")
    out = subprocess.run([exe, "doctor", str(gust_log)], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "passed" in out.stdout and "error" not in out.stdout.lower()


def test_info_plot_and_rerun(gust_log, tmp_path, capsys):
    assert main(["info", str(gust_log), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    # + pose and location, the scene's and the markers
    assert info["messages"] == step_messages(gust_log) + 2 * 60 + 60 + 2 + 60
    assert step_messages(gust_log) == STEPS_1S * (len(LOG_GROUPS) - len(SAMPLED_GROUPS))
    png = tmp_path / "run.png"
    assert main(["plot", str(gust_log), "--out", str(png)]) == 0
    assert png.stat().st_size > 10_000
    assert "written to" in capsys.readouterr().out
    again = tmp_path / "again.mcap"
    assert main(["rerun", str(gust_log), "--out", str(again), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["equal"] is True and result["first_difference"] is None
    assert result["command"][1:3] == ["gust", "--wing=optimised"]
    assert step_messages(again) == STEPS_1S * (len(LOG_GROUPS) - len(SAMPLED_GROUPS))


def test_rerun_reports_a_difference(gust_log, tmp_path, capsys):
    from bioflex_jsb.cli.rerun import compare_logs

    same = compare_logs(str(gust_log), str(gust_log), 1e-8)
    assert same["equal"] and same["messages"] == sink.summarise(gust_log)["messages"]
    other = tmp_path / "other.mcap"
    assert cli.main(["gust", "--duration", "1", "--models", "coupled", "--gust", "sharp:2",
                     "--out", str(other), "--json"]) == 0
    capsys.readouterr()
    diff = compare_logs(str(gust_log), str(other), 1e-8)
    assert not diff["equal"] and "/bioflex/coupled/" in diff["first_difference"]


def test_compare_logs_the_run_and_the_lti_prediction_and_reruns(tmp_path, capsys):
    out = tmp_path / "cmp.mcap"
    assert main(["compare", "--duration", "1", "--out", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["out"] == str(out)
    msgs = read_all(out)
    run = msgs["/bioflex/coupled/rigid_body"]
    lti = msgs["/bioflex/coupled/lti_prediction"]
    assert len(run) == len(lti) == STEPS_1S
    assert [ns for ns, _ in lti] == [ns for ns, _ in run]
    # small gust: the linear prediction follows the nonlinear run (compare's own check)
    dq = max(abs(m["q_rad_s"]) for _, m in run)
    assert dq > 1e-3
    assert max(abs(a["q_rad_s"] - b["q_rad_s"]) for (_, a), (_, b) in zip(run, lti,
                                                                          strict=True)) < 0.2 * dq
    again = tmp_path / "cmp2.mcap"
    assert main(["rerun", str(out), "--out", str(again), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["equal"] and result["command"][1] == "compare"


def test_runs_log_by_default_unless_told_not_to(tmp_path, monkeypatch, capsys):
    from bioflex_jsb.cli.common import LOG_DIR_ENV_VAR

    folder = tmp_path / "logs"  # its parent exists: only the last directory is created
    monkeypatch.setenv(LOG_DIR_ENV_VAR, str(folder))
    args = ["gust", "--duration", "0.2", "--gust-start", "0.1", "--models", "rigid", "--json"]
    assert main(args) == 0
    first = json.loads(capsys.readouterr().out)["out"]
    assert main(args) == 0
    second = json.loads(capsys.readouterr().out)["out"]
    logs = sorted(folder.glob("gust-optimised-*.mcap"))
    assert {str(p) for p in logs} == {first, second} and first != second
    counts = {c["topic"]: c["messages"] for c in sink.summarise(first)["channels"]}
    assert {**per_step(counts), **sampled_counts(counts)} == expected_counts(
        "rigid", round(0.2 / DEFAULT_DT_S))  # pose and location at 60 Hz
    assert main([*args, "--no-log"]) == 0
    assert json.loads(capsys.readouterr().out)["out"] is None
    assert len(list(folder.iterdir())) == 2
    assert main([*args, "--no-log", "--out", str(tmp_path / "x.mcap")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "contradict" in err
    (tmp_path / "file").write_text("")
    monkeypatch.setenv(LOG_DIR_ENV_VAR, str(tmp_path / "file" / "logs"))
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--no-log" in err


def test_output_into_a_closed_pipe_is_no_traceback(gust_log):
    """`bioflex-jsb info run.mcap | head -1`: the reader leaves before the output is written."""
    proc = subprocess.Popen([sys.executable, "-m", "bioflex_jsb", "info", str(gust_log)],
                            cwd=ROOT, env=_env(), stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    proc.stdout.close()  # before the interpreter has even started
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141 and "Traceback" not in err and err == ""


@pytest.mark.parametrize("command", ["info", "plot", "rerun"])
def test_bad_files_exit_2_with_one_line(command, gust_log, tmp_path, capsys):
    truncated = tmp_path / "cut.mcap"
    truncated.write_bytes(gust_log.read_bytes()[:20_000])
    text = tmp_path / "text.mcap"
    text.write_text("not a log\n")
    extra = ["--out", str(tmp_path / "x.mcap")] if command == "rerun" else []
    for bad, words in ((tmp_path / "missing.mcap", "not found"),
                       (text, "not an MCAP file"), (truncated, "--recover")):
        assert main([command, str(bad), *extra]) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and words in err, err


def test_non_finite_numbers_are_written_as_they_are(tmp_path):
    row = {k: 0.01 for k in ("u", "alpha", "q", "theta", "w_g", "latitude_rad",
                             "longitude_rad", "phi_rad", "theta_rad", "psi_rad", "p_rad_s",
                             "r_rad_s", "elevator_rad", "throttle", "lift_n", "drag_n",
                             "pitch_moment_n_m", "eta1", "eta1_dot")}
    row.update(n_z=1.0, airspeed_m_s=15.0, altitude_m=100.0)
    log = _bare_log(tmp_path / "nan.mcap")
    log.sample("coupled", 0.0, row)
    log.sample("coupled", 0.01, {**row, "eta1": float("nan"), "lift_n": float("inf"),
                                 "u": 1e-300})
    log.close()
    msgs = read_all(tmp_path / "nan.mcap")
    assert math.isnan(msgs["/bioflex/coupled/modal"][1][1]["eta_rad"][0])  # binary doubles
    assert msgs["/bioflex/coupled/modal_loads"][1][1]["lift_n"] == math.inf
    assert msgs["/bioflex/coupled/rigid_body"][1][1]["du_m_s"] == 1e-300
    assert msgs["/bioflex/coupled/rigid_body"][0][1]["du_m_s"] == 0.01


def _bare_log(path: Path) -> sink.RunLog:
    stream = open(path, "wb")  # noqa: SIM115 - closed by RunLog.close
    return sink.RunLog(path, stream, sink.McapFileWriter(stream, "test"))


def test_lti_prediction_channel(tmp_path, node_check):
    from bioflex_jsb.simulation.results import TimeHistory

    t = np.arange(50) * 0.01
    hist = TimeHistory("coupled", t, {"u": np.sin(t), "alpha": t, "q": t, "theta": t,
                                      "n_z": 1 + t, "eta1": t, "eta2": -t}, {}, {})
    log = _bare_log(tmp_path / "lti.mcap")
    log.prediction("coupled", hist)
    log.close()
    msgs = read_all(tmp_path / "lti.mcap")["/bioflex/coupled/lti_prediction"]
    assert len(msgs) == 50 and msgs[10][1]["eta_rad"] == [pytest.approx(0.1), -0.1]
    assert node_check(tmp_path / "lti.mcap")["counts"] == {
        "/bioflex/coupled/lti_prediction": 50}


def _env():
    return {**os.environ, "PYTHONPATH": str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH",
                                                                                "")}


# A gust run that reports each logged step's time on stdout (to know what was flown).
DRIVER = """
import sys
from bioflex_jsb import cli
from bioflex_jsb.runtime.coupled_step import CoupledStep
original = CoupledStep.stepper
def stepper(self):
    advance, k = original(self), [0]
    def counted(w_g, table, j):
        stop = advance(w_g, table, j)
        sys.stdout.write(repr(k[0] * self.dt_s) + "\\n")
        sys.stdout.flush()
        k[0] += 1
        return stop
    return counted
CoupledStep.stepper = stepper
sys.exit(cli.main(sys.argv[1:]))
"""


def _start_run(path: Path, until_s: float):
    proc = subprocess.Popen(
        [sys.executable, "-c", DRIVER, "gust", "--duration", "20", "--models", "coupled",
         "--out", str(path), "--json"],
        cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    last = None
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        line = proc.stdout.readline()
        if not line:
            break
        last = float(line)
        if last >= until_s:
            return proc, last
    proc.kill()
    pytest.fail(f"the run did not reach t = {until_s} s (last {last})")


def test_sigint_leaves_a_finished_file_with_every_step(tmp_path, node_check):
    path = tmp_path / "int.mcap"
    proc, _ = _start_run(path, until_s=2.0)
    proc.send_signal(signal.SIGINT)
    rest, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    flown = [float(x) for x in rest.split()[:-1] if _is_number(x)]
    msgs = read_all(path)
    rigid = msgs["/bioflex/coupled/rigid_body"]
    n = len(rigid)
    assert n >= int(2.0 / DEFAULT_DT_S)
    # every step, none skipped, the same count on every topic, through @mcap/core too
    assert [ns for ns, _ in rigid] == [round(k * DEFAULT_DT_S * 1e9) for k in range(n)]
    if flown:
        # the signal lands between two statements of the instrumented loop: the last step
        # printed and the last step logged can be one step apart (either way), no more
        assert abs(rigid[-1][0] * 1e-9 - flown[-1]) <= DEFAULT_DT_S + 1e-9
    counts = node_check(path)["counts"]
    # the loads too: the run hands on its last row's loads when it is stopped; pose and
    # location at the 60 Hz samples of the steps logged
    assert {**per_step(counts), **sampled_counts(counts)} == expected_counts("coupled", n)
    assert "interrupted" in err and "holds every step" in err


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def test_sigkill_loses_at_most_one_chunk_and_recovers(tmp_path, node_check, capsys):
    path = tmp_path / "killed.mcap"
    # killed just before a chunk closes (chunks span [k, k+1) × CHUNK_SPAN_S): the worst case
    proc, last = _start_run(path, until_s=7.9 * sink.CHUNK_SPAN_S)
    proc.kill()
    # the steps printed before the kill: through the text stream, whose buffer may already
    # hold lines the loop above has not read (communicate() reads only the pipe: the run was
    # then taken as stopped at until_s while a later chunk was on disk, "lost" < 0, a flake
    # under load); a line cut by the kill is not a step's time
    rest = proc.stdout.read()
    proc.communicate(timeout=60)
    sampled = [float(x) for x in rest.split("\n")[:-1] if _is_number(x)]
    last_flown_s = sampled[-1] if sampled else last
    # the killed log has no summary: info says how to recover it
    assert main(["info", str(path)]) == 2
    assert "--recover" in capsys.readouterr().err
    fixed = tmp_path / "fixed.mcap"
    assert main(["info", str(path), "--recover", str(fixed), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    lost_s = last_flown_s - report["last_time_s"]
    print(f"SIGKILL at t = {last_flown_s:.3f} s simulated: recovered up to "
          f"{report['last_time_s']:.3f} s, lost {lost_s:.3f} s")
    assert 0.0 <= lost_s <= sink.CHUNK_SPAN_S + 2 * DEFAULT_DT_S <= 1.0
    counts = node_check(fixed)["counts"]
    counts = {**per_step(counts), **sampled_counts(counts)}
    n = round(report["last_time_s"] / DEFAULT_DT_S) + 1
    loads = counts.pop(sink.topic("coupled", "loads"))
    assert counts == expected_counts("coupled", n, RUN_GROUPS)
    # the loads' chunk follows its steps' one step behind: killed between the two writes, a
    # block (864 steps) more is lost
    assert n - 1 - 864 <= loads <= n - 1


def test_varints_are_canonical_protobuf():
    """The timestamp varints: every length 1 … 5 bytes, equal to the shortest encoding."""
    from bioflex_jsb.sinks.mcap_io import protobuf, records

    v = np.array([0, 1, 127, 128, 16383, 16384, 2**21 - 1, 2**21, 2**28 - 1, 2**28,
                  999_999_999], dtype=np.int64)
    lengths = [records._varint_length(x) for x in v.tolist()]  # the records' lengths
    assert lengths == [len(protobuf.varint(int(x))) for x in v]
    for x, n in zip(v.tolist(), lengths, strict=True):
        row = np.zeros(n + 2, dtype=np.uint8)
        records._write_varint(row, 1, x, n)  # the records' writer, one byte in
        assert row[0] == 0 and row[-1] == 0  # nothing outside its n bytes
        got = row[1:1 + n].tobytes()
        assert got == protobuf.varint(x) and protobuf.read_varint(got, 0) == (x, n)


def test_records_write_the_sampled_records_at_their_steps_only():
    """Records with ``every``: each step's every-step record, the others only at the sampled
    steps, in step order across a change of the timestamp's varint lengths (one compiled
    pass, several layouts); each channel's sequence numbers count its own messages and its
    index entries point at its records."""
    import struct

    from bioflex_jsb.sinks.mcap_io import protobuf, records

    def pieces(ls, ln):
        return [records.doubles((1,)),
                records.timestamp(1, ls, ln) + records.doubles((2,))]

    recs = records.Records([7, 9], pieces, timestamped=True, every=1)
    ns = np.array([127_999_999_000, 127_999_999_500, 128_000_000_000, 128_000_000_250,
                   128_000_001_000, 128_000_002_000], dtype=np.int64)  # 1 → 2-byte seconds
    floats = np.column_stack([np.arange(6.0), 100.0 + np.arange(6.0)])
    sampled = np.array([0, 2, 3, 5])
    block, index = recs.build(ns, floats, 40, sampled, 11)
    data, pos, got = bytes(block), 0, []
    while pos < len(data):
        op, length, cid, seq, log_ns, pub_ns = struct.unpack_from("<BQHIQQ", data, pos)
        assert op == 0x05 and log_ns == pub_ns
        got.append((pos, cid, seq, log_ns, data[pos + 31:pos + 9 + length]))
        pos += 9 + length
    assert pos == len(data)
    expect = []
    for r in range(6):
        expect.append((7, 40 + r, int(ns[r])))
        if r in sampled:
            expect.append((9, 11 + sampled.tolist().index(r), int(ns[r])))
    assert [(c, q, t) for _, c, q, t, _ in got] == expect
    for cid in (7, 9):
        mine = [(t, at) for at, c, _, t, _ in got if c == cid]
        assert index[cid].tolist() == [list(e) for e in mine]
    read = protobuf.read_varint
    for _, cid, _, t, body in got:
        if cid == 9:  # the timestamp and the sampled row's own double
            assert body[0] == 0x0A
            stamp = body[2:2 + body[1]]
            sec, k = read(stamp, 1)
            nsec, _ = read(stamp, k + 1)
            assert sec * 10**9 + nsec == t
            step = ns.tolist().index(t)
            assert struct.unpack_from("<d", body, len(body) - 8)[0] == 100.0 + step
        else:
            assert struct.unpack_from("<d", body, 1)[0] == ns.tolist().index(t)


def _chunks_of(recorder, time_s, table, dt_s=1 / 960):
    """Hand ``table`` to ``recorder`` as run_gust does: blocks of the steps it asks for."""
    block = recorder.start(tuple(NAMES_2), dt_s)
    for k in range(0, len(table), block):
        recorder.rows(time_s[k:k + block], table[k:k + block])
    recorder.stop(len(table))
    return block


def _names(n_modes: int) -> tuple[str, ...]:
    from bioflex_jsb.simulation.channels import channel_units as base_channels

    return tuple(base_channels(n_modes))


NAMES_2 = _names(2)


def test_dict_samples_and_table_recorder_write_the_same_messages(tmp_path):
    names = NAMES_2
    rng = np.random.default_rng(3)
    table = rng.standard_normal((1000, len(names))) * 0.1
    table[:, names.index("altitude_m")] += 100.0
    time_s = np.arange(1000) / 960
    a, b = _bare_log(tmp_path / "a.mcap"), _bare_log(tmp_path / "b.mcap")
    block = _chunks_of(a.recorder("coupled"), time_s, table)
    assert block == 864  # CHUNK_SPAN_S of steps at 960 Hz
    for k in range(1000):
        b.sample("coupled", time_s[k], dict(zip(names, table[k].tolist(), strict=True)))
    a.close()
    b.close()
    ma, mb = read_all(tmp_path / "a.mcap"), read_all(tmp_path / "b.mcap")
    assert ma == mb and len(ma["/bioflex/coupled/rigid_body"]) == 1000
    first = ma["/bioflex/coupled/modal"][5][1]
    assert first["eta_rad"][1] == table[5, names.index("eta2")]  # the double itself
    # a chunk every CHUNK_SPAN_S of simulated time (864 steps at 960 Hz): 2 for 1000 steps
    assert sink.summarise(tmp_path / "a.mcap")["chunks"] == 2


def test_recorder_writes_each_block_at_once_and_once(tmp_path):
    """Rows reach the file as soon as their block is handed over, each once; stop adds
    nothing; a block across a varint-length change of the timestamps reads back in order."""
    names = NAMES_2
    n_rows = 1000
    table = np.zeros((n_rows, len(names)))
    table[:, 0] = np.arange(n_rows)  # u: the row number, to find every row in the file
    time_s = 127.5 + np.arange(n_rows) / 960  # seconds 127 → 128: 1 → 2 byte varints
    log = _bare_log(tmp_path / "r.mcap")
    rec = log.recorder("coupled")
    block = rec.start(names, 1 / 960)
    rec.rows(time_s[:block], table[:block])
    # written when handed over, before stop: five topics at every step, pose and location
    # at its 60 Hz samples (127.5 s is the start of a 1/60 s bin: every 16th step from the first)
    assert log._writer._n_messages == block * 5 + 2 * samples(block)
    rec.rows(time_s[block:900], table[block:900])  # the loop failed after row 899
    rec.stop(900)
    rec.stop(900)
    log.close()
    msgs = read_all(tmp_path / "r.mcap")
    assert [m["du_m_s"] for _, m in msgs["/bioflex/coupled/rigid_body"]] == list(range(900))
    pose = msgs["/bioflex/coupled/pose"]
    # the sample at step 480 (t = 128 s) is the first with 2-byte seconds varints
    assert [ns for ns, _ in pose] == [round(t * 1e9) for t in time_s[:900:STEPS_PER_SAMPLE]]
    assert round(128.0 * 1e9) in [ns for ns, _ in pose]
    assert all(m["timestamp"] == {"sec": ns // 10**9, "nsec": ns % 10**9} for ns, m in pose)
    assert [ns for ns, _ in msgs["/bioflex/coupled/location"]] == [ns for ns, _ in pose]


# --------------------------------------------------------------- run descriptions and errors

def _legacy_copy(src: Path, dst: Path) -> None:
    """``src`` rewritten as a log of before run descriptions: its bioflex.run record holds
    only the command, its argparse arguments and the argument list that repeats it."""
    from mcap.reader import make_reader
    from mcap.writer import CompressionType, Writer

    with open(src, "rb") as f, open(dst, "wb") as out:
        reader = make_reader(f)
        summary = reader.get_summary()
        meta = sink.read_metadata(reader)[sink.RUN_METADATA]
        d = sink.description_from_metadata(meta)
        argv = ["gust", "--wing", d.wing, "--mass-basis", d.mass_basis, "--speed",
                repr(d.speed_m_s), "--gust", d.gust, "--duration", repr(d.duration_s),
                "--gust-start", repr(d.gust_start_s), "--dt", repr(d.dt_s), "--models",
                ",".join(d.models)]
        legacy = {k: v for k, v in meta.items() if k != "description"}
        legacy.update(command="gust", argv=json.dumps(argv), arguments=json.dumps(
            {"wing": d.wing, "speed": d.speed_m_s, "gust": d.gust, "models": list(d.models)}))
        w = Writer(out, compression=CompressionType.ZSTD)
        w.start(profile="", library="bioflex-jsb 0.old")
        schemas = {sid: w.register_schema(s.name, s.encoding, s.data)
                   for sid, s in summary.schemas.items()}
        channels = {cid: w.register_channel(c.topic, c.message_encoding,
                                            schemas[c.schema_id], dict(c.metadata))
                    for cid, c in summary.channels.items()}
        w.add_metadata(sink.RUN_METADATA, legacy)
        for _schema, channel, message in reader.iter_messages(log_time_order=True):
            w.add_message(channels[channel.id], message.log_time, message.data,
                          message.publish_time, message.sequence)
        w.finish()


def test_old_logs_without_a_description_stay_readable_and_rerunnable(gust_log, tmp_path,
                                                                         capsys):
    old = tmp_path / "old.mcap"
    _legacy_copy(gust_log, old)
    meta = sink.summarise(old)["metadata"][sink.RUN_METADATA]
    assert "description" not in meta and sink.description_from_metadata(meta) is None
    assert main(["info", str(old)]) == 0
    assert "argv" in capsys.readouterr().out
    again = tmp_path / "again.mcap"
    assert main(["rerun", str(old), "--out", str(again), "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["equal"] is True and result["command"][1] == "gust"
    # the repeated run is a new log: it records its description
    new_meta = sink.summarise(again)["metadata"][sink.RUN_METADATA]
    assert sink.description_from_metadata(new_meta).models == ("coupled",)


def _described_log(path: Path, description: RunDescription) -> None:
    log = sink.RunLog.open(path, description, {"name": "optimised"}, {})
    log.close()


def test_rerun_refuses_a_sitl_session_and_a_bad_description_with_one_line(tmp_path, capsys):
    sitl = tmp_path / "sitl.mcap"
    _described_log(sitl, RunDescription(kind="sitl", wing="optimised", speed_m_s=15.0,
                                        gust="none", models=("coupled",)))
    assert main(["rerun", str(sitl), "--out", str(tmp_path / "x.mcap")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "SITL" in err, err
    bad = tmp_path / "bad.mcap"
    stream = open(bad, "wb")  # noqa: SIM115 - closed by RunLog.close
    sink.RunLog.local(bad, stream, {"description": json.dumps(
        {"kind": "gust", "wing": "optimised", "speed_m_s": -1.0})}).close()
    assert main(["rerun", str(bad), "--out", str(tmp_path / "y.mcap")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "speed_m_s" in err, err
    with pytest.raises(sink.LogError, match="not JSON"):
        sink.description_from_metadata({"description": "{"})


def test_rerun_flies_the_description_it_reads(tmp_path):
    from bioflex_jsb.cli.rerun import argv_for

    d = RunDescription(kind="sweep", wing="optimised", speed_m_s=16.5, gust="1cos:2:10",
                       models=("qsd",), duration_s=0.5, gust_start_s=0.1, dt_s=0.002,
                       mass_basis="paper", extra={"case_id": "c1"})
    path = tmp_path / "case.mcap"
    _described_log(path, d)
    meta = sink.summarise(path)["metadata"][sink.RUN_METADATA]
    assert sink.description_from_metadata(meta) == d
    assert meta["wing"] == "optimised" and meta["gust"] == "1cos:2:10"
    assert argv_for(d) == ["gust", "--wing=optimised", "--mass-basis=paper",
                           "--speed=16.5", "--gust=1cos:2:10", "--duration=0.5",
                           "--gust-start=0.1", "--dt=0.002", "--models=qsd"]
    cmp = RunDescription(kind="compare", wing="optimised", speed_m_s=15.0, models=("rigid",))
    assert argv_for(cmp)[0] == "compare" and argv_for(cmp)[-1] == "--model=rigid"


def test_a_log_that_cannot_be_written_is_the_sinks_own_one_line_error(tmp_path, capsys):
    where = tmp_path / "missing" / "run.mcap"
    d = RunDescription(kind="gust", wing="optimised", speed_m_s=15.0)
    with pytest.raises(sink.LogWriteError) as caught:
        sink.RunLog.open(where, d)
    assert isinstance(caught.value, OSError) and "cannot write log" in str(caught.value)
    assert main(["gust", "--duration", "0.1", "--gust-start", "0.05", "--models", "rigid",
                 "--out", str(where), "--json"]) == 2
    err = capsys.readouterr().err  # the command refuses it before flying (one line too)
    assert len(err.strip().splitlines()) == 1 and "does not exist" in err, err


SINK_AND_LOG_COMMANDS = [*sorted((ROOT / "bioflex_jsb" / "sinks" / "mcap").glob("*.py")),
                         *(ROOT / "bioflex_jsb" / "cli" / f"{m}.py"
                           for m in ("gust", "compare", "rerun", "info", "plot")),
                         ROOT / "bioflex_jsb" / "sweep" / "evaluate.py"]


@pytest.mark.parametrize("path", SINK_AND_LOG_COMMANDS, ids=lambda p: p.name)
def test_no_blanket_except_and_the_sink_knows_no_cli(path):
    import re

    text = path.read_text()
    assert not re.search(r"except\s*(\(\s*)?(Base)?Exception\b|except\s*:", text), path
    if "sinks" in path.parts:
        assert "bioflex_jsb.cli" not in text and "UsageError" not in text \
            and not re.search(r"^\s*(import|from) argparse", text, re.M), path
