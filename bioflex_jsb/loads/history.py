"""Section loads of a run: the loads time history of a nonlinear ``TimeHistory``, its
metrics (peaks with their times, increments over 1 g) and its figure.

Accelerations (docs/loads.md, "Accelerations"): the load factor n_z is the run's own channel
(JSBSim's, at the CG); the pitch acceleration q̇ is the central difference of the pitch rate
(second order; q is smooth, its fastest content the short period near 1-2 Hz, where the
difference's error at the co-simulation's 1/960 s step is (ω Δt)²/6 < 1e-4); the modal
accelerations η̈ are **the modal equation's** (:mod:`bioflex_jsb.flight_dynamics.
modal_matrices`), evaluated on the run's own flow and modal state: the same equation the
co-simulation integrates, so it holds at every sample, whereas a difference of η̇ would be
off by (ω Δt)²/6 ≈ 8 % for the third mode (107 Hz, 9 samples a period) and smear a
sharp-edged gust's jump over a step. The ``qsd`` model has η̈ = 0 (quasi-static).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.loads.flaperon import of_run as flaperon_of_run
from bioflex_jsb.loads.model import METHODS, QUANTITIES, QUANTITY_UNITS, LoadsModel
from bioflex_jsb.parameters import constants as C
from bioflex_jsb.simulation.results import TimeHistory

G = C.STANDARD_GRAVITY_M_S2


@dataclass(eq=False)
class SectionLoads:
    """Loads at the monitoring stations over a run.

    ``values[method]``: (samples, 3, stations) array, quantities in :data:`QUANTITIES`
    order (shear [N], bending [N·m], torque [N·m]; signs in :mod:`bioflex_jsb.loads.model`);
    methods ``force_summation`` and ``mode_displacement`` (absent for a rigid wing).
    ``static[method]``: (3, stations) the 1 g trim's loads. ``aero`` and ``inertia``: the
    force summation's two parts (samples, 3, stations).
    """

    wing: str
    model: str
    time_s: np.ndarray
    stations_m: np.ndarray
    station_fractions: tuple[float, ...]
    values: dict[str, np.ndarray]
    static: dict[str, np.ndarray]
    aero: np.ndarray
    inertia: np.ndarray
    meta: dict[str, object] = field(default_factory=dict)

    @property
    def methods(self) -> tuple[str, ...]:
        return tuple(m for m in METHODS if m in self.values)

    def station_label(self, j: int) -> str:
        f = self.station_fractions[j]
        return "root" if f == 0.0 else f"{100 * f:g}% b/2"

    def get(self, method: str, quantity: str, station: int) -> np.ndarray:
        """One load's time history [N or N·m]."""
        return self.values[method][:, QUANTITIES.index(quantity), station]

    def difference(self) -> np.ndarray | None:
        """Force summation − mode displacement, (samples, 3, stations); None for a rigid
        wing."""
        if "mode_displacement" not in self.values:
            return None
        return self.values["force_summation"] - self.values["mode_displacement"]

    def channels(self) -> tuple[dict[str, np.ndarray], dict[str, str]]:
        """Flat channels (for a TimeHistory, a log): ``loads_<fs|md>_<quantity>_s<j>``."""
        out, units = {}, {}
        for method in self.methods:
            tag = "fs" if method == "force_summation" else "md"
            for qi, quantity in enumerate(QUANTITIES):
                for j in range(self.stations_m.size):
                    name = f"loads_{tag}_{quantity}_s{j}"
                    out[name] = self.values[method][:, qi, j]
                    units[name] = QUANTITY_UNITS[quantity]
        return out, units

    def plot(self, path=None, gust_start_s: float | None = None, force: bool = False):
        """The figure (a matplotlib Figure; written to ``path`` when given: a figure
        suffix, an existing file only if it is a plot of ours or with ``force``)."""
        from bioflex_jsb.loads.plots import plot_section_loads

        if path is not None:
            from bioflex_jsb.plot_files import check_plot_target

            check_plot_target(path, force)
        return plot_section_loads(self, path, gust_start_s)


def _required(run: TimeHistory, names) -> None:
    missing = [c for c in names if c not in run.channels]
    if missing:
        raise InputError(f"run of model {run.model!r} has no channel {missing[0]!r}; section "
                         "loads need u, alpha, q, n_z, airspeed_m_s and the modal state")


def run_signals(lm: LoadsModel, run: TimeHistory) -> np.ndarray:
    """The signal vector z (samples, len(z)) of ``run`` (:func:`~bioflex_jsb.loads.model.
    signal_names`; module docstring for the accelerations)."""
    if run.meta.get("history", "all") != "all":
        raise InputError("section loads need every step of the run (keep='all'); this run "
                         "kept an envelope only")
    t = np.asarray(run.time_s, dtype=float)
    if t.size < 3:
        raise InputError("section loads need a run of at least 3 samples")
    _required(run, ("alpha", "q", "n_z", "airspeed_m_s"))
    n = lm.n_modes
    wing_model = run.model in ("coupled", "qsd")
    if wing_model:
        _required(run, [f"eta{i + 1}" for i in range(n)] + [f"eta{i + 1}_dot" for i in range(n)])
        if f"eta{n + 1}" in run.channels:
            raise InputError(f"the run has more wing modes than the wing's {n}")
    v = np.asarray(run["airspeed_m_s"], dtype=float)
    q_pa = 0.5 * lm.density_kg_m3 * v**2
    d_alpha = np.asarray(run["alpha"], dtype=float)
    q = np.asarray(run["q"], dtype=float)
    if wing_model:
        d_eta = np.column_stack([run[f"eta{i + 1}"] for i in range(n)])
        d_eta_dot = np.column_stack([run[f"eta{i + 1}_dot"] for i in range(n)])
    else:
        d_eta = d_eta_dot = np.zeros((t.size, n))
    eta = lm.static_eta_rad[None, :] + d_eta
    z = np.zeros((t.size, 5 + 3 * n))
    z[:, 0] = q_pa * (lm.alpha_wing_rad + lm.static_alpha_rad + d_alpha)
    z[:, 1] = q_pa * q / v
    z[:, 2:2 + n] = q_pa[:, None] * eta
    z[:, 2 + n:2 + 2 * n] = (q_pa / v)[:, None] * d_eta_dot
    z[:, 2 + 2 * n] = q_pa
    z[:, 3 + 2 * n] = G * np.asarray(run["n_z"], dtype=float)
    z[:, 4 + 2 * n] = np.gradient(q, t)
    if run.model == "coupled":
        z[:, 5 + 2 * n:] = modal_accelerations(lm, run, q_pa, v, d_alpha, q, d_eta, d_eta_dot)
    return z


def modal_accelerations(lm: LoadsModel, run: TimeHistory, q_pa, v, d_alpha, q, d_eta,
                        d_eta_dot) -> np.ndarray:
    """η̈ (samples, n) [rad/s²] by the modal equation of the run as flown:
    η̈ = −(Ω² − Q K_a)Δη − (2ζΩ − (Q/V) D_a)Δη̇ + Q b_α Δα + (Q/V) b_q q + b_0 ΔQ, with
    b_0 = ω²η₀/Q₀ for a run from the elastic trim (``meta['static_eta_rad']``)."""
    mm = lm.matrices
    b_0 = mm.b_0
    static = run.meta.get("static_eta_rad")
    if static is not None:
        b_0 = mm.omega**2 * np.asarray(static, dtype=float) / lm.dynamic_pressure_pa
    omega2 = mm.omega**2
    qv = q_pa / v
    acc = (-(d_eta * omega2) + q_pa[:, None] * (d_eta @ mm.k_aero.T)
           - d_eta_dot * (2.0 * mm.zeta * mm.omega) + qv[:, None] * (d_eta_dot @ mm.d_aero.T)
           + np.outer(q_pa * d_alpha, mm.b_alpha) + np.outer(qv * q, mm.b_q)
           + np.outer(q_pa - lm.dynamic_pressure_pa, b_0))
    return acc


def section_loads_of_run(lm: LoadsModel, run: TimeHistory) -> SectionLoads:
    """The loads of ``run`` at ``lm``'s stations by both methods (MD absent for ``rigid``).
    Refused (InputError, one line): the native model's run (its wing is in JSBSim's XML,
    with no modal loads model), and a run flown with another wing than ``lm``'s, as its own
    loads say (``meta["loads"]["wing"]``: another variant's or aircraft's wing gives root
    bending moments off by up to four orders of magnitude, silently)."""
    if run.model == "native":
        raise InputError("the native wing (in the aircraft's XML) has no section loads "
                         "model; fly the coupled model")
    flown = (run.meta.get("loads") or {}).get("wing")
    if flown is not None and flown != lm.wing:
        raise InputError(f"the run was flown with wing {flown!r}; its section loads need "
                         f"that wing, not {lm.wing!r}")
    if abs(float(run.meta.get("speed_m_s", lm.speed_m_s)) - lm.speed_m_s) > 1e-9:
        raise InputError(f"the loads model is for {lm.speed_m_s:g} m/s, the run was trimmed at "
                         f"{run.meta.get('speed_m_s')} m/s")
    z = run_signals(lm, run)
    s = lm.n_stations
    shape = (len(z), 3, s)
    flap = np.zeros((len(z), 3 * s))  # a flaperon's strip loads (loads/flaperon.py)
    lm, flap_rad = flaperon_of_run(lm, run)
    if flap_rad is not None:
        q_flap = (0.5 * lm.density_kg_m3 * np.asarray(run["airspeed_m_s"], dtype=float)**2
                  * flap_rad)
        flap = np.outer(q_flap, lm.flaperon.fs_rows)
        if run.model == "coupled":
            n = lm.n_modes
            z[:, 5 + 2 * n:] += np.outer(q_flap, lm.flaperon.force)
    values = {"force_summation": (lm.force_summation(z) + flap).reshape(shape)}
    static_all = lm.static_loads()
    static = {"force_summation": static_all["force_summation"]}
    if run.model in ("coupled", "qsd") and lm.md_matrix is not None:
        n = lm.n_modes
        eta = lm.static_eta_rad[None, :] + np.column_stack(
            [run[f"eta{i + 1}"] for i in range(n)])
        values["mode_displacement"] = lm.mode_displacement(eta).reshape(shape)
        static["mode_displacement"] = static_all["mode_displacement"]
    meta = {"speed_m_s": lm.speed_m_s, "static": lm.static_note,
            "gust": run.meta.get("gust"), "density_kg_m3": lm.density_kg_m3,
            "accelerations": "n_z: run channel; q_dot: central differences of q; "
                             "eta_ddot: the modal equation (loads/history.py)",
            "stopped": run.stopped, "mass": lm.mass_source}
    if lm.md_matrix is None:
        meta["mode_displacement_unavailable"] = lm.md_unavailable
    return SectionLoads(lm.wing, run.model, np.asarray(run.time_s, dtype=float), lm.stations_m,
                        lm.station_fractions, values, static,
                        (lm.force_summation(z, "aero") + flap).reshape(shape),
                        lm.force_summation(z, "inertia").reshape(shape), meta)


def with_load_channels(run: TimeHistory, loads: SectionLoads) -> TimeHistory:
    """A copy of ``run`` with the loads as channels (:meth:`SectionLoads.channels`:
    ``loads_<fs|md>_<quantity>_s<j>``, units N and N*m; the stations in
    ``meta['loads_stations_m']``): what a gust run would carry and a log would write."""
    if loads.time_s.shape != run.time_s.shape or not np.array_equal(loads.time_s, run.time_s):
        raise InputError("the loads were not computed from this run (other samples)")
    chans, units = loads.channels()
    return TimeHistory(run.model, run.time_s, {**run.channels, **chans},
                       {**run.units, **units},
                       {**run.meta, "loads_stations_m": loads.stations_m.tolist(),
                        "loads_static": loads.meta.get("static")}, run.stopped)


def loads_metrics(loads: SectionLoads, gust_start_s: float = 0.5) -> dict[str, object]:
    """The ``loads`` sub-dict of a run's metrics: per method, quantity and station the
    largest and smallest value after ``gust_start_s`` [s] with their times [s], the 1 g
    value and the increments over it (units in the names: N, N·m, s); the largest
    |FS − MD| beside them. A run that stopped early gives its values up to then
    (``stopped`` says so)."""
    after = loads.time_s >= gust_start_s
    out: dict[str, object] = {"stations_m": loads.stations_m.tolist(),
                              "station_fractions": list(loads.station_fractions),
                              "stopped": loads.meta.get("stopped"), "methods": {}}
    if not np.any(after):
        return out
    t = loads.time_s[after]
    for method in loads.methods:
        per_q = {}
        for qi, quantity in enumerate(QUANTITIES):
            rows = []
            for j in range(loads.stations_m.size):
                x = loads.values[method][after, qi, j]
                static = float(loads.static[method][qi, j])
                i_hi, i_lo = int(np.argmax(x)), int(np.argmin(x))
                rows.append({"station": loads.station_label(j),
                             "max": float(x[i_hi]), "time_max_s": float(t[i_hi]),
                             "min": float(x[i_lo]), "time_min_s": float(t[i_lo]),
                             "static_1g": static, "increment_up": float(x[i_hi]) - static,
                             "increment_down": float(x[i_lo]) - static})
            per_q[quantity] = rows
        out["methods"][method] = per_q
    diff = loads.difference()
    if diff is not None:
        out["max_abs_difference"] = {
            quantity: [float(np.max(np.abs(diff[after, qi, j])))
                       for j in range(loads.stations_m.size)]
            for qi, quantity in enumerate(QUANTITIES)}
    return out
