"""The wing's section loads in the 3-D scene: coloured spheres at the monitoring stations.

``/bioflex/<model>/scene_loads`` (``foxglove.SceneUpdate``, entity :data:`ENTITY_ID` in the
body frame ``<model>_body``, ``frame_locked``), one message per scene sample (the first step
of each 1/:data:`~.scene.SCENE_RATE_HZ` bin, the times the wing's mesh is drawn at), from the
very rows the loads topic ``/bioflex/<model>/loads`` carries (:class:`LoadMarkers` wraps the
run's :class:`~.loads_topic.LoadsTopic`: each block it writes is also drawn here, as a chunk
of its own after the loads' chunk).

At each monitoring station (``stations_m``, both halves) two spheres:

* **bending** on the elastic axis, for the bending moment ``bending_n_m``;
* **torque** on the leading edge, for the torque ``torque_n_m``;

each of the force-summation loads when the run has them (the complete load), else the
mode-displacement ones. A sphere shows the load's ratio r = load / its 1 g value (the
channel metadata's ``static_1g``, the elastic trim's loads): its colour blue (r ≤ 0) →
white (r = 1, the 1 g load) → red (r ≥ 2), linear in between; its diameter
:data:`DIAMETER_M` · clip(|r|, :data:`R_MIN`, :data:`R_MAX`). The spheres ride on the wing
as drawn: the station's elastic axis heaves and its chord twists by the mode shapes times the
scene sample's η and the exaggeration (:mod:`.scene`). The legend is the ``bioflex.scene``
metadata's ``loads_*`` entries (:func:`legend`).
"""

from __future__ import annotations

import numpy as np

from bioflex_jsb.sinks.mcap.formatting import F, Records, _timestamp
from bioflex_jsb.sinks.mcap.protobuf import I64, tag
from bioflex_jsb.sinks.mcap.scene import _consts, _dbl, _head, _sub
from bioflex_jsb.sinks.mcap.schemas import body_frame, topic
from bioflex_jsb.sinks.mcap.writer import _signals_deferred

GROUP = "scene_loads"  # /bioflex/<model>/scene_loads
ENTITY_ID = "section_loads"
QUANTITIES = ("bending_n_m", "torque_n_m")  # sphere sets, in this order in each message
# DECISION (drawing only): a sphere at the 1 g load is 25 mm across (a fifth of the tip
# chord); the size follows |r| between a fifth and three times the 1 g load (a 3 m/s gust
# gives r ≈ 2-3 at the root, tests/test_scene_loads.py), so a sphere never vanishes or
# swallows the wing
DIAMETER_M = 0.025
R_MIN, R_MAX = 0.2, 3.0
# colours [r, g, b] at r = 0 (and below), 1 and 2 (and above); alpha 1
BLUE, WHITE, RED = (0.15, 0.35, 1.0), (1.0, 1.0, 1.0), (1.0, 0.15, 0.1)
FLOATS_PER_SPHERE = 9  # the doubles a message's sphere takes: position x y z, size, r g b


def legend(method: str) -> dict[str, str]:
    """The markers' legend (strings, for the ``bioflex.scene`` metadata)."""
    return {
        "loads_topic": topic("<model>", GROUP), "loads_entity": ENTITY_ID,
        "loads_method": method,
        "loads_spheres": "per monitoring station and half: bending moment on the elastic "
                         "axis, torque on the leading edge",
        "loads_colour": "r = load / 1 g load: blue r<=0, white r=1, red r>=2 (linear)",
        "loads_size": f"diameter {DIAMETER_M:g} m x clip(|r|, {R_MIN:g}, {R_MAX:g})",
    }


def colour(ratio: np.ndarray) -> np.ndarray:
    """(…, 3) colour of the load ratios ``ratio`` (module docstring)."""
    r = np.asarray(ratio, dtype=float)[..., None]
    lo = np.asarray(BLUE) + np.clip(r, 0.0, 1.0) * (np.asarray(WHITE) - np.asarray(BLUE))
    hi = np.asarray(WHITE) + np.clip(r - 1.0, 0.0, 1.0) * (np.asarray(RED) - np.asarray(WHITE))
    return np.where(r <= 1.0, lo, hi)


def diameter_m(ratio: np.ndarray) -> np.ndarray:
    """The spheres' diameters [m] for the load ratios ``ratio``."""
    return DIAMETER_M * np.clip(np.abs(np.asarray(ratio, dtype=float)), R_MIN, R_MAX)


def _sphere() -> list:
    """A SpherePrimitive (field 9 of SceneEntity): pose (position variable, no rotation),
    size (x, y, z) and colour (r, g, b variable, alpha 1)."""
    pose = _sub(1, _sub(1, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F])
                + _consts(2, (0.0, 0.0, 0.0, 1.0)))
    size = _sub(2, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F])
    rgba = _sub(3, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F, _dbl(4, 1.0)])
    return _sub(9, pose + size + rgba)


class _Stations:
    """The monitoring stations on the scene's mesh: the elastic axis's body x and the
    shapes (bending, twist) interpolated at them, the chord ahead of the axis."""

    def __init__(self, mesh, stations_m) -> None:
        y = np.asarray(stations_m, dtype=float)
        shape = mesh.shape
        k = shape.stations_m

        def at(rows) -> np.ndarray:
            return np.array([np.interp(y, k, r) for r in np.atleast_2d(rows)])

        self.y_m = y
        self.ea_x_m = np.interp(y, k, mesh.ea_x_m)
        self.le_ahead_m = np.interp(y, k, mesh.chord_fwd_m[0])  # leading edge ahead of it
        self.bending_m, self.twist_rad = at(shape.bending_m), at(shape.twist_rad)
        self.z0_m, self.exaggeration = mesh.z0_m, mesh.exaggeration

    def points(self, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(m, S, 3) body positions [m] of the elastic axis and of the leading edge at the
        starboard stations for the modal coordinates ``eta`` (m, n)."""
        e = self.exaggeration
        twist = e * eta @ self.twist_rad
        heave = -e * eta @ self.bending_m
        m, s = twist.shape
        ea = np.stack([np.broadcast_to(self.ea_x_m, (m, s)), np.broadcast_to(-self.y_m, (m, s)),
                       self.z0_m + heave], axis=-1)
        le = ea + np.stack([self.le_ahead_m * np.cos(twist), np.zeros((m, s)),
                            self.le_ahead_m * np.sin(twist)], axis=-1)
        return ea, le


class LoadMarkers:
    """The loads topic of a run (``topic``: its :class:`~.loads_topic.LoadsTopic`) with the
    markers drawn from each block it writes (:meth:`rows`); ``scene`` is the log's
    :class:`~.scene.SceneLog`, ``layout`` the run's ``meta["loads"]``."""

    def __init__(self, scene, topic_, model: str, layout: dict) -> None:
        self._topic, self._scene, self._model = topic_, scene, model
        methods = layout["methods"]
        tag_ = "fs" if "force_summation" in methods else "md"
        self.method = "force_summation" if tag_ == "fs" else "mode_displacement"
        names = list(layout["names"])
        s = len(layout["stations_m"])
        self._cols = [names.index(f"loads_{tag_}_{q}_s{j}") for q in QUANTITIES
                      for j in range(s)]
        static = layout["static_1g"]
        self.one_g = np.array([static[f"loads_{tag_}_{q}_s{j}"] for q in QUANTITIES
                               for j in range(s)], dtype=float)
        if not np.all(np.abs(self.one_g) > 0.0):  # a ratio needs a 1 g load
            raise ValueError(f"the {model} run has a zero 1 g load at a station: no ratio "
                             "to draw")
        self.stations = _Stations(scene.mesh, layout["stations_m"])
        self._n_stations = s
        w = scene._writer
        scene.remember_eta(model)
        self.marker_channel_id = w.add_channel(topic(model, GROUP), scene.schema_id(),
                                               {"model": model, **legend(self.method)})
        frame = body_frame(model)
        spheres = [p for _ in range(2 * len(QUANTITIES) * s) for p in _sphere()]
        head = _head(frame, ENTITY_ID)

        def pieces(ls: int, ln: int) -> list[list]:
            return [_sub(2, _timestamp(1, ls, ln) + head + spheres)]

        self._records = Records([self.marker_channel_id], pieces, True)
        self.marker_seq = 0
        self.marker_messages = 0  # logged

    # the loads topic's own figures
    @property
    def channel_id(self) -> int:
        return self._topic.channel_id

    @property
    def n_columns(self) -> int:
        return self._topic.n_columns

    @property
    def seq(self) -> int:
        return self._topic.seq

    @property
    def messages(self) -> int:
        return self._topic.messages

    def rows(self, time_s, values) -> None:
        """The loads topic's block (:meth:`LoadsTopic.rows`), then the markers of its
        steps that are scene samples, as a chunk of their own."""
        self._topic.rows(time_s, values)
        got = self.build(time_s, values)
        if got is not None:
            w = self._scene._writer
            with _signals_deferred():
                w.append_block(*got)
                w.close_chunk()

    def stop(self) -> None:
        self._topic.stop()

    def ratios(self, values: np.ndarray) -> np.ndarray:
        """(m, 2·S) load / 1 g load of the rows ``values`` (bending at the S stations, then
        torque)."""
        return np.asarray(values, dtype=float)[:, self._cols] / self.one_g

    def build(self, time_s, values):
        """The records and index of the markers at the steps of ``time_s`` the scene drew
        (their η kept by the scene); None if none."""
        ns = np.rint(np.asarray(time_s, dtype=float) * 1e9).astype(np.int64)
        eta_at = self._scene.drawn_eta(self._model)
        pick = [i for i, t in enumerate(ns.tolist()) if t in eta_at]
        if not pick:
            return None
        eta = np.array([eta_at.pop(int(ns[i])) for i in pick])
        r = self.ratios(np.asarray(values)[pick])  # (m, 2S)
        s = self._n_stations
        ea, le = self.stations.points(eta)  # (m, S, 3) starboard
        m = len(pick)
        pos = np.concatenate([ea, le], axis=1)  # (m, 2S, 3): bending spheres, torque spheres
        blocks = []
        for sign in (1.0, -1.0):  # starboard (−y), port (+y)
            p = pos * np.array([1.0, sign, 1.0])
            d = diameter_m(r)[..., None]
            blocks.append(np.concatenate([p, np.repeat(d, 3, axis=-1), colour(r)], axis=-1))
        floats = np.concatenate(blocks, axis=1).reshape(m, 2 * 2 * s * FLOATS_PER_SPHERE)
        block, index = self._records.build(ns[pick], floats, self.marker_seq)
        self.marker_seq += m
        self.marker_messages += m
        return block, index
