"""Both wing halves on unsteady strips: the antisymmetric modal wing with Theodorsen's section
beyond the quasi-steady strips, for the full-span co-simulation step with ``aero="unsteady"``.

**Representation.** As the quasi-steady full-span step (:mod:`bioflex_jsb.simulation
.full_span`): symmetric and antisymmetric combinations. The symmetric half of the wing is
the half wing's unsteady wing (:class:`~bioflex_jsb.simulation.unsteady_wing
.UnsteadyModalWing`: its modes, their Jones lag states, apparent mass and Küssner gust states
on the starboard strips); the antisymmetric half is this module's: the antisymmetric modes
η_a, η̇_a and their own lag states ``lag1[k]``, ``lag2[k]`` [m/s] per starboard strip k. A
port strip's lag state is the symmetric one minus the antisymmetric one, a starboard strip's
their sum (the lags are linear in the upwash, which splits the same way).

**The increments** are those of the linear unsteady lateral model
(:func:`~bioflex_jsb.aeroelasticity.antisymmetric.unsteady_lateral_model`), the same rows of
:func:`~bioflex_jsb.aeroelasticity.antisymmetric.strip_loads` (the same Jones coefficients,
the same apparent mass): the circulatory lift through the lags on the three-quarter-chord
upwash minus the quasi-steady lift, and the apparent mass on the heave acceleration
ḧ = ṗ y + Σ φ_i η̈_i and the pitch Σ θ_i η_i. The strips' roll rate is p − p_g (the gust roll
rate: the upwash of a linear spanwise gust, antisymmetric_strips' sign) in every upwash; the
apparent mass acts on the body's roll acceleration ṗ alone, a backward difference of the
snapshots' p over the last step (as the half wing's unsteady step takes q̇; zero at the first
step). The apparent mass of the modes' own acceleration is implicit (on the left of
E ż = N z + …, then E⁻¹); that of ṗ, the wing's apparent roll inertia, acts explicitly
through the ṗ of the last step, as JSBSim integrates the roll. With ``unsteadiness`` 0 the
increments vanish, the lags only listen (block triangular) and the step is the quasi-steady
full-span step's to round-off.

**The modal equation** (z = [η_a, η̇_a, lag1, lag2])

    E ż = N(Q, Q/V) z + n_p (p − p_g) + n_ṗ ṗ + [0; Q F^δ δ_s + F^{r,β}; 0] / m

(N: the quasi-steady strips' rows of :class:`~bioflex_jsb.aeroelasticity
.antisymmetric_strips.AntisymmetricStrips` plus the increments) is integrated as the
quasi-steady one: exact discretisation at a reference flow (Q_r, Q_r/V_r), its first-order
change with Q and Q/V by Fréchet derivatives of the exponential along ∂A/∂Q, ∂A/∂(Q/V)
(the quasi-steady rows' exactly, the increments' by central differences), the input
columns and load rows likewise to first order about the reference, renewed with the
symmetric wing's when the flow moves by more than ``refresh_rel``.

**Loads to JSBSim.** The rolling moment ΔL of the quasi-steady step (η_{k+1} in the flow) plus
the increments' ΔL_u = −2 Σ Δl y w (their lift on both halves, with η̈_{k+1} of the held
inputs and the last step's ṗ); the side force plus the increments' lift on the geometric
dihedral, −2 Σ Δl Γ_g w; the yawing moment with the induced drag of all the elastic rolling
moment, −α_i (ΔL + ΔL_u) (:mod:`~bioflex_jsb.simulation.full_span`, "Yaw rate, sideslip,
side force and yawing moment"). The linear unsteady lateral model carries the same three.

This is the readable reference; the co-simulation runs the same arithmetic compiled
(:mod:`bioflex_jsb.simulation.unsteady_full_span_kernel`, held to it by
tests/test_unsteady_full_span.py).
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm, expm_frechet

from bioflex_jsb.aeroelasticity.antisymmetric import Layout, lag_names, strip_loads
from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    AntisymmetricStrips,
    YawSideslipTerms,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.full_span import AntisymmetricModalWing, LateralInputs
from bioflex_jsb.simulation.modal_wing import one_blas_thread

# Relative step of the central differences of the increments' rows in Q and Q/V. ESTIMATE:
# the rows are smooth (polynomials in ρ = 2 (Q/V)²/Q and V = Q/(Q/V)); at 1e-5 the
# truncation (~1e-10 relative) and the round-off (~1e-11) stay far below the first-order
# expansion's own error over a 5 % refresh band (~1e-3).
DIFF_REL = 1e-5


class UnsteadyAntisymmetricWing(AntisymmetricModalWing):
    """The antisymmetric modal wing on unsteady strips (module docstring); model ``coupled``
    only. ``strips`` the quasi-steady strips per unit flow (the full-span step's);
    ``sections`` the same strips' physical section
    (:func:`~bioflex_jsb.aeroelasticity.antisymmetric.aircraft_strips`: chord, elastic axis,
    three-quarter-chord point, dihedral; the linear unsteady model's); ``unsteadiness``
    (0 … 1) scales the increments as the linear model's does."""

    def __init__(self, strips: AntisymmetricStrips, sections, model: str, dt_s: float,
                 symmetric_tip_twist_rad, refresh_rel: float = 0.05,
                 terms: YawSideslipTerms | None = None, unsteadiness: float = 1.0) -> None:
        if model != "coupled":
            raise InputError(f"the unsteady antisymmetric strips are the coupled wing's, not "
                             f"{model!r}")
        super().__init__(strips, model, dt_s, symmetric_tip_twist_rad, refresh_rel, terms)
        if sections.n_modes != strips.n_modes:
            raise ValueError(f"the sections carry {sections.n_modes} modes, the strips "
                             f"{strips.n_modes}")
        self.sections = sections
        self.unsteadiness = float(unsteadiness)
        k = sections.n_strips
        self.n_strips = k
        n = self.n_modes
        self.n_states = 2 * n + 2 * k
        self.state_names = (tuple(f"asym_eta{i + 1}" for i in range(n))
                            + tuple(f"asym_eta{i + 1}_dot" for i in range(n)) + lag_names(k))
        self._x = np.zeros(self.n_states)
        # z and the two inputs p − p_g, ṗ in strip_loads' layout: p − p_g the last column
        self._layout = Layout(self.n_states + 1, self.n_states, slice(0, n), slice(n, 2 * n),
                              (slice(2 * n, 2 * n + k), slice(2 * n + k, 2 * n + 2 * k)))
        self._last_p: float | None = None
        self._u = np.zeros(n + 2)  # the held inputs of the last step [p − p_g, ṗ, g]

    # -- the continuous system -------------------------------------------------------------
    def continuous(self, q_pa: float, q_over_v: float) -> dict[str, np.ndarray]:
        """The system at Q [Pa] and Q/V [Pa·s/m]: ``a`` (n_z × n_z) and ``b`` (n_z × (n + 2),
        columns p − p_g [rad/s], ṗ [rad/s²], the generalised force on each mode [N·m]) of
        ż = a z + b u; ``rows`` (3 × (n_z + n + 2)): the increments' rolling moment [N·m,
        right wing down], side force [N, body +y] and nothing (0) on [z, u] with η̈ of ż
        folded in (ż = a z + b u)."""
        s, n, nz = self.strips, self.n_modes, self.n_states
        v = q_pa / q_over_v
        rho = 2.0 * q_over_v**2 / q_pa
        lay = self._layout
        loads = strip_loads(self.sections, lay, v, rho, quasi_steady=False, unsteady=True,
                            unsteadiness=self.unsteadiness)
        m = s.mass_kg_m2[:, None]
        rhs = np.zeros((nz, nz + 2 + n))
        rhs[:2 * n, :2 * n] = s.a_matrix(q_pa, q_over_v)
        rhs[n:2 * n, nz] = q_over_v * s.force_p / s.mass_kg_m2
        rhs[n:2 * n, :nz + 1] += loads.force_x / m
        rhs[n:2 * n, nz + 1] = loads.force_xd[:, nz] / s.mass_kg_m2  # ṗ's apparent mass
        rhs[n:2 * n, nz + 2:] = np.diag(1.0 / s.mass_kg_m2)
        rhs[2 * n:, :nz + 1] = loads.lag_a
        e = np.eye(nz)
        e[n:2 * n, n:2 * n] -= loads.force_xd[:, n:2 * n] / m
        ab = np.linalg.solve(e, rhs)
        a, b = ab[:, :nz], ab[:, nz:]
        # the loads on [z, p − p_g, ṗ, g] with η̈ = (a z + b u)[η̇ rows]
        rows = np.zeros((3, nz + 2 + n))
        for i, (x_row, xd_row) in enumerate(((loads.roll_x, loads.roll_xd),
                                             (loads.side_x, loads.side_xd))):
            rows[i, :nz + 1] = x_row
            rows[i, nz + 1] += xd_row[nz]
            rows[i] += xd_row[n:2 * n] @ ab[n:2 * n]
        return {"a": a, "b": b, "rows": rows}

    def _derivatives(self, q_pa: float, q_over_v: float) -> tuple[dict, dict, dict]:
        """The system at (Q, Q/V) and its derivatives per unit Q and Q/V: the
        quasi-steady rows exactly (they are linear in Q and Q/V), the increments by central
        differences (:data:`DIFF_REL`)."""
        here = self.continuous(q_pa, q_over_v)

        def diff(dq: float, ds: float, h: float) -> dict:
            up = self.continuous(q_pa + dq, q_over_v + ds)
            down = self.continuous(q_pa - dq, q_over_v - ds)
            return {key: (up[key] - down[key]) / (2.0 * h) for key in here}

        hq, hs = DIFF_REL * q_pa, DIFF_REL * q_over_v
        d_q, d_s = diff(hq, 0.0, hq), diff(0.0, hs, hs)
        # the quasi-steady rows' exact derivatives in place of their differences where the
        # increments are zero (unsteadiness 0): no round-off left in the quasi-steady step
        s, n = self.strips, self.n_modes
        if self.unsteadiness == 0.0:
            for d in (d_q, d_s):
                d["a"][:2 * n, :2 * n] = 0.0
                d["b"][:2 * n] = 0.0
            d_q["a"][n:2 * n, :n] = s.force_eta / s.mass_kg_m2[:, None]
            d_s["a"][n:2 * n, n:2 * n] = s.force_etadot / s.mass_kg_m2[:, None]
            d_s["b"][n:2 * n, 0] = s.force_p / s.mass_kg_m2
        return here, d_q, d_s

    def reference(self, q_pa: float, v_m_s: float) -> None:
        """Exact discretisation at (Q_r, V_r) and its first-order change in Q and Q/V (module
        docstring)."""
        with one_blas_thread():
            qv = q_pa / v_m_s
            here, d_q, d_s = self._derivatives(q_pa, qv)
            a, nz = here["a"], self.n_states
            aug = np.zeros((2 * nz, 2 * nz))
            aug[:nz, :nz] = a
            aug[:nz, nz:] = np.eye(nz)
            e = expm(aug * self.dt_s)
            phi, psi = e[:nz, :nz], e[:nz, nz:]
            self._stack = np.vstack([
                phi,
                expm_frechet(a * self.dt_s, d_q["a"] * self.dt_s, compute_expm=False),
                expm_frechet(a * self.dt_s, d_s["a"] * self.dt_s, compute_expm=False)])
            self._psi_b = np.stack([psi @ here["b"], psi @ d_q["b"], psi @ d_s["b"]])
            self._continuous = (here, d_q, d_s)
            self._key = (float(q_pa), float(v_m_s))

    def _at(self, name: str, q_pa: float, q_over_v: float) -> np.ndarray:
        """The continuous system's ``name`` at (Q, Q/V), first order about the reference."""
        here, d_q, d_s = self._continuous
        q_r, v_r = self._key
        return here[name] + (q_pa - q_r) * d_q[name] + (q_over_v - q_r / v_r) * d_s[name]

    def inputs(self, q_pa: float, v_m_s: float, inputs: LateralInputs) -> np.ndarray:
        """The held inputs u = [p − p_g, ṗ, generalised force per mode] of a step."""
        p = float(inputs.p_rad_s)
        p_dot = 0.0 if self._last_p is None else (p - self._last_p) / self.dt_s
        force = q_pa * self.strips.force_delta * (-inputs.aileron_rad)
        extra = self.forcing_n_m(q_pa, v_m_s, inputs)
        if extra is not None:
            force = force + extra
        return np.concatenate([[p - inputs.p_g_rad_s, p_dot], force])

    def step(self, q_pa: float, v_m_s: float, inputs: LateralInputs) -> None:
        """[η_a, η̇_a, lags]_k → _{k+1} with the flow and inputs of t_k held."""
        if self.needs_reference(q_pa, v_m_s):
            self.reference(q_pa, v_m_s)
        q_r, v_r = self._key
        u = self.inputs(q_pa, v_m_s, inputs)
        nz = self.n_states
        dq, ds = q_pa - q_r, q_pa / v_m_s - q_r / v_r
        y = self._stack @ self._x
        p0, p1, p2 = self._psi_b
        self._x = (y[:nz] + dq * y[nz:2 * nz] + ds * y[2 * nz:] + p0 @ u + dq * (p1 @ u)
                   + ds * (p2 @ u))
        self._u = u
        self._last_p = float(inputs.p_rad_s)

    def increment_loads(self, q_pa: float, v_m_s: float) -> tuple[float, float]:
        """(rolling moment [N·m, right wing down], side force [N, body +y]) of the unsteady
        increments on the current state with the last step's inputs, in the flow (Q, V)."""
        if self._key is None:
            return 0.0, 0.0
        rows = self._at("rows", q_pa, q_pa / v_m_s)
        zu = np.concatenate([self._x, self._u])
        return float(rows[0] @ zu), float(rows[1] @ zu)

    def reactions(self, q_pa: float, v_m_s: float, inputs: LateralInputs
                  ) -> tuple[float, float, float]:
        """(rolling moment, side force, yawing moment) as the quasi-steady wing's, with the
        increments' rolling moment and side force added and the induced drag of all the
        elastic rolling moment in the yawing moment (module docstring)."""
        roll_u, side_u = self.increment_loads(q_pa, v_m_s)
        roll = self.roll_moment_n_m(q_pa, v_m_s) + roll_u
        t = self.terms
        if t is None:
            return roll, side_u, 0.0
        eta_s = self._symmetric(inputs.eta_s)
        roll += t.roll_n_m(q_pa, v_m_s, inputs.r_rad_s, inputs.beta_rad, eta_s)
        side = t.side_n(q_pa, v_m_s, inputs.wing_lift_n, self.eta, self.eta_dot) + side_u
        yaw = t.yaw_n_m(q_pa, v_m_s, inputs.wing_lift_n, inputs.p_rad_s, self.eta_dot, eta_s,
                        roll)
        return roll, side, yaw

    @property
    def eta_dot(self) -> np.ndarray:
        """η̇_a [rad/s]."""
        return self._x[self.n_modes:2 * self.n_modes]

    @property
    def lag_states(self) -> np.ndarray:
        """The lag states lag1[k], lag2[k] [m/s] (antisymmetric part, starboard strips)."""
        return self._x[2 * self.n_modes:]
