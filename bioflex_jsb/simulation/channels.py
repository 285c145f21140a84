"""The channels of a run: names, units, meanings and the row of one step, built by name.

Every driver logs the same channels (``docs/logging.md``): perturbations from the trim at the
start of the run (u, alpha, theta), the pitch rate q, the load factor, the gust, the air data,
the modal loads applied, the absolute pose and the rest of the state (for logs and ground
stations) and the modal state η_i, η̇_i. Frames: NED Euler angles, FRD body rates, NED
velocities (``docs/conventions.md``).

Two kinds of angle share a unit and differ in what they are measured from: ``alpha`` and
``theta`` are *perturbations* from the trim (0 at the start of the run), ``alpha_rad`` and
``theta_rad`` the *absolute* angles. The short names are the paper's state names (Eq. 4) and
the stored golden histories' columns; each perturbation also answers to a name that says what
it is, the MCAP log's field name (:data:`ALIASES`: ``run["dalpha_rad"]`` is ``run["alpha"]``).
:func:`describe` gives every channel's unit, kind, meaning (frame and sign) and that name.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from operator import itemgetter

PERTURBATION = "perturbation"  # measured from the trim at the start of the run (0 there)
ABSOLUTE = "absolute"  # the quantity itself


@dataclass(frozen=True)
class Channel:
    """What a channel holds: ``unit``; ``kind`` :data:`PERTURBATION` (from the trim at the
    start of the run) or :data:`ABSOLUTE`; ``meaning``: the quantity, its frame and sign;
    ``alias``: the name that says what it is (the MCAP log's field), or None when the
    channel's own name says it."""

    unit: str
    kind: str
    meaning: str
    alias: str | None = None

    def as_dict(self) -> dict[str, str | None]:
        return {"unit": self.unit, "kind": self.kind, "meaning": self.meaning,
                "alias": self.alias}


_P, _A = PERTURBATION, ABSOLUTE
# name → what it holds, in the order of the table's columns (the order of this mapping is the
# only place an order is defined; rows are built by name)
CHANNELS: dict[str, Channel] = {
    "u": Channel("m/s", _P, "true airspeed minus its trim value, faster positive", "du_m_s"),
    "alpha": Channel("rad", _P, "angle of attack against the air (the gust included) minus "
                     "its trim value, nose up positive", "dalpha_rad"),
    "q": Channel("rad/s", _A, "pitch rate about the body y axis (starboard), nose up "
                 "positive; 0 at the trim, so also its perturbation", "q_rad_s"),
    "theta": Channel("rad", _P, "pitch angle (NED Euler θ) minus its trim value, nose up "
                     "positive", "dtheta_rad"),
    "n_z": Channel("-", _A, "normal load factor (JSBSim's accelerations/Nz), up positive, 1 "
                   "in level flight"),
    "w_g": Channel("m/s", _A, "vertical gust velocity, up positive (JSBSim's wind-down is "
                   "−w_g)", "w_g_m_s"),
    "airspeed_m_s": Channel("m/s", _A, "true airspeed"),
    "altitude_m": Channel("m", _A, "altitude above sea level"),
    "lift_n": Channel("N", _A, "the elastic wing's incremental lift applied to the airframe, "
                      "up, normal to the air velocity (0 for the rigid model)"),
    "drag_n": Channel("N", _A, "the elastic wing's incremental drag applied to the airframe, "
                      "aft, along the air velocity"),
    "pitch_moment_n_m": Channel("N*m", _A, "the elastic wing's incremental pitching moment "
                                "applied to the airframe, about the CG, nose up"),
    "latitude_rad": Channel("rad", _A, "geodetic latitude (WGS-84), north positive"),
    "longitude_rad": Channel("rad", _A, "longitude, east positive"),
    "phi_rad": Channel("rad", _A, "roll angle φ (NED Euler), right wing down positive"),
    "theta_rad": Channel("rad", _A, "pitch angle θ (NED Euler), nose up positive"),
    "psi_rad": Channel("rad", _A, "heading ψ (NED Euler), clockwise from north"),
    "p_rad_s": Channel("rad/s", _A, "roll rate about the body x axis (forward)"),
    "r_rad_s": Channel("rad/s", _A, "yaw rate about the body z axis (down)"),
    "elevator_rad": Channel("rad", _A, "elevator deflection, trailing edge down positive "
                            "(held at trim in a gust run)"),
    "throttle": Channel("-", _A, "throttle, 0 to 1 (held at trim in a gust run)"),
    "alpha_rad": Channel("rad", _A, "angle of attack against the air (the gust included), "
                         "nose up positive"),
    "beta_rad": Channel("rad", _A, "sideslip angle, wind from starboard positive"),
    "v_north_m_s": Channel("m/s", _A, "inertial velocity, north (NED)"),
    "v_east_m_s": Channel("m/s", _A, "inertial velocity, east (NED)"),
    "v_down_m_s": Channel("m/s", _A, "inertial velocity, down (NED)"),
}
# A controller's commands, when one is in the loop (bioflex_jsb.simulation.controller)
COMMAND_CHANNELS: dict[str, Channel] = {
    "ctrl_elevator_rad": Channel("rad", _P, "elevator commanded by the controller in the loop, "
                                 "added to the trim's, trailing edge down positive (the "
                                 "surface's angle, within its travel: elevator_rad)"),
    "ctrl_throttle": Channel("-", _P, "throttle commanded by the controller in the loop, added "
                             "to the trim's (the total clipped to 0..1: throttle)"),
    "ctrl_flaperon_rad": Channel("rad", _P, "flaperon (both ailerons together, trailing edges "
                                 "down positive) commanded by the controller in the loop "
                                 "(the deflection, within its travel: flaperon_rad)"),
    "ctrl_aileron_rad": Channel("rad", _P, "aileron δa = (left - right)/2 commanded by the "
                                "controller in the loop, added to the trim's, + rolls right "
                                "(the surfaces' angle, within their travel: aileron_rad)"),
    "flaperon_rad": Channel("rad", _P, "flaperon deflection whose loads act over this step "
                            "(the previous step's command within the ±10° travel), trailing "
                            "edges down positive"),
}
# A full-span run's channels (both wing halves, bioflex_jsb.simulation.full_span)
LATERAL_CHANNELS: dict[str, Channel] = {
    "aileron_rad": Channel("rad", _A, "JSBSim's aileron δa = (left - right)/2 the "
                           "antisymmetric modes saw this step, + rolls right"),
    "modal_roll_n_m": Channel("N*m", _P, "the antisymmetric modes' rolling moment applied "
                              "over this step, right wing down positive"),
    "tip_twist_starboard_rad": Channel("rad", _P, "starboard tip twist of the modes, leading "
                                       "edge up"),
    "tip_twist_port_rad": Channel("rad", _P, "port tip twist of the modes, leading edge up"),
    "modal_side_n": Channel("N", _P, "the antisymmetric modes' side force applied over this "
                            "step, body +y"),
    "modal_yaw_n_m": Channel("N*m", _P, "the modes' yawing moment applied over this step, "
                             "nose right"),
}
BASE_UNITS: dict[str, str] = {name: c.unit for name, c in CHANNELS.items()}
# the self-describing name → the channel's own (``TimeHistory`` answers to both)
ALIASES: dict[str, str] = {c.alias: name for name, c in CHANNELS.items() if c.alias}

# Channels by pattern: the modal state, the section loads, the LTI model's inertial α
_ETA = re.compile(r"eta(\d+)")
_ETA_DOT = re.compile(r"eta(\d+)_dot")
_ASYM = re.compile(r"asym_eta(\d+)")
_ASYM_DOT = re.compile(r"asym_eta(\d+)_dot")
_LOADS = re.compile(r"loads_(fs|md)_(shear_n|bending_n_m|torque_n_m)_s(\d+)")
# the sensor stations' channels (bioflex_jsb.simulation.sensors: imu_channels, airspeed_channel)
_IMU = re.compile(r"imu_([a-z][a-z0-9_]{0,31})_(a|g)([xyz])_(m_s2|rad_s)")
_PROBE = re.compile(r"airspeed_([a-z][a-z0-9_]{0,31})_m_s")
_LOAD_METHOD = {"fs": "force summation", "md": "mode displacement"}
_LOAD_QUANTITY = {
    "shear_n": ("N", "vertical shear of the wing outboard, up positive"),
    "bending_n_m": ("N*m", "bending moment, tip up positive"),
    "torque_n_m": ("N*m", "torque about the elastic axis, leading edge up positive"),
}


def describe(name: str, unit: str | None = None) -> Channel:
    """What the channel ``name`` holds (:class:`Channel`). A name this module does not know
    (a channel another source added) is described by its ``unit`` alone (kind and meaning
    ``unknown``)."""
    if name in CHANNELS:
        return CHANNELS[name]
    if name in COMMAND_CHANNELS:
        return COMMAND_CHANNELS[name]
    if name in LATERAL_CHANNELS:
        return LATERAL_CHANNELS[name]
    if m := _ASYM.fullmatch(name):
        return Channel("rad", _P, f"modal coordinate of antisymmetric wing mode {m.group(1)} "
                       "(a full-span run; starboard tip twist positive, the port half the "
                       "opposite)")
    if m := _ASYM_DOT.fullmatch(name):
        return Channel("rad/s", _P, "rate of the modal coordinate of antisymmetric wing mode "
                       f"{m.group(1)}")
    if m := _ETA.fullmatch(name):
        return Channel("rad", _P, f"modal coordinate of wing mode {m.group(1)} (twist-"
                       "normalised: its largest section twist per unit η is 1 rad, tip twist "
                       "positive, leading edge up) from its value at the trim (0 at a rigid "
                       "trim, the static deflection at an elastic one)")
    if m := _ETA_DOT.fullmatch(name):
        return Channel("rad/s", _P, f"rate of the modal coordinate of wing mode {m.group(1)}")
    if m := _LOADS.fullmatch(name):
        method, quantity, station = m.groups()
        q_unit, what = _LOAD_QUANTITY[quantity]
        return Channel(q_unit, _A, f"{what}, by {_LOAD_METHOD[method]}, at monitoring station "
                       f"{station} (run.meta['loads']['stations_m']), the 1 g part included "
                       "(its value: run.meta['loads']['static_1g'])")
    if (m := _IMU.fullmatch(name)) and (m.group(2) == "a") == (m.group(4) == "m_s2"):
        station, kind, axis = m.group(1), m.group(2), m.group(3)
        if kind == "a":
            return Channel("m/s^2", _A, f"specific force along the {axis} axis of IMU "
                           f"{station!r}, its own axes (FRD when mounted level: 1 g level "
                           "flight reads z −9.81), at its point with the wing's modes")
        return Channel("rad/s", _A, f"angular rate about the {axis} axis of IMU {station!r}, "
                       "its own axes, the wing's modal rotation rates included")
    if m := _PROBE.fullmatch(name):
        return Channel("m/s", _A, f"true airspeed at airspeed probe {m.group(1)!r} (its "
                       "point's velocity against the air, the wing's modes included)")
    if name == "alpha_inertial":
        return Channel("rad", _P, "the LTI model's state α: inertial angle of attack θ − γ "
                       "(the gust not included), its perturbation from trim")
    return Channel(unit or "?", "unknown", "unknown")


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


def mode_tips(modes) -> list[dict[str, object]]:
    """What each wing mode's coordinate η_i [rad] does at the wing tip, for figures: a mode
    without twist (``ModalData.twist_free``: pure bending, a sailplane's first) moves the tip
    by ``per_rad`` [m] per rad of η_i (``quantity`` "tip deflection", up +); any other twists
    the tip by ``per_rad`` [rad] per rad (``quantity`` "tip twist", leading edge up +).
    ``modes``: a ``ModalData`` (signs: docs/conventions.md, bending positive down)."""
    free = modes.twist_free()
    out: list[dict[str, object]] = []
    for i in range(modes.n_modes):
        if free[i]:
            out.append({"quantity": "tip deflection", "unit": "m",
                        "per_rad": float(-modes.bending_m[i, -1])})
        else:
            out.append({"quantity": "tip twist", "unit": "rad",
                        "per_rad": float(modes.twist_rad[i, -1])})
    return out
