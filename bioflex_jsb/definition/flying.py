"""The elastic wing of a definition with an airframe (docs/aircraft.md, "The wing on an
airframe"): its structure kinds, its flight-model settings, and its fit to the airframe.

The prototype's membrane wing carries one chordwise position of each axis (Eq. 11-12 of the
paper), so its stations' ``elastic_axis`` and ``centre_of_mass`` are constant along the
span; a modal file's [axes] and a beam's stations may vary (the modes carry them; their
mean is the variant's, as for a variant file). Structure kinds: ``prototype-membrane`` (the
prototype's membrane half wing as calibrated to Table 2, ribbed or not:
parameters/wing_structure.py), ``modal`` (a modal file, docs/structures.md) and ``beam``
(beam sections as a clamped wing has them, with point masses and struts: its modes are
computed from the beam and take a modal file's place in the flight build,
structures/beam_wing.py; the same wing is analysed clamped too).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from bioflex_jsb.definition.airframe import GENERATED
from bioflex_jsb.definition.model import (
    AeroSettings,
    AirframeDefinition,
    FlyingWing,
    MembraneStructure,
    ModalStructure,
    WingStation,
)
from bioflex_jsb.definition.ranges import DAMPING_RANGE
from bioflex_jsb.definition.reader import Reader
from bioflex_jsb.errors import InputError

# The prototype's six wing variants as shipped definitions
# (bioflex_jsb/data/aircraft/bioflex_<variant>.toml).
PROTOTYPE_VARIANTS = ("original", "optimised", "inertial-forward", "elastic-forward",
                      "inertial-backward", "elastic-backward")
SHIPPED_AIRCRAFT = tuple(f"bioflex_{v}" for v in PROTOTYPE_VARIANTS)
FLYING_KINDS = ("prototype-membrane", "modal")
FLYING_AERO_FIELDS = ("pin_c_eta1_q1", "published_c_eta1_q1")
PHYSICAL_PIN = "physical"
# The flight model's modal basis: the paper's three modes (Table 2); the coefficient names,
# logs and exports are made for them (flight_dynamics/wing_model.py DEFAULT_N_MODES).
FLYING_N_MODES = 3
# Largest |C_η1^Q1| [-] that may be pinned: flight_dynamics/wing_model.py
# MAX_PINNED_COEFFICIENT's reason (strip theory bounds it by 2π; 100 leaves 16 × that).
PIN_LIMIT = 100.0
# The wing's span (2 × the tip station) and the airframe's span_m agree within 5 %: the
# elastic wing is the aircraft's main wing (b of S = b c̄); a wing in another unit than the
# airframe is far outside.
SPAN_TOLERANCE = 0.05
# Axis positions constant along the span to 1e-9 of the chord (the rounding of the file).
AXIS_TOLERANCE = 1e-9
# A modal file's mean axes and the stations' agree within 1e-6 of the chord (files print
# six or more digits).
MODAL_AXIS_TOLERANCE = 1e-6


def check_span(r: Reader, stations: tuple[WingStation, ...], airframe: AirframeDefinition) -> None:
    """The wing's span matches the airframe's (:data:`SPAN_TOLERANCE`); an airframe whose
    span comes from its JSBSim aircraft is checked when it is completed
    (:meth:`~bioflex_jsb.definition.aircraft.Aircraft.with_jsbsim`)."""
    if airframe.span_m is None:
        return
    wing_span = 2.0 * stations[-1].y_m
    if abs(wing_span / airframe.span_m - 1.0) > SPAN_TOLERANCE:
        raise r.fail(f"wing.stations[{len(stations) - 1}].y_m", f"the wing's span 2 x "
                     f"{stations[-1].y_m:g} = {wing_span:g} m differs from airframe.span_m "
                     f"{airframe.span_m:g} m by more than {100 * SPAN_TOLERANCE:g} % (the "
                     "elastic wing is the aircraft's main wing; y_m is the semispan)")


def _constant(r: Reader, stations, key: str) -> float:
    values = np.array([getattr(s, key) for s in stations])
    if np.ptp(values) > AXIS_TOLERANCE:
        raise r.fail(f"wing.stations.{key}", f"varies along the span ({values.min():g}.."
                     f"{values.max():g}); a flying wing has one chordwise {key} (Eq. 11-12); "
                     "use a modal file for axes that vary")
    return float(values[0])


def axes(stations: tuple[WingStation, ...]) -> tuple[float, float]:
    """(x_inertial_frac, x_elastic_frac) [-] of a flying wing (constant along the span)."""
    return float(stations[0].centre_of_mass), float(stations[0].elastic_axis)


def flying_structure(r: Reader, stations: tuple[WingStation, ...], base_dir: Path | None
                     ) -> MembraneStructure | ModalStructure | None:
    """The ``[structure]`` of a wing on an airframe (module docstring); ``None`` for beam
    sections (the loader reads them as a clamped wing's)."""
    t = r.table("structure", None)
    if t.get("kind", "beam") == "beam":
        return None  # beam sections, read as for a clamped wing (and flown as its modes)
    r.keys(t, "structure", ("kind", "ribs", "modes_file", "damping_ratio", "n_modes"))
    kind = r.choice(t, "structure", "kind", FLYING_KINDS + ("beam",), None)
    zeta = r.number(t, "structure", "damping_ratio", *DAMPING_RANGE, "(ratio)",
                    hint=" (a ratio, not a percentage: 2 % is 0.02)")
    n = r.integer(t, "structure", "n_modes", FLYING_N_MODES, FLYING_N_MODES, FLYING_N_MODES)
    if kind == "prototype-membrane":
        r.keys(t, "structure", ("kind", "ribs", "damping_ratio", "n_modes"))
        for key in ("centre_of_mass", "elastic_axis"):
            _constant(r, stations, key)
        return MembraneStructure(r.boolean(t, "structure", "ribs"), zeta, n)
    r.keys(t, "structure", ("kind", "modes_file", "damping_ratio", "n_modes"))
    path = Path(r.text(t, "structure", "modes_file"))
    if base_dir is not None and not path.is_absolute():
        path = base_dir / path
    from bioflex_jsb.structures.modal_file import read_modal_file

    try:
        modes = read_modal_file(path)
    except InputError as exc:  # the modal file's own one-line reason, under this field
        raise r.fail("structure.modes_file", str(exc)) from None
    for key, mine in (("centre_of_mass", modes.x_inertial_frac),
                      ("elastic_axis", modes.x_elastic_frac)):
        stated = _constant(r, stations, key)
        if abs(float(np.mean(mine)) - stated) > MODAL_AXIS_TOLERANCE:
            raise r.fail(f"wing.stations.{key}", f"{stated:g} differs from the modes file's "
                         f"[axes] (mean {float(np.mean(mine)):g}): give the file's value")
    return ModalStructure(str(path.resolve()), zeta, n)


def _pin(r: Reader, at: dict, key: str) -> float | None:
    v = at.get(key)
    if v is None or (key == "pin_c_eta1_q1" and v == PHYSICAL_PIN):
        return None
    return r.number(at, "aero", key, -PIN_LIMIT, PIN_LIMIT, "(coefficient)",
                    hint=" (a Table B1 coefficient of any wing is a few units at most)")


def flying_wing(r: Reader, wing: dict, at: dict, aero: AeroSettings, name: str,
                beam: bool = False) -> FlyingWing:
    """The flight-model settings of the wing (``[wing] name``, ``[aero]`` pins); a ``beam``
    wing keeps the clamped wing's [aero] settings too (for its clamped analysis; in flight
    it takes the vortex lattice as every flying wing does)."""
    if not beam and "model" in at:
        raise r.fail("aero.model", "is a clamped-wing setting; an aircraft's commands choose "
                     "the aerodynamic model with --aero (docs/aircraft.md)")
    if not beam and aero.lift_slope != "vlm":
        raise r.fail("aero.lift_slope", "must be 'vlm' on an airframe: the flight model's "
                     "strips take the vortex lattice's spanwise loading (Table B1)")
    pin = at.get("pin_c_eta1_q1")
    if isinstance(pin, str) and pin != PHYSICAL_PIN:
        raise r.fail("aero.pin_c_eta1_q1", f"must be a number or {PHYSICAL_PIN!r}, got {pin!r}")
    for key in ("strips", "section_lift_slope_per_rad"):
        if key in at and not beam:
            raise r.fail(f"aero.{key}", "is a clamped-wing setting (strip lift slope); an "
                         "aircraft's wing takes the vortex lattice's (lift_slope = 'vlm')")
    wing_name = r.text(wing, "wing", "name") if "name" in wing else name
    return FlyingWing(wing_name, _pin(r, at, "pin_c_eta1_q1"),
                      _pin(r, at, "published_c_eta1_q1"))


def flight_refusal(aircraft) -> str | None:
    """Why the nonlinear co-simulation (``gust``, ``compare``, ``trim --wing``, ``sitl``)
    cannot fly ``aircraft`` (an :class:`~bioflex_jsb.definition.aircraft.Aircraft`), or
    ``None``. The prototype's airframe (``aircraft.flight_problem()`` is None: every field
    the prototype's) flies with any wing. Another airframe flies on its own JSBSim aircraft
    (``airframe.jsbsim``: a package aircraft or a directory) when the linear analyses take
    it (:meth:`~bioflex_jsb.definition.aircraft.Aircraft.linear_problem`: a beam or modal
    wing, the derivatives as a table: the wing's loads are built from them) and the file gives the
    speeds it flies at (``airframe.cruise_speed_m_s``, ``speed_range_m_s``). The generated
    ``bioflex`` airframe with other numbers cannot fly: its JSBSim model holds the
    prototype's numbers (:meth:`flight_problem`'s line says which field differs)."""
    prototype = aircraft.flight_problem()
    if prototype is None:
        return None
    problem = aircraft.linear_problem()
    if problem:
        return problem
    a = aircraft.airframe
    if a.jsbsim == GENERATED:
        return prototype
    if getattr(a, "cruise_speed_m_s", None) is None:
        return (f"aircraft {aircraft.name!r}: airframe.cruise_speed_m_s and "
                "airframe.speed_range_m_s are needed to fly it (the speeds gust, compare, "
                "trim and sitl trim at; docs/aircraft.md)")
    aircraft.planform()  # the flight model's planform, or its one-line DefinitionError
    return None


def flight_speeds(aircraft) -> tuple[float, tuple[float, float]]:
    """(cruise speed [m/s], (lowest, highest) trim speed [m/s]) of an aircraft that flies
    (:func:`flight_refusal` is None): the prototype's (Table 1's 15 m/s; 5-40 m/s,
    parameters/airframe.py AIRSPEED_RANGE_M_S) on its airframe, else the file's."""
    from bioflex_jsb.parameters.airframe import AIRSPEED_RANGE_M_S, CRUISE_SPEED_M_S

    if aircraft.flight_problem() is None:
        return CRUISE_SPEED_M_S, AIRSPEED_RANGE_M_S
    a = aircraft.airframe
    return a.cruise_speed_m_s, a.speed_range_m_s
