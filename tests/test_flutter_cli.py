"""``bioflex-jsb flutter``: the clamped Goland benchmark against its published strip-theory
result, the paper wings' report, and one-line refusals of combinations not available."""

from __future__ import annotations

import json

import pytest

from bioflex_jsb.cli import main
from bioflex_jsb.parameters import goland as G
from tests.cli_helpers import assert_one_line_error, run_cli


@pytest.fixture(scope="module")
def goland_json():
    import contextlib
    import io

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["flutter", "--wing", "goland", "--clamped", "--aero", "unsteady",
                     "--json"])
    return code, json.loads(buf.getvalue())


def test_goland_clamped_unsteady_matches_published_strip_theory(goland_json):
    code, d = goland_json
    assert code == 0
    # Published: 137.2 m/s, 70.7 rad/s, the exact strip-theory (Theodorsen, lift slope 2π)
    # flutter point of Goland, J. Appl. Mech. 12(4), A197-A208 (1945), as tabulated by
    # Patil, Hodges & Cesnik, J. Aircraft 38(1), 88-94 (2001). Measured (p-k on the exact
    # C(k), 8.64 kg·m about the elastic axis, ρ = 1.225 kg/m³): 136.96 m/s (−0.2 %),
    # 70.02 rad/s (−1.0 %). Tolerance: 3 %, the issue's "within a few per cent"
    # (tests/test_goland.py holds the library to 1 % / 2 %).
    assert d["flutter_speed_m_s"] == pytest.approx(G.PUBLISHED_FLUTTER_SPEED_M_S, rel=0.03)
    assert d["frequency_rad_s"] == pytest.approx(G.PUBLISHED_FLUTTER_FREQUENCY_RAD_S,
                                                 rel=0.03)
    assert d["published"]["flutter_speed_m_s"] == G.PUBLISHED_FLUTTER_SPEED_M_S
    assert d["published"]["comparable"] and "Goland (1945)" in d["published"]["source"]
    assert abs(d["published"]["speed_rel_diff"]) < 0.03
    # reported: reduced frequency k = ωb/V, mode, mechanism, natural frequencies
    b = G.CHORD_M / 2
    assert d["reduced_frequency"] == pytest.approx(
        d["frequency_rad_s"] * b / d["flutter_speed_m_s"], rel=1e-3)
    assert d["mechanism"] == "coalescence" and d["kind"] == "flutter"
    assert {d["mode"], d["partner_mode"]} == {"mode 1 (bending)", "mode 2 (torsion)"}
    # first three natural frequencies vs published 49.5, 97.0, 248.9 rad/s (Patil, Hodges
    # & Cesnik 2001); measured −2.7, −1.3, −2.0 %: tolerance 3 % (tests/test_goland.py)
    for w, ref in zip(d["natural_frequencies_rad_s"][:3],
                      G.PUBLISHED_NATURAL_FREQUENCIES_RAD_S, strict=True):
        assert w == pytest.approx(ref, rel=0.03)


def test_goland_state_space_and_issue_reading(capsys):
    # State-space (Jones lag states) within 0.5 % of p-k (tests/test_goland.py), so within
    # 3 % of the published 137.2 m/s too; the issue's literal reading (8.64 kg·m about the
    # centre of mass, ρ = 1.02 kg/m³) measured 137.29 m/s, 68.19 rad/s (frequency −3.5 %).
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped",
                           "--method", "state-space", "--json")
    assert code == 0
    assert json.loads(out)["flutter_speed_m_s"] == pytest.approx(137.2, rel=0.03)
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped",
                           "--inertia-about", "centre-of-mass", "--density", "1.02", "--json")
    d = json.loads(out)
    assert code == 0 and d["inertia_about"] == "centre-of-mass" and d["density_kg_m3"] == 1.02
    assert d["flutter_speed_m_s"] == pytest.approx(137.2, rel=0.03)
    assert d["frequency_rad_s"] == pytest.approx(70.7, rel=0.04)


def test_goland_quasi_steady_is_not_compared_with_published(capsys):
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--aero",
                           "quasi-steady", "--structural-damping", "0.02", "--json")
    d = json.loads(out)
    assert code == 0 and d["aero"] == "quasi-steady" and d["structural_damping"] == 0.02
    assert d["published"]["comparable"] is False and d["published"]["speed_rel_diff"] is None
    assert d["flutter_speed_m_s"] < 0.7 * G.PUBLISHED_FLUTTER_SPEED_M_S  # single-mode, early
    assert d["mechanism"] == "single-mode"


def test_goland_text_report(capsys):
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped")
    assert code == 0
    assert "flutter at 137.0 m/s" in out and "published: 137.2 m/s" in out
    assert "natural frequencies [rad/s]: 48.15" in out


def test_paper_wing_reports_mechanism_and_damping(capsys):
    code, out, _ = run_cli(capsys, "flutter", "--wing", "elastic-backward", "--aero",
                           "quasi-steady", "--json")
    d = json.loads(out)
    assert code == 0 and d["clamped"] is False and d["aero"] == "quasi-steady"
    assert d["structural_damping"] == [0.02, 0.02, 0.02]
    assert 5.0 < d["flutter_speed_m_s"] < 30.0
    assert d["mechanism"] in ("coalescence", "single-mode", "static divergence")
    assert len(d["natural_frequencies_rad_s"]) == 3 and d["reduced_frequency"] > 0.0
    code, out, _ = run_cli(capsys, "flutter", "--wing", "elastic-backward", "--aero",
                           "quasi-steady", "--structural-damping", "0", "--json")
    d0 = json.loads(out)
    assert d0["structural_damping"] == [0.0, 0.0, 0.0]
    # quasi-steady twist modes have no aerodynamic damping: the assumed ζ sets the speed
    assert d0["flutter_speed_m_s"] < d["flutter_speed_m_s"]


@pytest.mark.slow  # two unsteady flutter scans: 13.6 s measured; full suite only
def test_paper_wing_unsteady_reports_body_freedom_flutter(capsys):
    # Unsteady strips (aeroelasticity/free_aircraft.py): the backward-axis wings' flutter is
    # set by the aerodynamics, not the assumed damping (issue 15: < 10 % between ζ = 0 and
    # 0.02; measured 19.54 vs 19.51 m/s), a short-period (body-freedom) instability.
    out = {}
    for z in ("0", "0.02"):
        code, text, _ = run_cli(capsys, "flutter", "--wing", "elastic-backward", "--aero",
                                "unsteady", "--structural-damping", z, "--json")
        assert code == 0
        out[z] = json.loads(text)
    assert out["0"]["flutter_speed_m_s"] == pytest.approx(out["0.02"]["flutter_speed_m_s"],
                                                          rel=0.10)
    for d in out.values():
        assert d["aero"] == "unsteady" and d["mechanism"] == "body-freedom"
        assert d["mode"] == "short_period" and 15.0 < d["flutter_speed_m_s"] < 25.0
        assert d["wing_divergence_speed_m_s"] == pytest.approx(18.73, abs=0.05)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--wing", "goland"], "give --clamped"),
        (["--wing", "original", "--clamped"], "--clamped takes a clamped-wing definition"),
        (["--wing", "original", "--method", "pk"], "accept --method state-space"),
        (["--wing", "original", "--lift-slope", "vlm"], "--lift-slope is available"),
        (["--wing", "original", "--inertia-about", "centre-of-mass"],
         "--inertia-about is available"),
        (["--wing", "goland", "--clamped", "--aero", "viscous"], "invalid choice"),
        (["--wing", "goland", "--clamped", "--structural-damping", "1.5"], "0 <= Z <= 0.3"),
        (["--wing", "goland", "--clamped", "--structural-damping", "x"], "0 <= Z <= 0.3"),
        (["--wing", "goland", "--clamped", "--density", "0"], "0.01 <= RHO <= 2"),
        # 1e-300 kg/m^3 was a traceback (brentq) before; the range is the definition
        # format's (about 33 km altitude to denser than any surface air)
        (["--clamped", "goland", "--density", "1e-300"], "0.01 <= RHO <= 2"),
        (["--wing", "goland", "--clamped", "--range", "20:900"], "range must satisfy"),
        (["--wing", "banana"], "valid names: original"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, argv, needle):
    code, _, err = run_cli(capsys, "flutter", *argv)
    assert_one_line_error(code, err, needle)


def test_help_states_units_and_ranges(capsys):
    code, out, _ = run_cli(capsys, "flutter", "--help")
    assert code == 0
    flat = " ".join(out.split())
    for text in ("[m/s]", "[rad/s]", "k = omega*b/V", "0 <= Z <= 0.3", "kg/m^3", "goland",
                 "0 < LOW < HIGH <= 400", "unstable at and below", "docs/aircraft.md"):
        assert text in flat, text


# False "safe" results (issue: the searches only saw a crossing inside --range). Before the
# one engine, each of these printed "no instability" (measured on the previous commit).
def test_clamped_instability_below_the_range_is_reported(capsys):
    # Goland flutters at 136.96 m/s: with --range 140:260 it is unstable at 140 m/s.
    code, out, _ = run_cli(capsys, "flutter", "--wing", "goland", "--clamped", "--range",
                           "140:260", "--json")
    d = json.loads(out)
    assert code == 0 and d["present_at_lower_end"] is True
    assert d["flutter_speed_m_s"] is None and d["unstable_at_and_below_m_s"] == 140.0
    assert d["kind"] == "flutter"
    assert d["mode"] == "mode 2 (torsion)" and d["published"]["comparable"] is False
    code, out, _ = run_cli(capsys, "flutter", "--clamped", "goland", "--range", "140:260")
    assert "unstable at and below 140 m/s" in out and "no instability" not in out


def test_quasi_steady_never_no_instability_beside_a_divergence(capsys):
    # quasi-steady Goland flutters at 64.53 m/s, diverges at 252.3: --range 70:260 printed
    # "no instability" and "static divergence at 252.3 m/s" together.
    for method in ("pk", "state-space"):
        code, out, _ = run_cli(capsys, "flutter", "--clamped", "goland", "--aero",
                               "quasi-steady", "--method", method, "--range", "70:260")
        assert code == 0 and "no instability" not in out, out
        assert "unstable at and below 70 m/s" in out and "static divergence at 252.3" in out


def test_free_aircraft_lower_end_is_flagged(capsys):
    # elastic-backward flutters at 15.45 m/s (quasi-steady): with --range 20:40 the lower end
    # was printed as "flutter at 20.0 m/s" with no flag.
    code, out, _ = run_cli(capsys, "flutter", "--wing", "elastic-backward", "--aero",
                           "quasi-steady", "--range", "20:40", "--json")
    d = json.loads(out)
    assert code == 0 and d["present_at_lower_end"] is True
    # no onset found: null, not the range's lower end a script would take for one
    assert d["flutter_speed_m_s"] is None and d["unstable_at_and_below_m_s"] == 20.0
    assert d["kind"] == "flutter" and d["mode"] is not None
    code, out, _ = run_cli(capsys, "flutter", "--wing", "elastic-backward", "--aero",
                           "quasi-steady")
    assert "flutter at 15.4 m/s [quasi-steady artefact" in out


@pytest.mark.parametrize("argv, needle", [
    # each was ignored silently: the clamped Goland wing analysed as if not given
    (["--clamped", "goland", "--aircraft", "bioflex_original"], "--aircraft is the free"),
    (["--clamped", "goland", "--wing", "optimised"], "give one of them"),
    (["--clamped", "goland", "--mass-basis", "paper"], "--mass-basis is the free"),
])
def test_options_a_clamped_analysis_does_not_take_are_refused(capsys, argv, needle):
    code, _, err = run_cli(capsys, "flutter", *argv)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and needle in lines[0], err
