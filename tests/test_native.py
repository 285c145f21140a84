"""The modal wing exported as JSBSim systems (bioflex_jsb.generators.native_wing)."""

from __future__ import annotations

import csv
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb.drivers.native import native_airframe, repository_files
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.generators import native_aircraft as NA
from bioflex_jsb.generators import native_wing as J
from bioflex_jsb.generators.xml_writer import number_difference
from tests.golden_cases import BUILT_WING_RTOL_OF_RANGE, channel_error

REPO = Path(__file__).resolve().parents[1]
DOCS = REPO / "docs" / "native.md"
# A console run takes well under a second; this only stops a hung one.
CONSOLE_TIMEOUT_S = 120
# The repository's native files against the exporter's output on this processor, by value
# (docs/validation.md, "Platform spread and golden tolerances"): at most 3.5e-12 of a number
# measured (scripts/platform_spread.py, OpenBLAS SandyBridge kernels; the files print 12
# significant digits, so a last printed digit is 5e-12 of a number), after the beam's
# eigenproblem became the inverted pencil (before: 3.7e-5, the wing's modes moving with the
# eigen-solver's platform noise). 1e-8 leaves three decades for an unmeasured BLAS and is 1e5
# times below what a 0.1 % change of one Table B1 derivative does to the numbers it enters
# (1e-3: a stale file is seen).
NATIVE_FILE_RTOL = 1e-8


def _exe(name: str) -> str:
    """A console program of this environment: beside the interpreter, never from PATH."""
    path = Path(sys.executable).with_name(name)
    assert path.is_file(), f"{name} is not installed beside {sys.executable}"
    return str(path)


def _documented(prefix: str) -> list[str]:
    """The commands of docs/native.md that start with ``prefix`` (indented code lines)."""
    lines = [m.group(1) for m in re.finditer(r"^    (\S.*)$", DOCS.read_text(encoding="utf-8"),
                                             re.MULTILINE)]
    found = [line for line in lines if line.startswith(prefix)]
    assert found, f"docs/native.md documents no command starting with {prefix!r}"
    return found


def _run(command: str, cwd: Path, **placeholders: str) -> subprocess.CompletedProcess:
    """Run a documented command as written, its placeholders (whole words: DIR, REPO, ...)
    replaced, its program taken from beside the interpreter."""
    argv = shlex.split(command)
    for name, value in placeholders.items():
        argv = [re.sub(rf"\b{re.escape(name)}\b", lambda _m, v=value: v, a) for a in argv]
    proc = subprocess.run([_exe(argv[0]), *argv[1:]], cwd=cwd, capture_output=True, text=True,
                          timeout=CONSOLE_TIMEOUT_S)
    assert proc.returncode == 0, (argv, proc.stdout[-2000:], proc.stderr[-2000:])
    return proc


def _read_csv(path: Path) -> dict[str, np.ndarray]:
    """The console program's CSV: column caption → values."""
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    data = np.array(rows[1:], dtype=float)
    return {h.strip(): data[:, i] for i, h in enumerate(rows[0])}


CAPTIONS = ["Time", "vt [ft/s]", "u [ft/s]", "w [ft/s]", "q [rad/s]", "theta [rad]",
            "alpha [rad]", "wind_down [ft/s]", "rpm [rev/min]", "eta1 [rad]", "eta2 [rad]",
            "eta3 [rad]", "active [-]"]


def _stale(files: dict[str, str], root: Path = REPO) -> dict[str, float | None]:
    """The files of ``files`` (path → text) that ``root`` does not hold to within
    NATIVE_FILE_RTOL: path → the largest relative change of a number (None: other text
    between the numbers, or no such file)."""
    out = {}
    for rel, text in files.items():
        path = root / rel
        diff = number_difference(path.read_text(encoding="utf-8"), text) if path.is_file() else None
        if diff is None or diff > NATIVE_FILE_RTOL:
            out[rel] = diff
    return out


def test_repository_files_are_up_to_date():
    """systems/, aircraft/bioflex_<variant>/ and the Fig. 21 script are the exporter's output,
    by value (NATIVE_FILE_RTOL)."""
    stale = _stale(repository_files())
    assert not stale, f"regenerate with python -m bioflex_jsb.drivers.native: {stale}"


def test_files_are_compared_by_the_numbers_and_the_text_between_them():
    assert number_difference('<v a="2">1.5e-3</v>', '<v a="2">1.5000003e-3</v>') == (
        pytest.approx(2e-7))
    assert number_difference("<v>0</v>", "<v>0</v>") == 0.0
    assert number_difference("<v>0</v>", "<v>1e-30</v>") == float("inf")
    assert number_difference("<v>1</v>", "<w>1</w>") is None  # another structure
    assert number_difference("<v>1</v>", "<v>1 2</v>") is None  # another count of numbers


@pytest.mark.parametrize("key", ["C_eta1^Q1", "C_L_eta1", "C_etadot1^Q3"])
def test_a_file_of_a_0_1_percent_different_wing_is_stale(key):
    """The value comparison still sees a physics change: 0.1 % on one Table B1 derivative
    changes the numbers it enters by 1e-3 (measured 9.93e-4 to 1.0e-3: 3.3 times
    NATIVE_FILE_RTOL)."""
    import dataclasses

    from bioflex_jsb.flight_dynamics.modal_coefficients import parse_override_key

    wing = build_wing(VARIANTS["optimised"]).model
    attr, index = parse_override_key(key, wing.n_modes)
    value = float(np.asarray(getattr(wing.coefficients, attr))[index])
    changed = dataclasses.replace(
        wing, coefficients=wing.coefficients.with_overrides({key: 1.001 * value}))
    files = NA.render_aircraft_files(J.ExportSpec(changed, "optimised"), include_shared=False)
    stale = _stale(files)
    assert stale and all(v is not None and v > 3 * NATIVE_FILE_RTOL for v in stale.values()), stale


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
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import nrmse

    wing = build_wing(VARIANTS[variant]).model
    setup = RunConfig(15.0, parse_gust(f"sharp:{amplitude}"), duration_s=3.0)
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


def test_published_modal_state_is_the_state_at_the_current_time(tmp_path):
    """``bioflex/modal/eta<i>`` (functions evaluated when read) are Φ_h⁻¹ of the stored
    half-step state, and the loads in the aerodynamics are those of the stored state."""
    from bioflex_jsb.runtime.fdm import Airframe

    # the aircraft exported here from the wing built here, so that the XML's coefficients and
    # the spec below come from the same eigen-solution (the repository's files hold the
    # recording machine's, within NATIVE_FILE_RTOL of this one's: issue 22)
    spec = _spec("optimised")
    root = tmp_path / "root"
    NA.export(spec, root)
    af = Airframe(root=root, aircraft=J.aircraft_name("optimised"))
    af.set_dt(J.DEFAULT_DT_S)
    af.trim(15.0)
    af["atmosphere/wind-down-fps"] = -3.0
    af.run(40)
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


@pytest.fixture(scope="module")
def fig21_console_csv(tmp_path_factory) -> dict[str, np.ndarray]:
    """The documented Fig. 21 command of docs/native.md, run as written (REPO, OUTDIR: an
    absolute directory), from another working directory."""
    (command,) = _documented("jsbsim --root=REPO --script=scripts/fig21_native.xml")
    out = tmp_path_factory.mktemp("fig21_out")
    cwd = tmp_path_factory.mktemp("elsewhere")
    proc = _run(command, cwd, REPO=str(REPO), OUTDIR=str(out))
    assert "Overriding simulation step size" in proc.stdout  # --simulation-rate took
    assert "bioflex: stopped" not in proc.stdout
    return _read_csv(out / J.FIG21_OUTPUT)


def test_fig21_script_runs_in_the_console_program(fig21_console_csv):
    """No JSBSim trim (the Python trim as the initial condition, the airframe held while the
    propellers spin up), the modal wing active, η1 and q as the co-simulation's of the same
    case, the columns as docs/native.md lists them."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.parameters import prototype as P
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust
    from bioflex_jsb.simulation.results import nrmse

    col = fig21_console_csv
    assert list(col) == CAPTIONS
    docs = DOCS.read_text(encoding="utf-8")
    assert all(f"| `{c}` |" in docs for c in CAPTIONS)  # every column explained
    dt = J.DEFAULT_DT_S
    t = col["Time"]
    assert t[-1] >= J.FIG21_SETTLE_S + J.FIG21_DURATION_S - 2 * dt
    assert np.all(col["active [-]"][1:] == 1.0)
    setup = RunConfig(P.SECTION5_AIRSPEED_M_S, parse_gust(f"sharp:{P.SECTION5_GUST_AMPLITUDE_M_S}"),
                     duration_s=J.FIG21_DURATION_S, gust_start_s=J.FIG21_GUST_START_S, dt_s=dt)
    ref = run_gust(Airframe(), build_wing(VARIANTS[J.FIG21_VARIANT]).model, "coupled", setup)
    assert ref.stopped is None
    # alignment (measured, not fitted per run): the row stamped settle + t − dt holds the
    # state the co-simulation samples at t (one row later NRMSE is ≈ 14 % on η1)
    at = J.FIG21_SETTLE_S + ref.time_s - dt
    eta1 = np.interp(at, t, col["eta1 [rad]"])
    q = np.interp(at, t, col["q [rad/s]"])
    errors = {"eta1": nrmse(ref.channels["eta1"], eta1), "q": nrmse(ref.channels["q"], q)}
    assert max(errors.values()) < 0.01, errors
    assert np.max(np.abs(eta1)) > 0.01  # the wing flexed


def test_documented_export_flies_in_the_console_program(tmp_path, fig21_console_csv):
    """docs/native.md's two lines (export, then the console program), run as written from
    one working directory with a relative DIR: the exported optimised wing at the default
    15 m/s and gust is the Fig. 21 flight, row for row."""
    (export,) = _documented("bioflex-jsb export-jsbsim --wing")
    (fly,) = _documented("jsbsim --root=DIR ")
    out = _run(export, tmp_path, DIR="flight").stdout
    root = (tmp_path / "flight").resolve()
    assert f"fly it: jsbsim --root={root} " in out  # the printed command: absolute root
    proc = _run(fly, tmp_path, DIR="flight")
    assert "bioflex: stopped" not in proc.stdout
    col = _read_csv(root / "bioflex_optimised.csv")
    assert list(col) == CAPTIONS
    np.testing.assert_array_equal(col["Time"], fig21_console_csv["Time"])
    # row for row within the golden cases' tolerance for a wing built on another processor
    # (the export is this machine's wing, the repository's files the recording machine's)
    errors = {name: channel_error(name, fig21_console_csv[name], col[name])
              for name in CAPTIONS[1:]}
    assert max(errors.values()) <= BUILT_WING_RTOL_OF_RANGE, errors
    # and the exported aircraft and system are the repository's, by value
    rels = ["aircraft/bioflex_optimised/bioflex_optimised.xml",
            "systems/bioflex_modal_optimised.xml"]
    stale = _stale({rel: (root / rel).read_text(encoding="utf-8") for rel in rels})
    assert not stale, stale


def test_the_command_of_the_help_flies_the_export(tmp_path, capsys):
    """``export-jsbsim --help``'s command, DIR and <wing> filled in, flies an export."""
    assert _cli(["export-jsbsim", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    (command,) = re.findall(r"`(jsbsim [^`]+)`", text)
    assert "--simulation-rate=960" in command
    assert _cli(["export-jsbsim", "--wing", "elastic-forward", "--out", str(tmp_path / "x")]) == 0
    printed = capsys.readouterr().out
    command = command.replace("<wing>", "elastic-forward")
    assert f"fly it: {command.replace('DIR', str((tmp_path / 'x').resolve()))}\n" in printed
    _run(command, tmp_path, DIR="x")
    col = _read_csv(tmp_path / "x" / "bioflex_elastic-forward.csv")
    assert np.all(col["active [-]"][1:] == 1.0) and np.max(np.abs(col["eta1 [rad]"])) > 1e-3


def test_a_run_at_another_step_stops_at_once_with_a_message(tmp_path):
    """Without --simulation-rate the wheel's console program runs at 1/120 s, where the wing
    would be rigid: the script stops at its first step and says what to add."""
    proc = _run(f"jsbsim --root=REPO --script={J.FIG21_SCRIPT} --outputpath=OUT", tmp_path,
                REPO=str(REPO), OUT=str(tmp_path))
    assert "bioflex: stopped, simulation/dt is not the exported step" in proc.stdout
    assert "--simulation-rate=960" in proc.stdout
    rows = (tmp_path / J.FIG21_OUTPUT).read_text().splitlines()
    assert len(rows) <= 2  # the header, at most one row


def _export(spec, root: Path, gust_up_m_s: float):
    """What ``export-jsbsim`` writes, through the driver: (case, trim)."""
    from bioflex_jsb.drivers.native import export_flight, write_export

    case, state, files = export_flight(spec, gust_up_m_s)
    write_export(files, root)
    return case, state


def test_relative_outputpath_is_taken_from_the_root(tmp_path):
    """As docs/native.md says: JSBSim resolves a relative --outputpath against --root."""
    case, _ = _export(_spec("original"), tmp_path / "root", 0.0)
    (tmp_path / "root" / "runs").mkdir()
    _run(f"{case.command('ROOT')} --outputpath=runs", tmp_path, ROOT=str(tmp_path / "root"))
    assert (tmp_path / "root" / "runs" / case.output).is_file()
    assert not (tmp_path / "runs").exists()


@pytest.mark.parametrize("variant, speed", [("original", 9.5), ("original", 32.0)])
def test_export_flies_level_at_the_ends_of_the_trim_range(tmp_path, variant, speed):
    """No gust: released from the trim, the exported aircraft stays in level flight (the
    propellers settled on the trim RPM during the hold)."""
    case, state = _export(_spec(variant, speed_m_s=speed), tmp_path, 0.0)
    assert "atmosphere/wind-down-fps\"" not in (tmp_path / case.script).read_text("utf-8")
    _run(case.command("ROOT"), tmp_path, ROOT=str(tmp_path))
    col = _read_csv(tmp_path / case.output)
    fly = col["Time"] >= case.settle_s
    assert col["rpm [rev/min]"][fly][0] == pytest.approx(state.propeller_rpm, rel=1e-8)
    assert np.max(np.abs(col["q [rad/s]"][fly])) < 1e-4  # measured 7e-6 rad/s
    assert np.ptp(col["theta [rad]"][fly]) < 1e-4  # measured 1e-5 rad over 5 s
    assert np.all(col["active [-]"][fly] == 1.0)


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
    assert info["script"] == f"scripts/{craft}.xml"
    assert info["initial_condition"] == f"aircraft/{craft}/trim.xml"
    assert info["command"] == (f"jsbsim --root={tmp_path.resolve()} --script=scripts/{craft}.xml"
                               " --simulation-rate=960")
    assert info["output_csv"] == str(tmp_path.resolve() / f"{craft}.csv")
    assert [c["column"] for c in info["columns"]] == CAPTIONS
    assert all((tmp_path / rel).is_file() for rel in (info["script"], info["initial_condition"]))
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
    (["--speed", "4.9"], "speed 4.9 m/s is outside 5..40 m/s"),
    (["--speed", "40.5"], "speed 40.5 m/s is outside 5..40 m/s"),
    (["--speed", "nan"], "outside 5..40 m/s"),
    (["--speed", "8"], "cannot trim at 8 m/s"),  # in the range, but below the stall speed
    (["--gust", "1cos:3:10"], "sharp-edged gust (sharp:A) or none"),
    (["--gust", "sharp:x"], "must be a number"),
])
def test_cli_bad_input_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys, argv, words):
    out = tmp_path / "root"
    assert _cli(["export-jsbsim", "--out", str(out), *argv]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1
    assert not out.exists()


def test_cli_refuses_a_root_where_jsbsim_could_not_write_the_csv(tmp_path, capsys):
    (tmp_path / "bioflex_original.csv").mkdir()
    assert _cli(["export-jsbsim", "--wing", "original", "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "is not a regular file" in err and err.count("\n") == 1


def test_cli_replaces_its_own_files_but_not_a_users_without_force(tmp_path, capsys):
    argv = ["export-jsbsim", "--wing", "original", "--out", str(tmp_path)]
    assert _cli(argv) == 0
    assert _cli(argv) == 0  # its own files: replaced
    script = tmp_path / "scripts" / "bioflex_original.xml"
    script.write_text("<runscript/>\n", encoding="utf-8")
    capsys.readouterr()
    assert _cli(argv) == 2
    err = capsys.readouterr().err
    assert "already exists" in err and "--force" in err and err.count("\n") == 1
    assert script.read_text(encoding="utf-8") == "<runscript/>\n"
    assert _cli([*argv, "--force"]) == 0
    assert "GENERATED by bioflex_jsb" in script.read_text(encoding="utf-8")
    # a generated file the user edited keeps its header but not the recorded content: kept
    # (it was replaced silently), replaced with --force
    edited = script.read_text(encoding="utf-8") + "<!-- my edit -->\n"
    script.write_text(edited, encoding="utf-8")
    capsys.readouterr()
    assert _cli(argv) == 2
    err = capsys.readouterr().err
    assert "edited since it was generated" in err and err.count("\n") == 1
    assert script.read_text(encoding="utf-8") == edited
    assert _cli([*argv, "--force"]) == 0
    assert script.read_text(encoding="utf-8") != edited
    assert _cli(argv) == 0  # unedited again: replaced


def test_cli_without_gust_writes_a_script_in_still_air(tmp_path, capsys):
    assert _cli(["export-jsbsim", "--wing", "original", "--gust", "none", "--speed", "20",
                 "--out", str(tmp_path)]) == 0
    text = (tmp_path / "scripts" / "bioflex_original.xml").read_text(encoding="utf-8")
    assert "in still air" in text and 'name="atmosphere/wind-down-fps"' not in text
    ic = (tmp_path / "aircraft" / "bioflex_original" / "trim.xml").read_text(encoding="utf-8")
    assert "trim at 20 m/s" in ic


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


def test_cli_unusable_directory_exits_2(tmp_path, capsys):
    """Also as root: a path through a regular file cannot be a directory."""
    (tmp_path / "file").write_text("x", encoding="utf-8")
    assert _cli(["export-jsbsim", "--wing", "original", "--out", str(tmp_path / "file" / "x")]) == 2
    err = capsys.readouterr().err
    assert "cannot write" in err and err.count("\n") == 1
