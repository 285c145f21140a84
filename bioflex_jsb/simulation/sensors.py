"""What an IMU and an airspeed probe read at their own point of the flexible aircraft.

The numerical core of the sensor stations (``docs/aircraft.md``, "Sensors"); no JSBSim here:
the coupled step (:mod:`bioflex_jsb.runtime.coupled_step`) hands it the rigid body's state
and the wing's modal state each step.

**Accelerometer** (specific force, body axes from the CG: x forward, y starboard, z down
[m/s²]). A point at r [m] from the CG, fixed to the rigid airframe, reads

    f(r) = f_cg + ω̇ × r + ω × (ω × r),

f_cg the non-gravitational force over the mass (JSBSim's ``forces/fb*-total-lbs`` over
``inertia/mass-slugs``: what the autopilot's IMU at the CG reads today), ω the body rates
and ω̇ their rates (JSBSim's ``velocities/p-rad_sec``…, ``accelerations/pdot-rad_sec2``…).
A point on the elastic wing also moves with the modes: its displacement is Σ_i U_i η_i,
U_i the mode's translation at the point (:func:`station_shapes`), so it adds

    Σ_i U_i η̈_i + 2 ω × Σ_i U_i η̇_i

(its acceleration relative to the body and the Coriolis term; products of two small
elastic quantities and of the deflection with ω̇ and ω² are left out, as the linear modal
model leaves them out). Its axes turn with the wing by the small rotation δ = Σ_i Ψ_i η_i
(Ψ_i the mode's rotation there: the bending slope as a roll, the twist as a pitch), so a
vector v in body axes reads v − δ × v in the deflected axes; then the sensor's mounting
(its Euler angles from the body axes) turns it into the sensor's axes.

**Gyro** (body rates at the point, sensor axes [rad/s]): ω + Σ_i Ψ_i η̇_i, in the deflected
axes as above.

**Airspeed probe** (true airspeed at the point [m/s]): |v_air + ω × r + Σ_i U_i η̇_i|, v_air
the CG's velocity against the air in body axes (from the run's airspeed, α and β).

**The modal rates and accelerations.** The coupled step knows η_{k−1}, η_k and, once the wing
has stepped, η_{k+1}: the row of t_k takes η̈_k = (η_{k+1} − 2 η_k + η_{k−1}) / Δt² (central,
no lag; a harmonic of frequency ω reads (sin(ωΔt/2)/(ωΔt/2))² of its amplitude: 0.34 % low
for the prototype's first mode, 30.9 Hz, at Δt = 1/960 s) and η̇_k the wing's own state (the
quasi-static wing, whose η̇ is not a state: (η_{k+1} − η_{k−1}) / (2Δt)).
:func:`latest_modal_kinematics` gives the values at the newest state instead, for an
autopilot sent the state a step reached (ArduPilot's JSON backend): η̈ the mean over the last
step, (η̇_{k+1} − η̇_k)/Δt, half a step old (0.52 ms at 960 Hz).

**Both wing halves** (a full-span run: :mod:`bioflex_jsb.simulation.full_span`). The
modal columns are the symmetric modes η_s, then the antisymmetric ones η_a
(:meth:`SensorSet.with_antisymmetric`). A wing point at y moves by Σ U^s η_s + sign(y) Σ U^a
η_a, U^a the antisymmetric shape of the starboard half at |y| (normalised with the starboard
tip twist positive): a positive η_a twists the starboard section leading edge up and the
port one leading edge down, and bends them opposite ways; the columns of a port station are
the starboard mirror's times −1 (its roll slope included, so both halves of a mode that
dips the starboard tip and lifts the port one read the same roll). A point of the rigid
airframe (no wing point: a fuselage IMU, the autopilot's) rolls with the fuselage, whose roll
relative to the mean axes (JSBSim's body axes) is the antisymmetric modes' root slope
ρ₀ = Σ w'_i(0) η_a,i (the beam with the fuselage's roll freedom,
:mod:`bioflex_jsb.structures.antisymmetric`): Ψ^a = (ρ₀, 0, 0), U^a = Ψ^a × r. The symmetric
modes are clamped at the root: they leave such a point alone, as on the half wing, whose
sensors read exactly as before.

**Noise** (:class:`NoiseSource`): ArduPilot's SITL meanings (:mod:`bioflex_jsb.parameters.
sensors`): bias, uniform ±RND, or a sine at SIM_VIB_FREQ with amplitude RND (1 ± 5 %),
in the sensor's axes, seeded.
"""

from __future__ import annotations

import math
import re

import numba
import numpy as np

from bioflex_jsb.parameters.sensors import (
    VIBRATION_AMPLITUDE_SPREAD,
    AirspeedSpec,
    ImuSpec,
    SensorNoise,
    Sensors,
    WingPoint,
    euler_matrix,
)

IMU_AXES = ("ax_m_s2", "ay_m_s2", "az_m_s2", "gx_rad_s", "gy_rad_s", "gz_rad_s")
IMU_UNITS = ("m/s^2",) * 3 + ("rad/s",) * 3
NAME_PATTERN = re.compile(r"[a-z][a-z0-9_]{0,31}")
# The rigid body's inputs of a step, in this order (SI, body axes FRD): the CG's specific
# force [m/s²], the body rates [rad/s], their rates [rad/s²], the CG's velocity against the
# air [m/s].
KINEMATICS = ("f_x", "f_y", "f_z", "p", "q", "r", "p_dot", "q_dot", "r_dot",
              "u_air", "v_air", "w_air")
NOISE_BLOCK = 4096  # noise samples drawn at a time per sensor (a step then only indexes)
# What the compiled sensor row reads of the airframe, in this order (JSBSim's units): the
# total forces [lbf] and the mass [slug], the rates' rates [rad/s²], the body velocities
# [ft/s], θ, φ [rad] and the rates [rad/s]; :meth:`SensorRows.compiled` turns them into the
# :data:`KINEMATICS` as the coupled step's ``_kinematics`` does.
KINEMATICS_READS = ("fbx_lbf", "fby_lbf", "fbz_lbf", "mass_slug", "p_dot", "q_dot", "r_dot",
                    "u_fps", "v_fps", "w_fps", "theta", "phi", "p", "q", "r")


def imu_channels(name: str) -> tuple[str, ...]:
    """The six channels of the IMU ``name``: specific force x, y, z [m/s²], rates x, y, z
    [rad/s], in its sensor axes."""
    return tuple(f"imu_{name}_{axis}" for axis in IMU_AXES)


def airspeed_channel(name: str) -> str:
    """The channel of the airspeed probe ``name`` [m/s]."""
    return f"airspeed_{name}_m_s"


def station_shapes(modes, point: WingPoint | None, n_modes: int | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """(U (3, n), Ψ (3, n)): each mode's translation [m per unit η] and small rotation [rad
    per unit η] at the wing point ``point`` in body axes (x forward, y starboard, z down),
    from the modes' shapes (``ModalData``: bending φ positive down, twist θ leading edge up,
    linear between its stations; docs/conventions.md). ``point`` None (a sensor on the rigid
    airframe) or no ``modes``: zeros (n = ``n_modes`` then).

    The elastic axis there moves down by φ(|y|); the section turns by Ψ = (ρ, θ, 0): the
    roll ρ = sign(y) dφ/dy (bending down growing outboard dips the starboard wing, rolling
    right; the port wing mirrors) and the pitch θ (leading edge up is nose up); a point d
    from the elastic axis (``elastic_axis_offset_m`` aft, ``height_m`` up: d = (−aft, 0,
    −height) in body axes) moves by Ψ × d more.
    """
    if modes is None or point is None:
        n = int(n_modes or 0) if modes is None else modes.n_modes
        return np.zeros((3, n)), np.zeros((3, n))
    y = abs(point.y_m)
    side = math.copysign(1.0, point.y_m) if point.y_m != 0.0 else 0.0
    stations = np.asarray(modes.stations_m, dtype=float)
    if y > stations[-1] * (1.0 + 1e-9):
        raise ValueError(f"sensor station y = {point.y_m:g} m is beyond the wing's modes "
                         f"(semispan {stations[-1]:g} m)")
    bending = np.asarray(modes.bending_m, dtype=float)
    twist = np.asarray(modes.twist_rad, dtype=float)
    # the slope of the bending by second-order differences on the modes' own stations
    slope = np.gradient(bending, stations, axis=1, edge_order=2 if stations.size > 2 else 1)
    phi = np.array([np.interp(y, stations, b) for b in bending])
    theta = np.array([np.interp(y, stations, t) for t in twist])
    rho = side * np.array([np.interp(y, stations, s) for s in slope])
    dx, dz = -point.elastic_axis_offset_m, -point.height_m
    u = np.vstack([theta * dz, -rho * dz, phi - theta * dx])
    psi = np.vstack([rho, theta, np.zeros_like(theta)])
    return u, psi


def antisymmetric_shapes(modes, root_slope, point: WingPoint | None, position_m
                         ) -> tuple[np.ndarray, np.ndarray]:
    """(U (3, n), Ψ (3, n)) of the antisymmetric modes ``modes`` (``ModalData`` of the
    starboard half) at a sensor (module docstring, "Both wing halves"): at the wing point
    ``point``, sign(y) times :func:`station_shapes` of the starboard shape at |y| (a point on
    the centreline, y = 0: zeros); on the rigid airframe (``point`` None) at ``position_m``
    (body axes from the CG [m]), the fuselage's roll Ψ = (ρ₀, 0, 0) and U = Ψ × r with
    ``root_slope`` ρ₀ (n,) [rad per unit η] (None: zeros)."""
    n = modes.n_modes
    if point is not None:
        u, psi = station_shapes(modes, point)
        side = math.copysign(1.0, point.y_m) if point.y_m != 0.0 else 0.0
        return side * u, side * psi
    if root_slope is None:
        return np.zeros((3, n)), np.zeros((3, n))
    rho = np.asarray(root_slope, dtype=float)
    _, y, z = (float(v) for v in position_m)
    return (np.vstack([np.zeros(n), -rho * z, rho * y]),
            np.vstack([rho, np.zeros(n), np.zeros(n)]))


@numba.njit(cache=True, nogil=True)
def _imu_readings(kin, eta, eta_dot, eta_ddot, r, u, psi, mount, noise, out):
    """The readings of m IMUs (module docstring) into ``out`` (m, 6): ``kin`` the
    :data:`KINEMATICS` (12,), η, η̇, η̈ (n,), ``r`` (m, 3) positions [m], ``u``, ``psi`` (m,
    3, n) the modes' translations and rotations there, ``mount`` (m, 3, 3) body → sensor
    axes, ``noise`` (m, 6) what the sensor adds this sample (bias and noise, sensor axes)."""
    fx, fy, fz = kin[0], kin[1], kin[2]
    p, q, rr = kin[3], kin[4], kin[5]
    pd, qd, rd = kin[6], kin[7], kin[8]
    m, n = r.shape[0], eta.shape[0]
    for s in range(m):
        x, y, z = r[s, 0], r[s, 1], r[s, 2]
        # ω̇ × r + ω × (ω × r)
        cx, cy, cz = q * z - rr * y, rr * x - p * z, p * y - q * x  # ω × r
        ax = fx + (qd * z - rd * y) + (q * cz - rr * cy)
        ay = fy + (rd * x - pd * z) + (rr * cx - p * cz)
        az = fz + (pd * y - qd * x) + (p * cy - q * cx)
        vx = vy = vz = 0.0  # the point's modal velocity Σ U η̇
        dx = dy = dz = 0.0  # the axes' modal rotation Σ Ψ η
        gx, gy, gz = p, q, rr
        for i in range(n):
            ax += u[s, 0, i] * eta_ddot[i]
            ay += u[s, 1, i] * eta_ddot[i]
            az += u[s, 2, i] * eta_ddot[i]
            vx += u[s, 0, i] * eta_dot[i]
            vy += u[s, 1, i] * eta_dot[i]
            vz += u[s, 2, i] * eta_dot[i]
            dx += psi[s, 0, i] * eta[i]
            dy += psi[s, 1, i] * eta[i]
            dz += psi[s, 2, i] * eta[i]
            gx += psi[s, 0, i] * eta_dot[i]
            gy += psi[s, 1, i] * eta_dot[i]
            gz += psi[s, 2, i] * eta_dot[i]
        # Coriolis: 2 ω × v
        ax += 2.0 * (q * vz - rr * vy)
        ay += 2.0 * (rr * vx - p * vz)
        az += 2.0 * (p * vy - q * vx)
        # in the deflected axes: v − δ × v
        bx, by, bz = ax - (dy * az - dz * ay), ay - (dz * ax - dx * az), az - (dx * ay - dy * ax)
        hx, hy, hz = gx - (dy * gz - dz * gy), gy - (dz * gx - dx * gz), gz - (dx * gy - dy * gx)
        for j in range(3):
            out[s, j] = (mount[s, j, 0] * bx + mount[s, j, 1] * by + mount[s, j, 2] * bz
                         + noise[s, j])
            out[s, 3 + j] = (mount[s, j, 0] * hx + mount[s, j, 1] * hy + mount[s, j, 2] * hz
                             + noise[s, 3 + j])


@numba.njit(cache=True, nogil=True)
def _airspeed_readings(kin, eta_dot, r, u, noise, out):
    """The true airspeed [m/s] at m probes into ``out`` (m,): |v_air + ω × r + Σ U η̇| plus
    ``noise`` (m,)."""
    p, q, rr = kin[3], kin[4], kin[5]
    for s in range(r.shape[0]):
        x, y, z = r[s, 0], r[s, 1], r[s, 2]
        vx = kin[9] + q * z - rr * y
        vy = kin[10] + rr * x - p * z
        vz = kin[11] + p * y - q * x
        for i in range(eta_dot.shape[0]):
            vx += u[s, 0, i] * eta_dot[i]
            vy += u[s, 1, i] * eta_dot[i]
            vz += u[s, 2, i] * eta_dot[i]
        out[s] = math.sqrt(vx * vx + vy * vy + vz * vz) + noise[s]


@numba.njit(cache=True, nogil=True)
def _hold_kernel(x, at, n, dt, hist, flags):
    """:meth:`SensorRows.before` compiled: the wing's η_k, η̇_k from its state ``x`` (η_i at
    ``x[at[i]]``, η̇_i at ``x[at[n + i]]``) into ``hist`` rows 1 and 2; row 0 (η_{k−1}) made
    η_k − Δt η̇_k at the first call (``flags[0]`` 0)."""
    for i in range(n):
        hist[1, i] = x[at[i]]
        hist[2, i] = x[at[n + i]]
    if flags[0] == 0.0:
        for i in range(n):
            hist[0, i] = hist[1, i] - dt * hist[2, i]
        flags[0] = 1.0


@numba.njit(cache=True, nogil=True)
def _row_kernel(reads, wind_down_fps, m_per_ft, x, at, n, dt, rate_state, hist, kin, dot,
                ddot, r, u, psi, mount, noise, imu_out, r_air, u_air, air_noise, air_out, table,
                k, cols):
    """:meth:`SensorRows.row` and the rigid body's kinematics compiled (module docstring):
    ``reads`` the :data:`KINEMATICS_READS`, the wind down [ft/s]; the wing's η_{k+1} at
    ``x[at[:n]]``; the channels written into ``table[k, cols]`` (IMUs, then probes);
    η_{k−1} ← η_k after."""
    fx, fy, fz, mass, pd, qd, rd = reads[0], reads[1], reads[2], reads[3], reads[4], reads[5], \
        reads[6]
    uu, vv, ww, theta, phi = reads[7], reads[8], reads[9], reads[10], reads[11]
    c = m_per_ft / mass
    st, ct = math.sin(theta), math.cos(theta)
    kin[0], kin[1], kin[2] = fx * c, fy * c, fz * c
    kin[3], kin[4], kin[5] = reads[12], reads[13], reads[14]
    kin[6], kin[7], kin[8] = pd, qd, rd
    kin[9] = (uu + wind_down_fps * st) * m_per_ft
    kin[10] = (vv - wind_down_fps * math.sin(phi) * ct) * m_per_ft
    kin[11] = (ww - wind_down_fps * math.cos(phi) * ct) * m_per_ft
    for i in range(n):
        xi = x[at[i]]
        ddot[i] = (xi - 2.0 * hist[1, i] + hist[0, i]) / (dt * dt)
        dot[i] = hist[2, i] if rate_state else (xi - hist[0, i]) / (2.0 * dt)
    m = imu_out.shape[0]
    if m:
        _imu_readings(kin, hist[1], dot, ddot, r, u, psi, mount, noise, imu_out)
        for s in range(m):
            for j in range(6):
                table[k, cols[6 * s + j]] = imu_out[s, j]
    if air_out.shape[0]:
        _airspeed_readings(kin, dot, r_air, u_air, air_noise, air_out)
        for s in range(air_out.shape[0]):
            table[k, cols[6 * m + s]] = air_out[s]
    for i in range(n):
        hist[0, i] = hist[1, i]


def central_modal_kinematics(eta_prev, eta, eta_next, eta_dot, dt_s: float,
                             rate_state: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(η̇_k [rad/s], η̈_k [rad/s²]) at t_k from η_{k−1}, η_k, η_{k+1} [rad] (module
    docstring): η̈ the second central difference; η̇ the wing's own ``eta_dot`` when it is a
    state (``rate_state``), else the central difference."""
    eta_prev, eta, eta_next = (np.asarray(a, dtype=float) for a in (eta_prev, eta, eta_next))
    ddot = (eta_next - 2.0 * eta + eta_prev) / (dt_s * dt_s)
    dot = (np.asarray(eta_dot, dtype=float) if rate_state
           else (eta_next - eta_prev) / (2.0 * dt_s))
    return dot, ddot


def latest_modal_kinematics(eta_prev2, eta_prev, eta, eta_dot_prev, eta_dot, dt_s: float,
                            rate_state: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """(η̇, η̈) at the newest state (index k+1) from the states before it (module docstring):
    with a rate state, η̇ the state's and η̈ = (η̇_{k+1} − η̇_k)/Δt (the last step's mean, half
    a step old); without, η̇ = (η_{k+1} − η_k)/Δt and η̈ = (η_{k+1} − 2η_k + η_{k−1})/Δt²."""
    eta_prev2, eta_prev, eta = (np.asarray(a, dtype=float) for a in (eta_prev2, eta_prev, eta))
    if rate_state:
        dot = np.asarray(eta_dot, dtype=float)
        return dot, (dot - np.asarray(eta_dot_prev, dtype=float)) / dt_s
    return (eta - eta_prev) / dt_s, (eta - 2.0 * eta_prev + eta_prev2) / (dt_s * dt_s)


class NoiseSource:
    """What a sensor adds to each sample in its own axes (ArduPilot's meanings:
    :mod:`bioflex_jsb.parameters.sensors`): the biases, and uniform noise ±RND or, with a
    vibration frequency, RND (1 ± 5 %) sin(2π f t). ``biases``, ``amplitudes``: per
    channel; ``frequencies_hz``: per channel (0: uniform noise); the samples drawn from a
    seeded generator a block at a time."""

    def __init__(self, biases, amplitudes, frequencies_hz, seed: int) -> None:
        self.biases = np.asarray(biases, dtype=float)
        self.amplitudes = np.asarray(amplitudes, dtype=float)
        self.frequencies_hz = np.asarray(frequencies_hz, dtype=float)
        self.vibrating = bool(np.any(self.frequencies_hz > 0.0))
        self.random = bool(np.any(self.amplitudes > 0.0))
        self._rng = np.random.default_rng(int(seed))
        self._block = np.zeros((0, self.biases.size))
        self._at = 0

    def _uniform(self) -> np.ndarray:
        if self._at >= len(self._block):
            self._block = self._rng.uniform(-1.0, 1.0, size=(NOISE_BLOCK, self.biases.size))
            self._at = 0
        row = self._block[self._at]
        self._at += 1
        return row

    def sample(self, t_s: float) -> np.ndarray:
        """The sample's addition at time ``t_s`` [s] (one per call, in order)."""
        if not self.random:
            return self.biases
        u = self._uniform()
        if not self.vibrating:
            return self.biases + self.amplitudes * u
        wave = np.sin(2.0 * math.pi * self.frequencies_hz * t_s)
        # as ArduPilot: with any vibration frequency set, no uniform noise on any axis (an
        # axis whose frequency is 0 reads sin 0 = 0)
        return self.biases + self.amplitudes * (1.0 + VIBRATION_AMPLITUDE_SPREAD * u) * wave


def imu_noise(noise: SensorNoise) -> NoiseSource:
    """The :class:`NoiseSource` of an IMU's :class:`SensorNoise` (six channels)."""
    return NoiseSource((*noise.accel_bias_m_s2, *noise.gyro_bias_rad_s),
                       (noise.accel_noise_m_s2,) * 3 + (noise.gyro_noise_rad_s,) * 3,
                       tuple(noise.vibration_hz) * 2, noise.seed)


class SensorSet:
    """An aircraft's IMUs and airspeed probes with their modal shapes, ready to read.

    ``sensors``: the :class:`~bioflex_jsb.parameters.sensors.Sensors` (positions in body
    axes from the CG); ``modes``: the wing's ``ModalData`` (None: a rigid wing, no modal
    part); ``n_modes``: the modes the run flies (the first ones of ``modes``);
    ``antisymmetric``: a full-span run's antisymmetric modes (``ModalData``, starboard half)
    and ``root_slope`` their root slopes [rad per unit η] (module docstring, "Both wing
    halves"): their columns after the symmetric ones (:attr:`n_columns` in all).
    """

    def __init__(self, sensors: Sensors, modes=None, n_modes: int | None = None,
                 antisymmetric=None, root_slope=None) -> None:
        self.sensors = sensors
        self.imus: tuple[ImuSpec, ...] = tuple(sensors.imus)
        self.airspeeds: tuple[AirspeedSpec, ...] = tuple(sensors.airspeeds)
        for spec in (*self.imus, *self.airspeeds):
            if not NAME_PATTERN.fullmatch(spec.name):
                raise ValueError(f"sensor name {spec.name!r}: accepted lower-case letters, "
                                 "digits and _, starting with a letter, at most 32")
        names = [s.name for s in self.imus] + [s.name for s in self.airspeeds]
        if len(set(s.name for s in self.imus)) != len(self.imus) or len(
                set(s.name for s in self.airspeeds)) != len(self.airspeeds):
            raise ValueError(f"sensor names must differ: {names}")
        n = (modes.n_modes if modes is not None else 0) if n_modes is None else int(n_modes)
        if modes is not None and n > modes.n_modes:
            raise ValueError(f"{n} modes flown, the modes hold {modes.n_modes}")
        if modes is not None and n < modes.n_modes:
            modes = modes.truncated(n)
        self.modes, self.n_modes = modes, n
        self.antisymmetric, self.root_slope = antisymmetric, root_slope
        self.n_antisymmetric = 0 if antisymmetric is None else antisymmetric.n_modes
        self.n_columns = n + self.n_antisymmetric  # the symmetric modes, then the others

        def shapes(spec) -> tuple[np.ndarray, np.ndarray]:
            u, psi = station_shapes(modes, spec.wing, n)
            if antisymmetric is None:
                return u, psi
            u_a, psi_a = antisymmetric_shapes(antisymmetric, root_slope, spec.wing,
                                              spec.position_m)
            return np.hstack([u, u_a]), np.hstack([psi, psi_a])

        m, nc = len(self.imus), self.n_columns
        self.r = np.zeros((m, 3))
        self.u = np.zeros((m, 3, nc))
        self.psi = np.zeros((m, 3, nc))
        self.mount = np.zeros((m, 3, 3))
        for s, imu in enumerate(self.imus):
            self.r[s] = imu.position_m
            self.u[s], self.psi[s] = shapes(imu)
            self.mount[s] = np.array(euler_matrix(*imu.orientation_rad))
        a = len(self.airspeeds)
        self.r_air = np.zeros((a, 3))
        self.u_air = np.zeros((a, 3, nc))
        for s, probe in enumerate(self.airspeeds):
            self.r_air[s] = probe.position_m
            self.u_air[s], _ = shapes(probe)
        self._noise = [imu_noise(imu.noise) for imu in self.imus]
        self._noisy = any(src.random or np.any(src.biases) for src in self._noise)
        self._imu_noise = np.zeros((m, 6))
        self._air_noise = [NoiseSource((0.0,), (p.noise_m_s,), (0.0,), p.seed)
                           for p in self.airspeeds]
        self._air_noise_now = np.zeros(a)
        self._air_noisy = any(p.noise_m_s > 0.0 for p in self.airspeeds)
        self.imu_out = np.zeros((m, 6))
        self.air_out = np.zeros(a)
        self.channels: tuple[str, ...] = tuple(
            c for imu in self.imus for c in imu_channels(imu.name)) + tuple(
            airspeed_channel(p.name) for p in self.airspeeds)
        self.units: dict[str, str] = {}
        for imu in self.imus:
            self.units.update(zip(imu_channels(imu.name), IMU_UNITS, strict=True))
        for p in self.airspeeds:
            self.units[airspeed_channel(p.name)] = "m/s"
        self.values = np.zeros(len(self.channels))

    def __len__(self) -> int:
        return len(self.channels)

    def with_antisymmetric(self, modes, root_slope=None) -> SensorSet:
        """These sensors on both wing halves: a new set (fresh noise streams, the same
        seeds) whose columns add the antisymmetric ``modes`` (``ModalData``, starboard half)
        with their root slopes ``root_slope`` [rad per unit η] (module docstring)."""
        return SensorSet(self.sensors, self.modes, self.n_modes, modes, root_slope)

    def _columns(self, a) -> np.ndarray:
        """``a`` as the :attr:`n_columns` modal columns: cut to them, zeros after a shorter
        one (a wing at rest given by its symmetric modes alone)."""
        a = np.asarray(a, dtype=float)[:self.n_columns]
        if a.size == self.n_columns:
            return a
        out = np.zeros(self.n_columns)
        out[:a.size] = a
        return out

    def read(self, kin, eta, eta_dot, eta_ddot, t_s: float) -> np.ndarray:
        """Every channel (:attr:`channels` order) for the rigid body's :data:`KINEMATICS`
        ``kin`` (12,) and the modal state η [rad], η̇ [rad/s], η̈ [rad/s²] at time ``t_s``
        [s] (the noise's clock: call once per sample, in order; both halves: the symmetric
        modes, then the antisymmetric ones). The returned array is reused by the next
        call."""
        kin = np.asarray(kin, dtype=float)
        eta, eta_dot, eta_ddot = (np.asarray(a, dtype=float)[:self.n_columns]
                                  for a in (eta, eta_dot, eta_ddot))
        if self._noisy:
            for s, src in enumerate(self._noise):
                self._imu_noise[s] = src.sample(t_s)
        if len(self.imus):
            _imu_readings(kin, eta, eta_dot, eta_ddot, self.r, self.u, self.psi, self.mount,
                          self._imu_noise, self.imu_out)
        m6 = 6 * len(self.imus)
        self.values[:m6] = self.imu_out.ravel()
        if len(self.airspeeds):
            if self._air_noisy:
                for s, src in enumerate(self._air_noise):
                    self._air_noise_now[s] = src.sample(t_s)[0]
            _airspeed_readings(kin, eta_dot, self.r_air, self.u_air, self._air_noise_now,
                               self.air_out)
            self.values[m6:] = self.air_out
        return self.values

    def clean(self, kin, eta, eta_dot, eta_ddot) -> dict[str, float]:
        """Every channel by name as :meth:`read` gives it without the noise and the biases
        (the sensor's true reading; its noise streams untouched): a controller's trim
        values (:class:`~bioflex_jsb.simulation.controller.ControlLoop`)."""
        kin = np.asarray(kin, dtype=float)
        eta, eta_dot, eta_ddot = (self._columns(a) for a in (eta, eta_dot, eta_ddot))
        imu = np.zeros((len(self.imus), 6))
        air = np.zeros(len(self.airspeeds))
        if len(self.imus):
            _imu_readings(kin, eta, eta_dot, eta_ddot, self.r, self.u, self.psi, self.mount,
                          np.zeros_like(imu), imu)
        if len(self.airspeeds):
            _airspeed_readings(kin, eta_dot, self.r_air, self.u_air, np.zeros_like(air), air)
        return dict(zip(self.channels, [*imu.ravel().tolist(), *air.tolist()], strict=True))

    def imu_index(self, name: str) -> int:
        """The position of the IMU ``name`` among :attr:`imus`."""
        for s, imu in enumerate(self.imus):
            if imu.name == name:
                return s
        raise KeyError(name)

    def describe(self) -> dict[str, object]:
        """The sensors as plain data (logs, --json): each IMU's spec and its modal shapes
        (columns: the symmetric modes, then any antisymmetric ones)."""
        extra = ({} if self.antisymmetric is None
                 else {"antisymmetric_modes": self.n_antisymmetric})
        return {**extra, "imus": [dict(imu.as_dict(), channels=list(imu_channels(imu.name)),
                              translation_m_per_rad=self.u[s].tolist(),
                              rotation_rad_per_rad=self.psi[s].tolist())
                         for s, imu in enumerate(self.imus)],
                "airspeeds": [dict(p.as_dict(), channel=airspeed_channel(p.name))
                              for p in self.airspeeds]}


def air_velocity_body(airspeed_m_s: float, alpha_rad: float, beta_rad: float
                      ) -> tuple[float, float, float]:
    """The CG's velocity against the air in body axes [m/s] from V, α, β (JSBSim's
    definitions: α = atan2(w, u), β = asin(v / V))."""
    cb = math.cos(beta_rad)
    return (airspeed_m_s * math.cos(alpha_rad) * cb, airspeed_m_s * math.sin(beta_rad),
            airspeed_m_s * math.sin(alpha_rad) * cb)


class SensorRows:
    """The sensor channels of each step of a run, for the coupled step
    (:mod:`bioflex_jsb.runtime.coupled_step`): :meth:`before` with the wing's state at t_k
    before its step, :meth:`row` with the rigid body's :data:`KINEMATICS` at t_k and the
    wing's η_{k+1} after it (module docstring: central differences, η_{−1} = η_0 − Δt η̇_0,
    a wing at rest before the run). ``rate_state``: the wing's η̇ is a state (the coupled,
    unsteady and native wings; not the quasi-static one). ``lateral``: a full-span run's
    antisymmetric wing (its ``eta``, ``eta_dot`` [rad, rad/s], read when the symmetric
    wing's are given: the set's columns after them, :meth:`SensorSet.with_antisymmetric`)."""

    def __init__(self, sensor_set: SensorSet, dt_s: float, rate_state: bool,
                 lateral=None) -> None:
        self.set = sensor_set
        self.dt_s = float(dt_s)
        self.rate_state = bool(rate_state)
        self.lateral = lateral
        if (lateral is None) != (sensor_set.n_antisymmetric == 0) or (
                lateral is not None and lateral.n_modes != sensor_set.n_antisymmetric):
            raise ValueError("the sensors' antisymmetric modes and the lateral wing differ")
        n = sensor_set.n_columns
        self.n_modes = n
        # η_{k−1}, η_k, η̇_k: one array, shared by this readable step and :meth:`compiled`
        self.hist = np.zeros((3, n))
        self.eta_prev, self.eta_k, self.eta_dot_k = self.hist
        self.flags = np.zeros(1)  # [0]: η_{k−1} set (the first before())

    @property
    def channels(self) -> tuple[str, ...]:
        return self.set.channels

    def _both(self, eta, lateral_eta) -> np.ndarray:
        """The symmetric wing's ``eta`` with the antisymmetric one's after it (both halves)."""
        if self.lateral is None:
            return np.asarray(eta, dtype=float)[:self.n_modes]
        n_s = self.set.n_modes
        return np.concatenate([np.asarray(eta, dtype=float)[:n_s], lateral_eta])

    def before(self, eta, eta_dot) -> None:
        """The wing's η_k [rad], η̇_k [rad/s] (before its step k; both halves: the
        antisymmetric wing's read here)."""
        lat = self.lateral
        self.eta_k[:] = self._both(eta, None if lat is None else lat.eta)
        self.eta_dot_k[:] = self._both(eta_dot, None if lat is None else lat.eta_dot)
        if not self.flags[0]:
            self.eta_prev[:] = self.eta_k - self.dt_s * self.eta_dot_k
            self.flags[0] = 1.0

    def compiled(self, x: np.ndarray, cols: np.ndarray, m_per_ft: float, parts=None):
        """``(hold, write)``: :meth:`before` and :meth:`row` (with the rigid body's
        kinematics) as compiled calls for the coupled step's compiled path, bound once to
        the wing's state ``x`` (η, η̇, updated in place; both halves: the full-span kernel's
        state, ``parts`` the symmetric and antisymmetric wings' states, each [η, η̇], as views
        into it: where each lies in ``x`` is read from them), the table columns ``cols`` of
        :attr:`channels` and ft→m ``m_per_ft``: ``hold()`` before the wing's step,
        ``write(reads, wind_down_fps, table, k, t_s)`` after it (``reads`` the
        :data:`KINEMATICS_READS` of the airframe at t_k, the wind down [ft/s]) writes the
        row's channels into ``table[k]``. The same arithmetic as the readable methods."""
        ss, n, dt = self.set, self.n_modes, self.dt_s
        hist, flags = self.hist, self.flags
        at = _state_positions(x, ss.n_modes, ss.n_antisymmetric, parts)  # η, then η̇ in x
        cols = np.ascontiguousarray(cols, dtype=np.int64)
        kin, dot, ddot = np.zeros(len(KINEMATICS)), np.zeros(n), np.zeros(n)
        noisy, air_noisy = ss._noisy, ss._air_noisy
        sources, air_sources = ss._noise, ss._air_noise
        imu_noise, air_noise = ss._imu_noise, ss._air_noise_now
        arrays = (x, at, n, dt, self.rate_state, hist, kin, dot, ddot, ss.r, ss.u, ss.psi,
                  ss.mount, imu_noise, ss.imu_out, ss.r_air, ss.u_air, air_noise, ss.air_out)
        types = tuple(numba.typeof(a) for a in arrays)
        table_type = numba.typeof(np.zeros((1, 1)))
        reads_type = numba.typeof((0.0,) * len(KINEMATICS_READS))
        entry = _row_kernel.compile((reads_type, numba.float64, numba.float64, *types,
                                     table_type, numba.int64, numba.typeof(cols)))
        hold_entry = _hold_kernel.compile(tuple(numba.typeof(a) for a in (x, at, n, dt, hist,
                                                                           flags)))
        checked, call = None, _row_kernel

        def hold() -> None:
            hold_entry(x, at, n, dt, hist, flags)

        def write(reads, wind_down_fps: float, table: np.ndarray, k: int, t_s: float) -> None:
            nonlocal checked, call
            if table is not checked:  # the machine code for the table type it was built for
                checked = table
                call = entry if numba.typeof(table) == table_type else _row_kernel
            if noisy:
                for s, src in enumerate(sources):
                    imu_noise[s] = src.sample(t_s)
            if air_noisy:
                for s, src in enumerate(air_sources):
                    air_noise[s] = src.sample(t_s)[0]
            call(reads, wind_down_fps, m_per_ft, *arrays, table, k, cols)

        return hold, write

    def row(self, kin, eta_next, t_s: float) -> np.ndarray:
        """The channels at t_k (``t_s`` [s]) from the rigid body's ``kin`` then and the
        wing's η_{k+1} [rad] (reused array; both halves: the antisymmetric wing's η_{k+1}
        read here, its step done)."""
        lat = self.lateral
        dot, ddot = central_modal_kinematics(self.eta_prev, self.eta_k,
                                             self._both(eta_next, None if lat is None
                                                        else lat.eta),
                                             self.eta_dot_k, self.dt_s, self.rate_state)
        values = self.set.read(kin, self.eta_k, dot, ddot, t_s)
        self.eta_prev[:] = self.eta_k
        return values


def _state_positions(x: np.ndarray, n_s: int, n_a: int, parts) -> np.ndarray:
    """Where η_s, η_a, then η̇_s, η̇_a lie in the state ``x`` (int64): the half wing's
    [η, η̇, …] (``parts`` None; the unsteady wing's lag states after them), or each of
    ``parts`` (the symmetric and antisymmetric wings' [η, η̇, …], views into ``x``; on
    unsteady strips each wing's lag states after its η̇) at its own offset; ValueError for a
    part not inside ``x``."""
    if not x.flags.c_contiguous:
        raise ValueError("the wing's state must be one contiguous array")
    if parts is None:
        if n_a or x.size < 2 * n_s:
            raise ValueError(f"the wing's state has {x.size} values, the sensors read "
                             f"{2 * (n_s + n_a)}")
        return np.arange(2 * n_s, dtype=np.int64)
    offsets = []
    for view, n in zip(parts, (n_s, n_a), strict=True):
        start = (view.__array_interface__["data"][0] - x.__array_interface__["data"][0]) \
            // x.itemsize
        if view.size < 2 * n or start < 0 or start + view.size > x.size \
                or not np.shares_memory(view, x):
            raise ValueError("a wing's state is not a view into the full-span state")
        offsets.append(start)
    (o_s, o_a) = offsets
    return np.concatenate([o_s + np.arange(n_s), o_a + np.arange(n_a),
                           o_s + n_s + np.arange(n_s), o_a + n_a + np.arange(n_a)]
                          ).astype(np.int64)


class AutopilotImu:
    """The IMU an autopilot reads, at the state a step reached (ArduPilot's JSON backend,
    the MAVLink vehicle's HIGHRES_IMU): its own :class:`SensorSet` (its own noise stream,
    read once per sample) and the wing's states before the last step, for
    :func:`latest_modal_kinematics`. Call :meth:`before_step` with the wing's η, η̇ before
    each step, :meth:`read` after it. Both wing halves (:meth:`follow` a full-span step): the
    antisymmetric wing's η_a, η̇_a are read with the symmetric ones given (module docstring,
    "Both wing halves": an IMU on the fuselage rolls with their root slope)."""

    def __init__(self, spec: ImuSpec, modes=None, n_modes: int | None = None,
                 dt_s: float = 1.0) -> None:
        self.spec = spec
        self.set = SensorSet(Sensors(imus=(spec,)), modes, n_modes)
        self.dt_s = float(dt_s)
        self._lateral = None
        self.reset(self.set.n_modes)

    def reset(self, n_modes: int) -> None:
        """A new flight: the wing at rest before it (η_{k−1} = η_k = 0, η̇_k = 0)."""
        n = n_modes + (0 if self._lateral is None else self._lateral.n_modes)
        self._hist = (np.zeros(n), np.zeros(n), np.zeros(n))

    def follow(self, step) -> None:
        """A new flight of the coupled step ``step`` (its ``n_modes``, ``lateral`` and, with
        both halves, ``antisymmetric_wing``): the wing at rest; with both halves the IMU's
        columns gain the antisymmetric modes (once; a fresh noise stream, the same seed)."""
        lateral = getattr(step, "lateral", None)
        if lateral is not None and self.set.n_antisymmetric != lateral.n_modes:
            wing_a = step.antisymmetric_wing
            self.set = self.set.with_antisymmetric(wing_a.modes, wing_a.root_slope)
        self._lateral = lateral
        self.reset(step.n_modes)

    def _both(self, eta, lateral_eta) -> np.ndarray:
        eta = np.array(eta, dtype=float)
        return eta if self._lateral is None else np.concatenate([eta, lateral_eta])

    def before_step(self, eta, eta_dot) -> None:
        """The wing's η [rad], η̇ [rad/s] before the step about to be flown."""
        lat = self._lateral
        self._hist = (self._hist[1], self._both(eta, None if lat is None else lat.eta),
                      self._both(eta_dot, None if lat is None else lat.eta_dot))

    def read(self, kin, eta, eta_dot, t_s: float, rate_state: bool
             ) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
        """(specific force [m/s²], rates [rad/s]) in the IMU's axes at the newest state: the
        rigid body's :data:`KINEMATICS` ``kin`` and the wing's η, η̇ now, at ``t_s`` [s]."""
        eta_prev, eta_k, eta_dot_k = self._hist
        lat = self._lateral
        eta = self._both(eta, None if lat is None else lat.eta)
        eta_dot = self._both(eta_dot, None if lat is None else lat.eta_dot)
        dot, ddot = latest_modal_kinematics(eta_prev, eta_k, eta, eta_dot_k, eta_dot,
                                            self.dt_s, rate_state)
        v = self.set.read(kin, eta, dot, ddot, t_s).tolist()
        return (v[0], v[1], v[2]), (v[3], v[4], v[5])
