"""The valid ranges of a definition's fields [unit], each with its reason: one leaf module
that the readers (loader, flying) and the API's guards share."""

from __future__ import annotations

import math

# an aileron's hinge line [chord fraction]: the control-surface module's range and reason
from bioflex_jsb.aeroelasticity.control_surface import HINGE_RANGE  # noqa: F401

# Valid ranges [unit], each with its reason.
# Semispan b/2 [m]: 0.05 m (a wind-tunnel model) to 100 m (the largest wings built are
# about 40 m per side: A380 39.8 m, Helios 37.7 m); a file in mm (6096 for 6.096 m) is
# outside.
SEMISPAN_RANGE_M = (0.05, 100.0)
CHORD_RANGE_M = (0.005, 30.0)  # a 5 mm model chord to a 30 m root chord
LEADING_EDGE_RANGE_M = (-100.0, 100.0)
TWIST_LIMIT_RAD = math.radians(30.0)  # beyond 30° the strip's attached flow is gone
# Dihedral of a panel, |atan(Δz/Δy)| [rad]: up to 30°. The beam runs along y and the strips
# lie in planes through it: at 30° the real spar is 1/cos 30° = 15 % longer than the beam,
# and beyond it the wing is no longer a wing with some dihedral (docs/aircraft.md).
DIHEDRAL_LIMIT_RAD = math.radians(30.0)
# Point masses on the wing [kg]: 1e-6 (a milligram-scale balance weight of a model) to 1e6
# (a transport's fuel per wing is ~1e5 kg); at most 100 of them (engines, tanks, pods).
POINT_MASS_RANGE_KG = (1e-6, 1e6)
POINT_MASS_INERTIA_RANGE_KG_M2 = (0.0, 1e7)  # its own pitch inertia; 0: a point
# Chordwise position of a point mass's centre of mass [chord fraction aft of the LE]: a
# wing-mounted engine or a pod sits ahead of the leading edge (negative), a tip tank or a
# balance weight up to a few chords ahead or behind; -3..3 catches a value in metres or %.
POINT_MASS_CHORD_RANGE = (-3.0, 3.0)
MAX_POINT_MASSES = 100
# A strut's vertical stiffness at its attachment [N/m] (k = (EA/L) sin² γ): a C172's
# aluminium strut is ~2e6 N/m; the range is the beam stiffnesses' 1e-3..1e12.
STRUT_STIFFNESS_RANGE_N_M = (1e-3, 1e12)
MAX_STRUTS = 4
# Stiffnesses [N·m²]: 1e-3 (a foam-and-film model wing) to 1e12 (a transport's root
# bending is about 1e10).
STIFFNESS_RANGE_N_M2 = (1e-3, 1e12)
MASS_PER_LENGTH_RANGE_KG_M = (1e-4, 1e5)  # 0.1 g/m (a model) to 100 t/m
INERTIA_RANGE_KG_M = (1e-9, 1e6)
# Structural damping ratio ζ [-]: built-up wings measure 0.005-0.05; 0.3 leaves room for a
# heavily damped test article; 5 is a percentage or a typo (2 % is 0.02).
DAMPING_RANGE = (0.0, 0.3)
# Air density [kg/m³]: 0.01 (about 33 km, ISA; above it the atmosphere is no place for a
# wing, and the strip models' dynamic pressure vanishes) to 2 (denser than any air at the
# surface: -50 °C sea level is 1.58).
DENSITY_RANGE_KG_M3 = (0.01, 2.0)
LIFT_SLOPE_RANGE_PER_RAD = (1.0, 7.0)  # thin aerofoil 2π = 6.283; real sections 5.5-6.9
STRIPS_RANGE = (4, 200)
N_MODES_RANGE = (2, 20)
N_ELEMENTS_RANGE = (4, 400)
SPEED_LIMIT_M_S = 400.0  # the strip models are incompressible: above ~0.3 Mach, caution
AERO_MODELS = ("unsteady", "quasi-steady")
LIFT_SLOPES = ("strip", "vlm")
METHODS = ("pk", "state-space")
INERTIA_AXES = ("elastic-axis", "centre-of-mass")
TWIST_UNITS = ("deg", "rad")
# Monitoring stations of the section loads [fraction of the semispan]: model.py's
# DEFAULT_MONITORING_STATIONS, the root and the quarter points (the tip, s = 1, carries no
# load and is refused).
MAX_MONITORING_STATIONS = 50  # a table of section loads, not a spanwise distribution
# [aileron]: its span [fraction of the semispan] is at least this wide: narrower is a tab,
# not an aileron, and no strip analysis resolves it (200 strips are 0.5 % of the semispan).
MIN_CONTROL_SPAN_FRACTION = 0.01
# [aileron.actuator]: the second-order actuator's natural frequency [rad/s] and damping
# ratio. 1 rad/s is slower than any flown surface (a glider's ailerons through cables and a
# pilot move in 0.2 s or less); 1000 rad/s (160 Hz) is above any servo's bandwidth, where
# the actuator is no longer a lag worth a state. ζ from 0.1 (a lightly damped servo
# resonance) to 3 (an overdamped, nearly first-order lag).
ACTUATOR_FREQUENCY_RANGE_RAD_S = (1.0, 1000.0)
ACTUATOR_DAMPING_RANGE = (0.1, 3.0)
