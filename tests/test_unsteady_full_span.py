"""Both wing halves on unsteady strips in the nonlinear co-simulation
(simulation/unsteady_full_span.py; docs/lateral.md, "Both halves on unsteady strips"): the
step without its increments is the quasi-steady full-span step, a steady roll its
quasi-steady balance, and a run against the linear unsteady lateral model in compare
(an aileron step and rolling gusts, the prototype and the c172_elastic, the error halving
with the step); the p_g column of compare's lateral model keeps the increments' side force;
the compiled step is the Python one; gust, compare, sitl and ardupilot accept --span full
--aero unsteady."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity.antisymmetric import aircraft_strips
from bioflex_jsb.aeroelasticity.antisymmetric_strips import (
    antisymmetric_strips,
    yaw_sideslip_terms,
)
from bioflex_jsb.drivers.compare import compare_run
from bioflex_jsb.drivers.compare_lateral import full_span_lateral_model
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.flight_dynamics.lateral_elastic import antisymmetric_wing
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.jsbsim_aircraft import airframe_for
from bioflex_jsb.simulation.full_span import (
    AileronInput,
    AntisymmetricModalWing,
    LateralInputs,
)
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.unsteady_full_span import UnsteadyAntisymmetricWing
from tests.cli_helpers import run_cli

PROTOTYPE, C172 = "bioflex_optimised", "c172_elastic"
LATERAL = ("beta_rad", "p_rad_s", "r_rad_s", "phi_rad", "asym_eta1", "modal_roll_n_m")
# The prototype's roll inertia [kg·m²] (JSBSim's model, docs/lateral.md): any positive one
# gives the step's equations; this one gives the prototype's antisymmetric modes
PROTOTYPE_IXX_KG_M2 = 0.05


def _wings(unsteadiness: float, dt_s: float = DEFAULT_DT_S, model: str = "coupled"):
    """(the unsteady antisymmetric wing, the quasi-steady one of ``model``) of the
    prototype, on the same strips with the same yaw rate's and sideslip's terms."""
    ac = api.load_aircraft(PROTOTYPE)
    build = ac.wing()
    wing_a = antisymmetric_wing(build, PROTOTYPE_IXX_KG_M2)
    strips = antisymmetric_strips(wing_a, ac.definition.aileron, build.aero.chord_m)
    n_s = 3
    terms = yaw_sideslip_terms(wing_a, build.modes, n_s, build.planform,
                               2.0 * build.aero.semispan_m)
    tip = np.asarray(build.modes.twist_rad)[:n_s, -1]
    unsteady = UnsteadyAntisymmetricWing(strips, aircraft_strips(build, wing_a,
                                                                 PROTOTYPE_IXX_KG_M2),
                                         "coupled", dt_s, tip, terms=terms,
                                         unsteadiness=unsteadiness)
    return unsteady, AntisymmetricModalWing(strips, model, dt_s, tip, terms=terms)


def _inputs(k: int, dt_s: float) -> tuple[float, float, LateralInputs]:
    """A flow and lateral inputs that move every term: Q, V within and beyond the 5 %
    refresh band, p, p_g, the aileron, r, β, the wing's lift and η_s."""
    t = k * dt_s
    v = 15.0 * (1.0 + 0.08 * np.sin(2.0 * t))
    q = 0.5 * 1.2 * v**2
    return q, v, LateralInputs(0.2 * np.sin(9.0 * t), 0.01 * (t > 0.05), 0.05 * np.sin(5.0 * t),
                               0.1 * np.sin(3.0 * t), 0.02 * np.cos(4.0 * t),
                               12.0 * (1.0 + 0.1 * np.sin(6.0 * t)),
                               (0.01 * np.sin(7.0 * t), -0.005, 0.002))


def test_without_the_increments_the_step_is_the_quasi_steady_one():
    """Unsteadiness 0: the increments vanish, the lags only listen, and η_a, η̇_a and the
    rolling moment, side force and yawing moment are the quasi-steady full-span step's over
    0.5 s of moving inputs, the reference renewed as the flow leaves its band. Measured:
    9.3e-14 of each channel's largest value (round-off of the larger exponential and of
    the lag rows' differences); bar 1e-12."""
    unsteady, quasi = _wings(0.0)
    got, want = [], []
    for k in range(int(round(0.5 / DEFAULT_DT_S))):
        q, v, inputs = _inputs(k, DEFAULT_DT_S)
        for wing, out in ((unsteady, got), (quasi, want)):
            wing.step(q, v, inputs)
            out.append(np.r_[wing.eta, wing.eta_dot, wing.reactions(q, v, inputs)])
    got, want = np.array(got), np.array(want)
    scale = np.max(np.abs(want), axis=0)
    assert np.all(scale > 0.0)
    assert np.max(np.abs(got - want) / scale) < 1e-12
    assert np.max(np.abs(unsteady.lag_states)) > 0.0  # the lags listened


def test_a_steady_roll_is_the_quasi_steady_balance():
    """Held p, p_g, aileron, r, β: once the lags settle (the slowest, 0.0455 V/b, 7.46 /s on
    the prototype at 15 m/s) the unsteady wing's η_a and loads are the quasi-static balance
    of the quasi-steady strips (the qsd wing's: the increments vanish in a steady state,
    the lift on the three-quarter-chord upwash then the quasi-steady one). The quasi-steady
    coupled wing with p held is no reference: its first mode grows (+1.44 rad/s at 15 m/s,
    the quasi-steady strips' missing pitch damping, docs/lateral.md), which the unsteady
    strips damp. Measured after 4 s: 1.1e-15 of η_a, 2.1e-15 of the rolling moment, 6.7e-15
    of the yawing moment, the increments' moment 7e-16 N·m; bar 1e-10."""
    dt_s = 1.0 / 240.0
    unsteady, quasi = _wings(1.0, dt_s, "qsd")
    q, v = 135.0, 15.0
    inputs = LateralInputs(0.1, 0.01, 0.02, 0.05, 0.01, 12.0, (0.01, -0.005, 0.002))
    for _ in range(int(round(4.0 / dt_s))):
        unsteady.step(q, v, inputs)
        quasi.step(q, v, inputs)
    assert np.max(np.abs(unsteady.eta - quasi.eta)) < 1e-10 * np.max(np.abs(quasi.eta))
    got, want = unsteady.reactions(q, v, inputs), quasi.reactions(q, v, inputs)
    for a, b in zip(got, want, strict=True):
        assert abs(a - b) <= 1e-10 * abs(b), (got, want)
    assert abs(unsteady.increment_loads(q, v)[0]) < 1e-10 * abs(want[0])


def test_the_unsteady_wing_refuses_the_quasi_static_model():
    ac = api.load_aircraft(PROTOTYPE)
    build = ac.wing()
    wing_a = antisymmetric_wing(build, PROTOTYPE_IXX_KG_M2)
    strips = antisymmetric_strips(wing_a, None, build.aero.chord_m)
    with pytest.raises(Exception, match="coupled wing's"):
        UnsteadyAntisymmetricWing(strips, aircraft_strips(build, wing_a, PROTOTYPE_IXX_KG_M2),
                                  "qsd", DEFAULT_DT_S, np.zeros(3))


def test_the_compiled_step_is_the_python_one():
    """The compiled kernel (simulation/unsteady_full_span_kernel.py) against the Python
    step: the prototype through a rolling gust with an aileron step, 1 s, every channel.
    Measured: the full-span channels within 1e-12 of their range, the worst channel 8.1e-11
    (the half wing's η̇3: its kernel's SIMD sums, tests/test_unsteady_kernel.py); bars 1e-11
    and 1e-9."""
    ac = api.load_aircraft(PROTOTYPE)
    runs = [run_gust(Airframe(), ac.wing(), "coupled",
                     RunConfig(15.0, parse_gust("none+roll:0.1:15"), 1.0, models=("coupled",),
                               aero="unsteady"),
                     span="full", aileron=ac.definition.aileron, compiled=compiled,
                     aileron_input=AileronInput("step", np.radians(0.5), 0.3))
            for compiled in (False, True)]
    python, compiled = runs
    assert python.meta["lateral_strips"] == "unsteady, python"
    assert compiled.meta["lateral_strips"] == "unsteady, compiled kernel"
    lateral = {"aileron_rad", "modal_roll_n_m", "tip_twist_starboard_rad",
               "tip_twist_port_rad", "modal_side_n", "modal_yaw_n_m"}
    for name in python.channels:
        a, b = np.asarray(python[name]), np.asarray(compiled[name])
        scale = max(float(np.ptp(a)), 1e-300)
        bar = 1e-11 if name in lateral or name.startswith("asym_") else 1e-9
        assert np.max(np.abs(a - b)) <= bar * scale, name


def _compare(name: str, speed: float, gust: str, duration_s: float, dt_s: float = DEFAULT_DT_S,
             aileron_deg: float | None = None) -> dict:
    ac = api.load_aircraft(name)
    build, airframe = ac.wing(), airframe_for(ac)
    step = None if aileron_deg is None else AileronInput("step", np.radians(aileron_deg), 0.5)
    run = run_gust(airframe, build, "coupled",
                   RunConfig(speed, parse_gust(gust), duration_s, dt_s=dt_s,
                             models=("coupled",), aero="unsteady"),
                   span="full", aileron=ac.definition.aileron, aileron_input=step)
    assert run.stopped is None
    assert run.meta["lateral_strips"] == "unsteady, compiled kernel"
    return compare_run(build, run, "coupled", speed, aero="unsteady", airframe=airframe,
                       aileron=ac.definition.aileron).nrmse


# NRMSE of the linear unsteady lateral model against the run (compare --span full --aero
# unsteady), measured: the prototype's 0.5° aileron step from 0.5 s, 1.5 s: beta 0.0073,
# p 0.0124, r 0.0105, phi 0.0043, asym_eta1 0.0053, modal_roll 0.0076 (each halves with the
# step: 0.0037, 0.0062, 0.0058, 0.0021, 0.0027, 0.0042 at dt/2); bars about 1.5x
AILERON_STEP_NRMSE = {"beta_rad": 0.011, "p_rad_s": 0.019, "r_rad_s": 0.016, "phi_rad": 0.0065,
                       "asym_eta1": 0.008, "modal_roll_n_m": 0.012}


def test_an_aileron_step_on_unsteady_strips_is_the_linear_models():
    nrmse = _compare(PROTOTYPE, 15.0, "none", 1.5, aileron_deg=0.5)
    for channel, bar in AILERON_STEP_NRMSE.items():
        assert nrmse[channel] < bar, (channel, nrmse[channel])


def test_the_prototypes_rolling_gust_error_halves_with_the_step():
    """The prototype's rolling gust (0.1 rad/s over 15 m, 1 s) at dt and dt/2: the error is
    the explicit coupling's one-step lag of p, r, β (and of ṗ in the apparent roll
    inertia), first order. Measured NRMSE at dt, dt/2, dt/4: asym_eta1 0.0304, 0.0155,
    0.0079; p 0.0095, 0.0048, 0.0024; beta 0.0824, 0.0404, 0.0202; phi 0.0133, 0.0067,
    0.0035; modal_roll 0.0197 at dt. Ratio bar 1.8-2.2 (measured 1.96-2.04)."""
    first = _compare(PROTOTYPE, 15.0, "none+roll:0.1:15", 1.0)
    second = _compare(PROTOTYPE, 15.0, "none+roll:0.1:15", 1.0, DEFAULT_DT_S / 2.0)
    for channel in ("asym_eta1", "p_rad_s", "beta_rad", "phi_rad"):
        assert 1.8 < first[channel] / second[channel] < 2.2, (channel, first, second)
    assert first["modal_roll_n_m"] < 0.03 and first["asym_eta1"] < 0.045


# The c172_elastic's rolling gust (0.1 rad/s over 40 m, 3 s), measured: beta 0.0044, p
# 0.0022, r 0.0019, phi 0.0006, asym_eta1 0.0073, modal_roll 0.0139 (the quasi-steady
# strips' 0.0044, 0.0021, 0.0019, 0.00055, 0.0087, 0.0113); bars about 1.5x
C172_NRMSE = {"beta_rad": 0.0066, "p_rad_s": 0.0033, "r_rad_s": 0.0029, "phi_rad": 0.0009,
              "asym_eta1": 0.011, "modal_roll_n_m": 0.021}


def test_the_c172s_rolling_gust_on_unsteady_strips_is_the_linear_models():
    nrmse = _compare(C172, 57.8, "none+roll:0.1:40", 3.0)
    for channel, bar in C172_NRMSE.items():
        assert nrmse[channel] < bar, (channel, nrmse[channel])


def test_the_gust_roll_rates_column_keeps_the_increments_side_force():
    """The p_g column of compare's lateral model is minus its p column less what p does
    alone (the rigid model's β and φ rows: w₀/V, C_Yp, φ̇ = p): on the c172's unsteady strips
    (dihedral) the increments' side force of p − p_g stays in the β row (it was set to zero
    with the rigid part); on the quasi-steady strips the elastic β row has no p term and the
    column is zero there, as before."""
    ac = api.load_aircraft(C172)
    build, airframe = ac.wing(), airframe_for(ac)
    rigid = full_span_lateral_model(build, airframe, "rigid", 57.8).ss
    for aero in ("quasi-steady", "unsteady"):
        ss = full_span_lateral_model(build, airframe, "coupled", 57.8, aero=aero).ss
        p, beta = ss.states.index("p"), ss.states.index("beta")
        elastic = ss.a[beta, p] - rigid.a[rigid.states.index("beta"), rigid.states.index("p")]
        column = ss.b[beta, ss.inputs.index("p_g")]
        assert column == pytest.approx(-elastic, abs=1e-15)
        if aero == "quasi-steady":
            assert column == 0.0
        else:
            assert abs(column) > 1e-6 * abs(ss.a[beta, p])


def test_gust_and_compare_accept_both_halves_on_unsteady_strips(capsys):
    code, out, _ = run_cli(capsys, "compare", "--span", "full", "--aero", "unsteady",
                           "--aileron-step", "0.5", "--aileron-start", "0.2", "--gust", "none",
                           "--duration", "0.5", "--no-log", "--json")
    assert code == 0
    nrmse = json.loads(out)["nrmse"]
    assert all(nrmse[c] < 0.05 for c in LATERAL), nrmse
    code, out, _ = run_cli(capsys, "gust", "--span", "full", "--aero", "unsteady", "--models",
                           "coupled", "--aileron-step", "0.5", "--aileron-start", "0.1",
                           "--gust", "none", "--duration", "0.3", "--no-log", "--json")
    assert code == 0
    assert "coupled" in json.loads(out)["lateral"]


def test_sitl_and_ardupilot_fly_both_halves_on_unsteady_strips():
    """The SITL vehicle (the c172_elastic entering its loiter circle) and the ArduPilot
    backend's physics (the prototype) with span='full', aero='unsteady': the compiled
    full-span step, its modes and lag states moving with the roll."""
    from bioflex_jsb.definition.flying import flight_speeds
    from bioflex_jsb.drivers import ardupilot as ad
    from bioflex_jsb.drivers.sitl import (
        DEFAULT_HOME,
        DEFAULT_START_HEIGHT_M,
        SitlSim,
        sitl_airframe,
    )
    from bioflex_jsb.links import mavlink_modes as MODES

    ac = api.load_aircraft(C172)
    build = ac.wing()
    airframe, _ = sitl_airframe(ac, 57.8, DEFAULT_HOME[2] + DEFAULT_START_HEIGHT_M)
    sim = SitlSim(build, build.modes, speed_m_s=57.8, airframe=airframe, span="full",
                  aero="unsteady", airspeed_range_m_s=tuple(flight_speeds(ac)[1]))
    sim.vehicle.set_mode(MODES.CIRCLE)
    table = np.array([sim.step() for _ in range(int(round(0.5 / sim.dt_s)))])
    assert sim.stopped is None and sim.core.compiled
    rows = dict(zip(sim.names, table.T, strict=True))
    assert np.max(np.abs(rows["asym_eta1"])) > 0.0
    assert np.max(np.abs(sim.core.lateral.lag_states)) > 0.0
    prototype = api.load_aircraft(PROTOTYPE)
    ph = ad.ArduPilotPhysics(Airframe(), prototype.wing(), "coupled", span="full",
                             aero="unsteady", aileron=prototype.definition.aileron)
    assert ph.step_kind == "compiled kernel"
    armed_idle = (1500, 1500, 1050, 1500) + (0,) * 12  # fires the launcher
    while ph.phase != ad.FLIGHT:
        ph.step(armed_idle, 1200)
    for _ in range(100):
        ph.step(armed_idle, 1200)
    assert not ph.stops
    assert ph.summary()["step"] == "compiled kernel"


def test_the_log_records_both_halves_and_rerun_flies_them_again(capsys, tmp_path):
    """A gust log's run description holds --aero unsteady, --span full and the aileron
    step; rerun flies the same run again (the step is deterministic: rtol 1e-8)."""
    from bioflex_jsb.cli.rerun import argv_for
    from bioflex_jsb.simulation.run import RunDescription

    log = tmp_path / "run.mcap"
    code, _, _ = run_cli(capsys, "gust", "--span", "full", "--aero", "unsteady", "--models",
                         "coupled", "--aileron-step", "0.5", "--aileron-start", "0.1",
                         "--gust", "none", "--duration", "0.3", "--out", str(log), "--json")
    assert code == 0
    code, _, err = run_cli(capsys, "rerun", str(log), "--out", str(tmp_path / "again.mcap"))
    assert code == 0, err
    d = RunDescription("gust", "optimised", 15.0, models=("coupled",),
                       extra={"aero": "unsteady", "span": "full", "aileron_step": 0.5,
                              "aileron_start": 0.1, "aileron_width": 0.5})
    argv = dict(a.split("=", 1) for a in argv_for(d)[1:])
    assert argv["--span"] == "full" and float(argv["--aileron-step"]) == 0.5
    assert float(argv["--aileron-start"]) == 0.1 and argv["--aero"] == "unsteady"


def test_a_sitl_sessions_log_says_both_halves_and_the_step(tmp_path, monkeypatch, capsys):
    """bioflex-jsb sitl --span full --aero unsteady: the session flies (1 s, no ground
    station needed: udpout) and its log's description records the span, the strips and
    the step (compiled)."""
    import socket

    from bioflex_jsb import cli
    from bioflex_jsb.sinks.mcap import (
        RUN_METADATA,
        description_from_metadata,
        open_reader,
        read_metadata,
    )

    if "sitl" not in cli.COMMAND_MODULES:
        monkeypatch.setattr(cli, "COMMAND_MODULES", cli.COMMAND_MODULES + ("sitl",))
    listener = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)  # the "ground station"
    listener.bind(("127.0.0.1", 0))
    port = listener.getsockname()[1]
    out = tmp_path / "sitl.mcap"
    try:
        rc = cli.main(["sitl", "--aircraft", C172, "--span", "full", "--aero", "unsteady",
                       "--duration", "1", "--speedup", "4", "--out", str(out), "--mavlink",
                       f"udpout:127.0.0.1:{port}", "--json"])
    finally:
        listener.close()
    assert rc == 0
    assert json.loads(capsys.readouterr().out)["aero"] == "unsteady"
    with open_reader(str(out)) as (reader, _summary):
        d = description_from_metadata(read_metadata(reader)[RUN_METADATA])
    assert d.extra["span"] == "full" and d.extra["step"] == "compiled kernel"
    assert d.extra["aero"] == "unsteady"
