"""Force summation of the unsteady wing (``aero="unsteady"``), recovered after its steps.

The unsteady strips' lift at a step is the quasi-steady strip lift of the force summation
(:mod:`bioflex_jsb.loads.model`: Δα with the gust, q, η, η̇) plus the increments of
:func:`bioflex_jsb.aeroelasticity.strip_increments.strip_load_rows`, per strip: Jones's
circulatory lag on the three-quarter-chord upwash, the apparent mass, and Küssner's gust
lift in place of the quasi-steady one. Those need the wing's lag and Küssner states, which
a run does not log (4 per strip: 160 for the prototype's 40 strips), and the modal
accelerations η̈ of the unsteady modal equation (lag states included).

Both are **recomputed from the logged inputs**, block by block as the run's rows arrive
(:class:`~bioflex_jsb.loads.stream.LoadStream`); the compiled step is not touched. The row
of t_k holds the flow the wing stepped with over [t_k, t_k+1] (α, q, V, the gust w_g: the
wing holds its inputs f_k, ``unsteady_wing.INPUTS``, over the step) and its η_k, η̇_k. The
lag and Küssner states obey, per state j, ẏ_j = −r_j(V) y_j + a_j(V)·[η; η̇] + b_j(V)·f (the
wing's own rows, ``UnsteadyModalWing.continuous``: diagonal in the lag states, their rates
∝ V): each is integrated exactly over every step with f_k and V_k held (as the wing holds
them) and η, η̇ linear between the logged η_k and η_{k+1}, vectorised over the strips and
over the rows (the recursion in closed form over chunks of :data:`CHUNK_ROWS`). It is not
the wing's exact step (which integrates η with the lags): against a replay of the Python
reference wing (:class:`~bioflex_jsb.simulation.unsteady_wing.UnsteadyModalWing`) on the
same rows the increments' loads differ by < 1e-3 of their peak, η̈ by < 2.5 % of its peak
(``tests/test_loads_unsteady.py``), at a fraction of its cost (the replay: 70-150 µs a row
on this machine; this: ~15 µs).

Accelerations at t_k: α̇_i and q̇ the backward differences of the step's inputs (the wing's
own), η̈ = A(V) x_k + B(V) f_k from the wing's rows. The rows are quadratic in V at one
density (Q = ½ρV² at the loads model's ρ, as the quasi-steady force summation takes it):
fitted once at 0.5, 1, 1.5 × the trim speed (exact for a quadratic).
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb.aeroelasticity.strip_increments import strip_load_rows
from bioflex_jsb.simulation.modal_wing import TrimReference, one_blas_thread
from bioflex_jsb.simulation.unsteady_wing import FIT_SPEED_NODES, UnsteadyModalWing

NEEDED = ("alpha", "alpha_rad", "q", "airspeed_m_s", "w_g")


def strip_station_matrices(lm) -> tuple[np.ndarray, np.ndarray]:
    """(S_v, S_m), (s, K): shear and bending moment at the stations of a load per unit span
    constant over each lattice strip (N/m → N, N·m), from the loads model's cells."""
    yc, wc, strip = lm.cells_m, lm.cell_widths_m, lm.cell_strips
    k = int(strip.max()) + 1
    onehot = np.zeros((yc.size, k))
    onehot[np.arange(yc.size), strip] = 1.0
    out = yc[None, :] > lm.stations_m[:, None]
    a_v = out * wc[None, :]
    a_m = a_v * (yc[None, :] - lm.stations_m[:, None])
    return a_v @ onehot, a_m @ onehot


class UnsteadyStripLoads:
    """The unsteady increments' loads at the stations and the modal accelerations of a run
    of the unsteady wing, row by row in the run's order (module docstring).

    ``lm``: the loads model (its ``build``, density, speed and stations); ``names``: the
    run's channels; ``dt_s`` [s] its step."""

    def __init__(self, lm, names, dt_s: float) -> None:
        from bioflex_jsb.flight_dynamics.rigid import level_flight_condition

        build = lm.build
        col = {c: i for i, c in enumerate(names)}
        self.n = n = lm.n_modes
        self._i = {c: col[c] for c in NEEDED}
        self._i_eta = np.array([col[f"eta{i + 1}"] for i in range(n)]
                               + [col[f"eta{i + 1}_dot"] for i in range(n)], dtype=np.intp)
        self._dt = float(dt_s)
        self._rho = rho = lm.density_kg_m3
        self._q_trim = lm.dynamic_pressure_pa
        # the run's wing: its trim's Q and C_L0 of the level flight at sea level
        # (runtime/coupled_step.py); α_0 does not enter the rows
        cl_trim = level_flight_condition(lm.speed_m_s, airframe=build.airframe).cl_trim
        wing = UnsteadyModalWing.from_build(
            build, TrimReference(0.0, lm.dynamic_pressure_pa, cl_trim), dt_s=self._dt,
            aero=build.airframe.aero)
        g = wing.geometry
        nodes = [c * lm.speed_m_s for c in FIT_SPEED_NODES]
        inv = np.linalg.inv(np.vander(nodes, 3, increasing=True))
        mats = [wing.continuous(v, rho)[:2] for v in nodes]
        rows = [strip_load_rows(g, n, v, rho) for v in nodes]

        def fit(values):
            return [sum(inv[p, j] * values[j] for j in range(3)) for p in range(3)]

        self._a = fit([a for a, _ in mats])  # A_p: A(V) = Σ V^p A_p
        self._b = fit([b for _, b in mats])
        strips = {f: fit([getattr(r, f) for r in rows])
                  for f in ("lift_x", "lift_xd", "lift_w", "torque_x", "torque_xd", "torque_w")}
        sv, sm = strip_station_matrices(lm)
        # the strips' rows summed to the stations at once: (3 s, ·) per power of V, rows
        # shear, bending (of the lift), torque (quantity-major, as LoadsModel.fs_matrix)
        self._rows = {kind: [np.vstack([sv @ strips[f"lift_{kind}"][p],
                                        sm @ strips[f"lift_{kind}"][p],
                                        sv @ strips[f"torque_{kind}"][p]]) for p in range(3)]
                      for kind in ("x", "xd", "w")}
        self._n_out = 3 * sv.shape[0]
        lag, ed = slice(2 * n, wing.state.size), slice(n, 2 * n)
        # the coefficients of the powers of V, transposed and contiguous for the products

        def stacked(ms):
            return [np.ascontiguousarray(m_.T) for m_ in ms]

        self._mat = {"lag_s": stacked([a[lag, :2 * n] for a in self._a]),
                     "lag_f": stacked([b[lag] for b in self._b]),
                     "ed_x": stacked([a[ed] for a in self._a]),
                     "ed_f": stacked([b[ed] for b in self._b]),
                     "st_x": stacked(self._rows["x"]), "st_xd": stacked(self._rows["xd"]),
                     "st_w": stacked([r.reshape(-1)[:, None] for r in self._rows["w"]])}
        lag = slice(2 * n, wing.state.size)
        block = mats[1][0][lag, lag]  # at the trim speed itself (the fit rounds)
        if np.count_nonzero(block - np.diag(np.diag(block))):
            raise AssertionError("the lag states' rows are not diagonal in the lag states")
        self._rate_per_v = -np.diag(block) / nodes[1]  # r_j / V [1/m]: β_j V / b
        # carried from row to row: the lag states, the last row's inputs, state and speed
        self._y = np.zeros(lag.stop - lag.start)
        self._last = None  # (f_k, [η; η̇]_k, V_k) of the last row
        self.rows_done = 0

    def _inputs(self, rows: np.ndarray) -> np.ndarray:
        """f (steps, 8) of the rows as the wing forms them (``UnsteadyModalWing._inputs``):
        Q Δα, Q q/V, ΔQ (Q = ½ρV² at the loads model's ρ), α_i, q, α̇_i, q̇, w_g."""
        ix = self._i
        v = rows[:, ix["airspeed_m_s"]]
        d_alpha, q, wg = rows[:, ix["alpha"]], rows[:, ix["q"]], rows[:, ix["w_g"]]
        alpha_i = d_alpha - wg / v
        prev = (self._last[0][3], self._last[0][4]) if self._last is not None else None
        a_prev = np.concatenate([[alpha_i[0] if prev is None else prev[0]], alpha_i[:-1]])
        q_prev = np.concatenate([[q[0] if prev is None else prev[1]], q[:-1]])
        q_pa = 0.5 * self._rho * v * v
        f = np.zeros((len(rows), 8))
        f[:, 0], f[:, 1], f[:, 2] = q_pa * d_alpha, q_pa / v * q, q_pa - self._q_trim
        f[:, 3], f[:, 4], f[:, 7] = alpha_i, q, wg
        f[:, 5] = (alpha_i - a_prev) / self._dt
        f[:, 6] = (q - q_prev) / self._dt
        return f

    def block(self, rows: np.ndarray, eta_logged=None) -> tuple[np.ndarray, np.ndarray]:
        """For ``rows`` (the next rows of the run, in order; steps × channels): (the
        increments' loads (steps, 3 s) in the stations' quantity-major order [N, N·m],
        η̈ (steps, n) [rad/s²])."""
        if not len(rows):
            return np.zeros((0, self._n_out)), np.zeros((0, self.n))
        # BLAS on one thread: these products are small (a block of 864 rows by 8-170
        # columns), and OpenBLAS's threads on the shared 2-core machine made them 2-3 ×
        # slower (measured 130-160 against ~40 µs a row)
        with one_blas_thread():
            return self._block(np.asarray(rows, dtype=float))

    def _block(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        m, n = len(rows), self.n
        v = rows[:, self._i["airspeed_m_s"]]
        f = self._inputs(rows)
        s = rows[:, self._i_eta]  # [η; η̇] (steps, 2n)
        # the steps into each row k: from row k−1 (the last block's last row for k = 0)
        if self._last is None:
            f_prev = np.vstack([f[:1] * 0.0, f[:-1]])
            s_prev = np.vstack([s[:1], s[:-1]])
            v_prev = np.concatenate([v[:1], v[:-1]])
        else:
            f_prev = np.vstack([self._last[0][None, :], f[:-1]])
            s_prev = np.vstack([self._last[1][None, :], s[:-1]])
            v_prev = np.concatenate([[self._last[2]], v[:-1]])
        mat = self._mat
        c0 = _poly(v_prev, s_prev, mat["lag_s"]) + _poly(v_prev, f_prev, mat["lag_f"])
        c1 = _poly(v_prev, s - s_prev, mat["lag_s"])
        rdt = np.outer(v_prev, self._rate_per_v) * self._dt
        e = np.exp(-rdt)
        g0 = -np.expm1(-rdt) / rdt * self._dt  # (1 − e^{−rΔt}) / r
        g1 = (1.0 - g0 / self._dt) / rdt * self._dt  # ∫ e^{−r(Δt−τ)} τ/Δt dτ
        u = g0 * c0 + g1 * c1
        if self._last is None:  # the run's first row: the trim, every lag state zero
            e[0], u[0] = 0.0, 0.0
        y = _recursion(e, u, self._y)
        self._y = y[-1].copy()
        self._last = (f[-1].copy(), s[-1].copy(), float(v[-1]))
        x = np.hstack([s, y])
        eta_ddot = _poly(v, x, mat["ed_x"]) + _poly(v, f, mat["ed_f"])
        # the full state of the strip rows: [u, α_i, q, θ, η, η̇, lags]; its rate's α̇_i, q̇, η̈
        full = np.zeros((m, 4 + x.shape[1]))
        full[:, 1], full[:, 2], full[:, 4:] = f[:, 3], f[:, 4], x
        rate = np.zeros_like(full)
        rate[:, 1], rate[:, 2], rate[:, 4 + n:4 + 2 * n] = f[:, 5], f[:, 6], eta_ddot
        loads = (_poly(v, full, mat["st_x"]) + _poly(v, rate, mat["st_xd"])
                 + _poly(v, f[:, 7:8], mat["st_w"]))
        self.rows_done += m
        return loads, eta_ddot


def _poly(v: np.ndarray, x: np.ndarray, mt: list[np.ndarray]) -> np.ndarray:
    """Σ_p V^p (x @ M_p^T) per row, ``mt`` the three M_p^T."""
    return x @ mt[0] + v[:, None] * (x @ mt[1]) + (v * v)[:, None] * (x @ mt[2])


# NUMERICAL: rows per chunk of :func:`_recursion`'s closed form. Within a chunk y_k =
# P_k (y_0 + Σ_i u_i / P_i), P the running product of the decays e^{−rΔt}; the quotients
# amplify rounding by 1/P over the chunk: the fastest state (Küssner's 1.8 V/b: 300 s⁻¹ for
# the prototype at 15 m/s, rΔt = 0.31) decays by e^{−5} in 16 rows, so rounding grows to
# ~2e-14 relative, where a loop over the rows (16 times the numpy calls) has 1e-16.
CHUNK_ROWS = 16


def _recursion(e: np.ndarray, u: np.ndarray, y0: np.ndarray) -> np.ndarray:
    """y_k = e_k y_{k−1} + u_k for every row k (y_{−1} = ``y0``), elementwise over the
    columns: (rows, states). In chunks of :data:`CHUNK_ROWS` rows, each in closed form."""
    out = np.empty_like(u)
    y = y0
    for i in range(0, len(u), CHUNK_ROWS):
        ec, uc = e[i:i + CHUNK_ROWS], u[i:i + CHUNK_ROWS]
        if np.any(ec == 0.0):  # a reset row (the run's first): step through the chunk
            for k in range(len(ec)):
                y = ec[k] * y + uc[k]
                out[i + k] = y
            continue
        prod = np.cumprod(ec, axis=0)
        out[i:i + len(ec)] = prod * (y + np.cumsum(uc / prod, axis=0))
        y = out[i + len(ec) - 1]
    return out
