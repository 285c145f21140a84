"""Flaperons: the wing's ailerons deflected symmetrically, as a command of the symmetric
(half-wing) model: their strip loads on the symmetric modes and their lift and pitching
moment on the rigid body, the same section data as the antisymmetric aileron.

**Sign.** δf [rad] is the deflection of both ailerons together, **trailing edge down
positive** on both halves (more lift: a flap down): δ_left = δ_right = δf. In JSBSim's
aileron terms δf = ½ (δ_left + δ_right), the symmetric part that JSBSim's tables (C_lδa, a
rolling moment only) do not carry: the flaperon's loads reach JSBSim through the external
reactions alone, never through ``fcs/aileron-cmd-norm``, so nothing is counted twice.

**Section** (thin aerofoil, :mod:`~bioflex_jsb.aeroelasticity.control_surface`): strip k,
covered over the part χ_k of its width by the aileron hinged at ``hinge`` chord fractions,
carries per unit span and unit dynamic pressure Q the flap lift c_k a₀,k τ χ_k δf (up, at
the strip's aerodynamic centre; τ = c_lδ/2π, the circulatory part in proportion to the
strip's own slope a₀,k = C_lα,k: ``cl_alpha_c_m`` of the lattice strip) and the
quarter-chord moment c_k² χ_k c_mδ δf (nose up; c_mδ < 0). These are exactly the flap terms
of :func:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.antisymmetric_strips`, with the
same sign on both halves.

**Derivatives** (Table B1's normalisation: whole span, S and c̄ of the airframe; the strips
of the wing's own modal coefficients, the C_η1^Q1 pin's shift of e included):

    C_Lδf    = (2/S)   Σ_k w_k c_k a₀,k τ χ_k                                 [1/rad]
    C_mδf    = (2/S c̄) Σ_k w_k χ_k (d_k c_k a₀,k τ + c_k² c_mδ)               [1/rad]
    C_δf^Qi  = (2/S c̄) Σ_k w_k χ_k (w_ik c_k a₀,k τ + θ_ik c_k² c_mδ)         [1/rad]

with d_k the aerodynamic centre ahead of the CG (nose-up arm of an upward lift) and w_ik =
e_k θ_ik − φ_ik the upward displacement of the aerodynamic centre per unit η_i (the virtual
work of Table B1's C_α^Qi). The induced drag of the flaperon's lift is 2 k C_L0 C_Lδf, as
the modes' (:mod:`bioflex_jsb.flight_dynamics.modal_matrices`).

**Left out** (the same as the modal lift's, Eq. 4): the flaperon's downwash at the tail,
the lattice's spanwise redistribution of a part-span flap's load (strip theory on the
α-loading's local slope), unsteady flap terms (the quasi-steady strips only), and the
hinge moment. A uniform rectangular strip (a₀ = 2π) gives the closed form C_Lδf = 2 c
c_lδ (y₂ − y₁)/S, tested against the derivatives (``tests/test_flaperon.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bioflex_jsb.aerodynamics.theodorsen import TWO_PI
from bioflex_jsb.aeroelasticity.control_surface import (
    ControlSurface,
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.modal_coefficients import shifted, spanwise_geometry
from bioflex_jsb.flight_dynamics.rigid import (
    FlightCondition,
    alpha_rate_scale,
    rigid_derivatives,
)
from bioflex_jsb.parameters.constants import STANDARD_GRAVITY_M_S2
from bioflex_jsb.state_space import StateSpace

FLAPERON = "flaperon"  # the LTI model's input name and the controller's command
# The flaperon's travel [rad] in the co-simulation: the deflection is clipped to it. The
# prototype's generated flight controls give the ailerons ±20° (parameters.airframe
# CONTROL_LIMITS); a flaperon that also rolls the aircraft shares it with the aileron, so
# the symmetric part alone is kept within half of it.
FLAPERON_LIMIT_RAD = math.radians(10.0)


@dataclass(frozen=True, eq=False)
class FlaperonDerivatives:
    """A wing's flaperon (module docstring): ``surface`` the aileron deflected
    symmetrically; ``c_l_per_rad`` C_Lδf, ``c_m_per_rad`` C_mδf (about the CG, nose up) on
    the airframe's S, c̄; ``c_q_per_rad`` (n,) C_δf^Qi; per starboard strip (K,):
    ``strip_lift_m`` c a₀ τ χ [m/rad] (the flap lift per unit span per unit Q and rad) and
    ``strip_moment_m2`` c² χ c_mδ [m²/rad] (the quarter-chord moment likewise, nose up);
    ``area_m2``, ``chord_m`` the reference S and c̄."""

    surface: ControlSurface
    c_l_per_rad: float
    c_m_per_rad: float
    c_q_per_rad: np.ndarray
    strip_lift_m: np.ndarray
    strip_moment_m2: np.ndarray
    area_m2: float
    chord_m: float

    def forcing_per_q(self, masses_kg_m2) -> np.ndarray:
        """b_δf = S c̄ C_δf^Qi / m_i [1/(Pa·s²) per rad]: η̈_i per unit Q δf."""
        m = np.asarray(masses_kg_m2, dtype=float)
        return self.area_m2 * self.chord_m * self.c_q_per_rad / m

    def as_dict(self) -> dict[str, object]:
        return {"surface": self.surface.as_dict(), "c_l_per_rad": self.c_l_per_rad,
                "c_m_per_rad": self.c_m_per_rad, "c_q_per_rad": self.c_q_per_rad.tolist()}


def flaperon_derivatives(build, surface: ControlSurface | None) -> FlaperonDerivatives:
    """The flaperon derivatives of ``build`` (a WingBuild: its strips, modes and airframe)
    with its aileron ``surface`` deflected symmetrically; InputError (one line) for a wing
    without an aileron or one beyond its semispan."""
    if surface is None:
        raise InputError("the wing has no aileron ([aileron] in its aircraft definition) to "
                         "deflect as flaperons")
    planform, modes = build.planform, build.modes
    if surface.end_m > planform.semispan_m * (1.0 + 1e-9):
        raise InputError(f"the aileron ends at {surface.end_m:g} m, beyond the semispan "
                         f"{planform.semispan_m:g} m")
    strips = shifted(spanwise_geometry(build.aero, planform, modes.x_elastic_frac,
                                       modes.stations_m), build.e_shift_frac * planform.chord_m)
    n = build.model.n_modes
    y, w = strips.stations_m, strips.weights_m
    phi = np.array([np.interp(y, modes.stations_m, b) for b in modes.bending_m[:n]])
    theta = np.array([np.interp(y, modes.stations_m, t) for t in modes.twist_rad[:n]])
    chi = strip_coverage(np.asarray(build.aero.weights_m, dtype=float), surface)
    tau = flap_lift_slope_per_rad(surface.hinge) / TWO_PI
    lift = strips.cl_alpha_c_m * tau * chi  # [m/rad]
    moment = strips.chord_m**2 * chi * flap_moment_slope_per_rad(surface.hinge)  # [m²/rad]
    ref = build.airframe.reference
    s, cb = ref.area_m2, ref.mean_chord_m
    work = strips.e_m * theta - phi
    c_l = 2.0 * float(lift @ w) / s
    c_m = 2.0 * float((strips.d_m * lift + moment) @ w) / (s * cb)
    c_q = 2.0 * ((work * lift + theta * moment) @ w) / (s * cb)
    return FlaperonDerivatives(surface, c_l, c_m, c_q, lift, moment, s, cb)


def flaperon_column(condition: FlightCondition, deriv: FlaperonDerivatives,
                    masses_kg_m2, n_modes: int) -> np.ndarray:
    """The B column of the coupled model's states [u, α, q, θ, η, η̇] for δf [rad]: the
    rigid rows as the elevator's (:func:`~bioflex_jsb.flight_dynamics.lti.control_columns`:
    X the induced drag of the lift, Z through the α equation's divisor, M with M_ẇ Z) and
    the modes' η̈ rows Q b_δf."""
    af = condition.airframe
    aero = af.aero
    qs = condition.dynamic_pressure_pa * af.reference.area_m2
    cb = af.reference.mean_chord_m
    mass, iyy = af.mass.mass_kg, af.mass.iyy_kg_m2
    z = -deriv.c_l_per_rad * qs / mass
    x = -2.0 * aero.k_induced * condition.cl_trim * deriv.c_l_per_rad * qs / mass
    m = deriv.c_m_per_rad * qs * cb / iyy
    div, f = alpha_rate_scale(rigid_derivatives(condition, aero, mass, iyy))
    m_wdot = aero.cm_alphadot_per_rad * qs * cb**2 / (2.0 * iyy * condition.speed_m_s**2)
    col = np.zeros(4 + 2 * n_modes)
    col[:4] = (x, z / div, m + m_wdot * z * f, 0.0)
    col[4 + n_modes:] = condition.dynamic_pressure_pa * deriv.forcing_per_q(masses_kg_m2)
    return col


def with_flaperon(ss: StateSpace, condition: FlightCondition,
                  deriv: FlaperonDerivatives, masses_kg_m2) -> StateSpace:
    """The coupled model with controls (``build_state_space("coupled", controls=True)``)
    with the input ``flaperon`` [rad] appended: its B column (:func:`flaperon_column`) and
    the D entries of its outputs (n_z through the α row; tip_twist and the states none)."""
    if ss.model != "coupled" or "n_z" not in ss.outputs or FLAPERON in ss.inputs:
        raise InputError("the flaperon input is added to the coupled model with its controls "
                         "(linear_model(..., model='coupled'))")
    n = (ss.n_states - 4) // 2
    col = flaperon_column(condition, deriv, masses_kg_m2, n)
    d = np.zeros(ss.d.shape[0])
    # n_z = u₀ (q − α̇)/g: its D entry is −u₀/g times the α row's B (as the elevator's)
    d[ss.outputs.index("n_z")] = -ss.speed_m_s / STANDARD_GRAVITY_M_S2 * col[
        ss.states.index("alpha")]
    notes = dict(ss.notes, flaperon=deriv.as_dict())
    return StateSpace(model=ss.model, speed_m_s=ss.speed_m_s, a=ss.a,
                      b=np.hstack([ss.b, col[:, None]]), c=ss.c, d=np.hstack([ss.d, d[:, None]]),
                      states=ss.states, state_units=ss.state_units,
                      inputs=ss.inputs + (FLAPERON,), input_units=ss.input_units + ("rad",),
                      outputs=ss.outputs, output_units=ss.output_units, notes=notes)


def lift_matrices(build, surface: ControlSurface):
    """The root-held static problem of the flaperon's lift (its reversal): the aileron
    analysis' matrices (:func:`~bioflex_jsb.aeroelasticity.aileron.static_roll_matrices` on
    :func:`~bioflex_jsb.aeroelasticity.aileron.flight_roll_strips`) with the rolling
    moment's output Σ w y L' replaced by the half wing's lift Σ w L': the same stiffness,
    aerodynamic and flap forcing, the output unweighted by the span station. Its
    ``effectiveness(q_pa)`` is the lift per δf elastic over rigid, its
    ``reversal_dynamic_pressure_pa()`` where that lift vanishes (optimised wing: 12.33 m/s
    at sea level, below its aileron's 12.82 m/s: ``tests/test_flaperon.py``)."""
    from dataclasses import replace

    from bioflex_jsb.aeroelasticity.aileron import flight_roll_strips, static_roll_matrices

    rs = flight_roll_strips(build, surface)
    w = rs.weights_m
    lift_alpha = rs.chord_m * rs.lift_slope_per_rad  # [m/rad]
    return replace(static_roll_matrices(rs), moment_eta=rs.twist_rad @ (w * lift_alpha),
                   moment_delta=float(np.sum(w * rs.chord_m * rs.coverage
                                             * rs.flap_lift_per_rad)))
