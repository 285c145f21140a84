"""The modal wing on unsteady strips, for the co-simulation step (``aero="unsteady"``).

The same interface as :class:`~bioflex_jsb.simulation.modal_wing.ModalWing` (``step(flow)``,
``loads(flow)``, ``eta``, ``eta_dot``, ``prepare(flow)``), with the gust w_g [m/s, up] passed
beside the flow (``step(flow, gust_m_s)``, ``loads(flow, gust_m_s)``): the wing must tell
the gust from the body's own angle of attack.

Model: the paper's modal wing (ModalWing's quasi-steady strips, Eq. 3 and Table B1, with the
flow's own Q and V) plus the unsteady increments of the free aircraft's LTI model
(:mod:`bioflex_jsb.aeroelasticity.free_aircraft`, rows from
:func:`~bioflex_jsb.aeroelasticity.strip_increments.strip_increments`): per lattice strip,
Theodorsen's circulatory lift through Jones's C(k) on the three-quarter-chord upwash minus
the quasi-steady lift, the apparent mass about the physical elastic axis, and the wing's
gust lift through Küssner's function (Sears & Sparks) instead of at once. JSBSim's rigid
aerodynamics carry the whole aircraft's quasi-steady lift, gust included; the loads handed
back are the modal ones plus those increments (for the body: lift, its induced drag 2 k C_L0
ΔL and the pitching moment about the CG).

States (:attr:`state_names`, :attr:`state_units`): η_i [rad], η̇_i [rad/s] (perturbations
from the trim deformation), then ``lag1[k]``, ``lag2[k]`` (Jones) and ``kussner1[k]``,
``kussner2[k]`` [m/s] per starboard strip k. Inputs held over a step (zero-order hold),
f = [Q Δα, Q q/V, ΔQ, α_i, q, α̇_i, q̇, w_g]: the first three ModalWing's (Δα against the
air, gust included, so the modes see the quasi-steady gust as in the paper); α_i = Δα −
w_g/V the body's inertial angle of attack (the LTI state α), on which the lag states act;
α̇_i and q̇ the body's accelerations, which the apparent mass needs and JSBSim integrates:
backward differences over the last step (the LTI model solves them implicitly; their
apparent-mass share of the body's loads is ≈ 2 % of the aircraft's mass).

Integration: exact discretisation at a reference flow (Q_r, V_r), density ρ_r = 2Q_r/V_r²,
renewed when Q or V moves by more than ``refresh_rel`` (5 %), as ModalWing. At fixed density
every matrix is a quadratic in V (stiffness ∝ Q, damping ∝ ρV, lag rates ∝ V, apparent mass
∝ ρ), so A(V), B(V) and the load rows are kept as three coefficient matrices (evaluated at
0.5, 1, 1.5 V_r and solved exactly), and

    x_{k+1} = [Φ_r + (V − V_r) ∂Φ/∂V] x_k + Ψ_r B(V) f_k,

Φ_r = e^{A(V_r) Δt}, Ψ_r = ∫_0^Δt e^{A(V_r) τ} dτ, ∂Φ/∂V the Fréchet derivative of the
exponential along dA/dV: exact at the reference for any step, first order in the change
since. Loads of the state after the step in the step's flow, η̈ from the held inputs. This
is the readable reference; the co-simulation runs the same arithmetic compiled
(:mod:`bioflex_jsb.simulation.unsteady_kernel`, held to it by tests/test_unsteady_kernel.py).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm, expm_frechet

from bioflex_jsb.aeroelasticity.free_aircraft import StripGeometry, strip_geometry
from bioflex_jsb.aeroelasticity.strip_increments import lag_state_names, strip_increments
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel
from bioflex_jsb.flight_dynamics.modal_matrices import modal_matrices
from bioflex_jsb.parameters.airframe import RigidAerodynamics
from bioflex_jsb.simulation.modal_wing import (
    FlowState,
    TrimReference,
    WingLoads,
    one_blas_thread,
)

INPUTS = ("Q*dalpha", "Q*q/V", "dQ", "alpha_i", "q", "alpha_i_dot", "q_dot", "w_g")
INPUT_UNITS = ("Pa*rad", "Pa*rad/m", "Pa", "rad", "rad/s", "rad/s^2", "rad/s^2", "m/s")
FIT_SPEED_NODES = (0.5, 1.0, 1.5)  # speeds of the quadratic's fit, × V_r


class UnsteadyModalWing:
    """Elastic wing with unsteady strips and its step (module docstring); model ``coupled``.

    Args:
        wing: the elastic wing model (modes, Table B1; its damping ratios are used).
        geometry: the strips of the same build
            (:func:`~bioflex_jsb.aeroelasticity.free_aircraft.strip_geometry`).
        trim: the trim the perturbations are taken from.
        dt_s: the step [s]; aero: the rigid aerodynamics (induced drag factor; None: those
            of the wing's aircraft, ``wing.airframe``);
        refresh_rel: relative change of Q or V that renews the reference.
    """

    model = "coupled"

    def __init__(self, wing: ElasticWingModel, geometry: StripGeometry, trim: TrimReference,
                 dt_s: float = 1.0 / 120.0, aero: RigidAerodynamics | None = None,
                 refresh_rel: float = 0.05) -> None:
        if not (np.isfinite(dt_s) and dt_s > 0.0):
            raise InputError(f"time step must be finite and > 0 s, got {dt_s!r}")
        if geometry.phi.shape[0] != wing.n_modes:
            raise InputError(f"the strips carry {geometry.phi.shape[0]} modes, the wing "
                             f"model {wing.n_modes}")
        self.wing, self.geometry, self.trim = wing, geometry, trim
        self.dt_s = float(dt_s)
        self.refresh_rel = float(refresh_rel)
        self.n_modes = n = wing.n_modes
        self.n_strips = geometry.chord_m.size
        aero = wing.airframe.aero if aero is None else aero
        self.matrices = modal_matrices(wing, trim.cl_trim, aero)
        self._k2 = 2.0 * aero.k_induced * trim.cl_trim  # induced drag per unit lift [-]
        eta = tuple(f"eta{i + 1}" for i in range(n))
        self.state_names = (eta + tuple(f"{e}_dot" for e in eta)
                            + lag_state_names(self.n_strips, gust=True))
        self.state_units = ("rad",) * n + ("rad/s",) * n + ("m/s",) * (4 * self.n_strips)
        self._x = np.zeros(len(self.state_names))
        self._key: tuple[float, float] | None = None
        self._last: tuple[float, float] | None = None  # (α_i, q) of the last step
        self._f = np.zeros(len(INPUTS))

    @classmethod
    def from_build(cls, build, trim: TrimReference, dt_s: float = 1.0 / 120.0,
                   **kwargs) -> UnsteadyModalWing:
        """The wing of a :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild`
        (its ``model`` and its strips)."""
        return cls(build.model, strip_geometry(build), trim, dt_s, **kwargs)

    # -- continuous model -----------------------------------------------------------------
    def continuous(self, speed_m_s: float, density_kg_m3: float):
        """(A (n_x×n_x), B (n_x×8), L (2 × (n_x + 8))) at ``speed_m_s`` [m/s] and
        ``density_kg_m3`` [kg/m³], the quasi-steady part at Q = ½ρV²: ẋ = A x + B f, and the
        increments' body loads [Z [N, down]; M [N·m, nose up]] = L [x; f] with η̈ of ẋ."""
        mm, n = self.matrices, self.n_modes
        v, rho = float(speed_m_s), float(density_kg_m3)
        q_pa = 0.5 * rho * v * v
        inc = strip_increments(self.geometry, n, v, rho, gust=True)
        nx, nf = self._x.size, len(INPUTS)
        ia, iq, ied = 1, 2, slice(4 + n, 4 + 2 * n)
        if np.any(inc.z_x[[0, 3]]) or np.any(inc.m_x[[0, 3]]) or np.any(inc.q_x[:, [0, 3]]):
            raise AssertionError("strip increments on u or θ: not a wing input")
        mi = mm.mass_kg_m2

        def inputs(x_rows, xd_rows, w_rows):
            """The columns of the body inputs α_i, q, α̇_i, q̇, w_g of a row (set)."""
            return np.stack([x_rows[..., ia], x_rows[..., iq], xd_rows[..., ia],
                             xd_rows[..., iq], np.asarray(w_rows, dtype=float)], axis=-1)

        # η̈ rows: (I − Q_η̈/m) η̈ = quasi-steady + increments on x, on α̇, q̇, and gust
        m_eta = np.eye(n) - inc.q_xd[:, ied] / mi[:, None]
        rhs_x = inc.q_x[:, 4:] / mi[:, None]
        rhs_x[:, :n] -= np.diag(mm.omega**2) - q_pa * mm.k_aero
        rhs_x[:, n:2 * n] -= np.diag(2.0 * mm.zeta * mm.omega) - (q_pa / v) * mm.d_aero
        rhs_f = np.zeros((n, nf))
        rhs_f[:, :3] = mm.forcing_columns()
        rhs_f[:, 3:] = inputs(inc.q_x, inc.q_xd, inc.q_w) / mi[:, None]
        a = np.zeros((nx, nx))
        b = np.zeros((nx, nf))
        a[:n, n:2 * n] = np.eye(n)
        a[n:2 * n] = np.linalg.solve(m_eta, rhs_x)
        b[n:2 * n] = np.linalg.solve(m_eta, rhs_f)
        lag = slice(2 * n, nx)
        a[lag] = inc.lag_a[:, 4:]
        b[lag, 3:] = np.column_stack([inc.lag_a[:, ia], inc.lag_a[:, iq],
                                      np.zeros((nx - 2 * n, 2)), inc.lag_b])
        loads = np.zeros((2, nx + nf))
        for r, (row_x, row_xd, row_w) in enumerate(((inc.z_x, inc.z_xd, inc.z_w),
                                                    (inc.m_x, inc.m_xd, inc.m_w))):
            loads[r, :nx] = row_x[4:] + row_xd[ied] @ a[n:2 * n]
            loads[r, nx + 3:] = inputs(row_x, row_xd, row_w)
            loads[r, nx:] += row_xd[ied] @ b[n:2 * n]
        return a, b, loads

    # -- reference step -------------------------------------------------------------------
    def _reference(self, q_pa: float, v_m_s: float) -> None:
        """Exact step at (Q_r, V_r) and the quadratics in V at ρ_r (module docstring), BLAS
        on one thread (as ModalWing's: on a loaded 2-core machine OpenBLAS's threads made a
        refresh of these 166-state matrices take 335-1550 ms instead of 54-113 ms)."""
        with one_blas_thread():
            self._compute_reference(q_pa, v_m_s)

    def _compute_reference(self, q_pa: float, v_m_s: float) -> None:
        rho = 2.0 * q_pa / (v_m_s * v_m_s)
        nodes = [c * v_m_s for c in FIT_SPEED_NODES]
        mats = [self.continuous(v, rho) for v in nodes]
        vander = np.vander(nodes, 3, increasing=True)  # rows [1, V, V²]
        inv = np.linalg.inv(vander)
        coef = [[sum(inv[p, j] * mats[j][i] for j in range(3)) for p in range(3)]
                for i in range(3)]  # coef[matrix][power]
        a_r, b_r = mats[1][0], mats[1][1]
        da_dv = coef[0][1] + 2.0 * v_m_s * coef[0][2]
        nx, nf = b_r.shape
        dt = self.dt_s
        aug = np.zeros((nx + 3 * nf, nx + 3 * nf))
        aug[:nx, :nx] = a_r
        for p in range(3):
            aug[:nx, nx + p * nf:nx + (p + 1) * nf] = coef[1][p]
        e = expm(aug * dt)
        self._phi = np.vstack([e[:nx, :nx],
                               expm_frechet(a_r * dt, da_dv * dt, compute_expm=False)])
        self._psi_b = [e[:nx, nx + p * nf:nx + (p + 1) * nf] for p in range(3)]  # Ψ_r B_p
        self._b_poly = coef[1]
        self._a_poly = coef[0]
        self._load_poly = coef[2]
        self._key = (float(q_pa), float(v_m_s))

    def prepare(self, flow: FlowState) -> None:
        """Compute the step's matrices for ``flow`` now (the first step would do it)."""
        self._reference(flow.dynamic_pressure_pa, flow.airspeed_m_s)

    def _inputs(self, flow: FlowState, gust_m_s: float) -> np.ndarray:
        q_pa, v = flow.dynamic_pressure_pa, flow.airspeed_m_s
        d_alpha = flow.alpha_rad - self.trim.alpha_rad
        alpha_i = d_alpha - gust_m_s / v
        if self._last is None:
            rates = (0.0, 0.0)
        else:
            rates = ((alpha_i - self._last[0]) / self.dt_s,
                     (flow.q_rad_s - self._last[1]) / self.dt_s)
        return np.array([q_pa * d_alpha, q_pa / v * flow.q_rad_s,
                         q_pa - self.trim.dynamic_pressure_pa, alpha_i, flow.q_rad_s,
                         rates[0], rates[1], gust_m_s])

    # -- the step -------------------------------------------------------------------------
    def step(self, flow: FlowState, gust_m_s: float = 0.0) -> None:
        """Advance η, η̇ and the lag states over one step with ``flow`` and the gust
        ``gust_m_s`` [m/s, up] held (zero-order hold)."""
        q_pa, v = flow.dynamic_pressure_pa, flow.airspeed_m_s
        key = self._key
        if (key is None or abs(q_pa - key[0]) > self.refresh_rel * abs(key[0])
                or abs(v - key[1]) > self.refresh_rel * abs(key[1])):
            self._reference(q_pa, v)
        f = self._inputs(flow, gust_m_s)
        nx = self._x.size
        y = self._phi @ self._x
        dv = v - self._key[1]
        p0, p1, p2 = self._psi_b
        self._x = y[:nx] + dv * y[nx:] + p0 @ f + v * (p1 @ f) + v * v * (p2 @ f)
        self._f = f
        self._last = (float(f[3]), float(f[4]))

    def loads(self, flow: FlowState, gust_m_s: float = 0.0) -> WingLoads:
        """Loads of the current state in ``flow`` with the gust ``gust_m_s`` [m/s, up] (the
        inputs of the last :meth:`step`; a wing not yet stepped takes them from ``flow``):
        ModalWing's modal loads plus the unsteady increments."""
        if self._key is None:
            self._reference(flow.dynamic_pressure_pa, flow.airspeed_m_s)
        f = self._f if self._last is not None else self._inputs(flow, gust_m_s)
        mm, n = self.matrices, self.n_modes
        ref = self.wing.airframe.reference  # S, c̄ of the wing's aircraft
        qs = flow.dynamic_pressure_pa * ref.area_m2
        rate = ref.mean_chord_m / (2.0 * flow.airspeed_m_s)
        eta, eta_dot = self._x[:n], self._x[n:2 * n]
        lift, drag, moment = qs * (mm.load_eta @ eta + rate * (mm.load_etadot @ eta_dot))
        v = flow.airspeed_m_s
        lp = self._load_poly
        xf = np.concatenate([self._x, f])
        z_inc, m_inc = (lp[0] + v * lp[1] + v * v * lp[2]) @ xf
        return WingLoads(float(lift - z_inc), float(drag - self._k2 * z_inc),
                         float(moment + m_inc))

    # -- state ----------------------------------------------------------------------------
    @property
    def eta(self) -> np.ndarray:
        """Modal coordinates Δη [rad] (perturbations from the static deformation at trim)."""
        return self._x[: self.n_modes]

    @eta.setter
    def eta(self, value) -> None:
        self._x = self._x.copy()
        self._x[: self.n_modes] = np.asarray(value, dtype=float)

    @property
    def eta_dot(self) -> np.ndarray:
        """Modal rates Δη̇ [rad/s]."""
        return self._x[self.n_modes: 2 * self.n_modes]

    @eta_dot.setter
    def eta_dot(self, value) -> None:
        self._x = self._x.copy()
        self._x[self.n_modes: 2 * self.n_modes] = np.asarray(value, dtype=float)

    @property
    def lag_states(self) -> dict[str, float]:
        """The aerodynamic lag states by name (:attr:`state_names`) [m/s]."""
        n2 = 2 * self.n_modes
        return dict(zip(self.state_names[n2:], self._x[n2:].tolist(), strict=True))

    @property
    def state(self) -> np.ndarray:
        """The whole state in :attr:`state_names` order (a copy)."""
        return self._x.copy()

    def tip_twist_rad(self, tip_twist_per_mode: np.ndarray) -> float:
        """Elastic tip twist Σ θ_i(b/2) Δη_i [rad], positive leading edge up."""
        return float(np.asarray(tip_twist_per_mode) @ self.eta)
