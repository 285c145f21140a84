"""The coupled LTI model of Eq. (4), its rigid part and the QSD reduction of Eq. (9)–(10).

Every model here is the package's one :class:`~bioflex_jsb.state_space.StateSpace`
(continuous; ``.to_control()`` gives python-control's). State order (named in every one):
    x = [u, α, q, θ, η_1 … η_n, η̇_1 … η̇_n]
    u [m/s], α [rad], q [rad/s], θ [rad], η_i [rad] (modes normalised on twist), η̇_i [rad/s].
Input: w_g [m/s], vertical gust velocity, positive **upward** (raises α by w_g/u_0).
With ``controls=True`` (:func:`build_state_space`, what ``bioflex-jsb export`` writes) also
the elevator δe [rad] (JSBSim's sign: + trailing edge down, nose down) and the throttle δt
[-] (fraction of the motor's maximum shaft power), and the outputs n_z [-] (load-factor
perturbation, positive up; n_z = 1 + this) and tip_twist [rad] (the wing's tip section
twist, positive leading edge up, Σ θ_i(tip) η_i) beside the states (q is the pitch rate
[rad/s]).

Equations used, with the corrections listed in docs/decisions.md ("Paper typos"):

* structural damping 2 ζ_i ω_i (Eq. 2 and A_EĖ print ζ_i ω_i);
* H_iu = (C_u^Qi + 2 C_0^Qi) Q S c̄ / (m_i u_0) (Table B2 prints m for m_i), C_u^Q = 0;
* G_R uses M_ẇ (Appendix B prints M_iω).

Derivatives that the paper uses but does not define: C_Dη_i = 2 k C_L0 C_Lη_i and
C_Dη̇_i = 2 k C_L0 C_Lη̇_i (induced drag of the extra lift, parabolic polar).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.modal_coefficients import ModalCoefficients
from bioflex_jsb.flight_dynamics.rigid import (
    RIGID_STATE_UNITS,
    RIGID_STATES,
    FlightCondition,
    RigidDerivatives,
    alpha_rate_scale,
    rigid_derivatives,
    rigid_matrices,
)
from bioflex_jsb.parameters.airframe import AirframeData, RigidAerodynamics
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.state_space import StateSpace  # the one state-space type (re-exported)

MODELS = ("rigid", "coupled", "qsd")


@dataclass(frozen=True)
class ElasticWingModel:
    """What the LTI builder needs to know about an elastic wing (speed independent).

    frequencies_rad_s, damping_ratios, generalised_masses_kg_m2: the m_i of Table B2 as used
    in H_i (see :mod:`bioflex_jsb.flight_dynamics.wing_model` for the convention);
    coefficients: Table B1; wing_lift_slope_per_rad: C_Lα of the wing alone (lifting line) on
    the airframe's reference area S [1/rad], used for the trim lift distribution in C_0^Q;
    cm_ac: section moment coefficient about the aerodynamic centre [-]; airframe: the
    aircraft the wing was built for (its S and c̄ non-dimensionalise ``coefficients``; the
    flight condition must carry the same).
    """

    name: str
    frequencies_rad_s: np.ndarray
    damping_ratios: np.ndarray
    generalised_masses_kg_m2: np.ndarray
    coefficients: ModalCoefficients
    wing_lift_slope_per_rad: float
    cm_ac: float
    tip_twist_per_eta: np.ndarray | None = None  # θ_i at the tip per unit η_i [rad/rad]
    airframe: AirframeData = field(kw_only=True)  # the aircraft the wing was built for

    @property
    def n_modes(self) -> int:
        return int(len(self.frequencies_rad_s))


def check_same_reference(wing: ElasticWingModel, condition: FlightCondition) -> None:
    """The wing's coefficients and the condition's derivatives share S and c̄ (a wing built
    for one aircraft at another's flight condition is a caller's bug: ValueError)."""
    mine, theirs = wing.airframe.reference, condition.airframe.reference
    if mine != theirs:
        raise ValueError(f"wing {wing.name!r} was built for airframe {wing.airframe.name!r} "
                         f"({mine}) but the flight condition is {condition.airframe.name!r}'s "
                         f"({theirs}): build the condition with airframe=wing.airframe")


@dataclass(frozen=True)
class ElasticDerivatives:
    """Dimensional elastic derivatives at one flight condition (Table B2).

    x_eta, z_eta [m/s² per rad]; x_etadot, z_etadot [m/s² per rad/s]; m_eta [1/s²];
    m_etadot [1/s]; h_u [1/(s·m)]·…: H-terms are generalised accelerations [rad/s² per unit
    of the state they multiply]. h_eta and h_etadot are (n, n), rows = mode acted on.
    """

    x_eta: np.ndarray
    x_etadot: np.ndarray
    z_eta: np.ndarray
    z_etadot: np.ndarray
    m_eta: np.ndarray
    m_etadot: np.ndarray
    h_u: np.ndarray
    h_alpha: np.ndarray
    h_q: np.ndarray
    h_eta: np.ndarray
    h_etadot: np.ndarray


def elastic_derivatives(
    wing: ElasticWingModel,
    condition: FlightCondition,
    aero: RigidAerodynamics | None = None,
    mass_kg: float | None = None,
    iyy_kg_m2: float | None = None,
) -> ElasticDerivatives:
    """Table B2 derivatives of the structural modes at ``condition`` (S, c̄, mass, I_yy and
    k of the condition's airframe unless given)."""
    check_same_reference(wing, condition)
    af = condition.airframe
    aero = af.aero if aero is None else aero
    mass_kg = af.mass.mass_kg if mass_kg is None else mass_kg
    iyy_kg_m2 = af.mass.iyy_kg_m2 if iyy_kg_m2 is None else iyy_kg_m2
    c = wing.coefficients
    u0 = condition.speed_m_s
    qs = condition.dynamic_pressure_pa * af.reference.area_m2
    cb = af.reference.mean_chord_m
    mi = np.asarray(wing.generalised_masses_kg_m2, dtype=float)
    c_d_eta = 2.0 * aero.k_induced * condition.cl_trim * c.c_l_eta
    c_d_etadot = 2.0 * aero.k_induced * condition.cl_trim * c.c_l_etadot
    alpha_wing = condition.cl_trim / wing.wing_lift_slope_per_rad
    c_0_q = alpha_wing * c.c_alpha_q + wing.cm_ac * c.c_mac_q
    return ElasticDerivatives(
        x_eta=-c_d_eta * qs / mass_kg,
        x_etadot=-c_d_etadot * qs * cb / (2.0 * mass_kg * u0),
        z_eta=-c.c_l_eta * qs / mass_kg,
        z_etadot=-c.c_l_etadot * qs * cb / (2.0 * mass_kg * u0),
        m_eta=c.c_m_eta * qs * cb / iyy_kg_m2,
        m_etadot=c.c_m_etadot * qs * cb**2 / (2.0 * iyy_kg_m2 * u0),
        h_u=2.0 * c_0_q * qs * cb / (mi * u0),
        h_alpha=c.c_alpha_q * qs * cb / mi,
        h_q=c.c_q_q * qs * cb**2 / (2.0 * mi * u0),
        h_eta=c.c_eta_q * qs * cb / mi[:, None],
        h_etadot=c.c_etadot_q * qs * cb**2 / (2.0 * mi[:, None] * u0),
    )


@dataclass(frozen=True)
class CoupledBlocks:
    """The sub-matrices of Eq. (4) at one flight condition (Appendix B)."""

    a_rr: np.ndarray
    a_re: np.ndarray
    a_redot: np.ndarray
    a_er: np.ndarray
    a_ee: np.ndarray
    a_eedot: np.ndarray
    g_r: np.ndarray
    g_e: np.ndarray
    rigid: RigidDerivatives
    elastic: ElasticDerivatives


def coupled_blocks(
    wing: ElasticWingModel,
    condition: FlightCondition,
    aero: RigidAerodynamics | None = None,
    a_rr: np.ndarray | None = None,
    elastic: ElasticDerivatives | None = None,
) -> CoupledBlocks:
    """Assemble the blocks of Eq. (4).

    ``a_rr`` replaces the analytic A_RR (e.g. by JSBSim's linearization of the airframe at
    the same trim); G_R is then its α column over u_0, which is what Appendix B's G_R is.
    ``elastic`` replaces the Table B2 derivatives of the modes (:func:`elastic_derivatives`
    at ``condition``), e.g. one of them changed for a sensitivity study.
    """
    rd = rigid_derivatives(condition, aero)
    ed = elastic if elastic is not None else elastic_derivatives(wing, condition, aero)
    a_rr_analytic, g_r = rigid_matrices(rd)
    if a_rr is None:
        a_rr = a_rr_analytic
    else:
        a_rr = np.asarray(a_rr, dtype=float)
        if a_rr.shape != (4, 4):
            raise ValueError(f"a_rr must be 4x4, got {a_rr.shape}")
        g_r = (a_rr[:, 1] / condition.speed_m_s).reshape(4, 1)
    u0 = condition.speed_m_s
    n = wing.n_modes
    div, f = alpha_rate_scale(rd)

    def rigid_rows(x, z, m):
        return np.vstack([x, z / div, m + rd.m_wdot * z * f, np.zeros(n)])

    omega = np.asarray(wing.frequencies_rad_s, dtype=float)
    zeta = np.asarray(wing.damping_ratios, dtype=float)
    a_er = np.column_stack([ed.h_u, ed.h_alpha, ed.h_q, np.zeros(n)])
    return CoupledBlocks(
        a_rr=a_rr,
        a_re=rigid_rows(ed.x_eta, ed.z_eta, ed.m_eta),
        a_redot=rigid_rows(ed.x_etadot, ed.z_etadot, ed.m_etadot),
        a_er=a_er,
        a_ee=-np.diag(omega**2) + ed.h_eta,
        a_eedot=-np.diag(2.0 * zeta * omega) + ed.h_etadot,
        g_r=g_r,
        g_e=(ed.h_alpha / u0).reshape(n, 1),
        rigid=rd,
        elastic=ed,
    )


def elastic_state_names(n: int) -> tuple[tuple[str, ...], tuple[str, ...]]:
    names = tuple(f"eta{i + 1}" for i in range(n)) + tuple(f"eta{i + 1}_dot" for i in range(n))
    units = ("rad",) * n + ("rad/s",) * n
    return names, units


CONTROL_INPUTS = ("elevator", "throttle")
CONTROL_INPUT_UNITS = ("rad", "-")
AERODYNAMIC_MODEL = ("quasi-steady: Table B1/B2 derivatives (strip/vortex-lattice spanwise "
                     "loading), the paper's Eq. (4); analytic rigid block "
                     "(flight_dynamics/rigid.py)")


def control_columns(condition: FlightCondition, aero: RigidAerodynamics | None = None,
                    mass_kg: float | None = None,
                    iyy_kg_m2: float | None = None) -> np.ndarray:
    """B columns of the rigid states [u, α, q, θ] for the elevator [rad] and the throttle [-].

    Elevator: the tail's lift C_Lδe and moment C_mδe (the pitch row also through M_ẇ Z_δe)
    and the induced drag of that lift, 2 k C_L0 C_Lδe; the tail does not load the wing's
    modes. Throttle: X_δt = ∂T/∂δt / m at the trim airspeed with the propeller RPM
    quasi-static (:func:`thrust_per_throttle_n`); the thrust line passes through the centre
    of gravity (no moment); an airframe without the prototype's propulsion model takes the
    derivatives' C_Tδt and C_mδt (a JSBSim aircraft's, identified; zero for a glider).
    Units: per rad of elevator, per unit throttle. S, c̄, mass, I_yy and the derivatives
    are the condition's airframe's unless given.
    """
    af = condition.airframe
    aero = af.aero if aero is None else aero
    mass_kg = af.mass.mass_kg if mass_kg is None else mass_kg
    iyy_kg_m2 = af.mass.iyy_kg_m2 if iyy_kg_m2 is None else iyy_kg_m2
    u0 = condition.speed_m_s
    qs = condition.dynamic_pressure_pa * af.reference.area_m2
    cb = af.reference.mean_chord_m
    z_de = -aero.cl_delta_e_per_rad * qs / mass_kg
    x_de = -2.0 * aero.k_induced * condition.cl_trim * aero.cl_delta_e_per_rad * qs / mass_kg
    m_de = aero.cm_delta_e_per_rad * qs * cb / iyy_kg_m2
    div, f = alpha_rate_scale(rigid_derivatives(condition, aero, mass_kg, iyy_kg_m2))
    m_wdot = aero.cm_alphadot_per_rad * qs * cb**2 / (2.0 * iyy_kg_m2 * u0**2)
    if af.propulsion is None:
        x_dt = aero.ct_delta_t * qs / mass_kg
        m_dt = aero.cm_delta_t * qs * cb / iyy_kg_m2
    else:
        x_dt, m_dt = thrust_per_throttle_n(condition) / mass_kg, 0.0
    return np.array([[x_de, x_dt], [z_de / div, 0.0], [m_de + m_wdot * z_de * f, m_dt],
                     [0.0, 0.0]])


def _drive(condition: FlightCondition):
    """(thrust(J, V) [N], power(J, V) [W], trim J [-]) of the drive at ``condition``: the
    propeller's C_T(J), C_P(J) tables (linear interpolation, as JSBSim's) with n = V/(J D),
    trimmed where the thrust equals the drag C_D Q S; trim J None if the tables cannot."""
    from scipy.optimize import brentq

    prop = condition.airframe.propulsion
    if prop is None:
        raise ValueError(f"airframe {condition.airframe.name!r} has no propulsion model (its "
                         "throttle column is zero)")
    j_tab, ct_tab, cp_tab = _propeller_tables_cached(prop)
    rho, d = condition.density_kg_m3, prop.prop_diameter_m
    drag = condition.cd_trim * condition.dynamic_pressure_pa * condition.airframe.reference.area_m2

    def thrust(j: float, v: float) -> float:
        return float(np.interp(j, j_tab, ct_tab)) * rho * (v / (j * d)) ** 2 * d**4

    def power(j: float, v: float) -> float:
        return float(np.interp(j, j_tab, cp_tab)) * rho * (v / (j * d)) ** 3 * d**5

    j_lo = float(j_tab[1])
    j_hi = float(j_tab[np.nonzero(ct_tab <= 0.0)[0][0]]) if np.any(ct_tab <= 0.0) \
        else float(j_tab[-1])
    v0 = condition.speed_m_s
    try:
        j_trim = brentq(lambda j: thrust(j, v0) - drag, j_lo, j_hi)
    except ValueError:
        j_trim = None
    return thrust, power, j_trim, (j_lo, j_hi)


def thrust_per_throttle_n(condition: FlightCondition) -> float:
    """∂T/∂δt [N per unit throttle] at the level-flight trim ``condition``, airspeed held,
    RPM in equilibrium (shaft power = δt × PROPULSION.motor_max_shaft_power_w):
    P_max (∂T/∂J)/(∂P/∂J) (:func:`_drive`); NaN if the propeller cannot trim there."""
    thrust, power, j, _ = _drive(condition)
    if j is None:
        return float("nan")
    v, h = condition.speed_m_s, 1e-4
    dt_dj = (thrust(j + h, v) - thrust(j - h, v)) / (2 * h)
    dp_dj = (power(j + h, v) - power(j - h, v)) / (2 * h)
    return float(condition.airframe.propulsion.motor_max_shaft_power_w * dt_dj / dp_dj)


def thrust_speed_derivative_n_s_m(condition: FlightCondition) -> float:
    """∂T/∂V [N per m/s] at constant throttle (shaft power) and equilibrium RPM at the trim
    ``condition``: the fixed-pitch propeller's thrust falls as the airspeed rises. Table B2,
    and so the analytic A_RR, leave it out (thrust speed-independent); JSBSim's
    linearization has it (``bioflex-jsb linearize``). NaN if the propeller cannot trim."""
    from scipy.optimize import brentq

    thrust, power, j0, (j_lo, j_hi) = _drive(condition)
    if j0 is None:
        return float("nan")
    v0 = condition.speed_m_s
    p0 = power(j0, v0)
    out = []
    for v in (v0 * (1 + 1e-4), v0 * (1 - 1e-4)):
        j = brentq(lambda jj, v=v: power(jj, v) - p0, j_lo, j_hi)
        out.append(thrust(j, v))
    return float((out[0] - out[1]) / (2e-4 * v0))


_TABLES: dict = {}


def _propeller_tables_cached(prop):
    """The drive ``prop``'s propeller tables (aerodynamics/propeller.py), computed once per
    drive (a blade-element calculation of 27 advance ratios)."""
    if prop not in _TABLES:
        from bioflex_jsb.aerodynamics.propeller import propeller_tables

        _TABLES[prop] = propeller_tables(prop)
    return _TABLES[prop]


def _with_outputs(ss: StateSpace, a_alpha_row: np.ndarray, b_alpha_row: np.ndarray,
                  tip_rows: tuple[np.ndarray, np.ndarray] | None) -> StateSpace:
    """``ss`` with the outputs n_z [-] and tip_twist [rad] appended (see the module
    docstring): Δn_z = u_0 (q − α̇)/g from the inertial α̇ of the α row (in level flight the
    α row has no gravity term)."""
    g = STANDARD_GRAVITY_M_S2
    u0 = ss.speed_m_s
    iq = ss.states.index("q")
    e_q = np.zeros(ss.n_states)
    e_q[iq] = 1.0
    c_rows = [u0 / g * (e_q - a_alpha_row)]
    d_rows = [-u0 / g * b_alpha_row]
    names, units = ["n_z"], ["-"]
    if tip_rows is not None:
        c_rows.append(tip_rows[0])
        d_rows.append(tip_rows[1])
        names.append("tip_twist")
        units.append("rad")
    return StateSpace(
        model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a, b=ss.b,
        c=np.vstack([ss.c, *c_rows]), d=np.vstack([ss.d, *d_rows]),
        states=ss.states, state_units=ss.state_units, inputs=ss.inputs,
        input_units=ss.input_units, outputs=ss.outputs + tuple(names),
        output_units=ss.output_units + tuple(units), notes=ss.notes,
    )


def build_state_space(
    model: str,
    condition: FlightCondition,
    wing: ElasticWingModel | None = None,
    aero: RigidAerodynamics | None = None,
    a_rr: np.ndarray | None = None,
    controls: bool = False,
    elastic: ElasticDerivatives | None = None,
) -> StateSpace:
    """The ``rigid`` (A_RR), ``coupled`` (Eq. 4) or ``qsd`` (Eq. 9–10) model at ``condition``.

    The QSD model also outputs the quasi-static modal deflections
    η = −A_EE⁻¹ (A_ER x_R + G_E w_g). ``a_rr`` replaces the analytic rigid block and
    ``elastic`` the Table B2 derivatives of the modes (see :func:`coupled_blocks`).
    ``controls``: inputs (w_g, elevator, throttle) instead of w_g alone, and the outputs n_z
    and tip_twist after the states (module docstring).
    """
    if model not in MODELS:
        raise InputError(f"unknown model {model!r}; accepted: {', '.join(MODELS)}")
    if controls:
        if elastic is not None:
            raise ValueError("elastic= is for the sensitivity models, without controls")
        return _with_controls(model, condition, wing, aero, a_rr)
    common = dict(inputs=("w_g",), input_units=("m/s",), speed_m_s=condition.speed_m_s)
    block = {"rigid_block": rigid_block_note(a_rr, condition.airframe)}
    if model == "rigid":
        a, g = rigid_matrices(rigid_derivatives(condition, aero))
        if a_rr is not None:
            a = np.asarray(a_rr, dtype=float)
            g = (a[:, 1] / condition.speed_m_s).reshape(4, 1)
        return StateSpace(
            model=model, a=a, b=g, c=np.eye(4), d=np.zeros((4, 1)),
            states=RIGID_STATES, state_units=RIGID_STATE_UNITS,
            outputs=RIGID_STATES, output_units=RIGID_STATE_UNITS, notes=block, **common,
        )
    if wing is None:
        raise InputError(f"the {model} model needs an elastic wing")
    blk = coupled_blocks(wing, condition, aero, a_rr, elastic)
    n = wing.n_modes
    e_names, e_units = elastic_state_names(n)
    notes = {"wing": wing.name, "overrides": dict(wing.coefficients.overrides), **block}
    if model == "coupled":
        a = np.block(
            [
                [blk.a_rr, blk.a_re, blk.a_redot],
                [np.zeros((n, 4)), np.zeros((n, n)), np.eye(n)],
                [blk.a_er, blk.a_ee, blk.a_eedot],
            ]
        )
        b = np.vstack([blk.g_r, np.zeros((n, 1)), blk.g_e])
        states = RIGID_STATES + e_names
        units = RIGID_STATE_UNITS + e_units
        return StateSpace(
            model=model, a=a, b=b, c=np.eye(4 + 2 * n), d=np.zeros((4 + 2 * n, 1)),
            states=states, state_units=units, outputs=states, output_units=units,
            notes=notes, **common,
        )
    # QSD, Eq. (10)
    a_ee_inv_a_er = np.linalg.solve(blk.a_ee, blk.a_er)
    a_ee_inv_g_e = np.linalg.solve(blk.a_ee, blk.g_e)
    a = blk.a_rr - blk.a_re @ a_ee_inv_a_er
    b = blk.g_r - blk.a_re @ a_ee_inv_g_e
    c = np.vstack([np.eye(4), -a_ee_inv_a_er])
    d = np.vstack([np.zeros((4, 1)), -a_ee_inv_g_e])
    return StateSpace(
        model=model, a=a, b=b, c=c, d=d,
        states=RIGID_STATES, state_units=RIGID_STATE_UNITS,
        outputs=RIGID_STATES + e_names[:n], output_units=RIGID_STATE_UNITS + e_units[:n],
        notes=notes, **common,
    )


# Which rigid block a model carries (its notes["rigid_block"]): the analytic A_RR of the
# Table B2 derivatives, with the thrust independent of airspeed (the propeller's dT/dV
# missing from X_u: the coupled phugoid is near neutral, docs/aeroelasticity.md "Two coupled
# LTI models"), or JSBSim's linearization of the airframe at the trim (``a_rr``), which has it.
# A JSBSim aircraft's derivatives identified from its own model carry the thrust's speed
# derivative (C_Tu, runtime/identification.py): its analytic block has it.
RIGID_BLOCK_ANALYTIC = "analytic (Table B2; thrust independent of airspeed)"
RIGID_BLOCK_IDENTIFIED = ("analytic, derivatives identified from the JSBSim aircraft (with "
                          "the thrust's change with airspeed)")
RIGID_BLOCK_JSBSIM = "JSBSim linearization (with the propeller's thrust change)"


def rigid_block_note(a_rr: np.ndarray | None, airframe: AirframeData | None = None) -> str:
    """The ``rigid_block`` note of a model built with ``a_rr`` (None: the analytic one) for
    ``airframe`` (an identified schedule's block says so)."""
    if a_rr is not None:
        return RIGID_BLOCK_JSBSIM
    identified = airframe is not None and airframe.schedule is not None
    return RIGID_BLOCK_IDENTIFIED if identified else RIGID_BLOCK_ANALYTIC


def _with_controls(model, condition, wing, aero, a_rr) -> StateSpace:
    """:func:`build_state_space` with the elevator and throttle inputs and the n_z and
    tip-twist outputs."""
    base = build_state_space(model, condition, wing, aero, a_rr)
    b_rigid = control_columns(condition, aero)
    n = base.n_states
    if model == "qsd" or model == "rigid":
        b_ctrl = b_rigid  # the controls do not load the wing: the QSD reduction keeps them
    else:
        b_ctrl = np.vstack([b_rigid, np.zeros((n - 4, 2))])
    d_ctrl = np.zeros((base.d.shape[0], 2))
    notes = dict(base.notes, aerodynamics=AERODYNAMIC_MODEL,
                 density_kg_m3=condition.density_kg_m3, trim_cl=condition.cl_trim,
                 rigid_block=rigid_block_note(a_rr, condition.airframe))
    ss = StateSpace(
        model=base.model, speed_m_s=base.speed_m_s, a=base.a,
        b=np.hstack([base.b, b_ctrl]), c=base.c, d=np.hstack([base.d, d_ctrl]),
        states=base.states, state_units=base.state_units,
        inputs=base.inputs + CONTROL_INPUTS, input_units=base.input_units + CONTROL_INPUT_UNITS,
        outputs=base.outputs, output_units=base.output_units, notes=notes,
    )
    ia = ss.states.index("alpha")
    tip = None
    if model != "rigid" and wing is not None and wing.tip_twist_per_eta is not None:
        theta_tip = np.asarray(wing.tip_twist_per_eta, dtype=float)
        eta_rows = [ss.outputs.index(f"eta{i + 1}") for i in range(wing.n_modes)]
        tip = (theta_tip @ ss.c[eta_rows], theta_tip @ ss.d[eta_rows])
    return _with_outputs(ss, ss.a[ia], ss.b[ia], tip)
