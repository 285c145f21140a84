"""bioflex-jsb: a JSBSim airframe of a bio-inspired elastic-wing UAV with a modal wing.

Layout, by discipline and by when the code runs (lower layers never import higher ones; the
import-linter contract in ``pyproject.toml`` checks it):

* ``parameters``      published data (``prototype``) and documented estimates/calibrations;
* ``structures``      half-wing beam model, mode shapes, modal-data files;
* ``aerodynamics``    vortex lattice of the planform, airframe polars, propeller;
* ``flight_dynamics`` Table B1/B2 derivatives, the LTI model of Eq. (4), QSD, eigen-analysis,
  the modal matrices;
* ``simulation``      the modal-wing step, gusts, run descriptions and results (pure numerics);
* ``generators``      build-time JSBSim XML writers (never import the runtime);
* ``runtime``         the JSBSim boundary (the only package importing jsbsim) and the one
  coupled step;
* ``sinks``, ``links`` MCAP logs, plots, model export; the MAVLink vehicle;
* ``drivers``         gust, native, SITL loops over the coupled step;
* ``sweep``           parameter sweeps over the drivers (local cores or Dask);
* ``api``             the documented Python API;
* ``cli``             the ``bioflex-jsb`` command, one client of the API.
"""

__version__ = "0.1.0"

import os as _os
import sys as _sys

# The modules that compile with numba. numba keys a cached kernel by its own source file's
# path and time stamp only: a kernel that calls one of another file's (the full-span and the
# unsteady kernels call the half wing's) keeps its old machine code when only that other
# file changes, at the same path (an upgrade in place). The cache folder is therefore named
# by the content of all of them together (tests/test_numba_cache.py checks this list
# against the package's imports of numba).
NUMBA_MODULES = (
    "loads/stream.py", "simulation/controller_kernel.py", "simulation/full_span_kernel.py",
    "simulation/sensors.py", "simulation/step_kernel.py", "simulation/unsteady_kernel.py",
    "simulation/unsteady_full_span_kernel.py",
    "sinks/mcap/scene.py", "sinks/mcap/scene_loads.py", "sinks/mcap_io/records.py",
)


def kernel_sources_key() -> str:
    """The first 16 hex digits of the SHA-256 of the :data:`NUMBA_MODULES`' bytes, in that
    order (each file read whole: they are the package's own, 2-40 kB)."""
    import hashlib

    digest = hashlib.sha256()
    here = _os.path.dirname(_os.path.abspath(__file__))
    for rel in NUMBA_MODULES:
        with open(_os.path.join(here, *rel.split("/")), "rb") as fh:
            digest.update(fh.read(1 << 20))
    return digest.hexdigest()[:16]


def _user_cache_dir() -> str:
    """numba's cache of this package's compiled kernels: per user, not inside the
    installation (a read-only site-packages, a shared environment): NUMBA_CACHE_DIR when the
    user set it, else ``$XDG_CACHE_HOME/bioflex-jsb/numba/<kernel sources key>``
    (``~/.cache`` without it; ``%LOCALAPPDATA%`` on Windows). numba keeps one entry per
    source file's path in it, so each installation (a new virtual environment) still
    compiles once; the key (:func:`kernel_sources_key`) gives changed kernel sources a
    folder of their own, so no kernel runs machine code compiled against another version
    of a kernel it calls."""
    if _sys.platform == "win32" and _os.environ.get("LOCALAPPDATA"):
        base = _os.environ["LOCALAPPDATA"]
    else:
        base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(
            _os.path.expanduser("~"), ".cache")
    return _os.path.join(base, "bioflex-jsb", "numba", kernel_sources_key())


# Before numba is imported (it reads NUMBA_CACHE_DIR once, at its import); a user's own
# NUMBA_CACHE_DIR is kept. numba already imported by the caller: its setting is kept too.
if "NUMBA_CACHE_DIR" not in _os.environ and "numba" not in _sys.modules:
    _os.environ["NUMBA_CACHE_DIR"] = _user_cache_dir()
