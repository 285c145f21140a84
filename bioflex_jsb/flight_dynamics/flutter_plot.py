"""The V-g / V-f diagram of a flutter search (:meth:`FlutterResult.plot`).

Two panels against airspeed [m/s], one line per considered branch of the scan (the
phugoid and the strips' lag roots are left out, as the search leaves them out): the damping
ratio ζ = −Re λ / |λ| [-] (negative: growing; the classical V-g diagram's g is about
−2ζ) and the frequency |Im λ| [rad/s]. A branch whose roots are real (an
over-damped mode) is drawn at frequency 0 with the less stable of its real roots. The first
instability is marked on both panels; a clamped wing's static divergence and a free
aircraft's divergence of the wing with the body held are drawn as vertical lines.

matplotlib is imported when a figure is drawn (object-oriented, no pyplot state).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

FIGSIZE_IN = (10.0, 8.0)
DPI = 110
# ζ axis: real roots have ζ = 1 and would squeeze the region near 0 where flutter is read;
# the axis ends at this ζ (lines above it leave the frame, said in the axis label).
ZETA_TOP = 0.6
IMAG_REAL_RAD_S = 1e-6  # |Im λ| at or below this: a real root [rad/s]


def branch_curves(result) -> dict[str, np.ndarray]:
    """The root drawn for each considered branch name at every scanned speed (the upper
    root of a pair; of real roots the one of largest Re λ), ``{name: roots (n_speeds,)}``."""
    roots = np.asarray(result.branch_roots)
    labels = result.branch_labels
    considered = result.branch_considered or (True,) * len(labels)
    out: dict[str, np.ndarray] = {}
    for name in dict.fromkeys(lab for lab, c in zip(labels, considered, strict=True) if c):
        cols = roots[:, [j for j, lab in enumerate(labels) if lab == name]]
        pick = np.empty(cols.shape[0], dtype=complex)
        for k, row in enumerate(cols):
            upper = row[row.imag > IMAG_REAL_RAD_S]
            pick[k] = upper[np.argmax(upper.imag)] if upper.size else row[np.argmax(row.real)]
        out[name] = pick
    return out


def _title(result) -> str:
    zeta = result.structural_damping
    z = "the wing's own" if zeta is None else f"{zeta:g}"
    return (f"{result.name}: V-g / V-f, {result.aero} strips, {result.method}, "
            f"ρ {result.density_kg_m3:g} kg/m³, structural ζ {z}")


def _marker_text(result) -> str:
    """The first instability in a few short lines (the legend's entry)."""
    partner = f"\nwith {result.partner_mode}" if result.partner_mode else ""
    what = f"{result.kind}, {result.mechanism}{partner}\nbranch {result.mode}"
    freq = f", {result.frequency_rad_s:.1f} rad/s" if result.kind == "flutter" else ""
    if result.present_at_lower_end:
        where = f"unstable at and below {result.range_m_s[0]:g} m/s{freq}"
    else:
        where = f"{result.speed_m_s:.1f} m/s{freq}"
    return f"first instability:\n{where}\n{what}"


def plot_flutter(result, path: str | Path | None = None):
    """The figure of ``result`` (module docstring), written to ``path`` when given (a PNG
    carries the package's Software tag: a later run may replace it)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from bioflex_jsb import __version__

    if len(result.branch_labels) != np.asarray(result.branch_roots).shape[-1]:
        raise ValueError("the result carries no labelled scan to draw (branch_labels)")
    fig = Figure(figsize=FIGSIZE_IN, layout="constrained")
    FigureCanvasAgg(fig)
    ax_g, ax_f = fig.subplots(2, 1, sharex=True)
    lo, hi = result.range_m_s
    v = np.asarray(result.speeds_m_s, dtype=float)
    keep = (v >= lo - 1e-9) & (v <= hi + 1e-9)
    curves = branch_curves(result)
    colours = [f"C{i}" for i in range(10)]
    for i, (name, lam) in enumerate(curves.items()):
        lam = lam[keep]
        zeta = -lam.real / np.maximum(np.abs(lam), 1e-300)
        freq = np.where(np.abs(lam.imag) > IMAG_REAL_RAD_S, np.abs(lam.imag), 0.0)
        style = dict(color=colours[i % len(colours)], lw=1.6)
        ax_g.plot(v[keep], zeta, label=name, **style)
        ax_f.plot(v[keep], freq, label=name, **style)
    ax_g.axhline(0.0, color="k", lw=0.9)
    ax_g.axhspan(-1.5, 0.0, color="tab:red", alpha=0.07, lw=0)
    z_all = np.concatenate([(-c.real / np.maximum(np.abs(c), 1e-300))[keep]
                            for c in curves.values()]) if curves else np.zeros(1)
    ax_g.set_ylim(min(-0.05, 1.1 * float(np.nanmin(z_all))),
                  min(ZETA_TOP, max(0.1, 1.1 * float(np.nanmax(z_all)))))
    ax_g.set_ylabel(f"damping ratio ζ = −Re λ/|λ| [-]\n(< 0: unstable; axis cut at "
                    f"{ZETA_TOP:g})")
    ax_f.set_ylabel("frequency |Im λ| [rad/s]\n(0: real root)")
    ax_f.set_xlabel("airspeed V [m/s]")
    ax_f.set_ylim(bottom=0.0)
    for ax in (ax_g, ax_f):
        ax.grid(True, alpha=0.3)
        ax.set_xlim(lo, hi)
    if result.mechanism is not None:
        v_mark = result.range_m_s[0] if result.present_at_lower_end else result.speed_m_s
        colour = "tab:red"
        for ax in (ax_g, ax_f):
            ax.axvline(v_mark, color=colour, ls="--", lw=1.2)
        ax_g.plot([v_mark], [0.0], "o", color=colour, ms=8, zorder=5,
                  label=_marker_text(result))
        ax_f.plot([v_mark], [result.frequency_rad_s or 0.0], "o", color=colour, ms=8,
                  zorder=5)
    else:
        ax_g.text(0.02, 0.04, f"no instability between {lo:.1f} and {hi:.1f} m/s",
                  transform=ax_g.transAxes, fontsize=10)
    div = result.divergence_speed_m_s
    if div is not None and lo <= div <= hi and not (
            result.mechanism == "static divergence" and result.divergence_is_instability):
        what = ("static divergence" if result.divergence_is_instability
                else "wing divergence, body held\n(not an instability of the aircraft)")
        ax_g.axvline(div, color="0.4", ls=":", lw=1.4, label=f"{what}: {div:.1f} m/s")
        ax_f.axvline(div, color="0.4", ls=":", lw=1.4)
    left_out = [lab for lab, c in zip(result.branch_labels, result.branch_considered,
                                      strict=True) if not c]
    title = "branch" + (f" (left out: {', '.join(dict.fromkeys(left_out))})"
                        if left_out else "")
    ax_g.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, title=title,
                title_fontsize=9)
    title = _title(result)
    if result.quasi_steady_artefact:
        title += ("\nquasi-steady strips: a single-mode torsion instability of C = 1 strips "
                  "(no pitch damping); --aero unsteady for the physical one")
    fig.suptitle(title, fontsize=11, color="black")
    if path is not None:
        out = Path(path)
        suffix = out.suffix.lower().lstrip(".")
        tag = f"bioflex-jsb {__version__}"
        meta = {"Software": tag} if suffix == "png" else {"Creator": tag}
        fig.savefig(out, dpi=DPI, metadata=meta if suffix in ("png", "pdf", "svg") else None)
    return fig
