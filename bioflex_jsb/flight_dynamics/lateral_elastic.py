"""The lateral-directional model with the wing's antisymmetric modes (docs/lateral.md).

The rigid lateral model (:mod:`bioflex_jsb.flight_dynamics.lateral`, states β, p, r, φ)
coupled to the wing's antisymmetric modes (:mod:`bioflex_jsb.structures.antisymmetric`: the
beam with the fuselage's roll freedom, free-free, M-orthogonal to the rigid roll) by
quasi-steady strips, as Eq. (4) couples the symmetric modes to the longitudinal states:

* state x = [β, p, r, φ, η_1 … η_n, η̇_1 … η̇_n] (η_i [rad], the project's normalisation:
  max |twist| = 1 on the starboard half, tip twist positive; the port half is the mirror
  image with the opposite sign);
* the starboard strip at y (the lattice's strips, C_lα c of a uniform α: the symmetric
  loading's, a strip-theory approximation for the antisymmetric one, or with the build's
  ``lateral_aero = "lattice"`` the lattice's antisymmetric loading of the whole
  distribution, :mod:`~bioflex_jsb.aerodynamics.antisymmetric_loading`; e shifted as the
  symmetric model's pin of C_η1^Q1 shifts it, the paper's wings) sees
  Δα = Σ θ_i η_i + Σ φ_i η̇_i / V + p y / V (φ_i bending down, a wing going down sees the
  air come up) and carries the lift l = Q C_lα c Δα (up); the port strip the opposite;
* the rolling moment of the modes' lift, ΔL = −2 ∫_0^{b/2} l y dy over its η and η̇ terms
  (the rigid roll's own damping is JSBSim's C_lp, already in the rigid block);
* the generalised force on mode i, Q_i = ∫_0^{b/2} l (e θ_i − φ_i) dy (the virtual-work
  term of Table B1, on the half aircraft whose generalised mass m_i is), with the rigid
  roll rate's lift in it; η̈_i = −ω_i² η_i − 2 ζ_i ω_i η̇_i + Q_i / m_i;
* added by :func:`bioflex_jsb.aeroelasticity.antisymmetric_strips.lateral_model_with_aileron`
  (the model the API and ``compare`` return): the aileron's load on the modes, and the yaw
  rate's and sideslip's forcing of the modes, the modes' side force and yawing moment
  (:class:`~bioflex_jsb.aeroelasticity.antisymmetric_strips.YawSideslipTerms` linearised
  about the trim); left out: the lateral gust's load on the modes, unsteady strips.

The QSD reduction (η̈ = η̇ = 0, as Eq. 9-10 for the longitudinal model) keeps the states
β, p, r, φ with the static deformation residualised.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import linear_sum_assignment

from bioflex_jsb.aerodynamics.antisymmetric_loading import (
    antisymmetric_lift_matrix,
    lift_per_alpha,
)
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.eigen import IMAG_TOL_RAD_S, Mode, ModeSet
from bioflex_jsb.flight_dynamics.lateral import (
    LATERAL_INPUTS,
    LATERAL_STATE_UNITS,
    LATERAL_STATES,
    LateralAerodynamics,
    LateralTrim,
    build_lateral_state_space,
    inertia_matrix,
    lateral_mode_labels,
)
from bioflex_jsb.flight_dynamics.modal_coefficients import shifted, spanwise_geometry
from bioflex_jsb.state_space import StateSpace
from bioflex_jsb.structures.antisymmetric import solve_antisymmetric
from bioflex_jsb.structures.modal_data import ModalData

LATERAL_MODELS = ("rigid", "coupled", "qsd")
ANTISYMMETRIC_PREFIX = "antisymmetric_"


@dataclass(frozen=True)
class AntisymmetricWing:
    """The wing's antisymmetric modes at the lattice's starboard strips.

    ``modes`` (:class:`ModalData`, normalised; generalised masses of the half aircraft
    [kg·m²]); ``stations_m``, ``weights_m`` [m] the strips; ``cl_alpha_c_m`` C_lα c
    [m/rad]; ``e_m`` [m] the aerodynamic centre ahead of the elastic axis; ``phi``,
    ``theta`` (n, K) bending [m, down] and twist [rad, LE up] per unit η at the strips;
    ``fuselage_roll_inertia_kg_m2`` [kg·m²] (the aircraft's I_xx less the two wing halves').
    What the yaw rate's and sideslip's terms take from the wing's build (None, 0: a wing
    without them): ``symmetric`` the half wing's symmetric modes (:class:`ModalData`, bending
    down, twist leading edge up), ``n_symmetric`` how many of them the wing model flies,
    ``planform`` (its dihedral) and ``span_m`` [m] the wing's span; ``root_slope`` (n,) each
    mode's bending slope at the root [rad per unit η, starboard wing down outboard positive]:
    the fuselage's roll relative to the mean axes, from the beam's root node (None: not
    known). ``lift_matrix_m`` (K, K) [m/rad] the lattice's antisymmetric loading of the
    strips, l'/q = A α (:mod:`~bioflex_jsb.aerodynamics.antisymmetric_loading`); None: the
    strips' own C_lα c α."""

    modes: ModalData
    stations_m: np.ndarray
    weights_m: np.ndarray
    cl_alpha_c_m: np.ndarray
    e_m: np.ndarray
    phi: np.ndarray
    theta: np.ndarray
    fuselage_roll_inertia_kg_m2: float
    symmetric: ModalData | None = None
    n_symmetric: int = 0
    planform: object = None
    span_m: float = 0.0
    root_slope: np.ndarray | None = None
    lift_matrix_m: np.ndarray | None = None

    def lift_m(self, alpha_rad: np.ndarray) -> np.ndarray:
        """l'/q [m] at the strips of the antisymmetric distributions ``alpha_rad`` (…, K)
        [rad], by the strips or the lattice (``lift_matrix_m``)."""
        return lift_per_alpha(self.cl_alpha_c_m, self.lift_matrix_m, alpha_rad)

    @property
    def n_modes(self) -> int:
        return int(self.phi.shape[0])


def wing_sections(build):
    """The beam sections of ``build`` (a WingBuild): a definition's beam, else the
    calibrated membrane beam of a named variant; a wing given only as a modal-data file has
    no beam to take the antisymmetric modes from (one line)."""
    v = build.variant
    if v.beam is not None:
        return v.beam.sections
    if v.modes_file:
        raise InputError(f"wing {v.name!r} is a modal-data file ({v.modes_file}): its "
                         "antisymmetric modes need the beam (the file holds the clamped "
                         "symmetric ones only)")
    from bioflex_jsb.flight_dynamics.wing_model import membrane_structure
    from bioflex_jsb.structures.wing_model import wing_sections as membrane_sections

    return membrane_sections(membrane_structure(v),
                             x_inertial_frac=v.x_inertial_frac,
                             x_elastic_frac=v.x_elastic_frac)


def antisymmetric_wing(build, aircraft_ixx_kg_m2: float, n_modes: int = 3) -> AntisymmetricWing:
    """The antisymmetric modes of ``build``'s wing on its aircraft of roll inertia
    ``aircraft_ixx_kg_m2`` [kg·m²] (the wing's included: JSBSim's I_xx), sampled at its
    strips; damping the wing's symmetric modes' first ζ."""
    sections = wing_sections(build)
    half_wing = solve_antisymmetric(sections, 0.0, n_modes=1).half_roll_inertia_kg_m2
    j_f = float(aircraft_ixx_kg_m2) - 2.0 * half_wing
    if not j_f > 0.0:
        raise InputError(f"the aircraft's roll inertia {aircraft_ixx_kg_m2:.4g} kg m^2 is not "
                         f"more than its wing's {2.0 * half_wing:.4g} kg m^2: the wing's "
                         "beam and the airframe's inertia disagree")
    sol = solve_antisymmetric(sections, j_f, n_modes=n_modes)
    y_nodes = sol.nodes_m
    bend, twist = sol.sample(y_nodes)
    zeta = float(np.asarray(build.modes.damping_ratios)[0])
    raw = ModalData(
        frequencies_rad_s=sol.frequencies_rad_s,
        damping_ratios=np.full(n_modes, zeta),
        generalised_masses_kg_m2=np.ones(n_modes),
        stations_m=y_nodes, bending_m=bend, twist_rad=twist,
        x_elastic_frac=np.interp(y_nodes, sections.stations_m, sections.x_elastic_frac),
        x_inertial_frac=np.interp(y_nodes, sections.stations_m, sections.x_inertial_frac),
        source=sections.description,
        notes=f"antisymmetric, fuselage roll inertia {j_f:.6g} kg m^2")
    modes = raw.normalised()
    # the root node's slope w'(0) (the fuselage's roll), scaled as the shapes are
    root_slope = np.asarray(sol.roll_slope, dtype=float) / raw.normalisation_factors()
    strips = spanwise_geometry(build.aero, build.planform, modes.x_elastic_frac,
                               modes.stations_m)
    # the symmetric model's pin of C_η1^Q1 (a shift of e, the paper's wings) holds here too
    strips = shifted(strips, build.e_shift_frac * build.planform.chord_m)
    y = strips.stations_m
    phi = np.array([np.interp(y, modes.stations_m, b) for b in modes.bending_m])
    theta = np.array([np.interp(y, modes.stations_m, t) for t in modes.twist_rad])
    return AntisymmetricWing(modes, y, strips.weights_m, strips.cl_alpha_c_m, strips.e_m, phi,
                             theta, j_f, symmetric=build.modes,
                             n_symmetric=int(build.model.n_modes), planform=build.planform,
                             span_m=2.0 * float(build.aero.semispan_m),
                             root_slope=root_slope,
                             lift_matrix_m=antisymmetric_lift_matrix(
                                 build.aero, build.lateral_aero))


@dataclass(frozen=True)
class StripTerms:
    """Dimensional strip terms at a dynamic pressure and speed: ``roll_eta``,
    ``roll_etadot`` (n,) the rolling moment [N·m per rad, per rad/s]; ``force_p`` (n,),
    ``force_eta``, ``force_etadot`` (n, n) the generalised forces [N·m per rad/s, per rad,
    per rad/s] (row: the mode acted on)."""

    roll_eta: np.ndarray
    roll_etadot: np.ndarray
    force_p: np.ndarray
    force_eta: np.ndarray
    force_etadot: np.ndarray


def strip_terms(wing: AntisymmetricWing, dynamic_pressure_pa: float, speed_m_s: float
                ) -> StripTerms:
    """:class:`StripTerms` of ``wing`` (module docstring)."""
    q, v = float(dynamic_pressure_pa), float(speed_m_s)
    w, y = wing.weights_m, wing.stations_m
    work = wing.e_m * wing.theta - wing.phi  # (n, K) upward AC displacement per unit η
    if wing.lift_matrix_m is not None:  # the lattice's loading, per unit Q and Q/V
        u = lattice_unit_terms(wing)
        return StripTerms(roll_eta=q * u.roll_eta, roll_etadot=q / v * u.roll_etadot,
                          force_p=q / v * u.force_p, force_eta=q * u.force_eta,
                          force_etadot=q / v * u.force_etadot)
    lift = q * wing.cl_alpha_c_m * w  # lift of a strip per rad of Δα [N]
    return StripTerms(
        roll_eta=-2.0 * (wing.theta * lift) @ y,
        roll_etadot=-2.0 * (wing.phi * lift / v) @ y,
        force_p=work @ (lift * y / v),
        force_eta=np.einsum("ik,jk,k->ij", work, wing.theta, lift),
        force_etadot=np.einsum("ik,jk,k->ij", work, wing.phi, lift / v),
    )


def lattice_unit_terms(wing: AntisymmetricWing) -> StripTerms:
    """:class:`StripTerms` of ``wing``'s lattice loading (``lift_matrix_m``) per unit
    dynamic pressure (η terms) and per unit Q/V (η̇ and p terms) [N·m/Pa, N·m/(Pa·s/m)]:
    each distribution's lift l'/q = A α (θ_i, φ_i, y), its rolling moment −2 Σ w y l'/q
    and its virtual work Σ w (e θ_i − φ_i) l'/q."""
    w, y = wing.weights_m, wing.stations_m
    work = wing.e_m * wing.theta - wing.phi  # (n, K) upward AC displacement per unit η
    l_theta, l_phi = w * wing.lift_m(wing.theta), w * wing.lift_m(wing.phi)
    return StripTerms(roll_eta=-2.0 * l_theta @ y, roll_etadot=-2.0 * l_phi @ y,
                      force_p=work @ (w * wing.lift_m(y)), force_eta=work @ l_theta.T,
                      force_etadot=work @ l_phi.T)


def build_lateral_elastic(model: str, trim: LateralTrim, aero: LateralAerodynamics,
                          wing: AntisymmetricWing | None) -> StateSpace:
    """The ``rigid``, ``coupled`` or ``qsd`` lateral model (module docstring): inputs v_g
    [m/s], aileron, rudder [rad]; outputs the states (QSD: and its quasi-static η) and
    n_y [-]."""
    if model not in LATERAL_MODELS:
        raise InputError(f"unknown model {model!r}; accepted: {', '.join(LATERAL_MODELS)}")
    rigid = build_lateral_state_space(trim, aero)
    if model == "rigid":
        return rigid
    if wing is None:
        raise InputError(f"the lateral {model} model needs an elastic wing")
    n = wing.n_modes
    t = strip_terms(wing, trim.dynamic_pressure_pa, trim.speed_m_s)
    j_inv = np.linalg.inv(inertia_matrix(trim))[:, 0]  # (ṗ, ṙ) per unit rolling moment
    m = np.asarray(wing.modes.generalised_masses_kg_m2, dtype=float)
    om = np.asarray(wing.modes.frequencies_rad_s, dtype=float)
    zeta = np.asarray(wing.modes.damping_ratios, dtype=float)
    a_re = np.zeros((4, n))
    a_redot = np.zeros((4, n))
    a_re[1:3] = np.outer(j_inv, t.roll_eta)
    a_redot[1:3] = np.outer(j_inv, t.roll_etadot)
    a_er = np.zeros((n, 4))
    a_er[:, 1] = t.force_p / m
    a_ee = -np.diag(om**2) + t.force_eta / m[:, None]
    a_eedot = -np.diag(2.0 * zeta * om) + t.force_etadot / m[:, None]
    names = tuple(f"eta{i + 1}" for i in range(n))
    notes = {**rigid.notes, "wing": "antisymmetric modes, quasi-steady strips",
             "frequencies_rad_s": om.tolist(),
             "fuselage_roll_inertia_kg_m2": wing.fuselage_roll_inertia_kg_m2}
    n_y_c, n_y_d = rigid.c[4], rigid.d[4]
    if model == "coupled":
        a = np.block([[rigid.a, a_re, a_redot],
                      [np.zeros((n, 4)), np.zeros((n, n)), np.eye(n)],
                      [a_er, a_ee, a_eedot]])
        b = np.vstack([rigid.b, np.zeros((2 * n, 3))])
        states = LATERAL_STATES + names + tuple(f"{s}_dot" for s in names)
        units = LATERAL_STATE_UNITS + ("rad",) * n + ("rad/s",) * n
        c = np.vstack([np.eye(4 + 2 * n), np.r_[n_y_c, np.zeros(2 * n)]])
        d = np.vstack([np.zeros((4 + 2 * n, 3)), n_y_d])
        return StateSpace(model="coupled-lateral", speed_m_s=trim.speed_m_s, a=a, b=b, c=c,
                          d=d, states=states, state_units=units, inputs=LATERAL_INPUTS,
                          input_units=rigid.input_units, outputs=states + ("n_y",),
                          output_units=units + ("-",), notes=notes)
    eta_of_x = -np.linalg.solve(a_ee, a_er)  # static η per rigid state
    a = rigid.a + a_re @ eta_of_x
    c = np.vstack([np.eye(4), eta_of_x, n_y_c])
    d = np.vstack([np.zeros((4 + n, 3)), n_y_d])
    return StateSpace(model="qsd-lateral", speed_m_s=trim.speed_m_s, a=a, b=rigid.b, c=c, d=d,
                      states=LATERAL_STATES, state_units=LATERAL_STATE_UNITS,
                      inputs=LATERAL_INPUTS, input_units=rigid.input_units,
                      outputs=LATERAL_STATES + names + ("n_y",),
                      output_units=LATERAL_STATE_UNITS + ("rad",) * n + ("-",), notes=notes)


def residualised(ss: StateSpace) -> StateSpace:
    """The coupled lateral model ``ss`` (states β, p, r, φ, η, η̇; any inputs) with its modes
    residualised (η̇ = η̈ = 0: η = −A_ff⁻¹ (A_fr x + B_f u), f = [η, η̇]): the QSD model,
    states β, p, r, φ, outputs those, the quasi-static η_i and n_y. An input that loads the
    modes (the aileron's generalised force) enters the balance through B_f; without one it
    is ``build_lateral_elastic("qsd")`` (tested to round-off)."""
    if ss.model != "coupled-lateral":
        raise ValueError(f"residualised takes the coupled lateral model, not {ss.model!r}")
    a, b = np.asarray(ss.a, dtype=float), np.asarray(ss.b, dtype=float)
    c, d = np.asarray(ss.c, dtype=float), np.asarray(ss.d, dtype=float)
    r = len(LATERAL_STATES)
    solve_fr = np.linalg.solve(a[r:, r:], a[r:, :r])  # A_ff⁻¹ A_fr
    solve_fu = np.linalg.solve(a[r:, r:], b[r:])  # A_ff⁻¹ B_f
    keep = [i for i, name in enumerate(ss.outputs) if not name.endswith("_dot")]
    c_q = c[:, :r] - c[:, r:] @ solve_fr
    d_q = d - c[:, r:] @ solve_fu
    return StateSpace(model="qsd-lateral", speed_m_s=ss.speed_m_s,
                      a=a[:r, :r] - a[:r, r:] @ solve_fr, b=b[:r] - a[:r, r:] @ solve_fu,
                      c=c_q[keep], d=d_q[keep], states=ss.states[:r],
                      state_units=ss.state_units[:r], inputs=ss.inputs,
                      input_units=ss.input_units,
                      outputs=tuple(ss.outputs[i] for i in keep),
                      output_units=tuple(ss.output_units[i] for i in keep),
                      notes={**ss.notes, "wing": "antisymmetric modes residualised (QSD)"})


def coupled_mode_set(ss: StateSpace, rigid: StateSpace, wing: AntisymmetricWing) -> ModeSet:
    """The labelled modes of a coupled lateral model ``ss``: each root matched to the
    nearest of the uncoupled references (the rigid model's roll, spiral, Dutch roll; each
    antisymmetric mode's −ζω ± iω√(1 − ζ²), ``antisymmetric_k``) by a least-distance
    assignment (valid while the coupling moves a root less than the distance between
    references: checked at the speeds of tests/test_lateral.py)."""
    lam = np.linalg.eigvals(ss.a)
    ref_rigid = np.linalg.eigvals(rigid.a)
    labels = list(lateral_mode_labels(ref_rigid, float(rigid.a[1, 1])))
    refs = list(ref_rigid)
    for k, (w, z) in enumerate(zip(wing.modes.frequencies_rad_s, wing.modes.damping_ratios,
                                   strict=True)):
        root = complex(-z * w, w * np.sqrt(max(1.0 - z * z, 0.0)))
        refs += [root, root.conjugate()]
        labels += [f"{ANTISYMMETRIC_PREFIX}{k + 1}"] * 2
    cost = np.abs(np.subtract.outer(lam, np.array(refs)))
    rows, cols = linear_sum_assignment(cost)
    named = [""] * lam.size
    for r, c in zip(rows, cols, strict=True):
        named[r] = labels[c]
    order = ["roll", "spiral", "dutch_roll"] + sorted(
        {x for x in labels if x.startswith(ANTISYMMETRIC_PREFIX)},
        key=lambda s: int(s.rsplit("_", 1)[1]))
    modes: list[Mode] = []
    for name in order:
        roots = [lam[k] for k in range(lam.size) if named[k] == name]
        cplx = [r for r in roots if abs(r.imag) > IMAG_TOL_RAD_S]
        if cplx:
            r = max(cplx, key=lambda z: z.imag)
            modes.append(Mode(name, float(r.real), float(abs(r.imag))))
        else:
            modes.extend(Mode(name, float(r.real), 0.0) for r in sorted(roots,
                                                                        key=lambda z: z.real))
    return ModeSet(float(ss.speed_m_s), ss.model, tuple(modes))


def with_density(trim: LateralTrim, density_kg_m3: float) -> LateralTrim:
    """``trim`` at another air density [kg/m³] (the derivatives unchanged): for the
    checks of the coupling's limits."""
    return replace(trim, density_kg_m3=float(density_kg_m3))
