"""Design exploration: C_η1^Q1, short-period damping and peak gust load factor against the
inertial and elastic axis positions (the paper's optimisation loop, its Fig. 20).

    python scripts/design_axes.py [--campaign scripts/campaigns/design_axes.toml]
        [--out design_axes.csv] [--plot design_axes.png] [--workers N] [--resume]

Runs the campaign with the sweep machinery (local processes; the table is written as cases
finish, so ``--resume`` completes an interrupted run), then draws three maps over
(x_E, x_I) [fractions of the chord aft of the leading edge]:

* C_η1^Q1 [-], the strip model's physical value (no pin): negative is the stable side;
* ζ of the short period of the coupled LTI model [-] at the campaign's speed; hatched where
  that model is unstable (flutter or divergence speed below the campaign's speed);
* the peak |Δn_z| [-] of the nonlinear JSBSim gust run; hatched where the run diverged
  (the wing past its divergence / flutter speed), with the flutter speed [m/s] written in.

The paper's original (0.50, 0.50) and optimised (0.25, 0.22) axes are marked. The table
also prints, best first, the wings that neither diverge nor flutter within the campaign's
range.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from bioflex_jsb.sweep.campaign import CampaignError, load_campaign  # noqa: E402
from bioflex_jsb.sweep.driver import missing_cases, run_sweep  # noqa: E402
from bioflex_jsb.sweep.local import LocalExecutor  # noqa: E402
from bioflex_jsb.sweep.store import StoreError, open_store, read_results  # noqa: E402

MARKS = {"original": (0.50, 0.50), "optimised": (0.25, 0.22)}  # (x_I, x_E), Table 8


def grid(rows, key):
    """(x_E values, x_I values, 2-D list [i_I][i_E] of ``key``; NaN where missing)."""
    xe = sorted({r["x_elastic_frac"] for r in rows})
    xi = sorted({r["x_inertial_frac"] for r in rows})
    z = [[math.nan] * len(xe) for _ in xi]
    for r in rows:
        v = r.get(key)
        z[xi.index(r["x_inertial_frac"])][xe.index(r["x_elastic_frac"])] = (
            math.nan if v is None else float(v))
    return xe, xi, z


def plot(rows, path: Path, title: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    panels = [
        ("c_eta1_q1", "C_η1^Q1 (physical) [-]", "RdBu_r"),
        ("short_period_damping", "short-period damping ζ [-]", "viridis"),
        ("peak_dn_z", "peak |Δn_z| of the gust run [-]", "magma_r"),
    ]
    from matplotlib.patches import Patch

    def hatched(r, key) -> bool:
        """A cell whose value is not a measure of the wing: its LTI model is unstable at the
        campaign's speed (ζ of an unstable or real short-period root is meaningless) or, on
        the load-factor map, the gust run diverged."""
        fs = r.get("flutter_speed_m_s")
        if key == "peak_dn_z":
            return r["status"] != "ok"
        return fs is not None and fs <= r["speed_m_s"]

    fig, axes = plt.subplots(1, 3, figsize=(16, 5.4), constrained_layout=True)
    for ax, (key, label, cmap) in zip(axes, panels, strict=True):
        xe, xi, z = grid(rows, key)
        z = np.asarray(z, dtype=float)
        if key != "c_eta1_q1":  # hatched cells carry no colour: their value means nothing
            for r in rows:
                if hatched(r, key):
                    z[xi.index(r["x_inertial_frac"]), xe.index(r["x_elastic_frac"])] = np.nan
        z = np.ma.masked_invalid(z)
        if key == "c_eta1_q1":
            lim = float(np.nanmax(np.abs(z))) if z.count() else 1.0
            mesh = ax.pcolormesh(xe, xi, z, cmap=cmap, vmin=-lim, vmax=lim, shading="nearest")
        else:
            mesh = ax.pcolormesh(xe, xi, z, cmap=cmap, shading="nearest")
        fig.colorbar(mesh, ax=ax, label=label)
        if key != "c_eta1_q1":
            dx = (xe[1] - xe[0]) / 2 if len(xe) > 1 else 0.05
            dy = (xi[1] - xi[0]) / 2 if len(xi) > 1 else 0.05
            for r in rows:
                fs = r.get("flutter_speed_m_s")
                if not hatched(r, key):
                    continue
                x, y = r["x_elastic_frac"], r["x_inertial_frac"]
                ax.add_patch(plt.Rectangle((x - dx, y - dy), 2 * dx, 2 * dy, fill=False,
                                           hatch="xx", edgecolor="0.4", linewidth=0))
                ax.text(x, y, r["status"] if fs is None else f"{fs:.0f} m/s", ha="center",
                        va="center", fontsize=7, color="0.2")
        for name, (x_i, x_e) in MARKS.items():
            ax.plot(x_e, x_i, "o", mfc="none", mec="k")
            ax.annotate(name, (x_e, x_i), textcoords="offset points", xytext=(5, 5),
                        fontsize=8)
        ax.set_xlabel("elastic axis x_E [fraction of chord]")
        ax.set_ylabel("inertial axis x_I [fraction of chord]")
        ax.set_title(label.split(" [")[0])
        if key != "c_eta1_q1":
            what = ("gust run diverged (status or LTI flutter speed written)"
                    if key == "peak_dn_z" else
                    "LTI model unstable at this speed (its flutter speed written)")
            ax.legend(handles=[Patch(facecolor="white", edgecolor="0.4", hatch="xx",
                                     label=what),
                               plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="k",
                                          label="paper's wings (Table 8)")],
                      loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8,
                      frameon=False, ncol=1)
    fig.suptitle(title)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--campaign", default=str(ROOT / "scripts" / "campaigns" / "design_axes.toml"))
    p.add_argument("--out", default="design_axes.csv", help=".csv or .parquet")
    p.add_argument("--plot", default="design_axes.png")
    p.add_argument("--workers", type=int, default=None, help="default: one per core")
    p.add_argument("--resume", action="store_true", help="complete an existing --out")
    args = p.parse_args(argv)
    try:
        campaign = load_campaign(args.campaign)
        store = open_store(args.out, campaign.columns(), resume=args.resume)
    except (CampaignError, StoreError) as exc:
        print(f"design_axes: error: {exc}", file=sys.stderr)
        return 2
    cases = campaign.cases()
    todo = missing_cases(cases, store.done_ids)
    try:
        with LocalExecutor(args.workers) as ex:
            summary = run_sweep(todo, store, ex, total=len(cases))
    finally:
        store.close()
    if summary.interrupted:
        print(f"interrupted; rerun with --resume to complete {args.out}", file=sys.stderr)
        return 130
    wanted = {c.case_id for c in cases}
    rows = [r for r in read_results(args.out) if r["case_id"] in wanted]
    speed = campaign.speeds_m_s[0]
    plot(rows, Path(args.plot), f"{campaign.name}: {speed:g} m/s, gust {campaign.gusts[0]}, "
         f"{campaign.models[0]} model")
    print(f"{len(rows)} wings ({summary.run} run now) -> {args.out}; maps -> {args.plot}")
    print(f"{'x_I':>5} {'x_E':>5} {'C_η1^Q1':>8} {'ζ_sp':>6} {'|Δn_z|':>7} {'V_f [m/s]':>9}  "
          "status")

    def key(r):
        stable = r["status"] == "ok" and r["flutter_speed_m_s"] is None
        return (not stable, r["peak_dn_z"] if r["peak_dn_z"] is not None else math.inf)

    for r in sorted(rows, key=key):
        vf = "-" if r["flutter_speed_m_s"] is None else f"{r['flutter_speed_m_s']:.1f}"
        dn = "-" if r["peak_dn_z"] is None else f"{r['peak_dn_z']:.3f}"
        sp = "-" if r["short_period_damping"] is None else f"{r['short_period_damping']:.3f}"
        c = "-" if r["c_eta1_q1"] is None else f"{r['c_eta1_q1']:+.3f}"
        print(f"{r['x_inertial_frac']:5.2f} {r['x_elastic_frac']:5.2f} {c:>8} {sp:>6} "
              f"{dn:>7} {vf:>9}  {r['status']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
