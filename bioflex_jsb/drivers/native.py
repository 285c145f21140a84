"""The native modal-wing aircraft (the wing in JSBSim's XML): its trim for the console program
(the Fig. 21 case's and an export's), its files, and the aircraft loaded once for the benchmark.

A native run is :func:`bioflex_jsb.drivers.gust.run_gust` with the model ``native``: the same
coupled step, with JSBSim flying the wing. Regenerate the repository's native files with
``python -m bioflex_jsb.drivers.native`` (they need a JSBSim trim, so their writer is a
driver; the XML itself is :mod:`bioflex_jsb.generators.native_wing`'s).
"""

from __future__ import annotations

import argparse
import sys
from functools import lru_cache
from pathlib import Path

from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.generators import native_aircraft as NA
from bioflex_jsb.generators import native_wing as J
from bioflex_jsb.parameters import prototype as P
from bioflex_jsb.runtime.coupled_step import configure_airframe
from bioflex_jsb.runtime.fdm import TRIM_CONTROLS, Airframe
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S


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
    ic = {
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
    names = TRIM_CONTROLS + tuple(f"fcs/throttle-cmd-norm[{i}]" for i in range(af.engine_count))
    return NA.TrimState(ic, {name: af[name] for name in names}, trim.speed_m_s,
                        trim.propeller_rpm, af.last_rpm_settle_s)


def fig21_trim_state(dt_s: float = DEFAULT_DT_S) -> NA.TrimState:
    """Trim of the Fig. 21 case (:func:`trim_state` at the paper's 15 m/s)."""
    return trim_state(P.SECTION5_AIRSPEED_M_S, dt_s)


def export_flight(spec: J.ExportSpec, gust_up_m_s: float = P.SECTION5_GUST_AMPLITUDE_M_S,
                  ) -> tuple[NA.FlightCase, NA.TrimState, dict[str, str]]:
    """``bioflex-jsb export-jsbsim``'s files: the trim at the export's speed, then the system,
    the aircraft, the trim as an initial condition and a script
    (:func:`~bioflex_jsb.generators.native_aircraft.export_case`). Returns the case, the trim
    and the files (path from the JSBSim root → text; write them with
    :func:`write_export`). Raises TrimError (one line), ExportError."""
    state = trim_state(spec.speed_m_s, spec.dt_s)
    case = NA.export_case(spec, state, gust_up_m_s)
    files = NA.render_aircraft_files(spec)
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
