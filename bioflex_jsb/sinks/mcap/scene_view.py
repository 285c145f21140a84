"""The logged aircraft drawn with matplotlib: a scene message decoded from the log by the log's
own schemas and its triangles drawn as they are (``docs/img/scene.png``, made by
``scripts/scene_screenshot.py``, which flies the case).

Nothing here computes geometry: :func:`scene_at` reads the ``SceneUpdate`` entities of
:mod:`.scene` back from a file, :func:`draw_scene` draws their triangle lists and the gust
arrow, so the picture is what the log holds (``tests/test_scene_docs.py`` checks the
triangles drawn against Google's protobuf runtime's decoding of the same message).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from bioflex_jsb.sinks.mcap.reader import iter_messages, open_reader
from bioflex_jsb.sinks.mcap.scene import AIRFRAME_GROUP, SCENE_GROUP
from bioflex_jsb.sinks.mcap.schemas import SCENE_METADATA, topic

# the default picture: the Fig. 21 case (optimised wing, 15 m/s, sharp:3 from 0.2 s),
# coupled, at the largest |η1| of its first 1.2 s (the wing twisted most by the gust)
SCREENSHOT_CASE = {"wing": "optimised", "speed_m_s": 15.0, "gust": "sharp:3",
                   "duration_s": 1.2, "gust_start_s": 0.2, "model": "coupled"}


def scene_at(path: str | Path, model: str = "coupled", time_s: float | None = None) -> dict:
    """The wing's scene message of ``model`` at ``time_s`` [s] (the last one at or before
    it; default: the one where |η₁| is largest), the airframe's last message before it and
    the modal coordinates of that step: ``{"time_s", "wing", "airframe", "eta_rad",
    "exaggeration"}`` (entities as decoded dicts). LookupError if the log has no scene."""
    wing_topic, air_topic = topic(model, SCENE_GROUP), topic(model, AIRFRAME_GROUP)
    modal_topic = topic(model, "modal")
    wings, airs, etas = [], [], {}
    with open_reader(path) as (reader, summary):
        if not any(c.topic == wing_topic for c in summary.channels.values()):
            raise LookupError(f"{str(path)!r} has no scene of the {model} run ({wing_topic})")
        meta = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        for top, ns, msg in iter_messages(reader, [wing_topic, air_topic, modal_topic]):
            if top == wing_topic:
                wings.append((ns, msg["entities"][0]))
            elif top == air_topic:
                airs.append((ns, msg["entities"][0]))
            else:
                etas[ns] = msg["eta_rad"]
    if time_s is None:
        ns, wing = max(wings, key=lambda w: abs(etas[w[0]][0]))
    else:
        before = [w for w in wings if w[0] <= round(time_s * 1e9)] or wings[:1]
        ns, wing = before[-1]
    air = [a for a in airs if a[0] <= ns][-1][1]
    return {"time_s": ns * 1e-9, "wing": wing, "airframe": air, "eta_rad": etas[ns],
            "exaggeration": float(meta[SCENE_METADATA]["exaggeration"])}


def triangles(primitive: dict) -> np.ndarray:
    """(T, 3, 3) vertices of a decoded ``TriangleListPrimitive`` (indexed or not) [m]."""
    pts = np.array([(p.get("x", 0.0), p.get("y", 0.0), p.get("z", 0.0))
                    for p in primitive["points"]])
    idx = np.asarray(primitive.get("indices") or np.arange(len(pts)), dtype=np.int64)
    return pts[idx].reshape(-1, 3, 3)


def _colour(primitive: dict) -> tuple:
    c = primitive.get("color", {})
    return (c.get("r", 0.0), c.get("g", 0.0), c.get("b", 0.0), c.get("a", 0.0))


def arrow_segment(arrow: dict) -> tuple[np.ndarray, np.ndarray]:
    """(tail, tip) [m] of a decoded ``ArrowPrimitive``: along its pose's +x, shaft plus
    head long."""
    pos, q = arrow["pose"]["position"], arrow["pose"]["orientation"]
    x, y, z, w = (q.get(k, 0.0) for k in "xyzw")
    axis = np.array([1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w)])
    tail = np.array([pos.get(k, 0.0) for k in "xyz"])
    return tail, tail + axis * (arrow.get("shaft_length", 0.0) + arrow.get("head_length", 0.0))


def draw_scene(shot: dict, path: str | Path, title: str = "", metadata: dict | None = None
               ) -> dict[str, np.ndarray]:
    """Draw the entities of :func:`scene_at` to ``path`` (PNG; ``metadata``: a JSON text
    in its Description); returns the triangles drawn per part (name → (T, 3, 3)) and the
    arrow ((2, 3): tail, tip)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    drawn: dict[str, np.ndarray] = {}
    parts = [("fuselage", "tail", "fin"), ("starboard_wing", "port_wing")]
    fig = plt.figure(figsize=(9.0, 6.0), dpi=120)
    ax = fig.add_subplot(projection="3d")
    for entity, names in zip((shot["airframe"], shot["wing"]), parts, strict=True):
        for name, prim in zip(names, entity["triangles"], strict=True):
            tris = drawn[name] = triangles(prim)
            rgba = _colour(prim)
            ax.add_collection3d(Poly3DCollection(
                tris, facecolor=rgba, edgecolor=tuple(0.6 * c for c in rgba[:3]) + (0.6,),
                linewidths=0.3))
    for arrow in shot["wing"].get("arrows", []):
        seg = np.array(arrow_segment(arrow))
        drawn["gust_arrow"] = seg
        ax.add_collection3d(Line3DCollection([seg], colors=[_colour(arrow)], linewidths=3))
        ax.scatter(*seg[1], color=_colour(arrow), s=25, marker="^")
    allpts = np.concatenate([t.reshape(-1, 3) for t in drawn.values()])
    lo, hi = allpts.min(axis=0), allpts.max(axis=0)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo).max()
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - 0.35 * half, mid[2] + 0.35 * half)
    ax.set_box_aspect((1.0, 1.0, 0.35))
    ax.view_init(elev=24, azim=-128)
    ax.set_xlabel("x forward [m]")
    ax.set_ylabel("y left [m]")
    ax.set_zlabel("z up [m]")
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    info = {"Description": json.dumps(metadata, sort_keys=True)} if metadata else None
    fig.savefig(path, metadata=info)
    plt.close(fig)
    return drawn


def tip_twist_rad(wing_entity: dict) -> float:
    """The starboard tip chord's angle, leading edge up [rad], from its last two vertices."""
    pts = wing_entity["triangles"][0]["points"]
    le, te = pts[-2], pts[-1]
    return math.atan2(le["z"] - te["z"], le["x"] - te["x"])


def render_screenshot(log_path: str | Path, png_path: str | Path) -> tuple[dict, dict]:
    """``docs/img/scene.png`` from a log of :data:`SCREENSHOT_CASE` (flown by
    ``scripts/scene_screenshot.py``, which may import the drivers): the shot (decoded) and
    the triangles drawn; the PNG's Description holds the case, the time and the tip's
    twist, which the docs test compares with a fresh log."""
    c = SCREENSHOT_CASE
    shot = scene_at(log_path, c["model"])
    eta = shot["eta_rad"]
    twist = tip_twist_rad(shot["wing"])
    title = (f"{c['wing']} wing, {c['speed_m_s']:g} m/s, gust {c['gust']} at "
             f"{c['gust_start_s']:g} s ({c['model']})\nt = {shot['time_s']:.3f} s, "
             f"η = ({', '.join(f'{e:+.3f}' for e in eta)}) rad, tip twist "
             f"{math.degrees(twist):+.1f}° (exaggeration {shot['exaggeration']:g}); "
             "drawn from the log's SceneUpdate")
    meta = {"case": c, "time_s": shot["time_s"], "eta_rad": eta, "tip_twist_rad": twist,
            "exaggeration": shot["exaggeration"]}
    drawn = draw_scene(shot, png_path, title, meta)
    return shot, drawn
