"""aerodynamics."""
