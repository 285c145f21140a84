"""Continuous turbulence in the frequency domain: the LTI model's frequency response from the
gust to its outputs, output PSDs under the von Kármán (or Dryden) spectrum, RMS and the
characteristic frequency N₀, against Welch estimates from long nonlinear runs.

Definitions (one-sided spectra, frequency f [Hz]):

* gust: S_w(f) = Φ_w(Ω = 2π f/V) · 2π/V [(m/s)²/Hz], Φ_w of :func:`bioflex_jsb.simulation.
  gusts.turbulence_psd` (frozen turbulence swept at the trim airspeed V, as the runs fly it);
* response: H_y(f) = C_y (j2πf I − A)⁻¹ B_w + D_y, S_y = |H_y|² S_w;
* RMS σ_y = (∫ S_y df)^½ and N₀ = (∫ f² S_y df / ∫ S_y df)^½ [Hz], the expected rate of
  up-crossings of the mean (Rice), both over the band F_MIN_HZ..f_max. The upper limit is
  needed: with quasi-steady strips an output that the gust drives directly (n_z, the force
  summation's loads: the D term) has S_y ∝ f^(−5/3) at high frequency, whose second moment
  diverges, so N₀ of such an output is a property of the band (the default f_max is above
  the third wing mode, 107 Hz, and below the runs' Nyquist frequency).

Welch estimates (``scipy.signal.welch``, Hann segments, 50 % overlap) carry a 95 % band from
the χ² distribution with ν = 2 K degrees of freedom, K the number of *non-overlapping*
segments in the record (conservative: overlapping Hann segments add about 1.9× that).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.flight_dynamics.lti import StateSpace
from bioflex_jsb.simulation.gusts import turbulence_psd

F_MIN_HZ = 0.02  # lowest frequency of the band [Hz]: below the phugoid (≈ 0.1 Hz at 15 m/s)
DEFAULT_F_MAX_HZ = 150.0  # highest [Hz]: above the third wing mode (107 Hz), below Nyquist
OUTPUT_LABELS = {"q": "pitch rate q", "n_z": "load factor increment Δn_z",
                 "fs_bending_n_m_s0": "root bending moment M (FS)"}
N_FREQUENCIES = 4000  # log-spaced points of the analytic spectra (integrals to < 1e-4)


def frequency_grid_hz(f_max_hz: float = DEFAULT_F_MAX_HZ, n: int = N_FREQUENCIES) -> np.ndarray:
    return np.geomspace(F_MIN_HZ, f_max_hz, n)


def frequency_response(ss: StateSpace, outputs, f_hz: np.ndarray, input_name: str = "w_g"
                       ) -> np.ndarray:
    """H (len(outputs), len(f)) complex, per unit of the input (``w_g`` [m/s])."""
    rows = [ss.outputs.index(o) for o in outputs]
    iw = ss.inputs.index(input_name)
    c, b, d = ss.c[rows], ss.b[:, iw], ss.d[rows, iw]
    n = ss.n_states
    out = np.empty((len(rows), f_hz.size), dtype=complex)
    eye = np.eye(n)
    for k, f in enumerate(f_hz):
        x = np.linalg.solve(2j * math.pi * f * eye - ss.a, b)
        out[:, k] = c @ x + d
    return out


def gust_psd_hz(kind: str, f_hz: np.ndarray, sigma_m_s: float, scale_m: float,
                speed_m_s: float) -> np.ndarray:
    """Temporal one-sided gust PSD S_w(f) [(m/s)²/Hz] (module docstring)."""
    omega = 2.0 * math.pi * np.asarray(f_hz) / speed_m_s
    return turbulence_psd(kind, omega, sigma_m_s, scale_m) * 2.0 * math.pi / speed_m_s


def spectral_moments(f_hz: np.ndarray, psd: np.ndarray, f_max_hz: float,
                     f_min_hz: float = F_MIN_HZ) -> tuple[float, float]:
    """(RMS, N₀ [Hz]) of a one-sided PSD over ``f_min_hz``..``f_max_hz`` (trapezoid rule)."""
    keep = (f_hz >= f_min_hz) & (f_hz <= f_max_hz)
    f, s = f_hz[keep], psd[..., keep]
    m0 = np.trapezoid(s, f, axis=-1)
    m2 = np.trapezoid(s * f**2, f, axis=-1)
    return np.sqrt(m0), np.sqrt(m2 / m0)


@dataclass
class SpectralComparison:
    """One turbulence case: the LTI's PSD per output on ``f_hz``, its RMS (F_MIN_HZ..f_max)
    and N₀; the
    nonlinear run's Welch PSD on ``welch_f_hz`` with its 95 % band (``band_lo``,
    ``band_hi`` multiply the estimate), its RMS over its bins (from 1/segment) and N₀;
    both N₀ from the check band's lower end to f_max; ``in_band`` the
    fraction of Welch bins within ``check_band_hz`` whose LTI value lies in the band;
    ``lti_rms_band``, ``run_rms_band`` both RMS from the check band's lower end to f_max
    (the Welch segments resolve nothing below 1/segment: the phugoid's share of the
    full-band RMS is the LTI's alone)."""

    outputs: tuple[str, ...]
    units: tuple[str, ...]
    sigma_m_s: float
    scale_m: float
    kind: str
    f_hz: np.ndarray
    lti_psd: np.ndarray
    lti_rms: np.ndarray
    lti_n0_hz: np.ndarray
    welch_f_hz: np.ndarray
    welch_psd: np.ndarray
    band_lo: float
    band_hi: float
    run_rms: np.ndarray
    run_n0_hz: np.ndarray
    in_band: np.ndarray
    check_band_hz: tuple[float, float]
    f_max_hz: float
    lti_rms_band: np.ndarray
    run_rms_band: np.ndarray
    stopped: str | None = None

    def as_dict(self) -> dict:
        rows = {}
        for i, (o, u) in enumerate(zip(self.outputs, self.units, strict=True)):
            rows[o] = {"unit": u, "lti_rms": float(self.lti_rms[i]),
                       "lti_n0_hz": float(self.lti_n0_hz[i]), "run_rms": float(self.run_rms[i]),
                       "run_n0_hz": float(self.run_n0_hz[i]),
                       "lti_rms_band": float(self.lti_rms_band[i]),
                       "run_rms_band": float(self.run_rms_band[i]),
                       "rms_ratio_band": float(self.run_rms_band[i] / self.lti_rms_band[i]),
                       "fraction_in_band": float(self.in_band[i])}
        return {"kind": self.kind, "sigma_m_s": self.sigma_m_s, "scale_m": self.scale_m,
                "f_max_hz": self.f_max_hz, "check_band_hz": list(self.check_band_hz),
                "welch_band_95": [self.band_lo, self.band_hi], "outputs": rows,
                "stopped": self.stopped}


def compare_spectra(ss: StateSpace, outputs, units, series: np.ndarray, dt_s: float, *,
                    kind: str, sigma_m_s: float, scale_m: float, speed_m_s: float,
                    segment_s: float = 8.0, f_max_hz: float = DEFAULT_F_MAX_HZ,
                    check_band_hz: tuple[float, float] = (0.25, 100.0),
                    stopped: str | None = None) -> SpectralComparison:
    """The LTI spectra of ``outputs`` against the Welch spectra of ``series`` (samples,
    outputs): the nonlinear run's increments of the same outputs, at step ``dt_s`` [s]."""
    from scipy.signal import welch
    from scipy.stats import chi2

    f = frequency_grid_hz(f_max_hz)
    h = frequency_response(ss, outputs, f)
    s_w = gust_psd_hz(kind, f, sigma_m_s, scale_m, speed_m_s)
    lti_psd = np.abs(h) ** 2 * s_w
    lti_rms, _ = spectral_moments(f, lti_psd, f_max_hz)
    x = np.asarray(series, dtype=float)
    nper = int(round(segment_s / dt_s))
    if x.shape[0] < 2 * nper:
        raise ValueError(f"the record ({x.shape[0] * dt_s:.1f} s) is shorter than two "
                         f"Welch segments of {segment_s:g} s")
    fw, pw = welch(x - x.mean(axis=0), fs=1.0 / dt_s, window="hann", nperseg=nper,
                   noverlap=nper // 2, axis=0, detrend="linear")
    pw = pw.T  # (outputs, freqs)
    nu = 2.0 * math.floor(x.shape[0] / nper)
    lo, hi = nu / chi2.ppf(0.975, nu), nu / chi2.ppf(0.025, nu)
    keep = fw > 0.0
    run_rms, _ = spectral_moments(fw[keep], pw[:, keep], f_max_hz, float(fw[keep][0]))
    sel = (fw >= check_band_hz[0]) & (fw <= check_band_hz[1])
    lti_at = np.array([np.interp(np.log(fw[sel]), np.log(f), lti_psd[i])
                       for i in range(len(outputs))])
    inside = (lti_at >= pw[:, sel] * lo) & (lti_at <= pw[:, sel] * hi)
    fb = check_band_hz[0]
    band_lti, lti_n0 = spectral_moments(f, lti_psd, f_max_hz, fb)
    band_run, run_n0 = spectral_moments(fw, pw, f_max_hz, fb)
    return SpectralComparison(tuple(outputs), tuple(units), sigma_m_s, scale_m, kind, f,
                              lti_psd, lti_rms, lti_n0, fw, pw, float(lo), float(hi), run_rms,
                              run_n0, inside.mean(axis=1), check_band_hz, f_max_hz, band_lti,
                              band_run, stopped)


def plot_bode(ss: StateSpace, outputs, units, path=None, f_max_hz: float = DEFAULT_F_MAX_HZ):
    """Magnitude and phase of H_y(f) per output (per m/s of upward gust)."""
    from bioflex_jsb.loads.plots import new_figure, save

    f = frequency_grid_hz(f_max_hz, 2000)
    h = frequency_response(ss, outputs, f)
    fig, ax = new_figure(2, len(outputs), (4.2 * len(outputs), 6.0))
    for i, (o, u) in enumerate(zip(outputs, units, strict=True)):
        ax[0, i].loglog(f, np.abs(h[i]), color="C0")
        ax[0, i].set_title(OUTPUT_LABELS.get(o, o), fontsize=10)
        ax[0, i].set_ylabel(f"|H| [{u} per m/s]")
        ax[1, i].semilogx(f, np.degrees(np.unwrap(np.angle(h[i]))), color="C0")
        ax[1, i].set_ylabel("phase [deg]")
        ax[1, i].set_xlabel("frequency [Hz]")
        for a in ax[:, i]:
            a.grid(True, which="both", alpha=0.3)
    block = ss.notes.get("rigid_block")
    fig.suptitle(f"Frequency response of the {ss.model} LTI model to an upward gust w_g, "
                 f"{ss.speed_m_s:g} m/s" + (f"; rigid block: {block}" if block else ""),
                 fontsize=10)
    if path is not None:
        save(fig, path)
    return fig


def plot_psd(cases: list[SpectralComparison], path=None):
    """Output PSDs: the LTI's (line) against the nonlinear run's Welch estimate with its
    95 % band (shaded), one row per turbulence case, one column per output."""
    from bioflex_jsb.loads.plots import new_figure, save

    n_out = len(cases[0].outputs)
    fig, ax = new_figure(len(cases), n_out, (4.2 * n_out, 3.4 * len(cases)))
    for r, c in enumerate(cases):
        for i, (o, u) in enumerate(zip(c.outputs, c.units, strict=True)):
            a = ax[r, i]
            keep = (c.welch_f_hz > 0) & (c.welch_f_hz <= c.f_max_hz)
            fw, pw = c.welch_f_hz[keep], c.welch_psd[i, keep]
            a.fill_between(fw, pw * c.band_lo, pw * c.band_hi, color="C1", alpha=0.25, lw=0,
                           label="nonlinear, Welch 95 % band")
            a.loglog(fw, pw, color="C1", lw=0.9, label="nonlinear (Welch)")
            a.loglog(c.f_hz, c.lti_psd[i], color="C0", lw=1.3, label="LTI |H|² S_w")
            a.axvspan(*c.check_band_hz, color="0.9", zorder=-1)
            a.set_title(f"{OUTPUT_LABELS.get(o, o)}, σ_w = {c.sigma_m_s:g} m/s", fontsize=9)
            a.text(0.03, 0.04, f"RMS > {c.check_band_hz[0]:g} Hz: LTI {c.lti_rms_band[i]:.3g}, "
                   f"run {c.run_rms_band[i]:.3g} {u}\nLTI inside the band: "
                   f"{100 * c.in_band[i]:.0f} % of bins", transform=a.transAxes, fontsize=7,
                   bbox={"facecolor": "w", "alpha": 0.8, "lw": 0})
            a.set_ylabel("PSD [1/Hz]" if u == "-" else f"PSD [({u})²/Hz]")
            a.set_xlabel("frequency [Hz]")
            a.grid(True, which="major", alpha=0.3)
    handles, labels = ax[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower center", ncol=3, fontsize=8)
    fig.suptitle(f"{cases[0].kind} turbulence, L = {cases[0].scale_m:g} m: LTI against "
                 "nonlinear co-simulation (grey: the band checked)", fontsize=10)
    if path is not None:
        save(fig, path)
    return fig
