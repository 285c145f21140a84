"""Time response of an LTI model to a gust history (exact zero-order-hold discretisation)."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from bioflex_jsb.flight_dynamics.lti import StateSpace
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.simulation.results import TimeHistory


def simulate(ss: StateSpace, time_s: np.ndarray, w_g_m_s: np.ndarray) -> TimeHistory:
    """Response from trim to the gust samples ``w_g_m_s`` at uniformly spaced ``time_s``.

    The input is held over each interval (as the co-simulation holds it over a JSBSim step).

    In Eq. (4) the gust is a force input, so the state α is the *inertial* angle of attack
    θ − γ (γ the flight-path angle against the ground); the wing feels α + w_g/u_0. The
    channel ``alpha`` returned here is that aerodynamic angle, the one JSBSim reports as
    ``aero/alpha-rad`` (``alpha_inertial`` keeps the state). Channels: every output of
    ``ss``, ``n_z`` (load factor 1 + u_0 (q − α̇)/g, from the inertial α̇) and ``w_g``.
    """
    t = np.asarray(time_s, dtype=float)
    w = np.asarray(w_g_m_s, dtype=float)
    if t.ndim != 1 or len(t) < 2 or w.shape != t.shape:
        raise ValueError("time_s and w_g_m_s must be 1-D arrays of the same length ≥ 2")
    dt = float(t[1] - t[0])
    if not np.allclose(np.diff(t), dt, rtol=1e-6, atol=1e-12):
        raise ValueError("time_s must be uniformly spaced")
    n, m = ss.b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = ss.a
    aug[:n, n:] = ss.b
    e = expm(aug * dt)
    phi, gamma = e[:n, :n], e[:n, n:]
    x = np.zeros((len(t), n))
    for k in range(len(t) - 1):
        x[k + 1] = phi @ x[k] + gamma[:, 0] * w[k]
    y = x @ ss.c.T + np.outer(w, ss.d[:, 0])
    xdot = x @ ss.a.T + np.outer(w, ss.b[:, 0])
    channels = {name: y[:, i] for i, name in enumerate(ss.outputs)}
    units = dict(zip(ss.outputs, ss.output_units, strict=True))
    i_q, i_a = ss.states.index("q"), ss.states.index("alpha")
    channels["alpha_inertial"] = x[:, i_a]
    units["alpha_inertial"] = "rad"
    channels["alpha"] = x[:, i_a] + w / ss.speed_m_s
    u0 = ss.speed_m_s
    channels["n_z"] = 1.0 + u0 * (x[:, i_q] - xdot[:, i_a]) / STANDARD_GRAVITY_M_S2
    units["n_z"] = "-"
    channels["w_g"] = w
    units["w_g"] = "m/s"
    return TimeHistory(ss.model, t, channels, units, {"source": "lti", "speed_m_s": ss.speed_m_s})
