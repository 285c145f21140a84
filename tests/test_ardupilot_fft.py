"""scripts/ardupilot_fft.py without ArduPlane: its spectral peak, ArduPilot's notch and
low-pass as ported, the parameter file, the batch split, and the --dt / --defaults options
the flights use."""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f"{name}_script",
                                                  REPO / "scripts" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


fft = _load("ardupilot_fft")
FS = 1000.0  # ArduPilot SITL's gyro rate (INS_SITL_SENSOR_A) [Hz]
MODE_HZ = 42.023  # the prototype's aeroelastic_1 at 15 m/s (bioflex-jsb modes) [Hz]


def _batches(f_hz, amp, n_batches=20, noise=0.0, seed=1, extra=()):
    rng = np.random.default_rng(seed)
    t = np.arange(n_batches * fft.BATCH_COUNT) / FS
    x = amp * np.sin(2 * np.pi * f_hz * t + 0.3)
    for fe, ae in extra:
        x += ae * np.sin(2 * np.pi * fe * t)
    x += noise * rng.standard_normal(len(t))
    return [x[i:i + fft.BATCH_COUNT] for i in range(0, len(x), fft.BATCH_COUNT)]


def test_the_peak_finder_reads_a_sine_in_noise_to_a_fraction_of_a_bin():
    # a 42.023 Hz sine of 0.03 rad/s (the wing IMU's mode in turbulence) in white noise of
    # 0.01 rad/s rms and a large rigid-body motion at 1.2 Hz; bins are 0.98 Hz wide
    segs = _batches(MODE_HZ, 0.03, noise=0.01, extra=((1.2, 0.1),))
    f, a = fft.amplitude_spectrum(segs, FS)
    peak_hz, peak_amp = fft.spectral_peak(f, a, fft.SEARCH_HZ)
    assert abs(peak_hz - MODE_HZ) < 0.01  # 0.02 %, far inside "a few %"
    assert peak_amp == pytest.approx(0.03, rel=0.03)  # the window's gain divided out


def test_the_peak_finder_refuses_a_band_without_bins():
    f, a = fft.amplitude_spectrum(_batches(MODE_HZ, 1.0, n_batches=1), FS)
    with pytest.raises(fft.ScriptError):
        fft.spectral_peak(f, a, (42.0, 42.05))


def test_arduPilots_notch_is_att_deep_at_its_centre_and_transparent_far_away():
    c = fft.notch_coefficients(FS, MODE_HZ, MODE_HZ / 2, 40.0)
    # NotchFilter.cpp: the gain at the centre is A² = 10^(-ATT/20)
    assert fft.gain_db(c, MODE_HZ, FS) == pytest.approx(-40.0, abs=1e-6)
    assert abs(fft.gain_db(c, 2.0, FS)) < 0.1 and abs(fft.gain_db(c, 300.0, FS)) < 0.2
    # applied to a steady sine it takes what the closed form says
    t = np.arange(4000) / FS
    y = fft.biquad(c, np.sin(2 * np.pi * MODE_HZ * t))
    assert fft.db(np.abs(y[-1000:]).max()) == pytest.approx(-40.0, abs=0.5)


def test_arduPilots_gyro_lowpass_is_butterworth():
    c = fft.lowpass_coefficients(FS, 20.0)
    assert fft.gain_db(c, 20.0, FS) == pytest.approx(-3.0103, abs=1e-3)  # -3 dB at cutoff
    assert fft.gain_db(c, 0.0, FS) == pytest.approx(0.0, abs=1e-9)
    # the 2nd-order Butterworth's |H| = 1/sqrt(1 + (f/fc)^4), prewarped: within 0.3 dB at 42 Hz
    analog = -10 * math.log10(1 + (MODE_HZ / 20.0) ** 4)
    assert fft.gain_db(c, MODE_HZ, FS) == pytest.approx(analog, abs=0.3)


def test_the_notch_removes_the_mode_from_a_synthetic_gyro():
    segs = _batches(MODE_HZ, 0.03, n_batches=8, noise=1e-4)
    raw = np.concatenate(segs)
    c = fft.notch_coefficients(FS, MODE_HZ, MODE_HZ / 2, 40.0)
    out = fft.biquad(c, raw)[2 * fft.BATCH_COUNT:]  # past the filter's start
    f0, a0 = fft.amplitude_spectrum(segs[2:], FS)
    f1, a1 = fft.amplitude_spectrum(
        [out[i:i + fft.BATCH_COUNT] for i in range(0, len(out), fft.BATCH_COUNT)], FS)
    assert fft.db(fft.amplitude_at(f1, a1, MODE_HZ) / fft.amplitude_at(f0, a0, MODE_HZ)) < -35


def test_the_parameter_file(tmp_path):
    params = {**fft.fft_parameters(), **fft.notch_parameters(42.1)}
    assert params["FFT_ENABLE"] == 1 and params["INS_LOG_BAT_OPT"] == 4
    assert params["FFT_MINHZ"] < MODE_HZ < params["FFT_MAXHZ"]
    assert params["INS_HNTCH_MODE"] == 0 and params["INS_HNTCH_BW"] == pytest.approx(21.05)
    path = tmp_path / "fft.parm"
    fft.write_new(path, fft.render_parm(params, "test"), force=False)
    lines = [ln.split() for ln in path.read_text().splitlines() if not ln.startswith("#")]
    assert {n: float(v) for n, v in lines} == pytest.approx(params)
    with pytest.raises(fft.ScriptError):  # never over an existing file
        fft.write_new(path, "x", force=False)
    with pytest.raises(fft.ScriptError):
        fft.notch_parameters(5.0)
    # the command line: exit 2, one line, and the file kept
    r = subprocess.run([sys.executable, str(REPO / "scripts" / "ardupilot_fft.py"), "params",
                        "--out", str(path)], capture_output=True, text=True)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "exists" in r.stderr


def test_batches_split_into_raw_and_filtered_and_holes_are_dropped():
    def batch(instance, t0, holes=False):
        return {"instance": instance, "mul": 1000.0, "count": 4, "t0_s": t0,
                "rate_hz": FS, "x": [1, 2, 3, 4], "y": [5, 6, 7, 8], "z": [0] * 4,
                **({"holes": True} if holes else {})}
    pre, post = fft.split_batches([batch(0, 1.0), batch(0, 20.0), batch(3, 21.0),
                                   batch(0, 22.0, holes=True)], from_s=10.0)
    assert len(pre) == 1 and len(post) == 1
    assert pre[0][1][1].tolist() == [0.005, 0.006, 0.007, 0.008]  # counts / multiplier
    assert fft.launch_time_s([(1.0, 0.0), (2.0, 12.0), (3.0, 15.0)]) == 2.0


def test_the_flights_options_are_checked():
    r = subprocess.run([sys.executable, "-m", "bioflex_jsb", "ardupilot", "--dt", "0.5",
                        "--no-log"], capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and "--dt 0.5 s is outside" in r.stderr
    r = subprocess.run([sys.executable, str(REPO / "scripts" / "ardupilot_sitl.py"), "fly",
                        "/nonexistent", "--defaults", "/nonexistent/fft.parm"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--defaults" in r.stderr
