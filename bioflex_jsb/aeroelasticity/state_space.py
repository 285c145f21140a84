"""Flutter by eigen-analysis of the modal structure with finite-state strip aerodynamics.

State vector z = (η [kg^½·m], η̇ [kg^½·m/s], x [m]): the M-orthonormal modal coordinates of
:mod:`bioflex_jsb.aeroelasticity.clamped_wing` (their heave shapes are in m per unit η, so η
carries kg^½·m), their rates, and the aerodynamic lag states of every strip
(:func:`bioflex_jsb.aeroelasticity.strip_aero.finite_state_model`: Jones's Wagner states,
optionally Küssner's gust states). With the modal mass I, stiffness K = diag(ω²) and viscous
damping C_s = diag(2ζω):

    (I + M_a) η̈ = −(K − D_q) η − (C_s − D_qd) η̇ + C x + D_g w_g
    ẋ = A x + B_q η + B_qd η̇ + B_g w_g

The eigenvalues are tracked over speed by the one engine
(:mod:`bioflex_jsb.flight_dynamics.flutter_engine`, :class:`StateSpaceFamily`): each
structural mode's pair starts at its wind-off roots ±iω_i√(1 − ζ²) − ζω_i, the lag roots
are labelled ``lag`` (real and stable; they do not count for flutter), and every root is
continued by eigenvector correlation and eigenvalue continuity (linear extrapolation over
the two previous speeds); the engine finds the first crossing and names the mechanism.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aeroelasticity.clamped_wing import (
    ClampedWingModel,
    structural_damping_matrix,
)
from bioflex_jsb.aeroelasticity.pk import clamped_search, finite_or_none
from bioflex_jsb.aeroelasticity.strip_aero import (
    check_aero,
    divergence_speed_m_s,
    finite_state_model,
)
from bioflex_jsb.flight_dynamics import flutter_engine as engine
from bioflex_jsb.state_space import StateSpace

# Speed step of the tracking sweep [m/s]. ESTIMATE: as for the p-k sweep (2 m/s: no branch
# swaps on the Goland wing).
DEFAULT_SPEED_STEP_M_S = 2.0


@dataclass(frozen=True, eq=False)
class AeroelasticSystem:
    """ż = A z + B_g w_g of the wing at one speed; ``state_names`` / ``state_units``;
    ``b_gust`` [per m/s] is zero unless built with ``gust=True``."""

    a: np.ndarray
    b_gust: np.ndarray
    state_names: tuple[str, ...]
    state_units: tuple[str, ...]
    n_modes: int
    speed_m_s: float
    gust: bool = False

    def to_state_space(self) -> StateSpace:
        """This system as the package's :class:`~bioflex_jsb.state_space.StateSpace`: the
        input w_g [m/s] (positive up, met by every strip's leading edge at once), the outputs
        the states themselves (C = I, D = 0; names and units those of the states)."""
        n = self.a.shape[0]
        return StateSpace(model="clamped-aeroelastic", speed_m_s=self.speed_m_s, a=self.a,
                          b=np.reshape(self.b_gust, (n, 1)), c=np.eye(n), d=np.zeros((n, 1)),
                          states=self.state_names, state_units=self.state_units,
                          inputs=("w_g",), input_units=("m/s",), outputs=self.state_names,
                          output_units=self.state_units,
                          notes={"n_modes": self.n_modes, "gust": self.gust})


def aeroelastic_system(
    model: ClampedWingModel, *, speed_m_s: float, density_kg_m3: float,
    aero: str = "unsteady", structural_damping: float = 0.0, gust: bool = False,
) -> AeroelasticSystem:
    """The first-order aeroelastic system of the module docstring at ``speed_m_s``."""
    check_aero(aero)
    fs = finite_state_model(model, speed_m_s=speed_m_s, density_kg_m3=density_kg_m3,
                            aero=aero, gust=gust)
    n, nx = model.n_modes, fs.n_states
    m_t = model.mass + fs.apparent_mass
    c_s = structural_damping_matrix(model, structural_damping)
    a = np.zeros((2 * n + nx, 2 * n + nx))
    a[:n, n:2 * n] = np.eye(n)
    a[n:2 * n, :n] = np.linalg.solve(m_t, fs.d_q - model.stiffness)
    a[n:2 * n, n:2 * n] = np.linalg.solve(m_t, fs.d_qd - c_s)
    b_g = np.zeros(2 * n + nx)
    b_g[n:2 * n] = np.linalg.solve(m_t, fs.d_g)
    if nx:
        a[n:2 * n, 2 * n:] = np.linalg.solve(m_t, fs.c)
        a[2 * n:, :n] = fs.b_q
        a[2 * n:, n:2 * n] = fs.b_qd
        a[2 * n:, 2 * n:] = fs.a
        b_g[2 * n:] = fs.b_g
    names = tuple(f"eta_{i + 1}" for i in range(n)) + tuple(
        f"eta_dot_{i + 1}" for i in range(n)) + fs.state_names
    units = ("kg^0.5 m",) * n + ("kg^0.5 m/s",) * n + fs.state_units
    return AeroelasticSystem(a, b_g, names, units, n, float(speed_m_s), bool(gust))


def state_space_family(model: ClampedWingModel, *, density_kg_m3: float,
                       aero: str = "unsteady", structural_damping: float = 0.0,
                       name: str = "") -> engine.EigenFamily:
    """The clamped wing's aeroelastic system as the engine's :class:`EigenFamily`."""
    check_aero(aero)
    zeta = float(structural_damping)
    w0 = model.natural_frequencies_rad_s
    upper = 1j * w0 * np.sqrt(max(1.0 - zeta * zeta, 0.0)) - zeta * w0
    labels = model.mode_labels()

    def matrix(v: float) -> np.ndarray:
        return aeroelastic_system(model, speed_m_s=v, density_kg_m3=density_kg_m3, aero=aero,
                                  structural_damping=zeta).a

    fam = engine.EigenFamily(
        matrix, np.concatenate([upper, upper.conj()]), labels + labels, rest_label="lag",
        extrapolate=True, method="state-space", aero=aero, name=name, mode_labels=labels,
        natural_frequencies_rad_s=tuple(float(w) for w in w0),
        reference_semichord_m=float(np.mean(model.semichord_m)),
        divergence_speed_m_s=finite_or_none(divergence_speed_m_s(model, density_kg_m3)),
        divergence_is_instability=True)
    fam.zeta, fam.density_kg_m3 = zeta, float(density_kg_m3)
    return fam


def state_space_sweep(
    model: ClampedWingModel, speeds_m_s: np.ndarray, *, density_kg_m3: float,
    aero: str = "unsteady", structural_damping: float = 0.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Tracked branch roots (len(speeds), n_modes), the upper root of each mode's pair, and
    all eigenvalues at every speed (len(speeds), n_states) in the tracked order."""
    fam = state_space_family(model, density_kg_m3=density_kg_m3, aero=aero,
                             structural_damping=structural_damping)
    track = engine.scan(fam, speeds_m_s)
    roots = track.roots
    n = model.n_modes
    pair = np.stack([roots[:, :n], roots[:, n:2 * n]])
    upper = np.where(pair[0].imag >= pair[1].imag, pair[0], pair[1])
    return upper, roots


def state_space_flutter(
    model: ClampedWingModel,
    *,
    density_kg_m3: float,
    aero: str = "unsteady",
    structural_damping: float = 0.0,
    speed_range_m_s: tuple[float, float] = (20.0, 260.0),
    speed_step_m_s: float = DEFAULT_SPEED_STEP_M_S,
    name: str = "",
    progress=None,
    full_scan: bool = False,
) -> engine.FlutterResult:
    """First flutter or divergence of ``model`` in ``speed_range_m_s`` by eigen-analysis
    (the engine's search, bisected to 1e-7 m/s; ``progress``, ``full_scan``:
    :func:`~bioflex_jsb.flight_dynamics.flutter_engine.first_instability`'s)."""
    fam = state_space_family(model, density_kg_m3=density_kg_m3, aero=aero,
                             structural_damping=structural_damping, name=name)
    return clamped_search(fam, model, speed_range_m_s, speed_step_m_s, progress=progress,
                          full_scan=full_scan)
