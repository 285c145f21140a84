"""Output files are checked before any work and never replace a user's file (the CLI
review of 2026-12-03): ``info --recover``, ``ardupilot --summary/--table``, logs that must be
``.mcap``, one command's outputs that name the same file, study options without their
study, and run lengths the loads cannot take. Each case: exit 2, one line, the user's file
byte for byte as it was, nothing run."""

from __future__ import annotations

import pytest

from tests.cli_helpers import assert_one_line_error, run_cli

PRECIOUS = b"precious\n"


@pytest.fixture()
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _kept(path) -> bool:
    return path.read_bytes() == PRECIOUS


@pytest.mark.parametrize("argv, name, needle", [
    # info --recover replaced any existing file (it had no --force)
    (["info", "log.mcap", "--recover", "mine.mcap"], "mine.mcap", "already exists"),
    # ardupilot's summary and table replaced a user's file at the end of the session
    (["ardupilot", "--no-log", "--summary", "mine.json"], "mine.json", "already exists"),
    (["ardupilot", "--no-log", "--table", "mine.npz"], "mine.npz", "already exists"),
])
def test_a_users_file_is_not_replaced(here, capsys, argv, name, needle):
    (here / "log.mcap").write_bytes(b"")
    target = here / name
    target.write_bytes(PRECIOUS)
    code, _, err = run_cli(capsys, *argv)
    assert_one_line_error(code, err, needle)
    assert _kept(target)


@pytest.mark.parametrize("argv, needle", [
    # refused at the start, not after a session of hours
    (["ardupilot", "--no-log", "--summary", "absent/s.json"], "does not exist"),
    (["ardupilot", "--no-log", "--table", "absent/t.npz"], "does not exist"),
    (["ardupilot", "--no-log", "--summary", "s.png"], "ending in .json"),
    (["info", "log.mcap", "--recover", "fixed.txt"], "ending in .mcap"),
    (["info", "log.mcap", "--force"], "give --recover"),
    # a log is an MCAP file: a .svg --out with --plot of the same name destroyed the log
    (["gust", "--out", "c.svg", "--plot", "c.svg"], "name the same file"),
    (["gust", "--out", "c.svg"], "ending in .mcap"),
    (["gust", "--out", ""], "the file name is empty"),
    (["sitl", "--out", "s.txt"], "ending in .mcap"),
    (["modes", "--plot", "s.png", "--mode-sheet", "s.png"], "name the same file"),
    # options of a study that is not run were silently ignored
    (["loads", "--csv", "x.csv"], "--csv applies to --tuned"),
    (["loads", "--sigmas", "1"], "--sigmas applies to --frequency"),
    (["loads", "--bode", "b.png"], "--bode applies to --frequency"),
    # the loads need every step kept: refused up front, not after the run
    (["loads", "--duration", "200"], "up to 120 s"),
    (["loads", "--frequency", "--record", "300"], "up to 120 s"),
    # a step too fine for JSBSim's trim was reported as a motor short of thrust
    (["gust", "--dt", "3e-5"], "outside 0.0001..0.02 s"),
    (["loads", "--dt", "3e-5"], "outside 0.0001..0.02 s"),
    # the SITL vehicle's and the ArduPilot backend's speed: the range every command has
    (["sitl", "--speed", "100"], "outside 5..40 m/s"),
    (["ardupilot", "--speed", "100"], "outside 5..40 m/s"),
])
def test_outputs_and_options_refused_before_any_work(here, capsys, argv, needle):
    (here / "log.mcap").write_bytes(b"")
    code, _, err = run_cli(capsys, *argv)
    assert_one_line_error(code, err, needle)
    assert sorted(p.name for p in here.iterdir()) == ["log.mcap"]


def test_recover_replaces_with_force(here, capsys):
    """``--force`` is the one way to replace it (a truncated log of ours as the source)."""
    code, _, err = run_cli(capsys, "gust", "--models", "rigid", "--duration", "0.3",
                           "--gust-start", "0.1", "--out", "run.mcap", "--json")
    assert code == 0, err
    data = (here / "run.mcap").read_bytes()
    (here / "cut.mcap").write_bytes(data[: len(data) // 2])
    (here / "mine.mcap").write_bytes(PRECIOUS)
    code, _, err = run_cli(capsys, "info", "cut.mcap", "--recover", "mine.mcap", "--force")
    assert code == 0, err
    assert (here / "mine.mcap").read_bytes()[:8] == b"\x89MCAP0\r\n"


def test_rerun_checks_its_inputs_before_flying(here, capsys):
    """``rerun``: an existing --out, and a damaged original log (a flipped byte in a chunk),
    are refused in one line before the run is flown again (the damage was found after the
    run, a KeyError traceback for a damaged summary); a run of a variant file given by a
    relative path repeats from another directory (it recorded the relative path)."""
    (here / "w").mkdir()
    (here / "w" / "fwd.toml").write_text('base = "optimised"\nx_elastic_frac = 0.3\n'
                                         'pin_c_eta1_q1 = "physical"\n')
    import os

    os.chdir(here / "w")
    code, _, err = run_cli(capsys, "gust", "--wing", "fwd.toml", "--models", "rigid",
                           "--duration", "0.3", "--gust-start", "0.1", "--out", "run.mcap",
                           "--json")
    assert code == 0, err
    os.chdir(here)
    (here / "mine.mcap").write_bytes(PRECIOUS)
    code, _, err = run_cli(capsys, "rerun", "w/run.mcap", "--out", "mine.mcap")
    assert_one_line_error(code, err, "already exists")
    assert _kept(here / "mine.mcap")
    code, out, err = run_cli(capsys, "rerun", "w/run.mcap", "--out", "again.mcap", "--json")
    assert code == 0, err
    data = bytearray((here / "w" / "run.mcap").read_bytes())
    middle = len(data) // 2
    data[middle:middle + 3] = bytes(b ^ 0x55 for b in data[middle:middle + 3])
    (here / "bad.mcap").write_bytes(bytes(data))
    code, _, err = run_cli(capsys, "rerun", "bad.mcap", "--out", "new.mcap")
    assert_one_line_error(code, err, "is damaged")
    assert not (here / "new.mcap").exists()
