"""Flutter results shared by the p-k and state-space solutions, and the Goland benchmark.

Mechanism (:func:`classify_mechanism`):

* ``"static divergence"``: the root that crosses into the right half plane is real (zero
  frequency);
* ``"coalescence"``: the unstable branch's frequency has closed on another branch's: at the
  flutter speed their separation is below ``COALESCENCE_GAP_RATIO`` of the wind-off one;
* ``"single-mode"``: otherwise (one mode loses its damping without approaching another).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np
from scipy.linalg import eig

from bioflex_jsb.aeroelasticity.clamped_wing import ClampedWingModel
from bioflex_jsb.aeroelasticity.strip_aero import modal_strip_matrices

MECHANISMS = ("coalescence", "single-mode", "static divergence")

# DEFINITION: a branch pair whose frequency separation at the flutter speed is below half of
# the wind-off separation has "coalesced" (the classical bending-torsion flutter of the
# Goland wing closes the 49→97 rad/s gap to a few rad/s); a single-mode flutter keeps its
# neighbours at about their wind-off distance.
COALESCENCE_GAP_RATIO = 0.5
# DEFINITION: a crossing root whose frequency is below this fraction of the lowest natural
# frequency is a real (static) root.
STATIC_FREQUENCY_FRACTION = 1e-3


@dataclass(frozen=True)
class FlutterResult:
    """The first instability of a wing over a speed range.

    Attributes:
        speed_m_s: flutter (or divergence) speed [m/s]; ``None`` if nothing crosses.
        frequency_rad_s: frequency of the crossing root [rad/s] (0 for divergence).
        reduced_frequency: k = ωb/V at the crossing [-] (reference semichord).
        mode: the unstable branch, by its wind-off mode ("torsion 1", ...).
        partner_mode: the branch it coalesced with (``None`` unless coalescence).
        mechanism: one of :data:`MECHANISMS` (``None`` if nothing crosses).
        natural_frequencies_rad_s: wind-off natural frequencies [rad/s].
        mode_labels: names of the wind-off modes.
        divergence_speed_m_s: static divergence speed [m/s] (``math.inf`` if none).
        method, aero, lift_slope: how it was computed; structural_damping: modal viscous
            damping ratio ζ [-] given to every mode.
        speeds_m_s, branch_roots: the tracked sweep: (n_speeds,), (n_speeds, n_modes) complex
            eigenvalues p [1/s] of each branch (not in :meth:`as_dict`).
    """

    speed_m_s: float | None
    frequency_rad_s: float | None
    reduced_frequency: float | None
    mode: str | None
    partner_mode: str | None
    mechanism: str | None
    natural_frequencies_rad_s: tuple[float, ...]
    mode_labels: tuple[str, ...]
    divergence_speed_m_s: float
    method: str
    aero: str
    lift_slope: str
    structural_damping: float
    speeds_m_s: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    branch_roots: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)), repr=False)

    def as_dict(self) -> dict:
        d = asdict(self)
        d.pop("speeds_m_s")
        d.pop("branch_roots")
        if not math.isfinite(d["divergence_speed_m_s"]):
            d["divergence_speed_m_s"] = None
        return d


def divergence_speed_m_s(model: ClampedWingModel, density_kg_m3: float) -> float:
    """Static divergence speed [m/s] of the strip model (steady aerodynamics, C = 1).

    Steady generalised forces D W η are ∝ V² (D ∝ V, W ∝ V): divergence where
    K − V² G loses positive definiteness, G = D W at 1 m/s. ``math.inf`` if never.
    """
    mats = modal_strip_matrices(model, speed_m_s=1.0, density_kg_m3=density_kg_m3)
    g = mats.force @ mats.upwash_displacement
    lam = eig(g, model.stiffness, right=False)  # G x = μ K x → V² = 1/μ
    mu = lam[(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) & (lam.real > 0.0)].real
    return math.inf if mu.size == 0 else float(1.0 / math.sqrt(mu.max()))


def classify_mechanism(
    branch_frequencies_rad_s: np.ndarray, wind_off_rad_s: np.ndarray, unstable: int,
    crossing_frequency_rad_s: float,
) -> tuple[str, int | None]:
    """Mechanism and coalescence partner (branch index) of a crossing (module docstring).

    ``branch_frequencies_rad_s`` (n,) are the branches' frequencies at the crossing speed.
    """
    if abs(crossing_frequency_rad_s) < STATIC_FREQUENCY_FRACTION * float(np.min(wind_off_rad_s)):
        return "static divergence", None
    others = [j for j in range(len(wind_off_rad_s)) if j != unstable]
    if not others:
        return "single-mode", None
    gap_now = np.array([abs(branch_frequencies_rad_s[unstable] - branch_frequencies_rad_s[j])
                        for j in others])
    gap_off = np.array([abs(wind_off_rad_s[unstable] - wind_off_rad_s[j]) for j in others])
    ratio = gap_now / gap_off
    j = int(np.argmin(ratio))
    if ratio[j] < COALESCENCE_GAP_RATIO:
        return "coalescence", others[j]
    return "single-mode", None


def goland_flutter(
    aero: str = "unsteady",
    lift_slope: str = "strip",
    method: str = "pk",
    structural_damping: float = 0.0,
    *,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    n_modes: int | None = None,
    inertia_about: str | None = None,
    density_kg_m3: float | None = None,
) -> FlutterResult:
    """Flutter of the clamped Goland wing (:mod:`bioflex_jsb.parameters.goland`).

    ``aero``: ``"unsteady"`` (Theodorsen's C(k) in p-k; Jones's finite-state form in the
    state-space method) or ``"quasi-steady"`` (C = 1). ``lift_slope``: ``"strip"`` (2π on
    every strip) or ``"vlm"`` (the vortex lattice's spanwise lift slope). ``method``:
    ``"pk"`` or ``"state-space"``. ``structural_damping``: viscous modal damping ratio ζ [-]
    on every mode. ``inertia_about`` (default ``goland.DEFAULT_INERTIA_AXIS``): see
    :func:`~bioflex_jsb.aeroelasticity.clamped_wing.goland_sections`. ``density_kg_m3``
    defaults to ``goland.FLUTTER_DENSITY_KG_M3`` (sea level, the density at which the
    published flutter point is reproduced; the issue's 1.02 kg/m³ is
    ``goland.AIR_DENSITY_KG_M3``).
    """
    from bioflex_jsb.aeroelasticity import pk, state_space
    from bioflex_jsb.aeroelasticity.clamped_wing import (
        DEFAULT_N_MODES,
        clamped_wing_model,
        goland_sections,
    )
    from bioflex_jsb.parameters import goland as G

    axis = G.DEFAULT_INERTIA_AXIS if inertia_about is None else inertia_about
    rho = G.FLUTTER_DENSITY_KG_M3 if density_kg_m3 is None else float(density_kg_m3)
    model = clamped_wing_model(goland_sections(inertia_about=axis),
                               lift_slope=lift_slope, n_modes=n_modes or DEFAULT_N_MODES)
    kwargs = dict(density_kg_m3=rho, aero=aero,
                  structural_damping=structural_damping, speed_range_m_s=speed_range_m_s)
    if method == "pk":
        return pk.pk_flutter(model, **kwargs)
    if method == "state-space":
        return state_space.state_space_flutter(model, **kwargs)
    raise ValueError(f"method must be 'pk' or 'state-space', not {method!r}")
