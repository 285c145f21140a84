"""Build-time JSBSim file generators: the airframe, its autopilot and the native modal wing.

They write XML from the parameters and the physics; they never import the JSBSim runtime
(an import-linter contract checks it). What a file needs from a JSBSim run (a trim for an
initial condition) is computed by a driver and handed in.
"""
