"""Helpers of the CLI tests: run a command in-process, check a one-line refusal."""

from __future__ import annotations

from bioflex_jsb.cli import main


def run_cli(capsys, *argv):
    """(exit status, stdout, stderr) of ``bioflex-jsb argv…`` run in this process."""
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_one_line_error(code, err, needle):
    """Exit status 2, one line on stderr containing ``needle``, no traceback."""
    assert code == 2
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert needle in lines[0], lines[0]
