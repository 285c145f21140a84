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
