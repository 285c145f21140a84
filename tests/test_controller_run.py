"""A controller in the coupled step (runtime/coupled_step.py, runtime/control_surfaces.py):
the JSBSim boundary's elevator map (measured), a zero controller leaves the run as it was
to the bit, the surface follows the command one step later, the throttle, the Python step
and the compiled one agree, and what cannot be commanded is one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.errors import InputError
from bioflex_jsb.runtime.control_surfaces import elevator_map
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.controller import LinearController
from bioflex_jsb.simulation.gusts import parse_gust

DT = 1.0 / 960.0


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("optimised")


@pytest.fixture(scope="module")
def airframe():
    return Airframe()


def _setup(gust: str = "1cos:1:2", duration_s: float = 0.6) -> RunConfig:
    return RunConfig(15.0, parse_gust(gust), duration_s, 0.1, models=("coupled",))


def test_elevator_maps():
    """The prototype's controls: one gain, 20° per unit command
    (parameters.airframe.CONTROL_LIMITS); JSBSim's c172p: an aerosurface_scale of −28°/+23°
    with its gain 0.01745 rad/deg (c172p.xml), so 0.4886 and 0.40135 rad per unit."""
    m = elevator_map(Airframe())
    assert m.down_rad == m.up_rad == pytest.approx(math.radians(20.0), abs=1e-8)
    c172 = elevator_map(airframe_for(api.load_aircraft("c172_elastic")))
    assert c172.down_rad == pytest.approx(23 * 0.01745, rel=1e-12)
    assert c172.up_rad == pytest.approx(28 * 0.01745, rel=1e-12)
    assert c172.command(c172.angle_rad(-0.3)) == pytest.approx(-0.3, rel=1e-14)


def test_zero_controller_changes_nothing(wing):
    """A controller that commands 0 writes the trim's own command: every channel of the run
    is the uncontrolled run's to the bit (each on a fresh airframe: a trim starts from
    the airframe's last state, and its result differs in the last bits)."""
    setup = _setup()
    zero = LinearController.from_arrays(None, None, None, [[0.0, 0.0]], DT, ["alpha", "q"],
                                        ["elevator"], "zero")
    plain = run_gust(Airframe(), wing.model, "coupled", setup)
    ctrl = run_gust(Airframe(), wing.model, "coupled", setup, controller=zero)
    assert set(ctrl.channels) == set(plain.channels) | {"ctrl_elevator_rad"}
    for name, values in plain.channels.items():
        assert np.array_equal(values, ctrl[name]), name
    assert ctrl.meta["controller"]["name"] == "zero"


def test_surface_follows_the_command_one_step_later(wing, airframe):
    """δe from row k is the elevator of row k + 1 (JSBSim's flight controls move it in its
    step k), exactly: the map's rad-per-command conversion and back."""
    gain = LinearController.from_arrays(None, None, None, [[2.0, 0.1]], DT, ["alpha", "q"],
                                        ["elevator"], "gla")
    run = run_gust(airframe, wing.model, "coupled", _setup(), controller=gain)
    cmd, surface = run["ctrl_elevator_rad"], run["elevator_rad"]
    assert abs(cmd).max() > math.radians(2.0)  # the gust moved it
    assert np.abs(surface[1:] - surface[0] - cmd[:-1]).max() < 1e-15
    assert cmd[0] == pytest.approx(2.0 * run["alpha"][0] + 0.1 * run["q"][0], abs=1e-15)
    assert run.units["ctrl_elevator_rad"] == "rad"


def test_python_step_and_compiled_step_agree(wing, airframe):
    gain = LinearController.from_arrays(None, None, None, [[2.0, 0.1]], DT, ["alpha", "q"],
                                        ["elevator"], "gla")
    setup = _setup(duration_s=0.4)
    fast = run_gust(airframe, wing.model, "coupled", setup, controller=gain)
    slow = run_gust(airframe, wing.model, "coupled", setup, controller=gain, compiled=False)
    for name in ("alpha", "q", "eta1", "elevator_rad", "ctrl_elevator_rad"):
        span = np.ptp(fast[name])
        assert np.abs(fast[name] - slow[name]).max() <= 1e-9 * span, name


class _Throttle:
    """A throttle step of +0.05 from 0.1 s (a Python controller)."""

    inputs = ("u",)
    outputs = ("throttle",)

    def step(self, t_s, signals):
        return {"throttle": 0.05 if t_s >= 0.1 else 0.0}


def test_throttle(wing, airframe):
    run = run_gust(airframe, wing.model, "coupled", _setup("none", 0.3), controller=_Throttle())
    thr = run["throttle"]
    k = int(round(0.1 / DT))
    assert thr[k] == thr[0] and thr[k + 1] == pytest.approx(thr[0] + 0.05, abs=1e-12)
    assert run["u"][-1] > run["u"][k]  # it speeds up


def test_what_cannot_be_commanded(wing):
    sgs = api.load_aircraft("sgs_elastic")
    with pytest.raises(InputError, match="has no engine: a controller cannot command its "
                                         "throttle"):
        api.fly_gust(sgs, gust="none", models=("coupled",), duration_s=0.1,
                     controller=_Throttle())
    eta9 = LinearController.from_arrays(None, None, None, [[1.0]], DT, ["eta9"],
                                        ["elevator"])
    with pytest.raises(InputError, match="no channel 'eta9'"):
        api.fly_gust(wing, gust="none", models=("coupled",), duration_s=0.1, controller=eta9)


def test_the_log_holds_the_controller(wing, tmp_path):
    """/bioflex/<model>/controller: the commands and the signals read, every step, read back
    by read_log as the run's ctrl_* channel to the bit; the file passes pymcap's strict
    doctor (chunks in log-time order)."""
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import RunLog
    from tests.test_events import doctor_strict

    path = tmp_path / "ctrl.mcap"
    desc = RunDescription("gust", "optimised", 15.0, gust="1cos:1:2", models=("coupled",),
                          duration_s=0.6, gust_start_s=0.1)
    log = RunLog.open(path, desc, wing_variant=wing.variant.as_dict())
    try:
        run = api.fly_gust(wing, 15.0, "1cos:1:2", models=("coupled",), duration_s=0.6,
                           gust_start_s=0.1, recorders={"coupled": log.recorder("coupled")},
                           controller="gla_optimised")["coupled"]
    finally:
        log.close()
    back = api.read_log(path)["coupled"]
    assert np.array_equal(back["ctrl_elevator_rad"], run["ctrl_elevator_rad"])
    assert "ctrl_throttle" not in back.channels  # not commanded
    assert back.meta["controller"]["inputs"] == ["alpha", "q"]
    assert back.meta["controller"]["name"] == run.meta["controller"]["name"]
    doctor_strict(path)


def test_cli_refuses_a_bad_controller_in_one_line(capsys, tmp_path):
    from tests.cli_helpers import assert_one_line_error, run_cli

    bad = tmp_path / "bad.toml"
    bad.write_text('[controller]\ndt_s = 0\ninputs = ["qq"]\noutputs = ["elevator"]\n'
                   'd = [[1.0]]\n')
    for command in ("gust", "compare"):
        code, _, err = run_cli(capsys, command, "--controller", str(bad), "--no-log")
        assert_one_line_error(code, err, "'qq' is not a signal of the run")
    code, _, err = run_cli(capsys, "gust", "--controller", "no_such", "--no-log")
    assert_one_line_error(code, err, "shipped controller (fs_inertial-backward, "
                                     "gla_flaperon_optimised, gla_optimised, "
                                     "roll_damper_c172_elastic)")


def test_rerun_flies_the_controller_again():
    from bioflex_jsb.cli.rerun import argv_for
    from bioflex_jsb.simulation.run import RunDescription

    d = RunDescription("gust", "optimised", 15.0, extra={"controller": "/abs/gla.toml"})
    argv = argv_for(d)
    assert "--controller=/abs/gla.toml" in argv  # every option --option=value (cli/rerun.py)
