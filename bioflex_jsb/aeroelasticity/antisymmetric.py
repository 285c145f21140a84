"""Unsteady strips on the wing's antisymmetric modes, and antisymmetric flutter.

The lateral model of :mod:`bioflex_jsb.flight_dynamics.lateral_elastic` couples the wing's
antisymmetric modes (the beam with the fuselage's roll freedom,
:mod:`bioflex_jsb.structures.antisymmetric`) to β, p, r, φ by the paper's quasi-steady
strips: the starboard strip at y carries the lift l_qs = ½ρV C_lα c w_qs/V·V (up) at its
aerodynamic centre, a distance e ahead of the elastic axis, with the upwash

    w_qs = V Σ θ_i η_i + Σ φ_i η̇_i + p y          [m/s]

(φ_i bending down, θ_i twist leading edge up; the port strip the mirror image, opposite).
This module adds, strip by strip, what Theodorsen's section has beyond it, exactly as the
symmetric free aircraft's unsteady strips (:mod:`bioflex_jsb.aeroelasticity.free_aircraft`)
do on the symmetric modes:

* circulatory: L_c = ½ρV C_lα c [C(k) w_¾] on the three-quarter-chord upwash of the
  section's own motion, w_¾ = w_qs + Σ (x_¾ − x_E) θ_i η̇_i (the roll rate heaves the
  section, p y, without pitching it), C(k) by R. T. Jones's two exponentials (Wagner's
  function; Jones 1940, NACA Rep. 681): two lag states per strip, ``lag1[k]``, ``lag2[k]``
  [m/s], ẋ_j = −β_j V/b x_j + A_j β_j V/b w_¾ and C w_¾ → (1 − A_1 − A_2) w_¾ + x_1 + x_2.
  The increment L_c − l_qs acts with the paper's arm e, so in a steady state (no η̇, lags
  settled) it vanishes: a steady roll, the static deformation and the divergence are the
  quasi-steady model's;
* apparent mass (thin aerofoil, Theodorsen's L_nc, M_nc about the physical elastic axis,
  a = 2 x_E,frac − 1 semichords aft of mid-chord) on the heave acceleration
  ḧ = ṗ y + Σ φ_i η̈_i (down) and the pitch α_s = Σ θ_i η_i: the roll's apparent inertia
  and the modes' apparent mass, moved to the left of E ẋ = A x.

Loads: the rolling moment of both halves ΔL = −2 ∫_0^{b/2} Δl y dy [N·m] (right wing down)
and the generalised force Q_i = ∫_0^{b/2} (−φ_i Δl + θ_i Δτ) dy [N·m] on the half aircraft
(the generalised masses m_i are the half aircraft's), Δτ = e Δl_c + M_nc the torque about
the elastic axis (leading edge up).

Two systems are built from it:

* :func:`unsteady_lateral_model`: the coupled lateral model of the one builder
  (β, p, r, φ, η, η̇; JSBSim's rigid derivatives, the aileron's quasi-steady load on the
  modes, the yaw rate's and sideslip's terms:
  :func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`) with
  these increments and the lag states appended; with ``unsteadiness`` 0 its rows and
  columns of β … η̇ are that quasi-steady model's exactly (the lags then only listen: block
  triangular), which labels its roots by continuation to 1
  (:func:`unsteady_lateral_mode_set`). The aileron's own unsteady terms (Theodorsen's
  T-functions: its circulatory lift through the lag, its δ̇, δ̈ apparent mass) need the
  surface's rate and acceleration: with an actuator
  (:mod:`bioflex_jsb.aeroelasticity.actuated_aileron`) they are in it, its states δa, δ̇a
  after the lags;
* :func:`antisymmetric_family`: the antisymmetric aeroelastic system of the flutter search:
  the roll rate p (the aircraft's I_xx, roll damping from the same strips: the wing's, the
  tail's left out) and the modes, the sideslip, yaw and bank left out (they do not load the
  modes: the lateral model's strips see p and η only); a clamped wing (root held, no p)
  is the same problem as its symmetric one, the clamped modes on Theodorsen's sections.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.aerodynamics.indicial import JONES_WAGNER
from bioflex_jsb.aeroelasticity.actuated_aileron import (
    ACTUATOR_STATES,
    ACTUATOR_UNITS,
    SURFACE_INPUT,
    actuated_inputs,
    actuator_note,
    flap_strip_loads,
)
from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    dihedral_rad,
    lateral_model_with_aileron,
)
from bioflex_jsb.aeroelasticity.control_surface import ControlSurface, SurfaceActuator
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics import flutter_engine as engine
from bioflex_jsb.flight_dynamics.eigen import IMAG_TOL_RAD_S, Mode, ModeSet
from bioflex_jsb.flight_dynamics.lateral import LateralAerodynamics, LateralTrim, inertia_matrix
from bioflex_jsb.flight_dynamics.lateral_elastic import (
    ANTISYMMETRIC_PREFIX,
    AntisymmetricWing,
    build_lateral_elastic,
    coupled_mode_set,
)
from bioflex_jsb.flight_dynamics.modal_coefficients import spanwise_geometry
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.state_space import StateSpace

AERO_MODELS = engine.AERO_MODELS
LATERAL_AERO = ("quasi-steady", "unsteady")
SYMMETRIES = ("symmetric", "antisymmetric", "both")
ROLL_LABEL = "roll"
LAG_LABEL = "lag"
# Steps of the labelling homotopy (unsteadiness 0 → 1) of :func:`unsteady_lateral_mode_set`
# and of the flutter family's first speed. ESTIMATE: 20 steps move no physical root by more
# than a few per cent of its distance to a lag root on the wings of tests/test_antisymmetric
# _flutter.py (the labels are the same with 40).
HOMOTOPY_STEPS = 20


@dataclass(frozen=True, eq=False)
class AntisymmetricStrips:
    """The starboard strips of an antisymmetric analysis and the modes on them.

    ``stations_m`` y, ``weights_m`` [m] (starboard half: Σ = semispan); ``chord_m`` c;
    ``cl_alpha_c_m`` C_lα c [m/rad]; ``e_m`` [m] the arm of the circulatory lift ahead of
    the elastic axis (the paper's, after the pin's shift); ``e_34_m`` x_¾ − x_E [m]
    (physical); ``a`` the physical elastic axis [semichords aft of mid-chord]; ``phi``,
    ``theta`` (n, K) bending [m, down] and twist [rad] per unit η; ``frequencies_rad_s``,
    ``damping_ratios``, ``generalised_masses_kg_m2`` (half aircraft) of the n modes and
    their ``mode_labels``; ``roll_inertia_kg_m2`` the aircraft's I_xx [kg·m²] (``None``:
    the root is clamped, no roll freedom); ``name``; ``quasi_steady_form`` what
    quasi-steady strips are: ``paper`` (the lift l_qs alone, the lateral model's and Eq.
    4's) or ``theodorsen`` (Theodorsen's section with C = 1: three-quarter-chord upwash
    and apparent mass, the clamped wing's quasi-steady strips); ``dihedral_rad`` (K,) the
    strips' geometric dihedral Γ_g [rad, tip up] of the increments' side force (None:
    flat)."""

    stations_m: np.ndarray
    weights_m: np.ndarray
    chord_m: np.ndarray
    cl_alpha_c_m: np.ndarray
    e_m: np.ndarray
    e_34_m: np.ndarray
    a: np.ndarray
    phi: np.ndarray
    theta: np.ndarray
    frequencies_rad_s: np.ndarray
    damping_ratios: np.ndarray
    generalised_masses_kg_m2: np.ndarray
    mode_labels: tuple[str, ...]
    roll_inertia_kg_m2: float | None
    name: str = ""
    quasi_steady_form: str = "paper"
    dihedral_rad: np.ndarray | None = None

    @property
    def n_modes(self) -> int:
        return int(self.phi.shape[0])

    @property
    def n_strips(self) -> int:
        return int(self.stations_m.size)


def aircraft_strips(build, wing: AntisymmetricWing, roll_inertia_kg_m2: float | None = None
                    ) -> AntisymmetricStrips:
    """:class:`AntisymmetricStrips` of an aircraft's wing: ``wing`` (the antisymmetric modes
    of ``build``, a WingBuild, at the lattice's strips, e shifted by the pin) with the
    physical chord, elastic axis and three-quarter-chord point of ``build``'s planform.
    Strips only: the lattice's loading (``lateral_aero = "lattice"``) has no unsteady
    counterpart here (one line)."""
    if wing.lift_matrix_m is not None:
        raise InputError("lateral_aero='lattice' is quasi-steady: the unsteady lateral model "
                         "has Theodorsen's strips only; accepted with aero='unsteady': "
                         "lateral_aero='strips'")
    modes = wing.modes
    strips = spanwise_geometry(build.aero, build.planform, modes.x_elastic_frac,
                               modes.stations_m)
    y = strips.stations_m
    if not np.allclose(y, wing.stations_m, rtol=0.0, atol=1e-12):
        raise ValueError("the antisymmetric wing was sampled on other strips than build's")
    c = strips.chord_m
    xe_frac = np.interp(y, modes.stations_m, np.asarray(modes.x_elastic_frac, dtype=float))
    n = wing.n_modes
    return AntisymmetricStrips(
        stations_m=y, weights_m=wing.weights_m, chord_m=c, cl_alpha_c_m=wing.cl_alpha_c_m,
        e_m=wing.e_m, e_34_m=(0.75 - xe_frac) * c, a=2.0 * xe_frac - 1.0, phi=wing.phi,
        theta=wing.theta, frequencies_rad_s=np.asarray(modes.frequencies_rad_s, dtype=float),
        damping_ratios=np.asarray(modes.damping_ratios, dtype=float),
        generalised_masses_kg_m2=np.asarray(modes.generalised_masses_kg_m2, dtype=float),
        mode_labels=tuple(f"{ANTISYMMETRIC_PREFIX}{i + 1}" for i in range(n)),
        roll_inertia_kg_m2=roll_inertia_kg_m2, name=build.variant.name,
        dihedral_rad=dihedral_rad(build.planform, y))


def clamped_strips(model, structural_damping: float = 0.0, name: str = ""
                   ) -> AntisymmetricStrips:
    """:class:`AntisymmetricStrips` of a clamped wing (a
    :class:`~bioflex_jsb.aeroelasticity.clamped_wing.ClampedWingModel`): its root held, the
    antisymmetric modes are its clamped modes (M-orthonormal: masses 1); Theodorsen's
    section puts the circulatory lift at the quarter chord, e = b (a + ½) ahead of the
    elastic axis, and x_¾ − x_E = b (½ − a)."""
    b = np.asarray(model.semichord_m, dtype=float)
    a = np.asarray(model.elastic_axis_a, dtype=float)
    n = model.n_modes
    return AntisymmetricStrips(
        stations_m=np.asarray(model.stations_m, dtype=float),
        weights_m=np.asarray(model.weights_m, dtype=float), chord_m=2.0 * b,
        cl_alpha_c_m=np.asarray(model.lift_slope_per_rad, dtype=float) * 2.0 * b,
        e_m=b * (a + 0.5), e_34_m=b * (0.5 - a), a=a,
        phi=np.asarray(model.heave_m, dtype=float),
        theta=np.asarray(model.pitch_rad, dtype=float),
        frequencies_rad_s=np.asarray(model.natural_frequencies_rad_s, dtype=float),
        damping_ratios=np.full(n, float(structural_damping)),
        generalised_masses_kg_m2=np.ones(n), mode_labels=tuple(model.mode_labels()),
        roll_inertia_kg_m2=None, name=name, quasi_steady_form="theodorsen")


@dataclass(frozen=True)
class Layout:
    """Where the strips' variables sit in a state vector of ``n_all`` states: ``p`` the roll
    rate's index (``None``: no roll freedom), ``eta``, ``eta_dot`` the modes' slices,
    ``lags`` the two lag states' slices (empty for quasi-steady strips)."""

    n_all: int
    p: int | None
    eta: slice
    eta_dot: slice
    lags: tuple[slice, ...]


@dataclass(frozen=True, eq=False)
class StripLoads:
    """Loads of the strips on a state x (rows ``*_x``) and its rate ẋ (``*_xd``, the
    apparent mass): ``roll_*`` (N,) the rolling moment [N·m per unit, right wing down],
    ``force_*`` (n, N) the generalised forces [N·m per unit]; ``lag_a`` (n_lag, N) the lag
    states' rates [1/s on m/s]; ``side_*`` (N,) the side force of the lift on the strips'
    geometric dihedral Γ_g, −2 Σ l Γ_g w [N per unit, body +y] (zero for a flat wing)."""

    roll_x: np.ndarray
    roll_xd: np.ndarray
    force_x: np.ndarray
    force_xd: np.ndarray
    lag_a: np.ndarray
    side_x: np.ndarray
    side_xd: np.ndarray


def strip_loads(s: AntisymmetricStrips, layout: Layout, speed_m_s: float,
                density_kg_m3: float, *, quasi_steady: bool, unsteady: bool,
                amplitudes: tuple[float, float] = JONES_WAGNER.amplitudes,
                unsteadiness: float = 1.0, gamma_rad=None) -> StripLoads:
    """The loads of the strips ``s`` on the states of ``layout`` (module docstring):
    ``quasi_steady`` the paper's strips l_qs; ``unsteady`` Theodorsen's beyond them (the
    circulatory increment through Jones's lags with ``amplitudes``, (0, 0): C = 1 without
    lag states, and the apparent mass), scaled by ``unsteadiness`` (the lags' own rates
    are not: with 0 they listen without acting). ``gamma_rad`` (K,) the strips' geometric
    dihedral Γ_g [rad, tip up] of the side force (None: ``s.dihedral_rad``, or flat)."""
    v, rho = float(speed_m_s), float(density_kg_m3)
    n_all, k = layout.n_all, s.n_strips
    y, b = s.stations_m, 0.5 * s.chord_m

    def rows() -> np.ndarray:
        return np.zeros((k, n_all))

    wqs = rows()
    wqs[:, layout.eta] = v * s.theta.T
    wqs[:, layout.eta_dot] = s.phi.T
    if layout.p is not None:
        wqs[:, layout.p] = y
    w34 = wqs.copy()
    w34[:, layout.eta_dot] += (s.e_34_m * s.theta).T
    half = 0.5 * rho * v * s.cl_alpha_c_m[:, None]  # lift per m/s of upwash [N/m per m/s]
    lift_x, lift_xd, torque_x, torque_xd = rows(), rows(), rows(), rows()
    if quasi_steady:
        lift_x += half * wqs
        torque_x += s.e_m[:, None] * half * wqs
    n_lag = sum(sl.stop - sl.start for sl in layout.lags)
    lag_a = np.zeros((n_lag, n_all))
    if unsteady:
        eps = float(unsteadiness)
        amp, beta = amplitudes, JONES_WAGNER.exponents
        l_c = half * (1.0 - sum(amp)) * w34
        for sl in layout.lags:
            l_c[:, sl] += np.diag(half[:, 0])
        dl = eps * (l_c - half * wqs)
        # apparent mass: heave acceleration ḧ (down) and pitch α_s of the section
        hdd_xd = rows()
        hdd_xd[:, layout.eta_dot] = s.phi.T
        if layout.p is not None:
            hdd_xd[:, layout.p] = y
        ad = rows()
        ad[:, layout.eta_dot] = s.theta.T  # α̇_s on x; α̈_s the same row on ẋ
        pb2 = eps * (math.pi * rho * b**2)[:, None]
        ba = (b * s.a)[:, None]
        lift_x += dl + pb2 * v * ad
        lift_xd += pb2 * (hdd_xd - ba * ad)
        torque_x += s.e_m[:, None] * dl - pb2 * v * (b * (0.5 - s.a))[:, None] * ad
        torque_xd += pb2 * (ba * hdd_xd - (b**2 * (0.125 + s.a**2))[:, None] * ad)
        for j, sl in enumerate(layout.lags):
            rate = beta[j] * v / b
            rj = slice(j * k, (j + 1) * k)
            lag_a[rj, sl] -= np.diag(rate)
            lag_a[rj] += amp[j] * rate[:, None] * w34
    w = s.weights_m

    def roll(lift):
        return -2.0 * (w * y) @ lift

    def force(lift, torque):
        return -(s.phi * w) @ lift + (s.theta * w) @ torque

    gamma = s.dihedral_rad if gamma_rad is None else gamma_rad
    gamma = np.zeros(k) if gamma is None else np.asarray(gamma, dtype=float)

    def side(lift):  # a half's lift leans inboard on its dihedral: port mirrors starboard
        return -2.0 * (w * gamma) @ lift

    return StripLoads(roll(lift_x), roll(lift_xd), force(lift_x, torque_x),
                      force(lift_xd, torque_xd), lag_a, side(lift_x), side(lift_xd))


def lag_names(n_strips: int) -> tuple[str, ...]:
    """lag1[k], lag2[k] for k in 0 … n_strips − 1 (the symmetric model's names)."""
    return tuple(f"lag{j + 1}[{k}]" for j in range(2) for k in range(n_strips))


# --------------------------------------------------------------------------------------
# the lateral model on unsteady strips
# --------------------------------------------------------------------------------------
def unsteady_lateral_model(trim: LateralTrim, aero: LateralAerodynamics,
                           wing: AntisymmetricWing, strips: AntisymmetricStrips,
                           surface: ControlSurface | None, chord_m: np.ndarray, *,
                           unsteadiness: float = 1.0, static_eta_s=None,
                           actuator: SurfaceActuator | None = None,
                           flap_terms: bool = True) -> StateSpace:
    """The coupled lateral model of the one builder
    (:func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`:
    quasi-steady strips, ``surface``'s quasi-steady load on the modes, the yaw rate's and
    sideslip's terms about the trim with ``static_eta_s``) with the unsteady strips'
    increments (module docstring): states β, p, r, φ, η_i, η̇_i, then lag1[k], lag2[k]
    [m/s]; inputs v_g, aileron, rudder; outputs the states and n_y. ``chord_m`` [m] the
    builder's strips' chords (the lattice's, ``build.aero.chord_m``). ``unsteadiness``
    (0 … 1) scales the increments: 0 is the quasi-steady model with the lags listening (its
    eigenvalues the quasi-steady ones and −β_j V/b_k).

    ``actuator``: the aileron's actuator (None: none, the model above); with it the states
    ``aileron`` [rad], ``aileron_dot`` [rad/s] follow the lags, the input ``aileron_cmd``
    [rad] replaces ``aileron``, and, with ``flap_terms`` and a ``surface``, the aileron's
    own unsteady loads (Theodorsen's T-functions: its circulatory lift through the lags,
    its δ̇, δ̈ apparent mass; :mod:`bioflex_jsb.aeroelasticity.actuated_aileron`) are on
    the strips."""
    base = _quasi_steady_base(trim, aero, wing, surface, chord_m, static_eta_s)
    return with_unsteady_strips(base, trim, strips, unsteadiness=unsteadiness,
                                actuator=actuator, surface=surface if flap_terms else None)


def _quasi_steady_base(trim: LateralTrim, aero: LateralAerodynamics, wing: AntisymmetricWing,
                       surface: ControlSurface | None, chord_m: np.ndarray,
                       static_eta_s) -> StateSpace:
    """The one builder's coupled lateral model: the unsteady model's quasi-steady part."""
    base, _ = lateral_model_with_aileron("coupled", trim, aero, wing, surface, chord_m,
                                         static_eta_s)
    return base


def with_unsteady_strips(base: StateSpace, trim: LateralTrim, strips: AntisymmetricStrips, *,
                         unsteadiness: float = 1.0, actuator: SurfaceActuator | None = None,
                         surface: ControlSurface | None = None) -> StateSpace:
    """``base`` (a coupled lateral model, states β, p, r, φ, η_i, η̇_i) with the unsteady
    strips' increments of ``strips`` (the same modes) scaled by ``unsteadiness`` and their
    lag states appended. The increments' rolling moment acts on ṗ, ṙ through J⁻¹, with the
    yawing moment of their induced drag, −α_i ΔL_u (α_i = L_w/(Q π b²), L_w = m g, b twice
    the strips' semispan: the full-span step's induced angle); their generalised force on
    η̈; their side force on the strips' dihedral (``strips.dihedral_rad``), −2 Σ Δl Γ_g w, on
    β̇ (÷ m V) and n_y (÷ m g). ``base``'s B, n_y row and notes are carried over (B through
    the apparent mass's E⁻¹). ``actuator`` (None: none) appends the aileron's states after
    the lags, and ``surface`` (with an actuator; None: none) puts the aileron's unsteady
    loads on the strips (:func:`unsteady_lateral_model`), their side force too."""
    n, k = strips.n_modes, strips.n_strips
    n0 = 4 + 2 * n
    if base.n_states != n0 or base.model != "coupled-lateral":
        raise ValueError(f"the unsteady strips go onto a coupled lateral model of {n} modes, "
                         f"not {base.model!r} with {base.n_states} states")
    n_lagged = n0 + 2 * k
    n_all = n_lagged + (0 if actuator is None else 2)
    layout = Layout(n_all, 1, slice(4, 4 + n), slice(4 + n, n0),
                    (slice(n0, n0 + k), slice(n0 + k, n_lagged)))
    loads = strip_loads(strips, layout, trim.speed_m_s, trim.density_kg_m3,
                        quasi_steady=False, unsteady=True, unsteadiness=unsteadiness)
    if actuator is not None and surface is not None:
        extra = flap_strip_loads(strips, surface, n_all, layout.lags, n_lagged, n_lagged + 1,
                                 trim.speed_m_s, trim.density_kg_m3, unsteadiness)
        loads = StripLoads(*(x + y for x, y in zip(
            (loads.roll_x, loads.roll_xd, loads.force_x, loads.force_xd, loads.lag_a,
             loads.side_x, loads.side_xd), extra, strict=True)))
    q, mass, v = float(trim.dynamic_pressure_pa), float(trim.mass_kg), float(trim.speed_m_s)
    span_m = 2.0 * float(np.sum(strips.weights_m))
    induced = mass * STANDARD_GRAVITY_M_S2 / (q * math.pi * span_m**2)  # α_i [rad]
    # (ṗ, ṙ) per unit rolling moment with its induced drag's yawing moment
    j_inv = np.linalg.inv(inertia_matrix(trim)) @ np.array([1.0, -induced])
    m = strips.generalised_masses_kg_m2
    i_beta = base.states.index("beta")

    def rates(roll, force, side) -> np.ndarray:
        out = np.zeros((n_all, n_all))
        out[1:3] = np.outer(j_inv, roll)
        out[layout.eta_dot] = force / m[:, None]
        out[i_beta] = side / (mass * v)
        return out

    a = np.zeros((n_all, n_all))
    a[:n0, :n0] = base.a
    a += rates(loads.roll_x, loads.force_x, loads.side_x)
    a[n0:n_lagged] += loads.lag_a
    e = np.eye(n_all) - rates(loads.roll_xd, loads.force_xd, loads.side_xd)
    b_plant = np.vstack([base.b, np.zeros((n_all - n0, base.b.shape[1]))])
    i_ny = base.outputs.index("n_y")
    n_y_c = np.r_[base.c[i_ny], np.zeros(n_all - n0)]
    d_ny = np.asarray(base.d[i_ny], dtype=float)
    inputs, lags = base.inputs, lag_names(k)
    states = base.states + lags
    units = base.state_units + ("m/s",) * 2 * k
    notes = {**base.notes, "wing": "antisymmetric modes, unsteady strips (Jones lag states, "
             "apparent mass)", "lag_states": 2 * k, "unsteadiness": float(unsteadiness)}
    if actuator is not None:
        col = base.inputs.index(SURFACE_INPUT)
        a[:n0, n_lagged] += base.b[:, col]  # the surface's loads now read its state
        a_act, b_act = actuator.matrices()
        a[n_lagged:, n_lagged:] = a_act
        b_plant[:, col] = 0.0
        b_plant[n_lagged:, col] = b_act[:, 0]
        n_y_c[n_lagged] = d_ny[col]
        d_ny = d_ny.copy()
        d_ny[col] = 0.0
        inputs = actuated_inputs(base.inputs)
        states += ACTUATOR_STATES
        units += ACTUATOR_UNITS
        notes["aileron_actuator"] = actuator_note(actuator)
        notes["aileron_unsteady"] = (
            "none: the aileron's quasi-steady load only" if surface is None else
            "Theodorsen's flap terms: circulatory lift through the lags, apparent mass in "
            "aileron_dot and its rate (aeroelasticity/actuated_aileron.py)")
    a = np.linalg.solve(e, a)
    b = np.linalg.solve(e, b_plant)
    # n_y: the aerodynamic side force (the rigid one, the modes', the increments' with
    # their apparent mass on ẋ = A x + B u)
    weight = mass * STANDARD_GRAVITY_M_S2
    n_y_c = n_y_c + loads.side_x / weight + loads.side_xd @ a / weight
    d_ny = d_ny + loads.side_xd @ b / weight
    c = np.vstack([np.eye(n_all), n_y_c])
    d = np.vstack([np.zeros((n_all, b.shape[1])), d_ny])
    return StateSpace(model="unsteady-lateral", speed_m_s=trim.speed_m_s, a=a, b=b,
                      c=c, d=d, states=states, state_units=units, inputs=inputs,
                      input_units=base.input_units, outputs=states + ("n_y",),
                      output_units=units + ("-",), notes=notes)


def _homotopy(matrix, reference_a: np.ndarray, reference_labels: list[str],
              steps: int = HOMOTOPY_STEPS) -> tuple[np.ndarray, list[str]]:
    """The roots of ``matrix(1)`` labelled by continuation from ``matrix(0)`` (whose roots
    are ``reference_a``'s, labelled ``reference_labels``, and the lags' −β_j V/b_k,
    labelled ``lag``): the engine's joint assignment with eigenvector correlation at each
    step of the unsteadiness."""
    lam0, vec0 = np.linalg.eig(matrix(0.0))
    ref = np.linalg.eigvals(reference_a)
    chosen = list(engine.assign(ref, lam0))
    rest = [i for i in range(lam0.size) if i not in chosen]
    order = np.array(chosen + rest)
    labels = list(reference_labels) + [LAG_LABEL] * len(rest)
    lam, vec = lam0[order], vec0[:, order]
    prev_lam = lam
    for eps in np.linspace(0.0, 1.0, steps + 1)[1:]:
        new_lam, new_vec = np.linalg.eig(matrix(float(eps)))
        pred = lam + (lam - prev_lam)
        idx = engine.assign(pred, new_lam, vec, new_vec)
        prev_lam, lam, vec = lam, new_lam[idx], new_vec[:, idx]
    return lam, labels


def unsteady_lateral_mode_set(trim: LateralTrim, aero: LateralAerodynamics,
                              wing: AntisymmetricWing, strips: AntisymmetricStrips,
                              surface: ControlSurface | None, chord_m: np.ndarray,
                              static_eta_s=None, actuator: SurfaceActuator | None = None,
                              flap_terms: bool = True) -> tuple[StateSpace, ModeSet]:
    """(the unsteady lateral model, its labelled modes): the quasi-steady coupled model's
    labels (:func:`coupled_mode_set` on the one builder's model, the quasi-steady part of
    :func:`unsteady_lateral_model` with the same arguments) carried to the unsteady one by
    continuation in the unsteadiness (0 → 1, :data:`HOMOTOPY_STEPS` steps); the lag roots
    left out. ``actuator``, ``flap_terms`` as :func:`unsteady_lateral_model`'s (the model
    with them; its modes are those without the actuator, whose roots are its own)."""
    rigid = build_lateral_elastic("rigid", trim, aero, None)
    qs = _quasi_steady_base(trim, aero, wing, surface, chord_m, static_eta_s)
    qs_modes = coupled_mode_set(qs, rigid, wing)
    labels = _root_labels(qs, rigid, wing)

    def matrix(eps: float) -> np.ndarray:
        return with_unsteady_strips(qs, trim, strips, unsteadiness=eps).a

    lam, names = _homotopy(matrix, qs.a, labels)
    # the actuator's states leave the aircraft's roots as they are (block triangular): the
    # modes are the model's without it
    ss = with_unsteady_strips(qs, trim, strips, actuator=actuator,
                              surface=surface if flap_terms else None)
    return ss, _mode_set(lam, names, ss, [m.mode for m in qs_modes.modes])


def _root_labels(qs: StateSpace, rigid: StateSpace, wing: AntisymmetricWing) -> list[str]:
    """The label of every root of the quasi-steady coupled model, in the order of
    ``np.linalg.eigvals(qs.a)`` (the assignment of :func:`coupled_mode_set`)."""
    from scipy.optimize import linear_sum_assignment

    from bioflex_jsb.flight_dynamics.lateral import lateral_mode_labels

    lam = np.linalg.eigvals(qs.a)
    ref_rigid = np.linalg.eigvals(rigid.a)
    labels = list(lateral_mode_labels(ref_rigid, float(rigid.a[1, 1])))
    refs = list(ref_rigid)
    for k, (w, z) in enumerate(zip(wing.modes.frequencies_rad_s, wing.modes.damping_ratios,
                                   strict=True)):
        root = complex(-z * w, w * np.sqrt(max(1.0 - z * z, 0.0)))
        refs += [root, root.conjugate()]
        labels += [f"{ANTISYMMETRIC_PREFIX}{k + 1}"] * 2
    rows, cols = linear_sum_assignment(np.abs(np.subtract.outer(lam, np.array(refs))))
    named = [""] * lam.size
    for r, c in zip(rows, cols, strict=True):
        named[r] = labels[c]
    return named


def _mode_set(lam: np.ndarray, names: list[str], ss: StateSpace, order: list[str]) -> ModeSet:
    modes: list[Mode] = []
    for name in dict.fromkeys(order):
        roots = [lam[k] for k in range(lam.size) if names[k] == name]
        cplx = [r for r in roots if abs(r.imag) > IMAG_TOL_RAD_S]
        if cplx:
            r = max(cplx, key=lambda z: z.imag)
            modes.append(Mode(name, float(r.real), float(abs(r.imag))))
        else:
            modes.extend(Mode(name, float(r.real), 0.0)
                         for r in sorted(roots, key=lambda z: z.real))
    return ModeSet(float(ss.speed_m_s), ss.model, tuple(modes))


# --------------------------------------------------------------------------------------
# antisymmetric flutter
# --------------------------------------------------------------------------------------
def _layout(s: AntisymmetricStrips, lags: bool) -> Layout:
    n, k = s.n_modes, s.n_strips
    i0 = 0 if s.roll_inertia_kg_m2 is None else 1
    n0 = i0 + 2 * n
    n_all = n0 + (2 * k if lags else 0)
    return Layout(n_all, None if i0 == 0 else 0, slice(i0, i0 + n), slice(i0 + n, n0),
                  (slice(n0, n0 + k), slice(n0 + k, n_all)) if lags else ())


def antisymmetric_matrix(s: AntisymmetricStrips, speed_m_s: float, density_kg_m3: float,
                         aero: str = "unsteady", unsteadiness: float = 1.0) -> np.ndarray:
    """A of ẋ = A x of the antisymmetric aeroelastic system of ``s`` at ``speed_m_s``
    [m/s] (module docstring): x = [p [rad/s] (with the roll freedom), η_i, η̇_i, then with
    ``aero`` ``unsteady`` lag1[k], lag2[k] [m/s]]; I_xx ṗ = L (the strips' rolling moment,
    the rigid roll damping included), m_i (η̈_i + 2 ζ_i ω_i η̇_i + ω_i² η_i) = Q_i."""
    if aero not in AERO_MODELS:
        raise InputError(f"unknown aerodynamics {aero!r}; accepted: {', '.join(AERO_MODELS)}")
    unsteady = aero == "unsteady"
    theodorsen_qs = not unsteady and s.quasi_steady_form == "theodorsen"
    layout = _layout(s, unsteady)
    amplitudes = (0.0, 0.0) if theodorsen_qs else JONES_WAGNER.amplitudes
    loads = strip_loads(s, layout, speed_m_s, density_kg_m3, quasi_steady=True,
                        unsteady=unsteady or theodorsen_qs, amplitudes=amplitudes,
                        unsteadiness=unsteadiness)
    n_all, m = layout.n_all, s.generalised_masses_kg_m2
    om, zeta = s.frequencies_rad_s, s.damping_ratios
    a = np.zeros((n_all, n_all))
    e = np.eye(n_all)
    a[layout.eta, layout.eta_dot] = np.eye(s.n_modes)
    a[layout.eta_dot, layout.eta] = -np.diag(om**2)
    a[layout.eta_dot, layout.eta_dot] = -np.diag(2.0 * zeta * om)
    a[layout.eta_dot] += loads.force_x / m[:, None]
    e[layout.eta_dot] -= loads.force_xd / m[:, None]
    if layout.p is not None:
        a[layout.p] += loads.roll_x / s.roll_inertia_kg_m2
        e[layout.p] -= loads.roll_xd / s.roll_inertia_kg_m2
    if layout.lags:
        a[layout.lags[0].start:] += loads.lag_a
    return np.linalg.solve(e, a)


def roll_subsidence_estimate_rad_s(s: AntisymmetricStrips, speed_m_s: float,
                                   density_kg_m3: float) -> float:
    """L_p / I_xx [1/s] of the rigid wing on the strips (the roll root alone)."""
    q_over_v = 0.5 * density_kg_m3 * speed_m_s
    l_p = -2.0 * q_over_v * float(np.sum(s.weights_m * s.cl_alpha_c_m * s.stations_m**2))
    return l_p / float(s.roll_inertia_kg_m2)


class AntisymmetricFamily(engine.EigenFamily):
    """The antisymmetric aeroelastic system as the engine's family: the roll (``roll``, a
    rigid branch: its instability is body-freedom flutter), the modes' pairs (their
    labels), the lag roots (``lag``, not considered). At the first speed the quasi-steady
    system's roots are named after the references (the roll estimate, the wind-off roots)
    and carried to the unsteady system by continuation in the unsteadiness."""

    def __init__(self, s: AntisymmetricStrips, density_kg_m3: float, aero: str, **attrs):
        self.strips, self.rho = s, float(density_kg_m3)
        super().__init__(lambda v: antisymmetric_matrix(s, v, self.rho, aero),
                         np.zeros(0), (), rest_label=LAG_LABEL,
                         rigid_labels=(ROLL_LABEL,), aero=aero, **attrs)

    def _references(self, speed_m_s: float) -> tuple[np.ndarray, list[str]]:
        s = self.strips
        w, z = s.frequencies_rad_s, s.damping_ratios
        upper = 1j * w * np.sqrt(np.maximum(1.0 - z * z, 0.0)) - z * w
        roots = list(upper) + list(upper.conj())
        labels = list(s.mode_labels) * 2
        if s.roll_inertia_kg_m2 is not None:
            roots.insert(0, roll_subsidence_estimate_rad_s(s, speed_m_s, self.rho))
            labels.insert(0, ROLL_LABEL)
        return np.array(roots, dtype=complex), labels

    def first(self, speed_m_s: float) -> engine.Point:
        v = float(speed_m_s)
        ref, ref_labels = self._references(v)
        if self.aero != "unsteady":
            lam, vec = np.linalg.eig(self.matrix(v))
            order = engine.assign(ref, lam)
            self.labels = tuple(ref_labels)
            self.considered = np.ones(len(ref_labels), dtype=bool)
            return engine.Point(v, lam[order], vec[:, order])
        s = self.strips
        qs = antisymmetric_matrix(s, v, self.rho, "quasi-steady")
        if s.quasi_steady_form == "theodorsen":  # the homotopy's start is the paper's strips
            qs = antisymmetric_matrix(replace(s, quasi_steady_form="paper"), v, self.rho,
                                      "quasi-steady")
        lam_qs = np.linalg.eigvals(qs)
        named = engine.assign(ref, lam_qs)
        labels = [""] * lam_qs.size
        for j, i in enumerate(named):
            labels[i] = ref_labels[j]

        def matrix(eps: float) -> np.ndarray:
            return antisymmetric_matrix(s, v, self.rho, "unsteady", unsteadiness=eps)

        lam, names = _homotopy(matrix, qs, labels)
        _lam, vec = np.linalg.eig(self.matrix(v))
        order = engine.assign(lam, _lam)
        self.labels = tuple(names)
        self.considered = np.array([lab != LAG_LABEL for lab in names])
        return engine.Point(v, _lam[order], vec[:, order])


def antisymmetric_flutter(s: AntisymmetricStrips, *, range_m_s: tuple[float, float],
                          step_m_s: float, density_kg_m3: float, aero: str = "unsteady",
                          structural_damping: float | None = None, tol_m_s: float,
                          start_m_s: float | None = None,
                          divergence_speed_m_s: float | None = None,
                          divergence_is_instability: bool = False, progress=None,
                          full_scan: bool = False) -> engine.FlutterResult:
    """The first antisymmetric instability of ``s`` in ``range_m_s`` [m/s]: the engine's
    scan (from ``start_m_s``, default the range's lower end, in ``step_m_s``), bisected to
    ``tol_m_s``; the result's ``settings`` say ``symmetry: antisymmetric``.
    ``structural_damping`` ζ [-] replaces the strips' (None: theirs); the divergence speed
    (clamped wing: the symmetric one, the same problem) as the engine takes it."""
    if structural_damping is not None:
        s = replace(s, damping_ratios=np.full(s.n_modes, float(structural_damping)))
    fam = AntisymmetricFamily(
        s, density_kg_m3, aero, extrapolate=True, method="state-space", name=s.name,
        mode_labels=s.mode_labels,
        natural_frequencies_rad_s=tuple(float(w) for w in s.frequencies_rad_s),
        reference_semichord_m=float(np.mean(0.5 * s.chord_m)),
        divergence_speed_m_s=divergence_speed_m_s,
        divergence_is_instability=divergence_is_instability)
    grid = engine.default_grid(tuple(range_m_s), step_m_s, start_m_s)
    settings = {"symmetry": "antisymmetric"}
    if s.roll_inertia_kg_m2 is not None:
        settings["roll_inertia_kg_m2"] = float(s.roll_inertia_kg_m2)
    return engine.first_instability(
        fam, grid, tuple(range_m_s), tol_m_s=tol_m_s, structural_damping=structural_damping,
        density_kg_m3=density_kg_m3, settings=settings, progress=progress,
        full_scan=full_scan)


def aircraft_flutter(build, *, range_m_s: tuple[float, float], step_m_s: float,
                     density_kg_m3: float, aero: str = "unsteady",
                     structural_damping: float | None = None, tol_m_s: float,
                     start_m_s: float, progress=None, full_scan: bool = False
                     ) -> engine.FlutterResult:
    """The free aircraft's antisymmetric flutter: ``build``'s (a WingBuild's) antisymmetric
    modes on its airframe's roll inertia I_xx (the wing's included; the fuselage's the
    rest), the roll freedom, ``aero`` strips; ``structural_damping`` ζ [-] (None: the
    wing model's first mode's, as the symmetric search's default)."""
    from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing

    ixx = float(build.model.airframe.mass.ixx_kg_m2)
    wing = antisymmetric_wing(build, ixx)
    zeta = (float(np.asarray(build.model.damping_ratios, dtype=float)[0])
            if structural_damping is None else float(structural_damping))
    s = aircraft_strips(build, wing, ixx)
    res = antisymmetric_flutter(s, range_m_s=range_m_s, step_m_s=step_m_s,
                                density_kg_m3=density_kg_m3, aero=aero,
                                structural_damping=zeta, tol_m_s=tol_m_s, start_m_s=start_m_s,
                                progress=progress, full_scan=full_scan)
    return replace(res, structural_damping=structural_damping)


def _onset(r: engine.FlutterResult) -> float:
    """Where ``r`` goes unstable [m/s]: −inf at and below its lower end, inf never."""
    if r.present_at_lower_end:
        return -math.inf
    return math.inf if r.speed_m_s is None else float(r.speed_m_s)


# DEFINITION: two symmetries go unstable together when their onsets agree within this
# [m/s] (a clamped wing's two problems are one: the same speed to the bisection's 1e-7 m/s)
SAME_ONSET_M_S = 1e-6


def first_of(symmetric: engine.FlutterResult, antisymmetric: engine.FlutterResult
             ) -> engine.FlutterResult:
    """The result of the symmetry that goes unstable first (the lower onset; the symmetric
    one when they agree within :data:`SAME_ONSET_M_S`), its ``settings`` saying
    ``symmetry`` (its own), ``first_symmetry`` (``symmetric``, ``antisymmetric``,
    ``both`` or ``none``: nothing unstable) and ``other_symmetry`` (the other result's
    :meth:`~FlutterResult.as_dict`)."""
    a, b = _onset(symmetric), _onset(antisymmetric)
    if math.isinf(a) and math.isinf(b) and a > 0 and b > 0:
        which = "none"
    elif a == b or abs(a - b) <= SAME_ONSET_M_S:
        which = "both"
    else:
        which = "symmetric" if a < b else "antisymmetric"
    first, other = ((antisymmetric, symmetric) if which == "antisymmetric"
                    else (symmetric, antisymmetric))
    own = "antisymmetric" if first is antisymmetric else "symmetric"
    settings = dict(first.settings, symmetry=own, first_symmetry=which,
                    other_symmetry=other.as_dict())
    return replace(first, settings=settings)
