"""An aircraft's engines as JSBSim models them, and starting them as JSBSim expects.

The kind of each engine is the root element of its engine file (``piston_engine``,
``turbine_engine``, ``turboprop_engine``, ``electric_engine``, ``rocket_engine``), found as
JSBSim finds it (:mod:`bioflex_jsb.runtime.aircraft_files`). A JSBSim aircraft is loaded
with its engines stopped; the co-simulation flies them running:

* every kind: JSBSim's own ``propulsion/set-running`` (``FGPropulsion::InitRunning``: a
  piston's magnetos on both, its propeller at twice its idle RPM and its mixture leaned
  for the air's pressure, p/(29.92 inHg × 1.3), as a pilot leans it; a turbine's spools
  at idle; the starter not needed), after the initial condition is run so that the
  engines see the flight's air;
* piston: nothing more (JSBSim's propeller lever, ``fcs/advance-cmd-norm``, is left where
  the aircraft's file puts it: set to 1 it stopped the pa28's IO-360 in every trim);
* turboprop: the condition lever (JSBSim's mixture command) forward;
* electric: nothing more (a motor runs when it has a throttle);
* rocket: refused (a rocket's burn is not a steady flight to trim).

A glider (no engine) has nothing to start and is trimmed to its steady glide.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from bioflex_jsb.runtime.aircraft_files import named_files, read_aircraft_xml, read_xml
from bioflex_jsb.runtime.results import AircraftLoadError, TrimError
from bioflex_jsb.simulation import jsbsim_properties as JP

KINDS = {"piston_engine": "piston", "turbine_engine": "turbine",
         "turboprop_engine": "turboprop", "electric_engine": "electric",
         "rocket_engine": "rocket"}
SUPPORTED = ("piston", "turbine", "turboprop", "electric")


@dataclass(frozen=True)
class Engine:
    """One engine: its index in JSBSim (``propulsion/engine[i]``), its kind (:data:`KINDS`'
    values) and its file's name."""

    index: int
    kind: str
    file: str


def engines_of(aircraft_path: str | Path) -> tuple[Engine, ...]:
    """The engines of the aircraft file, in JSBSim's order (module docstring)."""
    path = Path(aircraft_path)
    tree = read_aircraft_xml(path)
    engines = []
    for named in named_files(path, tree):
        if named.element != "engine":
            continue
        tag = read_xml(named.source, "the engine file").getroot().tag
        kind = KINDS.get(tag)
        if kind is None:
            raise AircraftLoadError(f"the engine file {str(named.source)!r} is a <{tag}>: "
                                    f"not an engine JSBSim knows ({', '.join(KINDS)})")
        engines.append(Engine(len(engines), kind, named.name))
    if any(e.kind not in SUPPORTED for e in engines):
        bad = next(e for e in engines if e.kind not in SUPPORTED)
        raise AircraftLoadError(f"engine {bad.index} ({bad.file}) is a {bad.kind} engine: "
                                f"the co-simulation trims {', '.join(SUPPORTED)} engines in "
                                "steady flight, not a rocket's burn")
    return tuple(engines)


def start(fdm, engines: tuple[Engine, ...]) -> None:
    """Start ``engines`` of ``fdm`` (a ``jsbsim.FGFDMExec`` at its initial condition) as
    the module docstring says, and check they run (:class:`TrimError`: one line naming the
    engine that did not start)."""
    if not engines:
        return
    manager = fdm.get_property_manager()
    fdm.run_ic()
    fdm[JP.PROPULSION_SET_RUNNING] = -1
    for e in engines:
        levers = {"turboprop": (JP.FCS_MIXTURE_CMD_NORM,)}.get(e.kind, ())
        for lever in levers:
            name = f"{lever}[{e.index}]"
            if manager.hasNode(name):
                fdm[name] = 1.0
    fdm.run_ic()
    for e in engines:
        name = JP.engine(e.index, "set-running")
        if manager.hasNode(name) and fdm[name] < 0.5:
            raise TrimError(f"engine {e.index} ({e.kind}, {e.file}) did not start: JSBSim "
                            f"leaves it stopped after propulsion/set-running (its fuel, "
                            "electrical or starter systems may hold it; see the aircraft's "
                            "Systems/)")


@lru_cache(maxsize=8)
def zero_thrust_advance_ratio(aircraft_path: Path) -> float:
    """J at which the propeller's C_T(J) crosses zero [-] (windmilling), from the C_THRUST
    table of the aircraft's first thruster file (``Engines/<file>.xml`` beside it): the
    table JSBSim flies, read rather than recomputed (the blade-element model that wrote it,
    :mod:`bioflex_jsb.aerodynamics.propeller`, needs scipy's optimisers, ~30 MB of memory a
    run does not otherwise need)."""
    aircraft = read_aircraft_xml(aircraft_path).getroot()
    thruster = aircraft.find(".//propulsion/engine/thruster")
    if thruster is None or not thruster.get("file"):
        raise AircraftLoadError(f"{str(aircraft_path)!r} has no propeller (thruster file)")
    prop_path = aircraft_path.parent / "Engines" / f"{thruster.get('file')}.xml"
    table = read_xml(prop_path, "the propeller").getroot().find(
        ".//table[@name='C_THRUST']/tableData")
    if table is None or not (table.text or "").strip():
        raise AircraftLoadError(f"{str(prop_path)!r} has no C_THRUST table")
    rows = np.array([float(x) for x in table.text.split()]).reshape(-1, 2)
    j, ct = rows[:, 0], rows[:, 1]
    if not np.any(ct <= 0.0) or ct[0] <= 0.0:
        raise AircraftLoadError(f"the C_THRUST table of {str(prop_path)!r} does not cross zero")
    k = int(np.argmax(ct <= 0.0))
    return float(j[k - 1] + (j[k] - j[k - 1]) * ct[k - 1] / (ct[k - 1] - ct[k]))
