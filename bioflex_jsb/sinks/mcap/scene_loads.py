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
metadata's ``loads_*`` entries (:func:`legend`). A chunk's markers are one compiled pass
(:func:`_marker_floats`, the arithmetic of :func:`marker_floats`, which
tests/test_scene_loads.py holds it to).
"""

from __future__ import annotations

import numba
import numpy as np

from bioflex_jsb.simulation.step_kernel import guard_cache
from bioflex_jsb.sinks.mcap.schemas import body_frame, topic
from bioflex_jsb.sinks.mcap_io.protobuf import I64, tag
from bioflex_jsb.sinks.mcap_io.records import F, Records, consts, dbl, entity_head, sub, timestamp
from bioflex_jsb.sinks.mcap_io.writer import signals_deferred

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
_COLOURS = tuple(np.array(c, dtype=float) for c in (BLUE, WHITE, RED))


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
    pose = sub(1, sub(1, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F])
                + consts(2, (0.0, 0.0, 0.0, 1.0)))
    size = sub(2, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F])
    rgba = sub(3, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F, dbl(4, 1.0)])
    return sub(9, pose + size + rgba)


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
        self.minus_y_m = -y  # the starboard stations' body y
        self.ea_x_m = np.interp(y, k, mesh.ea_x_m)
        self.le_ahead_m = np.interp(y, k, mesh.chord_fwd_m[0])  # leading edge ahead of it
        self.bending_m, self.twist_rad = at(shape.bending_m), at(shape.twist_rad)
        self.z0_m, self.exaggeration = mesh.z0_m, mesh.exaggeration

    def twist_heave(self, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The stations' twist [rad] and heave [m, up] (m, S), the exaggeration included,
        for the modal coordinates ``eta`` (m, n)."""
        e = self.exaggeration
        return e * eta @ self.twist_rad, -e * eta @ self.bending_m

    def floats(self, values: np.ndarray, cols: np.ndarray, one_g: np.ndarray,
               eta: np.ndarray) -> np.ndarray:
        """:func:`marker_floats` of the ratios ``values[:, cols] / one_g`` (``values`` the
        samples' load rows, ``cols`` an ``intp`` array) on the wing of ``eta`` (m, n): the
        compiled pass (:func:`_marker_floats`)."""
        return _marker_floats(values, cols, one_g, *self.twist_heave(eta), self.ea_x_m,
                              self.minus_y_m, self.le_ahead_m, self.z0_m, *_COLOURS,
                              DIAMETER_M, R_MIN, R_MAX)

    def points(self, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(m, S, 3) body positions [m] of the elastic axis and of the leading edge at the
        starboard stations for the modal coordinates ``eta`` (m, n)."""
        twist, heave = self.twist_heave(eta)
        m, s = twist.shape
        ea = np.stack([np.broadcast_to(self.ea_x_m, (m, s)), np.broadcast_to(-self.y_m, (m, s)),
                       self.z0_m + heave], axis=-1)
        le = ea + np.stack([self.le_ahead_m * np.cos(twist), np.zeros((m, s)),
                            self.le_ahead_m * np.sin(twist)], axis=-1)
        return ea, le


def marker_floats(stations: _Stations, ratio: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """The doubles of m marker messages (numpy, the readable form of :func:`_marker_floats`):
    the load ratios ``ratio`` (m, 2·S: bending at the S stations, then torque) drawn on the
    wing of the modal coordinates ``eta`` (m, n); per message the starboard spheres, then
    the port ones, each position, size (x, y, z) and colour (r, g, b)."""
    r = np.asarray(ratio, dtype=float)
    ea, le = stations.points(eta)  # (m, S, 3) starboard
    m = len(r)
    pos = np.concatenate([ea, le], axis=1)  # (m, 2S, 3): bending spheres, torque spheres
    blocks = []
    for sign in (1.0, -1.0):  # starboard (−y), port (+y)
        p = pos * np.array([1.0, sign, 1.0])
        d = diameter_m(r)[..., None]
        blocks.append(np.concatenate([p, np.repeat(d, 3, axis=-1), colour(r)], axis=-1))
    return np.concatenate(blocks, axis=1).reshape(m, 2 * r.shape[1] * FLOATS_PER_SPHERE)


@numba.njit(cache=True, nogil=True, inline="always")
def _clip(x, lo, hi):
    """``numpy.clip`` of a double (NaN kept)."""
    if x != x:
        return x
    x = x if x > lo else lo
    return x if x < hi else hi


@numba.njit(cache=True, nogil=True)
def _marker_floats(values, cols, one_g, twist, heave, ea_x, minus_y, le_ahead, z0,
                   blue, white, red, diameter, r_min, r_max):
    """The doubles of the markers of m samples: ``values`` their load rows, ``cols`` the
    2·S columns drawn (bending at the S stations, then torque) and ``one_g`` their 1 g
    values; ``twist``, ``heave`` (m, S) the stations' (:meth:`_Stations.twist_heave`); per
    sample the starboard spheres (bending on the elastic axis, torque on the leading edge),
    then the port ones (y mirrored), each position, size (x, y, z), colour (r, g, b):
    operation for operation :func:`marker_floats` (the same doubles, tests/test_scene_loads.py;
    its numpy and the ratios' on a chunk's 54 samples took ~0.25 ms in a run, its caches
    cold, this ~0.05 ms)."""
    m, s = twist.shape
    n = 2 * s  # spheres a half
    out = np.empty((m, 2 * n * FLOATS_PER_SPHERE))
    for i in range(m):
        for p in range(n):
            r = values[i, cols[p]] / one_g[p]
            k = p % s
            x, y, z = ea_x[k], minus_y[k], z0 + heave[i, k]
            if p >= s:  # the torque's sphere: on the leading edge (y + 0 as numpy's
                # ea + (…, 0, …): the root's −0 becomes +0, a byte of the log)
                x, y, z = (x + le_ahead[k] * np.cos(twist[i, k]), y + 0.0,
                           z + le_ahead[k] * np.sin(twist[i, k]))
            d = diameter * _clip(np.abs(r), r_min, r_max)
            lo, hi = _clip(r, 0.0, 1.0), _clip(r - 1.0, 0.0, 1.0)
            for half in range(2):
                at = FLOATS_PER_SPHERE * (p + half * n)
                sign = 1.0 if half == 0 else -1.0
                # the position × (1, ±1, 1), as numpy's
                out[i, at], out[i, at + 1], out[i, at + 2] = x * 1.0, y * sign, z * 1.0
                out[i, at + 3], out[i, at + 4], out[i, at + 5] = d, d, d
                for c in range(3):
                    out[i, at + 6 + c] = (blue[c] + lo * (white[c] - blue[c]) if r <= 1.0
                                          else white[c] + hi * (red[c] - white[c]))
    return out


guard_cache(_clip)
guard_cache(_marker_floats)


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
        self._cols_array = np.array(self._cols, dtype=np.intp)
        static = layout["static_1g"]
        self.one_g = np.array([static[f"loads_{tag_}_{q}_s{j}"] for q in QUANTITIES
                               for j in range(s)], dtype=float)
        if not np.all(np.abs(self.one_g) > 0.0):  # a ratio needs a 1 g load
            raise ValueError(f"the {model} run has a zero 1 g load at a station: no ratio "
                             "to draw")
        self.stations = _Stations(scene.mesh, layout["stations_m"])
        w = scene._writer
        scene.remember_eta(model)
        self.marker_channel_id = w.add_channel(topic(model, GROUP), scene.schema_id(),
                                               {"model": model, **legend(self.method)})
        frame = body_frame(model)
        spheres = [p for _ in range(2 * len(QUANTITIES) * s) for p in _sphere()]
        head = entity_head(frame, ENTITY_ID)

        def pieces(ls: int, ln: int) -> list[list]:
            return [sub(2, timestamp(1, ls, ln) + head + spheres)]

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
            with signals_deferred():
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
        pick, eta = self._scene.take_drawn(self._model, ns)
        if not len(pick):
            return None
        floats = self.stations.floats(np.asarray(values, dtype=float)[pick],
                                      self._cols_array, self.one_g, eta)
        m = len(pick)
        block, index = self._records.build(ns[pick], floats, self.marker_seq)
        self.marker_seq += m
        self.marker_messages += m
        return block, index
