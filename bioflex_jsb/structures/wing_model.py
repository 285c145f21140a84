"""The prototype's half wing as a beam: modes, calibration and the Table 2 comparison.

Pure numerics (no I/O). :func:`wing_modes` is what the rest of bioflex-jsb calls to get the
default modal data; :func:`calibrate_stiffness` is how the stiffnesses of
:mod:`bioflex_jsb.parameters.wing_structure` were obtained; :func:`table2_comparison` puts
the beam's frequencies and generalised masses beside Table 2.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.wing_structure import (
    FIRST_BENDING_OVER_MODE_3,
    RIBBED_WING,
    UNRIBBED_WING,
    WingStructure,
)
from bioflex_jsb.structures.beam import (
    DEFAULT_N_ELEMENTS,
    BeamSections,
    beam_modes,
    solve_beam,
    wing_from_membrane,
)
from bioflex_jsb.structures.modal_data import ModalData
from bioflex_jsb.structures.sections import open_section_torsional_stiffness_n_m2

# A mode is "twist-dominated" when more than half of its strain energy is torsional.
TWIST_DOMINATED_ENERGY_FRACTION = 0.5  # definition (docs/structures.md)


def wing_sections(
    structure: WingStructure = RIBBED_WING,
    *,
    x_inertial_frac: float | None = None,
    x_elastic_frac: float | None = None,
    n_stations: int = 41,
) -> BeamSections:
    """Beam sections of ``structure``; axis overrides as in :func:`wing_from_membrane`."""
    return wing_from_membrane(
        semispan_m=structure.semispan_m,
        chord_m=structure.chord_m,
        layup=structure.layup,
        ribs=structure.ribs,
        torsional_stiffness_root_n_m2=structure.torsional_stiffness_root_n_m2,
        torsional_stiffness_tip_ratio=structure.torsional_stiffness_tip_ratio,
        bending_stiffness_n_m2=structure.bending_stiffness_n_m2,
        x_inertial_frac=x_inertial_frac,
        x_elastic_frac=x_elastic_frac,
        n_stations=n_stations,
        description=structure.name,
        hand_start_m=structure.hand_start_m,
        torsional_stiffness_kink_ratio=structure.torsional_stiffness_kink_ratio,
        hand_inertia_ratio=structure.hand_inertia_ratio,
    )


def wing_modes(
    structure: WingStructure = RIBBED_WING,
    n_modes: int = 3,
    *,
    x_inertial_frac: float | None = None,
    x_elastic_frac: float | None = None,
    n_elements: int = DEFAULT_N_ELEMENTS,
    damping_ratio: float = P.STRUCTURAL_DAMPING_RATIO,
) -> ModalData:
    """Normalised modes of the half wing (default: the ribbed original wing, 3 modes)."""
    sections = wing_sections(
        structure, x_inertial_frac=x_inertial_frac, x_elastic_frac=x_elastic_frac
    )
    return beam_modes(
        sections,
        n_modes,
        n_elements=n_elements,
        damping_ratio=damping_ratio,
        notes=f"calibrated to {structure.calibrated_to}",
    )


# ------------------------------------------------------------------------------------------
# Calibration
# ------------------------------------------------------------------------------------------
def _split_modes(structure: WingStructure, n_modes: int, n_elements: int):
    """Frequencies [Hz] of the torsion-dominated and bending-dominated modes (sorted)."""
    sol = solve_beam(wing_sections(structure), n_modes, n_elements)
    f = sol.frequencies_rad_s / (2.0 * np.pi)
    tors = sol.torsion_energy_fraction > TWIST_DOMINATED_ENERGY_FRACTION
    return f[tors], f[~tors]


@dataclass(frozen=True)
class StiffnessCalibration:
    """Result of :func:`calibrate_stiffness` (values to copy into ``wing_structure``).

    ``torsional_stiffness_tip_ratio`` is the effective tip/root GJ ratio (for the arm/hand
    wing: the membrane floor / root). ``torsional_stiffness_kink_ratio`` and
    ``hand_inertia_ratio`` are ``None`` / 1 for the linear taper.
    """

    torsional_stiffness_root_n_m2: float
    torsional_stiffness_tip_ratio: float
    bending_stiffness_n_m2: float
    torsional_stiffness_kink_ratio: float | None = None
    hand_inertia_ratio: float = 1.0


# Pure bending must stay out of the way of the torsion modes while solving for GJ.
_STIFF_BENDING_N_M2 = 1e9  # ESTIMATE: puts first bending above 1e4 Hz (x_I = x_E: uncoupled)


def calibrate_bending_stiffness(
    structure: WingStructure, target_hz: float, *, n_elements: int = DEFAULT_N_ELEMENTS
) -> float:
    """EI [N·m²] that puts the first bending-dominated mode of ``structure`` at ``target_hz``.

    f_B1 ∝ √EI (uniform EI, x_I = x_E): exact in one step, a second pass checks it.
    """
    ei = structure.bending_stiffness_n_m2
    for _ in range(2):
        _, fb = _split_modes(replace(structure, bending_stiffness_n_m2=ei), 6, n_elements)
        ei *= (target_hz / fb[0]) ** 2
    return float(ei)


def _calibrate_arm_hand(structure: WingStructure, targets: tuple[float, float, float],
                        n_elements: int) -> WingStructure:
    """GJ root, kink ratio and hand inertia ratio that put torsion 1–3 on ``targets``.

    Tip GJ = the membrane's open-section floor (``torsional_stiffness_tip_ratio=None``).
    Three equations, three unknowns: :func:`scipy.optimize.least_squares` on the relative
    errors, unknowns in log form (all positive). The start (uniform GJ, no kink, h = 1) is
    deliberately far from the answer; the residual at the solution is checked.
    """
    stiff = replace(structure, bending_stiffness_n_m2=_STIFF_BENDING_N_M2,
                    torsional_stiffness_tip_ratio=None)
    target = np.asarray(targets, dtype=float)

    def build(p: np.ndarray) -> WingStructure:
        return replace(stiff, torsional_stiffness_root_n_m2=float(np.exp(p[0])),
                       torsional_stiffness_kink_ratio=float(np.exp(p[1])),
                       hand_inertia_ratio=float(np.exp(p[2])))

    def residual(p: np.ndarray) -> np.ndarray:
        ft, _ = _split_modes(build(p), 3, n_elements)
        return ft[:3] / target - 1.0

    # Start: root GJ of the linear-taper fit order of magnitude, kink at 0.3, h = 1.
    p0 = np.log([3.0, 0.3, 1.0])
    from scipy.optimize import least_squares  # calibration only: imported when run

    sol = least_squares(residual, p0, x_scale=1.0, xtol=1e-13, ftol=1e-13, gtol=1e-13,
                        bounds=(np.log([1e-2, 1e-3, 0.05]), np.log([1e3, 1.0, 2.0])))
    # 1e-8 relative: a converged square system solves to round-off; a miss is far larger.
    if np.max(np.abs(sol.fun)) > 1e-8:
        raise RuntimeError(f"arm/hand calibration did not converge: errors {sol.fun}")
    return replace(build(sol.x), bending_stiffness_n_m2=structure.bending_stiffness_n_m2)


def calibrate_stiffness(
    structure: WingStructure,
    torsion_targets_hz: tuple[float, ...],
    bending_target_hz: float | None = None,
    *,
    n_elements: int = DEFAULT_N_ELEMENTS,
) -> StiffnessCalibration:
    """Stiffnesses (and hand inertia) that put the torsion modes (and first bending) on target.

    Requires x_I = x_E (the layup's own axes), so that bending and torsion are uncoupled.

    Two targets (linear GJ taper, ``structure.hand_start_m`` ignored):

    * the taper ratio GJ_tip/GJ_root alone sets f_T2/f_T1 (root value scales both): solved
      with Brent's method on [1e-4, 1];
    * then f ∝ √GJ_root gives the root value in one step.

    Three targets (arm/hand wing, ``structure.hand_start_m`` set): GJ root, GJ kink ratio and
    hand inertia ratio h with the tip GJ at the membrane floor (:func:`_calibrate_arm_hand`).

    ``bending_target_hz``: f_B1 ∝ √EI gives EI in one step on the calibrated structure (kept
    from ``structure`` when ``None``).
    """
    targets = tuple(float(f) for f in torsion_targets_hz)
    if len(targets) == 3:
        if structure.hand_start_m is None:
            raise ValueError("calibrate_stiffness: three targets need structure.hand_start_m")
        fit = _calibrate_arm_hand(structure, targets, n_elements)
        ei = structure.bending_stiffness_n_m2
        if bending_target_hz is not None:
            ei = calibrate_bending_stiffness(fit, bending_target_hz, n_elements=n_elements)
        floor = open_section_torsional_stiffness_n_m2(structure.layup, structure.chord_m)
        return StiffnessCalibration(
            fit.torsional_stiffness_root_n_m2, floor / fit.torsional_stiffness_root_n_m2, ei,
            fit.torsional_stiffness_kink_ratio, fit.hand_inertia_ratio)
    if len(targets) != 2:
        raise ValueError("calibrate_stiffness: give two (linear taper) or three (arm/hand) "
                         "torsion targets")
    f1, f2 = targets
    linear = replace(structure, hand_start_m=None, torsional_stiffness_kink_ratio=None,
                     hand_inertia_ratio=1.0)
    stiff = replace(linear, bending_stiffness_n_m2=_STIFF_BENDING_N_M2)

    def ratio_error(ratio: float) -> float:
        ft, _ = _split_modes(replace(stiff, torsional_stiffness_tip_ratio=ratio), 2, n_elements)
        return ft[1] / ft[0] - f2 / f1

    from scipy.optimize import brentq  # calibration only: imported when run

    ratio = brentq(ratio_error, 1e-4, 1.0, xtol=1e-10, rtol=1e-10)
    ft, _ = _split_modes(replace(stiff, torsional_stiffness_tip_ratio=ratio), 2, n_elements)
    root = stiff.torsional_stiffness_root_n_m2 * (f1 / ft[0]) ** 2
    ei = structure.bending_stiffness_n_m2
    if bending_target_hz is not None:
        probe = replace(linear, torsional_stiffness_root_n_m2=root,
                        torsional_stiffness_tip_ratio=ratio)
        ei = calibrate_bending_stiffness(probe, bending_target_hz, n_elements=n_elements)
    return StiffnessCalibration(root, ratio, ei)


def calibrate_default_wings(n_elements: int = DEFAULT_N_ELEMENTS):
    """Recompute the calibrated numbers of ``wing_structure`` (ribbed, then unribbed).

    * EI: first bending of the ribbed wing with UNIFORM mass (h = 1, the membrane + rib
      estimate) at FIRST_BENDING_OVER_MODE_3 × 107.2 Hz (x_I = x_E: GJ does not enter). The
      lighter hand of the calibrated wing then puts its first bending higher.
    * ribbed: arm/hand GJ and hand inertia ratio on all three Table 2 "with ribs" modes;
    * unribbed: linear GJ taper on modes 1–2 of Table 2 "without ribs" (mode 3 predicted).
    """
    f_r = P.MODE_FREQUENCIES_RIBS_HZ
    f_n = P.MODE_FREQUENCIES_NO_RIBS_HZ
    first_bending_hz = FIRST_BENDING_OVER_MODE_3 * f_r[2]  # ESTIMATE factor (wing_structure)
    uniform_mass = replace(RIBBED_WING, hand_inertia_ratio=1.0)
    ei = calibrate_bending_stiffness(uniform_mass, first_bending_hz, n_elements=n_elements)
    ribbed = calibrate_stiffness(replace(RIBBED_WING, bending_stiffness_n_m2=ei), f_r, None,
                                 n_elements=n_elements)
    unribbed_structure = replace(UNRIBBED_WING, bending_stiffness_n_m2=ei)
    unribbed = calibrate_stiffness(unribbed_structure, (f_n[0], f_n[1]), None,
                                   n_elements=n_elements)
    return ribbed, unribbed


# ------------------------------------------------------------------------------------------
# Table 2 comparison
# ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Table2Row:
    """One mode: model vs Table 2 (frequencies [Hz], generalised masses [kg·m²])."""

    mode: int
    kind: str
    model_frequency_hz: float
    paper_frequency_hz: float
    model_generalised_mass_kg_m2: float
    paper_generalised_mass_kg_m2: float
    torsion_energy_fraction: float
    twist_free: bool

    @property
    def frequency_error(self) -> float:
        """Relative frequency error (model − paper)/paper [-]."""
        return self.model_frequency_hz / self.paper_frequency_hz - 1.0


def table2_comparison(ribs: bool = True, n_elements: int = DEFAULT_N_ELEMENTS) -> list[Table2Row]:
    """Rows for the three modes of Table 2 (``ribs`` selects the column)."""
    structure = RIBBED_WING if ribs else UNRIBBED_WING
    paper_f = P.MODE_FREQUENCIES_RIBS_HZ if ribs else P.MODE_FREQUENCIES_NO_RIBS_HZ
    paper_m = P.GENERALISED_MASSES_RIBS_KG_M2 if ribs else P.GENERALISED_MASSES_NO_RIBS_KG_M2
    sol = solve_beam(wing_sections(structure), 3, n_elements)
    modes = wing_modes(structure, 3, n_elements=n_elements)
    free = modes.twist_free()
    rows = []
    n_t = n_b = 0
    for i in range(3):
        frac = float(sol.torsion_energy_fraction[i])
        if frac > TWIST_DOMINATED_ENERGY_FRACTION:
            n_t += 1
            kind = f"torsion {n_t}"
        else:
            n_b += 1
            kind = f"bending {n_b}"
        rows.append(Table2Row(i + 1, kind, float(modes.frequencies_hz[i]), paper_f[i],
                              float(modes.generalised_masses_kg_m2[i]), paper_m[i], frac,
                              bool(free[i])))
    return rows


def table2_report(n_elements: int = DEFAULT_N_ELEMENTS) -> str:
    """Plain-text table of :func:`table2_comparison` for both columns (for docs and reports)."""
    lines = ["column     mode kind        f model  f Table2  error    m_i model  m_i Table2"]
    for ribs in (True, False):
        for r in table2_comparison(ribs, n_elements):
            note = " (no twist: scaled on tip deflection)" if r.twist_free else ""
            lines.append(
                f"{'ribs' if ribs else 'no ribs':10s} {r.mode:4d} {r.kind:11s} "
                f"{r.model_frequency_hz:8.2f} {r.paper_frequency_hz:8.1f} "
                f"{100 * r.frequency_error:+6.2f}%  {r.model_generalised_mass_kg_m2:9.3e} "
                f"{r.paper_generalised_mass_kg_m2:9.3e}{note}"
            )
    return "\n".join(lines)


def tip_bending_twist_ratio_m(modes: ModalData, mode: int = 0) -> float:
    """φ(tip)/θ(tip) of one mode [m/rad]: positive = elastic axis down when the LE twists up."""
    return float(modes.bending_m[mode, -1] / modes.twist_rad[mode, -1])


EXAMPLE_FILE_HEADER = """Example modal-data file (docs/structures.md, "Modal-data files")
The three modes of the default ribbed half wing (beam model, bioflex_jsb.structures.wing_model),
at 11 stations, lengths in mm to show the unit conversion. Starboard half wing, root clamped.
bending: elastic-axis displacement per unit modal coordinate, positive DOWN.
twist: section twist per unit modal coordinate, positive LEADING EDGE UP.
generalised_mass: half wing, for the shapes as written [kg*m^2].
Modes 1-3 are pure torsion (x_I = x_E): their bending is zero.
Regenerate: python -c "from bioflex_jsb.structures.wing_model import write_example_file as w; w()"
"""


def example_modes(n_stations: int = 11) -> ModalData:
    """The modes shipped in ``bioflex_jsb/data/modes/example_ribbed.toml`` (ribbed wing)."""
    sections = wing_sections(RIBBED_WING)
    return beam_modes(
        sections,
        3,
        stations_m=np.linspace(0.0, RIBBED_WING.semispan_m, n_stations),
        notes=f"calibrated to {RIBBED_WING.calibrated_to}",
    )


def write_example_file(path=None) -> None:
    """Regenerate the shipped example file (the one function here that writes a file)."""
    from pathlib import Path

    from bioflex_jsb.structures.modal_file import write_modal_file

    target = Path(path) if path else Path(__file__).parents[1] / "data/modes/example_ribbed.toml"
    write_modal_file(target, example_modes(), length="mm", header=EXAMPLE_FILE_HEADER)
