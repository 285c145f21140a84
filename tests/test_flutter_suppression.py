"""Active flutter suppression (simulation/flutter_suppression.py): the unsteady LTI model with
the elevator, the closed-loop flutter search, and the nonlinear co-simulation agreeing.

Inertial-backward wing (axes aft: body-freedom flutter), unsteady strips, the shipped
``fs_inertial-backward`` (δe = 0.4414 q, a pitch damper; its design in
scripts/design_flutter_suppression.py). Measured (the tolerances stand above these):

* LTI, the closed loop at 960 Hz with the run's one step of delay: open loop 18.858 m/s
  (19.93 rad/s; api.flutter's unsteady free-aircraft search: 18.86 m/s), closed loop
  20.808 m/s (13.5 rad/s): +1.95 m/s, +10.3 %; the flutter root's growth rate at 20.5,
  20.75, 21.0 m/s: −1.03, −0.19, +0.64 1/s;
* nonlinear runs (``gust --aero unsteady --models coupled --gust sharp:0.05 --duration 6``
  with the controller), logarithmic decrement of η₁ from 0.7 s: −0.87 (20.5 m/s), −0.028
  (20.75 m/s, bounded over 6 s), +0.79 1/s (21.0 m/s: exit 3, |η₁| > 0.52 rad at 4.63 s);
  σ = 0 interpolated at 20.759 m/s, 0.05 m/s below the LTI's; the open loop at 20.0 m/s
  diverges (exit 3 at 1.15 s with sharp:0.3).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.free_aircraft import unsteady_state_space
from bioflex_jsb.errors import InputError
from bioflex_jsb.simulation import flutter_suppression as FS
from bioflex_jsb.simulation.controller import load_controller

SHIPPED = "fs_inertial-backward"
OPEN_LOOP_M_S = 18.858  # this search, the open loop (module docstring)
CLOSED_LOOP_M_S = 20.808  # this search with the shipped controller
SEARCH_TOL_M_S = 0.01  # above the 1 mm/s bisection; the scan's grid cannot move it more


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("inertial-backward")


@pytest.fixture(scope="module")
def controller():
    return load_controller(SHIPPED)


def test_plant_has_the_unsteady_roots_and_the_elevator(wing):
    """The elevator's columns leave A as the unsteady model's (the same roots), and move
    the pitch rate nose-down for a trailing-edge-down elevator."""
    v = 19.0
    p = FS.controlled_plant(wing, v)
    ref = unsteady_state_space(wing, v, gust=True)
    np.testing.assert_allclose(p.a, ref.a, rtol=0, atol=1e-9)
    ie, iq = p.inputs.index("elevator"), p.states.index("q")
    assert p.b[iq, ie] < 0.0  # C_mδe < 0: trailing edge down, nose down
    assert "n_z" in p.outputs and "q" in p.outputs


def test_open_loop_search_matches_the_flutter_command(wing):
    """The closed-loop search with no controller finds the unsteady free aircraft's
    body-freedom flutter (api.flutter, the phugoid left out there: it is stable here)."""
    res = FS.closed_loop_flutter(wing, None, (18.0, 20.0))
    assert res.speed_m_s == pytest.approx(OPEN_LOOP_M_S, abs=SEARCH_TOL_M_S)
    assert res.frequency_rad_s == pytest.approx(19.93, abs=0.05)
    ref = api.flutter(wing, (15.0, 25.0), aero="unsteady")
    assert res.speed_m_s == pytest.approx(ref.speed_m_s, abs=SEARCH_TOL_M_S)


def test_shipped_controller_raises_the_flutter_speed(wing, controller):
    """The pitch damper puts the closed loop's flutter 1.95 m/s (10 %) above the open loop's,
    as its file says, at the flutter branch's lower frequency."""
    res = api.closed_loop_flutter(wing, controller, (19.0, 22.0))
    assert res.speed_m_s == pytest.approx(CLOSED_LOOP_M_S, abs=SEARCH_TOL_M_S)
    assert res.speed_m_s - OPEN_LOOP_M_S > 1.9
    assert res.frequency_rad_s == pytest.approx(13.5, abs=0.3)
    notes = controller.system.notes
    assert notes["closed_loop_flutter_m_s"] == pytest.approx(res.speed_m_s, abs=SEARCH_TOL_M_S)
    assert notes["open_loop_flutter_m_s"] == pytest.approx(OPEN_LOOP_M_S, abs=SEARCH_TOL_M_S)


def test_a_destabilising_gain_lowers_it(wing):
    """The search is not blind to the controller: the pitch rate fed the wrong way (pitch
    anti-damping) brings the flutter below the open loop's (measured 16.92 m/s at −0.1
    rad per rad/s), and at −0.2 the loop is unstable at the range's lower end, reported as
    such and with no speed."""
    res = FS.closed_loop_flutter(wing, FS.static_gain([-0.1], ("q",)), (12.0, 20.0))
    assert res.speed_m_s is not None and res.speed_m_s < OPEN_LOOP_M_S - 1.5
    worse = FS.closed_loop_flutter(wing, FS.static_gain([-0.2], ("q",)), (12.0, 20.0))
    assert worse.present_at_lower_end and worse.speed_m_s is None


def test_log_decrement_of_a_damped_sine():
    """σ of y = e^{σt} sin(ωt) + a slow drift, for σ < 0 and σ > 0 (closed form)."""
    t = np.arange(0.0, 6.0, 1.0 / 960.0)
    for sigma in (-0.8, 0.3):
        y = np.exp(sigma * t) * np.sin(13.5 * t) + 0.05 * t
        got, peaks = FS.growth_from_response(t, y, 13.5, 0.5)
        assert got == pytest.approx(sigma, abs=0.02)
        assert peaks >= 10
    with pytest.raises(InputError, match="two periods"):
        FS.growth_from_response(t, np.sin(13.5 * t), 13.5, 5.9)


def test_api_refuses_bad_input(wing):
    with pytest.raises(InputError):
        api.closed_loop_flutter(wing, None, (30.0, 10.0))
    with pytest.raises(InputError):
        api.closed_loop_flutter(wing, None, (10.0, 1000.0))

    class Python:
        inputs, outputs = ("q",), ("elevator",)

        def step(self, t_s, signals):
            return {"elevator": 0.0}

    with pytest.raises(InputError, match="linear controller"):
        api.closed_loop_flutter(wing, Python(), (18.0, 20.0))


def _fly(wing, speed, controller):
    return api.fly_gust(wing, speed, "sharp:0.05", models=("coupled",), duration_s=6.0,
                        aero="unsteady", controller=controller)["coupled"]


@pytest.mark.slow
def test_nonlinear_runs_bracket_the_closed_loop_flutter(wing, controller):
    """Nonlinear co-simulation with the controller: bounded and decaying at 20.75 m/s, where
    the open loop diverges; diverging at 21.0 m/s; the zero of the logarithmic decrement's
    growth rate between them within 0.15 m/s of the LTI closed-loop flutter speed (measured
    0.05 m/s), each run's growth rate within 0.3 1/s of the LTI flutter root's."""
    w = 13.5  # the closed loop's flutter frequency [rad/s]
    below, above = 20.75, 21.0
    run_b = _fly(wing, below, controller)
    run_a = _fly(wing, above, controller)
    assert run_b.stopped is None
    assert run_a.stopped is not None
    sig_b, _ = FS.growth_from_response(run_b.time_s, run_b["eta1"], w, 0.7)
    sig_a, _ = FS.growth_from_response(run_a.time_s, run_a["eta1"], w, 0.7)
    assert sig_b < 0.0 < sig_a
    lti = {}
    for v in (below, above):
        s = FS.closed_loop_roots(FS.controlled_plant(wing, v), controller)
        s = s[(s.imag > 5.0) & (s.imag < 40.0)]
        lti[v] = float(np.max(s.real))
    assert abs(sig_b - lti[below]) < 0.3 and abs(sig_a - lti[above]) < 0.3
    crossing = below + (above - below) * (-sig_b) / (sig_a - sig_b)
    assert crossing == pytest.approx(CLOSED_LOOP_M_S, abs=0.15)
    open_loop = _fly(wing, below, None)
    assert open_loop.stopped is not None
    assert math.isfinite(crossing)


def test_flutter_command_with_a_controller(capsys):
    """``flutter --controller``: both speeds and the margin as JSON; what it does not take is
    one line, exit 2."""
    import json

    from tests.cli_helpers import assert_one_line_error, run_cli

    code, out, _ = run_cli(capsys, "flutter", "--wing", "inertial-backward", "--controller",
                           SHIPPED, "--range", "18:21", "--json")
    assert code == 0
    d = json.loads(out)
    assert d["open_loop"]["speed_m_s"] == pytest.approx(OPEN_LOOP_M_S, abs=SEARCH_TOL_M_S)
    assert d["closed_loop"]["speed_m_s"] == pytest.approx(CLOSED_LOOP_M_S, abs=SEARCH_TOL_M_S)
    assert d["margin_m_s"] == pytest.approx(CLOSED_LOOP_M_S - OPEN_LOOP_M_S, abs=0.02)
    code, _, err = run_cli(capsys, "flutter", "--controller", SHIPPED, "--aero",
                           "quasi-steady")
    assert_one_line_error(code, err, "unsteady strips")
    code, _, err = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--controller",
                           SHIPPED)
    assert_one_line_error(code, err, "clamped wing has none")
