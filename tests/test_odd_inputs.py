"""Odd inputs of the less-visited paths (the review of 2026-12-04): each ended in a
traceback, a bare numpy/scipy/Python error, a wrong reason or a silent wrong result; each is
now refused in one line (exit 2 in the CLI, InputError in the API) before anything is
flown or written."""

from __future__ import annotations

import json
import shutil
import struct
import zlib
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.errors import InputError
from tests.cli_helpers import assert_one_line_error, run_cli

DATA = Path(api.__file__).resolve().parent / "data" / "aircraft"


def _model_file(path: Path, **changes) -> Path:
    arrays = dict(A=np.eye(2), B=np.ones((2, 1)), C=np.eye(2), D=np.zeros((2, 1)), model="x",
                  speed_m_s=np.array([15.0]), states=np.array(["a", "b"]),
                  state_units=np.array(["-", "-"]), inputs=np.array(["u"]),
                  input_units=np.array(["-"]), outputs=np.array(["a", "b"]),
                  output_units=np.array(["-", "-"]), metadata=json.dumps({}))
    arrays.update(changes)
    np.savez(path, **arrays)
    return path


@pytest.mark.parametrize("name, content", [
    ("empty.npz", b""), ("text.mat", b"hi\n"), ("zip.npz", b"PK\x03\x04" + b"0" * 50)])
def test_export_over_an_unreadable_file_is_refused_and_keeps_it(tmp_path, capsys, name,
                                                                  content):
    """EOFError, MatReadError and BadZipFile tracebacks before."""
    target = tmp_path / name
    target.write_bytes(content)
    code, _, err = run_cli(capsys, "export", "--out", str(target))
    assert_one_line_error(code, err, "already exists")
    assert target.read_bytes() == content
    with pytest.raises(InputError, match="not a model file"):
        api.to_python_control(str(target))


def test_a_model_file_with_odd_arrays_is_one_input_error(tmp_path):
    with pytest.raises(InputError, match="not a bioflex-jsb model file"):  # an IndexError
        api.to_python_control(_model_file(tmp_path / "e.npz", speed_m_s=np.array([])))
    with pytest.raises(InputError, match="not a JSON object"):  # then an AttributeError
        api.to_python_control(_model_file(tmp_path / "l.npz", metadata=json.dumps([1, 2])))


def test_two_outputs_of_loads_frequency_on_one_file_are_refused(tmp_path, capsys):
    same = str(tmp_path / "same.png")
    code, _, err = run_cli(capsys, "loads", "--frequency", "--record", "17", "--sigmas", "0.1",
                           "--bode", same, "--plot", same)
    assert_one_line_error(code, err, "name the same file")
    assert not Path(same).exists()


def _goland_file(tmp_path: Path) -> Path:
    return Path(shutil.copy(DATA / "goland.toml", tmp_path / "goland.toml"))


@pytest.mark.parametrize("call, needle", [
    # a Path is read like a file name (AttributeError 'PosixPath' has no 'path'); the bad
    # lift slope is only reached once the file was read
    (lambda w, r, t: api.flutter(_goland_file(t), clamped=True, lift_slope="foo"),
     "unknown lift_slope 'foo'"),
    (lambda w, r, t: api.flutter(w, clamped=True), "clamped=True analyses"),
    (lambda w, r, t: api.modes(w, 15.0, clamped=True), "not WingBuild"),
    (lambda w, r, t: api.flutter(w, 5),
     r"range_m_s: must be \[low, high\] m/s with 0 < low < high <= 400 m/s"),
    (lambda w, r, t: api.section_loads(w, "run"), "not str"),
    (lambda w, r, t: api.section_loads(w, {"coupled": r}), "not the dict of runs"),
    (lambda w, r, t: api.section_loads(w, r, 0.5), "a sequence of fractions"),
    (lambda w, r, t: api.section_loads(w, r, "0.5"), "a sequence of fractions"),
    (lambda w, r, t: api.section_loads("optimised", r), "give a wing"),
    (lambda w, r, t: api.fly_gust(None), "not None"),
    (lambda w, r, t: api.compare(None), "not None"),
    (lambda w, r, t: api.compare(w, recorder="x.mcap"), "must be a StepRecorder"),
    (lambda w, r, t: api.fly_gust(w, recorders={"rigid": "x"}, models=("rigid",)),
     "must be a StepRecorder"),
    (lambda w, r, t: api.metrics(None), "a TimeHistory"),
    (lambda w, r, t: api.linear_model(w, 1e-300),  # ZeroDivision
     "speed_m_s: 1e-300 m/s is outside the valid range 0.1..400 m/s"),
    (lambda w, r, t: api.fly_fig21("rigid", duration_s=-1), "duration_s: must be > 0 s"),
    (lambda w, r, t: api.fly_fig21("rigid", duration_s=0), "must be > 0"),  # an empty run
    (lambda w, r, t: api.fly_fig21("rigid", duration_s="1"),
     "duration_s: must be a finite number in s"),
    (lambda w, r, t: api.fly_fig21("nope"), "unknown model 'nope'"),
    (lambda w, r, t: api.fly_gust(w, duration_s=1e6, models=("rigid",)), "too long"),
    (lambda w, r, t: api.fly_gust(w, gust="dryden:1:50", duration_s=4000.0,
                                  models=("rigid",)), "of turbulence"),
    (lambda w, r, t: api.flutter("goland", clamped=True, structural_damping=0.95),
     "outside the valid range 0..0.3"),  # the p-k method's IndexError
])
def test_the_api_refuses_in_one_line(optimised_wing, optimised_run, tmp_path, call, needle):
    with pytest.raises(InputError, match=needle) as info:
        call(optimised_wing, optimised_run, tmp_path)
    assert "\n" not in str(info.value)


def test_flutter_structural_damping_beyond_the_definitions_range_is_exit_2(capsys):
    code, _, err = run_cli(capsys, "flutter", "--clamped", "goland", "--structural-damping",
                           "0.95")
    assert_one_line_error(code, err, "0 <= Z <= 0.3")


def test_export_jsbsim_names_its_step_and_makes_no_tree_for_a_mistyped_path(tmp_path,
                                                                            capsys):
    code, _, err = run_cli(capsys, "export-jsbsim", "--out", str(tmp_path / "J"), "--dt",
                           "5e-5")  # said "needs more thrust than the motor gives"
    assert_one_line_error(code, err, "--dt 5e-05 s is outside 0.0001..0.02 s")
    deep = tmp_path / "deep" / "a" / "b" / "c"
    code, _, err = run_cli(capsys, "export-jsbsim", "--out", str(deep))
    assert_one_line_error(code, err, "does not exist")
    assert not (tmp_path / "deep").exists() and not (tmp_path / "J").exists()


def test_a_sweep_speed_below_1_m_s_is_refused_at_load(tmp_path, capsys):
    campaign = tmp_path / "c.toml"
    campaign.write_text('metrics = ["eigenvalues"]\n[axes]\nwings = ["optimised"]\n'
                        "speeds_m_s = [1e-300, 0.001]\n")
    code, _, err = run_cli(capsys, "sweep", str(campaign), "--out", str(tmp_path / "o.csv"),
                           "--workers", "1")
    # the whole accepted range (the kind of bioflex_jsb.inputs), not only the side crossed
    assert_one_line_error(code, err, "axes.speeds_m_s[0]: 1e-300 m/s is outside the valid range "
                                     "1..100 m/s")
    assert not (tmp_path / "o.csv").exists()


def test_a_png_that_claims_a_huge_image_is_a_users_file(tmp_path, capsys):
    """PIL's DecompressionBombError was a traceback; the file is the user's, kept."""
    def chunk(kind: bytes, data: bytes) -> bytes:
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data)))

    big = tmp_path / "big.png"
    big.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(
        ">IIBBBBB", 20000, 20000, 8, 2, 0, 0, 0)) + chunk(b"IEND", b""))
    before = big.read_bytes()
    code, _, err = run_cli(capsys, "modes", "--plot", str(big))
    assert_one_line_error(code, err, "already exists")
    assert big.read_bytes() == before
