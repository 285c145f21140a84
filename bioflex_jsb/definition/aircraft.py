"""The aircraft as one object (AeroSandbox's ``Airplane`` in spirit): a definition with an
airframe, loaded once and passed into every analysis (docs/aircraft.md).

:class:`Aircraft` holds the :class:`~bioflex_jsb.definition.model.Definition` (airframe,
wing planform, structure, settings) and builds what the analyses take: the elastic wing
(:meth:`Aircraft.wing`: today's :class:`~bioflex_jsb.flight_dynamics.wing_model.WingBuild`,
modes, strips, Table B1/B2 model), its :class:`~bioflex_jsb.flight_dynamics.wing_model.
WingVariant` and :class:`~bioflex_jsb.parameters.wing.Planform`.

What runs with another airframe (docs/aircraft.md): the LINEAR analyses (``modes``,
``flutter`` of the free aircraft on quasi-steady and unsteady strips, ``linear_model``, the
elastic trim) take the aircraft's values, passed down as one
:class:`~bioflex_jsb.parameters.airframe.AirframeData` (:meth:`Aircraft.airframe_data`:
S, b, c̄, mass, inertia, the 22 rigid derivatives) carried by the wing's model and by every
flight condition built for it, and the wing's planform (:meth:`Aircraft.planform`) carried
by the :class:`WingBuild`; :meth:`Aircraft.linear_problem` says what they cannot take
(derivatives from JSBSim, the prototype's membrane on another airframe). A ``beam`` wing's
modes are computed from its beam (:meth:`Aircraft.variant`: a
:class:`~bioflex_jsb.structures.beam_wing.BeamWing`) and flow where a modal file's do.

What flies: the nonlinear co-simulation (the JSBSim runs of ``gust``, ``compare``,
``trim``, ``export-jsbsim``) flies the generated prototype airframe with any wing (axes,
ribs, damping, a modal file or a beam, the C_η1^Q1 pin) when the file's airframe is the prototype's
(:meth:`Aircraft.flight_problem` is None: each field equal to 1e-9 relative, the rounding of
a printed value), and another aircraft on its own JSBSim aircraft (``airframe.jsbsim``: a
package aircraft such as the SGS, or a directory; a glider in its steady glide) when the
linear analyses take it and it gives its flight speeds
(:func:`bioflex_jsb.definition.flying.flight_refusal`). The generated ``bioflex`` airframe
with other numbers is refused in one line naming the first field that differs (its JSBSim
model holds the prototype's numbers), never flown with them in its place.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import math
from pathlib import Path

import numpy as np

from bioflex_jsb.aerodynamics.antisymmetric_loading import LATERAL_AERO
from bioflex_jsb.definition.airframe import GENERATED
from bioflex_jsb.definition.clamped import beam_wing
from bioflex_jsb.definition.flying import FLYING_N_MODES, axes, check_span
from bioflex_jsb.definition.loader import load_definition
from bioflex_jsb.definition.model import (
    DEFAULT_MONITORING_STATIONS,
    Definition,
    JSBSimValues,
    MembraneStructure,
    ModalStructure,
)
from bioflex_jsb.definition.reader import DefinitionError, Reader
from bioflex_jsb.definition.sensors import resolve_sensors
from bioflex_jsb.flight_dynamics.wing_model import (
    DEFAULT_MASS_BASIS,
    WingBuild,
    WingVariant,
    build_wing,
    with_lateral_aero,
)
from bioflex_jsb.parameters.airframe import (
    AIRFRAME_GEOMETRY,
    MASS_PROPERTIES,
    PROTOTYPE_AIRFRAME,
    REFERENCE_GEOMETRY,
    RIGID_AERODYNAMICS,
    AirframeData,
    MassProperties,
    ReferenceGeometry,
    RigidAerodynamics,
)
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3
from bioflex_jsb.parameters.sensors import Sensors
from bioflex_jsb.parameters.wing import DEFAULT_PLANFORM, Planform

# DECISION: the definition's [airframe] numbers and the JSBSim aircraft they describe must
# agree: JSBSim flies its XML's mass, inertia and geometry while the modal wing, the elastic
# trim and the section loads take the file's, so a mismatch would make the run and the linear
# analyses two different aircraft (a user's 10 % heavier file with SGS.xml's 710 lb: the
# loads carry ΔW/2 = 158 N of lift that is never flown). Relative tolerance 1 %: a
# value rounded to 3 significant digits is off by at most 0.5 % (the shipped sgs_elastic
# file, 5 digits: largest 2.5e-5, S); the CG within 1 % of the mean chord (a 1 % static
# margin; an inch rounded in metres is 1.3 mm, 0.13 % of SGS's chord).
CONSISTENCY_REL = 0.01
CONSISTENCY_CG_CHORDS = 0.01

# Equal to the prototype's: 1e-9 relative (printed values carry 4-10 digits; the shipped
# files repeat parameters/ to the last digit: measured 0 difference).
SAME_REL = 1e-9


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= SAME_REL * max(abs(a), abs(b), 1e-12)


def _constant_chord_form(y, chord, x, z) -> tuple[float, float] | None:
    """(outer panel start [m], its leading-edge sweep [rad]) when the stations are the
    constant-chord :class:`Planform`'s form (one chord, flat, a straight inner panel and at
    most one straight swept outer panel), else None."""
    if float(chord.max() - chord.min()) > SAME_REL * float(chord.max()) or np.any(z != 0.0):
        return None
    straight = [i for i in range(len(y)) if x[i] == 0.0]
    k = straight[-1]
    if straight != list(range(k + 1)):
        return None
    semispan, start = float(y[-1]), float(y[k])
    sweep = math.atan(float(x[-1]) / (semispan - start)) if k < len(y) - 1 else 0.0
    for i in range(k + 1, len(y)):
        if abs(x[i] - (y[i] - start) * math.tan(sweep)) > 1e-9 * semispan:
            return None
    return start, sweep


class Aircraft:
    """An aircraft definition and what the analyses build from it; ``lateral_aero`` the
    antisymmetric loading its wing's lateral elastic models take (:meth:`wing`'s
    ``WingBuild.lateral_aero``: ``strips``, or ``lattice`` by :meth:`with_lateral_aero`)."""

    lateral_aero = "strips"

    def __init__(self, definition: Definition) -> None:
        if definition.airframe is None:
            raise DefinitionError(f"definition {definition.name!r} has no [airframe]: it is "
                                  "a clamped wing (flutter --clamped, api.flutter(..., "
                                  "clamped=True)); an aircraft needs [airframe]")
        self.definition = definition

    @property
    def name(self) -> str:
        return self.definition.name

    @property
    def airframe(self):
        return self.definition.airframe

    @property
    def source(self) -> str:
        """Where the definition was read: its file's absolute path (a log records it, and
        ``rerun`` reads it from any directory), or its name when it has no file."""
        path = self.definition.path
        return str(Path(path).resolve()) if path else self.name

    def __repr__(self) -> str:
        return (f"Aircraft({self.name!r}, jsbsim={self.airframe.jsbsim!r}, "
                f"wing={self.definition.flying.name!r})")

    # -- the airframe as the analyses' parameter types ---------------------------------
    def reference_geometry(self) -> ReferenceGeometry:
        """S [m²], b [m], c̄ [m] of the coefficients."""
        self.require_complete()
        a = self.airframe
        return ReferenceGeometry(a.reference_area_m2, a.span_m, a.mean_chord_m)

    def mass_properties(self) -> MassProperties:
        """Mass [kg] and inertia about the CG [kg·m²]."""
        self.require_complete()
        a, i = self.airframe, self.airframe.inertia
        return MassProperties(a.mass_kg, i.ixx_kg_m2, i.iyy_kg_m2, i.izz_kg_m2, i.ixz_kg_m2)

    def rigid_aerodynamics(self) -> RigidAerodynamics:
        """The rigid derivatives: the file's table, else those identified from the JSBSim
        aircraft at its cruise speed (:meth:`airframe_data` carries them at every speed)."""
        self.require_complete()
        a = self.airframe
        if a.derivatives is not None:
            return RigidAerodynamics(**a.derivatives)
        return a.schedule.at(a.cruise_speed_m_s)

    def airframe_data(self) -> AirframeData:
        """The airframe as the linear analyses take it (module docstring): the prototype's
        own :data:`~bioflex_jsb.parameters.airframe.PROTOTYPE_AIRFRAME` object when this
        airframe is the prototype's (:meth:`flight_problem` is ``None``: its numbers are
        then the same to the last bit), else built from the file (no propulsion model:
        the LTI's throttle column is zero; the JSBSim aircraft's engine is JSBSim's)."""
        if self.flight_problem() is None:
            return PROTOTYPE_AIRFRAME
        problem = self.linear_problem()
        if problem:
            raise DefinitionError(problem)
        schedule = self.airframe.schedule if self.airframe.derivatives is None else None
        return AirframeData(self.name, self.reference_geometry(), self.mass_properties(),
                            self.rigid_aerodynamics(), None, schedule)

    # -- the wing ---------------------------------------------------------------------
    def planform(self) -> Planform:
        """The wing's planform with the CG from the airframe: the stations' chords, leading
        edges and heights, linear between stations (a tapered, multi-panel or dihedral
        wing: :meth:`Planform.from_stations`); a wing of constant chord, flat, with a
        straight inner panel and at most one swept outer panel keeps the prototype's
        constant-chord form (its numbers, to the bit)."""
        d = self.definition
        where = f"definition {d.name!r}"
        chord = d.column("chord_m")
        y, x, z = d.column("y_m"), d.column("leading_edge_x_m"), d.column("z_m")
        if abs(x[0]) > 0.0 or abs(z[0]) > 0.0:
            raise DefinitionError(f"{where}: wing.stations[0].leading_edge_x_m and z_m must "
                                  "be 0 (the wing frame's origin is the root leading edge)")
        x_cg = self.airframe.wing_cg_x_m
        legacy = _constant_chord_form(y, chord, x, z)
        if legacy is None:
            return Planform.from_stations(y, chord, x, z, x_cg)
        start, sweep = legacy
        return Planform(semispan_m=float(y[-1]), chord_m=float(chord[0]),
                        outer_panel_start_m=start, outer_sweep_rad=sweep, x_cg_m=x_cg)

    def variant(self) -> WingVariant:
        """The wing as a :class:`WingVariant` (its axes, structure, damping, pin); a
        ``beam`` structure as its :class:`~bioflex_jsb.structures.beam_wing.BeamWing`,
        whose modes take a modal file's place (axes: the stations' means, as a modal
        file's [axes] are taken)."""
        d = self.definition
        x_i, x_e = axes(d.stations)
        s = d.structure
        beam = None
        if isinstance(s, MembraneStructure):
            ribs, modes_file = s.ribs, None
        elif isinstance(s, ModalStructure):
            ribs, modes_file = True, s.modes_file
        else:
            ribs, modes_file = True, None
            beam = beam_wing(d)
            x_i = float(np.mean(d.column("centre_of_mass")))
            x_e = float(np.mean(d.column("elastic_axis")))
        f = d.flying
        return WingVariant(f.name, x_i, x_e, ribs=ribs, structural_damping=s.damping_ratio,
                           modes_file=modes_file, pinned_c_eta1_q1=f.pin_c_eta1_q1,
                           published_c_eta1_q1=f.published_c_eta1_q1,
                           description=d.description, beam=beam)

    # -- the JSBSim aircraft's own numbers ---------------------------------------------
    def jsbsim_mismatches(self, values: JSBSimValues) -> list[str]:
        """Every number the file gives that its JSBSim aircraft (``values``) disagrees with
        beyond :data:`CONSISTENCY_REL` (the CG: :data:`CONSISTENCY_CG_CHORDS` of the mean
        chord), one phrase each."""
        a = self.airframe
        out = []
        rows = [("reference_area_m2", "m²"), ("span_m", "m"), ("mean_chord_m", "m"),
                ("mass_kg", "kg")]
        for field, unit in rows:
            mine, theirs = getattr(a, field), getattr(values, field)
            if mine is not None and not abs(mine - theirs) <= CONSISTENCY_REL * max(
                    abs(mine), abs(theirs)):
                out.append(f"{field} {mine:.6g} {unit} (JSBSim: {theirs:.6g} {unit})")
        if a.inertia is not None:
            theirs_i = values.inertia
            largest = max(theirs_i.ixx_kg_m2, theirs_i.iyy_kg_m2, theirs_i.izz_kg_m2)
            for k in ("ixx", "iyy", "izz", "ixz"):
                mine, theirs = (getattr(a.inertia, f"{k}_kg_m2"),
                                getattr(theirs_i, f"{k}_kg_m2"))
                scale = largest if k == "ixz" else max(abs(mine), abs(theirs))
                if not abs(mine - theirs) <= CONSISTENCY_REL * scale:
                    out.append(f"inertia_kg_m2.{k} {mine:.6g} kg·m² (JSBSim: {theirs:.6g}; "
                               "about the CG with its point masses and fuel)")
        if a.cg_m is not None:
            chord = a.mean_chord_m if a.mean_chord_m is not None else values.mean_chord_m
            limit = CONSISTENCY_CG_CHORDS * chord
            for axis, mine, theirs in zip("xyz", a.cg_m, values.cg_m, strict=True):
                if not abs(mine - theirs) <= limit:
                    out.append(f"cg_m ({axis}) {mine:.6g} m (JSBSim: {theirs:.6g} m, "
                               "structural frame)")
        return out

    def mac_leading_edge_m(self) -> tuple[float, float]:
        """(x of the wing's mean aerodynamic chord's leading edge aft of the root's [m], the
        mean aerodynamic chord [m]) from the stations (chord and leading edge linear
        between them): c̄ = ∫c² dy / ∫c dy, x_le = ∫x_le c dy / ∫c dy."""
        d = self.definition
        y = np.linspace(0.0, d.semispan_m, 401)
        c = np.interp(y, d.column("y_m"), d.column("chord_m"))
        x = np.interp(y, d.column("y_m"), d.column("leading_edge_x_m"))
        area = float(np.trapezoid(c, y))
        return float(np.trapezoid(x * c, y)) / area, float(np.trapezoid(c * c, y)) / area

    def with_jsbsim(self, values: JSBSimValues) -> Aircraft:
        """This aircraft with the fields its file leaves out taken from its JSBSim aircraft
        (``values``), the file's own compared with them (one line listing every mismatch),
        and ``checked`` set. The wing's attachment, when not given, is estimated from the
        aerodynamic reference point: the wing's mean aerodynamic chord's quarter-chord point
        there (JSBSim's AERORP is conventionally at the wing's quarter MAC), on the plane of
        symmetry."""
        a = self.airframe
        bad = self.jsbsim_mismatches(values)
        if bad:
            raise DefinitionError(
                f"aircraft {self.name!r}: its [airframe] disagrees with the JSBSim aircraft "
                f"{a.jsbsim!r} (more than {CONSISTENCY_REL:.0%}): " + "; ".join(bad)
                + ": leave a field out to take JSBSim's, or make them the same aircraft")
        fill: dict[str, object] = {}
        for field in ("reference_area_m2", "span_m", "mean_chord_m", "mass_kg", "cg_m",
                      "inertia", "cruise_speed_m_s", "speed_range_m_s"):
            if getattr(a, field) is None and getattr(values, field) is not None:
                fill[field] = getattr(values, field)
        if a.wing_root_leading_edge_m is None:
            x_le, mac = self.mac_leading_edge_m()
            arp = values.aero_reference_point_m
            fill["wing_root_leading_edge_m"] = (arp[0] - x_le - 0.25 * mac, 0.0, arp[2])
        if a.derivatives is None and values.schedule is not None:
            fill["schedule"] = values.schedule
        done = dataclasses.replace(a, **fill, from_jsbsim=tuple(fill), checked=True)
        if a.span_m is None:
            check_span(Reader({}, f"aircraft {self.name!r}"), self.definition.stations, done)
        missing = done.missing()
        if missing:
            raise DefinitionError(f"aircraft {self.name!r}: {', '.join(missing)} neither in "
                                  "the file nor found from the JSBSim aircraft")
        return Aircraft(dataclasses.replace(self.definition, airframe=done))

    def require_complete(self) -> None:
        """A :class:`DefinitionError` when fields are still to come from the JSBSim
        aircraft (the aircraft was loaded without completing it)."""
        missing = self.airframe.missing()
        if missing:
            raise DefinitionError(
                f"aircraft {self.name!r}: airframe.{missing[0]} (and {len(missing) - 1} more) "
                "come from its JSBSim aircraft: load it with api.load_aircraft or the "
                "commands' --aircraft, which read them from JSBSim")

    def linear_problem(self) -> str | None:
        """Why the linear analyses (``modes``, ``flutter``, ``linear_model``: module
        docstring) cannot take this aircraft, or ``None``."""
        a, d = self.airframe, self.definition
        head = f"aircraft {d.name!r}: "
        if a.missing():
            return (f"{head}airframe.{a.missing()[0]} comes from its JSBSim aircraft: load "
                    "it with api.load_aircraft or the commands' --aircraft")
        if isinstance(d.structure, MembraneStructure) and a.jsbsim != GENERATED:
            return (f"{head}structure.kind = 'prototype-membrane' is the prototype's wing "
                    "(its calibrated half-wing beam); on another airframe give the wing's "
                    "beam (kind = 'beam') or its modes in a 'modal' file")
        if isinstance(d.structure, MembraneStructure) and d.structure.n_modes != FLYING_N_MODES:
            return f"{head}structure.n_modes must be {FLYING_N_MODES}"
        return None

    def flight_problem(self) -> str | None:
        """Why this aircraft does not fly on the generated prototype airframe (module
        docstring), or ``None``; :func:`~bioflex_jsb.definition.flying.flight_refusal` says
        whether it flies on its own JSBSim aircraft instead."""
        a, d = self.airframe, self.definition
        head = f"aircraft {d.name!r}: "
        tail = (" (the generated airframe's JSBSim model holds the prototype's numbers; "
                "another airframe flies on its own JSBSim aircraft, airframe.jsbsim; the "
                "linear analyses modes, flutter and linear_model take this one: "
                "docs/aircraft.md)")
        if a.jsbsim != GENERATED:
            return (f"{head}airframe.jsbsim = {a.jsbsim!r} is not the generated prototype "
                    f"airframe {GENERATED!r}: the aircraft flies on its own JSBSim aircraft "
                    f"where definition.flying.flight_refusal allows it{tail}")
        g, ref = AIRFRAME_GEOMETRY, REFERENCE_GEOMETRY
        rows = [
            ("airframe.reference_area_m2", a.reference_area_m2, ref.area_m2),
            ("airframe.span_m", a.span_m, ref.span_m),
            ("airframe.mean_chord_m", a.mean_chord_m, ref.mean_chord_m),
            ("airframe.mass_kg", a.mass_kg, MASS_PROPERTIES.mass_kg),
            ("airframe.cg_m[0]", a.cg_m[0], g.cg_x_m), ("airframe.cg_m[1]", a.cg_m[1], 0.0),
            ("airframe.cg_m[2]", a.cg_m[2], g.cg_z_m),
            ("airframe.wing_root_leading_edge_m[0]", a.wing_root_leading_edge_m[0],
             g.wing_root_leading_edge_x_m),
            ("airframe.wing_root_leading_edge_m[1]", a.wing_root_leading_edge_m[1], 0.0),
            ("airframe.wing_root_leading_edge_m[2]", a.wing_root_leading_edge_m[2], 0.0),
            ("air.density_kg_m3", d.air.density_kg_m3, SEA_LEVEL_DENSITY_KG_M3),
        ]
        rows += [(f"airframe.inertia_kg_m2.{k}", getattr(a.inertia, f"{k}_kg_m2"),
                  getattr(MASS_PROPERTIES, f"{k}_kg_m2")) for k in ("ixx", "iyy", "izz", "ixz")]
        if a.derivatives is None:
            return (f"{head}airframe.derivatives = 'jsbsim': the prototype's LTI model takes "
                    f"its rigid derivatives from the file{tail}")
        rows += [(f"airframe.derivatives.{k}", v, getattr(RIGID_AERODYNAMICS, k))
                 for k, v in a.derivatives.items()]
        for field, mine, proto in rows:
            if not _same(mine, proto):
                return f"{head}{field} = {mine:g} differs from the prototype's {proto:g}{tail}"
        pf = self.planform()
        if pf.stations_m is not None:
            return (f"{head}the wing's planform (tapered, multi-panel or with dihedral) "
                    "differs from the prototype's constant-chord wing (wing.stations)"
                    f"{tail}")
        for field in ("semispan_m", "chord_m", "outer_panel_start_m", "outer_sweep_rad",
                      "x_cg_m"):
            mine, proto = getattr(pf, field), getattr(DEFAULT_PLANFORM, field)
            if not _same(mine, proto):
                return (f"{head}the wing's planform {field} = {mine:g} differs from the "
                        f"prototype's {proto:g} (wing.stations, airframe.cg_m){tail}")
        if isinstance(d.structure, MembraneStructure) and d.structure.n_modes != FLYING_N_MODES:
            return f"{head}structure.n_modes must be {FLYING_N_MODES}"
        return None

    def with_lateral_aero(self, lateral_aero: str) -> Aircraft:
        """This aircraft with its wing's lateral elastic models loaded by ``lateral_aero``
        (``strips`` or ``lattice``; anything else one line)."""
        if lateral_aero not in LATERAL_AERO:
            raise DefinitionError(f"lateral_aero: unknown lateral aerodynamics "
                                  f"{lateral_aero!r}; accepted: {', '.join(LATERAL_AERO)}")
        other = copy.copy(self)
        other.lateral_aero = lateral_aero
        return other

    def wing(self, mass_basis: str = DEFAULT_MASS_BASIS) -> WingBuild:
        """The elastic wing on this airframe (modes, strips, the Table B1/B2 model, the
        :class:`AirframeData` its model carries); a :class:`DefinitionError` with
        :meth:`linear_problem`'s line if the linear analyses cannot take it. Flying it
        is a separate check (:meth:`flight_problem`: the CLI's flight commands and
        ``api.fly_gust``/``compare`` make it). Its ``lateral_aero`` is the aircraft's."""
        return with_lateral_aero(self._wing(mass_basis), self.lateral_aero)

    def _wing(self, mass_basis: str) -> WingBuild:
        if self.flight_problem() is None:
            # the prototype's own planform and airframe objects: flight_problem has checked
            # these equal them, and the nonlinear runs read those objects
            build = build_wing(self.variant(), FLYING_N_MODES, mass_basis, DEFAULT_PLANFORM,
                               PROTOTYPE_AIRFRAME)
        else:
            build = build_wing(self.variant(), FLYING_N_MODES, mass_basis, self.planform(),
                               self.airframe_data())
        stations = tuple(float(s) for s in self.definition.monitoring_stations)
        sensors = self.sensors()
        if stations == DEFAULT_MONITORING_STATIONS and not sensors:
            return build  # the cached build itself
        # the definition's [loads] stations go with its wing into every analysis that
        # reports section loads (gust, compare, api.fly_gust, sweeps), its [sensors] into
        # every run that flies it
        if stations != DEFAULT_MONITORING_STATIONS:
            build = dataclasses.replace(build, monitoring_stations=stations)
        return dataclasses.replace(build, sensors=sensors) if sensors else build

    def sensors(self) -> Sensors:
        """The definition's ``[sensors]`` in body axes from the CG
        (:func:`~bioflex_jsb.definition.sensors.resolve_sensors`); none: an empty
        :class:`~bioflex_jsb.parameters.sensors.Sensors` (the autopilot's IMU at the CG)."""
        return resolve_sensors(self.definition.sensor_stations, self.definition)

    def summary(self) -> dict[str, object]:
        """The definition's airframe and wing as plain data (for logs and --json)."""
        a = self.airframe
        return {"name": self.name, "path": self.definition.path,
                "airframe": {k: (dataclasses.asdict(v) if dataclasses.is_dataclass(v) else v)
                             for k, v in dataclasses.asdict(a).items()},
                "wing": self.variant().as_dict()}


def load_aircraft(name_or_file: str | Path) -> Aircraft:
    """A shipped aircraft by name (``bioflex_<variant>``) or a definition file with an
    ``[airframe]`` (docs/aircraft.md)."""
    return Aircraft(load_definition(name_or_file))


# The aircraft of a call made without one: the prototype with the optimised wing (the paper's
# Fig. 21 case; every shipped bioflex_<variant> has the same airframe).
DEFAULT_AIRCRAFT = "bioflex_optimised"


@functools.cache
def default_aircraft() -> Aircraft:
    """The default aircraft (:data:`DEFAULT_AIRCRAFT`), loaded once: the one place where a
    call made without an aircraft gets the prototype's values (its airframe, speeds,
    planform, post-stall limits). Its :meth:`Aircraft.airframe_data` is the prototype's
    own object, so ``airframe is default_aircraft().airframe_data()`` says whether an
    analysis' airframe is the prototype's."""
    return load_aircraft(DEFAULT_AIRCRAFT)
