"""The sensor stations' numerical core against closed forms (simulation/sensors.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.parameters.sensors import (
    CG_IMU,
    AirspeedSpec,
    ImuSpec,
    SensorNoise,
    Sensors,
    WingPoint,
)
from bioflex_jsb.simulation.sensors import (
    SensorSet,
    central_modal_kinematics,
    latest_modal_kinematics,
    station_shapes,
)
from bioflex_jsb.structures.modal_data import ModalData


def _kin(f=(0.0, 0.0, -9.80665), w=(0.0, 0.0, 0.0), wd=(0.0, 0.0, 0.0), v=(15.0, 0.0, 0.0)):
    return np.array([*f, *w, *wd, *v], dtype=float)


def _beam_modes() -> ModalData:
    """One bending mode of a clamped uniform beam of 1 m, sampled finely (its shape from the
    Euler-Bernoulli closed form, β L = 1.8751), and a torsion-like second mode (twist
    growing linearly outboard, no bending): shapes whose slope and twist are known."""
    y = np.linspace(0.0, 1.0, 401)
    bl = 1.8751040687
    sigma = (math.cosh(bl) + math.cos(bl)) / (math.sinh(bl) + math.sin(bl))
    b = (np.cosh(bl * y) - np.cos(bl * y) - sigma * (np.sinh(bl * y) - np.sin(bl * y)))
    bending = np.vstack([0.05 * b / b[-1], np.zeros_like(y)])
    twist = np.vstack([np.zeros_like(y), y])
    return ModalData(frequencies_rad_s=[2 * math.pi * 30.0, 2 * math.pi * 70.0],
                     damping_ratios=[0.0, 0.0], generalised_masses_kg_m2=[1.0, 1.0],
                     stations_m=y, bending_m=bending, twist_rad=twist, x_elastic_frac=0.3,
                     x_inertial_frac=0.3, source="test")


def _read(sensors: Sensors, kin, eta=(), eta_dot=(), eta_ddot=(), modes=None, t=0.0):
    n = len(eta)
    s = SensorSet(sensors, modes, n_modes=n)
    z = np.zeros(n)
    vals = s.read(kin, np.asarray(eta, float) if n else z, np.asarray(eta_dot, float) if n
                  else z, np.asarray(eta_ddot, float) if n else z, t)
    return dict(zip(s.channels, vals.tolist(), strict=True))


def test_cg_imu_reads_the_cg_specific_force_and_rates_exactly():
    kin = _kin(f=(0.31, -0.02, -9.7), w=(0.1, -0.2, 0.05), wd=(3.0, -1.0, 0.5))
    out = _read(Sensors(imus=(CG_IMU,)), kin)
    assert [out[f"imu_cg_a{c}_m_s2"] for c in "xyz"] == [0.31, -0.02, -9.7]
    assert [out[f"imu_cg_g{c}_rad_s"] for c in "xyz"] == [0.1, -0.2, 0.05]


def test_pure_rotation_about_z_gives_the_centripetal_acceleration():
    """ω about z at a point r on the x axis: −ω² r along x, nothing else (a = ω × (ω × r))."""
    w, r = 2.5, 0.4
    imu = ImuSpec("nose", (r, 0.0, 0.0))
    out = _read(Sensors(imus=(imu,)), _kin(f=(0.0, 0.0, 0.0), w=(0.0, 0.0, w)))
    assert out["imu_nose_ax_m_s2"] == pytest.approx(-w * w * r, rel=1e-15)
    assert out["imu_nose_ay_m_s2"] == 0.0 and out["imu_nose_az_m_s2"] == 0.0
    assert out["imu_nose_gz_rad_s"] == w
    # a 0.1 % error in ω² r is seen
    assert abs(out["imu_nose_ax_m_s2"] - (-w * w * r * 1.001)) > 1e-4


def test_angular_acceleration_gives_the_tangential_acceleration():
    """ω̇ about y (pitch) at a point ahead of the CG: ω̇ × r = (0, q̇, 0) × (x, 0, 0) = (0, 0,
    −q̇ x): the nose pitching up accelerates up (−z)."""
    qd, x = 4.0, 0.3
    out = _read(Sensors(imus=(ImuSpec("nose", (x, 0.0, 0.0)),)),
                _kin(f=(0.0, 0.0, 0.0), wd=(0.0, qd, 0.0)))
    assert out["imu_nose_az_m_s2"] == pytest.approx(-qd * x, rel=1e-15)
    assert out["imu_nose_ax_m_s2"] == 0.0


def test_mounting_turns_the_readings_into_the_sensor_axes():
    """A board yawed 90°: its x axis is the body's y, its y the body's −x."""
    imu = ImuSpec("turned", (0.0, 0.0, 0.0), orientation_rad=(0.0, 0.0, math.pi / 2))
    out = _read(Sensors(imus=(imu,)), _kin(f=(1.0, 2.0, 3.0), w=(0.1, 0.2, 0.3)))
    assert out["imu_turned_ax_m_s2"] == pytest.approx(2.0, abs=1e-15)
    assert out["imu_turned_ay_m_s2"] == pytest.approx(-1.0, abs=1e-15)
    assert out["imu_turned_az_m_s2"] == pytest.approx(3.0, abs=1e-15)
    assert out["imu_turned_gx_rad_s"] == pytest.approx(0.2, abs=1e-15)


def test_station_shapes_of_a_bending_mode_and_a_twist_mode():
    modes = _beam_modes()
    point = WingPoint(y_m=1.0, chord_position=0.5, height_m=0.0, elastic_axis_offset_m=0.1)
    u, psi = station_shapes(modes, point)
    # mode 1: the tip deflects 0.05 m down per unit η; the beam's tip slope is
    # φ'(L)/φ(L) = 1.3765 / L (Euler-Bernoulli closed form: 2 (sinh βL sin βL)/(...)·β);
    # by finite differences on 401 stations within 1e-4
    bl = 1.8751040687
    sigma = (math.cosh(bl) + math.cos(bl)) / (math.sinh(bl) + math.sin(bl))
    tip = math.cosh(bl) - math.cos(bl) - sigma * (math.sinh(bl) - math.sin(bl))
    slope = bl * (math.sinh(bl) + math.sin(bl) - sigma * (math.cosh(bl) - math.cos(bl)))
    assert u[2, 0] == pytest.approx(0.05, rel=1e-12)
    assert psi[0, 0] == pytest.approx(0.05 * slope / tip, rel=1e-4)
    # mode 2: twist 1 rad per unit η at the tip; a point 0.1 m aft of the elastic axis
    # moves down by 0.1 per unit η; leading edge up is a nose-up pitch (+y)
    assert psi[1, 1] == pytest.approx(1.0, rel=1e-12)
    assert u[2, 1] == pytest.approx(0.1, rel=1e-12)
    # the port wing mirrors: the same translation, the roll slope reversed
    u_p, psi_p = station_shapes(modes, WingPoint(-1.0, 0.5, 0.0, 0.1))
    np.testing.assert_array_equal(u_p, u)
    assert psi_p[0, 0] == -psi[0, 0] and psi_p[1, 1] == psi[1, 1]


def test_a_harmonic_mode_reads_omega_squared_phi_eta_at_the_station():
    """η = A sin ωt: the tip accelerometer's z reads −ω² φ A sin ωt (its peak ω² φ A); the
    gyro about x reads ρ A ω cos ωt. A 0.1 % error in either amplitude is seen."""
    modes = _beam_modes()
    point = WingPoint(y_m=1.0, chord_position=0.3, height_m=0.0, elastic_axis_offset_m=0.0)
    imu = ImuSpec("tip", (0.0, 1.0, 0.0), wing=point)
    sensors = Sensors(imus=(imu,))
    s = SensorSet(sensors, modes, n_modes=1)
    omega, amp = 2 * math.pi * 30.0, 0.01
    u, psi = station_shapes(modes, point, 1)
    t = np.linspace(0.0, 1.0 / 30.0, 200, endpoint=False)
    az, gx = [], []
    for tk in t:
        eta = [amp * math.sin(omega * tk)]
        eta_dot = [amp * omega * math.cos(omega * tk)]
        eta_ddot = [-amp * omega**2 * math.sin(omega * tk)]
        v = s.read(_kin(f=(0.0, 0.0, 0.0), v=(0.0, 0.0, 0.0)), eta, eta_dot, eta_ddot, tk)
        az.append(v[2])
        gx.append(v[3])
    peak = omega**2 * u[2, 0] * amp
    # the small-angle tilt of the axes is second order here (f = 0 at the CG)
    assert max(az) == pytest.approx(peak, rel=1e-6)
    assert max(gx) == pytest.approx(psi[0, 0] * amp * omega, rel=1e-6)
    assert abs(max(az) - 1.001 * peak) > 1e-4 * peak


def test_the_deflected_axes_see_gravity_turned_by_the_twist():
    """A wing point twisted by δ nose up (leading edge up) reads the CG's specific force
    (0, 0, −g) as (−g sin δ, 0, −g cos δ) to first order: f_x = −δ g... with the sign of
    v − δ × v: δ = (0, δ, 0), v = (0, 0, −g): δ × v = (−δ g, 0, 0) → f_x = +δ g."""
    modes = _beam_modes()
    point = WingPoint(y_m=1.0, chord_position=0.3, height_m=0.0, elastic_axis_offset_m=0.0)
    imu = ImuSpec("tip", (0.0, 1.0, 0.0), wing=point)
    s = SensorSet(Sensors(imus=(imu,)), modes)
    delta, g = 0.01, 9.80665
    v = s.read(_kin(f=(0.0, 0.0, -g)), [0.0, delta], [0.0, 0.0], [0.0, 0.0], 0.0)
    # a sensor pitched nose up by δ sees the downward gravity reaction tilted: its x axis
    # points up by δ, the specific force (up, −z body) has +sin δ along it
    assert v[0] == pytest.approx(g * delta, rel=1e-12)
    assert v[2] == pytest.approx(-g, rel=1e-12)


def test_modal_kinematics_of_a_harmonic():
    """Central differences at Δt = 1/960 s of η = sin ωt at 30.9 Hz: η̈ reads
    (sin(ωΔt/2)/(ωΔt/2))² of −ω² sin ωt (0.34 % low), in phase."""
    omega, dt = 2 * math.pi * 30.9, 1.0 / 960.0
    t = 0.0123
    eta = [math.sin(omega * (t + j * dt)) for j in (-1, 0, 1)]
    dot, ddot = central_modal_kinematics([eta[0]], [eta[1]], [eta[2]], [0.0], dt,
                                         rate_state=False)
    x = omega * dt / 2
    assert ddot[0] == pytest.approx(-omega**2 * math.sin(omega * t) * (math.sin(x) / x) ** 2,
                                    rel=1e-9)
    assert (math.sin(x) / x) ** 2 == pytest.approx(1 - 0.0034, abs=1e-4)
    assert dot[0] == pytest.approx(omega * math.cos(omega * t) * math.sin(2 * x) / (2 * x),
                                   rel=1e-9)
    # the latest estimate: η̈ the mean over the last step, at its middle
    d1 = [omega * math.cos(omega * (t + j * dt)) for j in (0, 1)]
    _, last = latest_modal_kinematics([0.0], [0.0], [0.0], [d1[0]], [d1[1]], dt)
    mid = t + dt / 2
    assert last[0] == pytest.approx(-omega**2 * math.sin(omega * mid) * math.sin(x) / x,
                                    rel=1e-9)


def test_airspeed_probe_on_a_yawing_aircraft():
    """A probe 0.8 m out on the starboard wing of an aircraft yawing right at r: the air
    meets it at V − r y (the outer wing moves back against the air)."""
    probe = AirspeedSpec("right", (0.0, 0.8, 0.0))
    out = _read(Sensors(airspeeds=(probe,)), _kin(w=(0.0, 0.0, 0.5), v=(15.0, 0.0, 0.0)))
    assert out["airspeed_right_m_s"] == pytest.approx(15.0 - 0.5 * 0.8, rel=1e-15)


def test_noise_is_seeded_biased_and_of_arduPilots_size():
    noise = SensorNoise(accel_bias_m_s2=(0.1, 0.0, -0.2), accel_noise_m_s2=0.5,
                        gyro_bias_rad_s=(0.01, 0.0, 0.0), gyro_noise_rad_s=0.02, seed=7)
    imu = ImuSpec("n", (0.0, 0.0, 0.0), noise=noise)

    def series(spec, n=20000):
        s = SensorSet(Sensors(imus=(spec,)))
        return np.array([s.read(_kin(f=(0.0, 0.0, 0.0), v=(0.0, 0.0, 0.0)), [], [], [],
                                k / 1000.0).copy() for k in range(n)])

    a, b = series(imu), series(imu)
    np.testing.assert_array_equal(a, b)  # seeded
    # the mean is the bias; the RMS of uniform ±RND is RND/√3 (ArduPilot's rand_float)
    assert a[:, 0].mean() == pytest.approx(0.1, abs=0.01)
    assert a[:, 2].mean() == pytest.approx(-0.2, abs=0.01)
    assert a[:, 1].std() == pytest.approx(0.5 / math.sqrt(3), rel=0.02)
    assert a[:, 4].std() == pytest.approx(0.02 / math.sqrt(3), rel=0.02)
    assert np.abs(a[:, 1]).max() <= 0.5
    c = series(ImuSpec("n", (0.0, 0.0, 0.0), noise=SensorNoise(accel_noise_m_s2=0.5, seed=8)))
    assert not np.array_equal(a[:, 1], c[:, 1])


def test_vibration_is_a_sine_at_its_frequency():
    noise = SensorNoise(accel_noise_m_s2=1.0, vibration_hz=(0.0, 0.0, 50.0), seed=1)
    s = SensorSet(Sensors(imus=(ImuSpec("v", (0.0, 0.0, 0.0), noise=noise),)))
    fs = 1000.0
    z = np.array([s.read(_kin(f=(0.0, 0.0, 0.0)), [], [], [], k / fs)[2]
                  for k in range(2000)])
    x = np.array([s.read(_kin(f=(0.0, 0.0, 0.0)), [], [], [], k / fs)[0]
                  for k in range(10)])
    spec = np.abs(np.fft.rfft(z))
    assert np.fft.rfftfreq(z.size, 1 / fs)[np.argmax(spec)] == pytest.approx(50.0)
    assert np.abs(z).max() <= 1.05 + 1e-12 and np.abs(z).max() > 0.95
    np.testing.assert_array_equal(x, 0.0)  # no frequency on x: nothing (as ArduPilot)


def test_names_are_checked():
    with pytest.raises(ValueError, match="sensor name"):
        SensorSet(Sensors(imus=(ImuSpec("Bad Name", (0.0, 0.0, 0.0)),)))
    with pytest.raises(ValueError, match="must differ"):
        SensorSet(Sensors(imus=(ImuSpec("a", (0.0, 0.0, 0.0)), ImuSpec("a", (1.0, 0.0, 0.0)))))
