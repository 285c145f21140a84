"""Figures of the section loads (matplotlib, imported when a figure is drawn)."""

from __future__ import annotations

from bioflex_jsb.loads.model import QUANTITIES

LABELS = {"shear_n": "shear V [N]", "bending_n_m": "bending moment M [N·m]",
          "torque_n_m": "torque T [N·m]"}
SIGNS = {"shear_n": "up +", "bending_n_m": "tip up +", "torque_n_m": "leading edge up +"}


def _figure(rows: int, cols: int, size):
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


def plot_section_loads(loads, path=None, gust_start_s: float | None = None):
    """Shear, bending and torque against time at every station: force summation solid,
    mode displacement dashed, the 1 g value dotted; the difference FS − MD in a second
    column."""
    fig, ax = _figure(3, 2, (11.0, 8.5))
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
    fig.legend(handles, labels, loc="outside lower center", ncol=min(8, len(labels)),
               fontsize=8)
    fig.suptitle(f"Section loads, wing {loads.wing}, {loads.model} model, "
                 f"{loads.meta.get('speed_m_s')} m/s, gust {loads.meta.get('gust')} "
                 "(FS solid: force summation; MD dashed: mode displacement; dotted: 1 g)",
                 fontsize=10)
    if path is not None:
        save(fig, path)
    return fig
