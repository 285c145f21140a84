"""The antisymmetric modes' quasi-steady strips per unit flow, with the ailerons on them:
what the nonlinear co-simulation's full-span step (:mod:`bioflex_jsb.simulation.full_span`)
and the linear lateral model with ailerons (:func:`lateral_elastic_with_aileron`) share.

The lateral model of the wing with its aileron, :func:`lateral_model_with_aileron`, is the one
:func:`bioflex_jsb.api.lateral_model` returns and ``compare --span full`` drives.

The strips, modes and signs are those of :mod:`bioflex_jsb.flight_dynamics.lateral_elastic`
(:func:`~bioflex_jsb.flight_dynamics.lateral_elastic.strip_terms` divided by Q or Q/V: the
same arithmetic, tested to 1e-12): the starboard strip at y sees

    Δα = Σ θ_i η_i + Σ φ_i η̇_i / V + (p − p_g) y / V,

carries the lift l = Q C_lα c Δα (up; with the wing's ``lift_matrix_m``, the lattice's
loading, l = Q A Δα of the whole distribution: :mod:`~bioflex_jsb.aerodynamics
.antisymmetric_loading`, the flap's lift then A τ χ δ_s) and, where the aileron covers the
part χ of it, the flap
lift Q c χ c_lδ (a₀/2π) δ_s and the quarter-chord moment Q c² χ c_mδ δ_s (thin aerofoil:
:mod:`~bioflex_jsb.aeroelasticity.control_surface`, the section of
:func:`~bioflex_jsb.aeroelasticity.aileron.flight_roll_strips`); the port strip carries the
opposite. δ_s [rad] is the starboard surface's angle in the antisymmetric sense, trailing edge
down: δ_s = ½ (δ_right − δ_left) = −δa, δa JSBSim's aileron (½ (left − right), + rolls
right); the symmetric part ½ (δ_left + δ_right) (a differential aileron's, flaperons) loads
the symmetric modes and is left out.

**The gust roll rate p_g** [rad/s]: the antisymmetric part of a spanwise-varying vertical
gust, w_g(y) = −p_g y (w_g up, y to starboard: the port wing meets rising air, the starboard
wing sinking air, for p_g > 0), which the strip sees as Δα = −p_g y / V: a gust roll rate
p_g acts on the strips as the aircraft's own roll rate −p_g would (the standard models' p_g,
MIL-F-8785C / MIL-HDBK-1797's p_g = ∂w_g/∂y with w_g down, in this sign: a positive p_g
rolls the aircraft right, the way p is positive).

Per unit flow (module of :class:`AntisymmetricStrips`): the generalised force on mode i
(the virtual work of the half aircraft, whose generalised mass m_i is, Table B1's)

    Q_i = Q [Σ_j F^η_ij η_j + F^δ_i δ_s] + (Q/V) [Σ_j F^η̇_ij η̇_j + F^p_i (p − p_g)]

and the rolling moment of the **deformation's** lift on both halves (about body x, right
wing down positive: a lift up at y > 0 rolls left)

    ΔL = Q Σ_i R^η_i η_i + (Q/V) Σ_i R^η̇_i η̇_i,    R = −2 ∫₀^{b/2} (lift per unit) y dy.

The rigid wing's own roll damping (the (p − p_g) y/V lift) and the aileron's own lift are
**not** in ΔL: JSBSim's rigid tables carry them (C_lp p̂ and C_lδa δa), so only the
deformation's increment goes to JSBSim; the aileron's loss of effectiveness is that
increment, the twist the aileron's hinge moment and lift put into the modes (F^δ) times the
lift it costs (R^η). The gust's rigid rolling moment (−C_lp p_g b/(2V) on the rigid wing) is
the gust's imposer's to add, not this module's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
)
from bioflex_jsb.flight_dynamics.lateral import (
    LateralAerodynamics,
    LateralTrim,
    inertia_matrix,
)
from bioflex_jsb.flight_dynamics.lateral_elastic import (
    LATERAL_MODELS,
    AntisymmetricWing,
    StripTerms,
    build_lateral_elastic,
    lattice_unit_terms,
    residualised,
)
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.state_space import StateSpace


@dataclass(frozen=True, eq=False)
class AntisymmetricStrips:
    """The antisymmetric modes and their strips per unit flow (module docstring).

    ``omega_rad_s``, ``zeta``, ``mass_kg_m2`` (n,) the modes' ω, ζ, generalised mass (half
    aircraft); per unit Q [Pa]: ``force_eta`` (n, n) [N·m/Pa per rad], ``force_delta`` (n,)
    [N·m/Pa per rad of δ_s], ``roll_eta`` (n,) [N·m/Pa per rad]; per unit Q/V [Pa·s/m]:
    ``force_etadot`` (n, n), ``force_p`` (n,), ``roll_etadot`` (n,) [N·m/(Pa·s/m) per rad/s];
    ``tip_twist_rad`` (n,) the starboard tip's twist per unit η_i [rad, leading edge up];
    ``surface`` the aileron (None: no aileron on the strips, F^δ = 0)."""

    omega_rad_s: np.ndarray
    zeta: np.ndarray
    mass_kg_m2: np.ndarray
    force_eta: np.ndarray
    force_etadot: np.ndarray
    force_p: np.ndarray
    force_delta: np.ndarray
    roll_eta: np.ndarray
    roll_etadot: np.ndarray
    tip_twist_rad: np.ndarray
    surface: ControlSurface | None = None

    @property
    def n_modes(self) -> int:
        return int(self.omega_rad_s.size)

    def a_matrix(self, q_pa: float, q_over_v: float) -> np.ndarray:
        """The continuous (2n × 2n) matrix of [η, η̇] at Q [Pa] and Q/V [Pa·s/m]."""
        n, m = self.n_modes, self.mass_kg_m2[:, None]
        a = np.zeros((2 * n, 2 * n))
        a[:n, n:] = np.eye(n)
        a[n:, :n] = -np.diag(self.omega_rad_s**2) + q_pa * self.force_eta / m
        a[n:, n:] = -np.diag(2.0 * self.zeta * self.omega_rad_s) + q_over_v * self.force_etadot / m
        return a

    def forcing_columns(self) -> np.ndarray:
        """(2n × 2) the η̈ rows per unit of the inputs (Q δ_s, (Q/V)(p − p_g))."""
        n = self.n_modes
        b = np.zeros((2 * n, 2))
        b[n:, 0] = self.force_delta / self.mass_kg_m2
        b[n:, 1] = self.force_p / self.mass_kg_m2
        return b

    def quasi_static_eta(self, q_pa: float, q_over_v: float, delta_s_rad: float,
                         relative_roll_rad_s: float) -> np.ndarray:
        """η [rad] balancing the flow with η̇ = η̈ = 0: (diag(m ω²) − Q F^η) η = Q F^δ δ_s +
        (Q/V) F^p (p − p_g)."""
        k = np.diag(self.mass_kg_m2 * self.omega_rad_s**2) - q_pa * self.force_eta
        rhs = q_pa * self.force_delta * delta_s_rad + q_over_v * self.force_p * relative_roll_rad_s
        return np.linalg.solve(k, rhs)


def antisymmetric_strips(wing: AntisymmetricWing, surface: ControlSurface | None,
                         chord_m: np.ndarray) -> AntisymmetricStrips:
    """:class:`AntisymmetricStrips` of ``wing`` (its strips, modes; lateral_elastic's) with
    ``surface`` on them (None: no aileron) and the strips' chords ``chord_m`` [m] (the
    lattice's, ``build.aero.chord_m``)."""
    w, y = wing.weights_m, wing.stations_m
    chord = np.asarray(chord_m, dtype=float)
    if chord.shape != y.shape:
        raise ValueError(f"chord_m has {chord.size} strips, the wing {y.size}")
    clac_w = wing.cl_alpha_c_m * w  # lift of a strip per rad of Δα per Pa [m]
    work = wing.e_m * wing.theta - wing.phi  # (n, K) upward AC displacement per unit η
    if surface is None:
        force_delta = np.zeros(wing.n_modes)
    else:
        chi = strip_coverage(w, surface)
        # flap lift per Pa per rad [m]: c χ c_lδ a₀/2π = χ C_lα c c_lδ/2π (flight_roll_strips);
        # the lattice's: its loading of the angle τ χ, τ = c_lδ/2π (roll_derivatives')
        tau = flap_lift_slope_per_rad(surface.hinge) / TWO_PI
        lift_delta = (chi * wing.cl_alpha_c_m * flap_lift_slope_per_rad(surface.hinge) / TWO_PI
                      if wing.lift_matrix_m is None else wing.lift_m(chi * tau))
        moment_delta = chord**2 * chi * flap_moment_slope_per_rad(surface.hinge)  # [m²]
        force_delta = (w * (lift_delta * work + moment_delta * wing.theta)).sum(axis=1)
    modes = wing.modes
    if wing.lift_matrix_m is not None:  # the lattice's loading (lateral_elastic's terms)
        unit = lattice_unit_terms(wing)
    else:
        unit = StripTerms(
            force_eta=np.einsum("ik,jk,k->ij", work, wing.theta, clac_w),
            force_etadot=np.einsum("ik,jk,k->ij", work, wing.phi, clac_w),
            force_p=work @ (clac_w * y),
            roll_eta=-2.0 * (wing.theta * clac_w) @ y,
            roll_etadot=-2.0 * (wing.phi * clac_w) @ y)
    return AntisymmetricStrips(
        omega_rad_s=np.asarray(modes.frequencies_rad_s, dtype=float),
        zeta=np.asarray(modes.damping_ratios, dtype=float),
        mass_kg_m2=np.asarray(modes.generalised_masses_kg_m2, dtype=float),
        force_eta=unit.force_eta, force_etadot=unit.force_etadot, force_p=unit.force_p,
        force_delta=force_delta, roll_eta=unit.roll_eta, roll_etadot=unit.roll_etadot,
        tip_twist_rad=np.asarray(modes.twist_rad, dtype=float)[:, -1].copy(),
        surface=surface)


def lateral_elastic_with_aileron(ss: StateSpace, strips: AntisymmetricStrips,
                                 dynamic_pressure_pa: float) -> StateSpace:
    """The coupled lateral model ``ss`` (:func:`~bioflex_jsb.flight_dynamics.lateral_elastic
    .build_lateral_elastic`, model ``coupled``, built on the same wing) with the aileron's
    generalised force on the modes in its ``aileron`` column: η̈_i += −Q F^δ_i / m_i · δa
    (δa JSBSim's aileron, δ_s = −δa), at the trim's dynamic pressure [Pa]. The rigid block's
    aileron column (JSBSim's C_lδa) is unchanged: the model the co-simulation's full-span
    step linearises to."""
    if ss.model != "coupled-lateral":
        raise ValueError(f"the aileron's load on the modes goes into the coupled lateral "
                         f"model, not {ss.model!r}")
    n = strips.n_modes
    b = ss.b.copy()
    col = ss.inputs.index("aileron")
    first = ss.states.index("eta1_dot")
    b[first:first + n, col] += -float(dynamic_pressure_pa) * strips.force_delta / strips.mass_kg_m2
    notes = {**ss.notes, "aileron_on_modes": (
        "none: no aileron on the strips" if strips.surface is None else
        "thin-aerofoil flap lift and moment on the lattice's strips, "
        f"{strips.surface.start_m:.6g}-{strips.surface.end_m:.6g} m, hinge "
        f"{strips.surface.hinge:.6g} c (aeroelasticity/antisymmetric_strips.py)")}
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=b, c=ss.c, d=ss.d,
                      states=ss.states, state_units=ss.state_units, inputs=ss.inputs,
                      input_units=ss.input_units, outputs=ss.outputs,
                      output_units=ss.output_units, notes=notes)


def lateral_model_with_aileron(model: str, trim: LateralTrim, aero: LateralAerodynamics,
                               wing: AntisymmetricWing | None, surface: ControlSurface | None,
                               chord_m: np.ndarray | None, static_eta_s=None
                               ) -> tuple[StateSpace, AntisymmetricStrips | None]:
    """(the lateral model, its strips) of ``model`` at ``trim`` with ``aero``'s rigid
    derivatives: ``rigid`` (:func:`~bioflex_jsb.flight_dynamics.lateral_elastic
    .build_lateral_elastic`; strips None), ``coupled`` (the antisymmetric modes of ``wing``
    with ``surface``'s generalised force on them in the aileron column:
    :func:`lateral_elastic_with_aileron`) or ``qsd`` (that model with its modes
    residualised, the aileron's load in their static balance:
    :func:`~bioflex_jsb.flight_dynamics.lateral_elastic.residualised`). ``surface`` None: no
    aileron on the strips (the aileron drives the rigid rolling moment only); ``chord_m``
    [m] the strips' chords (the lattice's, ``build.aero.chord_m``). Inputs v_g [m/s],
    aileron, rudder [rad].

    The coupled and qsd models also hold the yaw rate's and sideslip's terms of the
    nonlinear step linearised about the trim (:func:`lateral_elastic_with_yaw_sideslip`),
    where ``wing`` carries its build's symmetric modes and planform; ``static_eta_s`` [rad]
    the trim's static symmetric deflection (None: zero, a rigid trim's, the one JSBSim
    trims and ``compare --span full`` flies from)."""
    if model == "rigid" or model not in LATERAL_MODELS or wing is None:
        # the rigid model, or the one-line refusal of an unknown model or a missing wing
        return build_lateral_elastic(model, trim, aero, wing), None
    strips = antisymmetric_strips(wing, surface, chord_m)
    coupled = lateral_elastic_with_aileron(build_lateral_elastic("coupled", trim, aero, wing),
                                           strips, trim.dynamic_pressure_pa)
    terms = wing_yaw_sideslip_terms(wing)
    if terms is not None:
        coupled = lateral_elastic_with_yaw_sideslip(coupled, strips, terms, trim, static_eta_s)
    return (coupled if model == "coupled" else residualised(coupled)), strips


def trim_wing_lift_n(trim: LateralTrim) -> float:
    """The wing's lift L_w = n_z W [N] of the yaw rate's terms at the level trim: n_z = 1
    (W = m g)."""
    return float(trim.mass_kg) * STANDARD_GRAVITY_M_S2


def wing_yaw_sideslip_terms(wing: AntisymmetricWing) -> YawSideslipTerms | None:
    """:class:`YawSideslipTerms` of ``wing`` with its build's symmetric modes, planform and
    span (as the full-span step makes them, ``runtime/full_span_step.py``); None for a wing
    without them."""
    if wing.symmetric is None or wing.planform is None:
        return None
    return yaw_sideslip_terms(wing, wing.symmetric, wing.n_symmetric, wing.planform,
                              wing.span_m)


def yaw_sideslip_rows(ss: StateSpace, strips: AntisymmetricStrips, terms: YawSideslipTerms,
                      trim: LateralTrim, static_eta_s=None) -> dict[str, np.ndarray]:
    """The yaw rate's and sideslip's terms of the nonlinear step linearised about ``trim``
    (L_w = m g, its Q, V; η_s = ``static_eta_s`` [rad], None zero), each a row over the
    states of the coupled model ``ss``: ``forcing`` (n_a × states) the generalised force on
    the antisymmetric modes [N·m per unit state] (:meth:`YawSideslipTerms.forcing`: r and β
    columns); ``roll`` the rolling moment of the yaw rate and sideslip on η_s [N·m, right
    wing down] (:meth:`~YawSideslipTerms.roll_n_m`: r, β); ``side`` the side force [N,
    body +y] (:meth:`~YawSideslipTerms.side_n`: η_a, η̇_a); ``yaw`` the yawing moment [N·m,
    nose right] (:meth:`~YawSideslipTerms.yaw_n_m`: η̇_a, p, and the induced drag of all the
    elastic rolling moment, ΔL of η_a, η̇_a and the roll row's r, β). Products of the
    lateral quantities with the changes of L_w, Q, V and η_s are second order and left out."""
    n, n_s = strips.n_modes, terms.roll_r_s.size
    q, v = float(trim.dynamic_pressure_pa), float(trim.speed_m_s)
    lift = trim_wing_lift_n(trim)
    eta_s = np.zeros(n_s) if static_eta_s is None else np.asarray(static_eta_s, dtype=float)
    if eta_s.shape != (n_s,):
        raise ValueError(f"static_eta_s has {eta_s.size} modes, the terms {n_s}")
    states = ss.states
    i_b, i_p, i_r = (states.index(k) for k in ("beta", "p", "r"))
    e0, d0 = states.index("eta1"), states.index("eta1_dot")
    n_x = len(states)
    forcing = np.zeros((n, n_x))
    forcing[:, i_r] = lift / v * terms.force_r
    forcing[:, i_b] = q * (terms.force_beta + terms.force_beta_s @ eta_s)
    roll = np.zeros(n_x)
    roll[i_r] = q / v * (terms.roll_r_s @ eta_s)
    roll[i_b] = q * (terms.roll_beta_s @ eta_s)
    side = np.zeros(n_x)
    side[e0:e0 + n] = lift * terms.side_eta + q * terms.side_dihedral_eta
    side[d0:d0 + n] = q / v * terms.side_dihedral_etadot
    elastic_roll = roll.copy()  # all the elastic rolling moment: ΔL and the roll row
    elastic_roll[e0:e0 + n] += q * strips.roll_eta
    elastic_roll[d0:d0 + n] += q / v * strips.roll_etadot
    yaw = -terms.induced_per_lift * lift / q * elastic_roll
    yaw[d0:d0 + n] += lift / v * terms.yaw_etadot
    yaw[i_p] += q / v * (terms.yaw_p_s @ eta_s)
    return {"forcing": forcing, "roll": roll, "side": side, "yaw": yaw}


def lateral_elastic_with_yaw_sideslip(ss: StateSpace, strips: AntisymmetricStrips,
                                      terms: YawSideslipTerms, trim: LateralTrim,
                                      static_eta_s=None) -> StateSpace:
    """The coupled lateral model ``ss`` with the rows of :func:`yaw_sideslip_rows`: the
    forcing in the η̈ rows (÷ m_i), the rolling and yawing moments in ṗ, ṙ through J⁻¹ (as
    ΔL is), the side force in β̇ (÷ m V) and in n_y (÷ m g). The β terms act on the air's
    sideslip β − v_g/V (the nonlinear step reads JSBSim's, wind included): their v_g column
    is their β column over −V, as the rigid model's."""
    if ss.model != "coupled-lateral":
        raise ValueError(f"the yaw rate's and sideslip's terms go into the coupled lateral "
                         f"model, not {ss.model!r}")
    rows = yaw_sideslip_rows(ss, strips, terms, trim, static_eta_s)
    n, v, mass = strips.n_modes, float(trim.speed_m_s), float(trim.mass_kg)
    d0 = ss.states.index("eta1_dot")
    extra = np.zeros_like(np.asarray(ss.a, dtype=float))
    extra[d0:d0 + n] = rows["forcing"] / strips.mass_kg_m2[:, None]
    j_inv = np.linalg.inv(inertia_matrix(trim))  # (ṗ, ṙ) per unit (L, N)
    extra[1:3] = np.outer(j_inv[:, 0], rows["roll"]) + np.outer(j_inv[:, 1], rows["yaw"])
    extra[ss.states.index("beta")] = rows["side"] / (mass * v)
    i_b, i_vg = ss.states.index("beta"), ss.inputs.index("v_g")
    b = np.asarray(ss.b, dtype=float).copy()
    b[:, i_vg] += -extra[:, i_b] / v
    c = np.asarray(ss.c, dtype=float).copy()
    c[ss.outputs.index("n_y")] += rows["side"] / (mass * STANDARD_GRAVITY_M_S2)
    notes = {**ss.notes, "yaw_sideslip": (
        "yaw rate's and sideslip's forcing of the modes, their rolling moment on the "
        "symmetric deflection, the modes' side force and yawing moment, linearised about "
        "the trim (aeroelasticity/antisymmetric_strips.py)")}
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=np.asarray(ss.a) + extra,
                      b=b, c=c, d=ss.d, states=ss.states, state_units=ss.state_units,
                      inputs=ss.inputs, input_units=ss.input_units, outputs=ss.outputs,
                      output_units=ss.output_units, notes=notes)
def _slope_at(stations_m: np.ndarray, bending_m: np.ndarray, y_m: np.ndarray) -> np.ndarray:
    """dφ/dy [m/m per unit η] of the bending ``bending_m`` (n, k) given at ``stations_m``,
    at ``y_m`` (second-order differences on the modes' own stations, then linear)."""
    slope = np.gradient(np.asarray(bending_m, dtype=float), np.asarray(stations_m, dtype=float),
                        axis=1)
    return np.array([np.interp(y_m, stations_m, s) for s in slope])


def dihedral_rad(planform, y_m: np.ndarray) -> np.ndarray:
    """The planform's geometric dihedral Γ(y) [rad, tip up positive] at the starboard
    stations ``y_m``: the slope of its leading edge's height (zero for a flat wing)."""
    y = np.asarray(y_m, dtype=float)
    if not getattr(planform, "has_dihedral", False):
        return np.zeros_like(y)
    grid = np.linspace(0.0, float(planform.semispan_m), 4001)
    return np.arctan(np.interp(y, grid, np.gradient(planform.height_at(grid), grid)))


@dataclass(frozen=True, eq=False)
class YawSideslipTerms:
    """The yaw rate's, the sideslip's and the side force's terms of the full-span step, per
    unit flow (the physics: :mod:`bioflex_jsb.simulation.full_span`, "Yaw rate, sideslip,
    side force and yawing moment"). ``n_a`` antisymmetric, ``n_s`` symmetric modes; L_w the
    wing's lift [N] (n_z W), Q [Pa], V [m/s], r, p [rad/s], β [rad]; η_s the symmetric
    modes' total deflection [rad] (the trim's static one plus the run's Δη_s).

    Generalised forces on the antisymmetric modes [N·m]: ``force_r`` (n_a) per unit L_w r/V,
    ``force_beta`` (n_a) per unit Q β, ``force_beta_s`` (n_a, n_s) per unit Q β η_s.
    Rolling moment, right wing down [N·m]: ``roll_r_s`` (n_s) per unit (Q r/V) η_s,
    ``roll_beta_s`` (n_s) per unit Q β η_s. Side force along body +y [N]: ``side_eta``
    (n_a) per unit L_w η_a, ``side_dihedral_eta`` per unit Q η_a, ``side_dihedral_etadot``
    per unit (Q/V) η̇_a. Yawing moment about body +z, nose right [N·m]: ``yaw_etadot``
    (n_a) per unit (L_w/V) η̇_a, ``yaw_p_s`` (n_s) per unit (Q p/V) η_s, and
    −``induced_per_lift`` L_w/Q times the elastic rolling moment [1/m²: 1/(π b²)]."""

    force_r: np.ndarray
    force_beta: np.ndarray
    force_beta_s: np.ndarray
    roll_r_s: np.ndarray
    roll_beta_s: np.ndarray
    side_eta: np.ndarray
    side_dihedral_eta: np.ndarray
    side_dihedral_etadot: np.ndarray
    yaw_etadot: np.ndarray
    yaw_p_s: np.ndarray
    induced_per_lift: float

    def forcing(self, q_pa: float, v_m_s: float, wing_lift_n: float, r_rad_s: float,
                beta_rad: float, eta_s) -> np.ndarray:
        """The generalised force on the antisymmetric modes [N·m] (n_a)."""
        return (wing_lift_n * r_rad_s / v_m_s * self.force_r
                + q_pa * beta_rad * (self.force_beta + self.force_beta_s @ eta_s))

    def roll_n_m(self, q_pa: float, v_m_s: float, r_rad_s: float, beta_rad: float,
                 eta_s) -> float:
        """The rolling moment of the yaw rate and the sideslip on the symmetric deflection
        [N·m, right wing down]."""
        return float(q_pa * r_rad_s / v_m_s * (self.roll_r_s @ eta_s)
                     + q_pa * beta_rad * (self.roll_beta_s @ eta_s))

    def side_n(self, q_pa: float, v_m_s: float, wing_lift_n: float, eta_a, eta_a_dot
               ) -> float:
        """The side force of the antisymmetric deformation [N, body +y, to starboard]."""
        return float(wing_lift_n * (self.side_eta @ eta_a)
                     + q_pa * (self.side_dihedral_eta @ eta_a)
                     + q_pa / v_m_s * (self.side_dihedral_etadot @ eta_a_dot))

    def yaw_n_m(self, q_pa: float, v_m_s: float, wing_lift_n: float, p_rad_s: float,
                eta_a_dot, eta_s, roll_n_m: float) -> float:
        """The yawing moment of the deformation [N·m, body +z, nose right]; ``roll_n_m`` the
        elastic rolling moment of the same step (its lift's induced drag)."""
        return float(wing_lift_n / v_m_s * (self.yaw_etadot @ eta_a_dot)
                     + q_pa * p_rad_s / v_m_s * (self.yaw_p_s @ eta_s)
                     - self.induced_per_lift * wing_lift_n / q_pa * roll_n_m)


def yaw_sideslip_terms(wing: AntisymmetricWing, symmetric, n_symmetric: int, planform,
                       span_m: float) -> YawSideslipTerms:
    """:class:`YawSideslipTerms` of ``wing``'s strips and antisymmetric modes with the
    first ``n_symmetric`` modes of ``symmetric`` (the half wing's ModalData, the same sign
    conventions: bending down, twist leading edge up), the planform's dihedral and the
    wing's span ``span_m`` [m]."""
    y, w = wing.stations_m, wing.weights_m
    clac_w = wing.cl_alpha_c_m * w  # a c w: a strip's lift per Pa per rad [m²]
    share = clac_w / (2.0 * clac_w.sum())  # a strip's part of the wing's lift [-]
    work = wing.e_m * wing.theta - wing.phi  # (n_a, K) upward AC displacement per unit η
    ns = int(n_symmetric)
    st = symmetric.stations_m
    theta_s = np.array([np.interp(y, st, t) for t in symmetric.twist_rad[:ns]])
    slope_s = _slope_at(st, symmetric.bending_m[:ns], y)  # (n_s, K) down per outboard
    slope_a = _slope_at(wing.modes.stations_m, wing.modes.bending_m, y)
    gamma = dihedral_rad(planform, y)
    terms = YawSideslipTerms(
        force_r=-2.0 * work @ (y * share),
        force_beta=work @ (clac_w * gamma),
        force_beta_s=-np.einsum("ik,jk,k->ij", work, slope_s, clac_w),
        roll_r_s=4.0 * theta_s @ (clac_w * y * y),
        roll_beta_s=2.0 * slope_s @ (clac_w * y),
        side_eta=2.0 * slope_a @ share,
        side_dihedral_eta=-2.0 * wing.theta @ (clac_w * gamma),
        side_dihedral_etadot=-2.0 * wing.phi @ (clac_w * gamma),
        yaw_etadot=-2.0 * wing.phi @ (share * y),
        yaw_p_s=-2.0 * theta_s @ (clac_w * y * y),
        induced_per_lift=1.0 / (np.pi * float(span_m) ** 2))
    if wing.lift_matrix_m is None:
        return terms
    # the lattice: the sideslip's antisymmetric angles ±β Γ, ∓β dφ_s/dy η_s and the
    # antisymmetric deformation's θ_a, φ_a load the strips through its matrix. The yaw rate:
    # a strip's onset flow V − r y changes its normal wash (α (1 − r y/V), whose
    # antisymmetric part −α r y/V the matrix loads) and its Kutta–Joukowski speed (the
    # symmetric load l times −r y/V): Δl = −(r/V) (y l + Q A (α y)), the strips' −2 (r y/V) l
    # when A is their diagonal; α the trim's uniform α_w (l_r = Q C_lα c α_w, so Q α_w =
    # L_w / (2 Σ C_lα c w)) and the symmetric twist θ_s η_s (l_e). The lift's lean stays the
    # strips' (it tilts l, it adds none)
    l_gamma, l_slope = w * wing.lift_m(gamma), w * wing.lift_m(slope_s)
    l_y = w * wing.lift_m(y) / (2.0 * clac_w.sum())  # per unit L_w of α_w y [-]
    l_theta_s_y = w * wing.lift_m(theta_s * y)  # (n_s, K) per unit Q η_s of θ_s y [m²]
    return replace(terms, force_beta=work @ l_gamma, force_beta_s=-work @ l_slope.T,
                   force_r=-work @ (y * share) - work @ l_y,
                   roll_r_s=2.0 * theta_s @ (clac_w * y * y) + 2.0 * l_theta_s_y @ y,
                   roll_beta_s=2.0 * l_slope @ y,
                   side_dihedral_eta=-2.0 * (w * wing.lift_m(wing.theta)) @ gamma,
                   side_dihedral_etadot=-2.0 * (w * wing.lift_m(wing.phi)) @ gamma)
