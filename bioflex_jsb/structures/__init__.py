"""Structures: half-wing beam model, mode shapes, modal-data files.

* :mod:`.modal_data`  the :class:`ModalData` interface (what the rest of the code consumes);
* :mod:`.sections`    chordwise section properties, Eq. (11)–(12);
* :mod:`.beam`        clamped-free bending–torsion beam finite elements;
* :mod:`.wing_model`  the prototype's wing: default modes, calibration, Table 2 comparison;
* :mod:`.modal_file`  TOML modal-data files (the only I/O of this package).
"""

from bioflex_jsb.structures.modal_data import ModalData, ModalDataError

__all__ = ["ModalData", "ModalDataError"]
