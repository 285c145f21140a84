"""The aileron's actuator in the lateral models, and the aileron's unsteady (Theodorsen)
loads on the unsteady strips.

**The actuator.** An aircraft definition's ``[aileron.actuator]``
(:class:`~bioflex_jsb.aeroelasticity.control_surface.SurfaceActuator`) puts the aileron's
angle and rate into the lateral models as states, ``aileron`` δa [rad] and ``aileron_dot``
δ̇a [rad/s] (JSBSim's aileron: ½ (left − right), + rolls right), driven by the input
``aileron_cmd`` [rad]: δ̈a = ω_n² (δa_cmd − δa) − 2 ζ ω_n δ̇a. The model's ``aileron``
column becomes the A column of the state δa (its D entry the C entry), so without the
flap's unsteady terms the actuated model is the model without it in series after the
actuator (:func:`with_actuator`). The actuator does not feel the hinge moment (an ideal,
stiff servo); its roots are ω_n's, apart from the aircraft's (the A matrix is block
triangular: the aircraft's modes are those of the model without it).

**The flap's unsteady loads** (:func:`flap_strip_loads`), strip by strip where the aileron
covers the part χ of it, beyond the quasi-steady flap load that the one builder's coupled
model already carries (its lift Q c χ c_lδ a₀/2π δ_s at the arm e and its thin-aerofoil
moment Q c² χ c_mδ δ_s; JSBSim's C_lδa for the rigid rolling moment): with Theodorsen's
T-functions of the hinge c = 2·hinge − 1 and the physical elastic axis a
(:func:`~bioflex_jsb.aerodynamics.theodorsen.flap_section_matrices`), δ_s = −δa the
starboard surface's angle (trailing edge down):

* circulatory: the flap's three-quarter-chord upwash χ (V T₁₀ δ_s/π + b T₁₁ δ̇_s/2π) [m/s]
  joins the strip's upwash w_¾ in Jones's lag states (their rates and their lift), and the
  increment over the quasi-steady flap lift, ½ρV C_lα c [(1 − A₁ − A₂) w_¾,δ − χ V T₁₀
  δ_s/π], acts with the arm e as the strips' own increments do: in a steady state (δ̇ = 0,
  the lags settled) it vanishes, so the steady roll per aileron is the quasi-steady model's;
* apparent mass (thin plate, χ of the strip): the lift −ρb² χ (V T₄ δ̇_s + b T₁ δ̈_s) and
  the moment about the elastic axis ρb² χ (V b (−T₁ + T₈ + (c − a) T₄ − ½ T₁₁) δ̇_s +
  b² (T₇ + (c − a) T₁) δ̈_s); the steady moment −ρV²b² χ (T₄ + T₁₀) δ_s is the quasi-steady
  model's c_mδ already.

Their rolling moment (both halves, −2 ∫ Δl y dy) acts on ṗ, ṙ through J⁻¹, their
generalised force ∫ (−φ_i Δl + θ_i Δτ) dy on the modes, as the strips' increments do
(:mod:`bioflex_jsb.aeroelasticity.antisymmetric`); δ̈a is the actuator state's rate, so the
apparent mass's δ̈ terms sit on the left with the modes' (E ẋ = A x + B u).
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb.aerodynamics.indicial import JONES_WAGNER
from bioflex_jsb.aerodynamics.theodorsen import flap_section_matrices
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    SurfaceActuator,
    strip_coverage,
)
from bioflex_jsb.state_space import StateSpace

ACTUATOR_STATES = ("aileron", "aileron_dot")
ACTUATOR_UNITS = ("rad", "rad/s")
COMMAND_INPUT = "aileron_cmd"
SURFACE_INPUT = "aileron"


def actuated_inputs(inputs: tuple[str, ...]) -> tuple[str, ...]:
    """``inputs`` with the surface's ``aileron`` renamed ``aileron_cmd``."""
    return tuple(COMMAND_INPUT if name == SURFACE_INPUT else name for name in inputs)


def with_actuator(ss: StateSpace, actuator: SurfaceActuator) -> StateSpace:
    """``ss`` (a lateral model with the input ``aileron`` [rad]) behind ``actuator``: states
    ``aileron`` [rad], ``aileron_dot`` [rad/s] appended, the input ``aileron_cmd`` [rad] in
    the aileron's place, outputs ``aileron``, ``aileron_dot`` appended (module docstring)."""
    col = ss.inputs.index(SURFACE_INPUT)
    n = ss.n_states
    a_act, b_act = actuator.matrices()
    a = np.zeros((n + 2, n + 2))
    a[:n, :n] = ss.a
    a[:n, n] = ss.b[:, col]
    a[n:, n:] = a_act
    b = np.vstack([np.asarray(ss.b, dtype=float), np.zeros((2, ss.b.shape[1]))])
    b[:n, col] = 0.0
    b[n:, col] = b_act[:, 0]
    c = np.zeros((ss.c.shape[0] + 2, n + 2))
    c[:-2, :n] = ss.c
    c[:-2, n] = ss.d[:, col]
    c[-2:, n:] = np.eye(2)
    d = np.vstack([np.asarray(ss.d, dtype=float), np.zeros((2, ss.d.shape[1]))])
    d[:, col] = 0.0
    return StateSpace(
        model=ss.model, speed_m_s=ss.speed_m_s, a=a, b=b, c=c, d=d,
        states=ss.states + ACTUATOR_STATES, state_units=ss.state_units + ACTUATOR_UNITS,
        inputs=actuated_inputs(ss.inputs), input_units=ss.input_units,
        outputs=ss.outputs + ACTUATOR_STATES, output_units=ss.output_units + ACTUATOR_UNITS,
        notes={**ss.notes, "aileron_actuator": actuator_note(actuator)}, dt_s=ss.dt_s)


def actuator_note(actuator: SurfaceActuator) -> str:
    """The models' ``notes["aileron_actuator"]``."""
    return (f"second order, natural frequency {actuator.natural_frequency_rad_s:g} rad/s, "
            f"damping ratio {actuator.damping_ratio:g}: states aileron, aileron_dot, input "
            "aileron_cmd (aeroelasticity/actuated_aileron.py)")


def flap_strip_loads(strips, surface: ControlSurface, n_all: int, lags: tuple[slice, ...],
                     delta: int, delta_dot: int, speed_m_s: float, density_kg_m3: float,
                     unsteadiness: float = 1.0):
    """The aileron's unsteady loads (module docstring) on a state vector of ``n_all`` states
    with the lag states at ``lags`` and δa, δ̇a at ``delta``, ``delta_dot``: (roll_x,
    roll_xd, force_x, force_xd, lag_a) as the fields of
    :class:`~bioflex_jsb.aeroelasticity.antisymmetric.StripLoads` (the ``*_xd`` rows on ẋ:
    δ̈a), then (side_x, side_xd), the side force of that lift on the strips' dihedral
    −2 Σ l Γ_g w [N per unit, body +y; flat wing: zero], ``strips`` the unsteady model's
    :class:`~bioflex_jsb.aeroelasticity.antisymmetric.AntisymmetricStrips`. The increments
    are scaled by ``unsteadiness``; the lags' rates are not."""
    v, rho, eps = float(speed_m_s), float(density_kg_m3), float(unsteadiness)
    k = strips.n_strips
    y, b = strips.stations_m, 0.5 * strips.chord_m
    chi = strip_coverage(strips.weights_m, surface)
    c_hinge = 2.0 * surface.hinge - 1.0
    half = 0.5 * rho * v * strips.cl_alpha_c_m  # lift per m/s of upwash [N/m per m/s]
    # per unit δa (δ_s = −δa): rows over the strips, columns δa, δ̇a (x) and δ̈a (ẋ)
    w34 = np.zeros((k, 2))
    lift_x, lift_xd = np.zeros((k, 2)), np.zeros(k)
    torque_x, torque_xd = np.zeros((k, 2)), np.zeros(k)
    for j in np.flatnonzero(chi):
        m = flap_section_matrices(speed_m_s=v, semichord_m=b[j], elastic_axis_a=strips.a[j],
                                  hinge_c=c_hinge, density_kg_m3=rho)
        w34[j] = -chi[j] * np.array([m.upwash_displacement[2], m.upwash_rate[2]])
        # apparent mass: lift = M_hβ β̈ + B_hβ β̇, moment = −M_αβ β̈ − B_αβ β̇
        lift_x[j, 1] = -chi[j] * m.apparent_damping[0, 2]
        lift_xd[j] = -chi[j] * m.apparent_mass[0, 2]
        torque_x[j, 1] = chi[j] * m.apparent_damping[1, 2]
        torque_xd[j] = chi[j] * m.apparent_mass[1, 2]
    w_qs = np.zeros((k, 2))
    w_qs[:, 0] = w34[:, 0]
    dl = eps * half[:, None] * ((1.0 - sum(JONES_WAGNER.amplitudes)) * w34 - w_qs)
    lift_x = eps * lift_x + dl
    torque_x = eps * torque_x + strips.e_m[:, None] * dl
    lift_xd, torque_xd = eps * lift_xd, eps * torque_xd
    cols = [delta, delta_dot]

    def spread(x2: np.ndarray, xd: np.ndarray | None = None) -> np.ndarray:
        out = np.zeros((x2.shape[0], n_all))
        out[:, cols] = x2
        if xd is not None:
            out[:, delta_dot] = xd
        return out

    w = strips.weights_m

    def roll(lift):
        return -2.0 * (w * y) @ lift

    def force(lift, torque):
        return -(strips.phi * w) @ lift + (strips.theta * w) @ torque

    zero = np.zeros((k, 2))
    lx, tx = spread(lift_x), spread(torque_x)
    lxd, txd = spread(zero, lift_xd), spread(zero, torque_xd)
    n_lag = sum(sl.stop - sl.start for sl in lags)
    lag_a = np.zeros((n_lag, n_all))
    for j, _sl in enumerate(lags):
        rate = JONES_WAGNER.exponents[j] * v / b
        lag_a[j * k:(j + 1) * k] = spread(JONES_WAGNER.amplitudes[j] * rate[:, None] * w34)
    gamma = getattr(strips, "dihedral_rad", None)
    gamma = np.zeros(k) if gamma is None else np.asarray(gamma, dtype=float)

    def side(lift):  # a half's lift leans inboard on its dihedral: port mirrors starboard
        return -2.0 * (w * gamma) @ lift

    return (roll(lx), roll(lxd), force(lx, tx), force(lxd, txd), lag_a, side(lx),
            side(lxd))


def step_response(ss: StateSpace, input_name: str, amplitude: float,
                  times_s: np.ndarray) -> np.ndarray:
    """The outputs of ``ss`` (continuous, from rest) after a step of ``amplitude`` [the
    input's unit] in ``input_name`` at t = 0, at ``times_s`` [s] (rows: times, columns: the
    outputs), exactly: x(t) = ∫₀ᵗ e^{Aτ} dτ B u, the integral the upper-right block of the
    exponential of [[A, B u], [0, 0]] t (Van Loan 1978)."""
    from scipy.linalg import expm

    col = ss.inputs.index(input_name)
    n = ss.n_states
    u = float(amplitude)
    big = np.zeros((n + 1, n + 1))
    big[:n, :n] = ss.a
    big[:n, n] = ss.b[:, col] * u
    out = []
    for t in np.asarray(times_s, dtype=float):
        x = expm(big * t)[:n, n]
        out.append(ss.c @ x + ss.d[:, col] * u)
    return np.array(out)
