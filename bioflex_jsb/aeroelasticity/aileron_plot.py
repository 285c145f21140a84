"""The figure of an aileron-effectiveness result
(:meth:`bioflex_jsb.aeroelasticity.aileron.AileronResult.plot`). Above: the rolling-moment
effectiveness of the held wing and the steady roll rate's, elastic over rigid, against
airspeed [m/s], reversed below zero. Below: p b/(2V) per radian of aileron [1/rad], elastic
and rigid. The reversal is marked, the divergence (root held) dotted; each curve is left
open at its pole (the held wing's at the divergence, the rolling wing's at its own).
matplotlib is imported when a figure is drawn (object-oriented, no pyplot state).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

FIGSIZE_IN = (9.0, 7.5)
DPI = 110
EFFECTIVENESS_AXIS = (-1.5, 2.0)  # [-]: near divergence the curves leave it (said on it)


def _broken_at(speeds: np.ndarray, values: np.ndarray, pole_m_s: float | None) -> np.ndarray:
    """``values`` with a gap (NaN) at the grid point nearest the pole: no line across it."""
    out = np.array(values, dtype=float)
    if pole_m_s is not None and speeds[0] < pole_m_s < speeds[-1]:
        out[int(np.searchsorted(speeds, pole_m_s))] = np.nan
    return out


def plot_aileron(result, path=None):
    """The figure of ``result``, an
    :class:`~bioflex_jsb.aeroelasticity.aileron.AileronResult` (module docstring), written
    to ``path`` when given (a PNG carries the package's Software tag)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from bioflex_jsb import __version__

    fig = Figure(figsize=FIGSIZE_IN, layout="constrained")
    FigureCanvasAgg(fig)
    ax_e, ax_p = fig.subplots(2, 1, sharex=True)
    v = result.speeds_m_s
    held = _broken_at(v, result.effectiveness, result.divergence_speed_m_s)
    rolling = _broken_at(v, result.roll_effectiveness, result.roll_divergence_speed_m_s)
    ax_e.plot(v, held, lw=1.8, label="rolling moment, root held: R/R_rigid")
    ax_e.plot(v, rolling, lw=1.8, ls="--", label="steady roll rate: p/p_rigid")
    ax_e.axhline(1.0, color="0.5", lw=0.8)
    ax_e.axhline(0.0, color="k", lw=0.9)
    ax_e.axhspan(EFFECTIVENESS_AXIS[0], 0.0, color="tab:red", alpha=0.07, lw=0)
    ax_e.set_ylim(*EFFECTIVENESS_AXIS)
    ax_e.set_ylabel(f"aileron effectiveness, elastic/rigid [-]\n(< 0: reversed; axis "
                    f"{EFFECTIVENESS_AXIS[0]:g}..{EFFECTIVENESS_AXIS[1]:g})")
    ax_p.plot(v, _broken_at(v, result.roll_rate_per_rad, result.roll_divergence_speed_m_s),
              lw=1.8, label="elastic")
    ax_p.axhline(result.rigid_roll_rate_per_rad, color="0.4", ls="-.", lw=1.2,
                 label=f"rigid: {result.rigid_roll_rate_per_rad:.3f} /rad")
    ax_p.axhline(0.0, color="k", lw=0.9)
    top = 1.6 * abs(result.rigid_roll_rate_per_rad)
    ax_p.set_ylim(-top, top)
    ax_p.set_ylabel("steady roll rate p b/(2V)\nper radian of aileron [1/rad]")
    ax_p.set_xlabel("airspeed V [m/s]")
    lo, hi = result.range_m_s
    for ax in (ax_e, ax_p):
        ax.grid(True, alpha=0.3)
        ax.set_xlim(lo, hi)
    vr = result.reversal_speed_m_s
    if vr is not None and lo <= vr <= hi:
        for ax in (ax_e, ax_p):
            ax.axvline(vr, color="tab:red", ls="--", lw=1.2)
        ax_e.plot([vr], [0.0], "o", color="tab:red", ms=8, zorder=5,
                  label=f"reversal: {vr:.1f} m/s")
    vd = result.divergence_speed_m_s
    if vd is not None and lo <= vd <= hi:
        for ax in (ax_e, ax_p):
            ax.axvline(vd, color="0.4", ls=":", lw=1.4)
        ax_e.plot([], [], color="0.4", ls=":", label=f"divergence, root held: {vd:.1f} m/s")
    ax_e.legend(loc="best", fontsize=9)
    ax_p.legend(loc="best", fontsize=9)
    s = result.surface
    what = ("clamped" if result.settings.get("clamped", True) else
            "the aircraft's flight model of the wing")
    fig.suptitle(f"{result.name} ({what}): {s.get('name', 'aileron')} "
                 f"{s.get('start_m', 0):.3g}-{s.get('end_m', 0):.3g} m, hinge "
                 f"{s.get('hinge_chord_fraction', 0):.3g} c; steady strips, "
                 f"ρ {result.density_kg_m3:g} kg/m³", fontsize=11)
    if path is not None:
        out = Path(path)
        suffix = out.suffix.lower().lstrip(".")
        tag = f"bioflex-jsb {__version__}"
        meta = {"Software": tag} if suffix == "png" else {"Creator": tag}
        fig.savefig(out, dpi=DPI, metadata=meta if suffix in ("png", "pdf", "svg") else None)
    return fig
