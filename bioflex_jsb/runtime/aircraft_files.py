"""The files JSBSim reads for an aircraft, found as JSBSim finds them, and the private copy
of them the co-simulation flies (docs/aircraft.md, "Your JSBSim aircraft").

Where JSBSim looks (JSBSim 1.2-1.3: ``FGModel::FindFullPathName`` and its overrides in
``FGPropulsion`` and ``FGFCS``; a name without an extension gets ``.xml``):

* the aircraft file ``<aircraft dir>/<name>.xml``;
* a top-level section with a ``file`` attribute (``<aerodynamics file=…/>``,
  ``<mass_balance file=…/>``, ``<autopilot file=…>``, ``<flight_control file=…>``, …): the
  aircraft directory;
* an engine or a thruster (``<engine file=…>``, ``<thruster file=…>``): the aircraft
  directory, then its ``Engines/``, then the root's ``engine/``;
* a system (``<system file=…>``): the aircraft directory, then its ``Systems/``, then the
  root's ``systems/``.

The root of an aircraft in a user's directory ``ROOT/aircraft/NAME/NAME.xml`` is ``ROOT``
(its ``engine/`` and ``systems/`` come first); after it, the jsbsim package's own root, so
that an aircraft naming the package's engines (``eng_io320``) loads from anywhere.

The copy. The co-simulation adds the modal wing's external reactions to the aircraft's XML,
so it flies a copy in a temporary JSBSim root. Only what JSBSim will read is copied: the
aircraft file (rewritten) and each file it names, each put where JSBSim looks first
(``Engines/``, ``Systems/`` or the aircraft directory of the copy), so the copy resolves
every name to the same content. Every file copied is a regular file inside one of the
directories above (a link that leads out of them, a device, a FIFO, a directory is refused),
of at most :data:`MAX_FILE_BYTES`, :data:`MAX_TOTAL_BYTES` in all, read with that bound; a
name that is absolute or climbs out with ``..`` is refused. The aircraft file's top-level
``<input>`` and ``<output>`` sections (sockets and files JSBSim would open) are left out of
the copy: the co-simulation has its own inputs and logs.

Temporary roots live under one folder per user (:func:`scratch_parent`), named with the
process id; a root whose process is gone (a run killed with SIGKILL cannot clean up) is
removed when the next one is made.
"""

from __future__ import annotations

import math
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path, PurePosixPath

from bioflex_jsb.files import read_input_bytes
from bioflex_jsb.generators import airframe as airframe_xml
from bioflex_jsb.runtime.results import AircraftLoadError
from bioflex_jsb.simulation import jsbsim_properties as JP

# One file JSBSim reads [bytes]: the largest of the jsbsim package is 1.6 MB (an aircraft
# with large aerodynamic tables); 16 MiB is 10 times that.
MAX_FILE_BYTES = 16 * 1024 * 1024
# All files of one aircraft [bytes]: 4 times one file's bound (the package's largest
# aircraft with its engines and systems is under 2 MB).
MAX_TOTAL_BYTES = 64 * 1024 * 1024
# Most files one aircraft may name (the package's most: 40, a four-engine aircraft's
# engines, thrusters and systems).
MAX_FILES = 400

ENGINE_ELEMENTS = ("engine", "thruster")
SYSTEM_ELEMENTS = ("system",)
# Top-level sections JSBSim would open as sockets or output files: not copied.
DROPPED_SECTIONS = ("input", "output")


@dataclass(frozen=True)
class NamedFile:
    """One file the aircraft names: the element that names it (``engine``, ``system``, …),
    the name as written, where JSBSim finds it (``source``) and where the copy puts it,
    relative to the copy's aircraft directory (``target``)."""

    element: str
    name: str
    source: Path
    target: PurePosixPath


def package_root() -> Path | None:
    """The jsbsim package's JSBSim root (its ``aircraft/``, ``engine/``, ``systems/``), or
    None where the installed jsbsim has none (a build without its data files: JSBSim's
    ``get_default_root_dir`` refuses; the package's folders are then not searched)."""
    import jsbsim

    try:
        return Path(jsbsim.get_default_root_dir()).resolve()
    except OSError:
        return None


def user_root(aircraft_dir: Path) -> Path | None:
    """The JSBSim root an aircraft directory sits in (``ROOT/aircraft/NAME``), or None."""
    parent = aircraft_dir.parent
    return parent.parent if parent.name == "aircraft" else None


def _with_xml(name: str) -> PurePosixPath:
    path = PurePosixPath(name)
    return path if path.suffix else path.with_suffix(".xml")


def _checked_name(aircraft: Path, element: str, name: str) -> PurePosixPath:
    path = _with_xml(name.strip())
    if not name.strip() or path.is_absolute() or ".." in path.parts or "\\" in name:
        raise AircraftLoadError(
            f"{str(aircraft)!r}: <{element} file={name!r}> must name a file relative to the "
            "aircraft's folders (no absolute path, no '..')")
    return path


def _inside(path: Path, folders: tuple[Path, ...]) -> bool:
    real = path.resolve()
    return any(real == f or f in real.parents for f in folders)


def _search(aircraft_dir: Path, element: str) -> tuple[Path, ...]:
    roots = [r for r in (user_root(aircraft_dir), package_root()) if r is not None]
    if element in ENGINE_ELEMENTS:
        return (aircraft_dir, aircraft_dir / "Engines", *(r / "engine" for r in roots))
    if element in SYSTEM_ELEMENTS:
        return (aircraft_dir, aircraft_dir / "Systems", *(r / "systems" for r in roots))
    return (aircraft_dir,)


def named_files(aircraft_path: Path, tree: ET.ElementTree,
                skip: frozenset[str] = frozenset()) -> list[NamedFile]:
    """Every file the aircraft file ``aircraft_path`` (parsed: ``tree``) makes JSBSim read,
    found as JSBSim finds it (module docstring), but the system files named in ``skip``
    (``name.xml``: written into the copy by the caller). Raises :class:`AircraftLoadError`
    naming the first that cannot be found or may not be read."""
    aircraft_dir = aircraft_path.parent.resolve()
    root = tree.getroot()
    found: list[NamedFile] = []
    elements = [el for el in root.iter() if el.get("file") is not None]
    for el in elements:
        if el.tag not in ENGINE_ELEMENTS + SYSTEM_ELEMENTS and el not in list(root):
            continue  # only top-level sections, engines, thrusters and systems name files
        rel = _checked_name(aircraft_path, el.tag, el.get("file"))
        if el.tag in SYSTEM_ELEMENTS and str(rel) in skip:
            continue
        folders = _search(aircraft_dir, el.tag)
        found_in = next((f for f in folders if (f / rel).exists()), None)
        source = None if found_in is None else found_in / rel
        if source is None:
            where = ", ".join(str(f) for f in folders)
            raise AircraftLoadError(f"{str(aircraft_path)!r}: <{el.tag} file="
                                    f"{el.get('file')!r}> is in none of {where} (where JSBSim "
                                    "looks)")
        allowed = tuple(f.resolve() for f in folders if f.is_dir())
        if not _inside(source, allowed):
            raise AircraftLoadError(f"{str(source)!r} (<{el.tag} file={el.get('file')!r}>) "
                                    "is a link leading out of the aircraft's folders: refused")
        # where the copy puts it: as found in the aircraft's folders, a root's engine/ or
        # systems/ file in the copy's Engines/ or Systems/ (JSBSim's next place to look)
        if found_in in (aircraft_dir, aircraft_dir / "Engines", aircraft_dir / "Systems"):
            first = found_in.relative_to(aircraft_dir).parts
        else:
            first = ("Engines",) if el.tag in ENGINE_ELEMENTS else ("Systems",)
        target = PurePosixPath(*first, *rel.parts)
        found.append(NamedFile(el.tag, el.get("file"), source, target))
        if len(found) > MAX_FILES:
            raise AircraftLoadError(f"{str(aircraft_path)!r} names more than {MAX_FILES} "
                                    "files")
    return found


def read_named_files(aircraft_path: Path, files: list[NamedFile]
                     ) -> dict[PurePosixPath, bytes]:
    """The content of each of ``files`` (:func:`named_files` of ``aircraft_path``) by its
    target in a copy's aircraft directory, each read once (two engines of one file) with
    the bound of one file, :data:`MAX_TOTAL_BYTES` in all; :class:`AircraftLoadError`
    (one line) past a bound."""
    total, out = 0, {}
    for f in files:
        if f.target in out:
            continue
        data = read_input_bytes(f.source, f"the file <{f.element} file={f.name!r}>",
                                MAX_FILE_BYTES, AircraftLoadError)
        total += len(data)
        if total > MAX_TOTAL_BYTES:
            raise AircraftLoadError(f"the files {str(aircraft_path)!r} names exceed "
                                    f"{MAX_TOTAL_BYTES // (1024 * 1024)} MiB in all")
        out[f.target] = data
    return out


def read_xml(path: str | os.PathLike, what: str = "the JSBSim aircraft") -> ET.ElementTree:
    """The XML file ``path`` (``what`` it is, for the message), read with the bound of every
    input file (:data:`MAX_FILE_BYTES`) and parsed; one line if it cannot be."""
    data = read_input_bytes(path, what, MAX_FILE_BYTES, AircraftLoadError)
    try:
        return ET.ElementTree(ET.fromstring(data))
    except ET.ParseError as exc:
        raise AircraftLoadError(f"{what} {str(path)!r} is not valid XML: {exc}") from None


def read_aircraft_xml(path: str | os.PathLike) -> ET.ElementTree:
    """The aircraft file ``path``, read with the bound of every input file and parsed."""
    return read_xml(path, "the JSBSim aircraft")


def scratch_parent() -> Path:
    """The folder of this user's temporary JSBSim roots (in the system's temporary
    directory)."""
    return Path(tempfile.gettempdir()) / f"bioflex-jsb-aircraft-{os.getuid()}"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process of that id: alive
        return True
    return True


def remove_stale_roots(parent: Path) -> int:
    """Remove the temporary roots under ``parent`` whose process has ended (a run killed
    before it could clean up); returns how many were removed."""
    removed = 0
    for entry in parent.iterdir() if parent.is_dir() else ():
        pid_text = entry.name.split("-", 1)[0]
        if entry.is_dir() and not entry.is_symlink() and pid_text.isdigit() \
                and not _alive(int(pid_text)):
            shutil.rmtree(entry, ignore_errors=True)
            removed += 1
    return removed


def private_root(aircraft_path: str | os.PathLike, tree: ET.ElementTree,
                 generated: dict[str, str] | None = None
                 ) -> tuple[tempfile.TemporaryDirectory, str]:
    """A temporary JSBSim root flying ``tree`` (the aircraft file, already changed by the
    caller) as ``aircraft/<name>/<name>.xml`` with every file it names copied (module
    docstring) and the ``generated`` system files (``name.xml`` → its text: the SITL
    glider's autopilot) written to its ``Systems/``: (the directory, kept alive by the
    caller; the aircraft's name)."""
    src = Path(aircraft_path)
    name = src.stem
    generated = generated or {}
    files = named_files(src, tree, frozenset(generated))
    parent = scratch_parent()
    parent.mkdir(mode=0o700, exist_ok=True)
    remove_stale_roots(parent)
    work = tempfile.TemporaryDirectory(prefix=f"{os.getpid()}-", dir=parent)
    base = Path(work.name)
    target_dir = base / "aircraft" / name
    target_dir.mkdir(parents=True)
    for sub in ("engine", "systems"):  # the root's own folders: everything is in the copy
        (base / sub).mkdir()
    root = tree.getroot()
    for section in [el for el in root if el.tag in DROPPED_SECTIONS]:
        root.remove(section)
    try:
        contents = read_named_files(src, files)
    except AircraftLoadError:
        work.cleanup()
        raise
    for target, data in contents.items():
        out = target_dir.joinpath(*target.parts)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_bytes(data)
    for file, text in generated.items():
        out = target_dir / "Systems" / file
        out.parent.mkdir(exist_ok=True)
        out.write_text(text, encoding="utf-8")
    tree.write(target_dir / f"{name}.xml", encoding="utf-8", xml_declaration=True)
    return work, name


def alpha_limits_rad(path: Path) -> tuple[float, float]:
    """The <alphalimits> of the aircraft file [rad] (the range JSBSim's trim searches)."""
    tree = read_aircraft_xml(path)
    lim = tree.getroot().find("aerodynamics/alphalimits")
    if lim is None:
        # JSBSim's trim then searches −5°..20° (FGTrimAxis); report that range.
        return math.radians(-5.0), math.radians(20.0)
    scale = 1.0 if lim.get("unit", "RAD").upper() == "RAD" else math.pi / 180.0
    try:
        return float(lim.findtext("min")) * scale, float(lim.findtext("max")) * scale
    except (TypeError, ValueError):
        raise AircraftLoadError(f"malformed <alphalimits> in {str(path)!r}") from None


# -- the modal wing's hooks, the α range of the aircraft -------------------------------------
# The co-simulation writes the elastic wing's incremental loads into external reactions
# (bioflex_jsb.generators.airframe: modal-lift, modal-drag, modal-side forces at the CG, body
# axes; modal-pitch, modal-roll, modal-yaw moments; and the gust's). The generated prototype
# has them in its XML; another aircraft gets the same ones in its private copy, at its CG
# (structural frame, metres to inches).
INCH_PER_M = 1.0 / 0.0254  # the inch is 0.0254 m exactly


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
        if var not in (JP.AERO_ALPHA_RAD, JP.AERO_ALPHA_DEG):
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
