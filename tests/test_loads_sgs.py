"""Section loads of another aircraft's wing (issue 24): JSBSim's SGS glider with its
modes-file wing (``data/aircraft/sgs_elastic.toml``). The loads model takes the wing's own
planform, lattice and airframe; its inertia per span is fitted to the modes file's
generalised masses (a modes file has no mass distribution, EI or GJ: mode displacement is
absent, said why). Checks: the fit against the beam the modes were made from
(``sgs_wing.toml``), the 1 g root bending moment by hand, the static part against the
elastic trim, a gust run's loads in its MCAP loads topic."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from bioflex_jsb import api
from bioflex_jsb.definition.clamped import beam_sections
from bioflex_jsb.definition.loader import load_definition
from bioflex_jsb.errors import InputError
from bioflex_jsb.flight_dynamics.elastic_trim import elastic_trim
from bioflex_jsb.loads.model import (
    MODAL_MASS_FIT_TOLERANCE,
    QUANTITIES,
    build_loads_model,
    modal_mass_sections,
    signal_names,
)
from bioflex_jsb.parameters import prototype as P
from tests.cli_helpers import run_cli
from tests.tools import channel_metadata, decode_topic

G = P.STANDARD_GRAVITY_M_S2
IV, IM, IT = (QUANTITIES.index(q) for q in QUANTITIES)
SPEED_M_S = 25.0  # the SGS definition's cruise speed


@pytest.fixture(scope="module")
def sgs():
    return api.load_aircraft("sgs_elastic").wing()


@pytest.fixture(scope="module")
def beam():
    """The beam the SGS modes file was made from (its header says so)."""
    from pathlib import Path

    return beam_sections(load_definition(
        Path(api.__file__).resolve().parent / "data" / "aircraft" / "sgs_wing.toml"))


def test_the_fitted_inertia_is_the_beams(sgs, beam):
    """Uniform m', I' fitted to the three generalised masses: the beam's 7.0 kg/m within
    1e-3 (measured 7.0045: the fit integrates the file's shapes linearly between its 41
    stations, the beam's elements are Hermite cubics: 7.4e-4 of modes 1 and 3's masses) and
    its 0.4375 kg·m within 1e-6 (mode 2 is pure twist, linear in the beam too: measured
    2.6e-8); the centres of mass and elastic axes coincide (38 % chord): S' = 0."""
    ms = modal_mass_sections(sgs)
    np.testing.assert_allclose(ms.mass_per_length_kg_m, beam.mass_per_length_kg_m[0],
                               rtol=1e-3)
    np.testing.assert_allclose(ms.torsional_inertia_kg_m, beam.torsional_inertia_kg_m[0],
                               rtol=1e-6)
    np.testing.assert_array_equal(beam.mass_per_length_kg_m, beam.mass_per_length_kg_m[0])
    assert ms.half_wing_mass_kg == pytest.approx(beam.half_wing_mass_kg, rel=1e-3)
    np.testing.assert_array_equal(ms.static_moment_kg, 0.0)
    assert "fitted to the modes file" in ms.source


def test_a_wing_whose_mass_is_not_uniform_is_refused(sgs):
    """Doubling mode 3's generalised mass leaves no uniform m' that gives both bending
    modes' (measured: mode 1 missed by 50 %): one line, InputError (a gust run says why
    it has no loads)."""
    masses = sgs.modes.generalised_masses_kg_m2.copy()
    masses[2] *= 2.0
    wrong = replace(sgs, modes=replace(sgs.modes, generalised_masses_kg_m2=masses))
    with pytest.raises(InputError, match="mass is not uniform") as err:
        modal_mass_sections(wrong)
    assert "\n" not in str(err.value) and f"{100 * MODAL_MASS_FIT_TOLERANCE:g} %" in str(
        err.value)


def _weight_moment_n_m(ms) -> float:
    """g ∫ m' y dy of the half wing, uniform m': g m' (b/2)² / 2."""
    half = float(ms.stations_m[-1])
    return float(G * ms.mass_per_length_kg_m[0] * half**2 / 2.0)


def test_one_g_root_bending_is_half_lift_times_centroid_less_wing_weight(sgs):
    """Rigid 1 g level trim at 25 m/s: M_root = L_half ȳ_L − g ∫ m' y dy, ȳ_L the lift
    centroid of a four times finer lattice (160 strips, each strip's load at its middle) on
    the wing's own planform (7.036 m semispan, 1 m chord). The lattice's resolution: the
    centroid of the wing's 40 strips is 3.2385198 m, of 160 strips 3.2385194 m (1.3e-7
    relative, measured), so the tolerance is 1e-6 of the lift moment. L_half is the lift
    the model's strips carry at α_w = C_L/C_Lα,w (the co-simulation's, modal_matrices.py),
    C_Lα,w on the airframe's S as C_L is (flight_dynamics/wing_model.py; the lattice's own is
    on its planform's 14.072 m² against SGS.xml's 13.073 m²): the wing carries W/2 (before
    that conversion 1.0764 × W/2). The root shear is L_half − m_half g to rounding."""
    from bioflex_jsb.aerodynamics.vortex_lattice import solve_spanwise_aerodynamics

    lm = build_loads_model(sgs, SPEED_M_S, static="rigid")
    assert lm.md_matrix is None and "EI and GJ" in lm.md_unavailable
    fs = lm.static_loads()["force_summation"]
    assert set(lm.static_loads()) == {"force_summation"}
    fine = solve_spanwise_aerodynamics(sgs.planform, n_spanwise=160)
    lift = fine.weights_m * fine.cl_alpha_c_m_per_rad
    centroid = float(lift @ (0.5 * (fine.edges_m[1:] + fine.edges_m[:-1])) / lift.sum())
    half_lift = lm.dynamic_pressure_pa * lm.alpha_wing_rad * float(lift.sum())
    weight = sgs.airframe.mass.mass_kg * G
    assert half_lift == pytest.approx(weight / 2.0, rel=1e-6)
    ms = modal_mass_sections(sgs)
    hand = half_lift * centroid - _weight_moment_n_m(ms)
    assert fs[IM, 0] == pytest.approx(hand, rel=1e-6 * half_lift * centroid / hand)
    # the shear: the wing's own 40 strips' lift (the fine lattice's is 7e-7 more) less the
    # half wing's weight, exact sums
    own = lm.dynamic_pressure_pa * lm.alpha_wing_rad * float(
        sgs.aero.weights_m @ sgs.aero.cl_alpha_c_m_per_rad)
    assert fs[IV, 0] == pytest.approx(own - G * ms.half_wing_mass_kg, rel=1e-9)
    # the glider's wing weight relieves its root by a third: the check sees it
    assert _weight_moment_n_m(ms) > 0.3 * hand


def test_a_pure_load_factor_is_the_wings_weight(sgs):
    """z = g n_z alone: root shear −m_half g and bending −g m' (b/2)²/2 (uniform m';
    the cells' midpoint rule exact for the linear moment arm), torque 0 (S' = 0)."""
    lm = build_loads_model(sgs, SPEED_M_S, static="rigid")
    names = signal_names(lm.n_modes)
    z = np.zeros(len(names))
    z[names.index("g*n_z")] = G
    loads = lm.force_summation(z).reshape(3, -1)
    ms = modal_mass_sections(sgs)
    assert loads[IV, 0] == pytest.approx(-G * ms.half_wing_mass_kg, rel=1e-9)
    assert loads[IM, 0] == pytest.approx(-_weight_moment_n_m(ms), rel=1e-9)
    assert loads[IT, 0] == 0.0


def test_static_part_equals_the_elastic_trim(sgs):
    """The static part is the elastic trim's (``trim --aircraft sgs_elastic`` prints it):
    the same η₀; the generalised forces of its aerodynamic loads balance the structure,
    m_i ω_i² η₀_i, within the quadrature difference of the 2 mm cells against the strips'
    control stations (measured 5.3e-5, 2.3e-4, 6.6e-5 relative for modes 1-3: tolerance
    5e-4); the half wing's lift of η₀ is the trim's C_Lη η₀ Q S / 2 to rounding."""
    trim = elastic_trim(sgs, SPEED_M_S)
    lm = build_loads_model(sgs, SPEED_M_S)
    np.testing.assert_array_equal(lm.static_eta_rad, trim.eta_rad)
    z = lm.static_signals()
    modes = sgs.modes
    balance = modes.generalised_masses_kg_m2 * modes.frequencies_rad_s**2 * trim.eta_rad
    np.testing.assert_allclose(lm.generalised_aero_force(z), balance, rtol=5e-4)
    n = lm.n_modes
    z_eta = np.zeros_like(z)
    z_eta[2:2 + n] = z[2:2 + n]
    lift_eta = lm.force_summation(z_eta, "aero").reshape(3, -1)[IV, 0]
    assert lift_eta == pytest.approx(trim.loads.lift_n / 2.0, rel=1e-10)


def test_a_gust_runs_loads_are_in_its_log(tmp_path, capsys):
    """``gust --aircraft sgs_elastic``: every model reports force summation (no mode
    displacement: the modes file has no EI, GJ) and its log's ``/bioflex/<model>/loads``
    topic holds them: the topic's peaks are the metrics' (to the bit), its 1 g values the
    loads model's at the run's own density."""
    out = tmp_path / "sgs.mcap"
    code, text, _ = run_cli(capsys, "gust", "--aircraft", "sgs_elastic", "--gust",
                            "1cos:2:25", "--duration", "1.5", "--out", str(out), "--json")
    assert code == 0
    summary = json.loads(text)["summary"]
    for model in ("rigid", "coupled", "qsd"):
        loads = summary[model]["loads"]
        assert list(loads["methods"]) == ["force_summation"], loads.get("unavailable")
        meta = channel_metadata(out, f"/bioflex/{model}/loads")
        assert meta["methods"] == "force_summation"
        msgs = decode_topic(out, f"/bioflex/{model}/loads")
        assert len(msgs) == round(1.5 / api.DEFAULT_DT_S)
        t = np.array([ns for ns, _ in msgs]) * 1e-9
        bending = np.array([list(m.fs_bending_n_m) for _, m in msgs])
        assert np.array([list(m.md_bending_n_m) for _, m in msgs]).size == 0
        root = loads["methods"]["force_summation"]["bending_n_m"][0]
        after = t >= 0.5 - 1e-9
        assert float(np.max(bending[after, 0])) == root["max"]
        assert float(np.min(bending[after, 0])) == root["min"]
        lm = build_loads_model(api.load_aircraft("sgs_elastic").wing(), SPEED_M_S,
                               density_kg_m3=float(meta["density_kg_m3"]),
                               static="rigid" if model == "rigid" else "elastic")
        static = json.loads(meta["static_1g"])
        np.testing.assert_allclose(static["fs_bending_n_m"],
                                   lm.static_loads()["force_summation"][IM], rtol=1e-12)
        # the 2 m/s upward gust raises the root bending moment by a tenth at least
        assert root["increment_up"] > 0.1 * root["static_1g"]


def _sgs_with_stations(tmp_path, stations: str):
    """A copy of the shipped SGS definition with ``[loads] stations = <stations>``."""
    import shutil
    from pathlib import Path

    data = Path(api.__file__).resolve().parent / "data" / "aircraft"
    shutil.copy(data / "sgs_elastic_modes.toml", tmp_path / "sgs_elastic_modes.toml")
    text = (data / "sgs_elastic.toml").read_text(encoding="utf-8")
    path = tmp_path / "sgs_stations.toml"
    path.write_text(text + f"\n[loads]\nstations = {stations}\n", encoding="utf-8")
    return path


def test_the_definitions_stations_reach_every_run(tmp_path, capsys):
    """``[loads] stations`` of a definition on its own JSBSim aircraft: the gust run's loads
    (api.fly_gust, ``gust``) and ``loads`` are at those stations. Before, runs of another
    airframe reported the default root/25/50/75 % silently, and ``loads --aircraft``
    refused every airframe but the prototype's."""
    path = _sgs_with_stations(tmp_path, "[0.0, 0.1, 0.2]")
    aircraft = api.load_aircraft(path)
    assert aircraft.wing().monitoring_stations == (0.0, 0.1, 0.2)
    run = api.fly_gust(aircraft, gust="1cos:1:25", models=("rigid",), duration_s=0.5,
                       gust_start_s=0.1)["rigid"]
    assert run.meta["loads"]["station_fractions"] == [0.0, 0.1, 0.2]
    assert run.meta["loads"]["stations_m"] == pytest.approx([0.0, 0.7036, 1.4072], rel=1e-12)
    code, out, _ = run_cli(capsys, "loads", "--aircraft", str(path), "--gust", "1cos:1:25",
                           "--duration", "1", "--json")
    assert code == 0
    data = json.loads(out)
    assert data["speed_m_s"] == SPEED_M_S  # the aircraft's cruise speed, not 15 m/s
    assert data["loads"]["station_fractions"] == [0.0, 0.1, 0.2]
    # --tuned takes this airframe (tests/test_loads_aircraft.py) and its own chord: a
    # gradient whose gust is shorter than it is refused in one line
    code, _, err = run_cli(capsys, "loads", "--aircraft", str(path), "--tuned",
                           "--gradients", "0.1")
    assert code == 2 and "shorter than the aircraft's mean chord" in err
