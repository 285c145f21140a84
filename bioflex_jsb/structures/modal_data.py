"""Modal data of the elastic half wing: the one interface the rest of bioflex-jsb consumes.

A :class:`ModalData` holds n structural modes of the **starboard half wing, root chord
clamped** (Section 3.1, Table 2), sampled at k spanwise stations y = 0 … b/2.

Sign conventions (Section 3.1, after Table 2; ``docs/conventions.md``):

* ``bending_m[i, k]`` = φ_i^b(y_k): vertical displacement of the elastic axis per unit
  modal coordinate η_i, **positive downward** [m/rad];
* ``twist_rad[i, k]`` = dφ_i^b/dx(y_k): section twist per unit η_i, **positive leading edge
  up** [rad/rad].

Normalisation (Table 2 gives generalised masses in kg·m², so η_i is an angle):

* each mode is scaled so that the largest |twist| over the stations is exactly 1 rad/rad,
  and the sign is chosen so that the tip twist is positive (if the tip twist is negligible,
  the sign of the largest |twist| is used); η_i is then the largest section twist in rad;
* a mode with no twist at all (pure bending, which happens when the inertial and elastic axes
  coincide) cannot be scaled on its twist; it is scaled so that its largest |bending| equals
  the outermost station's y (for a cantilever: the tip deflects by η_i·b/2, η_i is the angle
  of the line from the root to the deflected tip), with the tip displacement positive (down),
  so η_i is still an angle;
* ``generalised_masses_kg_m2[i]`` = m_i = ∫ (m' φ² + 2 S_α φ θ + I_α θ²) dy over the HALF
  wing (one side, root clamped, as Table 2), for the shapes as scaled here [kg·m²].

:meth:`ModalData.normalised` applies this scaling to modes given in any other normalisation
(and scales the generalised masses by the square of the inverse scale factor), so modes from a
user's finite-element model can be brought into the convention without changing physics.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from bioflex_jsb.errors import InputError

# A mode counts as twist-free when max|twist| · (b/2) is below this fraction of max|bending|
# ESTIMATE: FE round-off of an exactly uncoupled bending eigenvector is ~1e-15 relative; any
# real bending–torsion coupling (|x_I − x_E| ≥ 1e-6 chord) gives ratios far above 1e-9.
TWIST_FREE_RELATIVE_TOLERANCE = 1e-9

# A tip twist smaller than this fraction of the largest |twist| does not decide the sign.
# ESTIMATE: chosen well above round-off and well below any physical tip twist of a clamped-free
# torsion mode (whose tip is an antinode).
TIP_SIGN_RELATIVE_TOLERANCE = 1e-6


class ModalDataError(InputError):
    """Invalid modal data; the message names the offending field."""


def _as_float_array(name: str, value, ndim: int) -> np.ndarray:
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError) as exc:
        raise ModalDataError(f"ModalData.{name}: not numeric ({exc})") from None
    if arr.ndim != ndim:
        raise ModalDataError(
            f"ModalData.{name}: expected a {ndim}-D array, got shape {arr.shape}"
        )
    if not np.all(np.isfinite(arr)):
        bad = np.argwhere(~np.isfinite(arr))[0]
        raise ModalDataError(
            f"ModalData.{name}: non-finite value {arr[tuple(bad)]} at index {tuple(bad.tolist())}"
        )
    arr.setflags(write=False)
    return arr


@dataclass(frozen=True, eq=False)
class ModalData:
    """n structural modes of the clamped half wing sampled at k spanwise stations.

    Attributes:
        frequencies_rad_s: (n,) natural frequencies ω_i [rad/s], positive, non-decreasing.
        damping_ratios: (n,) structural damping ratios ζ_i [-] (the modal equation uses
            2 ζ_i ω_i), ≥ 0.
        generalised_masses_kg_m2: (n,) generalised masses m_i of the HALF wing [kg·m²], > 0.
        stations_m: (k,) spanwise stations y of the starboard half, 0 ≤ y ≤ b/2, strictly
            increasing [m].
        bending_m: (n, k) φ_i^b(y): elastic-axis displacement per unit η_i, positive DOWN
            [m/rad].
        twist_rad: (n, k) dφ_i^b/dx(y): section twist per unit η_i, positive LEADING EDGE UP
            [rad/rad].
        x_elastic_frac: (k,) elastic-axis position, fraction of the local chord aft of the
            leading edge [-] (Eq. 12). A scalar is broadcast to all stations.
        x_inertial_frac: (k,) inertial-axis position, fraction of chord aft of the leading
            edge [-] (Eq. 11). A scalar is broadcast.
        source: where the modes come from (model and parameter set, or file name).
        notes: free text (normalisation remarks, calibration, …).

    See the module docstring for the normalisation (max |twist| = 1, tip twist positive).
    """

    frequencies_rad_s: np.ndarray
    damping_ratios: np.ndarray
    generalised_masses_kg_m2: np.ndarray
    stations_m: np.ndarray
    bending_m: np.ndarray
    twist_rad: np.ndarray
    x_elastic_frac: np.ndarray
    x_inertial_frac: np.ndarray
    source: str
    notes: str = field(default="")

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        for name in ("frequencies_rad_s", "damping_ratios", "generalised_masses_kg_m2",
                     "stations_m"):
            set_(self, name, _as_float_array(name, getattr(self, name), 1))
        n = self.frequencies_rad_s.shape[0]
        k = self.stations_m.shape[0]
        if n < 1:
            raise ModalDataError("ModalData.frequencies_rad_s: at least one mode is needed")
        for name in ("damping_ratios", "generalised_masses_kg_m2"):
            if getattr(self, name).shape != (n,):
                raise ModalDataError(
                    f"ModalData.{name}: length {getattr(self, name).shape[0]} does not match "
                    f"the {n} modes of frequencies_rad_s"
                )
        if k < 2:
            raise ModalDataError("ModalData.stations_m: at least two stations are needed")
        if np.any(np.diff(self.stations_m) <= 0.0):
            i = int(np.argmax(np.diff(self.stations_m) <= 0.0))
            raise ModalDataError(
                f"ModalData.stations_m: not strictly increasing at index {i + 1} "
                f"({self.stations_m[i]} then {self.stations_m[i + 1]} m)"
            )
        if self.stations_m[0] < 0.0:
            raise ModalDataError(
                f"ModalData.stations_m: stations are on the starboard half, y ≥ 0 "
                f"(first is {self.stations_m[0]} m)"
            )
        for name in ("bending_m", "twist_rad"):
            arr = _as_float_array(name, getattr(self, name), 2)
            if arr.shape != (n, k):
                raise ModalDataError(
                    f"ModalData.{name}: shape {arr.shape} does not match "
                    f"(n_modes, n_stations) = ({n}, {k})"
                )
            set_(self, name, arr)
        for name in ("x_elastic_frac", "x_inertial_frac"):
            raw = np.array(getattr(self, name), dtype=float)
            if raw.ndim == 0:
                raw = np.full(k, float(raw))
            arr = _as_float_array(name, raw, 1)
            if arr.shape != (k,):
                raise ModalDataError(
                    f"ModalData.{name}: length {arr.shape[0]} does not match the {k} stations"
                )
            if np.any((arr < 0.0) | (arr > 1.0)):
                raise ModalDataError(
                    f"ModalData.{name}: chord fractions must lie in [0, 1], got "
                    f"{arr.min():g}..{arr.max():g}"
                )
            set_(self, name, arr)
        if np.any(self.frequencies_rad_s <= 0.0):
            raise ModalDataError("ModalData.frequencies_rad_s: frequencies must be positive")
        if np.any(np.diff(self.frequencies_rad_s) < 0.0):
            raise ModalDataError(
                "ModalData.frequencies_rad_s: modes must be ordered by increasing frequency"
            )
        if np.any(self.damping_ratios < 0.0):
            raise ModalDataError("ModalData.damping_ratios: damping ratios must be ≥ 0")
        if np.any(self.generalised_masses_kg_m2 <= 0.0):
            raise ModalDataError(
                "ModalData.generalised_masses_kg_m2: generalised masses must be positive"
            )
        if not isinstance(self.source, str):
            raise ModalDataError("ModalData.source: must be a string")
        if not isinstance(self.notes, str):
            raise ModalDataError("ModalData.notes: must be a string")

    # ------------------------------------------------------------------------------------
    @property
    def n_modes(self) -> int:
        """Number of modes n."""
        return int(self.frequencies_rad_s.shape[0])

    @property
    def n_stations(self) -> int:
        """Number of spanwise stations k."""
        return int(self.stations_m.shape[0])

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies [Hz]."""
        return self.frequencies_rad_s / (2.0 * np.pi)

    def truncated(self, n: int) -> ModalData:
        """The first ``n`` modes (lowest frequencies), 1 ≤ n ≤ n_modes."""
        if not 1 <= n <= self.n_modes:
            raise ModalDataError(
                f"ModalData.truncated: n = {n} outside 1..{self.n_modes} (n_modes)"
            )
        return replace(
            self,
            frequencies_rad_s=self.frequencies_rad_s[:n],
            damping_ratios=self.damping_ratios[:n],
            generalised_masses_kg_m2=self.generalised_masses_kg_m2[:n],
            bending_m=self.bending_m[:n],
            twist_rad=self.twist_rad[:n],
        )

    def twist_free(self) -> np.ndarray:
        """(n,) bool: modes without twist (pure bending), scaled on their bending instead."""
        span = max(float(self.stations_m[-1]), float(self.stations_m[-1] - self.stations_m[0]))
        max_twist = np.max(np.abs(self.twist_rad), axis=1)
        max_bend = np.max(np.abs(self.bending_m), axis=1)
        return max_twist * span <= TWIST_FREE_RELATIVE_TOLERANCE * max_bend

    def normalisation_factors(self) -> np.ndarray:
        """(n,) signed factors a_i such that shape_i / a_i is in the project normalisation."""
        factors = np.empty(self.n_modes)
        free = self.twist_free()
        for i in range(self.n_modes):
            if free[i]:
                j = int(np.argmax(np.abs(self.bending_m[i])))
                scale = abs(self.bending_m[i, j]) / float(self.stations_m[-1])
                tip, ref = self.bending_m[i, -1], self.bending_m[i, j]
            else:
                j = int(np.argmax(np.abs(self.twist_rad[i])))
                scale = abs(self.twist_rad[i, j])
                tip, ref = self.twist_rad[i, -1], self.twist_rad[i, j]
            if scale == 0.0:
                raise ModalDataError(f"ModalData.bending_m/twist_rad: mode {i + 1} is all zero")
            if abs(tip) > TIP_SIGN_RELATIVE_TOLERANCE * abs(ref):
                sign = np.sign(tip)
            else:
                sign = np.sign(ref)
            factors[i] = sign * scale
        return factors

    def normalised(self) -> ModalData:
        """A copy scaled to max |twist| = 1 with positive tip twist (see module docstring).

        Shapes are divided by a_i and generalised masses by a_i², so η_i' = a_i η_i and the
        physics (deflection for a given energy) is unchanged.
        """
        a = self.normalisation_factors()
        # a² overflows for a shape given as 1e308: m_i is then 0, refused as not positive
        with np.errstate(over="ignore"):
            masses = self.generalised_masses_kg_m2 / a**2
        return replace(
            self,
            bending_m=self.bending_m / a[:, None],
            twist_rad=self.twist_rad / a[:, None],
            generalised_masses_kg_m2=masses,
        )

    def is_normalised(self, rtol: float = 1e-9) -> bool:
        """True when every mode already follows the normalisation (factor 1 within ``rtol``)."""
        return bool(np.all(np.abs(self.normalisation_factors() - 1.0) <= rtol))
