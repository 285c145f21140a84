"""Figures of the section loads (matplotlib, imported when a figure is drawn)."""

from __future__ import annotations

from bioflex_jsb.loads.model import QUANTITIES

LABELS = {"shear_n": "shear V [N]", "bending_n_m": "bending moment M [N·m]",
          "torque_n_m": "torque T [N·m]"}
SIGNS = {"shear_n": "up +", "bending_n_m": "tip up +", "torque_n_m": "leading edge up +"}


def new_figure(rows: int, cols: int, size):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt.subplots(rows, cols, figsize=size, squeeze=False, constrained_layout=True)


def save(fig, path) -> None:
    """Write ``fig`` to ``path`` (PNG carries the Software tag of bioflex-jsb)."""
    import matplotlib.pyplot as plt

    meta = {"Software": "bioflex-jsb"} if str(path).lower().endswith(".png") else None
    fig.savefig(path, dpi=130, metadata=meta)
    plt.close(fig)


# mode displacement is taken to miss a load when it carries less than this share of the
# force summation's 1 g value at the root (the prototype's three twist-dominated modes carry
# 9 % of the root shear and 14 % of the root bending: docs/loads.md, "What MD can see")
MD_MISSES_BELOW = 0.5


def md_caveat(loads) -> str:
    """One line for a section-loads figure: the share of the force summation's root loads
    at 1 g that mode displacement carries (it sums only what the wing's modes carry: the
    beam's stress resultants of η), and which method to read where MD misses most of a load
    (:data:`MD_MISSES_BELOW`); empty without MD or without a root station."""
    if "mode_displacement" not in loads.static or 0.0 not in tuple(loads.station_fractions):
        return ""
    j = tuple(loads.station_fractions).index(0.0)
    fs, md = loads.static["force_summation"][:, j], loads.static["mode_displacement"][:, j]
    share = {q: float(md[i] / fs[i]) if fs[i] != 0.0 else float("nan")
             for i, q in enumerate(QUANTITIES)}
    names = {"shear_n": "shear", "bending_n_m": "bending", "torque_n_m": "torque"}
    text = ("MD / FS at the root at 1 g: "
            + ", ".join(f"{names[q]} {100 * v:.0f} %" for q, v in share.items()))
    missed = [names[q] for q, v in share.items() if abs(v) < MD_MISSES_BELOW]
    if missed:
        text += (". MD sums only what the wing's modes carry and misses most of the "
                 f"{' and '.join(missed)}: read FS for {'it' if len(missed) == 1 else 'them'}"
                 " (the FS − MD column is mostly that missing part; docs/loads.md)")
    return text


def plot_section_loads(loads, path=None, gust_start_s: float | None = None):
    """Shear, bending and torque against time at every station: force summation solid,
    mode displacement dashed, the 1 g value dotted; the difference FS − MD in a second
    column; below, what share of the root loads MD carries (:func:`md_caveat`)."""
    fig, ax = new_figure(3, 2, (11.0, 9.2))
    colours = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C7"]
    t = loads.time_s
    diff = loads.difference()
    for qi, quantity in enumerate(QUANTITIES):
        a, b = ax[qi, 0], ax[qi, 1]
        for j in range(loads.stations_m.size):
            col = colours[j % len(colours)]
            label = loads.station_label(j)
            a.plot(t, loads.values["force_summation"][:, qi, j], color=col, lw=1.4,
                   label=f"{label} FS")
            if "mode_displacement" in loads.values:
                a.plot(t, loads.values["mode_displacement"][:, qi, j], color=col, lw=1.0,
                       ls="--", label=f"{label} MD")
                b.plot(t, diff[:, qi, j], color=col, lw=1.1, label=label)
            a.axhline(loads.static["force_summation"][qi, j], color=col, lw=0.6, ls=":")
        a.set_ylabel(f"{LABELS[quantity]}\n({SIGNS[quantity]})")
        b.set_ylabel(f"FS − MD [{LABELS[quantity].split('[')[1]}")
        for x in (a, b):
            x.grid(True, alpha=0.3)
            if gust_start_s is not None:
                x.axvline(gust_start_s, color="0.5", lw=0.6)
        if diff is None:
            b.text(0.5, 0.5, "rigid wing: no mode displacement", ha="center",
                   transform=b.transAxes)
    ax[2, 0].set_xlabel("time [s]")
    ax[2, 1].set_xlabel("time [s]")
    handles, labels = ax[0, 0].get_legend_handles_labels()
    # the caveat of mode displacement heads the legend: one box below the axes, in the
    # layout (a free fig.text or a supxlabel overlaps the legend there)
    import textwrap

    note = md_caveat(loads)
    legend = fig.legend(handles, labels, loc="outside lower center",
                        ncol=min(8, len(labels)), fontsize=8,
                        title="\n".join(textwrap.wrap(note, 140)) or None, title_fontsize=8.5)
    if note:
        legend.get_frame().set_facecolor("lightyellow")
    fig.suptitle(f"Section loads, wing {loads.wing}, {loads.model} model, "
                 f"{loads.meta.get('speed_m_s')} m/s, gust {loads.meta.get('gust')} "
                 "(FS solid: force summation; MD dashed: mode displacement; dotted: 1 g)",
                 fontsize=10)
    if path is not None:
        save(fig, path)
    return fig
