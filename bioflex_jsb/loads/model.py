"""Section loads of the elastic half wing at monitoring stations (pure numerics, no I/O).

Two methods, side by side (docs/loads.md):

* **force summation** (FS): the strip loads of the wing outboard of a station, aerodynamic
  (the co-simulation's strip model, the gust included) plus inertial (the wing's mass under
  the rigid-body and modal accelerations, gravity included), summed to the station;
* **mode displacement** (MD): the beam's stress resultants of the modal deflection,
  M = −EI Σ φ_i'' η_i, T = GJ Σ θ_i' η_i, V = EI Σ φ_i''' η_i (from the beam's finite
  elements, :mod:`bioflex_jsb.structures.beam`).

Frames and signs (``docs/conventions.md``; wing frame x aft of the root leading edge, y to
starboard, z up). At a station y_s, for the starboard wing outboard of it:

* shear V(y_s) = ∫_{y_s}^{b/2} f dy [N], f the net upward load per span: positive **up**;
* bending moment M(y_s) = ∫_{y_s}^{b/2} (y − y_s) f dy [N·m]: positive **tip up** (upper
  surface in compression), the moment of the upward loads about the station's x-axis;
* torque T(y_s) = ∫_{y_s}^{b/2} t dy [N·m], t the section torque per span about the local
  elastic axis: positive **leading edge up** (the twist's sign). The structure is the straight
  beam of ``structures/beam.py`` (the outer panel's sweep is neglected for the structure, as
  there), so torque is taken about the local elastic axis of each section.

Loads per unit span (Q dynamic pressure [Pa], V airspeed [m/s]):

* aerodynamic, the co-simulation's strips (Table B1, ``modal_coefficients``): lift
  l = Q C_lα c α_s, with the strip's angle from zero lift
  α_s = α_w + Δα_trim + Δα − d q/V + Σ θ_i η_i + Σ φ_i η̇_i / V
  (α_w = C_L0/C_Lα,w the wing's trim angle, Δα the aerodynamic angle of attack from the run,
  the gust included, d the aerodynamic centre ahead of the CG, η the total deflection, static
  η₀ plus the perturbation), constant over each lattice strip (the lattice's own loading);
  torque l·e + Q c² C_mac about the elastic axis, e the offset of the aerodynamic centre
  ahead of it, shifted as the wing's C_η1^Q1 pin shifts it (``WingBuild.e_shift_frac``);
* inertial and gravity: a point at x moves up with n_z g − q̇ (x − x_cg) − Σ(φ_i + (x − x_E)
  θ_i) η̈_i including gravity (n_z the load factor at the CG, positive up; q̇ the pitch
  acceleration, nose up), so f = −m' n_z g + m' (x_I − x_cg) q̇ + Σ (m' φ_i + S' θ_i) η̈_i and
  t = S' n_z g − (I' + S'(x_E − x_cg)) q̇ − Σ (S' φ_i + I' θ_i) η̈_i, with m', S', I' the
  beam's mass, static moment and torsional inertia about the elastic axis per span; a
  beam's point mass M (its centre of mass d aft of the elastic axis, its own pitch inertia
  I_cg) adds the same terms concentrated at its station, with M, M d, I_cg + M d².
  Centripetal terms (q²) and the chordwise loads are left out; a strut-braced beam has no
  force summation (the strut's reaction k w is not a signal of z).

Every FS load is linear in one signal vector z (:data:`SIGNALS`), so a
:class:`LoadsModel` holds one matrix and the LTI model's loads outputs follow from it
(:mod:`bioflex_jsb.loads.lti`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from bioflex_jsb.definition.model import DEFAULT_MONITORING_STATIONS
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.modal_coefficients import shifted, spanwise_geometry
from bioflex_jsb.flight_dynamics.modal_matrices import ModalMatrices, modal_matrices
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.parameters import constants as C

# root, 25, 50, 75 % semispan: a definition's default [loads] stations
DEFAULT_STATION_FRACTIONS = DEFAULT_MONITORING_STATIONS
QUANTITIES = ("shear_n", "bending_n_m", "torque_n_m")
QUANTITY_UNITS = {"shear_n": "N", "bending_n_m": "N*m", "torque_n_m": "N*m"}
METHODS = ("force_summation", "mode_displacement")
# NUMERICAL: widest integration cell of the force summation [m]. Strip loads are constant per
# lattice strip (exact), the beam's m', S', I' linear per section interval (midpoint rule
# exact); only the moment arm times the mode shapes' curvature is left, O(h²): at 2 mm the
# root bending moment of the 1 g case moves by < 1e-6 relative against 0.5 mm (measured).
CELL_WIDTH_M = 0.002
# NUMERICAL: the raw beam eigenvectors are matched to the normalised modes of the WingBuild
# by one scale factor per mode; the fit's residual must be below this (round-off is ~1e-14).
SCALE_FIT_TOLERANCE = 1e-8


def signal_names(n_modes: int) -> tuple[str, ...]:
    """Names of the signal vector z that the force summation is linear in (units in each):
    Q·α_s,rigid [Pa·rad], Q·q/V [Pa·rad/m], Q·η_i [Pa·rad], Q·η̇_i/V [Pa·rad/m], Q [Pa],
    g·n_z [m/s²], q̇ [rad/s²], η̈_i [rad/s²]."""
    eta = tuple(f"Q*eta{i + 1}" for i in range(n_modes))
    eta_dot = tuple(f"Q*eta{i + 1}_dot/V" for i in range(n_modes))
    acc = tuple(f"eta{i + 1}_ddot" for i in range(n_modes))
    return ("Q*alpha_body", "Q*q/V", *eta, *eta_dot, "Q", "g*n_z", "q_dot", *acc)


@dataclass(frozen=True, eq=False)
class LoadsModel:
    """Section loads of one wing at one trim speed, as matrices (module docstring).

    stations_m (s,) [m]; fs_matrix (3 s, len(z)): rows shear, bending, torque of every
    station (quantity-major: row q·s + j), columns the signals z (:func:`signal_names`);
    fs_aero_columns: which columns are aerodynamic (the rest inertial); md_matrix (3 s, n):
    the same rows per unit total deflection η [rad], or None for a wing without EI, GJ (a
    modes file: ``md_unavailable`` says why); ``mass_source``: where the inertia per span
    comes from (the beam, or the fit to a modes file's generalised masses:
    :func:`modal_mass_sections`); static_eta_rad (n,) η₀ and
    static_alpha_rad Δα_trim of the static part; alpha_wing_rad α_w; dynamic_pressure_pa,
    speed_m_s, density_kg_m3 of the trim; matrices: the modal wing's per-unit matrices (the
    modal accelerations by the model); static_note says where the static part comes from.
    """

    wing: str
    stations_m: np.ndarray
    station_fractions: tuple[float, ...]
    speed_m_s: float
    density_kg_m3: float
    dynamic_pressure_pa: float
    cl_trim: float
    alpha_wing_rad: float
    static_eta_rad: np.ndarray
    static_alpha_rad: float
    fs_matrix: np.ndarray
    fs_aero_columns: np.ndarray
    md_matrix: np.ndarray | None
    matrices: ModalMatrices
    n_modes: int
    static_note: str
    half_wing_mass_kg: float
    mass_source: str
    md_unavailable: str | None
    cells_m: np.ndarray = field(repr=False)
    cell_widths_m: np.ndarray = field(repr=False)
    cell_coefficients: tuple[np.ndarray, np.ndarray] = field(repr=False)
    cell_shapes: tuple[np.ndarray, np.ndarray] = field(repr=False)  # (φ, θ) at the cells
    cell_strips: np.ndarray = field(repr=False)  # the lattice strip of each cell
    build: object = field(repr=False)  # the WingBuild (the unsteady wing's strips)
    # a flaperon's loads (loads/flaperon.py: its FS rows and modal forcing), None: none
    flaperon: object = field(default=None, repr=False)

    @property
    def n_stations(self) -> int:
        return int(self.stations_m.size)

    def rows(self) -> list[tuple[str, int]]:
        """(quantity, station index) of each matrix row."""
        return [(q, j) for q in QUANTITIES for j in range(self.n_stations)]

    def static_signals(self) -> np.ndarray:
        """z at the static 1 g trim: zero perturbation, η = η₀ (for :meth:`force_summation`)."""
        n = self.n_modes
        q0 = self.dynamic_pressure_pa
        z = np.zeros(5 + 3 * n)
        z[0] = q0 * (self.alpha_wing_rad + self.static_alpha_rad)
        z[2:2 + n] = q0 * self.static_eta_rad
        z[2 + 2 * n] = q0
        z[3 + 2 * n] = C.STANDARD_GRAVITY_M_S2
        return z

    def force_summation(self, z: np.ndarray, part: str = "total") -> np.ndarray:
        """FS loads (3 s,) or (samples, 3 s) for signals z (…, len(z)); ``part``:
        ``total``, ``aero`` or ``inertia``."""
        k = self.fs_matrix
        if part != "total":
            mask = self.fs_aero_columns if part == "aero" else ~self.fs_aero_columns
            k = np.where(mask[None, :], k, 0.0)
        return np.asarray(z) @ k.T

    def mode_displacement(self, eta_total_rad: np.ndarray) -> np.ndarray:
        """MD loads (3 s,) or (samples, 3 s) of the total deflection η [rad]."""
        if self.md_matrix is None:
            raise InputError(f"wing {self.wing!r}: {self.md_unavailable}")
        return np.asarray(eta_total_rad) @ self.md_matrix.T

    @property
    def methods(self) -> tuple[str, ...]:
        """The methods this model gives (:data:`METHODS` order): no mode displacement
        without the beam's EI, GJ."""
        return METHODS if self.md_matrix is not None else ("force_summation",)

    def static_loads(self) -> dict[str, np.ndarray]:
        """The 1 g trim's loads {method: (3, s)} (quantity rows, station columns), for
        :attr:`methods`."""
        z = self.static_signals()
        s = self.n_stations
        out = {"force_summation": self.force_summation(z).reshape(3, s)}
        if self.md_matrix is not None:
            out["mode_displacement"] = self.mode_displacement(self.static_eta_rad).reshape(3, s)
        return out

    def generalised_aero_force(self, z: np.ndarray) -> np.ndarray:
        """Generalised force of the FS **aerodynamic** loads of the half wing on each mode,
        ∫ (−φ_i f + θ_i t) dy [N·m per rad of η_i] (φ down, f up: work of the loads)."""
        f_coef, t_coef = self.cell_coefficients
        mask = self.fs_aero_columns
        f = (np.where(mask, f_coef, 0.0) @ z) * self.cell_widths_m
        t = (np.where(mask, t_coef, 0.0) @ z) * self.cell_widths_m
        phi, theta = self.cell_shapes
        return -phi @ f + theta @ t


def _sections(variant):
    """The beam sections of a beam-model variant (mass, stiffness, point masses): a
    definition's beam wing's own, else the prototype's membrane beam; refused for a modes
    file, and for a beam with struts (the force summation has no signal of the deflection
    itself, which the strut's reaction is)."""
    if variant.beam is not None:
        sections = variant.beam.sections
        if sections.springs:
            raise InputError(
                f"wing {variant.name!r}: section loads of a strut-braced beam are not "
                "modelled (the force summation would leave out the strut's reaction, a load "
                "of the deflection that its signals do not carry)")
        return sections
    if variant.modes_file:
        raise InputError(
            f"wing {variant.name!r}: section loads need the beam's mass and stiffness "
            "(EI, GJ, m', I'), which a modes file does not give; use a beam-model wing "
            "(a named wing, or a variant file without modes_file)")
    from bioflex_jsb.flight_dynamics.wing_model import membrane_structure
    from bioflex_jsb.structures.wing_model import wing_sections

    return wing_sections(membrane_structure(variant),
                         x_inertial_frac=variant.x_inertial_frac,
                         x_elastic_frac=variant.x_elastic_frac)


# ESTIMATE: how closely the uniform m', I' of a modes-file wing must give back each mode's
# generalised mass (:func:`modal_mass_sections`). The fit integrates the file's shapes
# linearly between its stations where the beam's finite elements are Hermite cubics: for
# the SGS wing's 40-element modes that alone leaves 7.4e-4 (modes 1 and 3, measured; mode 2
# to round-off), and m' comes out 7.0045 kg/m against its beam's 7.0 (sgs_wing.toml). A wing
# whose mass is not near uniform misses by far more than 1 % and gets no force summation.
MODAL_MASS_FIT_TOLERANCE = 0.01


@dataclass(frozen=True, eq=False)
class MassSections:
    """The wing's inertia per span for the force summation, at ``stations_m`` [m] (linear
    in between): m' ``mass_per_length_kg_m`` [kg/m], I' ``torsional_inertia_kg_m`` [kg·m]
    about the elastic axis, S' ``static_moment_kg`` = m' (x_I − x_E) c [kg] (positive for
    the centre of mass aft of the elastic axis); the axes as chord fractions aft of the
    leading edge; ``source`` says where the numbers come from. The interface of
    :class:`~bioflex_jsb.structures.beam.BeamSections` that the force summation reads."""

    stations_m: np.ndarray
    mass_per_length_kg_m: np.ndarray
    torsional_inertia_kg_m: np.ndarray
    static_moment_kg: np.ndarray
    x_elastic_frac: np.ndarray
    x_inertial_frac: np.ndarray
    source: str

    @property
    def half_wing_mass_kg(self) -> float:
        """∫ m' dy over the half wing [kg] (trapezoid rule: exact for linear m')."""
        return float(np.trapezoid(self.mass_per_length_kg_m, self.stations_m))

    def at(self, y_m: np.ndarray) -> dict[str, np.ndarray]:
        """m', I', S' linearly interpolated at ``y_m`` (the keys of ``BeamSections.at``)."""
        y = np.asarray(y_m, dtype=float)
        return {"m": np.interp(y, self.stations_m, self.mass_per_length_kg_m),
                "I": np.interp(y, self.stations_m, self.torsional_inertia_kg_m),
                "S": np.interp(y, self.stations_m, self.static_moment_kg)}


def modal_mass_sections(build) -> MassSections:
    """The inertia per span of a modes-file wing (``build.variant.modes_file``).

    A modes file (docs/structures.md) carries the shapes φ_i, θ_i, the frequencies, the
    generalised masses m_i and the axes x_E, x_I, but no mass distribution, no EI and no GJ.
    The force summation takes the **spanwise-uniform** m' and I' (about the elastic axis)
    whose generalised masses m_i = ∫ (m' φ_i² + 2 S' φ_i θ_i + I' θ_i²) dy, S' = m'(x_I −
    x_E) c on the wing's planform, best match the file's (least squares over the modes),
    and refuses the wing (InputError, said why) if a mode's generalised mass is then off by
    more than :data:`MODAL_MASS_FIT_TOLERANCE`, if the modes cannot separate m' from I' (no
    twist, or no bending, in any mode) or if the fit is not physical (m' ≤ 0, I' < m' d²)."""
    modes, planform = build.modes, build.planform
    name = build.variant.name
    y = np.linspace(0.0, float(modes.stations_m[-1]), 4001)  # 1.8 mm on the SGS's 7.04 m
    chord = planform.chord_at(y)
    offset = np.interp(y, modes.stations_m, modes.x_inertial_frac - modes.x_elastic_frac) * chord
    rows = []
    for phi_i, theta_i in zip(modes.bending_m, modes.twist_rad, strict=True):
        phi = np.interp(y, modes.stations_m, phi_i)
        theta = np.interp(y, modes.stations_m, theta_i)
        rows.append([np.trapezoid(phi * phi + 2.0 * offset * phi * theta, y),
                     np.trapezoid(theta * theta, y)])
    a = np.array(rows)
    masses = np.asarray(modes.generalised_masses_kg_m2, dtype=float)
    head = f"wing {name!r} (a modes file: no mass distribution, EI or GJ)"
    if np.linalg.matrix_rank(a, tol=1e-9 * np.max(np.abs(a))) < 2:
        raise InputError(f"{head}: its modes do not give m' and I' apart (they need bending "
                         "and twist); force summation needs them: use a beam-model wing")
    (m_per_length, inertia), *_ = np.linalg.lstsq(a, masses, rcond=None)
    miss = np.abs(a @ np.array([m_per_length, inertia]) / masses - 1.0)
    if m_per_length <= 0.0 or inertia < m_per_length * np.max(offset**2):
        raise InputError(f"{head}: its generalised masses give no physical uniform mass "
                         f"(m' = {m_per_length:.4g} kg/m, I' = {inertia:.4g} kg*m)")
    if np.max(miss) > MODAL_MASS_FIT_TOLERANCE:
        raise InputError(
            f"{head}: a uniform m', I' misses mode {int(np.argmax(miss)) + 1}'s generalised "
            f"mass by {100 * np.max(miss):.1f} % (accepted {100 * MODAL_MASS_FIT_TOLERANCE:g} "
            "%): its mass is not uniform; force summation needs a beam-model wing")
    ys = np.asarray(modes.stations_m, dtype=float)
    d = (modes.x_inertial_frac - modes.x_elastic_frac) * planform.chord_at(ys)
    return MassSections(
        stations_m=ys, mass_per_length_kg_m=np.full(ys.size, m_per_length),
        torsional_inertia_kg_m=np.full(ys.size, inertia),
        static_moment_kg=m_per_length * d, x_elastic_frac=np.asarray(modes.x_elastic_frac),
        x_inertial_frac=np.asarray(modes.x_inertial_frac),
        source=(f"uniform m' = {m_per_length:.5g} kg/m, I' = {inertia:.5g} kg*m fitted to the "
                f"modes file's generalised masses (worst mode {100 * np.max(miss):.2g} % off)"))


MD_UNAVAILABLE_MODES_FILE = ("mode displacement needs the beam's EI and GJ (a modes file "
                             "gives neither): force summation only")


def station_positions_m(fractions, semispan_m: float) -> np.ndarray:
    """Stations [m] from fractions of the semispan; each in [0, 1), strictly increasing."""
    f = np.asarray(tuple(fractions), dtype=float)
    if f.ndim != 1 or f.size == 0 or not np.all(np.isfinite(f)):
        raise InputError("monitoring stations: give one or more fractions of the semispan")
    if np.any(f < 0.0) or np.any(f >= 1.0) or np.any(np.diff(f) <= 0.0):
        raise InputError(f"monitoring stations {f.tolist()}: accepted fractions of the "
                         "semispan 0 <= y/(b/2) < 1, strictly increasing (0 = root)")
    return f * semispan_m


def _cells(breaks: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray]:
    """Midpoints and widths of cells no wider than ``width`` between sorted ``breaks``."""
    mids, widths = [], []
    for a, b in zip(breaks[:-1], breaks[1:], strict=True):
        if b - a <= 1e-12:
            continue
        k = max(1, math.ceil((b - a) / width))
        edges = np.linspace(a, b, k + 1)
        mids.append(0.5 * (edges[:-1] + edges[1:]))
        widths.append(np.diff(edges))
    return np.concatenate(mids), np.concatenate(widths)


def _point_mass_rows(mass, sections, modes, planform, stations_m: np.ndarray,
                     n_signals: int, n: int) -> np.ndarray:
    """(3 s, signals) force-summation rows of a point mass (a beam's ``PointMass``) at the
    stations inboard of it: the distributed inertia's terms (module docstring) with m' → M,
    S' → M d, I' → I_cg + M d² (d its offset aft of the elastic axis), concentrated at y_p;
    its columns are the inertial signals g·n_z, q̇, η̈_i."""
    y = np.array([mass.y_m])
    d = sections.point_mass_offset_m(mass)
    static, inertia = mass.mass_kg * d, mass.pitch_inertia_kg_m2 + mass.mass_kg * d * d
    x_le, chord = float(planform.leading_edge_x_at(y)[0]), float(planform.chord_at(y)[0])
    x_e = x_le + float(np.interp(y, sections.stations_m, sections.x_elastic_frac)[0]) * chord
    arm_cg_i, arm_cg_e = x_e + d - planform.x_cg_m, x_e - planform.x_cg_m
    phi = np.array([np.interp(y, modes.stations_m, b)[0] for b in modes.bending_m])
    theta = np.array([np.interp(y, modes.stations_m, t)[0] for t in modes.twist_rad])
    f, t = np.zeros(n_signals), np.zeros(n_signals)
    first = 3 + 2 * n  # g·n_z, then q̇, then η̈_i (signal_names)
    f[first:] = [-mass.mass_kg, mass.mass_kg * arm_cg_i, *(mass.mass_kg * phi + static * theta)]
    t[first:] = [static, -(inertia + static * arm_cg_e), *(-(static * phi + inertia * theta))]
    inboard = (mass.y_m > stations_m).astype(float)[:, None]
    arm = np.maximum(mass.y_m - stations_m, 0.0)[:, None]
    return np.vstack([inboard * f, inboard * arm * f, inboard * t])


def _md_matrix(sections, modes, stations_m: np.ndarray) -> np.ndarray:
    """(3 s, n) beam stress resultants per unit η_i at the stations (module docstring):
    shear EI φ''' , bending −EI φ'', torque GJ θ' of the FE solution, each mode scaled to the
    WingBuild's normalisation; at an inner node the mean of its two elements."""
    from bioflex_jsb.structures.beam import solve_beam

    n = modes.n_modes
    sol = solve_beam(sections, n, n_elements=_n_elements(modes))
    raw_bend, raw_twist = sol.sample(modes.stations_m)
    nodes = sol.nodes_m
    out = np.zeros((3, stations_m.size, n))
    half = float(modes.stations_m[-1])
    for i in range(n):
        a = np.concatenate([raw_bend[i] / half, raw_twist[i]])
        b = np.concatenate([modes.bending_m[i] / half, modes.twist_rad[i]])
        scale = float(a @ b / (a @ a))
        if np.max(np.abs(scale * a - b)) > SCALE_FIT_TOLERANCE * np.max(np.abs(b)):
            raise RuntimeError(f"beam mode {i + 1} does not match the wing's modes")
        q = np.vstack([np.zeros(3), sol.vectors[:, i].reshape(-1, 3)]) * scale  # (w, w', θ)
        for j, y in enumerate(stations_m):
            values = []
            for e in _elements_at(nodes, y):
                h = nodes[e + 1] - nodes[e]
                xi = (y - nodes[e]) / h
                wv = np.array([q[e, 0], q[e, 1], q[e + 1, 0], q[e + 1, 1]])
                w2 = np.array([(-6 + 12 * xi) / h**2, (-4 + 6 * xi) / h,
                               (6 - 12 * xi) / h**2, (-2 + 6 * xi) / h]) @ wv
                w3 = np.array([12 / h**3, 6 / h**2, -12 / h**3, 6 / h**2]) @ wv
                t1 = (q[e + 1, 2] - q[e, 2]) / h
                values.append((w3, w2, t1))
            w3, w2, t1 = np.mean(values, axis=0)
            props = sections.at(np.array([y]))
            ei, gj = float(props["EI"][0]), float(props["GJ"][0])
            out[:, j, i] = (ei * w3, -ei * w2, gj * t1)
    return out.reshape(3 * stations_m.size, n)


# The MD matrices built so far: the beam's eigen-solution is 90 % of a LoadsModel's cost
# (0.135 of 0.15 s, measured) and depends on the wing's structure, modes and stations only,
# not on the speed or the static part, so the rigid, coupled and qsd runs of one wing (and a
# gust run after its loads post-process) share it. Keyed by the values it is built from;
# at most _MD_CACHE_SIZE entries (≈ 1 kB each), the oldest dropped first.
_MD_CACHE: dict[tuple, np.ndarray] = {}
_MD_CACHE_SIZE = 32


def _md_matrix_cached(sections, modes, stations_m: np.ndarray) -> np.ndarray:
    """:func:`_md_matrix`, memoised on every array it is built from: the beam's sections,
    the modes' samples and the stations (a copy is returned: callers may not change the
    kept one)."""
    arrays = (sections.stations_m, sections.bending_stiffness_n_m2,
              sections.torsional_stiffness_n_m2, sections.mass_per_length_kg_m,
              sections.torsional_inertia_kg_m, sections.chord_m, sections.x_elastic_frac,
              sections.x_inertial_frac, modes.stations_m, modes.bending_m, modes.twist_rad,
              stations_m)
    key = tuple((np.shape(a), np.asarray(a, dtype=float).tobytes()) for a in arrays)
    got = _MD_CACHE.get(key)
    if got is None:
        got = _md_matrix(sections, modes, stations_m)
        if len(_MD_CACHE) >= _MD_CACHE_SIZE:
            _MD_CACHE.pop(next(iter(_MD_CACHE)))
        _MD_CACHE[key] = got
    return got.copy()


def _n_elements(modes) -> int:
    """The FE mesh of the beam modes: their stations are the nodes (``beam_modes``)."""
    return int(modes.stations_m.size - 1)


def _elements_at(nodes: np.ndarray, y: float) -> list[int]:
    """The element(s) whose closure holds ``y``: two at an inner node, one elsewhere."""
    tol = 1e-9 * nodes[-1]
    hit = np.flatnonzero(np.abs(nodes - y) <= tol)
    if hit.size:
        k = int(hit[0])
        return [e for e in (k - 1, k) if 0 <= e < nodes.size - 1]
    return [int(np.clip(np.searchsorted(nodes, y) - 1, 0, nodes.size - 2))]


def build_loads_model(build, speed_m_s: float, stations=None, *,
                      density_kg_m3: float = C.SEA_LEVEL_DENSITY_KG_M3,
                      static: str = "elastic") -> LoadsModel:
    """The :class:`LoadsModel` of ``build`` (a :class:`~bioflex_jsb.flight_dynamics.
    wing_model.WingBuild`: the prototype's or a definition's wing, on its own planform,
    lattice strips and airframe) at the level-flight trim ``speed_m_s``. A beam-model wing
    gets both methods; a modes-file wing force summation only, with the uniform inertia
    fitted to its generalised masses (:func:`modal_mass_sections`; InputError if that fit
    fails).

    ``stations``: fractions of the semispan (None: the wing's own,
    ``build.monitoring_stations``, an aircraft definition's ``[loads] stations``, else
    :data:`DEFAULT_STATION_FRACTIONS`). ``static``: the 1 g static part,
    ``elastic`` (the elastic trim's η₀ and Δα, :mod:`bioflex_jsb.flight_dynamics.
    elastic_trim`: the deformed wing the rigid reading's airframe carries) or ``rigid``
    (η₀ = 0: the undeformed wing at the rigid trim). ``elastic`` beyond the wing's static
    divergence speed is refused (InputError from the elastic trim)."""
    if static not in ("elastic", "rigid"):
        raise InputError(f"unknown static part {static!r}; accepted: elastic, rigid")
    if stations is None:
        stations = getattr(build, "monitoring_stations", None) or DEFAULT_STATION_FRACTIONS
    variant, modes, aero = build.variant, build.modes, build.aero
    planform = build.planform
    if abs(aero.semispan_m - planform.semispan_m) > 1e-9 * planform.semispan_m:
        raise RuntimeError(f"the wing's lattice spans {aero.semispan_m:g} m, its planform "
                           f"{planform.semispan_m:g} m")
    if variant.modes_file:
        sections = modal_mass_sections(build)
        md_unavailable = MD_UNAVAILABLE_MODES_FILE
        mass_source = sections.source
    else:
        sections = _sections(variant)
        md_unavailable = None
        mass_source = ("the beam's sections (the definition's [structure])"
                       if variant.beam is not None
                       else "the beam's sections (structures/wing_model.py)")
    half = planform.semispan_m
    ys = station_positions_m(stations, half)
    condition = level_flight_condition(float(speed_m_s), density_kg_m3,
                                       airframe=build.airframe)
    q0 = condition.dynamic_pressure_pa
    n = modes.n_modes
    strips = shifted(spanwise_geometry(aero, planform, modes.x_elastic_frac, modes.stations_m),
                     build.e_shift_frac * planform.chord_m)
    breaks = np.unique(np.concatenate([aero.edges_m, sections.stations_m, ys, [half]]))
    yc, wc = _cells(breaks, CELL_WIDTH_M)
    strip = np.clip(np.searchsorted(aero.edges_m, yc, side="right") - 1, 0, aero.edges_m.size - 2)
    clac, e, d, c = (strips.cl_alpha_c_m[strip], strips.e_m[strip], strips.d_m[strip],
                     strips.chord_m[strip])
    # α of a strip is imposed at its control point: mode shapes at the strips' stations
    phi_s = np.array([np.interp(strips.stations_m, modes.stations_m, b) for b in modes.bending_m])
    theta_s = np.array([np.interp(strips.stations_m, modes.stations_m, t)
                        for t in modes.twist_rad])
    phi_a, theta_a = phi_s[:, strip], theta_s[:, strip]  # (n, cells)
    # inertia at the cells: the beam's sections and the shapes at the cells
    props = sections.at(yc)
    m, s_a, i_a = props["m"], props["S"], props["I"]
    phi_c = np.array([np.interp(yc, modes.stations_m, b) for b in modes.bending_m])
    theta_c = np.array([np.interp(yc, modes.stations_m, t) for t in modes.twist_rad])
    x_le = planform.leading_edge_x_at(yc)
    chord = planform.chord_at(yc)
    x_e = x_le + np.interp(yc, sections.stations_m, sections.x_elastic_frac) * chord
    x_i = x_le + np.interp(yc, sections.stations_m, sections.x_inertial_frac) * chord
    arm_cg_i, arm_cg_e = x_i - planform.x_cg_m, x_e - planform.x_cg_m
    zeros = np.zeros_like(yc)
    # per-cell load per span and unit signal: columns as signal_names(n)
    f_cols = [clac, -clac * d, *(clac * theta_a), *(clac * phi_a), zeros, -m, m * arm_cg_i,
              *(m * phi_c + s_a * theta_c)]
    t_cols = [clac * e, -clac * d * e, *(clac * e * theta_a), *(clac * e * phi_a),
              c**2 * build.model.cm_ac, s_a, -(i_a + s_a * arm_cg_e),
              *(-(s_a * phi_c + i_a * theta_c))]
    f_coef, t_coef = np.column_stack(f_cols), np.column_stack(t_cols)
    aero_cols = np.zeros(f_coef.shape[1], dtype=bool)
    aero_cols[:3 + 2 * n] = True
    out = yc[None, :] > ys[:, None]  # cells outboard of each station (stations are breaks)
    a_v = out * wc[None, :]
    a_m = a_v * (yc[None, :] - ys[:, None])
    fs = np.vstack([a_v @ f_coef, a_m @ f_coef, a_v @ t_coef])
    for mass in getattr(sections, "point_masses", ()):
        fs += _point_mass_rows(mass, sections, modes, planform, ys, fs.shape[1], n)
    if static == "elastic":
        from bioflex_jsb.flight_dynamics.elastic_trim import elastic_trim

        trim = elastic_trim(build, float(speed_m_s), density_kg_m3=density_kg_m3)
        eta0, dalpha0 = np.asarray(trim.eta_rad, dtype=float), trim.delta_alpha_rad
        note = (f"elastic trim at {speed_m_s:g} m/s (flight_dynamics/elastic_trim.py): "
                f"eta0 = {np.round(eta0, 5).tolist()} rad, delta alpha {dalpha0:.5f} rad")
    else:
        eta0, dalpha0 = np.zeros(n), 0.0
        note = "rigid trim: undeformed wing (eta0 = 0)"
    return LoadsModel(
        wing=variant.name, stations_m=ys, station_fractions=tuple(float(x) for x in ys / half),
        speed_m_s=float(speed_m_s), density_kg_m3=float(density_kg_m3), dynamic_pressure_pa=q0,
        cl_trim=condition.cl_trim,
        alpha_wing_rad=condition.cl_trim / build.model.wing_lift_slope_per_rad,
        static_eta_rad=eta0, static_alpha_rad=float(dalpha0), fs_matrix=fs,
        fs_aero_columns=aero_cols,
        md_matrix=None if md_unavailable else _md_matrix_cached(sections, modes, ys),
        matrices=modal_matrices(build.model, condition.cl_trim), n_modes=n,
        static_note=note, half_wing_mass_kg=sections.half_wing_mass_kg,
        mass_source=mass_source, md_unavailable=md_unavailable,
        cells_m=yc, cell_widths_m=wc, cell_coefficients=(f_coef, t_coef),
        cell_shapes=(phi_c, theta_c), cell_strips=strip, build=build)
