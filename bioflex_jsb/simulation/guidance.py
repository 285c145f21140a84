"""Lateral guidance of the SITL vehicle: the L1 law of Park, Deyst & How (2004), pure
functions on a local flat-Earth frame.

Frame: north-east [m] from an origin (the home position), positions and ground velocities
as (north, east) pairs. Lateral acceleration commands are [m/s², + to the right of the
velocity], banks [rad, + right wing down].

L1 law (Park, Deyst & How, "A New Nonlinear Guidance Logic for Trajectory Tracking", AIAA
GNC 2004): pick the reference point on the path at the distance L1 ahead of the aircraft;
with η the angle from the ground velocity to the line of sight to it, command

    a_cmd = 2 V² sin η / L1,

the centripetal acceleration of the circle through the aircraft, tangent to its velocity,
that reaches the reference point. Linearised about a straight track it is a second-order
loop of damping ζ and period P when L1 = ζ P V / π (ArduPilot's NAVL1_PERIOD and
NAVL1_DAMPING parameterise it the same way; this code is written from the paper).

* straight legs (:func:`l1_track`): the reference point is where the circle of radius L1
  about the aircraft cuts the track ahead of the foot of the perpendicular; farther than L1
  from the track, it is the foot itself (η ≤ 90°: the aircraft turns towards the track);
* circles (:func:`l1_circle`): the reference point is the intersection of the loiter circle
  with the L1 circle ahead in the loiter direction; outside reach (farther than L1 from the
  circle) the centre's bearing ± the tangent angle, which steers onto a tangent.

|η| is capped at 90° (a reference point behind gives the hardest turn, not a reversal).
"""

from __future__ import annotations

import math
from typing import NamedTuple

G_M_S2 = 9.80665
EARTH_RADIUS_M = 6_371_000.0  # mean radius: the local north-east frame's scale


class Guidance(NamedTuple):
    """A lateral command: acceleration [m/s², + right] and the cross-track error [m, + the
    aircraft is right of the path] it was computed from."""

    accel_m_s2: float
    cross_track_m: float


def l1_distance_m(ground_speed_m_s: float, period_s: float = 20.0, damping: float = 0.75) -> float:
    """L1 = ζ P V / π [m] (at least 1 m)."""
    return max(1.0, damping * period_s * ground_speed_m_s / math.pi)


def ne_from_latlon(lat_rad: float, lon_rad: float, lat0_rad: float,
                   lon0_rad: float) -> tuple[float, float]:
    """North, east [m] of (lat, lon) from (lat0, lon0): equirectangular (flat Earth, good to
    well under 1 m over the few km a SITL flight spans)."""
    dlon = math.remainder(lon_rad - lon0_rad, 2.0 * math.pi)
    return ((lat_rad - lat0_rad) * EARTH_RADIUS_M,
            dlon * EARTH_RADIUS_M * math.cos(lat0_rad))


def latlon_from_ne(north_m: float, east_m: float, lat0_rad: float,
                   lon0_rad: float) -> tuple[float, float]:
    """(lat, lon) [rad] of the point north, east [m] of (lat0, lon0) (inverse of
    :func:`ne_from_latlon`)."""
    return (lat0_rad + north_m / EARTH_RADIUS_M,
            lon0_rad + east_m / (EARTH_RADIUS_M * math.cos(lat0_rad)))


def _eta_accel(pos, vel, ref, l1_m: float) -> float:
    vn, ve = vel
    speed = math.hypot(vn, ve)
    if speed < 0.1:
        return 0.0
    dn, de = ref[0] - pos[0], ref[1] - pos[1]
    # angle from the velocity to the line of sight, + when the point is to the right
    eta = math.atan2(vn * de - ve * dn, vn * dn + ve * de)
    eta = max(-0.5 * math.pi, min(0.5 * math.pi, eta))
    return 2.0 * speed * speed * math.sin(eta) / l1_m


def l1_track(pos, vel, a, b, l1_m: float) -> Guidance:
    """Lateral command along the straight track from ``a`` to ``b`` (north-east [m])."""
    tn, te = b[0] - a[0], b[1] - a[1]
    length = math.hypot(tn, te)
    if length < 1e-6:
        return Guidance(_eta_accel(pos, vel, b, l1_m), 0.0)
    tn, te = tn / length, te / length
    rn, re = pos[0] - a[0], pos[1] - a[1]
    along = rn * tn + re * te
    cross = re * tn - rn * te  # + right of the track (track north: + is east)
    if abs(cross) >= l1_m:
        ahead = 0.0
    else:
        ahead = math.sqrt(l1_m * l1_m - cross * cross)
    s = min(along + ahead, length)  # not beyond b: b itself is then the reference point
    ref = (a[0] + s * tn, a[1] + s * te)
    if along + ahead > length:
        ref = b
    return Guidance(_eta_accel(pos, vel, ref, l1_m), cross)


def l1_circle(pos, vel, centre, radius_m: float, clockwise: bool, l1_m: float) -> Guidance:
    """Lateral command onto the circle of ``radius_m`` about ``centre`` (north-east [m]),
    flown clockwise (seen from above) or not. The cross-track error is the distance from
    the circle [m, + outside]."""
    rn, re = pos[0] - centre[0], pos[1] - centre[1]
    d = math.hypot(rn, re)
    err = d - radius_m
    if d < 1e-6:
        return Guidance(0.0, err)
    bearing = math.atan2(re, rn)  # from the centre to the aircraft
    sense = 1.0 if clockwise else -1.0
    if abs(err) < l1_m and d + radius_m > l1_m:
        # intersection of the circle (centre, R) with the circle (aircraft, L1): the angle at
        # the centre between the aircraft and the intersection (law of cosines)
        c = (d * d + radius_m * radius_m - l1_m * l1_m) / (2.0 * d * radius_m)
        phi = math.acos(max(-1.0, min(1.0, c)))
        ang = bearing + sense * phi
        ref = (centre[0] + radius_m * math.cos(ang), centre[1] + radius_m * math.sin(ang))
        accel = _eta_accel(pos, vel, ref, l1_m)
    elif err >= l1_m:
        # outside reach: head for the tangent point (the loiter direction's side)
        tangent = math.asin(min(1.0, radius_m / d))
        los = bearing + math.pi - sense * tangent
        ref = (pos[0] + l1_m * math.cos(los), pos[1] + l1_m * math.sin(los))
        accel = _eta_accel(pos, vel, ref, l1_m)
    else:
        # deep inside the circle (L1 > d + R): fly outwards along the loiter direction
        ang = bearing + sense * 0.25 * math.pi
        ref = (pos[0] + l1_m * math.cos(ang), pos[1] + l1_m * math.sin(ang))
        accel = _eta_accel(pos, vel, ref, l1_m)
    return Guidance(accel, err)


def bank_for(accel_m_s2: float, max_bank_rad: float) -> float:
    """Bank [rad] of a coordinated turn with the lateral acceleration ``accel_m_s2``,
    clipped to ±``max_bank_rad``."""
    phi = math.atan2(accel_m_s2, G_M_S2)
    return max(-max_bank_rad, min(max_bank_rad, phi))


def distance_m(p, q) -> float:
    return math.hypot(p[0] - q[0], p[1] - q[1])
