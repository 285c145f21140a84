"""The architecture as tests: the import-linter contracts (``pyproject.toml``: the layers, one
package importing jsbsim, no import circle between sibling modules), no blanket exception
handlers."""

from __future__ import annotations

import re
import subprocess
import sys
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
