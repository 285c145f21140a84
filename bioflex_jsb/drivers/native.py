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
from bioflex_jsb.definition.reader import DefinitionError
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.generators import native_aircraft as NA
from bioflex_jsb.generators import native_wing as J
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.parameters.constants import SEA_LEVEL_DENSITY_KG_M3
from bioflex_jsb.runtime.coupled_step import configure_airframe
from bioflex_jsb.runtime.fdm import TRIM_CONTROLS, Airframe
from bioflex_jsb.runtime.results import TrimError
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


def glide_trim_state(files: dict[str, str], spec: J.ExportSpec) -> NA.TrimState:
    """Glide trim of an exported glider (``files``: its aircraft and system, written to a
    temporary root and loaded there, never into the user's): the steady, straight,
    wings-level glide at ``spec.speed_m_s`` [m/s] true airspeed, ISA sea level, by
    :meth:`Airframe.trim` (an aircraft without an engine: α, the flight-path angle γ and the
    pitch trim by Newton in JSBSim's initial-condition run, runtime/glide.py) with
    the export's step and integrators, as :func:`trim_state` trims the prototype. The modal
    loads are zero in it: the wing is held at its trim reference while JSBSim's step is 0.
    Raises TrimError (one line)."""
    with tempfile.TemporaryDirectory(prefix="bioflex-glide-trim-") as tmp:
        write_export(files, Path(tmp))
        af = Airframe(tmp, spec.aircraft_name)
        if not af.glider:
            raise TrimError(f"aircraft {spec.aircraft_name!r} has {af.engine_count} engines: "
                            "an aircraft file's export is trimmed to a glide")
        configure_airframe(af, spec.dt_s, modal_hooks=False)
        trim = af.trim(spec.speed_m_s)
        return NA.TrimState(_state(af), {name: af[name] for name in TRIM_CONTROLS},
                            trim.speed_m_s, 0.0, 0.0, gamma_rad=trim.flight_path_rad)


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
                  speed_m_s: float = P.CRUISE_SPEED_M_S) -> J.ExportSpec:
    """The :class:`~bioflex_jsb.generators.native_wing.ExportSpec` of an aircraft definition
    (``aircraft``: :class:`bioflex_jsb.definition.aircraft.Aircraft`, ``build``: its wing,
    :meth:`~bioflex_jsb.definition.aircraft.Aircraft.wing`): the generated prototype's
    airframe exports as ``--wing`` does (aircraft ``bioflex_<wing>``); an aircraft file's
    (``airframe.jsbsim``: a jsbsim package aircraft or a directory) as a copy of that file
    named after the definition, with the wing's values (S, c̄, mass, derivatives) from the
    definition and the chord of ``aero/ci2vel`` from the file. Raises DefinitionError or
    ExportError (one line)."""
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
        return J.ExportSpec(wing, variant, model, dt_s, speed_m_s, rho)
    craft = re.sub(r"[^A-Za-z0-9_-]+", "_", d.name)
    return J.ExportSpec(wing, variant, model, dt_s, speed_m_s, rho, jsbsim_path=a.jsbsim_path,
                        aircraft=craft, jsbsim_chord_m=NA.jsbsim_chord_m(a.jsbsim_path))


def export_flight(spec: J.ExportSpec, gust_up_m_s: float = P.SECTION5_GUST_AMPLITUDE_M_S,
                  ) -> tuple[NA.FlightCase, NA.TrimState, dict[str, str]]:
    """``bioflex-jsb export-jsbsim``'s files: the trim at the export's speed (an aircraft
    file's glider: :func:`glide_trim_state`), then the system, the aircraft, the trim as an
    initial condition and a script
    (:func:`~bioflex_jsb.generators.native_aircraft.export_case`). Returns the case, the trim
    and the files (path from the JSBSim root → text; write them with
    :func:`write_export`). Raises TrimError (one line), ExportError."""
    files = NA.render_aircraft_files(spec)
    if spec.jsbsim_path:
        state = glide_trim_state(files, spec)
    else:
        state = trim_state(spec.speed_m_s, spec.dt_s)
    case = NA.export_case(spec, state, gust_up_m_s)
    files.update(NA.flight_files(state, case))
    return case, state, files


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
