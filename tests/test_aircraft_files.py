"""The files JSBSim reads for an aircraft (runtime/aircraft_files.py): found where JSBSim
finds them, copied with a bound, links and names that lead out refused, JSBSim's sockets
and output files left out, a killed run's copy removed; an aircraft JSBSim cannot
initialise refused in one line (runtime/fdm.py load_fdm)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from bioflex_jsb.runtime import aircraft_files as F
from bioflex_jsb.runtime.results import AircraftLoadError
from tests.cli_helpers import assert_one_line_error, run_cli

jsbsim = pytest.importorskip("jsbsim")
PACKAGE = Path(jsbsim.get_default_root_dir()) / "aircraft"
WING = """
[wing]
stations = [
  { y_m = 0.0, chord_m = 1.49, elastic_axis = 0.35, centre_of_mass = 0.40 },
  { y_m = 5.45, chord_m = 1.49, elastic_axis = 0.35, centre_of_mass = 0.40 },
]
[structure]
kind = "beam"
bending_stiffness_n_m2 = 2.0e6
torsional_stiffness_n_m2 = 1.0e6
mass_per_length_kg_m = 8.0
pitch_inertia_kg_m = 1.0
[aero]
lift_slope = "vlm"
[air]
density_kg_m3 = 1.225
"""


def _own_aircraft(tmp_path: Path, name: str = "c172p") -> Path:
    """A user's JSBSim root with a copy of the package's ``name`` (its XML only: the
    engines are the package's)."""
    folder = tmp_path / "root" / "aircraft" / "mine"
    folder.mkdir(parents=True)
    shutil.copy(PACKAGE / name / f"{name}.xml", folder / "mine.xml")
    return folder


def test_engines_are_found_where_jsbsim_finds_them(tmp_path):
    """c172p.xml names eng_io320 and prop_75in2f, which are in the package root's engine/,
    not in the aircraft's Engines/ (the propeller was looked for only there)."""
    path = PACKAGE / "c172p" / "c172p.xml"
    files = F.named_files(path, F.read_aircraft_xml(path))
    where = {f.name: f.source.parent.name for f in files}
    assert where == {"eng_io320": "engine", "prop_75in2f": "engine"}
    assert all(str(f.target).startswith("Engines/") for f in files)


def test_a_users_own_root_comes_before_the_package(tmp_path):
    folder = _own_aircraft(tmp_path)
    engine_dir = tmp_path / "root" / "engine"
    engine_dir.mkdir()
    shutil.copy(Path(jsbsim.get_default_root_dir()) / "engine" / "eng_io320.xml", engine_dir)
    files = F.named_files(folder / "mine.xml", F.read_aircraft_xml(folder / "mine.xml"))
    sources = {f.name: f.source for f in files}
    assert sources["eng_io320"].parent == engine_dir.resolve()
    assert sources["prop_75in2f"].parent.name == "engine"  # the package's


@pytest.mark.parametrize("target", ["/dev/zero", "/etc/hostname"])
def test_a_link_out_of_the_folders_is_refused(tmp_path, target):
    """A link in Engines/ to a device or out of the tree is refused before a byte is read
    (a zero.xml -> /dev/zero link copied 12 GB in 20 s)."""
    folder = _own_aircraft(tmp_path)
    (folder / "Engines").mkdir()
    os.symlink(target, folder / "Engines" / "eng_io320.xml")
    with pytest.raises(AircraftLoadError, match="link leading out"):
        F.named_files(folder / "mine.xml", F.read_aircraft_xml(folder / "mine.xml"))


def test_a_name_that_climbs_out_is_refused(tmp_path):
    folder = _own_aircraft(tmp_path)
    text = (folder / "mine.xml").read_text().replace('file="eng_io320"',
                                                      'file="../../../eng_io320"')
    (folder / "mine.xml").write_text(text)
    with pytest.raises(AircraftLoadError, match="no absolute path, no '..'"):
        F.named_files(folder / "mine.xml", F.read_aircraft_xml(folder / "mine.xml"))


def test_only_what_jsbsim_reads_is_copied_and_sockets_are_left_out(tmp_path):
    """A large file beside the XML is not copied (it cost 1.1 GB a run); an <output> or
    <input> section is not in the copy."""
    folder = _own_aircraft(tmp_path)
    (folder / "big.bin").write_bytes(b"\\0" * (1 << 20))
    tree = F.read_aircraft_xml(folder / "mine.xml")
    ET.SubElement(tree.getroot(), "output", name="/tmp/stolen.csv", type="CSV")
    ET.SubElement(tree.getroot(), "input", port="1137")
    work, name = F.private_root(folder / "mine.xml", tree)
    try:
        copied = sorted(str(p.relative_to(work.name)) for p in Path(work.name).rglob("*")
                        if p.is_file())
        assert copied == ["aircraft/mine/Engines/eng_io320.xml",
                          "aircraft/mine/Engines/prop_75in2f.xml", "aircraft/mine/mine.xml"]
        written = ET.parse(Path(work.name) / "aircraft" / "mine" / "mine.xml").getroot()
        assert written.find("output") is None and written.find("input") is None
    finally:
        work.cleanup()


def test_a_killed_runs_copy_is_removed_by_the_next(tmp_path):
    """A process that made a copy and was killed with SIGKILL leaves it; the next copy
    removes it (its process id is gone)."""
    code = ("import sys; from pathlib import Path; from bioflex_jsb.runtime import "
            "aircraft_files as F; p = Path(sys.argv[1]); "
            "w, _ = F.private_root(p, F.read_aircraft_xml(p)); print(w.name, flush=True); "
            "import os, signal; os.kill(os.getpid(), signal.SIGKILL)")
    path = PACKAGE / "c172p" / "c172p.xml"
    proc = subprocess.run([sys.executable, "-c", code, str(path)], capture_output=True,
                          text=True, timeout=120)
    left = Path(proc.stdout.strip())
    assert proc.returncode == -9 and left.is_dir()
    work, _ = F.private_root(path, F.read_aircraft_xml(path))
    work.cleanup()
    assert not left.exists()


def test_an_aircraft_jsbsim_cannot_initialise_is_one_line(tmp_path, capsys):
    """dr1.xml loads but its pushback system reads a property nobody defines: JSBSim raises
    from RunIC (a user saw a traceback and an abort, exit 134); now exit 2, one line."""
    definition = tmp_path / "dr1.toml"
    definition.write_text('name = "dr1_elastic"\n[airframe]\njsbsim = "dr1"\n'
                          + WING.replace("5.45", "3.5"), encoding="utf-8")
    code, _, err = run_cli(capsys, "trim", "--aircraft", str(definition))
    assert_one_line_error(code, err, "but cannot initialise it")
