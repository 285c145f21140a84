"""Another JSBSim aircraft in the co-simulation (docs/aircraft.md, "What runs with another
airframe"): the modal wing's hooks added to its XML, the range of its α tables, and the
steady-glide trim of an aircraft without an engine.

The hooks. The co-simulation writes the elastic wing's incremental loads into four external
reactions (:mod:`bioflex_jsb.generators.airframe`: ``modal-lift``, ``modal-drag`` at the CG,
body axes; ``modal-pitch``, ``modal-roll`` moments). The generated prototype has them in its
XML; another aircraft (a jsbsim package aircraft such as ``SGS``, or a user's directory) is
loaded from a copy of its directory, in a temporary JSBSim root made for the
:class:`~bioflex_jsb.runtime.fdm.Airframe` (deleted with it), whose XML has the same four
reactions added at the definition's CG (``airframe.cg_m``, structural frame, metres → inches
at 39.37 in/m); nothing the user wrote is changed. The root's ``engine/`` and ``systems/``
are the jsbsim package's (links), so an aircraft that names the package's engines loads.

The steady glide. JSBSim's trim (``FGFDMExec::DoTrim``) trims u̇ with the throttle; an
aircraft without an engine (SGS.xml's ``<propulsion>`` is empty) cannot hold its speed in
level flight ("udot doesn't appear to be trimmable"). The physically consistent steady state
at a given airspeed is the steady glide: drag balanced by the weight's component along the
path, D = −W sin γ, L = W cos γ. :func:`glide_trim` solves for the angle of attack α, the
flight-path angle γ (negative: descending) and the pitch-trim command that zero JSBSim's own
u̇, ẇ (ft/s²) and q̇ (rad/s²) in JSBSim's initial-condition evaluation (``RunIC``: the
forces and moments of the state, nothing integrated), wings level, by Newton's method with
a finite-difference Jacobian: the trim JSBSim would make with γ as its u̇ control.
"""

from __future__ import annotations

import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.aircraft_files import private_root, read_aircraft_xml
from bioflex_jsb.runtime.results import AircraftLoadError, TrimError

INCH_PER_M = 1.0 / 0.0254  # the inch is 0.0254 m exactly
# The glide trim's convergence: JSBSim's own trim tolerances are 1e-3 ft/s² on u̇, ẇ and
# 1e-4 rad/s² on q̇ (FGTrimAxis; runtime/fdm.py TRIM_TOLERANCE_*); Newton is asked for
# 1e-3 of them, which it reaches in 3-5 iterations (the tables are linear between their
# points: measured 4 iterations at 20-28 m/s for SGS, residuals below 1e-9).
GLIDE_TOL_FT_S2 = 1e-6
GLIDE_TOL_RAD_S2 = 1e-7
GLIDE_MAX_ITERATIONS = 30
# Finite-difference steps of the Jacobian [rad, rad, -]: 1e-7 rad moves α by a millionth
# of a table interval (1° = 0.0175 rad), so a step crosses a table point at most once in
# ten thousand evaluations; the residuals are O(10 ft/s²) per rad, so the differences keep
# 8 significant digits.
FD_STEP = 1e-7
# The γ search is bounded: a glide steeper than 45° is no glide (L/D < 1).
GAMMA_LIMIT_RAD = math.radians(45.0)
PITCH_TRIM = "fcs/pitch-trim-cmd-norm"  # the control JSBSim's full trim moves for q̇


def derived_root(jsbsim_path: str, cg_m: tuple[float, float, float],
                 systems: dict[str, str] | None = None
                 ) -> tuple[tempfile.TemporaryDirectory, str]:
    """A temporary JSBSim root holding a copy of the aircraft ``jsbsim_path``
    (``<dir>/<name>.xml``) with the modal-wing reactions at ``cg_m`` [m, structural frame]:
    (the directory, the aircraft's name). ``systems``: system files to add (file name
    without ``.xml`` → its text; the SITL glider's autopilot,
    :func:`bioflex_jsb.generators.autopilot.render_glider_autopilot`), written to the copy's
    ``Systems/`` (JSBSim looks there first) and included ahead of its flight controls, in
    order (JSBSim cannot add a system to a loaded model). Raises :class:`AircraftLoadError`
    (one line) for a file JSBSim could not read either or one that has the reactions
    already."""
    src = Path(jsbsim_path)
    tree = read_aircraft_xml(src)
    root = tree.getroot()
    ext = root.find("external_reactions")
    if ext is None:
        ext = ET.SubElement(root, "external_reactions")
    taken = {e.get("name") for e in ext}
    hooks = {**airframe_xml.EXTERNAL_FORCES, **airframe_xml.EXTERNAL_MOMENTS}
    clash = sorted(taken & set(hooks))
    if clash:
        raise AircraftLoadError(f"{str(src)!r} already has an external reaction named "
                                f"{clash[0]!r} (the modal wing's hooks' names)")
    for name_, (direction, _text) in airframe_xml.EXTERNAL_FORCES.items():
        f = ET.SubElement(ext, "force", name=name_, frame="BODY", unit="LBS")
        loc = ET.SubElement(f, "location", unit="IN")
        for axis, value in zip("xyz", cg_m, strict=True):
            ET.SubElement(loc, axis).text = repr(value * INCH_PER_M)
        _direction(f, direction)
    for name_, (direction, _text) in airframe_xml.EXTERNAL_MOMENTS.items():
        _direction(ET.SubElement(ext, "moment", name=name_, frame="BODY", unit="LBSFT"),
                   direction)
    if systems:
        fcs = root.find("flight_control")
        at = list(root).index(fcs) if fcs is not None else len(root)
        for i, file in enumerate(systems):
            root.insert(at + i, ET.Element("system", file=file))
    for key in [k for k in root.attrib if k.startswith("{")]:  # the schema's location
        del root.attrib[key]
    own = {f"{file}.xml": text for file, text in (systems or {}).items()}
    work, name = private_root(src, tree, own)
    return work, name


def _direction(parent: ET.Element, direction: tuple[float, float, float]) -> None:
    d = ET.SubElement(parent, "direction")
    for axis, value in zip("xyz", direction, strict=True):
        ET.SubElement(d, axis).text = repr(float(value))


LIFT_AXES = ("LIFT", "NORMAL", "Z")  # JSBSim's names of the axis that carries the lift


def _alpha_tables(element: ET.Element) -> list[tuple[float, float]]:
    """The α range [rad] of each table under ``element`` with α as its row variable
    (``aero/alpha-rad`` or ``aero/alpha-deg``)."""
    out = []
    for table in element.iter("table"):
        variables = table.findall("independentVar")
        if not variables:
            continue
        row = next((v for v in variables if v.get("lookup") == "row"), variables[0])
        var = (row.text or "").strip()
        if var not in ("aero/alpha-rad", "aero/alpha-deg"):
            continue
        lines = [ln.split() for ln in (table.findtext("tableData") or "").strip().splitlines()
                 if ln.split()]
        if len(variables) > 1:
            lines = lines[1:]  # the first line holds the column breakpoints
        alphas = [float(ln[0]) for ln in lines]
        scale = 1.0 if var.endswith("rad") else math.pi / 180.0
        out.append((min(alphas) * scale, max(alphas) * scale))
    return out


def alpha_table_range_rad(path: str | os.PathLike) -> tuple[float, float]:
    """The α range [rad] of the aircraft's lift curve: the widest table over α in its lift
    axis (``<axis name="LIFT">``, or ``NORMAL``/``Z``). Beyond it JSBSim holds the table's
    end value, so the aircraft's aerodynamics end there (the run stops:
    simulation/limits.py). Narrower α tables (increments of flaps, ground effect, stall
    hysteresis) are held constant outside their range by their authors' design and do not
    bound it. An aircraft whose lift axis names its tables only through functions defined
    elsewhere: the common α range of all its tables. One without any α table is refused."""
    root = read_aircraft_xml(path).getroot()
    lift = [r for axis in root.iter("axis") if axis.get("name", "").upper() in LIFT_AXES
            for r in _alpha_tables(axis)]
    if lift:
        return max(lift, key=lambda r: r[1] - r[0])
    every = _alpha_tables(root)
    lo = max((r[0] for r in every), default=math.inf)
    hi = min((r[1] for r in every), default=-math.inf)
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi):
        raise AircraftLoadError(f"{str(path)!r} has no aerodynamic table over the angle of "
                                "attack (aero/alpha-rad or -deg): its valid range of alpha is "
                                "unknown")
    return lo, hi


def glide_trim(fdm, speed_m_s: float) -> int:
    """Trim ``fdm`` (a JSBSim instance at its initial condition: wings level, true airspeed
    ``speed_m_s`` [m/s], controls zero) to the steady glide (module docstring); returns the
    Newton iterations taken. The instance is left at the trimmed initial condition.
    Raises :class:`TrimError` (one line) when no glide is found."""
    def residuals(x: np.ndarray) -> np.ndarray:
        fdm["ic/gamma-rad"] = x[1]
        fdm["ic/alpha-rad"] = x[0]
        fdm[PITCH_TRIM] = x[2]
        fdm.run_ic()
        return np.array([fdm["accelerations/udot-ft_sec2"], fdm["accelerations/wdot-ft_sec2"],
                         fdm["accelerations/qdot-rad_sec2"]])

    tol = np.array([GLIDE_TOL_FT_S2, GLIDE_TOL_FT_S2, GLIDE_TOL_RAD_S2])
    x = np.zeros(3)
    r = residuals(x)
    for iteration in range(1, GLIDE_MAX_ITERATIONS + 1):
        jac = np.empty((3, 3))
        for j in range(3):
            xj = x.copy()
            xj[j] += FD_STEP
            jac[:, j] = (residuals(xj) - r) / FD_STEP
        if not np.all(np.isfinite(jac)) or abs(np.linalg.det(jac)) < 1e-300:
            break
        x = x - np.linalg.solve(jac, r)
        if abs(x[1]) > GAMMA_LIMIT_RAD or abs(x[2]) > 1.0:
            x[1] = float(np.clip(x[1], -GAMMA_LIMIT_RAD, GAMMA_LIMIT_RAD))
            x[2] = float(np.clip(x[2], -1.0, 1.0))
        r = residuals(x)
        if np.all(np.abs(r) <= tol):
            return iteration
    what = ("the pitch trim at its stop" if abs(x[2]) >= 1.0 else
            f"the glide steeper than {math.degrees(GAMMA_LIMIT_RAD):g} deg"
            if abs(x[1]) >= GAMMA_LIMIT_RAD else "no convergence")
    raise TrimError(f"cannot trim a steady glide at {speed_m_s:g} m/s ({what}: alpha "
                    f"{math.degrees(x[0]):.2f} deg, gamma {math.degrees(x[1]):.2f} deg; "
                    f"udot {r[0]:.1e} ft/s2, wdot {r[1]:.1e} ft/s2, qdot {r[2]:.1e} rad/s2)")


def airframe_from_file(jsbsim_path: str, cg_m: tuple[float, float, float], airframe_class,
                       definition_name: str | None = None,
                       systems: dict[str, str] | None = None):
    """An ``airframe_class`` (:class:`~bioflex_jsb.runtime.fdm.Airframe`) of another
    aircraft (``<dir>/<name>.xml``: a jsbsim package aircraft or a user's) with the modal
    wing's hooks at ``cg_m`` [m, structural frame], loaded from a copy
    (:func:`derived_root`, kept while the airframe lives), its α range from its tables;
    ``definition_name``: the aircraft definition it flies (the name of the
    :class:`~bioflex_jsb.parameters.airframe.AirframeData` its wing carries: the coupled
    step checks the pair); ``systems``: system files added to the copy (:func:`derived_root`)."""
    work, name = derived_root(jsbsim_path, cg_m, systems)
    airframe = airframe_class(work.name, name)
    airframe._workdir = work
    airframe.alpha_table_range_rad = alpha_table_range_rad(jsbsim_path)
    airframe.definition_name = definition_name
    return airframe


# Central-difference steps of the glider's A_RR (:func:`rigid_jacobian`): 0.01 m/s of
# airspeed and 1e-4 rad (rad/s) of α, θ, q: inside one interval of SGS.xml's tables (1°
# = 0.0175 rad), and large enough that JSBSim's accelerations (~10 ft/s² per rad, printed
# to 1e-12 relative) keep 7 digits in the differences.
JACOBIAN_STEPS = (0.01, 1e-4, 1e-4, 1e-4)
# JSBSim's α̇ (in C_mα̇) is computed from the previous evaluation's accelerations: three
# evaluations of one state make it that state's own (ẇ does not depend on α̇: the second
# is already exact; the third confirms it).
ALPHADOT_PASSES = 3


def glide_elevator_norm(fdm) -> float:
    """A glider's trimmed elevator, −1..1: its normalised command (elevator command + the
    pitch trim :func:`glide_trim` moves, clipped to ±1), what an FCS like SGS.xml's moves
    the surface by; that FCS writes only the deflection in rad, and its never-written
    ``fcs/elevator-pos-norm`` read 0 whatever the trim."""
    command = float(fdm["fcs/elevator-cmd-norm"]) + float(fdm[PITCH_TRIM])
    return min(1.0, max(-1.0, command))


def rigid_jacobian(fdm, powered: bool = False) -> np.ndarray:
    """A_RR (4×4, x_R = [u [m/s], α [rad], q [rad/s], θ [rad]], SI) of ``fdm`` at its
    current state (the glide trim, wings level, no wind), by central differences of JSBSim's
    own state derivatives: V̇ = (u u̇ + w ẇ)/V, α̇ = (u ẇ − w u̇)/(u² + w²), q̇, θ̇ = q
    (body axes), each state evaluated until its α̇ is its own (:data:`ALPHADOT_PASSES`)
    and, ``powered``, with the propellers at their steady RPM (quasi-static, as JSBSim's
    trim and the linear model take them). The glider's replacement for JSBSim's
    FGLinearization, which reads the throttle of engine 0 and fails on an aircraft without
    one (it crashed the process in JSBSim 1.3.3), and the exact linearisation of JSBSim's
    model the identified derivatives are checked against (FGLinearization takes α̇ after
    one evaluation: tests/test_identification.py). The state is put back at the end."""
    m = 0.3048  # m per ft (exact), JSBSim's velocities and accelerations are in ft
    u0, w0 = fdm["velocities/u-fps"] * m, fdm["velocities/w-fps"] * m
    x0 = np.array([math.hypot(u0, w0), math.atan2(w0, u0), fdm["velocities/q-rad_sec"],
                   fdm["attitude/theta-rad"]])

    def derivatives(x: np.ndarray) -> np.ndarray:
        v, alpha, q, theta = x
        u, w = v * math.cos(alpha), v * math.sin(alpha)
        fdm["ic/u-fps"], fdm["ic/v-fps"], fdm["ic/w-fps"] = u / m, 0.0, w / m
        fdm["ic/theta-rad"], fdm["ic/q-rad_sec"] = theta, q
        fdm["ic/p-rad_sec"], fdm["ic/r-rad_sec"] = 0.0, 0.0
        for _ in range(ALPHADOT_PASSES):
            fdm.run_ic()
            if powered:  # the propellers at their steady RPM, as JSBSim's trim puts them
                fdm.get_propulsion().get_steady_state()
        udot = fdm["accelerations/udot-ft_sec2"] * m
        wdot = fdm["accelerations/wdot-ft_sec2"] * m
        return np.array([(u * udot + w * wdot) / v, (u * wdot - w * udot) / (u * u + w * w),
                         fdm["accelerations/qdot-rad_sec2"], q])

    a = np.empty((4, 4))
    for j, h in enumerate(JACOBIAN_STEPS):
        dx = np.zeros(4)
        dx[j] = h
        a[:, j] = (derivatives(x0 + dx) - derivatives(x0 - dx)) / (2.0 * h)
    derivatives(x0)  # back at the trim state
    return a
