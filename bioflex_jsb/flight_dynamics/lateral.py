"""The rigid aircraft's linear lateral-directional model: sideslip, roll and yaw rates, bank.

The paper's model is longitudinal (Eq. 4); it prints no lateral data. This is the other half
of the rigid aircraft's small-perturbation equations about a wings-level trim, built from
lateral derivatives identified from the aircraft's JSBSim model
(:func:`bioflex_jsb.runtime.identification.identify_lateral`; for the prototype, its
generated JSBSim airframe, whose lateral tables are the ESTIMATES of
``parameters/airframe.py``).

Axes and signs (docs/lateral.md):

* **body axes** at the trim (x forward along the fuselage reference line, y to starboard,
  z down), the axes JSBSim's rates ``velocities/p-aero-rad_sec``, ``r-aero-rad_sec`` and its
  moments ``moments/l-aero-lbsft``, ``n-aero-lbsft`` are in; the derivatives are of those
  (body-axis C_Y of the body-y force, C_l, C_n about body x, z through the CG), rates
  non-dimensional with b/(2V);
* state x = [β, p, r, φ]: β the sideslip angle [rad] (v/V, positive with the air from the
  right, nose left of the flight path), p the roll rate [rad/s] (right wing down), r the yaw
  rate [rad/s] (nose right), φ the bank angle [rad] (right wing down);
* inputs: v_g [m/s], a uniform lateral gust, positive **to starboard** (the air moves to the
  right: the aircraft sees β − v_g/V); aileron [rad] (JSBSim's sign, half the difference
  left − right of the surfaces: + = left trailing edge down, roll right); rudder [rad]
  (JSBSim's: + = trailing edge left, nose left);
* outputs: the states and n_y [-], the lateral load factor (side specific force over g,
  positive to starboard: what a lateral accelerometer at the CG reads over g).

Equations (body axes, linearised about β = p = r = φ = 0 with u_0 = V cos α_0,
w_0 = V sin α_0, pitch attitude θ_0; Etkin & Reid, *Dynamics of Flight*, 3rd ed., Sec. 4.9):

    V β̇ = Y_β β + (Y_p + w_0) p + (Y_r − u_0) r + g cos θ_0 φ
    J [ṗ, ṙ]ᵀ = [L, N]ᵀ,  J = [[I_xx, −I_xz], [−I_xz, I_zz]]
    φ̇ = p + tan θ_0 r

with Y_• the side force per unit mass [m/s² per unit], L_•, N_• the moments [N·m per unit],
I_xz = ∫ x z dm the product of inertia (the negative of JSBSim's ``inertia/ixz-slugs_ft2``,
which is the J₁₃ JSBSim integrates with: measured, tests/test_lateral.py).

Modes: ``roll`` (roll subsidence, the fast real root), ``spiral`` (the slow real root,
unstable when positive) and ``dutch_roll`` (the oscillatory pair); a model without an
oscillatory pair (four real roots) names the root nearest the roll-subsidence approximation
``roll``, the slowest ``spiral`` and the other two ``dutch_roll``; one with two pairs names
the faster ``dutch_roll`` and the slower ``roll_spiral`` (the coupled roll-spiral
oscillation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.flight_dynamics.eigen import IMAG_TOL_RAD_S, Mode, ModeSet
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.state_space import StateSpace

LATERAL_STATES = ("beta", "p", "r", "phi")
LATERAL_STATE_UNITS = ("rad", "rad/s", "rad/s", "rad")
LATERAL_INPUTS = ("v_g", "aileron", "rudder")
LATERAL_INPUT_UNITS = ("m/s", "rad", "rad")
LATERAL_LABELS = ("roll", "spiral", "dutch_roll")
ROLL_SPIRAL_LABEL = "roll_spiral"  # the coupled roll-spiral oscillation (two pairs)
MODEL_NAME = "rigid-lateral"


@dataclass(frozen=True)
class LateralAerodynamics:
    """Non-dimensional lateral-directional derivatives [per rad], body axes at the trim,
    moments about the CG on S and b, rates with b/(2V) (module docstring): side force C_Y,
    rolling moment C_l (right wing down), yawing moment C_n (nose right), each of β, p̂ =
    p b/(2V), r̂ = r b/(2V), the aileron and the rudder [rad]."""

    cy_beta: float
    cy_p: float
    cy_r: float
    cy_delta_a: float
    cy_delta_r: float
    cl_beta: float
    cl_p: float
    cl_r: float
    cl_delta_a: float
    cl_delta_r: float
    cn_beta: float
    cn_p: float
    cn_r: float
    cn_delta_a: float
    cn_delta_r: float

    def as_dict(self) -> dict[str, float]:
        return {k: float(getattr(self, k)) for k in self.__dataclass_fields__}


@dataclass(frozen=True)
class LateralTrim:
    """The trim the lateral model is about and the rigid body it belongs to.

    ``speed_m_s`` V [m/s], ``density_kg_m3`` ρ [kg/m³], ``alpha_rad`` α_0 and
    ``theta_rad`` θ_0 [rad] (θ_0 = α_0 + γ_0: a glider's glide has γ_0 < 0), ``mass_kg``
    [kg], ``ixx_kg_m2``, ``izz_kg_m2`` [kg·m²] and ``ixz_kg_m2`` = ∫ x z dm [kg·m²] (body
    axes, z down: module docstring), ``area_m2`` S and ``span_m`` b of the coefficients;
    ``source`` where the derivatives come from."""

    speed_m_s: float
    density_kg_m3: float
    alpha_rad: float
    theta_rad: float
    mass_kg: float
    ixx_kg_m2: float
    izz_kg_m2: float
    ixz_kg_m2: float
    area_m2: float
    span_m: float
    source: str = ""

    @property
    def dynamic_pressure_pa(self) -> float:
        return 0.5 * self.density_kg_m3 * self.speed_m_s**2


@dataclass(frozen=True)
class LateralDerivatives:
    """Dimensional derivatives at a trim: ``y`` side force per unit mass [m/s² per rad, per
    rad/s for p, r]; ``l``, ``n`` the moments [N·m per rad, per rad/s]; ``l_prime``,
    ``n_prime`` the angular accelerations J⁻¹ [L, N] [rad/s² per unit] (the primed
    derivatives of Etkin & Reid). Each a dict keyed ``beta``, ``p``, ``r``, ``delta_a``,
    ``delta_r``."""

    y: dict[str, float]
    l: dict[str, float]  # noqa: E741 (the rolling moment's usual name)
    n: dict[str, float]
    l_prime: dict[str, float]
    n_prime: dict[str, float]


_KEYS = ("beta", "p", "r", "delta_a", "delta_r")


def lateral_derivatives(trim: LateralTrim, aero: LateralAerodynamics) -> LateralDerivatives:
    """The dimensional derivatives of ``aero`` at ``trim`` (module docstring)."""
    v, qs, b = trim.speed_m_s, trim.dynamic_pressure_pa * trim.area_m2, trim.span_m
    rate = b / (2.0 * v)  # p̂ per unit p [s]
    scale = {"beta": 1.0, "p": rate, "r": rate, "delta_a": 1.0, "delta_r": 1.0}
    y = {k: getattr(aero, f"cy_{k}") * qs * scale[k] / trim.mass_kg for k in _KEYS}
    ell = {k: getattr(aero, f"cl_{k}") * qs * b * scale[k] for k in _KEYS}
    en = {k: getattr(aero, f"cn_{k}") * qs * b * scale[k] for k in _KEYS}
    j = inertia_matrix(trim)
    inv = np.linalg.inv(j)
    lp = {k: float(inv[0] @ (ell[k], en[k])) for k in _KEYS}
    np_ = {k: float(inv[1] @ (ell[k], en[k])) for k in _KEYS}
    return LateralDerivatives(y, ell, en, lp, np_)


def inertia_matrix(trim: LateralTrim) -> np.ndarray:
    """J of the roll-yaw equations [kg·m²]: [[I_xx, −I_xz], [−I_xz, I_zz]]."""
    return np.array([[trim.ixx_kg_m2, -trim.ixz_kg_m2], [-trim.ixz_kg_m2, trim.izz_kg_m2]])


def lateral_matrices(trim: LateralTrim, aero: LateralAerodynamics
                     ) -> tuple[np.ndarray, np.ndarray]:
    """A (4×4, states [β, p, r, φ]) and B (4×3, inputs [v_g, aileron, rudder]) of the
    module docstring's equations."""
    d = lateral_derivatives(trim, aero)
    v, g = trim.speed_m_s, STANDARD_GRAVITY_M_S2
    u0, w0 = v * math.cos(trim.alpha_rad), v * math.sin(trim.alpha_rad)
    a = np.array([
        [d.y["beta"] / v, (d.y["p"] + w0) / v, (d.y["r"] - u0) / v,
         g * math.cos(trim.theta_rad) / v],
        [d.l_prime["beta"], d.l_prime["p"], d.l_prime["r"], 0.0],
        [d.n_prime["beta"], d.n_prime["p"], d.n_prime["r"], 0.0],
        [0.0, 1.0, math.tan(trim.theta_rad), 0.0],
    ])
    # the gust enters as β − v_g/V in the aerodynamic terms: the β column (all aerodynamic)
    # over −V
    b_gust = -a[:, 0] / v
    b_ctrl = np.array([[d.y[k] / v, d.l_prime[k], d.n_prime[k], 0.0]
                       for k in ("delta_a", "delta_r")]).T
    return a, np.column_stack([b_gust, b_ctrl])


def build_lateral_state_space(trim: LateralTrim, aero: LateralAerodynamics,
                              notes: dict | None = None) -> StateSpace:
    """The rigid lateral-directional model at ``trim`` (module docstring): states β, p, r,
    φ; inputs v_g [m/s], aileron, rudder [rad]; outputs the states and n_y [-]."""
    a, b = lateral_matrices(trim, aero)
    d = lateral_derivatives(trim, aero)
    g, v = STANDARD_GRAVITY_M_S2, trim.speed_m_s
    # n_y = Y/(m g): the aerodynamic side force of β − v_g/V, p, r and the surfaces
    c_ny = np.array([d.y["beta"], d.y["p"], d.y["r"], 0.0]) / g
    d_ny = np.array([-d.y["beta"] / v, d.y["delta_a"], d.y["delta_r"]]) / g
    c = np.vstack([np.eye(4), c_ny])
    dd = np.vstack([np.zeros((4, 3)), d_ny])
    info = {"axes": "body axes at the trim", "alpha_trim_rad": trim.alpha_rad,
            "theta_trim_rad": trim.theta_rad, "density_kg_m3": trim.density_kg_m3,
            "derivatives": aero.as_dict(), "source": trim.source, **(notes or {})}
    return StateSpace(model=MODEL_NAME, speed_m_s=v, a=a, b=b, c=c, d=dd,
                      states=LATERAL_STATES, state_units=LATERAL_STATE_UNITS,
                      inputs=LATERAL_INPUTS, input_units=LATERAL_INPUT_UNITS,
                      outputs=LATERAL_STATES + ("n_y",),
                      output_units=LATERAL_STATE_UNITS + ("-",), notes=info)


@dataclass(frozen=True)
class ClassicalApproximations:
    """The textbook approximations of the lateral modes, with the primed derivatives for
    I_xz: roll subsidence λ ≈ L'_p [1/s] (roll alone); spiral λ ≈ −(g/V) (L'_β N'_r −
    L'_r N'_β)/(L'_β N'_p − L'_p N'_β) [1/s] (Etkin & Reid, *Dynamics of Flight*, 3rd ed.,
    Sec. 6.7: the last two coefficients of the characteristic polynomial); Dutch roll
    ω_n² ≈ N'_β (1 − Y_r/V) + Y_β N'_r/V [rad²/s²] and 2 ζ ω_n ≈ −(Y_β/V + N'_r) [1/s]
    (sideslip and yaw alone; Nelson, *Flight Stability and Automatic Control*, 2nd ed.,
    Sec. 5.6)."""

    roll_rad_s: float
    spiral_rad_s: float
    dutch_roll_frequency_rad_s: float
    dutch_roll_damping: float


def classical_approximations(trim: LateralTrim, aero: LateralAerodynamics
                             ) -> ClassicalApproximations:
    """:class:`ClassicalApproximations` of ``aero`` at ``trim``."""
    d = lateral_derivatives(trim, aero)
    v = trim.speed_m_s
    lp, np_ = d.l_prime, d.n_prime
    g = STANDARD_GRAVITY_M_S2
    spiral = -(g / v) * (lp["beta"] * np_["r"] - lp["r"] * np_["beta"]) / (
        lp["beta"] * np_["p"] - lp["p"] * np_["beta"])
    w2 = np_["beta"] * (1.0 - d.y["r"] / v) + d.y["beta"] * np_["r"] / v
    wn = math.sqrt(max(w2, 0.0))
    two_zeta_wn = -(d.y["beta"] / v + np_["r"])
    return ClassicalApproximations(lp["p"], spiral, wn,
                                   two_zeta_wn / (2.0 * wn) if wn > 0 else math.inf)


def lateral_mode_labels(lam: np.ndarray, roll_estimate_rad_s: float | None = None
                        ) -> tuple[str, ...]:
    """``roll``, ``spiral``, ``dutch_roll`` (or ``roll_spiral``) for each of the four roots
    ``lam`` of a lateral model (module docstring); ``roll_estimate_rad_s`` (L'_p) picks the
    roll root among four real ones (without it: the fastest)."""
    lam = np.asarray(lam, dtype=complex)
    if lam.shape != (4,):
        raise ValueError(f"expected the 4 lateral eigenvalues, got shape {lam.shape}")
    real = [i for i in range(4) if abs(lam[i].imag) <= IMAG_TOL_RAD_S]
    cplx = [i for i in range(4) if i not in real]
    labels = [""] * 4
    if len(cplx) == 4:
        order = sorted(cplx, key=lambda i: abs(lam[i]))
        for i in order[:2]:
            labels[i] = ROLL_SPIRAL_LABEL
        for i in order[2:]:
            labels[i] = "dutch_roll"
        return tuple(labels)
    for i in cplx:
        labels[i] = "dutch_roll"
    by_speed = sorted(real, key=lambda i: abs(lam[i]))
    spiral = by_speed[0]
    labels[spiral] = "spiral"
    rest = by_speed[1:]
    if len(rest) == 1:
        labels[rest[0]] = "roll"
        return tuple(labels)
    target = roll_estimate_rad_s
    roll = (rest[-1] if target is None
            else min(rest, key=lambda i: abs(lam[i].real - target)))
    for i in rest:
        labels[i] = "roll" if i == roll else "dutch_roll"
    return tuple(labels)


def lateral_mode_set(ss: StateSpace) -> ModeSet:
    """The labelled modes of a lateral model ``ss`` (states β, p, r, φ: one entry per
    conjugate pair, im ≥ 0; both roots of a real Dutch roll), in the order roll, spiral,
    Dutch roll; the roll root among four real ones is the one nearest L'_p = ∂ṗ/∂p."""
    if ss.states != LATERAL_STATES:
        raise ValueError(f"a lateral model has the states {LATERAL_STATES}, not {ss.states}")
    lam = np.linalg.eigvals(ss.a)
    labels = lateral_mode_labels(lam, float(ss.a[1, 1]))
    modes: list[Mode] = []
    for name in ("roll", "spiral", "dutch_roll", ROLL_SPIRAL_LABEL):
        roots = [lam[k] for k in range(4) if labels[k] == name]
        if not roots:
            continue
        complex_roots = [r for r in roots if abs(r.imag) > IMAG_TOL_RAD_S]
        if complex_roots:
            r = max(complex_roots, key=lambda z: z.imag)
            modes.append(Mode(name, float(r.real), float(abs(r.imag))))
        else:
            modes.extend(Mode(name, float(r.real), 0.0) for r in sorted(roots,
                                                                        key=lambda z: z.real))
    return ModeSet(float(ss.speed_m_s), ss.model, tuple(modes))
