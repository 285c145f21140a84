"""Section loads in the 3-D scene (bioflex_jsb/sinks/mcap/scene_loads.py): the markers of a
gust run with the scene and the loads, read back with Google's protobuf runtime from the
file's own schema and checked against the loads topic's values at the same log time."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from bioflex_jsb.sinks.mcap import scene, scene_loads
from tests.tools import channel_metadata, decode_topic

pytest.importorskip("google.protobuf")
pytest.importorskip("foxglove_schemas_protobuf")

EXAGGERATION = 2.0
# Rounding only (as in tests/test_scene.py): a colour or a size is one or two double
# operations on the logged load and its 1 g value, a position a few on numbers below 1 m.
TOL = 1e-12


def _fly(path, build, duration_s: float, scene: float | None):
    """A coupled sharp 3 m/s gust from 0.2 s with both methods' section loads, logged to
    ``path`` (with the scene at ``scene``, or none)."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust

    desc = RunDescription("gust", "optimised", 15.0, models=("coupled",),
                          duration_s=duration_s, gust_start_s=0.2)
    log = sink.RunLog.open(path, desc, wing_variant=build.variant.as_dict(), scene=scene)
    try:
        run = run_gust(Airframe(), build.model, "coupled",
                       RunConfig(15.0, parse_gust("sharp:3"), duration_s, 0.2),
                       recorder=log.recorder("coupled"), loads=build)
    finally:
        log.close()
    assert not run.stopped
    return path


@pytest.fixture(scope="module")
def build():
    return build_wing(VARIANTS["optimised"])


@pytest.fixture(scope="module")
def gust_log(tmp_path_factory, build):
    return _fly(tmp_path_factory.mktemp("scene_loads") / "gust.mcap", build, 1.0,
                EXAGGERATION)


def _spheres(msg) -> np.ndarray:
    """(spheres, 7): position x, y, z, diameter, r, g, b of a marker message."""
    ent = msg.entities[0]
    return np.array([(s.pose.position.x, s.pose.position.y, s.pose.position.z, s.size.x,
                      s.color.r, s.color.g, s.color.b) for s in ent.spheres])


def test_a_marker_message_at_every_scene_sample_with_the_loads(gust_log):
    wing = [ns for ns, _ in decode_topic(gust_log, "/bioflex/coupled/scene")]
    loads = [ns for ns, _ in decode_topic(gust_log, "/bioflex/coupled/loads")]
    markers = decode_topic(gust_log, "/bioflex/coupled/scene_loads")
    assert len(wing) == 60  # 1 s at 60 Hz
    assert [ns for ns, _ in markers] == [ns for ns in wing if ns in set(loads)]
    assert len(markers) >= 59  # the last step's loads may wait for a next step
    ent = markers[0][1].entities[0]
    assert (ent.frame_id, ent.id, ent.frame_locked) == ("coupled_body", "section_loads", True)
    meta = channel_metadata(gust_log, "/bioflex/coupled/scene_loads")
    assert meta["loads_method"] == "force_summation"
    assert "white r=1" in meta["loads_colour"] and "clip(|r|" in meta["loads_size"]


def test_colour_and_size_follow_the_load_over_its_1g_value(gust_log, build):
    """Each sphere's colour and diameter are the rule's for the logged load at its station
    over the 1 g value the loads channel states (force summation): the gust's bending peak
    turns the root sphere red and large, and the spheres sit on the deformed wing."""
    loads = dict(decode_topic(gust_log, "/bioflex/coupled/loads"))
    modal = dict(decode_topic(gust_log, "/bioflex/coupled/modal"))
    meta = channel_metadata(gust_log, "/bioflex/coupled/loads")
    one_g = json.loads(meta["static_1g"])
    stations = json.loads(meta["stations_m"])
    s = len(stations)
    markers = decode_topic(gust_log, "/bioflex/coupled/scene_loads")
    peak = 0.0
    mesh = scene.AircraftMesh(scene.wing_shape(build, max_stations=scene.SCENE_MESH_STATIONS),
                              scene.airframe_outline(), EXAGGERATION)  # the log's mesh
    for ns, msg in markers:
        sp = _spheres(msg)
        assert sp.shape == (2 * 2 * s, 7)  # starboard then port; bending then torque
        m = loads[ns]
        ratio = np.concatenate([np.array(m.fs_bending_n_m) / one_g["fs_bending_n_m"],
                                np.array(m.fs_torque_n_m) / one_g["fs_torque_n_m"]])
        for half in (sp[:2 * s], sp[2 * s:]):
            np.testing.assert_allclose(half[:, 3], scene_loads.diameter_m(ratio), atol=TOL)
            np.testing.assert_allclose(half[:, 4:], scene_loads.colour(ratio), atol=TOL)
        # rule by hand at the root's bending: white at 1, red at 2, blue at 0
        r = ratio[0]
        expect = (np.array(scene_loads.WHITE) + min(max(r - 1, 0), 1) * (
            np.array(scene_loads.RED) - scene_loads.WHITE)) if r > 1 else (
            np.array(scene_loads.BLUE) + min(max(r, 0), 1) * (
                np.array(scene_loads.WHITE) - scene_loads.BLUE))
        np.testing.assert_allclose(sp[0, 4:], expect, atol=TOL)
        peak = max(peak, r)
        # on the deformed wing: the bending sphere on the elastic axis at the station, its
        # height the mesh's heave there (the mode shapes interpolated at the station)
        eta = np.array(modal[ns].eta_rad)
        heave = -EXAGGERATION * np.array([np.interp(stations, mesh.shape.stations_m, b)
                                          for b in mesh.shape.bending_m]).T @ eta
        np.testing.assert_allclose(sp[:s, 2], mesh.z0_m + heave, atol=TOL)
        np.testing.assert_allclose(sp[:s, 1], -np.array(stations), atol=TOL)
        np.testing.assert_allclose(sp[2 * s:3 * s, 1], np.array(stations), atol=TOL)
        np.testing.assert_allclose(sp[:s, 0], np.interp(stations, mesh.shape.stations_m,
                                                        mesh.ea_x_m), atol=TOL)
    assert peak > 1.5  # the 3 m/s gust: the root's bending well over its 1 g value
    root = max(markers, key=lambda item: _spheres(item[1])[0, 3])
    big = _spheres(root[1])[0]
    assert big[3] > 1.5 * scene_loads.DIAMETER_M and big[4] == 1.0 and big[6] < 0.6


def test_the_rule_of_colour_and_size():
    r = np.array([-1.0, 0.0, 0.5, 1.0, 1.5, 2.0, 5.0])
    c = scene_loads.colour(r)
    assert c[0].tolist() == c[1].tolist() == list(scene_loads.BLUE)
    assert c[3].tolist() == list(scene_loads.WHITE)
    # white + (red − white) at the clip: red to rounding (1e-15)
    assert c[5] == pytest.approx(scene_loads.RED, abs=1e-15) and c[6].tolist() == c[5].tolist()
    assert c[2] == pytest.approx((np.array(scene_loads.BLUE) + scene_loads.WHITE) / 2)
    d = scene_loads.diameter_m(r)
    assert d[3] == scene_loads.DIAMETER_M
    assert d[1] == scene_loads.R_MIN * scene_loads.DIAMETER_M  # never vanishes
    assert d[6] == scene_loads.R_MAX * scene_loads.DIAMETER_M
    assert d[0] == d[3]  # |r|: a load reversed to −1 g is as large as 1 g, and blue
    assert math.isclose(d[4], 1.5 * scene_loads.DIAMETER_M)


def test_the_compiled_markers_are_the_numpy_ones(build):
    """A run log's marker doubles (the compiled _Stations.floats) are marker_floats'
    (numpy): ratios in each part of the rule (below 0, 0-1, 1-2, above 2, ±inf, NaN), the
    root station on the plane of symmetry (its ±0 y), the loads picked from wider rows.
    Identical here (0 of 5760 differ, measured); 1e-15 (m, or of a colour) leaves room for
    a libm whose sin/cos round one ulp apart from numpy's."""
    mesh = scene.AircraftMesh(scene.wing_shape(build, max_stations=scene.SCENE_MESH_STATIONS),
                              scene.airframe_outline(), EXAGGERATION)
    st = scene_loads._Stations(mesh, [0.0, 0.2, 0.4, 0.6])
    rng = np.random.default_rng(3)
    m, s = 40, 4
    eta = rng.normal(0.0, 0.3, (m, mesh.shape.n_modes))
    one_g = rng.uniform(0.5, 5.0, 2 * s) * np.where(np.arange(2 * s) % 3, 1.0, -1.0)
    ratio = rng.uniform(-1.5, 3.5, (m, 2 * s))
    ratio[0, :6] = -np.inf, np.inf, np.nan, 0.0, 1.0, 2.0
    values = np.column_stack([rng.normal(size=m), ratio * one_g])
    cols = np.arange(1, 2 * s + 1, dtype=np.intp)
    got = st.floats(values, cols, one_g, eta)
    ref = scene_loads.marker_floats(st, values[:, cols] / one_g, eta)
    assert got.shape == ref.shape == (m, 2 * 2 * s * scene_loads.FLOATS_PER_SPHERE)
    np.testing.assert_allclose(got, ref, rtol=0.0, atol=1e-15)
    # the signed zeros of the root's y, as numpy has them (bytes of the log)
    y = got.reshape(m, 4 * s, scene_loads.FLOATS_PER_SPHERE)[:, :, 1]
    y_ref = ref.reshape(m, 4 * s, scene_loads.FLOATS_PER_SPHERE)[:, :, 1]
    assert (np.signbit(y) == np.signbit(y_ref)).all()


def test_no_markers_without_the_scene(tmp_path, build):
    path = _fly(tmp_path / "plain.mcap", build, 0.3, None)
    topics = {c["topic"] for c in sink.summarise(path)["channels"]}
    assert "/bioflex/coupled/loads" in topics and "/bioflex/coupled/scene_loads" not in topics
