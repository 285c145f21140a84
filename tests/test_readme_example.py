"""The README's Python example runs as written, in a fresh directory, with this interpreter."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"


def readme_example() -> str:
    text = README.read_text(encoding="utf-8")
    m = re.search(r"<!-- example:python -->\s*```python\n(.*?)```", text, re.DOTALL)
    assert m, "README has no <!-- example:python --> block"
    return m.group(1)


@pytest.mark.slow
def test_readme_python_example_runs_in_a_fresh_directory(tmp_path):
    code = readme_example()
    assert "bioflex_jsb.cli" not in code and "subprocess" not in code  # the API, not the CLI
    result = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    assert "coupled  peak q" in out and "rigid    peak q" in out, out
    assert "flutter:" in out and "flutter_speed_m_s" in out, out
    assert "stopped: None" in out, out
