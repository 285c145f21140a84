"""Eigen-analysis of the LTI models: labelled modes, tracking through speed, flutter search.

Mode identity (``short_period``, ``phugoid``, ``aeroelastic_1`` …) is fixed once, at a low
starting speed where the aerodynamic coupling is weak, by matching the coupled eigenvalues to
those of the *uncoupled* blocks (A_RR for the rigid modes; the structural block
[[0, I], [A_EE, A_EĖ]] for the aeroelastic ones). From there every label is carried from one
speed to the next by eigenvector correlation (modal assurance criterion) together with
eigenvalue continuity, never by sort order, so crossings and coalescences do not swap labels.
The tracking and the flutter search are the one engine's
(:mod:`bioflex_jsb.flight_dynamics.flutter_engine`): this module supplies the paper model's
state matrix and its reference labels (:class:`~bioflex_jsb.flight_dynamics.flutter_engine.
EigenFamily`), for the default rigid parameter set or another one (``aero``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics import flutter_engine as engine
from bioflex_jsb.flight_dynamics.flutter_engine import FlutterResult
from bioflex_jsb.flight_dynamics.lti import ElasticWingModel, build_state_space, coupled_blocks
from bioflex_jsb.flight_dynamics.rigid import FlightCondition, level_flight_condition
from bioflex_jsb.parameters.airframe import AirframeData, RigidAerodynamics
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3

RIGID_LABELS = ("short_period", "phugoid")
IMAG_TOL_RAD_S = 1e-6  # below this |Im λ| a root is reported as real [rad/s]
EXCLUDED_FROM_FLUTTER = ("phugoid",)
UNSTABLE_RE_RAD_S = engine.GROWTH_TOL_1_S  # Re λ above this is unstable [1/s]
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
    """The labelled modes of one model at one speed (one entry per conjugate pair).

    A sequence of its modes: ``len(ms)``, ``for m in ms``, ``ms[0]``; ``ms["short_period"]``
    is :meth:`get`; ``"phugoid" in ms`` whether :meth:`get` finds that name."""

    speed_m_s: float
    model: str
    modes: tuple[Mode, ...]

    def __len__(self) -> int:
        return len(self.modes)

    def __iter__(self):
        return iter(self.modes)

    def __getitem__(self, key: int | str) -> Mode:
        """``key`` a name (:meth:`get`) or a position in :attr:`modes`."""
        if isinstance(key, str):
            return self.get(key)
        return self.modes[key]

    def __contains__(self, name: object) -> bool:
        return isinstance(name, str) and bool(name) and any(name in (m.mode, m.branch)
                                                            for m in self.modes)

    @property
    def names(self) -> tuple[str, ...]:
        """The modes' names, in order (a real pair's two roots: the name twice)."""
        return tuple(m.mode for m in self.modes)

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


def airframe_of(wing: ElasticWingModel | None, airframe: AirframeData | None) -> AirframeData:
    """The aircraft of an analysis: the wing's (it was built for it), else ``airframe``; a
    rigid analysis without either, or a different ``airframe`` beside a wing, is a caller's
    bug (ValueError)."""
    if wing is None:
        if airframe is None:
            raise ValueError("a rigid analysis needs the aircraft: give airframe= (an "
                             "AirframeData) or a wing built for it")
        return airframe
    if airframe is not None and airframe.reference != wing.airframe.reference:
        raise ValueError(f"wing {wing.name!r} was built for airframe {wing.airframe.name!r}, "
                         f"not {airframe.name!r}")
    return wing.airframe


def _pair_units(lam: np.ndarray) -> list[tuple[int, ...]]:
    """The roots of a real matrix as units: each conjugate pair (indices of both roots) and
    each real root (|Im λ| <= :data:`IMAG_TOL_RAD_S`) alone; ValueError for a complex root
    without its conjugate (:func:`~bioflex_jsb.flight_dynamics.flutter_engine.closed_under_
    conjugation` tells beforehand)."""
    free = list(range(lam.size))
    units: list[tuple[int, ...]] = []
    while free:
        i = free.pop(0)
        if abs(lam[i].imag) <= IMAG_TOL_RAD_S:
            units.append((i,))
            continue
        partner = [k for k in free if engine.conjugates(lam[i], lam[k])]
        if not partner:
            raise ValueError(f"root {lam[i]:.6g} has no conjugate among {lam}")
        free.remove(partner[0])
        units.append((i, partner[0]))
    return units


def mode_labels_of_roots(lam: np.ndarray) -> tuple[str, ...]:
    """``short_period`` or ``phugoid`` for each of the four roots ``lam`` of a real rigid
    longitudinal model (A_RR, or the rigid-body roots of a coupled one).

    Each mode is a second-order factor s² + 2ζω_n s + ω_n² of the characteristic polynomial:
    one conjugate pair or two real roots (an over-damped short period, as the J3Cub's), never
    a pair split between the two, with ω_n² the product of its two roots. The short period is
    the factor of the larger ω_n: of the ways to share the roots so, the one with the largest
    ratio of the short period's ω_n to the phugoid's. With two pairs this is the pair of the
    larger modulus; with four real roots, the two largest. Ranking single roots by modulus
    instead would call the phugoid pair "short_period" when one real short-period root is
    slower than the phugoid.
    """
    lam = np.asarray(lam, dtype=complex)
    if lam.shape != (4,):
        raise ValueError(f"expected the 4 rigid eigenvalues, got shape {lam.shape}")
    best, best_sp = -math.inf, ()
    for sp in _two_root_choices(_pair_units(lam)):
        ph = [i for i in range(4) if i not in sp]
        w_sp = abs(lam[sp[0]] * lam[sp[1]])
        w_ph = abs(lam[ph[0]] * lam[ph[1]])
        ratio = math.inf if w_ph == 0.0 else w_sp / w_ph
        if ratio > best:
            best, best_sp = ratio, sp
    return tuple(RIGID_LABELS[0] if i in best_sp else RIGID_LABELS[1] for i in range(4))


def _two_root_choices(units: list[tuple[int, ...]]) -> list[tuple[int, ...]]:
    """The sets of two roots made of whole units: one pair, or two real roots."""
    out = [u for u in units if len(u) == 2]
    singles = [u[0] for u in units if len(u) == 1]
    out += [(a, b) for k, a in enumerate(singles) for b in singles[k + 1:]]
    return out


def _reference(model: str, wing: ElasticWingModel | None, cond: FlightCondition,
               aero: RigidAerodynamics | None = None):
    """Uncoupled reference eigenvalues with labels, for the first speed of a sweep."""
    ss_rigid = build_state_space("rigid", cond, aero=aero)
    lam = np.linalg.eigvals(ss_rigid.a)
    labels = mode_labels_of_roots(lam)
    order = sorted(range(4), key=lambda i: (labels[i] != RIGID_LABELS[0], -abs(lam[i])))
    ref = [(labels[i], lam[i]) for i in order]
    if model == "coupled":
        assert wing is not None
        blk = coupled_blocks(wing, cond, aero)
        n = wing.n_modes
        s = np.block([[np.zeros((n, n)), np.eye(n)], [blk.a_ee, blk.a_eedot]])
        lam_e = np.linalg.eigvals(s)
        # aeroelastic_i: ordered by natural frequency of the uncoupled structural block
        order_e = np.argsort(np.abs(lam_e), kind="stable")
        for k, i in enumerate(order_e):
            ref.append((f"aeroelastic_{k // 2 + 1}", lam_e[i]))
    return ref if model == "coupled" else ref[:4]


def structural_mode_labels(natural_rad_s: Sequence[float]) -> tuple[str, ...]:
    """The coupled model's name of each wing mode, in the order of ``natural_rad_s``
    (``aeroelastic_k``: the k-th lowest natural frequency, as :func:`_reference` numbers
    the branches)."""
    rank = np.argsort(np.argsort(np.asarray(natural_rad_s, dtype=float), kind="stable"),
                      kind="stable")
    return tuple(f"aeroelastic_{int(r) + 1}" for r in rank)


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


def paper_family(model: str, wing: ElasticWingModel | None, density_kg_m3: float,
                 aero: RigidAerodynamics | None = None,
                 start_m_s: float = 2.0, airframe: AirframeData | None = None
                 ) -> engine.EigenFamily:
    """The paper model ``model`` (rigid, coupled, qsd) as the engine's family: its state
    matrix A(V) and the reference labels of the uncoupled blocks at ``start_m_s``; the
    aircraft is the wing's (:func:`airframe_of`), ``aero`` replaces its derivatives."""
    af = airframe_of(wing, airframe)

    def matrix(v: float) -> np.ndarray:
        return build_state_space(model, level_flight_condition(v, density_kg_m3, aero,
                                                               airframe=af), wing, aero).a

    ref = _reference(model, wing, level_flight_condition(float(start_m_s), density_kg_m3, aero,
                                                         airframe=af), aero)
    natural = () if wing is None else tuple(float(w) for w in wing.frequencies_rad_s)
    return engine.EigenFamily(
        matrix, np.array([r[1] for r in ref]), [r[0] for r in ref], rest_label="lag",
        excluded=EXCLUDED_FROM_FLUTTER, rigid_labels=RIGID_LABELS,
        paired_labels=RIGID_LABELS, partition=mode_labels_of_roots,
        natural_frequencies_rad_s=natural, mode_labels=structural_mode_labels(natural),
        reference_semichord_m=af.reference.mean_chord_m / 2.0, method="state-space",
        aero="quasi-steady", name="" if wing is None else wing.name)


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
    aero: RigidAerodynamics | None = None
    airframe: AirframeData | None = None

    def at(self, k: int) -> ModeSet:
        return _collapse(float(self.speeds_m_s[k]), self.model, self.labels, self.eigenvalues[k])

    def mode_sets(self) -> list[ModeSet]:
        return [self.at(k) for k in range(len(self.speeds_m_s))]

    def continued(self, k: int, speed_m_s: float) -> np.ndarray:
        """Roots at ``speed_m_s``, ordered like the labels, continued from grid point ``k``."""
        fam = paper_family(self.model, self.wing, self.density_kg_m3, self.aero,
                           float(self.speeds_m_s[0]), self.airframe)
        prev = engine.Point(float(self.speeds_m_s[k]), self.eigenvalues[k],
                            self.eigenvectors[k])
        return fam.follow(float(speed_m_s), prev, prev.roots).roots


def track(
    model: str,
    speeds_m_s: Sequence[float],
    wing: ElasticWingModel | None = None,
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    airframe: AirframeData | None = None,
) -> Sweep:
    """Eigenvalues of ``model`` at increasing ``speeds_m_s`` with labels tracked (the
    engine's :func:`~bioflex_jsb.flight_dynamics.flutter_engine.scan`), rigid set ``aero``.

    The grid should be fine enough that eigenvectors change little between neighbours
    (0.25 m/s is ample here; :func:`sweep_grid` makes one).
    """
    speeds = np.asarray(speeds_m_s, dtype=float)
    if speeds.ndim != 1 or len(speeds) == 0 or np.any(np.diff(speeds) <= 0):
        raise ValueError("speeds_m_s must be a non-empty, strictly increasing sequence")
    fam = paper_family(model, wing, density_kg_m3, aero, float(speeds[0]), airframe)
    tr = engine.scan(fam, speeds)
    return Sweep(model, speeds, tr.roots, tr.labels, tuple(p.vectors for p in tr.points),
                 wing, density_kg_m3, aero, airframe)


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
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    airframe: AirframeData | None = None,
) -> list[ModeSet]:
    """Labelled modes of ``model`` at each speed in ``speeds_m_s`` (labels tracked from 2 m/s);
    the aircraft is the wing's, or ``airframe`` for the rigid model (:func:`airframe_of`)."""
    targets = sorted(set(float(v) for v in speeds_m_s))
    grid = sweep_grid(targets)
    sweep = track(model, grid, wing, density_kg_m3, aero, airframe)
    index = {float(v): k for k, v in enumerate(grid)}
    by_speed = {v: sweep.at(index[v]) for v in targets}
    return [by_speed[float(v)] for v in speeds_m_s]


# The free aircraft's search: labels fixed at this speed [m/s] (below every range), the
# scan step [m/s] and the bisection tolerance [m/s]; the speed is reported to the
# tolerance's 0.01 m/s.
SCAN_START_M_S = 2.0
SCAN_STEP_M_S = 0.1
SCAN_TOL_M_S = 0.01


def find_flutter(
    wing: ElasticWingModel,
    range_m_s: tuple[float, float] = (5.0, 40.0),
    step_m_s: float = SCAN_STEP_M_S,
    tol_m_s: float = SCAN_TOL_M_S,
    density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
    aero: RigidAerodynamics | None = None,
    *,
    progress=None,
    full_scan: bool = False,
) -> FlutterResult:
    """The coupled model's first instability in ``range_m_s`` (the engine's search: scan
    from 2 m/s in ``step_m_s``, bisection to ``tol_m_s``, speed rounded to 0.01 m/s).

    The phugoid is left out of the search, as the paper leaves it out of Figs. 15-19
    (Section 3.2: the vortex model cannot give the drag the phugoid depends on): in the
    linear model it goes unstable below about 10 m/s, where the formal trim C_L exceeds 2,
    for the rigid aircraft as well. ``divergence_speed_m_s`` is the wing's with the body
    held (:func:`wing_divergence_speed_m_s`). ``progress``, ``full_scan``:
    :func:`~bioflex_jsb.flight_dynamics.flutter_engine.first_instability`'s.
    """
    from dataclasses import replace

    lo, hi = range_m_s
    if not (0.0 < lo < hi):
        raise InputError(f"flutter range must satisfy 0 < low < high, got {lo}:{hi}")
    fam = paper_family("coupled", wing, density_kg_m3, aero,
                       min(SCAN_START_M_S, lo))
    fam.divergence_speed_m_s = wing_divergence_speed_m_s(
        wing, density_kg_m3, (2.0, max(DIVERGENCE_SEARCH_TOP_M_S, DIVERGENCE_TOP_OVER_RANGE * hi)))
    res = engine.first_instability(
        fam, engine.default_grid((lo, hi), step_m_s, SCAN_START_M_S), (lo, hi),
        tol_m_s=tol_m_s, structural_damping=_common_zeta(wing),
        density_kg_m3=density_kg_m3, progress=progress, full_scan=full_scan)
    if res.speed_m_s is None:
        return res
    v = round(res.speed_m_s, 2)
    return replace(res, speed_m_s=v, reduced_frequency=res.frequency_rad_s * res.semichord_m / v)


# The wing's divergence (body held) is searched from 2 m/s to the larger of 60 m/s (the
# prototype's: 1.5 x its 40 m/s range) and 1.5 x the flutter range's top (a larger aircraft
# scanned over a wider range: its divergence beside a flutter found up there).
DIVERGENCE_SEARCH_TOP_M_S = 60.0
DIVERGENCE_TOP_OVER_RANGE = 1.5


def _common_zeta(wing: ElasticWingModel) -> float | None:
    z = np.asarray(wing.damping_ratios, dtype=float)
    return float(z[0]) if z.size and np.all(z == z[0]) else None


def wing_divergence_speed_m_s(wing: ElasticWingModel,
                              density_kg_m3: float = SEA_LEVEL_DENSITY_KG_M3,
                              range_m_s: tuple[float, float] = (2.0, 60.0)) -> float | None:
    """Speed [m/s] at which the wing's static stiffness in the aircraft, A_EE = −ω² + H_η
    of Eq. (4), first becomes singular (its divergence with the body held); None in range.
    The same for both aerodynamic models (the unsteady increments vanish in a steady state)."""
    from scipy.optimize import brentq

    def det(v):
        cond = level_flight_condition(v, density_kg_m3, airframe=wing.airframe)
        return float(np.linalg.det(coupled_blocks(wing, cond).a_ee))

    grid = np.arange(range_m_s[0], range_m_s[1] + 0.25, 0.5)
    signs = np.sign([det(v) for v in grid])
    flips = np.flatnonzero(signs[1:] != signs[:-1])
    if flips.size == 0:
        return None
    k = int(flips[0])
    return float(brentq(det, grid[k], grid[k + 1], xtol=1e-4))
