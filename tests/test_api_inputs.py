"""The Python API's bad inputs (the review of 2026-12-03): each refused with an InputError
in one line before anything is flown or written, where it was silently accepted (a wrong
wing's section loads, an unknown trim, a run without its gust, a user's file replaced by a
plot) or ended in numpy's or Python's own error."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from bioflex_jsb import api
from bioflex_jsb.errors import InputError


@pytest.fixture(scope="module")
def wing(optimised_wing):
    return optimised_wing


@pytest.fixture(scope="module")
def run(optimised_run):
    return optimised_run


@pytest.mark.parametrize("kwargs, needle", [
    ({"trim": "nope"}, "unknown trim"),  # flew from the rigid trim
    ({"duration_s": 0.0}, "duration_s must be > 0"),  # a run of 0 samples
    ({"duration_s": math.nan}, "must be finite"),
    ({"duration_s": "0.3"}, "must be a number"),
    ({"gust_start_s": -0.5}, "must be within the run"),  # the gust already on at t = 0
    ({"gust_start_s": 10.0, "duration_s": 1.0}, "must be within the run"),  # no gust
    ({"models": ()}, "give one or more"),  # returned {}
    ({"models": "coupled"}, "a tuple of model names"),  # "unknown wing model 'c'"
    ({"models": ("native",)}, "unknown model 'native'"),  # a KeyError from JSBSim
    ({"dt_s": 1e-5}, "outside 0.0001..0.02"),  # "more thrust than the motor gives"
    ({"dt_s": 0.05}, "outside 0.0001..0.02"),  # "propeller RPM did not settle"
    ({"models": ("coupled",), "recorders": {"rigid": object()}}, "not flown"),  # no log
    ({"gust": None}, "a gust text"),
])
def test_fly_gust_refuses_before_flying(wing, kwargs, needle):
    with pytest.raises(InputError, match=needle):
        api.fly_gust(wing, **kwargs)


def test_compare_refuses_a_run_without_its_gust(wing):
    with pytest.raises(InputError, match="must be within the run"):
        api.compare(wing, duration_s=0.5, gust_start_s=10.0)  # NRMSE 1.0 everywhere


def test_metrics_take_the_runs_own_gust_start(run):
    """It used 0.5 s for a gust at 0.1 s: peak Δα 0.0215 rad instead of 0.197."""
    assert api.metrics(run).as_dict() == api.metrics(run, 0.1).as_dict()
    assert api.metrics(run).peak_dalpha_rad > 2.0 * api.metrics(run, 0.5).peak_dalpha_rad
    with pytest.raises(InputError, match="gust_start_s: must be a finite number in s"):
        api.metrics(run, math.nan)


@pytest.mark.parametrize("other, kwargs, needle", [
    ("sgs_elastic", {}, "flown with wing 'optimised'"),  # 79 424 N m against 10.4
    ("original", {}, "flown with wing 'optimised'"),  # 11.60 N m against 10.42
    ("optimised", {"density_kg_m3": -1.0},
     "density_kg_m3: -1 kg/m.3 is outside the valid range 0.01..2"),  # 7.65 N m, silently
    ("optimised", {"density_kg_m3": math.nan},
     "density_kg_m3: must be a finite number in kg/m.3, got nan"),
])
def test_section_loads_of_the_runs_own_wing_only(run, other, kwargs, needle):
    wing = (api.load_aircraft(other) if other.startswith("sgs") else api.load_wing(other))
    with pytest.raises(InputError, match=needle):
        api.section_loads(wing, run, **kwargs)


def test_section_loads_refuse_the_native_wing(wing):
    with pytest.raises(InputError, match="native wing"):
        api.section_loads(wing, api.fly_fig21("native", duration_s=0.6))


@pytest.mark.parametrize("call, needle", [
    (lambda w: api.modes(w, 15.0, structural_damping=-0.5),
     "structural_damping: -0.5 .* is outside the valid range 0..0.3"),
    (lambda w: api.flutter(w, structural_damping=math.nan),
     "structural_damping: must be a finite number"),
    (lambda w: api.free_speed_range_m_s(w, math.nan), "must be a finite number"),
    (lambda w: api.linear_model(w, 15.0, model="nope"), "unknown model"),  # a ValueError
    (lambda w: api.load_wing(None), "a variant name or a variant file"),
])
def test_linear_analyses_refuse_bad_numbers_and_names(wing, call, needle):
    with pytest.raises(InputError, match=needle):
        call(wing)


def test_a_plot_never_replaces_a_users_file(tmp_path, wing):
    """``Comparison.plot`` and ``SectionLoads.plot`` replaced any existing file; wrote
    ``x.png`` for ``x`` and returned ``x``; wrote ``plots.png`` for a directory."""
    comparison = api.compare(wing, duration_s=0.4, gust_start_s=0.1)
    mine = tmp_path / "mine.png"
    mine.write_text("USER DATA")
    for path, needle in ((mine, "not a plot bioflex-jsb wrote"), (tmp_path / "x", "ending in"),
                         (tmp_path, "ending in"), (tmp_path / "no" / "a.png", "does not exist"),
                         ("", "a file name")):
        with pytest.raises(InputError, match=needle):
            comparison.plot(path, "t")
    assert mine.read_text() == "USER DATA"
    ours = Path(comparison.plot(tmp_path / "c.png", "t"))
    comparison.plot(ours, "t")  # a plot of ours: replaced
    comparison.plot(mine, "t", force=True)  # a user's file: only when told
    assert mine.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("call, needle", [
    # 71 s for no physical answer
    (lambda w: api.modes(w, 1e5), "outside the valid range 0.1..400 m/s"),
    (lambda w: api.linear_model(w, 0.0), "speed_m_s: 0 m/s is outside"),  # a numpy ValueError
    # "arange: cannot compute length"
    (lambda w: api.modes(w, math.nan), "speed_m_s: must be a finite number in m/s"),
    (lambda w: api.flutter(w, (5.0, math.inf)), "range_m_s: must be"),  # "Maximum allowed size"
    (lambda w: api.flutter(w, "5:40"),
     r"range_m_s: must be \[low, high\] m/s with 0 < low < high <= 400 m/s"),
    (lambda w: api.fly_gust("optimised"), "a WingBuild\\) or an Aircraft"),  # AttributeError
    (lambda w: api.flutter("goland"), "clamped=True"),  # "'str' object has no attribute"
])
def test_speeds_and_wings_of_the_linear_analyses(wing, call, needle):
    with pytest.raises(InputError, match=needle):
        call(wing)


def test_a_missing_channel_names_the_channels_there(run):
    with pytest.raises(KeyError, match="channels: u, alpha"):
        run["nope"]


def test_plot_runs_draws_fly_gusts_results_and_refuses_what_is_not_a_run(tmp_path, wing):
    runs = api.fly_gust(wing, gust="sharp:3", models=("rigid", "coupled"), duration_s=0.5,
                        gust_start_s=0.1)
    assert runs["coupled"].meta["wing"] == "optimised"  # which wing flew (the title's)
    out = api.plot_runs(runs, tmp_path / "g.png", "sharp:3")
    assert out == tmp_path / "g.png" and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert api.plot_runs(runs["coupled"], tmp_path / "one.svg").stat().st_size > 0
    mine = tmp_path / "mine.png"
    mine.write_text("USER DATA")
    for call, needle in ((lambda: api.plot_runs(runs, mine), "not a plot bioflex-jsb wrote"),
                         (lambda: api.plot_runs({}, tmp_path / "e.png"), "not none"),
                         (lambda: api.plot_runs([1.0], tmp_path / "f.png"), "not float"),
                         (lambda: api.plot_runs("coupled", tmp_path / "s.png"), "not str"),
                         (lambda: api.plot_runs(runs, tmp_path / "t.png", title=3), "title")):
        with pytest.raises(InputError, match=needle):
            call()
    assert mine.read_text() == "USER DATA"


def test_a_mode_set_is_a_sequence_of_its_modes(wing):
    ms = api.modes(wing, 15.0)
    assert len(ms) == len(ms.modes) and list(ms) == list(ms.modes) and ms[0] is ms.modes[0]
    assert ms["short_period"] is ms.get("short_period")
    assert "short_period" in ms and "phugoid" in ms and "no_such_mode" not in ms
    assert "" not in ms and 3 not in ms
    assert ms.names == tuple(m.mode for m in ms.modes)
    with pytest.raises(KeyError, match="no mode 'no_such_mode'"):
        ms["no_such_mode"]
