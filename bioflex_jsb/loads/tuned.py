"""Tuned discrete gust: 1-cosine gusts over a range of gradient lengths, up and down; the
critical gradient per station, load quantity and method; correlated-load envelopes.

Gradient lengths (docs/loads.md, "Tuned gust"): the airworthiness codes (CS/FAR 25.341)
scale the gradient H from 9 to 107 m (30 to 350 ft) for transport aircraft, with the design
gust velocity U = U_ref (H / 107 m)^(1/6). Their range runs from gusts that are short for the
aircraft (a few chords: they excite the wing's own modes) to gusts long enough for the
short-period response to be quasi-static. For the 1.7 m span prototype at 15 m/s
(c̄ = 0.183 m, first wing mode 31 Hz, short period about 0.75 s) the same two ends are

* short: the gust time 2H/V at the first wing mode's period, H = V/(2 f₁) ≈ 0.24 m at 15 m/s
  (1.3 chords); the default starts there, at DEFAULT_H_MIN_CHORDS c̄ = 0.27 m;
* long: 2H/V two short-period periods, H = V T_sp ≈ 11 m; the default ends at
  DEFAULT_H_MAX_M = 15 m, past which a gust is a slow change of angle of attack for this
  aircraft.

Another aircraft (``--aircraft`` on its own JSBSim airframe) takes the same two ends from
its own data, :func:`aircraft_gust_scales`: the shortest DEFAULT_H_MIN_CHORDS of its mean
chord, the longest H = V T_sp with T_sp = 2π/ω_n its rigid short period's natural period at
the speed (ω_n = |λ|, defined for real roots too: an over-damped short period's slower root),
within the codes' 107 m; the run goes on 2 T_sp after the gust. For JSBSim's c172p at its
57.8 m/s cruise (ω_n 7.91 rad/s): H 2.24..45.9 m, 1.59 s after the gust. The prototype keeps
its defaults above, chosen by hand at the long end (its rule would give 15 × 0.594 = 8.9 m
with ω_n 10.6 rad/s, shorter than the 15 m its tables were measured with).

Amplitude: ``cs25`` scaling U = U_ref (H/H_max)^(1/6), the code's shape with the reference at
the longest gradient (U_ref default 3 m/s, the paper's gust), or ``fixed`` (every gust U_ref).
The 1-cos gust of ``simulation/gusts.py`` is given by its length L = 2H.

The flying is the caller's: :func:`tuned_gust` takes ``fly(gust_text, duration_s) ->
SectionLoads``, so it runs on any machinery; :func:`tuned_cases` and :func:`tuned_result`
are the two ends the command joins through the sweep executors (local processes or Dask:
:mod:`bioflex_jsb.sweep.tuned_loads`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.loads.model import QUANTITIES

DEFAULT_H_MIN_CHORDS = 1.5  # shortest gradient [chords]: near the first wing mode (above)
DEFAULT_H_MAX_M = 15.0  # longest gradient [m]: quasi-static short period at 15 m/s (above)
DEFAULT_N_LENGTHS = 10  # gradients, log-spaced
DEFAULT_AMPLITUDE_M_S = 3.0  # U_ref [m/s]: the paper's 3 m/s gust
SCALINGS = ("cs25", "fixed")
# After the gust has passed, the run goes on this long [s]: two short-period periods
# (0.7-0.9 s at 15 m/s, Table 3) for the peak of the response that follows the gust.
SETTLE_AFTER_S = 1.6
GUST_START_S = 0.2  # time before the gust [s]: the trim (the loads are steady from t = 0)


# The airworthiness codes' longest gradient [m]: CS/FAR 25.341(a)(2), 350 ft.
CODE_H_MAX_M = 350.0 * 0.3048


# The record of the default scales (the settings' ``scales``): the rule of the module
# docstring, chosen for the prototype.
DEFAULT_SCALES_SOURCE = "the prototype's defaults (loads/tuned.py)"


def default_gradients_m(mean_chord_m: float, n: int = DEFAULT_N_LENGTHS) -> np.ndarray:
    """``n`` log-spaced gradients H [m] from DEFAULT_H_MIN_CHORDS c̄ (``mean_chord_m`` [m],
    the aircraft's mean chord) to DEFAULT_H_MAX_M."""
    return np.geomspace(DEFAULT_H_MIN_CHORDS * mean_chord_m, DEFAULT_H_MAX_M, n)


@dataclass(frozen=True)
class GustScales:
    """The tuned gust's lengths and times for one aircraft at one speed: the shortest and
    longest gradient H [m] and how long each run goes on after its gust [s]."""

    h_min_m: float
    h_max_m: float
    settle_after_s: float
    source: str  # how they were found (the settings' record)

    def gradients_m(self, n: int = DEFAULT_N_LENGTHS) -> np.ndarray:
        """``n`` log-spaced gradients H [m] from h_min_m to h_max_m."""
        return np.geomspace(self.h_min_m, self.h_max_m, n)


def default_scales(mean_chord_m: float) -> GustScales:
    """The default scales (module docstring, chosen for the prototype) of an aircraft of
    mean chord ``mean_chord_m`` [m]: H from DEFAULT_H_MIN_CHORDS c̄ to DEFAULT_H_MAX_M,
    SETTLE_AFTER_S after the gust."""
    return GustScales(DEFAULT_H_MIN_CHORDS * mean_chord_m, DEFAULT_H_MAX_M, SETTLE_AFTER_S,
                      DEFAULT_SCALES_SOURCE)


def _settling(scales: GustScales | None) -> tuple[float, str]:
    """(the time a run goes on after its gust [s], the scales' record) of ``scales``; None
    (gradients given without scales): the defaults' SETTLE_AFTER_S."""
    if scales is None:
        return SETTLE_AFTER_S, DEFAULT_SCALES_SOURCE
    return scales.settle_after_s, scales.source


def aircraft_gust_scales(mean_chord_m: float, speed_m_s: float,
                         short_period_rad_s: float) -> GustScales:
    """The tuned gust's scales of an aircraft of mean chord ``mean_chord_m`` [m] at
    ``speed_m_s`` [m/s] whose rigid short period has the natural frequency
    ``short_period_rad_s`` ω_n = |λ| [rad/s] (module docstring): H from
    DEFAULT_H_MIN_CHORDS c̄ to V·2π/ω_n (at most CODE_H_MAX_M), 2·2π/ω_n after the gust."""
    for name, value in (("mean chord [m]", mean_chord_m), ("speed [m/s]", speed_m_s),
                        ("short-period frequency [rad/s]", short_period_rad_s)):
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"tuned gust: the aircraft's {name} must be positive, got "
                             f"{value!r}")
    period_s = 2.0 * math.pi / short_period_rad_s
    h_min = DEFAULT_H_MIN_CHORDS * mean_chord_m
    h_max = min(speed_m_s * period_s, CODE_H_MAX_M)
    if h_max <= h_min:
        raise InputError(f"tuned gust: the short period's {period_s:.3g} s at {speed_m_s:g} "
                         f"m/s gives a longest gradient {h_max:.3g} m, not above the "
                         f"shortest ({DEFAULT_H_MIN_CHORDS:g} chords, {h_min:.3g} m); give "
                         "--gradients")
    return GustScales(h_min, h_max, 2.0 * period_s,
                      f"{DEFAULT_H_MIN_CHORDS:g} c̄ to V·T_sp, T_sp = 2π/ω_n = "
                      f"{period_s:.3f} s (the rigid short period at {speed_m_s:g} m/s)")


def gust_scales(build, speed_m_s: float, density_kg_m3: float | None = None) -> GustScales:
    """The tuned gust's scales of the aircraft the wing ``build`` (a ``WingBuild``) was built
    for, at ``speed_m_s`` [m/s]: the prototype's defaults (:func:`default_scales`) on the
    default aircraft's airframe (definition/aircraft.py default_aircraft), else the
    aircraft's own (:func:`aircraft_gust_scales`: its mean chord and its rigid short period
    at the speed, in air of ``density_kg_m3`` [kg/m^3]; None: sea level)."""
    from bioflex_jsb.definition.aircraft import default_aircraft
    from bioflex_jsb.flight_dynamics.eigen import modes_at

    airframe = build.model.airframe
    chord_m = airframe.reference.mean_chord_m
    if airframe is default_aircraft().airframe_data():
        return default_scales(chord_m)
    density = {} if density_kg_m3 is None else {"density_kg_m3": density_kg_m3}
    sp = modes_at("rigid", [speed_m_s], build.model, **density)[0].get("short_period")
    return aircraft_gust_scales(chord_m, speed_m_s, sp.frequency_rad_s)


def gust_amplitude_m_s(h_m: float, u_ref_m_s: float, h_max_m: float, scaling: str) -> float:
    """U [m/s] of the gradient ``h_m``: U_ref (H/H_max)^(1/6) (cs25) or U_ref (fixed)."""
    if scaling not in SCALINGS:
        raise InputError(f"unknown amplitude scaling {scaling!r}; accepted: {', '.join(SCALINGS)}")
    return u_ref_m_s * (h_m / h_max_m) ** (1.0 / 6.0) if scaling == "cs25" else u_ref_m_s


@dataclass
class TunedGustResult:
    """The sweep: ``cases`` (one per gust: gradient, sign, amplitude, gust text),
    ``loads`` (the SectionLoads of each case), ``critical`` rows (docs: one per station,
    quantity, method and direction)."""

    cases: list[dict]
    loads: list = field(repr=False)
    critical: list[dict]
    stations_m: list[float]
    station_fractions: list[float]
    settings: dict

    def as_dict(self) -> dict:
        return {"settings": self.settings, "stations_m": self.stations_m,
                "station_fractions": self.station_fractions, "cases": self.cases,
                "critical": self.critical}

    def csv_rows(self) -> list[list]:
        head = ["station", "y_m", "quantity", "method", "direction", "critical_H_m",
                "gust_sign", "gust_amplitude_m_s", "gust", "value", "static_1g", "increment",
                "time_s"]
        rows = [head]
        for r in self.critical:
            rows.append([r[k] for k in ("station", "y_m", "quantity", "method", "direction",
                                        "gradient_m", "sign", "amplitude_m_s", "gust",
                                        "value", "static_1g", "increment", "time_s")])
        return rows


def tuned_cases(speed_m_s: float, gradients_m=None, *,
                u_ref_m_s: float = DEFAULT_AMPLITUDE_M_S, scaling: str = "cs25",
                scales: GustScales | None = None) -> list[dict]:
    """The sweep's gusts, in order: every gradient of ``gradients_m`` [m] (default
    ``scales.gradients_m()``: the aircraft's, :func:`default_scales` or
    :func:`aircraft_gust_scales`) up then down, each a dict of its gradient [m], sign,
    amplitude [m/s, up +], gust text (``1cos:U:L``, L = 2H), duration [s] (the gust, then
    ``scales.settle_after_s``, SETTLE_AFTER_S without scales) and gust start [s]."""
    if gradients_m is None and scales is None:
        raise ValueError("tuned gust: give the gradients [m] or the aircraft's scales")
    h = scales.gradients_m() if gradients_m is None else np.asarray(gradients_m, dtype=float)
    if h.ndim != 1 or h.size == 0 or not np.all(np.isfinite(h)) or np.any(h <= 0.0):
        raise InputError("gust gradients must be positive lengths [m]")
    if not (math.isfinite(u_ref_m_s) and u_ref_m_s > 0.0):
        raise InputError(f"gust amplitude must be a positive speed [m/s], got {u_ref_m_s!r}")
    h_max = float(h.max())
    settle_after_s, _ = _settling(scales)
    cases = []
    for hm in h:
        u = gust_amplitude_m_s(float(hm), u_ref_m_s, h_max, scaling)
        for sign in (1, -1):
            cases.append({"gradient_m": float(hm), "sign": "up" if sign > 0 else "down",
                          "amplitude_m_s": sign * u,
                          "gust": f"1cos:{sign * u:.6g}:{2.0 * hm:.6g}",
                          "duration_s": GUST_START_S + 2.0 * hm / speed_m_s
                          + settle_after_s,
                          "gust_start_s": GUST_START_S})
    return cases


def tuned_gust(fly, speed_m_s: float, gradients_m=None, *,
               u_ref_m_s: float = DEFAULT_AMPLITUDE_M_S, scaling: str = "cs25",
               progress=None, scales: GustScales | None = None) -> TunedGustResult:
    """Fly 1-cos gusts of every gradient in ``gradients_m`` [m] up and down through
    ``fly(gust_text, duration_s, gust_start_s)`` (returns a SectionLoads), one after the
    other, and find the critical cases (:func:`tuned_result`). The command flies the same
    cases on the sweep executors (:mod:`bioflex_jsb.sweep.tuned_loads`)."""
    cases = tuned_cases(speed_m_s, gradients_m, u_ref_m_s=u_ref_m_s, scaling=scaling,
                        scales=scales)
    loads = []
    for case in cases:
        loads.append(fly(case["gust"], case["duration_s"], case["gust_start_s"]))
        if progress is not None:
            progress(len(loads), len(cases), case["gust"])
    return tuned_result(cases, loads, speed_m_s, u_ref_m_s=u_ref_m_s, scaling=scaling,
                        scales=scales)


def tuned_result(cases: list[dict], loads: list, speed_m_s: float, *,
                 u_ref_m_s: float = DEFAULT_AMPLITUDE_M_S,
                 scaling: str = "cs25", scales: GustScales | None = None
                 ) -> TunedGustResult:
    """The critical case per station, quantity, method and direction (largest increment up,
    largest down, over the run after the gust start) of ``cases`` (:func:`tuned_cases`, in
    their order) and their SectionLoads ``loads`` (the same order)."""
    if len(cases) != len(loads) or not cases:
        raise ValueError(f"{len(cases)} cases and {len(loads)} section loads")
    cases = [dict(c, stopped=sl.meta.get("stopped")) for c, sl in zip(cases, loads,
                                                                      strict=True)]
    h = np.array(sorted({c["gradient_m"] for c in cases}))
    h_max = float(h.max())
    first = loads[0]
    critical = []
    for method in first.methods:
        for qi, quantity in enumerate(QUANTITIES):
            for j in range(first.stations_m.size):
                for direction in ("up", "down"):
                    best = None
                    for case, sl in zip(cases, loads, strict=True):
                        after = sl.time_s >= GUST_START_S
                        if not np.any(after):  # stopped before the gust (case["stopped"])
                            continue
                        x = sl.values[method][after, qi, j]
                        static = float(sl.static[method][qi, j])
                        i = int(np.argmax(x) if direction == "up" else np.argmin(x))
                        inc = float(x[i]) - static
                        if best is None or (inc > best["increment"] if direction == "up"
                                            else inc < best["increment"]):
                            best = {"station": first.station_label(j),
                                    "y_m": float(first.stations_m[j]), "quantity": quantity,
                                    "method": method, "direction": direction,
                                    "gradient_m": case["gradient_m"], "sign": case["sign"],
                                    "amplitude_m_s": case["amplitude_m_s"],
                                    "gust": case["gust"], "value": float(x[i]),
                                    "static_1g": static, "increment": inc,
                                    "time_s": float(sl.time_s[after][i])}
                    if best is not None:
                        critical.append(best)
    gradients = list(dict.fromkeys(c["gradient_m"] for c in cases))
    settle_after_s, source = _settling(scales)
    settings = {"speed_m_s": speed_m_s, "gradients_m": gradients, "u_ref_m_s": u_ref_m_s,
                "scaling": scaling, "h_max_m": h_max, "gust_start_s": GUST_START_S,
                "settle_after_s": settle_after_s, "scales": source,
                "model": first.model, "wing": first.wing,
                "static": first.meta.get("static")}
    for c in cases:
        del c["gust_start_s"]
    return TunedGustResult(cases, loads, critical, first.stations_m.tolist(),
                           list(first.station_fractions), settings)


def plot_envelopes(result: TunedGustResult, path=None, method: str = "force_summation"):
    """Correlated loads: bending moment against torque at every station, each gust's time
    history thin, the convex hull of all of them, and the critical cases of bending and
    torque (up and down) marked and labelled with their gradient and sign."""
    from scipy.spatial import ConvexHull

    from bioflex_jsb.loads.plots import new_figure, save

    stations = result.stations_m
    cols = min(len(stations), 2)
    rows = math.ceil(len(stations) / cols)
    fig, ax = new_figure(rows, cols, (5.6 * cols, 4.6 * rows))
    qb, qt = QUANTITIES.index("bending_n_m"), QUANTITIES.index("torque_n_m")
    h_all = np.array([c["gradient_m"] for c in result.cases])
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm, Normalize
    from matplotlib.lines import Line2D

    # colour = gradient length H [m] on a log scale (the lengths are log-spaced), with its bar
    norm = (LogNorm(h_all.min(), h_all.max()) if h_all.max() > h_all.min()
            else Normalize(h_all.min() * 0.9, h_all.max() * 1.1))
    cmap = plt.get_cmap("viridis")
    labels = []  # (axes, x, y, text) of the critical cases, written once the limits are set
    for j in range(len(stations)):
        a = ax[j // cols, j % cols]
        pts = []
        for case, sl in zip(result.cases, result.loads, strict=True):
            m, t = sl.values[method][:, qb, j], sl.values[method][:, qt, j]
            a.plot(t, m, lw=0.6, color=cmap(norm(case["gradient_m"])), alpha=0.8,
                   ls="-" if case["sign"] == "up" else "--")
            pts.append(np.column_stack([t, m]))
        pts = np.concatenate(pts)
        hull = ConvexHull(pts)
        loop = np.append(hull.vertices, hull.vertices[0])
        a.plot(pts[loop, 0], pts[loop, 1], color="k", lw=1.4, label="convex hull")
        s0 = result.loads[0].static[method]
        a.plot(s0[qt, j], s0[qb, j], "s", color="k", ms=6, mfc="w", label="1 g")
        for r in result.critical:
            if r["method"] != method or r["y_m"] != stations[j] or \
                    r["quantity"] not in ("bending_n_m", "torque_n_m"):
                continue
            k = next(i for i, c in enumerate(result.cases) if c["gust"] == r["gust"])
            sl = result.loads[k]
            i = int(np.argmin(np.abs(sl.time_s - r["time_s"])))
            x, y = sl.values[method][i, qt, j], sl.values[method][i, qb, j]
            mark = "^" if r["direction"] == "up" else "v"
            a.plot(x, y, mark, color="C3", ms=7)
            name = "M" if r["quantity"] == "bending_n_m" else "T"
            tag = f"{name}{'max' if r['direction'] == 'up' else 'min'}"
            labels.append((a, x, y, f"{tag} H={r['gradient_m']:.3g} m {r['sign']}"))
        a.set_title(f"{result.loads[0].station_label(j)} (y = {stations[j]:.3f} m)", fontsize=10)
        a.set_xlabel("torque T [N·m] (leading edge up +)")
        a.set_ylabel("bending moment M [N·m] (tip up +)")
        a.grid(True, alpha=0.3)
    for k in range(len(stations), rows * cols):
        ax[k // cols, k % cols].axis("off")
    for a, x, y, text in labels:  # inside the axes: towards its centre from the point
        (x0, x1), (y0, y1) = a.get_xlim(), a.get_ylim()
        right = x > 0.5 * (x0 + x1)
        above = y > 0.5 * (y0 + y1)
        a.annotate(text, (x, y), textcoords="offset points",
                   xytext=(-6 if right else 6, -6 if above else 6), fontsize=7, color="C3",
                   ha="right" if right else "left", va="top" if above else "bottom",
                   annotation_clip=True,
                   bbox=dict(boxstyle="round,pad=0.1", facecolor="white", alpha=0.75, lw=0))
    handles, names = ax[0, 0].get_legend_handles_labels()
    handles += [Line2D([], [], color="0.3", lw=0.8, ls="-"),
                Line2D([], [], color="0.3", lw=0.8, ls="--"),
                Line2D([], [], color="C3", marker="^", ls="none"),
                Line2D([], [], color="C3", marker="v", ls="none")]
    names += ["gust up", "gust down", "critical case, largest", "critical case, smallest"]
    fig.legend(handles, names, loc="outside lower center", ncol=6, fontsize=8)
    bar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), ax=ax, shrink=0.6,
                       pad=0.02)
    bar.set_label("gust gradient length H [m] (line colour)")
    lengths = np.unique(h_all)
    ticks = lengths if len(lengths) <= 10 else lengths[np.unique(
        np.round(np.linspace(0, len(lengths) - 1, 10)).astype(int))]
    bar.ax.minorticks_off()
    bar.set_ticks(ticks, labels=[f"{h:.2g}" for h in ticks])
    st = result.settings
    fig.suptitle(f"Correlated loads ({method.replace('_', ' ')}), wing {st['wing']}, "
                 f"{st['speed_m_s']:g} m/s, 1-cos gusts H = {min(st['gradients_m']):.2g}-"
                 f"{max(st['gradients_m']):.3g} m, up and down", fontsize=10)
    if path is not None:
        save(fig, path)
    return fig
