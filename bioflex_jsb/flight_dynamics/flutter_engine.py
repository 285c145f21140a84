"""The one analysis engine: mode tracking over airspeed, the first instability, one result.

Every flutter and mode analysis of the package (the clamped wing by p-k or state space, the
free aircraft on quasi-steady or unsteady strips, either rigid parameter set) is a
:class:`RootFamily`: a set of labelled branches whose roots λ [1/s] (complex; Re λ > 0 is
growth) depend on the airspeed V [m/s]. The engine

1. **tracks** the branches over an increasing speed grid (:func:`scan`): at each speed the
   family's candidate roots are shared out among the branches by one joint assignment
   (Hungarian algorithm, :func:`assign`) on the cost

       |λ − λ̂| / (1 + |λ̂|)  +  (1 − MAC(φ_prev, φ))   (the MAC term when vectors exist),

   λ̂ the branch's prediction (its root at the previous speed, or the linear extrapolation
   of the two previous ones where the family asks for it) and MAC the modal assurance
   criterion of the eigenvectors; labels are never taken from sort order;
2. finds the **first instability** in the range (:func:`first_instability`): the first grid
   speed ≥ the range's lower end at which a considered branch has Re λ >
   :data:`GROWTH_TOL_1_S`, then bisection on the largest considered Re λ between the last
   stable and first unstable grid speed (the roots continued from the last stable one) to
   ``tol_m_s``; the reported speed is the bracket's unstable end. A branch already unstable
   at the range's lower end is reported with ``present_at_lower_end=True`` and no speed
   ("unstable at and below" the lower end, ``unstable_at_and_below_m_s``), never as "no
   instability" and never with the lower end as its speed; a static divergence of the
   analysed system (``RootFamily.divergence_is_instability``) inside the range and below
   the first crossing is the first instability (mechanism ``static divergence``), and one
   below the range makes the system unstable at its lower end;
3. names the **mechanism** by one rule (:func:`mechanism`), written there;
4. returns one :class:`FlutterResult` for all of them.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

GROWTH_TOL_1_S = 1e-9  # a root is unstable when Re λ exceeds this [1/s]
# DEFINITION: a crossing root whose |Im λ| is below this fraction of the lowest natural
# frequency (and below IMAG_TOL_RAD_S in absolute terms, whichever is larger) is real: a
# static divergence.
STATIC_FREQUENCY_FRACTION = 1e-3
IMAG_TOL_RAD_S = 1e-6
# DEFINITION (the one coalescence rule): another considered branch has coalesced with the
# unstable one when, at the crossing, its frequency is within this fraction of the unstable
# branch's frequency ...
COALESCENCE_RELATIVE_GAP = 0.25
# ... and their separation has closed to below this fraction of the one at the scan's first
# speed (the wind-off one for a clamped wing): a neighbour that was always close is not a
# coalescence. Measured on the cases in tests (test_goland.py, test_free_aircraft.py): Goland
# p-k unsteady 0.07 of the 20 m/s gap (coalescence), quasi-steady torsion flutter at 64.5
# m/s: nearest branch 45 % away (single-mode).
COALESCENCE_CLOSING_RATIO = 0.5
MECHANISMS = ("coalescence", "single-mode", "body-freedom", "static divergence")
METHODS = ("pk", "state-space")
AERO_MODELS = ("quasi-steady", "unsteady")


def _mac(v_prev: np.ndarray, v_now: np.ndarray) -> np.ndarray:
    """Modal assurance criterion matrix between two sets of (column) eigenvectors."""
    num = np.abs(v_prev.conj().T @ v_now) ** 2
    den = np.outer(np.sum(np.abs(v_prev) ** 2, axis=0), np.sum(np.abs(v_now) ** 2, axis=0))
    return num / den


def assign(predicted: np.ndarray, candidates: np.ndarray, prev_vectors=None,
           vectors=None) -> np.ndarray:
    """Indices into ``candidates`` of each predicted branch (joint assignment, module doc)."""
    predicted = np.asarray(predicted, dtype=complex)
    cost = np.abs(predicted[:, None] - candidates[None, :]) / (1.0 + np.abs(predicted)[:, None])
    if prev_vectors is not None and vectors is not None:
        cost = cost + (1.0 - _mac(prev_vectors, vectors))
    rows, cols = linear_sum_assignment(cost)
    return cols[np.argsort(rows)]


@dataclass(frozen=True, eq=False)
class Point:
    """The tracked branches at one speed: ``roots[j]`` of ``labels[j]``; eigenvectors as
    columns (``None`` for a family without them, the p-k)."""

    speed_m_s: float
    roots: np.ndarray
    vectors: np.ndarray | None = None


@dataclass(frozen=True, eq=False)
class Track:
    """Tracked roots over a grid: ``roots[k, j]`` of branch ``labels[j]`` at
    ``speeds_m_s[k]``; ``points[k]`` keeps the vectors for continuation."""

    labels: tuple[str, ...]
    points: tuple[Point, ...]

    @property
    def speeds_m_s(self) -> np.ndarray:
        return np.array([p.speed_m_s for p in self.points])

    @property
    def roots(self) -> np.ndarray:
        return np.array([p.roots for p in self.points])


class RootFamily:
    """What the engine analyses (subclass and fill in).

    Attributes: ``labels`` (one per tracked root), ``considered`` (bool per root: counts
    for the flutter search; e.g. the phugoid and the lag roots do not), ``rigid_labels``
    (branches of the rigid body: their instability is body-freedom flutter),
    ``extrapolate`` (predict a branch linearly from its two previous roots),
    ``natural_frequencies_rad_s``, ``reference_semichord_m`` (for k = ωb/V),
    ``divergence_speed_m_s`` (``None`` if none is known), ``divergence_is_instability``
    (whether that divergence is one of this system: the clamped wing's; the free
    aircraft's "wing with the body held" is not), ``method``, ``aero``, ``name``,
    ``mode_labels`` (the names of the wing's modes in the order of
    ``natural_frequencies_rad_s``; empty: the considered branches' names).
    """

    labels: tuple[str, ...] = ()
    considered: np.ndarray
    rigid_labels: tuple[str, ...] = ()
    extrapolate: bool = False
    natural_frequencies_rad_s: tuple[float, ...] = ()
    reference_semichord_m: float = math.nan
    divergence_speed_m_s: float | None = None
    divergence_is_instability: bool = False
    method: str = "state-space"
    aero: str = "quasi-steady"
    name: str = ""
    mode_labels: tuple[str, ...] = ()

    def first(self, speed_m_s: float) -> Point:
        """The labelled roots at the first speed of a scan."""
        raise NotImplementedError

    def follow(self, speed_m_s: float, previous: Point, predicted: np.ndarray) -> Point:
        """The roots at ``speed_m_s`` continuing ``previous`` (``predicted`` per branch)."""
        raise NotImplementedError


class EigenFamily(RootFamily):
    """The eigenvalues of a state matrix A(V) (every root tracked, conjugates included).

    ``paired_labels`` (the rigid ``short_period`` and ``phugoid``) name modes that are each
    one second-order factor of a real matrix (one conjugate pair or two real roots) told
    apart by a rule, not by continuity: at every speed ``partition`` (the roots of those
    branches → a label per root, whole factors) names them, and the tracker only orders the
    roots within a name (:func:`share_paired`). Tracked root by root, a real root of the
    over-damped short period that met a real phugoid root made a pair carrying both names,
    and identities carried from the lowest speed, where the two time scales cross, named
    the phugoid "short_period" at cruise (the J3Cub)."""

    def __init__(self, matrix: Callable[[float], np.ndarray], reference: np.ndarray,
                 reference_labels: Sequence[str], *, rest_label: str = "lag",
                 excluded: Sequence[str] = (), paired_labels: Sequence[str] = (),
                 partition: Callable[[np.ndarray], Sequence[str]] | None = None,
                 **attrs) -> None:
        self.matrix = matrix
        self.reference = np.asarray(reference, dtype=complex)
        self.reference_labels = tuple(reference_labels)
        self.rest_label = rest_label
        self.excluded = tuple(excluded) + (rest_label,)
        self.paired_labels = tuple(paired_labels)
        self.partition = partition
        for k, v in attrs.items():
            setattr(self, k, v)

    def _shared(self, lam, order, predicted):
        if not self.paired_labels or self.partition is None:
            return order
        return share_paired(self.labels, self.paired_labels, self.partition, lam, order,
                            predicted)

    def first(self, speed_m_s: float) -> Point:
        lam, vec = np.linalg.eig(self.matrix(float(speed_m_s)))
        chosen = list(assign(self.reference, lam))
        rest = [i for i in range(lam.size) if i not in chosen]
        order = np.array(chosen + rest)
        self.labels = self.reference_labels + (self.rest_label,) * len(rest)
        self.considered = np.array([lab not in self.excluded for lab in self.labels])
        order = self._shared(lam, order, np.concatenate([self.reference, lam[rest]]))
        return Point(float(speed_m_s), lam[order], vec[:, order])

    def follow(self, speed_m_s: float, previous: Point, predicted: np.ndarray) -> Point:
        lam, vec = np.linalg.eig(self.matrix(float(speed_m_s)))
        order = assign(predicted, lam, previous.vectors, vec)
        order = self._shared(lam, order, predicted)
        return Point(float(speed_m_s), lam[order], vec[:, order])


# DEFINITION: two complex roots are a conjugate pair when |λ_1 − conj(λ_2)| is below this
# fraction of 1 + |λ_1| (a real matrix's pairs agree to rounding, ~1e-15 relative).
CONJUGATE_REL_TOL = 1e-8


def conjugates(a: complex, b: complex) -> bool:
    """Whether roots ``a`` and ``b`` are a conjugate pair (:data:`CONJUGATE_REL_TOL`)."""
    return abs(a - np.conj(b)) <= CONJUGATE_REL_TOL * (1.0 + abs(a))


def closed_under_conjugation(lam: np.ndarray) -> bool:
    """Whether every complex root of ``lam`` has its conjugate among the others (each used
    once); a real root (|Im λ| <= :data:`IMAG_TOL_RAD_S`) stands alone."""
    free = list(range(len(lam)))
    while free:
        i = free.pop(0)
        if abs(lam[i].imag) <= IMAG_TOL_RAD_S:
            continue
        partner = [k for k in free if conjugates(lam[i], lam[k])]
        if not partner:
            return False
        free.remove(partner[0])
    return True


def share_paired(labels: Sequence[str], paired: Sequence[str],
                 partition: Callable[[np.ndarray], Sequence[str]], lam: np.ndarray,
                 order: np.ndarray, predicted: np.ndarray) -> np.ndarray:
    """``order`` (root index per branch) with the roots on the ``paired`` labels' branches
    named by ``partition``: each label's branches take the roots it names, each root the
    branch it is nearest the prediction of (joint assignment). Unchanged where the tracker's
    names already are the partition's, and where the roots on those branches are not whole
    factors (a complex root whose conjugate the tracker gave another branch, as a lag's,
    near a coalescence of a rigid root with a wing or lag root): there the tracker's names
    stand."""
    pos = [j for j, lab in enumerate(labels) if lab in paired]
    roots_idx = [int(order[j]) for j in pos]
    if not closed_under_conjugation(lam[roots_idx]):
        return order
    named = list(partition(lam[roots_idx]))
    if named == [labels[j] for j in pos]:
        return order
    out = np.array(order)
    for lab in paired:
        branches = [j for j in pos if labels[j] == lab]
        mine = [r for r, nl in zip(roots_idx, named, strict=True) if nl == lab]
        if len(mine) != len(branches):
            raise ValueError(f"partition named {len(mine)} roots {lab!r}, which has "
                             f"{len(branches)} branches")
        cols = assign(predicted[branches], lam[mine])
        for b, c in zip(branches, cols, strict=True):
            out[b] = mine[c]
    return out


def _predict(points: Sequence[Point], speed_m_s: float, extrapolate: bool) -> np.ndarray:
    last = points[-1].roots
    if not extrapolate or len(points) < 2:
        return last
    h0 = points[-1].speed_m_s - points[-2].speed_m_s
    h1 = speed_m_s - points[-1].speed_m_s
    return last + (last - points[-2].roots) * (h1 / h0)


def _check_grid(speeds: np.ndarray) -> None:
    if speeds.ndim != 1 or speeds.size == 0 or np.any(np.diff(speeds) <= 0.0) \
            or speeds[0] <= 0.0:
        raise ValueError("speeds_m_s must be a non-empty, positive, strictly increasing "
                         "sequence")


def scan(family: RootFamily, speeds_m_s: Sequence[float], *,
         stop: Callable[[Point], bool] | None = None) -> Track:
    """Track ``family`` over increasing ``speeds_m_s`` (ends early where ``stop`` is true)."""
    speeds = np.asarray(speeds_m_s, dtype=float)
    _check_grid(speeds)
    points = [family.first(float(speeds[0]))]
    if stop is None or not stop(points[0]):
        for v in speeds[1:]:
            pred = _predict(points, float(v), family.extrapolate)
            points.append(family.follow(float(v), points[-1], pred))
            if stop is not None and stop(points[-1]):
                break
    return Track(tuple(family.labels), tuple(points))


def continued(family: RootFamily, track: Track, k: int, speed_m_s: float) -> Point:
    """The roots at ``speed_m_s`` (between grid points k and k+1) continued from point k,
    predicted by linear interpolation towards point k+1 when the family extrapolates."""
    p0 = track.points[k]
    pred = p0.roots
    if family.extrapolate and k + 1 < len(track.points):
        p1 = track.points[k + 1]
        frac = (speed_m_s - p0.speed_m_s) / (p1.speed_m_s - p0.speed_m_s)
        pred = p0.roots + frac * (p1.roots - p0.roots)
    return family.follow(float(speed_m_s), p0, pred)


def _is_static(omega: float, natural: Sequence[float]) -> bool:
    low = min(natural) if len(natural) else 0.0
    return abs(omega) <= max(IMAG_TOL_RAD_S, STATIC_FREQUENCY_FRACTION * low)


def mechanism(labels: Sequence[str], considered: np.ndarray, roots: np.ndarray, unstable: int,
              first_roots: np.ndarray | None, rigid_labels: Sequence[str],
              natural_rad_s: Sequence[float]) -> tuple[str, str | None]:
    """The one mechanism rule, in this order:

    1. ``static divergence``: the unstable root is real (|Im λ| below
       :data:`STATIC_FREQUENCY_FRACTION` of the lowest natural frequency, at least
       :data:`IMAG_TOL_RAD_S`);
    2. ``body-freedom``: the unstable branch is a rigid-body one (the short period: the
       rigid aircraft's is stable, so the wing drives it);
    3. ``coalescence`` (partner named): the nearest other considered branch in frequency
       (upper half plane) is within :data:`COALESCENCE_RELATIVE_GAP` of the unstable
       frequency and their separation has closed below :data:`COALESCENCE_CLOSING_RATIO` of
       the one at the scan's first speed (``first_roots``: an instability present at that
       speed has closed nothing and is single-mode);
    4. ``single-mode`` otherwise.
    """
    omega = abs(roots[unstable].imag)
    if _is_static(omega, natural_rad_s):
        return "static divergence", None
    if labels[unstable] in rigid_labels:
        return "body-freedom", None
    best, gap, partner = math.inf, None, None
    for i, lab in enumerate(labels):
        if not considered[i] or lab == labels[unstable] or roots[i].imag <= IMAG_TOL_RAD_S:
            continue
        g = abs(roots[i].imag - omega) / omega
        if g < best:
            best, partner = g, i
    if partner is None or best >= COALESCENCE_RELATIVE_GAP:
        return "single-mode", None
    if first_roots is not None:
        gap0 = abs(abs(first_roots[partner].imag) - abs(first_roots[unstable].imag))
        gap = abs(roots[partner].imag - omega)
        if gap0 > 0.0 and gap >= COALESCENCE_CLOSING_RATIO * gap0:
            return "single-mode", None
    return "coalescence", labels[partner]


# The caveat a quasi-steady single-mode result carries beside its number (the result's
# ``caveat``; the CLI prints it on the result's line and in --json).
QUASI_STEADY_CAVEAT = (
    "quasi-steady strips (C = 1) have no aerodynamic pitch damping: a single-mode torsion "
    "instability on them is the model's artefact, its speed set by the assumed structural "
    "damping; unsteady strips (aero 'unsteady', the default) give the physical result")


@dataclass(frozen=True)
class FlutterResult:
    """The first instability of a system over a speed range (any model, any method).

    Attributes:
        name: the wing or aircraft.
        speed_m_s: flutter (or divergence) speed [m/s]; ``None`` if nothing is unstable in
            the range, and ``None`` when ``present_at_lower_end`` (no onset was found: the
            range's lower end is ``unstable_at_and_below_m_s``, never a flutter speed).
        frequency_rad_s: |Im λ| of the unstable root there [rad/s] (0: divergence).
        reduced_frequency: k = ωb/V [-], b = ``semichord_m``.
        mode, partner_mode: the unstable branch and (coalescence only) its partner.
        mechanism: one of :data:`MECHANISMS` (:func:`mechanism`), ``None`` if stable.
        present_at_lower_end: the system is already unstable at the range's lower end: the
            crossing is below the range; frequency, mode and mechanism are the instability's
            there.
        unstable_at_and_below_m_s: the range's lower end [m/s] when
            ``present_at_lower_end`` ("unstable at and below"), else ``None``.
        divergence_speed_m_s: static divergence speed [m/s] (``None``: none found);
            ``divergence_is_instability`` says whether it is one of the analysed system
            (clamped wing) or of the wing with the body held (free aircraft).
        natural_frequencies_rad_s, mode_labels: the wing's wind-off natural frequencies
            [rad/s] and, in the same order, the names of their modes (one each: zip them).
        range_m_s: the speed range searched [m/s]; method (pk, state-space), aero
            (quasi-steady, unsteady), structural_damping ζ [-] (``None``: the wing's own),
            density_kg_m3 [kg/m³], semichord_m [m], settings (other inputs).
        speeds_m_s, branch_roots, branch_labels, branch_considered: the tracked scan
            (``branch_roots[k, j]`` [1/s] of branch ``branch_labels[j]`` at
            ``speeds_m_s[k]``; ``branch_considered[j]``: whether it counts for the search:
            not the phugoid, not a lag root); not in :meth:`as_dict`; drawn by :meth:`plot`.
    """

    name: str
    speed_m_s: float | None
    frequency_rad_s: float | None
    reduced_frequency: float | None
    mode: str | None
    partner_mode: str | None
    mechanism: str | None
    present_at_lower_end: bool
    divergence_speed_m_s: float | None
    divergence_is_instability: bool
    natural_frequencies_rad_s: tuple[float, ...]
    mode_labels: tuple[str, ...]
    range_m_s: tuple[float, float]
    method: str
    aero: str
    structural_damping: float | None
    density_kg_m3: float
    semichord_m: float
    settings: dict = field(default_factory=dict)
    speeds_m_s: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False,
                                   compare=False)
    branch_roots: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False,
                                     compare=False)
    branch_labels: tuple[str, ...] = field(default=(), repr=False, compare=False)
    branch_considered: tuple[bool, ...] = field(default=(), repr=False, compare=False)

    @property
    def flutter_speed_m_s(self) -> float | None:
        """Alias of :attr:`speed_m_s` (the name the CLI's JSON and the sweeps use)."""
        return self.speed_m_s

    @property
    def unstable_at_and_below_m_s(self) -> float | None:
        """The range's lower end [m/s] when the system is unstable there, else ``None``."""
        return float(self.range_m_s[0]) if self.present_at_lower_end else None

    @property
    def kind(self) -> str | None:
        """``flutter`` (oscillatory), ``divergence`` (real root) or ``None``."""
        if self.mechanism is None:
            return None
        return "divergence" if self.mechanism == "static divergence" else "flutter"

    @property
    def quasi_steady_artefact(self) -> bool:
        """Whether the result is the quasi-steady strips' single-mode torsion instability
        (:data:`QUASI_STEADY_CAVEAT`): quasi-steady aerodynamics and a single-mode
        mechanism. A quasi-steady coalescence or divergence is not flagged (their pitch
        damping does not make them)."""
        return self.aero == "quasi-steady" and self.mechanism == "single-mode"

    @property
    def caveat(self) -> str | None:
        """What the number does not mean (:data:`QUASI_STEADY_CAVEAT`), or ``None``."""
        return QUASI_STEADY_CAVEAT if self.quasi_steady_artefact else None

    @property
    def wing(self) -> str:
        return self.name

    @property
    def wing_divergence_speed_m_s(self) -> float | None:
        """The divergence speed of the wing with the body held (free aircraft)."""
        return None if self.divergence_is_instability else self.divergence_speed_m_s

    def as_dict(self) -> dict:
        return {
            "name": self.name, "wing": self.name,
            "speed_m_s": self.speed_m_s, "flutter_speed_m_s": self.speed_m_s,
            "unstable_at_and_below_m_s": self.unstable_at_and_below_m_s,
            "frequency_rad_s": self.frequency_rad_s,
            "reduced_frequency": self.reduced_frequency, "mode": self.mode,
            "partner_mode": self.partner_mode, "mechanism": self.mechanism,
            "kind": self.kind, "present_at_lower_end": self.present_at_lower_end,
            "quasi_steady_artefact": self.quasi_steady_artefact, "caveat": self.caveat,
            "divergence_speed_m_s": self.divergence_speed_m_s,
            "divergence_is_instability": self.divergence_is_instability,
            "natural_frequencies_rad_s": list(self.natural_frequencies_rad_s),
            "mode_labels": list(self.mode_labels), "range_m_s": list(self.range_m_s),
            "method": self.method, "aero": self.aero,
            "structural_damping": self.structural_damping,
            "density_kg_m3": self.density_kg_m3, "semichord_m": self.semichord_m,
            **self.settings,
        }

    def plot(self, path, force: bool = False):
        """The V-g / V-f diagram: damping ratio and frequency of every considered branch
        against airspeed, the first instability marked (a matplotlib Figure; written to
        ``path``: a figure suffix, an existing file only if it is a plot of ours or with
        ``force``). The lines end where the search's scan ended: at the first instability,
        or at the range's top for a result of a full scan (``full_scan=True``, as the
        CLI's ``flutter --plot`` asks)."""
        from bioflex_jsb.flight_dynamics.flutter_plot import plot_flutter
        from bioflex_jsb.plot_files import check_plot_target

        return plot_flutter(self, check_plot_target(path, force))


def first_instability(
    family: RootFamily, grid_m_s: Sequence[float], range_m_s: tuple[float, float], *,
    tol_m_s: float, structural_damping: float | None, density_kg_m3: float,
    settings: dict | None = None, progress: Callable[[float, float], None] | None = None,
    full_scan: bool = False,
) -> FlutterResult:
    """The first instability of ``family`` in ``range_m_s`` (module docstring, step 2).

    ``grid_m_s`` is the tracking grid; it may start below the range (labels are then fixed
    at a lower speed, as the free aircraft's are at 2 m/s); only speeds ≥ the range's lower
    end count. ``progress`` is called with each grid speed [m/s] as it is scanned and the
    grid's top [m/s] (a progress bar's). ``full_scan``: scan the whole grid, not only up
    to the first instability (the result's scan then covers the range: its
    :meth:`FlutterResult.plot`).
    """
    lo, hi = (float(x) for x in range_m_s)
    grid = np.asarray(grid_m_s, dtype=float)
    in_range_from = lo - 1e-12
    considered_mask: list[np.ndarray] = []

    def growth(p: Point) -> float:
        return float(p.roots[considered_mask[0]].real.max())

    def unstable(p: Point) -> bool:
        if not considered_mask:
            considered_mask.append(np.asarray(family.considered, dtype=bool))
        return p.speed_m_s >= in_range_from and growth(p) > GROWTH_TOL_1_S

    def stop(p: Point) -> bool:
        if progress is not None:
            progress(p.speed_m_s, float(grid[-1]))
        return unstable(p) and not full_scan

    full = scan(family, grid, stop=stop)
    labels, considered = full.labels, considered_mask[0]
    first_bad = next((k for k, p in enumerate(full.points) if unstable(p)), None)
    pts = full.points if first_bad is None else full.points[:first_bad + 1]
    track = Track(labels, tuple(pts))
    v_div = family.divergence_speed_m_s
    structural = tuple(getattr(family, "mode_labels", ()) or ())
    if not structural:  # the considered branches, one name each
        structural = tuple(dict.fromkeys(lab for lab, c in zip(labels, considered,
                                                                 strict=True) if c))
    base = dict(
        name=family.name, divergence_speed_m_s=v_div,
        divergence_is_instability=family.divergence_is_instability,
        natural_frequencies_rad_s=tuple(float(w) for w in family.natural_frequencies_rad_s),
        mode_labels=structural,
        range_m_s=(lo, hi), method=family.method, aero=family.aero,
        structural_damping=structural_damping, density_kg_m3=float(density_kg_m3),
        semichord_m=float(family.reference_semichord_m), settings=dict(settings or {}),
        speeds_m_s=full.speeds_m_s, branch_roots=full.roots, branch_labels=tuple(labels),
        branch_considered=tuple(bool(c) for c in considered),
    )
    first_roots = pts[0].roots
    last = pts[-1]
    div_counts = family.divergence_is_instability and v_div is not None
    if first_bad is not None:
        k = len(pts) - 1
        at_lower = k == 0 or pts[k - 1].speed_m_s < in_range_from
        if at_lower:
            v_cross, at = last.speed_m_s, last
        else:
            a, b = pts[k - 1].speed_m_s, last.speed_m_s
            while b - a > tol_m_s:
                mid = 0.5 * (a + b)
                if growth(continued(family, track, k - 1, mid)) > GROWTH_TOL_1_S:
                    b = mid
                else:
                    a = mid
            v_cross, at = b, continued(family, track, k - 1, b)
        if div_counts and v_div < v_cross - tol_m_s:
            return _divergence_result(base, v_div, lo)
        j = int(np.argmax(np.where(considered, at.roots.real, -np.inf)))
        mech, partner = mechanism(labels, considered, at.roots, j,
                                  first_roots, family.rigid_labels,
                                  family.natural_frequencies_rad_s)
        omega = abs(at.roots[j].imag)
        if mech == "static divergence":
            omega = 0.0
        return FlutterResult(
            speed_m_s=None if at_lower else float(v_cross), frequency_rad_s=float(omega),
            reduced_frequency=float(omega * family.reference_semichord_m / v_cross),
            mode=labels[j], partner_mode=partner, mechanism=mech,
            present_at_lower_end=bool(at_lower), **base)
    if div_counts and v_div <= hi:
        return _divergence_result(base, v_div, lo)
    return FlutterResult(speed_m_s=None, frequency_rad_s=None, reduced_frequency=None,
                         mode=None, partner_mode=None, mechanism=None,
                         present_at_lower_end=False, **base)


def _divergence_result(base: dict, v_div: float, lo: float) -> FlutterResult:
    """The static divergence of the analysed system as its first instability (unstable at
    and below the lower end if it lies below the range: no speed)."""
    below = v_div < lo
    return FlutterResult(speed_m_s=None if below else float(v_div), frequency_rad_s=0.0,
                         reduced_frequency=0.0, mode="divergence", partner_mode=None,
                         mechanism="static divergence", present_at_lower_end=bool(below),
                         **base)


def default_grid(range_m_s: tuple[float, float], step_m_s: float,
                 start_m_s: float | None = None) -> np.ndarray:
    """The scan grid from ``start_m_s`` (default the range's lower end) to its upper end in
    ``step_m_s``."""
    lo, hi = range_m_s
    start = lo if start_m_s is None else min(start_m_s, lo)
    grid = np.arange(start, hi + 0.5 * step_m_s, step_m_s)
    return grid[grid <= hi + 1e-12]
