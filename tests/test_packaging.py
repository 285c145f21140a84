"""The wheel ships the JSBSim root (aircraft/ and systems/) and the package data."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

pytestmark = pytest.mark.slow  # real ground stations / subprocess runs: not in the fast subset

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    proc = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", str(REPO), "--no-deps", "-q", "-w", str(out)],
        capture_output=True, text=True, timeout=600,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    wheels = list(out.glob("bioflex_jsb-*.whl"))
    assert len(wheels) == 1
    return wheels[0]


def test_wheel_contains_the_jsbsim_root_and_data(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for rel in (
        "bioflex_jsb/jsbsim_root/aircraft/bioflex/bioflex.xml",
        "bioflex_jsb/jsbsim_root/systems/bioflex_flight_controls.xml",
        "bioflex_jsb/data/modes/example_ribbed.toml",
        "bioflex_jsb/data/variants/axes_forward.toml",
    ):
        assert rel in names, rel
    prefix = "bioflex_jsb/jsbsim_root/aircraft/bioflex/Engines/"
    engines = [n for n in names if n.startswith(prefix)]
    assert len(engines) >= 2  # motor and propeller


def test_every_committed_jsbsim_file_is_in_the_wheel(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for folder in ("aircraft", "systems"):
        for f in (REPO / folder).rglob("*.xml"):
            rel = f"bioflex_jsb/jsbsim_root/{f.relative_to(REPO).as_posix()}"
            assert rel in names, rel


# --- The wheel outside the source tree -------------------------------------------------------
# A user installs the wheel, not the checkout: the test builds the sdist and the wheel with the
# standard front end (`python -m build`: the wheel is built from the unpacked sdist, so a file
# missing from MANIFEST.in fails here too), installs the wheel (not editable) into a fresh venv
# in a temporary directory, and runs the commands there. The fresh venv borrows this
# interpreter's third-party packages through a .pth line (installing jsbsim, numba, dask ...
# again would take minutes and the network): a .pth line only appends a directory to sys.path,
# so the package under test is the wheel's copy, which sits earlier on the path (asserted).


@pytest.fixture(scope="module")
def dists(tmp_path_factory) -> dict[str, Path]:
    out = tmp_path_factory.mktemp("dist")
    proc = subprocess.run([sys.executable, "-m", "build", "--outdir", str(out), str(REPO)],
                          capture_output=True, text=True, timeout=900, cwd=out)
    assert proc.returncode == 0, (proc.stdout + proc.stderr)[-3000:]
    wheels, sdists = list(out.glob("bioflex_jsb-*.whl")), list(out.glob("bioflex_jsb-*.tar.gz"))
    assert len(wheels) == 1 and len(sdists) == 1, sorted(p.name for p in out.iterdir())
    return {"wheel": wheels[0], "sdist": sdists[0]}


def _site_packages(python: Path) -> Path:
    code = "import sysconfig; print(sysconfig.get_paths()['purelib'])"
    return Path(subprocess.run([str(python), "-c", code], capture_output=True, text=True,
                               check=True).stdout.strip())


@pytest.fixture(scope="module")
def installed(dists, tmp_path_factory) -> Path:
    """A fresh venv (outside the repository) with the wheel installed; its bin directory."""
    root = tmp_path_factory.mktemp("venv")
    venv = root / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=300)
    python = venv / "bin" / "python"
    borrowed = [p for p in sys.path if p.endswith("site-packages") and Path(p).is_dir()]
    (_site_packages(python) / "borrowed_deps.pth").write_text("\n".join(borrowed) + "\n")
    # --ignore-installed: pip sees the borrowed directories, and in CI they hold a
    # non-editable bioflex-jsb of the same version, which it would take as "already
    # satisfied" and install nothing
    proc = subprocess.run([str(python), "-m", "pip", "install", "--no-deps", "--no-index", "-q",
                           "--ignore-installed", str(dists["wheel"])],
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return venv / "bin"


def _run_installed(bin_dir: Path, args: list[str], cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    return subprocess.run(args, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


def test_twine_accepts_the_sdist_and_the_wheel(dists):
    proc = subprocess.run([sys.executable, "-m", "twine", "check", "--strict",
                           str(dists["wheel"]), str(dists["sdist"])],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_version_is_single_sourced():
    """pyproject.toml takes the version from the package (``dynamic``), so the wheel's metadata,
    ``bioflex_jsb.__version__`` and ``--version`` cannot drift apart."""
    import tomllib

    import bioflex_jsb

    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    assert "version" not in project and "version" in project["dynamic"]
    assert re.fullmatch(r"\d+\.\d+\.\d+(\.dev\d+)?", bioflex_jsb.__version__)


def test_the_installed_wheel_runs_outside_the_source_tree(installed, tmp_path):
    work = tmp_path / "user"
    work.mkdir()
    python = str(installed / "python")
    show = "import bioflex_jsb; print(bioflex_jsb.__file__); print(bioflex_jsb.__version__)"
    where = _run_installed(installed, [python, "-c", show], work)
    assert where.returncode == 0, where.stderr
    location, version = where.stdout.split()
    assert Path(location).resolve().is_relative_to(installed.parent.resolve()), location
    assert not Path(location).resolve().is_relative_to(REPO), location

    exe = str(installed / "bioflex-jsb")
    ver = _run_installed(installed, [exe, "--version"], work)
    assert ver.returncode == 0 and ver.stdout.strip() == f"bioflex-jsb {version}", ver

    gust = _run_installed(installed, [exe, "gust", "--duration", "1", "--no-log", "--json"], work)
    assert gust.returncode == 0, gust.stderr[-3000:]
    runs = json.loads(gust.stdout)
    assert runs, gust.stdout

    flutter = _run_installed(installed, [exe, "flutter", "--json"], work)
    assert flutter.returncode == 0, flutter.stderr[-3000:]
    json.loads(flutter.stdout)

    export = _run_installed(installed, [exe, "export-jsbsim", "--out", str(work / "root")],
                            work)
    assert export.returncode == 0, export.stderr[-3000:]
    assert any((work / "root" / "aircraft").rglob("*.xml"))


def test_the_readme_example_runs_against_the_installed_wheel(installed, tmp_path):
    from tests.test_readme_example import readme_example

    proc = _run_installed(installed, [str(installed / "python"), "-c", readme_example()],
                          tmp_path)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "flutter:" in proc.stdout and "coupled  peak q" in proc.stdout, proc.stdout
