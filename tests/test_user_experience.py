"""What a new user meets (issue 18): honest outputs, readable plots, working instructions, no
traceback. One test (or parameter case) per item of the issue this module covers."""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.cli import build_parser, main
from bioflex_jsb.flight_dynamics import eigen
from bioflex_jsb.flight_dynamics.lti import build_state_space, thrust_speed_derivative_n_s_m
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.flight_dynamics.wing_model import (
    build_wing,
    get_variant,
    load_variant_file,
)
from bioflex_jsb.parameters.airframe import AIRSPEED_RANGE_M_S, MASS_PROPERTIES, PROTOTYPE_AIRFRAME
from bioflex_jsb.simulation.results import TimeHistory, gust_metrics

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE_MODES = ROOT / "bioflex_jsb" / "data" / "modes" / "example_ribbed.toml"


def run_cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line(code, err, status=2):
    assert code == status, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# ---- item 1: a diverged run reads as diverged ------------------------------------------
def test_diverged_gust_run_has_null_metrics_time_and_mode(capsys, tmp_path):
    code, out, err = run_cli(capsys, "gust", "--wing", "elastic-backward", "--speed", 20,
                             "--models", "coupled", "--duration", 1.0, "--no-log", "--json")
    assert code == 3
    data = json.loads(out)
    m = data["summary"]["coupled"]
    assert m["diverged"] is True and data["diverged"] == ["coupled"]
    for key in ("peak_du_m_s", "peak_dalpha_rad", "peak_dq_rad_s", "peak_dtheta_rad",
                "peak_dn_z", "overshoot", "settling_time_s"):
        assert m[key] is None, key
    assert 0.2 < m["divergence_time_s"] < 0.5 and m["divergence_mode"] == "aeroelastic_1"
    code, out, err = run_cli(capsys, "gust", "--wing", "elastic-backward", "--speed", 20,
                             "--models", "coupled", "--duration", 1.0, "--no-log",
                             "--plot", tmp_path / "d.png")
    assert code == 3 and "diverged at t = 0.3" in out and "0.000" not in out
    assert (tmp_path / "d.png").stat().st_size > 10_000


def test_diverged_compare_reports_no_nrmse(capsys):
    code, out, _ = run_cli(capsys, "compare", "--wing", "elastic-backward", "--speed", 20,
                           "--duration", 1.0, "--no-log", "--json")
    data = json.loads(out)
    assert code == 3 and data["diverged"] is True
    assert all(v is None for v in data["nrmse"].values())


def test_metrics_unit_diverged_and_turbulence():
    t = np.arange(0.0, 4.0, 0.01)
    ch = {"u": 0.1 * np.sin(t), "alpha": 0.02 * np.sin(7 * t) * (t > 0.5),
          "q": 0.1 * np.cos(7 * t), "theta": 0.01 * t, "n_z": 1.0 + 0.1 * np.sin(5 * t)}
    turb = TimeHistory("coupled", t, ch, {}, {"gust": "dryden:1:50:3"})
    m = gust_metrics(turb, 0.5)
    assert m.kind == "turbulence" and m.overshoot is None and m.settling_time_s is None
    assert m.rms_dalpha_rad == pytest.approx(0.02 / np.sqrt(2), rel=0.05)
    sharp = TimeHistory("coupled", t, ch, {}, {"gust": "sharp:3"})
    assert gust_metrics(sharp, 0.5).overshoot is not None
    stopped = TimeHistory("coupled", t, ch, {}, {"gust": "sharp:3"},
                          stopped="mode aeroelastic_2 diverged: |eta2| = 0.6 rad at t = 3.99 s")
    d = gust_metrics(stopped, 0.5)
    assert d.diverged and d.peak_dn_z is None and d.divergence_mode == "aeroelastic_2"
    assert d.divergence_time_s == pytest.approx(t[-1])
    assert all(isinstance(v, float | type(None)) for v in d.as_dict().values())  # table-safe


# ---- item 2: own FE modes on the first try ----------------------------------------------
def docs_example(tmp_path) -> str:
    """The variant file of docs/wing_variants.md ("Your own FE modes, end to end"), verbatim."""
    text = (ROOT / "docs" / "wing_variants.md").read_text(encoding="utf-8")
    block = text.split("```toml\n# my_wing.toml\n", 1)[1].split("```", 1)[0]
    (tmp_path / "example_ribbed.toml").write_bytes(EXAMPLE_MODES.read_bytes())
    return block


def own_modes_variant(tmp_path, extra=""):
    f = tmp_path / "my_wing.toml"
    f.write_text(docs_example(tmp_path) + extra)
    return f


def test_own_fe_modes_example_inherits_the_pin_and_flies(capsys, tmp_path, monkeypatch):
    """The docs/wing_variants.md example, run as the docs say (in the file's folder)."""
    f = own_modes_variant(tmp_path)
    v = load_variant_file(f)
    assert v.pinned_c_eta1_q1 == get_variant("original").pinned_c_eta1_q1
    assert eigen.find_flutter(build_wing(v).model).flutter_speed_m_s is None
    monkeypatch.chdir(tmp_path)
    code, out, err = run_cli(capsys, "modes", "--wing", "my_wing.toml", "--speed", "15")
    assert code == 0 and "UNSTABLE" not in out, err
    code, out, err = run_cli(capsys, "gust", "--wing", "my_wing.toml")
    assert code == 0, err
    assert "diverged" not in out and (tmp_path / "gust.png").is_file()


@pytest.mark.parametrize("extra, needle", [
    ("x_elastic_frac = 0.3\n", "has no effect with 'modes_file'"),
    ("ribs = false\n", "has no effect with 'modes_file'"),
    ("pin_c_eta1_q1 = true\n", "finite number or 'physical'"),
])
def test_own_modes_ambiguities_are_refused(capsys, tmp_path, extra, needle):
    code, _, err = run_cli(capsys, "modes", "--wing", own_modes_variant(tmp_path, extra))
    assert needle in one_line(code, err)


def test_moved_axes_need_an_explicit_pin(capsys, tmp_path):
    f = tmp_path / "aft.toml"
    f.write_text('base = "original"\nx_elastic_frac = 0.3\n')
    code, _, err = run_cli(capsys, "modes", "--wing", f)
    line = one_line(code, err)
    assert "pin_c_eta1_q1 = -0.03" in line and '"physical"' in line
    f.write_text('base = "original"\nx_elastic_frac = 0.3\npin_c_eta1_q1 = "physical"\n')
    assert load_variant_file(f).pinned_c_eta1_q1 is None


def test_damping_rule_is_the_larger_value(tmp_path):
    f = own_modes_variant(tmp_path, "structural_damping = 0.03\n")
    assert np.all(build_wing(load_variant_file(f)).model.damping_ratios == 0.03)


# ---- item 4: bad inputs: exit 2, one line -----------------------------------------------
@pytest.mark.parametrize("argv, needle", [
    (["gust", "--plot", "x.txt", "--no-log"], "cannot write .txt"),
    (["modes", "--plot", "x.txt"], "cannot write .txt"),
    (["compare", "--plot", "x.txt", "--no-log"], "cannot write .txt"),
    (["gust", "--duration", "1e9", "--no-log"], "too long"),
    (["compare", "--duration", "1e9", "--no-log"], "too long"),
    (["gust", "--duration", "6000", "--dt", "1e-4", "--no-log"], "steps"),
    (["gust", "--dt", "1e-5", "--no-log"], "outside 0.0001..0.02 s"),
    (["gust", "--speed", "110", "--no-log"], "outside 5..40 m/s"),
    (["modes", "--speed", "1e6"], "outside 5..40 m/s"),
    (["modes", "--speed", "0.001"], "outside 5..40 m/s"),
    (["export", "--speed", "1e6", "--out", "m.npz"], "outside 5..40 m/s"),
    (["rerun", "x.mcap", "--out", "y.mcap", "--rtol", "-1"], "0 <= rtol < 1"),
    (["rerun", "x.mcap", "--out", "y.mcap", "--rtol", "nan"], "0 <= rtol < 1"),
])
def test_bad_inputs_exit_2_with_one_line(capsys, tmp_path, monkeypatch, argv, needle):
    monkeypatch.chdir(tmp_path)
    code, _, err = run_cli(capsys, *argv)
    assert needle in one_line(code, err)
    assert not (tmp_path / "m.npz").exists()


def test_airspeed_range_in_every_help():
    lo, hi = AIRSPEED_RANGE_M_S
    text = f"{lo:g} to {hi:g} m/s"
    parser = build_parser()
    sub = next(a for a in parser._actions if a.choices and "gust" in a.choices).choices
    for name in ("gust", "compare", "modes", "export", "trim"):
        assert text in " ".join(sub[name].format_help().split()), name
    assert "as for trim" in " ".join(sub["linearize"].format_help().split())


# ---- item 5 (plots): a user's file is never replaced without --force --------------------
def test_plot_over_a_user_file_needs_force_and_ours_is_replaced(capsys, tmp_path):
    notes = tmp_path / "loci.png"
    notes.write_text("my notes")
    code, _, err = run_cli(capsys, "modes", "--plot", notes)
    assert "already exists" in one_line(code, err) and notes.read_text() == "my notes"
    assert run_cli(capsys, "modes", "--plot", notes, "--force")[0] == 0
    from bioflex_jsb.sinks.plotting import is_our_plot

    assert is_our_plot(notes)
    assert run_cli(capsys, "modes", "--plot", notes)[0] == 0  # ours: replaced without --force


# ---- item 6: one default case -----------------------------------------------------------
def test_one_default_case_everywhere():
    parser = build_parser()
    for argv in (["gust"], ["compare"], ["modes"], ["export", "--out", "m.npz"]):
        args = parser.parse_args(argv)
        assert args.wing == "optimised", argv
        speed = args.speed[0] if isinstance(args.speed, list) else (args.speed or 15.0)
        assert speed == 15.0, argv
        if hasattr(args, "gust"):
            assert args.gust.text() == "sharp:3", argv
    assert parser.parse_args(["trim"]).speed == 15.0


# ---- item 7: metrics a reader can interpret ---------------------------------------------
def test_unstable_real_root_is_not_a_short_period(capsys):
    code, out, _ = run_cli(capsys, "modes", "--wing", "elastic-backward", "--speed", 20,
                           "--json")
    data = json.loads(out)
    for res in data["results"]:
        for m in res["modes"]:
            if m["mode"] == "short_period":
                assert m["re"] < 0.0 and m["stable"]
            if m["re"] > 0.0:
                assert m["stable"] is False
    qsd = next(r for r in data["results"] if r["model"] == "qsd")
    div = next(m for m in qsd["modes"] if m["mode"] == "divergence")
    assert div["branch"] == "short_period" and div["im"] == 0.0 and div["re"] > 30.0
    assert data["unstable"]
    code, out, _ = run_cli(capsys, "modes", "--wing", "elastic-backward", "--speed", 20)
    assert "UNSTABLE (real root of the short_period branch)" in out


def test_compare_table_has_units_per_channel(capsys):
    code, out, _ = run_cli(capsys, "compare", "--gust", "sharp:0.3", "--duration", 1.0,
                           "--no-log")
    rows = {ln.split()[0]: ln.split() for ln in out.splitlines() if ln.split()}
    assert code == 0
    assert rows["u"][3] == "m/s" and rows["alpha"][3] == "deg" and rows["q"][3] == "deg/s"


def test_turbulence_table_has_rms_not_settling(capsys):
    code, out, _ = run_cli(capsys, "gust", "--gust", "dryden:1:50:3", "--duration", 2.0,
                           "--models", "rigid", "--no-log", "--plot", "")
    assert code == 0 and "rms Δα [deg]" in out and "settling" not in out.splitlines()[1]


def test_linearize_explains_the_phugoid_and_prints_b(capsys):
    code, out, _ = run_cli(capsys, "linearize", "--speed", 15, "--json")
    data = json.loads(out)
    c = data["phugoid_comparison"]
    # the whole X_u difference is the propeller's dT/dV, which Table B2 leaves out
    assert c["jsbsim_x_u_1_s"] - c["analytic_x_u_1_s"] == pytest.approx(
        c["thrust_term_1_s"], abs=2e-3)
    assert c["thrust_term_1_s"] == pytest.approx(
        thrust_speed_derivative_n_s_m(level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME))
        / MASS_PROPERTIES.mass_kg)
    assert np.array(data["B"]).shape == (4, 3)
    code, out, _ = run_cli(capsys, "linearize", "--speed", 15)
    assert "B, u = [w_g" in out and "dT/dV" in out


# ---- item 8: the exported model ---------------------------------------------------------
def test_export_has_controls_outputs_metadata_and_reads_back(capsys, tmp_path):
    from bioflex_jsb.sinks.model_export import read_state_space

    for suffix in (".npz", ".mat"):
        path = tmp_path / f"m{suffix}"
        assert run_cli(capsys, "export", "--out", path)[0] == 0
        ss = read_state_space(path)
        assert ss.inputs == ("w_g", "elevator", "throttle")
        assert ss.input_units == ("m/s", "rad", "-")
        assert ss.outputs[-2:] == ("n_z", "tip_twist") and ss.output_units[-2:] == ("-", "rad")
        for key in ("wing", "speed_m_s", "mass_basis", "aerodynamics"):
            assert key in ss.notes, key
        assert ss.notes["wing"] == "optimised" and ss.notes["mass_basis"] == "consistent"
    # n_z = u0 (q - alpha_dot)/g, as the co-simulation's channel; elevator nose down
    cond = level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME)
    full = build_state_space("coupled", cond, build_wing(get_variant("optimised")).model,
                             controls=True)
    x = np.random.default_rng(1).normal(size=full.n_states)
    u = np.array([1.0, 0.02, 0.1])
    xdot = full.a @ x + full.b @ u
    y = full.c @ x + full.d @ u
    iq, ia = full.states.index("q"), full.states.index("alpha")
    assert y[full.outputs.index("n_z")] == pytest.approx(15.0 * (x[iq] - xdot[ia]) / 9.80665)
    assert full.b[iq, 1] < 0.0 and full.b[0, 2] > 0.0  # + elevator: nose down; throttle: thrust


def test_to_python_control_accepts_the_exported_file(capsys, tmp_path):
    control = pytest.importorskip("control")
    from bioflex_jsb.sinks.model_export import to_python_control

    path = tmp_path / "m.npz"
    assert run_cli(capsys, "export", "--out", path)[0] == 0
    for model in (path, str(path), np.load(path)):
        sys_ = to_python_control(model)
        assert isinstance(sys_, control.StateSpace)
        assert list(sys_.input_labels) == ["w_g", "elevator", "throttle"]


# ---- item 9: figures --------------------------------------------------------------------
def test_figures_carry_our_tag_and_draw_diverged_runs(tmp_path):
    from bioflex_jsb.sinks import plotting

    t = np.arange(0.0, 2.0, 0.001)
    ok = TimeHistory("rigid", t, {c: 0.01 * np.sin(3 * t) for c in
                                   ("u", "alpha", "q", "theta", "eta1")} | {
        "n_z": 1 + 0.1 * np.sin(3 * t), "w_g": 3.0 * (t > 0.5)}, {}, {"gust": "sharp:3",
                                                                     "gust_start_s": 0.5})
    bad = ok.truncated(300)
    bad.model, bad.stopped = "coupled", "mode aeroelastic_1 diverged at t = 0.299 s"
    bad.channels["eta1"] = np.exp(np.linspace(0, 20, 300))
    out = plotting.time_histories([ok, bad], tmp_path / "h.png", "title")
    assert plotting.is_our_plot(out) and not plotting.is_our_plot(tmp_path / "none.png")
    sweep = eigen.track("qsd", np.arange(5.0, 25.0, 0.5),
                        build_wing(get_variant("elastic-backward")).model)
    assert plotting.is_our_plot(plotting.root_locus([sweep], tmp_path / "l.png", "t"))


# ---- item 10: progress bars under a pseudo-terminal -------------------------------------
@pytest.mark.slow
def test_progress_bar_under_a_pty(tmp_path):
    import pty

    argv = [sys.executable, "-m", "bioflex_jsb", "gust", "--duration", "30", "--models",
            "rigid", "--no-log", "--plot", ""]
    pid, fd = pty.fork()
    if pid == 0:  # child: the command on the pseudo-terminal
        os.chdir(tmp_path)
        os.execv(sys.executable, argv)
    seen, deadline = b"", time.monotonic() + 300
    while time.monotonic() < deadline:
        ready, _, _ = select.select([fd], [], [], 1.0)
        if not ready:
            continue
        try:
            chunk = os.read(fd, 65536)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        seen += chunk
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0, seen[-500:]
    assert b"optimised rigid" in seen and b"step/s" in seen, seen[:500]


def test_no_progress_bar_without_a_terminal(tmp_path):
    done = subprocess.run([sys.executable, "-m", "bioflex_jsb", "gust", "--duration", "1",
                           "--models", "rigid", "--no-log", "--plot", ""], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "step/s" not in done.stderr


def test_plot_of_a_log_never_replaces_a_users_file(tmp_path, capsys):
    """`plot run.mcap` writes run.png beside the log: a file of the user's there is refused
    (exit 2, one line) unless --force; a figure bioflex-jsb drew may be redrawn."""
    from bioflex_jsb.cli import main

    log = tmp_path / "r.mcap"
    assert main(["gust", "--duration", "1", "--models", "rigid", "--out", str(log), "--json",
                 "--plot", ""]) == 0
    capsys.readouterr()
    png = tmp_path / "r.png"
    png.write_text("the user's notes")
    assert main(["plot", str(log)]) == 2
    err = capsys.readouterr().err
    assert "--force" in err and err.count("\n") == 1
    assert png.read_text() == "the user's notes"
    assert main(["plot", str(log), "--out", str(tmp_path / "r.txt")]) == 2
    capsys.readouterr()
    assert main(["plot", str(log), "--force"]) == 0
    assert main(["plot", str(log)]) == 0  # now ours: redrawn without --force
