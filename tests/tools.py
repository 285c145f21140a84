"""The test extra's command-line programs, found beside this interpreter (its environment's
``bin/``), never on PATH: a test must not depend on what PATH happens to hold."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest


def env_program(name: str) -> str:
    """The program ``name`` of this Python's environment (e.g. ``pymcap-cli``, ``jsbsim``);
    the test fails, saying what to install, when it is not there."""
    exe = Path(sys.executable).parent / name
    if not exe.exists():
        pytest.fail(f"{exe} is missing: install the test extra (pip install '.[test]')")
    return str(exe)
