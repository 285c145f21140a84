"""A second aircraft through the linear analyses from its definition file alone (issue 23,
item 4, linear part): JSBSim's SGS glider (bioflex_jsb/data/aircraft/sgs_elastic.toml, its
derivatives from SGS.xml, its wing the estimated beam of sgs_wing.toml as modes).

Its numbers need not match anything published; they must be physically plausible. The
checks, each against a closed form written here with its numbers:

* the wing's frequencies against the uniform cantilever's closed forms (bending
  1.8751², 4.6941² sqrt(EI/(m' L⁴)), torsion (π/2) sqrt(GJ/(I_α L²)));
* the clamped wing's divergence against the strip-theory closed form
  q_D = (π/2)² GJ / (L² e c a₀);
* the short period against the two-degree-of-freedom estimate
  ω_sp² ≈ −M_α + M_q Z_α/u₀;
* the phugoid against Lanchester's sqrt(2) g/u₀, corrected for the quasi-static pitch
  balance of a lightly stable airframe.

And the proof that the values are this aircraft's, not the prototype's: the state matrix
entries against the file's derivatives, a prototype condition beside this wing refused,
the commands not yet moved to another airframe refused in one line (its
flight: tests/test_second_aircraft_flight.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.definition import load_definition
from bioflex_jsb.definition.clamped import beam_sections
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.lti import build_state_space
from bioflex_jsb.flight_dynamics.rigid import level_flight_condition
from bioflex_jsb.parameters.airframe import PROTOTYPE_AIRFRAME
from bioflex_jsb.structures.beam import beam_modes
from bioflex_jsb.structures.modal_file import read_modal_file
from tests.cli_helpers import run_cli

G = 9.80665
RHO = 1.225
# sgs_elastic.toml
S, CBAR, MASS, IYY = 13.073, 0.99974, 322.05, 911.11
CL_ALPHA, CD0, K, CM_ALPHA, CM_Q = 4.3, 0.0157, 0.024718, -0.573, -9.0
# sgs_wing.toml's beam
EI, GJ, M_PER_L, I_ALPHA, L, CHORD = 4.93e5, 1.17e5, 7.0, 0.4375, 7.036, 1.0


@pytest.fixture(scope="module")
def sgs():
    return api.load_aircraft("sgs_elastic")


def test_the_shipped_modes_are_the_beam_wings(sgs):
    # provenance of sgs_elastic_modes.toml: sgs_wing.toml's beam, 3 modes, 40 elements, as its
    # header says (the file prints every digit: measured 0 difference)
    built = beam_modes(beam_sections(load_definition("sgs_wing")), 3, n_elements=40)
    shipped = read_modal_file(sgs.definition.structure.modes_file)
    for field in ("frequencies_rad_s", "generalised_masses_kg_m2", "bending_m", "twist_rad",
                  "stations_m"):
        a, b = getattr(built, field), getattr(shipped, field)
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), field


def test_wing_frequencies_against_the_beam_closed_forms(sgs):
    # centre of mass on the elastic axis: bending and torsion uncoupled, so the closed forms
    # are exact for the continuum; 40 elements measured within 1e-4 (bending 1 18.8484 vs
    # 18.8483, torsion 115.458 vs 115.451, bending 2 118.121 vs 118.121 rad/s); bar 1e-3
    w = sgs.wing().model.frequencies_rad_s
    bend = math.sqrt(EI / (M_PER_L * L**4))
    closed = (1.8751**2 * bend, math.pi / 2 * math.sqrt(GJ / (I_ALPHA * L**2)),
              4.6941**2 * bend)
    assert closed == pytest.approx((18.848, 115.451, 118.121), abs=0.01)
    assert np.allclose(w, closed, rtol=1e-3)


def test_clamped_divergence_against_the_strip_closed_form():
    # q_D = (pi/2)^2 GJ / (L^2 e c a0): e = (0.38 - 0.25) c, a0 = 2 pi (strip lift slope),
    # = 7138 Pa, V_D = sqrt(2 q_D / rho) = 107.95 m/s; measured 107.97 (the p-k search's
    # step); bar 0.5 % (the search's tolerance and the 40-element beam)
    q_d = (math.pi / 2) ** 2 * GJ / (L**2 * 0.13 * CHORD * 2 * math.pi)
    v_d = math.sqrt(2 * q_d / RHO)
    assert v_d == pytest.approx(107.95, abs=0.05)
    res = api.flutter("bioflex_jsb/data/aircraft/sgs_wing.toml", clamped=True)
    assert res.mechanism == "static divergence" and not res.present_at_lower_end
    assert res.speed_m_s == pytest.approx(v_d, rel=5e-3)


def _dimensional(v):
    q_s = 0.5 * RHO * v**2 * S
    cl = MASS * G / q_s
    z_alpha = -(CL_ALPHA + CD0 + K * cl**2) * q_s / MASS  # [m/s^2 per rad]
    m_alpha = CM_ALPHA * q_s * CBAR / IYY  # [1/s^2]
    m_q = CM_Q * q_s * CBAR**2 / (2 * IYY * v)  # [1/s]
    return z_alpha, m_alpha, m_q


def test_the_model_is_this_aircrafts(sgs):
    # the rigid block's alpha and pitch rows from the file's S, c-bar, mass, Iyy and
    # derivatives (SGS.xml's), to rounding; the prototype's numbers would be 10-1000 x off
    a = api.linear_model(sgs, 25.0, "rigid").a
    z_alpha, m_alpha, m_q = _dimensional(25.0)
    assert a[1, 1] == pytest.approx(z_alpha / 25.0, rel=1e-12)
    m_wdot = -5.2 * 0.5 * RHO * 625 * S * CBAR**2 / (2 * IYY * 625)
    assert a[2, 1] == pytest.approx(m_alpha + m_wdot * z_alpha, rel=1e-12)
    assert a[2, 2] == pytest.approx(m_q + m_wdot * 25.0, rel=1e-12)
    # the wing's Table B1 coefficients are non-dimensional with the glider's S and c-bar: a
    # prototype flight condition beside this wing is a caller's bug, refused
    wing = sgs.wing().model
    assert wing.airframe.reference.area_m2 == S and wing.airframe is not PROTOTYPE_AIRFRAME
    with pytest.raises(ValueError, match="built for airframe 'sgs_elastic'"):
        build_state_space("coupled", level_flight_condition(25.0,
                                                            airframe=PROTOTYPE_AIRFRAME), wing)
    # the elastic trim is the glider's: C_L = m g / (Q S) = 0.631 at 25 m/s
    cond = level_flight_condition(25.0, airframe=wing.airframe)
    assert cond.cl_trim == pytest.approx(MASS * G / (0.5 * RHO * 625 * S), rel=1e-12)
    from bioflex_jsb.flight_dynamics.elastic_trim import elastic_trim

    trim = elastic_trim(sgs.wing(), 25.0)
    assert trim.cl_trim == pytest.approx(cond.cl_trim, rel=1e-12)
    # the static tip deflection up at 1 g: measured 0.132 m (1.9 % of the semispan, the
    # range of a sailplane's wing at 1 g: a few per cent); bar 0.5-5 %
    assert 0.005 * L < trim.tip_deflection_up_m < 0.05 * L
    ss = api.linear_model(sgs, 25.0, "coupled", trim="elastic")
    assert ss.notes["eta_static_rad"] == pytest.approx(list(trim.eta_rad), rel=1e-12)


@pytest.mark.parametrize("speed", [25.0, 30.0, 35.0])
def test_short_period_against_the_hand_estimate(sgs, speed):
    # omega_sp^2 ~ -M_alpha + M_q Z_alpha/u0 (the 2-DoF short period, u held; M_alphadot
    # damps, it does not stiffen). At 25 m/s: Q S = 5004.6 N, M_alpha = -3.147 1/s^2,
    # M_q = -0.989 1/s, Z_alpha/u0 = -2.683 1/s: omega = sqrt(3.147 + 2.652) = 2.409 rad/s;
    # the rigid model 2.466. Measured +2.4, +1.2, +0.6 % at 25, 30, 35 m/s: the estimate
    # holds u still, and the glider's phugoid is near (0.40 rad/s at 25 m/s; +5 % at 20 m/s,
    # +14 % at 15, where omega_sp/omega_p is 3.8 and 2.1); bar 5 %.
    # The elastic wing (coupled model) raises it by measured 4.5, 7.0, 10.7 % (the same
    # speeds); bar 15 % of the rigid one's.
    z_alpha, m_alpha, m_q = _dimensional(speed)
    hand = math.sqrt(-m_alpha + m_q * z_alpha / speed)
    if speed == 25.0:
        assert hand == pytest.approx(2.409, abs=2e-3)
    rigid = api.modes(sgs, speed, "rigid").get("short_period")
    assert rigid.frequency_rad_s == pytest.approx(hand, rel=0.05)
    assert rigid.damping > 0.5  # a heavily damped short period (Cmq -9, Cmadot -5.2)
    coupled = api.modes(sgs, speed, "coupled").get("short_period")
    assert coupled.frequency_rad_s == pytest.approx(rigid.frequency_rad_s, rel=0.15)


@pytest.mark.parametrize("speed", [25.0, 30.0, 35.0])
def test_phugoid_against_lanchester(sgs, speed):
    # Lanchester: omega_p = sqrt(2) g/u0 (0.555 rad/s at 25 m/s). With alpha and q in
    # quasi-static balance (q-dot = 0: alpha = -M_q q/M_alpha; alpha-dot = 0 in the alpha row)
    # it becomes omega_p^2 = 2 (g/u0)^2 M_alpha / (M_alpha - Z_alpha M_q/u0): the glider's
    # pitch stiffness is not large against its pitch damping (factor 0.543 at 25 m/s):
    # 0.408 rad/s. Measured 0.399 (-2.3 %; 30, 35 m/s -1.2, -0.6 %; -5 % at 20 m/s, -12 %
    # at 15: the short period near, as above); bar 5 %. And below Lanchester's, as the
    # correction says.
    z_alpha, m_alpha, m_q = _dimensional(speed)
    lanchester = math.sqrt(2.0) * G / speed
    corrected = lanchester * math.sqrt(m_alpha / (m_alpha - z_alpha * m_q / speed))
    ph = api.modes(sgs, speed, "rigid").get("phugoid")
    assert ph.frequency_rad_s == pytest.approx(corrected, rel=0.05)
    assert ph.frequency_rad_s < lanchester


def test_free_aircraft_flutter_both_aerodynamic_models(sgs):
    # nothing in the prototype's 5-40 m/s (the SGS flies 20-28 m/s); its default range is
    # derived from its wing: 5-150 % of 1.5 x its divergence speed, body held (121.61 m/s),
    # so the default search finds the flutter a fixed 5-40 m/s called "no instability"; the
    # default strips are unsteady (the quasi-steady ones' 59 m/s is their torsion artefact),
    # scanned in the range / 350 steps (0.49 m/s: the same point as at 0.1 m/s, measured)
    assert api.flutter(sgs, (5.0, 40.0)).speed_m_s is None
    default = api.flutter(sgs)
    top = 1.5 * 121.61
    assert default.range_m_s == pytest.approx((0.05 * top, top), abs=0.2)
    assert default.aero == "unsteady" and not default.quasi_steady_artefact
    assert default.speed_m_s == pytest.approx(138.93, abs=0.1)
    # quasi-steady strips: the torsion mode's own flutter (no pitch damping on a quasi-steady
    # section: docs/decisions.md "Structural damping"), measured 59.11 m/s, 102.5 rad/s;
    # unsteady strips (Jones lag states): that mode is damped, the first instability is the
    # torsion-bending coalescence at 138.93 m/s, 58.8 rad/s, k 0.21 (a wing-flutter reduced
    # frequency); the wing's divergence, body held, 121.61 m/s (VLM loading). Bars: 0.1 m/s
    # (the bisection is 1e-4 m/s; the scan's labels are what may move)
    qs = api.flutter(sgs, (5.0, 150.0), aero="quasi-steady")
    assert qs.speed_m_s == pytest.approx(59.11, abs=0.1)
    assert qs.mode == "aeroelastic_2" and qs.mechanism == "single-mode"
    assert qs.quasi_steady_artefact and qs.caveat
    assert qs.divergence_speed_m_s == pytest.approx(121.61, abs=0.1)
    from bioflex_jsb.aeroelasticity.free_aircraft import free_flutter

    # the unsteady scan at 0.5 m/s (api's 0.1 m/s takes 40 s; measured the same point)
    un = free_flutter(sgs.wing(), aero="unsteady", range_m_s=(5.0, 150.0), step_m_s=0.5)
    assert un.speed_m_s == pytest.approx(138.93, abs=0.1)
    assert un.mechanism == "coalescence" and 0.1 < un.reduced_frequency < 1.0
    assert not un.present_at_lower_end


def test_commands_take_the_aircraft_file(capsys, tmp_path):
    path = "bioflex_jsb/data/aircraft/sgs_elastic.toml"
    code, out, _ = run_cli(capsys, "modes", "--aircraft", path, "--speed", "25", "--json")
    assert code == 0
    import json

    data = json.loads(out)
    sp = [m for r in data["results"] if r["model"] == "rigid" for m in r["modes"]
          if m["mode"] == "short_period"]
    assert sp and sp[0]["frequency_rad_s"] == pytest.approx(2.466, abs=1e-3)
    code, out, _ = run_cli(capsys, "flutter", "--aircraft", path, "--range", "5:150", "--aero",
                           "quasi-steady")
    assert code == 0 and "flutter at 59.1 m/s [quasi-steady artefact" in out
    # the flight commands fly it (tests/test_second_aircraft_flight.py; sitl:
    # tests/test_glider_sitl.py); export writes the LTI model of its own glide condition at
    # its cruise speed (the throttle column zero: no engine)
    out_file = tmp_path / "sgs.npz"
    code, out, err = run_cli(capsys, "export", "--aircraft", path, "--out", str(out_file),
                             "--json")
    assert code == 0, err
    info = json.loads(out)
    assert info["speed_m_s"] == 25.0 and info["wing"] == "sgs"
    from bioflex_jsb.sinks.model_export import read_state_space

    ss = read_state_space(out_file)
    assert ss.a.shape[0] == 10
    throttle = list(ss.inputs).index("throttle")
    assert not ss.b[:, throttle].any()
    mine = api.linear_model(sgs_wing := api.load_aircraft("sgs_elastic").wing(), 25.0,
                            "coupled")
    assert ss.a == pytest.approx(mine.a, rel=1e-12, abs=1e-12), sgs_wing.variant.name


def test_the_api_defaults_to_the_aircrafts_cruise_speed(sgs):
    """``api.modes``, ``api.linear_model`` without a speed analyse an Aircraft at its own
    cruise speed (the SGS: 25 m/s, its file), as the CLI's ``modes --aircraft`` does; they
    said 15 m/s, the prototype's, outside the glider's 20-28 m/s. A bare wing of another
    airframe has no cruise speed: one line asks for it. ``free_speed_range_m_s`` takes the
    Aircraft too (it raised AttributeError)."""
    ms = api.modes(sgs)
    assert ms.speed_m_s == 25.0
    assert ms.as_dict() == api.modes(sgs, 25.0).as_dict()
    assert np.array_equal(api.linear_model(sgs).a, api.linear_model(sgs, 25.0).a)
    with pytest.raises(InputError, match="give speed_m_s"):
        api.modes(sgs.wing())
    assert api.modes(api.load_wing("optimised")).speed_m_s == 15.0  # the prototype's
    assert api.free_speed_range_m_s(sgs) == api.free_speed_range_m_s(sgs.wing(), 1.225)
    assert api.free_speed_range_m_s(api.load_wing("optimised")) == (5.0, 40.0)


def test_a_modes_file_wing_reports_no_ribs(sgs):
    """The log's and JSON's wing variant said ``ribs: true`` for the SGS's modes-file wing,
    which has no ribs: the flag only chooses the prototype's beam."""
    variant = sgs.wing().variant
    assert variant.modes_file and variant.as_dict()["ribs"] is None
    assert api.load_wing("optimised").variant.as_dict()["ribs"] is True
