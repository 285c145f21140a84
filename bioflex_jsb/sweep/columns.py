"""The columns of a campaign's results table (the schema of ``sweep/store.py``'s files): the
inputs of a case, its status, the metrics it asked for, where and when it ran; each with its
type (``str``, ``float``, ``int``; None is allowed in every column)."""

from __future__ import annotations

from collections.abc import Sequence

from bioflex_jsb.flight_dynamics.wing_model import DEFAULT_N_MODES
from bioflex_jsb.simulation.results import RMS_METRICS

DEFAULT_AERO = "quasi-steady"  # the coupled step's strips (run.aero) of the paper
# Modes whose eigenvalues the "eigenvalues" metric records (NaN where a model has no such
# mode: the rigid and QSD models have no aeroelastic modes).
EIGEN_MODES = ("short_period", "phugoid") + tuple(
    f"aeroelastic_{i + 1}" for i in range(DEFAULT_N_MODES)
)

# name -> type ("str", "float", "int"); None is allowed in every column.
INPUT_COLUMNS: dict[str, str] = {
    "case_id": "str",
    "case_index": "int",
    "wing": "str",
    "x_inertial_frac": "float",
    "x_elastic_frac": "float",
    "pinned_c_eta1_q1": "float",
    "speed_m_s": "float",
    "gust": "str",
    "gust_kind": "str",
    "gust_amplitude_m_s": "float",
    "gust_length_m": "float",
    "seed": "int",
    "model": "str",
    "duration_s": "float",
    "gust_start_s": "float",
    "dt_s": "float",
    "mass_basis": "str",
}
STATUS_COLUMNS: dict[str, str] = {
    "status": "str",  # ok | diverged (the gust run left the valid range) | failed
    "error": "str",
}
METRIC_COLUMNS: dict[str, dict[str, str]] = {
    "gust": {
        "peak_du_m_s": "float",
        "peak_dalpha_rad": "float",
        "peak_dq_rad_s": "float",
        "peak_dtheta_rad": "float",
        "peak_dn_z": "float",
        "overshoot": "float",
        "settling_time_s": "float",
        "time_beyond_stall_s": "float",
        "time_flown_s": "float",
    },
    "flutter": {
        "flutter_speed_m_s": "float",
        "flutter_mode": "str",
        "flutter_frequency_rad_s": "float",
        "flutter_kind": "str",
    },
    "eigenvalues": {
        f"{mode}_{part}": "float"
        for mode in EIGEN_MODES
        for part in ("re_rad_s", "im_rad_s", "damping", "frequency_rad_s")
    },
    "coefficients": {
        "c_eta1_q1": "float",
        "c_eta1_q1_physical": "float",
        "e_shift_frac": "float",
        **{f"mode{i + 1}_frequency_hz": "float" for i in range(DEFAULT_N_MODES)},
    },
}
# The RMS of each perturbation after the gust start (GustMetrics: the response to turbulence
# that ``gust`` reports), in the tables of campaigns with a turbulence gust, after the gust
# metrics (empty for their discrete gusts); a table of discrete gusts keeps its columns.
TURBULENCE_COLUMNS: dict[str, str] = dict.fromkeys(RMS_METRICS, "float")
# The largest command of a case's controller over the run (|ctrl_<command>| [rad], [-]):
# what it asked of the surface and the motor, in the tables of campaigns with a controllers
# axis (empty for a case without a controller or a command it does not write).
CONTROLLER_COLUMNS: dict[str, str] = {"peak_ctrl_elevator_rad": "float",
                                      "peak_ctrl_throttle": "float",
                                      "peak_ctrl_flaperon_rad": "float"}
# Columns a table of the same campaign written by an earlier version lacks; such a table is
# resumed without them (its new rows leave them out, as its earlier rows do).
LATER_COLUMNS: frozenset[str] = frozenset({*TURBULENCE_COLUMNS, "peak_ctrl_flaperon_rad"})
# Where and when a case ran: differs between runs of the same case, so comparisons of
# results tables leave these out (:data:`RUN_INFO_COLUMNS`).
RUN_INFO_COLUMNS: dict[str, str] = {
    "worker": "str",
    "started_unix_s": "float",
    "wall_time_s": "float",
}


def result_columns(metrics: Sequence[str], aero: str = DEFAULT_AERO,
                   aircraft: bool = False, turbulence: bool = False,
                   controller: bool = False) -> dict[str, str]:
    """Every column of a results table for ``metrics``, in order, with its type. A campaign
    of the unsteady strips (``aero``) has an ``aero`` column after ``mass_basis``, one with
    an ``aircraft`` axis an ``aircraft`` column after ``wing`` (the definition's name, empty
    for the wings of ``axes.wings``), one with a ``turbulence`` gust and the gust metrics the
    :data:`TURBULENCE_COLUMNS` after them, one with a ``controllers`` axis a
    ``controller`` column after ``model`` (the file's path or the shipped name, "none") and
    the controller's command peaks after the gust metrics (:data:`CONTROLLER_COLUMNS`,
    empty without one); other tables keep the columns of a store written without these
    options (so its files resume)."""
    cols = {}
    for name, kind in INPUT_COLUMNS.items():
        cols[name] = kind
        if name == "wing" and aircraft:
            cols["aircraft"] = "str"
        if name == "model" and controller:
            cols["controller"] = "str"
    if aero != DEFAULT_AERO:
        cols["aero"] = "str"
    cols.update(STATUS_COLUMNS)
    for m, columns in METRIC_COLUMNS.items():
        if m in metrics:
            cols.update(columns)
            if m == "gust" and turbulence:
                cols.update(TURBULENCE_COLUMNS)
            if m == "gust" and controller:
                cols.update(CONTROLLER_COLUMNS)
    cols.update(RUN_INFO_COLUMNS)
    return cols
