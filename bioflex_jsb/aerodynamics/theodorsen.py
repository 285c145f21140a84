"""Unsteady thin-aerofoil theory of a 2-D section: Theodorsen's and Sears' functions.

Sources (cited below by short name):

* Theodorsen (1935): T. Theodorsen, "General theory of aerodynamic instability and the
  mechanism of flutter", NACA Report 496.
* Sears (1941): W. R. Sears, "Some aspects of non-stationary airfoil theory and its practical
  application", J. Aeronautical Sciences 8(3), 104-108.
* BAH (1955): R. L. Bisplinghoff, H. Ashley, R. L. Halfman, *Aeroelasticity*, Addison-Wesley,
  Chapter 5 (oscillating aerofoil, gusts; C(k) tabulated).
* Hodges & Pierce (2011): D. H. Hodges, G. A. Pierce, *Introduction to Structural Dynamics and
  Aeroelasticity*, 2nd ed., Cambridge, Chapter 5 (Theodorsen's lift and moment).

Frames and signs (the beam's, :mod:`bioflex_jsb.structures.beam`, and ``docs/conventions.md``):

* the section has semichord b [m]; chordwise positions are measured in semichords from the
  mid-chord, positive **aft**: leading edge −1, trailing edge +1;
* the elastic axis (the pitch axis) is at ``a`` semichords aft of the mid-chord
  (a = 2·x_E/c − 1 for x_E a chord fraction from the leading edge);
* heave h [m] of the elastic axis is positive **down**; pitch α [rad] is positive
  **nose (leading edge) up**; the free stream V [m/s] flows from leading to trailing edge;
* lift L' [N/m] per unit span is positive **up**; the moment M' [N·m/m] about the elastic axis
  is positive **nose up**. The generalised forces that do work on (h, α) are (−L', M');
* harmonic motion is written q(t) = Re(q̄ e^{iωt}) (Theodorsen's convention); the reduced
  frequency is k = ωb/V [-], based on the semichord;
* a vertical gust w_g [m/s] is positive **up** (it raises the angle of attack by w_g/V).

The loads (Theodorsen 1935; Hodges & Pierce 2011, Chapter 5, written here with a
general circulatory lift slope a₀):

    L' = πρb² (ḧ + Vα̇ − b a α̈) + a₀ ρ V b C(k) Q
    M' = πρb² (b a ḧ − V b (½ − a) α̇ − b² (⅛ + a²) α̈) + a₀ ρ V b² (a + ½) C(k) Q
    Q  = ḣ + V α + b (½ − a) α̇       [m/s], the upwash at the three-quarter chord

The first groups are the non-circulatory (apparent-mass) loads of the thin plate; the second
the circulatory lift a₀ρVbQ at the quarter chord, lagged by C(k). ``lift_slope_per_rad``
(a₀, default 2π) scales only the circulatory part, so that a strip can carry the spanwise
lift slope of a lifting-surface solution (the apparent mass is a property of the section's
shape, not of its circulation, and keeps its thin-plate value).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import hankel2, j0, j1

TWO_PI = 2.0 * math.pi
"""Thin-aerofoil lift slope [1/rad] (the default a₀)."""


def _reduced_frequency(k) -> np.ndarray:
    kk = np.asarray(k, dtype=float)
    if np.any(kk < 0.0) or not np.all(np.isfinite(kk)):
        raise ValueError("reduced frequency k must be finite and ≥ 0")
    return kk


def theodorsen_c(reduced_frequency) -> np.ndarray | complex:
    """Theodorsen's function C(k) = H₁⁽²⁾(k) / (H₁⁽²⁾(k) + i H₀⁽²⁾(k)) [-] (Theodorsen 1935).

    ``reduced_frequency`` k = ωb/V ≥ 0 (scalar or array). Exact, from the Hankel functions of
    the second kind (:func:`scipy.special.hankel2`). Limits: C(0) = 1 (steady flow),
    C(k) → ½ as k → ∞. For k = 0 the limit 1 is returned (the Hankel functions are singular).
    """
    k = _reduced_frequency(reduced_frequency)
    out = np.ones(k.shape, dtype=complex)
    pos = k > 0.0
    kp = k[pos]
    h1 = hankel2(1, kp)
    h0 = hankel2(0, kp)
    out[pos] = h1 / (h1 + 1j * h0)
    return out if out.ndim else complex(out)


def sears_s(reduced_frequency, *, reference: str = "mid-chord") -> np.ndarray | complex:
    """Sears' function S(k) [-]: lift of a section in a sinusoidal vertical gust (Sears 1941).

    A gust w_g(x, t) = w̄ e^{iω(t − x/V)} (x from the mid-chord, positive aft) gives the
    lift L' = a₀ ρ V b S(k) w̄ e^{iωt} with a₀ = 2π (Sears 1941; BAH 1955, Chapter 5).

    ``reference="mid-chord"``: S(k) = [J₀(k) − i J₁(k)] C(k) + i J₁(k), the gust's phase
    taken at the mid-chord (Sears' form). ``reference="leading-edge"``: the gust's phase taken
    where it meets the leading edge, S_LE(k) = S(k) e^{−ik}; this is the transform of
    Küssner's indicial function (:mod:`bioflex_jsb.aerodynamics.indicial`). S(0) = 1 for both.
    """
    if reference not in ("mid-chord", "leading-edge"):
        raise ValueError(f"reference must be 'mid-chord' or 'leading-edge', not {reference!r}")
    k = _reduced_frequency(reduced_frequency)
    c = np.asarray(theodorsen_c(k))
    s = (j0(k) - 1j * j1(k)) * c + 1j * j1(k)
    if reference == "leading-edge":
        s = s * np.exp(-1j * k)
    return s if np.ndim(s) else complex(s)


def elastic_axis_a(x_elastic_frac: float) -> float:
    """``a`` [semichords aft of mid-chord] of an axis at ``x_elastic_frac`` chords from the LE."""
    return 2.0 * float(x_elastic_frac) - 1.0


@dataclass(frozen=True)
class SectionMatrices:
    """Theodorsen's loads of one section as matrices on q = (h [m], α [rad]).

    Generalised forces per unit span f = (−L' [N/m], M' [N·m/m]):

        f = −M_nc q̈ − B_nc q̇ + C(k) · d (wᵀ q + eᵀ q̇)

    Attributes:
        apparent_mass: M_nc (2, 2), units [[kg/m, kg], [kg, kg·m]]; symmetric, positive
            definite (the thin plate's apparent mass and inertia about the axis).
        apparent_damping: B_nc (2, 2), units [[kg/(m·s), kg/s], [kg/s, kg·m/s]].
        force_vector: d = a₀ ρ V b (−1, b (a + ½)) [kg/(m·s), kg/s]: the generalised forces
            per unit three-quarter-chord upwash Q [m/s] (lift at the quarter chord).
        upwash_displacement: w = (0, V) [1/s, m/s]: Q from q.
        upwash_rate: e = (1, b (½ − a)) [-, m]: Q from q̇.
        gust_vector: the upwash of a gust [m/s] per unit gust velocity [-]; the gust's
            generalised forces are d·(Küssner- or Sears-lagged w_g).
    """

    apparent_mass: np.ndarray
    apparent_damping: np.ndarray
    force_vector: np.ndarray
    upwash_displacement: np.ndarray
    upwash_rate: np.ndarray
    gust_vector: float = 1.0


def section_matrices(
    *,
    speed_m_s: float,
    semichord_m: float,
    elastic_axis_a: float,
    density_kg_m3: float,
    lift_slope_per_rad: float = TWO_PI,
) -> SectionMatrices:
    """The matrices of :class:`SectionMatrices` for one section (see the module docstring)."""
    v, b, a, rho = float(speed_m_s), float(semichord_m), float(elastic_axis_a), float(
        density_kg_m3
    )
    if not (b > 0.0 and rho > 0.0 and v >= 0.0):
        raise ValueError("need semichord_m > 0, density_kg_m3 > 0 and speed_m_s ≥ 0")
    if not lift_slope_per_rad > 0.0:
        raise ValueError(f"lift_slope_per_rad must be positive, got {lift_slope_per_rad}")
    pr = math.pi * rho * b * b
    m_nc = pr * np.array([[1.0, -b * a], [-b * a, b * b * (0.125 + a * a)]])
    b_nc = pr * v * np.array([[0.0, 1.0], [0.0, b * (0.5 - a)]])
    d = float(lift_slope_per_rad) * rho * v * b * np.array([-1.0, b * (a + 0.5)])
    return SectionMatrices(
        apparent_mass=m_nc,
        apparent_damping=b_nc,
        force_vector=d,
        upwash_displacement=np.array([0.0, v]),
        upwash_rate=np.array([1.0, b * (0.5 - a)]),
    )


def circulation_value(circulation: str | complex, frequency_rad_s: float,
                      semichord_m: float, speed_m_s: float) -> complex:
    """The circulatory factor of the loads at ω [rad/s]: ``"theodorsen"`` the exact C(k),
    k = |ω| b/V (its conjugate for ω < 0: q̄ e^{iωt} with ω < 0 is the complex-conjugate
    response), ``"quasi-steady"`` 1, or a complex number used as C directly."""
    if not isinstance(circulation, str):
        return complex(circulation)
    if circulation == "quasi-steady":
        return 1.0 + 0.0j
    if circulation != "theodorsen":
        raise ValueError(f"circulation must be 'theodorsen' or 'quasi-steady', not "
                         f"{circulation!r}")
    w = float(frequency_rad_s)
    c = complex(theodorsen_c(abs(w) * semichord_m / speed_m_s))
    return c.conjugate() if w < 0.0 else c


def section_force_matrix(
    frequency_rad_s: float,
    *,
    speed_m_s: float,
    semichord_m: float,
    elastic_axis_a: float,
    density_kg_m3: float,
    lift_slope_per_rad: float = TWO_PI,
    circulation: str | complex = "theodorsen",
) -> np.ndarray:
    """Complex 2×2 matrix A(ω): (−L̄', M̄') = A (h̄, ᾱ) for harmonic motion at ω [rad/s].

    ``circulation``: ``"theodorsen"`` uses the exact C(k), ``"quasi-steady"`` C = 1 (the
    quasi-steady theory with apparent mass and three-quarter-chord upwash), or a complex
    number used as C directly (e.g. an approximation of C(k)).
    """
    mats = section_matrices(
        speed_m_s=speed_m_s,
        semichord_m=semichord_m,
        elastic_axis_a=elastic_axis_a,
        density_kg_m3=density_kg_m3,
        lift_slope_per_rad=lift_slope_per_rad,
    )
    w = float(frequency_rad_s)
    c = circulation_value(circulation, w, semichord_m, speed_m_s)
    upwash = mats.upwash_displacement + 1j * w * mats.upwash_rate
    return (w * w) * mats.apparent_mass - 1j * w * mats.apparent_damping + c * np.outer(
        mats.force_vector, upwash
    )


def section_lift_moment(
    heave_m: complex,
    pitch_rad: complex,
    frequency_rad_s: float,
    **kwargs,
) -> tuple[complex, complex]:
    """Complex amplitudes (L̄' [N/m], up; M̄' [N·m/m], nose up) for harmonic h̄, ᾱ.

    Keyword arguments as :func:`section_force_matrix`.
    """
    f = section_force_matrix(frequency_rad_s, **kwargs) @ np.array([heave_m, pitch_rad],
                                                                  dtype=complex)
    return complex(-f[0]), complex(f[1])


def divergence_dynamic_pressure_pa(
    *, semichord_m: float, elastic_axis_a: float, torsional_stiffness_n_m_per_rad: float,
    lift_slope_per_rad: float = TWO_PI,
) -> float:
    """Divergence dynamic pressure ½ρV² [Pa] of a 2-D section on a torsion spring [N·m/rad/m].

    Steady lift q·2b·a₀·α at the quarter chord, b (a + ½) ahead of the axis: divergence when
    q·2b·a₀·b(a + ½) equals the spring stiffness (BAH 1955, Chapter 8). Infinite (returned
    as ``math.inf``) when the axis is at or ahead of the quarter chord.
    """
    arm = float(semichord_m) * (float(elastic_axis_a) + 0.5)
    if arm <= 0.0:
        return math.inf
    return float(torsional_stiffness_n_m_per_rad) / (2.0 * semichord_m * lift_slope_per_rad
                                                    * arm)


# --------------------------------------------------------------------------------------
# the section with a trailing-edge flap: Theodorsen's T-functions
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class FlapTFunctions:
    """Theodorsen's (1935) T-functions T₁ … T₁₄ [-] of a flap hinged at ``c`` semichords aft
    of the mid-chord (−1 ≤ c < 1) on a section whose elastic axis is at ``a`` (T₉, T₁₃, T₁₄
    depend on it); :func:`flap_t_functions`."""

    c: float
    a: float
    t1: float
    t2: float
    t3: float
    t4: float
    t5: float
    t6: float
    t7: float
    t8: float
    t9: float
    t10: float
    t11: float
    t12: float
    t13: float
    t14: float


def flap_t_functions(hinge_c: float, elastic_axis_a: float) -> FlapTFunctions:
    """Theodorsen's T-functions of a flap hinged at ``hinge_c`` [semichords aft of the
    mid-chord, −1 ≤ c < 1; c = 2·hinge − 1 for a hinge at ``hinge`` chord fractions] on a
    section with its elastic axis at ``elastic_axis_a`` [semichords aft of the mid-chord].

    Closed forms in c, with r = √(1 − c²) and φ_c = arccos c (Theodorsen 1935, NACA Report
    496, p. 6; the same in BAH 1955, Chapter 5):

        T₁ = −r (2 + c²)/3 + c φ_c            T₈ = −r (1 + 2c²)/3 + c φ_c
        T₂ = c r² − r (1 + c²) φ_c + c φ_c²   T₉ = ½ (r³/3 + a T₄)
        T₃ = −(⅛ + c²) φ_c² + ¼ c r (7 + 2c²) φ_c − ⅛ r² (5c² + 4)
        T₄ = −φ_c + c r                       T₁₀ = r + φ_c
        T₅ = −r² − φ_c² + 2 c r φ_c           T₁₁ = φ_c (1 − 2c) + r (2 − c)
        T₆ = T₂                               T₁₂ = r (2 + c) − φ_c (2c + 1)
        T₇ = −(⅛ + c²) φ_c + ⅛ c r (7 + 2c²)  T₁₃ = ½ (−T₇ − (c − a) T₁)
                                              T₁₄ = 1/16 + ½ a c

    At c = −1 (the whole chord is the flap, hinged at the leading edge) r = 0, φ_c = π: the
    flap's loads are those of a pitch about the leading edge (tests/test_flap_section.py).
    The thin-aerofoil integrals they come from: ∫_c^1 √((1+x)/(1−x)) dx = T₁₀,
    ∫_c^1 (x − c) √((1+x)/(1−x)) dx = T₁₁/2, ∫_c^1 √(1−x²) dx = −T₄/2,
    ∫_c^1 (x − c) √(1−x²) dx = −T₁/2 (x in semichords from the mid-chord)."""
    c, a = float(hinge_c), float(elastic_axis_a)
    if not (math.isfinite(c) and -1.0 <= c < 1.0):
        raise ValueError(f"flap hinge c must satisfy -1 <= c < 1 semichords, got {hinge_c!r}")
    if not math.isfinite(a):
        raise ValueError(f"elastic axis a must be finite, got {elastic_axis_a!r}")
    r = math.sqrt(1.0 - c * c)
    ph = math.acos(c)
    t1 = -r * (2.0 + c * c) / 3.0 + c * ph
    t2 = c * r * r - r * (1.0 + c * c) * ph + c * ph * ph
    t3 = (-(0.125 + c * c) * ph * ph + 0.25 * c * r * (7.0 + 2.0 * c * c) * ph
          - 0.125 * r * r * (5.0 * c * c + 4.0))
    t4 = -ph + c * r
    t5 = -r * r - ph * ph + 2.0 * c * r * ph
    t7 = -(0.125 + c * c) * ph + 0.125 * c * r * (7.0 + 2.0 * c * c)
    t8 = -r * (1.0 + 2.0 * c * c) / 3.0 + c * ph
    t9 = 0.5 * (r**3 / 3.0 + a * t4)
    t10 = r + ph
    t11 = ph * (1.0 - 2.0 * c) + r * (2.0 - c)
    t12 = r * (2.0 + c) - ph * (2.0 * c + 1.0)
    t13 = 0.5 * (-t7 - (c - a) * t1)
    t14 = 1.0 / 16.0 + 0.5 * a * c
    return FlapTFunctions(c, a, t1, t2, t3, t4, t5, t2, t7, t8, t9, t10, t11, t12, t13, t14)


@dataclass(frozen=True)
class FlapSectionMatrices:
    """Theodorsen's loads of a section with a flap as matrices on q = (h [m], α [rad],
    β [rad]): h heave down, α pitch nose up about the elastic axis, β the flap's angle about
    its hinge, trailing edge down. Generalised forces per unit span f = (−L' [N/m], M'_α
    [N·m/m], nose up about the elastic axis, M'_β [N·m/m], the hinge moment, trailing edge
    down; the work-conjugates of q):

        f = −M_nc q̈ − B_nc q̇ − K_nc q + C(k) d (wᵀ q + eᵀ q̇)

    ``apparent_mass`` M_nc (3, 3) symmetric, ``apparent_damping`` B_nc, ``apparent_stiffness``
    K_nc (the flap's steady non-circulatory moment and hinge moment: V² terms),
    ``force_vector`` d = a₀ ρ V b (−1, b (a + ½), −b T₁₂/2π) per unit three-quarter-chord
    upwash Q [m/s], ``upwash_displacement`` w = (0, V, V T₁₀/π), ``upwash_rate``
    e = (1, b (½ − a), b T₁₁/2π); ``t`` the T-functions."""

    apparent_mass: np.ndarray
    apparent_damping: np.ndarray
    apparent_stiffness: np.ndarray
    force_vector: np.ndarray
    upwash_displacement: np.ndarray
    upwash_rate: np.ndarray
    t: FlapTFunctions


def flap_section_matrices(*, speed_m_s: float, semichord_m: float, elastic_axis_a: float,
                          hinge_c: float, density_kg_m3: float,
                          lift_slope_per_rad: float = TWO_PI) -> FlapSectionMatrices:
    """:class:`FlapSectionMatrices` of one section: Theodorsen's (1935) lift, moment about
    the elastic axis and hinge moment for heave, pitch and flap motion (written with the
    T-functions of :func:`flap_t_functions`; lift up):

        L'  = πρb² (ḧ + Vα̇ − b a α̈) − ρb² (V T₄ β̇ + b T₁ β̈) + a₀ρVb C(k) Q
        M'_α = πρb² (b a ḧ − V b (½ − a) α̇ − b² (⅛ + a²) α̈)
              + ρb² (−V² (T₄ + T₁₀) β + V b (−T₁ + T₈ + (c − a) T₄ − ½ T₁₁) β̇
                     + b² (T₇ + (c − a) T₁) β̈) + a₀ρVb² (a + ½) C(k) Q
        M'_β = −ρb² ((−2T₉ − T₁ + T₄ (a − ½)) V b α̇ + 2 T₁₃ b² α̈ + V² (T₅ − T₄T₁₀) β/π
                     − T₄T₁₁ V b β̇/2π − T₃ b² β̈/π − T₁ b ḧ) − (a₀/2π) ρVb² T₁₂ C(k) Q
        Q   = ḣ + V α + b (½ − a) α̇ + V T₁₀ β/π + b T₁₁ β̇/2π      [m/s]

    ``lift_slope_per_rad`` a₀ scales the circulatory part only (the apparent mass keeps its
    thin-plate value, as :func:`section_matrices`); with β = 0 the (h, α) block is
    :func:`section_matrices`'s."""
    v, b, a, rho = (float(speed_m_s), float(semichord_m), float(elastic_axis_a),
                    float(density_kg_m3))
    if not (b > 0.0 and rho > 0.0 and v >= 0.0):
        raise ValueError("need semichord_m > 0, density_kg_m3 > 0 and speed_m_s ≥ 0")
    if not lift_slope_per_rad > 0.0:
        raise ValueError(f"lift_slope_per_rad must be positive, got {lift_slope_per_rad}")
    t = flap_t_functions(hinge_c, a)
    c = t.c
    rb2 = rho * b * b
    pi = math.pi
    m_ab = -rb2 * b * b * (t.t7 + (c - a) * t.t1)
    m_nc = np.array([
        [pi * rb2, -pi * rb2 * b * a, -rb2 * b * t.t1],
        [-pi * rb2 * b * a, pi * rb2 * b * b * (0.125 + a * a), m_ab],
        [-rb2 * b * t.t1, m_ab, -rb2 * b * b * t.t3 / pi]])
    b_nc = rb2 * v * np.array([
        [0.0, pi, -t.t4],
        [0.0, pi * b * (0.5 - a), -b * (-t.t1 + t.t8 + (c - a) * t.t4 - 0.5 * t.t11)],
        [0.0, b * (-2.0 * t.t9 - t.t1 + t.t4 * (a - 0.5)), -b * t.t4 * t.t11 / (2.0 * pi)]])
    k_nc = rb2 * v * v * np.array([
        [0.0, 0.0, 0.0],
        [0.0, 0.0, t.t4 + t.t10],
        [0.0, 0.0, (t.t5 - t.t4 * t.t10) / pi]])
    d = float(lift_slope_per_rad) * rho * v * b * np.array(
        [-1.0, b * (a + 0.5), -b * t.t12 / (2.0 * pi)])
    return FlapSectionMatrices(
        apparent_mass=m_nc, apparent_damping=b_nc, apparent_stiffness=k_nc, force_vector=d,
        upwash_displacement=np.array([0.0, v, v * t.t10 / pi]),
        upwash_rate=np.array([1.0, b * (0.5 - a), b * t.t11 / (2.0 * pi)]), t=t)


def flap_section_loads(heave_m: complex, pitch_rad: complex, flap_rad: complex,
                       frequency_rad_s: float, *, speed_m_s: float, semichord_m: float,
                       elastic_axis_a: float, hinge_c: float, density_kg_m3: float,
                       lift_slope_per_rad: float = TWO_PI,
                       circulation: str | complex = "theodorsen"
                       ) -> tuple[complex, complex, complex]:
    """Complex amplitudes (L̄' [N/m] up, M̄'_α [N·m/m] nose up about the elastic axis, M̄'_β
    [N·m/m] hinge moment, trailing edge down) for harmonic h̄ [m], ᾱ, β̄ [rad] at ω [rad/s]
    (:func:`flap_section_matrices`); ``circulation`` as :func:`section_force_matrix`'s:
    ``theodorsen`` (the exact C(k)), ``quasi-steady`` (C = 1) or a complex C."""
    mats = flap_section_matrices(speed_m_s=speed_m_s, semichord_m=semichord_m,
                                 elastic_axis_a=elastic_axis_a, hinge_c=hinge_c,
                                 density_kg_m3=density_kg_m3,
                                 lift_slope_per_rad=lift_slope_per_rad)
    w = float(frequency_rad_s)
    cc = circulation_value(circulation, w, semichord_m, speed_m_s)
    q = np.array([heave_m, pitch_rad, flap_rad], dtype=complex)
    upwash = mats.upwash_displacement + 1j * w * mats.upwash_rate
    f = ((w * w) * mats.apparent_mass - 1j * w * mats.apparent_damping
         - mats.apparent_stiffness + cc * np.outer(mats.force_vector, upwash)) @ q
    return complex(-f[0]), complex(f[1]), complex(f[2])
