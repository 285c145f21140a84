"""The channels of a run: names, units and the row of one step, built by name.

Every driver logs the same channels (``docs/logging.md``): perturbations from the trim at the
start of the run (u, alpha, q, theta), the load factor, the gust, the air data, the modal
loads applied, the absolute pose and the rest of the state (for logs and ground stations) and
the modal state η_i, η̇_i. Frames: NED Euler angles, FRD body rates, NED velocities
(``docs/conventions.md``).
"""

from __future__ import annotations

from operator import itemgetter

# name → unit, in the order of the table's columns (the order of this mapping is the only
# place an order is defined; rows are built by name)
BASE_UNITS: dict[str, str] = {
    "u": "m/s", "alpha": "rad", "q": "rad/s", "theta": "rad", "n_z": "-", "w_g": "m/s",
    "airspeed_m_s": "m/s", "altitude_m": "m",
    "lift_n": "N", "drag_n": "N", "pitch_moment_n_m": "N*m",
    "latitude_rad": "rad", "longitude_rad": "rad", "phi_rad": "rad",
    "theta_rad": "rad", "psi_rad": "rad", "p_rad_s": "rad/s", "r_rad_s": "rad/s",
    "elevator_rad": "rad", "throttle": "-",
    "alpha_rad": "rad", "beta_rad": "rad", "v_north_m_s": "m/s", "v_east_m_s": "m/s",
    "v_down_m_s": "m/s",
}


def eta_names(n_modes: int) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """(η names, η̇ names) of ``n_modes`` modes: ``eta1``…, ``eta1_dot``…"""
    return (tuple(f"eta{i + 1}" for i in range(n_modes)),
            tuple(f"eta{i + 1}_dot" for i in range(n_modes)))


def channel_units(n_modes: int) -> dict[str, str]:
    """Channel names of a run with ``n_modes`` wing modes and their units."""
    units = dict(BASE_UNITS)
    eta, eta_dot = eta_names(n_modes)
    units.update({n: "rad" for n in eta})
    units.update({n: "rad/s" for n in eta_dot})
    return units


def row_getter(names: tuple[str, ...]):
    """``getter(row)``: the values of the dict ``row`` in the order of ``names`` (a tuple)."""
    return itemgetter(*names)
