"""aeroelasticity: flutter of clamped wings on unsteady strip aerodynamics.

* :mod:`~bioflex_jsb.aeroelasticity.clamped_wing`: the beam's modes with aerodynamic strips
  (2-D lift slope or the vortex lattice's span loading); the Goland wing's sections;
* :mod:`~bioflex_jsb.aeroelasticity.strip_aero`: generalised aerodynamic forces, Theodorsen
  (frequency domain) and Jones/Küssner finite-state (time domain);
* :mod:`~bioflex_jsb.aeroelasticity.pk`: the p-k branches (a root family of the one engine,
  :mod:`bioflex_jsb.flight_dynamics.flutter_engine`: tracking, search, result, mechanism);
* :mod:`~bioflex_jsb.aeroelasticity.state_space`: structure + lag states, the engine's
  eigen family;
* :mod:`~bioflex_jsb.aeroelasticity.flutter`: either method on a clamped wing, the Goland
  benchmark;
* :mod:`~bioflex_jsb.aeroelasticity.free_aircraft`: the paper's free aircraft, Eq. (4) with
  unsteady strips (named Jones lag states), its flutter and the six-wing table;
* :mod:`~bioflex_jsb.aeroelasticity.strip_increments`: the unsteady strips' loads beyond the
  quasi-steady ones as rows on the state (for the LTI model and the co-simulation's wing);
* :mod:`~bioflex_jsb.aeroelasticity.control_surface`: a trailing-edge surface (aileron) on
  the strips, its thin-aerofoil section; :mod:`~bioflex_jsb.aeroelasticity.aileron`: aileron
  effectiveness, steady roll and reversal of a clamped wing or an aircraft's wing (the
  figure: :mod:`~bioflex_jsb.aeroelasticity.aileron_plot`).
"""

from bioflex_jsb.aeroelasticity.flutter import FlutterResult, goland_flutter

__all__ = ["FlutterResult", "goland_flutter"]
