"""Indicial (step-response) functions of thin-aerofoil theory and a strip's finite-state model.

Sources (cited below by short name):

* Jones (1940): R. T. Jones, "The unsteady lift of a wing of finite aspect ratio", NACA
  Report 681: Wagner's function φ(s) ≈ 1 − 0.165 e^{−0.0455 s} − 0.335 e^{−0.3 s}.
* Sears & Sparks (1941): W. R. Sears, B. O. Sparks, "On the reaction of an elastic wing to
  vertical gusts", J. Aeronautical Sciences 9(2), 64-67: Küssner's function
  ψ(s) ≈ 1 − 0.5 e^{−0.13 s} − 0.5 e^{−s}.
* BAH (1955): Bisplinghoff, Ashley & Halfman, *Aeroelasticity*, Chapter 5 (both
  approximations, and the Fourier relation between an indicial function and its transfer
  function).
* Leishman (2006): J. G. Leishman, *Principles of Helicopter Aerodynamics*, 2nd ed.,
  Chapter 8 (the state-space form of the exponential approximations used below).

Variables: s = V t / b [-] is the distance travelled in semichords b [m] at airspeed V [m/s]
(t [s]). Wagner's φ(s) is the circulatory lift after a step in the three-quarter-chord upwash
Q [m/s], as a fraction of its steady value; Küssner's ψ(s) the lift after a sharp-edged gust
front reaches the leading edge. Frequency responses use e^{iωt}, k = ωb/V (see
:mod:`bioflex_jsb.aerodynamics.theodorsen` for frames and signs, which are those used here).

Exact references: φ and ψ have no closed form; :func:`wagner_exact` and :func:`kussner_exact`
evaluate the Fourier integrals of the exact C(k) and Sears S(k) (leading-edge reference)
numerically, φ(s) = T(0) + (2/π) ∫₀^∞ Im T(k)/k cos(ks) dk for a causal step response whose
transfer function is T(k) (BAH 1955, Chapter 5). Closed values: φ(0) = ½, φ(∞) = 1, ψ(0) = 0,
ψ(∞) = 1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import quad

from bioflex_jsb.aerodynamics.theodorsen import (
    TWO_PI,
    SectionMatrices,
    sears_s,
    section_matrices,
    theodorsen_c,
)
from bioflex_jsb.state_space import StateSpace, with_motion_inputs


@dataclass(frozen=True)
class ExponentialIndicial:
    """Indicial function f(s) = 1 − Σ A_j e^{−β_j s} [-], s in semichords travelled.

    ``amplitudes`` A_j [-], ``exponents`` β_j [-] (per semichord). Its transfer function (the
    response to e^{iks}) is T(k) = 1 − Σ A_j ik/(ik + β_j).
    """

    name: str
    amplitudes: tuple[float, ...]
    exponents: tuple[float, ...]
    source: str

    @property
    def initial_value(self) -> float:
        """f(0) = 1 − Σ A_j [-]."""
        return 1.0 - float(sum(self.amplitudes))

    def value(self, s) -> np.ndarray:
        """f(s) [-] for s ≥ 0 semichords (0 for s < 0: the response is causal)."""
        s = np.asarray(s, dtype=float)
        out = np.ones_like(s)
        for a, b in zip(self.amplitudes, self.exponents, strict=True):
            out = out - a * np.exp(-b * np.maximum(s, 0.0))
        return np.where(s >= 0.0, out, 0.0)

    def transfer(self, reduced_frequency) -> np.ndarray:
        """T(k) = 1 − Σ A_j ik/(ik + β_j) [-] at reduced frequency k = ωb/V."""
        ik = 1j * np.asarray(reduced_frequency, dtype=float)
        out = np.ones_like(ik)
        for a, b in zip(self.amplitudes, self.exponents, strict=True):
            out = out - a * ik / (ik + b)
        return out


JONES_WAGNER = ExponentialIndicial(
    "Wagner (R. T. Jones)", (0.165, 0.335), (0.0455, 0.3), "Jones (1940), NACA Report 681"
)
"""R. T. Jones's two-exponential approximation of Wagner's function (Jones 1940)."""

SEARS_SPARKS_KUSSNER = ExponentialIndicial(
    "Küssner (Sears & Sparks)", (0.5, 0.5), (0.13, 1.0), "Sears & Sparks (1941)"
)
"""Sears & Sparks's two-exponential approximation of Küssner's function (Sears & Sparks
1941; quoted in BAH 1955, Chapter 5)."""


def wagner_jones(s) -> np.ndarray:
    """Wagner's function by Jones's approximation (Jones 1940) [-], s in semichords."""
    return JONES_WAGNER.value(s)


def kussner_sears_sparks(s) -> np.ndarray:
    """Küssner's function by Sears & Sparks's approximation [-], s in semichords."""
    return SEARS_SPARKS_KUSSNER.value(s)


def jones_c(reduced_frequency) -> np.ndarray:
    """Jones's approximation of Theodorsen's C(k) [-]: the transfer function of his φ(s)."""
    return JONES_WAGNER.transfer(reduced_frequency)


# Split point of the Fourier integrals below: [0, K_SPLIT] by adaptive quadrature (the
# integrands have a logarithmic behaviour at k → 0), [K_SPLIT, ∞) by QUADPACK's Fourier
# integrator (QAWF). DEFINITION: any value of order 1 works; 1 puts the split well past the
# logarithmic region.
_K_SPLIT = 1.0


def _step_from_transfer(transfer, s: float) -> float:
    """Causal step response at s > 0 from T(k): T(0) + (2/π)∫₀^∞ Im T(k)/k cos(ks) dk."""

    def g(k: float) -> float:
        return float(np.imag(transfer(k))) / k

    head, _ = quad(lambda k: g(k) * math.cos(k * s), 0.0, _K_SPLIT, limit=200)
    tail, _ = quad(g, _K_SPLIT, math.inf, weight="cos", wvar=s, limlst=200)
    return float(np.real(transfer(0.0))) + 2.0 / math.pi * (head + tail)


def wagner_exact(s) -> np.ndarray:
    """Wagner's function φ(s) [-] from the exact C(k), by numerical Fourier inversion.

    φ(0) = ½ exactly (the lift's circulatory part at the instant of the step); φ(∞) = 1.
    Accurate to about 1e-7 (QUADPACK's error estimate), slow (~ms per point): a reference.
    """
    s_arr = np.atleast_1d(np.asarray(s, dtype=float))
    out = np.empty_like(s_arr)
    for i, si in enumerate(s_arr):
        if si < 0.0:
            out[i] = 0.0
        elif si == 0.0:
            out[i] = 0.5
        else:
            out[i] = _step_from_transfer(lambda k: theodorsen_c(k), si)
    return out if np.ndim(s) else out[0]


def kussner_exact(s) -> np.ndarray:
    """Küssner's function ψ(s) [-] from the exact Sears function, by Fourier inversion.

    s [semichords] from the moment the gust front meets the leading edge; ψ(0) = 0, ψ(∞) = 1.
    """
    s_arr = np.atleast_1d(np.asarray(s, dtype=float))
    out = np.empty_like(s_arr)
    for i, si in enumerate(s_arr):
        if si <= 0.0:
            out[i] = 0.0
        else:
            out[i] = _step_from_transfer(lambda k: sears_s(k, reference="leading-edge"), si)
    return out if np.ndim(s) else out[0]


# --------------------------------------------------------------------------------------
# Finite-state model of one strip
# --------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class StripStateSpace:
    """Finite-state (time-domain) Theodorsen/Küssner loads of one strip, per unit span.

    With q = (h [m], α [rad]) (h down, α nose up, about the elastic axis) and the gust
    velocity w_g [m/s] (positive up) at the strip's leading edge:

        ẋ = A x + B_q q + B_qd q̇ + B_g w_g
        f = C x + D_q q + D_qd q̇ − M_nc q̈ + D_g w_g

    f = (−L' [N/m], M' [N·m/m]) are the generalised forces on (h, α). The apparent-mass term
    −M_nc q̈ is kept apart: a structural model adds M_nc to its mass matrix.

    The lag states x [m] are the upwash filtered by each exponential of the indicial
    functions: x_j' = −β_j (V/b) x_j + Q for Wagner's states (Q the three-quarter-chord
    upwash [m/s]), with w_g in place of Q for Küssner's. The lagged upwash is then
    Q_eff = φ(0) Q + (V/b) Σ A_j β_j x_j [m/s], and f_c = d·Q_eff (circulatory lift at the
    quarter chord, d of :class:`~bioflex_jsb.aerodynamics.theodorsen.SectionMatrices`).
    Its frequency response is Theodorsen's (Sears') with C(k) replaced by the approximation's
    transfer function (checked in tests/test_unsteady_aero.py).

    Attributes: the matrices above (A (n, n) [1/s]; B_q, B_qd (n, 2) [m/s per unit of
    (h, α) and (ḣ, α̇)]; B_g (n,) [-]; C (2, n) [per metre of lag state]; D_* alike),
    ``state_names`` and ``state_units`` (n,), ``section`` the underlying
    :class:`SectionMatrices`, ``speed_m_s``, ``semichord_m``.
    """

    a: np.ndarray
    b_q: np.ndarray
    b_qd: np.ndarray
    b_g: np.ndarray
    c: np.ndarray
    d_q: np.ndarray
    d_qd: np.ndarray
    d_g: np.ndarray
    apparent_mass: np.ndarray
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    section: SectionMatrices
    speed_m_s: float
    semichord_m: float

    @property
    def n_states(self) -> int:
        return int(self.a.shape[0])

    def force_matrix(self, frequency_rad_s: float) -> np.ndarray:
        """Complex 2×2 (−L̄', M̄') per (h̄, ᾱ) of the finite-state model at ω [rad/s]."""
        iw = 1j * float(frequency_rad_s)
        resolvent = np.linalg.solve(iw * np.eye(self.n_states) - self.a,
                                    self.b_q + iw * self.b_qd)
        return self.c @ resolvent + self.d_q + iw * self.d_qd - iw * iw * self.apparent_mass

    def gust_force(self, frequency_rad_s: float) -> np.ndarray:
        """Complex (−L̄', M̄') per unit gust amplitude w̄_g [m/s] at the leading edge, at ω."""
        iw = 1j * float(frequency_rad_s)
        resolvent = np.linalg.solve(iw * np.eye(self.n_states) - self.a, self.b_g)
        return self.c @ resolvent + self.d_g

    def to_state_space(self) -> StateSpace:
        """This strip as the package's :class:`~bioflex_jsb.state_space.StateSpace`: inputs
        (h [m], α [rad], their rates and accelerations, w_g [m/s]), outputs
        (``minus_lift_n_per_m`` −L' [N/m], ``moment_n_m_per_m`` M' [N·m/m], nose up about the
        elastic axis), states the lag states [m]
        (:func:`~bioflex_jsb.state_space.with_motion_inputs`)."""
        return with_motion_inputs("strip", self.speed_m_s, self, ("h", "alpha"), ("m", "rad"),
                                  ("minus_lift_n_per_m", "moment_n_m_per_m"),
                                  ("N/m", "N m/m"))


def strip_state_space(
    *,
    speed_m_s: float,
    semichord_m: float,
    elastic_axis_a: float,
    density_kg_m3: float,
    lift_slope_per_rad: float = TWO_PI,
    gust: bool = True,
    wagner: ExponentialIndicial = JONES_WAGNER,
    kussner: ExponentialIndicial = SEARS_SPARKS_KUSSNER,
    strip_label: str = "",
) -> StripStateSpace:
    """State-space matrices of one strip (see :class:`StripStateSpace`).

    ``gust=False`` leaves out Küssner's states (B_g, D_g are then zero columns).
    ``strip_label`` is appended to the state names (e.g. ``"[3]"`` for strip 3).
    """
    v, b = float(speed_m_s), float(semichord_m)
    if not v > 0.0:
        raise ValueError("the finite-state model needs speed_m_s > 0 (its poles are β V/b)")
    sec = section_matrices(
        speed_m_s=v, semichord_m=b, elastic_axis_a=elastic_axis_a,
        density_kg_m3=density_kg_m3, lift_slope_per_rad=lift_slope_per_rad,
    )
    parts = [(wagner, "wagner")] + ([(kussner, "kussner")] if gust else [])
    n = sum(len(p.exponents) for p, _ in parts)
    a = np.zeros((n, n))
    b_q = np.zeros((n, 2))
    b_qd = np.zeros((n, 2))
    b_g = np.zeros(n)
    c = np.zeros((2, n))
    names, units = [], []
    i = 0
    for func, tag in parts:
        for j, (amp, beta) in enumerate(zip(func.amplitudes, func.exponents, strict=True)):
            a[i, i] = -beta * v / b
            if tag == "wagner":
                b_q[i] = sec.upwash_displacement
                b_qd[i] = sec.upwash_rate
            else:
                b_g[i] = sec.gust_vector
            c[:, i] = sec.force_vector * (v / b) * amp * beta
            names.append(f"{tag}_lag_{j + 1}_m{strip_label}")
            units.append("m")
            i += 1
    phi0 = wagner.initial_value
    d_q = phi0 * np.outer(sec.force_vector, sec.upwash_displacement)
    d_qd = -sec.apparent_damping + phi0 * np.outer(sec.force_vector, sec.upwash_rate)
    d_g = (kussner.initial_value if gust else 0.0) * sec.force_vector * sec.gust_vector
    return StripStateSpace(
        a=a, b_q=b_q, b_qd=b_qd, b_g=b_g, c=c, d_q=d_q, d_qd=d_qd, d_g=d_g,
        apparent_mass=sec.apparent_mass, state_names=tuple(names), state_units=tuple(units),
        section=sec, speed_m_s=v, semichord_m=b,
    )
