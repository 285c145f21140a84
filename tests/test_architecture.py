"""The architecture as tests: the import-linter contracts (``pyproject.toml``: the layers, one
package importing jsbsim, no import circle between sibling modules), no blanket exception
handlers, the prototype's parameter constants read only by the loader, no history (issues,
reviews, dates) in the code's comments."""

from __future__ import annotations

import ast
import io
import re
import subprocess
import sys
import tokenize
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "bioflex_jsb"


def _tool(name: str) -> Path:
    """A console script of this interpreter's environment (not whatever PATH finds)."""
    path = Path(sys.executable).with_name(name)
    if not path.exists():
        pytest.skip(f"{name} is not installed beside {sys.executable} (test extra)")
    return path


def test_import_layers_contract_is_kept():
    result = subprocess.run([str(_tool("lint-imports")), "--no-cache"], cwd=ROOT,
                            capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert "Contracts: 4 kept, 0 broken." in result.stdout
    assert "Only bioflex_jsb.inputs imports pydantic KEPT" in result.stdout


def test_only_the_runtime_imports_jsbsim():
    pattern = re.compile(r"^\s*(import jsbsim|from jsbsim\b)", re.MULTILINE)
    users = sorted(str(p.relative_to(PACKAGE)) for p in PACKAGE.rglob("*.py")
                   if pattern.search(p.read_text(encoding="utf-8")))
    assert users and all(u.startswith("runtime/") for u in users), users


def test_no_blanket_exception_handlers():
    """An unexpected exception is a bug and shows its traceback: no ``except Exception`` or
    bare ``except:`` turns it into a one-line usage error."""
    pattern = re.compile(r"^\s*except\s*(Exception|BaseException)?\s*(as \w+)?\s*:", re.MULTILINE)
    found = [f"{p.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}"
             for p in PACKAGE.rglob("*.py")
             for text in [p.read_text(encoding="utf-8")]
             for m in pattern.finditer(text)]
    assert not found, found


# The prototype's parameter modules (the paper's numbers and the estimates calibrated for the
# prototype); constants (physical constants), sensors and goland (the Goland benchmark wing)
# are not the prototype's.
PROTOTYPE_MODULES = ("airframe", "airframe_consistent", "prototype", "wing", "wing_structure")
# Where the prototype's parameter constants may be read: the parameters themselves and the
# loader that builds the aircraft from them (bioflex_jsb.definition), and the modules whose
# subject is the prototype itself: the generators writing its JSBSim files, the paper's
# named wing variants (flight_dynamics.wing_model), the prototype's membrane beam and its
# calibration to Table 2's frequencies and generalised masses (structures.wing_model), the
# paper's Section 5 gust case (15 m/s, 3 m/s) flown by the native export
# (drivers.native), the published-number checks (validation) and the comparison of the
# paper's and the consistent parameter sets.
ALLOWED_READERS = (
    "bioflex_jsb.parameters",
    "bioflex_jsb.definition",
    "bioflex_jsb.generators.airframe",
    "bioflex_jsb.generators.native_aircraft",
    "bioflex_jsb.flight_dynamics.wing_model",
    "bioflex_jsb.structures.wing_model",
    "bioflex_jsb.drivers.native",
    "bioflex_jsb.flight_dynamics.consistent_aircraft",
    "bioflex_jsb.validation",
)
# Readers not moved yet onto the aircraft object passed in, each with what it reads: empty,
# every analysis takes the aircraft passed in (a call made without one gets the loader's
# default_aircraft()). It only shrinks: a module that stops reading them must leave it
# (second assertion), and none may join it.
NOT_YET_MOVED: dict[str, str] = {}


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _prototype_names(tree) -> set[str]:
    """Names of the prototype's parameter modules an AST imports: UPPER_CASE constants
    (not the types), or a whole module; function-level imports count too."""
    found: set[str] = set()
    prefix = "bioflex_jsb.parameters"
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == prefix:
                found.update(a.name for a in node.names if a.name in PROTOTYPE_MODULES)
            elif (node.module.startswith(prefix + ".")
                  and node.module.split(".")[2] in PROTOTYPE_MODULES):
                found.update(a.name for a in node.names
                             if re.fullmatch(r"[A-Z][A-Z0-9_]*", a.name))
        elif isinstance(node, ast.Import):
            found.update(a.name for a in node.names if a.name.startswith(prefix + ".")
                         and a.name.split(".")[2] in PROTOTYPE_MODULES)
    return found


def test_prototype_constants_are_read_only_by_the_loader():
    """Every analysis takes the aircraft passed in: the prototype's parameter constants are
    imported by the parameters, the loader and the prototype's own generators and checks,
    and by the readers listed as not moved yet, and by no other module."""
    readers = {}
    for path in PACKAGE.rglob("*.py"):
        names = _prototype_names(ast.parse(path.read_text(encoding="utf-8")))
        if names:
            readers[_module_name(path)] = sorted(names)
    assert readers, "the AST walk found no reader at all: it is broken"
    allowed = [m for m in readers
               if any(m == a or m.startswith(a + ".") for a in ALLOWED_READERS)]
    unexpected = {m: n for m, n in readers.items()
                  if m not in allowed and m not in NOT_YET_MOVED}
    assert not unexpected, ("take these values from the aircraft/definition object passed "
                            f"in: {unexpected}")
    moved = sorted(set(NOT_YET_MOVED) - set(readers))
    assert not moved, f"no longer reading the prototype's constants: remove from the list {moved}"


# History belongs to the changelog and the issue tracker, not to the code: a comment says what
# and why, not which issue, review or day asked for it.
HISTORY_IN_COMMENTS = re.compile(
    r"\bissues?\s*#?\d+|\bthe issue's\b|\b20\d\d-\d\d-\d\d\b|\breview(s|ed|er|ers)?\b"
    r"|\bPR\s*#?\d+", re.IGNORECASE)
# In strings (docstrings, help texts) dates are data (the MAVLink signing epoch, a generated
# file's creation date); only the references to an issue are history there.
HISTORY_IN_STRINGS = re.compile(r"\bissues?\s*#?\d+|\bthe issue's\b", re.IGNORECASE)


def _history(path: Path) -> list[str]:
    found = []
    source = path.read_text(encoding="utf-8")
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        pattern = {tokenize.COMMENT: HISTORY_IN_COMMENTS,
                   tokenize.STRING: HISTORY_IN_STRINGS}.get(tok.type)
        if pattern is None:
            continue
        for m in pattern.finditer(tok.string):
            line = tok.start[0] + tok.string[:m.start()].count("\n")
            found.append(f"{path.relative_to(ROOT)}:{line}: {m.group(0)!r}")
    return found


def test_no_history_in_code_comments():
    """No comment of the package or its scripts names an issue, a review or a date; no
    docstring or help text names an issue."""
    files = sorted(PACKAGE.rglob("*.py")) + sorted((ROOT / "scripts").rglob("*.py"))
    assert len(files) > 100, "the walk found too few files: it is broken"
    found = [hit for path in files for hit in _history(path)]
    assert not found, found


@pytest.mark.parametrize("comment, history", [
    ("# see issue 42", True), ("# fixed for Issue #7", True), ("# 2026-12-02, night", True),
    ("# as the review asked", True), ("# the issue's figure", True),
    ("# a wing issue: 3 modes", False), ("# reviewing the trim: 2 iterations", False)])
def test_the_history_pattern_tells_history_from_physics(comment, history):
    assert bool(HISTORY_IN_COMMENTS.search(comment)) is history


# JSBSim's own property trees (FGFDMExec's; the ``ap/`` and ``bioflex/`` trees are the
# generated aircraft's systems and are named by their generators).
JSBSIM_TREES = ("accelerations", "aero", "atmosphere", "attitude", "external_reactions", "fcs",
                "flight-path", "forces", "ic", "inertia", "metrics", "moments", "position",
                "propulsion", "simulation", "velocities")
PROPERTY_LITERAL = re.compile(rf"({'|'.join(JSBSIM_TREES)})/[^\s:]*")


def test_the_runtime_names_jsbsim_properties_in_one_module():
    """The runtime reads and writes JSBSim's properties by the names of
    simulation/jsbsim_properties.py: no other runtime module spells one (an error message
    naming a property is prose, with spaces, and is not counted)."""
    found = []
    for path in sorted((PACKAGE / "runtime").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if (isinstance(node, ast.Constant) and isinstance(node.value, str)
                    and PROPERTY_LITERAL.fullmatch(node.value)):
                found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value!r}")
    assert not found, found
    assert PROPERTY_LITERAL.fullmatch("propulsion/engine[")  # an f-string's part counts


def test_one_class_named_airframe():
    """``Airframe`` is the JSBSim adapter's (runtime/fdm.py); a definition's ``[airframe]``
    table is an ``AirframeDefinition``."""
    owners = sorted(str(path.relative_to(PACKAGE)) for path in PACKAGE.rglob("*.py")
                    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8")))
                    if isinstance(node, ast.ClassDef) and node.name == "Airframe")
    assert owners == ["runtime/fdm.py"], owners


def test_no_function_is_graded_e_or_f():
    """Functions an engineer can read: radon's cyclomatic complexity of every function and
    method of the package and of scripts/ stays below grade E (31 and over), so a function
    that grows branches by accretion fails here and is broken up along its seams."""
    radon = pytest.importorskip("radon.complexity", reason="radon is in the test extra")
    graded = []
    for path in sorted([*PACKAGE.rglob("*.py"), *(ROOT / "scripts").rglob("*.py")]):
        for block in radon.cc_visit(path.read_text(encoding="utf-8")):
            rank = radon.cc_rank(block.complexity)
            if rank in ("E", "F"):
                graded.append(f"{path.relative_to(ROOT)}:{block.lineno} {block.name} "
                              f"{rank} ({block.complexity})")
    assert not graded, graded


def test_no_private_name_is_imported_across_modules():
    """A module's private names (a leading underscore) are its own: another module that
    needs one gets a public name, so what a module offers shows in what it names."""
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith(
                    "bioflex_jsb")):
                found += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}"
                          for a in node.names
                          if a.name.startswith("_") and not a.name.startswith("__")]
    assert not found, found
