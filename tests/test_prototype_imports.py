"""Nothing below the loader reads parameters/prototype.py directly (issue 23, item 1).

A source scan (every module of the package, parsed: ``import`` statements, absolute and
relative) lists the modules that import ``bioflex_jsb.parameters.prototype``, the
prototype's parameter set: the paper's data that the shipped definition files are checked
against. They are allowed in three groups: the loader (``bioflex_jsb/definition``), the
parameter modules (``bioflex_jsb/parameters``: the paper's data and the estimates derived
from it), the readers of the paper's *published results* (they compare with or calibrate to
a table, they do not describe the aircraft), and an explicit allow-list of the modules still
to move, each with its reason, that only shrinks. The aircraft's description (reference
geometry, mass, inertia, CG, derivatives) is read from :mod:`bioflex_jsb.parameters.airframe`
and the physical constants from :mod:`bioflex_jsb.parameters.constants`.

Before the move: 22 modules outside definition/ and parameters/ imported it; after: the 10
listed here, besides the loads package written meanwhile (H10); then 9 (H15:
flight_dynamics/wing_model.py reads the published C_eta1^Q1 from parameters/wing.py); then
6 (issue 23, the second aircraft flies: runtime/coupled_step.py, simulation/unsteady_wing.py
and simulation/gusts.py take S, c-bar and the derivatives from the wing's AirframeData). The
linear analyses below the loader (flight_dynamics/rigid, lti, eigen, modal_matrices,
elastic_trim, wing_model; aeroelasticity/free_aircraft) take the aircraft's values from the
``AirframeData`` their wing model and flight condition carry
(tests/test_second_aircraft.py flies another airframe's numbers through them).
"""

from __future__ import annotations

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "bioflex_jsb"
TARGET = "bioflex_jsb.parameters.prototype"

ALLOWED_PACKAGES = ("definition/", "parameters/")

# Readers of the paper's published results (tables of results, the paper's test cases):
# the data prototype.py keeps for them.
PAPER_RESULT_READERS = {
    "validation.py": "Tables 3 and 6 short-period roots, compared with the models",
    "structures/wing_model.py": "Table 2 frequencies and generalised masses: the beam's "
                                "calibration targets and the Table 2 comparison; Section "
                                "3.1's neglected structural damping (0) as wing_modes' default",
    "flight_dynamics/consistent_aircraft.py": "Table 3's rigid short period at 15 m/s, the "
                                              "target its derivatives are calibrated to",
    "drivers/native.py": "the paper's Section 5 gust case (15 m/s, 3 m/s) as the native "
                         "export's defaults",
    "generators/native_aircraft.py": "the paper's Section 5 gust case (15 m/s, 3 m/s) of the "
                                     "native aircraft's script",
}

# Still to move (shrinks to empty): each reads the aircraft's description from prototype.py.
STILL_TO_MOVE = {
    # a package entry (ending in /) covers its modules: H10's gust-loads package is being
    # written while this list is made (5 of its modules read S, c-bar, g, rho from it)
}


def _allowed_by(entry: str, module: str) -> bool:
    return module.startswith(entry) if entry.endswith("/") else module == entry


def _module_name(path: Path, package: Path) -> str:
    rel = path.relative_to(package.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _imports_prototype(path: Path, package_dir: Path = PACKAGE) -> bool:
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    here = _module_name(path, package_dir).split(".")
    package = here if path.name == "__init__.py" else here[:-1]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            if any(a.name == TARGET or a.name.startswith(TARGET + ".") for a in node.names):
                return True
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                root = package[: len(package) - node.level + 1]
                base = ".".join(root + ([base] if base else []))
            if base == TARGET or base.startswith(TARGET + "."):
                return True
            if any(f"{base}.{a.name}" == TARGET for a in node.names):
                return True
    return False


def _importers() -> list[str]:
    return sorted(str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                  if _imports_prototype(p))


def test_the_scan_finds_every_form_of_import(tmp_path):
    # the detector itself: each spelling is found, a look-alike is not
    forms = {
        "from bioflex_jsb.parameters import prototype as P": True,
        "from bioflex_jsb.parameters import airframe, prototype": True,
        "import bioflex_jsb.parameters.prototype": True,
        "from bioflex_jsb.parameters.prototype import SPAN_M": True,
        "from ..parameters import prototype": True,
        "from ..parameters.prototype import MASS_KG": True,
        "from bioflex_jsb.parameters import airframe": False,
        "x = 'bioflex_jsb.parameters.prototype'": False,
    }
    package = tmp_path / "bioflex_jsb"
    (package / "simulation").mkdir(parents=True)
    probe = package / "simulation" / "probe.py"
    for text, expected in forms.items():
        probe.write_text(text + "\n", encoding="utf-8")
        assert _imports_prototype(probe, package) is expected, text


def test_nothing_below_the_loader_reads_the_prototype_directly():
    allowed = set(PAPER_RESULT_READERS) | set(STILL_TO_MOVE)
    users = _importers()
    outside = [u for u in users if not u.startswith(ALLOWED_PACKAGES)]
    new = [u for u in outside if not any(_allowed_by(e, u) for e in allowed)]
    assert not new, (f"{new} import parameters.prototype: read the aircraft's description "
                     "from parameters.airframe (REFERENCE_GEOMETRY, MASS_PROPERTIES, ...) or "
                     "the Aircraft, physical constants from parameters.constants")
    # the allow-lists only shrink: an entry that no longer imports it must be removed
    stale = sorted(e for e in allowed if not any(_allowed_by(e, u) for u in outside))
    assert not stale, f"{stale} no longer import parameters.prototype: remove them here"
    # 22 outside definition/ and parameters/ before issue 23's move (module docstring), 10
    # after, 9 after H15's, 6 after the second aircraft flew (coupled_step, unsteady_wing and
    # gusts take S, c-bar from the wing's AirframeData), besides the loads package
    assert len([u for u in outside if not u.startswith("loads/")]) <= 6
