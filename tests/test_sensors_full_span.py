"""Sensor stations on both wing halves (simulation/sensors.py, "Both wing halves"): a station
reads the antisymmetric modes with the sign of its side, the fuselage rolls with the modes'
root slope, the half wing's sensors read as before, and the compiled full-span step's
sensor channels are the Python step's."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers.gust import run_gust
from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing
from bioflex_jsb.parameters.sensors import ImuSpec, Sensors, WingPoint
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.run_config import RunConfig
from bioflex_jsb.simulation.sensors import KINEMATICS, SensorSet

C172 = "c172_elastic"
SPEED_M_S = 57.8  # its cruise [m/s]
# The c172's roll inertia [kg m^2] for the antisymmetric modes of the core tests: any value
# above its two wing halves' (1607 kg m^2) gives a fuselage roll freedom; JSBSim's c172p
# I_xx is 948 slug ft^2 = 1285 kg m^2 and the definition's wing is heavier, so the flown
# tests take the airframe's own (with its wing's mass added by the definition).
IXX_KG_M2 = 3000.0


@pytest.fixture(scope="module")
def c172():
    return api.load_aircraft(C172)


@pytest.fixture(scope="module")
def wing_a(c172):
    return antisymmetric_wing(c172.wing(), IXX_KG_M2)


def _pair(y_m: float) -> Sensors:
    """A starboard and a port wing IMU at ±y (quarter chord, 0.1 m aft of the elastic axis,
    on the chord plane) and a fuselage IMU off the CG."""
    def tip(name: str, y: float) -> ImuSpec:
        return ImuSpec(name, (-0.5, y, 0.0), wing=WingPoint(y, 0.25, 0.0, 0.1))

    return Sensors(imus=(tip("stbd", y_m), tip("port", -y_m),
                         ImuSpec("body", (0.3, 0.2, 0.4))))


def _read(ss: SensorSet, eta, eta_dot, eta_ddot, kin=None) -> dict[str, float]:
    return ss.clean(np.zeros(len(KINEMATICS)) if kin is None else kin, eta, eta_dot, eta_ddot)


def test_a_wing_pair_reads_the_antisymmetric_modes_with_the_sign_of_its_side(c172, wing_a):
    """With η_a alone the port station's translations and pitch are the starboard one's
    negated and its roll the same (a mode that dips the starboard tip lifts the port one:
    both halves roll the aircraft the same way); with η_s alone the reverse. Exact (the
    columns are the mirror's times the side's sign)."""
    build = c172.wing()
    y = 0.9 * float(build.aero.semispan_m)
    half = SensorSet(_pair(y), build.modes, build.model.n_modes)
    full = half.with_antisymmetric(wing_a.modes, wing_a.root_slope)
    n_s, n_a = full.n_modes, full.n_antisymmetric
    assert (n_s, n_a, full.n_columns) == (build.model.n_modes, 3, n_s + 3)
    rng = np.random.default_rng(1)
    for part in ("antisymmetric", "symmetric"):
        v = np.zeros((3, full.n_columns))
        cols = slice(n_s, None) if part == "antisymmetric" else slice(0, n_s)
        v[:, cols] = rng.normal(size=(3, v[:, cols].shape[1])) * 1e-3
        r = _read(full, *v)
        odd = -1.0 if part == "antisymmetric" else 1.0
        for axis, mirror in (("az_m_s2", odd), ("gx_rad_s", -odd), ("gy_rad_s", odd)):
            s, p = r[f"imu_stbd_{axis}"], r[f"imu_port_{axis}"]
            assert abs(s) > 1e-9, (part, axis)
            assert p == pytest.approx(mirror * s, rel=1e-12, abs=1e-15), (part, axis)


def test_the_fuselage_rolls_with_the_modes_root_slope(c172, wing_a):
    """A fuselage IMU reads the gyro x rate p + Σ ρ₀ η̇_a and, at r = (x, y, z), the
    acceleration Σ ρ₀ η̈_a (0, −z, y); the symmetric (clamped) modes leave it alone. The
    root slope is the beam's root node's, which the bending's second-order one-sided
    difference at the root approaches (measured 0.29 % off on mode 1)."""
    build = c172.wing()
    full = SensorSet(_pair(1.0), build.modes, build.model.n_modes).with_antisymmetric(
        wing_a.modes, wing_a.root_slope)
    rho = np.asarray(wing_a.root_slope)
    m = wing_a.modes
    slope = np.gradient(m.bending_m, m.stations_m, axis=1, edge_order=2)[:, 0]
    assert slope[0] == pytest.approx(rho[0], rel=0.005)
    n_s = full.n_modes
    eta_dot = np.zeros(full.n_columns)
    eta_ddot = np.zeros(full.n_columns)
    eta_dot[n_s:] = (0.01, -0.02, 0.005)
    eta_ddot[n_s:] = (0.3, 0.1, -0.2)
    eta_dot[:n_s] = 0.05  # the symmetric modes: not at the fuselage
    eta_ddot[:n_s] = 2.0
    r = _read(full, np.zeros(full.n_columns), eta_dot, eta_ddot)
    assert r["imu_body_gx_rad_s"] == pytest.approx(rho @ eta_dot[n_s:], rel=1e-12)
    roll_acc = rho @ eta_ddot[n_s:]
    assert r["imu_body_ay_m_s2"] == pytest.approx(-0.4 * roll_acc, rel=1e-12)
    assert r["imu_body_az_m_s2"] == pytest.approx(0.2 * roll_acc, rel=1e-12)
    assert r["imu_body_ax_m_s2"] == 0.0


def test_the_half_wing_sensors_read_as_before(c172, wing_a):
    """Adding the antisymmetric columns leaves the symmetric ones as they were: with η_a = 0
    every channel equals the half-wing set's, bit for bit (the half wing's runs read exactly
    as before: checked against main e5685b4, sha256 of a prototype run's sensor channels,
    coupled and qsd, compiled and Python, identical)."""
    build = c172.wing()
    half = SensorSet(_pair(2.0), build.modes, build.model.n_modes)
    full = half.with_antisymmetric(wing_a.modes, wing_a.root_slope)
    assert np.array_equal(full.u[:, :, :half.n_modes], half.u)
    assert np.array_equal(full.psi[:, :, :half.n_modes], half.psi)
    rng = np.random.default_rng(2)
    kin = rng.normal(size=len(KINEMATICS))
    v = rng.normal(size=(3, half.n_modes)) * 1e-2
    padded = [np.concatenate([a, np.zeros(full.n_antisymmetric)]) for a in v]
    assert _read(full, *padded, kin=kin) == _read(half, *v, kin=kin)


@pytest.fixture(scope="module")
def rolling(c172):
    """A rolling gust flown with both halves and a starboard/port pair at 95 % semispan and
    a fuselage IMU, compiled and Python."""
    y = 0.95 * float(c172.wing().aero.semispan_m)
    runs = {}
    for compiled in (True, False):
        run = run_gust(airframe_for(c172), c172.wing(), "coupled",
                       RunConfig(SPEED_M_S, parse_gust("none+roll:0.1:40"), 1.0), span="full",
                       aileron=c172.definition.aileron, sensors=_pair(y), compiled=compiled)
        assert run.stopped is None
        runs[compiled] = run
    return runs


def test_the_compiled_full_span_sensors_are_the_python_steps(rolling):
    """Every sensor channel of the compiled full-span step equals the Python step's to 1e-12
    of its range (measured 5.4e-14)."""
    fast, slow = rolling[True], rolling[False]
    names = [c for c in fast.channels if c.startswith("imu_")]
    assert len(names) == 18
    for name in names:
        a, b = np.asarray(fast[name]), np.asarray(slow[name])
        assert np.max(np.abs(a - b)) <= 1e-12 * max(np.ptp(a), 1e-9), name


def test_the_unsteady_full_span_sensors_with_a_controller_are_the_python_steps(c172):
    """Both halves on unsteady strips (each wing's lag states after its η, η̇ in the
    full-span state) with the wing pair, the fuselage IMU and the roll damper in the loop:
    the compiled step's sensor channels and command equal the Python step's to 1e-9 of
    their range (measured 2.9e-13, the fuselage a_z; the run's worst channel, the pitching
    moment, 1.3e-10: the unsteady step's compiled-against-Python spread, docs/lateral.md),
    and the pair's mean gyro x leaves JSBSim's p by the modes' roll rate (measured up to
    5.3e-4 rad/s over 0.6 s)."""
    from bioflex_jsb.simulation.controller import load_controller

    y = 0.95 * float(c172.wing().aero.semispan_m)
    runs = [run_gust(airframe_for(c172), c172.wing(), "coupled",
                     RunConfig(SPEED_M_S, parse_gust("none+roll:0.1:40"), 0.6,
                               models=("coupled",), aero="unsteady"),
                     span="full", aileron=c172.definition.aileron, sensors=_pair(y),
                     controller=load_controller("roll_damper_c172_elastic"),
                     compiled=compiled) for compiled in (True, False)]
    assert all(r.stopped is None for r in runs)
    names = [c for c in runs[0].channels if c.startswith("imu_")] + ["ctrl_aileron_rad"]
    assert len(names) == 19
    for name in names:
        a, b = np.asarray(runs[0][name]), np.asarray(runs[1][name])
        assert np.ptp(a) > 0.0, name
        assert np.max(np.abs(a - b)) <= 1e-9 * np.ptp(a), name
    mean = 0.5 * (np.asarray(runs[0]["imu_stbd_gx_rad_s"])
                  + np.asarray(runs[0]["imu_port_gx_rad_s"]))
    assert np.max(np.abs(mean - np.asarray(runs[0]["p_rad_s"]))) > 1e-5


def test_a_rolling_wing_pair_reads_its_antisymmetric_modes(rolling):
    """In the rolling gust the mean of the pair's gyro x is JSBSim's roll rate p plus the
    antisymmetric modes' roll rate at the station, Σ Ψ_x η̇_a (the run's ``asym_eta<i>_dot``
    and the shapes ``meta["sensors"]`` gives), to 1e-3 of that modal part (what is left is
    the deflected axes' second-order terms); the port and starboard vertical accelerations
    differ by the roll's ṗ·2y (measured: p to 0.0846 rad/s)."""
    run = rolling[True]
    p = np.asarray(run["p_rad_s"])
    assert np.max(p) > 0.08
    meta = run.meta["sensors"]
    assert meta["antisymmetric_modes"] == 3
    stbd = next(s for s in meta["imus"] if s["name"] == "stbd")
    psi_x = np.asarray(stbd["rotation_rad_per_rad"])[0]
    n_s = psi_x.size - 3
    eta_dot = np.column_stack([run[f"asym_eta{i + 1}_dot"] for i in range(3)])
    modal = eta_dot @ psi_x[n_s:]
    mean = 0.5 * (np.asarray(run["imu_stbd_gx_rad_s"]) + np.asarray(run["imu_port_gx_rad_s"]))
    assert np.max(np.abs(modal)) > 1e-5
    assert np.max(np.abs(mean - p - modal)) < 1e-3 * np.max(np.abs(modal))
    az_s, az_p = np.asarray(run["imu_stbd_az_m_s2"]), np.asarray(run["imu_port_az_m_s2"])
    assert np.max(np.abs(az_s - az_p)) > 0.1  # starboard pushed down, port up


def test_the_autopilot_imu_rolls_with_the_fuselage_on_both_halves(c172, wing_a):
    """The autopilot's IMU (the ArduPilot backend's, the MAVLink vehicle's) following a
    full-span step reads the antisymmetric modes' state with the symmetric one's: at the CG
    its gyro x is p + Σ ρ₀ η̇_a; following a half-wing step it reads as before (p)."""
    from types import SimpleNamespace

    from bioflex_jsb.simulation.sensors import AutopilotImu

    build = c172.wing()
    n_s = build.model.n_modes
    lateral = SimpleNamespace(n_modes=3, eta=np.zeros(3), eta_dot=np.zeros(3))
    full = SimpleNamespace(n_modes=n_s, lateral=lateral, antisymmetric_wing=wing_a)
    half = SimpleNamespace(n_modes=n_s, lateral=None)
    kin = np.zeros(len(KINEMATICS))
    kin[3] = 0.1  # p [rad/s]
    dt = 1.0 / 960.0
    for step, expected in ((half, 0.1), (full, None)):
        imu = AutopilotImu(ImuSpec("ap", (0.0, 0.0, 0.0), autopilot=True), build.modes, n_s, dt)
        imu.follow(step)
        lateral.eta_dot = np.array([0.02, -0.01, 0.03])
        imu.before_step(np.zeros(n_s), np.zeros(n_s))
        _, gyro = imu.read(kin, np.zeros(n_s), np.zeros(n_s), 0.0, True)
        if expected is None:
            expected = 0.1 + np.asarray(wing_a.root_slope) @ lateral.eta_dot
            assert abs(expected - 0.1) > 1e-3
        assert gyro[0] == pytest.approx(expected, rel=1e-12)


def test_the_unsteady_half_wings_sensors_read_its_modes():
    """The compiled sensor row finds η, η̇ at the front of the unsteady wing's longer state
    (its lag states after them): its sensor channels equal the Python step's to 1e-9 of
    their range (measured 1.9e-12; the sensor row indexes the state, which is why it is
    tested here)."""
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.runtime.fdm import Airframe

    build = build_wing(VARIANTS["optimised"])
    sensors = Sensors(imus=(ImuSpec("tip", (-0.3, 0.85, 0.0),
                                    wing=WingPoint(0.85, 1.0, 0.0, 0.14)),))
    runs = [run_gust(Airframe(), build, "coupled",
                     RunConfig(15.0, parse_gust("1cos:1:5"), 0.6, models=("coupled",),
                               aero="unsteady", gust_start_s=0.1),
                     sensors=sensors, compiled=compiled) for compiled in (True, False)]
    for name in (c for c in runs[0].channels if c.startswith("imu_tip")):
        a, b = np.asarray(runs[0][name]), np.asarray(runs[1][name])
        assert np.ptp(a) > 0.0
        assert np.max(np.abs(a - b)) <= 1e-9 * np.ptp(a), name


def test_the_sitl_vehicles_imu_rolls_with_the_fuselage(c172):
    """A SitlSim session with both halves entering its loiter circle: the autopilot's IMU
    (at the CG: no [sensors]) reads gyro x = p + Σ ρ₀ η̇_a at the state each step reached
    (the MAVLink vehicle's HIGHRES_IMU; the ArduPilot backend reads the same AutopilotImu),
    to 1e-3 of that modal part (the deflected axes' second-order terms; measured 1e-14 of
    it), the modal part up to 2.8 % of p (7.7e-3 against 0.276 rad/s)."""
    from bioflex_jsb.definition.flying import flight_speeds
    from bioflex_jsb.drivers.sitl import (
        DEFAULT_HOME,
        DEFAULT_START_HEIGHT_M,
        SitlSim,
        sitl_airframe,
    )
    from bioflex_jsb.links import mavlink_modes as modes

    build = c172.wing()
    airframe, _ = sitl_airframe(c172, SPEED_M_S, DEFAULT_HOME[2] + DEFAULT_START_HEIGHT_M)
    sim = SitlSim(build, build.modes, model="coupled", speed_m_s=SPEED_M_S,
                  airframe=airframe, span="full",
                  airspeed_range_m_s=tuple(flight_speeds(c172)[1]))
    sim.vehicle.set_mode(modes.CIRCLE)
    rho = np.asarray(sim.core.antisymmetric_wing.root_slope)
    p, gx, modal = [], [], []
    for _ in range(int(round(2.0 / sim.dt_s))):
        sim.step()
        assert sim.stopped is None
        state = sim.vehicle_state()
        p.append(state.p_rad_s)
        gx.append(state.imu_gyro_rad_s[0])
        modal.append(rho @ sim.core.lateral.eta_dot)
    p, gx, modal = (np.asarray(v) for v in (p, gx, modal))
    assert np.max(np.abs(modal)) > 1e-3 * np.max(np.abs(p))
    assert np.max(np.abs(gx - p - modal)) < 1e-3 * np.max(np.abs(modal))
