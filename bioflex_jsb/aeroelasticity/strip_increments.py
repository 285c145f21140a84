"""The unsteady strips' loads beyond the paper's quasi-steady ones, as rows on the state.

One model, two users: the free aircraft's LTI model
(:func:`bioflex_jsb.aeroelasticity.free_aircraft.unsteady_state_space`, which adds the rows
to Eq. 4 through the rigid and modal equations) and the co-simulation's unsteady wing
(:mod:`bioflex_jsb.simulation.unsteady_wing`, which integrates the modes and lag states and
hands the loads to JSBSim). The physics (Theodorsen's circulatory loads through Jones's
C(k) on the three-quarter-chord upwash, minus the paper's quasi-steady strips; apparent
mass about the physical elastic axis; optionally Küssner's gust lift instead of the
paper's instantaneous one) is described in :mod:`bioflex_jsb.aeroelasticity.free_aircraft`.

State order of the rows (that of :func:`unsteady_state_space`): x = [u [m/s], α [rad],
q [rad/s], θ [rad], η_i [rad], η̇_i [rad/s], lag1[k], lag2[k] [m/s], (kussner1[k],
kussner2[k] [m/s])], k over the lattice's starboard strips; α is the inertial angle of
attack (the gust is the input w_g [m/s, up]).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aerodynamics.indicial import JONES_WAGNER, SEARS_SPARKS_KUSSNER

RIGID_STATES = ("u", "alpha", "q", "theta")


@dataclass(frozen=True, eq=False)
class StripIncrements:
    """Loads of the unsteady increments at one airspeed and density (module docstring).

    Rows on the state x (``*_x``), on its rate ẋ (``*_xd``: the apparent mass; only the
    columns of α̇, q̇ and η̈ are non-zero) and per unit gust w_g (``*_w``):

    * ``z_*``: body force along z (down) [N per unit of the column's state];
    * ``m_*``: pitching moment about the centre of gravity, nose up [N·m per unit];
    * ``q_*``: (n_modes, n_states) generalised forces on the modes [N·m per unit]
      (whole span; divide by the m_i of the wing model's mass basis).

    ``lag_a`` (n_lag, n_states), ``lag_b`` (n_lag,): the lag (and Küssner) states' rates,
    ẋ_lag = lag_a x + lag_b w_g [1/s on m/s]; ``lag_slice`` their place in x.
    """

    states: tuple[str, ...]
    n_modes: int
    n_strips: int
    z_x: np.ndarray
    m_x: np.ndarray
    q_x: np.ndarray
    z_xd: np.ndarray
    m_xd: np.ndarray
    q_xd: np.ndarray
    z_w: float
    m_w: float
    q_w: np.ndarray
    lag_a: np.ndarray
    lag_b: np.ndarray
    lag_slice: slice

    @property
    def n_states(self) -> int:
        return len(self.states)


def lag_state_names(n_strips: int, gust: bool) -> tuple[str, ...]:
    """lag1[k], lag2[k] (and kussner1[k], kussner2[k]) for k in 0 … n_strips − 1."""
    names = tuple(f"lag{j + 1}[{k}]" for j in range(2) for k in range(n_strips))
    if gust:
        names += tuple(f"kussner{j + 1}[{k}]" for j in range(2) for k in range(n_strips))
    return names


def _strip_rows(g, n_modes: int, speed_m_s: float, density_kg_m3: float,
                gust: bool) -> dict:
    """The increments per strip and unit span, on the full state x (module docstring), and
    the lag states' rates: ``dl_circ`` circulatory lift [N/m] on x, ``l_nc_x``, ``l_nc_xd``
    apparent-mass lift [N/m] on x and ẋ, ``m_nc_x``, ``m_nc_xd`` apparent-mass moment about
    the elastic axis [N·m/m] on x and ẋ, with ``gust`` ``dl_g`` the Küssner lift on x and
    ``dl_w`` (K, 1) per unit gust; ``lag_a``, ``lag_b``; sizes ``n_all``, ``n0``.
    :func:`strip_increments` sums them over the span, :func:`strip_load_rows` hands them
    out per strip."""
    n, k_strips = int(n_modes), g.chord_m.size
    n0 = 4 + 2 * n
    n_all = n0 + (4 if gust else 2) * k_strips
    v, rho = float(speed_m_s), float(density_kg_m3)
    b = 0.5 * g.chord_m
    ia, iq = 1, 2
    ie = slice(4, 4 + n)
    ied = slice(4 + n, 4 + 2 * n)
    lag = [slice(n0 + j * k_strips, n0 + (j + 1) * k_strips) for j in range(4 if gust else 2)]
    amp, beta = JONES_WAGNER.amplitudes, JONES_WAGNER.exponents

    def rows() -> np.ndarray:
        return np.zeros((k_strips, n_all))

    # three-quarter-chord upwash [m/s] and the paper's angle × V [m/s]
    w34 = rows()
    w34[:, ia] = v
    w34[:, iq] = -g.d_34_m
    w34[:, ie] = v * g.theta.T
    w34[:, ied] = (g.phi + g.e_34_m * g.theta).T
    wqs = rows()
    wqs[:, ia] = v
    wqs[:, iq] = -g.d_m
    wqs[:, ie] = v * g.theta.T
    wqs[:, ied] = g.phi.T
    half = 0.5 * rho * v * g.cl_alpha_c_m[:, None]
    l_c = half * (1.0 - sum(amp)) * w34
    for j in range(2):
        l_c[:, lag[j]] += np.diag(half[:, 0])
    dl_circ = l_c - half * wqs  # circulatory increment [N/m] on x
    # apparent mass: heave acceleration (down), pitch rate and acceleration, on x and ẋ
    hdd_x, hdd_xd = rows(), rows()
    hdd_x[:, iq] = -v
    hdd_xd[:, ia] = v
    hdd_xd[:, iq] = -g.d_e_m
    hdd_xd[:, ied] = g.phi.T
    ad_x = rows()
    ad_x[:, iq] = 1.0
    ad_x[:, ied] = g.theta.T
    add_xd = ad_x.copy()  # α̇_s in x; α̈_s = the same row on ẋ
    pb2 = (math.pi * rho * b**2)[:, None]
    ba = (b * g.a)[:, None]
    out = {"n_all": n_all, "n0": n0, "dl_circ": dl_circ,
           "l_nc_x": pb2 * (hdd_x + v * ad_x), "l_nc_xd": pb2 * (hdd_xd - ba * add_xd),
           "m_nc_x": pb2 * (ba * hdd_x - v * (b * (0.5 - g.a))[:, None] * ad_x),
           "m_nc_xd": pb2 * (ba * hdd_xd - (b**2 * (0.125 + g.a**2))[:, None] * add_xd)}
    n_lag = n_all - n0
    lag_a = np.zeros((n_lag, n_all))
    lag_b = np.zeros(n_lag)
    for j in range(2):
        rate = beta[j] * v / b
        rj = slice(j * k_strips, (j + 1) * k_strips)
        lag_a[rj, lag[j]] -= np.diag(rate)
        lag_a[rj] += amp[j] * rate[:, None] * w34
    if gust:
        # wing's gust lift: ½ρV C_lα c Σ x_g (Küssner) instead of ½ρV C_lα c w_g (paper),
        # on the paper's arms; Sears & Sparks: Σ A_j = 1, no direct term
        kamp, kbeta = SEARS_SPARKS_KUSSNER.amplitudes, SEARS_SPARKS_KUSSNER.exponents
        dl_g = rows()
        for j in range(2):
            dl_g[:, lag[2 + j]] += np.diag(half[:, 0])
            rate = kbeta[j] * v / b
            rj = slice((2 + j) * k_strips, (3 + j) * k_strips)
            lag_a[rj, lag[2 + j]] -= np.diag(rate)
            lag_b[rj] += kamp[j] * rate
        out["dl_g"] = dl_g
        out["dl_w"] = -half  # (K, 1): minus the paper's instantaneous gust lift per m/s
    out["lag_a"], out["lag_b"] = lag_a, lag_b
    return out


@dataclass(frozen=True, eq=False)
class StripLoadRows:
    """The unsteady increments' loads **per strip and unit span** (the force summation of
    the unsteady wing, :mod:`bioflex_jsb.loads.unsteady`): ``lift_x`` (K, n_states) [N/m per
    unit of the state, up] on the full state x (module docstring), ``lift_xd`` on its rate
    ẋ (apparent mass: the α̇, q̇ and η̈ columns), ``lift_w`` (K,) per unit gust w_g [N/m per
    m/s]; ``torque_*`` the same for the section torque about the elastic axis [N·m/m,
    leading edge up]: the circulatory and Küssner lift at the offset e of the aerodynamic
    centre ahead of the elastic axis (the arms the generalised forces of
    :func:`strip_increments` take) plus the apparent mass's moment."""

    lift_x: np.ndarray
    lift_xd: np.ndarray
    lift_w: np.ndarray
    torque_x: np.ndarray
    torque_xd: np.ndarray
    torque_w: np.ndarray


def strip_load_rows(g, n_modes: int, speed_m_s: float, density_kg_m3: float
                    ) -> StripLoadRows:
    """The :class:`StripLoadRows` of the strips ``g`` with the Küssner states (the
    co-simulation's unsteady wing) at ``speed_m_s`` [m/s], ``density_kg_m3`` [kg/m³]."""
    r = _strip_rows(g, n_modes, speed_m_s, density_kg_m3, True)
    e = g.e_m[:, None]
    circ = r["dl_circ"] + r["dl_g"]
    return StripLoadRows(
        lift_x=circ + r["l_nc_x"], lift_xd=r["l_nc_xd"].copy(), lift_w=r["dl_w"][:, 0].copy(),
        torque_x=e * circ + r["m_nc_x"], torque_xd=r["m_nc_xd"].copy(),
        torque_w=(e * r["dl_w"])[:, 0])


def strip_increments(g, n_modes: int, speed_m_s: float, density_kg_m3: float, *,
                     gust: bool = False) -> StripIncrements:
    """The :class:`StripIncrements` of the strips ``g`` (a
    :class:`~bioflex_jsb.aeroelasticity.free_aircraft.StripGeometry`) with ``n_modes`` modes
    at ``speed_m_s`` [m/s] and ``density_kg_m3`` [kg/m³]; ``gust``: with the Küssner states
    (the wing's gust lift through Küssner's function instead of at once)."""
    n, k_strips = int(n_modes), g.chord_m.size
    r = _strip_rows(g, n_modes, speed_m_s, density_kg_m3, gust)
    n_all, n0, dl_circ = r["n_all"], r["n0"], r["dl_circ"]
    w = g.weights_m

    def loads(dl_c, l_nc, m_nc):
        """Z [N], M about CG [N·m], Q_i [N·m] of the strip increments (rows on x or ẋ)."""
        z = -(w @ (dl_c + l_nc))
        m = (w * g.d_m) @ dl_c + w @ (m_nc + g.d_e_m[:, None] * l_nc)
        q = ((g.e_m * g.theta - g.phi) * w) @ dl_c + (-(g.phi * w) @ l_nc
                                                      + (g.theta * w) @ m_nc)
        return z, m, q

    z_x, m_x, q_x = loads(dl_circ, r["l_nc_x"], r["m_nc_x"])
    z_xd, m_xd, q_xd = loads(np.zeros_like(dl_circ), r["l_nc_xd"], r["m_nc_xd"])
    z_w, m_w, q_w = 0.0, 0.0, np.zeros(n)
    if gust:
        dl_g = r["dl_g"]
        zero = np.zeros_like(dl_g)
        zg, mg, qg = loads(dl_g, zero, zero)
        z_x, m_x, q_x = z_x + zg, m_x + mg, q_x + qg
        dl_w = r["dl_w"]
        zw, mw, qw = loads(dl_w, np.zeros_like(dl_w), np.zeros_like(dl_w))
        z_w, m_w, q_w = float(zw[0]), float(mw[0]), qw[:, 0]
    names = RIGID_STATES + tuple(f"eta{i + 1}" for i in range(n)) + tuple(
        f"eta{i + 1}_dot" for i in range(n)) + lag_state_names(k_strips, gust)
    return StripIncrements(names, n, k_strips, z_x, m_x, q_x, z_xd, m_xd, q_xd, z_w, m_w, q_w,
                           r["lag_a"], r["lag_b"], slice(n0, n_all))
