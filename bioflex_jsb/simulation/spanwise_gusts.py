"""Gusts that vary over the aircraft: rolling, oblique, lateral, and late at the tail.

The uniform vertical gust w_g(t) of :mod:`bioflex_jsb.simulation.gusts` meets every point of
the aircraft at once. The components of :class:`~bioflex_jsb.simulation.gusts.SpanwiseParts`
(the ``+…`` parts of a gust specification) make the field vary over the aircraft; this module
is their field, pure numerics (no JSBSim): the runtime writes its loads
(:mod:`bioflex_jsb.runtime.gust_loads`).

Frames and signs (docs/conventions.md): y the spanwise station [m], positive to starboard,
from the plane of symmetry; w_g positive **up**; v_g positive **to starboard** (the air
moves to the right); p_g positive with the right wing down, the sense of the body rate p.

Field (frozen in the air, swept at the trim airspeed V, as the uniform gusts):

* **rolling gust** ``roll:P:L``: w_g(y, t) = −p_g(t)·y with p_g = P/2 (1 − cos 2π x/L),
  x = V (t − t_0) the distance flown since the gust start, 0 ≤ x ≤ L. It is the field of
  air rolling with p_g: a wing rolling at p sees the upwash p·y, so it feels (p − p_g)·y,
  MIL-F-8785C's p_g = ∂w_g/∂y with w_g positive down (3.7.2, "rotary gusts").
* **oblique front** ``front:Λ`` of the vertical sharp/1cos gust W(t) (its centreline
  history): the front is a straight line at the angle Λ to the span (Λ = 0: parallel to it,
  the uniform gust), frozen in the air, so station y meets it at t_0 − y tan Λ / V:
  w_g(y, t) = W(t + y tan Λ / V). Λ > 0: the starboard wing meets it first. The wing's
  leading edge is taken as straight (a swept wing's own x(y) adds to the delay: neglected,
  the prototype's outer-panel sweep moves its tip 3 cm: 2 ms at 15 m/s).
* **lateral gust** ``lateral:FORM``: v_g(t) uniform over the aircraft, a 1-cos, a step or
  MIL-F-8785C turbulence with its own σ_v, L_v (the lateral spectra have the vertical ones'
  forms: Dryden Φ_v = σ² L/π (1 + 3 L²Ω²)/(1 + L²Ω²)², von Kármán likewise with 1.339 L,
  :func:`~bioflex_jsb.simulation.gusts.turbulence_psd`); its series is drawn from the seed
  and a stream of its own, so it is independent of the vertical series of the same seed.
  The fin meets it at the CG's instant (no fin delay).
* **rolling turbulence** ``pg``: the p_g of the vertical turbulence, MIL-F-8785C
  (3.7.2.2; the same form for its Dryden and von Kármán models; MIL-HDBK-1797's H_p):

      Φ_p(Ω) = σ_w²/L_w · 0.8 (π L_w / (4 b))^{1/3} / (1 + (4 b Ω / π)²)   [(rad/s)²/(rad/m)]

  one-sided over Ω ∈ [0, ∞) in the normalisation of Φ_w, so its variance is the closed form
  σ_p² = σ_w²/L_w · 0.8 (π L_w/(4b))^{1/3} · π²/(8 b) (:func:`rolling_variance`). The
  standard draws p_g independently of w_g (by symmetry the centreline w_g and ∂w_g/∂y at
  one point are uncorrelated in isotropic turbulence); so does this module (its own
  stream). The form assumes b well below L_w.
* **tail delay** ``tail``: the horizontal tail, l_t behind the CG, meets the vertical gust
  τ = l_t/V after the wing: w_t(t) = W(t − τ) (the wing's downwash on it lags by the same
  time: Δα_t = (1 − dε/dα) w_t/V, Etkin & Reid Sec. 5.5's downwash lag for the gust).

Spanwise decomposition (:class:`SpanStations`: the strips' weights g_i = C_lα c Δy, lift per
unit dynamic pressure per radian [m²/rad]): a field w(y) is carried by

* its **symmetric part at the wing**, the uniform gust of the same lift,
  w̄ = Σ g w / Σ g: what the airframe and the symmetric modal wing take (today's w_g);
* its **antisymmetric part as an equivalent gust roll rate**
  p_g = −Σ g y w / Σ g y², the rolling gust of the same strip rolling moment (first-moment
  equivalence; exact for the linear gust, where w = −p_g y gives back p_g);
* v_g, and the tail's delayed w_t.

Higher spanwise moments (a symmetric bump that loads the tips, a kink) are dropped: they
change neither the lift nor the rolling moment of the rigid wing.

The rigid wing's rolling moment of a field (strip theory, lift up at y rolls left):
ΔL = −∫ l(y) y dy with l = Q C_lα c w_g/V (:meth:`SpanStations.rolling_moment_n_m`); for the
linear gust ΔL = (Q p_g/V) ∫ C_lα c y² dy, on a rectangular wing of uniform C_lα
Q p_g C_lα c b³/(12 V) (:func:`rectangular_rolling_moment_n_m`), which is −L_p p_g with the
strip roll damping C_lp = −C_lα/6 (:meth:`SpanStations.roll_damping_per_rad`).

The one function a wing model takes p_g from: :meth:`SpanwiseGustField.roll_rate_samples`
(p_g [rad/s] by step number).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.gusts import GustField, GustSpec, turbulence_psd

# Seed streams of the series drawn from one gust seed: numpy's SeedSequence takes the pair
# (seed, stream), so the series are independent (GustField's own vertical series is
# default_rng(seed), a different sequence).
ROLL_STREAM = 1
LATERAL_STREAM = 2
# MIL-F-8785C's p_g form (module docstring): the constant 0.8 and the roll-off 4b/π.
P_G_GAIN = 0.8
DEFAULT_STRIPS = 40  # stations per half span of a rectangular SpanStations


def rolling_psd(omega_rad_m, sigma_w_m_s: float, scale_w_m: float, span_m: float) -> np.ndarray:
    """MIL-F-8785C's one-sided rolling-gust spectrum Φ_p(Ω) [(rad/s)²/(rad/m)] at spatial
    frequencies ``omega_rad_m`` [rad/m] (module docstring) of vertical turbulence σ_w [m/s],
    L_w [m] and a wing of span b [m]."""
    om = np.asarray(omega_rad_m, dtype=float)
    gain = sigma_w_m_s**2 / scale_w_m * P_G_GAIN * (math.pi * scale_w_m / (4.0 * span_m)) ** (1 / 3)
    return gain / (1.0 + (4.0 * span_m * om / math.pi) ** 2)


def rolling_variance(sigma_w_m_s: float, scale_w_m: float, span_m: float) -> float:
    """σ_p² [(rad/s)²] of :func:`rolling_psd`: ∫₀^∞ dΩ/(1 + (kΩ)²) = π/(2k), k = 4b/π."""
    gain = sigma_w_m_s**2 / scale_w_m * P_G_GAIN * (math.pi * scale_w_m / (4.0 * span_m)) ** (1 / 3)
    return gain * math.pi**2 / (8.0 * span_m)


def synthesise(psd_rad_m, n_steps: int, dt_s: float, speed_m_s: float,
               rng: np.random.Generator) -> np.ndarray:
    """A stationary series of ``n_steps`` samples at ``dt_s`` [s] whose one-sided spatial
    spectrum is ``psd_rad_m(Ω)`` [unit²/(rad/m)], swept at ``speed_m_s`` [m/s]: the inverse
    FFT of random phases, as :class:`~bioflex_jsb.simulation.gusts.GustField` synthesises
    the vertical series (Φ(Ω) dΩ = S(f) df, dΩ = 2π df/V; each bin carries half its
    power)."""
    n_fft = 1 << max(4, int(math.ceil(math.log2(2 * n_steps))))
    freqs_hz = np.fft.rfftfreq(n_fft, d=dt_s)
    psd_hz = psd_rad_m(2.0 * math.pi * freqs_hz / speed_m_s) * (2.0 * math.pi / speed_m_s)
    df = freqs_hz[1] - freqs_hz[0]
    amp = np.sqrt(psd_hz * df / 2.0)
    phases = rng.uniform(0.0, 2.0 * math.pi, size=len(freqs_hz))
    spectrum = amp * np.exp(1j * phases) * n_fft
    spectrum[0] = 0.0
    return np.fft.irfft(spectrum, n=n_fft)[:n_steps]


def one_cosine(tau_s, amplitude: float, length_m: float, speed_m_s: float) -> np.ndarray:
    """A/2 (1 − cos 2π x/L) for 0 ≤ x = V τ ≤ L, else 0, at times ``tau_s`` [s] after the
    start (array)."""
    x = np.asarray(tau_s, dtype=float) * speed_m_s
    shape = 0.5 * amplitude * (1.0 - np.cos(2.0 * math.pi * x / length_m))
    return np.where((x < 0.0) | (x > length_m), 0.0, shape)


def closed_form(spec: GustSpec, tau_s, speed_m_s: float) -> np.ndarray:
    """A sharp or 1cos gust ``spec`` (its amplitude in its own unit) at times ``tau_s`` [s]
    after its start; none: zeros."""
    tau = np.asarray(tau_s, dtype=float)
    if spec.kind == "sharp":
        return np.where(tau < 0.0, 0.0, spec.amplitude_m_s)
    if spec.kind == "1cos":
        return one_cosine(tau, spec.amplitude_m_s, spec.length_m, speed_m_s)
    if spec.kind == "none":
        return np.zeros(tau.shape)
    raise ValueError(f"no closed form for gust kind {spec.kind!r}")


@dataclass(frozen=True)
class SpanStations:
    """The wing's strips over the full span: stations ``y_m`` [m] (starboard positive) and
    weights ``weight_m2`` g = C_lα c Δy [m²/rad] (the strip's lift per unit dynamic pressure
    per radian), with the reference area ``area_m2`` S and span ``span_m`` b of the
    aircraft's coefficients (module docstring)."""

    y_m: np.ndarray
    weight_m2: np.ndarray
    area_m2: float
    span_m: float

    @classmethod
    def rectangular(cls, span_m: float, chord_m: float, lift_slope_per_rad: float,
                    n_half: int = DEFAULT_STRIPS) -> SpanStations:
        """A rectangular wing of uniform C_lα: ``n_half`` equal strips a side (midpoints)."""
        dy = 0.5 * span_m / n_half
        half = (np.arange(n_half) + 0.5) * dy
        y = np.concatenate([-half[::-1], half])
        return cls(y, np.full(2 * n_half, lift_slope_per_rad * chord_m * dy),
                   span_m * chord_m, span_m)

    @classmethod
    def from_half_wing(cls, stations_m, widths_m, cl_alpha_c_m_per_rad, area_m2: float,
                       span_m: float) -> SpanStations:
        """The starboard half's strips (a vortex lattice's
        :class:`~bioflex_jsb.aerodynamics.vortex_lattice.SpanwiseAerodynamics`: stations,
        widths, C_lα c) mirrored to port (a symmetric wing is described once)."""
        y = np.asarray(stations_m, dtype=float)
        g = np.asarray(widths_m, dtype=float) * np.asarray(cl_alpha_c_m_per_rad, dtype=float)
        if y.ndim != 1 or y.shape != g.shape or not np.all(y > 0.0):
            raise InputError("the half wing's strips need positive stations and one weight "
                             "each")
        return cls(np.concatenate([-y[::-1], y]), np.concatenate([g[::-1], g]),
                   float(area_m2), float(span_m))

    def symmetric_gust(self, w_m_s: np.ndarray) -> np.ndarray:
        """w̄ = Σ g w / Σ g [m/s] of the field ``w_m_s`` (stations on the last axis)."""
        return np.asarray(w_m_s, dtype=float) @ self.weight_m2 / self.weight_m2.sum()

    def equivalent_roll_rate(self, w_m_s: np.ndarray) -> np.ndarray:
        """p_g = −Σ g y w / Σ g y² [rad/s] of the field ``w_m_s`` [m/s, up] (stations on the
        last axis): the linear gust of the same strip rolling moment."""
        gy = self.weight_m2 * self.y_m
        return -(np.asarray(w_m_s, dtype=float) @ gy) / float(gy @ self.y_m)

    def rolling_moment_n_m(self, w_m_s: np.ndarray, dynamic_pressure_pa: float,
                           speed_m_s: float) -> np.ndarray:
        """The strips' rolling moment ΔL = −Σ Q g (w/V) y [N·m, right wing down] of the
        field ``w_m_s`` [m/s, up] (stations on the last axis)."""
        return -(dynamic_pressure_pa / speed_m_s) * (np.asarray(w_m_s, dtype=float)
                                                     @ (self.weight_m2 * self.y_m))

    def roll_damping_per_rad(self) -> float:
        """The strips' C_lp = −(2/(S b²)) Σ g y² [per rad of p b/(2V)]: L_p = ∂L/∂p =
        −(Q/V) Σ g y² and C_lp = L_p (2V/b)/(Q S b)."""
        return -2.0 * float(self.weight_m2 @ self.y_m**2) / (self.area_m2 * self.span_m**2)


def rectangular_rolling_moment_n_m(p_g_rad_s: float, dynamic_pressure_pa: float,
                                   speed_m_s: float, lift_slope_per_rad: float, chord_m: float,
                                   span_m: float) -> float:
    """Closed form of the strip integral for the linear gust w = −p_g y on a rectangular
    wing of uniform C_lα: ΔL = (Q p_g/V) C_lα c ∫_{−b/2}^{b/2} y² dy = Q p_g C_lα c b³/(12 V)
    [N·m, right wing down]."""
    return (dynamic_pressure_pa * p_g_rad_s * lift_slope_per_rad * chord_m * span_m**3
            / (12.0 * speed_m_s))


@dataclass(frozen=True)
class TailGust:
    """What the tail's delayed gust needs: ``arm_m`` l_t, CG to the tail's aerodynamic
    centre [m] (positive aft); ``lift_slope_per_rad`` a_t,S (1 − dε/dα), the tail's lift
    per radian of gust angle on the wing's area S [1/rad] (tail efficiency and the wing's
    downwash in it)."""

    arm_m: float
    lift_slope_per_rad: float

    @classmethod
    def from_derivatives(cls, aero, mean_chord_m: float) -> TailGust:
        """The tail of an aircraft's rigid derivatives ``aero``
        (:class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics`; c̄ [m]), as the
        textbook tail terms split them (Etkin & Reid, *Dynamics of Flight*, 3rd ed.,
        Sec. 5.5; Nelson, *Flight Stability and Automatic Control*, 2nd ed., Sec. 3.6):
        the elevator's lift acts at the tail, so l_t/c̄ = −C_mδe/C_Lδe; the tail's pitch
        damping C_mq,t = −2 a_t,S (l_t/c̄)² gives a_t,S = −C_mq/(2 (l_t/c̄)²) (C_mq taken as
        the tail's: the wing's share is small for a conventional aircraft); the downwash
        lag C_mα̇ = C_mq,t dε/dα gives dε/dα = C_mα̇/C_mq. For the prototype (C_mδe −0.9,
        C_Lδe 0.35, C_mq −7.3, C_mα̇ −2.5, c̄ 0.183 m): l_t = 0.471 m, a_t,S 0.552 (its
        estimates' own S_t/S C_Lα,t = 0.35/0.65 = 0.538), dε/dα 0.342: a_t,S (1 − dε/dα)
        = 0.363. One line (InputError) for derivatives without a tail (C_Lδe = 0, C_mq ≥ 0)."""
        cl_de, cm_de = aero.cl_delta_e_per_rad, aero.cm_delta_e_per_rad
        if cl_de == 0.0 or cm_de * cl_de >= 0.0:
            raise InputError("the tail's penetration delay needs an elevator aft of the CG "
                             "(C_Ldelta_e != 0 and C_mdelta_e of the opposite sign)")
        if aero.cm_q_per_rad >= 0.0:
            raise InputError("the tail's penetration delay needs a pitch damping C_mq < 0")
        ratio = -aero.cm_delta_e_per_rad / aero.cl_delta_e_per_rad  # l_t / c̄
        slope = -aero.cm_q_per_rad / (2.0 * ratio**2)
        downwash = aero.cm_alphadot_per_rad / aero.cm_q_per_rad
        if not 0.0 <= downwash < 1.0:
            raise InputError(f"the tail's downwash gradient C_malphadot/C_mq = {downwash:.3g} "
                             "is outside 0..1: the tail's delay cannot be split from it")
        return cls(ratio * mean_chord_m, slope * (1.0 - downwash))


class GustParts(NamedTuple):
    """A gust's parts at a run of steps (arrays, one value per step): ``w_sym`` the
    symmetric gust at the wing [m/s, up] (what the uniform gust was), ``p_g`` the equivalent
    gust roll rate [rad/s, right wing down], ``v_g`` the lateral gust [m/s, to starboard],
    ``w_tail`` the vertical gust at the tail [m/s, up] (w_sym without the tail delay)."""

    w_sym: np.ndarray
    p_g: np.ndarray
    v_g: np.ndarray
    w_tail: np.ndarray


class SpanwiseGustField:
    """The field of a gust ``spec`` with spanwise parts (or none), flown at ``speed_m_s``
    [m/s] from ``start_s`` [s] for ``duration_s`` [s] at steps of ``dt_s`` [s], over the
    strips ``stations`` and the ``tail`` (module docstring). Step k is at t_k = k Δt; the
    turbulence series are synthesised once, their sample 0 at the first step at or after
    the start, as :class:`~bioflex_jsb.simulation.gusts.GustField`'s.

    :meth:`samples` is the symmetric gust at the wing, the w_g a coupled step takes
    (identical to GustField's for a gust without spanwise parts); :meth:`parts` every part;
    :meth:`roll_rate_samples` p_g alone (for a wing model's antisymmetric strips).
    """

    def __init__(self, spec: GustSpec, speed_m_s: float, stations: SpanStations,
                 tail: TailGust | None = None, start_s: float = 0.5, duration_s: float = 10.0,
                 dt_s: float = 1.0 / 120.0) -> None:
        parts = spec.spanwise
        self.spec, self.speed_m_s, self.stations, self.tail = spec, float(speed_m_s), stations, tail
        self.start_s, self.dt_s = float(start_s), float(dt_s)
        self.parts_spec = parts
        if parts is not None and parts.tail_delay and tail is None:
            raise InputError(f"gust {spec.text()!r}: the tail delay needs the tail (TailGust)")
        self.vertical = GustField(spec.vertical(), speed_m_s, start_s, duration_s, dt_s)
        self._first_step = max(0, math.ceil(self.start_s / self.dt_s - 1e-9))
        n = int(math.ceil(max(duration_s - start_s, dt_s) / dt_s)) + 2
        self._roll_series = self._lateral_series = None
        if parts is not None and parts.rolling_turbulence:
            rng = np.random.default_rng([spec.seed, ROLL_STREAM])
            self._roll_series = synthesise(
                lambda om: rolling_psd(om, spec.amplitude_m_s, spec.length_m, stations.span_m),
                n, dt_s, speed_m_s, rng)
        lateral = None if parts is None else parts.lateral
        if lateral is not None and lateral.kind in ("dryden", "vonkarman"):
            rng = np.random.default_rng([lateral.seed, LATERAL_STREAM])
            self._lateral_series = synthesise(
                lambda om: turbulence_psd(lateral.kind, om, lateral.amplitude_m_s,
                                          lateral.length_m), n, dt_s, speed_m_s, rng)
        self._tan = math.tan(parts.front_angle_rad) if parts is not None else 0.0

    # -- the parts by step number -----------------------------------------------------------
    def _series(self, series: np.ndarray, k: np.ndarray) -> np.ndarray:
        j = k - self._first_step
        return np.where(j < 0, 0.0, series[np.clip(j, 0, len(series) - 1)])

    def _vertical_at(self, tau_s: np.ndarray) -> np.ndarray:
        """The centreline's vertical gust W at times ``tau_s`` [s] after the start (any
        shape): closed forms exactly, turbulence linearly between its samples."""
        spec = self.spec.vertical()
        if spec.kind in ("dryden", "vonkarman"):
            steps = (np.asarray(tau_s, dtype=float) + self.start_s) / self.dt_s
            lo = np.floor(steps + 1e-9).astype(np.int64)
            frac = np.clip(steps - lo, 0.0, 1.0)
            k0 = int(lo.min()) if lo.size else 0
            block = self.vertical.samples(int(lo.max()) - k0 + 2, k0) if lo.size else []
            block = np.asarray(block)
            return (1.0 - frac) * block[lo - k0] + frac * block[lo - k0 + 1]
        return closed_form(spec, tau_s, self.speed_m_s)

    def parts(self, n_steps: int, first_step: int = 0) -> GustParts:
        """The parts at steps first_step … first_step + n_steps − 1 (:class:`GustParts`)."""
        k = np.arange(first_step, first_step + n_steps)
        tau = k * self.dt_s - self.start_s
        p = self.parts_spec
        zeros = np.zeros(n_steps)
        if p is not None and self._tan != 0.0:
            shift = self.stations.y_m * self._tan / self.speed_m_s  # station y meets it early
            field = self._vertical_at(tau[:, None] + shift[None, :])
            w_sym = self.stations.symmetric_gust(field)
            p_front = self.stations.equivalent_roll_rate(field)
        else:
            w_sym = self.vertical.samples(n_steps, first_step)
            p_front = zeros
        if p is None:
            return GustParts(w_sym, zeros, zeros, w_sym)
        p_g = p_front
        if p.roll_length_m > 0.0:
            p_g = p_g + one_cosine(tau, p.roll_peak_rad_s, p.roll_length_m, self.speed_m_s)
        if self._roll_series is not None:
            p_g = p_g + self._series(self._roll_series, k)
        v_g = zeros
        if self._lateral_series is not None:
            v_g = self._series(self._lateral_series, k)
        elif p.lateral is not None:
            v_g = closed_form(p.lateral, tau, self.speed_m_s)
        w_tail = w_sym
        if p.tail_delay:
            w_tail = self._vertical_at(tau - self.tail.arm_m / self.speed_m_s)
        return GustParts(w_sym, p_g, v_g, w_tail)

    def samples(self, n_steps: int, first_step: int = 0) -> np.ndarray:
        """The symmetric gust at the wing w̄ [m/s, up] at steps first_step …: the w_g of the
        coupled step (and of :class:`GustField` for the same vertical gust)."""
        return self.parts(n_steps, first_step).w_sym

    def at_step(self, k: int) -> float:
        """:meth:`samples` at step ``k`` [m/s, up]."""
        return float(self.samples(1, k)[0])

    def roll_rate_samples(self, n_steps: int, first_step: int = 0) -> np.ndarray:
        """The equivalent gust roll rate p_g [rad/s, right wing down] at steps first_step …
        (module docstring): the antisymmetric input of the rigid rolling moment and of a
        wing model's antisymmetric strips (which see the upwash (p − p_g)·y)."""
        return self.parts(n_steps, first_step).p_g

    @property
    def varies(self) -> bool:
        """Whether anything but the uniform vertical gust blows (the runtime then writes
        the extra loads)."""
        return self.parts_spec is not None


def gust_field(spec: GustSpec, speed_m_s: float, stations: SpanStations | None = None,
               tail: TailGust | None = None, start_s: float = 0.5, duration_s: float = 10.0,
               dt_s: float = 1.0 / 120.0) -> GustField | SpanwiseGustField:
    """The field of ``spec``: the uniform :class:`GustField` without spanwise parts (the
    unchanged path), else :class:`SpanwiseGustField` (``stations`` then needed)."""
    if spec.spanwise is None:
        return GustField(spec, speed_m_s, start_s, duration_s, dt_s)
    if stations is None:
        raise InputError(f"gust {spec.text()!r}: its spanwise parts need the wing's strips")
    return SpanwiseGustField(spec, speed_m_s, stations, tail, start_s, duration_s, dt_s)


def tail_delay_elevator_rad(tail: TailGust, aero, w_tail_m_s, w_sym_m_s,
                            speed_m_s: float) -> np.ndarray:
    """The elevator angle [rad] whose tail lift is the tail delay's,
    δe = a_t,S (1 − dε/dα) (w_t − w̄)/(V C_Lδe): a linear model with an elevator input flies
    the delay with it (its moment follows, since :meth:`TailGust.from_derivatives` puts the
    tail at l_t = −c̄ C_mδe/C_Lδe)."""
    dw = np.asarray(w_tail_m_s, dtype=float) - np.asarray(w_sym_m_s, dtype=float)
    return tail.lift_slope_per_rad * dw / (speed_m_s * aero.cl_delta_e_per_rad)


def lateral_gust_response(ss, time_s, p_g_rad_s, v_g_m_s) -> dict[str, np.ndarray]:
    """The rigid lateral model ``ss`` (:func:`~bioflex_jsb.flight_dynamics.lateral.
    build_lateral_state_space`: states β, p, r, φ, input v_g first) from rest under the gust
    roll rate p_g [rad/s] and the lateral gust v_g [m/s] at uniformly spaced ``time_s``
    [s], each held over a step: the run's channels beta_rad, p_rad_s, r_rad_s, phi_rad.
    p_g enters as p − p_g in the rolling and yawing moments, as the run applies it
    (``runtime/gust_loads.py``: JSBSim's C_lp and C_np, no side force): B_p = [0, −L'_p,
    −N'_p, 0] (the p column of A without β's w_0/V and Y_p/V, which the gust does not
    apply, and φ̇ = p)."""
    from scipy.linalg import expm

    t = np.asarray(time_s, dtype=float)
    a = np.asarray(ss.a, dtype=float)
    b = np.column_stack([np.asarray(ss.b, dtype=float)[:, 0],
                         [0.0, -a[1, 1], -a[2, 1], 0.0]])
    dt = float(t[1] - t[0])
    aug = np.zeros((6, 6))
    aug[:4, :4], aug[:4, 4:] = a, b
    e = expm(aug * dt)
    phi, gam = e[:4, :4], e[:4, 4:]
    u = np.column_stack([np.asarray(v_g_m_s, dtype=float), np.asarray(p_g_rad_s, dtype=float)])
    x = np.zeros((len(t), 4))
    for k in range(len(t) - 1):
        x[k + 1] = phi @ x[k] + gam @ u[k]
    return {"beta_rad": x[:, 0], "p_rad_s": x[:, 1], "r_rad_s": x[:, 2], "phi_rad": x[:, 3]}
