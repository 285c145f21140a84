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

Every cell is the strip model's own wing (unpinned), the only coefficient defined across
the grid. The paper's original (0.50, 0.50) and optimised (0.25, 0.22) axes are marked; as
named wings (``--wing original``, ``flutter``, ``gust``) they fly with C_η1^Q1 pinned to the
published value, so the figure says, beside each mark, the pinned value and the flutter
speed of the wing so pinned, next to the same axes unpinned (the original's strip value
+0.19 is unstable from 12 m/s; pinned to the paper's −0.03 it is stable to 40 m/s). The table
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


def named_wings(flutter_range_m_s) -> dict[str, dict]:
    """The paper's two wings as the named variants fly them (C_η1^Q1 pinned to the published
    value): axis positions, pinned C_η1^Q1 [-] and the coupled LTI model's flutter or
    divergence speed [m/s] in ``flutter_range_m_s`` (None: none there), by the campaign's
    own flutter search (sweep/evaluate.py)."""
    from bioflex_jsb.flight_dynamics.eigen import find_flutter
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.sweep.campaign import axis_variant

    out = {}
    for name, (x_i, x_e) in MARKS.items():
        variant = VARIANTS[name]
        f = find_flutter(build_wing(variant).model, flutter_range_m_s)
        # the same axes unpinned, as the map's cells are (the marks fall between cells)
        free = build_wing(axis_variant(x_i, x_e)).model
        g = find_flutter(free, flutter_range_m_s)
        out[name] = {"x_inertial_frac": x_i, "x_elastic_frac": x_e,
                     "pinned_c_eta1_q1": variant.pinned_c_eta1_q1,
                     "flutter_speed_m_s": f.flutter_speed_m_s, "kind": f.kind,
                     "unpinned_c_eta1_q1": float(free.coefficients.c_eta_q[0, 0]),
                     "unpinned_flutter_speed_m_s": g.flutter_speed_m_s, "unpinned_kind": g.kind,
                     "range_m_s": tuple(flutter_range_m_s)}
    return out


def _mark_text(name: str, named: dict | None) -> str:
    """The label beside a paper's wing: its cell (unpinned) and the named wing (pinned)."""
    if not named or name not in named:
        return f"{name} (Table 8)"
    w = named[name]

    def status(speed, kind) -> str:
        if speed is None:
            return f"stable to {w['range_m_s'][1]:g} m/s"
        return f"{kind} at {speed:.0f} m/s"

    return (f"{name} (Table 8)\n"
            f"unpinned, as mapped: C = {w['unpinned_c_eta1_q1']:+.2f}, "
            f"{status(w['unpinned_flutter_speed_m_s'], w['unpinned_kind'])}\n"
            f"--wing {name}, pinned: C = {w['pinned_c_eta1_q1']:+.2f}, "
            f"{status(w['flutter_speed_m_s'], w['kind'])}")


def plot(rows, path: Path, title: str, named: dict | None = None) -> None:
    """The three maps of ``rows`` to ``path``; ``named``: :func:`named_wings`, for the marks'
    labels (without it the marks say only their name)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    panels = [
        ("c_eta1_q1", "C_η1^Q1 (strip model, unpinned) [-]", "RdBu_r"),
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
            ax.plot(x_e, x_i, "o", mfc="white", mec="k", ms=8, mew=1.5, zorder=5)
            # on a light box: the maps run from white to black under a mark
            ax.annotate(name, (x_e, x_i), textcoords="offset points", xytext=(7, 7),
                        fontsize=8,
                        zorder=6, va="bottom",
                        ha="right" if x_e > 0.5 * (xe[0] + xe[-1]) else "left",
                        bbox=dict(boxstyle="round,pad=0.25", facecolor="white", alpha=0.9,
                                  edgecolor="0.5", lw=0.5))
        ax.set_xlabel("elastic axis x_E [fraction of chord]")
        ax.set_ylabel("inertial axis x_I [fraction of chord]")
        ax.set_title(label.split(" [")[0])
        if key == "c_eta1_q1":  # which C_η1^Q1: the map's (unpinned) and the named wings'
            ax.legend(handles=[plt.Line2D([], [], ls="none", marker="o", mfc="white", mec="k")
                               for _ in MARKS],
                      labels=[_mark_text(name, named) for name in MARKS],
                      loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8,
                      frameon=False, ncol=1)
        else:
            what = ("gust run diverged (status or LTI flutter speed written)"
                    if key == "peak_dn_z" else
                    "LTI model unstable at this speed (its flutter speed written)")
            ax.legend(handles=[Patch(facecolor="white", edgecolor="0.4", hatch="xx",
                                     label=what),
                               plt.Line2D([], [], ls="none", marker="o", mfc="none", mec="k",
                                          label="paper's wings (Table 8)")],
                      loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=8,
                      frameon=False, ncol=1)
    fig.suptitle(f"{title}; every cell the strip model's wing, C_η1^Q1 unpinned (the named "
                 "wings pin it to the paper's value: left map)")
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
    named = named_wings(cases[0].settings.flutter_range_m_s or (5.0, 40.0))
    plot(rows, Path(args.plot), f"{campaign.name}: {speed:g} m/s, gust {campaign.gusts[0]}, "
         f"{campaign.models[0]} model", named)
    print(f"{len(rows)} wings ({summary.run} run now) -> {args.out}; maps -> {args.plot}")
    print(f"{'x_I':>5} {'x_E':>5} {'C_η1^Q1':>8} {'ζ_sp':>6} {'|Δn_z|':>7} {'V_f [m/s]':>9}  "
          "status")

    def key(r):
        stable = r["status"] == "ok" and r["flutter_speed_m_s"] is None
        return (not stable, r["peak_dn_z"] if r["peak_dn_z"] is not None else math.inf)

    for name in named:
        print(" | ".join(_mark_text(name, named).splitlines()))
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
