"""The JSBSim runtime's errors and results (pure data: no JSBSim import)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.errors import InputError


class FdmError(InputError):
    """Base of the adapter's errors; the message is always a single line."""


class AircraftLoadError(FdmError):
    """The JSBSim root or aircraft file is missing, malformed or rejected by JSBSim."""


class TrimError(FdmError):
    """JSBSim's trim failed; the message names the saturated control or failed condition."""


class LinearizationError(FdmError):
    """JSBSim's linear model could not be reduced to the rigid longitudinal states."""


@dataclass(frozen=True)
class TrimResult:
    """A converged JSBSim trim: wings-level, constant-altitude flight.

    Attributes:
        speed_m_s: true airspeed [m/s]; altitude_m: altitude above sea level [m].
        alpha_rad, theta_rad: angle of attack and pitch attitude [rad] (θ = α in level flight).
        elevator_norm: elevator position, −1..1 of its travel (+ = trailing edge down); a
            glider's: its elevator command with the pitch trim (runtime/fdm.py).
        elevator_rad: elevator deflection [rad] (+ = trailing edge down, nose-down moment).
        throttle: throttle position 0..1 of every motor of the contra-rotating pair
            (fraction of the maximum shaft power).
        aileron_norm: aileron position −1..1 (+ = roll right); ≈ 0, the pair's reaction
            torques cancel.
        propeller_rpm: speed of one propeller [rev/min] (both turn at the same speed);
            thrust_n: total thrust of the pair [N].
        converged: True: JSBSim reported every trim condition within tolerance.
        flight_path_rad: the flight-path angle γ [rad] (0: level flight; an aircraft
            without an engine is trimmed to its steady glide, γ < 0: runtime/trim.py).
        residuals: the accelerations left: ``udot_m_s2``, ``wdot_m_s2`` [m/s²],
            ``qdot_rad_s2``, ``pdot_rad_s2``, ``rdot_rad_s2`` [rad/s²] (of the flying
            instance, set to the companion's trim; see the module docstring).
    """

    speed_m_s: float
    altitude_m: float
    alpha_rad: float
    theta_rad: float
    elevator_norm: float
    elevator_rad: float
    throttle: float
    aileron_norm: float
    propeller_rpm: float
    thrust_n: float
    converged: bool
    residuals: dict[str, float] = field(default_factory=dict)
    flight_path_rad: float = 0.0  # γ [rad], positive climbing: 0 level, < 0 a glide
    # the elastic trim's static wing state (flight_dynamics.elastic_trim.ElasticTrim) the
    # rigid trim carries; None for a rigid trim (runtime/fdm.py Airframe.trim)
    elastic: object | None = field(default=None, compare=False)


@dataclass(frozen=True)
class ModeEigenvalue:
    """One eigenvalue of a conjugate pair (the one with im ≥ 0), with its mode.

    re, im [rad/s]; damping ζ = −re/|λ| [-]; frequency_rad_s ω_n = |λ| [rad/s].
    """

    mode: str
    re: float
    im: float
    damping: float
    frequency_rad_s: float


RIGID_STATES = ("u", "alpha", "q", "theta")
RIGID_STATE_UNITS = ("m/s", "rad", "rad/s", "rad")


@dataclass(frozen=True)
class RigidLinearization:
    """JSBSim's linear model at a trim, reduced to x_R = [u, α, q, θ] (SI).

    Attributes:
        speed_m_s: trim airspeed [m/s].
        trim: the trim it was taken at.
        a: 4×4 system matrix, states :data:`RIGID_STATES` in :data:`RIGID_STATE_UNITS`
            (row i: d x_i/dt; e.g. a[0, 1] = ∂u̇/∂α [m/s² per rad]).
        eigenvalues: one :class:`ModeEigenvalue` per conjugate pair (or real root),
            short period first.
        jsbsim_states: JSBSim's full state list the model was reduced from.
        residualised_states: the states eliminated as quasi-static (propeller RPM).
    """

    speed_m_s: float
    trim: TrimResult
    a: np.ndarray
    eigenvalues: tuple[ModeEigenvalue, ...]
    jsbsim_states: tuple[str, ...]
    residualised_states: tuple[str, ...]
    states: tuple[str, ...] = RIGID_STATES
    state_units: tuple[str, ...] = RIGID_STATE_UNITS

    def mode(self, name: str) -> ModeEigenvalue:
        """The eigenvalue (im ≥ 0) of mode ``name`` ('short_period' or 'phugoid')."""
        for ev in self.eigenvalues:
            if ev.mode == name:
                return ev
        raise KeyError(f"no {name!r} eigenvalue")


@dataclass(frozen=True)
class LateralLinearization:
    """JSBSim's lateral-directional linear model at a trim (SI).

    Attributes:
        speed_m_s: trim airspeed [m/s]; trim: the trim it was taken at.
        a: 4×4 system matrix, states [β, p, r, φ] in rad, rad/s (body axes; row i:
            d x_i/dt), the lateral block of JSBSim's model
            (:func:`~bioflex_jsb.runtime.linearization.reduce_to_lateral`).
        method: ``FGLinearization`` (JSBSim's own) or ``central differences`` (of JSBSim's
            state derivatives: a glider, which FGLinearization cannot take;
            :func:`~bioflex_jsb.runtime.linearization.lateral_jacobian`).
    """

    speed_m_s: float
    trim: TrimResult
    a: np.ndarray
    method: str

    @property
    def eigenvalues(self) -> np.ndarray:
        """The four roots [rad/s]."""
        return np.linalg.eigvals(self.a)


def label_modes(eigenvalues: np.ndarray) -> tuple[ModeEigenvalue, ...]:
    """Label the 4 longitudinal eigenvalues and keep one per conjugate pair.

    Each mode is one conjugate pair or two real roots, the short period the one of the
    larger natural frequency (:func:`bioflex_jsb.flight_dynamics.eigen.mode_labels_of_roots`:
    an over-damped short period's two real roots stay together). Short period first; complex
    pairs are reported once (im > 0); real roots each appear (im = 0).
    """
    from bioflex_jsb.flight_dynamics.eigen import mode_labels_of_roots

    lam = np.asarray(eigenvalues, dtype=complex)
    if lam.shape != (4,):
        raise ValueError(f"expected 4 longitudinal eigenvalues, got {lam.shape}")
    labels = mode_labels_of_roots(lam)
    order = sorted(range(4), key=lambda i: (labels[i] != "short_period", -abs(lam[i])))
    out = []
    for i in order:
        value = lam[i]
        if value.imag < 0.0:
            continue
        modulus = abs(value)
        out.append(
            ModeEigenvalue(
                mode=labels[i],
                re=float(value.real),
                im=float(abs(value.imag)),
                damping=float(-value.real / modulus) if modulus > 0 else 1.0,
                frequency_rad_s=float(modulus),
            )
        )
    return tuple(out)
