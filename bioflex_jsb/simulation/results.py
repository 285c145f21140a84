"""Results of a run as data: named channels with units, and the gust-response metrics.

Channels of a gust run (perturbations are from the trim at the start of the run):
    time_s [s], u [m/s] airspeed perturbation, alpha [rad], q [rad/s], theta [rad] (all
    perturbations), n_z [-] load factor (1 in level flight, positive up), w_g [m/s] gust
    (up), eta1..etan [rad] modal coordinates, lift_n / drag_n / pitch_moment_n_m the modal
    loads applied.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

SETTLING_BAND = 0.05  # settled: |Δα| stays within 5 % of its peak (a common 5 % criterion)


@dataclass
class TimeHistory:
    """One run: ``channels[name]`` sampled at ``time_s``; ``units[name]`` says the unit."""

    model: str
    time_s: np.ndarray
    channels: dict[str, np.ndarray]
    units: dict[str, str]
    meta: dict[str, object] = field(default_factory=dict)
    stopped: str | None = None  # why the run stopped early (divergence), None if it finished

    def __getitem__(self, name: str) -> np.ndarray:
        return self.channels[name]

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


@dataclass(frozen=True)
class GustMetrics:
    """Gust-response summary of one run (perturbations from trim).

    peak_du_m_s, peak_dalpha_rad, peak_dq_rad_s, peak_dtheta_rad: largest |perturbation|;
    peak_dn_z: largest |n_z − 1| [-]; overshoot: largest excursion of Δα past zero after
    its first peak, as a fraction of that peak [-] (a short-period damping measure: 0 for a
    dead-beat response); settling_time_s: from gust start until |Δα| stays within 5 % of its
    peak [s] (None if it never does within the run).
    """

    peak_du_m_s: float
    peak_dalpha_rad: float
    peak_dq_rad_s: float
    peak_dtheta_rad: float
    peak_dn_z: float
    overshoot: float
    settling_time_s: float | None

    def as_dict(self) -> dict[str, float | None]:
        return dict(self.__dict__)


def gust_metrics(run: TimeHistory, gust_start_s: float) -> GustMetrics:
    """Summarise ``run`` for a gust that starts at ``gust_start_s`` [s]."""
    t = run.time_s
    after = t >= gust_start_s
    alpha = run["alpha"][after]
    ta = t[after]

    def peak(name: str) -> float:
        return float(np.max(np.abs(run[name][after]))) if np.any(after) else 0.0

    i_peak = int(np.argmax(np.abs(alpha))) if len(alpha) else 0
    a_peak = float(alpha[i_peak]) if len(alpha) else 0.0
    if a_peak != 0.0:
        past = -np.sign(a_peak) * alpha[i_peak:]
        overshoot = float(max(0.0, past.max()) / abs(a_peak))
        outside = np.nonzero(np.abs(alpha) > SETTLING_BAND * abs(a_peak))[0]
        last = outside[-1]
        settling = None if last == len(alpha) - 1 else float(ta[last + 1] - gust_start_s)
    else:
        overshoot, settling = 0.0, 0.0
    return GustMetrics(
        peak_du_m_s=peak("u"),
        peak_dalpha_rad=abs(a_peak),
        peak_dq_rad_s=peak("q"),
        peak_dtheta_rad=peak("theta"),
        peak_dn_z=float(np.max(np.abs(run["n_z"][after] - 1.0))) if np.any(after) else 0.0,
        overshoot=overshoot,
        settling_time_s=settling,
    )


def nrmse(reference: np.ndarray, other: np.ndarray) -> float:
    """RMS(other − reference) / RMS(reference) [-]; ``inf`` when the reference is all zero."""
    ref = np.asarray(reference, dtype=float)
    diff = np.asarray(other, dtype=float) - ref
    denom = float(np.sqrt(np.mean(ref**2)))
    if denom == 0.0:
        return float("inf") if np.any(diff != 0.0) else 0.0
    return float(np.sqrt(np.mean(diff**2)) / denom)
