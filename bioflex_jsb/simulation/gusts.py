"""Vertical gusts: sharp-edged, 1-cosine and continuous turbulence (Dryden, von Kármán).

Every gust is a vertical wind velocity w_g(t) [m/s], positive **upward** (it raises the angle
of attack by about w_g/V), uniform over the aircraft: the wing and the tail meet it at the
same instant and the whole span sees the same value. That is what JSBSim's wind input
(``atmosphere/wind-down-fps``, which the JSBSim adapter drives with −w_g) does, and what the
paper's Eq. (4) assumes (one input w_g). Gust penetration along the fuselage and spanwise
variation are not modelled (docs/gusts.md).

Command-line forms (:func:`parse_gust`):

* ``sharp:AMPLITUDE_m_s`` a step of AMPLITUDE at the gust start time;
* ``1cos:AMPLITUDE_m_s:LENGTH_m`` w = A/2 (1 − cos(2π x/L)) while 0 ≤ x ≤ L, x the distance
  flown since the gust start (the gust lasts L/V; the gradient distance is L/2);
* ``dryden:SIGMA_m_s:SCALE_m[:SEED]`` and ``vonkarman:SIGMA_m_s:SCALE_m[:SEED]``: stationary
  vertical turbulence of RMS SIGMA and length scale SCALE (MIL-F-8785C spectra), frozen in
  space (Taylor) and swept at the trim airspeed, synthesised with SEED (default 0) so every
  run is reproducible.
* ``none``: calm air.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.errors import InputError

GUST_FORMS = (
    "sharp:AMPLITUDE_m_s",
    "1cos:AMPLITUDE_m_s:LENGTH_m",
    "dryden:SIGMA_m_s:SCALE_m[:SEED]",
    "vonkarman:SIGMA_m_s:SCALE_m[:SEED]",
    "none",
)
MAX_GUST_M_S = 50.0  # beyond this the small-UAV model is meaningless (3x the cruise speed)


class GustSpecError(InputError):
    """A gust specification that cannot be used; the message says what is accepted."""


@dataclass(frozen=True)
class GustSpec:
    """A parsed gust. ``kind`` is sharp, 1cos, dryden, vonkarman or none.

    amplitude_m_s: step size / 1-cos peak / turbulence RMS σ [m/s]; length_m: 1-cos
    length or turbulence scale [m]; seed: turbulence seed.
    """

    kind: str
    amplitude_m_s: float = 0.0
    length_m: float = 0.0
    seed: int = 0

    def text(self) -> str:
        """The command-line form of this gust."""
        if self.kind == "none":
            return "none"
        if self.kind == "sharp":
            return f"sharp:{self.amplitude_m_s:g}"
        if self.kind == "1cos":
            return f"1cos:{self.amplitude_m_s:g}:{self.length_m:g}"
        return f"{self.kind}:{self.amplitude_m_s:g}:{self.length_m:g}:{self.seed}"


def _number(text: str, what: str, spec: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise GustSpecError(f"gust {spec!r}: {what} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise GustSpecError(f"gust {spec!r}: {what} must be finite, got {text!r}")
    return value


def parse_gust(spec: str) -> GustSpec:
    """Parse a command-line gust; raises :class:`GustSpecError` naming what is accepted."""
    accepted = "accepted forms: " + ", ".join(GUST_FORMS)
    parts = spec.strip().split(":")
    kind = parts[0].lower()
    if kind == "none" and len(parts) == 1:
        return GustSpec("none")
    if kind == "sharp":
        if len(parts) != 2:
            raise GustSpecError(f"gust {spec!r}: sharp takes one value; {accepted}")
        amp = _number(parts[1], "the amplitude [m/s]", spec)
        _check_amplitude(amp, spec)
        return GustSpec("sharp", amp)
    if kind == "1cos":
        if len(parts) != 3:
            raise GustSpecError(f"gust {spec!r}: 1cos takes amplitude and length; {accepted}")
        amp = _number(parts[1], "the amplitude [m/s]", spec)
        length = _number(parts[2], "the gust length [m]", spec)
        _check_amplitude(amp, spec)
        if length <= 0.0:
            raise GustSpecError(f"gust {spec!r}: the gust length must be > 0 m, got {length:g}")
        return GustSpec("1cos", amp, length)
    if kind in ("dryden", "vonkarman"):
        if len(parts) not in (3, 4):
            raise GustSpecError(
                f"gust {spec!r}: {kind} takes SIGMA_m_s:SCALE_m[:SEED]; {accepted}"
            )
        sigma = _number(parts[1], "the RMS intensity sigma [m/s]", spec)
        scale = _number(parts[2], "the length scale [m]", spec)
        if sigma < 0.0 or sigma > MAX_GUST_M_S:
            raise GustSpecError(f"gust {spec!r}: sigma must be 0..{MAX_GUST_M_S:g} m/s")
        if scale <= 0.0:
            raise GustSpecError(f"gust {spec!r}: the length scale must be > 0 m, got {scale:g}")
        seed = 0
        if len(parts) == 4:
            try:
                seed = int(parts[3])
            except ValueError:
                raise GustSpecError(
                    f"gust {spec!r}: the seed must be a whole number, got {parts[3]!r}"
                ) from None
            if seed < 0:
                raise GustSpecError(f"gust {spec!r}: the seed must be ≥ 0")
        return GustSpec(kind, sigma, scale, seed)
    raise GustSpecError(f"unknown gust form {spec!r}; {accepted}")


def _check_amplitude(amp: float, spec: str) -> None:
    if abs(amp) > MAX_GUST_M_S:
        raise GustSpecError(
            f"gust {spec!r}: |amplitude| must be ≤ {MAX_GUST_M_S:g} m/s, got {amp:g}"
        )


def turbulence_psd(kind: str, omega_rad_m: np.ndarray, sigma_m_s: float, scale_m: float):
    """One-sided vertical-turbulence spectrum Φ_w(Ω) [(m/s)²/(rad/m)] (MIL-F-8785C forms).

    Both integrate over Ω ∈ [0, ∞) to σ².
    """
    lw = scale_m * np.asarray(omega_rad_m, dtype=float)
    base = sigma_m_s**2 * scale_m / math.pi
    if kind == "dryden":
        return base * (1.0 + 3.0 * lw**2) / (1.0 + lw**2) ** 2
    if kind == "vonkarman":
        a = 1.339 * lw
        return base * (1.0 + (8.0 / 3.0) * a**2) / (1.0 + a**2) ** (11.0 / 6.0)
    raise ValueError(f"no spectrum for gust kind {kind!r}")


class GustField:
    """w_g(t) [m/s, up] for a gust that starts at ``start_s`` while flying at ``speed_m_s``.

    Turbulence is synthesised once (inverse FFT of the spectrum with seeded random phases,
    resolution ``dt_s``, length ``duration_s``) so repeated runs with the same seed agree
    exactly.
    """

    def __init__(
        self,
        spec: GustSpec,
        speed_m_s: float,
        start_s: float = 0.5,
        duration_s: float = 10.0,
        dt_s: float = 1.0 / 120.0,
    ) -> None:
        self.spec = spec
        self.speed_m_s = float(speed_m_s)
        self.start_s = float(start_s)
        self._series: np.ndarray | None = None
        self._dt = float(dt_s)
        # the first step at or after the start (1e-9 of a step absorbs the rounding of start/Δt)
        self._first_step = max(0, math.ceil(self.start_s / self._dt - 1e-9))
        if spec.kind in ("dryden", "vonkarman"):
            n = int(math.ceil(max(duration_s - start_s, dt_s) / dt_s)) + 2
            n_fft = 1 << max(4, int(math.ceil(math.log2(2 * n))))
            rng = np.random.default_rng(spec.seed)
            freqs_hz = np.fft.rfftfreq(n_fft, d=dt_s)
            omega_spatial = 2.0 * math.pi * freqs_hz / self.speed_m_s  # [rad/m]
            # temporal one-sided PSD [(m/s)²/Hz]: Φ(Ω) dΩ = S(f) df, dΩ = 2π df / V
            psd_hz = turbulence_psd(spec.kind, omega_spatial, spec.amplitude_m_s, spec.length_m)
            psd_hz *= 2.0 * math.pi / self.speed_m_s
            df = freqs_hz[1] - freqs_hz[0]
            amp = np.sqrt(psd_hz * df / 2.0)  # each complex bin carries half the power
            phases = rng.uniform(0.0, 2.0 * math.pi, size=len(freqs_hz))
            spectrum = amp * np.exp(1j * phases) * n_fft
            spectrum[0] = 0.0
            self._series = np.fft.irfft(spectrum, n=n_fft)[:n]

    def samples(self, n_steps: int, first_step: int = 0) -> np.ndarray:
        """w_g [m/s, up] at steps first_step … first_step + n_steps − 1 (:meth:`at_step` of
        each), as an array: a run samples its gust block by block, in bounded memory."""
        k = np.arange(first_step, first_step + n_steps)
        if self._series is not None:
            j = k - self._first_step
            out = self._series[np.clip(j, 0, len(self._series) - 1)]
            return np.where(j < 0, 0.0, out)
        tau = k * self._dt - self.start_s
        kind = self.spec.kind
        if kind == "none":
            return np.zeros(len(k))
        if kind == "sharp":
            return np.where(tau < 0.0, 0.0, self.spec.amplitude_m_s)
        x = tau * self.speed_m_s
        phase = 2.0 * math.pi * x / self.spec.length_m
        shape = 0.5 * self.spec.amplitude_m_s * (1.0 - np.cos(phase))
        return np.where((tau < 0.0) | (x > self.spec.length_m), 0.0, shape)

    def at_step(self, k: int) -> float:
        """Upward gust velocity w_g [m/s] at step ``k`` of the run's step ``dt_s``: t_k = k Δt
        for the closed forms; a sampled series is indexed by step number (its sample 0 at the
        first step at or after the start), so no rounding of times moves it by a sample."""
        if self._series is None:
            return self.vertical_m_s(k * self._dt)
        j = k - self._first_step
        if j < 0:
            return 0.0
        return float(self._series[min(j, len(self._series) - 1)])

    def vertical_m_s(self, t_s: float) -> float:
        """Upward gust velocity w_g at time ``t_s`` [m/s]."""
        tau = t_s - self.start_s
        kind = self.spec.kind
        if kind == "none" or tau < 0.0:
            return 0.0
        if kind == "sharp":
            return self.spec.amplitude_m_s
        if kind == "1cos":
            x = tau * self.speed_m_s
            if x > self.spec.length_m:
                return 0.0
            phase = 2.0 * math.pi * x / self.spec.length_m
            return 0.5 * self.spec.amplitude_m_s * (1.0 - math.cos(phase))
        assert self._series is not None
        k = min(int(tau / self._dt), len(self._series) - 1)
        return float(self._series[k])
