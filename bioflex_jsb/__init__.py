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


def _user_cache_dir() -> str:
    """numba's cache of this package's compiled kernels: per user, not inside the
    installation (a read-only site-packages, a shared environment): NUMBA_CACHE_DIR when the
    user set it, else ``$XDG_CACHE_HOME/bioflex-jsb/numba`` (``~/.cache`` without it;
    ``%LOCALAPPDATA%`` on Windows). numba keeps one entry per source file's path in it, so
    each installation (a new virtual environment) still compiles once."""
    if _sys.platform == "win32" and _os.environ.get("LOCALAPPDATA"):
        base = _os.environ["LOCALAPPDATA"]
    else:
        base = _os.environ.get("XDG_CACHE_HOME") or _os.path.join(
            _os.path.expanduser("~"), ".cache")
    return _os.path.join(base, "bioflex-jsb", "numba")


# Before numba is imported (it reads NUMBA_CACHE_DIR once, at its import); a user's own
# NUMBA_CACHE_DIR is kept. numba already imported by the caller: its setting is kept too.
if "NUMBA_CACHE_DIR" not in _os.environ and "numba" not in _sys.modules:
    _os.environ["NUMBA_CACHE_DIR"] = _user_cache_dir()
