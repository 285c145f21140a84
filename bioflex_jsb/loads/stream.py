"""Section loads of a run as it is flown: block by block, vectorised, bounded memory.

:class:`LoadStream` turns each block of a gust run's rows (``drivers/gust.py``: the rows
of one log chunk, 0.9 s of simulated time) into the loads at the monitoring stations by
the same arithmetic as the post-process (:func:`bioflex_jsb.loads.history.
section_loads_of_run`): the signals z of each row, one matrix product per method. The
pitch acceleration q̇ is the central difference of q (as ``numpy.gradient``: one-sided at
the two ends of the run), so a row's loads need the next row's q: the stream **holds the
last row of each block** and hands it on with the next block, and :meth:`LoadStream.finish`
hands on the last row of the run. Every row's loads are therefore those of the
post-process of the whole run (to rounding: ``tests/test_loads_run.py``), whatever the
blocks.

Methods per run (``docs/loads.md``, "In every gust run"): force summation and mode
displacement for the quasi-steady coupled and qsd wings; force summation only for the rigid
model (no wing modes: the mode-displacement loads are zero by construction and are not
reported); both for the unsteady wing, whose force summation adds its strips' lag, apparent
mass and Küssner increments and takes η̈ of its own modal equation, the lag states
recomputed from the rows (:mod:`bioflex_jsb.loads.unsteady`); force summation only for a
wing without EI, GJ (a modes file: ``LoadsModel.methods``).

A block's signals z (and the modal accelerations of the coupled wing) are one compiled pass
over its rows (:func:`_signals`), the matrix products numpy's as before: the same doubles as
the readable numpy it replaces (:meth:`LoadStream._loads_numpy`, tests/test_loads_run.py).
"""

from __future__ import annotations

import numba
import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.loads.model import METHODS, QUANTITIES, QUANTITY_UNITS, LoadsModel
from bioflex_jsb.parameters import constants as C
from bioflex_jsb.simulation.step_kernel import guard_cache

G = C.STANDARD_GRAVITY_M_S2
TAGS = {"force_summation": "fs", "mode_displacement": "md"}


def channel_names(methods, n_stations: int) -> tuple[str, ...]:
    """The load channels of a run, in column order: per method (:data:`METHODS` order),
    quantity (:data:`QUANTITIES`) and station, ``loads_<fs|md>_<quantity>_s<j>`` (the names
    of :meth:`~bioflex_jsb.loads.history.SectionLoads.channels`)."""
    return tuple(f"loads_{TAGS[m]}_{q}_s{j}" for m in METHODS if m in methods
                 for q in QUANTITIES for j in range(n_stations))


def run_methods(model: str, aero: str = "quasi-steady") -> tuple[str, ...]:
    """The methods a run of ``model`` with ``aero`` strips reports (module docstring)."""
    if model == "rigid":
        return ("force_summation",)
    if model not in ("coupled", "qsd"):
        raise InputError(f"section loads are for the rigid, coupled and qsd wings, not "
                         f"{model!r}")
    if aero not in ("quasi-steady", "unsteady"):
        raise InputError(f"unknown strips {aero!r}; accepted: quasi-steady, unsteady")
    return METHODS


@numba.njit(cache=True, nogil=True)
def _signals(rows, cols, q_dot, d_eta, d_eta_dot, ke, de, eta, half_rho, alpha0, static_eta,
             g, omega2, damping, b_alpha, b_q, b_0, q_trim, modal):
    """The signals z (m, 5 + 3 n) of the rows ``rows`` (``cols``: the columns of the
    airspeed, α, q and n_z), their total η written into ``eta`` (m, n), operation for
    operation as :meth:`LoadStream._loads_numpy` (the same doubles): Q = (½ρ V) V, z's η̈
    columns zero unless ``modal`` (the coupled wing's modal equation, its products ``ke`` =
    Δη K_aᵀ and ``de`` = Δη̇ D_aᵀ by numpy's matmul, as there). One array returned: numba's
    boxing of a returned tuple lets a stop signal that lands in it end as ``SystemError``
    instead of ``KeyboardInterrupt`` (tests/test_signal_faults.py met it)."""
    m, n = d_eta.shape
    z = np.zeros((m, 5 + 3 * n))
    i_v, i_alpha, i_q, i_nz = cols[0], cols[1], cols[2], cols[3]
    for r in range(m):
        v = rows[r, i_v]
        q_pa = half_rho * v * v
        d_alpha, q = rows[r, i_alpha], rows[r, i_q]
        qv = q_pa / v
        z[r, 0] = q_pa * (alpha0 + d_alpha)
        z[r, 1] = q_pa * q / v
        for i in range(n):
            e = static_eta[i] + d_eta[r, i]
            eta[r, i] = e
            z[r, 2 + i] = q_pa * e
            z[r, 2 + n + i] = qv * d_eta_dot[r, i]
        z[r, 2 + 2 * n] = q_pa
        z[r, 3 + 2 * n] = g * rows[r, i_nz]
        z[r, 4 + 2 * n] = q_dot[r]
        if modal:
            for i in range(n):
                z[r, 5 + 2 * n + i] = (-(d_eta[r, i] * omega2[i]) + q_pa * ke[r, i]
                                       - d_eta_dot[r, i] * damping[i] + qv * de[r, i]
                                       + (q_pa * d_alpha) * b_alpha[i] + (qv * q) * b_q[i]
                                       + (q_pa - q_trim) * b_0[i])
    return z


guard_cache(_signals)


class LoadStream:
    """The loads of one run of ``model`` computed block by block (module docstring).

    ``lm``: the loads model (its speed the run's trim); ``names``: the run's channel names
    (the row order); ``dt_s`` [s] its step; ``static_eta_rad``: η₀ of a run flown from the
    elastic trim (its modal equation's b₀, as ``run.meta['static_eta_rad']``), else None;
    ``aero``: the wing's strips. :attr:`names` and :attr:`units` are the load channels;
    :attr:`static_1g` their 1 g values."""

    def __init__(self, lm: LoadsModel, names, dt_s: float, model: str,
                 static_eta_rad=None, aero: str = "quasi-steady") -> None:
        self.lm = lm
        self.model = model
        self.methods = tuple(m for m in run_methods(model, aero) if m in lm.methods)
        if not self.methods:
            raise InputError(f"wing {lm.wing!r}: {lm.md_unavailable}; and the run of model "
                             f"{model!r} with {aero} strips has no force summation")
        n = lm.n_modes
        col = {c: i for i, c in enumerate(names)}
        need = ["alpha", "q", "n_z", "airspeed_m_s"]
        self._wing = model in ("coupled", "qsd")
        if self._wing:
            need += [f"eta{i + 1}" for i in range(n)] + [f"eta{i + 1}_dot" for i in range(n)]
            if f"eta{n + 1}" in col:
                raise InputError(f"the run has more wing modes than the wing's {n}")
        missing = [c for c in need if c not in col]
        if missing:
            raise InputError(f"run of model {model!r} has no channel {missing[0]!r}; section "
                             "loads need alpha, q, n_z, airspeed_m_s and the modal state")
        self._i_alpha, self._i_q, self._i_nz, self._i_v = (col[c] for c in need[:4])
        self._i_eta = np.array([col[f"eta{i + 1}"] for i in range(n)] if self._wing else [],
                               dtype=np.intp)
        self._i_etad = np.array([col[f"eta{i + 1}_dot"] for i in range(n)] if self._wing
                                else [], dtype=np.intp)
        self.dt_s = float(dt_s)
        mm = lm.matrices
        b_0 = mm.b_0 if static_eta_rad is None else (
            mm.omega**2 * np.asarray(static_eta_rad, dtype=float) / lm.dynamic_pressure_pa)
        self._b0 = b_0
        self.names = channel_names(self.methods, lm.n_stations)
        self.units = {f"loads_{TAGS[m]}_{q}_s{j}": QUANTITY_UNITS[q] for m in self.methods
                      for q in QUANTITIES for j in range(lm.n_stations)}
        static = lm.static_loads()
        self.static_1g = dict(zip(self.names, np.concatenate(
            [static[m].reshape(-1) for m in METHODS if m in self.methods]).tolist(),
            strict=True))
        # the product of each method: FS on z, MD on the total η
        self._fs = lm.fs_matrix.T if "force_summation" in self.methods else None
        self._md = lm.md_matrix.T if "mode_displacement" in self.methods else None
        # the unsteady wing's increments and η̈, replayed from the rows (loads/unsteady.py)
        self._unsteady = None
        if aero == "unsteady" and self._fs is not None:
            from bioflex_jsb.loads.unsteady import UnsteadyStripLoads

            self._unsteady = UnsteadyStripLoads(lm, names, dt_s)
        # the compiled pass's constants (_signals), each as _loads_numpy computes it
        self._cols = np.array([self._i_v, self._i_alpha, self._i_q, self._i_nz], dtype=np.intp)
        self._consts = (0.5 * lm.density_kg_m3, lm.alpha_wing_rad + lm.static_alpha_rad,
                        np.ascontiguousarray(lm.static_eta_rad, dtype=float), G,
                        mm.omega**2, 2.0 * mm.zeta * mm.omega, mm.b_alpha, mm.b_q,
                        np.asarray(self._b0, dtype=float), lm.dynamic_pressure_pa)
        # a flaperon's strip loads and modal forcing (loads/flaperon.py), from its channel
        self._flap = None
        if lm.flaperon is not None and "flaperon_rad" in col:
            self._flap = (col["flaperon_rad"], lm.flaperon)
        self._held_t: float | None = None  # the last row handed in, its loads not yet out
        self._held: np.ndarray | None = None
        self._q_before = None  # q of the row before the held one (None: the run's first)
        self._held_t_before = 0.0  # its time [s]
        self.rows_out = 0

    @property
    def n_channels(self) -> int:
        return len(self.names)

    @property
    def holding(self) -> bool:
        """Whether a row waits for its loads (:meth:`finish` hands it on)."""
        return self._held is not None

    def add(self, time_s: np.ndarray, rows: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Hand in a block of rows (steps × the run's channels, times [s]); return the rows
        whose loads are now known: (times, those rows (a copy), their loads (rows × :attr:
        `names`)): the row held from the last block and all of this block but its last
        (held until the next block or :meth:`finish`)."""
        rows = np.asarray(rows, dtype=float)
        time_s = np.asarray(time_s, dtype=float)
        if not len(rows):
            return time_s[:0], rows[:0], np.empty((0, self.n_channels))
        if self._held is None:
            t_all, r_all = time_s, rows
        else:  # a new array: its rows are the caller's to keep, no copy
            t_all = np.concatenate([[self._held_t], time_s])
            r_all = np.concatenate([self._held[None, :], rows])
        q = r_all[:, self._i_q]
        # q̇ of rows 0 … len-2 of r_all: central differences, row 0 one-sided if the run's
        q_dot = np.empty(len(r_all) - 1)
        if len(r_all) > 2:
            q_dot[1:] = (q[2:] - q[:-2]) / (t_all[2:] - t_all[:-2])
        if len(q_dot):
            if self._q_before is None:  # the run's first row: forward difference
                q_dot[0] = (q[1] - q[0]) / (t_all[1] - t_all[0])
            else:
                q_dot[0] = (q[1] - self._q_before) / (t_all[1] - self._held_t_before)
        out_t, out_rows = t_all[:-1], r_all[:-1]
        loads = self._loads(out_rows, q_dot)
        if len(r_all) > 1:
            self._q_before = float(q[-2])
            self._held_t_before = float(t_all[-2])
        self._held_t = float(t_all[-1])
        self._held = r_all[-1].copy()
        self.rows_out += len(out_t)
        return out_t, out_rows.copy() if r_all is rows else out_rows, loads

    def finish(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The run is over: the held last row with its loads (q̇ by the backward difference,
        as ``numpy.gradient`` at the end; NaN force summation for a run of one step, which
        has no difference)."""
        if self._held is None:
            raise RuntimeError("LoadStream.finish: no row held (finished already, or no row "
                               "handed in)")
        row = self._held[None, :]
        if self._q_before is None:
            q_dot = np.array([np.nan])
        else:
            q_dot = np.array([(row[0, self._i_q] - self._q_before)
                              / (self._held_t - self._held_t_before)])
        t = np.array([self._held_t])
        loads = self._loads(row, q_dot)
        self._held = None
        self.rows_out += 1
        return t, row.copy(), loads

    def _loads(self, rows: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """The loads (rows × :attr:`names`) of ``rows`` with their pitch accelerations
        ``q_dot`` [rad/s²] (the signals of ``loads.history.run_signals``): the compiled pass
        of :meth:`_loads_numpy`."""
        n = self.lm.n_modes
        m = len(rows)
        if self._wing:
            d_eta = rows[:, self._i_eta]
            d_eta_dot = rows[:, self._i_etad]
        else:
            d_eta = d_eta_dot = np.zeros((m, n))
        modal = self._fs is not None and self._unsteady is None and self.model == "coupled"
        mm = self.lm.matrices
        if modal:
            ke, de = d_eta @ mm.k_aero.T, d_eta_dot @ mm.d_aero.T
        else:
            ke = de = d_eta
        eta = np.empty((m, n))
        z = _signals(rows, self._cols, np.asarray(q_dot, dtype=float), d_eta, d_eta_dot, ke, de,
                     eta, *self._consts, modal)
        flap = None
        if self._flap is not None:  # Q δf of each row: its strips' loads and its η̈ forcing
            i_flap, fl = self._flap
            flap = self._consts[0] * rows[:, self._i_v] ** 2 * rows[:, i_flap]
            if modal:
                z[:, 5 + 2 * n:] += np.outer(flap, fl.force)
        parts = []
        if self._fs is not None:
            if self._unsteady is not None:
                extra, eta_ddot = self._unsteady.block(rows, d_eta)
                z[:, 5 + 2 * n:] = eta_ddot
                parts.append(z @ self._fs + extra)
            else:
                parts.append(z @ self._fs)
            if flap is not None:
                parts[-1] = parts[-1] + np.outer(flap, self._flap[1].fs_rows)
        if self._md is not None:
            parts.append(eta @ self._md)
        return parts[0] if len(parts) == 1 else np.hstack(parts)

    def _loads_numpy(self, rows: np.ndarray, q_dot: np.ndarray) -> np.ndarray:
        """:meth:`_loads` in numpy, the readable reference of the compiled pass."""
        lm = self.lm
        n = lm.n_modes
        m = len(rows)
        v = rows[:, self._i_v]
        q_pa = 0.5 * lm.density_kg_m3 * v * v
        d_alpha = rows[:, self._i_alpha]
        q = rows[:, self._i_q]
        if self._wing:
            d_eta = rows[:, self._i_eta]
            d_eta_dot = rows[:, self._i_etad]
        else:
            d_eta = d_eta_dot = np.zeros((m, n))
        eta = lm.static_eta_rad[None, :] + d_eta
        parts = []
        if self._fs is not None:
            z = np.empty((m, 5 + 3 * n))
            z[:, 0] = q_pa * (lm.alpha_wing_rad + lm.static_alpha_rad + d_alpha)
            z[:, 1] = q_pa * q / v
            z[:, 2:2 + n] = q_pa[:, None] * eta
            z[:, 2 + n:2 + 2 * n] = (q_pa / v)[:, None] * d_eta_dot
            z[:, 2 + 2 * n] = q_pa
            z[:, 3 + 2 * n] = G * rows[:, self._i_nz]
            z[:, 4 + 2 * n] = q_dot
            if self._unsteady is not None:
                extra, eta_ddot = self._unsteady.block(rows, d_eta)
                z[:, 5 + 2 * n:] = eta_ddot
                parts.append(z @ self._fs + extra)
            elif self.model == "coupled":
                z[:, 5 + 2 * n:] = self._modal_accelerations(q_pa, v, d_alpha, q, d_eta,
                                                             d_eta_dot)
                parts.append(z @ self._fs)
            else:
                z[:, 5 + 2 * n:] = 0.0
                parts.append(z @ self._fs)
        if self._md is not None:
            parts.append(eta @ self._md)
        return parts[0] if len(parts) == 1 else np.hstack(parts)

    def _modal_accelerations(self, q_pa, v, d_alpha, q, d_eta, d_eta_dot) -> np.ndarray:
        """η̈ [rad/s²] by the modal equation (``loads.history.modal_accelerations``)."""
        mm = self.lm.matrices
        qv = q_pa / v
        return (-(d_eta * mm.omega**2) + q_pa[:, None] * (d_eta @ mm.k_aero.T)
                - d_eta_dot * (2.0 * mm.zeta * mm.omega) + qv[:, None] * (d_eta_dot @ mm.d_aero.T)
                + np.outer(q_pa * d_alpha, mm.b_alpha) + np.outer(qv * q, mm.b_q)
                + np.outer(q_pa - self.lm.dynamic_pressure_pa, self._b0))


def layout_for_methods(layout: dict, methods) -> dict:
    """A run's loads layout (``meta["loads"]``) cut to ``methods`` (its names, units,
    methods and 1 g values; the stations, density and notes kept): for a prediction that
    has some of the run's methods only (the unsteady LTI model: mode displacement)."""
    keep = [m for m in METHODS if m in layout["methods"] and m in tuple(methods)]
    prefixes = tuple(f"loads_{TAGS[m]}_" for m in keep)
    names = [c for c in layout["names"] if c.startswith(prefixes)] if keep else []
    return {**layout, "methods": keep, "names": names,
            "units": {c: layout["units"][c] for c in names},
            "static_1g": {c: layout["static_1g"][c] for c in names}}
