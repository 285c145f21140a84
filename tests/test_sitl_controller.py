"""A controller in the loop of the SITL vehicle (drivers/sitl.py, runtime/control_surfaces.py
"Over an autopilot"): its elevator is added to the autopilot's through the pitch trim, the
surface the autopilot's plus the controller's to rounding; the session log holds its
commands and signals (/bioflex/<model>/controller) as the rows; what cannot be added is one
line."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.errors import InputError
from bioflex_jsb.runtime.control_surfaces import elevator_map, throttle_command
from bioflex_jsb.simulation import jsbsim_properties as JP
from bioflex_jsb.simulation.controller import LinearController
from tests.test_sitl import build, make_sim, run_cli  # noqa: F401  (the wing fixture)

KICK_AT_S = 0.2
KICK_RAD = 0.03


class _Kick:
    """An elevator step of KICK_RAD over the trim from KICK_AT_S (reads q, unused)."""

    inputs = ("q",)
    outputs = ("elevator",)

    def step(self, t_s, signals):
        return {"elevator": KICK_RAD if t_s >= KICK_AT_S - 1e-9 else 0.0}


def test_the_controllers_elevator_adds_to_the_autopilots(build):  # noqa: F811
    """In CRUISE the autopilot writes fcs/elevator-cmd-norm inside every JSBSim step; the
    controller's δe goes to the pitch trim, so after each step the surface is
    m (autopilot's command + the trim's pitch trim) + δe (the prototype's one-slope map m,
    20° per unit), to 1e-12 rad; the autopilot answers the kick (its own command moves)."""
    sim = make_sim(build, controller=_Kick())
    a = sim.airframe
    m = elevator_map(a, over_autopilot=True)
    pitch_trim0 = a[JP.FCS_PITCH_TRIM_CMD_NORM]
    names = sim.names
    col = names.index("ctrl_elevator_rad")
    applied, ap_cmd = [], []
    with a.capturing():
        for _ in range(int(round(0.4 / sim.dt_s))):
            row = sim.step()
            surface = a[JP.FCS_ELEVATOR_POS_RAD]
            ap = a[JP.FCS_ELEVATOR_CMD_NORM]
            applied.append(surface - m.angle_rad(ap + pitch_trim0))
            ap_cmd.append(ap)
            assert applied[-1] == pytest.approx(row[col], abs=1e-12)
    applied = np.array(applied)
    k = int(round(KICK_AT_S / sim.dt_s))
    assert np.all(applied[:k] == pytest.approx(0.0, abs=1e-12))
    assert np.all(applied[k:] == pytest.approx(KICK_RAD, abs=1e-12))
    assert np.ptp(ap_cmd[k:]) > 1e-3  # the autopilot fights the kick: both act
    assert sim.controller_meta["inputs"] == ["q"] and sim.stopped is None


def test_the_session_log_holds_the_controller(build, tmp_path):  # noqa: F811
    """A linear controller on q through a session's SplitLog: read back, the log's
    ctrl_elevator_rad is the rows' to the bit and its meta says what it was; the file passes
    pymcap's strict doctor (the controller's chunks after the steps')."""
    from bioflex_jsb.cli.gust import open_log
    from bioflex_jsb.cli.sitl import SplitLog
    from bioflex_jsb.simulation.run import RunDescription
    from tests.test_events import doctor_strict

    gain = LinearController.from_arrays(None, None, None, [[0.05]], sim_dt := 1 / 960,
                                        ["q"], ["elevator"], "q_damper")
    sim = make_sim(build, controller=gain)
    assert sim.dt_s == sim_dt
    path = tmp_path / "s.mcap"
    log = SplitLog(str(path), RunDescription("sitl", "optimised", 15.0, gust="none",
                                             models=("coupled",), duration_s=1.0),
                   build, 256.0, open_log)
    on_sample = log.attach(sim)
    sim.trigger_gust()  # GUST_AMP_MS 1 over 30 m: the pitch rate moves
    cmds = []
    with sim.airframe.capturing():
        for _ in range(700):
            t = sim.t_s
            values = sim.step()
            on_sample(t, sim.wing.model, values)
            cmds.append(values[sim.names.index("ctrl_elevator_rad")])
            if len(cmds) % 24 == 0:
                log.idle(1.0)
    log.close()
    back = api.read_log(path)["coupled"]
    assert np.ptp(cmds) > math.radians(0.01)
    assert np.array_equal(back["ctrl_elevator_rad"], np.array(cmds))
    assert back.meta["controller"]["name"] == "q_damper"
    assert back.meta["controller"]["inputs"] == ["q"]
    doctor_strict(path)


def test_a_powered_autopilots_throttle_is_not_commanded():
    """A powered aircraft's autopilot writes the levers itself: a controller's throttle over
    it is refused in one line (the prototype's autothrottle adds to the lever: accepted)."""
    powered = SimpleNamespace(glider=False, engines=(SimpleNamespace(index=0),),
                              aircraft="c172_sitl",
                              has_property=lambda n: n == "ap/throttle-trim-norm[0]")
    with pytest.raises(InputError, match="writes the throttle levers itself"):
        throttle_command(powered, over_autopilot=True)


def test_the_cli_refuses_a_bad_controller_in_one_line(capsys, monkeypatch, tmp_path):
    from tests.cli_helpers import assert_one_line_error

    bad = tmp_path / "bad.toml"
    bad.write_text('[controller]\ndt_s = 0\ninputs = ["qq"]\noutputs = ["elevator"]\n'
                   'd = [[1.0]]\n')
    code = run_cli(["sitl", "--controller", str(bad), "--no-log", "--duration", "0.1"],
                   monkeypatch)
    assert_one_line_error(code, capsys.readouterr().err, "'qq' is not a signal of the run")


def test_a_flaperon_controller_flies_the_compiled_step_quietly(capsys, monkeypatch, tmp_path):
    """``sitl --controller gla_flaperon_optimised``: the compiled step flies the flaperon
    (runtime/flaperon_step.py), so nothing is said about the step, on stderr or as a Python
    warning; the session's log records the flaperon's surface (its section loads need
    it)."""
    import warnings

    monkeypatch.chdir(tmp_path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = run_cli(["sitl", "--controller", "gla_flaperon_optimised", "--out",
                        "s.mcap", "--duration", "0.2", "--speedup", "4", "--json"],
                       monkeypatch)
    err = capsys.readouterr().err
    assert code == 0, err
    assert not [ln for ln in err.splitlines() if "note:" in ln or "flaperon" in ln], err
    assert not [w for w in caught if "flaperon" in str(w.message)]
    back = api.read_log(tmp_path / "s.mcap")
    run = next(iter(back.values()))
    assert run.meta["flaperon"]["surface"]["name"] == "aileron"
