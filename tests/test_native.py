"""The modal wing exported as JSBSim systems (bioflex_jsb.adapters.jsbsim_export)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.adapters import jsbsim_export as J
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing

REPO = Path(__file__).resolve().parents[1]


def test_repository_files_are_up_to_date():
    """systems/, aircraft/bioflex_<variant>/ and the Fig. 21 script are the exporter's output."""
    stale = [rel for rel, text in J.repository_files().items()
             if not (REPO / rel).is_file() or (REPO / rel).read_text(encoding="utf-8") != text]
    assert not stale, f"regenerate with python -m bioflex_jsb.adapters.jsbsim_export: {stale}"


@pytest.mark.parametrize("dt_s", [1.0 / 480.0, 1.0 / 120.0])
def test_discrete_step_is_exact_and_stable_at_the_third_mode(dt_s):
    wing = build_wing(VARIANTS["optimised"]).model
    nums = J.modal_numbers(wing, 0.5)
    assert nums.omega[2] * dt_s > 1.0  # explicit schemes would be at or past their limit
    assert J.spectral_radius_max(nums, dt_s) < 1.0
    # the table rows are e^{A dt}: one step of the free structure matches the analytic mode
    phi, _ = nums.discrete(0.0, 0.0, dt_s)
    w, z = nums.omega[2], nums.zeta[2]
    lam = -z * w + 1j * w * np.sqrt(1 - z**2)
    eig = np.linalg.eigvals(phi)
    assert np.min(np.abs(eig - np.exp(lam * dt_s))) < 1e-9


def test_exported_aircraft_loads_in_jsbsim_without_warnings():
    from bioflex_jsb.adapters.jsbsim_fdm import Airframe

    af = Airframe(root=REPO, aircraft=J.aircraft_name("original"))
    assert af.warnings == []
    assert af["bioflex/modal/enabled"] == 1.0


@pytest.mark.parametrize("variant, amplitude", [
    ("original", 0.3), ("optimised", 0.3), ("original", 3.0), ("optimised", 3.0)])
def test_native_xml_matches_the_cosimulation(variant, amplitude):
    """Same sharp gust at 15 m/s, 3 s: native XML vs Python co-simulation. At 3 m/s (Fig. 21)
    Q moves by more than 5 %: both renew their reference flow the same way."""
    from bioflex_jsb.adapters.cosim import RunSetup, run_gust
    from bioflex_jsb.adapters.jsbsim_fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import nrmse

    wing = build_wing(VARIANTS[variant]).model
    setup = RunSetup(15.0, parse_gust(f"sharp:{amplitude}"), duration_s=3.0)
    ref = run_gust(Airframe(), wing, "coupled", setup)
    nat = J.run_native_gust(Airframe(root=REPO, aircraft=J.aircraft_name(variant)), setup)
    assert ref.stopped is None
    errors = {c: nrmse(ref.channels[c], nat.channels[c])
              for c in ("u", "alpha", "q", "theta", "eta1")}
    assert max(errors.values()) < 0.01, errors
    # and the wing matters: the rigid airframe of the same file is far off
    rigid = Airframe(root=REPO, aircraft=J.aircraft_name(variant))
    rigid["bioflex/modal/enabled"] = 0.0
    flat = J.run_native_gust(rigid, setup)
    assert nrmse(ref.channels["q"], flat.channels["q"]) > 0.05


def test_in_place_step_equals_the_matrix_step():
    rng = np.random.default_rng(1)
    phi = np.eye(6) + 0.05 * rng.normal(size=(6, 6))
    psi = rng.normal(size=(6, 3))
    x, g = rng.normal(size=6), rng.normal(size=3)
    c, d = J.in_place_step(phi, psi)
    v = x.copy()
    for k in range(6):
        v[k] = c[k] @ v + d[k] @ g
    np.testing.assert_allclose(v, phi @ x + psi @ g, rtol=0, atol=1e-12)


def test_fig21_script_runs_in_the_console_program(tmp_path):
    """``jsbsim --script=scripts/fig21_native.xml``: no JSBSim trim (the Python trim as the
    initial condition, the airframe held while the propellers spin up), the modal wing
    active, η1 and q as the co-simulation's of the same case."""
    import csv
    import shutil
    import subprocess
    import sys

    from bioflex_jsb.adapters.cosim import RunSetup, run_gust
    from bioflex_jsb.adapters.jsbsim_fdm import Airframe
    from bioflex_jsb.parameters import prototype as P
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


def test_bench_native_times_a_step():
    us = J.bench_native(200)
    assert np.isfinite(us) and us > 0.0


def _cli(argv):
    from bioflex_jsb import cli

    modules = cli.COMMAND_MODULES
    if "export_jsbsim" not in modules:
        cli.COMMAND_MODULES = modules + ("export_jsbsim",)
    try:
        return cli.main(argv)
    finally:
        cli.COMMAND_MODULES = modules


def test_cli_writes_a_loadable_root(tmp_path, capsys):
    from bioflex_jsb.adapters.jsbsim_fdm import Airframe

    assert _cli(["export-jsbsim", "--wing", "elastic-forward", "--model", "qsd",
                 "--out", str(tmp_path), "--json"]) == 0
    assert '"aircraft": "bioflex_elastic-forward_qsd"' in capsys.readouterr().out
    af = Airframe(root=tmp_path, aircraft="bioflex_elastic-forward_qsd")
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
