"""The wheel ships the JSBSim root (aircraft/ and systems/) and the package data."""

from __future__ import annotations

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
