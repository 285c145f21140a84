"""A controller fed by sensor stations (runtime/coupled_step.py, simulation/controller.py
"Timing"): it reads the sensors' sample of t_k, the very value the row of t_k logs; its
command first shows in the sensors' sample of t_{k+1}, never in that of t_k (one step of
delay, as a sampled controller has); the compiled and Python steps agree; a linear
controller reads the perturbation from the sensor's true reading at the trim."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.drivers.gust import run_gust
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.parameters.sensors import CG_IMU, SensorNoise, Sensors
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.simulation.controller import LinearController
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.run_config import RunConfig
from tests.test_sensors_flight import _tip

DT = 1.0 / 960.0
TIP_AZ = "imu_tip_az_m_s2"
STEP_AT = 150  # the step whose command first moves the elevator (Python controller below)


@pytest.fixture(scope="module")
def build():
    return build_wing(VARIANTS["optimised"])


def _cfg(gust: str = "1cos:1:2", duration_s: float = 0.3) -> RunConfig:
    return RunConfig(15.0, parse_gust(gust), duration_s, 0.05, 0.0, DT, models=("coupled",))


class _Recorder:
    """Reads the tip accelerometer and the CG's, commands ``gain`` [rad per m/s²] times the
    tip's perturbation from the first sample it saw plus a step of ``kick`` [rad] from step
    :data:`STEP_AT`, and keeps every sample it was given."""

    inputs = (TIP_AZ, "imu_cg_az_m_s2")
    outputs = ("elevator",)

    def __init__(self, gain: float = 0.0, kick: float = 0.0) -> None:
        self.gain, self.kick = gain, kick
        self.seen: list[float] = []

    def step(self, t_s, signals):
        self.seen.append(signals[TIP_AZ])
        k = len(self.seen) - 1
        return {"elevator": self.gain * (signals[TIP_AZ] - self.seen[0])
                + (self.kick if k >= STEP_AT else 0.0)}


def _sensors(build, noise: bool = False) -> Sensors:
    kw = {"noise": SensorNoise(accel_noise_m_s2=0.05, seed=7)} if noise else {}
    return Sensors(imus=(_tip(build, **kw), CG_IMU))


def test_a_tip_accelerometer_controller_reads_the_row_it_logs(build):
    """Every sample the controller got is the row's logged tip a_z of that step, to the bit
    (noise included: the row is computed once and read by both), and its command is applied:
    logged, and the surface of row k + 1 is the trim's plus the command of row k."""
    ctrl = _Recorder(gain=0.002)
    run = run_gust(Airframe(), build.model, "coupled", _cfg(), sensors=_sensors(build, True),
                   loads=build, controller=ctrl)
    az = run[TIP_AZ]
    assert len(ctrl.seen) == len(az)
    assert np.array_equal(np.array(ctrl.seen), az)
    cmd, surface = run["ctrl_elevator_rad"], run["elevator_rad"]
    assert np.ptp(az) > 20.0  # m/s²: the gust rang the wing at the tip
    assert np.abs(cmd).max() > math.radians(1.0)  # the controller answered it
    assert np.abs(surface[1:] - surface[0] - cmd[:-1]).max() < 1e-14
    assert run.meta["controller"]["inputs"] == [TIP_AZ, "imu_cg_az_m_s2"]
    assert run.units[TIP_AZ] == "m/s^2"


def test_the_command_first_shows_in_the_next_sample(build):
    """Two runs from the same trim, one with an elevator step of 0.05 rad commanded at step
    STEP_AT: every sensor channel of rows 0..STEP_AT is the same to the bit, row STEP_AT + 1
    differs (the forces of x_{k+1} carry the command of step k): one step of delay."""
    runs = [run_gust(Airframe(), build.model, "coupled", _cfg("none", 0.2),
                     sensors=_sensors(build), loads=build, controller=_Recorder(kick=kick))
            for kick in (0.0, 0.05)]
    k = STEP_AT
    for name in (TIP_AZ, "imu_cg_az_m_s2", "imu_tip_gy_rad_s"):
        a, b = runs[0][name], runs[1][name]
        assert np.array_equal(a[:k + 1], b[:k + 1]), name
    # the CG's specific force: the elevator's lift, −Z_δe δe/m, a few tenths of m/s² per
    # 0.05 rad on the prototype; the first sample after it already differs by it
    jump = runs[1]["imu_cg_az_m_s2"][k + 1] - runs[0]["imu_cg_az_m_s2"][k + 1]
    assert abs(jump) > 0.05
    assert runs[1]["ctrl_elevator_rad"][k] == 0.05 and runs[1]["ctrl_elevator_rad"][k - 1] == 0


def test_compiled_and_python_steps_agree_with_a_sensor_fed_linear_controller(build):
    """A linear (compiled) gain on the tip's a_z: the compiled and the Python step give the
    same sensor channels (noise included: the same seeded stream) and commands, and the
    command is D (a_z − a_z trim), the trim's the tip's true reading at the trim (the first
    row's, in calm air before the gust, within its noise and the trim's residual
    acceleration)."""
    gain = LinearController.from_arrays(None, None, None, [[0.003]], DT, [TIP_AZ],
                                        ["elevator"], "tip_az")
    runs = [run_gust(Airframe(), build.model, "coupled", _cfg(), compiled=c,
                     sensors=_sensors(build, noise=True), loads=build, controller=gain)
            for c in (True, False)]
    for name in (TIP_AZ, "imu_cg_az_m_s2", "ctrl_elevator_rad", "eta1", "alpha"):
        a, b = runs[0][name], runs[1][name]
        assert np.max(np.abs(a - b)) <= 1e-9 * max(np.ptp(a), 1e-12), name
    run = runs[0]
    offset = run[TIP_AZ] - run["ctrl_elevator_rad"] / 0.003
    assert np.ptp(offset) < 1e-9
    # the first sample: the trim's true reading, its noise (±0.05 m/s²) and the trim's
    # residual acceleration
    assert offset[0] == pytest.approx(run[TIP_AZ][0], abs=0.07)
    assert offset[0] == pytest.approx(-9.81, abs=0.2)  # level flight: 1 g up, z down


def test_the_tip_imu_reads_as_a_signal():
    from bioflex_jsb.simulation.channels import describe
    from bioflex_jsb.simulation.controller import check_signals

    assert check_signals([TIP_AZ, "imu_tip_gx_rad_s", "airspeed_pitot_m_s"])
    assert describe("imu_tip_gz_rad_s").unit == "rad/s"
    assert describe("imu_tip_ax_rad_s").kind == "unknown"  # an accelerometer in rad/s
