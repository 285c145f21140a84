"""Eigen-analysis of the LTI models: labelled modes, tracking through speed, flutter search.

Mode identity (``short_period``, ``phugoid``, ``aeroelastic_1`` …) is fixed once, at a low
starting speed where the aerodynamic coupling is weak, by matching the coupled eigenvalues to
those of the *uncoupled* blocks (A_RR for the rigid modes; the structural block
[[0, I], [A_EE, A_EĖ]] for the aeroelastic ones). From there every label is carried from one
speed to the next by eigenvector correlation (modal assurance criterion) together with
eigenvalue continuity, never by sort order, so crossings and coalescences do not swap labels.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import linear_sum_assignment

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel, build_state_space, coupled_blocks
from bioflex_jsb.flight_dynamics.rigid import FlightCondition, level_flight_condition
from bioflex_jsb.parameters import prototype as P

RIGID_LABELS = ("short_period", "phugoid")
IMAG_TOL_RAD_S = 1e-6  # below this |Im λ| a root is reported as real [rad/s]
EXCLUDED_FROM_FLUTTER = ("phugoid",)
UNSTABLE_RE_RAD_S = 1e-9  # a root with Re λ above this is unstable [1/s] (find_flutter's tol)
# The name of an unstable real root: a static divergence, whatever branch it was tracked on
# (a real root at +39.5 rad/s is not a "short period" with damping -1). Its Mode keeps the
# tracked identity in ``branch``.
DIVERGENCE_LABEL = "divergence"


@dataclass(frozen=True)
class Mode:
    """One eigenvalue with its mode identity.

    ``re``, ``im`` [rad/s]; ``damping`` ζ = −re/|λ| [-]; ``frequency_rad_s`` ω_n = |λ|;
    ``branch``: the identity tracked through the speed sweep (short_period, phugoid,
    aeroelastic_i), the same as ``mode`` except for an unstable real root, whose ``mode`` is
    ``divergence``; ``unstable``: Re λ > :data:`UNSTABLE_RE_RAD_S`.
    """

    mode: str
    re: float
    im: float
    branch: str = ""

    def __post_init__(self) -> None:
        if not self.branch:
            object.__setattr__(self, "branch", self.mode)

    @property
    def unstable(self) -> bool:
        return self.re > UNSTABLE_RE_RAD_S

    @property
    def eigenvalue(self) -> complex:
        return complex(self.re, self.im)

    @property
    def frequency_rad_s(self) -> float:
        return float(abs(self.eigenvalue))

    @property
    def damping(self) -> float:
        wn = self.frequency_rad_s
        return float(-self.re / wn) if wn > 0.0 else 1.0

    def as_dict(self) -> dict[str, float | str]:
        return {
            "mode": self.mode,
            "re": self.re,
            "im": self.im,
            "damping": self.damping,
            "frequency_rad_s": self.frequency_rad_s,
            "stable": not self.unstable,
            "branch": self.branch,
        }


@dataclass(frozen=True)
class ModeSet:
    """The labelled modes of one model at one speed (one entry per conjugate pair)."""

    speed_m_s: float
    model: str
    modes: tuple[Mode, ...]

    def get(self, name: str) -> Mode:
        """The mode called ``name`` (for a real pair, the less stable root); failing that, the
        root tracked on the branch ``name`` (e.g. the ``divergence`` root that the short
        period turned into)."""
        found = [m for m in self.modes if m.mode == name] or [
            m for m in self.modes if m.branch == name]
        if not found:
            raise KeyError(f"no mode {name!r} at {self.speed_m_s} m/s ({self.model})")
        return max(found, key=lambda m: m.re)

    def as_dict(self) -> dict[str, object]:
        return {
            "speed_m_s": self.speed_m_s,
            "model": self.model,
            "modes": [m.as_dict() for m in self.modes],
        }


def _reference(model: str, wing: ElasticWingModel | None, cond: FlightCondition):
    """Uncoupled reference eigenvalues with labels, for the first speed of a sweep."""
    ss_rigid = build_state_space("rigid", cond)
    lam = np.linalg.eigvals(ss_rigid.a)
    order = np.argsort(-np.abs(lam))  # short period: the two largest |λ|
    labels = [RIGID_LABELS[0]] * 2 + [RIGID_LABELS[1]] * 2
    ref = [(labels[k], lam[i]) for k, i in enumerate(order)]
    if model == "coupled":
        assert wing is not None
        blk = coupled_blocks(wing, cond)
        n = wing.n_modes
        s = np.block([[np.zeros((n, n)), np.eye(n)], [blk.a_ee, blk.a_eedot]])
        lam_e = np.linalg.eigvals(s)
        # aeroelastic_i: ordered by natural frequency of the uncoupled structural block
        order_e = np.argsort(np.abs(lam_e), kind="stable")
        for k, i in enumerate(order_e):
            ref.append((f"aeroelastic_{k // 2 + 1}", lam_e[i]))
    return ref


def _mac(v_prev: np.ndarray, v_now: np.ndarray) -> np.ndarray:
    """Modal assurance criterion matrix between two sets of (column) eigenvectors."""
    num = np.abs(v_prev.conj().T @ v_now) ** 2
    den = np.outer(np.sum(np.abs(v_prev) ** 2, axis=0), np.sum(np.abs(v_now) ** 2, axis=0))
    return num / den


def _collapse(speed: float, model: str, labels: Sequence[str], lam: np.ndarray) -> ModeSet:
    """One entry per conjugate pair (im ≥ 0); both roots of a real pair."""
    modes: list[Mode] = []
    for name in dict.fromkeys(labels):
        roots = [lam[k] for k, lab in enumerate(labels) if lab == name]
        complex_roots = [r for r in roots if abs(r.imag) > IMAG_TOL_RAD_S]
        if complex_roots:
            r = max(complex_roots, key=lambda z: z.imag)
            modes.append(Mode(name, float(r.real), float(abs(r.imag))))
        else:
            for r in sorted(roots, key=lambda z: z.real):
                label = DIVERGENCE_LABEL if r.real > UNSTABLE_RE_RAD_S else name
                modes.append(Mode(label, float(r.real), 0.0, branch=name))
    return ModeSet(speed, model, tuple(modes))


@dataclass(frozen=True)
class Sweep:
    """Tracked eigenvalues of one model over a speed grid.

    ``eigenvalues[k, j]`` is the j-th root at ``speeds_m_s[k]``; ``labels[j]`` its identity
    (constant along the sweep by construction); ``eigenvectors[k][:, j]`` its eigenvector.
    """

    model: str
    speeds_m_s: np.ndarray
    eigenvalues: np.ndarray
    labels: tuple[str, ...]
    eigenvectors: tuple[np.ndarray, ...]
    wing: ElasticWingModel | None
    density_kg_m3: float

    def at(self, k: int) -> ModeSet:
        return _collapse(float(self.speeds_m_s[k]), self.model, self.labels, self.eigenvalues[k])

    def mode_sets(self) -> list[ModeSet]:
        return [self.at(k) for k in range(len(self.speeds_m_s))]

    def continued(self, k: int, speed_m_s: float) -> np.ndarray:
        """Roots at ``speed_m_s``, ordered like the labels, continued from grid point ``k``."""
        lam, vec = _eig(self.model, speed_m_s, self.wing, self.density_kg_m3)
        perm = _match(self.eigenvalues[k], self.eigenvectors[k], lam, vec)
        return lam[perm]


def _eig(model: str, speed_m_s: float, wing, density_kg_m3: float):
    ss = build_state_space(model, level_flight_condition(float(speed_m_s), density_kg_m3), wing)
    return np.linalg.eig(ss.a)


def _match(lam_prev, vec_prev, lam, vec) -> np.ndarray:
    """Permutation of (lam, vec) that best continues (lam_prev, vec_prev)."""
    mac = _mac(vec_prev, vec)
    dist = np.abs(lam_prev[:, None] - lam[None, :]) / (1.0 + np.abs(lam_prev)[:, None])
    rows, cols = linear_sum_assignment((1.0 - mac) + dist)
    return cols[np.argsort(rows)]


def track(
    model: str,
    speeds_m_s: Sequence[float],
    wing: ElasticWingModel | None = None,
    density_kg_m3: float = P.SEA_LEVEL_DENSITY_KG_M3,
) -> Sweep:
    """Eigenvalues of ``model`` at increasing ``speeds_m_s`` with labels tracked.

    The grid should be fine enough that eigenvectors change little between neighbours
    (0.25 m/s is ample here; :func:`sweep_grid` makes one).
    """
    speeds = np.asarray(speeds_m_s, dtype=float)
    if speeds.ndim != 1 or len(speeds) == 0 or np.any(np.diff(speeds) <= 0):
        raise ValueError("speeds_m_s must be a non-empty, strictly increasing sequence")
    all_lam, all_vec = [], []
    labels: list[str] = []
    for k, v in enumerate(speeds):
        lam, vec = _eig(model, float(v), wing, density_kg_m3)
        if k == 0:
            ref = _reference(model, wing, level_flight_condition(float(v), density_kg_m3))
            if model == "qsd":
                ref = ref[:4]
            ref_lam = np.array([r[1] for r in ref])
            cost = np.abs(ref_lam[:, None] - lam[None, :]) / (1.0 + np.abs(ref_lam[:, None]))
            rows, cols = linear_sum_assignment(cost)
            perm = cols[np.argsort(rows)]
            labels = [r[0] for r in ref]
        else:
            perm = _match(all_lam[-1], all_vec[-1], lam, vec)
        all_lam.append(lam[perm])
        all_vec.append(vec[:, perm])
    return Sweep(model, speeds, np.array(all_lam), tuple(labels), tuple(all_vec), wing,
                 density_kg_m3)


def sweep_grid(
    targets_m_s: Sequence[float], start_m_s: float = 2.0, step_m_s: float = 0.25
) -> np.ndarray:
    """A tracking grid from ``start_m_s`` that contains every target speed exactly."""
    top = max(targets_m_s)
    start = min(start_m_s, min(targets_m_s))
    grid = np.arange(start, top + step_m_s, step_m_s)
    grid = np.union1d(grid[grid <= top], np.asarray(targets_m_s, dtype=float))
    return grid


def modes_at(
    model: str,
    speeds_m_s: Sequence[float],
    wing: ElasticWingModel | None = None,
    density_kg_m3: float = P.SEA_LEVEL_DENSITY_KG_M3,
) -> list[ModeSet]:
    """Labelled modes of ``model`` at each speed in ``speeds_m_s`` (labels tracked from 2 m/s)."""
    targets = sorted(set(float(v) for v in speeds_m_s))
    grid = sweep_grid(targets)
    sweep = track(model, grid, wing, density_kg_m3)
    index = {float(v): k for k, v in enumerate(grid)}
    by_speed = {v: sweep.at(index[v]) for v in targets}
    return [by_speed[float(v)] for v in speeds_m_s]


@dataclass(frozen=True)
class FlutterResult:
    """Lowest airspeed at which a root crosses into the right half plane.

    ``flutter_speed_m_s`` is None when no root crosses within ``range_m_s``; ``frequency_rad_s``
    is |Im λ| at the crossing (0 for a static divergence, ``kind`` says which).
    """

    wing: str
    flutter_speed_m_s: float | None
    mode: str | None
    frequency_rad_s: float | None
    kind: str | None
    range_m_s: tuple[float, float]

    def as_dict(self) -> dict[str, object]:
        return {
            "wing": self.wing,
            "flutter_speed_m_s": self.flutter_speed_m_s,
            "mode": self.mode,
            "frequency_rad_s": self.frequency_rad_s,
            "kind": self.kind,
            "range_m_s": list(self.range_m_s),
        }


def find_flutter(
    wing: ElasticWingModel,
    range_m_s: tuple[float, float] = (5.0, 40.0),
    step_m_s: float = 0.1,
    tol_m_s: float = 0.01,
    density_kg_m3: float = P.SEA_LEVEL_DENSITY_KG_M3,
    growth_tol_1_s: float = 1e-9,
) -> FlutterResult:
    """Scan the coupled model over ``range_m_s`` and bisect the first crossing to ``tol_m_s``.

    A root counts as unstable when Re λ > ``growth_tol_1_s`` [1/s]. The phugoid is left out
    of the search, as the paper leaves it out of Figs. 15-19 (Section 3.2: the vortex model
    cannot give the drag the phugoid depends on): in the linear model it goes unstable below
    about 10 m/s, where the formal trim C_L exceeds 2, for the rigid aircraft as well.
    """
    lo, hi = range_m_s
    if not (0.0 < lo < hi):
        raise InputError(f"flutter range must satisfy 0 < low < high, got {lo}:{hi}")
    grid = np.arange(min(2.0, lo), hi + 0.5 * step_m_s, step_m_s)
    grid = grid[grid <= hi + 1e-12]
    sweep = track("coupled", grid, wing, density_kg_m3)
    considered = np.array([lab not in EXCLUDED_FROM_FLUTTER for lab in sweep.labels])
    growth = sweep.eigenvalues[:, considered].real.max(axis=1)
    in_range = grid >= lo - 1e-12
    unstable = np.nonzero((growth > growth_tol_1_s) & in_range)[0]
    if len(unstable) == 0:
        return FlutterResult(wing.name, None, None, None, None, (lo, hi))
    k = int(unstable[0])
    if k == 0 or not in_range[k - 1]:
        v_cross = float(grid[k])  # already unstable at the bottom of the range
    else:
        a, b = float(grid[k - 1]), float(grid[k])

        def max_re(v: float) -> float:
            return float(sweep.continued(k - 1, v)[considered].real.max())

        while b - a > tol_m_s:
            mid = 0.5 * (a + b)
            if max_re(mid) > growth_tol_1_s:
                b = mid
            else:
                a = mid
        v_cross = b
    at_cross = sweep.continued(k - 1, v_cross) if k > 0 else sweep.eigenvalues[k]
    masked = np.where(considered, at_cross.real, -np.inf)
    j = int(np.argmax(masked))
    root = at_cross[j]
    kind = "flutter" if abs(root.imag) > IMAG_TOL_RAD_S else "divergence"
    return FlutterResult(
        wing.name,
        round(v_cross, 2),
        sweep.labels[j],
        float(abs(root.imag)),
        kind,
        (lo, hi),
    )
