"""The figure of a flight: a ``sitl`` or ``ardupilot`` session's log as ``bioflex-jsb plot``
draws it (:func:`flight_figure`), with :mod:`.plotting`'s styles and file handling."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.sinks import plotting  # first: it selects matplotlib's file-only backend
from bioflex_jsb.sinks.plotting import ModeDisplay, running_envelope

# ---------------------------------------------------------------------------------------
# A flight (a SITL or ArduPilot session)
# ---------------------------------------------------------------------------------------
FLIGHT_POINTS = 4000  # samples drawn per line: a 600 s session at 960 Hz is 576 000 steps
MAX_EVENT_LABELS = 14  # events written on the figure; the rest are counted in the note
_DEG = 180.0 / np.pi  # rad to deg
# The smallest span each state axis shows, in its unit: a flight in still air holds its
# altitude to millimetres and its airspeed to 1e-3 m/s, which matplotlib would spread over
# the whole panel with an offset (+6.84e2) and ticks of 0.002 m; these spans show such a
# flight as level. About the sensors' noise or an autopilot's hold band: 2 m of altitude,
# 1 m/s of airspeed, 2 degrees of attitude and of α, 0.1 of load factor.
MIN_SPAN = {"altitude_m": 2.0, "airspeed_m_s": 1.0, "attitude_deg": 2.0, "n_z": 0.1,
            "alpha_deg": 2.0}


def _thinned(t: np.ndarray, x: np.ndarray):
    """(t, x) with at most about :data:`FLIGHT_POINTS` samples, for smooth channels."""
    step = max(1, len(t) // FLIGHT_POINTS)
    return t[::step], x[::step]


def _band(ax, t: np.ndarray, x: np.ndarray, colour, label: str, lw: float = 1.2):
    """``x`` as its running mean with the running min/max shaded, over windows that leave
    about :data:`FLIGHT_POINTS` samples (a wing mode's 30-110 Hz would fill a solid band)."""
    window = max(float(t[-1] - t[0]) / FLIGHT_POINTS, float(t[1] - t[0])) if len(t) > 1 else 1
    tc, lo, hi, mean = running_envelope(t, x, window)
    ax.fill_between(tc, lo, hi, color=colour, alpha=0.25, lw=0)
    ax.plot(tc, mean, color=colour, lw=lw, label=label)


def _heading(t: np.ndarray, deg: np.ndarray):
    """(t, heading [deg], lowest value shown [deg]): the heading in [0, 360) or, when that
    wraps more often (a flight about north), in [-180, 180), with a NaN where it wraps so
    that no line crosses the axis there. Rounded to 1e-6 deg first: JSBSim's ψ of a due-north
    flight alternates between 2π and 2π − 1e-14 rad."""
    best = None
    for low in (0.0, -180.0):
        out = np.mod(np.round(deg, 6) - low, 360.0) + low
        jumps = np.flatnonzero(np.abs(np.diff(out)) > 180.0) + 1
        if best is None or len(jumps) < len(best[2]):
            best = (low, out, jumps)
    low, out, jumps = best
    return np.insert(t, jumps, t[jumps]), np.insert(out, jumps, np.nan), low


def _events_merged(events: Sequence[Mapping], t_end: float) -> list[tuple[float, str]]:
    """(time [s], text) of the events within the run; those within 1 % of the run's length
    of the one before are joined to it (one number on the figure)."""
    out: list[tuple[float, str]] = []
    close_s = 0.01 * t_end
    for e in events:
        t, text = float(e["time_s"]), str(e["text"])
        if not 0.0 <= t <= t_end + 1e-9:
            continue
        if out and t - out[-1][0] <= close_s:
            out[-1] = (out[-1][0], f"{out[-1][1]}; {text}")
        else:
            out.append((t, text))
    return out


def _one_flight(runs: Sequence[TimeHistory]) -> tuple[TimeHistory, list[str]]:
    """The runs of one session (a SITL session logs the steps of each wing model under its
    own topics: ``WING_COUPLED`` switched in flight) as one run in time order, a channel
    that a run lacks NaN there; and which model flew when."""
    runs = sorted((r for r in runs if len(r.time_s)), key=lambda r: float(r.time_s[0]))
    if len(runs) == 1:
        return runs[0], []
    names = list(dict.fromkeys(n for r in runs for n in r.channels))
    t = np.concatenate([r.time_s for r in runs])
    order = np.argsort(t, kind="stable")
    channels = {n: np.concatenate([r.channels[n] if n in r.channels
                                   else np.full(len(r.time_s), np.nan) for r in runs])[order]
                for n in names}
    units = {n: u for r in runs for n, u in r.units.items()}
    meta = {k: v for r in reversed(runs) for k, v in r.meta.items()}
    spans = [f"{r.model} {float(r.time_s[0]):.1f}-{float(r.time_s[-1]):.1f} s" for r in runs]
    return TimeHistory("+".join(dict.fromkeys(r.model for r in runs)), t[order], channels,
                       units, meta), spans


def flight_figure(runs: TimeHistory | Sequence[TimeHistory], path: str | Path, title: str,
                  events: Sequence[Mapping] = ()) -> Path:
    """A flight (a ``sitl`` or ``ardupilot`` session's log; several runs of one session are
    joined in time order) against time [s]: altitude [m],
    airspeed [m/s], bank φ and pitch θ [deg], heading ψ [deg], each wing mode as the tip
    twist [deg] or tip deflection [m] it makes (:class:`ModeDisplay`; running mean, min/max
    shaded), load factor n_z [-] and angle of attack α [deg] (with the gust w_g [m/s] where
    one blew), and the track north against east [m] (the logged NED velocity integrated
    from the start). ``events``: the log's (time_s, text): numbered on every time axis and
    on the track, listed below the figure."""
    from matplotlib.gridspec import GridSpec

    run, spans = _one_flight([runs] if isinstance(runs, TimeHistory) else list(runs))
    t = np.asarray(run.time_s, dtype=float)
    fig = plt.figure(figsize=(15, 12.5))
    grid = GridSpec(5, 2, figure=fig, width_ratios=(1.35, 1.0), hspace=0.12, wspace=0.22)
    left = [fig.add_subplot(grid[0, 0])]
    left += [fig.add_subplot(grid[i, 0], sharex=left[0]) for i in range(1, 5)]
    ax_track = fig.add_subplot(grid[0:3, 1])
    ax_nz = fig.add_subplot(grid[3, 1], sharex=left[0])
    ax_alpha = fig.add_subplot(grid[4, 1], sharex=left[0])
    _state_panels(left[:4], run, t)
    notes = _mode_panel(left[4], run, t)
    _load_panels(ax_nz, ax_alpha, run, t)
    for ax in left + [ax_nz, ax_alpha]:
        ax.grid(True, alpha=0.3)
    for ax in left[:-1] + [ax_nz]:
        ax.tick_params(labelbottom=False)
    left[4].set_xlabel("time [s]")
    ax_alpha.set_xlabel("time [s]")
    left[0].set_xlim(float(t[0]), float(t[-1]))
    track = _track(ax_track, run, t)
    merged = _events_merged(events, float(t[-1]) if len(t) else 0.0)
    shown_events = merged[:MAX_EVENT_LABELS]
    _mark_events(shown_events, left + [ax_nz, ax_alpha], left[0], ax_track, t, track)
    ax_track.legend(fontsize=8, loc="best")
    fig.suptitle(title, y=0.995)
    fig.text(0.5, 0.005, _footnote(merged, shown_events, spans, notes), ha="center",
             va="bottom", fontsize=8, color="0.2", wrap=True)
    fig.subplots_adjust(left=0.06, right=0.95, top=0.955, bottom=0.1)
    return plotting.save_figure(fig, path)


def _plain_axis(ax, min_span: float | None = None) -> None:
    """``ax``'s y ticks as plain numbers (no offset or scientific notation) and, given
    ``min_span`` [the axis' unit], at least that span about the middle of the data."""
    ax.ticklabel_format(axis="y", style="plain", useOffset=False)
    low, high = ax.get_ylim()
    if min_span is not None and high - low < min_span:
        mid = 0.5 * (low + high)
        ax.set_ylim(mid - 0.5 * min_span, mid + 0.5 * min_span)


def _line(ax, run: TimeHistory, t: np.ndarray, name: str, scale: float = 1.0, **kw) -> None:
    """``run``'s channel ``name`` × ``scale`` against ``t`` [s] (thinned), if it has it."""
    if name in run.channels:
        ax.plot(*_thinned(t, run[name] * scale), **kw)


def _state_panels(axes, run: TimeHistory, t: np.ndarray) -> None:
    """Altitude [m], airspeed [m/s], bank and pitch [deg], heading [deg] (compass ticks)."""
    ax_alt, ax_v, ax_att, ax_psi = axes
    _line(ax_alt, run, t, "altitude_m", color="tab:blue", lw=1.3)
    ax_alt.set_ylabel("altitude [m] (MSL)")
    _line(ax_v, run, t, "airspeed_m_s", color="tab:blue", lw=1.3)
    ax_v.set_ylabel("airspeed [m/s]")
    _line(ax_att, run, t, "phi_rad", _DEG, color="tab:red", lw=1.3,
          label="bank φ (right wing down +)")
    _line(ax_att, run, t, "theta_rad", _DEG, color="tab:green", lw=1.3,
          label="pitch θ (nose up +)")
    ax_att.set_ylabel("attitude [deg]")
    ax_att.legend(fontsize=8, loc="best")
    _plain_axis(ax_alt, MIN_SPAN["altitude_m"])
    _plain_axis(ax_v, MIN_SPAN["airspeed_m_s"])
    _plain_axis(ax_att, MIN_SPAN["attitude_deg"])
    if "psi_rad" in run.channels:
        tt, psi = _thinned(t, run["psi_rad"] * _DEG)
        tt, psi, low = _heading(tt, psi)
        ax_psi.plot(tt, psi, color="tab:purple", lw=1.3)
        ticks = np.arange(low, low + 361.0, 90.0)
        ax_psi.set_ylim(low, low + 360.0)
        ax_psi.set_yticks(ticks, [f"{v:g} {'NESW'[int(v // 90) % 4]}" for v in ticks])
    ax_psi.set_ylabel("heading ψ [deg]")


def _mode_panel(ax_eta, run: TimeHistory, t: np.ndarray) -> dict[str, list[str]]:
    """Each wing mode as the quantity it makes (a twin axis per unit); the modes drawn by
    quantity, for the footnote."""
    modes = sorted(int(n[3:]) for n in run.channels if n.startswith("eta")
                   and n[3:].isdigit())
    notes: dict[str, list[str]] = {}  # quantity drawn -> the modes drawn so
    axes_by_unit: dict[str, object] = {}
    colours = ("tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown")
    for k, i in enumerate(modes):
        shown = ModeDisplay([run], i)
        ax = axes_by_unit.get(shown.unit)
        if ax is None:
            ax = ax_eta if not axes_by_unit else ax_eta.twinx()
            axes_by_unit[shown.unit] = ax
            what = {"deg": "tip twist [deg]" if shown.quantity != "eta" else "η [deg]",
                    "m": "tip deflection [m] (up +)"}[shown.unit]
            ax.set_ylabel(f"wing modes: {what}")
        _band(ax, t, run[f"eta{i}"] * shown.scale(run), colours[k % len(colours)],
              f"mode {i}" + (f" ({shown.unit})" if len(axes_by_unit) > 1 else ""))
        notes.setdefault(shown.quantity, []).append(str(i))
    for ax in axes_by_unit.values():
        _plain_axis(ax)
    if modes:
        handles = [h for ax in axes_by_unit.values() for h in ax.get_legend_handles_labels()[0]]
        ax_eta.legend(handles, [h.get_label() for h in handles], fontsize=8,
                      loc="upper right", ncol=len(handles))
    else:
        ax_eta.text(0.5, 0.5, "no wing modes in this log (rigid wing)", ha="center",
                    va="center", transform=ax_eta.transAxes)
    return notes


def _load_panels(ax_nz, ax_alpha, run: TimeHistory, t: np.ndarray) -> None:
    """Load factor n_z [-] (band) and angle of attack [deg], the gust [m/s] on a twin axis."""
    if "n_z" in run.channels:
        _band(ax_nz, t, run["n_z"], "tab:blue", "n_z")
    ax_nz.axhline(1.0, color="0.5", lw=0.7)
    ax_nz.set_ylabel("load factor n_z [-]")
    _plain_axis(ax_nz, MIN_SPAN["n_z"])
    _line(ax_alpha, run, t, "alpha_rad", _DEG, color="tab:blue", lw=1.3, label="α")
    ax_alpha.set_ylabel("angle of attack α [deg]")
    _plain_axis(ax_alpha, MIN_SPAN["alpha_deg"])
    gust = run.channels.get("w_g")
    if gust is not None and np.any(gust != 0.0):
        ax_w = ax_alpha.twinx()
        ax_w.plot(*_thinned(t, gust), color="black", lw=0.9)
        ax_w.set_ylabel("gust w_g [m/s] (up)")


def _track(ax_track, run: TimeHistory, t: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray] | None:
    """The track north against east [m] (the NED velocity integrated by trapezoids from the
    start), with time marks; (east, north) or None without the velocity."""
    track = None
    if "v_north_m_s" in run.channels and "v_east_m_s" in run.channels and len(t) > 1:
        dt = np.diff(t)
        north = np.concatenate([[0.0], np.cumsum(
            0.5 * (run["v_north_m_s"][1:] + run["v_north_m_s"][:-1]) * dt)])
        east = np.concatenate([[0.0], np.cumsum(
            0.5 * (run["v_east_m_s"][1:] + run["v_east_m_s"][:-1]) * dt)])
        ax_track.plot(*_thinned(east, north), color="tab:blue", lw=1.4)
        ax_track.plot(east[0], north[0], "^", color="tab:green", ms=10, label="start")
        ax_track.plot(east[-1], north[-1], "s", color="tab:red", ms=8, label="end")
        every = _nice_step(float(t[-1] - t[0]) / 8.0)
        for tk in np.arange(np.ceil(t[0] / every) * every, t[-1], every)[1:]:
            k = int(np.searchsorted(t, tk))
            ax_track.plot(east[k], north[k], ".", color="tab:blue", ms=6)
            ax_track.annotate(f"{tk:g} s", (east[k], north[k]), textcoords="offset points",
                              xytext=(4, -9), fontsize=7, color="tab:blue")
        track = east, north
    else:
        ax_track.text(0.5, 0.5, "no NED velocity in this log", ha="center",
                      transform=ax_track.transAxes)
    ax_track.set_aspect("equal", adjustable="datalim")
    ax_track.set_xlabel("east [m]")
    ax_track.set_ylabel("north [m]")
    ax_track.set_title("track (logged NED velocity integrated from the start)", fontsize=10)
    ax_track.grid(True, alpha=0.3)
    return track


def _mark_events(shown_events, time_axes, ax_top, ax_track, t: np.ndarray,
                 track: tuple[np.ndarray, np.ndarray] | None) -> None:
    """The events numbered: a dotted line on every time axis, the number above the top one
    and a numbered circle on the track."""
    for n, (te, _text) in enumerate(shown_events, 1):
        for ax in time_axes:
            ax.axvline(te, color="0.55", lw=0.7, ls=":")
        ax_top.annotate(str(n), (te, 1.0), xycoords=("data", "axes fraction"),
                        xytext=(0, 2), textcoords="offset points", ha="center",
                        va="bottom", fontsize=8, color="0.2")
        if track is not None:
            east, north = track
            k = min(int(np.searchsorted(t, te)), len(t) - 1)
            ax_track.plot(east[k], north[k], "o", mfc="white", mec="0.2", ms=11, zorder=5)
            ax_track.annotate(str(n), (east[k], north[k]), ha="center", va="center",
                              fontsize=7, zorder=6)


def _footnote(merged, shown_events, spans: list[str], notes: dict[str, list[str]]) -> str:
    """The events listed, the wing models flown and what each mode is drawn as."""
    lines = [f"{n}: t = {te:.1f} s {text}" for n, (te, text) in enumerate(shown_events, 1)]
    if len(merged) > len(shown_events):
        lines.append(f"(+{len(merged) - len(shown_events)} more events: bioflex-jsb info "
                     "FILE.mcap)")
    foot = "events: " + " | ".join(lines) if lines else "events: none logged"
    if spans:
        foot += "\nwing model flown: " + ", ".join(spans)
    if notes:
        what = {"tip twist": "the tip twist it makes (leading edge up +)",
                "tip deflection": "the tip deflection it makes (up +)",
                "eta": "its coordinate η in degrees (the log does not carry the mode shapes)"}
        foot += "\nwing modes: " + "; ".join(
            f"mode{'s' if len(m) > 1 else ''} {', '.join(m)} drawn as {what[q]}"
            for q, m in notes.items()) + "; running mean, min/max shaded"
    return foot


def _nice_step(x: float) -> float:
    """The 1-2-5 number nearest above ``x`` (> 0)."""
    if not x > 0.0:
        return 1.0
    e = 10.0 ** np.floor(np.log10(x))
    return float(next(m * e for m in (1.0, 2.0, 5.0, 10.0) if m * e >= x))
