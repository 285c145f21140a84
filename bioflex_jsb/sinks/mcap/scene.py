"""The aircraft in 3-D: ``foxglove.SceneUpdate`` messages of the deformed aircraft.

Two topics per wing model (``docs/logging.md``), both ``SceneUpdate`` messages of one entity
in the body frame ``<model>_body`` (x forward, y left, z up, origin at the centre of gravity;
``frame_locked``, so it rides on the ``pose`` transform): ``/bioflex/<model>/scene`` at
:data:`SCENE_RATE_HZ` (not every step), entity ``wing``: both wing halves as triangle meshes
deformed by the modal coordinates and the gust as an arrow (vertical in the world, up for an
upward gust, its length proportional to w_g); ``/bioflex/<model>/airframe`` once per chunk
(at its first step), entity ``airframe``: the rigid fuselage, horizontal tail and fin. The
rigid parts are two thirds of the bytes of a whole aircraft; apart, they cost nothing per
step, and a viewer that seeks gets them from the topic's last message.

The wing's mesh has a leading-edge and a trailing-edge vertex at the root, at strips'
stations of the lifting line (``WingBuild.aero.stations_m``: where the loads act; in a run's
log :data:`SCENE_MESH_STATIONS` of them in all, :func:`mesh_stations_m`) and at the tip.
Each section is moved as the modes move it (``docs/conventions.md``): its elastic axis (at
``x_elastic_frac`` of the chord) rises by −Σ φ_i(y) η_i (``bending_m``, positive down)
and the chord turns about it, leading edge up, by Σ θ_i(y) η_i (``twist_rad``), the shapes
interpolated at the stations as the modal coefficients of the loads and the LTI model
interpolate them (``flight_dynamics.modal_coefficients``); both multiplied by the
exaggeration stored in the ``bioflex.scene`` metadata (1: true scale). η are the logged
modal coordinates, perturbations from the trim; the two halves deform alike (the modes are
symmetric). The messages are built a chunk at a time (:class:`Records` of :mod:`.formatting`:
the byte layout is fixed, only the doubles and the timestamp move); in a run log the doubles
of a chunk's samples come from one compiled pass (:func:`_sample_floats`, the arithmetic of
:func:`scene_floats`, which the mode sheet and the tests use, operation for operation).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numba
import numpy as np

from bioflex_jsb.definition.outline import AirframeOutline, airframe_outline
from bioflex_jsb.simulation.step_kernel import guard_cache
from bioflex_jsb.sinks.mcap.schemas import (
    AIRFRAME_GROUP,
    SCENE_GROUP,
    SCENE_METADATA,
    SCENE_PROTO_SCHEMA,
    body_frame,
    topic,
)
from bioflex_jsb.sinks.mcap_io.protobuf import I64, LEN, VARINT, string_field, tag, varint
from bioflex_jsb.sinks.mcap_io.records import (
    F,
    Records,
    consts,
    dbl,
    entity_head,
    sample_steps,
    sub,
    timestamp,
)

if TYPE_CHECKING:
    from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

# DECISION: a display's frame rate. The 3-D panel draws at most this often; the wing modes
# (31-107 Hz) are sampled, not resolved (the modal topic has every step).
SCENE_RATE_HZ = 60.0
# NUMERICAL: a step's sample bin is floor(t·rate + this): 1e-6 of a bin (17 ns at 60 Hz)
# absorbs the rounding of t = k·dt, far below any step
SAMPLE_BIN_EPS = 1e-6
DEFAULT_EXAGGERATION = 1.0  # true scale: the logged twist is degrees already (η₁ ~ 0.3 rad)
# DECISION (drawing only): the gust arrow is 0.1 m long per m/s (a 3 m/s gust: 0.3 m, a
# third of the fuselage), its head 30 % of it, 15 mm shaft and 40 mm head diameters, ahead
# of the nose by 0.1 m at the wing's height
GUST_ARROW_M_PER_M_S = 0.1
_ARROW_HEAD_FRACTION = 0.3
_ARROW_SHAFT_DIAMETER_M = 0.015
_ARROW_HEAD_DIAMETER_M = 0.04
_ARROW_AHEAD_OF_NOSE_M = 0.1
# DECISION (drawing only): the logged scene's wing is drawn at 17 stations a half (root, tip
# and 15 of the prototype's 40 strips' stations, evenly picked by index: mesh_stations_m, so
# the tip, where the cosine-spaced strips crowd and the shapes turn, keeps its density), not
# at all 42: the shapes drawn linearly between them are within 0.7, 1.9 and 4.2 % of each
# mode's peak (modes 1-3) of the 42-station mesh, and a scene message is 3.0 kB instead of
# 7.2 kB. The mode sheet and the mode animation draw every station.
SCENE_MESH_STATIONS = 17
# NUMERICAL (drawing only): the fuselage's spheroid in rings along x and sides around
_FUSELAGE_RINGS, _FUSELAGE_SIDES = 16, 12
COLOURS = {  # r, g, b, a [0-1]
    "fuselage": (0.55, 0.57, 0.60, 1.0), "tail": (0.35, 0.45, 0.60, 1.0),
    "fin": (0.35, 0.45, 0.60, 1.0), "wing": (0.90, 0.55, 0.15, 1.0),
    "gust": (0.20, 0.60, 1.00, 1.0),
}
ENTITY_ID = "wing"  # the scene topic's entity: triangle lists WING_PARTS, the gust arrow
WING_PARTS = ("starboard_wing", "port_wing")
AIRFRAME_ENTITY_ID = "airframe"  # the airframe topic's entity: triangle lists AIRFRAME_PARTS
AIRFRAME_PARTS = ("fuselage", "tail", "fin")
# The airframe's message goes with the first step of a chunk, at most every 0.5 s of log time:
# a SITL session closes a chunk every few tens of ms (its latency and crash-safety promise),
# and one airframe a chunk there made the log 80 % larger (810 against 452 bytes a step).
AIRFRAME_PERIOD_NS = 500_000_000


# -- the half wing at the mesh's stations ---------------------------------------------------
@dataclass(frozen=True)
class WingShape:
    """The starboard half wing at the K stations of the mesh (root, the strips' stations,
    tip) in the wing frame (x aft of the root leading edge, y to starboard) [m]: leading edge,
    chord, elastic axis (fraction of the chord aft of the leading edge), the mode shapes
    ``bending_m`` (n, K) [m/rad, down] and ``twist_rad`` (n, K) [rad/rad, leading edge up],
    and the centre of gravity ``x_cg_m`` (the body frame's origin)."""

    stations_m: np.ndarray
    leading_edge_x_m: np.ndarray
    chord_m: np.ndarray
    x_elastic_frac: np.ndarray
    bending_m: np.ndarray
    twist_rad: np.ndarray
    x_cg_m: float
    source: str

    @property
    def n_modes(self) -> int:
        return int(self.bending_m.shape[0])


def wing_shape(build, planform=None, max_stations: int | None = None) -> WingShape:
    """The mesh's half wing of the wing ``build`` (a ``WingBuild``: its modes and strips) on
    ``planform`` (default: the build's own, the one its strips were made on: the prototype's
    ``parameters.wing.DEFAULT_PLANFORM`` or a definition's stations): root, the strips'
    stations and tip, or at most ``max_stations`` of them (root, tip and strips' stations
    evenly picked by index: :func:`mesh_stations_m`)."""
    if planform is None:
        planform = build.planform
    modes, aero = build.modes, build.aero
    y = mesh_stations_m(aero.stations_m, aero.semispan_m, max_stations)

    def at(rows) -> np.ndarray:
        return np.array([np.interp(y, modes.stations_m, r) for r in np.atleast_2d(rows)])

    return WingShape(
        stations_m=y, leading_edge_x_m=np.asarray(planform.leading_edge_x_at(y), dtype=float),
        chord_m=np.asarray(planform.chord_at(y), dtype=float),
        x_elastic_frac=at(np.broadcast_to(modes.x_elastic_frac, modes.stations_m.shape))[0],
        bending_m=at(modes.bending_m), twist_rad=at(modes.twist_rad),
        x_cg_m=float(planform.x_cg_m), source=f"wing {build.variant.name}: {modes.source}")


def mesh_stations_m(strip_stations_m, semispan_m: float, max_stations: int | None = None
                    ) -> np.ndarray:
    """The mesh's stations [m]: the root (0), the strips' stations and the tip
    (``semispan_m``); with ``max_stations`` (≥ 3), the strips' stations thinned to
    ``max_stations`` − 2 picked evenly by index (the first and last strips kept)."""
    strips = np.asarray(strip_stations_m, dtype=float)
    if max_stations is not None:
        if max_stations < 3:
            raise ValueError(f"a mesh needs at least 3 stations, not {max_stations}")
        if len(strips) > max_stations - 2:
            strips = strips[np.unique(np.round(np.linspace(0, len(strips) - 1,
                                                           max_stations - 2)).astype(int))]
    return np.concatenate([[0.0], strips, [float(semispan_m)]])


# -- the mesh in the body frame ------------------------------------------------------------
def _spheroid(length_m: float, diameter_m: float, nose_x_m: float):
    """Points (P, 3) and triangle indices of a prolate spheroid along x, nose at nose_x."""
    a, r = 0.5 * length_m, 0.5 * diameter_m
    s = np.cos(np.linspace(0.0, math.pi, _FUSELAGE_RINGS + 1))[1:-1]  # x/a, nose to tail
    phi = np.linspace(0.0, 2.0 * math.pi, _FUSELAGE_SIDES, endpoint=False)
    rho = r * np.sqrt(1.0 - s**2)
    ring = np.stack([np.repeat(nose_x_m - a + a * s, _FUSELAGE_SIDES),
                     (rho[:, None] * np.cos(phi)).ravel(),
                     (rho[:, None] * np.sin(phi)).ravel()], axis=1)
    pts = np.vstack([[nose_x_m, 0.0, 0.0], ring, [nose_x_m - length_m, 0.0, 0.0]])
    n, m = _FUSELAGE_SIDES, len(s)
    tris = []
    for k in range(n):
        k2 = (k + 1) % n
        tris.append((0, 1 + k, 1 + k2))
        tris.append((len(pts) - 1, 1 + (m - 1) * n + k2, 1 + (m - 1) * n + k))
        for i in range(m - 1):
            p, q = 1 + i * n, 1 + (i + 1) * n
            tris += [(p + k, q + k, q + k2), (p + k, q + k2, p + k2)]
    return pts, np.array(tris, dtype=np.uint32).ravel()


def _quads(n_stations: int) -> np.ndarray:
    """Indices of a strip of quads between consecutive stations, vertices 2j (leading edge)
    and 2j + 1 (trailing edge) at station j."""
    j = np.arange(n_stations - 1)
    le, te, le2, te2 = 2 * j, 2 * j + 1, 2 * j + 2, 2 * j + 3
    return np.stack([le, te, te2, le, te2, le2], axis=1).astype(np.uint32).ravel()


class AircraftMesh:
    """The aircraft's vertices in the body frame (FLU, origin at the CG) [m]: the rigid
    parts, once; the wing's, for given modal coordinates (:meth:`wing_xz`); the gust arrow
    (:meth:`gust_arrow`)."""

    def __init__(self, shape: WingShape, outline: AirframeOutline,
                 exaggeration: float = DEFAULT_EXAGGERATION) -> None:
        if not (math.isfinite(exaggeration) and exaggeration > 0.0):
            raise ValueError(f"the scene's exaggeration must be a number > 0, not "
                             f"{exaggeration!r}")
        self.shape, self.outline, self.exaggeration = shape, outline, float(exaggeration)
        c, xe = shape.chord_m, shape.x_elastic_frac
        self.ea_x_m = shape.x_cg_m - (shape.leading_edge_x_m + xe * c)  # body x of the axis
        self.chord_fwd_m = np.stack([xe * c, xe * c - c])  # (2, K): LE and TE ahead of it
        self.y_m = shape.stations_m
        self.z0_m = outline.wing_height_m
        self.wing_indices = _quads(len(self.y_m))
        o = outline
        self.nose_x_m = shape.x_cg_m + o.nose_ahead_of_root_le_m
        fus = _spheroid(o.fuselage_length_m, o.fuselage_max_diameter_m, self.nose_x_m)
        x_le = shape.x_cg_m - o.tail_le_x_m
        x_te = x_le - o.tail_chord_m
        b = o.tail_semispan_m
        tail = (np.array([[x_le, -b, 0], [x_te, -b, 0], [x_le, b, 0], [x_te, b, 0]], float),
                np.array([0, 1, 3, 0, 3, 2], dtype=np.uint32))
        h, ct = o.fin_height_m, o.fin_tip_chord_m
        fin = (np.array([[x_le, 0, 0], [x_te, 0, 0], [x_te, 0, h], [x_te + ct, 0, h]], float),
               np.array([0, 1, 2, 0, 2, 3], dtype=np.uint32))
        self.rigid = {"fuselage": fus, "tail": tail, "fin": fin}
        self.arrow_head_m = np.array([self.nose_x_m + _ARROW_AHEAD_OF_NOSE_M, 0.0, self.z0_m])

    @property
    def wing_vertices(self) -> int:
        """Vertices of one wing half (two per station)."""
        return 2 * len(self.y_m)

    def twist_heave(self, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The twist [rad, leading edge up] and heave [m, up] (m, K) of the stations, the
        exaggeration included, for the modal coordinates ``eta`` (m, n) [rad]."""
        eta = np.asarray(eta, dtype=float).reshape(len(eta), -1)
        if eta.shape[1] != self.shape.n_modes:
            raise ValueError(f"the scene's wing has {self.shape.n_modes} modes, the samples "
                             f"{eta.shape[1]}")
        e = self.exaggeration
        return e * eta @ self.shape.twist_rad, -e * eta @ self.shape.bending_m

    def wing_xz(self, eta: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(x, z) [m] of one half's vertices, (m, K, 2) each (station, then leading/trailing
        edge), for the modal coordinates ``eta`` (m, n) [rad]; y is ∓``y_m`` (starboard is
        −y in the body frame)."""
        twist, heave = self.twist_heave(eta)
        d = self.chord_fwd_m.T[None]  # (1, K, 2)
        x = self.ea_x_m[None, :, None] + d * np.cos(twist)[:, :, None]
        z = self.z0_m + heave[:, :, None] + d * np.sin(twist)[:, :, None]
        return x, z

    def sample_floats(self, v: np.ndarray, cols: np.ndarray, eta: np.ndarray) -> np.ndarray:
        """:func:`scene_floats` of the samples' rows ``v`` (m, channels; ``cols`` the columns
        of w_g, φ, θ, an ``intp`` array) and their modal coordinates ``eta`` (m, n): the
        compiled pass (:func:`_sample_floats`)."""
        return _sample_floats(v, cols, *self.twist_heave(eta), self.ea_x_m, self.chord_fwd_m,
                              self.z0_m, self.arrow_head_m, GUST_ARROW_M_PER_M_S,
                              1 - _ARROW_HEAD_FRACTION, _ARROW_HEAD_FRACTION)

    def gust_arrow(self, w_g_m_s, roll_rad, pitch_rad) -> np.ndarray:
        """(m, 9): the arrow's tail position (x, y, z) [m], its orientation (x, y, z, w) (its
        +x along the gust: world up for w_g > 0, in the body frame of the NED Euler angles
        roll φ and pitch θ), shaft and head lengths [m]."""
        w = np.asarray(w_g_m_s, dtype=float)
        ph, th = np.asarray(roll_rad, dtype=float), np.asarray(pitch_rad, dtype=float)
        up = np.stack([np.sin(th), np.sin(ph) * np.cos(th), np.cos(ph) * np.cos(th)], axis=1)
        d = np.where(w[:, None] < 0.0, -up, up)
        length = GUST_ARROW_M_PER_M_S * np.abs(w)
        tail = self.arrow_head_m[None] - length[:, None] * d
        q = np.stack([np.zeros_like(w), -d[:, 2], d[:, 1], 1.0 + d[:, 0]], axis=1)
        q /= np.linalg.norm(q, axis=1, keepdims=True)
        return np.column_stack([tail, q, (1 - _ARROW_HEAD_FRACTION) * length,
                                _ARROW_HEAD_FRACTION * length])


_POSE = sub(1, consts(1, (0.0, 0.0, 0.0)) + consts(2, (0.0, 0.0, 0.0, 1.0)))


def _indices(number: int, idx: np.ndarray) -> bytes:
    data = np.asarray(idx, dtype="<u4").tobytes()
    return tag(number, LEN) + varint(len(data)) + data


def _rigid_list(points: np.ndarray, idx: np.ndarray, colour) -> list:
    body = [b"".join(b"".join(consts(2, p)) for p in points)]
    return sub(12, _POSE + body + consts(3, colour) + [_indices(5, idx)])


def _wing_list(y_m: np.ndarray, idx: np.ndarray, colour) -> list:
    """A wing half: its vertices' x and z are doubles of the chunk (y constant)."""
    points: list = []
    for y in y_m:
        for _ in range(2):
            points += sub(2, [tag(1, I64), F, dbl(2, float(y)) + tag(3, I64), F])
    return sub(12, _POSE + points + consts(3, colour) + [_indices(5, idx)])


def _arrow(colour) -> list:
    pose = sub(1, sub(1, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F])
                + sub(2, [tag(1, I64), F, tag(2, I64), F, tag(3, I64), F, tag(4, I64), F]))
    return sub(7, pose + [tag(2, I64), F, dbl(3, _ARROW_SHAFT_DIAMETER_M) + tag(4, I64), F,
                           dbl(5, _ARROW_HEAD_DIAMETER_M)] + consts(6, colour))


def text_primitive(text: str, position_m, size: float = 0.06) -> list:
    """A ``TextPrimitive`` (field 13 of SceneEntity): ``text`` at ``position_m`` (body frame),
    billboarded, ``size`` [m] high."""
    pose = sub(1, consts(1, position_m) + consts(2, (0.0, 0.0, 0.0, 1.0)))
    return sub(13, pose + [tag(2, VARINT) + b"\x01", dbl(3, size)] + consts(5, (1, 1, 1, 1))
                + [string_field(6, text)])


def scene_pieces(mesh: AircraftMesh, frame: str, texts: list | None = None):
    """``pieces(ls, ln)`` of one wing SceneUpdate for :class:`Records`: its doubles are the
    gust arrow's 9 (:meth:`AircraftMesh.gust_arrow`) then each half's x, z per vertex
    (starboard, port: :meth:`scene_floats`); ``texts``: constant text primitives
    (:func:`text_primitive`)."""
    wings = [part for sign in (-1.0, 1.0)
             for part in _wing_list(sign * mesh.y_m, mesh.wing_indices, COLOURS["wing"])]
    head = entity_head(frame, ENTITY_ID)
    arrow = _arrow(COLOURS["gust"])
    extra = [part for text in texts or [] for part in text]

    def pieces(ls: int, ln: int) -> list[list]:
        return [sub(2, timestamp(1, ls, ln) + head + arrow + wings + extra)]

    return pieces


def airframe_pieces(mesh: AircraftMesh, frame: str):
    """``pieces(ls, ln)`` of the airframe's SceneUpdate (no doubles: every vertex is
    constant)."""
    rigid = [part for name in AIRFRAME_PARTS
             for part in _rigid_list(*mesh.rigid[name], COLOURS[name])]
    head = entity_head(frame, AIRFRAME_ENTITY_ID)

    def pieces(ls: int, ln: int) -> list[list]:
        return [sub(2, timestamp(1, ls, ln) + head + rigid)]

    return pieces


def scene_floats(mesh: AircraftMesh, eta, w_g_m_s, roll_rad, pitch_rad) -> np.ndarray:
    """The doubles of m messages (rows of :func:`scene_pieces`' layout)."""
    x, z = mesh.wing_xz(eta)
    half = np.stack([x, z], axis=-1).reshape(len(x), -1)
    return np.column_stack([mesh.gust_arrow(w_g_m_s, roll_rad, pitch_rad), half, half])


@numba.njit(cache=True, nogil=True)
def _sample_floats(v, cols, twist, heave, ea_x, chord_fwd, z0, arrow_head, m_per_m_s,
                   shaft_frac, head_frac):
    """The doubles of :func:`scene_floats` for the samples' rows ``v`` (m, channels; ``cols``
    the columns of w_g, φ, θ) and their stations' ``twist`` and ``heave`` (m, K:
    :meth:`AircraftMesh.twist_heave`), in one pass, operation for operation as
    :meth:`AircraftMesh.gust_arrow` and :meth:`AircraftMesh.wing_xz` (the same doubles,
    tests/test_scene.py). Their ~50 small numpy operations on a chunk's 54 samples take
    ~0.2 ms in a run, its caches cold, this (with :meth:`AircraftMesh.twist_heave`) ~0.08 ms."""
    m, k_n = twist.shape
    out = np.empty((m, 9 + 8 * k_n))
    for i in range(m):
        w, ph, th = v[i, cols[0]], v[i, cols[1]], v[i, cols[2]]
        # the arrow: +x along the gust (world up for w_g > 0), its tail behind the head
        ct = np.cos(th)
        u0, u1, u2 = np.sin(th), np.sin(ph) * ct, np.cos(ph) * ct
        if w < 0.0:
            u0, u1, u2 = -u0, -u1, -u2
        length = m_per_m_s * np.abs(w)
        out[i, 0] = arrow_head[0] - length * u0
        out[i, 1] = arrow_head[1] - length * u1
        out[i, 2] = arrow_head[2] - length * u2
        q1, q2, q3 = -u2, u1, 1.0 + u0  # its x is 0
        norm = np.sqrt((0.0 * 0.0 + q1 * q1 + q2 * q2) + q3 * q3)  # numpy's sum, in order
        out[i, 3], out[i, 4], out[i, 5], out[i, 6] = 0.0 / norm, q1 / norm, q2 / norm, q3 / norm
        out[i, 7], out[i, 8] = shaft_frac * length, head_frac * length
        # the wing: each station's leading and trailing edge (x, z), starboard then port
        for k in range(k_n):
            c, s = np.cos(twist[i, k]), np.sin(twist[i, k])
            zk = z0 + heave[i, k]
            for j in range(2):
                d = chord_fwd[j, k]
                x, z = ea_x[k] + d * c, zk + d * s
                at = 9 + 4 * k + 2 * j
                out[i, at], out[i, at + 1] = x, z
                out[i, at + 4 * k_n], out[i, at + 4 * k_n + 1] = x, z
    return out


guard_cache(_sample_floats)


@numba.njit(cache=True, nogil=True)
def _positions(ns, wanted):
    """The position in ``ns`` (increasing) of each of ``wanted`` (increasing), −1 where
    absent."""
    at = np.full(len(wanted), -1, dtype=np.int64)
    j = 0
    for i in range(len(wanted)):
        while j < len(ns) and ns[j] < wanted[i]:
            j += 1
        if j < len(ns) and ns[j] == wanted[i]:
            at[i] = j
    return at


guard_cache(_positions)


# -- in a run log ---------------------------------------------------------------------------
class _Channel:
    def __init__(self, cid: int, records: Records, airframe_id: int, airframe: Records
                 ) -> None:
        self.id, self.records = cid, records
        self.airframe_id, self.airframe = airframe_id, airframe
        self.seq = self.airframe_seq = 0
        self.last_bin = None  # the sample bin of the model's last step
        self.last_airframe_ns: int | None = None  # log time of the last airframe message
        self.names: tuple = ()
        self.etas: list[int] = []
        self.cols = np.zeros(3, dtype=np.intp)  # the columns of w_g, φ, θ
        # the log times [ns] and η [rad] of the samples drawn, in time order, kept for the
        # section-load markers (scene_loads.py) until they draw them (None: the run has no
        # loads, nothing kept)
        self.drawn: tuple[np.ndarray, np.ndarray] | None = None


class SceneLog:
    """The scene topics of a log: ``rows`` takes each chunk of a model's steps (the
    recorder's rows, in the channels' ``names`` order) and appends the samples' messages to
    the writer's chunk in progress (the caller holds signals and closes the chunk)."""

    def __init__(self, writer: McapFileWriter, mesh: AircraftMesh,
                 rate_hz: float = SCENE_RATE_HZ) -> None:
        self._writer, self.mesh, self.rate_hz = writer, mesh, float(rate_hz)
        self._schema_id: int | None = None
        self._channels: dict[str, _Channel] = {}
        self.messages = 0
        writer.add_metadata(SCENE_METADATA, scene_metadata(mesh, self.rate_hz))

    @classmethod
    def for_run(cls, writer: McapFileWriter, description, wing_variant=None,
                exaggeration: float = DEFAULT_EXAGGERATION, build=None) -> SceneLog:
        """The scene of the run ``description``: its wing ``build`` (a ``WingBuild``: its
        planform, modes and airframe), or else built as the run built it (the variant
        ``wing_variant``, a ``WingVariant.as_dict()``, or else the description's ``wing``, on
        the prototype's airframe; the build cache returns the run's own build); the airframe
        drawn is the build's (definition/outline.py)."""
        if build is not None:
            return cls(writer, AircraftMesh(wing_shape(build, max_stations=SCENE_MESH_STATIONS),
                                            airframe_outline(build.airframe), exaggeration))
        from bioflex_jsb.flight_dynamics.wing_model import (
            WingVariant,
            build_wing,
            resolve_variant,
        )

        variant = (WingVariant(**dict(wing_variant)) if wing_variant is not None
                   else resolve_variant(description.wing))
        build = build_wing(variant, mass_basis=description.mass_basis)
        return cls(writer, AircraftMesh(wing_shape(build, max_stations=SCENE_MESH_STATIONS),
                                        airframe_outline(build.airframe), exaggeration))

    def schema_id(self) -> int:
        """The id of the ``foxglove.SceneUpdate`` schema (added at the first call)."""
        if self._schema_id is None:
            name, data = SCENE_PROTO_SCHEMA
            self._schema_id = self._writer.add_schema(name, "protobuf", data)
        return self._schema_id

    def with_loads(self, loads_topic, model: str, layout: dict):
        """The run's loads topic (``loads_topic``, a :class:`~.loads_topic.LoadsTopic` of
        ``layout``, the run's ``meta["loads"]``) drawing each block it writes as section-load
        markers too (:class:`~.scene_loads.LoadMarkers`)."""
        from bioflex_jsb.sinks.mcap.scene_loads import LoadMarkers

        return LoadMarkers(self, loads_topic, model, layout)

    def remember_eta(self, model: str) -> None:
        """Keep the η of every sample drawn for ``model`` from now on (:meth:`take_drawn`)."""
        ch = self._channel(model)
        if ch.drawn is None:
            ch.drawn = (np.empty(0, dtype=np.int64), np.empty((0, self.mesh.shape.n_modes)))

    def take_drawn(self, model: str, ns: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Of the log times ``ns`` [ns] (increasing), the positions of those the scene drew
        for ``model`` and the η [rad] (rows) it drew them with; these are forgotten, the
        samples drawn at other times kept."""
        ch = self._channel(model)
        kept_ns, kept_eta = ch.drawn
        at = _positions(np.ascontiguousarray(ns, dtype=np.int64), kept_ns)
        hit = at >= 0
        if hit.all():  # the usual block: every sample kept is among its steps
            ch.drawn = (kept_ns[:0], kept_eta[:0])
            return at, kept_eta
        ch.drawn = (kept_ns[~hit], kept_eta[~hit])
        return at[hit], kept_eta[hit]

    def _channel(self, model: str) -> _Channel:
        ch = self._channels.get(model)
        if ch is None:
            w = self._writer
            self.schema_id()
            frame = body_frame(model)
            cid = w.add_channel(topic(model, SCENE_GROUP), self._schema_id, {"model": model})
            aid = w.add_channel(topic(model, AIRFRAME_GROUP), self._schema_id,
                                {"model": model})
            ch = self._channels[model] = _Channel(
                cid, Records([cid], scene_pieces(self.mesh, frame), True),
                aid, Records([aid], airframe_pieces(self.mesh, frame), True))
        return ch

    def rows(self, model: str, names, time_s, rows: np.ndarray) -> None:
        """Log the samples among the steps ``rows`` (steps × channels) at ``time_s`` [s]
        (:meth:`build`) into the chunk in progress."""
        for block, index in self._build(model, names, time_s, rows):  # no copy joins them
            self._writer.append_block(block, index)

    def build(self, model: str, names, time_s, rows: np.ndarray):
        """The records (and index entries) of the airframe at the first of the steps
        ``rows`` (at ``time_s`` [s]) and of the wing at each step whose time enters a new
        1/rate bin (a run's first step too); None if there are no steps."""
        parts = self._build(model, names, time_s, rows)
        if len(parts) < 2:
            return parts[0] if parts else None
        (air, air_index), (block, index) = parts
        for entries in index.values():
            entries[:, 1] += len(air)
        return b"".join((air, block)), {**air_index, **index}

    def _build(self, model: str, names, time_s, rows: np.ndarray) -> list[tuple]:
        """:meth:`build`'s records apart: (records, index) of the airframe's message, if
        one is due, then of the wing's, if any sample."""
        t = np.asarray(time_s, dtype=float)
        if not len(t):
            return []
        ch = self._channel(model)
        # the samples: the steps entering a new 1/rate bin (the rule pose and location use)
        pick, ch.last_bin = sample_steps(t, self.rate_hz, SAMPLE_BIN_EPS, ch.last_bin)
        t0 = np.rint(t[:1] * 1e9).astype(np.int64)
        parts = []
        if ch.last_airframe_ns is None or t0[0] - ch.last_airframe_ns >= AIRFRAME_PERIOD_NS:
            parts.append(ch.airframe.build(t0, np.empty((1, 0)), ch.airframe_seq))
            ch.airframe_seq += 1
            ch.last_airframe_ns = int(t0[0])
        if not len(pick):
            return parts
        names = tuple(names)
        if ch.names != names:  # the columns read: η (none for a wing without modes), w_g, φ, θ
            col = {n: i for i, n in enumerate(names)}
            n_eta = sum(1 for n in names if n.startswith("eta") and n[3:].isdigit())
            if n_eta not in (0, self.mesh.shape.n_modes):
                raise ValueError(f"the {model} samples have {n_eta} modal coordinates, the "
                                 f"scene's wing {self.mesh.shape.n_modes} modes")
            ch.etas = [col[f"eta{i + 1}"] for i in range(self.mesh.shape.n_modes)
                       if f"eta{i + 1}" in col]
            ch.cols = np.array([col["w_g"], col["phi_rad"], col["theta_rad"]], dtype=np.intp)
            ch.names = names
        v = np.asarray(rows, dtype=float)[pick]
        eta = v[:, ch.etas] if ch.etas else np.zeros((len(pick), self.mesh.shape.n_modes))
        floats = self.mesh.sample_floats(v, ch.cols, eta)
        ns = np.rint(t[pick] * 1e9).astype(np.int64)
        if ch.drawn is not None:
            kept_ns, kept_eta = ch.drawn
            ch.drawn = ((ns, eta) if not len(kept_ns) else
                        (np.concatenate([kept_ns, ns]), np.concatenate([kept_eta, eta])))
        parts.append(ch.records.build(ns, floats, ch.seq))
        ch.seq += len(pick)
        self.messages += len(pick)
        return parts


def scene_metadata(mesh: AircraftMesh, rate_hz: float) -> dict[str, str]:
    """The ``bioflex.scene`` metadata record."""
    o = mesh.outline
    return {
        "exaggeration": repr(mesh.exaggeration),
        "rate_hz": repr(float(rate_hz)),
        "topic": topic("<model>", SCENE_GROUP), "frame": body_frame("<model>"),
        "entity": ENTITY_ID, "parts": ",".join(WING_PARTS) + ",gust_arrow",
        "airframe_topic": topic("<model>", AIRFRAME_GROUP),
        "airframe_entity": AIRFRAME_ENTITY_ID, "airframe_parts": ",".join(AIRFRAME_PARTS),
        "airframe_rate": "at the first step of a chunk, at most every 0.5 s",
        "wing_stations": str(len(mesh.y_m)),
        "wing_vertices_per_half": str(mesh.wing_vertices),
        "deformation": "heave -exaggeration*sum(bending_m*eta), twist "
                       "exaggeration*sum(twist_rad*eta) about the elastic axis, per station",
        "gust_arrow_m_per_m_s": repr(GUST_ARROW_M_PER_M_S),
        "wing_source": mesh.shape.source,
        "airframe": (f"fuselage {o.fuselage_length_m:g} x {o.fuselage_max_diameter_m:g} m, "
                     f"tail {2 * o.tail_semispan_m:g} x {o.tail_chord_m:g} m "
                     "(parameters/airframe_consistent.py)"),
    }
