"""The native modal-wing aircraft (the wing in JSBSim's XML): its trim for the console program
(the Fig. 21 case's and an export's), its files, and the aircraft loaded once for the benchmark.

A native run is :func:`bioflex_jsb.drivers.gust.run_gust` with the model ``native``: the same
coupled step, with JSBSim flying the wing. Regenerate the repository's native files with
``python -m bioflex_jsb.drivers.native`` (they need a JSBSim trim, so their writer is a
driver; the XML itself is :mod:`bioflex_jsb.generators.native_wing`'s).
"""

from __future__ import annotations

import argparse
import re
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

from bioflex_jsb.definition.airframe import GENERATED
from bioflex_jsb.definition.flying import flight_speeds
from bioflex_jsb.definition.reader import DefinitionError
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.generators import native_aircraft as NA
from bioflex_jsb.generators import native_wing as J
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3
from bioflex_jsb.runtime.coupled_step import configure_airframe
from bioflex_jsb.runtime.fdm import TRIM_CONTROLS, Airframe
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S

# The exported flights start at ISA sea level (as the prototype's: TrimState): a definition's
# air density must be that one's, to the rounding of a printed 1.225 (1e-9 relative).
DENSITY_REL_TOL = 1e-9


def trim_state(speed_m_s: float = P.SECTION5_AIRSPEED_M_S,
               dt_s: float = DEFAULT_DT_S) -> NA.TrimState:
    """Level trim at ``speed_m_s`` [m/s], ISA sea level, by :meth:`Airframe.trim` (the
    co-simulation's trim: same integrators and step ``dt_s`` [s]) of the rigid airframe, read
    from the flying instance. The native aircraft's trim is the same: its trim companion is the
    airframe's, and the modal loads are zero at the trim reference. Raises TrimError (one
    line) where level flight cannot be trimmed."""
    af = Airframe()
    configure_airframe(af, dt_s)
    trim = af.trim(speed_m_s)
    ic = _state(af)
    names = TRIM_CONTROLS + tuple(f"fcs/throttle-cmd-norm[{i}]" for i in range(af.engine_count))
    return NA.TrimState(ic, {name: af[name] for name in names}, trim.speed_m_s,
                        trim.propeller_rpm, af.last_rpm_settle_s)


def fig21_trim_state(dt_s: float = DEFAULT_DT_S) -> NA.TrimState:
    """Trim of the Fig. 21 case (:func:`trim_state` at the paper's 15 m/s)."""
    return trim_state(P.SECTION5_AIRSPEED_M_S, dt_s)


def aircraft_trim_state(files: dict[str, str], spec: J.ExportSpec) -> NA.TrimState:
    """Trim of an exported aircraft file (``files``: its aircraft, the files it names and
    the system, written to a temporary root and loaded there, never into the user's) at
    ``spec.speed_m_s`` [m/s] true airspeed, ISA sea level, by :meth:`Airframe.trim` with the
    export's step and integrators, as :func:`trim_state` trims the prototype: a glider's
    steady, straight, wings-level glide (α, the flight-path angle γ and the pitch trim by
    Newton in JSBSim's initial-condition run, runtime/trim.py); a powered aircraft's level
    flight, its engines started as JSBSim expects (runtime/engines.py) and trimmed by
    JSBSim. The controls kept are the trim's surfaces and each engine's levers JSBSim has
    (throttle, mixture, propeller advance, turboprop condition) as the trim left them. The
    modal loads are zero in it: the wing is held at its trim reference while JSBSim's step
    is 0. Raises TrimError (one line)."""
    with tempfile.TemporaryDirectory(prefix="bioflex-export-trim-") as tmp:
        write_export(files, Path(tmp))
        af = Airframe(tmp, spec.aircraft_name)
        configure_airframe(af, spec.dt_s, modal_hooks=False)
        trim = af.trim(spec.speed_m_s)
        controls = {name: af[name] for name in TRIM_CONTROLS}
        for i in range(af.engine_count):
            for lever in ENGINE_LEVERS:
                name = f"{lever}[{i}]"
                if af.has_property(name):
                    controls[name] = af[name]
        return NA.TrimState(_state(af), controls, trim.speed_m_s, trim.propeller_rpm, 0.0,
                            gamma_rad=trim.flight_path_rad)


# An engine's levers, per engine (``<lever>[i]``), kept in an exported trim where JSBSim has
# them: FGFCS's throttle, mixture and propeller-advance commands (a turboprop's condition
# lever is its mixture command).
ENGINE_LEVERS = ("fcs/throttle-cmd-norm", "fcs/mixture-cmd-norm", "fcs/advance-cmd-norm")


def carried_files(spec: J.ExportSpec) -> dict[str, str]:
    """The files the aircraft file ``spec.jsbsim_path`` names (engines, propellers,
    systems, sections), found as JSBSim finds them (runtime/aircraft_files.py) and put in
    the exported aircraft's folder where JSBSim looks first (``Engines/``, ``Systems/``, the
    folder itself): path from the JSBSim root → text, each after a comment naming its
    original (so a later export replaces it as its own). Read with the bounds of every
    input file; ExportError (one line) for a file that is not UTF-8 text."""
    from bioflex_jsb.runtime.aircraft_files import (
        named_files,
        read_aircraft_xml,
        read_named_files,
    )

    src = Path(spec.jsbsim_path)
    named = named_files(src, read_aircraft_xml(src))
    sources = {f.target: f.source for f in named}
    out = {}
    for target, data in read_named_files(src, named).items():
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            raise J.ExportError(f"{str(sources[target])!r} is not UTF-8 text: the export "
                                "copies the files an aircraft names as text") from None
        note = (f"<!-- GENERATED by bioflex_jsb.drivers.native (bioflex-jsb export-jsbsim): "
                f"a copy of {sources[target]}. Do not edit. -->")
        out[f"aircraft/{spec.aircraft_name}/{target}"] = NA.with_note(text, note)
    return out


def _state(af: Airframe) -> dict[str, tuple[str, float]]:
    """The state of ``af`` as initial-condition elements (element → (unit, value))."""
    return {
        "ubody": ("FT/SEC", af["velocities/u-fps"]),
        "vbody": ("FT/SEC", af["velocities/v-fps"]),
        "wbody": ("FT/SEC", af["velocities/w-fps"]),
        "p": ("RAD/SEC", af["velocities/p-rad_sec"]),
        "q": ("RAD/SEC", af["velocities/q-rad_sec"]),
        "r": ("RAD/SEC", af["velocities/r-rad_sec"]),
        "elevation": ("FT", af["position/terrain-elevation-asl-ft"]),
        "altitudeMSL": ("FT", af["position/h-sl-ft"]),
        "phi": ("RAD", af["attitude/phi-rad"]),
        "theta": ("RAD", af["attitude/theta-rad"]),
        "psi": ("RAD", af["attitude/psi-rad"]),
        "latitude": ("RAD", af["position/lat-geod-rad"]),
        "longitude": ("RAD", af["position/long-gc-rad"]),
    }


def aircraft_spec(aircraft, build, model: str = "coupled", dt_s: float = DEFAULT_DT_S,
                  speed_m_s: float | None = None) -> J.ExportSpec:
    """The :class:`~bioflex_jsb.generators.native_wing.ExportSpec` of an aircraft definition
    (``aircraft``: :class:`bioflex_jsb.definition.aircraft.Aircraft`, ``build``: its wing,
    :meth:`~bioflex_jsb.definition.aircraft.Aircraft.wing`): the generated prototype's
    airframe exports as ``--wing`` does (aircraft ``bioflex_<wing>``); an aircraft file's
    (``airframe.jsbsim``: a jsbsim package aircraft or a directory) as a copy of that file
    named after the definition, with the wing's values (S, c̄, mass, derivatives) from the
    definition and the chord of ``aero/ci2vel`` from the file; trimmed at ``speed_m_s``
    [m/s] (None: the aircraft's cruise speed). Raises DefinitionError or ExportError (one
    line)."""
    a, d = aircraft.airframe, aircraft.definition
    rho = d.air.density_kg_m3
    if abs(rho - SEA_LEVEL_DENSITY_KG_M3) > DENSITY_REL_TOL * SEA_LEVEL_DENSITY_KG_M3:
        raise DefinitionError(f"aircraft {d.name!r}: air.density_kg_m3 = {rho:g}: the exported "
                              "flight starts at ISA sea level, accepted: "
                              f"{SEA_LEVEL_DENSITY_KG_M3:g} kg/m3")
    wing, variant = build.model, build.variant.name
    if a.jsbsim == GENERATED:
        problem = aircraft.flight_problem()  # the generated XML holds the prototype's numbers
        if problem:
            raise DefinitionError(problem)
    cruise, speeds = flight_speeds(aircraft)
    speed_m_s = cruise if speed_m_s is None else speed_m_s
    if a.jsbsim == GENERATED:
        return J.ExportSpec(wing, variant, model, dt_s, speed_m_s, rho)
    craft = re.sub(r"[^A-Za-z0-9_-]+", "_", d.name)
    return J.ExportSpec(wing, variant, model, dt_s, speed_m_s, rho, jsbsim_path=a.jsbsim_path,
                        aircraft=craft, jsbsim_chord_m=NA.jsbsim_chord_m(a.jsbsim_path),
                        speed_range_m_s=(float(speeds[0]), float(speeds[1])))


def export_flight(spec: J.ExportSpec, gust_up_m_s: float = P.SECTION5_GUST_AMPLITUDE_M_S,
                  ) -> tuple[NA.FlightCase, NA.TrimState, dict[str, str]]:
    """``bioflex-jsb export-jsbsim``'s files: the trim at the export's speed (an aircraft
    file's glider: :func:`glide_trim_state`), then the system, the aircraft, the trim as an
    initial condition and a script
    (:func:`~bioflex_jsb.generators.native_aircraft.export_case`). Returns the case, the trim
    and the files (path from the JSBSim root → text; write them with
    :func:`write_export`). Raises TrimError (one line), ExportError."""
    if spec.jsbsim_path:
        carried = carried_files(spec)
        names = frozenset(f.name for f in _named(spec))
        files = NA.render_aircraft_files(spec, carried=names)
        files.update(carried)
        state = aircraft_trim_state(files, spec)
    else:
        files = NA.render_aircraft_files(spec)
        state = trim_state(spec.speed_m_s, spec.dt_s)
    case = NA.export_case(spec, state, gust_up_m_s)
    files.update(NA.flight_files(state, case))
    return case, state, files


def _named(spec: J.ExportSpec):
    from bioflex_jsb.runtime.aircraft_files import named_files, read_aircraft_xml

    src = Path(spec.jsbsim_path)
    return named_files(src, read_aircraft_xml(src))


def write_export(files: dict[str, str], out_dir: Path) -> list[Path]:
    """Write :func:`export_flight`'s files under the JSBSim root ``out_dir``; the paths.
    Raises OSError."""
    return airframe_xml.write_files(files, out_dir)


def repository_files() -> dict[str, str]:
    """The repository's native files (systems, aircraft, the Fig. 21 initial condition and
    script): path → text."""
    return NA.repository_files(fig21_trim_state())


def write_repository(root: Path) -> list[Path]:
    """Write :func:`repository_files` under the JSBSim root ``root``; return the paths."""
    return airframe_xml.write_files(repository_files(), root)


@lru_cache(maxsize=len(J.REPOSITORY_VARIANTS))
def native_airframe(variant: str = "original") -> Airframe:
    """The repository's native modal-wing aircraft of ``variant``, loaded once per process
    and set to the exported step, for ``bioflex-jsb bench`` (at most one per named wing)."""
    af = Airframe(aircraft=J.aircraft_name(variant))
    af.set_dt(DEFAULT_DT_S)
    return af


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m bioflex_jsb.drivers.native",
        description="Regenerate the repository's native modal-wing systems, aircraft and script.",
    )
    parser.add_argument("--root", type=Path, default=airframe_xml.default_output_root())
    args = parser.parse_args(argv)
    for path in write_repository(args.root):
        print(path)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
