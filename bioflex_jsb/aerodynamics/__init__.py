"""aerodynamics: vortex-lattice (Weissinger-type) spanwise aerodynamics of the planform.

:mod:`bioflex_jsb.aerodynamics.vortex_lattice` gives the strip quantities C_lα·c(y) and
x_ac(y) for the Table B1 integrals, influence matrices from a spanwise α(y) to lift per
unit span, the wing's C_Lα, aerodynamic centre and roll damping (docs/aerodynamics.md).
"""
