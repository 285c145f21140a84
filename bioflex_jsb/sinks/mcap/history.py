"""A log's runs read back as the :class:`~bioflex_jsb.simulation.results.TimeHistory` objects
the runs returned: every channel, under the run's names and units.

Where each channel comes from (``docs/logging.md``): ``rigid_body`` (the perturbations, the
attitude, rates, air data, altitude, velocities: :data:`.schemas.RIGID_BODY_CHANNELS`),
``modal`` (η_i, η̇_i), ``modal_loads``, ``gust``, ``controls`` at every step; ``location``
(latitude, longitude [deg in the log, rad in the run]) at the 3-D scene's 60 Hz samples,
interpolated linearly in time to every step (and extrapolated from the last two samples
after the last one): ``meta["resampled"]`` names them; ``loads`` (the section loads, in
chunks of their own, read with ``loads=True``) at every step; a run's stop from its event
on ``/bioflex/events``. Times are the log's [ns] in seconds (a run's own times rounded to
the nanosecond). A value a step's message lacks is NaN; a channel no message has is left
out. ``lti_prediction`` topics are runs of their own (``meta["label"]`` "LTI <model>").

A read is bounded: at most :data:`READ_MAX_STEPS` steps (the summary's message counts say
how many before anything is decoded), or a window ``start_s`` <= t < ``end_s`` of a longer
log (only the chunks that overlap it are read).
"""

from __future__ import annotations

import json
import math
from array import array
from pathlib import Path

import numpy as np

from bioflex_jsb.aeroelasticity.control_surface import ControlSurface
from bioflex_jsb.simulation.channels import CHANNELS, describe
from bioflex_jsb.simulation.controller import COMMAND_CHANNELS
from bioflex_jsb.simulation.results import TimeHistory
from bioflex_jsb.sinks.mcap.reader import NotOurs, iter_messages, open_reader, read_metadata
from bioflex_jsb.sinks.mcap.schemas import EVENTS_TOPIC, RIGID_BODY_CHANNELS, RUN_METADATA
from bioflex_jsb.sinks.mcap_io.errors import LogError
from bioflex_jsb.values import is_finite_real, is_real

# At most this many steps (messages of rigid_body and lti_prediction topics) per read: 17
# minutes of one model at 960 Hz; every channel of a gust run with its loads is 55 doubles,
# so 0.44 GB of arrays at the bound (and the decoding, ~15 µs a message, 6 messages a step,
# about 90 s).
READ_MAX_STEPS = 1_000_000
STEP_GROUPS = ("rigid_body", "modal", "modal_loads", "gust", "controls", "location",
               "controller", "lateral")
REFERENCE_GROUPS = ("rigid_body", "lti_prediction")  # their messages are the run's steps
LOADS_GROUP = "loads"
RESAMPLED = "linear in time between the 60 Hz location samples (docs/logging.md)"
_LOAD_FIELDS = tuple(f"{tag}_{q}" for tag in ("fs", "md")
                     for q in ("shear_n", "bending_n_m", "torque_n_m"))
_LOAD_METHODS = {"fs": "force_summation", "md": "mode_displacement"}


def _number(msg: dict, field: str, topic: str, ns: int, required: bool = False) -> float:
    """``msg[field]`` as a float (NaN if absent and not ``required``); NotOurs otherwise."""
    value = msg.get(field)
    if value is None and not required:
        return math.nan
    if not is_real(value):
        raise NotOurs(topic, ns, f"field {field!r} is {type(value).__name__}, not a number")
    return float(value)


def _numbers(msg: dict, field: str, topic: str, ns: int, required: bool = False) -> list:
    """``msg[field]`` as a list of numbers (empty if absent and not ``required``)."""
    value = msg.get(field)
    if value is None and not required:
        return []
    if not isinstance(value, list | tuple) or not all(
            isinstance(v, int | float) and not isinstance(v, bool) for v in value):
        raise NotOurs(topic, ns, f"field {field!r} is not a list of numbers")
    return [float(v) for v in value]


def _values(group: str, msg: dict, topic: str, ns: int) -> dict[str, float]:
    """The run's channels in one message of ``group`` (a reference group: its rigid-body
    fields, and the prediction's η and loads)."""
    if group in REFERENCE_GROUPS:
        out = {RIGID_BODY_CHANNELS[f]: _number(msg, f, topic, ns)
               for f in RIGID_BODY_CHANNELS if f in msg}
        if group == "lti_prediction":
            out.update(_indexed(msg, "eta_rad", "eta{}", topic, ns))
            out.update(_loads(msg, topic, ns))
        return out
    if group == "modal":
        return {**_indexed(msg, "eta_rad", "eta{}", topic, ns, required=True),
                **_indexed(msg, "eta_dot_rad_s", "eta{}_dot", topic, ns)}
    if group == "gust":
        return {"w_g": _number(msg, "w_g_m_s", topic, ns, required=True)}
    if group == "location":
        return {f"{f}_rad": math.radians(_number(msg, f, topic, ns))
                for f in ("latitude", "longitude") if f in msg}
    if group == LOADS_GROUP:
        return _loads(msg, topic, ns)
    if group == "controller":  # its commands (a command it does not write is NaN: left out)
        values = {c: _number(msg, f, topic, ns) for c, f in (
            ("ctrl_elevator_rad", "elevator_cmd_rad"), ("ctrl_throttle", "throttle_cmd"),
            ("ctrl_flaperon_rad", "flaperon_cmd_rad"), ("ctrl_aileron_rad", "aileron_cmd_rad"))}
        return {c: v for c, v in values.items() if not math.isnan(v)}
    if group == "lateral":  # a full-span run's antisymmetric wing (lateral_topic.py)
        out = {f: _number(msg, f, topic, ns) for f in (
            "aileron_rad", "modal_roll_n_m", "tip_twist_starboard_rad", "tip_twist_port_rad",
            "modal_side_n", "modal_yaw_n_m")}
        out.update(_indexed(msg, "asym_eta_rad", "asym_eta{}", topic, ns))
        out.update(_indexed(msg, "asym_eta_dot_rad_s", "asym_eta{}_dot", topic, ns))
        return out
    fields = {"modal_loads": ("lift_n", "drag_n", "pitch_moment_n_m"),
              "controls": ("elevator_rad", "throttle")}[group]
    return {f: _number(msg, f, topic, ns) for f in fields if f in msg}


def _indexed(msg, field, name, topic, ns, required=False) -> dict[str, float]:
    return {name.format(i + 1): v
            for i, v in enumerate(_numbers(msg, field, topic, ns, required))}


def _loads(msg, topic, ns) -> dict[str, float]:
    return {f"loads_{f}_s{j}": v for f in _LOAD_FIELDS if f in msg
            for j, v in enumerate(_numbers(msg, f, topic, ns))}


class _Group:
    """One topic's messages: their log times [ns] and per channel the values (NaN where a
    message lacks the channel), growing together."""

    def __init__(self) -> None:
        self.ns = array("q")
        self.values: dict[str, array] = {}

    def add(self, ns: int, values: dict[str, float]) -> None:
        k = len(self.ns)
        self.ns.append(ns)
        for name, v in values.items():
            column = self.values.get(name)
            if column is None:
                column = self.values[name] = array("d", [math.nan]) * k
            column.append(v)
        for column in self.values.values():
            if len(column) == k:
                column.append(math.nan)


def histories(path: str | Path, *, loads: bool = False, start_s: float | None = None,
              end_s: float | None = None) -> tuple[list, dict[str, str]]:
    """The runs of the log ``path`` rebuilt as TimeHistory objects (JSBSim runs, then LTI
    predictions) with every channel (module docstring), and its ``bioflex.run`` metadata.
    ``loads``: also the section loads (chunks of their own: a figure of the flight need not
    read them, nor stop at their damage). ``start_s``/``end_s`` [s]: the steps logged at
    start_s <= t < end_s only. LogError (one line) for a file that is not a finished log of
    ours, or one of more than :data:`READ_MAX_STEPS` steps in the window."""
    start_ns, end_ns = _window_ns(start_s, end_s)
    with open_reader(path) as (reader, summary):
        meta = read_metadata(reader).get(RUN_METADATA, {})
        groups = (*STEP_GROUPS, "lti_prediction", *((LOADS_GROUP,) if loads else ()))
        topics, channel_meta = {}, {}
        for ch in summary.channels.values():  # /bioflex/<model>/<group>: docs/logging.md
            parts = ch.topic.split("/")
            if len(parts) == 4 and parts[:2] == ["", "bioflex"] and parts[3] in groups:
                topics[ch.topic] = (parts[2], parts[3])
                channel_meta[ch.topic] = dict(ch.metadata)
        _check_size(path, summary, topics, start_ns is None and end_ns is None)
        read: dict[tuple[str, str], _Group] = {}
        events: list[tuple[int, dict]] = []
        steps = 0
        wanted = [*topics, *([EVENTS_TOPIC] if any(c.topic == EVENTS_TOPIC for c in
                                                    summary.channels.values()) else [])]
        for top, ns, msg in iter_messages(reader, wanted, start_ns, end_ns):
            if top == EVENTS_TOPIC:
                events.append((ns, msg))
                continue
            model, group = topics[top]
            if group in REFERENCE_GROUPS:
                steps += 1
                if steps > READ_MAX_STEPS:
                    raise _too_long(path, steps)
            read.setdefault((model, group), _Group()).add(ns, _values(group, msg, top, ns))
    runs = []
    for model, ref in [(m, g) for (m, g) in read if g == "rigid_body"] + \
            [(m, g) for (m, g) in read if g == "lti_prediction"]:
        prediction = ref == "lti_prediction"
        top = f"/bioflex/{model}/{ref}"
        parts = [read[(model, ref)]] if prediction else \
            [read[(model, g)] for g in (*STEP_GROUPS, LOADS_GROUP) if (model, g) in read]
        t_ns = np.frombuffer(read[(model, ref)].ns, dtype=np.int64)
        channels = _ordered(_aligned(t_ns, parts, read.get((model, "location"))))
        layout = _loads_layout(channel_meta.get(top if prediction else
                                                f"/bioflex/{model}/{LOADS_GROUP}"), channels)
        run = TimeHistory(model, t_ns * 1e-9, channels,
                          {n: describe(n).unit for n in channels},
                          _run_meta(meta, path, layout, channels))
        control = channel_meta.get(f"/bioflex/{model}/controller")
        if control and not prediction:
            run.meta["controller"] = _controller_meta(control)
            if "flaperon" in control:  # the surface its flaperon commands moved
                run.meta["flaperon"] = _flaperon_meta(control["flaperon"])
        if prediction:
            run.meta.update(label=f"LTI {model}", linestyle="--")
        else:
            run.stopped = _stop(events, model)
        runs.append(run)
    return runs, meta


def _window_ns(start_s, end_s) -> tuple[int | None, int | None]:
    """The window [start_s, end_s) [s] as log times [ns]; LogError for a bad one."""
    out = []
    for what, v in (("start_s", start_s), ("end_s", end_s)):
        if v is not None and (not is_finite_real(v) or v < 0.0):
            raise LogError(f"{what} must be a finite time >= 0 s, got {v!r}")
        out.append(None if v is None else int(round(v * 1e9)))
    if None not in out and out[1] <= out[0]:
        raise LogError(f"the window must end after it starts: start_s {start_s!r} s, "
                       f"end_s {end_s!r} s")
    return out[0], out[1]


def _too_long(path, steps: int) -> LogError:
    return LogError(f"{str(path)!r} holds {steps} steps, more than one read takes "
                    f"({READ_MAX_STEPS}, ~0.4 GB of channels): give a window, start_s and "
                    "end_s [s]")


def _check_size(path, summary, topics, whole: bool) -> None:
    """Refuse a whole log of more than READ_MAX_STEPS steps before decoding any."""
    stats = summary.statistics
    if not whole or stats is None:
        return
    ids = [cid for cid, ch in summary.channels.items()
           if ch.topic in topics and topics[ch.topic][1] in REFERENCE_GROUPS]
    steps = sum(stats.channel_message_counts.get(cid, 0) for cid in ids)
    if steps > READ_MAX_STEPS:
        raise _too_long(path, steps)


def _aligned(t_ns: np.ndarray, parts: list[_Group], location: _Group | None
             ) -> dict[str, np.ndarray]:
    """Every channel of ``parts`` at the steps ``t_ns`` (a message at another log time is
    not a step's: left out; a step without a message: NaN); the location's channels
    interpolated to every step (module docstring)."""
    out: dict[str, np.ndarray] = {}
    for group in parts:
        ns = np.frombuffer(group.ns, dtype=np.int64)
        same = len(ns) == len(t_ns) and np.array_equal(ns, t_ns)
        if not same:
            at = np.clip(np.searchsorted(t_ns, ns), 0, max(len(t_ns) - 1, 0))
            hit = (t_ns[at] == ns) if len(t_ns) else np.zeros(len(ns), bool)
        for name, column in group.values.items():
            values = np.frombuffer(column, dtype=float).copy()
            if group is location:
                out[name] = _interpolated(t_ns, ns, values)
            elif same:
                out[name] = values
            else:
                full = np.full(len(t_ns), np.nan)
                full[at[hit]] = values[hit]
                out[name] = full
    return out


def _interpolated(t_ns: np.ndarray, ns: np.ndarray, values: np.ndarray) -> np.ndarray:
    """``values`` sampled at ``ns`` at every time ``t_ns``: linear between the samples, and
    beyond the last one along the last two's line (before the first: the first)."""
    if len(ns) == 0:
        return np.full(len(t_ns), np.nan)
    t = (t_ns - t_ns[0]) * 1e-9 if len(t_ns) else t_ns * 1e-9
    s = (ns - (t_ns[0] if len(t_ns) else 0)) * 1e-9
    out = np.interp(t, s, values)
    if len(ns) >= 2:
        after = t > s[-1]
        slope = (values[-1] - values[-2]) / (s[-1] - s[-2])
        out[after] = values[-1] + slope * (t[after] - s[-1])
    return out


def _order(name: str) -> tuple:
    """A channel's place in a run (the run's own order: the base channels, η, η̇, loads)."""
    if name in CHANNELS:
        return (0, list(CHANNELS).index(name))
    if name.startswith("eta"):
        dot = name.endswith("_dot")
        return (2 if dot else 1, int(name[3:-4] if dot else name[3:]))
    if name.startswith("loads_"):
        head, _, j = name.rpartition("_s")
        return (3, _LOAD_FIELDS.index(head[6:]), int(j))
    return (4, name)


def _ordered(channels: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    return {n: channels[n] for n in sorted(channels, key=_order)}


def _json(text: str | None, what: str):
    if text is None:
        return None
    try:
        return json.loads(text)
    except ValueError:
        raise LogError(f"the log's {what} is not JSON") from None


def _loads_layout(metadata: dict[str, str] | None, channels) -> dict | None:
    """A run's ``meta["loads"]`` (``drivers.gust``) from its loads channel's metadata
    (:func:`.loads_topic.channel_metadata`); None without one."""
    if not metadata or "stations_m" not in metadata:
        return None
    static = _json(metadata.get("static_1g"), "loads static_1g") or {}
    names = sorted((n for n in channels if n.startswith("loads_")), key=_order)
    try:
        return {"names": names, "units": {n: describe(n).unit for n in names},
                "methods": [m for m in metadata.get("methods", "").split(",") if m],
                "stations_m": _json(metadata["stations_m"], "loads stations_m"),
                "station_fractions": _json(metadata.get("station_fractions"),
                                           "loads station_fractions"),
                "static_1g": {f"loads_{f}_s{j}": float(v) for f, values in static.items()
                              for j, v in enumerate(values)},
                "note": metadata.get("static"),
                "density_kg_m3": float(metadata.get("density_kg_m3", "nan")),
                "wing": metadata.get("wing")}
    except (TypeError, ValueError, AttributeError) as exc:
        raise LogError(f"the log's loads metadata is not one bioflex-jsb writes ({exc})"
                       ) from None


def _controller_meta(metadata: dict[str, str]) -> dict:
    """A run's ``meta["controller"]`` from its controller channel's metadata
    (:func:`.controller_topic.channel_metadata`)."""
    outputs = [o for o in metadata.get("commands", "").split(",") if o]
    return {"name": metadata.get("name"), "kind": metadata.get("kind"),
            "inputs": _json(metadata.get("signals"), "controller signals") or [],
            "outputs": outputs,
            "channels": [COMMAND_CHANNELS.get(o, o) for o in outputs],
            "n_states": _json(metadata.get("n_states"), "controller n_states"),
            "dt_s": _json(metadata.get("dt_s"), "controller dt_s")}


def _flaperon_meta(text: str) -> dict:
    """A run's ``meta["flaperon"]`` (its ``surface``: span range [m], hinge [chord
    fraction], name) from the controller channel's metadata; LogError (one line) for one
    bioflex-jsb does not write."""
    record = _json(text, "controller flaperon")
    surface = record.get("surface") if isinstance(record, dict) else None
    try:
        if not isinstance(surface, dict) or not isinstance(surface.get("name"), str) or not all(
                is_finite_real(surface.get(k)) for k in ("start_m", "end_m",
                                                         "hinge_chord_fraction")):
            raise ValueError("no surface with a name, span range and hinge")
        ControlSurface(float(surface["start_m"]), float(surface["end_m"]),
                       float(surface["hinge_chord_fraction"]), surface["name"])
    except ValueError as exc:
        raise LogError(f"the log's controller flaperon is not one bioflex-jsb writes ({exc})"
                       ) from None
    return record


_FLOAT_META = ("speed_m_s", "duration_s", "gust_start_s", "dt_s")


def _run_meta(meta: dict[str, str], path, layout, channels) -> dict:
    """A run's ``meta`` from the log's ``bioflex.run`` record: the fields a run of
    ``fly_gust`` has that the log keeps (speed, time step, gust, gust start, wing, mass
    basis, overrides), ``source`` "log", the ``log`` path, the loads layout."""
    out: dict[str, object] = {"source": "log", "log": str(path)}
    for key in _FLOAT_META:
        if key in meta:
            try:
                out[key] = float(meta[key])
            except ValueError:
                raise LogError(f"the log's run metadata {key} is {meta[key]!r}, not a "
                               "number") from None
    out.update({k: meta[k] for k in ("gust", "wing", "mass_basis", "command") if k in meta})
    if "overrides" in meta:
        out["overrides"] = _json(meta["overrides"], "run metadata overrides")
    if "mode_tips" in meta:  # what η_i does at the tip (a gust run's meta says so too)
        out["mode_tips"] = _json(meta["mode_tips"], "run metadata mode_tips")
    if layout is not None:
        out["loads"] = layout
    resampled = [n for n in ("latitude_rad", "longitude_rad") if n in channels]
    if resampled:
        out["resampled"] = dict.fromkeys(resampled, RESAMPLED)
    return out


def _stop(events: list[tuple[int, dict]], model: str) -> str | None:
    """Why ``model``'s run stopped: its ERROR event "<model> run stopped (<mode>): <why>"
    (``cli/gust.py``), else None."""
    head = f"{model} run stopped"
    for _, msg in events:
        text = str(msg.get("message", ""))
        if msg.get("name") == model and text.startswith(head):
            return text.split("): ", 1)[1] if "): " in text else text[len(head):].lstrip(": ")
    return None
