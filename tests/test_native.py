"""The modal wing exported as JSBSim systems (bioflex_jsb.generators.native_wing)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.drivers.native import native_airframe, repository_files
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.generators import native_wing as J

REPO = Path(__file__).resolve().parents[1]


def test_repository_files_are_up_to_date():
    """systems/, aircraft/bioflex_<variant>/ and the Fig. 21 script are the exporter's output."""
    stale = [rel for rel, text in repository_files().items()
             if not (REPO / rel).is_file() or (REPO / rel).read_text(encoding="utf-8") != text]
    assert not stale, f"regenerate with python -m bioflex_jsb.generators.native_wing: {stale}"


def _spec(variant, **kw):
    return J.ExportSpec(build_wing(VARIANTS[variant]).model, variant, **kw)


@pytest.mark.parametrize("variant", J.REPOSITORY_VARIANTS)
def test_coupled_step_is_within_1_percent_of_the_exact_dynamics_at_the_default_step(variant):
    spec = _spec(variant)
    nums = J.modal_matrices(spec.wing, spec.cl_trim)
    assert nums.omega[2] * spec.dt_s > 0.4  # ω₃Δt = 0.47-0.70: not over-resolved
    err, _ = J.leapfrog_eigen_error(nums, spec.leapfrog(nums))
    assert err <= J.EIGEN_REL_TOL  # 0.12-0.91 % over 0-40 m/s (docs/native.md)


def test_structure_alone_is_integrated_exactly_at_any_step():
    """No flow (Q = 0) and no aerodynamic part in the exact blocks: the step is e^{A Δt} of
    the in-vacuo modes to rounding, also at 1/120 s (ω₃ Δt = 5.6)."""
    from scipy.linalg import expm

    nums = J.modal_matrices(build_wing(VARIANTS["optimised"]).model, 0.5)
    for dt in (J.DEFAULT_DT_S, 1.0 / 120.0):
        co = J.leapfrog_coefficients(nums, dt)
        # the stored state is y = Φ_h x: compare in x
        half = np.zeros((6, 6))
        for i in range(3):
            h = np.linalg.inv(co.half_inv[i])
            half[np.ix_([i, i + 3], [i, i + 3])] = h
        step_x = np.linalg.inv(half) @ J.leapfrog_matrix(nums, co, 0.0, 0.0) @ half
        np.testing.assert_allclose(step_x, expm(nums.a_matrix(0.0, 0.0) * dt), atol=1e-9)


def test_splitting_is_second_order():
    """Halving the step divides the eigenvalue error of the coupled step by about 4
    (optimised wing at 25 m/s, away from the 15 m/s reference flow, so the modes' own
    aerodynamic terms are split too, not only the couplings)."""
    from scipy.linalg import expm

    spec = _spec("optimised")
    nums = J.modal_matrices(spec.wing, spec.cl_trim)
    q = 0.5 * spec.rho_ref * 25.0**2  # away from the reference, so the diagonal splits too
    errors = []
    for dt in (J.DEFAULT_DT_S, J.DEFAULT_DT_S / 2):
        co = spec.leapfrog(nums, dt)
        exact = np.sort_complex(np.linalg.eigvals(expm(nums.a_matrix(q, q / 25.0) * dt)))
        step = np.sort_complex(np.linalg.eigvals(J.leapfrog_matrix(nums, co, q, q / 25.0)))
        errors.append(np.max(np.abs(np.log(step) - np.log(exact))) / dt)
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.15), errors


def test_a_step_too_coarse_for_the_wing_is_refused_with_one_that_is_not():
    with pytest.raises(J.ExportError, match=r"too coarse .* 0\.00104167 s is within it"):
        _spec("optimised", dt_s=2 * J.DEFAULT_DT_S)


def test_exported_aircraft_loads_in_jsbsim_without_warnings():
    from bioflex_jsb.runtime.fdm import Airframe

    af = Airframe(root=REPO, aircraft=J.aircraft_name("original"))
    assert af.warnings == []
    assert af["bioflex/modal/enabled"] == 1.0


@pytest.mark.parametrize("variant, amplitude", [
    ("original", 0.3), ("optimised", 0.3), ("original", 3.0), ("optimised", 3.0)])
def test_native_xml_matches_the_cosimulation(variant, amplitude):
    """Same sharp gust at 15 m/s, 3 s: native XML vs Python co-simulation (measured: at most
    0.3 % for the original wing; η₁ of the optimised wing 0.72 % at 0.3 m/s, 0.75 % at 3 m/s,
    the other channels ≤ 0.53 %)."""
    from bioflex_jsb.drivers.gust import RunSetup, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import nrmse

    wing = build_wing(VARIANTS[variant]).model
    setup = RunSetup(15.0, parse_gust(f"sharp:{amplitude}"), duration_s=3.0)
    ref = run_gust(Airframe(), wing, "coupled", setup)
    nat = run_gust(Airframe(root=REPO, aircraft=J.aircraft_name(variant)), None, "native", setup)
    assert ref.stopped is None
    errors = {c: nrmse(ref.channels[c], nat.channels[c])
              for c in ("u", "alpha", "q", "theta", "eta1")}
    assert max(errors.values()) < 0.01, errors
    # and the wing matters: the rigid airframe of the same file is far off
    rigid = Airframe(root=REPO, aircraft=J.aircraft_name(variant))
    rigid["bioflex/modal/enabled"] = 0.0
    flat = run_gust(rigid, None, "native", setup)
    assert nrmse(ref.channels["q"], flat.channels["q"]) > 0.05


def test_published_modal_state_is_the_state_at_the_current_time():
    """``bioflex/modal/eta<i>`` (functions evaluated when read) are Φ_h⁻¹ of the stored
    half-step state, and the loads in the aerodynamics are those of the stored state."""
    from bioflex_jsb.runtime.fdm import Airframe

    af = Airframe(root=REPO, aircraft=J.aircraft_name("optimised"))
    af.set_dt(J.DEFAULT_DT_S)
    af.trim(15.0)
    af["atmosphere/wind-down-fps"] = -3.0
    af.run(40)
    spec = _spec("optimised")
    nums = J.modal_matrices(spec.wing, spec.cl_trim)
    co = spec.leapfrog(nums)
    for i in range(3):
        y = np.array([af[f"bioflex/modal/y-eta{i + 1}-scaled"] * co.eta_rate[i],
                      af[f"bioflex/modal/y-eta{i + 1}-dot"]])
        x = co.half_inv[i] @ y
        assert af[f"bioflex/modal/eta{i + 1}"] == pytest.approx(x[0], rel=1e-9, abs=1e-15)
        assert af[f"bioflex/modal/eta{i + 1}-dot"] == pytest.approx(x[1], rel=1e-9, abs=1e-12)
    assert abs(af["bioflex/modal/eta1"]) > 1e-4
    lift = af["aero/bioflex/modal-lift-lbs"]
    assert abs(lift) > 1e-3
    # the lift of the stored state y (η and η̇ its two parts) in this step's air data
    y_eta = np.array([af[f"bioflex/modal/y-eta{i + 1}-scaled"] for i in range(3)]) * co.eta_rate
    y_rate = np.array([af[f"bioflex/modal/y-eta{i + 1}-dot"] for i in range(3)])
    from bioflex_jsb import units as U
    from bioflex_jsb.parameters import prototype as P

    q_s = af["aero/qbar-psf"] * U.PA_PER_PSF * P.REFERENCE_AREA_M2
    ci2vel = P.MEAN_AERODYNAMIC_CHORD_M * U.FT_PER_M / (2.0 * af["velocities/vt-fps"])
    terms = q_s * np.concatenate([nums.load_eta[0] * y_eta,
                                  ci2vel * nums.load_etadot[0] * y_rate])
    # coefficients are written with 12 significant digits
    assert lift == pytest.approx(terms.sum() * U.LBF_PER_N, rel=1e-10)
    assert af["aero/force/modal-drag"] == pytest.approx(
        nums.load_eta[1, 0] / nums.load_eta[0, 0] * lift, rel=1e-9)
    af["bioflex/modal/enabled"] = 0.0
    af.run(1)
    assert af["aero/force/modal-lift"] == 0.0 and af["aero/moment/modal-pitch"] == 0.0


def test_fig21_script_runs_in_the_console_program(tmp_path):
    """``jsbsim --script=scripts/fig21_native.xml``: no JSBSim trim (the Python trim as the
    initial condition, the airframe held while the propellers spin up), the modal wing
    active, η1 and q as the co-simulation's of the same case."""
    import csv
    import shutil
    import subprocess
    import sys

    from bioflex_jsb.drivers.gust import RunSetup, run_gust
    from bioflex_jsb.parameters import prototype as P
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import nrmse

    exe = shutil.which("jsbsim") or str(Path(sys.executable).with_name("jsbsim"))
    dt = J.DEFAULT_DT_S
    proc = subprocess.run(
        [exe, f"--root={REPO}", f"--script={J.FIG21_SCRIPT}", f"--simulation-rate={1 / dt}",
         f"--outputpath={tmp_path}"],
        cwd=tmp_path, capture_output=True, text=True, timeout=20)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "Overriding simulation step size" in proc.stdout  # --simulation-rate took
    with open(tmp_path / J.FIG21_OUTPUT, newline="") as fh:
        rows = list(csv.reader(fh))
    head = [h.strip().removeprefix("/fdm/jsbsim/") for h in rows[0]]
    data = np.array(rows[1:], dtype=float)
    col = {h: data[:, i] for i, h in enumerate(head)}
    t = col["Time"]
    assert t[-1] >= J.FIG21_SETTLE_S + J.FIG21_DURATION_S - 2 * dt
    flying = t >= J.FIG21_SETTLE_S
    assert np.all(col["bioflex/modal/active"][flying] == 1.0)
    setup = RunSetup(P.SECTION5_AIRSPEED_M_S, parse_gust(f"sharp:{P.SECTION5_GUST_AMPLITUDE_M_S}"),
                     duration_s=J.FIG21_DURATION_S, gust_start_s=J.FIG21_GUST_START_S, dt_s=dt)
    ref = run_gust(Airframe(), build_wing(VARIANTS[J.FIG21_VARIANT]).model, "coupled", setup)
    assert ref.stopped is None
    # alignment (measured, not fitted per run): the row stamped settle + t − dt holds the
    # state the co-simulation samples at t (one row later NRMSE is ≈ 14 % on η1)
    at = J.FIG21_SETTLE_S + ref.time_s - dt
    eta1 = np.interp(at, t, col["bioflex/modal/eta1"])
    q = np.interp(at, t, col["velocities/q-rad_sec"])
    errors = {"eta1": nrmse(ref.channels["eta1"], eta1), "q": nrmse(ref.channels["q"], q)}
    assert max(errors.values()) < 0.01, errors
    assert np.max(np.abs(eta1)) > 0.01  # the wing flexed


def test_native_airframe_is_loaded_once_at_the_exported_step():
    af = native_airframe("optimised")
    assert native_airframe("optimised") is af
    assert af.dt_s == pytest.approx(J.DEFAULT_DT_S)


def _cli(argv):
    from bioflex_jsb import cli

    modules = cli.COMMAND_MODULES
    if "export_jsbsim" not in modules:
        cli.COMMAND_MODULES = modules + ("export_jsbsim",)
    try:
        return cli.main(argv)
    finally:
        cli.COMMAND_MODULES = modules


@pytest.mark.parametrize("model, craft", [("qsd", "bioflex_elastic-forward_qsd"),
                                          ("coupled", "bioflex_elastic-forward")])
def test_cli_writes_a_loadable_root(tmp_path, capsys, model, craft):
    import json

    from bioflex_jsb.runtime.fdm import Airframe

    assert _cli(["export-jsbsim", "--wing", "elastic-forward", "--model", model,
                 "--out", str(tmp_path), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["aircraft"] == craft
    if model == "coupled":
        assert 0.0 < info["eigenvalue_error_max"] <= J.EIGEN_REL_TOL
    af = Airframe(root=tmp_path, aircraft=craft)
    assert af.warnings == []
    af.set_dt(J.DEFAULT_DT_S)
    trim = af.trim(15.0)
    af["atmosphere/wind-down-fps"] = -1.0
    af.run(50)
    assert af["bioflex/modal/active"] == 1.0
    assert abs(af["bioflex/modal/eta1"]) > 1e-4
    assert abs(af["bioflex/modal/alpha0-rad"] - trim.alpha_rad) < 1e-9


@pytest.mark.parametrize("argv, words", [
    (["--wing", "no-such-wing"], "unknown wing"),
    (["--dt", "0"], "time step"),
    (["--wing", "optimised", "--dt", "0.0025"], "too coarse"),
])
def test_cli_bad_input_exits_2_with_one_line(tmp_path, capsys, argv, words):
    assert _cli(["export-jsbsim", "--out", str(tmp_path), *argv]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1


@pytest.mark.skipif(os.geteuid() == 0, reason="root can write anywhere")
def test_cli_unwritable_directory_exits_2(tmp_path, capsys):
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        assert _cli(["export-jsbsim", "--wing", "original", "--out", str(locked / "x")]) == 2
    finally:
        locked.chmod(0o700)
    err = capsys.readouterr().err
    assert "cannot write" in err and err.count("\n") == 1
