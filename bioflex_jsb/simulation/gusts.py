"""Vertical gusts: sharp-edged, 1-cosine and continuous turbulence (Dryden, von Kármán).

Every gust is a vertical wind velocity w_g(t) [m/s], positive **upward** (it raises the angle
of attack by about w_g/V), uniform over the aircraft: the wing and the tail meet it at the
same instant and the whole span sees the same value. That is what JSBSim's wind input
(``atmosphere/wind-down-fps``, which the JSBSim adapter drives with −w_g) does, and what the
paper's Eq. (4) assumes (one input w_g). A specification may add, after ``+``, the components
that vary over the aircraft (:class:`SpanwiseParts`; flown by
:mod:`bioflex_jsb.simulation.spanwise_gusts`): a rolling gust, a lateral gust, an oblique
front of the vertical gust, the rolling component of vertical turbulence and the penetration
delay from the wing to the tail. :class:`GustField` is the uniform vertical gust alone.

Command-line forms (:func:`parse_gust`):

* ``sharp:AMPLITUDE_m_s`` a step of AMPLITUDE at the gust start time;
* ``1cos:AMPLITUDE_m_s:LENGTH_m`` w = A/2 (1 − cos(2π x/L)) while 0 ≤ x ≤ L, x the distance
  flown since the gust start (the gust lasts L/V; the gradient distance is L/2);
* ``dryden:SIGMA_m_s:SCALE_m[:SEED]`` and ``vonkarman:SIGMA_m_s:SCALE_m[:SEED]``: stationary
  vertical turbulence of RMS SIGMA and length scale SCALE (MIL-F-8785C spectra), frozen in
  space (Taylor) and swept at the trim airspeed, synthesised with SEED (default 0) so every
  run is reproducible.
* ``none``: calm air.

Components after the vertical form, each once, joined by ``+`` (:class:`SpanwiseParts`):

* ``roll:PEAK_rad_s:LENGTH_m`` a 1-cosine rolling gust, w_g(y, t) = −p_g(t)·y with
  p_g = P/2 (1 − cos(2π x/L)) over the same distance flown as the vertical 1-cos;
* ``lateral:FORM`` a lateral gust v_g [m/s], positive to starboard, FORM any of sharp, 1cos,
  dryden, vonkarman above (its amplitude/σ is v_g's, its scale L_v);
* ``front:ANGLE_deg`` the vertical sharp or 1cos gust's front at ANGLE to the span (0: met by
  the whole span at once; positive: the starboard wing first), |ANGLE| ≤ 80;
* ``pg`` the rolling component p_g of the vertical dryden/vonkarman turbulence
  (MIL-F-8785C);
* ``tail`` the tail meets the vertical gust l_t/V after the wing.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.errors import InputError, plain_integer, plain_number

GUST_FORMS = (
    "sharp:AMPLITUDE_m_s",
    "1cos:AMPLITUDE_m_s:LENGTH_m",
    "dryden:SIGMA_m_s:SCALE_m[:SEED]",
    "vonkarman:SIGMA_m_s:SCALE_m[:SEED]",
    "none",
)
MAX_GUST_M_S = 50.0  # beyond this the small-UAV model is meaningless (3x the cruise speed)
# Shortest 1-cos length and turbulence scale [m]: one mean aerodynamic chord of the aircraft
# flown (parse_gust's min_length_m; without one the default aircraft's,
# default_min_gust_length_m: the prototype's Table 1 c̄ = 0.183 m).
# Every wing model here treats the gust as uniform over the chord at each instant
# (quasi-steady strips; the unsteady strips' Küssner penetration starts from the
# same assumption of a gust wider than the section); a shorter gust is thinner than the wing
# it crosses. For scale: the classic 1-cos gust of the airworthiness codes (FAR 23.341) is
# 25 chords long, and MIL-F-8785C's smallest turbulence scale is 10 ft (3 m).
# Longest 1-cos length and turbulence scale [m]: 10 km, 13 times MIL-F-8785C's largest
# scale (2500 ft = 762 m, von Kármán above 2000 ft); a longer gust is steady wind for any run.
MAX_GUST_LENGTH_M = 10_000.0
# A 1-cos gust must last at least this many steps of the run: sampled at Δt, its peak is then
# met within Δt/2, i.e. within (1 − cos(π/10))/2 = 2.4 % of its amplitude; a gust shorter
# than a step can fall between two samples and not be flown at all.
MIN_GUST_STEPS = 10
MAX_SEED = 2**63  # default_rng takes any int >= 0; sweep results store the seed as int64
# Largest peak of a rolling gust [rad/s]: the tips of a 20 m span then meet ±50 m/s,
# MAX_GUST_M_S (the prototype's 1.7 m span: ±4.3 m/s at the tips).
MAX_ROLL_GUST_RAD_S = 5.0
# Largest angle of an oblique gust front to the span [deg]: at 80° the front takes
# tan 80° = 5.7 span lengths of flight to cross the span; at 90° it would run along the
# flight path and a field frozen in the air and swept at V has no such front.
MAX_FRONT_ANGLE_DEG = 80.0
SPANWISE_FORMS = ("roll:PEAK_rad_s:LENGTH_m", "lateral:FORM", "front:ANGLE_deg", "pg", "tail")
TURBULENCE_KINDS = ("dryden", "vonkarman")


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
    # the components that vary over the aircraft (None: the uniform vertical gust alone)
    spanwise: SpanwiseParts | None = None

    def text(self) -> str:
        """The command-line form of this gust."""
        if self.spanwise is not None:
            return self.vertical().text() + self.spanwise.text()
        if self.kind == "none":
            return "none"
        if self.kind == "sharp":
            return f"sharp:{self.amplitude_m_s:g}"
        if self.kind == "1cos":
            return f"1cos:{self.amplitude_m_s:g}:{self.length_m:g}"
        return f"{self.kind}:{self.amplitude_m_s:g}:{self.length_m:g}:{self.seed}"

    def vertical(self) -> GustSpec:
        """The uniform vertical gust of this specification, without its spanwise parts."""
        return self if self.spanwise is None else replace(self, spanwise=None)


@dataclass(frozen=True)
class SpanwiseParts:
    """The components of a gust that vary over the aircraft (module docstring; their field:
    :class:`bioflex_jsb.simulation.spanwise_gusts.SpanwiseGustField`).

    roll_peak_rad_s, roll_length_m: a 1-cos rolling gust p_g [rad/s] over LENGTH [m] (0, 0:
    none); lateral: the lateral gust v_g (a vertical form read as v_g, positive to
    starboard) or None; front_angle_rad: the vertical gust's front to the span [rad],
    positive with the starboard wing first; rolling_turbulence: the MIL-F-8785C p_g of the
    vertical turbulence; tail_delay: the tail meets the vertical gust l_t/V late."""

    roll_peak_rad_s: float = 0.0
    roll_length_m: float = 0.0
    lateral: GustSpec | None = None
    front_angle_rad: float = 0.0
    rolling_turbulence: bool = False
    tail_delay: bool = False

    def text(self) -> str:
        """The ``+…`` suffix of the command-line form."""
        out = ""
        if self.roll_length_m > 0.0:
            out += f"+roll:{self.roll_peak_rad_s:g}:{self.roll_length_m:g}"
        if self.lateral is not None:
            out += f"+lateral:{self.lateral.text()}"
        if self.front_angle_rad != 0.0:
            out += f"+front:{math.degrees(self.front_angle_rad):g}"
        if self.rolling_turbulence:
            out += "+pg"
        if self.tail_delay:
            out += "+tail"
        return out


def _number(text: str, what: str, spec: str) -> float:
    """A plain ASCII number of the gust ``spec`` (``1_5``, ``１５``, ``nan``, ``1e999``
    refused: :func:`bioflex_jsb.errors.plain_number`)."""
    try:
        return plain_number(text, what)
    except InputError as exc:
        raise GustSpecError(f"gust {spec!r}: {exc}") from None


def _length(text: str, name: str, spec: str, min_length_m: float) -> float:
    """A 1-cos length or turbulence scale [m] in min_length_m..MAX_GUST_LENGTH_M."""
    value = _number(text, f"the {name} [m]", spec)
    accepted = f"accepted: {min_length_m:g}..{MAX_GUST_LENGTH_M:g} m"
    if value <= 0.0:
        raise GustSpecError(f"gust {spec!r}: the {name} must be > 0 m ({accepted}), got "
                            f"{value:g}")
    if value < min_length_m:
        raise GustSpecError(
            f"gust {spec!r}: the {name} {value:g} m is shorter than one mean chord "
            f"({accepted}): such a gust is thinner than the wing it crosses, which every wing "
            "model here takes as uniform over the chord")
    if value > MAX_GUST_LENGTH_M:
        raise GustSpecError(f"gust {spec!r}: the {name} {value:g} m is too long ({accepted}; "
                            "a longer gust is a steady wind for any run)")
    return value


def check_gust_resolution(gust: GustSpec, speed_m_s: float, dt_s: float) -> None:
    """A 1-cos ``gust`` flown at ``speed_m_s`` must last :data:`MIN_GUST_STEPS` steps of
    ``dt_s`` [s]; else :class:`GustSpecError` naming the shortest length and the step."""
    parts = gust.spanwise
    if parts is not None:  # its 1-cos components: the rolling and the lateral gust
        if parts.roll_length_m > 0.0:
            check_gust_resolution(GustSpec("1cos", parts.roll_peak_rad_s, parts.roll_length_m),
                                  speed_m_s, dt_s)
        if parts.lateral is not None:
            check_gust_resolution(parts.lateral, speed_m_s, dt_s)
    if gust.kind != "1cos":
        return
    steps = gust.length_m / speed_m_s / dt_s
    if steps < MIN_GUST_STEPS:
        shortest = MIN_GUST_STEPS * speed_m_s * dt_s
        raise GustSpecError(
            f"gust {gust.text()!r} lasts {steps:.3g} steps of {dt_s:g} s at {speed_m_s:g} m/s; "
            f"accepted: at least {MIN_GUST_STEPS} steps (its peak is then sampled within "
            f"2.4 %), a length >= {shortest:.3g} m or a smaller --dt")


def default_min_gust_length_m() -> float:
    """The shortest 1-cos length and turbulence scale [m] of a gust given without its
    aircraft: one mean chord of the default aircraft
    (:func:`~bioflex_jsb.definition.aircraft.default_aircraft`, the prototype: 0.183 m)."""
    from bioflex_jsb.definition.aircraft import default_aircraft

    return default_aircraft().airframe_data().reference.mean_chord_m


def parse_gust(spec: str, min_length_m: float | None = None) -> GustSpec:
    """Parse a command-line gust; raises :class:`GustSpecError` naming what is accepted.
    ``min_length_m``: the shortest 1-cos length and turbulence scale [m], one mean chord of
    the aircraft flown (None: :func:`default_min_gust_length_m`, the default aircraft's). A
    vertical form may be followed by ``+`` and the components of :class:`SpanwiseParts`
    (module docstring)."""
    if min_length_m is None:
        min_length_m = default_min_gust_length_m()
    head, plus, rest = spec.strip().partition("+")
    base = _parse_vertical(head, min_length_m)
    if not plus:
        return base
    return replace(base, spanwise=_parse_spanwise(spec, base, rest.split("+"), min_length_m))


def _parse_spanwise(spec: str, base: GustSpec, items: list[str],
                    min_length_m: float) -> SpanwiseParts:
    """The ``+`` components of ``spec`` (after the vertical ``base``), each once."""
    accepted = "accepted after '+': " + ", ".join(SPANWISE_FORMS)
    seen: set[str] = set()
    fields: dict[str, object] = {}
    for item in items:
        name, _, args = item.strip().partition(":")
        name = name.lower()
        if name in seen:
            raise GustSpecError(f"gust {spec!r}: {name!r} is given twice; {accepted}")
        seen.add(name)
        if name == "roll":
            values = args.split(":")
            if len(values) != 2:
                raise GustSpecError(f"gust {spec!r}: roll takes PEAK_rad_s:LENGTH_m; {accepted}")
            peak = _number(values[0], "the rolling gust's peak [rad/s]", spec)
            if abs(peak) > MAX_ROLL_GUST_RAD_S:
                raise GustSpecError(f"gust {spec!r}: |roll peak| must be <= "
                                    f"{MAX_ROLL_GUST_RAD_S:g} rad/s, got {peak:g}")
            fields["roll_peak_rad_s"] = peak
            fields["roll_length_m"] = _length(values[1], "rolling gust's length", spec,
                                              min_length_m)
        elif name == "lateral":
            lateral = _parse_vertical(args, min_length_m)
            if lateral.kind == "none":
                raise GustSpecError(f"gust {spec!r}: lateral takes one of sharp, 1cos, dryden, "
                                    "vonkarman (v_g [m/s], to starboard)")
            fields["lateral"] = lateral
        elif name == "front":
            angle = _number(args, "the gust front's angle to the span [deg]", spec)
            if abs(angle) > MAX_FRONT_ANGLE_DEG:
                raise GustSpecError(f"gust {spec!r}: |front angle| must be <= "
                                    f"{MAX_FRONT_ANGLE_DEG:g} deg, got {angle:g}")
            if base.kind not in ("sharp", "1cos"):
                raise GustSpecError(f"gust {spec!r}: front needs a sharp or 1cos vertical "
                                    "gust (turbulence's spanwise part is '+pg')")
            fields["front_angle_rad"] = math.radians(angle)
        elif name in ("pg", "tail") and args:
            raise GustSpecError(f"gust {spec!r}: {name} takes no value; {accepted}")
        elif name == "pg":
            if base.kind not in TURBULENCE_KINDS:
                raise GustSpecError(f"gust {spec!r}: pg is the rolling part of dryden or "
                                    "vonkarman vertical turbulence")
            fields["rolling_turbulence"] = True
        elif name == "tail":
            if base.kind == "none":
                raise GustSpecError(f"gust {spec!r}: tail delays the vertical gust, and there "
                                    "is none")
            fields["tail_delay"] = True
        else:
            raise GustSpecError(f"gust {spec!r}: unknown component {item.strip()!r}; "
                                f"{accepted}")
    return SpanwiseParts(**fields)


def _parse_vertical(spec: str, min_length_m: float) -> GustSpec:
    """One vertical form (no ``+``) of :func:`parse_gust`."""
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
        _check_amplitude(amp, spec)
        length = _length(parts[2], "gust length", spec, min_length_m)
        return GustSpec("1cos", amp, length)
    if kind in ("dryden", "vonkarman"):
        if len(parts) not in (3, 4):
            raise GustSpecError(
                f"gust {spec!r}: {kind} takes SIGMA_m_s:SCALE_m[:SEED]; {accepted}"
            )
        sigma = _number(parts[1], "the RMS intensity sigma [m/s]", spec)
        if sigma < 0.0 or sigma > MAX_GUST_M_S:
            raise GustSpecError(f"gust {spec!r}: sigma must be 0..{MAX_GUST_M_S:g} m/s")
        scale = _length(parts[2], "length scale", spec, min_length_m)
        seed = 0
        if len(parts) == 4:
            try:
                seed = plain_integer(parts[3], "the seed")
            except InputError as exc:
                raise GustSpecError(f"gust {spec!r}: {exc}") from None
            if not 0 <= seed < MAX_SEED:
                raise GustSpecError(f"gust {spec!r}: the seed must be 0..{MAX_SEED - 1}")
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
        if spec.spanwise is not None:
            raise GustSpecError(
                f"gust {spec.text()!r}: its parts after '+' (spanwise, lateral, tail) are flown "
                "by gust, compare and sitl; here give the vertical gust alone "
                f"({spec.vertical().text()!r})")
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
