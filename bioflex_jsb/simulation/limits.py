"""The valid range of a run, checked after every step by the one coupled step.

A run that leaves it stops; the message names the cause, the time and, for a wing mode, the
mode (``docs/conventions.md``).
"""

from __future__ import annotations

import math

# A modal coordinate beyond this is outside the linear (small-twist) range of the model:
# the modes are normalised on twist, and at 0.52 rad (30°) of twist sin η differs from η by
# 4.5 %, the limit we accept for the small-angle kinematics behind Eq. (3).
ETA_LIMIT_RAD = 0.52
# The run stops when α leaves the airframe's aerodynamic tables (no data beyond: the range is
# the airframe's own, runtime/fdm.py Airframe.alpha_table_range_rad). Between the lift peak
# and the table end JSBSim's post-stall model holds while the modal derivatives, linear in α,
# do not: that time is reported (``time_beyond_stall_s``), not stopped, so that a transient
# excursion past the lift peak (the paper's 3 m/s gust at 15 m/s reaches 13.1° against a
# 12.8° peak) is shown rather than hidden or fatal.


def mode_labels(n_symmetric: int, n_antisymmetric: int = 0) -> tuple[tuple[str, str], ...]:
    """(mode name, coordinate channel) of each modal coordinate of a run: the half wing's
    symmetric modes ``aeroelastic_i`` / ``eta<i>``, then both halves' antisymmetric modes
    ``antisymmetric_i`` / ``asym_eta<i>`` (the names ``modes`` and the logs use)."""
    return (tuple((f"aeroelastic_{i + 1}", f"eta{i + 1}") for i in range(n_symmetric))
            + tuple((f"antisymmetric_{i + 1}", f"asym_eta{i + 1}")
                    for i in range(n_antisymmetric)))


def out_of_range(names, values, t_s: float, alpha_rad: float, eta, agl_m: float,
                 alpha_range_rad: tuple[float, float],
                 labels: tuple[tuple[str, str], ...] | None = None) -> str | None:
    """Why the run must stop after the step whose row is ``values`` (``names`` its channel
    names) at ``t_s`` [s], with the angle of attack ``alpha_rad`` [rad], the new modal
    state ``eta`` [rad] and the height above ground ``agl_m`` [m]; None if it may go on.
    ``alpha_range_rad``: the α range of the flown airframe's tables [rad] (the generated
    prototype's from its generator; another aircraft's from its XML:
    runtime/aircraft_files.py). ``labels``: (mode name, channel) of each coordinate of
    ``eta`` (:func:`mode_labels`; None: all symmetric, the half wing's)."""
    isfinite = math.isfinite
    if not all(map(isfinite, values)):
        bad = next(n for n, v in zip(names, values, strict=True) if not isfinite(v))
        return f"the state became non-finite ({bad}) at t = {t_s:.3f} s"
    lo, hi = alpha_range_rad
    if not lo <= alpha_rad <= hi:
        return (
            f"angle of attack {math.degrees(alpha_rad):.1f} deg left the aerodynamic model "
            f"({math.degrees(lo):.0f}..{math.degrees(hi):.0f} deg, deep stall) "
            f"at t = {t_s:.3f} s"
        )
    worst, i_worst = 0.0, -1
    for i, e in enumerate(eta):
        if abs(e) > worst:
            worst, i_worst = abs(e), i
    if worst > ETA_LIMIT_RAD:
        mode, channel = (labels[i_worst] if labels is not None
                         else (f"aeroelastic_{i_worst + 1}", f"eta{i_worst + 1}"))
        return (
            f"mode {mode} diverged: |{channel}| = {worst:.3f} rad > "
            f"{ETA_LIMIT_RAD:.3f} rad (beyond the linear range) at t = {t_s:.3f} s"
        )
    if agl_m <= 0.0:
        return f"the aircraft reached the ground at t = {t_s:.3f} s"
    return None
