"""The root loads of gust runs as text lines (the ``gust`` command's summary table).

Reads the ``loads`` mapping of each run's metrics
(:func:`bioflex_jsb.simulation.results.section_load_metrics`): per model and method, the
root bending moment's and torque's peak (the extreme farther from the 1 g value, up or
down), its increment over 1 g and its time.
"""

from __future__ import annotations

from collections.abc import Mapping

LABELS = {"force_summation": "FS", "mode_displacement": "MD"}
ROOT = 0  # the first station; a root load only when its fraction is 0


def _peak(row: Mapping[str, float]) -> tuple[float, float, float]:
    """(peak, increment over 1 g, time [s]) of one load: the extreme farther from 1 g."""
    if abs(row["increment_up"]) >= abs(row["increment_down"]):
        return row["max"], row["increment_up"], row["time_max_s"]
    return row["min"], row["increment_down"], row["time_min_s"]


def root_loads_lines(summary: Mapping[str, Mapping[str, object]]) -> list[str]:
    """Lines of the root bending moment and torque peaks of each model's metrics (as
    JSON: ``summary[model]["loads"]``), both methods; a run without loads says why (a
    diverged run is left out: it has no response metrics)."""
    rows, notes, no_md = [], [], []
    for model, m in summary.items():
        loads = m.get("loads")
        if not loads:
            continue
        if "unavailable" in loads:
            notes.append(f"section loads: {model}: none ({loads['unavailable']})")
            continue
        if not loads["station_fractions"] or loads["station_fractions"][ROOT] != 0.0:
            continue
        if model != "rigid" and "mode_displacement" not in loads["methods"]:
            no_md.append(model)
        for method, per_q in loads["methods"].items():
            b = _peak(per_q["bending_n_m"][ROOT])
            t = _peak(per_q["torque_n_m"][ROOT])
            rows.append(f"{model:<8} {LABELS[method]:<6} {b[0]:9.3f} {b[1]:+11.3f} {b[2]:9.3f}"
                        f" {t[0]:9.4f} {t[1]:+11.4f} {t[2]:9.3f}")
    if not rows:
        return notes
    head = [f"{'root loads':<15} {'bending moment M [N*m]':^31} {'torque T [N*m]':^31}",
            f"{'model':<8} {'method':<6} {'peak':>9} {'vs 1 g':>11} {'at t [s]':>9}"
            f" {'peak':>9} {'vs 1 g':>11} {'at t [s]':>9}"]
    if any(f" {LABELS['mode_displacement']} " in r for r in rows):
        foot = ["root loads: FS force summation, MD mode displacement (docs/loads.md; MD "
                "sees what the wing's modes carry: the prototype's three are "
                "twist-dominated); peak: the extreme farther from the 1 g value after the "
                "gust start"]
    else:
        foot = ["root loads: FS force summation (docs/loads.md); peak: the extreme farther "
                "from the 1 g value after the gust start"]
    if no_md:
        notes.append(f"section loads: {', '.join(no_md)}: no mode displacement (it needs the "
                     "beam's EI and GJ, which the wing's modes file does not give)")
    return head + rows + foot + notes
