"""Mode shapes to look at: an MCAP in which each mode of the wing oscillates in turn (``modes
--animate``) and a sheet of their shapes for a report (``modes --mode-sheet``).

The modes: the wing's structural modes (clamped half wing, ``WingBuild.modes``: one modal
coordinate each) and the aeroelastic modes of the coupled model (the paper's Eq. 4) at one
speed (``aeroelastic_1`` …, labels tracked from 2 m/s by :func:`~bioflex_jsb.flight_dynamics.
eigen.track`; their η part of the eigenvector, complex: the sections need not move in phase).
Each shape is scaled so that the starboard tip twists by 1 rad per unit amplitude at phase 0
(its largest tip twist when the others lag); a mode that would reach a tip heave of
:data:`PEAK_TIP_HEAVE_FRAC` of the semispan first (a bending mode) is scaled on its tip heave
instead, so that the animation shows it at that heave. In the animation every mode
oscillates at :data:`DISPLAY_PERIOD_S` (the real 20-110 Hz cannot be watched) for
:data:`CYCLES` cycles with a peak tip twist of :data:`PEAK_TIP_TWIST_RAD` (or tip heave, as
above), undamped; its label (a text in the scene and an event) gives the real frequency and
damping ratio. The scene is :mod:`.scene`'s (model ``modes``: topics
``/bioflex/modes/scene`` and ``/airframe``, frame ``modes_body``, a fixed ``pose`` at the
world origin).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bioflex_jsb import __version__
from bioflex_jsb.sinks.mcap.formatting import log_message
from bioflex_jsb.sinks.mcap.scene import (
    AircraftMesh,
    airframe_outline,
    airframe_pieces,
    scene_floats,
    scene_metadata,
    scene_pieces,
    text_primitive,
    wing_shape,
)
from bioflex_jsb.sinks.mcap.schemas import (
    AIRFRAME_GROUP,
    EVENT_LEVELS,
    EVENTS_PROTO_SCHEMA,
    EVENTS_TOPIC,
    PROTO_SCHEMAS,
    SCENE_GROUP,
    SCENE_METADATA,
    SCENE_PROTO_SCHEMA,
    WORLD_FRAME,
    body_frame,
    topic,
)
from bioflex_jsb.sinks.mcap_io.protobuf import length_delimited, string_field, varint
from bioflex_jsb.sinks.mcap_io.records import Records
from bioflex_jsb.sinks.mcap_io.writer import McapFileWriter

MODEL = "modes"
MODES_METADATA = "bioflex.modes"
# DECISION (display only): one cycle a second, three cycles per mode, 60 frames a second, a
# 10° peak tip twist (the shapes are normalised; their amplitude is free)
DISPLAY_PERIOD_S = 1.0
CYCLES = 3
FRAME_RATE_HZ = 60.0
PEAK_TIP_TWIST_RAD = math.radians(10.0)
# a bending mode's peak tip heave in the animation [fraction of the semispan]
PEAK_TIP_HEAVE_FRAC = 0.05


@dataclass(frozen=True)
class ModeShape:
    """One mode: ``kind`` (structural, aeroelastic), ``name``, natural frequency [Hz],
    damping ratio [-], the eigenvalue [rad/s] (aeroelastic) and ``eta`` (n,) complex: the
    modal coordinates per unit amplitude (tip twist 1 rad at phase 0)."""

    kind: str
    name: str
    frequency_hz: float
    damping: float
    eta: np.ndarray
    eigenvalue: complex | None = None

    def label(self, speed_m_s: float) -> str:
        where = f" at {speed_m_s:g} m/s" if self.kind == "aeroelastic" else " (clamped wing)"
        if self.eigenvalue is not None and abs(self.eigenvalue.imag) < 1e-9:
            return (f"{self.name}{where}: real root {self.eigenvalue.real:+.3g} 1/s "
                    "(non-oscillatory)")
        return f"{self.name}{where}: {self.frequency_hz:.2f} Hz, damping ratio {self.damping:.3f}"

    def as_dict(self) -> dict:
        return {"kind": self.kind, "name": self.name, "frequency_hz": self.frequency_hz,
                "damping": self.damping,
                "eigenvalue_rad_s": None if self.eigenvalue is None else
                [self.eigenvalue.real, self.eigenvalue.imag],
                "eta_re": self.eta.real.tolist(), "eta_im": self.eta.imag.tolist()}


def _unit_tip_twist(build, eta: np.ndarray) -> np.ndarray:
    """``eta`` scaled to its display amplitude: tip twist 1 rad at phase 0, or, for a mode
    that reaches :data:`PEAK_TIP_HEAVE_FRAC` of the semispan in tip heave before
    :data:`PEAK_TIP_TWIST_RAD` in tip twist (a bending mode: a sailplane's first), the tip
    heave (up) of that fraction × 1 rad / PEAK_TIP_TWIST_RAD at phase 0; the animation then
    multiplies by PEAK_TIP_TWIST_RAD."""
    twist = complex(np.asarray(build.modes.twist_rad, dtype=float)[:, -1] @ eta)
    heave = complex(np.asarray(build.modes.bending_m, dtype=float)[:, -1] @ eta)
    heave_ref_m = PEAK_TIP_HEAVE_FRAC * float(build.modes.stations_m[-1])
    if abs(twist) / PEAK_TIP_TWIST_RAD >= abs(heave) / heave_ref_m:
        if abs(twist) < 1e-12:
            raise ValueError("a mode without tip twist or tip heave cannot be scaled")
        return eta / twist
    # bending_m is positive down: the tip goes up at phase 0
    return eta / (-heave * PEAK_TIP_TWIST_RAD / heave_ref_m)


def mode_shapes(build, speed_m_s: float) -> list[ModeShape]:
    """The structural modes of ``build`` and the aeroelastic modes of its coupled model at
    ``speed_m_s`` [m/s] (sea level)."""
    from bioflex_jsb.flight_dynamics import eigen
    from bioflex_jsb.flight_dynamics.lti import build_state_space
    from bioflex_jsb.flight_dynamics.rigid import level_flight_condition

    n = build.modes.n_modes
    out = []
    for i in range(n):
        unit = np.zeros(n, dtype=complex)
        unit[i] = 1.0
        out.append(ModeShape("structural", f"structural mode {i + 1}",
                             float(build.modes.frequencies_rad_s[i] / (2 * math.pi)),
                             float(build.model.damping_ratios[i]),
                             _unit_tip_twist(build, unit)))
    grid = eigen.sweep_grid([speed_m_s])
    sweep = eigen.track("coupled", grid, build.model)
    k = int(np.flatnonzero(grid == speed_m_s)[0])
    condition = level_flight_condition(speed_m_s, airframe=build.model.airframe)
    states = build_state_space("coupled", condition, build.model).states
    rows = [states.index(f"eta{i + 1}") for i in range(n)]
    for label in dict.fromkeys(lab for lab in sweep.labels if lab.startswith("aeroelastic")):
        cols = [j for j, lab in enumerate(sweep.labels) if lab == label]
        j = max(cols, key=lambda c: (sweep.eigenvalues[k, c].imag, sweep.eigenvalues[k, c].real))
        lam = complex(sweep.eigenvalues[k, j])
        eta = np.asarray(sweep.eigenvectors[k][rows, j], dtype=complex)
        out.append(ModeShape("aeroelastic", label, abs(lam) / (2 * math.pi),
                             -lam.real / abs(lam) if abs(lam) > 0 else 1.0,
                             _unit_tip_twist(build, eta), lam))
    return out


def _pose_message(ns: int) -> bytes:
    """A ``foxglove.FrameTransform``: ``modes_body`` at the world origin, unrotated."""
    sec, nsec = divmod(int(ns), 1_000_000_000)
    stamp = length_delimited(1, b"\x08" + varint(sec) + b"\x10" + varint(nsec))
    vec = b"\x09" + bytes(8) + b"\x11" + bytes(8) + b"\x19" + bytes(8)  # x, y, z = 0
    quat = vec + b"\x21" + np.float64(1.0).tobytes()  # w = 1
    return (stamp + string_field(2, WORLD_FRAME) + string_field(3, body_frame(MODEL))
            + length_delimited(4, vec) + length_delimited(5, quat))


def write_animation(path: str | Path, build, speed_m_s: float,
                    shapes: list[ModeShape] | None = None) -> dict:
    """Write the animation of ``shapes`` (default :func:`mode_shapes`) to ``path``; returns
    what was written (modes, their start times [s], frames)."""
    shapes = mode_shapes(build, speed_m_s) if shapes is None else shapes
    mesh = AircraftMesh(wing_shape(build), airframe_outline(build.airframe), 1.0)
    frame = body_frame(MODEL)
    label_at = (mesh.nose_x_m, 0.0, mesh.z0_m + 0.25)
    with open(path, "wb") as stream:
        w = McapFileWriter(stream, library=f"bioflex-jsb {__version__}")
        try:
            meta = scene_metadata(mesh, FRAME_RATE_HZ)
            meta["display"] = (f"each mode for {CYCLES} cycles at {DISPLAY_PERIOD_S:g} s a "
                               f"cycle, peak tip twist {math.degrees(PEAK_TIP_TWIST_RAD):g} "
                               f"deg or tip heave {PEAK_TIP_HEAVE_FRAC:.0%} of the semispan, "
                               "whichever comes first")
            w.add_metadata(SCENE_METADATA, meta)
            w.add_metadata(MODES_METADATA, {
                "wing": build.variant.name, "speed_m_s": repr(float(speed_m_s)),
                "model": "coupled (Eq. 4, quasi-steady), sea level",
                "modes": json.dumps([s.as_dict() for s in shapes])})
            sid = w.add_schema(SCENE_PROTO_SCHEMA[0], "protobuf", SCENE_PROTO_SCHEMA[1])
            pid = w.add_schema(PROTO_SCHEMAS["pose"][0], "protobuf", PROTO_SCHEMAS["pose"][1])
            eid = w.add_schema(EVENTS_PROTO_SCHEMA[0], "protobuf", EVENTS_PROTO_SCHEMA[1])
            scene_id = w.add_channel(topic(MODEL, SCENE_GROUP), sid, {"model": MODEL})
            air_id = w.add_channel(topic(MODEL, AIRFRAME_GROUP), sid, {"model": MODEL})
            pose_id = w.add_channel(topic(MODEL, "pose"), pid, {"model": MODEL})
            event_id = w.add_channel(EVENTS_TOPIC, eid, {})
            air = Records([air_id], airframe_pieces(mesh, frame), True)
            n_frames = int(round(CYCLES * DISPLAY_PERIOD_S * FRAME_RATE_HZ))
            tau = np.arange(n_frames) / FRAME_RATE_HZ
            starts, seq = [], 0
            for k, shape in enumerate(shapes):
                t0 = k * CYCLES * DISPLAY_PERIOD_S
                ns0 = int(round(t0 * 1e9))
                starts.append(t0)
                text = shape.label(speed_m_s)
                w.append(event_id, ns0, k, log_message(ns0, EVENT_LEVELS.index("INFO"), text,
                                                       MODEL))
                w.append(pose_id, ns0, k, _pose_message(ns0))
                block, index = air.build(np.array([ns0]), np.empty((1, 0)), k)
                w.append_block(block, index)
                eta = PEAK_TIP_TWIST_RAD * np.real(
                    shape.eta[None, :] * np.exp(2j * math.pi * tau / DISPLAY_PERIOD_S)[:, None])
                zeros = np.zeros(n_frames)
                rec = Records([scene_id], scene_pieces(mesh, frame,
                                                       [text_primitive(text, label_at)]), True)
                ns = np.rint((t0 + tau) * 1e9).astype(np.int64)
                block, index = rec.build(ns, scene_floats(mesh, eta, zeros, zeros, zeros), seq)
                seq += n_frames
                w.append_block(block, index)
                w.close_chunk()
            w.finish()
        finally:
            w.shutdown()
    return {"modes": [s.name for s in shapes], "start_s": starts, "frames_per_mode": n_frames}


def draw_mode_sheet(path: str | Path, build, speed_m_s: float,
                    shapes: list[ModeShape] | None = None, software: str = "") -> Path:
    """A sheet of the shapes: per mode the section twist θ(y) and the elastic axis's
    bending w(y) (up) along the half span per unit amplitude (tip twist 1 rad, or for a
    bending mode the tip heave of the module docstring; real part solid, imaginary part
    dotted: the share a quarter period behind), titled with frequency and damping."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shapes = mode_shapes(build, speed_m_s) if shapes is None else shapes
    shape = wing_shape(build)
    y = shape.stations_m
    cols = max(sum(s.kind == "structural" for s in shapes),
               sum(s.kind == "aeroelastic" for s in shapes))
    fig, axes = plt.subplots(2, cols, figsize=(4.6 * cols, 7.0), sharex=True, squeeze=False)
    legend: dict[str, object] = {}
    for row, kind in enumerate(("structural", "aeroelastic")):
        mine = [s for s in shapes if s.kind == kind]
        for c in range(cols):
            ax = axes[row, c]
            if c >= len(mine):
                ax.set_visible(False)
                continue
            s = mine[c]
            twist = s.eta @ shape.twist_rad
            heave_mm = -1e3 * (s.eta @ shape.bending_m)
            legend.setdefault("twist", ax.plot(y, twist.real, color="C0", lw=1.8,
                                               label="twist θ, real part (leading edge up +)"
                                               )[0])
            if np.abs(twist.imag).max() > 1e-3:
                legend.setdefault("twist_imag", ax.plot(
                    y, twist.imag, color="C0", lw=1.2, ls=":",
                    label="twist θ, imaginary part (a quarter period behind)")[0])
            ax.axhline(0.0, color="0.6", lw=0.6)
            ax.set_ylim(-1.15, 1.15)
            ax.set_ylabel("twist θ [rad]", color="C0")  # every panel: each its own pair
            ax.tick_params(axis="y", colors="C0")
            bx = ax.twinx()
            legend.setdefault("bending", bx.plot(y, heave_mm.real, color="C3", lw=1.5,
                                                 ls="--", label="bending w, real part (up +)"
                                                 )[0])
            lim = max(1e-3, 1.15 * np.abs(heave_mm).max())
            bx.set_ylim(-lim, lim)
            bx.set_ylabel("bending w [mm]", color="C3")  # its scale differs per mode
            bx.tick_params(axis="y", colors="C3")
            title = s.label(speed_m_s).replace(": ", ":\n", 1)
            ax.set_title(title, fontsize=9)
            if row == 1:
                ax.set_xlabel("spanwise station y [m]")
    fig.suptitle(f"Mode shapes of the {build.variant.name} wing (starboard half, root "
                 f"clamped), per unit modal amplitude; aeroelastic modes of the coupled "
                 f"model at {speed_m_s:g} m/s", fontsize=10)
    fig.legend(list(legend.values()), [h.get_label() for h in legend.values()],
               loc="upper center", bbox_to_anchor=(0.5, 0.965), ncol=len(legend), fontsize=8,
               frameon=False)
    fig.tight_layout(rect=(0.0, 0.0, 1.0, 0.945))
    out = Path(path)
    fig.savefig(out, dpi=150, metadata={"Software": software} if software else None)
    plt.close(fig)
    return out
