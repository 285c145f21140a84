"""modes --animate and --mode-sheet (bioflex_jsb/sinks/mcap/scene_modes.py): every mode in
turn, labelled with the frequency and damping the modes table gives, the wing twisting as the
mode's shape; the sheet a PNG of ours; bad requests refused in one line."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb import api, cli
from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.sinks.mcap import scene_modes
from tests.tools import decode_topic

# Rounding only (a cosine and a few products of doubles below 1): see tests/test_scene.py
TOL = 1e-12
N_FRAMES = round(scene_modes.CYCLES * scene_modes.DISPLAY_PERIOD_S * scene_modes.FRAME_RATE_HZ)


@pytest.fixture(scope="module")
def animated(tmp_path_factory):
    d = tmp_path_factory.mktemp("modes")
    status = cli.main(["modes", "--animate", str(d / "modes.mcap"), "--mode-sheet",
                       str(d / "sheet.png"), "--models", "coupled", "--json"])
    assert status == 0
    return d


def test_each_mode_in_turn_labelled_with_the_tables_numbers(animated):
    events = decode_topic(animated / "modes.mcap", "/bioflex/events")
    frames = decode_topic(animated / "modes.mcap", "/bioflex/modes/scene")
    assert len(events) == 6 and len(frames) == 6 * N_FRAMES
    build = build_wing(VARIANTS["optimised"])
    table = api.modes(build, 15.0, "coupled")
    for i, (ns, ev) in enumerate(events[:3]):
        f = build.modes.frequencies_rad_s[i] / (2 * math.pi)
        assert ev.message.startswith(f"structural mode {i + 1} ") and f"{f:.2f} Hz" in ev.message
        assert ns == round(i * scene_modes.CYCLES * scene_modes.DISPLAY_PERIOD_S * 1e9)
    for i, (_, ev) in enumerate(events[3:]):
        m = table.get(f"aeroelastic_{i + 1}")
        assert ev.message.startswith(f"aeroelastic_{i + 1} at 15 m/s")
        assert f"{m.frequency_rad_s / (2 * math.pi):.2f} Hz" in ev.message
        assert f"damping ratio {m.damping:.3f}" in ev.message
    for k, (ns, ev) in enumerate(events):  # the label in the scene is the event's text
        assert frames[k * N_FRAMES][0] == ns
        assert frames[k * N_FRAMES][1].entities[0].texts[0].text == ev.message


def test_a_structural_mode_twists_the_wing_as_its_shape(animated):
    build = build_wing(VARIANTS["optimised"])
    frames = decode_topic(animated / "modes.mcap", "/bioflex/modes/scene")
    y = np.concatenate([[0.0], build.aero.stations_m, [build.aero.semispan_m]])
    peak = scene_modes.PEAK_TIP_TWIST_RAD
    for i in range(3):
        shape = np.interp(y, build.modes.stations_m, build.modes.twist_rad[i])
        for frame, phase in ((0, 1.0), (N_FRAMES // (4 * scene_modes.CYCLES), 0.0)):
            pts = frames[i * N_FRAMES + frame][1].entities[0].triangles[0].points
            xz = np.array([(p.x, p.z) for p in pts]).reshape(-1, 2, 2)
            twist = np.arctan2(xz[:, 0, 1] - xz[:, 1, 1], xz[:, 0, 0] - xz[:, 1, 0])
            expect = peak * phase * shape / build.modes.twist_rad[i][-1]
            assert twist == pytest.approx(expect, abs=TOL)


def test_the_sheet_is_a_png_of_ours(animated):
    from PIL import Image

    from bioflex_jsb.sinks.plotting import is_our_plot

    with Image.open(animated / "sheet.png") as im:
        assert im.size[0] > 1500  # six panels at 150 dpi
    assert is_our_plot(animated / "sheet.png")


@pytest.mark.parametrize("extra, says", [
    (["--speed", "12", "--speed", "15"], "at one --speed"),
    (["--aero", "unsteady"], "drop --aero unsteady"),
])
def test_refused_in_one_line(tmp_path, capsys, extra, says):
    status = cli.main(["modes", "--animate", str(tmp_path / "a.mcap"), *extra])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and says in err[0]
    assert not (tmp_path / "a.mcap").exists()


def test_a_users_file_is_not_replaced(tmp_path, capsys):
    mine = tmp_path / "mine.mcap"
    mine.write_text("keep me")
    status = cli.main(["modes", "--animate", str(mine)])
    out = capsys.readouterr()
    err = out.err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "--force" in err[0]
    assert mine.read_text() == "keep me" and out.out == ""  # refused before any work


def test_the_modes_layout_names_what_the_animation_holds(animated):
    import json
    from pathlib import Path

    from bioflex_jsb.sinks import mcap as sink

    layout = json.loads((Path(__file__).resolve().parents[1] / "docs" / "foxglove"
                         / "modes_layout.json").read_text())
    have = {c["topic"] for c in sink.summarise(animated / "modes.mcap")["channels"]}
    three = layout["configById"]["3D!bioflexmodes"]
    assert three["followTf"] == sink.body_frame(scene_modes.MODEL)
    assert set(three["topics"]) <= have
    assert layout["configById"]["RosOut!bioflexmodesevents"]["topicToRender"] in have


def test_a_bending_mode_is_scaled_on_its_tip_heave():
    """A sailplane's first mode bends without twisting: scaled on its tip heave (up at phase
    0, PEAK_TIP_HEAVE_FRAC of the semispan in the animation), not refused; the sheet's
    shapes then equal the beam's mode per unit amplitude."""
    build = api.load_aircraft("sgs_elastic").wing()
    shapes = scene_modes.mode_shapes(build, 25.0)
    first = shapes[0]
    assert first.kind == "structural"
    tip_heave_up_m = -complex(build.modes.bending_m[:, -1] @ first.eta)
    semispan_m = float(build.modes.stations_m[-1])
    # animated at PEAK_TIP_TWIST_RAD x eta: the tip rises by the heave fraction of the span
    animated_m = scene_modes.PEAK_TIP_TWIST_RAD * tip_heave_up_m
    assert animated_m.real == pytest.approx(scene_modes.PEAK_TIP_HEAVE_FRAC * semispan_m,
                                            rel=1e-12)
    assert abs(animated_m.imag) < 1e-12
    # a twist mode keeps the unit tip twist
    twisting = next(s for s in shapes[:3] if abs(build.modes.twist_rad[:, -1] @ s.eta) > 0.5)
    assert complex(build.modes.twist_rad[:, -1] @ twisting.eta) == pytest.approx(1.0, abs=1e-12)
