"""The native modal-wing aircraft (the wing in JSBSim's XML): its trim for the console program
(the Fig. 21 case's and an export's), its files, and the aircraft loaded once for the benchmark.

A native run is :func:`bioflex_jsb.drivers.gust.run_gust` with the model ``native``: the same
coupled step, with JSBSim flying the wing. Regenerate the repository's native files with
``python -m bioflex_jsb.drivers.native`` (they need a JSBSim trim, so their writer is a
driver; the XML itself is :mod:`bioflex_jsb.generators.native_wing`'s).
"""

from __future__ import annotations

import argparse
import math
import re
import sys
import tempfile
from functools import lru_cache
from pathlib import Path

import numpy as np

from bioflex_jsb import units as U
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

# Glide trim (:func:`glide_trim_state`): Newton on (α, γ, elevator) until |u̇|, |ẇ| are below
# GLIDE_TRIM_TOL_FPS2 [ft/s²] and |q̇| below GLIDE_TRIM_TOL_RAD_S2 [rad/s²]. Left over 2 s,
# 1e-6 ft/s² moves the speed by 2e-6 ft/s and 1e-7 rad/s² the pitch rate by 2e-7 rad/s, 1e-5
# and 4e-5 of what a 0.3 m/s gust makes (vt 0.19 ft/s, q 4.7e-3 rad/s). Measured on the SGS:
# 4 Newton steps to 3.6e-12 ft/s² and 2.3e-14 rad/s² at 25 m/s; 3-5 steps at 18-28 m/s; no
# glide at 17 m/s (stall) nor at 32 m/s (C_L 0.39, under the CLwbh table's first 0.43). Finite
# differences of GLIDE_TRIM_STEP [rad, -]:
# JSBSim's tables are piecewise linear, so a small step sees the slope of the segment.
GLIDE_TRIM_TOL_FPS2 = 1e-6
GLIDE_TRIM_TOL_RAD_S2 = 1e-7
GLIDE_TRIM_STEP = 1e-6
GLIDE_TRIM_ITERATIONS = 25
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


def _glide_state(af: Airframe, v_fps: float, x: np.ndarray) -> np.ndarray:
    """(u̇ [ft/s²], ẇ [ft/s²], q̇ [rad/s²]) of ``af`` restarted at airspeed ``v_fps`` with
    x = (α [rad], γ [rad], elevator command [-]), wings level (JSBSim's RunIC: dt = 0)."""
    af["ic/vt-fps"] = v_fps
    af["ic/gamma-rad"] = x[1]
    af["ic/alpha-rad"] = x[0]
    af["fcs/elevator-cmd-norm"] = x[2]
    af.restart_from_initial_conditions()
    return np.array([af["accelerations/udot-ft_sec2"], af["accelerations/wdot-ft_sec2"],
                     af["accelerations/qdot-rad_sec2"]])


def glide_trim_state(files: dict[str, str], spec: J.ExportSpec) -> NA.TrimState:
    """Glide trim of an exported glider (``files``: its aircraft and system, written to a
    temporary root and loaded there; never into the user's): steady, straight, wings-level
    flight at ``spec.speed_m_s`` [m/s] true airspeed, ISA sea level, the flight-path angle γ
    (negative: descending), α and the elevator solved by Newton (constants above) from the
    linear model's glide (C_L from the weight, γ = −atan(C_D/C_L)). JSBSim's own trim cannot
    trim a glider (u̇ needs the throttle). The modal loads are zero: the wing is held at its
    trim reference while JSBSim's step is 0. Raises TrimError (one line)."""
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition

    cond = level_flight_condition(spec.speed_m_s, spec.rho_ref, airframe=spec.wing.airframe)
    x = np.array([cond.alpha_trim_rad, -math.atan(cond.cd_trim / cond.cl_trim), 0.0])
    with tempfile.TemporaryDirectory(prefix="bioflex-glide-trim-") as tmp:
        write_export(files, Path(tmp))
        af = Airframe(tmp, spec.aircraft_name)
        if af.engine_count:
            raise TrimError(f"aircraft {spec.aircraft_name!r} has {af.engine_count} engines: "
                            "the glide trim is for an aircraft without one")
        af.set_initial_conditions(spec.speed_m_s)
        v_fps = spec.speed_m_s * U.FT_PER_M
        scale = np.array([GLIDE_TRIM_TOL_FPS2, GLIDE_TRIM_TOL_FPS2, GLIDE_TRIM_TOL_RAD_S2])
        for _ in range(GLIDE_TRIM_ITERATIONS):
            f = _glide_state(af, v_fps, x)
            if np.all(np.abs(f) <= scale):
                break
            jac = np.column_stack([(_glide_state(af, v_fps, x + GLIDE_TRIM_STEP * e) - f)
                                   / GLIDE_TRIM_STEP for e in np.eye(3)])
            try:
                x = x - np.linalg.solve(jac, f)
            except np.linalg.LinAlgError:
                raise TrimError(f"aircraft {spec.aircraft_name!r}: no glide trim at "
                                f"{spec.speed_m_s:g} m/s: u-dot, w-dot, q-dot do not change "
                                "with alpha, gamma and the elevator there (a flat end of a "
                                "table or a dead elevator); try another --speed") from None
        else:
            raise TrimError(f"aircraft {spec.aircraft_name!r}: no glide trim at "
                            f"{spec.speed_m_s:g} m/s (residual u-dot {f[0]:.3g} ft/s2, w-dot "
                            f"{f[1]:.3g} ft/s2, q-dot {f[2]:.3g} rad/s2 after "
                            f"{GLIDE_TRIM_ITERATIONS} Newton steps: beyond the aircraft's "
                            "tables (stall, their end in alpha) or its elevator; try another "
                            "--speed)")
        # the last evaluation was at x: af holds the trimmed state
        if not -1.0 <= x[2] <= 1.0:
            raise TrimError(f"aircraft {spec.aircraft_name!r}: the glide at "
                            f"{spec.speed_m_s:g} m/s needs elevator command {x[2]:.3g}, "
                            "beyond its travel (-1..1): try another --speed")
        state = _state(af)
        controls = {name: af[name] for name in TRIM_CONTROLS}
    return NA.TrimState(state, controls, spec.speed_m_s, 0.0, 0.0, gamma_rad=float(x[1]))


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
