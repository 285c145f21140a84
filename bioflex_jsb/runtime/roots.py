"""Where the JSBSim files are: the JSBSim root holding ``aircraft/`` and ``systems/``.

It is, in order: the ``root`` argument, when given; the directory named by the environment
variable ``BIOFLEX_JSBSIM_ROOT``, when set; a repository checkout (``aircraft/`` and
``systems/`` beside the ``bioflex_jsb`` package); an installed wheel
(``bioflex_jsb/jsbsim_root/`` inside the package). A root named explicitly that lacks the
aircraft is an error, never skipped; between the last two the first that holds the aircraft
file is used; if neither does, the error says where it looked.
"""

from __future__ import annotations

import os
from pathlib import Path

from bioflex_jsb.generators.airframe import AIRCRAFT_NAME as DEFAULT_AIRCRAFT
from bioflex_jsb.runtime.results import AircraftLoadError

ROOT_ENV_VAR = "BIOFLEX_JSBSIM_ROOT"


def _package_dir() -> Path:
    return Path(__file__).resolve().parents[1]


def candidate_roots() -> list[Path]:
    """Default JSBSim roots, in the order they are tried: checkout, then installed wheel."""
    return [_package_dir().parent, _package_dir() / "jsbsim_root"]


def aircraft_file(root: Path, aircraft: str = DEFAULT_AIRCRAFT) -> Path:
    """Path JSBSim loads for ``aircraft`` under ``root``: aircraft/<name>/<name>.xml."""
    return Path(root) / "aircraft" / aircraft / f"{aircraft}.xml"


def locate_root(root: str | os.PathLike | None = None, aircraft: str = DEFAULT_AIRCRAFT) -> Path:
    """The JSBSim root to use (see the module docstring); raises :class:`AircraftLoadError`."""
    if root is None and os.environ.get(ROOT_ENV_VAR):
        root = os.environ[ROOT_ENV_VAR]
        origin = f"${ROOT_ENV_VAR}"
    else:
        origin = "the given JSBSim root"
    if root is not None:
        path = Path(root).expanduser().resolve()
        if not path.is_dir():
            raise AircraftLoadError(f"{origin} {str(path)!r} is not a directory")
        if not aircraft_file(path, aircraft).is_file():
            raise AircraftLoadError(
                f"no aircraft file {str(aircraft_file(path, aircraft))!r} under {origin}"
            )
        return path
    for path in candidate_roots():
        if aircraft_file(path, aircraft).is_file() and (path / "systems").is_dir():
            return path
    tried = ", ".join(repr(str(p)) for p in candidate_roots())
    hint = f"set {ROOT_ENV_VAR} or pass a JSBSim root"
    if aircraft == DEFAULT_AIRCRAFT:
        hint += " (python -m bioflex_jsb.generators.airframe writes the bioflex files)"
    raise AircraftLoadError(
        f"cannot find the JSBSim files of {aircraft!r} (aircraft/ and systems/) in {tried}; " + hint
    )
