"""Strip theory on beam modes: generalised aerodynamic forces, frequency and time domain.

Each strip k of a :class:`~bioflex_jsb.aeroelasticity.clamped_wing.ClampedWingModel` carries
Theodorsen's section loads (:mod:`bioflex_jsb.aerodynamics.theodorsen`) on the local heave
h_k = Σ_i heave_m[i, k] η_i (down) and pitch α_k = Σ_i pitch_rad[i, k] η_i (leading edge up),
η the modal coordinates. Virtual work gives the generalised forces on η:

    Q_aero = Σ_k w_k T_kᵀ (−L'_k, M'_k),       T_k = [heave_m[:, k]; pitch_rad[:, k]] (2, n)

In matrix form (n modes, K strips):

    Q_aero = −M_a η̈ − B_a η̇ + D · diag(C(k_k)) · (W η + E η̇)

with M_a, B_a (n, n) the apparent mass and damping, D (n, K) the circulatory force of a unit
three-quarter-chord upwash on each strip, W and E (K, n) the upwash [m/s] of each strip per
unit η and η̇. Theodorsen's C(k) makes it the frequency-domain model (p-k); Jones's
finite-state form (:func:`bioflex_jsb.aerodynamics.indicial.strip_state_space`, two lag
states per strip, plus two Küssner gust states per strip if asked) the time-domain one.
``aero="quasi-steady"`` sets C = 1 (apparent mass and three-quarter-chord upwash kept).
A vertical gust w_g [m/s] (up) is taken to reach every strip's leading edge at the same time
(unswept wing); Sears' function / Küssner's states lag its lift.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.aerodynamics.indicial import jones_c, strip_state_space
from bioflex_jsb.aerodynamics.theodorsen import sears_s, section_matrices, theodorsen_c
from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.state_space import StateSpace, with_motion_inputs

AERO_MODELS = ("unsteady", "quasi-steady")


def check_aero(aero: str) -> str:
    if aero not in AERO_MODELS:
        raise ValueError(f"aero must be one of {AERO_MODELS}, not {aero!r}")
    return aero


@dataclass(frozen=True, eq=False)
class ModalStripMatrices:
    """The speed-dependent matrices of the module docstring at one airspeed and density.

    apparent_mass M_a, apparent_damping B_a (n, n); force D (n, K); upwash_displacement W
    and upwash_rate E (K, n); semichord_m (K,); speed_m_s, density_kg_m3.
    """

    apparent_mass: np.ndarray
    apparent_damping: np.ndarray
    force: np.ndarray
    upwash_displacement: np.ndarray
    upwash_rate: np.ndarray
    semichord_m: np.ndarray
    speed_m_s: float
    density_kg_m3: float


def _transforms(model: ClampedWingModel) -> list[np.ndarray]:
    return [np.vstack([model.heave_m[:, k], model.pitch_rad[:, k]])
            for k in range(model.stations_m.size)]


def modal_strip_matrices(
    model: ClampedWingModel, *, speed_m_s: float, density_kg_m3: float
) -> ModalStripMatrices:
    """Project every strip's Theodorsen matrices onto the modes (module docstring)."""
    n, k_strips = model.n_modes, model.stations_m.size
    m_a = np.zeros((n, n))
    b_a = np.zeros((n, n))
    d = np.zeros((n, k_strips))
    w_up = np.zeros((k_strips, n))
    e_up = np.zeros((k_strips, n))
    for k, t in enumerate(_transforms(model)):
        sec = section_matrices(
            speed_m_s=speed_m_s, semichord_m=model.semichord_m[k],
            elastic_axis_a=model.elastic_axis_a[k], density_kg_m3=density_kg_m3,
            lift_slope_per_rad=model.lift_slope_per_rad[k],
        )
        wk = model.weights_m[k]
        m_a += wk * t.T @ sec.apparent_mass @ t
        b_a += wk * t.T @ sec.apparent_damping @ t
        d[:, k] = wk * t.T @ sec.force_vector
        w_up[k] = sec.upwash_displacement @ t
        e_up[k] = sec.upwash_rate @ t
    return ModalStripMatrices(m_a, b_a, d, w_up, e_up, np.asarray(model.semichord_m, float),
                              float(speed_m_s), float(density_kg_m3))


def circulation_functions(
    matrices: ModalStripMatrices, frequency_rad_s: float, aero: str, *, jones: bool = False
) -> np.ndarray:
    """C(k) of every strip [-] at ω [rad/s] (1 for quasi-steady; Jones's fit if ``jones``)."""
    if check_aero(aero) == "quasi-steady":
        return np.ones(matrices.semichord_m.size, dtype=complex)
    k = abs(frequency_rad_s) * matrices.semichord_m / matrices.speed_m_s
    c = jones_c(k) if jones else np.asarray(theodorsen_c(k), dtype=complex)
    return np.conj(c) if frequency_rad_s < 0.0 else c


def generalised_aero_matrix(
    matrices: ModalStripMatrices, frequency_rad_s: float, aero: str = "unsteady",
    *, jones: bool = False,
) -> np.ndarray:
    """Complex (n, n) Q(ω): generalised aerodynamic forces per unit harmonic η̄ at ω [rad/s].

    Q(ω) = ω² M_a − iω B_a + D diag(C) (W + iω E); units of the modal stiffness.
    """
    w = float(frequency_rad_s)
    c = circulation_functions(matrices, w, aero, jones=jones)
    upwash = matrices.upwash_displacement + 1j * w * matrices.upwash_rate
    return (w * w * matrices.apparent_mass - 1j * w * matrices.apparent_damping
            + matrices.force @ (c[:, None] * upwash))


def gust_force_vector(matrices: ModalStripMatrices, frequency_rad_s: float) -> np.ndarray:
    """Complex (n,) generalised forces per unit harmonic gust w̄_g [m/s] at the leading edge.

    Sears' function referred to the leading edge (the gust's phase where it meets the wing).
    """
    k = abs(frequency_rad_s) * matrices.semichord_m / matrices.speed_m_s
    s = np.asarray(sears_s(k, reference="leading-edge"), dtype=complex)
    s = np.conj(s) if frequency_rad_s < 0.0 else s
    return matrices.force @ s


@dataclass(frozen=True, eq=False)
class ModalAeroStateSpace:
    """Finite-state generalised aerodynamic forces of the wing on its modal coordinates η.

        ẋ = A x + B_q η + B_qd η̇ + B_g w_g
        Q_aero = C x + D_q η + D_qd η̇ − M_a η̈ + D_g w_g

    ``state_names`` / ``state_units`` name every lag state (``wagner_lag_1_m[k]`` …, [m]).
    The structural model adds M_a to its modal mass (see
    :mod:`bioflex_jsb.aeroelasticity.state_space`).
    """

    a: np.ndarray
    b_q: np.ndarray
    b_qd: np.ndarray
    b_g: np.ndarray
    c: np.ndarray
    d_q: np.ndarray
    d_qd: np.ndarray
    d_g: np.ndarray
    apparent_mass: np.ndarray
    state_names: tuple[str, ...] = field(default=())
    state_units: tuple[str, ...] = field(default=())
    speed_m_s: float | None = None  # [m/s] the airspeed it was built at

    @property
    def n_states(self) -> int:
        return int(self.a.shape[0])

    def force_matrix(self, frequency_rad_s: float) -> np.ndarray:
        """Complex (n, n) frequency response, comparable with :func:`generalised_aero_matrix`."""
        iw = 1j * float(frequency_rad_s)
        out = self.d_q + iw * self.d_qd - iw * iw * self.apparent_mass
        if self.n_states:
            res = np.linalg.solve(iw * np.eye(self.n_states) - self.a, self.b_q + iw * self.b_qd)
            out = out + self.c @ res
        return out

    def to_state_space(self) -> StateSpace:
        """These forces as the package's :class:`~bioflex_jsb.state_space.StateSpace`
        (``speed_m_s`` set: :func:`finite_state_model`'s): inputs (η_i [kg^½·m], the M-orthonormal
        modal coordinates of :mod:`~bioflex_jsb.aeroelasticity.clamped_wing`, their rates and
        accelerations, w_g [m/s]), outputs ``Q_i`` the generalised aerodynamic forces
        [kg^½·m/s²] (:func:`~bioflex_jsb.state_space.with_motion_inputs`)."""
        if self.speed_m_s is None:
            raise ValueError("ModalAeroStateSpace.to_state_space needs speed_m_s (the airspeed "
                             "the forces were built at)")
        n = int(self.apparent_mass.shape[0])
        return with_motion_inputs("modal-aero", self.speed_m_s, self,
                                  tuple(f"eta_{i + 1}" for i in range(n)), ("kg^0.5 m",) * n,
                                  tuple(f"Q_{i + 1}" for i in range(n)),
                                  ("kg^0.5 m/s^2",) * n)


def finite_state_model(
    model: ClampedWingModel, *, speed_m_s: float, density_kg_m3: float,
    aero: str = "unsteady", gust: bool = False,
) -> ModalAeroStateSpace:
    """The wing's :class:`ModalAeroStateSpace` at ``speed_m_s`` [m/s].

    ``aero="unsteady"``: Jones's Wagner states on every strip (and Küssner's if ``gust``);
    ``aero="quasi-steady"``: no lag states, C = 1 (a gust then acts without lag).
    """
    n = model.n_modes
    m_a = np.zeros((n, n))
    d_q = np.zeros((n, n))
    d_qd = np.zeros((n, n))
    d_g = np.zeros(n)
    blocks = []
    for k, t in enumerate(_transforms(model)):
        ss = strip_state_space(
            speed_m_s=speed_m_s, semichord_m=model.semichord_m[k],
            elastic_axis_a=model.elastic_axis_a[k], density_kg_m3=density_kg_m3,
            lift_slope_per_rad=model.lift_slope_per_rad[k], gust=gust, strip_label=f"[{k}]",
        )
        wk = model.weights_m[k]
        m_a += wk * t.T @ ss.apparent_mass @ t
        if check_aero(aero) == "quasi-steady":
            sec = ss.section
            d_q += wk * t.T @ np.outer(sec.force_vector, sec.upwash_displacement) @ t
            d_qd += wk * t.T @ (np.outer(sec.force_vector, sec.upwash_rate)
                                - sec.apparent_damping) @ t
            d_g += wk * t.T @ (sec.force_vector * sec.gust_vector) if gust else 0.0
            continue
        d_q += wk * t.T @ ss.d_q @ t
        d_qd += wk * t.T @ ss.d_qd @ t
        d_g += wk * t.T @ ss.d_g
        blocks.append((ss.a, ss.b_q @ t, ss.b_qd @ t, ss.b_g, wk * t.T @ ss.c,
                       ss.state_names, ss.state_units))
    n_x = sum(b[0].shape[0] for b in blocks)
    a = np.zeros((n_x, n_x))
    b_q = np.zeros((n_x, n))
    b_qd = np.zeros((n_x, n))
    b_g = np.zeros(n_x)
    c = np.zeros((n, n_x))
    names: list[str] = []
    units: list[str] = []
    i = 0
    for a_k, bq_k, bqd_k, bg_k, c_k, nm, un in blocks:
        j = i + a_k.shape[0]
        a[i:j, i:j] = a_k
        b_q[i:j] = bq_k
        b_qd[i:j] = bqd_k
        b_g[i:j] = bg_k
        c[:, i:j] = c_k
        names.extend(nm)
        units.extend(un)
        i = j
    return ModalAeroStateSpace(a, b_q, b_qd, b_g, c, d_q, d_qd, d_g, m_a, tuple(names),
                               tuple(units), float(speed_m_s))


def divergence_speed_m_s(model: ClampedWingModel, density_kg_m3: float) -> float:
    """Static divergence speed [m/s] of the strip model (steady aerodynamics, C = 1).

    Steady generalised forces D W η are ∝ V² (D ∝ V, W ∝ V): divergence where
    K − V² G loses positive definiteness, G = D W at 1 m/s. ``math.inf`` if never.
    """
    import math

    from scipy.linalg import eig

    mats = modal_strip_matrices(model, speed_m_s=1.0, density_kg_m3=density_kg_m3)
    g = mats.force @ mats.upwash_displacement
    lam = eig(g, model.stiffness, right=False)  # G x = μ K x → V² = 1/μ
    mu = lam[(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) & (lam.real > 0.0)].real
    return math.inf if mu.size == 0 else float(1.0 / math.sqrt(mu.max()))
