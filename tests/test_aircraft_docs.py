"""docs/aircraft.md's worked example, run verbatim: its ``file:`` blocks are written to a
directory, its ``run`` blocks (Python, and the shell lines through the CLI in this process)
run there; the tolerances are the ones written in the document."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

from bioflex_jsb.cli import main

DOC = Path(__file__).resolve().parents[1] / "docs" / "aircraft.md"
BLOCK = re.compile(r"<!-- (file: (?P<name>\S+)|run) -->\n```(?P<lang>\w+)\n(?P<body>.*?)```",
                   re.DOTALL)


def test_worked_example_runs_verbatim(tmp_path, monkeypatch, capsys):
    blocks = list(BLOCK.finditer(DOC.read_text(encoding="utf-8")))
    files = [b for b in blocks if b["name"]]
    runs = [b for b in blocks if not b["name"]]
    assert files and {b["lang"] for b in runs} == {"python", "sh"}
    monkeypatch.chdir(tmp_path)
    for b in files:
        (tmp_path / b["name"]).write_text(b["body"], encoding="utf-8")
    for b in runs:
        if b["lang"] == "python":
            exec(compile(b["body"], str(DOC), "exec"), {"__name__": "__doc_example__"})
            continue
        for line in b["body"].strip().splitlines():
            argv = shlex.split(line)
            assert argv[0] == "bioflex-jsb"
            assert main(argv[1:]) == 0, line
    out = capsys.readouterr().out
    assert "flutter at 32.5 m/s, mode 3 (torsion), frequency 22.37 rad/s" in out
    assert "static divergence at 37.2 m/s" in out
