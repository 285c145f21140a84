"""The modal wing of the co-simulation: one step of the elastic wing, no I/O.

Each airframe step the co-simulation loop (``bioflex_jsb.drivers.gust``) hands the wing the
flow state it reads from JSBSim (:class:`FlowState`), takes the incremental loads
(:class:`WingLoads`) and writes them into the airframe's external reactions.

Model (the same physics as the LTI model of Eq. 4, with the *current* dynamic pressure and
airspeed instead of trim values, so the loads are nonlinear in airspeed):

* the modal coordinates are perturbations Δη from the static deformation at trim (the rigid
  aerodynamics of the airframe already carry the trimmed, deformed wing);
* generalised force on mode i:
  Q_i = Q S c̄ [C_α^Qi Δα + C_q^Qi q c̄/(2V) + Σ_j C_ηj^Qi Δη_j + Σ_j C_η̇j^Qi Δη̇_j c̄/(2V)]
  + (Q − Q_0) S c̄ C_0^Qi, with Δα = α − α_0 (α measured against the air, gusts included);
* modal equation m_i (Δη̈_i + 2 ζ_i ω_i Δη̇_i + ω_i² Δη_i) = Q_i;
* incremental loads: ΔL = Q S (C_Lη·Δη + C_Lη̇·Δη̇ c̄/(2V)) (up), ΔD = Q S (C_Dη·Δη +
  C_Dη̇·Δη̇ c̄/(2V)) (aft, along the air velocity), ΔM = Q S c̄ (C_mη·Δη + C_mη̇·Δη̇ c̄/(2V))
  (nose up, about the centre of gravity). The modes are symmetric, so there is no rolling
  moment; roll rate p does not enter.

Integration (``coupled``): exact discretisation with the inputs held over the step
(zero-order hold). With A(Q, V), B(Q, V) the modal system matrices and (Q_r, V_r) a
reference flow,

    x_{k+1} = [Φ_r + (Q − Q_r) ∂Φ/∂Q + (Q/V − Q_r/V_r) ∂Φ/∂(Q/V)] x_k + Ψ_r B(Q, V) f_k,

Φ_r = e^{A_r Δt}, Ψ_r = ∫_0^Δt e^{A_r τ} dτ, and ∂Φ the Fréchet derivatives of the
exponential along ∂A/∂Q and ∂A/∂(Q/V) (``scipy.linalg.expm_frechet``): exact at the
reference flow for any step, so the structural dynamics up to the third mode (107 Hz,
ω Δt = 5.6 at 1/120 s) are integrated without a stability limit, and exact to first order
in the change of the aerodynamic stiffness and damping since the reference (a few per cent
of ω²). The reference is renewed when Q or V moves by more than ``refresh_rel`` (default
5 %): at the co-simulation's step that changes η₁ by < 0.05 % against a step exact at every
step's flow (holding Ψ_r ΔA x_k over the step instead, a first-order treatment, is 2 % off
in the Fig. 21 case; tests/test_gusts_and_modal_wing.py).

Timing in the co-simulation (``drivers/gust.py``): the wing advances with the flow of t_k
first and the loads of the new state η_{k+1} go with JSBSim's step k, whose forces belong to
t_{k+1}: no coupling lag. ``qsd`` takes Δη as the quasi-static solution of the flow of t_k.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np
from scipy.linalg import expm, expm_frechet
from threadpoolctl import ThreadpoolController

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_matrices import modal_matrices
from bioflex_jsb.parameters.airframe import RigidAerodynamics

WING_MODELS = ("rigid", "coupled", "qsd")


@lru_cache(maxsize=1)
def _blas_controller() -> ThreadpoolController:
    """threadpoolctl's view of the loaded BLAS libraries (inspected once per process)."""
    return ThreadpoolController()


def one_blas_thread():
    """A context in which BLAS uses one thread (about 10 µs to enter and leave)."""
    return _blas_controller().limit(limits=1, user_api="blas")
# Default co-simulation step [s]: 31 samples per period of the first wing mode (in vacuo), 9
# of the third. The Fig. 21 run at this step is within 1 % NRMSE of the same run at a quarter
# of it on u, α, q, θ and η₁ (tests/test_cosim.py). JSBSim's aircraft default, 1/120 s,
# leaves 4 samples per period.
DEFAULT_DT_S = 1.0 / 960.0
# The co-simulation step's range [s]. Finest: below ~6e-5 s JSBSim's trim of the prototype
# fails, reported as a motor short of thrust (measured: 5e-5 and 3e-5 s fail,
# 6e-5 and 1e-4 trim at 15 m/s), so 1e-4 s (10 kHz, 90 steps a period of the wing's 110 Hz
# third mode) with margin; coarsest 0.02 s (50 Hz: at 0.04-0.1 s the propeller's RPM does
# not settle in the trim, and the wing's modes are unresolved).
MIN_DT_S, MAX_DT_S = 1e-4, 0.02


@dataclass(frozen=True)
class FlowState:
    """Flow at the wing, read from the airframe each step.

    alpha_rad: angle of attack against the air (gust included) [rad]; q_rad_s: pitch rate
    [rad/s]; airspeed_m_s: true airspeed [m/s]; dynamic_pressure_pa [Pa].
    """

    alpha_rad: float
    q_rad_s: float
    airspeed_m_s: float
    dynamic_pressure_pa: float


@dataclass(frozen=True)
class WingLoads:
    """Incremental loads of the elastic wing on the airframe.

    lift_n: up, perpendicular to the air velocity [N]; drag_n: along the air velocity,
    positive aft [N]; pitch_moment_n_m: about the centre of gravity, nose up [N·m].
    """

    lift_n: float
    drag_n: float
    pitch_moment_n_m: float


@dataclass(frozen=True)
class TrimReference:
    """The trim the perturbations are taken from: α_0 [rad], Q_0 [Pa], C_L0 [-]."""

    alpha_rad: float
    dynamic_pressure_pa: float
    cl_trim: float


class ModalWing:
    """Elastic wing state and its step. ``model`` is ``rigid``, ``coupled`` or ``qsd``."""

    def __init__(
        self,
        wing: ElasticWingModel,
        trim: TrimReference,
        model: str = "coupled",
        dt_s: float = 1.0 / 120.0,
        aero: RigidAerodynamics | None = None,
        refresh_rel: float = 0.05,
        static_eta: np.ndarray | None = None,
    ) -> None:
        """``aero``: the rigid aerodynamics (the induced-drag factor k of the loads); None:
        those of the wing's aircraft (``wing.airframe``: S, c̄ and k are the aircraft's).
        ``static_eta``: the static deflection η₀ [rad] of an elastic trim
        (:mod:`bioflex_jsb.flight_dynamics.elastic_trim`), from which Δη is measured: its
        loads join the incremental ones and the ΔQ forcing becomes ω²η₀/Q₀ (the whole
        aerodynamic generalised force at trim per unit Q); None: the rigid trim (η₀ = 0,
        the paper's reading)."""
        if model not in WING_MODELS:
            raise InputError(f"unknown wing model {model!r}; accepted: {', '.join(WING_MODELS)}")
        if not (np.isfinite(dt_s) and dt_s > 0.0):
            raise InputError(f"time step must be finite and > 0 s, got {dt_s!r}")
        self.wing = wing
        self.trim = trim
        self.model = model
        self.dt_s = float(dt_s)
        self.refresh_rel = float(refresh_rel)
        n = wing.n_modes
        self.n_modes = n
        # the one builder of the modal matrices (shared with the native export)
        mm = modal_matrices(wing, trim.cl_trim, aero)
        self.static_eta = np.zeros(wing.n_modes) if static_eta is None else np.asarray(
            static_eta, dtype=float)
        if static_eta is not None:
            mm = replace(mm, b_0=mm.omega**2 * self.static_eta / trim.dynamic_pressure_pa)
        # loads of the static deflection per unit Q S [C_L, C_D, C_m·c̄]: zero for a rigid trim
        self._static_load = mm.load_eta @ self.static_eta
        self.matrices = mm
        self._load_eta, self._load_etadot = mm.load_eta, mm.load_etadot
        # Per-unit-Q parts of the lower (η̈) rows, so a step needs no matrix assembly:
        # η̈ = −ω²η − 2ζωη̇ + Q·K_a η + (Q/V)·D_a η̇ + Q·b_α Δα + (Q/V)·b_q q + b_0 ΔQ.
        self._k_aero, self._d_aero = mm.k_aero, mm.d_aero
        self._forcing = mm.forcing_columns()
        self._x = np.zeros(2 * n)  # [Δη, Δη̇]
        self._load_x = np.hstack([self._load_eta, np.zeros_like(self._load_eta)])
        self._key: tuple[float, float] | None = None
        self._phi = self._gamma = None
        # a flaperon (set_flaperon): η̈ per unit Q δf, its step column and the deflection held
        self._flap_force: np.ndarray | None = None
        self._flap_cols: np.ndarray | None = None
        self.flaperon_rad = 0.0

    def set_flaperon(self, force_per_q: np.ndarray) -> None:
        """Let a flaperon force the modes: η̈ gains Q b_δf δf (``force_per_q`` b_δf (n,)
        [1/(Pa·s²) per rad], :mod:`bioflex_jsb.aeroelasticity.flaperon`), δf
        :attr:`flaperon_rad` [rad] held over each step (zero-order hold, as the flow)."""
        self._flap_force = np.asarray(force_per_q, dtype=float).reshape(self.n_modes)
        self._key = None  # the step's columns again, with the flaperon's

    # -- modal dynamics -------------------------------------------------------------------
    def _matrices(self, q_pa: float, v_m_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Continuous A_e (2n×2n) and B_e (2n×3) for inputs f = [Δα, q, ΔQ]."""
        mm = self.matrices
        return mm.a_matrix(q_pa, q_pa / v_m_s), mm.b_matrix(q_pa, q_pa / v_m_s)

    def _reference(self, q_pa: float, v_m_s: float) -> None:
        """Exact discretisation at (Q_r, V_r): Φ = e^{A dt}, Ψ = ∫_0^dt e^{A τ} dτ, and the
        first-order change of Φ per unit change of Q and of Q/V (Fréchet derivatives of the
        exponential along ∂A/∂Q and ∂A/∂(Q/V)). BLAS runs on one thread here: on these
        12×12 matrices OpenBLAS's default threads only add hand-over costs (a refresh took
        5-39 ms instead of about 1 ms on a loaded 2-core machine)."""
        with one_blas_thread():
            self._compute_reference(q_pa, v_m_s)

    def _compute_reference(self, q_pa: float, v_m_s: float) -> None:
        a, _ = self._matrices(q_pa, v_m_s)
        n2 = a.shape[0]
        aug = np.zeros((2 * n2, 2 * n2))
        aug[:n2, :n2] = a
        aug[:n2, n2:] = np.eye(n2)
        e = expm(aug * self.dt_s)
        n = self.n_modes
        phi, psi_lower = e[:n2, :n2], e[:n2, n2 + n :]
        zeros = np.zeros((n, n))
        d_a_dq = np.block([[zeros, zeros], [self._k_aero, zeros]])
        d_a_dqv = np.block([[zeros, zeros], [zeros, self._d_aero]])
        # One matrix for the step: rows [Φ; ∂Φ/∂Q; ∂Φ/∂(Q/V)] act on x, columns of
        # ``_inputs`` on the per-unit flow forcing (Q Δα, Q q / V, ΔQ).
        self._stack = np.vstack([
            phi,
            expm_frechet(a * self.dt_s, d_a_dq * self.dt_s, compute_expm=False),
            expm_frechet(a * self.dt_s, d_a_dqv * self.dt_s, compute_expm=False),
        ])
        self._input_cols = psi_lower @ self._forcing
        if self._flap_force is not None:
            self._flap_cols = psi_lower @ self._flap_force
        self._key = (q_pa, v_m_s)

    def prepare_arrays(self) -> None:
        """Give every array the compiled step reads a shape and a contiguous layout (the
        reference arrays are placeholders until the first refresh; the rates of η̇ are
        rebound as one contiguous state vector)."""
        n2 = 2 * self.n_modes
        if self._key is None:
            self._stack = np.zeros((3 * n2, n2))
            self._input_cols = np.zeros((n2, 3))
        self._x = np.ascontiguousarray(self._x, dtype=float).copy()
        self._load_eta = np.ascontiguousarray(self._load_eta)
        self._load_etadot = np.ascontiguousarray(self._load_etadot)
        self._k_aero = np.ascontiguousarray(self._k_aero)

    def prepare(self, flow: FlowState) -> None:
        """Compute the step's matrices for ``flow`` now (the first step would otherwise do
        it): for real-time loops, so the first paced step costs what the others do."""
        if self.model == "coupled":
            self._reference(flow.dynamic_pressure_pa, flow.airspeed_m_s)

    def _advance(self, flow: FlowState) -> None:
        """x ← [Φ_r + ΔQ ∂Φ/∂Q + Δ(Q/V) ∂Φ/∂(Q/V)] x + Ψ_r B(Q,V) f (module docstring)."""
        q_pa, v = flow.dynamic_pressure_pa, flow.airspeed_m_s
        key = self._key
        if (
            key is None
            or abs(q_pa - key[0]) > self.refresh_rel * abs(key[0])
            or abs(v - key[1]) > self.refresh_rel * abs(key[1])
        ):
            self._reference(q_pa, v)
        q_r, v_r = self._key
        m = 2 * self.n_modes
        y = self._stack @ self._x
        f = (q_pa * (flow.alpha_rad - self.trim.alpha_rad), q_pa / v * flow.q_rad_s,
             q_pa - self.trim.dynamic_pressure_pa)
        self._x = (y[:m] + (q_pa - q_r) * y[m : 2 * m] + (q_pa / v - q_r / v_r) * y[2 * m :]
                   + self._input_cols @ f)
        if self._flap_force is not None:
            self._x += self._flap_cols * (q_pa * self.flaperon_rad)

    @property
    def eta(self) -> np.ndarray:
        """Modal coordinates Δη [rad] (perturbations from the static deformation at trim)."""
        return self._x[: self.n_modes]

    @eta.setter
    def eta(self, value) -> None:
        self._x = np.concatenate([np.asarray(value, dtype=float), self._x[self.n_modes :]])

    @property
    def eta_dot(self) -> np.ndarray:
        """Modal rates Δη̇ [rad/s]."""
        return self._x[self.n_modes :]

    @eta_dot.setter
    def eta_dot(self, value) -> None:
        self._x = np.concatenate([self._x[: self.n_modes], np.asarray(value, dtype=float)])

    def _inputs(self, flow: FlowState) -> np.ndarray:
        return np.array(
            [
                flow.alpha_rad - self.trim.alpha_rad,
                flow.q_rad_s,
                flow.dynamic_pressure_pa - self.trim.dynamic_pressure_pa,
            ]
        )

    def quasi_static_eta(self, flow: FlowState) -> np.ndarray:
        """Δη that balances the current flow with η̇ = η̈ = 0 (Eq. 9-10) [rad]."""
        a, b = self._matrices(flow.dynamic_pressure_pa, flow.airspeed_m_s)
        n = self.n_modes
        force = b[n:] @ self._inputs(flow)
        if self._flap_force is not None:
            force = force + flow.dynamic_pressure_pa * self.flaperon_rad * self._flap_force
        return np.linalg.solve(a[n:, :n], -force)

    def step(self, flow: FlowState) -> None:
        """Advance the modal state over one step with ``flow`` held (zero-order hold)."""
        if self.model == "coupled":
            self._advance(flow)
        elif self.model == "qsd":
            self.eta = self.quasi_static_eta(flow)
            self.eta_dot = np.zeros(self.n_modes)

    def loads(self, flow: FlowState) -> WingLoads:
        """Incremental loads of the current modal state in ``flow``."""
        if self.model == "rigid":
            return WingLoads(0.0, 0.0, 0.0)
        if self.model == "qsd":
            self.eta = self.quasi_static_eta(flow)
        ref = self.wing.airframe.reference  # S, c̄ of the wing's aircraft
        qs = flow.dynamic_pressure_pa * ref.area_m2
        rate = ref.mean_chord_m / (2.0 * flow.airspeed_m_s)
        self._load_x[:, self.n_modes :] = self._load_etadot * rate  # rates scale with c̄/2V
        lift, drag, moment = (self._load_x @ self._x + self._static_load).tolist()
        return WingLoads(qs * lift, qs * drag, qs * moment)

    def tip_twist_rad(self, tip_twist_per_mode: np.ndarray) -> float:
        """Elastic tip twist Σ θ_i(b/2) Δη_i [rad], positive leading edge up."""
        return float(np.asarray(tip_twist_per_mode) @ self.eta)
