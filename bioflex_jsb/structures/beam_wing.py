"""A beam wing as the flight model takes it: beam sections (with point masses and struts)
whose modes are computed once per process and handed on as the
:class:`~bioflex_jsb.structures.modal_data.ModalData` a modal file gives.

A definition's ``[structure] kind = "beam"`` wing on an airframe becomes a
:class:`BeamWing`; the flight build (``flight_dynamics/wing_model.py``) asks it for its
modes (:meth:`BeamWing.modes`) where it would read a modal file, so everything downstream
(Table B1/B2, modes, flutter of the free aircraft, gust runs) is the modal file's path.

Cache: the modes are kept in this process, keyed on :attr:`BeamWing.digest` (a SHA-256 of
every number the modes depend on: the sections, point masses, springs, mesh and damping;
not the description, which only names the modes' source) and the number of modes. A 40-element
solve (a 120-dof dense eigenproblem, ``structures/beam.py``) takes about 60 ms (measured on
the project's busy 2-core machine), a seventh of the vortex lattice every build solves
(about 0.4 s), so there is no disk cache: a new process solves it again.
"""

from __future__ import annotations

import hashlib
from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np

from bioflex_jsb.structures.beam import DEFAULT_N_ELEMENTS, BeamSections, beam_modes
from bioflex_jsb.structures.modal_data import ModalData

# Modes kept per process: each is a few kB (41 stations × a few modes); a sweep over many
# beam wings keeps the most recent ones.
MODES_CACHE_SIZE = 64
_MODES: OrderedDict[tuple[str, int], ModalData] = OrderedDict()


def _digest(sections: BeamSections, n_elements: int, damping_ratio: float) -> str:
    h = hashlib.sha256()
    for name in ("stations_m", "bending_stiffness_n_m2", "torsional_stiffness_n_m2",
                 "mass_per_length_kg_m", "torsional_inertia_kg_m", "chord_m",
                 "x_elastic_frac", "x_inertial_frac"):
        h.update(name.encode())
        h.update(np.ascontiguousarray(getattr(sections, name), dtype="<f8").tobytes())
    h.update(repr([(float(p.y_m), float(p.mass_kg), float(p.x_frac),
                    float(p.pitch_inertia_kg_m2)) for p in sections.point_masses]).encode())
    h.update(repr([(float(k.y_m), float(k.stiffness_n_m)) for k in sections.springs]).encode())
    h.update(repr((int(n_elements), float(damping_ratio))).encode())
    return h.hexdigest()


@dataclass(frozen=True, eq=False)
class BeamWing:
    """Beam sections and the settings of their modes: ``n_elements`` finite elements,
    ``damping_ratio`` ζ [-] of every mode. Equal (and hashed) by :attr:`digest`, the
    physical content, so a wing variant holding one keys the build cache on what it is
    (the sections' description, the modes' source line, is not part of it)."""

    sections: BeamSections
    n_elements: int = DEFAULT_N_ELEMENTS
    damping_ratio: float = 0.0
    digest: str = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "digest",
                           _digest(self.sections, self.n_elements, self.damping_ratio))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, BeamWing) and other.digest == self.digest

    def __hash__(self) -> int:
        return hash(self.digest)

    def __repr__(self) -> str:
        return f"BeamWing({self.sections.description!r}, sha256 {self.digest[:12]})"

    def modes(self, n_modes: int) -> ModalData:
        """The lowest ``n_modes`` modes in the project's normalisation, sampled at the
        finite-element nodes (root to tip), with :attr:`damping_ratio` on each; computed
        once per process (module docstring)."""
        key = (self.digest, int(n_modes))
        got = _MODES.get(key)
        if got is None:
            got = beam_modes(self.sections, int(n_modes), n_elements=self.n_elements,
                             damping_ratio=self.damping_ratio)
            _MODES[key] = got
            while len(_MODES) > MODES_CACHE_SIZE:
                _MODES.popitem(last=False)
        else:
            _MODES.move_to_end(key)
        if got.source != self.sections.description:  # the same beam under another name
            got = replace(got, source=self.sections.description)
        return got
