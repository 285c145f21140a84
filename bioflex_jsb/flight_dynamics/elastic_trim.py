"""Elastic trim: the static aeroelastic equilibrium of the wing at a level-flight trim.

Reading of the airframe (docs/decisions.md, "Elastic trim"): the rigid aerodynamics are
those of the aircraft with its wing in the **undeformed** (jig) shape. At a trim the wing
then deflects under its own trim loads, its static deflection η₀ adds lift, drag and
pitching moment, and the rigid trim (α, elevator) must carry them. The fixed point is:

* wing (modal statics, Eq. 2 with η̈ = η̇ = 0, mass-normalised, per mode i; the aerodynamic
  stiffness at the trim's dynamic pressure Q):

      (Ω² − Q K_a) η₀ = Q [b_0 + b_α (α − α_r)]

  with K_a, b_α, b_0 of :mod:`bioflex_jsb.flight_dynamics.modal_matrices`
  (b_0 = S c̄ C_0^Qi / m_i: the wing's trim generalised force of Table B1 at the rigid trim
  α_r, lift on the wing like C_lα c(y) at α_w = C_L0/C_Lα,w, plus the C_mac term) and
  α − α_r the change of the body's angle of attack from the rigid trim;
* the wing's static loads (Table B1/B2, as the co-simulation applies them):
  L = Q S C_Lη·η₀ (up), D = Q S 2 k C_L0 C_Lη·η₀ (aft), M = Q S c̄ C_mη·η₀ (nose up, CG);
* the rigid trim with those loads applied: a callable ``rigid_trim(loads) -> (α, δe)``:
  JSBSim's trim with the loads in the airframe's external reactions (the runtime's), or
  :func:`linear_rigid_trim`, the linear airframe model of
  :class:`~bioflex_jsb.parameters.airframe.RigidAerodynamics` (the default).

Only α reaches the wing (the elevator is on the tail and Q is fixed by the speed), so the
fixed point is one scalar equation α = T(α), T the rigid trim of the loads of η₀(α). It is
solved by a plain fixed-point step followed by secant steps (exact after two for a linear
rigid trim, whatever the loop gain; a plain iteration can diverge near the divergence speed
where η₀ is large).

Beyond the wing's static divergence speed (Ω² − Q K_a singular: the A_EE of Eq. (4), the
wing with the body held) there is no stable static equilibrium: :func:`elastic_trim` raises
:class:`~bioflex_jsb.errors.InputError` naming that speed.

Linearising about the elastic trim (:func:`linearise_about_elastic_trim`): the aerodynamics
are linear and the trim lift is W/(Q S) whatever the wing's share, so A_RR, A_RE, A_RĖ, A_EE,
A_EĖ and G are unchanged. What changes is H_iu, the change of mode i's generalised force with
airspeed at fixed state: ∂/∂u of Q S c̄ C^Qi(trim) is 2/u₀ times the **whole** aerodynamic
generalised force at trim, which at the elastic equilibrium balances the structure:
Q S c̄ C_0,e^Qi = m_i ω_i² η₀_i, so H_iu = 2 ω_i² η₀_i / u₀ (the paper's 2 C_0^Qi Q S c̄ /
(m_i u₀) leaves out the aerodynamic stiffness acting on the static deflection, i.e. it
linearises about an undeformed wing). The co-simulation's ΔQ forcing b_0 becomes
ω_i² η₀_i / Q₀ for the same reason; with it the perturbation Δη is exactly η − η₀ at any Q.

Units: SI; angles [rad] unless the name ends in ``_deg``; η [rad] (modes normalised on a
twist, docs/conventions.md).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import StateSpace, build_state_space, coupled_blocks
from bioflex_jsb.flight_dynamics.modal_matrices import ModalMatrices, modal_matrices
from bioflex_jsb.flight_dynamics.rigid import FlightCondition, level_flight_condition
from bioflex_jsb.parameters.airframe import (
    RigidAerodynamics,
)
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3, STANDARD_GRAVITY_M_S2

# NUMERICAL: the fixed point's tolerance on α [rad]; 1e-12 rad is ~1e-10 of a trim α and
# far below anything the loads or the tables resolve. A JSBSim rigid trim resolves α to its
# own tolerance only; pass a looser ``tol_rad`` with it (≈ 1e-6 rad).
DEFAULT_TOL_RAD = 1e-12
DEFAULT_MAX_ITERATIONS = 30
# NUMERICAL: a positive real eigenvalue μ of Ω⁻² K_a counts as real when its imaginary part
# is below this fraction of |μ| (round-off of a real eigenvalue of a 3×3 is ~1e-16 relative).
_REAL_EIG_REL = 1e-9


@dataclass(frozen=True)
class StaticWingLoads:
    """Loads of the statically deflected wing on the airframe.

    lift_n: up, perpendicular to the air velocity [N]; drag_n: aft, along the air velocity
    [N]; pitch_moment_n_m: about the centre of gravity, nose up [N·m].
    """

    lift_n: float = 0.0
    drag_n: float = 0.0
    pitch_moment_n_m: float = 0.0

    def as_dict(self) -> dict[str, float]:
        return {"lift_n": self.lift_n, "drag_n": self.drag_n,
                "pitch_moment_n_m": self.pitch_moment_n_m}


@dataclass(frozen=True)
class RigidTrimPoint:
    """A rigid trim: angle of attack α [rad] and elevator δe [rad, + trailing edge down]."""

    alpha_rad: float
    elevator_rad: float


RigidTrim = Callable[[StaticWingLoads], RigidTrimPoint]
"""The rigid trim with extra wing loads applied (JSBSim's, or :func:`linear_rigid_trim`)."""


def linear_rigid_trim(
    condition: FlightCondition,
    aero: RigidAerodynamics | None = None,
    mass_kg: float | None = None,
) -> RigidTrim:
    """Level-flight trim of the linear airframe model with extra loads.

    Lift: Q S (C_L0,α=0 + C_Lα α + C_Lδe δe) + L = m g; moment about the CG:
    Q S c̄ (C_m0 + C_mα α + C_mδe δe) + M = 0 (thrust along the flight path, through the CG:
    ``AIRFRAME_GEOMETRY``; drag only sets the throttle). Unlike
    :func:`~bioflex_jsb.flight_dynamics.rigid.level_flight_condition` the elevator's lift is
    kept, as JSBSim's trim keeps it (JSBSim at 15 m/s: α 1.77°, δe 1.12°; this: 1.79°, 1.00°).
    S, c̄, the mass and the derivatives are the condition's airframe's unless given.
    """
    af = condition.airframe
    aero = af.aero if aero is None else aero
    mass_kg = af.mass.mass_kg if mass_kg is None else mass_kg
    qs = condition.dynamic_pressure_pa * af.reference.area_m2
    qsc = qs * af.reference.mean_chord_m
    weight = mass_kg * STANDARD_GRAVITY_M_S2
    matrix = np.array([[aero.cl_alpha_per_rad, aero.cl_delta_e_per_rad],
                       [aero.cm_alpha_per_rad, aero.cm_delta_e_per_rad]])

    def trim(loads: StaticWingLoads) -> RigidTrimPoint:
        rhs = np.array([(weight - loads.lift_n) / qs - aero.cl0,
                        -loads.pitch_moment_n_m / qsc - aero.cm0])
        alpha, elevator = np.linalg.solve(matrix, rhs)
        return RigidTrimPoint(float(alpha), float(elevator))

    return trim


def divergence_dynamic_pressure_pa(mm: ModalMatrices) -> float:
    """Lowest Q [Pa] at which Ω² − Q K_a is singular (wing divergence, body held); inf if none.

    det(Ω² − Q K_a) = 0 ⇔ 1/Q is an eigenvalue μ of Ω⁻² K_a; the lowest Q is 1/max μ over
    the real positive μ. Independent of the air density (a dynamic pressure)."""
    mu = np.linalg.eigvals(mm.k_aero / (mm.omega**2)[:, None])
    real = mu[(np.abs(mu.imag) <= _REAL_EIG_REL * np.abs(mu)) & (mu.real > 0.0)].real
    return math.inf if real.size == 0 else float(1.0 / real.max())


def divergence_speed_m_s(wing, cl_trim: float = 0.5,
                         density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                         aero: RigidAerodynamics | None = None) -> float:
    """The wing's static divergence speed with the body held [m/s] (inf if none).

    ``wing`` an :class:`~bioflex_jsb.flight_dynamics.lti.ElasticWingModel`. K_a does not
    depend on the trim (``cl_trim`` only enters the loads, not the stiffness)."""
    q_d = divergence_dynamic_pressure_pa(modal_matrices(wing, cl_trim, aero))
    return math.sqrt(2.0 * q_d / density_kg_m3) if math.isfinite(q_d) else math.inf


def trimmed_divergence_speed_m_s(
    wing,
    *,
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    range_m_s: tuple[float, float] = (1.0, 60.0),
    step_m_s: float = 0.05,
) -> float:
    """Lowest speed [m/s] in ``range_m_s`` at which the trim's linear system (wing statics +
    the lift and moment balance of :func:`linear_rigid_trim`) is singular; inf if none.

    For information only: :func:`elastic_trim` refuses from the (lower, for the
    backward-axis wings) held-body divergence speed, beyond which the wing at a fixed α
    has no stable equilibrium (docs/decisions.md, "Elastic trim"). The system's
    determinant is scanned on a ``step_m_s`` grid and the first sign change bisected.
    """
    mm = modal_matrices(wing, 0.5, aero)  # K_a, b_α and the load rows do not depend on C_L0
    aero = wing.airframe.aero if aero is None else aero
    n = mm.n
    cb = wing.airframe.reference.mean_chord_m

    def det(v: float) -> float:
        q = 0.5 * density_kg_m3 * v * v
        m = np.zeros((n + 2, n + 2))
        m[:n, :n] = np.diag(mm.omega**2) - q * mm.k_aero
        m[:n, n] = -q * mm.b_alpha
        m[n, :n], m[n, n], m[n, n + 1] = mm.load_eta[0], aero.cl_alpha_per_rad, \
            aero.cl_delta_e_per_rad
        m[n + 1, :n], m[n + 1, n], m[n + 1, n + 1] = mm.load_eta[2] / cb, \
            aero.cm_alpha_per_rad, aero.cm_delta_e_per_rad
        return float(np.linalg.det(m))

    grid = np.arange(range_m_s[0], range_m_s[1] + 0.5 * step_m_s, step_m_s)
    values = np.array([det(v) for v in grid])
    flips = np.flatnonzero(np.sign(values[1:]) != np.sign(values[:-1]))
    if flips.size == 0:
        return math.inf
    lo, hi = float(grid[flips[0]]), float(grid[flips[0] + 1])
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if np.sign(det(mid)) == np.sign(det(lo)):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


@dataclass(frozen=True)
class ElasticTrim:
    """The static aeroelastic equilibrium at a level-flight trim (module docstring).

    eta_rad: absolute static modal deflection η₀ from the undeformed wing [rad];
    tip_twist_deg: Σ θ_i(b/2) η₀_i, leading edge up [deg]; tip_deflection_up_m:
    −Σ φ_i(b/2) η₀_i, elastic axis at the tip, up [m]; section_alpha_range_rad: min and max
    over the span of the sections' angle from zero lift, α_w + Δα + Σ θ_i(y) η₀_i [rad];
    rigid: the trim without wing loads; alpha_rad, elevator_rad: the elastic trim;
    loads: the deflected wing's loads that the elastic trim carries;
    c_0_q_rigid: C_0^Qi of Table B1 at the rigid trim (the paper's) [-];
    c_0_q_elastic: the whole aerodynamic generalised force at the elastic trim over Q S c̄,
    = m_i ω_i² η₀_i/(Q S c̄) [-]; h_u_elastic_per_m: H_iu about the elastic trim,
    2 ω_i² η₀_i/u₀ [rad/s² per m/s]; divergence_speed_m_s: the wing's static divergence
    speed, body held (inf if none) [m/s]; dynamic_pressure_ratio: Q/Q_D [-];
    eta_at_rigid_trim_rad: η₀ under the loads of the rigid trim (the fixed point's first
    iterate, the wing "linearised about the undeformed trim") [rad];
    alpha_history_rad: the fixed point's iterates of α; modal_residual: max |Ω²η₀ − Q(b_0 +
    b_α Δα + K_a η₀)| / max |Ω² η₀| at the result [-].
    """

    wing: str
    speed_m_s: float
    density_kg_m3: float
    dynamic_pressure_pa: float
    cl_trim: float
    eta_rad: np.ndarray
    tip_twist_deg: float
    tip_deflection_up_m: float
    section_alpha_range_rad: tuple[float, float]
    rigid: RigidTrimPoint
    alpha_rad: float
    elevator_rad: float
    loads: StaticWingLoads
    c_0_q_rigid: np.ndarray
    c_0_q_elastic: np.ndarray
    h_u_elastic_per_m: np.ndarray
    divergence_speed_m_s: float
    dynamic_pressure_ratio: float
    iterations: int
    converged: bool
    eta_at_rigid_trim_rad: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    alpha_history_rad: tuple[float, ...] = field(repr=False, default=())
    modal_residual: float = 0.0

    @property
    def delta_alpha_rad(self) -> float:
        """α(elastic) − α(rigid) [rad]."""
        return self.alpha_rad - self.rigid.alpha_rad

    @property
    def delta_elevator_rad(self) -> float:
        """δe(elastic) − δe(rigid) [rad]."""
        return self.elevator_rad - self.rigid.elevator_rad

    def as_dict(self) -> dict[str, object]:
        """JSON form (SI, rad; the proposed ``trim --wing W --json`` fields)."""
        div = self.divergence_speed_m_s
        return {
            "wing": self.wing,
            "speed_m_s": self.speed_m_s,
            "density_kg_m3": self.density_kg_m3,
            "dynamic_pressure_pa": self.dynamic_pressure_pa,
            "eta_rad": [float(x) for x in self.eta_rad],
            "eta_at_rigid_trim_rad": [float(x) for x in self.eta_at_rigid_trim_rad],
            "tip_twist_rad": math.radians(self.tip_twist_deg),
            "tip_twist_deg": self.tip_twist_deg,
            "tip_deflection_up_m": self.tip_deflection_up_m,
            "section_alpha_range_rad": list(self.section_alpha_range_rad),
            "alpha_rigid_rad": self.rigid.alpha_rad,
            "elevator_rigid_rad": self.rigid.elevator_rad,
            "alpha_rad": self.alpha_rad,
            "elevator_rad": self.elevator_rad,
            "delta_alpha_rad": self.delta_alpha_rad,
            "delta_elevator_rad": self.delta_elevator_rad,
            "wing_loads": self.loads.as_dict(),
            "c_0_q_rigid": [float(x) for x in self.c_0_q_rigid],
            "c_0_q_elastic": [float(x) for x in self.c_0_q_elastic],
            "divergence_speed_m_s": None if math.isinf(div) else div,
            "dynamic_pressure_ratio": self.dynamic_pressure_ratio,
            "iterations": self.iterations,
            "converged": self.converged,
        }


def _tip(values: np.ndarray) -> np.ndarray:
    return np.asarray(values, dtype=float)[:, -1]


def elastic_trim(
    build,
    speed_m_s: float,
    *,
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    rigid_trim: RigidTrim | None = None,
    tol_rad: float = DEFAULT_TOL_RAD,
    max_iterations: int = DEFAULT_MAX_ITERATIONS,
) -> ElasticTrim:
    """The elastic trim of ``build`` (a :class:`~bioflex_jsb.flight_dynamics.wing_model.
    WingBuild`: its ``model`` and ``modes``) at ``speed_m_s`` [m/s], level flight.

    ``rigid_trim`` defaults to :func:`linear_rigid_trim` of ``aero``. Raises
    :class:`InputError` at or beyond the wing's static divergence speed, and if the fixed
    point does not converge in ``max_iterations``.
    """
    wing, modes = build.model, build.modes
    condition = level_flight_condition(float(speed_m_s), density_kg_m3, aero,
                                       airframe=wing.airframe)
    ref = condition.airframe.reference
    q = condition.dynamic_pressure_pa
    mm = modal_matrices(wing, condition.cl_trim, aero)
    q_div = divergence_dynamic_pressure_pa(mm)
    v_div = math.sqrt(2.0 * q_div / density_kg_m3) if math.isfinite(q_div) else math.inf
    if q >= q_div:
        raise InputError(
            f"wing {wing.name!r}: no static aeroelastic equilibrium at {speed_m_s:g} m/s: "
            f"beyond the wing's static divergence speed {v_div:.2f} m/s (body held, "
            f"rho = {density_kg_m3:g} kg/m^3); trim below it"
        )
    trim_fn = linear_rigid_trim(condition, aero) if rigid_trim is None else rigid_trim
    rigid = trim_fn(StaticWingLoads())
    stiffness = np.diag(mm.omega**2) - q * mm.k_aero
    qs = q * ref.area_m2

    def eta_of(alpha: float) -> np.ndarray:
        return np.linalg.solve(stiffness, q * (mm.b_0 + mm.b_alpha * (alpha - rigid.alpha_rad)))

    def loads_of(eta: np.ndarray) -> StaticWingLoads:
        lift, drag, moment = qs * (mm.load_eta @ eta)
        return StaticWingLoads(float(lift), float(drag), float(moment))

    def residual(alpha: float) -> tuple[float, RigidTrimPoint]:
        point = trim_fn(loads_of(eta_of(alpha)))
        return point.alpha_rad - alpha, point

    history = [rigid.alpha_rad]
    a0 = rigid.alpha_rad
    g0, point = residual(a0)
    a1 = a0 + g0  # one plain fixed-point step
    converged = abs(g0) <= tol_rad
    alpha = a0
    iterations = 0
    while not converged and iterations < max_iterations:
        iterations += 1
        history.append(a1)
        g1, point = residual(a1)
        alpha = a1
        if abs(g1) <= tol_rad:
            converged = True
            break
        slope = (g1 - g0) / (a1 - a0)
        if slope == 0.0:
            break
        a0, g0, a1 = a1, g1, a1 - g1 / slope
    if not converged:
        raise InputError(
            f"wing {wing.name!r}: elastic trim at {speed_m_s:g} m/s did not converge in "
            f"{max_iterations} iterations (last alpha change {abs(g0):.3g} rad)"
        )
    eta = eta_of(alpha)
    loads = loads_of(eta)
    sc = ref.area_m2 * ref.mean_chord_m
    c0_rigid = mm.b_0 * mm.mass_kg_m2 / sc
    c0_elastic = mm.mass_kg_m2 * mm.omega**2 * eta / (q * sc)
    forcing = q * (mm.b_0 + mm.b_alpha * (alpha - rigid.alpha_rad) + mm.k_aero @ eta)
    restoring = mm.omega**2 * eta
    scale = float(np.max(np.abs(restoring))) or 1.0
    alpha_w = condition.cl_trim / wing.wing_lift_slope_per_rad + (alpha - rigid.alpha_rad)
    section = alpha_w + np.asarray(modes.twist_rad, dtype=float).T @ eta
    return ElasticTrim(
        wing=wing.name,
        speed_m_s=float(speed_m_s),
        density_kg_m3=float(density_kg_m3),
        dynamic_pressure_pa=q,
        cl_trim=condition.cl_trim,
        eta_rad=eta,
        tip_twist_deg=math.degrees(float(_tip(modes.twist_rad) @ eta)),
        tip_deflection_up_m=-float(_tip(modes.bending_m) @ eta),
        section_alpha_range_rad=(float(section.min()), float(section.max())),
        rigid=rigid,
        alpha_rad=point.alpha_rad,
        elevator_rad=point.elevator_rad,
        loads=loads,
        c_0_q_rigid=c0_rigid,
        c_0_q_elastic=c0_elastic,
        h_u_elastic_per_m=2.0 * mm.omega**2 * eta / condition.speed_m_s,
        divergence_speed_m_s=v_div,
        dynamic_pressure_ratio=q / q_div if math.isfinite(q_div) else 0.0,
        iterations=iterations,
        converged=converged,
        eta_at_rigid_trim_rad=eta_of(rigid.alpha_rad),
        alpha_history_rad=tuple(history),
        modal_residual=float(np.max(np.abs(restoring - forcing))) / scale,
    )


def linearise_about_elastic_trim(
    model: str,
    trim: ElasticTrim,
    wing,
    aero: RigidAerodynamics | None = None,
    a_rr: np.ndarray | None = None,
) -> StateSpace:
    """The ``coupled`` or ``qsd`` model of Eq. (4) linearised about ``trim`` (module
    docstring): H_iu = 2 ω_i² η₀_i / u₀ replaces the paper's; everything else is Eq. (4).
    ``a_rr``: JSBSim's rigid block instead of the analytic one (as ``compare`` uses).

    The states stay perturbations (Δη for ``coupled``); ``notes["eta_static_rad"]`` holds η₀,
    so absolute deflections are η₀ + Δη. ``rigid`` has no wing and is refused.
    """
    if model not in ("coupled", "qsd"):
        raise InputError(f"linearising about the elastic trim needs a wing model "
                         f"(coupled or qsd), not {model!r}")
    condition = level_flight_condition(trim.speed_m_s, trim.density_kg_m3, aero,
                                       airframe=wing.airframe)
    base = build_state_space(model, condition, wing, aero, a_rr=a_rr)
    blk = coupled_blocks(wing, condition, aero)
    n = wing.n_modes
    d_h_u = trim.h_u_elastic_per_m - blk.a_er[:, 0]  # change of the u column of A_ER
    a, c = base.a.copy(), base.c.copy()
    if model == "coupled":
        a[4 + n:, 0] += d_h_u
    else:  # A_QSD = A_RR − A_RE A_EE⁻¹ A_ER; η_qs = −A_EE⁻¹ A_ER x_R
        solved = np.linalg.solve(blk.a_ee, d_h_u)
        a[:, 0] -= blk.a_re @ solved
        c[4:, 0] -= solved
    notes = dict(base.notes, trim="elastic", eta_static_rad=[float(x) for x in trim.eta_rad],
                 alpha_trim_rad=trim.alpha_rad, elevator_trim_rad=trim.elevator_rad)
    return replace(base, a=a, c=c, notes=notes)
