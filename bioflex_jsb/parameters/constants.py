"""Physical constants (not properties of any aircraft), SI.

* ``STANDARD_GRAVITY_M_S2``: g_n = 9.80665 m/s², the standard acceleration of gravity (3rd
  CGPM, 1901; ISO 80000-3).
* ``SEA_LEVEL_DENSITY_KG_M3``: ρ_0 = 1.225 kg/m³, the air density of the ISO 2533 standard
  atmosphere at sea level (15 °C, 101 325 Pa). The paper's flight condition is unstated; the
  prototype flies at sea level ISA unless told otherwise.
"""

STANDARD_GRAVITY_M_S2 = 9.80665
SEA_LEVEL_DENSITY_KG_M3 = 1.225
