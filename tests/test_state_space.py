"""The one StateSpace type (bioflex_jsb/state_space.py, issue 23 item 3): every linear model
is one or converts to one, and ``to_control()`` gives python-control's ``StateSpace`` with the
same poles, frequency response and signal names.

Tolerances: python-control builds its system from the same matrices and (0.10.2, without
slycot) solves the same linear algebra through numpy/LAPACK: measured 0 difference in poles
and responses on this machine. Another python-control (slycot's Hessenberg evaluation) or
another processor's BLAS rounds differently; both computations are backward stable, so they
agree to a few ulps times the problem's conditioning: 1e-9 relative to the largest magnitude
leaves six orders of room over the 1e-15 such rounding gives on these 10- and 108-state
models (poles up to 680 rad/s beside lag roots near −4 1/s).
"""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aerodynamics.indicial import strip_state_space
from bioflex_jsb.aeroelasticity.state_space import aeroelastic_system
from bioflex_jsb.aeroelasticity.strip_aero import finite_state_model
from bioflex_jsb.definition import load_definition
from bioflex_jsb.definition.clamped import clamped_model
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.parameters import goland as G
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.state_space import StateSpace

control = pytest.importorskip("control", reason="python-control: the 'control' extra")

REL = 1e-9  # module docstring
FREQUENCIES_RAD_S = (0.3, 3.0, 30.0, 300.0)  # rigid modes (~1 rad/s) to the wing's (~200)


def _prototype_coupled() -> StateSpace:
    """The prototype's coupled LTI model (Eq. 4) at 15 m/s with the controls and the n_z and
    tip-twist outputs (what ``bioflex-jsb export`` writes)."""
    wing = api.load_wing("original")
    return build_state_space("coupled", level_flight_condition(15.0, airframe=PROTOTYPE_AIRFRAME),
                             wing.model, controls=True)


def _goland_aeroelastic() -> StateSpace:
    """The clamped Goland wing with Jones's Wagner and Küssner lag states at 120 m/s, below
    its flutter speed: a stable system (largest real part of a pole −4.1 1/s, measured)."""
    model = clamped_model(load_definition("goland"))
    return aeroelastic_system(model, speed_m_s=120.0, density_kg_m3=G.FLUTTER_DENSITY_KG_M3,
                              aero="unsteady", gust=True).to_state_space()


def _matched_poles(mine: np.ndarray, theirs: np.ndarray) -> float:
    """Largest distance from each of our poles to its nearest unused python-control pole,
    relative to the largest pole's magnitude (a one-to-one match, greedy by distance)."""
    left = list(theirs)
    worst = 0.0
    for p in sorted(mine, key=lambda z: (z.real, z.imag)):
        k = int(np.argmin([abs(p - q) for q in left]))
        worst = max(worst, abs(p - left.pop(k)))
    return worst / float(np.max(np.abs(mine)))


@pytest.mark.parametrize("build", [_prototype_coupled, _goland_aeroelastic])
def test_python_control_has_our_poles_response_and_names(build):
    # measured: poles and responses identical (0 difference) for both (REL: module
    # docstring)
    ss = build()
    sys_ = ss.to_control()
    assert isinstance(sys_, control.StateSpace) and sys_.isctime()
    assert list(sys_.state_labels) == list(ss.states)
    assert list(sys_.input_labels) == list(ss.inputs)
    assert list(sys_.output_labels) == list(ss.outputs)
    assert sys_.name == f"bioflex_{ss.model}"
    assert _matched_poles(ss.eigenvalues(), sys_.poles()) <= REL
    ours = ss.frequency_response(FREQUENCIES_RAD_S)
    for k, w in enumerate(FREQUENCIES_RAD_S):
        theirs = np.asarray(sys_(1j * w)).reshape(ours[k].shape)
        scale = float(np.max(np.abs(theirs)))
        assert scale > 0.0 and float(np.max(np.abs(ours[k] - theirs))) <= REL * scale, w


def test_python_control_step_response_is_our_model_s():
    # control.forced_response integrates the model over each step with the input
    # interpolated linearly; ours is the exact zero-order hold (expm): for a step input
    # (constant over every step) both are exact, so a gust step on the prototype's model
    # gives the same outputs to 1e-9 of their peak (measured 7e-15 of the 3.97 peak).
    ss = _prototype_coupled()
    dt, n = 0.01, 300
    t = np.arange(n) * dt
    u = np.zeros((len(ss.inputs), n))
    u[ss.inputs.index("w_g")] = 1.0  # a 1 m/s step gust, positive up
    theirs = control.forced_response(ss.to_control(), t, u).outputs
    disc = ss.to_discrete(dt)
    x = np.zeros(ss.n_states)
    ours = np.empty_like(theirs)
    for k in range(n):
        ours[:, k] = disc.c @ x + disc.d @ u[:, k]
        x = disc.a @ x + disc.b @ u[:, k]
    assert float(np.max(np.abs(ours))) > 0.1  # the step moves the aircraft
    assert float(np.max(np.abs(ours - theirs))) <= REL * float(np.max(np.abs(theirs)))


def test_discrete_model_is_python_control_s_zero_order_hold():
    # python-control's sample_system (scipy's cont2discrete, zoh) of the same system:
    # the same matrices to 1e-9 of their largest entry (measured 0), dt carried over
    ss = _goland_aeroelastic()
    dt = 1e-3
    disc = ss.to_discrete(dt)
    ref = control.sample_system(ss.to_control(), dt, method="zoh")
    assert not disc.continuous and disc.dt_s == dt
    for mine, theirs in ((disc.a, ref.A), (disc.b, ref.B)):
        assert float(np.max(np.abs(mine - theirs))) <= REL * float(np.max(np.abs(theirs)))
    sys_ = disc.to_control()
    assert sys_.isdtime() and sys_.dt == dt
    # a discrete frequency response at z = exp(i w dt)
    ours = disc.frequency_response([30.0])[0]
    theirs = np.asarray(sys_(np.exp(1j * 30.0 * dt))).reshape(ours.shape)
    assert float(np.max(np.abs(ours - theirs))) <= REL * float(np.max(np.abs(theirs)))
    with pytest.raises(ValueError, match="already discrete"):
        disc.to_discrete(dt)


def test_strip_converts_with_its_own_force_matrix():
    # The strip's StateSpace driven by (q, iw q, -w^2 q) and by w_g is the strip's own
    # force matrix and gust force: the same algebra, 1e-12 relative (measured 1.6e-16).
    strip = strip_state_space(speed_m_s=40.0, semichord_m=0.3, elastic_axis_a=-0.2,
                              density_kg_m3=1.225)
    ss = strip.to_state_space()
    assert ss.model == "strip" and ss.states == strip.state_names
    assert ss.inputs == ("h", "alpha", "h_dot", "alpha_dot", "h_ddot", "alpha_ddot", "w_g")
    assert ss.input_units[:2] == ("m", "rad") and ss.input_units[4] == "m/s^2"
    assert ss.outputs == ("minus_lift_n_per_m", "moment_n_m_per_m")
    for w in (5.0, 50.0):
        g = ss.frequency_response([w])[0]
        iw = 1j * w
        motion = g[:, 0:2] + iw * g[:, 2:4] + iw * iw * g[:, 4:6]
        ref = strip.force_matrix(w)
        assert float(np.max(np.abs(motion - ref))) <= 1e-12 * float(np.max(np.abs(ref)))
        gust = strip.gust_force(w)
        assert float(np.max(np.abs(g[:, 6] - gust))) <= 1e-12 * float(np.max(np.abs(gust)))


@pytest.mark.parametrize("aero", ["unsteady", "quasi-steady"])
def test_modal_forces_convert_with_their_own_force_matrix(aero):
    # as for the strip (1e-12 relative, measured 9e-17); the quasi-steady forces have no lag
    # state: a static StateSpace (D only)
    model = clamped_model(load_definition("goland"))
    fs = finite_state_model(model, speed_m_s=100.0, density_kg_m3=G.FLUTTER_DENSITY_KG_M3,
                            aero=aero)
    ss = fs.to_state_space()
    n = model.n_modes
    assert ss.n_states == fs.n_states and (ss.n_states == 0) == (aero == "quasi-steady")
    assert ss.outputs == tuple(f"Q_{i + 1}" for i in range(n)) and ss.speed_m_s == 100.0
    w = 60.0
    g = ss.frequency_response([w])[0]
    iw = 1j * w
    motion = g[:, :n] + iw * g[:, n:2 * n] + iw * iw * g[:, 2 * n:3 * n]
    ref = fs.force_matrix(w)
    assert float(np.max(np.abs(motion - ref))) <= 1e-12 * float(np.max(np.abs(ref)))


def test_aeroelastic_conversion_keeps_the_flutter_matrix():
    # the StateSpace's A is the flutter analysis's matrix itself (not a copy's rounding)
    model = clamped_model(load_definition("goland"))
    system = aeroelastic_system(model, speed_m_s=120.0, density_kg_m3=G.FLUTTER_DENSITY_KG_M3)
    ss = system.to_state_space()
    assert ss.a is system.a and ss.states == system.state_names
    assert ss.notes == {"n_modes": model.n_modes, "gust": False}
    assert not np.any(ss.b)  # no gust states asked for: a zero gust column


def test_missing_python_control_is_one_line(monkeypatch):
    monkeypatch.setitem(sys.modules, "control", None)  # import control raises ImportError
    with pytest.raises(InputError) as info:
        _prototype_coupled().to_control()
    text = str(info.value)
    assert "pip install 'bioflex-jsb[control]'" in text and "\n" not in text


def test_inconsistent_model_is_refused():
    ok = dict(model="x", speed_m_s=1.0, a=np.zeros((2, 2)), b=np.zeros((2, 1)),
              c=np.zeros((1, 2)), d=np.zeros((1, 1)), states=("x1", "x2"),
              state_units=("m", "m/s"), inputs=("u",), input_units=("N",), outputs=("y",),
              output_units=("m",))
    assert StateSpace(**ok).continuous
    with pytest.raises(ValueError, match="b is \\(2, 2\\), expected \\(2, 1\\)"):
        StateSpace(**{**ok, "b": np.zeros((2, 2))})
    with pytest.raises(ValueError, match="distinct names"):
        StateSpace(**{**ok, "states": ("x1", "x1")})
    with pytest.raises(ValueError, match="dt_s"):
        StateSpace(**{**ok, "dt_s": -1.0})
    with pytest.raises(ValueError, match="dt_s"):
        StateSpace(**{**ok, "dt_s": math.inf})
