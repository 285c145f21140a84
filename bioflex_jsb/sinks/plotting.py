"""Plots (the only module that imports matplotlib): root loci and time histories."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only; no display is needed or assumed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from bioflex_jsb.flight_dynamics.eigen import Sweep  # noqa: E402
from bioflex_jsb.simulation.results import TimeHistory  # noqa: E402

MODEL_STYLE = {
    "rigid": dict(color="black", marker="o"),
    "coupled": dict(color="tab:green", marker="s"),
    "qsd": dict(color="tab:red", marker="^"),
}
MODE_COLOURS = {
    "short_period": "tab:blue",
    "phugoid": "tab:gray",
    "aeroelastic_1": "tab:orange",
    "aeroelastic_2": "tab:purple",
    "aeroelastic_3": "tab:brown",
}


def _arrowed_branch(ax, lam: np.ndarray, colour: str, label: str | None, marker: str):
    """One root's path with an arrow every few points, pointing to increasing speed."""
    ax.plot(lam.real, lam.imag, "-", color=colour, lw=1.0, label=label, marker=marker, ms=2.5)
    step = max(1, len(lam) // 6)
    for k in range(step, len(lam), step):
        ax.annotate(
            "",
            xy=(lam[k].real, lam[k].imag),
            xytext=(lam[k - 1].real, lam[k - 1].imag),
            arrowprops=dict(arrowstyle="->", color=colour, lw=1.2),
        )


def root_locus(sweeps: Sequence[Sweep], path: str | Path, title: str) -> Path:
    """Root loci of one or more models over their speed sweeps (Figs. 15, 16, 18, 19).

    Left: every root of every model (aeroelastic branches included); right: the short period
    and phugoid region. Arrows point towards increasing airspeed; the speed range is in the
    legend. Units: rad/s on both axes.
    """
    fig, (ax_all, ax_sp) = plt.subplots(1, 2, figsize=(13, 5.5))
    for sweep in sweeps:
        style = MODEL_STYLE.get(sweep.model, dict(color="k", marker="."))
        v0, v1 = sweep.speeds_m_s[0], sweep.speeds_m_s[-1]
        seen: set[str] = set()
        for j, name in enumerate(sweep.labels):
            lam = sweep.eigenvalues[:, j]
            if lam[len(lam) // 2].imag < -1e-9:
                continue  # draw the upper half plane only
            colour = MODE_COLOURS.get(name, style["color"])
            if sweep.model == "rigid":
                colour = "black"
            label = f"{sweep.model}: {name}" if (name not in seen) else None
            seen.add(name)
            _arrowed_branch(ax_all, lam, colour, label, style["marker"])
            if name in ("short_period", "phugoid"):
                _arrowed_branch(ax_sp, lam, colour, label, style["marker"])
        ax_all.set_title(f"{title}: all roots, {v0:g}–{v1:g} m/s")
    ax_sp.set_title("short period and phugoid (zoom)")
    for ax in (ax_all, ax_sp):
        ax.axvline(0.0, color="0.6", lw=0.8)
        ax.set_xlabel("Re λ [rad/s]")
        ax.set_ylabel("Im λ [rad/s]")
        ax.grid(True, alpha=0.3)
    ax_all.legend(fontsize=7, loc="best")
    ax_sp.legend(fontsize=7, loc="best")
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out


TIME_PANELS = (
    ("u", "Δu [m/s]", 1.0),
    ("alpha", "Δα [deg]", 180.0 / np.pi),
    ("q", "q [deg/s]", 180.0 / np.pi),
    ("theta", "Δθ [deg]", 180.0 / np.pi),
    ("n_z", "n_z [-]", 1.0),
    ("eta1", "η₁ [deg]", 180.0 / np.pi),
)


def time_histories(runs: Sequence[TimeHistory], path: str | Path, title: str) -> Path:
    """Gust time histories of several runs on shared axes (like Figs. 21 and 22)."""
    fig, axes = plt.subplots(3, 2, figsize=(12, 9), sharex=True)
    for ax, (name, label, scale) in zip(axes.flat, TIME_PANELS, strict=True):
        for run in runs:
            if name not in run.channels:
                continue
            style = MODEL_STYLE.get(run.model, {})
            tag = run.meta.get("label", run.model)
            ax.plot(run.time_s, run[name] * scale, label=str(tag), color=style.get("color"),
                    lw=1.2, ls=str(run.meta.get("linestyle", "-")))
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    out = Path(path)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    return out
