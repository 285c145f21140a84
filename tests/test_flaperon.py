"""Flaperons (aeroelasticity/flaperon.py, runtime/flaperon_step.py, loads/flaperon.py): both
ailerons down together as a controller's ``flaperon`` command [rad, trailing edges down].

Optimised wing at 15 m/s, the prototype's aileron (0.51-0.85 m of the 0.85 m semispan, hinge
at 75 % chord). Measured (the tolerances stand above these):

* derivatives: C_Lδf 0.9571 /rad, C_mδf −0.7156 /rad, C_δf^Q (−0.2925, 0.0646, 0.0676) /rad,
  the same to 1e-15 from the aileron analysis' strips (aeroelasticity/aileron.py);
* a 1° flaperon step at t = 0.1 s, 1 s flown, against the LTI model with the flaperon input
  (JSBSim's rigid block, the loads at the trim's air) fed the deflection the run flew: NRMSE
  η1 0.0055, α 0.0061, q 0.0065, root bending 0.0115, n_z 0.0146 (the run's n_z one step
  later: below);
* root-held lift effectiveness of the flaperon: reversal 12.332 m/s by the LTI model's modal
  rows and C_Lη and by the bordered eigenproblem of the strips (the two agree to 1e-9), the
  aileron's rolling-moment reversal 12.820 m/s (``api.aileron_effectiveness``); at the
  15 m/s cruise the flaperon's lift effectiveness is −0.245: it works reversed.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from bioflex_jsb import api
from bioflex_jsb.aeroelasticity import aileron as A
from bioflex_jsb.aeroelasticity.control_surface import (
    flap_lift_slope_per_rad,
    flap_moment_slope_per_rad,
    strip_coverage,
)
from bioflex_jsb.aeroelasticity.flaperon import (
    FLAPERON_LIMIT_RAD,
    flaperon_derivatives,
    lift_matrices,
)
from bioflex_jsb.drivers.gust import RunConfig, run_gust
from bioflex_jsb.errors import InputError
from bioflex_jsb.loads import alleviation as G
from bioflex_jsb.loads.alleviation import ROOT_BENDING
from bioflex_jsb.runtime.fdm import Airframe
from bioflex_jsb.runtime.flaperon_step import FlaperonLoads
from bioflex_jsb.simulation.full_span import prototype_aileron
from bioflex_jsb.simulation.gusts import parse_gust
from bioflex_jsb.simulation.modal_wing import DEFAULT_DT_S
from bioflex_jsb.simulation.results import nrmse

V = 15.0
ROOT = "loads_fs_bending_n_m_s0"
STEP_RAD = math.radians(1.0)
STEP_AT_S = 0.1
RHO_SEA_LEVEL = 1.225  # [kg/m³] ISA sea level: linear_model's and aileron_effectiveness' air


class FlaperonStep:
    """A Python controller: the flaperon stepped to ``delta_rad`` at ``t0_s``."""

    inputs = ("alpha",)
    outputs = ("flaperon",)

    def __init__(self, t0_s: float = STEP_AT_S, delta_rad: float = STEP_RAD) -> None:
        self.t0_s, self.delta_rad = t0_s, delta_rad

    def step(self, t_s, signals):
        return {"flaperon": self.delta_rad if t_s >= self.t0_s else 0.0}


@pytest.fixture(scope="module")
def wing():
    return api.load_wing("optimised")


@pytest.fixture(scope="module")
def surface(wing):
    return prototype_aileron(wing.variant.name)


@pytest.fixture(scope="module")
def step_run(wing):
    """1 s at 15 m/s in calm air with the flaperon stepped 1° at 0.1 s (the Python step)."""
    setup = RunConfig(V, parse_gust("none"), 1.0, STEP_AT_S, models=("coupled",))
    return run_gust(Airframe(), wing, "coupled", setup, loads=wing, compiled=False,
                    controller=FlaperonStep())


# -- the section and the strip integral ---------------------------------------------------
def _glauert(hinge: float) -> tuple[float, float]:
    """(c_l, c_m about the quarter chord) per radian of a flap hinged at ``hinge`` chord
    fractions, by thin-aerofoil theory integrated numerically: the camber line's slope
    dz/dx = −δ aft of the hinge (trailing edge down), x = ½ c (1 − cos θ), Glauert's
    A₀ = −(1/π) ∫ dz/dx dθ, A_n = (2/π) ∫ dz/dx cos nθ dθ over 0..π (α = 0), and
    c_l = π (2 A₀ + A₁), c_m,¼ = (π/4)(A₂ − A₁) (Anderson, *Fundamentals of
    Aerodynamics*, §4.8, Eqs. 4.50, 4.51, 4.64, 4.65)."""
    th = math.acos(1.0 - 2.0 * hinge)
    a0 = -quad(lambda t: -1.0, th, math.pi)[0] / math.pi
    a1, a2 = (2.0 / math.pi * quad(lambda t, n=n: -math.cos(n * t), th, math.pi)[0]
              for n in (1, 2))
    return math.pi * (2.0 * a0 + a1), 0.25 * math.pi * (a2 - a1)


@pytest.mark.parametrize("flap_chord", [0.05, 0.1, 0.2, 0.25, 0.3, 0.4, 0.5])
def test_section_slopes_are_glauerts(flap_chord):
    """c_lδ = 2 (π − θh + sin θh) and c_mδ = −½ sin θh (1 − cos θh) per flap chord
    fraction E against thin-aerofoil theory integrated afresh; E = 0.25 gives Houghton and
    Carpenter's 3.826 /rad (§4.5), and the effectiveness τ = c_lδ/2π grows with E."""
    hinge = 1.0 - flap_chord
    cl, cm = _glauert(hinge)
    assert flap_lift_slope_per_rad(hinge) == pytest.approx(cl, rel=1e-9)
    assert flap_moment_slope_per_rad(hinge) == pytest.approx(cm, rel=1e-9)
    if flap_chord == 0.25:
        assert flap_lift_slope_per_rad(hinge) == pytest.approx(3.826, abs=5e-4)
    if flap_chord > 0.05:
        assert flap_lift_slope_per_rad(hinge) > flap_lift_slope_per_rad(hinge + 0.05)


def test_flaperon_derivatives_are_the_strip_integral(wing, surface):
    """C_Lδf = (2/S) Σ w c a₀ τ χ over the aileron and C_δf^Q the strips' virtual work, by
    the aileron analysis' own strips (aeroelasticity/aileron.py: the lattice's C_lα c and
    Table B1's arm by another path) to round-off; the strips cover the aileron's 0.34 m
    exactly; the lift lies between the thin-aerofoil closed form 2 c c_lδ (y₂ − y₁)/S with
    the covered strips' least and greatest lift slope; the moment is nose down (the
    aileron lies aft of the CG)."""
    d = flaperon_derivatives(wing, surface)
    rs = A.flight_roll_strips(wing, surface)
    m = A.static_roll_matrices(rs)
    s, cbar = wing.airframe.reference.area_m2, wing.airframe.reference.mean_chord_m
    lift_delta = float(np.sum(rs.weights_m * rs.chord_m * rs.coverage * rs.flap_lift_per_rad))
    assert d.c_l_per_rad == pytest.approx(2.0 * lift_delta / s, rel=1e-12)
    assert np.allclose(d.c_q_per_rad, 2.0 * m.force_delta / (s * cbar), rtol=1e-12, atol=0)
    chi = strip_coverage(np.asarray(wing.aero.weights_m, float), surface)
    assert float(np.sum(chi * wing.aero.weights_m)) == pytest.approx(
        surface.end_m - surface.start_m, abs=1e-12)
    covered = rs.coverage > 0.0
    a0 = rs.lift_slope_per_rad[covered]
    closed = 2.0 * rs.chord_m[0] * flap_lift_slope_per_rad(surface.hinge) * (
        surface.end_m - surface.start_m) / s  # a₀ = 2π everywhere [1/rad]
    assert np.ptp(rs.chord_m) == 0.0  # the optimised wing is rectangular: c is one number
    assert closed * a0.min() / (2 * math.pi) < d.c_l_per_rad < closed * a0.max() / (2 * math.pi)
    assert d.c_l_per_rad == pytest.approx(0.9571, abs=1e-4)
    assert d.c_m_per_rad == pytest.approx(-0.7156, abs=1e-4)
    assert np.allclose(d.c_q_per_rad, [-0.2925, 0.0646, 0.0676], atol=1e-4)


def test_lti_flaperon_column(wing, surface):
    """The LTI model's flaperon input: the modes' η̈ rows Q S c̄ C_δf^Q / m_i, the α row the
    lift over m V (with the α̇ divisor, within a few % of it at 15 m/s), and the model
    without ``flaperon=True`` unchanged."""
    ss = api.linear_model(wing, V, flaperon=True)
    plain = api.linear_model(wing, V)
    assert ss.inputs == plain.inputs + ("flaperon",)
    assert np.array_equal(ss.a, plain.a) and np.array_equal(ss.b[:, :-1], plain.b)
    d = flaperon_derivatives(wing, surface)
    n = (ss.n_states - 4) // 2
    q = 0.5 * RHO_SEA_LEVEL * V**2
    s, cbar = d.area_m2, d.chord_m
    m = np.asarray(wing.model.generalised_masses_kg_m2, float)
    col = ss.b[:, -1]
    assert np.allclose(col[4 + n:], q * s * cbar * d.c_q_per_rad / m, rtol=1e-12)
    mass = wing.airframe.mass.mass_kg
    z_alpha = -q * s * d.c_l_per_rad / (mass * V)  # α̇ = Z/(m V) without the α̇ divisor
    assert col[ss.states.index("alpha")] == pytest.approx(z_alpha, rel=0.05)


# -- the nonlinear step against the LTI model ---------------------------------------------
def test_flaperon_step_follows_the_lti_model(wing, step_run):
    """A 1° step, the run against the LTI model (api._gla_plant with the flaperon: Eq. 4,
    JSBSim's rigid block, the loads) driven by the deflection the run flew
    (``flaperon_rad``, zero-order hold at the run's step). NRMSE bounds over the measured
    (module docstring) by about 2×: η1 0.0055, α 0.0061, q 0.0065, root bending 0.0115.
    n_z: the run's row k holds the acceleration of the forces that acted over the step into
    it, the LTI's D term the same sample's, so the run is compared one step later (0.0146;
    unshifted 0.077, the step's jump one sample off)."""
    run = step_run
    assert run.stopped is None
    _, _, plant = api._gla_plant(wing, V, flaperon=True)
    dis = plant.to_discrete(DEFAULT_DT_S)
    u = np.asarray(run["flaperon_rad"], float)
    j = plant.inputs.index("flaperon")
    x = np.zeros(dis.a.shape[0])
    ys = np.empty((len(u), len(plant.outputs)))
    for k, uk in enumerate(u):
        ys[k] = dis.c @ x + dis.d[:, j] * uk
        x = dis.a @ x + dis.b[:, j] * uk
    bounds = {"eta1": 0.012, "alpha": 0.013, "q": 0.013, ROOT_BENDING: 0.025}
    for out, bound in bounds.items():
        lti = ys[:, plant.outputs.index(out)]
        if out == ROOT_BENDING:
            nl = run[ROOT] - run.meta["loads"]["static_1g"][ROOT]
        else:
            nl = run[out] - run[out][0]
        assert nrmse(lti, nl) < bound, out
        assert np.abs(lti).max() > 0.0
    nz = run["n_z"] - run["n_z"][0]
    lti_nz = ys[:, plant.outputs.index("n_z")]
    assert nrmse(lti_nz[:-1], nz[1:]) < 0.03
    # the flaperon down lifts at once, ΔL = Q S C_Lδf δf (the reactions of the command's
    # row: 0.716 N), and the root bends up; within ~7 ms the wing's nose-down twist takes
    # more lift off than the flap adds (reversed at 15 m/s): the root bending settles below
    # the trim's (measured −0.13 N·m at 0.9 s against +0.19 N·m at 2 ms), as the LTI's does
    d = flaperon_derivatives(wing, prototype_aileron(wing.variant.name))
    k0 = int(np.argmax(run["ctrl_flaperon_rad"] > 0.0))
    q = 0.5 * RHO_SEA_LEVEL * run["airspeed_m_s"][k0] ** 2
    jump = run["lift_n"][k0] - run["lift_n"][k0 - 1]
    assert jump == pytest.approx(q * d.area_m2 * d.c_l_per_rad * STEP_RAD, rel=2e-3)
    root = run[ROOT] - run.meta["loads"]["static_1g"][ROOT]
    assert root[k0 + 2] > 0.1
    lti_root = ys[:, plant.outputs.index(ROOT_BENDING)]
    assert root[-1] < -0.05 and lti_root[-1] < -0.05


# -- reversal --------------------------------------------------------------------------------
def _lti_lift_effectiveness(wing, v: float) -> float:
    """The flaperon's lift over its rigid lift, root held (α, q frozen), by the LTI model:
    the modes' static deflection η = −A_ηη⁻¹ b_δf and C_L = C_Lδf + C_Lη·η."""
    ss = api.linear_model(wing, v, flaperon=True)
    n = (ss.n_states - 4) // 2
    eta = -np.linalg.solve(ss.a[4 + n:, 4:4 + n], ss.b[4 + n:, -1])
    c_l = ss.notes["flaperon"]["c_l_per_rad"]
    return 1.0 + float(np.asarray(wing.model.coefficients.c_l_eta, float) @ eta) / c_l


def test_reversal_against_the_aileron(wing, surface):
    """The flaperon reverses where the wing's lift per δf vanishes, the aileron where its
    rolling moment Σ w y L' does: the same structure, strips and section data, but the
    aileron's weighting by y. They need not match: a flaperon outboard (its lift's centroid
    0.68 m out) loses lift to the flap's nose-down twist with the twist's lift unweighted,
    so it reverses first (12.33 m/s against the aileron's 12.82 m/s). Its reversal speed by
    the LTI model (brentq on the root-held effectiveness) is the bordered eigenproblem's of
    the aileron analysis with the rolling moment's y dropped (flaperon.lift_matrices; to
    1e-6: independent codes)."""
    v_lti = brentq(lambda v: _lti_lift_effectiveness(wing, v), 5.0, 20.0, xtol=1e-8)
    lift = lift_matrices(wing, surface)
    v_eig = math.sqrt(2.0 * lift.reversal_dynamic_pressure_pa() / RHO_SEA_LEVEL)
    assert v_lti == pytest.approx(v_eig, rel=1e-6)
    assert v_lti == pytest.approx(12.332, abs=0.005)
    aileron = api.aileron_effectiveness(wing, aileron=surface).as_dict()
    assert aileron["density_kg_m3"] == RHO_SEA_LEVEL
    assert aileron["reversal_speed_m_s"] == pytest.approx(12.820, abs=0.005)
    assert v_lti < aileron["reversal_speed_m_s"] < V  # both reversed at the cruise speed
    assert _lti_lift_effectiveness(wing, V) == pytest.approx(-0.245, abs=0.005)
    q_cruise = 0.5 * RHO_SEA_LEVEL * V**2
    assert lift.effectiveness(q_cruise) == pytest.approx(_lti_lift_effectiveness(wing, V),
                                                         rel=1e-6)


# -- logging, the step asked for, refusals -----------------------------------------------------
def test_channels_are_logged(wing, surface, step_run):
    """The command (ctrl_flaperon_rad) and the deflection flown (flaperon_rad: the previous
    row's command, within the ±10° travel), both in rad; the reactions carry its lift."""
    run = step_run
    for name in ("ctrl_flaperon_rad", "flaperon_rad"):
        assert name in run.channels and run.units[name] == "rad"
    cmd, flown = run["ctrl_flaperon_rad"], run["flaperon_rad"]
    k0 = int(np.argmax(cmd > 0.0))
    assert cmd[k0] == STEP_RAD and np.all(cmd[:k0] == 0.0)
    assert np.array_equal(flown[1:], cmd[:-1]) and flown[0] == 0.0
    fl = FlaperonLoads(flaperon_derivatives(wing, surface), 0.0)
    fl.set_command(math.radians(25.0))
    assert fl.command_rad == FLAPERON_LIMIT_RAD == pytest.approx(math.radians(10.0))


def test_the_log_holds_the_flaperon_command(wing, tmp_path):
    """/bioflex/<model>/controller carries flaperon_cmd_rad; read_log gives it back as the
    run's ctrl_flaperon_rad to the bit (the elevator not commanded: absent)."""
    from bioflex_jsb.simulation.run import RunDescription
    from bioflex_jsb.sinks.mcap import RunLog

    path = tmp_path / "flap.mcap"
    desc = RunDescription("gust", "optimised", V, gust="none", models=("coupled",),
                          duration_s=0.2, gust_start_s=STEP_AT_S)
    log = RunLog.open(path, desc, wing_variant=wing.variant.as_dict())
    try:
        run = api.fly_gust(wing, V, "none", models=("coupled",), duration_s=0.2,
                           gust_start_s=STEP_AT_S, recorders={"coupled": log.recorder("coupled")},
                           controller=FlaperonStep())["coupled"]
    finally:
        log.close()
    back = api.read_log(path)["coupled"]
    assert np.array_equal(back["ctrl_flaperon_rad"], run["ctrl_flaperon_rad"])
    assert back["ctrl_flaperon_rad"].max() == STEP_RAD
    assert "ctrl_elevator_rad" not in back.channels
    assert back.meta["controller"]["channels"] == ["ctrl_flaperon_rad"]
    # the surface flown is recorded, so the log's section loads carry the flap's own: the
    # root bending from the log read back equals the run's (the deflection from the command
    # one row later, as the runtime flies it)
    assert back.meta["flaperon"]["surface"] == run.meta["flaperon"]["surface"]

    def bending(r):
        return api.section_loads(wing, r).values["force_summation"][:, 1, 0]

    assert np.abs(bending(back) - bending(run)).max() < 1e-9  # N·m; measured 0


@pytest.mark.parametrize("text, needle", [
    ("[1", "is not JSON"),
    ('{"surface": 3}', "no surface with a name"),
    ('{"surface": {"name": "aileron", "start_m": 0.5, "end_m": 0.2, '
     '"hinge_chord_fraction": 0.75}}', "start < end"),
    ('{"surface": {"name": "aileron", "start_m": 0.2, "end_m": 0.5, '
     '"hinge_chord_fraction": "x"}}', "no surface with a name"),
])
def test_a_damaged_flaperon_record_is_one_line(text, needle):
    from bioflex_jsb.sinks.mcap.history import _flaperon_meta
    from bioflex_jsb.sinks.mcap_io.errors import LogError

    with pytest.raises(LogError, match=needle) as err:
        _flaperon_meta(text)
    assert "\n" not in str(err.value)


# The compiled step against the Python one it is tested against (tests/test_step_kernel.py,
# KERNEL_RTOL_OF_RANGE: the same arithmetic, the last digits of a sum apart). Measured on
# these cases: at most 4.8e-14 of a channel's range on the half wing (coupled; qsd 5.6e-15,
# rigid 1.8e-15), 6.9e-13 on both halves, 8.3e-13 with the tip IMU's controller (both
# v_north_m_s).
KERNEL_RTOL_OF_RANGE = 1e-9


@pytest.mark.parametrize("model", ["coupled", "qsd", "rigid"])
@pytest.mark.parametrize("which", ["step", "gla_flaperon_optimised"])
def test_compiled_and_python_steps_agree_with_a_flaperon(wing, model, which):
    """A flaperon controller flies the compiled step (no warning: warnings are errors here)
    and its every channel is the Python step's to 1e-9 of its range: the 1° flaperon step
    and the shipped elevator + flaperon controller through 1cos:0.3:2.08 (the flaperon's
    forcing of the modes, its loads in lift_n, drag_n, pitch_moment_n_m and the reactions,
    flaperon_rad one row behind the command)."""
    from tests.golden_cases import compare_runs

    setup = RunConfig(V, parse_gust("1cos:0.3:2.08"), 1.2, STEP_AT_S, models=(model,))
    runs = []
    for compiled in (True, False):
        ctrl = FlaperonStep() if which == "step" else api.load_controller(which)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            runs.append(run_gust(Airframe(), wing, model, setup, loads=wing,
                                 compiled=compiled, controller=ctrl))
    fast, slow = runs
    assert fast.stopped is None and slow.stopped is None
    assert "step_note" not in fast.meta
    worst = compare_runs(slow, fast)
    assert max(worst.values()) < KERNEL_RTOL_OF_RANGE, worst
    assert np.abs(fast["ctrl_flaperon_rad"]).max() > 0.0  # the flaperon moved
    assert np.array_equal(fast["flaperon_rad"][1:], fast["ctrl_flaperon_rad"][:-1])


def test_a_sensor_fed_flaperon_flies_the_compiled_step_as_the_python_one(wing):
    """A linear flaperon gain on the wing tip's a_z (tests/test_controller_sensors.py's
    stations, noise included): the sensor channels are written before the controller and
    the flaperon's loads after it on the compiled step as on the Python one; every channel
    within 1e-9 of its range."""
    from bioflex_jsb.simulation.controller import LinearController
    from tests.golden_cases import compare_runs
    from tests.test_controller_sensors import DT, TIP_AZ, _sensors

    gain = LinearController.from_arrays(None, None, None, [[0.003]], DT, [TIP_AZ],
                                        ["flaperon"], "tip_az_flap")
    setup = RunConfig(V, parse_gust("1cos:1:2"), 0.3, 0.05, 0.0, DT, models=("coupled",))
    fast, slow = (run_gust(Airframe(), wing, "coupled", setup, compiled=c,
                           sensors=_sensors(wing, noise=True), loads=wing, controller=gain)
                  for c in (True, False))
    worst = compare_runs(slow, fast)
    assert max(worst.values()) < KERNEL_RTOL_OF_RANGE, worst
    assert np.abs(fast["ctrl_flaperon_rad"]).max() > 0.0 and TIP_AZ in fast.channels


def test_both_halves_fly_the_flaperon_on_the_compiled_step(wing):
    """span='full': the full-span kernel steps the half wing with the half wing's kernel,
    flaperon block included; the 1° step agrees with the Python step to 1e-9 of each
    channel's range, and the step flown is the compiled one."""
    from bioflex_jsb.runtime.coupled_step import CoupledStep
    from tests.golden_cases import compare_runs

    setup = RunConfig(V, parse_gust("1cos:0.3:2.08"), 0.6, STEP_AT_S, models=("coupled",))
    fast, slow = (run_gust(Airframe(), wing, "coupled", setup, compiled=c, span="full",
                           controller=FlaperonStep()) for c in (True, False))
    worst = compare_runs(slow, fast)
    assert max(worst.values()) < KERNEL_RTOL_OF_RANGE, worst
    assert np.abs(fast["lift_n"]).max() > 0.0
    step = CoupledStep(Airframe(), wing, "coupled", V, span="full", controller=FlaperonStep())
    assert step.compiled and step.lateral is not None


def test_refusals_are_one_line(wing):
    """What cannot carry a flaperon is one line (InputError): a wing without its build's
    strips (a bare flight model), the unsteady strips; linear_model's flaperon only on the
    quasi-steady coupled model."""
    setup = RunConfig(V, parse_gust("none"), 0.05, 0.01, models=("coupled",))
    with pytest.raises(InputError, match="needs the Python modal wing and its build"):
        run_gust(Airframe(), wing.model, "coupled", setup, compiled=False,
                 controller=FlaperonStep())
    with pytest.raises(InputError, match="flaperon=True is the quasi-steady coupled model"):
        api.linear_model(wing, V, model="qsd", flaperon=True)
    with pytest.raises(InputError, match="no aileron"):
        flaperon_derivatives(wing, None)


def test_compare_closes_the_loop_with_the_flaperon(wing):
    """``compare`` with a linear flaperon controller (δf = 0.5 Δα): the LTI model takes the
    flaperon input of the surface the run flew (``meta["flaperon"]``) and its strips'
    loads. 1cos:0.3:2.08 at 15 m/s, measured NRMSE α 0.0035, q 0.0076, η1 0.0078, the
    command 0.0035, root bending 0.0046; bounds about 2× above."""
    from bioflex_jsb.simulation.controller import LinearController

    k = LinearController.from_arrays(None, None, None, [[0.5, 0.0]], 0.0, ["alpha", "q"],
                                     ["flaperon"], "flap")
    r = api.compare(wing, V, "1cos:0.3:2.08", controller=k)
    bounds = {"alpha": 0.008, "q": 0.015, "eta1": 0.016, "ctrl_flaperon_rad": 0.008,
              ROOT: 0.01}
    for name, bound in bounds.items():
        assert r.nrmse[name] < bound, name


# -- gust load alleviation with both surfaces -----------------------------------------------
@pytest.fixture(scope="module")
def gla_both(wing):
    """The shipped elevator + flaperon controller and its LTI prediction."""
    ctrl = api.load_controller("gla_flaperon_optimised")
    return ctrl, api.predict_alleviation(wing, ctrl, V)


def test_shipped_two_surface_controller(gla_both):
    """gla_flaperon_optimised (scripts/design_gla_flaperon.py: δe = 2.083 Δα + 0.205 q,
    δf = 0.025 Δα + 0.027 q): its prediction is its notes' (tuned 0.9323, RMS 0.9000), its
    commands within the design's limits (elevator 10°, flaperon 8°). With the flaperon
    reversed at 15 m/s the design finds little use for it: its tuned ratio is no better
    than the elevator-only gla_optimised's 0.9276 (docs/loads.md), the RMS 0.900 against
    0.907."""
    ctrl, pred = gla_both
    assert ctrl.outputs == ("elevator", "flaperon")
    notes = ctrl.system.notes
    assert pred.tuned_ratio == pytest.approx(notes["predicted_tuned_ratio"], abs=1e-4)
    assert pred.rms_ratio == pytest.approx(notes["predicted_rms_ratio"], abs=1e-4)
    assert pred.tuned_ratio == pytest.approx(0.9323, abs=1e-3)
    assert pred.tuned_ratio > 0.9276
    assert pred.rms_ratio == pytest.approx(0.9000, abs=1e-3)


@pytest.mark.slow
def test_two_surface_tuned_gust_nonlinear_gives_the_prediction(wing, gla_both):
    """Every tuned gradient flown open and closed with elevator and flaperon: measured
    nonlinear tuned ratio 0.9298 against the LTI's 0.9323, per gradient within 0.0148; the
    elevator-only controller, the same way, 0.9246 against 0.9276 (tests/test_gla.py).
    Tolerances those of tests/test_gla.py; the flaperon's command peaks 0.34-0.89°, within
    its 8° design limit. Slow: 20 open and closed runs, 2.3 s on a 2-core machine (7.0 s
    with the closed runs on the Python step, compiled=False)."""
    ctrl, pred = gla_both
    airframe = Airframe()
    peaks, flap = [], []
    for c in G.tuned_cases(V, api._gla_gradients(wing, V)):
        setup = RunConfig(V, parse_gust(c["gust"]), c["duration_s"], c["gust_start_s"],
                          models=("coupled",))
        row = []
        for k in (None, ctrl):
            run = run_gust(airframe, wing, "coupled", setup, loads=wing, controller=k)
            assert run.stopped is None
            row.append(np.abs(run[ROOT] - run.meta["loads"]["static_1g"][ROOT]).max())
        flap.append(np.abs(run["ctrl_flaperon_rad"]).max())
        peaks.append(row)
    peaks = np.array(peaks)
    tuned = peaks[:, 1].max() / peaks[:, 0].max()
    assert tuned == pytest.approx(pred.tuned_ratio, abs=0.01)
    assert np.abs(peaks[:, 1] / peaks[:, 0] - pred.peak_ratios).max() < 0.025
    assert 0.0 < max(flap) < math.radians(8.0)


def test_cli_flies_the_flaperon(capsys, tmp_path, monkeypatch):
    """``gust --controller gla_flaperon_optimised``: the build's strips flown (the CLI
    otherwise flies the bare flight model) on the compiled step, nothing on stderr, the
    flaperon's peak in the summary; the unsteady strips refused in one line (exit 2)."""
    from tests.cli_helpers import assert_one_line_error, run_cli

    monkeypatch.chdir(tmp_path)  # its figure
    code, out, err = run_cli(capsys, "gust", "--models", "coupled", "--duration", "1",
                             "--gust", "1cos:1:2", "--controller", "gla_flaperon_optimised",
                             "--no-log")
    assert code == 0, err
    assert not err.strip()  # the compiled step flies it: nothing to say
    assert "ctrl_flaperon_rad peak" in out
    code, _, err = run_cli(capsys, "gust", "--models", "coupled", "--aero", "unsteady",
                           "--duration", "1", "--controller", "gla_flaperon_optimised",
                           "--no-log")
    assert_one_line_error(code, err, "the unsteady wing has no flap terms")


def test_section_loads_after_the_run_carry_the_flaperon(wing, step_run):
    """``api.section_loads`` of a flaperon run gives the streamed root bending to round-off
    (measured 2e-15 N·m; without the flap's strip loads it would be off by 0.19 N·m of a
    0.24 N·m peak), from ``flaperon_rad`` or, as a log read back keeps it, from the command
    one row later; a run that moved a flaperon without recording its surface is refused in
    one line."""
    import copy

    def bending(run):
        return api.section_loads(wing, run).values["force_summation"][:-1, 1, 0]

    streamed = step_run[ROOT][:-1]
    assert np.abs(bending(step_run) - streamed).max() < 1e-9
    run = copy.copy(step_run)
    run.channels = {k: v for k, v in step_run.channels.items() if k != "flaperon_rad"}
    assert np.abs(bending(run) - streamed).max() < 1e-9
    run.meta = {k: v for k, v in step_run.meta.items() if k != "flaperon"}
    with pytest.raises(InputError, match="does not record"):
        bending(run)


@pytest.mark.slow
def test_two_surface_turbulence_rms_nonlinear_gives_the_prediction(wing, gla_both):
    """60 s of von Kármán turbulence (seed 1), open and closed with both surfaces: the RMS
    ratio of the root bending moment over 0.25-150 Hz, measured 0.8982 against the LTI's
    0.9000 (elevator only, the same way: 0.9077 against 0.9069); within 0.03 as
    tests/test_gla.py. About 3.3 s on a 2-core machine, both runs on the compiled step (8.7 s
    with the closed run on the Python step, compiled=False)."""
    from bioflex_jsb.loads.spectral import compare_spectra

    ctrl, pred = gla_both
    kind, sigma, scale = G.TURBULENCE
    setup = RunConfig(V, parse_gust(f"{kind}:{sigma:g}:{scale:g}:1"), 60.0, 0.5,
                      models=("coupled",))
    _, _, plant = api._gla_plant(wing, V)
    rms = []
    for k in (None, ctrl):
        run = run_gust(Airframe(), wing, "coupled", setup, loads=wing, controller=k)
        assert run.stopped is None
        x = (run[ROOT] - run.meta["loads"]["static_1g"][ROOT])[int(round(1.0 / DEFAULT_DT_S)):]
        sc = compare_spectra(plant, [G.ROOT_BENDING], ["N*m"], x[:, None], DEFAULT_DT_S,
                             kind=kind, sigma_m_s=sigma, scale_m=scale, speed_m_s=V)
        rms.append(float(sc.run_rms_band[0]))
    assert rms[1] / rms[0] == pytest.approx(pred.rms_ratio, abs=0.03)


def test_a_sweep_case_flies_the_flaperon(tmp_path):
    """A campaign's ``controllers`` axis with gla_flaperon_optimised: the case flies the
    build's strips (it flew the bare flight model) and its log reads back the flaperon's
    command."""
    import tomllib

    from bioflex_jsb.sweep.campaign import parse_campaign
    from bioflex_jsb.sweep.evaluate import run_case
    from tests.test_sweep_controller import BASE

    (case,) = parse_campaign(tomllib.loads(
        BASE + 'controllers = ["gla_flaperon_optimised"]\n')).cases()
    row = run_case(case, str(tmp_path))
    assert row["status"] == "ok", row["error"]
    back = api.read_log(tmp_path / f"{case.case_id}.mcap")["coupled"]
    assert np.abs(back["ctrl_flaperon_rad"]).max() > 0.0
