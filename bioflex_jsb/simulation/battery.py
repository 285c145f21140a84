"""A simple physical battery for the SITL vehicle's BATTERY_STATUS and SYS_STATUS.

A lithium-polymer pack of ``cells`` in series, ``capacity_mah`` [mA·h]: open-circuit cell
voltage linear in the state of charge s (``V_EMPTY_V`` at s = 0 to ``V_FULL_V`` at s = 1,
with the usual knee below 10 %), an internal resistance R [Ω] in series, and a load of
P = P_shaft / η_drive + P_avionics [W]. The current I solves P = (V_oc − R I) I (the lower
root); the charge drawn integrates I over simulated time. ESTIMATE: 3S 5000 mA·h, R 0.03 Ω,
η 0.75, avionics 3 W (≈ 1 h of cruise at 15 m/s for this airframe's ≈ 40 W shaft power).

Reported only: an empty battery raises a warning but does not limit the motor (the
airframe's motor model has no supply voltage).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

V_FULL_V = 4.2
V_EMPTY_V = 3.3
KNEE_SOC = 0.1


@dataclass
class Battery:
    cells: int = 3
    capacity_mah: float = 5000.0
    resistance_ohm: float = 0.03
    drive_efficiency: float = 0.75
    avionics_w: float = 3.0
    consumed_mah: float = 0.0
    energy_j: float = 0.0
    current_a: float = 0.0
    voltage_v: float = 3 * V_FULL_V

    @property
    def soc(self) -> float:
        """State of charge 0..1."""
        return max(0.0, 1.0 - self.consumed_mah / self.capacity_mah)

    def open_circuit_v(self) -> float:
        s = self.soc
        cell = V_EMPTY_V + (V_FULL_V - V_EMPTY_V) * s
        if s < KNEE_SOC:  # the steep end of discharge: 0.3 V more lost towards empty
            cell -= 0.3 * (1.0 - s / KNEE_SOC)
        return self.cells * cell

    def draw(self, shaft_power_w: float, dt_s: float) -> None:
        """Supply ``shaft_power_w`` [W] at the propellers for ``dt_s`` [s] of simulated time."""
        p = max(0.0, shaft_power_w) / self.drive_efficiency + self.avionics_w
        v_oc, r = self.open_circuit_v(), self.resistance_ohm
        disc = v_oc * v_oc - 4.0 * r * p
        i = (v_oc - math.sqrt(disc)) / (2.0 * r) if disc > 0.0 else v_oc / (2.0 * r)
        self.current_a = i
        self.voltage_v = v_oc - r * i
        self.consumed_mah += i * dt_s / 3.6
        self.energy_j += self.voltage_v * i * dt_s

    @property
    def remaining_pct(self) -> int:
        return int(round(100.0 * self.soc))

    def time_remaining_s(self) -> float:
        """At the present current [s] (inf at no current)."""
        if self.current_a <= 0.0:
            return math.inf
        return (self.capacity_mah - self.consumed_mah) * 3.6 / self.current_a
