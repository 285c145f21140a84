"""The flutter search's defaults and what its results say: unsteady strips by default for
the free aircraft, the quasi-steady torsion artefact flagged beside the number, no speed
for an instability at the range's lower end, aligned mode names, over-damped p-k roots,
the V-g / V-f diagram and the scan's progress."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from bioflex_jsb import api
from tests.cli_helpers import run_cli

FLYING_WING = str(Path(__file__).parent / "fixtures" / "patil_hodges_flying_wing.toml")


@pytest.fixture(scope="module")
def inertial_backward():
    return api.load_wing("inertial-backward")


# ---- over-damped modes in the p-k --------------------------------------------------------

@pytest.mark.parametrize("method", ["pk", "state-space"])
def test_flying_wing_with_an_over_damped_mode_is_analysed_by_both_methods(method):
    # The p-k ended in "IndexError: index 5 is out of bounds for axis 0 with size 5": the
    # first bending mode is over-damped (real roots) from a few m/s, and frozen at another
    # branch's frequency both of its near-real roots fell just below the real axis.
    # Quarter-chord elastic axis and centre of mass: no divergence, no flutter; both methods
    # must say so over the derived range (5.2-105 m/s).
    r = api.flutter(FLYING_WING, clamped=True, method=method)
    assert r.speed_m_s is None and r.mechanism is None and not r.present_at_lower_end
    assert r.range_m_s[1] == pytest.approx(104.98, abs=0.01)
    assert len(r.mode_labels) == len(r.natural_frequencies_rad_s) == 6


def test_over_damped_branch_is_tracked_as_a_real_root():
    r = api.flutter(FLYING_WING, clamped=True, method="pk", full_scan=True)
    first_bending = r.branch_roots[:, r.branch_labels.index("mode 1 (bending)")]
    # at ω = 0 the p-k's C = 1 problem is real: the root is exactly real, and stable
    assert np.all(first_bending.imag == 0.0) and np.all(first_bending.real < 0.0)
    assert r.speeds_m_s[-1] == pytest.approx(r.range_m_s[1], abs=1.0)  # the whole range


def test_pk_candidates_hold_every_branch_when_near_real_roots_fall_below_the_axis():
    from bioflex_jsb.aeroelasticity.pk import ZeroFrequencyRoots, candidates

    # the flying wing's roots at 19 rad/s (50 m/s): six branches, and the two near-real
    # roots of the over-damped bending mode both below the axis
    roots = np.array([-11.06 - 0.0028j, -5.68 - 19.59j, -5.40 + 19.03j, -3.88 + 2.97j,
                      -3.48 + 12.46j, -3.37 - 3.71j, -3.16 - 11.48j, -3.14 - 2.33j,
                      -3.06 + 4.49j, -3.02 + 24.50j, -2.91 - 23.59j, -0.081 - 0.0127j])
    upper_only = roots[roots.imag >= 0.0]
    assert upper_only.size == 5  # what the old filter kept for six branches
    zero = ZeroFrequencyRoots(real=np.array([-11.0, -0.08], dtype=complex),
                              upper=np.array([-5.0 + 19.0j]))
    pool = candidates(roots, zero, 6, 1e-3)
    assert pool.size >= 6 and -11.0 in pool and -0.08 in pool
    # too few above the axis and no real roots: the upper roots at ω = 0 fill in
    pool = candidates(roots[:3], ZeroFrequencyRoots(np.zeros(0, complex),
                                                    np.array([-1 + 1j, -2 + 2j])), 3, 1e-3)
    assert pool.size == 3


# ---- the default aerodynamics and the caveat ----------------------------------------------

def test_free_aircraft_defaults_to_unsteady_strips(inertial_backward):
    # body-freedom flutter of the short period at 18.86 m/s (docs/aeroelasticity.md; the
    # paper: "above 20 m/s"); the quasi-steady model's 14.9 m/s single-mode torsion flutter
    # is its artefact. Bars 0.05 m/s: the bisection is to 1e-4 m/s, ζ moves it 0.008 m/s.
    r = api.flutter(inertial_backward)
    assert r.aero == "unsteady" and r.caveat is None and not r.quasi_steady_artefact
    assert r.mechanism == "body-freedom" and r.mode == "short_period"
    assert r.speed_m_s == pytest.approx(18.86, abs=0.05)
    qs = api.flutter(inertial_backward, aero="quasi-steady")
    assert qs.speed_m_s == pytest.approx(14.90, abs=0.05)
    assert qs.mechanism == "single-mode" and qs.quasi_steady_artefact
    assert "no aerodynamic pitch damping" in qs.caveat
    assert qs.as_dict()["caveat"] == qs.caveat and qs.as_dict()["quasi_steady_artefact"]


def test_an_instability_at_the_lower_end_has_no_speed(inertial_backward):
    # at ζ = 0 the quasi-steady torsion root is unstable at 5 m/s already: api.flutter gave
    # speed_m_s = 5.0 and kind "flutter", a number a script took for a flutter speed
    r = api.flutter(inertial_backward, aero="quasi-steady", structural_damping=0.0)
    assert r.present_at_lower_end and r.speed_m_s is None and r.flutter_speed_m_s is None
    assert r.unstable_at_and_below_m_s == 5.0 and r.kind == "flutter"
    d = r.as_dict()
    assert d["speed_m_s"] is None and d["unstable_at_and_below_m_s"] == 5.0


def test_mode_labels_align_with_the_natural_frequencies(inertial_backward):
    for aero in ("quasi-steady", "unsteady"):
        r = api.flutter(inertial_backward, aero=aero)
        pairs = list(zip(r.mode_labels, r.natural_frequencies_rad_s, strict=True))
        assert [p[0] for p in pairs] == ["aeroelastic_1", "aeroelastic_2", "aeroelastic_3"]
        assert len(r.branch_labels) == r.branch_roots.shape[1]
        assert "short_period" in r.branch_labels  # the branches keep the rigid modes
    g = api.flutter("goland", clamped=True)
    assert len(g.mode_labels) == len(g.natural_frequencies_rad_s) == 6


def test_cli_prints_the_caveat_beside_the_number(capsys):
    code, out, _ = run_cli(capsys, "flutter", "--wing", "inertial-backward")
    assert code == 0 and "unsteady strips" in out
    assert "flutter at 18.9 m/s, mode short_period" in out
    assert "caveat" not in out
    code, out, _ = run_cli(capsys, "flutter", "--wing", "inertial-backward", "--aero",
                           "quasi-steady")
    assert code == 0
    line = next(ln for ln in out.splitlines() if "flutter at" in ln)
    assert "flutter at 14.9 m/s [quasi-steady artefact: see the caveat]" in line
    assert "caveat: quasi-steady strips (C = 1) have no aerodynamic pitch damping" in out
    code, out, _ = run_cli(capsys, "flutter", "--wing", "inertial-backward", "--aero",
                           "quasi-steady", "--structural-damping", "0", "--json")
    d = json.loads(out)
    assert d["flutter_speed_m_s"] is None and d["unstable_at_and_below_m_s"] == 5.0
    assert d["quasi_steady_artefact"] is True and d["caveat"]


# ---- the V-g / V-f diagram -----------------------------------------------------------------

def test_cli_draws_the_vg_diagram(capsys, tmp_path):
    from bioflex_jsb.plot_files import is_our_plot

    png = tmp_path / "vg.png"
    code, out, _ = run_cli(capsys, "flutter", "--wing", "inertial-backward", "--plot",
                           str(png), "--json")
    d = json.loads(out)
    assert code == 0 and d["plot"] == str(png) and is_our_plot(png)
    assert png.stat().st_size > 40_000
    # the same flutter point as without the full scan the diagram asks for
    assert d["flutter_speed_m_s"] == 18.9
    user = tmp_path / "mine.png"
    user.write_bytes(b"not a plot")
    code, _, err = run_cli(capsys, "flutter", "--wing", "inertial-backward", "--plot",
                           str(user))
    assert code == 2 and "--force" in err and user.read_bytes() == b"not a plot"


def test_result_plot_draws_every_considered_branch_and_marks_the_point(tmp_path):
    from bioflex_jsb.errors import InputError

    r = api.flutter("goland", clamped=True, full_scan=True)
    fig = r.plot(tmp_path / "goland.png")
    ax_g, ax_f = fig.axes[:2]
    names = [t.get_text() for t in ax_g.get_legend().get_texts()]
    assert names[:6] == list(r.mode_labels)
    assert any("137.0 m/s" in n and "coalescence" in n for n in names)
    assert any("static divergence: 252.3 m/s" in n for n in names)
    # the branch lines reach the range's top: a full scan
    assert max(line.get_xdata()[-1] for line in ax_f.get_lines()[:6]) == pytest.approx(
        r.range_m_s[1], abs=3.0)
    with pytest.raises(InputError, match="not a plot"):
        (tmp_path / "x.png").write_text("user's")
        r.plot(tmp_path / "x.png")


def test_full_scan_changes_nothing_but_the_scan():
    short = api.flutter("goland", clamped=True)
    full = api.flutter("goland", clamped=True, full_scan=True)
    assert full.speed_m_s == short.speed_m_s and full.mechanism == short.mechanism
    assert full.speeds_m_s[-1] > short.speeds_m_s[-1]


# ---- progress --------------------------------------------------------------------------

def test_progress_is_called_with_each_scanned_speed_and_the_top():
    seen = []
    r = api.flutter("goland", clamped=True, progress=lambda v, top: seen.append((v, top)))
    speeds = [v for v, _ in seen]
    assert speeds == sorted(speeds) and speeds[0] == pytest.approx(r.range_m_s[0])
    tops = {top for _, top in seen}
    assert len(tops) == 1 and tops.pop() == pytest.approx(r.range_m_s[1], abs=3.0)
    assert speeds[-1] >= r.speed_m_s  # the scan stopped at the first unstable grid speed


def test_progress_bar_on_a_terminal_only(capsys, monkeypatch):
    from bioflex_jsb.cli.flutter import ScanProgress

    with ScanProgress() as bar:
        assert bar is None  # stderr is not a terminal under pytest: nothing printed
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True, raising=False)
    with ScanProgress() as bar:
        assert bar is not None
        bar(10.0, 40.0)
        bar(40.0, 40.0)
    err = capsys.readouterr().err
    assert "flutter scan" in err and "m/s" in err
