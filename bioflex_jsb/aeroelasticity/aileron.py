"""Aileron effectiveness and reversal of an elastic wing: the steady antisymmetric problem
of one half wing on strips and modes.

**The problem.** Ailerons deflected antisymmetrically, δ [rad] trailing edge down on this
(starboard) half and up on the other, load the two halves antisymmetrically; in the body's
frame each half is the cantilever clamped at the root (a wing held at its root, or one
rolling steadily: no roll acceleration, centrifugal loads left out), so one half wing
carries the problem. Steady strips (C = 1, no rates but the roll rate's upwash), each strip k
at y_k [m] with width w_k, chord c_k, lift slope a₀,k, lift acting at its aerodynamic
centre e_k [m] ahead of the elastic axis (a clamped wing's strips: the quarter chord,
Theodorsen's b(a + ½); an aircraft's: Table B1's x_E − x_ac), the surface covering χ_k
of it (:mod:`~bioflex_jsb.aeroelasticity.control_surface`). Per unit dynamic pressure q
[Pa], with modal heave h_ik [m] (down) and twist θ_ik [rad] (leading edge up):

    L'_k / q = c_k a₀,k (Σ_j θ_jk η_j − p̂ y_k / l) + c_k χ_k c_lδ,k δ          [N/m / Pa]
    M'_k / q = e_k L'_k / q + c_k² χ_k c_mδ δ       (about the elastic axis, nose up)
    K η = q (G η + F_δ δ + F_p p̂)                    (modal equilibrium; virtual work)
    R   = q (R_η η + R_δ δ + R_p p̂),  R = Σ_k w_k y_k L'_k                       [N·m]

p̂ = p l / V is the roll rate p [rad/s] of this half rising, non-dimensional with the
semispan l (the aircraft's p b/2V), which lowers the local angle of attack by p y/V; R the
root rolling moment of the half wing's lift (the aircraft's is 2R; its rolling-moment
coefficient 2R/(q S b), S = 2 Σ w c, b = 2l). G_ij = Σ_k w_k c_k a₀,k θ_jk (e_k θ_ik − h_ik);
F_δ, F_p the generalised forces of a unit δ and p̂; K the modal stiffness.

* **Rolling-moment effectiveness** (root held, p̂ = 0): η = q (K − qG)⁻¹ F_δ δ and
  R/δ = q [R_δ + q R_η (K − qG)⁻¹ F_δ]; the effectiveness is R/R_rigid = 1 + q R_η (K −
  qG)⁻¹ F_δ / R_δ (1 at q = 0, a pole at the clamped divergence).
* **Steady roll** (R = 0: the wing's roll damping balances the aileron): the bordered
  system [[K − qG, −qF_p], [R_η, R_p]] (η, p̂) = (qF_δ, −R_δ) δ gives p̂/δ, p b/(2V) per
  radian of aileron; rigid p̂/δ = −R_δ/R_p (full-span uniform strips: 3 c_lδ/(2 a₀)).
* **Reversal** (R/δ = 0 at p̂ = 0): det [[K − qG, −qF_δ], [R_η, R_δ]] = 0, the generalised
  eigenproblem 𝒦 x = q 𝒜 x with 𝒦 = [[K, 0], [R_η, R_δ]], 𝒜 = [[G, F_δ], [0, 0]]: its
  lowest positive real q. The determinant is det(K − qG) · R_δ · effectiveness, so its
  zeros are those of the effectiveness only (the divergence's pole and det(K − qG)'s zero
  cancel). At that q the steady-roll solution is p̂ = 0 too: both effectivenesses reverse
  together (tested). The steady-roll system's own singularity, det [[K − qG, −qF_p],
  [R_η, R_p]] = 0, is the divergence of a wing free to roll (far above the held one in
  every case measured: Goland 726 against 252 m/s).

Validation (``tests/test_aileron.py``): the uniform wing on torsion alone, whose closed form
:func:`uniform_wing_effectiveness` follows (Megson, *Aircraft Structures for Engineering
Students*, §13.2, the finite wing with an aileron over s₁ < z < s; BAH 1955, Chapter 8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import eig

from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
)

# The eigenvalues 1/q of a bordered pencil: real when |Im| is below this share of the
# largest |μ| (round-off of a real eigenvalue of a real pencil is ~1e-15 of it).
REAL_TOLERANCE = 1e-9
# The derived speed range [m/s] (derived_range_m_s), in N_SPEEDS points: its top is
# TOP_OVER_REVERSAL × the reversal speed, or TOP_OVER_DIVERGENCE × the divergence speed when
# that lies within DIVERGENCE_SHOWN × the reversal speed, at most SPEED_LIMIT_M_S (the strips
# are incompressible).
TOP_OVER_REVERSAL = 1.5
TOP_OVER_DIVERGENCE = 1.1
DIVERGENCE_SHOWN = 2.0
SPEED_LIMIT_M_S = 400.0
N_SPEEDS = 241


@dataclass(frozen=True, eq=False)
class RollStrips:
    """One half wing's strips and modes for the steady antisymmetric problem (module
    docstring). Per strip (K,): ``stations_m`` y, ``weights_m`` w, ``chord_m`` c,
    ``lift_slope_per_rad`` a₀, ``arm_m`` e (lift point ahead of the elastic axis),
    ``coverage`` χ, ``flap_lift_per_rad`` c_lδ (a₀/2π of the thin aerofoil's),
    ``flap_moment_per_rad`` c_mδ about the quarter chord; per mode (n, K) ``heave_m``
    (down) and ``twist_rad`` (leading edge up) per unit modal coordinate; ``stiffness``
    (n, n) the modal stiffness in the same units; ``semispan_m`` l; ``surface``;
    ``lift_matrix_m`` (K, K) [m/rad] the lattice's antisymmetric loading l'/q = A α of the
    strips (:mod:`~bioflex_jsb.aerodynamics.antisymmetric_loading`: it replaces c a₀ in
    every lift, the flap's as A (τ χ), τ = c_lδ/a₀), None: the strips' c a₀."""

    stations_m: np.ndarray
    weights_m: np.ndarray
    chord_m: np.ndarray
    lift_slope_per_rad: np.ndarray
    arm_m: np.ndarray
    coverage: np.ndarray
    flap_lift_per_rad: np.ndarray
    flap_moment_per_rad: np.ndarray
    heave_m: np.ndarray = field(repr=False)
    twist_rad: np.ndarray = field(repr=False)
    stiffness: np.ndarray = field(repr=False)
    semispan_m: float = 0.0
    surface: ControlSurface | None = None
    lift_matrix_m: np.ndarray | None = field(default=None, repr=False)


def clamped_roll_strips(model: ClampedWingModel, surface: ControlSurface) -> RollStrips:
    """The :class:`RollStrips` of a clamped wing's model with ``surface`` on its strips
    (the model built with the surface's ends as ``breaks_m`` puts strip edges on them)."""
    if surface.end_m > model.weights_m.sum() * (1.0 + 1e-12):
        raise ValueError(f"the surface ends at {surface.end_m:g} m, beyond the semispan "
                         f"{model.weights_m.sum():g} m")
    b = np.asarray(model.semichord_m, dtype=float)
    a0 = np.asarray(model.lift_slope_per_rad, dtype=float)
    chi = strip_coverage(model.weights_m, surface)
    return RollStrips(
        stations_m=np.asarray(model.stations_m, float),
        weights_m=np.asarray(model.weights_m, float),
        chord_m=2.0 * b, lift_slope_per_rad=a0,
        arm_m=b * (np.asarray(model.elastic_axis_a, float) + 0.5),
        coverage=chi,
        flap_lift_per_rad=flap_lift_slope_per_rad(surface.hinge) * a0 / TWO_PI,
        flap_moment_per_rad=np.full(b.size, flap_moment_slope_per_rad(surface.hinge)),
        heave_m=np.asarray(model.heave_m, float), twist_rad=np.asarray(model.pitch_rad, float),
        stiffness=model.stiffness, semispan_m=float(model.weights_m.sum()), surface=surface)


def flight_roll_strips(build, surface: ControlSurface) -> RollStrips:
    """The :class:`RollStrips` of an aircraft's flight model of the wing (a
    :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild`): its flown modes (half-wing
    generalised masses, K_ii = ω_i² m_i) on the vortex lattice's starboard strips, each with
    the lattice's C_lα c and the arm of Table B1 (x_E − x_ac, after a C_η1^Q1 pin's shift:
    the flight model's), the surface's coverage of each strip a fraction where an end falls
    inside one. The antisymmetric problem on the modes of the clamped half wing: what the
    body frame sees of a wing rolling steadily (module docstring). The build's
    ``lateral_aero`` ``lattice`` loads the strips by the lattice's antisymmetric influence
    matrix (``lift_matrix_m``)."""
    from bioflex_jsb.aerodynamics.antisymmetric_loading import antisymmetric_lift_matrix
    from bioflex_jsb.aeroelasticity.free_aircraft import strip_geometry

    semispan = float(build.aero.semispan_m)
    if surface.end_m > semispan * (1.0 + 1e-12):
        raise ValueError(f"the surface ends at {surface.end_m:g} m, beyond the semispan "
                         f"{semispan:g} m")
    g = strip_geometry(build)
    n = build.model.n_modes
    w = np.asarray(build.aero.weights_m, dtype=float)
    chord = np.asarray(g.chord_m, dtype=float)
    a0 = np.asarray(g.cl_alpha_c_m, dtype=float) / chord
    modes = build.modes
    stiffness = np.diag(np.asarray(modes.frequencies_rad_s[:n], float) ** 2
                        * np.asarray(modes.generalised_masses_kg_m2[:n], float))
    return RollStrips(
        stations_m=np.asarray(build.aero.stations_m, float), weights_m=w, chord_m=chord,
        lift_slope_per_rad=a0, arm_m=np.asarray(g.e_m, float),
        coverage=strip_coverage(w, surface),
        flap_lift_per_rad=flap_lift_slope_per_rad(surface.hinge) * a0 / TWO_PI,
        flap_moment_per_rad=np.full(w.size, flap_moment_slope_per_rad(surface.hinge)),
        heave_m=np.asarray(g.phi[:n], float), twist_rad=np.asarray(g.theta[:n], float),
        stiffness=stiffness, semispan_m=semispan, surface=surface,
        lift_matrix_m=antisymmetric_lift_matrix(build.aero, build.lateral_aero))


@dataclass(frozen=True, eq=False)
class StaticRollMatrices:
    """The per-Pa matrices of the module docstring: ``stiffness`` K, ``aero`` G (n, n),
    ``force_delta`` F_δ, ``force_roll`` F_p (n,) [per rad, per unit p̂], ``moment_eta`` R_η
    (n,), ``moment_delta`` R_δ, ``moment_roll`` R_p [N·m/Pa per rad, per unit p̂];
    ``area_m2`` S = 2 Σ w c, ``span_m`` b = 2l (for the coefficients)."""

    stiffness: np.ndarray
    aero: np.ndarray
    force_delta: np.ndarray
    force_roll: np.ndarray
    moment_eta: np.ndarray
    moment_delta: float
    moment_roll: float
    area_m2: float
    span_m: float

    def _solve(self, q_pa: float, rhs: np.ndarray) -> np.ndarray:
        return np.linalg.solve(self.stiffness - q_pa * self.aero, rhs)

    def rolling_moment_per_rad(self, q_pa: float) -> float:
        """R/δ [N·m/rad] of the half wing, root held (p̂ = 0), at dynamic pressure q [Pa]."""
        q = float(q_pa)
        if q == 0.0:
            return 0.0
        return q * (self.moment_delta
                    + q * float(self.moment_eta @ self._solve(q, self.force_delta)))

    def effectiveness(self, q_pa: float) -> float:
        """Rolling-moment effectiveness R/R_rigid [-], root held, at q [Pa]."""
        q = float(q_pa)
        return 1.0 + q * float(self.moment_eta @ self._solve(q, self.force_delta)) \
            / self.moment_delta

    def rigid_roll_rate_per_rad(self) -> float:
        """Steady p̂/δ = p b/(2V) per radian of aileron of the rigid wing, −R_δ/R_p [1/rad]."""
        return -self.moment_delta / self.moment_roll

    def roll_rate_per_rad(self, q_pa: float) -> float:
        """Steady p̂/δ [1/rad] of the elastic wing at q [Pa] (the bordered system)."""
        q = float(q_pa)
        n = self.stiffness.shape[0]
        a = np.zeros((n + 1, n + 1))
        a[:n, :n] = self.stiffness - q * self.aero
        a[:n, n] = -q * self.force_roll
        a[n, :n] = self.moment_eta
        a[n, n] = self.moment_roll
        rhs = np.concatenate([q * self.force_delta, [-self.moment_delta]])
        return float(np.linalg.solve(a, rhs)[n])

    def coefficients(self) -> dict[str, float]:
        """The rigid wing's C_lδ and C_lp [1/rad] (both halves: 2R/(q S b), p with b/2V)."""
        scale = 2.0 / (self.area_m2 * self.span_m)
        return {"cl_delta_per_rad": scale * self.moment_delta,
                "cl_p_per_rad": scale * self.moment_roll}

    def reversal_dynamic_pressure_pa(self) -> float:
        """The lowest q [Pa] at which R/δ = 0 (module docstring); ``math.inf`` if none."""
        return _lowest_bordered(self.stiffness, self.aero, self.force_delta,
                                self.moment_eta, self.moment_delta)

    def roll_divergence_dynamic_pressure_pa(self) -> float:
        """The lowest q [Pa] at which the steady-roll system is singular (divergence of the
        wing free to roll); ``math.inf`` if none."""
        return _lowest_bordered(self.stiffness, self.aero, self.force_roll,
                                self.moment_eta, self.moment_roll)

    def divergence_dynamic_pressure_pa(self) -> float:
        """The lowest q [Pa] at which K − qG is singular (the clamped wing's divergence, as
        :func:`~bioflex_jsb.aeroelasticity.strip_aero.divergence_speed_m_s`); ``math.inf``
        if none."""
        return _lowest_positive(eig(self.aero, self.stiffness, right=False))


def _lowest_positive(mu: np.ndarray) -> float:
    """1/max μ over the real, positive, finite μ = 1/q; ``math.inf`` if there is none."""
    mu = mu[np.isfinite(mu)]
    if mu.size == 0:
        return math.inf
    real = mu[(np.abs(mu.imag) <= REAL_TOLERANCE * np.abs(mu).max()) & (mu.real > 0.0)].real
    return math.inf if real.size == 0 else float(1.0 / real.max())


def _lowest_bordered(k, g, force, moment_eta, moment_input) -> float:
    n = k.shape[0]
    kk = np.zeros((n + 1, n + 1))
    aa = np.zeros((n + 1, n + 1))
    kk[:n, :n] = k
    kk[n, :n] = moment_eta
    kk[n, n] = moment_input
    aa[:n, :n] = g
    aa[:n, n] = force
    return _lowest_positive(eig(aa, kk, right=False))


def static_roll_matrices(strips: RollStrips) -> StaticRollMatrices:
    """The per-Pa matrices of ``strips`` (module docstring)."""
    s = strips
    w, y, c = s.weights_m, s.stations_m, s.chord_m
    lift_alpha = c * s.lift_slope_per_rad  # [m/rad] lift per span per Pa per rad
    work = s.arm_m * s.twist_rad - s.heave_m  # (n, K): a unit upward lift's virtual work
    lift_delta = c * s.coverage * s.flap_lift_per_rad  # [m/rad]
    moment_delta = s.arm_m * lift_delta + c * c * s.coverage * s.flap_moment_per_rad
    roll_alpha = -y / s.semispan_m  # local angle of attack per unit p̂ [rad]
    if s.lift_matrix_m is not None:
        return _lattice_roll_matrices(s, work, roll_alpha)
    return StaticRollMatrices(
        stiffness=np.asarray(s.stiffness, float),
        aero=(work * (w * lift_alpha)) @ s.twist_rad.T,
        force_delta=(w * (-lift_delta * s.heave_m + moment_delta * s.twist_rad)).sum(axis=1),
        force_roll=(w * lift_alpha * roll_alpha * work).sum(axis=1),
        moment_eta=s.twist_rad @ (w * y * lift_alpha),
        moment_delta=float(np.sum(w * y * lift_delta)),
        moment_roll=float(np.sum(w * y * lift_alpha * roll_alpha)),
        area_m2=float(2.0 * np.sum(w * c)), span_m=2.0 * s.semispan_m)


def _lattice_roll_matrices(s: RollStrips, work: np.ndarray, roll_alpha: np.ndarray
                           ) -> StaticRollMatrices:
    """:func:`static_roll_matrices` with the lattice's loading: each lift l'/q = A α of its
    distribution α (the twists, the roll rate's, the flap's τ χ) in place of c a₀ α."""
    w, y, c, a = s.weights_m, s.stations_m, s.chord_m, np.asarray(s.lift_matrix_m, float)
    lift_twist = s.twist_rad @ a.T  # (n, K) [m per unit η]
    lift_roll = a @ roll_alpha  # [m per unit p̂]
    tau = s.flap_lift_per_rad / s.lift_slope_per_rad  # c_lδ/a₀ = the thin aerofoil's τ
    lift_delta = a @ (s.coverage * tau)  # [m/rad]
    moment_delta = s.arm_m * lift_delta + c * c * s.coverage * s.flap_moment_per_rad
    return StaticRollMatrices(
        stiffness=np.asarray(s.stiffness, float),
        aero=(work * w) @ lift_twist.T,
        force_delta=(w * (-lift_delta * s.heave_m + moment_delta * s.twist_rad)).sum(axis=1),
        force_roll=(w * lift_roll * work).sum(axis=1),
        moment_eta=lift_twist @ (w * y),
        moment_delta=float(np.sum(w * y * lift_delta)),
        moment_roll=float(np.sum(w * y * lift_roll)),
        area_m2=float(2.0 * np.sum(w * c)), span_m=2.0 * s.semispan_m)


def uniform_wing_effectiveness(q_pa, *, torsional_stiffness_n_m2: float, semispan_m: float,
                               chord_m: float, arm_m: float, lift_slope_per_rad: float,
                               flap_lift_per_rad: float, flap_moment_per_rad: float,
                               start_m: float, end_m: float) -> np.ndarray:
    """Closed form of the rolling-moment effectiveness [-] of a uniform wing (torsion only,
    steady strips, root held) with an aileron on ``start_m`` < y < ``end_m``.

    Torsion: GJ θ'' + q c e a₀ θ = −μ(y) GJ, θ(0) = 0, θ'(l) = 0, with the aileron's moment
    about the elastic axis μ GJ = q c (e c_lδ + c c_mδ) δ on the aileron, 0 elsewhere; λ² =
    q c e a₀ / GJ. The root rolling moment needs ∫ θ y dy only: with ψ'' + λ²ψ = y, ψ(0) =
    ψ'(l) = 0, i.e. ψ = y/λ² − sin λy / (λ³ cos λl), Green's identity gives ∫₀ˡ θ y dy =
    −μ ∫ ψ dy over the aileron, so

        R/(q c δ) = c_lδ (y₂² − y₁²)/2 − a₀ μ/δ [(y₂² − y₁²)/(2λ²)
                    + (cos λy₂ − cos λy₁)/(λ⁴ cos λl)],

    and the effectiveness is that over its rigid value c_lδ (y₂² − y₁²)/2 (BAH 1955, Ch. 8;
    Megson, §13.2, the same problem by direct integration). Full span (y₁ = 0, y₂ = l):
    1 − (1 + c c_mδ/(e c_lδ)) [1 − 2 (sec λl − 1)/(λl)²]. ``arm_m`` e [m] (the lift ahead
    of the elastic axis) may be negative (λ imaginary: the formula holds in complex
    arithmetic). ``q_pa`` [Pa] a number or an array."""
    q = np.atleast_1d(np.asarray(q_pa, dtype=float))
    gj, l_m, c, e = torsional_stiffness_n_m2, semispan_m, chord_m, arm_m
    a0, cl, cm = lift_slope_per_rad, flap_lift_per_rad, flap_moment_per_rad
    y1, y2 = start_m, end_m
    out = np.ones(q.size)
    pos = q > 0.0
    qq = q[pos]
    lam = np.sqrt((qq * c * e * a0 / gj).astype(complex))
    mu = qq * c * (e * cl + c * cm) / gj
    integral = ((y2**2 - y1**2) / (2.0 * lam**2)
                + (np.cos(lam * y2) - np.cos(lam * y1)) / (lam**4 * np.cos(lam * l_m)))
    rigid = cl * (y2**2 - y1**2) / 2.0
    out[pos] = ((rigid - a0 * mu * integral) / rigid).real
    return out if np.ndim(q_pa) else float(out[0])


def typical_section_reversal_ratio(*, chord_m: float, arm_m: float, flap_lift_per_rad: float,
                                   flap_moment_per_rad: float) -> float:
    """q_R/q_D of the typical section [-]: −e c_lδ/(c c_mδ) (Hodges & Pierce 2011, Ch. 3;
    Megson §13.2: q_R = −K c_lδ/(S c a₀ c_mδ) against q_D = K/(S e a₀)); the spring's
    stiffness and the lift slope cancel."""
    return -arm_m * flap_lift_per_rad / (chord_m * flap_moment_per_rad)


def _speed(q_pa: float, density_kg_m3: float) -> float | None:
    """V = √(2q/ρ) [m/s], None for q = ∞."""
    return None if not math.isfinite(q_pa) else math.sqrt(2.0 * q_pa / density_kg_m3)


@dataclass(frozen=True, eq=False)
class AileronResult:
    """Aileron effectiveness of an elastic wing against airspeed (module docstring).

    ``speeds_m_s`` (N,) [m/s]; per speed: ``effectiveness`` R/R_rigid [-] (root held),
    ``roll_effectiveness`` (p̂/δ)/(p̂/δ)_rigid [-] (steady roll), ``rolling_moment_per_rad``
    R/δ [N·m/rad] of the half wing (the aircraft's is twice), ``roll_rate_per_rad`` p̂/δ =
    p b/(2V) per radian [1/rad]. Scalars: ``rigid_roll_rate_per_rad``, the rigid wing's
    ``cl_delta_per_rad`` and ``cl_p_per_rad`` (both halves, on S and b), the speeds [m/s] of
    ``reversal_speed_m_s`` (R/δ = 0; None: none), ``divergence_speed_m_s`` (clamped) and
    ``roll_divergence_speed_m_s`` (free to roll) (None: none), the dynamic-pressure ratio
    ``reversal_over_divergence`` q_R/q_D and the typical section's
    ``typical_section_ratio`` −e c_lδ/(c c_mδ) (of the surface's mean section, for
    comparison), ``density_kg_m3``, ``range_m_s``, ``surface`` (its as_dict), ``name``,
    ``settings`` (what the model was: strips, modes, lift slope)."""

    name: str
    speeds_m_s: np.ndarray
    effectiveness: np.ndarray
    roll_effectiveness: np.ndarray
    rolling_moment_per_rad: np.ndarray
    roll_rate_per_rad: np.ndarray
    rigid_roll_rate_per_rad: float
    cl_delta_per_rad: float
    cl_p_per_rad: float
    reversal_speed_m_s: float | None
    divergence_speed_m_s: float | None
    roll_divergence_speed_m_s: float | None
    reversal_over_divergence: float | None
    typical_section_ratio: float
    density_kg_m3: float
    range_m_s: tuple[float, float]
    surface: dict
    settings: dict = field(default_factory=dict)
    # the four curves at one named speed (an aircraft's cruise), computed there: {"speed_m_s",
    # "effectiveness", "roll_effectiveness", "rolling_moment_per_rad", "roll_rate_per_rad"}
    reference: dict | None = None
    # F_δ: the generalised force on each mode of a unit aileron angle per unit dynamic
    # pressure [the modal stiffness's units per Pa per rad] (module docstring)
    modal_force_per_rad_per_pa: tuple[float, ...] = ()

    @property
    def reversal_above_divergence(self) -> bool:
        """Whether the clamped wing diverges before its aileron reverses."""
        return (self.reversal_speed_m_s is not None and self.divergence_speed_m_s is not None
                and self.reversal_speed_m_s > self.divergence_speed_m_s)

    def as_dict(self) -> dict:
        def r(x):
            return None if x is None else float(x)

        return {
            "name": self.name, "wing": self.name, "surface": dict(self.surface),
            "density_kg_m3": self.density_kg_m3, "range_m_s": list(self.range_m_s),
            "reversal_speed_m_s": r(self.reversal_speed_m_s),
            "divergence_speed_m_s": r(self.divergence_speed_m_s),
            "roll_divergence_speed_m_s": r(self.roll_divergence_speed_m_s),
            "reversal_above_divergence": self.reversal_above_divergence,
            "reversal_over_divergence": r(self.reversal_over_divergence),
            "typical_section_ratio": self.typical_section_ratio,
            "rigid": {"cl_delta_per_rad": self.cl_delta_per_rad,
                      "cl_p_per_rad": self.cl_p_per_rad,
                      "roll_rate_pb_2v_per_rad": self.rigid_roll_rate_per_rad,
                      "rolling_moment_per_rad_per_pa": self.rolling_moment_per_rad_per_pa},
            "speeds_m_s": [float(v) for v in self.speeds_m_s],
            "effectiveness": [float(v) for v in self.effectiveness],
            "roll_effectiveness": [float(v) for v in self.roll_effectiveness],
            "rolling_moment_n_m_per_rad": [float(v) for v in self.rolling_moment_per_rad],
            "roll_rate_pb_2v_per_rad": [float(v) for v in self.roll_rate_per_rad],
            "at_reference_speed": None if self.reference is None else dict(self.reference),
            "modal_force_per_rad_per_pa": list(self.modal_force_per_rad_per_pa),
            **self.settings,
        }

    @property
    def rolling_moment_per_rad_per_pa(self) -> float:
        """The rigid half wing's R/(q δ) [N·m/(Pa·rad)] (C_lδ q S b / 2 over q)."""
        return float(self.settings.get("rigid_moment_per_pa_rad", math.nan))

    def at(self, speed_m_s: float) -> dict[str, float]:
        """The four curves interpolated at ``speed_m_s`` [m/s] (within the range)."""
        v = float(speed_m_s)
        return {name: float(np.interp(v, self.speeds_m_s, getattr(self, name)))
                for name in ("effectiveness", "roll_effectiveness", "rolling_moment_per_rad",
                             "roll_rate_per_rad")}

    def plot(self, path, force: bool = False):
        """The effectiveness figure (a matplotlib Figure; written to ``path``: a figure
        suffix, an existing file only if it is a plot of ours or with ``force``): the
        rolling-moment and roll-rate effectiveness, and p b/(2V) per radian of aileron,
        against airspeed, the reversal marked, the divergence dotted."""
        from bioflex_jsb.aeroelasticity.aileron_plot import plot_aileron
        from bioflex_jsb.plot_files import check_plot_target

        return plot_aileron(self, check_plot_target(path, force))


def derived_range_m_s(reversal_m_s: float | None, divergence_m_s: float | None
                      ) -> tuple[float, float]:
    """The default range [m/s]: from 0 to 1.5 × the reversal speed, or to 1.1 × the
    divergence speed when that lies within 2 × the reversal speed (so that the figure shows
    both; Goland with its aileron: 1.1 × 252.3 m/s); without a reversal 1.5 × the
    divergence speed; at most 400 m/s (the strips are incompressible)."""
    if reversal_m_s is None:
        top = SPEED_LIMIT_M_S if divergence_m_s is None else TOP_OVER_REVERSAL * divergence_m_s
    else:
        top = TOP_OVER_REVERSAL * reversal_m_s
        if divergence_m_s is not None and divergence_m_s <= DIVERGENCE_SHOWN * reversal_m_s:
            top = max(top, TOP_OVER_DIVERGENCE * divergence_m_s)
    return 0.0, min(SPEED_LIMIT_M_S, top)


def reversal_speed_m_s(strips: RollStrips, density_kg_m3: float) -> float | None:
    """The aileron reversal speed [m/s] of ``strips`` at ``density_kg_m3`` [kg/m³] (None:
    none): the lowest speed at which the rolling moment per aileron angle, root held, is
    zero; the steady roll rate per aileron angle of the wing free to roll, −R_δ/R_p of the
    same elastic balance, changes sign there too (module docstring)."""
    return _speed(static_roll_matrices(strips).reversal_dynamic_pressure_pa(),
                  float(density_kg_m3))


def aileron_effectiveness(strips: RollStrips, *, density_kg_m3: float,
                          range_m_s: tuple[float, float] | None = None,
                          n_speeds: int = N_SPEEDS, name: str = "",
                          settings: dict | None = None,
                          reference_speed_m_s: float | None = None) -> AileronResult:
    """Effectiveness, steady roll and reversal of ``strips`` (:class:`RollStrips`) at
    ``density_kg_m3`` [kg/m³] over ``range_m_s`` [m/s] (default :func:`derived_range_m_s`)
    in ``n_speeds`` points (module docstring); the curves also at ``reference_speed_m_s``
    [m/s] (an aircraft's cruise) when given."""
    rho = float(density_kg_m3)
    mats = static_roll_matrices(strips)
    v_r = _speed(mats.reversal_dynamic_pressure_pa(), rho)
    q_d = mats.divergence_dynamic_pressure_pa()
    v_d = _speed(q_d, rho)
    v_rd = _speed(mats.roll_divergence_dynamic_pressure_pa(), rho)
    rng = derived_range_m_s(v_r, v_d) if range_m_s is None else (float(range_m_s[0]),
                                                                 float(range_m_s[1]))
    speeds = np.linspace(rng[0], rng[1], int(n_speeds))
    q = 0.5 * rho * speeds**2
    eff = np.array([mats.effectiveness(x) for x in q])
    rate = np.array([mats.roll_rate_per_rad(x) for x in q])
    moment = np.array([mats.rolling_moment_per_rad(x) for x in q])
    rigid_rate = mats.rigid_roll_rate_per_rad()
    coef = mats.coefficients()
    chi = strips.coverage * strips.weights_m
    mean = {k: float(np.sum(chi * getattr(strips, k)) / np.sum(chi))
            for k in ("chord_m", "arm_m", "flap_lift_per_rad", "flap_moment_per_rad")}
    q_r = None if v_r is None else 0.5 * rho * v_r**2
    reference = None
    if reference_speed_m_s is not None:
        q_ref = 0.5 * rho * float(reference_speed_m_s) ** 2
        reference = {"speed_m_s": float(reference_speed_m_s),
                     "effectiveness": mats.effectiveness(q_ref),
                     "roll_effectiveness": mats.roll_rate_per_rad(q_ref) / rigid_rate,
                     "rolling_moment_per_rad": mats.rolling_moment_per_rad(q_ref),
                     "roll_rate_per_rad": mats.roll_rate_per_rad(q_ref)}
    surface = strips.surface.as_dict() if strips.surface is not None else {}
    surface.update(flap_lift_per_rad=mean["flap_lift_per_rad"],
                   flap_moment_quarter_chord_per_rad=mean["flap_moment_per_rad"])
    return AileronResult(
        name=name, speeds_m_s=speeds, effectiveness=eff, roll_effectiveness=rate / rigid_rate,
        rolling_moment_per_rad=moment, roll_rate_per_rad=rate,
        rigid_roll_rate_per_rad=rigid_rate, cl_delta_per_rad=coef["cl_delta_per_rad"],
        cl_p_per_rad=coef["cl_p_per_rad"], reversal_speed_m_s=v_r, divergence_speed_m_s=v_d,
        roll_divergence_speed_m_s=v_rd,
        reversal_over_divergence=None if q_r is None or v_d is None else q_r / q_d,
        typical_section_ratio=typical_section_reversal_ratio(**mean),
        density_kg_m3=rho, range_m_s=rng, surface=surface,
        settings={"rigid_moment_per_pa_rad": mats.moment_delta, "n_strips":
                  int(strips.stations_m.size), "n_modes": int(strips.stiffness.shape[0]),
                  **(settings or {})}, reference=reference,
        modal_force_per_rad_per_pa=tuple(float(f) for f in mats.force_delta))
