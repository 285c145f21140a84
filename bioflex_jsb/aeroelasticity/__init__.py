"""aeroelasticity: flutter of clamped wings on unsteady strip aerodynamics.

* :mod:`~bioflex_jsb.aeroelasticity.clamped_wing`: the beam's modes with aerodynamic strips
  (2-D lift slope or the vortex lattice's span loading); the Goland wing's sections;
* :mod:`~bioflex_jsb.aeroelasticity.strip_aero`: generalised aerodynamic forces, Theodorsen
  (frequency domain) and Jones/Küssner finite-state (time domain);
* :mod:`~bioflex_jsb.aeroelasticity.pk`: p-k flutter solution with branch tracking;
* :mod:`~bioflex_jsb.aeroelasticity.state_space`: eigen-analysis of structure + lag states;
* :mod:`~bioflex_jsb.aeroelasticity.flutter`: the result, mechanism and the Goland benchmark;
* :mod:`~bioflex_jsb.aeroelasticity.free_aircraft`: the paper's free aircraft, Eq. (4) with
  unsteady strips (named Jones lag states), its flutter and the six-wing table;
* :mod:`~bioflex_jsb.aeroelasticity.strip_increments`: the unsteady strips' loads beyond the
  quasi-steady ones as rows on the state (for the LTI model and the co-simulation's wing).
"""

from bioflex_jsb.aeroelasticity.flutter import FlutterResult, goland_flutter

__all__ = ["FlutterResult", "goland_flutter"]
