"""Figures a user can read: every line told apart, η₁ defined, one legend, titles that say
what was flown. Drawn from synthetic runs (no flight), checked through matplotlib's figure."""

from __future__ import annotations

import numpy as np
import pytest

from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.sinks import plotting


def _run(model: str, label: str | None = None, gust_at: float | None = 0.5) -> TimeHistory:
    t = np.linspace(0.0, 2.0, 401)
    w_g = np.where(t >= gust_at, 3.0, 0.0) if gust_at is not None else np.zeros_like(t)
    ch = {name: np.sin(t + i) * 0.01 for i, name in
          enumerate(("u", "alpha", "q", "theta", "eta1"))}
    ch["n_z"] = 1.0 + ch["alpha"]
    ch["w_g"] = w_g
    meta = {"label": label} if label else {}
    return TimeHistory(model, t, ch, {k: "-" for k in ch}, meta)


@pytest.fixture()
def captured(monkeypatch):
    """The figure handed to the writer, instead of a file."""
    figures = []
    monkeypatch.setattr(plotting, "save_figure", lambda fig, path: figures.append(fig) or path)
    return figures


def test_two_wings_flown_with_the_same_model_get_different_colours(captured):
    plotting.time_histories([_run("qsd", "original"), _run("qsd", "optimised")], "x.png", "t")
    ax = captured[0].axes[0]
    colours = [line.get_color() for line in ax.get_lines() if line.get_label() in
               ("original", "optimised")]
    assert len(colours) == 2 and colours[0] != colours[1], colours


def test_one_figure_legend_and_eta1_is_defined(captured):
    plotting.time_histories([_run("rigid"), _run("coupled"), _run("qsd")], "x.png", "t")
    fig = captured[0]
    assert len(fig.legends) == 1
    assert [t.get_text() for t in fig.legends[0].get_texts()] == ["rigid", "coupled", "qsd"]
    panel_legends = [ax for ax in fig.axes if ax.get_legend() is not None]
    assert [ax.get_ylabel() for ax in panel_legends] == ["gust w_g [m/s] (up)"]
    notes = " ".join(t.get_text() for t in fig.texts)
    # runs without the mode's shape: η₁ itself, and the note says why
    assert "η₁" in notes and "do not carry its shape" in notes, notes
    assert fig.axes[6].get_ylabel().startswith("η₁ [deg]")


def _eta_panel(fig):
    ax = fig.axes[7]  # η₁ at the gust onset: the samples themselves
    return ax.get_ylabel(), ax.get_lines()[0].get_ydata()


def test_a_twisting_first_mode_is_drawn_as_its_tip_twist(captured):
    run = _run("coupled")
    run.meta["mode_tips"] = [{"quantity": "tip twist", "unit": "rad", "per_rad": 0.5}]
    plotting.time_histories([run], "x.png", "t")
    label, y = _eta_panel(captured[0])
    assert "tip twist [deg]" in label, label
    keep = (run.time_s >= 0.45) & (run.time_s <= 0.85)
    np.testing.assert_allclose(y, np.degrees(0.5 * run["eta1"][keep]))
    assert "leading edge up" in " ".join(t.get_text() for t in captured[0].texts)


def test_a_bending_first_mode_is_drawn_as_its_tip_deflection_in_metres(captured):
    # a sailplane's first mode bends (sgs_elastic): metres at the tip, not degrees
    run = _run("coupled")
    run.meta["mode_tips"] = [{"quantity": "tip deflection", "unit": "m", "per_rad": -7.0}]
    lti = _run("coupled", "LTI coupled")  # a prediction: no shape, the run's is taken
    plotting.time_histories([run, lti], "x.png", "t")
    label, y = _eta_panel(captured[0])
    assert "tip deflection [m]" in label and "deg" not in label, label
    keep = (run.time_s >= 0.45) & (run.time_s <= 0.85)
    np.testing.assert_allclose(y, -7.0 * run["eta1"][keep])
    notes = " ".join(t.get_text() for t in captured[0].texts)
    assert "bending mode" in notes and "twist" not in notes, notes


def test_wings_whose_first_modes_differ_are_drawn_as_eta_and_say_so(captured):
    a, b = _run("coupled", "a"), _run("qsd", "b")
    a.meta["mode_tips"] = [{"quantity": "tip twist", "unit": "rad", "per_rad": 1.0}]
    b.meta["mode_tips"] = [{"quantity": "tip deflection", "unit": "m", "per_rad": 1.0}]
    plotting.time_histories([a, b], "x.png", "t")
    assert _eta_panel(captured[0])[0].startswith("η₁ [deg]")
    assert "modes differ" in " ".join(t.get_text() for t in captured[0].texts)


def test_mode_tips_name_twist_for_the_prototype_and_deflection_for_the_sailplane():
    from bioflex_jsb import api
    from bioflex_jsb.simulation.channels import mode_tips

    proto = mode_tips(api.load_wing("optimised").modes)
    assert [t["quantity"] for t in proto] == ["tip twist"] * 3
    assert proto[0]["per_rad"] == pytest.approx(1.0)  # scaled to a unit tip twist
    sgs = api.load_aircraft("sgs_elastic").wing().modes
    tips = mode_tips(sgs)
    assert tips[0]["quantity"] == "tip deflection" and tips[0]["unit"] == "m"
    # bending is positive down (docs/conventions.md): the figure's up is its negative
    assert tips[0]["per_rad"] == pytest.approx(-float(sgs.bending_m[0, -1]))


def test_a_sitl_session_title_says_the_gust_it_flew():
    from bioflex_jsb.cli.plot import _title

    meta = {"command": "sitl", "wing": "optimised", "gust": "none", "speed_m_s": "15.0"}
    title = _title(meta, [_run("coupled", gust_at=1.25)], "f.mcap")
    assert "gust none" not in title and "t = 1.2 s" in title and "3.00 m/s" in title, title
    assert _title(meta, [_run("coupled", gust_at=None)], "f.mcap").endswith("still air")
    gust_meta = {"command": "gust", "wing": "optimised", "gust": "sharp:3", "speed_m_s": "15"}
    assert _title(gust_meta, [], "f.mcap") == "optimised wing, 15 m/s, gust sharp:3"


def _labels(fig) -> list[str]:
    return [ax.get_ylabel() for ax in fig.axes]


def test_root_locus_speed_labels_keep_apart_and_coinciding_models_are_named(tmp_path,
                                                                             captured):
    from bioflex_jsb import cli
    from bioflex_jsb.sinks.plotting import LABEL_CLEARANCE_PX

    assert cli.main(["modes", "--plot", str(tmp_path / "loci.png")]) == 0
    fig = captured[0]
    ax_ph = fig.axes[2]
    spots = [ax_ph.transData.transform(t.xy) for t in ax_ph.texts if t.get_text().isdigit()]
    assert len(spots) >= 4
    gaps = [np.hypot(*(p - q)) for i, p in enumerate(spots) for q in spots[:i]]
    assert min(gaps) >= LABEL_CLEARANCE_PX  # the phugoid zoom crowds at high speed
    notes = [t.get_text() for t in ax_ph.texts if "agree" in t.get_text()]
    assert notes and "coupled and QSD" in notes[0], [t.get_text() for t in ax_ph.texts]
    # which rigid block the models have (their phugoid is not JSBSim's): on the figure
    foot = " ".join(t.get_text() for t in fig.texts)
    assert "rigid block of every model here: analytic (Table B2" in foot, foot
    assert "not JSBSim's" in foot, foot


def _flight_run(seconds: float = 20.0) -> TimeHistory:
    """A synthetic turn: 15 m/s, heading through north (350° → 20°), banked, the modes
    ringing at 31 Hz."""
    t = np.arange(0.0, seconds, 1 / 240)
    psi = np.radians(350.0 + 1.5 * t) % (2 * np.pi)
    ch = {"u": 0 * t, "alpha": 0 * t, "q": 0 * t, "theta": 0 * t, "n_z": 1.0 + 0 * t,
          "w_g": 0 * t, "airspeed_m_s": 15.0 + 0 * t, "altitude_m": 100.0 - 0.1 * t,
          "phi_rad": np.radians(20.0) + 0 * t, "theta_rad": 0.03 + 0 * t, "psi_rad": psi,
          "alpha_rad": 0.04 + 0 * t, "v_north_m_s": 15.0 * np.cos(psi),
          "v_east_m_s": 15.0 * np.sin(psi)}
    for i in (1, 2, 3):
        ch[f"eta{i}"] = 0.01 * np.sin(2 * np.pi * 31 * i * t)
    tips = [{"quantity": "tip deflection", "unit": "m", "per_rad": -7.0},
            {"quantity": "tip twist", "unit": "rad", "per_rad": 1.0},
            {"quantity": "tip deflection", "unit": "m", "per_rad": -7.0}]
    return TimeHistory("coupled", t, ch, {k: "-" for k in ch}, {"mode_tips": tips})


def test_a_flight_figure_has_the_flight_the_track_and_the_events(captured):
    run = _flight_run()
    events = [{"time_s": 2.0, "text": "Mode LOITER"}, {"time_s": 2.05, "text": "at once"},
              {"time_s": 12.0, "text": "Reached waypoint #1"}, {"time_s": 99.0, "text": "x"}]
    from bioflex_jsb.sinks.flight_plot import flight_figure

    flight_figure(run, "x.png", "a flight", events)
    fig = captured[0]
    labels = _labels(fig)
    for want in ("altitude [m] (MSL)", "airspeed [m/s]", "attitude [deg]", "heading ψ [deg]",
                 "north [m]", "load factor n_z [-]", "angle of attack α [deg]"):
        assert want in labels, labels
    # modes of two kinds: metres on one axis, degrees on its twin
    assert "wing modes: tip deflection [m] (up +)" in labels
    assert "wing modes: tip twist [deg]" in labels
    heading = fig.axes[labels.index("heading ψ [deg]")]
    assert heading.get_ylim() == (-180.0, 180.0)  # a flight through north: no wrap
    track = fig.axes[labels.index("north [m]")]
    east, north = track.get_lines()[0].get_data()
    # the track is the velocity integrated: 20 s at 15 m/s is 300 m of path
    assert np.sum(np.hypot(np.diff(east), np.diff(north))) == pytest.approx(300, rel=0.01)
    foot = " ".join(t.get_text() for t in fig.texts)
    assert "1: t = 2.0 s Mode LOITER; at once" in foot and "2: t = 12.0 s" in foot, foot
    assert " x" not in foot.split("events:")[1].split("\n")[0]  # after the run: not drawn


def test_a_level_flight_reads_as_level(captured):
    """Still air: altitude and airspeed held to millimetres show as flat lines on plain
    ticks (no '+6.84e2' offset), each axis at least its MIN_SPAN wide."""
    from bioflex_jsb.sinks.flight_plot import MIN_SPAN, flight_figure

    run = _flight_run()
    t = run.time_s
    run.channels["altitude_m"] = 684.0 + 0.009 * (1.0 - np.exp(-t / 5.0))  # as sitl logged
    run.channels["airspeed_m_s"] = 15.0 + 6e-4 * np.sin(t / 3.0)
    run.channels["n_z"] = 0.998 + 0 * t
    flight_figure(run, "x.png", "a level flight")
    fig = captured[0]
    fig.canvas.draw()
    labels = _labels(fig)
    for label, key in (("altitude [m] (MSL)", "altitude_m"), ("airspeed [m/s]", "airspeed_m_s"),
                       ("load factor n_z [-]", "n_z"), ("angle of attack α [deg]", "alpha_deg")):
        ax = fig.axes[labels.index(label)]
        low, high = ax.get_ylim()
        assert high - low >= MIN_SPAN[key] * (1 - 1e-9), (label, low, high)
        assert ax.yaxis.get_offset_text().get_text() == "", label
    ax = fig.axes[labels.index("altitude [m] (MSL)")]
    assert ax.get_ylim()[0] < 684.0 < ax.get_ylim()[1]


def test_a_sitl_log_is_plotted_as_a_flight(tmp_path, monkeypatch, capsys, captured):
    import json

    from bioflex_jsb import cli
    from bioflex_jsb.cli.gust import open_log
    from bioflex_jsb.cli.sitl import SplitLog
    from bioflex_jsb.drivers.sitl import SitlSim, run_paced
    from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
    from bioflex_jsb.links import mavlink_modes as MODES
    from bioflex_jsb.simulation.run import RunDescription

    build = build_wing(VARIANTS["optimised"])
    sim = SitlSim(build.model, build.modes, speedup=100.0)
    out = tmp_path / "session.mcap"
    log = SplitLog(str(out), RunDescription(kind="sitl", wing="optimised", speed_m_s=15.0,
                                            gust="none", models=("coupled",)),
                   build, 256.0, open_log)
    logged = log.attach(sim)
    assert sim.vehicle.set_mode(MODES.LOITER) is None  # a turn: bank and heading change
    try:
        run_paced(sim, 4.0, None, logged, idle=log.idle)
    finally:
        log.close()
    assert cli.main(["plot", str(out), "--out", str(tmp_path / "f.png"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["figure"] == "flight"
    labels = _labels(captured[0])
    assert "heading ψ [deg]" in labels and "north [m]" in labels, labels
    assert "wing modes: tip twist [deg]" in labels  # the log says what its modes are
    assert "Mode LOITER" in " ".join(t.get_text() for t in captured[0].texts)


@pytest.fixture()
def saved(monkeypatch):
    """Every matplotlib figure written (Figure.savefig), kept instead of the file."""
    from matplotlib.figure import Figure

    figures = []
    monkeypatch.setattr(Figure, "savefig", lambda fig, *a, **k: figures.append(fig))
    return figures


def test_every_panel_of_the_mode_sheet_labels_both_its_axes(tmp_path, saved):
    from bioflex_jsb import cli

    assert cli.main(["modes", "--mode-sheet", str(tmp_path / "sheet.png")]) == 0
    fig = saved[0]
    panels = [ax for ax in fig.axes if ax.get_visible()]
    left = [ax for ax in panels if ax.yaxis.get_label_position() == "left"]
    right = [ax for ax in panels if ax.yaxis.get_label_position() == "right"]
    assert len(left) == len(right) == 6
    # each right axis has its own scale (bending per unit amplitude differs per mode)
    assert all(ax.get_ylabel() == "bending w [mm]" for ax in right), \
        [ax.get_ylabel() for ax in right]
    assert all(ax.get_ylabel() == "twist θ [rad]" for ax in left)


def _section_loads(md_share: float):
    from bioflex_jsb.loads.history import SectionLoads

    t = np.linspace(0.0, 1.0, 11)
    fs = np.array([[10.0, 5.0], [3.0, 1.0], [-0.7, -0.4]])  # (quantity, station)
    md = fs * np.array([[md_share], [md_share], [0.75]])
    values = {"force_summation": np.broadcast_to(fs, (len(t), 3, 2)).copy(),
              "mode_displacement": np.broadcast_to(md, (len(t), 3, 2)).copy()}
    return SectionLoads("optimised", "coupled", t, np.array([0.0, 0.425]), (0.0, 0.5), values,
                        {"force_summation": fs, "mode_displacement": md},
                        values["force_summation"], 0 * values["force_summation"],
                        {"speed_m_s": 15.0, "gust": "1cos:3:5"})


def test_the_section_loads_figure_says_what_mode_displacement_misses(saved):
    from bioflex_jsb.loads.plots import md_caveat, plot_section_loads

    plot_section_loads(_section_loads(0.09), "x.png")
    title = saved[0].legends[0].get_title().get_text().replace("\n", " ")
    assert "shear 9 %" in title and "torque 75 %" in title, title
    assert "misses most of the shear and bending" in title and "read FS" in title
    # modes that carry the bending (a beam's bending modes): the shares, no warning
    assert "misses" not in md_caveat(_section_loads(0.95))


def test_the_tuned_envelope_has_a_colour_bar_and_keeps_its_labels_inside(tmp_path, saved,
                                                                        capsys):
    from bioflex_jsb import cli

    assert cli.main(["loads", "--tuned", "--gradients", "0.5,3", "--stations", "0,0.5",
                     "--plot", str(tmp_path / "env.png")]) == 0
    fig = saved[0]
    bars = [ax for ax in fig.axes if ax.get_ylabel().startswith("gust gradient length H [m]")]
    assert len(bars) == 1, [ax.get_ylabel() for ax in fig.axes]
    assert [t.get_text() for t in bars[0].get_yticklabels()] == ["0.5", "3"]
    fig.canvas.draw()
    for ax in fig.axes:
        if ax in bars:
            continue
        box = ax.get_window_extent()
        for text in ax.texts:
            inside = text.get_window_extent().expanded(0.98, 0.9)
            assert box.x0 <= inside.x0 and inside.x1 <= box.x1, (text.get_text(), box, inside)


def _rolling(model: str, label: str | None = None, controller: bool = False,
             p_g: bool = True) -> TimeHistory:
    """A synthetic full-span run: the longitudinal channels and the lateral ones."""
    run = _run(model, label)
    t = run.time_s
    lateral = {name: np.cos(t + i) * 0.02 for i, name in enumerate(
        ("beta_rad", "p_rad_s", "r_rad_s", "phi_rad", "asym_eta1", "aileron_rad"))}
    lateral["modal_roll_n_m"] = 3.0 * np.sin(2.0 * t)
    lateral["p_g"] = np.where(t >= 0.5, 0.1, 0.0) if p_g else np.zeros_like(t)
    lateral["v_g"] = np.where(t >= 0.5, 1.0, 0.0)
    if controller:
        lateral["ctrl_aileron_rad"] = -0.01 * np.sin(t)
    for name, values in lateral.items():
        run.channels[name] = values
        run.units[name] = "-"
    return run


def test_a_run_that_rolls_gets_the_lateral_panels_beside_the_longitudinal_ones(captured):
    """Eight lateral-directional panels after the eight longitudinal ones (which keep their
    places in fig.axes), each drawing its channel in the drawn unit; the aileron panel the
    controller's command when one flew, the gust panel p_g when it blows."""
    run, lti = _rolling("coupled", controller=True), _rolling("coupled", "LTI coupled")
    lti.meta["source"] = "lti"  # its lines carry the NRMSE
    plotting.time_histories([run, lti], "x.png", "t", nrmse={"p_rad_s": 0.01})
    fig = captured[0]
    assert len(fig.axes) == 16
    assert [ax.get_ylabel() for ax in fig.axes[:6]] == [
        "Δu [m/s]", "Δα [deg]", "q [deg/s]", "Δθ [deg]", "n_z [-]", "gust w_g [m/s] (up)"]
    labels = [ax.get_ylabel() for ax in fig.axes[8:]]
    assert labels == ["β [deg]", "p [deg/s]", "r [deg/s]", "φ [deg]",
                      "δa command over trim [deg]", "gust roll rate p_g [deg/s]",
                      "η_a1 [deg]", "modes' rolling moment [N·m]"]
    for ax, channel, scale in ((fig.axes[9], "p_rad_s", np.degrees(1.0)),
                               (fig.axes[12], "ctrl_aileron_rad", np.degrees(1.0)),
                               (fig.axes[13], "p_g", np.degrees(1.0)),
                               (fig.axes[15], "modal_roll_n_m", 1.0)):
        np.testing.assert_allclose(ax.get_lines()[0].get_ydata(), scale * run[channel])
    gust_lines = [ln for ln in fig.axes[13].get_lines() if ln.get_label().startswith("p_g")]
    assert len(gust_lines) == 1  # the gust input once
    assert any("NRMSE 0.010" in t.get_text() for t in fig.axes[9].get_legend().get_texts())
    notes = " ".join(t.get_text() for t in fig.texts)
    assert "Lateral signs" in notes and "lateral-directional" in notes


def test_the_lateral_panels_choose_the_surface_and_the_lateral_gust_when_so_flown(captured):
    plotting.time_histories([_rolling("coupled", p_g=False)], "x.png", "t")
    labels = [ax.get_ylabel() for ax in captured[0].axes[8:]]
    assert labels[4] == "aileron δa [deg]" and labels[5] == "lateral gust v_g [m/s]"


def test_a_run_that_does_not_roll_keeps_the_eight_panels(captured):
    plotting.time_histories([_run("coupled")], "x.png", "t")
    assert len(captured[0].axes) == 8
