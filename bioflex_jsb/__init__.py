"""bioflex-jsb: a JSBSim airframe of a bio-inspired elastic-wing UAV with a modal wing.

Layout (one folder per discipline):

* ``parameters``      published data (``prototype``) and documented estimates/calibrations;
* ``structures``      half-wing beam model, mode shapes, modal-data files;
* ``aerodynamics``    lifting-line aerodynamics of the planform;
* ``flight_dynamics`` Table B1/B2 derivatives, the LTI model of Eq. (4), QSD, eigen-analysis;
* ``simulation``      the co-simulation step and gust models (pure numerics, no I/O);
* ``adapters``        JSBSim, MCAP, MAVLink, Dask and plotting: everything with I/O;
* ``cli``             the ``bioflex-jsb`` command.
"""

__version__ = "0.1.0"
