"""One line saying why JSBSim's trim failed: which control saturated or which condition
failed, read from JSBSim's trim messages (the 'not trimmable' verdict and the final axis
report). Pure text processing: no JSBSim import."""

from __future__ import annotations

import contextlib
import math
import re

# A normalised control this close to its stop counts as saturated in the trim diagnosis
# (JSBSim's trim report prints controls to 2 significant digits).
SATURATION_MARGIN = 0.01

# JSBSim's trim report: one line per axis, e.g.
# "  Throttle            : 1      udot : -3.68e+01 Tolerance: 1e-03  Failed"
REPORT_LINE = re.compile(
    r"^\s*(?P<control>[A-Za-z][A-Za-z ]*?)\s*:\s*(?P<value>\S+)\s+(?P<state>\w+)\s*:\s*"
    r"(?P<residual>\S+)\s+Tolerance:\s*\S+\s+(?P<verdict>Passed|Failed)\s*$",
    re.MULTILINE,
)
UNTRIMMABLE = re.compile(r"Sorry, (?P<state>\w+) doesn't appear to be trimmable")

def diagnose_trim_failure(text: str, v: float, alpha_limits_rad: tuple[float, float],
                          first_warning: str = "", engine: str = "the motor gives") -> str:
    """One line: which control saturated or which condition failed (from JSBSim's
    trim messages: the 'not trimmable' verdict and the final axis report); ``engine``: what
    gives the thrust, with its verb ("the motor gives", "the engines give")."""
    axes: dict[str, tuple[str, float, float, bool]] = {}
    for m in REPORT_LINE.finditer(text):
        try:
            value, residual = float(m["value"]), float(m["residual"])
        except ValueError:
            continue
        axes[m["state"]] = (m["control"], value, residual, m["verdict"] == "Passed")
    untrimmable = [m["state"] for m in UNTRIMMABLE.finditer(text)]
    where = f"at {v:g} m/s"
    lo_deg, hi_deg = (math.degrees(a) for a in alpha_limits_rad)

    def sign(state: str) -> float:
        return axes[state][2] if state in axes else 0.0

    def saturated(state: str, limit: float) -> bool:
        return state in axes and abs(axes[state][1] - limit) <= SATURATION_MARGIN

    if "udot" in untrimmable or saturated("udot", 1.0):
        if sign("udot") < 0.0 or saturated("udot", 1.0):
            return (
                f"cannot trim {where}: level flight needs more thrust than {engine} "
                "(throttle saturated at 1)"
            )
        return f"cannot trim {where}: the aircraft accelerates even at zero throttle"
    if "wdot" in untrimmable:
        if sign("wdot") >= 0.0:
            return (
                f"cannot trim {where}: level flight needs an angle of attack beyond the "
                f"stall limit {hi_deg:.1f} deg (speed below the stall speed)"
            )
        return (
            f"cannot trim {where}: level flight needs an angle of attack below the "
            f"negative-stall limit {lo_deg:.1f} deg"
        )
    if "qdot" in untrimmable or saturated("qdot", 1.0) or saturated("qdot", -1.0):
        stop = "nose-down" if sign("qdot") > 0.0 else "nose-up"
        return (
            f"cannot trim {where}: the elevator is at its {stop} stop and cannot balance "
            "the pitching moment"
        )
    if untrimmable:
        return f"cannot trim {where}: JSBSim finds {', '.join(untrimmable)} untrimmable"
    failed = [f"{s} (by {c.strip().lower()})" for s, (c, _, _, ok) in axes.items() if not ok]
    if failed:
        return (
            f"cannot trim {where}: JSBSim's trim did not converge; out of tolerance: "
            + ", ".join(failed)
        )
    reason = first_warning
    return f"cannot trim {where}: JSBSim's trim failed" + (f" ({reason})" if reason else "")


@contextlib.contextmanager
def trim_report(fdm):
    """JSBSim prints its trim's axis report, which :func:`diagnose_trim_failure` reads, only
    at a debug level of 1 or more, and that level is the process's (``FGJSBBase::debug_lvl``:
    any ``FGFDMExec.set_debug_level`` changes it for every instance; a test that silenced its
    own JSBSim made a later 60 m/s trim read "accelerates even at zero throttle"): at least 1
    during the trim, the level found restored after."""
    level = fdm.get_debug_level()
    fdm.set_debug_level(max(1, level))
    try:
        yield
    finally:
        fdm.set_debug_level(level)
