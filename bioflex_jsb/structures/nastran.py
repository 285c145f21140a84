"""A finite-element modal deck (Nastran SOL 103 output, OP2) as the wing's modal data.

Reading: :func:`read_op2_modes` reads an OP2 file written with ``PARAM,POST,-1`` (its
eigenvalue table LAMA, the eigenvectors OUGV1/BOPHIG, the grids' positions and output
frames) with ``pyyeti`` (the optional extra ``pip install ".[nastran]"``: pyyeti reads OP2
files with numpy 2; pyNastran's released versions pin numpy < 2) and keeps the grids the
user names, in the order named (root to tip), as :class:`FEModes`: positions in the basic
frame, the six displacements of each grid per mode in the basic frame, frequencies and
generalised masses, all in the deck's own units.

Mapping (:func:`fe_modal_data`, no I/O, pure numpy; docs/structures.md "From a Nastran
deck"): the named grids are the wing's reference line (the elastic axis, or any spanwise
line whose chord fraction the modal data's ``x_elastic_frac`` then states), root first.
With the deck's axes ``span`` (root to tip), ``up`` and ``aft`` given as ±x, ±y, ±z of its
basic frame:

* stations y_k = (p_k − p_0)·ŝ [m], the first grid being the clamped root (y = 0);
* bending φ = −T·û [m per unit η] (positive down: docs/structures.md);
* twist θ = h (R·ŝ) [rad per unit η], h = (â × ŝ)·û = ±1 (positive leading edge up: a
  rotation about ŝ that moves the trailing edge down; h = −1 for a port wing in a
  right-handed frame);
* frequencies from LAMA [rad/s]; generalised masses (LAMA's, of the deck's half wing
  clamped at its root, for the shapes as written) in SI: × mass unit × length unit².

The result is normalised as every :class:`~bioflex_jsb.structures.modal_data.ModalData`
(docs/structures.md) and may be written as a modal file (:func:`write_op2_modal_file`,
``modal_file.write_modal_file``), which a definition's ``kind = "modal"`` flies.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bioflex_jsb.errors import InputError
from bioflex_jsb.files import open_input
from bioflex_jsb.structures.modal_data import ModalData, ModalDataError

# The deck's units in SI. Length: the grids' coordinates and translations. Mass: the mass
# unit of its generalised masses (a model in lbf-s^2/in with WTMASS already gives slinches).
LENGTH_UNITS_M = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254, "ft": 0.3048}
MASS_UNITS_KG = {"kg": 1.0, "t": 1000.0, "g": 1e-3,
                 "slinch": 0.45359237 * 9.80665 / 0.0254,  # lbf s^2/in = 175.1268 kg
                 "slug": 0.45359237 * 9.80665 / 0.3048}  # lbf s^2/ft = 14.5939 kg
AXES = ("+x", "-x", "+y", "-y", "+z", "-z")
# A grid's stations must increase along the span by more than this fraction of the
# semispan (two grids at one station, or out of order, are a mistake in the list).
MIN_STATION_STEP_FRAC = 1e-9
MAX_GRIDS = 10_000  # the stations of a modal file: a wing's reference line, not its mesh
# Largest OP2 file read [bytes]: pyyeti reads it into memory; a SOL 103 deck of a wing's
# beam or shell model with its first tens of modes is a few MB to a few hundred.
MAX_OP2_BYTES = 2 * 1024**3


class NastranError(InputError):
    """An OP2 file or a mapping that cannot be used; the message says what and what is
    accepted."""


@dataclass(frozen=True, eq=False)
class FEModes:
    """Modes of a finite-element model at chosen grids, in the deck's units.

    ``grid_ids`` (g,); ``positions`` (g, 3) in the basic frame [length unit];
    ``translations`` and ``rotations`` (n, g, 3) per mode, basic frame [length unit, rad];
    ``frequencies_rad_s`` (n,); ``generalised_masses`` (n,) [mass unit × length unit²];
    ``source``: where they come from."""

    grid_ids: np.ndarray
    positions: np.ndarray
    translations: np.ndarray
    rotations: np.ndarray
    frequencies_rad_s: np.ndarray
    generalised_masses: np.ndarray
    source: str


def _axis(text: str, what: str) -> np.ndarray:
    if text not in AXES:
        raise NastranError(f"{what} {text!r}: accepted {', '.join(AXES)} (the deck's basic "
                           "frame)")
    v = np.zeros(3)
    v["xyz".index(text[1])] = 1.0 if text[0] == "+" else -1.0
    return v


def fe_modal_data(fe: FEModes, *, span: str = "+y", up: str = "+z", aft: str = "+x",
                  length_unit: str = "m", mass_unit: str = "kg",
                  x_elastic_frac: float = 0.5, x_inertial_frac: float = 0.5,
                  damping_ratio: float = 0.0) -> ModalData:
    """The modal data of the wing from ``fe`` (module docstring), normalised; ``span``,
    ``up``, ``aft``: the deck's axes (±x, ±y, ±z, mutually perpendicular);
    ``length_unit`` (:data:`LENGTH_UNITS_M`), ``mass_unit`` (:data:`MASS_UNITS_KG`); the
    axes' chord fractions aft of the leading edge (``x_elastic_frac``: where the grids'
    line lies); ``damping_ratio`` ζ of every mode. :class:`NastranError` in one line for
    a mapping that cannot be made."""
    s_hat, u_hat, a_hat = _axis(span, "span"), _axis(up, "up"), _axis(aft, "aft")
    if abs(s_hat @ u_hat) + abs(s_hat @ a_hat) + abs(u_hat @ a_hat) > 0.0:
        raise NastranError(f"span {span}, up {up}, aft {aft}: the three must be different "
                           "axes of the deck's frame")
    if length_unit not in LENGTH_UNITS_M or mass_unit not in MASS_UNITS_KG:
        raise NastranError(f"units {length_unit!r}, {mass_unit!r}: accepted length "
                           f"{', '.join(LENGTH_UNITS_M)}; mass {', '.join(MASS_UNITS_KG)}")
    length, mass = LENGTH_UNITS_M[length_unit], MASS_UNITS_KG[mass_unit]
    hand = float(np.cross(a_hat, s_hat) @ u_hat)  # +1 starboard, -1 port (right-handed)
    y = (fe.positions - fe.positions[0]) @ s_hat * length
    steps = np.diff(y)
    if y.size < 2 or np.any(steps <= MIN_STATION_STEP_FRAC * max(abs(y[-1]), 1e-300)):
        bad = int(np.argmax(steps <= MIN_STATION_STEP_FRAC * max(abs(y[-1]), 1e-300))) + 1
        raise NastranError(f"grid {int(fe.grid_ids[bad])} is at {y[bad]:g} m along the span "
                           f"({span}) from grid {int(fe.grid_ids[0])}, not outboard of the "
                           "grid before it: name the grids from the root to the tip, one "
                           "per station (and check --span)")
    off_line = np.linalg.norm((fe.positions - fe.positions[0]) * length
                              - np.outer(y, s_hat), axis=1)
    bending = -(fe.translations @ u_hat) * length
    twist = hand * (fe.rotations @ s_hat)
    try:
        modes = ModalData(
            frequencies_rad_s=fe.frequencies_rad_s,
            damping_ratios=np.full(fe.frequencies_rad_s.size, float(damping_ratio)),
            generalised_masses_kg_m2=fe.generalised_masses * mass * length**2,
            stations_m=y, bending_m=bending, twist_rad=twist,
            x_elastic_frac=np.full(y.size, float(x_elastic_frac)),
            x_inertial_frac=np.full(y.size, float(x_inertial_frac)),
            source=fe.source,
            notes=(f"{fe.grid_ids.size} grids {int(fe.grid_ids[0])}..{int(fe.grid_ids[-1])}; "
                   f"span {span}, up {up}, aft {aft}; units {length_unit}, {mass_unit}; the "
                   f"grids' line off the straight span line by up to "
                   f"{float(off_line.max()):.3g} m"))
        return modes.normalised()
    except ModalDataError as exc:
        raise NastranError(f"{fe.source}: {exc}") from None


def _row_index(frame) -> dict[tuple[int, int], int]:
    """{(id, dof): row} of a pyyeti table indexed by (id, dof)."""
    ids = frame.index.get_level_values(0).to_numpy()
    dofs = frame.index.get_level_values(1).to_numpy()
    return {(int(i), int(d)): k for k, (i, d) in enumerate(zip(ids, dofs, strict=True))}


def read_op2_modes(path: str | Path, grids) -> FEModes:
    """The modes of the OP2 file ``path`` (Nastran SOL 103 with ``PARAM,POST,-1``) at the
    grid ids ``grids`` (root to tip), read with pyyeti (module docstring): positions and
    displacements in the basic frame (a grid with another output frame, CD ≠ 0, is
    refused). :class:`NastranError` in one
    line: pyyeti missing (``pip install ".[nastran]"``), a file pyyeti cannot read, no
    eigenvalues or eigenvectors in it, a grid that is not in it."""
    try:
        from pyyeti.nastran import op2
    except ImportError:
        raise NastranError("reading an OP2 file needs pyyeti: pip install "
                           "\"bioflex-jsb[nastran]\" (or pip install pyyeti)") from None
    p = Path(path)
    # a regular file of at most MAX_OP2_BYTES (pyyeti reads it by name, into memory: a FIFO
    # would hang it, a device fill the memory)
    with open_input(p, "OP2 file", MAX_OP2_BYTES, NastranError):
        pass
    ids = [int(g) for g in grids]
    if not 2 <= len(ids) <= MAX_GRIDS or len(set(ids)) != len(ids):
        raise NastranError(f"grids: give 2..{MAX_GRIDS} distinct grid ids, root to tip")
    import warnings

    with warnings.catch_warnings():
        # pyyeti's reader warns about its own API's future; the file is read all the same
        warnings.simplefilter("ignore", FutureWarning)
        try:
            data = op2.rdparampost(str(p), get_ougs=True)
        except (ValueError, KeyError, IndexError, OSError, EOFError) as exc:
            raise NastranError(f"OP2 file {str(p)!r}: pyyeti cannot read it ({exc}); a "
                               "SOL 103 run with PARAM,POST,-1 is accepted") from None
    lama, shapes, uset = data.get("lama"), data.get("ougv1"), data.get("uset")
    if lama is None or shapes is None or uset is None:
        raise NastranError(f"OP2 file {str(p)!r}: holds no eigenvalue table (LAMA), "
                           "eigenvectors (OUGV1) or grid table (USET); a SOL 103 run with "
                           "PARAM,POST,-1 and DISP(PLOT) = ALL is accepted")
    lama = np.atleast_2d(np.asarray(lama, dtype=float))
    n = lama.shape[0]
    vectors = np.asarray(shapes, dtype=float)
    if vectors.shape[1] != n:
        raise NastranError(f"OP2 file {str(p)!r}: {vectors.shape[1]} eigenvectors for {n} "
                           "eigenvalues")
    # pyyeti's USET table: six rows per grid, columns x, y, z: its position in basic (dof
    # 1), its output frame's id and type (dof 2), the frame's origin and axes (dofs 3-6)
    where = _row_index(uset)
    table = np.asarray(uset[["x", "y", "z"]], dtype=float)
    rows_of = _row_index(shapes)
    values = np.asarray(shapes, dtype=float)  # rows (id, dof): T1..T3, R1..R3; columns modes
    positions, trans, rots = [], [], []
    for g in ids:
        if (g, 1) not in where or (g, 6) not in where:
            raise NastranError(f"grid {g} is not a grid of {str(p)!r} (its USET table)")
        if int(table[where[(g, 2)], 0]) != 0:
            raise NastranError(f"grid {g}: its displacements are in output frame "
                               f"{int(table[where[(g, 2)], 0])}; grids with the basic frame "
                               "as their output frame (GRID CD = 0) are accepted")
        try:
            u = values[[rows_of[(g, dof)] for dof in range(1, 7)]]  # (6, n)
        except KeyError:
            raise NastranError(f"grid {g}: no eigenvector rows in {str(p)!r} (DISP(PLOT) = "
                               "ALL writes them)") from None
        positions.append(table[where[(g, 1)]])
        trans.append(u[:3].T)
        rots.append(u[3:].T)
    return FEModes(
        grid_ids=np.array(ids), positions=np.array(positions),
        translations=np.stack(trans, axis=1), rotations=np.stack(rots, axis=1),
        frequencies_rad_s=lama[:, 3].copy(), generalised_masses=lama[:, 5].copy(),
        source=f"Nastran OP2 {p.name} ({n} modes)")


def op2_modal_data(path: str | Path, grids, **mapping) -> ModalData:
    """:func:`read_op2_modes` then :func:`fe_modal_data` (``mapping``: its keywords)."""
    return fe_modal_data(read_op2_modes(path, grids), **mapping)
