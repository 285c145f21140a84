"""``export --axis lateral``: the lateral-directional model written as the longitudinal one is
(named signals and units, read back and converted to python-control with its names), the
matrices api.lateral_model gives, exactly."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.sinks.model_export import read_state_space, to_python_control
from tests.cli_helpers import run_cli


@pytest.mark.parametrize(("argv", "subject", "model"), [
    ((), None, "coupled"),
    (("--aircraft", "c172_elastic", "--model", "qsd"), "c172_elastic", "qsd"),
])
def test_export_axis_lateral_round_trips(capsys, tmp_path, argv, subject, model):
    path = tmp_path / "lateral.npz"
    code, out, err = run_cli(capsys, "export", "--axis", "lateral", "--out", str(path), *argv)
    assert code == 0, err
    back = read_state_space(path)
    wing = api.load_aircraft(subject) if subject else api.load_wing("optimised")
    want = api.lateral_model(wing, None, model)
    for m in ("a", "b", "c", "d"):
        np.testing.assert_array_equal(getattr(back, m), getattr(want, m), err_msg=m)
    assert back.states == want.states and back.inputs == ("v_g", "aileron", "rudder")
    assert back.outputs[-1] == "n_y" and back.notes["axis"] == "lateral"
    sys_ctrl = to_python_control(path)
    assert list(sys_ctrl.input_labels) == ["v_g", "aileron", "rudder"]
    assert list(sys_ctrl.state_labels)[:4] == ["beta", "p", "r", "phi"]
