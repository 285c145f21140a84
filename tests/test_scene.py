"""The aircraft in 3-D (bioflex_jsb/sinks/mcap/scene.py): foxglove.SceneUpdate messages read
back with Google's protobuf runtime from the file's own schema, the mesh checked against the
mode shapes and the logged modal coordinates."""

from __future__ import annotations

import math

import numpy as np
import pytest

from bioflex_jsb.flight_dynamics.wing_model import VARIANTS, build_wing
from bioflex_jsb.simulation.channels import channel_units
from bioflex_jsb.simulation.run import RunDescription
from bioflex_jsb.sinks import mcap as sink
from bioflex_jsb.sinks.mcap import scene
from tests.tools import decode_topic, published_files

pytest.importorskip("google.protobuf")
pytest.importorskip("foxglove_schemas_protobuf")

EXAGGERATION = 4.0
# Rounding only: every vertex is a few double operations on numbers below 1 m, so 1e-12 m
# (and 1e-12 rad) holds with a margin of 1e3 over the ~1e-15 seen; the tip's bending
# displacement being checked is ~1e-4 m, its twist ~1 rad.
TOL = 1e-12


@pytest.fixture(scope="module")
def build():
    return build_wing(VARIANTS["optimised"])


@pytest.fixture(scope="module")
def gust_log(tmp_path_factory, build):
    """1.2 s of the Fig. 21 case (coupled), logged with the scene at EXAGGERATION."""
    from bioflex_jsb.drivers.gust import RunConfig, run_gust
    from bioflex_jsb.runtime.fdm import Airframe
    from bioflex_jsb.simulation.gusts import parse_gust

    path = tmp_path_factory.mktemp("scene") / "gust.mcap"
    desc = RunDescription("gust", "optimised", 15.0, models=("coupled",), duration_s=1.2,
                          gust_start_s=0.2)
    log = sink.RunLog.open(path, desc, wing_variant=build.variant.as_dict(),
                           scene=EXAGGERATION)
    try:
        run = run_gust(Airframe(), build.model, "coupled",
                       RunConfig(15.0, parse_gust("sharp:3"), 1.2, 0.2),
                       recorder=log.recorder("coupled"))
    finally:
        log.close()
    assert not run.stopped
    return path


def test_embedded_scene_schemas_are_the_published_ones():
    from foxglove_schemas_protobuf import SceneUpdate_pb2

    from bioflex_jsb.sinks.mcap_io import foxglove_descriptors as fox

    published = published_files(SceneUpdate_pb2.DESCRIPTOR)
    assert list(published) == list(fox.SCENE_UPDATE_FILES)
    assert fox.files(fox.SCENE_UPDATE_FILES) == list(published.values())


def test_sixty_messages_a_second_at_the_first_step_of_each_bin(gust_log):
    msgs = decode_topic(gust_log, "/bioflex/coupled/scene")
    steps = [ns for ns, _ in decode_topic(gust_log, "/bioflex/coupled/modal")]
    t = np.array(steps) * 1e-9
    bins = np.floor(t * scene.SCENE_RATE_HZ + 1e-6)
    first = np.array(steps)[np.flatnonzero(np.diff(np.concatenate([[-1], bins])))]
    assert [ns for ns, _ in msgs] == first.tolist()
    assert len(msgs) == 72  # 1.2 s at 60 Hz
    ent = msgs[0][1].entities[0]
    assert (ent.frame_id, ent.id, ent.frame_locked) == ("coupled_body", "wing", True)
    assert ent.timestamp.seconds * 10**9 + ent.timestamp.nanos == msgs[0][0]
    # the rigid parts: once per chunk (0.9 s: chunks start at 0 and 0.9 s), at its first step
    air = decode_topic(gust_log, "/bioflex/coupled/airframe")
    chunk = sink.CHUNK_SPAN_S
    assert [ns for ns, _ in air] == [steps[0], steps[int(np.searchsorted(t, chunk - 1e-9))]]
    body = air[0][1].entities[0]
    assert (body.frame_id, body.id) == ("coupled_body", "airframe")
    assert len(body.triangles) == len(scene.AIRFRAME_PARTS)
    fuselage = np.array([(p.x, p.y, p.z) for p in body.triangles[0].points])
    outline = scene.airframe_outline()
    assert np.ptp(fuselage[:, 0]) == pytest.approx(outline.fuselage_length_m, abs=TOL)
    assert 2 * np.abs(fuselage[:, 1:]).max() <= outline.fuselage_max_diameter_m + TOL
    info = sink.summarise(gust_log)["metadata"][sink.schemas.SCENE_METADATA]
    assert float(info["exaggeration"]) == EXAGGERATION


def test_the_tip_moves_by_the_mode_shapes_times_eta(gust_log, build):
    """At the logged step where η₁ is largest: the tip's elastic axis is displaced by
    −E Σ bending_m(tip) η (down positive) and the tip chord turned by E Σ twist_rad(tip) η,
    the shapes read straight from the wing's ModalData (its last station is the tip)."""
    modes = build.modes
    assert modes.stations_m[-1] == pytest.approx(build.aero.semispan_m, abs=1e-12)
    modal = dict(decode_topic(gust_log, "/bioflex/coupled/modal"))
    msgs = decode_topic(gust_log, "/bioflex/coupled/scene")
    ns, msg = max(msgs, key=lambda m: abs(modal[m[0]].eta_rad[0]))
    eta = np.array(modal[ns].eta_rad)
    assert abs(eta[0]) > 0.05  # the gust has deformed the wing
    tris = msg.entities[0].triangles
    assert len(tris) == len(scene.WING_PARTS)
    k = min(len(build.aero.stations_m), scene.SCENE_MESH_STATIONS - 2) + 2  # root, strips, tip
    for half, sign in ((tris[0], -1.0), (tris[1], 1.0)):
        pts = np.array([(p.x, p.y, p.z) for p in half.points])
        assert pts.shape == (2 * k, 3)
        assert len(half.indices) == 6 * (k - 1)
        assert pts[-1, 1] == pytest.approx(sign * build.aero.semispan_m, abs=TOL)
        le, te = pts[-2], pts[-1]
        xe = float(np.broadcast_to(modes.x_elastic_frac, modes.stations_m.shape)[-1])
        ea_z = le[2] + xe * (te[2] - le[2])
        z0 = scene.airframe_outline().wing_height_m
        assert -(ea_z - z0) == pytest.approx(EXAGGERATION * modes.bending_m[:, -1] @ eta,
                                             abs=TOL)
        assert abs(modes.bending_m[:, -1] @ eta) > 1e-6  # a displacement TOL can see
        twist = math.atan2(le[2] - te[2], le[0] - te[0])
        assert twist == pytest.approx(EXAGGERATION * modes.twist_rad[:, -1] @ eta, abs=TOL)
        chord = math.hypot(le[0] - te[0], le[2] - te[2])
        assert chord == pytest.approx(build.aero.chord_m[-1], abs=TOL)  # a rigid rotation
        root_le, root_te = pts[0], pts[1]
        assert root_le[2] == pytest.approx(z0, abs=TOL) == root_te[2]  # clamped root
    gust = dict(decode_topic(gust_log, "/bioflex/coupled/gust"))[ns].w_g_m_s
    arrow = msg.entities[0].arrows[0]
    assert arrow.shaft_length + arrow.head_length == pytest.approx(
        scene.GUST_ARROW_M_PER_M_S * abs(gust), abs=TOL)


def test_the_compiled_samples_are_the_numpy_ones(build):
    """A run log's scene doubles (AircraftMesh.sample_floats, compiled) are scene_floats'
    (numpy, the mode sheet's): gusts up, down, ±0 and NaN, rolled and pitched samples, the
    columns picked from wider rows. Identical here (0 of 5800 doubles differ, measured);
    1e-15 m, an ulp or so at 0.5 m, leaves room for a libm whose sin/cos round one ulp
    apart from numpy's."""
    mesh = scene.AircraftMesh(scene.wing_shape(build, max_stations=scene.SCENE_MESH_STATIONS),
                              scene.airframe_outline(), EXAGGERATION)
    rng = np.random.default_rng(7)
    m = 40
    eta = rng.normal(0.0, 0.3, (m, mesh.shape.n_modes))
    w, phi, theta = rng.normal(0.0, 3.0, m), rng.normal(0.0, 0.5, m), rng.normal(0.0, 0.3, m)
    w[:3] = 0.0, -0.0, np.nan
    rows = np.column_stack([rng.normal(size=m), theta, w, rng.normal(size=m), phi])
    got = mesh.sample_floats(rows, np.array([2, 4, 1], dtype=np.intp), eta)
    ref = scene.scene_floats(mesh, eta, w, phi, theta)
    assert got.shape == ref.shape == (m, 9 + 8 * len(mesh.y_m))
    np.testing.assert_allclose(got, ref, rtol=0.0, atol=1e-15)
    # a NaN gust: the arrow's tail and lengths NaN, its orientation (up) and the wing not
    assert np.isnan(got[2, [0, 1, 2, 7, 8]]).all() and not np.isnan(got[2, 3:7]).any()
    assert not np.isnan(got[:, 9:]).any()


def test_no_scene_unless_asked(tmp_path):
    desc = RunDescription("gust", "optimised", 15.0, models=("coupled",), duration_s=0.1)
    log = sink.RunLog.open(tmp_path / "plain.mcap", desc)
    _feed(log, np.zeros(3), 10)
    log.close()
    topics = {c["topic"] for c in sink.summarise(tmp_path / "plain.mcap")["channels"]}
    assert topics and not topics & {"/bioflex/coupled/scene", "/bioflex/coupled/airframe"}


def _feed(log, eta, n_steps, dt=1 / 960):
    names = tuple(channel_units(3))
    for k in range(n_steps):
        row = dict.fromkeys(names, 0.0)
        row.update(latitude_rad=0.7, longitude_rad=0.2, altitude_m=100.0, w_g=-2.0,
                   theta_rad=0.3, airspeed_m_s=15.0, throttle=0.5)
        row.update({f"eta{i + 1}": float(e) for i, e in enumerate(eta)})
        log.sample("coupled", k * dt, row)


def test_samples_as_dicts_get_the_scene_too(tmp_path, build):
    """The dict path (RunLog.sample, the SITL loop): a fixed η, a downward gust, the aircraft
    pitched up 0.3 rad: the arrow points down in the world."""
    desc = RunDescription("sitl", "optimised", 15.0, models=("coupled",), duration_s=0.5)
    log = sink.RunLog.open(tmp_path / "sitl.mcap", desc, scene=1.0)
    eta = np.array([0.1, -0.05, 0.02])
    _feed(log, eta, 480)
    log.close()
    msgs = decode_topic(tmp_path / "sitl.mcap", "/bioflex/coupled/scene")
    assert len(msgs) == 30
    ent = msgs[-1][1].entities[0]
    tip = [(p.x, p.z) for p in ent.triangles[0].points][-2:]
    twist = math.atan2(tip[0][1] - tip[1][1], tip[0][0] - tip[1][0])
    assert twist == pytest.approx(build.modes.twist_rad[:, -1] @ eta, abs=TOL)
    a = ent.arrows[0]
    q = np.array([a.pose.orientation.x, a.pose.orientation.y, a.pose.orientation.z,
                  a.pose.orientation.w])
    x_axis = _rotate(q, np.array([1.0, 0.0, 0.0]))  # the arrow's direction, body frame
    # world down in FLU body axes for pitch θ (roll 0): (−sin θ, 0, −cos θ)
    assert x_axis == pytest.approx([-math.sin(0.3), 0.0, -math.cos(0.3)], abs=TOL)
    assert a.shaft_length + a.head_length == pytest.approx(0.2, abs=TOL)


def _rotate(q, v):
    x, y, z, w = q
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    return r @ v


def test_protobufjs_reads_the_scene_as_foxglove_does(gust_log, tmp_path_factory):
    """@mcap/core's indexed reader and protobufjs (Foxglove's decoder) from the file's own
    schema: every scene message decodes, in log-time order, to the vertices Google's
    runtime reads."""
    from tests.test_mcap import _node_checker

    result = _node_checker(tmp_path_factory)(gust_log)
    assert result["counts"]["/bioflex/coupled/scene"] == 72
    assert result["counts"]["/bioflex/coupled/airframe"] == 2
    assert result["ordered"] is True and result["dataCrcOk"] is True
    theirs = result["samples"]["/bioflex/coupled/scene"]["entities"][0]  # the second message
    mine = decode_topic(gust_log, "/bioflex/coupled/scene")[1][1].entities[0]
    for t, m in zip(theirs["triangles"], mine.triangles, strict=True):
        assert [tuple(p.get(k, 0.0) for k in "xyz") for p in t["points"]] == [
            (p.x, p.y, p.z) for p in m.points]  # toObject leaves out zeros (defaults: false)
        assert t["indices"] == list(m.indices)
    assert theirs["arrows"][0].get("shaftLength", 0.0) == mine.arrows[0].shaft_length


def test_another_aircraft_is_drawn_from_its_own_definition(tmp_path, capsys):
    """A gust log of the SGS (a definition on JSBSim's sailplane) draws that wing: the
    definition's semispan and chord and the outline scaled to its span;
    before, its log had no scene (the mesh was the prototype's)."""
    from bioflex_jsb import api, cli
    from bioflex_jsb.sinks.mcap import scene_view

    path = tmp_path / "sgs.mcap"
    assert cli.main(["gust", "--aircraft", "sgs_elastic", "--duration", "0.6",
                     "--gust-start", "0.1", "--models", "coupled", "--json",
                     "--out", str(path)]) == 0
    capsys.readouterr()
    build = api.load_aircraft("sgs_elastic").wing()
    shot = scene_view.scene_at(path, "coupled")
    pts = np.concatenate([scene_view.triangles(t).reshape(-1, 3)
                          for t in shot["wing"]["triangles"]])
    semispan = float(build.aero.semispan_m)
    assert semispan == pytest.approx(7.036)
    assert np.abs(pts[:, 1]).max() == pytest.approx(semispan, rel=1e-9)
    chord = pts[:, 0].max() - pts[:, 0].min()
    assert chord == pytest.approx(1.0, abs=0.05)  # 1 m chord; the twist tilts it a little
    air = np.concatenate([scene_view.triangles(t).reshape(-1, 3)
                          for t in shot["airframe"]["triangles"]])
    # the prototype's outline x 14.073/1.7: a fuselage several metres long, not 1 m
    assert air[:, 0].max() - air[:, 0].min() > 4.0
