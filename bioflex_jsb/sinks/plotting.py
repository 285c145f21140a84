"""Plots: root loci and time histories (a flight's figure: :mod:`.flight_plot`).

Every figure is written with ``Software = "bioflex-jsb <version>"`` in its metadata
(:data:`SOFTWARE_TAG`), so a later run can tell a plot of ours (which it may replace) from a
user's file (which needs ``--force``): :func:`~bioflex_jsb.plot_files.is_our_plot`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; no display is needed or assumed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.backend_bases import FigureCanvasBase  # noqa: E402

from bioflex_jsb import __version__  # noqa: E402
from bioflex_jsb.flight_dynamics.eigen import Sweep  # noqa: E402
from bioflex_jsb.plot_files import is_our_plot  # noqa: F401 (the CLI's and tests' name)
from bioflex_jsb.simulation.results import TimeHistory  # noqa: E402

SOFTWARE_TAG = f"bioflex-jsb {__version__}"
DPI = 110

# One style per wing model, chosen to stay apart where the lines overlap: rigid thin black
# dash-dot, coupled a wide solid blue, QSD an orange dashed line drawn on top of it (the
# blue shows between the dashes where the two agree).
MODEL_STYLE = {
    "rigid": dict(color="black", ls="-.", lw=1.1, zorder=3),
    "coupled": dict(color="tab:blue", ls="-", lw=2.2, zorder=2),
    "qsd": dict(color="tab:orange", ls=(0, (5, 2.5)), lw=1.5, zorder=4),
    "native": dict(color="tab:green", ls="-", lw=1.4, zorder=3),
}
LOCUS_COLOURS = {"rigid": "black", "coupled": "tab:blue", "qsd": "tab:red"}
# Where the coupled and QSD roots agree (every rigid-body root of a stiff wing) one model's
# line would hide the other's: the coupled roots are drawn wide and pale underneath, the QSD
# roots thin with open markers on top, so both show.
LOCUS_LINE = {
    "rigid": dict(lw=1.0, zorder=3),
    "coupled": dict(lw=3.4, alpha=0.55, zorder=2),
    "qsd": dict(lw=1.0, zorder=4, markerfacecolor="none"),
}
MODE_MARKERS = {
    "short_period": ("o", "-"),
    "phugoid": ("s", "-"),
    "aeroelastic_1": ("^", "--"),
    "aeroelastic_2": ("v", ":"),
    "aeroelastic_3": ("D", "-."),
}
UNSTABLE_SHADE = dict(color="tab:red", alpha=0.06, lw=0)


def supported_formats() -> dict[str, str]:
    """File suffixes (no dot) that :func:`time_histories` and :func:`root_locus` can write."""
    return dict(FigureCanvasBase.get_supported_filetypes())


def save_figure(fig, path: str | Path) -> Path:
    """Write ``fig`` to ``path`` with the Software tag (:data:`SOFTWARE_TAG`) and close it."""
    out = Path(path)
    suffix = out.suffix.lower().lstrip(".")
    meta = {"Software": SOFTWARE_TAG} if suffix == "png" else {"Creator": SOFTWARE_TAG}
    fig.savefig(out, dpi=DPI, metadata=meta if suffix in ("png", "pdf", "svg") else None)
    plt.close(fig)
    return out


# ---------------------------------------------------------------------------------------
# Root loci
# ---------------------------------------------------------------------------------------
def _branches(sweep: Sweep):
    """(label, roots over the sweep) of each branch, upper half plane only: the samples of a
    branch below the real axis are NaN (a conjugate branch keeps its real-axis part, where a
    pair has split into two real roots)."""
    out = []
    for j, name in enumerate(sweep.labels):
        lam = np.array(sweep.eigenvalues[:, j], dtype=complex)
        below = lam.imag < -1e-9
        if np.all(below):
            continue
        lam[below] = complex(np.nan, np.nan)
        out.append((name, lam))
    return out


# below this relative gap the coupled and QSD branches coincide at the figure's scale (a
# line width in a zoom spanning |λ|), and the zoom says so
AGREE_NOTE_BELOW = 0.01
LABEL_CLEARANCE_PX = 18.0  # a speed label is left out nearer than this to one already placed


def _speed_labels(jobs, fig) -> None:
    """Write the airspeed [m/s] beside the root at each multiple of ``every_m_s`` of each job
    (ax, roots, speeds [m/s], colour, every_m_s), once the axes' limits and the layout are
    final: a label that would land within :data:`LABEL_CLEARANCE_PX` of one already written
    on the same axes (where a branch crowds, as the phugoid does at high speed) or outside
    the axes is left out; each branch's end speeds are placed first."""
    fig.canvas.draw()  # the final transforms
    placed: dict[int, list[np.ndarray]] = {}
    for ax, lam, speeds, colour, every_m_s in jobs:
        marks = np.arange(np.ceil(speeds[0] / every_m_s) * every_m_s, speeds[-1] + 1e-9,
                          every_m_s)
        order = sorted(range(len(marks)), key=lambda i: (0 if i in (0, len(marks) - 1)
                                                          else 1, i))
        box = ax.get_window_extent()
        for i in order:
            v = marks[i]
            k = int(np.argmin(np.abs(speeds - v)))
            if abs(speeds[k] - v) > 1e-6 or not np.isfinite(lam[k]):
                continue
            xy = ax.transData.transform((lam[k].real, lam[k].imag))
            if not box.contains(*xy):
                continue
            mine = placed.setdefault(id(ax), [])
            if any(np.hypot(*(xy - p)) < LABEL_CLEARANCE_PX for p in mine):
                continue
            mine.append(xy)
            # beside the branch, not on it: offset along its normal (left of travel)
            ends = [j for j in (k - 1, k + 1) if 0 <= j < len(lam) and np.isfinite(lam[j])]
            d = (ax.transData.transform((lam[max(ends)].real, lam[max(ends)].imag))
                 - ax.transData.transform((lam[min(ends)].real, lam[min(ends)].imag))
                 if len(ends) == 2 else np.array([1.0, 0.0]))
            n = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9)
            ax.annotate(f"{v:g}", (lam[k].real, lam[k].imag), textcoords="offset pixels",
                        xytext=tuple(11.0 * n), fontsize=7, color=colour, ha="center",
                        va="center", zorder=7,
                        bbox=dict(boxstyle="round,pad=0.15", facecolor="white", alpha=0.8,
                                  lw=0))


def _agreement(sweeps: Sequence[Sweep], name: str, a: str = "coupled", b: str = "qsd"
               ) -> float | None:
    """The largest |λ_a − λ_b| / |λ_a| [-] of branch ``name`` between models ``a`` and ``b``
    over the speeds both swept; None if either lacks it."""
    by_model = {s.model: s for s in sweeps}
    if a not in by_model or b not in by_model or name not in by_model[a].labels \
            or name not in by_model[b].labels:
        return None
    sa, sb = by_model[a], by_model[b]
    va, vb = np.asarray(sa.speeds_m_s, dtype=float), np.asarray(sb.speeds_m_s, dtype=float)
    common = np.intersect1d(va, vb)
    if not len(common):
        return None
    la = sa.eigenvalues[np.searchsorted(va, common), sa.labels.index(name)]
    lb = sb.eigenvalues[np.searchsorted(vb, common), sb.labels.index(name)]
    rel = np.abs(la - lb) / np.maximum(np.abs(la), 1e-12)
    return float(np.nanmax(rel)) if np.any(np.isfinite(rel)) else None


def _box(points: np.ndarray, margin: float = 0.12, min_span: float = 0.2):
    """Axis limits that hold ``points`` (complex) with a margin, the imaginary axis from 0."""
    points = points[np.isfinite(points)]
    re, im = points.real, points.imag
    x0, x1 = float(re.min()), float(re.max())
    y0, y1 = min(0.0, float(im.min())), float(im.max())
    dx, dy = max(x1 - x0, min_span), max(y1 - y0, min_span)
    return (x0 - margin * dx, x1 + margin * dx), (y0 - margin * dy, y1 + margin * dy)


def root_locus(sweeps: Sequence[Sweep], path: str | Path, title: str,
               note: str | None = None) -> Path:
    """Root loci of one or more models over their speed sweeps (Figs. 15, 16, 18, 19).

    Four panels, rad/s on every axis: (a) every root of every model; (b) the short period,
    zoomed so that it holds every root of that branch, also where it turns real and
    unstable; (c) the phugoid, zoomed; (d) the growth rate Re λ of each mode against the
    airspeed [m/s], where a crossing of zero is a flutter or divergence speed. Colour = model
    (rigid black, coupled wide pale blue underneath, QSD thin red with open markers on top,
    so that both show where they agree), marker and line style = mode; numbers beside the
    roots are airspeeds [m/s], arrows point to increasing speed; the right half plane
    (unstable) is shaded. ``note``: a line under the panels (which rigid block the models
    have: their phugoid depends on it).
    """
    fig, axes = plt.subplots(2, 2, figsize=(14, 11))
    ax_all, ax_sp, ax_ph, ax_re = axes.flat
    sp_points, ph_points = [], []
    label_jobs: list[tuple] = []  # speed labels, written once the layout is final
    v_lo = min(float(s.speeds_m_s[0]) for s in sweeps)
    v_hi = max(float(s.speeds_m_s[-1]) for s in sweeps)
    for sweep in sweeps:
        colour = LOCUS_COLOURS.get(sweep.model, "tab:gray")
        speeds = np.asarray(sweep.speeds_m_s, dtype=float)
        seen: set[str] = set()
        growth: dict[str, np.ndarray] = {}
        for j, name in enumerate(sweep.labels):
            re = sweep.eigenvalues[:, j].real
            growth[name] = np.maximum(growth.get(name, re), re)
        for name, lam in _branches(sweep):
            marker, ls = MODE_MARKERS.get(name, (".", "-"))
            label = None if name in seen else f"{sweep.model}: {name}"
            seen.add(name)
            targets = [ax_all]
            if name == "short_period":
                targets.append(ax_sp)
                sp_points.append(lam)
            elif name == "phugoid":
                targets.append(ax_ph)
                ph_points.append(lam)
            line = LOCUS_LINE.get(sweep.model, dict(lw=1.0, zorder=3))
            for ax in targets:
                ax.plot(lam.real, lam.imag, ls=ls, color=colour, marker=marker,
                        ms=5 if sweep.model == "qsd" else 3,
                        markevery=max(1, len(lam) // 25), label=label, **line)
                step = max(1, len(lam) // 5)
                for k in range(step, len(lam), step):
                    if not (np.isfinite(lam[k]) and np.isfinite(lam[k - 1])):
                        continue
                    ax.annotate("", xy=(lam[k].real, lam[k].imag),
                                xytext=(lam[k - 1].real, lam[k - 1].imag),
                                arrowprops=dict(arrowstyle="->", color=colour, lw=1.1))
                unstable = np.nan_to_num(lam.real, nan=-1.0) > 0.0
                if np.any(unstable):
                    ax.plot(lam.real[unstable], lam.imag[unstable], ls="none", marker="x",
                            color="tab:red", ms=5, mew=1.2)
            if name.startswith("aeroelastic") or name == "short_period":
                label_jobs.append((ax_all, lam, speeds, colour, 10.0))
            if name == "short_period":
                label_jobs.append((ax_sp, lam, speeds, colour, 5.0))
            if name == "phugoid":
                label_jobs.append((ax_ph, lam, speeds, colour, 5.0))
        for name, re in growth.items():
            marker, ls = MODE_MARKERS.get(name, (".", "-"))
            line = LOCUS_LINE.get(sweep.model, dict(lw=1.0, zorder=3))
            ax_re.plot(speeds, re, ls=ls, color=colour, marker=marker,
                       ms=5 if sweep.model == "qsd" else 3,
                       markevery=max(1, len(speeds) // 12), label=f"{sweep.model}: {name}",
                       **line)
    ax_all.set_title(f"(a) {title}: all roots, {v_lo:g}–{v_hi:g} m/s "
                     "(numbers: airspeed [m/s])", fontsize=10)
    ax_sp.set_title("(b) short period (zoom; × = unstable root)", fontsize=10)
    ax_ph.set_title("(c) phugoid (zoom)", fontsize=10)
    ax_re.set_title("(d) growth rate of each mode: Re λ > 0 is unstable", fontsize=10)
    for ax, points in ((ax_sp, sp_points), (ax_ph, ph_points)):
        if points:
            (x0, x1), (y0, y1) = _box(np.concatenate(points))
            ax.set_xlim(x0, x1)
            ax.set_ylim(y0, y1)
    for ax in (ax_all, ax_sp, ax_ph):
        x0, x1 = ax.get_xlim()
        if x1 > 0.0:
            ax.axvspan(0.0, x1, **UNSTABLE_SHADE)
            ax.set_xlim(x0, x1)
        ax.axvline(0.0, color="0.5", lw=0.8)
        ax.set_xlabel("Re λ [rad/s]")
        ax.set_ylabel("Im λ [rad/s]")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    ax_re.axhline(0.0, color="0.3", lw=0.9)
    y0, y1 = ax_re.get_ylim()
    if y1 > 0.0:
        ax_re.axhspan(0.0, y1, **UNSTABLE_SHADE)
        ax_re.set_ylim(y0, y1)
    ax_re.set_xlabel("airspeed [m/s]")
    ax_re.set_ylabel("Re λ [rad/s]")
    ax_re.grid(True, alpha=0.3)
    ax_re.legend(fontsize=7, loc="best", ncol=2)
    for ax, name in ((ax_sp, "short_period"), (ax_ph, "phugoid")):
        gap = _agreement(sweeps, name)
        if gap is not None and gap < AGREE_NOTE_BELOW:  # coinciding lines: say so
            ax.text(0.02, 0.02, f"coupled and QSD roots agree within {100 * gap:.2g} % of |λ|"
                    " here:\nthe wide pale blue line lies under the red one",
                    transform=ax.transAxes, fontsize=8, va="bottom", ha="left",
                    bbox=dict(facecolor="white", alpha=0.85, lw=0))
    if note:
        fig.text(0.5, 0.005, note, ha="center", va="bottom", fontsize=9, color="0.2",
                 wrap=True)
        fig.tight_layout(rect=(0.0, 0.03, 1.0, 1.0))
    else:
        fig.tight_layout()
    _speed_labels(label_jobs, fig)
    return save_figure(fig, path)


# ---------------------------------------------------------------------------------------
# Time histories
# ---------------------------------------------------------------------------------------
TIME_PANELS = (
    ("u", "Δu [m/s]", 1.0),
    ("alpha", "Δα [deg]", 180.0 / np.pi),
    ("q", "q [deg/s]", 180.0 / np.pi),
    ("theta", "Δθ [deg]", 180.0 / np.pi),
    ("n_z", "n_z [-]", 1.0),
    ("w_g", "gust w_g [m/s] (up)", 1.0),
    ("eta1", "{label}, 0.1 s envelope", None),  # scale: ModeDisplay's
    ("eta1_zoom", "{label}, gust onset", None),
)
DEG = 180.0 / np.pi
# The lateral-directional panels of a run that rolls (a full-span run, a gust that varies
# over the aircraft: its channels p_rad_s …), in the sign conventions of
# simulation/channels.py. Two panels are chosen by what the runs carry: the aileron (the
# command over the trim when a controller flew, else the surfaces' δa) and the gust input
# (its roll rate p_g when it has one, else its lateral v_g).
LATERAL_PANELS = (
    ("beta_rad", "β [deg]", DEG),
    ("p_rad_s", "p [deg/s]", DEG),
    ("r_rad_s", "r [deg/s]", DEG),
    ("phi_rad", "φ [deg]", DEG),
    ("aileron", "", DEG),
    ("lateral_gust", "", None),
    ("asym_eta1", "η_a1 [deg]", DEG),
    ("modal_roll_n_m", "modes' rolling moment [N·m]", 1.0),
)
AILERON_PANELS = {
    "ctrl_aileron_rad": "δa command over trim [deg]",
    "aileron_rad": "aileron δa [deg]",
}
LATERAL_GUST_PANELS = {
    "p_g": ("gust roll rate p_g [deg/s]", DEG),
    "v_g": ("lateral gust v_g [m/s]", 1.0),
}
LATERAL_NOTE = ("Lateral signs: β wind from starboard +; p, φ, p_g, rolling moment right wing "
                "down +; r nose right +; δa rolls right +; v_g to starboard +; η_a1 the "
                "coordinate of antisymmetric mode 1 (docs/lateral.md)")
INPUT_CHANNELS = ("w_g", "p_g", "v_g")  # the gust's samples: drawn once, in black
# what a lateral panel says when no run carries its channel (a half-wing run that rolls)
_HALF_WING = "the half wing: no antisymmetric modes (--span full flies both halves)"
ABSENT = {"asym_eta1": _HALF_WING, "modal_roll_n_m": _HALF_WING,
          "aileron_rad": "no aileron input in these runs"}
ENVELOPE_NOTE = "Left: its running mean, the running min/max over 0.1 s shaded"
# Runs that share a model's style (e.g. two wings flown with the same model) get these
# colours instead, in order, so that every line in a figure can be told apart.
EXTRA_COLOURS = ("tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")
ENVELOPE_WINDOW_S = 0.1  # η₁ envelope: max/min over 0.1 s (three cycles of a 31 Hz mode)
ZOOM_BEFORE_S, ZOOM_AFTER_S = 0.05, 0.35  # the η₁ zoom around the gust onset [s]


class ModeDisplay:
    """How a figure draws wing mode ``mode`` (1-based) of ``runs``: as what its coordinate η
    [rad] does at the wing tip (``run.meta["mode_tips"]``, :func:`~bioflex_jsb.simulation.
    channels.mode_tips`): the tip twist [deg] of a twisting mode (the prototype's three), the
    tip deflection [m, up] of a bending one (a sailplane's first). Runs without the shape (an
    LTI prediction) take the other runs'; runs whose wings disagree (one twists, one bends)
    or that carry no shape at all are drawn as η itself [deg], and the note says so.

    ``scale(run)``: the factor from η [rad] to the drawn unit; ``label``: the axis label
    without the unit's brackets … with them (``label``); ``note``: one line for the figure."""

    def __init__(self, runs: Sequence[TimeHistory], mode: int = 1):
        self.mode = mode
        sub = "₁₂₃₄₅₆₇₈₉"[mode - 1] if 1 <= mode <= 9 else str(mode)
        tips: dict[int, dict] = {}
        for run in runs:
            table = run.meta.get("mode_tips")
            if isinstance(table, Sequence) and len(table) >= mode and isinstance(
                    table[mode - 1], Mapping):
                tips[id(run)] = table[mode - 1]
        kinds = {str(t.get("quantity")) for t in tips.values()}
        self._tips = tips
        self._default = next(iter(tips.values()), None)
        if len(kinds) == 1 and kinds <= {"tip twist", "tip deflection"}:
            self.quantity = kinds.pop()
            twist = self.quantity == "tip twist"
            self.unit = "deg" if twist else "m"
            self.label = f"η{sub} tip {'twist' if twist else 'deflection'} [{self.unit}]"
            self.note = (f"η{sub}: wing mode {mode}, drawn as the tip "
                         + ("twist it makes (leading edge up +)" if twist else
                            "deflection it makes (a bending mode; up +)"))
        else:
            self.quantity, self.unit = "eta", "deg"
            self.label = f"η{sub} [deg]"
            why = ("the wings' modes differ (one twists, one bends)" if len(kinds) > 1 else
                   "the runs do not carry its shape")
            self.note = (f"η{sub}: the coordinate of wing mode {mode} in degrees ({why}; "
                         "docs/conventions.md for its scaling)")

    def scale(self, run: TimeHistory) -> float:
        if self.quantity == "eta":
            return 180.0 / np.pi
        tip = self._tips.get(id(run), self._default)
        per_rad = float(tip["per_rad"])
        return per_rad * 180.0 / np.pi if self.unit == "deg" else per_rad


def _style(run: TimeHistory) -> dict:
    style = dict(MODEL_STYLE.get(run.model, dict(color=None, ls="-", lw=1.2, zorder=2)))
    for key, meta in (("color", "color"), ("ls", "linestyle"), ("lw", "linewidth")):
        if meta in run.meta:
            style[key] = run.meta[meta]
    return style


def running_envelope(t: np.ndarray, x: np.ndarray, window_s: float):
    """Running minimum, maximum and mean of ``x`` over windows of ``window_s`` [s]."""
    if len(t) < 2:
        return t, x, x, x
    n = max(1, int(round(window_s / float(t[1] - t[0]))))
    k = len(x) // n
    if k < 2:
        return t, x, x, x
    blocks = x[: k * n].reshape(k, n)
    tc = t[: k * n].reshape(k, n).mean(axis=1)
    return tc, blocks.min(axis=1), blocks.max(axis=1), blocks.mean(axis=1)


def _gust_onset(runs: Sequence[TimeHistory]) -> float:
    for run in runs:
        if "gust_start_s" in run.meta:
            return float(run.meta["gust_start_s"])
    for run in runs:
        if "w_g" in run.channels and len(run.time_s):
            nz = np.nonzero(np.abs(run["w_g"]) > 0.0)[0]
            if len(nz):
                return float(run.time_s[nz[0]])
    return 0.0


@dataclass
class _Panels:
    """What every panel of :func:`time_histories` shares: the runs, their styles, the mode
    shown for η₁, the gust onset and the η₁ zoom's centre [s], the NRMSE labels."""

    runs: Sequence[TimeHistory]
    shown: ModeDisplay
    styles: dict[int, dict]
    t_gust: float
    t_zoom: float
    t_end: float
    nrmse: Mapping[str, float] | None

    @classmethod
    def of(cls, runs: Sequence[TimeHistory], nrmse: Mapping[str, float] | None) -> _Panels:
        t_gust = _gust_onset(runs)
        elastic = [r for r in runs if r.model != "rigid" and "eta1" in r.channels]
        t_zoom = t_gust  # the η₁ zoom: the gust onset, or where the wing diverged before it
        if elastic and all(r.stopped is not None and r.stop_time_s < t_gust for r in elastic):
            t_zoom = max(r.stop_time_s for r in elastic) - ZOOM_AFTER_S + ZOOM_BEFORE_S
        t_end = max((float(r.time_s[-1]) for r in runs if len(r.time_s)), default=1.0)
        return cls(runs, ModeDisplay([r for r in runs if r.model != "rigid"]),
                   _distinct_styles(runs), t_gust, t_zoom, t_end, nrmse)

    def draw(self, ax, name: str, ylabel: str, scale: float | None) -> None:
        """One panel: every run's ``name`` channel, the diverged runs' ×, limits and labels;
        a channel no run carries (the half wing's antisymmetric mode): a note instead."""
        channel = "eta1" if name == "eta1_zoom" else name
        if not self._runs_on(name, channel):
            ax.text(0.5, 0.5, ABSENT.get(channel, "not in these runs"), transform=ax.transAxes,
                    ha="center", va="center", color="0.45", fontsize=9)
            ax.set_ylabel(ylabel)
            ax.set_xlim(0.0, self.t_end)
            ax.set_yticks([])
            return
        zoom = ((self.t_zoom - ZOOM_BEFORE_S, self.t_zoom + ZOOM_AFTER_S)
                if name == "eta1_zoom" else None)
        limits: list[float] = []
        stops: list[tuple[float, float]] = []  # (t [s], value) where a diverged run ends
        for run in self._runs_on(name, channel):
            self._line(ax, run, name, channel, scale, zoom, limits, stops)
        if limits and any(r.stopped is not None and channel in r.channels for r in self.runs):
            lo, hi = min(limits), max(limits)
            pad = 0.15 * max(hi - lo, 1e-9)
            ax.set_ylim(lo - pad, hi + pad)  # diverged runs are clipped, their × at the edge
            stops = [(t, float(np.clip(y, lo - pad, hi + pad))) for t, y in stops]
        for t_stop, y_stop in stops:
            ax.plot([t_stop], [y_stop], marker="X", color="tab:red", ms=9, ls="none",
                    zorder=6, clip_on=False)
        ax.set_xlim(*(zoom if zoom is not None else (0.0, self.t_end)))
        if self.t_gust > 0.0 and (zoom is None or zoom[0] <= self.t_gust <= zoom[1]):
            ax.axvline(self.t_gust, color="0.6", lw=0.7, ls=":")
        ax.set_ylabel(ylabel.format(label=self.shown.label))
        ax.grid(True, alpha=0.3)
        if self.nrmse is not None or name in INPUT_CHANNELS:
            ax.legend(fontsize=7, loc="best")  # NRMSE differs by panel: a legend in each

    def _runs_on(self, name: str, channel: str) -> list[TimeHistory]:
        """The runs drawn on a panel: those with the channel and samples; η₁ of elastic runs
        only (the rigid wing does not deform); the gust input once (every run flies the
        same samples)."""
        out = [r for r in self.runs if channel in r.channels and len(r.time_s)
               and not (channel == "eta1" and r.model == "rigid")]
        return out[:1] if name in INPUT_CHANNELS else out

    def _label(self, run: TimeHistory, name: str, channel: str) -> str:
        if name in INPUT_CHANNELS:
            gust_text = str(run.meta.get("gust", "") or "")
            return f"{name}, gust {gust_text}" if gust_text else name
        label = str(run.meta.get("label", run.model))
        if (self.nrmse is not None and run.meta.get("source") == "lti"
                and channel in self.nrmse):
            label += f", NRMSE {self.nrmse[channel]:.3f}"
        if run.stopped is not None:
            label += f" (diverged at t = {run.stop_time_s:.2f} s)"
        return label

    def _line(self, ax, run: TimeHistory, name: str, channel: str, scale: float | None,
              zoom: tuple[float, float] | None, limits: list[float],
              stops: list[tuple[float, float]]) -> None:
        """One run's line on a panel (η₁ as its running envelope and mean); the finished
        runs' extremes go to ``limits``, a diverged run's last point to ``stops``."""
        style = (dict(color="black", ls="-", lw=1.2, zorder=2) if name in INPUT_CHANNELS
                 else dict(self.styles[id(run)]))
        t, y = run.time_s, run[channel] * (self.shown.scale(run) if scale is None else scale)
        label = self._label(run, name, channel)
        if zoom is not None:
            keep = (t >= zoom[0]) & (t <= zoom[1])
            t, y = t[keep], y[keep]
            if not len(t):
                return
        if name == "eta1" and len(t) > 2:
            tc, lo, hi, mean = running_envelope(t, y, ENVELOPE_WINDOW_S)
            ax.fill_between(tc, lo, hi, color=style["color"], alpha=0.18, lw=0,
                            zorder=style["zorder"] - 1)
            ax.plot(tc, mean, label=label, **style)
            extremes = [float(lo.min()), float(hi.max())]
        else:
            ax.plot(t, y, label=label, **style)
            extremes = [float(y.min()), float(y.max())]
        if run.stopped is None:
            limits += extremes
        elif name not in INPUT_CHANNELS and (zoom is None or run.time_s[-1] <= zoom[1]):
            stops.append((float(t[-1]), float(y[-1])))


def _figure_legend(fig, axes) -> None:
    """One legend for the figure (the same lines in every panel; not the gust input's)."""
    handles: dict[str, object] = {}
    for ax in axes.flat:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if not label.startswith(INPUT_CHANNELS):
                handles.setdefault(label, handle)
    if handles:
        fig.legend(list(handles.values()), list(handles), loc="upper center",
                   ncol=min(len(handles), 4), fontsize=9, frameon=False,
                   bbox_to_anchor=(0.5, 0.975))


def time_histories(runs: Sequence[TimeHistory], path: str | Path, title: str,
                   nrmse: Mapping[str, float] | None = None) -> Path:
    """Gust time histories of several runs on shared axes (like Figs. 21 and 22).

    Eight panels against time [s]: Δu, Δα, q, Δθ, n_z, the gust input w_g, the first wing
    mode η₁ as an envelope (running min/max over 0.1 s, shaded, with the running mean: the
    31 Hz oscillation would otherwise fill a solid band) and η₁ itself around the gust onset;
    η₁ drawn as the tip twist [deg] or, for a bending mode, the tip deflection [m] it makes
    (:class:`ModeDisplay`). A run that stopped
    early (diverged) ends in a red × on every panel and says when in the legend; the axes
    are scaled to the runs that finished, so they stay readable. ``nrmse`` (channel →
    NRMSE [-]) labels the LTI prediction's line in every panel (``compare``).

    Runs that roll (a full-span run, a gust that varies over the aircraft: any run with the
    channel ``p_rad_s``) get eight lateral-directional panels beside those
    (:data:`LATERAL_PANELS`: β, p, r, φ [deg, deg/s], the aileron [deg], the gust's roll rate
    p_g [deg/s] or lateral v_g [m/s], the first antisymmetric mode η_a1 [deg] and the
    modes' rolling moment [N·m]); the figure's first eight axes stay the longitudinal ones.
    """
    lateral = _lateral_panels(runs)
    cols = 4 if lateral else 2
    fig = plt.figure(figsize=(12 * cols / 2, 12.6))
    grid = fig.add_gridspec(4, cols)
    # made column block by column block: the longitudinal axes are fig.axes[:8] (callers and
    # tests index them), the lateral ones after them
    axes = np.empty((4, cols), dtype=object)
    for c0 in range(0, cols, 2):
        for r in range(4):
            for c in (c0, c0 + 1):
                axes[r, c] = fig.add_subplot(grid[r, c])
    longitudinal = axes[:, :2]
    panels = _Panels.of(runs, nrmse)
    for ax, (name, ylabel, scale) in zip(longitudinal.flat, TIME_PANELS, strict=True):
        panels.draw(ax, name, ylabel, scale)
    if lateral:
        for ax, (name, ylabel, scale) in zip(axes[:, 2:].flat, lateral, strict=True):
            panels.draw(ax, name, ylabel, scale)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    fig.suptitle(title, y=0.995)
    if nrmse is None:
        _figure_legend(fig, axes)
    notes = []
    if any("eta1" in r.channels and r.model != "rigid" for r in runs):
        notes.append(f"{panels.shown.note}. {ENVELOPE_NOTE}")
    if lateral:
        notes.append(LATERAL_NOTE)
    if notes:
        fig.text(0.5, 0.004, "\n".join(notes), ha="center", va="bottom", fontsize=8,
                 color="0.25", wrap=True)
    top = 0.955 if nrmse is None else 0.98
    fig.tight_layout(rect=(0.0, 0.02 * max(len(notes), 1), 1.0,
                           top - (0.02 if lateral else 0.0)))
    if lateral:  # each block's heading over its two columns
        for block, text in ((axes[0, :2], "longitudinal"), (axes[0, 2:], "lateral-directional")):
            left, right = block[0].get_position(), block[1].get_position()
            fig.text(0.5 * (left.x0 + right.x1), right.y1 + 0.012, text, ha="center",
                     va="bottom", fontsize=11, fontweight="bold")
    return save_figure(fig, path)


def _lateral_panels(runs: Sequence[TimeHistory]) -> tuple | None:
    """:data:`LATERAL_PANELS` with the aileron and gust panels chosen for ``runs`` (None:
    no run rolls)."""
    if not any("p_rad_s" in r.channels for r in runs):
        return None

    def carried(name: str) -> bool:
        return any(name in r.channels for r in runs)

    def blows(name: str) -> bool:
        return any(name in r.channels and np.any(np.asarray(r[name]) != 0.0) for r in runs)

    aileron = next((c for c in AILERON_PANELS if carried(c)), "aileron_rad")
    gust = next((c for c in LATERAL_GUST_PANELS if blows(c)),
                next((c for c in LATERAL_GUST_PANELS if carried(c)), "p_g"))
    out = []
    for name, ylabel, scale in LATERAL_PANELS:
        if name == "aileron":
            name, ylabel = aileron, AILERON_PANELS[aileron]
        elif name == "lateral_gust":
            name, (ylabel, scale) = gust, LATERAL_GUST_PANELS[gust]
        out.append((name, ylabel, scale))
    return tuple(out)


def _distinct_styles(runs: Sequence[TimeHistory]) -> dict[int, dict]:
    """Each run's line style; a run whose colour and dash repeat an earlier run's gets the
    next of :data:`EXTRA_COLOURS` (and a solid line), so no two runs look alike."""
    out: dict[int, dict] = {}
    seen: set[tuple[str, str]] = set()
    extra = iter(EXTRA_COLOURS)
    for run in runs:
        style = _style(run)
        key = (str(style.get("color")), str(style.get("ls")))
        if key in seen:
            style = dict(style, color=next(extra, "0.4"), ls="-", lw=1.6)
            key = (str(style["color"]), "-")
        seen.add(key)
        out[id(run)] = style
    return out


def gust_figure(runs, path: str | Path, title: str | None = None, force: bool = False
                ) -> Path:
    """:func:`time_histories` of ``runs`` (a TimeHistory, a sequence of them or a dict of
    them: ``api.fly_gust``'s) to ``path`` (:func:`~bioflex_jsb.plot_files.check_plot_target`:
    a figure suffix; an existing file only if it is a plot of ours, or ``force``); ``title``
    None: the first run's wing, speed and gust (the ``gust`` command's). InputError, one
    line, for anything that is not runs."""
    from bioflex_jsb.errors import InputError
    from bioflex_jsb.plot_files import check_plot_target

    if isinstance(runs, TimeHistory):
        runs = [runs]
    elif isinstance(runs, Mapping):
        runs = list(runs.values())
    elif not isinstance(runs, str | bytes) and isinstance(runs, Iterable):
        runs = list(runs)
    else:
        raise InputError(f"runs: a TimeHistory, a sequence of them or fly_gust's dict, not "
                         f"{type(runs).__name__}")
    wrong = [type(r).__name__ for r in runs if not isinstance(r, TimeHistory)]
    if wrong or not runs:
        raise InputError("runs: give one TimeHistory or more (fly_gust's results), not "
                         + (wrong[0] if wrong else "none"))
    if title is None:
        meta = runs[0].meta
        title = ", ".join(x for x in (
            f"{meta['wing']} wing" if meta.get("wing") else "",
            f"{meta['speed_m_s']:g} m/s" if isinstance(meta.get("speed_m_s"), float) else "",
            f"gust {meta['gust']}" if meta.get("gust") else "") if x)
    if not isinstance(title, str):
        raise InputError(f"title: a text, not {type(title).__name__}")
    return time_histories(runs, check_plot_target(path, force), title)
