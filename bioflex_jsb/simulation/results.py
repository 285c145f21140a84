"""Results of a run as data: named channels with units, and the gust-response metrics.

Channels of a gust run (:mod:`bioflex_jsb.simulation.channels` describes each one:
``run.describe()``): time_s [s]; u [m/s], alpha [rad], theta [rad] perturbations from the
trim at the start of the run (also named du_m_s, dalpha_rad, dtheta_rad, the log's names),
q [rad/s] the pitch rate; n_z [-] load factor (1 in level flight, positive up), w_g [m/s]
gust (up); the absolute state (airspeed_m_s, alpha_rad, theta_rad, phi_rad, psi_rad, …),
eta1..etan [rad] modal coordinates, lift_n / drag_n / pitch_moment_n_m the modal loads
applied, loads_<fs|md>_<quantity>_s<j> the wing's section loads.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.simulation.channels import ALIASES
from bioflex_jsb.simulation.channels import describe as describe_channel

SETTLING_BAND = 0.05  # settled: |Δα| stays within 5 % of its peak (a common 5 % criterion)
# The short-period settling (GustMetrics.short_period_settling_time_s) separates the slow
# motion by a least-squares fit of Δα = a Δu + b Δθ + c over the last SLOW_FIT_FRACTION of
# the record after the gust; it needs at least SLOW_FIT_MIN_RECORD_S of record after the
# gust, so that the fit window (≥ 1 s) spans more than one short-period cycle (0.7-0.9 s at
# 15 m/s: Table 3) and cannot absorb a short period that is still ringing.
SLOW_FIT_FRACTION = 0.5
SLOW_FIT_MIN_RECORD_S = 2.0
# A gust run keeps every step (keep="all") up to this duration by default [s] (≈ 0.24 MB
# per simulated second of table, and as much again for the returned history); longer runs
# keep an envelope (keep="envelope": drivers/gust.py), which section loads cannot use.
KEEP_ALL_MAX_S = 120.0
TURBULENCE_KINDS = ("dryden", "vonkarman")  # continuous gusts: no single peak to settle from

# How a run left its valid range (the stop messages of simulation/limits.py), as a name.
_DIVERGENCE_PATTERNS = (
    (re.compile(r"mode (aeroelastic_\d+) diverged"), None),  # None: the matched mode name
    (re.compile(r"angle of attack"), "angle_of_attack"),
    (re.compile(r"non-finite"), "non_finite_state"),
    (re.compile(r"ground"), "ground"),
    (re.compile(r"interrupted"), "interrupted"),
)


def divergence_mode(stopped: str) -> str:
    """Short name of why a run stopped: ``aeroelastic_<i>`` (a wing mode beyond its linear
    range), ``angle_of_attack`` (left the aerodynamic tables), ``non_finite_state``,
    ``ground``, ``interrupted``, else ``other``."""
    for pattern, name in _DIVERGENCE_PATTERNS:
        found = pattern.search(stopped)
        if found:
            return name or found.group(1)
    return "other"


def stop_event_text(model: str, stopped: str) -> str:
    """The text of a log's event for ``model``'s run that stopped (``stopped``: why):
    "<model> run stopped (<divergence mode>): <why>", as ``gust`` logs it; reading a log
    back takes ``stopped`` from it."""
    return f"{model} run stopped ({divergence_mode(stopped)}): {stopped}"


@dataclass
class TimeHistory:
    """One run: ``channels[name]`` sampled at ``time_s`` [s]; ``units[name]`` says the unit
    and :meth:`describe` what each channel is (perturbation or absolute, frame, sign).
    ``run[name]`` also takes a perturbation's self-describing name (``run["dalpha_rad"]`` is
    ``run["alpha"]``: :data:`~bioflex_jsb.simulation.channels.ALIASES`)."""

    model: str
    time_s: np.ndarray
    channels: dict[str, np.ndarray]
    units: dict[str, str]
    meta: dict[str, object] = field(default_factory=dict)
    stopped: str | None = None  # why the run stopped early (divergence), None if it finished

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.channels[ALIASES.get(name, name)]
        except KeyError:  # the channels it has, in the message (a bare KeyError said none)
            raise KeyError(f"no channel {name!r} in this {self.model} run; channels: "
                           f"{', '.join(self.channels)}") from None

    def __contains__(self, name: str) -> bool:
        return ALIASES.get(name, name) in self.channels

    def describe(self) -> dict[str, dict[str, str | None]]:
        """Every channel's unit, kind (``perturbation`` from the trim at the start of the
        run, or ``absolute``), meaning (the quantity, its frame and sign) and alias (the
        self-describing name it also answers to, None when its own name says it), by
        channel name in the run's order."""
        return {name: dict(describe_channel(name, self.units.get(name)).as_dict(),
                           unit=self.units.get(name, "?"))
                for name in self.channels}

    @property
    def stop_time_s(self) -> float | None:
        """Time of the last sample of a run that stopped early [s]; None if it finished."""
        if self.stopped is None:
            return None
        return float(self.time_s[-1]) if len(self.time_s) else 0.0

    def truncated(self, n: int) -> TimeHistory:
        """The first ``n`` samples."""
        return TimeHistory(
            self.model,
            self.time_s[:n],
            {k: v[:n] for k, v in self.channels.items()},
            dict(self.units),
            dict(self.meta),
            self.stopped,
        )


# The numeric fields of GustMetrics (GustMetrics.as_dict), e.g. a results table's columns.
NUMERIC_METRICS = (
    "peak_du_m_s", "peak_dalpha_rad", "peak_dq_rad_s", "peak_dtheta_rad", "peak_dn_z",
    "overshoot", "settling_time_s", "rms_du_m_s", "rms_dalpha_rad", "rms_dq_rad_s",
    "rms_dtheta_rad", "rms_dn_z", "divergence_time_s", "short_period_settling_time_s",
)
# The RMS metrics, given for turbulence (GustMetrics)
RMS_METRICS = tuple(k for k in NUMERIC_METRICS if k.startswith("rms_"))


@dataclass(frozen=True, repr=False)
class GustMetrics:
    """Gust-response summary of one run (perturbations from trim, after the gust start).

    Every run: peak_du_m_s, peak_dalpha_rad, peak_dq_rad_s, peak_dtheta_rad: largest
    |perturbation| [m/s, rad, rad/s, rad]; peak_dn_z: largest |n_z − 1| [-].

    A discrete gust (``kind`` "discrete": sharp-edged, 1-cosine): overshoot, the largest
    excursion of Δα past zero after its first peak as a fraction of that peak [-] (a
    short-period damping measure: 0 for a dead-beat response); settling_time_s, from the gust
    start until |Δα| stays within 5 % of its peak [s], None when it has not settled by the
    end of the run. Δα is measured from the trim α, and that is the right reference: α is
    the angle to the relative wind, and a uniform vertical gust that persists leaves the
    same trim relative to the air (the aircraft climbs with the air mass), so Δα returns to
    0. This settling time is that of the whole motion, the phugoid included: where the
    phugoid carries |Δα| above 5 % of the peak (the elastic wing's phugoid, whose α follows
    the speed through the wing's twist), it measures the phugoid's decay, not the short
    period's.

    short_period_settling_time_s [s]: the same 5 % band on the short-period part of Δα, the
    "stabilisation time" of the paper's Fig. 21 (whose transfer functions are those of the
    short-period response; the paper leaves the phugoid out): Δα minus its slow part, where
    the slow part is a Δu + b Δθ + c fitted by least squares over the last half of the
    record after the gust. Once the fast modes (short period, wing modes) have decayed, the
    state of a linear model lies in the phugoid's two-dimensional invariant subspace, on
    which Δα is a fixed linear combination of Δu and Δθ, so the fit leaves exactly the
    fast part. None when the run has not settled so by its end, or when it has less than
    SLOW_FIT_MIN_RECORD_S [s] of record after the gust (the fit window would not span a
    short-period cycle).

    Turbulence (``kind`` "turbulence": Dryden, von Kármán): there is no single peak to
    overshoot or settle from, so overshoot and settling_time_s are None and the RMS of each
    perturbation is given instead (rms_du_m_s, rms_dalpha_rad, rms_dq_rad_s, rms_dtheta_rad
    [m/s, rad, rad/s, rad], rms_dn_z [-]); the peaks are the largest values of this one
    random record.

    A run that diverged (left the valid range: ``diverged`` True) has every response metric
    None: a peak of a diverging response measures the divergence, not the gust response.
    ``divergence_time_s`` [s] and ``divergence_mode`` (:func:`divergence_mode`) say when and
    how, ``divergence`` the full reason.

    ``loads``: the wing's section loads (:func:`section_load_metrics`, ``docs/loads.md``):
    per method, quantity and monitoring station the largest and smallest value after the
    gust start with their times, the 1 g value and the increments over it; None for a run
    without load channels or one that diverged; ``{"unavailable": why}`` for a run whose
    wing has no section loads (a modes-file wing, the native wing).
    """

    kind: str
    peak_du_m_s: float | None
    peak_dalpha_rad: float | None
    peak_dq_rad_s: float | None
    peak_dtheta_rad: float | None
    peak_dn_z: float | None
    overshoot: float | None = None
    settling_time_s: float | None = None
    rms_du_m_s: float | None = None
    rms_dalpha_rad: float | None = None
    rms_dq_rad_s: float | None = None
    rms_dtheta_rad: float | None = None
    rms_dn_z: float | None = None
    short_period_settling_time_s: float | None = None
    diverged: bool = False
    divergence_time_s: float | None = None
    divergence_mode: str | None = None
    divergence: str | None = None
    loads: dict[str, object] | None = None

    def __repr__(self) -> str:
        """One line: the kind, the metrics that have a value (4 digits), the divergence and
        a summary of ``loads`` (the full dict is ``.loads``)."""
        parts = [f"kind={self.kind!r}"]
        parts += [f"{k}={v:.4g}" for k, v in self.as_dict().items() if v is not None]
        if self.diverged:
            parts.append(f"diverged=True, divergence_mode={self.divergence_mode!r}")
        if self.loads is not None:
            parts.append(f"loads=<{_loads_summary(self.loads)}: .loads>")
        return f"GustMetrics({', '.join(parts)})"

    def as_dict(self) -> dict[str, float | None]:
        """The numeric metrics only (:data:`NUMERIC_METRICS`: numbers or None)."""
        return {k: getattr(self, k) for k in NUMERIC_METRICS}

    def as_json(self) -> dict[str, object]:
        """Every field: the numeric metrics and ``kind``, ``diverged``, ``divergence_mode``,
        ``divergence``."""
        return dict(self.__dict__)


def _loads_summary(loads: dict) -> str:
    """``GustMetrics.loads`` in a few words: its methods and stations, or why it has none."""
    if "unavailable" in loads:
        return f"unavailable: {loads['unavailable']}"
    methods = ", ".join(loads.get("methods", {})) or "no methods"
    return f"{methods} at {len(loads.get('stations_m', []))} stations"


def is_turbulence(gust_text: str) -> bool:
    """Whether a gust specification (``dryden:1:50``, ``sharp:3``) is continuous turbulence."""
    return str(gust_text).split(":", 1)[0].strip().lower() in TURBULENCE_KINDS


def gust_metrics(run: TimeHistory, gust_start_s: float,
                 turbulence: bool | None = None) -> GustMetrics:
    """Summarise ``run`` for a gust that starts at ``gust_start_s`` [s].

    ``turbulence``: whether the gust is continuous (RMS instead of overshoot and settling);
    None reads it from the gust specification ``run.meta["gust"]``.
    """
    if turbulence is None:
        turbulence = is_turbulence(str(run.meta.get("gust", "")))
    kind = "turbulence" if turbulence else "discrete"
    loads = None if run.stopped is not None else section_load_metrics(run, gust_start_s)
    if run.stopped is not None:
        return GustMetrics(kind, None, None, None, None, None, diverged=True,
                           divergence_time_s=run.stop_time_s,
                           divergence_mode=divergence_mode(run.stopped),
                           divergence=" ".join(str(run.stopped).split()))
    after = run.time_s >= gust_start_s
    if not np.any(after):
        return GustMetrics(kind, None, None, None, None, None, loads=loads)
    ta = run.time_s[after]
    du, alpha, dq, dtheta = (run[c][after] for c in ("u", "alpha", "q", "theta"))
    dn_z = run["n_z"][after] - 1.0

    def peak(x: np.ndarray) -> float:
        return float(np.max(np.abs(x)))

    def rms(x: np.ndarray) -> float:
        return float(np.sqrt(np.mean(np.square(x))))

    common = dict(peak_du_m_s=peak(du), peak_dalpha_rad=peak(alpha), peak_dq_rad_s=peak(dq),
                  peak_dtheta_rad=peak(dtheta), peak_dn_z=peak(dn_z))
    common["loads"] = loads
    if turbulence:
        return GustMetrics(kind, **common, rms_du_m_s=rms(du), rms_dalpha_rad=rms(alpha),
                           rms_dq_rad_s=rms(dq), rms_dtheta_rad=rms(dtheta), rms_dn_z=rms(dn_z))
    i_peak = int(np.argmax(np.abs(alpha)))
    a_peak = float(alpha[i_peak])
    if a_peak != 0.0:
        past = -np.sign(a_peak) * alpha[i_peak:]
        overshoot = float(max(0.0, past.max()) / abs(a_peak))
        band = SETTLING_BAND * abs(a_peak)
        settling = _settling_time(ta, alpha, band, gust_start_s)
        fast = _short_period_part(ta, alpha, du, dtheta, gust_start_s)
        sp_settling = None if fast is None else _settling_time(ta, fast, band, gust_start_s)
    else:
        overshoot, settling, sp_settling = 0.0, 0.0, 0.0
    return GustMetrics(kind, **common, overshoot=overshoot, settling_time_s=settling,
                       short_period_settling_time_s=sp_settling)


LOAD_METHODS = (("force_summation", "fs"), ("mode_displacement", "md"))
LOAD_QUANTITIES = ("shear_n", "bending_n_m", "torque_n_m")  # bioflex_jsb.loads.QUANTITIES


def section_load_metrics(run: TimeHistory, gust_start_s: float) -> dict[str, object] | None:
    """The section-load metrics of a run with load channels ``loads_<fs|md>_<quantity>_s<j>``
    [N, N·m] and their layout in ``run.meta["loads"]`` (stations_m, station_fractions,
    methods, static_1g per channel: :mod:`bioflex_jsb.loads.stream`): per method, quantity
    and station the largest and smallest value at or after ``gust_start_s`` [s] with their
    times [s], the 1 g value and the increments over it (``increment_up`` = max − 1 g,
    ``increment_down`` = min − 1 g); ``max_abs_difference`` the largest |FS − MD| per
    quantity and station when both methods are there. None without load channels;
    ``{"unavailable": why}`` when the run says why it has none. An envelope history
    (``keep="envelope"``) keeps every load's and difference's extremes, so these are those
    of every step."""
    layout = run.meta.get("loads")
    if layout is None:
        why = run.meta.get("loads_unavailable")
        return None if why is None else {"unavailable": str(why)}
    fractions = list(layout["station_fractions"])
    out: dict[str, object] = {"stations_m": list(layout["stations_m"]),
                              "station_fractions": fractions,
                              "static": layout.get("note"), "methods": {}}
    after = run.time_s >= gust_start_s
    if not np.any(after):
        return out
    t = run.time_s[after]
    static = layout["static_1g"]
    labels = ["root" if f == 0.0 else f"{100 * f:g}% b/2" for f in fractions]
    for method, tag in LOAD_METHODS:
        if method not in layout["methods"]:
            continue
        per_q = {}
        for quantity in LOAD_QUANTITIES:
            rows = []
            for j, label in enumerate(labels):
                name = f"loads_{tag}_{quantity}_s{j}"
                x = run.channels[name][after]
                i_hi, i_lo = int(np.argmax(x)), int(np.argmin(x))
                s_1g = float(static[name])
                rows.append({"station": label, "max": float(x[i_hi]),
                             "time_max_s": float(t[i_hi]), "min": float(x[i_lo]),
                             "time_min_s": float(t[i_lo]), "static_1g": s_1g,
                             "increment_up": float(x[i_hi]) - s_1g,
                             "increment_down": float(x[i_lo]) - s_1g})
            per_q[quantity] = rows
        out["methods"][method] = per_q
    if all(m in layout["methods"] for m, _ in LOAD_METHODS):
        out["max_abs_difference"] = {
            quantity: [float(np.max(np.abs(run.channels[f"loads_fs_{quantity}_s{j}"][after]
                                           - run.channels[f"loads_md_{quantity}_s{j}"][after])))
                       for j in range(len(labels))]
            for quantity in LOAD_QUANTITIES}
    return out


def _settling_time(t: np.ndarray, x: np.ndarray, band: float, start_s: float) -> float | None:
    """Time from ``start_s`` until |x| stays within ``band`` [s]; None if the last sample
    is outside it."""
    outside = np.nonzero(np.abs(x) > band)[0]
    if len(outside) == 0:
        return 0.0
    last = outside[-1]
    return None if last == len(x) - 1 else float(t[last + 1] - start_s)


def _short_period_part(t: np.ndarray, alpha: np.ndarray, du: np.ndarray, dtheta: np.ndarray,
                       start_s: float) -> np.ndarray | None:
    """Δα minus its slow (phugoid) part a Δu + b Δθ + c, fitted over the last
    SLOW_FIT_FRACTION of the record after ``start_s`` (GustMetrics); None if the record
    after ``start_s`` is shorter than SLOW_FIT_MIN_RECORD_S."""
    if len(t) < 2 or t[-1] - start_s < SLOW_FIT_MIN_RECORD_S:
        return None
    fit = t >= t[-1] - SLOW_FIT_FRACTION * (t[-1] - start_s)
    basis = np.column_stack([du, dtheta, np.ones_like(du)])
    coef = np.linalg.lstsq(basis[fit], alpha[fit], rcond=None)[0]
    return alpha - basis @ coef


def nrmse(reference: np.ndarray, other: np.ndarray) -> float:
    """RMS(other − reference) / RMS(reference) [-]; ``inf`` when the reference is all zero."""
    ref = np.asarray(reference, dtype=float)
    diff = np.asarray(other, dtype=float) - ref
    denom = float(np.sqrt(np.mean(ref**2)))
    if denom == 0.0:
        return float("inf") if np.any(diff != 0.0) else 0.0
    return float(np.sqrt(np.mean(diff**2)) / denom)
