"""Both wing halves in the co-simulation: the antisymmetric modal wing beside the symmetric one.

**Representation.** The run flies the wing as its symmetric and antisymmetric parts: the
symmetric modal coordinates η_s (the half wing's clamped modes, Eq. 3,
:class:`~bioflex_jsb.simulation.modal_wing.ModalWing`, as before) and the antisymmetric ones
η_a (the beam with the fuselage's roll freedom, :mod:`bioflex_jsb.structures.antisymmetric`,
normalised as lateral_elastic's: max |twist| = 1 on the starboard half, tip twist positive).
A point of the starboard half at y moves by Σ φ^s_i(y) η_s,i + Σ φ^a_i(y) η_a,i, the mirror
point of the port half by Σ φ^s_i η_s,i − Σ φ^a_i η_a,i (the antisymmetric shapes change
sign across the centreline): port and starboard are the sum and the difference, logged as
the tip twists ``tip_twist_starboard_rad`` and ``tip_twist_port_rad`` [rad, leading edge up].

**The antisymmetric step** (:class:`AntisymmetricModalWing`; its compiled twin in
:mod:`bioflex_jsb.simulation.full_span_kernel`): the strips of
:mod:`bioflex_jsb.aeroelasticity.antisymmetric_strips` with the roll rate p of the snapshot,
the aileron deflection read from JSBSim each step (``fcs/left-aileron-pos-rad``,
``fcs/right-aileron-pos-rad``: δ_s = ½ (right − left)) and the gust roll rate p_g (an input,
0 unless a spanwise gust gives one); their modal equation

    η̈_a = −ω² η_a − 2ζω η̇_a + [Q F^η η_a + (Q/V) F^η̇ η̇_a + Q F^δ δ_s + (Q/V) F^p (p − p_g)] / m

is integrated as the symmetric one is (exact discretisation at a reference flow, its
first-order change with Q and Q/V by Fréchet derivatives, the reference renewed with the
symmetric wing's when the flow moves by more than ``refresh_rel``), the flow of t_k held over
the step; the rolling moment of η_{k+1} in that flow, ΔL = Q R^η η_a + (Q/V) R^η̇ η̇_a
[N·m, right wing down], goes to JSBSim's ``external_reactions/modal-roll`` for its step, as
the symmetric loads go to modal-lift, -drag, -pitch. ``qsd``: η_a the quasi-static balance of
the flow of t_k, η̇_a = 0; ``rigid``: no antisymmetric wing (η_a = 0, no moment).

**The loading** (the build's ``lateral_aero``, :mod:`bioflex_jsb.aerodynamics
.antisymmetric_loading`): the strips' C_lα c, or the vortex lattice's antisymmetric loading
of each distribution (p y/V, θ_a, φ_a, the aileron's, the sideslip's), folded into the
per-unit-flow matrices above (:class:`~bioflex_jsb.aeroelasticity.antisymmetric_strips
.AntisymmetricStrips`, :class:`~bioflex_jsb.aeroelasticity.antisymmetric_strips
.YawSideslipTerms`): the step and its kernel are the same either way.

No double count: the rigid wing's roll damping and the aileron's own rolling moment are
JSBSim's (C_lp, C_lδa in its rigid tables); ΔL is the lift of the deformation alone, which is
also how the aileron's loss of effectiveness (its twist of the wing) reaches the airframe.

**Yaw rate, sideslip, side force and yawing moment** (:class:`~bioflex_jsb.aeroelasticity
.antisymmetric_strips.YawSideslipTerms`). Each starboard strip at y has the lift
l(y) = l_r(y) + l_e(y): the rigid wing's, taken as the wing's lift L_w = n_z W (JSBSim's
load factor and weight: the wing carries the aircraft's normal load, the tail's share left
out) spread as the strips' additional loading a c(y) / (2 Σ a c w), and the symmetric
deflection's, l_e = Q a c θ_s η_s (η_s the trim's static deflection plus Δη_s). The port
strip mirrors it. First order in the lateral quantities:

* yaw rate r [rad/s, nose right]: the strip's airspeed is V − r y, its lift l (1 − 2 r y/V);
  the rolling moment of l_r (C_lr) is JSBSim's, the strips add that of l_e,
  ΔL_r = (4 Q r/V) Σ y² a c w θ_s η_s, and force the antisymmetric modes with all of it,
  −2 (r/V) Σ (e θ − φ) y l w;
* sideslip β [rad, wind from the right]: each half's angle of attack changes by ±β Γ(y)
  (starboard +), Γ the geometric dihedral less the bending slope of the symmetric
  deflection, Γ = Γ_g − dφ_s/dy η_s; the geometric part's rolling moment is JSBSim's
  (C_lβ), the strips add that of the bending slope, ΔL_β = 2 Q β Σ y a c w dφ_s/dy η_s, and
  force the modes with both;
* side force [N, body +y]: the lift of a half bent antisymmetrically leans with its local
  slope, Y = 2 L_w Σ s dφ_a/dy η_a (s a strip's share), and the deformation's own lift on
  the geometric dihedral, −2 Σ Δl_e Γ_g (a rigid wing's antisymmetric lift on its dihedral,
  C_Yp, is JSBSim's);
* yawing moment [N·m, body +z, nose right]: a strip's lift leans forward by its local
  upwash angle, the plunge rate φ_a η̇_a/V of the antisymmetric modes on the lift l,
  −2 (L_w/V) Σ s y φ_a η̇_a, and the roll rate's p y/V on l_e, −2 (Q p/V) Σ y² a c w θ_s η_s
  (the rigid lift's, C_np, is JSBSim's); and back by the trim's induced angle
  α_i = L_w/(Q π b²) (elliptic loading), the deformation's lift's induced drag,
  ΔN = −α_i ΔL (ΔL all the elastic rolling moment: less lift on a half, less drag there).

These go to JSBSim beside modal-roll: ΔL_r + ΔL_β into modal-roll, Y into ``modal-side``,
N into ``modal-yaw`` (external_reactions; N, N·m turned into lbf, lbf·ft at the boundary),
computed as ΔL with η_{k+1} in the flow, r, β and n_z of t_k; the forcing enters the modal
step as the aileron's does (held over the step). With nothing lateral (r = β = 0,
η_a = 0) every one is zero: the symmetric runs are unchanged. Left out: the side force's
moment arm (the wing's aerodynamic centre is taken at the CG, where the reaction acts),
the products of two lateral quantities (β η_a, r η_a: symmetric loads), the plunge rate of
the symmetric modes under r and β, the drag's own change with V − r y (C_nr of the rigid
drag is JSBSim's) and the change of the induced angle the deformation's lift makes (a
lattice term). The antisymmetric modes on unsteady strips:
:mod:`bioflex_jsb.simulation.unsteady_full_span`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg import expm, expm_frechet

from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    AntisymmetricStrips,
    YawSideslipTerms,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation.modal_wing import WING_MODELS, one_blas_thread

# The channels of a full-span run, after the half wing's (their meanings:
# simulation/channels.py describe)
LATERAL_FIXED = ("aileron_rad", "modal_roll_n_m", "tip_twist_starboard_rad",
                 "tip_twist_port_rad", "modal_side_n", "modal_yaw_n_m")


def lateral_names(n_modes: int) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(η_a names, η̇_a names) of ``n_modes`` antisymmetric modes: ``asym_eta1``…,
    ``asym_eta1_dot``… (not ``eta…``: the half wing's channels keep that prefix)."""
    return (tuple(f"asym_eta{i + 1}" for i in range(n_modes)),
            tuple(f"asym_eta{i + 1}_dot" for i in range(n_modes)))


def full_span_columns(names, n_modes: int) -> np.ndarray:
    """The row's columns (int64) of the compiled full-span step's channels, in the order
    its kernels write them: :data:`LATERAL_FIXED`, then η_a and η̇_a of ``n_modes``
    antisymmetric modes, as indices into the run's channel ``names``."""
    eta, eta_dot = lateral_names(n_modes)
    return np.array([list(names).index(c) for c in (*LATERAL_FIXED, *eta, *eta_dot)],
                    dtype=np.int64)


def joined_state(symmetric: np.ndarray, antisymmetric: np.ndarray
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Both wings' states end to end in one new array, as the compiled full-span step
    updates them in place: (the array, a view of its symmetric part, a view of its
    antisymmetric part), the views to stand for the wings' own states."""
    n = symmetric.size
    x = np.concatenate([symmetric, antisymmetric]).astype(float, copy=False)
    return x, x[:n], x[n:]


def lateral_channel_units(n_modes: int) -> dict[str, str]:
    """The full-span run's extra channels and their units, in the row's order."""
    eta, eta_dot = lateral_names(n_modes)
    units = {"aileron_rad": "rad", "modal_roll_n_m": "N*m", "tip_twist_starboard_rad": "rad",
             "tip_twist_port_rad": "rad", "modal_side_n": "N", "modal_yaw_n_m": "N*m"}
    units.update({n: "rad" for n in eta})
    units.update({n: "rad/s" for n in eta_dot})
    return units


@dataclass(frozen=True)
class LateralInputs:
    """What the antisymmetric strips see at t_k: ``p_rad_s`` the body roll rate [rad/s, right
    wing down], ``aileron_rad`` JSBSim's δa = ½ (δ_left − δ_right) [rad, + rolls right],
    ``p_g_rad_s`` the gust roll rate [rad/s] (antisymmetric_strips' sign); ``r_rad_s`` the
    yaw rate [rad/s, nose right], ``beta_rad`` the sideslip [rad, wind from the right],
    ``wing_lift_n`` the wing's lift n_z W [N], ``eta_s`` the symmetric modes' total
    deflection [rad] (static plus Δη_s; None: undeformed)."""

    p_rad_s: float
    aileron_rad: float
    p_g_rad_s: float = 0.0
    r_rad_s: float = 0.0
    beta_rad: float = 0.0
    wing_lift_n: float = 0.0
    eta_s: tuple | np.ndarray | None = None


class AntisymmetricModalWing:
    """The antisymmetric modal state [η_a, η̇_a] and its step (module docstring); the
    readable reference of the compiled kernel. ``model`` rigid, coupled or qsd (the run's);
    ``symmetric_tip_twist_rad`` (n_s,) the symmetric modes' tip twist per unit η_s [rad];
    ``terms`` the yaw rate's, sideslip's, side force's and yawing moment's (None: none)."""

    def __init__(self, strips: AntisymmetricStrips, model: str, dt_s: float,
                 symmetric_tip_twist_rad, refresh_rel: float = 0.05,
                 terms: YawSideslipTerms | None = None) -> None:
        if model not in WING_MODELS:
            raise InputError(f"unknown wing model {model!r}; accepted: {', '.join(WING_MODELS)}")
        self.strips = strips
        self.model = model
        self.dt_s = float(dt_s)
        self.refresh_rel = float(refresh_rel)
        self.n_modes = strips.n_modes
        self.symmetric_tip_twist_rad = np.asarray(symmetric_tip_twist_rad, dtype=float)
        self._x = np.zeros(2 * self.n_modes)
        self._key: tuple[float, float] | None = None
        self._stack = np.zeros((6 * self.n_modes, 2 * self.n_modes))
        self._input_cols = np.zeros((2 * self.n_modes, 2))
        self.terms = terms
        # [η_a, η̇_a]_{k+1} per unit generalised force held over the step [1/(N·m)]
        self._force_map = np.zeros((2 * self.n_modes, self.n_modes))

    @property
    def eta(self) -> np.ndarray:
        """η_a [rad]."""
        return self._x[:self.n_modes]

    @property
    def eta_dot(self) -> np.ndarray:
        """η̇_a [rad/s]."""
        return self._x[self.n_modes:]

    def reference(self, q_pa: float, v_m_s: float) -> None:
        """Exact discretisation at (Q_r, V_r): Φ, its change per unit Q and Q/V (Fréchet
        derivatives along ∂A/∂Q, ∂A/∂(Q/V)) and Ψ B (ModalWing._compute_reference's)."""
        with one_blas_thread():
            s, n = self.strips, self.n_modes
            n2 = 2 * n
            a = s.a_matrix(q_pa, q_pa / v_m_s)
            aug = np.zeros((2 * n2, 2 * n2))
            aug[:n2, :n2] = a
            aug[:n2, n2:] = np.eye(n2)
            e = expm(aug * self.dt_s)
            phi, psi = e[:n2, :n2], e[:n2, n2:]
            zeros = np.zeros((n, n))
            m = s.mass_kg_m2[:, None]
            d_q = np.block([[zeros, zeros], [s.force_eta / m, zeros]])
            d_qv = np.block([[zeros, zeros], [zeros, s.force_etadot / m]])
            self._stack = np.vstack([
                phi,
                expm_frechet(a * self.dt_s, d_q * self.dt_s, compute_expm=False),
                expm_frechet(a * self.dt_s, d_qv * self.dt_s, compute_expm=False)])
            self._input_cols = psi @ s.forcing_columns()
            self._force_map = psi[:, n:] / s.mass_kg_m2[None, :]
            self._key = (float(q_pa), float(v_m_s))

    def needs_reference(self, q_pa: float, v_m_s: float) -> bool:
        """Whether the flow (Q, V) lies beyond the reference (ModalWing's rule)."""
        key = self._key
        return (key is None or abs(q_pa - key[0]) > self.refresh_rel * abs(key[0])
                or abs(v_m_s - key[1]) > self.refresh_rel * abs(key[1]))

    def step(self, q_pa: float, v_m_s: float, inputs: LateralInputs) -> None:
        """[η_a, η̇_a]_k → _{k+1} with the flow of t_k held (module docstring)."""
        if self.model == "rigid":
            return
        qv = q_pa / v_m_s
        delta_s = -inputs.aileron_rad
        rel_p = inputs.p_rad_s - inputs.p_g_rad_s
        force = self.forcing_n_m(q_pa, v_m_s, inputs)
        if self.model == "qsd":
            s = self.strips
            k = np.diag(s.mass_kg_m2 * s.omega_rad_s**2) - q_pa * s.force_eta
            eta = s.quasi_static_eta(q_pa, qv, delta_s, rel_p)
            if force is not None:
                eta = eta + np.linalg.solve(k, force)
            self._x = np.concatenate([eta, np.zeros(self.n_modes)])
            return
        if self.needs_reference(q_pa, v_m_s):
            self.reference(q_pa, v_m_s)
        q_r, v_r = self._key
        n2 = 2 * self.n_modes
        y = self._stack @ self._x
        f = np.array([q_pa * delta_s, qv * rel_p])
        self._x = (y[:n2] + (q_pa - q_r) * y[n2:2 * n2] + (qv - q_r / v_r) * y[2 * n2:]
                   + self._input_cols @ f)
        if force is not None:
            self._x = self._x + self._force_map @ force

    def forcing_n_m(self, q_pa: float, v_m_s: float, inputs: LateralInputs):
        """The yaw rate's and sideslip's generalised force on the modes [N·m] (None: no
        terms)."""
        if self.terms is None:
            return None
        return self.terms.forcing(q_pa, v_m_s, inputs.wing_lift_n, inputs.r_rad_s,
                                  inputs.beta_rad, self._symmetric(inputs.eta_s))

    def _symmetric(self, eta_s) -> np.ndarray:
        n_s = self.symmetric_tip_twist_rad.size
        return np.zeros(n_s) if eta_s is None else np.asarray(eta_s, dtype=float)

    def reactions(self, q_pa: float, v_m_s: float, inputs: LateralInputs
                  ) -> tuple[float, float, float]:
        """(rolling moment [N·m, right wing down], side force [N, body +y], yawing moment
        [N·m, nose right]) of the current state in the flow (Q, V) and ``inputs`` (its
        ``eta_s`` the symmetric deflection of the same instant): ΔL, plus the yaw rate's and
        sideslip's, and the side force and yawing moment (module docstring)."""
        roll = self.roll_moment_n_m(q_pa, v_m_s)
        t = self.terms
        if self.model == "rigid" or t is None:
            return roll, 0.0, 0.0
        eta_s = self._symmetric(inputs.eta_s)
        roll += t.roll_n_m(q_pa, v_m_s, inputs.r_rad_s, inputs.beta_rad, eta_s)
        side = t.side_n(q_pa, v_m_s, inputs.wing_lift_n, self.eta, self.eta_dot)
        yaw = t.yaw_n_m(q_pa, v_m_s, inputs.wing_lift_n, inputs.p_rad_s, self.eta_dot, eta_s,
                        roll)
        return roll, side, yaw

    def roll_moment_n_m(self, q_pa: float, v_m_s: float) -> float:
        """ΔL of the current state in the flow (Q, V) [N·m, right wing down]."""
        if self.model == "rigid":
            return 0.0
        s = self.strips
        return float(q_pa * (s.roll_eta @ self.eta) + q_pa / v_m_s * (s.roll_etadot @ self.eta_dot))

    def row(self, aileron_rad: float, moment_n_m: float, eta_a, eta_a_dot, eta_s,
            side_n: float = 0.0, yaw_n_m: float = 0.0) -> dict:
        """The extra channels of a row: the aileron δa, the moment applied over the step,
        the tip twists and η_a, η̇_a of t_k (before the step), η_s of t_k, the side force and
        yawing moment applied over the step."""
        sym = float(self.symmetric_tip_twist_rad @ np.asarray(eta_s, dtype=float))
        anti = float(self.strips.tip_twist_rad @ np.asarray(eta_a, dtype=float))
        eta, eta_dot = lateral_names(self.n_modes)
        row = {"aileron_rad": aileron_rad, "modal_roll_n_m": moment_n_m,
               "tip_twist_starboard_rad": sym + anti, "tip_twist_port_rad": sym - anti,
               "modal_side_n": side_n, "modal_yaw_n_m": yaw_n_m}
        row.update(zip(eta, (float(v) for v in eta_a), strict=True))
        row.update(zip(eta_dot, (float(v) for v in eta_a_dot), strict=True))
        return row


AILERON_INPUTS = ("step", "doublet")


@dataclass(frozen=True)
class AileronInput:
    """An aileron input over the trim for a full-span run: ``kind`` ``step`` (δa from
    ``start_s`` on) or ``doublet`` (δa for ``width_s``, then −δa for ``width_s``, then 0);
    ``angle_rad`` δa [rad, JSBSim's ½ (left − right), + rolls right]; ``start_s`` [s]."""

    kind: str
    angle_rad: float
    start_s: float
    width_s: float = 0.5

    def __post_init__(self) -> None:
        if self.kind not in AILERON_INPUTS:
            raise InputError(f"unknown aileron input {self.kind!r}; accepted: "
                             f"{', '.join(AILERON_INPUTS)}")
        for name in ("angle_rad", "start_s", "width_s"):
            if not np.isfinite(getattr(self, name)):
                raise InputError(f"aileron input {name} must be finite")
        if self.start_s < 0.0 or self.width_s <= 0.0:
            raise InputError("aileron input: need start_s >= 0 s and width_s > 0 s")

    def changes(self, dt_s: float) -> dict[int, float]:
        """{step number: δa over the trim [rad] from that step on}."""
        k0 = int(round(self.start_s / dt_s))
        if self.kind == "step":
            return {k0: self.angle_rad}
        k1 = k0 + max(1, int(round(self.width_s / dt_s)))
        k2 = k1 + max(1, int(round(self.width_s / dt_s)))
        return {k0: self.angle_rad, k1: -self.angle_rad, k2: 0.0}

    def as_dict(self) -> dict:
        return {"kind": self.kind, "angle_rad": self.angle_rad, "start_s": self.start_s,
                "width_s": self.width_s}


def prototype_aileron(variant_name: str):
    """The aileron of the prototype's wing variant ``variant_name`` (its shipped definition
    ``bioflex_<variant>``'s ``[aileron]``, an estimate: the paper gives none), or None when
    there is no such definition (a modal-data wing) or it has no aileron."""
    from bioflex_jsb.definition.aircraft import load_aircraft
    from bioflex_jsb.definition.flying import SHIPPED_AIRCRAFT

    name = f"bioflex_{variant_name}"
    if name not in SHIPPED_AIRCRAFT:
        return None
    return load_aircraft(name).definition.aileron
