#!/usr/bin/env python3
"""ArduPlane sees the wing: its in-flight FFT finds the first wing mode, a harmonic notch
removes it from the rate controllers' input (docs/ardupilot.md, "The wing in ArduPlane's
gyro").

    python scripts/ardupilot_fft.py params --out fft.parm [--notch-hz F] [--force]
    python scripts/ardupilot_fft.py analyse LOG.BIN [--from-s T] [--mode-hz F]
    python scripts/ardupilot_fft.py fly /path/to/ardupilot --out DIR [--speedup N]
        [--plot FIG.png]

``params`` writes the ArduPlane parameters added to ``bioflex_plane.parm``: the in-flight
FFT (FFT_*), the batch sampler of the first IMU's raw and filtered gyro (INS_LOG_BAT_*),
the IMU's place for the EKF (INS_POS1_*) and, with ``--notch-hz``, the fixed harmonic notch
(INS_HNTCH_*). ``analyse`` reads a dataflash log (pymavlink's DFReader): the FFT's FTN1 and
FTN2 peaks, and the batch sampler's gyro (ISBH/ISBD) raw (pre-filter) and filtered
(post-filter: what the rate controllers read) through its own spectrum. ``fly`` flies the
documented mission (scripts/ardupilot_sitl.py) twice in Dryden turbulence with the
autopilot's IMU on the wing (scripts/aircraft/bioflex_optimised_wing_imu.toml): first with
the FFT and no notch, then with the notch set at the frequency ArduPlane's FFT found; it
prints one JSON document (the two analyses, ``bioflex-jsb modes``' first wing mode, the
FFT's error against it, the notch's attenuation in dB) and draws the figure.

Exit status: 0 done; 1 a flight did not complete its mission or a log holds no batch in
turbulence; 2 bad input (one line on stderr).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
AIRCRAFT = REPO / "scripts" / "aircraft" / "bioflex_optimised_wing_imu.toml"
SPEED_M_S = 15.0  # the prototype's cruise (Table 1), the trim and launcher exit speed
# Dryden vertical turbulence (MIL-F-8785C form, simulation/gusts.py): sigma 1.5 m/s is
# "moderate" at low altitude (MIL-F-8785C Fig. 10 gives 1.5-3 m/s at 60 m for moderate),
# scale 50 m (of the order of the altitude flown, 60 m); seed fixed: both flights meet the
# same turbulence in time (ArduPlane's closed loop makes the paths differ).
TURBULENCE = "dryden:1.5:50:7"
TURBULENCE_AT_S = 10.0  # turbulence starts this long after the launch [s], for good
# The co-simulation step: ArduPilot's SITL IMU (AP_InertialSensor_SITL, INS_SITL_SENSOR_A
# = 1000 Hz) takes one sample per physics frame and labels them 1 kHz, so the frames must
# be 1 ms for the FFT, the notch and the batch's sample rate to be true (at the default
# 1/960 s every frequency would read 1000/960 = 4.2 % high).
DT_S = 0.001
SETTLE_S = 3.0  # batches are used from this long after the turbulence starts [s]
LAUNCH_SPEED_M_S = 10.0  # the launch is when the GPS ground speed first passes this [m/s]
# ArduPilot's IMU_SENSOR_TYPE (AP_InertialSensor.h): ISBH.type of a gyro batch
GYRO_TYPE = 1
# The FFT (libraries/AP_GyroFFT): a 256-sample window at the 1 kHz gyro rate, 3.9 Hz bins
# (the peak is interpolated between them), searched from FFT_MINHZ (20 Hz: the parameter's
# lowest; the rigid modes, < 2 Hz, well below) to FFT_MAXHZ 60 Hz: the first wing mode
# (42.0 Hz at 15 m/s) inside, the second (77.7 Hz, bioflex-jsb modes) outside. Searched up
# to 100 Hz in the first ArduPlane flight, the FFT reported the second mode (77.75 Hz),
# the stronger of the two in the closed loop's pitch gyro (docs/ardupilot.md).
FFT_WINDOW = 256
FFT_MIN_HZ, FFT_MAX_HZ = 20, 60
# The batch sampler (libraries/AP_InertialSensor/BatchSampler.cpp): 1024 samples per batch,
# IMU 1, option 4 = pre- and post-filter batches in turn.
BATCH_COUNT = 1024
BATCH_PRE_AND_POST = 4
# The harmonic notch: fixed mode (INS_HNTCH_MODE 0, INS_HNTCH_REF 0: the frequency is
# INS_HNTCH_FREQ), the first harmonic only (HMNCS 1: the second wing mode is not a harmonic
# of the first), bandwidth half the centre frequency and 40 dB deep (ArduPilot's defaults
# are BW = FREQ/2 and ATT 40: INS_HNTCH_FREQ 80, _BW 40, _ATT 40 in HarmonicNotchFilter.cpp).
NOTCH_BW_FRACTION = 0.5
NOTCH_ATT_DB = 40.0
# The autopilot IMU's place from the CG for the EKF [m, body FRD]: the definition's wing
# station (0.10 m out, 0.0146 m ahead of the CG; the lever arm itself is in what the backend
# sends, so SIM_IMU_POS stays 0).
IMU_POS_M = (0.015, 0.10, 0.0)
# Where the mode is searched in the logged spectra [Hz]: around the first wing mode, below
# the second (77.7 Hz)
SEARCH_HZ = (30.0, 60.0)
NFFT_PAD = 8  # zero padding of each batch's transform (finer grid for the peak)
# The mode's band for the attenuation figure: ±2 bins of a batch (BATCH_COUNT samples at
# 1 kHz: ±1.95 Hz), the Hann window's main lobe, the finest the spectra resolve; the mode's
# own half-power band (±ζ f = ±0.74 Hz at ζ 0.0175, bioflex-jsb modes) is inside it.
BAND_BINS = 2


class ScriptError(Exception):
    """One line for the user."""


# ---------------------------------------------------------------- the spectral analysis

def amplitude_spectrum(segments: list[np.ndarray], fs_hz: float, pad: int = NFFT_PAD):
    """The mean amplitude spectrum of equal-length ``segments`` (each Hann-windowed, mean
    removed, zero-padded ``pad`` times): (frequencies [Hz], amplitude [unit of the signal]).
    The power of the segments is averaged, then its root taken; a sine of amplitude A
    reads A at its frequency (the window's coherent gain divided out)."""
    if not segments:
        raise ScriptError("no samples to transform")
    n = len(segments[0])
    if any(len(s) != n for s in segments) or n < 8:
        raise ScriptError("segments must share one length of at least 8 samples")
    w = np.hanning(n)
    nfft = pad * n
    power = np.zeros(nfft // 2 + 1)
    for s in segments:
        x = np.asarray(s, dtype=float)
        power += np.abs(np.fft.rfft((x - x.mean()) * w, nfft)) ** 2
    amp = np.sqrt(power / len(segments)) * 2.0 / w.sum()
    return np.fft.rfftfreq(nfft, 1.0 / fs_hz), amp


def spectral_peak(freq_hz: np.ndarray, amp: np.ndarray, band_hz: tuple[float, float]):
    """The largest peak of ``amp`` inside ``band_hz``: (frequency [Hz], amplitude), the
    frequency refined by a parabola through the log amplitudes of the three bins around it
    (exact for a Gaussian-shaped peak; a Hann-windowed sine's main lobe is close to one)."""
    lo, hi = band_hz
    idx = np.flatnonzero((freq_hz >= lo) & (freq_hz <= hi))
    if idx.size < 3:
        raise ScriptError(f"the band {lo:g}..{hi:g} Hz holds fewer than 3 bins")
    i = idx[np.argmax(amp[idx])]
    if i == idx[0] or i == idx[-1] or amp[i] <= 0:
        return float(freq_hz[i]), float(amp[i])
    a, b, c = np.log(amp[i - 1:i + 2])
    den = a - 2 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    df = freq_hz[1] - freq_hz[0]
    return float(freq_hz[i] + delta * df), float(math.exp(b - 0.25 * (a - c) * delta))


def amplitude_at(freq_hz: np.ndarray, amp: np.ndarray, f_hz: float) -> float:
    """The amplitude at ``f_hz`` (linear between the grid's bins)."""
    return float(np.interp(f_hz, freq_hz, amp))


def band_rms(freq_hz: np.ndarray, amp: np.ndarray, f_hz: float, half_width_hz: float) -> float:
    """The root of the summed power within ``half_width_hz`` of ``f_hz`` (same units and
    grid on both sides of a ratio: the band's share of the signal)."""
    m = np.abs(freq_hz - f_hz) <= half_width_hz
    return float(np.sqrt(np.sum(amp[m] ** 2)))


def db(ratio: float) -> float:
    return 20.0 * math.log10(ratio)


# ---------------------------------------------------------------- parameters

def fft_parameters() -> dict[str, float]:
    """The FFT, the batch sampler and the IMU's place (module constants: their sources)."""
    return {
        "FFT_ENABLE": 1, "FFT_MINHZ": FFT_MIN_HZ, "FFT_MAXHZ": FFT_MAX_HZ,
        "FFT_WINDOW_SIZE": FFT_WINDOW, "FFT_SAMPLE_MODE": 0,
        "INS_LOG_BAT_MASK": 1, "INS_LOG_BAT_OPT": BATCH_PRE_AND_POST,
        "INS_LOG_BAT_CNT": BATCH_COUNT,
        "INS_POS1_X": IMU_POS_M[0], "INS_POS1_Y": IMU_POS_M[1], "INS_POS1_Z": IMU_POS_M[2],
    }


def notch_parameters(freq_hz: float, bandwidth_hz: float | None = None,
                     attenuation_db: float = NOTCH_ATT_DB) -> dict[str, float]:
    """A fixed harmonic notch on the first harmonic at ``freq_hz`` [Hz]."""
    if not (math.isfinite(freq_hz) and 10.0 <= freq_hz <= 495.0):
        raise ScriptError(f"notch frequency must be 10..495 Hz, got {freq_hz:g}")
    bw = NOTCH_BW_FRACTION * freq_hz if bandwidth_hz is None else bandwidth_hz
    return {"INS_HNTCH_ENABLE": 1, "INS_HNTCH_MODE": 0, "INS_HNTCH_REF": 0,
            "INS_HNTCH_FREQ": round(freq_hz, 2), "INS_HNTCH_BW": round(bw, 2),
            "INS_HNTCH_ATT": attenuation_db, "INS_HNTCH_HMNCS": 1}


def render_parm(params: dict[str, float], header: str) -> str:
    """ArduPilot's parameter file format: ``NAME value`` a line, ``#`` comments."""
    lines = [f"# {line}" for line in header.splitlines()]
    lines += [f"{name:<18}{value:g}" for name, value in params.items()]
    return "\n".join(lines) + "\n"


def write_new(path: Path, text: str, force: bool) -> None:
    """Write ``text`` to ``path``, never over an existing file without ``force``."""
    if path.exists() and not force:
        raise ScriptError(f"{path} exists (--force replaces it)")
    path.write_text(text)


# ---------------------------------------------------------------- the dataflash log

def read_log(path: Path) -> dict:
    """FTN1, FTN2 (peak 0), GPS speed and the gyro batches of a dataflash log."""
    from pymavlink import DFReader

    if not path.is_file():
        raise ScriptError(f"{path}: no such log")
    log = DFReader.DFReader_binary(str(path), zero_time_base=False)
    out: dict = {"ftn1": [], "ftn2": [], "gps": [], "arsp": [], "batches": [], "params": {}}
    batch = None
    while True:
        m = log.recv_match(type=["ISBH", "ISBD", "FTN1", "FTN2", "GPS", "ARSP", "PARM"])
        if m is None:
            break
        kind = m.get_type()
        if kind == "ISBH":
            batch = None
            if m.type == GYRO_TYPE:
                batch = {"seq": m.N, "instance": m.instance, "mul": float(m.mul),
                         "count": m.smp_cnt, "t0_s": m.SampleUS * 1e-6,
                         "rate_hz": float(m.smp_rate), "x": [], "y": [], "z": [], "next": 0}
                out["batches"].append(batch)
        elif kind == "ISBD" and batch is not None and m.N == batch["seq"]:
            if m.seqno != batch["next"]:
                batch["holes"] = True  # a lost ISBD: the batch is not contiguous
            batch["next"] = m.seqno + 1
            for axis in "xyz":
                batch[axis].extend(getattr(m, axis))
        elif kind == "FTN1":
            out["ftn1"].append((m.TimeUS * 1e-6, m.PkAvg))
        elif kind == "FTN2" and m.Id == 0:
            out["ftn2"].append((m.TimeUS * 1e-6, m.PkX, m.PkY, m.PkZ))
        elif kind == "GPS":
            out["gps"].append((m.TimeUS * 1e-6, m.Spd))
        elif kind == "ARSP":
            out["arsp"].append((m.TimeUS * 1e-6, m.Airspeed))
        elif kind == "PARM":
            out["params"][m.Name] = m.Value
    return out


def launch_time_s(gps: list[tuple[float, float]]) -> float | None:
    """The first time [s, log time] the GPS ground speed passes LAUNCH_SPEED_M_S."""
    return next((t for t, v in gps if v > LAUNCH_SPEED_M_S), None)


def split_batches(batches: list[dict], from_s: float):
    """Complete gyro batches from ``from_s`` on, (pre-filter, post-filter): ArduPilot logs
    a post-filter batch of IMU i as instance i + the gyro count (Write_ISBH), so with IMU 1
    only (INS_LOG_BAT_MASK 1) instance 0 is raw and any other the filtered gyro."""
    pre, post = [], []
    for b in batches:
        if b.get("holes") or len(b["x"]) != b["count"] or b["t0_s"] < from_s:
            continue
        arr = np.array([b["x"], b["y"], b["z"]], dtype=float) / b["mul"]  # rad/s
        (pre if b["instance"] == 0 else post).append((b["rate_hz"], arr))
    return pre, post


def _analysis_start_s(path: Path, log: dict, from_s: float | None,
                      turbulence_at_s: float) -> float:
    """``from_s``, or SETTLE_S after the turbulence (``turbulence_at_s`` after the launch)."""
    if from_s is not None:
        return from_s
    launch = launch_time_s(log["gps"])
    if launch is None:
        raise ScriptError(f"{path}: no launch (GPS speed never above "
                          f"{LAUNCH_SPEED_M_S:g} m/s)")
    return launch + turbulence_at_s + SETTLE_S


def _airspeed_report(log: dict, from_s: float) -> dict:
    """The airspeed's median and 5-95 % range [m/s] from ``from_s`` (None without ARSP)."""
    arsp = np.array([v for t, v in log["arsp"] if t >= from_s])
    return {"airspeed_m_s_median": float(np.median(arsp)) if arsp.size else None,
            "airspeed_m_s_p5_p95": (np.percentile(arsp, [5, 95]).tolist()
                                    if arsp.size else None)}


def _filtered_report(pre_spectrum, post_spectrum, peak_hz: float, rate: float) -> dict:
    """The filtered gyro against the raw at the raw peak and over its ±BAND_BINS bins."""
    f, a = pre_spectrum
    fp, ap = post_spectrum
    at = amplitude_at(fp, ap, peak_hz)
    half = BAND_BINS * rate / BATCH_COUNT
    return {"filtered_at_peak_rad_s": at,
            "filtered_over_raw_db": db(at / amplitude_at(f, a, peak_hz)),
            "band_hz": [peak_hz - half, peak_hz + half],
            "band_filtered_over_raw_db": db(band_rms(fp, ap, peak_hz, half)
                                            / band_rms(f, a, peak_hz, half))}


def _fft_report(log: dict, from_s: float) -> dict:
    """ArduPlane's FFT peaks (FTN2 peak 0 per axis, FTN1's average), medians from
    ``from_s``; the FFT holds FFT_MINHZ while it sees no peak above FFT_SNR_REF: those
    frames are left out and counted."""
    late = [row for row in log["ftn2"] if row[0] >= from_s and row[2] > FFT_MIN_HZ + 0.01]
    late1 = [row for row in log["ftn1"] if row[0] >= from_s and row[1] > FFT_MIN_HZ + 0.01]
    out: dict = {"fft_frames_without_peak": sum(
        1 for row in log["ftn2"] if row[0] >= from_s and row[2] <= FFT_MIN_HZ + 0.01)}
    if late:
        out["fft_ftn2_pitch_peak_hz_median"] = float(np.median([r[2] for r in late]))
        out["fft_ftn2_roll_peak_hz_median"] = float(np.median([r[1] for r in late]))
        out["fft_ftn2_samples"] = len(late)
    if late1:
        out["fft_ftn1_pkavg_hz_median"] = float(np.median([r[1] for r in late1]))
    return out


def _errors_against_mode(result: dict, mode_hz: float) -> dict:
    """The raw peak's and the FFT's errors [%] against the mode's frequency ``mode_hz``."""
    out = {"mode_hz": mode_hz,
           "raw_peak_error_pct": 100.0 * (result["raw_peak_hz"] / mode_hz - 1.0)}
    if "fft_ftn2_pitch_peak_hz_median" in result:
        out["fft_error_pct"] = 100.0 * (result["fft_ftn2_pitch_peak_hz_median"] / mode_hz - 1.0)
    return out


def analyse(path: Path, from_s: float | None = None, mode_hz: float | None = None,
            turbulence_at_s: float = TURBULENCE_AT_S) -> dict:
    """The FFT's peaks and the batch spectra of a log, from ``from_s`` [s, log time] (None:
    SETTLE_S after the turbulence, ``turbulence_at_s`` after the launch)."""
    log = read_log(path)
    from_s = _analysis_start_s(path, log, from_s, turbulence_at_s)
    pre, post = split_batches(log["batches"], from_s)
    if not pre:
        raise ScriptError(f"{path}: no complete raw gyro batch after {from_s:.1f} s "
                          "(INS_LOG_BAT_MASK, INS_LOG_BAT_OPT?)")
    rate = pre[0][0]
    result: dict = {"log": str(path), "from_s": from_s, "batch_rate_hz": rate,
                    **_airspeed_report(log, from_s),
                    "batches_pre": len(pre), "batches_post": len(post),
                    "notch": {k: v for k, v in log["params"].items()
                              if k.startswith("INS_HNTCH_") or k == "INS_GYRO_FILTER"}}
    spectra = {name: amplitude_spectrum([arr[1] for _, arr in group], rate)  # pitch (y)
               for name, group in (("pre", pre), ("post", post)) if group}
    peak_hz, peak_amp = spectral_peak(*spectra["pre"], SEARCH_HZ)
    result["raw_peak_hz"] = peak_hz
    result["raw_peak_rad_s"] = peak_amp
    if "post" in spectra:
        result.update(_filtered_report(spectra["pre"], spectra["post"], peak_hz, rate))
    result.update(_fft_report(log, from_s))
    if mode_hz is not None:
        result.update(_errors_against_mode(result, mode_hz))
    result["_spectra"] = spectra
    return result


# ---------------------------------------------------------------- ArduPilot's gyro filters

# ArduPlane's gyro low-pass default [Hz]: INS_GYRO_FILTER, DEFAULT_GYRO_FILTER 20
# (libraries/AP_InertialSensor/AP_InertialSensor.cpp, 90700977c553)
GYRO_FILTER_HZ = 20.0


def notch_coefficients(fs_hz: float, f0_hz: float, bandwidth_hz: float,
                       attenuation_db: float):
    """ArduPilot's notch biquad (libraries/Filter/NotchFilter.cpp, calculate_A_and_Q and
    init_with_A_and_Q, 90700977c553): (b0, b1, b2, a1, a2), normalised by a0. Its gain at
    ``f0_hz`` is A² = 10^(−attenuation/20)."""
    A = 10.0 ** (-attenuation_db / 40.0)
    octaves = math.log2(f0_hz / (f0_hz - bandwidth_hz / 2.0)) * 2.0
    Q = math.sqrt(2.0 ** octaves) / (2.0 ** octaves - 1.0)
    omega = 2.0 * math.pi * f0_hz / fs_hz
    alpha = math.sin(omega) / (2.0 * Q)
    a0 = 1.0 + alpha
    return ((1.0 + alpha * A * A) / a0, -2.0 * math.cos(omega) / a0,
            (1.0 - alpha * A * A) / a0, -2.0 * math.cos(omega) / a0, (1.0 - alpha) / a0)


def lowpass_coefficients(fs_hz: float, cutoff_hz: float):
    """ArduPilot's LowPassFilter2p biquad (libraries/Filter/LowPassFilter2p.cpp,
    compute_params: a Butterworth pair by the bilinear transform, prewarped):
    (b0, b1, b2, a1, a2)."""
    cutoff_hz = min(cutoff_hz, 0.4 * fs_hz)
    ohm = math.tan(math.pi * cutoff_hz / fs_hz)
    c = 1.0 + 2.0 * math.cos(math.pi / 4.0) * ohm + ohm * ohm
    b0 = ohm * ohm / c
    return (b0, 2.0 * b0, b0, 2.0 * (ohm * ohm - 1.0) / c,
            (1.0 - 2.0 * math.cos(math.pi / 4.0) * ohm + ohm * ohm) / c)


def biquad(coeffs, x: np.ndarray) -> np.ndarray:
    """Apply (b0, b1, b2, a1, a2) to ``x``, started at rest on its first sample as
    ArduPilot's filters start."""
    b0, b1, b2, a1, a2 = coeffs
    y = np.empty(len(x))
    x1 = x2 = y1 = y2 = float(x[0])
    for i, xi in enumerate(np.asarray(x, dtype=float)):
        yi = b0 * xi + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2
        x2, x1, y2, y1 = x1, xi, y1, yi
        y[i] = yi
    return y


def gain_db(coeffs, f_hz: float, fs_hz: float) -> float:
    """|H(e^{jω})| of a biquad at ``f_hz`` [dB]."""
    b0, b1, b2, a1, a2 = coeffs
    z = np.exp(-1j * 2.0 * math.pi * f_hz / fs_hz)
    return db(abs((b0 + b1 * z + b2 * z * z) / (1.0 + a1 * z + a2 * z * z)))


# ---------------------------------------------------------------- the stand-in flight

def standin_gyro(duration_s: float, turbulence_at_s: float = 2.0) -> tuple[float, np.ndarray]:
    """Fly ``bioflex-jsb ardupilot`` against the CI stand-in of ArduPilot's JSON side
    (tests/ardupilot_standin.py): the launch switch, then trim servos held (no autopilot
    closes the loop) through the turbulence; the pitch gyro ArduPilot would have received
    in flight from the turbulence on, at the frame rate 1/DT_S: (rate [Hz], samples
    [rad/s])."""
    import socket
    import time

    sys.path.insert(0, str(REPO / "tests"))
    from ardupilot_standin import ArduPilotStandin

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    cmd = [sys.executable, "-m", "bioflex_jsb", "ardupilot", "--aircraft", str(AIRCRAFT),
           "--model", "coupled", "--dt", f"{DT_S:g}", "--gust", TURBULENCE,
           "--gust-at", f"{turbulence_at_s:g}", "--port", str(port), "--no-log",
           "--end-when-silent", "1"]
    server = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        sa = ArduPilotStandin(("127.0.0.1", port), timeout_s=60.0)
        launch = [1500, 1500, 1000, 1500, 1900] + [0] * 11
        trim = [1500, 1500, 1130, 1500, 1000] + [0] * 11  # throttle 13 %: the parm's trim
        gyro, t_flight = [], None
        while True:
            pwm = launch if t_flight is None else trim
            sa.send_servos(pwm)
            try:
                st = sa.receive()
            except TimeoutError:
                continue  # the server still building its step: ArduPilot re-sends
            if st is None:
                continue
            v = st.values
            speed = math.hypot(*v["velocity"][:2])
            if t_flight is None and speed > LAUNCH_SPEED_M_S:
                t_flight = float(v["timestamp"])
            if t_flight is not None:
                t = float(v["timestamp"]) - t_flight
                if t >= turbulence_at_s + SETTLE_S:
                    gyro.append(v["gyro"][1])  # pitch rate, FRD [rad/s]
                if t >= duration_s:
                    break
        sa.close()
        time.sleep(0.1)
    finally:
        server.terminate()
        server.wait(timeout=30)
    return 1.0 / DT_S, np.asarray(gyro)


def standin_report(duration_s: float, plot: Path | None) -> dict:
    """The stand-in's analysis: the raw gyro's peak against ``modes``, then ArduPilot's own
    filter chain (notch at that peak, then INS_GYRO_FILTER's low-pass, ported above) on it:
    the notch's attenuation at the mode."""
    mode_hz = first_wing_mode_hz()
    fs, raw = standin_gyro(duration_s)
    seg = BATCH_COUNT
    pieces = [raw[i:i + seg] for i in range(0, len(raw) - seg + 1, seg)]
    f, a = amplitude_spectrum(pieces, fs)
    peak_hz, peak_amp = spectral_peak(f, a, SEARCH_HZ)
    n = notch_parameters(peak_hz)
    notch = notch_coefficients(fs, n["INS_HNTCH_FREQ"], n["INS_HNTCH_BW"], n["INS_HNTCH_ATT"])
    lpf = lowpass_coefficients(fs, GYRO_FILTER_HZ)
    lp_only = biquad(lpf, raw)
    both = biquad(lpf, biquad(notch, raw))
    spectra = {}
    for name, x in (("lpf", lp_only), ("notch", both)):
        spectra[name] = amplitude_spectrum(
            [x[i:i + seg] for i in range(0, len(x) - seg + 1, seg)], fs)
    at = {k: amplitude_at(*v, peak_hz) for k, v in spectra.items()}
    raw_at = amplitude_at(f, a, peak_hz)
    half = BAND_BINS * fs / seg
    band = {k: band_rms(*v, peak_hz, half) for k, v in spectra.items()}
    report = {
        "autopilot": "tests/ardupilot_standin.py (no ArduPlane: trim servos, open loop)",
        "aircraft": str(AIRCRAFT.relative_to(REPO)), "turbulence": TURBULENCE, "dt_s": DT_S,
        "samples": int(len(raw)), "batches": len(pieces),
        "modes_aeroelastic_1_hz": mode_hz, "raw_peak_hz": peak_hz,
        "raw_peak_rad_s": peak_amp, "raw_peak_error_pct": 100.0 * (peak_hz / mode_hz - 1.0),
        "notch": n,
        "lowpass_over_raw_db": db(at["lpf"] / raw_at),
        "lowpass_and_notch_over_raw_db": db(at["notch"] / raw_at),
        "notch_attenuation_at_peak_db": db(at["notch"] / at["lpf"]),
        "band_hz": [peak_hz - half, peak_hz + half],
        "notch_attenuation_band_db": db(band["notch"] / band["lpf"]),
        "lowpass_and_notch_over_raw_band_db": db(band["notch"] / band_rms(f, a, peak_hz, half)),
        "notch_gain_at_peak_closed_form_db": gain_db(notch, peak_hz, fs),
        "lowpass_gain_at_peak_closed_form_db": gain_db(lpf, peak_hz, fs),
    }
    if plot is not None:
        res_a = {"_spectra": {"pre": (f, a), "post": spectra["lpf"]}}
        res_b = {"_spectra": {"pre": (f, a), "post": spectra["notch"]}}
        figure(plot, mode_hz, res_a, res_b,
               suptitle="Stand-in (no ArduPlane): autopilot IMU on the wing centre box, "
                        "Dryden 1.5 m/s; ArduPilot's notch and low-pass ported",
               post_label="filtered (ArduPilot's filter chain, ported)")
        report["figure"] = str(plot)
    return report


# ---------------------------------------------------------------- the flights

def first_wing_mode_hz(aircraft: Path = AIRCRAFT, speed_m_s: float = SPEED_M_S) -> float:
    """``bioflex-jsb modes``' aeroelastic_1 of the coupled model [Hz, damped: im / 2π]."""
    out = subprocess.run([sys.executable, "-m", "bioflex_jsb", "modes", "--aircraft",
                          str(aircraft), "--speed", f"{speed_m_s:g}", "--json"],
                         capture_output=True, text=True, check=True).stdout
    for res in json.loads(out)["results"]:
        if res["model"] == "coupled":
            for m in res["modes"]:
                if m["mode"] == "aeroelastic_1":
                    return m["im"] / (2 * math.pi)
    raise ScriptError("bioflex-jsb modes gave no aeroelastic_1")


def physics_command() -> str:
    return (f"{sys.executable} -m bioflex_jsb ardupilot --aircraft {AIRCRAFT} "
            f"--model coupled --dt {DT_S:g} --gust {TURBULENCE} --gust-at {TURBULENCE_AT_S:g} "
            "--end-when-silent 2 --summary physics.json --no-log")


def fly_once(ap: Path, out: Path, params: dict, speedup: float) -> tuple[dict, Path]:
    """One mission with ``params`` added; (the flight script's summary, the log)."""
    out.mkdir(parents=True, exist_ok=True)
    parm = out / "fft.parm"
    write_new(parm, render_parm(params, "scripts/ardupilot_fft.py"), force=True)
    cmd = [sys.executable, str(REPO / "scripts" / "ardupilot_sitl.py"), "fly", str(ap),
           "--out", str(out), "--speedup", f"{speedup:g}", "--physics-cmd",
           physics_command(), "--defaults", str(parm)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    (out / "fly.json").write_text(res.stdout)
    (out / "fly.stderr").write_text(res.stderr)
    if res.returncode == 2:
        raise ScriptError(f"the flight could not run: {res.stderr.strip()}")
    summary = json.loads(res.stdout) if res.stdout.strip() else {}
    logs = sorted((out / "logs").glob("*.BIN"), key=os.path.getmtime)
    if not logs:
        raise ScriptError(f"{out}: ArduPlane wrote no dataflash log")
    return summary, logs[-1]


def figure(path: Path, mode_hz: float, a: dict, b: dict,
           suptitle: str = "ArduPlane SITL, autopilot IMU on the wing centre box, Dryden "
                           "1.5 m/s: pitch gyro spectra",
           post_label: str = "filtered gyro (batch, post-filter: rate controllers' input)"
           ) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), sharey=True)
    for ax, res, title in ((axes[0], a, "without notch (INS_GYRO_FILTER low-pass only)"),
                           (axes[1], b, "with the harmonic notch")):
        for key, style, label in (("pre", "-", "raw gyro (pre-filter)"),
                                  ("post", "-", post_label)):
            if key in res["_spectra"]:
                f, amp = res["_spectra"][key]
                ax.semilogy(f, np.maximum(amp, 1e-7), style, lw=1, label=label)
        ax.axvline(mode_hz, color="k", ls="--", lw=1,
                   label=f"bioflex-jsb modes aeroelastic_1 {mode_hz:.2f} Hz")
        if "fft_ftn2_pitch_peak_hz_median" in res:
            ax.axvline(res["fft_ftn2_pitch_peak_hz_median"], color="r", ls=":", lw=1.5,
                       label=f"ArduPlane FFT (FTN2 pitch, median) "
                             f"{res['fft_ftn2_pitch_peak_hz_median']:.2f} Hz")
        ax.set_xlim(0, 120)
        ax.set_ylim(bottom=1e-5)
        ax.set_xlabel("frequency [Hz]")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    axes[0].set_ylabel("pitch gyro amplitude [rad/s]")
    fig.suptitle(suptitle, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def public(res: dict) -> dict:
    return {k: v for k, v in res.items() if not k.startswith("_")}


def fly(ap: Path, out: Path, speedup: float, plot: Path | None) -> dict:
    mode_trim_hz = first_wing_mode_hz()
    base = fft_parameters()
    s_a, log_a = fly_once(ap, out / "no_notch", base, speedup)
    a = analyse(log_a)
    # the mode at the airspeed ArduPlane flew (its ARSP median in the turbulence): the first
    # wing mode rises 1.3 Hz per m/s near 15 m/s (bioflex-jsb modes: 42.02, 43.30, 44.62 Hz
    # at 15, 16, 17 m/s)
    flown = round(a["airspeed_m_s_median"], 2)
    mode_hz = first_wing_mode_hz(speed_m_s=flown)
    a = analyse(log_a, mode_hz=mode_hz)
    fft_hz = a.get("fft_ftn2_pitch_peak_hz_median")
    if fft_hz is None:
        raise ScriptError(f"{log_a}: ArduPlane's FFT logged no peak (FTN2) in turbulence")
    notch = notch_parameters(fft_hz)
    s_b, log_b = fly_once(ap, out / "notch", {**base, **notch}, speedup)
    b = analyse(log_b, mode_hz=mode_hz)
    report = {
        "aircraft": str(AIRCRAFT.relative_to(REPO)), "speed_m_s": SPEED_M_S,
        "turbulence": TURBULENCE, "dt_s": DT_S,
        "modes_aeroelastic_1_hz_at_15_m_s": mode_trim_hz,
        "flown_airspeed_m_s": flown,
        "modes_aeroelastic_1_hz": mode_hz,
        "arduplane_fft_peak_hz": fft_hz,
        "arduplane_fft_error_pct": a.get("fft_error_pct"),
        "raw_batch_peak_hz": a["raw_peak_hz"],
        "raw_batch_peak_error_pct": a["raw_peak_error_pct"],
        "notch": notch,
        "filtered_over_raw_db_without_notch": a.get("filtered_over_raw_db"),
        "filtered_over_raw_db_with_notch": b.get("filtered_over_raw_db"),
        "no_notch": public(a), "with_notch": public(b),
        "missions_complete": [not s_a.get("incomplete", ["?"]), not s_b.get("incomplete", ["?"])],
    }
    if a.get("filtered_over_raw_db") is not None and b.get("filtered_over_raw_db") is not None:
        report["notch_attenuation_at_peak_db"] = (b["filtered_over_raw_db"]
                                                  - a["filtered_over_raw_db"])
        report["notch_attenuation_band_db"] = (b["band_filtered_over_raw_db"]
                                               - a["band_filtered_over_raw_db"])
    if plot is not None:
        figure(plot, mode_hz, a, b)
        report["figure"] = str(plot)
    return report


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("params", help="write the FFT / batch / notch parameter file")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--notch-hz", type=float, default=None)
    p.add_argument("--force", action="store_true")
    a = sub.add_parser("analyse", help="the FFT peaks and gyro spectra of a dataflash log")
    a.add_argument("log", type=Path)
    a.add_argument("--from-s", type=float, default=None)
    a.add_argument("--mode-hz", type=float, default=None)
    f = sub.add_parser("fly", help="two flights (no notch, notch) and the report")
    f.add_argument("ardupilot", type=Path)
    f.add_argument("--out", type=Path, default=Path("ardupilot_fft"))
    f.add_argument("--speedup", type=float, default=1.0)
    f.add_argument("--plot", type=Path, default=None)
    st = sub.add_parser("standin", help="without ArduPlane: the CI stand-in flies, "
                        "ArduPilot's filters ported")
    st.add_argument("--duration", type=float, default=30.0,
                    help="flight after the launch [s] (default 30)")
    st.add_argument("--plot", type=Path, default=None)
    args = parser.parse_args(argv)
    try:
        if args.command == "standin":
            if not (math.isfinite(args.duration) and 10.0 <= args.duration <= 600.0):
                raise ScriptError(f"--duration must be 10..600 s, got {args.duration:g}")
            print(json.dumps(standin_report(args.duration, args.plot), indent=1))
            return 0
        if args.command == "params":
            params = fft_parameters()
            if args.notch_hz is not None:
                params.update(notch_parameters(args.notch_hz))
            write_new(args.out, render_parm(params, "scripts/ardupilot_fft.py params"),
                      args.force)
            return 0
        if args.command == "analyse":
            print(json.dumps(public(analyse(args.log, args.from_s, args.mode_hz)), indent=1))
            return 0
        if not (math.isfinite(args.speedup) and args.speedup > 0):
            raise ScriptError(f"--speedup must be > 0, got {args.speedup:g}")
        report = fly(args.ardupilot.resolve(), args.out.resolve(), args.speedup, args.plot)
        print(json.dumps(report, indent=1))
        return 0 if all(report["missions_complete"]) else 1
    except ScriptError as exc:
        print(f"ardupilot_fft: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
